"""The trials team's design-stage RAO model: heave, roll and pitch of the ship per metre of wave amplitude.

The team's model file (models/<ship>/design/<ship>_design_rao.nc, written offline by
``python -m vtrials.physics.seakeeping.design``; README.md beside it states how it differs from the
simulator's truth) holds zero-speed BEM coefficients of the design mesh, the design mass and restoring
matrices and a fixed linear roll damping. The RAO at forward speed U is the design office's usual
encounter-frequency correction and a roll damping growing with speed (the file's ``roll_damping_per_speed``,
e.g. Ikeda's hull lift) and nothing more (e.g. Lloyd 1989, "Seakeeping", §§ 5, 9):

    [−ω_e² (M + A(|ω_e|)) + iω_e (B(|ω_e|) + B_44 + U B_44,U) + C] ξ̂ = X(ω, μ),   ω_e = ω − ω² U cos μ / g,

for ξ over the file's free DOFs (``free_dofs``: sway, heave, roll and pitch in the current files, sway
coupled with roll as strip theory has it, Salvesen, Tuck & Faltinsen 1970; heave, roll and pitch alone in
older ones; yaw may be listed too), the others held, sway and yaw without restoring; the RAOs returned are
heave (z down), roll φ and pitch θ at the body origin O. Where |ω_e| < :data:`OMEGA_E_FREE` (following
seas near ω_e = 0) sway and yaw, which have no restoring, are held instead (their response is undefined
there); e^{+iω_e t},
crest at O at t = 0 (the file's convention). μ is the direction the waves travel relative to the
heading (0 following, π head seas, +π/2 travelling to starboard); the file stores 0 ≤ μ ≤ π and the
other side follows by port–starboard symmetry (roll changes sign). Outside the file's frequencies:
A held at its end values below ω_min and going linearly to A∞ by 2 ω_max above; B linear to 0 at
ω_e = 0 and at 2 ω_max; X held below ω_min and zero above ω_max (design-stage simplifications, stated).

A point at (x, y) from O [m] (body axes, y starboard) moves vertically by z − x θ + y φ (z down):
:meth:`DesignRAO.vertical` gives it positive UP, the quantity :mod:`vtrials.reduce.heave` returns.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from vtrials.errors import InputError
from vtrials.records.design import read_team_model

FREE = (2, 3, 4)                        # heave, roll, pitch: the outputs (and the free DOFs of older files)
SIGN_Y = np.array([1.0, -1.0, 1.0, -1.0, 1.0, -1.0])   # y → −y: sway, roll and yaw change sign
SYMMETRIC_DOFS = (0, 2, 4)              # surge, heave, pitch (port–starboard symmetric modes)
#: Encounter frequency [rad/s] below which sway and yaw (no restoring) are held (module doc).
OMEGA_E_FREE = 0.05
MODELS_DIR = Path(__file__).resolve().parents[2] / "models"


class DesignRAO:
    """A design-stage RAO model read from a team model file (module doc)."""

    def __init__(self, path: str | Path):
        data, attrs = read_team_model(path)
        need = ("omega", "heading", "added_mass", "radiation_damping", "added_mass_infinite_frequency",
                "rigid_body_mass", "restoring", "excitation_force_re", "excitation_force_im")
        miss = [k for k in need if k not in data]
        if miss or "roll_damping_linear" not in attrs:
            raise InputError(str(path), ", ".join(miss) or "roll_damping_linear",
                             "missing from the design RAO file (write it with vtrials.physics.seakeeping.design)")
        self.path = Path(path)
        self.attrs = attrs
        self.omega = np.asarray(data["omega"], dtype=float)
        self.headings = np.asarray(data["heading"], dtype=float)
        free = tuple(int(d) for d in json.loads(attrs.get("free_dofs", "[2, 3, 4]")))
        if not set(FREE) <= set(free) or not set(free) <= {1, 2, 3, 4, 5}:
            raise InputError(str(path), "free_dofs", f"{list(free)}: must include heave, roll and pitch (2, 3, 4) "
                             "and only sway, heave, roll, pitch, yaw (1-5)")
        self.free = free
        self._out = [free.index(d) for d in FREE]                  # heave, roll, pitch within the free DOFs
        self._horiz = [k for k, d in enumerate(free) if d in (1, 5)]
        ix = np.ix_(range(self.omega.size), free, free)
        self.A = np.array(data["added_mass"][ix], dtype=float)
        self.B = np.array(data["radiation_damping"][ix], dtype=float)
        sub = np.ix_(free, free)
        self.A_inf = np.array(data["added_mass_infinite_frequency"][sub], dtype=float)
        self.M = np.array(data["rigid_body_mass"][sub], dtype=float)
        self.C = np.array(data["restoring"][sub], dtype=float)
        self.B44 = float(attrs["roll_damping_linear"])
        self.B44_per_speed = float(attrs.get("roll_damping_per_speed", 0.0))   # [N m s per m/s]
        self.X = (data["excitation_force_re"] + 1j * data["excitation_force_im"])[:, :, list(free)]
        self._mirror = SIGN_Y[list(free)]
        # port–starboard symmetry of the hull: the symmetric modes (heave, pitch) are uncoupled from the
        # antisymmetric ones (sway, roll, yaw); the BEM's and the mesh hydrostatics' numerical couplings,
        # ~1e-4 of the diagonals, are set to zero
        sym = [k for k, d in enumerate(free) if d in SYMMETRIC_DOFS]
        anti = [k for k, d in enumerate(free) if d not in SYMMETRIC_DOFS]
        for a in (self.A, self.B):
            a[np.ix_(range(a.shape[0]), sym, anti)] = 0.0
            a[np.ix_(range(a.shape[0]), anti, sym)] = 0.0
        for a in (self.A_inf, self.M, self.C):
            a[np.ix_(sym, anti)] = 0.0
            a[np.ix_(anti, sym)] = 0.0
        self.g = float(attrs["g"])
        self.x_from_midship = float(attrs["reference_x_from_midship"])
        self.design = json.loads(attrs.get("design_toml", "{}"))
        # frequency grid for A, B extended to 0 and 2 ω_max (module doc)
        w_hi = 2.0 * self.omega[-1]
        self._wg = np.concatenate(([0.0], self.omega, [w_hi]))
        self._Ag = np.concatenate((self.A[:1], self.A, self.A_inf[None]), axis=0)
        z = np.zeros((1, len(free), len(free)))
        self._Bg = np.concatenate((z, self.B, z), axis=0)

    def _coeff(self, grid_vals, w):
        flat = grid_vals.reshape(self._wg.size, -1)
        out = np.empty((w.size, flat.shape[1]))
        for c in range(flat.shape[1]):
            out[:, c] = np.interp(w, self._wg, flat[:, c])
        n = len(self.free)
        return out.reshape((w.size, n, n))

    def excitation(self, omega, mu) -> np.ndarray:
        """X (…, n) [N/m, N m/m] of the free DOFs at wave frequencies ω and directions μ (broadcast)."""
        w, m = np.broadcast_arrays(np.asarray(omega, dtype=float), np.asarray(mu, dtype=float))
        b = np.remainder(m + math.pi, 2.0 * math.pi) - math.pi      # [−π, π)
        sgn = np.where(b < 0.0, -1.0, 1.0)
        b = np.abs(b)
        h = self.headings
        jb = np.clip(np.searchsorted(h, b) - 1, 0, h.size - 2)
        fb = np.clip((b - h[jb]) / (h[jb + 1] - h[jb]), 0.0, 1.0)
        om = self.omega
        jw = np.clip(np.searchsorted(om, w) - 1, 0, om.size - 2)
        fw = np.clip((w - om[jw]) / (om[jw + 1] - om[jw]), 0.0, 1.0)
        X = self.X
        x = ((1 - fw)[..., None] * ((1 - fb)[..., None] * X[jw, jb] + fb[..., None] * X[jw, jb + 1])
             + fw[..., None] * ((1 - fb)[..., None] * X[jw + 1, jb] + fb[..., None] * X[jw + 1, jb + 1]))
        x = np.where((w > om[-1])[..., None], 0.0, x)
        mirror = np.where(sgn[..., None] < 0.0, self._mirror, 1.0)
        return x * mirror

    def _system(self, omega, mu, U: float):
        """(Z (n, k, k), X (n, k), ω_e (n,), shape) of the free DOFs at the flattened (ω, μ) (module doc)."""
        if not (math.isfinite(U) and U >= 0.0):
            raise InputError("record", "U", f"ship speed {U!r} m/s: must be a finite number ≥ 0")
        w, m = np.broadcast_arrays(np.asarray(omega, dtype=float), np.asarray(mu, dtype=float))
        if np.any(~np.isfinite(w)) or np.any(w <= 0.0):
            raise InputError("record", "omega", "wave frequencies must be finite and > 0 rad/s")
        shape = w.shape
        w, m = w.ravel(), m.ravel()
        we = w - w * w * U * np.cos(m) / self.g
        awe = np.abs(we)
        A = self._coeff(self._Ag, awe)
        Bc = self._coeff(self._Bg, awe)
        r = self._out[1]
        Bc[:, r, r] += self.B44 + self.B44_per_speed * U
        Z = -(we ** 2)[:, None, None] * (self.M + A) + 1j * we[:, None, None] * Bc + self.C
        X = self.excitation(w, m)
        held = awe < OMEGA_E_FREE
        if self._horiz and np.any(held):            # sway and yaw held: unit rows and columns, no force
            h = self._horiz
            Zh = Z[held]
            Zh[:, h, :] = 0.0
            Zh[:, :, h] = 0.0
            Zh[:, h, h] = 1.0
            Z[held] = Zh
            Xh = X[held]
            Xh[:, h] = 0.0
            X[held] = Xh
        return Z, X, we, shape

    def rao(self, omega, mu, U: float) -> np.ndarray:
        """Complex RAOs (3, …) of heave (z down) [m/m], roll [rad/m], pitch [rad/m] at O (module doc).

        omega [rad/s] > 0 and mu [rad] broadcast together; U [m/s] ≥ 0.
        """
        Z, X, _, shape = self._system(omega, mu, U)
        out = np.linalg.solve(Z, X[..., None])[..., 0][:, self._out]
        return np.moveaxis(out, -1, 0).reshape((3,) + shape)

    def roll_receptance(self, omega, mu, U: float) -> np.ndarray:
        """Roll per unit roll moment h_φ [rad/(N m)] at the encounter frequency of (ω, μ) (complex, shape of
        the broadcast inputs): the (roll, roll) element of Z⁻¹, with sway (and yaw) free as in :meth:`rao`.
        A change δ = ΔC₄₄ + iω_e ΔB₄₄ of the roll stiffness and damping scales the roll RAO by
        1/(1 + δ h_φ) (Sherman–Morrison; heave and pitch are uncoupled from roll by symmetry)."""
        Z, _, _, shape = self._system(omega, mu, U)
        e = np.zeros(Z.shape[:2], dtype=complex)
        e[:, self._out[1]] = 1.0
        h = np.linalg.solve(Z, e[..., None])[..., 0][:, self._out[1]]
        return h.reshape(shape)

    @property
    def roll_scales(self) -> tuple[float, float]:
        """(C₄₄ [N m/rad], 2 C₄₄/ω_n [N m s/rad]): the design roll stiffness and critical damping at the design
        roll natural frequency, the units in which a fit reports roll stiffness and damping changes."""
        r = self._out[1]
        c44 = float(self.C[r, r])
        return c44, 2.0 * c44 / float(self.attrs["roll_natural_frequency"])

    def roll_damping_ratio(self, U: float) -> float:
        """The design's roll damping at speed U [m/s] as a fraction of :attr:`roll_scales`' critical damping:
        the fixed ratio plus the per-speed term."""
        return float(self.attrs.get("roll_damping_ratio", 0.0)) + self.B44_per_speed * U / self.roll_scales[1]

    def vertical(self, rao, x: float, y: float = 0.0) -> np.ndarray:
        """Vertical displacement UP [m/m] of the point (x, y) from O (body axes) from rao (3, …) of :meth:`rao`."""
        rao = np.asarray(rao)
        return -(rao[0] - x * rao[2] + y * rao[1])


def load_design_rao(ship: str, models_dir: str | Path | None = None) -> DesignRAO:
    """The design-stage RAO model of ``ship`` from models/<ship>/design/<ship>_design_rao.nc."""
    base = Path(models_dir) if models_dir is not None else MODELS_DIR
    return DesignRAO(base / ship / "design" / f"{ship}_design_rao.nc")
