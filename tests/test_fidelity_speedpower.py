"""Issue 17 acceptance for the speed/power analysis: KVLCC2 in a 15 kn wind, every spot with head- and
tail-wind runs, corrected power within 1 % of the true calm-water curve at equal speed (the truth: the
model's own steady states at the trial's r/min). Also the residual-acceleration correction the
reduction applies, against an exact quadratic track."""

import json
import math

import numpy as np
import pytest

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


@pytest.fixture(scope="module")
def kvlcc2_sp(tmp_path_factory, scenarios_dir):
    out = tmp_path_factory.mktemp("kvlcc2_sp")
    run(scenarios_dir / "kvlcc2_speed_power.toml", out, plot=False)
    return json.loads((out / "results.json").read_text())


def test_kvlcc2_speed_power_within_one_percent_in_head_and_tail_wind(kvlcc2_sp):
    tr = kvlcc2_sp["trials"][0]
    errs = []
    for sp, red in zip(tr["error"]["spots"], tr["reduced"]["spots"]):
        r_aa = [w["r_aa"] for w in red["wind"]]
        assert min(r_aa) < 0 < max(r_aa), r_aa  # the spot has tail- and head-wind runs
        assert red["xi_P"] is not None and red["xi_P"] > 0  # the DPM's third term is in
        errs.append(sp["power_at_equal_speed"]["error"])
    print("power error at equal speed per spot [%]:", np.round(np.array(errs) * 100, 2))
    assert len(errs) == 5
    assert max(abs(e) for e in errs) < 0.01
