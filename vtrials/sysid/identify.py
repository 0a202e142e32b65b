"""Identification of a ship's hull maneuvering coefficients from trial records (records only).

Pipeline: each maneuver record → :mod:`vtrials.sysid.records` (levelled specific force, aiding) →
EKF + RTS smoother (:mod:`vtrials.sysid.navfilter`) → inverse-dynamics equation-error regression of
the hull forces with the KNOWN mass, added mass, propeller and rudder of the team's MMG model
(:mod:`vtrials.sysid.regression`; model-test values, Y&Y 2015) → leave-one-maneuver-out cross-
validation among model structures → prediction of held-back maneuvers from their directors' sheets
(:mod:`vtrials.sysid.predict`). Intervals: ±1.96 σ of the Newey–West covariance of the regression.
"""

from __future__ import annotations

import numpy as np

from vtrials.errors import InputError
from vtrials.sysid import mmg
from vtrials.sysid import predict as PR
from vtrials.sysid import records as RE
from vtrials.sysid import regression as RG

_WHERE = "vtrials.sysid.identify"
Z95 = 1.959963984540054
MIN_T = 2.0   # stepwise entry test: a selected term must stand at ≥ 2 σ (regression.forward_select)


def _team(mrs) -> str:
    ships = sorted({m.ship for m in mrs})
    if len(ships) != 1:
        raise InputError(_WHERE, "records", f"records of several ships {ships}; allowed: one ship per identification")
    return ships[0]


def identify_records(paths, structure: str = "mmg", select: bool = True, held_back=(),
                     compare=("mmg", "abkowitz", "blanke")) -> dict:
    """Identify from the maneuver records ``paths``; predict the maneuvers of the ``held_back``
    records (their directors' sheets and approaches, never their motion). JSON-ready dict (SI; the
    coefficients non-dimensional, Y&Y 2015 prime system)."""
    paths = [str(p) for p in paths]
    if not paths:
        raise InputError(_WHERE, "records", "none given; allowed: one or more maneuver records (.nc)")
    mrs = [RE.read_maneuver(p) for p in paths]
    ship_name = _team(mrs)
    ship = mmg.team_ship(ship_name)
    sols = [RE.reconstruct(m) for m in mrs]
    segs = [RE.segment(m, s) for m, s in zip(mrs, sols)]
    # the coefficients and their intervals from the whole structure: a term dropped by selection would
    # bias the others (v'^3, v'^2 r', v' r'^2, r'^3 stand in for one another), and intervals after
    # selection are too narrow (post-selection inference). The predictions use the stepwise-selected
    # model, whose terms are each significant, since the whole structure extrapolates wildly.
    fits = RG.identify(ship, segs, structure, False, lags="auto", weighted=True)
    model = RG.identify(ship, segs, structure, True, lags="auto", min_t=MIN_T, weighted=True) if select else fits
    coeffs = {}
    for ft in fits.values():
        for k, c, s in zip(ft.terms, ft.coef, ft.sigma()):
            coeffs[k] = {"value": float(c), "std": float(s), "lo95": float(c - Z95 * s), "hi95": float(c + Z95 * s)}
    structures = tuple(dict.fromkeys((structure, *compare)))
    cv = (RG.cross_validate(ship, segs, structures, select, lags="auto", min_t=MIN_T, weighted=True)
          if len(segs) > 1 and compare else {})
    best = {eq: min(cv, key=lambda s: cv[s][eq]) for eq in "XYN"} if cv else {}
    fitted = RG.coefficients(model)
    maneuvers = []
    for m, sol, seg in zip(mrs, sols, segs):
        res = {}
        for eq, ft in model.items():
            A, y, _ = RG.design(ship, [seg], eq, ft.terms)
            res[eq] = float(np.sqrt(np.mean((y - A @ ft.coef)**2)))
        maneuvers.append({"record": m.path, "name": m.name, "kind": m.kind, "ordered": m.ordered,
                          "approach": m.approach(), "samples": int(seg.t.size), "hull_force_rms": res,
                          "smoothed": {k: {"rms": float(np.sqrt(np.mean(sol.state(k)**2))),
                                           "median_sigma": float(np.median(sol.sigma(k)))} for k in ("u", "v", "r")}})
    predictions = []
    for p in held_back:
        hb = RE.read_maneuver(p)
        if hb.ship != ship_name:
            raise InputError(str(p), "ship", f"{hb.ship!r}; allowed: {ship_name!r}, the identified ship")
        ap = hb.approach()
        predictions.append({"record": hb.path, "name": hb.name, "ordered": hb.ordered, "approach": ap,
                            "predicted": PR.held_back(ship, fitted, hb.ordered, ap["speed_mps"], ap["shaft_rps"])})
    return {"ship": ship_name, "structure": structure, "selected": bool(select), "coefficients": coeffs,
            "prediction_model": {"terms": {eq: list(ft.terms) for eq, ft in model.items()}, "coefficients": fitted},
            "fit": {eq: {"rms": ft.rms, "n": ft.n, "n_eff": ft.n_eff, "bic": ft.bic} for eq, ft in model.items()},
            "cross_validation": cv, "best_structure_by_cv": best, "maneuvers": maneuvers,
            "predictions": predictions,
            "known_parts": "mass, added mass, propeller and rudder of the team's MMG model (model tests, Y&Y 2015); "
                           "hull coefficients identified",
            "interval": "95 %: ±1.96 σ, Newey–West (HAC) covariance of the equation-error regression, Bartlett "
                        "bandwidth by Andrews' (1991) AR(1) plug-in rule"}
