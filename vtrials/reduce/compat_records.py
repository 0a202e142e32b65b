"""Compat on a trial record: the strapdown IMU, the gyrocompass, the log, a mean-attitude reference and
optionally GNSS velocity, read from the record alone, put on the IMU's time grid and handed to
:mod:`vtrials.reduce.compat` (one-stage and the seed's two-stage fit).

What the team knows and uses (all from the record and its instruments' meta):

* IMU rates and specific forces, and the accelerometer offset ρ from the centre of motion = the IMU's
  surveyed position in the hull frame (origin midship on the waterline: the reference point of the
  record's ``frames``). The reconstructed states are those of that point.
* Gyrocompass heading, time-shifted by the data sheet's latency (meta ``latency_s``), unwrapped and
  interpolated (linear) onto the IMU grid; weight σ = ``heading_sigma``.
* Log speed (speed through the water along the hull at the log) interpolated onto the IMU grid and used
  as u; weight σ = ``log_sigma``. The log's own calibration error goes into u, not into a bias.
* v ≈ 0 and w ≈ 0 on every sample (seed 003 §3.2: the mean sway and heave velocities of a ship on a
  steady course vanish); weights ``sway_sigma``, ``heave_sigma`` (about the RMS of the motion).
* Mean attitude, ``attitude_source``:
  ``"reference"`` — an attitude instrument's roll and pitch (vertical gyro), per sample, weighted by
  its reading step, with its stated zero accuracy (meta ``bias_std``) as an error constant over the
  record whose effect on every parameter is added to the bound (``Observation.drift``): the mean
  attitude it gives is only as good as that zero (a horizontal accelerometer bias is known to
  g·bias_std), while the rate gyro biases come from its trends;
  ``"accelerometers"`` — seed 003 §3.2: roll and pitch "attitudes" from the specific force
  (:func:`vtrials.reduce.compat.accelerometer_attitude`, centripetal term removed with the log speed),
  a straight line fitted over the record and used per sample, weighted by their scatter about the line.
  With it a horizontal accelerometer bias is an attitude offset: only the invariant combinations
  (:func:`vtrials.reduce.compat.invariant_combinations`) are determined.
* ``gnss``: the receiver's speed and course over ground → v_north, v_east at the antenna, shifted by its
  latency, less the antenna's lever-arm velocity A(φ, θ, ψ)(ω × r_ant) (attitude from a first fit without
  GNSS, rates measured), interpolated onto the grid; they replace the log and v ≈ 0 (w ≈ 0 stays).

The Cramér–Rao bounds are the coloured-residual bounds of :mod:`vtrials.reduce.compat` (Morelli & Klein
1997) with Student-t intervals; the IMU's white noise (integrated by the kinematics into random walks)
is not in them (see that module).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from vtrials.errors import InputError
from vtrials.reduce import compat as C
from vtrials.records.netcdf import Record

_WHERE = "compat_records"
D = math.pi / 180.0
EV_EXECUTE, EV_FINEX = 2, 3
BIASES = ("b_p", "b_q", "b_r", "b_ax", "b_ay", "b_az")
CONSTANT_TAU_S = 1e9  # a zero error constant over any record, as a Gauss–Markov drift
ONE_STAGE_FREE = C.ATTITUDE_PARAMETERS + C.MOTION_PARAMETERS


@dataclasses.dataclass(frozen=True)
class CompatData:
    """The fit's inputs built from a record: the IMU record, the observations, the attitude
    observations of the two-stage fit and notes of what was used."""

    imu: C.ImuRecord
    observations: dict
    two_stage_observations: dict
    notes: dict


def run_window(record: Record, run: int | None = None, length_s: float | None = None) -> tuple[float, float]:
    """(t0, t1) of a run's data: EXECUTE → FINEX from the record's event marks (the first run if ``run``
    is None); with ``length_s`` the first ``length_s`` seconds after EXECUTE (seed 003 §5.1 cut one
    record to several lengths)."""
    ev = record.events
    runs = sorted(set(int(r) for r in ev["run"]))
    if not runs:
        raise InputError(str(record.path), "events", "the record has no run marks (EXECUTE/FINEX)")
    r = runs[0] if run is None else int(run)
    te = [t for t, n, c in zip(ev["time"], ev["run"], ev["code"]) if n == r and c == EV_EXECUTE]
    tf = [t for t, n, c in zip(ev["time"], ev["run"], ev["code"]) if n == r and c == EV_FINEX]
    if not te or not tf:
        raise InputError(str(record.path), "events", f"run {r} has no EXECUTE/FINEX marks; runs: {runs}")
    t0, t1 = float(te[0]), float(tf[-1])
    if length_s is not None:
        if not (0 < length_s <= t1 - t0 + 1e-6):
            raise InputError(str(record.path), "length_s", f"{length_s!r} s; allowed: 0 < length ≤ "
                                                           f"{t1 - t0:.1f} s (the run's length)")
        t1 = t0 + float(length_s)
    return t0, t1


def _need(record: Record, inst: str, channels: tuple) -> None:
    if inst not in record.instruments:
        raise InputError(str(record.path), inst, f"no such instrument in the record; it has "
                                                 f"{', '.join(record.instruments)}")
    have = record.channels(inst)
    for c in channels:
        if c not in have:
            raise InputError(str(record.path), f"{inst}.{c}", f"no such channel; it has {', '.join(have)}")


def _on_grid(t_grid: np.ndarray, t: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Linear interpolation onto the grid; NaN outside the instrument's samples."""
    ok = np.isfinite(t) & np.isfinite(y)
    t, y = t[ok], y[ok]
    out = np.full(t_grid.size, np.nan)
    if t.size < 2:
        return out
    inside = (t_grid >= t[0]) & (t_grid <= t[-1])
    out[inside] = np.interp(t_grid[inside], t, y)
    return out


def compat_data(record: Record, t0: float, t1: float, *, imu: str = "imu", heading: str = "gyro",
                log: str = "em_log", attitude: str = "vertical_gyro", attitude_source: str = "reference",
                gnss: str | None = None, heading_sigma: float = 0.1 * D, log_sigma: float = 0.1,
                sway_sigma: float = 0.3, heave_sigma: float = 0.5, gnss_sigma: float = 0.05,
                lever_attitude: np.ndarray | None = None) -> CompatData:
    """Build the fit's inputs from ``record`` over [t0, t1] (see the module note).

    ``lever_attitude``: (N, 3) roll, pitch, heading on the IMU grid for the GNSS lever-arm correction
    (from a first fit); None: heading from the gyrocompass, roll and pitch zero."""
    f = str(record.path)
    if attitude_source not in ("reference", "accelerometers"):
        raise InputError(f, "attitude_source", f"{attitude_source!r}; allowed: 'reference', 'accelerometers'")
    if not (t1 > t0):
        raise InputError(f, "window", f"[{t0}, {t1}] is empty")
    _need(record, imu, ("ax", "ay", "az", "p", "q", "r"))
    _need(record, heading, ("heading",))
    ti, _ = record.channel(imu, "p")
    sel = (ti >= t0) & (ti <= t1)
    if np.count_nonzero(sel) < 100:
        raise InputError(f, f"{imu}.time", f"only {np.count_nonzero(sel)} IMU samples in [{t0:.1f}, {t1:.1f}] s")
    t = ti[sel]
    rates = np.column_stack([record.channel(imu, c)[1][sel] for c in ("p", "q", "r")])
    sf = np.column_stack([record.channel(imu, c)[1][sel] for c in ("ax", "ay", "az")])
    m_imu = record.meta(imu)
    rho = np.asarray(m_imu.get("surveyed_position_m", [0.0, 0.0, 0.0]), float)
    imu_rec = C.ImuRecord(t, rates, sf, rho)
    n = t.size
    notes = {"imu": imu, "offset_m": rho.tolist(), "samples": int(n), "t0": float(t[0]), "t1": float(t[-1]),
             "attitude_source": attitude_source, "gnss": gnss}

    th, hh = record.channel(heading, "heading")
    lat = float(record.meta(heading).get("latency_s", 0.0))
    ok = np.isfinite(hh)
    th, hh = th[ok] - lat, np.unwrap(hh[ok])
    psi = _on_grid(t, th, hh)
    mh = record.meta(heading)
    drift = (float(mh.get("drift_std_rad", 0.0)), float(mh.get("drift_tau_s", 1.0)))
    obs = {"heading": C.Observation(psi, heading_sigma, drift=drift if drift[0] > 0 else None)}

    if gnss is None:
        _need(record, log, ("speed",))
        tl, ul = record.channel(log, "speed")
        lat_l = float(record.meta(log).get("latency_s", 0.0))
        obs["u"] = C.Observation(_on_grid(t, tl - lat_l, ul), log_sigma)
        obs["v"] = C.Observation(np.zeros(n), sway_sigma)
        notes["log"] = log
    else:
        _need(record, gnss, ("sog", "cog"))
        tg, sog = record.channel(gnss, "sog")
        _, cog = record.channel(gnss, "cog")
        mg = record.meta(gnss)
        tg = tg - float(mg.get("latency_s", 0.0))
        vn = _on_grid(t, tg, sog * np.cos(cog))
        ve = _on_grid(t, tg, sog * np.sin(cog))
        r_ant = np.asarray(mg.get("surveyed_position_m", [0.0, 0.0, 0.0]), float)
        att = lever_attitude if lever_attitude is not None else np.column_stack([np.zeros(n), np.zeros(n),
                                                                                np.nan_to_num(psi)])
        lever = np.cross(rates, r_ant)  # ω × r_ant in body axes (biases negligible at this lever)
        lev_e = np.einsum("nij,nj->ni", C.rotation_body_to_earth(att[:, 0], att[:, 1], att[:, 2]), lever)
        obs["v_north"] = C.Observation(vn - lev_e[:, 0], gnss_sigma)
        obs["v_east"] = C.Observation(ve - lev_e[:, 1], gnss_sigma)
        notes["gnss_lever_arm_m"] = r_ant.tolist()
    obs["w"] = C.Observation(np.zeros(n), heave_sigma)

    two = {}
    if attitude_source == "reference":
        _need(record, attitude, ("roll", "pitch"))
        ma = record.meta(attitude)
        sig0 = float(ma.get("bias_std", 0.0))
        if not sig0 > 0:
            raise InputError(f, f"{attitude}.meta.bias_std", "the attitude reference states no zero accuracy; "
                                                             "allowed: > 0 rad")
        res = float(ma.get("resolution", 0.0))
        lat_a = float(ma.get("latency_s", 0.0))
        for k in ("roll", "pitch"):
            ta, ya = record.channel(attitude, k)
            w = (ta >= t0) & (ta <= t1) & np.isfinite(ya)
            # per sample, weighted by its reading step (at least 0.01°); its zero error is constant over
            # the record: a drift of infinite correlation time, whose effect the bound carries
            obs[k] = C.Observation(_on_grid(t, ta - lat_a, ya), max(res, 0.01 * D), drift=(sig0, CONSTANT_TAU_S))
            two[k] = obs[k]
            notes[f"mean_{k}_rad"] = float(np.mean(ya[w]))
        notes["attitude_zero_sigma_rad"] = sig0
    else:
        speed = float(np.nanmean(obs["u"].values)) if "u" in obs else None
        roll_a, pitch_a = C.accelerometer_attitude(imu_rec, speed=speed)
        for k, y in (("roll", roll_a), ("pitch", pitch_a)):
            line = np.polyval(np.polyfit(t - t[0], y, 1), t - t[0])
            s = max(float(np.std(y - line)), 1e-4)
            obs[k] = C.Observation(line, s)
            two[k] = obs[k]
            notes[f"{k}_line_sigma_rad"] = s
    two_obs = dict(obs)
    two_obs.update(two)
    return CompatData(imu_rec, obs, two_obs, notes)


def invariant_estimates(imu: C.ImuRecord, parameters: dict, free: tuple, covariance: np.ndarray,
                        dof: dict) -> dict:
    """The invariant combinations (b_ax + g cos θ̄ θ̄, b_ay − g cos θ̄ cos φ̄ φ̄) as value ± bound: the
    gradient with respect to the free parameters by forward differences of the integrated states
    (steps of :data:`vtrials.reduce.compat._STEP`), propagated through the fit's covariance;
    degrees of freedom those of b_ax / b_ay."""
    obs = {"heading": C.Observation(np.zeros(imu.time_s.size), 1.0)}
    model = C._Model(imu, C._check_observations(obs, imu.time_s.size))
    par = np.array([parameters[k] for k in C.PARAMETERS])
    base = np.array(C.invariant_combinations(parameters, model.states(par), imu.gravity))
    grad = np.zeros((2, len(free)))
    for j, name in enumerate(free):
        i = C._INDEX[name]
        pp = par.copy()
        pp[i] += C._STEP[i]
        pd = dict(zip(C.PARAMETERS, pp))
        grad[:, j] = (np.array(C.invariant_combinations(pd, model.states(pp), imu.gravity)) - base) / C._STEP[i]
    cov = grad @ covariance @ grad.T
    out = {}
    for k, (name, b) in enumerate((("x", "b_ax"), ("y", "b_ay"))):
        d = dof.get(b)
        out[name] = C.Estimate(float(base[k]), float(math.sqrt(max(cov[k, k], 0.0))),
                               None if d is None or not math.isfinite(d) else float(d)).to_dict()
    return out


def _estimates(res, names) -> dict:
    return {k: res.estimate(k).to_dict() for k in names}


def _states(res, t: np.ndarray, every: int) -> dict:
    x = res.states
    ev = C._earth_velocity(x)
    return {"time": t[::every].tolist(), "roll": x[::every, 0].tolist(), "pitch": x[::every, 1].tolist(),
            "heading": x[::every, 2].tolist(), "u": x[::every, 3].tolist(), "v": x[::every, 4].tolist(),
            "w": x[::every, 5].tolist(), "v_down": ev[::every, 2].tolist()}


def reduce_compat(record: Record, t0: float | None = None, t1: float | None = None, *, run: int | None = None,
                  length_s: float | None = None, stages: tuple = ("one", "two"), states_every: int = 1,
                  **kw) -> dict:
    """Compat on a record's run: one-stage (all parameters together) and/or the seed's two-stage fit.

    Returns for each stage the biases (and initial states) as value ± bound (95 % Student-t interval),
    the invariant combinations of horizontal accelerometer bias and mean attitude, the bound kind, the
    fit's convergence, and the reconstructed states of the centre of motion (every ``states_every``-th
    sample). Window: [t0, t1], or the run's EXECUTE → FINEX (first ``length_s`` s)."""
    if t0 is None or t1 is None:
        t0, t1 = run_window(record, run, length_s)
    data = compat_data(record, t0, t1, **kw)
    if kw.get("gnss") is not None:
        # the antenna's lever-arm velocity needs the attitude: from a first fit without GNSS
        kw0 = dict(kw)
        kw0["gnss"] = None
        first = C.compat_fit(data.imu, compat_data(record, t0, t1, **kw0).observations, ONE_STAGE_FREE)
        data = compat_data(record, t0, t1, lever_attitude=first.states[:, :3], **kw)
    t = data.imu.time_s
    out = {"window": [float(t0), float(t1)], "notes": data.notes}
    if "one" in stages:
        r = C.compat_fit(data.imu, data.observations, ONE_STAGE_FREE)
        inv = invariant_estimates(data.imu, r.parameters, r.free, r.covariance,
                                  {k: float(r.dof[r.free.index(k)]) for k in ("b_ax", "b_ay")})
        out["one_stage"] = {"estimates": _estimates(r, r.free), "invariants": inv,
                            "converged": r.converged, "iterations": r.iterations,
                            "states": _states(r, t, states_every)}
    if "two" in stages:
        two = C.two_stage_fit(data.imu, data.two_stage_observations)
        inv = invariant_estimates(data.imu, two.motion.parameters, two.free, two.covariance,
                                  {k: float(two.motion.dof[two.motion.free.index(k)]) for k in ("b_ax", "b_ay")})
        out["two_stage"] = {"estimates": _estimates(two, two.free),
                            "motion_stage_bounds": {k: float(two.motion.estimate(k).std) for k in two.motion.free},
                            "invariants": inv,
                            "converged": bool(two.attitude.converged and two.motion.converged),
                            "states": _states(two.motion, t, states_every)}
    return out
