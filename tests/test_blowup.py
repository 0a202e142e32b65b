"""A non-finite or runaway state stops the run with the time and the state in the message."""

from __future__ import annotations

import math

import numpy as np
import pytest

from vtrials.cli import main
from vtrials.errors import SimulationError
from vtrials.physics.simulator import ShipState, Simulator
from vtrials.physics.vessel import load_vessel


def test_nan_state_stops_with_time_and_state():
    sim = Simulator(load_vessel("kvlcc2_l7"), 2, 0.01)
    for i in range(2):
        sim.set_state(i, ShipState(u=1.0, shaft_rps=(11.0,)))
    sim.step(100)
    sim.qvel[1, 1] = np.nan
    with pytest.raises(SimulationError) as e:
        sim.step(10)
    msg = str(e.value)
    assert "t = 1.000 s" in msg and "ship 1" in msg and "non-finite" in msg
    assert "heading" in msg and "velocity through water" in msg
    assert e.value.time_s == pytest.approx(1.0)
    assert e.value.ship == 1


def test_runaway_is_caught_before_it_becomes_nan():
    """A time step far beyond the heave period's stability limit makes the motion explode; the run
    stops at the runaway limit, with a finite state in the message, not with NaN records."""
    sim = Simulator(load_vessel("kvlcc2_l7"), 1, 0.9)
    sim.set_state(0, ShipState(u=1.1, z=0.01, shaft_rps=(11.0,)))
    with pytest.raises(SimulationError) as e:
        sim.step(2000)
    msg = str(e.value)
    assert "runaway" in msg or "capsize" in msg
    assert "nan" not in msg.lower()
    assert math.isfinite(e.value.time_s)
    assert np.all(np.isfinite(sim.truth()))


def test_cli_blowup_exit_code_and_nothing_written(tmp_path, capsys):
    scen = tmp_path / "bad.toml"
    scen.write_text("""
[scenario]
title = "unstable step"
ship = "kvlcc2_l7"
seed = 1
timestep_s = 0.9

[initial]
froude_number = 0.142

[[maneuver]]
name = "turn"
kind = "turning_circle"
rudder_deg = 35.0
""")
    out = tmp_path / "out"
    code = main(["run", str(scen), "--out", str(out), "--quiet"])
    err = capsys.readouterr().err
    assert code == 3
    assert "simulation stopped at t =" in err and "state:" in err
    assert not out.exists()
