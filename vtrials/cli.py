"""Command line: ``vtrials run SCENARIO --out DIR`` (and ``vtrials models``)."""

from __future__ import annotations

import argparse
import sys
import textwrap

from vtrials import __version__
from vtrials.errors import InputError, SimulationError, VtrialsError


def _fields(cls, indent="    ") -> str:
    from vtrials.schema import doc_table
    lines = []
    for name, allowed, doc in doc_table(cls):
        lines.append(f"{indent}{name:<22} {doc} — {allowed}")
    return "\n".join(lines)


def _scenario_help() -> str:
    from vtrials.trials.programs import KINDS
    from vtrials.scenario import Environment, Head, Initial
    from vtrials.physics.environment.current import Current
    parts = [
        "Scenario file (TOML). Tables and fields (units at the edge: kn, deg; SI inside):",
        "  [scenario]", _fields(Head),
        "  [initial]   (exactly one speed field)", _fields(Initial),
        "  [environment]", _fields(Environment),
        "  [environment.current]   (directions: where the water flows to)", _fields(Current),
        "  [[maneuver]]   one table per maneuver; field 'kind' selects:",
    ]
    for kind, cls in KINDS.items():
        parts.append(f"    kind = \"{kind}\": {textwrap.shorten(cls.__doc__ or '', 150)}")
        parts.append(_fields(cls, indent="      "))
    from vtrials.trials.agenda import AgendaRules, SpeedSpec, SpotSpec, Steadiness, TrialHead
    parts += [
        "", "  [agenda]   instead of maneuvers: a trial agenda run by the virtual crew on one ship", _fields(AgendaRules),
        "  [agenda.steadiness]   how the director judges a steady approach", _fields(Steadiness),
        "  [[agenda.trial]]   one table per trial", _fields(TrialHead),
        "  [[agenda.trial.spot]]   (kind = \"standardization\") one power setting", _fields(SpotSpec),
        "  [[agenda.trial.speed]]   (kind = \"log_calibration\") one speed", _fields(SpeedSpec),
        "  An agenda writes records/<trial>.nc, truth.nc, results.json (a 'trials' list with reduced,",
        "  truth and error per trial) and report.md with PNG figures.",
    ]
    parts += [
        "",
        "Outputs in DIR: truth.nc (true state history, one netCDF group per maneuver), results.json",
        "(simulated_time_s, wall_time_s, and per maneuver name, kind and truth metrics computed",
        "from the true track through the water), trajectory.png. Nothing is written if the",
        "scenario has an error or the simulation fails. Exit status: 0 ok, 2 bad input, 3 the",
        "simulation stopped (non-finite or runaway state; the message gives time and state).",
    ]
    return "\n".join(parts)


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="vtrials",
        description="vtrials — virtual ship trials: a MuJoCo ship in a modelled sea, run through trial "
                    "maneuvers, with the true motion recorded and every result scored against it.",
        epilog="Commands:\n  run      simulate a scenario file and write truth, records, results and plots\n"
               "  inspect  list a trial record's channels, rates and units; plot chosen channels\n"
               "  campaign run many randomized replicates of an agenda; coverage and sharpness of every interval\n"
               "  render   render a run's truth as a video (MuJoCo, offscreen)\n"
               "  plan     the cheapest agenda predicted to meet an accuracy target at a site, verified by campaigns\n"
               "  identify identify the hull's maneuvering coefficients from maneuver records; predict held-back maneuvers\n"
               "  models   list the vessel models\n\nSee 'vtrials run --help' for the scenario format.",
        formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--version", action="version", version=f"vtrials {__version__}")
    sub = p.add_subparsers(dest="command", metavar="COMMAND")
    r = sub.add_parser("run", help="simulate a scenario and write its outputs",
                       description="Simulate every maneuver of SCENARIO (each from the scenario's initial "
                                   "condition, side by side in one MuJoCo batch) and write the outputs to DIR.",
                       epilog=_scenario_help(), formatter_class=argparse.RawDescriptionHelpFormatter)
    r.add_argument("scenario", metavar="SCENARIO", help="scenario file (TOML), e.g. scenarios/kvlcc2_l7_turning.toml")
    r.add_argument("--out", metavar="DIR", required=True, help="output directory (created if missing)")
    r.add_argument("--threads", type=int, default=1, metavar="N",
                   help="MuJoCo batch threads (results are identical for any N; default 1)")
    r.add_argument("--no-plot", action="store_true", help="skip trajectory.png")
    r.add_argument("--quiet", action="store_true", help="print nothing but errors")
    sub.add_parser("models", help="list the vessel models", description="List the vessel models under models/.")
    ins = sub.add_parser("inspect", help="list a trial record's channels and plot some of them",
                         description="List every instrument of a trial record (RECORD.nc) with its channels, "
                                     "sample counts, mean rates and units, and its event marks; with --plot, draw "
                                     "the chosen channels against time into a PNG.",
                         formatter_class=argparse.RawDescriptionHelpFormatter,
                         epilog="Channels are named INSTRUMENT/CHANNEL, e.g. gyro/heading knotmeter/speed.")
    ins.add_argument("record", metavar="RECORD", help="trial record file (records/*.nc written by 'vtrials run')")
    ins.add_argument("--plot", nargs="+", metavar="INSTRUMENT/CHANNEL", help="channels to plot")
    ins.add_argument("--out", metavar="PNG", help="where to write the plot (default: RECORD with .png)")
    c = sub.add_parser("campaign", help="run many randomized replicates of an agenda and measure interval coverage",
                       description="Run N replicates of an agenda scenario (each with its own draws of the "
                                   "scenario's [campaign.vary] fields and its own seed), reduce and score every "
                                   "replicate, and write campaign.parquet (one row per replicate and reduced "
                                   "quantity), summary.parquet and summary.json (coverage with its Wilson interval, "
                                   "sharpness and verdict per quantity) to DIR.",
                       epilog="[campaign] table of the scenario: replicates, seed, and [campaign.vary] with "
                              "'dotted.path' = { uniform = [lo, hi] } | { normal = [mean, sd], min, max } | "
                              "{ choice = [...] }. Results do not depend on worker count or executor.")
    c.add_argument("scenario", metavar="SCENARIO", help="agenda scenario file (TOML), with an optional [campaign]")
    c.add_argument("--out", metavar="DIR", required=True, help="output directory")
    c.add_argument("--replicates", type=int, metavar="N", help="number of replicates (default: [campaign] replicates)")
    c.add_argument("--seed", type=int, metavar="S", help="campaign seed (default: [campaign] seed)")
    c.add_argument("--executor", choices=("process", "dask"), default="process",
                   help="process: a local spawn process pool (default); dask: a Dask distributed cluster")
    c.add_argument("--address", metavar="ADDRESS", help="Dask scheduler address (with --executor dask; default: "
                                                        "a local cluster)")
    c.add_argument("--workers", type=int, metavar="K", help="worker processes (process pool; default: CPU count)")
    c.add_argument("--resume", action="store_true", help="continue a campaign killed before it finished")
    c.add_argument("--batch", type=int, default=1, metavar="B",
                   help="replicates a worker steps together in one simulator (same table for any B; faster per "
                        "replicate, B days' records in memory at once; default 1)")
    c.add_argument("--records", action="store_true", help="keep every replicate's records and truth")
    c.add_argument("--quiet", action="store_true", help="no progress bar")
    pl = sub.add_parser("plan", help="the cheapest trial agenda predicted to meet an accuracy target",
                        description="Search a family of candidate agendas (spots, runs per spot, run length), "
                                    "cheapest first, by campaigns at the plan's site climate; choose the cheapest "
                                    "predicted to meet the target; verify it and the agenda one step cheaper by "
                                    "larger campaigns. Writes plan.json, plan.md and the campaigns to DIR.",
                        epilog="Plan file (TOML): [plan] kind, scenario, seed, search_replicates, verify_replicates; "
                               "[site] water_depth_m; [climate] 'dotted.path' = { uniform | normal | choice } or a "
                               "value; [target] quantity (speed | power), rpm/pitch or order, tolerance, "
                               "confidence, rule (quantile | wilson); [limits] max_hours, max_wind_kn; "
                               "[candidates] spots, runs, run_s, neighbours, turn_s, setting_change_s. "
                               "See vtrials/plan/spec.py and scenarios/plans/plan_patrol51_standardization.toml.")
    pl.add_argument("plan", metavar="PLAN", help="plan file (TOML)")
    pl.add_argument("--out", metavar="DIR", required=True, help="output directory (an unfinished plan there resumes)")
    pl.add_argument("--replicates", type=int, metavar="N", help="replicates per search campaign (default: the plan's)")
    pl.add_argument("--verify-replicates", type=int, metavar="M",
                    help="replicates of each verifying campaign (default: the plan's)")
    pl.add_argument("--workers", type=int, default=1, metavar="W", help="worker processes per campaign (default 1)")
    pl.add_argument("--assemble", action="store_true",
                    help="run nothing: decide and report from the campaigns already in DIR (verifying campaigns "
                         "stopped short are summarized over the replicates they have)")
    pl.add_argument("--quiet", action="store_true", help="print nothing but errors")
    ren = sub.add_parser("render", help="render a run's truth as a video",
                         description="Render the ship of RUN_DIR/truth.nc in its sea with its wake (MuJoCo, "
                                     "offscreen: MUJOCO_GL=egl or osmesa where there is no display).")
    ren.add_argument("run_dir", metavar="RUN_DIR", help="a directory written by 'vtrials run'")
    ren.add_argument("--out", metavar="VIDEO", required=True, help="video file (.mp4 needs imageio-ffmpeg; .gif)")
    ren.add_argument("--run", metavar="NAME", help="which maneuver of the run (default: the first)")
    ren.add_argument("--fps", type=int, default=20, help="frames per second (default 20)")
    ren.add_argument("--speed", type=float, default=None,
                     help="simulated seconds per video second (default: the run in at most 60 s)")
    idf = sub.add_parser("identify", help="identify maneuvering coefficients from maneuver records",
                         description="Reconstruct each maneuver's motion from its records (EKF + RTS smoother), "
                                     "regress the hull forces of the team's model (3-DOF MMG or 4-DOF Blanke) on it (inverse dynamics with the "
                                     "known propeller, rudder and added mass), cross-validate model structures, "
                                     "predict the held-back maneuvers, and score all of it against the truth when "
                                     "the ship's model and the runs' results are at hand. Writes identification.json "
                                     "and identification.png to DIR.")
    idf.add_argument("records", nargs="+", metavar="RECORD", help="maneuver records (RUN_DIR/records/*.nc)")
    idf.add_argument("--model", choices=("mmg", "abkowitz", "blanke", "blanke4", "blanke3"), default=None,
                     help="hull model structure of the ship's team model (default: its first — mmg, Yasukawa & "
                          "Yoshimura 2015, for KVLCC2 L7; blanke4, Blanke & Christensen 1993, for patrol51)")
    idf.add_argument("--out", metavar="DIR", required=True, help="output directory")
    idf.add_argument("--held-back", nargs="+", default=[], metavar="RECORD",
                     help="records of maneuvers to predict (not fitted): turning circles and zig-zags")
    idf.add_argument("--all-terms", action="store_true",
                     help="predict with every term of the structure (default: the stepwise-selected terms)")
    idf.add_argument("--refine", choices=("none", "oe"), default="none",
                     help="oe: also refine the equation-error coefficients by output error (Levenberg–Marquardt fit "
                          "of the model's simulated u, v, r, heading to the smoothed ones; MMG model), reported beside them")
    idf.add_argument("--no-score", action="store_true", help="reduce only; do not compare with the truth")
    return p


def _identify(args) -> int:
    import json
    from vtrials.runner.staging import check_out, staged_output
    from vtrials.sysid.identify import identify_records
    check_out(args.out)
    doc = identify_records(args.records, args.model, not args.all_terms, args.held_back, refine=args.refine)
    if not args.no_score:
        from vtrials.score.identification import score
        doc["score"] = score(doc)
    with staged_output(args.out) as out:
        (out / "identification.json").write_text(json.dumps(doc, indent=1))
        from vtrials.report.identification import identification_plot
        identification_plot(doc, out / "identification.png")
    print(f"identified the {len(doc['coefficients'])} hull terms of {doc['structure']} for {doc['ship']} from "
          f"{len(doc['maneuvers'])} maneuver(s); {sum(len(v) for v in doc['prediction_model']['terms'].values())} "
          "kept for predictions")
    for k in doc["intervals_checked"]:
        c = doc["coefficients"].get(k)
        if c:
            sc = doc.get("score", {}).get("coefficients", {}).get(k)
            tail = f"   truth {sc['truth']:+.5g} ({100 * sc['rel_error']:+.1f} %)" if sc else ""
            print(f"  {k:<5} {c['value']:+.5g}  95 % [{c['lo95']:+.5g}, {c['hi95']:+.5g}]{tail}")
    if "output_error" in doc:
        o = doc["output_error"]
        print(f"  output error (LM, {o['nfev']} evaluations): weighted RMS {o['rms_weighted']['start']:.3f} → "
              f"{o['rms_weighted']['refined']:.3f}")
        for k in doc["intervals_checked"]:
            c = o["coefficients"].get(k)
            if c:
                sc = doc.get("score", {}).get("output_error", {}).get("coefficients", {}).get(k)
                tail = f"   truth {sc['truth']:+.5g} ({100 * sc['rel_error']:+.1f} %)" if sc else ""
                print(f"  {k:<5} {c['value']:+.5g}  95 % [{c['lo95']:+.5g}, {c['hi95']:+.5g}]{tail}  (output error)")
    for p in doc["predictions"]:
        print(f"  predicted {p['name']}: " + ", ".join(f"{k} {v:.3g}" for k, v in p["predicted"].items()))
    if "score" in doc:
        print(f"  verdict: {doc['score']['verdict']}")
    print(f"wrote {args.out}/identification.json, identification.png")
    return 0


def _campaign(args) -> int:
    from vtrials.campaign.run import run_campaign
    for name, v, lo in (("--replicates", args.replicates, 1), ("--workers", args.workers, 1), ("--seed", args.seed, 0),
                        ("--batch", args.batch, 1)):
        if v is not None and v < lo:
            raise InputError(name, "", f"must be at least {lo}")
    executor, client = None, None
    if args.executor == "dask":
        try:
            from distributed import Client
        except ImportError:
            raise InputError("--executor", "dask", "needs the dask extra: pip install 'vtrials[dask]'") from None
        client = Client(args.address) if args.address else Client(n_workers=args.workers or None)
        executor = client.get_executor()
    try:
        doc = run_campaign(args.scenario, args.out, replicates=args.replicates, seed=args.seed, executor=executor,
                           workers=args.workers, resume=args.resume, keep_records=args.records,
                           progress=not args.quiet, batch=args.batch)
    finally:
        if client is not None:
            client.close()
    if not args.quiet:
        print(f"{'quantity':<56} {'n':>5} {'coverage':>9} {'Wilson 95 %':>15} {'sharpness':>9}  verdict")
        for q in doc["quantities"]:
            print(f"{q['group']:<56} {q['n']:>5} {q['coverage']:>9.3f} "
                  f"[{q['wilson_lo']:.3f}, {q['wilson_hi']:.3f}] {q['sharpness']:>9.2f}  {q['verdict']}")
        print(f"wrote {args.out}/campaign.parquet, summary.parquet, summary.json")
    return 0


def _plan(args) -> int:
    from vtrials.plan import plan
    for name, v, lo in (("--replicates", args.replicates, 3), ("--verify-replicates", args.verify_replicates, 3),
                        ("--workers", args.workers, 1)):
        if v is not None and v < lo:
            raise InputError(name, "", f"must be at least {lo}")
    say = None if args.quiet else (lambda line: print(line, flush=True))
    doc = plan(args.plan, args.out, workers=args.workers, say=say, search_replicates=args.replicates,
               verify_replicates=args.verify_replicates, assemble=args.assemble)
    if not args.quiet:
        from pathlib import Path
        print(Path(args.out, "plan.md").read_text())
        print(f"wrote {args.out}/plan.json, plan.md")
    return 0


def _inspect(args) -> int:
    from pathlib import Path

    import numpy as np

    from vtrials.records.netcdf import RecordError, open_record
    if Path(args.record).is_dir():
        raise InputError(args.record, "", "is a directory; expected a trial record file (e.g. DIR/records/NAME.nc)")
    try:
        rec = open_record(args.record)
    except FileNotFoundError:
        raise InputError(args.record, "", "file not found") from None
    except (OSError, RecordError) as exc:
        raise InputError(args.record, "", str(exc).split(": ", 1)[-1]) from None
    print(f"{args.record}: {rec.attrs.get('title', '')}")
    print(f"{'instrument/channel':<34} {'samples':>8} {'rate [Hz]':>10}  units")
    for inst in rec.instruments:
        for ch in rec.channels(inst):
            t, x = rec.channel(inst, ch)
            rate = (len(t) - 1) / (t[-1] - t[0]) if len(t) > 1 and t[-1] > t[0] else float("nan")
            print(f"{inst + '/' + ch:<34} {len(t):>8} {rate:>10.3f}  {rec.units(inst, ch)}")
    ev = rec.events
    for tt, run, lab in zip(ev["time"], ev["run"], ev["label"]):
        print(f"event  t = {tt:10.2f} s  run {run:3d}  {lab}")
    if args.plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, axes = plt.subplots(len(args.plot), 1, figsize=(10, 2.4 * len(args.plot)), sharex=True, squeeze=False)
        for ax, name in zip(axes[:, 0], args.plot):
            inst, _, ch = name.partition("/")
            if inst not in rec.instruments or ch not in rec.channels(inst):
                raise InputError(args.record, name, "no such channel (see the list above)")
            t, x = rec.channel(inst, ch)
            ax.plot(t, x, lw=0.8)
            ax.set_ylabel(f"{name}\n[{rec.units(inst, ch)}]", fontsize=8)
            for tt in ev["time"]:
                ax.axvline(tt, color="0.7", lw=0.6, ls="--")
            ax.grid(True, alpha=0.3)
        axes[-1, 0].set_xlabel("time [s] (dashed: event marks)")
        fig.tight_layout()
        out = Path(args.out) if args.out else Path(args.record).with_suffix(".png")
        from vtrials.records.netcdf import atomic_path
        with atomic_path(out) as tmp:
            fig.savefig(tmp, dpi=100, format="png")
        plt.close(fig)
        print(f"wrote {out}")
    return 0


def summary_line(tr: dict) -> str:
    """One line of a trial's scores: the scalars of its summary (``error.summary``, or ``summary`` for
    trials scored per leg, whose entries may be one level deeper, e.g. per response)."""
    sm = (tr.get("error") or {}).get("summary", tr.get("summary", {}))
    flat = {f"{k} {k2}" if isinstance(v, dict) else k: v2
            for k, v in sm.items() for k2, v2 in (v.items() if isinstance(v, dict) else [(k, v)])}
    return f"  {tr['name']:<20} {tr['kind']:<16} " + ", ".join(
        f"{k} {v:.4g}" for k, v in flat.items() if isinstance(v, (int, float)) and not isinstance(v, bool))


def _run_agenda(scn, args) -> int:
    """An agenda: the crew's progress per run, then the scores of every trial."""
    from vtrials.runner.trial_day import simulate_agenda, write_agenda_outputs
    say = None if args.quiet else (lambda line: print(line, flush=True))
    if say:
        say(f"vtrials: {scn.head.title} — agenda of {len(scn.agenda.runs)} runs, ship {scn.vessel.name}")
    result = simulate_agenda(scn, progress=say)
    _SIMULATED[0] = result.simulated_time_s
    doc = write_agenda_outputs(result, args.out, plot=not args.no_plot)
    for tr in doc["trials"]:  # a quantity the trial's legs cannot determine is reported, not computed
        for u in tr.get("reduced", {}).get("under_determined", []):
            print(f"vtrials: warning: {tr['name']}: {u['quantity']} under-determined: {u['why']}", file=sys.stderr)
    if say:
        say(f"trial time {doc['agenda']['total_time_s'] / 3600:.2f} h simulated in {doc['wall_time_s']:.1f} s wall time")
        for tr in doc["trials"]:
            say(summary_line(tr))
        say(f"wrote {args.out}/results.json, truth.nc, records/*.nc" + ("" if args.no_plot else ", report.md"))
    return 0


_SIMULATED = [None]  # trial time simulated by the finished simulation of this call (for the Ctrl-C line)


def main(argv: list[str] | None = None) -> int:
    _SIMULATED[0] = None
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.command is None:
        parser.print_help()
        return 2
    try:
        if args.command == "models":
            from vtrials.physics.vessel import available_models, load_vessel
            for name in available_models():
                v = load_vessel(name)
                print(f"{name:<14} {v.meta.title}")
            return 0
        if args.command == "run":
            from vtrials.scenario import load_scenario
            from vtrials.runner.side_by_side import simulate, write_outputs
            from vtrials.runner.staging import check_out
            if args.threads < 1:
                raise InputError("--threads", "", "must be at least 1")
            scn = load_scenario(args.scenario)
            check_out(args.out)  # before simulating: a bad --out is found in a second, not after the run
            if scn.agenda is not None:
                return _run_agenda(scn, args)
            if not args.quiet:
                print(f"vtrials: {scn.head.title} — {len(scn.maneuvers)} maneuver(s), ship {scn.vessel.name}",
                      flush=True)
            result = simulate(scn, nthread=args.threads)
            _SIMULATED[0] = result.simulated_time_s
            doc = write_outputs(result, args.out, plot=not args.no_plot)
            if not args.quiet:
                print(f"simulated {doc['simulated_time_s']:.1f} s in {doc['wall_time_s']:.2f} s wall time")
                for m in doc["maneuvers"]:
                    keys = [k for k in m["truth"] if k != "ship_length_m"][:4]
                    summary = ", ".join(f"{k} {m['truth'][k]:.4g}" for k in keys
                                        if isinstance(m["truth"][k], (int, float)))
                    print(f"  {m['name']:<24} {m['kind']:<15} {summary}")
                print(f"wrote {args.out}/results.json, truth.nc" + ("" if args.no_plot else ", trajectory.png"))
            return 0
        if args.command == "inspect":
            return _inspect(args)
        if args.command == "campaign":
            return _campaign(args)
        if args.command == "identify":
            return _identify(args)
        if args.command == "plan":
            return _plan(args)
        if args.command == "render":
            from vtrials.envs.video import render_run
            if args.fps < 1:
                raise InputError("--fps", "", f"{args.fps}: at least 1 frame per second")
            doc = render_run(args.run_dir, args.out, fps=args.fps, speed=args.speed, run=args.run)
            print(f"wrote {doc['file']}: {doc['frames']} frames of run {doc['run']} "
                  f"({doc['simulated_s']:.0f} s simulated, {doc['speed']:.1f}x)")
            return 0
    except SimulationError as exc:
        text = str(exc)
        print(f"vtrials: {text if text.startswith('simulation stopped') else 'simulation stopped: ' + text}",
              file=sys.stderr)
        return 3
    except VtrialsError as exc:
        print(f"vtrials: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt as exc:
        t = getattr(exc, "trial_time_s", _SIMULATED[0])
        at = (" before the simulation started" if t is None else f" at trial time {t:.1f} s"
              + (" (writing the outputs)" if _SIMULATED[0] is not None else ""))
        print(f"vtrials: interrupted{at}; nothing written", file=sys.stderr)
        return 130
    except OSError as exc:  # the disk filled up, a file vanished under the run, …
        print(f"vtrials: error: {exc.filename or ''}: {exc.strerror or exc}; nothing written", file=sys.stderr)
        return 1
    return 2


if __name__ == "__main__":
    raise SystemExit(main())
