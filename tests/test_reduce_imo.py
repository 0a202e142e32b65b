"""vtrials.reduce.imo: IMO MSC.137(76) limits at and around their boundaries."""

from __future__ import annotations

import math

import pytest

from vtrials.reduce import imo
from vtrials.reduce.estimate import Estimate
from vtrials.units import DEG

L = 200.0


@pytest.mark.parametrize("fn,k", [(imo.advance, 4.5), (imo.tactical_diameter, 5.0), (imo.initial_turning, 2.5)])
def test_length_limits_at_boundary(fn, k):
    lim = k * L
    at = fn(lim, L)
    assert at.limit == pytest.approx(lim) and at.passed and at.margin.value == pytest.approx(0.0)
    assert fn(lim * (1 + 1e-9), L).passed is False
    assert fn(lim * (1 - 1e-9), L).passed is True
    # an exact value (std 0) never straddles; an uncertain one near the limit does
    assert not at.straddles
    near = fn(Estimate(lim - 1.0, 2.0), L)
    assert near.passed and near.straddles and 0.5 < near.p_pass < 1.0
    far = fn(Estimate(lim - 10.0, 2.0), L)
    assert far.passed and not far.straddles and far.margin.value == pytest.approx(10.0)
    assert far.margin.std == 2.0


@pytest.mark.parametrize("lv,first,second", [
    (5.0, 10.0, 25.0), (9.999, 10.0, 25.0), (10.0, 10.0, 25.0), (20.0, 15.0, 32.5),
    (29.999, 19.9995, 39.99925), (30.0, 20.0, 40.0), (45.0, 20.0, 40.0)])
def test_zigzag_10_limits_by_length_over_speed(lv, first, second):
    V = 7.0
    Lx = lv * V
    assert imo.first_overshoot_10_limit(Lx, V) / DEG == pytest.approx(first)
    assert imo.second_overshoot_10_limit(Lx, V) / DEG == pytest.approx(second)


def test_zigzag_limits_are_continuous_at_band_edges():
    V = 5.0
    for lv in (10.0, 30.0):
        for f in (imo.first_overshoot_10_limit, imo.second_overshoot_10_limit):
            assert f((lv - 1e-9) * V, V) == pytest.approx(f(lv * V, V), abs=1e-9)


def test_overshoot_verdicts_at_boundary():
    V, Lx = 8.0, 160.0  # L/V = 20 s: 15° and 32.5°
    assert imo.first_overshoot_10(15.0 * DEG, Lx, V).passed
    assert not imo.first_overshoot_10(15.01 * DEG, Lx, V).passed
    assert imo.second_overshoot_10(32.5 * DEG, Lx, V).passed
    assert not imo.second_overshoot_10(32.51 * DEG, Lx, V).passed
    assert imo.first_overshoot_20(25.0 * DEG).passed and not imo.first_overshoot_20(25.001 * DEG).passed
    v = imo.first_overshoot_10(Estimate(14.8 * DEG, 0.2 * DEG), Lx, V)
    assert v.passed and v.straddles  # 14.8 ± 0.39 contains 15
    assert "L/V = 20.00" in v.note
    with pytest.raises(ValueError):
        imo.first_overshoot_10_limit(100.0, 0.0)


def test_stopping_limits_and_relaxation():
    assert imo.stopping(15 * L, L).passed and not imo.stopping(15 * L + 0.01, L).passed
    r = imo.stopping(18 * L, L, relaxed=True)
    assert r.passed and r.limit == 20 * L and "relaxed" in r.note
    assert not imo.stopping(20 * L + 0.01, L, relaxed=True).passed


def test_p_pass_uses_t_distribution_with_dof():
    v1 = imo.advance(Estimate(4.5 * L - 2.0, 1.0), L)
    v2 = imo.advance(Estimate(4.5 * L - 2.0, 1.0, dof=3), L)
    assert v1.p_pass == pytest.approx(0.97725, abs=1e-4)
    assert v2.p_pass < v1.p_pass  # heavier tails
    assert v2.straddles and not v1.straddles  # t(3) 95 % half-width 3.18 > 2 > 1.96


def test_assess_collects_verdicts_and_undecided():
    V, Lx = 7.5, 150.0
    out = imo.assess(Lx, V, advance_m=Estimate(600.0, 5.0), tactical_diameter_m=Estimate(748.0, 3.0),
                     first_overshoot_10_rad=8.0 * DEG, stopping_track_reach_m=2200.0)
    assert set(out) >= {"advance", "tactical_diameter", "first_overshoot_10", "stopping", "overall", "undecided"}
    assert out["overall"] is True
    assert out["undecided"] == ["tactical_diameter"]  # 748 ± 5.9 straddles 750
    out2 = imo.assess(Lx, V, stopping_track_reach_m=Estimate(2260.0, 1.0))
    assert out2["overall"] is False
    assert imo.speed_condition_ok(9.0, 10.0) and not imo.speed_condition_ok(8.99, 10.0)
    assert math.isclose(out["advance"].to_dict()["limit"], 4.5 * Lx)
