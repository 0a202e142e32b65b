"""Mean second-order wave drift force (surge, sway, yaw) from a ship's BEM database.

For the components j of a seaway, F̄ = Σ_j a_j² D(ω_j, β_j) (the mean of the difference-frequency
force at zero difference, Newman 1974, "Second-order, slowly-varying forces on vessels in irregular
waves"; slow-drift oscillations are not modelled), D the database's far-field drift per unit amplitude
squared (:mod:`vtrials.physics.seakeeping.database`: surge [N/m²], sway [N/m²], yaw [N m/m²]), with
β_j = μ_j − ψ the component's heading relative to the ship at this step (linear interpolation over
the database headings, mirror image for β < 0: sway and yaw change sign). Zero-speed drift: at forward
speed this is the database's value, not an added-resistance method (the forward-speed SNNM method is
:mod:`vtrials.physics.forces.added_resistance`; :mod:`vtrials.physics.seakeeping.sea_ship` chooses). The force is horizontal (seakeeping frame) and turned into body axes.

Parameter block: [n, nβ, headings(nβ), then per component a², cos μ, sin μ and the table (nβ × 3)
of D at the component's frequency].
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from vtrials.errors import InputError
from vtrials.physics.forces import context as L
from vtrials.physics.forces._wavetable import heading_fold, lerp, ship_pose
from vtrials.physics.forces.registry import register


def pack(db, components: np.ndarray, dofs=(0, 1, 2)) -> np.ndarray:
    """Parameter block for database ``db`` (with drift) and wave components (n, 6). ``dofs``: which
    of surge (0), sway (1), yaw (2) the drift acts in (the others are zeroed in the table; e.g. (1, 2)
    when another method gives the surge force, :mod:`vtrials.physics.seakeeping.sea_ship`)."""
    if db.drift is None:
        raise InputError(db.attrs.get("_path", "database"), "mean_drift_force", "not in this database")
    comp = np.asarray(components, dtype=np.float64)
    if comp.ndim != 2 or comp.shape[1] != 6 or not np.all(np.isfinite(comp)):
        raise InputError("waves", "components", f"must be a finite (n, 6) array, got shape {comp.shape}")
    h = np.asarray(db.headings, dtype=float)
    if h.size < 2 or abs(h[0]) > 1e-9 or abs(h[-1] - math.pi) > 1e-9 or np.ptp(np.diff(h)) > 1e-9:
        raise InputError(db.attrs.get("_path", "database"), "heading",
                         "wave_drift needs equally spaced headings from 0 to pi")
    keep = np.zeros(3)
    for d in dofs:
        if d not in (0, 1, 2):
            raise InputError("wave_drift", "dofs", f"expected drift DOFs among 0 (surge), 1 (sway), 2 (yaw), got {dofs!r}")
        keep[d] = 1.0
    out = [np.array([comp.shape[0], h.size]), h]
    for a, w, _k, cm, sm, _eps in comp:
        D = np.array([[np.interp(w, db.omega, db.drift[:, ib, j]) for j in range(3)] for ib in range(h.size)]) * keep
        out += [np.array([a * a, cm, sm]), D.ravel()]
    return np.concatenate(out).astype(np.float64)


@nb.njit(cache=True, fastmath=False)
def drift_kernel(p, s, env, ctx, aux, w):
    n = int(p[0])
    nbeta = int(p[1])
    dh = p[3] - p[2]
    base = 2 + nbeta
    stride = 3 + 3 * nbeta
    _, _, _, cp, sp = ship_pose(ctx)
    fx = 0.0
    fy = 0.0
    mz = 0.0
    for c in range(n):
        q = base + c * stride
        a2 = p[q]
        cm = p[q + 1]
        sm = p[q + 2]
        i0, fr, sgn = heading_fold(cm, sm, cp, sp, dh, nbeta)     # β = μ − ψ, folded
        t0 = q + 3 + 3 * i0
        t1 = t0 + 3
        fx += a2 * lerp(p, t0, t1, fr)
        fy += sgn * a2 * lerp(p, t0 + 1, t1 + 1, fr)
        mz += sgn * a2 * lerp(p, t0 + 2, t1 + 2, fr)
    fn = cp * fx - sp * fy
    fe = sp * fx + cp * fy
    for k in range(3):
        w[k] = ctx[L.ROT + k] * fn + ctx[L.ROT + 3 + k] * fe
        w[3 + k] = ctx[L.ROT + 6 + k] * mz
    # (a yaw moment about the vertical, turned into body axes)


WAVE_DRIFT_COMPONENT = register("wave_drift", drift_kernel)
