"""Writing and reading the project's data files (CF-style netCDF4 through h5netcdf).

One writer for every file vtrials produces: groups of variables sharing a time dimension, each
with units and long names, written to a temporary file and renamed into place only when it is
complete, so a failed or killed run leaves no partial file. Output is byte-reproducible (no
timestamps are stored).
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from pathlib import Path

import h5netcdf
import numpy as np


@contextlib.contextmanager
def atomic_path(path: str | Path):
    """Yield a temporary path next to ``path``; on success it replaces ``path`` atomically."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    # temporaries left by a writer that was killed (never a complete file: they are renamed only
    # when finished) are removed before this one is written
    for stale in path.parent.glob(f".{path.name}.*.part"):
        with contextlib.suppress(OSError):
            stale.unlink()
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".part", dir=path.parent)
    os.close(fd)
    try:
        yield Path(tmp)
        mask = os.umask(0o022)
        os.umask(mask)
        os.chmod(tmp, 0o666 & ~mask)  # mkstemp makes the file 0600; the finished file gets the user's umask
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


def _attr(v):
    if isinstance(v, bool):
        return np.int8(v)
    if v is None:
        return ""
    return v


def write_groups(path: str | Path, groups: dict, attrs: dict) -> None:
    """Write ``groups`` = {name: {"time": array, "variables": {var: (array, units, long_name)},
    "attrs": {...}}} as netCDF4 groups with a ``time`` dimension each; ``attrs`` are global. A variable
    with more than one dimension (e.g. a wave spectrum per sample) gets dimensions ``<var>_axis1``, …
    after ``time``."""
    with atomic_path(path) as tmp:
        with h5netcdf.File(tmp, "w", track_order=True) as f:
            for k, v in attrs.items():
                f.attrs[k] = _attr(v)
            for gname, g in groups.items():
                grp = f.create_group(gname)
                t = np.asarray(g["time"], dtype=np.float64)
                grp.dimensions["time"] = t.size
                tv = grp.create_variable("time", ("time",), np.float64, compression="gzip",
                                         compression_opts=4, shuffle=True)
                tv[:] = t
                tv.attrs["units"] = "s"
                tv.attrs["long_name"] = "simulated time"
                tv.attrs["standard_name"] = "time"
                for k, v in g.get("attrs", {}).items():
                    grp.attrs[k] = _attr(v)
                for vname, (arr, units, long_name) in g["variables"].items():
                    arr = np.asarray(arr, dtype=np.float64)
                    dims = ("time",)
                    for k, n in enumerate(arr.shape[1:]):  # a spectrum per sample: extra dimensions of its own
                        dims += (f"{vname}_axis{k + 1}",)
                        grp.dimensions[dims[-1]] = n
                    var = grp.create_variable(vname, dims, np.float64, compression="gzip",
                                              compression_opts=4, shuffle=True)
                    var[:] = arr
                    var.attrs["units"] = units
                    var.attrs["long_name"] = long_name


def read_groups(path: str | Path) -> dict:
    """Read a file written by :func:`write_groups` back into plain numpy arrays and dicts."""
    out = {"attrs": {}, "groups": {}}
    with h5netcdf.File(path, "r") as f:
        out["attrs"] = {k: _plain(v) for k, v in f.attrs.items()}
        for gname, grp in f.groups.items():
            g = {"attrs": {k: _plain(v) for k, v in grp.attrs.items()}, "variables": {}, "units": {}}
            for vname, var in grp.variables.items():
                g["variables"][vname] = np.asarray(var[:])
                g["units"][vname] = _plain(var.attrs.get("units", ""))
            out["groups"][gname] = g
    return out


def groups_as_read(groups: dict, attrs: dict) -> dict:
    """What :func:`read_groups` returns for a file that :func:`write_groups` would write from ``groups``
    and ``attrs`` — without writing it: the same float64 arrays, units and attribute values (booleans
    as integers, ``None`` as "", sequences as arrays), in the same order. A campaign replicate reduces
    such in-memory records exactly as it would the files (tests/test_campaign_fastpath.py checks the
    two are equal)."""

    def attr(v):
        v = _attr(v)
        if isinstance(v, (list, tuple)):
            v = np.asarray(v)
        return _plain(v)

    out = {"attrs": {k: attr(v) for k, v in attrs.items()}, "groups": {}}
    for gname, g in groups.items():
        variables = {"time": np.array(g["time"], dtype=np.float64)}
        units = {"time": "s"}
        for vname, (arr, u, _long_name) in g["variables"].items():
            variables[vname] = np.array(arr, dtype=np.float64)
            units[vname] = u
        out["groups"][gname] = {"attrs": {k: attr(v) for k, v in g.get("attrs", {}).items()},
                                "variables": variables, "units": units}
    return out


def _plain(v):
    if isinstance(v, np.ndarray) and v.ndim == 0:
        return v.item()
    if isinstance(v, np.generic):
        return v.item()
    if isinstance(v, bytes):
        return v.decode()
    return v


# --------------------------------------------------------------------------- trial records (reader)
import json  # noqa: E402


class RecordError(ValueError):
    """A file that is not a trial record (or a truth file offered to a reduction)."""


class Record:
    """A trial record as a trials team has it: instrument channels on their own clocks, event marks
    and the team's knowledge (ship particulars, surveyed positions, nominal calibrations).

    Opening a truth file raises :class:`RecordError`: reductions never read truth.
    """

    def __init__(self, path: str | Path, data: dict | None = None):
        self.path = Path(path)
        data = read_groups(self.path) if data is None else data
        content = data["attrs"].get("content")
        if content != "record":
            raise RecordError(f"{self.path}: not a trial record (content = {content!r}); reductions read "
                              f"records only")
        self.attrs = data["attrs"]
        self._groups = data["groups"]
        self.team = json.loads(self.attrs.get("team_knowledge", "{}"))

    @property
    def instruments(self) -> list[str]:
        return [g for g in self._groups if not g.startswith("_")]

    def channels(self, instrument: str) -> list[str]:
        return [v for v in self._groups[instrument]["variables"] if v != "time"]

    def channel(self, instrument: str, name: str) -> tuple[np.ndarray, np.ndarray]:
        """(time [s] on the instrument's own clock, values in SI units)."""
        g = self._groups[instrument]
        return g["variables"]["time"], g["variables"][name]

    def units(self, instrument: str, name: str) -> str:
        return self._groups[instrument]["units"].get(name, "")

    def meta(self, instrument: str) -> dict:
        a = dict(self._groups[instrument]["attrs"])
        for k, v in list(a.items()):
            if isinstance(v, str) and v[:1] in "{[":
                try:
                    a[k] = json.loads(v)
                except ValueError:
                    pass
        return a

    @property
    def events(self) -> dict:
        """Event marks as logged by the data acquisition system: time, run number, code, label."""
        g = self._groups.get("_events")
        if g is None:
            return {"time": np.zeros(0), "run": np.zeros(0, int), "code": np.zeros(0, int), "label": []}
        codes = json.loads(g["attrs"]["codes"])
        code = g["variables"]["code"].astype(int)
        return {"time": g["variables"]["time"], "run": g["variables"]["run"].astype(int), "code": code,
                "label": [codes[str(c)] for c in code]}


    @property
    def run_log(self) -> list[dict]:
        """The director's log sheet: one entry per executed run (course, settings, COMEX/EXECUTE/FINEX
        times, steadiness verdicts, whether the run was accepted); empty for single maneuvers."""
        return json.loads(self.attrs.get("run_log", "[]") or "[]")

    def attr(self, name: str, default=None):
        """A file attribute, JSON-decoded when it holds JSON."""
        v = self.attrs.get(name, default)
        if isinstance(v, str) and v[:1] in "{[":
            try:
                return json.loads(v)
            except ValueError:
                return v
        return v


def open_record(path: str | Path) -> Record:
    """Open a trial record for reading (numpy arrays out)."""
    return Record(path)


def record_in_memory(path: str | Path, groups: dict, attrs: dict) -> Record:
    """The record :func:`write_groups` would write to ``path`` from ``groups`` and ``attrs``, as
    :func:`open_record` would read it back — but nothing is written (:func:`groups_as_read`)."""
    return Record(path, groups_as_read(groups, attrs))
