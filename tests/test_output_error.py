"""Output-error refinement (vtrials.sysid.output_error) on a synthetic case with a known answer.

Truth: the independent scipy MMG integrator tests/reference/mmg3dof.py (Y&Y 2015, KVLCC2 L7 of
docs/ships.md §1) flies a 10/10 zig-zag and a 35° turn. The "measurements" are its u, v, r and heading
every 0.5 s plus coloured noise of known size (stationary AR(1), ρ = 0.8 between samples: output-error
residuals are correlated in time, as from a smoother); the rudder and shaft speed drive the model
exactly. Starting 8 % off, LM recovers the four linear derivatives; over a small Monte Carlo the 95 %
intervals from the Jacobian with the coloured-residual correction (Newey–West sandwich, fixed-b
widening) cover the truth at about their nominal rate, while the white-residual s²(JᵀJ)⁻¹ ones,
n/n_eff ≈ 9 times too confident in variance, do not.
"""

import math

import numpy as np
import pytest

from tests.reference import mmg3dof as ref
from vtrials.errors import InputError
from vtrials.sysid import mmg, output_error as oe

P = ref.KVLCC2_L7
U0 = 0.142 * math.sqrt(ref.G * P["L"])
N_RPS = ref.self_propulsion_rps(P, U0)
SHIP = mmg.kvlcc2_l7()
TRUE = mmg.kvlcc2_hull()
DT_OUT = 0.5
SIGMA = {"u": 0.002, "v": 0.002, "r": 1e-4, "psi": math.radians(0.1)}   # noise of each channel (SI): a smoother's
RHO = 0.8        # AR(1) coefficient of the noise between output samples
Z95 = 1.959963984540054


@pytest.fixture(scope="module")
def flights():
    out = []
    for prog, t_end in ((ref.ZigZag(10, 10, 1), 70.0), (ref.TurningCircle(35), 50.0)):
        res = ref.simulate(P, U0, N_RPS, prog, t_end, rtol=1e-9, atol=1e-10)
        t_in = np.arange(0.0, t_end + 1e-9, 0.05)
        s_in = res(t_in)
        t_out = np.arange(0.0, t_end + 1e-9, DT_OUT)
        s_out = res(t_out)
        out.append((s_in[:6, 0], t_in, s_in[6], t_out, {"u": s_out[3], "v": s_out[4], "r": s_out[5],
                                                        "psi": s_out[2]}))
    return out


def _ar1(rng, n, sigma):
    e = np.empty(n)
    e[0] = rng.standard_normal()
    w = math.sqrt(1 - RHO**2)
    for k in range(1, n):
        e[k] = RHO * e[k - 1] + w * rng.standard_normal()
    return sigma * e


def _maneuvers(flights, rng):
    return [oe.Maneuver(x0, t_in, d, np.full(t_in.size, N_RPS),
                        {ch: (t_out, z + _ar1(rng, t_out.size, SIGMA[ch]), SIGMA[ch]) for ch, z in zs.items()})
            for x0, t_in, d, t_out, zs in flights]


def test_output_error_recovers_known_coefficients_with_calibrated_intervals(flights):
    start = dict(TRUE)
    for k, f in zip(mmg.LINEAR, (1.08, 0.92, 0.92, 1.08)):
        start[k] = TRUE[k] * f
    z_hac, z_white, rel = [], [], []
    for i in range(12):
        mans = _maneuvers(flights, np.random.default_rng(np.random.SeedSequence([16, i])))
        res = oe.refine(SHIP, start, mmg.LINEAR, mans, max_nfev=10, lags="auto")
        sh, sw = res.sigma(), np.sqrt(np.diag(res.cov_white))
        for j, k in enumerate(mmg.LINEAR):
            e = res.coeffs[k] - TRUE[k]
            z_hac.append(e / sh[k])
            z_white.append(e / sw[j])
            rel.append(e / TRUE[k])
    z_hac, z_white, rel = map(np.asarray, (z_hac, z_white, rel))
    cov_hac, cov_white = np.mean(np.abs(z_hac) <= Z95), np.mean(np.abs(z_white) <= Z95)
    print(f"max |rel err| {np.abs(rel).max():.4f}, rms z (HAC) {np.sqrt(np.mean(z_hac**2)):.2f}, coverage "
          f"{cov_hac:.2f}; rms z (white) {np.sqrt(np.mean(z_white**2)):.2f}, coverage {cov_white:.2f}; "
          f"lags {res.lags}, residual rms {res.rms:.2f}")
    assert np.abs(rel).max() < 0.03                  # from 8 % off to within 3 % in every replicate
    assert abs(np.mean(rel)) < 0.005                   # no bias
    assert 0.6 < np.sqrt(np.mean(z_hac**2)) < 1.4      # interval widths honest in the mean
    assert cov_hac >= 0.85
    assert cov_white < 0.70                            # without the correction: far too confident
    assert 0.8 < res.rms < 1.25                        # the residuals at the noise level in σ units


def test_fixed_b_factor():
    """The fixed-b widening against a direct Monte Carlo: the 95 % two-sided point of |t| for the mean
    of white noise (T = 200) studentised by the Bartlett HAC with the code's weights at b = 0.1 and 0.5
    (4000 series) — far above 1.96 at large b, as Kiefer & Vogelsang's cubic says."""
    assert oe.fixed_b_factor(0.0) == 1.0
    assert oe.fixed_b_factor(3.0) == oe.fixed_b_factor(1.0)
    rng = np.random.default_rng(2005)
    T = 200
    x = rng.standard_normal((4000, T))
    xm = x.mean(axis=1)
    e = x - xm[:, None]
    for b in (0.1, 0.5):
        M = int(b * T)
        lrv = np.mean(e * e, axis=1)
        for lag in range(1, M + 1):
            lrv += 2 * (1 - lag / (M + 1)) * np.mean(e[:, lag:] * e[:, :-lag], axis=1) * (T - lag) / T
        q = np.quantile(np.abs(xm / np.sqrt(lrv / T)), 0.95)
        print(f"b {b}: Monte Carlo {q:.3f}, fixed-b {1.96 * oe.fixed_b_factor(b):.3f}")
        assert q == pytest.approx(1.96 * oe.fixed_b_factor(b), rel=0.06)
        assert q > 1.96 * (1 + b)


def test_channel_sigmas_and_sensitivity(flights):
    """At the true coefficients the relaxation step returns the noise's σ of each channel; a rudder
    zero error shifts the estimate as refitting would (the linearised GUM sensitivity)."""
    mans = _maneuvers(flights, np.random.default_rng(np.random.SeedSequence(3)))
    sig = oe.channel_sigmas(SHIP, TRUE, mans)
    for ch, s in SIGMA.items():
        assert sig[ch] == pytest.approx(s, rel=0.25), ch
    assert oe.channel_sigmas(SHIP, TRUE, mans, floor={"u": 1.0})["u"] == 1.0
    res = oe.refine(SHIP, TRUE, mmg.LINEAR, mans, max_nfev=10)
    d = math.radians(0.5)
    bumped = [mans[0], oe.Maneuver(mans[1].x0, mans[1].t_input, mans[1].delta + d, mans[1].n, mans[1].outputs)]
    lin = oe.shift(SHIP, res, mans, 1, bumped[1])
    refit = oe.refine(SHIP, res.coeffs, mmg.LINEAR, bumped, max_nfev=10)
    full = np.array([refit.coeffs[k] - res.coeffs[k] for k in mmg.LINEAR])
    print("sensitivity to a 0.5° rudder zero: linearised", lin, "refitted", full)
    np.testing.assert_allclose(lin, full, rtol=0.1, atol=0.02 * np.abs(full).max())
    with pytest.raises(InputError, match="free"):
        oe.refine(SHIP, TRUE, ("Y_vq",), mans)
