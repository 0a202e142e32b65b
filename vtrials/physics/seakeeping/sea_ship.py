"""A ship in a seaway as the runners simulate it: the seakeeping vessel plus the mean wave force chosen.

:func:`sea_ship` = :func:`vtrials.physics.seakeeping.timedomain.seakeeping_vessel` (maneuvering model,
A∞ in the heave/roll/pitch added mass, radiation memory, first-order excitation) with

* the horizontal added-mass Coriolis terms of the A∞ block (:mod:`vtrials.physics.forces.seakeeping_coriolis`)
  when the hull model's vessel file applies none (``added_mass.coriolis = "none"``): without them the
  linear model has a spurious second-order mean surge force (the zero-speed "creep");
* the mean second-order wave force, ``mean_force``:
  - ``"snnm"`` (default): surge from the SNNM added-resistance method at the ship's instantaneous speed
    and heading (:mod:`vtrials.physics.forces.added_resistance`, Liu & Papanikolaou 2020), sway and yaw
    from the database's zero-speed drift (:mod:`vtrials.physics.forces.wave_drift`, surge column dropped);
  - ``"database"``: the database's zero-speed far-field drift in surge, sway and yaw (no speed effect);
  - ``"none"``: no mean wave force (first-order motions only).
Nothing is counted twice: the maneuvering model's calm-water resistance is unchanged and only one
source gives each mean force component.
"""

from __future__ import annotations

import math

import numpy as np

from vtrials.errors import InputError
from vtrials.physics.forces import added_resistance, seakeeping_coriolis, wave_drift, wave_excitation, wave_flow
from vtrials.physics.forces.registry import Component
from vtrials.physics.seakeeping.timedomain import flow_geometry, seakeeping_vessel

MEAN_FORCES = ("snnm", "database", "none")


def sea_ship(vessel, db, components: np.ndarray, dt: float, model=None, mean_force: str = "snnm",
             excitation_dofs=(0, 1, 2, 3, 4, 5)):
    """(vessel, radiation model) for ``vessel`` in the seaway ``components`` (n, 6) with database ``db``."""
    if mean_force not in MEAN_FORCES:
        raise InputError("sea_ship", "mean_force", f"{mean_force!r} is not one of {', '.join(MEAN_FORCES)}")
    v, model = seakeeping_vessel(vessel, db, components, dt, model=model, excitation_dofs=excitation_dofs,
                                 drift=(mean_force == "database"))
    comps = list(v.components)
    if vessel.added_mass.coriolis == "none":
        comps.append(Component("seakeeping_coriolis", "seakeeping_coriolis", seakeeping_coriolis.pack(v.M_A)))
    if mean_force == "snnm":
        comps.append(Component("added_resistance", "added_resistance",
                               added_resistance.pack(added_resistance.snnm_hull(vessel), components)))
        comps.append(Component("wave_drift", "wave_drift", wave_drift.pack(db, components, dofs=(1, 2))))
    v.components = comps
    return v, model


def seaway_params(vessel, db, components: np.ndarray, mean_force: str = "snnm",
                  excitation_dofs=(0, 1, 2, 3, 4, 5), snnm=None) -> dict[str, np.ndarray]:
    """Parameter blocks of the seaway-dependent components of :func:`sea_ship`'s vessel, by component
    name, for the wave components ``components`` (n, 6): what changes when the same ship meets another
    realization (the gymnasium environments draw one per episode and set these per ship). The blocks
    are those :func:`sea_ship` packs (a test holds them equal); n fixes their length. ``snnm``: the
    vessel's :func:`~vtrials.physics.forces.added_resistance.snnm_hull` when the caller keeps it (it
    fits the hull form, ~0.1 s)."""
    if mean_force not in MEAN_FORCES:
        raise InputError("seaway_params", "mean_force", f"{mean_force!r} is not one of {', '.join(MEAN_FORCES)}")
    out = {"wave_excitation": wave_excitation.pack(db, components, excitation_dofs)}
    if len(components):
        out["wave_flow"] = wave_flow.pack(components, *flow_geometry(vessel))
    if mean_force == "database":
        out["wave_drift"] = wave_drift.pack(db, components)
    elif mean_force == "snnm":
        hull = added_resistance.snnm_hull(vessel) if snnm is None else snnm
        out["added_resistance"] = added_resistance.pack(hull, components)
        out["wave_drift"] = wave_drift.pack(db, components, dofs=(1, 2))
    return out


def in_database_band(db, components: np.ndarray, depth_m: float = math.inf) -> tuple[np.ndarray, float]:
    """``components`` with those outside the database's frequency range [ω_min/2, ω_max] silenced
    (amplitude 0, frequency and wave number moved to the nearest edge; the count is kept, so that
    parameter blocks keep their length), and the fraction of the sea's variance silenced."""
    from vtrials.physics.environment.waves import wavenumber
    comp = np.array(components, dtype=np.float64)
    lo, hi = 0.5 * float(db.omega[0]), float(db.omega[-1])
    out = (comp[:, 1] < lo) | (comp[:, 1] > hi)
    var = float(np.sum(comp[:, 0] ** 2))
    dropped = float(np.sum(comp[out, 0] ** 2)) / var if var > 0.0 else 0.0
    if np.any(out):
        comp[out, 0] = 0.0
        comp[out, 1] = np.clip(comp[out, 1], lo, hi)
        comp[out, 2] = wavenumber(comp[out, 1], depth_m)
    return comp, dropped
