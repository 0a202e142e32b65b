"""Reliability of whole runs: outputs all or nothing (SIGINT and SIGKILL at random moments),
Ctrl-C as one line with exit 130, under-determined reductions reported (not computed), the user's
umask, no MUJOCO_LOG.TXT, MuJoCo warnings as SimulationError."""

from __future__ import annotations

import hashlib
import json
import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from vtrials.errors import SimulationError
from vtrials.reduce.trials import resolve_current

ROOT = Path(__file__).resolve().parents[1]

PAIR = """
[scenario]
title = "one reciprocal pair"
ship = "patrol51"
seed = {seed}
timestep_s = 0.1
truth_every = 20

[environment]
water_depth_m = 150.0

[environment.current]
speed_kn = 1.2
direction_deg = 70.0

[agenda]
base_course_deg = 10.0
autopilot_rudder_deg = 3.0
approach_s = 20.0
repeat_unsteady = 0

[[agenda.trial]]
name = "log_cal"
kind = "log_calibration"
run_s = 30.0

[[agenda.trial.speed]]
rpm = 410.0
pitch = 1.022
pattern = "pair"
"""


def _cmd(scen: Path, out: Path) -> list[str]:
    return [sys.executable, "-m", "vtrials", "run", str(scen), "--out", str(out)]


def _env():
    env = dict(os.environ)
    env["PYTHONPATH"] = str(ROOT) + os.pathsep + env.get("PYTHONPATH", "")
    return env


def _tree(d: Path) -> dict:
    """relative path → sha256 of every file under d (results.json and report.md without wall times)."""
    out = {}
    for p in sorted(d.rglob("*")):
        if p.is_file():
            b = p.read_bytes()
            if p.name == "results.json":
                doc = json.loads(b)
                doc.pop("wall_time_s", None)
                doc.pop("timings", None)
                b = json.dumps(doc, sort_keys=True).encode()
            if p.name == "report.md" or p.suffix == ".png":
                b = b""  # wall times and figure rendering: their presence is what counts here
            out[str(p.relative_to(d))] = hashlib.sha256(b).hexdigest()
    return out


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """A complete run of seed 2000 and one of seed 2001 (the references), with their wall times."""
    d = tmp_path_factory.mktemp("runs")
    ref = {}
    for seed in (2000, 2001):
        scen = d / f"pair_{seed}.toml"
        scen.write_text(PAIR.format(seed=seed))
        out = d / f"ref_{seed}"
        t0 = time.perf_counter()
        r = subprocess.run(_cmd(scen, out), env=_env(), capture_output=True, text=True, cwd=d, timeout=300)
        wall = time.perf_counter() - t0
        assert r.returncode == 0, r.stderr
        ref[seed] = (scen, out, _tree(out), wall, r)
    return d, ref


def test_under_determined_current_reported_exit_0_with_warning(runs):
    d, ref = runs
    scen, out, tree, wall, r = ref[2000]
    warn = [ln for ln in r.stderr.splitlines() if ln.startswith("vtrials: warning:")]
    assert len(warn) == 1 and "current under-determined" in warn[0] and "one axis" in warn[0], r.stderr
    assert "Traceback" not in r.stderr
    doc = json.loads((out / "results.json").read_text())
    red = doc["trials"][0]["reduced"]
    assert red["under_determined"][0]["quantity"] == "current"
    assert set(red["current"]) == {"under_determined", "trend", "t_ref"}  # no number for the current
    assert doc["trials"][0]["error"]["summary"]["max_current_error_kn"] is None
    # the rest of the trial is still reduced: the pair's speed through water, against the truth
    leg = doc["trials"][0]["error"]["legs"][0]
    assert leg["stw_error_kn"] is not None and abs(leg["stw_error_kn"]) < 0.3
    assert "under-determined" in (out / "report.md").read_text()
    assert not (d / "MUJOCO_LOG.TXT").exists()


def test_files_get_the_users_umask(runs):
    _, ref = runs
    out = ref[2000][1]
    mask = os.umask(0o022)
    os.umask(mask)
    for p in [out, *out.rglob("*")]:
        want = (0o777 if p.is_dir() else 0o666) & ~mask
        assert p.stat().st_mode & 0o777 == want, (p, oct(p.stat().st_mode))


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGKILL])
def test_killed_run_leaves_the_earlier_run_or_the_new_one(runs, sig, tmp_path):
    """Kill a run of seed 2001 writing into a directory holding a complete run of seed 2000, at
    random moments of its life (seeded): afterwards the directory holds exactly one of the two."""
    d, ref = runs
    old_tree, new_tree = ref[2000][2], ref[2001][2]
    wall = ref[2001][3]
    rng = np.random.default_rng(12 if sig == signal.SIGINT else 13)
    seen = set()
    # three moments as fractions of the reference run's wall time, and one (None) as soon as the run's
    # staging directory appears: a kill then always finds the earlier run in place, however the
    # machine's load makes this run's speed differ from the reference's
    for k, frac in enumerate([*rng.uniform(0.1, 0.7, 2), 0.97, None]):
        out = tmp_path / f"out{k}"
        import shutil
        shutil.copytree(ref[2000][1], out)
        proc = subprocess.Popen(_cmd(ref[2001][0], out), env=_env(), stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, text=True, cwd=tmp_path)
        if sig == signal.SIGINT:
            proc.stdout.readline()  # in main() (a Ctrl-C during Python's start-up is Python's own)
        if frac is None:
            while proc.poll() is None and not list(tmp_path.glob(f".out{k}.staging-*")):
                time.sleep(0.005)
        else:
            time.sleep(float(frac) * wall)
        proc.send_signal(sig)
        so, se = proc.communicate(timeout=300)
        tree = _tree(out)
        assert tree in (old_tree, new_tree), (k, frac, sorted(set(tree) ^ set(old_tree)))
        seen.add("old" if tree == old_tree else "new")
        assert not [p for p in tmp_path.iterdir() if p.name.startswith(f".out{k}.")] or sig == signal.SIGKILL
        if sig == signal.SIGINT and proc.returncode == -signal.SIGINT:
            # the signal came as Python shut down after a complete run: the new run is in place
            assert tree == new_tree and "Traceback" not in se, se
        elif sig == signal.SIGINT and proc.returncode != 0:
            assert proc.returncode == 130, se
            lines = se.strip().splitlines()
            assert len(lines) == 1 and lines[0].startswith("vtrials: interrupted ") \
                and lines[0].endswith("nothing written") and "trial time" in lines[0], se
    if sig == signal.SIGINT:
        return
    # a later run cleans what a killed one left beside --out
    r = subprocess.run(_cmd(ref[2001][0], tmp_path / "out0"), env=_env(), capture_output=True, text=True,
                       cwd=tmp_path, timeout=300)
    assert r.returncode == 0 and _tree(tmp_path / "out0") == new_tree
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".out0.")]
    assert not (tmp_path / "MUJOCO_LOG.TXT").exists()
    assert "old" in seen


def test_resolve_current_under_determined_cases():
    """One reciprocal pair; two pairs on one axis (rank-deficient): the current is reported as
    under-determined, each pair's STW is the mean of its ground speeds (seed 000 eq. 3); four legs
    on two axes (one four-leg set): all resolved, and the fit recovers a known current exactly."""
    U, cn, ce = 7.0, 0.4, -0.3
    def vg(h, u):
        return math.hypot(u * math.cos(h) + cn, u * math.sin(h) + ce)
    h1 = np.radians([10.0, 190.0])
    g, Ud, cur, fit, under = resolve_current([0.0, 900.0], h1, [vg(h, U) for h in h1], [0.02, 0.02], [1, 1])
    assert under[0]["quantity"] == "current" and "one axis" in under[0]["why"] and "north" not in cur
    assert Ud[1].value == pytest.approx(0.5 * (vg(h1[0], U) + vg(h1[1], U)))
    assert Ud[1].value == pytest.approx(U, abs=0.02)  # only the cross-axis current remains (2nd order)
    h2 = np.radians([10.0, 190.0, 10.0, 190.0])
    v2 = [vg(h, u) for h, u in zip(h2, [U, U, 9.0, 9.0])]
    g, Ud, cur, fit, under = resolve_current([0, 900, 1800, 2700], h2, v2, [0.02] * 4, [1, 1, 2, 2])
    assert "rank" in under[0]["why"] and Ud[2].value == pytest.approx(9.0, abs=0.02)
    h4 = np.radians([10.0, 100.0, 190.0, 280.0, 10.0, 190.0])
    v4 = [vg(h, u) for h, u in zip(h4, [U] * 4 + [9.0, 9.0])]
    g, Ud, cur, fit, under = resolve_current([0, 600, 1200, 1800, 2400, 3000], h4, v4, [0.02] * 6,
                                             [1, 1, 1, 1, 2, 2])
    assert under == [] and fit["dof"] == 2
    assert cur["north"].value == pytest.approx(cn, abs=1e-8) and cur["east"].value == pytest.approx(ce, abs=1e-8)
    assert Ud[1].value == pytest.approx(U, abs=1e-8) and Ud[2].value == pytest.approx(9.0, abs=1e-8)


def test_mujoco_warning_is_simulation_error_and_no_log_file(tmp_path, monkeypatch):
    from vtrials.physics.simulator import ShipState, Simulator
    from vtrials.physics.vessel import load_vessel
    monkeypatch.chdir(tmp_path)
    sim = Simulator(load_vessel("kvlcc2_l7"), 1, 0.01)
    sim.set_state(0, ShipState(u=1.0, shaft_rps=(11.0,)))
    sim.step(5)
    sim.batch.warning[0, 3, 1] += 1  # as MuJoCo does on "Nan, Inf or huge value in QPOS"
    with pytest.raises(SimulationError) as e:
        sim.step(1)
    msg = str(e.value)
    assert msg.startswith("simulation stopped at t = ") and "MuJoCo warning" in msg and "qpos" in msg
    assert "\n" not in msg and e.value.time_s == pytest.approx(0.06)
    assert not (tmp_path / "MUJOCO_LOG.TXT").exists()
