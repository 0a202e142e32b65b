"""The seaway (vtrials.physics.environment.waves): spectra, spreading, dispersion, Airy kinematics,
and the realized sea checked the way a wave buoy would check it.

References used as independent checks: quadrature (scipy) of the spectra and spreading functions;
closed-form Airy formulas (Dean & Dalrymple 1991, ch. 4) written out here with cosh/sinh; exact
inverses of the dispersion relation (ω² h/g = x tanh x for chosen x = kh) and a bracketing root
finder; finite differences for the kinematic identities; and, for the realized sea, the sampling
errors derived in the docstrings of the tests below (Gaussian-sea theory plus the finite number of
components), with tolerances of 3σ.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.optimize import brentq, least_squares
from scipy.special import polygamma

from vtrials.errors import InputError
from vtrials.physics.environment import waves as W
from vtrials.units import DEG, G

DEEP = math.inf
T_REC = 3 * 3600.0  # a 3-hour record
DT = 0.5  # [s] sampling of the virtual buoy


# =================================================================================================
# helpers: a virtual buoy (η, u, v at one point) and its spectral analysis
# =================================================================================================

def _quad_all(f, cuts=(0.05, 0.5, 0.9, 1.1, 1.5, 3.0, 8.0, math.inf)):
    return sum(quad(f, a, b, limit=400, epsabs=0.0, epsrel=1e-11)[0] for a, b in zip(cuts[:-1], cuts[1:]))


def buoy_record(field, seconds=T_REC, dt=DT):
    """η, u_n, u_e at the origin on the mean surface, sampled every dt for ``seconds``."""
    t = np.arange(0.0, seconds, dt)
    eta, vel, _ = W.kinematics(field.components, field.depth_m, 0.0, 0.0, 0.0, t)
    return eta, vel[:, 0], vel[:, 1]


def band_spectra(dt, series, m):
    """Band-averaged one-sided (cross-)spectra [·²·s/rad] from full-record FFTs (Daniell smoothing).

    Each band averages m raw periodogram ordinates (spacing 2π/T); returns the band edges [rad/s]
    and a dict (i, j) → co-spectrum (real part) per band.
    """
    n = series[0].size
    X = [np.fft.rfft(s - s.mean()) for s in series]
    dw = 2.0 * math.pi / (n * dt)
    nb = (X[0].size - 1) // m
    edges = dw * (0.5 + m * np.arange(nb + 1))
    scale = 2.0 * dt / (2.0 * math.pi * n)
    out = {}
    for i in range(len(X)):
        for j in range(i, len(X)):
            P = (X[i] * np.conj(X[j])).real * scale
            out[i, j] = P[1:1 + nb * m].reshape(nb, m).mean(axis=1)
    return edges, out


def band_mean(S, edges, n_fine=32):
    """Exact-enough band averages of a model spectrum function over [edges[b], edges[b+1]]."""
    lo, hi = edges[:-1], edges[1:]
    x = lo[:, None] + (hi - lo)[:, None] * (np.arange(n_fine) + 0.5)[None, :] / n_fine
    return S(x.ravel()).reshape(x.shape).mean(axis=1)


def count_covariance(system, edges):
    """Covariance of the number of components per band, from the stratified frequency draw.

    Component j's quantile is uniform in [j, j+1)/n (equal-energy strata); with π_jb the overlap
    of stratum j with band b (in quantile units), each component falls in exactly one band, so
    Cov(c_b, c_b') = Σ_j (δ_bb' π_jb − π_jb π_jb') (multinomial per stratum). Exact.
    """
    w = np.linspace(system.omega_lo, system.omega_hi, 16385)
    S = system.spectrum_1d(w)
    F = np.concatenate(([0.0], np.cumsum(0.5 * (S[1:] + S[:-1]) * np.diff(w))))
    q = np.interp(edges, w, F / F[-1] * system.n, left=0.0, right=system.n)
    j = np.arange(system.n)[:, None]
    pi = np.clip(np.minimum(q[None, 1:], j + 1) - np.maximum(q[None, :-1], j), 0.0, None)
    return np.diag(pi.sum(axis=0)) - pi.T @ pi, F[-1] / system.n


def fit_peaks(field, edges, Shat, m, sel, gammas):
    """Weighted LS fit of ln(band spectrum) by a sum of JONSWAP shapes with free (H_s, ω_p) each.

    Noise model per band (ln-space covariance, both parts derived):
      * record length (Gaussian sea): a mean of m exponential ordinates is Gamma(m) distributed, so
        ln Ŝ_b has variance ψ'(m) (trigamma), independent between bands; its mean offset
        ψ(m) − ln m only moves the level (absorbed by H_s, and corrected below);
      * finite number of components: band energy = (m0_band/n) × count, count covariance from
        :func:`count_covariance`, divided by E_b E_b' to go to ln-space.
    Returns the estimates [(H_s, ω_p) per system] and their standard deviations from the
    Gauss–Newton covariance (Jᵀ C⁻¹ J)⁻¹ (Seber & Wild 2003, §2.1) — H_s from this fit is not
    used (the variance gives it better), ω_p is.
    """
    systems = field.systems
    y = np.log(Shat[sel]) - (polygamma(0, m) - math.log(m))
    C = np.eye(sel.sum()) * float(polygamma(1, m))
    Eb_total = band_mean(field.spectrum, edges)[sel] * np.diff(edges)[sel]
    for s in systems:
        Cc, e = count_covariance(s, edges)
        C = C + (e * e) * Cc[np.ix_(sel, sel)] / np.outer(Eb_total, Eb_total)
    L = np.linalg.cholesky(C)
    last = np.nonzero(sel)[0].max() + 1
    e_used = edges[:last + 1]
    sel_used = sel[:last]

    def model(theta):
        tot = 0.0
        for i, g in enumerate(gammas):
            hs, wp = math.exp(theta[2 * i]), math.exp(theta[2 * i + 1])
            tot = tot + band_mean(lambda w: W.jonswap_spectrum(w, hs, wp, g), e_used)
        return np.log(tot[sel_used])

    def resid(theta):
        return np.linalg.solve(L, y - model(theta))

    th0 = np.array([v for s in systems for v in (math.log(s.hs_m), math.log(s.omega_p) + 0.05)])
    res = least_squares(resid, th0, x_scale=0.1, xtol=1e-12, ftol=1e-12, gtol=1e-12)
    cov = np.linalg.inv(res.jac.T @ res.jac)
    est = [(math.exp(res.x[2 * i]), math.exp(res.x[2 * i + 1])) for i in range(len(systems))]
    sd = np.sqrt(np.diag(cov))
    return est, [(sd[2 * i], sd[2 * i + 1]) for i in range(len(systems))]


def buoy_direction(spec, sel):
    """Bulk (mean direction towards, r₁) from the first-order Fourier coefficients of a PUV buoy.

    Per band: a₁ = C_ηu / √(C_ηη (C_uu + C_vv)), b₁ = C_ηv / √(...) (Longuet-Higgins et al. 1963;
    the velocity transfer |u|/|η| = ω F_c cancels); bulk: energy-weighted over the selected bands.
    """
    Cee, Ceu, Cev, Cuu, Cvv = spec[0, 0], spec[0, 1], spec[0, 2], spec[1, 1], spec[2, 2]
    den = np.sqrt(Cee * (Cuu + Cvv))
    a1, b1 = Ceu / den, Cev / den
    w = Cee[sel] / Cee[sel].sum()
    A1, B1 = float(w @ a1[sel]), float(w @ b1[sel])
    return math.atan2(B1, A1), math.hypot(A1, B1)


def direction_sigmas(r1, r2, m, weights, n_lines):
    """Standard errors of the bulk mean direction [rad] and of r₁ (derived; see the test docstring).

    Record part (Gaussian sea, band of ν = 2m degrees of freedom; Kuik, van Vledder & Holthuijsen
    1988 by the delta method): in axes along the mean direction, with u', v' the velocities divided
    by their transfer function, the co-spectral matrix of (η, u', v') is
        S [[1, r₁, 0], [r₁, (1 + r₂)/2, 0], [0, 0, (1 − r₂)/2]]
    and Cov(Ĉ_ab, Ĉ_cd) = (C_ac C_bd + C_ad C_bc)/ν. Then var θ̂ = (1 − r₂)/(2ν r₁²) and var r̂₁ =
    gᵀ Σ g with g = ∂r₁/∂(C_ηη, C_ηu', C_u'u', C_v'v') = (−r₁/2, 1, −r₁/2, −r₁/2)/S. Bulk:
    Σ w_b² var_b (bands independent).
    Finite-N part: the bulk is the mean over the n components in the bands of cos and sin of their
    direction offsets; the directions' strata form a simple random sample (without replacement) of
    the n strata, so the variance is at most the i.i.d. one: var sin Δμ/(n r₁²) = (1 − r₂)/(2 n r₁²)
    for θ, var cos Δμ/n = ((1 + r₂)/2 − r₁²)/n for r₁.
    """
    nu = 2.0 * m
    C = {("e", "e"): 1.0, ("e", "u"): r1, ("u", "u"): 0.5 * (1 + r2), ("v", "v"): 0.5 * (1 - r2),
         ("e", "v"): 0.0, ("u", "v"): 0.0}

    def c(a, b):
        return C.get((a, b), C.get((b, a)))

    pairs = [("e", "e"), ("e", "u"), ("u", "u"), ("v", "v")]
    g = np.array([-0.5 * r1, 1.0, -0.5 * r1, -0.5 * r1])
    cov = np.array([[(c(a, cc) * c(b, d) + c(a, d) * c(b, cc)) / nu for cc, d in pairs] for a, b in pairs])
    var_r1_band = float(g @ cov @ g)
    var_th_band = (1.0 - r2) / (2.0 * nu * r1 * r1)
    w2 = float(np.sum(np.asarray(weights) ** 2))
    var_th = w2 * var_th_band + (1.0 - r2) / (2.0 * n_lines * r1 * r1)
    var_r1 = w2 * var_r1_band + (0.5 * (1.0 + r2) - r1 * r1) / n_lines
    return math.sqrt(var_th), math.sqrt(var_r1)


def hs_sigma(field, seconds):
    """σ(Ĥ_s)/H_s for Ĥ_s = 4 √(sample variance) of a Gaussian sea: ½ √(2π ∫S² dω / (T m0²)).

    var(m̂0) = (2/T) ∫ R(τ)² dτ = (2π/T) ∫₀^∞ S² dω for a record T much longer than the correlation
    time (Parseval, R(τ) = ∫₀^∞ S cos ωτ dω); Ĥ_s ∝ √m̂0 halves the relative error.
    """
    w = np.linspace(min(s.omega_lo for s in field.systems), max(s.omega_hi for s in field.systems), 40001)
    S = field.spectrum(w)
    m0 = np.trapezoid(S, w)
    return 0.5 * math.sqrt(2.0 * math.pi * np.trapezoid(S * S, w) / (seconds * m0 * m0))


def wrap(a):
    return (a + math.pi) % (2.0 * math.pi) - math.pi


# =================================================================================================
# spectra and spreading
# =================================================================================================

def test_spectra_integrate_to_hs_and_peak_where_they_should():
    hs = 3.0
    cases = [
        ("ITTC T_0", lambda w: W.ittc_spectrum(w, hs, t0=9.0), 2 * math.pi / 9.0),
        ("ITTC T_1", lambda w: W.ittc_spectrum(w, hs, t1=7.0), (0.8 * W.ittc_B(t1=7.0)) ** 0.25),
        ("ITTC T_z", lambda w: W.ittc_spectrum(w, hs, tz=6.5), (0.8 * W.ittc_B(tz=6.5)) ** 0.25),
        ("Bretschneider", lambda w: W.bretschneider_spectrum(w, hs, 0.7), 0.7),
    ] + [(f"JONSWAP γ={g}", (lambda g: lambda w: W.jonswap_spectrum(w, hs, 0.7, g))(g), 0.7)
         for g in (1.0, 2.0, 3.3, 5.0, 7.0, 10.0)]
    for name, S, wp in cases:
        m0 = _quad_all(lambda w: float(S(np.array([w]))[0]))
        # acceptance asks 0.5 %; the normalisations are exact, so quadrature accuracy is what is left
        assert m0 == pytest.approx(hs * hs / 16.0, rel=1e-8), name
        w = np.linspace(0.5 * wp, 2.0 * wp, 300001)
        assert w[np.argmax(S(w))] == pytest.approx(wp, abs=2 * (w[1] - w[0])), name
    # the periods are what they claim: T_1 = 2π m0/m1, T_z = 2π √(m0/m2), by quadrature
    S1 = lambda w: float(W.ittc_spectrum(np.array([w]), hs, t1=7.0)[0])  # noqa: E731
    m0, m1 = _quad_all(S1), _quad_all(lambda w: S1(w) * w)
    assert 2 * math.pi * m0 / m1 == pytest.approx(7.0, rel=1e-8)
    Sz = lambda w: float(W.ittc_spectrum(np.array([w]), hs, tz=6.5)[0])  # noqa: E731
    assert 2 * math.pi * math.sqrt(_quad_all(Sz) / _quad_all(lambda w: Sz(w) * w * w)) == pytest.approx(6.5, rel=1e-8)
    # ITTC's published rounded constants (A, B) = (173, 691)/T_1⁴, (487, 1949)/T_0⁴, (123, 495)/T_z⁴
    for (A, B), kw in (((173, 691), "t1"), ((487, 1949), "t0"), ((123, 495), "tz")):
        assert W.ittc_B(**{kw: 1.0}) == pytest.approx(B, rel=2.5e-3), kw  # 691.3, 1948.2, 496.1
        assert A / (4 * B) == pytest.approx(1 / 16, rel=7e-3), kw  # their H_s error: ≤ 0.35 %
    # Bretschneider is ITTC with T_0, and JONSWAP with γ = 1
    w = np.linspace(0.2, 4.0, 500)
    np.testing.assert_allclose(W.bretschneider_spectrum(w, hs, 0.7), W.ittc_spectrum(w, hs, t0=2 * math.pi / 0.7),
                               rtol=1e-12)
    np.testing.assert_allclose(W.jonswap_spectrum(w, hs, 0.7, 1.0), W.bretschneider_spectrum(w, hs, 0.7),
                               rtol=1e-10)
    # sea + swell: the sum keeps H_s,total = √(H_s1² + H_s2²); its two peaks are where they should be
    f = W.WaveField(np.zeros((0, 6)), DEEP, W.systems_of(W.Waves(
        spectrum="pierson_moskowitz", hs_m=2.0, t1_s=6.0, swell_hs_m=1.5, swell_tp_s=15.0)))
    m0 = _quad_all(lambda w: float(f.spectrum(np.array([w]))[0]), cuts=(0.05, 0.3, 0.5, 1.0, 2.0, 8.0, math.inf))
    assert m0 == pytest.approx((2.0 ** 2 + 1.5 ** 2) / 16.0, rel=1e-8)
    assert f.tp_s == pytest.approx(15.0, rel=1e-4)
    w = np.linspace(0.3, 3.0, 270001)
    S = f.spectrum(w)
    peaks = w[1:-1][(S[1:-1] > S[:-2]) & (S[1:-1] > S[2:])]
    # two maxima, each near its own system's peak (the other's slope moves them: the swell's tail
    # pulls the wind sea's maximum 2 % lower here)
    assert peaks == pytest.approx([2 * math.pi / 15.0, f.systems[0].omega_p], rel=0.03)
    # the scenario path (numerical moments of the shape) agrees with ITTC's closed forms
    for kw, T in (("tz", 6.5), ("t1", 7.0)):
        assert W.peak_frequency("pierson_moskowitz", **{kw: T}) == \
            pytest.approx((0.8 * W.ittc_B(**{kw: T})) ** 0.25, rel=1e-9), kw
    # JONSWAP given T_z or T_1: the spectrum built has that period (quadrature)
    for kw, T in (("tz", 6.0), ("t1", 6.5)):
        wp = W.peak_frequency("jonswap", 3.3, **{kw: T})
        Sj = lambda w: float(W.jonswap_spectrum(np.array([w]), hs, wp, 3.3)[0])  # noqa: E731
        m0 = _quad_all(Sj)
        got = (2 * math.pi * math.sqrt(m0 / _quad_all(lambda w: Sj(w) * w * w)) if kw == "tz"
               else 2 * math.pi * m0 / _quad_all(lambda w: Sj(w) * w))
        assert got == pytest.approx(T, rel=1e-6), kw


def test_jonswap_closed_form_normalisation_how_well_it_holds():
    """1 − 0.287 ln γ against the exact factor: ≤ 0.35 % for 1 ≤ γ ≤ 5; −1.8 % at 7; −6.9 % at 10."""
    err = {g: W.jonswap_normalisation_approx(g) / W.jonswap_normalisation(g) - 1.0
           for g in (1.0, 1.5, 2.0, 3.3, 4.0, 5.0, 7.0, 10.0)}
    assert max(abs(err[g]) for g in (1.0, 1.5, 2.0, 3.3, 4.0, 5.0)) < 3.5e-3
    assert err[7.0] == pytest.approx(-0.0175, abs=1e-3)
    assert err[10.0] == pytest.approx(-0.069, abs=2e-3)


def test_spreading_normalisation_and_moments():
    for s in (0.5, 1.0, 2.0, 10.0, 25.0, 75.0, 200.0):
        f = lambda mu, s=s: float(W.spreading_function("cos2s", mu, s))  # noqa: E731
        assert quad(f, -math.pi, math.pi, points=[0.0], limit=400, epsabs=0.0, epsrel=1e-12)[0] == \
            pytest.approx(1.0, rel=1e-9), s
        r1 = quad(lambda mu: f(mu) * math.cos(mu), -math.pi, math.pi, points=[0.0], limit=400)[0]
        r2 = quad(lambda mu: f(mu) * math.cos(2 * mu), -math.pi, math.pi, points=[0.0], limit=400)[0]
        e1, e2 = W.spreading_moments("cos2s", s)
        assert (r1, r2) == pytest.approx((float(e1), float(e2)), abs=1e-9), s
        assert float(W.circular_spread(e1)) == pytest.approx(math.sqrt(2.0 / (s + 1.0)), rel=1e-12)
    # D₀ against the Γ-function formula written out directly (small s, no overflow)
    for s in (1.0, 2.5, 10.0):
        d0 = 2 ** (2 * s - 1) * math.gamma(s + 1) ** 2 / (math.pi * math.gamma(2 * s + 1))
        assert float(W.cos2s_norm(s)) == pytest.approx(d0, rel=1e-12)
    f = lambda mu: float(W.spreading_function("cos2", mu))  # noqa: E731
    assert quad(f, -math.pi, math.pi, points=[-math.pi / 2, math.pi / 2])[0] == pytest.approx(1.0, rel=1e-10)
    r1 = quad(lambda mu: f(mu) * math.cos(mu), -math.pi / 2, math.pi / 2)[0]
    assert r1 == pytest.approx(float(W.spreading_moments("cos2")[0]), rel=1e-10)
    assert float(W.spreading_function("cos2", 0.6 * math.pi)) == 0.0
    # the direction sampler inverts the CDF: F(sampled angle) = quantile, F by quadrature / closed form
    q = np.linspace(0.002, 0.998, 25)
    for s in (0.3, 10.0, 150.0):
        th = W._sample_spreading("cos2s", np.full_like(q, s), q)
        F = [quad(lambda m, s=s: float(W.spreading_function("cos2s", m, s)), -math.pi, t, limit=200)[0] for t in th]
        # linear interpolation between 4097 nodes: |error| ≤ h² max|D'|/8 ≈ 1e−5 at s = 150
        np.testing.assert_allclose(F, q, atol=2e-5)
    th = W._sample_spreading("cos2", np.ones_like(q), q)
    np.testing.assert_allclose(0.5 + (th + np.sin(th) * np.cos(th)) / math.pi, q, atol=2e-6)
    # Mitsuyasu (Goda 1985): s_max at the peak, ω⁵ below, ω^-2.5 above
    s = W.mitsuyasu_s(np.array([0.5, 1.0, 2.0]) * 0.8, 0.8, 10.0)
    np.testing.assert_allclose(s, [10.0 / 32.0, 10.0, 10.0 * 2.0 ** -2.5], rtol=1e-14)


def test_dispersion_deep_shallow_and_exact_values():
    w = np.array([0.05, 0.3, 0.8, 1.5, 3.0])
    np.testing.assert_array_equal(W.wavenumber(w, DEEP), w * w / G)
    np.testing.assert_array_equal(W.wavenumber(w[1:], 1e4), w[1:] ** 2 / G)  # ω²h/g > 20: tanh = 1 in float64
    # exact inverses: choose kh = x, then ω² = g (x/h) tanh x
    h = 17.0
    x = np.array([1e-3, 0.05, 0.5, 1.0, math.pi, 6.0, 15.0])
    w = np.sqrt(G * x / h * np.tanh(x))
    np.testing.assert_allclose(W.wavenumber(w, h) * h, x, rtol=1e-13)
    # a bracketing root finder as a separate solver
    w = np.linspace(0.05, 4.0, 37)
    ref = [brentq(lambda k, ww=ww: G * k * math.tanh(k * 6.0) - ww * ww, 1e-9, 50.0, xtol=1e-15, rtol=1e-15)
           for ww in w]
    np.testing.assert_allclose(W.wavenumber(w, 6.0), ref, rtol=1e-12)
    # shallow limit k → ω/√(gh): relative error (kh)²/6 to leading order
    h = 2.0
    w = np.array([0.005, 0.01, 0.02])
    k = W.wavenumber(w, h)
    kh = k * h
    np.testing.assert_allclose(k / (w / np.sqrt(G * h)) - 1.0, kh ** 2 / 6.0, rtol=2e-2)
    assert W.wavenumber(np.array([[0.5, 1.0]]), 30.0).shape == (1, 2)
    with pytest.raises(ValueError, match="depth"):
        W.wavenumber(w, 0.0)


# =================================================================================================
# kinematics
# =================================================================================================

def _one(a, w, depth, mu, eps):
    k = float(W.wavenumber(np.array([w]), depth)[0])
    return np.array([[a, w, k, math.cos(mu), math.sin(mu), eps]]), k


@pytest.mark.parametrize("w, depth", [(0.9, 12.0), (0.9, 60.0), (0.9, DEEP), (3.0, 30.0)])
def test_single_component_matches_airy(w, depth):
    """(3.0 rad/s, 30 m): kh = 27.5, the kernel's shortcut for negligible finite-depth terms."""
    a, mu, eps = 0.8, 1.1, 0.4
    comp, k = _one(a, w, depth, mu, eps)
    rng = np.random.default_rng(5)
    x, y, t = rng.uniform(-300, 300, 50), rng.uniform(-300, 300, 50), rng.uniform(0, 500, 50)
    z = rng.uniform(0.0, min(depth, 40.0) - 0.1, 50)
    eta, vel, acc = W.kinematics(comp, depth, x, y, z, t)
    th = w * t - k * (x * math.cos(mu) + y * math.sin(mu)) + eps
    if math.isfinite(depth):  # textbook form, z' = −z measured up from the mean surface
        fc = np.cosh(k * (-z + depth)) / np.sinh(k * depth)
        fs = np.sinh(k * (-z + depth)) / np.sinh(k * depth)
    else:
        fc = fs = np.exp(-k * z)
    uh = a * w * fc * np.cos(th)
    w_up = -a * w * fs * np.sin(th)
    np.testing.assert_allclose(eta, a * np.cos(th), rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(vel[:, 0], uh * math.cos(mu), rtol=1e-11, atol=1e-12)
    np.testing.assert_allclose(vel[:, 1], uh * math.sin(mu), rtol=1e-11, atol=1e-12)
    np.testing.assert_allclose(vel[:, 2], -w_up, rtol=1e-11, atol=1e-12)
    np.testing.assert_allclose(acc[:, 0], -a * w * w * fc * np.sin(th) * math.cos(mu), rtol=1e-11, atol=1e-12)
    np.testing.assert_allclose(acc[:, 2], a * w * w * fs * np.cos(th), rtol=1e-11, atol=1e-12)
    np.testing.assert_allclose(W.elevation(comp, x, y, t), eta, rtol=0, atol=1e-13)
    # the scalar kernel is the same function
    assert W.kinematics_at(comp, depth, x[3], y[3], z[3], t[3])[1] == pytest.approx(vel[3, 0], rel=1e-14)
    # direction convention: a wave going east (μ = 90°) arrives later at a point further east
    comp_e, k_e = _one(1.0, w, depth, math.pi / 2, 0.0)
    assert W.elevation_at(comp_e, 0.0, 10.0, 10.0 * k_e / w) == pytest.approx(1.0, abs=1e-12)


def test_array_wrappers_broadcast_and_chunk_like_the_point_kernel():
    f = W.realize(W.Waves(hs_m=2.0, tp_s=8.0, n_components=50), 30.0, np.random.default_rng(2))
    x = np.linspace(-50.0, 50.0, 7)[:, None]
    t = np.linspace(0.0, 900.0, 20001)[None, :]  # 140 007 points: three chunks of W.CHUNK
    eta, vel, acc = W.kinematics(f.components, 30.0, x, 5.0, 2.0, t)
    assert eta.shape == (7, 20001) and vel.shape == acc.shape == (7, 20001, 3)
    np.testing.assert_array_equal(W.elevation(f.components, x, 5.0, t), eta)
    for i, j in ((0, 0), (3, 12345), (6, 20000), (5, 19999)):
        r = W.kinematics_at(f.components, 30.0, x[i, 0], 5.0, 2.0, t[0, j])
        assert r == (eta[i, j], *vel[i, j], *acc[i, j])


def test_very_large_kh_does_not_overflow():
    comp, k = _one(1.0, 6.0, 5000.0, 0.0, 0.0)  # kh ≈ 1.8e4: cosh/sinh overflow, our form does not
    assert k * 5000.0 > 1e4
    eta, vel, acc = W.kinematics(comp, 5000.0, 0.0, 0.0, np.array([0.0, 0.5, 4999.0]), 0.0)
    assert np.all(np.isfinite(vel)) and np.all(np.isfinite(acc))
    np.testing.assert_allclose(vel[:, 0], 6.0 * np.exp(-k * np.array([0.0, 0.5, 4999.0])), rtol=1e-12)
    with pytest.raises(ValueError, match="below the bottom"):
        W.kinematics(comp, 5000.0, 0.0, 0.0, 5001.0, 0.0)


@pytest.mark.parametrize("depth", [15.0, DEEP])
def test_irregular_kinematics_identities(depth):
    """Kinematic surface condition ∂η/∂t = w_up, a = ∂u/∂t, continuity, irrotationality, w(h) = 0."""
    waves = W.Waves(hs_m=2.0, tp_s=8.0, direction_deg=200.0, n_components=150)
    f = W.realize(waves, depth, np.random.default_rng(11))
    c, h = f.components, f.depth_m
    rng = np.random.default_rng(3)
    pts = np.column_stack([rng.uniform(-200, 200, 20), rng.uniform(-200, 200, 20),
                           rng.uniform(0.5, 10.0, 20), rng.uniform(0, 1000, 20)])
    dt, dx = 1e-2, 1e-2

    def d4(f, h):  # fourth-order central difference of f at 0 (error ~ h⁴ f⁽⁵⁾/30)
        return (f(-2 * h) - 8 * f(-h) + 8 * f(h) - f(2 * h)) / (12 * h)

    for x, y, z, t in pts:
        k = lambda *p: np.array(W.kinematics_at(c, h, *p))  # noqa: E731
        here = k(x, y, z, t)
        scale_u = np.abs(k(x, y, 0.0, t)[1:4]).max()
        # surface: ∂η/∂t equals the upward velocity at z = 0
        deta = d4(lambda e: W.elevation_at(c, x, y, t + e), dt)
        assert deta == pytest.approx(-k(x, y, 0.0, t)[3], abs=1e-6 * scale_u)
        # acceleration = ∂u/∂t
        du = d4(lambda e: k(x, y, z, t + e)[1:4], dt)
        np.testing.assert_allclose(here[4:7], du, atol=1e-6 * np.abs(here[4:7]).max())
        # continuity ∂u_n/∂x + ∂u_e/∂y + ∂u_d/∂z = 0 and curl = 0 (potential flow)
        gx = d4(lambda e: k(x + e, y, z, t)[1:4], dx)
        gy = d4(lambda e: k(x, y + e, z, t)[1:4], dx)
        gz = d4(lambda e: k(x, y, z + e, t)[1:4], dx)
        grad_scale = np.abs(np.concatenate([gx, gy, gz])).max()
        assert abs(gx[0] + gy[1] + gz[2]) < 1e-6 * grad_scale
        assert abs(gz[0] - gx[2]) < 1e-6 * grad_scale and abs(gy[2] - gz[1]) < 1e-6 * grad_scale
    if math.isfinite(depth):  # no flow through the bottom
        _, vel, _ = W.kinematics(c, h, pts[:, 0], pts[:, 1], h, pts[:, 3])
        _, vel_top, _ = W.kinematics(c, h, pts[:, 0], pts[:, 1], 0.0, pts[:, 3])
        assert np.abs(vel[:, 2]).max() < 1e-14 * np.abs(vel_top).max()
        assert np.abs(vel[:, :2]).max() > 0.05 * np.abs(vel_top[:, :2]).max()  # but it slides along it


# =================================================================================================
# realization
# =================================================================================================

def test_realization_is_reproducible_and_keeps_the_energy():
    waves = W.Waves(hs_m=2.5, tp_s=9.0, direction_deg=30.0, swell_hs_m=1.0, swell_tp_s=15.0,
                    swell_direction_deg=100.0)
    a = W.realize(waves, 40.0, np.random.default_rng(np.random.SeedSequence(7)))
    b = W.realize(waves, 40.0, np.random.default_rng(np.random.SeedSequence(7)))
    c = W.realize(waves, 40.0, np.random.default_rng(np.random.SeedSequence(8)))
    assert a.components.tobytes() == b.components.tobytes()
    assert not np.array_equal(a.components, c.components)
    assert a.components.shape == (300, 6) and a.components.flags.c_contiguous
    # equal-energy components: the realized H_s is the band-limited target exactly
    w = np.linspace(0.01, 10.0, 400001)
    band = sum(np.trapezoid(np.where((w >= s.omega_lo) & (w <= s.omega_hi), s.spectrum_1d(w), 0.0), w)
               for s in a.systems)
    assert a.hs_realized_m == pytest.approx(4.0 * math.sqrt(band), rel=1e-6)
    assert a.hs_realized_m == pytest.approx(a.hs_m, rel=2e-3)  # the band [0.5, 5] ω_p holds > 99.6 % of m0
    assert a.hs_m == pytest.approx(math.hypot(2.5, 1.0))
    # each system's frequencies are stratified: exactly one per equal-energy bin
    for s, part in zip(a.systems, (a.components[:200], a.components[200:])):
        ww = np.linspace(s.omega_lo, s.omega_hi, 16385)
        S = s.spectrum_1d(ww)
        F = np.concatenate(([0.0], np.cumsum(0.5 * (S[1:] + S[:-1]) * np.diff(ww))))
        q = np.interp(part[:, 1], ww, F / F[-1] * s.n)
        np.testing.assert_array_equal(np.floor(q).astype(int), np.arange(s.n))
        assert np.all(part[:, 1] >= s.omega_lo) and np.all(part[:, 1] <= s.omega_hi)
        np.testing.assert_allclose(part[:, 2], W.wavenumber(part[:, 1], 40.0), rtol=1e-15)
        np.testing.assert_allclose(part[:, 3] ** 2 + part[:, 4] ** 2, 1.0, rtol=1e-14)
    # directions: the swell comes FROM 100°, so it travels towards 280°
    assert a.systems[1].direction_to == pytest.approx(280.0 * DEG)
    mean_to = math.atan2(a.components[200:, 4].mean(), a.components[200:, 3].mean())
    assert abs(wrap(mean_to - 280.0 * DEG)) < 5.0 * DEG
    # calm sea: no components, kernels return zeros
    calm = W.realize(W.Waves(), DEEP, np.random.default_rng(0))
    assert calm.components.shape == (0, 6)
    assert W.kinematics_at(calm.components, DEEP, 0.0, 0.0, 1.0, 5.0) == (0.0,) * 7


@pytest.mark.parametrize("seed, depth", [(101, DEEP), (202, DEEP), (303, 25.0)])
def test_realized_sea_recovers_hs_tp_direction_and_spread(seed, depth):
    """Acceptance: a virtual PUV buoy's 3-h record gives back H_s, T_p, mean direction and spreading.

    Sampling errors allowed (3σ each, σ derived, not tuned):
      * H_s = 4 √(variance of η): σ/H_s = ½ √(2π ∫S²dω /(T m0²)) (Gaussian sea, see hs_sigma) —
        1.8 % here. The realization's own error is smaller (its variance is exact by construction;
        only cross terms between lines, O(1/(Δω T)), remain): over 40 seeds the rms error was
        0.4 σ.
      * T_p: weighted least-squares fit of the JONSWAP shape (γ known) to band-averaged spectra
        (bands of m = 32 raw ordinates, 0.019 rad/s, ν = 64) where S > 10 % of the peak; σ from the
        fit covariance with the per-band noise derived in fit_peaks (record length + finite number
        of components) — 0.5 % here (over 40 seeds the rms error was 0.36 σ).
      * mean direction and spreading from the bulk first-order Fourier coefficients (buoy method):
        σ derived in direction_sigmas (record + finite N) — 2.0° and 0.023 rad in σ₁ here (over
        40 seeds the rms errors were 0.31 σ and 0.29 σ: the bounds are upper bounds, the
        Latin-hypercube directions and line spectrum beat the i.i.d./Gaussian assumptions).
    """
    waves = W.Waves(spectrum="jonswap", hs_m=2.5, tp_s=9.0, gamma=3.3, direction_deg=30.0,
                    spreading="cos2s", spreading_s=10.0, n_components=200)
    field = W.realize(waves, depth, np.random.default_rng(seed))
    eta, u, v = buoy_record(field)  # finite depth: u, v carry coth(kh), which a₁, b₁ cancel
    sys0 = field.systems[0]
    # H_s
    hs_hat = 4.0 * eta.std()
    sig_hs = hs_sigma(field, T_REC) * field.hs_m
    assert abs(hs_hat - field.hs_m) < 3 * sig_hs, (hs_hat, field.hs_m, sig_hs)
    # T_p
    m = 32
    edges, spec = band_spectra(DT, (eta, u, v), m)
    Sb = band_mean(field.spectrum, edges)
    sel = Sb > 0.1 * Sb.max()
    (est,), (sd,) = fit_peaks(field, edges, spec[0, 0], m, sel, [3.3])
    tp_hat, sig_tp = 2 * math.pi / est[1], sd[1] * field.tp_s  # σ(ln ω_p) = σ(T_p)/T_p
    assert abs(tp_hat - 9.0) < 3 * sig_tp, (tp_hat, sig_tp)
    assert sig_tp < 0.01 * 9.0  # so a 3 % error in T_p would fail
    # direction and spreading from the buoy
    seld = Sb > 0.05 * Sb.max()
    th_hat, r1_hat = buoy_direction(spec, seld)
    r1, r2 = (float(x) for x in W.spreading_moments("cos2s", 10.0))
    weights = spec[0, 0][seld] / spec[0, 0][seld].sum()
    frac = np.sum(Sb[seld] * np.diff(edges)[seld]) / (sys0.hs_m ** 2 / 16.0)
    sig_th, sig_r1 = direction_sigmas(r1, r2, m, weights, frac * sys0.n)
    mean_to, spread = field.bulk_direction()
    assert mean_to == pytest.approx(210.0 * DEG)  # from 30° → towards 210°
    assert spread == pytest.approx(math.sqrt(2.0 / 11.0), rel=1e-6)
    assert abs(wrap(th_hat - mean_to)) < 3 * sig_th, (th_hat / DEG, sig_th / DEG)
    sig_spread = sig_r1 / math.sqrt(2.0 * (1.0 - r1))  # σ₁ = √(2(1 − r₁))
    assert abs(float(W.circular_spread(r1_hat)) - spread) < 3 * sig_spread, (r1_hat, sig_spread)
    assert sig_spread < 0.05 and sig_th < 3.0 * DEG


def _phasor_autocorrelation(comp, x, y, lags):
    """|ρ(τ)| envelope of η's time-average autocorrelation at (x, y), exactly, from the components.

    Components of equal frequency add as phasors A = Σ a e^{i(ε − k·x)} at the point; then
    ρ(τ) = Re Σ w_k e^{iΩ_k τ}, w_k = |A_k|²/Σ|A|², and |Σ w_k e^{iΩ_k τ}| is its envelope.
    """
    om, inv = np.unique(comp[:, 1], return_inverse=True)
    ph = comp[:, 5] - comp[:, 2] * (x * comp[:, 3] + y * comp[:, 4])
    A = (np.bincount(inv, comp[:, 0] * np.cos(ph), om.size)
         + 1j * np.bincount(inv, comp[:, 0] * np.sin(ph), om.size))
    wk = np.abs(A) ** 2
    wk /= wk.sum()
    out = np.empty(lags.size)
    for i in range(0, lags.size, 4096):
        out[i:i + 4096] = np.abs(np.exp(1j * np.outer(lags[i:i + 4096], om)) @ wk)
    return out, wk


def test_no_periodicity_within_three_hours_and_the_check_can_fail():
    """Envelope of η's autocorrelation at a point for lags 5 min … 3 h stays below a derived bound.

    For the single summation, at a lag τ long enough that the phases Ω_k τ are scattered (τ well
    past the correlation time, which is below a minute here), Σ w_k e^{iΩ_kτ} is a complex
    Gaussian with E|·|² = Σw_k², so P(|ρ_c| > b) = exp(−b²/Σw²) (Rayleigh). A union bound over
    the M lags evaluated gives b = √(Σw² ln(M/p)); with p = 1e−3, n = 200 equal components and
    M = 21 001 lags, b ≈ 0.29. A fixed-grid double summation (40 frequencies × 5 directions,
    the same spectrum) repeats after 2π/Δω ≈ 200 s: its envelope reaches 1 — the same check fails.
    """
    waves = W.Waves(hs_m=2.0, tp_s=8.0, n_components=200)
    lags = np.arange(300.0, 10800.0 + 0.25, 0.5)
    for seed in (1, 2, 3):
        f = W.realize(waves, DEEP, np.random.default_rng(seed))
        env, wk = _phasor_autocorrelation(f.components, 25.0, -40.0, lags)
        bound = math.sqrt(np.sum(wk ** 2) * math.log(lags.size / 1e-3))
        assert 0.25 < bound < 0.32
        assert env.max() < bound, (seed, env.max(), bound)
    # fixed grids: ω_i = (i + 1) Δω over the same band, 5 directions each, equal-Δ amplitudes √(2 S D Δω Δμ)
    s = f.systems[0]
    nf, nd = 40, 5
    dw = (s.omega_hi - s.omega_lo) / nf
    om = s.omega_lo + dw * (np.arange(nf) + 0.5)
    mu = s.direction_to + np.linspace(-math.pi / 2, math.pi / 2, nd + 1)[:-1] + math.pi / (2 * nd)
    Sd = s.directional(om, mu)
    rng = np.random.default_rng(9)
    O, M = np.meshgrid(om, mu, indexing="ij")
    grid = np.column_stack([np.sqrt(2 * Sd * dw * (math.pi / nd)).ravel(), O.ravel(),
                            W.wavenumber(O.ravel(), DEEP), np.cos(M).ravel(), np.sin(M).ravel(),
                            rng.uniform(0, 2 * math.pi, nf * nd)])
    env, wk = _phasor_autocorrelation(grid, 25.0, -40.0, lags)
    bound = math.sqrt(np.sum(wk ** 2) * math.log(lags.size / 1e-3))
    assert env.max() > 0.99 > 0.32  # the single-sum bound above
    period = 2 * math.pi / dw
    i = np.argmin(np.abs(lags - 10 * period))
    assert env[i] > 0.99
    # and the kernel's own η shows it: η(t + 10 T_rep) = η(t) when the grid starts at a multiple of Δω
    grid[:, 1] = np.repeat(dw * (np.arange(nf) + 20), nd)
    t = np.linspace(0, 600, 601)
    e1 = W.elevation(grid, 25.0, -40.0, t)
    e2 = W.elevation(grid, 25.0, -40.0, t + 10 * period)
    np.testing.assert_allclose(e2, e1, atol=1e-9 * np.abs(e1).max())


def test_sea_and_swell_with_mitsuyasu_spreading():
    """Bimodal sea: total H_s and both peak periods and mean directions recovered (3σ, as above).

    Wind sea JONSWAP H_s 2 m, T_p 7 s from 0°, Mitsuyasu s_max 10; swell JONSWAP H_s 1.5 m, T_p
    14 s from 60°, cos-2s s = 25. H_s: σ from hs_sigma; peaks: fit of two JONSWAP shapes (γ known)
    with σ from fit_peaks; directions: bulk first moments over the bands where one system holds
    ≥ 90 % of the energy, against the target's bulk direction over the same bands, σ from
    direction_sigmas with that system's r₁, r₂ there.
    """
    waves = W.Waves(hs_m=2.0, tp_s=7.0, direction_deg=0.0, spreading="mitsuyasu", spreading_s=10.0,
                    swell_hs_m=1.5, swell_tp_s=14.0, swell_direction_deg=60.0, swell_spreading="cos2s",
                    swell_spreading_s=25.0)
    for seed in (5, 6):
        field = W.realize(waves, DEEP, np.random.default_rng(seed))
        eta, u, v = buoy_record(field)
        assert field.hs_m == pytest.approx(2.5)
        assert abs(4 * eta.std() - 2.5) < 3 * hs_sigma(field, T_REC) * 2.5
        m = 32
        edges, spec = band_spectra(DT, (eta, u, v), m)
        Sb = band_mean(field.spectrum, edges)
        sel = Sb > 0.1 * Sb.max()
        est, sd = fit_peaks(field, edges, spec[0, 0], m, sel, [3.3, 3.3])
        for (hs, wp), (_, s_lnwp), sysm in zip(est, sd, field.systems):
            assert abs(math.log(wp / sysm.omega_p)) < 3 * s_lnwp, (sysm.tp_s, 2 * math.pi / wp, s_lnwp)
            assert s_lnwp < 0.04
        assert field.tp_s == pytest.approx(14.0, rel=1e-3)  # the swell's peak is the higher one
        wc = 0.5 * (edges[1:] + edges[:-1])
        for i, sysm in enumerate(field.systems):
            own = band_mean(sysm.spectrum_1d, edges)
            seld = (own > 0.9 * Sb) & (own > 0.05 * own.max())
            assert seld.sum() >= 10
            th_hat, _ = buoy_direction(spec, seld)
            # the target's bulk direction over these bands (the other system's few % included)
            A1 = B1 = 0.0
            for sj in field.systems:
                a1, b1 = sj.first_moments(wc[seld])
                Sj = band_mean(sj.spectrum_1d, edges)[seld]
                A1, B1 = A1 + np.dot(Sj, a1), B1 + np.dot(Sj, b1)
            th_true = math.atan2(B1, A1)
            assert abs(wrap(th_true - sysm.direction_to)) < 5.0 * DEG  # mostly this system's
            r1s, r2s = W.spreading_moments(sysm.spreading, sysm.s_of(wc[seld]))
            wts = own[seld] / own[seld].sum()
            r1 = float(np.dot(wts, np.broadcast_to(r1s, wts.shape)))
            r2 = float(np.dot(wts, np.broadcast_to(r2s, wts.shape)))
            n_lines = sysm.n * np.sum(own[seld] * np.diff(edges)[seld]) / (sysm.hs_m ** 2 / 16.0)
            sig_th, _ = direction_sigmas(r1, r2, m, spec[0, 0][seld] / spec[0, 0][seld].sum(), n_lines)
            assert abs(wrap(th_hat - th_true)) < 3 * sig_th, (i, th_hat / DEG, th_true / DEG, sig_th / DEG)
        # Mitsuyasu: each wind-sea component's direction offset follows s(ω) at its own frequency
        sea = field.components[:field.systems[0].n]
        s0 = field.systems[0]
        cosd = sea[:, 3] * math.cos(s0.direction_to) + sea[:, 4] * math.sin(s0.direction_to)
        r1j, r2j = W.spreading_moments("mitsuyasu", s0.s_of(sea[:, 1]))
        r1_const = float(W.spreading_moments("cos2s", s0.s)[0])
        for part in (sea[:, 1] < 0.9 * s0.omega_p, sea[:, 1] > 1.2 * s0.omega_p):
            n = part.sum()
            # i.i.d. bound on the variance of the mean (the stratified draw does better)
            sig = math.sqrt(np.sum(0.5 * (1 + r2j[part]) - r1j[part] ** 2)) / n
            assert abs(cosd[part].mean() - r1j[part].mean()) < 3 * sig
        # and a constant s = s_max would not pass: the upper flank (most components) is broader
        assert cosd[part].mean() < r1_const - 3 * sig


def test_other_spreadings_are_sampled_from_their_distribution():
    """Component directions follow cos² (±90°) and long-crested seas are long-crested."""
    f = W.realize(W.Waves(hs_m=1.0, tp_s=6.0, direction_deg=270.0, spreading="cos2", n_components=400),
                  DEEP, np.random.default_rng(4))
    d = np.arctan2(f.components[:, 4], f.components[:, 3]) - 90.0 * DEG  # from 270° → towards 90°
    d = wrap(d)
    assert np.abs(d).max() <= math.pi / 2
    # Kolmogorov–Smirnov distance to F(θ) = ½ + (θ + sin θ cos θ)/π; stratified draws do far better
    # than the i.i.d. 1.36/√n (5 % level)
    ds = np.sort(d)
    F = 0.5 + (ds + np.sin(ds) * np.cos(ds)) / math.pi
    n = ds.size
    ks = max(np.max(np.arange(1, n + 1) / n - F), np.max(F - np.arange(n) / n))
    assert ks < 1.36 / math.sqrt(n)
    g = W.realize(W.Waves(hs_m=1.0, tp_s=6.0, direction_deg=45.0, spreading="none"), 30.0,
                  np.random.default_rng(4))
    np.testing.assert_allclose(g.components[:, 3], math.cos(225.0 * DEG), rtol=1e-14)
    np.testing.assert_allclose(g.components[:, 4], math.sin(225.0 * DEG), rtol=1e-14)
    assert g.bulk_direction()[1] == pytest.approx(0.0, abs=1e-7)


def test_truth_helpers_directional_spectrum_integrates_to_the_1d_one():
    waves = W.Waves(hs_m=2.0, tp_s=8.0, direction_deg=10.0, spreading="mitsuyasu", spreading_s=10.0,
                    swell_hs_m=1.0, swell_tp_s=13.0, swell_direction_deg=300.0, swell_spreading="cos2")
    f = W.realize(waves, DEEP, np.random.default_rng(1))
    w = np.linspace(0.3, 3.0, 60)
    mu = np.linspace(0.0, 2 * math.pi, 1441)[:-1]
    Sd = f.directional_spectrum(w, mu)
    # (rectangle rule on a periodic integrand; Mitsuyasu's s < ½ at high ω leaves a cusp behind the peak)
    np.testing.assert_allclose(Sd.sum(axis=1) * (mu[1] - mu[0]), f.spectrum(w), rtol=1e-5)
    assert Sd.shape == (60, 1440) and np.all(Sd >= 0.0)


def test_input_errors_name_the_field():
    with pytest.raises(InputError, match=r"environment\.waves\.tp_s.*exactly one of tp_s, tz_s, t1_s"):
        W.realize(W.Waves(hs_m=2.0), DEEP, np.random.default_rng(0))
    with pytest.raises(InputError, match=r"tp_s.*given: tp_s, tz_s"):
        W.realize(W.Waves(hs_m=2.0, tp_s=8.0, tz_s=6.0), DEEP, np.random.default_rng(0))
    with pytest.raises(InputError, match=r"tz_s.*Bretschneider"):
        W.realize(W.Waves(spectrum="bretschneider", hs_m=2.0, tz_s=6.0), DEEP, np.random.default_rng(0))
    with pytest.raises(InputError, match=r"swell_tp_s.*missing"):
        W.realize(W.Waves(swell_hs_m=1.0), DEEP, np.random.default_rng(0))
    with pytest.raises(InputError, match=r"water_depth_m.*-3"):
        W.realize(W.Waves(hs_m=1.0, tp_s=8.0), -3.0, np.random.default_rng(0))
    with pytest.raises(InputError, match=r"spreading.*'cos3'"):
        W.realize(W.Waves(hs_m=1.0, tp_s=8.0, spreading="cos3"), DEEP, np.random.default_rng(0))
    with pytest.raises(TypeError, match="Generator"):
        W.realize(W.Waves(hs_m=1.0, tp_s=8.0), DEEP, 42)
    # the schema reader checks ranges and names the field and what is allowed
    from vtrials.schema import read_table
    with pytest.raises(InputError, match=r"environment\.waves\.hs_m: 25\.0 is out of range.*\[0, 20\] m"):
        read_table(W.Waves, {"hs_m": 25.0, "tp_s": 8.0}, "s.toml", "environment.waves")
    with pytest.raises(InputError, match=r"environment\.waves\.spreading: 'cos3' is not allowed"):
        read_table(W.Waves, {"spreading": "cos3"}, "s.toml", "environment.waves")
    got, _ = read_table(W.Waves, {"hs_m": 2, "tz_s": 6, "direction_deg": 45}, "s.toml", "environment.waves")
    assert dataclasses.replace(got) == W.Waves(hs_m=2.0, tz_s=6.0, direction_deg=45.0)
