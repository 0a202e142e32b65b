"""``vtrials render RUN_DIR --out video.mp4``: any run's truth (truth.nc) as a video of the ship in
its sea with its wake, rendered by MuJoCo offscreen (:mod:`vtrials.envs.render`).

MP4 needs the optional ``imageio-ffmpeg`` (``pip install vtrials[render]``: a bundled ffmpeg);
``.gif`` is written with Pillow (a matplotlib dependency) and needs nothing more.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from vtrials.errors import InputError

WAKE_S_PER_L = 40.0  # wake drawn over the last 40 L/U of track (in seconds: 40 L / U, capped below)


def truth_frames(run_dir: str | Path, group: str | None = None):
    """(ship name, group name, time (K,), qpos rows (K, nq) without shaft angles, track (K, 2))
    of one group of RUN_DIR/truth.nc (default: the first)."""
    from vtrials.physics.vessel import load_vessel
    from vtrials.records.netcdf import read_groups
    path = Path(run_dir) / "truth.nc"
    if not path.is_file():
        raise InputError(str(run_dir), "RUN_DIR", "holds no truth.nc (a directory written by 'vtrials run')")
    doc = read_groups(path)
    ship = doc["attrs"].get("ship")
    groups = doc["groups"]
    if not groups:
        raise InputError(str(path), "", "holds no runs")
    name = group or next(iter(groups))
    if name not in groups:
        raise InputError(str(path), "--run", f"{name!r} is not a run of this file (runs: {', '.join(groups)})")
    var = groups[name]["variables"]
    v = load_vessel(ship)
    t = np.asarray(var["time"] if "time" in var else var["t"], float)
    q = np.zeros((t.size, v.model.nq))
    q[:, 0], q[:, 1], q[:, 2] = var["x"], var["y"], var["z"]
    q[:, 3], q[:, 4], q[:, 5], q[:, 6] = var["qw"], var["qx"], var["qy"], var["qz"]
    for k in range(v.steering.shape[0]):
        col = f"rudder_{k}"
        if col in var:
            q[:, int(v.steering[k, 3])] = var[col]
    return v, name, t, q, np.column_stack([var["x"], var["y"]])


def render_run(run_dir: str | Path, out: str | Path, fps: int = 20, speed: float | None = None,
               run: str | None = None, width: int = 640, height: int = 360, max_seconds: float = 60.0) -> dict:
    """Render one run of RUN_DIR to ``out`` (.mp4 or .gif); ``speed`` = simulated seconds per video
    second (default: the whole run in at most ``max_seconds``). Returns what was written."""
    from vtrials.envs.render import ShipRenderer
    v, name, t, q, track = truth_frames(run_dir, run)
    out = Path(out)
    if out.suffix.lower() not in (".mp4", ".gif"):
        raise InputError(str(out), "--out", "the video file must end in .mp4 or .gif")
    T = float(t[-1] - t[0])
    speed = float(speed) if speed else max(1.0, T / max_seconds)
    times = np.arange(t[0], t[-1] + 1e-9, speed / fps)
    idx = np.minimum(np.searchsorted(t, times), t.size - 1)
    ren = ShipRenderer(v.model, width, height)
    frames = []
    try:
        for i in idx:
            frames.append(ren.frame(q[i], track[: i + 1], v.length))
    finally:
        ren.close()
    if out.suffix.lower() == ".gif":
        from PIL import Image
        imgs = [Image.fromarray(f) for f in frames]
        imgs[0].save(out, save_all=True, append_images=imgs[1:], duration=int(1000 / fps), loop=0)
    else:
        try:
            import imageio_ffmpeg
        except ImportError:
            raise InputError(str(out), "--out", "MP4 needs imageio-ffmpeg (pip install 'vtrials[render]'); "
                                                "or write a .gif") from None
        w = imageio_ffmpeg.write_frames(str(out), (width, height), fps=fps, macro_block_size=1)
        w.send(None)
        for f in frames:
            w.send(np.ascontiguousarray(f))
        w.close()
    return {"file": str(out), "run": name, "frames": len(frames), "speed": speed, "simulated_s": T}
