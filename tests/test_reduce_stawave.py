"""STAWAVE-1 and STAWAVE-2 (ITTC 7.5-04-01-01.1) added resistance: structure and integrals checked.

References: independent quadrature (scipy.integrate.quad) of the spectrum integral; the wave spectrum's
m0 = H_s²/16 (vtrials.physics.environment.waves); the limits of the formulas.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad

from vtrials.errors import InputError
from vtrials.physics.environment.waves import bretschneider_spectrum
from vtrials.reduce.stawave import raw_motion, raw_reflection, stawave1, stawave1_limit_hs, stawave2
from vtrials.units import G

SHIP = dict(L_pp=200.0, B=32.0, T=12.0, C_B=0.80, k_yy=0.25)
V = 7.5  # [m/s], Fr = 0.169


def test_stawave1_is_the_spectral_integral_of_a_constant_reflection():
    hs, B, L_bwl, rho = 2.0, 32.0, 30.0, 1025.0
    c = 0.5 * rho * G * B * math.sqrt(B / L_bwl)  # R/ζ_A² of a fully reflecting bow, blunted by √(B/L_BWL)
    wp = 2 * math.pi / 8.0
    integral, _ = quad(lambda w: 2.0 * bretschneider_spectrum(np.array([w]), hs, wp)[0] * c, 0.05, 20.0, limit=200)
    assert stawave1(hs, B, L_bwl, rho) == pytest.approx(integral, rel=1e-4)
    assert stawave1_limit_hs(200.0) == pytest.approx(2.25 * math.sqrt(2.0))


def test_motion_part_peaks_at_omega_bar_one_and_is_continuous():
    Fr = V / math.sqrt(G * SHIP["L_pp"])
    w1 = 1.17 * Fr ** -0.143 / (math.sqrt(SHIP["L_pp"] / G) * SHIP["k_yy"] ** (1 / 3))  # ω where ω̄ = 1
    w = np.linspace(0.2 * w1, 3.0 * w1, 20001)
    r = raw_motion(w, V, SHIP["L_pp"], SHIP["B"], SHIP["C_B"], SHIP["k_yy"])
    assert w[np.argmax(r)] == pytest.approx(w1, rel=1e-3)
    peak = 4 * 1025.0 * G * SHIP["B"] ** 2 / SHIP["L_pp"] * 60.3 * SHIP["C_B"] ** 1.34 * Fr ** 1.5 * math.exp(-3.5 * Fr)
    assert r.max() == pytest.approx(peak, rel=1e-6)
    below, above = raw_motion(np.array([w1 * (1 - 1e-9), w1 * (1 + 1e-9)]), V, SHIP["L_pp"], SHIP["B"],
                              SHIP["C_B"], SHIP["k_yy"])
    assert below == pytest.approx(above, rel=1e-6)


def test_reflection_limits():
    f1 = 0.692 * (V / math.sqrt(SHIP["T"] * G)) ** 0.769 + 1.81 * SHIP["C_B"] ** 6.95
    short = raw_reflection(np.array([6.0]), V, SHIP["B"], SHIP["T"], SHIP["C_B"])[0]
    assert short == pytest.approx(0.5 * 1025.0 * G * SHIP["B"] * f1, rel=1e-6)  # total reflection
    long = raw_reflection(np.array([0.05]), V, SHIP["B"], SHIP["T"], SHIP["C_B"])[0]
    assert long < 1e-3 * short
    w = np.linspace(0.05, 3.0, 500)
    assert np.all(np.diff(raw_reflection(w, V, SHIP["B"], SHIP["T"], SHIP["C_B"])) >= 0.0)


def test_stawave2_irregular_integral():
    hs, tp = 2.0, 8.0
    wp = 2 * math.pi / tp
    w = np.linspace(0.05, 5.0, 20001)
    S = bretschneider_spectrum(w, hs, wp)
    r = stawave2(w, S, V, **SHIP)

    def integrand(x):
        xa = np.array([x])
        return 2.0 * bretschneider_spectrum(xa, hs, wp)[0] * (
            raw_motion(xa, V, SHIP["L_pp"], SHIP["B"], SHIP["C_B"], SHIP["k_yy"])[0]
            + raw_reflection(xa, V, SHIP["B"], SHIP["T"], SHIP["C_B"])[0])
    ref, _ = quad(integrand, 0.05, 5.0, limit=400, points=[wp])
    assert r == pytest.approx(ref, rel=1e-4)
    r1 = stawave1(hs, SHIP["B"], 30.0)
    print(f"STAWAVE-2 R_AW = {r / 1e3:.1f} kN, STAWAVE-1 = {r1 / 1e3:.1f} kN (H_s 2 m, T_p 8 s, 200 m ship, 14.6 kn)")
    assert r > 0.0
    with pytest.raises(InputError, match="C_B"):
        stawave2(w, S, V, L_pp=200.0, B=32.0, T=12.0, C_B=1.5)
