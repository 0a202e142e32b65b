"""Spiral manoeuvres: direct (Dieudonné) and reverse (Bech) spiral reduction.

Direct spiral (Dieudonné 1953; seed 002 "Spiral tests"; ITTC 7.5-04-02-01): one continuous manoeuvre,
rudder stepped 15R → 15L → 15R, each setting held until the rate of turn is constant and then ~2 min
recorded; a setting the helm missed is held as reached. Reduction: per hold, the steady rate of turn is
Δheading/Δtime over the steady window, plotted against the rudder angle ACTUALLY reached (mean of the
rudder record over the window, not the ordered angle). A directionally unstable ship shows a
hysteresis loop: between two rudder angles two steady rates exist, depending on the branch.

Reverse spiral (Bech 1968, 1971): the helmsman/autopilot holds a set rate of turn; the mean rudder
needed is recorded. The curve δ(r) is single valued even for an unstable ship, so it maps the part
of the S-curve that the direct spiral cannot reach.

Inputs: gyro ``t_heading, heading`` [s, rad] and rudder synchro ``t_rudder, rudder`` [s, rad] on
their own clocks; rudder positive to starboard, heading clockwise; rates are rad/s.

Definitions and uncertainty:

* Holds (:func:`rudder_holds`): the rudder record (5-sample running median) is split where it departs
  from the current plateau by more than ``step_threshold`` for ``persist`` samples; plateaus shorter
  than ``min_hold_s`` are transitions. The first detected hold is the approach (seed 002: a minute of
  steady approach before EXECUTE) and is dropped unless ``t_execute`` or the log's ``holds`` say
  otherwise.
* Steady window: the last ``window_s`` (120 s) of each hold. Rate = OLS slope of the unwrapped heading
  over the window, SE from the residuals inflated for lag-1 autocorrelation (√((1+ρ)/(1−ρ))).
  Rudder = mean over the window, SE = s/√n likewise inflated, plus the synchro resolution/√12 when
  given. Steadiness test: a quadratic in time over the window gives the change of rate across it,
  Δr = 2c·W; the hold is NOT STEADY when |Δr| > tol_abs + tol_rel·|r| + z·SE(Δr) (defaults
  0.003°/s, 3 %, z = 2) or when the hold is shorter than the window. Such points are reported with
  ``steady=False`` and excluded from every average and fit.
* Branches: 'down' when the hold was entered with the rudder moving to port (angle decreasing), 'up'
  when moving to starboard.
* Loop, model-free (:func:`hysteresis_loop` ``direct``): at every rudder setting visited on both
  branches (within ``match_tol``), the branch difference r_down − r_up with its SE; a loop point when
  the difference is positive (the down sweep stays on the starboard branch), exceeds 2 SE and exceeds
  the practical tolerance 0.003°/s + 3 % of the rate. Width bracket: the loop spans at least the
  settings with significant differences and at most the interval to the nearest settings beyond
  them; height: the largest significant difference.
* Loop, model (:func:`fit_spiral_curve`): δ(r) = c₀ + c₁r + c₂r² + c₃r³ (the steady-state S-curve,
  e.g. the steady branches of r³ − a r = b δ) by weighted least squares with the effective variance
  σ_δ² + (dδ/dr)² σ_r² (errors in both variables), covariance scaled by the Birge ratio when χ²/ν > 1.
  The loop exists when dδ/dr has two real roots r₁ < r₂ (c₃ > 0): the edges are the fold rudder angles
  δ(r₂) and δ(r₁); width = δ(r₁) − δ(r₂); height = the spread of the outer steady rates at the loop
  centre. c₁ = dδ/dr at r = 0 [s] is the directional-stability slope (negative: unstable at straight
  course). Uncertainties by Monte Carlo over the coefficient covariance (width is not smooth at 0, so
  no delta method): std of the draws, and ``p_loop`` = fraction of draws with a loop. A stable ship
  gives width 0 with p_loop small. The model is a local description: fit only the central settings
  (``max_rudder``) if the curve saturates at large rudder.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Sequence

import numpy as np

from vtrials.reduce.estimate import Estimate
from vtrials.reduce.series import clean_series as _clean, ar1_inflation as _ar1_inflation
from vtrials.units import DEG


# --------------------------------------------------------------------------------------------- helpers
def _slope(t, y):
    """OLS slope and its lag-1-corrected SE; dof."""
    x = t - t.mean()
    sxx = float(x @ x)
    b = float(x @ (y - y.mean())) / sxx
    r = y - y.mean() - b * x
    dof = len(t) - 2
    s2 = float(r @ r) / dof
    return b, math.sqrt(s2 / sxx) * _ar1_inflation(r), dof


def _mean(y, resolution=0.0):
    n = len(y)
    m = float(np.mean(y))
    se = float(np.std(y, ddof=1) / math.sqrt(n)) * _ar1_inflation(y - m) if n > 1 else math.inf
    return Estimate(m, math.hypot(se, resolution / math.sqrt(12.0)), n - 1)


# --------------------------------------------------------------------------------------------- holds
def rudder_holds(t_rudder, rudder, *, step_threshold: float = 0.75 * DEG, min_hold_s: float = 30.0,
                 persist: int = 3) -> list[tuple[float, float]]:
    """Time intervals [s] over which the rudder [rad] was held at one setting.

    A 5-sample running median of the record is split where it departs from the current plateau level
    (mean of the filtered plateau over its last ≤ 30 samples) by more than ``step_threshold`` [rad] for ``persist`` consecutive
    samples; the moving samples at the start of a plateau (further than the threshold from its final
    median) are trimmed; plateaus shorter than ``min_hold_s`` [s] are dropped.
    """
    t, d = _clean(t_rudder, rudder)
    n = len(t)
    if n < 5:
        return []
    pad = np.pad(d, 2, mode="edge")
    dm = np.median(np.lib.stride_tricks.sliding_window_view(pad, 5), axis=1)
    segs = []
    start = 0
    i = 1
    cs = np.concatenate([[0.0], np.cumsum(dm)])
    while i < n:
        j0 = max(start, i - 30)
        level = (cs[i] - cs[j0]) / (i - j0)  # mean of the (median-filtered) plateau so far
        if abs(dm[i] - level) > step_threshold:
            j = min(n, i + persist)
            if np.all(np.abs(dm[i:j] - level) > step_threshold) and j - i == persist:
                segs.append((start, i))
                start = i
        i += 1
    segs.append((start, n))
    out = []
    for a, b in segs:
        if b - a < 3:
            continue
        lev = float(np.median(dm[a:b]))
        # trim the moves in and out: samples further from the level than the hold's own scatter
        # (3 × 1.4826 MAD, at least 0.02°) are not held; plus one sample of guard at each end
        mad = 1.4826 * float(np.median(np.abs(d[a:b] - lev)))
        tol = min(step_threshold, max(3 * mad, 0.02 * DEG))
        k = a
        while k < b and abs(d[k] - lev) > tol:
            k += 1
        e = b - 1
        while e > k and abs(d[e] - lev) > tol:
            e -= 1
        k, e = min(k + 1, e), max(e - 1, k)
        if e > k and t[e] - t[k] >= min_hold_s:
            out.append((float(t[k]), float(t[e])))
    return out


# ------------------------------------------------------------------------------------ spiral points
@dataclasses.dataclass(frozen=True)
class SpiralPoint:
    """One rudder setting of a direct spiral (rad, rad/s, s)."""

    rudder: Estimate  # mean rudder reached over the steady window
    rate: Estimate  # steady rate of turn
    steady: bool
    branch: str  # 'down' (rudder moving to port), 'up' (to starboard)
    order: int  # position in the sequence
    hold: tuple[float, float]
    window: tuple[float, float]
    rate_change: Estimate  # change of rate across the window (steadiness test)
    note: str = ""

    def to_dict(self) -> dict:
        return {"rudder": self.rudder.to_dict(), "rate": self.rate.to_dict(), "steady": self.steady,
                "branch": self.branch, "order": self.order, "hold": self.hold, "window": self.window,
                "rate_change": self.rate_change.to_dict(), "note": self.note}


def spiral_points(t_heading, heading, t_rudder, rudder, *, holds: Sequence[tuple[float, float]] | None = None,
                  window_s: float = 120.0, tol_abs: float = 0.003 * DEG, tol_rel: float = 0.03,
                  z: float = 2.0, rudder_resolution: float = 0.0, t_execute: float | None = None,
                  **hold_kw) -> list[SpiralPoint]:
    """Steady rate of turn [rad/s] vs rudder reached [rad] for every hold of a direct spiral.

    ``holds`` [(t0, t1)] from the trial log, or detected with :func:`rudder_holds` (``hold_kw``);
    detected holds starting before ``t_execute`` [s] are the approach and are dropped (default: the
    first detected hold is the approach — the seed-002 spiral starts with a minute of approach).
    See the module docstring for the window, the steadiness test and the uncertainties.
    """
    th, psi = _clean(t_heading, heading)
    psi = np.unwrap(psi)
    tr, dr = _clean(t_rudder, rudder)
    if holds is not None:
        hl = list(holds)
    else:
        hl = rudder_holds(tr, dr, **hold_kw)
        # the record starts with the approach (helm steering, not a rudder hold): drop what precedes
        # EXECUTE (default: the first detected hold, i.e. the first rudder move marks EXECUTE)
        if t_execute is None and hl:
            t_execute = hl[0][1]
        if t_execute is not None:
            hl = [h for h in hl if h[0] >= t_execute]
    means = []
    for a, b in hl:
        m = (tr >= a) & (tr <= b)
        means.append(float(np.mean(dr[m])) if np.any(m) else float("nan"))
    pts = []
    for k, (a, b) in enumerate(hl):
        before = (tr >= a - 60.0) & (tr <= a - 3.0)
        if k > 0:
            direction = means[k] - means[k - 1]
        elif np.count_nonzero(before) >= 3:  # the level the first setting was approached from
            direction = means[0] - float(np.median(dr[before]))
        elif len(hl) > 1:
            direction = means[1] - means[0]
        else:
            direction = -1.0
        branch = "down" if direction < 0 else "up"
        w0 = max(a, b - window_s)
        note = ""
        short = b - a < window_s
        mh = (th >= w0) & (th <= b)
        mr = (tr >= w0) & (tr <= b)
        if np.count_nonzero(mh) < 8 or np.count_nonzero(mr) < 3:
            pts.append(SpiralPoint(Estimate(means[k], math.inf), Estimate(float("nan"), math.inf), False, branch, k,
                                   (a, b), (w0, b), Estimate(float("nan"), math.inf), "too few samples"))
            continue
        tt, yy = th[mh], psi[mh]
        r, se, dof = _slope(tt, yy)
        x = tt - tt.mean()
        A = np.column_stack([np.ones_like(x), x, x * x])
        coef, *_ = np.linalg.lstsq(A, yy, rcond=None)
        res = yy - A @ coef
        s2 = float(res @ res) / max(len(tt) - 3, 1)
        cov = s2 * np.linalg.pinv(A.T @ A)
        W = float(np.ptp(tt))
        dr_ = 2 * coef[2] * W
        se_dr = 2 * math.sqrt(cov[2, 2]) * W * _ar1_inflation(res)
        steady = (not short) and abs(dr_) <= tol_abs + tol_rel * abs(r) + z * se_dr
        if short:
            note = f"hold shorter than the {window_s:.0f}-s window"
        elif not steady:
            note = "never steady within the time allowed (rate still changing across the window)"
        pts.append(SpiralPoint(_mean(dr[mr], rudder_resolution), Estimate(r, se, dof), bool(steady), branch, k,
                               (a, b), (w0, b), Estimate(dr_, se_dr), note))
    return pts


@dataclasses.dataclass(frozen=True)
class ReversePoint:
    """One held rate of a reverse spiral."""

    rate: Estimate  # rate of turn held [rad/s]
    rudder: Estimate  # mean rudder needed [rad]
    window: tuple[float, float]


def reverse_spiral_points(t_heading, heading, t_rudder, rudder, segments: Sequence[tuple[float, float]], *,
                          rudder_resolution: float = 0.0) -> list[ReversePoint]:
    """Reverse (Bech) spiral: per segment [(t0, t1)] of held rate of turn, the rate held (OLS slope of
    heading, lag-1-corrected SE) and the mean rudder needed (SE of the mean, lag-1 corrected — the
    helm works continuously, so the rudder samples are strongly autocorrelated)."""
    th, psi = _clean(t_heading, heading)
    psi = np.unwrap(psi)
    tr, dr = _clean(t_rudder, rudder)
    out = []
    for a, b in segments:
        mh = (th >= a) & (th <= b)
        mr = (tr >= a) & (tr <= b)
        if np.count_nonzero(mh) < 5 or np.count_nonzero(mr) < 3:
            raise ValueError(f"segment ({a}, {b}) has too few samples")
        r, se, dof = _slope(th[mh], psi[mh])
        out.append(ReversePoint(Estimate(r, se, dof), _mean(dr[mr], rudder_resolution), (float(a), float(b))))
    return out


# ------------------------------------------------------------------------------------- S-curve model
@dataclasses.dataclass(frozen=True)
class SpiralCurve:
    """δ(r) = Σ c_k r^k (k = 0..3), δ in rad, r in rad/s."""

    coef: np.ndarray
    cov: np.ndarray
    chi2_per_dof: float
    n: int

    def rudder(self, r):
        return np.polynomial.polynomial.polyval(r, self.coef)


def fit_spiral_curve(rate, rate_std, rudder, rudder_std, *, iterations: int = 4) -> SpiralCurve:
    """Weighted cubic δ(r) through steady points (effective-variance weights, Birge-scaled covariance).

    ``rate``, ``rate_std`` [rad/s]; ``rudder``, ``rudder_std`` [rad]. Needs at least 5 points.
    """
    r = np.asarray(rate, float)
    sr = np.asarray(rate_std, float)
    d = np.asarray(rudder, float)
    sd = np.asarray(rudder_std, float)
    if len(r) < 5:
        raise ValueError("at least 5 steady points are needed for the spiral curve")
    rs = float(np.max(np.abs(r))) or 1.0
    x = r / rs
    X = np.vander(x, 4, increasing=True)
    floor = 1e-6 * max(float(np.ptp(d)), 1e-12)
    var = sd ** 2 + floor ** 2
    beta = np.zeros(4)
    for _ in range(iterations):
        w = 1.0 / var
        XtW = X.T * w
        cov_b = np.linalg.pinv(XtW @ X)
        beta = cov_b @ XtW @ d
        slope = np.polynomial.polynomial.polyval(x, np.polynomial.polynomial.polyder(beta)) / rs
        var = sd ** 2 + (slope * sr) ** 2 + floor ** 2
    w = 1.0 / var
    XtW = X.T * w
    cov_b = np.linalg.pinv(XtW @ X)
    beta = cov_b @ XtW @ d
    res = d - X @ beta
    dof = len(r) - 4
    chi2 = float(np.sum(w * res ** 2)) / dof if dof > 0 else 1.0
    cov_b = cov_b * max(1.0, chi2)
    S = np.diag(rs ** -np.arange(4.0))
    return SpiralCurve(S @ beta, S @ cov_b @ S, chi2, len(r))


def _loop_from_coef(c) -> tuple[float, float, float, float]:
    """(width, height, edge_low, edge_high) of the loop of δ(r) = Σ c_k r^k; zeros and NaN when the
    curve is monotone."""
    c0, c1, c2, c3 = c
    if c3 <= 0:
        return 0.0, 0.0, float("nan"), float("nan")
    disc = 4 * c2 * c2 - 12 * c1 * c3
    if disc <= 0:
        return 0.0, 0.0, float("nan"), float("nan")
    sq = math.sqrt(disc)
    r1, r2 = (-2 * c2 - sq) / (6 * c3), (-2 * c2 + sq) / (6 * c3)
    p = np.polynomial.polynomial.polyval
    d_hi, d_lo = p(r1, c), p(r2, c)  # local max at r1, local min at r2
    width = d_hi - d_lo
    dm = 0.5 * (d_hi + d_lo)
    roots = np.roots([c3, c2, c1, c0 - dm])
    roots = np.sort(roots.real[np.abs(roots.imag) < 1e-9 * (1 + np.abs(roots.real))])
    height = float(roots[-1] - roots[0]) if len(roots) >= 2 else 0.0
    return float(width), height, float(d_lo), float(d_hi)


def _loop_many(C: np.ndarray) -> np.ndarray:
    """Vectorised (width, height) of :func:`_loop_from_coef` for coefficient rows C (n, 4)."""
    c0, c1, c2, c3 = C.T
    disc = 4 * c2 * c2 - 12 * c1 * c3
    ok = (c3 > 0) & (disc > 0)
    out = np.zeros((len(C), 2))
    if not np.any(ok):
        return out
    c0, c1, c2, c3, disc = c0[ok], c1[ok], c2[ok], c3[ok], disc[ok]
    sq = np.sqrt(disc)
    r1, r2 = (-2 * c2 - sq) / (6 * c3), (-2 * c2 + sq) / (6 * c3)

    def pv(r):
        return c0 + c1 * r + c2 * r * r + c3 * r ** 3

    d_hi, d_lo = pv(r1), pv(r2)
    dm = 0.5 * (d_hi + d_lo)
    # three real roots of c3 r³ + c2 r² + c1 r + (c0 − dm) = 0 (trigonometric form)
    a, b, c = c2 / c3, c1 / c3, (c0 - dm) / c3
    p = b - a * a / 3
    q = 2 * a ** 3 / 27 - a * b / 3 + c
    pn = np.minimum(p, -1e-300)
    arg = np.clip(3 * q / (2 * pn) * np.sqrt(-3 / pn), -1.0, 1.0)
    m = 2 * np.sqrt(-pn / 3)
    phi = np.arccos(arg) / 3
    roots = np.stack([m * np.cos(phi - 2 * np.pi * k / 3) for k in range(3)])
    out[ok, 0] = d_hi - d_lo
    out[ok, 1] = np.where(p < 0, roots.max(axis=0) - roots.min(axis=0), 0.0)
    return out


@dataclasses.dataclass
class LoopResult:
    """Hysteresis loop of a spiral (rad, rad/s)."""

    width: Estimate
    height: Estimate
    edges: tuple[float, float]  # fold rudder angles (low, high) of the fitted S-curve [rad]
    p_loop: float  # Monte Carlo fraction of coefficient draws with a loop
    verdict: str  # 'unstable (loop)', 'stable (no loop)', 'inconclusive'
    slope_at_origin: Estimate  # dδ/dr at r = 0 [s]
    curve: SpiralCurve | None
    direct: dict
    consistent: bool | None  # fitted edges inside the model-free bracket
    notes: list = dataclasses.field(default_factory=list)

    def to_dict(self) -> dict:
        d = {"width": self.width.to_dict(), "height": self.height.to_dict(), "edges": self.edges,
             "p_loop": self.p_loop, "verdict": self.verdict, "slope_at_origin": self.slope_at_origin.to_dict(),
             "consistent": self.consistent, "notes": self.notes}
        dd = dict(self.direct)
        dd["pairs"] = [{k: (v.to_dict() if isinstance(v, Estimate) else v) for k, v in p.items()}
                       for p in dd.get("pairs", [])]
        if isinstance(dd.get("height"), Estimate):
            dd["height"] = dd["height"].to_dict()
        d["direct"] = dd
        return d


def _direct_loop(points: Sequence[SpiralPoint], match_tol: float, z: float, tol_abs: float = 0.003 * DEG,
                 tol_rel: float = 0.03) -> dict:
    down = [p for p in points if p.branch == "down"]
    up = [p for p in points if p.branch == "up"]
    pairs = []
    for pd in down:
        cands = [pu for pu in up if abs(pu.rudder.value - pd.rudder.value) <= match_tol]
        if not cands:
            continue
        pu = min(cands, key=lambda q: abs(q.rudder.value - pd.rudder.value))
        diff = pd.rate.value - pu.rate.value
        sd = math.hypot(pd.rate.std, pu.rate.std)
        practical = tol_abs + tol_rel * max(abs(pd.rate.value), abs(pu.rate.value))
        pairs.append({"rudder": 0.5 * (pd.rudder.value + pu.rudder.value),
                      "difference": Estimate(diff, sd),
                      "significant": bool(diff > z * sd and diff > practical)})
    sig = [p for p in pairs if p["significant"]]
    settings = np.sort(np.array([p.rudder.value for p in points]))
    out: dict = {"pairs": pairs}
    if not sig:
        out.update({"loop": False, "width_bracket": (0.0, 0.0), "height": Estimate(0.0, 0.0)})
        return out
    rr = np.array([p["rudder"] for p in sig])
    lo_r, hi_r = float(rr.min()), float(rr.max())
    below = settings[settings < lo_r - match_tol]
    above = settings[settings > hi_r + match_tol]
    outer_lo = float(below.max()) if below.size else -math.inf
    outer_hi = float(above.min()) if above.size else math.inf
    best = max(sig, key=lambda p: abs(p["difference"].value))
    out.update({"loop": True, "width_bracket": (hi_r - lo_r, outer_hi - outer_lo),
                "edge_brackets": ((outer_lo, lo_r), (hi_r, outer_hi)),
                "height": Estimate(abs(best["difference"].value), best["difference"].std)})
    return out


def hysteresis_loop(points: Sequence, *, max_rudder: float | None = None, match_tol: float = 0.5 * DEG,
                    z: float = 2.0, n_mc: int = 4000, seed: int = 0) -> LoopResult:
    """Loop width [rad] and height [rad/s] from spiral points (see the module docstring).

    ``points``: :class:`SpiralPoint` (direct spiral; unsteady points are ignored) or
    :class:`ReversePoint`; ``max_rudder`` [rad] limits the S-curve fit to the central settings.
    """
    notes: list[str] = []
    pts = [p for p in points if getattr(p, "steady", True)]
    n_unsteady = len(points) - len(pts)
    if n_unsteady:
        notes.append(f"{n_unsteady} setting(s) never steady: excluded")
    fit_pts = [p for p in pts if max_rudder is None or abs(p.rudder.value) <= max_rudder]
    direct = _direct_loop([p for p in pts if isinstance(p, SpiralPoint)], match_tol, z) \
        if any(isinstance(p, SpiralPoint) for p in pts) else {"pairs": [], "loop": None}
    try:
        curve = fit_spiral_curve([p.rate.value for p in fit_pts], [p.rate.std for p in fit_pts],
                                 [p.rudder.value for p in fit_pts], [p.rudder.std for p in fit_pts])
    except ValueError as exc:
        notes.append(str(exc))
        return LoopResult(Estimate(float("nan"), math.inf), Estimate(float("nan"), math.inf), (math.nan, math.nan),
                          math.nan, "inconclusive", Estimate(float("nan"), math.inf), None, direct, None, notes)
    w, h, elo, ehi = _loop_from_coef(curve.coef)
    rng = np.random.default_rng(seed)
    draws = rng.multivariate_normal(curve.coef, curve.cov, size=n_mc, method="svd")
    wh = _loop_many(draws)
    p_loop = float(np.mean(wh[:, 0] > 0))
    if p_loop >= 0.975:
        verdict = "unstable (loop)"
    elif p_loop <= 0.025:
        verdict = "stable (no loop)"
    else:
        verdict = "inconclusive"
    if curve.chi2_per_dof > 3:
        notes.append(f"cubic S-curve fits poorly (chi2/dof = {curve.chi2_per_dof:.1f}); consider max_rudder")
    rates = np.array([p.rate.value for p in fit_pts])
    if w > 0:
        c = curve.coef
        sq = math.sqrt(4 * c[2] ** 2 - 12 * c[1] * c[3])
        rr = ((-2 * c[2] - sq) / (6 * c[3]), (-2 * c[2] + sq) / (6 * c[3]))
        if min(rr) < rates.min() or max(rr) > rates.max():
            notes.append("fold points of the fitted curve lie outside the measured rates (extrapolated)")
    consistent = None
    if w > 0 and direct.get("loop"):
        (a0, a1), (b0, b1) = direct["edge_brackets"]
        tol = match_tol
        consistent = bool(a0 - tol <= elo <= a1 + tol and b0 - tol <= ehi <= b1 + tol)
    elif direct.get("loop") is not None:
        consistent = bool(direct.get("loop")) == (w > 0)
    slope0 = Estimate(float(curve.coef[1]), math.sqrt(float(curve.cov[1, 1])), curve.n - 4)
    return LoopResult(Estimate(w, float(np.std(wh[:, 0]))), Estimate(h, float(np.std(wh[:, 1]))), (elo, ehi),
                      p_loop, verdict, slope0, curve, direct, consistent, notes)


@dataclasses.dataclass
class SpiralResult:
    points: list
    loop: LoopResult
    down: list  # steady points of the down branch in sequence order
    up: list
    never_steady: list

    def to_dict(self) -> dict:
        return {"points": [p.to_dict() for p in self.points], "loop": self.loop.to_dict(),
                "never_steady": [p.order for p in self.never_steady]}


def direct_spiral(t_heading, heading, t_rudder, rudder, *, max_rudder: float | None = None, seed: int = 0,
                  **kw) -> SpiralResult:
    """Full direct-spiral reduction: points (:func:`spiral_points`, keyword arguments passed on),
    branches, and the hysteresis loop (:func:`hysteresis_loop`)."""
    pts = spiral_points(t_heading, heading, t_rudder, rudder, **kw)
    loop = hysteresis_loop(pts, max_rudder=max_rudder, seed=seed)
    return SpiralResult(pts, loop, [p for p in pts if p.steady and p.branch == "down"],
                        [p for p in pts if p.steady and p.branch == "up"], [p for p in pts if not p.steady])
