"""Seakeeping star-pattern trial (issue 13): agenda checks, the legs' courses relative to the observed
waves, and a short simulated trial whose transfer functions are scored against the truth RAOs."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from vtrials.cli import main
from vtrials.trials.agenda import WAVE_RELATIVE_DEG, Run
from vtrials.trials.seakeeping import leg_course

SHORT_PATH = Path(__file__).resolve().parent / "data" / "patrol51_seakeeping_short.toml"
SHORT = SHORT_PATH.read_text()


def _bad(tmp_path, capsys, text):
    p = tmp_path / "a.toml"
    p.write_text(text)
    out = tmp_path / "out"
    code = main(["run", str(p), "--out", str(out), "--quiet"])
    err = capsys.readouterr().err.strip()
    assert code == 2
    assert len(err.splitlines()) == 1, err
    assert str(p) in err
    assert not out.exists(), "nothing may be written for a bad agenda"
    return err


@pytest.mark.parametrize("edit, field, words", [
    (lambda s: s.replace('heading = "bow_starboard"', 'heading = "starboard_bow"'), "agenda.trial[0].leg[1].heading",
     "starboard_bow"),
    (lambda s: s.replace('heading = "bow_starboard"', 'heading = "bow_starboard"\nstation_keeping = true'),
     "agenda.trial[0].leg[1].heading", "station-keeping leg is held head to the sea"),
    (lambda s: s.replace('leg_s = 360.0\n\n[[agenda.trial.leg]]\nheading = "bow_starboard"',
                         'leg_s = 10.0\n\n[[agenda.trial.leg]]\nheading = "bow_starboard"'), "agenda.trial[0].leg[0].leg_s",
     "10"),
    (lambda s: s.replace('heading = "head"\norder = "ahead_1_3"', 'heading = "head"\norder = "back_1_3"'),
     "agenda.trial[0].leg[0].order", "ahead order"),
    (lambda s: s.replace('heading = "head"\norder = "ahead_1_3"', 'heading = "head"\nrpm = 300.0'),
     "agenda.trial[0].leg[0].pitch", "controllable-pitch"),
    (lambda s: s.replace("hs_m = 0.75", "hs_m = 0.0"), "agenda.trial[0].kind", "needs a wind sea"),
    (lambda s: s.replace('heading = "head"\norder', 'heading = "head"\nspeed_kn = 8.0\norder'), "agenda.trial[0].leg[0]",
     "speed_kn"),
])
def test_bad_seakeeping_agenda(tmp_path, capsys, edit, field, words):
    assert edit(SHORT) != SHORT, "the edit must change the scenario"
    err = _bad(tmp_path, capsys, edit(SHORT))
    assert field in err and words in err, err


def test_leg_courses_relative_to_the_observed_waves():
    """Waves observed coming from 300°: head seas steer 300°, following 120°, waves on the starboard bow
    (from 45° to starboard of the bow) 255°, on the port beam 030°, on the starboard quarter 165°."""
    team = {"sea_observed": [{"from_rad": math.radians(300.0)}]}
    want = {"head": 300.0, "following": 120.0, "bow_starboard": 255.0, "beam_port": 30.0, "quarter_starboard": 165.0,
            "bow_port": 345.0, "beam_starboard": 210.0, "quarter_port": 75.0}
    for name, course in want.items():
        run = Run(1, "sk", "seakeeping", 0.0, 5.0, 0.6, ("governed",), 600.0, 0.3, 1, 1, name, None,
                  {"wave_relative": math.radians(WAVE_RELATIVE_DEG[name])})
        got = math.degrees(leg_course(team, run)) % 360.0
        assert abs(got - course) < 1e-9, (name, got, course)
        # the database's relative heading of the waves' travel: β = μ − ψ = from + 180° − course
        beta = (300.0 + 180.0 - got) % 360.0
        assert abs(((beta - (180.0 + WAVE_RELATIVE_DEG[name])) + 180.0) % 360.0 - 180.0) < 1e-9


def test_true_transfer_of_a_component_sea_is_what_h1_estimates():
    """The scorer's true transfer function (expected Hann-window cross-spectra of the components,
    :func:`vtrials.score.seakeeping.binned_transfer`) against H₁ of records built from the same
    components: 400 sinusoids with random phases, a quarter of them met at negative encounter
    frequencies (overtaking waves: recorded at |ω_e| with the conjugate transfer function), a smooth
    complex H plus direction-like scatter of its phase (so γ² < 1). H₁'s own 95 % intervals
    (Bendat & Piersol) must cover the binned truth in about 95 % of the bins with γ² > 0.8
    (Wilson-interval rule of the house), and the truth must beat the unbinned H at the bin centre."""
    from vtrials.reduce.transfer import transfer_function
    from vtrials.score.coverage import wilson
    from vtrials.score.seakeeping import binned_transfer
    rng = np.random.default_rng(13)
    n, fs, T, Ts = 400, 10.0, 1500.0, 120.0
    we = rng.uniform(0.3, 2.5, n) * np.where(rng.uniform(size=n) < 0.25, -1.0, 1.0)
    amp = 0.05 * np.exp(-((np.abs(we) - 1.0) / 0.6) ** 2) + 0.005
    Hc = (1.0 / (1.0 - (np.abs(we) / 1.2) ** 2 + 0.3j * np.abs(we) / 1.2)) * np.exp(1j * rng.normal(0.0, 0.35, n))
    H = np.where(we < 0, np.conj(Hc), Hc)  # so that the recorded (|ω_e|) transfer function is Hc
    t = np.arange(int(T * fs)) / fs
    ph = rng.uniform(0, 2 * np.pi, n)
    arg = we[:, None] * t[None, :] + ph[:, None]
    x = amp @ np.cos(arg)
    y = (amp * np.abs(H)) @ np.cos(arg + np.angle(H)[:, None])
    y += rng.normal(0.0, 0.002, t.size)  # output noise
    tf = transfer_function(x, y, fs, int(Ts * fs))
    Ht, coh = binned_transfer(amp, we, H, tf.omega, Ts)
    sel = (tf.coherence > 0.8) & (tf.omega > 0.4) & (tf.omega < 2.4)
    assert sel.sum() >= 25
    lo, hi = tf.amplitude_interval()
    hit = ((lo <= np.abs(Ht)) & (np.abs(Ht) <= hi))[sel]
    cov = float(np.mean(hit))
    err = np.abs(tf.amplitude / np.abs(Ht) - 1.0)[sel]
    print(f"bins {sel.sum()}, amplitude coverage {cov:.3f}, median |error| {np.median(err):.3f}")
    w_lo, w_hi = wilson(int(hit.sum()), int(hit.size))
    assert w_lo <= 0.95 <= w_hi or 0.90 <= cov <= 0.99, (cov, w_lo, w_hi)
    # without the conjugation of the overtaking components the phase would be wrong: the check has teeth
    Hbad, _ = binned_transfer(amp, np.abs(we), H, tf.omega, Ts)
    dph_good = np.abs(np.angle(tf.H * np.conj(Ht)))[sel]
    dph_bad = np.abs(np.angle(tf.H * np.conj(Hbad)))[sel]
    assert np.median(dph_good) < 0.5 * np.median(dph_bad)


# ----------------------------------------------------------------------------------- a short simulated trial
@pytest.fixture(scope="module")
def short_trial(tmp_path_factory):
    import json
    import vtrials
    out = tmp_path_factory.mktemp("seakeeping")
    res = vtrials.run(SHORT_PATH, out, plot=True)
    doc = json.loads((out / "results.json").read_text())
    return res, doc, out


def _trial(doc):
    return [t for t in doc["trials"] if t["kind"] == "seakeeping"][0]


def test_short_trial_legs_records_and_report(short_trial):
    """Every leg steered on its course relative to the OBSERVED wave direction (not the true one), the
    wave probe and the motion sensors in the record, the report pages written."""
    from vtrials.records.netcdf import open_record
    res, doc, out = short_trial
    rec = open_record(out / "records" / "seakeeping.nc")
    frm = math.degrees(rec.team["sea_observed"][0]["from_rad"])
    for a in rec.run_log:
        want = (frm - WAVE_RELATIVE_DEG[a["maneuver"]["wave_heading"]]) % 360.0
        assert abs(((a["course_deg"] - want) + 180.0) % 360.0 - 180.0) < 1e-6
        assert a["accepted"]
    kinds = {rec.meta(n)["kind"] for n in rec.instruments}
    assert {"wave_probe", "imu", "attitude"} <= kinds
    t, eta = rec.channel("bow_probe", "elevation")
    assert 0.6 < 4.0 * float(np.std(eta)) < 0.9  # the sea's H_s is 0.75 m
    report = (out / "report.md").read_text()
    assert "seakeeping star pattern" in report
    for f in ("seakeeping_polar.png", "seakeeping_rms.png", "seakeeping_tf_run1.png"):
        assert (out / f).stat().st_size > 10_000


def test_short_trial_rms_motions_and_probe_hs(short_trial):
    """RMS heave (strapdown with orientation, from the IMU), vertical acceleration, roll and pitch of each
    leg against the true motions of the same window (the record's own RMS: what is left is the
    instruments' error and the strapdown's high-pass: accelerometer noise 0.002 m/s² against 0.1 m/s²,
    the vertical gyro's 0.03° noise and 0.05° steps against 0.5–4°), within 2 % (measured: 0.25 %); the
    probe's H_s interval covers the sea's H_s."""
    _, doc, _ = short_trial
    tr = _trial(doc)
    for leg in tr["legs"]:
        assert leg["hs_probe"]["covered"], leg["hs_probe"]
        for n in ("heave", "vertical_acc", "roll", "pitch"):
            assert abs(leg["rms"][n]["error"]) <= 0.02, (leg["label"], n, leg["rms"][n])


def test_short_trial_transfer_functions_against_the_truth(short_trial):
    """Issue 13's acceptance — transfer functions within 10 % of the truth where γ² > 0.8, with intervals
    that cover — on the 6-min head-seas leg (the 25-min legs: benchmarks/seakeeping_transfer.py).

    How often an estimate lies within 10 % is set by its random error, which on a 6-min leg (n_d ≈ 6
    averages) is twice that of a 25-min leg; so the share within 10 % is compared with the share the
    reduction's own random error allows, Σ_b P(|t_ν| ≤ 0.10/ε_b)/n (ν = 2n_d − 2): the measured share
    may fall short of it by at most two binomial standard deviations. The 95 % amplitude intervals must
    cover the truth by the house rule (Wilson interval of the coverage contains 0.95, or the coverage
    lies in [0.90, 0.99]). Heave and vertical acceleration are the same record (a factor −ω_e²): their
    bins are pooled with pitch's all the same, each response being scored as the report shows it."""
    from vtrials.score.coverage import wilson
    _, doc, _ = short_trial
    tr = _trial(doc)
    head = [L for L in tr["legs"] if L["label"].startswith("head")][0]
    n_tot, within, expected, var, covered = 0, 0, 0.0, 0.0, 0
    for name in ("heave", "vertical_acc", "pitch"):
        t = head["transfer"][name]
        assert t["bins"] >= 12, (name, t["bins"])  # the head-seas leg is well determined
        err = np.abs(np.asarray(t["amp_error"]))
        n_tot += err.size
        within += int(np.sum(err <= 0.10))
        expected += t["expected_within_10pct"] * err.size
        var += t["expected_within_10pct_var"] * err.size ** 2
        covered += int(np.sum(t["amp_covered"]))
        print(f"{name}: {err.size} bins, median |err| {np.median(err):.3f}, within 10 % {np.mean(err <= 0.1):.2f} "
              f"(random error allows {t['expected_within_10pct']:.2f}), amplitude coverage {t['amp_coverage']:.2f}")
    assert within >= expected - 2.0 * math.sqrt(var), (within, expected, math.sqrt(var))
    lo, hi = wilson(covered, n_tot)
    assert lo <= 0.95 <= hi or 0.90 <= covered / n_tot <= 0.99, (covered, n_tot, lo, hi)
    # roll in head seas is driven by the oblique waves the bow probe cannot tell apart: no bin is determined
    assert head["transfer"]["roll"]["bins"] == 0


def test_short_trial_ship_as_wave_buoy_scored(short_trial):
    """The trial's reduction carries the ship as a wave buoy — one sea fitted to both legs with the team's
    design RAOs, the two headings (45° apart) telling port from starboard — and the scoring sets it against
    the true sea per leg, in results.json and the report. In a small sea (H_s 0.75 m) on 6-min legs:
    H_s within 15 % and direction within 15° on both legs (measured: H_s −12.6 %, directions +4.3° and +3.7°)."""
    res, doc, out = short_trial
    tr = _trial(doc)
    sb, sc = tr["reduced"]["ship_buoy"], tr["ship_buoy"]
    assert sb["side_from"] == "headings" and len(sb["legs"]) == len(tr["legs"]) == 2
    for leg in sc["legs"]:
        print(f"run {leg['run']} {leg['label']}: H_s {leg['hs_error']:+.1%}, waves from {leg['from_rel_deg']:+.1f}° "
              f"(true {leg['from_rel_true_deg']:+.1f}°), error {leg['dir_error_deg']:+.1f}°")
        assert abs(leg["hs_error"]) <= 0.15
        assert abs(leg["dir_error_deg"]) <= 15.0 and leg["side_right"]
    assert sc["summary"]["all"]["both"] == 2
    assert "The ship as a wave buoy" in (out / "report.md").read_text()


def test_short_trial_wave_fusion_scored(short_trial):
    """With the wave radar as installed aboard (trial calibration, seed 004: reads about 1.5 × the sea),
    the trial's reduction fuses it with the measured heave and pitch through the design RAOs (seed 004
    eqs. 1–5) on every leg, and the scoring sets radar and fused H_s against the true sea, in results.json,
    the report's table and its fusion figure. On these 6-min legs in a 0.75-m sea the radar (this
    installation's draw) reads 0.61 and 0.72 × the sea; heave + pitch fused 0.85 and 0.91: fusion takes
    out the radar's scale, and what is left is the design model's (it over-predicts heave and pitch in
    head and bow seas, models/patrol51/design/README.md; seed 004's 15 % is for seas above 2.5 m,
    benchmarks/campaign_wavefusion.py). Checked: the radar more than 25 % off, the fused error less than
    half the radar's on each leg, and within 20 %."""
    res, doc, out = short_trial
    tr = _trial(doc)
    wf, sc = tr["reduced"]["wave_fusion"], tr["wave_fusion"]
    assert wf["radar"] == "radar" and len(wf["legs"]) == len(tr["legs"]) == 2
    for leg, red in zip(sc["legs"], wf["legs"]):
        f = leg["fused_ratio"]
        print(f"run {leg['run']} {leg['label']}: radar/true {leg['radar_ratio']:.3f}, fused heave+pitch "
              f"{f['heave+pitch']:.3f}, heave {f['heave']:.3f}, pitch {f['pitch']:.3f} ({red['n_spectra']} spectra)")
        assert red["n_spectra"] >= 2
        assert abs(leg["radar_ratio"] - 1.0) > 0.25
        assert abs(f["heave+pitch"] - 1.0) < 0.5 * abs(leg["radar_ratio"] - 1.0)
        assert abs(f["heave+pitch"] - 1.0) <= 0.20
        # r is the mean of the measured over predicted RMS of the two components (seed 004 eq. 5)
        r = 0.5 * sum(red["measured_rms"][c] / red["predicted_rms"][c] for c in ("heave", "pitch"))
        assert red["hs_fused"]["heave+pitch"] == pytest.approx(r * red["hs_radar"], rel=1e-12)
    report = (out / "report.md").read_text()
    assert "Wave fusion (seed 004)" in report
    assert (out / "seakeeping_fusion.png").stat().st_size > 10_000


def test_wave_estimates_left_out_with_a_note(short_trial, monkeypatch):
    """Without the team's design model for the ship, or on legs too short for two Welch segments, the
    seakeeping reduction gives no ship-as-buoy (or fusion) result and says why in its notes."""
    from vtrials.records.netcdf import open_record
    from vtrials.reduce.seakeeping import BUOY_MIN_LEG_S, _by_kind, ship_buoy_block, wave_fusion_block
    _, _, out = short_trial
    rec = open_record(out / "records" / "seakeeping.nc")
    kinds = _by_kind(rec)
    rec.team = dict(rec.team, ship="no_such_ship")
    notes = []
    assert ship_buoy_block(rec, kinds, notes) is None and wave_fusion_block(rec, kinds, notes) is None
    assert len(notes) == 2 and all("no design-stage RAO model for 'no_such_ship'" in n for n in notes)
    rec = open_record(out / "records" / "seakeeping.nc")
    notes = []
    runs = rec.run_log
    for run in runs:                                   # a log sheet whose legs were short
        run["t_finex"] = run["t_execute"] + 0.5 * BUOY_MIN_LEG_S
    monkeypatch.setattr(type(rec), "run_log", property(lambda self: runs))
    assert ship_buoy_block(rec, kinds, notes) is None
    assert "shorter than 256 s" in notes[0]
