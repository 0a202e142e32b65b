"""Positioning and timing instruments (issue 17 item 6): range–range radar multipath, transponder
delays and station survey error; GNSS multipath, latency and outages; the loggers' clocks.

Each mechanism's parameter is recovered from a long simulated record (or many simulated trials) and
compared with the catalogue value within a tolerance derived from the sampling error of the estimate.
The end-to-end check simulates measured-mile runs with the catalogue range–range radar and measures the
spread of the per-run speed over ground against seed 002's ±0.05 kn steady-speed accuracy.
"""

from __future__ import annotations

import functools
import math

import numpy as np
import pytest

from vtrials.errors import InputError
from vtrials.instruments import parts as P
from vtrials.instruments.devices import GNSS, AcousticRange, RangeRadar
from vtrials.instruments.suite import InstrumentSet, load_catalogue
from vtrials.physics.vessel import load_vessel
from vtrials.reduce.runstats import sog_from_track
from vtrials.units import KNOT

# the patrol51 standardization range (scenarios/patrol51_standardization.toml): base course 045°
SITE = {"transponders": [[-12000.0, -9000.0], [-12000.0, 9000.0]], "transponder_side": -1.0}
CAT = load_catalogue()


def _track(t, north, east, vn=0.0, ve=0.0):
    """Truth columns of a ship at constant velocity, level, heading north (site at the origin)."""
    z = np.zeros(t.size)
    o = np.ones(t.size)
    return {"t": t, "x": north + vn * t, "y": east + ve * t, "z": z, "qw": o, "qx": z, "qy": z, "qz": z,
            "u": vn * o, "v": ve * o, "w": z, "p": z, "q": z, "r": z, "heading": z}


def _autocov(e: np.ndarray, lags) -> np.ndarray:
    """Sample autocovariance of the (n, k) regular series e at integer lags, averaged over its k columns."""
    e = e - e.mean(axis=0)
    n = e.shape[0]
    return np.array([np.mean(np.sum(e[: n - k] * e[k:], axis=0) / (n - k)) for k in lags])


def _ou_slope_var(t, tau, sigma, white):
    """Variance of the least-squares slope of a series whose error is a first-order Gauss–Markov process
    (sd sigma, correlation time tau) plus white noise (sd white): wᵀ C w, w = (t − t̄)/S_tt."""
    dt = t - t.mean()
    w = dt / np.dot(dt, dt)
    C = sigma ** 2 * np.exp(-np.abs(t[:, None] - t[None, :]) / tau) + white ** 2 * np.eye(t.size)
    return float(w @ C @ w)


# --------------------------------------------------------------------------------- range–range radar
def test_range_radar_multipath_is_the_catalogue_gauss_markov_process():
    """Static ship, 2·10⁵ s at 1 Hz: the range errors' autocovariance is σ_m² e^{−k/τ} for lags k ≥ 1
    (multipath) plus σ_w² at lag 0 (white). Sampling error of a sample autocovariance of a Gauss–Markov
    series of N samples: relative sd ≈ √(2τ/N) per range (Bartlett), √(τ/N) for the two ranges
    together — 1.2 % here; tolerances are 4 of those (σ_m²), and for τ (from the ratio of lags 1 and
    30, errors of each ≲ 2 %, ln-ratio 0.97) 10 %."""
    spec = dict(CAT["falcon_radar"])
    spec.pop("clock_offset_s")
    dev = RangeRadar("falcon", spec, "mast", np.zeros(3), {"site": SITE})
    dev.reset(np.random.default_rng(3))
    T = 200000.0
    p0 = np.array([0.0, 0.0])
    t, ch = dev.process(_track(np.arange(0.0, T, 1.0), *p0))
    st = np.array(SITE["transponders"]) + np.array(dev.drawn()["survey_error_m"])
    bias = np.array(dev.drawn()["chain"]["parts"][1]["bias"])  # Resample, Bias, GaussMarkov, WhiteNoise
    r_true = np.linalg.norm(p0 - st, axis=1)
    err = np.column_stack([ch["range_a"], ch["range_b"]]) - r_true - bias
    gm = spec["gauss_markov"]
    sm2, tau, sw2 = gm["sd"] ** 2, gm["tau_s"], spec["noise"] ** 2
    n = err.shape[0]
    assert abs(err.mean()) < 4 * math.sqrt(2 * sm2 * tau / n / 2)  # the drawn bias is the whole offset
    c = _autocov(err, [0, 1, 30])
    rel = math.sqrt(tau / n)
    tau_hat = 29.0 / math.log(c[1] / c[2])
    sm2_hat = c[1] * math.exp(1.0 / tau_hat)
    print(f"radar multipath: tau {tau_hat:.2f} s (cat {tau}), sd {math.sqrt(sm2_hat):.3f} m (cat {math.sqrt(sm2)}), "
          f"white {math.sqrt(max(c[0] - sm2_hat, 0)):.3f} m (cat {math.sqrt(sw2)})")
    assert tau_hat == pytest.approx(tau, rel=0.10)
    assert sm2_hat == pytest.approx(sm2, rel=4 * rel + 0.02)  # + the τ̂ error carried into e^{1/τ̂}
    assert c[0] - sm2_hat == pytest.approx(sw2, rel=0.08)
    assert math.sqrt(sm2 + sw2) == pytest.approx(2.7, rel=0.01)  # seed 002's ±2.7 m range error


def test_transponder_delays_and_survey_errors_are_drawn_per_trial_and_bias_the_fix():
    """Per trial, each transponder's delay ~ N(0, 1.0²) m and each station's survey error ~ N(0, 0.5²) m
    per axis (2000 trials: sample sd within 4/√(2·4000) of the catalogue sd); and in one trial the fix
    is biased by exactly what the two-range geometry predicts: J δp = b − (u_a·δs_a, u_b·δs_b), with
    u the unit vectors from the stations to the ship (mean over 2·10⁴ s; its standard error from the
    multipath, ≈ 0.1 m, sets the tolerance)."""
    spec = dict(CAT["falcon_radar"])
    spec.pop("clock_offset_s")
    dev = RangeRadar("falcon", spec, "mast", np.zeros(3), {"site": SITE})
    biases, surveys = [], []
    for k in range(2000):
        dev.reset(np.random.default_rng(1000 + k))
        d = dev.drawn()
        biases.append(d["chain"]["parts"][1]["bias"])
        surveys.append(d["survey_error_m"])
    b = np.array(biases).ravel()
    s = np.array(surveys).ravel()
    print(f"transponder delay sd {b.std():.4f} m (cat {spec['bias']['sd']}), survey sd {s.std():.4f} m "
          f"(cat {spec['survey_sd_m']})")
    assert b.std() == pytest.approx(spec["bias"]["sd"], rel=4 / math.sqrt(2 * b.size))
    assert s.std() == pytest.approx(spec["survey_sd_m"], rel=4 / math.sqrt(2 * s.size))
    assert abs(b.mean()) < 4 * spec["bias"]["sd"] / math.sqrt(b.size)
    # one trial with a large survey error and delay, to see the geometry
    spec2 = {**spec, "bias": {"mean": 0.0, "sd": 5.0}, "survey_sd_m": 5.0}
    dev = RangeRadar("falcon", spec2, "mast", np.zeros(3), {"site": SITE})
    dev.reset(np.random.default_rng(7))
    p0 = np.array([-2000.0, 3000.0])
    t, ch = dev.process(_track(np.arange(0.0, 20000.0, 1.0), *p0))
    d = dev.drawn()
    bias, ds = np.array(d["chain"]["parts"][1]["bias"]), np.array(d["survey_error_m"])
    st = np.array(SITE["transponders"])
    u = (p0 - st) / np.linalg.norm(p0 - st, axis=1)[:, None]
    dp_pred = np.linalg.solve(u, bias - np.sum(u * ds, axis=1))
    dp = np.array([ch["north"].mean() - p0[0], ch["east"].mean() - p0[1]])
    assert np.linalg.norm(dp_pred) > 3.0  # a bias well above the tolerance
    print(f"radar fix bias {dp} m, predicted from the geometry {dp_pred} m")
    np.testing.assert_allclose(dp, dp_pred, atol=0.5)


def test_range_radar_per_run_sog_scatter_is_seed_002s():
    """400 measured-mile runs (1 nmi at 15 kn on the base course 045°, 240 s) with the catalogue Falcon,
    each trial with its own draws; SOG from the straight-line fit of the fixes (the reduction's
    method). The per-run SOG error's sd matches the prediction of the Gauss–Markov + white range errors
    mapped through the geometry (transponder delays and survey errors add < 1 % in variance: neglected),
    within 4/√(2·400) = 14 %; and 2σ is of the order of seed 002's ±0.05 kn — where the former white
    2.7 m range noise gave a tenth of that."""
    spec = dict(CAT["falcon_radar"])
    spec.pop("clock_offset_s")
    U = 15.0 * KNOT
    T = 1852.0 / U
    c, s_ = math.cos(math.radians(45.0)), math.sin(math.radians(45.0))
    t = np.arange(0.0, T + 10.0, 0.5)
    cols = _track(t, -926.0 * c, -926.0 * s_, U * c, U * s_)
    white = {**{k: v for k, v in spec.items() if k not in ("gauss_markov", "bias", "survey_sd_m")}, "noise": 2.7}
    err, err_white = [], []
    for k in range(400):
        for sp, out in ((spec, err), (white, err_white)):
            dev = RangeRadar("falcon", sp, "mast", np.zeros(3), {"site": SITE})
            dev.reset(np.random.default_rng(5000 + k))
            tt, ch = dev.process(cols)
            out.append(sog_from_track(tt, ch["north"], ch["east"], 5.0, 5.0 + T).sog.value - U)
    err, err_white = np.array(err), np.array(err_white)
    # prediction: along-track error = g·δr at mid-run, g = along-track row of J⁻¹
    st = np.array(SITE["transponders"])
    u = (0.0 - st) / np.linalg.norm(st, axis=1)[:, None]
    g = np.array([c, s_]) @ np.linalg.inv(u)
    ts = np.arange(5.0, 5.0 + T, 1.0)  # 1-Hz fixes in the window
    v1 = _ou_slope_var(ts, spec["gauss_markov"]["tau_s"], spec["gauss_markov"]["sd"], spec["noise"])
    sd_pred = math.sqrt(float(g @ g) * v1)
    assert err.std() == pytest.approx(sd_pred, rel=4 / math.sqrt(2 * err.size))
    assert abs(err.mean()) < 4 * sd_pred / math.sqrt(err.size)
    two_sigma_kn = 2 * err.std() / KNOT
    print(f"per-run SOG error: sd {err.std() / KNOT:.4f} kn (predicted {sd_pred / KNOT:.4f}), mean "
          f"{err.mean() / KNOT:.4f} kn, 2 sd {two_sigma_kn:.4f} kn; white-only model 2 sd {2 * err_white.std() / KNOT:.4f} kn")
    assert 0.03 < two_sigma_kn < 0.07  # seed 002 Table 2: steady ship speed, pulse radar, ±0.05 kn
    assert 2 * err_white.std() / KNOT < 0.015  # the white-only model was far too clean


def test_acoustic_range_hydrophone_survey_error_biases_the_fix():
    """Acoustic range (seed 002): the hydrophones' survey errors (drawn per trial, catalogue sd) bias
    the fix by J⁻¹(−u·δh) (u: horizontal unit vectors from the hydrophones to the ship); the mean of
    ~8000 fixes (white 0.5 m range noise: standard error ≈ 0.01 m) matches within 0.1 m."""
    site = {"hydrophones": [[-600.0, -800.0], [-600.0, 800.0]], "hydrophone_side": -1.0, "water_depth_m": 200.0}
    spec = {**CAT["acoustic_range"], "survey_sd_m": 3.0}
    dev = AcousticRange("acoustic", spec, "hull", np.zeros(3), {"site": site})
    sds = []
    for k in range(1000):
        dev.reset(np.random.default_rng(600 + k))
        sds.append(dev.drawn()["survey_error_m"])
    assert np.std(sds) == pytest.approx(3.0, rel=4 / math.sqrt(2 * 4000))
    dev.reset(np.random.default_rng(9))
    p0 = np.array([300.0, 200.0])
    t, ch = dev.process(_track(np.arange(0.0, 20000.0, 0.5), *p0))
    dh = np.array(dev.drawn()["survey_error_m"])
    h = np.array(site["hydrophones"])
    u = (p0 - h) / np.linalg.norm(p0 - h, axis=1)[:, None]
    dp_pred = np.linalg.solve(u, -np.sum(u * dh, axis=1))
    dp = np.array([ch["north"].mean() - p0[0], ch["east"].mean() - p0[1]])
    assert np.linalg.norm(dp_pred) > 1.0
    print(f"acoustic fix bias {dp} m, predicted {dp_pred} m")
    np.testing.assert_allclose(dp, dp_pred, atol=0.1)


# ------------------------------------------------------------------------------------------- GNSS
def _gnss(name, **over):
    spec = {**CAT[name], **over}
    return GNSS("gnss", spec, "antenna", np.zeros(3), {})


def test_gnss_multipath_and_correction_error_autocovariance():
    """Static antenna, 4·10⁵ s at 1 Hz. (a) multipath alone: σ and τ recovered (tolerances as for the
    radar: relative sd of the autocovariances √(τ/N) for the two axes, 0.5 %); (b) the dgps entry:
    the autocovariance at lags 1, 10, 60, 200 s is σ_c² e^{−k/τ_c} + σ_m² e^{−k/τ_m} (sampling error
    dominated by the 120-s process: √(τ_c/N) = 1.7 %, tolerance 4 of those)."""
    cat = CAT["dgps"]
    mp = cat["multipath"]
    T = 400000.0
    cols = _track(np.arange(0.0, T, 1.0), 0.0, 0.0)
    dev = _gnss("dgps", gauss_markov={"sd": 0.0, "tau_s": 1.0}, noise=0.0, dropout_p=0.0,
                outages={"rate_per_h": 0.0, "duration_s": 1.0}, latency_s=0.0)
    dev.reset(np.random.default_rng(21))
    t, ch = dev.process(cols)
    e = np.column_stack([ch["north"], ch["east"]])
    c = _autocov(e, [1, 20])
    tau_hat = 19.0 / math.log(c[0] / c[1])
    n = e.shape[0]
    print(f"gnss multipath: tau {tau_hat:.2f} s (cat {mp['tau_s']}), sd {math.sqrt(c[0] * math.exp(1.0 / tau_hat)):.4f} m "
          f"(cat {mp['sd']})")
    assert tau_hat == pytest.approx(mp["tau_s"], rel=0.10)
    assert c[0] * math.exp(1.0 / tau_hat) == pytest.approx(mp["sd"] ** 2, rel=4 * math.sqrt(mp["tau_s"] / n) + 0.01)
    # the whole dgps error (no outages, so the series is regular)
    dev = _gnss("dgps", dropout_p=0.0, outages={"rate_per_h": 0.0, "duration_s": 1.0}, latency_s=0.0)
    dev.reset(np.random.default_rng(22))
    t, ch = dev.process(cols)
    e = np.column_stack([ch["north"], ch["east"]])
    lags = [1, 10, 60, 200]
    gm = cat["gauss_markov"]
    pred = np.array([gm["sd"] ** 2 * math.exp(-k / gm["tau_s"]) + mp["sd"] ** 2 * math.exp(-k / mp["tau_s"])
                     for k in lags])
    tol = 4 * math.sqrt(gm["tau_s"] / e.shape[0]) * (gm["sd"] ** 2 + mp["sd"] ** 2)
    print("dgps autocovariance at", lags, "s:", np.round(_autocov(e, lags), 4), "model", np.round(pred, 4), "tol", round(tol, 4))
    np.testing.assert_allclose(_autocov(e, lags), pred, atol=tol)


@pytest.mark.parametrize("name", ["dgps", "rtk_gnss"])
def test_gnss_latency_is_the_time_tag_offset(name):
    """Ship at 10 m/s due north for 10⁵ s: a fix stamped t describes t − L, so its mean along-track
    error is −U·L. L recovered within 4 standard errors of the mean error (the 120-/60-s correction
    error dominates: se ≈ σ_c √(2τ_c/T))."""
    cat = CAT[name]
    U = 10.0
    T = 100000.0
    dev = _gnss(name, outages={"rate_per_h": 0.0, "duration_s": 1.0})
    dev.reset(np.random.default_rng(31))
    t, ch = dev.process(_track(np.arange(0.0, T, 0.1), 0.0, 0.0, U, 0.0))
    err = ch["north"] - U * t
    gm = cat["gauss_markov"]
    se = math.sqrt(gm["sd"] ** 2 * 2 * gm["tau_s"] / T + cat["multipath"]["sd"] ** 2 * 2 * cat["multipath"]["tau_s"] / T)
    L_hat = -err.mean() / U
    print(f"{name} latency {L_hat:.4f} s (cat {cat['latency_s']}), 4 se {4 * se / U:.4f} s")
    assert L_hat == pytest.approx(cat["latency_s"], abs=4 * se / U)
    assert 4 * se / U < 0.25 * cat["latency_s"]  # the test resolves the latency


@pytest.mark.parametrize("name", ["dgps", "rtk_gnss"])
def test_gnss_outages_rate_and_duration(name):
    """The catalogue outage process over 1000 h (1 Hz): number of outages ~ Poisson with mean
    T/(U + D) (tolerance 4√n), mean up time 1/rate and mean outage length D within 4 standard errors
    (exponential: sd = mean; fixed: exactly D), the lost fraction D/(U + D), exactly the samples inside
    the outages removed, and the same output for any chunking."""
    o = CAT[name]["outages"]
    rate, D = o["rate_per_h"] / 3600.0, o["duration_s"]
    part = P.Outages(rate, D, o["durations"])
    T = 1000 * 3600.0
    t = np.arange(0.0, T, 1.0)
    part.reset(np.random.default_rng(41))
    to, _ = part.process(t, t)
    outs = np.array(part.outages())
    outs = outs[outs[:, 1] < T]
    n = outs.shape[0]
    U = 1.0 / rate
    expect = T / (U + D)
    lengths = outs[:, 1] - outs[:, 0]
    ups = outs[1:, 0] - outs[:-1, 1]
    print(f"{name} outages: {n} (expected {expect:.1f}), mean length {lengths.mean():.3f} s (cat {D}), mean up "
          f"{ups.mean():.1f} s (cat {U:.1f}), lost {1.0 - to.size / t.size:.5f} (model {D / (U + D):.5f})")
    assert abs(n - expect) < 4 * math.sqrt(expect)
    if o["durations"] == "fixed":
        np.testing.assert_allclose(lengths[1:], D, rtol=1e-9)
    else:
        assert lengths.mean() == pytest.approx(D, abs=4 * D / math.sqrt(n))
    assert ups.mean() == pytest.approx(U, abs=4 * U / math.sqrt(n))
    allo = np.array(part.outages())
    j = np.searchsorted(allo[:, 0], t, side="right") - 1
    inside = (j >= 0) & (t < allo[np.maximum(j, 0), 1])
    np.testing.assert_array_equal(to, t[~inside])
    lost = 1.0 - to.size / t.size
    # sd of the lost time ≈ D √(2n) (lengths and count); whole samples: < 1 sample per outage
    assert lost == pytest.approx(D / (U + D), abs=4 * D * math.sqrt(2 * n) / T + n / T)
    # streaming invariance
    part2 = P.Outages(rate, D, o["durations"])
    part2.reset(np.random.default_rng(41))
    chunks = [part2.process(t[a:a + 9973], t[a:a + 9973])[0] for a in range(0, t.size, 9973)]
    np.testing.assert_array_equal(np.concatenate(chunks), to)


def test_speed_over_ground_from_a_gappy_gnss_record():
    """A 30-min run with a 4-min outage in it: the fixes simply are not there, and the straight-line
    SOG fit (the reduction) uses the rest; its error is within 4 sd of the slope error predicted for
    those very time stamps from the dgps error processes (wᵀ C w with the two Gauss–Markov
    autocovariances plus white noise)."""
    cat = CAT["dgps"]
    dev = _gnss("dgps", outages={"rate_per_h": 3.0, "duration_s": 240.0, "durations": "fixed"})
    U = 7.0
    for seed in range(50):
        dev.reset(np.random.default_rng(seed))
        t, ch = dev.process(_track(np.arange(0.0, 1800.0, 0.5), 0.0, 0.0, U, 0.0))
        if np.diff(t).max() > 200.0:
            break
    else:
        pytest.fail("no outage drawn in 50 trials")
    fit = sog_from_track(t, ch["north"], ch["east"], 0.0, 1800.0)
    assert fit.n == t.size < 1800 - 200
    gm, mp = cat["gauss_markov"], cat["multipath"]
    dt = t - t.mean()
    w = dt / np.dot(dt, dt)
    lag = np.abs(t[:, None] - t[None, :])
    C = (gm["sd"] ** 2 * np.exp(-lag / gm["tau_s"]) + mp["sd"] ** 2 * np.exp(-lag / mp["tau_s"])
         + cat["noise"] ** 2 * np.eye(t.size))
    print(f"gappy run: {fit.n} fixes, largest gap {np.diff(t).max():.1f} s, SOG error {fit.sog.value - U:.5f} m/s, "
          f"predicted sd {math.sqrt(float(w @ C @ w)):.5f} m/s")
    assert abs(fit.sog.value - U) < 4 * math.sqrt(float(w @ C @ w))


# ------------------------------------------------------------------------------------------- clocks
@functools.lru_cache(maxsize=1)
def _kvlcc2():
    return load_vessel("kvlcc2")


def _iset(items, seed=5):
    return InstrumentSet(_kvlcc2(), seed, SITE, items, "scenario.toml")


def test_logger_clocks_offset_and_drift():
    """Every instrument stamps its readings with its own logger clock: stamp = t + c + d·t. Same seed,
    clock on vs 'none': identical values (the clock draws from its own stream), stamps differ by exactly
    c + d·t with the drawn c, d. Over 2400 clocks (12 instruments × 200 trials), the offsets' and
    drifts' sd are the catalogue's (within 4/√(2·2400)) and the instruments' clocks are independent."""
    cat = CAT["logger_clock"]
    t = np.arange(0.0, 7200.0, 0.05)
    cols = _track(t, 0.0, 0.0, 5.0, 0.0)
    a = _iset([{"name": "dgps", "spec": "dgps", "site": "gnss_antenna", "clock": "logger_clock"}])
    b = _iset([{"name": "dgps", "spec": "dgps", "site": "gnss_antenna", "clock": "none"}])
    for s in (a, b):
        s.reset()
        for k in range(0, t.size, 5000):
            s.push({c: v[k:k + 5000] for c, v in cols.items()})
            s.flush(["dgps"])  # only the receiver: the truth here has no wind or machinery columns
    ta, ca = a.readings("dgps")
    tb, cb = b.readings("dgps")
    np.testing.assert_array_equal(ca["north"], cb["north"])
    clk = a.drawn()["dgps"]["logger_clock"]
    np.testing.assert_allclose(ta - tb, clk["offset_s"] + clk["drift_ppm"] * 1e-6 * tb, rtol=0, atol=1e-9)
    assert "logger_clock" not in b.drawn()["dgps"]
    # statistics over many clocks: the suite's clocks for many instruments and trials
    offs, drifts = [], []
    for seed in range(200):
        s = _iset([], seed=seed)
        s.reset()
        d = s.drawn()
        offs += [d[n]["logger_clock"]["offset_s"] for n in sorted(d)]
        drifts += [d[n]["logger_clock"]["drift_ppm"] for n in sorted(d)]
    offs, drifts = np.array(offs), np.array(drifts)
    tol = 4 / math.sqrt(2 * offs.size)
    print(f"clocks: {offs.size} drawn, offset sd {offs.std():.5f} s (cat {cat['offset_s']}), drift sd "
          f"{drifts.std():.3f} ppm (cat {cat['drift_ppm']})")
    assert offs.std() == pytest.approx(cat["offset_s"], rel=tol)
    assert drifts.std() == pytest.approx(cat["drift_ppm"], rel=tol)
    assert abs(offs.mean()) < 4 * cat["offset_s"] / math.sqrt(offs.size)
    # independent between the loggers of one ship: offsets of two instruments uncorrelated over trials
    m = len(_iset([]).devices)
    o2 = offs.reshape(-1, m)
    assert abs(np.corrcoef(o2[:, 0], o2[:, 1])[0, 1]) < 4 / math.sqrt(o2.shape[0])


def test_logger_clock_input_errors():
    with pytest.raises(InputError, match=r"scenario.toml.*instrument\[0\]\.clock.*'gps_time' is not a clock"):
        _iset([{"name": "dgps", "spec": "dgps", "site": "gnss_antenna", "clock": "gps_time"}])
    with pytest.raises(InputError, match=r"instrument\[0\]\.clock.*'gyrocompass' is not a clock"):
        _iset([{"name": "dgps", "spec": "dgps", "site": "gnss_antenna", "clock": "gyrocompass"}])


def test_range_radar_fix_error_geometry_is_the_fixs_own_response():
    """The reduction's data-sheet model of the radar's fix error (vtrials.reduce.trials._fix_errors)
    maps a range error into the fix as the fix computation itself does: against finite differences of
    two_range_fix at points of wide and narrow crossing angle."""
    from vtrials.instruments.devices import two_range_fix
    from vtrials.reduce.trials import _fix_errors
    a, b = np.array([-12000.0, -9000.0]), np.array([-12000.0, 9000.0])
    meta = {"kind": "range_radar", "transponder_a": a.tolist(), "transponder_b": b.tolist(),
            "range_errors": [[2.0, 30.0], [1.8, 0.0]]}
    p = np.array([[0.0, 0.0], [-11000.0, 200.0], [3000.0, -4000.0]])
    errs = _fix_errors(meta, p[:, 0], p[:, 1])
    assert [(sd, tau) for _, sd, tau in errs] == [(2.0, 30.0), (2.0, 30.0), (1.8, 0.0), (1.8, 0.0)]
    ra, rb = np.linalg.norm(p - a, axis=1), np.linalg.norm(p - b, axis=1)
    h = 0.01
    for G, dra, drb in ((errs[0][0], h, 0.0), (errs[1][0], 0.0, h)):
        n1, e1 = two_range_fix(ra + dra, rb + drb, a, b, -1.0)  # north of a→b: port
        n0, e0 = two_range_fix(ra - dra, rb - drb, a, b, -1.0)
        fd = np.column_stack([n1 - n0, e1 - e0]) / (2 * h)
        np.testing.assert_allclose(G, fd, rtol=1e-5, atol=1e-7)
    # near the baseline the fix's dilution is large (and the model says so)
    assert np.linalg.norm(errs[0][0][1]) > 4.0 * np.linalg.norm(errs[0][0][0])  # 4.4x at 1 km off it
