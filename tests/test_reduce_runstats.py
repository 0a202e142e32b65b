"""vtrials.reduce.runstats on synthetic records whose statistics are known."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import signal

from vtrials.reduce import runstats as R
from vtrials.reduce.estimate import Estimate
from vtrials.units import DEG, KNOT, RPM

# 95 % coverage of N Monte Carlo trials: accept 0.95 ± 3 binomial standard errors
N_MC = 300
TOL_MC = 3.0 * math.sqrt(0.95 * 0.05 / N_MC)  # ≈ 0.038


def ar1(rng, n, phi, sigma, burn=200):
    """AR(1) noise x_i = φ x_{i−1} + e_i (stationary after burn-in)."""
    return signal.lfilter([1.0], [1.0, -phi], rng.normal(0.0, sigma, n + burn))[burn:]


def test_channel_stats_basic_values_and_window():
    t = np.arange(0.0, 100.0, 0.5)
    x = 3.0 + np.sin(0.7 * t)
    st = R.channel_stats(t, x, 10.0, 60.0)
    m = (t >= 10.0) & (t <= 60.0)
    assert st.n == m.sum() == 101
    assert st.mean == pytest.approx(x[m].mean(), abs=1e-14)
    assert st.std == pytest.approx(x[m].std(ddof=1), rel=1e-12)
    assert st.min == pytest.approx(x[m].min(), abs=1e-14)
    assert st.max == pytest.approx(x[m].max(), abs=1e-14)
    assert 1.0 <= st.n_eff <= st.n
    e = st.estimate()
    assert isinstance(e, Estimate) and e.std == pytest.approx(st.se)


def test_white_noise_effective_size_close_to_n():
    rng = np.random.default_rng(11)
    x = rng.normal(0.0, 2.0, 4000)
    st = R.channel_stats(np.arange(x.size), x)
    assert st.n_eff > 0.8 * st.n  # white noise: almost every sample independent
    assert st.se == pytest.approx(st.std / math.sqrt(st.n), rel=0.15)


def test_ar1_standard_error_coverage_and_bayley_hammersley():
    """AR(1), φ = 0.8: n/n_eff → (1 + φ)/(1 − φ) = 9. The corrected SE gives ~95 % coverage of
    the true mean (0); the naive σ/√n covers only about half the time."""
    rng = np.random.default_rng(2)
    n, phi = 1500, 0.8
    cover = naive = 0
    ratios = []
    for _ in range(N_MC):
        x = ar1(rng, n, phi, 1.0)
        st = R.channel_stats(np.arange(n), x)
        cover += st.estimate().covers(0.0)
        naive += abs(st.mean) <= 1.96 * st.std / math.sqrt(n)
        ratios.append(n / st.n_eff)
    assert abs(cover / N_MC - 0.95) <= TOL_MC
    assert naive / N_MC < 0.65
    assert np.mean(ratios) == pytest.approx((1 + phi) / (1 - phi), rel=0.15)


def test_angular_channel_across_north():
    rng = np.random.default_rng(3)
    true = 1.0 * DEG  # heading 001°, samples straddle 000°
    x = np.mod(true + rng.normal(0.0, 2.0 * DEG, 2000), 2 * math.pi)
    st = R.channel_stats(np.arange(x.size), x, angular=True)
    d = R.wrap_pi(st.mean - true)
    assert abs(d) < 4 * st.se + 1e-12
    assert st.std == pytest.approx(2.0 * DEG, rel=0.05)
    assert st.min <= st.mean <= st.max
    assert st.max - st.min < 20 * DEG  # not the 360° a linear min/max would report
    # a linear mean would be ~180°
    assert abs(R.wrap_pi(np.mean(x) - true)) > 90 * DEG


def test_run_table_and_shaft_power():
    t = np.arange(0.0, 180.0, 1.0)
    q = np.full(t.size, 1000.0)  # N m
    n = np.full(t.size, 120.0 * RPM)  # 120 r/min
    p = R.shaft_power(q, n)
    # P [kW] = Q [N m] · r/min / 9549 (9549.3 = 60000/2π)
    assert p[0] / 1000.0 == pytest.approx(1000.0 * 120.0 / (60000.0 / (2 * math.pi)), rel=1e-12)
    assert p[0] / 1000.0 == pytest.approx(1000.0 * 120.0 / 9549.0, rel=1e-4)
    tab = R.run_table(t, {"torque": q, "rps": n, "heading": np.full(t.size, 0.1)}, 0.0, 60.0,
                      angular=("heading",))
    assert tab["torque"].mean == 1000.0 and tab["heading"].angular
    ps = R.shaft_power_stats(t, q, n)
    assert ps.mean == pytest.approx(p[0])


def test_shaft_power_estimate_propagation():
    qe = Estimate(2.0e5, 2.0e3, 50)  # 1 %
    ne = Estimate(2.0, 0.01, 50)  # 0.5 %
    pe = R.shaft_power_estimate(qe, ne)
    assert pe.value == pytest.approx(2 * math.pi * 2.0 * 2.0e5)
    assert pe.std / pe.value == pytest.approx(math.hypot(0.01, 0.005), rel=1e-12)
    assert pe.dof > 50  # Welch–Satterthwaite: more than either input alone


@pytest.mark.parametrize("cog_deg", [10.0, 100.0, 190.0, 280.0, 359.0])
def test_sog_from_exact_track(cog_deg):
    t = np.arange(0.0, 300.0, 1.0)
    v = 12.0 * KNOT
    c = cog_deg * DEG
    north = 50.0 + v * t * math.cos(c)
    east = -20.0 + v * t * math.sin(c)
    f = R.sog_from_track(t, north, east, 60.0, 240.0)
    assert f.sog.value == pytest.approx(v, rel=1e-12)
    assert abs(R.wrap_pi(f.cog.value - c)) < 1e-12
    assert f.along_rms < 1e-9 and f.cross_rms < 1e-9
    assert f.n == 181


def test_sog_from_track_correlated_noise_coverage():
    """Snaking track: AR(1) along- and cross-track position noise (φ = 0.8, 0.5 m). The SOG and COG
    intervals cover the truth at about 95 %."""
    rng = np.random.default_rng(5)
    t = np.arange(0.0, 1200.0, 1.0)
    v, c = 6.0, 250.0 * DEG
    cov_s = cov_c = 0
    for _ in range(N_MC):
        al, cr = ar1(rng, t.size, 0.8, 0.5), ar1(rng, t.size, 0.8, 0.5)
        north = v * t * math.cos(c) + al * math.cos(c) - cr * math.sin(c)
        east = v * t * math.sin(c) + al * math.sin(c) + cr * math.cos(c)
        f = R.sog_from_track(t, north, east)
        cov_s += f.sog.covers(v)
        lo, hi = f.cog.interval()
        cov_c += abs(R.wrap_pi(f.cog.value - c)) <= (hi - f.cog.value)
    assert abs(cov_s / N_MC - 0.95) <= TOL_MC
    assert abs(cov_c / N_MC - 0.95) <= TOL_MC


def test_exp_kernel_form_equals_the_dense_quadratic_form():
    rng = np.random.default_rng(2)
    t = np.cumsum(rng.uniform(0.2, 2.0, 80))  # irregular sampling
    x = rng.normal(size=t.size)
    for tau in (0.0, 3.0, 40.0):
        R_ = np.eye(t.size) if tau == 0 else np.exp(-np.abs(t[:, None] - t[None, :]) / tau)
        assert R.exp_kernel_form(t, x, tau) == pytest.approx(x @ R_ @ x, rel=1e-12)


def test_sog_from_track_with_the_data_sheet_fix_errors_covers_a_short_run():
    """A 5-min run whose fixes wander with a 30-s Gauss–Markov error (2 m) plus 1.8 m white, per axis
    (the Falcon radar's range error, seed 002): the residuals' sandwich variance alone is biased low
    on a window only ten correlation times long; with the data sheet's error model (type B) the SOG
    and COG intervals cover ~95 %."""
    rng = np.random.default_rng(8)
    t = np.arange(0.0, 300.0, 1.0)
    v, c = 4.0, 30.0 * DEG
    phi = math.exp(-1.0 / 30.0)
    ex, ey = np.tile([1.0, 0.0], (t.size, 1)), np.tile([0.0, 1.0], (t.size, 1))
    model = [(g, sd, tau) for sd, tau in ((2.0, 30.0), (1.8, 0.0)) for g in (ex, ey)]
    cov_plain = cov_model = cov_c = 0
    for _ in range(N_MC):
        en = ar1(rng, t.size, phi, 2.0 * math.sqrt(1 - phi ** 2), burn=400) + rng.normal(0.0, 1.8, t.size)
        ee = ar1(rng, t.size, phi, 2.0 * math.sqrt(1 - phi ** 2), burn=400) + rng.normal(0.0, 1.8, t.size)
        north, east = v * t * math.cos(c) + en, v * t * math.sin(c) + ee
        cov_plain += R.sog_from_track(t, north, east).sog.covers(v)
        f = R.sog_from_track(t, north, east, fix_errors=model)
        cov_model += f.sog.covers(v)
        lo, hi = f.cog.interval()
        cov_c += abs(R.wrap_pi(f.cog.value - c)) <= (hi - f.cog.value)
    assert cov_plain / N_MC < 0.9  # what the model corrects
    assert abs(cov_model / N_MC - 0.95) <= TOL_MC
    assert abs(cov_c / N_MC - 0.95) <= TOL_MC


def _displayed_from_profile(rng, v_of_t, x_of_t, t_start, t_end):
    """A LORAN-like display: irregular updates every 15–60 s; each value = mean speed since the
    previous update (distance/time)."""
    tu = [t_start]
    while tu[-1] < t_end:
        tu.append(tu[-1] + rng.uniform(15.0, 60.0))
    tu = np.array(tu)
    vals = np.r_[v_of_t(t_start), np.diff(x_of_t(tu)) / np.diff(tu)]
    return tu, vals


def test_sog_from_displayed_interval_weighting_is_distance_over_time():
    rng = np.random.default_rng(7)
    V0, A, w = 8.0, 0.6, 2 * math.pi / 100.0  # 100-s helm-induced surge

    def v(t):
        return V0 + A * np.sin(w * t)

    def x(t):
        return V0 * t - A / w * np.cos(w * t)

    tu, vals = _displayed_from_profile(rng, v, x, 0.0, 900.0)
    est = R.sog_from_displayed(tu, vals)
    exact = (x(tu[-1]) - x(tu[0])) / (tu[-1] - tu[0])
    assert est.value == pytest.approx(exact, abs=1e-12)
    assert est.std > 0 and est.dof == tu.size - 2
    assert est.covers(V0)
    # the hold weighting is a different (biased for this display) average
    hold = R.sog_from_displayed(tu, vals, weighting="hold")
    assert hold.value != pytest.approx(exact, abs=1e-9)
    # a window: only updates whose interval lies inside it
    est_w = R.sog_from_displayed(tu, vals, 100.0, 600.0)
    inside = (tu[:-1] >= 100.0) & (tu[1:] <= 600.0)
    k0, k1 = np.nonzero(inside)[0][[0, -1]]
    assert est_w.value == pytest.approx((x(tu[k1 + 1]) - x(tu[k0])) / (tu[k1 + 1] - tu[k0]), abs=1e-12)


def test_updates_from_samples():
    t = np.arange(10.0)
    x = np.array([5, 5, 5, 6, 6, 7, 7, 7, 7, 8.0])
    tu, xu = R.updates_from_samples(t, x)
    assert tu.tolist() == [0, 3, 5, 9] and xu.tolist() == [5, 6, 7, 8]
