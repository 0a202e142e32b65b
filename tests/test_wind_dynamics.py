"""Wind acting on the simulated ship: drift and heel as the loads predict; the gusts the ship feels
have the chosen spectrum."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.signal import welch

from vtrials.physics import steering as H
from vtrials.physics.environment import wind as W
from vtrials.physics.environment.current import Current, pack
from vtrials.physics.simulator import ShipState, Simulator
from vtrials.units import KNOT
from vtrials.physics.vessel import load_vessel


def test_beam_wind_drift_and_heel_follow_the_loads():
    v = load_vessel("patrol51")
    U10 = 30 * KNOT
    env = W.pack_env(W.Wind(speed_kn=30.0, direction_deg=90.0), pack(Current(), 200.0))
    sim = Simulator(v, 1, 0.02, envs=env)
    # dead in the water, heading north: the wind comes from the starboard beam
    sim.set_state(0, ShipState(heading=0.0, shaft_rps=(0.0, 0.0)))
    sim.set_helm(0, [(H.HOLD, 0.0)])
    sim.evaluate()
    wk = sim.comp_w[0, sim.comp_names.index("wind")]
    # the load model's own prediction at this relative wind
    loads = W.wind_loads(U10, math.pi / 2, v.windage)  # reference height 10 m: the wind there is U10
    assert wk[1] < 0 and wk[3] < 0 and loads[1] < 0 and loads[3] < 0
    np.testing.assert_allclose(wk[[1, 3]], loads[[1, 3]], rtol=1e-6)
    sim.step(int(120 / 0.02))
    c = sim.truth()
    col = {n: j for j, n in enumerate(sim.rec_names)}
    assert c[-1, 0, col["y"]] < -5.0           # drifted west, to leeward
    assert c[-1, 0, col["v"]] < -0.1            # still moving to port
    roll = np.degrees(c[-int(30 / 0.02):, 0, col["roll"]]).mean()
    assert roll < -0.2                          # heeled to port, to leeward
    # the wind's own heeling moment over the restoring gives a lower bound: once the ship drifts, the
    # water's resistance to the drift acts low on the hull and adds a couple in the same sense
    K_wind = wk[3]
    phi_wind = math.degrees(K_wind / (v.particulars.water_density * 9.80665 * v.particulars.displacement
                                      * v.hydrostatics.GM_T))
    assert phi_wind < 0
    assert 1.0 * phi_wind > roll > 5.0 * phi_wind


def test_gusts_felt_by_the_ship_have_the_spectrum():
    """The true wind recorded at the ship (a ship at rest, 2 h, NPD gusts) has the NPD variance and shape."""
    v = load_vessel("patrol51")
    U10 = 20 * KNOT
    wind = W.Wind(speed_kn=20.0, direction_deg=0.0, gust_spectrum="npd", gust_components=400,
                  gust_f_min_hz=1 / 1800.0, gust_f_max_hz=0.5)
    env = W.pack_env(wind, pack(Current(), 200.0), np.random.default_rng(7))
    sim = Simulator(v, 1, 0.05, envs=env, record_every=10)  # 2 Hz record
    sim.set_state(0, ShipState(heading=0.0, shaft_rps=(0.0, 0.0)))
    sim.set_helm(0, [(H.HOLD, 0.0)])
    sim.step(int(7200 / 0.05))
    c = sim.truth()
    u = c[:, 0, sim.rec_names.index("wind_speed")]
    gust = u - u.mean()
    f = np.linspace(1 / 1800.0, 0.5, 200000)
    S = W.npd_spectrum(f, U10, 10.0)
    var_target = np.trapezoid(S, f)
    # a 2-h record of a random process: standard error of the variance ~ var·√(2/N_eff); allow 25 %
    assert gust.var() == pytest.approx(var_target, rel=0.25)
    fw, P = welch(gust, fs=2.0, nperseg=2048)
    band = (fw > 0.01) & (fw < 0.2)
    ratio = P[band] / W.npd_spectrum(fw[band], U10, 10.0)
    assert np.median(ratio) == pytest.approx(1.0, abs=0.3)
