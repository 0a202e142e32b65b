"""Scoring Compat (:mod:`vtrials.reduce.compat_records`) against truth: the IMU's effective biases over
the fit window and the true motion of the centre of motion.

Reference "true bias" (what a constant-bias model can estimate): for each IMU channel the constant rate
that best explains the running integral of everything the instrument added to its true measurand,

    e(t) = recorded − true measurand at the IMU site,   b_true = LS slope of ∫ e dt over the window,

at the true instants of the recorded stamps (the IMU's logger clock, drawn and kept in the truth file,
inverted: :func:`true_time`), with the true measurand (specific force including the lever-arm terms,
body rates) computed from the truth file by :class:`vtrials.instruments.kinematics.SiteKinematics` and interpolated linearly to the
recorded time stamps exactly as the IMU's own sampling does (:class:`vtrials.instruments.parts.Resample`).
This is the drawn turn-on bias, plus the bias instability (Gauss–Markov) and bias random walk as they
are over the window, plus misalignment and scale factor acting on the steady measurand (for the
horizontal accelerometers mostly the misalignment's gravity leak g·δ). The kinematics integrate the
inputs, so a constant is judged by the integral: a plain window mean would give the misalignment of a
gyro acting on the wave-frequency rates a value δ·(φ(T) − φ(0))/T set by where the record happens to
start and stop in the roll cycle (2·10⁻⁶ rad/s for δ = 0.05°, about the b_q bound), which no fit of the
integrated attitude sees; the slope of the integral takes the oscillation's trend only. The white
noise enters as the slope of its integral, a Wiener process (standard deviation σ √(6Δt/(5T)):
2·10⁻⁷ rad/s for the navigation unit over 90 s, a tenth of the smallest bound). The invariant combinations' references use the true mean roll and
pitch of the window.

Timing of the simulator's truth: the truth file's body rates p, q, r and velocities describe the time
step that ENDS at their stamp (semi-implicit integration: the velocity of step n carries the pose from
n − 1 to n), half a step behind the attitude of the same row. Integrating them with exact kinematics
reproduces the true Euler angles half a step earlier to 2·10⁻⁵ rad, and at the stamped instant only to
2·10⁻³ rad RMS in roll in a State 4 sea (tests/test_compat_records.py). The instruments, and this
scorer's references, carry them forward to the row's instant (:class:`vtrials.instruments.kinematics.
SiteKinematics` with the integrator step, ``truth_columns(..., step_s)``), so states are scored at the
stamped instant; ``rate_lag_s`` (default 0) can still shift the comparison.

True states: roll, pitch (Euler angles of the hull frame), the body velocities through the water
(u_r, v_r, w_r: with a log and v ≈ 0 the fit reconstructs water-relative velocities; with GNSS aiding
over-ground ones, u, v, w) and the heave velocity (earth-down velocity of the reference point), at the
recorded IMU time stamps.
"""

from __future__ import annotations

import math

import numpy as np

from vtrials.instruments.kinematics import SiteKinematics
from vtrials.units import G

IMU_CHANNELS = (("b_ax", "ax"), ("b_ay", "ay"), ("b_az", "az"), ("b_p", "p"), ("b_q", "q"), ("b_r", "r"))
_COLS = ("x", "y", "z", "qw", "qx", "qy", "qz", "roll", "pitch", "heading", "u", "v", "w", "p", "q", "r",
         "u_r", "v_r", "w_r", "du", "dv", "dw", "dp", "dq", "dr", "current_n", "current_e")


def truth_columns(truth_vars: dict, t_truth: np.ndarray, step_s: float | None) -> dict:
    """The truth columns the scoring needs, from the truth file's variables; ``step_s`` the simulation's
    time step (the truth file's ``timestep_s``), so that velocities and rates are taken at their rows'
    instants as the instruments take them (module note), or None for columns already at one instant."""
    cols = {k: np.asarray(truth_vars[k], float) for k in _COLS}
    cols["t"] = np.asarray(t_truth, float)
    if step_s is not None:
        cols["step_s"] = np.full(cols["t"].size, float(step_s))
    return cols


def imu_clock(truth_attrs: dict, imu: str = "imu") -> dict | None:
    """The IMU's drawn logger clock from the truth file's ``instrument_errors`` (None: true time)."""
    import json
    errs = truth_attrs.get("instrument_errors")
    errs = json.loads(errs) if isinstance(errs, str) else (errs or {})
    return (errs.get(imu) or {}).get("logger_clock")


def true_time(t_rec: np.ndarray, clock: dict | None) -> np.ndarray:
    """Simulation time of recorded stamps: the logger clock stamps t + c + d·(t − t_ref)
    (:class:`vtrials.instruments.parts.ClockOffset`), inverted."""
    t_rec = np.asarray(t_rec, float)
    if not clock:
        return t_rec
    c, d, tr = float(clock["offset_s"]), float(clock["drift_ppm"]) * 1e-6, float(clock["t_ref_s"])
    return (t_rec - c + d * tr) / (1.0 + d)


def _interp(t_out: np.ndarray, t: np.ndarray, y: np.ndarray) -> np.ndarray:
    if y.ndim == 1:
        return np.interp(t_out, t, y)
    return np.column_stack([np.interp(t_out, t, y[:, k]) for k in range(y.shape[1])])


def true_imu(cols: dict, site, t_rec: np.ndarray) -> dict:
    """True measurand of an IMU at ``site`` at the recorded time stamps: channel → array."""
    kin = SiteKinematics(cols, np.asarray(site, float))
    sf = _interp(t_rec, cols["t"], kin.specific_force())
    om = _interp(t_rec, cols["t"], kin.omega)
    return {"ax": sf[:, 0], "ay": sf[:, 1], "az": sf[:, 2], "p": om[:, 0], "q": om[:, 1], "r": om[:, 2]}


def true_biases(record, cols: dict, t0: float, t1: float, imu: str = "imu", clock: dict | None = None) -> dict:
    """Effective bias of each IMU channel over [t0, t1] of record time (module note): name → value [SI].
    ``clock``: the IMU's drawn logger clock (:func:`imu_clock`), to find the true instants of the
    recorded stamps."""
    t_rec, _ = record.channel(imu, "p")
    sel = (t_rec >= t0) & (t_rec <= t1)
    site = record.meta(imu)["surveyed_position_m"]  # the surveyed position is the true site here
    t = true_time(t_rec[sel], clock)
    tru = true_imu(cols, site, t)
    return {b: _integrated_slope(t, record.channel(imu, ch)[1][sel] - tru[ch]) for b, ch in IMU_CHANNELS}


def _integrated_slope(t: np.ndarray, e: np.ndarray) -> float:
    """Least-squares slope of the running integral of e: the constant that best explains what e adds
    to the integrated states (module note)."""
    E = np.concatenate([[0.0], np.cumsum(0.5 * (e[1:] + e[:-1]) * np.diff(t))])
    return float(np.polyfit(t - t[0], E, 1)[0])


def true_states(cols: dict, t: np.ndarray) -> dict:
    """True roll, pitch, heading, body velocities (through the water and over ground) and the heave
    velocity (earth-down velocity of the reference point) at times t."""
    kin = SiteKinematics(cols, np.zeros(3))
    out = {k: np.interp(t, cols["t"], cols[k]) for k in ("roll", "pitch")}
    for j, k in enumerate(("u", "v", "w")):
        out[k] = np.interp(t, cols["t"], kin.nu[:, j])
        out[f"{k}_r"] = np.interp(t, cols["t"], kin.nu_r[:, j])
    out["heading"] = np.interp(t, cols["t"], np.unwrap(cols["heading"]))
    v_down = np.einsum("nj,nj->n", kin.R[:, 2, :], kin.nu)
    out["v_down"] = np.interp(t, cols["t"], v_down)
    return out


def true_invariants(biases: dict, states: dict, gravity: float = G) -> dict:
    """Reference invariant combinations with the true window-mean attitude."""
    phi, th = float(np.mean(states["roll"])), float(np.mean(states["pitch"]))
    return {"x": biases["b_ax"] + gravity * math.cos(th) * th,
            "y": biases["b_ay"] - gravity * math.cos(th) * math.cos(phi) * phi}


def _covers(e: dict, x: float) -> bool:
    return bool(e["lo95"] <= x <= e["hi95"])


def score_stage(stage: dict, biases: dict, cols: dict, over_ground: bool = False, clock: dict | None = None,
                rate_lag_s: float = 0.0) -> dict:
    """Errors, coverage and reconstruction RMS errors of one stage's result. ``rate_lag_s``: compare the
    states with the truth that much earlier (the simulator's body rates describe the step that ends at
    their time stamp: half a step behind its attitude, see the module note); ``state_rms`` is at the
    stamped instant, ``state_rms_rate_instant`` at the shifted one."""
    t = np.asarray(stage["states"]["time"], float)
    tru = true_states(cols, true_time(t, clock))
    est = stage["estimates"]
    out = {"biases": {}, "invariants": {}, "state_rms": {}}
    for b in biases:
        if b in est:
            e = est[b]
            out["biases"][b] = {"value": e["value"], "std": e["std"], "dof": e["dof"], "truth": biases[b],
                                "error": e["value"] - biases[b], "covered": _covers(e, biases[b])}
    inv_true = true_invariants(biases, tru)
    for k, e in stage.get("invariants", {}).items():
        out["invariants"][k] = {"value": e["value"], "std": e["std"], "dof": e["dof"], "truth": inv_true[k],
                                "error": e["value"] - inv_true[k], "covered": _covers(e, inv_true[k])}
    s = stage["states"]
    vel = ("u", "v", "w") if over_ground else ("u_r", "v_r", "w_r")
    pairs = {"roll": "roll", "pitch": "pitch", "u": vel[0], "v": vel[1], "w": vel[2], "v_down": "v_down"}
    refs = {"state_rms": tru}
    if rate_lag_s:
        refs["state_rms_rate_instant"] = true_states(cols, true_time(t, clock) - rate_lag_s)
    for key, tr in refs.items():
        out[key] = {}
        for k, ref in pairs.items():
            d = np.asarray(s[k], float) - tr[ref]
            out[key][k] = float(np.sqrt(np.mean(d ** 2)))
            out[key][f"{k}_detrended"] = float(np.std(d - np.polyval(np.polyfit(t - t[0], d, 1), t - t[0])))
            out[key][f"{k}_true_rms"] = float(np.std(tr[ref]))
    return out


def score_compat(reduced: dict, record, cols: dict, imu: str = "imu", over_ground: bool = False,
                 clock: dict | None = None, rate_lag_s: float = 0.0) -> dict:
    """Score every stage of :func:`vtrials.reduce.compat_records.reduce_compat`'s output; ``clock``: the
    IMU's drawn logger clock (:func:`imu_clock`); ``rate_lag_s``: see :func:`score_stage`."""
    t0, t1 = reduced["window"]
    b = true_biases(record, cols, t0, t1, imu, clock)
    out = {"true_biases": b}
    for st in ("one_stage", "two_stage"):
        if st in reduced:
            out[st] = score_stage(reduced[st], b, cols, over_ground, clock, rate_lag_s)
    return out
