"""A synthetic ship for the wave-estimation tests: closed-form RAOs of plausible shape and linear responses.

Not a seakeeping model of any vessel: the shapes follow the long-wave limits and the wavelength
filtering of a uniform box (the κ = kL cos μ/2 functions of Jensen, Mansour & Olsen 2004, Ocean Eng.
31:359–389, in spirit), times a single-degree-of-freedom resonance in the encounter frequency. Heave
[m/m], pitch [rad/m], roll [rad/m]; μ is the wave propagation direction relative to the heading
(0 following, π head seas); roll is antisymmetric in μ.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from vtrials.units import G


@dataclasses.dataclass(frozen=True)
class SyntheticShip:
    L: float = 100.0  # [m]
    B: float = 14.0
    T: float = 4.5
    w3: float = 1.05  # heave natural frequency [rad/s]
    z3: float = 0.30  # heave damping ratio
    w5: float = 1.10
    z5: float = 0.30
    w4: float = 0.60  # roll
    z4: float = 0.10
    pitch_gain: float = 1.0  # scales the pitch RAO (a design-stage model may differ)

    def rao(self, omega, mu, U):
        """Complex RAOs (3, …) heave, pitch, roll at wave frequency ω [rad/s], relative direction μ [rad], U [m/s]."""
        w = np.asarray(omega, dtype=float)
        mu = np.asarray(mu, dtype=float)
        k = w * w / G
        we = w - k * U * np.cos(mu)
        att = np.exp(-0.5 * k * self.T)
        kl = 0.5 * k * self.L * np.cos(mu)
        kb = 0.5 * k * self.B * np.sin(mu)
        f3 = np.sinc(kl / math.pi)  # sin κ/κ
        safe = np.where(np.abs(kl) < 1e-6, 1e-6, kl)
        f5 = np.where(np.abs(kl) < 1e-6, 1.0, 3.0 * (np.sin(safe) - safe * np.cos(safe)) / safe ** 3)
        f4 = np.sinc(kb / math.pi)

        def res(wn, z):
            x = we / wn
            return 1.0 / (1.0 - x * x + 2j * z * x)

        heave = att * f3 * res(self.w3, self.z3)
        pitch = self.pitch_gain * 1j * k * np.cos(mu) * att * f5 * res(self.w5, self.z5)
        roll = 1j * k * np.sin(mu) * att * f4 * res(self.w4, self.z4) * 1.5
        return np.stack([heave, pitch, roll])


def responses(ship: SyntheticShip, components, heading: float, U: float, t):
    """Heave, pitch, roll records (3, n_t) of the ship at speed U [m/s] on heading [rad] (towards, from north),
    passing the origin at t = 0, in a realized seaway's components (n, 6) [a, ω, k, cos μ, sin μ, ε]."""
    a, w, k = components[:, 0], components[:, 1], components[:, 2]
    mu_abs = np.arctan2(components[:, 4], components[:, 3])
    mu = mu_abs - heading
    we = w - k * U * np.cos(mu)
    H = ship.rao(w, mu, U)  # (3, n)
    ph = np.exp(1j * (np.outer(t, we) + components[None, :, 5]))  # (n_t, n)
    return np.real(ph @ (a[:, None] * H.T)).T
