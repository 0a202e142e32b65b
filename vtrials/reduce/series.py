"""Small helpers every reduction of a recorded time series needs (records only, SI units)."""

from __future__ import annotations

import math

import numpy as np


def clean_series(t, *ys):
    """Time-ordered samples with non-finite values and repeated time stamps dropped.

    ``t`` [s] and any number of channels of the same length; returns (t, *channels) as float arrays.
    """
    t = np.asarray(t, float).ravel()
    arrs = [np.asarray(y, float).ravel() for y in ys]
    ok = np.isfinite(t)
    for a in arrs:
        if a.shape != t.shape:
            raise ValueError("channel and time arrays differ in length")
        ok &= np.isfinite(a)
    order = np.argsort(t[ok], kind="stable")
    t = t[ok][order]
    arrs = [a[ok][order] for a in arrs]
    keep = np.concatenate([[True], np.diff(t) > 0])
    return (t[keep], *[a[keep] for a in arrs])


def noise_sigma(t, y, chunk: int = 12) -> float:
    """White-noise σ of a smooth channel from pooled residuals of cubic fits to consecutive chunks of
    ``chunk`` samples (chunks with variance > 10× the median left out as wild points)."""
    t, y = clean_series(t, y)
    n = len(t)
    if n < 6:
        return float("nan")
    var, dof = [], []
    i0 = 0
    while i0 < n - 5:
        i1 = n if n - (i0 + chunk) < 6 else i0 + chunk
        tt = t[i0:i1]
        x = (tt - tt.mean()) / max(np.ptp(tt), 1e-9)
        A = np.vander(x, 4)
        coef, *_ = np.linalg.lstsq(A, y[i0:i1], rcond=None)
        r = y[i0:i1] - A @ coef
        var.append(float(r @ r) / (len(tt) - 4))
        dof.append(len(tt) - 4)
        i0 = i1
    var, dof = np.array(var), np.array(dof)
    med = np.median(var)
    keep = var <= 10 * med if med > 0 else np.ones(var.shape, bool)
    return math.sqrt(float(np.sum(var[keep] * dof[keep]) / np.sum(dof[keep])))


def ar1_inflation(resid) -> float:
    """√((1+ρ)/(1−ρ)) for a positive lag-1 autocorrelation ρ of the residuals (1 otherwise): the
    factor by which an OLS standard error understates the truth for AR(1) errors (ρ capped at 0.95)."""
    r = np.asarray(resid, float)
    if len(r) < 8:
        return 1.0
    r = r - r.mean()
    den = float(r @ r)
    if den <= 0:
        return 1.0
    rho = min(max(float(r[1:] @ r[:-1]) / den, 0.0), 0.95)
    return math.sqrt((1 + rho) / (1 - rho))


def correlated_variance(t, w, components, phase=None) -> float:
    """Variance of the linear combination Σ w_i e_i of errors e_i at times ``t`` [s] that are
    correlated in time: ``components`` (sd, τ) pairs of exponentially correlated (Gauss–Markov)
    errors, cov(e_i, e_j) = Σ sd² exp(−|t_i − t_j|/τ). With ``phase`` [rad] the e_i are the
    projections of an isotropic horizontal error (each axis so correlated, axes independent) on the
    unit vectors of direction phase_i, which multiplies the covariance by cos(phase_i − phase_j)
    (e.g. the radial components of a tracking error around a circle)."""
    t = np.asarray(t, float)
    w = np.asarray(w, float)
    comps = [(float(sd), float(tau)) for sd, tau in components if sd > 0.0 and tau > 0.0]
    if t.size == 0 or not comps:
        return 0.0
    dt = np.abs(t[:, None] - t[None, :])
    C = sum(sd ** 2 * np.exp(-dt / tau) for sd, tau in comps)
    if phase is not None:
        ph = np.asarray(phase, float)
        C = C * np.cos(ph[:, None] - ph[None, :])
    return float(w @ C @ w)


def slope_variance(t, components) -> float:
    """Variance [(unit/s)²] of a least-squares slope over the samples at ``t`` [s] from errors that are
    correlated in time: ``components`` (sd, τ) pairs of exponentially correlated (Gauss–Markov)
    errors, cov(e_i, e_j) = Σ sd² exp(−|t_i − t_j|/τ). Var(b) = wᵀ C w with the OLS weights
    w_i = (t_i − t̄)/Σ(t − t̄)². A slowly wandering error (τ much longer than the window) moves the
    slope by about sd·√(2/(τT)), which residual-based standard errors do not see."""
    t = np.asarray(t, float)
    if t.size < 2 or not components:
        return 0.0
    x = t - t.mean()
    sxx = float(x @ x)
    if sxx <= 0.0:
        return math.inf
    w = x / sxx
    dt = np.abs(t[:, None] - t[None, :])
    C = sum(float(sd) ** 2 * np.exp(-dt / float(tau)) for sd, tau in components if sd > 0.0 and tau > 0.0)
    return float(w @ C @ w) if not np.isscalar(C) else 0.0
