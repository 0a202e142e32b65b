"""N ships of one vessel doing one task: the shared engine of the scalar and the vector environments.

One :class:`~vtrials.physics.simulator.Simulator` holds the N ships in one ``mujoco.batch`` with the
force kernel vectorised over ships; commands are written into the simulator's per-ship command rows
(what ``set_rudder_order`` / ``set_shaft_order`` / ``set_pitch_order`` do, for all ships at once); the
agent sees the ship through :mod:`vtrials.envs.observe`; rewards come from the truth
(:mod:`vtrials.envs.tasks`). Each ship has its own random Generator, so a ship's episode depends only
on its seed, not on the number of ships or on the others.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from vtrials.errors import InputError, SimulationError
from vtrials.physics.environment import wind as W
from vtrials.physics.environment.current import Current
from vtrials.physics.environment.current import pack as pack_current
from vtrials.physics.forces import context as L
from vtrials.physics.simulator import ShipState, Simulator
from vtrials.physics.vessel import load_vessel
from vtrials.envs.observe import CHANNELS, ObservationModel, suite_parts
from vtrials.envs.tasks import make_task
from vtrials.units import DEG, KNOT

# lever positions of the telegraph orders (continuous lever −1 … 1; between orders r/min and pitch
# are interpolated linearly)
LEVER = (("back_emergency", -1.0), ("back_full", -0.8), ("back_2_3", -0.6), ("back_1_3", -0.4), ("stop", 0.0),
         ("ahead_1_3", 0.2), ("ahead_2_3", 0.4), ("standard", 0.6), ("full", 0.8), ("flank", 1.0))
SEAS = ("calm", "wind", "current", "wind_current", "waves", "wind_current_waves")
RUDDER_LEVELS = 11  # discrete rudder orders: −δ_max … δ_max in equal steps
N_GUSTS = 64  # gust components per ship (NPD spectrum)
N_WAVES = 60  # wave components per ship (JONSWAP wind sea, cos-2s short-crested; the shipped scenarios use
#               150-200: fewer keep the env fast; the realization still has the spectrum's variance)
DEPTH_M = 1.0e4
# time step per ship model: those of the shipped scenarios (scenarios/*.toml)
SHIP_DT = {"kvlcc2": 0.05, "patrol51": 0.02}
N_COMMON = 9  # common features ahead of the task's
# where the Stopping task lays its mark (ship lengths ahead): a task design choice, beyond the reach of
# a crash stop (back_full, rudder amidships) from the approach orders, measured on these models in calm
# water: patrol51 3.4 L from full (12.3 m/s), 2.6 L from standard; KVLCC2 9.9 L from full (7.9 m/s),
# 7.7 L from standard
STOP_MARK_L = {"patrol51": {"mark_L": (4.0, 8.0)}, "kvlcc2": {"mark_L": (11.0, 20.0)}}


@dataclasses.dataclass(frozen=True)
class SeaRanges:
    """Ranges the domain randomisation draws from (uniform); knots and degrees at this edge."""

    wind_kn: tuple[float, float] = (10.0, 30.0)
    current_kn: tuple[float, float] = (0.5, 2.0)
    gust_spectrum: str = "npd"
    hs_m: tuple[float, float] = (0.5, 2.5)  # significant wave height of the wind sea (sea states 2-4)
    # T_p/√H_s [s/√m]: DNV-RP-C205 (2010) §3.5.5.5 gives JONSWAP seas 3.6 ≤ T_p/√H_s ≤ 5, with
    # γ = exp(5.75 − 1.15 T_p/√H_s) there (γ = 1 from 5 on)
    tp_per_sqrt_hs: tuple[float, float] = (3.6, 5.0)
    spreading_s: float = 10.0  # cos-2s exponent of a wind sea (Goda 1985)


class ShipBatch:
    """``n`` ships of ``ship`` doing ``task`` in the sea state ``sea``.

    Parameters: task (one of tasks.TASKS), ship (a model name), sea (one of SEAS), discrete (discrete
    actions), engine_action (the agent works the telegraph lever; task default if None), stack (frames
    of observations stacked), control_period_s (default L/U_full/12 rounded to whole steps),
    task_options (task parameters), nthread (MuJoCo batch threads).
    """

    def __init__(self, task: str = "CourseKeeping", ship: str = "patrol51", n: int = 1, sea: str = "calm",
                 discrete: bool = False, engine_action: bool | None = None, stack: int = 1,
                 control_period_s: float | None = None, task_options: dict | None = None, nthread: int = 1,
                 sea_ranges: SeaRanges = SeaRanges()):
        if sea not in SEAS:
            raise InputError("environment", "sea", f"{sea!r} is not a sea state (allowed: {', '.join(SEAS)})")
        if ship not in SHIP_DT:
            raise InputError("environment", "ship", f"{ship!r} has no environment set-up (allowed: "
                                                     f"{', '.join(SHIP_DT)})")
        if int(stack) < 1:
            raise InputError("environment", "stack", f"{stack!r}: stack at least 1 frame")
        self.vessel = v = load_vessel(ship)
        self.ship, self.sea, self.n = ship, sea, int(n)
        self.ranges = sea_ranges
        self.dt = SHIP_DT[ship]
        self.L = v.length
        self.delta_max = v.autopilot.rudder_limit_deg * DEG
        task_options = {**STOP_MARK_L.get(ship, {}), **dict(task_options or {})} if task == "Stopping" \
            else task_options
        self.task = make_task(task, self.n, self.L, self.delta_max, task_options)
        self.engine = self.task.engine_action if engine_action is None else bool(engine_action)
        self.discrete = bool(discrete)
        self.stack = int(stack)
        # lever table (orders the ship's telegraph has)
        lev = [(o, x) for o, x in LEVER if o in v.telegraph]
        self.lever_orders = [o for o, _ in lev]
        self.lever_pos = np.array([x for _, x in lev])
        self.lever_rps = np.array([v.telegraph[o][0] for o in self.lever_orders])
        dp = self.vessel.shaft_params
        from vtrials.physics.propulsion import S_CP, S_PITCH_DESIGN
        self.cp = dp[:, S_CP] > 0
        self.lever_pitch = np.array([v.telegraph[o][1] if v.telegraph[o][1] is not None else np.nan
                                     for o in self.lever_orders])
        self.design_pitch = dp[:, S_PITCH_DESIGN]
        self.n_full = v.telegraph["full"][0]
        # the steady approach at each order (a one-ship helper, calm water), cached
        self._helper = Simulator(v, 1, self.dt, record_every=0)
        self._steady: dict[str, ShipState] = {}
        U_full = self._steady_state("full").u
        period = control_period_s if control_period_s is not None else self.L / U_full / 12.0
        self.substeps = max(1, int(round(period / self.dt)))
        self.period = self.substeps * self.dt
        self.task.period = self.period
        # horizon of the observation noise: the longest episode (the slowest approach order)
        U_min = min(self._steady_state(o).u for o in self.task.orders)
        self.max_steps = int(math.ceil(self.task.duration_LU * self.L / U_min / self.period))
        base = pack_current(Current(), DEPTH_M)
        self.env_width = W.env_width(N_GUSTS)
        env0 = np.zeros(self.env_width)
        env0[:base.shape[0]] = base
        # waves: the seakeeping vessel (radiation memory, wave excitation, mean wave forces) built once
        # for a template seaway of N_WAVES components; each episode's own realization is set per ship
        self.waves = "waves" in sea
        sim_vessel = v
        if self.waves:
            from vtrials.physics.seakeeping.database import load_database
            from vtrials.physics.seakeeping.sea_ship import sea_ship
            from vtrials.scenario import hydro_path
            from vtrials.physics.forces.added_resistance import snnm_hull
            self._db = load_database(hydro_path(v))
            self._snnm = snnm_hull(v)
            comp0, _ = self._wave_components(np.random.default_rng(0), {})
            sim_vessel, _ = sea_ship(v, self._db, comp0, self.dt)
        self.wave_comp = np.zeros((self.n, N_WAVES if self.waves else 0, 6))
        self.sim = Simulator(sim_vessel, self.n, self.dt, envs=env0, nthread=nthread, record_every=0)
        parts, sites, self.devices, self.dev_index = suite_parts(v)
        self.obs_model = ObservationModel(parts, sites, self.n, self.period, self.max_steps)
        self.rng = [np.random.default_rng() for _ in range(self.n)]
        self.steps = np.zeros(self.n, dtype=np.int64)
        self.act_prev = np.zeros((self.n, 2))
        self.n_feat = N_COMMON + self.task.n_features
        self.frames = np.zeros((self.n, self.stack, self.n_feat), dtype=np.float32)
        self.meas = np.zeros((self.n, len(CHANNELS)))
        self.truth = {}
        self.drawn = [dict() for _ in range(self.n)]
        self.track: list[list] = [[] for _ in range(self.n)]  # truth positions at control instants (wake)

    # ------------------------------------------------------------------ set-up helpers
    def _steady_state(self, order: str) -> ShipState:
        if order not in self._steady:
            rps, pitch = self.vessel.telegraph[order]
            ns = self._helper.ns
            s = self._helper.steady_at_order(0, (rps,) * ns, () if pitch is None else (pitch,) * ns)
            self._steady[order] = s
        return self._steady[order]

    def lever_of(self, order: str) -> float:
        return float(dict(LEVER)[order])

    def _lever_to_orders(self, lever: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        rps = np.interp(lever, self.lever_pos, self.lever_rps)
        if np.any(self.cp):
            pitch = np.interp(lever, self.lever_pos, self.lever_pitch)
        else:
            pitch = np.full_like(lever, np.nan)
        return rps, pitch

    def render_waves(self, i: int) -> tuple[np.ndarray, float] | None:
        """(wave components, time) of ship ``i`` for the renderer, None in a sea without waves."""
        return (self.wave_comp[i], float(self.sim.time[i])) if self.waves else None

    def _wave_components(self, rng: np.random.Generator, d: dict) -> tuple[np.ndarray, dict]:
        """A wind-sea realization of N_WAVES components (JONSWAP, cos-2s) within the hydrodynamic
        database's band, and what was drawn (H_s, T_p, γ, direction it comes from; knots/degrees)."""
        from vtrials.physics.environment.waves import Waves, realize
        from vtrials.physics.seakeeping.sea_ship import in_database_band
        r = self.ranges
        hs = float(d.get("hs_m", rng.uniform(*r.hs_m)))
        ratio = rng.uniform(*r.tp_per_sqrt_hs)
        tp = float(d.get("tp_s", ratio * math.sqrt(hs)))
        ratio = tp / math.sqrt(hs)
        gamma = math.exp(5.75 - 1.15 * ratio) if ratio < 5.0 else 1.0
        gamma = min(max(gamma, 1.0), 10.0)
        frm = float(d.get("wave_from_deg", rng.uniform(0.0, 360.0)))
        waves = Waves(hs_m=hs, tp_s=tp, gamma=gamma, direction_deg=frm, spreading_s=self.ranges.spreading_s,
                      n_components=N_WAVES)
        field = realize(waves, DEPTH_M, rng.spawn(1)[0])
        comp, _ = in_database_band(self._db, field.components, DEPTH_M)
        return comp, {"hs_m": hs, "tp_s": tp, "gamma": gamma, "wave_from_deg": frm}

    def _sea_block(self, rng: np.random.Generator, opts: dict) -> tuple[np.ndarray, dict]:
        r = self.ranges
        wind = "wind" in self.sea
        cur = "current" in self.sea
        d = {"wind_kn": 0.0, "wind_from_deg": 0.0, "current_kn": 0.0, "current_to_deg": 0.0}
        if wind:
            d["wind_kn"] = rng.uniform(*r.wind_kn)
            d["wind_from_deg"] = rng.uniform(0.0, 360.0)
        if cur:
            d["current_kn"] = rng.uniform(*r.current_kn)
            d["current_to_deg"] = rng.uniform(0.0, 360.0)
        for k in d:
            if k in opts:
                d[k] = float(opts[k])
        gust_rng = rng.spawn(1)[0]
        env = pack_current(Current(speed_kn=d["current_kn"], direction_deg=d["current_to_deg"]), DEPTH_M)
        spectrum = r.gust_spectrum if wind else "none"
        wnd = W.Wind(speed_kn=d["wind_kn"], direction_deg=d["wind_from_deg"], gust_spectrum=spectrum,
                     gust_components=N_GUSTS)
        env = W.pack_env(wnd, env, gust_rng)
        out = np.zeros(self.env_width)
        out[:env.shape[0]] = env
        if self.waves:
            # a wind sea comes from where the wind blows from (when there is wind)
            known = {k: float(opts[k]) for k in ("hs_m", "tp_s", "wave_from_deg") if k in opts}
            if wind and "wave_from_deg" not in known:
                known["wave_from_deg"] = d["wind_from_deg"]
            comp, drawn = self._wave_components(rng.spawn(1)[0], known)
            d.update(drawn)
            d["wave_components"] = comp
        return out, d

    # ------------------------------------------------------------------ episodes
    def reset_ships(self, idx, seeds=None, options: dict | None = None) -> None:
        """Start new episodes on ships ``idx`` (seeds: one per ship, or None to go on drawing from
        each ship's Generator)."""
        opts = dict(options or {})
        idx = np.atleast_1d(np.asarray(idx, dtype=np.int64))
        for j, i in enumerate(idx):
            if seeds is not None and seeds[j] is not None:
                self.rng[i] = np.random.default_rng(np.random.SeedSequence(int(seeds[j])))
            rng_sea, rng_task, rng_obs = self.rng[i].spawn(3)
            env, sea = self._sea_block(rng_sea, opts)
            self.sim.env[i] = env
            if self.waves:
                from vtrials.physics.seakeeping.sea_ship import seaway_params
                comp = sea.pop("wave_components")
                self.wave_comp[i] = comp
                for name, par in seaway_params(self.vessel, self._db, comp, snnm=self._snnm).items():
                    self.sim.set_component_params(i, name, par)
            order = opts.get("order") or self.task.orders[int(rng_task.integers(len(self.task.orders)))]
            if order not in self.vessel.telegraph:
                raise InputError("reset options", "order", f"{order!r} is not a telegraph order of "
                                                           f"{self.ship} (allowed: {', '.join(self.vessel.telegraph)})")
            st = self.task.start(i, rng_task)
            if "heading_deg" in opts:
                st["heading"] = float(opts["heading_deg"]) * DEG
                self.task.psi0[i] = st["heading"]
            s0 = dataclasses.replace(self._steady_state(order), heading=st["heading"], x=st["x"], y=st["y"])
            self.sim.set_state(i, s0)
            self.task.begin(i, abs(s0.u), rng_task)
            self.obs_model.reset(i, rng_obs)
            self.steps[i] = 0
            self.act_prev[i] = (0.0, self.lever_of(order))
            self.drawn[i] = {"order": order, **sea}
            self.track[i] = []
        self._observe(idx, first=True)

    def _read_truth(self) -> dict:
        sim = self.sim
        c = sim.kinematics()  # what an evaluation would put in ctx, without the forces
        R = c[:, L.ROT:L.ROT + 9]
        u, v, w = c[:, L.NU], c[:, L.NU + 1], c[:, L.NU + 2]
        vn = R[:, 0] * u + R[:, 1] * v + R[:, 2] * w
        ve = R[:, 3] * u + R[:, 4] * v + R[:, 5] * w
        self.truth = {"t": sim.time.copy(), "x": c[:, L.POS].copy(), "y": c[:, L.POS + 1].copy(),
                      "psi": c[:, L.EUL + 2].copy(), "u_r": c[:, L.NU_R].copy(), "v_r": c[:, L.NU_R + 1].copy(),
                      "r": c[:, L.NU + 5].copy(), "vn": vn, "ve": ve, "sog": np.hypot(vn, ve),
                      "rudder": c[:, L.DELTA + self.dev_index["rudder"]].copy(),
                      "shaft_rps": c[:, L.SHAFT_N + self.dev_index["shaft_rps"]].copy()}
        return self.truth

    def _observe(self, idx: np.ndarray, first: bool = False) -> None:
        truth = self._read_truth()
        sub = {k: a[idx] for k, a in truth.items()}
        m = self.obs_model.sample(sub, idx)
        self.meas[idx] = m
        for i in idx:
            self.track[i].append((truth["x"][i], truth["y"][i]))
        U0 = self.task.U0[idx]
        f = np.empty((idx.size, self.n_feat))
        f[:, 0] = np.sin(m[:, 0])
        f[:, 1] = np.cos(m[:, 0])
        f[:, 2] = m[:, 1] * self.task.T[idx]
        f[:, 3] = m[:, 5] / U0
        f[:, 4] = m[:, 4] / U0
        f[:, 5] = m[:, 6] / self.delta_max
        f[:, 6] = m[:, 7] / self.n_full
        f[:, 7:9] = self.act_prev[idx]
        f[:, N_COMMON:] = self.task.features(m, idx)
        f = np.clip(f, -50.0, 50.0).astype(np.float32)
        if first:
            self.frames[idx] = f[:, None, :]
        else:
            self.frames[idx, :-1] = self.frames[idx, 1:]
            self.frames[idx, -1] = f

    def observations(self) -> np.ndarray:
        return self.frames.reshape(self.n, -1)

    def decode(self, action) -> tuple[np.ndarray, np.ndarray]:
        """Actions of all ships → (rudder fraction, lever) in [−1, 1]."""
        a = np.asarray(action)
        if self.discrete:
            a = a.reshape(self.n, -1).astype(np.int64)
            rud = a[:, 0] / (RUDDER_LEVELS - 1) * 2.0 - 1.0
            if self.engine:
                lev = self.lever_pos[a[:, 1]]
            else:
                lev = self.act_prev[:, 1]
        else:
            a = np.clip(a.reshape(self.n, -1).astype(np.float64), -1.0, 1.0)
            rud = a[:, 0]
            lev = a[:, 1] if self.engine else self.act_prev[:, 1]
        return rud, lev

    def step(self, action) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """One control period for every ship: (reward, terminated, truncated, failed)."""
        rud, lev = self.decode(action)
        sim = self.sim
        delta = rud * self.delta_max
        sim.rud_cmd[:, :] = delta[:, None]
        rps, pitch = self._lever_to_orders(lev)
        sim.shaft_cmd[:, :] = rps[:, None]
        if np.any(self.cp):
            sim.pitch_cmd[:, self.cp] = pitch[:, None]
        self.act_prev[:, 0] = rud
        self.act_prev[:, 1] = lev
        failed = np.zeros(self.n, dtype=bool)
        left = self.substeps
        while left > 0:
            before = sim._step_count
            try:
                sim.step(left)
                left = 0
            except SimulationError:
                # a runaway ship (the kernel checks every state before it is integrated): its episode
                # ends; it is parked dead in the water so that the others can go on
                left -= sim._step_count - before
                for i in np.flatnonzero(sim.status):
                    failed[i] = True
                    park = dataclasses.replace(self._steady_state("stop"), u=0.0, x=float(self.truth["x"][i]),
                                               y=float(self.truth["y"][i]), time=float(sim.time[i]))
                    sim.set_state(int(i), park)
        self.steps += 1
        self._observe(np.arange(self.n))
        reward, term = self.task.score(self.truth, delta)
        reward = np.where(failed, -100.0, reward)
        term = term | failed
        trunc = (self.steps >= self.task_steps()) & ~term
        return reward, term, trunc, failed

    def task_steps(self) -> np.ndarray:
        """Each ship's episode length in control steps (duration in L/U₀ of its approach speed)."""
        return np.ceil(self.task.duration_LU * self.task.T / self.period).astype(np.int64)
