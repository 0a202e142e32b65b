"""Current: forces use velocity through the water, positions integrate velocity over ground.

Acceptance (issue 2): a turning circle in a uniform steady current equals the calm-water one
translated by current × time (within 0.1 % of L), with identical velocities through the water.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from vtrials.physics import steering as H
from vtrials.physics.environment.current import Current, current_at, current_numpy, pack
from vtrials.physics.simulator import Simulator
from vtrials.units import KNOT, froude_to_speed
from vtrials.physics.vessel import load_vessel


def test_turn_in_uniform_current_is_translated_calm_turn():
    v = load_vessel("kvlcc2_l7")
    Vc = 0.35  # m/s, 30 % of the approach speed
    cur = Current(speed_kn=Vc / KNOT, direction_deg=30.0)
    envs = np.stack([pack(Current(), 8.05), pack(cur, 8.05)])
    sim = Simulator(v, 2, 0.01, envs=envs)
    s = sim.self_propulsion(0, froude_to_speed(0.142, 7.0))
    sim.set_state(1, s)
    for i in range(2):
        sim.set_helm(i, [(H.HOLD, math.radians(35.0))])
    sim.step(15000)
    tr = sim.truth()
    col = {n: j for j, n in enumerate(sim.rec_names)}
    t = tr[:, 0, 0]
    vc = np.array([math.cos(math.radians(30.0)), math.sin(math.radians(30.0))]) * Vc
    dx = tr[:, 1, col["x"]] - vc[0] * t - tr[:, 0, col["x"]]
    dy = tr[:, 1, col["y"]] - vc[1] * t - tr[:, 0, col["y"]]
    assert np.abs(np.hypot(dx, dy)).max() < 0.001 * v.length
    for name in ("u_r", "v_r", "w_r", "r", "roll", "pitch", "z", "heading", "shaft_n_0"):
        np.testing.assert_allclose(tr[:, 1, col[name]], tr[:, 0, col[name]], rtol=0,
                                   atol=1e-7 * max(1.0, np.abs(tr[:, 0, col[name]]).max()), err_msg=name)
    # the heading turned through 360° and the track over ground is no circle at all
    assert tr[-1, 0, col["heading"]] > 2 * math.pi
    assert np.hypot(tr[-1, 1, col["x"]] - tr[-1, 0, col["x"]], tr[-1, 1, col["y"]] - tr[-1, 0, col["y"]]) > 20.0
    # the water track (position minus integrated current) is the calm track
    np.testing.assert_allclose(tr[:, 1, col["x"]] - tr[:, 1, col["drift_n"]], tr[:, 0, col["x"]], atol=1e-3 * 7.0)


def test_current_field_conventions():
    """Directions are where the water goes to; tidal phase 0 is maximum flood; gradient per nmi."""
    e = pack(Current(speed_kn=1.0, direction_deg=90.0), 100.0)
    vn, ve, an, ae = current_at(e, 0.0, 0.0, 0.0)
    assert (vn, ve) == pytest.approx((0.0, KNOT))
    assert (an, ae) == pytest.approx((0.0, 0.0))
    T = 12.42 * 3600.0
    e = pack(Current(tidal_amplitude_kn=2.0, tidal_direction_deg=0.0), 100.0)
    assert current_at(e, 0, 0, 0.0)[:2] == pytest.approx((2 * KNOT, 0.0))
    assert current_at(e, 0, 0, T / 4)[:2] == pytest.approx((0.0, 0.0), abs=1e-12)
    assert current_at(e, 0, 0, T / 2)[:2] == pytest.approx((-2 * KNOT, 0.0))
    # partial time derivative against a central difference
    e = pack(Current(speed_kn=0.5, tidal_amplitude_kn=1.5, tidal_direction_deg=40.0, tidal_phase_deg=70.0,
                     trend_kn_per_h=0.3, trend_direction_deg=200.0), 100.0)
    for t in (0.0, 1000.0, 20000.0):
        h = 1.0
        num = (np.array(current_at(e, 5, 5, t + h)[:2]) - np.array(current_at(e, 5, 5, t - h)[:2])) / (2 * h)
        assert np.array(current_at(e, 5, 5, t)[2:]) == pytest.approx(num, rel=1e-6, abs=1e-12)
    # a linear trend: +0.6 kn/h towards 090
    e = pack(Current(trend_kn_per_h=0.6, trend_direction_deg=90.0), 100.0)
    assert current_at(e, 0, 0, 1800.0)[:2] == pytest.approx((0.0, 0.3 * KNOT))
    # a gradient: 1 kn current to the north growing by 0.2 kn per nmi eastward
    e = pack(Current(speed_kn=1.0, direction_deg=0.0, gradient_kn_per_nmi=0.2, gradient_axis_deg=90.0), 100.0)
    assert current_at(e, 0.0, 1852.0, 0.0)[:2] == pytest.approx((1.2 * KNOT, 0.0))
    assert current_at(e, 3000.0, -926.0, 0.0)[:2] == pytest.approx((0.9 * KNOT, 0.0))
    # the numpy twin agrees
    xs = np.array([0.0, 100.0, -500.0])
    vn, ve = current_numpy(e, xs, xs * 2, xs * 10)
    for k in range(3):
        assert (vn[k], ve[k]) == pytest.approx(current_at(e, xs[k], 2 * xs[k], 10 * xs[k])[:2])


def test_forces_follow_water_in_tidal_current():
    """With a time-varying current the through-water state of a ship on autopilot is unaffected by the
    current's absolute value to first order: the speed through the water stays at the approach speed
    while the speed over ground swings with the tide."""
    v = load_vessel("kvlcc2")
    T = 600.0  # a short 'tide' so that the test sees a full period
    cur = Current(tidal_amplitude_kn=1.0, tidal_direction_deg=0.0, tidal_period_h=T / 3600.0)
    sim = Simulator(v, 1, 0.05, envs=pack(cur, 1000.0))
    U = 7.0
    s = sim.self_propulsion(0, U)
    sim.set_helm(0, [(H.HEADING, 0.0, math.radians(10.0), 3.0, 3.0 / 406.0, 3.0 * 27.0)])
    sim.step(int(T / 0.05))
    tr = sim.truth()
    col = {n: j for j, n in enumerate(sim.rec_names)}
    sog = np.hypot(tr[:, 0, col["u"]], tr[:, 0, col["v"]])
    stw = np.hypot(tr[:, 0, col["u_r"]], tr[:, 0, col["v_r"]])
    assert sog.max() - sog.min() > 1.8 * KNOT * 0.9
    assert stw.max() - stw.min() < 0.02 * U
    assert s.shaft_rps[0] > 0


def test_drifting_ship_moves_with_accelerating_water():
    """No thrust, no rudder, at rest in the water: in a quickly varying tidal stream (Froude–Krylov
    pressure force plus added mass) the ship is carried along and stays at rest relative to it."""
    v = load_vessel("kvlcc2_l7")
    cur = Current(tidal_amplitude_kn=1.0, tidal_direction_deg=45.0, tidal_period_h=60.0 / 3600.0)
    sim = Simulator(v, 1, 0.01, envs=pack(cur, 100.0))
    from vtrials.physics.simulator import ShipState
    sim.set_state(0, ShipState(heading=0.3, shaft_rps=(0.0,)))
    sim.step(6000)
    tr = sim.truth()
    col = {n: j for j, n in enumerate(sim.rec_names)}
    sog = np.hypot(tr[:, 0, col["u"]], tr[:, 0, col["v"]])
    stw = np.hypot(tr[:, 0, col["u_r"]], tr[:, 0, col["v_r"]])
    assert sog.max() > 0.9 * KNOT
    assert stw.max() < 0.01 * sog.max()
