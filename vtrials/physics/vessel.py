"""Vessel models as data: ``models/<name>/ship.toml`` (every coefficient with its source) plus an
MJCF file (hull on a free joint, rudders and shafts on hinges, instrument sites).

Frames: the hull body's frame is at midship on the design waterline, x forward, y starboard,
z down; the world is north-east-down with gravity +z. So ship conventions hold inside MuJoCo
without sign flips: heading ψ is the yaw about world z, positive clockwise seen from above.

Loading checks the parameter file (names, types, ranges, sources) and checks that the MJCF's
rigid-body data agree with it (hull mass = ρ∇, centre of gravity, radii of gyration, shaft
inertia), so the two files cannot silently disagree.
"""

from __future__ import annotations

import dataclasses
import math
import os
from pathlib import Path

import mujoco
import numpy as np

from vtrials.physics import propulsion
from vtrials.physics.environment import wind
from vtrials.errors import InputError
from vtrials.physics.forces import hull_blanke
from vtrials.physics.forces.registry import Component
from vtrials.physics.forces import hull_mmg
from vtrials.physics.forces import hydrostatics
from vtrials.physics.forces import propeller
from vtrials.physics.forces import rudder
from vtrials.schema import load_toml, num, read_table, text, unknown_key, vector
from vtrials.units import DEG, G

MODELS_DIR = Path(__file__).resolve().parents[2] / "models"


@dataclasses.dataclass(frozen=True)
class Meta:
    name: str = text("model name (its folder name)")
    title: str = text("one-line description")
    mjcf: str = text("MJCF file in the model folder")
    hull_model: str = text("hull force model", ("mmg", "blanke"))


@dataclasses.dataclass(frozen=True)
class Resistance:
    """Calm-water resistance curve (for hull models that take it as a table)."""

    speeds: tuple = vector("speeds through the water, increasing, from 0", "m/s", 0.0, 100.0)
    values: tuple = vector("resistance at those speeds", "N", 0.0, 1e9)


@dataclasses.dataclass(frozen=True)
class Particulars:
    length: float = num("length between perpendiculars L", "m", 0.0, 500.0, lo_open=True)
    beam: float = num("moulded beam B", "m", 0.0, 100.0, lo_open=True)
    draught: float = num("mean draught d", "m", 0.0, 40.0, lo_open=True)
    displacement: float = num("displacement volume ∇", "m^3", 0.0, 1e6, lo_open=True)
    water_density: float = num("water density ρ", "kg/m^3", 990.0, 1040.0)
    x_G: float = num("centre of gravity forward of midship", "m", -100.0, 100.0)
    KG: float = num("centre of gravity above keel", "m", 0.0, 60.0, lo_open=True)


@dataclasses.dataclass(frozen=True)
class Inertia:
    k_xx: float = num("roll radius of gyration about G", "m", 0.0, 100.0, lo_open=True)
    k_yy: float = num("pitch radius of gyration about G", "m", 0.0, 200.0, lo_open=True)
    k_zz: float = num("yaw radius of gyration about G", "m", 0.0, 200.0, lo_open=True)


@dataclasses.dataclass(frozen=True)
class Hydrostatics:
    GM_T: float = num("transverse metacentric height", "m", 0.0, 50.0, lo_open=True)
    GM_L: float = num("longitudinal metacentric height (about the centre of flotation)", "m", 0.0, 5000.0,
                      lo_open=True)
    waterplane_area: float = num("waterplane area A_wp", "m^2", 0.0, 1e5, lo_open=True)
    x_F: float = num("centre of flotation forward of midship", "m", -100.0, 100.0)
    KB: float = num("centre of buoyancy above keel", "m", 0.0, 40.0, lo_open=True)


@dataclasses.dataclass(frozen=True, kw_only=True)
class AddedMass:
    """Added mass in one of two forms; heave and pitch always as ratios (no maneuvering model has them).

    ``mmg``: non-dimensional m'_x, m'_y, J'_z at midship, roll as a ratio. ``derivatives``: the
    dimensional acceleration derivatives of a 4-DOF model (sign convention: force = derivative ×
    acceleration, so the added mass is minus the derivative).
    """

    form: str = text("how the added mass is given", ("mmg", "derivatives"))
    m_x_prime: float = num("surge added mass m'_x (÷ ½ρL²d)", "", 0.0, 1.0, default=0.0)
    m_y_prime: float = num("sway added mass m'_y (÷ ½ρL²d)", "", 0.0, 2.0, default=0.0)
    J_z_prime: float = num("yaw added inertia J'_z (÷ ½ρL⁴d), about the origin", "", 0.0, 1.0, default=0.0)
    roll_ratio: float = num("roll added inertia ÷ roll inertia about G (mmg form)", "", 0.0, 5.0, default=0.0)
    X_udot: float = num("X_u̇", "kg", -1e12, 0.0, default=0.0)
    Y_vdot: float = num("Y_v̇", "kg", -1e12, 0.0, default=0.0)
    Y_pdot: float = num("Y_ṗ", "kg m", -1e12, 1e12, default=0.0)
    Y_rdot: float = num("Y_ṙ", "kg m", -1e12, 1e12, default=0.0)
    K_vdot: float = num("K_v̇", "kg m", -1e12, 1e12, default=0.0)
    K_pdot: float = num("K_ṗ", "kg m^2", -1e14, 0.0, default=0.0)
    K_rdot: float = num("K_ṙ", "kg m^2", -1e14, 1e14, default=0.0)
    N_vdot: float = num("N_v̇", "kg m", -1e12, 1e12, default=0.0)
    N_pdot: float = num("N_ṗ", "kg m^2", -1e14, 1e14, default=0.0)
    N_rdot: float = num("N_ṙ", "kg m^2", -1e14, 0.0, default=0.0)
    heave_ratio: float = num("heave added mass ÷ ship mass", "", 0.0, 5.0)
    pitch_ratio: float = num("pitch added inertia ÷ pitch inertia about G", "", 0.0, 5.0)
    coriolis: str = text("added-mass Coriolis terms in the dynamics: 'kirchhoff' (all), 'no_munk' (the hull "
                         "derivatives contain the ideal-fluid Munk moments, as MMG's do) or 'none' (the "
                         "derivatives contain all of them)", ("kirchhoff", "no_munk", "none"))


@dataclasses.dataclass(frozen=True)
class Damping:
    heave_ratio: float = num("heave damping, fraction of critical", "", 0.0, 2.0)
    roll_ratio: float = num("linear roll damping, fraction of critical", "", 0.0, 2.0)
    pitch_ratio: float = num("pitch damping, fraction of critical", "", 0.0, 2.0)
    roll_quadratic: float = num("quadratic roll damping B_44q (K = −B_44q |p| p)", "N m s^2", 0.0, 1e15)


@dataclasses.dataclass(frozen=True)
class Autopilot:
    """The ship's heading autopilot (PID on heading error, derivative on yaw rate)."""

    gain: float = num("proportional gain K_p (rudder per heading error)", "rad/rad", 0.0, 50.0, lo_open=True)
    integral_time: float = num("integral time T_i (K_i = K_p/T_i)", "s", 0.0, 1e5, lo_open=True)
    derivative_time: float = num("derivative time T_d (K_d = K_p T_d)", "s", 0.0, 1e4)
    rudder_limit_deg: float = num("largest rudder the autopilot orders", "deg", 0.0, 90.0, lo_open=True)

    @property
    def pid(self) -> tuple[float, float, float]:
        """(K_p, K_i, K_d) = (K_p, K_p/T_i, K_p T_d) of the heading controller."""
        return self.gain, self.gain / self.integral_time, self.gain * self.derivative_time


_SECTIONS = {"meta": Meta, "particulars": Particulars, "inertia": Inertia, "hydrostatics": Hydrostatics,
             "added_mass": AddedMass, "damping": Damping, "autopilot": Autopilot}
ORDERS = ("ahead_1_3", "ahead_2_3", "standard", "full", "flank", "stop",
          "back_1_3", "back_2_3", "back_full", "back_emergency")


@dataclasses.dataclass(frozen=True)
class TelegraphOrder:
    """What an engine order sets on every shaft: r/min (at the edge, converted to rev/s) and pitch."""

    rpm: float = num("shaft speed order (negative: astern rotation)", "r/min", -5000.0, 5000.0)
    pitch: float = num("pitch ratio order (controllable pitch only)", "", -2.0, 3.0, default=None)


def _read_telegraph(tab, f: str, shafts: list, props: list) -> tuple[dict, dict]:
    """Engine-order table → {order: (rev/s, pitch ratio or None)}, checked against the machinery."""
    if not isinstance(tab, dict):
        raise InputError(f, "telegraph", "expected a table of engine orders")
    default_source = tab.get("source")
    orders, sources = {}, {}
    for key, val in tab.items():
        if key == "source":
            continue
        if key not in ORDERS:
            raise unknown_key(f, "telegraph", key, list(ORDERS))
        if not isinstance(val, dict):
            raise InputError(f, f"telegraph.{key}", "expected { rpm = ..., pitch = ..., source = ... }")
        val = dict(val)
        src = val.pop("source", default_source)
        if not (isinstance(src, str) and src.strip()):
            raise InputError(f, f"telegraph.{key}", "no source given")
        o, _ = read_table(TelegraphOrder, val, f, f"telegraph.{key}")
        rps = o.rpm / 60.0
        for i, sh in enumerate(shafts):
            if abs(rps) > sh.max_rps + 1e-12:
                raise InputError(f, f"telegraph.{key}.rpm", f"{o.rpm:g} r/min exceeds shaft {sh.name!r}'s maximum "
                                                            f"{sh.max_rps * 60:g} r/min")
            if sh.controllable_pitch:
                if o.pitch is None:
                    raise InputError(f, f"telegraph.{key}.pitch", "missing: the propellers are controllable pitch")
                if not (sh.pitch_min <= o.pitch <= sh.pitch_max):
                    raise InputError(f, f"telegraph.{key}.pitch", f"{o.pitch:g} outside shaft {sh.name!r}'s pitch range "
                                                                  f"[{sh.pitch_min:g}, {sh.pitch_max:g}]")
            elif o.pitch is not None:
                raise InputError(f, f"telegraph.{key}.pitch", "fixed-pitch propellers take no pitch order")
        orders[key] = (rps, o.pitch)
        sources[key] = src
    missing = [k for k in ORDERS if k not in orders]
    if missing:
        raise InputError(f, f"telegraph.{missing[0]}", f"missing engine order (every ship needs {', '.join(ORDERS)})")
    return orders, sources


_HULLS = {"mmg": ("hull_mmg", hull_mmg.HullMMG), "blanke": ("hull_blanke", hull_blanke.HullBlanke)}
_ARRAYS = {"propeller": propeller.Propeller, "shaft": propulsion.Shaft, "rudder": rudder.Rudder}


@dataclasses.dataclass
class Vessel:
    """A loaded, checked vessel model."""

    name: str
    folder: Path
    toml_path: Path
    mjcf_path: Path
    meta: Meta
    particulars: Particulars
    inertia: Inertia
    hydrostatics: Hydrostatics
    added_mass: AddedMass
    damping: Damping
    autopilot: Autopilot
    hull: object
    resistance: object
    windage: object
    propellers: list
    shafts: list
    rudders: list
    sources: dict
    model: mujoco.MjModel
    sites: dict
    # derived
    mass: float = 0.0
    r_G: np.ndarray = None
    M_RB: np.ndarray = None
    M_A: np.ndarray = None
    B_lin: np.ndarray = None
    rudder_adr: np.ndarray = None  # (nr, 2): qpos address, dof address
    shaft_params: np.ndarray = None  # (ns, NSHAFTP)
    steering: np.ndarray = None  # (nr, 6): max angle [rad], rate [rad/s], T [s], qadr, dadr, armature
    telegraph: dict = None  # engine order → (rev/s, pitch ratio or None)
    components: list = dataclasses.field(default_factory=list)

    @property
    def length(self) -> float:
        return self.particulars.length

    @property
    def max_rudder(self) -> float:
        """The smallest of the rudders' maximum angles [rad]."""
        return float(np.min(self.steering[:, 0]))

    @property
    def max_rps(self) -> float:
        return float(min(s.max_rps for s in self.shafts))

    def restoring_matrix(self) -> np.ndarray:
        """Linear hydrostatic stiffness (6×6, origin at midship waterline), for checks and tests."""
        p, h = self.particulars, self.hydrostatics
        rho = p.water_density
        C = np.zeros((6, 6))
        C[2, 2] = rho * G * h.waterplane_area
        C[2, 4] = C[4, 2] = -rho * G * h.waterplane_area * h.x_F
        C[3, 3] = rho * G * p.displacement * h.GM_T
        C[4, 4] = rho * G * (p.displacement * h.GM_L + h.waterplane_area * h.x_F ** 2)
        return C


def model_dir(name: str) -> Path:
    return MODELS_DIR / name


def available_models() -> list[str]:
    return sorted(p.name for p in MODELS_DIR.iterdir() if (p / "ship.toml").is_file())


def load_vessel(name_or_path: str | Path, *, file_for_errors: str | None = None,
                field_for_errors: str = "ship") -> Vessel:
    """Load a built-in model by name (``models/<name>/ship.toml`` of the package, never a folder of the
    working directory) or a user's model by an explicit path (a ``Path``, or a string holding a path
    separator or ending in ``.toml``: a model folder or its ship.toml), with its MJCF, checked."""
    where = file_for_errors or str(name_or_path)
    if not isinstance(name_or_path, (str, Path)):
        raise InputError(where, field_for_errors, f"expected a model name or path, got {name_or_path!r}"[:200])
    s = str(name_or_path)
    if "\x00" in s or not s:
        raise InputError(where, field_for_errors, f"{s!r} is not a model name or path")
    is_path = isinstance(name_or_path, Path) or "/" in s or os.sep in s or s.endswith(".toml")
    if is_path:
        p = Path(name_or_path)
        if p.suffix == ".toml" and p.is_file():
            toml_path = p
        elif p.is_dir() and (p / "ship.toml").is_file():
            toml_path = p / "ship.toml"
        else:
            raise InputError(where, field_for_errors, f"no model at {s!r} (expected a model folder holding "
                                                      f"ship.toml, or a ship.toml file)")
    else:
        toml_path = model_dir(s) / "ship.toml"
        if s not in available_models():
            import difflib
            close = difflib.get_close_matches(s, available_models(), n=1, cutoff=0.6)
            hint = f"; did you mean {close[0]!r}?" if close else ""
            raise InputError(where, field_for_errors,
                             f"unknown ship {s!r}{hint} (built-in models: {', '.join(available_models())}; "
                             f"a model of your own is given by its path, e.g. ./{s})")
    f = str(toml_path)
    doc = load_toml(toml_path)
    known = list(_SECTIONS) + [v[0] for v in _HULLS.values()] + list(_ARRAYS) + ["resistance", "telegraph", "windage"]
    for key in doc:
        if key not in known:
            raise unknown_key(f, "", key, known)
    parts = {}
    sources: dict[str, dict] = {}
    for sec, cls in _SECTIONS.items():
        if sec not in doc:
            raise InputError(f, sec, "missing section")
        parts[sec], sources[sec] = read_table(cls, doc[sec], f, sec, sourced=(sec != "meta"))
    meta: Meta = parts["meta"]
    am: AddedMass = parts["added_mass"]
    mmg_fields = ("m_x_prime", "m_y_prime", "J_z_prime", "roll_ratio")
    der_fields = ("X_udot", "Y_vdot", "Y_pdot", "Y_rdot", "K_vdot", "K_pdot", "K_rdot", "N_vdot", "N_pdot", "N_rdot")
    wrong = [k for k in (der_fields if am.form == "mmg" else mmg_fields) if k in doc["added_mass"]]
    if wrong:
        raise InputError(f, f"added_mass.{wrong[0]}", f"not used with added_mass.form = {am.form!r}")
    hull_sec, hull_cls = _HULLS[meta.hull_model]
    if hull_sec not in doc:
        raise InputError(f, hull_sec, f"missing section (meta.hull_model is {meta.hull_model!r})")
    hull, sources[hull_sec] = read_table(hull_cls, doc[hull_sec], f, hull_sec, sourced=True)
    for other, _ in _HULLS.values():
        if other != hull_sec and other in doc:
            raise InputError(f, other, f"section for another hull model (meta.hull_model is {meta.hull_model!r})")
    resistance = None
    if meta.hull_model == "blanke":
        if "resistance" not in doc:
            raise InputError(f, "resistance", "missing section (the blanke hull takes its resistance curve from it)")
        resistance, sources["resistance"] = read_table(Resistance, doc["resistance"], f, "resistance", sourced=True)
        sp, rv = np.array(resistance.speeds), np.array(resistance.values)
        if len(sp) != len(rv) or len(sp) < 2:
            raise InputError(f, "resistance.values", "needs as many values as speeds (at least 2)")
        if sp[0] != 0.0 or rv[0] != 0.0 or np.any(np.diff(sp) <= 0):
            raise InputError(f, "resistance.speeds", "must start at 0 m/s (with 0 N) and increase")
    elif "resistance" in doc:
        raise InputError(f, "resistance", "only the blanke hull model takes a resistance table")
    parts["resistance"] = resistance
    windage = None
    if "windage" in doc:
        windage, sources["windage"] = read_table(wind.Windage, doc["windage"], f, "windage", sourced=True)
    parts["windage"] = windage
    arrays: dict[str, list] = {}
    for sec, cls in _ARRAYS.items():
        items = doc.get(sec, [])
        if not isinstance(items, list) or not items:
            raise InputError(f, sec, f"expected at least one [[{sec}]] table")
        arrays[sec] = []
        for i, tab in enumerate(items):
            obj, src = read_table(cls, tab, f, f"{sec}[{i}]", sourced=True)
            arrays[sec].append(obj)
            sources[f"{sec}[{i}]"] = src
    if "telegraph" not in doc:
        raise InputError(f, "telegraph", "missing section (engine orders → r/min and pitch)")
    telegraph, sources["telegraph"] = _read_telegraph(doc["telegraph"], f, arrays["shaft"], arrays["propeller"])
    vessel = _assemble(toml_path, meta, parts, hull, arrays, sources)
    vessel.telegraph = telegraph
    return vessel


def _names(items, f, sec):
    names = [it.name for it in items]
    for i, n in enumerate(names):
        if names.index(n) != i:
            raise InputError(f, f"{sec}[{i}].name", f"duplicate name {n!r}")
    return names


def _assemble(toml_path: Path, meta: Meta, parts: dict, hull, arrays: dict, sources: dict) -> Vessel:
    f = str(toml_path)
    folder = toml_path.parent
    if meta.name != folder.name:
        raise InputError(f, "meta.name", f"{meta.name!r} differs from the model folder name {folder.name!r}")
    mjcf_path = folder / meta.mjcf
    if not mjcf_path.is_file():
        raise InputError(f, "meta.mjcf", f"MJCF file {meta.mjcf!r} not found in {folder}")
    try:
        model = mujoco.MjModel.from_xml_path(str(mjcf_path))
    except ValueError as exc:
        msg = str(exc).strip().replace("\n", " ")
        raise InputError(str(mjcf_path), "", f"MuJoCo cannot compile it: {msg}") from None
    P: Particulars = parts["particulars"]
    I: Inertia = parts["inertia"]
    H: Hydrostatics = parts["hydrostatics"]
    A: AddedMass = parts["added_mass"]
    D: Damping = parts["damping"]
    # --- the simulation conventions are enforced here, whatever the MJCF says
    model.opt.gravity[:] = (0.0, 0.0, G)
    model.opt.density = 0.0
    model.opt.viscosity = 0.0
    model.opt.wind[:] = 0.0
    model.opt.integrator = mujoco.mjtIntegrator.mjINT_EULER
    # the ship needs MuJoCo's rigid-body dynamics, gravity and integrator only: switching the other
    # stages off makes a step ~35 % cheaper, and autoreset off means MuJoCo never silently resets a
    # diverging ship (vtrials' own checks stop the run with the state instead)
    for bit in ("CONTACT", "CONSTRAINT", "EQUALITY", "FRICTIONLOSS", "LIMIT", "MIDPHASE", "WARMSTART", "SENSOR",
                "ISLAND", "FILTERPARENT", "CLAMPCTRL", "REFSAFE", "EULERDAMP", "AUTORESET", "NATIVECCD",
                "MULTICCD"):
        flag = getattr(mujoco.mjtDisableBit, f"mjDSBL_{bit}", None)
        if flag is not None:
            model.opt.disableflags |= flag
    mf = str(mjcf_path)
    # --- hull body and free joint
    hull_id = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "hull")
    if hull_id < 0:
        raise InputError(mf, "body 'hull'", "missing: the hull must be a body named 'hull'")
    if model.njnt < 1 or model.jnt_type[0] != mujoco.mjtJoint.mjJNT_FREE or model.jnt_bodyid[0] != hull_id:
        raise InputError(mf, "body 'hull'", "the first joint must be a free joint on the hull body")
    mass = P.water_density * P.displacement
    z_G = P.draught - P.KG
    r_G = np.array([P.x_G, 0.0, z_G])
    I_G = mass * np.array([I.k_xx ** 2, I.k_yy ** 2, I.k_zz ** 2])

    def mismatch(field, got, want, tol=1e-6):
        if not np.allclose(got, want, rtol=tol, atol=tol * max(1.0, float(np.max(np.abs(want))))):
            raise InputError(mf, field, f"{np.round(got, 6).tolist()} disagrees with ship.toml, which gives "
                                        f"{np.round(want, 6).tolist()}")

    mismatch("body 'hull' inertial mass (ρ∇)", model.body_mass[hull_id], mass)
    mismatch("body 'hull' inertial pos (x_G, 0, draught − KG)", model.body_ipos[hull_id], r_G)
    if not np.allclose(np.abs(model.body_iquat[hull_id]), [1, 0, 0, 0], atol=1e-9):
        raise InputError(mf, "body 'hull' inertial", "principal axes must be the hull axes (use diaginertia)")
    mismatch("body 'hull' inertial diaginertia (m k²)", model.body_inertia[hull_id], I_G)
    sites = {}
    for i in range(model.nsite):
        nm = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_SITE, i)
        if model.site_bodyid[i] == hull_id and nm:
            sites[nm] = model.site_pos[i].copy()
    # --- propellers, shafts, rudders
    props = arrays["propeller"]
    shafts = arrays["shaft"]
    rudders = arrays["rudder"]
    pnames = _names(props, f, "propeller")
    _names(shafts, f, "shaft")
    _names(rudders, f, "rudder")
    from vtrials.physics.forces.context import MAX_RUDDERS, MAX_SHAFTS
    if len(shafts) > MAX_SHAFTS or len(props) > MAX_SHAFTS:
        raise InputError(f, "shaft", f"at most {MAX_SHAFTS} shafts and propellers are supported")
    if len(rudders) > MAX_RUDDERS:
        raise InputError(f, "rudder", f"at most {MAX_RUDDERS} rudders are supported")
    if len(shafts) != len(props):
        raise InputError(f, "shaft", "every propeller needs exactly one shaft")

    def hinge(field, jname, axis_want):
        jid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, jname)
        if jid < 0:
            raise InputError(f, field, f"joint {jname!r} not found in {mjcf_path.name}")
        if model.jnt_type[jid] != mujoco.mjtJoint.mjJNT_HINGE:
            raise InputError(mf, f"joint {jname!r}", "must be a hinge")
        if model.body_parentid[model.jnt_bodyid[jid]] != hull_id:
            raise InputError(mf, f"joint {jname!r}", "its body must be a child of the hull")
        if not np.allclose(model.jnt_axis[jid], axis_want, atol=1e-9):
            raise InputError(mf, f"joint {jname!r} axis", f"{model.jnt_axis[jid].tolist()} but {axis_want} is "
                                                          f"required")
        bid = model.jnt_bodyid[jid]
        if model.body_mass[bid] > 1e-6 * mass:
            raise InputError(mf, f"body of joint {jname!r}", "must be (nearly) massless: its mass belongs to "
                                                              "the hull's inertial, its inertia to the armature")
        return jid, int(model.jnt_qposadr[jid]), int(model.jnt_dofadr[jid])

    used_props = set()
    shaft_rows = [None] * len(props)
    for i, s in enumerate(shafts):
        if s.propeller not in pnames:
            raise InputError(f, f"shaft[{i}].propeller", f"unknown propeller {s.propeller!r} (known: {pnames})")
        if s.propeller in used_props:
            raise InputError(f, f"shaft[{i}].propeller", f"propeller {s.propeller!r} has two shafts")
        used_props.add(s.propeller)
        if s.rotation not in (-1, 1):
            raise InputError(f, f"shaft[{i}].rotation", "must be +1 or -1")
        jid, qadr, dadr = hinge(f"shaft[{i}].joint", s.joint, [float(s.rotation), 0.0, 0.0])
        mismatch(f"joint {s.joint!r} armature (shaft[{i}].inertia)", model.dof_armature[dadr], s.inertia)
        k = pnames.index(s.propeller)
        pr = props[k]
        if s.controllable_pitch:
            if not (s.pitch_min < s.pitch_max and s.pitch_rate > 0):
                raise InputError(f, f"shaft[{i}]", "a controllable-pitch shaft needs pitch_min < pitch_max and "
                                                   "pitch_rate > 0")
            if not (s.pitch_min <= pr.pitch_ratio <= s.pitch_max):
                raise InputError(f, f"shaft[{i}].pitch_max", f"the design pitch ratio {pr.pitch_ratio} of propeller "
                                                             f"{pr.name!r} is outside [pitch_min, pitch_max]")
        if pr.curve == "polynomial" and pr.j_max <= 0:
            raise InputError(f, f"propeller[{k}].j_max", "a polynomial curve needs j_max > 0 (its validity)")
        shaft_rows[k] = propulsion.pack(s, k, qadr, dadr, pr.pitch_ratio)
    shaft_params = np.vstack(shaft_rows)
    rudder_adr = []
    steering = []
    for i, r in enumerate(rudders):
        if r.propeller not in pnames:
            raise InputError(f, f"rudder[{i}].propeller", f"unknown propeller {r.propeller!r} (known: {pnames})")
        jid, qadr, dadr = hinge(f"rudder[{i}].joint", r.joint, [0.0, 0.0, -1.0])
        rudder_adr.append((qadr, dadr))
        steering.append([r.max_angle_deg * DEG, r.rate_deg_s * DEG, r.time_constant, qadr, dadr,
                         model.dof_armature[dadr]])
        if model.dof_armature[dadr] <= 0:
            raise InputError(mf, f"joint of rudder[{i}]", "needs a positive armature (rudder stock inertia)")
    v = Vessel(name=meta.name, folder=folder, toml_path=toml_path, mjcf_path=mjcf_path, meta=meta,
               particulars=P, inertia=I, hydrostatics=H, added_mass=A, damping=D,
               autopilot=parts["autopilot"], hull=hull, resistance=parts["resistance"],
               windage=parts["windage"],
               propellers=props, shafts=shafts, rudders=rudders, sources=sources, model=model, sites=sites)
    v.mass = mass
    v.r_G = r_G
    v.rudder_adr = np.array(rudder_adr, dtype=np.int64)
    v.shaft_params = shaft_params
    v.steering = np.array(steering, dtype=np.float64)
    _derive(v)
    return v


def _derive(v: Vessel) -> None:
    """Rigid-body and added-mass matrices, damping, and the component list."""
    P, I, H, A, D = v.particulars, v.inertia, v.hydrostatics, v.added_mass, v.damping
    model = v.model
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    Mfull = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, data, Mfull)
    v.M_RB = Mfull[:6, :6].copy()
    rho, Lpp, d = P.water_density, P.length, P.draught
    half = 0.5 * rho * Lpp ** 2 * d
    I_G = v.mass * np.array([I.k_xx ** 2, I.k_yy ** 2, I.k_zz ** 2])
    if A.form == "mmg":
        M_A = np.diag([A.m_x_prime * half, A.m_y_prime * half, A.heave_ratio * v.mass,
                       A.roll_ratio * I_G[0], A.pitch_ratio * I_G[1], A.J_z_prime * half * Lpp ** 2])
    else:
        M_A = np.zeros((6, 6))
        M_A[0, 0] = -A.X_udot
        M_A[2, 2] = A.heave_ratio * v.mass
        M_A[4, 4] = A.pitch_ratio * I_G[1]
        for row, (a, b, c) in ((1, (A.Y_vdot, A.Y_pdot, A.Y_rdot)), (3, (A.K_vdot, A.K_pdot, A.K_rdot)),
                               (5, (A.N_vdot, A.N_pdot, A.N_rdot))):
            M_A[row, 1], M_A[row, 3], M_A[row, 5] = -a, -b, -c
    v.M_A = M_A
    C = v.restoring_matrix()
    Mtot = v.M_RB + M_A
    B = np.zeros(3)
    for j, (dof, zeta) in enumerate(((2, D.heave_ratio), (3, D.roll_ratio), (4, D.pitch_ratio))):
        B[j] = 2.0 * zeta * math.sqrt(Mtot[dof, dof] * C[dof, dof])
    v.B_lin = B
    u_floor = 1e-3 * math.sqrt(G * Lpp)
    if v.meta.hull_model == "mmg":
        comps = [Component("hull", "hull_mmg", hull_mmg.pack(v.hull, Lpp, d, rho, u_floor))]
    else:
        comps = [Component("hull", "hull_blanke",
                           hull_blanke.pack(v.hull, np.array(v.resistance.speeds), np.array(v.resistance.values)))]
    pnames = [p.name for p in v.propellers]
    rot = {sh.propeller: sh.rotation for sh in v.shafts}
    for k, pr in enumerate(v.propellers):
        comps.append(Component(f"propeller:{pr.name}", "propeller",
                               propeller.pack(pr, k, Lpp, rho, u_floor, rot[pr.name])))
    for k, rd in enumerate(v.rudders):
        kp = pnames.index(rd.propeller)
        comps.append(Component(f"rudder:{rd.name}", "rudder",
                               rudder.pack(rd, k, kp, v.propellers[kp].diameter, Lpp, rho, u_floor,
                                               v.hull.z_H)))
    if v.windage is not None:
        comps.append(Component("wind", "wind", wind.pack_wind(v.windage)))
    comps.append(Component("hydrostatics", "hydrostatics",
                           hydrostatics.pack_restoring(v.mass, G, rho, P.displacement, H.waterplane_area, H.x_F,
                                                       H.GM_T, H.GM_L, v.r_G, P.draught - H.KB)))
    comps.append(Component("damping", "damping",
                           hydrostatics.pack_damping(B[0], B[1], B[2], D.roll_quadratic)))
    v.components = comps
