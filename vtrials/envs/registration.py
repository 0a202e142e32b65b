"""Registers the vtrials environments with gymnasium (importing this module does it).

``gymnasium.make("vtrials/CourseKeeping-v0")`` after ``import vtrials.envs.registration``, or in one
go ``gymnasium.make("vtrials.envs.registration:vtrials/CourseKeeping-v0")``. Ids: ``vtrials/<Task>-v0``
(patrol51) and ``vtrials/<Task>-KVLCC2-v0`` for each task of :data:`vtrials.envs.tasks.TASKS`; keyword
arguments (sea, discrete, engine_action, stack, task_options, ...) pass through ``make``;
``gymnasium.make_vec(id, num_envs, vectorization_mode="vector_entry_point")`` gives the native
vector env.
"""

from __future__ import annotations

from gymnasium.envs.registration import register, registry

from vtrials.envs.tasks import TASKS

SHIPS = {"": "patrol51", "-KVLCC2": "kvlcc2"}


def env_ids() -> list[str]:
    return [f"vtrials/{t}{s}-v0" for t in TASKS for s in SHIPS]


def register_all() -> None:
    for task in TASKS:
        for suffix, ship in SHIPS.items():
            eid = f"vtrials/{task}{suffix}-v0"
            if eid in registry:
                continue
            register(id=eid, entry_point="vtrials.envs.ship_env:ShipEnv",
                     vector_entry_point="vtrials.envs.vector:ShipVectorEnv",
                     kwargs={"task": task, "ship": ship}, disable_env_checker=False)


register_all()
