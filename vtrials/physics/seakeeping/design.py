"""Offline builder of the trials team's DESIGN-STAGE RAO model (not the simulator's truth).

Run ``python -m vtrials.physics.seakeeping.design <ship>`` (needs the optional ``[hydro]`` extra, i.e.
Capytaine; use a separate venv). It reads ``models/<ship>/design/design.toml`` (the design condition
and modelling choices, each with its source) and writes ``models/<ship>/design/<ship>_design_rao.nc``:
zero-speed, deep-water radiation and excitation coefficients of the parametric hull on the design
mesh (:func:`.build.solve_level`, same axes and phase conventions as the truth database), the design
rigid-body mass matrix, the design restoring matrix and the fixed linear roll damping. The RAO itself is
assembled at run time by :mod:`vtrials.reduce.design_rao` (the reductions may not import physics):
sway, heave, roll and pitch free (:data:`FREE_DOFS`), the coefficients at the encounter frequency,
nothing else for speed.

How the design model differs from the truth (models/<ship>/design/README.md quantifies it with
``benchmarks/design_rao_vs_truth.py``):

* mesh: the coarsest level of ``hull.toml`` and coarser frequency/heading grids;
* condition: the design KG (preliminary weight estimate) instead of the as-inclined one; radii of
  gyration from design rules of thumb; the stability booklet's KM for the roll stiffness, the coarse
  mesh's own hydrostatics for heave and pitch;
* roll damping: a fixed fraction of critical at the design roll natural frequency, plus Ikeda's hull-lift
  term per m/s of speed (``roll_damping_speed``; no other viscous model);
* dynamics: surge and yaw held (the autopilot holds the heading), sway free without restoring and without
  the maneuvering model's hull forces (strip theory couples sway and roll, Salvesen, Tuck & Faltinsen
  1970), no forward-speed terms besides the encounter frequency.
"""

from __future__ import annotations

import argparse
import dataclasses
import datetime as _dt
import json
import math
import sys
import tomllib
from pathlib import Path

import numpy as np

from vtrials.errors import InputError

from . import build as B
from . import hullform as hf
from .rao import effective_inertia

#: The design model's free DOFs: sway, heave, roll, pitch (surge and yaw held). Roll needs sway free: on a
#: small ship the sway–roll inertia coupling m z_G + A24 is large (patrol51's design roll natural
#: frequency is 1.19 rad/s free to sway, 1.04 rad/s held), and a ship held in sway in long beam waves
#: does not heel with the wave slope. Yaw free without restoring or autopilot (no heading control in a
#: frequency-domain model) would wander at low encounter frequency and, through the roll–yaw coupling,
#: double the long-wave roll (measured on patrol51's design model: 2.0–3.2 × the slope at 0.2–0.3 rad/s
#: in beam seas, 1.02–1.04 with yaw held).
FREE_DOFS = (1, 2, 3, 4)


def _val(x):
    return x["value"] if isinstance(x, dict) else x


def load_design(ship: str, models_dir: Path = B.MODELS_DIR) -> tuple[B.ShipSetup, dict]:
    """(ShipSetup of the design condition, the parsed design.toml)."""
    path = models_dir / ship / "design" / "design.toml"
    if not path.is_file():
        raise InputError(str(path), "", "file not found")
    doc = tomllib.loads(path.read_text())
    truth = B.load_setup(ship, models_dir)
    d, c = doc["design"], doc["condition"]
    T = float(_val(c["draught"]))
    if abs(T - truth.particulars.draught) > 1e-9 or abs(float(_val(c["displacement"])) - truth.volume) > 1e-6:
        raise InputError(str(path), "condition", "the design builder meshes hull.toml's lines at their own draught "
                         "and displacement; a different draught needs its own hull table")
    r_G = np.array([float(_val(c["x_G"])) - truth.origin_x, 0.0, T - float(_val(c["KG"]))])
    omega = np.linspace(float(_val(d["omega_min"])), float(_val(d["omega_max"])), int(_val(d["n_omega"])))
    step = math.radians(float(_val(d["heading_step_deg"])))
    headings = np.linspace(0.0, math.pi, int(round(math.pi / step)) + 1)
    setup = dataclasses.replace(
        truth, r_G=r_G, k_G=np.array([float(_val(c[k])) for k in ("k_xx", "k_yy", "k_zz")]),
        levels=(tuple(int(v) for v in _val(d["mesh_level"])),), omega=omega, headings=headings)
    return setup, doc


def design_matrices(setup: B.ShipSetup, doc: dict, res: dict) -> dict:
    """Design M (6×6 about O), C (6×6) and the linear roll damping added to the BEM's [N m s]."""
    c, m = doc["condition"], doc["model"]
    M = B.rigid_body_mass_matrix(setup.mass, setup.r_G, setup.k_G)
    C = np.array(res["C"], dtype=float)          # the coarse mesh's hydrostatics with the design mass and KG
    gm_t = float(_val(c["KM_T"])) - float(_val(c["KG"]))
    C[3, 3] = setup.rho * setup.g * setup.volume * gm_t
    C[3, :3] = C[:3, 3] = 0.0
    zeta = float(_val(m["roll_damping_ratio"]))
    idx = [3, 1]                                  # roll, then the free sway (no restoring)

    def roll_inertia(A):                          # the inertia felt in roll, sway free
        return effective_inertia(M[np.ix_(idx, idx)] + A[np.ix_(idx, idx)])

    def A_at(w):
        return np.array([[np.interp(w, setup.omega, res["A"][:, i, j]) for j in range(6)] for i in range(6)])

    wn = math.sqrt(C[3, 3] / roll_inertia(res["A_inf"]))
    for _ in range(50):
        wn = math.sqrt(C[3, 3] / roll_inertia(A_at(wn)))
    i_eff = roll_inertia(A_at(wn))
    b44_wave = float(np.interp(wn, setup.omega, res["B"][:, 3, 3]))
    crit = 2.0 * math.sqrt(i_eff * C[3, 3])
    out = {"M": M, "C": C, "B44_add": max(zeta * crit - b44_wave, 0.0), "omega_roll": wn, "GM_T": gm_t,
           "B44_wave": b44_wave, "B44_crit": crit, "B44_per_speed": 0.0}
    if "roll_damping_speed" in m:
        kind = _val(m["roll_damping_speed"])
        if kind != "ikeda_lift":
            raise InputError("design.toml", "model.roll_damping_speed", f"{kind!r}: the only method is 'ikeda_lift'")
        from vtrials.physics.forces.roll_damping import RollHull, lift
        hp = setup.particulars
        h = RollHull(L=hp.length, B=hp.beam, d=hp.draught, C_B=hp.C_B, C_M=hp.C_M,
                     OG=hp.draught - float(_val(c["KG"])), rho=setup.rho)
        out["B44_per_speed"] = float(lift(h, 1.0))
    return out


def write_design(path: Path, setup: B.ShipSetup, res: dict, mats: dict, attrs: dict) -> None:
    import h5netcdf

    path.parent.mkdir(parents=True, exist_ok=True)
    with h5netcdf.File(path, "w") as f:
        f.dimensions = {"omega": setup.omega.size, "heading": setup.headings.size, "dof_i": 6, "dof_j": 6}

        def var(name, dims, data, units, long_name):
            v = f.create_variable(name, dims, data=np.asarray(data, dtype=np.float64))
            v.attrs["units"] = units
            v.attrs["long_name"] = long_name

        mixed = "kg | kg m | kg m2 by dof pair (translation/rotation)"
        var("omega", ("omega",), setup.omega, "rad s-1", "wave angular frequency (zero speed)")
        var("heading", ("heading",), setup.headings, "rad",
            "wave heading relative to the ship: direction of travel from +x towards +y (starboard); pi = head seas")
        var("added_mass", ("omega", "dof_i", "dof_j"), res["A"], mixed, "radiation added mass A_ij(omega), design mesh")
        var("radiation_damping", ("omega", "dof_i", "dof_j"), res["B"], "kg s-1 | kg m s-1 | kg m2 s-1",
            "radiation damping B_ij(omega), design mesh")
        var("added_mass_infinite_frequency", ("dof_i", "dof_j"), res["A_inf"], mixed, "A_ij at omega = infinity")
        var("rigid_body_mass", ("dof_i", "dof_j"), mats["M"], "kg | kg m | kg m2",
            "design rigid-body mass matrix about O (design KG and radii of gyration)")
        var("restoring", ("dof_i", "dof_j"), mats["C"], "N m-1 | N | N m",
            "design restoring: coarse-mesh hydrostatics at the design KG, roll from the stability booklet KM")
        for part, fn in (("re", np.real), ("im", np.imag)):
            var(f"excitation_force_{part}", ("omega", "heading", "dof_i"), fn(res["X"]), "N m-1 | N m m-1",
                f"excitation force per unit wave amplitude (Froude-Krylov + diffraction), {part} part")
        for k, v in attrs.items():
            f.attrs[k] = v


def build_design(ship: str, models_dir: Path = B.MODELS_DIR, n_threads: int = 2) -> Path:
    setup, doc = load_design(ship, models_dir)
    form = hf.fit_hullform(setup.particulars)
    ns, ng = setup.levels[0]
    mesh = hf.hull_mesh(form, ns, ng)
    res = B.solve_level(setup, mesh, setup.omega, setup.headings, kochin=False, n_threads=n_threads)
    mats = design_matrices(setup, doc, res)
    print(f"{ship}: design mesh {ns}x{ng} ({mesh.n_panels} half-hull panels) solved in {res['seconds']:.1f} s; "
          f"GM_T {mats['GM_T']:.3f} m, roll natural frequency {mats['omega_roll']:.3f} rad/s, "
          f"B44 added {mats['B44_add']:.4g} N m s", flush=True)
    try:
        import importlib.metadata as im
        versions = {p: im.version(p) for p in ("capytaine", "numpy", "h5netcdf")}
    except Exception:   # pragma: no cover
        versions = {}
    attrs = {
        "title": doc["design"]["title"],
        "ship": ship,
        "content": "design-stage RAO model (trials team); NOT the simulator's truth",
        "generator": f"python -m vtrials.physics.seakeeping.design {ship}",
        "date": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
        "software_versions": json.dumps(versions),
        "design_toml": json.dumps(doc),
        "mesh_stations_girth": json.dumps([ns, ng]),
        "mesh_panels_half_hull": mesh.n_panels,
        "rho": setup.rho, "g": setup.g, "water_depth": "infinite", "forward_speed": 0.0,
        "reference_x_from_midship": setup.origin_x,
        "axes": "body axes about O (calm waterline, centreline): x forward, y starboard, z down; "
                "dofs surge, sway, heave, roll, pitch, yaw",
        "heading_convention": "direction of wave travel relative to the ship, from +x towards +y (starboard); "
                              "pi = head seas, 0 = following, pi/2 = travelling to starboard (from port)",
        "phase_convention": "eta(t) = Re{a exp(i(omega t - k (x cos b + y sin b)))}; F(t) = Re{X a exp(i omega t)}",
        "free_dofs": json.dumps(list(FREE_DOFS)),
        "roll_damping_linear": mats["B44_add"],
        "roll_damping_ratio": float(_val(doc["model"]["roll_damping_ratio"])),
        "roll_damping_per_speed": mats["B44_per_speed"],
        "roll_natural_frequency": mats["omega_roll"],
        "GM_T": mats["GM_T"],
        "center_of_gravity": json.dumps([float(v) for v in setup.r_G]),
        "radii_of_gyration": json.dumps([float(v) for v in setup.k_G]),
        "mass": setup.mass,
    }
    out = models_dir / ship / "design" / f"{ship}_design_rao.nc"
    write_design(out, setup, res, mats, attrs)
    print(f"{ship}: wrote {out} ({out.stat().st_size / 1e6:.2f} MB)", flush=True)
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m vtrials.physics.seakeeping.design",
                                 description=__doc__.split("\n")[0])
    ap.add_argument("ships", nargs="+")
    ap.add_argument("--threads", type=int, default=2)
    a = ap.parse_args(argv)
    for s in a.ships:
        build_design(s, n_threads=a.threads)
    return 0


if __name__ == "__main__":
    sys.exit(main())
