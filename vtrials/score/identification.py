"""Scoring an identification (:mod:`vtrials.sysid.identify`) against the truth.

References, each by its own definition:

* coefficients: the simulator's hull model of the ship (``models/<ship>/ship.toml``, section
  ``hull_mmg``, X_0 = −R'_0; or ``hull_blanke``, dimensional). A term the model lacks is true at 0;
* held-back maneuvers: the truth metrics of the run that recorded them (``results.json`` of the run
  directory holding the record, :mod:`vtrials.truth.metrics`: advance, transfer and tactical diameter
  of the water track, zig-zag overshoots of the true heading).
"""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

from vtrials.errors import InputError

_WHERE = "vtrials.score.identification"
#: Acceptance of issue 16: linear derivatives within 10 %; held-back turns within 5 %, overshoots 1.5°.
LIMITS = {"linear_rel": 0.10, "turn_rel": 0.05, "overshoot_deg": 1.5}
_TURN = ("advance_m", "transfer_m", "tactical_diameter_m")
_ZIGZAG = ("first_overshoot_deg", "second_overshoot_deg")


def true_coefficients(ship: str) -> dict:
    """{term: value} of the simulator's hull model of ``ship``: MMG (Y&Y 2015 prime system, X_0 = −R'_0)
    or Blanke's 4-DOF model (dimensional, SI; its resistance curve is a table, not a term)."""
    from vtrials.physics.vessel import load_vessel
    v = load_vessel(ship)
    if v.meta.hull_model not in ("mmg", "blanke"):
        raise InputError(_WHERE, "ship", f"{ship!r} has a {v.meta.hull_model!r} hull model; allowed: an mmg or "
                         "blanke hull (its coefficients are the identification's truth)")
    h = dataclasses.asdict(v.hull)
    out = {k: float(val) for k, val in h.items() if k[:2] in ("X_", "Y_", "K_", "N_")}
    if v.meta.hull_model == "mmg":
        out["X_0"] = -float(h["R0"])
    return out


def _truth_of(record: str) -> dict:
    path = Path(record)
    res = path.parent.parent / "results.json"
    if not res.is_file():
        raise InputError(str(path), "held_back", f"no {res} beside the record; allowed: a record inside a run "
                         "directory (RUN_DIR/records/NAME.nc) whose results.json holds the truth")
    name = path.stem
    for m in json.loads(res.read_text())["maneuvers"]:
        if m["name"] == name:
            return m["truth"]
    raise InputError(str(res), "maneuvers", f"no maneuver {name!r} in the run's results")


def score(result: dict) -> dict:
    """Errors of the identified coefficients (with interval coverage) and of the held-back predictions."""
    truth = true_coefficients(result["ship"])

    def against_truth(cs):
        out = {}
        for k, c in cs.items():
            t = truth.get(k, 0.0)
            out[k] = {"truth": t, "error": c["value"] - t, "rel_error": (c["value"] - t) / t if t else None,
                      "covered": bool(c["lo95"] <= t <= c["hi95"])}
        return out

    coeffs = against_truth(result["coefficients"])
    checked = result.get("intervals_checked") or ("Y_v", "Y_r", "N_v", "N_r")
    linear = {k: coeffs[k]["rel_error"] for k in checked if k in coeffs}
    preds = []
    worst = {"turn_rel": 0.0, "overshoot_deg": 0.0}
    for p in result["predictions"]:
        tr = _truth_of(p["record"])
        row = {"name": p["name"], "errors": {}}
        for k, v in p["predicted"].items():
            if k in _TURN and k in tr:
                e = (v - tr[k]) / tr[k]
                row["errors"][k] = {"predicted": v, "truth": tr[k], "rel_error": e}
                worst["turn_rel"] = max(worst["turn_rel"], abs(e))
            elif k in _ZIGZAG and k in tr:
                e = v - tr[k]
                row["errors"][k] = {"predicted": v, "truth": tr[k], "error_deg": e}
                worst["overshoot_deg"] = max(worst["overshoot_deg"], abs(e))
        preds.append(row)
    max_lin = max((abs(e) for e in linear.values()), default=None)
    verdict = {"linear_within_10pct": max_lin is not None and max_lin <= LIMITS["linear_rel"],
               "turns_within_5pct": worst["turn_rel"] <= LIMITS["turn_rel"] if preds else None,
               "overshoots_within_1p5deg": worst["overshoot_deg"] <= LIMITS["overshoot_deg"] if preds else None}
    extra = {}
    if "output_error" in result:   # the output-error refinement, scored the same way
        oe = against_truth(result["output_error"]["coefficients"])
        extra["output_error"] = {"coefficients": oe,
                                 "linear_rel_error": {k: oe[k]["rel_error"] for k in checked if k in oe}}
    return {**extra, "coefficients": coeffs, "linear_rel_error": linear, "max_linear_rel_error": max_lin,
            "predictions": preds, "worst": worst, "verdict": verdict,
            "coverage": {"n": len(coeffs), "covered": sum(c["covered"] for c in coeffs.values())}}
