"""Force components, steering gear, shaft governor and helm programs, each checked on its own."""

from __future__ import annotations

import math

import numpy as np
import pytest

from vtrials.physics import steering as H
from vtrials.physics.forces import context as L
from vtrials.physics.simulator import ShipState, Simulator
from vtrials.units import froude_to_speed
from vtrials.physics.vessel import load_vessel

U0 = froude_to_speed(0.142, 7.0)


@pytest.fixture(scope="module")
def vessel():
    return load_vessel("kvlcc2_l7")


def test_steering_gear_rate_limit_and_clamp(vessel):
    sim = Simulator(vessel, 2, 0.01)
    s = sim.self_propulsion(0, U0)
    sim.set_state(1, s)
    sim.set_helm(0, [(H.HOLD, math.radians(35.0))])
    sim.set_helm(1, [(H.HOLD, math.radians(-50.0))])  # beyond the maximum: the gear stops at 35°
    sim.step(500)
    c = sim.truth()
    d = np.degrees(c[:, :, sim.rec_names.index("rudder_0")])
    t = c[:, 0, 0]
    rate = np.diff(d, axis=0) / 0.01
    assert rate.max() == pytest.approx(15.8, rel=1e-9)
    assert rate.min() == pytest.approx(-15.8, rel=1e-9)
    k1 = np.searchsorted(t, 1.0)
    assert d[k1, 0] == pytest.approx(15.8, abs=0.16)
    assert d[:, 0].max() <= 35.0 + 1e-9 and d[:, 1].min() >= -35.0 - 1e-9
    assert d[-1, 0] == pytest.approx(35.0, abs=1e-3) and d[-1, 1] == pytest.approx(-35.0, abs=1e-3)


def test_governor_holds_rpm_in_a_turn_and_engine_limits(vessel):
    sim = Simulator(vessel, 2, 0.01)
    s = sim.self_propulsion(0, U0)
    sim.set_state(1, s)
    sim.set_helm(0, [(H.HOLD, math.radians(35.0))])
    sim.shaft_cmd[1, 0] = 25.0   # far more than the 1 kW motor can turn at this speed
    sim.step(3000)
    c = sim.truth()
    col = {n: j for j, n in enumerate(sim.rec_names)}
    n0 = c[:, 0, col["shaft_n_0"]]
    assert np.abs(n0 / s.shaft_rps[0] - 1).max() < 1e-3
    q = c[:, 1, col["engine_torque_0"]]
    n1 = c[:, 1, col["shaft_n_0"]]
    sh = vessel.shafts[0]
    assert np.all(np.abs(q) <= sh.max_torque * (1 + 1e-12))
    assert np.all(np.abs(q * 2 * math.pi * n1) <= sh.max_power * (1 + 1e-9))
    assert q[-1] * 2 * math.pi * n1[-1] == pytest.approx(sh.max_power, rel=1e-6)  # power-limited
    assert n1[-1] < 25.0


def test_straight_ahead_component_signs(vessel):
    sim = Simulator(vessel, 1, 0.01)
    s = sim.self_propulsion(0, U0)
    sim.evaluate()
    w = {n: sim.comp_w[0, k] for k, n in enumerate(sim.comp_names)}
    assert w["hull"][0] < 0 < w["propeller:main"][0]
    assert w["hull"][0] + w["propeller:main"][0] + w["rudder:main"][0] == pytest.approx(0.0, abs=1e-9)
    J = sim.aux[0, L.AUX_PROP + L.P_J]
    assert J == pytest.approx(U0 * 0.6 / (s.shaft_rps[0] * 0.216), rel=1e-12)
    # rudder to starboard at speed: normal force > 0, side force to port, yaw moment to starboard
    s.rudder = math.radians(20.0)
    sim.set_state(0, s)
    sim.evaluate()
    wr = sim.comp_w[0, sim.comp_names.index("rudder:main")]
    assert sim.aux[0, L.AUX_RUD + L.R_FN] > 0
    assert wr[1] < 0 < wr[5]
    assert wr[0] < 0  # steering resistance
    assert wr[3] > 0  # lateral force below the waterline to port heels the ship to starboard


def test_course_keeping_autopilot_recovers_heading(vessel):
    sim = Simulator(vessel, 1, 0.02)
    s = sim.self_propulsion(0, U0)
    s.heading = math.radians(8.0)
    sim.set_state(0, s)
    ap = vessel.autopilot
    sim.set_helm(0, [(H.HEADING, 0.0, math.radians(ap.rudder_limit_deg), *ap.pid)])
    sim.step(6000)
    c = sim.truth()
    psi = np.degrees(c[:, 0, sim.rec_names.index("heading")])
    assert abs(psi[-1]) < 0.1
    assert psi.min() > -4.0  # no wild overshoot


def test_williamson_turn_reaches_reciprocal(tmp_path, vessel):
    from vtrials.runner.side_by_side import simulate
    from vtrials.scenario import load_scenario
    p = tmp_path / "w.toml"
    p.write_text("""
[scenario]
title = "Williamson"
ship = "kvlcc2_l7"
seed = 1
timestep_s = 0.02
[initial]
froude_number = 0.142
heading_deg = 30.0
[[maneuver]]
name = "williamson_stbd"
kind = "williamson"
rudder_deg = 35.0
first_side = "starboard"
approach_s = 5.0
[[maneuver]]
name = "williamson_port"
kind = "williamson"
rudder_deg = 35.0
first_side = "port"
approach_s = 5.0
""")
    res = simulate(load_scenario(p))
    for m in res.maneuvers:
        assert m.completed
        c = m.columns
        final = math.degrees(c["heading"][-1] - c["heading"][0])
        assert abs(abs(final) - 180.0) < 1.0, final
        assert m.truth["max_heading_change_deg"] > 60.0
        assert "time_to_reciprocal_s" in m.truth
        # the point of a Williamson turn: back near the original track line
        assert abs(m.truth["cross_track_at_reciprocal_m"]) < 1.5 * vessel.length
