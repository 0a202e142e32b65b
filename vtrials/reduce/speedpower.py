"""Speed–power curves and the resistance-increase corrections of the speed/power trial analysis.

Units: speeds m/s, power W, resistance N, angles rad, air density kg/m³, areas m², heights m,
shaft speed rev/s, torque N m, thrust N. Sources: ITTC Recommended Procedure 7.5-04-01-01.1
"Preparation, conduct and analysis of speed/power trials" (2017, rev. 2021) and ISO 15016:2015
(harmonised with it); Strasser et al. 2015 (J. Mar. Sci. Technol. 20, 2–13) for their verification.

Uncertainty: every fit returns the parameter covariance; predictions use the delta method
var ŷ(x) = g(x)ᵀ Σ g(x), g = ∂ŷ/∂θ, with Student-t quantiles on the residual degrees of freedom
(Seber & Wild, *Nonlinear Regression*, 1989, §5.1; exact for models linear in the parameters).
"""

from __future__ import annotations

import dataclasses
import math
from typing import Callable

import numpy as np
from scipy import optimize, stats

from vtrials.reduce.estimate import Estimate
from vtrials.reduce.runstats import sandwich_variance

RHO_AIR = 1.225  # [kg/m³] ISA sea-level air density; pass the measured value when known
# power-law exponent of the true wind's height profile: 1/9 in ITTC 7.5-04-01-01.1 (2017, rev. 2021)
# §"Resistance increase due to wind" and in ISO 15016:2015 (harmonised with it); the simulated mean
# wind uses the same (vtrials.physics.environment.wind.TRIALS_PROFILE_EXPONENT)
WIND_PROFILE_EXPONENT = 1.0 / 9.0


# ==================================================================================================
# curve fits
# ==================================================================================================
@dataclasses.dataclass(frozen=True)
class CurveFit:
    """A fitted curve y(x) with parameter covariance.

    kind "power": y = a + b x^q (params a, b[, q]); "powerlaw": y = b x^q (b[, q]); "poly":
    y = Σ c_k x^k (c0..c_deg). q_fixed holds q when it was not fitted. s: residual standard deviation
    (weighted: of the standardised residuals × 1 when weights are absolute); dof = n − p.
    """

    kind: str
    params: np.ndarray
    cov: np.ndarray
    names: tuple
    dof: int
    s: float
    x: np.ndarray
    y: np.ndarray
    residuals: np.ndarray
    q_fixed: float | None = None
    degree: int | None = None
    absolute_sigma: bool = False

    # -- model ---------------------------------------------------------------------------------
    def _q(self):
        return self.q_fixed if self.q_fixed is not None else self.params[self.names.index("q")]

    def __call__(self, x):
        x = np.asarray(x, dtype=float)
        p = self.params
        if self.kind == "poly":
            return np.polyval(p[::-1], x)
        if self.kind == "power":
            return p[0] + p[1] * x ** self._q()
        return p[0] * x ** self._q()  # powerlaw

    def gradient(self, x):
        """∂y/∂params at x, shape (len(x), n_params)."""
        x = np.atleast_1d(np.asarray(x, dtype=float))
        p = self.params
        if self.kind == "poly":
            return np.column_stack([x ** k for k in range(p.size)])
        q = self._q()
        xq = x ** q
        lx = np.log(np.maximum(x, 1e-300))
        if self.kind == "power":
            cols = [np.ones_like(x), xq]
            if self.q_fixed is None:
                cols.append(p[1] * xq * lx)
        else:
            cols = [xq]
            if self.q_fixed is None:
                cols.append(p[0] * xq * lx)
        return np.column_stack(cols)

    def derivative(self, x):
        """dy/dx at x."""
        x = np.asarray(x, dtype=float)
        p = self.params
        if self.kind == "poly":
            return np.polyval(np.polyder(p[::-1]), x)
        q = self._q()
        bb = p[1] if self.kind == "power" else p[0]
        return bb * q * x ** (q - 1.0)

    # -- uncertainty ---------------------------------------------------------------------------
    def param(self, name) -> Estimate:
        i = self.names.index(name)
        return Estimate(float(self.params[i]), float(math.sqrt(max(self.cov[i, i], 0.0))),
                        None if self.absolute_sigma else (self.dof if self.dof > 0 else None))

    def predict(self, x):
        """(ŷ, std of the mean response) at x (delta method)."""
        g = self.gradient(x)
        var = np.einsum("ij,jk,ik->i", g, self.cov, g)
        y = np.atleast_1d(self(x))
        return y, np.sqrt(np.maximum(var, 0.0))

    def _quantile(self, level):
        if self.absolute_sigma or self.dof <= 0:
            return stats.norm.ppf(0.5 + level / 2.0)
        return stats.t.ppf(0.5 + level / 2.0, self.dof)

    def band(self, x, level=0.95, prediction=False):
        """Two-sided confidence band (lo, hi) of the mean curve at x, or with ``prediction=True`` the
        prediction band for one new observation (adds the residual variance s²)."""
        y, sd = self.predict(x)
        if prediction:
            sd = np.sqrt(sd * sd + self.s ** 2)
        k = self._quantile(level)
        return y - k * sd, y + k * sd

    def at(self, x) -> Estimate:
        """ŷ(x) at a scalar x as an Estimate."""
        y, sd = self.predict(float(x))
        return Estimate(float(y[0]), float(sd[0]),
                        None if self.absolute_sigma else (self.dof if self.dof > 0 else None))

    def inverse(self, y, bracket=None) -> Estimate:
        """x such that ŷ(x) = y (monotone part of the curve within ``bracket``, default the data range
        widened by 50 %); std by the delta method σ_x = σ_ŷ(x)/|dŷ/dx| (curve uncertainty only)."""
        if bracket is None:
            lo, hi = float(np.min(self.x)), float(np.max(self.x))
            span = hi - lo
            left = lo - 0.5 * span
            if self.kind != "poly":
                left = max(left, 1e-9)
            bracket = (left, hi + 0.5 * span)
        xr = optimize.brentq(lambda z: float(self(z)) - y, *bracket, xtol=1e-14, rtol=1e-14)
        _, sd = self.predict(xr)
        slope = float(self.derivative(xr))
        return Estimate(float(xr), float(sd[0]) / abs(slope),
                        None if self.absolute_sigma else (self.dof if self.dof > 0 else None))


def _var_proj_q(x, y, w, kind, q_bounds):
    """Variable projection for q: for fixed q the model is linear in the other parameters."""

    def design(q):
        xq = x ** q
        return np.column_stack([np.ones_like(x), xq]) if kind == "power" else xq[:, None]

    def rss(q):
        X = design(q) * w[:, None]
        beta, *_ = np.linalg.lstsq(X, y * w, rcond=None)
        r = y * w - X @ beta
        return float(r @ r)

    grid = np.linspace(q_bounds[0], q_bounds[1], 120)
    vals = [rss(g) for g in grid]
    k = int(np.argmin(vals))
    lo, hi = grid[max(k - 1, 0)], grid[min(k + 1, grid.size - 1)]
    res = optimize.minimize_scalar(rss, bounds=(lo, hi), method="bounded", options={"xatol": 1e-12})
    q = float(res.x)
    X = design(q) * w[:, None]
    beta, *_ = np.linalg.lstsq(X, y * w, rcond=None)
    return beta, q


def fit_curve(x, y, kind="poly", degree=2, q=None, std=None, absolute_sigma=None,
              q_bounds=(0.5, 10.0)) -> CurveFit:
    """Least-squares curve y(x): "poly" (degree ``degree``), "power" y = a + b x^q, or "powerlaw"
    y = b x^q (q fitted unless given). Use it for speed–power, speed vs r/min, torque, thrust, etc.

    std: per-point standard uncertainty of y (weights 1/std²); absolute_sigma (default: True when std is
    given) uses (JᵀWJ)⁻¹ as the covariance, otherwise s²(JᵀWJ)⁻¹ with s² = Σw r²/(n − p). For a fitted q
    the fit is by variable projection (Golub & Pereyra 1973) on a grid-bracketed bounded search; the
    covariance uses the full Jacobian including ∂/∂q.
    """
    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)
    if x.shape != y.shape or x.ndim != 1:
        raise ValueError("x and y must be equal-length 1-D arrays")
    n = x.size
    sv = None if std is None else np.broadcast_to(np.asarray(std, dtype=float), (n,))
    w = np.ones(n) if sv is None else 1.0 / sv
    if absolute_sigma is None:
        absolute_sigma = sv is not None
    if kind == "poly":
        X = np.column_stack([x ** k for k in range(degree + 1)])
        beta, *_ = np.linalg.lstsq(X * w[:, None], y * w, rcond=None)
        params = beta
        names = tuple(f"c{k}" for k in range(degree + 1))
        q_fixed = None
    elif kind in ("power", "powerlaw"):
        if np.any(x <= 0):
            raise ValueError("power-law fits need x > 0")
        if q is None:
            beta, qq = _var_proj_q(x, y, w, kind, q_bounds)
            params = np.r_[beta, qq]
            q_fixed = None
        else:
            xq = x ** q
            X = np.column_stack([np.ones_like(x), xq]) if kind == "power" else xq[:, None]
            beta, *_ = np.linalg.lstsq(X * w[:, None], y * w, rcond=None)
            params = beta
            q_fixed = float(q)
        names = (("a", "b") if kind == "power" else ("b",)) + (("q",) if q is None else ())
    else:
        raise ValueError("kind must be 'poly', 'power' or 'powerlaw'")
    tmp = CurveFit(kind=kind, params=np.asarray(params, dtype=float), cov=np.zeros((len(names),) * 2),
                   names=names, dof=n - len(names), s=0.0, x=x, y=y, residuals=np.zeros(n),
                   q_fixed=q_fixed, degree=degree if kind == "poly" else None,
                   absolute_sigma=bool(absolute_sigma))
    if kind != "poly" and q is None:
        # Gauss–Newton polish of all parameters (the 1-D search on q stops at ~√eps of the flat RSS)
        rss = float(np.sum((w * (y - tmp(x))) ** 2))
        for _ in range(30):
            J = tmp.gradient(x) * w[:, None]
            step, *_ = np.linalg.lstsq(J, w * (y - tmp(x)), rcond=None)
            trial = dataclasses.replace(tmp, params=tmp.params + step)
            rss_new = float(np.sum((w * (y - trial(x))) ** 2))
            if not rss_new < rss:
                break
            tmp, rss = trial, rss_new
    J = tmp.gradient(x)
    r = y - tmp(x)
    dof = n - len(names)
    Jw = J * w[:, None]
    inv = np.linalg.pinv(Jw.T @ Jw)
    rss_w = float(np.sum((w * r) ** 2))
    s = math.sqrt(rss_w / dof) if dof > 0 else math.nan
    if absolute_sigma:
        cov = inv
        s_out = 1.0 if sv is not None else s
    elif dof > 0:
        cov = inv * rss_w / dof
        s_out = s
    else:
        cov = np.full_like(inv, np.nan)
        s_out = math.nan
    return dataclasses.replace(tmp, cov=cov, dof=dof, s=s_out, residuals=r)


def fit_speed_power(vs, power, q=None, kind="power", degree=3, std=None, absolute_sigma=None) -> CurveFit:
    """Speed–power curve P(V_S) from speeds through water [m/s] and (corrected) powers [W].

    Default P = a + b V^q — the form of the ITTC 7.5-04-01-01.1 (2017) iterative method and ISO
    15016:2015 — with q fitted (or fixed, e.g. q = 3); kind="poly" for a polynomial of ``degree``.
    See :func:`fit_curve` for the uncertainty options.
    """
    return fit_curve(vs, power, kind=kind, degree=degree, q=q, std=std, absolute_sigma=absolute_sigma)


def power_at_speed(fit: CurveFit, v) -> Estimate:
    """Power [W] at speed v [m/s] (scalar) with the delta-method uncertainty of the mean curve."""
    return fit.at(v)


def speed_at_power(fit: CurveFit, p) -> Estimate:
    """Speed [m/s] at power p [W] (e.g. contract power), σ_V = σ_P̂(V)/|dP/dV|."""
    return fit.inverse(p)


# ==================================================================================================
# wind
# ==================================================================================================
def true_wind(v_wr, psi_wr, v_g):
    """True wind from the measured relative wind and the ship's speed over ground.

    v_wr [m/s] relative wind speed, psi_wr [rad] relative wind angle (direction the wind comes FROM,
    clockwise from the bow; 0 = head wind), v_g [m/s] speed over ground (the ship's track is assumed
    along its heading — no drift). The wind of the ship's own motion comes from ahead at V_G, so
    (ITTC 7.5-04-01-01.1 (2017) §"wind"; ISO 15016:2015 annex on true wind):

        V_WT = √(V_WR² + V_G² − 2 V_WR V_G cos ψ_WR),
        ψ_WT = atan2(V_WR sin ψ_WR, V_WR cos ψ_WR − V_G)    (from-direction relative to the bow).

    Returns (v_wt, psi_wt) arrays; the true direction from north is heading + ψ_WT.
    """
    v_wr = np.asarray(v_wr, dtype=float)
    psi = np.asarray(psi_wr, dtype=float)
    v_g = np.asarray(v_g, dtype=float)
    x = v_wr * np.cos(psi) - v_g
    y = v_wr * np.sin(psi)
    return np.hypot(x, y), np.arctan2(y, x)


def relative_wind(v_wt, psi_wt, v_g):
    """Inverse of :func:`true_wind`: V_WR = √(V_WT² + V_G² + 2V_WT V_G cos ψ_WT),
    ψ_WR = atan2(V_WT sin ψ_WT, V_WT cos ψ_WT + V_G). Angles relative to the bow [rad]."""
    v_wt = np.asarray(v_wt, dtype=float)
    psi = np.asarray(psi_wt, dtype=float)
    x = v_wt * np.cos(psi) + np.asarray(v_g, dtype=float)
    y = v_wt * np.sin(psi)
    return np.hypot(x, y), np.arctan2(y, x)


@dataclasses.dataclass(frozen=True)
class WindResistance:
    """R_AA [N] per run with std; the wind used: v_wr_ref, psi_wr_ref (relative, at the reference
    height), v_wt, psi_wt (true, at the anemometer height, relative to the bow). coef_sens [N]: the
    signed change of each run's R_AA for a +1σ error of the coefficient (part of ``std``), one error
    common to the runs, so that a mean over runs can combine it with its signs."""

    r_aa: np.ndarray
    std: np.ndarray
    v_wr_ref: np.ndarray
    psi_wr_ref: np.ndarray
    v_wt: np.ndarray
    psi_wt: np.ndarray
    coef_sens: np.ndarray | None = None


def average_true_wind(v_wt, psi_wt, heading):
    """True wind averaged as a vector over a double run (ITTC 7.5-04-01-01.1 (2017) §"wind": the true
    wind vectors of the runs of a pair are averaged, then each run's relative wind is recomposed from
    the mean true wind and that run's heading and speed). v_wt [m/s], psi_wt [rad, from-direction off
    the bow], heading [rad] per run; returns per run (v_wt, psi_wt) of the mean true wind."""
    v_wt = np.asarray(v_wt, dtype=float)
    d = np.asarray(psi_wt, dtype=float) + np.asarray(heading, dtype=float)  # from-direction off north
    x, y = float(np.mean(v_wt * np.cos(d))), float(np.mean(v_wt * np.sin(d)))
    mean_dir = math.atan2(y, x)
    psi = np.arctan2(np.sin(mean_dir - heading), np.cos(mean_dir - heading))
    return np.full_like(v_wt, math.hypot(x, y)), psi


def correct_airwake(speed, angle, speed_coef, direction_coef):
    """Undo a mast anemometer's airwake calibration: the site reads U_m = U (1 + a₀ + Σ aₖ cos kγ +
    bₖ sin kγ) at γ_m = γ + c₀ + Σ cₖ sin kγ (γ the undisturbed relative wind angle; coefficients from
    the ship's airwake survey or model test, ITTC 7.5-04-01-01.1 (2017) §"wind": the anemometer
    reading is corrected for the ship's own airwake). speed_coef = [a₀, a₁, b₁, a₂, b₂, …],
    direction_coef = [c₀, c₁, …] [rad]. Returns the undisturbed (speed, angle), γ by fixed point."""
    sp = np.asarray(speed, dtype=float)
    gm = np.asarray(angle, dtype=float)
    ws = np.asarray(speed_coef, dtype=float)
    wd = np.asarray(direction_coef, dtype=float)

    def off(g):
        return wd[0] + sum(wd[i] * np.sin(i * g) for i in range(1, wd.size)) if wd.size else 0.0 * g

    g = gm.copy()
    for _ in range(60):
        g = gm - off(g)
    k = (ws.size - 1) // 2
    fac = 1.0 + (ws[0] if ws.size else 0.0) + sum(ws[2 * i - 1] * np.cos(i * g) + ws[2 * i] * np.sin(i * g)
                                                  for i in range(1, k + 1))
    return sp / fac, g


def _r_aa(v_wr, psi_wr, v_g, cx, a_xv, rho_a, z_a, z_ref, heading=None):
    v_wt, psi_wt = true_wind(v_wr, psi_wr, v_g)
    if heading is not None:
        v_wt, psi_wt = average_true_wind(v_wt, psi_wt, heading)
    if z_a is not None or heading is not None:
        v_wt_ref = v_wt if z_a is None else v_wt * (z_ref / z_a) ** WIND_PROFILE_EXPONENT
        v_wr_ref, psi_wr_ref = relative_wind(v_wt_ref, psi_wt, v_g)
    else:
        v_wr_ref, psi_wr_ref = np.asarray(v_wr, float), np.asarray(psi_wr, float)
    r = 0.5 * rho_a * a_xv * (np.asarray(cx(psi_wr_ref), dtype=float) * v_wr_ref ** 2
                              - float(cx(0.0)) * np.asarray(v_g, float) ** 2)
    return r, v_wr_ref, psi_wr_ref, v_wt, psi_wt


def wind_resistance(v_wr, psi_wr, v_g, cx: Callable, a_xv, rho_a=RHO_AIR, z_anemometer=None,
                    z_ref=10.0, v_wr_std=None, psi_wr_std=None, cx_rel_std=0.0, heading=None) -> WindResistance:
    """Resistance increase due to wind (ITTC 7.5-04-01-01.1 (2017) eq. for R_AA; ISO 15016:2015):

        R_AA = ½ ρ_A C_X(ψ_WR,ref) A_XV V_WR,ref² − ½ ρ_A C_X(0) A_XV V_G²

    The second term removes the still-air resistance of the ship's own motion (relative wind V_G from
    ahead), which the reference (tank) prediction already contains. Inputs per run: measured relative
    wind speed v_wr [m/s] and angle psi_wr [rad, from-direction clockwise from the bow], v_g [m/s],
    cx(ψ) the ship's wind resistance coefficient (positive = resistance, i.e. −C_X of the usual
    body-axis force convention), a_xv [m²] transverse projected area above the waterline, rho_a
    [kg/m³]. If z_anemometer [m] is given, the true wind is brought to the reference height z_ref of
    the coefficients by the 1/9 power law V_WT,ref = V_WT (z_ref/z_a)^{1/9} (ITTC 2017; ISO 15016:2015)
    and the relative wind is recomposed; otherwise the measured relative wind is used as is. With
    ``heading`` [rad] per run (the runs of one double run), the true wind vectors are averaged over
    the runs first (:func:`average_true_wind`, ITTC 2017).

    Uncertainty: v_wr_std [m/s], psi_wr_std [rad] propagated by central differences, plus a relative
    uncertainty cx_rel_std of the coefficient (applied to the first term).
    """
    v_wr = np.atleast_1d(np.asarray(v_wr, dtype=float))
    psi_wr = np.atleast_1d(np.asarray(psi_wr, dtype=float))
    v_g = np.atleast_1d(np.asarray(v_g, dtype=float))
    args = (cx, a_xv, rho_a, z_anemometer, z_ref, None if heading is None else np.atleast_1d(np.asarray(heading, float)))
    r, vr_ref, pr_ref, vwt, pwt = _r_aa(v_wr, psi_wr, v_g, *args)
    var = np.zeros_like(r)
    if v_wr_std is not None:
        h = 1e-6 * np.maximum(np.abs(v_wr), 1.0)
        d = (_r_aa(v_wr + h, psi_wr, v_g, *args)[0] - _r_aa(v_wr - h, psi_wr, v_g, *args)[0]) / (2 * h)
        var = var + (d * np.asarray(v_wr_std, dtype=float)) ** 2
    if psi_wr_std is not None:
        h = 1e-6
        d = (_r_aa(v_wr, psi_wr + h, v_g, *args)[0] - _r_aa(v_wr, psi_wr - h, v_g, *args)[0]) / (2 * h)
        var = var + (d * np.asarray(psi_wr_std, dtype=float)) ** 2
    sens = np.zeros_like(r)
    if cx_rel_std:
        first = 0.5 * rho_a * a_xv * np.asarray(cx(pr_ref), dtype=float) * vr_ref ** 2
        sens = cx_rel_std * first
        var = var + sens ** 2
    return WindResistance(r_aa=r, std=np.sqrt(var), v_wr_ref=vr_ref, psi_wr_ref=pr_ref, v_wt=vwt,
                          psi_wt=pwt, coef_sens=sens)


def direct_power_method(p_ms, delta_r, v_s, eta_d_id, eta_d_ms=None, p_ms_std=None,
                        delta_r_std=None, xi_p=None):
    """Corrected power by the Direct Power Method (ITTC 7.5-04-01-01.1 (2017, rev. 2021) §"Direct
    Power Method"; ISO 15016:2015):

        P_D,id = P_D,ms − ΔR V_S/η_D,id − P_D,ms (1 − η_D,ms/η_D,id)

    p_ms [W] measured delivered power, delta_r [N] total resistance increase (wind + waves + …),
    v_s [m/s] speed through water, eta_d_id propulsive efficiency in the ideal condition (from the
    model tests), eta_d_ms in the trial condition. The standard takes η_D,ms from the overload factor
    ξ_P of the load-variation test (:func:`overload_factor`),

        η_D,ms = η_D,id / (1 + ξ_P (P_D,ms − P_D,id)/P_D,id),

    which is implicit in P_D,id and solved here by fixed-point iteration when ``xi_p`` is given. With
    neither eta_d_ms nor xi_p the third term is dropped (η_D,ms = η_D,id, the simple form
    P_id = P_ms − ΔR V_S/η_D) — which overstates the corrected power when the propeller is overloaded.

    Returns (p_id, std) arrays; std from p_ms_std [W] and delta_r_std [N] (independent; the small
    dependence of η_D,ms on the data is not propagated).
    """
    p_ms = np.asarray(p_ms, dtype=float)
    dr = np.asarray(delta_r, dtype=float)
    v_s = np.asarray(v_s, dtype=float)
    if xi_p is not None:
        if eta_d_ms is not None:
            raise ValueError("give eta_d_ms or xi_p, not both")
        xi = np.asarray(xi_p, dtype=float)
        p_id = p_ms - dr * v_s / eta_d_id
        for _ in range(100):
            ratio = 1.0 / (1.0 + xi * (p_ms - p_id) / p_id)  # η_D,ms / η_D,id
            new = p_ms - dr * v_s / eta_d_id - p_ms * (1.0 - ratio)
            if np.all(np.abs(new - p_id) <= 1e-12 * np.abs(p_ms)):
                p_id = new
                break
            p_id = new
        ratio = 1.0 / (1.0 + xi * (p_ms - p_id) / p_id)
    else:
        ratio = 1.0 if eta_d_ms is None else np.asarray(eta_d_ms, dtype=float) / eta_d_id
        p_id = p_ms - dr * v_s / eta_d_id - p_ms * (1.0 - ratio)
    var = np.zeros(np.broadcast(p_ms, dr, v_s).shape)
    if p_ms_std is not None:
        var = var + (np.asarray(ratio) * np.asarray(p_ms_std, dtype=float)) ** 2
    if delta_r_std is not None:
        var = var + (v_s / eta_d_id * np.asarray(delta_r_std, dtype=float)) ** 2
    return p_id, np.sqrt(var)


def overload_factor(p_d, eta_d, p_d_id, eta_d_id) -> float:
    """Overload factor ξ_P from a load-variation test at one speed (ITTC 7.5-04-01-01.1 (2017, rev.
    2021); ISO 15016:2015): the least-squares slope through the origin of η_D,id/η_D − 1 against
    (P_D − P_D,id)/P_D,id over the test's loadings, the relation the Direct Power Method uses
    (:func:`direct_power_method`). p_d [W], eta_d [–] per loading; p_d_id, eta_d_id at zero added load."""
    x = (np.asarray(p_d, dtype=float) - p_d_id) / p_d_id
    y = eta_d_id / np.asarray(eta_d, dtype=float) - 1.0
    if x.size < 1 or not np.any(x != 0):
        raise ValueError("the load-variation test needs at least one loading that changes the power")
    return float(x @ y / (x @ x))


def acceleration_resistance(accel, displacement_m3, rho_water=1025.0, added_mass_fraction=0.08, accel_std=None):
    """Inertial resistance of a ship still gaining (or losing) speed on a run: R_acc = (m + m_x) a [N],
    m = ρ ∇, m_x = ``added_mass_fraction`` × m, a [m/s²] the run's mean acceleration along its track.
    A run the director accepted as steady may still carry a small acceleration that his instruments
    cannot resolve (a VLCC at 1e-4 m/s² over a 10-min run: 0.1 kn, ~3 % of its resistance); adding
    R_acc to the resistance increase removes it in the Direct Power Method. This is a correction beyond
    ITTC 7.5-04-01-01.1 (2017), which asks for steady runs instead. Default m_x/m = 0.08: KVLCC2's
    m′_x/m′ = 0.022/0.274 (Yasukawa & Yoshimura 2015, J. Mar. Sci. Technol. 20:37–52, Table 3).
    An acceleration the fixes do not resolve (|a| < 2 std) is taken as zero: only a resolved trend is
    corrected, as only a significant trend makes the director call a run unsteady.
    Returns (R_acc, std)."""
    m = rho_water * float(displacement_m3) * (1.0 + added_mass_fraction)
    if accel_std is not None:
        accel = np.where(np.abs(np.asarray(accel, float)) > 2.0 * np.asarray(accel_std, float), accel, 0.0)
    a = np.asarray(accel, dtype=float)
    return m * a, (np.zeros_like(a) if accel_std is None else m * np.asarray(accel_std, dtype=float))


def along_track_acceleration(t, north, east, t0=None, t1=None):
    """Mean acceleration along the track [m/s²] in [t0, t1] and its standard error: least-squares
    quadratic s(t) = s₀ + v t + ½ a t² of the along-track distance (projected on the mean course);
    the standard error allows for correlated fix errors (sandwich variance of the residuals,
    :func:`vtrials.reduce.runstats.sandwich_variance`)."""

    t = np.asarray(t, dtype=float)
    w = np.isfinite(t) & np.isfinite(north) & np.isfinite(east)
    if t0 is not None:
        w &= t >= t0
    if t1 is not None:
        w &= t <= t1
    t, n, e = t[w], np.asarray(north, float)[w], np.asarray(east, float)[w]
    if t.size < 5:
        raise ValueError("need at least 5 fixes for an acceleration")
    tc = t - t.mean()
    vn, ve = np.polyfit(tc, n, 1)[0], np.polyfit(tc, e, 1)[0]
    c = math.atan2(ve, vn)
    s = n * math.cos(c) + e * math.sin(c)
    X = np.column_stack([np.ones_like(tc), tc, 0.5 * tc ** 2])
    P = np.linalg.pinv(X)
    beta = P @ s
    r = s - X @ beta
    var, _ = sandwich_variance(P[2], r)
    return float(beta[2]), float(math.sqrt(max(var * t.size / max(t.size - 3, 1), 0.0)))


def along_track_acceleration_from_velocity(t, sog, cog, t0=None, t1=None):
    """Mean acceleration along the track [m/s²] in [t0, t1] and its standard error, from a receiver's
    own velocity (GNSS Doppler SOG [m/s] and COG [rad]): least-squares slope of the along-track
    velocity sog·cos(cog − c̄), c̄ the circular mean course. Doppler velocities do not carry the slowly
    varying errors of the code positions (velocity from the carrier's Doppler shift, a few cm/s;
    Misra & Enge, Global Positioning System: Signals, Measurements, and Performance, 2nd ed. 2006),
    so a 10-min run's slope is resolved far better than from the fixes' curvature. The
    standard error is the sandwich variance of the residuals (gusts and helm make the speed
    fluctuations coloured, :func:`vtrials.reduce.runstats.sandwich_variance`)."""

    t = np.asarray(t, dtype=float)
    sog, cog = np.asarray(sog, dtype=float), np.asarray(cog, dtype=float)
    w = np.isfinite(t) & np.isfinite(sog) & np.isfinite(cog)
    if t0 is not None:
        w &= t >= t0
    if t1 is not None:
        w &= t <= t1
    t, sog, cog = t[w], sog[w], cog[w]
    if t.size < 5:
        raise ValueError("need at least 5 velocities for an acceleration")
    c = math.atan2(float(np.sum(sog * np.sin(cog))), float(np.sum(sog * np.cos(cog))))
    v = sog * np.cos(cog - c)
    X = np.column_stack([np.ones_like(t), t - t.mean()])
    P = np.linalg.pinv(X)
    r = v - X @ (P @ v)
    var, _ = sandwich_variance(P[1], r)
    return float(P[1] @ v), float(math.sqrt(max(var * t.size / max(t.size - 2, 1), 0.0)))


def displacement_correction(power, disp_trial, disp_target, power_std=None):
    """P₂ = P₁ (∇₂/∇₁)^{2/3} (Admiralty-type displacement correction; ITTC 7.5-04-01-01.1 (2017),
    ISO 15016:2015 — intended for small differences between trial and contract displacement).
    power [W], displacements [m³] (or any consistent unit). Returns (p2, std)."""
    f = (np.asarray(disp_target, dtype=float) / np.asarray(disp_trial, dtype=float)) ** (2.0 / 3.0)
    p2 = np.asarray(power, dtype=float) * f
    std = np.zeros_like(p2) if power_std is None else np.asarray(power_std, dtype=float) * f
    return p2, std
