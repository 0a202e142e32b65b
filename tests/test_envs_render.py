"""Rendering: frames of every task are pictures of a ship in its sea (not blank), and any run's truth
renders to a video through the CLI."""

from __future__ import annotations

import numpy as np
import pytest

from vtrials.envs.ship_env import ShipEnv
from vtrials.envs.tasks import TASKS


def _not_blank(img: np.ndarray) -> None:
    assert img.dtype == np.uint8 and img.ndim == 3 and img.shape[2] == 3
    assert img.std() > 5.0, "flat image"
    colours = np.unique(img.reshape(-1, 3) // 8, axis=0)
    assert len(colours) > 20, "too few colours for a ship in a sea"
    # the ship stands out of the sea: the centre of the frame differs from the sea at the border
    h, w, _ = img.shape
    centre = img[h // 3: 2 * h // 3, w // 3: 2 * w // 3].reshape(-1, 3).astype(float)
    sea = np.median(img[-10:].reshape(-1, 3), axis=0)
    assert np.mean(np.abs(centre - sea).sum(axis=1) > 40) > 0.01, "no ship in the middle of the frame"


@pytest.mark.parametrize("task", TASKS)
def test_rgb_array_frame_of_each_task(task):
    env = ShipEnv(task, "patrol51", sea="wind", render_mode="rgb_array", width=240, height=160)
    env.reset(seed=1)
    for _ in range(20):
        env.step(env.action_space.sample() * 0 + 0.5)
    img = env.render()
    assert img.shape == (160, 240, 3)
    _not_blank(img)
    # the picture follows the ship: another pose, another picture
    for _ in range(10):
        env.step(env.action_space.sample() * 0 - 0.5)
    assert not np.array_equal(img, env.render())
    env.close()


def test_frame_in_waves_shows_the_wave_surface():
    """In waves the sea is drawn as the ship's own wave surface: a frame differs from the same pose in
    a flat sea, and the wave surface moves with time (another instant, another picture)."""
    env = ShipEnv("CourseKeeping", "patrol51", sea="waves", render_mode="rgb_array", width=240, height=160)
    env.reset(seed=4, options={"hs_m": 2.0})
    for _ in range(5):
        env.step(np.zeros(1, dtype=np.float32))
    img = env.render()
    _not_blank(img)
    core = env.core
    flat = env._renderer.frame(core.sim.qpos[0], np.array(core.track[0]), core.L)
    assert np.mean(np.abs(img.astype(int) - flat.astype(int)).sum(axis=2) > 30) > 0.05
    comp, t = core.render_waves(0)
    later = env._renderer.frame(core.sim.qpos[0], np.array(core.track[0]), core.L, waves=(comp, t + 2.0))
    assert not np.array_equal(img, later)
    env.close()


def test_cli_renders_a_run_to_video(tmp_path):
    from vtrials.cli import main
    from vtrials.physics.simulator import Simulator
    from vtrials.physics.vessel import load_vessel
    from vtrials.records.netcdf import write_groups
    v = load_vessel("patrol51")
    sim = Simulator(v, 1, 0.02, record_every=5)
    sim.steady_at_order(0, (7.5, 7.5), (1.22, 1.22))
    sim.set_rudder_order(0, 0.3)
    sim.step(1000)
    rows = sim.truth()[:, 0, :]
    var = {n: (rows[:, j], "", n) for j, n in enumerate(sim.rec_names) if n != "t"}
    write_groups(tmp_path / "truth.nc", {"turn": {"time": rows[:, 0], "variables": var, "attrs": {}}},
                 {"ship": "patrol51", "content": "truth"})
    out = tmp_path / "turn.gif"
    assert main(["render", str(tmp_path), "--out", str(out), "--fps", "5", "--speed", "5"]) == 0
    from PIL import Image
    im = Image.open(out)
    assert im.n_frames == 20  # truth at 0 … 19.9 s, 5x at 5 frames/s: one frame per simulated second
    im.seek(im.n_frames - 1)
    _not_blank(np.asarray(im.convert("RGB")))
    assert main(["render", str(tmp_path / "nothing"), "--out", str(out)]) == 2
