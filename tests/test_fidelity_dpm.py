"""Issue 17 item 1: the Direct Power Method with its third term, η_D,ms from the overload factor ξ_P of
a load-variation test run on the model itself (ITTC 7.5-04-01-01.1 (2017, rev. 2021); ISO 15016:2015).

Reference: the model's own self-propulsion point at the same speed without the added load (the
"ideal" power the correction must return), computed by a separate root-find on the surge balance."""

import numpy as np
import pytest

from vtrials.physics.simulator import Simulator
from vtrials.physics.vessel import load_vessel
from vtrials.reduce import speedpower as SP
from vtrials.truth.calmwater import load_variation


@pytest.fixture(scope="module")
def kvlcc2():
    v = load_vessel("kvlcc2")
    return v, Simulator(v, 1, 0.05, record_every=0)


def test_dpm_solves_the_implicit_eta_relation():
    p_ms, dr, v, eta_id, xi = np.array([8.0e6, 5.0e6]), np.array([2.0e5, -5.0e4]), 7.0, 0.6, 0.14
    p_id, _ = SP.direct_power_method(p_ms, dr, v, eta_id, xi_p=xi)
    eta_ms = eta_id / (1.0 + xi * (p_ms - p_id) / p_id)
    np.testing.assert_allclose(p_id, p_ms - dr * v / eta_id - p_ms * (1.0 - eta_ms / eta_id), rtol=1e-12)
    # ξ_P = 0: η_D,ms = η_D,id, the simple form
    p0, _ = SP.direct_power_method(p_ms, dr, v, eta_id, xi_p=0.0)
    np.testing.assert_allclose(p0, p_ms - dr * v / eta_id, rtol=1e-14)
    with pytest.raises(ValueError, match="not both"):
        SP.direct_power_method(p_ms, dr, v, eta_id, eta_d_ms=0.5, xi_p=xi)


def test_overload_factor_of_the_reduction_matches_the_tank(kvlcc2):
    v, sim = kvlcc2
    lv = load_variation(v, [6.0], sim=sim)
    pts = lv["points"][0]
    xi = SP.overload_factor([p["power_W"] for p in pts[1:]], [p["eta_D"] for p in pts[1:]],
                            pts[0]["power_W"], pts[0]["eta_D"])
    assert xi == pytest.approx(lv["xi_P"][0], rel=1e-12)
    assert 0.05 < xi < 0.4  # a heavily loaded single-screw propeller loses efficiency with load


@pytest.mark.parametrize("V", [4.0, 6.0, 7.5])
def test_dpm_returns_the_calm_water_power_of_an_overloaded_propeller(kvlcc2, V):
    """A head-wind-like added resistance of 15 % and 35 % of R_T (outside the fitted loadings): the
    DPM with ξ_P returns the self-propulsion power within 0.1 %; without the third term it is > 1 %
    high at the larger load."""
    v, sim = kvlcc2
    fit = load_variation(v, [V], sim=sim)
    probe = load_variation(v, [V], fractions=(0.15, 0.35), sim=sim)["points"][0]
    p_true = probe[0]["power_W"]
    eta_id = probe[0]["eta_D"]
    errs, errs_simple = [], []
    for p in probe[1:]:
        p_id, _ = SP.direct_power_method(p["power_W"], p["dR_N"], V, eta_id, xi_p=fit["xi_P"][0])
        p_simple, _ = SP.direct_power_method(p["power_W"], p["dR_N"], V, eta_id)
        errs.append(float(p_id) / p_true - 1.0)
        errs_simple.append(float(p_simple) / p_true - 1.0)
    print(f"V={V}: DPM with xi_P errors {np.round(np.array(errs) * 100, 4)} %, "
          f"without {np.round(np.array(errs_simple) * 100, 3)} %")
    assert max(abs(e) for e in errs) < 1e-3
    assert errs_simple[-1] > 0.01
