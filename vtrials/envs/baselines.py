"""Baseline policies: the ship's PID autopilot (and the helmsman's rules built on it) for each task,
for all ships of an environment at once, from the measured channels only.

PID on the gyro heading error e = ψ_m − ψ_d with derivative on the IMU yaw rate (as the ship's
autopilot, vessel.Autopilot: δ = −K_p (e + ∫e/T_i + T_d r_m), clipped at the autopilot's rudder limit,
integration held while saturated). Per task:

* CourseKeeping: ψ_d = the commanded course.
* ZigZag: the helmsman's rule on the gyro: δ_z to the side of the current phase, reversed when the
  heading change passes ±ψ_z.
* Williamson: hard over to starboard until the heading has changed 60°, hard to port until within 20°
  of the reciprocal course (IMO MSC/Circ.1053), then the autopilot with line-of-sight guidance (below)
  onto the original track line run in reverse.
* Stopping: the autopilot on the track course; full astern (back_full) once the GNSS distance to the mark
  is within the crash-stop reach at the measured speed (reach ∝ U², calibrated at full ahead:
  STOP_REACH_L), stop once the ship is at rest.
* TrackFollowing: line-of-sight guidance, ψ_d = ψ_track − atan(e_ct/Δ), Δ = 2 L (Fossen 2011, Handbook
  of Marine Craft Hydrodynamics and Motion Control, §10.3.2), and the autopilot on ψ_d.
"""

from __future__ import annotations

import math

import numpy as np

from vtrials.envs.core import RUDDER_LEVELS, ShipBatch
from vtrials.envs.tasks import wrap
from vtrials.units import DEG

# crash-stop head reach from full ahead (back_full, rudder amidships), ship lengths: measured on the
# models (core.STOP_MARK_L's note)
STOP_REACH_L = {"patrol51": 3.4, "kvlcc2": 9.9}


class PIDPolicy:
    """The autopilot baseline for every ship of ``core`` (a ShipBatch: env.unwrapped.core)."""

    def __init__(self, core: ShipBatch):
        self.core = core
        ap = core.vessel.autopilot
        self.kp, self.ti, self.td = ap.gain, ap.integral_time, ap.derivative_time
        self.limit = ap.rudder_limit_deg * DEG
        n = core.n
        self.integ = np.zeros(n)
        self.phase = np.zeros(n, dtype=np.int64)
        self.U_full = core._steady_state("full").u

    def reset(self, idx=None) -> None:
        idx = np.arange(self.core.n) if idx is None else np.atleast_1d(idx)
        self.integ[idx] = 0.0
        self.phase[idx] = 0

    def _pid(self, psi_d: np.ndarray) -> np.ndarray:
        m = self.core.meas
        e = wrap(m[:, 0] - psi_d)
        dt = self.core.period
        d = -self.kp * (e + self.integ / self.ti + self.td * m[:, 1])
        sat = np.abs(d) >= self.limit
        self.integ = np.where(sat, self.integ, self.integ + e * dt)
        return np.clip(d, -self.limit, self.limit)

    def rudder_and_lever(self) -> tuple[np.ndarray, np.ndarray]:
        c = self.core
        t = c.task
        m = c.meas
        lever = c.act_prev[:, 1].copy()
        name = t.name
        if name == "CourseKeeping":
            delta = self._pid(t.ref)
        elif name == "ZigZag":
            d = wrap(m[:, 0] - t.psi0)
            side = t._flip(t.side_m, d, t.pz)
            delta = side * t.dz
        elif name == "Williamson":
            dpsi = wrap(m[:, 0] - t.psi0)
            recip = t.psi0 + math.pi
            self.phase = np.where((self.phase == 0) & (dpsi >= 60 * DEG), 1, self.phase)
            self.phase = np.where((self.phase == 1) & (np.abs(wrap(m[:, 0] - recip)) <= 20 * DEG), 2, self.phase)
            # back on the track: line-of-sight onto the original line run in reverse (cross-track sign flips)
            ect, _ = t.track_errors(m[:, 2], m[:, 3], m[:, 0], np.arange(c.n))
            psi_d = recip - np.arctan(-ect / (2.0 * c.L))
            delta = np.where(self.phase == 0, self.limit, np.where(self.phase == 1, -self.limit, self._pid(psi_d)))
        elif name == "Stopping":
            delta = self._pid(t.psi0)
            ect, along = t.track_errors(m[:, 2], m[:, 3], m[:, 0], np.arange(c.n))
            dist = t.mark - along
            reach = STOP_REACH_L[c.ship] * c.L * (m[:, 4] / self.U_full) ** 2
            self.phase = np.where((self.phase == 0) & (dist <= reach), 1, self.phase)
            self.phase = np.where((self.phase == 1) & (m[:, 4] < 0.05 * t.U0), 2, self.phase)
            lever = np.where(self.phase == 1, c.lever_of("back_full"), np.where(self.phase == 2, 0.0, lever))
        elif name == "TrackFollowing":
            ect, _ = t.track_errors(m[:, 2], m[:, 3], m[:, 0], np.arange(c.n))
            delta = self._pid(t.psi0 - np.arctan(ect / (2.0 * c.L)))
        else:
            raise ValueError(f"no baseline for task {name!r}")
        return delta / c.delta_max, lever

    def __call__(self) -> np.ndarray:
        """Actions of every ship in the environment's action format."""
        c = self.core
        rud, lev = self.rudder_and_lever()
        rud = np.clip(rud, -1.0, 1.0)
        if c.discrete:
            ri = np.rint((rud + 1.0) / 2.0 * (RUDDER_LEVELS - 1)).astype(np.int64)
            if not c.engine:
                return ri
            li = np.abs(c.lever_pos[None, :] - lev[:, None]).argmin(axis=1)
            return np.column_stack([ri, li])
        if not c.engine:
            return rud[:, None].astype(np.float32)
        return np.column_stack([rud, lev]).astype(np.float32)


def run_episode(env, policy: PIDPolicy, seed: int, options: dict | None = None, max_steps: int | None = None):
    """Run one episode of a scalar ShipEnv with ``policy``; returns (return, truth heading errors for
    course keeping or None, steps)."""
    obs, info = env.reset(seed=seed, options=options)
    policy.reset()
    core = env.unwrapped.core
    total, k, errs = 0.0, 0, []
    while True:
        a = policy()[0]
        obs, r, term, trunc, info = env.step(a)
        total += r
        k += 1
        if core.task.name == "CourseKeeping":
            errs.append(float(wrap(core.truth["psi"][0] - core.task.ref[0])))
        if term or trunc or (max_steps and k >= max_steps):
            break
    return total, (np.array(errs) if errs else None), k
