"""vtrials — a physics-based virtual ship-trial simulator.

A ship model runs in MuJoCo inside a modelled sea; a virtual crew executes trial maneuvers;
the truth is recorded and every result is scored against it. Start with :func:`run`.
"""

__version__ = "0.1.0"

from .errors import InputError, SimulationError, VtrialsError  # noqa: E402
from .run import RunResult, run, simulate  # noqa: E402
from .scenario import load_scenario  # noqa: E402
from .simulator import ShipState, Simulator  # noqa: E402
from .vessel import load_vessel  # noqa: E402

__all__ = ["run", "simulate", "load_scenario", "load_vessel", "Simulator", "ShipState", "RunResult",
           "InputError", "SimulationError", "VtrialsError", "__version__"]
