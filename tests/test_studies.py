"""Current-correction study helpers (vtrials.campaign.studies, reduce.current.iterative_spot_speed) on
synthetic trials whose answer is known in closed form: a sinusoidal current along the base course,
runs equally spaced, power exactly a + b V^q."""

from __future__ import annotations

import math

import numpy as np
import pytest

from vtrials.campaign import studies as ST
from vtrials.reduce import current as C
from vtrials.units import KNOT

DT = 790.0                       # s between run mid-times (the patrol vessel's spacing in the study)
BASE = math.radians(45.0)
SPOTS = {1: 5.0, 2: 7.5, 3: 10.0}  # m/s through the water
A, B, Q = 2.0e4, 900.0, 3.2      # P = a + b V^q [W]


def current(t, amp, period, phase):
    return amp * np.cos(2 * np.pi * t / period + phase)


def synthetic_trial(amp=1.0 * KNOT, period=C.TIDAL_PERIOD, phase=0.7, runs_per_spot=4, t0=500.0):
    runs, truth = [], []
    k = 0
    for g, v in SPOTS.items():
        for j in range(runs_per_spot):
            t = t0 + k * DT
            hd = BASE + (math.pi if j % 2 else 0.0)
            s = math.cos(hd - BASE)
            vg = v + s * float(current(t, amp, period, phase))
            runs.append({"run": k + 1, "group": g, "t_mid": t, "course": hd, "vg": {"value": vg, "std": 0.0},
                         "power": {"value": A + B * v ** Q}})
            truth.append({"run": k + 1, "stw": v, "heading": hd})
            k += 1
    return {"reduced": {"runs": runs}, "truth": {"runs": truth}}


def mom_error_closed_form(t_first, n, amp, period, phase):
    """Σ wᵢ sᵢ c(tᵢ) for c = amp cos(ωt + φ): (−1)^m Δ^m c(t₀)/2^m with m = n − 1 and the forward
    difference of a cosine Δ^m cos(ωt + φ) = (2 sin(ωΔ/2))^m cos(ωt + φ + m(ωΔ + π)/2)."""
    m = n - 1
    w = 2 * math.pi / period
    return (-1) ** m * amp * (2 * math.sin(w * DT / 2)) ** m * math.cos(w * t_first + phase + m * (w * DT + math.pi) / 2) / 2 ** m


@pytest.mark.parametrize("pattern", [{1: 2, 2: 2, 3: 2}, {1: 1, 2: 2, 3: 2}, {1: 1, 2: 1, 3: 1}])
def test_mean_of_means_error_is_the_forward_difference(pattern):
    amp, phase = 1.0 * KNOT, 0.7
    trial = synthetic_trial(amp=amp, period=3 * 3600.0, phase=phase)
    res = ST.current_methods(trial, pattern)
    for sp in res:
        n = 2 * pattern[sp["group"]]
        first = (sp["group"] - 1) * 4  # index of the spot's first run in the full trial
        t_first = 500.0 + first * DT
        assert sp["truth"] == pytest.approx(SPOTS[sp["group"]], abs=1e-12)
        assert sp["mom"]["error"] == pytest.approx(mom_error_closed_form(t_first, n, amp, 3 * 3600.0, phase), abs=1e-10)


def test_iterative_exact_for_the_assumed_semidiurnal_current_and_wrong_for_a_fast_one():
    for pattern, model in (({1: 2, 2: 2, 3: 2}, "tidal"), ({1: 1, 2: 2, 3: 2}, "tidal")):
        res = ST.current_methods(synthetic_trial(), pattern)
        for sp in res:
            assert sp["iterative"]["model"] == model
            assert abs(sp["iterative"]["error"]) < 1e-6  # the model is the truth: the fit is exact
    # two-run averages in the same semidiurnal stream err by half the current's change between the runs
    res = ST.current_methods(synthetic_trial(), {1: 1, 2: 2, 3: 2})
    assert abs(res[0]["mom"]["error"]) > 1e-3
    # a 2 h oscillation is not the 12.42 h sinusoid the iterative method fits: it fails, and worse than
    # the four-run mean of means, which only needs the current smooth over a double run pair
    fast = ST.current_methods(synthetic_trial(period=2 * 3600.0, phase=1.1), {1: 2, 2: 2, 3: 2})
    it_rms = math.sqrt(np.mean([sp["iterative"]["error"] ** 2 for sp in fast]))
    mom_rms = math.sqrt(np.mean([sp["mom"]["error"] ** 2 for sp in fast]))
    assert it_rms > 0.02 and it_rms > 2 * mom_rms


def test_six_runs_fall_back_to_a_model_they_can_carry():
    res = ST.current_methods(synthetic_trial(), {1: 1, 2: 1, 3: 1})
    assert res[0]["iterative"]["model"] == "constant" and res[0]["iterative"]["dof"] == 2


def test_select_runs_keeps_the_first_double_runs_and_rejects_too_many():
    runs = synthetic_trial()["reduced"]["runs"]
    kept = ST.select_runs(runs, {1: 1, 3: 2})
    assert [r["run"] for r in kept] == [1, 2, 9, 10, 11, 12]
    with pytest.raises(ValueError):
        ST.select_runs(runs, {1: 3})


def test_iterative_spot_speed_is_the_balanced_mean_with_the_propagated_current_covariance():
    """Value: ½(mean of the spot's base-course V_S + mean of its reciprocal V_S); std: the fitted current's
    covariance pushed through V_S,i = V_G,i − sᵢ c(tᵢ), checked by sampling the current parameters."""
    base = synthetic_trial()
    rr = base["reduced"]["runs"]
    t = np.array([r["t_mid"] for r in rr])
    hd = np.array([r["course"] for r in rr])
    vg = np.array([r["vg"]["value"] for r in rr])
    p = np.array([r["power"]["value"] for r in rr]) * (1 + 0.01 * np.random.default_rng(3).standard_normal(len(rr)))
    it = C.ittc_iterative(t, vg, hd, p, model="tidal")
    idx = [4, 5, 6]  # base, reciprocal, base: weights 1/4, 1/2, 1/4
    e = C.iterative_spot_speed(it, t, hd, idx, vg_std=0.01)
    assert e.value == pytest.approx(0.25 * it.vs[4] + 0.5 * it.vs[5] + 0.25 * it.vs[6], abs=1e-12)
    names = C._MODELS["tidal"]
    mean = np.array([it.current_params[n].value for n in names])
    k = len(names)
    draws = np.random.default_rng(4).multivariate_normal(mean, it.cov[-k:, -k:], size=20000)
    w2pi = 2 * np.pi / it.period
    tau = t[idx] - it.t_ref
    cur = (draws[:, [0]] * np.cos(w2pi * tau) + draws[:, [1]] * np.sin(w2pi * tau) + draws[:, [2]] * tau + draws[:, [3]])
    s = np.cos(hd[idx] - hd[0])
    spot = (vg[idx] - s * cur) @ np.array([0.25, 0.5, 0.25])
    sd_mc = math.sqrt(np.var(spot) + (0.25 ** 2 + 0.5 ** 2 + 0.25 ** 2) * 0.01 ** 2)
    assert e.std == pytest.approx(sd_mc, rel=0.03)
    with pytest.raises(ValueError):
        C.iterative_spot_speed(it, t, hd, [4, 6])  # both on the base course: not a spot


def test_bootstrap_rms_interval_contains_the_rms():
    e = np.random.default_rng(0).normal(0, 0.1, 200)
    r = ST.bootstrap_rms(e)
    assert r["lo95"] < r["rms"] < r["hi95"] and r["rms"] == pytest.approx(0.1, rel=0.15)
    d = ST.paired_rms_difference(2 * e, e)
    assert d["lo95"] > 0


@pytest.mark.parametrize("name", ["patrol51_strasser_semidiurnal", "patrol51_strasser_departing",
                                  "patrol51_insel_precision", "patrol51_insel_wind", "patrol51_insel_current"])
def test_study_scenarios_load_as_campaigns(name):
    from pathlib import Path

    from vtrials.campaign.spec import load_campaign, replicate_doc, replicate_seeds
    from vtrials.scenario import load_scenario
    path = str(Path(__file__).resolve().parent.parent / "scenarios" / "studies" / f"{name}.toml")
    spec = load_campaign(path)
    doc, drawn = replicate_doc(spec, replicate_seeds(spec.seed, spec.replicates)[0])
    scn = load_scenario(path, doc)
    runs = scn.agenda.trials[0].runs
    per_spot = [sum(r.group == g for r in runs) for g in (1, 2, 3)]
    assert per_spot == ([4, 4, 4] if "strasser" in name else [2, 2, 2])
    assert len(runs) == sum(per_spot)
    if "strasser" in name:
        assert 0.0 <= drawn["environment.current.tidal_phase_deg"] < 360.0
        assert scn.current.tidal_period_h == (12.42 if "semidiurnal" in name else 1.0)
