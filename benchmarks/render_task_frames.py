"""A rendered frame of each task (the README's pictures): the PID baseline flies each task for a
while in wind and current, then the frame is saved to benchmarks/figures/env_<Task>[_KVLCC2].png; and
each task once more in wind, current and waves (H_s 2 m patrol51, 3 m KVLCC2):
env_<Task>[_KVLCC2]_waves.png.

    MUJOCO_GL=egl python benchmarks/render_task_frames.py
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

FIG = Path(__file__).resolve().parent / "figures"
STEPS = {"CourseKeeping": 120, "ZigZag": 140, "Williamson": 160, "Stopping": 60, "TrackFollowing": 150}


def main():
    from PIL import Image
    from vtrials.envs.baselines import PIDPolicy
    from vtrials.envs.ship_env import ShipEnv
    from vtrials.envs.tasks import TASKS
    FIG.mkdir(parents=True, exist_ok=True)
    for ship, suffix in (("patrol51", ""), ("kvlcc2", "_KVLCC2")):
        for task, sea, tail in [(t, "wind_current", "") for t in TASKS] + [(t, "wind_current_waves", "_waves")
                                                                          for t in TASKS]:
            env = ShipEnv(task, ship, sea=sea, render_mode="rgb_array", width=480, height=270)
            env.reset(seed=4, options={"hs_m": 2.0 if ship == "patrol51" else 3.0} if "waves" in sea else None)
            pid = PIDPolicy(env.core)
            for _ in range(STEPS[task]):
                _, _, term, trunc, _ = env.step(pid()[0])
                if term or trunc:
                    break
            path = FIG / f"env_{task}{suffix}{tail}.png"
            Image.fromarray(env.render()).save(path)
            env.close()
            print(f"wrote {path}")


if __name__ == "__main__":
    main()
