"""The gymnasium environment of one ship doing one maneuver task (vtrials/<Task>-v0).

Observation (float32, ``stack`` frames of 9 + task features; all from the instruments, normalised):
sin/cos of the gyro heading, IMU yaw rate × L/U₀, EM-log speed / U₀, GNSS speed over ground / U₀,
rudder synchro / δ_max, shaft counter / full-ahead rev/s, the previous rudder action and lever, then
the task's features (tasks.py). Action: rudder order as a fraction of δ_max (the autopilot's rudder
limit) and, where the task works the engine, the telegraph lever −1 … 1 (orders at LEVER positions,
r/min and pitch interpolated); discrete variant: 11 rudder orders (× the telegraph orders).
Reward from the truth (tasks.py); termination by the task, truncation at the task's duration.
``reset(seed=s)`` reproduces the episode; ``options`` override the domain draws: wind_kn,
wind_from_deg, current_kn, current_to_deg, order (approach telegraph order), heading_deg.
"""

from __future__ import annotations

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from vtrials.envs.core import RUDDER_LEVELS, ShipBatch


def spaces_of(core: ShipBatch) -> tuple[spaces.Space, spaces.Space]:
    """(observation space, action space) of one ship of ``core``."""
    obs = spaces.Box(-50.0, 50.0, shape=(core.stack * core.n_feat,), dtype=np.float32)
    if core.discrete:
        act = spaces.MultiDiscrete([RUDDER_LEVELS, len(core.lever_orders)]) if core.engine \
            else spaces.Discrete(RUDDER_LEVELS)
    else:
        act = spaces.Box(-1.0, 1.0, shape=(2 if core.engine else 1,), dtype=np.float32)
    return obs, act


class ShipEnv(gym.Env):
    """One ship, one task (see the module docstring for the spaces)."""

    metadata = {"render_modes": ["rgb_array", "human"], "render_fps": 10}

    def __init__(self, task: str = "CourseKeeping", ship: str = "patrol51", sea: str = "calm",
                 discrete: bool = False, engine_action: bool | None = None, stack: int = 1,
                 control_period_s: float | None = None, task_options: dict | None = None,
                 render_mode: str | None = None, width: int = 480, height: int = 320):
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            from vtrials.errors import InputError
            raise InputError("environment", "render_mode", f"{render_mode!r} (allowed: rgb_array, human)")
        self.core = ShipBatch(task, ship, 1, sea, discrete, engine_action, stack, control_period_s, task_options)
        self.observation_space, self.action_space = spaces_of(self.core)
        self.render_mode = render_mode
        self._size = (width, height)
        self._renderer = None
        self.metadata = dict(self.metadata, render_fps=max(1, int(round(1.0 / self.core.period))))

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        if seed is None and not hasattr(self, "_seeded"):
            seed = int(self.np_random.integers(2 ** 63))
        self._seeded = True
        self.core.reset_ships([0], None if seed is None else [seed], options)
        return self.core.observations()[0].copy(), self._info()

    def step(self, action):
        a = np.asarray(action)[None] if self.core.discrete else np.asarray(action, dtype=np.float64)[None]
        r, term, trunc, failed = self.core.step(a)
        if self.render_mode == "human":
            self.render()
        return (self.core.observations()[0].copy(), float(r[0]), bool(term[0]), bool(trunc[0]),
                self._info(failed=bool(failed[0])))

    def _info(self, failed: bool = False) -> dict:
        c = self.core
        return {"t": float(c.truth["t"][0]), "measured": dict(zip(("heading", "yaw_rate", "north", "east", "sog",
                                                                   "log_speed", "rudder", "shaft_rps"),
                                                                  map(float, c.meas[0]))),
                "drawn": dict(c.drawn[0]), "failed": failed}

    def render(self):
        if self.render_mode is None:
            gym.logger.warn("render() called without a render_mode")
            return None
        from vtrials.envs.render import ShipRenderer
        if self._renderer is None:
            self._renderer = ShipRenderer(self.core.sim.model, *self._size)
        img = self._renderer.frame(self.core.sim.qpos[0], np.array(self.core.track[0]), self.core.L,
                                     waves=self.core.render_waves(0))
        if self.render_mode == "human":
            self._renderer.show(img)
            return None
        return img

    def close(self):
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None
