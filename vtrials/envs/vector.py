"""The native vector environment: N ships in one ``mujoco.batch``, one force-kernel call per step.

Same task, spaces, rewards and observations as :class:`vtrials.envs.ship_env.ShipEnv`; ship i of
``reset(seed=s)`` runs exactly the episode of ``ShipEnv.reset(seed=s + i)`` (as gymnasium's
SyncVectorEnv seeds its copies). Autoreset is gymnasium 1.x's NEXT_STEP mode: the step after a ship's
episode ended returns that ship's reset observation with reward 0 and the action ignored (the batch
steps the ship anyway and its new initial condition overwrites that step).
"""

from __future__ import annotations

import numpy as np
from gymnasium import spaces
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from vtrials.envs.core import ShipBatch
from vtrials.envs.ship_env import spaces_of


class ShipVectorEnv(VectorEnv):
    """``num_envs`` ships doing ``task`` (keyword arguments as ShipEnv, plus nthread)."""

    metadata = {"render_modes": ["rgb_array"], "autoreset_mode": AutoresetMode.NEXT_STEP}

    def __init__(self, num_envs: int = 16, task: str = "CourseKeeping", ship: str = "patrol51", sea: str = "calm",
                 discrete: bool = False, engine_action: bool | None = None, stack: int = 1,
                 control_period_s: float | None = None, task_options: dict | None = None, nthread: int = 1,
                 render_mode: str | None = None, width: int = 480, height: int = 320):
        from vtrials.physics.simulator import PARALLEL_FROM
        # threads only pay off for batches the kernel spreads over threads (MuJoCo's too)
        nthread = int(nthread) if num_envs >= PARALLEL_FROM else 1
        self.core = ShipBatch(task, ship, num_envs, sea, discrete, engine_action, stack, control_period_s,
                              task_options, nthread)
        self.num_envs = int(num_envs)
        self.single_observation_space, self.single_action_space = spaces_of(self.core)
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        self.render_mode = render_mode
        self._size = (width, height)
        self._renderer = None
        self._autoreset = np.zeros(self.num_envs, dtype=bool)
        self._seeded = False

    def reset(self, *, seed: int | list | None = None, options: dict | None = None):
        super().reset(seed=seed)
        n = self.num_envs
        if seed is None and not self._seeded:
            seed = int(self.np_random.integers(2 ** 62))
        if seed is None:
            seeds = None
        elif isinstance(seed, (int, np.integer)):
            seeds = [int(seed) + i for i in range(n)]
        else:
            seeds = list(seed)
        self._seeded = True
        opts = dict(options or {})
        mask = opts.pop("reset_mask", None)
        idx = np.arange(n) if mask is None else np.flatnonzero(mask)
        self.core.reset_ships(idx, None if seeds is None else [seeds[i] for i in idx], opts)
        self._autoreset[idx] = False
        return self.core.observations().copy(), self._info()

    def step(self, actions):
        core = self.core
        reward, term, trunc, failed = core.step(actions)
        ar = np.flatnonzero(self._autoreset)
        if ar.size:
            core.reset_ships(ar)
            reward[ar] = 0.0
            term[ar] = False
            trunc[ar] = False
        self._autoreset = term | trunc
        return core.observations().copy(), reward.astype(np.float64), term, trunc, self._info(failed)

    def _info(self, failed=None) -> dict:
        c = self.core
        info = {"t": c.truth["t"].copy(), "measured": c.meas.copy()}
        if failed is not None:
            info["failed"] = failed
        return info

    def render(self):
        """The first ship in its sea (rgb_array)."""
        if self.render_mode is None:
            return None
        from vtrials.envs.render import ShipRenderer
        if self._renderer is None:
            self._renderer = ShipRenderer(self.core.sim.model, *self._size)
        return self._renderer.frame(self.core.sim.qpos[0], np.array(self.core.track[0]), self.core.L,
                                     waves=self.core.render_waves(0))

    def close_extras(self, **kwargs):
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None
