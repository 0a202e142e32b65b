"""Running a scenario: the one code path behind ``vtrials run`` and :func:`vtrials.run`.

* :mod:`.side_by_side` — a list of ``[[maneuver]]`` programs, one ship each, stepped together; truth
  metrics and (optionally) instrument records per maneuver;
* :mod:`.trial_day` — an ``[agenda]`` run by the virtual crew on one ship: records, reductions,
  scoring against truth, report.
"""

from __future__ import annotations

from pathlib import Path

from vtrials.scenario import load_scenario


def run(scenario_path: str | Path, out_dir: str | Path, nthread: int = 1, plot: bool = True,
        progress=None):
    """Load, check, simulate and write a scenario. A scenario with an ``[agenda]`` goes through
    :mod:`vtrials.runner.trial_day` (crew, records, reductions, scoring, report); one with
    ``[[maneuver]]`` tables through :mod:`vtrials.runner.side_by_side`."""
    from vtrials.errors import InputError
    from vtrials.runner.staging import check_out
    if isinstance(nthread, bool) or not isinstance(nthread, int) or nthread < 1:
        raise InputError("run()", "nthread", f"expected an integer ≥ 1 (MuJoCo batch threads), got {nthread!r}")
    scn = load_scenario(scenario_path)
    check_out(out_dir)  # before simulating
    if scn.agenda is not None:
        from vtrials.runner.trial_day import simulate_agenda, write_agenda_outputs
        result = simulate_agenda(scn, progress=progress)
        write_agenda_outputs(result, out_dir, plot=plot)
        return result
    from vtrials.runner.side_by_side import simulate, write_outputs
    result = simulate(scn, nthread=nthread, progress=progress)
    write_outputs(result, out_dir, plot=plot)
    return result
