"""Scoring a wave buoy's directional reductions against the true sea over each of its windows (issue 13).

Per transmitted report (a record of ``record_s`` ending at its time stamp) and per method of
:func:`vtrials.reduce.directional.directional_estimate` ("fourier", "MLM", "IMLM", "MEM", "EMEP"):

* H_s: the report's 4 √m0 over its band against the true band H_s (:func:`vtrials.truth.seaway.band_truth`)
  and against the true surface's H_s over the same window at the buoy (:func:`vtrials.truth.seaway.window_hs`);
* mean direction: the method's S-weighted first moment against the components' over the same frequencies
  (the report's bins the reduction used: those with S above ``min_fraction`` of the peak), error wrapped
  to (−180°, 180°];
* spreading: the circular spread σ₁ from the same first moments, relative error σ₁/σ₁,true − 1.
Like with like: both sides are the bulk first circular moment over the same band.
"""

from __future__ import annotations

import math

import numpy as np

from vtrials.reduce.directional import directional_estimate
from vtrials.truth.seaway import band_truth, window_hs

METHODS = ("fourier", "MLM", "IMLM", "MEM", "EMEP")


def score_buoy_reports(times, reports, field, record_s: float, position=None, methods=METHODS,
                       min_fraction: float = 0.02, window_rate_hz: float = 2.0) -> list[dict]:
    """One row per report: true values, H_s errors and per-method direction/spreading errors (degrees, ratio).

    ``reports``: :class:`vtrials.reduce.directional.FourierCoefficients` per report (the buoy's band is the
    reports' frequency grid); ``position``: (north, east) [m] of a moored buoy or callables of t for a
    drifting one (None: the window H_s is not computed); ``min_fraction``: frequencies with S below that
    fraction of the peak are left out of the directional bulk values (the noise-dominated tails).
    """
    rows = []
    for t_end, fc in zip(times, reports):
        lo, hi = float(fc.omega[0]), float(fc.omega[-1])
        dw = float(fc.omega[1] - fc.omega[0]) if fc.omega.size > 1 else 0.0
        truth = band_truth(field, lo - 0.5 * dw, hi + 0.5 * dw)
        hs = 4.0 * math.sqrt(max(float(np.trapezoid(fc.S, fc.omega)), 0.0))
        row = {"t_end": float(t_end), "hs_true": truth["hs_m"], "hs": hs,
               "hs_error": hs / truth["hs_m"] - 1.0 if truth["hs_m"] > 0 else math.nan,
               "mean_direction_true_deg": math.degrees(truth["mean_direction_to"]),
               "spread_true_deg": math.degrees(truth["spread"])}
        if position is not None:
            hw = window_hs(field, position[0], position[1], float(t_end) - record_s, float(t_end), window_rate_hz)
            row["hs_window"] = hw
            row["hs_window_error"] = hs / hw - 1.0 if hw > 0 else math.nan
        used = None
        for m in methods:
            w_used, _, _, _, md, sg = directional_estimate(fc, m, min_fraction=min_fraction)
            if used is None:  # the frequencies the reduction used (the same for every method)
                used = band_truth(field, bins=(w_used, dw))
                row["mean_direction_true_deg"] = math.degrees(used["mean_direction_to"])
                row["spread_true_deg"] = math.degrees(used["spread"])
            row[f"{m}_direction_error_deg"] = math.degrees(math.remainder(md - used["mean_direction_to"], 2 * math.pi))
            row[f"{m}_spread_error"] = sg / used["spread"] - 1.0
        rows.append(row)
    return rows


def summarise(rows: list[dict], methods=METHODS, direction_tol_deg: float = 10.0, spread_tol: float = 0.20) -> dict:
    """Per method: mean |direction error| [deg], max, mean and sd of the spreading error, the fraction of
    reports within both tolerances; and the H_s error's mean and sd."""
    out = {}
    for m in methods:
        d = np.array([r[f"{m}_direction_error_deg"] for r in rows])
        s = np.array([r[f"{m}_spread_error"] for r in rows])
        ok = (np.abs(d) <= direction_tol_deg) & (np.abs(s) <= spread_tol)
        out[m] = {"direction_abs_mean_deg": float(np.mean(np.abs(d))), "direction_abs_max_deg": float(np.max(np.abs(d))),
                  "spread_error_mean": float(np.mean(s)), "spread_error_sd": float(np.std(s, ddof=1)) if s.size > 1 else 0.0,
                  "spread_abs_max": float(np.max(np.abs(s))), "fraction_within": float(np.mean(ok)), "n": int(d.size)}
    e = np.array([r["hs_error"] for r in rows])
    out["hs"] = {"error_mean": float(np.mean(e)), "error_sd": float(np.std(e, ddof=1)) if e.size > 1 else 0.0}
    if rows and "hs_window_error" in rows[0]:
        ew = np.array([r["hs_window_error"] for r in rows])
        out["hs_window"] = {"error_mean": float(np.mean(ew)), "error_sd": float(np.std(ew, ddof=1)) if ew.size > 1 else 0.0}
    return out


def score_wave_record(record, field) -> dict:
    """Every sea sensor of one trial record against the true sea: per wave buoy (spectra output) the
    :func:`summarise` of its reports (the window H_s for a moored buoy at its deployed position), per wave
    radar the ratio of its 2-min H_s to the seaway's (mean, sd, n) and its median peak period over the
    seaway's. Empty when the record has no sea sensor (or the sea is calm)."""
    from vtrials.reduce.directional import buoy_reports
    from vtrials.truth.seaway import band_truth
    out = {}
    if field is None:
        return out
    for name in record.instruments:
        meta = record.meta(name)
        kind = meta.get("kind")
        if kind == "wave_buoy" and meta.get("output") == "spectra":
            t, reps = buoy_reports(record, name)
            if not reps:
                continue
            pos = tuple(meta["deployed_position_m"]) if meta.get("mooring") == "moored" else None
            out[name] = summarise(score_buoy_reports(t, reps, field, float(meta["record_s"]), position=pos))
        elif kind == "wave_radar":
            _, hs = record.channel(name, "hs")
            _, tp = record.channel(name, "tp")
            if np.size(hs) == 0:
                continue
            r = np.asarray(hs) / band_truth(field)["hs_m"]
            out[name] = {"hs_ratio_mean": float(np.mean(r)), "hs_ratio_sd": float(np.std(r, ddof=1)) if r.size > 1 else 0.0,
                         "n": int(r.size), "tp_ratio_median": float(np.nanmedian(tp)) / field.tp_s}
    return out
