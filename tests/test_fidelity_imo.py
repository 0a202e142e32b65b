"""Issue 17 item 5: the IMO 10/10 verdicts take each criterion's worst case over all runs (as the
truth does), and the report prints the MSC.137(76) angle criteria in degrees."""

import math

from vtrials.reduce.maneuvering import imo_verdicts
from vtrials.report.trial_report import imo_rows
from vtrials.score.trials import json_ready


def _zz(run, first_deg, second_deg, t_init):
    e = lambda deg: {"value": math.radians(deg), "std": math.radians(0.1), "dof": None}  # noqa: E731
    return {"run": run, "type": "zigzag", "rudder_ordered": math.radians(10.0), "first_overshoot": e(first_deg),
            "second_overshoot": e(second_deg), "approach_sog": 7.9,
            "initial_turning_time": {"value": t_init, "std": 1.0}}


def test_second_overshoot_from_the_run_with_the_largest_second_overshoot():
    # the shipped kvlcc2_imo case: the run with the largest first overshoot (13.26°) is not the one with
    # the largest second overshoot (22.0°)
    runs = [_zz(1, 13.26, 13.6, 60.0), _zz(2, 12.9, 22.0, 70.0)]
    out = imo_verdicts(runs, [{"run": 1}, {"run": 2}], 320.0)
    v = out["verdicts"]
    assert abs(math.degrees(v["first_overshoot_10"]["value"]["value"]) - 13.26) < 1e-9
    assert abs(math.degrees(v["second_overshoot_10"]["value"]["value"]) - 22.0) < 1e-9
    assert abs(v["initial_turning"]["value"]["value"] - 70.0 * 7.9) < 1e-9


def test_report_prints_angles_in_degrees():
    runs = [_zz(1, 13.26, 13.6, 60.0), _zz(2, 12.9, 22.0, 70.0)]
    v = json_ready(imo_verdicts(runs, [{"run": 1}, {"run": 2}], 320.0))["verdicts"]
    rows = {r.split("|")[1].strip(): r for r in imo_rows(v, {})}
    row = rows["10/10 zig-zag second overshoot"]
    cells = [c.strip() for c in row.split("|")[1:-1]]
    assert cells[1] == "22.00°"  # value, degrees
    lv = 320.0 / 7.9
    assert cells[2] == f"{40.0:.2f}°" if lv >= 30 else cells[2] == f"{17.5 + 0.75 * lv:.2f}°"
    assert cells[3] == "True" and cells[4] == f"{40.0 - 22.0:.2f}°"
    assert rows["initial turning: distance to 10 deg heading change <= 2.5 L"].split("|")[2].strip() == \
        f"{70.0 * 7.9:.2f} m"
