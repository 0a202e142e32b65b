"""System identification of the patrol vessel's 4-DOF hull (issue 16) from SIMULATOR records:
scenarios/patrol51_identification.toml (zig-zags 5/5, 10/10, 15/15, turns 25° starboard and 15° port at
Ahead 2/3; zig-zag 10/10 and a 20° turn at Standard), the 25° port turn and the 20/20 zig-zag held back.

Independent references: the team's 4-DOF model (vtrials.sysid.blanke) is checked component by
component against the simulator's own force records (MuJoCo 6-DOF with heave and pitch; the team's
model is 4-DOF and written separately); the true coefficients are the model file's (BC93); the
held-back truths are the simulator's runs of those maneuvers.
"""

import h5py
import numpy as np
import pytest

from vtrials import run
from vtrials.score.identification import score, true_coefficients
from vtrials.sysid import blanke
from vtrials.sysid import predict as PR
from vtrials.sysid.identify import identify_records
from vtrials.sysid.regression import Segment

HELD = ("turn_25_port", "zigzag_20_20_starboard")


@pytest.fixture(scope="module")
def ident_run(tmp_path_factory, scenarios_dir):
    d = tmp_path_factory.mktemp("p51ident")
    run(scenarios_dir / "patrol51_identification.toml", d, plot=False)
    return d


@pytest.fixture(scope="module")
def identified(ident_run):
    recs = sorted((ident_run / "records").glob("*.nc"))
    train = [p for p in recs if p.stem not in HELD]
    held = [ident_run / "records" / f"{h}.nc" for h in HELD]
    doc = identify_records(train, held_back=held, with_contributions=False)
    return doc, score(doc)


def _truth_segment(g):
    """A maneuver's TRUE motion as the records' reconstruction gives it (levelled-frame sway and yaw
    rate, body surge), with the true rudder, shaft rate and pitch."""
    a = {k: g[k][()] for k in g.keys()}
    phi, p = a["roll"], a["p"]
    c = np.cos(phi)
    seg = Segment(a["time"], a["u_r"], a["v_r"] / c, a["r"] / c, a["du"], a["dv"] / c + a["v_r"] * np.tan(phi) * p / c,
                  a["dr"] / c + a["r"] * np.tan(phi) * p / c, 0.5 * (a["rudder_0"] + a["rudder_1"]),
                  0.5 * (a["shaft_n_0"] + a["shaft_n_1"]), phi, p, a["dp"], 0.5 * (a["pitch_0"] + a["pitch_1"]))
    return a, seg


def test_team_model_matches_the_simulators_forces(ident_run):
    """The known parts of the team's 4-DOF model against the simulator's force records: propellers and
    rudders within 0.01 % (same published equations, written twice). The hull forces that inverse
    dynamics leaves from the TRUE motion: within 1.5 % RMS of the true hull forces in sway, roll and yaw
    and 3 % in surge at 13 kn; at 18 kn in a 20° turn up to 2.5 % in sway. What the team's model leaves
    out accounts for all of it: the still-air windage, the simulator's net weight-and-buoyancy force of
    the heeled, sunk hull (6-DOF, beyond the team's GM restoring) and its pitch-rate terms — with those
    added back the difference is under 0.3 % (0.6 % in surge: the tank table's 1 m/s steps)."""
    ship = blanke.patrol51()
    m, g0 = ship.m, 9.80665
    with h5py.File(ident_run / "truth.nc") as f:
        for name in ("zigzag_15_15_starboard", "turn_20_starboard_standard"):
            a, seg = _truth_segment(f[name])
            P = ship.propeller_rudder_forces(seg.u, a["v_r"], a["r"], seg.delta, seg.n, seg.pitch)
            H = ship.hull_samples(seg)
            # the simulator's parts the team's model does not have (body axes, at the origin)
            gy = m * g0 * np.cos(a["pitch"]) * np.sin(a["roll"])
            gx = -m * g0 * np.sin(a["pitch"])
            team_restoring = -ship.rho * g0 * ship.volume * ship.GM * np.sin(a["roll"])
            omitted = {"X": a["F_hydrostatics_X"] + gx + a["F_wind_X"],
                       "Y": a["F_hydrostatics_Y"] + gy + a["F_wind_Y"] + m * ship.z_G * a["q"] * a["r"],
                       "K": a["F_hydrostatics_K"] - ship.z_G * gy + a["F_wind_K"] - team_restoring,
                       "N": a["F_hydrostatics_N"] + ship.x_G * gy + a["F_wind_N"]}
            for i, e in enumerate("XYKN"):
                tru = sum(a[f"F_{c}_{e}"] for c in ("propeller:port", "propeller:starboard", "rudder:port",
                                                   "rudder:starboard"))
                assert np.sqrt(np.mean((P[i] - tru) ** 2)) < 1e-4 * np.sqrt(np.mean(tru ** 2)) + 1e-3, (name, e)
                # surge: the whole hull force, the team's tank resistance (R/u² between 1 m/s steps) included
                got = H[e] - (ship.resistance(seg.u) if e == "X" else 0.0)
                hull = a[f"F_hull_{e}"]
                size = np.sqrt(np.mean(hull ** 2))
                rel = np.sqrt(np.mean((got - hull) ** 2)) / size
                rest = np.sqrt(np.mean((got - hull - omitted[e]) ** 2)) / size
                print(name, e, "inverse-dynamics hull force error (RMS, relative)", round(float(rel), 4),
                      "with the omitted parts added back", round(float(rest), 4))
                assert rel < (0.03 if e == "X" else 0.025 if name.endswith("standard") else 0.015), (name, e, rel)
                assert rest < (0.006 if e == "X" else 0.003), (name, e, rest)


def test_approach_assumptions_hold_for_the_twin_screw_ship(ident_run):
    """The team zeroes the rudder synchros and the heading reference on the straight approach, assuming
    rudders amidships and no drift angle there (twin outward-turning screws, calm water): the truth
    confirms both (< 0.01°), and the zeroed rudder record matches the true rudder within 4 stated σ."""
    from vtrials.sysid import records as RE
    with h5py.File(ident_run / "truth.nc") as f:
        for name in ("zigzag_10_10_starboard", "turn_25_starboard"):
            g = f[name]
            t = g["time"][:]
            ex = float(np.ravel(g.attrs["execute_time_s"])[0])
            k = (t > 3.0) & (t < ex)
            assert abs(np.degrees(np.mean(0.5 * (g["rudder_0"][k] + g["rudder_1"][k])))) < 0.01
            assert np.degrees(np.abs(np.arctan2(g["v_r"][k], g["u_r"][k])).max()) < 0.01
            mr = RE.read_maneuver(ident_run / "records" / f"{name}.nc")
            true = np.interp(mr.t, t, 0.5 * (g["rudder_0"][:] + g["rudder_1"][:]))
            off = float(np.mean(mr.delta - true))
            print(name, "rudder zero left", np.degrees(off), "deg; stated", np.degrees(mr.rudder_sd))
            assert 0 < mr.rudder_sd < np.radians(0.05) and abs(off) < 4 * mr.rudder_sd


def test_team_prediction_with_true_coefficients_reproduces_the_simulator(ident_run, identified):
    """The team's 4-DOF RK4 prediction with the TRUE hull coefficients against the simulator's own runs
    of the held-back maneuvers: turn within 1 %, overshoots within 0.2° (the prediction's own error,
    before any identification error)."""
    import json
    truth = {m["name"]: m["truth"] for m in json.loads((ident_run / "results.json").read_text())["maneuvers"]}
    ship = blanke.patrol51()
    coeffs = true_coefficients("patrol51")
    doc, _ = identified
    ap = {p["name"]: p["approach"] for p in doc["predictions"]}
    a = ap["turn_25_port"]
    turn = PR.turning_circle(ship, coeffs, a["speed_mps"], a["shaft_rps"], -25.0, pitch=a["pitch_ratio"])
    for k in ("advance_m", "transfer_m", "tactical_diameter_m"):
        assert turn[k] == pytest.approx(truth["turn_25_port"][k], rel=0.01), k
    a = ap["zigzag_20_20_starboard"]
    zz = PR.zigzag(ship, coeffs, a["speed_mps"], a["shaft_rps"], 20.0, 20.0, 1, pitch=a["pitch_ratio"])
    for k in ("first_overshoot_deg", "second_overshoot_deg"):
        assert abs(zz[k] - truth["zigzag_20_20_starboard"][k]) < 0.2, k


def test_patrol51_linear_derivatives_and_held_back_predictions(identified):
    """Acceptance of issue 16 for patrol51: Y_|u|v, Y_ur, N_|u|v, N_|u|r within 10 %; the held-back 25°
    turn within 5 % on advance and tactical diameter, the 20/20 zig-zag's overshoots within 1.5°."""
    doc, sc = identified
    print("linear relative errors", {k: round(v, 4) for k, v in sc["linear_rel_error"].items()},
          "sigma rel", {k: round(doc["coefficients"][k]["std"] / abs(doc["coefficients"][k]["value"]), 4)
                        for k in blanke.LINEAR}, "worst", sc["worst"])
    assert doc["structure"] == "blanke4" and doc["units"].startswith("SI")
    assert set(sc["linear_rel_error"]) == set(blanke.LINEAR)
    assert sc["max_linear_rel_error"] < 0.10
    assert sc["verdict"] == {"linear_within_10pct": True, "turns_within_5pct": True, "overshoots_within_1p5deg": True}
    assert len(sc["predictions"]) == 2 and sc["worst"]["turn_rel"] > 0
    # the CP propellers' pitch indicators are among the record-wide errors, with the stated zero error
    assert all(0.005 < e["pitch"] < 0.05 for e in doc["record_errors"].values())
    # leave-one-maneuver-out cross-validation prefers BC93's heel terms in yaw and sway (yaw: 31 vs 55 kN m
    # on this seed); in roll it does not (the records' heel carries the vertical reference's 0.1° zero)
    cv = doc["cross_validation"]
    assert cv["blanke4"]["N"] < 0.8 * cv["blanke3"]["N"] and cv["blanke4"]["Y"] < cv["blanke3"]["Y"]
