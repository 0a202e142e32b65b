"""Truth-metric definitions on analytic tracks, where the answer is known exactly."""

from __future__ import annotations

import math

import numpy as np
import pytest

from vtrials.truth import metrics as TM


def synthetic_turn(R=100.0, U=5.0, psi0=0.4, side=1, t_end=400.0, dt=0.05, transient=20.0):
    """A straight approach then a circle of radius R entered smoothly: heading rate ramps up over
    `transient` seconds. Integrated exactly enough (fine steps)."""
    t = np.arange(0.0, t_end, dt)
    r_ss = side * U / R
    r = np.where(t < transient, r_ss * t / transient, r_ss) if transient > 0 else np.full_like(t, r_ss)
    psi = psi0 + np.concatenate([[0.0], np.cumsum(0.5 * (r[1:] + r[:-1]) * dt)])
    x = np.concatenate([[0.0], np.cumsum(U * 0.5 * (np.cos(psi[1:]) + np.cos(psi[:-1])) * dt)])
    y = np.concatenate([[0.0], np.cumsum(U * 0.5 * (np.sin(psi[1:]) + np.sin(psi[:-1])) * dt)])
    return t, x, y, psi, np.full_like(t, U), np.zeros_like(t), r


@pytest.mark.parametrize("side", [1, -1])
def test_pure_circle_metrics(side):
    """A turn entered instantly (transient → 0) is a circle tangent to the approach course:
    advance = transfer = R, tactical diameter = 2R."""
    R, U = 100.0, 5.0
    t, x, y, psi, u, v, r = synthetic_turn(R, U, side=side, transient=0.0, dt=0.01)
    m = TM.turning(t, x, y, psi, u, v, r)
    assert m["advance_m"] == pytest.approx(R, rel=1e-4)
    assert m["transfer_m"] == pytest.approx(R, rel=1e-4)
    assert m["tactical_diameter_m"] == pytest.approx(2 * R, rel=1e-4)
    assert m["steady_turning_diameter_m"] == pytest.approx(2 * R, rel=1e-6)
    assert m["steady_speed_mps"] == pytest.approx(U)
    assert m["steady_rate_of_turn_dps"] == pytest.approx(math.degrees(U / R))
    assert m["time_to_90deg_s"] == pytest.approx(0.5 * math.pi * R / U, rel=1e-4)


def test_gradual_entry_increases_advance():
    R, U = 100.0, 5.0
    m = TM.turning(*synthetic_turn(R, U, transient=20.0))
    # entering over 20 s at 5 m/s adds about half the ramp length (50 m) to the advance
    assert m["advance_m"] == pytest.approx(R + 50.0, rel=0.02)
    assert m["steady_turning_diameter_m"] == pytest.approx(2 * R, rel=1e-5)


def test_circle_fit_recovers_circle_from_arc_with_noise():
    rng = np.random.default_rng(0)
    a = np.linspace(0.3, 2.0, 400)
    x = 12.0 + 50.0 * np.cos(a) + rng.normal(0, 0.05, a.size)
    y = -7.0 + 50.0 * np.sin(a) + rng.normal(0, 0.05, a.size)
    cx, cy, R = TM.fit_circle(x, y)
    assert (cx, cy, R) == pytest.approx((12.0, -7.0, 50.0), abs=0.05)


def test_zigzag_metrics_on_known_heading():
    """Heading ψ(t) = A sin(ω t) (after a linear start): crossings and peaks are known exactly."""
    A, w, a = math.radians(25.0), 2 * math.pi / 60.0, math.radians(10.0)
    t = np.arange(0.0, 200.0, 0.01)
    psi = 1.0 + A * np.sin(w * t)
    for side in (1, -1):
        m = TM.zigzag(t, 1.0 + side * (psi - 1.0), rudder_deg=10, heading_deg=10, first_side=side)
        t1 = math.asin(a / A) / w
        assert m["initial_turning_time_s"] == pytest.approx(t1, abs=1e-4)
        assert m["first_overshoot_deg"] == pytest.approx(15.0, abs=1e-4)
        assert m["second_overshoot_deg"] == pytest.approx(15.0, abs=1e-4)
        assert m["first_overshoot_time_s"] == pytest.approx(15.0, abs=1e-3)
        assert m["time_to_check_yaw_s"] == pytest.approx(15.0 - t1, abs=1e-3)
        assert m["period_s"] == pytest.approx(60.0, abs=1e-3)
