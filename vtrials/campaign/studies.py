"""Helpers of the published-finding studies (benchmarks/study_strasser2015.py, study_insel2008.py).

:func:`current_methods` re-reduces the runs of one scored standardization trial (a ``results.json``
trial document: its ``reduced`` runs come from the record alone, its ``truth`` runs from the true state)
over a chosen subset of double runs per spot, with the two current corrections of ITTC
7.5-04-01-01.1 (2017) / ISO 15016:2015 side by side:

* mean of means per spot (:func:`vtrials.reduce.current.mean_of_means`: the two-run average for one
  double run, (V₁ + 3V₂ + 3V₃ + V₄)/8 for two) — textbook, without the operational reduction's
  trend correction of two-run spots;
* the ITTC iterative method over all kept runs (:func:`vtrials.reduce.current.ittc_iterative`, the
  model chosen as the reduction does it: the semidiurnal "tidal" model when the runs leave it at
  least two degrees of freedom, else "linear", else "constant") and per spot its heading-balanced
  speed (:func:`vtrials.reduce.current.iterative_spot_speed`);

each scored against the spot's true speed through water over the same runs
(:func:`vtrials.score.trials.spot_stw_truth`, the scoring's own definition).

:func:`rms_table` summarises errors per (case, method, spot) with bootstrap 95 % intervals.
"""

from __future__ import annotations

import math

import numpy as np

from vtrials.reduce import current as CUR
from vtrials.score.trials import spot_stw_truth

MODELS = ("tidal", "linear", "constant")


def select_runs(runs: list[dict], pattern: dict[int, int]) -> list[dict]:
    """The first 2·pattern[group] runs (in run order) of each spot named in ``pattern``
    (group → number of double runs kept); spots not named are dropped."""
    out = []
    for g, n_dr in pattern.items():
        rs = sorted((r for r in runs if r["group"] == g), key=lambda r: r["run"])
        if len(rs) < 2 * n_dr:
            raise ValueError(f"spot {g} has {len(rs)} runs, fewer than {n_dr} double runs")
        out += rs[:2 * n_dr]
    return sorted(out, key=lambda r: r["run"])


def iterative_fit(t, vg, heading, power, min_dof: int = 2):
    """The ITTC iterative analysis with the richest current model the runs allow (≥ min_dof)."""
    for model in MODELS:
        try:
            it = CUR.ittc_iterative(t, vg, heading, power, model=model)
        except (ValueError, np.linalg.LinAlgError, RuntimeError):
            continue
        if it.dof >= min_dof:
            return it
    return None


def current_methods(trial: dict, pattern: dict[int, int]) -> list[dict]:
    """Per kept spot: truth, mean of means and ITTC iterative speed through water [m/s] with errors.

    trial: one ``results.json`` trial of kind standardization (``reduced.runs`` with run, group, t_mid,
    course, vg{value, std}, power{value}; ``truth.runs`` with run, stw, heading). pattern: group →
    double runs kept (e.g. {1: 1, 2: 2, 3: 2} for 1+2+2).
    """
    runs = select_runs(trial["reduced"]["runs"], pattern)
    truth = {r["run"]: r for r in trial["truth"]["runs"]}
    t = np.array([r["t_mid"] for r in runs])
    vg = np.array([r["vg"]["value"] for r in runs])
    vg_sd = np.array([r["vg"]["std"] for r in runs])
    hd = np.array([r["course"] for r in runs])
    pw = np.array([r["power"]["value"] for r in runs])
    it = iterative_fit(t, vg, hd, pw)
    out = []
    for g in pattern:
        idx = [i for i, r in enumerate(runs) if r["group"] == g]
        v_true = float(spot_stw_truth([truth[runs[i]["run"]] for i in idx]))
        mom = CUR.mean_of_means(vg[idx], vg_sd[idx])
        d = {"group": g, "n_runs": len(idx), "truth": v_true,
             "mom": {"value": mom.value, "std": mom.std, "error": mom.value - v_true}}
        if it is not None:
            e = CUR.iterative_spot_speed(it, t, hd, idx, vg_std=vg_sd)
            d["iterative"] = {"value": e.value, "std": e.std, "error": e.value - v_true, "model": it.model,
                              "dof": it.dof}
        else:
            d["iterative"] = None
        out.append(d)
    return out


def bootstrap_rms(err, n_boot: int = 2000, seed: int = 0) -> dict:
    """RMS of errors with a percentile-bootstrap 95 % interval (resampling replicates)."""
    e = np.asarray([x for x in err if x is not None and math.isfinite(x)], float)
    if e.size == 0:
        return {"n": 0, "rms": math.nan, "lo95": math.nan, "hi95": math.nan, "mean": math.nan,
                "max_abs": math.nan}
    rng = np.random.default_rng(seed)
    bs = np.sqrt(np.mean(rng.choice(e, size=(n_boot, e.size)) ** 2, axis=1))
    return {"n": int(e.size), "rms": float(np.sqrt(np.mean(e ** 2))), "lo95": float(np.quantile(bs, 0.025)),
            "hi95": float(np.quantile(bs, 0.975)), "mean": float(np.mean(e)), "max_abs": float(np.max(np.abs(e)))}


def paired_rms_difference(e1, e2, n_boot: int = 2000, seed: int = 1) -> dict:
    """RMS(e1) − RMS(e2) over paired replicates with a bootstrap 95 % interval (same resamples for both)."""
    a = np.asarray(e1, float)
    b = np.asarray(e2, float)
    ok = np.isfinite(a) & np.isfinite(b)
    a, b = a[ok], b[ok]
    if a.size == 0:
        return {"n": 0, "diff": math.nan, "lo95": math.nan, "hi95": math.nan}
    rng = np.random.default_rng(seed)
    k = rng.integers(0, a.size, size=(n_boot, a.size))
    d = np.sqrt(np.mean(a[k] ** 2, axis=1)) - np.sqrt(np.mean(b[k] ** 2, axis=1))
    return {"n": int(a.size), "diff": float(np.sqrt(np.mean(a ** 2)) - np.sqrt(np.mean(b ** 2))),
            "lo95": float(np.quantile(d, 0.025)), "hi95": float(np.quantile(d, 0.975))}
