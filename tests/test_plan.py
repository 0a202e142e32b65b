"""The trial planner: plan-file checks, agenda cost and order, the decision rule and the surrogate on
synthetic samples, the sequential search on a known error model, and a tiny plan end to end."""

from __future__ import annotations

import concurrent.futures as cf
import json
import math
import tomllib
import zlib
from pathlib import Path

import numpy as np
import pytest

from vtrials.campaign.spec import load_campaign
from vtrials.errors import InputError
from vtrials.plan import decide as D
from vtrials.plan.agendas import Candidate, candidates, dumps_toml, scenario_doc, trial_time, write_scenario
from vtrials.plan.search import Planner, plan
from vtrials.plan.spec import load_plan

DATA = Path(__file__).resolve().parent / "data"
PLAN = DATA / "plan_short.toml"
SHIPPED = Path(__file__).resolve().parents[1] / "scenarios" / "plans" / "plan_patrol51_standardization.toml"


def _edit(tmp_path, old: str, new: str) -> Path:
    text = PLAN.read_text()
    assert old in text
    p = tmp_path / "plan.toml"
    p.write_text(text.replace(old, new))
    (tmp_path / "plan_short_base.toml").write_text((DATA / "plan_short_base.toml").read_text())
    return p


@pytest.mark.parametrize("old, new, field, what", [
    ('kind = "standardization"', 'kind = "spiral"', "plan.kind", "trial kinds"),
    ('scenario = "plan_short_base.toml"', 'scenario = "nowhere.toml"', "plan.scenario", "no such file"),
    ('quantity = "speed"', 'quantity = "heave"', "target.quantity", "speed, power"),
    ("tolerance = 0.5", "tolerance = -0.5", "target.tolerance", "> 0"),
    ("confidence = 0.95", "confidence = 1.5", "target.confidence", "≤ 0.999"),
    ("rpm = 490.0", "rpmm = 490.0", "target.rpmm", "unknown field"),
    ("runs = [2]", "runs = [1]", "candidates.runs[0]", "from 2 to 6"),
    ("spots = [1]", "spots = [2]", "candidates.spots[0]", "from 1 to 1"),
    ("run_s = [30.0, 60.0]", "run_s = [30.0, 30.0]", "candidates.run_s", "repeat"),
    ("max_wind_kn = 10.0", "max_wind_kn = -1.0", "limits.max_wind_kn", "≥ 0"),
    ('{ uniform = [0.0, 15.0] }', '{ uniform = [12.0, 15.0] }', "climate.environment.wind.speed_kn",
     "never be run"),
    ('"environment.current.direction_deg"', '"environment.nowhere.x"', "climate.environment.nowhere.x",
     "no environment.nowhere"),
    ("[limits]", "[limitz]", "limitz", "unknown table"),
    ("seed = 5", 'seed = 5\nshape = "cauchy"', "plan.shape", "normal, empirical"),
])
def test_bad_plan_files_are_clear_input_errors(tmp_path, old, new, field, what):
    p = _edit(tmp_path, old, new)
    with pytest.raises(InputError) as e:
        load_plan(p)
    assert e.value.file == str(p) and e.value.field == field and what in str(e.value), str(e.value)


def test_weather_limit_truncates_the_wind_draws():
    spec = load_plan(PLAN)
    wind = next(v for v in spec.climate if v.path == "environment.wind.speed_kn")
    assert wind.kind == "uniform" and wind.args == (0.0, 10.0)  # uniform [0, 15] given wind ≤ 10 kn
    rng = np.random.default_rng(1)
    assert max(wind.draw(rng) for _ in range(500)) <= 10.0


def test_trial_time_and_candidate_order():
    spec = load_plan(SHIPPED)
    cands = candidates(spec)
    # hand computation: 2 spots × 3 runs × (60 s approach + 120 s run + 540 s turn) + 2 × 120 s change
    assert trial_time(2, 3, 120.0, 60.0, 540.0, 120.0) == pytest.approx(6 * 720.0 + 240.0)
    c = next(c for c in cands if (c.spots, c.runs, c.run_s) == (2, 3, 120.0))
    assert c.cost_s == pytest.approx(4560.0)
    costs = [c.cost_s for c in cands]
    assert costs == sorted(costs) and costs[0] == pytest.approx(2 * 660.0 + 120.0)
    assert all(c.cost_s <= spec.max_hours * 3600.0 for c in cands)
    n_all = len(spec.family.spots) * len(spec.family.runs) * len(spec.family.run_s)
    assert len(cands) == n_all  # 2.5 h admits all of this family; a shorter limit drops the dearest
    short = Planner.__new__(Planner)
    import dataclasses
    tight = dataclasses.replace(spec, max_hours=1.0)
    assert [c for c in candidates(tight)] == [c for c in cands if c.cost_s <= 3600.0]
    del short


def test_candidate_scenario_round_trips_and_loads(tmp_path):
    spec = load_plan(SHIPPED)
    cand = Candidate(2, 3, 120.0, 0.0)
    doc, group = scenario_doc(spec, cand, 7, 3)
    assert tomllib.loads(dumps_toml(doc)) == doc
    # the target (600 r/min) is the higher-power spot: second in order
    assert group == 2 and [s["rpm"] for s in doc["agenda"]["trial"][0]["spot"]] == [530.0, 600.0]
    p = tmp_path / "c.toml"
    write_scenario(spec, cand, 7, 3, p)
    camp = load_campaign(str(p))
    assert camp.replicates == 7 and {v.path for v in camp.vary} == {v.path for v in spec.climate}
    from vtrials.scenario import load_scenario
    scn = load_scenario(str(p), camp.doc)
    runs = scn.agenda.runs
    assert len(runs) == 6 and all(r.duration == pytest.approx(120.0) for r in runs)


def test_decision_rule_on_synthetic_errors():
    tol, conf = 0.1, 0.95
    e = np.r_[np.full(95, 0.05), np.full(5, 0.2)]  # 95 of 100 within
    s = D.empirical(e, tol, conf)
    assert s["within"] == 95 and s["fraction"] == pytest.approx(0.95)
    assert s["quantile_abs_error"] == pytest.approx(0.05)  # the 95th smallest |error|
    assert D.meets(s, conf, "quantile")
    assert not D.meets(s, conf, "wilson")  # Wilson lower bound of 95/100 is 0.888
    assert s["wilson_lo"] == pytest.approx(0.88825, abs=2e-4)
    s94 = D.empirical(np.r_[e[:94], 0.3, e[95:]], tol, conf)
    assert s94["within"] == 94 and not D.meets(s94, conf, "quantile") and s94["quantile_abs_error"] == pytest.approx(0.2)
    # a replicate without the quantity counts as outside
    s_nan = D.empirical(np.r_[np.full(19, 0.0), np.nan], tol, conf)
    assert s_nan["within"] == 19 and s_nan["missing"] == 1
    assert D.meets(D.empirical(np.zeros(200), tol, conf), conf, "wilson")  # 200/200: lower bound 0.981


def test_predicted_fraction_and_quantile_match_sampling():
    rng = np.random.default_rng(7)
    mse = 0.05 ** 2
    e = rng.normal(0.0, 0.05, 200000)
    assert D.predicted_fraction(mse, 0.1) == pytest.approx(np.mean(np.abs(e) <= 0.1), abs=2e-3)
    assert D.predicted_quantile(mse, 0.95) == pytest.approx(np.quantile(np.abs(e), 0.95), rel=1e-2)
    # the empirical shape: each campaign scaled by its own MSE, pooled; a missing replicate is +inf
    a, b = np.array([0.1, -0.2, 0.2]), np.array([1.0, -1.0, np.nan])
    sh = D.error_shape([(a, float(np.mean(a ** 2))), (b, 1.0)])
    assert sh[-1] == np.inf and sh.size == 6
    assert sh[:5] == pytest.approx(sorted([0.1 / 0.1732051, 0.2 / 0.1732051, 0.2 / 0.1732051, 1.0, 1.0]), rel=1e-6)
    assert D.predicted_fraction(4.0, 2.0, sh) == pytest.approx(np.mean(sh <= 1.0))  # tol/√mse = 1
    pool = D.error_shape([(e, float(np.mean(e ** 2)))])
    assert D.predicted_quantile(mse, 0.95, pool) == pytest.approx(D.predicted_quantile(mse, 0.95), rel=1e-2)


def test_surrogate_recovers_floors_and_slope():
    A = {(1, 2): 4e-3, (1, 3): 1e-3}
    B = 0.3
    pts = [(p, x, A[p] + B * x, 20) for p in A for x in (1 / 120, 1 / 360, 1 / 720)]
    s = D.fit_surrogate(pts)
    assert s.slope_identified and s.slope == pytest.approx(B, rel=1e-6)
    assert s.floors[(1, 2)] == pytest.approx(4e-3, rel=1e-6) and s.floors[(1, 3)] == pytest.approx(1e-3, rel=1e-6)
    one = D.fit_surrogate([((1, 2), 1 / 120, 5e-3, 20)])
    assert not one.slope_identified and one.known((1, 2), 1 / 120) and not one.known((1, 2), 1 / 240)
    assert not one.known((1, 3), 1 / 120)


def test_sequential_search_on_a_known_error_model(tmp_path):
    """A fake campaign draws normal errors from MSE = A[pattern] + B/(runs·run_s): the search must end on
    the cheapest candidate that meets, without running every candidate, and verify it and the one
    before it."""
    spec = load_plan(SHIPPED)
    A = {(1, 2): 0.045 ** 2, (1, 3): 0.02 ** 2, (1, 4): 0.015 ** 2, (2, 2): 0.03 ** 2, (2, 3): 0.015 ** 2,
         (2, 4): 0.01 ** 2}
    B = 0.1 ** 2 * 60  # 0.1 kn of noise on a single 60-s run

    def true_mse(c):
        return A[c.pattern] + B / (c.runs * c.run_s)

    def fake(self, cand, phase, n, seed):
        rng = np.random.default_rng(zlib.crc32(f"{cand.name}/{phase}".encode()))
        z = rng.standard_normal(n)
        e = z / np.sqrt(np.mean(z ** 2)) * math.sqrt(true_mse(cand))  # exactly the model's MSE
        st = D.empirical(e, 0.1, 0.95)
        return {"candidate": cand.name, "phase": phase, **st, "mse": float(np.mean(e ** 2)),
                "meets": D.meets(st, 0.95, "quantile"), "simulated_time_s": cand.cost_s, "errors": list(e)}

    pl = Planner(spec, tmp_path, search_replicates=40, verify_replicates=400)
    pl.campaign = fake.__get__(pl)
    doc = pl.run()
    truth = [c for c in pl.cands if D.predicted_fraction(true_mse(c), 0.1) >= 0.95]
    assert doc["chosen"] == truth[0].name
    i = pl.cands.index(truth[0])
    assert doc["one_step_cheaper"] == pl.cands[i - 1].name
    assert len(doc["search_order"]) < len(pl.cands)
    assert i > 0 and not doc["verification"]["one_step_cheaper"]["verified"]["meets"]
    assert doc["acceptance"]["met"]
    assert doc["surrogate"]["slope"] == pytest.approx(B, rel=0.05)


def test_tiny_plan_end_to_end(tmp_path):
    """Two candidates, three replicates: the cheaper one (generous tolerance) is chosen and verified;
    the speed errors are those of a real reduction against truth."""
    with cf.ThreadPoolExecutor(1) as ex:
        doc = plan(PLAN, tmp_path / "out", executor=ex)
    out = tmp_path / "out"
    saved = json.loads((out / "plan.json").read_text())
    assert saved["chosen"] == "s1_r2_t30" and saved["one_step_cheaper"] is None
    assert saved["search_order"] == ["s1_r2_t30"]
    v = doc["verification"]["chosen"]["verified"]
    assert v["n"] == 3 and v["missing"] == 0 and v["meets"]
    # a spot speed from two 30-s runs: well within 0.5 kn of the truth, but not exact
    assert 1e-4 < v["quantile_abs_error"] < 0.5
    # the simulated trial time follows the agenda (2 runs; the turn time is the plan's estimate)
    assert v["simulated_time_s"] == pytest.approx(660.0, rel=0.4)
    assert "Chosen agenda: s1_r2_t30" in (out / "plan.md").read_text()
    # assembling from the campaigns already there runs nothing and gives the same verdicts; a verifying
    # campaign stopped short is summarized over the replicates it has
    (out / "candidates" / "s1_r2_t30" / "verify" / "parts" / "replicate_00002.json").unlink()
    again = plan(PLAN, out, assemble=True)
    w = again["verification"]["chosen"]["verified"]
    assert again["chosen"] == "s1_r2_t30" and w["n"] == 2 and w["planned_replicates"] == 3
    assert w["errors"] == v["errors"][:2]
    assert "stopped short" in (out / "plan.md").read_text()


def test_cli_plan_bad_file_exits_2(tmp_path, capsys):
    from vtrials.cli import main
    p = _edit(tmp_path, "tolerance = 0.5", "tolerance = 0")
    assert main(["plan", str(p), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "target.tolerance" in err and not (tmp_path / "o").exists()
