"""Replicates stepped together (issue 11, deliverable 5): what a batch of B trial days in one simulator
saves per replicate, against the same replicates run one by one, measured in the same run.

For each batch size B (1 first: the one-by-one path), a fresh process runs replicates 0..K−1 of the
campaign scenario in groups of B with :func:`vtrials.campaign.run.run_replicates` — simulate, reduce
and score in memory, the campaign's fast path — one process at a time, so each has the CPU to itself
as far as the machine allows. Reported per B: wall time per replicate and its ratio to B = 1, the
simulation's share (crews, instruments and the shared stepping), the peak resident memory of the
process, and whether the rows equal B = 1's (they must: each day is bit-identical however it is
stepped). The load average is sampled throughout (shared machine).

    PYTHONPATH=. python benchmarks/bench_batch.py --replicates 8 --batch 1 2 4 8 \\
        --json benchmarks/results/bench_batch_patrol51.json
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import platform
import resource
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "benchmarks"))


def child(scenario: str, n: int, batch: int) -> dict:
    """In this process: replicates 0..n−1 in groups of ``batch``; wall time, rows' hash, peak memory."""
    from vtrials.campaign.run import run_replicates
    from vtrials.campaign.spec import load_campaign
    seed = load_campaign(scenario).seed
    run_replicates(scenario, [0], seed, n)  # compile and load everything once (not timed)
    t0 = time.perf_counter()
    out = []
    for k in range(0, n, batch):
        out += run_replicates(scenario, list(range(k, min(k + batch, n))), seed, n)
    wall = time.perf_counter() - t0
    sim = sum(r["timings"]["simulate_s"] for r in out)
    rows = json.dumps([[r["replicate"], r["drawn"], r["rows"]] for r in out], sort_keys=True, default=str)
    return {"batch": batch, "replicates": n, "wall_s": wall, "wall_per_replicate_s": wall / n,
            "simulate_share": sim / wall, "simulated_time_s": sum(r["simulated_time_s"] or 0.0 for r in out),
            "peak_rss_gb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2 ** 20,
            "rows_sha256": hashlib.sha256(rows.encode()).hexdigest()}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scenario", default="scenarios/patrol51_standardization_campaign.toml")
    ap.add_argument("--replicates", type=int, default=8)
    ap.add_argument("--batch", type=int, nargs="+", default=[1, 2, 4, 8])
    ap.add_argument("--json", default=None)
    ap.add_argument("--child", type=int, default=None, help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.child is not None:
        print(json.dumps(child(a.scenario, a.replicates, a.child)))
        return
    from bench_campaign import LoadSampler
    load = LoadSampler()
    load.start()
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    runs = []
    for b in sorted(set(a.batch) | {1}):
        p = subprocess.run([sys.executable, __file__, "--scenario", a.scenario, "--replicates", str(a.replicates),
                            "--child", str(b)], check=True, env=env, cwd=ROOT, capture_output=True, text=True)
        r = json.loads(p.stdout.strip().splitlines()[-1])
        runs.append(r)
        print(f"batch {b:3d}: {r['wall_per_replicate_s']:.2f} s per replicate, simulation {100 * r['simulate_share']:.0f} %,"
              f" peak {r['peak_rss_gb']:.2f} GB", flush=True)
    one = runs[0]
    for r in runs:
        r["ratio_to_one_by_one"] = r["wall_per_replicate_s"] / one["wall_per_replicate_s"]
        r["rows_equal_one_by_one"] = r["rows_sha256"] == one["rows_sha256"]
    doc = {"scenario": a.scenario, "replicates": a.replicates, "runs": runs,
           "machine": {"cpu_count": os.cpu_count(), "platform": platform.platform(), "python": sys.version.split()[0],
                       "load_1min_during": load.stop(),
                       "note": "one process at a time; other jobs may run beside it (load average above)"}}
    for r in runs:
        print(f"batch {r['batch']:3d}: {r['ratio_to_one_by_one']:.2f} x the one-by-one time per replicate; "
              f"rows equal: {r['rows_equal_one_by_one']}")
    if a.json:
        from vtrials.runner.outputs import json_clean
        Path(a.json).parent.mkdir(parents=True, exist_ok=True)
        Path(a.json).write_text(json.dumps(json_clean(doc), indent=1) + "\n")


if __name__ == "__main__":
    main()
