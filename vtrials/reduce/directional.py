"""Directional wave spectra from a heave–pitch–roll buoy (η, ∂η/∂x, ∂η/∂y) or an (η, u, v) buoy.

Directions μ [rad] are where the waves go TOWARDS, from north (x) clockwise to east (y), as in
:mod:`vtrials.physics.environment.waves`; the nautical "from" direction is μ + π.

1. First five Fourier coefficients (Longuet-Higgins, Cartwright & Smith 1963, "Observations of the
   directional spectrum of sea waves using the motions of a floating buoy"), from the cross-spectra
   G_mn = E[X_m* X_n] (one-sided, :func:`vtrials.reduce.spectra.cross_spectral_matrix`) of the channels
   1 = η, 2 = p, 3 = q. With p, q the slopes ∂η/∂x, ∂η/∂y (in quadrature with η) or the horizontal
   velocities u, v (in phase):
       a₁ = s Im G₁₂ / √(G₁₁(G₂₂ + G₃₃)),  b₁ = s Im G₁₃ / √(…)   (slopes, s = −1; velocities use Re, s = 1)
       a₂ = (G₂₂ − G₃₃)/(G₂₂ + G₃₃),  b₂ = 2 Re G₂₃/(G₂₂ + G₃₃),
   the moments ∫D(μ)(cos μ, sin μ, cos 2μ, sin 2μ) dμ of the spreading function D at each ω.
   Mean direction μ₁ = atan2(b₁, a₁), circular spread σ₁ = √(2(1 − √(a₁² + b₁²))) (Kuik, van Vledder
   & Holthuijsen 1988, J. Phys. Oceanogr. 18:1020); bulk values from the S-weighted a₁, b₁.
2. Maximum-likelihood method (Capon 1969; Isobe, Kondo & Horikawa 1984, Proc. 19th ICCE) written on
   the normalised co-spectral matrix of (1, cos μ, sin μ), which the five coefficients fix:
       Φ = [[1, a₁, b₁], [a₁, (1 + a₂)/2, b₂/2], [b₁, b₂/2, (1 − a₂)/2]],  D(μ) ∝ 1/(hᵀ Φ⁻¹ h),
   h = (1, cos μ, sin μ), normalised to ∫D dμ = 1.
3. Maximum-entropy method (Lygre & Krogstad 1986, J. Phys. Oceanogr. 16:2052–2060), c₁ = a₁ + i b₁,
   c₂ = a₂ + i b₂: φ₁ = (c₁ − c₂ c₁*)/(1 − |c₁|²), φ₂ = c₂ − c₁ φ₁,
       D(μ) = (1/2π)(1 − φ₁ c₁* − φ₂ c₂*)/|1 − φ₁ e^{−iμ} − φ₂ e^{−2iμ}|²,
   which reproduces all five coefficients exactly.
4. Extended maximum-entropy principle (EMEP; Hashimoto, Nagai & Asai 1994, Proc. 24th ICCE, "Extension of
   the maximum entropy principle method for directional wave spectrum estimation"): D is sought in the
   exponential family D(μ) = exp(Σ_{n=1}^{N} α_n cos nμ + β_n sin nμ)/Z — the Shannon-entropy maximum under
   moment constraints (Kobune & Hashimoto 1986) — with the order N chosen by Akaike's information
   criterion against the moments' sampling errors. For a buoy, whose data fix the moments up to n = 2,
   N ∈ {1, 2}: N = 1 (a von Mises distribution) meets a₁, b₁; N = 2 meets all four. Each fit solves the
   convex dual min F(λ) = ln ∫ exp(λ·f(μ)) dμ − λ·m̂ + ½ ε Σ λ_k², f = (cos μ, sin μ, cos 2μ, sin 2μ)[:2N],
   by damped Newton (gradient E_D[f] − m̂ + ελ, Hessian Cov_D[f] + ε I); the tiny ε = 10⁻⁹ only keeps λ
   finite when a noisy moment set is not realizable by any density. AIC = Σ_k (m_k(D) − m̂_k)²/σ_k² + 2·2N
   over all four moments, with σ_n² = (1 − r_n²)/ν for a record of ν degrees of freedom (r_n = |a_n + i b_n|;
   assumption, of the order of Long 1980's sampling variances): N = 1 is kept where the second moments do
   not differ from the von Mises ones by more than their errors justify. The diwasp-python port of the
   DIWASP toolbox (PyPI ``diwasp`` 0.1.1) has an EMEP, but requires wavespectra, xarray and pandas at install
   and works from sensor cross-spectra with transfer functions; not used (the buoy's five coefficients are
   all a buoy transmits).
5. Buoy reports (:func:`buoy_reports`): a wave buoy's transmitted spectra (S, a₁, b₁, a₂, b₂ per
   frequency and per record) read from a trial record, as :class:`FourierCoefficients`;
   :func:`observed_sea` turns the reports of a window into the observed wave system the speed-trial
   analysis uses (the format of ``team["sea_observed"]``, :mod:`vtrials.reduce.stawave`): H_s = 4√m0 of
   the averaged spectrum, its peak period (parabolic refinement), the mean direction it comes from, a
   JONSWAP γ from the peak's height over the Pierson–Moskowitz one of the same H_s and T_p
   (γ C(γ) = S(ω_p)/S_PM(ω_p), C(γ) ≈ 1 − 0.287 ln γ, DNV-RP-C205 §3.5.5; γ ≤ 1: Pierson–Moskowitz), and
   the standard error of H_s from the record's sampling variability (ν₀ = T m0²/(π ∫S² dω), Bendat &
   Piersol 2010 §8.2.1, over the reports' total duration: relative sd of H_s = ½ √(2/ν₀)).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from vtrials.errors import InputError
from vtrials.reduce.spectra import cross_spectral_matrix

TWO_PI = 2.0 * math.pi


@dataclasses.dataclass(frozen=True)
class FourierCoefficients:
    """S(ω) [m² s/rad] and the directional moments a₁, b₁, a₂, b₂ per ω [rad/s] (module doc)."""

    omega: np.ndarray
    S: np.ndarray
    a1: np.ndarray
    b1: np.ndarray
    a2: np.ndarray
    b2: np.ndarray
    dof: float

    @property
    def mean_direction(self) -> np.ndarray:
        """μ₁(ω) = atan2(b₁, a₁) [rad], towards, in [0, 2π)."""
        return np.arctan2(self.b1, self.a1) % TWO_PI

    @property
    def spread(self) -> np.ndarray:
        """σ₁(ω) = √(2(1 − r₁)) [rad]."""
        return np.sqrt(2.0 * (1.0 - np.clip(np.hypot(self.a1, self.b1), 0.0, 1.0)))

    def bulk(self, omega_lo: float = 0.0, omega_hi: float = math.inf) -> tuple[float, float, float]:
        """(H_s [m], mean direction towards [rad], σ₁ [rad]) over a band, a₁ and b₁ weighted by S."""
        m = (self.omega >= omega_lo) & (self.omega <= omega_hi) & np.isfinite(self.a1)
        w, S = self.omega[m], self.S[m]
        m0 = np.trapezoid(S, w)
        A1 = np.trapezoid(S * self.a1[m], w) / m0
        B1 = np.trapezoid(S * self.b1[m], w) / m0
        return 4.0 * math.sqrt(m0), math.atan2(B1, A1) % TWO_PI, math.sqrt(2.0 * (1.0 - min(1.0, math.hypot(A1, B1))))


def fourier_coefficients(eta, p, q, fs: float, nperseg: int, channels: str = "slopes") -> FourierCoefficients:
    """First five Fourier coefficients from records η [m] and p, q (slopes [–] or velocities [m/s]) at fs [Hz].

    ``channels``: "slopes" (heave–pitch–roll buoy: p = ∂η/∂x north, q = ∂η/∂y east) or "velocities"
    (u north, v east: a GPS or current-meter buoy).
    """
    if channels not in ("slopes", "velocities"):
        raise InputError("record", "channels", f"{channels!r}: expected 'slopes' or 'velocities'")
    G = cross_spectral_matrix([eta, p, q], fs, nperseg)
    C = G.S
    g11 = C[:, 0, 0].real
    g22 = C[:, 1, 1].real
    g33 = C[:, 2, 2].real
    with np.errstate(invalid="ignore", divide="ignore"):
        den = np.sqrt(g11 * (g22 + g33))
        if channels == "slopes":
            a1 = -C[:, 0, 1].imag / den
            b1 = -C[:, 0, 2].imag / den
        else:
            a1 = C[:, 0, 1].real / den
            b1 = C[:, 0, 2].real / den
        a2 = (g22 - g33) / (g22 + g33)
        b2 = 2.0 * C[:, 1, 2].real / (g22 + g33)
    return FourierCoefficients(G.omega, g11, a1, b1, a2, b2, G.dof)


def _normalise(D, mu):
    dmu = TWO_PI / mu.size
    return D / (np.sum(D, axis=-1, keepdims=True) * dmu)


def mlm(a1, b1, a2, b2, mu):
    """Maximum-likelihood spreading D(μ) [1/rad] on a uniform grid mu [rad] over one turn (module doc, 2).

    Coefficient arrays of shape (n,) give D of shape (n, len(mu)).
    """
    a1, b1, a2, b2 = (np.atleast_1d(np.asarray(v, dtype=float)) for v in (a1, b1, a2, b2))
    mu = np.asarray(mu, dtype=float)
    Phi = np.empty(a1.shape + (3, 3))
    Phi[..., 0, 0] = 1.0
    Phi[..., 0, 1] = Phi[..., 1, 0] = a1
    Phi[..., 0, 2] = Phi[..., 2, 0] = b1
    Phi[..., 1, 1] = 0.5 * (1.0 + a2)
    Phi[..., 2, 2] = 0.5 * (1.0 - a2)
    Phi[..., 1, 2] = Phi[..., 2, 1] = 0.5 * b2
    inv = np.linalg.pinv(Phi)
    h = np.stack([np.ones_like(mu), np.cos(mu), np.sin(mu)])  # (3, n_mu)
    quad = np.einsum("im,...ij,jm->...m", h, inv, h)
    D = 1.0 / np.maximum(quad, 1e-12)
    return _normalise(D, mu)


def imlm(a1, b1, a2, b2, mu, iterations: int = 30, relax: float = 1.0):
    """Iterated maximum-likelihood spreading (Pawka 1983, J. Geophys. Res. 88:2653; Oltman-Shay & Guza 1984,
    J. Phys. Oceanogr. 14:1800) [1/rad] on the uniform grid mu [rad].

    The MLM broadens the spreading: MLM(moments of D) ≠ D. Starting from D₀ = MLM of the measured
    coefficients, D_{n+1} = max(0, D_n + λ (D₀ − MLM(moments of D_n))), renormalised — the D whose MLM
    image matches the measured one.
    """
    mu = np.asarray(mu, dtype=float)
    D0 = mlm(a1, b1, a2, b2, mu)
    D = D0.copy()
    dmu = TWO_PI / mu.size
    c1, s1, c2, s2 = np.cos(mu), np.sin(mu), np.cos(2 * mu), np.sin(2 * mu)
    for _ in range(iterations):
        m = [np.sum(D * f, axis=-1) * dmu for f in (c1, s1, c2, s2)]
        D = _normalise(np.maximum(D + relax * (D0 - mlm(*m, mu)), 0.0), mu)
    return D


def mem(a1, b1, a2, b2, mu):
    """Maximum-entropy spreading D(μ) [1/rad] (Lygre & Krogstad 1986; module doc, 3) on the grid mu [rad]."""
    a1, b1, a2, b2 = (np.atleast_1d(np.asarray(v, dtype=float)) for v in (a1, b1, a2, b2))
    mu = np.asarray(mu, dtype=float)
    c1 = (a1 + 1j * b1)[:, None]
    c2 = (a2 + 1j * b2)[:, None]
    p1 = (c1 - c2 * np.conj(c1)) / (1.0 - np.abs(c1) ** 2)
    p2 = c2 - c1 * p1
    e1 = np.exp(-1j * mu)[None, :]
    num = (1.0 - p1 * np.conj(c1) - p2 * np.conj(c2)).real
    D = num / (TWO_PI * np.abs(1.0 - p1 * e1 - p2 * e1 * e1) ** 2)
    return _normalise(np.maximum(D, 0.0), mu)


EMEP_EPS = 1e-9  # dual regularisation of the EMEP fit (module doc, 4)


def _emep_fit(m_hat, sig2, F, mu, iterations: int = 100):
    """λ (n, k) of D ∝ exp(λ·F(μ)) for target moments m_hat (n, k) with moment variances sig2 (n, k)
    (module doc, 4): damped Newton on the convex dual, vectorised over rows. F: (k, n_mu)."""
    n, k = m_hat.shape
    lam = np.zeros((n, k))
    dmu = TWO_PI / mu.size

    def dual(lam_):
        z = lam_ @ F
        zmax = z.max(axis=1, keepdims=True)
        w = np.exp(z - zmax)
        Z = w.sum(axis=1) * dmu
        return np.log(Z) + zmax[:, 0] - np.sum(lam_ * m_hat, axis=1) + 0.5 * np.sum(sig2 * lam_ ** 2, axis=1), w, Z

    val, w, Z = dual(lam)
    for _ in range(iterations):
        D = w / Z[:, None]  # density ×(1/dmu) normalisation folded: Σ D dmu = 1
        E = D @ F.T * dmu
        cov = np.einsum("nm,km,lm->nkl", D, F, F) * dmu - E[:, :, None] * E[:, None, :]
        g = E - m_hat + sig2 * lam
        H = cov + np.einsum("nk,kl->nkl", sig2 + 1e-12, np.eye(k))
        step = np.linalg.solve(H, g[:, :, None])[:, :, 0]
        t = np.ones(n)
        for _ls in range(30):  # backtracking: accept where the dual decreases
            cand = lam - t[:, None] * step
            v2, w2, Z2 = dual(cand)
            ok = v2 <= val + 1e-14
            if np.all(ok):
                break
            t = np.where(ok, t, 0.5 * t)
        lam, val, w, Z = cand, v2, w2, Z2
        if np.max(np.abs(t[:, None] * step)) < 1e-10:
            break
    return lam


def emep(a1, b1, a2, b2, mu, dof: float | None = None, orders=(1, 2)):
    """EMEP spreading D(μ) [1/rad] (module doc, 4) on a uniform grid mu [rad] over one turn.

    ``dof``: the equivalent degrees of freedom of the coefficient estimates (a Welch bin's ν) — the
    moments are then met within their sampling errors and the order N ∈ ``orders`` chosen by AIC; None:
    exact moments, N = max(orders). Returns D of shape (n, len(mu)).
    """
    a1, b1, a2, b2 = (np.atleast_1d(np.asarray(v, dtype=float)) for v in (a1, b1, a2, b2))
    mu = np.asarray(mu, dtype=float)
    m_all = np.stack([a1, b1, a2, b2], axis=1)
    F_all = np.stack([np.cos(mu), np.sin(mu), np.cos(2 * mu), np.sin(2 * mu)])
    r = np.stack([np.hypot(a1, b1)] * 2 + [np.hypot(a2, b2)] * 2, axis=1)
    sig2 = np.maximum(1.0 - r ** 2, 1e-4) / float(dof) if dof is not None else None
    best_D = None
    best_aic = None
    dmu = TWO_PI / mu.size
    for N in (sorted(orders) if dof is not None else [max(orders)]):
        k = 2 * N
        lam = _emep_fit(m_all[:, :k], np.full((m_all.shape[0], k), EMEP_EPS), F_all[:k], mu)
        z = lam @ F_all[:k]
        D = np.exp(z - z.max(axis=1, keepdims=True))
        D = D / (D.sum(axis=1, keepdims=True) * dmu)
        if dof is None:
            return D
        got = D @ F_all.T * dmu
        aic = np.sum((got - m_all) ** 2 / np.maximum(sig2, 1e-12), axis=1) + 2.0 * k
        if best_D is None:
            best_D, best_aic = D, aic
        else:
            better = aic < best_aic
            best_D = np.where(better[:, None], D, best_D)
            best_aic = np.where(better, aic, best_aic)
    return best_D


METHODS = {"MLM": mlm, "IMLM": imlm, "MEM": mem, "EMEP": emep}


def buoy_reports(record, instrument: str) -> tuple[np.ndarray, list[FourierCoefficients]]:
    """(report times [s], one :class:`FourierCoefficients` per report) of a wave buoy's transmitted spectra
    in a trial record (channels S, a1, b1, a2, b2 over the frequencies of its metadata, ``omega_rad_s``)."""
    meta = record.meta(instrument)
    if meta.get("kind") != "wave_buoy" or meta.get("output") != "spectra":
        raise InputError(str(getattr(record, "path", "record")), f"{instrument}",
                         "not a wave buoy's spectra (kind wave_buoy with output = 'spectra')")
    omega = np.asarray(meta["omega_rad_s"], dtype=float)
    t, S = record.channel(instrument, "S")
    coef = {c: record.channel(instrument, c)[1] for c in ("a1", "b1", "a2", "b2")}
    dof = float(meta.get("welch_dof", math.nan))
    out = [FourierCoefficients(omega, np.asarray(S[i]), *(np.asarray(coef[c][i]) for c in ("a1", "b1", "a2", "b2")),
                               dof) for i in range(np.size(t))]
    return np.asarray(t), out


def observed_sea(reports: list[FourierCoefficients], record_s: float) -> list[dict]:
    """One observed wave system (module doc, 5) from the buoy reports of a window (each of ``record_s`` [s])."""
    if not reports:
        return []
    w = reports[0].omega
    S = np.mean([r.S for r in reports], axis=0)
    m0 = float(np.trapezoid(S, w))
    if not m0 > 0.0:
        return []
    A1 = float(np.mean([np.trapezoid(r.S * np.nan_to_num(r.a1), w) for r in reports])) / m0
    B1 = float(np.mean([np.trapezoid(r.S * np.nan_to_num(r.b1), w) for r in reports])) / m0
    k = int(np.argmax(S))
    wp = float(w[k])
    if 0 < k < w.size - 1:
        d = S[k - 1] - 2.0 * S[k] + S[k + 1]
        if d < 0.0:
            wp += 0.5 * (S[k - 1] - S[k + 1]) / d * float(w[1] - w[0])
    hs = 4.0 * math.sqrt(m0)
    s_pm = 0.3125 * hs * hs / wp * math.exp(-1.25)  # Bretschneider / PM at its peak
    ratio = float(np.max(S)) / s_pm
    gamma = None
    if ratio > 1.0:
        lo, hi = 1.0, 10.0  # γ C(γ) rises monotonically on [1, 10]
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if mid * (1.0 - 0.287 * math.log(mid)) < ratio else (lo, mid)
        gamma = 0.5 * (lo + hi)
    nu0 = len(reports) * record_s * m0 * m0 / (math.pi * float(np.trapezoid(S * S, w)))
    return [{"hs_m": hs, "tp_s": float(TWO_PI / wp), "gamma": gamma, "from_rad": (math.atan2(B1, A1) + math.pi) % TWO_PI,
             "hs_rel_std": 0.5 * math.sqrt(2.0 / nu0), "tp_rel_std": float((w[1] - w[0]) / wp),
             "from_std_rad": math.sqrt(2.0 * (1.0 - min(1.0, math.hypot(A1, B1)))) / math.sqrt(0.5 * nu0)}]


def directional_estimate(fc: FourierCoefficients, method: str, mu=None, omega_lo: float = 0.0,
                         omega_hi: float = math.inf, min_fraction: float = 0.0):
    """(ω, S, D (n_ω, n_μ), μ, bulk mean direction [rad], bulk σ₁ [rad]) of one report by ``method``
    ("MLM", "IMLM", "MEM", "EMEP"; "fourier": the coefficients' own bulk values, D = MEM's) over the band,
    leaving out frequencies whose S is below ``min_fraction`` of the peak (noise-dominated tails)."""
    if method != "fourier" and method not in METHODS:
        raise InputError("reduction", "method", f"{method!r}: allowed fourier, {', '.join(METHODS)}")
    mu = np.linspace(0.0, TWO_PI, 360, endpoint=False) if mu is None else np.asarray(mu, dtype=float)
    m = (fc.omega >= omega_lo) & (fc.omega <= omega_hi) & np.isfinite(fc.a1) & np.isfinite(fc.a2)
    m &= fc.S >= min_fraction * float(np.max(fc.S[m])) if np.any(m) else m
    w, S = fc.omega[m], fc.S[m]
    args = (fc.a1[m], fc.b1[m], fc.a2[m], fc.b2[m], mu)
    if method == "fourier":
        D = mem(*args)
        m0 = np.trapezoid(S, w)
        A1 = np.trapezoid(S * fc.a1[m], w) / m0
        B1 = np.trapezoid(S * fc.b1[m], w) / m0
        return w, S, D, mu, math.atan2(B1, A1) % TWO_PI, math.sqrt(2.0 * (1.0 - min(1.0, math.hypot(A1, B1))))
    D = emep(*args, dof=fc.dof if math.isfinite(fc.dof) else None) if method == "EMEP" else METHODS[method](*args)
    md, sg = bulk_from_directional(w, S, D, mu)
    return w, S, D, mu, md, sg


def spreading_moments(D, mu) -> tuple[np.ndarray, np.ndarray]:
    """(mean direction [rad], σ₁ [rad]) of spreading functions D (…, n_mu) on a uniform grid over one turn."""
    dmu = TWO_PI / np.asarray(mu).size
    a1 = np.sum(D * np.cos(mu), axis=-1) * dmu
    b1 = np.sum(D * np.sin(mu), axis=-1) * dmu
    return np.arctan2(b1, a1) % TWO_PI, np.sqrt(2.0 * (1.0 - np.clip(np.hypot(a1, b1), 0.0, 1.0)))


def bulk_from_directional(omega, S, D, mu) -> tuple[float, float]:
    """(mean direction [rad], σ₁ [rad]) of S(ω) D(ω, μ) over the band given (S-weighted first moments)."""
    dmu = TWO_PI / np.asarray(mu).size
    E = np.asarray(S)[:, None] * D
    A1 = np.trapezoid(np.sum(E * np.cos(mu), axis=-1) * dmu, omega)
    B1 = np.trapezoid(np.sum(E * np.sin(mu), axis=-1) * dmu, omega)
    m0 = np.trapezoid(S, omega)
    return math.atan2(B1, A1) % TWO_PI, math.sqrt(2.0 * (1.0 - min(1.0, math.hypot(A1, B1) / m0)))
