"""Instrument suites: which instruments a ship carries, where, with which catalogue spec; and the
running set of instruments that turns truth into readings during and after a simulation.

Suite file ``models/<ship>/instruments.toml``::

    [[instrument]]
    name = "gyro"              # unique
    spec = "gyrocompass"       # an entry of vtrials/instruments/catalogue.toml
    site = "gyro"              # an MJCF site of the hull (sensor position)
    shaft = "port"             # shaft instruments: which shaft
    rudder = "port"            # rudder synchro: which rudder
    full_scale = 1.0e5         # instruments whose errors are % of full scale
    clock = "logger_clock"     # optional: the clock entry of the catalogue that time-stamps its
                               # readings (default logger_clock; "none": stamps in true time)
    [instrument.set]           # optional: override catalogue values (same keys and units)
    noise = 0.05

A scenario may list ``[[instrument]]`` tables too: one with a suite name overrides that entry,
a new name adds an instrument. Every instrument draws from its own random stream, spawned from
the scenario seed and keyed by its name (numpy SeedSequence), so streams are independent and do
not depend on the order or number of instruments.

Clocks: each instrument's readings are time-stamped by its own logger clock (a ``kind = "clock"``
entry of the catalogue, ``logger_clock`` unless the entry names another or ``"none"``):
stamp = t + c + d·t with the offset c ~ N(0, offset_s²) and the drift d ~ N(0, drift_ppm²)·10⁻⁶
drawn per instrument per trial (:class:`vtrials.instruments.parts.ClockOffset`, t_ref = 0, the start
of the recording, when the loggers were synchronised), from a stream of its own (spawn-key namespace
``CLOCK_KEY``), so the clock leaves the instrument's other draws unchanged.
"""

from __future__ import annotations

import copy
import dataclasses
import zlib
from pathlib import Path

import numpy as np

from vtrials.errors import InputError
from vtrials.schema import did_you_mean, check_name, check_value, load_toml, num, read_table, table, text, unknown_key, Spec
from vtrials.instruments.devices import KINDS as SHIP_KINDS, RudderAngle, ShaftDevice, SpecError
from vtrials.instruments.parts import ClockOffset
from vtrials.instruments.wave_sensors import WAVE_KINDS

KINDS = {**SHIP_KINDS, **WAVE_KINDS}  # ship instruments, then the sea's (wave buoys, wave radar, relative motion)

CATALOGUE = Path(__file__).resolve().parent / "catalogue.toml"
SEED_KEY = 4  # spawn-key namespace of instrument streams
CLOCK_KEY = 5  # spawn-key namespace of the instruments' logger clocks
WINDAGE_KEY = 6  # spawn-key namespace of the team's wind-tunnel coefficients
WINDAGE_REL_STD = 0.05  # the team's wind coefficients' scale error, 1σ: what its reduction states
DEFAULT_CLOCK = "logger_clock"


@dataclasses.dataclass(frozen=True)
class Entry:
    name: str = text("instrument name (unique on the ship)")
    spec: str = text("catalogue entry")
    site: str = text("MJCF site of the sensor", default=None)
    shaft: str = text("shaft measured (shaft instruments)", default=None)
    rudder: str = text("rudder measured (rudder synchro)", default=None)
    full_scale: float = num("full scale of the instrument (for % FS errors)", "", 0.0, 1e12, lo_open=True,
                            default=None)
    clock: str = text("catalogue clock entry that stamps the readings ('none': true time)", default=None)


def load_catalogue(path: Path = CATALOGUE) -> dict:
    return load_toml(path)


def _entries(items, f: str, section: str) -> list[tuple[Entry, dict, str]]:
    if items is None:
        return []
    if not isinstance(items, list):
        raise InputError(f, section, "expected [[instrument]] tables")
    out = []
    for i, tab in enumerate(items):
        if not isinstance(tab, dict):
            raise InputError(f, f"{section}[{i}]", "expected a table")
        tab = dict(tab)
        sets = table(tab.pop("set", None), f, f"{section}[{i}].set")
        if "name" in tab:
            check_name(tab["name"], f, f"{section}[{i}].name")
        e, _ = read_table(Entry, tab, f, f"{section}[{i}]")
        out.append((e, sets, f"{section}[{i}]"))
    return out


_NONNEG = Spec("num", lo=0.0)
_SETTINGS = {  # what each common catalogue parameter accepts (catalogue.toml's header gives the meaning)
    "rate_hz": Spec("num", unit="Hz", lo=0.0, hi=1000.0, lo_open=True),
    "noise": _NONNEG, "resolution": _NONNEG, "random_walk": _NONNEG, "latency_s": Spec("num", unit="s", lo=0.0, hi=3600.0),
    "hold_s": Spec("num", unit="s", lo=0.0, hi=3600.0), "clock_offset_s": Spec("num", unit="s", lo=0.0, hi=3600.0),
    "dropout_p": Spec("num", lo=0.0, hi=1.0, hi_open=True), "misalignment_deg": Spec("num", unit="deg", lo=0.0, hi=90.0),
}
_DIST = {"bias": {"mean": Spec("num"), "sd": _NONNEG}, "scale": {"mean": Spec("num", lo=-1.0, hi=1.0, lo_open=True),
                                                                  "sd": Spec("num", lo=0.0, hi=1.0)},
         "gauss_markov": {"sd": _NONNEG, "tau_s": Spec("num", unit="s", lo=0.0, lo_open=True)}}


def check_setting(key: str, value, catalogue_value, f: str, name: str):
    """Check one ``[instrument.set]`` value: the common parameters by their allowed range (noise,
    resolution, standard deviations ≥ 0, rates > 0, probabilities in [0, 1), ranges lo < hi); a
    device's own parameters must have the shape of the catalogue's value (a number, a table of
    numbers, a list of numbers) and be finite, and non-negative where the catalogue's is."""
    if key in _SETTINGS:
        return check_value(_SETTINGS[key], value, f, name)
    if key in _DIST:
        fields = _DIST[key]
        if not isinstance(value, dict):
            if key == "bias":  # a bare number is the standard deviation
                return check_value(_NONNEG, value, f, name)
            raise InputError(f, name, f"expected a table {{ {', '.join(fields)} }} of numbers, got {value!r}"[:200])
        for k in value:
            if k not in fields:
                raise unknown_key(f, name, k, list(fields))
        return {k: check_value(fields[k], v, f, f"{name}.{k}") for k, v in value.items()}
    if key == "position_m":  # a sea sensor's deployment point [north, east] (wave buoys)
        if not (isinstance(value, list) and len(value) == 2):
            raise InputError(f, name, f"expected [north, east] in metres (two numbers), got {value!r}"[:200])
        return [check_value(Spec("num", lo=-1e7, hi=1e7), v, f, f"{name}[{k}]") for k, v in enumerate(value)]
    if key in ("range", "update_s"):
        if not (isinstance(value, list) and len(value) == 2):
            raise InputError(f, name, f"expected [low, high] (two numbers, low < high), got {value!r}"[:200])
        lo, hi = (check_value(Spec("num", lo=0.0 if key == "update_s" else None), v, f, f"{name}[{k}]")
                  for k, v in enumerate(value))
        if not lo < hi or (key == "update_s" and lo <= 0.0):
            raise InputError(f, name, f"expected [low, high] with {'0 < ' if key == 'update_s' else ''}low < high, "
                                      f"got {value!r}")
        return [lo, hi]
    return _like(value, catalogue_value, f, name)


def _like(value, ref, f: str, name: str):
    """value checked to have the shape of the catalogue's ref (and its sign, for numbers)."""
    if isinstance(ref, bool) or isinstance(value, bool):
        if not (isinstance(ref, bool) and isinstance(value, bool)):
            raise InputError(f, name, f"expected {'true or false' if isinstance(ref, bool) else 'a number'}, "
                                      f"got {value!r}"[:200])
        return value
    if isinstance(ref, dict):
        if set(ref) <= {"mean", "sd"} and isinstance(value, (int, float)):  # a distribution: a bare number is its sd
            return check_value(_NONNEG, value, f, name)
        if not isinstance(value, dict):
            raise InputError(f, name, f"expected a table with keys {', '.join(ref)}, got {value!r}"[:200])
        for k in value:
            if k not in ref:
                raise unknown_key(f, name, k, list(ref))
        return {k: _like(v, ref[k], f, f"{name}.{k}") for k, v in value.items()}
    if isinstance(ref, list):
        if not isinstance(value, list) or not value:
            raise InputError(f, name, f"expected a list of numbers, got {value!r}"[:200])
        if ref and isinstance(ref[0], (dict, list)):
            return [_like(v, ref[0], f, f"{name}[{k}]") for k, v in enumerate(value)]
        return [check_value(Spec("num"), v, f, f"{name}[{k}]") for k, v in enumerate(value)]
    if isinstance(ref, str):
        if not isinstance(value, str):
            raise InputError(f, name, f"expected a string, got {value!r}"[:200])
        return value
    leaf = name.rsplit(".", 1)[-1]
    signed = "bias" in leaf or "mean" in leaf or "offset" in leaf
    nonneg = not signed and ("noise" in leaf or "sd" in leaf or (isinstance(ref, (int, float)) and ref > 0))
    return check_value(Spec("num", lo=0.0 if nonneg else None), value, f, name)


class InstrumentSet:
    """The instruments of one ship, streaming truth chunks into readings."""

    def __init__(self, vessel, seed: int, site_info: dict, scenario_items=None, scenario_file: str = "",
                 stream: tuple = (), wind_profile: tuple[float, float] | None = None):
        """``wind_profile``: (power-law exponent, reference height [m]) of the simulated wind's mean
        profile — the scenario's :class:`vtrials.physics.environment.wind.Wind` ``profile_exponent``
        and ``reference_height_m`` (:func:`vtrials.scenario.instrument_set`); anemometers scale the
        truth's wind speed to their own height with it. None: the Wind defaults (1/9, 10 m)."""
        self.vessel = vessel
        cat = load_catalogue()
        suite_path = vessel.folder / "instruments.toml"
        suite = _entries(load_toml(suite_path).get("instrument") if suite_path.is_file() else None,
                         str(suite_path), "instrument")
        extra = _entries(scenario_items, scenario_file, "instrument")
        merged: dict[str, tuple[Entry, dict, str, str]] = {}
        for e, sets, where in suite:
            if e.name in merged:
                raise InputError(str(suite_path), f"{where}.name", f"duplicate instrument {e.name!r}")
            merged[e.name] = (e, sets, str(suite_path), where)
        for e, sets, where in extra:
            if e.name in merged:
                base, bsets, _, _ = merged[e.name]
                fields = {k: getattr(e, k) if getattr(e, k) is not None else getattr(base, k)
                          for k in ("name", "spec", "site", "shaft", "rudder", "full_scale", "clock")}
                merged[e.name] = (Entry(**fields), {**bsets, **sets}, scenario_file, where)
            else:
                merged[e.name] = (e, sets, scenario_file, where)
        self.seed = seed
        self.stream = tuple(stream)
        self.team = self._team(site_info)
        self.devices = {}
        self.clocks: dict[str, ClockOffset | None] = {}
        for name in sorted(merged):
            e, sets, f, where = merged[name]
            self.devices[name] = self._build(e, sets, cat, f, where)
            self.clocks[name] = self._clock(e, cat, f, where)
            if wind_profile is not None and self.devices[name].kind in ("anemometer", "sonic_anemometer"):
                self.devices[name].profile = (float(wind_profile[0]), float(wind_profile[1]))
        sonic = [d for d in self.devices.values() if d.kind == "sonic_anemometer"]
        if sonic:  # the ship's true airwake at their sites (truth: the devices read it, records never carry it)
            from vtrials.instruments.airwake import load_airwake
            aw = load_airwake(vessel.folder, vessel.sites)
            for d in sonic:
                d.set_airwake(aw, vessel.sites)
        self._out: dict[str, list] = {}

    def _team(self, site_info: dict) -> dict:
        v = self.vessel
        p = v.particulars
        team = {"site": site_info, "ship": v.name, "length_m": p.length, "beam_m": p.beam, "draught_m": p.draught,
                "displacement_m3": p.displacement, "water_density": p.water_density,
                "shafts": [s.name for s in v.shafts], "rudders": [r.name for r in v.rudders],
                "propeller_diameters_m": [pr.diameter for pr in v.propellers],
                "max_power_W": [s.max_power for s in v.shafts]}
        if v.windage is not None:
            from vtrials.physics.environment.wind import wind_coefficients
            ang = np.radians(np.arange(0.0, 181.0, 10.0))
            cx, cy, cn, ck = wind_coefficients(ang, v.windage)
            w = v.windage
            # the team's coefficients are a wind-tunnel test of a model of the ship, not the ship's own:
            # one scale error per trial, drawn with the 5 % (1σ) the reduction states for them
            # (vtrials.reduce.trials, cx_rel_std) — else the wind correction would share the truth's model
            rng = np.random.default_rng(np.random.SeedSequence(self.seed, spawn_key=(WINDAGE_KEY, *self.stream)))
            k = 1.0 + WINDAGE_REL_STD * float(rng.standard_normal())
            team["windage"] = {"A_F_m2": w.A_F, "A_L_m2": w.A_L, "L_oa_m": w.L_oa,
                               "source": "wind-tunnel test of a model: the ship's coefficients with one scale "
                                         f"error, drawn N(0, {WINDAGE_REL_STD:.0%}) per trial",
                               "C_rel_std": WINDAGE_REL_STD, "angles_rad": ang.tolist(), "C_X": (k * np.asarray(cx)).tolist(),
                               "C_Y": (k * np.asarray(cy)).tolist(), "C_N": (k * np.asarray(cn)).tolist()}
        return team

    @staticmethod
    def _clock(e: Entry, cat: dict, f: str, where: str) -> ClockOffset | None:
        """The logger clock of one instrument, from its catalogue clock entry."""
        name = e.clock if e.clock is not None else DEFAULT_CLOCK
        if name == "none":
            return None
        clocks = [k for k, v in cat.items() if isinstance(v, dict) and v.get("kind") == "clock"]
        if name not in clocks:
            raise InputError(f, f"{where}.clock", f"{name!r} is not a clock of the catalogue{did_you_mean(name, clocks)} "
                                                  f"(clocks: {', '.join(clocks)}, or 'none')")
        spec = cat[name]
        vals = {}
        for key in ("offset_s", "drift_ppm"):
            v = spec.get(key)
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not (v >= 0.0 and v < 1e6):
                raise InputError(str(CATALOGUE), f"{name}.{key}", f"expected a standard deviation >= 0 "
                                                                  f"(and < 1e6), got {v!r}")
            vals[key] = float(v)
        return ClockOffset(sd=vals["offset_s"], drift_ppm_sd=vals["drift_ppm"])

    def _build(self, e: Entry, sets: dict, cat: dict, f: str, where: str):
        v = self.vessel
        if e.spec not in cat:
            raise unknown_key(f, f"{where}.spec", e.spec, list(cat))
        spec = copy.deepcopy(cat[e.spec])
        for k, val in sets.items():
            if k not in spec and k not in KINDS.get(spec.get("kind"), KINDS["heading"]).extra_keys | \
                    {"rate_hz", "bias", "scale", "gauss_markov", "random_walk", "noise", "resolution", "range",
                     "latency_s", "hold_s", "update_s", "dropout_p", "clock_offset_s", "misalignment_deg"}:
                raise InputError(f, f"{where}.set.{k}", f"not a parameter of spec {e.spec!r}")
            spec[k] = check_setting(k, val, spec.get(k), f, f"{where}.set.{k}")
        kind = spec.get("kind")
        if kind not in KINDS:
            raise InputError(str(CATALOGUE), f"{e.spec}.kind", f"unknown kind {kind!r}")
        cls = KINDS[kind]
        site = np.zeros(3)
        if e.site is not None:
            if e.site not in v.sites:
                raise InputError(f, f"{where}.site", f"unknown site {e.site!r}{did_you_mean(e.site, v.sites)} (sites of {v.name}: "
                                                     f"{', '.join(sorted(v.sites))})")
            site = v.sites[e.site]
        try:
            if issubclass(cls, ShaftDevice):
                names = [s.name for s in v.shafts]
                if e.shaft not in names:
                    raise InputError(f, f"{where}.shaft", f"{e.shaft!r} is not a shaft of {v.name}{did_you_mean(e.shaft, names)} "
                                                          f"({', '.join(names)})")
                k = names.index(e.shaft)
                pk = [p.name for p in v.propellers].index(v.shafts[k].propeller)
                pos = np.array([v.propellers[pk].x, v.propellers[pk].y, v.propellers[pk].z])
                return cls(e.name, spec, e.site or f"shaft {e.shaft}", site if e.site else pos, self.team, pk,
                           e.full_scale, friction=v.shafts[k].friction)
            if cls is RudderAngle:
                names = [r.name for r in v.rudders]
                if e.rudder not in names:
                    raise InputError(f, f"{where}.rudder", f"{e.rudder!r} is not a rudder of {v.name}{did_you_mean(e.rudder, names)} "
                                                           f"({', '.join(names)})")
                k = names.index(e.rudder)
                rd = v.rudders[k]
                return cls(e.name, spec, f"rudder {e.rudder}", np.array([rd.x, rd.y, rd.z]), self.team, k)
            if e.site is None and getattr(cls, "hull_site_required", True):
                raise InputError(f, f"{where}.site", f"a {kind} instrument needs a site")
            return cls(e.name, spec, e.site or "sea", site, self.team)
        except SpecError as exc:
            raise InputError(f, f"{where}.{exc.field}", exc.problem) from None

    # ------------------------------------------------------------------ running
    def reset(self) -> None:
        for name, dev in self.devices.items():
            ss = np.random.SeedSequence(self.seed, spawn_key=(SEED_KEY, *self.stream, zlib.crc32(name.encode())))
            dev.reset(np.random.Generator(np.random.PCG64(ss)))
            clk = self.clocks.get(name)
            if clk is not None:
                cs = np.random.SeedSequence(self.seed, spawn_key=(CLOCK_KEY, *self.stream, zlib.crc32(name.encode())))
                clk.reset(np.random.Generator(np.random.PCG64(cs)))
        self._out = {name: [] for name in self.devices}
        self._pending: list[dict] = []  # queued truth chunks, consolidated into one at each flush
        self._seen = {name: 0 for name in self.devices}  # rows of the consolidated chunk each device has seen

    def process(self, cols: dict) -> None:
        """Feed one chunk of truth columns (times strictly after the previous chunk's)."""
        self.push(cols)
        self.flush()

    def push(self, cols: dict) -> None:
        """Queue a chunk of truth columns; instruments take it at the next :meth:`flush`. Streaming is
        chunk-size invariant, so a display can flush the few instruments it shows often while the rest
        take long chunks (each call has a fixed cost of ~0.4 ms per instrument)."""
        if cols["t"].size:
            self._pending.append(cols)

    def flush(self, names=None) -> None:
        """Bring the named instruments (default: all) up to the last pushed truth row."""
        if not self._pending:
            return
        if len(self._pending) > 1:  # one concatenation, shared by every device flushed from now on
            first = self._pending[0]
            self._pending = [{c: np.concatenate([p[c] for p in self._pending]) for c in first}]
        cols = self._pending[0]
        n = cols["t"].size
        for name in (self.devices if names is None else names):
            k = self._seen[name]
            if k >= n:
                continue
            part = cols if k == 0 else {c: v[k:] for c, v in cols.items()}
            t, ch = self.devices[name].process(part)
            clk = self.clocks.get(name)
            if clk is not None and t.size:  # the logger's stamp: t + c + d·(t − t_ref), as ClockOffset
                t = t + clk.offset + (clk.drift_ppm * 1e-6) * (t - clk.t_ref)
            if t.size:
                self._out[name].append((t, ch))
            self._seen[name] = n
        done = min(self._seen.values())
        if done:
            self._pending = [{c: v[done:] for c, v in cols.items()}] if done < n else []
            for name in self._seen:
                self._seen[name] -= done

    def readings(self, name: str) -> tuple[np.ndarray, dict]:
        """All readings of one instrument so far: (time, {channel: values})."""
        self.flush([name])
        parts = self._out[name]
        dev = self.devices[name]
        if not parts:
            return np.zeros(0), {c: np.zeros(0) for c in dev.channels}
        t = np.concatenate([p[0] for p in parts])
        return t, {c: np.concatenate([p[1][c] for p in parts]) for c in dev.channels}

    def window(self, name: str, t0: float) -> tuple[np.ndarray, dict]:
        """Readings of one instrument stamped at or after t0 (what a display shows over a recent window;
        cost independent of the length of the recording). Flushes that instrument first."""
        self.flush([name])
        parts = self._out[name]
        dev = self.devices[name]
        k = len(parts)
        while k > 0 and parts[k - 1][0].size and parts[k - 1][0][0] >= t0:
            k -= 1
        if k > 0:
            k -= 1  # the part that straddles t0
        sel = parts[k:]
        if not sel:
            return np.zeros(0), {c: np.zeros(0) for c in dev.channels}
        t = np.concatenate([p[0] for p in sel])
        keep = t >= t0
        return t[keep], {c: np.concatenate([p[1][c] for p in sel])[keep] for c in dev.channels}

    @property
    def needs_sea(self) -> bool:
        """Whether any instrument senses the seaway itself (wave buoys, wave radar, relative motion)."""
        return any(getattr(d, "needs_sea", False) for d in self.devices.values())

    def attach_sea(self, field) -> None:
        """Give the sea-sensing instruments the scenario's seaway (a WaveField, or None for a calm sea)."""
        for d in self.devices.values():
            if getattr(d, "needs_sea", False):
                d.attach_sea(field)

    def of_kind(self, kind: str) -> list[str]:
        """Names of the instruments of one kind (e.g. "shaft_torque"), in name order."""
        return [n for n, d in self.devices.items() if d.kind == kind]

    def drawn(self) -> dict:
        out = {}
        for name, dev in self.devices.items():
            d = dev.drawn()
            clk = self.clocks.get(name)
            out[name] = {**d, "logger_clock": clk.drawn()} if clk is not None else d
        return out

    def meta(self) -> dict:
        return {name: dev.meta() for name, dev in self.devices.items()}
