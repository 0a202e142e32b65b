"""Data compatibility (flight-path reconstruction) for a ship: Compat.

The rigid-body kinematic equations are integrated from the measured body rates and specific forces;
instrument biases (and, where observable, scale factors) and the initial states are adjusted by an
output-error fit until the integrated states agree with what was observed or assumed: gyro heading,
log speed, sway and heave velocities that average to zero, mean attitudes, and optionally GNSS
position or velocity. The method is the one of Compat as described by Arney et al. (DSTO FFG-7 ship
motion and airwake trial, seed 003 §3; program after Feik 1989, DSTO ARL-FM-TM-416) and of SIDPAC's
``compat`` (Morelli & Klein, *Aircraft System Identification*, 2nd ed. 2016, ch. 10).

Axes and signs (vtrials): body x forward, y starboard, z down; earth axes north, east, down (NED);
Euler angles roll φ, pitch θ (bow up positive), heading ψ (clockwise from north).

Instrument models (an instrument error is what the instrument ADDS to the truth)::

    p_m = (1 + k_p) p + b_p            (same for q, r)
    f_m = (1 + k_a) f_acc + b_a        (per axis x, y, z)

with f_acc the specific force (acceleration minus gravity, what an accelerometer reads) at the
accelerometer, which sits at ``offset`` ρ from the centre of motion. Corrected inputs::

    ω = (ω_m − b_ω)/(1 + k_ω)
    f = (f_m − b_a)/(1 + k_a) − ω̇ × ρ − ω × (ω × ρ)          (rigid-body transfer to the centre)
    a = f + g (−sin θ, cos θ sin φ, cos θ cos φ)               (gravity through the Euler angles)

ω̇ is the numerical derivative of the measured rates (a constant bias has no derivative). States
x = (φ, θ, ψ, u, v, w, N, E, D) obey (e.g. Etkin & Reid, *Dynamics of Flight*, 1996, §4.4)::

    φ̇ = p + (q sin φ + r cos φ) tan θ,  θ̇ = q cos φ − r sin φ,  ψ̇ = (q sin φ + r cos φ)/cos θ
    u̇ = a_x − q w + r v,  v̇ = a_y − r u + p w,  ẇ = a_z − p v + q u
    (Ṅ, Ė, Ḋ) = A(φ, θ, ψ) (u, v, w)

integrated by classical Runge–Kutta on the sample grid (inputs at the half steps by cubic
interpolation of the samples). The velocities are over the ground (inertial), but a steady, uniform
current changes nothing: it adds nothing to the inertial acceleration, so the velocities through the
water obey the same equations, and with a log and v ≈ 0 the fit simply reconstructs water-relative
velocities (tests). A current that changes along the track (a gradient or a front) pushes the hull:
the accelerometers feel Aᵀċ while the sway through the water still averages to zero, and the lateral
accelerometer bias absorbs ċ — the failure the seed suspected (its Table 6, §5.1); GNSS velocity
aiding (channels v_north, v_east) in place of log and v ≈ 0 removes it.

The fit (modified Newton–Raphson = Gauss–Newton with step halving) minimises
J = ½ Σ_channels Σ_i ((y_i − ŷ_i)/σ)² with output sensitivities S from forward finite differences.
Bounds: ``"white"`` is the Cramér–Rao bound M⁻¹, M = Σ Sᵀ R⁻¹ S, with the stated σ — correct only
when the residuals are white with that σ. Here they are not: the pseudo-observations (v ≈ 0, w ≈ 0,
log = u) leave the wave-frequency motion in the residuals, a strongly coloured sequence, and the white
bound then covers a true bias only 0.69–0.80 of the time for b_p, b_q, b_az (tests). ``"coloured"``
(the default) is the correction of Morelli & Klein (1997, J. Guidance Control Dyn. 20(1) 74–80),
Cov = M⁻¹ [Σ_i Σ_j S_iᵀ R⁻¹ R̂_vv(i − j) R⁻¹ S_j] M⁻¹, with R̂_vv from the residual periodogram (per
channel) whose lowest band — emptied by the fit itself, and exactly where bias sensitivities live — is
refilled from the neighbouring band, and with Satterthwaite degrees of freedom so that intervals use
Student's t (see :func:`_coloured_covariance` for why, and for the variants that failed). Measured 95 %
coverage of the six biases on synthetic replicates: 0.925–0.985 (200, seeds 1000+, on which REFILL was
chosen), 0.90–0.965 and 0.93–0.98 (two independent sets of 200, seeds 9000+ and 9200+). A slowly varying observation error that a
data sheet states (a gyrocompass's wander, a vertical gyro's zero: ``Observation.drift``) is a trend the
fit absorbs into a bias and cannot see in its residuals; its effect G Σ Gᵀ is added to both bounds
(:func:`_drift_covariance`; on simulator records, vtrials/reduce/compat_records.py). Input noise (gyro and
accelerometer white noise integrated into random walks) is process noise that an output-error fit does
not model: it is not in either bound (a 0.003 °/s white gyro noise at 10 Hz drops the b_r coverage
to 0.88; with navigation-grade 0.0005 °/s, as in the tests, it is negligible).

Identifiability (a physical fact worth knowing before reading any bias): on a steady heading a
longitudinal accelerometer bias is indistinguishable from a pitch offset (b_ax ≡ −g cos θ δθ) and a
lateral one from a roll offset (b_ay ≡ g cos θ cos φ δφ). If the mean attitude pseudo-observation is
derived from the same accelerometers (:func:`accelerometer_attitude`, as in the seed), the bias is
absorbed by the attitude and only the combinations ``b_ax + g cos θ̄ θ̄`` and
``b_ay − g cos θ̄ cos φ̄ φ̄`` are determined (:func:`invariant_combinations`). A turn, or an independent
mean-attitude reference, separates them.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence

import numba as nb
import numpy as np

from vtrials.errors import InputError
from vtrials.reduce.estimate import Estimate
from vtrials.units import G

STATES = ("roll", "pitch", "heading", "u", "v", "w", "north", "east", "down")
EARTH_VELOCITIES = ("v_north", "v_east", "v_down")
CHANNELS = STATES + EARTH_VELOCITIES
PARAMETERS = ("b_p", "b_q", "b_r", "b_ax", "b_ay", "b_az",
              "k_p", "k_q", "k_r", "k_ax", "k_ay", "k_az",
              "roll0", "pitch0", "heading0", "u0", "v0", "w0", "north0", "east0", "down0")
_INDEX = {n: i for i, n in enumerate(PARAMETERS)}
# finite-difference steps, in each parameter's own unit
_STEP = np.array([1e-6] * 3 + [1e-5] * 3 + [1e-6] * 6 + [1e-6] * 3 + [1e-5] * 3 + [1e-4] * 3)

ATTITUDE_PARAMETERS = ("b_p", "b_q", "b_r", "roll0", "pitch0", "heading0")
MOTION_PARAMETERS = ("b_ax", "b_ay", "b_az", "u0", "v0", "w0")
_ATTITUDE_CHANNELS = ("roll", "pitch", "heading")

_WHERE = "compat"
REFILL = 1.5  # lowest periodogram band refilled in the coloured-residual correction [2π/T]


@dataclasses.dataclass(frozen=True)
class ImuRecord:
    """Strapdown IMU record.

    time_s (N,) [s] strictly increasing; rates (N, 3) measured p, q, r [rad/s]; specific_force (N, 3)
    measured a_x, a_y, a_z [m/s²] (what an accelerometer reads: +g up the z axis at rest, i.e.
    f_z ≈ −g in z-down axes); offset (3,) accelerometer position from the centre of motion in body
    axes [m]; gravity [m/s²].
    """

    time_s: np.ndarray
    rates: np.ndarray
    specific_force: np.ndarray
    offset: np.ndarray = dataclasses.field(default_factory=lambda: np.zeros(3))
    gravity: float = G

    def __post_init__(self):
        t = np.asarray(self.time_s, dtype=float)
        if t.ndim != 1 or t.size < 10:
            raise InputError(_WHERE, "imu.time_s", f"needs a 1-D array of ≥ 10 samples, got shape {t.shape}")
        if not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0):
            raise InputError(_WHERE, "imu.time_s", "must be finite and strictly increasing")
        for name in ("rates", "specific_force"):
            a = np.asarray(getattr(self, name), dtype=float)
            if a.shape != (t.size, 3):
                raise InputError(_WHERE, f"imu.{name}", f"shape {a.shape}; allowed: ({t.size}, 3)")
            if not np.all(np.isfinite(a)):
                raise InputError(_WHERE, f"imu.{name}", "contains non-finite values; allowed: finite numbers")
            object.__setattr__(self, name, a)
        off = np.asarray(self.offset, dtype=float)
        if off.shape != (3,) or not np.all(np.isfinite(off)):
            raise InputError(_WHERE, "imu.offset", f"value {self.offset!r}; allowed: 3 finite numbers [m]")
        if not (self.gravity > 0 and math.isfinite(self.gravity)):
            raise InputError(_WHERE, "imu.gravity", f"value {self.gravity!r}; allowed: > 0 m/s²")
        object.__setattr__(self, "time_s", t)
        object.__setattr__(self, "offset", off)


@dataclasses.dataclass(frozen=True)
class Observation:
    """One observed (or assumed) channel for the fit.

    values: (N,) on the IMU time grid (NaN = not observed at that sample), or, with ``average=True``,
    one number compared with the record mean of the modelled channel (e.g. a mean heel from an
    inclinometer). sigma: the stated standard deviation of one value [channel unit, SI].
    drift: (sd, τ) of a slowly varying error of the channel that its data sheet states (first-order
    Gauss–Markov, e.g. a gyrocompass's wander): over a short record it is a near-linear trend that the
    fit absorbs into a bias (a heading trend is a yaw-rate bias), invisible in the residuals, so its
    effect G Σ Gᵀ (G = M⁻¹ Sᵀ R⁻¹ of that channel, Σ_ij = sd² exp(−|t_i − t_j|/τ)) is added to the
    bound (:func:`compat_fit`).
    """

    values: np.ndarray | float
    sigma: float
    average: bool = False
    drift: tuple[float, float] | None = None


@dataclasses.dataclass(frozen=True)
class CompatResult:
    """Outcome of one output-error fit.

    free: names of the estimated parameters (order of ``std``, ``covariance``, ``correlation``);
    parameters: every parameter's value (estimated or held); std: the chosen bound (1σ) per free
    parameter; dof: Satterthwaite degrees of freedom of each coloured bound (∞ for white);
    bound_kind: ``"white"`` or ``"coloured"``; covariance / covariance_white /
    covariance_coloured; correlation; residuals: channel → y − ŷ; states (N, 9) in the order of
    ``STATES``; rates (N, 3) corrected p, q, r; acceleration (N, 3) corrected body acceleration of the
    centre of motion (gravity removed); iterations; cost J; converged.
    """

    free: tuple[str, ...]
    parameters: dict
    std: np.ndarray
    dof: np.ndarray
    bound_kind: str
    covariance: np.ndarray
    covariance_white: np.ndarray
    covariance_coloured: np.ndarray
    correlation: np.ndarray
    residuals: dict
    states: np.ndarray
    rates: np.ndarray
    acceleration: np.ndarray
    iterations: int
    cost: float
    converged: bool

    def estimate(self, name: str) -> Estimate:
        """A free parameter as value ± bound with its degrees of freedom (t interval)."""
        i = self.free.index(name)
        d = float(self.dof[i])
        return Estimate(float(self.parameters[name]), float(self.std[i]), None if not math.isfinite(d) else d)


@dataclasses.dataclass(frozen=True)
class TwoStageResult:
    """Attitude stage, motion stage, and the joint covariance of (attitude free + motion free)
    parameters with the attitude-stage uncertainty propagated into the motion stage."""

    attitude: CompatResult
    motion: CompatResult
    free: tuple[str, ...]
    covariance: np.ndarray

    @property
    def std(self) -> np.ndarray:
        return np.sqrt(np.diag(self.covariance))

    def estimate(self, name: str) -> Estimate:
        """A parameter of either stage with its propagated bound; degrees of freedom those of the
        stage that estimated it."""
        i = self.free.index(name)
        stage = self.attitude if name in self.attitude.free else self.motion
        d = float(stage.dof[stage.free.index(name)])
        return Estimate(float(self.motion.parameters[name]), float(self.std[i]), None if not math.isfinite(d) else d)


def rate_derivative(time_s: np.ndarray, rates: np.ndarray) -> np.ndarray:
    """Angular acceleration from sampled rates [rad/s²]: fourth-order central differences
    (f₋₂ − 8f₋₁ + 8f₁ − f₂)/(12Δt) on a uniform grid, second-order ones next to the ends and on a
    non-uniform grid."""
    t = np.asarray(time_s, float)
    w = np.asarray(rates, float)
    d = np.gradient(w, t, axis=0, edge_order=2)
    dt = np.diff(t)
    if t.size >= 5 and np.allclose(dt, dt[0], rtol=1e-9, atol=0.0):
        d[2:-2] = (w[:-4] - 8 * w[1:-3] + 8 * w[3:-1] - w[4:]) / (12 * dt[0])
    return d


@nb.njit(cache=True)
def _derivative(x, w, acc_m, g, out):
    """Right-hand side of the kinematic equations for state x, corrected rates w and specific force
    at the centre of motion acc_m (gravity still in it)."""
    phi, th, psi, u, v, ww = x[0], x[1], x[2], x[3], x[4], x[5]
    p, q, r = w[0], w[1], w[2]
    sf, cf = math.sin(phi), math.cos(phi)
    st, ct = math.sin(th), math.cos(th)
    sp, cp = math.sin(psi), math.cos(psi)
    ax = acc_m[0] - g * st
    ay = acc_m[1] + g * ct * sf
    az = acc_m[2] + g * ct * cf
    out[0] = p + (q * sf + r * cf) * st / ct
    out[1] = q * cf - r * sf
    out[2] = (q * sf + r * cf) / ct
    out[3] = ax - q * ww + r * v
    out[4] = ay - r * u + p * ww
    out[5] = az - p * v + q * u
    out[6] = ct * cp * u + (sf * st * cp - cf * sp) * v + (cf * st * cp + sf * sp) * ww
    out[7] = ct * sp * u + (sf * st * sp + cf * cp) * v + (cf * st * sp - sf * cp) * ww
    out[8] = -st * u + ct * sf * v + ct * cf * ww


@nb.njit(cache=True)
def _corrected_inputs(rates_m, f_m, rdot_m, offset, par):
    """Bias/scale-corrected rates and the specific force transferred to the centre of motion."""
    n = rates_m.shape[0]
    w = np.empty((n, 3))
    f = np.empty((n, 3))
    for i in range(n):
        for k in range(3):
            w[i, k] = (rates_m[i, k] - par[k]) / (1.0 + par[6 + k])
        p, q, r = w[i, 0], w[i, 1], w[i, 2]
        pd = rdot_m[i, 0] / (1.0 + par[6])
        qd = rdot_m[i, 1] / (1.0 + par[7])
        rd = rdot_m[i, 2] / (1.0 + par[8])
        x, y, z = offset[0], offset[1], offset[2]
        # ω̇ × ρ + ω × (ω × ρ)
        tx = (qd * z - rd * y) + (q * (p * y - q * x) - r * (r * x - p * z))
        ty = (rd * x - pd * z) + (r * (q * z - r * y) - p * (p * y - q * x))
        tz = (pd * y - qd * x) + (p * (r * x - p * z) - q * (q * z - r * y))
        f[i, 0] = (f_m[i, 0] - par[3]) / (1.0 + par[9]) - tx
        f[i, 1] = (f_m[i, 1] - par[4]) / (1.0 + par[10]) - ty
        f[i, 2] = (f_m[i, 2] - par[5]) / (1.0 + par[11]) - tz
    return w, f


def _midpoints(t: np.ndarray, a: np.ndarray) -> np.ndarray:
    """Values at the interval midpoints: cubic (4-point Lagrange) interpolation inside, quadratic at
    the two end intervals; fourth-order accurate for smooth signals on a uniform grid."""
    t_mid = 0.5 * (t[1:] + t[:-1])
    out = np.empty((t.size - 1,) + a.shape[1:])
    n = t.size
    if n < 4:
        return 0.5 * (a[1:] + a[:-1])
    # interior intervals i = 1 … n−3 use samples i−1 … i+2
    i = np.arange(1, n - 2)
    nodes = np.stack([i - 1, i, i + 1, i + 2], axis=1)
    tt = t[nodes]
    x = t_mid[i]
    w = np.ones((i.size, 4))
    for j in range(4):
        for k in range(4):
            if k != j:
                w[:, j] *= (x - tt[:, k]) / (tt[:, j] - tt[:, k])
    out[i] = np.einsum("nj,nj...->n...", w, a[nodes])
    for i0, nd in ((0, (0, 1, 2)), (n - 2, (n - 3, n - 2, n - 1))):
        tt = t[list(nd)]
        x = t_mid[i0]
        acc = 0.0
        for j in range(3):
            wj = 1.0
            for k in range(3):
                if k != j:
                    wj *= (x - tt[k]) / (tt[j] - tt[k])
            acc = acc + wj * a[nd[j]]
        out[i0] = acc
    return out


@nb.njit(cache=True)
def _integrate(t, rates_m, f_m, rdot_m, rates_h, f_h, rdot_h, offset, g, par):
    """Classical Runge–Kutta on the sample grid, inputs at the half steps interpolated (cubic) from the
    samples → states (N, 9); global error O(Δt⁴) for smooth inputs."""
    n = t.shape[0]
    w, f = _corrected_inputs(rates_m, f_m, rdot_m, offset, par)
    wh, fh = _corrected_inputs(rates_h, f_h, rdot_h, offset, par)
    x = np.empty((n, 9))
    for k in range(9):
        x[0, k] = par[12 + k]
    k1 = np.empty(9)
    k2 = np.empty(9)
    k3 = np.empty(9)
    k4 = np.empty(9)
    xp = np.empty(9)
    for i in range(n - 1):
        h = t[i + 1] - t[i]
        _derivative(x[i], w[i], f[i], g, k1)
        for k in range(9):
            xp[k] = x[i, k] + 0.5 * h * k1[k]
        _derivative(xp, wh[i], fh[i], g, k2)
        for k in range(9):
            xp[k] = x[i, k] + 0.5 * h * k2[k]
        _derivative(xp, wh[i], fh[i], g, k3)
        for k in range(9):
            xp[k] = x[i, k] + h * k3[k]
        _derivative(xp, w[i + 1], f[i + 1], g, k4)
        for k in range(9):
            x[i + 1, k] = x[i, k] + h * (k1[k] + 2.0 * k2[k] + 2.0 * k3[k] + k4[k]) / 6.0
    return x


def _earth_velocity(x: np.ndarray) -> np.ndarray:
    phi, th, psi = x[:, 0], x[:, 1], x[:, 2]
    uvw = x[:, 3:6]
    return np.einsum("nij,nj->ni", rotation_body_to_earth(phi, th, psi), uvw)


def rotation_body_to_earth(roll, pitch, heading) -> np.ndarray:
    """A(φ, θ, ψ) = R_z(ψ) R_y(θ) R_x(φ), body → NED, shape (..., 3, 3)."""
    sf, cf = np.sin(roll), np.cos(roll)
    st, ct = np.sin(pitch), np.cos(pitch)
    sp, cp = np.sin(heading), np.cos(heading)
    return np.stack([
        np.stack([ct * cp, sf * st * cp - cf * sp, cf * st * cp + sf * sp], -1),
        np.stack([ct * sp, sf * st * sp + cf * cp, cf * st * sp - sf * cp], -1),
        np.stack([-st, ct * sf, ct * cf], -1)], -2)


def _outputs(x: np.ndarray, names: Sequence[str]) -> dict:
    out = {}
    ev = None
    for n in names:
        if n in EARTH_VELOCITIES:
            if ev is None:
                ev = _earth_velocity(x)
            out[n] = ev[:, EARTH_VELOCITIES.index(n)]
        else:
            out[n] = x[:, STATES.index(n)]
    return out


def _wrap(a):
    return (a + np.pi) % (2 * np.pi) - np.pi


def _check_observations(observations: Mapping[str, Observation], n: int) -> dict:
    if not observations:
        raise InputError(_WHERE, "observations", "empty; allowed: a mapping channel → Observation")
    obs = {}
    for name, o in observations.items():
        if name not in CHANNELS:
            raise InputError(_WHERE, f"observations.{name}", f"unknown channel; allowed: {', '.join(CHANNELS)}")
        if not isinstance(o, Observation):
            raise InputError(_WHERE, f"observations.{name}", f"value {o!r}; allowed: an Observation")
        if not (o.sigma > 0 and math.isfinite(o.sigma)):
            raise InputError(_WHERE, f"observations.{name}.sigma", f"value {o.sigma!r}; allowed: > 0")
        if o.average:
            try:
                v = float(o.values)
            except (TypeError, ValueError):
                v = math.nan
            if not math.isfinite(v):
                raise InputError(_WHERE, f"observations.{name}.values",
                                 f"value {o.values!r}; allowed: one finite number (average=True)")
            obs[name] = (v, float(o.sigma), True)
        else:
            v = np.asarray(o.values, dtype=float)
            if v.shape != (n,):
                raise InputError(_WHERE, f"observations.{name}.values",
                                 f"shape {v.shape}; allowed: ({n},) on the IMU time grid (NaN = missing)")
            if np.count_nonzero(np.isfinite(v)) < 2:
                raise InputError(_WHERE, f"observations.{name}.values", "fewer than 2 finite samples")
            obs[name] = (v, float(o.sigma), False)
        if o.drift is not None:
            sd, tau = (float(x) for x in o.drift)
            if o.average or not (sd >= 0 and math.isfinite(sd) and tau > 0 and math.isfinite(tau)):
                raise InputError(_WHERE, f"observations.{name}.drift", f"value {o.drift!r}; allowed: (sd ≥ 0, "
                                 f"tau > 0) on a per-sample channel")
    return obs


def _residual_blocks(x: np.ndarray, obs: dict) -> dict:
    """channel → residual array (per-sample, NaN where unobserved) or length-1 array (average)."""
    y = _outputs(x, list(obs))
    res = {}
    for name, (v, s, avg) in obs.items():
        if avg:
            d = v - np.mean(y[name])
            res[name] = np.array([_wrap(d) if name == "heading" else d])
        else:
            d = v - y[name]
            res[name] = _wrap(d) if name == "heading" else d
    return res


def _stack(res: dict, obs: dict) -> np.ndarray:
    parts = []
    for name, r in res.items():
        s = obs[name][1]
        parts.append(np.where(np.isfinite(r), r, 0.0) / s)
    return np.concatenate(parts)


class _Model:
    def __init__(self, imu: ImuRecord, obs: dict):
        self.t = imu.time_s
        self.w = imu.rates
        self.f = imu.specific_force
        self.rd = rate_derivative(imu.time_s, imu.rates)
        self.off = imu.offset
        self.g = float(imu.gravity)
        self.obs = obs
        self.wh = _midpoints(self.t, self.w)
        self.fh = _midpoints(self.t, self.f)
        self.rdh = _midpoints(self.t, self.rd)

    def states(self, par):
        return _integrate(self.t, self.w, self.f, self.rd, self.wh, self.fh, self.rdh, self.off, self.g, par)

    def residuals(self, par):
        x = self.states(par)
        return x, _residual_blocks(x, self.obs)

    def sensitivities(self, par, idx):
        """Output sensitivities ∂ŷ/∂θ per channel (forward differences; the outputs are close to
        linear in biases and initial states, steps in _STEP): channel → (n_rows, len(idx))."""
        sens = {name: [] for name in self.obs}
        r0 = _residual_blocks(self.states(par), self.obs)
        for j in idx:
            h = _STEP[j]
            pp = par.copy()
            pp[j] += h
            rp = _residual_blocks(self.states(pp), self.obs)
            for name in self.obs:
                d = rp[name] - r0[name]
                if name == "heading":
                    d = _wrap(d)
                sens[name].append(-d / h)  # residual = y − ŷ
        return {k: np.stack(v, axis=1) for k, v in sens.items()}


def _information(sens: dict, obs: dict, res: dict) -> tuple[np.ndarray, np.ndarray]:
    """M = Σ Sᵀ R⁻¹ S and the gradient Σ Sᵀ R⁻¹ r (missing samples carry no weight)."""
    npar = next(iter(sens.values())).shape[1]
    m = np.zeros((npar, npar))
    grad = np.zeros(npar)
    for name, s in sens.items():
        r = res[name]
        ok = np.isfinite(r)
        sw = s[ok] / obs[name][1] ** 2
        m += s[ok].T @ sw
        grad += sw.T @ r[ok]
    return m, grad


def _residual_spectrum(v: np.ndarray, L: int, refill: float) -> tuple[np.ndarray, np.ndarray, float]:
    """Periodogram |V(ω)|²/n of a residual sequence on the rfft grid of length L (zero-padded), with
    the band |ω| < refill·2π/T replaced by the mean Hann-tapered periodogram over
    refill·2π/T ≤ |ω| < 2·refill·2π/T. Returns (spectrum, mask of the refilled band, its dof).

    The fit makes the residuals orthogonal to the sensitivities; bias and initial-state sensitivities
    (constants, ramps) live in the lowest frequency band, so the fit empties the periodogram exactly
    there. Used as is (all lags), the bound of a bias came out about half the true scatter even for
    white residuals; the neighbouring band has not been emptied and estimates the level. The taper keeps
    the leakage of the wave peak out of that estimate. refill = 1.5 (REFILL) was chosen on the 200 synthetic
    replicates of tests/test_reduce_compat.py: coverage 0.925–0.985 for the six biases; refill = 1 and
    refill = 2 both gave 0.995 for b_p (wide bounds from few reference ordinates, few dof)."""
    n = v.size
    spec = np.abs(np.fft.rfft(v, n=L)) ** 2 / n
    k = np.arange(spec.size) * n / L  # frequency in units of 2π/T
    low = k < refill
    band = (k >= refill) & (k < 2 * refill)
    taper = np.hanning(n)
    tapered = np.abs(np.fft.rfft(v * taper, n=L)) ** 2 / np.sum(taper ** 2)
    spec[low] = tapered[band].mean()
    return spec, low, 2.0 * refill


def _coloured_covariance(sens: dict, obs: dict, res: dict, cov_w: np.ndarray, refill: float
                         ) -> tuple[np.ndarray, np.ndarray]:
    """Coloured-residual covariance M⁻¹ [Σ_i Σ_j S_iᵀ R⁻¹ R_vv(i − j) R⁻¹ S_j] M⁻¹ (Morelli & Klein
    1997, per channel, cross-channel correlation neglected) and the Satterthwaite degrees of freedom
    of each parameter's variance.

    R_vv is the sample autocorrelation over all lags, evaluated exactly in the frequency domain
    (zero-padded FFT, L ≥ 2N): Σ_f |A_f|² P_f / L with A the DFT of the weighted sensitivities and P the
    residual periodogram whose lowest band is refilled (:func:`_residual_spectrum`). A variance built
    from a handful of periodogram ordinates is itself uncertain: with independent ordinates
    (χ²₂ each; the refilled band has 2·refill·… dof) the Satterthwaite (1946) approximation gives
    ν = 2 E[σ̂²]² / Var[σ̂²], and intervals should use Student's t with ν. Channels observed at fewer
    than 90 % of the samples (e.g. GNSS at 1 Hz on a 10 Hz grid) and averages count as white with the
    stated σ and exact (ν = ∞).

    Alternatives tried and rejected on the synthetic records of tests/test_reduce_compat.py: the raw
    periodogram (bias bounds about half the scatter), a Bartlett lag window (smears the wave peak to
    zero frequency: 2–3× too wide), an AIC-chosen autoregressive spectrum (cannot resolve the empty
    band below the wave spectrum: about 2× too wide), a wider refill band (too wide when the wave
    spectrum starts close to zero frequency)."""
    npar = cov_w.shape[0]
    middle = np.zeros((npar, npar))
    var_of_var = np.zeros(npar)
    for name, s in sens.items():
        r = res[name]
        sig = obs[name][1]
        if obs[name][2]:
            middle += np.outer(s[0], s[0]) / sig ** 2
            continue
        ok = np.isfinite(r)
        if ok.mean() < 0.9:
            sw = s[ok] / sig ** 2
            middle += sw.T @ sw * sig ** 2
            continue
        n = r.size
        L = 1 << int(math.ceil(math.log2(2 * n)))
        v = np.where(ok, r, 0.0)
        spec, low, dof_low = _residual_spectrum(v, L, refill)
        a_f = np.fft.rfft(np.where(ok[:, None], s, 0.0) / sig ** 2, n=L, axis=0)
        wts = np.full(L // 2 + 1, 2.0)
        wts[0] = wts[-1] = 1.0
        middle += np.real(np.einsum("f,fi,fj->ij", wts * spec, np.conj(a_f), a_f)) / L
        c = wts[:, None] * np.abs(a_f @ cov_w) ** 2 / L  # contribution per ordinate to each variance
        contrib = c * spec[:, None]
        pad = L / n
        var_of_var += pad * np.sum(contrib[~low] ** 2, axis=0) + 2.0 * np.sum(contrib[low], axis=0) ** 2 / dof_low
    cov = cov_w @ (0.5 * (middle + middle.T)) @ cov_w
    cov = 0.5 * (cov + cov.T)
    with np.errstate(divide="ignore"):
        dof = np.where(var_of_var > 0, 2.0 * np.diag(cov) ** 2 / np.maximum(var_of_var, 1e-300), np.inf)
    return cov, dof


def _drift_covariance(sens: dict, obs: dict, observations: Mapping[str, Observation], t: np.ndarray,
                      cov_w: np.ndarray) -> np.ndarray:
    """Σ_c G_c Σ_c G_cᵀ over the channels with a stated drift (see :class:`Observation`)."""
    npar = cov_w.shape[0]
    out = np.zeros((npar, npar))
    for name, o in observations.items():
        if o.drift is None or o.drift[0] == 0.0:
            continue
        sd, tau = (float(x) for x in o.drift)
        s = sens[name]
        ok = np.isfinite(obs[name][0])
        g = cov_w @ (np.where(ok[:, None], s, 0.0) / obs[name][1] ** 2).T  # (npar, N)
        out += sd ** 2 * g @ _exponential_kernel(t, np.ascontiguousarray(g.T), tau)
    return 0.5 * (out + out.T)


@nb.njit(cache=True)
def _exponential_kernel(t, x, tau):
    """Σ_j exp(−|t_i − t_j|/τ) x_j for every i, in O(N) by a forward and a backward first-order
    recursion (the kernel factors as exp(−(t_i − t_j)/τ) = Π of the one-step factors)."""
    n, m = x.shape
    fwd = np.empty((n, m))
    bwd = np.empty((n, m))
    fwd[0] = x[0]
    for i in range(1, n):
        a = math.exp(-(t[i] - t[i - 1]) / tau)
        fwd[i] = a * fwd[i - 1] + x[i]
    bwd[n - 1] = x[n - 1]
    for i in range(n - 2, -1, -1):
        a = math.exp(-(t[i + 1] - t[i]) / tau)
        bwd[i] = a * bwd[i + 1] + x[i]
    return fwd + bwd - x


def _parameter_vector(imu: ImuRecord, obs: dict, initial: Mapping[str, float] | None) -> np.ndarray:
    par = np.zeros(len(PARAMETERS))

    def first(name):
        if name in obs:
            v, _, avg = obs[name]
            if avg:
                return v
            ok = np.flatnonzero(np.isfinite(v))
            return float(v[ok[0]]) if ok.size else 0.0
        return 0.0

    par[_INDEX["roll0"]] = first("roll")
    par[_INDEX["pitch0"]] = first("pitch")
    par[_INDEX["heading0"]] = first("heading")
    par[_INDEX["u0"]] = first("u")
    par[_INDEX["north0"]] = first("north")
    par[_INDEX["east0"]] = first("east")
    for name, value in (initial or {}).items():
        if name not in _INDEX:
            raise InputError(_WHERE, f"initial.{name}", f"unknown parameter; allowed: {', '.join(PARAMETERS)}")
        if not math.isfinite(float(value)):
            raise InputError(_WHERE, f"initial.{name}", f"value {value!r}; allowed: finite")
        par[_INDEX[name]] = float(value)
    return par


def compat_fit(imu: ImuRecord, observations: Mapping[str, Observation], free: Sequence[str],
               initial: Mapping[str, float] | None = None, bounds: str = "coloured",
               max_iterations: int = 30, tolerance: float = 1e-3, refill: float = REFILL) -> CompatResult:
    """Output-error data-compatibility fit (modified Newton–Raphson).

    free: parameter names to estimate (from :data:`PARAMETERS`); all others are held at ``initial``
    (default: 0 for biases and scale factors; first observed value for initial states that are
    observed, else 0). bounds: ``"coloured"`` (Morelli–Klein, default) or ``"white"`` (raw M⁻¹).
    Converged when every parameter step is below ``tolerance`` × its white bound.
    """
    n = imu.time_s.size
    obs = _check_observations(observations, n)
    if not (0.0 < refill <= 10.0):
        raise InputError(_WHERE, "refill", f"value {refill!r}; allowed: 0 < refill ≤ 10 (units of 2π/T)")
    if bounds not in ("white", "coloured"):
        raise InputError(_WHERE, "bounds", f"value {bounds!r}; allowed: 'white', 'coloured'")
    free = tuple(free)
    if not free:
        raise InputError(_WHERE, "free", "empty; allowed: names from PARAMETERS")
    for name in free:
        if name not in _INDEX:
            raise InputError(_WHERE, "free", f"unknown parameter {name!r}; allowed: {', '.join(PARAMETERS)}")
    if len(set(free)) != len(free):
        raise InputError(_WHERE, "free", f"value {free!r} repeats a name")
    if not (isinstance(max_iterations, int) and max_iterations >= 1):
        raise InputError(_WHERE, "max_iterations", f"value {max_iterations!r}; allowed: integer ≥ 1")
    idx = [_INDEX[k] for k in free]
    model = _Model(imu, obs)
    par = _parameter_vector(imu, obs, initial)

    x, res = model.residuals(par)
    cost = 0.5 * float(np.sum(_stack(res, obs) ** 2))
    converged = False
    it = 0
    for it in range(1, max_iterations + 1):
        sens = model.sensitivities(par, idx)
        m, grad = _information(sens, obs, res)
        try:
            step = np.linalg.solve(m, grad)
            cov_w = np.linalg.inv(m)
        except np.linalg.LinAlgError as exc:
            raise InputError(_WHERE, "free", f"parameters {free} are not identifiable from the observed "
                             f"channels {tuple(obs)} (singular information matrix)") from exc
        # step halving until the cost does not increase
        lam = 1.0
        for _ in range(20):
            trial = par.copy()
            trial[idx] += lam * step
            xt, rt = model.residuals(trial)
            ct = 0.5 * float(np.sum(_stack(rt, obs) ** 2))
            if ct <= cost * (1 + 1e-12):
                break
            lam *= 0.5
        par, x, res, cost = trial, xt, rt, ct
        small = np.all(np.abs(lam * step) <= tolerance * np.sqrt(np.abs(np.diag(cov_w))))
        if small:
            converged = True
            break

    if not converged:
        sens = model.sensitivities(par, idx)
    # (when converged the last step was below tolerance × bound: the sensitivities of that iteration
    # stand for the final point)
    m, _ = _information(sens, obs, res)
    cov_w = np.linalg.inv(m)
    cov_c, dof_c = _coloured_covariance(sens, obs, res, cov_w, refill)
    cov_d = _drift_covariance(sens, obs, observations, imu.time_s, cov_w)
    cov_c = cov_c + cov_d
    cov = cov_c if bounds == "coloured" else cov_w + cov_d
    std = np.sqrt(np.diag(cov))
    dof = dof_c if bounds == "coloured" else np.full(std.size, np.inf)
    corr = cov / np.outer(std, std)
    w, f = _corrected_inputs(model.w, model.f, model.rd, model.off, par)
    st, ct_ = np.sin(x[:, 1]), np.cos(x[:, 1])
    grav = model.g * np.stack([-st, ct_ * np.sin(x[:, 0]), ct_ * np.cos(x[:, 0])], axis=1)
    return CompatResult(free=free, parameters={k: float(par[i]) for k, i in _INDEX.items()}, std=std,
                        dof=dof, bound_kind=bounds, covariance=cov, covariance_white=cov_w, covariance_coloured=cov_c,
                        correlation=corr, residuals=res, states=x, rates=w, acceleration=f + grav,
                        iterations=it, cost=cost, converged=converged)


def two_stage_fit(imu: ImuRecord, observations: Mapping[str, Observation],
                  attitude_free: Sequence[str] = ATTITUDE_PARAMETERS,
                  motion_free: Sequence[str] = MOTION_PARAMETERS,
                  initial: Mapping[str, float] | None = None, bounds: str = "coloured") -> TwoStageResult:
    """The seed's two-stage procedure: (1) attitude parameters from the attitude channels (roll,
    pitch, heading); (2) with those held, the motion parameters from the remaining channels.

    The joint covariance propagates the stage-1 uncertainty into stage 2 (two-step estimation):
    δθ₂ = G δθ₁ + (stage-2 error at fixed θ₁), G = −M₂⁻¹ S₂ᵀR⁻¹ S₂₁ with S₂₁ the sensitivity of the
    stage-2 outputs to the stage-1 parameters; the observation sets of the two stages are treated as
    independent. Cov = [[C₁, C₁Gᵀ], [G C₁, C₂ + G C₁ Gᵀ]].
    """
    att_obs = {k: v for k, v in observations.items() if k in _ATTITUDE_CHANNELS}
    mot_obs = {k: v for k, v in observations.items() if k not in _ATTITUDE_CHANNELS}
    if not att_obs:
        raise InputError(_WHERE, "observations", "two-stage fit needs at least one of roll, pitch, heading")
    if not mot_obs:
        raise InputError(_WHERE, "observations", "two-stage fit needs at least one non-attitude channel")
    first = compat_fit(imu, att_obs, attitude_free, initial=initial, bounds=bounds)
    held = dict(initial or {})
    held.update({k: first.parameters[k] for k in attitude_free})
    second = compat_fit(imu, mot_obs, motion_free, initial=held, bounds=bounds)
    # propagation of stage-1 uncertainty
    n = imu.time_s.size
    obs2 = _check_observations(mot_obs, n)
    model = _Model(imu, obs2)
    par = np.array([second.parameters[k] for k in PARAMETERS])
    _, res2 = model.residuals(par)
    s21 = model.sensitivities(par, [_INDEX[k] for k in attitude_free])
    s2 = model.sensitivities(par, [_INDEX[k] for k in motion_free])
    cross = np.zeros((len(motion_free), len(attitude_free)))
    for name in obs2:
        ok = np.isfinite(res2[name])
        cross += s2[name][ok].T @ s21[name][ok] / obs2[name][1] ** 2
    g_mat = -second.covariance_white @ cross
    c1 = first.covariance
    c2 = second.covariance
    top = np.hstack([c1, c1 @ g_mat.T])
    bottom = np.hstack([g_mat @ c1, c2 + g_mat @ c1 @ g_mat.T])
    cov = np.vstack([top, bottom])
    return TwoStageResult(attitude=first, motion=second, free=tuple(attitude_free) + tuple(motion_free),
                          covariance=0.5 * (cov + cov.T))


def accelerometer_attitude(imu: ImuRecord, speed: np.ndarray | float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Roll and pitch "attitudes" from the specific force (the seed's mean-attitude pseudo-observation,
    §3.2). With z down, at rest f = (g sin θ, −g cos θ sin φ, −g cos θ cos φ), so
    θ_m = asin(f_x/g) and φ_m = −asin(f_y/(g cos θ_m)).

    If ``speed`` (log speed [m/s], scalar or (N,)) is given, the steady-turn centripetal term r·u in
    a_y is removed first. Returns (roll, pitch) [rad] per sample; wave accelerations remain in them,
    so fit a line or take the mean before using them as observations. Accelerometer biases pass
    straight into these attitudes (see the module note on identifiability).
    """
    g = imu.gravity
    fx = imu.specific_force[:, 0]
    fy = imu.specific_force[:, 1]
    if speed is not None:
        u = np.broadcast_to(np.asarray(speed, float), fx.shape)
        fy = fy - imu.rates[:, 2] * u
    pitch = np.arcsin(np.clip(fx / g, -1, 1))
    roll = -np.arcsin(np.clip(fy / (g * np.cos(pitch)), -1, 1))
    return roll, pitch


def invariant_combinations(parameters: Mapping[str, float], states: np.ndarray,
                           gravity: float = G) -> tuple[float, float]:
    """(b_ax + g cos θ̄ θ̄, b_ay − g cos θ̄ cos φ̄ φ̄): the combinations of horizontal accelerometer
    bias and mean attitude that a steady-heading record determines whatever the attitude reference
    (first-order in the mean angles; see the module note)."""
    phi = float(np.mean(states[:, 0]))
    th = float(np.mean(states[:, 1]))
    return (parameters["b_ax"] + gravity * math.cos(th) * th,
            parameters["b_ay"] - gravity * math.cos(th) * math.cos(phi) * phi)
