"""What an agent sees: the ship's instruments at the control instants, vectorised over ships.

A per-ship :class:`~vtrials.instruments.suite.InstrumentSet` streams every truth row through each
device (~0.4 ms per device call); at 256 ships that would cost more than the physics. This module
samples the same catalogue error parts at the control instants only, for all ships at once:

    reading = Q( m·(1 + s) + b + e_GM + w ),   Q = rounding to the resolution

with the scale-factor error s and the bias b drawn once per episode, the first-order Gauss–Markov
error e_GM propagated exactly between control instants (e_{k+1} = a e_k + σ√(1−a²) w, a = exp(−Δ/τ);
the same discretisation as :class:`vtrials.instruments.parts.GaussMarkov`) and white noise w per
sample. GNSS drops a fix with the catalogue's probability (the previous fix is held); its position
also carries the catalogue's multipath (a second Gauss–Markov error, drawn after the others so the
other channels' draws are unchanged) and its latency (the fix describes the antenna L seconds earlier:
position − L·velocity). The part
values are read from the ship's own suite (catalogue + ``models/<ship>/instruments.toml``) through
an InstrumentSet, so overrides there apply here too. The gyrocompass adds its speed error less its
corrector's (settings drawn per episode; :mod:`vtrials.instruments.sensor_errors`). Left out: the
devices' sampling clocks, the gyrocompass latency (0.1 s; below one control period) and its ballistic
transients (84-min loop; an episode starts settled), GNSS outages (lost fraction ~0.2 %), lever-arm
terms other than the yaw rate's.

Each ship draws from its own Generator (seeded per episode), with the episode's white noise drawn
up front, so a ship's observations do not depend on how many ships run together.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from vtrials.instruments import sensor_errors as SE
from vtrials.units import DEG

# channel order of the measured arrays
CHANNELS = ("heading", "yaw_rate", "north", "east", "sog", "log_speed", "rudder", "shaft_rps")
# instruments they come from (device kind in the suite)
SOURCES = {"heading": "heading", "yaw_rate": "imu", "north": "gnss", "east": "gnss", "sog": "gnss",
           "log_speed": "em_log", "rudder": "rudder", "shaft_rps": "shaft_rpm"}


@dataclasses.dataclass(frozen=True)
class ErrorParts:
    """Error parts of one channel, SI (scale dimensionless)."""

    scale_mean: float = 0.0
    scale_sd: float = 0.0
    bias_mean: float = 0.0
    bias_sd: float = 0.0
    gm_sd: float = 0.0
    gm_tau: float = 1.0
    noise: float = 0.0
    resolution: float = 0.0
    dropout_p: float = 0.0
    # gyrocompass speed error (heading channel): site latitude [rad], corrector speed range [m/s] and
    # the corrector latitude's error (mean, sd) [rad]; north_seeking False: none
    north_seeking: bool = False
    latitude: float = 0.0
    corrector_lo: float = 0.0
    corrector_hi: float = 0.0
    corrector_lat_mean: float = 0.0
    corrector_lat_sd: float = 0.0
    gm2_sd: float = 0.0       # a second Gauss–Markov error (GNSS multipath)
    gm2_tau: float = 1.0
    latency: float = 0.0      # [s] the reading describes the measurand this long before its time


def _dist(spec: dict, key: str, f: float = 1.0) -> tuple[float, float]:
    d = spec.get(key)
    if d is None:
        return 0.0, 0.0
    if isinstance(d, dict):
        return float(d.get("mean", 0.0)) * f, float(d.get("sd", 0.0)) * f
    return float(d) * f, 0.0


def _parts(spec: dict, f: float) -> ErrorParts:
    sm, ss = _dist(spec, "scale")
    bm, bs = _dist(spec, "bias", f)
    gm = spec.get("gauss_markov") or {"sd": 0.0, "tau_s": 1.0}
    return ErrorParts(sm, ss, bm, bs, float(gm["sd"]) * f, float(gm["tau_s"]), float(spec.get("noise", 0.0)) * f,
                      float(spec.get("resolution", 0.0)) * f, float(spec.get("dropout_p", 0.0)))


def default_site() -> dict:
    """The trial site of a scenario that states none (vtrials.scenario's defaults)."""
    from vtrials.scenario import DEFAULT_HYDROPHONES, DEFAULT_TRANSPONDERS, Site
    s = Site()
    return {"transponders": DEFAULT_TRANSPONDERS, "hydrophones": DEFAULT_HYDROPHONES,
            "transponder_side": s.transponder_side, "hydrophone_side": s.hydrophone_side,
            "latitude_deg": s.latitude_deg, "range_center": [s.range_center_north_m, s.range_center_east_m],
            "water_depth_m": 1.0e4}


def suite_parts(vessel) -> tuple[dict[str, ErrorParts], dict[str, np.ndarray], dict[str, str], dict[str, int]]:
    """The error parts of each channel, the sensor sites (hull frame, m), the device names and the
    rudder / propeller index the rudder synchro and the shaft counter read, from the ship's
    instrument suite (first device of each kind in name order)."""
    from vtrials.instruments.suite import InstrumentSet
    iset = InstrumentSet(vessel, 0, default_site())
    dev = {}
    for ch, kind in SOURCES.items():
        names = iset.of_kind(kind)
        if not names:
            raise ValueError(f"ship {vessel.name!r} carries no {kind} instrument (needed for {ch!r})")
        dev[ch] = names[0]
    parts, sites = {}, {}
    for ch, name in dev.items():
        d = iset.devices[name]
        s = d.spec
        sites[ch] = np.asarray(d.site, dtype=float)
        if ch == "yaw_rate":  # the IMU's rate gyros
            dph = DEG / 3600.0
            bm, bs = _dist(s, "gyro_bias_dph", dph)
            gm = s.get("gyro_gauss_markov_dph", {"sd": 0.0, "tau_s": 100.0})
            sc = s.get("gyro_scale", {"mean": 0.0, "sd": 0.0})
            parts[ch] = ErrorParts(float(sc["mean"]), float(sc["sd"]), bm, bs, float(gm["sd"]) * dph,
                                   float(gm["tau_s"]), float(s.get("gyro_noise_dps", 0.0)) * DEG, 0.0, 0.0)
        elif ch in ("north", "east", "sog"):
            base = _parts(s, d.f)
            if ch == "sog":  # velocity noise on each of v_N, v_E (no slow error)
                parts[ch] = ErrorParts(noise=float(s.get("velocity_noise_mps", 0.0)), dropout_p=base.dropout_p)
            else:
                mp = s.get("multipath") or {"sd": 0.0, "tau_s": 1.0}
                parts[ch] = dataclasses.replace(base, gm2_sd=float(mp["sd"]) * d.f, gm2_tau=float(mp["tau_s"]),
                                                latency=float(s.get("latency_s", 0.0)))
        elif ch == "heading" and getattr(d, "north_seeking", False):
            lm, ls = _dist(s, "corrector_latitude_error_deg", DEG)
            parts[ch] = dataclasses.replace(_parts(s, d.f), north_seeking=True, latitude=d.lat, corrector_lo=d.cs_lo,
                                            corrector_hi=d.cs_hi, corrector_lat_mean=lm, corrector_lat_sd=ls)
        else:
            parts[ch] = _parts(s, d.f)
    index = {"rudder": int(iset.devices[dev["rudder"]].index),
             "shaft_rps": int(iset.devices[dev["shaft_rps"]].index)}
    return parts, sites, dev, index


class ObservationModel:
    """Measured channels of N ships at control instants ``period`` apart (episodes ≤ ``horizon`` samples)."""

    def __init__(self, parts: dict[str, ErrorParts], sites: dict[str, np.ndarray], n: int, period: float,
                 horizon: int):
        self.parts = parts
        self.sites = sites
        self.n = int(n)
        self.period = float(period)
        self.horizon = int(horizon) + 1
        C = len(CHANNELS)
        P = [parts[c] for c in CHANNELS]
        self.res = np.array([p.resolution for p in P])
        self.noise = np.array([p.noise for p in P])
        self.gm_sd = np.array([p.gm_sd for p in P])
        self.a = np.array([math.exp(-self.period / p.gm_tau) for p in P])
        self.b = self.gm_sd * np.sqrt(1.0 - self.a ** 2)
        self.drop_p = parts["north"].dropout_p
        self.gm2_sd = np.array([p.gm2_sd for p in P])
        self.a2 = np.array([math.exp(-self.period / p.gm2_tau) for p in P])
        self.b2 = self.gm2_sd * np.sqrt(1.0 - self.a2 ** 2)
        self.latency = parts["north"].latency
        self.gm2 = np.zeros((n, C))
        self.w2 = np.zeros((n, self.horizon, C))
        self.scale = np.zeros((n, C))
        self.bias = np.zeros((n, C))
        self.gm = np.zeros((n, C))
        # white noise of the episode: (ship, sample, channel) for w, GM innovations, sog's second axis
        self.w = np.zeros((n, self.horizon, C + C + 1))
        self.drop = np.zeros((n, self.horizon), dtype=bool)
        self.k = np.zeros(n, dtype=np.int64)
        self.last = np.zeros((n, C))
        self.gyro = parts["heading"]
        self.corr_speed = np.zeros(n)
        self.corr_lat = np.full(n, self.gyro.latitude)

    def reset(self, ship: int, rng: np.random.Generator) -> None:
        """New instrument draws for ship ``ship`` (its episode's whole noise sequence)."""
        C = len(CHANNELS)
        P = [self.parts[c] for c in CHANNELS]
        self.scale[ship] = [p.scale_mean + p.scale_sd * rng.standard_normal() for p in P]
        self.bias[ship] = [p.bias_mean + p.bias_sd * rng.standard_normal() for p in P]
        self.gm[ship] = self.gm_sd * rng.standard_normal(C)  # stationary start
        self.w[ship] = rng.standard_normal((self.horizon, 2 * C + 1))
        self.drop[ship] = rng.random(self.horizon) < self.drop_p
        self.drop[ship, 0] = False
        self.gm2[ship] = self.gm2_sd * rng.standard_normal(C)  # drawn last: the draws above are unchanged
        self.w2[ship] = rng.standard_normal((self.horizon, C))
        self.k[ship] = 0
        g = self.gyro
        if g.north_seeking:  # drawn last: the other parts keep their draws
            self.corr_speed[ship] = float(rng.uniform(g.corrector_lo, g.corrector_hi)) if g.corrector_hi > 0 else 0.0
            self.corr_lat[ship] = float(np.clip(g.latitude + g.corrector_lat_mean + g.corrector_lat_sd
                                                * rng.standard_normal(), -80 * DEG, 80 * DEG))

    def sample(self, truth: dict, idx: np.ndarray | None = None) -> np.ndarray:
        """Readings (len(idx), channels) of ships ``idx`` (default all) from their truth arrays
        (len(idx),) at this control instant; advances those ships' sample counters."""
        C = len(CHANNELS)
        idx = np.arange(self.n) if idx is None else np.asarray(idx, dtype=np.int64)
        # all ships (every control step): views of the per-ship arrays rather than gathered copies
        rows = slice(None) if idx.size == self.n and np.array_equal(idx, np.arange(self.n)) else idx
        kk = self.k[rows]
        k = np.minimum(kk, self.horizon - 1)
        w = self.w[idx, k]  # (n, 2C+1)
        started = (kk > 0)[:, None]
        gm = np.where(started, self.a * self.gm[rows] + self.b * w[:, C:2 * C], self.gm[rows])
        self.gm[rows] = gm
        gm2 = np.where(started, self.a2 * self.gm2[rows] + self.b2 * self.w2[idx, k], self.gm2[rows])
        self.gm2[rows] = gm2
        psi, r = truth["psi"], truth["r"]
        c, s = np.cos(psi), np.sin(psi)
        # sensor positions and velocities (rigid-body yaw lever arms)
        xg, yg = self.sites["north"][0], self.sites["north"][1]
        vn = truth["vn"] - r * (s * xg + c * yg)
        ve = truth["ve"] + r * (c * xg - s * yg)
        m = np.empty((idx.size, C))
        m[:, 0] = psi
        if self.gyro.north_seeking:  # speed error less the corrector's (reading − true)
            m[:, 0] += SE.speed_error(truth["vn"], self.gyro.latitude) - np.where(
                self.corr_speed[rows] > 0,
                np.arcsin(np.clip(self.corr_speed[rows] * c / (SE.EARTH_RADIUS * SE.EARTH_RATE
                                                               * np.cos(self.corr_lat[rows])), -1.0, 1.0)), 0.0)
        m[:, 1] = r
        m[:, 2] = truth["x"] + c * xg - s * yg - self.latency * vn
        m[:, 3] = truth["y"] + s * xg + c * yg - self.latency * ve
        m[:, 4] = 0.0
        m[:, 5] = truth["u_r"] - r * self.sites["log_speed"][1]
        m[:, 6] = truth["rudder"]
        m[:, 7] = truth["shaft_rps"]
        y = m * (1.0 + self.scale[rows]) + self.bias[rows] + gm + gm2 + self.noise * w[:, :C]
        sv = self.noise[4]
        y[:, 4] = np.hypot(vn + sv * w[:, 4], ve + sv * w[:, 2 * C])
        nz = self.res > 0
        y[:, nz] = np.round(y[:, nz] / self.res[nz]) * self.res[nz]
        y[:, 0] = np.mod(y[:, 0], 2 * math.pi)
        y[:, 5] = np.maximum(y[:, 5], 0.0)  # the EM log shows zero astern
        drop = self.drop[idx, k] & (kk > 0)
        if np.any(drop):
            y[drop, 2:5] = self.last[idx[drop], 2:5]
        self.last[rows] = y
        self.k[rows] = kk + 1
        return y
