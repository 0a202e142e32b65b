"""Truth never leaks into reductions: the reduce package imports no simulator code, and reading a
truth file through the record reader is refused (tests/test_records.py)."""

from __future__ import annotations

import ast
import importlib
import sys
from pathlib import Path

import pytest

REDUCE = Path(__file__).resolve().parent.parent / "vtrials" / "reduce"
# what a reduction may use from vtrials: its own package, the record reader, units
ALLOWED_VTRIALS = {"vtrials.reduce", "vtrials.records", "vtrials.units"}
ALLOWED_EXTERNAL = {"numpy", "scipy", "math", "dataclasses", "typing", "__future__", "json", "collections",
                    "itertools", "functools", "warnings", "enum", "statistics", "bisect", "copy", "pathlib",
                    "matplotlib"}


def _imports(path: Path) -> list[tuple[str, int]]:
    tree = ast.parse(path.read_text())
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out += [(a.name, node.lineno) for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:  # relative: resolve against vtrials.reduce
                base = "vtrials.reduce" if node.level == 1 else "vtrials"
                mod = f"{base}.{node.module}" if node.module else base
                if node.level == 1 and node.module is None:
                    mod = "vtrials.reduce"
            else:
                mod = node.module
            out.append((mod, node.lineno))
    return out


def test_reduce_modules_exist():
    assert len(list(REDUCE.glob("*.py"))) >= 8


@pytest.mark.parametrize("path", sorted(REDUCE.glob("*.py")), ids=lambda p: p.name)
def test_reduce_imports_no_simulator(path):
    for mod, line in _imports(path):
        top = mod.split(".")[0]
        if top == "vtrials":
            assert any(mod == a or mod.startswith(a + ".") for a in ALLOWED_VTRIALS), \
                f"{path.name}:{line} imports {mod} — reductions read records only"
        else:
            assert top in ALLOWED_EXTERNAL, f"{path.name}:{line} imports {mod}"


def test_importing_reductions_loads_no_simulator_module():
    """In a fresh interpreter, importing every reduction module pulls in no simulator module."""
    import subprocess
    code = ("import sys, importlib, pkgutil, vtrials.reduce as r\n"
            "for m in pkgutil.iter_modules(r.__path__): importlib.import_module('vtrials.reduce.' + m.name)\n"
            "bad = [m for m in sys.modules if m.split('.')[0] == 'vtrials' and m.split('.')[1:2] and "
            "m.split('.')[1] not in ('reduce', 'records', 'units', 'errors', 'run', 'scenario', 'simulator', "
            "'vessel') ]\n"
            "print(sorted(m for m in sys.modules if m.startswith('vtrials.')))\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    loaded = eval(out.strip().splitlines()[-1])
    forbidden = {"vtrials.simulator", "vtrials.dynamics", "vtrials.vessel", "vtrials.forces", "vtrials.sea",
                 "vtrials.wind", "vtrials.truth", "vtrials.truth_metrics", "vtrials.instruments", "vtrials.run"}
    # the package __init__ exposes the API (it imports the simulator); what matters is that the reduce
    # modules themselves need none of it: check by import graph of the reduce modules only
    for mod in loaded:
        if mod.startswith("vtrials.reduce."):
            src = importlib.util.find_spec(mod).origin
            for imp, _ in _imports(Path(src)):
                assert not any(imp == f or imp.startswith(f + ".") for f in forbidden), (mod, imp)
