"""vtrials — a physics-based virtual ship-trial simulator.

A ship model runs in MuJoCo inside a modelled sea; a virtual crew executes trial maneuvers;
the truth is recorded and every result is scored against it. Start with :func:`run`.

The package is laid out along the data flow (docs/architecture.md): ``physics`` → ``truth``
(references) and ``instruments`` → ``records`` → ``reduce`` → ``score`` → ``report``, with ``trials``
(agenda, crew, controllers) driving the physics and ``runner`` / ``cli`` composing the stages.
Importing the package loads nothing heavy: the names below are resolved on first use, so
``import vtrials.reduce`` never loads the simulator.
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
    import sys

    if "numba" in sys.modules:  # already imported: its configuration is read, set it directly
        sys.modules["numba"].config.CACHE_DIR = str(d)
    else:  # numba reads this when it is first imported (and spawned workers inherit it)
        os.environ["NUMBA_CACHE_DIR"] = str(d)


_numba_cache_dir()
# numba's OpenMP workers must not spin between kernel calls: MuJoCo's batch threads need the cores
__import__("os").environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

from vtrials.errors import InputError, SimulationError, VtrialsError  # noqa: E402

_LAZY = {
    "run": ("vtrials.runner", "run"),
    "simulate": ("vtrials.runner.side_by_side", "simulate"),
    "RunResult": ("vtrials.runner.side_by_side", "RunResult"),
    "load_scenario": ("vtrials.scenario", "load_scenario"),
    "load_vessel": ("vtrials.physics.vessel", "load_vessel"),
    "Simulator": ("vtrials.physics.simulator", "Simulator"),
    "ShipState": ("vtrials.physics.simulator", "ShipState"),
}


def __getattr__(name: str):
    """Resolve the public API on first use (PEP 562), so that importing one stage loads no other."""
    if name in _LAZY:
        import importlib
        mod, attr = _LAZY[name]
        value = getattr(importlib.import_module(mod), attr)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'vtrials' has no attribute {name!r}")


__all__ = ["run", "simulate", "load_scenario", "load_vessel", "Simulator", "ShipState", "RunResult",
           "InputError", "SimulationError", "VtrialsError", "__version__"]
