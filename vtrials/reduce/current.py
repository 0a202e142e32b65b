"""Current elimination: speed through the water from speeds over ground of runs at equal settings.

Units: speeds m/s, times s, headings and directions rad (clockwise from true north), power W.
A current "direction" θ here is its *set* (the direction it flows toward). Every result carries a
standard uncertainty (:class:`~vtrials.reduce.estimate.Estimate` or an explicit std array); where the
inputs carry no uncertainty and the method has no redundancy the std is NaN, never a made-up number.

Scalar (along-course) methods — runs on a base course and its reciprocal, alternating
---------------------------------------------------------------------------------------
Let run i (i = 0..n−1, equally spaced in time by Δ) have V_G,i = V_S + sᵢ c(tᵢ), sᵢ = (−1)^i, with c the
current component along the base course. Repeated averaging of neighbours ("mean of means") gives the
binomial weights wᵢ = C(n−1, i)/2^{n−1}:

    n = 2: (V₁ + V₂)/2                       (two-run spot; seed 002)
    n = 3: (V₁ + 2V₂ + V₃)/4                 (three-run spot; seed 002)
    n = 4: (V₁ + 3V₂ + 3V₃ + V₄)/8           (ITTC 7.5-04-01-01.1 (2017) / ISO 15016:2015 mean of means)

Derivation of what each cancels (this module's own; checked in tests/test_reduce_current.py):
Σ wᵢ sᵢ c(tᵢ) = Σ C(n−1,i)(−1)^i c(t₀ + iΔ)/2^{n−1} = (−1)^{n−1} Δ^{n−1}c(t₀)/2^{n−1}, the (n−1)-th forward
difference. It vanishes for every polynomial current of degree ≤ n − 2 and for c = k t^{n−1} equals
(−1)^{n−1}(n−1)! k Δ^{n−1}/2^{n−1}. Hence

    two-run average     exact for a constant current; linear current c = c₀ + k t gives an error
                        (c(t₁) − c(t₂))/2 = −kΔ/2 — half the change of the current between the two
                        runs' mid-times (sign: positive when the current along the first run's course
                        decreases);
    three-run MoM       exact for a linear current; quadratic c = k t² gives error +kΔ²/2 = c''Δ²/4;
    ITTC four-run MoM   exact up to a QUADRATIC current (not cubic); cubic c = k t³ gives −(3/4)kΔ³.

All of these need equal time spacing; :func:`polynomial_current_elimination` is the time-aware
generalisation (same cancellation order for any spacing).

Vector methods — runs on several headings at constant power (seed 000, Appendix A)
----------------------------------------------------------------------------------
Ground speed on heading φ with speed through water U and a current of speed C setting toward θ:

    V² = (U + C cos(φ − θ))² + C² sin²(φ − θ) = U² + C² + 2UC cos(φ − θ)          (A.1)

See :func:`four_leg_current`, :func:`least_squares_current`, :func:`reciprocal_pair_speed`.
Note that (A.1) is symmetric in U and C: the data cannot tell a ship at U in a current C from one at C in
a current U; every solver here takes the root with U ≥ C.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
from scipy import optimize, special

from vtrials.reduce.estimate import Estimate

TWO_PI = 2.0 * math.pi
TIDAL_PERIOD = 12.42 * 3600.0  # [s] principal lunar semidiurnal period (M2), as ITTC 7.5-04-01-01.1 uses


def _std_array(std, n):
    if std is None:
        return None
    s = np.broadcast_to(np.asarray(std, dtype=float), (n,)).copy()
    return s


def _wrap_pi(a):
    return math.pi - (math.pi - a) % TWO_PI


# ==================================================================================================
# mean of means
# ==================================================================================================
def mean_of_means_weights(n: int) -> np.ndarray:
    """Weights of the mean of means of n alternating runs: C(n−1, i)/2^{n−1} (repeated averaging)."""
    if n < 2:
        raise ValueError("mean of means needs at least 2 runs")
    i = np.arange(n)
    return special.comb(n - 1, i, exact=False) / 2.0 ** (n - 1)


def mean_of_means(vg, std=None) -> Estimate:
    """Mean of means of n runs on alternating reciprocal headings, equal settings, equal spacing.

    vg: speeds over ground [m/s] in run order. std: per-run standard uncertainty (scalar or array) of
    vg; propagated as σ² = Σ wᵢ² σᵢ² (runs independent). Without std the uncertainty is NaN: the
    method has no redundancy to estimate it. The truncation error of the current model is not
    included (see module docstring for its size).
    """
    vg = np.asarray(vg, dtype=float)
    w = mean_of_means_weights(vg.size)
    value = float(np.dot(w, vg))
    s = _std_array(std, vg.size)
    err = math.nan if s is None else float(np.sqrt(np.sum((w * s) ** 2)))
    return Estimate(value, err)


def two_run_average(vg, std=None) -> Estimate:
    """(V₁ + V₂)/2 of a two-run spot (seed 002; valid for a constant current along the course)."""
    vg = np.asarray(vg, dtype=float)
    if vg.size != 2:
        raise ValueError("two_run_average needs exactly 2 runs")
    return mean_of_means(vg, std)


def three_run_mean_of_means(vg, std=None) -> Estimate:
    """(V₁ + 2V₂ + V₃)/4 of a three-run spot (seed 002; cancels a current linear in time)."""
    vg = np.asarray(vg, dtype=float)
    if vg.size != 3:
        raise ValueError("three_run_mean_of_means needs exactly 3 runs")
    return mean_of_means(vg, std)


def ittc_mean_of_means(vg, std=None) -> Estimate:
    """(V₁ + 3V₂ + 3V₃ + V₄)/8 over two double runs (ITTC 7.5-04-01-01.1 (2017), ISO 15016:2015).

    Cancels a current up to quadratic in time for equally spaced runs (module docstring). Also used for
    the power of the four runs (same weights).
    """
    vg = np.asarray(vg, dtype=float)
    if vg.size != 4:
        raise ValueError("ittc_mean_of_means needs exactly 4 runs")
    return mean_of_means(vg, std)


# ==================================================================================================
# joint fit of a standardization day: one speed per spot, one current for the day
# ==================================================================================================
def ship_scatter(solve, chi2: float, dof: int, resid, std):
    """Run-to-run scatter τ of the ship's own speed (gusts, helm, a spot not quite settled) beyond the
    tracking's stated σ, for a fit of speeds over ground: the one variance τ² common to the runs for
    which χ² = dof when the runs are weighed by 1/(σᵢ² + τ²) (Paule & Mandel 1982, J. Res. NBS 87(5),
    the consensus-mean estimator, applied to a fit). ``solve(τ)`` refits with those weights and returns
    (w, weighted Jacobian, β, residuals, χ²); ``chi2`` is its χ² at τ = 0. Returns (τ, solve(τ))."""
    if not (dof > 0 and chi2 > dof):
        return 0.0, solve(0.0)
    hi = float(np.max(np.abs(resid))) + float(np.max(std))
    while solve(hi)[4] > dof:
        hi *= 2.0
    tau = optimize.brentq(lambda x: solve(x)[4] - dof, 0.0, hi, xtol=1e-9)
    return float(tau), solve(tau)


def scatter_budget(a, std, tau: float, ref, dof: int) -> tuple[float, float | None]:
    """Standard uncertainty and dof of an estimate Σ aᵢ V_i of speeds V_i = Vᵢ* + eᵢ + δᵢ (eᵢ the tracking
    error, σᵢ; δᵢ the ship's own scatter, τ) against the reference Σ w̃ᵢ Vᵢ* + δᵢ — the mean of the
    same runs' true speeds, which carries their scatter too: u² = Σ aᵢ² σᵢ² + τ² Σ (aᵢ − w̃ᵢ)²; where the
    fit weighs the runs as the reference does, the scatter cancels. Welch–Satterthwaite dof with the
    τ part on the fit's dof (None: normal)."""
    u_track = float(np.sum((np.asarray(a) * std) ** 2))
    u_ship = tau ** 2 * float(np.sum((np.asarray(a) - ref) ** 2))
    u2 = u_track + u_ship
    nu = u2 ** 2 / (u_ship ** 2 / dof) if u_ship > 0 else None
    return math.sqrt(u2), nu


@dataclasses.dataclass(frozen=True)
class SpotCurrentFit:
    """Result of :func:`joint_spot_current_fit`.

    groups: spot labels in order; vs: speed through water per spot (heading-balanced) [m/s], as
    Estimates whose std is the scatter-scaled one (``scale`` × the stated-σ one) on ``dof``;
    offset: per spot the half difference of the base- and reciprocal-course speeds over ground that the
    current's time variation does not explain (the constant current along the course plus the
    heading-dependent part of the ship's own speed, e.g. head and tail wind) [m/s]; model: current
    shape ("tidal", "linear", "none"); shape: its coefficients [m/s] of ``basis`` (τ/T_span,
    cos ωτ, sin ωτ); chi2 = Σ (r/σ)², dof = n − p; cov_stated: parameter covariance from the stated
    σ alone (absolute); scale = max(1, χ²/dof) (Birge ratio: the scatter where it exceeds what the
    stated σ allow)."""

    groups: tuple
    vs: tuple
    offset: tuple
    model: str
    shape: np.ndarray
    t_ref: float
    t_span: float
    period: float
    chi2: float
    dof: int
    scale: float
    residuals: np.ndarray
    cov_stated: np.ndarray
    ship_scatter: float = 0.0
    cov_shape: np.ndarray | None = None  # covariance of ``shape`` with the runs weighed by σᵢ² + τ²

    def current_change(self, t) -> np.ndarray:
        """The fitted time-varying part of the along-course current at times t [s] (m/s; its constant
        is in the spots' offsets)."""
        return _shape_basis(np.atleast_1d(np.asarray(t, float)), self.model, self.t_ref, self.t_span,
                            self.period) @ self.shape

    def current_rate(self, t) -> tuple[np.ndarray, np.ndarray]:
        """Rate of change of the fitted along-course current at times t [s] and its standard
        uncertainty (m/s², along the base course): dc/dt of the shape terms, 1/T_span for the
        linear term, ∓ω sin/cos ωτ for the tidal pair."""
        d = _shape_rate_basis(np.atleast_1d(np.asarray(t, float)), self.model, self.t_ref, self.t_span,
                              self.period)
        rate = d @ self.shape
        cov = self.cov_shape if self.cov_shape is not None else np.zeros((d.shape[1], d.shape[1]))
        return rate, np.sqrt(np.maximum(np.einsum("ij,jk,ik->i", d, cov, d), 0.0))


_SHAPES = {"tidal": 3, "linear": 1, "none": 0}


def _shape_basis(t, model, t_ref, t_span, period):
    tau = np.asarray(t, float) - t_ref
    cols = []
    if model in ("tidal", "linear"):
        cols.append(tau / t_span)
    if model == "tidal":
        cols += [np.cos(TWO_PI * tau / period), np.sin(TWO_PI * tau / period)]
    return np.column_stack(cols) if cols else np.zeros((tau.size, 0))


def _shape_rate_basis(t, model, t_ref, t_span, period):
    """Time derivatives of the :func:`_shape_basis` columns [1/s]."""
    tau = np.asarray(t, float) - t_ref
    w = TWO_PI / period
    cols = []
    if model in ("tidal", "linear"):
        cols.append(np.full(tau.size, 1.0 / t_span))
    if model == "tidal":
        cols += [-w * np.sin(w * tau), w * np.cos(w * tau)]
    return np.column_stack(cols) if cols else np.zeros((tau.size, 0))


def joint_spot_current_fit(t, vg, vg_std, heading, group, model=None, period=TIDAL_PERIOD,
                           min_dof: int = 2, offsets: str | None = None) -> SpotCurrentFit:
    """Speed through water of every spot of a standardization day from one weighted least-squares fit
    of all its runs: V_G,i = V_g + sᵢ (d_g + c(tᵢ)), sᵢ = cos(φᵢ − φ₀) (±1 on the base course and its
    reciprocal), one speed V_g and one offset d_g per spot, and the time variation c(t) of the current
    along the course common to the day.

    The current model is that of the ITTC iterative method (ITTC 7.5-04-01-01.1 (2017, rev. 2021):
    V_C(t) = V_C,C cos ωτ + V_C,S sin ωτ + V_C,T τ + V_C,0, ω = 2π/12.42 h) without its constant: the
    constant along-course current cannot be told from a spot's heading-dependent speed (the ship is
    slower into the wind than with it: ~0.1 m/s for this 51-m ship in 20 kn), so each spot keeps its
    own offset d_g and V_g is the heading-balanced mean — ½(mean over base-course runs + mean over
    reciprocal runs) of the speed through water, the quantity a mean of means estimates. The common
    part is the current's change with time, resolved from the spots' repeated courses (a three-run spot
    B–R–B: V_G,1 − V_G,3 = c(t₁) − c(t₃)) across the whole day; with model "none" a three-run spot's V_g
    is exactly the mean of means (V₁ + 2V₂ + V₃)/4 for equal σ. ``model`` None: the richest of "tidal"
    (3 shape terms), "linear" (1), "none" with at least ``min_dof`` residual degrees of freedom (the
    richest the runs determine at all when none has that many).
    A two-run spot (one run each way) holds no contrast of its own; on a day of such spots the current's
    change is only seen across spots, so ``offsets`` "common" (one offset for the day: the constant
    current, with the heading-dependent speed taken equal at every spot) is tried after the per-spot
    ("spot") forms; None: that order.

    Unlike the ITTC iterative method there is no speed–power law in the fit: a power law across a CP
    ship's combinator line cannot fit the spots, and its misfit is not measurement scatter.

    Inputs: t [s] run mid-times, vg [m/s] speeds over ground, vg_std [m/s] their stated standard
    uncertainty (tracking), heading [rad] (base course or its reciprocal), group the spot of each run.
    Uncertainty (GUM, JCGM 100:2008; ITTC 7.5-02-01-01 for a least-squares fit): when the runs
    scatter more than the stated σ allow, the excess is taken as run-to-run scatter τ of the ship's own
    speed (gusts, helm, a big ship not quite settled; Paule–Mandel: χ² = dof) and the runs are weighed
    by σᵢ² + τ². With V̂_g = Σ aᵢ V_G,i, the error against the spot's heading-balanced mean of its runs'
    speeds (w̃) is Σ aᵢ eᵢ + Σ (aᵢ − w̃ᵢ) δᵢ: the tracking σ propagated, plus τ² Σ (aᵢ − w̃ᵢ)² — where
    the fit weighs a spot's runs as that mean does, the ship's scatter is the reference's too and does
    not count. Student t on the Welch–Satterthwaite dof (the τ part on the fit's dof); normal when the
    runs scatter no more than stated. The stated σ must then be honest: the tracking fix statistics
    with the data sheet's time-correlated error (:func:`vtrials.reduce.runstats.sog_from_track`).
    """
    t, vg, vg_std, heading = (np.asarray(a, dtype=float) for a in (t, vg, vg_std, heading))
    n = vg.size
    groups = tuple(sorted(set(group)))
    G = len(groups)
    gi = np.array([groups.index(g) for g in group])
    s = np.cos(heading - heading[0])
    if np.any(np.abs(s) < 0.5):
        raise ValueError("runs must be on the base course or its reciprocal")
    s = np.sign(s)
    if np.any(~np.isfinite(vg_std)) or np.any(vg_std <= 0):
        raise ValueError("every run needs a positive finite speed uncertainty")
    t_ref = float(np.mean(t))
    t_span = max(float(np.ptp(t)), 1.0)
    V = np.column_stack([(gi == k).astype(float) for k in range(G)])
    # a spot's offset only where it has runs on both courses (else it is its speed's twin)
    both = [k for k in range(G) if len({float(x) for x in s[gi == k]}) == 2]
    w = 1.0 / vg_std

    def design(m, off):
        if off == "spot":
            D = np.column_stack([(gi == k) * s for k in both]) if both else np.zeros((n, 0))
        else:
            D = s[:, None]
        return np.column_stack([V, D, s[:, None] * _shape_basis(t, m, t_ref, t_span, period)])

    for m in ([] if model is None else [model]):
        if m not in _SHAPES:
            raise ValueError(f"model must be one of {tuple(_SHAPES)}")
    if offsets not in (None, "spot", "common"):
        raise ValueError("offsets must be 'spot' or 'common'")
    shapes = [model] if model is not None else ["tidal", "linear"]
    offs = [offsets] if offsets is not None else ["spot", "common"]
    if offsets is None and all(np.count_nonzero(gi == k) >= 3 for k in range(G)):
        offs = ["spot"]  # every spot has its own contrast: its own offset
    order = [(m, o) for o in offs for m in shapes]
    if model is None:
        order.append(("none", offs[0]))
    chosen = first = None
    for m, o in order:
        X = design(m, o)
        p = X.shape[1]
        if p > n or np.linalg.matrix_rank(X * w[:, None]) < p:
            continue
        first = first or (m, o)
        if n - p >= min_dof:
            chosen = (m, o)
            break
    chosen = chosen or first  # too few runs for min_dof: the richest form the runs determine
    if chosen is None:
        raise ValueError("the runs cannot determine a speed per spot")
    X = design(*chosen)
    if chosen[1] == "common":
        both = [None]
    chosen = chosen[0]
    p = X.shape[1]
    dof = n - p

    def solve(tau):
        wt = 1.0 / np.sqrt(vg_std ** 2 + tau ** 2)
        Xw = X * wt[:, None]
        beta, *_ = np.linalg.lstsq(Xw, vg * wt, rcond=None)
        r = vg - X @ beta
        return wt, Xw, beta, r, float(np.sum((r * wt) ** 2))

    w, Xw, beta, r, chi2 = solve(0.0)
    cov = np.linalg.pinv(Xw.T @ Xw)
    scale = max(1.0, chi2 / dof) if dof > 0 else 1.0
    tau, (w, Xw, beta, r, _) = ship_scatter(solve, chi2, dof, r, vg_std)
    A = np.linalg.pinv(Xw) * w[None, :]  # β̂ = A v_G
    vs = []
    for k in range(G):
        # the spot's reference is its heading-balanced mean of the runs' own speeds (what the fit's V_g
        # means: vtrials.score.trials.spot_stw_truth)
        m = gi == k
        wt_ref = np.zeros(n)
        for c in (-1.0, 1.0):
            mc = m & (s == c)
            if mc.any():
                wt_ref[mc] = 1.0 / mc.sum()
        vs.append(Estimate(float(beta[k]), *scatter_budget(A[k], vg_std, tau, wt_ref / wt_ref.sum(), dof)))
    vs = tuple(vs)
    off = [math.nan] * G
    for j, k in enumerate(both):
        if k is None:  # one offset for the day
            off = [float(beta[G])] * G
        else:
            off[k] = float(beta[G + j])
    ks = slice(G + len(both), p)
    cov_shape = (A[ks] * (vg_std ** 2 + tau ** 2)[None, :]) @ A[ks].T
    return SpotCurrentFit(groups=groups, vs=vs, offset=tuple(off), model=chosen, shape=beta[G + len(both):],
                          t_ref=t_ref, t_span=t_span, period=float(period), chi2=chi2, dof=dof, scale=scale,
                          residuals=r, cov_stated=cov, ship_scatter=float(tau), cov_shape=cov_shape)


@dataclasses.dataclass(frozen=True)
class PolyCurrentResult:
    vs: Estimate  # speed through water [m/s]
    coeffs: np.ndarray  # current polynomial coefficients c_k of ((t − t_ref)/t_scale)^k [m/s]
    t_ref: float
    t_scale: float
    dof: int


def polynomial_current_elimination(t, vg, heading=None, degree=None, std=None) -> PolyCurrentResult:
    """Time-aware mean of means: V_G,i = V_S + sᵢ Σ_k c_k τᵢ^k solved by least squares.

    t [s] run mid-times; vg [m/s]; heading [rad] per run (sᵢ = cos(φᵢ − φ₀), ±1 for reciprocal runs;
    default alternating signs); degree of the current polynomial (default n − 2, the exact
    generalisation of the binomial mean of means to unequal spacing). With dof = n − degree − 2 > 0 the
    residual scatter gives the uncertainty, otherwise ``std`` (per-run vg uncertainty) is propagated,
    otherwise NaN. Reference: the polynomial-current idea behind the mean of means (ITTC
    7.5-04-01-01.1 (2017) §"mean of means"); the least-squares form is this module's.
    """
    t = np.asarray(t, dtype=float)
    vg = np.asarray(vg, dtype=float)
    n = vg.size
    if heading is None:
        s = (-1.0) ** np.arange(n)
    else:
        h = np.asarray(heading, dtype=float)
        s = np.cos(h - h[0])
    deg = n - 2 if degree is None else int(degree)
    if deg < 0 or deg + 2 > n:
        raise ValueError("need n ≥ degree + 2 runs")
    t_ref = float(t.mean())
    t_scale = float(max(np.ptp(t) / 2.0, 1.0))
    tau = (t - t_ref) / t_scale
    X = np.column_stack([np.ones(n)] + [s * tau ** k for k in range(deg + 1)])
    sv = _std_array(std, n)
    W = np.ones(n) if sv is None else 1.0 / sv
    beta, *_ = np.linalg.lstsq(X * W[:, None], vg * W, rcond=None)
    dof = n - X.shape[1]
    XtWX_inv = np.linalg.pinv((X * W[:, None]).T @ (X * W[:, None]))
    if sv is not None:
        cov = XtWX_inv
    elif dof > 0:
        r = vg - X @ beta
        cov = XtWX_inv * float(r @ r) / dof
    else:
        cov = np.full_like(XtWX_inv, np.nan)
    return PolyCurrentResult(
        vs=Estimate(float(beta[0]), float(math.sqrt(cov[0, 0])) if np.isfinite(cov[0, 0]) else math.nan,
                    dof if (sv is None and dof > 0) else None),
        coeffs=beta[1:], t_ref=t_ref, t_scale=t_scale, dof=dof)


# ==================================================================================================
# ITTC iterative method
# ==================================================================================================
_MODELS = {
    "tidal": ("V_CC", "V_CS", "V_CT", "V_C0"),
    "linear": ("V_CT", "V_C0"),
    "constant": ("V_C0",),
}


def _current_basis(tau, model, period):
    cols = []
    if model == "tidal":
        cols += [np.cos(TWO_PI * tau / period), np.sin(TWO_PI * tau / period)]
    if model in ("tidal", "linear"):
        cols.append(tau)
    cols.append(np.ones_like(tau))
    return np.column_stack(cols)


def _fit_offset_power(v, p, q=None, w=None, q_bounds=(0.5, 10.0)):
    """Least squares P = a + b v^q (q fixed or by variable projection). Returns a, b, q, rss."""
    v = np.maximum(np.asarray(v, dtype=float), 1e-12)
    p = np.asarray(p, dtype=float)
    w = np.ones_like(p) if w is None else np.asarray(w, dtype=float)

    def solve(qq):
        X = np.column_stack([np.ones_like(v), v ** qq]) * w[:, None]
        beta, *_ = np.linalg.lstsq(X, p * w, rcond=None)
        r = p * w - X @ beta
        return beta, float(r @ r)

    if q is None:
        grid = np.linspace(q_bounds[0], q_bounds[1], 96)
        rss = [solve(g)[1] for g in grid]
        k = int(np.argmin(rss))
        lo, hi = grid[max(k - 1, 0)], grid[min(k + 1, grid.size - 1)]
        res = optimize.minimize_scalar(lambda g: solve(g)[1], bounds=(lo, hi), method="bounded",
                                       options={"xatol": 1e-10})
        q = float(res.x)
    beta, rss = solve(q)
    return float(beta[0]), float(beta[1]), float(q), rss


@dataclasses.dataclass(frozen=True)
class IterativeResult:
    """Result of :func:`ittc_iterative`.

    vs, vs_std: per-run speed through water [m/s] and its std (from the fitted current's covariance,
    plus vg_std if given). current, current_std: fitted current along the reference (first run's)
    heading at each run [m/s]. a [W], b [W/(m/s)^q], q: fitted P = a + b V_S^q. current_params:
    V_CC, V_CS [m/s], V_CT [m/s²], V_C0 [m/s] (those of the chosen model), time origin t_ref [s].
    """

    vs: np.ndarray
    vs_std: np.ndarray
    current: np.ndarray
    current_std: np.ndarray
    a: Estimate
    b: Estimate
    q: Estimate
    current_params: dict
    names: tuple
    cov: np.ndarray
    t_ref: float
    period: float
    model: str
    iterations: int
    rss_history: tuple
    dof: int

    def current_at(self, t):
        """Current along the reference heading at times t [s]: (value, std) arrays [m/s]."""
        tau = np.atleast_1d(np.asarray(t, dtype=float)) - self.t_ref
        B = _current_basis(tau, self.model, self.period)
        k = len(_MODELS[self.model])
        c = np.array([self.current_params[nm].value for nm in _MODELS[self.model]])
        cc = self.cov[-k:, -k:]
        return B @ c, np.sqrt(np.einsum("ij,jk,ik->i", B, cc, B))

    def power(self, v):
        """Fitted P(V_S) = a + b V^q [W]."""
        return self.a.value + self.b.value * np.asarray(v, dtype=float) ** self.q.value


def ittc_iterative(t, vg, heading, power, q=None, model="tidal", period=TIDAL_PERIOD,
                   t_ref=None, vg_std=None, power_std=None, max_iter=500, tol=1e-12,
                   polish=True) -> IterativeResult:
    """ITTC iterative current correction (ITTC 7.5-04-01-01.1 (2017, rev. 2021; the analysis part was
    7.5-04-01-01.2 (2014) before the merge) / ISO 15016:2015;
    verified against simulated truth by Strasser et al. 2015, "A verification of the ITTC/ISO
    speed/power trials analysis", J. Mar. Sci. Technol. 20, 2–13).

    Model: P = a + b V_S^q over all runs together, V_S,i = V_G,i − sᵢ V_C(tᵢ) with sᵢ = cos(φᵢ − φ₀)
    (the current component along the reference course; ±1 for reciprocal runs) and

        V_C(t) = V_C,C cos(2πτ/T_C) + V_C,S sin(2πτ/T_C) + V_C,T τ + V_C,0,   τ = t − t_ref,

    T_C = 12.42 h ("tidal"); model="linear" keeps V_C,T τ + V_C,0, "constant" only V_C,0.

    Inputs: t [s] run mid-times, vg [m/s], heading [rad], power [W] (per run, e.g. P_D after the
    resistance corrections), q fixed or None (fitted), t_ref default min(t).

    Iteration (the fixed point the standard describes): start with V_C = 0; fit (a, b, q) to
    (V_S, P); from the curve, each run's speed V_S* = ((P − a)/b)^{1/q}; current samples
    sᵢ(V_G,i − V_S,i*) → least-squares fit of the current model → new V_S; repeat until the power-fit
    residual sum of squares stops decreasing (relative change < tol). ``polish`` then minimises the
    same power residuals jointly over all parameters (Levenberg–Marquardt), which is the converged
    solution of the standard's least-squares problem and gives the parameter covariance
    cov = s²(JᵀJ)⁻¹, s² = RSS/(n − p) (or absolute with power_std). Needs n > number of parameters
    (7 for tidal with q fitted) for a std; with n = p the stds are NaN.
    """
    t = np.asarray(t, dtype=float)
    vg = np.asarray(vg, dtype=float)
    ph = np.asarray(heading, dtype=float)
    P = np.asarray(power, dtype=float)
    n = vg.size
    if not (t.size == ph.size == P.size == n):
        raise ValueError("t, vg, heading, power must have equal length")
    if model not in _MODELS:
        raise ValueError(f"model must be one of {tuple(_MODELS)}")
    s = np.cos(ph - ph[0])
    if np.any(np.abs(s) < 0.5):
        raise ValueError("runs must be (near-)reciprocal to the first run's heading")
    t_ref = float(t.min()) if t_ref is None else float(t_ref)
    tau = t - t_ref
    B = _current_basis(tau, model, period)
    colscale = np.maximum(np.max(np.abs(B), axis=0), 1e-300)
    Bn = B / colscale
    k = B.shape[1]
    n_par = k + (2 if q is not None else 3)
    if n < n_par:
        raise ValueError(f"{n} runs cannot determine {n_par} parameters")
    pw = None if power_std is None else 1.0 / _std_array(power_std, n)

    cpar = np.zeros(k)  # normalised current coefficients
    rss_hist = []
    a = b = qq = None
    it = 0
    for it in range(1, max_iter + 1):
        vs = vg - s * (Bn @ cpar)
        a, b, qq, rss = _fit_offset_power(vs, P, q, pw)
        rss_hist.append(rss)
        if len(rss_hist) > 1 and rss_hist[-2] - rss <= tol * max(rss_hist[-2], 1e-300):
            break
        ratio = np.clip((P - a) / b, 1e-12, None)
        vs_star = ratio ** (1.0 / qq)
        c_obs = (vg - vs_star) * s / (s * s)
        cpar, *_ = np.linalg.lstsq(Bn, c_obs, rcond=None)

    # joint least squares (polish) and covariance
    def unpack(x):
        if q is None:
            return x[0], x[1], x[2], x[3:]
        return x[0], x[1], q, x[2:]

    p_scale = max(float(np.max(np.abs(P))), 1.0)

    def resid(x):
        aa, bb, qv, cp = unpack(x)
        v = np.maximum(vg - s * (Bn @ cp), 1e-12)
        r = (P - aa - bb * v ** qv) / p_scale
        return r if pw is None else r * pw * p_scale

    x0 = np.r_[a, b, qq, cpar] if q is None else np.r_[a, b, cpar]
    if polish:
        sol = optimize.least_squares(resid, x0, method="lm", x_scale="jac", xtol=1e-15, ftol=1e-15,
                                     gtol=1e-15, max_nfev=20000)
        x = sol.x
    else:
        x = x0
    aa, bb, qv, cp = unpack(x)
    # analytic Jacobian of the (unscaled) power model wrt the parameters
    v = np.maximum(vg - s * (Bn @ cp), 1e-12)
    cols = [np.ones(n), v ** qv]
    if q is None:
        cols.append(bb * v ** qv * np.log(v))
    dPdv = bb * qv * v ** (qv - 1.0)
    J = np.column_stack(cols + [-(dPdv * s)[:, None] * Bn])
    r = P - aa - bb * v ** qv
    dof = n - J.shape[1]
    if pw is not None:
        Jw = J * pw[:, None]
        cov = np.linalg.pinv(Jw.T @ Jw)
    elif dof > 0:
        cov = np.linalg.pinv(J.T @ J) * float(r @ r) / dof
    else:
        cov = np.full((J.shape[1], J.shape[1]), np.nan)
    # back to physical current parameters
    S = np.diag(np.r_[np.ones(J.shape[1] - k), 1.0 / colscale])
    cov = S @ cov @ S
    cphys = cp / colscale
    est_dof = dof if (pw is None and dof > 0) else None

    def est(i, val):
        sd = math.sqrt(cov[i, i]) if np.isfinite(cov[i, i]) and cov[i, i] >= 0 else math.nan
        return Estimate(float(val), sd, est_dof)

    names = ("a", "b") + (("q",) if q is None else ()) + _MODELS[model]
    off = J.shape[1] - k
    cur_params = {nm: est(off + j, cphys[j]) for j, nm in enumerate(_MODELS[model])}
    current = B @ cphys
    ccov = cov[off:, off:]
    current_std = np.sqrt(np.maximum(np.einsum("ij,jk,ik->i", B, ccov, B), 0.0))
    vs = vg - s * current
    vs_var = (s * current_std) ** 2
    if vg_std is not None:
        vs_var = vs_var + _std_array(vg_std, n) ** 2
    q_est = est(2, qv) if q is None else Estimate(float(q), 0.0)
    return IterativeResult(
        vs=vs, vs_std=np.sqrt(vs_var), current=current, current_std=current_std,
        a=est(0, aa), b=est(1, bb), q=q_est, current_params=cur_params, names=names, cov=cov,
        t_ref=t_ref, period=float(period), model=model, iterations=it,
        rss_history=tuple(rss_hist), dof=dof)


def iterative_spot_speed(res: IterativeResult, t, heading, idx, vg_std=None) -> Estimate:
    """Speed through water of one spot from an all-runs ITTC iterative analysis (:func:`ittc_iterative`).

    t, heading: the mid-times [s] and headings [rad] of ALL the runs given to the analysis (in its
    order); idx: indices of the spot's runs among them. Value: the heading-balanced mean
    ½(mean V_S over the spot's runs on its first run's course + mean over the reciprocal runs), the
    quantity a mean of means estimates, so the two methods are compared on one definition.

    Std: the spot's runs share the fitted current, so their V_S errors are correlated; with weights wᵢ
    and sᵢ = cos(φᵢ − φ₀) (φ₀ the analysis' reference course) the current part is
    σ² = (w s)ᵀ B Σ_c B ᵀ(w s) (B the current model's basis at the runs, Σ_c its parameter covariance),
    plus Σ wᵢ² vg_stdᵢ² when vg_std is given. Which current model was fitted (and whether it is right)
    is the caller's question: a current that departs from the model's shape leaves an error this std
    does not contain.
    """
    t = np.asarray(t, dtype=float)
    ph = np.asarray(heading, dtype=float)
    idx = np.asarray(idx, dtype=int)
    if idx.size < 2:
        raise ValueError("a spot needs at least two runs (a double run)")
    s_spot = np.cos(ph[idx] - ph[idx[0]])
    base, recip = s_spot > 0, s_spot <= 0
    if not base.any() or not recip.any():
        raise ValueError("a spot needs runs on both its course and the reciprocal")
    w = np.where(base, 0.5 / base.sum(), 0.5 / recip.sum())
    value = float(np.dot(w, np.asarray(res.vs)[idx]))
    B = _current_basis(t[idx] - res.t_ref, res.model, res.period)
    k = len(_MODELS[res.model])
    cc = res.cov[-k:, -k:]
    g = (w * np.cos(ph[idx] - ph[0])) @ B
    var = float(g @ cc @ g)
    if vg_std is not None:
        var += float(np.sum((w * _std_array(vg_std, t.size)[idx]) ** 2))
    std = math.sqrt(var) if np.isfinite(var) and var >= 0 else math.nan
    return Estimate(value, std, res.a.dof)


# ==================================================================================================
# four-leg resolution (seed 000, Appendix A) and its generalisations
# ==================================================================================================
RATIO_EPS = 1e-8  # |R − 1| below this: the ratio formula is 0/0 to rounding and is not used
RATIO_NAMES = ("A=VN²/VS²", "B=VN²/VE²", "D=VN²/VW²", "E=VS²/VE²", "F=VS²/VW²", "G=VE²/VW²")


def four_leg_b(vn2, ve2, vs2, vw2, alpha):
    """The six ratio solutions b_i = (1 + C′²)/(2C′) of seed 000 App. A, DERIVED here (the seed copy's
    printed b₂, b₄, b₅ are wrong; see below). Returns (ratios, b) arrays of length 6.

    With c = cos α, s = sin α and b = (1 + C′²)/(2C′), dividing (A.2)–(A.5) by 2C′ gives
    V_N'² ∝ b + c, V_S'² ∝ b − c, V_E'² ∝ b + s, V_W'² ∝ b − s (same factor 2C′), so each ratio R = (b + x)/(b + y)
    is linear in b: b = (x − R y)/(R − 1):

        A = V_N²/V_S² = (b + c)/(b − c)  →  b₁ = (A + 1) c/(A − 1)          (seed: same)
        B = V_N²/V_E² = (b + c)/(b + s)  →  b₂ = (c − B s)/(B − 1)          (seed: (B s − c)/(B − 1), sign)
        D = V_N²/V_W² = (b + c)/(b − s)  →  b₃ = (c + D s)/(D − 1)          (seed: same)
        E = V_S²/V_E² = (b − c)/(b + s)  →  b₄ = (c + E s)/(1 − E)          (seed: (E s + c)/(E − 1), sign)
        F = V_S²/V_W² = (b − c)/(b − s)  →  b₅ = (F s − c)/(F − 1)          (seed: (F s + c)/(F − 1), wrong)
        G = V_E²/V_W² = (b + s)/(b − s)  →  b₆ = (G + 1) s/(G − 1)          (seed: same)

    These hold for α in every quadrant (no 0–90° restriction, no relabelling of legs) and give b ≥ 1
    directly; the seed's instruction to take |b_i| repairs its b₂ and b₄ but not b₅. A ratio equal to
    1 (0/0, |R − 1| ≤ RATIO_EPS) gives NaN — e.g. b₆ when the current is along the N–S line.
    """
    c, s = math.cos(alpha), math.sin(alpha)
    R = np.array([vn2 / vs2, vn2 / ve2, vn2 / vw2, vs2 / ve2, vs2 / vw2, ve2 / vw2])
    with np.errstate(divide="ignore", invalid="ignore"):
        b = np.array([
            (R[0] + 1.0) * c / (R[0] - 1.0),
            (c - R[1] * s) / (R[1] - 1.0),
            (c + R[2] * s) / (R[2] - 1.0),
            (c + R[3] * s) / (1.0 - R[3]),
            (R[4] * s - c) / (R[4] - 1.0),
            (R[5] + 1.0) * s / (R[5] - 1.0),
        ])
    b[np.abs(R - 1.0) <= RATIO_EPS] = np.nan  # 0/0: this ratio carries no information on C′
    return R, b


def c_prime_from_b(b):
    """C′ = b − √(b² − 1) (the root < 1 of C′² − 2bC′ + 1 = 0; seed 000 eq. A.8). b < 1 (noise) → 1."""
    b = np.abs(np.asarray(b, dtype=float))
    bb = np.maximum(b, 1.0)
    with np.errstate(invalid="ignore"):
        return np.where(np.isfinite(bb), bb - np.sqrt(bb * bb - 1.0), np.nan)


def _four_leg_core(vn, ve, vs, vw):
    vn2, ve2, vs2, vw2 = vn * vn, ve * ve, vs * vs, vw * vw
    d_ns = vn2 - vs2
    d_ew = ve2 - vw2
    if d_ns == 0.0 and d_ew == 0.0:
        alpha = 0.0
        R = np.ones(6)
        b = np.full(6, np.nan)
        cpi = np.full(6, np.nan)
        cp = 0.0
    else:
        alpha = math.atan2(d_ew, d_ns)  # full-quadrant form of (A.7)
        R, b = four_leg_b(vn2, ve2, vs2, vw2, alpha)
        cpi = c_prime_from_b(b)
        wts = (R - 1.0) ** 2
        ok = np.isfinite(cpi) & (wts > 0)
        cp = float(np.sum(wts[ok] * cpi[ok]) / np.sum(wts[ok])) if np.any(ok) else 0.0
    one = 1.0 + cp * cp
    u_ns = math.sqrt((vn2 + vs2) / (2.0 * one))  # (A.6a)
    u_ew = math.sqrt((ve2 + vw2) / (2.0 * one))  # (A.6b)
    u = math.sqrt((vn2 + vs2 + ve2 + vw2) / (4.0 * one))
    return u, cp, alpha, R, b, cpi, u_ns, u_ew


@dataclasses.dataclass(frozen=True)
class FourLegResult:
    """Four-leg resolution. u [m/s] speed through water, c [m/s] current speed, c_prime = C/U,
    alpha [rad] current set relative to the first leg's heading (clockwise, (−π, π]; negative = to
    port of φ₁), theta [rad] current set from true north [0, 2π). ratios, b, c_prime_i: the six ratio
    solutions; u_ns, u_ew: U from (A.6a) and (A.6b)."""

    u: Estimate
    c: Estimate
    c_prime: Estimate
    alpha: Estimate
    theta: Estimate
    ratios: np.ndarray
    b: np.ndarray
    c_prime_i: np.ndarray
    u_ns: float
    u_ew: float


def four_leg_current(v_n, v_e, v_s, v_w, heading0=0.0, std=None) -> FourLegResult:
    """Current and speed through water from ground speeds on four legs 90° apart (seed 000 App. A).

    v_n, v_e, v_s, v_w: mean ground speeds [m/s] on headings φ₁ = heading0, φ₁ + 90°, φ₁ + 180°,
    φ₁ + 270° (clockwise; the seed's N, E, S, W for 010°, 100°, 190°, 280°). Equations, with the
    current setting toward θ and α = θ − φ₁ (this is the sign for which the seed's (A.2)–(A.5) follow
    from (A.1) with clockwise headings; the seed's text "α = φ₁ − θ" contradicts its own equations,
    while its remark "negative α: current to the left of φ₁" agrees with α = θ − φ₁):

        V_N² = U²(1 + 2C′cos α + C′²),  V_S² = U²(1 − 2C′cos α + C′²),
        V_E² = U²(1 + 2C′sin α + C′²),  V_W² = U²(1 − 2C′sin α + C′²).

    α = atan2(V_E² − V_W², V_N² − V_S²) — eq. (A.7) with the quadrant taken from the signs of both
    differences (both are 4UC × cos/sin α with UC > 0), so currents from every direction are handled
    without relabelling legs. C′ from the six ratio formulas of :func:`four_leg_b` (A.8), combined
    with weights (Rᵢ − 1)² (each formula's conditioning degrades as its ratio → 1; a heuristic — all
    six coincide for exact data). U = √((V_N² + V_S² + V_E² + V_W²)/(4(1 + C′²))), the mean of (A.6a)
    and (A.6b) in squares. C = C′U. Assumes C < U.

    std: standard uncertainty of each leg's mean ground speed (scalar or 4 values), propagated to
    every output by a numerical Jacobian (legs independent); NaN stds without it.
    """
    v = np.array([v_n, v_e, v_s, v_w], dtype=float)
    if np.any(v <= 0):
        raise ValueError("ground speeds must be positive")
    u, cp, alpha, R, b, cpi, u_ns, u_ew = _four_leg_core(*v)
    vals = np.array([u, cp * u, cp, alpha])
    sv = _std_array(std, 4)
    if sv is None:
        sd = np.full(4, np.nan)
    else:
        J = np.zeros((4, 4))
        for j in range(4):
            h = 1e-6 * max(v[j], 1e-3)
            vp, vm = v.copy(), v.copy()
            vp[j] += h
            vm[j] -= h
            fp = _four_leg_core(*vp)
            fm = _four_leg_core(*vm)
            gp = np.array([fp[0], fp[1] * fp[0], fp[1], fp[2]])
            gm = np.array([fm[0], fm[1] * fm[0], fm[1], fm[2]])
            d = gp - gm
            d[3] = _wrap_pi(d[3])
            J[:, j] = d / (2.0 * h)
        sd = np.sqrt(np.einsum("ij,j,ij->i", J, sv * sv, J))
    alpha_w = _wrap_pi(alpha)
    return FourLegResult(
        u=Estimate(vals[0], float(sd[0])), c=Estimate(vals[1], float(sd[1])),
        c_prime=Estimate(vals[2], float(sd[2])), alpha=Estimate(alpha_w, float(sd[3])),
        theta=Estimate((heading0 + alpha) % TWO_PI, float(sd[3])),
        ratios=R, b=b, c_prime_i=cpi, u_ns=u_ns, u_ew=u_ew)


def three_leg_alpha(v_n, v_e, v_s):
    """tan α = 1 − 2(V_N² − V_E²)/(V_N² − V_S²) (seed 000 eq. A.10; verified here:
    = (2V_E² − V_N² − V_S²)/(V_N² − V_S²) = 4UC sin α / 4UC cos α). Returned with atan2's quadrant [rad]."""
    vn2, ve2, vs2 = v_n * v_n, v_e * v_e, v_s * v_s
    return math.atan2(2.0 * ve2 - vn2 - vs2, vn2 - vs2)


@dataclasses.dataclass(frozen=True)
class LSQCurrentResult:
    """Least-squares (U, current) fit. u [m/s]; c [m/s] current speed; theta [rad] current set from
    north; current_north/east [m/s]; cov: 3×3 covariance of (U, c_N, c_E); residuals [m/s];
    s: residual std [m/s] (NaN when dof = 0); dof = n − 3."""

    u: Estimate
    c: Estimate
    theta: Estimate
    current_north: Estimate
    current_east: Estimate
    cov: np.ndarray
    residuals: np.ndarray
    s: float
    dof: int
    iterations: int

    def ground_speed(self, heading):
        """Predicted ground speed [m/s] on heading(s) [rad]."""
        h = np.asarray(heading, dtype=float)
        return np.hypot(self.u.value * np.cos(h) + self.current_north.value,
                        self.u.value * np.sin(h) + self.current_east.value)


def least_squares_current(headings, vg, std=None, absolute_sigma=None, max_iter=100,
                          tol=1e-14) -> LSQCurrentResult:
    """Fit (U, C, θ) to ground speeds on any set of ≥ 3 headings (seed 000 (A.1), vector addition).

    Model: V_G,i = |U hᵢ + c|, hᵢ = (cos φᵢ, sin φᵢ) (north, east), c = (c_N, c_E) = C(cos θ, sin θ);
    parameterised by (U, c_N, c_E), which stays well conditioned as C → 0 (θ is then undefined).

    Start: V² = U² + C² + 2UC cos(φ − θ) = P + a cos φ + b sin φ is LINEAR in (P, a, b) = (U² + C²,
    2UC cos θ, 2UC sin θ); its least-squares solution is exact for three distinct headings (the
    three-leg case of seed 000, ratios A and B "solved together") and, for four legs 90° apart, it is
    the closed form P = ΣV²/4, a = (V_N² − V_S²)/2, b = (V_E² − V_W²)/2. Then U², C² are the roots of
    z² − Pz + (UC)² = 0 with U ≥ C. Gauss–Newton on the speed residuals (weighted by 1/std²) refines it.

    Covariance: (JᵀWJ)⁻¹ if std is given (absolute_sigma default True), else s²(JᵀJ)⁻¹ with
    s² = RSS/(n − 3); NaN with three legs and no std. C and θ by the delta method.
    """
    ph = np.asarray(headings, dtype=float)
    v = np.asarray(vg, dtype=float)
    n = v.size
    if ph.size != n or n < 3:
        raise ValueError("need ≥ 3 (heading, speed) pairs")
    sv = _std_array(std, n)
    w = np.ones(n) if sv is None else 1.0 / sv ** 2
    if absolute_sigma is None:
        absolute_sigma = sv is not None
    X = np.column_stack([np.ones(n), np.cos(ph), np.sin(ph)])
    if np.linalg.matrix_rank(X, tol=1e-9) < 3:
        raise ValueError("headings must span at least three distinct, non-reciprocal directions "
                         "(e.g. a reciprocal pair plus one crossing leg)")
    sw = np.sqrt(w)
    lin, *_ = np.linalg.lstsq(X * sw[:, None], v * v * sw, rcond=None)
    P, a, b = lin
    uc = 0.5 * math.hypot(a, b)
    disc = math.sqrt(max(P * P - 4.0 * uc * uc, 0.0))
    u0 = math.sqrt(max(0.5 * (P + disc), 1e-12))
    c0 = math.sqrt(max(0.5 * (P - disc), 0.0))
    th0 = math.atan2(b, a)
    x = np.array([u0, c0 * math.cos(th0), c0 * math.sin(th0)])
    hc, hs = np.cos(ph), np.sin(ph)

    def model(x):
        gn = x[0] * hc + x[1]
        ge = x[0] * hs + x[2]
        vv = np.hypot(gn, ge)
        return vv, gn, ge

    it = 0
    for it in range(1, max_iter + 1):
        vv, gn, ge = model(x)
        vv_safe = np.maximum(vv, 1e-12)
        J = np.column_stack([(gn * hc + ge * hs) / vv_safe, gn / vv_safe, ge / vv_safe])
        r = v - vv
        dx, *_ = np.linalg.lstsq(J * sw[:, None], r * sw, rcond=None)
        x = x + dx
        if np.linalg.norm(dx) <= tol * max(np.linalg.norm(x), 1.0):
            break
    vv, gn, ge = model(x)
    vv_safe = np.maximum(vv, 1e-12)
    J = np.column_stack([(gn * hc + ge * hs) / vv_safe, gn / vv_safe, ge / vv_safe])
    r = v - vv
    dof = n - 3
    JtWJ_inv = np.linalg.pinv((J * w[:, None]).T @ J)
    rss_w = float(np.sum(w * r * r))
    s = math.sqrt(rss_w / dof) if dof > 0 else math.nan
    if absolute_sigma:
        cov = JtWJ_inv
    elif dof > 0:
        cov = JtWJ_inv * rss_w / dof
    else:
        cov = np.full((3, 3), np.nan)
    u, cn, ce = (float(z) for z in x)
    if u < math.hypot(cn, ce):
        raise ValueError("fit converged to a current faster than the ship (U < C): ambiguous data")
    C = math.hypot(cn, ce)
    theta = math.atan2(ce, cn) % TWO_PI
    est_dof = None if absolute_sigma else (dof if dof > 0 else None)
    sd = np.sqrt(np.maximum(np.diag(cov), 0.0)) if np.all(np.isfinite(cov)) else np.full(3, np.nan)
    if C > 0 and np.all(np.isfinite(cov)):
        gC = np.array([0.0, cn / C, ce / C])
        gT = np.array([0.0, -ce / C ** 2, cn / C ** 2])
        sC = math.sqrt(max(gC @ cov @ gC, 0.0))
        sT = math.sqrt(max(gT @ cov @ gT, 0.0))
    else:
        sC = float(np.sqrt(max(cov[1, 1] + cov[2, 2], 0.0))) if np.all(np.isfinite(cov)) else math.nan
        sT = math.inf if np.all(np.isfinite(cov)) else math.nan
    return LSQCurrentResult(
        u=Estimate(u, float(sd[0]), est_dof), c=Estimate(C, sC, est_dof),
        theta=Estimate(theta, sT, est_dof), current_north=Estimate(cn, float(sd[1]), est_dof),
        current_east=Estimate(ce, float(sd[2]), est_dof), cov=cov, residuals=r, s=s, dof=dof,
        iterations=it)


def speed_through_water(vg, heading, current_speed, current_dir):
    """U on a leg from its ground speed once the current is known (seed 000 (A.1) solved for U):
    U = −C cos β + √(V² − C² sin² β), β = φ − θ. Arrays broadcast; [m/s], [rad]."""
    V = np.asarray(vg, dtype=float)
    beta = np.asarray(heading, dtype=float) - np.asarray(current_dir, dtype=float)
    C = np.asarray(current_speed, dtype=float)
    disc = V * V - (C * np.sin(beta)) ** 2
    if np.any(disc < 0):
        raise ValueError("ground speed smaller than the cross-course current: no solution")
    return -C * np.cos(beta) + np.sqrt(disc)


def reciprocal_pair_speed(vx, vy, std=None) -> Estimate:
    """Uncorrected reciprocal-pair estimate U_u = √((V_x² + V_y²)/2) (seed 000 eq. 4) [m/s].

    Exact identity from (A.1): V_x² + V_y² = 2(U² + C²) for any current direction, so
    U_u = U√(1 + C′²) ≥ U — always high, by the factor :func:`reciprocal_pair_bias_factor`
    (≈ 1 + C′²/2, the seed's e = C′²/2). std: uncertainty of each mean ground speed (propagated);
    the bias is not included in the std.
    """
    uu = math.sqrt(0.5 * (vx * vx + vy * vy))
    if std is None:
        return Estimate(uu, math.nan)
    sx, sy = _std_array(std, 2)
    return Estimate(uu, math.sqrt((vx * sx) ** 2 + (vy * sy) ** 2) / (2.0 * uu))


def reciprocal_pair_bias_factor(c_prime):
    """U_u/U = √(1 + C′²) (seed 000 eq. 4–6; exact)."""
    c = np.asarray(c_prime, dtype=float)
    return np.sqrt(1.0 + c * c)


# ----------------------------------------------------------------------------------- water track
@dataclasses.dataclass(frozen=True)
class WaterTrackCurrent:
    """The current c(t) = a + b (t − t_ref) [m/s, north and east] from straight windows where both the
    ground velocity (tracking) and the velocity through the water (a water-track log) are measured.

    ``coef`` (2, 2): rows (a, b), columns (north, east) (b = 0 for a constant); ``cov_coef`` the
    covariance of (a_N, a_E[, b_N, b_E]) (generalised least squares with the log's systematic errors
    correlating the windows); ``birge``: the windows' χ²/dof against that covariance (when above 1 it
    has scaled ``cov_coef``)."""

    coef: np.ndarray
    t_ref: float
    line: bool
    n_windows: int
    cov_coef: np.ndarray
    birge: float

    def __call__(self, t: float) -> tuple[Estimate, Estimate, np.ndarray]:
        """(north, east, covariance (2, 2)) at time of day t [s]."""
        X = np.eye(2) if not self.line else np.hstack([np.eye(2), (t - self.t_ref) * np.eye(2)])
        val = self.coef[0] + (self.coef[1] * (t - self.t_ref) if self.line else 0.0)
        cov = X @ self.cov_coef @ X.T
        return Estimate(float(val[0]), math.sqrt(cov[0, 0])), Estimate(float(val[1]), math.sqrt(cov[1, 1])), cov


def _rot(psi):
    c, s = np.cos(psi), np.sin(psi)
    return np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2)


def current_from_water_track(t, v_ground, cov_ground, heading, v_water, var_water, *, scale_sd: float = 0.0,
                             misalignment_sd: float = 0.0, heading_sd: float = 0.0) -> WaterTrackCurrent:
    """Current from K straight windows: c_k = V_G,k − R(ψ_k) w_k, the ground velocity less the velocity
    through the water turned from body to earth axes (a Doppler log in water-track mode beside a GNSS:
    the set and drift a navigator reads off the two). Inputs per window: mid-time ``t`` (K,) [s],
    ``v_ground`` (K, 2) north/east [m/s] with covariance ``cov_ground`` (K, 2, 2), gyro ``heading`` (K,)
    [rad], the log's mean surge/sway ``v_water`` (K, 2) [m/s] with variances ``var_water`` (K, 2).

    Errors: per window the ground velocity's and the log's noise; common to all windows (one draw per
    trial, not reduced by averaging) the log's scale error (relative sd ``scale_sd``), its misalignment
    about the vertical (``misalignment_sd`` [rad]) and the heading's bias (``heading_sd`` [rad]): to first
    order c_k changes by −R(ψ_k)(s + (ε + δψ) J) w_k, which correlates the windows (the correlation is
    what makes the log's errors on windows of different headings look like scatter). The current is a
    line in time per axis from four windows spanning at least 10 min (else a constant), fitted by
    generalised least squares with that covariance; χ²/dof above 1 (a current changing within the day in
    a way a line does not follow) scales the result's covariance up (Birge ratio).
    """
    t = np.asarray(t, float)
    vg = np.asarray(v_ground, float).reshape(-1, 2)
    Sg = np.asarray(cov_ground, float).reshape(-1, 2, 2)
    psi = np.asarray(heading, float)
    w = np.asarray(v_water, float).reshape(-1, 2)
    vw = np.asarray(var_water, float).reshape(-1, 2)
    K = t.size
    if not (vg.shape[0] == Sg.shape[0] == psi.size == w.shape[0] == vw.shape[0] == K) or K == 0:
        raise ValueError("one ground velocity, covariance, heading, water velocity and variance per window")
    R = _rot(psi).reshape(K, 2, 2)
    ww = np.einsum("kij,kj->ki", R, w)
    y = (vg - ww).reshape(-1)                                   # (2K,): c_N,0, c_E,0, c_N,1, ...
    V = np.zeros((2 * K, 2 * K))
    for k in range(K):
        V[2 * k:2 * k + 2, 2 * k:2 * k + 2] = Sg[k] + R[k] @ np.diag(vw[k]) @ R[k].T
    J = np.array([[0.0, -1.0], [1.0, 0.0]])
    G = np.column_stack([ww.reshape(-1), np.einsum("kij,jl,kl->ki", R, J, w).reshape(-1)])
    V += G @ np.diag([scale_sd ** 2, misalignment_sd ** 2 + heading_sd ** 2]) @ G.T
    V += 1e-14 * np.eye(2 * K)
    line = K >= 4 and float(t.max() - t.min()) >= 600.0
    t_ref = float(np.mean(t))
    X = np.tile(np.eye(2), (K, 1))
    if line:
        X = np.hstack([X, np.kron((t - t_ref)[:, None], np.eye(2))])
    Vi = np.linalg.inv(V)
    cov_b = np.linalg.inv(X.T @ Vi @ X)
    beta = cov_b @ (X.T @ Vi @ y)
    r = y - X @ beta
    dof = 2 * K - X.shape[1]
    birge = float(r @ Vi @ r) / dof if dof > 0 else 1.0
    cov_b = cov_b * max(1.0, birge)
    coef = np.zeros((2, 2))
    coef[0] = beta[:2]
    if line:
        coef[1] = beta[2:]
    return WaterTrackCurrent(coef, t_ref, line, K, cov_b, birge)
