"""The trials team's own 3-DOF maneuvering model: MMG hull, propeller and rudder forces.

This is the model the identification fits; it shares no code with the simulator. Equations:
Yasukawa, H. & Yoshimura, Y. (2015) "Introduction of MMG standard method for ship maneuvering
predictions", J. Mar. Sci. Technol. 20:37-52 (below "Y&Y"), eqs. (4)-(10) and (35)-(46).

Axes: midship origin, x forward, y starboard; ``u`` surge, ``v`` sway at midship, ``r`` yaw rate
(SI). Hull forces are non-dimensional polynomials in v' = v/U and r' = r L/U:
X_H = ½ρLdU² X'_H, Y_H = ½ρLdU² Y'_H, N_H = ½ρL²dU² N'_H.

A hull *term* is named ``<eq>_<factors>``: ``X_0`` is the constant (−R'_0), ``Y_vvr`` is v'² r'
(Y&Y eq. 10), ``Y_v|r|`` is v'|r'| (second-order modulus model, Blanke 1981, Norrbin 1970).
"""

from __future__ import annotations

import dataclasses
import math
from types import MappingProxyType

import numpy as np

from vtrials.errors import InputError

_WHERE = "vtrials.sysid.mmg"

#: Model structures: the candidate terms of each equation.
STRUCTURES = MappingProxyType({
    # Y&Y (2015) eq. (10)
    "mmg": MappingProxyType({
        "X": ("X_0", "X_vv", "X_vr", "X_rr", "X_vvvv"),
        "Y": ("Y_v", "Y_r", "Y_vvv", "Y_vvr", "Y_vrr", "Y_rrr"),
        "N": ("N_v", "N_r", "N_vvv", "N_vvr", "N_vrr", "N_rrr"),
    }),
    # Abkowitz (1964)-style third-order Taylor expansion in (v', r'), keeping the even terms that
    # port/starboard symmetry allows in X and the odd terms in Y, N; it adds X_vvrr-type and
    # fourth-order cross terms that MMG drops (superset of "mmg" for X).
    "abkowitz": MappingProxyType({
        "X": ("X_0", "X_vv", "X_vr", "X_rr", "X_vvvv", "X_vvvr", "X_vvrr", "X_rrrr"),
        "Y": ("Y_v", "Y_r", "Y_vvv", "Y_vvr", "Y_vrr", "Y_rrr"),
        "N": ("N_v", "N_r", "N_vvv", "N_vvr", "N_vrr", "N_rrr"),
    }),
    # second-order modulus model (Norrbin 1970; Blanke 1981; ships.md §2 patrol vessel)
    "blanke": MappingProxyType({
        "X": ("X_0", "X_vv", "X_vr", "X_rr"),
        "Y": ("Y_v", "Y_r", "Y_v|v|", "Y_v|r|", "Y_r|v|", "Y_r|r|"),
        "N": ("N_v", "N_r", "N_v|v|", "N_v|r|", "N_r|v|", "N_r|r|"),
    }),
})

#: The linear (stability) derivatives the acceptance criteria name.
LINEAR = ("Y_v", "Y_r", "N_v", "N_r")


@dataclasses.dataclass(frozen=True)
class Ship:
    """Mass, added mass, propeller and rudder of the team's MMG model (SI; primes: Y&Y non-dim.).

    These are the parts assumed KNOWN in the identification (from model tests, drawings and open-water
    curves); only the hull coefficients are estimated.
    """

    L: float            # length between perpendiculars, m
    d: float            # draught, m
    m: float            # mass, kg
    x_G: float          # centre of gravity forward of midship, m
    I_zG: float         # yaw moment of inertia about G, kg m^2
    rho: float          # water density, kg/m^3
    mx: float           # added masses m'_x, m'_y, J'_z (Y&Y eq. 4 non-dimensionalisation)
    my: float
    Jz: float
    D_P: float          # propeller diameter, m
    t_P: float          # thrust deduction
    w_P0: float         # wake fraction straight ahead
    x_P: float          # x'_P, propeller position / L
    k0: float           # K_T(J) = k0 + k1 J + k2 J^2
    k1: float
    k2: float
    C1: float           # wake change in maneuvering, Y&Y eq. (36)
    C2_pos: float
    C2_neg: float
    H_R: float          # rudder span, m
    A_R: float          # rudder area, m^2
    t_R: float
    a_H: float
    x_H: float          # x'_H
    gammaR_neg: float   # flow straightening gamma_R for beta_R < 0 / > 0
    gammaR_pos: float
    l_R: float          # l'_R
    eps: float
    kappa: float
    f_alpha: float      # rudder lift gradient
    x_R: float = -0.5   # x'_R
    rudder_rate: float = 0.0   # steering gear's rated speed, rad/s (0: unknown; predictions need it)

    structures = STRUCTURES
    linear = LINEAR
    required = LINEAR + ("X_0",)
    prime = True   # coefficients non-dimensional (Y&Y 2015 prime system)
    state_names = ("x", "y", "psi", "u", "v", "r")

    # -- the identification's interface (shared with vtrials.sysid.blanke.Ship4) ----------------------
    def hull_samples(self, seg) -> dict:
        """Non-dimensional hull forces X'_H, Y'_H, N'_H: inverse dynamics less the known propeller and
        rudder (Y&Y eq. 4)."""
        X, Y, N = inertial_forces(self, seg.u, seg.v, seg.r, seg.udot, seg.vdot, seg.rdot)
        Xpr, Ypr, Npr = propeller_rudder_forces(self, seg.u, seg.v, seg.r, seg.delta, seg.n)
        q = 0.5 * self.rho * self.L * self.d * (seg.u**2 + seg.v**2)
        return {"X": (X - Xpr) / q, "Y": (Y - Ypr) / q, "N": (N - Npr) / (q * self.L)}

    def regressors(self, terms, seg) -> np.ndarray:
        return regressors(terms, seg.u, seg.v, seg.r, self.L)

    def row_weights(self, seg) -> np.ndarray:
        """U²: acceleration errors are about constant in newtons, in prime units they grow as 1/U²."""
        return seg.u**2 + seg.v**2

    def initial_state(self, speed: float) -> np.ndarray:
        return np.array([0.0, 0.0, 0.0, speed, 0.0, 0.0])

    def rates(self, coeffs: dict, y, delta: float, n: float, pitch: float = math.nan) -> np.ndarray:
        """Time derivative of (x, y, ψ, u, v, r) under the given rudder and shaft rate (Y&Y eq. 4)."""
        _, _, psi, u, v, r = y
        XH, YH, NH = hull_forces(self, coeffs, u, v, r)
        Xp, Yp, Np = propeller_rudder_forces(self, u, v, r, delta, n)
        ud, vd, rd = accelerations(self, XH + Xp, YH + Yp, NH + Np, u, v, r)
        c, s = math.cos(psi), math.sin(psi)
        return np.array([u * c - v * s, u * s + v * c, r, float(ud), float(vd), float(rd)])

    def masses(self) -> tuple[float, float, float, float]:
        """(m + m_x, m + m_y, x_G m, I_zG + x_G² m + J_z) in kg and kg m² (Y&Y eq. 4)."""
        s = 0.5 * self.rho * self.L**2 * self.d
        return (self.m + self.mx * s, self.m + self.my * s, self.x_G * self.m,
                self.I_zG + self.x_G**2 * self.m + self.Jz * s * self.L**2)


def kvlcc2_l7() -> Ship:
    """KVLCC2 at model scale L7 (1/45.714). Source: Y&Y (2015) Tables 1-3, as tabulated in
    docs/ships.md §1 (project reference set; x'_P −0.48, k2 −0.1385); rudder rate 15.8°/s at model
    scale (SIMMAN 2008, ships.md §1)."""
    rho, L = 1000.0, 7.00
    m = rho * 3.27
    return Ship(L=L, d=0.46, m=m, x_G=0.25, I_zG=m * (0.25 * L)**2, rho=rho,
                mx=0.022, my=0.223, Jz=0.011, D_P=0.216, t_P=0.220, w_P0=0.40, x_P=-0.48,
                k0=0.2931, k1=-0.2753, k2=-0.1385, C1=2.0, C2_pos=1.6, C2_neg=1.1, H_R=0.345,
                A_R=0.0539, t_R=0.387, a_H=0.312, x_H=-0.464, gammaR_neg=0.395, gammaR_pos=0.640,
                l_R=-0.710, eps=1.09, kappa=0.50, f_alpha=2.747, rudder_rate=math.radians(15.8))


def _patrol51():
    from vtrials.sysid.blanke import patrol51
    return patrol51()


#: The team's models by the ship name records carry (``team_knowledge.ship``).
SHIPS = MappingProxyType({"kvlcc2_l7": kvlcc2_l7, "patrol51": _patrol51})


def team_ship(name: str):
    """The team's model of a ship by name (MMG 3-DOF or the 4-DOF Blanke model); a clear error for a
    ship without one."""
    if name not in SHIPS:
        raise InputError(_WHERE, "ship", f"no team maneuvering model for {name!r}; allowed: {', '.join(SHIPS)}")
    return SHIPS[name]()


def kvlcc2_hull() -> dict[str, float]:
    """KVLCC2 hull coefficients, Y&Y (2015) Table 3 / docs/ships.md §1 (X_0 = −R'_0)."""
    return dict(X_0=-0.022, X_vv=-0.040, X_vr=0.002, X_rr=0.011, X_vvvv=0.771,
                Y_v=-0.315, Y_r=0.083, Y_vvv=-1.607, Y_vvr=0.379, Y_vrr=-0.391, Y_rrr=0.008,
                N_v=-0.137, N_r=-0.049, N_vvv=-0.030, N_vvr=-0.294, N_vrr=0.055, N_rrr=-0.013)


def _factors(term: str) -> list[tuple[str, bool]]:
    """'Y_v|r|' -> [('v', False), ('r', True)]; 'X_0' -> []."""
    if len(term) < 3 or term[0] not in "XYN" or term[1] != "_":
        raise InputError(_WHERE, "term", f"{term!r} is not a hull term; allowed: X_/Y_/N_ followed by "
                         "v, r, |v|, |r| factors or 0")
    body, out, i = term[2:], [], 0
    if body == "0":
        return out
    while i < len(body):
        if body[i] in "vr":
            out.append((body[i], False))
            i += 1
        elif body[i] == "|" and body[i + 2:i + 3] == "|" and body[i + 1:i + 2] in ("v", "r"):
            out.append((body[i + 1], True))
            i += 3
        else:
            raise InputError(_WHERE, "term", f"{term!r}: cannot read factor at {body[i:]!r}; allowed "
                             "factors: v, r, |v|, |r|")
    return out


def basis(term: str, vp: np.ndarray, rp: np.ndarray) -> np.ndarray:
    """Regressor of one hull term evaluated at v' and r' (non-dimensional arrays)."""
    vals = {"v": np.asarray(vp, float), "r": np.asarray(rp, float)}
    out = np.ones(np.broadcast(vals["v"], vals["r"]).shape)
    for name, absolute in _factors(term):
        out = out * (np.abs(vals[name]) if absolute else vals[name])
    return out


def regressors(terms, u, v, r, L: float) -> np.ndarray:
    """Matrix (len(u), len(terms)) of the non-dimensional hull regressors at (u, v, r) in SI."""
    U = np.hypot(u, v)
    vp, rp = v / U, r * L / U
    return np.column_stack([basis(t, vp, rp) for t in terms]) if len(terms) else np.zeros((len(U), 0))


def hull_forces(ship: Ship, coeffs: dict, u, v, r):
    """Dimensional hull forces X_H, Y_H (N), N_H (N m) from the coefficients given (Y&Y eq. 10)."""
    u, v, r = (np.asarray(a, float) for a in (u, v, r))
    U = np.hypot(u, v)
    vp, rp = v / U, r * ship.L / U
    q = 0.5 * ship.rho * ship.L * ship.d * U**2
    out = [np.zeros_like(U), np.zeros_like(U), np.zeros_like(U)]
    for term, c in coeffs.items():
        out["XYN".index(term[0])] = out["XYN".index(term[0])] + c * basis(term, vp, rp)
    return q * out[0], q * out[1], q * ship.L * out[2]


def propeller_rudder_forces(ship: Ship, u, v, r, delta, n):
    """Propeller thrust and rudder forces (X_P + X_R, Y_R, N_R) in N, N m: Y&Y eqs. (35)-(46).

    ``delta`` rudder angle (rad, + turns to starboard), ``n`` propeller rate (1/s); arrays broadcast.
    """
    s = ship
    u, v, r, delta, n = np.broadcast_arrays(*(np.asarray(a, float) for a in (u, v, r, delta, n)))
    U = np.hypot(u, v)
    beta = np.arctan2(-v, u)
    rp = r * s.L / U
    beta_P = beta - s.x_P * rp
    C2 = np.where(beta_P > 0, s.C2_pos, s.C2_neg)
    one_m_wP = (1 - s.w_P0) * (1 + (1 - np.exp(-s.C1 * np.abs(beta_P))) * (C2 - 1))
    J = u * one_m_wP / (n * s.D_P)
    KT = s.k0 + s.k1 * J + s.k2 * J**2
    X_P = (1 - s.t_P) * s.rho * n**2 * s.D_P**4 * KT
    eta = s.D_P / s.H_R
    u_R = s.eps * u * one_m_wP * np.sqrt(
        eta * (1 + s.kappa * (np.sqrt(1 + 8 * KT / (math.pi * J**2)) - 1))**2 + (1 - eta))
    beta_R = beta - s.l_R * rp
    v_R = U * np.where(beta_R < 0, s.gammaR_neg, s.gammaR_pos) * beta_R
    F_N = 0.5 * s.rho * s.A_R * (u_R**2 + v_R**2) * s.f_alpha * np.sin(delta - np.arctan(v_R / u_R))
    X_R = -(1 - s.t_R) * F_N * np.sin(delta)
    Y_R = -(1 + s.a_H) * F_N * np.cos(delta)
    N_R = -(s.x_R + s.a_H * s.x_H) * s.L * F_N * np.cos(delta)
    return X_P + X_R, Y_R, N_R


def inertial_forces(ship: Ship, u, v, r, udot, vdot, rdot):
    """Total external X, Y, N that the measured motion requires (inverse dynamics, Y&Y eq. 4)."""
    Mx, My, mxG, Izz = ship.masses()
    X = Mx * udot - My * v * r - mxG * r**2
    Y = My * vdot + Mx * u * r + mxG * rdot
    N = Izz * rdot + mxG * (vdot + u * r)
    return X, Y, N


def accelerations(ship: Ship, X, Y, N, u, v, r):
    """(u̇, v̇, ṙ) from total forces: Y&Y eq. (4) solved for the accelerations."""
    Mx, My, mxG, Izz = ship.masses()
    udot = (X + My * v * r + mxG * r**2) / Mx
    b1, b2 = Y - Mx * u * r, N - mxG * u * r
    det = My * Izz - mxG**2
    return udot, (b1 * Izz - mxG * b2) / det, (My * b2 - mxG * b1) / det
