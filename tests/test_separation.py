"""The layout follows the data flow, and truth never leaks into reductions.

* every ``vtrials`` module imports only from its own stage or from stages before it in the flow
  (docs/architecture.md); the reductions may use only the base modules and the record reader;
* in a fresh interpreter, ``import vtrials.reduce`` (and every reduction module) loads no module of
  the physics, truth, instruments, trials, score, report or runner stages, and not MuJoCo;
* reading a truth file through the record reader is refused (tests/test_records.py).
"""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import pytest

PKG = Path(__file__).resolve().parent.parent / "vtrials"
REDUCE = PKG / "reduce"

# the stages in the order data flows through them (docs/architecture.md); a module may import from its
# own stage and from earlier ones only
STAGES = ["base", "physics", "truth", "instruments", "records", "trials", "reduce", "score", "report", "app"]
STAGE_OF = {"errors": "base", "units": "base", "schema": "base", "physics": "physics", "truth": "truth",
            "instruments": "instruments", "records": "records", "trials": "trials", "reduce": "reduce",
            "score": "score", "report": "report", "scenario": "app", "runner": "app", "cli": "app",
            "campaign": "app", "plan": "app", "envs": "app", "sysid": "app", "__main__": "app", "": "app"}
# what a reduction may use from vtrials: its own package, the record reader, the base modules
ALLOWED_IN_REDUCE = {"vtrials.reduce", "vtrials.records", "vtrials.units", "vtrials.errors"}
ALLOWED_EXTERNAL = {"numpy", "scipy", "math", "dataclasses", "typing", "__future__", "json", "collections",
                    "itertools", "functools", "warnings", "enum", "statistics", "bisect", "copy", "pathlib",
                    "matplotlib", "numba"}
FORBIDDEN_AFTER_REDUCE = ("vtrials.physics", "vtrials.truth", "vtrials.instruments", "vtrials.trials",
                          "vtrials.score", "vtrials.report", "vtrials.runner", "vtrials.scenario", "mujoco")


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(PKG.parent).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def _imports(path: Path, module: str | None = None) -> list[tuple[str, int]]:
    """(imported module, line) of every import in ``path`` (as module ``module``, default its own
    name); ``from <package> import a`` counts as importing ``<package>.a`` (it may be a module)."""
    tree = ast.parse(path.read_text())
    me = (module or _module_name(path)).split(".")
    pkg = me if path.name == "__init__.py" else me[:-1]
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out += [(a.name, node.lineno) for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = pkg[:len(pkg) - (node.level - 1)]
                mod = ".".join(base + ([node.module] if node.module else []))
            else:
                mod = node.module
            if mod.split(".")[0] == "vtrials" and len(mod.split(".")) <= 2:
                out += [(f"{mod}.{a.name}", node.lineno) for a in node.names]
            else:
                out.append((mod, node.lineno))
    return out


def _stage(mod: str) -> str | None:
    parts = mod.split(".")
    if parts[0] != "vtrials":
        return None
    if len(parts) == 1 or parts[1] == "__version__":
        return "base"  # the package itself (its __init__ only defines the version and lazy names)
    return STAGE_OF.get(parts[1], "app")


def test_stage_table_covers_the_package():
    for p in PKG.iterdir():
        name = p.stem if p.suffix == ".py" else p.name
        if p.name.startswith((".", "_")) and p.name not in ("__main__.py",) or p.suffix not in (".py", ""):
            continue
        if p.is_dir() and not (p / "__init__.py").exists() and not list(p.glob("*.py")):
            continue
        assert name in STAGE_OF, f"vtrials/{p.name} has no stage in the flow: add it to STAGE_OF and the docs"


@pytest.mark.parametrize("path", sorted(p for p in PKG.rglob("*.py") if p.name != "__init__.py" or p.parent != PKG),
                         ids=lambda p: str(p.relative_to(PKG)))
def test_no_import_against_the_flow(path):
    mine = _stage(_module_name(path))
    for mod, line in _imports(path):
        theirs = _stage(mod)
        if theirs is None:
            continue
        assert STAGES.index(theirs) <= STAGES.index(mine), \
            f"{path.relative_to(PKG)}:{line} ({mine}) imports {mod} ({theirs}), a later stage of the flow"


def test_the_checks_can_fail(tmp_path):
    """The import parser sees relative, absolute and aliased imports of later stages."""
    f = tmp_path / "probe.py"
    f.write_text("from vtrials.reduce import estimate\nfrom ..report import plots as P\n"
                 "from vtrials import runner\nimport vtrials.score.trials\n")
    got = {m for m, _ in _imports(f, "vtrials.physics.probe")}
    assert got == {"vtrials.reduce.estimate", "vtrials.report.plots", "vtrials.runner", "vtrials.score.trials"}
    assert all(STAGES.index(_stage(m)) > STAGES.index("physics") for m in got)


def test_reduce_modules_exist():
    assert len(list(REDUCE.glob("*.py"))) >= 8


@pytest.mark.parametrize("path", sorted(REDUCE.glob("*.py")), ids=lambda p: p.name)
def test_reduce_imports_no_simulator(path):
    for mod, line in _imports(path):
        top = mod.split(".")[0]
        if top == "vtrials":
            assert any(mod == a or mod.startswith(a + ".") for a in ALLOWED_IN_REDUCE), \
                f"{path.name}:{line} imports {mod} — reductions read records only"
        else:
            assert top in ALLOWED_EXTERNAL, f"{path.name}:{line} imports {mod}"


def test_importing_reductions_loads_no_physics_in_a_fresh_interpreter():
    """After ``import vtrials.reduce`` and every reduction module, no module of a stage a reduction
    must not see (nor MuJoCo) is in sys.modules."""
    code = ("import sys, importlib, pkgutil, vtrials.reduce as r\n"
            "for m in pkgutil.iter_modules(r.__path__): importlib.import_module('vtrials.reduce.' + m.name)\n"
            "print(sorted(sys.modules))\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                         cwd=PKG.parent).stdout
    loaded = eval(out.strip().splitlines()[-1])
    assert any(m.startswith("vtrials.reduce.") for m in loaded)
    bad = [m for m in loaded if any(m == f or m.startswith(f + ".") for f in FORBIDDEN_AFTER_REDUCE)]
    assert not bad, f"import vtrials.reduce loaded {bad}"


def test_importing_the_package_is_light():
    """``import vtrials`` resolves its API lazily: it loads neither MuJoCo nor the simulator."""
    code = "import sys, vtrials\nprint(sorted(m for m in sys.modules if m.startswith(('vtrials', 'mujoco'))))\n"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                         cwd=PKG.parent).stdout
    assert eval(out.strip().splitlines()[-1]) == ["vtrials", "vtrials.errors"]
    # and the lazy names resolve
    code = "import vtrials\nprint(vtrials.Simulator.__module__, vtrials.run.__module__)\n"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                         cwd=PKG.parent).stdout
    assert out.split() == ["vtrials.physics.simulator", "vtrials.runner"]
