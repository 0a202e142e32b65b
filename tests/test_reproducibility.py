"""Same scenario and seed → byte-identical results.json (less wall time) and truth file, whatever the
thread count; a ship in a batch evolves exactly as it would alone."""

from __future__ import annotations

import json

import numpy as np

from vtrials.cli import main
from vtrials.runner.side_by_side import simulate
from vtrials.scenario import load_scenario


def _run(tmp_path, scen, name, threads):
    out = tmp_path / name
    assert main(["run", str(scen), "--out", str(out), "--threads", str(threads), "--quiet", "--no-plot"]) == 0
    doc = json.loads((out / "results.json").read_text())
    doc.pop("wall_time_s")
    return doc, (out / "truth.nc").read_bytes()


def test_byte_identical_outputs(tmp_path, scenarios_dir):
    scen = scenarios_dir / "kvlcc2_l7_zigzag.toml"
    a, ta = _run(tmp_path, scen, "a", 1)
    b, tb = _run(tmp_path, scen, "b", 2)
    assert a == b
    assert ta == tb
    # the texts too, not only the parsed values
    ra = (tmp_path / "a" / "results.json").read_text().splitlines()
    rb = (tmp_path / "b" / "results.json").read_text().splitlines()
    assert [x for x in ra if "wall_time_s" not in x] == [x for x in rb if "wall_time_s" not in x]


def test_batch_member_equals_single_run(tmp_path, scenarios_dir):
    full = simulate(load_scenario(scenarios_dir / "kvlcc2_l7_zigzag.toml"))
    text = (scenarios_dir / "kvlcc2_l7_zigzag.toml").read_text()
    head, *mans = text.split("[[maneuver]]")
    single = tmp_path / "one.toml"
    single.write_text(head + "[[maneuver]]" + mans[2])
    one = simulate(load_scenario(single))
    m_full = full.maneuvers[2]
    m_one = one.maneuvers[0]
    assert m_full.name == m_one.name
    n = len(m_one.columns["t"])
    for k, v in m_one.columns.items():
        assert np.array_equal(v, m_full.columns[k][:n]), k
    assert m_full.truth == m_one.truth
