"""Reducing a seakeeping trial record (star pattern, seed 004): per leg the response spectra and RMS,
the transfer functions from the measured wave to the motions, and the encounter-frequency bookkeeping.

Inputs, from the record only: the log sheet (legs, EXECUTE/FINEX), the bow wave probe's surface
elevation (a point moving with the ship: the wave the ship meets, in the encounter frame), the motion
package (IMU specific forces and rates at its surveyed site), the vertical gyro (roll, pitch), the
gyro compass and the speed log, and the team's sea-state observation (mean wave direction).

Per leg, on a common grid at the probe's rate over [EXECUTE, FINEX] (the double integration runs over
the leg padded with two minutes of the record on either side, reflected where the record ends):

* heave (up) of the IMU's site by strapdown with orientation: the earth-vertical acceleration from the
  specific-force triad rotated with roll and pitch from the vertical gyro, doubly integrated in the
  frequency domain with a high-pass at ``OMEGA_C`` (:mod:`vtrials.reduce.heave`); the vertical
  acceleration (up) of the same site; roll and pitch;
* response spectra S(ω_e) (Welch) and RMS (the record's own, about its mean) with chi-square 95 %
  intervals of the process value (:mod:`vtrials.reduce.spectra`); the probe's H_s = 4√m0 likewise (m0
  is the same on either frequency axis);
* transfer functions Ĥ₁ = Ĝ_xy/Ĝ_xx from the probe elevation x to each response y in encounter
  frequency, with coherence γ² and the random error ε of Bendat & Piersol (2010, Table 9.6,
  :mod:`vtrials.reduce.transfer`). The 95 % intervals take Student's t with 2n_d − 2 degrees of
  freedom instead of the normal quantile: for Gaussian records the error of Ĥ₁ along any direction of
  the complex plane, divided by its estimated standard deviation, is t-distributed with 2n_d − 2
  degrees of freedom (Goodman 1957, the distribution behind Bendat & Piersol's eq. 9.90); a 6-min leg
  with 90-s segments has n_d ≈ 6 (t = 2.25, the normal 1.96 covers ~91 %). The probe's stated gain accuracy (1σ) is added to ε in quadrature
  for the amplitude (a gain error scales every |Ĥ|); the phase adds the relative timing uncertainty of
  the two loggers' stamps, σ_φ² = ε² + (ω_e σ_τ)², σ_τ² = Σ over both instruments of the stated clock
  offset sd² + (drift sd × time since synchronisation)² (the record's clock metadata);
* the transfer function is reported as determined in the bins where γ² > 0.8, the response spectrum is
  at least 1 % of its peak (in the tails of a motion spectrum, 1/100 of the peak power and less, the
  estimate is dominated by what the linear wave-to-motion path does not carry: leakage from the peak,
  the ship's yaw and sway modulating the probe's footprint, nonlinear forcing) and ω_e > 1.2 ω_c;
* encounter frequency ↔ wave frequency: a = U cos μ / g with U the log speed and μ the direction the
  waves travel relative to the heading (observed wave direction, gyro heading). Head to beam seas
  (a ≤ 0): each ω_e has one wave frequency. Following and quartering seas (a > 0): below
  ω_e* = 1/(4a) three wave frequencies share one |ω_e| — these bins are flagged ``ambiguous`` and
  given no wave frequency (:mod:`vtrials.reduce.encounter`); the transfer function itself is defined
  in ω_e and needs no mapping.

The phase of Ĥ refers to the probe's footprint, not to the ship's reference point (the wave phase at
the footprint differs by k·r_probe).
"""

from __future__ import annotations

import math

import numpy as np
from scipy import stats

from vtrials.errors import InputError
from vtrials.records.netcdf import Record
from vtrials.reduce import encounter as ENC
from vtrials.reduce import heave as HV
from vtrials.reduce import spectra as SPC
from vtrials.reduce import transfer as TF
from vtrials.units import G

PAD_S = 120.0  # record kept on either side of a leg for the double integration [s]
OMEGA_C = 0.25  # high-pass corner of the heave double integration [rad/s] (below the encounter band of the sea)
SEGMENT_S = 120.0  # Welch segment length for a 25-min leg [s]; shorter legs use a quarter of the leg
RESPONSES = {"heave": "m", "vertical_acc": "m s-2", "roll": "rad", "pitch": "rad"}
COHERENCE_MIN = 0.8  # bins where the transfer function is reported as determined (issue 13)
ENERGY_MIN = 0.01  # ... and where the response spectrum holds at least this fraction of its peak


def _by_kind(rec: Record) -> dict:
    out: dict = {}
    for name in rec.instruments:
        out.setdefault(rec.meta(name).get("kind"), []).append(name)
    return out


def _interp(rec: Record, inst: str, ch: str, t: np.ndarray, angular: bool = False) -> np.ndarray:
    ti, y = rec.channel(inst, ch)
    ok = np.isfinite(y)
    ti, y = ti[ok], y[ok]
    if angular:
        y = np.unwrap(y)
    return np.interp(t, ti, y)


def segment_length(duration_s: float) -> float:
    """Welch segment length [s] for a leg of ``duration_s``: 120 s, or a quarter of a shorter leg."""
    return min(SEGMENT_S, 0.25 * duration_s)


def timing_sd(rec: Record, names, t: float) -> float:
    """Standard deviation [s] of the difference between the time stamps of instruments ``names`` at
    time t from their stated clock accuracy (offset, drift since synchronisation; independent clocks)."""
    var = 0.0
    for n in names:
        m = rec.meta(n)
        off = float(m.get("clock_offset_sd_s", 0.0) or 0.0)
        drift = float(m.get("clock_drift_ppm_sd", 0.0) or 0.0) * 1e-6 * (t - float(m.get("clock_t_ref_s", 0.0) or 0.0))
        var += off * off + drift * drift
    return math.sqrt(var)


def _rms(x: np.ndarray, fs: float, nper: int) -> dict:
    """RMS of the leg's record about its mean (the sample value, as seed 004 tabulates it), with the
    chi-square 95 % interval of the process RMS from the record's equivalent degrees of freedom
    (:func:`vtrials.reduce.spectra.variance_estimate`)."""
    v = SPC.VarianceEstimate(float(np.var(x)), SPC.variance_estimate(x, fs, nper).dof)
    lo, hi = v.rms_interval()
    return {"value": v.rms, "lo95": lo, "hi95": hi, "dof": v.dof}


def reduce_leg(rec: Record, run: dict, kinds: dict) -> dict:
    """Spectra, RMS and transfer functions of one accepted leg (module doc)."""
    probe = kinds["wave_probe"][0]
    imu = kinds["imu"][0]
    vg = kinds["attitude"][0]
    fs = float(rec.meta(probe).get("nominal_rate_hz", 10.0))
    t0, t1 = float(run["t_execute"]), float(run["t_finex"])
    # the double integration treats its record as periodic: it runs over the leg padded by PAD_S of the
    # record on either side (reflected where the record ends), so that its wrap-around transient
    # stays outside [EXECUTE, FINEX]
    ti = rec.channel(imu, "az")[0]
    ta = max(t0 - PAD_S, float(ti[0]))
    n = int(math.floor((t1 + PAD_S - ta) * fs))
    tg = ta + np.arange(n) / fs
    t_last = min(float(ti[-1]), float(rec.channel(vg, "roll")[0][-1]))
    tm = np.where(tg > t_last, 2.0 * t_last - tg, tg)  # mirror past the end of the record
    roll = _interp(rec, vg, "roll", tm)
    pitch = _interp(rec, vg, "pitch", tm)
    ax, ay, az = (_interp(rec, imu, c, tm) for c in ("ax", "ay", "az"))
    acc_all = -HV.vertical_acceleration(ax, ay, az, roll, pitch)  # up
    # past the end of the record the acceleration is reflected oddly (a(t_e + s) = −a(t_e − s) about its
    # mean): velocity then reflects evenly and the displacement stays continuous and bounded (an even
    # reflection of the acceleration would make the velocity jump by 2 v(t_e) and the heave ramp)
    past = tg > t_last
    a_c = acc_all - np.mean(acc_all[~past])
    a_c[past] = -a_c[past]
    heave_all = HV.double_integrate(a_c, fs, OMEGA_C)
    keep = (tg >= t0) & (tg < t1)
    t = tg[keep]
    heave, acc_up, roll, pitch = heave_all[keep], acc_all[keep], roll[keep], pitch[keep]
    eta = _interp(rec, probe, "elevation", t)
    w = np.ones(t.size, bool)
    series = {"heave": heave[w], "vertical_acc": acc_up[w] - np.mean(acc_up[w]), "roll": roll[w], "pitch": pitch[w]}
    x = eta[w] - np.mean(eta[w])
    T = float(np.count_nonzero(w)) / fs
    nper = int(round(segment_length(T) * fs))
    # the encounter geometry as the team knows it: log speed, gyro heading, observed wave direction
    heading = kinds.get("heading", [None])[0]
    psi = math.nan
    if heading is not None:
        h = _interp(rec, heading, "heading", t[w], angular=True)
        psi = math.atan2(float(np.mean(np.sin(h))), float(np.mean(np.cos(h))))
    logs = kinds.get("em_log") or kinds.get("doppler_log") or kinds.get("knotmeter") or []
    U = math.nan
    if logs:
        ch = "u" if rec.meta(logs[0]).get("kind") == "doppler_log" else "speed"
        U = float(np.mean(_interp(rec, logs[0], ch, t[w])))
    sea = rec.team.get("sea_observed") or []
    mu = math.nan
    if sea and math.isfinite(psi):
        mu = math.remainder(float(sea[0]["from_rad"]) + math.pi - psi, 2 * math.pi)  # travel direction re heading
    a = U * math.cos(mu) / G if math.isfinite(U) and math.isfinite(mu) else math.nan
    gain_sd = float(rec.meta(probe).get("scale_std", 0.0) or 0.0)
    out = {"run": run["run"], "label": run["label"], "wave_heading": run["maneuver"].get("wave_heading"),
           "station_keeping": bool(run["maneuver"].get("station_keeping")), "course_deg": run["course_deg"],
           "heading": psi, "speed": U, "mu": mu, "a": a, "duration_s": T, "fs_hz": fs, "segment_s": nper / fs,
           "omega_c": OMEGA_C, "probe_gain_std": gain_sd,
           "probe_site_m": rec.meta(probe).get("surveyed_position_m"),
           "imu_site_m": rec.meta(imu).get("surveyed_position_m")}
    out["singular_omega_e"] = 0.25 / a if a > 0 else None
    hs = SPC.VarianceEstimate(float(np.var(x)), SPC.variance_estimate(x, fs, nper).dof)
    lo, hi = hs.hs_interval()
    out["hs_probe"] = {"value": hs.hs, "lo95": lo, "hi95": hi, "dof": hs.dof}
    sx = SPC.response_spectrum(x, fs, nper)
    out["omega_e"] = sx.omega.tolist()
    out["probe_spectrum"] = sx.S.tolist()
    if math.isfinite(a):
        W = ENC.wave_frequencies(sx.omega, U, mu)
        amb = np.isfinite(W[:, 1]) | (a > 0) & ~np.isfinite(W[:, 0])
        out["ambiguous"] = amb.tolist()
        out["omega_wave"] = np.where(amb, np.nan, W[:, 0] if a <= 0 else np.where(np.isfinite(W[:, 0]), W[:, 0], W[:, 2])).tolist()
    resp = {}
    tmid = 0.5 * (t0 + t1)
    source = {"heave": imu, "vertical_acc": imu, "roll": vg, "pitch": vg}
    for name, y in series.items():
        s_tau = timing_sd(rec, (probe, source[name]), tmid)
        y = y - np.mean(y)
        sp = SPC.response_spectrum(y, fs, nper)
        tf = TF.transfer_function(x, y, fs, nper)
        eps = tf.error
        eps_amp = np.sqrt(eps ** 2 + gain_sd ** 2)
        eps_ph = np.sqrt(eps ** 2 + (sp.omega * s_tau) ** 2)
        z = float(stats.t.ppf(0.975, max(2.0 * tf.n_d - 2.0, 1.0)))
        amp = tf.amplitude
        det = (tf.coherence > COHERENCE_MIN) & (sp.S >= ENERGY_MIN * np.max(sp.S)) & (sp.omega > 1.2 * OMEGA_C)
        resp[name] = {"units": RESPONSES[name], "rms": _rms(y, fs, nper), "spectrum": sp.S.tolist(),
                      "determined": det.tolist(),
                      "H_re": tf.H.real.tolist(), "H_im": tf.H.imag.tolist(), "coherence": tf.coherence.tolist(),
                      "error": eps.tolist(), "amp_error": eps_amp.tolist(), "phase_error": eps_ph.tolist(),
                      "n_d": tf.n_d, "timing_sd_s": s_tau, "z95": z,
                      "amp_lo95": (amp * (1 - z * eps_amp)).tolist(), "amp_hi95": (amp * (1 + z * eps_amp)).tolist(),
                      "phase_lo95": (tf.phase - z * eps_ph).tolist(), "phase_hi95": (tf.phase + z * eps_ph).tolist()}
    out["responses"] = resp
    return out


def reduce_seakeeping(rec: Record) -> dict:
    """Every accepted leg of a seakeeping record (:func:`reduce_leg`)."""
    kinds = _by_kind(rec)
    missing = [k for k in ("wave_probe", "imu", "attitude") if not kinds.get(k)]
    legs = []
    notes = []
    if missing:
        notes.append(f"the record has no {', '.join(missing)}: no transfer functions")
    else:
        for run in sorted([r for r in rec.run_log if r["accepted"]], key=lambda r: r["run"]):
            legs.append(reduce_leg(rec, run, kinds))
    out = {"kind": "seakeeping", "legs": legs, "notes": notes, "coherence_min": COHERENCE_MIN}
    # the wave estimates share the instrument roles and the team's design model (read once)
    roles = _motion_roles(rec, kinds, notes, "wave estimates (ship as a buoy, fusion)")
    out["ship_buoy"] = ship_buoy_block(rec, kinds, notes, roles) if roles else None
    out["wave_fusion"] = wave_fusion_block(rec, kinds, notes, roles) if roles else None
    return out


#: Shortest leg the ship-as-buoy fit takes: two of its 128-s Welch segments.
BUOY_MIN_LEG_S = 256.0

#: Motion components fused with the wave radar in a seakeeping trial's reduction (seed 004 compares each
#: component and pair; heave + pitch gave its headline).
FUSION_COMBOS = (("heave", "pitch"), ("heave",), ("pitch",))


def _motion_roles(rec: Record, kinds: dict, notes: list, what: str):
    """(instrument names by run_motions' role, the team's design-stage RAO model, accepted runs) or None
    with a note naming what is missing."""
    from vtrials.reduce.design_rao import load_design_rao
    need = {"imu": "imu", "attitude": "attitude", "log": "em_log", "compass": "heading"}
    missing = [k for k in need.values() if not kinds.get(k)]
    runs = sorted([r for r in rec.run_log if r["accepted"]], key=lambda r: r["run"])
    if missing or not runs:
        notes.append(f"no {what}: the record has no {', '.join(missing) or 'accepted leg'}")
        return None
    ship = rec.team.get("ship", "")
    try:
        design = load_design_rao(ship)
    except InputError as exc:
        notes.append(f"no {what}: no design-stage RAO model for {ship!r} ({exc})")
        return None
    return {k: kinds[v][0] for k, v in need.items()}, design, runs


def wave_fusion_block(rec: Record, kinds: dict, notes: list, roles=None) -> dict | None:
    """Seed 004's wave fusion per accepted leg for :data:`FUSION_COMBOS`
    (:func:`vtrials.reduce.wavefusion.fuse_run`: the wave radar's H_s scaled by measured over predicted
    motion RMS through the team's design-stage RAOs); a leg the radar has no spectrum in is left out with
    a note. None without a radar, or (with a note) when the rest is missing. ``roles``: what
    :func:`_motion_roles` gave, if the caller has it."""
    from vtrials.reduce.wavefusion import fuse_run
    radars = kinds.get("wave_radar") or []
    if not radars:
        return None
    got = roles or _motion_roles(rec, kinds, notes, "wave fusion")
    if got is None:
        return None
    names, design, runs = got
    legs = []
    for r in runs:
        try:
            f = fuse_run(rec, float(r["t_execute"]), float(r["t_finex"]), design, combos=FUSION_COMBOS,
                         radar=radars[0], instruments=names)
        except InputError as exc:          # e.g. a leg shorter than one radar acquisition
            notes.append(f"run {r['run']}: no wave fusion ({exc})")
            continue
        legs.append({"run": r["run"], "label": r["label"], "hs_radar": f.hs_radar, "n_spectra": f.n_spectra,
                     "measured_rms": f.measured, "predicted_rms": f.predicted,
                     "r": {k: v.r for k, v in f.fused.items()}, "hs_fused": {k: v.hs for k, v in f.fused.items()},
                     "heading_std_deg": math.degrees(f.heading_std)})
    if not legs:
        return None
    return {"method": "seed 004 eqs. 1-5: H_s = r H_s,radar, r = mean of measured/predicted motion RMS "
                      "(reduce.wavefusion.fuse_run)", "radar": radars[0],
            "design_file": f"models/{rec.team.get('ship', '')}/design/{rec.team.get('ship', '')}_design_rao.nc",
            "combos": ["+".join(c) for c in FUSION_COMBOS], "legs": legs}


def ship_buoy_block(rec: Record, kinds: dict, notes: list, roles=None) -> dict | None:
    """The ship as a wave buoy over the trial's accepted legs (:func:`vtrials.reduce.shipbuoy.ship_buoy_from_legs`:
    one sea fitted to all legs' heave, roll and pitch with the team's design-stage RAOs, models/<ship>/design),
    or None with a note when the record lacks the motion sensors, the log or the compass, or the team has no
    design model for the ship. ``roles``: what :func:`_motion_roles` gave, if the caller has it."""
    from vtrials.reduce.shipbuoy import ship_buoy_from_legs
    got = roles or _motion_roles(rec, kinds, notes, "ship-as-buoy estimate")
    if got is None:
        return None
    names, design, runs = got
    ship = rec.team.get("ship", "")
    short = [r for r in runs if float(r["t_finex"]) - float(r["t_execute"]) < BUOY_MIN_LEG_S]
    if short:
        notes.append(f"ship as a wave buoy: runs {', '.join(str(r['run']) for r in short)} shorter than "
                     f"{BUOY_MIN_LEG_S:.0f} s (two Welch segments) left out")
    runs = [r for r in runs if r not in short]
    if not runs:
        return None
    windows = [(float(r["t_execute"]), float(r["t_finex"])) for r in runs]
    sb = ship_buoy_from_legs(rec, windows, design, instruments=names)
    f = sb.fit
    return {"method": "one sea (JONSWAP, free gamma; cos-2s) fitted to every leg's heave/roll/pitch cross-spectra, "
                      "roll stiffness and damping tuned (reduce.shipbuoy.ship_buoy_from_legs)",
            "design_file": f"models/{ship}/design/{ship}_design_rao.nc", "components": list(sb.components),
            "hs": f.hs, "tp": f.tp, "gamma": f.gamma, "s": f.s, "from_deg": sb.from_deg,
            "roll_tuning": list(f.roll), "side_from": sb.side_from,
            "legs": [{"run": r["run"], "label": r["label"], "heading": sb.headings[k], "U": sb.U[k],
                      "from_rel_deg": sb.from_relative_deg(k), "observed": list(sb.observed[k]),
                      "reliable": sb.reliable(k)} for k, r in enumerate(runs)]}
