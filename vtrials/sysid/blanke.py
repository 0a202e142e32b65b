"""The trials team's own 4-DOF (surge–sway–roll–yaw) model of a twin-screw, twin-rudder ship with a
dimensional second-order modulus hull (Blanke & Christensen 1993, "BC93" below, as in docs/ships.md §2).

This is the model the identification fits for patrol51; it shares no code with the simulator.

Axes: the ship's PMM origin on the waterline (the origin of the surveyed instrument positions), x
forward, y starboard, z down; u, v body velocities through the water at the origin, p roll rate, r
yaw rate, φ heel (+ starboard down). Equations:

* Rigid body about the origin with the centre of gravity at (x_G, 0, z_G) and the product of inertia
  I_xz = m x_G z_G that offset gives (Fossen 2011, "Handbook of Marine Craft Hydrodynamics and Motion
  Control", eqs. 3.44-3.49 with q = w = 0, y_G = 0); added mass from BC93's acceleration derivatives
  (force = derivative × acceleration); no added-mass Coriolis terms (BC93's velocity derivatives
  contain them).
* Hull: X_H = −R(u) + terms; the other equations the modulus terms of :data:`TERMS` (BC93's
  structure, names as docs/ships.md §2: Y_uv = Y_|u|v, Y_phiur = Y_φ|ur|, N_phiur = N_φu|r| …).
  R(u) from the tank prediction; roll restoring −ρg∇ GM_T sin φ from the inclining experiment.
* Propellers: thrust T = ρn²D⁴K_T(J, P/D) of the propellers' open-water chart (Wageningen B4-70,
  Oosterveld & van Oossanen 1975), J = u(1 − w_P)/(nD), X_P = (1 − t_P) T per shaft.
* Rudders (each behind its propeller): MMG inflow (Yasukawa & Yoshimura 2015, J. Mar. Sci. Technol.
  20:37, eqs. 18-26) with the jet speed written from the thrust, and the rudder's section lift and
  drag from its open-water characteristics (BC93: dC_L/dα 0.054/deg, stall 23°; induced drag of an
  elliptic-loaded foil; past stall a flat plate, Hoerner 1965 "Fluid-Dynamic Drag" ch. 3). The rudder's
  own side force acts at its centre depth, the hull force it induces (a_H) at the hull's.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from types import MappingProxyType

import numpy as np

from vtrials.errors import InputError

_WHERE = "vtrials.sysid.blanke"
G = 9.80665

#: Hull regressors: name → function of (u, v, r, φ, p) (SI), as in BC93.
TERMS = MappingProxyType({
    "X_vr": lambda u, v, r, f, p: v * r,
    "X_vv": lambda u, v, r, f, p: v * v,
    "X_rr": lambda u, v, r, f, p: r * r,
    **{f"{e}_uv": (lambda u, v, r, f, p: np.abs(u) * v) for e in "YKN"},
    "Y_ur": lambda u, v, r, f, p: u * r,
    "K_ur": lambda u, v, r, f, p: u * r,
    "N_ur": lambda u, v, r, f, p: np.abs(u) * r,
    **{f"{e}_vv": (lambda u, v, r, f, p: v * np.abs(v)) for e in "YKN"},
    **{f"{e}_vr": (lambda u, v, r, f, p: v * np.abs(r)) for e in "YKN"},
    **{f"{e}_rv": (lambda u, v, r, f, p: r * np.abs(v)) for e in "YKN"},
    "N_rr": lambda u, v, r, f, p: r * np.abs(r),
    **{f"{e}_phiuv": (lambda u, v, r, f, p: f * np.abs(u * v)) for e in "YKN"},
    "Y_phiur": lambda u, v, r, f, p: f * np.abs(u * r),
    "K_phiur": lambda u, v, r, f, p: f * np.abs(u * r),
    "N_phiur": lambda u, v, r, f, p: f * u * np.abs(r),
    "Y_phiuu": lambda u, v, r, f, p: f * u * u,
    "K_phiuu": lambda u, v, r, f, p: f * u * u,
    "N_phiuu": lambda u, v, r, f, p: f * u * np.abs(u),
    "K_up": lambda u, v, r, f, p: np.abs(u) * p,
    "K_pp": lambda u, v, r, f, p: p * np.abs(p),
    "K_p": lambda u, v, r, f, p: p,
    "K_phiphiphi": lambda u, v, r, f, p: f**3,
})

_Y = ("Y_uv", "Y_ur", "Y_vv", "Y_vr", "Y_rv")
_N = ("N_uv", "N_ur", "N_rr", "N_rv")
_K = ("K_uv", "K_ur", "K_vv", "K_vr", "K_rv")
_KROLL = ("K_up", "K_pp", "K_p", "K_phiphiphi")
#: Model structures: the candidate terms of each equation (X, Y, K, N).
STRUCTURES = MappingProxyType({
    # BC93's 4-DOF structure: sway and yaw forces change with heel
    "blanke4": MappingProxyType({
        "X": ("X_vr", "X_vv", "X_rr"),
        "Y": _Y + ("Y_phiuv", "Y_phiur", "Y_phiuu"),
        "K": _K + ("K_phiuv", "K_phiur", "K_phiuu") + _KROLL,
        "N": _N + ("N_phiuv", "N_phiur", "N_phiuu"),
    }),
    # the same without the heel terms in sway and yaw (a 3-DOF maneuvering model with roll riding along)
    "blanke3": MappingProxyType({
        "X": ("X_vr", "X_vv", "X_rr"), "Y": _Y, "K": _K + _KROLL, "N": _N,
    }),
})

#: The linear (stability) derivatives the acceptance criteria name (BC93's counterparts of Y'_v ...).
LINEAR = ("Y_uv", "Y_ur", "N_uv", "N_ur")
#: Terms kept in every selected model: the linear derivatives and the roll damping.
REQUIRED = LINEAR + ("K_p",)

#: K_T = Σ C[s, t] J^s (P/D)^t of a Wageningen B4-70 screw: Oosterveld & van Oossanen (1975), Int.
#: Shipbuilding Progress 22(251), Table 1 (Re 2·10⁶), with Z = 4 and A_E/A_0 = 0.70 folded in and equal
#: powers summed — the propellers' open-water chart as the maker supplies it (valid 0.5 ≤ P/D ≤ 1.4).
B4_70_KT = np.array([
    [4.34691080e-03, 2.23743400e-01, 4.40868259e-01, -2.20603330e-01, 0.0, 0.0, 6.38407000e-03],
    [-2.17087640e-01, -9.43175000e-02, -2.61843200e-02, 6.73696000e-02, 0.0, 0.0, -1.32742000e-04],
    [-2.31882109e-01, 0.0, 0.0, 0.0, 0.0, 0.0, -2.63968080e-03],
    [8.42594770e-02, 0.0, 0.0, -4.09184000e-03, 0.0, 0.0, 6.33056480e-04]])


@dataclasses.dataclass(frozen=True)
class Rudder:
    """One rudder behind its propeller (SI; primes ÷ L). Interaction factors as MMG (Y&Y 2015)."""

    x: float
    y: float
    z: float
    area: float
    span: float
    t_R: float
    a_H: float
    x_H: float          # x'_H
    gamma_neg: float
    gamma_pos: float
    l_R: float          # l'_R
    eps: float
    kappa: float
    lift_slope: float   # dC_L/dα, 1/rad
    stall: float        # rad
    stall_width: float  # rad
    cd0: float
    aspect: float
    oswald: float
    cn90: float


@dataclasses.dataclass(frozen=True)
class Ship4:
    """Mass, inertia, added mass, hydrostatics, resistance, propellers and rudders the team KNOWS
    (drawings, inclining experiment, model tests, makers' data); only the hull terms are estimated."""

    L: float
    d: float
    rho: float
    volume: float       # displaced volume ∇, m³
    m: float
    x_G: float
    z_G: float          # + down
    I_xx: float         # about the origin
    I_zz: float
    GM: float
    X_udot: float
    Y_vdot: float
    Y_pdot: float
    Y_rdot: float
    K_vdot: float
    K_pdot: float
    K_rdot: float
    N_vdot: float
    N_pdot: float
    N_rdot: float
    z_H: float          # depth of the hull's lateral force induced by the rudder
    resistance_speeds: tuple
    resistance_values: tuple
    D_P: float
    t_P: float
    w_P: float
    y_P: tuple          # propellers' lateral positions
    rudders: tuple
    rudder_rate: float = 0.0

    structures = STRUCTURES
    linear = LINEAR
    required = REQUIRED
    prime = False

    @property
    def I_xz(self) -> float:
        return self.m * self.x_G * self.z_G

    def mass_matrix(self) -> np.ndarray:
        """4×4 M_RB + M_A in (u, v, p, r) (Fossen 2011 eq. 3.44 at the origin; M_A = −derivatives)."""
        m, xg, zg = self.m, self.x_G, self.z_G
        return np.array([
            [m - self.X_udot, 0.0, 0.0, 0.0],
            [0.0, m - self.Y_vdot, -m * zg - self.Y_pdot, m * xg - self.Y_rdot],
            [0.0, -m * zg - self.K_vdot, self.I_xx - self.K_pdot, -self.I_xz - self.K_rdot],
            [0.0, m * xg - self.N_vdot, -self.I_xz - self.N_pdot, self.I_zz - self.N_rdot]])

    @functools.cached_property
    def _inverse_mass(self) -> np.ndarray:
        return np.linalg.inv(self.mass_matrix())

    def centripetal(self, u, v, p, r):
        """The rigid-body velocity terms −C_RB(ν)ν (X, Y, K, N) on the force side, M ν̇ = F + this
        (Fossen 2011 eq. 3.49 with q = w = 0, y_G = 0)."""
        m, xg, zg = self.m, self.x_G, self.z_G
        return (m * (v * r + xg * r * r - zg * p * r), -m * u * r, m * zg * u * r, -m * xg * u * r)

    def resistance(self, u):
        """Calm-water resistance from the tank table (R/u² interpolated; astern as ahead)."""
        au = np.abs(np.asarray(u, float))
        s, R = np.asarray(self.resistance_speeds), np.asarray(self.resistance_values)
        c = np.interp(au, s[1:], R[1:] / s[1:]**2)
        return c * au * np.asarray(u, float)

    def thrust(self, u, n, pitch):
        """Thrust of one propeller (N) from the open-water chart; n in 1/s, pitch = P/D."""
        J = u * (1.0 - self.w_P) / (n * self.D_P)
        c = (np.asarray(pitch, float)[..., None] ** np.arange(B4_70_KT.shape[1])) @ B4_70_KT.T
        kt = c[..., 0] + J * (c[..., 1] + J * (c[..., 2] + J * c[..., 3]))
        return self.rho * n * n * self.D_P**4 * kt

    def propeller_rudder_forces(self, u, v, r, delta, n, pitch):
        """(X, Y, K, N) of both propellers and both rudders at the same rudder angle, shaft rate and
        pitch on either side (arrays broadcast)."""
        u, v, r, delta, n, pitch = np.broadcast_arrays(*(np.asarray(a, float) for a in (u, v, r, delta, n, pitch)))
        T = self.thrust(u, n, pitch)
        X = len(self.y_P) * (1.0 - self.t_P) * T
        Y, K, N = np.zeros_like(u), np.zeros_like(u), np.zeros_like(u)
        U = np.hypot(u, v)
        beta = np.arctan2(-v, u)
        uP = u * (1.0 - self.w_P)
        for rd in self.rudders:
            jet = np.sqrt(np.maximum(uP**2 + 8.0 * T / (math.pi * self.rho * self.D_P**2), 0.0))
            eta = min(self.D_P / rd.span, 1.0)
            slip = uP + rd.kappa * (jet - uP)
            uR = rd.eps * np.sqrt(eta * slip**2 + (1.0 - eta) * uP**2)
            UbR = U * beta - rd.l_R * r * self.L
            vR = np.where(UbR < 0, rd.gamma_neg, rd.gamma_pos) * UbR
            alpha = delta - np.arctan2(vR, uR)
            q = 0.5 * self.rho * rd.area * (uR**2 + vR**2)
            cl, cd = self.foil(rd, alpha)
            FN = q * (cl * np.cos(alpha) + cd * np.sin(alpha))
            FT = q * (cd * np.cos(alpha) - cl * np.sin(alpha))
            Xr = -FN * np.sin(delta) - FT * np.cos(delta)
            Yr = -FN * np.cos(delta) + FT * np.sin(delta)
            XR = (1.0 - rd.t_R) * Xr
            X = X + XR
            Y = Y + (1.0 + rd.a_H) * Yr
            K = K - (rd.z + rd.a_H * self.z_H) * Yr
            N = N + (rd.x + rd.a_H * rd.x_H * self.L) * Yr - rd.y * XR
        return X, Y, K, N

    @staticmethod
    def foil(rd: Rudder, alpha):
        """C_L, C_D of the rudder's section: attached-flow lift and induced drag, a flat plate past
        stall, blended over the stall width (|α| < 90°)."""
        a = np.arctan2(np.sin(alpha), np.abs(np.cos(alpha)))
        cl_a = rd.lift_slope * a
        cd_a = rd.cd0 + cl_a**2 / (math.pi * rd.oswald * rd.aspect)
        cl_s = rd.cn90 * np.sin(a) * np.cos(a)
        cd_s = rd.cd0 + rd.cn90 * np.sin(a)**2
        w = 1.0 / (1.0 + np.exp(np.clip((np.abs(a) - rd.stall) / rd.stall_width, -50, 50)))
        return w * cl_a + (1 - w) * cl_s, w * cd_a + (1 - w) * cd_s

    # -- the identification's interface (shared with vtrials.sysid.mmg.Ship) --------------------------
    def body(self, seg):
        """Body-axis u, v, r, their derivatives, φ and p from a segment's levelled-frame states: the
        body y axis is the heading frame's turned by the heel (v_b = v cos φ, r_b = ψ̇ cos φ, level
        trim)."""
        c, s = np.cos(seg.phi), np.sin(seg.phi)
        return (seg.u, seg.v * c, seg.r * c, seg.udot, seg.vdot * c - seg.v * s * seg.p,
                seg.rdot * c - seg.r * s * seg.p, seg.phi, seg.p, seg.pdot)

    def hull_samples(self, seg) -> dict:
        """Hull forces (N, N m) the measured motion requires less the known parts (inverse dynamics)."""
        u, v, r, ud, vd, rd, phi, p, pd = self.body(seg)
        acc = np.stack([ud, vd, pd, rd])
        inert = self.mass_matrix() @ acc
        cen = self.centripetal(u, v, p, r)
        Xpr, Ypr, Kpr, Npr = self.propeller_rudder_forces(u, v, r, seg.delta, seg.n, seg.pitch)
        restoring = -self.rho * G * self.volume * self.GM * np.sin(phi)
        return {"X": inert[0] - cen[0] - Xpr + self.resistance(u), "Y": inert[1] - cen[1] - Ypr,
                "K": inert[2] - cen[2] - Kpr - restoring, "N": inert[3] - cen[3] - Npr}

    def regressors(self, terms, seg) -> np.ndarray:
        u, v, r, _, _, _, phi, p, _ = self.body(seg)
        return np.column_stack([regressor(t, u, v, r, phi, p) for t in terms]) if len(terms) else np.zeros((u.size, 0))

    def row_weights(self, seg) -> np.ndarray:
        """Dimensional forces: the reconstruction's errors are about constant in newtons (no weights)."""
        return np.ones_like(seg.u)

    # -- prediction ---------------------------------------------------------------------------------
    state_names = ("x", "y", "psi", "u", "v", "r", "phi", "p")

    def initial_state(self, speed: float) -> np.ndarray:
        return np.array([0.0, 0.0, 0.0, speed, 0.0, 0.0, 0.0, 0.0])

    def rates(self, coeffs: dict, y: np.ndarray, delta: float, n: float, pitch: float) -> np.ndarray:
        """Time derivative of the state (x, y, ψ, u, v, r, φ, p) under the given rudder, shaft rate and
        pitch (level trim: ψ̇ = r/cos φ, φ̇ = p)."""
        _, _, psi, u, v, r, phi, p = (float(a) for a in y)
        H = hull_forces(coeffs, u, v, r, phi, p)
        H[0] -= float(self.resistance(u))
        P = self.propeller_rudder_forces(u, v, r, delta, n, pitch)
        cen = self.centripetal(u, v, p, r)
        F = np.array([H[i] + float(P[i]) + cen[i] for i in range(4)])
        F[2] -= self.rho * G * self.volume * self.GM * math.sin(phi)
        ud, vd, pd, rd = self._inverse_mass @ F
        c, s, cf = math.cos(psi), math.sin(psi), math.cos(phi)
        vh = v / cf
        return np.array([u * c - vh * s, u * s + vh * c, r / cf, ud, vd, rd, p, pd])


def regressor(term: str, u, v, r, phi, p) -> np.ndarray:
    """One hull regressor at (u, v, r, φ, p) (SI arrays)."""
    if term not in TERMS:
        raise InputError(_WHERE, "term", f"{term!r} is not a hull term of the 4-DOF model; allowed: {', '.join(TERMS)}")
    return np.asarray(TERMS[term](*(np.asarray(a, float) for a in (u, v, r, phi, p))), float) * np.ones(np.shape(u))


def hull_forces(coeffs: dict, u: float, v: float, r: float, phi: float, p: float) -> list:
    """Hull forces X, Y, K, N (N, N m) at one state from the coefficients given (without the resistance)."""
    out = [0.0, 0.0, 0.0, 0.0]
    for term, c in coeffs.items():
        out["XYKN".index(term[0])] += c * TERMS[term](u, v, r, phi, p)
    return out


def patrol51() -> Ship4:
    """The 51.5 m patrol vessel as its trials team knows it. Sources: BC93 particulars, inertias, added
    mass and rudder (docs/ships.md §2); KG 3.36 m and GM_T 1.1 m (inclining, BC93); propellers B4-70,
    D 1.6 m, t_P 0.06, w_P 0.05 and the rudders' interaction factors from the yard's design estimates
    (models/patrol51/ship.toml states them); steering gear 5°/s (its rating); resistance: the tank
    prediction at 1 m/s steps (models/patrol51/resistance.md)."""
    rho, disp, L, d = 1014.0, 357.0, 51.5, 2.3
    m = rho * disp
    speeds = (0.0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16)
    values = (0.0, 2562.8, 7840.0, 14867.6, 23416.6, 34118.0, 48472.2, 65767.5, 85839.0, 125571.0, 171738.5,
              207083.3, 235667.2, 261257.7, 284335.6, 307331.0, 331507.2)
    rud = dict(y=0.0, x=-23.3, z=2.0, area=1.5, span=1.5, t_R=0.2, a_H=0.2, x_H=-0.45, gamma_neg=0.5,
               gamma_pos=0.5, l_R=-0.9, eps=1.0, kappa=0.5, lift_slope=math.degrees(0.054),
               stall=math.radians(23.0), stall_width=math.radians(2.0), cd0=0.013, aspect=3.0, oswald=0.9,
               cn90=1.2)
    rudders = tuple(Rudder(**{**rud, "y": y}) for y in (-2.4, 2.4))
    return Ship4(L=L, d=d, rho=rho, volume=disp, m=m, x_G=-3.38, z_G=d - 3.36, I_xx=2.3763e6, I_zz=47.934e6,
                 GM=1.1, X_udot=-17400.0, Y_vdot=-393000.0, Y_pdot=-296000.0, Y_rdot=-1.4e6, K_vdot=296000.0,
                 K_pdot=-774000.0, K_rdot=0.0, N_vdot=538000.0, N_pdot=0.0, N_rdot=-38.7e6, z_H=1.15,
                 resistance_speeds=speeds, resistance_values=values, D_P=1.6, t_P=0.06, w_P=0.05,
                 y_P=(-2.4, 2.4), rudders=rudders, rudder_rate=math.radians(5.0))
