"""Errors vtrials raises on bad input and on numerical failure.

Every input error names the file, the field and what is allowed, on one line, so that the CLI
can print it as is and exit non-zero before anything is written.
"""

from __future__ import annotations


class VtrialsError(Exception):
    """Base class of all errors vtrials raises on purpose."""


class InputError(VtrialsError):
    """A scenario, model or agenda file is wrong.

    Parameters
    ----------
    file:
        The file that holds the problem (path as given by the user).
    field:
        Dotted name of the offending field, e.g. ``hull.Y_v`` or ``maneuver[2].rudder_deg``.
    problem:
        What is wrong and what is allowed.
    """

    def __init__(self, file: str, field: str, problem: str):
        self.file = str(file)
        self.field = field
        self.problem = problem
        where = f"{self.file}: {field}" if field else self.file
        super().__init__(f"{where}: {problem}")


class SimulationError(VtrialsError):
    """The simulation stopped: a state became non-finite or ran away.

    The message carries the simulated time and the state at which it stopped.
    """

    def __init__(self, message: str, time_s: float | None = None, ship: int | None = None):
        self.time_s = time_s
        self.ship = ship
        super().__init__(message)
