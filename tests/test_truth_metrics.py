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


def _drifting_turn(R=150.0, U=5.0, leeway=(0.12, -0.05), wobble=0.0, side=1, dt=0.05, t_end=500.0):
    """A steady circle (radius R through a frame that drifts at ``leeway`` [m/s]) entered at t = 0,
    rate of change of heading r₀(1 + wobble·sin ψ) (the wind's heading-dependent push), positions in
    the water frame = circle + leeway·t."""
    r0 = U / R
    t = np.arange(0.0, t_end, dt)
    psi = np.empty_like(t)
    psi[0] = 0.3
    for k in range(1, t.size):  # midpoint integration of ψ̇ = r₀(1 + w sin ψ)
        half = psi[k - 1] + 0.5 * dt * side * r0 * (1 + wobble * math.sin(psi[k - 1]))
        psi[k] = psi[k - 1] + dt * side * r0 * (1 + wobble * math.sin(half))
    # along the circle the arc speed is R·|ψ̇| in the drifting frame
    ang = psi - side * math.pi / 2
    x = R * np.cos(ang) + leeway[0] * t
    y = R * np.sin(ang) + leeway[1] * t
    rate = np.gradient(psi, t)
    u = R * np.abs(rate)
    return t, x, y, psi, u, np.zeros_like(t), rate


def test_steady_circle_is_closed_by_its_own_loop_drift():
    """A circle drifting with the wind's leeway of the circling ship: the steady turning diameter is
    that of the circle in the frame drifting with it (ITTC 7.5-04-02-01 removes the drift loop by loop).
    A circle fitted to the open loop is off by up to drift·T/(2π) in radius, by where the loop starts
    (old definition: 294.2 m instead of 300 m here)."""
    R = 150.0
    t, x, y, psi, u, v, r = _drifting_turn(R=R, leeway=(0.12, -0.05))
    m = TM.turning(t, x, y, psi, u, v, r)
    assert m["steady_turning_diameter_m"] == pytest.approx(2 * R, abs=0.01)
    assert m["steady_loop_drift_mps"] == pytest.approx([0.12, -0.05], abs=1e-4)


@pytest.mark.parametrize("side", [1, -1])
def test_steady_rate_is_the_mean_rate_over_the_loop(side):
    """Rate varying around the loop (ψ̇ = r₀(1 + 0.1 sin ψ)): the steady rate of turn is the heading
    change over the loop / its duration, 2π/T with T = ∫dψ/ψ̇ = 2π/(r₀√(1 − 0.1²)); an OLS slope over
    the loop depends on the loop's starting heading (old definition: off by 1.1 % here)."""
    R, U, w = 150.0, 5.0, 0.1
    t, x, y, psi, u, v, r = _drifting_turn(R=R, U=U, leeway=(0.0, 0.0), wobble=w, side=side, dt=0.02)
    m = TM.turning(t, x, y, psi, u, v, r)
    expected = (U / R) * math.sqrt(1 - w * w)
    assert math.radians(m["steady_rate_of_turn_dps"]) == pytest.approx(expected, rel=1e-4)


def test_times_are_counted_from_the_execute_instant_between_truth_samples():
    """The truth is stored every 0.5 s and EXECUTE falls between samples (here 0.3 s before the
    next). A ramp u = min(U₀ + a(t − t_E), U_T) reaches 90 % of its change at t_E + 0.9(U_T − U₀)/a:
    counted from the EXECUTE sample that maneuvering.from_execute inserts (the approach carried on to
    EXECUTE) it is exact; counted from the first stored sample it was 0.9 × 0.3 s short (the later
    start and its higher initial speed). Angles are carried on along the shorter arc across ±π."""
    from vtrials.trials.maneuvering import from_execute
    t = np.arange(0.0, 400.0, 0.5)
    tE, U0, UT, a = 100.2, 2.0, 8.0, 0.1
    u = np.clip(U0 + a * (t - tE), U0, UT)
    x = np.concatenate([[0.0], np.cumsum(0.5 * (u[1:] + u[:-1]) * 0.5)])
    psi = math.pi - 0.0015 + 0.001 * (t - 99.5)
    heading = np.remainder(psi + math.pi, 2 * math.pi) - math.pi  # wraps between 99.5 and 100.0
    cols = {"t": t, "x_w": x, "y_w": 0 * t, "heading": heading, "u_r": u, "v_r": 0 * t}
    c = from_execute(cols, tE, 380.0)
    assert c["t"][0] == tE and c["t"][1] == 100.5
    assert math.remainder(c["heading"][0] - (math.pi - 0.0015 + 0.001 * (tE - 99.5)), 2 * math.pi) == \
        pytest.approx(0.0, abs=1e-12)
    assert c["u_r"][0] == pytest.approx(U0, abs=1e-12)
    exact = 0.9 * (UT - U0) / a
    out = TM.speed_change(c["t"], c["x_w"], c["y_w"], c["heading"], c["u_r"], c["v_r"])
    assert out["time_to_90_percent_s"] == pytest.approx(exact, abs=1e-6)
    w = (t >= tE) & (t <= 380.0)
    old = TM.speed_change(t[w], x[w], 0 * t[w], heading[w], u[w], 0 * t[w])
    assert old["time_to_90_percent_s"] == pytest.approx(exact - 0.9 * 0.3, abs=1e-6)
    # a sample exactly at EXECUTE: nothing inserted
    assert from_execute(cols, 100.5, 380.0)["t"][0] == 100.5


def test_signed_speed_is_astern_only_with_clear_sternway():
    """|V| signed by the surge only below −0.1 m/s: a stopped ship drifting 0.7 m/s abeam with a
    surge of ±3 cm/s has +0.7 m/s either way; going astern at 2 m/s it is −|V|."""
    U = TM.signed_speed([0.03, -0.03, -0.099, -2.0, 5.0], [0.7, 0.7, 0.0, 0.5, 0.0])
    assert U == pytest.approx([math.hypot(0.03, 0.7), math.hypot(0.03, 0.7), 0.099, -math.hypot(2.0, 0.5), 5.0])
