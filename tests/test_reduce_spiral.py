"""vtrials.reduce.spiral on synthetic spirals whose answers are known.

Yaw model: τ ṙ = b δ − h(r), ψ̇ = r (rad, s), h(r) = r³ − a r (unstable) or r³ + a r (stable). Steady
turns satisfy h(r) = b δ: for the unstable ship the steady branches of r³ − a r = b δ, with folds at
r_f = ±√(a/3), δ_f = ∓(2a/3) r_f / b; loop width 2|δ_f| = (4a/3b)√(a/3) and height (at δ = 0) 2√a.
Here √a = 0.3°/s and δ_f = 3.5°, so the loop is 7° wide and 0.6°/s high. The rudder follows the
seed-002 schedule 15R … 15L … 15R through a 2.5 °/s steering gear; each setting is held until the
rate is constant (|ṙ| < 1e-10 rad/s²) and then 150 s more (the crew's data). Integrated with
DOP853 (rtol 1e-10); records sampled at 1 Hz (±0.3 s jitter when noisy), gyro and rudder σ 0.1°.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate

from vtrials.reduce import spiral as S
from vtrials.units import DEG

SCHED = [15, 10, 7.5, 5, 2, 0, -2, -5, -7.5, -10, -15, -10, -7.5, -5, -2, 0, 2, 5, 7.5, 10, 15]
R0 = 0.3 * DEG
DF = 3.5 * DEG
A = R0 ** 2
B = (2 * A / 3) * (R0 / math.sqrt(3)) / DF
TAU = 2 * A * 60.0  # 60-s relaxation on the branch at δ = 0
W_TRUE = (4 * A / (3 * B)) * math.sqrt(A / 3)
H_TRUE = 2 * math.sqrt(A)


def h(r, stable=False):
    return r ** 3 + A * r if stable else r ** 3 - A * r


def simulate(schedule=SCHED, stable=False, misses=None, short=None, data_s=150.0, gear=2.5 * DEG, t_app=120.0):
    misses, short = misses or {}, short or {}
    pieces, rud_t, rud_d = [], [0.0], [0.0]
    state, d_prev, r_end = np.zeros(2), 0.0, []

    def run(t0, t1, dfun, ev=None):
        f = lambda tt, y: [y[1], (B * dfun(tt) - h(y[1], stable)) / TAU]  # noqa: E731
        sol = integrate.solve_ivp(f, (t0, t1), state, method="DOP853", rtol=1e-10, atol=1e-13, dense_output=True,
                                  events=ev)
        pieces.append((t0, sol.t[-1], sol.sol))
        return sol

    sol = run(0.0, t_app, lambda tt: 0.0)
    state, t = sol.y[:, -1], t_app
    for k, dn in enumerate(schedule):
        dnew = misses.get(k, dn) * DEG
        t0, tr = t, abs(dnew - d_prev) / gear
        if tr > 0:
            sol = run(t, t + tr, lambda tt, d0=d_prev, ts=t, dn=dnew: d0 + (dn - d0) * (tt - ts) / tr)
            state, t = sol.y[:, -1], t + tr
        rud_t += [t0, t]
        rud_d += [d_prev, dnew]
        if k in short:
            sol = run(t, t0 + short[k], lambda tt, dn=dnew: dn)
        else:
            def settled(tt, y, dn=dnew):
                return abs(B * dn - h(y[1], stable)) / TAU - 1e-10
            settled.terminal, settled.direction = True, -1
            sol = run(t, t + 30000.0, lambda tt, dn=dnew: dn, ev=settled)
            state, t = sol.y[:, -1], sol.t[-1]
            sol = run(t, t + data_s, lambda tt, dn=dnew: dn)
        state, t = sol.y[:, -1], sol.t[-1]
        r_end.append(float(state[1]))
        d_prev = dnew
    rud_t.append(t)
    rud_d.append(d_prev)
    return {"pieces": pieces, "rud": (np.array(rud_t), np.array(rud_d)), "r_end": np.array(r_end), "t_end": t,
            "stable": stable, "delta": [misses.get(k, dn) * DEG for k, dn in enumerate(schedule)]}


def record(sim, rng=None, sig=0.1 * DEG):
    t = np.arange(0.0, sim["t_end"], 1.0)
    if rng is not None:
        t = np.sort(t + rng.uniform(-0.3, 0.3, t.size))
        t = t[(t >= 0) & (t <= sim["t_end"])]
    psi = np.empty_like(t)
    for t0, t1, f in sim["pieces"]:
        m = (t >= t0) & (t <= t1)
        if m.any():
            psi[m] = f(t[m])[0]
    d = np.interp(t, *sim["rud"])
    if rng is not None:
        psi, d = psi + rng.normal(0, sig, t.size), d + rng.normal(0, sig, t.size)
    return t, np.mod(psi, 2 * math.pi), d


def true_rate(delta, r_end, stable=False):
    rr = np.roots([1.0, 0.0, A if stable else -A, -B * delta])
    rr = rr.real[np.abs(rr.imag) < 1e-12]
    return float(rr[np.argmin(np.abs(rr - r_end))])


@pytest.fixture(scope="module")
def unstable():
    return simulate(misses={17: 4.6})  # 5R on the return sweep reached as 4.6R and held (seed 002)


def test_noise_free_unstable_spiral_points_branches_and_loop(unstable):
    sim = unstable
    t, psi, d = record(sim)
    res = S.direct_spiral(t, psi, t, d)
    pts = res.points
    assert len(pts) == len(SCHED) and not res.never_steady
    for k, p in enumerate(pts):
        assert p.steady, (k, p.note)
        assert p.rudder.value == pytest.approx(sim["delta"][k], abs=1e-9)  # the angle REACHED
        assert p.rate.value == pytest.approx(true_rate(sim["delta"][k], sim["r_end"][k]), abs=1e-7)
        assert p.branch == ("up" if k == 0 or k > 10 else "down")
    # the ship jumped where the cubic says: starboard branch down to −2°, port branch up to +2°
    assert np.all(sim["r_end"][:7] > 0) and sim["r_end"][7] < 0
    assert np.all(sim["r_end"][10:17] < 0) and sim["r_end"][17] > 0
    loop = res.loop
    assert loop.verdict == "unstable (loop)" and loop.p_loop == 1.0
    # the S-curve fit reproduces the cubic exactly: width, height, fold angles, slope at r = 0
    assert loop.width.value == pytest.approx(W_TRUE, rel=1e-4)
    assert loop.height.value == pytest.approx(H_TRUE, rel=1e-4)
    assert loop.edges == pytest.approx((-DF, DF), abs=1e-4 * DF)
    assert loop.slope_at_origin.value == pytest.approx(-A / B, rel=1e-4)
    # model-free: branch differences at −2°, 0, +2°; the width lies between [4°, 9.6°]
    lo, hi = loop.direct["width_bracket"]
    assert lo == pytest.approx(4 * DEG, abs=1e-6) and hi == pytest.approx(9.6 * DEG, abs=1e-6)
    assert lo <= W_TRUE <= hi and loop.consistent
    # the largest branch difference is at δ = 0: 2√a
    assert loop.direct["height"].value == pytest.approx(H_TRUE, abs=1e-7)


def test_noisy_unstable_spiral_rates_cover_and_loop_found(unstable):
    """Gyro and synchro σ 0.1°, jittered 1 Hz: point intervals cover at the nominal rate, the loop
    width and height intervals cover 7° and 0.6°/s (over 10 records: rate z RMS 1.00, rudder 0.98)."""
    sim = unstable
    z, hits, n = [], 0, 0
    for seed in range(3):
        t, psi, d = record(sim, np.random.default_rng(seed))
        res = S.direct_spiral(t, psi, t, d)
        for k, p in enumerate(res.points):
            assert p.steady, (seed, k, p.note)
            r_true = true_rate(sim["delta"][k], sim["r_end"][k])
            z.append((p.rate.value - r_true) / p.rate.std)
            hits += int(p.rate.covers(r_true)) + int(p.rudder.covers(sim["delta"][k]))
            n += 2
        loop = res.loop
        assert loop.verdict == "unstable (loop)"
        assert loop.width.covers(W_TRUE) and loop.height.covers(H_TRUE)
        assert loop.width.std < 0.05 * W_TRUE
        lo, hi = loop.direct["width_bracket"]
        assert lo <= W_TRUE <= hi
    assert abs(hits / n - 0.95) <= 3 * math.sqrt(0.95 * 0.05 / n) + 0.01
    assert 0.7 < math.sqrt(np.mean(np.square(z))) < 1.3


def test_stable_spiral_has_no_loop():
    sim = simulate(stable=True, data_s=130.0)
    t, psi, d = record(sim, np.random.default_rng(7))
    res = S.direct_spiral(t, psi, t, d)
    assert all(p.steady for p in res.points)
    for k, p in enumerate(res.points):
        assert p.rate.value == pytest.approx(true_rate(sim["delta"][k], 0.0, stable=True), abs=2e-3 * DEG)
    loop = res.loop
    assert loop.verdict == "stable (no loop)" and loop.p_loop < 0.025
    assert loop.width.value == 0.0 and loop.width.covers(0.0)
    assert loop.height.value == 0.0
    assert loop.slope_at_origin.value > 0  # dδ/dr > 0 at straight course
    assert loop.direct["loop"] is False and loop.consistent


def test_setting_left_too_early_is_reported_not_averaged(unstable):
    """Setting 7 (−5°, where the ship leaves the starboard branch) abandoned after 200 s, mid-jump: the
    rate is still changing → NOT steady, reported as such and kept out of the loop analysis."""
    sim = simulate(short={7: 200.0})
    t, psi, d = record(sim, np.random.default_rng(3))
    res = S.direct_spiral(t, psi, t, d)
    assert [p.order for p in res.never_steady] == [7]
    p7 = res.points[7]
    assert "never steady" in p7.note and abs(p7.rate_change.value) > 5 * p7.rate_change.std
    assert any("never steady" in n for n in res.loop.notes)
    assert res.loop.verdict == "unstable (loop)" and res.loop.width.covers(W_TRUE)


def test_holds_from_log_equal_detected_holds(unstable):
    t, psi, d = record(unstable, np.random.default_rng(5))
    holds = S.rudder_holds(t, d)
    assert len(holds) == len(SCHED) + 1  # the approach at 0° first
    pts_log = S.spiral_points(t, psi, t, d, holds=holds[1:])
    pts_auto = S.spiral_points(t, psi, t, d)
    assert [p.rate.value for p in pts_log] == pytest.approx([p.rate.value for p in pts_auto])


def test_reverse_spiral_maps_the_unstable_middle_branch():
    """Bech: rates held on both outer branches AND on the unstable middle branch; the helm's rudder
    scatters (AR(1), σ 1°, ρ 0.9); the mean rudder equals h(r)/b within its SE, the S-curve through
    the points gives the loop of the direct spiral without ever jumping."""
    rng = np.random.default_rng(11)
    rates = np.array([-0.45, -0.35, -0.25, -0.15, -0.05, 0.05, 0.15, 0.25, 0.35, 0.45]) * DEG
    t_all, psi_all, d_all, segs = [], [], [], []
    t0, psi0 = 0.0, 0.3
    for r in rates:
        tt = t0 + np.arange(0.0, 300.0)
        e = np.empty(tt.size)
        e[0] = rng.normal(0, 1.0)
        for i in range(1, tt.size):
            e[i] = 0.9 * e[i - 1] + rng.normal(0, 1.0 * math.sqrt(1 - 0.81))
        d_all.append(h(r) / B + e * DEG)
        psi_all.append(psi0 + r * (tt - t0) + rng.normal(0, 0.1 * DEG, tt.size))
        t_all.append(tt)
        segs.append((t0 + 60.0, t0 + 299.0))
        psi0 += r * 300.0
        t0 += 300.0
    t, psi, d = np.concatenate(t_all), np.mod(np.concatenate(psi_all), 2 * math.pi), np.concatenate(d_all)
    pts = S.reverse_spiral_points(t, psi, t, d, segs)
    hits = sum(p.rudder.covers(h(p.rate.value) / B, 0.99) for p in pts)
    assert hits >= 9
    for p, r in zip(pts, rates):
        assert p.rate.value == pytest.approx(r, abs=0.002 * DEG)
        assert 0.05 * DEG < p.rudder.std < 0.6 * DEG  # lag-1 inflation of the autocorrelated helm
    loop = S.hysteresis_loop(pts)
    assert loop.verdict == "unstable (loop)"
    assert loop.width.covers(W_TRUE) and loop.height.covers(H_TRUE)
    assert loop.slope_at_origin.value < 0
