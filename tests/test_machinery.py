"""Shafts, engines, telegraph: trailed and locked shafts, differential thrust, limits, bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from vtrials.physics import steering as H
from vtrials.cli import main
from vtrials.physics.simulator import ShipState, Simulator
from vtrials.physics.vessel import MODELS_DIR, load_vessel


@pytest.fixture(scope="module")
def patrol():
    return load_vessel("patrol51")


def _straight_run(v, rps, pitch, modes=("governed", "governed"), T=400.0):
    """Steady straight run on autopilot; returns mean speed [m/s], per-shaft mean rps and power [W]."""
    sim = Simulator(v, 1, 0.02)
    s = sim.steady_at_order(0, (rps, rps), (pitch, pitch))
    sim.set_state(0, ShipState(u=s.u, shaft_rps=(rps, rps), pitch_ratio=(pitch, pitch), shaft_modes=modes))
    ap = v.autopilot
    sim.set_helm(0, [(H.HEADING, 0.0, math.radians(ap.rudder_limit_deg), *ap.pid)])
    sim.step(int(T / 0.02))
    c = sim.truth()[-int(100 / 0.02):, 0]
    col = {n: j for j, n in enumerate(sim.rec_names)}
    n = np.array([c[:, col[f"shaft_n_{k}"]].mean() for k in range(2)])
    P = np.array([(2 * math.pi * c[:, col[f"shaft_n_{k}"]] * c[:, col[f"prop_torque_{k}"]]).mean() for k in range(2)])
    speed = np.hypot(c[:, col["u_r"]], c[:, col["v_r"]]).mean()
    return speed, n, P, c[:, col["shaft_n_0"]]


def test_trailed_and_locked_shafts(patrol):
    rps, pitch = patrol.telegraph["standard"]
    U2, n2, P2, _ = _straight_run(patrol, rps, pitch)
    P_each = P2[1]
    assert P2[0] == pytest.approx(P2[1], rel=1e-6)  # symmetric twin-screw plant
    results = {}
    for mode in ("trailed", "locked"):
        # find the starboard r/min at which the starboard shaft delivers the same power as before
        def dP(r):
            return _straight_run(patrol, r, pitch, (mode, "governed"), T=300.0)[2][1] - P_each
        r_eq = brentq(dP, 0.9 * rps, 1.5 * rps, xtol=1e-3)
        U1, n1, P1, n_port = _straight_run(patrol, r_eq, pitch, (mode, "governed"))
        assert P1[1] == pytest.approx(P_each, rel=0.01)
        assert U1 < U2 - 0.5  # clearly slower on one shaft at the same power on the working shaft
        results[mode] = (U1, n1, n_port)
    # the locked shaft holds zero r/min throughout; the trailed one windmills ahead
    assert np.abs(results["locked"][2]).max() < 1e-9
    assert results["trailed"][1][0] > 0.1 * rps  # the trailed propeller windmills ahead


def test_differential_thrust_alone_turns_the_ship(patrol):
    """Rudders amidships, port shaft faster than starboard: the ship turns to starboard, and the
    other way round."""
    sim = Simulator(patrol, 2, 0.02)
    rps, pitch = patrol.telegraph["full"]
    s = sim.steady_at_order(0, (rps, rps), (pitch, pitch))
    sim.set_state(1, s)
    for i in range(2):
        sim.set_helm(i, [(H.HOLD, 0.0)])
    sim.shaft_cmd[0] = (1.2 * rps, 0.6 * rps)  # port fast
    sim.shaft_cmd[1] = (0.6 * rps, 1.2 * rps)  # starboard fast
    sim.step(int(120 / 0.02))
    c = sim.truth()
    psi = c[-1, :, sim.rec_names.index("heading")]
    rud = c[:, :, sim.rec_names.index("rudder_0")]
    assert np.abs(rud).max() < 1e-9
    assert math.degrees(psi[0]) > 20 and math.degrees(psi[1]) < -20


def test_machinery_limits_respected(patrol):
    """Engine torque slews within its rate; pitch moves within its rate and range; power within limit."""
    sim = Simulator(patrol, 1, 0.02)
    rps, pitch = patrol.telegraph["flank"]
    sim.steady_at_order(0, (rps, rps), (pitch, pitch))
    sim.set_order(0, *patrol.telegraph["back_emergency"])
    sim.step(int(60 / 0.02))
    c = sim.truth()[:, 0]
    col = {n: j for j, n in enumerate(sim.rec_names)}
    sh = patrol.shafts[0]
    q = c[:, col["engine_torque_0"]]
    pd = c[:, col["pitch_0"]]
    n = c[:, col["shaft_n_0"]]
    assert np.abs(np.diff(q)).max() <= sh.torque_rate * 0.02 * (1 + 1e-9)
    assert np.abs(np.diff(pd)).max() <= sh.pitch_rate * 0.02 * (1 + 1e-9)
    assert pd.min() >= sh.pitch_min - 1e-12 and pd[-1] == pytest.approx(patrol.telegraph["back_emergency"][1])
    assert np.all(np.abs(q * 2 * math.pi * n) <= sh.max_power * (1 + 1e-9))
    assert np.all(np.abs(q) <= sh.max_torque * (1 + 1e-9))


SCEN = """
[scenario]
title = "t"
ship = "{ship}"
seed = 1
timestep_s = 0.02
[initial]
{initial}
[[maneuver]]
name = "m"
kind = "crash_stop"
approach_s = 1.0
{extra}
"""


def _run(tmp_path, capsys, text):
    p = tmp_path / "s.toml"
    p.write_text(text)
    out = tmp_path / "out"
    code = main(["run", str(p), "--out", str(out), "--quiet"])
    err = capsys.readouterr().err
    return code, err, out


@pytest.mark.parametrize("initial,extra,words", [
    ('engine_order = "full_ahead"', "", ["initial.engine_order", "'full_ahead' is not allowed"]),
    ('engine_order = "full"', 'order = "back_flank"', ["maneuver[0].order", "not allowed"]),
    ('speed_kn = 40.0', "", ["initial.speed_kn", "machinery cannot give this approach"]),
    ('engine_order = "full"', 'trailed_shaft = "centre"', ["maneuver[0].trailed_shaft", "unknown shaft"]),
])
def test_bad_orders_in_scenarios(tmp_path, capsys, initial, extra, words):
    code, err, out = _run(tmp_path, capsys, SCEN.format(ship="patrol51", initial=initial, extra=extra))
    assert code == 2 and len(err.strip().splitlines()) == 1
    for w in words:
        assert w in err
    assert not out.exists()


def test_power_above_limit_is_an_input_error(tmp_path, capsys):
    """A telegraph order whose steady state needs more than the engine's power: refused before running."""
    import shutil
    d = tmp_path / "patrol51"
    shutil.copytree(MODELS_DIR / "patrol51", d)
    t = d / "ship.toml"
    t.write_text(t.read_text().replace("max_power = 4.5e6", "max_power = 1.0e6"))
    code, err, out = _run(tmp_path, capsys, SCEN.format(ship="./patrol51", initial='engine_order = "flank"', extra=""))
    assert code == 2 and "initial.engine_order" in err and "above its limit" in err
    assert not out.exists()


@pytest.mark.parametrize("edit,words", [
    (lambda s: s.replace('flank = { rpm = 600.0, pitch = 1.38 }', 'flank = { rpm = 600.0, pitch = 1.8 }'),
     ["telegraph.flank.pitch", "outside"]),
    (lambda s: s.replace('flank = { rpm = 600.0, pitch = 1.38 }', 'flank = { rpm = 900.0, pitch = 1.38 }'),
     ["telegraph.flank.rpm", "exceeds"]),
    (lambda s: s.replace('flank = { rpm = 600.0, pitch = 1.38 }', 'flanks = { rpm = 600.0, pitch = 1.38 }'),
     ["telegraph.flanks", "unknown"]),
    (lambda s: s.replace('back_emergency = { rpm = 530.0, pitch = -1.0 }\n', ''),
     ["telegraph.back_emergency", "missing"]),
])
def test_bad_telegraph_in_model(tmp_path, capsys, edit, words):
    import shutil
    d = tmp_path / "patrol51"
    shutil.copytree(MODELS_DIR / "patrol51", d)
    t = d / "ship.toml"
    t.write_text(edit(t.read_text()))
    code, err, out = _run(tmp_path, capsys, SCEN.format(ship="./patrol51", initial='engine_order = "full"', extra=""))
    assert code == 2
    for w in words:
        assert w in err
    assert not out.exists()
