"""Response spectra and transfer functions on synthetic records with analytically known answers.

References: a discrete linear filter's exact frequency response (scipy.signal.freqz of the same
coefficients) and exact output variance (Σ h_n² of its impulse response); Percival & Walden's (1993)
closed form for the degrees of freedom of a Hann/50 % Welch estimate.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import signal

from vtrials.errors import InputError
from vtrials.reduce.spectra import response_spectrum, variance_estimate, welch_dof
from vtrials.reduce.transfer import transfer_function

FS = 4.0  # [Hz]
T_RUN = 1500.0  # 25-min run [s]


def _system(wn=1.0, zeta=0.2):
    """A 2nd-order oscillator H(s) = wn²/(s² + 2ζ wn s + wn²), discretized (bilinear, prewarped at wn)."""
    wd = wn * math.sqrt(1.0 - zeta ** 2)
    z, p, k = signal.bilinear_zpk([], [complex(-zeta * wn, wd), complex(-zeta * wn, -wd)], wn ** 2, FS)
    b, a = signal.zpk2tf(z, p, k)
    return b.real, a.real


def test_welch_dof_matches_percival_walden():
    # Hann, 50 % overlap: ν = 36 K²/(19 K − 1) (Percival & Walden 1993, eq. 292c)
    for n_seg in (5, 11, 22):
        nperseg = 256
        n = nperseg + (n_seg - 1) * 128
        nu, K = welch_dof(n, nperseg)
        assert K == n_seg
        assert nu == pytest.approx(36.0 * K * K / (19.0 * K - 1.0), rel=2e-3)


def test_spectrum_and_m0_interval_coverage():
    b, a = _system(wn=1.2, zeta=0.15)
    imp = signal.lfilter(b, a, np.r_[1.0, np.zeros(20000)])
    m0_true = float(np.sum(imp ** 2))  # unit white noise in → exact output variance
    n = int(T_RUN * FS)
    rng = np.random.default_rng(1)
    covered = 0
    reps = 200
    S_mean = 0.0
    for r in range(reps):
        x = signal.lfilter(b, a, rng.standard_normal(n + 2000))[2000:]
        est = variance_estimate(x, FS, 512)
        lo, hi = est.m0_interval(0.95)
        covered += lo <= m0_true <= hi
        if r < 40:
            S_mean = S_mean + response_spectrum(x, FS, 512).S / 40
    w = response_spectrum(x, FS, 512).omega
    # exact spectrum of filtered unit white noise: |H(e^{iωΔt})|² / (π fs) per rad/s (one-sided)
    _, Hw = signal.freqz(b, a, worN=w / FS)
    S_true = np.abs(Hw) ** 2 / (math.pi * FS)
    band = (S_true > 0.05 * S_true.max()) & (w > 0.05)  # the ω = 0 bin is detrended away
    err = np.abs(S_mean[band] / S_true[band] - 1.0)
    assert np.max(err) < 0.12, np.max(err)
    print(f"m0 95 % interval coverage {covered / reps:.3f}; Welch spectrum max error {np.max(err):.3f}")
    assert 0.90 <= covered / reps <= 0.99, covered / reps


def test_transfer_function_within_10pc_and_intervals_cover():
    b, a = _system(wn=1.0, zeta=0.2)
    n = int(T_RUN * FS)
    rng = np.random.default_rng(7)
    amp_cov, ph_cov, nbins, errs = 0, 0, 0, []
    for r in range(60):
        # broadband input (a wave-like band), output with measurement noise
        x = signal.lfilter(*signal.butter(2, 0.4, fs=FS), rng.standard_normal(n))
        y = signal.lfilter(b, a, x) + 0.2 * np.std(x) * rng.standard_normal(n)
        tf = transfer_function(x, y, FS, 512)
        _, Ht = signal.freqz(b, a, worN=tf.omega / FS)
        use = (tf.coherence > 0.8) & (tf.omega > 0.1) & (tf.omega < 2.0)  # the band the input excites
        errs.append(np.abs(tf.amplitude[use] / np.abs(Ht[use]) - 1.0))
        ca, cp = tf.covers(Ht)
        amp_cov += int(np.sum(ca[use]))
        ph_cov += int(np.sum(cp[use]))
        nbins += int(np.sum(use))
    assert nbins > 1000
    errs = np.concatenate(errs)
    # 25 min, 512-sample segments (n_d ≈ 22; Δω = 0.05 rad/s, an eighth of the resonance's half-power
    # width, so the resolution bias stays below the random error — with 256 samples it does not and the
    # intervals under-cover near the peak): where γ² > 0.8, |H| within 10 % of the truth in ≥ 90 % of bins
    print(f"H1: {np.mean(errs < 0.10):.3f} of bins within 10 %, median error {np.median(errs):.4f}, "
          f"coverage amplitude {amp_cov / nbins:.3f} phase {ph_cov / nbins:.3f} over {nbins} bins")
    assert np.mean(errs < 0.10) >= 0.90, np.mean(errs < 0.10)
    assert np.median(errs) < 0.03, np.median(errs)
    assert 0.91 <= amp_cov / nbins <= 0.98, amp_cov / nbins
    assert 0.91 <= ph_cov / nbins <= 0.98, ph_cov / nbins


def test_bad_input_names_the_field():
    with pytest.raises(InputError, match="nperseg"):
        response_spectrum(np.zeros(100), 2.0, 1000)
    with pytest.raises(InputError, match="fs"):
        response_spectrum(np.zeros(100), -1.0, 32)
