"""Frequency-domain hydrodynamic database of a ship, read from the netCDF file shipped in its model folder.

The file is written offline by :mod:`.build` (Capytaine); reading needs only h5py. Everything is in
SI units, vtrials body axes about the ship's body origin O (on the calm waterline, centreline; x
forward, y starboard, z down), dof order (surge, sway, heave, roll, pitch, yaw), zero forward speed,
deep water.

Conventions the time-domain code relies on
-------------------------------------------
* Heading β [rad]: the direction in which the waves travel, relative to the ship, measured from +x
  towards +y (starboard). β = π: head seas (waves coming from ahead); 0: following seas; π/2: waves
  travelling to starboard (coming from port). The file holds 0 ≤ β ≤ π; :meth:`HydroDatabase.excitation`
  and :meth:`HydroDatabase.drift_at` extend to any β by port-starboard symmetry.
* Incident wave of amplitude a: η(x, y, t) = Re{a exp(i(ωt − k(x cos β + y sin β)))}, (x, y) in body
  axes relative to O, k = ω²/g: a crest passes O at t = 0.
* Excitation: F_j(t) = Re{X_j(ω, β) a exp(iωt)} [N or N m], X per metre of amplitude; X = X_FK + X_diff.
* Radiation: F_i = −A_ij(ω) ξ̈_j − B_ij(ω) ξ̇_j for harmonic motion (A, B real), A_inf = A(ω → ∞).
* Hydrostatics: F_i = −C_ij ξ_j (C: the meshed hull's buoyancy with the model's weight at G;
  ``C_model``: the model file's own restoring matrix, for comparison).
* Mean drift: F̄ = drift(ω, β) a² (surge [N], sway [N], yaw [N m]; per unit amplitude squared).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from vtrials.errors import InputError

MIRROR = np.array([1.0, -1.0, 1.0, -1.0, 1.0, -1.0])    # y → −y: sway, roll, yaw change sign
MIRROR_DRIFT = np.array([1.0, -1.0, -1.0])              # surge, sway, yaw


@dataclass(frozen=True)
class HydroDatabase:
    """Hydrodynamic coefficients of one ship (see the module docstring for axes and conventions).

    omega (nω,) [rad/s]; headings (nβ,) [rad]; A, B (nω, 6, 6); A_inf, C, C_model, mass_matrix (6, 6);
    X, X_FK, X_diff complex (nω, nβ, 6); drift (nω, nβ, 3) or None; rho [kg/m³]; g [m/s²];
    reference_point (3,) [m] in body axes (O = 0); reference_x_from_midship [m]; mass [kg];
    center_of_gravity (3,) [m] from O; radii_of_gyration (3,) [m] about G; attrs: the file's metadata.
    """

    omega: np.ndarray
    headings: np.ndarray
    A: np.ndarray
    B: np.ndarray
    A_inf: np.ndarray
    C: np.ndarray
    C_model: np.ndarray
    X: np.ndarray
    X_FK: np.ndarray
    X_diff: np.ndarray
    drift: np.ndarray | None
    rho: float
    g: float
    reference_point: np.ndarray
    reference_x_from_midship: float
    mass: float
    center_of_gravity: np.ndarray
    radii_of_gyration: np.ndarray
    mass_matrix: np.ndarray
    attrs: dict = field(default_factory=dict, compare=False, repr=False)

    @property
    def wavenumber(self) -> np.ndarray:
        """Deep-water wavenumber k = ω²/g [rad/m]."""
        return self.omega ** 2 / self.g

    def _heading_weights(self, beta: float):
        """(i0, i1, w, mirrored) to interpolate linearly in heading at any β (rad)."""
        b = math.remainder(float(beta), 2.0 * math.pi)      # (−π, π]
        mirrored = b < 0.0
        b = abs(b)
        h = self.headings
        if b <= h[0]:
            return 0, 0, 0.0, mirrored
        if b >= h[-1]:
            n = h.size - 1
            return n, n, 0.0, mirrored
        i1 = int(np.searchsorted(h, b))
        i0 = i1 - 1
        return i0, i1, (b - h[i0]) / (h[i1] - h[i0]), mirrored

    def excitation(self, beta: float, part: str = "total") -> np.ndarray:
        """X(ω, β) (nω, 6) complex at any heading β [rad]: linear interpolation of the complex values
        between stored headings, mirror image X(−β) = S X(β), S = diag(1, −1, 1, −1, 1, −1).
        ``part``: "total", "froude_krylov" or "diffraction"."""
        arr = {"total": self.X, "froude_krylov": self.X_FK, "diffraction": self.X_diff}.get(part)
        if arr is None:
            raise InputError("excitation", "part", f"must be total, froude_krylov or diffraction, got {part!r}")
        i0, i1, w, mirrored = self._heading_weights(beta)
        x = (1.0 - w) * arr[:, i0, :] + w * arr[:, i1, :]
        return x * MIRROR if mirrored else x

    def drift_at(self, beta: float) -> np.ndarray:
        """Mean drift (nω, 3) per unit amplitude² at any heading β [rad] (surge, sway, yaw)."""
        if self.drift is None:
            raise InputError(self.attrs.get("_path", "database"), "mean_drift_force", "not in this database")
        i0, i1, w, mirrored = self._heading_weights(beta)
        d = (1.0 - w) * self.drift[:, i0, :] + w * self.drift[:, i1, :]
        return d * MIRROR_DRIFT if mirrored else d


_REQUIRED = {
    "omega": ("omega",), "heading": ("heading",),
    "added_mass": ("omega", 6, 6), "radiation_damping": ("omega", 6, 6),
    "added_mass_infinite_frequency": (6, 6), "hydrostatic_stiffness": (6, 6),
    "hydrostatic_stiffness_model": (6, 6), "rigid_body_mass": (6, 6),
    "excitation_force_re": ("omega", "heading", 6), "excitation_force_im": ("omega", "heading", 6),
    "froude_krylov_force_re": ("omega", "heading", 6), "froude_krylov_force_im": ("omega", "heading", 6),
    "diffraction_force_re": ("omega", "heading", 6), "diffraction_force_im": ("omega", "heading", 6),
}
_REQUIRED_ATTRS = ("rho", "g", "reference_point", "reference_point_x_from_midship", "mass",
                   "center_of_gravity", "radii_of_gyration", "heading_convention", "phase_convention")


def _attr(v):
    if isinstance(v, bytes):
        return v.decode()
    if isinstance(v, np.ndarray) and v.size == 1:
        return v.item()
    if isinstance(v, np.generic):
        return v.item()
    return v


def load_database(path) -> HydroDatabase:
    """Read a ``<ship>_hydro.nc`` database (h5py only) and check it.

    Raises :class:`vtrials.errors.InputError` naming the file, the variable or attribute and what is
    expected, for a missing/unreadable file, missing variables or attributes, wrong shapes,
    non-finite values, non-increasing or non-positive frequencies, headings outside [0, π], or
    non-positive density/gravity.
    """
    import h5py

    p = Path(path)
    f_name = str(p)
    if not p.is_file():
        raise InputError(f_name, "", "file not found")
    try:
        fh = h5py.File(p, "r")
    except OSError as e:
        raise InputError(f_name, "", f"not a readable netCDF4/HDF5 file ({e})") from None
    with fh as f:
        data = {}
        for name in _REQUIRED:
            if name not in f:
                raise InputError(f_name, name, "variable missing (a database written by "
                                 "vtrials.physics.seakeeping.build has it)")
            data[name] = np.asarray(f[name][()], dtype=float)
        drift = np.asarray(f["mean_drift_force"][()], dtype=float) if "mean_drift_force" in f else None
        attrs = {k: _attr(v) for k, v in f.attrs.items()}
    for k in _REQUIRED_ATTRS:
        if k not in attrs:
            raise InputError(f_name, k, "global attribute missing")
    n_w, n_b = data["omega"].size, data["heading"].size
    sizes = {"omega": n_w, "heading": n_b}
    for name, dims in _REQUIRED.items():
        want = tuple(sizes[d] if isinstance(d, str) else d for d in dims)
        if data[name].shape != want:
            raise InputError(f_name, name, f"shape {data[name].shape}, expected {want}")
        if not np.all(np.isfinite(data[name])):
            raise InputError(f_name, name, "contains non-finite values")
    if drift is not None:
        if drift.shape != (n_w, n_b, 3):
            raise InputError(f_name, "mean_drift_force", f"shape {drift.shape}, expected {(n_w, n_b, 3)}")
        if not np.all(np.isfinite(drift)):
            raise InputError(f_name, "mean_drift_force", "contains non-finite values")
    w, h = data["omega"], data["heading"]
    if n_w < 2 or not (w[0] > 0.0 and np.all(np.diff(w) > 0.0)):
        raise InputError(f_name, "omega", "must hold at least two positive, strictly increasing frequencies [rad/s]")
    if n_b < 1 or not (h[0] >= 0.0 and h[-1] <= math.pi + 1e-12 and np.all(np.diff(h) > 0.0)):
        raise InputError(f_name, "heading", "must be strictly increasing within [0, pi] rad")
    rho, g = float(attrs["rho"]), float(attrs["g"])
    for key, v in (("rho", rho), ("g", g), ("mass", float(attrs["mass"]))):
        if not (math.isfinite(v) and v > 0.0):
            raise InputError(f_name, key, f"must be a positive number, got {v!r}")

    def vec3(key):
        try:
            v = np.asarray(json.loads(attrs[key]), dtype=float)
        except (TypeError, ValueError):
            v = np.asarray(attrs[key], dtype=float)
        if v.shape != (3,) or not np.all(np.isfinite(v)):
            raise InputError(f_name, key, f"must be three finite numbers, got {attrs[key]!r}")
        return v

    def cplx(prefix):
        return data[f"{prefix}_re"] + 1j * data[f"{prefix}_im"]

    attrs["_path"] = f_name
    return HydroDatabase(
        omega=w, headings=h, A=data["added_mass"], B=data["radiation_damping"],
        A_inf=data["added_mass_infinite_frequency"], C=data["hydrostatic_stiffness"],
        C_model=data["hydrostatic_stiffness_model"], X=cplx("excitation_force"),
        X_FK=cplx("froude_krylov_force"), X_diff=cplx("diffraction_force"), drift=drift, rho=rho, g=g,
        reference_point=vec3("reference_point"),
        reference_x_from_midship=float(attrs["reference_point_x_from_midship"]), mass=float(attrs["mass"]),
        center_of_gravity=vec3("center_of_gravity"), radii_of_gyration=vec3("radii_of_gyration"),
        mass_matrix=data["rigid_body_mass"], attrs=attrs)
