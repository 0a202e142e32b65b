"""The patrol vessel and the crash stops: heel in turns, stopping of both ships, scenario runs."""

from __future__ import annotations

import math

import numpy as np
import pytest

from vtrials.physics import steering as H
from vtrials.runner.side_by_side import simulate
from vtrials.scenario import load_scenario
from vtrials.physics.simulator import Simulator
from vtrials.physics.vessel import load_vessel


@pytest.fixture(scope="module")
def heel_matrix():
    """Steady heel [deg] of 200-s turns: rows approach orders (2/3, standard, full, flank), columns
    rudder 5…20° (below the 23° stall) to starboard, plus the mirror runs to port."""
    v = load_vessel("patrol51")
    orders = ["ahead_2_3", "standard", "full", "flank"]
    rudders = [5.0, 10.0, 15.0, 20.0, -20.0]
    sim = Simulator(v, len(orders) * len(rudders), 0.02)
    k = 0
    for o in orders:
        rps, pd = v.telegraph[o]
        for d in rudders:
            s = sim.steady_at_order(k, (rps, rps), (pd, pd))
            sim.set_state(k, s)
            sim.set_helm(k, [(H.HOLD, math.radians(d))])
            k += 1
    sim.step(int(200 / 0.02))
    roll = sim.truth()[:, :, sim.rec_names.index("roll")]
    return np.degrees(roll[-int(50 / 0.02):].mean(axis=0)).reshape(len(orders), len(rudders))


def test_steady_turns_heel_outward(heel_matrix):
    assert np.all(heel_matrix[:, :4] < 0)   # starboard turns heel to port
    assert np.all(heel_matrix[:, 4] > 0)    # port turns heel to starboard
    np.testing.assert_allclose(heel_matrix[:, 4], -heel_matrix[:, 3], rtol=1e-6)  # mirror image


def test_heel_grows_with_speed_and_rudder(heel_matrix):
    outward = -heel_matrix[:, :4]
    assert np.all(np.diff(outward, axis=0) > 0)  # faster approach → more heel, at every rudder angle
    assert np.all(np.diff(outward, axis=1) > 0)  # more rudder (below stall) → more heel, at every speed


def test_heel_comes_from_the_physics_not_a_formula():
    """With the hull's heel-dependent terms and the rudder's lever as they are, the 35° turn at full
    first heels INWARD (rudder force low on the hull) before the centrifugal heel takes over."""
    v = load_vessel("patrol51")
    sim = Simulator(v, 1, 0.02)
    rps, pd = v.telegraph["full"]
    sim.steady_at_order(0, (rps, rps), (pd, pd))
    sim.set_helm(0, [(H.HOLD, math.radians(35.0))])
    sim.step(int(60 / 0.02))
    roll = np.degrees(sim.truth()[:, 0, sim.rec_names.index("roll")])
    assert roll.max() > 0.5 and roll.min() < -5.0
    assert np.argmax(roll) < np.argmin(roll)


@pytest.fixture(scope="module")
def kvlcc2_stop(scenarios_dir):
    return simulate(load_scenario(scenarios_dir / "kvlcc2_crash_stop.toml"))


def test_kvlcc2_crash_stop(kvlcc2_stop):
    m = {x.name: x for x in kvlcc2_stop.maneuvers}["crash_stop_rudder_amidships"]
    assert m.completed
    t = m.truth
    L = 320.0
    assert 0 < t["track_reach_m"] <= 15 * L        # IMO MSC.137(76): ≤ 15 L
    assert t["track_reach_m"] >= t["head_reach_m"] > 5 * L
    assert 600 < t["time_to_dead_in_water_s"] < 1200
    # a right-handed screw backing swings the bow to starboard
    assert t["heading_change_deg"] > 10 and t["lateral_deviation_m"] > 0
    c = m.columns
    assert np.all(np.isfinite(c["u"]))
    n = c["shaft_n_0"]
    assert n[-1] < 0  # the shaft was reversed
    speed = kvlcc2_stop.maneuvers[2]
    assert speed.completed and speed.truth["terminal_speed_mps"] < speed.truth["initial_speed_mps"]


def test_patrol51_scenario(scenarios_dir):
    res = simulate(load_scenario(scenarios_dir / "patrol51_maneuvers.toml"))
    by = {m.name: m for m in res.maneuvers}
    assert all(m.completed for m in res.maneuvers), [m.name for m in res.maneuvers if not m.completed]
    cs = by["crash_stop_flank_back_emergency"].truth
    assert 0 < cs["time_to_dead_in_water_s"] < 60 and 0 < cs["track_reach_m"] < 10 * 51.5
    acc = by["acceleration_diw_to_flank"].truth
    assert acc["initial_speed_mps"] < 0.1 and acc["terminal_speed_mps"] > 14.0
    assert 0 < acc["time_to_terminal_speed_s"] < 300 and acc["reach_m"] > 0
    for o in ("2_3", "full", "flank"):
        for d in ("15", "35"):
            stb = by[f"turn_{d}_stbd_{o}"].truth
            port = by[f"turn_{d}_port_{o}"].truth
            assert stb["steady_heel_deg"] < 0 < port["steady_heel_deg"]
            assert stb["max_heel_deg"] < 0 < port["max_heel_deg"]
            assert abs(stb["max_heel_deg"]) >= abs(stb["steady_heel_deg"])
    assert by["locked_port_shaft_standard"].truth["mean_shaft_rps_0"] == pytest.approx(0.0, abs=1e-9)
    assert by["trailed_port_shaft_standard"].truth["mean_shaft_rps_0"] > 1.0
    for name in ("trailed_port_shaft_standard", "locked_port_shaft_standard"):
        assert by[name].truth["mean_shaft_power_W_0"] == pytest.approx(0.0, abs=1e-6)
