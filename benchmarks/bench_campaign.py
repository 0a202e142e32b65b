"""Campaign benchmark (issue 11, deliverable 5): a standardization campaign on a process pool, timed
against the single-run path in the same session, and its coverage table.

Two measurements on the same machine, one after the other:

1. the single-run path — ``python -m vtrials.cli run`` of the base scenario (a fresh process: simulate,
   write truth.nc and the records, reduce, score, results.json and the report with its figures), wall
   time of the whole command, after one untimed run that fills numba's caches;
2. the campaign — ``run_campaign`` of the campaign scenario on a spawn process pool of ``--workers``
   processes, ``--batch`` replicates stepped together in one simulator per task; every replicate takes
   the fast path (records reduced in memory, nothing written:
   :func:`vtrials.runner.trial_day.score_agenda`). Wall time, replicates per hour, and the ratio of the
   campaign's wall time per replicate to the single run's wall time.

The machine is shared (other jobs run beside this one): the load average is sampled every 10 s and
stated in the JSON with the CPU count, so the figures can be read for what they are.
``--time-limit S`` stops handing out replicates after S seconds of campaign wall time; the table is
then that of the completed prefix 0..K−1 (``replicates_completed``), stated as such.

The JSON's ``quantities`` are the campaign summary (coverage, Wilson interval, sharpness, verdict per
quantity class): the calibration table of the standardization intervals.

    PYTHONPATH=. python benchmarks/bench_campaign.py --replicates 200 --workers 2 \\
        --json benchmarks/results/bench_campaign.json
"""

from __future__ import annotations

import argparse
import concurrent.futures as cf
import json
import os
import platform
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


class LoadSampler(threading.Thread):
    """The 1-min load average every ``every`` seconds while the benchmark runs."""

    def __init__(self, every: float = 10.0):
        super().__init__(daemon=True)
        self.every, self.samples, self._stop = every, [], threading.Event()

    def run(self):
        while not self._stop.is_set():
            self.samples.append(os.getloadavg()[0])
            self._stop.wait(self.every)

    def stop(self) -> dict:
        self._stop.set()
        s = self.samples or [os.getloadavg()[0]]
        return {"mean_1min": sum(s) / len(s), "max_1min": max(s), "min_1min": min(s), "samples": len(s)}


def single_run(scenario: str) -> dict:
    """Wall time of the CLI's ``run`` of ``scenario`` in a fresh process (the single-run path)."""
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    with tempfile.TemporaryDirectory(prefix="vtrials-bench-run-") as tmp:
        t0 = time.perf_counter()
        subprocess.run([sys.executable, "-m", "vtrials.cli", "run", scenario, "--out", f"{tmp}/out", "--quiet"],
                       check=True, env=env, cwd=ROOT)
        wall = time.perf_counter() - t0
        res = json.loads(Path(f"{tmp}/out/results.json").read_text())
    return {"scenario": scenario, "wall_s": wall, "timings": res.get("timings"),
            "simulated_time_s": res.get("simulated_time_s")}


def campaign(scenario: str, out: Path, n: int, workers: int, time_limit: float | None, batch: int = 1) -> dict:
    """Run replicates 0..n−1 on a spawn pool, ``batch`` per simulator; stop handing out new ones after
    ``time_limit`` s."""
    from vtrials.campaign.run import _write_json_atomic, default_executor, finish, run_replicates
    from vtrials.campaign.spec import load_campaign
    spec = load_campaign(scenario)
    parts = out / "parts"
    parts.mkdir(parents=True, exist_ok=True)
    _write_json_atomic(out / "manifest.json", {"scenario": Path(scenario).name, "replicates": n,
                                               "campaign_seed": spec.seed})
    ex = default_executor(workers)
    t0 = time.perf_counter()
    done, timings = set(), []
    pending, nxt = set(), 0
    stopped = False
    try:
        while nxt < n or pending:
            while nxt < n and len(pending) < 2 * workers and not stopped:
                group = list(range(nxt, min(nxt + batch, n)))
                pending.add(ex.submit(run_replicates, scenario, group, spec.seed, n, None))
                nxt += len(group)
            if not pending:
                break
            fin, pending = cf.wait(pending, return_when=cf.FIRST_COMPLETED)
            for f in fin:
                for r in f.result():
                    _write_json_atomic(parts / f"replicate_{r['replicate']:05d}.json", r)
                    done.add(r["replicate"])
                    timings.append(r.get("timings") or {})
            if time_limit is not None and time.perf_counter() - t0 > time_limit and not stopped:
                stopped = True
                nxt = n  # no more submissions; the running ones finish
    finally:
        ex.shutdown(wait=True, cancel_futures=True)
    wall = time.perf_counter() - t0
    k = 0
    while k in done:
        k += 1
    doc = finish(out, k, wall_s=wall)
    mean = {key: sum(t.get(key, 0.0) for t in timings) / max(len(timings), 1)
            for key in ("simulate_s", "instruments_s", "calm_water_s", "sea_setup_s", "reduce_score_s")}
    return {"wall_s": wall, "replicates_run": len(done), "replicates_completed": k, "stopped_by_time_limit": stopped,
            "replicates_per_hour": 3600.0 * len(done) / wall, "mean_replicate_timings_s": mean,
            "quantities": doc["quantities"]}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scenario", default="scenarios/patrol51_standardization_campaign.toml")
    ap.add_argument("--single", default="scenarios/patrol51_standardization.toml",
                    help="scenario of the single-run path (the campaign scenario's base)")
    ap.add_argument("--replicates", type=int, default=200)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--batch", type=int, default=1, help="replicates per simulator (run_replicates)")
    ap.add_argument("--time-limit", type=float, default=None, help="seconds of campaign wall time")
    ap.add_argument("--out", help="campaign directory (default: a temporary one)")
    ap.add_argument("--json", default=str(ROOT / "benchmarks" / "results" / "bench_campaign.json"))
    a = ap.parse_args()
    load = LoadSampler()
    load.start()
    load_start = os.getloadavg()
    # a first run in a fresh checkout compiles numba's caches (27.7 s against 10.5 s warm, measured):
    # that one-time cost is not the single-run path's, and the campaign's workers find the caches filled
    single_run(a.single)
    single = single_run(a.single)
    out = Path(a.out or tempfile.mkdtemp(prefix="vtrials-bench-campaign-"))
    camp = campaign(a.scenario, out, a.replicates, a.workers, a.time_limit, a.batch)
    per_rep = camp["wall_s"] / max(camp["replicates_run"], 1)
    doc = {"scenario": a.scenario, "single_run_scenario": a.single, "replicates_requested": a.replicates,
           "workers": a.workers, "batch": a.batch, "executor": "spawn process pool",
           "machine": {"cpu_count": os.cpu_count(), "platform": platform.platform(), "python": sys.version.split()[0],
                       "load_average_at_start": list(load_start), "load_average_at_end": list(os.getloadavg()),
                       "load_1min_during": load.stop(),
                       "note": "shared machine: other jobs ran beside the benchmark (load average above)"},
           "single_run": single,
           "campaign": {k: v for k, v in camp.items() if k != "quantities"},
           "campaign_wall_per_replicate_s": per_rep,
           "ratio_campaign_per_replicate_to_single_run": per_rep / single["wall_s"],
           "target_wall_s": 900.0, "quantities": camp["quantities"]}
    from vtrials.runner.outputs import json_clean
    Path(a.json).parent.mkdir(parents=True, exist_ok=True)
    Path(a.json).write_text(json.dumps(json_clean(doc), indent=1) + "\n")
    print(f"single run {single['wall_s']:.1f} s; campaign {camp['replicates_run']} replicates in {camp['wall_s']:.0f} s "
          f"({camp['replicates_per_hour']:.0f}/h, {per_rep:.1f} s each = {per_rep / single['wall_s']:.2f} x the single run)")
    for q in camp["quantities"]:
        print(f"  {q['group']:<52} n {q['n']:>5} coverage {q['coverage']:.3f} [{q['wilson_lo']:.3f}, "
              f"{q['wilson_hi']:.3f}] sharpness {q['sharpness']:.2f} {q['verdict']}")


if __name__ == "__main__":
    main()
