"""Directional spectra from a buoy on synthetic cos-2s seas (realized by vtrials.physics.environment.waves).

Truth: the realized field's bulk mean direction and circular spread (WaveField.bulk_direction, the
closed-form first moments of cos-2s: r₁ = s/(s+1)). The buoy records η and either the surface slopes
(heave–pitch–roll buoy) or the orbital velocities (waves.kinematics) at the origin, 30 min at 2 Hz.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from vtrials.physics.environment.waves import Waves, kinematics, realize
from vtrials.reduce.directional import (bulk_from_directional, fourier_coefficients, imlm, mem, mlm,
                                        spreading_moments)

FS = 2.0


def _angle_diff(a, b):
    return abs(math.remainder(a - b, 2 * math.pi))


def _records(direction_from_deg, s, seed, channels):
    field = realize(Waves(hs_m=2.5, tp_s=8.0, direction_deg=direction_from_deg, spreading_s=s, n_components=400),
                    math.inf, np.random.default_rng(seed))
    t = np.arange(0.0, 1800.0, 1.0 / FS)
    c = field.components
    if channels == "slopes":
        th = c[None, :, 1] * t[:, None] + c[None, :, 5]
        eta = np.cos(th) @ c[:, 0]
        p = np.sin(th) @ (c[:, 0] * c[:, 2] * c[:, 3])
        q = np.sin(th) @ (c[:, 0] * c[:, 2] * c[:, 4])
    else:
        eta, vel, _ = kinematics(c, math.inf, 0.0, 0.0, 0.0, t)
        p, q = vel[:, 0], vel[:, 1]
    return field, eta, p, q


@pytest.mark.parametrize("direction_from_deg,s,channels", [(60.0, 10.0, "slopes"), (300.0, 4.0, "velocities"),
                                                            (200.0, 25.0, "slopes")])
def test_buoy_recovers_mean_direction_and_spread(direction_from_deg, s, channels):
    field, eta, p, q = _records(direction_from_deg, s, 5, channels)
    mu_true, sig_true = field.bulk_direction()
    wp = 2 * math.pi / 8.0
    fc = fourier_coefficients(eta, p, q, FS, 256, channels)
    band = (fc.omega >= 0.6 * wp) & (fc.omega <= 3.0 * wp)
    hs, mu1, sig1 = fc.bulk(0.6 * wp, 3.0 * wp)
    mu = np.linspace(0.0, 2 * math.pi, 360, endpoint=False)
    res = {"fourier": (mu1, sig1)}
    for name, method in (("MLM", mlm), ("IMLM", imlm), ("MEM", mem)):
        D = method(fc.a1[band], fc.b1[band], fc.a2[band], fc.b2[band], mu)
        assert np.allclose(np.sum(D, axis=1) * (2 * math.pi / mu.size), 1.0)
        res[name] = bulk_from_directional(fc.omega[band], fc.S[band], D, mu)
    for name, (m, sg) in res.items():
        print(f"{channels} s={s} from {direction_from_deg}°: {name}: mean error "
              f"{math.degrees(_angle_diff(m, mu_true)):.1f}°, spread {math.degrees(sg):.1f}° vs "
              f"{math.degrees(sig_true):.1f}° ({sg / sig_true - 1:+.3f})")
    for name in ("fourier", "MLM", "IMLM", "MEM"):
        m, sg = res[name]
        assert math.degrees(_angle_diff(m, mu_true)) < 10.0, name
    for name in ("fourier", "MEM"):  # MEM reproduces a₁, b₁ exactly
        assert res[name][1] == pytest.approx(sig_true, rel=0.20), name
    # the MLM spreads too wide (+18 to +50 % here); the iteration narrows it (+3 to +30 %), not always within 20 %
    assert res["MLM"][1] > sig_true
    assert abs(res["IMLM"][1] / sig_true - 1.0) < abs(res["MLM"][1] / sig_true - 1.0)


def test_mem_reproduces_the_coefficients_and_mlm_peaks_at_the_mean():
    a1, b1, a2, b2 = 0.6 * math.cos(1.0), 0.6 * math.sin(1.0), 0.3 * math.cos(2.0), 0.3 * math.sin(2.0)
    mu = np.linspace(0.0, 2 * math.pi, 4096, endpoint=False)
    D = mem(a1, b1, a2, b2, mu)[0]
    dmu = 2 * math.pi / mu.size
    got = [np.sum(D * f(k * mu)) * dmu for k in (1, 2) for f in (np.cos, np.sin)]
    assert np.allclose(got, [a1, b1, a2, b2], atol=1e-6)
    Dm = mlm(a1, b1, a2, b2, mu)[0]
    m, _ = spreading_moments(Dm[None, :], mu)
    assert math.degrees(_angle_diff(float(m[0]), 1.0)) < 10.0
