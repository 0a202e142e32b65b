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
from vtrials.reduce.stawave import (METHOD_REL_STD, observed_spectrum, raw_motion, raw_reflection,
                                    run_wave_resistance, stawave1, stawave1_limit_hs, stawave2)
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


def test_observed_spectrum_against_the_physics_forms():
    """The team's own spectra: 4√m₀ = H_s on the grid, and the Pierson–Moskowitz shape equal to the
    simulator's Bretschneider form (an independent implementation of the same formula); JONSWAP peaks
    at ω_p and is higher there than Pierson–Moskowitz of the same H_s."""
    w = np.linspace(0.05, 6.0, 6000)
    pm = observed_spectrum(w, 1.5, 8.0)
    assert 4.0 * math.sqrt(np.trapezoid(pm, w)) == pytest.approx(1.5, rel=1e-9)
    ref = bretschneider_spectrum(w, 1.5, 2 * math.pi / 8.0)
    assert np.max(np.abs(pm - ref)) < 5e-3 * ref.max()
    js = observed_spectrum(w, 1.5, 8.0, gamma=3.3)
    assert w[np.argmax(js)] == pytest.approx(2 * math.pi / 8.0, abs=2e-3)
    assert js.max() > 1.5 * pm.max()


def test_run_wave_resistance_by_sector():
    """Within ±45° of the bow: STAWAVE-2 of the observed sea, uncertainty from H_s (R ∝ H_s²) and the
    method; outside: half the head-sea value ± 1/√12 of it; a sea from two systems adds."""
    L, B, T, CB, V = 51.5, 8.6, 2.3, 0.35, 7.0
    s = {"hs_m": 1.0, "tp_s": 7.5, "gamma": None, "from_rad": math.radians(10.0), "hs_rel_std": 0.05}
    w = np.linspace(0.2, 6.0, 600) * (2 * math.pi / 7.5)
    head = stawave2(w, observed_spectrum(w, 1.0, 7.5), V, L, B, T, CB)
    r, sd = run_wave_resistance([s], math.radians(50.0), V, L, B, T, CB)      # 40° off the bow
    assert r == pytest.approx(head, rel=1e-12)
    assert sd == pytest.approx(head * math.hypot(0.10, METHOD_REL_STD), rel=1e-12)
    r, sd = run_wave_resistance([s], math.radians(60.0), V, L, B, T, CB)      # 50° off: outside
    assert r == pytest.approx(0.5 * head, rel=1e-12) and sd == pytest.approx(head / math.sqrt(12.0), rel=1e-12)
    r2, _ = run_wave_resistance([s, {**s, "from_rad": math.radians(190.0)}], math.radians(10.0), V, L, B, T, CB)
    assert r2 == pytest.approx(1.5 * head, rel=1e-12)
    assert run_wave_resistance([], 0.0, V, L, B, T, CB) == (0.0, 0.0)


def test_observed_sea_is_reproducible_and_scattered_as_stated():
    """Same seed → the same observation; over 2000 seeds the H_s, T_p and direction errors have the
    stated standard deviations (within 10 %) and no bias; a calm sea gives nothing; swell is a
    second system."""
    from vtrials.instruments.sea_observation import (DIRECTION_STD_RAD, HS_REL_STD, TP_REL_STD,
                                                     observe_sea)
    from vtrials.physics.environment.waves import Waves
    waves = Waves(spectrum="pierson_moskowitz", hs_m=0.88, tp_s=7.5, direction_deg=10.0)
    assert observe_sea(waves, 5) == observe_sea(waves, 5)
    obs = [observe_sea(waves, k)[0] for k in range(2000)]
    hs = np.array([o["hs_m"] for o in obs]) / 0.88 - 1.0
    tp = np.array([o["tp_s"] for o in obs]) / 7.5 - 1.0
    dd = np.array([o["from_rad"] for o in obs]) - math.radians(10.0)
    for e, sd in ((hs, HS_REL_STD), (tp, TP_REL_STD), (dd, DIRECTION_STD_RAD)):
        assert abs(np.std(e) / sd - 1.0) < 0.1 and abs(np.mean(e)) < 4 * sd / math.sqrt(e.size)
    assert observe_sea(Waves(), 5) == []
    two = observe_sea(Waves(spectrum="jonswap", hs_m=1.0, tp_s=6.0, swell_hs_m=0.5, swell_tp_s=12.0), 5)
    assert len(two) == 2 and two[0]["gamma"] == 3.3 and two[1]["tp_s"] > 8.0
