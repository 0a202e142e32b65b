"""Six-degree-of-freedom motion from strapdown accelerometers only (no gyros).

After M.D. Miles, "Measurement of six degree of freedom model motions using strapdown accelerometers",
21st ATTC (1986), seed 001: a rigid array of linear accelerometers at known positions ρ_j with sensitive
axes e_j reads

    a_j = e_j · [f_C + ω̇ × ρ_j + ω × (ω × ρ_j)]

with f_C = Aᵀ(ẍ₀ − g k₀) the specific force at the reference point C in body axes (A body → earth
NED, Euler angles φ, θ, ψ; k₀ down). Miles' 7-accelerometer planar layout (:func:`miles_array`) takes
pair differences; here any array whose design matrix [e_jᵀ, (ρ_j × e_j)ᵀ] has rank 6 is accepted and
(f_C, ω̇) are solved per sample by least squares, which reduces to Miles' pair formulas for his layout.

The nonlinear iterative scheme (Miles §3; steps 1 and 2 are iterated together):

1. ω̇⁽ⁿ⁺¹⁾ from the accelerometers with the centripetal terms of ω⁽ⁿ⁾ moved to the data side
   (ω⁽⁰⁾ = 0 is the linearised solution); ω by FFT integration with a high-pass cut-off. Miles takes
   the integration constants from zero-mean rates; here the constant rate is the one for which the
   Euler angles do not drift (mean φ̇ = θ̇ = ψ̇ = 0), which matters at large angles where
   ω_x = φ̇ − ψ̇ sin θ … has a mean (at 15° RMS it halves the roll/pitch/yaw NRE).
2. Roll and pitch by iterating φ̇ = ω_x + tan θ (ω_y sin φ + ω_z cos φ), θ̇ = ω_y cos φ − ω_z sin φ
   (FFT integration, zero mean), with the mean roll and pitch found from the mean direction of gravity:
   the constant offsets that make the mean horizontal acceleration in earth axes zero (the vessel
   oscillates about a steady course); yaw from ψ̇ = (ω_y sin φ + ω_z cos φ)/cos θ about a zero mean (the
   x₀ axis is the average heading).
3. Surge, sway and heave (earth axes moving with the mean velocity) by double FFT integration of
   ẍ₀ = A f_C + g k₀ (or at any point Q: A(f_C + (Ω̇ + Ω²) ρ_Q) + g k₀).

FFT integration (``integration="fft"``, the default) treats the record as periodic (as Miles'
random-phase simulations are): on a record whose frequencies are off the record's own grid the measured
NRE of roll/pitch/yaw was 2.4–17 % at 5° RMS (vs < 0.1 % periodic). ``integration="mirror"``
(:func:`mirror_integrate`: trapezoidal integration in time, a line removed, a zero-phase high-pass on
the mirror-extended record) needs no periodicity: 0.8–1.4 % on that record (15° RMS: 1.2–2.2 %,
FFT 8–19 %); on a periodic record it is less exact than the FFT (15° RMS: 2.0–2.4 % against 1.0–1.6 %), so use it for measured records.
:func:`suggest_cutoff` chooses the cut-off from the readings (0.2 × the angular accelerations'
spectral peak). The high-pass cut-off keeps low-frequency noise from being amplified (Miles:
"FC"); motion below it is lost — the method is for oscillatory motion, not for manoeuvres.

Error metric (Miles eq. in §4): NRE = 100 · RMS(x_est − x_true) / (4 · RMS(x_true)) %.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
from scipy.signal import welch

from vtrials.errors import InputError
from vtrials.units import G

_WHERE = "strapdown"


@dataclasses.dataclass(frozen=True)
class AccelerometerArray:
    """positions (n, 3) [m] from the reference point C, body axes (x fwd, y stbd, z down); axes (n, 3)
    unit sensitive axes. Needs n ≥ 6 and a rank-6 design (f_C and ω̇ observable)."""

    positions: np.ndarray
    axes: np.ndarray

    def __post_init__(self):
        p = np.asarray(self.positions, float)
        e = np.asarray(self.axes, float)
        if p.ndim != 2 or p.shape[1] != 3 or p.shape[0] < 6:
            raise InputError(_WHERE, "array.positions", f"shape {p.shape}; allowed: (n ≥ 6, 3) [m]")
        if e.shape != p.shape:
            raise InputError(_WHERE, "array.axes", f"shape {e.shape}; allowed: {p.shape} (one unit axis per sensor)")
        if not (np.all(np.isfinite(p)) and np.all(np.isfinite(e))):
            raise InputError(_WHERE, "array", "non-finite positions or axes")
        norm = np.linalg.norm(e, axis=1)
        if np.any(np.abs(norm - 1.0) > 1e-6):
            raise InputError(_WHERE, "array.axes", f"norms {np.round(norm, 6).tolist()}; allowed: unit vectors")
        h = np.hstack([e, np.cross(p, e)])
        if np.linalg.matrix_rank(h, tol=1e-9 * max(1.0, float(np.abs(h).max()))) < 6:
            raise InputError(_WHERE, "array", "the sensors do not observe all of f_C and ω̇ (design rank < 6); "
                             "allowed: an array with pairs separated along x, y (e.g. miles_array())")
        object.__setattr__(self, "positions", p)
        object.__setattr__(self, "axes", e)

    @property
    def design(self) -> np.ndarray:
        """H (n, 6): a_j = H_j · (f_C, ω̇) + centripetal_j."""
        return np.hstack([self.axes, np.cross(self.positions, self.axes)])


def miles_array(roll_separation: float = 0.30, pitch_separation: float = 0.84,
                yaw_separation: float = 0.95) -> AccelerometerArray:
    """Miles' planar layout (seed 001 Fig. 1): vertical accelerometers 1, 2 fore and aft (pitch), 5, 6 port
    and starboard (roll); lateral accelerometers 3, 4 fore and aft (yaw); longitudinal 7 at C.
    Default separations are his prototype's [m] (roll 0.30, pitch 0.84, yaw 0.95)."""
    for name, v in (("roll_separation", roll_separation), ("pitch_separation", pitch_separation),
                    ("yaw_separation", yaw_separation)):
        if not (v > 0 and math.isfinite(v)):
            raise InputError(_WHERE, name, f"value {v!r}; allowed: > 0 m")
    hp, hr, hy = pitch_separation / 2, roll_separation / 2, yaw_separation / 2
    pos = [(hp, 0, 0), (-hp, 0, 0), (hy, 0, 0), (-hy, 0, 0), (0, -hr, 0), (0, hr, 0), (0, 0, 0)]
    ax = [(0, 0, 1), (0, 0, 1), (0, 1, 0), (0, 1, 0), (0, 0, 1), (0, 0, 1), (1, 0, 0)]
    return AccelerometerArray(np.array(pos, float), np.array(ax, float))


def triaxial_array(positions) -> AccelerometerArray:
    """Tri-axial accelerometers at the given body positions (k, 3) [m]: three sensors (x, y, z) each.
    Three units at non-collinear points observe f_C and ω̇."""
    p = np.asarray(positions, float)
    if p.ndim != 2 or p.shape[1] != 3:
        raise InputError(_WHERE, "positions", f"shape {p.shape}; allowed: (k, 3) [m]")
    return AccelerometerArray(np.repeat(p, 3, axis=0), np.tile(np.eye(3), (p.shape[0], 1)))


def nre(estimate: np.ndarray, truth: np.ndarray) -> float:
    """Normalised RMS error (Miles): 100 · RMS(est − true)/(4 · RMS(true)) [%]."""
    est = np.asarray(estimate, float)
    tru = np.asarray(truth, float)
    if est.shape != tru.shape:
        raise InputError(_WHERE, "estimate", f"shape {est.shape}; allowed: the truth's shape {tru.shape}")
    rms_true = math.sqrt(float(np.mean(tru ** 2)))
    if rms_true == 0:
        raise InputError(_WHERE, "truth", "RMS is zero; NRE undefined")
    return 100.0 * math.sqrt(float(np.mean((est - tru) ** 2))) / (4.0 * rms_true)


def fft_integrate(x: np.ndarray, dt: float, cutoff_hz: float) -> np.ndarray:
    """∫x dt along axis 0 by FFT: X(ω)/(iω) above the cut-off, zero at and below it (zero-mean result;
    the record is treated as periodic)."""
    n = x.shape[0]
    spec = np.fft.rfft(x, axis=0)
    f = np.fft.rfftfreq(n, dt)
    keep = f > cutoff_hz
    factor = np.zeros(f.size, complex)
    factor[keep] = 1.0 / (2j * np.pi * f[keep])
    return np.fft.irfft(spec * factor.reshape((-1,) + (1,) * (x.ndim - 1)), n=n, axis=0)


INTEGRATIONS = ("fft", "mirror")


def mirror_integrate(x: np.ndarray, dt: float, cutoff_hz: float, order: int = 4) -> np.ndarray:
    """∫x dt along axis 0 for a record that is NOT periodic: trapezoidal integration in the time domain,
    a least-squares line removed (an integrand bias and the integration constant), then a zero-phase
    high-pass |H|² = 1/(1 + (f_c/f)^(2·order)) applied by FFT to the record extended by its mirror image
    (x(t), x(2T − t)), which is continuous at both joins, so no wrap-around step enters the filter;
    the mirror half is discarded. Measured on a 0.2013-Hz sinusoid over 300 s (60.4 cycles, cut-off
    0.04 Hz): NRE 0.77 % against 1.58 % for :func:`fft_integrate` (tests/test_reduce_strapdown.py).
    order 4 (default): on patrol51's simulated quartering-sea records the roll/pitch/heave NRE was 0.3–1.3
    points lower than with order 2 (a gentler knee removes wave-band motion near the cut-off)."""
    x = np.asarray(x, float)
    n = x.shape[0]
    y = np.concatenate([np.zeros((1,) + x.shape[1:]), np.cumsum(0.5 * (x[1:] + x[:-1]), axis=0) * dt], 0)
    s = np.linspace(-1.0, 1.0, n)
    v = np.column_stack([s, np.ones(n)])
    flat = y.reshape(n, -1)
    flat = flat - v @ np.linalg.lstsq(v, flat, rcond=None)[0]
    return mirror_highpass(flat, dt, cutoff_hz, order).reshape(y.shape)


def mirror_highpass(y: np.ndarray, dt: float, cutoff_hz: float, order: int = 4) -> np.ndarray:
    """Zero-phase high-pass |H|² = 1/(1 + (f_c/f)^(2·order)) along axis 0, by FFT of the record extended
    by its mirror image (the filter :func:`mirror_integrate` applies; also the band in which to compare
    a reconstruction with a truth that has motion below the cut-off)."""
    y = np.asarray(y, float)
    n = y.shape[0]
    flat = y.reshape(n, -1)
    ext = np.concatenate([flat, flat[::-1]], 0)
    f = np.fft.rfftfreq(2 * n, dt)
    h = np.zeros(f.size)
    h[1:] = 1.0 / (1.0 + (cutoff_hz / f[1:]) ** (2 * order))
    return np.fft.irfft(np.fft.rfft(ext, axis=0) * h[:, None], n=2 * n, axis=0)[:n].reshape(y.shape)


def _integrator(method: str):
    if method == "fft":
        return fft_integrate
    if method == "mirror":
        return mirror_integrate
    raise InputError(_WHERE, "integration", f"value {method!r}; allowed: one of {INTEGRATIONS}")



def suggest_cutoff(time_s: np.ndarray, accelerations: np.ndarray, array: AccelerometerArray,
                   fraction: float = 0.2) -> float:
    """A high-pass cut-off chosen from the records: ``fraction`` × the peak frequency of the summed
    spectrum of the angular accelerations (linear solve; Welch, 256-s segments or the record). A
    wave-excited (encounter) spectrum has little energy below about half its peak (the synthetic
    records of tests/test_reduce_strapdown.py: 0.5 ω_p), and 0.4 × that lower edge is the cut-off used
    for Miles' figure there, hence the default 0.2. Not below 2 / record length."""
    t = np.asarray(time_s, float)
    a = np.asarray(accelerations, float)
    if t.ndim != 1 or t.size < 16 or a.shape != (t.size, array.positions.shape[0]):
        raise InputError(_WHERE, "accelerations", f"shape {a.shape}; allowed: ({t.size}, {array.positions.shape[0]})")
    if not (0 < fraction <= 1):
        raise InputError(_WHERE, "fraction", f"value {fraction!r}; allowed: 0 < fraction ≤ 1")
    dt = float(np.mean(np.diff(t)))
    wdot = (a @ np.linalg.pinv(array.design).T)[:, 3:]
    f, p = welch(wdot, fs=1.0 / dt, nperseg=min(t.size, int(round(256.0 / dt))), axis=0, detrend="linear")
    return max(fraction * float(f[int(np.argmax(p.sum(axis=1)))]), 2.0 / (t[-1] - t[0]))


def rotation_body_to_earth(roll, pitch, heading) -> np.ndarray:
    """A(φ, θ, ψ) = R_z(ψ) R_y(θ) R_x(φ), shape (..., 3, 3)."""
    sf, cf, st, ct = np.sin(roll), np.cos(roll), np.sin(pitch), np.cos(pitch)
    sp, cp = np.sin(heading), np.cos(heading)
    return np.stack([
        np.stack([ct * cp, sf * st * cp - cf * sp, cf * st * cp + sf * sp], -1),
        np.stack([ct * sp, sf * st * sp + cf * cp, cf * st * sp - sf * cp], -1),
        np.stack([-st, ct * sf, ct * cf], -1)], -2)


def _centripetal(w: np.ndarray, arr: AccelerometerArray) -> np.ndarray:
    """e_j · ω × (ω × ρ_j) = (e·ω)(ω·ρ) − |ω|²(e·ρ), shape (N, n)."""
    ew = w @ arr.axes.T
    wr = w @ arr.positions.T
    ww = np.sum(w * w, axis=1)[:, None]
    er = np.sum(arr.axes * arr.positions, axis=1)[None, :]
    return ew * wr - ww * er


@dataclasses.dataclass(frozen=True)
class StrapdownMotion:
    """time_s; rates (N, 3) ω [rad/s]; rate_dot (N, 3); euler (N, 3) φ, θ, ψ [rad] (ψ about the mean
    heading); specific_force (N, 3) f_C body [m/s²]; acceleration (N, 3) ẍ₀ earth NED [m/s²];
    velocity (N, 3), displacement (N, 3) earth NED about the mean motion; iterations."""

    time_s: np.ndarray
    rates: np.ndarray
    rate_dot: np.ndarray
    euler: np.ndarray
    specific_force: np.ndarray
    acceleration: np.ndarray
    velocity: np.ndarray
    displacement: np.ndarray
    iterations: int


def strapdown_motion(time_s: np.ndarray, accelerations: np.ndarray, array: AccelerometerArray,
                     cutoff_hz: float, rate_cutoff_hz: float | None = None, gravity: float = G,
                     point: np.ndarray | None = None, max_iterations: int = 200,
                     tolerance: float = 1e-10, integration: str = "fft") -> StrapdownMotion:
    """Miles' nonlinear iterative reconstruction.

    time_s (N,) uniform [s]; accelerations (N, n) readings of the array's sensors [m/s²] (specific force:
    a sensor along −z at rest reads +g along its axis, i.e. a_j = e_j · f with f_z = −g at rest);
    cutoff_hz: high-pass cut-off of the FFT integrations of angles and translations (their true spectra
    are band-limited to the waves); rate_cutoff_hz: cut-off for ω̇ → ω (default cutoff_hz). The body
    rates of large oscillations have real content at difference frequencies below the wave band, so a
    lower rate cut-off is more accurate — but the fixed-point iteration of Euler's equations
    ω⁽ⁿ⁺¹⁾ = ∫(F − ω⁽ⁿ⁾ × ω⁽ⁿ⁾) has a gain of about 2|ω|/(2πf) at frequency f and diverges below
    f ≈ |ω|/π; keep rate_cutoff_hz above that. point: body point Q [m] for the translations
    (default C). integration: "fft" (:func:`fft_integrate`, exact for a periodic record, as Miles'
    simulations are) or "mirror" (:func:`mirror_integrate`, for a measured record, which never is).
    Converged when the largest change of ω, φ, θ and the mean attitude between iterations
    is below ``tolerance`` (rad/s, rad).
    """
    t = np.asarray(time_s, float)
    a = np.asarray(accelerations, float)
    if t.ndim != 1 or t.size < 16:
        raise InputError(_WHERE, "time_s", f"shape {t.shape}; allowed: 1-D, ≥ 16 samples")
    dt = float(np.mean(np.diff(t)))
    if not (dt > 0 and np.allclose(np.diff(t), dt, rtol=1e-6, atol=0)):
        raise InputError(_WHERE, "time_s", "must be uniformly sampled and increasing (FFT integration)")
    if a.shape != (t.size, array.positions.shape[0]):
        raise InputError(_WHERE, "accelerations", f"shape {a.shape}; allowed: ({t.size}, {array.positions.shape[0]})")
    if not np.all(np.isfinite(a)):
        raise InputError(_WHERE, "accelerations", "non-finite values; allowed: finite numbers")
    nyquist = 0.5 / dt
    if not (0 < cutoff_hz < nyquist):
        raise InputError(_WHERE, "cutoff_hz", f"value {cutoff_hz!r}; allowed: 0 < cutoff < {nyquist:g} Hz")
    rate_cut = cutoff_hz if rate_cutoff_hz is None else rate_cutoff_hz
    if not (0 < rate_cut < nyquist):
        raise InputError(_WHERE, "rate_cutoff_hz", f"value {rate_cutoff_hz!r}; allowed: 0 < cutoff < {nyquist:g} Hz")
    if not (isinstance(max_iterations, int) and max_iterations >= 1):
        raise InputError(_WHERE, "max_iterations", f"value {max_iterations!r}; allowed: integer ≥ 1")
    pinv = np.linalg.pinv(array.design)
    integrate = _integrator(integration)  # the chosen integration

    # 1–2. rates and attitude, iterated together
    w_osc = np.zeros((t.size, 3))
    c = np.zeros(3)
    phi = np.zeros(t.size)
    th = np.zeros(t.size)
    psi = np.zeros(t.size)
    mean = np.zeros(2)
    it = 0
    for it in range(1, max_iterations + 1):
        sol = (a - _centripetal(w_osc + c, array)) @ pinv.T
        w_new = integrate(sol[:, 3:], dt, rate_cut)
        fp, ft = phi + mean[0], th + mean[1]
        c_new = _zero_drift_rates(w_new, fp, ft)
        w = w_new + c_new
        phid, thd, psid = _euler_rates(w, fp, ft)
        phi_new = integrate(phid, dt, cutoff_hz)
        th_new = integrate(thd, dt, cutoff_hz)
        psi = integrate(psid, dt, cutoff_hz)
        f_c = sol[:, :3]
        mean_new = _mean_attitude(phi_new, th_new, psi, f_c, mean)
        change = max(float(np.max(np.abs(w_new + c_new - w_osc - c))), float(np.max(np.abs(phi_new - phi))),
                     float(np.max(np.abs(th_new - th))), float(np.max(np.abs(mean_new - mean))))
        w_osc, c, phi, th, mean = w_new, c_new, phi_new, th_new, mean_new
        if not math.isfinite(change) or change > 1e3:
            raise InputError(_WHERE, "rate_cutoff_hz", f"value {rate_cut!r} Hz: the rate iteration diverges "
                             "(low-frequency gain of Euler's equations > 1); allowed: a higher cut-off")
        if change < tolerance:
            break
    w = w_osc + c
    sol = (a - _centripetal(w, array)) @ pinv.T
    f_c = sol[:, :3]
    wdot = sol[:, 3:]
    phi = phi + mean[0]
    th = th + mean[1]
    psi = integrate(_euler_rates(w, phi, th)[2], dt, cutoff_hz)

    # 3. translations at C (or Q)
    f_q = f_c
    if point is not None:
        rq = np.asarray(point, float)
        if rq.shape != (3,) or not np.all(np.isfinite(rq)):
            raise InputError(_WHERE, "point", f"value {point!r}; allowed: 3 finite numbers [m]")
        f_q = f_c + np.cross(wdot, rq) + np.cross(w, np.cross(w, np.broadcast_to(rq, w.shape)))
    amat = rotation_body_to_earth(phi, th, psi)
    acc = np.einsum("nij,nj->ni", amat, f_q)
    acc[:, 2] += gravity
    vel = integrate(acc, dt, cutoff_hz)
    disp = integrate(vel, dt, cutoff_hz)
    return StrapdownMotion(time_s=t, rates=w, rate_dot=wdot, euler=np.stack([phi, th, psi], 1),
                           specific_force=f_c, acceleration=acc, velocity=vel, displacement=disp,
                           iterations=it)


def _euler_rates(w, phi, th):
    """(φ̇, θ̇, ψ̇) from body rates (SNAME/Etkin Euler angles; Miles eqs. 11–13)."""
    p, q, r = w[:, 0], w[:, 1], w[:, 2]
    sf, cf = np.sin(phi), np.cos(phi)
    return (p + np.tan(th) * (q * sf + r * cf), q * cf - r * sf, (q * sf + r * cf) / np.cos(th))


def _zero_drift_rates(w_osc, phi, th) -> np.ndarray:
    """Constant rate c added to the zero-mean integrated rates so that the Euler angles do not drift:
    mean(φ̇) = mean(θ̇) = mean(ψ̇) = 0 (linear in c). For large oscillations the body rates of a vessel
    on a steady course do not average to zero (ω_x = φ̇ − ψ̇ sin θ …), which Miles' zero-mean
    integration constants would ignore."""
    sf, cf, tt, ct = np.sin(phi), np.cos(phi), np.tan(th), np.cos(th)
    k = np.array([[1.0, np.mean(tt * sf), np.mean(tt * cf)],
                  [0.0, np.mean(cf), -np.mean(sf)],
                  [0.0, np.mean(sf / ct), np.mean(cf / ct)]])
    rhs = -np.array([np.mean(x) for x in _euler_rates(w_osc, phi, th)])
    return np.linalg.solve(k, rhs)


def _mean_attitude(phi, th, psi, f_c, start) -> np.ndarray:
    """Constant roll and pitch offsets (φ̄, θ̄) that make the mean horizontal earth-axis acceleration
    zero, mean((A f_C)_N) = mean((A f_C)_E) = 0 (Newton, numerical Jacobian)."""

    def horizontal(m):
        amat = rotation_body_to_earth(phi + m[0], th + m[1], psi)
        return np.mean(np.einsum("nij,nj->ni", amat[:, :2, :], f_c), axis=0)

    m = np.array(start, float)
    if not np.any(m):  # Miles' linearised first estimate: φ̄ = −P₂/g, θ̄ = P₁/g
        fm = np.mean(f_c, axis=0)
        gm = float(np.linalg.norm(fm))
        m = np.array([-math.asin(np.clip(fm[1] / gm, -1, 1)), math.asin(np.clip(fm[0] / gm, -1, 1))])
    for _ in range(30):
        h = horizontal(m)
        jac = np.empty((2, 2))
        for k in range(2):
            d = np.zeros(2)
            d[k] = 1e-7
            jac[:, k] = (horizontal(m + d) - h) / 1e-7
        step = np.clip(np.linalg.solve(jac, -h), -0.1, 0.1)
        m = m + step
        if np.max(np.abs(step)) < 1e-13:
            break
    return m


def strapdown_linear(time_s: np.ndarray, accelerations: np.ndarray, array: AccelerometerArray,
                     cutoff_hz: float, gravity: float = G) -> np.ndarray:
    """Miles' linearised analysis, for comparison: angles = double FFT integral of the angular
    accelerations solved without centripetal terms (φ̈ ≈ ω̇_x …), mean roll and pitch from
    φ̄ = −mean(f_y)/g, θ̄ = mean(f_x)/g. Returns euler (N, 3) [rad]. Miles: adequate only to about
    3° RMS; an order of magnitude worse than the nonlinear scheme at larger angles."""
    t = np.asarray(time_s, float)
    a = np.asarray(accelerations, float)
    if t.ndim != 1 or t.size < 16 or a.shape != (t.size, array.positions.shape[0]):
        raise InputError(_WHERE, "accelerations", f"shape {a.shape}; allowed: ({t.size}, {array.positions.shape[0]})")
    dt = float(np.mean(np.diff(t)))
    if not (0 < cutoff_hz < 0.5 / dt):
        raise InputError(_WHERE, "cutoff_hz", f"value {cutoff_hz!r}; allowed: 0 < cutoff < {0.5 / dt:g} Hz")
    sol = a @ np.linalg.pinv(array.design).T
    ang = fft_integrate(fft_integrate(sol[:, 3:], dt, cutoff_hz), dt, cutoff_hz)
    fm = np.mean(sol[:, :3], axis=0)
    ang[:, 0] += -fm[1] / gravity
    ang[:, 1] += fm[0] / gravity
    return ang
