"""A maneuver record turned into what the identification needs: smoothed planar states and
accelerations at the ship's reference point, with the recorded rudder angle and shaft speed.

Reads records only (instrument channels, their stated errors, the director's sheet), never truth.

* Time stamps: each instrument's stated latency removed (data sheet, record meta ``latency_s``).
* Attitude: roll and pitch integrated from the motion package's rates by the Euler-angle kinematics
  (Titterton & Weston 2004, "Strapdown Inertial Navigation Technology", eq. 3.48), started from the
  accelerometers' gravity direction over the first seconds of the steady approach.
* Specific force moved from the motion package to the reference point (midship, waterline: the origin
  of the surveyed positions) by a_ref = a − ω̇×l − ω×(ω×l), then levelled into the heading frame
  (x along the heading, horizontal): gravity drops out, so the planar filter integrates accelerations.
  The heading rate ψ̇ = (q sin φ + r cos φ)/cos θ is the filter's gyro input.
* Aiding: tracking fixes of the antenna (its surveyed height's horizontal displacement with heel and
  trim removed; the horizontal lever arm left to the filter), gyro heading; σ from the stated
  accuracies (white part ⊕ correlated parts, since the filter treats them as white).
* The filter's bias random walks cover what the levelling leaves: an unknown roll-gyro bias b tilts
  the levelled frame by b·t, i.e. a specific-force error g b t, matched over the record by a random
  walk of density g σ_b √T.
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
from scipy.signal import butter, filtfilt, savgol_filter

from vtrials.errors import InputError
from vtrials.records.netcdf import Record
from vtrials.reduce.maneuvering import instruments_by_kind
from vtrials.sysid import navfilter as NF
from vtrials.sysid import regression as RG

_WHERE = "vtrials.sysid.records"
G = 9.80665
_SETTLE_S = 3.0   # first seconds of the approach used to find the level (ship steady)
#: White yaw-jerk density of the filter's process model, (rad/s³)² s. A tuning, measured on the shipped
#: agenda against truth (tests/test_identify_records.py): 1e-4 follows the gyro noise into r and ṙ and
#: biases N'_v, N'_r by +1.6 %, +2.3 % (noisy regressors attenuate their coefficients); 1e-5 halves that.
JERK_PSD = 1e-5
#: Window of the roll acceleration's local-cubic derivative, s: a tenth of patrol51's 5.6 s roll period
#: keeps the roll's own swing (the cubic's bias at that window is under 1 %).
ROLL_WINDOW_S = 0.55
#: Time constant of the complementary filter between the integrated rates and a vertical reference, s:
#: the integral's drift over it (≈ 4e-4 rad) and the reference's noise averaged over it (0.03°/√(10 Hz × τ))
#: are both below the reference's resolution.
VERTICAL_TAU_S = 10.0


@dataclasses.dataclass(frozen=True)
class ManeuverRecord:
    """One maneuver's inputs for the navigation filter and the identification (SI)."""

    path: str
    name: str
    kind: str
    ordered: dict          # the director's sheet: the maneuver as ordered (degrees at this edge)
    ship: str
    t: np.ndarray          # IMU instants (latency removed)
    f: np.ndarray          # (N, 2) levelled specific force at the reference point, heading frame
    psi_rate: np.ndarray   # (N,) heading rate from the rate gyros
    roll: np.ndarray       # (N,) integrated roll, rad
    aiding: tuple          # navfilter.Aiding
    noise: NF.ImuNoise
    delta: np.ndarray      # (N,) rudder angle at the IMU instants, rad (mean over the rudders)
    n: np.ndarray          # (N,) shaft speed, 1/s (mean over the shafts)
    t_execute: float
    t_finex: float
    rudder_sd: float = 0.0  # the synchro's stated calibration uncertainty (a zero error common to the record), rad
    heading_sd: float = 0.0  # the gyro zero's error left over the record after the approach check, rad
    rudder_timing_sd: float = 0.0  # the rudder record's clock against the motion package's (stated offsets), s
    gyro_scale_sd: float = 0.0  # the rate gyros' stated scale-factor error (relative)
    p: np.ndarray | None = None      # (N,) roll rate from the motion package, rad/s
    pdot: np.ndarray | None = None   # (N,) roll acceleration (its smoothed derivative), rad/s²
    pitch: np.ndarray | None = None  # (N,) indicated pitch ratio of controllable-pitch propellers (mean)
    pitch_sd: float = 0.0            # the pitch indicators' stated zero error (common to the record)

    def approach(self) -> dict:
        """Speed over ground and shaft speed on the approach (before EXECUTE), as a team reads them."""
        pos = next(a for a in self.aiding if a.kind == "position")
        m = (pos.t < self.t_execute) & (pos.t > pos.t[0] + _SETTLE_S)
        if m.sum() < 3:
            raise InputError(self.path, "approach", "fewer than 3 fixes before EXECUTE; allowed: an approach of "
                             f"at least {_SETTLE_S + 1:g} s")
        tt, p = pos.t[m], pos.z[m]
        vel = np.polyfit(tt - tt[0], p, 1)[0]
        k = self.t < self.t_execute
        out = {"speed_mps": float(np.hypot(*vel)), "shaft_rps": float(np.mean(self.n[k]))}
        if self.pitch is not None:
            out["pitch_ratio"] = float(np.mean(self.pitch[k]))
        return out


def _need(kinds, kind, path, what):
    if not kinds.get(kind):
        raise InputError(path, "instruments", f"no {kind} instrument ({what}); the identification needs a "
                         "tracking system (gnss), a heading gyro, a motion package (imu), a rudder synchro and "
                         f"a shaft counter; the record has {', '.join(sorted(k for k in kinds if k))}")
    return kinds[kind][0]


def _position_sd(meta: dict) -> float:
    """A tracking system's stated position error: the white part ⊕ the correlated parts, m."""
    return math.sqrt(float(meta.get("horizontal_accuracy_m", 0.01))**2
                     + sum(float(s)**2 for s, _ in meta.get("correlated_errors", [])))


def _channel(rec, inst, name):
    t, y = rec.channel(inst, name)
    return t - float(rec.meta(inst).get("latency_s", 0.0)), y


def _attitude(t, w, f):
    """Roll and pitch by Euler-angle kinematics from body rates w (N, 3), started level-by-gravity."""
    k0 = t < t[0] + _SETTLE_S
    fm = f[k0].mean(axis=0)
    phi, th = math.atan2(-fm[1], -fm[2]), math.atan2(fm[0], math.hypot(fm[1], fm[2]))
    def rates(ph, tt, p, q, r):
        return (p + (q * math.sin(ph) + r * math.cos(ph)) * math.tan(tt), q * math.cos(ph) - r * math.sin(ph))

    out = np.empty((t.size, 2))
    out[0] = phi, th
    for k in range(t.size - 1):          # Heun's method, rates linear over the step
        dt = t[k + 1] - t[k]
        a = rates(phi, th, *w[k])
        b = rates(phi + dt * a[0], th + dt * a[1], *w[k + 1])
        phi, th = phi + 0.5 * dt * (a[0] + b[0]), th + 0.5 * dt * (a[1] + b[1])
        out[k + 1] = phi, th
    return out[:, 0], out[:, 1]


def _vertical_reference(rec, inst, t, phi, th):
    """Integrated roll and pitch with their slow drift taken from a vertical reference: a complementary
    filter (Higgins 1975, IEEE Trans. Aerosp. Electron. Syst. AES-11:321) — the rates' integral above
    1/(2π VERTICAL_TAU_S), the vertical reference below it, run forward and back (zero phase: the record
    is whole). The reference's own zero is set against the gravity level on the approach's first
    seconds. The integral drifts by the rate gyros' bias and misalignment (a 0.05° misalignment in a
    0.04 rad/s turn is 3.5e-5 rad/s of false roll rate, 0.2° over a turn), which would level the
    specific force wrongly (g × 0.003 rad = 0.03 m/s² of false sway acceleration)."""
    tv, roll = _channel(rec, inst, "roll")
    _, pitch = rec.channel(inst, "pitch")
    ok = np.isfinite(roll) & np.isfinite(pitch)
    if ok.sum() < 10:
        return phi, th
    tv, roll, pitch = tv[ok], roll[ok], pitch[ok]
    dt = float(np.median(np.diff(t)))
    b, a = butter(1, dt / VERTICAL_TAU_S / math.pi)   # first order, cut-off 1/(2π τ) at the IMU's rate
    out = []
    for x, ref in ((phi, roll), (th, pitch)):
        d = np.interp(t, tv, ref) - x
        d = d - float(np.mean(d[t < t[0] + _SETTLE_S]))
        out.append(x + filtfilt(b, a, d, padtype="even"))
    return out[0], out[1]


def _rudders(rec, kinds, t, t_exec, path):
    """Mean rudder angle at the IMU instants and the record-wide error of its zero (rad).

    A twin-screw, twin-rudder ship (two shaft counters and two rudder synchros in the record: outward-
    or inward-turning pairs, no propeller side force) holds a straight course in calm water with the
    rudders amidships, so the team zeroes each synchro on the straight approach (the team's assumption,
    like the gyro's zero; checked against truth in tests/test_identify_patrol51.py). What is left: the
    reading's step on the steady approach (resolution/√12) and the readings' scatter over the approach.
    A single-screw ship needs a little helm against its propeller's side force: its synchros keep
    their stated calibration uncertainty."""
    rud = kinds["rudder"]
    sd0 = float(rec.meta(rud[0]).get("calibration_uncertainty_rad", rec.meta(rud[0]).get("bias_std", 0.0)))
    series = [_channel(rec, r_, "angle") for r_ in rud]
    if len(rud) < 2 or len(kinds.get("shaft_rpm", [])) < 2:
        return np.mean([np.interp(t, *s_) for s_ in series], axis=0), sd0
    out, var = [], []
    for r_, (tr, dr) in zip(rud, series):
        k = (tr > tr[0] + _SETTLE_S) & (tr < t_exec)
        if k.sum() < 10:
            raise InputError(path, "approach", f"{k.sum()} rudder readings of {r_} on the steady approach; allowed: "
                             "an approach of at least 1 s more than the settling time")
        out.append(np.interp(t, tr, dr - float(np.mean(dr[k]))))
        var.append(float(rec.meta(r_).get("resolution", 0.0))**2 / 12.0 + float(np.var(dr[k])) / int(k.sum()))
    return np.mean(out, axis=0), math.sqrt(sum(var)) / len(rud)


def read_maneuver(path: str | Path) -> ManeuverRecord:
    """Read one maneuver record (a single maneuver's NetCDF record) into a :class:`ManeuverRecord`."""
    path = str(path)
    try:
        rec = Record(path)
    except (OSError, ValueError) as exc:
        raise InputError(path, "record", f"cannot be read as a trial record ({exc}); allowed: a maneuver record "
                         "written by 'vtrials run' (RUN_DIR/records/NAME.nc)") from None
    kinds = instruments_by_kind(rec)
    # the most accurate satellite fixes the record has (stated accuracy, white and correlated parts)
    trk = min(kinds.get("gnss", []), key=lambda n: _position_sd(rec.meta(n)), default=None) \
        or _need(kinds, "range_radar", path, "positions")
    gyro = _need(kinds, "heading", path, "heading")
    imu = _need(kinds, "imu", path, "accelerations and rates")
    rud = _need(kinds, "rudder", path, "rudder angle")
    _need(kinds, "shaft_rpm", path, "shaft speed")
    ev = rec.events
    lab = list(ev["label"])
    if "EXECUTE" not in lab:
        raise InputError(path, "_events", "no EXECUTE mark; allowed: a maneuver record with its EXECUTE time")
    t_exec = float(ev["time"][lab.index("EXECUTE")])
    t_finex = float(ev["time"][lab.index("FINEX")]) if "FINEX" in lab else math.inf

    t, ax = _channel(rec, imu, "ax")
    f = np.column_stack([ax] + [rec.channel(imu, c)[1] for c in ("ay", "az")])
    w = np.column_stack([rec.channel(imu, c)[1] for c in ("p", "q", "r")])
    im = rec.meta(imu)
    phi, th = _attitude(t, w, f)
    if kinds.get("attitude"):   # a vertical reference holds the integrated attitude's slow drift
        phi, th = _vertical_reference(rec, kinds["attitude"][0], t, phi, th)
    # specific force at the reference point: minus the lever arm's tangential and centripetal terms
    arm = np.asarray(im.get("surveyed_position_m", [0.0, 0.0, 0.0]), float)
    wd = np.gradient(w, t, axis=0)
    f = f - np.cross(wd, arm) - np.cross(w, np.cross(w, arm))
    cf, sf, ct, st = np.cos(phi), np.sin(phi), np.cos(th), np.sin(th)
    f_h = np.column_stack([ct * f[:, 0] + st * (sf * f[:, 1] + cf * f[:, 2]), cf * f[:, 1] - sf * f[:, 2]])
    psi_rate = (w[:, 1] * sf + w[:, 2] * cf) / ct

    # aiding: fixes (vertical lever arm's displacement removed) and heading
    tp, north = _channel(rec, trk, "north")
    _, east = rec.channel(trk, "east")
    ok = np.isfinite(north) & np.isfinite(east)
    tp, north, east = tp[ok], north[ok], east[ok]
    tm = rec.meta(trk)
    la = np.asarray(tm.get("surveyed_position_m", [0.0, 0.0, 0.0]), float)
    th_h, heading = _channel(rec, gyro, "heading")
    heading = np.unwrap(heading)
    psi = np.interp(tp, th_h, heading)
    ph, tt = np.interp(tp, t, phi), np.interp(tp, t, th)
    cp_, sp_ = np.cos(psi), np.sin(psi)
    north = north - la[2] * (cp_ * np.sin(tt) * np.cos(ph) + sp_ * np.sin(ph))
    east = east - la[2] * (sp_ * np.sin(tt) * np.cos(ph) - cp_ * np.sin(ph))
    sig_pos = _position_sd(tm)
    gm = rec.meta(gyro)
    # the gyro's zero against the track on the steady straight approach (calm basin, no current: no
    # drift angle there — the team's assumption, checked in the tests), then its wander over the record
    k = (tp > tp[0] + _SETTLE_S) & (tp < t_exec)
    if k.sum() >= 5:
        tc = tp[k] - tp[k].mean()
        vn, ve = np.polyfit(tc, north[k], 1)[0], np.polyfit(tc, east[k], 1)[0]
        offset = float(np.angle(np.mean(np.exp(1j * (psi[k] - math.atan2(ve, vn))))))
        heading = heading - offset
        sig_course = sig_pos / math.sqrt(float(tc @ tc)) / math.hypot(vn, ve)
    else:   # too few fixes on the approach (a tracking outage): the gyro's zero as its maker states it
        sig_course = float(gm.get("bias_std", math.radians(0.25)))
    tau = float(gm.get("drift_tau_s", 900.0))
    # the gyro's wander since the check: a Gauss–Markov drift grows by σ √(2 T/τ) over T ≪ τ, a ramp
    # whose mean square over the record is a third of its end value's
    wander2 = float(gm.get("drift_std_rad", 0.0))**2 * min(1.0, 2.0 * (tp[-1] - tp[0]) / tau)
    sig_head = math.sqrt(sig_course**2 + float(gm.get("resolution_rad", 0.0))**2 / 12.0 + wander2)
    # the approach's steady heading reads one constant step error of the gyro's resolution, which the
    # zero check takes in whole; in the maneuver the steps average out (uniform: resolution²/12)
    heading_sd = math.sqrt(sig_course**2 + wander2 / 3.0 + float(gm.get("resolution_rad", 0.0))**2 / 12.0)
    # time stamps: each clock's stated offset from the motion package's moves a fix along the track by
    # U δt and a heading by ψ̇ δt — nothing on a steady approach, metres and tenths of a degree in a fast
    # turn; the fixes' and headings' σ carry it (the speed and rate from the motion itself)
    clk = float(im.get("clock_offset_sd_s", 0.0))
    dt_pos, dt_head = math.hypot(clk, float(tm.get("clock_offset_sd_s", 0.0))), math.hypot(clk, float(gm.get("clock_offset_sd_s", 0.0)))
    speed = np.hypot(*np.gradient(np.column_stack([north, east]), tp, axis=0).T) if tp.size > 1 else np.zeros(tp.size)
    rate_h = np.interp(th_h, t, np.abs(psi_rate))
    aiding = (NF.Aiding("position", tp, np.column_stack([north, east]), np.hypot(sig_pos, speed * dt_pos),
                        (float(la[0]), float(la[1]))),
              NF.Aiding("heading", th_h, heading, np.hypot(sig_head, rate_h * dt_head)))

    # the motion package's data sheet → the filter's noise model
    T = float(t[-1] - t[0])
    gb = math.hypot(float(im.get("gyro_bias_std", 1e-5)), float(im.get("gyro_instability", [0.0, 1.0])[0]))
    ab_gm, ab_tau = (float(x) for x in im.get("accel_instability", [0.0, 100.0]))
    ab = math.hypot(float(im.get("accel_bias_std", 1e-3)), ab_gm)
    noise = NF.ImuNoise(
        accel_sigma=float(im.get("accel_noise_mps2", 0.005)), gyro_sigma=float(im.get("gyro_noise_rps", 3e-4)),
        accel_bias_rw=math.sqrt(2 * ab_gm**2 / ab_tau + float(im.get("accel_random_walk", 0.0))**2
                                + (G * gb)**2 * T),
        gyro_bias_rw=math.sqrt(2 * float(im.get("gyro_instability", [0.0, 1.0])[0])**2
                               / float(im.get("gyro_instability", [0.0, 1.0])[1])
                               + float(im.get("gyro_random_walk", 0.0))**2) or 1e-7,
        jerk_psd=JERK_PSD, accel_bias0=2.0 * ab, gyro_bias0=2.0 * gb)

    # the filter starts at the first fix: before it (a tracking outage at the start of the record) its
    # initial position would be a later fix's, and it would hold the ship still to match
    keep = t >= max(tp[0], th_h[0]) - 0.5 * float(np.median(np.diff(t)))
    t, f_h, psi_rate, phi = t[keep], f_h[keep], psi_rate[keep], phi[keep]
    if t.size < 3 or t[0] >= t_exec:
        raise InputError(path, "tracking", f"the first fix is at {tp[0]:.1f} s, after EXECUTE ({t_exec:.1f} s); "
                         "allowed: a record whose tracking starts on the approach")
    p = w[keep, 0]
    # roll acceleration: the local cubic's slope over ROLL_WINDOW_S (Savitzky & Golay 1964)
    dt = float(np.median(np.diff(t)))
    win = max(5, 2 * int(round(ROLL_WINDOW_S / dt / 2)) + 1)
    pdot = savgol_filter(p, win, 3, deriv=1, delta=dt) if t.size > win else np.gradient(p, t)
    delta, rudder_sd = _rudders(rec, kinds, t, t_exec, path)
    n = np.mean([np.interp(t, *_channel(rec, s_, "rps")) for s_ in kinds["shaft_rpm"]], axis=0)
    pitch, pitch_sd = None, 0.0
    if kinds.get("pitch_indicator"):
        pis = kinds["pitch_indicator"]
        pitch = np.mean([np.interp(t, *_channel(rec, i, "pitch")) for i in pis], axis=0)
        # each indicator's zero: its stated error and the hub-oil warming's drift (its full rise at the
        # rated power: a bound the team takes as 2 sigma), common to the record; the indicators are
        # calibrated one by one, so their zeros are independent and the mean's error is √(Σ σᵢ²)/n,
        # as for the rudders' synchros
        sds = [math.hypot(float(pm.get("bias_std", 0.0)),
                          0.5 * float(pm.get("bias_per_K", 0.0)) * float(pm.get("oil_temperature_rise_K", 0.0)))
               for pm in (rec.meta(i) for i in pis)]
        pitch_sd = math.sqrt(sum(x * x for x in sds)) / len(sds)
    return ManeuverRecord(path=path, name=str(rec.attr("trial", Path(path).stem)), kind=str(rec.attr("kind", "")),
                          ordered=rec.attr("maneuver", {}) or {}, ship=str(rec.attr("ship", "")), t=t, f=f_h,
                          psi_rate=psi_rate, roll=phi, aiding=aiding, noise=noise, delta=delta,
                          n=n, t_execute=t_exec, t_finex=t_finex, heading_sd=heading_sd,
                          rudder_timing_sd=math.hypot(float(rec.meta(rud).get("clock_offset_sd_s", 0.0)),
                                                      float(im.get("clock_offset_sd_s", 0.0))),
                          rudder_sd=rudder_sd,
                          gyro_scale_sd=float(im.get("gyro_scale_sd", 0.0)), p=p, pdot=pdot, pitch=pitch,
                          pitch_sd=pitch_sd)


def reconstruct(mr: ManeuverRecord) -> NF.NavSolution:
    """EKF + RTS smoother over the whole record (:func:`vtrials.sysid.navfilter.smooth`).

    The filter takes the gyro's error as white; what is left of its zero after the approach check is
    common to the whole record and turns the body velocities (δu = v δψ, δv = −u δψ), which no aiding
    here can see; likewise the rate gyros' scale-factor error (δr = s r). Their variances are added to
    the smoothed covariance along those directions, so the states' σ state what they cover."""
    sol = NF.smooth(mr.t, mr.f, mr.psi_rate, list(mr.aiding), mr.noise)
    P = sol.P.copy()
    J = np.zeros((sol.t.size, len(NF.STATES)))
    J[:, NF.STATES.index("psi")] = 1.0
    J[:, NF.STATES.index("u")] = sol.state("v")
    J[:, NF.STATES.index("v")] = -sol.state("u")
    P += mr.heading_sd**2 * J[:, :, None] * J[:, None, :]
    # the rate gyros' scale-factor error, common to the record: δr = s r (and δṙ = s ṙ)
    J = np.zeros((sol.t.size, len(NF.STATES)))
    J[:, NF.STATES.index("r")] = sol.state("r")
    J[:, NF.STATES.index("rdot")] = sol.state("rdot")
    P += mr.gyro_scale_sd**2 * J[:, :, None] * J[:, None, :]
    return dataclasses.replace(sol, P=P)


def segment(mr: ManeuverRecord, sol: NF.NavSolution, trim_s: float = 2.0) -> RG.Segment:
    """The regression segment of one maneuver: the smoothed record less ``trim_s`` at each end (where
    the smoother has data on one side only)."""
    k = (sol.t >= sol.t[0] + trim_s) & (sol.t <= sol.t[-1] - trim_s)
    return RG.Segment.from_nav(sol, mr.delta, mr.n, mr.roll, mr.p, mr.pdot, mr.pitch).where(k)
