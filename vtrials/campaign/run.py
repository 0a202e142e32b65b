"""Monte Carlo campaigns: many replicates of one trial agenda, every reduced quantity scored.

A replicate is the whole chain — draw the varied scenario fields and a fresh scenario seed, let the
crew run the agenda, reduce its records, score against truth — in a worker process. The records are
reduced in memory (:func:`vtrials.runner.trial_day.score_agenda`: the same arrays the record files would
hold, the same reduction code); truth.nc, the records and results.json are written only when the
campaign keeps them (``keep_records``). It returns one row per reduced quantity that carries an interval:

    replicate, quantity, group, reduced, std, lo95, hi95, half_width95, truth, error, covered

(``error`` and ``half_width95`` in the units the scoring states, e.g. relative for power at equal
speed). Rows are kept per replicate in ``parts/`` as they arrive, so a killed campaign resumes where
it stopped (``resume=True``) and gives the same table as an uninterrupted one; the final table
(``campaign.parquet``) is sorted by replicate, so it does not depend on worker count, executor or
completion order. ``summary.parquet`` / ``summary.json`` give per quantity class (``group``: the
quantity with run and spot indices removed) the coverage with its Wilson interval, the sharpness and
the verdict (:mod:`vtrials.score.coverage`).

Any :class:`concurrent.futures.Executor` runs it: a spawn process pool by default, or a Dask
``distributed`` client's executor for a cluster.
"""

from __future__ import annotations

import concurrent.futures as cf
import ctypes
import gc
import json
import math
import multiprocessing
import os
import re
import shutil
import tempfile
import time
from pathlib import Path

from vtrials.campaign.spec import CampaignSpec, load_campaign, replicate_doc, replicate_seeds
from vtrials.errors import InputError, SimulationError

COLUMNS = ("replicate", "quantity", "group", "reduced", "std", "lo95", "hi95", "half_width95", "truth", "error",
           "covered")
_KEYS = ("truth", "reduced", "error", "covered")


def _label(item: dict, i: int) -> str:
    for k in ("run", "group", "label", "spot", "name", "setting"):
        if k in item and isinstance(item[k], (int, float, str)) and not isinstance(item[k], bool):
            return f"{k}={item[k]}"
    return str(i)


def comparisons(tree, prefix: str = ""):
    """(path, comparison dict) of every scored comparison in a results tree."""
    if isinstance(tree, dict):
        if all(k in tree for k in _KEYS):
            yield prefix, tree
            return
        for k, v in tree.items():
            if k == "summary":
                continue
            yield from comparisons(v, f"{prefix}/{k}" if prefix else k)
    elif isinstance(tree, list):
        for i, v in enumerate(tree):
            lab = _label(v, i) if isinstance(v, dict) else str(i)
            yield from comparisons(v, f"{prefix}[{lab}]")


def _group(quantity: str) -> str:
    return re.sub(r"\[[^\]]*\]", "[]", quantity)


def _f(x):
    return math.nan if x is None else float(x)


def rows_of(results: dict, replicate: int) -> list[dict]:
    """The campaign rows of one replicate's results.json document."""
    rows = []
    for trial in results.get("trials", []):
        for path, c in comparisons(trial.get("error", {}), trial["name"]):
            if c.get("covered") is None:
                continue  # no interval to judge (no truth, or the reduction gave none)
            rows.append({"replicate": replicate, "quantity": path, "group": _group(path),
                         "reduced": _f(c.get("reduced")), "std": _f(c.get("std")), "lo95": _f(c.get("lo95")),
                         "hi95": _f(c.get("hi95")), "half_width95": _f(c.get("half_width95")),
                         "truth": _f(c.get("truth")), "error": _f(c.get("error")), "covered": bool(c["covered"])})
    return rows


def _replicate_scenario(path: str, spec, index: int, campaign_seed: int, n_total: int):
    from vtrials.scenario import load_scenario
    ss = replicate_seeds(campaign_seed, n_total)[index]
    doc, drawn = replicate_doc(spec, ss)
    scn = load_scenario(path, doc)
    if scn.agenda is None:
        raise InputError(path, "agenda", "a campaign needs an [agenda] (its reductions are what is scored)")
    return scn, drawn


def _score_day(res, index: int, drawn: dict, keep_dir: str | None) -> dict:
    from vtrials.runner.trial_day import score_agenda, write_agenda_outputs
    if keep_dir is None:
        # the fast path: records reduced in memory (the same arrays the files would hold), nothing written
        out = score_agenda(res)
    else:
        with tempfile.TemporaryDirectory(prefix="vtrials-rep-") as tmp:
            out = write_agenda_outputs(res, tmp, plot=False)
            dest = Path(keep_dir) / f"replicate_{index:05d}"
            if dest.exists():
                shutil.rmtree(dest)
            shutil.copytree(tmp, dest)
    return {"replicate": index, "drawn": drawn, "rows": rows_of(out, index),
            "simulated_time_s": out.get("simulated_time_s"), "timings": out.get("timings")}


def run_replicate(path: str, index: int, campaign_seed: int, n_total: int, keep_dir: str | None = None) -> dict:
    """Run replicate ``index`` of the campaign in ``path`` (in a worker); returns its rows and draws."""
    return run_replicates(path, [index], campaign_seed, n_total, keep_dir)[0]


def run_replicates(path: str, indices: list[int], campaign_seed: int, n_total: int,
                   keep_dir: str | None = None) -> list[dict]:
    """Run replicates ``indices`` of the campaign in ``path`` (in a worker), stepped together as the
    ships of one simulator when they can share it (:func:`vtrials.runner.trial_day.simulate_agendas`;
    each replicate's records are bit-identical to its day run alone, so the table does not depend on
    the batch size); returns their rows and draws, in the order of ``indices``."""
    from vtrials.runner.trial_day import CannotShare, simulate_agendas
    spec = load_campaign(path)
    days = [_replicate_scenario(path, spec, i, campaign_seed, n_total) for i in indices]
    scns = [scn for scn, _ in days]
    try:
        results = simulate_agendas(scns)
    except (SimulationError, CannotShare):
        if len(scns) == 1:
            raise
        # days that cannot share a simulator, or one ship's blow-up (it stops the whole batch): run the
        # days one by one, so the others complete and a failing replicate reports its own error
        del days, scns
        release_memory()
        return [r for i in indices for r in run_replicates(path, [i], campaign_seed, n_total, keep_dir)]
    rows = []
    for k, (i, (_, drawn)) in enumerate(zip(indices, days)):
        rows.append(_score_day(results[k], i, drawn, keep_dir))
        results[k] = None  # its records and truth can go before the next day is scored
    del results, days, scns
    release_memory()
    return rows


def release_memory() -> None:
    """Hand a finished replicate's memory back to the system. A replicate's day peaks at 1–2.3 GB of
    arrays (KVLCC2's IMO day); glibc keeps freed blocks below its (self-raising) mmap threshold in the
    heap, so a worker's resident size ratcheted up over replicates — 8.4 GB after 20 KVLCC2 replicates,
    and a worker was killed out of memory. After each replicate: collect cycles, then ``malloc_trim``
    (glibc; elsewhere a no-op). Measured on 4 KVLCC2 IMO replicates: 1.1–2.2 GB → 0.36 GB each time."""
    gc.collect()
    try:
        ctypes.CDLL("libc.so.6").malloc_trim(0)
    except (OSError, AttributeError):
        pass


def _die_with_parent() -> None:
    """Worker initializer: on Linux, ask the kernel to end this worker when the campaign process dies
    (prctl PR_SET_PDEATHSIG = 1, SIGTERM). A campaign killed with SIGTERM/SIGKILL otherwise left its
    spawn workers running their replicates to the end for nothing (one ran on for 45 min); with
    ``--resume`` those replicates are redone anyway. Elsewhere a no-op."""
    try:
        ctypes.CDLL("libc.so.6", use_errno=True).prctl(1, 15, 0, 0, 0)
    except (OSError, AttributeError):
        pass


def default_executor(workers: int | None = None) -> cf.Executor:
    """A process pool started with 'spawn' (safe with MuJoCo's and numba's threads), whose workers end
    with the campaign process."""
    return cf.ProcessPoolExecutor(max_workers=workers or os.cpu_count() or 1,
                                  mp_context=multiprocessing.get_context("spawn"), initializer=_die_with_parent)


def _write_json_atomic(path: Path, obj) -> None:
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".part")
    with os.fdopen(fd, "w") as f:
        json.dump(obj, f)
    os.replace(tmp, path)


def run_campaign(path: str | Path, out_dir: str | Path, replicates: int | None = None, seed: int | None = None,
                 executor: cf.Executor | None = None, workers: int | None = None, resume: bool = False,
                 keep_records: bool = False, progress: bool = False, batch: int = 1) -> dict:
    """Run (or resume) a campaign; write ``campaign.parquet``, ``summary.parquet`` and ``summary.json``.

    Returns the summary document. ``executor``: any concurrent.futures.Executor (default: a spawn
    process pool of ``workers`` processes, closed at the end). ``batch``: replicates a worker steps
    together in one simulator (:func:`run_replicates`; the table is the same for any value, and
    benchmarks/bench_campaign.py measures what it saves; each replicate of the batch holds its day's
    records in memory at once).
    """
    if isinstance(batch, bool) or not isinstance(batch, int) or batch < 1:
        raise InputError("run_campaign", "batch", f"expected an integer ≥ 1 (replicates per simulator), got {batch!r}")
    path = str(path)
    spec = load_campaign(path)  # checks the file before anything is started
    n = int(replicates or spec.replicates)
    cseed = spec.seed if seed is None else int(seed)
    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise InputError(str(out), "--out", "exists and is not a directory")
    parts = out / "parts"
    manifest = {"scenario": Path(path).name, "replicates": n, "campaign_seed": cseed}
    if parts.exists() and not resume and any(parts.iterdir()):
        raise InputError(str(out), "--out", "holds a campaign already: give --resume to continue it, "
                                            "or another directory")
    parts.mkdir(parents=True, exist_ok=True)
    mf = out / "manifest.json"
    if resume and mf.exists():
        old = json.loads(mf.read_text())
        if old != manifest:
            raise InputError(str(out), "--resume", f"the campaign there was {old}, not {manifest}")
    _write_json_atomic(mf, manifest)
    done = {int(p.stem.split("_")[1]) for p in parts.glob("replicate_*.json")}
    todo = [i for i in range(n) if i not in done]
    own = executor is None
    ex = default_executor(workers) if own else executor
    keep = str(out / "replicates") if keep_records else None
    bar = None
    if progress:
        from tqdm import tqdm
        bar = tqdm(total=n, initial=n - len(todo), unit="replicate", desc="campaign", dynamic_ncols=True)
    t0 = time.perf_counter()
    try:
        groups = [todo[k:k + batch] for k in range(0, len(todo), batch)]
        futs = [ex.submit(run_replicates, path, g, cseed, n, keep) for g in groups]
        for fut in cf.as_completed(futs):
            for r in fut.result():
                _write_json_atomic(parts / f"replicate_{r['replicate']:05d}.json", r)
                if bar is not None:
                    bar.update(1)
    finally:
        if bar is not None:
            bar.close()
        if own:
            ex.shutdown(wait=True, cancel_futures=True)
    return finish(out, n, wall_s=time.perf_counter() - t0)


def load_rows(out_dir: str | Path, n: int) -> tuple[list[dict], list[dict]]:
    """All rows and draws of replicates 0..n−1, in replicate order."""
    rows, draws = [], []
    for i in range(n):
        r = json.loads((Path(out_dir) / "parts" / f"replicate_{i:05d}.json").read_text())
        rows += r["rows"]
        draws.append({"replicate": i, **{k: v for k, v in r["drawn"].items()}})
    return rows, draws


def finish(out_dir: str | Path, n: int, wall_s: float | None = None) -> dict:
    """Assemble the tables of a complete campaign and summarize every quantity class."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    from vtrials.score.coverage import verdict
    out = Path(out_dir)
    rows, draws = load_rows(out, n)
    table = pa.table({c: [r[c] for r in rows] for c in COLUMNS})
    pq.write_table(table, out / "campaign.parquet")
    groups: dict[str, list[dict]] = {}
    for r in rows:
        groups.setdefault(r["group"], []).append(r)
    summary = []
    for g in sorted(groups):
        rs = groups[g]
        v = verdict([r["covered"] for r in rs], [r["half_width95"] for r in rs], [r["error"] for r in rs],
                    clusters=[r["replicate"] for r in rs])
        summary.append({"group": g, **v})
    scols = list(summary[0]) if summary else ["group"]
    pq.write_table(pa.table({c: [s[c] for s in summary] for c in scols}), out / "summary.parquet")
    doc = {"replicates": n, "quantities": summary, "draws": draws}
    if wall_s is not None:
        doc["wall_time_s"] = wall_s
    from vtrials.runner.outputs import json_clean
    _write_json_atomic(out / "summary.json", json_clean(doc))
    return doc
