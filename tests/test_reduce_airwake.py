"""AWSM motion removal on a known steady wind seen from a moving ship (analytic motion,
tests/reference/shipmotion.py), with the ship motion reconstructed by Compat from a noisy IMU."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tests.reference import shipmotion as sm
from vtrials.errors import InputError
from vtrials.reduce import airwake as AW
from vtrials.reduce import compat as C

D = math.pi / 180
FT = 0.3048
# seed 003 Table 4/5: mast position 10, top array: base (−142.5, 17.1, −15.8) ft, top z offset −31.5 ft
MAST = np.array([-142.5, 17.1, -15.8 - 31.5]) * FT
WIND = -12.0 * np.array([math.cos(45 * D), math.sin(45 * D), 0.0])  # 12 m/s from the north-east


def _rms(x):
    return float(np.sqrt(np.mean(np.asarray(x) ** 2)))


@pytest.fixture(scope="module")
def record():
    rng = np.random.default_rng(11)
    t = np.arange(0.0, 120.05, 0.1)
    s = sm.spectral
    m = sm.motion(t, s(rng, 3 * D, 0.55, mean=1 * D), s(rng, 1 * D, 0.65, mean=-0.3 * D),
                  s(rng, 1 * D, 0.55, mean=30 * D), s(rng, 0.08, 0.65, mean=8.0), s(rng, 0.25, 0.55),
                  s(rng, 0.5, 0.65))
    a = sm.rotation(*m.euler.T)
    w_body = np.einsum("nji,j->ni", a, WIND)
    inst = m.v_ground + np.cross(m.omega, np.broadcast_to(MAST, m.omega.shape))
    measured = w_body - inst + rng.normal(0, 0.05, m.omega.shape)  # sonic anemometer noise 0.05 m/s
    # Compat on a noisy, biased IMU at the centre of motion
    n = t.size
    bias_w = np.array([0.05, -0.03, 0.02]) * D
    bias_f = np.array([0.02, -0.03, 0.05])
    imu = C.ImuRecord(t, m.omega + bias_w + rng.normal(0, 0.0005 * D, (n, 3)),
                      m.specific_force + bias_f + rng.normal(0, 0.01, (n, 3)))
    obs = {"heading": C.Observation(m.euler[:, 2] + rng.normal(0, 0.1 * D, n), 0.1 * D),
           "roll": C.Observation(np.mean(m.euler[:, 0]) + rng.normal(0, 0.05 * D), 0.05 * D, True),
           "pitch": C.Observation(np.mean(m.euler[:, 1]) + rng.normal(0, 0.05 * D), 0.05 * D, True),
           "u": C.Observation(8.0 + rng.normal(0, 0.03, n), 0.1),
           "v": C.Observation(np.zeros(n), 0.3), "w": C.Observation(np.zeros(n), 0.5)}
    fit = C.compat_fit(imu, obs, C.ATTITUDE_PARAMETERS + C.MOTION_PARAMETERS)
    return m, w_body, measured, fit


def test_awsm_with_true_motion_is_exact(record):
    """Sign check against the independent synthesis: with the true ship motion, c = W_b − mean(V)."""
    m, w_body, measured, _ = record
    body, _ = AW.awsm(measured, m.v_ground, m.omega, MAST, m.euler[:, 0], m.euler[:, 1])
    expected = w_body - m.v_ground.mean(axis=0)
    assert np.max(np.abs(body - expected)) < 0.3  # anemometer noise only, 6σ
    assert _rms(body - expected) == pytest.approx(0.05, rel=0.1)


def test_awsm_with_compat_motion_removes_the_motion(record):
    """With Compat's reconstructed velocity and bias-corrected rates, the motion-induced velocity
    (ΔV + ω × ρ at the mast, 1.1 m/s RMS over the three components) is removed to within a few % of
    its RMS, and the mean of each component is unchanged but for the small mean of ω × ρ."""
    m, w_body, measured, fit = record
    body, _ = AW.awsm(measured, fit.states[:, 3:6], fit.rates, MAST, fit.states[:, 0], fit.states[:, 1])
    expected = w_body - m.v_ground.mean(axis=0)
    induced = measured - expected
    left = body - expected
    noise = 0.05
    fracs = []
    for k in range(3):
        frac = math.sqrt(max(_rms(left[:, k]) ** 2 - noise ** 2, 0.0)) / _rms(induced[:, k])
        fracs.append(frac)
        print(f"component {k}: induced RMS {_rms(induced[:, k]):.3f} m/s, left {100 * frac:.2f} %, "
              f"mean change {body[:, k].mean() - measured[:, k].mean():+.4f} m/s")
    # the mean moves only by mean(ω × ρ) = (attitude change over the record) × lever arm / duration
    rot_mean = np.cross(m.omega, np.broadcast_to(MAST, m.omega.shape)).mean(axis=0)
    for k in range(3):
        change = body[:, k].mean() - measured[:, k].mean()
        assert abs(change - rot_mean[k]) < 0.005
        assert abs(change) < 0.05 * _rms(induced[:, k])
    total = math.sqrt(max(_rms(left) ** 2 - noise ** 2, 0.0)) / _rms(induced)
    print(f"all components: left {100 * total:.2f} % of the induced RMS")
    assert total < 0.03
    assert max(fracs) < 0.08  # surge: Compat's u from the log carries ~0.016 m/s of slow error


def test_vertical_axes_and_true_wind(record):
    """Ship-carried vertical axes: rotate-then-remove gives R_zᵀ(ψ)W − mean(R V) to the noise; the
    seed's remove-then-rotate order leaves the pitch-projected mean speed (≈ Uθ) in the vertical
    component. The true wind comes back as the 12 m/s north-easterly."""
    m, w_body, measured, fit = record
    phi, th, psi = m.euler.T
    rot = AW.rotation_roll_pitch(phi, th)
    v_vert = np.einsum("nij,nj->ni", rot, m.v_ground)
    cp, sp = np.cos(psi), np.sin(psi)
    wind_heading_axes = np.stack([cp * WIND[0] + sp * WIND[1], -sp * WIND[0] + cp * WIND[1],
                                  np.full_like(cp, WIND[2])], 1)
    expected = wind_heading_axes - v_vert.mean(axis=0)
    better = AW.wind_relative_to_mean_motion(measured, m.v_ground, m.omega, MAST, phi, th)
    _, seed_order = AW.awsm(measured, m.v_ground, m.omega, MAST, phi, th)
    induced_w = _rms((measured - (w_body - m.v_ground.mean(axis=0)))[:, 2])
    err_better = _rms(better[:, 2] - expected[:, 2])
    err_seed = _rms(seed_order[:, 2] - expected[:, 2])
    print(f"vertical component left: rotate-first {100 * err_better / induced_w:.1f} %, "
          f"seed order {100 * err_seed / induced_w:.1f} % of the induced RMS")
    assert err_better < 0.08 and err_seed > 2 * err_better
    wind = AW.true_wind(measured, m.v_ground, m.omega, MAST, phi, th, psi)
    speed, came_from = AW.speed_and_from_direction(wind)
    assert abs(speed.mean() - 12.0) < 0.02
    assert abs(came_from.mean() - 45 * D) < 0.005


def test_bad_input_names_field():
    z = np.zeros((10, 3))
    with pytest.raises(InputError, match="position"):
        AW.awsm(z, z, z, (1.0, 2.0), np.zeros(10), np.zeros(10))
    with pytest.raises(InputError, match="ship_velocity"):
        AW.awsm(z, z[:5], z, (1.0, 2.0, 3.0), np.zeros(10), np.zeros(10))
    with pytest.raises(InputError, match="roll"):
        AW.awsm(z, z, z, (1.0, 2.0, 3.0), np.zeros(9), np.zeros(10))
