"""The waves' flow past the hull as the maneuvering forces see it: cross-flow, its gradient along the ship
and the slope of the water surface, averaged over the hull.

Why: the maneuvering model's hull forces (lift on a drift angle Y_v v, K_v v, N_v v, …; yaw-rate terms;
BC93's heel-at-speed terms), the rudder's inflow and the propeller's oblique inflow are forces of the
ship's motion *relative to the water*. In waves the water moves: a ship that sways with the orbital
motion of a long wave has no cross-flow, and one that heels with the surface slope is not heeled
relative to it. Applied to the absolute sway velocity and heel instead, the lift terms act on the
wave-frequency motion the potential-flow excitation already accounts for: measured on patrol51
(:func:`vtrials.physics.seakeeping.linearize.coupled_rao`), at 9 m/s in long beam waves (0.15–0.3
rad/s) the ship heeled 3.0–3.6 × the wave slope (1.08 × at rest) and its bow-sea roll was about twice
a lift-free model's. So the maneuvering kernels subtract what this component writes to ``aux``:

    v_w  = Σ_j a_j ω_j e^{−k_j d} sin β_j S(z_j) cos θ_j                    [m/s]   (aux[AUX_FLOW])
    r_w  = Σ_j a_j ω_j e^{−k_j d} sin β_j κ_j F(z_j) sin θ_j                [1/s]   (aux[AUX_FLOW + 1])
    φ_w  = −Σ_j a_j k_j sin β_j S(z_j) sin θ_j                              [rad]   (aux[AUX_FLOW + 2])

with θ_j the component's phase at the ship's origin (as in :mod:`.wave_excitation`), β_j = μ_j − ψ its
direction relative to the heading, κ_j = k_j cos β_j, z_j = κ_j L/2, S(z) = sin z / z and
F(z) = 3 (sin z − z cos z)/z³. v_w is the lateral orbital velocity (deep water, Airy) at depth d
averaged over the length L; r_w the slope along x of its least-squares straight line over the length
(the "yaw rate" of the flow: a cross-flow v_w + x r_w); φ_w minus the lateral surface slope averaged
over the length (a ship lying in the surface has φ = φ_w; φ positive starboard down). d is half the
draught (the centre of the lateral area of a wall-sided hull). Horizontal flow in the seakeeping
frame, taken as body-y (the roll projection, second order, is neglected); the surge orbital velocity is
not passed on (resistance and propeller advance see the mean flow).

Parameter block: [n, L, d, then per component a, ω, k, cos μ, sin μ, ε]. The component's wrench is zero;
it must come before the maneuvering components (:func:`vtrials.physics.seakeeping.timedomain.seakeeping_vessel`
puts it first).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from vtrials.errors import InputError
from vtrials.physics.forces import context as L
from vtrials.physics.forces._wavetable import component_phase, ship_pose
from vtrials.physics.forces.registry import register

HEAD = 3


def pack(components: np.ndarray, length: float, depth: float) -> np.ndarray:
    """Parameter block for wave components (n, 6) [a, ω, k, cos μ, sin μ, ε], hull length [m] and the
    depth [m] at which the orbital velocity is taken."""
    comp = np.asarray(components, dtype=np.float64)
    if comp.ndim != 2 or comp.shape[1] != 6 or not np.all(np.isfinite(comp)):
        raise InputError("waves", "components", f"must be a finite (n, 6) array, got shape {comp.shape}")
    if not (math.isfinite(length) and length > 0.0 and math.isfinite(depth) and depth >= 0.0):
        raise InputError("wave_flow", "length/depth", f"{length!r} m, {depth!r} m: need length > 0 and depth ≥ 0")
    return np.concatenate([np.array([comp.shape[0], length, depth], dtype=np.float64), comp.ravel()])


def _shape(z):
    """(S(z), F(z)) of the module doc, with their series near z = 0."""
    z = np.asarray(z, dtype=float)
    small = np.abs(z) < 1e-4
    zs = np.where(small, 1.0, z)
    S = np.where(small, 1.0 - z * z / 6.0, np.sin(zs) / zs)
    F = np.where(small, 1.0 - z * z / 10.0, 3.0 * (np.sin(zs) - zs * np.cos(zs)) / zs ** 3)
    return S, F


def flow_rao(omega, beta: float, length: float, depth: float, g: float = 9.80665) -> np.ndarray:
    """Complex amplitudes (3, nω) of (v_w [m/s], r_w [1/s], φ_w [rad]) per metre of wave amplitude, for
    waves of frequency ω [rad/s] travelling at β [rad] relative to the heading (module doc), in the
    phase convention of the wave excitation (x(t) = Re{x̂ a e^{iθ}}, θ the phase at the origin)."""
    w = np.atleast_1d(np.asarray(omega, dtype=float))
    k = w * w / g
    sb = math.sin(beta)
    kap = k * math.cos(beta)
    S, F = _shape(0.5 * kap * length)
    att = np.exp(-k * depth)
    return np.array([w * att * sb * S, -1j * w * att * sb * kap * F, 1j * k * sb * S])


@nb.njit(cache=True, fastmath=False)
def flow_kernel(p, s, env, ctx, aux, w):
    n = int(p[0])
    half = 0.5 * p[1]
    d = p[2]
    x, y, t, cp, sp = ship_pose(ctx)
    vw = 0.0
    rw = 0.0
    fw = 0.0
    for c in range(n):
        q = HEAD + 6 * c
        a = p[q]
        om = p[q + 1]
        k = p[q + 2]
        cm = p[q + 3]
        sm = p[q + 4]
        th = component_phase(p, q, x, y, t)
        sb = sm * cp - cm * sp           # sin β, β = μ − ψ
        kap = k * (cm * cp + sm * sp)    # k cos β
        z = kap * half
        if abs(z) < 1e-4:
            S = 1.0 - z * z / 6.0
            F = 1.0 - z * z / 10.0
        else:
            S = math.sin(z) / z
            F = 3.0 * (math.sin(z) - z * math.cos(z)) / (z * z * z)
        ct = math.cos(th)
        st = math.sin(th)
        orb = a * om * math.exp(-k * d) * sb
        vw += orb * S * ct
        rw += orb * kap * F * st
        fw -= a * k * sb * S * st
    aux[L.AUX_FLOW] = vw
    aux[L.AUX_FLOW + 1] = rw
    aux[L.AUX_FLOW + 2] = fw
    for j in range(6):
        w[j] = 0.0


WAVE_FLOW_COMPONENT = register("wave_flow", flow_kernel)
