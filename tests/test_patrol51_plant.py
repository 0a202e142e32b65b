"""CP plant load control (issue 17 item 3), on the plant alone: one shaft of the patrol vessel
(its ship.toml parameters) driven by :func:`vtrials.physics.propulsion.machinery_step`, integrated
here by explicit Euler, I 2π ṅ = Q_E − Q_P − c_F n, against a simple propeller torque law
Q_P = ρ n|n| D⁵ K_Q(P/D), K_Q = 0.01 + 0.045 (P/D)² (a B-series-like order of magnitude; the test
needs a load that exceeds the engine at full pitch and full r/min, not a particular propeller).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from vtrials.errors import InputError
from vtrials.physics import propulsion as PR
from vtrials.physics.vessel import load_vessel

RHO, D, DT = 1014.0, 1.6, 0.02


@pytest.fixture(scope="module")
def patrol():
    return load_vessel("patrol51")


def _qp(n, p):
    return RHO * n * abs(n) * D ** 5 * (0.01 + 0.045 * p * p)


def _run(sp, n0, p0, orders, T):
    """Integrate one shaft from a steady state at (n0, p0); ``orders`` = [(t, rps, pitch), ...]."""
    ms = np.zeros(PR.NMACH)
    ms[PR.M_PITCH] = p0
    ms[PR.M_SETPOINT] = n0
    q0 = _qp(n0, p0) + sp[PR.S_FRICTION] * n0
    ms[PR.M_INTEG] = ms[PR.M_TORQUE] = q0
    n = n0
    rows = []
    k_ord = 0
    n_cmd, p_cmd = n0, p0
    for step in range(int(T / DT)):
        t = step * DT
        while k_ord < len(orders) and orders[k_ord][0] <= t + 1e-12:
            _, n_cmd, p_cmd = orders[k_ord]
            k_ord += 1
        before = ms.copy()
        PR.machinery_step(sp, ms, n, n_cmd, p_cmd, PR.GOVERNED, DT)
        qp = _qp(n, ms[PR.M_PITCH])
        rows.append((t, n, ms[PR.M_PITCH], ms[PR.M_TORQUE], qp, ms[PR.M_SETPOINT], ms[PR.M_REV],
                     PR.available_torque(sp, n), before[PR.M_SETPOINT], n_cmd, before[PR.M_PITCH]))
        n += DT * (ms[PR.M_TORQUE] - qp - sp[PR.S_FRICTION] * n) / (2 * math.pi * sp[PR.S_INERTIA])
    names = ("t", "n", "p", "qe", "qp", "set", "rev", "qav", "set_before", "n_cmd", "p_before")
    return {k: np.array(c) for k, c in zip(names, zip(*rows))}


def test_crash_astern_reversal_follows_the_load_controller(patrol):
    """Ahead 2/3 → Back Emergency: the engine torque stays in [0, available] (non-reversing, torque and
    power limit); during the reversal the r/min set-point moves, at the governor's ramp rate, toward
    min(order, combinator r/min at the ACTUAL pitch); the shaft passes zero pitch near the combinator's
    300 r/min, not at the ~500 r/min of the old plant; afterwards the order is reached."""
    sp = patrol.shaft_params[0]
    n0, p0 = patrol.telegraph["ahead_2_3"]
    nb, pb = patrol.telegraph["back_emergency"]
    r = _run(sp, n0, p0, [(1.0, nb, pb)], 60.0)
    assert np.all(r["qe"] >= 0.0)
    assert np.all(r["qe"] <= r["qav"] * (1 + 1e-12))
    assert np.all(r["qe"] * 2 * math.pi * r["n"] <= sp[PR.S_PMAX] * (1 + 1e-12))
    # pitch moves at most at its rate
    assert np.abs(np.diff(r["p"])).max() <= sp[PR.S_PITCH_RATE] * DT * (1 + 1e-9)
    # set-point law while the reversal is latched
    lat = r["rev"] > 0
    assert lat.sum() > 10 / DT   # the reversal takes > 10 s (0.83 → −1.0 at 0.1 /s: 18.3 s)
    cap = np.array([PR.reversal_cap(sp, p) for p in r["p"]])
    want = r["set_before"] + np.clip(np.minimum(r["n_cmd"], cap) - r["set_before"], -sp[PR.S_NRATE] * DT,
                                     sp[PR.S_NRATE] * DT)
    np.testing.assert_allclose(r["set"][lat], want[lat], rtol=0, atol=1e-12)
    # the schedule is the combinator's: 300 r/min between P/D −0.5 and +0.62
    for p in (-0.5, -0.08, 0.0, 0.3, 0.62):
        assert PR.reversal_cap(sp, p) == pytest.approx(300.0 / 60.0, rel=1e-6)
    assert PR.reversal_cap(sp, -1.0) == pytest.approx(530.0 / 60.0, rel=1e-6)
    # shaft speed when the blades pass zero pitch: close to 300 r/min
    k0 = int(np.flatnonzero(r["p"] <= 0.0)[0])
    assert 60 * r["n"][k0] < 320.0, 60 * r["n"][k0]
    # while the blades are between the combinator's Back 1/3 and zero-thrust-ahead settings the shaft
    # runs at the combinator's 300 r/min (governor error included), once the set-point has come down
    mid = lat & (r["p"] > -0.5) & (r["p"] < 0.3)
    assert mid.sum() > 5 / DT and np.all(60 * r["n"][mid] < 320.0)
    # the reversal ends when the pitch reaches its order; then the r/min order is met
    kend = int(np.flatnonzero(lat)[-1]) + 1
    assert r["p"][kend] == pb
    assert r["t"][kend] == pytest.approx(1.0 + (p0 - pb) / sp[PR.S_PITCH_RATE], abs=2 * DT)
    assert 60 * r["n"][-1] == pytest.approx(60 * nb, abs=1.0)
    # the plant before load control (issue 17) fails the zero-pitch check: its set-point ramps straight
    # to the Back Emergency r/min, so the blades pass zero pitch near 500 r/min
    sp_off = sp.copy()
    sp_off[PR.S_LC] = 0.0
    old = _run(sp_off, n0, p0, [(1.0, nb, pb)], 30.0)
    assert 60 * old["n"][int(np.flatnonzero(old["p"] <= 0.0)[0])] > 450.0


def test_load_limiter_holds_the_pitch_at_the_engine_limit(patrol):
    """Flank r/min with the pitch ordered from 0.3 to 1.37: the propeller would need ~100 kN m, the
    engine has 71.6 kN m at 600 r/min. With load control the pitch stops (and is taken back) where
    the engine's load reaches 1 at the ordered r/min, so the shaft keeps its r/min; without it the
    pitch runs to its order and the shaft is pulled down (the engine torque clipped either way)."""
    sp = patrol.shaft_params[0].copy()
    nf, pf = patrol.telegraph["flank"]
    on = _run(sp, nf, 0.3, [(0.0, nf, pf)], 60.0)
    sp_off = sp.copy()
    sp_off[PR.S_LC] = 0.0
    off = _run(sp_off, nf, 0.3, [(0.0, nf, pf)], 60.0)
    assert _qp(nf, pf) > 1.3 * PR.available_torque(sp, nf)   # the load really exceeds the engine
    for r in (on, off):
        assert np.all(r["qe"] <= r["qav"] * (1 + 1e-12))
    assert off["p"][-1] == pf and 60 * off["n"][-1] < 560.0          # overloaded: r/min lost
    assert on["p"][-1] < pf - 0.1                                     # held short of its order
    assert 60 * on["n"][-1] > 590.0                                   # r/min kept
    # load on the torque/power limit at the larger of actual and set-point r/min (before each step)
    qav_set = np.array([PR.available_torque(sp, max(a, b)) for a, b in zip(on["n"], on["set_before"])])
    lam = np.concatenate([[np.nan], on["qe"][:-1]]) / qav_set
    away = (on["p"] - on["p_before"]) * on["p_before"] > 0
    assert np.all(lam[1:][away[1:]] < 1.0 + 1e-12)   # the pitch never grows while the engine is overloaded
    assert np.any(on["p"][1:] < on["p_before"][1:])   # and it was taken back when it was
    # steady: the engine carries the propeller at the ordered r/min, on its limit (load_limit 0.9 .. 1.0)
    assert 0.9 <= on["qe"][-1] / PR.available_torque(sp, nf) <= 1.0 + 1e-6
    assert 60 * on["n"][-1] == pytest.approx(600.0, abs=0.5)


def _old_machinery(sp, ms, n, n_cmd, p_cmd, mode, dt):
    """The machinery code of the step kernel before load control (re-implemented here)."""
    def clip(x, lim):
        return max(-lim, min(lim, x))
    if sp[PR.S_CP] > 0.0:
        pc = min(max(p_cmd, sp[PR.S_PITCH_MIN]), sp[PR.S_PITCH_MAX])
        ms[PR.M_PITCH] += clip(pc - ms[PR.M_PITCH], sp[PR.S_PITCH_RATE] * dt)
    else:
        ms[PR.M_PITCH] = sp[PR.S_PITCH_DESIGN]
    ms[PR.M_SETPOINT] += clip(n_cmd - ms[PR.M_SETPOINT], sp[PR.S_NRATE] * dt)
    if mode == PR.GOVERNED:
        qmax = sp[PR.S_QMAX]
        if abs(n) > 1e-9:
            qmax = min(qmax, sp[PR.S_PMAX] / (2 * math.pi * abs(n)))
        err = ms[PR.M_SETPOINT] - n
        q = clip(sp[PR.S_KP] * err + ms[PR.M_INTEG], qmax)
        qe = clip(ms[PR.M_TORQUE] + clip(q - ms[PR.M_TORQUE], sp[PR.S_TRATE] * dt), qmax)
        ms[PR.M_TORQUE] = qe
        ms[PR.M_INTEG] = clip(ms[PR.M_INTEG] + dt * (sp[PR.S_KI] * err), qmax)
    else:
        ms[PR.M_TORQUE] = 0.0
        ms[PR.M_INTEG] = 0.0


def test_without_load_control_the_machinery_is_unchanged(patrol):
    """Shafts without load control (every other ship) step exactly as before the change."""
    rng = np.random.default_rng(17)
    sp = patrol.shaft_params[0].copy()
    sp[PR.S_LC] = 0.0
    a = np.zeros(PR.NMACH)
    b = np.zeros(PR.NMACH)
    for _ in range(3000):
        n = rng.uniform(-12, 12)
        n_cmd, p_cmd = rng.uniform(-10, 10), rng.uniform(-1.5, 2.0)
        mode = int(rng.integers(0, 3))
        PR.machinery_step(sp, a, n, n_cmd, p_cmd, mode, DT)
        _old_machinery(sp, b, n, n_cmd, p_cmd, mode, DT)
        assert np.array_equal(a[:4], b[:4])


@pytest.mark.parametrize("change, field", [
    (dict(controllable_pitch=False), "load_control"),
    (dict(reversal_rps=(5.0,)), "reversal_pitch"),
    (dict(reversal_pitch=(-1.0, -1.0, 0.0, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0)), "reversal_pitch"),
])
def test_bad_load_control_input_names_the_field(patrol, change, field):
    s = dataclasses.replace(patrol.shafts[0], **change)
    with pytest.raises(InputError, match=field) as e:
        PR.pack(s, 0, 0, 0, 1.4, file="ship.toml")
    assert "ship.toml" in str(e.value) and "'port'" in str(e.value)
