"""Parametric hull form: offsets fitted to a ship's form coefficients, and its wetted-surface panel mesh.

Geometry (vtrials body axes, measured from midship): x forward from x = 0 at Lpp/2, y starboard,
z down from the calm waterline (keel at z = T). The hull has a constant draught T (flat keel line,
even keel) and

* a waterline half-breadth b(x) = B/2 f(ξ), ξ = 2x/L ∈ [−1, 1]: f = 1 on a parallel middle body
  ξ_a ≤ ξ ≤ ξ_f, f = 1 − u^p_f towards the stem (f = 0 there) and f = 1 − (1 − t) u^p_a towards the
  stern (f = t there: t > 0 is an immersed transom, closed by a flat face at the aft perpendicular);
  u ∈ [0, 1] is the normalized distance from the end of the parallel body;
* superellipse sections |y/b|^n + |z/T|^n = 1 (Lamé curves, the usual one-parameter family between
  V (n = 1) and box (n → ∞) sections) whose area fraction σ(ξ) = A(x)/(2 b T) equals the midship value
  σ_M = C_M on the parallel body and tends to σ_end at each end like 1 − u^r.

The free exponents (p_f, p_a, r) are solved so that the offsets have the model's C_WP, C_B and LCB
exactly (C_M is σ_M by construction); :func:`mesh_hydrostatics` integrates the panel mesh
independently so tests can check the mesh against the particulars. The superellipse area fraction
is σ(n) = Γ(1 + 1/n)² / Γ(1 + 2/n) (area of the Lamé curve, e.g. Weisstein, MathWorld "Superellipse").

This is a stand-in geometry, not a lines plan: it reproduces the particulars a seakeeping
computation depends on most (displacement and its longitudinal distribution, waterplane, midship
section) and nothing finer (no bulb, no stern aperture, no flare, no rise of floor).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq, least_squares
from scipy.special import gammaln

from vtrials.errors import InputError


@dataclass(frozen=True)
class HullParticulars:
    """Main dimensions and form coefficients a parametric hull is fitted to (SI; lcb from midship, + forward).

    ``parallel_fwd`` / ``parallel_aft``: extent of the parallel middle body forward / aft of midship as
    fractions of L/2; ``transom``: stern waterline half-breadth ÷ B/2 (0: no transom);
    ``sigma_stern`` / ``sigma_bow``: section area fraction σ = A/(2 b T) the sections tend to at the stern
    (transom) / stem; ``waterline_beam``: greatest beam of the waterline if less than ``beam`` (a flared
    hull whose beam ``beam`` lies above the waterline; the form coefficients stay referred to ``beam``);
    ``source``: where each number comes from.
    """

    length: float
    beam: float
    draught: float
    C_B: float
    C_M: float
    C_WP: float
    lcb: float
    parallel_fwd: float = 0.0
    parallel_aft: float = 0.0
    transom: float = 0.0
    sigma_stern: float = 0.5
    sigma_bow: float = 0.5
    waterline_beam: float | None = None
    source: str = ""

    def __post_init__(self):
        for name in ("length", "beam", "draught"):
            v = getattr(self, name)
            if not (math.isfinite(v) and v > 0.0):
                raise InputError("hull particulars", name, f"must be a positive length in metres, got {v!r}")
        for name in ("C_B", "C_M", "C_WP"):
            v = getattr(self, name)
            if not (math.isfinite(v) and 0.0 < v <= 1.0):
                raise InputError("hull particulars", name, f"must be in (0, 1], got {v!r}")
        if not self.C_B < min(self.C_M, self.C_WP):
            raise InputError("hull particulars", "C_B",
                             f"must be below C_M ({self.C_M}) and C_WP ({self.C_WP}), got {self.C_B}")
        if not abs(self.lcb) < 0.25 * self.length:
            raise InputError("hull particulars", "lcb", f"must lie within ±L/4 of midship, got {self.lcb!r} m")
        for name in ("parallel_fwd", "parallel_aft", "transom"):
            v = getattr(self, name)
            if not (0.0 <= v < 1.0):
                raise InputError("hull particulars", name, f"must be in [0, 1), got {v!r}")
        if self.waterline_beam is not None and not (0.5 * self.beam <= self.waterline_beam <= self.beam):
            raise InputError("hull particulars", "waterline_beam",
                             f"must be between B/2 and B = {self.beam} m, got {self.waterline_beam!r}")
        if not self.sigma_midship < 1.0:
            raise InputError("hull particulars", "C_M",
                             f"C_M B / B_WL = {self.sigma_midship:.4f} must be below 1 (C_M {self.C_M})")
        for name in ("sigma_stern", "sigma_bow"):
            v = getattr(self, name)
            if not (0.2 < v < 1.0):
                raise InputError("hull particulars", name, f"must be in (0.2, 1), got {v!r}")

    @property
    def b_wl(self) -> float:
        """Greatest waterline beam [m]."""
        return self.beam if self.waterline_beam is None else self.waterline_beam

    @property
    def sigma_midship(self) -> float:
        """Midship section area ÷ (B_WL T) = C_M B / B_WL."""
        return self.C_M * self.beam / self.b_wl

    @property
    def volume(self) -> float:
        """Displaced volume C_B L B T [m³]."""
        return self.C_B * self.length * self.beam * self.draught


@dataclass(frozen=True)
class HullForm:
    """A fitted parametric hull: particulars plus the solved exponents (see module docstring)."""

    particulars: HullParticulars
    p_fwd: float
    p_aft: float
    r_section: float


@dataclass(frozen=True)
class HullMesh:
    """Panel mesh of the starboard half (y ≥ 0) of the wetted surface, body axes from midship, z down.

    ``vertices`` (n, 3) [m]; ``faces`` (m, 4) vertex indices of quadrilaterals ordered so that the
    normal (v1 − v0) × (v3 − v0) points out of the hull into the water.
    """

    vertices: np.ndarray
    faces: np.ndarray

    @property
    def n_panels(self) -> int:
        return int(self.faces.shape[0])


# --------------------------------------------------------------------------------------------------
# offsets


def superellipse_area_fraction(n):
    """Area of |y|^n + |z|^n ≤ 1 in the quadrant ÷ 1: Γ(1 + 1/n)² / Γ(1 + 2/n)."""
    n = np.asarray(n, dtype=float)
    return np.exp(2.0 * gammaln(1.0 + 1.0 / n) - gammaln(1.0 + 2.0 / n))


def superellipse_exponent(sigma: float) -> float:
    """Exponent n of the Lamé section with area fraction ``sigma`` (0.2 < σ < 0.9999)."""
    if not (0.2 < sigma < 0.9999):
        raise InputError("hull form", "section area fraction", f"must be in (0.2, 0.9999), got {sigma!r}")
    return brentq(lambda n: float(superellipse_area_fraction(n)) - sigma, 0.55, 5000.0, xtol=1e-12)


def _u(xi, start, end_sign):
    """Normalized distance ∈ [0, 1] from the end of the parallel body (at ``start``) towards the end."""
    if end_sign > 0:
        return np.clip((xi - start) / (1.0 - start), 0.0, 1.0)
    return np.clip((-xi - start) / (1.0 - start), 0.0, 1.0)


def waterline_fraction(xi, hp: HullParticulars, p_fwd: float, p_aft: float):
    """f(ξ) = b(x) / (B/2)."""
    xi = np.asarray(xi, dtype=float)
    uf = _u(xi, hp.parallel_fwd, +1)
    ua = _u(xi, hp.parallel_aft, -1)
    return np.where(xi >= 0.0, 1.0 - uf ** p_fwd, 1.0 - (1.0 - hp.transom) * ua ** p_aft)


def section_fraction(xi, hp: HullParticulars, r: float):
    """σ(ξ) = A(x) / (2 b(x) T)."""
    xi = np.asarray(xi, dtype=float)
    uf = _u(xi, hp.parallel_fwd, +1)
    ua = _u(xi, hp.parallel_aft, -1)
    sm = hp.sigma_midship
    return np.where(xi >= 0.0, sm + (hp.sigma_bow - sm) * uf ** r, sm + (hp.sigma_stern - sm) * ua ** r)


def _offset_coefficients(hp: HullParticulars, p_fwd, p_aft, r, n=4001):
    """(C_WP, C_B, lcb/L) of the analytic offsets (dense trapezoid rule), referred to L, B, T."""
    xi = np.linspace(-1.0, 1.0, n)
    f = waterline_fraction(xi, hp, p_fwd, p_aft)
    s = section_fraction(xi, hp, r)
    k = hp.b_wl / hp.beam
    cwp = 0.5 * k * np.trapezoid(f, xi)
    a = f * s
    cb = 0.5 * k * np.trapezoid(a, xi)
    lcb = 0.5 * np.trapezoid(xi * a, xi) / np.trapezoid(a, xi)   # (x/L) = ξ/2
    return cwp, cb, lcb


def fit_hullform(hp: HullParticulars) -> HullForm:
    """Solve the exponents so that the offsets have C_WP, C_B and LCB of ``hp`` (to 1e-6 relative)."""
    target = np.array([hp.C_WP, hp.C_B, hp.lcb / hp.length])

    def resid(q):
        pf, pa, r = np.exp(q)
        cwp, cb, lcb = _offset_coefficients(hp, pf, pa, r)
        return np.array([cwp / hp.C_WP - 1.0, cb / hp.C_B - 1.0, lcb - target[2]])

    best = None
    for q0 in ([math.log(2.0), math.log(2.0), math.log(1.0)], [math.log(4.0), math.log(1.5), math.log(0.5)],
               [math.log(1.5), math.log(4.0), math.log(3.0)]):
        sol = least_squares(resid, q0, bounds=([math.log(0.3)] * 3, [math.log(40.0)] * 3), xtol=1e-14,
                            ftol=1e-14, gtol=1e-14)
        if best is None or sol.cost < best.cost:
            best = sol
    err = np.max(np.abs(resid(best.x)))
    if err > 1e-6:
        raise InputError("hull particulars", "C_WP/C_B/lcb",
                         f"no hull of this family has C_WP {hp.C_WP}, C_B {hp.C_B}, LCB {hp.lcb} m "
                         f"with C_M {hp.C_M} and B_WL {hp.b_wl} m (best misfit {err:.2e}); change the parallel body or transom")
    pf, pa, r = np.exp(best.x)
    return HullForm(hp, float(pf), float(pa), float(r))


def offsets(form: HullForm, xi):
    """Waterline half-breadth b [m], section area fraction σ and superellipse exponent n at stations ξ."""
    hp = form.particulars
    f = waterline_fraction(xi, hp, form.p_fwd, form.p_aft)
    s = section_fraction(xi, hp, form.r_section)
    n = np.array([superellipse_exponent(float(min(max(si, 0.2001), 0.9998))) for si in np.atleast_1d(s)])
    return 0.5 * hp.b_wl * f, s, n


# --------------------------------------------------------------------------------------------------
# mesh


def _section_points(b, T, n, m):
    """m + 1 points of the quarter Lamé section from the waterline (y = b, z = 0) to the keel (0, T),
    equally spaced in arc length (from a dense polyline)."""
    t = np.linspace(0.0, 0.5 * np.pi, 2001)
    c, s = np.cos(t), np.sin(t)
    y = b * np.abs(c) ** (2.0 / n)
    z = T * np.abs(s) ** (2.0 / n)
    y[-1], z[-1], y[0], z[0] = 0.0, T, b, 0.0
    ds = np.hypot(np.diff(y), np.diff(z))
    arc = np.concatenate([[0.0], np.cumsum(ds)])
    if arc[-1] <= 0.0:
        return np.zeros(m + 1), np.linspace(0.0, T, m + 1)
    target = np.linspace(0.0, arc[-1], m + 1)
    return np.interp(target, arc, y), np.interp(target, arc, z)


def station_positions(n_stations: int, cluster: float = 0.5):
    """ξ of the stations: half uniform, half sine-clustered towards both ends (``cluster`` = weight of the
    sine mapping), midship (ξ = 0) always a station."""
    half_f = n_stations // 2
    half_a = n_stations - half_f

    def one_side(n):
        u = np.linspace(0.0, 1.0, n + 1)
        return (1.0 - cluster) * u + cluster * np.sin(0.5 * np.pi * u)

    return np.concatenate([-one_side(half_a)[::-1][:-1], one_side(half_f)])


def hull_mesh(form: HullForm, n_stations: int = 40, n_girth: int = 12) -> HullMesh:
    """Quadrilateral panel mesh of the starboard half wetted surface (plus the transom face if any).

    ``n_stations`` intervals along the length, ``n_girth`` along each section from waterline to keel;
    panels: n_stations × n_girth (+ n_girth on a transom).
    """
    if n_stations < 6 or n_girth < 3:
        raise InputError("hull mesh", "n_stations/n_girth", f"need ≥ 6 and ≥ 3, got {n_stations}, {n_girth}")
    hp = form.particulars
    xi = station_positions(n_stations)
    x = 0.5 * hp.length * xi
    b, _, n = offsets(form, xi)
    m = n_girth
    verts = np.zeros((xi.size, m + 1, 3))
    for i in range(xi.size):
        y, z = _section_points(b[i], hp.draught, n[i], m)
        verts[i, :, 0] = x[i]
        verts[i, :, 1] = y
        verts[i, :, 2] = z
    idx = np.arange(xi.size * (m + 1)).reshape(xi.size, m + 1)
    faces = []
    for i in range(xi.size - 1):
        for j in range(m):
            # j → j+1 goes down the girth (waterline to keel), i → i+1 goes forward; with z down and y
            # starboard, (down the girth) × (forward) points out of the starboard side.
            faces.append([idx[i, j], idx[i, j + 1], idx[i + 1, j + 1], idx[i + 1, j]])
    V = verts.reshape(-1, 3)
    if hp.transom > 0.0:
        # flat transom face at the aft end: each strip between the section curve and the centreline
        # cut into columns about as wide as the girth spacing (quads from the curve inwards)
        y0, z0 = verts[0, :, 1], verts[0, :, 2]
        girth = float(np.sum(np.hypot(np.diff(y0), np.diff(z0)))) / m
        n_col = max(1, int(math.ceil(float(y0[0]) / girth)))
        frac = np.linspace(1.0, 0.0, n_col + 1)[1:]            # inner columns, towards the centreline
        base = V.shape[0]
        inner = np.stack([np.column_stack([np.full(m + 1, x[0]), f * y0, z0]) for f in frac])  # (n_col, m+1, 3)
        V = np.vstack([V, inner.reshape(-1, 3)])
        col = [idx[0]] + [base + c * (m + 1) + np.arange(m + 1) for c in range(n_col)]
        for c in range(n_col):
            a, b = col[c], col[c + 1]
            for j in range(m):
                faces.append([a[j], b[j], b[j + 1], a[j + 1]])   # normal aft
    F = np.asarray(faces, dtype=np.int64)
    mesh = HullMesh(V, F)
    return _drop_degenerate(mesh)


def _drop_degenerate(mesh: HullMesh, tol: float = 1e-10) -> HullMesh:
    a = _quad_area_vectors(mesh.vertices, mesh.faces)
    keep = np.linalg.norm(a, axis=1) > tol * max(1.0, float(np.max(np.linalg.norm(a, axis=1))))
    return HullMesh(mesh.vertices, mesh.faces[keep])


def _quad_area_vectors(V, F):
    p = V[F]
    return 0.5 * np.cross(p[:, 2] - p[:, 0], p[:, 3] - p[:, 1])


def _triangles(V, F):
    """Split quads (v0 v1 v2 v3) into triangles (v0 v1 v2), (v0 v2 v3): arrays (2m, 3, 3)."""
    p = V[F]
    return np.concatenate([p[:, [0, 1, 2]], p[:, [0, 2, 3]]])


def mesh_hydrostatics(mesh: HullMesh, symmetric: bool = True) -> dict:
    """Integrals of the wetted-surface mesh by the divergence theorem (whole hull if ``symmetric``).

    The open surface is closed by the waterplane z = 0 and the centreplane y = 0, on which the
    integrands below vanish or have n_z = 0, so (n outward, z down; Gauss's theorem):
    ∇ = ∫ z n_z dS, ∇ x_B = ∫ x z n_z dS, ∇ z_B = ∫ ½ z² n_z dS, A_wp = ∫ n_z dS,
    A_wp x_F = ∫ x n_z dS, I_T = ∫ y² n_z dS (waterplane, about the centreline),
    I_L = ∫ (x − x_F)² n_z dS. Exact on the flat-triangle surface (quadratic integrands by the
    edge-midpoint rule). Returns volume, x_B, z_B, KB, waterplane_area, x_F, I_T, I_L, BM_T, BM_L,
    wetted_area and draught.
    """
    tri = _triangles(mesh.vertices, mesh.faces)
    av = 0.5 * np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])   # area vector = n dS
    mid = 0.5 * (tri[:, [0, 1, 2]] + tri[:, [1, 2, 0]])                  # edge midpoints
    cen = tri.mean(axis=1)
    nz = av[:, 2]

    def quad_int(fun):   # ∫ fun dS n_z over each triangle, fun quadratic: edge-midpoint rule
        return np.sum(nz * np.mean(fun(mid), axis=1))

    vol = np.sum(nz * cen[:, 2])
    mx = quad_int(lambda q: q[..., 0] * q[..., 2])
    mz = quad_int(lambda q: 0.5 * q[..., 2] ** 2)
    awp = np.sum(nz)
    sx = np.sum(nz * cen[:, 0])
    it = quad_int(lambda q: q[..., 1] ** 2)
    ixx = quad_int(lambda q: q[..., 0] ** 2)
    wet = np.sum(np.linalg.norm(av, axis=1))
    k = 2.0 if symmetric else 1.0
    vol, mx, mz, awp, sx, it, ixx, wet = (k * v for v in (vol, mx, mz, awp, sx, it, ixx, wet))
    # a half hull's I_T about the centreline is half the whole one's; the factor 2 above gives it
    x_F = sx / awp
    I_L = ixx - awp * x_F ** 2
    T = float(np.max(mesh.vertices[:, 2]))
    z_B = mz / vol
    return {"volume": vol, "x_B": mx / vol, "z_B": z_B, "KB": T - z_B, "waterplane_area": awp,
            "x_F": x_F, "I_T": it, "I_L": I_L, "BM_T": it / vol, "BM_L": I_L / vol,
            "wetted_area": wet, "draught": T}


def section_area(form: HullForm, x: float, n_girth: int = 200) -> float:
    """Area of the section at x [m from midship] from its offsets polygon (both sides) [m²]."""
    hp = form.particulars
    b, _, n = offsets(form, np.array([2.0 * x / hp.length]))
    y, z = _section_points(float(b[0]), hp.draught, float(n[0]), n_girth)
    # polygon (waterline → keel along the section, back along the centreline): shoelace
    yy = np.concatenate([y, [0.0]])
    zz = np.concatenate([z, [0.0]])
    return float(abs(np.sum(yy * np.roll(zz, -1) - np.roll(yy, -1) * zz))) * 0.5 * 2.0


def mesh_section_area(mesh: HullMesh, x: float, tol: float = 1e-9) -> float:
    """Area of the mesh's station polygon at x (both sides; the station must be a mesh station) [m²]."""
    V = mesh.vertices
    on = np.abs(V[:, 0] - x) < tol
    if not np.any(on):
        raise InputError("hull mesh", "x", f"no mesh station at x = {x} m")
    pts = V[on]
    pts = pts[np.argsort(pts[:, 2], kind="stable")]   # waterline → keel (z rises along the girth)
    y, z = pts[:, 1], pts[:, 2]
    yy = np.concatenate([y, [0.0]])
    zz = np.concatenate([z, [0.0]])
    return float(abs(np.sum(yy * np.roll(zz, -1) - np.roll(yy, -1) * zz)))


def mirror(mesh: HullMesh) -> HullMesh:
    """Whole hull: the starboard half plus its port image (y → −y, faces reversed to stay outward)."""
    V = mesh.vertices
    Vp = V * np.array([1.0, -1.0, 1.0])
    Fp = mesh.faces[:, ::-1] + V.shape[0]
    return HullMesh(np.vstack([V, Vp]), np.vstack([mesh.faces, Fp]))


_HULL_FIELDS = ("length", "beam", "draught", "displacement", "C_M", "C_WP", "lcb", "parallel_fwd",
                "parallel_aft", "transom", "sigma_stern", "sigma_bow", "waterline_beam")
_HULL_REQUIRED = ("length", "beam", "draught", "displacement", "C_M", "C_WP", "lcb")


def hull_particulars_from_table(table: dict, file: str = "hull.toml") -> HullParticulars:
    """HullParticulars from the ``[hull]`` table of a model's ``hydro/hull.toml`` (values plain or
    ``{ value, source }``; every entry must name its source). C_B = displacement / (L B T)."""
    vals, sources = {}, []
    for key, item in table.items():
        if key not in _HULL_FIELDS:
            raise InputError(file, f"hull.{key}", f"unknown field (allowed: {', '.join(_HULL_FIELDS)})")
        if not (isinstance(item, dict) and "value" in item and isinstance(item.get("source"), str)):
            raise InputError(file, f"hull.{key}", "must be { value = <number>, source = \"<where it comes from>\" }")
        v = item["value"]
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            raise InputError(file, f"hull.{key}.value", f"must be a number, got {v!r}")
        vals[key] = float(v)
        sources.append(f"{key}: {item['source']}")
    for key in _HULL_REQUIRED:
        if key not in vals:
            raise InputError(file, f"hull.{key}", "missing (required: " + ", ".join(_HULL_REQUIRED) + ")")
    disp = vals.pop("displacement")
    if not disp > 0.0:
        raise InputError(file, "hull.displacement", f"must be a positive volume in m³, got {disp}")
    cb = disp / (vals["length"] * vals["beam"] * vals["draught"])
    return HullParticulars(C_B=cb, source="; ".join(sources), **vals)
