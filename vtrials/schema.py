"""Checked reading of TOML tables into typed dataclasses.

Model, scenario and agenda files are read through this one module so that every bad input gets
the same kind of message: file, dotted field name, what was wrong, what is allowed. Declare a
parameter with :func:`num`, :func:`text`, :func:`flag` or :func:`integer` as a dataclass field;
:func:`read_table` then checks a TOML table against the dataclass:

* unknown keys are errors (with the closest known name suggested),
* missing keys without a default are errors,
* values must have the declared type and lie in the declared range,
* in *sourced* tables (ship model files) every number must name its source, either inline
  (``Y_v = { value = -0.315, source = "..." }``) or through a ``source`` key of the table that
  applies to its bare numbers.
"""

from __future__ import annotations

import dataclasses
import difflib
import math
import tomllib
from pathlib import Path
from typing import Any

from vtrials.errors import InputError

_SPEC = "vtrials_spec"


@dataclasses.dataclass(frozen=True)
class Spec:
    """What a field accepts."""

    kind: str  # "num", "int", "text", "flag"
    doc: str = ""
    unit: str = ""
    lo: float | None = None
    hi: float | None = None
    lo_open: bool = False
    hi_open: bool = False
    choices: tuple[str, ...] = ()
    required: bool = True

    def allowed(self) -> str:
        if self.kind == "vec":
            lo = "-inf" if self.lo is None else f"{self.lo:g}"
            hi = "inf" if self.hi is None else f"{self.hi:g}"
            unit = f" {self.unit}" if self.unit else ""
            return f"a list of numbers in [{lo}, {hi}]{unit}"
        if self.kind == "text":
            return "one of " + ", ".join(repr(c) for c in self.choices) if self.choices else "a string"
        if self.kind == "flag":
            return "true or false"
        what = "an integer" if self.kind == "int" else "a number"
        lo = "-inf" if self.lo is None else f"{self.lo:g}"
        hi = "inf" if self.hi is None else f"{self.hi:g}"
        if self.lo is None and self.hi is None:
            rng = ""
        else:
            rng = f" in {'(' if self.lo_open or self.lo is None else '['}{lo}, {hi}{')' if self.hi_open or self.hi is None else ']'}"
        unit = f" {self.unit}" if self.unit else ""
        return f"{what}{rng}{unit}"


def _field(spec: Spec, default: Any) -> Any:
    md = {_SPEC: spec}
    if default is dataclasses.MISSING:
        return dataclasses.field(metadata=md)
    return dataclasses.field(default=default, metadata=md)


def num(doc: str = "", unit: str = "", lo: float | None = None, hi: float | None = None, *,
        lo_open: bool = False, hi_open: bool = False, default: Any = dataclasses.MISSING) -> Any:
    """A real-valued field in [lo, hi] (open ends with lo_open/hi_open)."""
    return _field(Spec("num", doc, unit, lo, hi, lo_open, hi_open, required=default is dataclasses.MISSING), default)


def vector(doc: str = "", unit: str = "", lo: float | None = None, hi: float | None = None, *,
           default: Any = dataclasses.MISSING) -> Any:
    """A list of real numbers, each in [lo, hi]."""
    return _field(Spec("vec", doc, unit, lo, hi, required=default is dataclasses.MISSING), default)


def integer(doc: str = "", lo: int | None = None, hi: int | None = None, *, default: Any = dataclasses.MISSING) -> Any:
    """An integer field in [lo, hi]."""
    return _field(Spec("int", doc, "", lo, hi, required=default is dataclasses.MISSING), default)


def text(doc: str = "", choices: tuple[str, ...] = (), *, default: Any = dataclasses.MISSING) -> Any:
    """A string field, optionally restricted to choices."""
    return _field(Spec("text", doc, choices=tuple(choices), required=default is dataclasses.MISSING), default)


def flag(doc: str = "", *, default: Any = dataclasses.MISSING) -> Any:
    """A boolean field."""
    return _field(Spec("flag", doc, required=default is dataclasses.MISSING), default)


def spec_of(f: dataclasses.Field) -> Spec | None:
    return f.metadata.get(_SPEC)


def load_toml(path: str | Path) -> dict:
    """Parse a TOML file; a missing or malformed file is an :class:`InputError` naming it."""
    p = Path(path)
    try:
        raw = p.read_bytes()
    except FileNotFoundError:
        raise InputError(str(path), "", "file not found") from None
    except OSError as exc:
        raise InputError(str(path), "", f"cannot read file ({exc.strerror})") from None
    try:
        return tomllib.loads(raw.decode("utf-8"))
    except UnicodeDecodeError:
        raise InputError(str(path), "", "not UTF-8 text; a TOML file is expected") from None
    except tomllib.TOMLDecodeError as exc:
        raise InputError(str(path), "", f"malformed TOML: {exc}") from None


def unknown_key(file: str, section: str, key: str, known: list[str]) -> InputError:
    """The error for a key that a table does not have, with the closest known names."""
    close = difflib.get_close_matches(key, known, n=1, cutoff=0.6)
    hint = f"; did you mean {close[0]!r}?" if close else ""
    allowed = ", ".join(sorted(known)) if len(known) <= 40 else f"{len(known)} known names"
    return InputError(file, _join(section, key), f"unknown field{hint} (allowed: {allowed})")


def _join(section: str, key: str) -> str:
    return f"{section}.{key}" if section else key


def check_value(spec: Spec, value: Any, file: str, name: str) -> Any:
    """Check one value against its spec; return it converted (int→float for numbers)."""
    if spec.kind in ("num", "int"):
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise InputError(file, name, f"expected {spec.allowed()}, got {_short(value)}")
        if spec.kind == "int":
            if isinstance(value, float):
                if not value.is_integer():
                    raise InputError(file, name, f"expected {spec.allowed()}, got {value!r}")
                value = int(value)
        else:
            value = float(value)
            if not math.isfinite(value):
                raise InputError(file, name, f"expected a finite number ({spec.allowed()}), got {value!r}")
        lo_bad = spec.lo is not None and (value < spec.lo or (spec.lo_open and value == spec.lo))
        hi_bad = spec.hi is not None and (value > spec.hi or (spec.hi_open and value == spec.hi))
        if lo_bad or hi_bad:
            raise InputError(file, name, f"{value!r} is out of range: expected {spec.allowed()}")
        return value
    if spec.kind == "vec":
        if not isinstance(value, list) or not value:
            raise InputError(file, name, f"expected {spec.allowed()}, got {value!r}")
        item = Spec("num", spec.doc, spec.unit, spec.lo, spec.hi)
        return tuple(check_value(item, x, file, f"{name}[{k}]") for k, x in enumerate(value))
    if spec.kind == "text":
        if not isinstance(value, str):
            raise InputError(file, name, f"expected {spec.allowed()}, got {value!r}")
        if spec.choices and value not in spec.choices:
            close = difflib.get_close_matches(value, spec.choices, n=1, cutoff=0.6)
            hint = f"; did you mean {close[0]!r}?" if close else ""
            raise InputError(file, name, f"{_short(value)} is not allowed{hint}: expected {spec.allowed()}")
        return value
    if spec.kind == "flag":
        if not isinstance(value, bool):
            raise InputError(file, name, f"expected {spec.allowed()}, got {value!r}")
        return value
    raise AssertionError(spec.kind)


def read_table(cls: type, table: Any, file: str, section: str, *, sourced: bool = False,
               extra_keys: tuple[str, ...] = ()) -> tuple[Any, dict[str, str]]:
    """Read a TOML table into dataclass ``cls``.

    Returns the instance and, for sourced tables, a dict field → source text. Keys in
    ``extra_keys`` are tolerated (the caller reads them).
    """
    if not isinstance(table, dict):
        raise InputError(file, section, f"expected a table, got {type(table).__name__} {table!r}")
    fields = {f.name: f for f in dataclasses.fields(cls) if spec_of(f) is not None}
    values: dict[str, Any] = {}
    sources: dict[str, str] = {}
    default_source = None
    if sourced:
        default_source = table.get("source")
        if default_source is not None and not (isinstance(default_source, str) and default_source.strip()):
            raise InputError(file, _join(section, "source"), "expected a non-empty string naming the source")
    for key, raw in table.items():
        if sourced and key == "source":
            continue
        if key in extra_keys:
            continue
        if key not in fields:
            raise unknown_key(file, section, key, list(fields) + list(extra_keys))
        name = _join(section, key)
        spec = spec_of(fields[key])
        value = raw
        if sourced and spec.kind in ("num", "int", "vec"):
            if isinstance(raw, dict):
                bad = set(raw) - {"value", "source", "unit", "note"}
                if bad:
                    raise InputError(file, name, f"unknown keys {sorted(bad)} (allowed: value, source, unit, note)")
                if "value" not in raw:
                    raise InputError(file, name, "inline table without 'value'")
                src = raw.get("source", default_source)
                if not (isinstance(src, str) and src.strip()):
                    raise InputError(file, name, "no source given: add source = \"...\" (inline or for the table)")
                for k in ("unit", "note"):
                    if k in raw and not isinstance(raw[k], str):
                        raise InputError(file, f"{name}.{k}", f"expected a string, got {_short(raw[k])}")
                unit = raw.get("unit")
                if unit is not None and spec.unit and unit != spec.unit:
                    raise InputError(file, name, f"unit {unit!r} given, but this field is in {spec.unit!r} (SI)")
                value = raw["value"]
                sources[key] = src.strip()
            else:
                if default_source is None:
                    raise InputError(file, name, "no source given: write { value = ..., source = \"...\" } "
                                                 "or give the table a source")
                sources[key] = default_source.strip()
        values[key] = check_value(spec, value, file, name)
    for key, f in fields.items():
        if key in values:
            continue
        if spec_of(f).required:
            raise InputError(file, _join(section, key), f"missing (expected {spec_of(f).allowed()})")
    return cls(**values), sources


def doc_table(cls: type) -> list[tuple[str, str, str]]:
    """(name, allowed, doc) for every declared field of cls — used by --help texts and docs."""
    rows = []
    for f in dataclasses.fields(cls):
        s = spec_of(f)
        if s is not None:
            rows.append((f.name, s.allowed(), s.doc))
    return rows


# ------------------------------------------------------------------ shared checks
NAME_PATTERN = r"[A-Za-z0-9][A-Za-z0-9_.-]{0,63}"
NAME_ALLOWED = ("a name of 1 to 64 characters: letters, digits, '_', '-', '.', starting with a letter or "
                "digit (it becomes a file name)")


def check_name(value: Any, file: str, name: str) -> str:
    """A name that becomes a file or group name (maneuver, trial, instrument): the safe pattern
    :data:`NAME_PATTERN` — no path separators, no '.' or '..', no NUL, at most 64 characters."""
    import re
    if not isinstance(value, str):
        raise InputError(file, name, f"expected {NAME_ALLOWED}, got {_short(value)}")
    if re.fullmatch(NAME_PATTERN, value) is None:
        raise InputError(file, name, f"{_short(value)} is not allowed: expected {NAME_ALLOWED}")
    return value


def did_you_mean(value: Any, choices) -> str:
    """"; did you mean 'x'?" for the closest of choices to a misspelt value ("" if none is close)."""
    if not isinstance(value, str):
        return ""
    close = difflib.get_close_matches(value, [str(c) for c in choices], n=1, cutoff=0.6)
    return f"; did you mean {close[0]!r}?" if close else ""


def _short(value: Any, n: int = 60) -> str:
    """repr of a value on one line, cut to about n characters."""
    r = repr(value)
    return r if len(r) <= n else r[:n - 3] + "..."


def table(value: Any, file: str, name: str, default: Any = None) -> dict:
    """value as a table (a copy); None → default (an empty table); anything else is an error."""
    if value is None:
        return dict(default or {})
    if not isinstance(value, dict):
        raise InputError(file, name, f"expected a table, got {type(value).__name__} {_short(value)}")
    return dict(value)


def table_list(value: Any, file: str, name: str) -> list:
    """value as a list of tables ([[name]] in TOML)."""
    if not isinstance(value, list):
        raise InputError(file, name, f"expected [[{name.rsplit('.', 1)[-1]}]] tables, got {_short(value)}")
    for i, t in enumerate(value):
        if not isinstance(t, dict):
            raise InputError(file, f"{name}[{i}]", f"expected a table, got {type(t).__name__} {_short(t)}")
    return value


def choice(value: Any, choices, file: str, name: str, what: str) -> str:
    """value as one of choices (a string); missing → "missing field", misspelt → "did you mean"."""
    choices = list(choices)
    allowed = ", ".join(choices)
    if value is None:
        raise InputError(file, name, f"missing field (expected one of {allowed})")
    if not isinstance(value, str):
        raise InputError(file, name, f"expected a string, one of {allowed}; got {_short(value)}")
    if value not in choices:
        close = difflib.get_close_matches(value, choices, n=1, cutoff=0.6)
        hint = f"; did you mean {close[0]!r}?" if close else ""
        raise InputError(file, name, f"unknown {what} {_short(value)}{hint} (allowed: {allowed})")
    return value
