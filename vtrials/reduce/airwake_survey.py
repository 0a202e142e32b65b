"""Reducing an airwake survey record: the air velocity at each mast position without ship motion, and
the airwake ratio (local / reference), from the record alone.

Per recording (one mast position, EXECUTE → FINEX; seed 003 §4):

1. Ship motion at the motion package (the IMU point, the reference point of the AWSM lever arms: the
   formula holds for any point of the hull whose velocity is used): attitude from the vertical gyro,
   heading from the gyrocompass, rates from the IMU gyros; the earth-axis acceleration A f + g k from
   the IMU's specific force, over the recording padded by ``pad_s`` on each side (data exist while the
   mast is moved). Horizontal velocity: the time integral of it plus v₀ + b t, with the initial velocity
   v₀ and an acceleration bias b (attitude errors tilt g into the horizontal) fitted, with an initial
   position, to the tracking fixes (their antenna lever arm A(ρ_ant − ρ_imu) and stated latency
   included) — a short Compat: the fixes give the low frequencies, the accelerometers the rest.
   (An FFT integral of the horizontal acceleration alone (strapdown.fft_integrate, tapered pads) left
   0.2–1.2 m/s errors on recordings where the ship's course wandered by 10–20°: the taper and the
   periodic wrap lose the slow velocity change.)
   Vertical velocity: the time integral less its least-squares straight line (heave is oscillatory
   about a zero mean; an accelerometer bias makes the line). Body axes: V_b = Aᵀ V.
2. AWSM (:func:`vtrials.reduce.airwake.awsm`): only the fluctuations of V_b are added back with ω × ρ,
   ρ = anemometer − IMU (surveyed positions), then the result is rotated with roll and pitch into
   ship-carried vertical axes — the seed's order; and, as the alternative that has no U·θ term, the
   rotate-first form (:func:`vtrials.reduce.airwake.wind_relative_to_mean_motion`).
3. Means per component (uncorrected in body axes and in vertical axes, corrected) with
   autocorrelation-corrected standard errors (:func:`vtrials.reduce.runstats.channel_stats`) — the
   uncertainty of the long-run mean in this wind — and the corrected mean over the recording with the
   instrument's uncertainty alone (``mean_awsm_recording``, :func:`_stats3`); the
   airwake ratio K = mean horizontal speed at the mast / at the reference anemometer (both corrected)
   with its standard error by the delta method on the paired series s_mast − K s_ref (which carries
   their correlation), and the direction offset (mean direction at the mast − at the reference).

Only records are read. All SI; angles in radians.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import cumulative_trapezoid

from vtrials.reduce import airwake as AW
from vtrials.reduce.estimate import Estimate
from vtrials.reduce.runstats import channel_stats, wrap_pi
from vtrials.reduce.strapdown import rotation_body_to_earth
from vtrials.units import G

PAD_S = 20.0


def _kinds(rec) -> dict:
    out: dict = {}
    for name in sorted(rec.instruments):
        out.setdefault(rec.meta(name).get("kind"), []).append(name)
    return out


def _interp(t_out, t, x, angular=False):
    if angular:
        x = np.unwrap(x)
    return np.interp(t_out, t, x)


def _stats3(t, x, inst: dict | None = None, sampling: bool = True) -> list:
    """Mean per component with its autocorrelation-corrected standard error; with ``inst`` (the
    anemometer's stated accuracy: zero offset σ_b, scale σ_s, head alignment σ_a [rad], white noise σ_n
    per sample) the instrument's own uncertainty of a mean is added in quadrature,
    u² = σ_b² + (σ_s x̄_k)² + σ_a² (|x̄|² − x̄_k²) (the head's misalignment, three small angles of σ_a,
    turns the mean vector: δ × x̄ moves component k by the other two components), degrees of freedom by
    Welch–Satterthwaite (the stated accuracies as exact: infinite dof).

    ``sampling`` False: the uncertainty of the mean OVER THE RECORDING (what the air did while the
    mast stood there), not of the long-run mean: the gusts' and waves' sampling error, which the
    autocorrelation-corrected standard error measures, is not an error of that mean; what is left is
    the instrument's u² plus its white noise averaged, σ_n²/n."""
    out = []
    xm = np.mean(x, axis=0)
    mag2 = float(xm @ xm)
    for k in range(3):
        e = channel_stats(t, x[:, k]).estimate()
        if inst:
            ui2 = inst["bias"] ** 2 + (inst["scale"] * e.value) ** 2 + inst["align"] ** 2 * (mag2 - float(xm[k]) ** 2)
            if sampling:
                std = math.sqrt(e.std ** 2 + ui2)
                dof = e.dof * (std / e.std) ** 4 if e.std > 0 else None
            else:
                std = math.sqrt(ui2 + inst.get("noise", 0.0) ** 2 / max(len(t), 1))
                dof = None
            e = Estimate(e.value, std, dof)
        out.append(e.to_dict())
    return out


def _inst(meta: dict) -> dict:
    return {"bias": float(meta.get("bias_std", 0.0) or 0.0), "scale": float(meta.get("scale_sd", 0.0) or 0.0),
            "align": float(meta.get("misalignment_sd_rad", 0.0) or 0.0),
            "noise": float(meta.get("noise_std", 0.0) or 0.0)}


def _ship_velocity(rec, names: dict, t: np.ndarray, pad_s: float):
    """(V_b (n, 3) at the IMU point, rates (n, 3), roll, pitch, heading, ΔV (n, 3) earth axes, zero
    mean) on the times t (uniform). See the module text (step 1)."""
    imu, att, hdg, trk = names["imu"], names["attitude"], names["heading"], names["track"]
    dt = float(np.median(np.diff(t)))
    ti, _ = rec.channel(imu, "ax")
    ta, _ = rec.channel(att, "roll")
    th, _ = rec.channel(hdg, "heading")
    lo = max(ti[0], ta[0], th[0])  # pad only where every motion channel has data
    hi = min(ti[-1], ta[-1], th[-1])
    n0 = int(max(0, min(round(pad_s / dt), math.floor((t[0] - lo) / dt))))
    n1 = int(max(0, min(round(pad_s / dt), math.floor((hi - t[-1]) / dt))))
    tp = np.concatenate([t[0] - dt * np.arange(n0, 0, -1), t, t[-1] + dt * np.arange(1, n1 + 1)])
    f = np.column_stack([_interp(tp, ti, rec.channel(imu, c)[1]) for c in ("ax", "ay", "az")])
    w = np.column_stack([_interp(tp, ti, rec.channel(imu, c)[1]) for c in ("p", "q", "r")])
    ta, roll = rec.channel(att, "roll")
    _, pitch = rec.channel(att, "pitch")
    th, heading = rec.channel(hdg, "heading")
    phi, th_ = _interp(tp, ta, roll), _interp(tp, ta, pitch)
    psi = _interp(tp, th, heading, angular=True)
    A = rotation_body_to_earth(phi, th_, psi)
    acc = np.einsum("nij,nj->ni", A, f)
    acc[:, 2] += G
    vel = np.empty_like(acc)
    # horizontal: integrated in time and tied to the fixes over the padded span
    vint = cumulative_trapezoid(acc[:, :2], tp, axis=0, initial=0.0)
    xint = cumulative_trapezoid(vint, tp, axis=0, initial=0.0)
    tm = rec.meta(trk)
    tf, north = rec.channel(trk, "north")
    _, east = rec.channel(trk, "east")
    tf = tf - float(tm.get("latency_s", 0.0) or 0.0)
    ok = (tf >= tp[0]) & (tf <= tp[-1]) & np.isfinite(north) & np.isfinite(east)
    if np.count_nonzero(ok) < 6:
        raise ValueError(f"fewer than 6 position fixes over the recording {t[0]:.0f}-{t[-1]:.0f} s")
    arm = np.einsum("nij,j->ni", A[:, :2, :], np.asarray(tm["surveyed_position_m"], float) -
                    np.asarray(rec.meta(imu)["surveyed_position_m"], float))
    tau = tf[ok] - tp[0]
    X = np.column_stack([np.ones_like(tau), tau, 0.5 * tau ** 2])
    for k, obs in ((0, north[ok]), (1, east[ok])):
        y = obs - np.interp(tf[ok], tp, xint[:, k]) - np.interp(tf[ok], tp, arm[:, k])
        c = np.linalg.lstsq(X, y, rcond=None)[0]
        vel[:, k] = c[1] + c[2] * (tp - tp[0]) + vint[:, k]
    # vertical: oscillatory about a zero mean, no trend (heave) — the time integral less its straight line
    vz = cumulative_trapezoid(acc[:, 2], tp, initial=0.0)
    vel[:, 2] = vz - np.polyval(np.polyfit(tp - tp[0], vz, 1), tp - tp[0])
    core = slice(n0, n0 + t.size)
    v_earth = vel[core]
    v_body = np.einsum("nji,nj->ni", A[core], v_earth)
    return v_body, w[core], phi[core], th_[core], psi[core], v_earth - v_earth.mean(axis=0)


def relative_to_mean_ground_velocity(measured, rates, position, roll, pitch, heading, dv_earth):
    """Air velocity relative to the ship's mean velocity over ground, in ship-carried vertical axes:
    R_z(ψ)ᵀ [A(φ, θ, ψ)(m + ω × ρ) + ΔV], ΔV the ship's velocity fluctuation over ground (earth axes,
    zero mean) at the point the lever arms ρ are measured from. The mean removed is the mean velocity
    vector over ground, so the ship's yaw and pitch oscillations do not turn it into a fluctuation
    (the seed's order removes the body-axis mean: the mean speed then leaks in as ≈ (0, −U δψ, U θ))."""
    inst = AW.instrument_velocity(np.zeros_like(np.asarray(measured, float)), rates, position)
    air = np.einsum("nij,nj->ni", rotation_body_to_earth(roll, pitch, heading), np.asarray(measured) + inst) + dv_earth
    cp, sp = np.cos(heading), np.sin(heading)
    return np.column_stack([air[:, 0] * cp + air[:, 1] * sp, -air[:, 0] * sp + air[:, 1] * cp, air[:, 2]])


def _corrected(rec, name: str, position, t, motion):
    """(measured body, measured vertical, AWSM relative to the mean ground velocity, the seed's order,
    rotate-first) — vertical axes, (n, 3) each."""
    tm, _ = rec.channel(name, "u")
    m = np.column_stack([_interp(t, tm, rec.channel(name, c)[1]) for c in ("u", "v", "w")])
    v_body, w, phi, th, psi, dv = motion
    _, seed = AW.awsm(m, v_body, w, position, phi, th)
    first = AW.wind_relative_to_mean_motion(m, v_body, w, position, phi, th)
    earth = relative_to_mean_ground_velocity(m, w, position, phi, th, psi, dv)
    return m, AW.to_vertical_axes(m, phi, th), earth, seed, first


def _horizontal_ratio(t, a, b, ia: dict, ib: dict) -> dict:
    """Ratio of mean horizontal speeds a/b with its standard error: the paired series s_a − K s_b
    (delta method, keeps their correlation) plus each anemometer's stated scale and zero offset
    (independent heads); the mean direction offset a − b plus both heads' alignment."""
    sa, sb = np.hypot(a[:, 0], a[:, 1]), np.hypot(b[:, 0], b[:, 1])
    ma, mb = float(np.mean(sa)), float(np.mean(sb))
    k = ma / mb
    st = channel_stats(t, sa - k * sb)
    se = st.se / mb
    ui = k * math.sqrt(ia["scale"] ** 2 + ib["scale"] ** 2 + (ia["bias"] / ma) ** 2 + (ib["bias"] / mb) ** 2)
    std = math.hypot(se, ui)
    d = wrap_pi(np.arctan2(-a[:, 1], -a[:, 0]) - np.arctan2(-b[:, 1], -b[:, 0]))
    ds = channel_stats(t, np.asarray(d)).estimate()
    dstd = math.sqrt(ds.std ** 2 + ia["align"] ** 2 + ib["align"] ** 2)
    return {"speed_ratio": Estimate(k, std, st.dof * (std / se) ** 4 if se > 0 else None).to_dict(),
            "direction_offset": Estimate(ds.value, dstd, ds.dof * (dstd / ds.std) ** 4 if ds.std > 0 else None).to_dict()}


def reduce_airwake_survey(rec, pad_s: float = PAD_S, keep_series: bool = True) -> dict:
    kinds = _kinds(rec)
    sonic = kinds.get("sonic_anemometer", [])
    masts = [n for n in sonic if rec.meta(n).get("mobile")]
    refs = [n for n in sonic if not rec.meta(n).get("mobile")]
    need = {"imu": kinds.get("imu"), "attitude": kinds.get("attitude"), "heading": kinds.get("heading"),
            "track": (kinds.get("gnss") or []) + (kinds.get("range_radar") or [])}
    missing = [k for k, v in need.items() if not v] + ([] if masts else ["mobile sonic_anemometer"])
    if missing:
        raise ValueError(f"{rec.path}: an airwake survey reduction needs {', '.join(missing)} in the record")
    names = {k: v[0] for k, v in need.items()}
    imu_pos = np.asarray(rec.meta(names["imu"])["surveyed_position_m"], float)
    mast = masts[0]
    mm = rec.meta(mast)
    sockets = {n: np.asarray(p, float) for n, p in zip(mm["positions"], mm["position_sites_m"])}
    ref = refs[0] if refs else None
    ref_pos = None if ref is None else np.asarray(rec.meta(ref)["surveyed_position_m"], float)
    im = _inst(mm)
    ir = _inst(rec.meta(ref)) if ref is not None else None
    runs = sorted([r for r in rec.run_log if r["accepted"] and r["kind"] == "airwake"], key=lambda r: r["run"])
    out = []
    for r in runs:
        pos = r["maneuver"]["position"]
        tm, code = rec.channel(mast, "position")
        sel = (tm >= r["t_execute"]) & (tm <= r["t_finex"])
        t = tm[sel]
        logged = [mm["positions"][int(c)] for c in np.unique(code[sel])]
        if logged != [pos]:
            out.append({"run": r["run"], "position": pos, "error": f"mast logged at {logged}, log sheet says {pos}"})
            continue
        motion = _ship_velocity(rec, names, t, pad_s)
        rho = sockets[pos] - imu_pos
        m_b, m_v, corr, seed, first = _corrected(rec, mast, rho, t, motion)
        d = {"run": r["run"], "position": pos, "label": r["label"], "condition": r["group"],
             "relative_wind_ordered": r["maneuver"]["relative_wind"],
             "relative_wind_speed_ordered": r["maneuver"]["relative_wind_speed"],
             "t_execute": r["t_execute"], "t_finex": r["t_finex"], "n": int(t.size),
             "mean_measured_body": _stats3(t, m_b, im), "mean_measured_vertical": _stats3(t, m_v, im),
             "mean_awsm": _stats3(t, corr, im), "mean_awsm_recording": _stats3(t, corr, im, sampling=False),
             "mean_awsm_seed_order": _stats3(t, seed, im),
             "mean_rotate_first": _stats3(t, first, im),
             "rms_correction": np.std(corr - m_v, axis=0).tolist(),
             "std_measured": np.std(m_v, axis=0).tolist(), "std_awsm": np.std(corr, axis=0).tolist()}
        # the seed's finding: the mean is unchanged by the correction (difference and its uncertainty);
        # the correction does not depend on the anemometer's errors, so no instrument term here
        d["mean_change"] = _stats3(t, corr - m_v)
        if ref is not None:
            _, rm_v, rcorr, _, _ = _corrected(rec, ref, ref_pos - imu_pos, t, motion)
            d["reference_mean_awsm"] = _stats3(t, rcorr, ir)
            d["airwake_ratio"] = _horizontal_ratio(t, corr, rcorr, im, ir)
            d["airwake_ratio_uncorrected"] = _horizontal_ratio(t, m_v, rm_v, im, ir)
        if keep_series:
            d["_series"] = {"t": t, "measured_vertical": m_v, "awsm": corr, "awsm_seed_order": seed,
                            "rotate_first": first}
        out.append(d)
    return {"kind": "airwake_survey", "mast": mast, "reference": ref, "imu": names["imu"],
            "pad_s": pad_s, "runs": out}
