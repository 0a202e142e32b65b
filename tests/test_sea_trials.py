"""A standardization trial in a seaway, end to end through the real runner (issue 10).

tests/data/patrol51_standardization_sea3_short.toml: the State 3 sea of
scenarios/patrol51_standardization_sea3.toml (H_s 0.88 m, T_p 7.5 s, cos-2s s = 10, from 010°) on
two spots (380 and 530 r/min), one reciprocal pair each on base course 045° (the sea 35° off the bow,
then 35° off the stern), 10-min runs, no wind, 0.25 kn current. ``vtrials.run`` simulates it on the ship built by
:func:`vtrials.scenario.sea_vessel` (excitation, radiation, SNNM added resistance, drift in sway/yaw),
writes the records, reduces them and scores against the calm-water truth (which keeps the calm-water ship).

Checked:

* the instruments saw the waves: the record's vertical gyro pitch has the RMS of the true pitch (within
  15 %; the truth's > 0.005 rad) and the IMU's pitch rate moves (RMS > 0.003 rad/s);
* speed loss: on the runs into the sea (35° off the bow) the true speed through the water is below the
  calm-water speed at the same settings (the scorer's calm-water twin) by the loss the force balance with
  the SNNM added resistance predicts (steady_at_order of the calm-water ship carrying only the SNNM
  component, at the run's heading and settings), within 25 % of the predicted loss. Measured: run 1
  (7.3 m/s) 0.0584 vs 0.0536 m/s (+9 %), run 3 (12.2 m/s) 0.0583 vs 0.0526 m/s (+11 %). The tolerance is
  wider than the 10 % of the component tests because a run's mean still holds part of the first-order
  surge motion (encounter periods of tens of seconds). The runs with the sea 35° off the stern are
  printed, not asserted: at 12.2 m/s the encounter frequency of the spectral peak is near zero
  (ω_e = ω(1 − ωU cos β/g) vanishes at ω ≈ 0.97 rad/s, the peak is at 0.84) and a run's mean is
  dominated by the slow first-order surge (measured: losses of 0.027 and 0.025 m/s against predicted
  0.034 and 0.047 m/s; with 180-s runs the same ship was 0.022 and 0.025 m/s FASTER than in calm water);
* the reduction: vtrials.reduce.trials applies no wave correction (the records carry no wave
  measurement), so its spot powers stand above the calm-water curve by the added resistance's power.
  Corrected here as a trials team would with STAWAVE-2 (:mod:`vtrials.reduce.stawave`, the sea's target
  spectrum as a wave buoy would give it; head-sea method applied on the base run within ±45°, none on
  the reciprocal run) and the Direct Power Method with the spot's η_D and ξ_P, the spot powers come within
  2.5 % of the calm-water truth, and at the slow spot closer than uncorrected. Measured: spot 1 (7.25 m/s)
  +3.12 % uncorrected, −0.36 % corrected (STAWAVE-2 ΔR 2.85 kN on the base run; SNNM gave 2.18 kN);
  spot 2 (12.22 m/s) +1.08 % and −0.13 % (its reciprocal run is the fast one above). STAWAVE-2 (the team's) and SNNM (the simulated sea's)
  are different methods, so the corrected residual is the difference of two empirical estimates, not
  zero by construction; patrol51's C_B 0.35 lies outside both methods' regression range.

Why 10-min runs: the mean speed of a 180-s run with the sea 35° off the stern scatters by 0.034 m/s at
7.3 m/s (free-running patrol51 at fixed settings, 8 seeds × 7 windows, benchmarks/radiation_timing.py;
0.0336 and 0.0341 m/s with the two timings of the radiation memory), which moves the slow spot's power at equal speed by about as much as the wave
correction the last check is about. With 180-s runs the checks held on 17 of 19 wave seeds with the
radiation memory lagging a step and on 10 of 19 with it centred in time (benchmarks/results/
sea_trials_seeds*.json; the into-sea runs agree between the two to 0.001 m/s on average, the runs with
the sea astern do not: 0.012 and 0.026 m/s scatter at the slow spot); with 10-min runs on 8 of 9 (seeds
2002–2010, centred memory; seed 2004's corrected slow spot is +2.9 %) and 3 of 4 with the lagging one
(seeds 2002–2005; benchmarks/results/sea_trials_seeds_600s.json), and on this file's seed the two
memories give +3.12/−0.36 % and +3.09/−0.39 % at the slow spot.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

import vtrials
from tests.calibration import calibration_power_error, drawn_meter_errors
from vtrials.physics.environment.waves import spectrum, peak_frequency
from vtrials.physics.forces import added_resistance as AR
from vtrials.physics.forces.registry import Component
from vtrials.physics.simulator import Simulator
from vtrials.reduce.speedpower import direct_power_method
from vtrials.records.netcdf import open_record
from vtrials.reduce.stawave import observed_spectrum, stawave2
from vtrials.scenario import load_scenario, wave_field
from vtrials.score.trials import true_curve

DATA = Path(__file__).resolve().parent / "data"
SHORT = DATA / "patrol51_standardization_sea3_short.toml"


@pytest.fixture(scope="module")
def sea_day(tmp_path_factory):
    out = tmp_path_factory.mktemp("sea3")
    res = vtrials.run(SHORT, out, plot=False)
    doc = json.loads((out / "results.json").read_text())
    return res, doc, out


def test_instruments_see_the_waves(sea_day):
    res, doc, out = sea_day
    crew = res.crew
    rows = np.concatenate(crew.truth_rows, axis=0)
    pitch = rows[:, crew.names.index("pitch")]
    z = rows[:, crew.names.index("z")]
    from vtrials.records.netcdf import open_record
    rec = open_record(out / "records" / "standardization.nc")
    _t, vg_pitch = rec.channel("vertical_gyro", "pitch")
    _t, q = rec.channel("imu", "q")
    print(f"truth pitch RMS {np.std(pitch):.4f} rad, heave RMS {np.std(z - np.mean(z)):.4f} m; record: vertical "
          f"gyro pitch RMS {np.std(vg_pitch):.4f} rad, IMU pitch rate RMS {np.std(q):.4f} rad/s")
    assert np.std(pitch) > 0.005              # calm water: only the trim changes between settings
    assert np.std(vg_pitch) == pytest.approx(np.std(pitch), rel=0.15)
    assert np.std(q) > 0.003


def _predicted_losses(doc):
    scn = load_scenario(SHORT)
    comp = wave_field(scn).components
    hull = AR.snnm_hull(scn.vessel)
    sea = Simulator(scn.vessel, 1, 0.05, components=list(scn.vessel.components) + [
        Component("added_resistance", "added_resistance", AR.pack(hull, comp))])
    calm = Simulator(scn.vessel, 1, 0.05)
    runs = {a["run"]: a for a in doc["agenda"]["runs"] if a.get("accepted")}
    out = []
    for r in doc["trials"][0]["truth"]["runs"]:
        a = runs[r["run"]]
        rps = tuple(x / 60.0 for x in a["rpm_ordered"])
        pitch = tuple(a["pitch_ordered"])
        s_sea = sea.steady_at_order(0, rps, pitch, heading=r["heading"])
        R = -float(sea.comp_w[0, sea.comp_names.index("added_resistance"), 0])
        s_calm = calm.steady_at_order(0, rps, pitch, heading=r["heading"])
        # the sea comes from 010°: the angle between the run's heading and the sea's direction
        off_bow = abs(math.degrees(math.remainder(r["heading"] - math.radians(10.0), 2 * math.pi)))
        out.append({"run": r["run"], "group": a["group"], "off_bow_deg": off_bow, "R": R,
                    "pred": s_calm.u - s_sea.u, "sim": s_calm.u - r["stw"], "calm": s_calm.u})
    return out


def test_speed_loss_matches_the_added_resistance(sea_day):
    _res, doc, _out = sea_day
    rows = _predicted_losses(doc)
    into_sea = 0
    for r in rows:
        print(f"run {r['run']} (sea {r['off_bow_deg']:.0f}° off the bow): calm {r['calm']:.4f} m/s, added resistance "
              f"{r['R']:.0f} N, predicted loss {r['pred']:.4f}, simulated {r['sim']:.4f} m/s")
        assert r["pred"] > 0.0
        if r["off_bow_deg"] < 90.0:
            into_sea += 1
            assert abs(r["sim"] - r["pred"]) <= 0.25 * r["pred"], r
    assert into_sea == 2


def test_stawave_corrected_reduction_recovers_the_calm_water_curve(sea_day):
    """The reduction's own wave correction (STAWAVE-2 from the team's observed sea on the runs within
    ±45° of the bow, half the head-sea value ± 1/√12 on the others: vtrials/reduce/stawave.py) brings
    the reduced power within 2.5 % of the calm-water truth at both spots once the meters' drawn
    calibration errors are taken out (tests/calibration.py), every interval covering. The observed sea is
    the scenario's within its stated errors, and the into-sea run's added resistance is STAWAVE-2 of it.
    Whether the corrected slow spot is nearer the truth than the measured power is a property of the
    campaign, not of one record: 13 of 19 wave seeds in benchmarks/results/sea_trials_seeds.json (this
    record's seed is one of the 6 others since the maneuvering forces see the waves' flow: measured
    +1.56 %, corrected −1.90 %)."""
    res, doc, out = sea_day
    meters = drawn_meter_errors(out / "truth.nc")
    t = doc["trials"][0]
    P_true, _ = true_curve(t["truth"]["calm_water"])
    rec = open_record(out / "records" / "standardization.nc")
    sea = rec.team["sea_observed"]
    assert len(sea) == 1 and abs(sea[0]["hs_m"] / 0.88 - 1.0) < 4 * sea[0]["hs_rel_std"]
    p = res.scenario.vessel.particulars
    C_B = rec.attr("condition", {})["displacement_m3"] / (p.length * p.beam * p.draught)  # the trial's
    worst_raw, worst_cor = 0.0, 0.0
    for s in t["reduced"]["spots"]:
        V = s["stw"]["value"]
        w = np.linspace(0.2, 6.0, 600) * (2.0 * math.pi / sea[0]["tp_s"])
        head = stawave2(w, observed_spectrum(w, sea[0]["hs_m"], sea[0]["tp_s"], sea[0]["gamma"]), V, p.length,
                        p.beam, p.draught, C_B, rho=p.water_density)
        # (the spot speed is the joint fit's: the pairs' average corrected by the trend between the spots)
        assert sorted(x["r_aw"] for x in s["waves"]) == pytest.approx([0.5 * head, head], rel=5e-3)
        Pt = float(P_true(V))
        cal = calibration_power_error(meters, s["torque"], s["rps"])
        raw = (s["power_measured"]["value"] / Pt) / (1.0 + cal) - 1.0
        cor = (s["power"]["value"] / Pt) / (1.0 + cal) - 1.0
        e = next(x for x in t["error"]["spots"] if x["group"] == s["group"])["power_at_equal_speed"]
        print(f"spot {s['group']}: V {V:.3f} m/s, head-sea STAWAVE-2 {head:.0f} N; measured power "
              f"{raw:+.2%}, corrected {cor:+.2%} vs the calm truth (net of the meters' {cal:+.2%}); "
              f"95 % half-width {e['half_width95']:.2%}")
        assert e["covered"], e
        worst_raw, worst_cor = max(worst_raw, abs(raw)), max(worst_cor, abs(cor))
    print(f"worst |error| measured {worst_raw:.2%}, corrected {worst_cor:.2%}")
    assert worst_cor <= 0.025


def test_side_by_side_runner_builds_the_ships_in_the_sea(tmp_path):
    """Two turning circles in the State 3 sea through the side-by-side runner: both complete, and the
    ships pitch as the sea makes them (RMS > 0.004 rad; the same turns without waves, where only the
    turn trims the ship, measured 0.00041 rad, and tactical diameters of 195.3 m against 192.4 and 194.4 m
    in the sea)."""
    res = vtrials.run(DATA / "patrol51_turns_sea3.toml", tmp_path / "sea", plot=False)
    for m in res.maneuvers:
        ps = float(np.std(m.columns["pitch"]))
        print(f"{m.name}: completed {m.completed}, pitch RMS {ps:.4f} rad, tactical diameter "
              f"{m.truth.get('tactical_diameter_m')}")
        assert m.completed
        assert ps > 0.004
        assert np.all(np.isfinite(m.columns["x"]))


@pytest.mark.parametrize("value,ok", [("snnm", True), ("database", True), ("none", True), ("stawave", False)])
def test_wave_loads_choice(tmp_path, value, ok):
    text = SHORT.read_text().replace("[environment.waves]", f'[environment.wave_loads]\nmean_force = "{value}"\n\n'
                                                              "[environment.waves]")
    f = tmp_path / "s.toml"
    f.write_text(text)
    from vtrials.errors import InputError
    from vtrials.scenario import sea_vessel
    if not ok:
        with pytest.raises(InputError) as e:
            load_scenario(f)
        assert "environment.wave_loads.mean_force" in str(e.value) and "stawave" in str(e.value)
        return
    scn = load_scenario(f)
    assert scn.wave_loads.mean_force == value
    names = [c.name for c in sea_vessel(scn)[0].components]
    assert "seakeeping_coriolis" in names                 # patrol51: added_mass.coriolis = "none"
    assert ("added_resistance" in names) == (value == "snnm")
    assert ("wave_drift" in names) == (value in ("snnm", "database"))
