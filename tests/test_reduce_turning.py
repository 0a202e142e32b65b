"""vtrials.reduce.turning on synthetic turning circles whose answers are known.

The synthetic turn (:func:`make_turn`): straight approach on course ψ₀ at U₀; at EXECUTE the rate of
turn ramps linearly from 0 to r over T_r (a transient spiral-in: heading quadratic in time), then
holds r; the speed falls smoothly (cubic smoothstep) from U₀ to U over T_u and then holds. After the
transient the water track is an exact circle of radius U/r. Positions through the water are the
integral of U(cos ψ, sin ψ) (16-point Gauss–Legendre per 1-s step, exact to rounding), then a
KNOWN constant drift D·(t − t_execute) is added. Analytic references: the heading marks solve
ψ(t) − ψ₀ = 10°, 90°, 180° in closed form; advance / transfer / tactical diameter are the along- /
across-course components of the water track at those instants (adaptive quadrature); steady
diameter = 2U/r.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate, stats

from vtrials.reduce import turning as T
from vtrials.reduce.estimate import Estimate
from vtrials.units import DEG

# --------------------------------------------------------------------------------- synthetic turn
GL_X, GL_W = np.polynomial.legendre.leggauss(16)


class Turn:
    """Analytic heading and speed of the synthetic turn (times relative to EXECUTE = 0)."""

    def __init__(self, U0=7.0, U=5.0, r=0.6 * DEG, T_r=40.0, T_u=40.0, psi0=30.0 * DEG, side=1):
        self.U0, self.U, self.r, self.T_r, self.T_u, self.psi0, self.side = U0, U, r, T_r, T_u, psi0, side

    def dpsi(self, t):
        """Unsigned heading change since EXECUTE [rad]."""
        t = np.asarray(t, float)
        tc = np.clip(t, 0.0, None)
        ramp = 0.5 * self.r * np.minimum(tc, self.T_r) ** 2 / self.T_r
        return ramp + self.r * np.clip(tc - self.T_r, 0.0, None)

    def heading(self, t):
        return self.psi0 + self.side * self.dpsi(t)

    def speed(self, t):
        x = np.clip(np.asarray(t, float) / self.T_u, 0.0, 1.0)
        return self.U0 - (self.U0 - self.U) * (3 * x ** 2 - 2 * x ** 3)

    def t_mark(self, deg):
        """Instant at which the heading has changed by ``deg`` degrees (closed form)."""
        d = deg * DEG
        d_ramp = 0.5 * self.r * self.T_r
        if d <= d_ramp:
            return math.sqrt(2 * d * self.T_r / self.r)
        return self.T_r + (d - d_ramp) / self.r

    def water_offset(self, t1):
        """Water-track displacement from EXECUTE to t1 projected on the approach course and its
        normal toward the turn: (along, across) by adaptive quadrature."""
        def fa(t):
            return self.speed(t) * math.cos(self.dpsi(t))

        def fc(t):
            return self.speed(t) * math.sin(self.dpsi(t))
        pts = [p for p in (self.T_r, self.T_u) if p < t1]
        kw = dict(points=pts or None, epsabs=1e-9, epsrel=1e-12, limit=400)
        return integrate.quad(fa, 0.0, t1, **kw)[0], integrate.quad(fc, 0.0, t1, **kw)[0]

    def water_track(self, t):
        """North, east of the water track at the (sorted, 1-s spaced or finer) sample times ``t``,
        zero at EXECUTE. Breakpoints 0, T_r, T_u must be sample times."""
        t = np.asarray(t, float)
        a, b = t[:-1], t[1:]
        tm = 0.5 * (a + b)[:, None] + 0.5 * (b - a)[:, None] * GL_X[None, :]
        w = 0.5 * (b - a)[:, None] * GL_W[None, :]
        sp, ps = self.speed(tm), self.heading(tm)
        dN = np.sum(w * sp * np.cos(ps), axis=1)
        dE = np.sum(w * sp * np.sin(ps), axis=1)
        N = np.concatenate([[0.0], np.cumsum(dN)])
        E = np.concatenate([[0.0], np.cumsum(dE)])
        k0 = int(np.argmin(np.abs(t)))
        assert t[k0] == 0.0
        return N - N[k0], E - E[k0]


def make_turn(turn: Turn, drift=(0.3, -0.2), t_app=120.0, total_deg=720.0, dt=1.0, t0=1000.0):
    """Recorded-like arrays (absolute clock t0 + …): t, north, east, heading (wrapped to [0, 2π))."""
    t_end = turn.t_mark(total_deg)
    t = np.arange(-t_app, t_end + 1e-9, dt)
    N, E = turn.water_track(t)
    N = N + drift[0] * t
    E = E + drift[1] * t
    psi = np.mod(turn.heading(t), 2 * math.pi)
    return t + t0, N, E, psi


def truth(turn: Turn) -> dict:
    out = {}
    for deg in (10.0, 90.0, 180.0):
        out[deg] = turn.water_offset(turn.t_mark(deg))
    return {"advance": out[90.0][0], "transfer": out[90.0][1], "tactical": out[180.0][1],
            "diameter": 2 * turn.U / turn.r, "rate": turn.side * turn.r, "speed": turn.U,
            "t90": turn.t_mark(90.0), "t180": turn.t_mark(180.0), "t10": turn.t_mark(10.0)}


# ---------------------------------------------------------------------------- (a) exact, no noise
@pytest.mark.parametrize("side", [1, -1], ids=["starboard", "port"])
def test_noiseless_turn_recovers_drift_and_metrics_exactly(side):
    """(a) + (c): exact data → drift to 1e-6 relative, metrics equal to the generated path."""
    turn = Turn(side=side)
    D = (0.3, -0.2)
    t, N, E, psi = make_turn(turn, drift=D)
    te = 1000.0
    res = T.turning_metrics(t, N, E, psi, te)
    tr = truth(turn)
    assert res.turn_side == side
    assert res.steady.steady, res.notes
    # the steady part starts once the rate ramp (15 s) has left the sliding rate window
    assert te + turn.T_r <= res.steady.t_start <= te + turn.T_r + 30.0
    assert res.drift.method == "pairs" and res.drift.n_pairs > 50
    assert res.drift.north.value == pytest.approx(D[0], rel=1e-6)
    assert res.drift.east.value == pytest.approx(D[1], rel=1e-6)
    assert res.approach_course.value == pytest.approx(turn.psi0, abs=1e-12)
    assert res.approach_speed.value == pytest.approx(turn.U0, rel=1e-9)
    # metrics: the only approximation left is the local cubic at the marks (≈ mm on a 400 m circle)
    assert res.advance.value == pytest.approx(tr["advance"], abs=5e-3)
    assert res.transfer.value == pytest.approx(tr["transfer"], abs=5e-3)
    assert res.tactical_diameter.value == pytest.approx(tr["tactical"], abs=5e-3)
    assert res.steady_diameter.value == pytest.approx(tr["diameter"], rel=1e-6)
    assert res.steady_rate.value == pytest.approx(tr["rate"], rel=1e-9)
    assert res.steady_speed.value == pytest.approx(tr["speed"], rel=1e-6)
    assert res.time_to_90.value == pytest.approx(tr["t90"], abs=1e-6)
    assert res.time_to_180.value == pytest.approx(tr["t180"], abs=1e-6)
    # the 10° mark lies 3.5 s before the end of the rate ramp: its local quadratic straddles the
    # kink of ψ̈ (9 ms error); the 90°/180° marks lie on the exactly linear part
    assert res.time_to_10.value == pytest.approx(tr["t10"], abs=0.02)
    path10 = integrate.quad(turn.speed, 0.0, tr["t10"], points=[turn.T_u])[0]
    assert res.distance_to_10.value == pytest.approx(path10, abs=0.1)
    # a ship without drift angle in this kinematic model: β = 0
    assert abs(res.drift_angle.value) < 1e-6
    # the values are not trivially the raw (drifting) track: without the correction they differ
    raw = T.turning_metrics(t, N, E, psi, te, drift=None)
    assert abs(raw.tactical_diameter.value - tr["tactical"]) > 10.0


def test_given_drift_and_corrected_track_are_consistent():
    turn = Turn()
    t, N, E, psi = make_turn(turn, drift=(-0.4, 0.25))
    Nc, Ec = T.drift_corrected_track(t, N, E, 1000.0, (-0.4, 0.25))
    Nw, Ew = turn.water_track(t - 1000.0)
    assert np.max(np.abs(Nc - Nw)) < 1e-9 and np.max(np.abs(Ec - Ew)) < 1e-9
    res = T.turning_metrics(t, N, E, psi, 1000.0, drift=(Estimate(-0.4, 0.01), Estimate(0.25, 0.01)))
    assert res.drift.method == "given"
    assert res.tactical_diameter.value == pytest.approx(truth(turn)["tactical"], abs=5e-3)
    # the stated drift uncertainty enters the tactical diameter: σ ≥ 0.01 m/s × t180
    assert res.tactical_diameter.std >= 0.01 * truth(turn)["t180"] * 0.99


def test_circle_fit_drift_cross_check_exact():
    turn = Turn()
    t, N, E, psi = make_turn(turn, drift=(0.3, -0.2))
    sw = T.steady_window(t, psi, 1000.0)
    d = T.drift_from_circle_fit(t, N, E, sw.t_start, sw.t_end, sw.rate.value)
    assert d.north.value == pytest.approx(0.3, rel=1e-6)
    assert d.east.value == pytest.approx(-0.2, rel=1e-6)
    assert d.detail["radius_m"] == pytest.approx(turn.U / turn.r, rel=1e-7)


# --------------------------------------------------------------------------- (b) noise, coverage
N_REP = 40


def _noisy(rng, t, N, E, psi, sig_p=2.0, sig_psi=0.1 * DEG, q_p=0.1, q_psi=0.05 * DEG):
    Nn = np.round((N + rng.normal(0, sig_p, N.size)) / q_p) * q_p
    En = np.round((E + rng.normal(0, sig_p, E.size)) / q_p) * q_p
    pn = np.mod(np.round((psi + rng.normal(0, sig_psi, psi.size)) / q_psi) * q_psi, 2 * math.pi)
    return Nn, En, pn


def test_noisy_turn_intervals_cover_at_nominal_rate():
    """(b) positions σ = 2 m (0.1 m resolution), gyro σ = 0.1° (0.05° resolution), 40 seeds: the
    95 % intervals of drift, advance, transfer, tactical and steady diameter, steady speed and rate,
    times to 90° and 180° cover the truth. Each metric: coverage not below the 0.1 % binomial
    quantile of a true 95 % interval; pooled over the 10 metrics (400 intervals): within
    0.95 ± (3 binomial SE + 0.02, allowing for metrics that share the drift estimate). Over 400
    seeds (not run here) every metric covered 93.5–96.8 % with z-score RMS 0.92–1.03."""
    turn = Turn(side=-1, psi0=200.0 * DEG)
    D = (0.25, 0.35)
    t, N, E, psi = make_turn(turn, drift=D, total_deg=740.0)
    tr = truth(turn)
    ref = {"drift_n": D[0], "drift_e": D[1], "advance": tr["advance"], "transfer": tr["transfer"],
           "tactical": tr["tactical"], "diameter": tr["diameter"], "speed": tr["speed"],
           "rate": tr["rate"], "t90": tr["t90"], "t180": tr["t180"]}
    hits = {k: 0 for k in ref}
    err = {k: [] for k in ref}
    for seed in range(N_REP):
        rng = np.random.default_rng(1000 + seed)
        Nn, En, pn = _noisy(rng, t, N, E, psi)
        res = T.turning_metrics(t, Nn, En, pn, 1000.0)
        assert res.steady.steady and res.drift.method == "pairs"
        est = {"drift_n": res.drift.north, "drift_e": res.drift.east, "advance": res.advance,
               "transfer": res.transfer, "tactical": res.tactical_diameter, "diameter": res.steady_diameter,
               "speed": res.steady_speed, "rate": res.steady_rate, "t90": res.time_to_90,
               "t180": res.time_to_180}
        for k, e in est.items():
            hits[k] += e.covers(ref[k])
            err[k].append((e.value - ref[k]) / e.std)
    lo_each = stats.binom.ppf(0.001, N_REP, 0.95)
    for k in ref:
        assert hits[k] >= lo_each, (k, hits[k], N_REP)
    pooled = sum(hits.values()) / (len(ref) * N_REP)
    assert abs(pooled - 0.95) <= 3 * math.sqrt(0.95 * 0.05 / (len(ref) * N_REP)) + 0.02, (pooled, hits)
    # the stated σ are realistic, not inflated: z-scores have RMS near 1 (not ≪ 1)
    zrms = math.sqrt(np.mean(np.concatenate([np.square(v) for v in err.values()])))
    assert 0.6 < zrms < 1.4, zrms
    # and the errors are small in absolute terms (a few metres on a ~480 m circle)
    assert abs(np.mean(err["tactical"])) < 0.6


# ---------------------------------------------------------------------- (d) not steady is flagged
def test_record_too_short_is_flagged_not_steady():
    """(d) FINEX after 85° of heading change (12° of it in the spiral-in): the steady part spans
    < 90° → NOT steady, announced in the notes; the 90° mark is never reached."""
    turn = Turn()
    t, N, E, psi = make_turn(turn, total_deg=85.0)
    res = T.turning_metrics(t, N, E, psi, 1000.0)
    assert not res.steady.steady
    assert any("NOT STEADY" in n for n in res.notes)
    assert res.steady.span < 90 * DEG
    assert res.advance is None and res.tactical_diameter is None
    assert any("never reached 90" in n for n in res.notes)


def test_still_accelerating_rate_is_flagged_not_steady():
    """(d) a spiral whose rate keeps growing (ramp over the whole record) is never steady."""
    turn = Turn(T_r=2000.0, r=2.0 * DEG)
    t, N, E, psi = make_turn(turn, total_deg=400.0)
    sw = T.steady_window(t, psi, 1000.0)
    assert not sw.steady
    assert "not steady" in sw.note


# ----------------------------------------------------------------------------- (e) rudder breakdown
def test_rudder_breakdown_detected_and_not_for_monotone_curve():
    """(e) rate vs rudder at two speeds and both sides. Speed 5 m/s starboard: the rate falls from
    25° to 35° (breakdown at 25°); the monotone curves are not flagged."""
    rud = np.array([10, 15, 20, 25, 35]) * DEG
    r_mono = np.array([0.30, 0.42, 0.50, 0.55, 0.58]) * DEG
    r_bk = np.array([0.30, 0.42, 0.50, 0.55, 0.45]) * DEG
    sd = 0.01 * DEG
    speeds, rudders, rates = [], [], []
    for spd, curve_s, curve_p in ((5.0, r_bk, r_mono), (8.0, r_mono, r_mono)):
        for d, rs, rp in zip(rud, curve_s, curve_p):
            speeds += [spd + 0.05, spd - 0.05]
            rudders += [d, -d]
            rates += [Estimate(rs, sd), Estimate(-rp, sd)]
    groups = T.rudder_breakdown(speeds, rudders, rates)
    assert len(groups) == 4
    flagged = {(round(g.speed), g.side): g for g in groups}
    g = flagged[(5, 1)]
    assert g.breakdown and g.breakdown_rudder == pytest.approx(25 * DEG)
    assert g.z_drop < -5
    for key in ((5, -1), (8, 1), (8, -1)):
        assert not flagged[key].breakdown
        assert np.all(np.diff(flagged[key].rudder) > 0)
    # a drop within the noise is not a breakdown
    noisy = [Estimate(r.value, 0.08 * DEG) for r in rates]
    assert not any(g.breakdown for g in T.rudder_breakdown(speeds, rudders, noisy))


# ------------------------------------------- drift coverage over ~100 irregular, gappy records
def _dense(turn, drift, total_deg=720.0):
    td, Nd, Ed, psid = make_turn(turn, drift=drift, total_deg=total_deg, dt=0.125)
    return td, Nd, Ed, np.unwrap(psid)


def _irregular(rng, dense, sig_p=3.0, sig_psi=0.1 * DEG):
    """Tracking fixes at ~1 Hz (±0.3 s jitter, 5 % dropped) and a gyro on its own jittered clock,
    interpolated from a 0.125-s dense synthetic turn (:func:`_dense`)."""
    td, Nd, Ed, psid = dense
    base = np.arange(td[0] + 0.5, td[-1] - 0.5, 1.0)
    tp = np.sort(base + rng.uniform(-0.3, 0.3, base.size))
    tp = tp[rng.random(tp.size) > 0.05]
    th = np.sort(base + 0.41 + rng.uniform(-0.3, 0.3, base.size))
    th = th[th < td[-1]]
    N = np.interp(tp, td, Nd) + rng.normal(0, sig_p, tp.size)
    E = np.interp(tp, td, Ed) + rng.normal(0, sig_p, tp.size)
    psi = np.mod(np.interp(th, td, psid) + rng.normal(0, sig_psi, th.size), 2 * math.pi)
    return tp, N, E, th, psi


def test_drift_pairs_interval_coverage_100_realizations():
    """Pair-method drift on 100 irregular, gappy records (σ_p = 3 m, gyro 0.1° on its own clock):
    the 95 % intervals of both components cover the true drift at 95 % within 3 binomial SE, and the
    z-scores have unit spread (600 records in development: z SD 1.00 and 0.99). The moving-circle
    fit agrees with the pairs within their combined uncertainty."""
    turn = Turn(T_r=20.0, T_u=20.0)
    D = (0.3, -0.2)
    hits, z, n = 0, [], 0
    dense = _dense(turn, D)
    for seed in range(100):
        rng = np.random.default_rng(7000 + seed)
        tp, N, E, th, psi = _irregular(rng, dense)
        d, sw = T.estimate_drift(tp, N, E, th, psi, 1000.0)
        assert d.method == "pairs" and sw.steady
        for est, true in ((d.north, D[0]), (d.east, D[1])):
            hits += int(est.covers(true))
            z.append((est.value - true) / est.std)
            n += 1
        if seed < 5:
            c = T.drift_from_circle_fit(tp, N, E, sw.t_start, sw.t_end, sw.rate.value)
            assert abs(c.north.value - d.north.value) < 3 * math.hypot(c.north.std, d.north.std)
            assert abs(c.east.value - d.east.value) < 3 * math.hypot(c.east.std, d.east.std)
    assert abs(hits / n - 0.95) <= 3 * math.sqrt(0.95 * 0.05 / n), hits / n
    assert 0.85 < float(np.std(z)) < 1.15 and abs(float(np.mean(z))) < 0.25


def test_heel_rudder_and_irregular_metrics():
    """Roll and rudder channels on their own clocks: steady heel (−3°, outward for a starboard turn
    with roll + = starboard down), maximum heel (a −5.5° dip during the transient) and the mean rudder
    in the steady part; the metrics of an irregular, gappy record agree with the truth within 3σ."""
    turn = Turn(T_r=20.0, T_u=20.0)
    rng = np.random.default_rng(42)
    tp, N, E, th, psi = _irregular(rng, _dense(turn, (0.1, 0.2)), sig_p=2.0)
    tr_ = np.arange(900.0, tp[-1], 0.5)
    x = tr_ - 1000.0
    roll = np.where(x > 0, -3.0 * DEG * (1 - np.exp(-x / 15.0)) - 4.0 * DEG * np.exp(-((x - 25.0) / 8.0) ** 2), 0.0)
    roll_m = roll + rng.normal(0, 0.05 * DEG, tr_.size)
    rud = np.where(x > 0, 35.0 * DEG, 0.0) + rng.normal(0, 0.1 * DEG, tr_.size)
    res = T.turning_metrics(tp, N, E, psi, 1000.0, t_heading=th, roll=roll_m, t_roll=tr_, rudder=rud, t_rudder=tr_)
    assert res.heel_steady.covers(-3.0 * DEG, 0.999)
    i = int(np.argmax(np.abs(roll)))
    assert res.heel_max.value == pytest.approx(roll[i], abs=0.1 * DEG)
    assert res.rudder_steady.value == pytest.approx(35.0 * DEG, abs=0.05 * DEG)
    tr = truth(turn)
    for key, est in (("advance", res.advance), ("transfer", res.transfer), ("tactical", res.tactical_diameter),
                     ("diameter", res.steady_diameter), ("t90", res.time_to_90)):
        assert abs(est.value - tr[key]) < 3.5 * est.std, (key, est, tr[key])
    assert abs(res.drift_angle.value) < 3.5 * res.drift_angle.std  # kinematic model: β = 0


def test_heel_interval_carries_the_sensor_zero_accuracy():
    """A vertical gyro's zero error (drawn once per record, σ_b stated by its maker) shifts every roll
    sample alike: averaging does not reduce it. With ``roll_bias`` = σ_b the heel intervals cover the
    true heel at the nominal rate over 200 records; without it they are several times too narrow."""
    turn = Turn(T_r=20.0, T_u=20.0)
    tp, N, E, psi = make_turn(turn)
    rng = np.random.default_rng(7)
    tr_ = np.arange(tp[0], tp[-1], 0.1)
    x = tr_ - 1000.0
    roll = np.where(x > 0, -3.0 * DEG * (1 - np.exp(-x / 15.0)), 0.0)
    sb = 0.1 * DEG
    hit = {True: [], False: []}
    for i in range(200):
        m = roll + rng.normal(0.0, sb) + rng.normal(0.0, 0.03 * DEG, tr_.size)
        for with_bias in (True, False)[:2 if i < 60 else 1]:  # 60 records show the narrow intervals
            res = T.turning_metrics(tp, N, E, psi, 1000.0, roll=m, t_roll=tr_, drift=(0.3, -0.2),
                                    roll_bias=sb if with_bias else 0.0)
            hit[with_bias].append(res.heel_steady.covers(-3.0 * DEG, 0.95))
    assert 0.90 <= np.mean(hit[True]) <= 0.99, np.mean(hit[True])
    assert np.mean(hit[False]) < 0.6, np.mean(hit[False])


def test_approach_speed_from_a_given_current_not_the_drift():
    """The circle's drift holds the wind's push on the circling ship besides the current; the approach
    speed through the water is the ground velocity less the current. Given both, the approach speed
    takes the current (and its covariance along the approach course)."""
    turn = Turn(T_r=20.0, T_u=20.0)
    cur = np.array([0.3, -0.2])
    tp, N, E, psi = make_turn(turn, drift=tuple(cur))
    lee = np.array([-0.05, 0.04])                   # the circles' extra drift (leeway), not in the approach
    cov = np.diag([0.02 ** 2, 0.01 ** 2])
    res_d = T.turning_metrics(tp, N, E, psi, 1000.0, drift=tuple(cur + lee))
    res_c = T.turning_metrics(tp, N, E, psi, 1000.0, drift=tuple(cur + lee), current=(cur, cov))
    u = np.array([math.cos(res_c.approach_course.value), math.sin(res_c.approach_course.value)])
    assert res_c.approach_speed.value == pytest.approx(turn.U0, abs=1e-6)
    assert res_d.approach_speed.value - res_c.approach_speed.value == pytest.approx(-float(lee @ u), abs=1e-9)
    assert res_c.approach_speed.std >= math.sqrt(float(u @ cov @ u))


# ------------------------------------------------------------------ steady loop (360° → 720°)
def _loop_turn(rng, R=150.0, U=5.0, wobble=0.1, ground_drift=(0.1, 0.25), side=1, t_end=480.0,
               sig_p=0.5, sig_h=0.001):
    """Approach at U on course ψ₀ for 60 s, then at EXECUTE (t = 0) an instant steady circle of
    radius R in a frame drifting at ``ground_drift`` (current + the circle's own leeway), the rate of
    change of heading r₀(1 + wobble·sin ψ) (the wind's push varies around the loop). Fixes at 1 Hz
    (σ_p), gyro at 10 Hz (σ_h). Returns the records and the analytic loop: heading change of 360°
    from EXECUTE at t₁ = T, 720° at 2T, T = 2π/(r₀√(1 − wobble²))."""
    r0 = U / R
    psi0 = 0.4
    dt = 0.01
    tt = np.arange(0.0, t_end, dt)
    psi = np.empty_like(tt)
    psi[0] = psi0
    for k in range(1, tt.size):
        half = psi[k - 1] + 0.5 * dt * side * r0 * (1 + wobble * math.sin(psi[k - 1]))
        psi[k] = psi[k - 1] + dt * side * r0 * (1 + wobble * math.sin(half))
    ang = psi - side * math.pi / 2
    cN, cE = -R * math.cos(psi0 - side * math.pi / 2), -R * math.sin(psi0 - side * math.pi / 2)
    N_t = cN + R * np.cos(ang) + ground_drift[0] * tt
    E_t = cE + R * np.sin(ang) + ground_drift[1] * tt
    # the approach: straight on ψ₀ at U plus the drift, joining the circle at EXECUTE (origin)
    ta = np.arange(-60.0, 0.0, dt)
    N_a = U * math.cos(psi0) * ta + ground_drift[0] * ta
    E_a = U * math.sin(psi0) * ta + ground_drift[1] * ta
    t_all = np.concatenate([ta, tt])
    N_all, E_all, psi_all = np.concatenate([N_a, N_t]), np.concatenate([E_a, E_t]), np.concatenate([np.full(ta.size, psi0), psi])
    tp = np.arange(-60.0, t_end - 1.0, 1.0) + 0.25
    th = np.arange(-60.0, t_end - 1.0, 0.1) + 0.05
    N = np.interp(tp, t_all, N_all) + rng.normal(0, sig_p, tp.size)
    E = np.interp(tp, t_all, E_all) + rng.normal(0, sig_p, tp.size)
    h = np.interp(th, t_all, psi_all) + rng.normal(0, sig_h, th.size)
    T = 2 * math.pi / (r0 * math.sqrt(1 - wobble ** 2))
    return tp, N, E, th, h, T


@pytest.mark.parametrize("side", [1, -1])
def test_steady_loop_diameter_rate_and_speed(side):
    """Steady values over the second loop, the track closed by the circle's own drift: diameter 2R,
    rate 2π/T (the mean rate over the loop), speed R·2π/T, each within its interval; the loop's end
    times are the analytic 360° and 720° instants. Correcting the loop with a drift that differs from
    its own by 0.1 m/s (the day's mean of both sides) moves the diameter by metres."""
    rng = np.random.default_rng(7 if side > 0 else 8)
    R, drift = 150.0, (0.1, 0.25)
    tp, N, E, th, h, Tl = _loop_turn(rng, R=R, ground_drift=drift, side=side)
    t_finex = 2 * Tl + 20.0
    loop = T.steady_loop(th, h, 0.0, t_finex)
    assert loop.full
    assert loop.t_start == pytest.approx(Tl, abs=0.05)
    assert loop.t_end == pytest.approx(2 * Tl, abs=0.05)
    own = (Estimate(drift[0], 0.002), Estimate(drift[1], 0.002))
    res = T.turning_metrics(tp, N, E, h, 0.0, t_heading=th, drift=own, loop_drift=own, t_finex=t_finex)
    rate = 2 * math.pi / Tl
    assert res.steady_diameter.covers(2 * R, 0.99)
    assert abs(res.steady_diameter.value - 2 * R) < 0.5
    assert res.steady_rate.covers(side * rate, 0.99)
    assert abs(res.steady_rate.value - side * rate) < 2e-4 * rate
    assert res.steady_speed.covers(R * rate, 0.99)
    other = (drift[0] - 0.1, drift[1])
    off = T.turning_metrics(tp, N, E, h, 0.0, t_heading=th, drift=own, loop_drift=other, t_finex=t_finex)
    assert abs(off.steady_diameter.value - 2 * R) > 1.0


def test_circle_radius_variance_from_correlated_errors_matches_monte_carlo():
    """The radius of a circle fitted to one loop under Gauss–Markov tracking errors (sd 1 m, τ 120 s,
    and 0.5 m, 10 s, per axis: a DGPS's wander and multipath) scatters as the linear propagation
    (:func:`vtrials.reduce.series.correlated_variance` through the fit's radius weights) says."""
    from vtrials.reduce.series import correlated_variance
    rng = np.random.default_rng(3)
    R, Tl = 150.0, 190.0
    t = np.arange(0.0, Tl, 1.0)
    a = 2 * math.pi * t / Tl
    x, y = R * np.cos(a), R * np.sin(a)
    comps = [(1.0, 120.0), (0.5, 10.0)]
    p, _, _ = T.fit_circle(x, y)
    h, ph = T._circle_radius_weights(x, y, p)
    sd_pred = math.sqrt(correlated_variance(t, h, comps, ph))
    dt = np.abs(t[:, None] - t[None, :])
    L = np.linalg.cholesky(sum(sd ** 2 * np.exp(-dt / tau) for sd, tau in comps) + 1e-9 * np.eye(t.size))
    Rs = []
    for _ in range(600):
        ex, ey = L @ rng.normal(size=t.size), L @ rng.normal(size=t.size)
        Rs.append(T.fit_circle(x + ex, y + ey)[0][2])
    sd_mc = float(np.std(Rs, ddof=1))
    assert sd_pred == pytest.approx(sd_mc, rel=0.12)
    assert sd_pred > 0.2  # far above the white-noise-only value a residual-based SE would give


def test_noise_sigma_pools_chunk_residuals_of_a_cubic():
    """noise_sigma: consecutive 12-sample chunks (a short tail folded into the last), a cubic fitted to
    each, residual variances pooled over Σ(m − 4) dof, chunks above 10× the median variance dropped.
    Checked against a chunk-by-chunk least-squares reference on an uneven 1-Hz-ish record with a
    wild point, and for recovering a known white σ under a smooth track."""
    rng = np.random.default_rng(3)
    n = 12 * 40 + 4                                    # 40 whole chunks and a 4-sample tail
    t = np.cumsum(rng.uniform(0.6, 1.4, n))
    y = 400.0 * np.sin(t / 90.0) + rng.normal(0.0, 0.3, n)
    y[200] += 40.0                                     # a wild point: its chunk is left out
    var, dof = [], []
    for i0 in range(0, n - 5, 12):                     # reference: the chunks one at a time
        i1 = n if n - (i0 + 12) < 6 else i0 + 12
        tt = t[i0:i1]
        A = np.vander((tt - tt.mean()) / np.ptp(tt), 4)
        r = y[i0:i1] - A @ np.linalg.lstsq(A, y[i0:i1], rcond=None)[0]
        var.append(r @ r / (len(tt) - 4))
        dof.append(len(tt) - 4)
        if i1 == n:
            break
    var, dof = np.array(var), np.array(dof)
    assert dof.sum() == 8 * 39 + 12                    # the tail made the last chunk 16 samples long
    keep = var <= 10 * np.median(var)
    assert np.count_nonzero(~keep) == 1
    s, d = T.noise_sigma(t, y)
    assert d == int(dof[keep].sum())
    assert s == pytest.approx(math.sqrt((var[keep] * dof[keep]).sum() / dof[keep].sum()), rel=1e-10)
    assert s == pytest.approx(0.3, rel=0.1)            # 350 dof: 2σ of the estimate is 7.6 %
