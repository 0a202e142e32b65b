"""The simulator: N ships of one vessel type stepped together in MuJoCo.

One code path for everything — the CLI, the Python API, campaigns and gymnasium environments:
``mujoco.batch.Batch`` holds the N MuJoCo states (N = 1 included); the step kernel of
:mod:`vtrials.physics.dynamics` (compiled for the ship's force components) computes every ship's
generalized forces in one numba call per step; MuJoCo integrates (semi-implicit Euler). Per-ship differences (environment, later loading condition)
live in per-ship parameter rows, so ships never share mutable state and results do not depend
on how many ships run together or on the thread count.
"""

from __future__ import annotations

import copy
import dataclasses
import itertools
import math
import weakref

import mujoco
import numpy as np
from mujoco import batch as mjbatch
from scipy.optimize import brentq

from vtrials.physics import dynamics as DY
from vtrials.physics import steering as H
from vtrials.errors import SimulationError
from vtrials.physics.forces import context as L
from vtrials.physics.forces.registry import component_type
from vtrials.physics.propulsion import (GOVERNED, LOCKED, M_INTEG, M_PITCH, M_SETPOINT, M_TORQUE, MODE_NAMES, NMACH, S_CP,
                         S_DADR, S_FRICTION, S_PITCH_DESIGN, S_PROP)
from vtrials.physics.environment import wind as W
from vtrials.physics.environment.current import NENV, Current
from vtrials.physics.environment.current import pack as pack_env
from vtrials.units import G, deg
from vtrials.physics.vessel import Vessel


PARALLEL_FROM = 8  # batches at least this large use the threaded kernel (when nthread > 1)
# runs of at least this many ship-steps go to the shards (one Python thread each, see _Shard); shorter
# runs to the threaded kernel and the whole batch (handing a run to threads costs ~0.1 ms)
SHARD_FROM = 256
_HOOK_IDS = itertools.count()


class _Shard:
    """Ships a…b−1 of a threaded simulator in a one-thread ``mujoco.batch`` of their own.

    A run of steps copies the ships' MuJoCo state rows (time, qpos, qvel, …: everything a step reads)
    into the shard's batch, steps them there with the serial step loop on the shard's rows of every
    per-ship array, and copies the rows back. Each shard runs in its own Python thread (the compiled
    loop and MuJoCo's step release the GIL), so the threads meet once per run rather than twice per
    step (the threaded kernel's ``prange`` and the batch's own pool). A step of a ship reads only its
    own row and arrays, so the results are those of the whole batch, bit for bit.
    """

    def __init__(self, model, a: int, b: int, rec_width: int):
        self.a, self.b = int(a), int(b)
        self.batch = mjbatch.Batch(model, self.b - self.a, nthread=1)
        self.state = self.batch.state
        self.qpos = self.batch.bind("qpos")
        self.qvel = self.batch.bind("qvel")
        self.qfrc = self.batch.bind("qfrc_applied")
        self.time = self.batch.bind("time")
        self.wcount = self.batch.warning[:, :, 1]
        self.no_rec = np.zeros((1, self.b - self.a, rec_width))
        self.rec = self.no_rec
        self._hook_error = None
        self.hook_id = next(_HOOK_IDS)
        DY._HOOKS[self.hook_id] = weakref.ref(self)
        weakref.finalize(self, DY._HOOKS.pop, self.hook_id, None)

    def rec_rows(self, rows: int) -> np.ndarray:
        """A contiguous buffer of at least ``rows`` truth rows of the shard's ships."""
        if self.rec is self.no_rec or self.rec.shape[0] < rows:
            self.rec = np.zeros((max(rows, 1), self.b - self.a, self.no_rec.shape[2]))
        return self.rec


#: First-order (oscillating) wave component types: left out of the steady states, where a frozen value at
#: one instant means nothing. Mean wave forces (wave_drift, added_resistance) stay in: a steady state in
#: a seaway includes them (tests/test_added_resistance.py, tests/test_wave_drift.py).
FIRST_ORDER_WAVE_TYPES = ("radiation", "wave_excitation", "wave_flow")


@dataclasses.dataclass
class ShipState:
    """A ship's initial condition (SI; velocities through the water, body axes)."""

    x: float = 0.0
    y: float = 0.0
    heading: float = 0.0
    u: float = 0.0
    v: float = 0.0
    r: float = 0.0
    z: float = 0.0
    roll: float = 0.0
    pitch: float = 0.0
    shaft_rps: tuple = ()
    pitch_ratio: tuple = ()  # pitch ratio per shaft (controllable pitch; fixed pitch ignores it)
    shaft_modes: tuple = ()  # "governed" (default), "trailed" or "locked" per shaft
    rudder: float = 0.0
    time: float = 0.0


def euler_to_quat(phi: float, theta: float, psi: float) -> np.ndarray:
    """z-y-x Euler angles → MuJoCo quaternion (w, x, y, z), body→world."""
    cphi, sphi = math.cos(phi / 2), math.sin(phi / 2)
    cth, sth = math.cos(theta / 2), math.sin(theta / 2)
    cpsi, spsi = math.cos(psi / 2), math.sin(psi / 2)
    return np.array([cpsi * cth * cphi + spsi * sth * sphi,
                     cpsi * cth * sphi - spsi * sth * cphi,
                     cpsi * sth * cphi + spsi * cth * sphi,
                     spsi * cth * cphi - cpsi * sth * sphi])


_MJ_WARNINGS: list[str] = []  # MuJoCo's last warning texts (kept here, not in ./MUJOCO_LOG.TXT)


def _keep_warning(text: str) -> None:
    _MJ_WARNINGS.append(str(text).strip())
    del _MJ_WARNINGS[:-10]


def _quiet_mujoco() -> None:
    """Route MuJoCo's warnings to :data:`_MJ_WARNINGS`: its default handler appends them to
    MUJOCO_LOG.TXT in the working directory. The simulator turns every warning into a
    :class:`SimulationError` through the warning counters."""
    if mujoco.get_mju_user_warning() is not _keep_warning:
        mujoco.set_mju_user_warning(_keep_warning)


class Simulator:
    """N ships of one :class:`Vessel`, each with its own environment block.

    Parameters
    ----------
    vessel: the loaded vessel model.
    n_ships: number of independent ships.
    dt: time step [s].
    envs: per-ship environment blocks (``sea.pack``), or one for all; calm deep water if None.
    nthread: MuJoCo batch threads (results are identical for any value).
    record_every: write a truth row every this many steps (0: no truth recording).
    planar: hold heave, roll and pitch at zero (a 3-DOF validation mode).
    components: replace the vessel's force components (tests, system identification).
    gravity: magnitude of gravity [m/s²] (0 for ideal-fluid checks).
    """

    def __init__(self, vessel: Vessel, n_ships: int = 1, dt: float = 0.01, envs=None, nthread: int = 1,
                 record_every: int = 1, limits: tuple[float, float, float] | None = None,
                 planar: bool = False, components: list | None = None, gravity: float = G):
        self.vessel = vessel
        self.n = int(n_ships)
        self.dt = float(dt)
        model = copy.copy(vessel.model)
        model.opt.timestep = self.dt
        model.opt.gravity[:] = (0.0, 0.0, gravity)
        self.model = model
        if isinstance(nthread, bool) or not isinstance(nthread, (int, np.integer)) or nthread < 1:
            from vtrials.errors import InputError
            raise InputError("Simulator", "nthread", f"expected an integer ≥ 1 (MuJoCo batch threads), got {nthread!r}")
        if isinstance(n_ships, bool) or not isinstance(n_ships, (int, np.integer)) or n_ships < 1:
            from vtrials.errors import InputError
            raise InputError("Simulator", "n_ships", f"expected an integer ≥ 1, got {n_ships!r}")
        if not (isinstance(dt, (int, float)) and math.isfinite(dt) and 0.0 < dt <= 1.0):
            from vtrials.errors import InputError
            raise InputError("Simulator", "dt", f"expected a time step in (0, 1] s, got {dt!r}")
        _quiet_mujoco()
        self.batch = mjbatch.Batch(model, self.n, nthread=nthread)
        self._wcount = self.batch.warning[:, :, 1]  # MuJoCo's warning counters, per ship and warning type
        self.qpos = self.batch.bind("qpos")
        self.qvel = self.batch.bind("qvel")
        self.qfrc = self.batch.bind("qfrc_applied")
        self.time = self.batch.bind("time")
        comps = vessel.components if components is None else components
        self.components = list(comps)
        self._calm_sim = None
        self._gravity = float(gravity)
        self.comp_names = [c.name for c in comps]
        self.comp_types = list(dict.fromkeys(component_type(c.type) for c in comps))
        self.comp_kind = np.array([self.comp_types.index(component_type(c.type)) for c in comps], dtype=np.int64)
        offs = np.cumsum([0] + [len(c.params) for c in comps])
        self.comp_off = offs.astype(np.int64)
        self.comp_par = np.tile(np.concatenate([np.zeros(0)] + [c.params for c in comps]), (self.n, 1))
        # the row of comp_par the kernel reads for each ship: the first ship's with the same values
        # (all of them until set_component_params gives a ship its own)
        self.par_row = np.zeros(self.n, dtype=np.int64)
        # the components' own states (radiation memory, filters, lags), per ship
        self.comp_soff = np.cumsum([0] + [len(c.states) for c in comps]).astype(np.int64)
        self._comp_st0 = np.concatenate([np.zeros(0)] + [c.states for c in comps])
        self.comp_st = np.tile(self._comp_st0, (self.n, 1))
        Mtot = vessel.M_RB + vessel.M_A
        self.planar = bool(planar)
        if self.planar:
            # validation mode: heave, roll and pitch held at zero (3-DOF horizontal-plane motion)
            keep = [0, 1, 5]
            Minv = np.zeros((6, 6))
            Minv[np.ix_(keep, keep)] = np.linalg.inv(Mtot[np.ix_(keep, keep)])
        else:
            Minv = np.linalg.inv(Mtot)
        self.minv = np.tile(Minv, (self.n, 1, 1))
        self.mrb = np.tile(vessel.M_RB, (self.n, 1, 1))
        self.ma = np.tile(vessel.M_A, (self.n, 1, 1))
        self.coriolis_mode = {"none": 0, "no_munk": 1, "kirchhoff": 2}[vessel.added_mass.coriolis]
        self.rb = np.tile(np.array([vessel.mass, *vessel.r_G, gravity]), (self.n, 1))
        self.steer = np.ascontiguousarray(vessel.steering)
        self.shaftp = np.ascontiguousarray(vessel.shaft_params)
        self.nr = self.steer.shape[0]
        self.ns = self.shaftp.shape[0]
        if envs is None:
            envs = pack_env(Current(), 1e4)
        envs = np.asarray(envs, dtype=np.float64)
        if envs.shape[-1] < NENV:
            raise ValueError(f"environment blocks need at least {NENV} entries")
        self.env = np.ascontiguousarray(np.broadcast_to(envs, (self.n, envs.shape[-1]))).copy()
        self.rud_cmd = np.zeros((self.n, self.nr))
        self.shaft_cmd = np.zeros((self.n, self.ns))
        self.pitch_cmd = np.tile(self.shaftp[:, S_PITCH_DESIGN], (self.n, 1))
        self.shaft_mode = np.zeros((self.n, self.ns))
        self.mach = np.zeros((self.n, self.ns, NMACH))
        # nav: unwrapped heading, water drift, then the gust phasors (wind.gust_step) for as many
        # gust components as the environment blocks can hold
        self.nav = np.zeros((self.n, DY.NNAV + W.gust_state_width(W.max_gusts(self.env.shape[1]))))
        self.phases, self.hs, self.events, self.ecount = H.new_arrays(self.n)
        self.ctx = np.zeros((self.n, L.NCTX))
        self.aux = np.zeros((self.n, L.NAUX))
        self.comp_w = np.zeros((self.n, len(comps) + 1, 6))
        self.nudot = np.zeros((self.n, 6))
        self.status = np.zeros(self.n, dtype=np.int64)
        self.scratch = np.zeros((self.n, 64))
        # many ships: the same per-ship kernel spread over threads (bit-identical results)
        serial, threaded = DY.step_kernels(self.comp_types)
        threads = self.n >= PARALLEL_FROM and nthread > 1
        self._kernel = threaded if threads else serial
        self._serial = serial
        self._one_rec = None
        # whole runs of steps in one compiled call (kernel + the batch's step through a hook)
        self._loop = DY.step_loops(self.comp_types)[1 if threads else 0]
        # long runs of many ships: one shard per thread (see _Shard)
        self._shards: list[_Shard] = []
        self._pool = None
        if threads:
            self._loop_serial = DY.step_loops(self.comp_types)[0]
            cuts = [round(k * self.n / nthread) for k in range(nthread + 1)]
            self._shards = [_Shard(model, a, b, DY.record_width(self.nr, self.ns, len(comps)))
                            for a, b in zip(cuts[:-1], cuts[1:]) if b > a]
        self._hook_id = next(_HOOK_IDS)
        self._hook_error = None
        DY._HOOKS[self._hook_id] = weakref.ref(self)
        weakref.finalize(self, DY._HOOKS.pop, self._hook_id, None)
        Lpp = vessel.length
        if limits is None:
            # runaway limits: Fn 2 through the water, 70° heel or trim, 3 rad/s
            limits = (2.0 * math.sqrt(G * Lpp), math.radians(70.0), 3.0)
        self.limits = np.array(limits, dtype=np.float64)
        self.record_every = int(record_every)
        self.rec_width = DY.record_width(self.nr, self.ns, len(comps))
        self.rec_names = DY.record_names(self.nr, self.ns, self.comp_names)
        self._chunks: list[np.ndarray] = []
        self._chunk = None
        self._krow = 0
        self._step_count = 0
        self._no_rec = np.zeros((1, self.n, self.rec_width))
        self._kin = None

    # ------------------------------------------------------------------ state
    def set_state(self, ship: int, s: ShipState, alone: bool = False) -> None:
        """Place ship ``ship`` in condition ``s`` (velocity through the water + current).

        The governors' torques come from an evaluation of the forces at the new state: of every ship
        (their ``ctx``, ``aux``, ... then describe their current states), or with ``alone`` of this
        ship only (the others keep those of their last step; a step recomputes them all before it
        uses them, so the simulation is the same either way — what an environment resetting one
        ship of many needs, at 1/N of the cost).
        """
        q = self.qpos[ship]
        v = self.qvel[ship]
        q[:] = 0.0
        v[:] = 0.0
        q[0:3] = (s.x, s.y, s.z)
        quat = euler_to_quat(s.roll, s.pitch, s.heading)
        q[3:7] = quat
        R = np.zeros(9)
        DY.quat_to_mat(*quat, R)
        R = R.reshape(3, 3)
        vc = self._current_world(ship, s.x, s.y, s.time)
        v[0:3] = R @ np.array([s.u, s.v, 0.0]) + vc
        v[5] = s.r
        for k in range(self.nr):
            q[int(self.steer[k, 3])] = s.rudder
            self.rud_cmd[ship, k] = s.rudder
        rps = tuple(s.shaft_rps) + (0.0,) * (self.ns - len(s.shaft_rps))
        pitch = tuple(s.pitch_ratio) + tuple(self.shaftp[len(s.pitch_ratio):, S_PITCH_DESIGN])
        modes = tuple(s.shaft_modes) + ("governed",) * (self.ns - len(s.shaft_modes))
        for k in range(self.ns):
            mode = MODE_NAMES[modes[k]]
            n = 0.0 if mode == LOCKED else rps[k]
            v[int(self.shaftp[k, S_DADR])] = 2.0 * math.pi * n
            self.shaft_cmd[ship, k] = n
            self.shaft_mode[ship, k] = mode
            self.pitch_cmd[ship, k] = pitch[k]
            self.mach[ship, k] = 0.0
            self.mach[ship, k, M_PITCH] = pitch[k] if self.shaftp[k, S_CP] > 0 else self.shaftp[k, S_PITCH_DESIGN]
            self.mach[ship, k, M_SETPOINT] = n
        self.time[ship] = s.time
        self.comp_st[ship] = self._comp_st0
        self.nav[ship] = 0.0
        self.nav[ship, DY.NV_PSI_U] = s.heading
        self.hs[ship] = 0.0
        self.ecount[ship] = 0
        self.qfrc[ship] = 0.0
        # governors hold the torque of this state (no start-up transient)
        if alone:
            self._evaluate_ship(ship)
        else:
            self.evaluate()
        for k in range(self.ns):
            if self.shaft_mode[ship, k] != GOVERNED:
                continue
            kp = int(self.shaftp[k, S_PROP])
            nk = self.ctx[ship, L.SHAFT_N + kp]
            q = self.aux[ship, L.AUX_PROP + 8 * kp + L.P_TORQUE] + self.shaftp[k, S_FRICTION] * nk
            self.mach[ship, k, M_INTEG] = q
            self.mach[ship, k, M_TORQUE] = q

    def _current_world(self, ship: int, x: float, y: float, t: float) -> np.ndarray:
        from vtrials.physics.environment.current import current_at
        vn, ve, _, _ = current_at(self.env[ship], x, y, t)
        return np.array([vn, ve, 0.0])

    def evaluate(self) -> np.ndarray:
        """Forces and accelerations at the current states, without side effects on the simulation.

        Fills ``ctx``, ``aux``, ``comp_w``, ``nudot`` and ``qfrc`` as a step would; returns ν̇ (N, 6).
        """
        nav = self.nav.copy()
        mach = self.mach.copy()
        hs = self.hs.copy()
        ev = self.events.copy()
        ec = self.ecount.copy()
        rc = self.rud_cmd.copy()
        st = self.comp_st.copy()
        self._call(nav=nav, mach=mach, hs=hs, events=ev, ecount=ec, rud_cmd=rc, comp_st=st, krec=-1)
        return self.nudot.copy()

    def _evaluate_ship(self, i: int) -> None:
        """:meth:`evaluate` of ship ``i`` alone (its rows of ctx, aux, comp_w, nudot, qfrc, status)."""
        r = slice(i, i + 1)
        if self._one_rec is None:
            self._one_rec = np.zeros((1, 1, self.rec_width))
        self._serial(self.dt, self.qpos[r], self.qvel[r], self.time[r], self.qfrc[r],
                     self.comp_kind, self.comp_off, self.comp_par, self.par_row[r], self.comp_soff,
                     self.comp_st[r].copy(),
                     self.minv[r], self.mrb[r], self.ma[r], self.coriolis_mode, self.rb[r], self.steer, self.shaftp,
                     self.env[r], self.rud_cmd[r].copy(), self.shaft_cmd[r], self.pitch_cmd[r], self.shaft_mode[r],
                     self.mach[r].copy(), self.nav[r].copy(), self.phases[r], self.hs[r].copy(), self.events[r].copy(),
                     self.ecount[r].copy(), self.ctx[r], self.aux[r], self.comp_w[r], self.nudot[r], self.limits,
                     self.status[r], self._one_rec, -1, self.scratch[r])

    def kinematics(self) -> np.ndarray:
        """The kinematic part of the context at the current states, (N, NCTX): velocities (over
        ground and through the water), position, Euler angles, time, rotation matrix, current,
        rudder angles and rates, shaft speeds — the values :meth:`evaluate` puts in ``ctx``, without
        computing forces (no side effects; the other entries are zero)."""
        if self._kin is None:
            self._kin = np.zeros((self.n, L.NCTX))
            self._kin_scratch = np.zeros((self.n, 18))
        DY.kinematics_all(self.qpos, self.qvel, self.time, self.env, self.steer, self.shaftp, self._kin,
                          self._kin_scratch)
        return self._kin

    def _call(self, nav=None, mach=None, hs=None, events=None, ecount=None, rud_cmd=None, comp_st=None, krec=-1,
              rec=None):
        return self._kernel(self.dt, self.qpos, self.qvel, self.time, self.qfrc,
                              self.comp_kind, self.comp_off, self.comp_par, self.par_row, self.comp_soff,
                              self.comp_st if comp_st is None else comp_st, self.minv, self.mrb, self.ma,
                              self.coriolis_mode, self.rb, self.steer, self.shaftp, self.env,
                              self.rud_cmd if rud_cmd is None else rud_cmd, self.shaft_cmd, self.pitch_cmd,
                              self.shaft_mode, self.mach if mach is None else mach,
                              self.nav if nav is None else nav,
                              self.phases, self.hs if hs is None else hs,
                              self.events if events is None else events,
                              self.ecount if ecount is None else ecount,
                              self.ctx, self.aux, self.comp_w, self.nudot, self.limits, self.status,
                              self._no_rec if rec is None else rec, krec, self.scratch)

    def set_component_params(self, ship: int, name: str, params: np.ndarray) -> None:
        """Give ship ``ship`` its own parameter block for component ``name`` (same length as the
        vessel's; e.g. its own wave realization). The way to change ``comp_par``: the kernel reads each
        ship's parameters from row ``par_row[ship]``, which this keeps up to date."""
        k = self.comp_names.index(name)
        a, b = int(self.comp_off[k]), int(self.comp_off[k + 1])
        params = np.asarray(params, dtype=np.float64).ravel()
        if params.shape[0] != b - a:
            raise ValueError(f"component {name!r} takes {b - a} parameters, not {params.shape[0]}")
        self.comp_par[ship, a:b] = params
        # ship reads its own row now; the ships that read its row read the first of them instead
        shared = np.flatnonzero((self.par_row == ship) & (np.arange(self.n) != ship))
        if shared.size:
            self.par_row[shared] = shared[0]
        self.par_row[ship] = ship

    def component_states(self, ship: int, name: str) -> np.ndarray:
        """A view of the internal states of component ``name`` on ship ``ship``."""
        k = self.comp_names.index(name)
        return self.comp_st[ship, int(self.comp_soff[k]):int(self.comp_soff[k + 1])]

    # ------------------------------------------------------------------ helm
    def set_helm(self, ship: int, phases: list[tuple]) -> None:
        """Give ship ``ship`` a helm program: a list of (mode, a1, ..., a7) phases."""
        if len(phases) > H.MAX_PHASES:
            raise ValueError(f"at most {H.MAX_PHASES} helm phases")
        self.phases[ship] = 0.0
        for k, ph in enumerate(phases):
            self.phases[ship, k, :len(ph)] = ph
        self.hs[ship] = 0.0
        self.hs[ship, H.H_NPHASE] = len(phases)
        self.hs[ship, H.H_TSTART] = -1.0
        self.hs[ship, H.H_ACTIVE] = 1.0 if phases else 0.0

    def shaft_power(self, ship: int) -> list[float]:
        """Delivered power of each shaft at the ship's current state [W] (propeller torque × 2πn)."""
        self.evaluate()
        out = []
        for k in range(self.ns):
            kp = int(self.shaftp[k, S_PROP])
            out.append(float(2 * math.pi * self.ctx[ship, L.SHAFT_N + kp]
                             * self.aux[ship, L.AUX_PROP + 8 * kp + L.P_TORQUE]))
        return out

    def set_order(self, ship: int, rps: float, pitch: float | None = None) -> None:
        """An engine order on every governed shaft: shaft speed [rev/s] and pitch ratio (CP only)."""
        for k in range(self.ns):
            self.shaft_cmd[ship, k] = rps
            if pitch is not None:
                self.pitch_cmd[ship, k] = pitch

    # ------------------------------------------------------------------ commands (controllers)
    # What a controller (crew, maneuver programme, gymnasium agent, input design) sets between steps.
    def set_rudder_order(self, ship: int, delta: float) -> None:
        """Rudder order [rad] on every rudder (positive turns the ship to starboard). Takes the helm
        from any compiled helm programme; the steering gear then follows at its rate limit."""
        self.hs[ship, H.H_ACTIVE] = 0.0
        self.rud_cmd[ship, :] = delta

    def _shafts(self, shaft: int | None) -> range:
        if shaft is None:
            return range(self.ns)
        if not 0 <= shaft < self.ns:
            raise ValueError(f"shaft index {shaft} out of range (the ship has {self.ns})")
        return range(shaft, shaft + 1)

    def set_shaft_order(self, ship: int, rps: float, shaft: int | None = None) -> None:
        """Shaft speed order [rev/s] (negative: astern) on one shaft or all."""
        for k in self._shafts(shaft):
            self.shaft_cmd[ship, k] = rps

    def set_pitch_order(self, ship: int, pitch: float, shaft: int | None = None) -> None:
        """Pitch ratio order P/D on one controllable-pitch shaft or all of them (fixed pitch: ignored)."""
        for k in self._shafts(shaft):
            if self.shaftp[k, S_CP] > 0.0:
                self.pitch_cmd[ship, k] = pitch

    def set_shaft_mode(self, ship: int, mode: str, shaft: int | None = None) -> None:
        """"governed", "trailed" or "locked" on one shaft or all."""
        if mode not in MODE_NAMES:
            raise ValueError(f"shaft mode {mode!r}: one of {', '.join(MODE_NAMES)}")
        for k in self._shafts(shaft):
            self.shaft_mode[ship, k] = MODE_NAMES[mode]

    def set_engine_order(self, ship: int, order: str) -> None:
        """A telegraph order (e.g. "full", "back_full") as the ship's telegraph table maps it."""
        if order not in self.vessel.telegraph:
            raise ValueError(f"engine order {order!r}: one of {', '.join(self.vessel.telegraph)}")
        self.set_order(ship, *self.vessel.telegraph[order])

    def helm_phase(self, ship: int) -> int:
        return int(self.hs[ship, H.H_PHASE])

    def helm_events(self, ship: int) -> np.ndarray:
        return self.events[ship, : self.ecount[ship]].copy()

    # ------------------------------------------------------------------ stepping
    def step(self, nstep: int = 1) -> None:
        """Advance every ship by ``nstep`` time steps.

        Runs of steps go to one compiled call (:func:`vtrials.physics.dynamics._run_steps`: the step
        kernel and the batch's step, per step, as a Python loop over both would), each run as long as
        the truth chunk has room for its rows.
        """
        every = self.record_every
        left = int(nstep)
        while left > 0:
            m = left
            rec = self._no_rec
            if every:
                first = (-self._step_count) % every  # the run's first recorded step
                if first < left:
                    if self._chunk is None or self._krow >= self._chunk.shape[0]:
                        self._new_chunk((left - first - 1) // every + 1)
                    rec = self._chunk
                    m = min(left, first + (rec.shape[0] - self._krow) * every)
            if self._shards and m * self.n >= SHARD_FROM:
                done, krow, code = self._run_shards(m, every, rec)
            else:
                done, krow, code = self._run(self._loop, m, every, rec)
            self._step_count += done
            self._krow = krow
            left -= done
            if code == DY.STOP_STATUS:
                self._raise_status()
            elif code == DY.STOP_MUJOCO:
                exc, self._hook_error = self._hook_error, None
                if isinstance(exc, mjbatch.SimulationError):
                    self._raise_mujoco(int(exc.ids[0]), str(exc))
                raise exc
            elif code == DY.STOP_WARNING:
                self._raise_mujoco(int(np.flatnonzero(self._wcount.any(axis=1))[0]), None)

    def _run(self, loop, m, every, rec):
        """``m`` steps of the whole batch in one call of ``loop``: (done, next row, code)."""
        return loop(
                m, every, self._step_count, self._krow, self._hook_id, self._wcount,
                self.dt, self.qpos, self.qvel, self.time, self.qfrc,
                self.comp_kind, self.comp_off, self.comp_par, self.par_row, self.comp_soff, self.comp_st, self.minv,
                self.mrb,
                self.ma, self.coriolis_mode, self.rb, self.steer, self.shaftp, self.env,
                self.rud_cmd, self.shaft_cmd, self.pitch_cmd, self.shaft_mode, self.mach, self.nav,
                self.phases, self.hs, self.events, self.ecount,
                self.ctx, self.aux, self.comp_w, self.nudot, self.limits, self.status, rec, self.scratch)

    # what a step changes besides the MuJoCo state and the truth rows (the event log is appended
    # at ecount, so restoring ecount restores it); a run of the shards that stops is redone from these
    _RUN_STATE = ("comp_st", "rud_cmd", "mach", "nav", "hs", "ecount", "ctx", "aux")

    def _run_shards(self, m, every, rec):
        """``m`` steps on the shards, each in a thread of its own (see :class:`_Shard`).

        When every shard completes the run, its rows go back to the batch. When one stops (a ship's
        status, a MuJoCo error or warning), the others have run past the step where the whole batch
        stops; the run is then undone and done again on the whole batch, which stops where the
        plain loop does, with its message.
        """
        if self._wcount.any():  # a warning left from before: the whole batch stops at once, as before
            return self._run(self._loop, m, every, rec)
        saved = [self.batch.state.copy()] + [getattr(self, k).copy() for k in self._RUN_STATE]
        rows = 0 if rec is self._no_rec else len(range((-self._step_count) % every, m, every))
        calls = []
        for sh in self._shards:
            a, b = sh.a, sh.b
            sh.state[...] = self.batch.state[a:b]
            srec = sh.no_rec if rec is self._no_rec else sh.rec_rows(rows)
            calls.append((m, every, self._step_count, 0, sh.hook_id, sh.wcount,
                          self.dt, sh.qpos, sh.qvel, sh.time, sh.qfrc,
                          self.comp_kind, self.comp_off, self.comp_par, self.par_row[a:b], self.comp_soff,
                          self.comp_st[a:b],
                          self.minv[a:b], self.mrb[a:b], self.ma[a:b], self.coriolis_mode, self.rb[a:b], self.steer,
                          self.shaftp, self.env[a:b], self.rud_cmd[a:b], self.shaft_cmd[a:b], self.pitch_cmd[a:b],
                          self.shaft_mode[a:b], self.mach[a:b], self.nav[a:b], self.phases[a:b], self.hs[a:b],
                          self.events[a:b], self.ecount[a:b], self.ctx[a:b], self.aux[a:b], self.comp_w[a:b],
                          self.nudot[a:b], self.limits, self.status[a:b], srec, self.scratch[a:b]))
        if self._pool is None:
            from concurrent.futures import ThreadPoolExecutor
            self._pool = ThreadPoolExecutor(max_workers=len(self._shards) - 1, thread_name_prefix="vtrials-shard")
            weakref.finalize(self, self._pool.shutdown, wait=False)
        futures = [self._pool.submit(self._loop_serial, *c) for c in calls[1:]]
        results = [self._loop_serial(*calls[0])] + [f.result() for f in futures]
        if all(r[0] == m and r[2] == 0 for r in results):
            for sh in self._shards:
                self.batch.state[sh.a:sh.b] = sh.state
                if rows:
                    rec[self._krow:self._krow + rows, sh.a:sh.b] = sh.rec[:rows]
            return m, self._krow + rows, 0
        self.batch.state[...] = saved[0]
        for k, arr in zip(self._RUN_STATE, saved[1:]):
            getattr(self, k)[...] = arr
        for sh in self._shards:
            sh.wcount[...] = 0
            sh._hook_error = None
        return self._run(self._loop, m, every, rec)

    def _raise_mujoco(self, i: int, text: str | None):
        """A MuJoCo warning (its warning counters rose) or error in ship i: stop with the time and state."""
        if text is None:
            kinds = [mujoco.mjtWarning(k).name for k in np.flatnonzero(self._wcount[i])]
            text = f"MuJoCo warning {', '.join(kinds)}" + (f" ({_MJ_WARNINGS[-1]})" if _MJ_WARNINGS else "")
        q = self.qpos[i]
        v = self.qvel[i]
        msg = (f"simulation stopped at t = {self.time[i]:.3f} s (ship {i}): {text}; "
               f"state: qpos {np.array2string(q, precision=4, max_line_width=10 ** 6)}, "
               f"qvel {np.array2string(v, precision=4, max_line_width=10 ** 6)}")
        raise SimulationError(msg, time_s=float(self.time[i]), ship=i)

    def check(self) -> None:
        """Check the current states (the kernel checks each state before it is integrated)."""
        self.evaluate()
        if np.any(self.status != DY.OK):
            self._raise_status()

    def _raise_status(self):
        i = int(np.flatnonzero(self.status)[0])
        code = int(self.status[i])
        c = self.ctx[i]
        msg = (f"simulation stopped at t = {self.time[i]:.3f} s (ship {i}): {DY.STATUS_TEXT.get(code, code)}; "
               f"state: position N {c[L.POS]:.2f} m, E {c[L.POS + 1]:.2f} m, z {c[L.POS + 2]:.3f} m; "
               f"roll {deg(c[L.EUL]):.2f}°, pitch {deg(c[L.EUL + 1]):.2f}°, heading {deg(c[L.EUL + 2]):.2f}°; "
               f"velocity through water u {c[L.NU_R]:.4g}, v {c[L.NU_R + 1]:.4g}, w {c[L.NU_R + 2]:.4g} m/s; "
               f"rates p {c[L.NU_R + 3]:.4g}, q {c[L.NU_R + 4]:.4g}, r {c[L.NU_R + 5]:.4g} rad/s; "
               f"accelerations {np.array2string(self.nudot[i], precision=4)}")
        raise SimulationError(msg, time_s=float(self.time[i]), ship=i)

    def _new_chunk(self, rows: int = 4096):
        """A new truth chunk for ``rows`` more rows (at most 4096): sized to the run ahead, so that
        short runs (a fleet's crews act every second or so) do not allocate and fill 4096 rows each."""
        if self._chunk is not None:
            self._chunks.append(self._chunk[: self._krow])
        self._chunk = np.zeros((max(1, min(int(rows), 4096)), self.n, self.rec_width))
        self._krow = 0

    def truth(self) -> np.ndarray:
        """All truth rows recorded so far, (K, N, width)."""
        parts = list(self._chunks)
        if self._chunk is not None:
            parts.append(self._chunk[: self._krow])
        if not parts:
            return np.zeros((0, self.n, self.rec_width))
        return np.concatenate(parts, axis=0)

    def clear_truth(self) -> None:
        self._chunks = []
        self._chunk = None
        self._krow = 0

    # ------------------------------------------------------------------ steady states
    def _calm_twin(self, ship: int):
        """(simulator, index) on which ship ``ship``'s steady states are solved: this one if it has no
        first-order wave components (:data:`FIRST_ORDER_WAVE_TYPES`), else a one-ship twin without them
        (same vessel, step, limits, mean wave forces and the ship's environment block), so that a frozen
        first-order wave force at one instant does not enter the balance."""
        if not any(c.type in FIRST_ORDER_WAVE_TYPES for c in self.components):
            return self, ship
        if self._calm_sim is None:
            self._calm_sim = Simulator(self.vessel, 1, self.dt, envs=self.env[ship], record_every=0,
                                       limits=tuple(self.limits), planar=self.planar, gravity=self._gravity,
                                       components=[c for c in self.components if c.type not in FIRST_ORDER_WAVE_TYPES])
        self._calm_sim.env[0] = self.env[ship]
        return self._calm_sim, 0

    def _surge_residual(self, ship: int, s: ShipState) -> float:
        """Net surge force of condition s (straight ahead, rudders amidships)."""
        self.set_state(ship, s)
        return float((self.mrb[ship] + self.ma[ship])[0] @ self.evaluate()[ship])

    def _trim(self, ship: int, s: ShipState) -> ShipState:
        """One Newton step on heave, heel and trim towards the static balance of condition s."""
        if self.planar:
            return s
        self.set_state(ship, s)
        F = (self.mrb[ship] + self.ma[ship]) @ self.evaluate()[ship]
        dz, dphi, dth = np.linalg.solve(self.vessel.restoring_matrix()[2:5, 2:5], F[2:5])
        s.z += dz
        s.roll += dphi
        s.pitch += dth
        return s

    def self_propulsion(self, ship: int, speed: float, heading: float = 0.0, pitch: tuple = (),
                        trim_iterations: int = 4) -> ShipState:
        """The calm-water steady straight-ahead condition at ``speed`` through the water.

        Finds the shaft speed (all shafts equal, at the given or design pitch, rudders amidships) at
        which the surge forces balance, and the heave, heel and trim at which the heave force, roll
        and pitch moments balance; returns that condition (also placed on the ship).
        """
        twin, k = self._calm_twin(ship)
        if twin is not self:
            s = twin.self_propulsion(k, speed, heading, pitch, trim_iterations)
            self.set_state(ship, s)
            return s
        s = ShipState(heading=heading, u=speed, shaft_rps=(0.0,) * self.ns, pitch_ratio=tuple(pitch))
        n_hi = float(np.max([sh.max_rps for sh in self.vessel.shafts]))

        def resid(n):
            s.shaft_rps = (n,) * self.ns
            return self._surge_residual(ship, s)

        for _ in range(trim_iterations):
            if resid(n_hi) < 0:
                raise SimulationError(f"no shaft speed up to {n_hi * 60:.1f} r/min holds {speed:.3f} m/s")
            n_sp = brentq(resid, 1e-6, n_hi, xtol=1e-13, rtol=1e-14)
            s.shaft_rps = (n_sp,) * self.ns
            s = self._trim(ship, s)
        self.set_state(ship, s)
        return s

    def steady_at_order(self, ship: int, rps: tuple, pitch: tuple = (), heading: float = 0.0,
                        trim_iterations: int = 4) -> ShipState:
        """The calm-water steady straight-ahead speed at the given shaft speeds and pitch ratios
        (dead in the water when they give no ahead thrust); returns that condition."""
        twin, k = self._calm_twin(ship)
        if twin is not self:
            s = twin.steady_at_order(k, rps, pitch, heading, trim_iterations)
            self.set_state(ship, s)
            return s
        s = ShipState(heading=heading, u=0.0, shaft_rps=tuple(rps), pitch_ratio=tuple(pitch))
        if self._surge_residual(ship, s) <= 0.0:
            self.set_state(ship, s)
            return s  # no ahead thrust: dead in the water
        u_hi = 0.9 * float(self.limits[0])

        def resid(u):
            s.u = u
            return self._surge_residual(ship, s)

        if resid(u_hi) > 0:
            raise SimulationError(f"the order {rps} gives more than {u_hi:.1f} m/s")
        for _ in range(trim_iterations):
            s.u = brentq(resid, 0.0, u_hi, xtol=1e-12, rtol=1e-14)
            s = self._trim(ship, s)
        self.set_state(ship, s)
        return s
