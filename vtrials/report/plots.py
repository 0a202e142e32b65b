"""Plots written by the CLI (matplotlib, Agg backend, PNG)."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def trajectory_plot(result, path) -> None:
    """Tracks over ground (north up, in ship lengths, EXECUTE marked) and heading / rudder histories."""
    L = result.scenario.vessel.length
    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(13, 6), gridspec_kw={"width_ratios": [1, 1.2]})
    for m in result.maneuvers:
        c = m.columns
        x0, y0 = c["x"][0], c["y"][0]
        line, = ax.plot((c["y"] - y0) / L, (c["x"] - x0) / L, lw=1.2, label=m.name)
        ex = np.searchsorted(c["t"], m.execute_time_s)
        if ex < len(c["t"]):
            ax.plot((c["y"][ex] - y0) / L, (c["x"][ex] - x0) / L, "o", color=line.get_color(), ms=4)
        te = c["t"] - m.execute_time_s
        ax2.plot(te, np.degrees(c["heading"] - c["heading"][min(ex, len(te) - 1)]), color=line.get_color(), lw=1.2)
        ax2.plot(te, np.degrees(c["rudder_0"]), color=line.get_color(), lw=0.8, ls="--")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("east / L")
    ax.set_ylabel("north / L")
    ax.set_title(f"{result.scenario.vessel.name}: tracks over ground (o = EXECUTE)")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7, loc="best")
    ax2.set_xlabel("time after EXECUTE [s]")
    ax2.set_ylabel("heading change (solid), rudder (dashed) [deg]")
    ax2.grid(True, alpha=0.3)
    ax2.set_title(result.scenario.head.title, fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110, format="png")
    plt.close(fig)
