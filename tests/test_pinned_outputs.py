"""Every shipped scenario's records, truth and results are byte-identical to the pinned fingerprints.

The pins (``pinned_outputs.json``, made by ``tests/pins.py --update``) catch any change of behaviour:
moving code, refactoring a kernel or reordering floating-point work must leave them as they are; a
deliberate change of physics, instruments, crew or reductions updates them in the same commit.
"""

from __future__ import annotations

import json

import pytest

from pins import PINS, fingerprint, platform_tag, run_and_fingerprint, scenarios

PINNED = json.loads(PINS.read_text())


def test_pins_cover_every_shipped_scenario():
    assert sorted(PINNED["outputs"]) == sorted(s.stem for s in scenarios())


@pytest.mark.parametrize("scenario", scenarios(), ids=lambda p: p.stem)
def test_outputs_match_pins(scenario, tmp_path):
    got = run_and_fingerprint(scenario, tmp_path / scenario.stem)
    want = PINNED["outputs"][scenario.stem]
    assert sorted(got) == sorted(want), "the set of output files changed"
    changed = [k for k in want if got[k] != want[k]]
    here = platform_tag()
    where = ("" if here == PINNED["platform"] else
             f" (the pins were made on {PINNED['platform']!r}, this is {here!r}: numba compiles for the host "
             "CPU, and another instruction set may change the last bits; check that nothing else changed "
             "before regenerating them with python tests/pins.py --update)")
    assert not changed, f"outputs differ from the pins: {changed}{where}"
