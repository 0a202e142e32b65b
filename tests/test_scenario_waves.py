"""[environment.waves] in scenarios: parsing, the seeded realization and the ship in the sea.

The State 3 standardization day (scenarios/patrol51_standardization_sea3.toml) is a shipped scenario:
the runners build their simulator from :func:`vtrials.scenario.sea_vessel` (end to end:
tests/test_sea_trials.py).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from vtrials.errors import InputError
from vtrials.physics.simulator import Simulator
from vtrials.physics import steering as H
from vtrials.scenario import environment_block, load_scenario, sea_vessel, wave_field

ROOT = Path(__file__).resolve().parents[1]
SEA3 = ROOT / "scenarios" / "patrol51_standardization_sea3.toml"
CALM = ROOT / "scenarios" / "patrol51_standardization.toml"


def test_sea3_scenario_realization_is_seeded_and_independent_of_the_gusts():
    scn = load_scenario(SEA3)
    assert scn.waves.hs_m == 0.88 and scn.waves.tp_s == 7.5
    a = wave_field(scn)
    b = wave_field(load_scenario(SEA3))
    assert np.array_equal(a.components, b.components)
    # H_s of the realization: 4 √(Σ a²/2) against the target (band 0.5–5 ω_p holds > 99 % of m₀)
    hs = 4.0 * math.sqrt(0.5 * float(np.sum(a.components[:, 0] ** 2)))
    assert hs == pytest.approx(0.88, rel=0.02)
    # adding a sea leaves the gusts of the same seed as they were
    calm = load_scenario(CALM)
    assert wave_field(calm) is None
    assert np.array_equal(environment_block(scn), environment_block(calm))


def test_other_seed_other_sea(tmp_path):
    text = SEA3.read_text().replace("seed = 2002", "seed = 2003")
    p = tmp_path / "s.toml"
    p.write_text(text)
    assert not np.array_equal(wave_field(load_scenario(p)).components, wave_field(load_scenario(SEA3)).components)


def test_ship_in_the_sea3_day_moves_and_stays_finite():
    scn = load_scenario(SEA3)
    v, dropped = sea_vessel(scn)
    names = [c.name for c in v.components]
    assert {"radiation", "wave_excitation", "wave_drift"} <= set(names)
    assert 0.0 <= dropped < 0.01
    calm = Simulator(scn.vessel, 1, scn.head.timestep_s)
    s0 = calm.self_propulsion(0, 6.0)
    sim = Simulator(v, 1, scn.head.timestep_s)
    sim.set_state(0, s0)
    ap = scn.vessel.autopilot
    sim.set_helm(0, [(H.HEADING, 0.0, math.radians(ap.rudder_limit_deg), *ap.pid, 0.0)])
    sim.step(int(round(120.0 / scn.head.timestep_s)))
    tr = sim.truth()[:, 0, :]
    assert np.all(np.isfinite(tr))
    z = tr[:, sim.rec_names.index("z")]
    assert 0.02 < float(np.std(z[len(z) // 2:])) < 0.5       # heave RMS in metres for H_s 0.88 m


@pytest.mark.parametrize("edit,field", [
    ('spectrum = "pierson_moskowitz"', 'spectrum = "foo"'),
    ("hs_m = 0.88", "hs_m = -1.0"),
])
def test_bad_waves_input_is_named(tmp_path, edit, field):
    p = tmp_path / "s.toml"
    p.write_text(SEA3.read_text().replace(edit, field))
    with pytest.raises(InputError, match="environment.waves"):
        load_scenario(p)


def test_waves_need_a_database(tmp_path):
    text = (ROOT / "scenarios" / "kvlcc2_l7_turning.toml").read_text()
    p = tmp_path / "s.toml"
    text = text.replace("[environment]", "[environment.waves]\nhs_m = 1.0\ntp_s = 8.0\n\n[environment]", 1) \
        if "[environment]" in text else text + "\n[environment.waves]\nhs_m = 1.0\ntp_s = 8.0\n"
    p.write_text(text)
    with pytest.raises(InputError, match="hydrodynamic database"):
        load_scenario(p)
