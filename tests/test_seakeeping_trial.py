"""Seakeeping star-pattern trial (issue 13): agenda checks, the legs' courses relative to the observed
waves, and a short simulated trial whose transfer functions are scored against the truth RAOs."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from vtrials.cli import main
from vtrials.trials.agenda import WAVE_RELATIVE_DEG, Run
from vtrials.trials.seakeeping import leg_course

ROOT = Path(__file__).resolve().parents[1]
SHORT = (ROOT / "scenarios" / "patrol51_seakeeping_short.toml").read_text()


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
    (lambda s: s.replace('heading = "bow_starboard"', 'heading = "starboard_bow"'), "agenda.trial[0].leg[1].heading",
     "starboard_bow"),
    (lambda s: s.replace('heading = "beam_port"', 'heading = "beam_port"\nstation_keeping = true'),
     "agenda.trial[0].leg[2].heading", "station-keeping leg is held head to the sea"),
    (lambda s: s.replace('leg_s = 360.0\n\n[[agenda.trial.leg]]\nheading = "bow_starboard"',
                         'leg_s = 10.0\n\n[[agenda.trial.leg]]\nheading = "bow_starboard"'), "agenda.trial[0].leg[0].leg_s",
     "10"),
    (lambda s: s.replace('heading = "head"\norder = "ahead_1_3"', 'heading = "head"\norder = "back_1_3"'),
     "agenda.trial[0].leg[0].order", "ahead order"),
    (lambda s: s.replace('heading = "head"\norder = "ahead_1_3"', 'heading = "head"\nrpm = 300.0'),
     "agenda.trial[0].leg[0].pitch", "controllable-pitch"),
    (lambda s: s.replace("hs_m = 0.75", "hs_m = 0.0"), "agenda.trial[0].kind", "needs a wind sea"),
    (lambda s: s.replace('heading = "head"\norder', 'heading = "head"\nspeed_kn = 8.0\norder'), "agenda.trial[0].leg[0]",
     "speed_kn"),
])
def test_bad_seakeeping_agenda(tmp_path, capsys, edit, field, words):
    err = _bad(tmp_path, capsys, edit(SHORT))
    assert field in err and words in err, err


def test_leg_courses_relative_to_the_observed_waves():
    """Waves observed coming from 300°: head seas steer 300°, following 120°, waves on the starboard bow
    (from 45° to starboard of the bow) 255°, on the port beam 030°, on the starboard quarter 165°."""
    team = {"sea_observed": [{"from_rad": math.radians(300.0)}]}
    want = {"head": 300.0, "following": 120.0, "bow_starboard": 255.0, "beam_port": 30.0, "quarter_starboard": 165.0,
            "bow_port": 345.0, "beam_starboard": 210.0, "quarter_port": 75.0}
    for name, course in want.items():
        run = Run(1, "sk", "seakeeping", 0.0, 5.0, 0.6, ("governed",), 600.0, 0.3, 1, 1, name, None,
                  {"wave_relative": math.radians(WAVE_RELATIVE_DEG[name])})
        got = math.degrees(leg_course(team, run)) % 360.0
        assert abs(got - course) < 1e-9, (name, got, course)
        # the database's relative heading of the waves' travel: β = μ − ψ = from + 180° − course
        beta = (300.0 + 180.0 - got) % 360.0
        assert abs(((beta - (180.0 + WAVE_RELATIVE_DEG[name])) + 180.0) % 360.0 - 180.0) < 1e-9
