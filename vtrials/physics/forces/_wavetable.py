"""Heading tables of the wave-force components: a wave component's heading relative to the ship,
folded onto the database's equally spaced headings 0…π, and linear interpolation between rows.

A component travelling towards μ (from north, clockwise) meets a ship heading ψ at β = μ − ψ in
(−π, π]; the database holds 0 ≤ β ≤ π and the mirror image gives β < 0 (sway, roll and yaw change
sign: the database convention of :mod:`vtrials.physics.seakeeping.database`). Used by
:mod:`vtrials.physics.forces.wave_excitation` and :mod:`vtrials.physics.forces.wave_drift`; and the
turn of a seakeeping-frame wrench into body axes (:func:`seakeeping_to_body`) that the excitation and
the radiation memory (:mod:`vtrials.physics.forces.radiation`) share.
"""

from __future__ import annotations

import math

import numba as nb

from vtrials.physics.forces import context as L


@nb.njit(cache=True, inline="always")
def heading_fold(cm, sm, cp, sp, dh, nbeta):
    """(i0, fr, sgn): β = μ − ψ from cos/sin of μ (cm, sm) and of ψ (cp, sp) — one atan2, no further
    trigonometry — folded to |β| ∈ [0, π] (sgn −1 when β < 0), and its place between rows i0 and
    i0 + 1 (fraction fr) of a table of nbeta headings dh apart starting at 0."""
    b = math.atan2(sm * cp - cm * sp, cm * cp + sm * sp)
    sgn = 1.0
    if b < 0.0:
        b = -b
        sgn = -1.0
    f = b / dh
    i0 = int(f)
    if i0 >= nbeta - 1:
        i0 = nbeta - 2
    return i0, f - i0, sgn


@nb.njit(cache=True, inline="always")
def ship_pose(ctx):
    """(x north, y east [m] of the origin, time [s], cos ψ, sin ψ) from the context: where and when a wave
    component's phase and relative heading are taken."""
    psi = ctx[L.EUL + 2]
    return ctx[L.POS], ctx[L.POS + 1], ctx[L.TIME], math.cos(psi), math.sin(psi)


@nb.njit(cache=True, inline="always")
def component_phase(p, q, x, y, t):
    """θ = ω t − k (x cos μ + y sin μ) + ε of the wave component whose [a, ω, k, cos μ, sin μ, ε] start at
    p[q] (:mod:`vtrials.physics.environment.waves`), at the ship's origin (x, y) at time t."""
    return p[q + 1] * t - p[q + 2] * (x * p[q + 3] + y * p[q + 4]) + p[q + 5]


@nb.njit(cache=True, inline="always")
def lerp(p, k0, k1, fr):
    """(1 − fr) p[k0] + fr p[k1]."""
    return (1.0 - fr) * p[k0] + fr * p[k1]


@nb.njit(cache=True, inline="always")
def seakeeping_to_body(w, ctx, cp, sp):
    """Turn the wrench ``w`` (forces 0–2, moments 3–5) from the seakeeping frame (x along the heading,
    horizontal; z down) into body axes in place: f_body = Rᵀ Rz(ψ) f, with cos/sin ψ (cp, sp) and the
    body-to-earth rotation R in ``ctx`` — so that a heeled or trimmed ship is not pushed sideways by a
    vertical load."""
    for o in (0, 3):
        fn = cp * w[o] - sp * w[o + 1]
        fe = sp * w[o] + cp * w[o + 1]
        fd = w[o + 2]
        for k in range(3):
            w[o + k] = ctx[L.ROT + k] * fn + ctx[L.ROT + 3 + k] * fe + ctx[L.ROT + 6 + k] * fd
