"""The trial planner: the cheapest agenda of a family predicted to meet an accuracy target, found by a
sequential, surrogate-guided search over campaigns, then verified by a larger independent campaign of
it and of the agenda one step cheaper.

Search (campaigns of ``search_replicates`` replicates, seed = the plan's seed):

1. order the candidates by predicted trial time (:mod:`vtrials.plan.agendas`);
2. fit the surrogate (:mod:`vtrials.plan.decide`) to the candidates run so far; walk the candidates from
   the cheapest: the first whose outcome the surrogate cannot predict (pattern not run yet, or a run
   length outside those run while the run-length term is not identified) is run next; a candidate
   predicted to fail is passed over; the first predicted to meet is run next if it has not been run,
   else it is chosen if its own campaign also meets the target (point rule); repeat.
3. verify the chosen candidate and the one before it in cost order by campaigns of
   ``verify_replicates`` replicates with another seed (seed + 1: independent of the search's draws, so
   the verdict is not biased by the choice).

Outputs in DIR: ``plan.json`` (everything, per candidate run: its campaign's errors summary, the
surrogate's prediction, trial time predicted and simulated), ``plan.md`` (the short report) and
``candidates/<name>/{scenario.toml, search/, verify/}`` (the campaigns).
"""

from __future__ import annotations

import json
import math
import time
from pathlib import Path

import numpy as np

from vtrials.campaign.run import run_campaign
from vtrials.errors import InputError
from vtrials.plan import decide as D
from vtrials.plan.agendas import Candidate, candidates, write_scenario
from vtrials.plan.spec import PlanSpec, load_plan
from vtrials.units import KNOT

_QUANTITY = {"speed": ("stw", 1.0 / KNOT), "power": ("power_at_equal_speed", 100.0)}


def target_errors(out_dir: Path, n: int | list[int], kind: str, group: int,
                  quantity: str) -> tuple[list[float], list[float]]:
    """Errors of the target quantity per replicate (replicates 0..n−1, or the listed ones; NaN where a
    replicate did not give it) in the target's unit, and the simulated trial time per replicate [s]."""
    key, scale = _QUANTITY[quantity]
    q = f"{kind}/spots[group={group}]/{key}"
    errs, sim = [], []
    for i in (range(n) if isinstance(n, int) else n):
        r = json.loads((Path(out_dir) / "parts" / f"replicate_{i:05d}.json").read_text())
        e = [row["error"] * scale for row in r["rows"] if row["quantity"] == q]
        errs.append(e[0] if e and e[0] is not None else math.nan)
        s = r.get("simulated_time_s")
        sim.append(math.nan if s is None else float(s))
    return errs, sim


class Planner:
    def __init__(self, spec: PlanSpec, out: Path, workers: int | None = 1, executor=None, say=None,
                 search_replicates: int | None = None, verify_replicates: int | None = None,
                 assemble: bool = False):
        self.assemble = assemble  # run nothing: summarize the campaigns already in ``out`` (maybe partial)
        self.spec = spec
        self.out = out
        self.workers = workers
        self.executor = executor
        self.say = say or (lambda s: None)
        self.n_search = search_replicates or spec.search_replicates
        self.n_verify = verify_replicates or spec.verify_replicates
        self.cands = candidates(spec)
        if not self.cands:
            raise InputError(spec.path, "limits.max_hours", f"no candidate agenda fits in {spec.max_hours:g} h")
        self.search: dict[str, dict] = {}
        self.shape = None
        self.order_run: list[str] = []

    def campaign(self, cand: Candidate, phase: str, n: int, seed: int) -> dict:
        d = self.out / "candidates" / cand.name
        scen = d / "scenario.toml"
        t0 = time.perf_counter()
        planned = n
        if self.assemble:
            from vtrials.plan.agendas import scenario_doc
            group = scenario_doc(self.spec, cand, n, seed)[1]
            parts = sorted(int(p.stem.split("_")[1]) for p in (d / phase / "parts").glob("replicate_*.json")) \
                if (d / phase / "parts").is_dir() else []
            parts = [i for i in parts if i < n]
            if not parts:
                raise InputError(str(d / phase), "--assemble", f"no replicates of the {phase} campaign of {cand.name}")
            n = len(parts)
        else:
            group = write_scenario(self.spec, cand, n, seed, scen)
            self.say(f"plan: {phase} campaign of {cand.name} ({cand.describe()}), {n} replicates ...")
            run_campaign(scen, d / phase, replicates=n, seed=seed, executor=self.executor, workers=self.workers,
                         resume=True)
            parts = n
        errs, sim = target_errors(d / phase, parts, self.spec.kind, group, self.spec.target.quantity)
        tg = self.spec.target
        st = D.empirical(errs, tg.tolerance, tg.confidence)
        fin = np.asarray([e for e in errs if math.isfinite(e)])
        res = {"candidate": cand.name, "phase": phase, "replicates": n, "planned_replicates": planned, "seed": seed,
               "target_group": group,
               **st, "mse": float(np.mean(fin ** 2)) if fin.size else math.inf,
               "meets": D.meets(st, tg.confidence, tg.rule),
               "simulated_time_s": float(np.nanmean(sim)), "wall_s": time.perf_counter() - t0,
               "errors": errs}
        self.say(f"plan:   {cand.name}: {st['within']}/{n} within ±{tg.tolerance:g} {tg.unit}, "
                 f"{100 * tg.confidence:g} % quantile of |error| {st['quantile_abs_error']:.4f} {tg.unit}, "
                 f"trial time {res['simulated_time_s'] / 3600:.2f} h simulated ({cand.cost_s / 3600:.2f} h predicted)")
        return res

    def surrogate(self) -> D.Surrogate:
        runs = [r for r in self.search.values() if math.isfinite(r["mse"])]
        self.shape = (D.error_shape([(r["errors"], r["mse"]) for r in runs]) if self.spec.shape == "empirical"
                      else None)
        pts = []
        for c in self.cands:
            r = self.search.get(c.name)
            if r is not None and math.isfinite(r["mse"]):
                pts.append((c.pattern, 1.0 / (c.runs * c.run_s), r["mse"], r["n"]))
        return D.fit_surrogate(pts)

    def predict(self, sur: D.Surrogate, c: Candidate) -> dict | None:
        x = 1.0 / (c.runs * c.run_s)
        if not sur.known(c.pattern, x):
            return None
        tg = self.spec.target
        mse = sur.mse(c.pattern, x)
        return {"mse": mse, "fraction": D.predicted_fraction(mse, tg.tolerance, self.shape),
                "quantile_abs_error": D.predicted_quantile(mse, tg.confidence, self.shape),
                "meets": D.predicted_meets(mse, tg.tolerance, tg.confidence, tg.rule, self.n_verify, self.shape)}

    def run_search(self, max_campaigns: int | None = None) -> Candidate | None:
        limit = max_campaigns or len(self.cands)
        while True:
            sur = self.surrogate()
            nxt, chosen = None, None
            for c in self.cands:
                p = self.predict(sur, c)
                if p is None:
                    nxt = c
                    break
                if p["meets"]:
                    r = self.search.get(c.name)
                    if r is None:
                        nxt = c
                        break
                    if r["within"] >= self.spec.target.confidence * r["n"] - 1e-9:
                        chosen = c
                        break
            if chosen is not None or nxt is None:
                return chosen
            if len(self.search) >= limit:
                self.say(f"plan: search stopped after {limit} campaigns")
                return None
            self.search[nxt.name] = self.campaign(nxt, "search", self.n_search, self.spec.seed)
            self.order_run.append(nxt.name)

    def run(self, max_campaigns: int | None = None) -> dict:
        spec, tg = self.spec, self.spec.target
        t0 = time.perf_counter()
        chosen = self.run_search(max_campaigns)
        sur = self.surrogate()
        cheaper = None
        if chosen is not None:
            i = self.cands.index(chosen)
            cheaper = self.cands[i - 1] if i > 0 else None
        verify = {}
        for role, c in (("chosen", chosen), ("one_step_cheaper", cheaper)):
            if c is not None:
                verify[role] = {"candidate": _cand_doc(c), "predicted": self.predict(sur, c),
                                "search": _strip(self.search.get(c.name)),
                                "verified": self.campaign(c, "verify", self.n_verify, spec.seed + 1)}
        table = []
        for c in self.cands:
            table.append({**_cand_doc(c), "predicted": self.predict(sur, c), "search": _strip(self.search.get(c.name))})
        doc = {
            "plan": Path(spec.path).name, "kind": spec.kind, "base_scenario": Path(spec.scenario_path).name,
            "ship": spec.base_doc.get("scenario", {}).get("ship"),
            "target": {"quantity": tg.quantity, "unit": tg.unit, "setting": tg.setting, "tolerance": tg.tolerance,
                       "confidence": tg.confidence, "rule": tg.rule},
            "limits": {"max_hours": spec.max_hours, "max_wind_kn": spec.max_wind_kn},
            "climate": {v.path: {v.kind: list(v.args), **({"min": v.lo} if v.lo is not None else {}),
                                 **({"max": v.hi} if v.hi is not None else {})} for v in spec.climate},
            "climate_fixed": spec.fixed,
            "search_replicates": self.n_search, "verify_replicates": self.n_verify,
            "surrogate": {"floors": {f"spots={k[0]},runs={k[1]}": v for k, v in sur.floors.items()},
                          "slope": sur.slope, "slope_identified": sur.slope_identified,
                          "model": "MSE = A[spots,runs] + B/(runs*run_s)", "shape": spec.shape,
                          "shape_quantile": (None if self.shape is None or not self.shape.size else
                                             D.predicted_quantile(1.0, tg.confidence, self.shape)),
                          "shape_pool": 0 if self.shape is None else int(self.shape.size)},
            "search_order": self.order_run,
            "chosen": None if chosen is None else chosen.name,
            "one_step_cheaper": None if cheaper is None else cheaper.name,
            "verification": verify, "candidates": table, "wall_time_s": time.perf_counter() - t0,
        }
        doc["acceptance"] = _acceptance(verify)
        return doc


def _cand_doc(c: Candidate) -> dict:
    return {"name": c.name, "spots": c.spots, "runs_per_spot": c.runs, "run_s": c.run_s,
            "predicted_trial_time_s": c.cost_s, "describe": c.describe()}


def _strip(r: dict | None) -> dict | None:
    return None if r is None else {k: v for k, v in r.items() if k != "errors"}


def _acceptance(verify: dict) -> dict:
    ch = verify.get("chosen", {}).get("verified")
    ck = verify.get("one_step_cheaper", {}).get("verified")
    return {"chosen_meets": None if ch is None else bool(ch["meets"]),
            "cheaper_fails": None if ck is None else (not ck["meets"]),
            "met": bool(ch and ch["meets"] and (ck is None or not ck["meets"]))}


def plan(path: str | Path, out_dir: str | Path, workers: int | None = 1, executor=None, say=None,
         search_replicates: int | None = None, verify_replicates: int | None = None,
         max_campaigns: int | None = None, assemble: bool = False) -> dict:
    """Plan the trial of the plan file ``path``; write plan.json and plan.md to ``out_dir``.

    ``assemble``: run no replicate; make the same decisions from the campaigns already in ``out_dir``
    and summarize each verifying campaign over the replicates it has (a campaign stopped short, e.g.
    at a deadline, is reported with its actual replicate count)."""
    spec = load_plan(path)
    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise InputError(str(out), "--out", "exists and is not a directory")
    out.mkdir(parents=True, exist_ok=True)
    pl = Planner(spec, out, workers, executor, say, search_replicates, verify_replicates, assemble)
    doc = pl.run(max_campaigns)
    from vtrials.runner.outputs import json_clean
    (out / "plan.json").write_text(json.dumps(json_clean(doc), indent=1))
    from vtrials.plan.report import markdown
    (out / "plan.md").write_text(markdown(doc))
    return doc
