"""The agenda engine: bad agendas, the director's steadiness verdict, calm-water truth, and whole
trial days — records written, reductions from the record files, scores against truth."""

from __future__ import annotations

import json
import math

import numpy as np
from scipy import stats
import pytest

from tests.calibration import drawn_meter_errors, net_of_calibration
from vtrials.trials.agenda import Steadiness
from vtrials.truth.calmwater import steady_points, twin_points
from vtrials.cli import main
from vtrials.trials.crew import judge
from vtrials.records.netcdf import open_record, read_groups
from vtrials.runner import run
from vtrials.units import KNOT
from vtrials.physics.vessel import load_vessel

HEAD = """
[scenario]
title = "t"
ship = "patrol51"
seed = 7
timestep_s = 0.05
truth_every = 10

[environment]
water_depth_m = 100.0
"""

SHORT = HEAD + """
[environment.current]
speed_kn = 0.5
direction_deg = 100.0

[agenda]
base_course_deg = 30.0
approach_s = 30.0
settle_min_s = 30.0
runout_s = 120.0

[agenda.steadiness]
window_s = 30.0

[[agenda.trial]]
name = "std"
kind = "standardization"
run_s = 60.0

[[agenda.trial.spot]]
rpm = 380.0
pitch = 0.92
runs = 2

[[agenda.trial.spot]]
rpm = 450.0
pitch = 1.22
runs = 2

[[agenda.trial.spot]]
rpm = 530.0
pitch = 1.37
runs = 2
"""


def _bad(tmp_path, capsys, text):
    p = tmp_path / "a.toml"
    p.write_text(text)
    out = tmp_path / "out"
    code = main(["run", str(p), "--out", str(out), "--quiet"])
    err = capsys.readouterr().err.strip()
    assert code == 2
    assert len(err.splitlines()) == 1, err
    assert str(p) in err
    assert not out.exists(), "nothing may be written for a bad agenda"
    return err


@pytest.mark.parametrize("edit, field, words", [
    (lambda s: s.replace('kind = "standardization"', 'kind = "sea_state"'), "agenda.trial[0].kind",
     "unknown trial kind"),
    (lambda s: s.replace("runs = 2\n\n[[agenda.trial.spot]]\nrpm = 450.0", "runs = 1\n\n[[agenda.trial.spot]]\nrpm = 450.0"),
     "agenda.trial[0].spot[0].runs", "at least 2 runs"),
    (lambda s: s.replace("rpm = 380.0\npitch = 0.92", "rpm = 380.0"), "agenda.trial[0].spot[0].pitch",
     "controllable-pitch"),
    (lambda s: s.replace("rpm = 380.0\npitch = 0.92", "rpm = 380.0\npitch = 0.92\ntrailed = \"centre\""),
     "agenda.trial[0].spot[0].trailed", "unknown shaft"),
    (lambda s: s.replace("rpm = 380.0\npitch = 0.92", "rpm = 380.0\npitch = 0.92\ntrailed = \"port\"\nlocked = \"starboard\""),
     "agenda.trial[0].spot[0]", "no shaft would be left driving"),
    (lambda s: s.replace("rpm = 530.0", "rpm = 900.0"), "agenda.trial[0].spot[2].rpm", "above"),
    (lambda s: s.replace('run_s = 60.0', 'run_s = 60.0\ndisplacement_m3 = 500.0'), "agenda.trial[0].displacement_m3",
     "one loading condition"),
    (lambda s: s.replace('base_course_deg = 30.0', 'base_course_deg = 30.0\nbase_speed = 3'), "agenda",
     "base_speed"),
    (lambda s: s + '\n[[maneuver]]\nname = "m"\nkind = "turning_circle"\nrudder_deg = 35.0\n', "agenda",
     "not both"),
])
def test_bad_standardization_agenda(tmp_path, capsys, edit, field, words):
    err = _bad(tmp_path, capsys, edit(SHORT))
    assert field in err and words in err, err


LOGCAL = HEAD + """
[agenda]
base_course_deg = 10.0

[[agenda.trial]]
name = "lc"
kind = "log_calibration"

[[agenda.trial.speed]]
rpm = 340.0
pitch = 0.743
pattern = "four_leg"
headings_deg = {headings}
"""


@pytest.mark.parametrize("headings", ["[10, 100, 190, 250]", "[10, 100, 10, 100]", "[10, 100, 190]",
                                      "[10, 280, 190, 100, 10]"])
def test_headings_that_cannot_form_a_four_leg_set(tmp_path, capsys, headings):
    err = _bad(tmp_path, capsys, LOGCAL.format(headings=headings))
    assert "agenda.trial[0].speed[0].headings_deg" in err


def test_four_leg_sets_either_way_round_are_accepted(tmp_path):
    from vtrials.scenario import load_scenario
    for h in ("[10, 100, 190, 280]", "[350, 260, 170, 80]"):
        p = tmp_path / "a.toml"
        p.write_text(LOGCAL.format(headings=h))
        scn = load_scenario(p)
        assert [round(math.degrees(r.heading)) % 360 for r in scn.agenda.runs] == \
            [int(x) % 360 for x in json.loads(h)]


# ----------------------------------------------------------------------------------- the director
def _display(t, rps=10.0, rps_slope=0.0, q=5e4, q_slope=0.0, heading=0.5, log=8.0, log_slope=0.0, rng=None):
    rng = rng or np.random.default_rng(0)
    n = t.size
    return {"rps": [(t, rps + rps_slope * t + 0.001 * rng.standard_normal(n))] * 2,
            "torque": [(t, q + q_slope * t + 50.0 * rng.standard_normal(n))] * 2,
            "heading": (t, heading + 0.002 * rng.standard_normal(n)),
            "log": (t, log + log_slope * t + 0.02 * rng.standard_normal(n))}


def test_director_verdicts():
    st = Steadiness()
    t = np.arange(0.0, 60.0, 0.5)
    ok, why = judge(_display(t), 0.5, st, ("governed", "governed"))
    assert ok and not why
    # r/min still coming up by 1 % over the window
    ok, why = judge(_display(t, rps_slope=0.1 / 60), 0.5, st, ("governed", "governed"))
    assert not ok and any("r/min" in w for w in why)
    # torque building up 5 % over the minute
    ok, why = judge(_display(t, q_slope=2.5e3 / 60), 0.5, st, ("governed", "governed"))
    assert not ok and any("torque" in w for w in why)
    # log speed still rising 0.3 kn/min
    ok, why = judge(_display(t, log_slope=0.3 * KNOT / 60), 0.5, st, ("governed", "governed"))
    assert not ok and any("log speed" in w for w in why)
    # heading 3° off the ordered course; near north the circular mean is used
    ok, why = judge(_display(t, heading=0.5 + math.radians(3)), 0.5, st, ("governed", "governed"))
    assert not ok and any("heading" in w for w in why)
    ok, _ = judge(_display(t, heading=math.radians(359.5)), math.radians(0.5), st, ("governed", "governed"))
    assert ok
    # a locked shaft's meters are not judged
    d = _display(t)
    d["rps"] = [d["rps"][0], (t, 0.3 * t)]
    ok, _ = judge(d, 0.5, st, ("governed", "locked"))
    assert ok


# ----------------------------------------------------------------------------------- calm-water truth
def test_calm_water_twins_agree_with_the_steady_state_solution():
    """Two independent routes to the calm-water truth: simulated twins (autopilot, governor, 6 DOF)
    converge on the root-found steady state for symmetric settings."""
    v = load_vessel("patrol51")
    rps = [(380 / 60, 380 / 60), (530 / 60, 530 / 60)]
    pitch = [(0.92, 0.92), (1.37, 1.37)]
    ref = steady_points(v, rps, pitch, dt=0.05)
    tw = twin_points(v, [{"rps": list(r), "pitch": list(p), "modes": ["governed"] * 2} for r, p in zip(rps, pitch)],
                     dt=0.05)
    for a, b in zip(ref, tw):
        assert b["steady"]
        assert b["stw"] == pytest.approx(a["stw"], rel=2e-4)
        assert b["power"] == pytest.approx(a["power"], rel=1e-3)


def test_trailed_shaft_twin_needs_rudder_and_loses_speed():
    v = load_vessel("patrol51")
    both = {"rps": [450 / 60] * 2, "pitch": [1.22] * 2, "modes": ["governed", "governed"]}
    one = {"rps": [450 / 60] * 2, "pitch": [1.22] * 2, "modes": ["trailed", "governed"]}
    a, b = twin_points(v, [both, one], dt=0.05)
    assert b["steady"] and b["stw"] < 0.85 * a["stw"]
    assert abs(b["rudder"]) > math.radians(0.5) > abs(a["rudder"])
    assert b["rps"][0] > 0.5  # the trailed screw windmills


# ----------------------------------------------------------------------------------- a short trial day
@pytest.fixture(scope="module")
def short_day(tmp_path_factory):
    d = tmp_path_factory.mktemp("short")
    p = d / "short.toml"
    p.write_text(SHORT)
    res = run(p, d / "a", plot=True)
    return p, d, res


def test_short_day_records_and_results(short_day):
    p, d, res = short_day
    out = d / "a"
    rec = open_record(out / "records" / "std.nc")
    log = rec.run_log
    assert [r["run"] for r in log if r["accepted"]] == [1, 2, 3, 4, 5, 6]
    ev = rec.events
    for r in log:
        marks = {lab: t for t, n, lab in zip(ev["time"], ev["run"], ev["label"]) if n == r["run"]
                 and r["t_comex"] - 1e-6 <= t <= r["t_finex"] + 1e-6}
        assert marks["COMEX"] < marks["EXECUTE"] < marks["FINEX"]
        assert marks["EXECUTE"] - marks["COMEX"] == pytest.approx(30.0, abs=0.06)
        assert marks["FINEX"] - marks["EXECUTE"] == pytest.approx(60.0, abs=0.06)
    # courses alternate base / reciprocal across the agenda
    assert [round(r["course_deg"]) for r in log] == [30, 210, 30, 210, 30, 210]
    # the record holds no truth: its variables are instrument channels and logs only
    raw = read_groups(out / "records" / "std.nc")
    assert raw["attrs"]["content"] == "record"
    assert "u_r" not in json.dumps(list(raw["groups"]))
    doc = json.loads((out / "results.json").read_text())
    tr = doc["trials"][0]
    assert set(tr) >= {"reduced", "truth", "error"}
    assert len(tr["reduced"]["spots"]) == 3
    assert (out / "report.md").is_file() and (out / "std_speed_power.png").is_file()
    assert doc["agenda"]["total_time_s"] == pytest.approx(sum(r["elapsed_s"] for r in doc["agenda"]["runs"])
                                                         + doc["agenda"]["runs"][0]["t_start"], rel=1e-9)


def test_short_day_is_reproducible(short_day):
    p, d, res = short_day
    res2 = run(p, d / "b", plot=False)
    a = read_groups(d / "a" / "records" / "std.nc")
    b = read_groups(d / "b" / "records" / "std.nc")
    assert a["attrs"] == b["attrs"]
    for g in a["groups"]:
        for k, v in a["groups"][g]["variables"].items():
            np.testing.assert_array_equal(v, b["groups"][g]["variables"][k])
    assert [x.t_finex for x in res.attempts] == [x.t_finex for x in res2.attempts]


# ----------------------------------------------------------------------------------- acceptance
@pytest.fixture(scope="module")
def log_calibration(tmp_path_factory, scenarios_dir):
    out = tmp_path_factory.mktemp("lc")
    run(scenarios_dir / "patrol51_log_calibration.toml", out, plot=True)
    return json.loads((out / "results.json").read_text())


def test_log_calibration_speed_through_water_per_leg(log_calibration):
    """Each leg's speed through water (the group's, from the joint current fit) within 0.1 kn of the mean
    of the group's true leg speeds; the legs' own true speeds spread about that mean by less than
    0.05 kn (head and tail wind). The groups' 95 % intervals: on one day six calibrated intervals all
    cover only 0.95⁶ = 74 % of the time (less independent still: the groups share the current's
    polynomial), so one day is checked for consistency, not coverage — no group off by more than 1.5
    half-widths (|z| > 2.94: 0.3 % per group), and Σ z² over the groups below the 99.9 % point of
    χ²(6). Their coverage is measured where it can be, over a campaign
    (benchmarks/results/campaign_patrol51_log_calibration_200.json)."""
    tr = log_calibration["trials"][0]
    for leg in tr["error"]["legs"]:
        assert abs(leg["stw_leg_truth"] - leg["stw"]["truth"]) < 0.05 * KNOT, leg
    legs = tr["error"]["legs"]
    assert len(legs) == 16
    z = {}
    for leg in legs:
        assert abs(leg["stw_error_kn"]) < 0.1, leg
        c = leg["stw"]
        z[leg["group"]] = (c["reduced"] - c["truth"]) / (0.5 * (c["hi95"] - c["lo95"]) / 1.959964)
        assert abs(z[leg["group"]]) <= 1.5 * 1.959964, leg
    assert len(z) == 6
    assert sum(v * v for v in z.values()) < stats.chi2.ppf(0.999, len(z)), z


def test_log_calibration_recovers_the_knotmeter(log_calibration):
    tr = log_calibration["trials"][0]
    cal = tr["error"]["calibrations"]["knotmeter"]
    assert cal["intercept"]["covered"] and cal["slope"]["covered"], cal
    # the reduced line is within 0.05 kn of the true one over the calibrated range
    assert max(abs(x) for x in cal["line_error_at_points_kn"]) < 0.05
    red = tr["reduced"]["calibrations"]["knotmeter"]
    # the line is solved inside the joint current fit: its dof are the legs' less its parameters (the line,
    # a speed per group without readings, the current's polynomial)
    assert red["r2"] > 0.999 and red["dof"] == red["legs_in_fit"] - len(red["parameters"]) >= 3
    assert red["parameters"][:2] == ["intercept", "slope"]
    assert tr["reduced"]["drift_angle"]["source"].startswith("doppler")


@pytest.fixture(scope="module")
def standardization(tmp_path_factory, scenarios_dir):
    out = tmp_path_factory.mktemp("std")
    run(scenarios_dir / "patrol51_standardization.toml", out, plot=True)
    return json.loads((out / "results.json").read_text()), drawn_meter_errors(out / "truth.nc")


def test_standardization_speed_power_within_one_percent(standardization):
    """Power at equal speed within 1 % of the truth at every spot once the meters' drawn calibration
    errors are taken out (at the lowest spot the torsionmeters run at 2 % of full scale, where the
    zero left after zero setting alone is worth ~1 %: tests/calibration.py); the full error inside
    the stated 95 % interval."""
    res, meters = standardization
    tr = res["trials"][0]
    sm = tr["error"]["summary"]
    assert sm["spots"] >= 8
    net = []
    for sp, red in zip(tr["error"]["spots"], tr["reduced"]["spots"]):
        e = sp["power_at_equal_speed"]
        assert e["covered"], sp
        net.append(net_of_calibration(e["error"], meters, red["torque"], red["rps"]))
        assert abs(sp["stw_error_kn"]) < 0.1
    print("power error net of the meters' calibration [%]:", np.round(np.array(net) * 100, 2))
    assert max(abs(x) for x in net) < 0.01


def test_standardization_speeds_covered(standardization):
    standardization = standardization[0]
    tr = standardization["trials"][0]
    cov = [sp["stw"]["covered"] for sp in tr["error"]["spots"]]
    assert sum(cov) >= len(cov) - 1, cov
    # five simulated hours or more, every run judged steady or repeated
    assert standardization["agenda"]["total_time_s"] > 5 * 3600
    assert all(r["accepted"] or not (r["approach_steady"] and r["run_steady"])
               for r in standardization["agenda"]["runs"])
