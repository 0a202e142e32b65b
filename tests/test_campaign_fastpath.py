"""The campaign replicate's fast path: records reduced in memory give exactly what the written record
files give — the same arrays and attributes, the same reduction, the same campaign rows."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from vtrials.campaign.run import rows_of
from vtrials.records.netcdf import open_record
from vtrials.runner.trial_day import (score_agenda, simulate_agenda, trial_records_in_memory,
                                      write_agenda_outputs)
from vtrials.scenario import load_scenario

SCN = Path(__file__).resolve().parent / "data" / "patrol51_standardization_short.toml"


@pytest.fixture(scope="module")
def day(tmp_path_factory):
    res = simulate_agenda(load_scenario(SCN))
    out = tmp_path_factory.mktemp("fast") / "run"
    written = write_agenda_outputs(res, out, plot=False)
    return res, out, written


def _same(a, b, where=""):
    """Deep equality of read-back record contents: arrays bit for bit (NaN equal to NaN), same types."""
    if isinstance(a, dict):
        assert isinstance(b, dict) and list(a) == list(b), where
        for k in a:
            _same(a[k], b[k], f"{where}/{k}")
    elif isinstance(a, np.ndarray):
        assert isinstance(b, np.ndarray) and a.dtype == b.dtype and a.shape == b.shape, where
        assert np.array_equal(a, b, equal_nan=True), where
    else:
        assert type(a) is type(b) and a == b, (where, a, b)


def test_in_memory_records_equal_the_written_files(day):
    res, out, _ = day
    mem = trial_records_in_memory(res)
    assert list(mem) == ["standardization"]
    for name, rec in mem.items():
        disk = open_record(out / "records" / f"{name}.nc")
        _same(disk.attrs, rec.attrs, "attrs")
        _same(disk._groups, rec._groups, "groups")
        assert disk.instruments == rec.instruments and disk.team == rec.team
        assert len(disk.run_log) == 6  # the record is a real one: six runs logged


def test_fast_path_rows_equal_the_written_records_rows(day):
    res, out, written = day
    fast = score_agenda(res)
    assert fast["trials"] == written["trials"]  # the whole scored tree, every number
    assert json.loads((out / "results.json").read_text())["trials"] == fast["trials"]
    rows_fast, rows_disk = rows_of(fast, 0), rows_of(written, 0)
    assert rows_fast == rows_disk
    groups = {r["group"] for r in rows_fast}
    assert "standardization/spots[]/stw" in groups and "standardization/spots[]/power_at_equal_speed" in groups
    # real physics in the rows: spot speeds within 0.1 m/s of the truth
    stw = [r for r in rows_fast if r["group"] == "standardization/spots[]/stw"]
    assert len(stw) == 2 and all(abs(r["error"]) < 0.1 for r in stw)
