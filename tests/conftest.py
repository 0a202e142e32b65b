"""Shared fixtures: scenario runs are expensive enough to share within a module."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
SCENARIOS = ROOT / "scenarios"
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))


@pytest.fixture(scope="session")
def scenarios_dir() -> Path:
    return SCENARIOS


def pytest_collection_modifyitems(config, items):
    """Under pytest-xdist (``--dist loadgroup``): a module's tests stay on one worker, so its
    module-scoped scenario runs are made once; the pinned-output tests (one whole scenario each, no
    shared fixture) go first and are spread over the workers one by one, longest first, so the
    longest scenario does not start last."""
    if not config.pluginmanager.hasplugin("xdist"):
        return
    pinned = [it for it in items if it.nodeid.startswith("tests/test_pinned_outputs.py::test_outputs_match_pins")]
    rest = [it for it in items if it not in pinned]
    for it in rest:
        it.add_marker(pytest.mark.xdist_group(it.nodeid.split("::", 1)[0]))
    # the seakeeping star pattern (about 5 min) first, then the others in their own order
    pinned.sort(key=lambda it: "patrol51_seakeeping]" not in it.nodeid)
    items[:] = pinned + rest
