"""The CLI's help documents everything, and a run writes what results.json promises."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from vtrials.cli import build_parser, main
from vtrials.trials.programs import KINDS


def test_help_texts(capsys):
    parser = build_parser()
    top = parser.format_help()
    assert "run" in top and "models" in top
    run = [a for a in parser._subparsers._group_actions[0].choices.items() if a[0] == "run"][0][1]
    text = run.format_help()
    for kind, cls in KINDS.items():
        assert kind in text
    for field in ("timestep_s", "froude_number", "speed_kn", "water_depth_m", "tidal_amplitude_kn",
                  "gradient_kn_per_nmi", "rudder_deg", "heading_change_deg", "first_side", "deviation_deg",
                  "results.json", "truth.nc", "--threads"):
        assert field in text, field


def test_module_entry_point_help():
    out = subprocess.run([sys.executable, "-m", "vtrials", "run", "--help"], capture_output=True, text=True)
    assert out.returncode == 0 and "SCENARIO" in out.stdout


def test_models_command(capsys):
    assert main(["models"]) == 0
    out = capsys.readouterr().out
    assert "kvlcc2_l7" in out and "kvlcc2 " in out


def test_run_writes_results(tmp_path, scenarios_dir, capsys):
    out = tmp_path / "o"
    assert main(["run", str(scenarios_dir / "kvlcc2_l7_turning.toml"), "--out", str(out)]) == 0
    doc = json.loads((out / "results.json").read_text())
    assert doc["simulated_time_s"] > 100 and doc["wall_time_s"] > 0
    assert doc["ship_length_m"] == 7.0
    assert [m["name"] for m in doc["maneuvers"]] == ["turn_35_starboard", "turn_35_port"]
    for m in doc["maneuvers"]:
        assert m["kind"] == "turning_circle" and m["completed"]
        for key in ("advance_m", "transfer_m", "tactical_diameter_m", "steady_turning_diameter_m",
                    "steady_speed_mps", "steady_rate_of_turn_dps", "ship_length_m"):
            assert isinstance(m["truth"][key], float), key
    assert (out / "trajectory.png").stat().st_size > 10000
    assert (out / "trajectory.png").read_bytes()[:4] == b"\x89PNG"


@pytest.mark.parametrize("path", sorted((Path(__file__).resolve().parent.parent / "scenarios").glob("*.toml")),
                         ids=lambda p: p.name)
def test_every_shipped_scenario_loads(path):
    """Every scenario in scenarios/ passes the full input check (model, instruments, agenda)."""
    from vtrials.scenario import load_scenario
    scn = load_scenario(path)
    assert scn.maneuvers or scn.agenda is not None


def test_summary_line_reads_every_trial_kinds_scores():
    """The run command's closing lines: a trial scored per run (error.summary) and a seakeeping trial
    scored per leg and response (summary, one level deeper) both print their scalars (a seakeeping
    trial had no error.summary and the command stopped with a KeyError after writing its outputs)."""
    from vtrials.cli import summary_line
    std = {"name": "std", "kind": "standardization", "error": {"summary": {"max_power_error": 0.0123, "runs": [1]}}}
    assert "max_power_error 0.0123" in summary_line(std)
    sk = {"name": "sk", "kind": "seakeeping", "legs": [],
          "summary": {"heave": {"bins": 12, "median_abs_amp_error": 0.021, "ok": True}}}
    line = summary_line(sk)
    assert "heave bins 12" in line and "heave median_abs_amp_error 0.021" in line and "ok" not in line
