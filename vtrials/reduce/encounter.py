"""Encounter-frequency transforms of wave spectra, with the following-seas ambiguity.

A ship at speed U [m/s] meets a deep-water wave component of frequency ω [rad/s] travelling at the
angle μ to the ship's heading (μ = 0 following seas, π head seas) at the encounter frequency

    ω_e = ω − k U cos μ = ω − a ω²,   a = U cos μ / g        (e.g. Lloyd 1989, "Seakeeping", §5.2)

and an instrument on the ship records the frequency |ω_e|. Energy is conserved between the two
frequency axes: S_e(ω_e) |dω_e| = S(ω) |dω| with the Jacobian dω_e/dω = 1 − 2 a ω.

* a ≤ 0 (head to beam seas): ω ↦ ω_e is monotonic, one ω per ω_e: ω = (−1 + √(1 + 4|a|ω_e))/(2|a|).
* a > 0 (following to beam seas): ω_e rises to its maximum 1/(4a) at ω* = 1/(2a) = g/(2 U cos μ)
  (the singular point, Jacobian 0: S_e has an integrable 1/√ singularity there), then falls through
  zero at ω = 1/a (waves overtaking at the ship's speed) and becomes negative. For |ω_e| < 1/(4a)
  three wave frequencies give the same |ω_e|: ω₁ = (1 − √(1 − 4aω_e))/(2a) < ω*, ω₂ = (1 +
  √(1 − 4aω_e))/(2a) ∈ (ω*, 1/a), and ω₃ = (1 + √(1 + 4aω_e))/(2a) > 1/a (ω_e < 0); above 1/(4a)
  only ω₃. S_e(|ω_e|) = Σ_j S(ω_j)/|1 − 2aω_j|.

The reverse transform is unique only for a ≤ 0. For a > 0 the energy at one |ω_e| must be shared
between its branches; :func:`wave_spectrum_from_encounter` shares it in proportion to a prior
spectrum shape (e.g. the wave radar's, or a fitted design spectrum) — exact when the prior has the
right shape — or, without a prior, gives it all to the first branch (ω < ω*), the usual assumption
(e.g. Nielsen 2017, Ocean Eng. 130:234) that is right when the waves are long compared with U.
"""

from __future__ import annotations

import math

import numpy as np

from vtrials.errors import InputError
from vtrials.units import G


def _a(U: float, mu: float) -> float:
    if not (math.isfinite(U) and U >= 0.0):
        raise InputError("record", "U", f"ship speed {U!r} m/s: must be a finite number ≥ 0")
    if not math.isfinite(mu):
        raise InputError("record", "mu", f"relative wave direction {mu!r} rad: must be finite")
    return U * math.cos(mu) / G


def encounter_frequency(omega, U: float, mu: float):
    """Signed ω_e = ω − ω² U cos μ/g [rad/s] (deep water) for wave frequency ω [rad/s], speed U [m/s], μ [rad]."""
    w = np.asarray(omega, dtype=float)
    return w - _a(U, mu) * w * w


def singular_frequency(U: float, mu: float) -> float:
    """ω* = g/(2 U cos μ) [rad/s] where dω_e/dω = 0 (following seas); inf when U cos μ ≤ 0."""
    a = _a(U, mu)
    return 1.0 / (2.0 * a) if a > 0.0 else math.inf


def wave_frequencies(omega_e, U: float, mu: float) -> np.ndarray:
    """The wave frequencies (…, 3) [rad/s] that an encounter frequency |ω_e| [rad/s] comes from; NaN where none.

    Column 0 the branch below ω*, 1 between ω* and 1/a, 2 above 1/a (module doc). Head seas (a < 0) and
    U = 0 fill column 0 only.
    """
    we = np.abs(np.asarray(omega_e, dtype=float))
    a = _a(U, mu)
    out = np.full(we.shape + (3,), np.nan)
    if a == 0.0:
        out[..., 0] = we
        return out
    if a < 0.0:
        out[..., 0] = (-1.0 + np.sqrt(1.0 - 4.0 * a * we)) / (-2.0 * a)
        return out
    disc = 1.0 - 4.0 * a * we
    ok = disc >= 0.0
    r = np.sqrt(np.where(ok, disc, 0.0))
    out[..., 0] = np.where(ok, (1.0 - r) / (2.0 * a), np.nan)
    out[..., 1] = np.where(ok & (we > 0.0), (1.0 + r) / (2.0 * a), np.nan)
    out[..., 2] = (1.0 + np.sqrt(1.0 + 4.0 * a * we)) / (2.0 * a)
    return out


def encounter_spectrum(S_of_omega, omega_e, U: float, mu: float, branches=(0, 1, 2)):
    """S_e(|ω_e|) = Σ_j S(ω_j)/|1 − 2aω_j| [unit² s/rad] for a callable wave spectrum S(ω) [unit² s/rad].

    ``branches`` selects which of the three wave-frequency branches contribute (all by default).
    Infinite at the singular point |ω_e| = 1/(4a) of following seas.
    """
    a = _a(U, mu)
    W = wave_frequencies(omega_e, U, mu)
    out = np.zeros(W.shape[:-1])
    for j in branches:
        w = W[..., j]
        ok = np.isfinite(w)
        if not np.any(ok):
            continue
        wj = np.where(ok, w, 1.0)
        with np.errstate(divide="ignore"):
            contrib = np.asarray(S_of_omega(wj), dtype=float) / np.abs(1.0 - 2.0 * a * wj)
        out = out + np.where(ok, contrib, 0.0)
    return out


def wave_spectrum_from_encounter(S_e_of_omega_e, omega, U: float, mu: float, prior=None):
    """S(ω) [unit² s/rad] on wave frequencies ω from an encounter spectrum S_e(|ω_e|) (a callable).

    S(ω) = S_e(|ω_e(ω)|) |1 − 2aω| p(ω), p the share of ω's branch in the energy at |ω_e|:
    p = 1 for a ≤ 0; for a > 0 with ``prior`` (a callable spectrum shape) p_j = q_j/Σ_k q_k, q = prior(ω_k)/
    |1 − 2aω_k| over the branches of |ω_e|; without a prior all energy goes to the branch below ω*.
    """
    w = np.asarray(omega, dtype=float)
    a = _a(U, mu)
    we = np.abs(w - a * w * w)
    J = np.abs(1.0 - 2.0 * a * w)
    Se = np.asarray(S_e_of_omega_e(we), dtype=float)
    if a <= 0.0:
        return Se * J
    if prior is None:
        return np.where(w < 1.0 / (2.0 * a), Se * J, 0.0)
    W = wave_frequencies(we, U, mu)
    q = np.zeros(W.shape)
    for j in range(3):
        ok = np.isfinite(W[..., j])
        wj = np.where(ok, W[..., j], 1.0)
        with np.errstate(divide="ignore"):
            q[..., j] = np.where(ok, np.asarray(prior(wj), dtype=float) / np.abs(1.0 - 2.0 * a * wj), 0.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        qw = np.asarray(prior(w), dtype=float) / J
        p = np.where(q.sum(axis=-1) > 0.0, qw / q.sum(axis=-1), 0.0)
    return Se * J * p
