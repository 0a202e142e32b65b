"""Bad input → one-line error naming file and field, non-zero exit, nothing written."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import pytest

from vtrials.cli import main
from vtrials.physics.vessel import MODELS_DIR

GOOD_SCENARIO = """
[scenario]
title = "t"
ship = "{ship}"
seed = 1
timestep_s = {dt}

[initial]
froude_number = 0.142

[environment]
water_depth_m = 8.05

[[maneuver]]
name = "turn"
kind = "{kind}"
rudder_deg = {rudder}
heading_change_deg = 90.0
approach_s = 1.0
"""


def scenario(tmp_path: Path, ship="kvlcc2_l7", kind="turning_circle", rudder=35.0, dt=0.01, text=None) -> Path:
    p = tmp_path / "s.toml"
    p.write_text(text if text is not None else GOOD_SCENARIO.format(ship=ship, kind=kind, rudder=rudder, dt=dt))
    return p


def model_copy(tmp_path: Path, edit) -> str:
    d = tmp_path / "kvlcc2_l7"
    shutil.copytree(MODELS_DIR / "kvlcc2_l7", d)
    t = d / "ship.toml"
    t.write_text(edit(t.read_text()))
    return "./kvlcc2_l7"


def run_cli(tmp_path, scen, capsys):
    out = tmp_path / "out"
    code = main(["run", str(scen), "--out", str(out), "--quiet"])
    err = capsys.readouterr().err
    return code, err, out


def check(code, err, out, *fragments):
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    for frag in fragments:
        assert frag in lines[0], (frag, lines[0])
    assert not out.exists()


def test_good_scenario_runs(tmp_path, capsys):
    code, err, out = run_cli(tmp_path, scenario(tmp_path), capsys)
    assert code == 0, err
    assert {p.name for p in out.iterdir()} == {"results.json", "truth.nc", "trajectory.png", "records"}
    assert [p.name for p in (out / "records").iterdir()] == ["turn.nc"]


def test_malformed_toml(tmp_path, capsys):
    p = scenario(tmp_path, text="[scenario\ntitle = 1\n")
    check(*run_cli(tmp_path, p, capsys), str(p), "malformed TOML")


def test_unknown_ship(tmp_path, capsys):
    p = scenario(tmp_path, ship="kvlcc3")
    check(*run_cli(tmp_path, p, capsys), str(p), "scenario.ship", "unknown ship 'kvlcc3'", "kvlcc2_l7")


def test_unknown_maneuver_kind(tmp_path, capsys):
    p = scenario(tmp_path, kind="loop_the_loop")
    check(*run_cli(tmp_path, p, capsys), str(p), "maneuver[0].kind", "turning_circle")


def test_rudder_beyond_maximum(tmp_path, capsys):
    p = scenario(tmp_path, rudder=40.0)
    check(*run_cli(tmp_path, p, capsys), str(p), "maneuver[0].rudder_deg", "maximum rudder angle", "35")


def test_misspelled_scenario_field(tmp_path, capsys):
    p = scenario(tmp_path)
    p.write_text(p.read_text().replace("froude_number", "froude_numbr"))
    check(*run_cli(tmp_path, p, capsys), str(p), "initial.froude_numbr", "did you mean 'froude_number'")


@pytest.mark.parametrize("edit,field,words", [
    (lambda s: s.replace("Y_v = -0.315\n", ""), "hull_mmg.Y_v", "missing"),
    (lambda s: s.replace("Y_v = -0.315", "Yv = -0.315"), "hull_mmg.Yv", "unknown field; did you mean"),
    (lambda s: s.replace("Y_v = -0.315", "Y_v = \"abc\""), "hull_mmg.Y_v", "expected a number"),
    (lambda s: s.replace("t_P = 0.220", "t_P = 1.5"), "propeller[0].t_P", "out of range"),
    (lambda s: s.replace('x_G = 0.25', 'x_G = { value = 0.25 }').replace(
        'source = "SIMMAN2008 / MMG2015 model L7 particulars (ships.md §1)"\n', ''), "particulars.", "source"),
    (lambda s: s.replace('displacement = 3.27', 'displacement = 3.30'), "inertial mass", "disagrees"),
])
def test_bad_model_file(tmp_path, capsys, edit, field, words):
    ship = model_copy(tmp_path, edit)
    p = scenario(tmp_path, ship=ship)
    code, err, out = run_cli(tmp_path, p, capsys)
    check(code, err, out, field, words)
    assert re.search(r"kvlcc2_l7/(ship\.toml|kvlcc2_l7\.xml)", err)


def test_bad_cli_arguments(tmp_path, capsys):
    with pytest.raises(SystemExit) as e:
        main(["run", "x.toml"])  # --out missing
    assert e.value.code == 2
    code = main(["run", str(tmp_path / "missing.toml"), "--out", str(tmp_path / "o"), "--quiet"])
    err = capsys.readouterr().err
    assert code == 2 and "missing.toml" in err and "file not found" in err
    assert not (tmp_path / "o").exists()
