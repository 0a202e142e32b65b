"""The sea around the ship: current now; wind and waves have their places in the same block.

Current model (environment.md; ITTC 7.5-04-01-01.2 iterative method's current model):
V_C(x, y, t) = V₀ + V_C,C cos(2πt/T_C) + V_C,S sin(2πt/T_C) + V_C,T t + G·(p − p_ref),
a horizontal vector (north, east) with a semidiurnal period T_C = 12.42 h by default, a linear
trend in time and a linear gradient in space (2×2 matrix G, 1/s). Hydrodynamic forces use the
velocity through the water; positions integrate the velocity over ground.

The per-ship environment block ``env`` (float64) holds:
  0..1   V₀ (north, east) [m/s]
  2..3   V_C,C, 4..5 V_C,S [m/s]
  6      T_C [s]
  7..8   V_C,T [m/s²]
  9..12  G row-major [1/s]
  13..14 p_ref (north, east) [m]
  15     water depth [m]
  16..31 reserved for wind, 32..63 reserved for waves (header)
"""

from __future__ import annotations

import dataclasses
import math

import numba as nb
import numpy as np

from vtrials.schema import num
from vtrials.units import DEG, KNOT

NENV = 64
E_DEPTH = 15
TIDAL_PERIOD_S = 12.42 * 3600.0  # principal lunar semidiurnal M2 period


@dataclasses.dataclass(frozen=True)
class Current:
    """A current as a scenario states it (knots and degrees at the edge; converted by :func:`pack`).

    Directions are the direction the water flows TOWARDS, from north, clockwise.
    """

    speed_kn: float = num("steady current speed", "kn", 0.0, 10.0, default=0.0)
    direction_deg: float = num("direction the steady current flows to (from north, clockwise)", "deg",
                               -360.0, 360.0, default=0.0)
    tidal_amplitude_kn: float = num("amplitude of the tidal (semidiurnal) part", "kn", 0.0, 10.0, default=0.0)
    tidal_direction_deg: float = num("axis of the tidal stream (flood direction)", "deg", -360.0, 360.0,
                                     default=0.0)
    tidal_phase_deg: float = num("tidal phase at t = 0 (0: maximum flood)", "deg", -360.0, 360.0, default=0.0)
    tidal_period_h: float = num("tidal period T_C", "h", 0.5, 48.0, default=12.42)
    trend_kn_per_h: float = num("linear change of current speed per hour", "kn/h", -5.0, 5.0, default=0.0)
    trend_direction_deg: float = num("direction of the trend vector", "deg", -360.0, 360.0, default=0.0)
    gradient_kn_per_nmi: float = num("change of the current (along its direction) per nautical mile "
                                     "travelled along gradient_axis_deg", "kn/nmi", -5.0, 5.0, default=0.0)
    gradient_axis_deg: float = num("axis along which the current changes", "deg", -360.0, 360.0, default=0.0)
    reference_north_m: float = num("north coordinate where the gradient term is zero", "m", default=0.0)
    reference_east_m: float = num("east coordinate where the gradient term is zero", "m", default=0.0)


def _unit(deg: float) -> np.ndarray:
    a = deg * DEG
    return np.array([math.cos(a), math.sin(a)])


def pack(current: Current, depth_m: float) -> np.ndarray:
    """Environment block for the kernel (SI)."""
    env = np.zeros(NENV)
    env[0:2] = current.speed_kn * KNOT * _unit(current.direction_deg)
    tide = current.tidal_amplitude_kn * KNOT * _unit(current.tidal_direction_deg)
    ph = current.tidal_phase_deg * DEG
    env[2:4] = tide * math.cos(ph)
    env[4:6] = -tide * math.sin(ph)
    env[6] = current.tidal_period_h * 3600.0
    env[7:9] = current.trend_kn_per_h * KNOT / 3600.0 * _unit(current.trend_direction_deg)
    # the current's own direction: that of the steady part, or of the tide when there is none
    flow_dir = current.direction_deg if current.speed_kn > 0 or current.tidal_amplitude_kn == 0 \
        else current.tidal_direction_deg
    gmag = current.gradient_kn_per_nmi * KNOT / 1852.0  # 1/s
    env[9:13] = (gmag * np.outer(_unit(flow_dir), _unit(current.gradient_axis_deg))).ravel()
    env[13] = current.reference_north_m
    env[14] = current.reference_east_m
    env[E_DEPTH] = depth_m
    return env


@nb.njit(cache=True)
def current_at(env, x, y, t):
    """Current (north, east) [m/s] and its partial time derivative at (x, y, t)."""
    w = 2.0 * math.pi / env[6]
    c = math.cos(w * t)
    s = math.sin(w * t)
    dx = x - env[13]
    dy = y - env[14]
    vn = env[0] + env[2] * c + env[4] * s + env[7] * t + env[9] * dx + env[10] * dy
    ve = env[1] + env[3] * c + env[5] * s + env[8] * t + env[11] * dx + env[12] * dy
    an = -env[2] * w * s + env[4] * w * c + env[7]
    ae = -env[3] * w * s + env[5] * w * c + env[8]
    return vn, ve, an, ae


def current_numpy(env: np.ndarray, x, y, t):
    """Vectorized numpy twin of :func:`current_at` for truth post-processing (arrays in/out)."""
    w = 2.0 * math.pi / env[6]
    c = np.cos(w * t)
    s = np.sin(w * t)
    dx = x - env[13]
    dy = y - env[14]
    vn = env[0] + env[2] * c + env[4] * s + env[7] * t + env[9] * dx + env[10] * dy
    ve = env[1] + env[3] * c + env[5] * s + env[8] * t + env[11] * dx + env[12] * dy
    return vn, ve
