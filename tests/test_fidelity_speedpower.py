"""Issue 17 acceptance for the speed/power analysis: KVLCC2 in a 15 kn wind, every spot with head- and
tail-wind runs, corrected power within 1 % of the true calm-water curve at equal speed (the truth: the
model's own steady states at the trial's r/min). Also the residual-acceleration correction the
reduction applies, against an exact quadratic track."""

import json
import math

import numpy as np
import pytest

from vtrials import run
from vtrials.reduce import speedpower as SP


def test_along_track_acceleration_of_a_quadratic_track():
    rng = np.random.default_rng(3)
    t = np.arange(0.0, 600.0, 1.0)
    a, v0, c = 1.2e-4, 7.0, math.radians(33.0)
    s = v0 * t + 0.5 * a * t ** 2
    n = 100.0 + s * math.cos(c) + rng.normal(0, 0.5, t.size)
    e = -50.0 + s * math.sin(c) + rng.normal(0, 0.5, t.size)
    got, se = SP.along_track_acceleration(t, n, e, 0.0, 599.0)
    assert abs(got - a) < 4 * se and se < 5e-6
    r, _ = SP.acceleration_resistance(a, 312600.0, 1025.0, added_mass_fraction=0.08)
    assert r == pytest.approx(1025.0 * 312600.0 * 1.08 * a, rel=1e-14)


@pytest.fixture(scope="module")
def kvlcc2_sp(tmp_path_factory, scenarios_dir):
    out = tmp_path_factory.mktemp("kvlcc2_sp")
    run(scenarios_dir / "kvlcc2_speed_power.toml", out, plot=False)
    return json.loads((out / "results.json").read_text())


def test_kvlcc2_speed_power_within_one_percent_in_head_and_tail_wind(kvlcc2_sp):
    tr = kvlcc2_sp["trials"][0]
    errs = []
    for sp, red in zip(tr["error"]["spots"], tr["reduced"]["spots"]):
        r_aa = [w["r_aa"] for w in red["wind"]]
        assert min(r_aa) < 0 < max(r_aa), r_aa  # the spot has tail- and head-wind runs
        assert red["xi_P"] is not None and red["xi_P"] > 0  # the DPM's third term is in
        errs.append(sp["power_at_equal_speed"]["error"])
    print("power error at equal speed per spot [%]:", np.round(np.array(errs) * 100, 2))
    assert len(errs) == 5
    assert max(abs(e) for e in errs) < 0.01
