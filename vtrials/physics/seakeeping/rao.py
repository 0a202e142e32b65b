"""Frequency-domain response amplitude operators (RAOs) from a ship's zero-speed BEM database.

For a regular wave of amplitude a, frequency ω and heading β (relative to the ship, the database's
convention: β = π head seas) met by the ship at forward speed U, the ship meets the crests at the
encounter frequency (deep water, e.g. Faltinsen 1990, Sea Loads on Ships and Offshore Structures §3)

    ω_e = ω − ω² U cos β / g,

and the linear response ξ(t) = Re{a ξ̂ e^{iω_e t}} solves (Newman 1977, Marine Hydrodynamics §6.15)

    (−ω_e² (M + A(|ω_e|)) + iω_e (B(|ω_e|) + B_visc) + C) ξ̂ = X(ω, β),

with the phase referred to a crest at the ship's origin O at t = 0. The sign of the damping term
follows the database's e^{+iωt} convention (F = Re{X a e^{iωt}}); texts that write −iωB use e^{−iωt}.

Approximation stated: the database is for zero speed. A and B are evaluated at the encounter
frequency (interpolated; outside the database's range extended as in :mod:`.radiation`); the
excitation X is the zero-speed one at the wave frequency ω (the incident wave's wavenumber is set by
ω, its rate at the ship by ω_e). No forward-speed corrections to A, B or X (e.g. Salvesen–Tuck–
Faltinsen 1970 speed terms) are applied, in the frequency domain nor in the time domain, so the two
remain comparable; their size at Froude numbers above ≈ 0.2 is not assessed here.

Only the DOFs listed in ``dofs`` move; the others are held (e.g. heave, roll, pitch = (2, 3, 4): the
horizontal motions are left to the maneuvering model). The simulated ship's sway and yaw are free under
its maneuvering model: the reference for its roll in beam and oblique seas is
:func:`vtrials.physics.seakeeping.linearize.coupled_rao`, not this held-DOF RAO.
"""

from __future__ import annotations

import math

import numpy as np

from vtrials.errors import InputError
from vtrials.physics.seakeeping.radiation import extended_coefficients


def encounter_frequency(omega, beta, U: float, g: float = 9.80665) -> np.ndarray:
    """ω_e = ω − ω² U cos β / g [rad/s] (deep water). omega [rad/s], beta [rad] (π: head seas), U [m/s]."""
    omega = np.asarray(omega, dtype=float)
    return omega - omega ** 2 * U * np.cos(beta) / g


def rao(db, omega, beta: float, U: float = 0.0, dofs=(2, 3, 4), M=None, C=None, B_visc=None,
        body_axes_added_mass: bool = False) -> np.ndarray:
    """Complex RAO ξ̂ (nω, 6) per metre of wave amplitude [m/m, rad/m] (zeros in the held DOFs).

    db: :class:`.database.HydroDatabase`; omega (nω,) wave frequencies [rad/s]; beta [rad]; U [m/s];
    M (6, 6) rigid-body mass matrix about O (default: the database's), C (6, 6) restoring (default:
    the database's), B_visc (6, 6) linear viscous damping [N s/m, N m s/rad] (default none).
    ``body_axes_added_mass``: add the speed term of the time-domain model, whose infinite-frequency
    added mass multiplies body-axis accelerations: the body heave velocity is w = ż + Uθ, so
    A∞_i3 ẇ = A∞_i3 (z̈ + U θ̇), i.e. Z_i5 += iω_e U A∞_i3 (the A∞ part of Salvesen, Tuck & Faltinsen's
    1970 speed coupling B35 = B35⁰ + U A33). Off (default): the plain zero-speed RAO.
    Raises InputError when an encounter frequency is zero (no linear steady state).
    """
    omega = np.atleast_1d(np.asarray(omega, dtype=float))
    if not np.all(np.isfinite(omega)) or np.any(omega <= 0.0):
        raise InputError("rao", "omega", f"must be positive finite frequencies [rad/s], got {omega!r}")
    if not math.isfinite(U):
        raise InputError("rao", "U", f"must be a finite speed [m/s], got {U!r}")
    idx = np.array(sorted({int(d) for d in dofs}))
    if idx.size == 0 or idx.min() < 0 or idx.max() > 5:
        raise InputError("rao", "dofs", f"must be DOF indices 0..5, got {dofs!r}")
    M = db.mass_matrix if M is None else np.asarray(M, dtype=float)
    C = db.C if C is None else np.asarray(C, dtype=float)
    Bv = np.zeros((6, 6)) if B_visc is None else np.asarray(B_visc, dtype=float)
    we = encounter_frequency(omega, beta, U, db.g)
    if np.any(np.abs(we) < 1e-9):
        raise InputError("rao", "omega", f"encounter frequency is zero at ω = {omega[np.abs(we) < 1e-9]} "
                         f"rad/s for U = {U} m/s, β = {beta} rad: no linear steady response")
    A, B = extended_coefficients(db.omega, db.A, db.B, db.A_inf, np.abs(we))
    X = db.excitation(beta)
    Xw = np.empty((omega.size, 6), dtype=complex)
    for j in range(6):
        Xw[:, j] = (np.interp(omega, db.omega, X[:, j].real)
                    + 1j * np.interp(omega, db.omega, X[:, j].imag))
    out = np.zeros((omega.size, 6), dtype=complex)
    sub = np.ix_(idx, idx)
    for n in range(omega.size):
        Z = -we[n] ** 2 * (M + A[n]) + 1j * we[n] * (B[n] + Bv) + C
        if body_axes_added_mass:
            Z[:, 4] += 1j * we[n] * U * db.A_inf[:, 2]
        out[n, idx] = np.linalg.solve(Z[sub], Xw[n, idx])
    return out


def effective_inertia(K: np.ndarray) -> float:
    """Inertia felt by the first DOF of the inertia block ``K`` (that DOF, then DOFs free to follow it
    without restoring): the Schur complement K₀₀ − K₀ᵣ K_rr⁻¹ K_r0 (K₀₀ when K is 1 × 1)."""
    K = np.atleast_2d(np.asarray(K, dtype=float))
    if K.shape[0] == 1:
        return float(K[0, 0])
    return float(K[0, 0] - K[0, 1:] @ np.linalg.solve(K[1:, 1:], K[1:, 0]))


def natural_frequency(db, dof: int, M=None, C=None, iters: int = 50, free=()) -> float:
    """Undamped natural frequency [rad/s] of one DOF: ω_n = sqrt(C_ii / I_eff(ω_n)) (fixed-point
    iteration on A(ω); e.g. Faltinsen 1990 §3). I_eff = M_ii + A_ii(ω) with the other DOFs held; with
    ``free`` DOFs (no restoring, free to move with it: e.g. sway (1,) for roll) the Schur complement of
    the inertia K = M + A(ω) over (dof, free): K_dd − K_df K_ff⁻¹ K_fd, the inertia a ship free to sway
    feels in roll (its sway–roll inertia coupling m z_G + A24 makes it sway as it rolls)."""
    M = db.mass_matrix if M is None else np.asarray(M, dtype=float)
    C = db.C if C is None else np.asarray(C, dtype=float)
    if not C[dof, dof] > 0.0:
        raise InputError("rao", "dof", f"DOF {dof} has no restoring (C_ii = {C[dof, dof]})")
    free = [int(f) for f in free]
    idx = [dof] + free

    def inertia(w):
        A = np.empty((len(idx), len(idx)))
        for a_, i in enumerate(idx):
            for b_, j in enumerate(idx):
                if w is None:
                    A[a_, b_] = db.A_inf[i, j]
                else:
                    A[a_, b_] = extended_coefficients(db.omega, db.A[:, i, j], db.B[:, i, j], db.A_inf[i, j],
                                                      np.array([w]))[0][0]
        return effective_inertia(M[np.ix_(idx, idx)] + A)

    w = math.sqrt(C[dof, dof] / inertia(None))
    for _ in range(iters):
        w_new = math.sqrt(C[dof, dof] / inertia(w))
        if abs(w_new - w) < 1e-12 * w:
            return w_new
        w = w_new
    return w
