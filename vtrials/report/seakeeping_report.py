"""Report pages of a seakeeping trial: per leg the transfer functions (reduced with their 95 % band and
coherence, the true transfer function of the realised sea and the long-crested RAO at the sea's mean
direction), a polar plot of the legs' headings relative to the waves over the probe's encounter
spectra, the probe H_s and RMS motions against truth (the fusion-scatter view of seed 004's figures),
and a table per leg. Every number shown is in results.json."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from vtrials.report.trial_report import _fig, _fmt, _save

UNITS = {"heave": "m/m", "vertical_acc": "(m/s²)/m", "roll": "rad/m", "pitch": "rad/m"}


def _arr(x):
    return np.array([np.nan if v is None else v for v in x], float)


def figures(tr: dict, out: Path) -> list[str]:
    plt = _fig()
    names = []
    red = {L["run"]: L for L in tr["reduced"]["legs"]}
    for sc in tr["legs"]:
        leg = red[sc["run"]]
        wb = _arr(leg["omega_e"])
        fig, axs = plt.subplots(3, 4, figsize=(15, 8.5), sharex=True,
                                gridspec_kw={"height_ratios": [3, 2, 1.2]})
        for j, n in enumerate(("heave", "vertical_acc", "roll", "pitch")):
            r = leg["responses"][n]
            t = sc["true_transfer"][n]
            H = _arr(r["H_re"]) + 1j * _arr(r["H_im"])
            Ht = _arr(t["H_re"]) + 1j * _arr(t["H_im"])
            H0 = _arr(t["H_rao_mean_direction_re"]) + 1j * _arr(t["H_rao_mean_direction_im"])
            det = np.asarray(r["determined"], bool)
            ax = axs[0, j]
            ax.fill_between(wb, _arr(r["amp_lo95"]), _arr(r["amp_hi95"]), color="C0", alpha=0.2, label="95 % band")
            ax.plot(wb, np.abs(H), "C0-", lw=0.8, label="H₁ (records)")
            ax.plot(wb[det], np.abs(H[det]), "C0o", ms=3, label="determined (γ²>0.8)")
            ax.plot(wb, np.abs(Ht), "k-", lw=1.2, label="true (realised sea)")
            ax.plot(wb, np.abs(H0), "k--", lw=0.8, label="RAO, mean direction")
            ax.set_title(f"{n} [{UNITS[n]}]")
            top = np.nanmax(np.abs(Ht)) if np.any(np.isfinite(Ht)) else 1.0
            ax.set_ylim(0, 1.6 * top if top > 0 else 1.0)
            ax = axs[1, j]
            ax.plot(wb, np.degrees(np.angle(H)), "C0.", ms=3)
            ax.plot(wb, np.degrees(np.angle(Ht)), "k-", lw=1)
            ax.set_ylim(-180, 180)
            ax.set_ylabel("phase [°]") if j == 0 else None
            ax = axs[2, j]
            ax.plot(wb, _arr(r["coherence"]), "C0-", lw=0.8)
            ax.plot(wb, _arr(t["coherence"]), "k-", lw=0.8)
            ax.axhline(0.8, color="r", lw=0.6)
            ax.set_ylim(0, 1.02)
            ax.set_xlabel("encounter frequency ω_e [rad/s]")
            ax.set_ylabel("γ²") if j == 0 else None
            ax.set_xlim(0, 3.0)
        axs[0, 0].legend(fontsize=7)
        fig.suptitle(f"run {sc['run']}: {sc['label']} — transfer functions from the bow probe's wave "
                     f"(probe-referred phase)")
        names.append(_save(fig, out, f"seakeeping_tf_run{sc['run']}.png"))
    # polar: the true directional spectrum with the legs' courses; the legs relative to the waves
    fig = plt.figure(figsize=(13, 6.5))
    ds = tr["truth"].get("directional_spectrum")
    ax = fig.add_subplot(1, 2, 1, projection="polar")
    ax.set_theta_zero_location("N")
    ax.set_theta_direction(-1)
    if ds:
        th, r = np.meshgrid(np.asarray(ds["from_edges_rad"]), np.asarray(ds["omega_edges"]))
        S = np.asarray(ds["S"])
        m = ax.pcolormesh(th, r, S, cmap="Blues", shading="flat")
        fig.colorbar(m, ax=ax, shrink=0.6, label="S(ω, θ) [m² s/rad²]")
    for leg in tr["reduced"]["legs"]:
        if math.isfinite(leg["heading"]):
            ax.annotate("", xy=(leg["heading"], 2.4), xytext=(0, 0),
                        arrowprops={"arrowstyle": "->", "color": "C3", "lw": 1.0})
            ax.text(leg["heading"], 2.55, str(leg["run"]), color="C3", fontsize=8)
    sb = tr["reduced"].get("ship_buoy")
    if sb:
        ax.plot([math.radians(sb["from_deg"])] * 2, [0.0, 2.5], "C1-", lw=2.0)
        ax.text(math.radians(sb["from_deg"]), 2.7, "ship as buoy", color="C1", fontsize=8)
    ax.set_title("true directional spectrum (waves coming from; radius ω [rad/s])\nred: the legs' courses "
                 "(gyro)" + ("; orange: the ship-as-buoy mean direction" if sb else ""), fontsize=9)
    ax = fig.add_subplot(1, 2, 2, projection="polar")
    ax.set_theta_zero_location("N")
    ax.set_theta_direction(-1)
    for leg in tr["reduced"]["legs"]:
        if not math.isfinite(leg["mu"]):
            continue
        rel = leg["mu"] - math.pi  # direction the waves come from, re the bow (+ starboard)
        wb = _arr(leg["omega_e"])
        S = _arr(leg["probe_spectrum"])
        keep = wb <= 3.0
        ax.scatter(np.full(keep.sum(), rel), wb[keep], c=S[keep], s=12, cmap="viridis")
        ax.annotate(f"{leg['run']}", (rel, 3.1), fontsize=8)
    ax.set_rlim(0, 3.3)
    ax.set_title("legs: where the waves come from re the bow (observed direction); radius ω_e [rad/s],\n"
                 "colour: the probe's encounter spectrum", fontsize=9)
    names.append(_save(fig, out, "seakeeping_polar.png"))
    # scatter: reduced vs true RMS motions and probe H_s (normalised), as seed 004's fusion scatter
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for k, n in enumerate(("heave", "vertical_acc", "roll", "pitch")):
        x = [sc["rms"][n]["truth"] for sc in tr["legs"] if n in sc["rms"]]
        y = [sc["rms"][n]["reduced"] / sc["rms"][n]["truth"] for sc in tr["legs"] if n in sc["rms"]]
        ax.plot(range(len(y)), y, "os^v"[k], label=f"RMS {n}")
    y = [sc["hs_probe"]["reduced"] / sc["hs_probe"]["truth"] for sc in tr["legs"]]
    ax.plot(range(len(y)), y, "k*", ms=9, label="probe H_s")
    ax.axhline(1.0, color="k", lw=0.6)
    ax.set_xlabel("leg (in order)")
    ax.set_ylabel("reduced / true")
    ax.legend(fontsize=7)
    names.append(_save(fig, out, "seakeeping_rms.png"))
    wf = tr.get("wave_fusion")
    if wf and wf["legs"]:
        # seed 004's fusion scatter, per leg: the radar's H_s and the fused ones over the true sea's
        fig, ax = plt.subplots(figsize=(7, 4.5))
        x = np.arange(len(wf["legs"]))
        ax.plot(x, [L["radar_ratio"] for L in wf["legs"]], "ks", label="radar")
        for k, (c, mk) in enumerate(zip(tr["reduced"]["wave_fusion"]["combos"], "o^v")):
            ax.plot(x, [L["fused_ratio"][c] for L in wf["legs"]], mk, color=f"C{k}", label=f"fused, {c}")
        ax.axhspan(0.85, 1.15, color="0.9")
        ax.axhline(1.0, color="k", lw=0.6)
        ax.set_xticks(x, [str(L["run"]) for L in wf["legs"]])
        ax.set_xlabel("run")
        ax.set_ylabel("H_s / true H_s")
        ax.legend(fontsize=7)
        ax.set_title("wave fusion (seed 004): radar H_s and radar × measured/predicted motion RMS", fontsize=9)
        names.append(_save(fig, out, "seakeeping_fusion.png"))
    return names


def markdown(tr: dict, figs: list[str]) -> list[str]:
    L = [f"## {tr['name']} (seakeeping star pattern)", "",
         f"True H_s of the sea {tr['truth']['hs']:.3f} m. Transfer functions H₁ = G_xy/G_xx from the bow wave "
         f"probe's elevation to each motion, scored in the bins the reduction reports as determined "
         f"(γ² > {tr['reduced']['coherence_min']:g} and at least 1 % of the response's spectral peak) against the "
         f"true transfer function of the realised sea.", "",
         "| response | bins | median abs. amplitude error | max | within 10 % | amplitude coverage | phase coverage |",
         "|---|---|---|---|---|---|---|"]
    for n, s in tr["summary"].items():
        L.append(f"| {n} | {s['bins']} | {100 * s['median_abs_amp_error']:.1f} % | {100 * s['max_abs_amp_error']:.1f} % | "
                 f"{100 * s['within_10pct']:.0f} % | {100 * s['amp_coverage']:.0f} % | {100 * s['phase_coverage']:.0f} % |")
    L += ["", "| run | leg | speed [m/s] | μ [°] | H_s probe (true) [m] | RMS heave [m] | RMS roll [°] | RMS pitch [°] | "
              "determined bins h/a/r/p |", "|---|---|---|---|---|---|---|---|---|"]
    red = {x["run"]: x for x in tr["reduced"]["legs"]}
    for sc in tr["legs"]:
        leg = red[sc["run"]]
        rm = sc["rms"]
        L.append(f"| {sc['run']} | {sc['label']} | {_fmt(leg['speed'])} | {_fmt(math.degrees(leg['mu']), 0)} | "
                 f"{_fmt(sc['hs_probe']['reduced'], 3)} ({_fmt(sc['hs_probe']['truth'], 3)}) | "
                 f"{_fmt(rm['heave']['reduced'], 3)} ({_fmt(rm['heave']['truth'], 3)}) | "
                 f"{_fmt(math.degrees(rm['roll']['reduced']))} ({_fmt(math.degrees(rm['roll']['truth']))}) | "
                 f"{_fmt(math.degrees(rm['pitch']['reduced']))} ({_fmt(math.degrees(rm['pitch']['truth']))}) | "
                 + "/".join(str(sc["transfer"][n]["bins"]) for n in ("heave", "vertical_acc", "roll", "pitch")) + " |")
    L.append("")
    L += ship_buoy_markdown(tr)
    L += wave_fusion_markdown(tr)
    L += [f"![{f}]({f})" for f in figs]
    L.append("")
    return L


def wave_fusion_markdown(tr: dict) -> list[str]:
    """Seed 004's wave fusion per leg: the radar's and the fused H_s against the true sea's."""
    wf, sc = tr["reduced"].get("wave_fusion"), tr.get("wave_fusion")
    if not wf or not sc:
        return []
    combos = wf["combos"]
    L = ["### Wave fusion (seed 004)", "",
         f"The wave radar (`{wf['radar']}`) H_s times r, the mean of measured over predicted motion RMS "
         f"(design-stage RAOs, `{wf['design_file']}`); true H_s {sc['hs_true']:.3f} m.", "",
         "| run | leg | radar / true | " + " | ".join(f"{c} / true" for c in combos) + " |",
         "|---|---|---|" + "---|" * len(combos)]
    for leg in sc["legs"]:
        L.append(f"| {leg['run']} | {leg['label']} | {leg['radar_ratio']:.3f} | "
                 + " | ".join(f"{leg['fused_ratio'][c]:.3f}" for c in combos) + " |")
    s = sc["summary"]
    if s:
        L += ["", "| | mean | std | std radar / std | within 15 % |", "|---|---|---|---|---|",
              f"| radar | {s['radar']['mean']:.3f} | {s['radar']['std']:.3f} | | {s['radar']['within_15pct']} |"]
        L += [f"| {c} | {s[c]['mean']:.3f} | {s[c]['std']:.3f} | {s[c]['scatter_reduction']:.1f} | {s[c]['within_15pct']} |"
              for c in combos]
    L.append("")
    return L


def ship_buoy_markdown(tr: dict) -> list[str]:
    """The ship as a wave buoy: the one sea fitted to all legs against the true sea, per leg."""
    sb, sc = tr["reduced"].get("ship_buoy"), tr.get("ship_buoy")
    if not sb or not sc:
        return []
    tune = sb["roll_tuning"]
    L = ["### The ship as a wave buoy", "",
         f"One sea fitted to every leg's heave, roll and pitch with the team's design-stage RAOs "
         f"(`{sb['design_file']}`): H_s {sb['hs']:.3f} m (true {tr['truth']['hs']:.3f} m), T_p {sb['tp']:.2f} s, "
         f"γ {sb['gamma']:.2f}, s {sb['s']:.1f}, from {sb['from_deg']:.1f}° (gyro north); port and starboard told by "
         f"the {sb['side_from']}" + (f"; roll stiffness {100 * tune[0]:+.0f} %, damping {100 * tune[1]:+.1f} % of "
                                     f"critical from the design's" if tune else "") + ".", "",
         "| run | leg | waves from (true) [° off the bow] | direction error [°] | side | reliable |",
         "|---|---|---|---|---|---|"]
    for leg in sc["legs"]:
        L.append(f"| {leg['run']} | {leg['label']} | {leg['from_rel_deg']:+.1f} ({leg['from_rel_true_deg']:+.1f}) | "
                 f"{leg['dir_error_deg']:+.1f} | {'right' if leg['side_right'] else 'WRONG'} | "
                 f"{'yes' if leg['reliable'] else 'no'} |")
    for key, s in sc["summary"].items():
        L.append("")
        L.append(f"{key} legs ({s['legs']}): H_s within 15 % on {s['hs_within_15pct']}, direction within 15° on "
                 f"{s['dir_within_15deg']}, side right on {s['side_right']}.")
    L.append("")
    return L
