"""Aided inertial navigation in the horizontal plane: extended Kalman filter + RTS smoother.

State (SI): ``x, y`` position of the reference point (where the IMU is) (earth axes, x north, y east), ``psi``
heading (rad, clockwise from north), ``u, v`` body velocity, ``r`` yaw rate, ``rdot`` yaw
acceleration, ``b_fx, b_fy`` accelerometer biases (m/s²), ``b_g`` gyro bias (rad/s).

Process (strapdown in the plane, IMU at the reference point, ship level): u̇ = f_x − b_fx + r v,
v̇ = f_y − b_fy − r u (specific force f measured by the IMU is the process input, integrated by the
midpoint rule with the step's mean specific force), ṙ = rdot,
rdot driven by white jerk (integrated random walk, Bar-Shalom, Li & Kirubarajan 2001 §6.2),
biases are random walks. The z-gyro is a measurement at the IMU rate: r_m = r + b_g + noise.
Aiding: position fixes (GNSS / range positioning), body velocity (Doppler log: u, v), surge (EM log:
u), heading (gyrocompass), each with white noise of stated standard deviation at its own instants.

Filter: EKF (Gelb 1974, ch. 6); smoother: Rauch, Tung & Striebel (1965) AIAA J. 3(8):1445.
Aiding instants are applied at the nearest IMU sample (timing error ≤ half the IMU period).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from vtrials.errors import InputError

_WHERE = "vtrials.sysid.navfilter"

STATES = ("x", "y", "psi", "u", "v", "r", "rdot", "b_fx", "b_fy", "b_g")
_KINDS = {"position": (0, 1), "velocity": (3, 4), "surge": (3,), "heading": (2,)}


@dataclasses.dataclass(frozen=True)
class ImuNoise:
    """IMU error model: white noise per sample and bias random walks; process model tuning."""

    accel_sigma: float = 0.005        # white noise of one specific-force sample, m/s²
    gyro_sigma: float = 3e-4          # white noise of one yaw-rate sample, rad/s
    accel_bias_rw: float = 1e-5       # accelerometer bias random walk, m/s² /√s
    gyro_bias_rw: float = 1e-6        # gyro bias random walk, rad/s /√s
    jerk_psd: float = 1e-5            # white yaw jerk spectral density, (rad/s³)² s
    accel_bias0: float = 0.01         # prior σ of the accelerometer biases, m/s²
    gyro_bias0: float = 1e-3          # prior σ of the gyro bias, rad/s


@dataclasses.dataclass(frozen=True)
class Aiding:
    """One aiding instrument's record: ``kind`` in position (x, y), velocity (u, v), surge (u),
    heading (psi); ``t`` (M,) s; ``z`` (M,) or (M, k) SI; ``sigma`` white-noise σ of each component
    (one value, or (M,) per fix: an error that grows with the motion, such as a time-stamp's);
    ``lever_arm`` (x, y) of the antenna / log transducer in body axes from the reference point, m
    (position: p + R(ψ) l; velocity: (u − r l_y, v + r l_x))."""

    kind: str
    t: np.ndarray
    z: np.ndarray
    sigma: float | np.ndarray
    lever_arm: tuple = (0.0, 0.0)


@dataclasses.dataclass(frozen=True)
class NavSolution:
    """Smoothed states ``x`` (N, 10) with covariances ``P`` (N, 10, 10) at the IMU instants ``t``;
    accelerations ``acc`` (N, 3) = (u̇, v̇, ṙ) with standard deviations ``acc_sigma``; filtered
    (forward-only) states ``x_filt`` for comparison."""

    t: np.ndarray
    x: np.ndarray
    P: np.ndarray
    acc: np.ndarray
    acc_sigma: np.ndarray
    x_filt: np.ndarray

    def state(self, name: str) -> np.ndarray:
        return self.x[:, STATES.index(name)]

    def sigma(self, name: str) -> np.ndarray:
        i = STATES.index(name)
        return np.sqrt(self.P[:, i, i])


def _deriv(x, f):
    """Time derivative of the state for specific force f = (f_x, f_y) at the reference point."""
    psi, u, v, r = x[2], x[3], x[4], x[5]
    c, sn = np.cos(psi), np.sin(psi)
    out = np.zeros_like(x)
    out[0], out[1], out[2] = u * c - v * sn, u * sn + v * c, r
    out[3], out[4], out[5] = f[0] - x[7] + r * v, f[1] - x[8] - r * u, x[6]
    return out


def _measure(kind, x, arm, lag: float = 0.0):
    """Predicted measurement h(x) and its Jacobian H for one aiding kind with lever arm (lx, ly), taken
    ``lag`` seconds after the IMU sample the state is at (fixes fall between samples: at 20 Hz a fix
    put on the nearest sample is up to 25 ms off, 0.2 m along the track at 8 m/s and, in a turn, a
    false sway of r × U × 25 ms; so heading and position are carried over the lag to first order)."""
    lx, ly = arm
    H = np.zeros((len(_KINDS[kind]), len(STATES)))
    if kind == "heading":
        H[0, 2], H[0, 5] = 1.0, lag
        return np.array([x[2] + x[5] * lag]), H
    if kind == "position":
        c, sn = np.cos(x[2]), np.sin(x[2])
        w0, w1 = lx + lag * (x[3] - x[5] * ly), ly + lag * (x[4] + x[5] * lx)   # arm + lag × its velocity
        H[0, 0] = H[1, 1] = 1.0
        H[0, 2], H[1, 2] = -sn * w0 - c * w1, c * w0 - sn * w1
        H[0, 3], H[1, 3] = c * lag, sn * lag
        H[0, 4], H[1, 4] = -sn * lag, c * lag
        H[0, 5], H[1, 5] = lag * (-c * ly - sn * lx), lag * (-sn * ly + c * lx)
        return np.array([x[0] + c * w0 - sn * w1, x[1] + sn * w0 + c * w1]), H
    H[0, 3], H[0, 5] = 1.0, -ly
    if kind == "surge":
        return x[[3]] - x[5] * ly, H
    H[1, 4], H[1, 5] = 1.0, lx
    return np.array([x[3] - x[5] * ly, x[4] + x[5] * lx]), H


def _check(t, f, g, aiding):
    t = np.asarray(t, float)
    if t.ndim != 1 or t.size < 3 or not np.all(np.diff(t) > 0):
        raise InputError(_WHERE, "t_imu", f"needs ≥ 3 strictly increasing times, got shape {t.shape}")
    f = np.asarray(f, float)
    if f.shape != (t.size, 2):
        raise InputError(_WHERE, "specific_force", f"shape {f.shape}; allowed: ({t.size}, 2)")
    g = np.asarray(g, float)
    if g.shape != t.shape:
        raise InputError(_WHERE, "gyro_rate", f"shape {g.shape}; allowed: ({t.size},)")
    for a in aiding:
        if a.kind not in _KINDS:
            raise InputError(_WHERE, "aiding.kind", f"{a.kind!r}; allowed: {', '.join(_KINDS)}")
        sg = np.asarray(a.sigma, float)
        if sg.ndim > 1 or (sg.ndim == 1 and sg.size != np.size(a.t)) or not np.all(sg > 0):
            raise InputError(_WHERE, f"aiding[{a.kind}].sigma", f"{a.sigma}; allowed: > 0, one value or one per fix")
    return t, f, g


def smooth(t_imu, specific_force, gyro_rate, aiding, noise: ImuNoise = ImuNoise(),
           x0=None, P0_diag=None) -> NavSolution:
    """EKF forward pass and RTS backward pass over a record.

    ``specific_force`` (N, 2) body f_x, f_y in m/s²; ``gyro_rate`` (N,) rad/s; ``aiding`` a list of
    :class:`Aiding`. ``x0`` initial state (default: first position, heading and velocity fixes, zero
    rates and biases) and ``P0_diag`` its variances (default: the aiding σ², generous rate priors).
    The IMU must be at the reference point (or its specific force transferred there by the caller):
    IMU lever arms are not modelled (an attempt with the ṙ × l and r² l terms in the propagation
    gave large velocity errors in the tests, cause not established, and was removed).
    """
    t, f, g = _check(t_imu, specific_force, gyro_rate, aiding)
    N, n = t.size, len(STATES)
    dt_all = np.diff(t)
    # measurements per IMU sample
    events: dict[int, list] = {}
    for a in aiding:
        ta = np.asarray(a.t, float)
        z = np.asarray(a.z, float).reshape(ta.size, -1)
        idx = _KINDS[a.kind]
        if z.shape[1] != len(idx):
            raise InputError(_WHERE, f"aiding[{a.kind}].z", f"{z.shape[1]} components; allowed: {len(idx)}")
        k = np.searchsorted(t, ta)
        k = np.clip(k, 1, N - 1)
        k = np.where(np.abs(t[k - 1] - ta) <= np.abs(t[k] - ta), k - 1, k)
        inside = (ta >= t[0] - dt_all[0]) & (ta <= t[-1] + dt_all[-1])
        sg = np.broadcast_to(np.asarray(a.sigma, float), ta.shape)
        lag = ta - t[k]
        for kk, zz, ss, lg in zip(k[inside], z[inside], sg[inside], lag[inside]):
            events.setdefault(int(kk), []).append((zz, float(ss), a.kind, tuple(map(float, a.lever_arm)), float(lg)))
    if x0 is None:
        x0 = np.zeros(n)
        x0[5] = g[0]
        for a in sorted(aiding, key=lambda a: a.kind != "heading"):   # heading first: lever arms
            z = np.asarray(a.z, float).reshape(len(a.t), -1)
            x0[list(_KINDS[a.kind])] = z[0]
            h, _ = _measure(a.kind, x0, a.lever_arm)
            x0[list(_KINDS[a.kind])] += z[0] - h
    x = np.asarray(x0, float).copy()
    if P0_diag is None:
        sig = {i: float(np.median(a.sigma)) for a in aiding for i in _KINDS[a.kind]}
        P0_diag = np.array([sig.get(0, 10.0)**2, sig.get(1, 10.0)**2, sig.get(2, 0.1)**2,
                            sig.get(3, 1.0)**2, sig.get(4, 1.0)**2, noise.gyro_sigma**2 + noise.gyro_bias0**2,
                            1e-4, noise.accel_bias0**2, noise.accel_bias0**2, noise.gyro_bias0**2])
    P = np.diag(np.asarray(P0_diag, float))
    xf, Pf = np.empty((N, n)), np.empty((N, n, n))
    xp, Pp, Fs = np.empty((N, n)), np.empty((N, n, n)), np.empty((N, n, n))
    H_g = np.zeros(n)
    H_g[5], H_g[9] = 1.0, 1.0
    R_g = noise.gyro_sigma**2
    I = np.eye(n)
    for k in range(N):
        # gyro update (scalar)
        Ph = P @ H_g
        s = H_g @ Ph + R_g
        K = Ph / s
        x = x + K * (g[k] - x[5] - x[9])
        P = P - np.outer(K, Ph)
        for zz, sg, kind, arm, lag in events.get(k, ()):
            h, H = _measure(kind, x, arm, lag)
            innov = zz - h
            if kind == "heading":
                innov = (innov + np.pi) % (2 * np.pi) - np.pi
            PH = P @ H.T
            K = np.linalg.solve(H @ PH + sg**2 * np.eye(len(h)), PH.T).T
            x = x + K @ innov
            P = P - K @ PH.T
        P = 0.5 * (P + P.T)
        xf[k], Pf[k] = x, P
        if k == N - 1:
            break
        dt = dt_all[k]
        psi, u, v, r, rd = x[2], x[3], x[4], x[5], x[6]
        pm = psi + 0.5 * r * dt
        c, sn = np.cos(pm), np.sin(pm)
        fm = 0.5 * (f[k] + f[k + 1])
        F = I.copy()
        F[0, 2], F[0, 3], F[0, 4], F[0, 5] = dt * (-u * sn - v * c), dt * c, -dt * sn, dt * 0.5 * dt * (-u * sn - v * c)
        F[1, 2], F[1, 3], F[1, 4], F[1, 5] = dt * (u * c - v * sn), dt * sn, dt * c, dt * 0.5 * dt * (u * c - v * sn)
        F[2, 5], F[2, 6] = dt, 0.5 * dt * dt
        F[3, 4], F[3, 5], F[3, 7] = dt * r, dt * v, -dt
        F[4, 3], F[4, 5], F[4, 8] = -dt * r, -dt * u, -dt
        F[5, 6] = dt
        # midpoint rule (RK2); specific force at the step's start and mean over the step
        x = x + dt * _deriv(x + 0.5 * dt * _deriv(x, f[k]), fm)
        Q = np.zeros((n, n))
        Q[3, 3] = Q[4, 4] = (noise.accel_sigma * dt)**2
        qj = noise.jerk_psd
        Q[5, 5], Q[5, 6], Q[6, 6] = qj * dt**3 / 3, qj * dt**2 / 2, qj * dt
        Q[6, 5] = Q[5, 6]
        Q[7, 7] = Q[8, 8] = noise.accel_bias_rw**2 * dt
        Q[9, 9] = noise.gyro_bias_rw**2 * dt
        P = F @ P @ F.T + Q
        xp[k + 1], Pp[k + 1], Fs[k] = x, P, F
    # RTS backward pass
    xs, Ps = xf.copy(), Pf.copy()
    for k in range(N - 2, -1, -1):
        C = np.linalg.solve(Pp[k + 1], Fs[k] @ Pf[k]).T
        d = xs[k + 1] - xp[k + 1]
        xs[k] = xf[k] + C @ d
        Ps[k] = Pf[k] + C @ (Ps[k + 1] - Pp[k + 1]) @ C.T
    # accelerations and their σ (linearised, plus the accelerometer's white noise)
    u, v, r = xs[:, 3], xs[:, 4], xs[:, 5]
    acc = np.column_stack([f[:, 0] - xs[:, 7] + r * v, f[:, 1] - xs[:, 8] - r * u, xs[:, 6]])
    Ju = np.zeros((N, n))
    Ju[:, 4], Ju[:, 5], Ju[:, 7] = r, v, -1.0
    Jv = np.zeros((N, n))
    Jv[:, 3], Jv[:, 5], Jv[:, 8] = -r, -u, -1.0
    var_u = np.einsum("ki,kij,kj->k", Ju, Ps, Ju) + noise.accel_sigma**2
    var_v = np.einsum("ki,kij,kj->k", Jv, Ps, Jv) + noise.accel_sigma**2
    acc_sigma = np.sqrt(np.column_stack([var_u, var_v, Ps[:, 6, 6]]))
    return NavSolution(t=t, x=xs, P=Ps, acc=acc, acc_sigma=acc_sigma, x_filt=xf)
