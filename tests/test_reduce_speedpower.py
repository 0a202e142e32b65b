"""vtrials.reduce.speedpower on synthetic data generated from known curves and known wind."""

from __future__ import annotations

import math

import numpy as np
import pytest

from vtrials.reduce import speedpower as SP
from vtrials.units import DEG, KNOT, RPM

A, B, Q = 2.0e5, 650.0, 3.2  # P = a + b V^q  [W, W/(m/s)^q, –]
V = np.repeat(np.linspace(5.0, 9.0, 6), 2)  # speeds through water [m/s], two runs per spot
N_MC = 200
TOL_MC = 3.0 * math.sqrt(0.95 * 0.05 / N_MC)  # 3 binomial standard errors ≈ 0.046


def truth(v):
    return A + B * np.asarray(v) ** Q


def test_fit_recovers_a_b_q_exactly():
    f = SP.fit_speed_power(V, truth(V))
    assert f.param("a").value == pytest.approx(A, rel=1e-7)
    assert f.param("b").value == pytest.approx(B, rel=1e-8)
    assert f.param("q").value == pytest.approx(Q, abs=1e-9)
    assert f.dof == V.size - 3 and np.max(np.abs(f.residuals)) < 1e-3
    g = SP.fit_speed_power(V, A + B * V ** 3, q=3.0)
    assert g.names == ("a", "b") and g.param("b").value == pytest.approx(B, rel=1e-12)


def test_polynomial_and_other_curves():
    # polynomial speed–power
    p = 1e5 - 2e4 * V + 3e3 * V ** 2 + 500.0 * V ** 3
    f = SP.fit_speed_power(V, p, kind="poly", degree=3)
    assert np.allclose(f.params, [1e5, -2e4, 3e3, 500.0], rtol=1e-8)
    # speed vs shaft speed (linear), thrust vs speed (pure power law)
    rps = np.linspace(60, 140, 9) * RPM
    vs = 0.3 + 3.9 * rps
    lin = SP.fit_curve(rps, vs, kind="poly", degree=1)
    assert np.allclose(lin.params, [0.3, 3.9], rtol=1e-12)
    thrust = 1.9e3 * V ** 1.8
    pl = SP.fit_curve(V, thrust, kind="powerlaw")
    assert pl.param("b").value == pytest.approx(1.9e3, rel=1e-7)
    assert pl.param("q").value == pytest.approx(1.8, abs=1e-9)


def test_power_at_speed_and_inverse():
    rng = np.random.default_rng(0)
    y = truth(V) * (1 + 0.01 * rng.standard_normal(V.size))
    f = SP.fit_speed_power(V, y)
    e = SP.power_at_speed(f, 7.3)
    assert e.std > 0 and e.dof == V.size - 3
    v = SP.speed_at_power(f, e.value)
    assert v.value == pytest.approx(7.3, abs=1e-9)
    # σ_V = σ_P / (dP/dV)
    assert v.std == pytest.approx(e.std / float(f.derivative(7.3)), rel=1e-9)
    lo, hi = f.band(np.array([6.0, 8.0]))
    plo, phi = f.band(np.array([6.0, 8.0]), prediction=True)
    assert np.all(plo < lo) and np.all(phi > hi)


@pytest.mark.parametrize("q", [None, 3.2])
def test_confidence_band_coverage_monte_carlo(q):
    """200 noisy realizations (1.5 % power noise): the 95 % band of the mean curve covers the true
    curve at three speeds at 95 % ± 3 binomial standard errors (exact t for fixed q; delta method
    for fitted q)."""
    rng = np.random.default_rng(42 if q is None else 43)
    x0 = np.array([5.5, 7.0, 8.8])
    hits = np.zeros(3)
    hits_param = 0
    for _ in range(N_MC):
        y = truth(V) + 0.015 * truth(V) * rng.standard_normal(V.size)
        f = SP.fit_speed_power(V, y, q=q, std=0.015 * truth(V), absolute_sigma=False)
        lo, hi = f.band(x0)
        hits += (lo <= truth(x0)) & (truth(x0) <= hi)
        # a parameter interval too: b for fixed q (linear model: exact t), q when fitted
        hits_param += f.param("b").covers(B) if q is not None else f.param("q").covers(Q)
    assert np.all(np.abs(hits / N_MC - 0.95) <= TOL_MC), hits / N_MC
    assert abs(hits_param / N_MC - 0.95) <= TOL_MC


# --------------------------------------------------------------------------------------------------
# wind
# --------------------------------------------------------------------------------------------------
def test_true_wind_known_cases_and_round_trip():
    vg = 7.0
    # head wind of 5 m/s: relative 12 m/s from ahead
    vwt, psi = SP.true_wind(12.0, 0.0, vg)
    assert vwt == pytest.approx(5.0) and psi == pytest.approx(0.0)
    # following wind of 10 m/s: relative 3 m/s from astern
    vwt, psi = SP.true_wind(3.0, math.pi, vg)
    assert vwt == pytest.approx(10.0) and abs(abs(psi) - math.pi) < 1e-12
    # calm: relative wind is the ship's own, from ahead
    vwt, _ = SP.true_wind(vg, 0.0, vg)
    assert vwt == pytest.approx(0.0, abs=1e-12)
    # V_WT² = V_WR² + V_G² − 2 V_WR V_G cos ψ_WR for arbitrary values, and the inverse
    rng = np.random.default_rng(1)
    vwr, pwr = rng.uniform(2, 20, 50), rng.uniform(-math.pi, math.pi, 50)
    vwt, pwt = SP.true_wind(vwr, pwr, vg)
    assert np.allclose(vwt ** 2, vwr ** 2 + vg ** 2 - 2 * vwr * vg * np.cos(pwr))
    vr2, pr2 = SP.relative_wind(vwt, pwt, vg)
    assert np.allclose(vr2, vwr) and np.allclose(np.angle(np.exp(1j * (pr2 - pwr))), 0, atol=1e-12)


def cx(psi):
    """A smooth wind resistance coefficient (positive = resistance), head wind 0.8, stern −0.5."""
    psi = np.asarray(psi, dtype=float)
    return 0.15 + 0.65 * np.cos(psi) - 0.05 * np.cos(2 * psi)


def test_wind_correction_removes_synthetic_wind_resistance():
    """Synthetic trial: calm-water delivered power P(V_S) plus the power of a known wind resistance;
    the measured relative wind is composed here independently (vectors in the earth frame). The
    wind correction with the direct power method returns the calm-water power exactly."""
    rho, axv, eta = 1.225, 450.0, 0.7
    vs = np.array([6.0, 6.0, 8.0, 8.0])  # m/s, reciprocal pairs, no current → V_G = V_S
    heading = np.array([30.0, 210.0, 30.0, 210.0]) * DEG
    wind_from, wind_speed = 75.0 * DEG, 11.0  # true wind from 075°, 11 m/s
    # earth-frame vectors (north, east); the wind blows TOWARD wind_from + 180°
    w = -wind_speed * np.array([math.cos(wind_from), math.sin(wind_from)])
    ship = vs[:, None] * np.column_stack([np.cos(heading), np.sin(heading)])
    rel = w[None, :] - ship  # air velocity seen on board
    v_wr = np.hypot(rel[:, 0], rel[:, 1])
    from_dir = np.arctan2(-rel[:, 1], -rel[:, 0])  # direction the relative wind comes from
    psi_wr = np.angle(np.exp(1j * (from_dir - heading)))
    r_true = 0.5 * rho * axv * (cx(psi_wr) * v_wr ** 2 - cx(0.0) * vs ** 2)
    p_calm = truth(vs)
    p_meas = p_calm + r_true * vs / eta
    wr = SP.wind_resistance(v_wr, psi_wr, vs, cx, axv, rho_a=rho)
    assert np.allclose(wr.r_aa, r_true, rtol=1e-12)
    assert np.allclose(wr.v_wt, wind_speed) and np.allclose(
        np.angle(np.exp(1j * (heading + wr.psi_wt - wind_from))), 0.0, atol=1e-12)
    p_id, p_std = SP.direct_power_method(p_meas, wr.r_aa, vs, eta)
    assert np.allclose(p_id, p_calm, rtol=1e-12)
    assert np.all(p_std == 0.0)
    # wind from 45° on the bow on the 030° runs, from abaft the beam on the 210° runs
    assert wr.r_aa[0] > 0 > wr.r_aa[1] and wr.r_aa[2] > wr.r_aa[3]


def test_wind_height_correction_and_uncertainty():
    vg = 7.0
    v_wr, psi = np.array([15.0]), np.array([20 * DEG])
    same = SP.wind_resistance(v_wr, psi, vg, cx, 400.0, z_anemometer=10.0, z_ref=10.0)
    none = SP.wind_resistance(v_wr, psi, vg, cx, 400.0)
    assert same.r_aa[0] == pytest.approx(none.r_aa[0], rel=1e-12)
    hi = SP.wind_resistance(v_wr, psi, vg, cx, 400.0, z_anemometer=40.0, z_ref=10.0)
    vwt_ref = none.v_wt * (10.0 / 40.0) ** (1 / 9)
    vr_ref, _ = SP.relative_wind(vwt_ref, none.psi_wt, vg)
    assert hi.v_wr_ref[0] == pytest.approx(vr_ref[0], rel=1e-12)
    assert hi.r_aa[0] < none.r_aa[0]  # weaker wind at the lower reference height
    u = SP.wind_resistance(v_wr, psi, vg, cx, 400.0, v_wr_std=0.5)
    # ∂R/∂V_WR = ρ A C_X(ψ) V_WR (no height correction)
    assert u.std[0] == pytest.approx(1.225 * 400.0 * float(cx(psi[0])) * 15.0 * 0.5, rel=1e-6)


def test_direct_power_method_full_form_and_displacement():
    p, dr, v, eid, ems = 5.0e6, 8.0e4, 7.5, 0.72, 0.70
    p_id, _ = SP.direct_power_method(p, dr, v, eid, eta_d_ms=ems)
    assert float(p_id) == pytest.approx(p - dr * v / eid - p * (1 - ems / eid), rel=1e-14)
    p2, s2 = SP.displacement_correction(4.0e6, 10000.0, 11000.0, power_std=4.0e4)
    assert float(p2) == pytest.approx(4.0e6 * 1.1 ** (2 / 3), rel=1e-14)
    assert float(s2) == pytest.approx(4.0e4 * 1.1 ** (2 / 3), rel=1e-14)


def test_knots_speed_power_example_units():
    """Speeds in knots only at the edges: a 14-kn design point from a fit in SI."""
    f = SP.fit_speed_power(V, truth(V))
    e = SP.power_at_speed(f, 14.0 * KNOT)
    assert e.value == pytest.approx(float(truth(14.0 * KNOT)), rel=1e-7)
