"""Fingerprints of the shipped scenarios' outputs, pinned so that a change of behaviour is always seen.

``fingerprint(out_dir)`` hashes every record file and ``truth.nc`` byte for byte, and ``results.json``
with its wall-clock entries (``wall_time_s``, ``timings``) removed. The pins in ``pinned_outputs.json``
were made before the package was reorganised (issue 9) and hold as long as no physics, instrument,
crew or reduction behaviour changes. They are specific to the machine kind that made them (numba
compiles for the host CPU; a different instruction set may change the last bits): the file records
that platform, and the test names it when the outputs differ (measured: the pins made on an AMD EPYC
machine hold byte for byte on an Intel Xeon one, so the platform is information, not a gate). After a deliberate change of behaviour, or on a new machine kind after checking that
nothing else changed, regenerate them with

    python tests/pins.py --update          # runs every shipped scenario (a few minutes)
    python tests/pins.py --update NAME ...  # only the named scenarios (file stems); the others' pins kept
"""

from __future__ import annotations

import hashlib
import json
import platform
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PINS = Path(__file__).resolve().parent / "pinned_outputs.json"
WALL_KEYS = ("wall_time_s", "timings")


def _strip(obj):
    if isinstance(obj, dict):
        return {k: _strip(v) for k, v in obj.items() if k not in WALL_KEYS}
    if isinstance(obj, list):
        return [_strip(v) for v in obj]
    return obj


def fingerprint(out_dir: Path) -> dict[str, str]:
    """{relative file name: sha256} of a run's records, truth and results (less wall times)."""
    out_dir = Path(out_dir)
    fp = {}
    for f in sorted(out_dir.rglob("*.nc")):
        fp[f.relative_to(out_dir).as_posix()] = hashlib.sha256(f.read_bytes()).hexdigest()
    res = json.loads((out_dir / "results.json").read_text())
    canon = json.dumps(_strip(res), sort_keys=True, separators=(",", ":"))
    fp["results.json"] = hashlib.sha256(canon.encode()).hexdigest()
    return fp


def platform_tag() -> str:
    import numba
    import numpy
    import mujoco
    cpu = "unknown"
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return (f"{platform.machine()} {cpu}; python {platform.python_version()}; numpy {numpy.__version__}; "
            f"numba {numba.__version__}; mujoco {mujoco.__version__}")


def scenarios() -> list[Path]:
    return sorted((ROOT / "scenarios").glob("*.toml"))


def run_and_fingerprint(scenario: Path, out: Path) -> dict[str, str]:
    import vtrials
    vtrials.run(str(scenario), str(out), plot=False)
    return fingerprint(out)


def main(argv: list[str]) -> int:
    if "--update" not in argv:
        print(__doc__)
        return 2
    names = [a for a in argv if a != "--update"]
    known = {s.stem for s in scenarios()}
    unknown = sorted(set(names) - known)
    if unknown:
        print(f"no shipped scenario named {', '.join(unknown)} (scenarios/*.toml stems)")
        return 2
    if names:  # only these: the other scenarios keep their pins (made on the platform the file names)
        pins = json.loads(PINS.read_text())
        pins["outputs"] = {k: v for k, v in pins["outputs"].items() if k in known}
        if pins["platform"] != platform_tag():
            print(f"note: the other pins were made on {pins['platform']!r}, this is {platform_tag()!r}")
    else:
        pins = {"platform": platform_tag(), "outputs": {}}
    with tempfile.TemporaryDirectory() as tmp:
        for s in [s for s in scenarios() if not names or s.stem in names]:
            pins["outputs"][s.stem] = run_and_fingerprint(s, Path(tmp) / s.stem)
            print(s.stem, "pinned", flush=True)
    PINS.write_text(json.dumps(pins, indent=1, sort_keys=True) + "\n")
    return 0


if __name__ == "__main__":
    sys.path.insert(0, str(ROOT))
    raise SystemExit(main(sys.argv[1:]))
