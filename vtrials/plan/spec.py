"""The plan input file: what trial, on which ship and site, to what accuracy, within which limits.

    [plan]
    kind = "standardization"                       # trial kind (the family of agendas; more kinds can follow)
    scenario = "patrol51_standardization.toml"     # base scenario (ship, instruments, site, agenda rules),
                                                   # relative to this file; its agenda and [campaign] are replaced
    ship = "patrol51"                              # optional: must match the base scenario's ship
    seed = 11                                      # campaign seed of the search; verification uses seed + 1
    search_replicates = 20                         # replicates per candidate while searching
    verify_replicates = 200                        # replicates of the verifying campaigns
    shape = "normal"                               # the surrogate's error distribution: normal, or empirical
                                                   # (pooled search campaigns; its tail is noisy with few)

    [site]
    water_depth_m = 120.0                          # depth of the trial site (fixed; or draw it in [climate])

    [climate]                                      # the site's weather: scenario fields drawn per replicate,
    "environment.wind.speed_kn" = { uniform = [0.0, 25.0] }     # the [campaign.vary] grammar
    "environment.current.tidal_phase_deg" = { uniform = [0.0, 360.0] }

    [target]
    quantity = "speed"          # speed: speed through water at the target spot [kn];
                                # power: power at equal speed at the target spot [% of the true power]
    rpm = 600.0                 # the target setting (r/min and pitch ratio, or an engine order)
    pitch = 1.38
    tolerance = 0.1             # |error| allowed, in the quantity's unit
    confidence = 0.95           # fraction of trials that must fall within the tolerance
    rule = "quantile"           # quantile: the empirical quantile of |error| ≤ tolerance;
                                # wilson: the Wilson lower bound of the fraction within tolerance ≥ confidence

    [limits]
    max_hours = 3.0             # longest trial the planner may propose (predicted trial time)
    max_wind_kn = 20.0          # weather limit: the trial is not run in more wind (caps the wind draw)

    [candidates]                # the family of agendas searched, ordered by their predicted trial time
    spots = [1, 2]              # spots: the target setting and its nearest neighbours (below)
    runs = [2, 3, 4]            # runs per spot: 2 (base, reciprocal), 3 (base, reciprocal, base), 4
    run_s = [60.0, 120.0, 240.0]
    neighbours = [{ rpm = 530.0, pitch = 1.37 }]   # other settings, nearest to the target first
    turn_s = 600.0              # time per run outside the approach and the run: Williamson turn, run-out,
                                # steadiness checks (checked against the campaigns' simulated trial time)
    setting_change_s = 120.0    # time per spot to change the setting and settle

Every field is checked when the file is read (:class:`InputError` with file, field, what is wrong and
what is allowed), before anything is simulated.
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

from vtrials.campaign.spec import Vary, parse_vary
from vtrials.errors import InputError
from vtrials.schema import load_toml

KINDS = ("standardization",)  # trial kinds the planner has an agenda family for
QUANTITIES = {"standardization": {"speed": "kn", "power": "%"}}
RULES = ("quantile", "wilson")
SHAPES = ("normal", "empirical")
_SETTING_KEYS = ("rpm", "pitch", "order")
_TABLES = {
    "plan": ("kind", "scenario", "ship", "seed", "search_replicates", "verify_replicates", "shape"),
    "site": ("water_depth_m",),
    "climate": None,
    "target": ("quantity", "tolerance", "confidence", "rule") + _SETTING_KEYS,
    "limits": ("max_hours", "max_wind_kn"),
    "candidates": ("spots", "runs", "run_s", "neighbours", "turn_s", "setting_change_s"),
}
WIND_PATH = "environment.wind.speed_kn"


@dataclasses.dataclass(frozen=True)
class Target:
    quantity: str
    unit: str
    setting: dict  # rpm/pitch or order, as the agenda's spot table takes it
    tolerance: float
    confidence: float
    rule: str


@dataclasses.dataclass(frozen=True)
class Family:
    spots: tuple[int, ...]
    runs: tuple[int, ...]
    run_s: tuple[float, ...]
    neighbours: tuple[dict, ...]
    turn_s: float
    setting_change_s: float


@dataclasses.dataclass(frozen=True)
class PlanSpec:
    path: str
    kind: str
    scenario_path: str
    base_doc: dict  # the base scenario without [campaign]; site depth applied
    climate: tuple[Vary, ...]  # with the weather limits applied
    fixed: dict  # climate fields given as plain values
    target: Target
    max_hours: float
    max_wind_kn: float | None
    family: Family
    seed: int
    search_replicates: int
    verify_replicates: int
    shape: str = "normal"  # error-distribution shape of the surrogate: normal | empirical (pooled campaigns)


def _num(x) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


def _pos_num(f, where, x, lo=0.0, hi=math.inf, lo_open=True) -> float:
    if not _num(x) or (x <= lo if lo_open else x < lo) or x > hi:
        lo_s = f"> {lo:g}" if lo_open else f"≥ {lo:g}"
        hi_s = "" if hi == math.inf else f" and ≤ {hi:g}"
        raise InputError(f, where, f"{x!r}: expected a number {lo_s}{hi_s}")
    return float(x)


def _int(f, where, x, lo, hi) -> int:
    if not isinstance(x, int) or isinstance(x, bool) or not lo <= x <= hi:
        raise InputError(f, where, f"{x!r}: expected an integer from {lo} to {hi}")
    return x


def _setting(f, where, tab) -> dict:
    if not isinstance(tab, dict):
        raise InputError(f, where, "expected a setting table: { rpm = ..., pitch = ... } or { order = \"...\" }")
    s = {k: tab[k] for k in _SETTING_KEYS if k in tab}
    if "order" in s:
        if not isinstance(s["order"], str) or len(s) > 1:
            raise InputError(f, where, "give an engine order (a string) alone, or rpm (and pitch)")
    elif "rpm" not in s:
        raise InputError(f, where, "no setting: give rpm (and pitch for a CP propeller) or an engine order")
    else:
        _pos_num(f, f"{where}.rpm", s["rpm"], 0.0, 5000.0)
        if "pitch" in s and not (_num(s["pitch"]) and -2.0 <= s["pitch"] <= 3.0):
            raise InputError(f, f"{where}.pitch", f"{s['pitch']!r}: expected a pitch ratio from -2 to 3")
    return s


def _list(f, where, x, check) -> tuple:
    if not isinstance(x, list) or not x:
        raise InputError(f, where, "expected a non-empty list")
    out = tuple(check(f"{where}[{i}]", v) for i, v in enumerate(x))
    if len(set(map(repr, out))) != len(out):
        raise InputError(f, where, "values repeat")
    return out


def load_plan(path: str | Path) -> PlanSpec:
    """Read and check a plan file (see the module docstring for its fields)."""
    f = str(path)
    doc = load_toml(path)
    for k, v in doc.items():
        if k not in _TABLES:
            raise InputError(f, k, f"unknown table (allowed: {', '.join(_TABLES)})")
        if not isinstance(v, dict):
            raise InputError(f, k, "expected a table")
        allowed = _TABLES[k]
        if allowed is not None:
            for kk in v:
                if kk not in allowed:
                    raise InputError(f, f"{k}.{kk}", f"unknown field (allowed: {', '.join(allowed)})")
    for k in ("plan", "target", "candidates"):
        if k not in doc:
            raise InputError(f, k, f"missing [{k}] table")
    plan = doc["plan"]
    kind = plan.get("kind")
    if kind not in KINDS:
        raise InputError(f, "plan.kind", f"{kind!r}: the planner knows the trial kinds {', '.join(KINDS)}")
    scen = plan.get("scenario")
    if not isinstance(scen, str) or not scen:
        raise InputError(f, "plan.scenario", "expected the base scenario file (a path relative to this file)")
    spath = Path(scen) if Path(scen).is_absolute() else Path(f).parent / scen
    if not spath.is_file():
        raise InputError(f, "plan.scenario", f"{scen!r}: no such file (looked for {spath})")
    base = load_toml(spath)
    base.pop("campaign", None)
    if "agenda" not in base or not isinstance(base["agenda"], dict):
        raise InputError(f, "plan.scenario", f"{scen}: the base scenario needs an [agenda] (its rules are used)")
    base["agenda"] = {k: v for k, v in base["agenda"].items() if k != "trial"}
    ship = plan.get("ship")
    if ship is not None and ship != base.get("scenario", {}).get("ship"):
        raise InputError(f, "plan.ship", f"{ship!r}: the base scenario {scen} is for "
                                         f"{base.get('scenario', {}).get('ship')!r}; give its ship or another scenario")
    seed = _int(f, "plan.seed", plan.get("seed", 0), 0, 2 ** 62)
    n_search = _int(f, "plan.search_replicates", plan.get("search_replicates", 20), 3, 100000)
    n_verify = _int(f, "plan.verify_replicates", plan.get("verify_replicates", 200), 3, 100000)
    shape = plan.get("shape", "normal")
    if shape not in SHAPES:
        raise InputError(f, "plan.shape", f"{shape!r}: expected one of {', '.join(SHAPES)}")

    site = doc.get("site", {})
    if "water_depth_m" in site:
        base.setdefault("environment", {})["water_depth_m"] = _pos_num(f, "site.water_depth_m",
                                                                       site["water_depth_m"], 0.0, 12000.0)
    lim = doc.get("limits", {})
    max_hours = _pos_num(f, "limits.max_hours", lim.get("max_hours", 24.0), 0.0, 240.0)
    max_wind = lim.get("max_wind_kn")
    if max_wind is not None:
        max_wind = _pos_num(f, "limits.max_wind_kn", max_wind, 0.0, 200.0, lo_open=False)

    climate = doc.get("climate", {})
    fixed = {k: v for k, v in climate.items() if not isinstance(v, dict)}
    dists = {k: v for k, v in climate.items() if isinstance(v, dict)}
    for k, v in fixed.items():
        if not (_num(v) or isinstance(v, str)):
            raise InputError(f, f"climate.{k}", f"{v!r}: expected a number, a string or a distribution table")
    vary = parse_vary(dists, base, f, "climate")
    for k in fixed:
        parse_vary({k: {"choice": [fixed[k]]}}, base, f, "climate")  # the path must exist
    vary = [_limit_wind(f, v, max_wind) for v in vary]
    if max_wind is not None and WIND_PATH in fixed and fixed[WIND_PATH] > max_wind:
        raise InputError(f, f"climate.{WIND_PATH}", f"{fixed[WIND_PATH]} kn is above limits.max_wind_kn "
                                                    f"({max_wind:g} kn): the trial could never be run")
    if max_wind is not None and WIND_PATH not in climate:
        w = base.get("environment", {}).get("wind", {}).get("speed_kn", 0.0)
        if w > max_wind:
            raise InputError(f, "limits.max_wind_kn", f"the base scenario's wind ({w} kn) is above the limit "
                                                      f"({max_wind:g} kn); draw the wind in [climate]")

    tg = doc["target"]
    qs = QUANTITIES[kind]
    q = tg.get("quantity")
    if q not in qs:
        raise InputError(f, "target.quantity", f"{q!r}: a {kind} plan can target {', '.join(qs)}")
    rule = tg.get("rule", "quantile")
    if rule not in RULES:
        raise InputError(f, "target.rule", f"{rule!r}: expected one of {', '.join(RULES)}")
    target = Target(q, qs[q], _setting(f, "target", tg),
                    _pos_num(f, "target.tolerance", tg.get("tolerance"), 0.0),
                    _pos_num(f, "target.confidence", tg.get("confidence", 0.95), 0.5, 0.999),
                    rule)
    if not target.confidence < 1.0:
        raise InputError(f, "target.confidence", "must be below 1")

    c = doc["candidates"]
    neighbours = (_list(f, "candidates.neighbours", c["neighbours"], lambda w, v: _setting(f, w, v))
                  if "neighbours" in c else ())
    spots = _list(f, "candidates.spots", c.get("spots", [1]), lambda w, v: _int(f, w, v, 1, 1 + len(neighbours)))
    runs = _list(f, "candidates.runs", c.get("runs", [2, 3]), lambda w, v: _int(f, w, v, 2, 6))
    run_s = _list(f, "candidates.run_s", c.get("run_s"), lambda w, v: _pos_num(f, w, v, 10.0, 7200.0, lo_open=False))
    for i, nb in enumerate(neighbours):
        if nb == target.setting:
            raise InputError(f, f"candidates.neighbours[{i}]", "is the target setting itself")
    fam = Family(tuple(sorted(spots)), tuple(sorted(runs)), tuple(sorted(run_s)), neighbours,
                 _pos_num(f, "candidates.turn_s", c.get("turn_s", 600.0), 0.0, 36000.0, lo_open=False),
                 _pos_num(f, "candidates.setting_change_s", c.get("setting_change_s", 120.0), 0.0, 36000.0,
                          lo_open=False))
    return PlanSpec(f, kind, str(spath), base, tuple(vary), fixed, target, max_hours, max_wind, fam, seed,
                    n_search, n_verify, shape)


def _limit_wind(f: str, v: Vary, max_wind: float | None) -> Vary:
    """The wind the trial is run in: the site's wind distribution given that it is within the limit.
    A uniform draw is truncated exactly (uniform on [lo, min(hi, limit)]); a normal draw is clipped at
    the limit (its tail above the limit is run at the limit — a conservative stand-in for truncation);
    a choice keeps only the values within the limit."""
    if max_wind is None or v.path != WIND_PATH:
        return v
    where = f"climate.{WIND_PATH}"
    if v.kind == "uniform":
        lo, hi = v.args
        if lo > max_wind:
            raise InputError(f, where, f"all of the wind [{lo:g}, {hi:g}] kn is above limits.max_wind_kn "
                                       f"({max_wind:g} kn): the trial could never be run")
        return dataclasses.replace(v, args=(lo, min(hi, max_wind)))
    if v.kind == "normal":
        hi = max_wind if v.hi is None else min(v.hi, max_wind)
        return dataclasses.replace(v, hi=hi)
    keep = tuple(a for a in v.args if _num(a) and a <= max_wind)
    if not keep:
        raise InputError(f, where, f"no choice is within limits.max_wind_kn ({max_wind:g} kn)")
    return dataclasses.replace(v, args=keep)
