"""System identification from SIMULATOR records (issue 16): KVLCC2 L7 identification agenda
(scenarios/kvlcc2_l7_identification.toml: zig-zags 5/5, 10/10, 15/15, 35° starboard and 20° port
turns) recorded by the free-running model's instruments; the 35° port turn and the 20/20 zig-zags held
back.

Independent references: the true coefficients are the simulator's model file; the held-back truths are
the simulator's own runs of those maneuvers (6-DOF MuJoCo, truth metrics by definition), which the
team's 3-DOF prediction never sees.
"""

import json

import h5py
import numpy as np
import pytest

from vtrials import run
from vtrials.cli import main
from vtrials.errors import InputError
from vtrials.score.identification import score, true_coefficients
from vtrials.sysid import mmg
from vtrials.sysid import records as RE
from vtrials.sysid.identify import identify_records


@pytest.fixture(scope="module")
def runs(tmp_path_factory, scenarios_dir):
    out = {}
    for name in ("identification", "turning", "zigzag"):
        d = tmp_path_factory.mktemp(name)
        run(scenarios_dir / f"kvlcc2_l7_{name}.toml", d, plot=False)
        out[name] = d
    return out


@pytest.fixture(scope="module")
def identified(runs):
    train = sorted((runs["identification"] / "records").glob("*.nc"))
    held = [runs["turning"] / "records" / "turn_35_port.nc"] + sorted((runs["zigzag"] / "records").glob("zigzag_20*.nc"))
    doc = identify_records(train, "mmg", True, held)
    return doc, score(doc)


def test_linear_coefficients_within_ten_percent(identified):
    doc, sc = identified
    print("linear relative errors", {k: round(v, 4) for k, v in sc["linear_rel_error"].items()},
          "intervals", {k: (round(doc["coefficients"][k]["lo95"], 4), round(doc["coefficients"][k]["hi95"], 4))
                        for k in mmg.LINEAR})
    assert set(sc["linear_rel_error"]) == set(mmg.LINEAR)
    assert sc["max_linear_rel_error"] < 0.10
    assert sc["verdict"]["linear_within_10pct"]
    # the interval adds the record-wide errors (gyro zero, synchro calibration) to the regression's own;
    # its calibration is measured over 100 replicates (benchmarks/campaign_identification.py); here at
    # most one of the four may miss (three or more misses of four 95 % intervals: probability 0.05 %)
    for k in mmg.LINEAR:
        c = doc["coefficients"][k]
        assert c["std_systematic"] > 0 and c["std"] ** 2 == pytest.approx(c["std_random"] ** 2 + c["std_systematic"] ** 2)
    assert sum(sc["coefficients"][k]["covered"] for k in mmg.LINEAR) >= 3


def test_held_back_maneuvers_predicted(identified):
    """35° port turn: advance, transfer and tactical diameter within 5 % of the simulator's truth; 20/20
    zig-zags (larger than any zig-zag fitted): both overshoots within 1.5°."""
    _, sc = identified
    for p in sc["predictions"]:
        print(p["name"], {k: (round(v["predicted"], 3), round(v["truth"], 3)) for k, v in p["errors"].items()})
    kinds = {k for p in sc["predictions"] for k in p["errors"]}
    assert kinds == {"advance_m", "transfer_m", "tactical_diameter_m", "first_overshoot_deg", "second_overshoot_deg"}
    assert len(sc["predictions"]) == 3
    assert sc["worst"]["turn_rel"] < 0.05
    assert sc["worst"]["overshoot_deg"] < 1.5


def test_cross_validation_ranks_true_structure_on_yaw(identified):
    doc, _ = identified
    cv = doc["cross_validation"]
    print("CV", cv)
    assert set(cv) == {"mmg", "abkowitz", "blanke"}
    assert cv["mmg"]["N"] < cv["blanke"]["N"] and cv["mmg"]["Y"] < cv["blanke"]["Y"]


def test_smoother_states_against_truth(runs):
    """The smoothed u, v, r against the true body velocities at midship: RMS errors at the mm/s level
    and their 95 % intervals covering most samples (reported; the filter treats the tracking's
    time-correlated errors as white, so coverage below 95 % is expected and measured here)."""
    d = runs["identification"]
    truth = h5py.File(d / "truth.nc")
    rows = []
    for p in sorted((d / "records").glob("*.nc")):
        mr = RE.read_maneuver(p)
        sol = RE.reconstruct(mr)
        g = truth[mr.name]
        for k, col in (("u", "u_r"), ("v", "v_r"), ("r", "r")):
            e = sol.state(k) - np.interp(sol.t, g["time"][:], g[col][:])
            rows.append((mr.name, k, float(np.sqrt(np.mean(e**2))), float(np.mean(np.abs(e) < 1.96 * sol.sigma(k)))))
    for r in rows:
        print(f"{r[0]:<24} {r[1]} rms {r[2]:.2e} coverage {r[3]:.2f}")
    rms = {k: max(r[2] for r in rows if r[1] == k) for k in "uvr"}
    cov = {k: np.mean([r[3] for r in rows if r[1] == k]) for k in "uvr"}
    assert rms["u"] < 0.004 and rms["v"] < 0.004 and rms["r"] < 2e-4     # U = 1.18 m/s, r up to 0.07 rad/s
    assert cov["u"] > 0.8 and cov["v"] > 0.8 and cov["r"] > 0.9


def test_approach_has_no_drift_angle(runs):
    """The team zeroes the gyro against the track on the straight approach, assuming no drift angle
    there (calm basin, no current, rudder amidships): the truth confirms it (< 0.01°)."""
    truth = h5py.File(runs["identification"] / "truth.nc")
    for name in truth:
        g = truth[name]
        k = (g["time"][:] > 3.0) & (g["time"][:] < 10.0)
        beta = np.arctan2(g["v_r"][k], g["u_r"][k])
        assert np.abs(beta).max() < np.radians(0.01)


def test_true_coefficients_from_model_file():
    t = true_coefficients("kvlcc2_l7")
    assert t["X_0"] == -0.022 and t["N_r"] == -0.049 and t["Y_vvv"] == -1.607
    p = true_coefficients("patrol51")   # BC93, dimensional; the resistance curve is a table, not a term
    assert p["Y_uv"] == -11800.0 and p["N_ur"] == -4.71e6 and p["K_p"] == -500000.0 and "X_0" not in p
    assert "astern_resistance_factor" not in p and "z_H" not in p


def test_record_wide_errors_move_the_fit_as_stated():
    """A heading error δψ turns the reconstructed body velocities and accelerations by −δψ (the sway
    a gyro zero error puts into the records); a rudder zero adds to every rudder angle."""
    from vtrials.sysid.identify import _perturbed
    from vtrials.sysid.regression import Segment
    t = np.linspace(0.0, 10.0, 11)
    seg = Segment(t, np.full(11, 1.2), np.full(11, 0.05), np.full(11, 0.01), np.full(11, 0.002), np.full(11, -0.001),
                  np.zeros(11), np.full(11, 0.1), np.full(11, 11.8))
    d = 1e-3
    h = _perturbed(seg, "heading", d)
    ang = np.arctan2(h.v, h.u) - np.arctan2(seg.v, seg.u)
    assert np.allclose(ang, -d, rtol=1e-5) and np.allclose(np.hypot(h.u, h.v), np.hypot(seg.u, seg.v), rtol=1e-6)
    assert np.allclose(_perturbed(seg, "rudder", d).delta, seg.delta + d)
    with pytest.raises(InputError, match="allowed: heading, rudder, rudder_timing"):
        _perturbed(seg, "log", d)


def test_bad_records(runs, tmp_path):
    with pytest.raises(InputError, match="no team maneuvering model"):
        mmg.team_ship("kvlcc2")
    with pytest.raises(InputError, match="records"):
        identify_records([])
    src = sorted((runs["identification"] / "records").glob("*.nc"))[0]
    bad = tmp_path / "no_imu.nc"
    import shutil
    shutil.copy(src, bad)
    with h5py.File(bad, "a") as f:
        del f["imu"]
    with pytest.raises(InputError, match="no imu instrument"):
        RE.read_maneuver(bad)


def test_cli_identify(runs, tmp_path, capsys):
    out = tmp_path / "id"
    train = [str(p) for p in sorted((runs["identification"] / "records").glob("*.nc"))]
    held = [str(runs["zigzag"] / "records" / "zigzag_20_20_port.nc")]
    assert main(["identify", *train, "--held-back", *held, "--out", str(out)]) == 0
    doc = json.loads((out / "identification.json").read_text())
    assert doc["ship"] == "kvlcc2_l7" and doc["score"]["verdict"]["linear_within_10pct"]
    png = out / "identification.png"
    from matplotlib.image import imread
    img = imread(png)
    assert img.shape[0] > 300 and img[..., :3].std() > 0.05        # a drawn figure, not a blank page
    assert "N_r" in capsys.readouterr().out
    # bad input: a clear error, nothing written
    bad = tmp_path / "id2"
    assert main(["identify", str(runs["identification"] / "results.json"), "--out", str(bad)]) == 2
    assert not bad.exists()


def test_prbs_rudder_is_a_maximum_length_sequence():
    from vtrials.trials.programs import Prbs
    for stages, n in ((3, 7), (4, 15)):
        b = Prbs(name="p", rudder_deg=-10.0, bit_s=2.0, stages=stages).bits()
        assert b.size == n and b[0] == -1.0                       # first bit to the side of the sign
        assert sorted([np.sum(b > 0), np.sum(b < 0)]) == [2**(stages - 1) - 1, 2**(stages - 1)]  # balance
        ac = np.array([np.dot(b, np.roll(b, k)) for k in range(1, n)])
        assert np.all(ac == -1)                                   # two-valued autocorrelation of an m-sequence
        runs = 1 + int(np.sum(b[1:] != b[:-1]))
        assert runs == 2**(stages - 1) <= 8                       # fits the helm's eight phases


def test_input_design_comparison(scenarios_dir, tmp_path):
    """The inputs agenda (zig-zags, turns, pull-outs, PRBS rudder) runs; the KVLCC2 L7 is course-
    unstable (Y&Y 2015), so its pull-outs keep a residual rate of the turn's sign; each maneuver's
    contribution (σ of the linear derivatives without it over σ with all) is reported, and the
    identification from the richer agenda still meets the 10 % acceptance."""
    d = tmp_path / "inputs"
    run(scenarios_dir / "kvlcc2_l7_identification_inputs.toml", d, plot=False)
    tr = {m["name"]: m["truth"] for m in json.loads((d / "results.json").read_text())["maneuvers"]}
    assert tr["pull_out_25_starboard"]["residual_rate_dps"] > 0.1
    assert tr["pull_out_25_port"]["residual_rate_dps"] < -0.1
    doc = identify_records(sorted((d / "records").glob("*.nc")), compare=())
    names = {m["name"] for m in doc["maneuvers"]}
    assert set(doc["contributions"]) == names and len(names) == 8
    for name, c in doc["contributions"].items():
        print(f"{name:<24}", {k: round(v, 3) for k, v in c.items()})
        assert set(c) == set(mmg.LINEAR) and all(0.5 < v < 3.0 for v in c.values())
    assert score(doc)["max_linear_rel_error"] < 0.10


def test_andrews_bandwidth_on_ar1_residuals():
    """Andrews (1991) AR(1) plug-in: for residuals e_t = ρ e_{t−1} + w_t the Bartlett bandwidth is
    1.1447 (4ρ² n / ((1 − ρ)²(1 + ρ)²))^(1/3); white residuals get none. Segments are not lagged across."""
    from vtrials.sysid.regression import andrews_lags
    rng = np.random.default_rng(5)
    n, rho = 20000, 0.9
    w = rng.standard_normal(n)
    e = np.empty(n)
    e[0] = w[0]
    for k in range(1, n):
        e[k] = rho * e[k - 1] + w[k]
    expected = 1.1447 * (4 * rho**2 * n / ((1 - rho)**2 * (1 + rho)**2)) ** (1 / 3)
    assert andrews_lags(e) == pytest.approx(expected, rel=0.1)
    assert andrews_lags(rng.standard_normal(n)) <= 3
    # two independent halves glued: the boundary's jump is not counted as correlation
    assert andrews_lags(np.concatenate([e[:n // 2], -e[n // 2:]]), [0, n // 2, n]) == pytest.approx(expected, rel=0.1)


def test_output_error_refinement_on_records(runs, capsys):
    """``--refine oe`` on two of the agenda's records (10/10 zig-zag, 35° turn): LM from the equation-
    error estimate fits the simulated u, v, r, ψ better; its residuals are coloured (the Newey–West
    variance several times the white one) and its 95 % intervals hold the true linear derivatives."""
    rec = runs["identification"] / "records"
    doc = identify_records([rec / "zigzag_10_10_starboard.nc", rec / "turn_35_starboard.nc"], compare=(),
                           with_contributions=False, refine="oe")
    sc = score(doc)
    oe = doc["output_error"]
    print({k: (round(oe["coefficients"][k]["value"], 4), round(sc["output_error"]["linear_rel_error"][k], 4),
               round(oe["coefficients"][k]["std"], 4)) for k in mmg.LINEAR}, oe["rms_weighted"], oe["lags"],
          oe["fixed_b"], {k: round(v, 1) for k, v in oe["n_over_n_eff"].items() if k in mmg.LINEAR})
    assert set(oe["coefficients"]) == set(doc["coefficients"]) and oe["channels"] == ["u", "v", "r", "psi"]
    assert oe["improved"] and oe["rms_weighted"]["refined"] < oe["rms_weighted"]["start"]
    assert all(oe["n_over_n_eff"][k] > 2.0 for k in mmg.LINEAR)
    assert oe["fixed_b"] > 1.0
    for k in mmg.LINEAR:
        c = oe["coefficients"][k]
        assert c["std"] ** 2 == pytest.approx(c["std_random"] ** 2 + c["std_systematic"] ** 2)
        assert sc["output_error"]["coefficients"][k]["covered"], k
    with pytest.raises(InputError, match="refine"):
        identify_records([rec / "zigzag_10_10_starboard.nc"], refine="lm")


def test_hac_sigmas_match_lag_by_lag_newey_west():
    """The FFT form of the Newey–West sums equals the lag-by-lag one (two segments, never lagged
    across their boundary)."""
    from vtrials.sysid.regression import hac_sigmas, ols
    rng = np.random.default_rng(11)
    A = rng.standard_normal((700, 3))
    y = A @ [1.0, -2.0, 0.5] + np.convolve(rng.standard_normal(720), np.ones(21) / 21, mode="valid")
    bounds = [0, 300, 700]
    fit = ols(A, y, ("a", "b", "c"), bounds, 0)
    got = hac_sigmas(A, y, fit.coef, bounds, (0, 7, 60))
    for L in (0, 7, 60):
        np.testing.assert_allclose(got[L], ols(A, y, ("a", "b", "c"), bounds, L).sigma(), rtol=1e-10)


def test_plateau_sigma_on_white_plus_slow_residuals():
    """Residuals = white noise + a slow AR(1) error (ρ = 0.99 per sample), the mixture the hull-force
    residuals are: Andrews' AR(1) rule sees the white part's lag-1 correlation (≈ 0.08) and its σ falls
    well short of the estimate's true scatter over 200 Monte Carlo replicates; the plateau σ (largest
    over the bandwidths) is within 15 % of it. Three segments, a slowly varying regressor."""
    from vtrials.sysid.identify import LAG_LADDER
    from vtrials.sysid.regression import andrews_lags, ols, plateau_sigma
    rng = np.random.default_rng(21)
    n, rho = 2400, 0.99
    t = np.arange(n) * 0.05
    A = np.column_stack([np.sin(2 * np.pi * t / 40.0), np.ones(n)])
    A = np.vstack([A, A, A])
    bounds = [0, n, 2 * n, 3 * n]
    est, s_and, s_pl, lags = [], [], [], []
    for _ in range(200):
        slow = np.empty(3 * n)
        w = rng.standard_normal(3 * n) * 0.3 * np.sqrt(1 - rho**2)
        for a in bounds[:-1]:
            slow[a] = rng.standard_normal() * 0.3
            for k in range(a + 1, a + n):
                slow[k] = rho * slow[k - 1] + w[k]
        y = A @ [0.5, 0.0] + rng.standard_normal(3 * n) + slow
        f = ols(A, y, ("a", "c"), bounds, "auto")
        est.append(f.coef[0])
        s_and.append(f.sigma()[0])
        s_pl.append(plateau_sigma(A, y, f.coef, bounds, LAG_LADDER)[0][0])
        lags.append(andrews_lags(y - A @ f.coef, bounds))
    sd = np.std(est)
    print(f"true sd {sd:.4f}; Andrews ({np.median(lags):.0f} lags) {np.mean(s_and):.4f}; plateau {np.mean(s_pl):.4f}")
    assert np.mean(s_and) < 0.8 * sd
    assert np.mean(s_pl) == pytest.approx(sd, rel=0.15)
