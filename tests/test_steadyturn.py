"""vtrials.truth.steadyturn — the steady-turning curve (spiral-trial truth) against plain time simulation.

The curve is solved from the simulator's accelerations (no time stepping); the checks here run the
simulator forward with the rudder held (Dieudonné 1953 direct-spiral style holds; ITTC 7.5-04-02-01)
and compare what the ship settles to:

* steady turns at 10°, 25° and −10° started from the steady straight course: rate of turn
  (heading slope), body yaw rate, u and v averaged over the last turn match the solved turn at
  that rudder angle;
* KVLCC2 at 65 r/min: the model is directionally unstable (δ(r) falls through r = 0), with a
  markedly asymmetric loop (MMG2015's flow-straightening γ_R is 0.395 for β_R < 0 and 0.640 for
  β_R > 0, so port turns are less damped); rudder amidships after a starboard turn keeps turning
  to starboard, after a port turn keeps turning to port; just inside each fold angle the branch
  persists, just outside it the ship falls to the other branch;
* patrol vessel at 450 r/min, P/D 1.22: stable; turns decay with the rudder amidships and a small
  rudder gives the one turn of the curve whichever side the ship comes from;
* the remaining difference (≈1e-4–7e-4 at dt = 0.05 s) is the integrator's first-order error: it
  halves with dt and its Richardson extrapolation vanishes;
* :func:`hysteresis` on an analytic S-curve δ = (r³ − a r)/b (folds and zero-rudder rates known).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from vtrials.physics import steering as H
from vtrials.physics.simulator import ShipState, Simulator
from vtrials.truth.steadyturn import hysteresis, steady_turn, steady_turn_at_rudder, steady_turning_curve
from vtrials.units import DEG, RPM
from vtrials.physics.vessel import load_vessel

DT = 0.05
TOL = 1e-3  # relative agreement asked of the steady turns (the brief's 0.5 %, tightened)


def _state(s: dict, rps, pitch) -> ShipState:
    """A ShipState at a solved steady turn (body yaw rate; p, q start at zero)."""
    return ShipState(u=s["u"], v=s["v"], r=s["r_body"], z=s["z"], roll=s["roll"], pitch=s["pitch"],
                     rudder=s["delta"], shaft_rps=tuple(rps), pitch_ratio=tuple(pitch))


def _run(vessel, rps, pitch, starts, duration, every):
    """Time simulation, one ship per (start state or None = straight course, rudder held) pair."""
    sim = Simulator(vessel, len(starts), DT, record_every=every)
    for i, (s0, delta) in enumerate(starts):
        if s0 is None:
            sim.steady_at_order(i, rps, pitch)
        else:
            sim.set_state(i, s0)
        sim.set_helm(i, [(H.HOLD, delta, 0.0)])
    sim.step(int(round(duration / DT)))
    tr = sim.truth()
    col = {n: sim.rec_names.index(n) for n in ("t", "heading", "u_r", "v_r", "r")}
    return {k: tr[:, :, j] for k, j in col.items()}


def _last_turn(rec, i):
    """Means over the last full turn of ship i: rate of turn (heading slope), body r, u, v."""
    t, psi = rec["t"][:, i], rec["heading"][:, i]
    m = np.abs(psi - psi[-1]) <= 2.0 * math.pi
    return {"r": np.polyfit(t[m], psi[m], 1)[0], "r_body": rec["r"][m, i].mean(), "u": rec["u_r"][m, i].mean(),
            "v": rec["v_r"][m, i].mean(), "window": t[-1] - t[m][0]}


def _check_turn(vessel, rps, pitch, curve, delta, sim):
    ref = steady_turn_at_rudder(vessel, delta, rps, pitch, curve=curve)
    assert ref["success"] and abs(ref["delta"] - delta) < 1e-10
    assert sim["window"] >= 2.0 * math.pi / abs(ref["r"]) * 0.99
    for k in ("r", "r_body", "u"):
        assert sim[k] == pytest.approx(ref[k], rel=TOL), k
    assert sim["v"] == pytest.approx(ref["v"], rel=TOL, abs=TOL * ref["speed"] * 0.1)
    return ref


# ------------------------------------------------------------------------------------------ KVLCC2
KV_RPS, KV_PITCH = (65 * RPM,), ()


@pytest.fixture(scope="module")
def kvlcc2():
    v = load_vessel("kvlcc2")
    curve = steady_turning_curve(v, KV_RPS, KV_PITCH, dt=DT)
    hy = hysteresis(curve)
    assert hy["unstable"], "the model's KVLCC2 is expected unstable at 65 r/min (see the module docstring)"
    (_, d1), (_, d2) = hy["folds"]  # δ₁ > 0: upper fold (port branch ends), δ₂: lower fold
    m = 0.15 * hy["width"]
    stbd = _state(steady_turn_at_rudder(v, 5 * DEG, KV_RPS, KV_PITCH, curve=curve), KV_RPS, KV_PITCH)
    port = _state(steady_turn_at_rudder(v, -5 * DEG, KV_RPS, KV_PITCH, curve=curve), KV_RPS, KV_PITCH)
    starts = [(None, 10 * DEG), (None, 25 * DEG), (None, -10 * DEG),
              (stbd, 0.0), (port, 0.0),                       # rudder amidships on either branch
              (stbd, d2 + m), (stbd, d2 - m),                 # lower fold: inside / outside
              (port, d1 - m), (port, d1 + m)]                 # upper fold: inside / outside
    rec = _run(v, KV_RPS, KV_PITCH, starts, 4200.0, 100)
    return v, curve, hy, starts, rec


def test_kvlcc2_curve_solved(kvlcc2):
    v, curve, hy, _, _ = kvlcc2
    assert curve["success"].all() and not curve["torque_limited"].any()
    assert np.max(curve["residual"]) < 1e-10
    assert curve["delta"][0] == pytest.approx(-v.max_rudder, abs=1e-9)
    assert curve["delta"][-1] == pytest.approx(v.max_rudder, abs=1e-9)
    # straight ahead at r = 0 is the self-propelled speed of the order
    sim = Simulator(v, 1, DT, record_every=0)
    assert curve["U0"] == pytest.approx(sim.steady_at_order(0, KV_RPS).u, rel=1e-6)


@pytest.mark.parametrize("k,delta_deg", [(0, 10.0), (1, 25.0), (2, -10.0)])
def test_kvlcc2_steady_turns_match_simulation(kvlcc2, k, delta_deg):
    v, curve, _, _, rec = kvlcc2
    _check_turn(v, KV_RPS, KV_PITCH, curve, delta_deg * DEG, _last_turn(rec, k))


def test_kvlcc2_hysteresis_loop(kvlcc2):
    """Unstable: the loop seen in simulation has the width and height the curve gives."""
    v, curve, hy, starts, rec = kvlcc2
    (r1, d1), (r2, d2) = hy["folds"]
    assert r1 < 0.0 < r2 and d2 < 0.0 < d1  # δ = 0 lies inside the loop
    assert max(hy["slope0"]) < 0.0
    r_end = rec["r"][-1]
    # settled rates on the branch the curve predicts; the other branch is at least the loop height away
    for i in range(3, 9):
        delta = starts[i][1]
        assert rec["r"][-1, i] * rec["r"][-200, i] > 0  # not crossing any more
        branch = 1 if r_end[i] > 0 else -1
        ref = steady_turn_at_rudder(v, delta, KV_RPS, KV_PITCH, curve=curve, branch=branch)
        assert r_end[i] == pytest.approx(ref["r_body"], rel=0.05), i
    assert r_end[3] > 0 and r_end[4] < 0     # δ = 0: starboard branch and port branch both persist
    assert r_end[5] > 0 and r_end[6] < 0     # lower fold: inside persists, outside falls to port
    assert r_end[7] < 0 and r_end[8] > 0     # upper fold: inside persists, outside falls to starboard
    # the zero-rudder rates of the two branches are the curve's (loop height)
    r_pos, r_neg = hy["r_zero_rudder"]
    assert hy["height"] == pytest.approx(r_pos - r_neg)
    assert r_end[4] == pytest.approx(r_neg, rel=0.01)
    assert r_end[3] == pytest.approx(r_pos, rel=0.05)  # near the lower fold: slow to settle


# ------------------------------------------------------------------------------------------ patrol
PV_RPS, PV_PITCH = (450 * RPM, 450 * RPM), (1.22, 1.22)


@pytest.fixture(scope="module")
def patrol():
    v = load_vessel("patrol51")
    curve = steady_turning_curve(v, PV_RPS, PV_PITCH, dt=DT)
    hy = hysteresis(curve)
    stbd = _state(steady_turn_at_rudder(v, 10 * DEG, PV_RPS, PV_PITCH, curve=curve), PV_RPS, PV_PITCH)
    port = _state(steady_turn_at_rudder(v, -10 * DEG, PV_RPS, PV_PITCH, curve=curve), PV_RPS, PV_PITCH)
    starts = [(None, 10 * DEG), (None, 25 * DEG), (None, -10 * DEG),
              (stbd, 0.0), (port, 0.0), (port, 0.5 * DEG), (stbd, -0.5 * DEG)]
    rec = _run(v, PV_RPS, PV_PITCH, starts, 700.0, 10)
    return v, curve, hy, starts, rec


def test_patrol_curve_solved(patrol):
    v, curve, hy, _, _ = patrol
    assert curve["success"].all() and not curve["torque_limited"].any()
    assert np.max(curve["residual"]) < 1e-10
    # twin screws turning outward, mirror-symmetric: δ(−r) = −δ(r)
    assert curve["delta"] == pytest.approx(-curve["delta"][::-1], abs=1e-9)
    assert curve["roll"] == pytest.approx(-curve["roll"][::-1], abs=1e-9)


@pytest.mark.parametrize("k,delta_deg", [(0, 10.0), (1, 25.0), (2, -10.0)])
def test_patrol_steady_turns_match_simulation(patrol, k, delta_deg):
    v, curve, _, _, rec = patrol
    ref = _check_turn(v, PV_RPS, PV_PITCH, curve, delta_deg * DEG, _last_turn(rec, k))
    assert abs(ref["roll"]) > 2 * DEG  # heeled: body r and the rate of turn differ by cos φ


def test_patrol_is_stable(patrol):
    v, curve, hy, starts, rec = patrol
    assert not hy["unstable"] and hy["width"] == 0.0 and hy["height"] == 0.0
    assert min(hy["slope0"]) > 0.0
    r10 = abs(rec["r"][0, 3])
    assert abs(rec["r"][-1, 3]) < 1e-4 * r10 and abs(rec["r"][-1, 4]) < 1e-4 * r10  # turns decay
    # a small rudder gives the curve's one turn, from either side
    for i in (5, 6):
        ref = steady_turn_at_rudder(v, starts[i][1], PV_RPS, PV_PITCH, curve=curve)
        assert rec["r"][-1, i] == pytest.approx(ref["r_body"], rel=1e-3)


def test_patrol_simulation_converges_to_the_curve_with_dt():
    """The time simulation's steady turn differs from the continuous-time equilibrium by the
    integrator's first-order error (semi-implicit Euler: O(dt·r) relative); halving dt halves it and
    the Richardson extrapolation 2·e(dt/2) − e(dt) lands on the solved turn."""
    v = load_vessel("patrol51")
    ref = steady_turn(v, 3.0 * DEG, PV_RPS, PV_PITCH, dt=DT)
    err = []
    for dt in (DT, DT / 2):
        sim = Simulator(v, 1, dt, record_every=int(round(0.5 / dt)))
        sim.set_state(0, _state(ref, PV_RPS, PV_PITCH))
        sim.set_helm(0, [(H.HOLD, ref["delta"], 0.0)])
        sim.step(int(round(300.0 / dt)))
        tr = sim.truth()[:, 0]
        last = tr[-int(120 / 0.5):]
        c = {n: sim.rec_names.index(n) for n in ("t", "heading", "u_r", "v_r")}
        err.append(np.array([np.polyfit(last[:, c["t"]], last[:, c["heading"]], 1)[0] / ref["r"],
                             last[:, c["u_r"]].mean() / ref["u"], last[:, c["v_r"]].mean() / ref["v"]]) - 1.0)
    e1, e2 = err
    assert np.all(np.abs(e1) > 2e-5) and np.all(np.abs(e1) < 1e-3)
    assert e2 / e1 == pytest.approx(0.5, abs=0.01)
    assert np.all(np.abs(2 * e2 - e1) < 3e-6)


# ------------------------------------------------------------------------------------------ pieces
def test_sign_convention_and_single_turn():
    """steady_turn alone: a starboard rate needs starboard rudder, the ship drifts outward (v < 0)."""
    v = load_vessel("patrol51")
    s = steady_turn(v, 2.0 * DEG, PV_RPS, PV_PITCH)
    assert s["success"] and s["delta"] > 0 and s["v"] < 0 and s["drift"] > 0
    assert s["diameter"] == pytest.approx(2 * s["speed"] / (2.0 * DEG))
    assert s["r_body"] == pytest.approx(2.0 * DEG * math.cos(s["roll"]) * math.cos(s["pitch"]))


def test_hysteresis_on_analytic_s_curve():
    """δ = (r³ − a r)/b: folds at r = ±√(a/3), width (4a/3b)√(a/3), zero-rudder rates ±√a."""
    a, b = (0.3 * DEG) ** 2, 1e-5
    r = np.linspace(-1.2 * DEG, 1.2 * DEG, 241)
    rf = math.sqrt(a / 3)
    r = np.sort(np.concatenate([r, [-rf, rf, -math.sqrt(a), math.sqrt(a)]]))
    hy = hysteresis({"r": r, "delta": (r ** 3 - a * r) / b})
    assert hy["unstable"]
    assert hy["width"] == pytest.approx(4 * a / (3 * b) * math.sqrt(a / 3), rel=1e-9)
    assert hy["height"] == pytest.approx(2 * math.sqrt(a), rel=1e-9)
    assert hy["centre"] == pytest.approx(0.0, abs=1e-12)
    stable = hysteresis({"r": r, "delta": (r ** 3 + a * r) / b})
    assert not stable["unstable"] and stable["width"] == 0.0 and stable["height"] == 0.0
