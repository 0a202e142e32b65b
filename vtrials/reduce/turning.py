"""Turning-circle (tactical) trial reduction: drift, drift-corrected track and turning metrics.

Inputs are RECORDED channels only, each on its own clock (time stamps in s, same time scale — the
seed-002 teams synchronise ship and shore clocks before each run; an unknown offset δt between the
gyro and the tracking clocks maps into the positions at the heading marks as U·δt):

* tracking positions ``t, north, east`` [s, m, m]: ~1 Hz, white noise of metres, possibly gappy;
* gyro heading ``t_heading, heading`` [s, rad], unwrapped here (``np.unwrap``), clockwise from north;
* optional roll (heel) ``t_roll, roll`` [s, rad] (positive = starboard down, as recorded) and rudder
  ``t_rudder, rudder`` [s, rad].

Procedure (seed 002, "Tactical trials"; ITTC 7.5-04-02-01 §turning circle; IMO MSC.137(76) and
MSC/Circ.1053 definitions of advance, transfer and tactical diameter):

1. Approach course ψ₀ = circular mean of the gyro heading over the approach (default the minute before
   EXECUTE, the COMEX minute); EXECUTE position and approach velocity from a straight-line fit of the
   positions over the same minute, evaluated at EXECUTE (noise σ_p/√n instead of σ_p).
2. Steady part (:func:`steady_window`): sliding least-squares rate of turn over windows spanning
   ``rate_window_deg`` of heading; reference rate = slope over the last ``ref_deg`` of heading change;
   the steady part starts at the first window centre after which every window agrees with the
   reference within max(tol·|r_ref|, z·SE) (tol = 2 % by default; z Bonferroni-corrected for the
   number of independent windows, so that gyro noise alone gives a false alarm in 1 % of records).
   The record is flagged NOT steady when the steady part spans less than ``min_span_deg`` (90°) of
   heading. A residual transient inside the tolerance biases the steady values by less than
   tol × (transient time constant / steady duration); that bias is not in the stated SEs.
3. Drift (:func:`drift_from_pairs`, the seed-002 method used by the report): positions one steady
   turning period T = 2π/|r_ss| apart (i.e. 360° of heading apart in a steady turn) differ only by the
   drift: d_i = (P(t_i + T) − P(t_i))/T for every tracking sample t_i in the steady part whose partner
   t_i + T is still recorded. The partner position is interpolated with a 4-point Lagrange cubic
   (exact to O(Δθ⁴) on a circle). Standard error: from the pair scatter. Pairs share interpolation
   samples, so they are not independent; the pair scatter is used to estimate the per-axis position
   noise σ̂² = T² Σ(d_i − d̄)² / Σ c_i (c_i = 1 + Σ w², the noise multiplicity of pair i) and the variance
   of the mean follows exactly from the linear weights of every raw sample in d̄ (σ̂² Σ a_k²). The error
   of T (from the SE of r_ss) adds (σ_T/T)² v̄ v̄ᵀ, v̄ the mean water velocity at the partner points.
   Why this one: differencing at equal heading cancels every disturbance that is a function of heading
   (wind forces on the turning ship, a slightly non-circular path), so it only assumes a constant drift
   and a steady rate. :func:`drift_from_circle_fit` (circle whose centre translates at constant
   velocity, fitted by least squares with a free phase rate) is an independent cross-check that uses
   all steady samples but assumes a perfectly circular path; it is used only when no pairs exist.
   The trial reduction (:mod:`vtrials.reduce.maneuvering`) takes each circle's drift over its steady
   loop instead (``drift='loop'``, :func:`drift_over_loop`: the displacement between the loop's ends,
   360° of heading apart, over its duration — the references' definition), since the pairs from a
   steady part that starts within the first loop carry its transient.
4. Drift-corrected track (:func:`drift_corrected_track`): recorded − drift·(t − t_execute).
5. Metrics from the corrected track: advance (along ψ₀ from EXECUTE to the 90° heading-change mark),
   transfer (perpendicular, positive toward the turn, at 90°), tactical diameter (perpendicular at
   180°), times to 10°, 90° and 180°, distance travelled to 10° (IMO initial turning), maximum heel.
6. Steady turn (:func:`steady_loop`): the values of the steady turn come from one full loop of heading,
   the second one — 360° to 720° of heading change after EXECUTE (the last 360° before FINEX when the
   turn ends short of 720°) — the definition the references use (:func:`vtrials.truth.metrics.turning`;
   ITTC 7.5-04-02-01 measures the steady turn once the transient of the first loop has died out, and
   IMO MSC/Circ.1053 asks for turns of at least 540°, so that a whole steady loop is not always
   recorded). The rate-of-turn test of step 2 only says whether the turn settled; its steady part
   usually starts within the first loop, where the speed and radius are still falling (on the patrol
   vessel's tactical day it started at EXECUTE in most turns, 40 replicates: steady diameter biased
   −1.1 m, 43 % covered). On the loop: steady turning diameter = geometric least-squares circle
   fitted to the track less the circle's OWN drift (``loop_drift``: each loop is closed by its own
   drift, as ITTC's drift correction does; the day's mean drift leaves the side-dependent leeway of the
   circling ship in the track, and the circle fitted to an open loop of a drifting circle is off by
   up to drift·T/(2π) in radius, depending on where the loop starts), steady rate of turn = 360° / (time for the loop) (the mean rate of change of
   heading; in wind the rate varies around the loop and an OLS slope depends on where the loop
   starts), steady speed U = R·|r_ss| (circumference / time for the loop), drift angle β = ψ − χ
   (heading minus the tangent direction of the fitted circle at each sample, positive bow-in).
   Steady heel and mean rudder are taken over the steady part of step 2.

Uncertainties (all 1-σ, combined in quadrature as independent sources):
* position noise σ_p per axis, estimated from the residuals of piecewise cubic fits (12-sample
  chunks; unbiased for a locally cubic track; chunks with variance > 10× the median are dropped as
  wild points) and propagated through the local cubic fits that give the positions at the marks;
* heading-mark times: quadratic fit of the heading around the crossing, σ_t = σ(ψ̂)/|ψ̇|, mapped to
  position through the track velocity at the mark;
* drift: its covariance × (t − t_execute)², and, for the fitted circle, the numerical sensitivity of R
  to the drift;
* EXECUTE position (approach fit) and approach course (SE of the mean heading, lag-1 corrected).
* distance to the 10° mark (IMO initial turning): chord EXECUTE → P(t₁₀) lengthened to the circular
  arc with the same change of track direction; SE from the chord-direction variance of the end points;
* heel: steady = mean roll over the steady part (SE lag-1 corrected); maximum = local quadratic at the
  sample of largest |roll| (SE from the roll noise); steady rudder likewise from the rudder channel;
* drift angle: SE of the mean of β_i (lag-1 corrected); the gyro/tracking clock offset is not included.
* steady loop: the two heading-mark times (local quadratic of the gyro, as for the marks) and the
  gyro's slow wander between them (Gauss–Markov σ_d, τ of the maker's specification:
  Var = 2σ_d²(1 − e^{−T/τ}), as a time error of ÷|r|) give σ_T, hence σ_r = |r| σ_T / T; the circle's
  radius: the fit's covariance plus its sensitivity to the loop drift through the drift's covariance;
  U: σ_U² = r² σ_R² + R² σ_r².

Rate of turn vs rudder (:func:`rudder_breakdown`, seed 002 Fig. 12): turns grouped by approach speed
and side; breakdown = the steady rate falls significantly (one-sided z test on the two SEs) when the
rudder angle grows.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Sequence

import numpy as np
from scipy import optimize, stats

from vtrials.reduce.estimate import Estimate
from vtrials.reduce.series import clean_series as _clean, ar1_inflation as _ar1_inflation, slope_variance, \
    correlated_variance

TWO_PI = 2.0 * math.pi


# --------------------------------------------------------------------------------------------- helpers
def noise_sigma(t, y, chunk: int = 12) -> tuple[float, int]:
    """White-noise standard deviation of a smooth channel and its degrees of freedom.

    The record is cut into consecutive chunks of ``chunk`` samples; a cubic in time is fitted to each
    and the residual sums of squares are pooled: σ² = Σ RSS / Σ (m − 4). Unbiased when the signal is
    locally a cubic (a turning track at 1 Hz is to better than 1 mm over 12 s). Chunks whose variance
    exceeds 10× the median chunk variance (wild points, gaps) are left out.
    """
    t, y = _clean(t, y)
    n = len(t)
    if n < 6:
        return float("nan"), 0
    m = max(6, min(chunk, n))
    bounds = []  # consecutive chunks of m samples; a tail shorter than 6 folds into the last one
    for i0 in range(0, n - 5, m):
        i1 = n if n - min(n, i0 + m) < 6 else i0 + m
        bounds.append((i0, i1))
        if i1 == n:
            break
    full = [b for b in bounds if b[1] - b[0] == m]
    var, dof = [], []
    if full:  # the equal chunks at once: residuals off the cubic's column space (batched QR)
        i0s = np.array([b[0] for b in full])[:, None] + np.arange(m)
        tt, yy = t[i0s], y[i0s]
        x = (tt - tt.mean(axis=1, keepdims=True)) / np.maximum(np.ptp(tt, axis=1), 1e-9)[:, None]
        q, _ = np.linalg.qr(x[..., None] ** np.arange(3, -1, -1))
        r = yy - np.einsum("bij,bj->bi", q, np.einsum("bij,bi->bj", q, yy))
        var.extend(np.einsum("bi,bi->b", r, r) / (m - 4))
        dof.extend([m - 4] * len(full))
    for i0, i1 in (b for b in bounds if b[1] - b[0] != m):
        tt = t[i0:i1]
        x = (tt - tt.mean()) / max(np.ptp(tt), 1e-9)
        A = np.vander(x, 4)
        coef, *_ = np.linalg.lstsq(A, y[i0:i1], rcond=None)
        r = y[i0:i1] - A @ coef
        var.append(float(r @ r) / (len(tt) - 4))
        dof.append(len(tt) - 4)
    var, dof = np.array(var), np.array(dof)
    med = np.median(var)
    keep = var <= 10.0 * med if med > 0 else np.ones(var.shape, bool)
    s2 = float(np.sum(var[keep] * dof[keep]) / np.sum(dof[keep]))
    return math.sqrt(s2), int(np.sum(dof[keep]))


def _ols_line(t, y):
    """Straight line y = a + b (t − t̄): returns b, SE(b) (lag-1 corrected), a, SE(a), t̄, dof."""
    t = np.asarray(t, float)
    y = np.asarray(y, float)
    n = len(t)
    tm = t.mean()
    x = t - tm
    sxx = float(x @ x)
    b = float(x @ (y - y.mean())) / sxx
    a = float(y.mean())
    r = y - a - b * x
    dof = n - 2
    s2 = float(r @ r) / dof if dof > 0 else float("nan")
    k = _ar1_inflation(r)
    return b, k * math.sqrt(s2 / sxx), a, k * math.sqrt(s2 / n), tm, dof


def _local_poly(t, y, tq, half_width, deg, sigma, min_pts=None):
    """Least-squares polynomial of degree ``deg`` in the samples within ±half_width of tq (widened
    until it holds at least ``min_pts``). Returns value, slope, var(value), var(slope), cov."""
    t = np.asarray(t, float)
    y = np.asarray(y, float)
    min_pts = min_pts or deg + 3
    hw = half_width
    for _ in range(60):
        m = np.abs(t - tq) <= hw
        if np.count_nonzero(m) >= min_pts:
            break
        hw *= 1.3
    tt, yy = t[m], y[m]
    if len(tt) < deg + 1:
        raise ValueError("not enough samples around t = %.2f s" % tq)
    scale = max(hw, 1e-9)
    x = (tt - tq) / scale
    A = np.vander(x, deg + 1, increasing=True)
    AtA_inv = np.linalg.pinv(A.T @ A)
    coef = AtA_inv @ A.T @ yy
    cov = sigma ** 2 * AtA_inv
    val, slope = float(coef[0]), float(coef[1]) / scale
    return val, slope, float(cov[0, 0]), float(cov[1, 1]) / scale ** 2, float(cov[0, 1]) / scale


def _lagrange_weights(ts: np.ndarray, tq: float, max_gap: float):
    """Indices and weights of the 4-point Lagrange interpolation of samples ``ts`` at tq (2 below,
    2 above; fewer at the ends). None when tq falls in a gap longer than ``max_gap``."""
    j = int(np.searchsorted(ts, tq))
    if j <= 0 or j >= len(ts):
        if j < len(ts) and ts[j] == tq:
            return np.array([j]), np.array([1.0])
        return None
    if ts[j] - ts[j - 1] > max_gap:
        return None
    lo, hi = max(0, j - 2), min(len(ts), j + 2)
    idx = np.arange(lo, hi)
    x = ts[idx]
    w = np.ones(len(idx))
    for a in range(len(idx)):
        for b in range(len(idx)):
            if a != b:
                w[a] *= (tq - x[b]) / (x[a] - x[b])
    return idx, w


def _first_crossing_time(t, f, level, after):
    """First time ≥ ``after`` at which samples f reach ``level`` from below (linear); index k of the
    first sample at or above the level, or None."""
    idx = np.flatnonzero((f >= level) & (t >= after))
    if idx.size == 0:
        return None
    k = int(idx[0])
    if k == 0 or t[k - 1] < after:
        return float(t[k]), k
    f0, f1 = f[k - 1], f[k]
    a = (level - f0) / (f1 - f0) if f1 != f0 else 1.0
    return float(t[k - 1] + a * (t[k] - t[k - 1])), k


def fit_circle(x, y) -> tuple[np.ndarray, np.ndarray, float]:
    """Geometric least-squares circle (Kåsa algebraic start, Gauss–Newton on the orthogonal distances).

    Returns (cx, cy, R), the 3×3 covariance s²(JᵀJ)⁻¹ with s² = RSS/(n − 3), and the residual RMS.
    """
    x = np.asarray(x, float)
    y = np.asarray(y, float)
    A = np.column_stack([x, y, np.ones_like(x)])
    sol, *_ = np.linalg.lstsq(A, x ** 2 + y ** 2, rcond=None)
    cx, cy = sol[0] / 2, sol[1] / 2
    R = math.sqrt(max(sol[2] + cx ** 2 + cy ** 2, 1e-12))
    p = np.array([cx, cy, R])
    for _ in range(50):
        dx, dy = x - p[0], y - p[1]
        d = np.hypot(dx, dy)
        res = d - p[2]
        J = np.column_stack([-dx / d, -dy / d, -np.ones_like(d)])
        step, *_ = np.linalg.lstsq(J, -res, rcond=None)
        p = p + step
        if np.max(np.abs(step)) < 1e-10 * max(1.0, abs(p[2])):
            break
    dx, dy = x - p[0], y - p[1]
    d = np.hypot(dx, dy)
    res = d - p[2]
    J = np.column_stack([-dx / d, -dy / d, -np.ones_like(d)])
    dof = max(len(x) - 3, 1)
    s2 = float(res @ res) / dof
    cov = s2 * np.linalg.pinv(J.T @ J)
    p[2] = abs(p[2])
    return p, cov, math.sqrt(s2)


def _circle_radius_weights(x, y, p) -> tuple[np.ndarray, np.ndarray]:
    """Weights h with δR = Σ h_k δρ_k for small radial errors δρ_k of the points (x_k, y_k) about the
    fitted circle p = (cx, cy, R) (row R of the Gauss–Newton pseudo-inverse), and the points' polar
    angles about the centre [rad]."""
    dx, dy = np.asarray(x, float) - p[0], np.asarray(y, float) - p[1]
    d = np.hypot(dx, dy)
    J = np.column_stack([-dx / d, -dy / d, -np.ones_like(d)])
    H = np.linalg.pinv(J.T @ J) @ J.T
    return -H[2], np.arctan2(dy, dx)


def _circ_mean(a: np.ndarray) -> tuple[float, float]:
    """Circular mean of angles [rad] and its standard error (lag-1 corrected)."""
    c, s = np.mean(np.cos(a)), np.mean(np.sin(a))
    m = math.atan2(s, c)
    dev = np.angle(np.exp(1j * (a - m)))
    se = float(np.std(dev, ddof=1) / math.sqrt(len(a))) * _ar1_inflation(dev) if len(a) > 1 else math.inf
    return m, se


# ------------------------------------------------------------------------------------- data classes
@dataclasses.dataclass(frozen=True)
class SteadyWindow:
    """Steady part of a turn. ``steady`` False: the rate of turn never settled within ``tol``."""

    t_start: float
    t_end: float
    rate: Estimate  # steady rate of turn [rad/s], signed (+ = starboard)
    steady: bool
    span: float  # heading change covered by the steady part [rad]
    note: str = ""


@dataclasses.dataclass(frozen=True)
class Drift:
    """Drift velocity over ground [m/s] with covariance; ``method`` 'pairs', 'circle' or 'given'."""

    north: Estimate
    east: Estimate
    cov: np.ndarray
    method: str
    n_pairs: int = 0
    detail: dict = dataclasses.field(default_factory=dict)

    @property
    def vector(self) -> np.ndarray:
        return np.array([self.north.value, self.east.value])

    def to_dict(self) -> dict:
        return {"north": self.north.to_dict(), "east": self.east.to_dict(), "method": self.method,
                "n_pairs": self.n_pairs, **{k: v for k, v in self.detail.items()
                                            if not isinstance(v, np.ndarray)}}


def _as_drift(drift) -> Drift:
    if isinstance(drift, Drift):
        return drift
    vn, ve = drift
    if isinstance(vn, Estimate):
        cov = np.diag([vn.std ** 2, ve.std ** 2])
        return Drift(vn, ve, cov, "given")
    return Drift(Estimate(float(vn), 0.0), Estimate(float(ve), 0.0), np.zeros((2, 2)), "given")


# ---------------------------------------------------------------------------------- steady window
def steady_window(t_heading, heading, t_execute: float, *, tol: float = 0.02,
                  rate_window_deg: float = 20.0, min_window_s: float = 10.0, ref_deg: float = 90.0,
                  min_span_deg: float = 90.0, sigma_heading: float | None = None) -> SteadyWindow:
    """Steady part of a turn from the gyro heading [s, rad] after EXECUTE [s].

    Local rates r_k: OLS slopes over sliding windows of ±½·``rate_window_deg`` of heading (at least
    ``min_window_s``). Reference r_ref: OLS slope over the last ``ref_deg`` of heading change. The
    steady part starts at the centre of the first window after which all windows satisfy
    |r_k − r_ref| ≤ max(tol·|r_ref|, z·SE(r_k)), and runs to the end of the record; SE(r_k) from the
    gyro noise (:func:`noise_sigma`), z = Φ⁻¹(1 − 0.005/m) for m independent windows. Flagged not
    steady when it spans less than ``min_span_deg`` of heading. The returned rate is the OLS slope
    over the steady part with its (lag-1 corrected) SE.
    """
    th, psi = _clean(t_heading, heading)
    psi = np.unwrap(psi)
    m = th >= t_execute
    th, psi = th[m], psi[m]
    if len(th) < 10:
        raise ValueError("too few heading samples after EXECUTE")
    s = 1.0 if psi[-1] >= psi[0] else -1.0
    dpsi = s * (psi - psi[0])
    sig = sigma_heading if sigma_heading is not None else noise_sigma(th, psi)[0]
    total = float(dpsi[-1])
    ref = min(math.radians(ref_deg), 0.5 * total)
    mref = dpsi >= total - ref
    r_ref = _ols_line(th[mref], psi[mref])[0]
    if r_ref * s <= 0:
        return SteadyWindow(float(th[-1]), float(th[-1]), Estimate(float(r_ref), math.inf), False, 0.0,
                            "no turn in the record")
    hw = max(0.5 * min_window_s, 0.5 * math.radians(rate_window_deg) / abs(r_ref))
    # sliding OLS slopes by prefix sums (windows by time)
    lo = np.searchsorted(th, th - hw, "left")
    hi = np.searchsorted(th, th + hw, "right")
    c = np.concatenate([[0.0], np.cumsum(np.ones_like(th))])
    ct = np.concatenate([[0.0], np.cumsum(th - th[0])])
    ctt = np.concatenate([[0.0], np.cumsum((th - th[0]) ** 2)])
    cy = np.concatenate([[0.0], np.cumsum(psi - psi[0])])
    cty = np.concatenate([[0.0], np.cumsum((th - th[0]) * (psi - psi[0]))])
    n = c[hi] - c[lo]
    St, Stt, Sy, Sty = ct[hi] - ct[lo], ctt[hi] - ctt[lo], cy[hi] - cy[lo], cty[hi] - cty[lo]
    sxx = Stt - St ** 2 / np.maximum(n, 1)
    valid = (n >= 4) & (sxx > 0) & (th - hw >= th[0]) & (th + hw <= th[-1])
    rk = np.where(valid, (Sty - St * Sy / np.maximum(n, 1)) / np.where(sxx > 0, sxx, 1), np.nan)
    sek = np.where(valid, sig / np.sqrt(np.where(sxx > 0, sxx, 1)), np.nan)
    # noise allowance: Bonferroni over the m independent windows of the record (1 % false alarm)
    m_ind = max(1.0, (th[-1] - th[0]) / (2 * hw))
    z_crit = float(stats.norm.ppf(1 - 0.01 / (2 * m_ind)))
    ok = np.abs(rk - r_ref) <= np.maximum(tol * abs(r_ref), z_crit * sek)
    bad = np.flatnonzero(valid & ~ok)
    vidx = np.flatnonzero(valid)
    if vidx.size == 0:
        return SteadyWindow(float(th[-1]), float(th[-1]), Estimate(float(r_ref), math.inf), False, 0.0,
                            "record too short for a rate window")
    k0 = int(vidx[0]) if bad.size == 0 else int(bad[-1]) + 1
    if k0 >= len(th):
        k0 = len(th) - 1
    t0 = float(th[k0])
    ms = th >= t0
    span = float(dpsi[-1] - dpsi[k0])
    if np.count_nonzero(ms) >= 5:
        b, se, *_, dof = _ols_line(th[ms], psi[ms])
        rate = Estimate(b, se, dof)
    else:
        rate = Estimate(float(r_ref), math.inf)
    steady = span >= math.radians(min_span_deg)
    note = "" if steady else (f"rate of turn not steady within {100 * tol:.0f} % over at least "
                              f"{min_span_deg:.0f} deg of heading (steady part spans "
                              f"{math.degrees(span):.0f} deg)")
    return SteadyWindow(t0, float(th[-1]), rate, steady, span, note)


# ------------------------------------------------------------------------------------------- drift
def drift_from_pairs(t, north, east, t_start: float, t_end: float, period: float,
                     period_std: float = 0.0, *, min_pairs: int = 5, fix_errors=()) -> Drift:
    """Drift velocity [m/s] from positions one steady turning period [s] (360° of heading) apart.

    Pairs (t_i, t_i + period) for every tracking sample t_i ∈ [t_start, t_end − period]; the partner
    position is a 4-point Lagrange interpolation. Returns the mean of the pair drifts with the
    pair-scatter standard error described in the module docstring (``detail['se_batch_*']`` holds a
    batch-means SE over ≤ 10 blocks of consecutive pairs as a diagnostic). ``fix_errors``: the
    tracking's time-correlated errors per axis, (sd [m], τ [s]) pairs: a wander slower than the
    period moves every pair alike, so the pair scatter cannot see it; its variance in the mean drift
    is propagated through the same sample weights (:func:`vtrials.reduce.series.correlated_variance`).
    """
    t, n_, e_ = _clean(t, north, east)
    T = float(period)
    dt_med = float(np.median(np.diff(t)))
    max_gap = 3.0 * dt_med
    first = np.flatnonzero((t >= t_start) & (t <= t_end - T))
    rows = []
    for i in first:
        lw = _lagrange_weights(t, t[i] + T, max_gap)
        if lw is None or t[i] + T > t_end + 1e-9:
            continue
        idx, w = lw
        if np.any(idx == i):
            continue
        rows.append((i, idx, w))
    npair = len(rows)
    if npair < min_pairs:
        raise ValueError(f"only {npair} drift pairs in the steady part (need {min_pairs}); the steady "
                         "part must span more than 360 deg of heading")
    a = np.zeros(len(t))
    dN = np.empty(npair)
    dE = np.empty(npair)
    cmult = np.empty(npair)
    for k, (i, idx, w) in enumerate(rows):
        dN[k] = (w @ n_[idx] - n_[i]) / T
        dE[k] = (w @ e_[idx] - e_[i]) / T
        cmult[k] = 1.0 + float(w @ w)
        a[i] -= 1.0 / (npair * T)
        a[idx] += w / (npair * T)
    DN, DE = float(dN.mean()), float(dE.mean())
    sum_a2 = float(a @ a)
    # per-axis noise variance implied by the pair scatter
    s2N = T ** 2 * float(np.sum((dN - DN) ** 2)) / float(np.sum(cmult)) * npair / (npair - 1)
    s2E = T ** 2 * float(np.sum((dE - DE) ** 2)) / float(np.sum(cmult)) * npair / (npair - 1)
    s2c = correlated_variance(t, a, fix_errors)
    cov = np.diag([s2N * sum_a2 + s2c, s2E * sum_a2 + s2c])
    # period error: mean water velocity at the partner points
    t1, t2 = t[rows[0][0]] + T, t[rows[-1][0]] + T
    if t2 - t1 > 0 and period_std > 0:
        i1, i2 = np.searchsorted(t, t1), min(np.searchsorted(t, t2), len(t) - 1)
        vbar = np.array([(n_[i2] - n_[i1]) / (t[i2] - t[i1]) - DN, (e_[i2] - e_[i1]) / (t[i2] - t[i1]) - DE])
        cov = cov + (period_std / T) ** 2 * np.outer(vbar, vbar)
    # batch-means diagnostic
    nb = min(10, npair // 3)
    detail = {"period_s": T, "period_std_s": period_std, "sigma_pair_north_m": math.sqrt(s2N),
              "sigma_pair_east_m": math.sqrt(s2E), "pair_t_start": float(t[rows[0][0]]),
              "pair_t_end": float(t[rows[-1][0]])}
    if nb >= 3:
        bN = np.array([b.mean() for b in np.array_split(dN, nb)])
        bE = np.array([b.mean() for b in np.array_split(dE, nb)])
        detail["se_batch_north"] = float(bN.std(ddof=1) / math.sqrt(nb))
        detail["se_batch_east"] = float(bE.std(ddof=1) / math.sqrt(nb))
    dof = npair - 1
    return Drift(Estimate(DN, math.sqrt(cov[0, 0]), dof), Estimate(DE, math.sqrt(cov[1, 1]), dof), cov,
                 "pairs", npair, detail)


def drift_from_heading_pairs(t, north, east, t_heading, heading, t_start: float, t_end: float, *,
                             min_pairs: int = 5) -> Drift:
    """Variant of :func:`drift_from_pairs` that pairs positions at gyro headings exactly 360° apart
    (each tracking sample's heading interpolated from the gyro, its partner's time from the inverse of
    the unwrapped heading). Does not assume a constant rate, but carries the gyro noise into every
    pair; SE by batch means over ≤ 10 blocks of consecutive pairs (dof = blocks − 1)."""
    t, n_, e_ = _clean(t, north, east)
    th, psi = _clean(t_heading, heading)
    psi = np.unwrap(psi)
    s = 1.0 if psi[-1] >= psi[0] else -1.0
    f = s * psi
    # smoothed heading for the inversion: 11-sample moving means of (t, ψ) — unbiased for a locally
    # linear heading (a running maximum of the raw gyro would lead it by ~σ); then strictly monotone
    k = 11 if len(th) > 40 else 3
    ker = np.ones(k) / k
    ts_, fs_ = np.convolve(th, ker, "valid"), np.convolve(f, ker, "valid")
    keep = np.concatenate([[True], np.diff(np.maximum.accumulate(fs_)) > 0]) & (fs_ >= np.maximum.accumulate(fs_))
    fi, ti = fs_[keep], ts_[keep]
    max_gap = 3.0 * float(np.median(np.diff(t)))
    dN, dE = [], []
    for i in np.flatnonzero((t >= t_start) & (t <= t_end)):
        h1 = np.interp(t[i], th, f)
        h2 = h1 + TWO_PI
        if h2 > fi[-1]:
            break
        t2 = float(np.interp(h2, fi, ti))
        if t2 > t_end:
            break
        lw = _lagrange_weights(t, t2, max_gap)
        if lw is None:
            continue
        idx, w = lw
        T = t2 - t[i]
        dN.append((w @ n_[idx] - n_[i]) / T)
        dE.append((w @ e_[idx] - e_[i]) / T)
    npair = len(dN)
    if npair < max(min_pairs, 9):
        raise ValueError(f"only {npair} heading pairs in the steady part")
    dN, dE = np.array(dN), np.array(dE)
    nb = min(10, npair // 3)
    bN = np.array([b.mean() for b in np.array_split(dN, nb)])
    bE = np.array([b.mean() for b in np.array_split(dE, nb)])
    sN, sE = bN.std(ddof=1) / math.sqrt(nb), bE.std(ddof=1) / math.sqrt(nb)
    return Drift(Estimate(float(dN.mean()), float(sN), nb - 1), Estimate(float(dE.mean()), float(sE), nb - 1),
                 np.diag([sN ** 2, sE ** 2]), "heading_pairs", npair)


def _moving_circle_model(p, tau):
    cN, cE, vN, vE, A, B, w = p
    cw, sw = np.cos(w * tau), np.sin(w * tau)
    N = cN + vN * tau + A * cw - B * sw
    E = cE + vE * tau + B * cw + A * sw
    return N, E


def drift_from_circle_fit(t, north, east, t_start: float, t_end: float, omega0: float) -> Drift:
    """Drift [m/s] from a least-squares circle whose centre translates at constant velocity.

    Model over the steady part, τ = t − t_mid: N = c_N + v_N τ + R cos(φ₀ + ωτ),
    E = c_E + v_E τ + R sin(φ₀ + ωτ) with the phase rate ω free (started at ``omega0`` [rad/s], the
    gyro rate; sign: the track rotates with the heading). Seven parameters by Levenberg–Marquardt on
    the stacked north/east residuals; covariance s²(JᵀJ)⁻¹ with s² = RSS/(2n − 7). ``detail`` holds the
    fitted radius [m] and its SE.
    """
    t, n_, e_ = _clean(t, north, east)
    m = (t >= t_start) & (t <= t_end)
    t, n_, e_ = t[m], n_[m], e_[m]
    if len(t) < 12:
        raise ValueError("too few samples for the moving-circle fit")
    tm = 0.5 * (t[0] + t[-1])
    tau = t - tm
    w0 = float(omega0)

    def linear_part(w):
        cw, sw = np.cos(w * tau), np.sin(w * tau)
        z = np.zeros_like(tau)
        o = np.ones_like(tau)
        X = np.vstack([np.column_stack([o, z, tau, z, cw, -sw]), np.column_stack([z, o, z, tau, sw, cw])])
        yv = np.concatenate([n_, e_])
        beta, *_ = np.linalg.lstsq(X, yv, rcond=None)
        r = yv - X @ beta
        return beta, float(r @ r)

    # variable projection over ω for a robust start
    ws = w0 * np.linspace(0.9, 1.1, 41)
    best = min(ws, key=lambda w: linear_part(w)[1])
    res1 = optimize.minimize_scalar(lambda w: linear_part(w)[1],
                                    bracket=(best - 0.005 * abs(w0), best, best + 0.005 * abs(w0)))
    wbest = float(res1.x)
    beta, _ = linear_part(wbest)
    p0 = np.concatenate([beta, [wbest]])

    def resid(p):
        N, E = _moving_circle_model(p, tau)
        return np.concatenate([N - n_, E - e_])

    sol = optimize.least_squares(resid, p0, method="lm", x_scale="jac")
    J = sol.jac
    dof = 2 * len(t) - 7
    s2 = float(sol.fun @ sol.fun) / dof
    cov = s2 * np.linalg.pinv(J.T @ J)
    p = sol.x
    R = math.hypot(p[4], p[5])
    gR = np.array([0, 0, 0, 0, p[4] / R, p[5] / R, 0])
    sR = math.sqrt(float(gR @ cov @ gR))
    c2 = cov[2:4, 2:4]
    return Drift(Estimate(float(p[2]), math.sqrt(c2[0, 0]), dof), Estimate(float(p[3]), math.sqrt(c2[1, 1]), dof),
                 c2, "circle", 0, {"radius_m": R, "radius_std_m": sR, "omega_rad_s": float(p[6]),
                                   "residual_rms_m": math.sqrt(s2)})


def estimate_drift(t, north, east, t_heading, heading, t_execute: float, *, method: str = "auto",
                   steady: SteadyWindow | None = None, fix_errors=(), **steady_kw) -> tuple[Drift, SteadyWindow]:
    """Drift of a tactical circle. ``method``: 'pairs' (seed 002, used by the report), 'heading_pairs',
    'circle' (moving-centre fit) or 'auto' (pairs; the circle fit when the steady part has fewer than
    5 pairs). Returns the drift and the steady window used."""
    sw = steady or steady_window(t_heading, heading, t_execute, **steady_kw)
    r = sw.rate
    T = TWO_PI / abs(r.value)
    T_std = TWO_PI * r.std / r.value ** 2 if math.isfinite(r.std) else 0.0
    if method in ("pairs", "auto"):
        try:
            return drift_from_pairs(t, north, east, sw.t_start, sw.t_end, T, T_std, fix_errors=fix_errors), sw
        except ValueError:
            if method == "pairs":
                raise
    if method == "heading_pairs":
        return drift_from_heading_pairs(t, north, east, t_heading, heading, sw.t_start, sw.t_end), sw
    return drift_from_circle_fit(t, north, east, sw.t_start, sw.t_end, r.value), sw


def drift_corrected_track(t, north, east, t_execute: float, drift) -> tuple[np.ndarray, np.ndarray]:
    """Recorded track [m] minus drift·(t − t_execute); ``drift`` is a :class:`Drift` or (v_N, v_E) [m/s]
    (floats or Estimates). Arrays keep the input order and length."""
    d = _as_drift(drift).vector
    t = np.asarray(t, float)
    dt = t - t_execute
    return np.asarray(north, float) - d[0] * dt, np.asarray(east, float) - d[1] * dt


# ---------------------------------------------------------------------------------- turning metrics
@dataclasses.dataclass
class TurningResult:
    """Reduced turning-circle metrics (SI: m, s, rad, m/s, rad/s). None where the record does not
    reach the mark. ``turn_side`` +1 starboard (heading increasing), −1 port."""

    turn_side: int
    approach_course: Estimate
    approach_speed: Estimate  # along ψ₀ through the water (approach ground velocity − drift) [m/s]
    steady: SteadyWindow
    drift: Drift | None
    advance: Estimate | None = None
    transfer: Estimate | None = None
    tactical_diameter: Estimate | None = None
    time_to_90: Estimate | None = None
    time_to_180: Estimate | None = None
    time_to_10: Estimate | None = None
    distance_to_10: Estimate | None = None
    steady_diameter: Estimate | None = None
    steady_speed: Estimate | None = None
    steady_rate: Estimate | None = None
    drift_angle: Estimate | None = None
    heel_steady: Estimate | None = None
    heel_max: Estimate | None = None
    rudder_steady: Estimate | None = None
    sigma_position: tuple[float, float] = (float("nan"), float("nan"))
    sigma_heading: float = float("nan")
    notes: list = dataclasses.field(default_factory=list)

    def to_dict(self) -> dict:
        out = {}
        for f in dataclasses.fields(self):
            v = getattr(self, f.name)
            if isinstance(v, (Estimate, Drift)):
                out[f.name] = v.to_dict()
            elif isinstance(v, SteadyWindow):
                out[f.name] = {"t_start": v.t_start, "t_end": v.t_end, "steady": v.steady,
                               "span_rad": v.span, "rate": v.rate.to_dict(), "note": v.note}
            else:
                out[f.name] = v
        return out


def _mark_time(th, psi_rel, level, after, sig, rate_guess):
    """Time at which the heading change psi_rel [rad] first reaches level, with its SE from a local
    quadratic fit (window ±max(3 samples, 4°/rate))."""
    c = _first_crossing_time(th, psi_rel, level, after)
    if c is None:
        return None
    tc, k = c
    dt_med = float(np.median(np.diff(th)))
    hw = max(3 * dt_med, math.radians(4.0) / max(abs(rate_guess), 1e-6))
    for _ in range(3):  # Newton refinement on the local quadratic
        m = np.abs(th - tc) <= hw
        tt, yy = th[m], psi_rel[m]
        if len(tt) < 4:
            break
        x = (tt - tc) / hw
        A = np.vander(x, 3, increasing=True)
        Ainv = np.linalg.pinv(A.T @ A)
        coef = Ainv @ A.T @ yy
        slope = coef[1] / hw
        if slope <= 0:
            break
        step = (level - coef[0]) / slope
        tc = tc + step
        if abs(step) < 1e-6:
            break
    m = np.abs(th - tc) <= hw
    tt, yy = th[m], psi_rel[m]
    x = (tt - tc) / hw
    A = np.vander(x, 3, increasing=True)
    Ainv = np.linalg.pinv(A.T @ A)
    coef = Ainv @ A.T @ yy
    slope = coef[1] / hw
    var_val = sig ** 2 * Ainv[0, 0]
    st = math.sqrt(var_val) / max(abs(slope), 1e-12)
    return float(tc), float(st), float(slope)


@dataclasses.dataclass(frozen=True)
class SteadyLoop:
    """The loop of heading the steady-turn values come from (:func:`steady_loop`): its start and end
    times [s], the heading change over it [rad] and the standard error of its duration [s]."""

    t_start: float
    t_end: float
    heading_change: float
    duration_std: float
    full: bool  # True: 360° → 720°; False: the last 360° before FINEX (turn shorter than 720°)
    start_std: float = 0.0  # SE of each end's time [s] (heading noise at the mark; the gyro's wander
    end_std: float = 0.0  # between the ends is given to the end)


def steady_loop(t_heading, heading, t_execute: float, t_finex: float | None = None, *,
                sigma_heading: float | None = None, gyro_drift: tuple[float, float] = (0.0, 1.0),
                pre_s: float = 10.0) -> SteadyLoop | None:
    """The steady loop of a turn from the gyro [s, rad]: 360° → 720° of heading change after EXECUTE,
    or the last 360° before FINEX when the turn ends short of 720° (None below 450°: the loop would
    start before 90°). Heading change counted from the heading at EXECUTE (local line through the
    ``pre_s`` seconds of gyro before it), as the reference does (:func:`vtrials.truth.metrics.turning`).

    The loop's ends are heading-mark times (:func:`_mark_time`); ``duration_std`` combines their
    SEs with the gyro's slow wander between them (Gauss–Markov (σ_d, τ): a heading error difference of
    variance 2σ_d²(1 − e^{−T/τ}), divided by |r| to a time)."""
    th, psi = _clean(t_heading, heading)
    psi = np.unwrap(psi)
    t_finex = float(th[-1]) if t_finex is None else float(t_finex)
    sig = sigma_heading if sigma_heading is not None else noise_sigma(th, psi)[0]
    pre = (th >= t_execute - pre_s) & (th <= t_execute)
    if np.count_nonzero(pre) < 3:
        return None
    psi_x = _local_poly(th[pre], psi[pre], t_execute, pre_s, 1, sig)[0]
    m = (th >= t_execute) & (th <= t_finex + 1e-9)
    th, psi = th[m], psi[m]
    if th.size < 20:
        return None
    side = 1.0 if psi[-1] >= psi_x else -1.0
    d = side * (psi - psi_x)
    total = float(d[-1])
    full = total >= 2 * TWO_PI
    lo, hi = (TWO_PI, 2 * TWO_PI) if full else (total - TWO_PI, total)
    if lo < math.radians(90.0):
        return None
    r_guess = total / max(float(th[-1] - th[0]), 1e-9)
    a = _mark_time(th, d, lo, t_execute, sig, r_guess)
    if a is None:
        return None
    if full:
        b = _mark_time(th, d, hi, a[0], sig, r_guess)
        if b is None:
            return None
        t_hi, se_hi, slope = b
    else:  # the loop ends at the last sample: its heading's noise moves the start mark instead
        t_hi, se_hi, slope = float(th[-1]), sig / max(a[2], 1e-12), a[2]
    T = t_hi - a[0]
    sd_d, tau = gyro_drift
    wander = 2.0 * sd_d ** 2 * (1.0 - math.exp(-T / tau)) if sd_d > 0 and tau > 0 else 0.0
    sT = math.sqrt(a[1] ** 2 + se_hi ** 2 + wander / max(abs(slope), 1e-12) ** 2)
    return SteadyLoop(float(a[0]), float(t_hi), float(hi - lo), sT, bool(full), float(a[1]),
                      math.sqrt(se_hi ** 2 + wander / max(abs(slope), 1e-12) ** 2))


def _local_poly_weights(t, tq, half_width, deg, min_pts):
    """Indices and weights w of the least-squares polynomial of degree ``deg`` through the samples
    within ±half_width of tq (widened until it holds ``min_pts``): value at tq = w · y[idx]; also the
    slope weights."""
    hw = half_width
    for _ in range(60):
        idx = np.flatnonzero(np.abs(t - tq) <= hw)
        if idx.size >= min_pts:
            break
        hw *= 1.3
    if idx.size < deg + 1:
        raise ValueError("not enough samples around t = %.2f s" % tq)
    x = (t[idx] - tq) / hw
    A = np.vander(x, deg + 1, increasing=True)
    H = np.linalg.pinv(A.T @ A) @ A.T
    return idx, H[0], H[1] / hw


def drift_over_loop(t, north, east, loop: SteadyLoop, *, mark_window_deg: float = 10.0,
                    sigma: tuple[float, float] | None = None, fix_errors=()) -> Drift:
    """Drift [m/s] of one steady loop: the displacement of the track between the loop's two ends (the
    same heading, 360° apart) over the loop's duration — the definition the references use for the
    loop drift (:func:`vtrials.truth.metrics.turning`, 360° → 720° of heading change: the wind's
    leeway of the circling ship plus the current, which ITTC 7.5-04-02-01 removes loop by loop).

    Why not the mean of all 360°-apart pairs over the steady part (:func:`drift_from_pairs`): on the
    patrol vessel the time per revolution is steady within 2 % from EXECUTE on, so the pairs start in
    the first loop, whose transient (the ship still slowing and the circle still shrinking) carries
    the track forward along the approach course: those drifts led the 360°–720° loop drift by
    0.008 m/s along the approach course (20 replicates of the tactical day; the day's drift was then
    70 % covered).

    The positions at the ends: local cubics over ±``mark_window_deg`` of heading (at least 8 fixes),
    linear in the fixes, so the variance is exact for white noise σ (per axis; default from the
    residuals, :func:`noise_sigma`) and for the tracking's time-correlated errors ``fix_errors``
    ((sd [m], τ [s]) pairs per axis, :func:`vtrials.reduce.series.correlated_variance`); the ends'
    time errors (``loop.start_std``, ``loop.end_std``) move each end along its velocity."""
    t, n_, e_ = _clean(t, north, east)
    if sigma is None:
        sigma = (noise_sigma(t, n_)[0], noise_sigma(t, e_)[0])
    T = loop.t_end - loop.t_start
    if not T > 0:
        raise ValueError("loop of zero duration")
    r = loop.heading_change / T
    hw = max(4 * float(np.median(np.diff(t))), math.radians(mark_window_deg) / max(abs(r), 1e-6))
    a = np.zeros(t.size)
    vel = []
    # the loop may end at the last gyro sample, up to a fix interval after the last fix: the local
    # cubic reaches it (two intervals at most)
    slack = 2.0 * float(np.median(np.diff(t)))
    for tq, sgn in ((loop.t_start, -1.0), (loop.t_end, 1.0)):
        if tq < t[0] - slack or tq > t[-1] + slack:
            raise ValueError("no tracking data at an end of the loop")
        idx, w0, w1 = _local_poly_weights(t, tq, hw, 3, 8)
        a[idx] += sgn * w0 / T
        vel.append(np.array([w1 @ n_[idx], w1 @ e_[idx]]))
    d = np.array([a @ n_, a @ e_])
    var_w = np.array(sigma) ** 2 * float(a @ a)
    var_c = correlated_variance(t, a, fix_errors)
    cov_t = (loop.start_std ** 2 * np.outer(vel[0], vel[0]) + loop.end_std ** 2 * np.outer(vel[1], vel[1])) / T ** 2
    cov = np.diag(var_w + var_c) + cov_t
    # the fixes' weights (for a functional that also uses these fixes: the loop's circle)
    return Drift(Estimate(float(d[0]), math.sqrt(cov[0, 0])), Estimate(float(d[1]), math.sqrt(cov[1, 1])), cov,
                 "loop", 0, {"loop_s": [loop.t_start, loop.t_end], "full_loop": loop.full, "weights": a,
                             "t_first": float(t[0]), "cov_timing": cov_t})


def turning_metrics(t, north, east, heading, t_execute: float, *, t_heading=None, roll=None, t_roll=None,
                    rudder=None, t_rudder=None, drift="auto", approach_s: float = 60.0,
                    steady: SteadyWindow | None = None, steady_tol: float = 0.02,
                    min_span_deg: float = 90.0, mark_window_deg: float = 10.0,
                    sigma_fix: float = 0.0, current=None, roll_bias: float = 0.0, fix_errors=(),
                    timing_sd: float = 0.0, loop_drift=None, t_finex: float | None = None,
                    gyro_drift: tuple[float, float] = (0.0, 1.0), lever_arm=None,
                    heading_sd: float = 0.0) -> TurningResult:
    """Turning-circle metrics from recorded channels (see the module docstring for definitions).

    Parameters: ``t, north, east`` tracking [s, m, m]; ``heading`` gyro [rad] on ``t_heading`` (the
    tracking time stamps if None); ``t_execute`` [s]; ``roll``/``t_roll`` [rad, s] and
    ``rudder``/``t_rudder`` [rad, s] optional; ``drift``: 'auto' / 'pairs' / 'heading_pairs' /
    'circle' (estimated from this record), 'loop' (the steady loop's own drift,
    :func:`drift_over_loop`; 'auto' when the turn has no steady loop), a :class:`Drift` or a (v_N, v_E) pair [m/s] (e.g. from
    :func:`vtrials.reduce.reach.interpolate_drift`), or None for no correction; ``approach_s`` [s]
    approach window before EXECUTE; ``sigma_fix`` [m] the tracking system's stated accuracy per axis,
    whose slowly varying part the residual-based σ_p cannot see: a mark's position relative to
    EXECUTE gets 2 σ_fix² per axis (the two fixes' errors taken independent) unless ``fix_errors``
    gives the error's time correlation (then the variance of its change over the time from EXECUTE to the
    mark). ``current``: (vector
    (2,) north/east [m/s], covariance (2, 2)) of the current, for the approach speed through the water
    (else the drift is taken for it); ``roll_bias`` [rad] the roll sensor's stated zero accuracy (1σ),
    added to the heel estimates' variance (it is common to the record: averaging does not reduce it);
    ``fix_errors`` the tracking's time-correlated errors per axis, (sd [m], τ [s]) pairs, for the
    approach velocity's variance (:func:`vtrials.reduce.series.slope_variance`); ``timing_sd`` [s] the
    standard uncertainty of each logger's time stamps against the run log's (clock offset and drift):
    a mark's time against the fixes carries two of them, the EXECUTE point one. ``loop_drift``: the
    circle's own drift (a :class:`Drift` or (v_N, v_E) [m/s]) the steady loop is closed with (default:
    ``drift``); ``t_finex`` [s] the end of the turn (default: the last gyro sample); ``gyro_drift``
    the gyro's slow wander (σ [rad], τ [s]) for the steady loop's duration (:func:`steady_loop`).
    ``lever_arm`` (x fwd, y stbd [m]) the antenna's offset the fixes were moved by along the gyro
    heading, and ``heading_sd`` [rad] the heading's slow error (bias and wander) that turns it: the
    steady diameter carries the radial part of that displacement.
    """
    notes: list[str] = []
    tp, N, E = _clean(t, north, east)
    th_in = t if t_heading is None else t_heading
    th, psi = _clean(th_in, heading)
    psi = np.unwrap(psi)
    sigN, _ = noise_sigma(tp, N)
    sigE, _ = noise_sigma(tp, E)
    sig_psi, _ = noise_sigma(th, psi)

    # approach: course (gyro) and EXECUTE position / velocity (line fit)
    ma = (th >= t_execute - approach_s) & (th <= t_execute)
    if np.count_nonzero(ma) < 3:
        raise ValueError("no approach heading data before EXECUTE")
    psi0, psi0_se = _circ_mean(psi[ma])
    # the references measure from the heading at the instant of EXECUTE; the approach course is the
    # mean over the approach, so the ship's yaw about it (the autopilot in gusts: its scatter beyond the
    # gyro's own noise) is an error of the axes and of the heading marks alike
    dev0 = np.angle(np.exp(1j * (psi[ma] - psi0)))
    yaw_var = max(float(np.var(dev0, ddof=1)) - sig_psi ** 2, 0.0) if dev0.size > 2 else 0.0
    # the axes also turn with the gyro's slow error (bias and wander: ``heading_sd``), which the
    # heading-change marks do not see (a turn of 0.17° moves a 900-m advance's transfer by 2.7 m)
    psi_axis_sd = math.sqrt(psi0_se ** 2 + yaw_var + heading_sd ** 2)
    psi_mark_sd = math.sqrt(psi0_se ** 2 + yaw_var)
    psi0 = psi0 + TWO_PI * round((float(np.mean(psi[ma])) - psi0) / TWO_PI)  # same branch as record
    mp = (tp >= t_execute - approach_s) & (tp <= t_execute)
    if np.count_nonzero(mp) < 3:
        raise ValueError("no approach positions before EXECUTE")
    bN, sbN, aN, saN, tmN, _ = _ols_line(tp[mp], N[mp])
    bE, sbE, aE, saE, tmE, _ = _ols_line(tp[mp], E[mp])
    # EXECUTE position and its variance (line evaluated at t_execute)
    xN = tp[mp] - tmN
    sxx = float(xN @ xN)
    nA = np.count_nonzero(mp)
    dte = t_execute - tmN
    PeN, PeE = aN + bN * dte, aE + bE * dte
    var_PeN = sigN ** 2 * (1.0 / nA + dte ** 2 / sxx)
    var_PeE = sigE ** 2 * (1.0 / nA + dte ** 2 / sxx)
    u = np.array([math.cos(psi0), math.sin(psi0)])
    nvec = np.array([-math.sin(psi0), math.cos(psi0)])
    v_app = np.array([bN, bE])
    var_app = (sbN * u[0]) ** 2 + (sbE * u[1]) ** 2 + slope_variance(tp[mp], fix_errors)

    # steady window and drift
    sw = steady or steady_window(th, psi, t_execute, tol=steady_tol, min_span_deg=min_span_deg,
                                 sigma_heading=sig_psi)
    if not sw.steady:
        notes.append("NOT STEADY: " + sw.note)
    side = 1 if sw.rate.value >= 0 else -1
    drift_obj: Drift | None
    loop = steady_loop(th, psi, t_execute, t_finex, sigma_heading=sig_psi, gyro_drift=gyro_drift)
    loop_d = None
    if loop is not None:
        try:
            loop_d = drift_over_loop(tp, N, E, loop, mark_window_deg=mark_window_deg, sigma=(sigN, sigE),
                                     fix_errors=fix_errors)
        except (ValueError, np.linalg.LinAlgError) as exc:
            notes.append(f"no loop drift ({exc})")
    if drift == "loop" and loop_d is not None:
        drift_obj = loop_d
        notes.append("drift over the steady loop (its ends 360 deg of heading apart)")
    elif isinstance(drift, str):
        try:
            drift_obj, _ = estimate_drift(tp, N, E, th, psi, t_execute, method="auto" if drift == "loop" else drift,
                                          steady=sw, fix_errors=fix_errors)
            if drift_obj.method == "circle" and drift == "auto":
                notes.append("drift from the moving-circle fit (steady part too short for 360-deg pairs)")
        except (ValueError, np.linalg.LinAlgError) as exc:
            drift_obj = None
            notes.append(f"drift not estimable ({exc}); track NOT drift-corrected")
    elif drift is None:
        drift_obj = None
        notes.append("track not drift-corrected (drift=None)")
    else:
        drift_obj = _as_drift(drift)
    if drift_obj is not None:
        Nc, Ec = drift_corrected_track(tp, N, E, t_execute, drift_obj)
        Sd = drift_obj.cov
    else:
        Nc, Ec = N, E
        Sd = np.zeros((2, 2))
    # approach speed through the water: ground velocity of the approach minus the current — the
    # current itself when the caller has it (``current``: (vector, covariance), e.g. from a water-track
    # log), else the drift, which on a circle also holds the wind's push on the turning ship
    if current is not None:
        c_vec, c_cov = np.asarray(current[0], float), np.asarray(current[1], float)
    elif drift_obj is not None:
        c_vec, c_cov = drift_obj.vector, Sd
    else:
        c_vec, c_cov = np.zeros(2), np.zeros((2, 2))
    v_w = v_app - c_vec
    app_speed = Estimate(float(v_w @ u), math.sqrt(var_app + float(u @ c_cov @ u)))

    res = TurningResult(turn_side=side, approach_course=Estimate(float(psi0), psi0_se),
                        approach_speed=app_speed, steady=sw, drift=drift_obj,
                        sigma_position=(sigN, sigE), sigma_heading=sig_psi, notes=notes)
    dpsi = side * (psi - psi0)
    r_guess = abs(sw.rate.value)

    def mark_fix_var(dt):
        """Variance per axis of the tracking's slowly varying error between EXECUTE and a mark dt [s]
        later: Σ 2 sd² (1 − e^{−dt/τ}) over its correlated parts when known (errors a mark's local fit
        cannot average out), else 2 σ_fix² (the two fixes' errors taken independent)."""
        if fix_errors:
            return sum(2.0 * sd ** 2 * (1.0 - math.exp(-abs(dt) / tau)) for sd, tau in fix_errors if tau > 0.0)
        return 2.0 * sigma_fix ** 2

    arm_h = math.hypot(float(lever_arm[0]), float(lever_arm[1])) if lever_arm is not None else 0.0

    def position_at(tq, t_se, dpsi_mark=0.0):
        """Corrected position at tq (local cubic over ±mark_window_deg of heading), velocity, and the
        2×2 covariance of (P(tq) − P_execute) from noise, the time SE, and drift."""
        hw = max(4 * float(np.median(np.diff(tp))), math.radians(mark_window_deg) / max(r_guess, 1e-6))
        post = tp >= t_execute  # the local fit must not straddle EXECUTE (acceleration jumps there)
        vN, sN_, varN, _, _ = _local_poly(tp[post], Nc[post], tq, hw, 3, sigN, min_pts=8)
        vE, sE_, varE, _, _ = _local_poly(tp[post], Ec[post], tq, hw, 3, sigE, min_pts=8)
        vel = np.array([sN_, sE_])
        # clocks: the mark's time (gyro) against the fixes' stamps (two loggers' errors), and the EXECUTE
        # time (run log) against the fixes' (the EXECUTE point moves along the approach velocity)
        C = np.diag([varN + var_PeN, varE + var_PeE]) + (t_se ** 2 + 2.0 * timing_sd ** 2) * np.outer(vel, vel) \
            + timing_sd ** 2 * np.outer(v_app, v_app) \
            + (tq - t_execute) ** 2 * Sd + mark_fix_var(tq - t_execute) * np.eye(2)
        # the fixes were moved from the antenna along the gyro heading: its slow error turns the lever
        # arm alike at EXECUTE and at the mark, which moves their difference by δψ·|arm|·2 sin(Δψ/2)
        # (direction turning with the heading: half of it per axis)
        C = C + 0.5 * (heading_sd * arm_h * 2.0 * math.sin(0.5 * dpsi_mark)) ** 2 * np.eye(2)
        return np.array([vN - PeN, vE - PeE]), vel, C

    def project(dP, C):
        along = float(dP @ u)
        across = side * float(dP @ nvec)
        va = float(u @ C @ u) + (across * psi_axis_sd) ** 2
        vc = float(nvec @ C @ nvec) + (along * psi_axis_sd) ** 2
        return along, math.sqrt(va), across, math.sqrt(vc)

    for deg_mark in (10.0, 90.0, 180.0):
        mk = _mark_time(th, dpsi, math.radians(deg_mark), t_execute, sig_psi, r_guess or 1e-3)
        if mk is None:
            notes.append(f"heading change never reached {deg_mark:.0f} deg")
            continue
        tq, tse, slope = mk
        tse = math.hypot(tse, psi_mark_sd / max(abs(slope), 1e-12))  # approach-course error shifts the mark
        if tq > tp[-1] or tq < tp[0]:
            notes.append(f"no tracking data at the {deg_mark:.0f} deg mark")
            continue
        dP, vel, C = position_at(tq, tse, math.radians(deg_mark))
        along, sa, across, sc = project(dP, C)
        tm_est = Estimate(tq - t_execute, tse)
        if deg_mark == 10.0:
            res.time_to_10 = tm_est
            # distance travelled to the 10° mark: chord EXECUTE → P(t10) of the corrected track,
            # lengthened to the circular arc with the same change of track direction θ (between the
            # approach water velocity and the local-fit velocity at t10): s = chord·(θ/2)/sin(θ/2).
            # Summing a noisy polyline instead would add a positive noise bias.
            v0 = v_app - (drift_obj.vector if drift_obj is not None else 0.0)
            cosang = float(v0 @ vel) / max(np.hypot(*v0) * np.hypot(*vel), 1e-12)
            th_tr = math.acos(min(1.0, max(-1.0, cosang)))
            chord = float(np.hypot(*dP))
            fac = (0.5 * th_tr) / math.sin(0.5 * th_tr) if th_tr > 1e-9 else 1.0
            cdir = dP / max(chord, 1e-12)
            res.distance_to_10 = Estimate(chord * fac, fac * math.sqrt(float(cdir @ C @ cdir)))
        elif deg_mark == 90.0:
            res.time_to_90 = tm_est
            res.advance = Estimate(along, sa)
            res.transfer = Estimate(across, sc)
        else:
            res.time_to_180 = tm_est
            res.tactical_diameter = Estimate(across, sc)

    # steady turn: one loop of heading (360° → 720°), the track closed by the circle's own drift;
    # circle fit, rate = heading change / time for the loop, speed = R·rate, drift angle
    if loop is None:
        res.steady_rate = sw.rate
        notes.append("no steady loop (the turn ends before 450 deg of heading change)")
    else:
        T = loop.t_end - loop.t_start
        rate = side * loop.heading_change / T
        res.steady_rate = Estimate(rate, abs(rate) * loop.duration_std / T)
        notes.append(f"steady values over the loop {'360-720 deg' if loop.full else 'last 360 deg'} "
                         f"of heading change, t = {loop.t_start:.1f}-{loop.t_end:.1f} s")
    ld = drift_obj if loop_drift is None else _as_drift(loop_drift)
    ms = (tp >= loop.t_start) & (tp <= loop.t_end) if loop is not None else np.zeros(tp.shape, bool)
    if np.count_nonzero(ms) >= 12:
        Sl = ld.cov if ld is not None else np.zeros((2, 2))
        Nl, El = drift_corrected_track(tp, N, E, t_execute, ld) if ld is not None else (N, E)
        p, cov, rms = fit_circle(Nl[ms], El[ms])
        R = float(p[2])
        # the radius is a linear functional of the radial position errors (Gauss–Newton at the
        # solution): white tracking noise σ_p and the tracking's time-correlated errors; the fit's own
        # residual scatter would also count the wind's non-circularity of the loop, which the
        # reference shares
        hR, theta_k = _circle_radius_weights(Nl[ms], El[ms], p)
        g = np.zeros(2)
        if ld is not None and np.any(Sl > 0):
            for j in range(2):
                eps = 1e-4
                dd = ld.vector.copy()
                dd[j] += eps
                N2, E2 = drift_corrected_track(tp[ms], N[ms], E[ms], t_execute, tuple(dd))
                g[j] = (fit_circle(N2, E2)[0][2] - R) / eps
        aw = ld.detail.get("weights") if ld is not None else None
        if aw is not None and len(aw) == tp.size and ld.detail.get("t_first") == float(tp[0]):
            # the loop's own drift comes from the same fixes (its two ends): the radius is one linear
            # functional of every fix's north and east error, through the fit (radial weights h) and
            # through the drift (weights a, mapped by ∂R/∂d) — taken as one, so that an error common
            # to the loop's ends and the circle (the tracking's slow wander) is not counted twice
            wN, wE = g[0] * np.asarray(aw, float), g[1] * np.asarray(aw, float)
            idx = np.flatnonzero(ms)
            wN[idx] += hR * np.cos(theta_k)
            wE[idx] += hR * np.sin(theta_k)
            varR = sigN ** 2 * float(wN @ wN) + sigE ** 2 * float(wE @ wE) \
                + correlated_variance(tp, wN, fix_errors) + correlated_variance(tp, wE, fix_errors) \
                + float(g @ np.asarray(ld.detail["cov_timing"], float) @ g)
        else:
            varR = 0.5 * (sigN ** 2 + sigE ** 2) * float(hR @ hR) + correlated_variance(tp[ms], hR, fix_errors, theta_k)
            varR += float(g @ Sl @ g)
        # drift angle: heading minus the tangent direction of the fitted circle
        theta = np.arctan2(El[ms] - p[1], Nl[ms] - p[0])
        chi = theta + side * math.pi / 2
        psi_t = np.interp(tp[ms], th, psi)
        beta = side * np.angle(np.exp(1j * (psi_t - chi)))
        bm = float(np.mean(beta))
        if lever_arm is not None and heading_sd > 0.0:
            # the fixes were moved from the antenna to the reference point along the gyro heading: its
            # slow error δψ (bias and wander, common to the loop) turns the lever arm (x, y) and moves
            # the reference point by δψ (−y, x) in the body axes, whose radial part at drift angle β
            # changes the radius by δψ (x cos β ± y sin β) (KVLCC2's antenna 130 m aft of midship and a
            # 0.15° gyro bias: 0.34 m of radius; the same on every sample, no fit averages it out)
            xa, ya = float(lever_arm[0]), float(lever_arm[1])
            varR += heading_sd ** 2 * ((xa * math.cos(bm)) ** 2 + (ya * math.sin(bm)) ** 2)
        res.steady_diameter = Estimate(2 * R, 2 * math.sqrt(varR))
        rr = res.steady_rate
        res.steady_speed = Estimate(R * abs(rr.value), math.sqrt((abs(rr.value)) ** 2 * varR
                                                                 + (R * rr.std) ** 2))
        bse = float(np.std(beta, ddof=1) / math.sqrt(len(beta))) * _ar1_inflation(beta - bm)
        res.drift_angle = Estimate(bm, bse, len(beta) - 1)
        if not sw.steady:
            notes.append("steady diameter / speed / drift angle come from a record that never settled")
    else:
        notes.append("steady loop too short for a circle fit")

    if roll is not None:
        tr, ro = _clean(t if t_roll is None else t_roll, roll)
        sig_r, _ = noise_sigma(tr, ro)
        mr = (tr >= sw.t_start) & (tr <= sw.t_end)
        if np.count_nonzero(mr) >= 3:
            mv = float(np.mean(ro[mr]))
            se = float(np.std(ro[mr], ddof=1) / math.sqrt(np.count_nonzero(mr))) * _ar1_inflation(ro[mr] - mv)
            res.heel_steady = Estimate(mv, math.hypot(se, roll_bias), int(np.count_nonzero(mr)) - 1)
        ma_ = tr >= t_execute
        if np.count_nonzero(ma_) >= 5:
            tt, rr_ = tr[ma_], ro[ma_]
            k = int(np.argmax(np.abs(rr_)))
            hw = 3 * float(np.median(np.diff(tt)))
            val, _, var, _, _ = _local_poly(tt, rr_, tt[k], hw, 2, sig_r, min_pts=5)
            res.heel_max = Estimate(val, math.sqrt(var + roll_bias ** 2))
    if rudder is not None:
        tr, rd = _clean(t if t_rudder is None else t_rudder, rudder)
        mr = (tr >= sw.t_start) & (tr <= sw.t_end)
        if np.count_nonzero(mr) >= 3:
            mv = float(np.mean(rd[mr]))
            se = float(np.std(rd[mr], ddof=1) / math.sqrt(np.count_nonzero(mr))) * _ar1_inflation(rd[mr] - mv)
            res.rudder_steady = Estimate(mv, se, int(np.count_nonzero(mr)) - 1)
    return res


# ----------------------------------------------------------------------- rate of turn vs rudder
@dataclasses.dataclass(frozen=True)
class BreakdownGroup:
    """Turns at one approach speed and one side, sorted by |rudder|."""

    speed: float  # mean approach speed of the group [m/s]
    side: int  # +1 starboard rudder, −1 port
    rudder: np.ndarray  # |rudder| [rad], increasing
    rate: np.ndarray  # |steady rate| [rad/s]
    rate_std: np.ndarray
    breakdown: bool
    breakdown_rudder: float | None  # |rudder| [rad] beyond which the rate falls
    z_drop: float  # most negative z of a rate change between consecutive rudder angles


def rudder_breakdown(approach_speed: Sequence[float], rudder: Sequence[float], rate: Sequence,
                     rate_std: Sequence[float] | None = None, *, speed_tol: float = 0.25,
                     z_crit: float = 1.645) -> list[BreakdownGroup]:
    """Rate of turn against rudder for many turns, grouped by approach speed (clusters no wider than
    ``speed_tol`` [m/s]) and side (sign of the rudder [rad]); ``rate`` [rad/s] floats or Estimates.

    Rudder breakdown (seed 002): a larger rudder angle gives a smaller steady rate of turn at the same
    speed. Flagged when |r| drops between consecutive |δ| with z = Δ|r| / √(σ₁² + σ₂²) < −z_crit
    (one-sided 5 % by default); ``breakdown_rudder`` is the |δ| of the largest rate before the drop.
    """
    spd = np.asarray(approach_speed, float)
    dl = np.asarray(rudder, float)
    rv = np.array([r.value if isinstance(r, Estimate) else float(r) for r in rate])
    if rate_std is None:
        rs = np.array([r.std if isinstance(r, Estimate) else 0.0 for r in rate])
    else:
        rs = np.asarray(rate_std, float)
    order = np.argsort(spd)
    clusters: list[list[int]] = []
    for i in order:
        if clusters and spd[i] - spd[clusters[-1][0]] <= speed_tol:
            clusters[-1].append(int(i))
        else:
            clusters.append([int(i)])
    groups = []
    for cl in clusters:
        for side in (1, -1):
            idx = [i for i in cl if np.sign(dl[i]) == side]
            if not idx:
                continue
            idx = sorted(idx, key=lambda i: abs(dl[i]))
            a_d = np.abs(dl[idx])
            a_r = np.abs(rv[idx])
            a_s = rs[idx]
            zmin, bk, bk_rud = 0.0, False, None
            for k in range(len(idx) - 1):
                den = math.hypot(a_s[k], a_s[k + 1])
                dr = a_r[k + 1] - a_r[k]
                z = dr / den if den > 0 else (-math.inf if dr < 0 else math.inf)
                if z < zmin:
                    zmin = z
                if z < -z_crit and not bk:
                    bk, bk_rud = True, float(a_d[k])
            groups.append(BreakdownGroup(float(np.mean(spd[idx])), side, a_d, a_r, a_s, bk, bk_rud, float(zmin)))
    return groups
