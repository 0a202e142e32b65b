"""The ship as a wave buoy: fit (H_s, T_p, μ₀, s) to measured heave/pitch/roll cross-spectra.

Truth: realized short-crested seas (JONSWAP, cos-2s s = 10; vtrials.physics.environment.waves); the ship
(tests/synthetic_ship.py) runs at 6 m/s for 25 min and its motions are recorded at 2 Hz with sensor
noise. The fit is given the ship's RAOs (here the same closed forms: the test isolates the estimator).
Waves from the port bow and from the starboard bow give the same heave and pitch; only the sign of the
roll cross-spectra tells them apart.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from synthetic_ship import SyntheticShip, responses

from vtrials.physics.environment.waves import Waves, realize
from vtrials.errors import InputError
from vtrials.reduce.shipbuoy import ResponseModel, fit_directional_spectrum
from vtrials.reduce.spectra import cross_spectral_matrix

SHIP = SyntheticShip()
FS = 2.0
U = 6.0


@pytest.mark.parametrize("rel_from_deg", [30.0, -30.0, 120.0, -60.0])
def test_ship_as_wave_buoy(rel_from_deg):
    """rel_from_deg: where the waves come from relative to the bow (+ starboard, − port)."""
    rng = np.random.default_rng(31)
    heading = math.radians(40.0)
    wdir_from = math.degrees(heading) + rel_from_deg
    field = realize(Waves(hs_m=3.0, tp_s=9.0, direction_deg=wdir_from % 360.0, spreading_s=10.0,
                          n_components=400), math.inf, rng)
    t = np.arange(0.0, 1500.0, 1.0 / FS)
    rec = responses(SHIP, field.components, heading, U, t)
    rec = rec + 0.02 * rec.std(axis=1, keepdims=True) * rng.standard_normal(rec.shape)  # sensor noise
    G = cross_spectral_matrix(rec, FS, 256)
    band = (G.omega >= 0.15) & (G.omega <= 2.0)
    omega = np.linspace(0.2, 2.5, 200)
    mu = np.linspace(-math.pi, math.pi, 72, endpoint=False)
    W, M = np.meshgrid(omega, mu, indexing="ij")
    model = ResponseModel(omega, mu, SHIP.rao(W, M, U), U, G.omega[band])
    fit = fit_directional_spectrum(model, G.S[band])
    mu_true, _ = field.bulk_direction()
    rel_true = math.remainder(mu_true - heading, 2 * math.pi)
    dmu = math.degrees(abs(math.remainder(fit.mu0 - rel_true, 2 * math.pi)))
    print(f"ship buoy, waves from {rel_from_deg:+.0f}° off the bow: H_s {fit.hs:.2f} vs {field.hs_realized_m:.2f} m, "
          f"T_p {fit.tp:.2f} vs 9.00 s, direction error {dmu:.1f}°, s {fit.s:.1f} vs 10")
    assert fit.hs == pytest.approx(field.hs_realized_m, rel=0.15)
    assert dmu < 15.0  # port and starboard told apart: a mirror image would be off by 2|rel| ≥ 60°


def test_observed_fraction_flags_folded_following_seas():
    """The in-band fraction of a fitted sea's responses (what :attr:`RecordBuoy.reliable` tests), against
    the same sums done directly: the encounter frequency of every (ω, μ) cell. Head seas at 9 m/s put all
    the response above 0.2 rad/s (fraction 1); in following seas at 9 m/s waves of 0.83–1.30 rad/s meet
    the ship below 0.2 rad/s (|ω − ω²U/g| < 0.2), which holds most of a T_p 6-s sea."""
    from vtrials.reduce.shipbuoy import OBSERVED_MIN, ShipBuoyFit, cos2s, jonswap, observed_fraction
    U, de = 9.0, 2.0 * math.pi / 128.0
    omega = np.linspace(0.2, 2.5, 200)
    mu = np.linspace(-math.pi, math.pi, 72, endpoint=False)
    W, M = np.meshgrid(omega, mu, indexing="ij")
    rao = SHIP.rao(W, M, U)
    bins = de * np.arange(int(2.0 / de) + 1)
    band = bins >= 0.2
    model, full = ResponseModel(omega, mu, rao, U, bins[band]), ResponseModel(omega, mu, rao, U, bins)
    we = np.abs(W - W * W * U * np.cos(M) / 9.80665)
    cell = np.gradient(omega)[:, None] * (2 * math.pi / mu.size)
    for mu0, tp, expect_reliable in ((math.pi, 8.0, True), (0.0, 8.0, True), (0.0, 6.0, False)):
        fit = ShipBuoyFit(2.0, tp, mu0, 10.0, 0.0, None)
        got = observed_fraction(model, full, fit)
        E = jonswap(omega, 2.0, tp)[:, None] * cos2s(M - mu0, 10.0) * cell
        k = np.rint(we / de)
        inside = (k >= np.argmax(band)) & (k <= bins.size - 1)
        for r in range(rao.shape[0]):
            a = np.abs(rao[r]) ** 2 * E
            direct = a[inside].sum() / a[k <= bins.size - 1].sum()
            assert got[r] == pytest.approx(direct, rel=0.02), (mu0, r, got[r], direct)
        print(f"mu0 {math.degrees(mu0):.0f}°, T_p {tp} s: observed fractions {np.round(got, 3)}")
        assert (min(got) >= OBSERVED_MIN) == expect_reliable


class _RetunedRoll:
    """The synthetic ship with its roll stiffness and damping changed by (κ_C, κ_B) in the units of the fit
    (C₄₄ = 1, B_crit = 2/ω_n): written out from the single-DOF roll, 1/(1 + κ_C − x² + 2i(ζ + κ_B)x)
    against 1/(1 − x² + 2iζx), x = ω_e/ω_n, with the same wave moment."""

    def __init__(self, ship, kc, kb):
        self.ship, self.kc, self.kb = ship, kc, kb

    def rao(self, omega, mu, U):
        R = self.ship.rao(omega, mu, U)
        w = np.asarray(omega, dtype=float)
        x = (w - w * w * U * np.cos(mu) / 9.80665) / self.ship.w4
        old = 1.0 - x * x + 2j * self.ship.z4 * x
        new = 1.0 + self.kc - x * x + 2j * (self.ship.z4 + self.kb) * x
        R[2] = R[2] * old / new
        return R


def test_roll_tuning_recovers_a_mistuned_roll():
    """The team's roll model is 25 % too stiff and its damping 6 % of critical too low (the true ship:
    κ_C = −0.2, κ_B = +0.06 from the model). Waves from the starboard bow at 6 m/s put the roll
    resonance in the band. With roll tuning the fit finds the sea (H_s within 15 % as in the test above,
    direction within 10°) and the roll changes (κ_C within 0.05, κ_B within 0.02). Measured: H_s −8.7 %,
    2.2°, (−0.178, 0.060); untuned −12 %, 3.0°."""
    rng = np.random.default_rng(7)
    heading = math.radians(40.0)
    true_ship = _RetunedRoll(SHIP, -0.2, 0.06)
    field = realize(Waves(hs_m=3.0, tp_s=9.0, direction_deg=(40.0 + 40.0) % 360.0, spreading_s=10.0,
                          n_components=400), math.inf, rng)
    t = np.arange(0.0, 1500.0, 1.0 / FS)
    rec = responses(true_ship, field.components, heading, U, t)
    rec = rec + 0.02 * rec.std(axis=1, keepdims=True) * rng.standard_normal(rec.shape)
    G = cross_spectral_matrix(rec, FS, 256)
    band = (G.omega >= 0.15) & (G.omega <= 2.0)
    omega = np.linspace(0.2, 2.5, 200)
    mu = np.linspace(-math.pi, math.pi, 72, endpoint=False)
    W, M = np.meshgrid(omega, mu, indexing="ij")
    R = SHIP.rao(W, M, U)
    part = np.zeros_like(R)
    part[2] = R[2]
    x = (W - W * W * U * np.cos(M) / 9.80665) / SHIP.w4
    h = 1.0 / (1.0 - x * x + 2j * SHIP.z4 * x)          # receptance with C₄₄ = 1
    mu_true, _ = field.bulk_direction()
    rel_true = math.remainder(mu_true - heading, 2 * math.pi)
    errs = {}
    for tune in (False, True):
        kw = dict(roll_part=part, roll_receptance=h, roll_scales=(1.0, 2.0 / SHIP.w4)) if tune else {}
        model = ResponseModel(omega, mu, R, U, G.omega[band], **kw)
        fit = fit_directional_spectrum(model, G.S[band], tune_roll=tune, roll_damping_min=-0.08)
        dmu = math.degrees(abs(math.remainder(fit.mu0 - rel_true, 2 * math.pi)))
        errs[tune] = (fit.hs / field.hs_realized_m - 1.0, dmu)
        print(f"roll tuned {tune}: H_s {fit.hs:.2f} vs {field.hs_realized_m:.2f} m, direction error {dmu:.1f}°, "
              f"roll changes {np.round(fit.roll, 3)} vs (-0.2, 0.06)")
    assert abs(errs[True][0]) < 0.15 and errs[True][1] < 10.0
    assert fit.roll[0] == pytest.approx(-0.2, abs=0.05)
    assert fit.roll[1] == pytest.approx(0.06, abs=0.02)
    with pytest.raises(InputError, match="roll part"):
        fit_directional_spectrum(ResponseModel(omega, mu, R, U, G.omega[band]), G.S[band], tune_roll=True)


class _RollPhase:
    """The synthetic ship with its roll RAO turned by ``deg`` degrees: a ship whose roll leads the team's
    model by about as much as patrol51's does at 9 m/s in bow seas (60–105°, the waves' flow in its lift)."""

    def __init__(self, ship, deg):
        self.ship, self.turn = ship, np.exp(1j * math.radians(deg))

    def rao(self, omega, mu, U):
        R = self.ship.rao(omega, mu, U)
        R[2] = R[2] * self.turn
        return R


def test_legs_on_different_headings_tell_port_from_starboard():
    """A star pattern in one sea (from 080°, H_s 3 m, T_p 9 s, s = 10): head (080), starboard bow (040) and
    port bow (125) legs of 25 min at 6 m/s, by a ship whose roll phase is 100° off the team's model.
    Leg by leg only roll tells the side, and this roll misleads (the precondition: both bow legs' single
    fits more than 30° off; measured 43° and 50°, pulled towards head seas). One sea fitted to the three
    legs (fit_legs, the legs' headings) finds it on every leg: H_s within 15 %, direction within 10° —
    with roll (measured −8 %, 2.4°) and without it (heave and pitch alone, whose mirror images disagree
    between headings: −3 %, 4.0°). Legs on reciprocal courses
    cannot tell the side by their headings (side_evidence)."""
    from vtrials.reduce.shipbuoy import fit_legs, side_evidence
    rng = np.random.default_rng(11)
    field = realize(Waves(hs_m=3.0, tp_s=9.0, direction_deg=80.0, spreading_s=10.0, n_components=400),
                    math.inf, rng)
    true_ship = _RollPhase(SHIP, 100.0)
    mu_true, _ = field.bulk_direction()                           # towards, from north
    headings = [math.radians(h) for h in (80.0, 40.0, 125.0)]
    omega = np.linspace(0.2, 2.5, 200)
    mu = np.linspace(-math.pi, math.pi, 72, endpoint=False)
    W, M = np.meshgrid(omega, mu, indexing="ij")
    R = SHIP.rao(W, M, U)
    data = {}
    for k, hd in enumerate(headings):
        t = 1800.0 * k + np.arange(0.0, 1500.0, 1.0 / FS)
        rec = responses(true_ship, field.components, hd, U, t)
        rec = rec + 0.02 * rec.std(axis=1, keepdims=True) * rng.standard_normal(rec.shape)
        G = cross_spectral_matrix(rec, FS, 256)
        band = (G.omega >= 0.15) & (G.omega <= 2.0)
        data[k] = (G.omega[band], G.S[band])

    def err(fit_mu0, hd):
        return math.degrees(abs(math.remainder(fit_mu0 - (mu_true - hd), 2 * math.pi)))

    single = []
    for k, hd in enumerate(headings):
        f = fit_directional_spectrum(ResponseModel(omega, mu, R, U, data[k][0]), data[k][1])
        single.append(err(f.mu0, hd))
    print(f"leg by leg (heave, pitch, roll): direction errors {np.round(single, 1)}°")
    assert min(single[1:]) > 30.0                                 # roll misleads both bow legs
    for rows, label in (([0, 1, 2], "heave, pitch, roll"), ([0, 1], "heave, pitch")):
        models = [ResponseModel(omega, mu, R[rows], U, data[k][0]) for k in data]
        G_meas = [data[k][1][:, rows][:, :, rows] for k in data]
        fit = fit_legs(models, G_meas, headings)
        errs = [err(fit.mu0 - hd, hd) for hd in headings]
        print(f"one sea on three legs ({label}): H_s {fit.hs:.2f} vs {field.hs_realized_m:.2f} m, "
              f"from {math.degrees(fit.direction_from(0.0)):.1f}° (true 80), direction errors {np.round(errs, 1)}°")
        assert fit.hs == pytest.approx(field.hs_realized_m, rel=0.15)
        assert max(errs) < 10.0
        assert len(fit.G_pred) == 3
    assert side_evidence(headings, ("heave", "pitch")) == "headings"
    recip = [headings[1], headings[1] + math.pi]
    assert side_evidence(recip, ("heave", "pitch")) == "none"
    assert side_evidence(recip, ("heave", "roll", "pitch")) == "roll"
    with pytest.raises(InputError, match="one of each per leg"):
        fit_legs(models, G_meas, headings[:2])
