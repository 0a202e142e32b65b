"""A ship set up for seakeeping in the time domain: the vessel's maneuvering model plus wave loads.

How the two models combine (nothing counted twice):

* Surge and yaw: the maneuvering model (hull, propellers, rudders, its added mass) is kept unchanged.
  The first-order wave excitation acts on them (unless masked), but no radiation memory: their
  hydrodynamic reaction stays the maneuvering model's.
* Sway: the maneuvering model's hull forces, but its added mass and its couplings with heave, roll and
  pitch are the database's A∞, with the radiation memory of sway and of the sway–roll coupling
  (inputs: the body sway velocity; K̂(0) = 0, so a steady drift angle gets no memory force). Reason:
  the long-wave limit. In a long beam wave a ship sways with the water and heels with the wave slope
  only if the wave excitation (whose diffraction part carries the hull's own A22(ω), A42(ω)) meets the
  same added mass in the dynamics. Measured on patrol51 (stand-in hull fitted to BC93's KM, zero
  speed, ω 0.2–0.5 rad/s, :func:`.linearize.coupled_rao`): with BC93's Y_v̇ and its antisymmetric
  sway–roll added mass (Y_ṗ = −K_v̇, where potential flow makes it symmetric) it heeled 2.8–3.4 times
  the wave slope and swayed 0.91–0.97 of the water; with the database's symmetric A24 but BC93's Y_v̇,
  1.5–1.7 times and 0.77; with the database's sway added mass and memory, 1.08–1.23 times (the quasi-
  static 1/(1 − (ω/ω_n)²) with ω_n 1.14 rad/s is 1.03–1.24) and 0.98–1.00 (tests/test_seakeeping_sim.py).
  The price: in waves the sway added mass at maneuvering frequencies is the stand-in hull's
  A22(ω → 0) (patrol51 ≈ 3.3e5 kg at 0.2 rad/s against BC93's
  Y_v̇ 3.93e5 kg), so maneuvers in waves see a slightly lighter ship in sway than in calm water.
* Heave, roll, pitch (the seakeeping DOFs): the maneuvering model has only the hydrostatic restoring
  and a linear/quadratic damping there. With seakeeping on
  - the added mass of these DOFs (and their couplings among themselves) is the database's A∞ in the
    exact added-mass solve of the dynamics (replacing the ship file's heave/roll/pitch ratios);
  - the frequency-dependent part is the radiation memory component (:mod:`vtrials.physics.forces.radiation`),
    driven by the heave, roll and pitch velocities, which are perturbations about the maneuvering
    motion; the potential damping is therefore in the memory, and the ship file's linear heave and
    pitch damping is removed;
  - roll: the wave part of roll damping comes from the memory; the viscous part is the
    ``roll_damping`` component (:mod:`vtrials.physics.forces.roll_damping`), set by the model's
    ``hydro/hull.toml`` ``[roll_damping]`` table. Every roll damping term of the maneuvering model is
    removed so that nothing is counted twice: the ship file's roll_ratio / roll_quadratic (damping
    component) and, for the Blanke hull, K_p, K_|u|p and K_p|p| (BC93's measured roll damping, which
    includes the wave part). ``method = "ikeda"``: Ikeda's viscous components (friction, eddy,
    lift, bilge keels); ``method = "hull_model"``: those removed terms come back in the component,
    less the database's potential damping B44(ω_n) at the natural roll frequency (so the total at
    ω_n is the ship file's, the wave part now frequency-dependent from the memory).
* The maneuvering forces (hull, rudders, propellers) see the ship's sway, yaw rate and heel relative to
  the waves' cross-flow, its gradient along the ship and the surface slope, averaged over the hull
  (:mod:`vtrials.physics.forces.wave_flow`): lift is a force of the motion relative to the water. On
  the absolute motion, patrol51 at 9 m/s heeled 3.0–3.6 × the slope of long beam waves (at rest 1.08 ×)
  and rolled about twice as much in bow seas as with the relative flow.
* Mean drift (surge, sway, yaw): the database's zero-speed drift per component
  (:mod:`vtrials.physics.forces.wave_drift`); the maneuvering model's calm-water resistance is unchanged,
  so the added resistance is this force alone.
* Forward speed: no speed corrections are added. The dynamics apply A∞ to body-axis accelerations,
  and the body heave velocity is w = ż + Uθ, so the time domain carries a speed coupling
  A∞_i3 U θ̇ (the A∞ part of Salvesen–Tuck–Faltinsen's B35 = B35⁰ + U A33); the matching RAO is
  :func:`.rao.rao` with ``body_axes_added_mass=True`` for heave and pitch in head seas.
* The frequency-domain reference for this whole coupled system (free sway and yaw, the maneuvering
  model's speed-dependent sway–roll–yaw hull terms, autopilot and steering) is
  :func:`.linearize.coupled_rao`; :func:`.rao.rao` holds the horizontal DOFs.
* Restoring stays the ship file's hydrostatics component (not the database mesh's C). The stand-in
  hull's waterplane should give the ship file's KM, or the wave excitation belongs to a hull of
  another roll stiffness: patrol51's is fitted to BC93's KM (hull.toml C_WP; mesh KM within 0.1 %),
  KVLCC2's mesh has GM_T 6.21 m against the ship file's 5.71 m (models/<ship>/hydro/README.md).
"""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np

from vtrials.errors import InputError
from vtrials.physics.forces import roll_damping as rd_mod
from vtrials.physics.forces import hydrostatics
from vtrials.physics.forces import radiation as rad_force
from vtrials.physics.forces import wave_drift, wave_excitation, wave_flow
from vtrials.physics.forces.registry import Component
from vtrials.physics.seakeeping.radiation import fit_radiation

SEAKEEPING_DOFS = (2, 3, 4)
#: DOFs of the radiation memory: the seakeeping DOFs and sway (see the module notes: the sway–roll
#: coupling and the sway added mass in waves are the database's, so that the long-wave limit holds).
MEMORY_DOFS = (1, 2, 3, 4)


def flow_geometry(vessel) -> tuple[float, float]:
    """(length [m], depth [m]) over and at which the maneuvering forces see the waves' flow
    (:mod:`vtrials.physics.forces.wave_flow`): L_pp and half the draught."""
    return float(vessel.particulars.length), 0.5 * float(vessel.particulars.draught)


def memory_model(db):
    """The fitted radiation memory (:class:`.radiation.RadiationModel`) the seakeeping vessel uses."""
    return fit_radiation(db, dofs=SEAKEEPING_DOFS, extra=tuple(d for d in MEMORY_DOFS if d not in SEAKEEPING_DOFS))


def roll_damping_of(vessel, db, hull_toml=None):
    """The viscous roll damping (:class:`vtrials.physics.forces.roll_damping.RollDamping`) the seakeeping
    vessel gets, from the ``[roll_damping]`` table of ``hull_toml`` (default: ``hull.toml`` next to the
    database). Its frequency-dependent parts are taken at the natural roll frequency of the vessel's
    mass and restoring with the database's added mass, free to sway as the simulated ship is
    (:func:`.rao.natural_frequency` with ``free=(1,)``)."""
    from vtrials.physics.seakeeping.hullform import hull_particulars_from_table
    from vtrials.physics.seakeeping.rao import natural_frequency
    from vtrials.schema import load_toml
    path = Path(hull_toml) if hull_toml is not None else Path(db.attrs["_path"]).parent / "hull.toml"
    tab = rd_mod.read_roll_damping_table(path)
    wn = natural_frequency(db, 3, M=vessel.M_RB, C=vessel.restoring_matrix(), free=(1,))
    if tab.method == "ikeda":
        hp = hull_particulars_from_table(load_toml(path)["hull"], str(path))
        P = vessel.particulars
        h = rd_mod.RollHull(L=hp.length, B=hp.beam, d=hp.draught, C_B=hp.C_B, C_M=hp.C_M,
                            OG=P.draught - P.KG, l_BK=tab.bilge_keel_length, b_BK=tab.bilge_keel_breadth,
                            rho=P.water_density, nu=tab.kinematic_viscosity)
        return rd_mod.ikeda(h, wn, where=str(path))
    # hull_model: the maneuvering model's own roll damping, less the wave part the memory now supplies
    b1, b1u, b2 = float(vessel.B_lin[1]), 0.0, float(vessel.damping.roll_quadratic)
    if vessel.meta.hull_model == "blanke":
        b1 -= vessel.hull.K_p
        b1u -= vessel.hull.K_up
        b2 -= vessel.hull.K_pp
    b44w = float(np.interp(wn, db.omega, db.B[:, 3, 3]))
    if b1 < b44w:
        raise InputError(str(path), "roll_damping.method", f"'hull_model': the ship file's linear roll damping "
                         f"{b1:.4g} N m s is below the database's wave damping {b44w:.4g} N m s at ω_n = {wn:.3f} "
                         "rad/s; there is no viscous part left to keep (use 'ikeda')")
    return rd_mod.RollDamping(wn, b1 - b44w, b1u, 0.0, 0.0, b2,
                              f"maneuvering model's roll damping less the database's B44({wn:.3f} rad/s) = {b44w:.4g} N m s",
                              (("ship-file linear", b1), ("wave part removed", b44w), ("per m/s", b1u),
                               ("quadratic", b2)))


def seakeeping_vessel(vessel, db, components: np.ndarray, dt: float, model=None,
                      excitation_dofs=(0, 1, 2, 3, 4, 5), drift: bool = True, roll_damping="model",
                      relative_flow: bool = True):
    """A shallow copy of ``vessel`` with A∞ in its added mass (heave/roll/pitch block), the damping
    component reduced to its roll (viscous) part, and the radiation and wave-excitation components.

    ``components``: wave components (n, 6) of :mod:`vtrials.physics.environment.waves`; ``dt``: the
    simulator step [s] (the radiation states are discretised for it); ``model``: a fitted
    :class:`.radiation.RadiationModel` (fitted here when None); ``drift``: add the mean drift
    component (:mod:`vtrials.physics.forces.wave_drift`); ``roll_damping``: "model" (from the
    model's hull.toml, :func:`roll_damping_of`), a :class:`~vtrials.physics.forces.roll_damping.RollDamping`,
    or None (no viscous roll damping at all: potential damping only); ``relative_flow``: the maneuvering
    components see the ship's motion relative to the waves' flow and surface (:mod:`.forces.wave_flow`,
    first in the component list; False only to measure what that changes). Returns (vessel, model).
    """
    if isinstance(roll_damping, str):
        if roll_damping != "model":
            raise InputError("seakeeping_vessel", "roll_damping", f"expected 'model', a RollDamping or None, got {roll_damping!r}")
        roll_damping = roll_damping_of(vessel, db)
    if model is None:
        model = memory_model(db)
    if tuple(model.dofs) != MEMORY_DOFS:
        raise InputError("seakeeping_vessel", "model", f"the radiation memory must cover the DOFs {MEMORY_DOFS} "
                         f"(timedomain.memory_model), got {tuple(model.dofs)}")
    v = copy.copy(vessel)
    M_A = vessel.M_A.copy()
    idx = np.ix_(SEAKEEPING_DOFS, SEAKEEPING_DOFS)
    M_A[idx] = db.A_inf[idx]
    # sway: its added mass and its couplings with heave, roll and pitch are the database's A∞ (the memory
    # adds A(ω) − A∞); its couplings with surge and yaw stay the maneuvering model's
    for j in MEMORY_DOFS:
        M_A[1, j] = db.A_inf[1, j]
        M_A[j, 1] = db.A_inf[j, 1]
    v.M_A = M_A
    comps = []
    if relative_flow and len(components):
        comps.append(Component("wave_flow", "wave_flow", wave_flow.pack(components, *flow_geometry(vessel))))
    for c in vessel.components:
        if c.name == "damping":
            p = c.params.copy()
            p[0] = 0.0      # heave: potential damping from the radiation memory
            p[2] = 0.0      # pitch: likewise
            p[1] = 0.0      # roll: viscous part in the roll_damping component, wave part in the memory
            p[3] = 0.0
            comps.append(Component("damping", c.type, p))
        elif c.type == "hull_blanke":
            p = c.params.copy()
            p[17] = p[18] = p[19] = 0.0    # K_|u|p, K_p|p|, K_p: as above
            comps.append(Component(c.name, c.type, p))
        else:
            comps.append(c)
    p, s0 = rad_force.pack(model, dt)
    comps.append(Component("radiation", "radiation", p, states=s0))
    comps.append(Component("wave_excitation", "wave_excitation",
                           wave_excitation.pack(db, components, excitation_dofs)))
    if roll_damping is not None:
        comps.append(Component("roll_damping", "roll_damping", rd_mod.pack(roll_damping)))
    if drift:
        comps.append(Component("wave_drift", "wave_drift", wave_drift.pack(db, components)))
    v.components = comps
    return v, model


__all__ = ["seakeeping_vessel", "roll_damping_of", "memory_model", "hydrostatics", "MEMORY_DOFS", "flow_geometry"]
