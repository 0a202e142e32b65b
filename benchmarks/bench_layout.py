"""Per-step cost of the simulator before and after a change, measured in one run (not a test).

Issue 9 moved the package into stages and put the force components behind a registry with a
generated dispatch; the per-step cost must stay within 5 % of what it was. This script checks out a
reference commit (default: the last one before the reorganisation) into a temporary directory and
times the same workload with both trees, alternating them over several rounds in fresh interpreters
(numba caches warmed first), each time also against a bare ``mj_step`` loop of the same MJCF in the
same process. Reported: the median over rounds of each tree's full-step cost and of the ratio of
the two, per workload:

* one ship, full 6-DOF, a 20/20 zig-zag helm programme, truth recorded every step (KVLCC2 at its
  production step 0.05 s, patrol51 at 0.02 s);
* 100 KVLCC2 ships in one batch on 2 threads.

Usage: python benchmarks/bench_layout.py [--ref COMMIT] [--rounds 5] [--json out.json]
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
REF = "6eef3e6"  # the pins commit: the code as it was before the reorganisation

WORKER = r'''
import json, math, sys, time
import mujoco
try:
    from vtrials.physics.simulator import Simulator
    from vtrials.physics.vessel import load_vessel
    from vtrials.physics import steering as H
except ImportError:  # the flat layout before the reorganisation
    from vtrials.simulator import Simulator
    from vtrials.vessel import load_vessel
    from vtrials import helm as H
ship, dt, n, nstep = sys.argv[1], float(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4])
v = load_vessel(ship)
model = v.model
model.opt.timestep = dt
data = mujoco.MjData(model)
def bare():
    mujoco.mj_resetData(model, data)
    data.qvel[0] = 5.0
    t0 = time.perf_counter()
    for _ in range(nstep):
        mujoco.mj_step(model, data)
    return (time.perf_counter() - t0) / nstep
sim = Simulator(v, n, dt, nthread=2 if n > 1 else 1, record_every=1)
if ship == "patrol51":
    rps, pd = v.telegraph["full"]
    s0 = sim.steady_at_order(0, (rps,) * sim.ns, (pd,) * sim.ns)
else:
    s0 = sim.self_propulsion(0, 15.5 * 1852 / 3600)
def full():
    for i in range(n):
        sim.set_state(i, s0)
        sim.set_helm(i, [(H.ZIGZAG, math.radians(20), math.radians(20), 0.0, 1.0, 0.0)])
    sim.clear_truth()
    t0 = time.perf_counter()
    sim.step(nstep)
    return (time.perf_counter() - t0) / nstep / n
full(); bare()
print(json.dumps({"bare": min(bare() for _ in range(5)), "full": min(full() for _ in range(5))}))
'''

WORKLOADS = [("kvlcc2", 0.05, 1, 4000), ("patrol51", 0.02, 1, 4000), ("kvlcc2", 0.05, 100, 200)]


def measure(tree: Path, ship: str, dt: float, n: int, nstep: int) -> dict:
    out = subprocess.run([sys.executable, "-c", WORKER, ship, str(dt), str(n), str(nstep)], cwd=tree,
                         capture_output=True, text=True, check=True,
                         env={"PYTHONPATH": str(tree), "PATH": "/usr/bin:/bin", "HOME": str(Path.home())})
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--ref", default=REF)
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--json")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        ref = Path(tmp) / "ref"
        ref.mkdir()
        archive = subprocess.run(["git", "archive", args.ref], cwd=ROOT, capture_output=True, check=True).stdout
        subprocess.run(["tar", "-x", "-C", str(ref)], input=archive, check=True)
        trees = {"before": ref, "after": ROOT}
        results = []
        for ship, dt, n, nstep in WORKLOADS:
            rows = {"before": [], "after": []}
            for name, tree in trees.items():  # warm both numba caches
                measure(tree, ship, dt, n, 50)
            for _ in range(args.rounds):
                for name, tree in trees.items():
                    rows[name].append(measure(tree, ship, dt, n, nstep))
            ratio = statistics.median(a["full"] / b["full"] for a, b in zip(rows["after"], rows["before"]))
            rel = {k: statistics.median(r["full"] / r["bare"] for r in v) for k, v in rows.items()}
            res = {"ship": ship, "dt": dt, "ships": n,
                   "before_us": statistics.median(r["full"] for r in rows["before"]) * 1e6,
                   "after_us": statistics.median(r["full"] for r in rows["after"]) * 1e6,
                   "after_over_before": ratio, "before_over_bare": rel["before"], "after_over_bare": rel["after"]}
            results.append(res)
            print(f"{ship:9s} dt {dt:5.3f} s  N = {n:3d}: before {res['before_us']:7.2f} us/ship-step "
                  f"({rel['before']:.2f} x bare), after {res['after_us']:7.2f} us "
                  f"({rel['after']:.2f} x bare); after/before = {ratio:.3f}  (target <= 1.05)", flush=True)
    if args.json:
        Path(args.json).write_text(json.dumps(results, indent=1))


if __name__ == "__main__":
    main()
