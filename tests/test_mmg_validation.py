"""The MuJoCo KVLCC2 L7 against an independent scipy integration of the same 3-DOF MMG equations.

The reference (tests/reference/mmg3dof.py) was written from the equations alone and shares no
code with vtrials. The simulator runs all 6 DOF (heave, roll and pitch free) through the real
scenario files, so these tests also cover scenario loading, the crew's EXECUTE and the truth
metrics. Acceptance (issue 2): advance, transfer and tactical diameter within 1 %, first and
second overshoot within 0.3°, self-propulsion r/min within 0.5 %.
"""

from __future__ import annotations

import math

import pytest

from tests.reference import mmg3dof as ref
from vtrials.physics import steering as H
from vtrials.runner.side_by_side import simulate
from vtrials.scenario import load_scenario
from vtrials.physics.simulator import Simulator
from vtrials.units import froude_to_speed
from vtrials.physics.vessel import load_vessel

U0 = froude_to_speed(0.142, 7.0)


@pytest.fixture(scope="module")
def n_ref():
    return ref.self_propulsion_rps(ref.KVLCC2_L7, U0)


@pytest.fixture(scope="module")
def turning(scenarios_dir):
    return simulate(load_scenario(scenarios_dir / "kvlcc2_l7_turning.toml"))


@pytest.fixture(scope="module")
def zigzag(scenarios_dir):
    return simulate(load_scenario(scenarios_dir / "kvlcc2_l7_zigzag.toml"))


def test_reference_parameters_match_model_file():
    """The reference's hand-typed coefficients and the model file agree (catches typos in either)."""
    v = load_vessel("kvlcc2_l7")
    h, pr, rd, am = v.hull, v.propellers[0], v.rudders[0], v.added_mass
    p = ref.KVLCC2_L7
    pairs = {"R0": h.R0, "Xvv": h.X_vv, "Xvr": h.X_vr, "Xrr": h.X_rr, "Xvvvv": h.X_vvvv, "Yv": h.Y_v,
             "Yr": h.Y_r, "Yvvv": h.Y_vvv, "Yvvr": h.Y_vvr, "Yvrr": h.Y_vrr, "Yrrr": h.Y_rrr, "Nv": h.N_v,
             "Nr": h.N_r, "Nvvv": h.N_vvv, "Nvvr": h.N_vvr, "Nvrr": h.N_vrr, "Nrrr": h.N_rrr,
             "mx": am.m_x_prime, "my": am.m_y_prime, "Jz": am.J_z_prime, "t_P": pr.t_P, "w_P0": pr.w_P0,
             "xP": pr.x_P_prime, "k0": pr.k0, "k1": pr.k1, "k2": pr.k2, "C1": pr.C1, "C2_pos": pr.C2_pos,
             "C2_neg": pr.C2_neg, "D_P": pr.diameter, "t_R": rd.t_R, "a_H": rd.a_H, "xH": rd.x_H_prime,
             "gammaR_neg": rd.gamma_R_neg, "gammaR_pos": rd.gamma_R_pos, "lR": rd.l_R_prime, "eps": rd.epsilon,
             "kappa": rd.kappa, "f_alpha": rd.f_alpha, "A_R": rd.area, "H_R": rd.span, "L": v.length,
             "d": v.particulars.draught, "disp": v.particulars.displacement, "x_G": v.particulars.x_G,
             "rho": v.particulars.water_density}
    for k, val in pairs.items():
        assert val == pytest.approx(p[k], rel=1e-12), k
    assert rd.x == pytest.approx(-0.5 * v.length)
    assert math.radians(rd.rate_deg_s) == pytest.approx(p["delta_rate_max"])
    assert rd.time_constant == pytest.approx(p["T_delta"])


def test_self_propulsion_rpm(turning, n_ref):
    n = turning.initial["shaft_rps"][0]
    assert n == pytest.approx(n_ref, rel=0.005)
    # it is the same equation solved two ways: far tighter than the acceptance bound
    assert n == pytest.approx(n_ref, rel=1e-9)


@pytest.mark.parametrize("name,rudder", [("turn_35_starboard", 35.0), ("turn_35_port", -35.0)])
def test_turning_circle_matches_reference(turning, n_ref, name, rudder):
    res = ref.turning_metrics(ref.simulate(ref.KVLCC2_L7, U0, n_ref, ref.TurningCircle(rudder), 400.0), 7.0)
    m = next(x for x in turning.maneuvers if x.name == name)
    assert m.completed
    for key in ("advance_m", "transfer_m", "tactical_diameter_m"):
        assert m.truth[key] == pytest.approx(res[key], rel=0.01), key
    for key in ("steady_turning_diameter_m", "steady_speed_mps", "steady_rate_of_turn_dps"):
        assert m.truth[key] == pytest.approx(res[key], rel=0.01), key


@pytest.mark.parametrize("name,delta,side", [("zigzag_10_10_starboard", 10, 1), ("zigzag_10_10_port", 10, -1),
                                             ("zigzag_20_20_starboard", 20, 1), ("zigzag_20_20_port", 20, -1)])
def test_zigzag_matches_reference(zigzag, n_ref, name, delta, side):
    res = ref.zigzag_metrics(ref.simulate(ref.KVLCC2_L7, U0, n_ref, ref.ZigZag(delta, delta, side), 300.0))
    m = next(x for x in zigzag.maneuvers if x.name == name)
    assert m.completed
    assert m.truth["first_overshoot_deg"] == pytest.approx(res["first_overshoot_deg"], abs=0.3)
    assert m.truth["second_overshoot_deg"] == pytest.approx(res["second_overshoot_deg"], abs=0.3)
    assert m.truth["initial_turning_time_s"] == pytest.approx(res["initial_turning_time_s"], abs=0.1)


def test_planar_mode_converges_to_reference(n_ref):
    """With heave, roll and pitch held, the remaining difference is time discretization: it must
    shrink when the step is halved (first-order Euler), pinning that nothing else differs."""
    v = load_vessel("kvlcc2_l7")
    res = ref.turning_metrics(ref.simulate(ref.KVLCC2_L7, U0, n_ref, ref.TurningCircle(35.0), 400.0), 7.0)
    errs = []
    for dt in (0.02, 0.01):
        sim = Simulator(v, 1, dt, planar=True)
        s = sim.self_propulsion(0, U0)
        sim.set_helm(0, [(H.HOLD, math.radians(35.0))])
        sim.step(int(round(70.0 / dt)))
        from vtrials.truth.columns import ship_columns
        from vtrials.truth import metrics as TM
        c = ship_columns(sim.truth(), sim.rec_names, 0, sim.dt)
        m = TM.turning(c["t"], c["x_w"], c["y_w"], c["heading"], c["u_r"], c["v_r"], c["r"])
        errs.append(abs(m["tactical_diameter_m"] / res["tactical_diameter_m"] - 1)
                    + abs(m["advance_m"] / res["advance_m"] - 1))
        assert s.roll == 0.0 and s.z == 0.0
        assert abs(c["roll"]).max() < 1e-6 and abs(c["z"]).max() < 1e-6  # rounding only
    assert errs[1] < 0.7 * errs[0]
    assert errs[1] < 0.002


def test_positive_rudder_turns_to_starboard(turning):
    """Sign convention: δ > 0 (trailing edge to starboard) turns the ship to starboard (ψ increases),
    and the ship heels outward (to port, negative roll) in the steady turn."""
    stb = next(x for x in turning.maneuvers if x.name == "turn_35_starboard").columns
    port = next(x for x in turning.maneuvers if x.name == "turn_35_port").columns
    assert stb["rudder_0"].max() == pytest.approx(math.radians(35.0), rel=1e-6)
    assert stb["heading"][-1] - stb["heading"][0] > math.radians(700)
    assert port["heading"][-1] - port["heading"][0] < -math.radians(700)
    assert stb["roll"][-1] < 0 < port["roll"][-1]
