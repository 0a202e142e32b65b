"""Truth reference for spiral trials: the steady-turning curve of the model's own equations.

A spiral trial measures the steady rate of turn against the rudder angle at fixed shaft settings:
the direct spiral of Dieudonné (1953) steps the rudder and waits for a steady rate; the reverse
spiral of Bech (1968) holds a rate of turn with the helm and records the mean rudder (ITTC
Recommended Procedure 7.5-04-02-01, Full Scale Manoeuvring Trials). A directionally unstable ship
has a hysteresis loop: for rudder angles between the two fold angles three steady turns exist, the
middle one unstable. The direct spiral cannot reach that middle branch; parameterising by the rate
(as the reverse spiral does) can, because δ(r) is single valued where r(δ) is not.

Here the curve is computed from the simulator's own equations, by definition: a steady turn is a
motion whose body-frame velocities and attitude relative to gravity are constant — the ship turns
at the rate ψ̇ = r about the vertical, with no vertical velocity, at its heave, heel and trim
equilibrium, all rudders at one angle δ, the governed shafts at their ordered r/min (or, where the
engine's torque or power limit binds, at the speed where the limited engine torque balances the
propeller; ``torque_limited`` says so). The unknowns u, v, δ, z, φ, θ (and any limited shaft
speeds) are found with :func:`scipy.optimize.root` on the six body accelerations that
:meth:`Simulator.evaluate` returns, so the reference shares every force with the simulation and
nothing else.

Kinematics of the steady turn (body axes x forward, y starboard, z down; z-y-x Euler angles):
angular velocity ω = ψ̇ R(φ, θ)ᵀ e_z, i.e. p = −ψ̇ sin θ, q = ψ̇ sin φ cos θ, r_body = ψ̇ cos φ cos θ;
the body heave velocity w makes the world vertical velocity zero. ``r`` in this module is always
the rate of turn ψ̇ (what a spiral trial measures: Δheading/Δtime); ``r_body`` is the body yaw rate
(the truth record's ``r``), smaller by cos φ cos θ.

Functions: :func:`steady_turn` (one rate), :func:`steady_turning_curve` (δ(r) by continuation),
:func:`steady_turn_at_rudder` (the turn at a rudder angle, on a chosen branch: a direct-spiral
point) and :func:`hysteresis` (stability, loop width and height). Calm deep water only (no current
or wind).
"""

from __future__ import annotations

import math

import numpy as np
from scipy import optimize

from vtrials.physics.dynamics import quat_to_mat
from vtrials.physics.forces import context as L
from vtrials.physics.propulsion import GOVERNED, M_INTEG, M_TORQUE, S_FRICTION, S_PMAX, S_PROP, S_QMAX
from vtrials.physics.simulator import ShipState, Simulator, euler_to_quat

_LIMIT_TOL = 1e-9  # relative margin before a shaft counts as torque/power limited


class _Problem:
    """One vessel at one shaft setting: a simulator for function evaluations and the scales."""

    def __init__(self, vessel, rps: tuple, pitch: tuple = (), dt: float = 0.05):
        self.vessel = vessel
        self.sim = Simulator(vessel, 1, dt, record_every=0)
        self.ns = self.sim.ns
        rps = tuple(float(n) for n in rps)
        if len(rps) == 1 and self.ns > 1:
            rps = rps * self.ns
        if len(rps) != self.ns:
            raise ValueError(f"{vessel.name} has {self.ns} shafts; got {len(rps)} shaft speeds")
        self.rps = rps
        self.pitch = tuple(float(p) for p in pitch)
        self.L = vessel.length
        self.d = vessel.particulars.draught
        self.straight = self.sim.steady_at_order(0, rps, self.pitch)
        if self.straight.u <= 0.0:
            raise ValueError(f"shaft order {rps} gives no ahead speed: no steady turn")
        self.U0 = float(self.straight.u)
        sp = self.sim.shaftp
        self.governed = [k for k in range(self.ns) if self.sim.shaft_mode[0, k] == GOVERNED]
        self.qmax_par = [(sp[k, S_QMAX], sp[k, S_PMAX]) for k in range(self.ns)]

    # --------------------------------------------------------------- state placement
    def place(self, psidot, u, v, delta, z, phi, theta, n) -> None:
        """Put the simulator's ship in the steady-turn state (exact helix kinematics, machinery
        torque holding the shafts)."""
        sim = self.sim
        cphi, sphi, cth, sth = math.cos(phi), math.sin(phi), math.cos(theta), math.sin(theta)
        s = ShipState(u=u, v=v, r=psidot * cphi * cth, z=z, roll=phi, pitch=theta, rudder=delta,
                      shaft_rps=tuple(n), pitch_ratio=self.pitch)
        sim.set_state(0, s)
        # no vertical velocity over the ground, rotation about the vertical
        w = (sth * u - cth * sphi * v) / (cth * cphi)
        R = np.zeros(9)
        quat_to_mat(*euler_to_quat(phi, theta, 0.0), R)
        sim.qvel[0][0:3] = R.reshape(3, 3) @ np.array([u, v, w])
        sim.qvel[0][3:6] = (-psidot * sth, psidot * sphi * cth, psidot * cphi * cth)
        # machinery torque = propeller torque + friction at this state (shaft acceleration zero)
        self._hold_shafts()

    def _hold_shafts(self):
        sim = self.sim
        sim.evaluate()
        for k in self.governed:
            kp = int(sim.shaftp[k, S_PROP])
            nk = sim.ctx[0, L.SHAFT_N + kp]
            q = sim.aux[0, L.AUX_PROP + 8 * kp + L.P_TORQUE] + sim.shaftp[k, S_FRICTION] * nk
            sim.mach[0, k, M_INTEG] = q
            sim.mach[0, k, M_TORQUE] = q

    def required_torque(self, k: int) -> float:
        """Machinery torque shaft k needs at the placed state (propeller + friction) [N m]."""
        sim = self.sim
        kp = int(sim.shaftp[k, S_PROP])
        nk = sim.ctx[0, L.SHAFT_N + kp]
        return float(sim.aux[0, L.AUX_PROP + 8 * kp + L.P_TORQUE] + sim.shaftp[k, S_FRICTION] * nk)

    def torque_limit(self, k: int, n: float) -> float:
        """The governor's torque limit at shaft speed n: min(Q_max, P_max / 2π|n|)."""
        qmax, pmax = self.qmax_par[k]
        if abs(n) > 1e-9:
            qmax = min(qmax, pmax / (2.0 * math.pi * abs(n)))
        return qmax

    # --------------------------------------------------------------- residual
    def unpack(self, x, limited):
        u = x[0] * self.U0
        v = x[1] * self.U0
        delta = x[2]
        z = x[3] * self.d
        phi, theta = x[4], x[5]
        n = list(self.rps)
        for j, k in enumerate(limited):
            n[k] = x[6 + j] * self.rps[k]
        return u, v, delta, z, phi, theta, n

    def residual(self, x, psidot, limited):
        u, v, delta, z, phi, theta, n = self.unpack(x, limited)
        self.place(psidot, u, v, delta, z, phi, theta, n)
        nud = self.sim.evaluate()[0]
        a_lin = self.U0 ** 2 / self.L
        a_ang = self.U0 ** 2 / self.L ** 2
        res = [nud[0] / a_lin, nud[1] / a_lin, nud[5] / a_ang, nud[2] / a_lin, nud[3] / a_ang, nud[4] / a_ang]
        for k in limited:
            qlim = self.torque_limit(k, n[k])
            res.append((self.required_torque(k) - qlim) / qlim)
        return np.array(res)

    # --------------------------------------------------------------- solve
    def x_from(self, g: dict, limited) -> np.ndarray:
        x = [g["u"] / self.U0, g["v"] / self.U0, g["delta"], g["z"] / self.d, g["roll"], g["pitch"]]
        n = g.get("shaft_rps", self.rps)
        for k in limited:
            x.append(n[k] / self.rps[k])
        return np.array(x, dtype=float)

    def straight_guess(self) -> dict:
        s = self.straight
        return {"u": s.u, "v": 0.0, "delta": 0.0, "z": float(s.z), "roll": float(s.roll), "pitch": float(s.pitch)}

    def solve(self, psidot: float, guess: dict | None = None) -> dict:
        g = dict(self.straight_guess() if guess is None else guess)
        limited = [k for k in self.governed if g.get("torque_limited", (False,) * self.ns)[k]]
        for _attempt in range(3):
            x, res, ok = self._root(psidot, g, limited)
            u, v, delta, z, phi, theta, n = self.unpack(x, limited)
            self.place(psidot, u, v, delta, z, phi, theta, n)
            # which governed shafts need more torque than the engine gives / which limited ones
            # would run above their order: change the set and solve again
            new = []
            for k in self.governed:
                if k in limited:
                    if n[k] < self.rps[k] * (1.0 - _LIMIT_TOL):
                        new.append(k)
                elif self.required_torque(k) > self.torque_limit(k, n[k]) * (1.0 + _LIMIT_TOL):
                    new.append(k)
            if new == limited:
                break
            g = self.result(psidot, x, limited, res, ok)
            g["shaft_rps"] = tuple(min(nk, self.rps[k]) for k, nk in enumerate(n))
            limited = new
        return self.result(psidot, x, limited, res, ok and new == limited)

    def jacobian(self, x, psidot, limited, h=1e-7):
        """Central-difference Jacobian with absolute steps in the scaled unknowns (all of order 1
        or smaller, so relative steps would vanish at the symmetric straight-ahead state)."""
        J = np.empty((x.size, x.size))
        for j in range(x.size):
            e = np.zeros(x.size)
            e[j] = h * max(1.0, abs(x[j]))
            J[:, j] = (self.residual(x + e, psidot, limited) - self.residual(x - e, psidot, limited)) / (2.0 * e[j])
        return J

    def _root(self, psidot, g, limited):
        x0 = self.x_from(g, limited)
        best = None
        for method in ("hybr", "lm"):
            opts = {"xtol": 1e-13} if method == "hybr" else {"xtol": 1e-14, "ftol": 1e-14, "maxiter": 60}
            sol = optimize.root(self.residual, x0, args=(psidot, limited), jac=self.jacobian, method=method,
                                options=opts)
            res = float(np.linalg.norm(self.residual(sol.x, psidot, limited)))
            if best is None or res < best[1]:
                best = (sol.x.copy(), res)
            if res < 1e-10:
                break
        return best[0], best[1], best[1] < 1e-8

    def result(self, psidot, x, limited, res, ok) -> dict:
        u, v, delta, z, phi, theta, n = self.unpack(x, limited)
        cphi, sphi, cth, sth = math.cos(phi), math.sin(phi), math.cos(theta), math.sin(theta)
        w = (sth * u - cth * sphi * v) / (cth * cphi)
        speed = math.sqrt(u * u + v * v + w * w)
        return {
            "r": float(psidot), "u": float(u), "v": float(v), "w": float(w), "delta": float(delta),
            "z": float(z), "roll": float(phi), "pitch": float(theta),
            "p": float(-psidot * sth), "q": float(psidot * sphi * cth), "r_body": float(psidot * cphi * cth),
            "speed": float(speed), "drift": float(math.atan2(-v, u)),
            "diameter": float(2.0 * speed / abs(psidot)) if psidot != 0.0 else math.inf,
            "shaft_rps": tuple(float(nk) for nk in n),
            "torque_limited": tuple(k in limited for k in range(self.ns)),
            "residual": float(res), "success": bool(ok),
        }


def steady_turn(vessel, r: float, rps: tuple, pitch: tuple = (), dt: float = 0.05, guess: dict | None = None,
                ) -> dict:
    """The steady turn of ``vessel`` at rate of turn ``r`` [rad/s] and shaft order ``rps``.

    ``rps``: ordered shaft speeds [rev/s] (one value is used for every shaft); ``pitch``: pitch
    ratios (controllable pitch; () = design). ``guess``: a previous result (or a dict with u, v,
    delta, z, roll, pitch) to start from; default the straight-ahead state at this order, good for
    moderate rates only — follow a curve with :func:`steady_turning_curve` for large ones. ``dt``
    is only the evaluating simulator's step (the equilibrium does not depend on it; a time
    simulation approaches it with a first-order error in dt).

    Returns a dict: ``r`` (= ψ̇, as given), ``u``, ``v``, ``w`` [m/s] (body axes, through the
    water), ``delta`` [rad] (every rudder), ``z`` [m], ``roll``, ``pitch`` [rad], ``p``, ``q``,
    ``r_body`` [rad/s], ``speed`` [m/s], ``drift`` β = atan2(−v, u) [rad], ``diameter`` 2U/|r| [m],
    ``shaft_rps`` (actual), ``torque_limited`` (per shaft), ``residual`` (norm of the accelerations,
    linear ÷ U₀²/L, angular ÷ U₀²/L²; U₀ the straight-ahead speed) and ``success``.
    """
    return _Problem(vessel, rps, pitch, dt).solve(float(r), guess)


_CURVE_KEYS = ("u", "v", "w", "delta", "z", "roll", "pitch", "r_body", "speed", "drift", "diameter", "residual")


def _march(prob, r_to, start, steps):
    """Continuation from ``start`` (a solution) to rate r_to in ``steps`` equal steps (secant predictor)."""
    out = [start]
    r0 = start["r"]
    for i in range(1, steps + 1):
        ri = r0 + (r_to - r0) * i / steps
        g = _predict(out, ri)
        out.append(prob.solve(ri, g))
    return out[1:]


def _predict(sols, ri):
    """Linear extrapolation of the last two solutions to rate ri (a guess)."""
    g = dict(sols[-1])
    if len(sols) >= 2 and sols[-1]["r"] != sols[-2]["r"]:
        a, b = sols[-2], sols[-1]
        f = (ri - b["r"]) / (b["r"] - a["r"])
        for k in ("u", "v", "delta", "z", "roll", "pitch"):
            g[k] = b[k] + f * (b[k] - a[k])
    return g


def _rate_at_max_rudder(prob, base, sign, dmax):
    """Rate of turn at which δ = ±dmax, by continuation outwards (direction ``sign``) from the
    r = 0 solution; the step is halved where the solver fails (near the largest rate a branch has)."""
    h = sign * 0.01 * prob.U0 / prob.L
    sols = [base]
    while True:
        ri = sols[-1]["r"] + h
        s = prob.solve(ri, _predict(sols, ri))
        if not s["success"]:
            h /= 2.0
            if abs(h) < 1e-6 * prob.U0 / prob.L:
                raise RuntimeError(f"steady turns end near r = {ri:.4g} rad/s before the maximum rudder")
            continue
        if abs(ri) > 5.0 * prob.U0 / prob.L:
            raise RuntimeError("no rate of turn reaches the maximum rudder")
        sols.append(s)
        if abs(s["delta"]) >= dmax:
            break
    a, b = sols[-2], sols[-1]
    target = math.copysign(dmax, b["delta"])

    def f(rr):
        return prob.solve(rr, _predict([a, b], rr))["delta"] - target

    return optimize.brentq(f, a["r"], b["r"], xtol=1e-12 * prob.U0 / prob.L)


def steady_turning_curve(vessel, rps: tuple, pitch: tuple = (), r_max: float | None = None, n: int = 81,
                         dt: float = 0.05) -> dict:
    """The steady-turning curve δ(r) at one shaft order, traced by continuation in r.

    The rate runs from the rate at full port rudder to the rate at full starboard rudder (by
    continuation from straight ahead; with ``r_max`` given, from −r_max to +r_max) through r = 0
    (straight course at the self-propelled speed of the order, :meth:`Simulator.steady_at_order`):
    (n − 1)/2 equal steps on each side (n rounded down to odd). Parameterising by r is the reverse spiral's (Bech 1968)
    and reaches the unstable middle branch. Added points, all solved: the one-sided slopes at
    r = 0 (``ddelta_dr0`` = (left, right); the MMG flow-straightening γ_R changes at β_R = 0, so
    δ(r) can have a kink there), the folds (local extrema of δ(r)) and the zero-rudder rates on the
    outer branches, so :func:`hysteresis` reads exact values.

    Returns a dict of arrays sorted by r: ``r``, ``delta``, ``u``, ``v``, ``w``, ``z``, ``roll``,
    ``pitch``, ``r_body``, ``speed``, ``drift``, ``diameter``, ``residual``, flags ``success``,
    ``torque_limited`` (any shaft) and ``added`` (refinement points); scalars ``rps``, ``pitch_ratio``,
    ``U0`` (straight-ahead speed), ``delta_max``, ``ddelta_dr0``, ``delta0`` (rudder for r = 0).
    """
    prob = _Problem(vessel, rps, pitch, dt)
    base = prob.solve(0.0)
    if not base["success"]:
        raise RuntimeError(f"no straight-ahead equilibrium at {rps}: residual {base['residual']:.3g}")
    dmax = vessel.max_rudder
    if r_max is None:
        ra = _rate_at_max_rudder(prob, base, +1.0, dmax)
        rb = _rate_at_max_rudder(prob, base, -1.0, dmax)
        r_lo, r_hi = min(ra, rb), max(ra, rb)
    else:
        r_lo, r_hi = -abs(r_max), abs(r_max)
    half = max(2, (int(n) - 1) // 2)
    neg = _march(prob, r_lo, base, half)
    pos = _march(prob, r_hi, base, half)
    pts = neg[::-1] + [base] + pos
    added = [False] * len(pts)
    # one-sided slopes at r = 0
    h = 1e-4 * prob.U0 / prob.L
    sm = prob.solve(-h, base)
    sp = prob.solve(h, base)
    slope = ((base["delta"] - sm["delta"]) / h, (sp["delta"] - base["delta"]) / h)
    extra = []

    def nearest(rr):
        return min(pts, key=lambda s: abs(s["r"] - rr))

    # folds: discrete local extrema of δ(r), refined by a bounded scalar search
    rs = np.array([s["r"] for s in pts])
    ds = np.array([s["delta"] for s in pts])
    for i in range(1, len(pts) - 1):
        if (ds[i] - ds[i - 1]) * (ds[i + 1] - ds[i]) < 0.0:
            sgn = 1.0 if ds[i] > ds[i - 1] else -1.0  # +1: a maximum
            res = optimize.minimize_scalar(lambda rr: -sgn * prob.solve(rr, nearest(rr))["delta"],
                                           bounds=(rs[i - 1], rs[i + 1]), method="bounded",
                                           options={"xatol": 1e-9 * prob.U0 / prob.L})
            extra.append(prob.solve(float(res.x), nearest(float(res.x))))
    # zero-rudder rates: sign changes of δ between grid points
    for i in range(len(pts) - 1):
        if ds[i] * ds[i + 1] >= 0.0 or min(abs(ds[i]), abs(ds[i + 1])) < 1e-12:
            continue  # no sign change, or a grid point is itself the crossing
        a = pts[i]
        rz = optimize.brentq(lambda rr: prob.solve(rr, a)["delta"], rs[i], rs[i + 1],
                             xtol=1e-12 * prob.U0 / prob.L)
        extra.append(prob.solve(rz, a))
    # insert the added points (skip those on a grid point)
    tol = 1e-3 * (r_hi - r_lo) / (2 * half)  # closer to a grid point than this: the grid point serves
    for s in extra:
        if np.min(np.abs(rs - s["r"])) > tol:
            pts.append(s)
            added.append(True)
    order = np.argsort([s["r"] for s in pts], kind="stable")
    pts = [pts[i] for i in order]
    added = [added[i] for i in order]
    out = {"r": np.array([s["r"] for s in pts])}
    for k in _CURVE_KEYS:
        out[k] = np.array([s[k] for s in pts])
    out["success"] = np.array([s["success"] for s in pts])
    out["torque_limited"] = np.array([any(s["torque_limited"]) for s in pts])
    out["added"] = np.array(added)
    out.update(rps=prob.rps, pitch_ratio=prob.pitch, U0=base["speed"], delta_max=dmax, ddelta_dr0=slope,
               delta0=base["delta"])
    return out


def steady_turn_at_rudder(vessel, delta: float, rps: tuple, pitch: tuple = (), curve: dict | None = None,
                          branch: int | None = None, dt: float = 0.05) -> dict:
    """The steady turn at rudder angle ``delta`` [rad] (what a direct spiral point should show).

    Found on the curve δ(r) (``curve`` from :func:`steady_turning_curve` at the same order, computed
    if None) by bracketing and :func:`scipy.optimize.brentq` on :func:`steady_turn`. ``branch``
    picks among several steady turns (inside a hysteresis loop): +1 the branch of largest r, −1 that
    of smallest r, 0 the middle (unstable) one; None requires a unique turn. Returns
    :func:`steady_turn`'s dict.
    """
    if curve is None:
        curve = steady_turning_curve(vessel, rps, pitch, dt=dt)
    r = np.asarray(curve["r"])
    d = np.asarray(curve["delta"], dtype=float) - delta
    d[np.abs(d) < 1e-10] = 0.0  # the curve ends at ±δ_max to solver precision
    brackets = [i for i in range(len(r) - 1) if d[i] * d[i + 1] <= 0.0 and d[i] != d[i + 1]]
    # a crossing exactly at a grid point appears in two brackets
    roots = []
    for i in brackets:
        if roots and d[i] == 0.0 and roots[-1] == i - 1:
            continue
        roots.append(i)
    if not roots:
        raise ValueError(f"rudder {math.degrees(delta):.3f}° is outside the curve's range")
    if branch is None:
        if len(roots) > 1:
            raise ValueError(f"{len(roots)} steady turns at rudder {math.degrees(delta):.3f}°: give branch")
        i = roots[0]
    elif branch == 0:
        if len(roots) != 3:
            raise ValueError(f"no middle branch at rudder {math.degrees(delta):.3f}°")
        i = roots[1]
    else:
        i = roots[-1] if branch > 0 else roots[0]
    prob = _Problem(vessel, rps, pitch, dt)
    keys = ("u", "v", "delta", "z", "roll", "pitch")
    ga = {k: float(curve[k][i]) for k in keys}
    gb = {k: float(curve[k][i + 1]) for k in keys}
    if d[i] == 0.0:
        return prob.solve(float(r[i]), ga)
    if d[i + 1] == 0.0:
        return prob.solve(float(r[i + 1]), gb)

    def guess(rr):
        f = (rr - r[i]) / (r[i + 1] - r[i])
        return {k: ga[k] + f * (gb[k] - ga[k]) for k in keys}

    rz = optimize.brentq(lambda rr: prob.solve(rr, guess(rr))["delta"] - delta, r[i], r[i + 1],
                         xtol=1e-13 * prob.U0 / prob.L, rtol=1e-13)
    return prob.solve(rz, guess(rz))


def hysteresis(curve: dict) -> dict:
    """Directional stability and the spiral loop from a steady-turning curve δ(r).

    The ship is directionally unstable on straight course when dδ/dr at r = 0 has the opposite
    sign to the outer branches (dδ/dr > 0 there for a ship whose starboard rudder turns it to
    starboard); either one-sided slope counts (``curve['ddelta_dr0']``, else finite differences).
    Then δ(r) has a local maximum at r₁ and a local minimum at r₂ (folds, the edges of the loop);
    for rudder angles between δ(r₂) and δ(r₁) three steady turns exist, the middle one unstable.
    Loop width = |δ(r₁) − δ(r₂)| (= 2δ* for a symmetric ship), loop height = the difference of the
    outer branches' rates at δ = 0. A stable ship: width 0, height 0, ``unstable`` False.

    Extrema and zero crossings are read from the points (exact when the curve carries them, as
    :func:`steady_turning_curve`'s does; otherwise the discrete extremum and linear interpolation).
    Returns ``unstable``, ``slope0`` (left, right) [s], ``width``, ``delta_star`` (= width/2),
    ``height`` [rad/s], ``centre`` (mid-loop rudder), ``folds`` [(r₁, δ₁), (r₂, δ₂)] and
    ``r_zero_rudder`` (rates at δ = 0 on the branch beyond r₂ and on the one below r₁) — the last
    two None if stable; height and those rates are nan if δ = 0 lies outside the loop.
    """
    r = np.asarray(curve["r"], dtype=float)
    d = np.asarray(curve["delta"], dtype=float)
    o = np.argsort(r)
    r, d = r[o], d[o]
    s_out = math.copysign(1.0, d[-1] - d[0])
    if "ddelta_dr0" in curve:
        slope = tuple(float(x) for x in curve["ddelta_dr0"])
    else:
        i0 = int(np.argmin(np.abs(r)))
        i0 = min(max(i0, 1), len(r) - 2)
        slope = (float((d[i0] - d[i0 - 1]) / (r[i0] - r[i0 - 1])), float((d[i0 + 1] - d[i0]) / (r[i0 + 1] - r[i0])))
    unstable = any(sl * s_out < 0.0 for sl in slope)
    out = {"unstable": bool(unstable), "slope0": slope, "width": 0.0, "delta_star": 0.0, "height": 0.0,
           "centre": 0.0, "folds": None, "r_zero_rudder": None}
    if not unstable:
        return out
    # folds: the extrema nearest r = 0 on either side (against the outer slope)
    ext = [i for i in range(1, len(r) - 1) if (d[i] - d[i - 1]) * (d[i + 1] - d[i]) < 0.0]
    lo = [i for i in ext if r[i] <= 0.0]
    hi = [i for i in ext if r[i] >= 0.0]
    if not lo or not hi:
        raise ValueError("unstable slope at r = 0 but no folds in the curve: extend its range")
    i1, i2 = lo[-1], hi[0]
    d1, d2 = d[i1], d[i2]
    width = abs(d1 - d2)
    # rates at zero rudder on the outer branches (outside the folds)
    r_port = r_stbd = math.nan
    for j in range(i1, 0, -1):
        if d[j] * d[j - 1] <= 0.0 and d[j] != d[j - 1]:
            r_port = r[j - 1] + (0.0 - d[j - 1]) * (r[j] - r[j - 1]) / (d[j] - d[j - 1])
            break
    for j in range(i2, len(r) - 1):
        if d[j] * d[j + 1] <= 0.0 and d[j] != d[j + 1]:
            r_stbd = r[j] + (0.0 - d[j]) * (r[j + 1] - r[j]) / (d[j + 1] - d[j])
            break
    out.update(width=float(width), delta_star=float(width / 2.0), height=float(abs(r_stbd - r_port)),
               centre=float((d1 + d2) / 2.0), folds=[(float(r[i1]), float(d1)), (float(r[i2]), float(d2))],
               r_zero_rudder=(float(r_stbd), float(r_port)))
    return out
