"""Writing a trial's record (what the trials team has) and its instruments' drawn errors (truth).

The record holds one group per instrument (its own time coordinate and channels, SI units, and the
metadata the team knows: kind, site and its surveyed position, nominal calibration and rate), an
``_events`` group with the marks the data acquisition system logged (COMEX, EXECUTE, FINEX, with the
run number), a ``_telegraph`` group with the engine-order log, and the team's knowledge of the ship
and the site as a JSON attribute. Nothing in it is truth: the instruments' actual error parameters go
into the truth file.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from vtrials import __version__
from vtrials.records.netcdf import write_groups

EVENT_CODES = {1: "COMEX", 2: "EXECUTE", 3: "FINEX"}
ORDER_CODES = {1: "ahead_1_3", 2: "ahead_2_3", 3: "standard", 4: "full", 5: "flank", 6: "stop",
               7: "back_1_3", 8: "back_2_3", 9: "back_full", 10: "back_emergency"}
ORDER_NUMBER = {v: k for k, v in ORDER_CODES.items()}


def _json_attr(v):
    if isinstance(v, (dict, list, tuple)):
        return json.dumps(v, sort_keys=True)
    if v is None:
        return ""
    return v


def record_groups(iset, t_end: float, events: list[tuple[float, int, int]],
                  orders: list[tuple[float, str]], t_start: float = -np.inf, settings=None) -> dict:
    """Groups for :func:`vtrials.records.netcdf.write_groups` from an instrument set's readings.

    Only samples stamped in [t_start, t_end] (the span of the recording) are kept. ``settings``:
    (t, shaft, rps order, pitch order, mode code) rows of the engine-room log, written as ``_settings``.
    """
    groups = {}
    for name, dev in iset.devices.items():
        t, ch = iset.readings(name)
        keep = (t <= t_end) & (t >= t_start)
        variables = {c: (ch[c][keep], units, long) for c, (units, long) in dev.channels.items()}
        attrs = dev.meta()
        clk = iset.clocks.get(name)
        if clk is not None:
            # the logger clock's stated accuracy (what the team knows of its time stamps): offset and
            # drift standard deviations, from its synchronisation at t_ref
            attrs.update(clock_offset_sd_s=clk.sd, clock_drift_ppm_sd=clk.drift_ppm_sd, clock_t_ref_s=clk.t_ref)
        groups[name] = {"time": t[keep], "variables": variables,
                        "attrs": {k: _json_attr(v) for k, v in attrs.items()}}
    ev = sorted(events)
    groups["_events"] = {"time": np.array([e[0] for e in ev]),
                         "variables": {"run": (np.array([e[1] for e in ev], float), "1", "run number"),
                                       "code": (np.array([e[2] for e in ev], float), "1",
                                                "event code (see the codes attribute)")},
                         "attrs": {"codes": json.dumps({str(k): v for k, v in EVENT_CODES.items()})}}
    groups["_telegraph"] = {"time": np.array([o[0] for o in orders]),
                            "variables": {"order": (np.array([ORDER_NUMBER[o[1]] for o in orders], float), "1",
                                                    "engine order code (see the codes attribute)")},
                            "attrs": {"codes": json.dumps({str(k): v for k, v in ORDER_CODES.items()})}}
    if settings is not None:
        st = np.array(settings, dtype=float).reshape(-1, 5)
        groups["_settings"] = {"time": st[:, 0], "variables": {
            "shaft": (st[:, 1], "1", "shaft index"),
            "rps_order": (st[:, 2], "s-1", "ordered shaft speed"),
            "pitch_order": (st[:, 3], "1", "ordered pitch ratio (CP)"),
            "mode": (st[:, 4], "1", "shaft mode: 0 governed, 1 trailed, 2 locked")},
            "attrs": {"content": "engine-room log of shaft orders"}}
    return groups


def record_contents(iset, t_end: float, events, orders, title: str, extra_attrs: dict,
                    t_start: float = -np.inf, settings=None) -> tuple[dict, dict]:
    """(groups, global attributes) of a trial record (:func:`record_groups`; the file's attributes)."""
    attrs = {"Conventions": "CF-1.10", "title": title, "content": "record", "vtrials_version": __version__,
             "team_knowledge": json.dumps(iset.team, sort_keys=True),
             "time_reference": "seconds of the data acquisition system's clock from the start of the trial"}
    attrs.update({k: _json_attr(v) for k, v in extra_attrs.items()})
    return record_groups(iset, t_end, events, orders, t_start, settings), attrs


def write_record(path: Path, iset, t_end: float, events, orders, title: str, extra_attrs: dict,
                 t_start: float = -np.inf, settings=None) -> None:
    write_groups(path, *record_contents(iset, t_end, events, orders, title, extra_attrs, t_start, settings))
