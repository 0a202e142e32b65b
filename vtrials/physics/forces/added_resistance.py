"""Mean added resistance in waves at forward speed: the SNNM semi-empirical method, per wave component.

Source: Liu S., Papanikolaou A. (2020), "Regression analysis of experimental data for added resistance
in waves of arbitrary heading and development of a semi-empirical formula", Ocean Engineering 206,
107357 ("SNNM", all headings from head to following seas). Symbols as there: L = L_pp, B, T (mean
draught), T_f, T_a (draughts at the perpendiculars), C_B, k_yy (pitch radius of gyration ÷ L),
E₁ = atan(0.495 B / L_E), E₂ = atan(0.495 B / L_R) the half angles of the waterline at bow and stern
(L_E, L_R the lengths of entrance and run: from the FP / AP to where the waterline reaches 99 % of B),
α the wave heading relative to the ship (π = head seas, 0 = following; symmetric port/starboard),
Fn = U/√(gL), λ = 2π/k the wavelength, c = ω/k the phase speed. Regular wave of amplitude ζ:

    R_AW = R_AWR + R_AWM  [N], opposing the ship's motion (force −R_AW along the ship's x axis);

* motion (radiation) part:
      R_AWM = 4 ρ g ζ² (B²/L) ω̄^{b₁} exp[(b₁/d₁)(1 − ω̄^{d₁})] a₁ a₂ a₃,
      ω̄ = 2.142 k_yy^{1/3} √(L/λ) [1 − (0.111/C_B)(ln(B/T) − ln 2.75)] (C_B/0.65)^{0.17}
          × [(−1.377 Fn² + 1.157 Fn)|cos α| + 0.618 (13 + cos 2α)/14],
      a₁ = 60.3 C_B^{1.34} (4 k_yy)² (0.87/C_B)^{−(1+Fn) cos α} (ln(B/T))^{−1} (1 − 2 cos α)/3   (π/2 ≤ α ≤ π),
      a₂ = 0.0072 + 0.1676 Fn (Fn < 0.12), Fn^{1.5} exp(−3.5 Fn) (Fn ≥ 0.12),
      a₃ = 1 + 28.7 atan(|T_a − T_f|/L),
      b₁ = 11, d₁ = 566 (L C_B/B)^{−2.66} for ω̄ < 1; b₁ = −8.5, d₁ = −566 (L/B)^{−2.66} (4 − 125 atan(|T_a − T_f|/L)) for ω̄ ≥ 1;
  following seas (α = 0) by the ship's speed against the wave's phase speed: U = 0 the formula at
  α = 0 (a₁ < 0: the waves push the ship along); U = c/4 a₁ = 0, a₂ = a₂(Fn); U = c/2 the head-sea
  a₁ (cos α = −1) at Fn = 0, a₂ = 0.0072; U > c/2 head-sea a₁, a₂ at Fn' = (U − c/2)/√(gL); linear
  in U between these points; for 0 < α < π/2 a₁, a₂ linear in α between α = π/2 and α = 0; where
  ω̄ ≤ 0 (Fn ≳ 1.2, far outside the regression) the motion part is taken as zero;
* reflection (diffraction) part, per unit ζ²: R_AWR = ρ g (2.25/4) B α_T Σ s_i, with
      s₁ = [sin²(E₁ − α) + (2ωU/g)(cos E₁ cos(E₁ − α) − cos α)] (0.87/C_B)^{(1+4√Fn) f(α)}   (E₁ ≤ α ≤ π),
      s₂ = [sin²(E₁ + α) + (2ωU/g)(cos E₁ cos(E₁ + α) − cos α)] (0.87/C_B)^{(1+4√Fn) f(α)}   (π − E₁ ≤ α ≤ π),
      s₃ = −[sin²(E₂ + α) + (2ωU/g)(cos E₂ cos(E₂ + α) − cos α)]   (0 ≤ α ≤ π − E₂),
      s₄ = −[sin²(E₂ − α) + (2ωU/g)(cos E₂ cos(E₂ − α) − cos α)]   (0 ≤ α ≤ E₂),
      f(α) = −cos α for α ≥ π − E₁, else 0;
      α_T = 1 − exp[−4π (T*/λ − T*/(2.5 L))] for λ/L ≤ 2.5, else 0; T* = T for the bow segments,
      T (4 + √|cos α|)/5 (C_B ≤ 0.75) or T (2 + √|cos α|)/3 (C_B > 0.75) for the stern segments.

The coefficients were read from the paper's formulas as reproduced in public implementations; the
paper itself was not at hand here (see the report of the change). SNNM was regressed on hulls with
C_B ≈ 0.5–0.9; patrol51 (C_B 0.35) is outside that range, so for it the method is an engineering
estimate, not a validated prediction.

In irregular seas the mean is Σ_j a_j² R_AW(ω_j, α_j, U)/ζ² over the components (each component a
regular wave of amplitude a_j; the cross terms average out), the time-domain form of the spectral
integral R̄ = 2 ∫∫ S(ω) D(μ) R_AW/ζ² dω dμ (ITTC 7.5-04-01-01.1 §10.3.2 for the integral). α_j and U
are the instantaneous ones (the ship turns, slows, accelerates).

Why SNNM here and not STAWAVE-2: the trials team's reduction corrects for waves with STAWAVE-2
(:mod:`vtrials.reduce.stawave`); a simulated sea built on the same formula would make the correction
trivially exact. Only the surge force is modelled; the database's zero-speed drift keeps the sway force
and yaw moment (:func:`vtrials.scenario.sea_vessel`, ``mean_force = "snnm"``).

Parameter block: [n, L, B, T, T_f, T_a, C_B, k_yy, E₁, E₂, ρ, g, then per component a², ω, k, cos μ, sin μ].
"""

from __future__ import annotations

import dataclasses
import math
import tomllib
from pathlib import Path

import numba as nb
import numpy as np

from vtrials.errors import InputError
from vtrials.physics.forces import context as L
from vtrials.physics.forces.registry import register

NHEAD = 12
NCOMP = 5
WATERLINE_FRACTION = 0.99  # L_E, L_R: to where the waterline reaches 99 % of B (Liu & Papanikolaou 2020)


@dataclasses.dataclass(frozen=True)
class SNNMHull:
    """The hull data SNNM needs (SI; k_yy ÷ L, dimensionless). ``source``: where each number comes from."""

    length: float
    beam: float
    draught: float
    draught_fore: float
    draught_aft: float
    C_B: float
    k_yy: float
    entrance_length: float
    run_length: float
    rho: float
    g: float = 9.80665
    source: str = ""

    def __post_init__(self):
        for name in ("length", "beam", "draught", "draught_fore", "draught_aft", "entrance_length",
                     "run_length", "rho", "g"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0.0):
                raise InputError("SNNMHull", name, f"must be a positive finite number (SI), got {v!r}")
        if not (0.0 < self.C_B < 1.0):
            raise InputError("SNNMHull", "C_B", f"must be in (0, 1), got {self.C_B!r}")
        if not (0.05 < self.k_yy < 0.5):
            raise InputError("SNNMHull", "k_yy", f"pitch radius of gyration ÷ L must be in (0.05, 0.5), got {self.k_yy!r}")
        if not self.beam > self.draught:
            raise InputError("SNNMHull", "beam", f"B/T must exceed 1 (ln(B/T) divides a₁), got B {self.beam}, T {self.draught}")

    @property
    def E1(self) -> float:
        return math.atan(0.495 * self.beam / self.entrance_length)

    @property
    def E2(self) -> float:
        return math.atan(0.495 * self.beam / self.run_length)

    def header(self) -> np.ndarray:
        return np.array([self.length, self.beam, self.draught, self.draught_fore, self.draught_aft, self.C_B,
                         self.k_yy, self.E1, self.E2, self.rho, self.g], dtype=np.float64)


def snnm_hull(vessel) -> SNNMHull:
    """SNNM data of a vessel model: L, B, T, C_B = ∇/(L B T), ρ from ship.toml, k_yy from its
    [inertia] (÷ L), even keel (T_f = T_a = T: the models carry no trim), and L_E, L_R from the
    waterline of the parametric hull in ``hydro/hull.toml`` (:mod:`vtrials.physics.seakeeping.hullform`,
    where the waterline half-breadth reaches 99 % of B/2)."""
    from vtrials.physics.seakeeping import hullform as hf
    hull_file = Path(vessel.folder) / "hydro" / "hull.toml"
    if not hull_file.is_file():
        raise InputError(str(hull_file), "", f"{vessel.name} has no hull form file for the added-resistance "
                                             f"method (SNNM needs the waterline's entrance and run)")
    hp = hf.hull_particulars_from_table(tomllib.loads(hull_file.read_text())["hull"], str(hull_file))
    form = hf.fit_hullform(hp)
    xi = np.linspace(-1.0, 1.0, 200001)
    f = hf.waterline_fraction(xi, hp, form.p_fwd, form.p_aft) * hp.b_wl / hp.beam
    full = np.nonzero(f >= WATERLINE_FRACTION)[0]
    le = 0.5 * hp.length * (1.0 - xi[full[-1]])
    lr = 0.5 * hp.length * (1.0 + xi[full[0]])
    p = vessel.particulars
    return SNNMHull(length=p.length, beam=p.beam, draught=p.draught, draught_fore=p.draught, draught_aft=p.draught,
                    C_B=p.displacement / (p.length * p.beam * p.draught), k_yy=vessel.inertia.k_yy / p.length,
                    entrance_length=float(le), run_length=float(lr), rho=p.water_density,
                    source=f"{vessel.toml_path} (L, B, T, ∇, ρ, k_yy); {hull_file} waterline (L_E, L_R)")


def pack(hull: SNNMHull, components: np.ndarray) -> np.ndarray:
    """Parameter block for ``hull`` and wave components (n, 6) of :mod:`vtrials.physics.environment.waves`."""
    comp = np.asarray(components, dtype=np.float64)
    if comp.ndim != 2 or comp.shape[1] != 6 or not np.all(np.isfinite(comp)):
        raise InputError("waves", "components", f"must be a finite (n, 6) array, got shape {comp.shape}")
    if np.any(comp[:, 1] <= 0.0) or np.any(comp[:, 2] <= 0.0):
        raise InputError("waves", "components", "frequencies and wavenumbers must be positive")
    rows = np.stack([comp[:, 0] ** 2, comp[:, 1], comp[:, 2], comp[:, 3], comp[:, 4]], axis=1)
    return np.concatenate([np.array([comp.shape[0]], dtype=np.float64), hull.header(), rows.ravel()])


@nb.njit(cache=True)
def _a2(fn):
    if fn < 0.12:
        return 0.0072 + 0.1676 * fn
    return fn ** 1.5 * math.exp(-3.5 * fn)


@nb.njit(cache=True)
def _a1(cos_a, fn, cb, kyy, ln_bt):
    return (60.3 * cb ** 1.34 * (4.0 * kyy) ** 2 * (0.87 / cb) ** (-(1.0 + fn) * cos_a)
            / ln_bt * (1.0 - 2.0 * cos_a) / 3.0)


@nb.njit(cache=True)
def _a12_following(U, c, fn, sq_gl, cb, kyy, ln_bt):
    """a₁, a₂ at α = 0 (following seas) by U against the phase speed c (see the module docstring)."""
    if U <= 0.0:
        return _a1(1.0, 0.0, cb, kyy, ln_bt), 0.0072
    q = 0.25 * c
    h = 0.5 * c
    if U <= q:
        t = U / q
        return (1.0 - t) * _a1(1.0, 0.0, cb, kyy, ln_bt), (1.0 - t) * 0.0072 + t * _a2(fn)
    if U <= h:
        t = (U - q) / (h - q)
        return t * _a1(-1.0, 0.0, cb, kyy, ln_bt), (1.0 - t) * _a2(fn) + t * 0.0072
    fn2 = (U - h) / sq_gl
    return _a1(-1.0, fn2, cb, kyy, ln_bt), _a2(fn2)


@nb.njit(cache=True)
def _alpha_T(Tst, lam, Lpp):
    if lam / Lpp > 2.5:
        return 0.0
    return 1.0 - math.exp(-4.0 * math.pi * (Tst / lam - Tst / (2.5 * Lpp)))


@nb.njit(cache=True)
def _segment(E, ang, two_wug, cos_a):
    return math.sin(ang) ** 2 + two_wug * (math.cos(E) * math.cos(ang) - cos_a)


@nb.njit(cache=True)
def raw_regular(h, omega, k, alpha, U):
    """R_AW/ζ² [N/m²] of one regular wave: h the header (:meth:`SNNMHull.header`), ω [rad/s], k [rad/m],
    α ∈ [0, π] [rad] (π head seas), U [m/s] (clipped at 0: SNNM is for ahead speeds)."""
    Lpp, B, T, Tf, Ta, cb, kyy, E1, E2, rho, g = h[0], h[1], h[2], h[3], h[4], h[5], h[6], h[7], h[8], h[9], h[10]
    if U < 0.0:
        U = 0.0
    sq_gl = math.sqrt(g * Lpp)
    fn = U / sq_gl
    lam = 2.0 * math.pi / k
    c = omega / k
    cos_a = math.cos(alpha)
    ln_bt = math.log(B / T)
    trim = math.atan(abs(Ta - Tf) / Lpp)
    # motion part
    if alpha >= 0.5 * math.pi:
        a1 = _a1(cos_a, fn, cb, kyy, ln_bt)
        a2 = _a2(fn)
    else:
        a1b = _a1(0.0, fn, cb, kyy, ln_bt)
        a2b = _a2(fn)
        a1f, a2f = _a12_following(U, c, fn, sq_gl, cb, kyy, ln_bt)
        t = alpha / (0.5 * math.pi)
        a1 = (1.0 - t) * a1f + t * a1b
        a2 = (1.0 - t) * a2f + t * a2b
    a3 = 1.0 + 28.7 * trim
    wbar = (2.142 * kyy ** (1.0 / 3.0) * math.sqrt(Lpp / lam) * (1.0 - 0.111 / cb * (ln_bt - math.log(2.75)))
            * (cb / 0.65) ** 0.17 * ((-1.377 * fn * fn + 1.157 * fn) * abs(cos_a)
                                     + 0.618 * (13.0 + math.cos(2.0 * alpha)) / 14.0))
    if wbar <= 0.0:          # far beyond the regression's speeds (Fn ≳ 1.2): no motion part
        wbar = 0.0
        b1 = 11.0
        d1 = 1.0
    elif wbar < 1.0:
        b1 = 11.0
        d1 = 566.0 * (Lpp * cb / B) ** (-2.66)
    else:
        b1 = -8.5
        d1 = -566.0 * (Lpp / B) ** (-2.66) * (4.0 - 125.0 * trim)
    r_m = 0.0
    if wbar > 0.0:
        r_m = 4.0 * rho * g * B * B / Lpp * wbar ** b1 * math.exp(b1 / d1 * (1.0 - wbar ** d1)) * a1 * a2 * a3
    # reflection part
    two_wug = 2.0 * omega * U / g
    f = -cos_a if alpha >= math.pi - E1 else 0.0
    bow_f = (0.87 / cb) ** ((1.0 + 4.0 * math.sqrt(fn)) * f)
    s = 0.0
    aT_bow = _alpha_T(T, lam, Lpp)
    if alpha >= E1:
        s += aT_bow * _segment(E1, E1 - alpha, two_wug, cos_a) * bow_f
    if alpha >= math.pi - E1:
        s += aT_bow * _segment(E1, E1 + alpha, two_wug, cos_a) * bow_f
    if alpha <= math.pi - E2 or alpha <= E2:
        if cb <= 0.75:
            Tst = T * (4.0 + math.sqrt(abs(cos_a))) / 5.0
        else:
            Tst = T * (2.0 + math.sqrt(abs(cos_a))) / 3.0
        aT_st = _alpha_T(Tst, lam, Lpp)
        if alpha <= math.pi - E2:
            s -= aT_st * _segment(E2, E2 + alpha, two_wug, cos_a)
        if alpha <= E2:
            s -= aT_st * _segment(E2, E2 - alpha, two_wug, cos_a)
    r_r = rho * g * 2.25 / 4.0 * B * s
    return r_m + r_r


def regular(hull: SNNMHull, omega, alpha, U, k=None) -> np.ndarray:
    """R_AW/ζ² [N/m²] on arrays (broadcast) of ω [rad/s], α [rad] (any sign: |α| folded into [0, π]),
    U [m/s]; k [rad/m] default deep water ω²/g."""
    omega, alpha, U = np.broadcast_arrays(np.asarray(omega, float), np.asarray(alpha, float), np.asarray(U, float))
    k = omega ** 2 / hull.g if k is None else np.broadcast_to(np.asarray(k, float), omega.shape)
    a = np.abs(np.remainder(alpha + np.pi, 2.0 * np.pi) - np.pi)
    out = np.empty(omega.shape)
    _regular_many(hull.header(), np.ascontiguousarray(omega).ravel(), np.ascontiguousarray(k).ravel(),
                  np.ascontiguousarray(a).ravel(), np.ascontiguousarray(U).ravel(), out.reshape(-1))
    return out


@nb.njit(cache=True)
def _regular_many(h, omega, k, a, U, out):
    for i in range(omega.size):
        out[i] = raw_regular(h, omega[i], k[i], a[i], U[i])


@nb.njit(cache=True, fastmath=False)
def added_resistance_kernel(p, s, env, ctx, aux, w):
    n = int(p[0])
    h = p[1:1 + NHEAD - 1]
    U = ctx[L.NU_R]
    psi = ctx[L.EUL + 2]
    cp = math.cos(psi)
    sp = math.sin(psi)
    R = 0.0
    base = NHEAD
    for c in range(n):
        q = base + NCOMP * c
        cm = p[q + 3]
        sm = p[q + 4]
        b = abs(math.atan2(sm * cp - cm * sp, cm * cp + sm * sp))     # |μ − ψ| in [0, π]
        R += p[q] * raw_regular(h, p[q + 1], p[q + 2], b, U)
    # −R along the ship's horizontal heading, turned into body axes
    fn = -R * cp
    fe = -R * sp
    for k in range(3):
        w[k] = ctx[L.ROT + k] * fn + ctx[L.ROT + 3 + k] * fe
        w[3 + k] = 0.0


ADDED_RESISTANCE_COMPONENT = register("added_resistance", added_resistance_kernel)
