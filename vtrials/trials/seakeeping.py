"""Seakeeping star pattern at sea: the course of each leg and the truth kept for its window.

The crew lays each leg relative to the mean wave direction it has observed (the team's sea-state
observation, :func:`vtrials.instruments.sea_observation.observe_sea`: the wind sea's direction FROM,
with its observation error) — never the true direction. A leg named ``bow_starboard`` has the waves
coming from 45° on the starboard bow: course = from − 45° (:data:`vtrials.trials.agenda.WAVE_RELATIVE_DEG`).

Truth kept per leg (for scoring, never for the crew's decisions): the window's true mean speed through
the water and over the ground, heading, and the RMS of the true motions the records measure — the
vertical displacement and acceleration of the IMU's site (about their window means), roll and pitch.
The true transfer functions are computed at scoring time from the hydrodynamic database at the
window's mean speed and heading (:mod:`vtrials.score.seakeeping`).
"""

from __future__ import annotations

import math

import numpy as np

from vtrials.errors import SimulationError
from vtrials.instruments.kinematics import SiteKinematics


def observed_wave_from(team: dict) -> float:
    """Mean direction the wind sea comes FROM [rad], as the team observed it."""
    sea = team.get("sea_observed") or []
    if not sea:
        raise SimulationError("a seakeeping leg needs the team's sea-state observation (no waves observed)")
    return float(sea[0]["from_rad"])


def leg_course(team: dict, run) -> float:
    """Ordered course of a seakeeping leg [rad] in (−π, π]."""
    c = observed_wave_from(team) - float(run.params["wave_relative"])
    return math.atan2(math.sin(c), math.cos(c))


def motion_site(iset) -> np.ndarray | None:
    """Body position of the IMU (the motion package whose records give heave) [m], or None."""
    names = iset.of_kind("imu")
    return iset.devices[names[0]].site if names else None


def leg_truth(cols: dict, t0: float, t1: float, site) -> dict:
    """True RMS motions over [t0, t1]: heave (vertical displacement, up) and vertical acceleration of
    ``site`` (about the window means), roll and pitch [m, m/s², rad]."""
    t = cols["t"]
    w = (t >= t0 - 1e-9) & (t <= t1 + 1e-9)
    c = {k: v[w] for k, v in cols.items()}
    out = {"roll_rms": float(np.std(c["roll"])), "pitch_rms": float(np.std(c["pitch"])),
           "roll_mean": float(np.mean(c["roll"])), "pitch_mean": float(np.mean(c["pitch"]))}
    if site is not None and c["t"].size > 4:
        kin = SiteKinematics(c, np.asarray(site, float))
        zd = kin.position()[:, 2]
        h = -(zd - np.mean(zd))
        out["heave_rms"] = float(np.std(h))
        dt = np.diff(c["t"])
        if np.all(dt > 0):
            # vertical acceleration (up) by central differences of the site's vertical velocity
            vz = -kin.velocity_world()[:, 2]
            a = np.gradient(vz, c["t"])
            out["vertical_acc_rms"] = float(np.std(a))
    out["u_r_mean"] = float(np.mean(c["u_r"]))
    out["v_r_mean"] = float(np.mean(c["v_r"]))
    out["ground_velocity_ne"] = [float(np.mean(np.gradient(c["x"], c["t"]))), float(np.mean(np.gradient(c["y"], c["t"])))]
    return out
