"""Calm-water truth at given shaft settings: the reference a standardization trial is scored against.

The trial's corrected speed–power points must lie on the ship's speed–power curve in calm, deep water
without wind or current. That curve is computed here from the model's own equations, by its own
definition: the steady straight-ahead state at the same shaft speeds, pitches and shaft modes. Two
ways, one check on the other:

* :func:`steady_points` — root-finding on the surge balance (:meth:`Simulator.steady_at_order`), exact
  for symmetric settings (all shafts governed at one speed and pitch, rudders amidships);
* :func:`twin_points` — a batch of "calm-water twins" (one ship per setting) simulated with the
  autopilot holding course until speed, r/min and heading are steady, then averaged over a window;
  this handles asymmetric settings (pitch trims from shaft balancing, trailed or locked shafts) whose
  steady state needs rudder and drift. ``tests/test_agenda.py`` checks the two agree where both apply.
"""

from __future__ import annotations

import math

import numpy as np

from vtrials.physics import steering as H
from vtrials.physics.propulsion import MODE_NAMES
from vtrials.physics.simulator import ShipState, Simulator
from vtrials.truth.columns import ship_columns


def _power(sim: Simulator, ship: int) -> tuple[float, list]:
    p = sim.shaft_power(ship)
    return float(sum(p)), p


def steady_points(vessel, rps: list[tuple], pitch: list[tuple], dt: float = 0.05) -> list[dict]:
    """Exact calm-water steady states for all-governed settings: speed [m/s], power [W] per setting."""
    sim = Simulator(vessel, 1, dt, record_every=0)
    out = []
    for n, p in zip(rps, pitch):
        s = sim.steady_at_order(0, tuple(n), tuple(p) if p is not None else ())
        P, per = _power(sim, 0)
        out.append({"stw": float(math.hypot(s.u, s.v)), "power": P, "shaft_power": per, "rps": list(n)})
    return out


TWIN_TOL_MPS = 2e-4  # [m/s] a twin is steady when its speed changes by less than this over a window


def twin_points(vessel, settings: list[dict], dt: float, window_s: float = 120.0, max_s: float = 4000.0,
                tol_mps: float = TWIN_TOL_MPS) -> list[dict]:
    """Calm-water twins: ``settings`` is a list of {"rps": per shaft [rev/s], "pitch": per shaft or None,
    "modes": per shaft}. Each twin starts from the symmetric steady state at its mean setting, takes
    its own setting and is simulated (autopilot holding course) until its speed changes by less than
    ``tol_mps`` over ``window_s``; returns per twin the means over the last window: stw [m/s], power
    [W], shaft powers, r/s, rudder [rad], drift angle [rad], and ``steady`` (False if max_s ran out)."""
    N = len(settings)
    sim = Simulator(vessel, N, dt, record_every=1)
    ns = sim.ns
    ap = vessel.autopilot
    lim = min(ap.rudder_limit_deg * math.pi / 180, vessel.max_rudder)
    gains = ap.pid
    for i, st in enumerate(settings):
        gov = [k for k in range(ns) if st["modes"][k] == "governed"]
        n0 = float(np.mean([st["rps"][k] for k in gov]))
        p0 = () if st.get("pitch") is None else tuple(float(np.mean([st["pitch"][k] for k in gov])) for _ in range(ns))
        s = sim.steady_at_order(i, (n0,) * ns, p0)
        s = ShipState(**{**s.__dict__, "shaft_modes": tuple(st["modes"]),
                         "shaft_rps": tuple(0.0 if st["modes"][k] == "locked" else
                                            (st["rps"][k] if st["modes"][k] == "governed" else n0)
                                            for k in range(ns))})
        if st.get("pitch") is not None:
            s.pitch_ratio = tuple(st["pitch"])
        sim.set_state(i, s)
        for k in range(ns):
            sim.shaft_mode[i, k] = MODE_NAMES[st["modes"][k]]
        sim.set_helm(i, [(H.HEADING, 0.0, lim, *gains, 0.0)])
    nwin = int(round(window_s / dt))
    done = np.zeros(N, bool)
    results: list[dict | None] = [None] * N
    elapsed = 0.0
    while True:
        sim.clear_truth()
        sim.step(nwin)
        elapsed += window_s
        rec = sim.truth()
        for i in range(N):
            if done[i]:
                continue
            c = ship_columns(rec, sim.rec_names, i, sim.dt)
            stw = np.hypot(c["u_r"], c["v_r"])
            half = stw.size // 2
            change = abs(float(np.mean(stw[half:]) - np.mean(stw[:half])))
            if change < tol_mps or elapsed >= max_s:
                done[i] = True
                per = [float(np.mean(2 * math.pi * c[f"shaft_n_{k}"] * c[f"prop_torque_{k}"])) for k in range(ns)]
                results[i] = {"stw": float(np.mean(stw)), "power": float(sum(per)), "shaft_power": per,
                              "rps": [float(np.mean(c[f"shaft_n_{k}"])) for k in range(ns)],
                              "rudder": float(np.mean(c["rudder_0"])) if "rudder_0" in c else 0.0,
                              "drift_angle": float(np.mean(np.arctan2(c["v_r"], c["u_r"]))),
                              "steady": change < tol_mps, "settle_s": elapsed}
        if done.all():
            return results


def load_variation(vessel, speeds, fractions=(-0.1, 0.1, 0.2, 0.3, 0.4), sim: Simulator | None = None) -> dict:
    """Load-variation test on the model itself: self-propulsion at a fixed speed with an added tow
    force, the test from which ITTC 7.5-04-01-01.1 (2017, rev. 2021) §"Direct Power Method" and ISO
    15016:2015 take the overload factor ξ_P (see :func:`vtrials.reduce.speedpower.overload_factor`).

    At each speed V [m/s] (an ascending list) the ship is first self-propelled (R_T from the hull
    components, delivered power P_D,id); then for each ΔR = f R_T, f in ``fractions``, the shaft speed is
    found at which the net surge force equals ΔR (the ship pushes the extra resistance, as in a head wind
    on trial), at the same trim, and P_D and η_D = (R_T + ΔR) V / P_D recorded. ξ_P is the least-squares
    slope through the origin of η_D,id/η_D − 1 against (P_D − P_D,id)/P_D,id. Returns
    {"speed_mps", "xi_P", "points": per speed [{dR_N, rps, power_W, eta_D}]}.
    """
    from scipy.optimize import brentq

    sim = sim or Simulator(vessel, 1, 0.05, record_every=0)
    hull = [i for i, n in enumerate(sim.comp_names) if n.startswith("hull")]
    # a model propeller in the tank is not held to the engine's limit: search up to 3 × the rated speed
    n_hi = 3.0 * float(np.max([sh.max_rps for sh in vessel.shafts]))
    out = {"speed_mps": [], "xi_P": [], "points": []}
    for V in speeds:
        s = sim.self_propulsion(0, float(V))
        P0 = float(sum(sim.shaft_power(0)))
        R0 = -float(sum(sim.comp_w[0, i, 0] for i in hull))
        eta0 = R0 * V / P0
        pts, x, y = [{"dR_N": 0.0, "rps": float(s.shaft_rps[0]), "power_W": P0, "eta_D": eta0}], [], []
        for f in fractions:
            dR = f * R0

            def resid(n):
                s.shaft_rps = (n,) * sim.ns
                return sim._surge_residual(0, s) - dR  # noqa: SLF001 (the simulator's own surge balance)

            n = brentq(resid, 1e-6, n_hi, xtol=1e-13, rtol=1e-14)
            s.shaft_rps = (n,) * sim.ns
            sim.set_state(0, s)
            P = float(sum(sim.shaft_power(0)))
            eta = (R0 + dR) * V / P
            pts.append({"dR_N": dR, "rps": n, "power_W": P, "eta_D": eta})
            x.append((P - P0) / P0)
            y.append(eta0 / eta - 1.0)
        x, y = np.asarray(x), np.asarray(y)
        out["speed_mps"].append(float(V))
        out["xi_P"].append(float(x @ y / (x @ x)))  # as vtrials.reduce.speedpower.overload_factor
        out["points"].append(pts)
    return out
