"""vtrials.reduce.current: each method is exact when its assumption holds, and its error is the
derived one when it does not (derivations in the module docstring of vtrials.reduce.current)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from vtrials.reduce import current as C
from vtrials.units import DEG, KNOT

VS = 7.0  # true speed through water [m/s]
DT = 1500.0  # spacing of the runs' mid-times [s] (25 min incl. the Williamson turn)


def runs(n, current, vs=VS, dt=DT, t0=3600.0):
    """n alternating reciprocal runs: V_G,i = V_S + (−1)^i c(t_i)."""
    t = t0 + dt * np.arange(n)
    s = (-1.0) ** np.arange(n)
    return t, vs + s * current(t)


# --------------------------------------------------------------------------------------------------
# mean of means
# --------------------------------------------------------------------------------------------------
def test_weights_are_binomial_and_sum_to_one():
    assert C.mean_of_means_weights(2).tolist() == [0.5, 0.5]
    assert C.mean_of_means_weights(3).tolist() == [0.25, 0.5, 0.25]
    assert C.mean_of_means_weights(4).tolist() == [1 / 8, 3 / 8, 3 / 8, 1 / 8]
    for n in range(2, 9):
        assert C.mean_of_means_weights(n).sum() == pytest.approx(1.0)


def test_two_run_average_constant_exact_linear_error_half_change():
    _, vg = runs(2, lambda t: 0.5 + 0 * t)
    assert C.two_run_average(vg).value == pytest.approx(VS, abs=1e-14)
    k = 0.4 / 3600.0  # current grows 0.4 m/s per hour
    t, vg = runs(2, lambda t: 0.3 + k * t)
    err = C.two_run_average(vg).value - VS
    # derived: error = (c(t1) − c(t2))/2 = −kΔ/2, half the current change between the mid-times
    assert err == pytest.approx(-k * DT / 2.0, abs=1e-14)
    assert abs(err) == pytest.approx(abs(0.3 + k * t[1] - (0.3 + k * t[0])) / 2.0, abs=1e-14)


def test_three_run_mean_of_means_linear_exact_quadratic_error():
    k1 = 0.4 / 3600.0
    _, vg = runs(3, lambda t: 0.3 + k1 * t)
    assert C.three_run_mean_of_means(vg).value == pytest.approx(VS, abs=1e-13)
    k2 = 0.2 / 3600.0 ** 2
    _, vg = runs(3, lambda t: 0.3 + k1 * t + k2 * t * t)
    # derived: error = (c1 − 2c2 + c3)/4 = 2k₂Δ²/4 = c''Δ²/4
    assert C.three_run_mean_of_means(vg).value - VS == pytest.approx(k2 * DT ** 2 / 2.0, abs=1e-13)


def test_ittc_mean_of_means_cancels_up_to_quadratic_not_cubic():
    k1, k2, k3 = 0.4 / 3600.0, 0.2 / 3600.0 ** 2, 0.05 / 3600.0 ** 3
    _, vg = runs(4, lambda t: 0.3 + k1 * t)
    assert C.ittc_mean_of_means(vg).value == pytest.approx(VS, abs=1e-13)
    _, vg = runs(4, lambda t: 0.3 + k1 * t + k2 * t * t)
    assert C.ittc_mean_of_means(vg).value == pytest.approx(VS, abs=1e-13)
    _, vg = runs(4, lambda t: 0.3 + k1 * t + k2 * t * t + k3 * t ** 3)
    # derived: error = (c1 − 3c2 + 3c3 − c4)/8 = −Δ³c/8 = −(3/4)k₃Δ³
    err = C.ittc_mean_of_means(vg).value - VS
    assert err == pytest.approx(-0.75 * k3 * DT ** 3, rel=1e-9)
    assert abs(err) > 1e-3  # a real, non-zero error


@pytest.mark.parametrize("n", [5, 6, 7])
def test_general_mean_of_means_cancels_degree_n_minus_2(n):
    coeffs = [0.3, 0.4 / 3600.0, 0.2 / 3600.0 ** 2, 0.05 / 3600.0 ** 3, 0.01 / 3600.0 ** 4,
              0.002 / 3600.0 ** 5, 4e-4 / 3600.0 ** 6]

    def cur(deg):
        return lambda t: sum(c * (t - 3600.0) ** k for k, c in enumerate(coeffs[: deg + 1]))

    _, vg = runs(n, cur(n - 2))
    assert C.mean_of_means(vg).value == pytest.approx(VS, abs=1e-12)
    # degree n−1: error = (−1)^{n−1}(n−1)! k Δ^{n−1} / 2^{n−1}
    kk = coeffs[n - 1]
    _, vg = runs(n, lambda t: kk * (t - 3600.0) ** (n - 1))
    expect = (-1) ** (n - 1) * math.factorial(n - 1) * kk * DT ** (n - 1) / 2 ** (n - 1)
    assert C.mean_of_means(vg).value - VS == pytest.approx(expect, rel=1e-8)


def test_mean_of_means_uncertainty_propagation():
    vg = np.array([7.3, 6.7, 7.31, 6.71])
    e = C.ittc_mean_of_means(vg, std=0.05)
    assert e.std == pytest.approx(0.05 * math.sqrt((1 + 9 + 9 + 1) / 64.0))
    assert math.isnan(C.ittc_mean_of_means(vg).std)  # no redundancy, no invented uncertainty


def test_polynomial_elimination_uneven_spacing():
    """With uneven spacing the binomial weights no longer cancel a quadratic current; the time-aware
    least-squares form does."""
    t = np.array([0.0, 1400.0, 3500.0, 4300.0])
    s = (-1.0) ** np.arange(4)
    cur = 0.3 + 0.4 / 3600.0 * t + 0.2 / 3600.0 ** 2 * t * t
    vg = VS + s * cur
    r = C.polynomial_current_elimination(t, vg)
    assert r.vs.value == pytest.approx(VS, abs=1e-12)
    assert abs(C.ittc_mean_of_means(vg).value - VS) > 1e-3
    # five runs, quadratic model: one dof → residual-based std, exact data → ~0
    t5 = np.r_[t, 6000.0]
    vg5 = VS + (-1.0) ** np.arange(5) * (0.3 + 0.4 / 3600.0 * t5 + 0.2 / 3600.0 ** 2 * t5 * t5)
    r5 = C.polynomial_current_elimination(t5, vg5, degree=2)
    assert r5.vs.value == pytest.approx(VS, abs=1e-12) and r5.dof == 1 and r5.vs.std < 1e-10


# --------------------------------------------------------------------------------------------------
# ITTC iterative method
# --------------------------------------------------------------------------------------------------
T_C = 12.42 * 3600.0


def _trial(current, n_spots=4, speeds=(5.0, 6.0, 7.0, 8.0), a=1.0e5, b=800.0, q=3.0, dt=1500.0):
    """n_spots × two double runs (4 runs each) alternating reciprocal headings."""
    vs = np.repeat(np.asarray(speeds[:n_spots], float), 4)
    n = vs.size
    t = 7200.0 + dt * np.arange(n)
    heading = np.tile([0.3, 0.3 + math.pi], n // 2)
    s = np.cos(heading - heading[0])
    vg = vs + s * current(t)
    power = a + b * vs ** q
    return t, vg, heading, power, vs


def test_iterative_tidal_plus_linear_current_exact():
    def cur(t):
        return 0.4 * np.cos(2 * math.pi * t / T_C + 0.7) + 0.1 + 0.15 / 3600.0 * (t - 7200.0)

    t, vg, hd, P, vs = _trial(cur)
    r = C.ittc_iterative(t, vg, hd, P)
    assert np.max(np.abs(r.vs - vs)) < 1e-8
    assert r.q.value == pytest.approx(3.0, abs=1e-8)
    assert r.a.value == pytest.approx(1.0e5, rel=1e-7)
    assert r.b.value == pytest.approx(800.0, rel=1e-8)
    assert np.max(np.abs(r.current - cur(t))) < 1e-8
    cur_fit, _ = r.current_at(np.array([9000.0, 20000.0]))
    assert np.allclose(cur_fit, cur(np.array([9000.0, 20000.0])), atol=1e-8)
    amp = math.hypot(r.current_params["V_CC"].value, r.current_params["V_CS"].value)
    assert amp == pytest.approx(0.4, abs=1e-8)
    assert r.current_params["V_CT"].value == pytest.approx(0.15 / 3600.0, rel=1e-6)
    assert r.dof == 16 - 7 and r.iterations >= 2
    # two double runs per spot would suffer from the tidal curvature without the model
    spot_mom = [C.ittc_mean_of_means(vg[4 * i: 4 * i + 4]).value for i in range(4)]
    assert np.max(np.abs(np.array(spot_mom) - vs[::4])) > 1e-4


def test_iterative_linear_model_fixed_q():
    t, vg, hd, P, vs = _trial(lambda t: -0.2 + 0.3 / 3600.0 * (t - 7200.0), n_spots=3)
    r = C.ittc_iterative(t, vg, hd, P, q=3.0, model="linear")
    assert np.max(np.abs(r.vs - vs)) < 1e-9
    assert r.q.value == 3.0 and r.names == ("a", "b", "V_CT", "V_C0")


def test_iterative_noisy_uncertainty_covers_truth():
    """Power noise 0.5 %: the fitted speeds' ±2.5σ intervals contain the truth in most runs and the
    fitted curve's q is within its interval."""
    rng = np.random.default_rng(21)

    def cur(t):
        return 0.3 * np.sin(2 * math.pi * t / T_C) + 0.05

    t, vg, hd, P, vs = _trial(cur, n_spots=4)
    Pn = P * (1.0 + 0.005 * rng.standard_normal(P.size))
    r = C.ittc_iterative(t, vg, hd, Pn)
    z = np.abs(r.vs - vs) / r.vs_std
    assert np.all(np.isfinite(z)) and np.mean(z < 2.5) >= 0.8
    assert r.q.interval(0.99)[0] <= 3.0 <= r.q.interval(0.99)[1]


# --------------------------------------------------------------------------------------------------
# four-leg resolution
# --------------------------------------------------------------------------------------------------
def legs(U, Cc, alpha, heading0=0.0):
    """Ground speeds on φ₁ … φ₁+270° for a current of C setting toward θ = φ₁ + α (vector sum)."""
    theta = heading0 + alpha
    out = []
    for k in range(4):
        ph = heading0 + k * math.pi / 2
        out.append(math.hypot(U * math.cos(ph) + Cc * math.cos(theta),
                              U * math.sin(ph) + Cc * math.sin(theta)))
    return out


ALPHAS = np.arange(0.0, 360.0, 7.5)
CPRIMES = (0.05, 0.1, 0.2, 0.3, 0.4, 0.5)


@pytest.mark.parametrize("heading0_deg", [10.0, 200.0])
def test_four_leg_recovers_current_from_every_direction(heading0_deg):
    U = 10.0 * KNOT
    h0 = heading0_deg * DEG
    for a_deg in ALPHAS:
        for cp in CPRIMES:
            a = a_deg * DEG
            r = C.four_leg_current(*legs(U, cp * U, a, h0), heading0=h0)
            assert r.u.value == pytest.approx(U, rel=1e-11)
            assert r.c.value == pytest.approx(cp * U, rel=1e-9)
            assert r.c_prime.value == pytest.approx(cp, rel=1e-9)
            assert abs(C._wrap_pi(r.alpha.value - a)) < 1e-10
            assert abs(C._wrap_pi(r.theta.value - (h0 + a))) < 1e-10
            assert r.u_ns == pytest.approx(U, rel=1e-11) and r.u_ew == pytest.approx(U, rel=1e-11)
            # each of the six derived ratio formulas on its own (NaN only where its ratio is 1)
            ok = np.isfinite(r.c_prime_i)
            assert ok.sum() >= 4
            assert np.allclose(r.c_prime_i[ok], cp, rtol=1e-6, atol=0)


def test_four_leg_negative_alpha_is_current_to_port():
    U = 5.0
    r = C.four_leg_current(*legs(U, 1.0, -40 * DEG))
    assert r.alpha.value == pytest.approx(-40 * DEG, abs=1e-12)
    assert r.theta.value == pytest.approx(320 * DEG, abs=1e-12)


def test_seed_printed_b_formulas_have_typos():
    """The seed copy prints b₂ = (B sin α − cos α)/(B − 1), b₄ = (E sin α + cos α)/(E − 1),
    b₅ = (F sin α + cos α)/(F − 1). Taking |b| (as the seed instructs) repairs b₂ and b₄ (overall sign),
    but b₅ stays wrong; the derived formulas are right."""
    U, cp, a = 5.0, 0.3, 30.0 * DEG
    vn, ve, vs, vw = legs(U, cp * U, a)
    B, E, F = vn ** 2 / ve ** 2, vs ** 2 / ve ** 2, vs ** 2 / vw ** 2
    s, c = math.sin(a), math.cos(a)
    seed_b2 = (B * s - c) / (B - 1)
    seed_b4 = (E * s + c) / (E - 1)
    seed_b5 = (F * s + c) / (F - 1)
    b_true = (1 + cp ** 2) / (2 * cp)
    assert seed_b2 == pytest.approx(-b_true) and seed_b4 == pytest.approx(-b_true)
    assert abs(abs(seed_b5) - b_true) > 0.1
    _, b = C.four_leg_b(vn ** 2, ve ** 2, vs ** 2, vw ** 2, a)
    assert np.allclose(b, b_true, rtol=1e-10)


def test_four_leg_uncertainty_matches_monte_carlo():
    rng = np.random.default_rng(4)
    U, Cc, a, sig = 6.0, 0.8, 120 * DEG, 0.03
    v = np.array(legs(U, Cc, a))
    r = C.four_leg_current(*v, std=sig)
    sims = np.array([[z.u.value, z.c.value, z.alpha.value] for z in
                     (C.four_leg_current(*(v + sig * rng.standard_normal(4))) for _ in range(2000))])
    assert np.std(sims[:, 0]) == pytest.approx(r.u.std, rel=0.1)
    assert np.std(sims[:, 1]) == pytest.approx(r.c.std, rel=0.1)
    assert np.std(sims[:, 2]) == pytest.approx(r.alpha.std, rel=0.1)


def test_three_leg_alpha_seed_a10():
    for a_deg in (15.0, 100.0, 200.0, 300.0):
        vn, ve, vs, _ = legs(5.0, 1.0, a_deg * DEG)
        assert abs(C._wrap_pi(C.three_leg_alpha(vn, ve, vs) - a_deg * DEG)) < 1e-12


# --------------------------------------------------------------------------------------------------
# least squares (U, C, θ)
# --------------------------------------------------------------------------------------------------
def vg_of(U, Cc, theta, headings):
    h = np.asarray(headings, float)
    return np.hypot(U * np.cos(h) + Cc * math.cos(theta), U * np.sin(h) + Cc * math.sin(theta))


def test_lsq_agrees_with_four_leg_closed_form():
    U, Cc, th = 9.0 * KNOT, 1.2 * KNOT, 250 * DEG
    h0 = 10 * DEG
    hd = h0 + np.arange(4) * math.pi / 2
    v = vg_of(U, Cc, th, hd)
    r4 = C.four_leg_current(*v, heading0=h0)
    rl = C.least_squares_current(hd, v)
    assert rl.u.value == pytest.approx(r4.u.value, rel=1e-12)
    assert rl.c.value == pytest.approx(r4.c.value, rel=1e-10)
    assert abs(C._wrap_pi(rl.theta.value - r4.theta.value)) < 1e-10
    # noisy legs: the two estimates agree within the propagated uncertainty
    rng = np.random.default_rng(8)
    vn = v + 0.02 * rng.standard_normal(4)
    a, b = C.four_leg_current(*vn, heading0=h0, std=0.02), C.least_squares_current(hd, vn, std=0.02)
    assert abs(a.u.value - b.u.value) < 2 * b.u.std


def test_lsq_three_legs_exact_and_irregular_headings():
    U, Cc, th = 5.0, 0.9, 75 * DEG
    hd3 = np.array([10, 100, 190]) * DEG  # the seed's N, E, S legs
    r3 = C.least_squares_current(hd3, vg_of(U, Cc, th, hd3))
    assert r3.u.value == pytest.approx(U, rel=1e-12) and r3.c.value == pytest.approx(Cc, rel=1e-10)
    assert r3.dof == 0 and math.isnan(r3.u.std)
    hd3b = np.array([0, 130, 250]) * DEG  # any three distinct headings
    r3b = C.least_squares_current(hd3b, vg_of(U, Cc, th, hd3b))
    assert r3b.u.value == pytest.approx(U, rel=1e-12)
    rng = np.random.default_rng(9)
    hd = rng.uniform(0, 2 * math.pi, 9)
    r = C.least_squares_current(hd, vg_of(U, Cc, th, hd))
    assert r.u.value == pytest.approx(U, rel=1e-12)
    assert r.c.value == pytest.approx(Cc, rel=1e-10)
    assert abs(C._wrap_pi(r.theta.value - th)) < 1e-10
    assert np.allclose(r.ground_speed(hd), vg_of(U, Cc, th, hd))
    with pytest.raises(ValueError):
        C.least_squares_current([0.0, math.pi, 0.0, math.pi], [5.5, 4.5, 5.5, 4.5])


def test_lsq_covariance_coverage():
    rng = np.random.default_rng(10)
    U, Cc, th, sig = 6.0, 1.0, 200 * DEG, 0.05
    hd = np.deg2rad([10, 55, 100, 145, 190, 235, 280, 325])
    v0 = vg_of(U, Cc, th, hd)
    n_mc, hit_abs, hit_rel = 300, 0, 0
    for _ in range(n_mc):
        v = v0 + sig * rng.standard_normal(hd.size)
        hit_abs += C.least_squares_current(hd, v, std=sig).u.covers(U)
        hit_rel += C.least_squares_current(hd, v).u.covers(U)  # residual-based, t with 5 dof
    tol = 3 * math.sqrt(0.95 * 0.05 / n_mc)
    assert abs(hit_abs / n_mc - 0.95) <= tol
    assert abs(hit_rel / n_mc - 0.95) <= tol


def test_speed_through_water_per_leg():
    U, Cc, th = 5.0, 1.1, 33 * DEG
    hd = np.deg2rad([0, 77, 150, 260])
    assert np.allclose(C.speed_through_water(vg_of(U, Cc, th, hd), hd, Cc, th), U, rtol=1e-12)


# --------------------------------------------------------------------------------------------------
# reciprocal pair
# --------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("alpha_deg", [0.0, 30.0, 90.0, 145.0, 270.0])
def test_reciprocal_pair_bias_factor_exact(alpha_deg):
    U, Cc = 8.0, 1.6
    vx, _, vy, _ = legs(U, Cc, alpha_deg * DEG)
    uu = C.reciprocal_pair_speed(vx, vy, std=0.01)
    assert uu.value / U == pytest.approx(float(C.reciprocal_pair_bias_factor(Cc / U)), rel=1e-13)
    assert uu.value >= U


def test_reciprocal_pair_seed_example():
    """Seed 000: C = 1 kn, U = 10 kn → e = C′²/2 = 0.5 %, 0.05 kn if neglected."""
    U, Cc = 10 * KNOT, 1 * KNOT
    vx, _, vy, _ = legs(U, Cc, 0.0)
    uu = C.reciprocal_pair_speed(vx, vy).value
    assert (uu - U) / KNOT == pytest.approx(0.05, abs=0.0015)
    assert float(C.reciprocal_pair_bias_factor(0.1)) - 1 == pytest.approx(0.005, rel=0.01)


# ----------------------------------------------------------------------------------- water track
def _water_track_windows(rng, cur, headings, speeds, t, s, eps, dpsi, noise=0.1, n=120, sg=0.01):
    """Windows of a straight run: ground velocity (with noise sg) and a water-track log's mean surge and
    sway (scale error s, misalignment eps, n samples of white noise), read with a heading biased by dpsi."""
    K = len(headings)
    vg, Sg, w, vw = [], [], [], []
    for k in range(K):
        U, psi = speeds[k], headings[k]
        c, sn = math.cos(psi), math.sin(psi)
        vg.append(np.array([U * c, U * sn]) + cur(t[k]) + rng.normal(0.0, sg, 2))
        Sg.append(np.eye(2) * sg ** 2)
        body = (1.0 + s) * np.array([U * math.cos(eps), -U * math.sin(eps)])
        w.append(body + rng.normal(0.0, noise / math.sqrt(n), 2))
        vw.append(np.full(2, noise ** 2 / n))
    return np.array(vg), np.array(Sg), np.asarray(headings) + dpsi, np.array(w), np.array(vw)


def test_water_track_current_exact_without_errors():
    t = np.array([0.0, 900.0, 1800.0, 2700.0, 3600.0])
    cur = lambda tt: np.array([0.2 + 1e-5 * tt, -0.1])  # noqa: E731
    rng = np.random.default_rng(0)
    vg, Sg, psi, w, vw = _water_track_windows(rng, cur, [0.3, 2.0, 3.5, 5.0, 0.3], [6.0, 7.0, 5.0, 6.5, 8.0],
                                              t, 0.0, 0.0, 0.0, noise=0.0, sg=0.0)
    res = C.current_from_water_track(t, vg, Sg, psi, w, vw)
    assert res.line
    for tt in (0.0, 1234.0, 3600.0):
        cn, ce, _ = res(tt)
        assert cn.value == pytest.approx(cur(tt)[0], abs=1e-9) and ce.value == pytest.approx(cur(tt)[1], abs=1e-9)


def test_water_track_current_interval_coverage():
    """Current from 6 windows on three headings, each trial with its own draw of the log's scale error
    (σ 0.5 %), misalignment (σ 0.5°) and heading bias (σ 0.15°) and white noise: over 400 trials the 95 %
    ellipse of the stated covariance covers the true current at the nominal rate, and is not a
    too-wide one (the mean squared Mahalanobis distance is near its expectation 2). Measured: coverage
    0.953, mean distance² 1.77."""
    rng = np.random.default_rng(11)
    t = np.linspace(0.0, 3000.0, 6)
    headings = [0.35, 0.35, 2.0, 2.0, 4.5, 4.5]
    speeds = [6.7, 6.7, 6.7, 12.0, 6.7, 12.0]
    true = np.array([-0.18, 0.18])
    d2 = []
    for _ in range(400):
        s, eps, dpsi = rng.normal(0.0, 0.005), rng.normal(0.0, 0.5 * DEG), rng.normal(0.0, 0.15 * DEG)
        vg, Sg, psi, w, vw = _water_track_windows(rng, lambda tt: true, headings, speeds, t, s, eps, dpsi)
        res = C.current_from_water_track(t, vg, Sg, psi, w, vw, scale_sd=0.005, misalignment_sd=0.5 * DEG,
                                         heading_sd=0.15 * DEG)
        cn, ce, cov = res(1500.0)
        e = np.array([cn.value, ce.value]) - true
        d2.append(float(e @ np.linalg.solve(cov, e)))
    d2 = np.array(d2)
    cover = np.mean(d2 <= 5.991)                 # χ²₂ 95 % quantile
    assert 0.91 <= cover <= 0.99, cover
    assert 1.5 <= d2.mean() <= 2.6, d2.mean()


def test_water_track_current_needs_matching_windows():
    with pytest.raises(ValueError, match="per window"):
        C.current_from_water_track([0.0, 1.0], np.zeros((2, 2)), np.zeros((2, 2, 2)), [0.0], np.zeros((2, 2)),
                                   np.zeros((2, 2)))
