"""Ship motions of one run from a trial record: heave at the motion package, roll and pitch, on one time grid.

Inputs (records only): the IMU's body specific forces (ax, ay, az) at its surveyed site, the vertical
gyro's roll and pitch (interpolated to the IMU's samples; their clocks are taken as common — the
stated clock offsets, ~0.02 s, are far below the wave periods), the EM log's speed through the water
and the gyro compass's heading. Heave UP at the IMU's site by orientation-corrected FFT double
integration (:mod:`vtrials.reduce.heave`, high-pass at ``omega_c``) over the window, then every series
is low-pass filtered and decimated to ``fs_out`` (zero-phase FIR, scipy.signal.decimate) — ship motions
lie far below 1 rad/s.

The team's response model is the design-stage RAO model (:mod:`vtrials.reduce.design_rao`): its heave
is referred to the IMU's site by :meth:`~vtrials.reduce.design_rao.DesignRAO.vertical` (the surveyed
position is in the body frame of the ship's model files, origin O).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
from scipy import signal

from vtrials.errors import InputError
from vtrials.reduce.heave import heave_from_accelerometers, vertical_acceleration
from vtrials.units import G


@dataclasses.dataclass(frozen=True)
class RunMotions:
    """Motion series of one run on a uniform grid: time [s], heave UP at the IMU [m], roll, pitch [rad],
    vertical acceleration (earth down, at the IMU) [m/s²]; fs [Hz]; mean speed through the water U [m/s];
    mean heading [rad] (towards, from north); IMU site (x, y, z) [m] from O; heading_std [rad]: standard
    deviation of the (unwrapped) gyro heading over the window — a leg whose course was not held has no
    single relative wave direction (the wave reductions assume one)."""

    t: np.ndarray
    heave: np.ndarray
    roll: np.ndarray
    pitch: np.ndarray
    acc_down: np.ndarray
    fs: float
    U: float
    heading: float
    site: tuple
    heading_std: float = 0.0

    def series(self, names) -> np.ndarray:
        """(len(names), n) of 'heave', 'roll', 'pitch', 'acc'."""
        m = {"heave": self.heave, "roll": self.roll, "pitch": self.pitch, "acc": self.acc_down}
        bad = [n for n in names if n not in m]
        if bad:
            raise InputError("record", "components", f"{bad}: allowed heave, roll, pitch, acc")
        return np.array([m[n] for n in names])


def _window(t, t0, t1, what):
    k = (t >= t0) & (t <= t1)
    if np.count_nonzero(k) < 64:
        raise InputError("record", what, f"fewer than 64 samples in the window {t0:.1f}–{t1:.1f} s")
    return k


def run_motions(record, t0: float, t1: float, fs_out: float = 2.0, omega_c: float = 0.25,
                imu: str = "imu", attitude: str = "vertical_gyro", log: str = "em_log",
                compass: str = "gyro") -> RunMotions:
    """The motions of the run between t0 and t1 [s] (record clocks) from ``record`` (module doc)."""
    for name in (imu, attitude, log, compass):
        if name not in record.instruments:
            raise InputError(str(getattr(record, "path", "record")), name,
                             f"instrument not in the record (has {', '.join(record.instruments)})")
    ti, ax = record.channel(imu, "ax")
    ay = record.channel(imu, "ay")[1]
    az = record.channel(imu, "az")[1]
    k = _window(ti, t0, t1, imu)
    ti, ax, ay, az = ti[k], ax[k], ay[k], az[k]
    fs = 1.0 / float(np.median(np.diff(ti)))
    tg, roll = record.channel(attitude, "roll")
    pitch = record.channel(attitude, "pitch")[1]
    ok = np.isfinite(roll) & np.isfinite(pitch)
    roll_i = np.interp(ti, tg[ok], roll[ok])
    pitch_i = np.interp(ti, tg[ok], pitch[ok])
    good = np.isfinite(ax) & np.isfinite(ay) & np.isfinite(az)
    if not np.all(good):                               # dropouts: bridge by interpolation
        for arr in (ax, ay, az):
            arr[~good] = np.interp(ti[~good], ti[good], arr[good])
    heave = heave_from_accelerometers(ax, ay, az, roll_i, pitch_i, fs, omega_c)
    acc = vertical_acceleration(ax, ay, az, roll_i, pitch_i)
    q = max(int(round(fs / fs_out)), 1)

    def dec(x):
        return signal.decimate(np.asarray(x, dtype=float), q, ftype="fir", zero_phase=True) if q > 1 else x

    tl, spd = record.channel(log, "speed")
    kl = _window(tl, t0, t1, log) & np.isfinite(spd)
    th, hdg = record.channel(compass, "heading")
    kh = _window(th, t0, t1, compass) & np.isfinite(hdg)
    heading = math.atan2(float(np.mean(np.sin(hdg[kh]))), float(np.mean(np.cos(hdg[kh])))) % (2.0 * math.pi)
    heading_std = float(np.std(np.unwrap(hdg[kh])))
    site = tuple(float(v) for v in record.meta(imu).get("surveyed_position_m", (0.0, 0.0, 0.0)))
    acc_d = dec(acc)
    return RunMotions(ti[::q][:acc_d.size], dec(heave), dec(roll_i), dec(pitch_i), acc_d - np.mean(acc_d),
                      fs / q, float(np.mean(spd[kl])), heading, site, heading_std)


def run_windows(record, min_s: float = 120.0) -> list[tuple[int, float, float]]:
    """(run number, EXECUTE time, FINEX time) of every run in the record's event marks (or COMEX–FINEX)."""
    ev = record.events
    out = []
    for run in sorted(set(int(r) for r in ev["run"])):
        sel = [i for i in range(len(ev["run"])) if int(ev["run"][i]) == run]
        lab = {ev["label"][i]: float(ev["time"][i]) for i in sel}
        t0 = lab.get("EXECUTE", lab.get("COMEX"))
        t1 = lab.get("FINEX")
        if t0 is not None and t1 is not None and t1 - t0 >= min_s:
            out.append((run, t0, t1))
    return out


def design_responses(design, names, omega, mu, U: float, site, R=None) -> np.ndarray:
    """(len(names), …) complex design RAOs of 'heave' (UP at the IMU site), 'roll', 'pitch', 'acc'
    (earth-down acceleration at the site, −ω_e² × the downward displacement); ``R``: the design's
    (heave, roll, pitch) RAOs at (omega, mu, U) if already computed (or a part of them)."""
    R = design.rao(omega, mu, U) if R is None else R
    up = design.vertical(R, site[0], site[1])
    out = []
    for n in names:
        if n == "heave":
            out.append(up)
        elif n == "roll":
            out.append(R[1])
        elif n == "pitch":
            out.append(R[2])
        elif n == "acc":
            w = np.asarray(omega, dtype=float)
            we = w - w * w * U * np.cos(mu) / G
            out.append(we * we * up)                  # a_down = −ω_e² z_down = ω_e² × (UP displacement)
        else:
            raise InputError("record", "components", f"{n!r}: allowed heave, roll, pitch, acc")
    return np.array(out)
