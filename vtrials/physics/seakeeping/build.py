"""Offline builder of a ship's frequency-domain hydrodynamic database with Capytaine.

Run ``python -m vtrials.physics.seakeeping.build <ship> [<ship> ...]`` (needs the optional ``[hydro]``
extra; capytaine is imported lazily, nothing at simulation time needs it). For each ship it reads
``models/<ship>/ship.toml`` (density, mass properties) and ``models/<ship>/hydro/hull.toml`` (hull
particulars, mesh levels, frequencies), meshes the parametric hull (:mod:`.hullform`) at each mesh
level, solves the linear potential-flow radiation and diffraction problems at zero speed in deep
water (Capytaine, Babarit & Delhommeau 2015, "Theoretical and numerical aspects of the open source
BEM solver NEMOH", EWTEC), and writes ``models/<ship>/hydro/<ship>_hydro.nc`` from the densest level
plus a README with the convergence study.

Axes. Capytaine works in x forward, y to port, z up (origin on the free surface); vtrials' body axes
are x forward, y starboard, z down. The mesh is handed to Capytaine as (x − x_O, −y, −z) about the
vtrials body origin O, i.e. rotated 180° about x, so every generalized quantity maps by
T = diag(1, −1, −1, 1, −1, −1) (surge, sway, heave, roll, pitch, yaw): A_v = T A_c T, F_v = T F_c.

Waves and phases. vtrials heading β (rad) is the direction the waves travel, relative to the ship,
measured from +x towards +y (starboard): β = 0 following seas, β = π head seas (waves coming from
ahead), β = π/2 waves travelling to starboard (coming from port). Capytaine's direction is measured
towards its +y (port), so β_c = −β. Capytaine uses Re{· e^{−iωt}}; vtrials uses
η(t) = Re{a e^{i(ωt − k·x)}} (crest at O at t = 0) and F(t) = Re{X a e^{iωt}}, so X_v = T conj(X_c).

Mean drift: far-field (Maruo/Kochin) formula as implemented in Capytaine
(``capytaine.post_pro.mean_drift_force.far_field_mean_drift_force``, following Maruo 1960 and
Newman 1967), using the motion RAO of the free ship with the model's mass properties plus a linear
viscous roll damping (otherwise the undamped roll resonance would dominate beam-sea drift).
"""

from __future__ import annotations

import argparse
import datetime as _dt
import json
import math
import sys
import time
import tomllib
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from vtrials.errors import InputError

from . import hullform as hf

MODELS_DIR = Path(__file__).resolve().parents[3] / "models"
DOF_NAMES = ("surge", "sway", "heave", "roll", "pitch", "yaw")
CAPY_DOFS = ("Surge", "Sway", "Heave", "Roll", "Pitch", "Yaw")
AXES_SIGN = np.array([1.0, -1.0, -1.0, 1.0, -1.0, -1.0])   # T: Capytaine (z up, y port) ↔ vtrials
DRIFT_SIGN = np.array([1.0, -1.0, -1.0])                    # surge, sway, yaw
G_STANDARD = 9.80665
LID_DEPTH = 0.1      # lid depth ÷ draught


@dataclass(frozen=True)
class ShipSetup:
    """What the BEM run needs from the model files (SI, vtrials body axes about the body origin O)."""

    name: str
    rho: float
    g: float
    volume: float
    mass: float
    r_G: np.ndarray              # centre of gravity from O [m], z down
    k_G: np.ndarray              # radii of gyration about G (k_xx, k_yy, k_zz) [m]
    origin_x: float              # O from midship [m]
    particulars: hf.HullParticulars
    levels: tuple
    omega: np.ndarray
    headings: np.ndarray         # rad
    roll_damping: float | None   # linear B44 [N m s] if given directly
    roll_damping_ratio: float | None
    model_C: np.ndarray          # restoring matrix of ship.toml (vtrials.vessel formula)
    model_hydrostatics: dict
    hull_source: str


def _val(x):
    return float(x["value"]) if isinstance(x, dict) else float(x)


def load_setup(ship: str, models_dir: Path = MODELS_DIR) -> ShipSetup:
    ship_file = models_dir / ship / "ship.toml"
    hull_file = models_dir / ship / "hydro" / "hull.toml"
    for f in (ship_file, hull_file):
        if not f.is_file():
            raise InputError(str(f), "", "file not found")
    doc = tomllib.loads(ship_file.read_text())
    hdoc = tomllib.loads(hull_file.read_text())
    p, h, i = doc["particulars"], doc["hydrostatics"], doc["inertia"]
    rho = _val(p["water_density"])
    vol = _val(p["displacement"])
    T = _val(p["draught"])
    hp = hf.hull_particulars_from_table(hdoc["hull"], str(hull_file))
    bem = hdoc["bem"]
    omega = np.linspace(_val(bem["omega_min"]), _val(bem["omega_max"]), int(_val(bem["n_omega"])))
    step = math.radians(_val(bem["heading_step_deg"]))
    headings = np.linspace(0.0, math.pi, int(round(math.pi / step)) + 1)
    r_G = np.array([_val(p["x_G"]), 0.0, T - _val(p["KG"])])
    A_wp, x_F = _val(h["waterplane_area"]), _val(h["x_F"])
    GM_T, GM_L = _val(h["GM_T"]), _val(h["GM_L"])
    C = np.zeros((6, 6))   # as vtrials.vessel.Vessel.restoring_matrix (origin O, z down)
    C[2, 2] = rho * G_STANDARD * A_wp
    C[2, 4] = C[4, 2] = -rho * G_STANDARD * A_wp * x_F
    C[3, 3] = rho * G_STANDARD * vol * GM_T
    C[4, 4] = rho * G_STANDARD * (vol * GM_L + A_wp * x_F ** 2)
    return ShipSetup(
        name=ship, rho=rho, g=G_STANDARD, volume=vol, mass=rho * vol, r_G=r_G,
        k_G=np.array([_val(i["k_xx"]), _val(i["k_yy"]), _val(i["k_zz"])]),
        origin_x=_val(bem["body_origin_x"]), particulars=hp,
        levels=tuple(tuple(int(v) for v in lv) for lv in hdoc["mesh"]["levels"]),
        omega=omega, headings=headings,
        roll_damping=_val(bem["roll_damping_linear"]) if "roll_damping_linear" in bem else None,
        roll_damping_ratio=_val(bem["roll_damping_ratio"]) if "roll_damping_ratio" in bem else None,
        model_C=C, model_hydrostatics={"waterplane_area": A_wp, "x_F": x_F, "GM_T": GM_T, "GM_L": GM_L,
                                       "KB": _val(h["KB"]), "KG": _val(p["KG"])},
        hull_source=hp.source)


def rigid_body_mass_matrix(mass: float, r_G: np.ndarray, k_G: np.ndarray) -> np.ndarray:
    """6×6 rigid-body mass matrix about O (Fossen 2011, eq. 3.44): [[m I, −m S(r)], [m S(r), I_G − m S(r)²]]."""
    S = np.array([[0.0, -r_G[2], r_G[1]], [r_G[2], 0.0, -r_G[0]], [-r_G[1], r_G[0], 0.0]])
    M = np.zeros((6, 6))
    M[:3, :3] = mass * np.eye(3)
    M[:3, 3:] = -mass * S
    M[3:, :3] = mass * S
    M[3:, 3:] = np.diag(mass * k_G ** 2) - mass * S @ S
    return M


def to_capytaine_vertices(vertices: np.ndarray, origin_x: float) -> np.ndarray:
    """vtrials body axes from midship → Capytaine axes about O: (x − x_O, −y, −z)."""
    v = np.asarray(vertices, dtype=float).copy()
    v[:, 0] -= origin_x
    v[:, 1:] *= -1.0
    return v


def matrix_to_vtrials(Mc: np.ndarray) -> np.ndarray:
    """T M_c T on the last two axes (6×6 blocks)."""
    return Mc * AXES_SIGN[:, None] * AXES_SIGN[None, :]


def force_to_vtrials(Xc: np.ndarray) -> np.ndarray:
    """T conj(X_c) on the last axis (6 dofs): Capytaine e^{−iωt} → vtrials e^{+iωt}."""
    return np.conj(Xc) * AXES_SIGN


def _capytaine_body(cpt, setup: ShipSetup, mesh: hf.HullMesh):
    v = to_capytaine_vertices(mesh.vertices, setup.origin_x)
    # the rotation about x keeps the vertex order's orientation: normals stay outward
    half = cpt.Mesh(vertices=v, faces=mesh.faces, name=f"{setup.name}_half")
    full = cpt.ReflectionSymmetricMesh(half=half, plane="xOz", name=f"{setup.name}_hull")
    # lid against irregular frequencies inside the hull at z = −0.1 T, panels of the hull's mean size:
    # a lid at −0.01 T or with 1.5× coarser panels left remnants of the first irregular frequency in
    # B33 of patrol51 near 2.9 rad/s (checked on the 50 × 13 mesh)
    lid = full.generate_lid(z=-LID_DEPTH * setup.particulars.draught)
    cog = to_capytaine_vertices((setup.r_G + np.array([setup.origin_x, 0.0, 0.0]))[None, :], setup.origin_x)[0]
    body = cpt.FloatingBody(mesh=full, lid_mesh=lid, dofs=cpt.rigid_body_dofs(rotation_center=(0.0, 0.0, 0.0)),
                            center_of_mass=cog, mass=setup.mass, name=setup.name)
    return body


def resolution_limit(setup: ShipSetup, mesh: hf.HullMesh) -> tuple[float, float]:
    """(largest panel radius of hull and lid [m], ω above which it exceeds λ/8 [rad/s]) — the
    criterion behind Capytaine's mesh-resolution warning."""
    import capytaine as cpt

    body = _capytaine_body(cpt, setup, mesh)
    r = float(np.max(body.mesh_including_lid.faces_radiuses))
    return r, math.sqrt(2.0 * math.pi * setup.g / (8.0 * r))


def solve_level(setup: ShipSetup, mesh: hf.HullMesh, omega, headings, *, kochin: bool, n_threads: int = 2) -> dict:
    """Radiation + diffraction (+ ω = ∞ added mass) on one mesh; results in vtrials axes/conventions."""
    import capytaine as cpt
    import xarray as xr

    t0 = time.perf_counter()
    body = _capytaine_body(cpt, setup, mesh)
    solver = cpt.BEMSolver()
    beta_c = np.mod(-np.asarray(headings), 2.0 * np.pi)
    beta_c = np.where(beta_c > np.pi, beta_c - 2.0 * np.pi, beta_c)    # (−π, π]; exact −0 → 0
    coords = {"omega": np.asarray(omega), "wave_direction": beta_c, "radiating_dof": list(CAPY_DOFS),
              "water_depth": [np.inf], "rho": [setup.rho], "g": [setup.g]}
    if kochin:
        dth = 2.0 * np.pi / 72.0
        coords["theta"] = dth * np.arange(-38, 73)      # [−190°, 360°]: Capytaine's drift needs 0 and 2π
    ds = solver.fill_dataset(xr.Dataset(coords=coords), body, n_threads=n_threads, progress_bar=False)
    ds = ds.sel(wave_direction=beta_c)   # Capytaine returns the directions sorted; back to ours
    inf_probs = [cpt.RadiationProblem(body=body, radiating_dof=d, omega=np.inf, rho=setup.rho, g=setup.g)
                 for d in CAPY_DOFS]
    inf_res = solver.solve_all(inf_probs, n_threads=n_threads, progress_bar=False)
    A_inf_c = np.array([[r.added_masses[di] for di in CAPY_DOFS] for r in inf_res]).T   # [influenced, radiating]
    C_c = body.compute_hydrostatic_stiffness(rho=setup.rho, g=setup.g)
    C_c = C_c.sel(influenced_dof=list(CAPY_DOFS), radiating_dof=list(CAPY_DOFS)).values
    elapsed = time.perf_counter() - t0

    def sel(name):
        return _drop_scalar_dims(ds[name])

    A_c = sel("added_mass").transpose("omega", "influenced_dof", "radiating_dof").sel(
        influenced_dof=list(CAPY_DOFS), radiating_dof=list(CAPY_DOFS)).values
    B_c = sel("radiation_damping").transpose("omega", "influenced_dof", "radiating_dof").sel(
        influenced_dof=list(CAPY_DOFS), radiating_dof=list(CAPY_DOFS)).values
    FK_c = sel("Froude_Krylov_force").transpose("omega", "wave_direction", "influenced_dof").sel(
        influenced_dof=list(CAPY_DOFS)).values
    DF_c = sel("diffraction_force").transpose("omega", "wave_direction", "influenced_dof").sel(
        influenced_dof=list(CAPY_DOFS)).values
    out = {
        "A": matrix_to_vtrials(A_c), "B": matrix_to_vtrials(B_c), "A_inf": matrix_to_vtrials(A_inf_c),
        "C": matrix_to_vtrials(C_c), "X_FK": force_to_vtrials(FK_c), "X_diff": force_to_vtrials(DF_c),
        "seconds": elapsed, "panels_half": mesh.n_panels,
        "panels_lid_full": int(body.lid_mesh.nb_faces) if body.lid_mesh is not None else 0,
    }
    out["X"] = out["X_FK"] + out["X_diff"]
    if kochin:
        out["drift"], out["roll_damping"] = _drift(setup, ds, A_c, B_c, C_c, FK_c + DF_c)
    return out


def _drop_scalar_dims(da):
    """Drop the one-value problem dimensions (rho, g, water_depth) Capytaine adds, keep all others."""
    dims = [d for d in ("rho", "g", "water_depth") if d in da.dims]
    return da.squeeze(dim=dims, drop=True) if dims else da


def _roll_damping_c(setup: ShipSetup, A_c, C_c, omega) -> float:
    """Linear viscous roll damping [N m s]: given, or ζ × 2 √((I44 + A44(ω_n)) C44) at the roll resonance."""
    if setup.roll_damping is not None:
        return setup.roll_damping
    M = rigid_body_mass_matrix(setup.mass, setup.r_G, setup.k_G)
    C44 = C_c[3, 3]
    wn = math.sqrt(max(C44, 1e-9) / (M[3, 3] + A_c[0, 3, 3]))
    for _ in range(20):
        a44 = np.interp(wn, omega, A_c[:, 3, 3])
        wn = math.sqrt(C44 / (M[3, 3] + a44))
    return 2.0 * setup.roll_damping_ratio * math.sqrt((M[3, 3] + np.interp(wn, omega, A_c[:, 3, 3])) * C44)


def _drift(setup: ShipSetup, ds, A_c, B_c, C_c, X_c):
    """Far-field mean drift (surge, sway, yaw) per unit amplitude² [N/m², N m/m²], vtrials axes, and the
    linear roll damping used in the RAO [N m s]."""
    import xarray as xr
    from capytaine.post_pro.mean_drift_force import far_field_mean_drift_force

    omega = ds["omega"].values
    M_c = matrix_to_vtrials(rigid_body_mass_matrix(setup.mass, setup.r_G, setup.k_G))  # T M T (T = T⁻¹)
    Bv = np.zeros((6, 6))
    Bv[3, 3] = _roll_damping_c(setup, A_c, C_c, omega)
    rao = np.zeros(X_c.shape, dtype=complex)   # (omega, beta, dof), Capytaine convention e^{−iωt}
    for k, w in enumerate(omega):
        Z = -w ** 2 * (M_c + A_c[k]) - 1j * w * (B_c[k] + Bv) + C_c
        rao[k] = np.linalg.solve(Z, X_c[k].T).T
    X = xr.DataArray(rao, dims=("omega", "wave_direction", "radiating_dof"),
                     coords={"omega": omega, "wave_direction": ds["wave_direction"].values,
                             "radiating_dof": list(CAPY_DOFS)})
    sub = xr.Dataset({"kochin_diffraction": _drop_scalar_dims(ds["kochin_diffraction"]),
                      "kochin_radiation": _drop_scalar_dims(ds["kochin_radiation"])})
    sub = sub.assign(wavenumber=("omega", omega ** 2 / setup.g), water_depth=np.inf, rho=setup.rho, g=setup.g)
    nb = X.sizes["wave_direction"]
    out = np.zeros((omega.size, nb, 3))
    for i in range(nb):   # one direction at a time: only the unidirectional (diagonal) terms are needed
        bi = X["wave_direction"].values[i:i + 1]
        res = far_field_mean_drift_force(X.sel(wave_direction=bi), sub.sel(wave_direction=bi))
        for j, name in enumerate(("drift_force_surge", "drift_force_sway", "drift_force_yaw")):
            out[:, i, j] = np.real(res[name].values[:, 0, 0]) * DRIFT_SIGN[j]
    return out, float(Bv[3, 3])


# --------------------------------------------------------------------------------------------------
# convergence


def peak_metrics(res: dict, omega: np.ndarray, headings: np.ndarray) -> dict:
    """Peaks (max over ω) of A33, B33, A55, |X3|, |X5| in head seas (β = π) of one mesh level."""
    ih = int(np.argmin(np.abs(headings - math.pi)))
    return {"A33": float(np.max(res["A"][:, 2, 2])), "B33": float(np.max(res["B"][:, 2, 2])),
            "A55": float(np.max(res["A"][:, 4, 4])), "X3": float(np.max(np.abs(res["X"][:, ih, 2]))),
            "X5": float(np.max(np.abs(res["X"][:, ih, 4])))}


def relative_changes(metrics: list[dict]) -> list[dict]:
    """|m_{k+1} − m_k| / |m_{k+1}| between consecutive levels."""
    return [{q: abs(b[q] - a[q]) / abs(b[q]) for q in b} for a, b in zip(metrics[:-1], metrics[1:])]


# --------------------------------------------------------------------------------------------------
# output


def write_database(path: Path, setup: ShipSetup, res: dict, attrs: dict) -> None:
    """CF-style netCDF4 (HDF5) file readable by xarray/h5netcdf and by :func:`.database.load_database`."""
    import h5netcdf

    path.parent.mkdir(parents=True, exist_ok=True)
    with h5netcdf.File(path, "w") as f:
        f.dimensions = {"omega": setup.omega.size, "heading": setup.headings.size, "dof_i": 6, "dof_j": 6,
                        "drift_dof": 3}

        def var(name, dims, data, units, long_name, **extra):
            v = f.create_variable(name, dims, data=np.asarray(data, dtype=np.float64))
            v.attrs["units"] = units
            v.attrs["long_name"] = long_name
            for k, val in extra.items():
                v.attrs[k] = val
            return v

        var("omega", ("omega",), setup.omega, "rad s-1", "wave angular frequency (zero speed)")
        var("heading", ("heading",), setup.headings, "rad",
            "wave heading relative to the ship: direction of travel from +x towards +y (starboard); pi = head seas")
        var("dof_i", ("dof_i",), np.arange(6), "1", "influenced dof (0 surge, 1 sway, 2 heave, 3 roll, 4 pitch, 5 yaw)")
        var("dof_j", ("dof_j",), np.arange(6), "1", "radiating dof (same order)")
        var("drift_dof", ("drift_dof",), np.array([0, 1, 5]), "1", "dof of the mean drift load (surge, sway, yaw)")
        mixed = "kg | kg m | kg m2 by dof pair (translation/rotation)"
        var("added_mass", ("omega", "dof_i", "dof_j"), res["A"], mixed, "radiation added mass A_ij(omega)")
        var("radiation_damping", ("omega", "dof_i", "dof_j"), res["B"], "kg s-1 | kg m s-1 | kg m2 s-1",
            "radiation damping B_ij(omega)")
        var("added_mass_infinite_frequency", ("dof_i", "dof_j"), res["A_inf"], mixed, "A_ij at omega = infinity")
        var("hydrostatic_stiffness", ("dof_i", "dof_j"), res["C"], "N m-1 | N | N m",
            "hydrostatic + gravity stiffness of the meshed hull with the model's mass and KG (Capytaine)")
        var("hydrostatic_stiffness_model", ("dof_i", "dof_j"), setup.model_C, "N m-1 | N | N m",
            "restoring matrix of ship.toml (GM_T, GM_L, waterplane area, x_F), for comparison")
        var("rigid_body_mass", ("dof_i", "dof_j"), rigid_body_mass_matrix(setup.mass, setup.r_G, setup.k_G),
            "kg | kg m | kg m2", "rigid-body mass matrix about the reference point from ship.toml")
        for key, label in (("X", "excitation"), ("X_FK", "froude_krylov"), ("X_diff", "diffraction")):
            for part, fn in (("re", np.real), ("im", np.imag)):
                var(f"{label}_force_{part}", ("omega", "heading", "dof_i"), fn(res[key]), "N m-1 | N m m-1",
                    f"{label} force per unit wave amplitude, {'real' if part == 're' else 'imaginary'} part",
                    convention="F(t) = Re{X a exp(i omega t)}, eta(t) = Re{a exp(i(omega t - k.x))}")
        if "drift" in res:
            var("mean_drift_force", ("omega", "heading", "drift_dof"), res["drift"], "N m-2 | N m m-2",
                "mean second-order drift load per unit wave amplitude squared (far-field, Maruo/Kochin)")
        for k, v in attrs.items():
            f.attrs[k] = v


def _readme(setup: ShipSetup, hyd: dict, levels: list, changes: list, attrs: dict, C: np.ndarray,
            checks: dict) -> str:
    hp = setup.particulars
    lines = [f"# Hydrodynamic database of {setup.name}", "",
             f"`{setup.name}_hydro.nc` — zero-speed, deep-water, linear potential-flow coefficients computed "
             f"offline with Capytaine {attrs['software_capytaine']} by `python -m vtrials.physics.seakeeping.build "
             f"{setup.name}` on {attrs['date'][:10]}. Loaded by `vtrials.physics.seakeeping.database.load_database` "
             "(h5py only; no Capytaine at run time).", "",
             "## Mesh", "",
             "Parametric stand-in hull (`vtrials.physics.seakeeping.hullform`), fitted to the particulars in "
             "`hull.toml` (each with its source). It is **not** the ship's lines: constant draught, Lamé "
             "(superellipse) sections, no bulb, no stern aperture, no appendages, no bilge keels. "
             + ("No published KVLCC2 offsets could be found and cited in the time available, so the "
                "parametric hull is used. " if setup.name == "kvlcc2" else "BC93 publish no lines. "),
             "",
             "| quantity | target | mesh (shipped level) | rel. error |", "|---|---|---|---|"]
    L, B, T = hp.length, hp.beam, hp.draught
    rows = [("∇ [m³]", hp.volume, hyd["volume"]), ("A_wp [m²]", hp.C_WP * L * B, hyd["waterplane_area"]),
            ("A_M [m²]", hp.C_M * B * T, hyd["A_M"]), ("LCB from midship [m]", hp.lcb, hyd["x_B"])]
    for name, tgt, got in rows:
        rel = (got - tgt) / (L if "LCB" in name else tgt)
        lines.append(f"| {name} | {tgt:.4g} | {got:.4g} | {rel:+.2e}{' (÷L)' if 'LCB' in name else ''} |")
    lines += ["", f"Wetted surface of the mesh {hyd['wetted_area']:.0f} m²; KB {hyd['KB']:.3f} m; BM_T "
              f"{hyd['BM_T']:.3f} m; BM_L {hyd['BM_L']:.1f} m; x_F {hyd['x_F']:.2f} m from midship.", "",
              "## Hydrostatics vs the model file", "",
              "| term | database (mesh) | ship.toml | ratio |", "|---|---|---|---|"]
    for (i, j), name in (((2, 2), "C33 = ρ g A_wp"), ((3, 3), "C44 = ρ g ∇ GM_T"), ((4, 4), "C55 = ρ g ∇ GM_L (+A_wp x_F²)"),
                         ((2, 4), "C35 = −ρ g A_wp x_F")):
        a, b = C[i, j], setup.model_C[i, j]
        ratio = f"{a / b:.3f}" if b != 0 else "— (ship.toml: 0)"
        lines.append(f"| {name} | {a:.4e} | {b:.4e} | {ratio} |")
    lines += ["", checks["hydrostatics_note"], "",
              "## Mesh convergence", "",
              "| level | stations × girth | panels (half hull) | lid panels (whole) | BEM time [s] | max A33 | max B33 | max A55 | max amplitude X3, head seas | max amplitude X5, head seas |",
              "|---|---|---|---|---|---|---|---|---|---|"]
    for k, lv in enumerate(levels):
        m = lv["metrics"]
        lines.append(f"| {k} | {lv['stations']} × {lv['girth']} | {lv['panels_half']} | {lv['panels_lid']} | {lv['seconds']:.0f} | "
                     f"{m['A33']:.4e} | {m['B33']:.4e} | {m['A55']:.4e} | {m['X3']:.4e} | {m['X5']:.4e} |")
    lines += ["", "Relative change between consecutive levels (|Δ| / finer):", "",
              "| levels | A33 | B33 | A55 | X3 | X5 |", "|---|---|---|---|---|---|"]
    for k, c in enumerate(changes):
        lines.append(f"| {k}→{k + 1} | " + " | ".join(f"{c[q]:.2%}" for q in ("A33", "B33", "A55", "X3", "X5")) + " |")
    lines += ["", "The shipped database is the densest level (all headings, drift; its time includes them); "
              "the coarser levels were run with head seas only. The maxima of A33 and X3 lie at the lowest "
              "frequency, so they test the long-wave end; B33 and A55 peak inside the range.", "",
              "## Conventions", "",
              "* Body axes about the vtrials body origin O = (x_O, 0, 0) from midship on the calm waterline "
              f"(x_O = {setup.origin_x} m): x forward, y starboard, z down; dof order surge, sway, heave, roll, "
              "pitch, yaw; rotations right-handed about these axes (pitch positive bow up, yaw positive to starboard).",
              "* Capytaine's axes (x forward, y port, z up) map by T = diag(1, −1, −1, 1, −1, −1): A = T A_c T, "
              "X = T conj(X_c).",
              "* Heading β: direction of wave travel relative to the ship, from +x towards +y (starboard); "
              "β = 180° head seas (waves coming from ahead), 0° following, 90° waves travelling to starboard "
              "(coming from port). Only 0–180° is stored; for β' = −β use the mirror image "
              "X(−β) = S X(β), S = diag(1, −1, 1, −1, 1, −1) (drift: sway and yaw change sign).",
              "* Phases: incident wave η(t) = Re{a e^{i(ωt − k·x)}} with k·x = k (x cos β + y sin β) "
              "(crest at O at t = 0); force F(t) = Re{X a e^{iωt}} per metre of amplitude. Excitation = "
              "Froude–Krylov + diffraction (both stored too).",
              "* Mean drift: per unit amplitude squared, far-field (Maruo/Kochin, Capytaine's implementation), "
              "with the RAO of the free ship using `rigid_body_mass` and a linear viscous roll damping "
              f"B44 = {float(attrs['drift_roll_damping']):.4g} N m s.",
              f"* ρ = {setup.rho} kg/m³, g = {setup.g} m/s², deep water, zero forward speed.",
              "",
              "## Limits", "",
              "* Zero speed: use encounter-frequency mapping and speed corrections in the time domain.",
              "* Potential flow: no viscous roll damping (add Ikeda or an equivalent linear term), no lift.",
              f"* Frequencies {setup.omega[0]:.2f}–{setup.omega[-1]:.2f} rad/s; the radiation kernel needs a "
              "high-frequency tail of B(ω) beyond that.",
              f"* Irregular frequencies are removed with a lid at z = −{LID_DEPTH} T inside the hull.",
              "* The parametric hull reproduces the particulars above, not the real lines; local quantities "
              "(pressure, sectional loads) are not representative.",
              "* Mesh resolution (Capytaine's rule: largest panel radius ≤ wavelength/8): the shipped hull and "
              f"lid have r ≤ {float(attrs['mesh_max_panel_radius']):.2f} m, fine enough up to ω = "
              f"{float(attrs['mesh_resolved_omega_max']):.2f} rad/s"
              + (", i.e. over the whole stored range." if float(attrs["mesh_resolved_omega_max"]) >= setup.omega[-1]
                 else "; the stored frequencies above that are less accurate."), "",
              "## Checks", "",
              "`tests/test_hydro_database.py` (no Capytaine needed): hull particulars from the mesh; "
              "symmetry of A and B and no symmetric/antisymmetric mode coupling; B ≥ 0; B decaying and "
              "A → A∞ over the top of the range; stiffness vs an independent mesh integration and vs "
              "ship.toml; long-wave limits of the excitation; Haskind's relation for all six dofs; "
              "Kramers–Kronig between A and B; drift signs, symmetry and the short-wave beam-sea limit; "
              "the convergence figures above.", ""]
    lines += checks.get("extra", [])
    lines += _time_domain_section(setup, C)
    return "\n".join(lines)


def _time_domain_section(setup: ShipSetup, C: np.ndarray) -> list:
    """README section: how the simulator uses this database (restoring, roll damping, sway-roll coupling)."""
    gm_mesh = setup.model_hydrostatics["GM_T"] * C[3, 3] / setup.model_C[3, 3]
    out = ["", "## Use in the time domain (vtrials.physics.seakeeping.timedomain)", "",
           f"* Roll restoring: the simulator uses ship.toml's GM_T = {setup.model_hydrostatics['GM_T']} m "
           f"(hydrostatics component, C44 = {setup.model_C[3, 3]:.4e} N m), not this database's C44 = {C[3, 3]:.4e} "
           f"N m (GM_T ≈ {gm_mesh:.2f} m of the meshed hull). The frequency-domain references "
           "(`rao.rao(..., C=vessel.restoring_matrix())`, `linearize.coupled_rao`) use the same ship.toml restoring, "
           "so simulator and references agree; the database's C is a diagnostic of the mesh only.",
           "* Roll damping: the radiation memory gives the wave part; the viscous part is the `roll_damping` "
           "component set by the `[roll_damping]` table of `hull.toml` (method, bilge keels, each with its source); "
           "every roll damping term of the maneuvering model is removed from the seakeeping vessel.",
           "* Surge and yaw keep the maneuvering model (its added mass and hull forces, no memory). Sway keeps "
           "the maneuvering model's hull forces, but its added mass and its coupling with roll are this database's "
           "A∞ with the radiation memory of sway, sway–roll and roll–sway (so that in long beam waves the ship "
           "sways with the water and heels with the wave slope: the diffraction part of the excitation carries "
           "this hull's A22(ω) and A42(ω)); `linearize.coupled_rao` is the frequency-domain model of the same "
           "system."]
    if setup.name == "patrol51":
        out += ["* Sway added mass: in waves the simulator's sway added mass at maneuvering frequencies is this "
                "hull's A22(ω → 0) (3.3e5 kg at 0.2 rad/s), not BC93's Y_v̇ 3.93e5 kg, and its sway–roll coupling the "
                "symmetric potential-flow A24 rather than BC93's antisymmetric Y_ṗ = −K_v̇ (with those, the "
                "ship heeled 2.8–3.4 times the wave slope in beam waves of 0.2–0.5 rad/s even with this waterplane; "
                "with BC93's Y_v̇ alone, 1.5–1.7 times)."]
    return out


def write_readme(setup: ShipSetup, nc_path: Path) -> Path:
    """(Re)write ``README.md`` next to a database from the file itself (no BEM needed)."""
    from .database import load_database

    db = load_database(nc_path)
    ns, ng = json.loads(db.attrs["mesh_stations_girth"])
    mesh = hf.hull_mesh(hf.fit_hullform(setup.particulars), ns, ng)
    hyd = hf.mesh_hydrostatics(mesh)
    hyd["A_M"] = hf.mesh_section_area(mesh, 0.0)
    pts = mesh.vertices[mesh.faces]
    hyd["r_max"] = float(np.max(np.linalg.norm(pts - pts.mean(axis=1, keepdims=True), axis=2)))
    hyd["omega_resolved"] = math.sqrt(2.0 * math.pi * setup.g / (8.0 * hyd["r_max"]))
    conv = json.loads(db.attrs["convergence"])
    text = _readme(setup, hyd, conv["levels"], conv["relative_changes"], db.attrs, db.C,
                   {"hydrostatics_note": db.attrs["hydrostatics_note"]})
    path = nc_path.parent / "README.md"
    path.write_text(text)
    return path


def build(ship: str, models_dir: Path = MODELS_DIR, n_threads: int = 2, levels: str = "all") -> Path:
    import capytaine as cpt

    setup = load_setup(ship, models_dir)
    form = hf.fit_hullform(setup.particulars)
    level_list = list(setup.levels) if levels == "all" else [setup.levels[-1]]
    head = np.array([math.pi])
    records, finest = [], None
    for k, (ns, ng) in enumerate(level_list):
        mesh = hf.hull_mesh(form, ns, ng)
        last = k == len(level_list) - 1
        res = solve_level(setup, mesh, setup.omega, setup.headings if last else head, kochin=last,
                          n_threads=n_threads)
        hd = setup.headings if last else head
        rec = {"stations": ns, "girth": ng, "panels_half": mesh.n_panels, "panels_lid": res["panels_lid_full"],
               "seconds": res["seconds"], "metrics": peak_metrics(res, setup.omega, hd)}
        records.append(rec)
        print(f"{ship}: level {k} {ns}x{ng}: {mesh.n_panels} half-hull panels, {res['seconds']:.1f} s, {rec['metrics']}",
              flush=True)
        if last:
            finest, finest_mesh = res, mesh
    changes = relative_changes([r["metrics"] for r in records])
    hyd = hf.mesh_hydrostatics(finest_mesh)
    hyd["A_M"] = hf.mesh_section_area(finest_mesh, 0.0)
    mh = setup.model_hydrostatics
    GM_T_mesh = hyd["KB"] + hyd["BM_T"] - mh["KG"]
    GM_L_mesh = hyd["KB"] + hyd["BM_L"] - mh["KG"]
    note = (f"The database keeps the mesh's own stiffness (consistent with its Froude–Krylov forces). "
            f"Mesh: KB {hyd['KB']:.3f} m (ship.toml {mh['KB']}), BM_T {hyd['BM_T']:.3f} m, so GM_T "
            f"{GM_T_mesh:.3f} m with KG {mh['KG']} m vs ship.toml GM_T {mh['GM_T']} m; GM_L {GM_L_mesh:.1f} m "
            f"vs {mh['GM_L']} m (an estimate in ship.toml); x_F {hyd['x_F'] - setup.origin_x:.2f} m from O vs "
            f"{mh['x_F']} m (an assumption in ship.toml).")
    if setup.name == "patrol51":
        note += (" The stand-in hull's C_WP (hull.toml) is fitted so that the mesh's KB + BM_T equals BC93's KM "
                 "(KG 3.36 + GM_T 1.1 = 4.46 m): with B = 8.6 m no waterplane of C_WP 0.72 (an earlier estimate) "
                 "gives a BM_T as small as BC93's (its mesh had BM_T 4.44 m, GM_T 2.61 m), and a wave excitation "
                 "of a hull 2.4 times stiffer in roll than the restoring it met made the simulated ship heel "
                 "several times the wave slope in long waves. ship.toml's waterplane area, x_F and GM_L are this "
                 "mesh's.")
    try:
        import importlib.metadata as im
        versions = {p: im.version(p) for p in ("capytaine", "numpy", "xarray", "h5netcdf")}
    except Exception:   # pragma: no cover - metadata missing
        versions = {"capytaine": cpt.__version__}
    roll_b = finest["roll_damping"]
    attrs = {
        "title": f"{setup.name} frequency-domain hydrodynamic database (zero speed, deep water)",
        "Conventions": "CF-1.8 (informal)",
        "ship": setup.name,
        "date": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
        "software_capytaine": versions.get("capytaine", ""),
        "software_versions": json.dumps(versions),
        "generator": "python -m vtrials.physics.seakeeping.build " + setup.name,
        "mesh_source": "parametric hull, vtrials.physics.seakeeping.hullform, fitted to models/"
                       f"{setup.name}/hydro/hull.toml",
        "mesh_panels_half_hull": finest_mesh.n_panels,
        "mesh_panels_whole_hull": 2 * finest_mesh.n_panels,
        "mesh_panels_lid_whole": finest["panels_lid_full"],
        "mesh_stations_girth": json.dumps(list(level_list[-1])),
        "irregular_frequencies": f"lid at z = -{LID_DEPTH} T (panels of the hull's mean size)",
        "symmetry": "port-starboard (xOz) mesh symmetry",
        "rho": setup.rho, "g": setup.g, "water_depth": "infinite",
        "forward_speed": 0.0,
        "reference_point": json.dumps([0.0, 0.0, 0.0]),
        "reference_point_description": "vtrials body origin O on the calm waterline, centreline",
        "reference_point_x_from_midship": setup.origin_x,
        "axes": "body axes x forward, y starboard, z down; dofs surge, sway, heave, roll, pitch, yaw",
        "axes_transform_from_capytaine": "T = diag(1,-1,-1,1,-1,-1); A = T A_c T; X = T conj(X_c); heading = -wave_direction_c",
        "heading_convention": "direction of wave travel relative to the ship, from +x towards +y (starboard); "
                              "pi = head seas (from ahead), 0 = following, pi/2 = travelling to starboard (from port)",
        "phase_convention": "eta(t) = Re{a exp(i(omega t - k (x cos b + y sin b)))}; F(t) = Re{X a exp(i omega t)}",
        "mass": setup.mass, "volume_model": setup.volume,
        "center_of_gravity": json.dumps([float(v) for v in setup.r_G]),
        "radii_of_gyration": json.dumps([float(v) for v in setup.k_G]),
        "drift_method": "far-field (Maruo/Kochin), capytaine.post_pro.mean_drift_force, free-ship RAO",
        "drift_roll_damping": roll_b,
        "convergence": json.dumps({"levels": records, "relative_changes": changes}),
        "hydrostatics_note": note,
        "hull_particulars_source": setup.hull_source,
    }
    r_max, w_res = resolution_limit(setup, finest_mesh)
    attrs["mesh_max_panel_radius"] = r_max
    attrs["mesh_resolved_omega_max"] = w_res
    out = models_dir / setup.name / "hydro" / f"{setup.name}_hydro.nc"
    write_database(out, setup, finest, attrs)
    write_readme(setup, out)
    print(f"{ship}: wrote {out} ({out.stat().st_size / 1e6:.2f} MB)", flush=True)
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m vtrials.physics.seakeeping.build", description=__doc__.split("\n")[0])
    ap.add_argument("ships", nargs="+")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--levels", choices=("all", "finest"), default="all")
    ap.add_argument("--readme-only", action="store_true", help="rewrite README.md from the existing database")
    a = ap.parse_args(argv)
    for s in a.ships:
        if a.readme_only:
            write_readme(load_setup(s), MODELS_DIR / s / "hydro" / f"{s}_hydro.nc")
        else:
            build(s, n_threads=a.threads, levels=a.levels)
    return 0


if __name__ == "__main__":
    sys.exit(main())
