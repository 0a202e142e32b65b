"""Replicates stepped together (issue 11, deliverable 5): the trial days of several replicates as the
ships of one simulator, each driven by its own crew in a coroutine (vtrials.trials.fleet). Every day's
records, truth references and scores are bit-identical to that day simulated alone — in calm water
with its own wind and current, and in a seaway with its own wave realization — and a campaign's table
does not depend on the batch size."""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np
import pytest

from vtrials.campaign.run import run_replicates
from vtrials.campaign.spec import load_campaign, replicate_doc, replicate_seeds
from vtrials.runner.trial_day import (CannotShare, score_agenda, simulate_agenda, simulate_agendas,
                                      trial_records_in_memory)
from vtrials.physics.simulator import Simulator
from vtrials.scenario import load_scenario
from vtrials.trials.driver import Driver
from vtrials.trials.fleet import Fleet

DATA = Path(__file__).resolve().parent / "data"
LOGCAL = DATA / "campaign_logcal.toml"
SEA = DATA / "patrol51_seakeeping_short.toml"


def _same(a, b, where=""):
    """Deep equality: arrays bit for bit (NaN equal to NaN), floats exactly, same structure."""
    if isinstance(a, dict):
        assert isinstance(b, dict) and list(a) == list(b), where
        for k in a:
            _same(a[k], b[k], f"{where}/{k}")
    elif isinstance(a, (list, tuple)):
        assert type(a) is type(b) and len(a) == len(b), where
        for i, (x, y) in enumerate(zip(a, b)):
            _same(x, y, f"{where}[{i}]")
    elif isinstance(a, np.ndarray):
        assert isinstance(b, np.ndarray) and a.dtype == b.dtype and a.shape == b.shape, where
        assert np.array_equal(a, b, equal_nan=True), where
    elif isinstance(a, float) and a != a:
        assert isinstance(b, float) and b != b, where
    else:
        assert a == b, (where, a, b)


def _check_identical(alone, together):
    for k, (a, b) in enumerate(zip(alone, together)):
        assert b.crew.ship == k and b.simulated_time_s == a.simulated_time_s
        _same(a.crew.truth_refs, b.crew.truth_refs, f"day {k} truth references")
        _same([att.log() for att in a.crew.attempts], [att.log() for att in b.crew.attempts], f"day {k} runs")
        ra, rb = trial_records_in_memory(a), trial_records_in_memory(b)
        assert list(ra) == list(rb) and ra
        for name in ra:
            _same(ra[name].attrs, rb[name].attrs, f"day {k} {name} attrs")
            _same(ra[name]._groups, rb[name]._groups, f"day {k} {name} channels")
        _same(np.concatenate(a.crew.truth_rows), np.concatenate(b.crew.truth_rows), f"day {k} truth")
        _same(score_agenda(a)["trials"], score_agenda(b)["trials"], f"day {k} scores")


def _replicates(n):
    spec = load_campaign(LOGCAL)
    return [load_scenario(LOGCAL, replicate_doc(spec, s)[0]) for s in replicate_seeds(spec.seed, n)]


def test_days_stepped_together_equal_the_days_alone():
    scns = _replicates(3)
    alone = [simulate_agenda(s) for s in scns]
    # the days differ (own current, wind, instrument draws; one ends ~390 s before the others, its
    # ship stepped on with nobody aboard) — and each is reproduced bit for bit in the shared simulator
    ends = [r.simulated_time_s for r in alone]
    assert max(ends) - min(ends) > 300.0
    together = simulate_agendas(scns)
    _check_identical(alone, together)


def test_seaway_days_with_their_own_wave_realizations_stepped_together():
    doc = tomllib.loads(SEA.read_text())
    # shortened for the test: one 2-min leg, 150 wave components (each ship its own realization)
    doc["environment"]["waves"]["n_components"] = 150
    doc["agenda"]["trial"][0]["leg"] = doc["agenda"]["trial"][0]["leg"][:1]
    doc["agenda"]["trial"][0]["leg"][0]["leg_s"] = 120.0
    scns = []
    for seed in (4004, 4005):
        doc["scenario"]["seed"] = seed
        scns.append(load_scenario(SEA, doc))
    alone = [simulate_agenda(s) for s in scns]
    assert not np.array_equal(alone[0].seaway, alone[1].seaway)  # two different seas
    _check_identical(alone, simulate_agendas(scns))


def test_days_that_cannot_share_a_simulator_are_refused_and_run_alone(tmp_path):
    scns = _replicates(2)
    doc = tomllib.loads(LOGCAL.read_text())
    doc["scenario"]["timestep_s"] = 0.04
    other = load_scenario(LOGCAL, doc)
    with pytest.raises(CannotShare, match="one by one"):
        simulate_agendas([scns[0], other])
    # a campaign worker given such a batch runs its days one by one: the same rows as alone
    spec = load_campaign(LOGCAL)
    together = run_replicates(str(LOGCAL), [0, 1], spec.seed, 2)
    alone = [run_replicates(str(LOGCAL), [i], spec.seed, 2)[0] for i in (0, 1)]
    for r in together + alone:
        r.pop("timings")
    assert together == alone


def test_fleet_hands_each_crew_exactly_its_own_slices():
    """Two controllers with different rhythms on one simulator: each ship's sink receives the slices
    its own advance calls cut (not the fleet's finer steps), and the rows are the ship's own."""
    from vtrials.physics.vessel import load_vessel
    v = load_vessel("patrol51")
    sim = Simulator(v, 2, 0.05)
    fleet = Fleet(sim)
    got = {0: [], 1: []}
    drivers = [fleet.driver(i, slice_s=2.0) for i in (0, 1)]
    for i, d in enumerate(drivers):
        d.sinks.append(lambda ship, rows, i=i: got[i].append((ship, rows)))

    def task(i, steps):
        def run():
            for n in steps:
                drivers[i].advance_steps(n)
        return run
    fleet.run([(0, task(0, [30, 7, 50])), (1, task(1, [3, 3, 3, 100]))])
    # ship 0: 30 → slices of 40 steps (2 s) max: 30, then 7, then 40 + 10
    assert [r.shape[0] for _, r in got[0]] == [30, 7, 40, 10]
    assert [r.shape[0] for _, r in got[1]] == [3, 3, 3, 40, 40, 20]
    assert all(s == 0 for s, _ in got[0]) and all(s == 1 for s, _ in got[1])
    # the rows: the same as one driver stepping ship 0 alone in the same slices
    lone = Simulator(v, 1, 0.05)
    ref = []
    d = Driver(lone, sinks=[lambda ship, rows: ref.append(rows)])
    for n in (30, 7, 40, 10):
        d.advance_steps(n)
    _same(np.concatenate(ref), np.concatenate([r for _, r in got[0]]), "ship 0 rows")


def test_a_failing_crew_stops_the_fleet_with_its_error():
    from vtrials.physics.vessel import load_vessel
    sim = Simulator(load_vessel("patrol51"), 2, 0.05)
    fleet = Fleet(sim)
    d0, d1 = fleet.driver(0), fleet.driver(1)
    d0.sinks.append(lambda s, r: None)
    d1.sinks.append(lambda s, r: None)

    def bad():
        d1.advance_steps(5)
        raise RuntimeError("crew 1 lost its bearings")
    with pytest.raises(RuntimeError, match="bearings"):
        fleet.run([(0, lambda: d0.advance_steps(100)), (1, bad)])
    with pytest.raises(RuntimeError, match="only inside Fleet.run"):
        d0.advance_steps(1)
    with pytest.raises(ValueError, match="one task per ship"):
        fleet.run([(0, lambda: None), (0, lambda: None)])
