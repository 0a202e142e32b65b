"""First-order wave excitation from a ship's BEM database, summed over the components of a seaway.

For wave component j (amplitude a_j, frequency ω_j, wavenumber k_j, direction of travel μ_j from
north clockwise, phase ε_j; :mod:`vtrials.physics.environment.waves`) the force on the ship is
(database convention, :mod:`vtrials.physics.seakeeping.database`)

    F(t) = Σ_j a_j Re{X(ω_j, β_j) e^{iθ_j}},   θ_j = ω_j t − k_j (x cos μ_j + y sin μ_j) + ε_j,

with (x north, y east) the ship's origin where it is now (its displaced position: the encounter
frequency comes out of the motion) and β_j = μ_j − ψ the heading of the component relative to the
ship at this step (ψ the ship's heading). The sums are in the seakeeping frame (x along the heading,
horizontal; z down) and turned into body axes with the ship's roll and pitch. X over the database's headings is tabulated per component at
its own frequency when the block is packed; the kernel interpolates linearly in β (mirror image
X(−β) = S X(β), S = diag(1, −1, 1, −1, 1, −1) for β < 0). Body axes at the origin; the zero-speed
excitation at the wave frequency (see :mod:`vtrials.physics.seakeeping.rao` for what that neglects).

Parameter block: [n, nβ, mask(6), headings(nβ), then per component a, ω, k, cos μ, sin μ, ε and the
table Re X, Im X (nβ × 6 each)]. ``mask`` selects the DOFs that receive the force (1/0).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from vtrials.errors import InputError
from vtrials.physics.forces._wavetable import component_phase, heading_fold, lerp, seakeeping_to_body, ship_pose
from vtrials.physics.forces.registry import register

HEAD = 8


def pack(db, components: np.ndarray, dofs=(0, 1, 2, 3, 4, 5)) -> np.ndarray:
    """Parameter block for database ``db`` and wave components (n, 6) [a, ω, k, cos μ, sin μ, ε]."""
    comp = np.asarray(components, dtype=np.float64)
    if comp.ndim != 2 or comp.shape[1] != 6 or not np.all(np.isfinite(comp)):
        raise InputError("waves", "components", f"must be a finite (n, 6) array, got shape {comp.shape}")
    h = np.asarray(db.headings, dtype=float)
    if h.size < 2 or abs(h[0]) > 1e-9 or abs(h[-1] - math.pi) > 1e-9 or np.ptp(np.diff(h)) > 1e-9:
        raise InputError(db.attrs.get("_path", "database"), "heading",
                         "wave_excitation needs equally spaced headings from 0 to pi")
    if comp.size and (comp[:, 1].min() < db.omega[0] * 0.5 or comp[:, 1].max() > db.omega[-1]):
        raise InputError("waves", "omega", f"components span {comp[:, 1].min():.3g}–{comp[:, 1].max():.3g} "
                         f"rad/s; the database covers {db.omega[0]:.3g}–{db.omega[-1]:.3g} rad/s")
    nb_ = h.size
    mask = np.zeros(6)
    mask[list(dofs)] = 1.0
    # X of every component at its frequency, (n, heading, dof): one interpolation per heading and DOF
    w = comp[:, 1]
    Xr = np.empty((comp.shape[0], nb_, 6))
    Xi = np.empty((comp.shape[0], nb_, 6))
    for ib in range(nb_):
        for j in range(6):
            Xr[:, ib, j] = np.interp(w, db.omega, db.X[:, ib, j].real)
            Xi[:, ib, j] = np.interp(w, db.omega, db.X[:, ib, j].imag)
    rows = np.concatenate([comp, Xr.reshape(comp.shape[0], 6 * nb_), Xi.reshape(comp.shape[0], 6 * nb_)], axis=1)
    return np.concatenate([np.array([comp.shape[0], nb_], dtype=np.float64), mask, h, rows.ravel()])


@nb.njit(cache=True, inline="always")
def _dof(p, r0, r1, di, fr, ct, st):
    """Re{X e^{iθ}} a for one DOF: X interpolated between heading rows r0, r1 (Im X di further)."""
    xr = lerp(p, r0, r1, fr)
    xi = lerp(p, r0 + di, r1 + di, fr)
    return xr * ct - xi * st


@nb.njit(cache=True, fastmath=False)
def excitation_kernel(p, s, env, ctx, aux, w):
    n = int(p[0])
    nbeta = int(p[1])
    h0 = 2 + 6
    dh = p[h0 + 1] - p[h0]
    base = h0 + nbeta
    stride = 6 + 12 * nbeta
    x, y, t, cp, sp = ship_pose(ctx)
    # the six sums in registers (w is written once): the same additions in the same order
    f0 = f1 = f2 = f3 = f4 = f5 = 0.0
    for c in range(n):
        q = base + c * stride
        a = p[q]
        cm = p[q + 3]
        sm = p[q + 4]
        th = component_phase(p, q, x, y, t)
        ct = a * math.cos(th)
        st = a * math.sin(th)
        i0, fr, sgn = heading_fold(cm, sm, cp, sp, dh, nbeta)   # β = μ − ψ, folded
        r0 = q + 6 + 6 * i0      # Re X at heading row i0; row i0 + 1 is 6 further; Im X is 6 nβ further
        r1 = r0 + 6
        di = 6 * nbeta
        f0 += _dof(p, r0, r1, di, fr, ct, st)
        f2 += _dof(p, r0 + 2, r1 + 2, di, fr, ct, st)
        f4 += _dof(p, r0 + 4, r1 + 4, di, fr, ct, st)
        if sgn < 0.0:   # mirror image: sway, roll and yaw change sign
            f1 += -1.0 * _dof(p, r0 + 1, r1 + 1, di, fr, ct, st)
            f3 += -1.0 * _dof(p, r0 + 3, r1 + 3, di, fr, ct, st)
            f5 += -1.0 * _dof(p, r0 + 5, r1 + 5, di, fr, ct, st)
        else:
            f1 += 1.0 * _dof(p, r0 + 1, r1 + 1, di, fr, ct, st)
            f3 += 1.0 * _dof(p, r0 + 3, r1 + 3, di, fr, ct, st)
            f5 += 1.0 * _dof(p, r0 + 5, r1 + 5, di, fr, ct, st)
    w[0] = f0
    w[1] = f1
    w[2] = f2
    w[3] = f3
    w[4] = f4
    w[5] = f5
    for d in range(6):
        w[d] *= p[2 + d]
    # the sums are in the seakeeping frame (x along the heading, horizontal; z down): to body axes
    seakeeping_to_body(w, ctx, cp, sp)


WAVE_EXCITATION_COMPONENT = register("wave_excitation", excitation_kernel)
