"""Encounter-frequency transforms: energy (m0) conserved forward and back, following-seas branches.

Reference: m0 = H_s²/16 of the wave spectrum (vtrials.physics.environment.waves, normalised by
quadrature); the encounter spectrum's integral is taken across the singular point by the substitution
|ω_e| = ω_e,max (1 − t²), which removes its 1/√ singularity.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from vtrials.physics.environment.waves import jonswap_spectrum
from vtrials.reduce.encounter import (encounter_frequency, encounter_spectrum, singular_frequency,
                                      wave_frequencies, wave_spectrum_from_encounter)
from vtrials.units import DEG, G

HS, TP = 3.0, 10.0
WP = 2.0 * math.pi / TP


def S(w):
    w = np.asarray(w, dtype=float)
    return np.where(w > 0.05, jonswap_spectrum(np.maximum(w, 0.05), HS, WP, 3.3), 0.0)


def _m0_encounter(U, mu):
    a = U * math.cos(mu) / G
    t = np.linspace(1e-6, 1.0, 200001)  # t = 0 is the singular point itself (finite integrand limit)
    if a <= 0.0:
        we = np.linspace(0.0, 8.0, 400001)
        return np.trapezoid(encounter_spectrum(S, we, U, mu), we)
    wmax = 1.0 / (4.0 * a)
    we1 = wmax * (1.0 - t * t)
    I1 = np.trapezoid(encounter_spectrum(S, we1, U, mu) * 2.0 * wmax * t, t)  # substitution, t: 0 → 1
    we2 = np.linspace(wmax * (1.0 + 1e-12), wmax + 10.0, 400001)
    I2 = np.trapezoid(encounter_spectrum(S, we2, U, mu), we2)
    return I1 + I2


@pytest.mark.parametrize("U,mu_deg", [(0.0, 0.0), (8.0, 180.0), (8.0, 135.0), (8.0, 30.0), (5.0, 0.0),
                                       (10.0, 60.0)])
def test_encounter_spectrum_conserves_m0(U, mu_deg):
    w = np.linspace(0.0, 6.0, 600001)
    m0 = np.trapezoid(S(w), w)
    assert m0 == pytest.approx(HS ** 2 / 16.0, rel=2e-3)
    assert _m0_encounter(U, mu_deg * DEG) == pytest.approx(m0, rel=3e-3)


def test_branches_map_back_to_the_same_encounter_frequency():
    U, mu = 8.0, 30.0 * DEG
    ws = singular_frequency(U, mu)
    assert ws == pytest.approx(G / (2.0 * U * math.cos(mu)))
    we = np.linspace(0.01, 0.9 / (4.0 * U * math.cos(mu) / G), 50)
    W = wave_frequencies(we, U, mu)
    assert np.all(np.isfinite(W))  # three branches below the maximum encounter frequency
    for j in range(3):
        assert np.allclose(np.abs(encounter_frequency(W[:, j], U, mu)), we, rtol=1e-10)
    assert np.all(W[:, 0] < ws) and np.all((W[:, 1] > ws) & (W[:, 1] < 2 * ws)) and np.all(W[:, 2] > 2 * ws)
    above = wave_frequencies([1.2 / (4.0 * U * math.cos(mu) / G)], U, mu)
    assert np.isnan(above[0, 0]) and np.isnan(above[0, 1]) and np.isfinite(above[0, 2])


@pytest.mark.parametrize("U,mu_deg", [(8.0, 150.0), (8.0, 30.0)])
def test_back_transform_recovers_the_spectrum(U, mu_deg):
    mu = mu_deg * DEG
    w = np.linspace(0.2, 3.0, 2801)
    w = w[np.abs(w - singular_frequency(U, mu)) > 1e-3]
    Se = lambda we: encounter_spectrum(S, we, U, mu)  # noqa: E731
    back = wave_spectrum_from_encounter(Se, w, U, mu, prior=S)  # prior of the right shape: exact
    assert np.allclose(back, S(w), rtol=1e-9, atol=1e-12)
    m0 = np.trapezoid(S(w), w)
    assert np.trapezoid(back, w) == pytest.approx(m0, rel=1e-6)
    if math.cos(mu) > 0.0:
        # without a prior, the first-branch assumption misplaces the energy of ω > ω* (measured here)
        naive = wave_spectrum_from_encounter(Se, w, U, mu)
        rel = abs(np.trapezoid(naive, w) / m0 - 1.0)
        print(f"first-branch assumption at U = {U} m/s, μ = {mu_deg}°: m0 error {rel:.3f}")
        assert rel > 0.01


def test_encounter_spectrum_matches_a_record_taken_on_a_moving_ship():
    """A long-crested following sea sampled at a point moving with the ship: Welch vs the three branches.

    A band's energy from a record of duration T scatters with Var = (2π/T) ∫_band S_e² dω_e (Bendat &
    Piersol 2010, §8.2.1): the record must agree within 3 σ (σ from the predicted S_e, bands clear of
    the singular point, where ∫S_e² diverges).
    """
    from vtrials.physics.environment.waves import Waves, elevation, realize
    from vtrials.reduce.spectra import response_spectrum

    U, fs, T = 5.0, 2.0, 6 * 3600.0
    field = realize(Waves(hs_m=HS, tp_s=TP, direction_deg=180.0, spreading="none", n_components=600),
                    math.inf, np.random.default_rng(4))  # waves go north; the ship steams north (μ = 0)
    t = np.arange(0.0, T, 1.0 / fs)
    eta = elevation(field.components, U * t, 0.0, t)
    sp = response_spectrum(eta, fs, 2048)
    Sw = field.systems[0].spectrum_1d
    lo, hi = field.systems[0].omega_lo, field.systems[0].omega_hi

    def S_band(w):
        w = np.asarray(w, dtype=float)
        return np.where((w >= lo) & (w <= hi), Sw(np.clip(w, lo, hi)), 0.0)

    wmax = G / (4.0 * U)
    assert 0.45 < wmax
    for a, b in ((0.25, 0.35), (0.35, 0.45)):  # above ω_e,max (branch 3 only) the band holds ~1 component
        m = (sp.omega >= a) & (sp.omega < b)
        measured = np.sum(sp.S[m]) * (sp.omega[1] - sp.omega[0])
        we = np.linspace(a, b, 200001)
        Se = encounter_spectrum(S_band, we, U, 0.0)
        predicted = np.trapezoid(Se, we)
        sigma = math.sqrt(2.0 * math.pi / T * np.trapezoid(Se * Se, we))
        print(f"|ω_e| in [{a:.2f}, {b:.2f}): record {measured:.4f} m², three branches {predicted:.4f} m² "
              f"(σ {sigma:.4f}; {(measured - predicted) / sigma:+.2f} σ)")
        assert abs(measured - predicted) < 3.0 * sigma
