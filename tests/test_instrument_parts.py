"""Error-model parts of virtual instruments: statistics, streaming invariance, reproducibility.

Tolerances come from sampling theory; the formula is stated next to each check. "k sigma" bounds use
k = 4 or 5 (two-sided false-alarm probability ~6e-5 / ~6e-7 per check); the seeds are fixed, so the
tests are deterministic, and the bounds say the seeds are not cherry-picked.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from scipy import stats

from vtrials.instruments.parts import (AverageBetweenUpdates, Bias, Chain, ClockOffset, Dropouts, GaussMarkov,
                                       IrregularUpdates, Latency, Misalignment, Part, Quantization, RandomWalk,
                                       Resample, Resolution, SampleHold, Saturation, ScaleFactor, WhiteNoise,
                                       WindowAverage)


# --------------------------------------------------------------------------------------------------
# helpers
# --------------------------------------------------------------------------------------------------

def run(part: Part, t, x, seed=0, cuts=None):
    """Reset with ``seed`` and feed (t, x) whole (cuts=None) or split at the indices ``cuts``."""
    part.reset(np.random.default_rng(seed))
    if cuts is None:
        return part.process(t, x)
    outs = [part.process(t[a:b], x[a:b]) for a, b in zip(cuts[:-1], cuts[1:])]
    return np.concatenate([o[0] for o in outs]), np.concatenate([o[1] for o in outs])


def random_cuts(n, rng, k=300):
    """Chunk boundaries with empty chunks (repeated cuts) and one-sample chunks."""
    c = np.sort(np.r_[0, 1, 2, rng.integers(0, n + 1, k), n - 1, n, n])
    c[k // 2] = c[k // 2 + 1]          # an extra empty chunk in the middle
    return c


def irregular_times(n, lo, hi, seed, t0=0.0):
    return t0 + np.cumsum(np.random.default_rng(seed).uniform(lo, hi, n))


def kabsch(a, b):
    """Least-squares rotation R with b_i ≈ R a_i (rows)."""
    u, _, vt = np.linalg.svd(a.T @ b)
    d = np.sign(np.linalg.det(vt.T @ u.T))
    return vt.T @ np.diag([1.0, 1.0, d]) @ u.T


def rotvec(R):
    """Rotation vector of R (log map)."""
    th = math.acos(max(-1.0, min(1.0, (np.trace(R) - 1.0) / 2.0)))
    w = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]]) / 2.0
    return w if th == 0 else w * th / math.sin(th)


def check_normal_draws(values, mean, sd, k=5.0):
    """Sample mean and sd of M iid N(mean, sd²) draws: SE(mean) = sd/√M, SE(s)/sd ≈ 1/√(2(M−1))."""
    v = np.asarray(values, dtype=float)
    m = v.shape[0]
    assert np.all(np.abs(v.mean(axis=0) - mean) < k * np.asarray(sd) / math.sqrt(m))
    assert np.all(np.abs(v.std(axis=0, ddof=1) / sd - 1.0) < k / math.sqrt(2 * (m - 1)))


def bartlett_sd_ar1(phi, h, n):
    """SD of the lag-h sample autocorrelation of an AR(1) with coefficient phi (Bartlett's formula,
    Box & Jenkins): var r_h ≈ [(1+φ²)(1−φ^{2h})/(1−φ²) − 2hφ^{2h}] / n."""
    return math.sqrt(((1 + phi**2) * (1 - phi ** (2 * h)) / (1 - phi**2) - 2 * h * phi ** (2 * h)) / n)


# --------------------------------------------------------------------------------------------------
# streaming invariance and reproducibility (every part)
# --------------------------------------------------------------------------------------------------

def _scalar_input():
    t = irregular_times(30_000, 0.05, 0.15, seed=11, t0=3.7)
    x = 2.0 + np.sin(0.05 * t) + 0.3 * np.sin(0.7 * t)
    return t, x


def _vector_input():
    t, x = _scalar_input()
    return t, np.c_[x, np.cos(0.03 * t), 0.1 * t]


FACTORIES = {
    "Bias": (lambda: Bias(0.1, 0.2), "s", True),
    "Bias3": (lambda: Bias([0, 1, 2], [0.1, 0.2, 0.3]), "v", True),
    "ScaleFactor": (lambda: ScaleFactor(0.02, 0.01), "s", True),
    "Misalignment3": (lambda: Misalignment(0.02), "v", True),
    "Misalignment1": (lambda: Misalignment(0.02, n_axes=1, wrap="positive"), "s", True),
    "WhiteNoise": (lambda: WhiteNoise(0.1), "s", True),
    "WhiteNoise3": (lambda: WhiteNoise(density=0.01, interval=0.1, n_axes=3), "v", True),
    "GaussMarkov": (lambda: GaussMarkov(5.0, 1.0), "s", True),
    "GaussMarkov3": (lambda: GaussMarkov([1.0, 5.0, 50.0], 1.0), "v", True),
    "RandomWalk": (lambda: RandomWalk(0.1), "s", True),
    "RandomWalk3": (lambda: RandomWalk(0.1, n_axes=3), "v", True),
    "Quantization": (lambda: Quantization(0.01), "s", False),
    "QuantizationFloor": (lambda: Resolution(0.05, mode="floor"), "v", False),
    "Saturation": (lambda: Saturation(1.5, 2.5), "s", False),
    "Latency": (lambda: Latency(0.37), "s", False),
    "ClockOffset": (lambda: ClockOffset(0.5, 0.1, 50.0), "s", True),
    "Resample": (lambda: Resample(1.3), "s", True),
    "ResamplePrev3": (lambda: Resample(7.0, method="previous"), "v", True),
    "SampleHold": (lambda: SampleHold(10.0, rate=1.0), "s", True),
    "SampleHoldLin": (lambda: SampleHold(7.5, method="linear"), "v", True),
    "IrregularUpdates": (lambda: IrregularUpdates(15.0, 60.0, method="linear"), "s", True),
    "AverageBetweenUpdates": (lambda: AverageBetweenUpdates(15.0, 60.0), "v", True),
    "WindowAverage": (lambda: WindowAverage(10.0, period=20.0), "s", True),
    "WindowAverageContig": (lambda: WindowAverage(3.0, output="integral"), "v", True),
    "WindowCount": (lambda: WindowAverage(10.0, period=20.0, output="count", pulses_per_unit=3.3), "s", True),
    "Dropouts": (lambda: Dropouts(0.1, 0.02, 4.0), "s", True),
}


def _input(kind):
    return _scalar_input() if kind == "s" else _vector_input()


@pytest.mark.parametrize("name", list(FACTORIES))
def test_streaming_invariance(name):
    """Whole series vs random chunking (empty and one-sample chunks too): bitwise identical output."""
    make, kind, _ = FACTORIES[name]
    t, x = _input(kind)
    part = make()
    ta, xa = run(part, t, x, seed=5)
    for s in (1, 2):
        tb, xb = run(part, t, x, seed=5, cuts=random_cuts(t.size, np.random.default_rng(s)))
        assert ta.shape[0] > 10 and xa.shape[1:] == x.shape[1:]
        assert np.array_equal(ta, tb) and np.array_equal(xa, xb)
        assert np.all(np.diff(ta) > 0)


@pytest.mark.parametrize("name", list(FACTORIES))
def test_reproducibility(name):
    """Same seed → identical (also when the part object is reused); other seed → different if random."""
    make, kind, is_random = FACTORIES[name]
    t, x = _input(kind)
    part = make()
    ta, xa = run(part, t, x, seed=1)
    d1 = part.drawn()
    tb, xb = run(make(), t, x, seed=1)
    tc, xc = run(part, t, x, seed=1)
    assert np.array_equal(ta, tb) and np.array_equal(xa, xb)
    assert np.array_equal(ta, tc) and np.array_equal(xa, xc) and part.drawn() == d1
    td, xd = run(part, t, x, seed=2)
    same = ta.shape == td.shape and np.array_equal(ta, td) and np.array_equal(xa, xd)
    assert same != is_random
    json.dumps(d1)      # the truth file can store drawn() as is


# --------------------------------------------------------------------------------------------------
# value errors
# --------------------------------------------------------------------------------------------------

def test_bias_draws_and_constancy():
    mean, sd, m = np.array([1.0, -2.0, 0.5]), np.array([0.1, 0.2, 0.3]), 2000
    t = np.arange(50) * 0.1
    x = np.random.default_rng(0).normal(size=(50, 3)) * 100.0
    b = np.empty((m, 3))
    part = Bias(mean, sd)
    for i in range(m):
        _, y = run(part, t, x, seed=i)
        b[i] = np.asarray(part.drawn()["bias"])
        # constant within the run and equal to the reported draw (up to rounding of x + b − x)
        assert np.allclose(y - x, b[i], rtol=0, atol=1e-12)
    check_normal_draws(b, mean, sd)
    # axes independent: sample correlation of independent pairs has SE 1/√M
    c = np.corrcoef(b.T)
    assert np.all(np.abs(c[np.triu_indices(3, 1)]) < 5 / math.sqrt(m))


def test_bias_needs_axes_for_vectors():
    p = Bias(0.0, 1.0)
    p.reset(np.random.default_rng(0))
    with pytest.raises(ValueError, match="n_axes"):
        p.process([0.0, 1.0], np.zeros((2, 3)))


def test_scale_factor_draws():
    mean, sd, m = 0.02, 0.005, 2000
    t = np.arange(20) * 1.0
    x = np.linspace(-5.0, 5.0, 20) + 0.01
    s = np.empty(m)
    part = ScaleFactor(mean, sd)
    for i in range(m):
        _, y = run(part, t, x, seed=i)
        s[i] = part.drawn()["scale_factor_error"]
        assert np.allclose(y / x - 1.0, s[i], rtol=0, atol=1e-12)
    check_normal_draws(s, mean, sd)


def test_misalignment_3d_is_rotation_with_stated_angles():
    sd, m = math.radians(1.0), 1000
    rng = np.random.default_rng(3)
    t = np.arange(40) * 0.05
    part = Misalignment(sd)
    angles = np.empty((m, 3))
    for i in range(m):
        x = rng.normal(size=(40, 3)) * 9.81
        _, y = run(part, t, x, seed=i)
        R = kabsch(x, y)                               # recovered from the data, not from drawn()
        assert np.allclose(np.linalg.norm(y, axis=1), np.linalg.norm(x, axis=1), rtol=1e-13)
        assert np.allclose(R @ R.T, np.eye(3), atol=1e-12) and abs(np.linalg.det(R) - 1) < 1e-12
        assert np.allclose(y, x @ R.T, atol=1e-10)     # exactly a rotation: residual at rounding level
        assert np.allclose(R, np.asarray(part.drawn()["matrix"]), atol=1e-12)
        angles[i] = rotvec(R)
        assert np.allclose(angles[i], part.drawn()["angles_rad"], atol=1e-12)
    check_normal_draws(angles, 0.0, sd)


def test_misalignment_planar_and_heading():
    sd, m = math.radians(1.0), 1000
    t = np.arange(10) * 1.0
    x2 = np.c_[np.full(10, 5.0), np.linspace(-1, 1, 10)]
    hd = np.linspace(-math.pi, math.pi - 1e-3, 10)    # heading crossing the wrap point
    a2, a1 = np.empty(m), np.empty(m)
    p2, p1 = Misalignment(sd, n_axes=2), Misalignment(sd, n_axes=1, wrap="signed")
    for i in range(m):
        _, y2 = run(p2, t, x2, seed=i)
        a2[i] = np.mean(np.arctan2(y2[:, 1], y2[:, 0]) - np.arctan2(x2[:, 1], x2[:, 0]))
        assert np.allclose(np.hypot(*y2.T), np.hypot(*x2.T), rtol=1e-13)
        _, y1 = run(p1, t, hd, seed=i + m)
        assert np.all((y1 >= -math.pi) & (y1 < math.pi))
        d = np.mod(y1 - hd + math.pi, 2 * math.pi) - math.pi   # offset modulo 2π
        assert np.ptp(d) < 1e-12
        a1[i] = d[0]
        assert abs(a1[i] - p1.drawn()["angles_rad"][0]) < 1e-12
    check_normal_draws(a2, 0.0, sd)
    check_normal_draws(a1, 0.0, sd)


def test_white_noise_statistics():
    n, sd = 1_000_000, 0.3
    t = np.arange(n) * 0.02
    _, y = run(WhiteNoise(sd), t, np.zeros(n), seed=4)
    # mean: SE sd/√n; variance: SE(s²)/σ² = √(2/n); lag-1 autocorrelation of white noise: SE 1/√n
    assert abs(y.mean()) < 5 * sd / math.sqrt(n)
    assert abs(y.var() / sd**2 - 1) < 5 * math.sqrt(2 / n)
    r1 = np.dot(y[1:], y[:-1]) / np.dot(y, y)
    assert abs(r1) < 5 / math.sqrt(n)
    assert stats.kstest(y / sd, "norm").pvalue > 1e-4
    # density form: sd = N_d / √interval, per axis, axes uncorrelated
    nd, dt = 0.004, 0.01
    _, y3 = run(WhiteNoise(density=nd, interval=dt, n_axes=3), t[:200_000], np.zeros((200_000, 3)), seed=5)
    assert np.all(np.abs(y3.var(axis=0) / (nd**2 / dt) - 1) < 5 * math.sqrt(2 / 200_000))
    c = np.corrcoef(y3.T)[np.triu_indices(3, 1)]
    assert np.all(np.abs(c) < 5 / math.sqrt(200_000))


def test_gauss_markov_regular_sampling():
    tau, sigma, dt, n = 2.0, 1.5, 0.05, 800_000
    t = np.arange(n) * dt
    part = GaussMarkov(tau, sigma)
    _, e = run(part, t, np.zeros(n), seed=7)
    assert part.drawn()["initial"] == e[0]
    phi = math.exp(-dt / tau)
    # variance of s² for an AR(1): 2σ⁴/n · (1+φ²)/(1−φ²)
    assert abs(e.var() / sigma**2 - 1) < 4 * math.sqrt(2 / n * (1 + phi**2) / (1 - phi**2))
    # ACF at lags τ/4, τ/2, τ, 2τ, 3τ → exp(−L/τ), Bartlett SE
    for mult in (0.25, 0.5, 1.0, 2.0, 3.0):
        h = int(round(mult * tau / dt))
        r = np.dot(e[h:], e[:-h]) / np.dot(e, e)
        assert abs(r - math.exp(-h * dt / tau)) < 4 * bartlett_sd_ar1(phi, h, n), mult


def test_gauss_markov_irregular_sampling():
    tau, sigma, n = 2.0, 1.5, 600_000
    t = irregular_times(n, 0.001, 0.1, seed=8)        # Δ spans 0.0005τ … 0.05τ
    _, e = run(GaussMarkov(tau, sigma), t, np.zeros(n), seed=9)
    # exact discretisation ⇒ normalised innovations z are iid N(0, 1): var SE √(2/n), lag-1 SE 1/√n
    a = np.exp(-np.diff(t) / tau)
    z = (e[1:] - a * e[:-1]) / (sigma * np.sqrt(1 - a**2))
    assert abs(z.var() - 1) < 5 * math.sqrt(2 / z.size)
    assert abs(np.dot(z[1:], z[:-1]) / np.dot(z, z)) < 5 / math.sqrt(z.size)
    assert stats.kstest(z, "norm").pvalue > 1e-4
    # correlation at irregular separations ≈ exp(−s/τ): pair every sample with the first one at least
    # L later; compare mean(e_i e_j)/σ² with mean(exp(−(t_j − t_i)/τ)).
    dbar = float(np.mean(np.diff(t)))
    for L in (0.5 * tau, tau, 2 * tau):
        j = np.searchsorted(t, t + L)
        ok = j < n
        i, j = np.nonzero(ok)[0], j[ok]
        est = np.mean(e[i] * e[j]) / sigma**2
        ref = np.mean(np.exp(-(t[j] - t[i]) / tau))
        # SE of a lag-h autocovariance estimate with known mean and σ (Bartlett): var ĉ_h/σ⁴ ≈
        # (1/n)Σ_m (ρ_m² + ρ_{m+h}ρ_{m−h}) = (1/n)[(1+φ²)/(1−φ²) + (2h+1)φ^{2h} + 2φ^{2h+2}/(1−φ²)],
        # evaluated for the regular series with the same mean step (φ = e^{−Δ̄/τ}, h = L/Δ̄)
        phi, h = math.exp(-dbar / tau), L / dbar
        se = math.sqrt(((1 + phi**2) / (1 - phi**2) + (2 * h + 1) * phi ** (2 * h)
                        + 2 * phi ** (2 * h + 2) / (1 - phi**2)) / i.size)
        assert abs(est - ref) < 4 * se, (L, est, ref, se)


def test_gauss_markov_stationary_from_first_sample():
    """4000 independent axes: at each time the cross-axis variance is σ² (SE σ²√(2/M)), and the
    correlation between t = 0 and t = τ is e⁻¹ (SE of a sample correlation ≈ (1−ρ²)/√M)."""
    tau, sigma, m = 3.0, 0.7, 4000
    t = np.array([0.0, 0.1, 0.3, 1.0, 3.0, 15.0])
    _, e = run(GaussMarkov(tau, sigma, n_axes=m), t, np.zeros((t.size, m)), seed=10)
    v = (e**2).mean(axis=1)                 # known mean 0
    assert np.all(np.abs(v / sigma**2 - 1) < 5 * math.sqrt(2 / m))
    rho = math.exp(-1.0)
    r = np.corrcoef(e[0], e[4])[0, 1]
    assert abs(r - rho) < 5 * (1 - rho**2) / math.sqrt(m)


def test_random_walk_variance_grows_linearly():
    q, dt, n, m = 0.3, 0.1, 10_000, 200
    t = np.arange(n) * dt
    x = np.zeros((n, m))
    _, r = run(RandomWalk(q, n_axes=m), t, x, seed=12)
    assert np.all(r[0] == 0.0)              # starts at zero at the first sample
    # non-overlapping increments over lag L: var = q² L, SE(s²)/var = √(2/n_inc)
    for lag in (1, 10, 100, 1000):
        inc = (r[lag::lag] - r[:-lag:lag]).ravel()
        assert abs(np.mean(inc**2) / (q**2 * lag * dt) - 1) < 5 * math.sqrt(2 / inc.size), lag
    # irregular sampling: increments normalised by q√Δ are N(0, 1)
    ti = irregular_times(200_000, 0.001, 0.5, seed=13)
    _, ri = run(RandomWalk(q), ti, np.zeros(ti.size), seed=14)
    z = np.diff(ri) / (q * np.sqrt(np.diff(ti)))
    assert abs(z.var() - 1) < 5 * math.sqrt(2 / z.size)


def test_quantization_grid_and_uniform_error():
    q, n = 0.01, 400_000
    t = np.arange(n) * 0.05
    # (a) slowly varying, monotone input crossing ~2750 steps: the error is a densely sampled sawtooth,
    # equidistributed on [−q/2, q/2] (closer to uniform than an iid sample, so iid bounds are conservative)
    # (b) iid input spread over many steps: iid uniform errors, the bounds are exact sampling theory
    slow = 0.0013771 * t + 0.05 * np.sin(0.01 * t)
    wide = np.random.default_rng(16).uniform(-3.0, 7.0, n)
    for x in (slow, wide):
        _, y = run(Quantization(q), t, x)
        k = y / q
        assert np.all(np.abs(k - np.round(k)) < 1e-9)       # multiples of the step
        err = y - x
        assert np.all(np.abs(err) <= q / 2 + 1e-12)
        # U(−q/2, q/2): mean 0 (SE q/√(12n)); var q²/12 with SE q²/√(180 n) (E[e⁴] = q⁴/80)
        assert abs(err.mean()) < 5 * q / math.sqrt(12 * n)
        assert abs(err.var() - q**2 / 12) < 5 * q**2 / math.sqrt(180 * n)
        assert stats.kstest(err / q, "uniform", args=(-0.5, 1.0)).pvalue > 1e-3
        _, yf = run(Resolution(q, mode="floor"), t, x)
        ef = yf - x                                          # floor: U(−q, 0], mean −q/2
        assert np.all((ef <= 1e-12) & (ef > -q - 1e-12))
        assert abs(ef.mean() + q / 2) < 5 * q / math.sqrt(12 * n)
    xs = np.linspace(-1, 1, 1001)
    _, yt = run(Quantization(0.3, mode="trunc"), np.arange(1001.0), xs)
    assert np.all(np.abs(yt) <= np.abs(xs) + 1e-12)


def test_saturation():
    t = np.arange(1000) * 0.1
    x = 3 * np.sin(0.2 * t)
    _, y = run(Saturation(-1.0, 2.0), t, x)
    inside = (x > -1) & (x < 2)
    assert np.array_equal(y[inside], x[inside])
    assert np.all(y[x >= 2] == 2.0) and np.all(y[x <= -1] == -1.0)


# --------------------------------------------------------------------------------------------------
# time-stamp errors
# --------------------------------------------------------------------------------------------------

def test_latency_cross_correlation_peak():
    delay, dt, n = 0.37, 0.01, 60_000
    rng = np.random.default_rng(15)
    t = np.arange(n) * dt
    f = rng.uniform(0.05, 1.0, 25)
    ph = rng.uniform(0, 2 * np.pi, 25)
    x = np.sin(2 * np.pi * f[None, :] * t[:, None] + ph).sum(axis=1)
    to, xo = run(Latency(delay), t, x)
    assert np.allclose(to - t, delay, atol=1e-9) and np.array_equal(xo, x)
    # the reading seen on the simulation's time grid is the input delayed; locate the cross-correlation
    # peak and refine it with a parabola: the delay is recovered to a small fraction of dt
    y = np.interp(t, to, xo)
    lags = np.arange(0, 80)
    cc = np.array([np.dot(y[100 + k:], x[100:n - k]) for k in lags])
    k = int(np.argmax(cc))
    frac = 0.5 * (cc[k - 1] - cc[k + 1]) / (cc[k - 1] - 2 * cc[k] + cc[k + 1])
    assert abs((k + frac) * dt - delay) < 0.1 * dt


def test_clock_offset_shifts_stamps_only():
    sd, dsd, m = 0.5, 40.0, 1500
    t = np.linspace(0.0, 3600.0, 50)
    x = np.random.default_rng(0).normal(size=50)
    part = ClockOffset(sd, mean=0.2, drift_ppm_sd=dsd, drift_ppm_mean=-10.0, t_ref=100.0)
    off, drift = np.empty(m), np.empty(m)
    for i in range(m):
        to, xo = run(part, t, x, seed=i)
        assert np.array_equal(xo, x)
        slope, icpt = np.polyfit(t - 100.0, to - t, 1)   # shift = c + d (t − t_ref)
        off[i], drift[i] = icpt, slope * 1e6
        d = part.drawn()
        assert abs(off[i] - d["offset_s"]) < 1e-9 and abs(drift[i] - d["drift_ppm"]) < 1e-4
    check_normal_draws(off, 0.2, sd)
    check_normal_draws(drift, -10.0, dsd)


# --------------------------------------------------------------------------------------------------
# sampling stages
# --------------------------------------------------------------------------------------------------

def test_resample_clock_phase_and_interpolation():
    rate, dt = 2.0, 0.02
    t = np.arange(0, 500, dt) + 0.013
    x = 3.0 * t - 1.0
    phases = []
    for seed in range(400):
        part = Resample(rate)
        to, xo = run(part, t, x, seed=seed)
        ph = part.drawn()["phase_s"]
        phases.append(ph)
        assert np.allclose(np.diff(to), 1 / rate, atol=1e-9)
        assert np.allclose(np.mod(to - ph + 0.25 / rate, 1 / rate), 0.25 / rate, atol=1e-9)
        assert to[0] >= t[0] and to[0] - t[0] < 1 / rate and to[-1] < t[-1]
        assert np.allclose(xo, 3.0 * to - 1.0, atol=1e-9)   # linear input: interpolation exact
    # phase ~ U(0, 1/rate): KS
    assert stats.kstest(np.array(phases) * rate, "uniform").pvalue > 1e-3
    # a sine: interpolation error ≤ A ω² dt² / 8
    A, w = 2.0, 1.3
    to, xo = run(Resample(rate, phase=0.1234), t, A * np.sin(w * t))
    assert np.max(np.abs(xo - A * np.sin(w * to))) <= A * w**2 * dt**2 / 8 + 1e-12
    # "previous": the latest input sample at or before the instant
    to, xo = run(Resample(rate, method="previous"), t, x)
    tin = (xo + 1.0) / 3.0
    assert np.all((to - tin >= -1e-9) & (to - tin < dt + 1e-9))


def test_sample_hold_updates_and_display_rate():
    dt, period = 0.02, 10.0
    t = np.arange(0, 2000, dt)
    part = SampleHold(period, rate=1.0, method="linear")
    to, xo = run(part, t, t.copy(), seed=3)                 # input = time: held value = update instant
    d = part.drawn()
    assert np.allclose(np.diff(to), 1.0, atol=1e-9)
    assert np.allclose(np.mod(to - d["out_phase_s"] + 0.5, 1.0), 0.5, atol=1e-9)
    upd = np.unique(xo)
    assert np.allclose(np.diff(upd), period, atol=1e-9)     # update intervals equal T
    assert np.allclose(np.mod(upd - d["phase_s"] + 1.0, period), 1.0, atol=1e-9)
    age = to - xo                                            # the latest update at or before each read
    assert np.all((age >= -1e-9) & (age < period))
    assert upd.size == pytest.approx(2000 / period, abs=1)
    # method "previous": the held value is the input sample at or before the update instant
    part = SampleHold(period, phase=4.321, method="previous")
    uo, ux = run(part, t, t.copy())
    assert np.allclose(uo, 4.321 + period * np.arange(uo.size), atol=1e-9)
    assert np.all((uo - ux >= -1e-9) & (uo - ux < dt))


def test_irregular_updates_intervals_uniform():
    a, b, dt = 15.0, 60.0, 0.1
    t = np.arange(0, 200_000, dt)
    to, xo = run(IrregularUpdates(a, b, method="linear"), t, t.copy(), seed=21)
    d = np.diff(to)
    assert np.all((d >= a - 1e-9) & (d <= b + 1e-9))
    assert d.size > 5000
    assert stats.kstest(d, "uniform", args=(a, b - a)).pvalue > 1e-3
    assert np.allclose(xo, to, atol=1e-8)                  # held value = input at the update instant
    to, xo = run(IrregularUpdates(a, b), t, t.copy(), seed=22)
    assert np.all((to - xo >= -1e-9) & (to - xo < dt))       # "previous": sample at/before the update


def test_irregular_updates_first_wait_is_stationary():
    """First update after the record starts follows the equilibrium forward-recurrence law
    G(s) = (1/m)∫₀ˢ (1 − F(u)) du (Cox 1962), computed here by numerical integration."""
    a, b = 15.0, 60.0
    t = np.arange(0.0, 70.0, 0.5) + 1000.0
    part = IrregularUpdates(a, b, method="linear")
    waits = np.array([run(part, t, t.copy(), seed=s)[0][0] - t[0] for s in range(2000)])
    grid = np.linspace(0, b, 6001)
    surv = 1 - np.clip((grid - a) / (b - a), 0, 1)
    G = np.concatenate([[0], np.cumsum(0.5 * (surv[1:] + surv[:-1]) * np.diff(grid))]) / (0.5 * (a + b))
    assert stats.kstest(waits, lambda s: np.interp(s, grid, G)).pvalue > 1e-3
    # mean forward recurrence E[Δ²]/(2E[Δ]) = (a² + ab + b²)/(3(a + b)) = 21 s
    assert abs(waits.mean() - (a * a + a * b + b * b) / (3 * (a + b))) < 5 * waits.std() / math.sqrt(waits.size)


def test_average_between_updates():
    a, b, dt = 15.0, 60.0, 0.05
    t = np.arange(0, 20_000, dt)
    to, xo = run(AverageBetweenUpdates(a, b), t, 0.5 * t + 2.0, seed=31)
    assert np.all((np.diff(to) >= a - 1e-9) & (np.diff(to) <= b + 1e-9))
    # ramp: the mean over [u_{j−1}, u_j] is the value at the midpoint (trapezoids exact)
    assert np.allclose(xo[1:], 0.5 * (0.5 * (to[1:] + to[:-1])) + 2.0, atol=1e-9)
    # a sine: mean = A (cos ωu₀ − cos ωu₁)/(ω(u₁ − u₀)); error of the linear interpolant ≤ A ω² dt²/8
    A, w = 1.5, 0.2
    to, xo = run(AverageBetweenUpdates(a, b), t, A * np.sin(w * t), seed=31)
    exact = A * (np.cos(w * to[:-1]) - np.cos(w * to[1:])) / (w * np.diff(to))
    assert np.max(np.abs(xo[1:] - exact)) <= A * w**2 * dt**2 / 8 + 1e-12


def test_window_average_duty_cycle_and_means():
    dt, window, period, phase = 0.02, 10.0, 20.0, 3.0
    t = np.arange(0, 4000, dt) + 0.007
    to, xo = run(WindowAverage(window, period=period, phase=phase), t, 2.0 * t)
    assert np.allclose(to, phase + window + period * np.arange(to.size), atol=1e-9)   # 10 s of every 20 s
    assert np.allclose(xo, 2.0 * (to - window / 2), atol=1e-9)     # ramp mean over [e − 10, e]
    _, xi = run(WindowAverage(window, period=period, phase=phase, output="integral"), t, 2.0 * t)
    assert np.allclose(xi, window * xo, rtol=1e-12)
    # sine: exact window mean; linear-interpolant error ≤ A ω² dt²/8
    A, w = 2.0, 0.9
    to, xs = run(WindowAverage(window, period=period, phase=phase), t, A * np.sin(w * t))
    exact = A * (np.cos(w * (to - window)) - np.cos(w * to)) / (w * window)
    assert np.max(np.abs(xs - exact)) <= A * w**2 * dt**2 / 8 + 1e-12
    # the gap is not counted: a signal that is 1 only in the gaps averages to 0 in the windows and a
    # signal that is 1 only in the windows to 1, up to the two edge samples (≤ dt/T)
    in_window = np.mod(t - phase, period) < window
    _, g = run(WindowAverage(window, period=period, phase=phase), t, (~in_window).astype(float))
    _, h = run(WindowAverage(window, period=period, phase=phase), t, in_window.astype(float))
    assert np.max(np.abs(g)) <= dt / window and np.max(np.abs(h - 1)) <= dt / window
    # back-to-back windows (period = window)
    to, xo = run(WindowAverage(5.0, phase=1.0), t, 2.0 * t)
    assert np.allclose(np.diff(to), 5.0, atol=1e-9) and np.allclose(xo, 2.0 * (to - 2.5), atol=1e-9)


def test_window_count_is_unbiased_pulse_count():
    """Kenyon-style count (10 s of every 20 s): count = ⌊C(e)⌋ − ⌊C(s)⌋ with a random pulse phase, so
    it is within 1 of the expected pulse number and its mean over seeds equals it (SE ≤ 0.5/√M)."""
    dt, ppu = 0.02, 3.3                                      # pulses per metre, input a speed [m/s]
    t = np.arange(0, 2000, dt)
    v = 2.0 + 0.5 * np.sin(2 * np.pi * t / 300.0)
    part = WindowAverage(10.0, period=20.0, phase=5.0, output="count", pulses_per_unit=ppu)
    _, ref = run(WindowAverage(10.0, period=20.0, phase=5.0, output="integral"), t, v)
    expected = ppu * ref
    m = 1000
    counts = np.array([run(part, t[:5000], v[:5000], seed=s)[1] for s in range(m)])
    assert np.all(counts == np.round(counts))
    err = counts - expected[: counts.shape[1]]
    assert np.all(np.abs(err) < 1)
    assert np.all(np.abs(err.mean(axis=0)) < 5 * 0.5 / math.sqrt(m))
    _, c = run(part, t, v, seed=1)
    assert np.all(np.abs(c - expected) < 1)


# --------------------------------------------------------------------------------------------------
# dropouts
# --------------------------------------------------------------------------------------------------

def test_dropouts_bernoulli_fraction():
    p, n = 0.07, 1_000_000
    t = np.arange(n) * 0.02
    to, xo = run(Dropouts(p=p), t, t.copy(), seed=41)
    assert np.array_equal(to, xo)                            # kept samples unchanged, no NaN
    lost = 1 - to.size / n
    assert abs(lost - p) < 5 * math.sqrt(p * (1 - p) / n)    # binomial SE
    kept = np.isin(t, to).astype(float)
    r1 = np.corrcoef(kept[1:], kept[:-1])[0, 1]              # independent per sample: SE 1/√n
    assert abs(r1) < 5 / math.sqrt(n)


def test_dropouts_outages():
    rate, dmean, dt, T = 1 / 20.0, 5.0, 0.1, 200_000.0
    t = np.arange(0, T, dt)
    to, _ = run(Dropouts(outage_rate=rate, outage_mean=dmean), t, np.zeros(t.size), seed=42)
    up = 1 / rate
    frac = dmean / (up + dmean)
    # two-state Markov indicator, correlation time τc = UD/(U+D): SE of the lost fraction
    # ≈ √(2 p(1−p) τc / T)
    tc = up * dmean / (up + dmean)
    assert abs((1 - to.size / t.size) - frac) < 5 * math.sqrt(2 * frac * (1 - frac) * tc / T)
    gaps = np.diff(to)
    gaps = gaps[gaps > 1.5 * dt] - dt      # a gap of (m+1)dt hides m samples; E[m dt] = D for a random phase
    n_out = gaps.size
    # number of up/down cycles in T: mean T/(U+D), variance T(σ_U² + σ_D²)/(U+D)³ (renewal CLT, Cox 1962);
    # seen from samples dt apart, outages shorter than dt hide no sample (fraction ≈ dt/(2D)) and up
    # times shorter than dt merge two outages (fraction ≈ dt/U)
    n_exp = T / (up + dmean) * (1 - dt / (2 * dmean) - dt / up)
    assert abs(n_out - n_exp) < 5 * math.sqrt(T * (up**2 + dmean**2) / (up + dmean) ** 3)
    # exponential durations: mean D (SE D/√n), variance D² (SE D²√(8/n), as E[d⁴] = 24D⁴); the detection
    # effects above shift the mean by < dt
    assert abs(gaps.mean() - dmean) < 5 * dmean / math.sqrt(n_out) + dt
    assert abs(gaps.var() / dmean**2 - 1) < 5 * math.sqrt(8 / n_out) + 2 * dt / dmean


# --------------------------------------------------------------------------------------------------
# chains
# --------------------------------------------------------------------------------------------------

def _imu_chain():
    return Chain([Resample(20.0), Misalignment(math.radians(0.5)), ScaleFactor(0.0, 0.01, n_axes=3),
                  Bias(0.0, 0.002, n_axes=3), GaussMarkov(100.0, 0.001, n_axes=3), RandomWalk(1e-4, n_axes=3),
                  WhiteNoise(density=0.003, interval=0.05, n_axes=3), Saturation(-20.0, 20.0),
                  Quantization(1e-4), Dropouts(0.01, 1 / 300.0, 2.0), Latency(0.05), ClockOffset(0.01, 0.0, 20.0)])


def _knotmeter_chain():
    return Chain([ScaleFactor(-0.02, 0.005), WindowAverage(10.0, period=20.0, output="count", pulses_per_unit=3.3),
                  Resample(1.0, method="previous"), Latency(0.5)])


def _loran_chain():
    return Chain([AverageBetweenUpdates(15.0, 60.0), GaussMarkov(300.0, 0.1), WhiteNoise(0.05),
                  Quantization(0.05), ClockOffset(0.2)])


@pytest.mark.parametrize("make,kind", [(_imu_chain, "v"), (_knotmeter_chain, "s"), (_loran_chain, "s")])
def test_chain_streaming_and_reproducibility(make, kind):
    t, x = _input(kind)
    ch = make()
    ta, xa = run(ch, t, x, seed=99)
    d = ch.drawn()
    for s in (3, 4):
        tb, xb = run(ch, t, x, seed=99, cuts=random_cuts(t.size, np.random.default_rng(s), k=500))
        assert np.array_equal(ta, tb) and np.array_equal(xa, xb)
        assert ch.drawn() == d
    assert ta.size > 10
    tc, xc = run(ch, t, x, seed=100)
    assert not (ta.shape == tc.shape and np.array_equal(xa, xc))
    assert [p["part"] for p in d["parts"]] == [type(p).__name__ for p in ch.parts]
    json.dumps(d)


def test_chain_parts_draw_independently():
    """Two identical random parts in one chain get different draws (own child streams)."""
    ch = Chain([Bias(0.0, 1.0), Bias(0.0, 1.0)])
    vals = []
    for s in range(500):
        ch.reset(np.random.default_rng(s))
        vals.append([p["bias"] for p in ch.drawn()["parts"]])
    v = np.array(vals)
    assert np.all(v[:, 0] != v[:, 1])
    assert abs(np.corrcoef(v.T)[0, 1]) < 5 / math.sqrt(500)
    t = np.arange(5.0)
    _, y = ch.process(t, np.zeros(5))
    assert np.allclose(y, v[-1].sum())


def test_chain_order_knotmeter_reads_held_counts():
    """WindowAverage(count) → Resample(previous): the 1-Hz reading shows the last completed count."""
    t = np.arange(0, 600, 0.02)
    v = np.full(t.size, 3.0)
    ch = Chain([WindowAverage(10.0, period=20.0, phase=0.0, output="count", pulses_per_unit=2.0),
                Resample(1.0, phase=0.5, method="previous")])
    to, xo = run(ch, t, v, seed=0)
    assert np.all(np.isin(xo, [59.0, 60.0, 61.0]))          # 2 pulses/m · 3 m/s · 10 s = 60 ± 1
    assert to[0] == pytest.approx(10.5) and np.allclose(np.diff(to), 1.0)


def test_contract_errors():
    p = WhiteNoise(1.0)
    with pytest.raises(RuntimeError, match="reset"):
        p.process([0.0], [0.0])
    p.reset(np.random.default_rng(0))
    p.process([0.0, 1.0], [0.0, 0.0])
    with pytest.raises(ValueError, match="increase"):
        p.process([1.0, 2.0], [0.0, 0.0])
    with pytest.raises(ValueError):
        GaussMarkov(tau=0.0, sigma=1.0)
    with pytest.raises(ValueError):
        WindowAverage(20.0, period=10.0)
    m = Misalignment(0.1, n_axes=3)
    m.reset(np.random.default_rng(0))
    with pytest.raises(ValueError, match="per-sample shape"):
        m.process([0.0], [1.0])
