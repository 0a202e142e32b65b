"""Issue 17 acceptance for the speed/power analysis: KVLCC2 in a 15 kn wind, every spot with head- and
tail-wind runs, corrected power within 1 % of the true calm-water curve at equal speed (the truth: the
model's own steady states at the trial's r/min). Also the residual-acceleration correction the
reduction applies, against an exact quadratic track and a receiver's velocity with known noise."""

import json
import math

import numpy as np
import pytest

from tests.calibration import drawn_meter_errors, net_of_calibration
from vtrials import run
from vtrials.reduce import speedpower as SP


def test_along_track_acceleration_of_a_quadratic_track():
    rng = np.random.default_rng(3)
    t = np.arange(0.0, 600.0, 1.0)
    a, v0, c = 1.2e-4, 7.0, math.radians(33.0)
    s = v0 * t + 0.5 * a * t ** 2
    n = 100.0 + s * math.cos(c) + rng.normal(0, 0.5, t.size)
    e = -50.0 + s * math.sin(c) + rng.normal(0, 0.5, t.size)
    got, se = SP.along_track_acceleration(t, n, e, 0.0, 599.0)
    assert abs(got - a) < 4 * se and se < 5e-6
    r, _ = SP.acceleration_resistance(a, 312600.0, 1025.0, added_mass_fraction=0.08)
    assert r == pytest.approx(1025.0 * 312600.0 * 1.08 * a, rel=1e-14)
    # an acceleration the fixes do not resolve is not corrected
    r0, _ = SP.acceleration_resistance([a, a], 312600.0, 1025.0, accel_std=[a, 0.4 * a])
    assert r0[0] == 0.0 and r0[1] == pytest.approx(1025.0 * 312600.0 * 1.08 * a, rel=1e-14)


def test_acceleration_standard_error_allows_for_correlated_fixes():
    """Fix errors with a 10-s correlation (short against the run): 400 tracks of 180 s; the stated
    standard error must match the scatter of the estimates (the white-noise formula understates it).
    Known limit: errors correlated over a good part of the run are absorbed by the fit and understated."""
    rng = np.random.default_rng(11)
    t = np.arange(0.0, 180.0, 1.0)
    phi = math.exp(-1.0 / 10.0)
    est, ses = [], []
    for _ in range(400):
        z = np.empty(t.size)
        z[0] = rng.normal(0, 3.0)
        for i in range(1, t.size):
            z[i] = phi * z[i - 1] + 3.0 * math.sqrt(1 - phi ** 2) * rng.normal()
        a, se = SP.along_track_acceleration(t, 8.0 * t + z + rng.normal(0, 0.5, t.size), 0.0 * t)
        est.append(a)
        ses.append(se)
    sd = float(np.std(est))
    print(f"acceleration scatter {sd:.2e}, mean stated se {np.mean(ses):.2e} m/s2")
    assert 0.6 * sd < float(np.mean(ses)) < 1.5 * sd


def test_acceleration_from_receiver_velocity():
    """Doppler velocity with white noise 0.05 m/s at 1 Hz on a 10-min run whose course is 40°: the slope
    is unbiased (mean of 300 tracks within 3 standard errors of the truth) and its stated standard
    error matches the scatter (white noise: σ/√Σ(t−t̄)² = 1.18e-5 m/s²)."""
    rng = np.random.default_rng(7)
    t = np.arange(0.0, 600.0, 1.0)
    a_true = 1.0e-4
    est, ses = [], []
    for _ in range(300):
        v = 5.0 + a_true * t + rng.normal(0, 0.05, t.size)
        cog = math.radians(40.0) + rng.normal(0, 0.002, t.size)
        a, se = SP.along_track_acceleration_from_velocity(t, v, cog, 0.0, 600.0)
        est.append(a)
        ses.append(se)
    sd = float(np.std(est))
    print(f"velocity slope: mean {np.mean(est):.3e}, scatter {sd:.2e}, stated {np.mean(ses):.2e} m/s2")
    assert abs(np.mean(est) - a_true) < 3 * sd / math.sqrt(300)
    assert 0.8 * sd < float(np.mean(ses)) < 1.25 * sd
    assert abs(sd - 0.05 / math.sqrt(np.sum((t - t.mean()) ** 2))) < 0.15 * sd


def test_true_curve_ignores_a_second_point_at_the_same_speed():
    """The scoring reference P_true(V) through calm-water points P = c V^3.4 (at the KVLCC2 trial's
    speeds and midpoints), plus the end point that a setting above the engine's limit gives: the top
    spot's steady state again, 2e-5 m/s and 1.5e-5 of power away (its twin converged to within the
    steadiness tolerance). The curve must stay on c V^3.4 between the spots (reference: the power law
    itself; the monotone cubic's own interpolation error is < 0.05 %)."""
    from vtrials.score.trials import true_curve

    c, q = 5.0e4, 3.4
    v = np.array([4.766, 4.964, 5.516, 6.067, 6.619, 7.171, 7.557, 7.943, 8.163, 8.349349])
    pts = [{"stw": x, "power": c * x ** q} for x in v]
    pts.append({"stw": 8.349370, "power": c * 8.349349 ** q * (1 + 1.5e-5)})
    P, (lo, hi) = true_curve(pts)
    vv = np.linspace(lo, 8.349349, 200)
    rel = P(vv) / (c * vv ** q) - 1.0
    assert np.max(np.abs(rel)) < 5e-4, np.max(np.abs(rel))


@pytest.fixture(scope="module")
def kvlcc2_sp(tmp_path_factory, scenarios_dir):
    out = tmp_path_factory.mktemp("kvlcc2_sp")
    run(scenarios_dir / "kvlcc2_speed_power.toml", out, plot=False)
    return json.loads((out / "results.json").read_text()), drawn_meter_errors(out / "truth.nc")


def test_kvlcc2_speed_power_within_one_percent_in_head_and_tail_wind(kvlcc2_sp):
    """The reduction within 0.6 % of the true curve at every spot once the meters' own calibration
    errors of this trial (torsionmeter scale ~0.5 %, counter ~0.25 r/min, both 1σ; seed 002 Table 2)
    are taken out — those no analysis can remove and the stated interval carries them — and the full
    error inside the stated 95 % interval."""
    res, meters = kvlcc2_sp
    tr = res["trials"][0]
    errs, net = [], []
    for sp, red in zip(tr["error"]["spots"], tr["reduced"]["spots"]):
        r_aa = [w["r_aa"] for w in red["wind"]]
        assert min(r_aa) < 0 < max(r_aa), r_aa  # the spot has tail- and head-wind runs
        assert red["xi_P"] is not None and red["xi_P"] > 0  # the DPM's third term is in
        e = sp["power_at_equal_speed"]
        assert e["covered"], e
        errs.append(e["error"])
        net.append(net_of_calibration(e["error"], meters, red["torque"], red["rps"]))
    print("power error at equal speed per spot [%]:", np.round(np.array(errs) * 100, 2),
          "net of the meters' calibration:", np.round(np.array(net) * 100, 2))
    assert len(errs) == 5
    # seed 1501, joint fit of the day on the along-course speeds: total -1.12..-0.36 %, net of the
    # meters -0.54..+0.02 %. The drawn torsionmeter scale error of this trial is -0.58 % on every spot:
    # the total is the net plus that draw, which no reduction can know (it is in the stated interval,
    # asserted above). Before the along-course speeds the mean of means passed the total at -0.77 % by a
    # cancellation: the track's speed magnitude carried +0.0115 m/s of cross-tide (V_C⊥²/2V) at spot 1
    # and the mean of means' quadratic current model -0.0127 m/s over the spot's 4-h span.
    assert max(abs(e) for e in net) < 0.006
    stw_err = [sp["stw"]["error"] for sp in tr["error"]["spots"]]
    print("speed-through-water error per spot [m/s]:", np.round(stw_err, 4))
    assert max(abs(e) for e in stw_err) < 0.006  # 0.1 % at 45 r/min: the current's change is fitted
