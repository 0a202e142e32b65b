"""vtrials.reduce.zigzag on synthetic zig-zags whose answers are known.

Ship: first-order Nomoto model T ṙ + r = K δ, ψ̇ = r (degrees and seconds inside the model), integrated
with a fine step (0.01 s, midpoint rule). Steering gear: the rudder moves at a constant 2.5 °/s toward
the ordered angle. Helm: EXECUTE at t = 0 (δ to the first side); when the heading change from the base
course reaches the check angle α on the current side, the opposite rudder is ordered (optionally after
a delay). References from the dense solution: the execute instants (when the order was given), the
heading-threshold crossings, and the heading extremes (parabola through the three densest samples)
→ overshoot angles = |extreme| − α and their times. Records: gyro and rudder synchro sampled at ~1 Hz
with ±0.3 s jitter on two different clocks, noise 0.1° on each.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from vtrials.reduce import imo
from vtrials.reduce import zigzag as Z
from vtrials.units import DEG


def simulate(K=0.08, T=25.0, delta=10.0, alpha=10.0, gear=2.5, side=1, psi0=50.0, t_app=60.0, n_exec=5,
             dt=0.01, t_after=60.0, delay=0.0):
    n = int((t_app + 800.0) / dt)
    t = -t_app + dt * np.arange(n)
    psi = np.empty(n)
    d = np.empty(n)
    psi_c, r_c, d_c, order = psi0, 0.0, 0.0, 0.0
    execs, sign, pending = [], side, None
    for i in range(n):
        ti = t[i]
        if not execs and ti >= 0.0:
            order = side * delta
            execs.append(ti)
        elif execs and len(execs) < n_exec:
            if pending is None and sign * (psi_c - psi0) >= alpha:
                pending = ti
            if pending is not None and ti >= pending + delay:
                sign, pending = -sign, None
                order = sign * delta
                execs.append(ti)
        d_c += max(-gear * dt, min(gear * dt, order - d_c))
        psi[i], d[i] = psi_c, d_c
        r_mid = r_c + 0.5 * dt * (K * d_c - r_c) / T
        psi_c += dt * r_mid
        r_c += dt * (K * d_c - r_mid) / T
        if len(execs) >= n_exec and ti > execs[-1] + t_after:
            n = i + 1
            break
    return {"t": t[:n], "psi": psi[:n], "d": d[:n], "execs": np.array(execs), "psi0": psi0, "alpha": alpha,
            "side": side}


def truth(S):
    """Crossings, overshoot angles [deg] and times [s] from the dense solution."""
    t, f, a = S["t"], S["side"] * (S["psi"] - S["psi0"]), S["alpha"]
    cross, ov, ot = [], [], []
    sgn, after = 1.0, 0.0
    while True:
        idx = np.flatnonzero((sgn * f >= a) & (t >= after))
        if idx.size == 0:
            break
        k = idx[0]
        cross.append(t[k - 1] + (a - sgn * f[k - 1]) / (sgn * f[k] - sgn * f[k - 1]) * (t[k] - t[k - 1]))
        nxt = np.flatnonzero((-sgn * f >= a) & (t > cross[-1]))
        end = nxt[0] if nxt.size else len(t)
        j = k + int(np.argmax(sgn * f[k:end]))
        if j >= end - 5:
            break
        y0, y1, y2 = sgn * f[j - 1], sgn * f[j], sgn * f[j + 1]
        h = 0.5 * (y0 - y2) / (y0 - 2 * y1 + y2)
        ov.append(y1 - 0.25 * (y0 - y2) * h - a)
        ot.append(t[j] + h * (t[1] - t[0]))
        sgn, after = -sgn, cross[-1]
    return {"cross": np.array(cross), "overshoots": np.array(ov), "otimes": np.array(ot)}


def record(S, rng, sig_h=0.1, sig_d=0.1, jitter=0.3):
    t0, t1 = S["t"][0] + 0.5, S["t"][-1] - 0.5
    bh = np.arange(t0, t1, 1.0)
    th = np.sort(bh + rng.uniform(-jitter, jitter, bh.size))
    br = np.arange(t0 + 0.37, t1, 1.0)
    tr = np.sort(br + rng.uniform(-jitter, jitter, br.size))
    h = np.interp(th, S["t"], S["psi"]) + rng.normal(0.0, sig_h, th.size)
    d = np.interp(tr, S["t"], S["d"]) + rng.normal(0.0, sig_d, tr.size)
    return th, np.mod(h * DEG, 2 * math.pi), tr, d * DEG


@pytest.fixture(scope="module")
def zz10():
    S = simulate()
    return S, truth(S)


def test_noise_free_record_reproduces_the_dense_solution(zz10):
    S, tr = zz10
    th, h, trd, d = record(S, np.random.default_rng(0), sig_h=0.0, sig_d=0.0)
    res = Z.zigzag_metrics(th, h, trd, d)
    assert res.first_side == 1 and res.check_angle == pytest.approx(10 * DEG)
    assert res.rudder_angle.value == pytest.approx(10 * DEG, abs=1e-9)
    assert len(res.executes) == 5 and len(res.overshoots) == 4
    # rudder executes: line through the moving samples extrapolated to the old level (the gear is
    # exactly linear; the simulation reverses the order one 0.01-s step after the crossing)
    for e, x in zip(res.executes, S["execs"]):
        assert e.value == pytest.approx(x, abs=0.02)
    for o, x in zip(res.overshoots, tr["overshoots"]):
        assert o.value / DEG == pytest.approx(x, abs=0.01)
    for o, x in zip(res.overshoot_times, tr["otimes"]):
        assert o.value == pytest.approx(x, abs=0.05)
    for c, x in zip(res.crossings, tr["cross"]):
        assert c.value == pytest.approx(x, abs=0.02)
    assert res.initial_turning_time.value == pytest.approx(tr["cross"][0], abs=0.02)
    assert res.time_to_check_yaw.value == pytest.approx(tr["otimes"][0] - S["execs"][1], abs=0.05)
    assert res.period.value == pytest.approx(S["execs"][3] - S["execs"][1], abs=0.02)
    assert res.period_heading.value == pytest.approx(tr["cross"][2] - tr["cross"][0], abs=0.02)
    assert abs(res.helm_delay) < 0.05
    assert res.second_overshoot.value / DEG == pytest.approx(tr["overshoots"][1], abs=0.01)


@pytest.mark.parametrize("side", [1, -1], ids=["starboard-first", "port-first"])
def test_noisy_1hz_overshoots_within_a_tenth_of_a_degree(zz10, side):
    """1 Hz, gyro noise 0.1°: first and second overshoots within 0.1° (RMS error here ≈ 0.035°)."""
    S = simulate(side=side) if side == -1 else zz10[0]
    tr = truth(S)
    errs = []
    for seed in range(8):
        res = Z.zigzag_metrics(*record(S, np.random.default_rng(100 + seed)))
        assert res.first_side == side
        e1 = res.first_overshoot.value / DEG - tr["overshoots"][0]
        e2 = res.second_overshoot.value / DEG - tr["overshoots"][1]
        assert abs(e1) < 0.1 and abs(e2) < 0.1, (seed, e1, e2)
        errs += [e1, e2]
        # the stated σ is a few hundredths of a degree and the interval is honest
        assert 0.01 < res.first_overshoot.std / DEG < 0.08
    assert math.sqrt(np.mean(np.square(errs))) < 0.06


def test_noisy_intervals_cover_at_nominal_rate(zz10):
    """60 noisy records: overshoot angles and times, executes: 95 % intervals cover the truth at the
    nominal rate within 3 binomial SE, z-scores with RMS near 1 (over 200 records: overshoot z SD
    0.92–1.01, execute z SD 1.01–1.18)."""
    S, tr = zz10
    n_rep = 60
    hits, n, z = 0, 0, []
    for seed in range(n_rep):
        res = Z.zigzag_metrics(*record(S, np.random.default_rng(seed)))
        pairs = [(res.overshoots[k], tr["overshoots"][k] * DEG) for k in range(2)]
        pairs += [(res.overshoot_times[k], tr["otimes"][k]) for k in range(2)]
        pairs += [(res.executes[k], S["execs"][k] + 0.005) for k in range(1, 4)]
        for e, x in pairs:
            hits += e.covers(x)
            n += 1
            z.append((e.value - x) / e.std)
    cov = hits / n
    assert abs(cov - 0.95) <= 3 * math.sqrt(0.95 * 0.05 / n) + 0.01, cov
    assert 0.8 < math.sqrt(np.mean(np.square(z))) < 1.25


def test_twenty_twenty_and_helm_delay_and_imo_verdict():
    """20°/20° with a helmsman who reverses 2 s after the threshold: the executes come from the rudder
    record (2 s late), the time to check yaw is measured from them, the overshoot is bigger than in
    the 10°/10° test and the IMO verdict follows from the reduced Estimate."""
    S10 = simulate()
    S = simulate(delta=20.0, alpha=20.0, delay=2.0, n_exec=4)
    tr = truth(S)
    res = Z.zigzag_metrics(*record(S, np.random.default_rng(4)))
    assert res.check_angle == pytest.approx(20 * DEG)
    assert res.helm_delay == pytest.approx(2.0, abs=0.3)
    assert res.first_overshoot.value / DEG == pytest.approx(tr["overshoots"][0], abs=0.1)
    assert res.time_to_check_yaw.value == pytest.approx(tr["otimes"][0] - S["execs"][1], abs=0.6)
    assert res.period.value == pytest.approx(S["execs"][3] - S["execs"][1], abs=0.3)
    assert res.first_overshoot.value > truth(S10)["overshoots"][0] * DEG
    v = imo.first_overshoot_20(res.first_overshoot)
    assert v.passed == (tr["overshoots"][0] <= 25.0)
    assert v.margin.std == res.first_overshoot.std


def test_short_record_has_first_overshoot_only():
    S = simulate(n_exec=2, t_after=40.0)
    res = Z.zigzag_metrics(*record(S, np.random.default_rng(1)))
    assert res.first_overshoot is not None
    assert res.second_overshoot is None and res.period is None and len(res.executes) == 2


def test_explicit_check_angle_and_executes_detection():
    S = simulate(delta=15.0, alpha=10.0)
    tr = truth(S)
    th, h, trd, d = record(S, np.random.default_rng(9))
    moves = Z.rudder_executes(trd, d)
    assert [m.direction for m in moves] == [1, -1, 1, -1, 1]
    assert moves[1].level_from == pytest.approx(15 * DEG, abs=0.1 * DEG)
    res = Z.zigzag_metrics(th, h, trd, d, check_angle=10 * DEG)
    assert res.first_overshoot.value / DEG == pytest.approx(tr["overshoots"][0], abs=0.1)
    # the default check angle would be the rudder amplitude (15°): the heading never reaches it again
    res15 = Z.zigzag_metrics(th, h, trd, d)
    assert res15.check_angle == pytest.approx(15 * DEG)


def test_clock_errors_enter_the_timing_intervals():
    """Gyro and rudder synchros on two loggers whose clocks are each off by a drawn offset (SD 0.2 s)
    and drift (SD 200 ppm, synchronised 1800 s before the run): the initial turning time (a gyro
    crossing less a rudder execute) then misses by the clocks' difference. Stating the clocks
    (:class:`Clock`, as in record meta) brings the 95 % coverage over 60 records to the nominal rate
    within 3 binomial SE, and the z-scores to RMS ≈ 1; without them the interval covers far less.
    The period between like executes is on one clock: its interval grows only by the drift over it."""
    S = simulate(delta=20.0, alpha=20.0, gear=5.0, K=0.2, T=10.0)
    tr = truth(S)
    clk = Z.Clock(0.2, 200.0, -1800.0)
    hit_with = hit_without = 0
    z = []
    n = 60
    for seed in range(n):
        rng = np.random.default_rng(500 + seed)
        th, h, trd, d = record(S, rng, sig_h=0.05, sig_d=0.05, jitter=0.1)
        # each logger's time stamp = true time + its clock error (offset + drift since t_ref)
        eg = rng.normal(0.0, 0.2) + rng.normal(0.0, 200e-6) * (th - clk.t_ref)
        er = rng.normal(0.0, 0.2) + rng.normal(0.0, 200e-6) * (trd - clk.t_ref)
        args = (th + eg, h, trd + er, d)
        a = Z.zigzag_metrics(*args, clock_heading=clk, clock_rudder=clk)
        b = Z.zigzag_metrics(*args)
        x = tr["cross"][0]
        hit_with += a.initial_turning_time.covers(x)
        hit_without += b.initial_turning_time.covers(x)
        z.append((a.initial_turning_time.value - x) / a.initial_turning_time.std)
        assert a.period.std >= b.period.std
        assert a.period.std == pytest.approx(math.hypot(b.period.std, 200e-6 * b.period.value), rel=1e-6)
    cov = hit_with / n
    assert abs(cov - 0.95) <= 3 * math.sqrt(0.95 * 0.05 / n) + 0.01, cov
    assert 0.75 < math.sqrt(np.mean(np.square(z))) < 1.3
    assert hit_without / n < 0.6, hit_without / n


def test_clock_of_a_mean_of_synchros():
    """The mean of n synchros on independent clocks: offset and drift SDs over √n; SD at t from both."""
    c = Z.Clock.mean([Z.Clock(0.02, 10.0, 0.0), Z.Clock(0.02, 10.0, 0.0)])
    assert c.offset_sd == pytest.approx(0.02 / math.sqrt(2))
    assert c.drift_ppm_sd == pytest.approx(10.0 / math.sqrt(2))
    assert c.sd(3600.0) == pytest.approx(math.hypot(0.02, 10e-6 * 3600.0) / math.sqrt(2))
    assert Z.Clock.from_meta({"clock_offset_sd_s": 0.02, "clock_drift_ppm_sd": 10.0, "clock_t_ref_s": 5.0}) == \
        Z.Clock(0.02, 10.0, 5.0)
