"""A ship set up for seakeeping in the time domain: the vessel's maneuvering model plus wave loads.

How the two models combine (nothing counted twice):

* Horizontal DOFs (surge, sway, yaw): the maneuvering model (hull, propellers, rudders, its added
  mass) is kept unchanged. The first-order wave excitation acts on them (unless masked), but no
  radiation memory: their hydrodynamic reaction stays the maneuvering model's.
* Heave, roll, pitch (the seakeeping DOFs): the maneuvering model has only the hydrostatic restoring
  and a linear/quadratic damping there. With seakeeping on
  - the added mass of these DOFs (and their couplings among themselves) is the database's A∞ in the
    exact added-mass solve of the dynamics (replacing the ship file's heave/roll/pitch ratios);
  - the frequency-dependent part is the radiation memory component (:mod:`vtrials.physics.forces.radiation`),
    driven by the heave, roll and pitch velocities, which are perturbations about the maneuvering
    motion; the potential damping is therefore in the memory, and the ship file's linear heave and
    pitch damping is removed;
  - roll keeps the ship file's roll damping (linear fraction of critical + quadratic) as the
    viscous part (a documented equivalent linearisation standing in for Ikeda's method, which is not
    implemented here); the wave-radiation part of roll damping comes from the memory.
* Mean drift (surge, sway, yaw): the database's zero-speed drift per component
  (:mod:`vtrials.physics.forces.wave_drift`); the maneuvering model's calm-water resistance is unchanged,
  so the added resistance is this force alone.
* Forward speed: no speed corrections are added. The dynamics apply A∞ to body-axis accelerations,
  and the body heave velocity is w = ż + Uθ, so the time domain carries a speed coupling
  A∞_i3 U θ̇ (the A∞ part of Salvesen–Tuck–Faltinsen's B35 = B35⁰ + U A33); the matching RAO is
  :func:`.rao.rao` with ``body_axes_added_mass=True``.
* Roll damping: patrol51's ship file has zero roll damping (only the potential damping of the memory
  then acts); kvlcc2's is 6.1e9 N m s/rad. Ikeda's method and bilge keels are not implemented.
* Restoring stays the ship file's hydrostatics component (not the database mesh's C).
"""

from __future__ import annotations

import copy

import numpy as np

from vtrials.physics.forces import hydrostatics
from vtrials.physics.forces import radiation as rad_force
from vtrials.physics.forces import wave_drift, wave_excitation
from vtrials.physics.forces.registry import Component
from vtrials.physics.seakeeping.radiation import fit_radiation

SEAKEEPING_DOFS = (2, 3, 4)


def seakeeping_vessel(vessel, db, components: np.ndarray, dt: float, model=None,
                      excitation_dofs=(0, 1, 2, 3, 4, 5), drift: bool = True):
    """A shallow copy of ``vessel`` with A∞ in its added mass (heave/roll/pitch block), the damping
    component reduced to its roll (viscous) part, and the radiation and wave-excitation components.

    ``components``: wave components (n, 6) of :mod:`vtrials.physics.environment.waves`; ``dt``: the
    simulator step [s] (the radiation states are discretised for it); ``model``: a fitted
    :class:`.radiation.RadiationModel` (fitted here when None); ``drift``: add the mean drift
    component (:mod:`vtrials.physics.forces.wave_drift`). Returns (vessel, model).
    """
    if model is None:
        model = fit_radiation(db, dofs=SEAKEEPING_DOFS)
    v = copy.copy(vessel)
    M_A = vessel.M_A.copy()
    idx = np.ix_(SEAKEEPING_DOFS, SEAKEEPING_DOFS)
    M_A[idx] = db.A_inf[idx]
    v.M_A = M_A
    comps = []
    for c in vessel.components:
        if c.name == "damping":
            p = c.params.copy()
            p[0] = 0.0      # heave: potential damping from the radiation memory
            p[2] = 0.0      # pitch: likewise
            comps.append(Component("damping", c.type, p))
        else:
            comps.append(c)
    p, s0 = rad_force.pack(model, dt)
    comps.append(Component("radiation", "radiation", p, states=s0))
    comps.append(Component("wave_excitation", "wave_excitation",
                           wave_excitation.pack(db, components, excitation_dofs)))
    if drift:
        comps.append(Component("wave_drift", "wave_drift", wave_drift.pack(db, components)))
    v.components = comps
    return v, model


def viscous_roll_damping(vessel) -> float:
    """The linear roll damping [N m s/rad] kept as the viscous part (the ship file's, see above)."""
    return float(vessel.B_lin[1])


__all__ = ["seakeeping_vessel", "viscous_roll_damping", "hydrostatics"]
