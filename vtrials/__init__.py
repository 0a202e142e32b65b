"""vtrials — a physics-based virtual ship-trial simulator.

A ship model runs in MuJoCo inside a modelled sea; a virtual crew executes trial maneuvers;
the truth is recorded and every result is scored against it. Start with :func:`run`.
"""

__version__ = "0.1.0"


def _numba_cache_dir() -> None:
    """Point numba's on-disk cache at a directory keyed by the hash of this package's sources.

    numba invalidates a cached kernel only when the kernel's own file changes, not when a kernel it
    calls (in another module) does; keying the cache on every source that uses numba (a kernel can
    only call kernels, which live in such files) rules out stale kernels, while edits elsewhere (the
    reductions, the report) keep the cache.
    """
    import hashlib
    import os
    from pathlib import Path

    if os.environ.get("NUMBA_CACHE_DIR"):
        return
    h = hashlib.sha256()
    pkg = Path(__file__).resolve().parent
    for f in sorted(pkg.rglob("*.py")):
        src = f.read_bytes()
        if b"numba" not in src and f.name not in ("units.py", "bseries.py"):  # constants kernels use
            continue
        h.update(f.relative_to(pkg).as_posix().encode())
        h.update(src)
    base = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "vtrials" / "numba"
    d = base / h.hexdigest()[:16]
    try:
        d.mkdir(parents=True, exist_ok=True)
    except OSError:
        return
    import numba

    numba.config.CACHE_DIR = str(d)


_numba_cache_dir()
# numba's OpenMP workers must not spin between kernel calls: MuJoCo's batch threads need the cores
__import__("os").environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

from .errors import InputError, SimulationError, VtrialsError  # noqa: E402
from .run import RunResult, run, simulate  # noqa: E402
from .scenario import load_scenario  # noqa: E402
from .simulator import ShipState, Simulator  # noqa: E402
from .vessel import load_vessel  # noqa: E402

__all__ = ["run", "simulate", "load_scenario", "load_vessel", "Simulator", "ShipState", "RunResult",
           "InputError", "SimulationError", "VtrialsError", "__version__"]
