"""Issue 13 items 1, 3, 4 (buoy half): the directional wave buoy against the true sea — its raw series against
an independent evaluation of the seaway, its reported spectra against the true spectrum, its H_s scatter
against the record's sampling variability, and the acceptance check (mean direction within 10°,
spreading within 20 % of the truth over each 30-min window) per directional method; EMEP on analytic
spreading functions; the buoy's reports read back from a record."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq
from scipy.special import i0e, i1e

from vtrials.instruments.suite import load_catalogue
from vtrials.instruments.wave_sensors import WaveBuoy, band_response
from vtrials.physics.environment.waves import Waves, elevation, kinematics, realize, spreading_function
from vtrials.records.netcdf import Record, write_groups
from vtrials.reduce.directional import FourierCoefficients, buoy_reports, emep, mem
from vtrials.score.waves import score_buoy_reports, summarise
from vtrials.truth.seaway import band_truth

TWO_PI = 2.0 * math.pi


def _field(frm=30.0, s=10.0, tp=10.0, hs=2.5, seed=1, **kw):
    return realize(Waves(hs_m=hs, tp_s=tp, direction_deg=frm, spreading_s=s, **kw), math.inf,
                   np.random.default_rng(seed))


def _buoy(field, entry="directional_waverider", seed=0, **over):
    spec = dict(load_catalogue()[entry])
    spec.update(over)
    d = WaveBuoy("buoy", spec, "sea", np.zeros(3), {"site": {"range_center": [0.0, 0.0]}})
    d.attach_sea(field)
    d.reset(np.random.default_rng(seed))
    return d


def _reports(d, n_records):
    t, ch = d.process({"t": np.arange(0.0, n_records * d.record + 5.0, 1.0)})
    om = np.array(d.meta()["omega_rad_s"])
    dof = d.meta()["welch_dof"]
    return t, [FourierCoefficients(om, ch["S"][i], ch["a1"][i], ch["b1"][i], ch["a2"][i], ch["b2"][i], dof)
               for i in range(t.size)], ch


IDEAL = {"band_hz": [1e-4, 50.0], "heave_scale": 0.0, "heave_noise_m": 0.0, "horizontal_noise": 0.0,
         "resolution": 0.0, "compass_bias_deg": 0.0}


def test_series_equal_the_seaway_and_its_orbits():
    """An ideal buoy (flat band, no errors) reads the surface elevation that waves.elevation gives at its
    point, and horizontal displacements whose time derivative is the orbital velocity of waves.kinematics
    (central differences, deep water)."""
    field = _field()
    d = _buoy(field, output="series", sample_hz=8.0, position_m=[120.0, -40.0], **IDEAL)
    t, ch = d.process({"t": np.arange(0.0, 300.0, 0.25)})
    np.testing.assert_allclose(ch["heave"], elevation(field.components, 120.0, -40.0, t), atol=1e-9)
    dt = t[1] - t[0]
    _, vel, _ = kinematics(field.components, math.inf, 120.0, -40.0, 0.0, t[1:-1])
    for k, name in ((0, "h_north"), (1, "h_east")):
        dxdt = (ch[name][2:] - ch[name][:-2]) / (2 * dt)
        assert np.max(np.abs(dxdt - vel[:, k])) < 0.01 * np.max(np.abs(vel[:, k]))


def test_slope_buoy_reads_slopes():
    """A heave–pitch–roll buoy's horizontal pair is ∂η/∂x, ∂η/∂y (central differences of waves.elevation)."""
    field = _field()
    d = _buoy(field, entry="hpr_discus_buoy", output="series", sample_hz=2.0, **IDEAL)
    t, ch = d.process({"t": np.arange(0.0, 120.0, 0.25)})
    h = 0.05
    gx = (elevation(field.components, h, 0.0, t) - elevation(field.components, -h, 0.0, t)) / (2 * h)
    gy = (elevation(field.components, 0.0, h, t) - elevation(field.components, 0.0, -h, t)) / (2 * h)
    np.testing.assert_allclose(ch["h_north"], gx, atol=1e-5)
    np.testing.assert_allclose(ch["h_east"], gy, atol=1e-5)


def test_band_response_is_the_data_sheet_band():
    """Datawell DWR-MkIII band-pass: 3 dB at 0.033 and 0.6 Hz, flat (< 0.3 dB) over 0.056–0.5 Hz."""
    g = band_response(np.array([0.033, 0.6, 0.056, 0.1, 0.5]), 0.033, 4, 0.6, 12)
    assert 20 * np.log10(g[0]) == pytest.approx(-3.01, abs=0.01)
    assert 20 * np.log10(g[1]) == pytest.approx(-3.01, abs=0.01)
    assert np.all(20 * np.log10(g[2:]) > -0.3)


def test_reported_spectrum_is_the_true_spectrum():
    """Eight 30-min reports averaged: per frequency band of 0.02 Hz around the peak, the buoy's spectrum is the
    seaway's (the components' energy in the band, times the buoy's |H|²) within the chi-square band of the
    average (ν ≈ 8 × 32 × 4 bins = 1000 dof: ±12 % at 99 %), and H_s per report scatters about the band
    truth as the record's sampling variability predicts (ν₀ = T m0²/(π∫S²dω), Bendat & Piersol)."""
    field = _field(seed=3)
    d = _buoy(field, seed=4)
    t, reps, ch = _reports(d, 8)
    om = reps[0].omega
    S = np.mean([r.S for r in reps], axis=0)
    c = field.components
    gain2 = band_response(c[:, 1] / TWO_PI, *d.band[:1], d.orders[0], d.band[1], d.orders[1]) ** 2
    wp = TWO_PI / 10.0
    for lo in np.arange(0.7 * wp, 1.6 * wp, TWO_PI * 0.02):
        hi = lo + TWO_PI * 0.02
        m = (om >= lo) & (om < hi)
        got = float(np.sum(S[m])) * (om[1] - om[0])
        inband = (c[:, 1] >= lo - 0.5 * (om[1] - om[0])) & (c[:, 1] < hi - 0.5 * (om[1] - om[0]))
        want = float(np.sum(0.5 * c[inband, 0] ** 2 * gain2[inband]))
        assert got == pytest.approx(want, rel=0.12), (lo, hi)
    hs_true = band_truth(field, om[0], om[-1])["hs_m"]
    ratio = ch["hs"] / hs_true
    w = np.linspace(om[0], om[-1], 4000)
    Sw = field.spectrum(w)
    nu0 = d.record * np.trapezoid(Sw, w) ** 2 / (math.pi * np.trapezoid(Sw ** 2, w))
    sd_pred = 0.5 * math.sqrt(2.0 / nu0)  # H_s ∝ √m0: relative sd half that of m0
    assert abs(ratio.mean() - 1.0) < 3.0 * sd_pred / math.sqrt(ratio.size) + 0.01
    assert 0.4 * sd_pred < ratio.std(ddof=1) < 2.0 * sd_pred
    assert sd_pred < 0.06  # the seed's "most buoy points within ±10 %" (2σ ≈ 10 %)


@pytest.mark.parametrize("frm,s,tp,seed", [(30.0, 10.0, 10.0, 1), (200.0, 4.0, 8.0, 2), (300.0, 25.0, 12.0, 3)])
def test_acceptance_direction_and_spreading(frm, s, tp, seed):
    """Acceptance (issue 13): per 30-min report, the mean direction within 10° and the spreading within 20 %
    of the true sea over the window, for the coefficients' own bulk values, MEM and EMEP. The MLM broadens
    the spreading (+12 to +33 % on these seas; its D does not reproduce a₁, b₁); IMLM narrows it back."""
    field = _field(frm=frm, s=s, tp=tp, seed=seed)
    d = _buoy(field, seed=seed + 10)
    t, reps, _ = _reports(d, 3)
    rows = score_buoy_reports(t, reps, field, d.record, position=(0.0, 0.0))
    summ = summarise(rows)
    for m in ("fourier", "MEM", "EMEP"):
        assert summ[m]["fraction_within"] == 1.0, (m, summ[m])
    for m in ("MLM", "IMLM"):
        assert summ[m]["direction_abs_max_deg"] < 10.0
    assert summ["MLM"]["spread_error_mean"] > summ["IMLM"]["spread_error_mean"] > summ["EMEP"]["spread_error_mean"] - 0.05
    assert abs(summ["hs_window"]["error_mean"]) < 0.03  # H_s against the true surface of the same window


def test_drifting_buoy_drifts_and_still_meets_the_acceptance():
    field = _field(frm=120.0, s=10.0, seed=5)
    d = _buoy(field, entry="triaxys_drifting_buoy", seed=6)
    t, reps, ch = _reports(d, 2)
    v = np.array(d.drawn()["drift_mps"])
    assert np.hypot(ch["north"][1] - ch["north"][0], ch["east"][1] - ch["east"][0]) == pytest.approx(
        np.hypot(*v) * d.record, rel=1e-9)
    rows = score_buoy_reports(t, reps, field, d.record, position=(lambda tt: d.position_at(tt)[0],
                                                                 lambda tt: d.position_at(tt)[1]))
    summ = summarise(rows, methods=("EMEP", "MEM"))
    assert summ["EMEP"]["fraction_within"] == 1.0 and summ["MEM"]["fraction_within"] == 1.0


def test_emep_on_an_analytic_cos2s():
    """EMEP (exact moments, N = 2) reproduces the four moments of a cos-2s (s = 10) exactly and the cos-2s
    itself closely (L1 < 0.01; MEM's peaked shape is ~0.7 off); with N = 1 it is the von Mises density whose
    mean resultant I₁(κ)/I₀(κ) is r₁ (scipy's Bessel functions)."""
    mu = np.linspace(0.0, TWO_PI, 720, endpoint=False)
    dmu = TWO_PI / mu.size
    s, mu0 = 10.0, 1.0
    r1, r2 = s / (s + 1), s * (s - 1) / ((s + 1) * (s + 2))
    a1, b1, a2, b2 = r1 * math.cos(mu0), r1 * math.sin(mu0), r2 * math.cos(2 * mu0), r2 * math.sin(2 * mu0)
    D = emep(a1, b1, a2, b2, mu)[0]
    got = [float(np.sum(D * f(k * mu)) * dmu) for k in (1, 2) for f in (np.cos, np.sin)]
    np.testing.assert_allclose(got, [a1, b1, a2, b2], atol=1e-7)
    Dt = spreading_function("cos2s", mu - mu0, s)
    assert float(np.sum(np.abs(D - Dt)) * dmu) < 0.01
    assert float(np.sum(np.abs(mem(a1, b1, a2, b2, mu)[0] - Dt)) * dmu) > 0.3
    kappa = brentq(lambda k: i1e(k) / i0e(k) - r1, 1e-6, 500.0)
    vm = np.exp(kappa * (np.cos(mu - mu0) - 1.0)) / (TWO_PI * i0e(kappa))
    D1 = emep(a1, b1, a2, b2, mu, orders=(1,))[0]
    np.testing.assert_allclose(D1, vm, rtol=1e-6)  # the dual regularisation ε = 1e-9 shifts κ by ~ε κ/Var


def test_emep_with_noise_picks_the_order_by_aic_and_stays_finite():
    """Von Mises moments (second moments I₂(κ)/I₀(κ)) with a large dof: AIC keeps N = 1 (no better fit
    worth 2 more parameters); a non-realizable set (|c₂| > 1) still gives a finite, normalised density."""
    from scipy.special import ive
    mu = np.linspace(0.0, TWO_PI, 360, endpoint=False)
    dmu = TWO_PI / mu.size
    kappa = 5.0
    r1, r2 = ive(1, kappa) / ive(0, kappa), ive(2, kappa) / ive(0, kappa)
    D = emep(r1, 0.0, r2, 0.0, mu, dof=40.0)[0]
    vm = np.exp(kappa * (np.cos(mu) - 1.0)) / (TWO_PI * ive(0, kappa))
    assert np.max(np.abs(D - vm)) < 1e-3 * vm.max()
    Dbad = emep(0.5, 0.0, 1.2, 0.0, mu, dof=30.0)[0]
    assert np.all(np.isfinite(Dbad)) and float(np.sum(Dbad) * dmu) == pytest.approx(1.0)


def test_buoy_reports_from_a_record(tmp_path):
    """The buoy's transmitted reports written as a record group read back as FourierCoefficients."""
    field = _field()
    d = _buoy(field, seed=2)
    t, ch = d.process({"t": np.arange(0.0, 1805.0, 1.0)})
    meta = {k: (v if not isinstance(v, (list, dict)) else __import__("json").dumps(v)) for k, v in d.meta().items()}
    groups = {"buoy": {"time": t, "variables": {c: (ch[c], u, ln) for c, (u, ln) in d.channels.items()},
                       "attrs": meta}}
    write_groups(tmp_path / "r.nc", groups, {"content": "record"})
    tt, reps = buoy_reports(Record(tmp_path / "r.nc"), "buoy")
    assert tt.size == 1
    np.testing.assert_array_equal(reps[0].a1, ch["a1"][0])
    np.testing.assert_allclose(reps[0].omega, d.meta()["omega_rad_s"])
    hs, mdir, sp = reps[0].bulk()
    assert hs == pytest.approx(ch["hs"][0], rel=1e-12)
    assert mdir == pytest.approx(ch["mean_direction_to"][0], abs=1e-12)


def test_observed_sea_from_buoy_reports_has_the_stawave_format():
    """Two 30-min reports of a JONSWAP (γ = 3.3) sea → one observed system as team["sea_observed"] has it:
    H_s within 3 of its stated standard errors, T_p within 5 %, direction (from) within 5°, γ in [2, 5]."""
    from vtrials.reduce.directional import observed_sea
    field = _field(frm=250.0, s=10.0, tp=9.0, hs=2.0, seed=8)
    d = _buoy(field, seed=9)
    _, reps, _ = _reports(d, 2)
    (sys,) = observed_sea(reps, d.record)
    assert set(sys) == {"hs_m", "tp_s", "gamma", "from_rad", "hs_rel_std", "tp_rel_std", "from_std_rad"}
    truth = band_truth(field, reps[0].omega[0], reps[0].omega[-1])
    assert abs(sys["hs_m"] / truth["hs_m"] - 1.0) < 3.0 * sys["hs_rel_std"]
    assert sys["tp_s"] == pytest.approx(9.0, rel=0.05)
    assert abs(math.degrees(math.remainder(sys["from_rad"] - math.radians(250.0), 2 * math.pi))) < 5.0
    assert 2.0 <= sys["gamma"] <= 5.0


def test_bad_buoy_settings_name_file_and_field():
    """A scenario's [instrument.set] for a buoy: position_m must be [north, east]; unknown variants are refused
    with the allowed values; a buoy needs no hull site."""

    from vtrials.errors import InputError
    from vtrials.instruments.suite import InstrumentSet
    from vtrials.physics.vessel import load_vessel
    from pathlib import Path
    vessel = load_vessel(Path(__file__).resolve().parents[1] / "models" / "patrol51")
    site = {"transponders": [[-10000.0, -6000.0], [-10000.0, 6000.0]], "transponder_side": -1.0,
            "hydrophones": [[-600.0, -800.0], [-600.0, 800.0]], "hydrophone_side": -1.0, "water_depth_m": 200.0,
            "range_center": [10.0, 20.0]}
    ok = InstrumentSet(vessel, 1, site, [{"name": "b", "spec": "directional_waverider",
                                          "set": {"position_m": [100.0, -50.0]}}], "s.toml")
    assert ok.devices["b"].position.tolist() == [100.0, -50.0] and ok.needs_sea
    default = InstrumentSet(vessel, 1, site, [{"name": "b", "spec": "directional_waverider"}], "s.toml")
    assert default.devices["b"].position.tolist() == [10.0, 20.0]
    with pytest.raises(InputError, match=r"s\.toml.*instrument\[0\]\.set\.position_m.*north, east"):
        InstrumentSet(vessel, 1, site, [{"name": "b", "spec": "directional_waverider", "set": {"position_m": 5.0}}],
                      "s.toml")
    with pytest.raises(InputError, match=r"instrument\[0\]\.measures.*displacements, slopes"):
        InstrumentSet(vessel, 1, site, [{"name": "b", "spec": "directional_waverider",
                                         "set": {"measures": "pressure"}}], "s.toml")
    with pytest.raises(InputError, match=r"instrument\[0\]\.site"):
        InstrumentSet(vessel, 1, site, [{"name": "m", "spec": "tsk_relative_motion"}], "s.toml")


def test_score_wave_record_scores_buoys_and_radars(tmp_path):
    """A record with a moored buoy and a radar: the buoy's reports are scored per method (the acceptance
    holds for EMEP here), the radar's H_s ratio is near its drawn calibration scale."""
    import json
    from vtrials.instruments.wave_sensors import WaveRadar
    from vtrials.score.waves import score_wave_record
    field = _field(seed=12)
    b = _buoy(field, seed=13)
    rspec = dict(load_catalogue()["wave_radar_recalibrated"], n_directions=24, frequencies_hz=[0.03, 0.35, 16])
    r = WaveRadar("radar", rspec, "sea", np.zeros(3), {})
    r.attach_sea(field)
    r.reset(np.random.default_rng(14))
    groups = {}
    for d in (b, r):
        t, ch = d.process({"t": np.arange(0.0, 3605.0, 1.0)})
        meta = {k: (json.dumps(v) if isinstance(v, (list, dict)) else v) for k, v in d.meta().items()}
        groups[d.name] = {"time": t, "variables": {c: (ch[c], u, ln) for c, (u, ln) in d.channels.items()},
                          "attrs": meta}
    write_groups(tmp_path / "r.nc", groups, {"content": "record"})
    sc = score_wave_record(Record(tmp_path / "r.nc"), field)
    assert set(sc) == {"buoy", "radar"}
    assert sc["buoy"]["EMEP"]["n"] == 2 and sc["buoy"]["EMEP"]["fraction_within"] == 1.0
    assert abs(sc["buoy"]["hs_window"]["error_mean"]) < 0.03
    assert sc["radar"]["n"] >= 28
    assert sc["radar"]["tp_ratio_median"] == pytest.approx(1.0, abs=0.05)
    assert score_wave_record(Record(tmp_path / "r.nc"), None) == {}
