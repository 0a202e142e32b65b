"""Output-error refinement of hull coefficients: Levenberg–Marquardt against measured trajectories.

The team's 3-DOF model (:mod:`vtrials.sysid.mmg`, Y&Y 2015 eq. 4 with the hull terms being fitted)
is integrated with scipy ``solve_ivp`` from each maneuver's initial state, driven by the RECORDED
rudder angle (linearly interpolated) and shaft rate; the weighted residuals (simulated − measured)/σ
of the chosen channels are minimised over the free coefficients by Levenberg–Marquardt (Moré 1978,
MINPACK, via scipy ``least_squares(method="lm")``). The Jacobian comes from forward differences, all
perturbed parameter sets integrated together as one vector ODE. Parameter covariance: the Gauss–Newton
(JᵀJ)⁻¹ (Jategaonkar 2006, "Flight Vehicle System Identification", ch. 4) with the coloured-residual
correction of Morelli & Klein (1997) — see :func:`refine`.
"""

from __future__ import annotations

import dataclasses

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import least_squares

from vtrials.errors import InputError
from vtrials.sysid import mmg

_WHERE = "vtrials.sysid.output_error"

CHANNELS = ("x", "y", "psi", "u", "v", "r")


@dataclasses.dataclass(frozen=True)
class Maneuver:
    """One measured maneuver: initial state ``x0`` = (x, y, psi, u, v, r); recorded rudder angle
    ``delta`` (rad) and shaft rate ``n`` (1/s) at ``t_input``; ``outputs`` {channel: (t, z, sigma)}."""

    x0: np.ndarray
    t_input: np.ndarray
    delta: np.ndarray
    n: np.ndarray
    outputs: dict


@dataclasses.dataclass(frozen=True)
class Refined:
    """LM result: all coefficients (free ones refined), the free names, their covariance, the
    residual RMS in σ units, and the number of LM function evaluations."""

    coeffs: dict
    free: tuple
    cov: np.ndarray
    rms: float
    nfev: int
    jac: np.ndarray | None = None        # weighted residuals' Jacobian (m, p) at the solution
    residuals: np.ndarray | None = None  # weighted residuals (m,) at the solution
    bounds: tuple = ()                   # start of each (maneuver, channel) block in the residuals
    cov_white: np.ndarray | None = None  # s² (JᵀJ)⁻¹: the covariance if the residuals were white
    lags: int = 0                        # Newey–West bandwidth used, samples
    fixed_b: float = 1.0                 # the fixed-b widening folded into ``cov`` (:func:`fixed_b_factor`)

    def sigma(self) -> dict:
        return dict(zip(self.free, np.sqrt(np.diag(self.cov))))


def _rhs(ship, terms, C, t_in, d_in, n_in):
    """Vector field of P parameter sets at once: state (6P,) laid out as (6, P); C (P, len(terms))."""
    facs = [mmg._factors(t) for t in terms]
    rows = {e: np.array([j for j, t in enumerate(terms) if t[0] == e], int) for e in "XYN"}
    CX, CY, CN = (C[:, rows[e]] for e in "XYN")
    L = ship.L
    Mx, My, mxG, Izz = ship.masses()
    det = My * Izz - mxG**2
    n_const = float(n_in[0]) if np.all(n_in == n_in[0]) else None

    def f(t, y):
        x, yy, psi, u, v, r = y.reshape(6, -1)
        delta = np.interp(t, t_in, d_in)
        n = n_const if n_const is not None else np.interp(t, t_in, n_in)
        U2 = u * u + v * v
        U = np.sqrt(U2)
        val = {"v": v / U, "r": r * L / U}
        val["|v|"], val["|r|"] = np.abs(val["v"]), np.abs(val["r"])
        B = np.ones((len(terms), u.size))
        for j, fs in enumerate(facs):
            for name, absolute in fs:
                B[j] *= val["|" + name + "|" if absolute else name]
        q = 0.5 * ship.rho * L * ship.d * U2
        XH = q * np.einsum("pj,jp->p", CX, B[rows["X"]])
        YH = q * np.einsum("pj,jp->p", CY, B[rows["Y"]])
        NH = q * L * np.einsum("pj,jp->p", CN, B[rows["N"]])
        Xpr, Ypr, Npr = mmg.propeller_rudder_forces(ship, u, v, r, delta, n)
        X, Y, N = XH + Xpr, YH + Ypr, NH + Npr
        ud = (X + My * v * r + mxG * r * r) / Mx
        b1, b2 = Y - Mx * u * r, N - mxG * u * r
        c, sn = np.cos(psi), np.sin(psi)
        return np.concatenate([u * c - v * sn, u * sn + v * c, r, ud,
                               (b1 * Izz - mxG * b2) / det, (My * b2 - mxG * b1) / det])

    return f


def simulate_batch(ship, terms, C, man: Maneuver, t_eval, rtol=1e-6, atol=1e-8):
    """States (P, 6, len(t_eval)) of the model for P coefficient sets ``C`` (P, len(terms))."""
    C = np.atleast_2d(np.asarray(C, float))
    P = C.shape[0]
    y0 = np.repeat(np.asarray(man.x0, float)[:, None], P, axis=1).ravel()
    t_eval = np.asarray(t_eval, float)
    sol = solve_ivp(_rhs(ship, tuple(terms), C, man.t_input, man.delta, man.n),
                    (float(man.t_input[0]), float(t_eval[-1])), y0, method="RK45", t_eval=t_eval,
                    rtol=rtol, atol=atol)
    if sol.status < 0 or sol.y.shape[1] != t_eval.size:
        raise RuntimeError(f"model integration failed: {sol.message}")
    return sol.y.reshape(6, P, -1).transpose(1, 0, 2)


def simulate(ship, coeffs: dict, man: Maneuver, t_eval) -> np.ndarray:
    """States (6, len(t_eval)) = (x, y, psi, u, v, r) of the model with hull ``coeffs``."""
    terms = tuple(coeffs)
    return simulate_batch(ship, terms, np.array([[coeffs[t] for t in terms]]), man, t_eval)[0]


def fixed_b_factor(b: float) -> float:
    """Widening of a ±1.96 σ interval whose σ is a Bartlett-kernel (Newey–West) HAC estimate with
    bandwidth b × the record length: the 97.5 % point of the fixed-b limit of the t statistic over 1.96.
    Kiefer, N. M. & Vogelsang, T. J. (2005) "A new asymptotic theory for heteroskedasticity-
    autocorrelation robust tests", Econometric Theory 21:1130–1164 — their cubic fit of the Bartlett
    kernel's critical values, cv(b) = 1.9600 + 2.9694 b + 0.4160 b² − 0.5324 b³ (b ≤ 1)."""
    b = min(max(float(b), 0.0), 1.0)
    return (1.9600 + 2.9694 * b + 0.4160 * b**2 - 0.5324 * b**3) / 1.9600


def _residuals_batch(ship, terms, C, maneuvers, rtol=1e-5, atol=1e-7, bounds=None):
    """Weighted residuals (P, m) for P coefficient sets over all maneuvers and channels; the start
    index of each (maneuver, channel) block is appended to ``bounds`` if given."""
    out = []
    for man in maneuvers:
        times = np.unique(np.concatenate([np.asarray(v[0], float) for v in man.outputs.values()]))
        S = simulate_batch(ship, terms, C, man, times, rtol, atol)
        for ch, (tc, z, sg) in man.outputs.items():
            k = np.searchsorted(times, tc)
            e = S[:, CHANNELS.index(ch), k] - np.asarray(z, float)[None, :]
            if ch == "psi":
                e = (e + np.pi) % (2 * np.pi) - np.pi
            if bounds is not None:
                bounds.append(sum(o.shape[1] for o in out))
            out.append(e / sg)
    if bounds is not None:
        bounds.append(sum(o.shape[1] for o in out))
    return np.concatenate(out, axis=1)


def refine(ship, coeffs0: dict, free, maneuvers, rel_step: float = 1e-4, max_nfev: int = 20,
           lags: int | str = 20, rtol: float = 1e-5, atol: float = 1e-7) -> Refined:
    """Levenberg–Marquardt refinement of the ``free`` coefficients (others held at ``coeffs0``).

    Covariance: (JᵀJ)⁻¹ M (JᵀJ)⁻¹ with M the Newey–West sum of J_tᵀ e_t e_{t−l} J_{t−l} over
    ``lags`` samples within each (maneuver, channel) record — the coloured-residual correction of
    Morelli & Klein (1997), J. Guid. Control Dyn. 20(4):796 — since output-error residuals are
    correlated in time. With the bandwidth a sizeable fraction b of a record, the Newey–West variance is
    biased low and itself uncertain; ``cov`` is scaled by the fixed-b factor (:func:`fixed_b_factor`),
    so that ±1.96 σ is Kiefer & Vogelsang's (2005) 95 % interval. ``lags = 0`` gives the white-residual
    s² (JᵀJ)⁻¹ (up to the s² estimate);
    ``lags = "auto"``: Andrews' (1991) bandwidth from the residuals' lag-1 correlation
    (:func:`vtrials.sysid.regression.andrews_lags`). ``rtol``/``atol``: integration tolerances of the
    model. The result also holds the white-residual covariance s² (JᵀJ)⁻¹ (``cov_white``; s² the
    residuals' mean square with m − p degrees of freedom): their diagonal ratio is the effective-sample
    correction n/n_eff the coloured residuals call for."""
    terms = tuple(coeffs0)
    free = tuple(free)
    for f in free:
        if f not in coeffs0:
            raise InputError(_WHERE, "free", f"{f!r} is not among the model's terms {terms}")
    for man in maneuvers:
        for ch in man.outputs:
            if ch not in CHANNELS:
                raise InputError(_WHERE, "outputs", f"{ch!r}; allowed: {', '.join(CHANNELS)}")
    jf = [terms.index(f) for f in free]
    base = np.array([coeffs0[t] for t in terms])

    def full(p):
        c = base.copy()
        c[jf] = p
        return c

    p0 = base[jf].copy()
    h = rel_step * np.maximum(np.abs(p0), 1e-2)
    cache = {}

    def batch(p):
        key = p.tobytes()
        if key not in cache:
            C = np.repeat(full(p)[None, :], len(free) + 1, axis=0)
            for i, j in enumerate(jf):
                C[i + 1, j] += h[i]
            R = _residuals_batch(ship, terms, C, maneuvers, rtol, atol)
            cache.clear()
            cache[key] = (R[0], ((R[1:] - R[0]) / h[:, None]).T)
        return cache[key]

    res = least_squares(lambda p: batch(p)[0], p0, jac=lambda p: batch(p)[1], method="lm",
                        max_nfev=max_nfev, x_scale="jac")
    r, J = batch(res.x)
    bounds: list = []
    _residuals_batch(ship, terms, full(res.x)[None, :], maneuvers, rtol, atol, bounds)
    m, p = r.size, len(free)
    if lags == "auto":
        from vtrials.sysid.regression import andrews_lags
        lags = andrews_lags(r, bounds)
    g = J * r[:, None]
    M = g.T @ g
    for lag in range(1, lags + 1):
        G = np.zeros_like(M)
        for a, b in zip(bounds[:-1], bounds[1:]):
            if b - a > lag:
                G += g[a + lag:b].T @ g[a:b - lag]
        M += (1.0 - lag / (lags + 1.0)) * (G + G.T)
    H = np.linalg.pinv(J.T @ J)
    sizes = np.diff(bounds)
    factor = fixed_b_factor(lags / float(np.mean(sizes[sizes > 0])))
    cov = H @ M @ H * m / (m - p) * factor**2
    out = dict(zip(terms, full(res.x)))
    return Refined(out, free, cov, float(np.sqrt(np.mean(r**2))), int(res.nfev), J, r, tuple(bounds),
                   H * float(r @ r) / (m - p), int(lags), float(factor))


def channel_sigmas(ship, coeffs: dict, maneuvers, floor: dict | None = None, rtol: float = 1e-5,
                   atol: float = 1e-7) -> dict:
    """Each channel's output-error standard deviation: the RMS over all maneuvers of the model's
    (simulated − measured) at ``coeffs`` — the maximum-likelihood estimate of a diagonal measurement-
    noise covariance for fixed parameters (Jategaonkar 2006, ch. 4, the relaxation step of the
    output-error method; Maine & Iliff 1986, NASA RP-1168), never below ``floor`` {channel: σ} (the
    measurement's own stated σ)."""
    terms = tuple(coeffs)
    C = np.array([[coeffs[t] for t in terms]])
    sq: dict = {}
    for man in maneuvers:
        ones = dataclasses.replace(man, outputs={ch: (tc, z, 1.0) for ch, (tc, z, _) in man.outputs.items()})
        bounds: list = []
        e = _residuals_batch(ship, terms, C, [ones], rtol, atol, bounds)[0]
        for ch, a, b in zip(ones.outputs, bounds[:-1], bounds[1:]):
            sq.setdefault(ch, []).append(e[a:b])
    out = {ch: float(np.sqrt(np.mean(np.concatenate(v)**2))) for ch, v in sq.items()}
    return {ch: max(s, (floor or {}).get(ch, 0.0)) for ch, s in out.items()}


def with_sigmas(maneuvers, sigmas: dict) -> list:
    """The maneuvers with every channel's σ replaced by ``sigmas[channel]``."""
    return [dataclasses.replace(m, outputs={ch: (tc, z, sigmas[ch]) for ch, (tc, z, _) in m.outputs.items()})
            for m in maneuvers]


def shift(ship, res: Refined, maneuvers, i: int, perturbed: Maneuver, rtol: float = 1e-5,
          atol: float = 1e-7) -> np.ndarray:
    """Linearised change of the free coefficients if maneuver ``i``'s data (inputs, initial state or
    outputs) were ``perturbed`` instead: δp = −(JᵀJ)⁻¹ Jᵢᵀ δrᵢ, δrᵢ the change of that maneuver's
    weighted residuals at the solution (one Gauss–Newton step; the GUM's sensitivity, JCGM 100:2008
    §5.1, of the output-error estimate to an error common to one record)."""
    terms = tuple(res.coeffs)
    C = np.array([[res.coeffs[t] for t in terms]])
    start = sum(sum(np.size(v[0]) for v in m.outputs.values()) for m in maneuvers[:i])
    base = _residuals_batch(ship, terms, C, [maneuvers[i]], rtol, atol)[0]
    new = _residuals_batch(ship, terms, C, [perturbed], rtol, atol)[0]
    Ji = res.jac[start:start + base.size]
    return -np.linalg.pinv(res.jac.T @ res.jac) @ (Ji.T @ (new - base))
