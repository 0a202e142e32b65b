"""The family of candidate agendas a plan searches, their predicted trial time, and the scenario
document that runs one of them in a campaign.

A standardization candidate is (spots, runs per spot, run length): the target setting and its
``spots − 1`` nearest neighbours, each run ``runs`` times alternating between the base course and its
reciprocal (2: base–reciprocal; 3: base–reciprocal–base, the 1:2:1 mean of means; 4: two pairs), every
measured run ``run_s`` long. Its predicted trial time is

    T = N_runs · (approach_s + run_s + turn_s) + spots · setting_change_s

with ``approach_s`` from the base scenario's agenda rules and ``turn_s`` / ``setting_change_s`` from the
plan (the planner reports it beside the trial time the campaigns simulate). Candidates are ordered by T
(ties: fewer runs, then shorter runs); "one step cheaper" is the previous candidate in that order.
"""

from __future__ import annotations

import dataclasses
import math
import re
from pathlib import Path

from vtrials.plan.spec import PlanSpec

DEFAULT_APPROACH_S = 60.0  # vtrials.trials.agenda.AgendaRules.approach_s default


@dataclasses.dataclass(frozen=True)
class Candidate:
    spots: int
    runs: int  # per spot
    run_s: float
    cost_s: float  # predicted trial time

    @property
    def name(self) -> str:
        return f"s{self.spots}_r{self.runs}_t{self.run_s:g}"

    @property
    def n_runs(self) -> int:
        return self.spots * self.runs

    @property
    def pattern(self) -> tuple[int, int]:
        """What the current elimination and the all-runs analysis see: (spots, runs per spot)."""
        return (self.spots, self.runs)

    def describe(self) -> str:
        kinds = {2: "base–reciprocal", 3: "base–reciprocal–base", 4: "two reciprocal pairs"}
        return (f"{self.spots} spot(s) × {self.runs} runs ({kinds.get(self.runs, f'{self.runs} alternating')}), "
                f"{self.run_s:g} s runs")


def trial_time(spots: int, runs: int, run_s: float, approach_s: float, turn_s: float, change_s: float) -> float:
    """Predicted trial time [s] of an agenda (see the module docstring)."""
    return spots * runs * (approach_s + run_s + turn_s) + spots * change_s


def candidates(spec: PlanSpec) -> list[Candidate]:
    """Every candidate of the plan's family within its time limit, cheapest first."""
    fam = spec.family
    approach = float(spec.base_doc["agenda"].get("approach_s", DEFAULT_APPROACH_S))
    out = []
    for s in fam.spots:
        for r in fam.runs:
            for t in fam.run_s:
                c = trial_time(s, r, t, approach, fam.turn_s, fam.setting_change_s)
                if c <= spec.max_hours * 3600.0:
                    out.append(Candidate(s, r, t, c))
    return order(out)


def order(cands: list[Candidate]) -> list[Candidate]:
    return sorted(cands, key=lambda c: (c.cost_s, c.n_runs, c.run_s, c.spots))


def spot_settings(spec: PlanSpec, n_spots: int) -> tuple[list[dict], int]:
    """The settings of an n-spot candidate in the order they are run (increasing power: r/min, then
    pitch; orders keep the plan's order) and the index of the target among them."""
    chosen = [spec.target.setting] + list(spec.family.neighbours[:n_spots - 1])
    if all("rpm" in s for s in chosen):
        chosen = sorted(chosen, key=lambda s: (s["rpm"], s.get("pitch", 0.0)))
    return chosen, chosen.index(spec.target.setting)


def scenario_doc(spec: PlanSpec, cand: Candidate, replicates: int, seed: int) -> tuple[dict, int]:
    """The campaign scenario of a candidate (base scenario, the candidate's agenda, the site climate as
    the [campaign.vary] draws) and the spot group (1-based) of the target."""
    import copy
    doc = copy.deepcopy(spec.base_doc)
    for path, value in spec.fixed.items():
        _set(doc, path, value)
    settings, it = spot_settings(spec, cand.spots)
    trial = {"name": spec.kind, "kind": spec.kind, "run_s": float(cand.run_s),
             "spot": [{**s, "runs": cand.runs} for s in settings]}
    disp = _displacement(spec)
    if disp is not None:
        trial["displacement_m3"] = disp
    doc["agenda"]["trial"] = [trial]
    vary = {}
    for v in spec.climate:
        d = {v.kind: list(v.args)}
        if v.lo is not None:
            d["min"] = v.lo
        if v.hi is not None:
            d["max"] = v.hi
        vary[v.path] = d
    doc["scenario"]["title"] = f"Plan candidate {cand.name}: {cand.describe()}"
    doc["campaign"] = {"replicates": int(replicates), "seed": int(seed), "vary": vary}
    return doc, it + 1


def _displacement(spec: PlanSpec):
    from vtrials.schema import load_toml
    try:
        tr = load_toml(spec.scenario_path)["agenda"]["trial"]
    except (KeyError, TypeError):
        return None
    for t in tr if isinstance(tr, list) else []:
        if isinstance(t, dict) and t.get("kind") == spec.kind and "displacement_m3" in t:
            return t["displacement_m3"]
    return None


def _set(doc: dict, path: str, value) -> None:
    from vtrials.campaign.spec import _locate
    cont, key = _locate(doc, path, "plan", f"climate.{path}")
    cont[key] = value


# ------------------------------------------------------------------------------------ TOML writer
_BARE = re.compile(r"^[A-Za-z0-9_-]+$")


def _key(k: str) -> str:
    if _BARE.match(k):
        return k
    return '"' + k.replace("\\", "\\\\").replace('"', '\\"') + '"'


def _value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n") + '"'
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{_key(k)} = {_value(x)}" for k, x in v.items()) + " }"
    raise TypeError(f"cannot write {type(v).__name__} to TOML")


def _is_table_array(v) -> bool:
    return isinstance(v, list) and bool(v) and all(isinstance(x, dict) for x in v)


def dumps_toml(doc: dict) -> str:
    """A TOML text of a document of tables, arrays of tables and plain values (what tomllib reads back)."""
    lines: list[str] = []

    def table(d: dict, prefix: list[str], header: str | None):
        if header is not None:
            lines.append("")
            lines.append(header)
        for k, v in d.items():
            if not isinstance(v, dict) and not _is_table_array(v):
                lines.append(f"{_key(k)} = {_value(v)}")
        for k, v in d.items():
            p = prefix + [_key(k)]
            if isinstance(v, dict):
                table(v, p, "[" + ".".join(p) + "]")
            elif _is_table_array(v):
                for item in v:
                    table(item, p, "[[" + ".".join(p) + "]]")

    table(doc, [], None)
    return "\n".join(lines).lstrip("\n") + "\n"


def write_scenario(spec: PlanSpec, cand: Candidate, replicates: int, seed: int, path: Path) -> int:
    """Write the candidate's campaign scenario to ``path``; returns the target's spot group."""
    doc, group = scenario_doc(spec, cand, replicates, seed)
    path.parent.mkdir(parents=True, exist_ok=True)
    head = (f"# Generated by the trial planner from {Path(spec.path).name} (base scenario "
            f"{Path(spec.scenario_path).name}):\n# {cand.describe()}; target spot group {group}.\n")
    path.write_text(head + dumps_toml(doc))
    return group
