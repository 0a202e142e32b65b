"""Unit conversions used at the edges (scenario files, reports). Everything inside is SI."""

from __future__ import annotations

import math

G = 9.80665  # standard gravity [m/s^2] (CGPM 1901), used everywhere in vtrials
KNOT = 1852.0 / 3600.0  # [m/s] per knot (exact by definition)
DEG = math.pi / 180.0  # [rad] per degree
RPM = 1.0 / 60.0  # [rev/s] per r/min


def kn_to_mps(v_kn: float) -> float:
    """Knots → m/s."""
    return v_kn * KNOT


def mps_to_kn(v: float) -> float:
    """m/s → knots."""
    return v / KNOT


def deg(x_rad):
    """Radians → degrees (scalar or array)."""
    return x_rad / DEG


def rad(x_deg):
    """Degrees → radians (scalar or array)."""
    return x_deg * DEG


def froude_to_speed(fn: float, length_m: float) -> float:
    """Length Froude number → speed [m/s]: U = Fn √(g L)."""
    return fn * math.sqrt(G * length_m)


def speed_to_froude(u: float, length_m: float) -> float:
    """Speed [m/s] → length Froude number."""
    return u / math.sqrt(G * length_m)
