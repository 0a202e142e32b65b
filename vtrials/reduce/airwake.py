"""Airwake without ship motion (AWSM): remove the ship's motion from ship-borne anemometer records.

After Arney et al., DSTO FFG-7 ship motion and airwake trial (seed 003 §4): only the FLUCTUATIONS of
the ship's velocity are removed, so that what remains is the air velocity relative to the ship's mean
motion — in still air a ship steaming at U still shows a wind over deck of U. Then the result is
rotated with roll and pitch into ship-carried vertical axes (origin and heading of the ship, z along
gravity), the frame of wind-tunnel data and of an airwake database.

Sign conventions (vtrials): body axes x forward, y starboard, z down; ship velocity V (body axes, at
the centre of motion, over the ground), rates ω = (p, q, r); an anemometer at body position ρ measures
the velocity of the air relative to the instrument, in body axes:

    m = W_b − (V + ω × ρ),      W_b = Aᵀ W (W the air velocity over the ground, NED)

AWSM adds back the instrument's motion except the ship's mean velocity:

    c = m + ΔV + ω × ρ,  ΔV = V − mean(V)   ⇒   c = W_b − mean(V)

component by component (each component may be measured at its own point, as on the seed's arrays):
u_c = u_m + ΔU + (qΔz − rΔy), v_c = v_m + ΔV + (rΔx − pΔz), w_c = w_m + ΔW + (pΔy − qΔx). The seed
prints u_c = u_m − ΔU + qΔz − rΔy …: the rotational terms agree with this, the translational ones carry
the opposite sign, which holds only if its anemometer reading and its ship velocity use opposite
senses; under one convention the instrument velocity V + ω × ρ enters as a whole, as above.

The seed's order (remove body-axis fluctuations, then rotate with the instantaneous roll and pitch)
leaves R(φ, θ) mean(V) − mean(R(φ, θ) V) in the result: the mean speed U projected by the pitch
oscillation (≈ U θ in the vertical component). :func:`wind_relative_to_mean_motion` rotates first and
removes the fluctuations in vertical axes, which does not have that term.
"""

from __future__ import annotations

import numpy as np

from vtrials.errors import InputError

_WHERE = "airwake"


def _series(name, a, n=None):
    a = np.asarray(a, float)
    if a.ndim != 2 or a.shape[1] != 3 or (n is not None and a.shape[0] != n):
        want = f"({n}, 3)" if n is not None else "(N, 3)"
        raise InputError(_WHERE, name, f"shape {a.shape}; allowed: {want}")
    if not np.all(np.isfinite(a)):
        raise InputError(_WHERE, name, "non-finite values; allowed: finite numbers")
    return a


def _angle(name, a, n):
    a = np.asarray(a, float)
    if a.shape != (n,) or not np.all(np.isfinite(a)):
        raise InputError(_WHERE, name, f"shape {a.shape}; allowed: ({n},) finite [rad]")
    return a


def _positions(position) -> np.ndarray:
    """(3, 3): row k is the point where velocity component k is measured."""
    p = np.asarray(position, float)
    if p.shape == (3,):
        p = np.tile(p, (3, 1))
    if p.shape != (3, 3) or not np.all(np.isfinite(p)):
        raise InputError(_WHERE, "position", f"value shape {p.shape}; allowed: (3,) one point, or (3, 3) "
                         "one point per velocity component [m, body axes from the centre of motion]")
    return p


def instrument_velocity(ship_velocity: np.ndarray, rates: np.ndarray, position) -> np.ndarray:
    """Velocity of the measuring point(s) over the ground in body axes, V + ω × ρ_k per component."""
    v = _series("ship_velocity", ship_velocity)
    w = _series("rates", rates, v.shape[0])
    p = _positions(position)
    rot = np.stack([np.cross(w, p[k])[:, k] for k in range(3)], axis=1)
    return v + rot


def rotation_roll_pitch(roll: np.ndarray, pitch: np.ndarray) -> np.ndarray:
    """R_y(θ) R_x(φ) (N, 3, 3): body → ship-carried vertical axes (x horizontal along the heading,
    z down along gravity)."""
    sf, cf, st, ct = np.sin(roll), np.cos(roll), np.sin(pitch), np.cos(pitch)
    z, o = np.zeros_like(sf), np.ones_like(sf)
    return np.stack([np.stack([ct, st * sf, st * cf], -1),
                     np.stack([z, cf, -sf], -1),
                     np.stack([-st, ct * sf, ct * cf], -1)], -2)


def to_vertical_axes(vector_body: np.ndarray, roll: np.ndarray, pitch: np.ndarray) -> np.ndarray:
    """Body-axis vectors (N, 3) → ship-carried vertical axes with roll and pitch [rad]."""
    v = _series("vector_body", vector_body)
    n = v.shape[0]
    return np.einsum("nij,nj->ni", rotation_roll_pitch(_angle("roll", roll, n), _angle("pitch", pitch, n)), v)


def awsm(measured: np.ndarray, ship_velocity: np.ndarray, rates: np.ndarray, position, roll: np.ndarray,
         pitch: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The seed's AWSM: c = m + ΔV + ω × ρ in body axes (ΔV about the record mean), then rotated with
    roll and pitch. Returns (body (N, 3), vertical axes (N, 3)) [m/s]. Inputs in SI, body axes."""
    m = _series("measured", measured)
    n = m.shape[0]
    v = _series("ship_velocity", ship_velocity, n)
    inst = instrument_velocity(v, rates, position)
    corrected = m + inst - np.mean(v, axis=0)
    return corrected, to_vertical_axes(corrected, roll, pitch)


def wind_relative_to_mean_motion(measured: np.ndarray, ship_velocity: np.ndarray, rates: np.ndarray,
                                 position, roll: np.ndarray, pitch: np.ndarray) -> np.ndarray:
    """Air velocity relative to the ship's mean motion in ship-carried vertical axes: the measurement
    plus the instrument velocity, rotated with roll and pitch, minus the record mean of the ship's
    velocity in the same axes: R(m + V + ω×ρ) − mean(R V) [m/s, (N, 3)]."""
    m = _series("measured", measured)
    n = m.shape[0]
    v = _series("ship_velocity", ship_velocity, n)
    rot = rotation_roll_pitch(_angle("roll", roll, n), _angle("pitch", pitch, n))
    air = np.einsum("nij,nj->ni", rot, m + instrument_velocity(v, rates, position))
    return air - np.mean(np.einsum("nij,nj->ni", rot, v), axis=0)


def true_wind(measured: np.ndarray, ship_velocity: np.ndarray, rates: np.ndarray, position, roll: np.ndarray,
              pitch: np.ndarray, heading: np.ndarray) -> np.ndarray:
    """Air velocity over the ground in earth axes (NED) [m/s]: A(φ, θ, ψ)(m + V + ω × ρ). The wind
    blows TOWARDS this vector; its 'from' direction is atan2(−E, −N)."""
    m = _series("measured", measured)
    n = m.shape[0]
    v = _series("ship_velocity", ship_velocity, n)
    psi = _angle("heading", heading, n)
    body = m + instrument_velocity(v, rates, position)
    sp, cp = np.sin(psi), np.cos(psi)
    z, o = np.zeros_like(sp), np.ones_like(sp)
    rz = np.stack([np.stack([cp, -sp, z], -1), np.stack([sp, cp, z], -1), np.stack([z, z, o], -1)], -2)
    return np.einsum("nij,nj->ni", rz, to_vertical_axes(body, roll, pitch))


def speed_and_from_direction(ned: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Horizontal speed [m/s] and the direction the wind comes FROM [rad, clockwise from north, 0–2π)
    of air velocities in NED (meteorological convention at the edges: convert with vtrials.units)."""
    a = _series("ned", ned)
    speed = np.hypot(a[:, 0], a[:, 1])
    return speed, np.mod(np.arctan2(-a[:, 1], -a[:, 0]), 2 * np.pi)
