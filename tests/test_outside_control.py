"""The simulator driven from outside: a hand-written controller on the gyro reading executes a 20/20
zig-zag and gets the overshoots of the built-in (compiled) zig-zag programme.

Both ships start from the same steady self-propulsion state at Fn 0.142 (KVLCC2 L7). The built-in
ship holds its course with the compiled autopilot for 10 s, then runs the compiled zig-zag on the
true heading inside the step kernel. The driven ship has no helm programme: a Python controller,
called by the :class:`~vtrials.trials.driver.Driver` every step, reads the gyro through the
instrument set (the truth stream the driver hands over, with the catalogue's gyrocompass made
error-free and sampled at ten times the step rate on its own clock, so that what is compared is the
interface and not the gyro's errors or its sampling), runs a PID autopilot with the same gains for
10 s, then shifts the rudder whenever the gyro heading passes ±20°. The controller's latest reading
is at most one step old (a step's truth row is handed over after the step), which moves each shift
by at most one step.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from vtrials.instruments.suite import InstrumentSet
from vtrials.physics import steering as H
from vtrials.physics.simulator import Simulator
from vtrials.physics.vessel import load_vessel
from vtrials.trials.driver import Driver, PeriodicController
from vtrials.truth import metrics as TM
from vtrials.truth.columns import ship_columns
from vtrials.units import DEG, froude_to_speed

DT = 0.01
APPROACH_S = 10.0
DURATION_S = 150.0
RUDDER = 20.0 * DEG
SWITCH = 20.0 * DEG
IDEAL_GYRO = {"name": "gyro", "spec": "gyrocompass", "site": "gyro", "set": {"rate_hz": 10.0 / DT, "bias": {"mean": 0.0, "sd": 0.0},
                                      "gauss_markov": {"sd": 0.0, "tau_s": 900.0}, "noise": 0.0,
                                      "resolution": 0.0, "latency_s": 0.0}}


class GyroZigZag(PeriodicController):
    """PID course keeping on the gyro, then a δ/ψ zig-zag on the gyro (starboard first)."""

    def __init__(self, ship, gains, limit, start):
        super().__init__(ship, DT, DURATION_S)
        self.kp, self.ki, self.kd = gains
        self.limit = limit
        self.start = start
        self.integ = 0.0
        self.psi = None
        self.psi_prev = None
        self.sigma = 1.0
        self.shifts = 0

    def _gyro(self, driver):
        iset = driver.instruments[self.ship]
        t, c = iset.window("gyro", driver.time(self.ship) - 1.0)
        if t.size == 0:
            return None
        h = float(c["heading"][-1])
        if self.psi is None:
            return math.atan2(math.sin(h), math.cos(h))
        return self.psi + math.atan2(math.sin(h - self.psi), math.cos(h - self.psi))  # unwrapped

    def control(self, driver):
        sim = driver.sim
        psi = self._gyro(driver)
        if psi is None:
            return
        self.psi_prev, self.psi = self.psi, psi
        t = driver.time(self.ship)
        if t - self.start < APPROACH_S:  # the built-in autopilot phase's own end test
            rate = 0.0 if self.psi_prev is None else (psi - self.psi_prev) / DT
            u = -(self.kp * psi + self.ki * self.integ + self.kd * rate)
            if abs(u) < self.limit:
                self.integ += psi * DT
            sim.set_rudder_order(self.ship, max(-self.limit, min(self.limit, u)))
            return
        if self.sigma * psi >= SWITCH:
            self.sigma = -self.sigma
            self.shifts += 1
        sim.set_rudder_order(self.ship, self.sigma * RUDDER if self.shifts < 4 else 0.0)


@pytest.fixture(scope="module")
def runs():
    v = load_vessel("kvlcc2_l7")
    ap = v.autopilot
    kp = ap.gain
    gains = (kp, kp / ap.integral_time, kp * ap.derivative_time)
    limit = min(ap.rudder_limit_deg * DEG, v.max_rudder)
    U = froude_to_speed(0.142, v.length)
    out = {}
    # built-in: compiled autopilot, then the compiled zig-zag
    sim = Simulator(v, 1, DT)
    s0 = sim.self_propulsion(0, U)
    sim.set_state(0, s0)
    sim.set_helm(0, [(H.HEADING, 0.0, limit, *gains, APPROACH_S),
                     (H.ZIGZAG, RUDDER, SWITCH, 0.0, 1.0, 4.0), (H.HOLD, 0.0)])
    sim.step(int(round(DURATION_S / DT)))
    out["built-in"] = ship_columns(sim.truth(), sim.rec_names, 0, sim.dt)
    # driven from outside through the driver
    sim = Simulator(v, 1, DT)
    sim.set_state(0, s0)
    iset = InstrumentSet(v, 1, {}, [IDEAL_GYRO], "test")
    iset.reset()
    drv = Driver(sim, {0: iset}, slice_s=DT, flush_every_s=1.0)
    rows = []
    drv.sinks.append(lambda ship, r: rows.append(r))
    ctl = GyroZigZag(0, gains, limit, s0.time)
    drv.run([ctl])
    out["driven"] = drv.columns(np.concatenate(rows))
    out["shifts"] = ctl.shifts
    return out


def _overshoots(c):
    ex = c["t"] >= APPROACH_S - 1e-9
    return TM.zigzag(c["t"][ex], c["heading"][ex], rudder_deg=20.0, heading_deg=20.0, first_side=1)


def test_driven_zigzag_matches_built_in_programme(runs):
    a = _overshoots(runs["built-in"])
    b = _overshoots(runs["driven"])
    assert runs["shifts"] == 4
    for key in ("first_overshoot_deg", "second_overshoot_deg"):
        assert math.isfinite(a[key]) and a[key] > 5.0  # a real zig-zag happened
        assert abs(a[key] - b[key]) <= 0.05, (key, a[key], b[key])


def test_instruments_saw_the_driven_run(runs):
    """The truth the driver handed over is the ship's own, continuous at the step rate."""
    t = runs["driven"]["t"]
    assert t.size >= int(round(DURATION_S / DT)) - 1
    assert np.allclose(np.diff(t), DT)
