"""The maneuver tasks: references, rewards (from the truth), terminations and the task's part of
the observation (from the measured channels only). Every function works on all ships at once.

Lengths are scaled by the ship length L, times by L/U₀ (U₀ the approach speed), so one task
definition fits KVLCC2 and patrol51 alike.

* CourseKeeping — hold a commanded heading ψ_ref: reward −(e/10°)² (clipped at −10) − 0.01 (δ/δ_max)².
  Option ``heading_integral`` (default off): one more feature, the time integral of the MEASURED
  heading error z = Σ clip(e_m, ±5°) Δt since the episode began, over (10° · L/U₀) — the controller
  state an autopilot's integral action keeps (instruments only), so that a policy can learn to hold
  the gyro heading with no steady offset. The clip bounds the wind-up during the course change.
* ZigZag — execute a δ_z/ψ_z zig-zag precisely (ITTC 7.5-04-02-01 / IMO MSC.137(76) procedure): the
  rudder order must follow the ideal order s·δ_z, where the ideal switching s flips when the TRUE heading
  change passes ±ψ_z; reward −((δ_o − s δ_z)/δ_z)²; ends after the 4th rudder reversal.
* Williamson — the Williamson turn (IMO MSC/Circ.1053 man-overboard turn): come to the reciprocal
  course back on the original track line; reward −|e_ψ|/π − 0.5 min(|e_ct|/L, 4); success (|e_ψ| < 5°,
  |e_ct| < 0.25 L) ends the episode with +20.
* Stopping — stop at a mark ahead on the track: reward −0.02 d/L per step, at rest (speed over ground
  < 5 % of U₀) the episode ends with +20 exp(−(d/L)²); overshooting by 3 L ends it with −20.
* TrackFollowing — follow a straight track from an offset start: reward −min(|e_ct|/L, 4) − 0.2 |e_ψ|/π.
"""

from __future__ import annotations

import math

import numpy as np

from vtrials.units import DEG

TASKS = ("CourseKeeping", "ZigZag", "Williamson", "Stopping", "TrackFollowing")


def wrap(a):
    """Angle to (−π, π]."""
    return np.mod(np.asarray(a) + math.pi, 2 * math.pi) - math.pi


class Task:
    """Per-ship task state for N ships; subclasses set the reference at reset and score each step."""

    name = ""
    duration_LU = 40.0  # episode length in L/U₀
    n_features = 0
    engine_action = False  # whether the agent works the telegraph by default
    orders = ("ahead_2_3", "standard", "full")  # approach orders drawn at reset

    def __init__(self, n: int, L: float, delta_max: float, options: dict | None = None):
        self.n, self.L, self.delta_max = n, L, delta_max
        self.opt = dict(options or {})
        self.psi0 = np.zeros(n)  # initial (track) course
        self.x0 = np.zeros(n)
        self.y0 = np.zeros(n)
        self.U0 = np.ones(n)
        self.T = np.ones(n)  # L/U₀
        self.done_flag = np.zeros(n, dtype=bool)

    def start(self, i: int, rng: np.random.Generator) -> dict:
        """The initial condition of ship i's episode: heading [rad] and offsets (north, east) [m]."""
        self.psi0[i] = rng.uniform(0.0, 2 * math.pi)
        return {"heading": self.psi0[i], "x": 0.0, "y": 0.0}

    def begin(self, i: int, U0: float, rng: np.random.Generator) -> None:
        self.U0[i] = max(U0, 0.1)
        self.T[i] = self.L / self.U0[i]
        self.done_flag[i] = False

    def track_errors(self, x, y, psi, idx):
        """Cross-track (starboard of the track +) and along-track distance [m] from the start line."""
        dx, dy = x - self.x0[idx], y - self.y0[idx]
        c, s = np.cos(self.psi0[idx]), np.sin(self.psi0[idx])
        return -s * dx + c * dy, c * dx + s * dy

    def features(self, meas: np.ndarray, idx: np.ndarray) -> np.ndarray:
        return np.zeros((idx.size, 0))

    def score(self, truth: dict, rud_order: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        raise NotImplementedError


class CourseKeeping(Task):
    name = "CourseKeeping"
    duration_LU = 40.0
    n_features = 3

    INTEGRAL_CLIP = 5 * DEG  # error clip of the heading-error integral (bounds the wind-up in a course change)

    def __init__(self, n, L, delta_max, options=None):
        super().__init__(n, L, delta_max, options)
        self.ref = np.zeros(n)
        self.integral = bool(self.opt.get("heading_integral", False))
        self.n_features = 4 if self.integral else 3
        self.period = 1.0  # control period [s]: set by the environment
        self.z = np.zeros(n)  # integral of the measured heading error [rad s]
        self.fresh = np.ones(n, dtype=bool)

    def begin(self, i, U0, rng):
        super().begin(i, U0, rng)
        step = float(self.opt.get("course_change_deg", 15.0)) * DEG
        self.ref[i] = self.psi0[i] + rng.uniform(-step, step)
        self.z[i] = 0.0
        self.fresh[i] = True

    def features(self, meas, idx):
        e = wrap(meas[:, 0] - self.ref[idx])
        f = [e / (10 * DEG), np.sin(self.ref[idx]), np.cos(self.ref[idx])]
        if self.integral:
            # first sample of an episode: nothing integrated yet
            self.z[idx] += np.where(self.fresh[idx], 0.0,
                                    np.clip(e, -self.INTEGRAL_CLIP, self.INTEGRAL_CLIP) * self.period)
            self.fresh[idx] = False
            f.append(self.z[idx] / (10 * DEG * self.T[idx]))
        return np.column_stack(f)

    def score(self, truth, rud_order):
        e = wrap(truth["psi"] - self.ref)
        r = -np.minimum((e / (10 * DEG)) ** 2, 10.0) - 0.01 * (rud_order / self.delta_max) ** 2
        return r, np.zeros(self.n, dtype=bool)


class ZigZag(Task):
    name = "ZigZag"
    duration_LU = 30.0
    n_features = 4

    def __init__(self, n, L, delta_max, options=None):
        super().__init__(n, L, delta_max, options)
        self.dz = float(self.opt.get("rudder_deg", 10.0)) * DEG
        self.pz = float(self.opt.get("heading_deg", 10.0)) * DEG
        self.side = np.ones(n)  # ideal order side from the true heading
        self.side_m = np.ones(n)  # the same logic on the gyro (what a helmsman can know)
        self.switches = np.zeros(n, dtype=np.int64)

    def begin(self, i, U0, rng):
        super().begin(i, U0, rng)
        self.side[i] = self.side_m[i] = 1.0
        self.switches[i] = 0

    @staticmethod
    def _flip(side, dpsi, pz):
        return np.where((side > 0) & (dpsi >= pz), -1.0, np.where((side < 0) & (dpsi <= -pz), 1.0, side))

    def features(self, meas, idx):
        d = wrap(meas[:, 0] - self.psi0[idx])
        self.side_m[idx] = self._flip(self.side_m[idx], d, self.pz)
        return np.column_stack([d / self.pz, self.side_m[idx], np.full(idx.size, self.dz / self.delta_max),
                                np.full(idx.size, self.pz / (10 * DEG))])

    def score(self, truth, rud_order):
        d = wrap(truth["psi"] - self.psi0)
        new = self._flip(self.side, d, self.pz)
        self.switches += (new != self.side)
        self.side = new
        r = -np.minimum(((rud_order - self.side * self.dz) / self.dz) ** 2, 10.0)
        return r, self.switches >= 4


class Williamson(Task):
    name = "Williamson"
    duration_LU = 40.0
    n_features = 4

    def features(self, meas, idx):
        ect, _ = self.track_errors(meas[:, 2], meas[:, 3], meas[:, 0], idx)
        e = wrap(meas[:, 0] - self.psi0[idx] - math.pi)
        return np.column_stack([np.sin(e), np.cos(e), ect / self.L, wrap(meas[:, 0] - self.psi0[idx]) / math.pi])

    def score(self, truth, rud_order):
        ect, _ = self.track_errors(truth["x"], truth["y"], truth["psi"], np.arange(self.n))
        e = wrap(truth["psi"] - self.psi0 - math.pi)
        ok = (np.abs(e) < 5 * DEG) & (np.abs(ect) < 0.25 * self.L)
        r = -np.abs(e) / math.pi - 0.5 * np.minimum(np.abs(ect) / self.L, 4.0) + 20.0 * ok
        return r, ok


class Stopping(Task):
    name = "Stopping"
    duration_LU = 40.0
    n_features = 3
    engine_action = True
    orders = ("standard", "full")

    def __init__(self, n, L, delta_max, options=None):
        super().__init__(n, L, delta_max, options)
        self.mark = np.zeros(n)
        lo, hi = self.opt.get("mark_L", (4.0, 8.0))
        self.mark_range = (float(lo), float(hi))
        self.k = np.zeros(n, dtype=np.int64)

    def begin(self, i, U0, rng):
        super().begin(i, U0, rng)
        self.mark[i] = rng.uniform(*self.mark_range) * self.L
        self.k[i] = 0

    def features(self, meas, idx):
        ect, along = self.track_errors(meas[:, 2], meas[:, 3], meas[:, 0], idx)
        return np.column_stack([(self.mark[idx] - along) / self.L, ect / self.L, meas[:, 4] / self.U0[idx]])

    def score(self, truth, rud_order):
        ect, along = self.track_errors(truth["x"], truth["y"], truth["psi"], np.arange(self.n))
        d = np.hypot(self.mark - along, ect) / self.L
        self.k += 1
        rest = (truth["sog"] < 0.05 * self.U0) & (self.k > 3)
        over = (along - self.mark) > 3.0 * self.L
        r = -0.02 * d + np.where(rest, 20.0 * np.exp(-d ** 2), 0.0) - np.where(over & ~rest, 20.0, 0.0)
        return r, rest | over


class TrackFollowing(Task):
    name = "TrackFollowing"
    duration_LU = 40.0
    n_features = 4

    def start(self, i, rng):
        psi_t = rng.uniform(0.0, 2 * math.pi)
        off = rng.uniform(-1.0, 1.0) * self.L
        self.psi0[i] = psi_t
        self.x0[i] = self.y0[i] = 0.0
        dpsi = rng.uniform(-20.0, 20.0) * DEG
        # start off the track (starboard + offset), on a heading off the track course
        return {"heading": psi_t + dpsi, "x": -math.sin(psi_t) * off, "y": math.cos(psi_t) * off}

    def features(self, meas, idx):
        ect, _ = self.track_errors(meas[:, 2], meas[:, 3], meas[:, 0], idx)
        e = wrap(meas[:, 0] - self.psi0[idx])
        return np.column_stack([ect / self.L, e / math.pi, np.sin(self.psi0[idx]), np.cos(self.psi0[idx])])

    def score(self, truth, rud_order):
        ect, _ = self.track_errors(truth["x"], truth["y"], truth["psi"], np.arange(self.n))
        e = wrap(truth["psi"] - self.psi0)
        r = -np.minimum(np.abs(ect) / self.L, 4.0) - 0.2 * np.abs(e) / math.pi
        return r, np.zeros(self.n, dtype=bool)


def make_task(name: str, n: int, L: float, delta_max: float, options: dict | None = None) -> Task:
    classes = {c.name: c for c in (CourseKeeping, ZigZag, Williamson, Stopping, TrackFollowing)}
    if name not in classes:
        from vtrials.errors import InputError
        raise InputError("environment", "task", f"{name!r} is not a task (allowed: {', '.join(TASKS)})")
    return classes[name](n, L, delta_max, options)
