"""Pictures of a ship in its sea through MuJoCo's own renderer (offscreen: EGL or OSMesa).

The ship's MJCF geometry at its simulated pose, a sea surface at the still waterline (a translucent
sheet; a wave surface once the sea has waves), and the wake: the ship's track as a trail of markers
fading with age. The world is north-east-down (z down), so the free camera looks down from
negative z; MuJoCo's image is then upside down and is turned half a turn.

Offscreen context: ``MUJOCO_GL`` if set (egl, osmesa, glfw), else glfw when a display exists, else EGL,
then OSMesa (README: install steps). The context is created here, so it works whenever mujoco was
imported.
"""

from __future__ import annotations

import copy
import math
import os

import mujoco
import numpy as np

SEA_RGBA = (0.16, 0.40, 0.62, 0.8)
WAKE_RGBA = (0.95, 0.97, 1.0, 0.9)
MAX_WAKE = 240  # markers drawn (the track is thinned to at most this many)


def _gl_context(width: int, height: int):
    want = os.environ.get("MUJOCO_GL", "").lower()
    order = [want] if want else (["glfw"] if os.environ.get("DISPLAY") else []) + ["egl", "osmesa"]
    errors = []
    for name in order:
        try:
            if name == "egl":
                from mujoco.egl import GLContext
            elif name == "osmesa":
                from mujoco.osmesa import GLContext
            else:
                from mujoco.glfw import GLContext
            ctx = GLContext(width, height)
            ctx.make_current()
            return ctx
        except Exception as exc:  # noqa: BLE001 — try the next backend, report all if none works
            errors.append(f"{name}: {exc}")
    raise RuntimeError("no OpenGL context for offscreen rendering (" + "; ".join(errors) +
                       "); install EGL (apt-get install -y libegl-mesa0 libegl1) or OSMesa "
                       "(apt-get install -y libosmesa6) and set MUJOCO_GL=egl or osmesa")


class ShipRenderer:
    """Renders frames of one ship model (``width`` × ``height`` RGB)."""

    def __init__(self, model: mujoco.MjModel, width: int = 480, height: int = 320):
        self.model = model = copy.copy(model)  # own copy: the visual settings below stay here
        self.width, self.height = int(width), int(height)
        self.model.vis.global_.offwidth = max(self.model.vis.global_.offwidth, self.width)
        self.model.vis.global_.offheight = max(self.model.vis.global_.offheight, self.height)
        hl = self.model.vis.headlight
        hl.ambient[:] = (0.45, 0.45, 0.45)
        hl.diffuse[:] = (0.65, 0.65, 0.65)
        self.data = mujoco.MjData(model)
        self._gl = _gl_context(self.width, self.height)
        self.scene = mujoco.MjvScene(model, maxgeom=2000)
        self.con = mujoco.MjrContext(model, mujoco.mjtFontScale.mjFONTSCALE_150)
        mujoco.mjr_setBuffer(mujoco.mjtFramebuffer.mjFB_OFFSCREEN, self.con)
        self.cam = mujoco.MjvCamera()
        self.cam.type = mujoco.mjtCamera.mjCAMERA_FREE
        self.opt = mujoco.MjvOption()
        self.pert = mujoco.MjvPerturb()
        self.rect = mujoco.MjrRect(0, 0, self.width, self.height)
        self._window = None

    def _add(self, gtype, size, pos, rgba, mat=None):
        s = self.scene
        if s.ngeom >= s.maxgeom:
            return
        g = s.geoms[s.ngeom]
        mujoco.mjv_initGeom(g, gtype, np.asarray(size, float), np.asarray(pos, float),
                            np.eye(3).ravel() if mat is None else np.asarray(mat, float).ravel(),
                            np.asarray(rgba, np.float32))
        s.ngeom += 1

    def frame(self, qpos: np.ndarray, track: np.ndarray | None = None, length: float | None = None,
              distance: float | None = None, azimuth_deg: float | None = None,
              elevation_deg: float = 28.0) -> np.ndarray:
        """One RGB frame (height, width, 3) of the ship at ``qpos`` with its ``track`` (K, 2: north,
        east) as the wake; the camera looks from astern-quarter at ``distance`` (3 L)."""
        self._gl.make_current()
        m, d = self.model, self.data
        d.qpos[:] = qpos
        mujoco.mj_kinematics(m, d)
        mujoco.mj_camlight(m, d)
        L = float(length) if length else 50.0
        x, y = float(qpos[0]), float(qpos[1])
        qw, qx, qy, qz = qpos[3:7]
        psi = math.atan2(2 * (qw * qz + qx * qy), 1 - 2 * (qy * qy + qz * qz))
        self.cam.lookat[:] = (x, y, 0.0)
        self.cam.distance = distance or 3.0 * L
        # azimuth about +z (down): from astern, off the port quarter
        self.cam.azimuth = math.degrees(psi) + 30.0 if azimuth_deg is None else azimuth_deg
        self.cam.elevation = elevation_deg  # +: camera above the water (z down)
        mujoco.mjv_updateScene(m, d, self.opt, self.pert, self.cam, mujoco.mjtCatBit.mjCAT_ALL, self.scene)
        # the sea: a translucent sheet at the still waterline
        self._add(mujoco.mjtGeom.mjGEOM_BOX, (40 * L, 40 * L, 0.002 * L), (x, y, 0.004 * L), SEA_RGBA)
        if track is not None and len(track):
            tr = np.asarray(track, float)
            step = max(1, int(math.ceil(len(tr) / MAX_WAKE)))
            tr = tr[::-1][::step][::-1]
            k = len(tr)
            for j, (n_, e_) in enumerate(tr):
                age = (k - 1 - j) / max(k - 1, 1)
                r = L * (0.04 + 0.08 * age)
                rgba = (*WAKE_RGBA[:3], WAKE_RGBA[3] * (1.0 - 0.8 * age))
                self._add(mujoco.mjtGeom.mjGEOM_ELLIPSOID, (r, r, 0.01 * L), (n_, e_, -0.002 * L), rgba)
        mujoco.mjr_render(self.rect, self.scene, self.con)
        rgb = np.empty((self.height, self.width, 3), dtype=np.uint8)
        mujoco.mjr_readPixels(rgb, None, self.rect, self.con)
        # OpenGL rows run bottom-up; z down turns the camera's up vector over: half a turn in all
        return np.ascontiguousarray(rgb[:, ::-1])

    def show(self, img: np.ndarray) -> None:
        """Show a frame in a window (render_mode="human"; matplotlib)."""
        import matplotlib.pyplot as plt
        if self._window is None:
            plt.ion()
            fig, ax = plt.subplots()
            ax.axis("off")
            self._window = ax.imshow(img)
        else:
            self._window.set_data(img)
        plt.pause(0.001)

    def close(self) -> None:
        if self._gl is not None:
            self.con.free()
            self._gl.free()
            self._gl = None
