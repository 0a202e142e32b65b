"""Calm-water resistance of displacement and fast round-bilge hulls: Holtrop & Mennen.

The method is the statistical power prediction of MARIN:

- [HM82] Holtrop J., Mennen G.G.J. (1982) "An approximate power prediction method",
  International Shipbuilding Progress 29(335):166-170. Component split, form factor (c12/c13
  form), wetted-area estimate, appendage, bulb, transom and correlation terms, the 1982
  wave-resistance formula and the numerical example of its section 5 (L 205 m, 25 kn).
- [H84] Holtrop J. (1984) "A statistical re-analysis of resistance and propulsion data",
  International Shipbuilding Progress 31(363):272-276. Re-analysis on 334 models including the
  Series 64 hulls: new form-factor formula (c14 form), revised low-speed wave resistance (m4
  term instead of m2), the separate formula for Fn > 0.55 (c17, m3) and the linear
  interpolation between Fn 0.40 and 0.55.
- [ITTC57] ITTC-1957 model-ship correlation line, C_F = 0.075 / (log10 Rn - 2)^2 (8th ITTC,
  Madrid 1957; ITTC Recommended Procedure 7.5-02-02-02).

Total resistance [HM82 eq. 1]:

    R_T = R_F (1 + k1) + R_APP + R_W + R_B + R_TR + R_A

Every coefficient below carries the equation of the paper it comes from; the numbers are the
published regression constants. The function is pure: a HullForm and an array of speeds in,
arrays of the components (N) out; nothing is cached or mutated.

Conventions: SI throughout. ``lcb`` is Holtrop's lcb: position of the centre of buoyancy forward
of 0.5 L_WL as a percentage of L_WL (negative aft). Speeds in m/s; knots only in reports
(``KNOT`` = 1852/3600 m/s exactly).

Editions. ``wave="1984"`` (default) is [H84]; ``wave="1982"`` evaluates the [HM82] formula at
every Froude number and exists to reproduce the 1982 worked example (the paper used it up to
about Fn 0.45). ``form_factor="1984"`` (default) is [H84] eq. for 1 + k1 with c14;
``form_factor="1982"`` is [HM82]'s c12/c13 formula, which the 1982 example uses.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

KNOT = 1852.0 / 3600.0  # m/s per international knot (exact by definition)

# Approximate 1 + k2 of appendages [HM82, table "approximate 1 + k2 values"].
# Where the paper gives a range, both ends are listed; pick and say which.
K2_RUDDER_BEHIND_SKEG = (1.5, 2.0)
K2_RUDDER_BEHIND_STERN = (1.3, 1.5)
K2_TWIN_SCREW_BALANCE_RUDDERS = 2.8
K2_SHAFT_BRACKETS = 3.0
K2_SKEG = (1.5, 2.0)
K2_STRUT_BOSSINGS = 3.0
K2_HULL_BOSSINGS = 2.0
K2_SHAFTS = (2.0, 4.0)
K2_STABILIZER_FINS = 2.8
K2_DOME = 2.7
K2_BILGE_KEELS = 1.4

# Stern-shape parameter C_stern [HM82, table]: afterbody form.
C_STERN_PRAM_GONDOLA = -25.0
C_STERN_V_SECTIONS = -10.0
C_STERN_NORMAL = 0.0
C_STERN_U_HOGNER = 10.0


@dataclasses.dataclass(frozen=True)
class Appendage:
    """One appendage: wetted area S_i [m^2] and its 1 + k2 [HM82]."""

    name: str
    area: float
    one_plus_k2: float

    def __post_init__(self):
        if not (math.isfinite(self.area) and self.area >= 0.0):
            raise ValueError(f"appendage {self.name!r}: wetted area must be >= 0, got {self.area}")
        if not (math.isfinite(self.one_plus_k2) and self.one_plus_k2 >= 1.0):
            raise ValueError(f"appendage {self.name!r}: 1 + k2 must be >= 1, got {self.one_plus_k2}")


def _opt(x):
    return None if x is None else float(x)


@dataclasses.dataclass(frozen=True)
class HullForm:
    """The inputs of the Holtrop & Mennen method [HM82 section 5, list of example data].

    Give C_M or A_M, and C_WP or A_WP (one of each; both only if they agree). Give S to use a
    known wetted area, else the [HM82] estimate is used (``wetted_area``).
    """

    L_WL: float                 # length on the waterline [m]
    B: float                    # moulded breadth [m]
    T_F: float                  # moulded draught at the forward perpendicular [m]
    T_A: float                  # moulded draught at the aft perpendicular [m]
    volume: float               # moulded displacement volume ∇ [m^3]
    lcb: float                  # LCB forward of 0.5 L_WL, % of L_WL (negative aft)
    C_M: float | None = None    # midship section coefficient A_M / (B T)
    A_M: float | None = None    # midship section area [m^2]
    C_WP: float | None = None   # waterplane area coefficient A_WP / (L_WL B)
    A_WP: float | None = None   # waterplane area [m^2]
    A_BT: float = 0.0           # transverse area of the bulbous bow at the FP [m^2]
    h_B: float = 0.0            # height of the centre of A_BT above the keel [m]
    A_T: float = 0.0            # immersed transom area at rest [m^2]
    S: float | None = None      # wetted area of the bare hull [m^2]; None: [HM82] estimate
    C_stern: float = 0.0        # stern-shape parameter (C_STERN_* above)
    appendages: tuple[Appendage, ...] = ()
    bow_thruster_diameter: float = 0.0  # d_TH of a bow-thruster tunnel opening [m]
    C_BTO: float = 0.003        # tunnel-opening coefficient, 0.003..0.012 [HM82]
    k_s: float = 150e-6         # hull roughness [m]; > 150 µm adds ΔC_A [HM82]

    def __post_init__(self):
        for name in ("L_WL", "B", "T_F", "T_A", "volume"):
            v = getattr(self, name)
            if not (math.isfinite(v) and v > 0.0):
                raise ValueError(f"HullForm.{name} must be finite and > 0, got {v}")
        for name in ("A_BT", "h_B", "A_T", "bow_thruster_diameter", "k_s"):
            v = getattr(self, name)
            if not (math.isfinite(v) and v >= 0.0):
                raise ValueError(f"HullForm.{name} must be finite and >= 0, got {v}")
        if not math.isfinite(self.lcb):
            raise ValueError("HullForm.lcb must be finite")
        T = 0.5 * (self.T_F + self.T_A)
        cm = _coef(_opt(self.C_M), _opt(self.A_M), self.B * T, "C_M", "A_M")
        cwp = _coef(_opt(self.C_WP), _opt(self.A_WP), self.L_WL * self.B, "C_WP", "A_WP")
        if not 0.0 < cm <= 1.0:
            raise ValueError(f"midship coefficient must be in (0, 1], got {cm}")
        if not 0.0 < cwp <= 1.0:
            raise ValueError(f"waterplane coefficient must be in (0, 1], got {cwp}")
        cb = self.volume / (self.L_WL * self.B * T)
        if not 0.0 < cb < cm:
            raise ValueError(f"C_B = {cb:.4f} must be below C_M = {cm:.4f} (C_P < 1)")
        if self.S is not None and not (math.isfinite(self.S) and self.S > 0.0):
            raise ValueError(f"HullForm.S must be > 0 when given, got {self.S}")
        if self.A_BT > 0.0 and not self.T_F - 1.5 * self.h_B > 0.0:
            raise ValueError("bulb: T_F - 1.5 h_B must be > 0 (P_B of [HM82])")
        if not isinstance(self.appendages, tuple):
            object.__setattr__(self, "appendages", tuple(self.appendages))

    # ---- derived form parameters -------------------------------------------------------
    @property
    def T(self) -> float:
        """Mean moulded draught [m]."""
        return 0.5 * (self.T_F + self.T_A)

    @property
    def C_B(self) -> float:
        """Block coefficient on L_WL: ∇ / (L_WL B T) [HM82]."""
        return self.volume / (self.L_WL * self.B * self.T)

    @property
    def C_Mc(self) -> float:
        """Midship coefficient (from C_M or A_M)."""
        return _coef(_opt(self.C_M), _opt(self.A_M), self.B * self.T, "C_M", "A_M")

    @property
    def C_WPc(self) -> float:
        """Waterplane coefficient (from C_WP or A_WP)."""
        return _coef(_opt(self.C_WP), _opt(self.A_WP), self.L_WL * self.B, "C_WP", "A_WP")

    @property
    def C_P(self) -> float:
        """Prismatic coefficient on L_WL, C_B / C_M [HM82]."""
        return self.C_B / self.C_Mc

    @property
    def wetted_area(self) -> float:
        """Bare-hull wetted area [m^2]: S if given, else [HM82] eq. for S:

        S = L (2T + B) sqrt(C_M) (0.453 + 0.4425 C_B - 0.2862 C_M - 0.003467 B/T + 0.3696 C_WP)
            + 2.38 A_BT / C_B
        """
        if self.S is not None:
            return float(self.S)
        return holtrop_wetted_area(self)

    @property
    def S_APP(self) -> float:
        """Total wetted area of the appendages [m^2]."""
        return float(sum(a.area for a in self.appendages))

    @property
    def one_plus_k2_eq(self) -> float:
        """Equivalent 1 + k2 = Σ(1 + k2)_i S_i / Σ S_i [HM82]; 1.0 with no appendage area."""
        s = self.S_APP
        if s <= 0.0:
            return 1.0
        return float(sum(a.one_plus_k2 * a.area for a in self.appendages) / s)


def _coef(c, a, ref, cname, aname) -> float:
    if c is None and a is None:
        raise ValueError(f"give {cname} or {aname}")
    if c is not None and a is not None and abs(c - a / ref) > 1e-3 * max(c, 1e-12):
        raise ValueError(f"{cname} = {c} and {aname} = {a} disagree ({aname}/ref = {a / ref:.5f})")
    return float(c) if c is not None else float(a / ref)


def holtrop_wetted_area(h: HullForm) -> float:
    """[HM82] wetted-area estimate of the bare hull [m^2] (see HullForm.wetted_area)."""
    L, B, T, cb, cm, cwp = h.L_WL, h.B, h.T, h.C_B, h.C_Mc, h.C_WPc
    return float(L * (2.0 * T + B) * math.sqrt(cm)
                 * (0.453 + 0.4425 * cb - 0.2862 * cm - 0.003467 * B / T + 0.3696 * cwp)
                 + 2.38 * h.A_BT / cb)


def ittc1957_cf(rn) -> np.ndarray:
    """ITTC-1957 correlation line C_F = 0.075 / (log10 Rn - 2)^2 [ITTC57]."""
    rn = np.asarray(rn, dtype=float)
    return 0.075 / (np.log10(rn) - 2.0) ** 2


def length_of_run(h: HullForm) -> float:
    """L_R = L (1 - C_P + 0.06 C_P lcb / (4 C_P - 1)) [HM82]."""
    cp = h.C_P
    return h.L_WL * (1.0 - cp + 0.06 * cp * h.lcb / (4.0 * cp - 1.0))


def form_factor(h: HullForm, edition: str = "1984") -> tuple[float, dict]:
    """Hull form factor 1 + k1 and its intermediates.

    "1982" [HM82]: 1 + k1 = c13 {0.93 + c12 (B/L_R)^0.92497 (0.95 - C_P)^-0.521448
                                 (1 - C_P + 0.0225 lcb)^0.6906},
        c12 = (T/L)^0.2228446                          T/L > 0.05
            = 48.20 (T/L - 0.02)^2.078 + 0.479948     0.02 < T/L < 0.05
            = 0.479948                                 T/L < 0.02
        c13 = 1 + 0.003 C_stern.
    "1984" [H84]: 1 + k1 = 0.93 + 0.487118 c14 (B/L)^1.06806 (T/L)^0.46106 (L/L_R)^0.121563
                                 (L^3/∇)^0.36486 (1 - C_P)^-0.604247,
        c14 = 1 + 0.011 C_stern.
    """
    L, B, T, cp, lcb = h.L_WL, h.B, h.T, h.C_P, h.lcb
    LR = length_of_run(h)
    if LR <= 0.0:
        raise ValueError(f"length of run L_R = {LR:.3f} m <= 0: lcb {lcb} % too far aft for C_P {cp:.3f}")
    if edition == "1982":
        tl = T / L
        if tl > 0.05:
            c12 = tl ** 0.2228446
        elif tl > 0.02:
            c12 = 48.20 * (tl - 0.02) ** 2.078 + 0.479948
        else:
            c12 = 0.479948
        c13 = 1.0 + 0.003 * h.C_stern
        k = c13 * (0.93 + c12 * (B / LR) ** 0.92497 * (0.95 - cp) ** -0.521448
                   * (1.0 - cp + 0.0225 * lcb) ** 0.6906)
        return float(k), {"L_R": LR, "c12": c12, "c13": c13}
    if edition == "1984":
        c14 = 1.0 + 0.011 * h.C_stern
        k = 0.93 + 0.487118 * c14 * (B / L) ** 1.06806 * (T / L) ** 0.46106 \
            * (L / LR) ** 0.121563 * (L ** 3 / h.volume) ** 0.36486 * (1.0 - cp) ** -0.604247
        return float(k), {"L_R": LR, "c14": c14}
    raise ValueError(f"form_factor edition must be '1982' or '1984', got {edition!r}")


def _wave_constants(h: HullForm) -> dict:
    """Speed-independent constants of the wave-resistance formulas [HM82], [H84]."""
    L, B, T, vol, cp, cm, cwp, lcb = h.L_WL, h.B, h.T, h.volume, h.C_P, h.C_Mc, h.C_WPc, h.lcb
    LR = length_of_run(h)
    bl = B / L
    # c7 [HM82]
    if bl < 0.11:
        c7 = 0.229577 * bl ** 0.33333
    elif bl < 0.25:
        c7 = bl
    else:
        c7 = 0.5 - 0.0625 * L / B
    # half angle of entrance of the load waterline, degrees [HM82]
    iE = 1.0 + 89.0 * math.exp(-(L / B) ** 0.80856 * (1.0 - cwp) ** 0.30484
                               * (1.0 - cp - 0.0225 * lcb) ** 0.6367 * (LR / B) ** 0.34574
                               * (100.0 * vol / L ** 3) ** 0.16302)
    c1 = 2223105.0 * c7 ** 3.78613 * (T / B) ** 1.07961 * (90.0 - iE) ** -1.37565
    # bulb [HM82]
    if h.A_BT > 0.0:
        c3 = 0.56 * h.A_BT ** 1.5 / (B * T * (0.31 * math.sqrt(h.A_BT) + h.T_F - h.h_B))
    else:
        c3 = 0.0
    c2 = math.exp(-1.89 * math.sqrt(c3))
    # transom [HM82]
    c5 = 1.0 - 0.8 * h.A_T / (B * T * cm)
    # lambda [HM82]
    lam = 1.446 * cp - 0.03 * L / B if L / B < 12.0 else 1.446 * cp - 0.36
    # c16, m1 [HM82]
    c16 = (8.07981 * cp - 13.8673 * cp ** 2 + 6.984388 * cp ** 3) if cp < 0.80 else 1.73014 - 0.7067 * cp
    m1 = 0.0140407 * L / T - 1.75254 * vol ** (1.0 / 3.0) / L - 4.79323 * B / L - c16
    # c15 [HM82]
    l3v = L ** 3 / vol
    if l3v < 512.0:
        c15 = -1.69385
    elif l3v < 1726.91:
        c15 = -1.69385 + (L / vol ** (1.0 / 3.0) - 8.0) / 2.36
    else:
        c15 = 0.0
    # high-speed formula, Fn > 0.55 [H84]
    c17 = 6919.3 * cm ** -1.3346 * (vol / L ** 3) ** 2.00977 * (L / B - 2.0) ** 1.40692
    m3 = -7.2035 * bl ** 0.326869 * (T / B) ** 0.605375
    return {"L_R": LR, "c1": c1, "c2": c2, "c3": c3, "c5": c5, "c7": c7, "iE_deg": iE,
            "lambda": lam, "c15": c15, "c16": c16, "m1": m1, "c17": c17, "m3": m3, "d": -0.9}


def wave_resistance(h: HullForm, Fn, rho: float = 1025.0, g: float = 9.80665,
                    edition: str = "1984", bridge: str = "linear") -> np.ndarray:
    """Wave resistance R_W [N] at Froude numbers Fn (array).

    "1984" [H84]:
      Fn <= 0.40:  R_Wa = c1 c2 c5 ∇ ρ g exp{m1 Fn^d + m4 cos(λ Fn^-2)}
      Fn >= 0.55:  R_Wb = c17 c2 c5 ∇ ρ g exp{m3 Fn^d + m4 cos(λ Fn^-2)}
      between:     R_W = R_Wa(0.40) + (10 Fn - 4) [R_Wb(0.55) - R_Wa(0.40)] / 1.5
      m4 = 0.4 c15 exp(-0.034 Fn^-3.29), d = -0.9.
      ``bridge="hermite"`` replaces [H84]'s linear bridge by the cubic Hermite polynomial in Fn that
      matches R_Wa and dR_Wa/dFn at 0.40 and R_Wb and dR_Wb/dFn at 0.55 (same end values, no slope
      jump: R_W is then C¹, so the local exponent d ln R/d ln V has no steps at Fn 0.40 and 0.55).
    "1982" [HM82]: R_W = c1 c2 c5 ∇ ρ g exp{m1 Fn^d + m2 cos(λ Fn^-2)},
      m2 = c15 C_P^2 exp(-0.1 Fn^-2), at every Fn.
    R_W = 0 at Fn = 0.
    """
    k = _wave_constants(h)
    Fn = np.asarray(Fn, dtype=float)
    out = np.zeros_like(Fn)
    pos = Fn > 0.0
    f = Fn[pos]
    base = k["c2"] * k["c5"] * h.volume * rho * g
    d, lam, c15 = k["d"], k["lambda"], k["c15"]

    def m4(x):
        return 0.4 * c15 * np.exp(-0.034 * x ** -3.29)

    def rwa(x):
        return k["c1"] * base * np.exp(k["m1"] * x ** d + m4(x) * np.cos(lam * x ** -2.0))

    def rwb(x):
        return k["c17"] * base * np.exp(k["m3"] * x ** d + m4(x) * np.cos(lam * x ** -2.0))

    if edition == "1982":
        m2 = c15 * h.C_P ** 2 * np.exp(-0.1 * f ** -2.0)
        out[pos] = k["c1"] * base * np.exp(k["m1"] * f ** d + m2 * np.cos(lam * f ** -2.0))
        return out
    if edition != "1984":
        raise ValueError(f"wave edition must be '1982' or '1984', got {edition!r}")
    if bridge not in ("linear", "hermite"):
        raise ValueError(f"wave bridge must be 'linear' or 'hermite', got {bridge!r}")
    ra40 = float(rwa(np.array(0.40)))
    rb55 = float(rwb(np.array(0.55)))
    if bridge == "linear":
        mid = ra40 + (10.0 * f - 4.0) * (rb55 - ra40) / 1.5
    else:
        eps = 1e-6
        da = float(rwa(np.array(0.40 + eps)) - rwa(np.array(0.40 - eps))) / (2 * eps)
        db = float(rwb(np.array(0.55 + eps)) - rwb(np.array(0.55 - eps))) / (2 * eps)
        x = np.clip((f - 0.40) / 0.15, 0.0, 1.0)
        h00, h10 = 2 * x ** 3 - 3 * x ** 2 + 1, x ** 3 - 2 * x ** 2 + x
        h01, h11 = -2 * x ** 3 + 3 * x ** 2, x ** 3 - x ** 2
        mid = h00 * ra40 + h10 * 0.15 * da + h01 * rb55 + h11 * 0.15 * db
    r = np.where(f <= 0.40, rwa(np.minimum(f, 0.40)),
                 np.where(f >= 0.55, rwb(np.maximum(f, 0.55)), mid))
    out[pos] = r
    return out


def correlation_allowance(h: HullForm) -> float:
    """Model-ship correlation allowance C_A [HM82]:

    C_A = 0.006 (L + 100)^-0.16 - 0.00205 + 0.003 sqrt(L/7.5) C_B^4 c2 (0.04 - c4),
    c4 = T_F/L for T_F/L <= 0.04, else 0.04 (L in m);
    plus, for roughness k_s > 150 µm, ΔC_A = (0.105 k_s^(1/3) - 0.005579) / L^(1/3) (k_s, L in m).
    """
    L = h.L_WL
    c2 = _wave_constants(h)["c2"]
    c4 = min(h.T_F / L, 0.04)
    ca = 0.006 * (L + 100.0) ** -0.16 - 0.00205 + 0.003 * math.sqrt(L / 7.5) * h.C_B ** 4 * c2 * (0.04 - c4)
    if h.k_s > 150e-6:
        ca += (0.105 * h.k_s ** (1.0 / 3.0) - 0.005579) / L ** (1.0 / 3.0)
    return float(ca)


def holtrop_mennen(hull: HullForm, speed_mps, rho: float = 1025.0, nu: float = 1.19e-6,
                   g: float = 9.80665, *, wave_edition: str = "1984", form_factor_edition: str = "1984") -> dict:
    """Calm-water resistance components of ``hull`` at ``speed_mps`` (m/s, array or scalar).

    rho [kg/m^3], nu [m^2/s] (default 1.19e-6 ≈ sea water at 15 °C), g [m/s^2].
    Returns a dict of arrays shaped like ``speed_mps`` (N, W, or dimensionless):
      V, Fn, Rn, C_F, R_F (= ½ρV²S C_F, ITTC-1957), one_plus_k1 (array, constant),
      R_APP, R_W, R_B, R_TR, C_A (array, constant), R_A, R_T, P_E (= R_T V, W),
    and scalars S (bare-hull wetted area used), S_APP, one_plus_k2_eq, and ``coefficients``
    (intermediates: L_R, C_B, C_P, C_M, C_WP, c1..c17, iE_deg, lambda, m1, m3, and per-speed arrays
    m4 (or m2), P_B, Fni, FnT, c6).
    At V = 0 every resistance is 0 and C_F is NaN (no Reynolds number).
    """
    if not (rho > 0 and nu > 0 and g > 0):
        raise ValueError("rho, nu and g must be > 0")
    V = np.asarray(speed_mps, dtype=float)
    if not np.all(np.isfinite(V)) or np.any(V < 0.0):
        raise ValueError("speeds must be finite and >= 0 (ahead); the method has no astern branch")
    h = hull
    L, B, T = h.L_WL, h.B, h.T
    S = h.wetted_area
    k1, kinfo = form_factor(h, form_factor_edition)
    wk = _wave_constants(h)
    pos = V > 0.0
    Vp = np.where(pos, V, 1.0)  # placeholder where V = 0; masked below
    q = 0.5 * rho * V ** 2

    Fn = V / math.sqrt(g * L)
    Rn = V * L / nu
    with np.errstate(divide="ignore", invalid="ignore"):
        C_F = np.where(pos, ittc1957_cf(np.where(pos, Rn, 1e6)), np.nan)
    C_Fz = np.where(pos, C_F, 0.0)

    R_F = q * S * C_Fz                                             # [HM82] R_F = ½ρV²S C_F
    # appendages [HM82]: R_APP = ½ρV² S_APP (1+k2)_eq C_F + ρV²π d_TH² C_BTO
    R_APP = q * h.S_APP * h.one_plus_k2_eq * C_Fz \
        + rho * V ** 2 * math.pi * h.bow_thruster_diameter ** 2 * h.C_BTO
    R_W = wave_resistance(h, Fn, rho=rho, g=g, edition=wave_edition)

    # bulbous bow near the surface [HM82]
    if h.A_BT > 0.0:
        P_B = 0.56 * math.sqrt(h.A_BT) / (h.T_F - 1.5 * h.h_B)
        Fni = Vp / np.sqrt(g * (h.T_F - h.h_B - 0.25 * math.sqrt(h.A_BT)) + 0.15 * Vp ** 2)
        R_B = np.where(pos, 0.11 * math.exp(-3.0 * P_B ** -2) * Fni ** 3 * h.A_BT ** 1.5 * rho * g
                       / (1.0 + Fni ** 2), 0.0)
        Fni = np.where(pos, Fni, 0.0)
    else:
        P_B, Fni, R_B = 0.0, np.zeros_like(V), np.zeros_like(V)

    # immersed transom [HM82]: FnT = V / sqrt(2 g A_T / (B + B C_WP)); c6 = 0.2 (1 - 0.2 FnT), FnT < 5
    if h.A_T > 0.0:
        FnT = V / np.sqrt(2.0 * g * h.A_T / (B + B * h.C_WPc))
        c6 = np.where(FnT < 5.0, 0.2 * (1.0 - 0.2 * FnT), 0.0)
        R_TR = q * h.A_T * c6
    else:
        FnT, c6, R_TR = np.zeros_like(V), np.zeros_like(V), np.zeros_like(V)

    C_A = correlation_allowance(h)
    R_A = q * S * C_A                                              # [HM82] R_A = ½ρV²S C_A

    R_T = R_F * k1 + R_APP + R_W + R_B + R_TR + R_A
    with np.errstate(divide="ignore", invalid="ignore"):
        Fpos = np.where(pos, Fn, 1.0)
        if wave_edition == "1984":
            mcos = {"m4": np.where(pos, 0.4 * wk["c15"] * np.exp(-0.034 * Fpos ** -3.29), 0.0)}
        else:
            mcos = {"m2": np.where(pos, wk["c15"] * h.C_P ** 2 * np.exp(-0.1 * Fpos ** -2.0), 0.0)}
    coeffs = dict(wk)
    coeffs.update(kinfo)
    coeffs.update({"C_B": h.C_B, "C_P": h.C_P, "C_M": h.C_Mc, "C_WP": h.C_WPc, "P_B": P_B,
                   "Fni": Fni, "FnT": FnT, "c6": c6, "c4": min(h.T_F / L, 0.04)})
    coeffs.update(mcos)
    return {
        "V": V, "Fn": Fn, "Rn": Rn, "C_F": C_F, "R_F": R_F,
        "one_plus_k1": np.full_like(V, k1), "R_APP": R_APP, "R_W": R_W, "R_B": R_B,
        "R_TR": R_TR, "C_A": np.full_like(V, C_A), "R_A": R_A, "R_T": R_T, "P_E": R_T * V,
        "S": S, "S_APP": h.S_APP, "one_plus_k2_eq": h.one_plus_k2_eq, "coefficients": coeffs,
        "editions": {"wave": wave_edition, "form_factor": form_factor_edition},
    }


# ---------------------------------------------------------------------------------------------
# 51.5 m twin-screw naval patrol vessel (Blanke & Christensen 1993; ships.md §2)
# ---------------------------------------------------------------------------------------------
# Derivation, sources and sensitivity: models/patrol51/resistance.md. Published particulars
# [BC93] = Blanke M., Christensen A.C. (1993) "Rudder-roll damping autopilot robustness to
# sway-yaw-roll couplings", 10th Ship Control Systems Symposium, Ottawa (as tabulated in
# ships.md §2): Lpp 51.5 m, B 8.6 m, T 2.3 m, ∇ 357 m³, ρ 1014 kg/m³, KB 1.53 m, KM 4.47 m,
# LCG 20.41 m from AP, rudder area 1.5 m² (each of two), propeller D 1.6 m, nominal 8 m/s,
# X_u|u| = -1.96e3 N s²/m².

PATROL51_RHO = 1014.0                  # [BC93]
PATROL51_NOMINAL_SPEED = 8.0           # m/s [BC93]
PATROL51_XUU = -1.96e3                 # N s²/m² [BC93]
PATROL51_R_NOMINAL = -PATROL51_XUU * PATROL51_NOMINAL_SPEED ** 2  # 125 440 N


def patrol51_hullform() -> HullForm:
    """HullForm of the 51.5 m patrol vessel; the assumed numbers are argued in resistance.md.

    Published [BC93]: L, B, T, ∇, LCG (-> lcb, even keel at rest), rudder area.
    Assumed: L_WL = Lpp (transom stern, AP at the transom); C_WP 0.65 (Morrish's KB formula on the
    published KB gives 0.695; the published BM = KM - KB matched by a half-breadth family
    y = B/2 (1 - |x|^n) gives 0.61);
    C_M 0.57 (C_P 0.615, typical of fast round-bilge hulls with C_B 0.35, cf. Series 64 C_P 0.63);
    A_T = 0.40 A_M; C_stern -10 (V-shaped afterbody sections); appendage areas from typical
    proportions; 1 + k2 from [HM82]'s table.
    """
    L, B, T = 51.5, 8.6, 2.3
    C_M = 0.57
    A_M = C_M * B * T
    appendages = (
        # two balanced spade rudders behind twin screws, 1.5 m² each [BC93], wetted both sides
        Appendage("twin-screw balance rudders", 2 * 2 * 1.5, K2_TWIN_SCREW_BALANCE_RUDDERS),
        # two A-brackets, two legs each, ~0.25 m chord x 1.2 m span, wetted both sides: 4 x 0.6 m²
        Appendage("shaft brackets", 2 * 2 * 2 * 0.25 * 1.2, K2_SHAFT_BRACKETS),
        # two exposed shafts, ~0.16 m diameter x ~5.5 m: π d l each
        Appendage("shafts", 2 * math.pi * 0.16 * 5.5, 3.0),  # mid-range of [HM82] 2.0-4.0
        # bilge keels: 2 x ~15 m (0.3 L) x 0.30 m deep, wetted both faces
        Appendage("bilge keels", 2 * 2 * 15.0 * 0.30, K2_BILGE_KEELS),
    )
    return HullForm(L_WL=L, B=B, T_F=T, T_A=T, volume=357.0,
                    lcb=(20.41 - 0.5 * L) / L * 100.0,   # LCB = LCG at rest on even keel
                    C_M=C_M, C_WP=0.65, A_BT=0.0, h_B=0.0, A_T=0.40 * A_M,
                    S=None, C_stern=C_STERN_V_SECTIONS, appendages=appendages)


def patrol51_resistance_table(speeds_mps=None, nu: float = 1.19e-6, g: float = 9.80665) -> dict:
    """Calibrated resistance curve of the 51.5 m patrol vessel.

    Holtrop & Mennen (1984 editions) on ``patrol51_hullform()`` in water of ρ = 1014 kg/m³, times
    one factor so that R_T(8 m/s) = -X_u|u| 8² = 125 440 N [BC93] exactly.
    Default speeds: 0..16 m/s every 0.5 m/s plus 5, 10, ..., 30 kn.
    Returns speed_mps, speed_kn, R_T [N], P_E [W], factor, R_T_holtrop [N] (unscaled) and the
    unscaled components of holtrop_mennen (key "components").
    """
    if speeds_mps is None:
        speeds_mps = np.union1d(np.arange(0.0, 16.0 + 1e-9, 0.5),
                                KNOT * np.array([5.0, 10.0, 15.0, 20.0, 25.0, 30.0]))
    V = np.asarray(speeds_mps, dtype=float)
    hull = patrol51_hullform()
    ref = holtrop_mennen(hull, np.array([PATROL51_NOMINAL_SPEED]), rho=PATROL51_RHO, nu=nu, g=g)
    factor = PATROL51_R_NOMINAL / float(ref["R_T"][0])
    comp = holtrop_mennen(hull, V, rho=PATROL51_RHO, nu=nu, g=g)
    R_T = factor * comp["R_T"]
    return {"speed_mps": V, "speed_kn": V / KNOT, "R_T": R_T, "P_E": R_T * V, "factor": factor,
            "R_T_holtrop": comp["R_T"], "components": comp}


# ---- the curve the model uses ------------------------------------------------------------------
# [ASH] Asheville-class gunboat (Wikipedia "Asheville-class gunboat"; schnellboot.net "Typ Asheville"):
# 240 LT, 16 kn on two 750 PS cruise diesels. resistance.md derives R/W = 0.030-0.035 at that point
# (eta_D 0.55-0.65, shafting 0.97) and 215-355 kN at 30 kn for this hull (the class's turbine and diesel
# points scaled by R ~ V^1.5..2).
PS = 735.49875                          # W per metric horsepower (exact)
ASHEVILLE_DISPLACEMENT = 240.0 * 1016.0469088  # kg, 240 long tons [ASH]
ASHEVILLE_DIESEL_SPEED = 16.0 * KNOT    # m/s [ASH]
ASHEVILLE_DIESEL_POWER = 2 * 750.0 * PS  # W brake [ASH]
ETA_D_RANGE = (0.55, 0.65)              # quasi-propulsive efficiency of a fast twin-screw craft (resistance.md)
SHAFTING = 0.97                         # shaft-line and gear efficiency (resistance.md)
SEA_WATER = 1025.0                      # kg/m^3, for the Asheville's displaced volume
PATROL51_R_30KN_BAND = (215e3, 355e3)   # N at 30 kn (resistance.md, "Is the factor plausible?")


def asheville_diesel_point() -> dict:
    """The Asheville cruise-diesel point Froude-scaled to this hull.

    Equal volumetric Froude number Fn∇ = V/sqrt(g ∇^(1/3)) and equal R/W (Froude similarity; the
    viscous scale effect between two ~50 m hulls is a few per cent and is left out):
    V = V_ash (∇/∇_ash)^(1/6), R = (R/W)_ash ρ g ∇. Returns speed [m/s], Fn∇, R/W band, R band [N]
    and its centre [N].
    """
    g = 9.80665
    vol_a = ASHEVILLE_DISPLACEMENT / SEA_WATER
    W_a = ASHEVILLE_DISPLACEMENT * g
    rw = tuple(ASHEVILLE_DIESEL_POWER * SHAFTING * e / ASHEVILLE_DIESEL_SPEED / W_a for e in ETA_D_RANGE)
    vol = 357.0
    V = ASHEVILLE_DIESEL_SPEED * (vol / vol_a) ** (1.0 / 6.0)
    W = PATROL51_RHO * vol * g
    band = (rw[0] * W, rw[1] * W)
    return {"speed_mps": V, "Fn_vol": ASHEVILLE_DIESEL_SPEED / math.sqrt(g * vol_a ** (1.0 / 3.0)),
            "R_over_W": rw, "R_band": band, "R": 0.5 * (band[0] + band[1])}


def patrol51_smooth_holtrop(speeds_mps, nu: float = 1.19e-6, g: float = 9.80665) -> np.ndarray:
    """Holtrop & Mennen (1984) R_T [N] of ``patrol51_hullform()`` with its two slope jumps removed.

    [H84]'s linear bridge of R_W between Fn 0.40 and 0.55 is replaced by the C¹ Hermite bridge
    (``wave_resistance(bridge="hermite")``), and the transom term's c6 = 0.2 (1 − 0.2 FnT), cut to
    0 at FnT = 5 [HM82], by its softplus rounding 0.04 w ln(1 + exp((5 − FnT)/w)), w = 0.25
    (equal to [HM82]'s c6 within 0.04 w e^(−1/w) = 2e-4 absolute for |FnT − 5| ≥ 1, C^∞).
    Everything else is ``holtrop_mennen`` unchanged.
    """
    V = np.asarray(speeds_mps, dtype=float)
    h = patrol51_hullform()
    comp = holtrop_mennen(h, V, rho=PATROL51_RHO, nu=nu, g=g)
    rw = wave_resistance(h, comp["Fn"], rho=PATROL51_RHO, g=g, bridge="hermite")
    FnT = comp["coefficients"]["FnT"]
    w = 0.25
    c6 = 0.04 * w * np.logaddexp(0.0, (5.0 - FnT) / w)
    r_tr = 0.5 * PATROL51_RHO * V ** 2 * h.A_T * c6
    return comp["R_T"] - comp["R_W"] + rw - comp["R_TR"] + r_tr


PATROL51_BC93_LOW_SPEED = 2.0   # m/s (Fn 0.089): the speed at which the curve takes BC93's X_u|u| law
PATROL51_KNEE_WIDTH = 0.15     # width of the correction's knee in ln V (about ±15 % of V_A)


def _knee(y, w):
    """−w ln(1 + exp(−y/w)): equal to y for y ≪ −w, to 0 for y ≫ w, C^∞ (a rounded min(y, 0))."""
    return -w * np.logaddexp(0.0, -y / w)


def patrol51_resistance(speeds_mps, nu: float = 1.19e-6, g: float = 9.80665) -> dict:
    """The resistance curve the patrol51 model uses: R = F(V) R_H(V), R_H the smoothed Holtrop
    prediction (``patrol51_smooth_holtrop``, the hull-specific shape: friction, transom, wave hump)
    and F a smooth correction of its level fixed by two sources:

    - BC93's surge coefficient as a low-speed law: R(2 m/s) = 1960 × 2² N (Fn 0.089, where
      Holtrop's wave resistance is below 0.1 % of R_T);
    - the Asheville class's cruise-diesel point Froude-scaled to this hull
      (``asheville_diesel_point``: V_A = 8.81 m/s, 16.0 kn on the Asheville; R = 115.8 kN, the centre
      of its R/W band 0.030-0.035).

    ln F = c + b k(ln(V/V_A)), k = ``_knee`` (a rounded min(·, 0), width 0.15): a power law V^b
    below V_A that levels off above it, so the hump and the post-hump shape are Holtrop's (the
    30-kn value then falls in resistance.md's 215-355 kN band; checked in the tests, not fitted).
    F is C^∞ and R_H is C¹, so d ln R/d ln V is continuous.
    Returns speed_mps, speed_kn, R_T [N], P_E [W], factor F, R_T_holtrop (smoothed) [N], b, c.
    """
    V = np.asarray(speeds_mps, dtype=float)
    A = asheville_diesel_point()
    VA = A["speed_mps"]
    V0 = PATROL51_BC93_LOW_SPEED
    w = PATROL51_KNEE_WIDTH
    h0, hA = patrol51_smooth_holtrop(np.array([V0, VA]), nu=nu, g=g)
    F0 = -PATROL51_XUU * V0 ** 2 / h0
    FA = A["R"] / hA
    k0, kA = float(_knee(np.log(V0 / VA), w)), float(_knee(0.0, w))
    b = math.log(F0 / FA) / (k0 - kA)
    c = math.log(FA) - b * kA
    rh = patrol51_smooth_holtrop(V, nu=nu, g=g)
    y = np.log(np.where(V > 0.0, V, 1.0) / VA)
    F = np.exp(c + b * _knee(y, w))
    R = np.where(V > 0.0, F * rh, 0.0)
    return {"speed_mps": V, "speed_kn": V / KNOT, "R_T": R, "P_E": R * V, "factor": F,
            "R_T_holtrop": rh, "b": b, "c": c}
