"""Analytic 6-DOF ship motion for testing the motion-reconstruction reductions.

Euler angles and the body velocities through the water are sums of sinusoids (plus a mean, and a
constant yaw rate for a slow turn), so every derivative is closed-form. Body rates follow from the
Euler-angle rates, ω = (φ̇ − ψ̇ sin θ, θ̇ cos φ + ψ̇ cos θ sin φ, −θ̇ sin φ + ψ̇ cos θ cos φ), and their
derivatives by the chain rule. A current constant in earth axes adds Aᵀc to the ground velocity but
nothing to the inertial acceleration: d/dt(Aᵀc) = −ω × Aᵀc cancels the transport term; a current that
changes in time adds Aᵀċ. Independent of
vtrials.reduce (the code under test).
"""

from __future__ import annotations

import dataclasses

import numpy as np

G = 9.80665


@dataclasses.dataclass(frozen=True)
class Harmonics:
    """x(t) = mean + rate·t + Σ a_k sin(ω_k t + α_k)."""

    amp: np.ndarray
    omega: np.ndarray
    phase: np.ndarray
    mean: float = 0.0
    rate: float = 0.0

    def __call__(self, t):
        arg = np.outer(t, self.omega) + self.phase
        x = self.mean + self.rate * t + np.sin(arg) @ self.amp
        xd = self.rate + np.cos(arg) @ (self.amp * self.omega)
        xdd = -np.sin(arg) @ (self.amp * self.omega ** 2)
        return x, xd, xdd


def harmonics(rng, amps, omegas, mean=0.0, rate=0.0):
    amps = np.asarray(amps, float)
    return Harmonics(amps, np.asarray(omegas, float), rng.uniform(0, 2 * np.pi, amps.size), mean, rate)


def rotation(phi, th, psi):
    sf, cf, st, ct, sp, cp = np.sin(phi), np.cos(phi), np.sin(th), np.cos(th), np.sin(psi), np.cos(psi)
    return np.stack([
        np.stack([ct * cp, sf * st * cp - cf * sp, cf * st * cp + sf * sp], -1),
        np.stack([ct * sp, sf * st * sp + cf * cp, cf * st * sp - sf * cp], -1),
        np.stack([-st, ct * sf, ct * cf], -1)], -2)


@dataclasses.dataclass(frozen=True)
class Motion:
    t: np.ndarray
    euler: np.ndarray      # (N, 3) φ, θ, ψ
    omega: np.ndarray      # (N, 3) p, q, r
    omega_dot: np.ndarray  # (N, 3)
    v_water: np.ndarray    # (N, 3) body velocity through the water
    v_ground: np.ndarray   # (N, 3) body velocity over ground
    v_earth: np.ndarray    # (N, 3) NED ground velocity
    accel: np.ndarray      # (N, 3) inertial acceleration of the centre, body axes
    specific_force: np.ndarray  # (N, 3) at the centre

    def specific_force_at(self, rho):
        """Specific force at body point rho: f + ω̇×ρ + ω×(ω×ρ)."""
        rho = np.asarray(rho, float)
        w = self.omega
        return (self.specific_force + np.cross(self.omega_dot, rho)
                + np.cross(w, np.cross(w, np.broadcast_to(rho, w.shape))))


def motion(t, phi: Harmonics, theta: Harmonics, psi: Harmonics, u: Harmonics, v: Harmonics,
           w: Harmonics, current_ned=(0.0, 0.0, 0.0), current_rate=(0.0, 0.0, 0.0)) -> Motion:
    """Motion with a current c(t) = current_ned + current_rate·t (earth axes). A current that changes
    along the track (the ship crossing a current gradient) pushes the hull: the inertial acceleration
    gains Aᵀċ, while the velocity through the water stays the harmonic one."""
    (f, fd, fdd), (th, thd, thdd), (ps, psd, psdd) = phi(t), theta(t), psi(t)
    sf, cf, st, ct = np.sin(f), np.cos(f), np.sin(th), np.cos(th)
    p = fd - psd * st
    q = thd * cf + psd * ct * sf
    r = -thd * sf + psd * ct * cf
    pd = fdd - psdd * st - psd * thd * ct
    qd = thdd * cf - thd * fd * sf + psdd * ct * sf - psd * thd * st * sf + psd * fd * ct * cf
    rd = -thdd * sf - thd * fd * cf + psdd * ct * cf - psd * thd * st * cf - psd * fd * ct * sf
    om = np.stack([p, q, r], 1)
    omd = np.stack([pd, qd, rd], 1)
    (uu, ud, _), (vv, vd, _), (ww, wd, _) = u(t), v(t), w(t)
    vw = np.stack([uu, vv, ww], 1)
    vwd = np.stack([ud, vd, wd], 1)
    a = rotation(f, th, ps)
    cd = np.asarray(current_rate, float)
    c = np.asarray(current_ned, float) + np.outer(t, cd)
    vg = vw + np.einsum("nji,nj->ni", a, c)
    acc = vwd + np.cross(om, vw) + np.einsum("nji,j->ni", a, cd)
    gb = G * np.stack([-st, ct * sf, ct * cf], 1)
    return Motion(t=t, euler=np.stack([f, th, ps], 1), omega=om, omega_dot=omd, v_water=vw, v_ground=vg,
                  v_earth=np.einsum("nij,nj->ni", a, vg), accel=acc, specific_force=acc - gb)


def spectral(rng, rms, omega_peak, n=24, mean=0.0, rate=0.0, band=(0.5, 2.5)):
    """Random-phase harmonics with a Pierson–Moskowitz-shaped spectrum
    S(ω) ∝ ω⁻⁵ exp(−1.25 (ω_p/ω)⁴) on n equally spaced frequencies in band·ω_p (frequencies jittered
    within their bin so that no two records share a period), scaled to the given RMS."""
    lo, hi = band[0] * omega_peak, band[1] * omega_peak
    dw = (hi - lo) / n
    w = lo + dw * (np.arange(n) + rng.uniform(0.0, 1.0, n))
    s = w ** -5 * np.exp(-1.25 * (omega_peak / w) ** 4)
    amp = np.sqrt(2 * s * dw)
    amp *= rms / np.sqrt(np.sum(amp ** 2) / 2)
    return Harmonics(amp, w, rng.uniform(0, 2 * np.pi, n), mean, rate)
