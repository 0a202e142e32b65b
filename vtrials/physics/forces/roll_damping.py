"""Viscous roll damping: Ikeda's component method, as a force component.

Potential flow (the radiation memory) gives only the wave part of roll damping; the viscous parts are
added here, by Ikeda's component-discrete method (Ikeda, Himeno & Tanaka 1978, "Components of roll
damping of ship at forward speed", J. SNAJ 143; summarised in Himeno 1981, "Prediction of ship roll
damping — state of the art", Univ. Michigan NAME report 239, and ITTC 7.5-02-07-04.5, 2011) in the
simplified form of Kawahara, Maekawa & Ikeda (2009/2011, "A simple prediction formula of roll damping
of conventional cargo ships on the basis of Ikeda's method and its limitation", Contemporary Ideas on
Ship Stability and Capsizing in Waves, Springer, pp. 465–486):

* friction (Kato 1958 laminar flat-plate law on the hull's wetted surface, Kawahara eq.):
  B_F0 = (4/3π) ρ S_f r_f³ φ_a ω C_f,  C_f = 1.328 (3.22 r_f² φ_a² / (T ν))^−½, T = 2π/ω,
  S_f = L (1.75 d + C_B B), r_f = d [(0.887 + 0.145 C_B)(1.7 + C_B B/d) − 2 OG/d] / π;
  this is 0.787 ρ S_f r_f² √(ω ν) (Ikeda's form): linear damping, independent of φ_a.
  Speed: B_F = B_F0 (1 + 4.1 U / (ω L)) (Ikeda, Himeno & Tanaka 1978);
* eddy making (Kawahara's regression of Ikeda's sectional method):
  B̂_E = 4 ω̂ φ_a C_R / (3π C_B (B/d)³), i.e. B_E = (4/3π) ρ L d⁴ ω φ_a C_R — the harmonic
  equivalent of a quadratic damping B_2E |φ̇| φ̇ with B_2E = ½ ρ L d⁴ C_R. Speed: × (0.04K)²/(1 +
  (0.04K)²), K = ω L / U (Ikeda, Himeno & Tanaka 1978);
* hull lift (Ikeda, Himeno & Tanaka 1978): B_L = ½ ρ L d U k_N l_O l_R (1 − 1.4 OG/l_R +
  0.7 OG²/(l_O l_R)), l_O = 0.3 d, l_R = 0.5 d, k_N = 2π d/L + κ (4.1 B/L − 0.045), κ = 0, 0.1,
  0.3 for C_M ≤ 0.92, ≤ 0.97, ≤ 0.99;
* bilge keels (normal force + hull pressure, Kawahara's regression of Ikeda's method):
  B̂_BK = A_BK(φ_a) exp(BBK1 + BBK2 C_M^BBK3) ω̂; speed-independent (Ikeda: the normal-force
  part hardly changes with speed).

Non-dimensional B̂ = B / (ρ ∇ B²) √(B / 2g), ω̂ = ω √(B / 2g); OG is the depth of the roll axis (G)
below the still-water level (positive down, Kawahara's convention). The wave part is NOT here: it is
the radiation memory's (nothing counted twice). Kawahara's formulas hold for C_B 0.5–0.85, B/d 2.5–4.5,
OG/d −1.5–0.2, C_M 0.9–0.99, b_BK/B 0.01–0.06, l_BK/L 0.05–0.4, ω̂ ≤ 1; :func:`check_range` refuses a
ship outside (patrol51's C_B 0.35, C_M 0.57 are outside: see :func:`from_hull_model`).

The component: K = −(B₁(u) p + B₂(u) |p| p), p the roll rate relative to the water, with the
frequency-dependent parts frozen at the ship's natural roll frequency ω_n (the roll response is
narrow-banded there) and the speed dependence kept live (u the relative surge speed):
B₁(u) = B_F0 (1 + 4.1 |u|/(ω_n L)) + b_L |u| + B_1BK,  B₂(u) = B_2E (0.04 ω_n L)² / (u² + (0.04 ω_n L)²) + B_2BK,
where the bilge-keel part is fitted as B_1BK + (8/3π) ω φ_a B_2BK to Kawahara's formula over
φ_a = 1–20° (least squares). Equivalent linearisation for the frequency domain: harmonic
B_eq = B₁ + (8/3π) ω φ_a B₂ (amplitude φ_a), stochastic B_eq = B₁ + √(8/π) σ_φ̇ B₂ (Gaussian roll
rate of standard deviation σ_φ̇; Roberts & Spanos 1990, Random Vibration and Statistical Linearization).
"""

from __future__ import annotations

import dataclasses
import math

import numba as nb
import numpy as np

from vtrials.errors import InputError
from vtrials.physics.forces import context as L
from vtrials.physics.forces.registry import register
from vtrials.schema import num, read_table, text

G = 9.80665

#: Kawahara et al. (2009) range of validity (their Table 1)
KAWAHARA_RANGE = {"C_B": (0.5, 0.85), "B/d": (2.5, 4.5), "OG/d": (-1.5, 0.2), "C_M": (0.9, 0.99),
                  "b_BK/B": (0.01, 0.06), "l_BK/L": (0.05, 0.4), "omega_hat": (0.0, 1.0)}


@dataclasses.dataclass(frozen=True, kw_only=True)
class RollDampingTable:
    """The ``[roll_damping]`` table of a model's ``hydro/hull.toml`` (every number with its source)."""

    method: str = text("viscous roll damping: 'ikeda' (Kawahara et al. 2009 simplified Ikeda) or "
                       "'hull_model' (the maneuvering hull model's own roll damping less the wave part)",
                       ("ikeda", "hull_model"))
    bilge_keel_length: float = num("total length of one bilge keel (0: none)", "m", 0.0, 500.0, default=0.0)
    bilge_keel_breadth: float = num("bilge keel breadth (depth normal to the hull; 0: none)", "m", 0.0, 10.0, default=0.0)
    kinematic_viscosity: float = num("kinematic viscosity of the water", "m^2/s", 1e-7, 1e-5, default=1.19e-6)


@dataclasses.dataclass(frozen=True)
class RollHull:
    """What Ikeda's method needs (SI): L, B, d [m], C_B, C_M, OG (depth of G below the waterline,
    positive down) [m], bilge keel length and breadth [m], ρ [kg/m³], ν [m²/s]."""

    L: float
    B: float
    d: float
    C_B: float
    C_M: float
    OG: float
    l_BK: float = 0.0
    b_BK: float = 0.0
    rho: float = 1025.0
    nu: float = 1.19e-6

    @property
    def volume(self) -> float:
        return self.C_B * self.L * self.B * self.d


def _bscale(h: RollHull) -> float:
    """B44 = B̂ · ρ ∇ B² / √(B/2g) [N m s per unit B̂]."""
    return h.rho * h.volume * h.B ** 2 / math.sqrt(h.B / (2.0 * G))


def check_range(h: RollHull, omega: float, where: str = "roll_damping") -> None:
    """InputError naming the parameter when the ship is outside Kawahara et al.'s range of validity."""
    vals = {"C_B": h.C_B, "B/d": h.B / h.d, "OG/d": h.OG / h.d, "C_M": min(h.C_M, 0.99),
            "omega_hat": omega * math.sqrt(h.B / (2.0 * G))}
    if h.l_BK > 0.0:
        vals["b_BK/B"] = h.b_BK / h.B
        vals["l_BK/L"] = h.l_BK / h.L
    for k, v in vals.items():
        lo, hi = KAWAHARA_RANGE[k]
        if not lo - 1e-9 <= v <= hi + 1e-9:
            raise InputError(where, k, f"{v:.4g} is outside the range of Kawahara et al.'s (2009) simplified "
                                       f"Ikeda formulas [{lo}, {hi}]; use method = 'hull_model' or measured damping")


def friction(h: RollHull, omega, U=0.0):
    """Frictional roll damping B_F [N m s] (Kato / Ikeda; Kawahara's form), linear, φ_a-independent."""
    omega = np.asarray(omega, dtype=float)
    rf = h.d * ((0.887 + 0.145 * h.C_B) * (1.7 + h.C_B * h.B / h.d) - 2.0 * h.OG / h.d) / math.pi
    Sf = h.L * (1.75 * h.d + h.C_B * h.B)
    phi = math.radians(10.0)            # cancels: C_f ∝ 1/φ_a
    T = 2.0 * math.pi / omega
    Cf = 1.328 * (3.22 * rf ** 2 * phi ** 2 / (T * h.nu)) ** -0.5
    BF0 = 4.0 / (3.0 * math.pi) * h.rho * Sf * rf ** 3 * phi * omega * Cf
    return BF0 * (1.0 + 4.1 * np.abs(U) / (omega * h.L))


def eddy_CR(h: RollHull, C_M=None) -> float:
    """Kawahara et al.'s regression of Ikeda's eddy-making pressure coefficient C_R (dimensionless)."""
    cb, bd, ogd = h.C_B, h.B / h.d, h.OG / h.d
    cm = min(h.C_M, 0.99) if C_M is None else C_M
    fe1 = (-0.0182 * cb + 0.0155) * (bd - 1.8) ** 3
    fe2 = -79.414 * cb ** 4 + 215.695 * cb ** 3 - 215.883 * cb ** 2 + 93.894 * cb - 14.848
    be1 = ((3.98 * cb - 5.1525) * (-0.2 * bd + 1.6) * ogd
           * ((0.9717 * cb ** 2 - 1.55 * cb + 0.723) * ogd + 0.04567 * cb + 0.9408))
    be2 = (0.25 * ogd + 0.95) * ogd - 219.2 * cb ** 3 + 443.7 * cb ** 2 - 283.3 * cb + 59.6
    be3 = -15.0 * cb * bd + 46.5 * cb + 11.2 * bd - 28.6
    return (fe1 + fe2) * math.exp(be1 + be2 * cm ** be3)


def eddy(h: RollHull, omega, phi_a, U=0.0):
    """Eddy-making roll damping B_E [N m s] (harmonic equivalent linear) at amplitude φ_a [rad]."""
    omega = np.asarray(omega, dtype=float)
    BE0 = 4.0 / (3.0 * math.pi) * h.rho * h.L * h.d ** 4 * omega * np.asarray(phi_a) * eddy_CR(h)
    k04 = 0.04 * omega * h.L
    return BE0 * k04 ** 2 / (np.asarray(U, dtype=float) ** 2 + k04 ** 2)


def lift(h: RollHull, U):
    """Hull-lift roll damping B_L [N m s] at speed U [m/s] (Ikeda, Himeno & Tanaka 1978)."""
    cm = h.C_M
    kappa = 0.0 if cm <= 0.92 else (0.1 if cm <= 0.97 else 0.3)
    kN = 2.0 * math.pi * h.d / h.L + kappa * (4.1 * h.B / h.L - 0.045)
    lo, lr = 0.3 * h.d, 0.5 * h.d
    return (0.5 * h.rho * h.L * h.d * np.abs(U) * kN * lo * lr
            * (1.0 - 1.4 * h.OG / lr + 0.7 * h.OG ** 2 / (lo * lr)))


def bilge_keel(h: RollHull, omega, phi_a):
    """Bilge-keel roll damping B_BK [N m s] (normal force + hull pressure; harmonic equivalent linear)
    at amplitude φ_a [rad], Kawahara et al.'s regression of Ikeda's method. Zero without bilge keels."""
    omega = np.asarray(omega, dtype=float)
    if h.l_BK <= 0.0 or h.b_BK <= 0.0:
        return np.zeros(np.broadcast(omega, np.asarray(phi_a)).shape)
    cb, bd, ogd, cm = h.C_B, h.B / h.d, h.OG / h.d, min(h.C_M, 0.99)
    lbkl, bbkb = h.l_BK / h.L, h.b_BK / h.B
    ph = np.degrees(np.asarray(phi_a, dtype=float))
    fbk1 = (-0.3651 * cb + 0.3907) * (bd - 2.83) ** 2 - 2.21 * cb + 2.632
    fbk2 = 0.00255 * ph ** 2 + 0.122 * ph + 0.4794
    fbk3 = ((-0.8913 * bbkb ** 2 - 0.0733 * bbkb) * lbkl ** 2
            + (5.2857 * bbkb ** 2 - 0.01185 * bbkb + 0.00189) * lbkl)
    bbk1 = (5.0 * bbkb + 0.3 * bd - 0.2 * lbkl + 0.00125 * ph ** 2 - 0.0425 * ph - 1.86) * ogd
    bbk2 = -15.0 * bbkb + 1.2 * cb - 0.1 * bd - 0.0657 * ogd ** 2 + 0.0586 * ogd + 1.6164
    bbk3 = 2.5 * ogd + 15.75
    bhat = fbk1 * fbk2 * fbk3 * np.exp(bbk1 + bbk2 * cm ** bbk3) * omega * math.sqrt(h.B / (2.0 * G))
    return bhat * _bscale(h)


@dataclasses.dataclass(frozen=True)
class RollDamping:
    """Linear + quadratic viscous roll damping, K = −(B₁(u) p + B₂(u) |p| p):
    B₁(u) = b1_0 + b1_u |u| [N m s], B₂(u) = b2_E k2 / (u² + k2) + b2_0 [N m s²] (k2 = (0.04 ω_n L)²
    is Ikeda's eddy speed reduction; k2 = 0: none). ``parts``: the components at zero speed [N m s or
    N m s²] for the record; ``omega_n``: the frequency the coefficients were taken at [rad/s]."""

    omega_n: float
    b1_0: float
    b1_u: float
    b2_E: float
    k2: float
    b2_0: float
    source: str = ""
    parts: tuple = ()

    def B1(self, U) -> np.ndarray:
        return self.b1_0 + self.b1_u * np.abs(np.asarray(U, dtype=float))

    def B2(self, U) -> np.ndarray:
        U = np.asarray(U, dtype=float)
        if self.k2 <= 0.0:
            return self.b2_E + self.b2_0 + 0.0 * U
        return self.b2_E * self.k2 / (U ** 2 + self.k2) + self.b2_0

    def harmonic(self, U, omega, phi_a) -> np.ndarray:
        """Equivalent linear B_eq = B₁ + (8/3π) ω φ_a B₂ [N m s] for roll φ_a sin ωt (equal energy per cycle)."""
        return self.B1(U) + 8.0 / (3.0 * math.pi) * np.asarray(omega) * np.asarray(phi_a) * self.B2(U)

    def stochastic(self, U, sigma_p) -> np.ndarray:
        """Equivalent linear B_eq = B₁ + √(8/π) σ_p B₂ [N m s] for a Gaussian roll rate of std σ_p [rad/s]."""
        return self.B1(U) + math.sqrt(8.0 / math.pi) * np.asarray(sigma_p) * self.B2(U)


def ikeda(h: RollHull, omega_n: float, check: bool = True, where: str = "roll_damping") -> RollDamping:
    """The component's coefficients by Ikeda's method at the natural roll frequency ω_n [rad/s]."""
    if check:
        check_range(h, omega_n, where)
    bF0 = float(friction(h, omega_n, 0.0))
    bL = float(lift(h, 1.0))
    b2E = 0.5 * h.rho * h.L * h.d ** 4 * eddy_CR(h)
    b1, b2 = 0.0, 0.0
    if h.l_BK > 0.0 and h.b_BK > 0.0:
        ph = np.radians(np.linspace(1.0, 20.0, 39))
        y = bilge_keel(h, omega_n, ph)
        X = np.stack([np.ones_like(ph), 8.0 / (3.0 * math.pi) * omega_n * ph], axis=1)
        b1, b2 = (float(c) for c in np.linalg.lstsq(X, y, rcond=None)[0])
    parts = (("friction B_F0", bF0), ("lift per m/s", bL), ("eddy quadratic B_2E", b2E),
             ("bilge keel linear", b1), ("bilge keel quadratic", b2))
    return RollDamping(omega_n, bF0 + b1, 4.1 * bF0 / (omega_n * h.L) + bL, b2E, (0.04 * omega_n * h.L) ** 2, b2,
                       "Ikeda (Kawahara et al. 2009 simplified; lift and speed terms Ikeda, Himeno & Tanaka 1978)",
                       parts)


def pack(rd: RollDamping) -> np.ndarray:
    """Parameter block [b1_0, b1_u, b2_E, k2, b2_0]."""
    return np.array([rd.b1_0, rd.b1_u, rd.b2_E, rd.k2, rd.b2_0], dtype=np.float64)


@nb.njit(cache=True, fastmath=False)
def roll_damping_kernel(p, s, env, ctx, aux, w):
    u = abs(ctx[L.NU_R + 0])
    pr = ctx[L.NU_R + 3]
    b1 = p[0] + p[1] * u
    if p[3] > 0.0:
        b2 = p[2] * p[3] / (u * u + p[3]) + p[4]
    else:
        b2 = p[2] + p[4]
    w[0] = 0.0
    w[1] = 0.0
    w[2] = 0.0
    w[3] = -(b1 * pr + b2 * abs(pr) * pr)
    w[4] = 0.0
    w[5] = 0.0


ROLL_DAMPING_COMPONENT = register("roll_damping", roll_damping_kernel)


def read_roll_damping_table(hull_toml) -> RollDampingTable:
    """The ``[roll_damping]`` table of ``hydro/hull.toml`` (InputError naming the file and field)."""
    from vtrials.schema import load_toml
    doc = load_toml(hull_toml)
    if "roll_damping" not in doc:
        raise InputError(str(hull_toml), "roll_damping", "missing table (method, bilge keels, viscosity)")
    tab, _ = read_table(RollDampingTable, doc["roll_damping"], str(hull_toml), "roll_damping", sourced=True)
    return tab


__all__ = ["RollHull", "RollDamping", "RollDampingTable", "friction", "eddy", "eddy_CR", "lift", "bilge_keel",
           "ikeda", "pack", "check_range", "read_roll_damping_table", "KAWAHARA_RANGE"]
