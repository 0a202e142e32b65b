"""Campaigns: reproducible draws, the same table whatever runs it, resume after a kill, and the
coverage statistics checked on analytic cases."""

from __future__ import annotations

import math
import shutil
from pathlib import Path

import numpy as np
import pytest

from vtrials.campaign.run import run_campaign
from vtrials.campaign.spec import load_campaign, replicate_doc, replicate_seeds
from vtrials.errors import InputError
from vtrials.score.coverage import sharpness, verdict, wilson

SCN = Path(__file__).resolve().parent / "data" / "campaign_logcal.toml"


def test_wilson_interval_against_a_hand_computation():
    # k = 95, n = 100: p = 0.95, z = 1.96 → (0.9513 ± 0.0442) / 1.0384
    lo, hi = wilson(95, 100)
    assert lo == pytest.approx(0.88825, abs=2e-4) and hi == pytest.approx(0.97846, abs=2e-4)
    assert wilson(0, 10)[0] == pytest.approx(0.0, abs=1e-12) and wilson(10, 10)[1] == pytest.approx(1.0, abs=1e-12)


def test_sharpness_and_verdict_on_honest_and_dishonest_intervals():
    rng = np.random.default_rng(3)
    sd = 0.2
    err = rng.normal(0.0, sd, 4000)
    hw = np.full(err.size, 1.96 * sd)
    covered = np.abs(err) <= hw
    assert sharpness(hw, err) == pytest.approx(1.0, abs=0.05)
    assert verdict(covered, hw, err)["verdict"] == "calibrated"
    wide = verdict(np.ones(err.size, bool), 100 * hw, err)  # covers always, 100× too wide
    assert wide["verdict"] == "uncalibrated" and "sharpness" in wide["why"]
    narrow = np.abs(err) <= hw / 3
    v = verdict(narrow, hw / 3, err)
    assert v["verdict"] == "uncalibrated" and "coverage" in v["why"]


def test_coverage_interval_allows_for_rows_that_share_a_replicate():
    """Honest intervals whose errors share a per-replicate part (a day's calibration draw): the rows of
    a replicate cover or miss together. Over 400 simulated campaigns of 200 replicates × 8 rows, the
    plain Wilson interval on the 1600 rows holds the true 0.95 far less often than 95 %; the one on
    Kish's effective number of trials about 95 % of the time. Rows of their own replicates: the plain
    interval again."""
    from vtrials.score.coverage import effective_trials
    rng = np.random.default_rng(7)
    C, m, share = 200, 8, 0.9  # 90 % of each row's error variance is the replicate's common draw
    plain = adjusted = 0
    for _ in range(400):
        common = rng.normal(0.0, math.sqrt(share), (C, 1))
        err = common + rng.normal(0.0, math.sqrt(1 - share), (C, m))
        cov = (np.abs(err) <= 1.959964).ravel()
        clusters = np.repeat(np.arange(C), m)
        k, n = int(cov.sum()), cov.size
        lo, hi = wilson(k, n)
        plain += lo <= 0.95 <= hi
        v = verdict(cov, np.full(n, 1.96), err.ravel(), clusters=clusters)
        adjusted += v["wilson_lo"] <= 0.95 <= v["wilson_hi"]
        assert C <= v["n_eff"] < n
    assert plain / 400 < 0.75, plain
    assert 0.92 <= adjusted / 400 <= 0.98, adjusted
    y = rng.random(500) < 0.95
    assert effective_trials(y, np.arange(500)) == pytest.approx(500, rel=0.15)
    v = verdict(y, np.ones(500), rng.normal(size=500), clusters=np.arange(500))
    assert (v["wilson_lo"], v["wilson_hi"]) == pytest.approx(wilson(int(y.sum()), 500), abs=0.01)


def test_draws_are_reproducible_and_per_replicate():
    spec = load_campaign(str(SCN))
    seeds = replicate_seeds(spec.seed, 3)
    a = [replicate_doc(spec, s)[1] for s in seeds]
    b = [replicate_doc(spec, s)[1] for s in replicate_seeds(spec.seed, 3)]
    assert a == b
    assert len({d["scenario.seed"] for d in a}) == 3
    assert len({d["environment.current.direction_deg"] for d in a}) == 3
    assert all(d["environment.wind.speed_kn"] >= 0.0 for d in a)
    # replicate i's draws do not depend on how many replicates there are
    assert replicate_doc(spec, replicate_seeds(spec.seed, 10)[1])[1] == a[1]


@pytest.mark.parametrize("vary, field, what", [
    ('"environment.nothing.x" = { uniform = [0, 1] }', "campaign.vary.environment.nothing.x", "no environment.nothing"),
    ('"environment.wind.speed_kn" = { uniform = [2, 1] }', "campaign.vary.environment.wind.speed_kn.uniform", "lower"),
    ('"environment.wind.speed_kn" = { gauss = [2, 1] }', "campaign.vary.environment.wind.speed_kn", "exactly one"),
    ('"agenda.trial[7].run_s" = { uniform = [60, 90] }', "campaign.vary.agenda.trial[7].run_s", "no element 7"),
])
def test_bad_campaign_tables_are_clear_errors(tmp_path, vary, field, what):
    text = SCN.read_text().split("[campaign.vary]")[0] + "[campaign.vary]\n" + vary + "\n"
    p = tmp_path / "bad.toml"
    p.write_text(text)
    with pytest.raises(InputError) as e:
        load_campaign(str(p))
    assert e.value.field == field and what in str(e.value)


def _table(out: Path):
    import pyarrow.parquet as pq
    return pq.read_table(out / "campaign.parquet")


@pytest.fixture(scope="module")
def serial(tmp_path_factory):
    out = tmp_path_factory.mktemp("camp") / "serial"
    doc = run_campaign(SCN, out, workers=1)
    return out, doc


def test_campaign_scores_every_replicate(serial):
    out, doc = serial
    t = _table(out).to_pydict()
    assert sorted(set(t["replicate"])) == [0, 1, 2]
    groups = {q["group"]: q for q in doc["quantities"]}
    assert "log_calibration/legs[]/stw" in groups
    stw = groups["log_calibration/legs[]/stw"]
    assert stw["n"] == 3 * 8  # 8 legs per replicate
    # errors are real numbers of the right size (kn-level trials: well under a knot)
    err = np.array([e for g, e in zip(t["group"], t["error"]) if g == "log_calibration/legs[]/stw"])
    assert np.all(np.isfinite(err)) and np.max(np.abs(err)) < 0.5
    assert len(doc["draws"]) == 3


def test_same_table_with_two_workers_in_batches_and_with_dask(serial, tmp_path):
    out, _ = serial
    ref = _table(out)
    run_campaign(SCN, tmp_path / "two", workers=2)
    assert _table(tmp_path / "two").equals(ref)
    # replicates stepped together, two per simulator (the third alone): the same table
    run_campaign(SCN, tmp_path / "batch", workers=1, batch=2)
    assert _table(tmp_path / "batch").equals(ref)
    with pytest.raises(InputError, match="batch"):
        run_campaign(SCN, tmp_path / "bad", workers=1, batch=0)
    from distributed import Client, LocalCluster
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
            Client(cluster) as client:
        run_campaign(SCN, tmp_path / "dask", executor=client.get_executor())
    assert _table(tmp_path / "dask").equals(ref)


def test_resume_after_a_kill_gives_the_same_table(serial, tmp_path):
    out, _ = serial
    part = tmp_path / "part"
    shutil.copytree(out, part)
    (part / "parts" / "replicate_00001.json").unlink()  # as if killed before replicate 1 finished
    (part / "campaign.parquet").unlink()
    with pytest.raises(InputError, match="--resume"):
        run_campaign(SCN, part, workers=1)
    run_campaign(SCN, part, workers=1, resume=True)
    assert _table(part).equals(_table(out))
    with pytest.raises(InputError, match="campaign there was"):
        run_campaign(SCN, part, replicates=5, workers=1, resume=True)


def test_coverage_summary_is_consistent_with_the_rows(serial):
    out, doc = serial
    t = _table(out).to_pydict()
    for q in doc["quantities"]:
        rows = [i for i, g in enumerate(t["group"]) if g == q["group"]]
        assert q["n"] == len(rows)
        assert q["covered"] == sum(t["covered"][i] for i in rows)
        for i in rows:  # the interval and the coverage flag agree
            inside = t["lo95"][i] <= t["truth"][i] <= t["hi95"][i]
            assert inside == t["covered"][i] or math.isclose(t["lo95"][i], t["truth"][i]) or \
                math.isclose(t["hi95"][i], t["truth"][i])


def _children(pid: int) -> list[int]:
    out = []
    for d in Path("/proc").iterdir():
        if d.name.isdigit():
            try:
                stat = (d / "stat").read_text()
            except OSError:
                continue
            if int(stat.rsplit(")", 1)[1].split()[1]) == pid:
                out.append(int(d.name))
    return out


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


def test_workers_end_with_a_killed_campaign(tmp_path):
    """A campaign process killed outright (SIGKILL: no cleanup runs) takes its spawn workers with it
    (Linux parent-death signal), instead of leaving them to finish their replicates for nothing."""
    import subprocess
    import sys
    import time
    p = subprocess.Popen([sys.executable, "-m", "vtrials.cli", "campaign", str(SCN), "--replicates", "3",
                          "--workers", "1", "--quiet", "--out", str(tmp_path / "c")],
                         stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    workers = []
    t0 = time.monotonic()
    while not workers and time.monotonic() - t0 < 120 and p.poll() is None:
        time.sleep(0.2)
        workers = [c for c in _children(p.pid)
                   if b"spawn_main" in Path(f"/proc/{c}/cmdline").read_bytes()]
    assert workers, "no worker process seen"
    time.sleep(1.0)  # the worker is importing / running its replicate
    p.kill()
    p.wait()
    t0 = time.monotonic()
    while any(_alive(w) for w in workers) and time.monotonic() - t0 < 30:
        time.sleep(0.2)
    assert not any(_alive(w) for w in workers)
