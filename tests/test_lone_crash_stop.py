"""A crash stop run on its own (no turning circles, no other approach): its track through the water
needs the current, which the reduction then takes from the run's own approach — the tracking's ground
velocity less the water-track log's, turned by the gyro — with the log's scale and alignment errors and
the gyro's bias in its covariance. Before, such a run was reduced on the ground track with no current in
any interval: on 60 KVLCC2 days (0-0.5 kn current) head reach, track reach and lateral deviation were
2-8 % covered, errors of tens of metres against ±3 m; with the approach's current 92-95 %."""

from __future__ import annotations

import json
import math

import pytest

from vtrials.runner import run

SCENARIO = """
[scenario]
title = "Patrol vessel crash stop on its own, 0.8 kn current"
ship = "patrol51"
seed = 2207
timestep_s = 0.05
record_every = 1
truth_every = 10

[environment]
water_depth_m = 150.0

[environment.current]
speed_kn = 0.8
direction_deg = 100.0

[environment.wind]
speed_kn = 8.0
direction_deg = 20.0

[agenda]
base_course_deg = 20.0
autopilot_rudder_deg = 3.0
approach_s = 60.0
settle_min_s = 30.0

[[agenda.trial]]
name = "stop"
kind = "maneuvering"

[[agenda.trial.run]]
type = "speed_change"
order = "flank"
to_order = "back_emergency"
"""


@pytest.fixture(scope="module")
def lone_stop(tmp_path_factory):
    d = tmp_path_factory.mktemp("lone_stop")
    (d / "lone_stop.toml").write_text(SCENARIO)
    run(d / "lone_stop.toml", d / "out", plot=False)
    return json.loads((d / "out" / "results.json").read_text())


def test_lone_crash_stop_is_corrected_for_the_current_of_its_own_approach(lone_stop):
    tr = lone_stop["trials"][0]
    red = tr["reduced"]["runs"][0]
    assert red["drift_method"] == "current from the water-track log against the tracking (this run's approach)"
    assert "no drift correction" not in red["notes"]
    # the current used is the real one (0.8 kn = 0.41 m/s from 100 deg) within its stated uncertainty
    c_n, c_e = red["drift_used"]["north"], red["drift_used"]["east"]
    true_n, true_e = 0.8 * 0.514444 * math.cos(math.radians(100.0)), 0.8 * 0.514444 * math.sin(math.radians(100.0))
    assert abs(c_n["value"] - true_n) < 3 * c_n["std"] + 0.01
    assert abs(c_e["value"] - true_e) < 3 * c_e["std"] + 0.01
    # the reaches' intervals carry the current's error over the time to dead in the water
    el = red["time_to_dead_in_water"]["value"]
    assert red["track_reach"]["std"] >= 0.5 * el * min(c_n["std"], c_e["std"])
    err = tr["error"]["runs"][0]
    for k in ("track_reach", "head_reach", "lateral_deviation", "time_to_dead_in_water"):
        e = err[k]
        assert abs(e["error"]) <= 1.5 * e["half_width95"], (k, e)
