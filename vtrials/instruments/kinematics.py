"""What a sensor at a site on the hull would see, computed from the true state (numpy, vectorized).

Rigid-body kinematics with the truth's body-frame quantities (origin O at midship waterline,
axes x forward, y starboard, z down; world north-east-down):
  position of site S:   p_S = p_O + R r_S
  velocity of S:        v_S = ν₁ + ω × r_S                      (body axes; over ground or through water)
  acceleration of S:    a_S = ν̇₁ + ω × ν₁ + ω̇ × r_S + ω × (ω × r_S)   (body axes, inertial)
  specific force:       f_S = a_S − Rᵀ g,  g = (0, 0, g) in NED    (what an accelerometer reads)
These are the same relations MuJoCo's site sensors use; computing them from the recorded truth lets
instruments run on their own clocks after (or alongside) the simulation.

One instant per row. A truth row is MuJoCo's state between steps of its semi-implicit Euler integrator:
x_{n+1} = x_n + h v_{n+1}, so the pose and the accelerations belong to the row's time t_n and the
velocities to the step just taken, t_n − h/2 (the position chords confirm it to 1e-9 m/s,
tests/test_truth_instant.py). A sensor reads all of them at t_n: with the step h (truth
column ``step_s``, which the drivers write) the velocities are carried half a step forward with the
row's own accelerations, ν(t_n) = ν + (h/2)(ν̇ + ω × ν) (the world-frame velocity's midpoint, in body
axes) and ω(t_n) = ω + (h/2) ω̇. Left uncorrected, the half step put the rate gyros 10 ms late
against the heading and the fixes and the accelerometers' centripetal term likewise (at dt 0.02 s),
which biased patrol51's identified Y_ur by +3.6 % (issue 16). Columns without ``step_s`` (an analytic
or continuous solution) are taken as they are.
"""

from __future__ import annotations

import numpy as np

from vtrials.physics.environment.wind import TRIALS_PROFILE_EXPONENT, Z_REF_10
from vtrials.units import G


def rotation_matrices(qw, qx, qy, qz) -> np.ndarray:
    """(n, 3, 3) body→world rotation matrices from quaternion columns."""
    n = np.sqrt(qw * qw + qx * qx + qy * qy + qz * qz)
    w, x, y, z = qw / n, qx / n, qy / n, qz / n
    R = np.empty((len(w), 3, 3))
    R[:, 0, 0] = 1 - 2 * (y * y + z * z)
    R[:, 0, 1] = 2 * (x * y - w * z)
    R[:, 0, 2] = 2 * (x * z + w * y)
    R[:, 1, 0] = 2 * (x * y + w * z)
    R[:, 1, 1] = 1 - 2 * (x * x + z * z)
    R[:, 1, 2] = 2 * (y * z - w * x)
    R[:, 2, 0] = 2 * (x * z - w * y)
    R[:, 2, 1] = 2 * (y * z + w * x)
    R[:, 2, 2] = 1 - 2 * (x * x + y * y)
    return R


def _stack(cols: dict, names) -> np.ndarray:
    return np.column_stack([cols[n] for n in names])


class SiteKinematics:
    """Measurands at a hull site for a chunk of truth columns (dict of equal-length arrays), all at
    the rows' instants (velocities carried half an integrator step forward, see the module text)."""

    def __init__(self, cols: dict, site: np.ndarray):
        self.c = cols
        self.r = np.asarray(site, dtype=float)
        self.t = cols["t"]
        self._R = None
        self._cache = {}

    def _half_step(self):
        """(n, 1) half the integrator step of each row [s], or None (columns already at one instant)."""
        h = self.c.get("step_s")
        return None if h is None else 0.5 * np.asarray(h, float).reshape(-1, 1)

    def _centred(self, names):
        if names not in self._cache:
            v = _stack(self.c, names)
            h = self._half_step()
            if h is not None:
                om = _stack(self.c, ("p", "q", "r"))
                nu = _stack(self.c, ("u", "v", "w"))
                # the world-frame velocity's change over half a step, in body axes; a current steady
                # over the step changes the velocity through the water by the same
                v = v + h * (_stack(self.c, ("du", "dv", "dw")) + np.cross(om, nu))
            self._cache[names] = v
        return self._cache[names]

    @property
    def R(self) -> np.ndarray:
        if self._R is None:
            self._R = rotation_matrices(self.c["qw"], self.c["qx"], self.c["qy"], self.c["qz"])
        return self._R

    @property
    def omega(self) -> np.ndarray:
        """(n, 3) body angular velocity at the rows' instants [rad/s]."""
        if "omega" not in self._cache:
            om = _stack(self.c, ("p", "q", "r"))
            h = self._half_step()
            self._cache["omega"] = om if h is None else om + h * _stack(self.c, ("dp", "dq", "dr"))
        return self._cache["omega"]

    @property
    def nu(self) -> np.ndarray:
        """(n, 3) body velocity of the origin over ground at the rows' instants [m/s]."""
        return self._centred(("u", "v", "w"))

    @property
    def nu_r(self) -> np.ndarray:
        """(n, 3) body velocity of the origin through the water at the rows' instants [m/s]."""
        return self._centred(("u_r", "v_r", "w_r"))

    def position(self) -> np.ndarray:
        """(n, 3) north, east, down of the site [m]."""
        return _stack(self.c, ("x", "y", "z")) + self.R @ self.r

    def velocity_body(self, through_water: bool = False) -> np.ndarray:
        """(n, 3) velocity of the site in body axes [m/s], over ground or through the water."""
        v = self.nu_r if through_water else self.nu
        return v + np.cross(self.omega, self.r)

    def velocity_world(self) -> np.ndarray:
        """(n, 3) velocity of the site over ground, north-east-down [m/s]."""
        return np.einsum("nij,nj->ni", self.R, self.velocity_body(False))

    def specific_force(self) -> np.ndarray:
        """(n, 3) specific force at the site in body axes [m/s²] (accelerometer truth)."""
        om = self.omega
        a = (_stack(self.c, ("du", "dv", "dw")) + np.cross(om, self.nu)
             + np.cross(_stack(self.c, ("dp", "dq", "dr")), self.r) + np.cross(om, np.cross(om, self.r)))
        g_body = G * self.R[:, 2, :]  # Rᵀ (0, 0, g): third row of R
        return a - g_body

    def apparent_wind(self, exponent: float = TRIALS_PROFILE_EXPONENT,
                      z_ref: float = Z_REF_10) -> tuple[np.ndarray, np.ndarray]:
        """Apparent wind at the site: (speed [m/s], angle it comes from off the bow [rad], + starboard).

        True wind from the truth record (speed at the wind-load reference height ``z_ref`` [m],
        direction it blows from) scaled to the site's height above the waterline by the power-law
        profile U(h) = U(z_ref) (h/z_ref)^exponent, minus the site's own velocity over ground (ship
        motion, including the lever arm of the mast: the motion-induced velocity); horizontal
        components in the ship's level frame. ``exponent`` and ``z_ref`` must be the simulated
        wind's own (:class:`vtrials.physics.environment.wind.Wind` ``profile_exponent``,
        ``reference_height_m``; defaults: its defaults, 1/9 and 10 m), or the anemometer reads a
        wind the ship does not feel.
        """
        c = self.c
        h = max(-self.position()[:, 2].mean(), 0.5)
        Uref = c["wind_speed"]
        U = Uref * (h / z_ref) ** exponent if np.any(Uref) else Uref
        d = c["wind_direction"]
        # wind velocity (towards) in world axes
        wn = -U * np.cos(d)
        we = -U * np.sin(d)
        vs = self.velocity_world()
        rel_n = wn - vs[:, 0]
        rel_e = we - vs[:, 1]
        psi = c["heading"]
        # air velocity relative to the ship, in heading-aligned level axes
        ax = rel_n * np.cos(psi) + rel_e * np.sin(psi)
        ay = -rel_n * np.sin(psi) + rel_e * np.cos(psi)
        speed = np.hypot(ax, ay)
        angle = np.arctan2(-ay, -ax)  # the direction it comes FROM, off the bow
        return speed, angle
