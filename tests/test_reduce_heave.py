"""Heave from accelerometers: FFT double integration, orientation correction, and the 1-D tilt error.

Synthetic buoy records from a realized seaway (vtrials.physics.environment.waves): the buoy heaves with
the surface elevation η at its mooring point and tilts with the surface (its z axis along the surface
normal), optionally following the horizontal orbital acceleration too (a drifting surface follower); its
accelerometer triad reads f_b = Rᵀ(a − g e_D). The reference is η itself (H_s = 4 std η).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from vtrials.errors import InputError
from vtrials.physics.environment.waves import Waves, realize
from vtrials.reduce.heave import (double_integrate, heave_from_accelerometers, heave_from_hull_accelerometer,
                                  vertical_acceleration)
from vtrials.units import G

FS = 2.0


def _buoy(hs, tp, seed, follow_orbits, spreading_s=10.0, duration=1800.0):
    field = realize(Waves(hs_m=hs, tp_s=tp, spreading_s=spreading_s, n_components=300), math.inf,
                    np.random.default_rng(seed))
    c = field.components
    t = np.arange(0.0, duration, 1.0 / FS)
    th = c[None, :, 1] * t[:, None] + c[None, :, 5]  # the buoy at the origin
    a, w, k, cm, sm = c[:, 0], c[:, 1], c[:, 2], c[:, 3], c[:, 4]
    eta = np.cos(th) @ a
    eta_x = np.sin(th) @ (a * k * cm)  # ∂η/∂x (north)
    eta_y = np.sin(th) @ (a * k * sm)  # ∂η/∂y (east)
    acc_d = np.cos(th) @ (a * w * w)  # −η̈ (down)
    if follow_orbits:  # horizontal particle acceleration at the surface (Airy, linear)
        acc_n = -np.sin(th) @ (a * w * w * cm)
        acc_e = -np.sin(th) @ (a * w * w * sm)
    else:
        acc_n = acc_e = np.zeros_like(t)
    # body z (down) along the surface's downward normal (η_x, η_y, 1)/N: −sin φ = η_y/N, tan θ = η_x
    nrm = np.sqrt(1.0 + eta_x ** 2 + eta_y ** 2)
    roll = -np.arcsin(eta_y / nrm)
    pitch = np.arctan(eta_x)
    fe = np.stack([acc_n, acc_e, acc_d - G], axis=-1)
    cp, sp, cr, sr = np.cos(pitch), np.sin(pitch), np.cos(roll), np.sin(roll)
    # R = R_y(θ) R_x(φ) (ψ = 0), rows of Rᵀ are R's columns
    R = np.empty(t.shape + (3, 3))
    R[:, 0] = np.stack([cp, sp * sr, sp * cr], axis=-1)
    R[:, 1] = np.stack([0 * cp, cr, -sr], axis=-1)
    R[:, 2] = np.stack([-sp, cp * sr, cp * cr], axis=-1)
    fb = np.einsum("nji,nj->ni", R, fe)  # Rᵀ f_e
    return t, eta, fb, roll, pitch, field


def test_double_integration_of_a_sum_of_sines():
    t = np.arange(0.0, 1024.0, 1.0 / FS)
    x = 1.5 * np.sin(2 * math.pi * t / 8.0 + 0.3) + 0.7 * np.cos(2 * math.pi * t / 12.8)  # on the FFT grid
    acc = -1.5 * (2 * math.pi / 8.0) ** 2 * np.sin(2 * math.pi * t / 8.0 + 0.3) \
        - 0.7 * (2 * math.pi / 12.8) ** 2 * np.cos(2 * math.pi * t / 12.8)
    assert np.max(np.abs(double_integrate(acc, FS, 0.2) - x)) < 1e-9


def test_orientation_corrected_heave_recovers_the_surface():
    t, eta, fb, roll, pitch, field = _buoy(4.0, 9.0, 3, follow_orbits=True)
    az = vertical_acceleration(fb[:, 0], fb[:, 1], fb[:, 2], roll, pitch)
    c = field.components
    acc_d = np.cos(c[None, :, 1] * t[:, None] + c[None, :, 5]) @ (c[:, 0] * c[:, 1] ** 2)
    assert np.max(np.abs(az - acc_d)) < 1e-9  # the rotation is undone exactly
    h = heave_from_accelerometers(fb[:, 0], fb[:, 1], fb[:, 2], roll, pitch, FS, 0.25)
    hs_true = 4.0 * np.std(eta)
    hs_est = 4.0 * np.std(h)
    assert hs_est == pytest.approx(hs_true, rel=0.02)
    mid = slice(h.size // 10, -h.size // 10)  # the FFT treats the record as periodic: its ends ring
    print(f"heave error RMS (middle 80 %) {np.std(h[mid] - eta[mid]) / np.std(eta):.4f} of RMS heave")
    assert np.std(h[mid] - eta[mid]) < 0.05 * np.std(eta)


@pytest.mark.parametrize("follow", [False, True])
def test_one_dimensional_method_overestimates_hs_in_steep_seas(follow):
    """Bender et al. (2010): the 1-D hull-fixed accelerometer overestimates H_s; measured here."""
    res = []
    for hs, tp in ((2.0, 10.0), (8.0, 10.0), (12.0, 12.0)):
        t, eta, fb, roll, pitch, field = _buoy(hs, tp, 11, follow_orbits=follow)
        wc = 0.5 * 2 * math.pi / tp * 0.5  # a quarter of the peak frequency
        h3 = heave_from_accelerometers(fb[:, 0], fb[:, 1], fb[:, 2], roll, pitch, FS, wc)
        h1 = heave_from_hull_accelerometer(fb[:, 2], FS, wc)
        hs_true = 4.0 * np.std(eta)
        res.append((hs, tp, 4 * np.std(h3) / hs_true - 1.0, 4 * np.std(h1) / hs_true - 1.0,
                    np.degrees(np.std(np.hypot(roll, pitch)))))
    for hs, tp, e3, e1, tilt in res:
        print(f"follow orbits={follow}: H_s {hs} m T_p {tp} s, tilt rms {tilt:.1f}°: 3-D {e3:+.3f}, 1-D {e1:+.3f}")
    assert all(abs(r[2]) < 0.02 for r in res)  # orientation-corrected: within 2 %
    assert abs(res[0][3]) < 0.05  # gentle seas: 1-D within 5 %
    assert res[2][3] > res[0][3] + 0.05  # steep seas: the 1-D error grows with steepness (an overestimate)


def test_bad_corner_names_the_field():
    with pytest.raises(InputError, match="omega_c"):
        double_integrate(np.zeros(64), FS, 100.0)
