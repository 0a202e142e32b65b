"""The identification's report figure: coefficients with their 95 % intervals (against the truth when
scored), held-back predictions against the truth, and the cross-validation of model structures."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from vtrials.records.netcdf import atomic_path  # noqa: E402


def identification_plot(doc: dict, path) -> None:
    sc = doc.get("score")
    traces = (doc.get("output_error") or {}).get("traces") or []
    fig, ax = plt.subplots(1, 4 if traces else 3, figsize=(20 if traces else 15, 4.8))
    first = [k for k in doc.get("intervals_checked") or ("Y_v", "Y_r", "N_v", "N_r") if k in doc["coefficients"]]
    terms = first + [k for k in doc["coefficients"] if k not in first]
    prime = not str(doc.get("units", "")).startswith("SI")
    if sc and not prime:   # dimensional terms span eight decades: errors relative to the truth
        terms = [k for k in terms if sc["coefficients"][k]["truth"] != 0.0]
    y = np.arange(len(terms))
    c = [doc["coefficients"][k] for k in terms]
    val = np.array([x["value"] for x in c])
    lo, hi = np.array([x["lo95"] for x in c]), np.array([x["hi95"] for x in c])
    if sc:
        t = np.array([sc["coefficients"][k]["truth"] for k in terms])
        scale = np.ones_like(t) if prime else np.abs(t)
        v, lo, hi = (val - t) / scale, (lo - t) / scale, (hi - t) / scale
        ax[0].axvline(0.0, color="k", lw=0.8)
        ax[0].set_xlabel("identified − true " + ("(non-dimensional)" if prime else "over |true|") + ", 95 % interval")
    elif prime:
        v = val
        ax[0].set_xlabel("identified value (non-dimensional), 95 % interval")
    else:
        scale = np.abs(val)
        v, lo, hi = val / scale, lo / scale, hi / scale
        ax[0].set_xlabel("identified value over its magnitude (SI terms), 95 % interval")
    oe = (doc.get("output_error") or {}).get("coefficients", {})
    ax[0].errorbar(v, y, xerr=[v - lo, hi - v], fmt="o", ms=4, capsize=3,
                   label="equation error" if oe else None)
    if oe:   # the output-error refinement beside it, on the same scale
        ko = [i for i, k in enumerate(terms) if k in oe]
        o = [oe[terms[i]] for i in ko]
        ov, olo, ohi = (np.array([x[key] for x in o]) for key in ("value", "lo95", "hi95"))
        if sc:
            ov, olo, ohi = ((a - t[ko]) / scale[ko] for a in (ov, olo, ohi))
        elif not prime:
            ov, olo, ohi = (a / np.abs(val[ko]) for a in (ov, olo, ohi))
        ax[0].errorbar(ov, y[ko] + 0.3, xerr=[ov - olo, ohi - ov], fmt="s", ms=4, capsize=3, color="C3",
                       label="output error (LM)")
        ax[0].legend(fontsize=8)
    # linear near zero (prime units up to 0.01; relative errors up to 30 %), logarithmic beyond
    ax[0].set_xscale("symlog", linthresh=0.01 if prime else 0.3)
    ax[0].set_yticks(y, terms)
    ax[0].invert_yaxis()
    ax[0].set_title(f"{doc['ship']}: hull coefficients ({doc['structure']})")
    if doc["predictions"]:
        labels, pred, true = [], [], []
        for i, p in enumerate(doc["predictions"]):
            rows = sc["predictions"][i]["errors"] if sc else {}
            for k, val in p["predicted"].items():
                labels.append(f"{p['name']}\n{k}")
                pred.append(val)
                true.append(rows[k]["truth"] if k in rows else np.nan)
        x = np.arange(len(labels))
        ax[1].bar(x - 0.2, pred, 0.4, label="predicted (identified model)")
        if sc:
            ax[1].bar(x + 0.2, true, 0.4, label="truth")
        ax[1].set_xticks(x, labels, rotation=75, fontsize=6)
        ax[1].legend(fontsize=8)
        ax[1].set_title("held-back maneuvers (m, deg)")
    else:
        ax[1].text(0.5, 0.5, "no held-back maneuvers", ha="center", transform=ax[1].transAxes)
    cv = doc.get("cross_validation") or {}
    if cv:
        names = list(cv)
        eqs = list(cv[names[0]])
        w = 0.8 / len(eqs)
        for j, eq in enumerate(eqs):   # each equation relative to its best structure (N and N m alike)
            best = min(cv[n][eq] for n in names)
            ax[2].bar(np.arange(len(names)) + w * (j - (len(eqs) - 1) / 2), [cv[n][eq] / best for n in names], w,
                      label=eq)
        ax[2].set_xticks(np.arange(len(names)), names)
        ax[2].set_ylabel("RMS of held-out hull force / best structure's")
        ax[2].legend(fontsize=8)
        ax[2].set_title("leave-one-maneuver-out cross-validation")
    if traces:   # the output-error fit: yaw rate measured (smoothed) and simulated, maneuvers end to end
        t0 = 0.0
        for i, tr in enumerate(traces):
            t = np.asarray(tr["t"]) - tr["t"][0] + t0
            lab = (lambda s: s) if i == 0 else (lambda s: None)
            ax[3].plot(t, np.degrees(tr["r_measured"]), "k", lw=1.2, label=lab("measured (smoothed)"))
            ax[3].plot(t, np.degrees(tr["r_start"]), "C0--", lw=0.9, label=lab("model, equation-error coefficients"))
            ax[3].plot(t, np.degrees(tr["r_refined"]), "C3", lw=0.9, label=lab("model, output-error (LM)"))
            ax[3].text(t0, 0.98, tr["name"], fontsize=6, rotation=90, va="top", transform=ax[3].get_xaxis_transform())
            t0 = t[-1] + 5.0
        ax[3].set_xlabel("time, maneuvers end to end (s)")
        ax[3].set_ylabel("yaw rate (deg/s)")
        ax[3].legend(fontsize=7)
        ax[3].set_title("output-error fit: simulated from the recorded inputs")
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=110, format="png")
    plt.close(fig)
