"""Identification of a ship's hull maneuvering coefficients from trial records (records only).

Pipeline: each maneuver record → :mod:`vtrials.sysid.records` (levelled specific force, aiding) →
EKF + RTS smoother (:mod:`vtrials.sysid.navfilter`) → inverse-dynamics equation-error regression of
the hull forces with the KNOWN mass, added mass, propeller and rudder of the team's MMG model
(:mod:`vtrials.sysid.regression`; model-test values, Y&Y 2015) → leave-one-maneuver-out cross-
validation among model structures → prediction of held-back maneuvers from their directors' sheets
(:mod:`vtrials.sysid.predict`). Intervals: ±1.96 σ, σ² the Newey–West variance of the regression
plus the variance from errors common to a whole record (:func:`systematic_covariance`).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from vtrials.errors import InputError
from vtrials.sysid import mmg
from vtrials.sysid import output_error as OE
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


def record_errors(mr: RE.ManeuverRecord) -> dict:
    """Errors common to a whole record that neither the smoother nor the regression's residuals can
    reveal, with their standard deviations: the gyro's zero left after the approach check (a heading
    error turns the body velocities: sway is not observable without it) and the rudder synchro's
    calibration and its logger's clock offset against the motion package's (a rudder shift recorded
    early or late). (The accelerometer and rate-gyro biases are not here: the tracking fixes bound their
    effect on the reconstructed motion, and the smoother's covariance carries it.)"""
    out = {"heading": float(mr.heading_sd), "rudder": float(mr.rudder_sd),
           "rudder_timing": float(mr.rudder_timing_sd)}
    if mr.pitch is not None:   # controllable pitch: the indicators' zero (the thrust the team computes)
        out["pitch"] = float(mr.pitch_sd)
    return out


def _perturbed(seg: RG.Segment, source: str, d: float) -> RG.Segment:
    """A segment as it would be reconstructed with one record-wide error of size d."""
    if source == "heading":     # body velocities and accelerations turn with the heading error
        return dataclasses.replace(seg, u=seg.u + d * seg.v, v=seg.v - d * seg.u,
                                   udot=seg.udot + d * seg.vdot, vdot=seg.vdot - d * seg.udot)
    if source == "rudder":
        return dataclasses.replace(seg, delta=seg.delta + d)
    if source == "rudder_timing":   # the rudder record d seconds late
        return dataclasses.replace(seg, delta=np.interp(seg.t + d, seg.t, seg.delta))
    if source == "pitch" and seg.pitch is not None:
        return dataclasses.replace(seg, pitch=seg.pitch + d)
    raise InputError(_WHERE, "source", f"{source!r}; allowed: heading, rudder, rudder_timing, pitch (CP propellers)")


def systematic_covariance(ship, segs, errors, fits) -> tuple[dict, dict]:
    """Covariance of the coefficients from the record-wide errors (GUM, JCGM 100:2008 §5.1, sensitivity
    by finite differences: each record's error moved by one σ, the whole structure refitted): {eq:
    matrix over that fit's terms}, and each source's share of the variance of the linear derivatives."""
    base = {eq: ft.coef for eq, ft in fits.items()}
    cov = {eq: np.zeros((len(ft.terms),) * 2) for eq, ft in fits.items()}
    share: dict = {}
    for i, errs in enumerate(errors):
        for source, sd in errs.items():
            if not sd > 0:
                continue
            trial = segs[:i] + [_perturbed(segs[i], source, sd)] + segs[i + 1:]
            for eq, ft in fits.items():
                A, y, b = RG.design(ship, trial, eq, ft.terms, weighted=True)
                d = np.linalg.lstsq(A, y, rcond=None)[0] - base[eq]
                cov[eq] += np.outer(d, d)
                for k, dk in zip(ft.terms, d):
                    if k in ship.linear:
                        share.setdefault(k, {}).setdefault(source, 0.0)
                        share[k][source] += float(dk * dk)
    return cov, share


#: Output-error refinement: the channels fitted (smoothed states), their sampling step (s), the moving-
#: average window (s) of the recorded rudder and shaft speed before they drive the model (a noisy input
#: makes the adaptive integrator crawl; 0.5 s is well inside the steering gear's 1–2 s to put the rudder
#: over) and the LM's evaluation budget.
OE_CHANNELS = ("u", "v", "r", "psi")
OE_STEP_S = 1.0
OE_INPUT_WINDOW_S = 0.5
OE_MAX_NFEV = 10


def _smooth_input(t, x, window_s):
    k = max(1, int(round(window_s / float(np.median(np.diff(t))))))
    if k < 2:
        return np.asarray(x, float)
    pad = np.pad(np.asarray(x, float), (k // 2, k - 1 - k // 2), mode="edge")
    return np.convolve(pad, np.ones(k) / k, mode="valid")


def oe_maneuver(sol, seg: RG.Segment, channels=OE_CHANNELS, step_s: float = OE_STEP_S) -> OE.Maneuver:
    """One maneuver for the output-error fit: the smoothed states at ``step_s`` over the regression
    segment as the measured outputs (σ set later from the residuals), the model started from the
    smoothed state at the segment's start and driven by the recorded rudder and shaft speed."""
    k = np.flatnonzero((sol.t >= seg.t[0]) & (sol.t <= seg.t[-1]))
    dec = max(1, int(round(step_s / float(np.median(np.diff(seg.t))))))
    ko = k[::dec]
    outs = {ch: (sol.t[ko], sol.state(ch)[ko], 1.0) for ch in channels}
    x0 = np.array([sol.state(ch)[k[0]] for ch in OE.CHANNELS])
    return OE.Maneuver(x0, seg.t, _smooth_input(seg.t, seg.delta, OE_INPUT_WINDOW_S),
                       _smooth_input(seg.t, seg.n, OE_INPUT_WINDOW_S), outs)


def _oe_perturbed(man: OE.Maneuver, source: str, d: float) -> OE.Maneuver:
    """A maneuver's output-error data as reconstructed with one record-wide error of size d (as
    :func:`_perturbed` for the regression): a heading zero turns the body velocities and shifts the
    heading, the rudder's zero or clock shifts the input."""
    if source == "heading":
        x0 = man.x0.copy()
        u, v = x0[3], x0[4]
        x0[2], x0[3], x0[4] = x0[2] + d, u + d * v, v - d * u
        o = dict(man.outputs)
        (tu, zu, su), (tv, zv, sv) = o["u"], o["v"]
        o["u"], o["v"] = (tu, zu + d * zv, su), (tv, zv - d * zu, sv)
        if "psi" in o:
            tp, zp, sp = o["psi"]
            o["psi"] = (tp, zp + d, sp)
        return dataclasses.replace(man, x0=x0, outputs=o)
    if source == "rudder":
        return dataclasses.replace(man, delta=man.delta + d)
    if source == "rudder_timing":
        return dataclasses.replace(man, delta=np.interp(man.t_input + d, man.t_input, man.delta))
    raise InputError(_WHERE, "source", f"{source!r}; allowed: heading, rudder, rudder_timing (output error, MMG)")


def output_error(ship, sols, segs, errors, start: dict, free=None, channels=OE_CHANNELS,
                 max_nfev: int = OE_MAX_NFEV, names=None) -> dict:
    """Output-error refinement (:func:`vtrials.sysid.output_error.refine`, Levenberg–Marquardt) of the
    ``free`` hull coefficients (default: all of ``start``) from the equation-error estimate ``start``,
    fitting the model's simulated u, v, r, ψ to the smoothed ones over every identification maneuver.

    Weights: each channel's σ is the RMS of its output error at the start (the output-error method's
    relaxation step, :func:`~vtrials.sysid.output_error.channel_sigmas`; never below the smoother's median
    σ); LM at those weights. Covariance: the sandwich (JᵀJ)⁻¹ M (JᵀJ)⁻¹ with M the Newey–West sum of the
    scores (Andrews' bandwidth): output-error residuals are correlated over many samples, and the white
    s² (JᵀJ)⁻¹ would overstate the information by n/n_eff (reported as ``n_over_n_eff``), widened by the
    fixed-b factor for a bandwidth that is a sizeable part of each record (reported as ``fixed_b``); plus the
    record-wide errors (gyro zero, rudder zero and clock) as linearised sensitivities (GUM)."""
    if not ship.prime:
        raise InputError(_WHERE, "refine", "output error is implemented for the 3-DOF MMG model; allowed: "
                         "a ship whose team model is MMG (kvlcc2_l7)")
    free = tuple(start) if free is None else tuple(free)
    mans = [oe_maneuver(sol, seg, channels) for sol, seg in zip(sols, segs)]
    floor = {ch: float(np.median(np.concatenate([sol.sigma(ch) for sol in sols]))) for ch in channels}
    sig0 = OE.channel_sigmas(ship, start, mans, floor)
    mans = OE.with_sigmas(mans, sig0)
    res = OE.refine(ship, start, free, mans, max_nfev=max_nfev, lags="auto")
    cost0 = float(np.mean(OE._residuals_batch(ship, tuple(start), np.array([[start[t] for t in start]]), mans)**2))
    sys_cov = np.zeros((len(free),) * 2)
    share: dict = {}
    for i, errs in enumerate(errors):
        for source, sd in errs.items():
            if not sd > 0 or source == "pitch":
                continue
            d = OE.shift(ship, res, mans, i, _oe_perturbed(mans[i], source, sd))
            sys_cov += np.outer(d, d)
            for k, dk in zip(free, d):
                if k in ship.linear:
                    share.setdefault(k, {}).setdefault(source, 0.0)
                    share[k][source] += float(dk * dk)
    traces = []   # the fit: measured, start (equation error) and refined model, for the report
    for i, man in enumerate(mans):
        tt = man.outputs[channels[0]][0]
        a, b = OE.simulate(ship, start, man, tt), OE.simulate(ship, res.coeffs, man, tt)
        traces.append({"name": names[i] if names else str(i), "t": tt.tolist(),
                       **{f"{ch}_{kind}": x.tolist() for ch in channels
                          for kind, x in (("measured", man.outputs[ch][1]), ("start", a[OE.CHANNELS.index(ch)]),
                                          ("refined", b[OE.CHANNELS.index(ch)]))}})
    var_r, var_s = np.diag(res.cov), np.diag(sys_cov)
    coeffs = {}
    for j, k in enumerate(free):
        c, sd = float(res.coeffs[k]), float(np.sqrt(var_r[j] + var_s[j]))
        coeffs[k] = {"value": c, "std": sd, "lo95": c - Z95 * sd, "hi95": c + Z95 * sd,
                     "std_random": float(np.sqrt(var_r[j])), "std_systematic": float(np.sqrt(var_s[j])),
                     "start": float(start[k])}
    white = np.diag(res.cov_white)
    return {"coefficients": coeffs, "free": list(free), "channels": list(channels), "channel_sigma": sig0,
            "step_s": OE_STEP_S, "rms_weighted": {"start": float(np.sqrt(cost0)), "refined": res.rms},
            "improved": bool(res.rms < np.sqrt(cost0)), "nfev": res.nfev, "lags": res.lags,
            "fixed_b": res.fixed_b,
            "n_over_n_eff": {k: float(var_r[j] / white[j]) for j, k in enumerate(free) if white[j] > 0},
            "systematic_share": share, "traces": traces,
            "interval": "95 %: ±1.96 σ; σ² = Newey–West sandwich of the output-error Jacobian (Andrews' bandwidth, "
                        "fixed-b widening: Kiefer & Vogelsang 2005) + the record-wide errors' variance (gyro zero, rudder zero and clock; linearised GUM "
                        "sensitivities)"}


def contributions(ship, segs, names, structure: str = "mmg") -> dict:
    """How much each maneuver adds: the linear derivatives' standard errors (whole structure, as
    reported) with that maneuver left out, relative to all maneuvers — 1.0 adds nothing, 2.0 means the
    derivative is known twice as well with it (the leave-one-out view of the information each input
    brings; Jategaonkar 2006, "Flight Vehicle System Identification", ch. 2 on input design)."""
    if len(segs) < 3:
        return {}
    base = RG.identify(ship, segs, structure, False, lags="auto", weighted=True)
    sig0 = {k: s for ft in base.values() for k, s in zip(ft.terms, ft.sigma()) if k in ship.linear}
    out = {}
    for i, name in enumerate(names):
        fits = RG.identify(ship, segs[:i] + segs[i + 1:], structure, False, lags="auto", weighted=True)
        sig = {k: s for ft in fits.values() for k, s in zip(ft.terms, ft.sigma()) if k in ship.linear}
        out[name] = {k: float(sig[k] / sig0[k]) for k in sig0}
    return out


#: Newey–West bandwidths (samples) at which the linear derivatives' random σ is reported for the
#: campaign's bandwidth study (``diagnostics``)
LAG_LADDER = (0, 10, 25, 50, 100, 200, 400)


def random_sigma(ship, segs, eq: str, ft: RG.Fit) -> tuple[np.ndarray, int]:
    """The regression's random σ of each term: the largest Newey–West σ over the bandwidths of
    :data:`LAG_LADDER` up to a quarter of the shortest maneuver and Andrews' own; returns (σ, the
    bandwidth at which the linear derivatives' σ peak).

    Why not Andrews' AR(1) rule alone (the fit's own ``lags="auto"``): the hull-force residuals are a
    mixture of white noise (the accelerometers', 20 Hz) and slow errors of the reconstruction (the
    tracking's correlated errors, which the smoother takes as white; seconds to a minute). The AR(1)
    plug-in reads the lag-1 correlation, which the white part holds near zero in the sway equation
    (ρ₁ ≈ 0.03 on the KVLCC2 agenda: 4–5 lags, 0.25 s), and misses the slow part: the Newey–West σ of
    Y'_v grows by 30–40 % from there to 100–200 lags and levels off (it falls again at long bandwidths
    only through the Bartlett window's bias). The largest σ over the bandwidths is the plateau.
    (The fixed-b widening of :func:`vtrials.sysid.output_error.fixed_b_factor` on top of it made the
    yaw derivatives' intervals too wide in the campaign's first replicates, sharpness ≈ 1.6: taking the
    largest σ over the bandwidths already errs on the wide side; the output-error refinement, with one
    bandwidth, keeps it.)"""
    A, y, bnd = RG.design(ship, segs, eq, ft.terms, weighted=True)
    out, sigmas = RG.plateau_sigma(A, y, ft.coef, bnd, LAG_LADDER)
    lin = [i for i, k in enumerate(ft.terms) if k in ship.linear] or list(range(len(ft.terms)))
    peak = max(sigmas, key=lambda L: float(np.sum(sigmas[L][lin] / np.maximum(ft.sigma()[lin], 1e-300))))
    return out, int(peak)


def identify_records(paths, structure: str | None = None, select: bool = True, held_back=(),
                     compare=None, with_contributions: bool = True, refine: str | None = None,
                     diagnostics: bool = False) -> dict:
    """Identify from the maneuver records ``paths``; predict the maneuvers of the ``held_back``
    records (their directors' sheets and approaches, never their motion). JSON-ready dict (SI; the
    MMG model's coefficients non-dimensional, Y&Y 2015 prime system, the 4-DOF model's dimensional).

    ``structure``: one of the team model's structures (default its first: "mmg" for KVLCC2, "blanke4"
    for patrol51); ``compare``: the structures cross-validated (default all of the model's).
    ``refine="oe"``: also the output-error (Levenberg–Marquardt) refinement of the whole structure from
    the equation-error estimate (:func:`output_error`), reported beside it as ``output_error`` (MMG
    model only). ``diagnostics``: the linear derivatives' random σ at the bandwidths of
    :data:`LAG_LADDER` (for the campaign's bandwidth study)."""
    if refine not in (None, "none", "oe"):
        raise InputError(_WHERE, "refine", f"{refine!r}; allowed: none, oe (output error)")
    paths = [str(p) for p in paths]
    if not paths:
        raise InputError(_WHERE, "records", "none given; allowed: one or more maneuver records (.nc)")
    mrs = [RE.read_maneuver(p) for p in paths]
    ship_name = _team(mrs)
    ship = mmg.team_ship(ship_name)
    structure = structure or next(iter(ship.structures))
    if structure not in ship.structures:
        raise InputError(_WHERE, "model", f"{structure!r} for {ship_name}; allowed: {', '.join(ship.structures)}")
    compare = tuple(ship.structures) if compare is None else compare
    sols = [RE.reconstruct(m) for m in mrs]
    segs = [RE.segment(m, s) for m, s in zip(mrs, sols)]
    # the coefficients and their intervals from the whole structure: a term dropped by selection would
    # bias the others (v'^3, v'^2 r', v' r'^2, r'^3 stand in for one another), and intervals after
    # selection are too narrow (post-selection inference). The predictions use the stepwise-selected
    # model, whose terms are each significant, since the whole structure extrapolates wildly.
    fits = RG.identify(ship, segs, structure, False, lags="auto", weighted=True)
    model = RG.identify(ship, segs, structure, True, lags="auto", min_t=MIN_T, weighted=True) if select else fits
    errors = [record_errors(m) for m in mrs]
    sys_cov, sys_share = systematic_covariance(ship, segs, errors, fits)
    coeffs = {}
    rand = {eq: random_sigma(ship, segs, eq, ft) for eq, ft in fits.items()}
    for eq, ft in fits.items():
        var_sys = np.diag(sys_cov[eq])
        for k, c, s, vs in zip(ft.terms, ft.coef, rand[eq][0], var_sys):
            sd = float(np.sqrt(s * s + vs))
            coeffs[k] = {"value": float(c), "std": sd, "lo95": float(c - Z95 * sd), "hi95": float(c + Z95 * sd),
                         "std_random": float(s), "std_systematic": float(np.sqrt(vs))}
    oe_doc = (output_error(ship, sols, segs, errors, RG.coefficients(fits), names=[m.name for m in mrs])
              if refine == "oe" else None)
    diag = {}
    if diagnostics:
        for eq, ft in fits.items():
            A, y, bnd = RG.design(ship, segs, eq, ft.terms, weighted=True)
            e = y - A @ ft.coef
            diag[eq] = {"andrews_lags": RG.andrews_lags(e, bnd), "lag1": RG._lag1(e, bnd),
                        "plateau_lags": rand[eq][1],
                        "segment_samples": [int(b) for b in np.diff(bnd)]}
            for k, v in zip(ft.terms, ft.sigma()):
                if k in ship.linear:
                    diag.setdefault("sigma_random_andrews", {})[k] = float(v)
            ladder = RG.hac_sigmas(A, y, ft.coef, bnd, LAG_LADDER)
            for L in LAG_LADDER:
                for k, v in zip(ft.terms, ladder[L]):
                    if k in ship.linear:
                        diag.setdefault("sigma_random", {}).setdefault(k, {})[str(L)] = float(v)
    structures = tuple(dict.fromkeys((structure, *compare)))
    cv = (RG.cross_validate(ship, segs, structures, select, lags="auto", min_t=MIN_T, weighted=True)
          if len(segs) > 1 and compare else {})
    best = {eq: min(cv, key=lambda s: cv[s][eq]) for eq in ship.structures[structure]} if cv else {}
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
                            "predicted": PR.held_back(ship, fitted, hb.ordered, ap["speed_mps"], ap["shaft_rps"],
                                                      ap.get("pitch_ratio", float("nan")))})
    extra = {}
    if oe_doc is not None:
        extra["output_error"] = oe_doc
    if diagnostics:
        extra["diagnostics"] = diag
    return {**extra, "ship": ship_name, "structure": structure, "selected": bool(select), "coefficients": coeffs,
            "prediction_model": {"terms": {eq: list(ft.terms) for eq, ft in model.items()}, "coefficients": fitted},
            "fit": {eq: {"rms": ft.rms, "n": ft.n, "n_eff": ft.n_eff, "bic": ft.bic} for eq, ft in model.items()},
            "cross_validation": cv, "best_structure_by_cv": best, "maneuvers": maneuvers,
            "predictions": predictions,
            "contributions": contributions(ship, segs, [m.name for m in mrs], structure) if with_contributions else {},
            "known_parts": ("mass, added mass, propeller and rudder of the team's MMG model (model tests, Y&Y 2015); "
                            "hull coefficients identified" if ship.prime else
                            "mass, inertia, added mass (BC93), GM, tank resistance, the propellers' open-water chart at "
                            "the indicated pitch and the rudders' lift, drag and interaction factors of the team's 4-DOF "
                            "model; hull coefficients identified (dimensional, BC93's modulus structure)"),
            "units": "non-dimensional (Y&Y 2015 prime system)" if ship.prime else "SI (dimensional, BC93)",
            "record_errors": {m.name: e for m, e in zip(mrs, errors)}, "systematic_share": sys_share,
            "intervals_checked": list(ship.linear),
            "intervals_note": "coverage measured for the linear derivatives only (benchmarks/campaign_identification.py); "
                              "the cubic terms trade off against one another and their intervals are not calibrated",
            "interval": "95 %: ±1.96 σ; σ² = the largest Newey–West (HAC) variance of the equation-error regression "
                        "over the bandwidths 0–400 samples (up to a quarter of the shortest maneuver) and Andrews' (1991) "
                        "AR(1) rule's: its plateau, + the record-wide errors' variance (gyro zero, rudder synchro "
                        "calibration and clock; GUM sensitivities)"}
