"""Wave estimation from a simulated trial record (issue 13 part C), reading the record only and the team's
DESIGN-STAGE RAOs (models/patrol51/design), scored against the true sea (vtrials.truth.seaway).

One short seakeeping leg of patrol51 (7 min at the standard order, 9 m/s, waves from the port quarter,
H_s 1.5 m, cos-2s s = 10) with the X-band wave radar at its TRIAL calibration (reads 1.51× the sea on
average, seed 004). Both reductions assume one relative wave direction over the run, so the leg must be
one whose course was held: the test checks the gyro heading's standard deviation against the 10° with
which benchmarks/campaign_wavefusion.py accepts a leg (measured 2.6°). The leg was at 8 kn (ahead 1/3)
before; there patrol51 does not hold its course in these seas (heading standard deviation 17–38° over
seeds 4322–4326 with the radiation memory lagging a step, 19–144° on 4322–4325 with it centred, which gives
the lightly damped roll its full resonance), and the fused H_s was 1.13, 1.41, 1.35, 1.18, 1.08 × the
truth on those seeds before the change, 1.24, 1.09, 1.43, 1.30 after: a coin toss, not a check.
At 9 m/s (seeds 4322–4325): heading standard deviation 1.7–5.5°, fused H_s 1.050, 1.025, 1.022, 1.055 ×
the truth before, 1.093, 1.029, 1.028, 1.058 after.

* ship as a wave buoy: H_s within 15 %, mean direction within 15°, port/starboard right, with the design
  roll tuned with the sea, on this port-quarter leg. Leg by leg not so in bow seas at speed since the
  truth's maneuvering forces see the waves' flow (the design model's roll phase is 60–105° off there):
  benchmarks/results/shipbuoy_sim.json, 13 reliable runs of 10 min: directions 7/13, H_s 5/13, sides
  9/13; 48 reliable star legs in campaign_wavefusion.json: directions 12/48, H_s 38/48, sides 23/48;
* ship as a wave buoy on a star pattern (one sea fitted to head and both bow legs; the headings tell the
  side): H_s within 15 % and direction within 15° on every leg (test_ship_as_wave_buoy_on_a_star);
* wave fusion (seed 004 eqs. 1–5) with heave + pitch takes out the radar's calibration error: fused H_s
  within 15 % while the radar is more than 25 % off (campaign of 64 25-min legs over H_s 1.5–5 m in
  benchmarks/results/campaign_wavefusion.json: radar/true std 0.246 → 0.048 fused, 39/40 within ±15 %
  above 2.5 m).
"""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from vtrials.records.netcdf import open_record, read_groups
from vtrials.reduce.design_rao import load_design_rao
from vtrials.reduce.seamotion import run_windows
from vtrials.reduce.shipbuoy import ship_buoy_from_legs, ship_buoy_from_record
from vtrials.reduce.wavefusion import fuse_run
from vtrials.runner.trial_day import simulate_agenda, write_agenda_outputs
from vtrials.scenario import load_scenario, wave_field
from vtrials.truth.seaway import sea_truth, window_heading

LEG = """
[scenario]
title = "patrol51 one seakeeping leg, port quarter seas, H_s 1.5 m, radar"
ship = "patrol51"
seed = 4322
timestep_s = 0.05
record_every = 1
truth_every = 20

[environment]
water_depth_m = 1000.0

[environment.waves]
spectrum = "pierson_moskowitz"
hs_m = 1.5
tp_s = 8.0
direction_deg = 300.0
spreading = "cos2s"
spreading_s = 10.0
n_components = 100

[environment.wind]
speed_kn = 15.0
direction_deg = 300.0

[agenda]
base_course_deg = 300.0
autopilot_rudder_deg = 20.0
turn_rudder_deg = 20.0
approach_s = 30.0
settle_min_s = 30.0
settle_max_s = 120.0
repeat_unsteady = 0

[agenda.steadiness]
window_s = 30.0
torque_pct = 5.0
speed_kn = 0.5
heading_deg = 3.0

[[agenda.trial]]
name = "seakeeping"
kind = "seakeeping"

[[agenda.trial.leg]]
heading = "quarter_port"
order = "standard"
leg_s = 420.0

[[instrument]]
name = "radar"
spec = "wave_radar_trial_calibration"
site = "transponder_mast"
"""


@pytest.fixture(scope="module")
def leg(tmp_path_factory):
    d = tmp_path_factory.mktemp("leg")
    p = d / "leg.toml"
    p.write_text(LEG)
    scn = load_scenario(p)
    write_agenda_outputs(simulate_agenda(scn), d / "out", plot=False)
    rec = open_record(d / "out" / "records" / "seakeeping.nc")
    tr = read_groups(d / "out" / "truth.nc")["groups"]["agenda"]["variables"]
    (run, t0, t1), = run_windows(rec)
    truth = sea_truth(wave_field(scn).components, window_heading(tr["time"], tr["heading"], t0, t1))
    return rec, t0, t1, truth


def test_ship_as_wave_buoy_on_a_record(leg):
    rec, t0, t1, truth = leg
    rb = ship_buoy_from_record(rec, t0, t1, load_design_rao("patrol51"))
    d = math.degrees(abs(math.remainder(math.radians(rb.from_relative_deg - truth["from_rel_deg"]), 2 * math.pi)))
    print(f"ship buoy: H_s {rb.fit.hs:.3f} vs {truth['hs']:.3f} m ({rb.fit.hs / truth['hs'] - 1:+.1%}), from "
          f"{rb.from_relative_deg:+.1f}° vs {truth['from_rel_deg']:+.1f}° off the bow (+ starboard), U {rb.U:.2f} m/s")
    assert truth["from_rel_deg"] < -90.0                  # the leg: waves from the port quarter
    assert rb.fit.hs == pytest.approx(truth["hs"], rel=0.15)
    assert d <= 15.0
    assert rb.from_relative_deg < 0.0                     # port, not its starboard mirror image


STAR = (LEG.replace("one seakeeping leg, port quarter seas, H_s 1.5 m, radar", "star: head and both bows, H_s 3.5 m")
        .replace("seed = 4322", "seed = 4400").replace("hs_m = 1.5", "hs_m = 3.5").replace("tp_s = 8.0", "tp_s = 10.65")
        .replace("n_components = 100", "n_components = 200").replace("speed_kn = 15.0", "speed_kn = 31.0")
        .split("[[agenda.trial.leg]]")[0]
        + "".join(f'[[agenda.trial.leg]]\nheading = "{h}"\norder = "standard"\nleg_s = 420.0\n\n'
                  for h in ("head", "bow_starboard", "bow_port")))


def test_ship_as_wave_buoy_on_a_star(tmp_path):
    """Three 7-min legs of a star pattern at 9 m/s in one short-crested sea (H_s 3.5 m, T_p 10.65 s, s = 10,
    from 300°): head, starboard bow, port bow. One sea fitted to the three legs (ship_buoy_from_legs, the
    design RAOs, roll tuned; the headings tell the side): H_s within 15 % and direction within 15° on
    every leg, each bow leg's side right. Measured: H_s −9.7 %, directions within 0.8° (leg by leg: the
    starboard bow 60° off); the same star on seeds 4401–4405 (with the radar aboard) −4 … −9 %, within
    11.6°."""
    (tmp_path / "star.toml").write_text(STAR)
    scn = load_scenario(tmp_path / "star.toml")
    write_agenda_outputs(simulate_agenda(scn), tmp_path / "out", plot=False)
    rec = open_record(tmp_path / "out" / "records" / "seakeeping.nc")
    tr = read_groups(tmp_path / "out" / "truth.nc")["groups"]["agenda"]["variables"]
    windows = [(t0, t1) for _, t0, t1 in run_windows(rec)]
    assert len(windows) == 3
    design = load_design_rao("patrol51")
    sb = ship_buoy_from_legs(rec, windows, design)
    assert sb.side_from == "headings"
    comp = wave_field(scn).components
    for k, (t0, t1) in enumerate(windows):
        truth = sea_truth(comp, window_heading(tr["time"], tr["heading"], t0, t1))
        d = math.degrees(abs(math.remainder(math.radians(sb.from_relative_deg(k) - truth["from_rel_deg"]), 2 * math.pi)))
        one = ship_buoy_from_record(rec, t0, t1, design)
        d1 = math.degrees(abs(math.remainder(math.radians(one.from_relative_deg - truth["from_rel_deg"]), 2 * math.pi)))
        print(f"leg {k}: waves from {truth['from_rel_deg']:+.1f}° off the bow; star fit H_s {sb.fit.hs / truth['hs'] - 1:+.1%},"
              f" direction error {d:.1f}°; this leg alone {one.fit.hs / truth['hs'] - 1:+.1%}, {d1:.1f}°")
        assert sb.fit.hs == pytest.approx(truth["hs"], rel=0.15)
        assert d <= 15.0
        if abs(truth["from_rel_deg"]) > 20.0:                 # a bow leg: on the right side
            assert math.copysign(1.0, sb.from_relative_deg(k)) == math.copysign(1.0, truth["from_rel_deg"])
        assert sb.reliable(k)


def test_wave_fusion_on_a_record_removes_the_radar_calibration_error(leg):
    rec, t0, t1, truth = leg
    f = fuse_run(rec, t0, t1, load_design_rao("patrol51"), combos=(("heave", "pitch"), ("heave",), ("pitch",)))
    radar = f.hs_radar / truth["hs"]
    fused = f.fused["heave+pitch"].hs / truth["hs"]
    print(f"radar/true {radar:.3f} ({f.n_spectra} spectra), fused (heave+pitch)/true {fused:.3f}; "
          f"heave {f.fused['heave'].hs / truth['hs']:.3f}, pitch {f.fused['pitch'].hs / truth['hs']:.3f}")
    assert f.n_spectra >= 2
    assert math.degrees(f.heading_std) <= 10.0            # the course was held: one relative wave direction
    assert abs(radar - 1.0) > 0.25                        # the trial calibration reads high
    assert abs(fused - 1.0) <= 0.15
    # r is the measured over predicted RMS, the same for any radar scale: fused H_s does not depend on it
    assert f.fused["heave+pitch"].r == pytest.approx(
        0.5 * sum(f.measured[c] / f.predicted[c] for c in ("heave", "pitch")), rel=1e-12)


def test_bad_input_is_named(leg):
    from vtrials.errors import InputError
    rec, t0, t1, _ = leg
    design = load_design_rao("patrol51")
    with pytest.raises(InputError, match="no_radar"):
        fuse_run(rec, t0, t1, design, radar="no_radar")
    with pytest.raises(InputError, match="fewer than 64 samples"):
        ship_buoy_from_record(rec, t0, t0 + 1.0, design)
    with pytest.raises(InputError, match="no legs"):
        ship_buoy_from_legs(rec, [], design)
    with pytest.raises(InputError, match="allowed heave, roll, pitch, acc"):
        fuse_run(rec, t0, t1, design, combos=(("sway",),))
