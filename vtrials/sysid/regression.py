"""Equation-error identification of the hull forces from smoothed states and accelerations.

Inverse dynamics (Y&Y 2015 eq. 4): the measured motion requires total forces X, Y, N; the KNOWN
parts — rigid-body and added mass, propeller thrust and rudder forces of :class:`vtrials.sysid.mmg.Ship`,
driven by the recorded rudder angle and shaft speed — are subtracted, leaving the hull forces, which
are regressed on the hull terms of a model structure, equation by equation (ordinary least squares
on the non-dimensional forces; Alexandersson et al. 2022, Ocean Eng. 247, "inverse dynamics").

Parameter covariance: heteroskedasticity- and autocorrelation-consistent (Newey & West 1987,
Econometrica 55:703, Bartlett weights), because residuals of smoothed records are correlated in time.
Term selection: forward selection by the Bayesian information criterion (Schwarz 1978), with the
residual correlation accounted for by an effective sample size.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from vtrials.errors import InputError

_WHERE = "vtrials.sysid.regression"


@dataclasses.dataclass(frozen=True)
class Segment:
    """One maneuver's reconstructed motion (SI): states, accelerations, rudder angle and shaft rate."""

    t: np.ndarray
    u: np.ndarray
    v: np.ndarray
    r: np.ndarray
    udot: np.ndarray
    vdot: np.ndarray
    rdot: np.ndarray
    delta: np.ndarray
    n: np.ndarray
    phi: np.ndarray | None = None    # heel (rad), roll rate (rad/s), roll acceleration and the propellers'
    p: np.ndarray | None = None      # pitch ratio: the 4-DOF model's inputs (None for a 3-DOF model)
    pdot: np.ndarray | None = None
    pitch: np.ndarray | None = None

    @classmethod
    def from_nav(cls, sol, delta, n, phi=None, p=None, pdot=None, pitch=None) -> "Segment":
        """From a :class:`vtrials.sysid.navfilter.NavSolution` and the rudder angle (rad), shaft rate
        (1/s) and, for a 4-DOF model, heel, roll rate, roll acceleration and pitch ratio resampled at its
        instants."""
        t = np.asarray(sol.t, float)
        delta, n = (np.broadcast_to(np.asarray(a, float), t.shape).copy() for a in (delta, n))
        roll = [None if a is None else np.broadcast_to(np.asarray(a, float), t.shape).copy()
                for a in (phi, p, pdot, pitch)]
        return cls(t, sol.state("u"), sol.state("v"), sol.state("r"), sol.acc[:, 0], sol.acc[:, 1],
                   sol.acc[:, 2], delta, n, *roll)

    def where(self, keep) -> "Segment":
        """The samples selected by ``keep`` (a boolean mask or index array)."""
        return Segment(*(None if (a := getattr(self, f.name)) is None else a[keep]
                         for f in dataclasses.fields(Segment)))


@dataclasses.dataclass(frozen=True)
class Fit:
    """Least-squares fit of one equation: term names, coefficients, their HAC covariance,
    residual RMS, sample count, effective sample count and BIC."""

    terms: tuple
    coef: np.ndarray
    cov: np.ndarray
    rms: float
    n: int
    n_eff: float
    bic: float

    def sigma(self) -> np.ndarray:
        return np.sqrt(np.diag(self.cov))

    def as_dict(self) -> dict:
        return dict(zip(self.terms, self.coef))


def hull_force_samples(ship, seg: Segment) -> dict:
    """Hull forces per equation from inverse dynamics less the known parts: non-dimensional for the
    MMG model (:meth:`vtrials.sysid.mmg.Ship.hull_samples`), in N and N m for the 4-DOF model
    (:meth:`vtrials.sysid.blanke.Ship4.hull_samples`)."""
    return ship.hull_samples(seg)


def design(ship, segments, eq: str, terms, weighted: bool = False):
    """Stacked regressor matrix and hull-force vector of equation ``eq`` (a key of the ship's
    structures: X, Y, N, and K for a 4-DOF model), and the segment boundaries (for the HAC covariance,
    which must not lag across maneuvers).

    ``weighted``: rows scaled by the ship's row weights over their maximum. For the MMG model these are
    U²: the errors of reconstructed accelerations are about constant in newtons, so in prime units they
    grow as 1/U² where a turn has lost half its speed; weighting by U² is the matching weighted least
    squares (the 4-DOF model fits dimensional forces: unit weights)."""
    eqs = next(iter(ship.structures.values())).keys()
    if eq not in eqs:
        raise InputError(_WHERE, "eq", f"{eq!r}; allowed: {', '.join(eqs)}")
    A, y, w, bounds = [], [], [], [0]
    for seg in segments:
        A.append(ship.regressors(terms, seg))
        y.append(hull_force_samples(ship, seg)[eq])
        w.append(ship.row_weights(seg))
        bounds.append(bounds[-1] + len(seg.u))
    A, y = np.vstack(A), np.concatenate(y)
    if weighted:
        w = np.concatenate(w)
        w = w / w.max()
        A, y = A * w[:, None], y * w
    return A, y, bounds


def _hac(A, e, bounds, lags: int):
    """Newey-West 'meat' Σ_l w_l Σ_t (a_t e_t)(a_{t-l} e_{t-l})ᵀ within each segment."""
    g = A * e[:, None]
    S = g.T @ g
    for lag in range(1, lags + 1):
        w = 1.0 - lag / (lags + 1.0)
        G = np.zeros_like(S)
        for a, b in zip(bounds[:-1], bounds[1:]):
            if b - a > lag:
                G += g[a + lag:b].T @ g[a:b - lag]
        S += w * (G + G.T)
    return S


def hac_sigmas(A, y, coef, bounds, lags_list) -> dict:
    """σ of the OLS coefficients under the Newey–West covariance (as :func:`ols`) at each bandwidth of
    ``lags_list`` at once: the scores' lagged cross-products within each segment from one FFT
    (Wiener–Khinchin; the same sums :func:`_hac` forms lag by lag, to rounding)."""
    A = np.asarray(A, float)
    n, p = A.shape
    e = np.asarray(y, float) - A @ coef
    g = A * e[:, None]
    top = int(max(lags_list))
    C = np.zeros((top + 1, p, p))
    for a, b in zip(bounds[:-1], bounds[1:]):
        m = b - a
        if m < 1:
            continue
        nfft = 1 << int(np.ceil(np.log2(2 * m)))
        F = np.fft.rfft(g[a:b], nfft, axis=0)
        c = np.fft.irfft(F[:, :, None] * np.conj(F[:, None, :]), nfft, axis=0)   # Σ_t g_i[t+l] g_j[t]
        k = min(top, m - 1)
        C[:k + 1] += c[:k + 1]
    AtA_inv = np.linalg.pinv(A.T @ A)
    out = {}
    for L in lags_list:
        S = C[0].copy()
        for lag in range(1, int(L) + 1):
            S += (1.0 - lag / (L + 1.0)) * (C[lag] + C[lag].T)
        out[L] = np.sqrt(np.diag(AtA_inv @ S @ AtA_inv) * n / (n - p))
    return out


def plateau_sigma(A, y, coef, bounds, ladder) -> tuple[np.ndarray, dict]:
    """The largest Newey–West σ of each coefficient over the bandwidths of ``ladder`` (those up to a
    quarter of the shortest segment) and Andrews' (:func:`andrews_lags`); also {bandwidth: σ}. For
    residuals that mix white noise with a slow error, the AR(1) plug-in sees the white part's lag-1
    correlation and picks too short a bandwidth; the σ levels off once the bandwidth spans the slow
    error's correlation (and falls beyond only through the Bartlett window's bias): its plateau."""
    A = np.asarray(A, float)
    e = np.asarray(y, float) - A @ coef
    cap = max(1, int(np.diff(bounds).min()) // 4)
    lad = [int(L) for L in ladder if L <= cap]
    sig = hac_sigmas(A, y, coef, bounds, sorted(set(lad + [andrews_lags(e, bounds)])))
    return np.max(np.array(list(sig.values())), axis=0), sig


def _lag1(e, bounds) -> float:
    """Lag-1 autocorrelation of residuals pooled within segments (never across a boundary)."""
    num = sum(float(np.dot(e[a + 1:b], e[a:b - 1])) for a, b in zip(bounds[:-1], bounds[1:]) if b - a > 1)
    return float(np.clip(num / float(e @ e), 0.0, 0.999)) if e @ e > 0 else 0.0


def andrews_lags(e, bounds=None) -> int:
    """Bartlett-kernel bandwidth by Andrews' (1991, Econometrica 59:817, eqs. 6.2 and 6.4) AR(1)
    plug-in rule, 1.1447 (α̂(1) n)^(1/3) with α̂(1) = 4ρ²/((1 − ρ)²(1 + ρ)²), ρ the residuals' lag-1
    autocorrelation: residuals of smoothed records decorrelate over seconds, so the bandwidth follows
    the data rather than a fixed count of samples."""
    e = np.asarray(e, float)
    bounds = [0, e.size] if bounds is None else list(bounds)
    rho = _lag1(e, bounds)
    a1 = 4.0 * rho**2 / ((1.0 - rho)**2 * (1.0 + rho)**2)
    return int(min(e.size - 1, np.ceil(1.1447 * (a1 * e.size)**(1.0 / 3.0))))


def ols(A, y, terms, bounds=None, lags: int | str = 20) -> Fit:
    """OLS with Newey-West covariance (``lags`` samples, or "auto": :func:`andrews_lags`) and a BIC
    on the effective sample size.

    The effective sample size is n (1 − ρ₁)/(1 + ρ₁) with ρ₁ the lag-1 residual autocorrelation
    (Bartlett 1946's AR(1) approximation)."""
    A, y = np.asarray(A, float), np.asarray(y, float)
    n, p = A.shape
    if n <= p:
        raise InputError(_WHERE, "samples", f"{n} samples for {p} terms; allowed: more samples than terms")
    bounds = [0, n] if bounds is None else list(bounds)
    coef, *_ = np.linalg.lstsq(A, y, rcond=None)
    e = y - A @ coef
    if lags == "auto":
        lags = andrews_lags(e, bounds)
    elif not (isinstance(lags, int) and lags >= 0):
        raise InputError(_WHERE, "lags", f"{lags!r}; allowed: a whole number of samples ≥ 0 or 'auto'")
    AtA_inv = np.linalg.pinv(A.T @ A)
    cov = AtA_inv @ _hac(A, e, bounds, lags) @ AtA_inv * n / (n - p)
    rho = _lag1(e, bounds)
    n_eff = n * (1 - rho) / (1 + rho)
    rss = float(e @ e)
    bic = n_eff * np.log(rss / n) + p * np.log(n_eff)
    return Fit(tuple(terms), coef, cov, float(np.sqrt(rss / n)), n, n_eff, float(bic))


def forward_select(ship, segments, eq: str, candidates, required=(), lags: int | str = 20,
                   min_t: float | None = None, weighted: bool = False) -> Fit:
    """Forward stepwise selection: start from ``required`` terms, add the candidate that lowers the
    BIC most, stop when none does. With ``min_t``, a candidate is admitted only if every non-required
    term of the enlarged fit is significant, |coefficient| ≥ min_t σ under the HAC covariance
    (stepwise regression's entry test, Efroymson 1960, in Draper & Smith 1998, "Applied Regression
    Analysis", ch. 15): BIC alone keeps terms that fit the records' systematic errors, and cubic terms
    that trade off against each other (v'²r', v'r'², v'³, r'³ are nearly collinear when v' follows r')
    then extrapolate wildly beyond the maneuvers fitted."""
    chosen = [t for t in candidates if t in required]
    rest = [t for t in candidates if t not in required]
    A_all, y, bounds = design(ship, segments, eq, list(candidates), weighted)
    col = {t: i for i, t in enumerate(candidates)}

    # the models compared share one effective sample size, the whole candidate set's: with each model's
    # own n_eff the criterion n_eff log(RSS/n) rewards a LOWER n_eff when RSS/n > 1 (forces in newtons)
    # and a higher one when RSS/n < 1 (prime units), i.e. it would depend on the units
    n_ref = ols(A_all, y, list(candidates), bounds, lags).n_eff

    def fit(ts):
        f = ols(A_all[:, [col[t] for t in ts]], y, ts, bounds, lags)
        rss = f.rms**2 * f.n
        return dataclasses.replace(f, bic=float(n_ref * np.log(rss / f.n) + len(ts) * np.log(n_ref)))

    def admissible(f):
        return min_t is None or all(abs(c) >= min_t * sg for k, c, sg in zip(f.terms, f.coef, f.sigma())
                                    if k not in required)

    best = fit(chosen) if chosen else None
    while rest:
        trials = [(f, t) for f, t in ((fit(chosen + [t]), t) for t in rest) if admissible(f)]
        if not trials:
            break
        cand, t = min(trials, key=lambda ft: ft[0].bic)
        if best is not None and cand.bic >= best.bic:
            break
        best, chosen = cand, chosen + [t]
        rest.remove(t)
    return best


def identify(ship, segments, structure: str = "mmg", select: bool = True, lags: int | str = 20,
             min_t: float | None = None, weighted: bool = False) -> dict:
    """Fit the hull terms of ``structure`` (a key of the ship's structures, e.g. :data:`mmg.STRUCTURES`)
    to all segments.

    With ``select`` the terms are chosen by forward BIC selection (the ship's required terms — the
    linear derivatives, X_0 or the roll damping — always kept). Returns {eq: Fit}."""
    if structure not in ship.structures:
        raise InputError(_WHERE, "structure", f"{structure!r}; allowed: {', '.join(ship.structures)}")
    out = {}
    for eq, terms in ship.structures[structure].items():
        req = tuple(t for t in terms if t in ship.required)
        if select:
            out[eq] = forward_select(ship, segments, eq, terms, req, lags, min_t, weighted)
        else:
            A, y, bounds = design(ship, segments, eq, terms, weighted)
            out[eq] = ols(A, y, terms, bounds, lags)
    return out


def coefficients(fits: dict) -> dict:
    """Merge the per-equation fits into one {term: value} mapping."""
    return {k: v for f in fits.values() for k, v in f.as_dict().items()}


def cross_validate(ship, segments, structures=("mmg", "blanke"), select: bool = True,
                   lags: int | str = 20, min_t: float | None = None, weighted: bool = False) -> dict:
    """Leave-one-maneuver-out cross-validation of the hull-force prediction.

    For each structure: fit on all segments but one, predict the held-out segment's non-dimensional
    hull forces; returns {structure: {eq: RMS prediction error}} over all held-out samples."""
    if len(segments) < 2:
        raise InputError(_WHERE, "segments", f"{len(segments)}; allowed: ≥ 2 maneuvers for cross-validation")
    out = {}
    for s in structures:
        err = {eq: [] for eq in ship.structures[s]}
        for i in range(len(segments)):
            train = [g for j, g in enumerate(segments) if j != i]
            fits = identify(ship, train, s, select, lags, min_t, weighted)
            for eq, ft in fits.items():
                A, y, _ = design(ship, [segments[i]], eq, ft.terms, weighted)
                err[eq].append(y - A @ ft.coef)
        out[s] = {eq: float(np.sqrt(np.mean(np.concatenate(e)**2))) for eq, e in err.items()}
    return out
