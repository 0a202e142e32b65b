"""Heave displacement from accelerometers: orientation correction and FFT double integration.

Axes: north-east-down earth axes, body axes x forward, y starboard, z down, Euler angles roll φ, pitch
θ (ZYX convention; the body → earth rotation R = R_z(ψ) R_y(θ) R_x(φ)). An accelerometer triad reads
the specific force f_b = Rᵀ(a − g e_D) [m/s²] (at rest, level: f_b = (0, 0, −g)).

* Orientation-corrected (strapdown with roll and pitch, e.g. from the motion package or an AHRS):
  the earth-down acceleration is a_D = f_D + g, f_D = −sin θ f_x + cos θ sin φ f_y + cos θ cos φ f_z
  (the third row of R; yaw does not enter).
* 1-D (hull-fixed single accelerometer along body z, treated as vertical): a_D ≈ f_z + g. The tilt
  error is second order in the tilt for the first-order wave motion, but its slow part (the wave-group
  modulation of g(1 − cos tilt) and of the tilt × horizontal-acceleration products) is amplified by
  1/ω² in the double integration; Bender, Guinasso, Walpert & Howden (2010, J. Atmos. Oceanic Technol.
  27:1012–1028) report that the 1-D method overestimated H_s by about 26 % against a 3-D strapdown
  method on a 3-m discus buoy in hurricane seas (figure quoted from the issue; the size here depends
  on steepness and the high-pass corner — tests/test_reduce_heave.py measures it).
* Double integration in the frequency domain: X(ω) = −A(ω)/ω² for ω above the high-pass corner ω_c,
  with a half-cosine taper from ω_c/2 to ω_c and zero below (the mean and drift of a doubly integrated
  signal are unobservable; the taper limits ringing). The record is treated as periodic (a Hann-tapered
  record ends can be used by the caller); heave positive UP is returned.
"""

from __future__ import annotations

import math

import numpy as np

from vtrials.errors import InputError
from vtrials.units import G


def vertical_acceleration(f_x, f_y, f_z, roll, pitch):
    """Earth-down acceleration a_D = f_D + g [m/s²] from body specific forces f [m/s²] and roll, pitch [rad]."""
    f_x, f_y, f_z, roll, pitch = (np.asarray(v, dtype=float) for v in (f_x, f_y, f_z, roll, pitch))
    f_d = -np.sin(pitch) * f_x + np.cos(pitch) * np.sin(roll) * f_y + np.cos(pitch) * np.cos(roll) * f_z
    return f_d + G


def double_integrate(acc, fs: float, omega_c: float):
    """Displacement [m] from acceleration [m/s²] sampled at fs [Hz] by FFT, high-pass at omega_c [rad/s].

    Gain −1/ω² above ω_c, half-cosine taper between ω_c/2 and ω_c, zero below (module doc).
    """
    acc = np.asarray(acc, dtype=float)
    if acc.ndim != 1 or acc.size < 16:
        raise InputError("record", "acc", f"must be a 1-D array of at least 16 samples, got shape {acc.shape}")
    if not (math.isfinite(fs) and fs > 0.0):
        raise InputError("record", "fs", f"sampling rate {fs!r} Hz: must be a finite number > 0")
    nyq = math.pi * fs
    if not (0.0 < omega_c < nyq):
        raise InputError("record", "omega_c", f"high-pass corner {omega_c!r} rad/s: must be in (0, {nyq:g}) rad/s")
    n = acc.size
    A = np.fft.rfft(acc - acc.mean())
    w = 2.0 * math.pi * np.fft.rfftfreq(n, 1.0 / fs)
    taper = np.clip((w - 0.5 * omega_c) / (0.5 * omega_c), 0.0, 1.0)
    taper = 0.5 - 0.5 * np.cos(math.pi * taper)
    gain = np.zeros_like(w)
    pos = w > 0.0
    gain[pos] = -taper[pos] / (w[pos] * w[pos])
    return np.fft.irfft(A * gain, n)


def heave_from_accelerometers(f_x, f_y, f_z, roll, pitch, fs: float, omega_c: float):
    """Heave UP [m] from a body accelerometer triad and roll, pitch [rad] (orientation-corrected)."""
    return -double_integrate(vertical_acceleration(f_x, f_y, f_z, roll, pitch), fs, omega_c)


def heave_from_hull_accelerometer(f_z, fs: float, omega_c: float):
    """Heave UP [m] from a single hull-fixed accelerometer along body z, taken as vertical (the 1-D method)."""
    return -double_integrate(np.asarray(f_z, dtype=float) + G, fs, omega_c)
