"""Identification campaign (issue 16): replicates of an identification agenda, each with its own
instrument draws, identified from its records and scored against the true model.

``--ship kvlcc2_l7`` (default): each replicate runs ``scenarios/kvlcc2_l7_identification.toml`` with a
scenario seed spawned from the campaign seed (numpy SeedSequence: the same table for any worker count),
identifies the hull (``vtrials.sysid.identify``, BIC-selected MMG; no cross-validation, to save time)
and predicts the held-back 35° port turn and 20/20 zig-zags, whose records come from one run of the
held-back scenarios (the sea is calm, so their truth does not change between replicates; only the
identified model does). ``--ship patrol51``: ``scenarios/patrol51_identification.toml`` (4-DOF Blanke
model), the held-back 25° port turn and 20/20 zig-zag recorded in each replicate's own run.
With ``--noise-scale 2`` every instrument's stated errors (noise, biases, drifts, correlated errors) are
doubled through the scenario's instrument overrides — the records AND the team's stated accuracies,
as for a worse instrument suite.

Reports per linear derivative: coverage of the 95 % interval with its Wilson interval, sharpness (mean
half-width over the 95 % quantile of |error|), mean and RMS relative error; the worst held-back
prediction errors; and the growth of the RMS errors from noise ×1 to ×2.

    python benchmarks/campaign_identification.py --replicates 100 --workers 2 \
        --out benchmarks/results/campaign_identification.json
    python benchmarks/campaign_identification.py --ship patrol51 --replicates 100 \
        --out benchmarks/results/campaign_identification_patrol51.json
    python benchmarks/campaign_identification.py --smoother --replicates 100 \
        --out benchmarks/results/campaign_identification_smoother.json     # states and covariance vs truth
    python benchmarks/campaign_identification.py --replicates 100 --workers 3 --noise-scale 1 \
        --out benchmarks/results/campaign_identification_bandwidth.json    # the regression's bandwidth study

Every row also holds the regression's random σ of the linear derivatives at fixed Newey–West bandwidths
(0–400 samples) and Andrews' (the rule before the study), so the summary's ``bandwidth_study`` gives the
coverage and sharpness each bandwidth rule would have had on the same replicates. ``--refine oe`` adds
the output-error refinement (about 20 s of CPU per replicate) on the first ``--oe-replicates``.
The results file is rewritten every 5 replicates (``"partial": true`` until the end).
"""

from __future__ import annotations

import argparse
import json
import shutil
import sys
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))


# the suite of models/kvlcc2_l7/instruments.toml with every stated error doubled (catalogue values x2)
DOUBLED = """
[[instrument]]
name = "tracking"
spec = "rtk_gnss"
site = "gnss_antenna"
[instrument.set]
gauss_markov = { sd = 0.02, tau_s = 60.0 }
multipath = { sd = 0.01, tau_s = 5.0 }
noise = 0.01

[[instrument]]
name = "gyro"
spec = "gyrocompass"
site = "gyro"
[instrument.set]
north_seeking = false
bias = { mean = 0.0, sd = 0.3 }
gauss_markov = { sd = 0.16, tau_s = 900.0 }
noise = 0.06

[[instrument]]
name = "imu"
spec = "imu_tactical"
site = "imu"
[instrument.set]
accel_bias_ug = { mean = 0.0, sd = 200.0 }
accel_gauss_markov_ug = { sd = 100.0, tau_s = 100.0 }
accel_noise_mps2 = 0.004
gyro_bias_dph = { mean = 0.0, sd = 4.0 }
gyro_gauss_markov_dph = { sd = 2.0, tau_s = 300.0 }
gyro_noise_dps = 0.01
misalignment_deg = 0.1

[[instrument]]
name = "rudder"
spec = "rudder_synchro"
rudder = "main"
[instrument.set]
bias = { mean = 0.0, sd = 0.24 }
noise = 0.06

[[instrument]]
name = "rpm"
spec = "shaft_counter"
shaft = "main"
[instrument.set]
bias = { mean = 0.0, sd = 0.5 }
"""


# patrol51: its scenario's instrument entries (identification DAQ clock) with every stated error doubled
# (catalogue values x2), inserted as [instrument.set] tables after each entry's clock line
DOUBLED_PATROL = {
    "rtk": 'gauss_markov = { sd = 0.02, tau_s = 60.0 }\nmultipath = { sd = 0.01, tau_s = 5.0 }\nnoise = 0.01',
    "gyro": 'bias = { mean = 0.0, sd = 0.3 }\ngauss_markov = { sd = 0.16, tau_s = 900.0 }\nnoise = 0.06',
    "imu": ('accel_bias_ug = { mean = 0.0, sd = 200.0 }\naccel_gauss_markov_ug = { sd = 100.0, tau_s = 100.0 }\n'
            'accel_noise_mps2 = 0.004\ngyro_bias_dph = { mean = 0.0, sd = 4.0 }\n'
            'gyro_gauss_markov_dph = { sd = 2.0, tau_s = 300.0 }\ngyro_noise_dps = 0.01\nmisalignment_deg = 0.1'),
    "vertical_gyro": 'bias = { mean = 0.0, sd = 0.2 }\nnoise = 0.06',
    "rudder_port": 'bias = { mean = 0.0, sd = 0.24 }\nnoise = 0.06',
    "rudder_starboard": 'bias = { mean = 0.0, sd = 0.24 }\nnoise = 0.06',
    "rpm_port": 'bias = { mean = 0.0, sd = 0.5 }',
    "rpm_starboard": 'bias = { mean = 0.0, sd = 0.5 }',
    "pitch_port": 'bias = { mean = 0.0, sd = 0.02 }\nbias_per_K = 0.002',
    "pitch_starboard": 'bias = { mean = 0.0, sd = 0.02 }\nbias_per_K = 0.002',
}


def _double_patrol(text: str) -> str:
    for name, lines in DOUBLED_PATROL.items():
        head = f'name = "{name}"\n'
        i = text.index(head)
        j = text.index('clock = "gnss_disciplined_clock"\n', i) + len('clock = "gnss_disciplined_clock"\n')
        if text.startswith("[instrument.set]\n", j):   # the entry has its own set table: add to it
            j += len("[instrument.set]\n")
            text = text[:j] + lines + "\n" + text[j:]
        else:
            text = text[:j] + "[instrument.set]\n" + lines + "\n" + text[j:]
    return text


SHIPS = {
    "kvlcc2_l7": {"scenario": ROOT / "scenarios" / "kvlcc2_l7_identification.toml", "seed_line": "seed = 16",
                  "held_back_scenarios": (ROOT / "scenarios" / "kvlcc2_l7_turning.toml",
                                          ROOT / "scenarios" / "kvlcc2_l7_zigzag.toml"),
                  "held_back": ("turn_35_port", "zigzag_20_20_*"), "linear": ("Y_v", "Y_r", "N_v", "N_r"),
                  "double": lambda text: text + DOUBLED},
    "patrol51": {"scenario": ROOT / "scenarios" / "patrol51_identification.toml", "seed_line": "seed = 161",
                 "held_back_scenarios": (), "held_back": ("turn_25_port", "zigzag_20_20_starboard"),
                 "linear": ("Y_uv", "Y_ur", "N_uv", "N_ur"), "double": _double_patrol},
}


def _scenario(ship: str, seed: int, scale: int, where: Path) -> Path:
    cfg = SHIPS[ship]
    text = cfg["scenario"].read_text().replace(cfg["seed_line"], f"seed = {seed}", 1)
    if "seed = %d" % seed not in text:
        raise RuntimeError("the identification scenario's seed line changed; update this script")
    if scale == 2:
        text = cfg["double"](text)
    elif scale != 1:
        raise ValueError("noise scale 1 or 2")
    p = where / f"identification_{scale}_{seed}.toml"
    p.write_text(text)
    return p


def _replicate(args) -> dict:
    ship, i, seed, scale, held, tmp, refine = args
    import vtrials
    from vtrials.score.identification import score
    from vtrials.sysid.identify import identify_records
    work = Path(tmp) / f"r{scale}_{i}"
    work.mkdir(parents=True, exist_ok=True)
    try:
        scn = _scenario(ship, seed, scale, work)
        vtrials.run(str(scn), str(work / "run"), plot=False)
        recs = sorted((work / "run" / "records").glob("*.nc"))
        if not held:   # held back from the replicate's own run
            held = [p for p in recs if p.stem in SHIPS[ship]["held_back"]]
        train = [p for p in recs if p not in held]
        doc = identify_records(train, None, True, held, compare=(), with_contributions=False,
                               refine=refine, diagnostics=True)
        sc = score(doc)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    row = {"replicate": i, "seed": seed, "scale": scale, "coefficients": {}, "predictions": sc["predictions"],
           "terms": doc["prediction_model"]["terms"]}
    for k in SHIPS[ship]["linear"]:
        c, s = doc["coefficients"][k], sc["coefficients"][k]
        row["coefficients"][k] = {"value": c["value"], "lo95": c["lo95"], "hi95": c["hi95"], "truth": s["truth"],
                                  "rel_error": s["rel_error"], "covered": s["covered"],
                                  "std_random": c["std_random"], "std_systematic": c["std_systematic"],
                                  "std_random_by_lags": doc["diagnostics"]["sigma_random"][k],
                                  "std_random_andrews": doc["diagnostics"]["sigma_random_andrews"][k]}
        if "output_error" in doc:
            c, s = doc["output_error"]["coefficients"][k], sc["output_error"]["coefficients"][k]
            row.setdefault("output_error", {})[k] = {
                "value": c["value"], "lo95": c["lo95"], "hi95": c["hi95"], "truth": s["truth"],
                "rel_error": s["rel_error"], "covered": s["covered"], "std_random": c["std_random"],
                "std_systematic": c["std_systematic"]}
    if "output_error" in doc:
        row["output_error_fit"] = {k: doc["output_error"][k] for k in ("rms_weighted", "improved", "nfev", "lags")}
    row["bandwidth"] = {eq: {key: d[key] for key in ("andrews_lags", "plateau_lags", "lag1") if key in d}
                        | {"segment_mean": float(np.mean(d["segment_samples"]))}
                        for eq, d in doc["diagnostics"].items() if eq in "XYNK"}
    return row


def _levelled_truth(g, step_s: float, t) -> dict:
    """The true states the navigation filter estimates (:mod:`vtrials.sysid.navfilter`), at times ``t``:
    the velocity of the reference point (midship, waterline) along and across the heading in the
    horizontal plane and the heading rate, from the truth group ``g`` with its velocities and rates
    taken at the rows' instants (:class:`vtrials.instruments.kinematics.SiteKinematics`)."""
    from vtrials.instruments.kinematics import SiteKinematics
    from vtrials.score.compat import truth_columns
    cols = truth_columns(g, g["time"][:], step_s)
    kin = SiteKinematics(cols, np.zeros(3))
    (u, v, w), (_, q, r) = kin.nu.T, kin.omega.T
    ph, th = cols["roll"], cols["pitch"]
    sp, cp, st, ct = np.sin(ph), np.cos(ph), np.sin(th), np.cos(th)
    lev = {"u": ct * u + st * (sp * v + cp * w), "v": cp * v - sp * w, "r": (q * sp + r * cp) / ct}
    return {k: np.interp(t, cols["t"], x) for k, x in lev.items()}


def _smoother(args) -> dict:
    """One replicate's smoother check: every maneuver reconstructed from its records and compared with
    the truth of what the filter estimates (midship, levelled heading frame, at the rows' instants:
    :func:`_levelled_truth`): RMS error and the fraction of samples inside ±1.96 σ."""
    ship, i, seed, tmp = args
    import h5py
    import vtrials
    from vtrials.sysid import records as RE
    work = Path(tmp) / f"s_{i}"
    work.mkdir(parents=True, exist_ok=True)
    out = {"replicate": i, "seed": seed, "states": {}}
    try:
        vtrials.run(str(_scenario(ship, seed, 1, work)), str(work / "run"), plot=False)
        with h5py.File(work / "run" / "truth.nc") as truth:
            step = float(truth.attrs["timestep_s"][0])
            for p in sorted((work / "run" / "records").glob("*.nc")):
                mr = RE.read_maneuver(p)
                sol = RE.reconstruct(mr)
                tru = _levelled_truth(truth[mr.name], step, sol.t)
                for k in ("u", "v", "r"):
                    e = sol.state(k) - tru[k]
                    out["states"].setdefault(k, []).append(
                        (float(np.sqrt(np.mean(e**2))), float(np.mean(np.abs(e) <= 1.96 * sol.sigma(k)))))
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return out


def _bandwidth_study(rs, LINEAR) -> dict:
    """Coverage and sharpness of the linear derivatives' 95 % intervals had the regression's random σ
    come from a fixed Newey–West bandwidth (samples), or from the largest σ over the bandwidths up to
    400 and Andrews' (the pipeline's rule since the study, :func:`vtrials.sysid.identify.random_sigma`),
    or with the fixed-b widening at a fixed bandwidth; "andrews (before)": Andrews' AR(1) bandwidth alone
    (the pipeline before the study); "reported": the intervals the rows hold (the code that ran them).
    Each with the record-wide errors' σ added as in the pipeline."""
    from vtrials.score.coverage import verdict
    Z = 1.959963984540054
    from vtrials.sysid.output_error import fixed_b_factor
    lags = list(rs[0]["coefficients"][LINEAR[0]]["std_random_by_lags"])
    out = {}
    for rule in ["andrews (before)", "reported"] + lags + [f"{L}+fixed_b" for L in lags] + ["max over 0-400 and Andrews'"]:
        per = {}
        for k in LINEAR:
            c = [r["coefficients"][k] for r in rs]
            if rule.startswith("max over"):   # the pipeline's rule (vtrials.sysid.identify.random_sigma)
                sr = np.array([max(max(x["std_random_by_lags"].values()), x["std_random_andrews"]) for x in c])
            elif rule == "reported":
                sr = np.array([x["std_random"] for x in c])
            elif rule == "andrews (before)":
                sr = np.array([x["std_random_andrews"] for x in c])
            elif rule.endswith("+fixed_b"):
                L = rule.split("+")[0]
                sr = np.array([x["std_random_by_lags"][L] * fixed_b_factor(int(L) / r["bandwidth"][k[0]]["segment_mean"])
                               for x, r in zip(c, rs)])
            else:
                sr = np.array([x["std_random_by_lags"][rule] for x in c])
            sd = np.hypot(sr, [x["std_systematic"] for x in c])
            err = np.array([x["value"] - x["truth"] for x in c])
            v = verdict(list(np.abs(err) <= Z * sd), Z * sd, err)
            per[k] = {key: v[key] for key in ("coverage", "wilson_lo", "wilson_hi", "sharpness", "verdict")}
        out[rule] = per
    return out


def summarise(rows: list[dict]) -> dict:
    from vtrials.score.coverage import verdict
    LINEAR = tuple(rows[0]["coefficients"])
    out = {}
    for scale in sorted({r["scale"] for r in rows}):
        rs = [r for r in rows if r["scale"] == scale]
        per = {}
        for k in LINEAR:
            c = [r["coefficients"][k] for r in rs]
            err = np.array([x["value"] - x["truth"] for x in c])
            half = np.array([(x["hi95"] - x["lo95"]) / 2 for x in c])
            v = verdict([x["covered"] for x in c], half, err)
            rel = np.array([x["rel_error"] for x in c])
            v.update(mean_rel_error=float(rel.mean()), rms_rel_error=float(np.sqrt(np.mean(rel**2))),
                     max_abs_rel_error=float(np.abs(rel).max()))
            per[k] = v
        worst = {}
        for r in rs:
            for p in r["predictions"]:
                for key, e in p["errors"].items():
                    val = abs(e.get("rel_error", e.get("error_deg")))
                    worst[key] = max(worst.get(key, 0.0), val)
        out[f"noise_x{scale}"] = {"replicates": len(rs), "linear": per, "worst_prediction_error": worst}
        oe_rows = [r for r in rs if "output_error" in r]
        if oe_rows:
            oe = {}
            for k in LINEAR:
                c = [r["output_error"][k] for r in oe_rows]
                err = np.array([x["value"] - x["truth"] for x in c])
                v = verdict([x["covered"] for x in c], np.array([(x["hi95"] - x["lo95"]) / 2 for x in c]), err)
                rel = np.array([x["rel_error"] for x in c])
                # the equation-error estimate on the same replicates, for comparison
                rel_ee = np.array([r["coefficients"][k]["rel_error"] for r in oe_rows])
                v.update(mean_rel_error=float(rel.mean()), rms_rel_error=float(np.sqrt(np.mean(rel**2))),
                         max_abs_rel_error=float(np.abs(rel).max()),
                         rms_rel_error_equation_error_same_replicates=float(np.sqrt(np.mean(rel_ee**2))))
                oe[k] = v
            out[f"noise_x{scale}"]["output_error"] = {
                "replicates": len(oe_rows), "linear": oe,
                "improved_fit": int(sum(r["output_error_fit"]["improved"] for r in oe_rows))}
        if all("std_random_by_lags" in r["coefficients"][LINEAR[0]] for r in rs):
            out[f"noise_x{scale}"]["bandwidth_study"] = _bandwidth_study(rs, LINEAR)
    if "noise_x1" in out and "noise_x2" in out:
        out["rms_growth_x2"] = {k: out["noise_x2"]["linear"][k]["rms_rel_error"]
                                / out["noise_x1"]["linear"][k]["rms_rel_error"] for k in LINEAR}
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--ship", choices=tuple(SHIPS), default="kvlcc2_l7")
    ap.add_argument("--replicates", type=int, default=100)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--seed", type=int, default=2016)
    ap.add_argument("--noise-scale", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--refine", choices=("none", "oe"), default="none",
                    help="also the output-error (LM) refinement, scored beside the equation-error estimate")
    ap.add_argument("--oe-replicates", type=int, default=10**9,
                    help="output error on the first N replicates of the nominal suite only (it costs ~20 s each)")
    ap.add_argument("--smoother", action="store_true",
                    help="check the smoother's states and covariance against truth instead (no identification)")
    ap.add_argument("--out", default=str(ROOT / "benchmarks" / "results" / "campaign_identification.json"))
    ap.add_argument("--resummarise", metavar="JSON",
                    help="recompute a results file's intervals by the pipeline's bandwidth rule from the σ its rows "
                         "store (the first replicates of campaign_identification_bandwidth.json ran with a first cut "
                         "that added the fixed-b widening) and its summary; rewritten in place")
    a = ap.parse_args(argv)
    if a.resummarise:
        return _resummarise(Path(a.resummarise))
    if a.smoother:
        return _smoother_campaign(a)
    import vtrials
    t0 = time.perf_counter()
    seeds = [int(s.generate_state(1)[0] % 2**31) for s in np.random.SeedSequence(a.seed).spawn(a.replicates)]
    with tempfile.TemporaryDirectory() as tmp:
        held = []
        cfg = SHIPS[a.ship]
        for scn in cfg["held_back_scenarios"]:
            d = Path(tmp) / scn.stem
            vtrials.run(str(scn), str(d), plot=False)
            held += [p for pat in cfg["held_back"] for p in sorted((d / "records").glob(f"{pat}.nc"))]
        jobs = [(a.ship, i, s, scale, [str(h) for h in held], tmp,
                 "oe" if a.refine == "oe" and scale == 1 and i < a.oe_replicates else None)
                for scale in a.noise_scale for i, s in enumerate(seeds)]
        rows = []
        with ProcessPoolExecutor(a.workers) as ex:
            for k, row in enumerate(ex.map(_replicate, jobs)):
                rows.append(row)
                if (k + 1) % 5 == 0:
                    print(f"{k + 1}/{len(jobs)} replicates, {time.perf_counter() - t0:.0f} s", flush=True)
                    partial = {"ship": a.ship, "campaign_seed": a.seed, "replicates": a.replicates, "partial": True,
                               "wall_s": time.perf_counter() - t0, "summary": summarise(rows), "rows": rows}
                    Path(a.out).parent.mkdir(parents=True, exist_ok=True)
                    Path(a.out).write_text(json.dumps(partial, indent=1))
    doc = {"ship": a.ship, "campaign_seed": a.seed, "replicates": a.replicates, "wall_s": time.perf_counter() - t0,
           "summary": summarise(rows), "rows": rows}
    Path(a.out).parent.mkdir(parents=True, exist_ok=True)
    Path(a.out).write_text(json.dumps(doc, indent=1))
    print(json.dumps(doc["summary"], indent=1))
    return 0


def _projection(before: dict, rows: list) -> dict:
    """The earlier 100-replicate campaign (same seeds, Andrews' bandwidth) with each interval widened by
    the mean ratio of the new rule's σ to the old one over the replicates run here (paired: the same
    seeds give the same estimates) — a projection, not a measurement."""
    from vtrials.score.coverage import verdict
    old = [r for r in before["rows"] if r["scale"] == 1]
    out = {}
    for k in rows[0]["coefficients"]:
        c = [r["coefficients"][k] for r in rows]
        ratio = np.array([np.hypot(x["std_random"], x["std_systematic"]) / np.hypot(x["std_random_andrews"],
                                                                                  x["std_systematic"]) for x in c])
        co = [r["coefficients"][k] for r in old]
        err = np.array([x["value"] - x["truth"] for x in co])
        half = np.array([(x["hi95"] - x["lo95"]) / 2 for x in co]) * ratio.mean()
        v = verdict(list(np.abs(err) <= half), half, err)
        out[k] = {"sigma_ratio_mean": float(ratio.mean()), "sigma_ratio_sd": float(ratio.std()), "replicates": len(co),
                  **{key: v[key] for key in ("coverage", "wilson_lo", "wilson_hi", "sharpness", "verdict")}}
    return out


def _resummarise(path: Path) -> int:
    """Each row's linear-derivative intervals by the pipeline's rule (vtrials.sysid.identify.random_sigma:
    the largest Newey–West σ over the bandwidths 0–400 samples and Andrews', ⊕ the record-wide σ) from the
    σ components the row stores — the same arithmetic as the pipeline — the row's original interval kept
    as ``as_run``; then the summary."""
    Z = 1.959963984540054
    doc = json.loads(path.read_text())
    for r in doc["rows"]:
        for k, c in r["coefficients"].items():
            if "std_random_by_lags" not in c:
                continue
            c.setdefault("as_run", {key: c[key] for key in ("lo95", "hi95", "covered", "std_random")})
            sr = max(max(c["std_random_by_lags"].values()), c["std_random_andrews"])
            sd = float(np.hypot(sr, c["std_systematic"]))
            c.update(std_random=sr, lo95=c["value"] - Z * sd, hi95=c["value"] + Z * sd,
                     covered=bool(abs(c["value"] - c["truth"]) <= Z * sd))
    doc["summary"] = summarise(doc["rows"])
    before = path.parent / "campaign_identification.json"
    if before.is_file() and path.resolve() != before.resolve():
        doc["summary"]["projection_over_the_earlier_100"] = _projection(json.loads(before.read_text()), doc["rows"])
    doc["resummarised"] = "intervals by the pipeline's plateau rule from the stored σ (as_run: the first cut's)"
    path.write_text(json.dumps(doc, indent=1))
    print(json.dumps({k: v for k, v in doc["summary"].items()}, indent=1)[:3000])
    return 0


def _smoother_campaign(a) -> int:
    t0 = time.perf_counter()
    seeds = [int(s.generate_state(1)[0] % 2**31) for s in np.random.SeedSequence(a.seed).spawn(a.replicates)]
    with tempfile.TemporaryDirectory() as tmp, ProcessPoolExecutor(a.workers) as ex:
        rows = list(ex.map(_smoother, [(a.ship, i, s, tmp) for i, s in enumerate(seeds)]))
    summary = {}
    for k in ("u", "v", "r"):
        rms = np.array([x[0] for r in rows for x in r["states"][k]])
        cov = np.array([x[1] for r in rows for x in r["states"][k]])
        summary[k] = {"records": int(rms.size), "median_rms": float(np.median(rms)), "max_rms": float(rms.max()),
                      "mean_coverage": float(cov.mean()), "min_coverage": float(cov.min())}
    doc = {"ship": a.ship, "campaign_seed": a.seed, "replicates": a.replicates, "wall_s": time.perf_counter() - t0,
           "smoother": summary, "rows": rows}
    Path(a.out).parent.mkdir(parents=True, exist_ok=True)
    Path(a.out).write_text(json.dumps(doc, indent=1))
    print(json.dumps(summary, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
