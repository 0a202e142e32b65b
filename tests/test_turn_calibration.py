"""Calibration fixes of the turning-circle and speed-change reductions, on synthetic records whose
answers are known (issue 11: honest intervals for tactical circles and crash stops).

* the drift of a circle over its steady loop (360° → 720°) against the mean of 360°-apart pairs from
  EXECUTE, which the first loop's transient biases;
* the day's drift with one circle per side (the side term takes their whole difference);
* the day's drift as the water-track current plus the circles' mean leeway, against a line in time
  that takes up a leeway changing with the turns' order;
* the gyro's speed-error correction from the receiver's own north velocity;
* dead in the water and the terminal speed on a water-track log when the current is poorly known;
* the time to terminal speed on the receiver's velocity when the fixes carry a coloured error.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from vtrials.reduce import gyro as GY
from vtrials.reduce import reach as RE
from vtrials.reduce import turning as T
from vtrials.reduce.current import WaterTrackCurrent
from vtrials.reduce.estimate import Estimate
from vtrials.reduce.maneuvering import DriftLine, LeewayDrift
from vtrials.units import DEG

from test_reduce_turning import Turn, make_turn


# ------------------------------------------------------------------------- drift over the loop
def test_loop_drift_is_the_second_loops_not_the_transients():
    """A turn with a 60-s transient (rate ramp and speed loss) in a constant drift (0.3, −0.2) m/s: the
    water track closes exactly over 360° → 720°, so the drift over that loop is the drift; the mean of
    the 360°-apart pairs started at EXECUTE (the patrol vessel's steady test passes from EXECUTE on)
    carries the transient's advance and misses it by centimetres per second."""
    turn = Turn(U0=7.0, U=5.0, r=2.0 * DEG, T_r=60.0, T_u=60.0)
    t, N, E, psi = make_turn(turn, drift=(0.3, -0.2), total_deg=740.0, dt=1.0)
    rng = np.random.default_rng(1)
    th = np.arange(t[0], t[-1], 0.1)
    hd = np.interp(th, t, np.unwrap(psi))
    loop = T.steady_loop(th, hd, 1000.0)
    assert loop.full
    assert loop.t_start - 1000.0 == pytest.approx(turn.t_mark(360.0), abs=0.05)
    d = T.drift_over_loop(t, N + rng.normal(0, 0.05, t.size), E + rng.normal(0, 0.05, t.size), loop)
    assert d.method == "loop"
    assert d.north.value == pytest.approx(0.3, abs=3 * d.north.std + 1e-4)
    assert d.east.value == pytest.approx(-0.2, abs=3 * d.east.std + 1e-4)
    assert d.north.std < 2e-3
    sw = T.SteadyWindow(1000.0, float(t[-1]), Estimate(turn.r, 1e-6), True, 0.0)
    pairs, _ = T.estimate_drift(t, N, E, th, hd, 1000.0, method="pairs", steady=sw)
    assert math.hypot(pairs.north.value - 0.3, pairs.east.value + 0.2) > 0.02


def test_loop_drift_variance_matches_monte_carlo_under_correlated_fix_errors():
    """The loop drift's stated covariance under a DGPS's Gauss–Markov wander (1 m, 120 s) and
    multipath (0.5 m, 10 s) matches the scatter of 400 noisy replicates of one loop."""
    turn = Turn(U0=6.0, U=5.0, r=3.0 * DEG, T_r=20.0, T_u=20.0)
    t, N, E, psi = make_turn(turn, drift=(0.1, 0.1), total_deg=740.0, dt=1.0)
    th = np.arange(t[0], t[-1], 0.1)
    loop = T.steady_loop(th, np.interp(th, t, np.unwrap(psi)), 1000.0)
    comps = [(1.0, 120.0), (0.5, 10.0)]
    dt = np.abs(t[:, None] - t[None, :])
    L = np.linalg.cholesky(sum(sd ** 2 * np.exp(-dt / tau) for sd, tau in comps) + 1e-9 * np.eye(t.size))
    rng = np.random.default_rng(5)
    got, sds = [], []
    for _ in range(400):
        d = T.drift_over_loop(t, N + L @ rng.normal(size=t.size), E + L @ rng.normal(size=t.size), loop,
                              sigma=(1e-3, 1e-3), fix_errors=comps)
        got.append(d.north.value)
        sds.append(d.north.std)
    assert float(np.std(got, ddof=1)) == pytest.approx(float(np.mean(sds)), rel=0.12)
    assert abs(float(np.mean(got)) - 0.1) < 3 * float(np.mean(sds)) / math.sqrt(400)


# ------------------------------------------------------------------------------- day's drift
def _drift(vn, ve, sd):
    return T.Drift(Estimate(vn, sd), Estimate(ve, sd), np.eye(2) * sd ** 2, "loop")


def test_drift_line_one_circle_per_side_takes_the_circles_own_errors():
    """One circle per side with a ±0.08 m/s side-dependent push: the mean of the sides is the current,
    and its standard error is the circles' own (√(σ₁² + σ₂²)/2, normal interval) — not their whole
    difference with a one-dof t interval (which made KVLCC2's drift intervals 20-100 times too wide)."""
    line = DriftLine([1000.0, 5000.0], [_drift(0.18, -0.05, 0.002), _drift(0.02, 0.11, 0.003)], [1, -1])
    dn, de = line.mean_of_sides(3000.0)
    assert dn.value == pytest.approx(0.10, abs=1e-12)
    assert de.value == pytest.approx(0.03, abs=1e-12)
    assert dn.std == pytest.approx(math.sqrt(0.002 ** 2 + 0.003 ** 2) / 2, rel=1e-9)
    assert dn.dof is None
    plain, _ = line(3000.0)
    assert plain.std > 0.05  # a straight run still carries the push's size


def test_leeway_drift_follows_the_current_not_the_order_of_the_turns():
    """Eighteen circles in three speed groups whose leeway shrinks from group to group, in a current
    that turns linearly in time (measured by the log: a known line): current + mean leeway is exact
    at every circle's time, the plain line through the drifts is not (its slope takes up the leeway's
    trend), and the error of the current's constant part does not enter the day's drift."""
    coef = np.array([[-0.18, 0.18], [2e-6, -1e-6]])
    cov = np.diag([1e-4, 1e-4, 1e-16, 1e-16])
    cur = WaterTrackCurrent(coef, 5000.0, True, 20, cov, 1.0)
    times = 1000.0 + 500.0 * np.arange(18)
    lee = []
    drifts = []
    for k, tt in enumerate(times):
        side = 1 if k % 2 == 0 else -1
        group = k // 6
        lk = np.array([-0.06 + 0.006 * group, -0.02]) + side * np.array([0.03, -0.06])
        lee.append(lk)
        cn, ce, _ = cur(tt)
        drifts.append(_drift(cn.value + lk[0], ce.value + lk[1], 0.01))
    mean_lee = np.mean(lee, axis=0)
    day = LeewayDrift(cur, times, drifts)
    line = DriftLine(times, drifts, [1 if k % 2 == 0 else -1 for k in range(18)])
    worst_line = 0.0
    for tt in (times[0], times[9], times[-1]):
        cn, ce, _ = cur(tt)
        dn, de = day.mean_of_sides(tt)
        assert dn.value == pytest.approx(cn.value + mean_lee[0], abs=1e-12)
        assert de.value == pytest.approx(ce.value + mean_lee[1], abs=1e-12)
        # the current's constant part (σ 0.01 m/s) cancels: the own errors (0.01/√18) and the
        # negligible rate error are left
        assert dn.std == pytest.approx(0.01 / math.sqrt(18), rel=0.01)
        ln, _ = line.mean_of_sides(tt)
        worst_line = max(worst_line, abs(ln.value - cn.value - mean_lee[0]))
    assert worst_line > 0.004


# --------------------------------------------------------------------------- gyro speed error
def test_speed_error_correction_with_the_receivers_north_velocity():
    """A gyro on an 84-s circle at 8 m/s reads high by arcsin(V_N/(R_E Ω cos φ)): corrected with the
    receiver's north velocity the reading is the heading to 1e-9 rad; with the track's 30-s slopes a
    swing of ~0.1° remains (the slopes lose part of V_N's swing)."""
    lat = 38.0 * DEG
    U, Tl = 8.0, 84.0
    th = np.arange(0.0, 400.0, 0.1)
    psi = 2 * math.pi * th / Tl
    vn = U * np.cos(psi)
    meas = psi + GY.speed_error(vn, lat)
    t_fix = np.arange(0.0, 400.0, 1.0)
    north = U * Tl / (2 * math.pi) * np.sin(2 * math.pi * t_fix / Tl)
    good = GY.correct_heading(th, meas, t_fix, north, lat, v_north=(th, vn))
    slopes = GY.correct_heading(th, meas, t_fix, north, lat)
    mid = (th > 50) & (th < 350)
    assert np.max(np.abs(good - psi)) < 1e-9
    assert np.max(np.abs(slopes[mid] - psi[mid])) > 0.05 * DEG


# ------------------------------------------------------------------ speed changes on the log
def _stop_records(rng, current_error=(0.3, 0.2)):
    """A straight crash stop: surge u = u₀ − a t (to sternway), sway 0, heading constant 40°, in a
    current (0.2, 0.1) m/s. Fixes at 1 Hz (σ 0.5 m), the receiver's velocity at 1 Hz (σ 0.05 m/s),
    a water-track log at 2 Hz (σ 0.1 m/s, scale error 0.3 %). The current given to the reduction is
    off by ``current_error`` with a stated SD of 0.05 m/s."""
    psi0, u0, a, cur = 40 * DEG, 6.0, 0.01, np.array([0.2, 0.1])
    t = np.arange(-120.0, 1200.0, 1.0)
    u = np.where(t < 0, u0, np.maximum(u0 - a * np.clip(t, 0, None), -2.0))
    s = np.concatenate([[0.0], np.cumsum(0.5 * (u[1:] + u[:-1]))])
    s -= s[np.searchsorted(t, 0.0)]
    e = np.array([math.cos(psi0), math.sin(psi0)])
    N = s * e[0] + cur[0] * t + rng.normal(0, 0.5, t.size)
    E = s * e[1] + cur[1] * t + rng.normal(0, 0.5, t.size)
    vel = (t, u * e[0] + cur[0] + rng.normal(0, 0.05, t.size), u * e[1] + cur[1] + rng.normal(0, 0.05, t.size))
    tw = np.arange(-120.0, 1200.0, 0.5)
    uw = np.interp(tw, t, u) * 1.003 + rng.normal(0, 0.1, tw.size)
    vw = rng.normal(0, 0.1, tw.size)
    given = RE.InterpolatedDrift(Estimate(cur[0] + current_error[0], 0.05), Estimate(cur[1] + current_error[1], 0.05),
                                 False, (0.0, 0.0))
    return t, N, E, np.full(t.size, psi0), vel, (tw, uw, vw, 0.005, 0.1, 0.5 * DEG), given, u0 / a


def test_dead_in_water_and_terminal_speed_on_the_log_when_the_current_is_poor():
    """With the current off by 0.36 m/s, the ground track's surge through the water crosses zero ~40 s
    off; its interval either misses or says the crossing is lost (the receiver's 1-Hz velocity over
    ±3.5 s leaves the slope of a 0.01 m/s² deceleration undetermined: SE ~50 s); on the water-track log
    the crossing and the terminal sternway are right within intervals of a few seconds, whatever the
    current."""
    rng = np.random.default_rng(11)
    t, N, E, hd, vel, water, given, t_diw = _stop_records(rng)
    kw = dict(heading=hd, drift=given, approach_s=120.0, n_boot=40, velocity=vel)
    ground = RE.reach_analysis(t, N, E, 0.0, **kw)
    log = RE.reach_analysis(t, N, E, 0.0, water=water, **kw)
    g_tdw = ground.time_to_dead_in_water
    assert abs(g_tdw.value - t_diw) > 20.0
    assert not g_tdw.covers(t_diw) or g_tdw.std > 10.0 * log.time_to_dead_in_water.std
    assert log.time_to_dead_in_water.covers(t_diw)
    assert abs(log.time_to_dead_in_water.value - t_diw) < 3.0
    assert log.terminal_speed.covers(-2.0)
    assert any("water-track log" in n for n in log.notes)
    # a well-known current (0.001 m/s): the ground track is kept
    good = RE.InterpolatedDrift(Estimate(0.2, 0.001), Estimate(0.1, 0.001), False, (0.0, 0.0))
    kept = RE.reach_analysis(t, N, E, 0.0, heading=hd, drift=good, approach_s=120.0, n_boot=40, velocity=vel,
                             water=water)
    assert not any("water-track log" in n for n in kept.notes)


def test_time_to_terminal_speed_on_the_receivers_velocity_despite_coloured_fix_errors():
    """An exponential acceleration 6 → 8 m/s (k = 0.25/s: band entry ln 50/k = 15.6 s) with multipath
    on the fixes (0.5 m, τ 10 s): the speed differentiated from the fixes wanders in and out of the
    0.04-m/s band long after the ship settled (entry "for good" at minutes); on the receiver's
    velocity the entry is within its interval."""
    rng = np.random.default_rng(0)
    k, u0, uT = 0.25, 6.0, 8.0
    t = np.arange(-90.0, 200.0, 1.0)
    tc = np.clip(t, 0, None)
    s = np.where(t < 0, u0 * t, uT * tc - (uT - u0) * (1 - np.exp(-k * tc)) / k)
    u = np.where(t < 0, u0, uT - (uT - u0) * np.exp(-k * tc))
    ar = np.zeros(t.size)
    for i in range(1, t.size):
        ar[i] = ar[i - 1] * math.exp(-0.1) + rng.normal(0, 0.5 * math.sqrt(1 - math.exp(-0.2)))
    N = s + ar + rng.normal(0, 0.3, t.size)
    E = rng.normal(0, 0.3, t.size)
    vel = (t, u + rng.normal(0, 0.05, t.size), rng.normal(0, 0.05, t.size))
    kw = dict(heading=np.zeros(t.size), approach_s=90.0, n_boot=40, fix_errors=[(0.5, 10.0)])
    r = RE.reach_analysis(t, N, E, 0.0, velocity=vel, **kw)
    p = RE.reach_analysis(t, N, E, 0.0, **kw)
    te = math.log(50.0) / k
    assert r.time_to_terminal_speed.covers(te)
    assert abs(r.time_to_terminal_speed.value - te) < 4.0
    assert p.time_to_terminal_speed.value - te > 60.0 and not p.time_to_terminal_speed.covers(te)
