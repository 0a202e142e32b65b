"""Trial records: exact round trip, xarray, atomic writes (no partial file), truth kept apart."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest

from vtrials.records.netcdf import RecordError, open_record, read_groups, write_groups
from vtrials.runner.side_by_side import simulate, write_outputs
from vtrials.scenario import load_scenario


@pytest.fixture(scope="module")
def outputs(tmp_path_factory, scenarios_dir):
    out = tmp_path_factory.mktemp("rec")
    res = simulate(load_scenario(scenarios_dir / "kvlcc2_l7_turning.toml"))
    write_outputs(res, out, plot=False)
    return res, out


def test_record_round_trip_is_exact(outputs):
    res, out = outputs
    m = res.maneuvers[0]
    rec = open_record(out / "records" / f"{m.name}.nc")
    assert set(rec.instruments) == set(m.instruments.devices)
    for name, dev in m.instruments.devices.items():
        t, ch = m.instruments.readings(name)
        keep = t <= m.finex_time_s
        tr, _ = rec.channel(name, next(iter(dev.channels)))
        assert np.array_equal(tr, t[keep])
        for c in dev.channels:
            assert np.array_equal(rec.channel(name, c)[1], ch[c][keep], equal_nan=True)
            assert rec.units(name, c) == dev.channels[c][0]
    ev = rec.events
    assert ev["label"] == ["COMEX", "EXECUTE", "FINEX"]
    assert ev["time"][1] == pytest.approx(m.execute_time_s)
    assert rec.meta("gyro")["site"] == "gyro"
    assert rec.team["length_m"] == 7.0


def test_record_and_truth_open_in_xarray(outputs):
    xr = pytest.importorskip("xarray")
    res, out = outputs
    m = res.maneuvers[0]
    ds = xr.open_dataset(out / "records" / f"{m.name}.nc", group="gyro", engine="h5netcdf")
    assert "heading" in ds and ds["heading"].attrs["units"] == "rad" and ds.sizes["time"] > 100
    tds = xr.open_dataset(out / "truth.nc", group=m.name, engine="h5netcdf")
    assert tds["x"].attrs["units"] == "m"
    np.testing.assert_array_equal(tds["heading"].values, m.columns["heading"])


def test_reductions_cannot_open_truth(outputs):
    _, out = outputs
    with pytest.raises(RecordError, match="not a trial record"):
        open_record(out / "truth.nc")


def test_instrument_errors_go_to_truth_only(outputs):
    res, out = outputs
    m = res.maneuvers[0]
    truth = read_groups(out / "truth.nc")
    import json
    drawn = json.loads(truth["groups"][m.name]["attrs"]["instrument_errors"])
    assert set(drawn) == set(m.instruments.devices)
    rec = read_groups(out / "records" / f"{m.name}.nc")
    text = repr(rec["attrs"]) + repr([g["attrs"] for g in rec["groups"].values()])
    assert "drawn" not in text and "instrument_errors" not in text


def test_failed_write_leaves_no_file(tmp_path, monkeypatch):
    import h5netcdf.core as core
    target = tmp_path / "r.nc"
    real = core.Group.create_variable
    calls = {"n": 0}

    def flaky(self, *a, **k):
        calls["n"] += 1
        if calls["n"] > 3:
            raise OSError("disk full (simulated)")
        return real(self, *a, **k)

    monkeypatch.setattr(core.Group, "create_variable", flaky)
    groups = {"g": {"time": np.arange(10.0), "variables": {f"v{i}": (np.arange(10.0), "m", "x") for i in range(8)}}}
    with pytest.raises(OSError):
        write_groups(target, groups, {"content": "record"})
    assert list(tmp_path.iterdir()) == []


def test_killed_writer_leaves_no_partial_file(tmp_path):
    """A writer killed (SIGKILL) in the middle of a big write leaves no file under the target name;
    its hidden temporary is removed by the next writer."""
    target = tmp_path / "big.nc"
    script = textwrap.dedent(f"""
        import numpy as np, time, h5netcdf.core as core
        from vtrials.records.netcdf import write_groups
        real = core.Group.create_variable
        def slow(self, *a, **k):
            time.sleep(0.05)
            return real(self, *a, **k)
        core.Group.create_variable = slow
        print("start", flush=True)
        groups = {{"g": {{"time": np.arange(1000.0), "variables": {{f"v{{i}}": (np.arange(1000.0), "m", "x")
                                                                 for i in range(400)}}}}}}
        write_groups({str(target)!r}, groups, {{"content": "record"}})
    """)
    proc = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, text=True)
    assert proc.stdout.readline().strip() == "start"
    time.sleep(1.5)  # well into the ~20 s write
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait()
    assert not target.exists()
    leftovers = list(tmp_path.iterdir())
    assert all(p.name.startswith(".big.nc.") and p.name.endswith(".part") for p in leftovers)
    write_groups(target, {"g": {"time": np.arange(3.0), "variables": {"v": (np.arange(3.0), "m", "x")}}},
                 {"content": "record"})
    assert [p.name for p in tmp_path.iterdir()] == ["big.nc"]
    assert read_groups(target)["groups"]["g"]["variables"]["v"].tolist() == [0.0, 1.0, 2.0]
