"""Radiation memory force: the state-space approximation of the Cummins convolution.

μ = C_r x with ẋ = A_r x + B_r ξ̇ (:mod:`vtrials.physics.seakeeping.radiation`), advanced by the
exact zero-order hold x⁺ = Φ x + Γ ξ̇ over the simulator's step (Φ, Γ packed for that step). The
velocity the kernel sees at t_n is the semi-implicit Euler step's secant, the mean velocity over
[t_{n-1}, t_n], i.e. the zero-order-hold input of the step just completed: the state is advanced over
that step first and the force is taken from the state at t_n. (Taking the force before the advance
delayed the memory by a whole step: heave and pitch at 2 rad/s led the RAO by 3.4° at dt 0.02 s, and the
response depended on dt; tests/test_seakeeping_sim.py checks the convergence.) The force is −μ, in the seakeeping frame (x along the heading, horizontal; z down), turned into body axes with
the ship's roll and pitch. Input ξ̇: the perturbation velocities of the seakeeping DOFs in that frame
(heave: the vertical velocity of the origin; roll, pitch: the body rates p, q, equal to first order),
zero mean about the maneuvering motion, so the memory adds no steady force to the maneuvering model
(and K̂(0) = 0 besides). Using the body heave velocity w instead would add −Uθ at forward speed, a
speed coupling the zero-speed RAO does not have. The A∞ part of
the radiation force is in the added-mass matrix of the dynamics' exact solve, not here.

Parameter block: [n_states, n_dofs, dofs(n_dofs), Φ (n×n), Γ (n × n_dofs), C (n_dofs × n), h, n_blocks,
block starts (n_blocks + 1)]: Φ is block-diagonal (one block per fitted DOF pair) and only its blocks are
multiplied, so a step costs Σ order² rather than n²; states: x (n),
then scratch: n for the new x and n_dofs for the inputs (held as component states: no allocation per step).
A simulator whose step is not h gets a non-finite force (and stops with a status) rather than a wrong memory.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from vtrials.physics.forces import context as L
from vtrials.physics.forces._wavetable import seakeeping_to_body
from vtrials.physics.forces.registry import register


def pack(model, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """(parameter block, initial states) for :class:`RadiationModel` ``model`` and step ``dt`` [s]."""
    Phi, Gam = model.discretize(dt)
    dofs = np.array(model.dofs)
    n = model.n_states
    starts = [k for k, _m in model.blocks()] + [n]
    p = np.concatenate([[n, dofs.size], dofs.astype(float), Phi.ravel(), Gam[:, dofs].ravel(),
                        model.C[dofs].ravel(), [dt, len(starts) - 1], starts])
    return p.astype(np.float64), np.zeros(2 * n + dofs.size)   # x, then scratch (no allocation per step)


@nb.njit(cache=True, fastmath=False)
def radiation_kernel(p, s, env, ctx, aux, w):
    n = int(p[0])
    m = int(p[1])
    o_phi = 2 + m
    o_gam = o_phi + n * n
    o_c = o_gam + n * m
    if abs(ctx[L.DT] - p[o_c + m * n]) > 1e-9 * p[o_c + m * n]:
        # discretised for another step: fail loudly (the simulator stops on a non-finite force)
        for j in range(6):
            w[j] = math.nan
        return
    # inputs: seakeeping-frame perturbation velocities: heave = vertical (down) velocity of the origin,
    # roll and pitch rates (body rates, equal to first order); surge/sway/yaw if listed: body values
    u = s[2 * n:2 * n + m]
    for r in range(m):
        d = int(p[2 + r])
        if d == 2:
            u[r] = ctx[L.ROT + 6] * ctx[L.NU] + ctx[L.ROT + 7] * ctx[L.NU + 1] + ctx[L.ROT + 8] * ctx[L.NU + 2]
        else:
            u[r] = ctx[L.NU_R + d]
    # advance: x⁺ = Φ x + Γ u (u held over the step), through the scratch part of the states
    tmp = s[n:2 * n]
    o_blk = o_c + m * n + 1
    for b in range(int(p[o_blk])):
        k0 = int(p[o_blk + 1 + b])
        k1 = int(p[o_blk + 2 + b])
        for k in range(k0, k1):
            acc = 0.0
            for l in range(k0, k1):
                acc += p[o_phi + k * n + l] * s[l]
            for r in range(m):
                acc += p[o_gam + k * m + r] * u[r]
            tmp[k] = acc
    for k in range(n):
        s[k] = tmp[k]
    # the force from the state at the step's end time t_n
    for j in range(6):
        w[j] = 0.0
    for r in range(m):
        acc = 0.0
        for k in range(n):
            acc += p[o_c + r * n + k] * s[k]
        w[int(p[2 + r])] = -acc
    # seakeeping frame (x along the heading, horizontal; z down) → body axes: f_body = Rᵀ Rz(ψ) f
    psi = ctx[L.EUL + 2]
    seakeeping_to_body(w, ctx, math.cos(psi), math.sin(psi))


RADIATION_COMPONENT = register("radiation", radiation_kernel)
