"""Pictures of a ship in its sea through MuJoCo's own renderer (offscreen: EGL or OSMesa).

The ship's MJCF geometry at its simulated pose, a sea surface at the still waterline (a translucent
sheet), in waves the wave surface around the ship (tiles on the linear free surface η(x, y, t) of the
ship's own wave components, tilted to its slope, lighter at the crests), and the wake: the ship's track as a trail of markers
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
WAVE_TILES = (48, 96)  # wave-surface tiles per side, fewest and most (enough to reach 2 L around the ship)
TILES_PER_WAVELENGTH = 6  # tile size: the mean wavelength 2π/k̄ (k̄ energy-weighted) over this


def wave_surface(comp: np.ndarray, t: float, x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray,
                                                                                     np.ndarray]:
    """η [m] (up) and its slopes ∂η/∂x, ∂η/∂y at points (x north, y east) [m] and time t [s] for wave
    components (n, 6) [a, ω, k, cos μ, sin μ, ε]: η = Σ a cos(ω t − k(x cos μ + y sin μ) + ε)."""
    a, w, k, cm, sm, eps = (comp[:, j][:, None] for j in range(6))
    th = w * t - k * (cm * x.ravel()[None, :] + sm * y.ravel()[None, :]) + eps
    c, s_ = np.cos(th), np.sin(th)
    eta = (a * c).sum(axis=0)
    ex = (a * k * cm * s_).sum(axis=0)
    ey = (a * k * sm * s_).sum(axis=0)
    return eta.reshape(x.shape), ex.reshape(x.shape), ey.reshape(x.shape)


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
        self.scene = mujoco.MjvScene(model, maxgeom=2000 + WAVE_TILES[1] ** 2)
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
              elevation_deg: float = 28.0, waves: tuple[np.ndarray, float] | None = None) -> np.ndarray:
        """One RGB frame (height, width, 3) of the ship at ``qpos`` with its ``track`` (K, 2: north,
        east) as the wake; the camera looks from astern-quarter at ``distance`` (3 L). ``waves``:
        (wave components (n, 6), time [s]) to draw the wave surface."""
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
        # the sea: a translucent sheet at the still waterline (in waves below the troughs, with the
        # wave surface drawn over it around the ship)
        if waves is not None and len(waves[0]) and np.any(waves[0][:, 0] > 0.0):
            sigma = self._add_waves(waves[0], float(waves[1]), x, y, L)
            self._add(mujoco.mjtGeom.mjGEOM_BOX, (40 * L, 40 * L, 0.002 * L), (x, y, 3.0 * sigma), SEA_RGBA)
        else:
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

    def _add_waves(self, comp: np.ndarray, t: float, x0: float, y0: float, L: float) -> float:
        """Tiles of the wave surface around (x0, y0); returns the RMS elevation of the sea [m]."""
        e = comp[:, 0] ** 2
        k_mean = float(np.sum(e * comp[:, 2]) / np.sum(e))
        h = 2.0 * math.pi / k_mean / TILES_PER_WAVELENGTH
        n = int(min(WAVE_TILES[1], max(WAVE_TILES[0], math.ceil(4.0 * L / h))))
        g = (np.arange(n) - (n - 1) / 2.0) * h
        X, Y = np.meshgrid(x0 + g, y0 + g, indexing="ij")
        eta, ex, ey = wave_surface(comp, t, X, Y)
        sigma = float(np.sqrt(0.5 * np.sum(comp[:, 0] ** 2)))
        for i in range(n):
            for j in range(n):
                # surface (x, y, −η) in north-east-down: tangents (1, 0, −η_x), (0, 1, −η_y)
                tx = np.array([1.0, 0.0, -ex[i, j]])
                ty = np.array([0.0, 1.0, -ey[i, j]])
                tx /= np.linalg.norm(tx)
                nz = np.cross(tx, ty)
                nz /= np.linalg.norm(nz)
                mat = np.column_stack([tx, np.cross(nz, tx), nz])
                lift = float(np.clip(eta[i, j] / (3.0 * sigma), -1.0, 1.0)) if sigma > 0.0 else 0.0
                # crests towards white, troughs darker
                rgba = tuple(c + (1.0 - c) * 0.6 * lift if lift > 0.0 else c * (1.0 + 0.5 * lift)
                             for c in SEA_RGBA[:3]) + (1.0,)
                self._add(mujoco.mjtGeom.mjGEOM_BOX, (0.52 * h, 0.52 * h, 0.01 * h), (X[i, j], Y[i, j], -eta[i, j]),
                          rgba, mat)
        return sigma

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
