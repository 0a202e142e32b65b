"""Zig-zag (horizontal overshoot) trial reduction from heading and rudder records.

Procedure (seed 002 "Horizontal overshoot tests"; IMO MSC.137(76) §5.3 and MSC/Circ.1053 §4.3.2;
ITTC 7.5-04-02-01 zig-zag test): steady approach; EXECUTE: rudder to δ (e.g. 10° starboard); when the
heading has changed by the check angle α (10°) from the base course, the rudder is reversed to δ on
the other side; when the heading passes the base course and reaches α on the other side, reversed
again; two and a half cycles.

Inputs: gyro ``t_heading, heading`` [s, rad] (clockwise; unwrapped here) and rudder synchro
``t_rudder, rudder`` [s, rad] (positive to starboard), each on its own clock (same time scale; an
offset between the two clocks shifts the times measured from the rudder executes by that offset).

Definitions (all times in s, angles in rad; f(t) = s·(ψ(t) − ψ₀), s = +1 for a first execute to
starboard, ψ₀ = base course = circular mean heading over the ``approach_s`` before the first execute):

* Execute instants (:func:`rudder_executes`): the rudder moves are found with a hysteresis comparator
  at ±½ amplitude about the approach level; each move's start is the intersection of a straight line
  fitted to the moving samples (10–90 % of the swing) with the previous plateau level (median of the
  plateau). SE by the delta method from the line-fit covariance (rudder noise σ from the plateau
  residuals) and the SE of the plateau level. A steering gear that moves at constant rate makes this
  exact; a first-order servo makes it the "effective" start.
* Heading-threshold crossings c_k (f = +α, −α, +α, … alternately): local quadratic fit of the heading
  around the first sample beyond the level, solved for the crossing; SE = σ(f̂)/|ḟ| with σ from the
  gyro noise (residuals of piecewise cubic fits), the base-course SE and the gyro's slow wander
  (Gauss–Markov σ, τ of the maker's specification) since the middle of the approach,
  var = 2σ²(1 − e^(−Δt/τ)), all divided by the rate of turn at the crossing: on a slow ship the
  wander dominates (KVLCC2, 0.3°/s: 0.08° over 100 s is 0.1 s), on a quick one the noise does. The
  period between like crossings keeps the noise of both and the wander between them (the base
  course cancels).
* Overshoot k: the extreme of f (alternately max and min) between consecutive crossings, refined by
  a least-squares cubic over the samples within which f stays within ``peak_drop`` of the extreme
  (≥ 7 samples), extreme from the cubic's stationary point. The window is kept short (0.5° below
  the extreme): a cubic over a wider one misses the heading's quartic flattening at the peak —
  over 2° the noise-free true heading of the patrol vessel's 10/10 and 20/20 zig-zags came out
  0.012° low (SD 0.009°) against its 0.007° noise SE; over 0.5°, 0.001° low — but not shorter than
  10 σ of the heading noise, so that a noisy or sparse record (1 Hz, σ 0.1°) still has enough
  samples in the fit for its variance to dominate the cubic's bias. Overshoot angle = |f_peak| − α (IMO: the
  additional heading deviation after the counter-rudder); SE by the delta method from the fit
  covariance (parabolic-peak error propagation), combined with the SE of ψ₀. Overshoot time is
  measured from the first execute.
* Initial turning time = c₁ − t_exec,1 (heading reaches α); time to check yaw = t_peak,1 − t_exec,2
  (from the counter-rudder execute to the first heading extreme, where the yaw is checked);
  period = t_exec,4 − t_exec,2 (one full cycle between like executes); ``period_heading`` = c₃ − c₁.
* ``helm_delay`` = mean(t_exec,k+1 − c_k): how late the rudder was reversed after the threshold.

Clocks (:class:`Clock`): the gyro and the rudder synchros are logged on their own clocks, each
synchronised to the trial's time base with a stated offset SD and a drift (ppm SD) since the
synchronisation at ``t_ref`` (record meta, the loggers' data sheet). A time measured between a
heading feature and a rudder execute (initial turning time, time to check yaw, overshoot times)
carries both clocks' errors at those instants, var = σ_g(t_a)² + σ_r(t_b)² with
σ(t)² = σ_off² + (ppm·10⁻⁶·(t − t_ref))²; one hour into a trial 10 ppm alone is 0.036 s, which
for a fast patrol vessel is several times the gyro-noise SE of a crossing. Differences on one
clock (the period between like executes, between heading crossings) keep only the drift over the
interval.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from vtrials.reduce.estimate import Estimate
from vtrials.reduce.series import clean_series as _clean, noise_sigma, ar1_inflation as _ar1_inflation
from vtrials.units import DEG


# --------------------------------------------------------------------------------------------- helpers
def _diff(a: Estimate, b: Estimate) -> Estimate:
    return Estimate(a.value - b.value, math.hypot(a.std, b.std))


# -------------------------------------------------------------------------------------- executes
def _plateau(seg, state, centre, amp, tol) -> float:
    beyond = seg[state * (seg - centre) > 0.5 * amp]
    if beyond.size == 0:
        return float(np.median(seg))
    lev = float(np.median(beyond))
    for _ in range(3):
        held = seg[np.abs(seg - lev) <= tol]
        if held.size == 0:
            break
        lev = float(np.median(held))
    return lev


@dataclasses.dataclass(frozen=True)
class RudderMove:
    """One rudder execute: start instant [s] (Estimate), from/to plateau levels [rad], direction."""

    t: Estimate
    level_from: float
    level_to: float
    direction: int  # +1 toward starboard, −1 toward port
    t_reached: float  # end of the move (line reaches the new level) [s]


def rudder_executes(t_rudder, rudder, *, approach_s: float = 30.0, sigma: float | None = None) -> list[RudderMove]:
    """Rudder executes (moves between plateaus) detected from the rudder record [s, rad].

    See the module docstring. The approach level is the median of the first ``approach_s`` of the
    record (before any move). Returns the moves in time order.
    """
    t, d = _clean(t_rudder, rudder)
    if len(t) < 10:
        raise ValueError("rudder record too short")
    m0 = t <= t[0] + approach_s
    c = float(np.median(d[m0]))
    A = float(np.percentile(np.abs(d - c), 95))
    if A <= 0:
        return []
    hi, lo = c + 0.5 * A, c - 0.5 * A
    state = 0
    events = []  # (index of first sample beyond the threshold, new state)
    for i, v in enumerate(d):
        if v > hi and state != 1:
            state = 1
            events.append((i, 1))
        elif v < lo and state != -1:
            state = -1
            events.append((i, -1))
    if sigma is None:
        sigma = noise_sigma(t[m0], d[m0]) if np.count_nonzero(m0) >= 8 else float("nan")
    moves = []
    for j, (k, st) in enumerate(events):
        k_prev = events[j - 1][0] if j > 0 else 0
        k_next = events[j + 1][0] if j + 1 < len(events) else len(t)
        # plateau levels: median of the samples beyond the comparator threshold, refined to the
        # samples within max(4σ, 5 % of A) of it (the held part, without the moves in and out)
        seg_prev = d[k_prev:k]
        seg_next = d[k:k_next]
        tol_pl = max(4 * (sigma if math.isfinite(sigma) else 0.0), 0.05 * A)
        L0 = _plateau(seg_prev, events[j - 1][1], c, A, tol_pl) if j > 0 else c
        L1 = _plateau(seg_next, st, c, A, tol_pl)
        sw = L1 - L0
        if sw == 0:
            continue
        lo_i = max(k_prev, k - 200)
        idx = np.arange(lo_i, min(k_next, k + 200))
        frac = (d[idx] - L0) / sw
        # contiguous moving samples around k with 0.1 < frac < 0.9
        inside = (frac > 0.1) & (frac < 0.9)
        kk = int(np.searchsorted(idx, k))
        a = kk
        while a - 1 >= 0 and inside[a - 1]:
            a -= 1
        b = kk
        while b < len(idx) and inside[b]:
            b += 1
        sel = idx[a:b]
        if len(sel) < 2:
            sel = np.array([k - 1, k]) if k >= 1 else np.array([k, k + 1])
        tt, yy = t[sel], d[sel]
        tm = tt.mean()
        x = tt - tm
        sxx = float(x @ x)
        slope = float(x @ (yy - yy.mean())) / sxx
        icpt = float(yy.mean())
        t_start = tm + (L0 - icpt) / slope
        t_end = tm + (L1 - icpt) / slope
        # plateau level SE: the held samples of the previous plateau (the move into it excluded)
        sg = sigma if math.isfinite(sigma) else 0.0
        pl = seg_prev if j > 0 else d[m0]
        pl = pl[np.abs(pl - L0) <= tol_pl]
        sL0 = float(np.std(pl, ddof=1) / math.sqrt(len(pl))) if len(pl) > 1 else 0.0
        # delta method: t_s = tm + (L0 − a)/b
        var_a = sg ** 2 / len(tt)
        var_b = sg ** 2 / sxx
        dts = (L0 - icpt) / slope
        var_t = (var_a + sL0 ** 2) / slope ** 2 + (dts / slope) ** 2 * var_b
        moves.append(RudderMove(Estimate(float(t_start), math.sqrt(var_t)), L0, L1, 1 if sw > 0 else -1,
                                float(t_end)))
    return moves


# -------------------------------------------------------------------------------- heading features
def _crossing(th, f, level, after, sig):
    """First time ≥ after at which f reaches ``level`` from below; (t, SE, slope) or None."""
    idx = np.flatnonzero((f >= level) & (th >= after))
    if idx.size == 0:
        return None
    k = int(idx[0])
    if k == 0:
        return None
    tc = th[k - 1] + (level - f[k - 1]) / (f[k] - f[k - 1]) * (th[k] - th[k - 1]) if f[k] != f[k - 1] else th[k]
    dt = float(np.median(np.diff(th)))
    slope_guess = max((f[k] - f[k - 1]) / (th[k] - th[k - 1]), 1e-9)
    hw = max(3 * dt, min(10 * dt, 2.0 * DEG / slope_guess))
    for _ in range(4):
        m = np.abs(th - tc) <= hw
        if np.count_nonzero(m) < 4:
            hw *= 1.5
            continue
        x = (th[m] - tc) / hw
        A = np.vander(x, 3, increasing=True)
        G = np.linalg.pinv(A.T @ A)
        coef = G @ A.T @ f[m]
        sl = coef[1] / hw
        if sl <= 0:
            break
        step = (level - coef[0]) / sl
        tc += step
        if abs(step) < 1e-7:
            break
    m = np.abs(th - tc) <= hw
    x = (th[m] - tc) / hw
    A = np.vander(x, 3, increasing=True)
    G = np.linalg.pinv(A.T @ A)
    coef = G @ A.T @ f[m]
    sl = coef[1] / hw
    se = sig * math.sqrt(G[0, 0]) / max(abs(sl), 1e-12)
    return float(tc), float(se), float(sl)


def _peak(th, f, t0, t1, sig, drop, wander=(0.0, 1.0)):
    """Maximum of f on [t0, t1] refined by a least-squares cubic; (t_peak, f_peak, var_t, var_f).

    ``wander`` (σ [rad], τ [s]): a Gauss–Markov error of the heading, correlated across the window;
    its share of the peak time's variance (g·M C Mᵀ·g with M the fit's hat rows, g the gradient of
    the stationary point, C_ij = σ² e^(−|t_i − t_j|/τ)) is added to var_t: a slope of the error
    across a flat peak moves it by slope/|f''| (KVLCC2: 0.0017°/s² at the peak, a wander of 0.08°
    over 900 s tilts a ±24-s window by ~0.001°/s, i.e. ~0.5 s)."""
    m = (th >= t0) & (th <= t1)
    if np.count_nonzero(m) < 3:
        return None
    ii = np.flatnonzero(m)
    k = int(ii[np.argmax(f[ii])])
    fmax = f[k]
    # window: contiguous samples with f > fmax − drop, at least 3 each side
    a = k
    while a - 1 >= 0 and f[a - 1] > fmax - drop:
        a -= 1
    b = k
    while b + 1 < len(f) and f[b + 1] > fmax - drop:
        b += 1
    a = min(a, max(0, k - 3))
    b = max(b, min(len(f) - 1, k + 3))
    tt, yy = th[a:b + 1], f[a:b + 1]
    tc = th[k]
    hw = max(float(np.max(np.abs(tt - tc))), 1e-9)
    x = (tt - tc) / hw
    A = np.vander(x, 4, increasing=True)
    G = np.linalg.pinv(A.T @ A)
    c = G @ A.T @ yy
    # stationary point of c0 + c1 x + c2 x² + c3 x³ nearest 0 with negative curvature
    roots = np.roots([3 * c[3], 2 * c[2], c[1]]) if abs(c[3]) > 1e-15 else np.array([-c[1] / (2 * c[2])])
    roots = [r.real for r in np.atleast_1d(roots) if abs(r.imag) < 1e-12 and abs(r.real) <= 1.0
             and 2 * c[2] + 6 * c[3] * r.real < 0]
    if not roots:
        return float(tc), float(fmax), (0.5 * float(np.median(np.diff(th)))) ** 2 / 3, sig ** 2
    xp = min(roots, key=abs)
    fp = c[0] + c[1] * xp + c[2] * xp ** 2 + c[3] * xp ** 3
    # delta method: value (∂f/∂c at fixed x, since f'(xp) = 0) and location (implicit function)
    gv = np.array([1.0, xp, xp ** 2, xp ** 3])
    var_f = sig ** 2 * float(gv @ G @ gv)
    fpp = 2 * c[2] + 6 * c[3] * xp
    gx = -np.array([0.0, 1.0, 2 * xp, 3 * xp ** 2]) / fpp
    var_x = sig ** 2 * float(gx @ G @ gx)
    if wander[0] > 0:
        row = gx @ G @ A.T
        C = wander[0] ** 2 * np.exp(-np.abs(tt[:, None] - tt[None, :]) / max(wander[1], 1e-9))
        var_x += float(row @ C @ row)
    return float(tc + xp * hw), float(fp), var_x * hw ** 2, var_f


# ------------------------------------------------------------------------------------------- clocks
@dataclasses.dataclass(frozen=True)
class Clock:
    """A logger clock's stated timing accuracy: offset SD [s] at synchronisation, drift SD [ppm],
    synchronisation instant t_ref [s] (record meta ``clock_offset_sd_s``, ``clock_drift_ppm_sd``,
    ``clock_t_ref_s``)."""

    offset_sd: float = 0.0
    drift_ppm_sd: float = 0.0
    t_ref: float = 0.0

    @classmethod
    def from_meta(cls, meta: dict) -> "Clock":
        return cls(float(meta.get("clock_offset_sd_s", 0.0)), float(meta.get("clock_drift_ppm_sd", 0.0)),
                   float(meta.get("clock_t_ref_s", 0.0)))

    @classmethod
    def mean(cls, clocks: list) -> "Clock":
        """The clock of a signal averaged over n independent loggers (its time error is the mean of
        theirs): offset and drift SDs add in quadrature over n."""
        if not clocks:
            return cls()
        n = len(clocks)
        return cls(math.sqrt(sum(c.offset_sd ** 2 for c in clocks)) / n,
                   math.sqrt(sum(c.drift_ppm_sd ** 2 for c in clocks)) / n, clocks[0].t_ref)

    def sd(self, t: float) -> float:
        """SD [s] of the clock's time error at time t."""
        return math.hypot(self.offset_sd, self.drift_ppm_sd * 1e-6 * (t - self.t_ref))

    def interval_sd(self, t0: float, t1: float) -> float:
        """SD [s] of an interval t1 − t0 measured on this one clock (its drift over the interval)."""
        return self.drift_ppm_sd * 1e-6 * abs(t1 - t0)


def _between(a: Estimate, ta: float, ca: Clock, b: Estimate, tb: float, cb: Clock) -> Estimate:
    """a − b for instants logged on two independent clocks (see the module docstring)."""
    return Estimate(a.value - b.value, math.sqrt(a.std ** 2 + b.std ** 2 + ca.sd(ta) ** 2 + cb.sd(tb) ** 2))


# ------------------------------------------------------------------------------------------ result
@dataclasses.dataclass
class ZigZagResult:
    """Zig-zag metrics (rad, s). None where the record does not reach the feature."""

    rudder_angle: Estimate  # mean |rudder − approach level| over the holds
    check_angle: float
    first_side: int
    approach_heading: Estimate
    executes: list  # Estimates of the rudder execute instants [s]
    crossings: list  # Estimates of the heading-threshold crossing instants [s]
    overshoots: list  # Estimates of the overshoot angles, in order [rad]
    overshoot_times: list  # Estimates from the first execute [s]
    initial_turning_time: Estimate | None = None
    time_to_check_yaw: Estimate | None = None
    first_overshoot: Estimate | None = None
    first_overshoot_time: Estimate | None = None
    second_overshoot: Estimate | None = None
    second_overshoot_time: Estimate | None = None
    period: Estimate | None = None
    period_heading: Estimate | None = None
    helm_delay: float | None = None
    sigma_heading: float = float("nan")
    notes: list = dataclasses.field(default_factory=list)

    def to_dict(self) -> dict:
        out = {}
        for f in dataclasses.fields(self):
            v = getattr(self, f.name)
            if isinstance(v, Estimate):
                out[f.name] = v.to_dict()
            elif isinstance(v, list) and v and isinstance(v[0], Estimate):
                out[f.name] = [e.to_dict() for e in v]
            else:
                out[f.name] = v
        return out


def zigzag_metrics(t_heading, heading, t_rudder, rudder, *, check_angle: float | None = None,
                   approach_s: float = 60.0, peak_drop: float = 0.5 * DEG, heading_resolution: float = 0.0,
                   sigma_heading: float | None = None, clock_heading: Clock | None = None,
                   clock_rudder: Clock | None = None, gyro_drift: tuple[float, float] = (0.0, 1.0)) -> ZigZagResult:
    """Reduce a zig-zag run (see the module docstring).

    ``check_angle`` α [rad]; default: the rudder amplitude rounded to the nearest degree (the 10°/10°
    and 20°/20° tests). ``approach_s`` [s] base-course window; ``peak_drop`` [rad] peak-fit window;
    ``heading_resolution`` [rad] gyro step added as resolution/√12 to the noise;
    ``clock_heading``, ``clock_rudder``: the two records' clocks (default: perfect clocks);
    ``gyro_drift`` (σ [rad], τ [s]): the gyro's slow wander (Gauss–Markov, the maker's specification)
    that moves the heading crossings (see the module docstring).
    """
    gd_sd, gd_tau = float(gyro_drift[0]), max(float(gyro_drift[1]), 1e-9)

    def wander_var(dt: float) -> float:
        # variance of the change of a Gauss–Markov error (σ, τ) over dt: 2σ²(1 − e^(−|dt|/τ))
        return 2.0 * gd_sd ** 2 * (1.0 - math.exp(-abs(dt) / gd_tau)) if gd_sd > 0 else 0.0

    cg = clock_heading or Clock()
    cr = clock_rudder or Clock()
    notes: list[str] = []
    th, psi = _clean(t_heading, heading)
    psi = np.unwrap(psi)
    tr, dr = _clean(t_rudder, rudder)
    moves = rudder_executes(tr, dr)
    if not moves:
        raise ValueError("no rudder execute found")
    t1 = moves[0].t.value
    sig = sigma_heading if sigma_heading is not None else noise_sigma(th, psi)
    sig = math.hypot(sig, heading_resolution / math.sqrt(12.0))
    ma = (th >= t1 - approach_s) & (th <= t1)
    if np.count_nonzero(ma) < 3:
        raise ValueError("no approach heading before the first execute")
    a = psi[ma]
    psi0 = math.atan2(np.mean(np.sin(a)), np.mean(np.cos(a)))
    psi0 += 2 * math.pi * round((float(np.mean(a)) - psi0) / (2 * math.pi))
    dev = a - psi0
    psi0_se = float(np.std(dev, ddof=1) / math.sqrt(len(a))) * _ar1_inflation(dev)
    side = moves[0].direction
    amp = np.array([abs(mv.level_to - moves[0].level_from) for mv in moves])
    rud = Estimate(float(np.mean(amp)), float(np.std(amp, ddof=1) / math.sqrt(len(amp))) if len(amp) > 1 else 0.0)
    alpha = check_angle if check_angle is not None else round(rud.value / DEG) * DEG
    f = side * (psi - psi0)
    res = ZigZagResult(rud, float(alpha), int(side), Estimate(psi0, psi0_se), [mv.t for mv in moves], [], [], [],
                       sigma_heading=sig, notes=notes)
    # alternate crossings and extremes
    sgn = 1.0
    after = t1
    crossings = []
    for _ in range(len(moves) + 2):
        c = _crossing(th, sgn * f, alpha, after, sig)
        if c is None:
            break
        tc, se, sl = c
        asl = max(abs(sl), 1e-12)
        # against the base course: its SE and the gyro's wander since the middle of the approach
        se_base = math.sqrt(se ** 2 + (psi0_se / asl) ** 2 + wander_var(tc - (t1 - 0.5 * approach_s)) / asl ** 2)
        crossings.append((Estimate(tc, se_base), sgn, se, asl))
        after = tc
        sgn = -sgn
    res.crossings = [c[0] for c in crossings]
    t_exec1 = moves[0].t
    for j, (c, sg_, _, _) in enumerate(crossings):
        t_next = crossings[j + 1][0].value if j + 1 < len(crossings) else th[-1]
        if j + 1 >= len(crossings):
            # the extreme after the last crossing counts only if the heading has turned back by then
            tail = (th >= c.value)
            g = sg_ * f[tail]
            if g.size < 5 or g[-1] > g.max() - max(peak_drop, 5 * sig):
                break
        pk = _peak(th, sg_ * f, c.value, t_next, sig, max(peak_drop, 10.0 * sig), (gd_sd, gd_tau))
        if pk is None:
            break
        tp, fp, vt, vf = pk
        res.overshoots.append(Estimate(fp - alpha, math.sqrt(vf + psi0_se ** 2)))
        res.overshoot_times.append(_between(Estimate(tp, math.sqrt(vt)), tp, cg, t_exec1, t_exec1.value, cr))
        if j == 0:
            res.first_overshoot = res.overshoots[-1]
            res.first_overshoot_time = res.overshoot_times[-1]
            if len(moves) >= 2:
                res.time_to_check_yaw = _between(Estimate(tp, math.sqrt(vt)), tp, cg, moves[1].t,
                                                 moves[1].t.value, cr)
        elif j == 1:
            res.second_overshoot = res.overshoots[-1]
            res.second_overshoot_time = res.overshoot_times[-1]
    if crossings:
        res.initial_turning_time = _between(crossings[0][0], crossings[0][0].value, cg, t_exec1, t_exec1.value, cr)
    else:
        notes.append("heading never reached the check angle")
    if len(moves) >= 4:
        p = _diff(moves[3].t, moves[1].t)
        res.period = Estimate(p.value, math.hypot(p.std, cr.interval_sd(moves[1].t.value, moves[3].t.value)))
    if len(crossings) >= 3:
        # the base course cancels in the difference; the gyro's wander between the two crossings
        # (same side, same slope sign) and the logger clock's drift over the interval remain
        (c1, _, s1, a1), (c3, _, s3, a3) = crossings[0], crossings[2]
        dt = c3.value - c1.value
        res.period_heading = Estimate(dt, math.sqrt(s1 ** 2 + s3 ** 2 + wander_var(dt) / (0.5 * (a1 + a3)) ** 2
                                                    + cg.interval_sd(c1.value, c3.value) ** 2))
    delays = [moves[k + 1].t.value - crossings[k][0].value for k in range(min(len(moves) - 1, len(crossings)))]
    if delays:
        res.helm_delay = float(np.mean(delays))
        if max(abs(x) for x in delays) > 30.0:
            notes.append("rudder executes do not follow the heading thresholds (check angle or clocks?)")
    return res
