"""Propeller in four quadrants: published first-quadrant values, continuity, physical signs."""

from __future__ import annotations

import math

import numpy as np
import pytest

from vtrials.physics.forces import bseries
from vtrials.physics.forces.propeller import K07, Propeller, coefficients, fit_section_model, pack
from vtrials.physics.vessel import load_vessel

# K_T read off the published B4-70 open-water diagram (Wageningen B-screw series, as drawn by Kuiper
# 1992, "The Wageningen propeller series", MARIN publication 92-001; digitized points). Chart
# reading accuracy is about ±0.005 in K_T.
B4_70_CHART_KT = {
    0.6: [(0.008, 0.2478), (0.259, 0.1656), (0.509, 0.0627)],
    1.0: [(0.008, 0.4525), (0.376, 0.3234), (0.742, 0.1572), (1.045, 0.0074)],
    1.4: [(0.006, 0.6241), (0.691, 0.3803), (1.342, 0.0685)],
}


@pytest.mark.parametrize("pd", sorted(B4_70_CHART_KT))
def test_bseries_matches_published_chart(pd):
    for J, kt_chart in B4_70_CHART_KT[pd]:
        kt, kq = bseries.kt_kq(J, pd, 0.70, 4)
        assert kt == pytest.approx(kt_chart, abs=0.005), (pd, J)
        assert kq > 0


def test_bseries_kvlcc2_series_equivalent():
    """The KVLCC2 propeller (P/D 0.721, A_E/A_0 0.431, Z 4) as a B-series: its bollard K_T agrees with
    the MMG paper's measured k0 = 0.2931 (Yasukawa & Yoshimura 2015) within 0.5 %."""
    kt, _ = bseries.kt_kq(0.0, 0.721, 0.431, 4)
    assert kt == pytest.approx(0.2931, rel=0.005)


def _props():
    v = load_vessel("kvlcc2")
    p = load_vessel("patrol51")
    return [(v.propellers[0], 1), (p.propellers[0], -1)]


@pytest.mark.parametrize("which", [0, 1])
def test_first_quadrant_is_the_own_curve(which):
    pr, rot = _props()[which]
    blk = pack(pr, 0, 100.0, 1025.0, 0.01, rot)
    pds = [pr.pitch_ratio] if pr.curve == "polynomial" else [0.6, 0.9, 1.2, 1.4]
    for pd in pds:
        jmax = pr.j_max if pr.curve == "polynomial" else 0.95 * pd
        for J in np.linspace(0.0, jmax, 9):
            ct, cq = coefficients(blk, math.atan2(J, K07), pd)
            kt = ct * math.pi * (J * J + K07 ** 2) / 8
            kq = cq * math.pi * (J * J + K07 ** 2) / 8
            if pr.curve == "polynomial":
                kt_own = pr.k0 + pr.k1 * J + pr.k2 * J * J
                kq_own = pr.q0 + pr.q1 * J + pr.q2 * J * J
            else:
                kt_own, kq_own = bseries.kt_kq(J, pd, pr.area_ratio, pr.blades)
            assert kt == pytest.approx(kt_own, abs=1e-12)
            assert kq == pytest.approx(kq_own, abs=1e-12)


@pytest.mark.parametrize("which", [0, 1])
def test_continuous_across_every_quadrant_boundary(which):
    """C_T*, C_Q* are continuous in β at 0, ±90°, ±180° (and at the own-curve taper edges), for
    several pitch settings including zero and reversed pitch."""
    pr, rot = _props()[which]
    blk = pack(pr, 0, 100.0, 1025.0, 0.01, rot)
    pds = [pr.pitch_ratio] if pr.curve == "polynomial" else [1.4, 1.0, 0.55, 0.0, -0.8]
    jhi = pr.j_max if pr.curve == "polynomial" else None
    for pd in pds:
        edges = [0.0, math.pi / 2, -math.pi / 2, math.pi - 1e-9, -math.pi + 1e-9]
        bhi = math.atan((jhi if jhi else 0.95 * pd) / K07) if pd > 0 else 0.3
        edges += [bhi, bhi + math.radians(10), -math.radians(10)]
        for b in edges:
            eps = 1e-7
            a = np.array(coefficients(blk, b - eps, pd))
            c = np.array(coefficients(blk, b + eps, pd))
            assert np.all(np.abs(a - c) < 1e-5), (pd, math.degrees(b), a, c)
        # wrap-around at ±180°
        a = np.array(coefficients(blk, math.pi, pd))
        c = np.array(coefficients(blk, -math.pi, pd))
        assert np.all(np.abs(a - c) < 1e-12)
    # and a scan shows no jumps anywhere (bounded slope)
    beta = np.linspace(-math.pi, math.pi, 20001)
    ct = np.array([coefficients(blk, b, pds[0])[0] for b in beta])
    assert np.max(np.abs(np.diff(ct))) < 20 * (beta[1] - beta[0])


def test_thrust_and_torque_continuous_through_zero_rpm_and_zero_speed():
    """In dimensional terms (V_A, n) the forces pass smoothly through n = 0 and V_A = 0."""
    pr, rot = _props()[0]
    blk = pack(pr, 0, 320.0, 1025.0, 0.01, rot)
    D = pr.diameter

    def TQ(VA, n):
        Vr2 = VA * VA + (K07 * n * D) ** 2
        ct, cq = coefficients(blk, math.atan2(VA, K07 * n * D), pr.pitch_ratio)
        return np.array([0.5 * 1025 * Vr2 * math.pi / 4 * D * D * ct, 0.5 * 1025 * Vr2 * math.pi / 4 * D ** 3 * cq])

    scale = np.abs(TQ(0.0, 1.0))  # bollard thrust and torque at 1 rev/s
    for VA in (-3.0, 0.0, 3.0):
        for eps in (1e-4, 1e-6):  # the jump shrinks with the step: no discontinuity at n = 0
            assert np.all(np.abs(TQ(VA, eps) - TQ(VA, -eps)) <= 20 * eps * scale + 1e-9)
    for n in (-1.0, 0.0, 1.0):
        for eps in (1e-4, 1e-6):  # nor at V_A = 0
            assert np.all(np.abs(TQ(eps, n) - TQ(-eps, n)) <= 20 * eps * scale + 1e-9)


def test_four_quadrant_physics():
    pr, rot = _props()[0]
    blk = pack(pr, 0, 320.0, 1025.0, 0.01, rot)
    pd = pr.pitch_ratio
    ct0, cq0 = coefficients(blk, 0.0, pd)                 # ahead bollard
    ct180, cq180 = coefficients(blk, math.pi, pd)          # astern bollard
    ct90, cq90 = coefficients(blk, math.pi / 2, pd)        # locked propeller, ship ahead
    ctq2, _ = coefficients(blk, math.radians(150), pd)     # crash-back: ship ahead, propeller astern
    assert ct0 > 0 and cq0 > 0
    assert ct180 < 0 and cq180 < 0                          # astern thrust, torque reversed
    assert 0.6 * ct0 < -ct180 < 0.95 * ct0                   # astern weaker than ahead (η_r)
    assert ct90 < 0 and cq90 < 0                             # locked: drag, and the water drives the blades (windmill)
    assert ctq2 < 0
    # zero-thrust J of the section model lies where the own curve's does (fit quality)
    _, err = fit_section_model(pr)
    assert err < 0.02


def test_controllable_pitch_reverses_thrust():
    pr, rot = _props()[1]
    blk = pack(pr, 0, 51.5, 1014.0, 0.01, rot)
    bollard = [coefficients(blk, 0.0, pd)[0] for pd in np.linspace(-1.0, 1.5, 26)]
    assert np.all(np.diff(bollard) > 0)   # thrust grows with pitch
    assert bollard[0] < 0 < bollard[-1]
    zero_pitch = min(np.linspace(-1.0, 1.5, 26), key=lambda p: abs(coefficients(blk, 0.0, p)[0]))
    assert abs(zero_pitch) < 0.15        # the zero-thrust pitch is near zero (camber)


def test_b_series_section_model_not_just_any_fit():
    """The section model, fitted at one pitch, predicts the B-series bollard thrust at other pitches
    to within 40 %: it carries the pitch dependence physically (outside the window it is all there is)."""
    pr = Propeller(name="x", diameter=1.0, x=0, y=0, z=0, t_P=0.1, w_P0=0.1, curve="bseries", blades=4,
                   area_ratio=0.7, pitch_ratio=1.0)
    p, _ = fit_section_model(pr)
    from vtrials.physics.forces.propeller import section_coefficients
    for pd in (0.6, 0.8, 1.2, 1.4):
        ct, _ = section_coefficients(np.array([0.0]), math.atan(pd / K07), p)
        kt_model = ct[0] * math.pi * K07 ** 2 / 8
        kt_b, _ = bseries.kt_kq(0.0, pd, 0.7, 4)
        assert kt_model == pytest.approx(kt_b, rel=0.4)
