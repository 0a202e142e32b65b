"""The instruments: what each device measures (its measurand at its site), its own physics, and the
chain of error parts from its catalogue entry.

Every device works on truth chunks (dicts of equal-length arrays at the simulation rate, as
:func:`vtrials.truth.columns.ship_columns` gives them), streaming: ``reset(rng)`` then ``process(cols)``
any number of times; it returns the samples it emits per channel, in SI units, on its own clock.
``drawn()`` lists the error parameters actually drawn (for the truth file); ``meta()`` what the
trials team knows (nominal calibration, surveyed position, rate) — the record carries it.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from vtrials.units import DEG, KNOT, RPM
from vtrials.instruments import parts as P
from vtrials.instruments import sensor_errors as SE
from vtrials.instruments.kinematics import SiteKinematics
from vtrials.physics.environment.wind import TRIALS_PROFILE_EXPONENT, Z_REF_10

UNIT_FACTORS = {"m": 1.0, "deg": DEG, "kn": KNOT, "m/s": 1.0, "rpm": RPM, "N m": 1.0, "N": 1.0, "1": 1.0,
                "SI": 1.0, "m/s2": 1.0, "deg/s": DEG}
COMMON_KEYS = {"kind", "source", "units", "rate_hz", "bias", "scale", "gauss_markov", "random_walk", "noise",
               "resolution", "range", "latency_s", "hold_s", "update_s", "dropout_p", "clock_offset_s",
               "misalignment_deg"}


class SpecError(ValueError):
    """An instrument spec is wrong (the suite loader turns it into an InputError naming file and field)."""

    def __init__(self, field: str, problem: str):
        self.field = field
        self.problem = problem
        super().__init__(f"{field}: {problem}")


def _dist(spec: dict, key: str, f: float = 1.0) -> tuple[float, float]:
    v = spec.get(key)
    if v is None:
        return 0.0, 0.0
    if isinstance(v, dict):
        return float(v.get("mean", 0.0)) * f, float(v.get("sd", 0.0)) * f
    return 0.0, float(v) * f


def value_chain(spec: dict, f: float, n_axes: int | None = None, *, sampling: list | None = None,
                full_scale: float | None = None) -> P.Chain:
    """The standard chain of a spec: sampling stage, bias/scale, Gauss–Markov, random walk, white
    noise, saturation, quantization, dropouts, latency, clock offset (parts.py's recommended order).
    ``f`` converts the spec's units to SI; ``*_fs`` entries are fractions of ``full_scale``."""
    parts: list[P.Part] = list(sampling) if sampling is not None else []
    if sampling is None and "rate_hz" in spec:
        parts.append(P.Resample(float(spec["rate_hz"])))
    if spec.get("misalignment_deg") and n_axes == 3:
        parts.append(P.Misalignment(sd=float(spec["misalignment_deg"]) * DEG, n_axes=3))
    sm, ss = _dist(spec, "scale")
    if ss or sm:
        parts.append(P.ScaleFactor(sm, ss, n_axes=n_axes))
    bm, bs = _dist(spec, "bias", f)
    if full_scale is not None and "bias_fs" in spec:
        fm, fs = _dist(spec, "bias_fs", full_scale)
        bm, bs = bm + fm, math.hypot(bs, fs)
    if bs or bm:
        parts.append(P.Bias(bm, bs, n_axes=n_axes))
    gm = spec.get("gauss_markov")
    if gm:
        parts.append(P.GaussMarkov(float(gm["tau_s"]), float(gm["sd"]) * f, n_axes=n_axes))
    if spec.get("random_walk"):
        parts.append(P.RandomWalk(float(spec["random_walk"]) * f, n_axes=n_axes))
    noise = float(spec.get("noise", 0.0)) * f
    if full_scale is not None and "noise_fs" in spec:
        noise = math.hypot(noise, float(spec["noise_fs"]) * full_scale)
    if noise:
        parts.append(P.WhiteNoise(noise, n_axes=n_axes))
    if spec.get("range"):
        lo, hi = spec["range"]
        parts.append(P.Saturation(float(lo) * f, float(hi) * f))
    res = float(spec.get("resolution", 0.0)) * f
    if full_scale is not None and "resolution_fs" in spec:
        res = float(spec["resolution_fs"]) * full_scale
    if res:
        parts.append(P.Quantization(res, n_axes=n_axes))
    if spec.get("dropout_p"):
        parts.append(P.Dropouts(p=float(spec["dropout_p"])))
    if spec.get("latency_s"):
        parts.append(P.Latency(float(spec["latency_s"])))
    if spec.get("clock_offset_s"):
        parts.append(P.ClockOffset(sd=float(spec["clock_offset_s"])))
    return P.Chain(parts)


class Device:
    """Base class: a named instrument at a site, with a catalogue spec (merged with overrides)."""

    kind = "device"
    extra_keys: set[str] = set()
    channels: dict[str, tuple[str, str]] = {}

    def __init__(self, name: str, spec: dict, site_name: str, site: np.ndarray, team: dict):
        unknown = set(spec) - COMMON_KEYS - self.extra_keys
        if unknown:
            raise SpecError(sorted(unknown)[0], f"not a {self.kind} parameter (allowed: "
                                                f"{', '.join(sorted(COMMON_KEYS | self.extra_keys))})")
        units = spec.get("units", "SI")
        if units not in UNIT_FACTORS:
            raise SpecError("units", f"{units!r} unknown (allowed: {', '.join(UNIT_FACTORS)})")
        self.name, self.spec, self.site_name = name, spec, site_name
        self.site = np.asarray(site, dtype=float)
        self.f = UNIT_FACTORS[units]
        self.team = team
        self.build()

    def build(self) -> None:
        self.chain = value_chain(self.spec, self.f, self.n_axes)

    n_axes: int | None = None

    def reset(self, rng: np.random.Generator) -> None:
        self.chain.reset(rng)

    def measurand(self, kin: SiteKinematics, cols: dict) -> np.ndarray:
        raise NotImplementedError

    def outputs(self, t: np.ndarray, y: np.ndarray) -> dict[str, np.ndarray]:
        names = list(self.channels)
        if y.ndim == 1:
            return {names[0]: y}
        return {n: y[:, k] for k, n in enumerate(names)}

    def process(self, cols: dict) -> tuple[np.ndarray, dict[str, np.ndarray]]:
        kin = SiteKinematics(cols, self.site)
        t, y = self.chain.process(cols["t"], self.measurand(kin, cols))
        return t, self.outputs(t, y)

    def drawn(self) -> dict:
        return {"chain": self.chain.drawn()}

    def meta(self) -> dict:
        m = {"kind": self.kind, "site": self.site_name, "surveyed_position_m": self.site.tolist(),
             "nominal_rate_hz": float(self.spec.get("rate_hz", 0.0)), "source": self.spec.get("source", "")}
        if self.spec.get("latency_s"):
            # the data sheet's (or bench-measured) delay from the measurement to its time stamp
            m["latency_s"] = float(self.spec["latency_s"])
        bias = self.spec.get("bias")
        if isinstance(bias, dict) and bias.get("sd"):
            # the stated accuracy of the zero (1σ, SI units of the channel), common to a whole record
            m["bias_std"] = float(bias["sd"]) * self.f
        if isinstance(self.spec.get("resolution"), (int, float)) and self.spec["resolution"] > 0:
            # the reading's step (SI): a steady quantity reads a constant step error, not noise
            m["resolution"] = float(self.spec["resolution"]) * self.f
        return m


def _wrap2pi(a):
    return np.mod(a, 2 * math.pi)


@nb.njit(cache=True)
def first_order_lag(t, x, tau, y0, t0):
    """y' = (x − y)/τ(t) integrated exactly for piecewise-constant input between samples; returns the
    output at the sample times and the final state. τ may vary sample to sample."""
    y = np.empty_like(x)
    yk = y0
    tl = t0
    for k in range(t.size):
        yk += (x[k] - yk) * (1.0 - math.exp(-(t[k] - tl) / tau[k]))
        tl = t[k]
        y[k] = yk
    return y, yk


# ---------------------------------------------------------------------------------------- navigation
class GNSS(Device):
    """Satellite positioning at the antenna: north, east (time-correlated errors) and velocity.

    Error model (catalogue entries dgps / rtk_gnss), in this order on the receiver's own fixes:
      * ``gauss_markov``: the slowly varying error of the corrected solution (residual differential /
        atmospheric error), first-order Gauss–Markov per horizontal axis;
      * ``multipath``: a second, faster Gauss–Markov process per axis — multipath on a moving ship is a
        coloured error that decorrelates as the reflection geometry changes (Braasch, "Multipath
        effects", in Parkinson & Spilker (eds.), GPS: Theory and Applications I, AIAA 1996);
      * ``noise`` (position) and ``velocity_noise_mps``: white receiver noise;
      * ``dropout_p``: isolated lost fixes; ``outages``: gaps (Poisson arrivals while up, exponential
        or fixed lengths, :class:`~vtrials.instruments.parts.Outages`) — the record has no fixes there;
      * ``latency_s``: the fix arrives, and is time-tagged by the logger, that long after the instant
        it describes (:class:`~vtrials.instruments.parts.Latency`).
    """

    kind = "gnss"
    extra_keys = {"velocity_noise_mps", "multipath", "outages"}
    channels = {"north": ("m", "antenna position north"), "east": ("m", "antenna position east"),
                "sog": ("m s-1", "speed over ground"), "cog": ("rad", "course over ground (0..2π)")}
    n_axes = 4

    def build(self):
        s, f = self.spec, self.f
        gm = s.get("gauss_markov", {"sd": 0.0, "tau_s": 1.0})
        n = float(s.get("noise", 0.0)) * f
        vn = float(s.get("velocity_noise_mps", 0.0))
        parts = [P.Resample(float(s["rate_hz"])),
                 P.GaussMarkov(float(gm["tau_s"]), [float(gm["sd"]) * f] * 2 + [0.0, 0.0], n_axes=4)]
        mp = s.get("multipath")
        if mp:
            if not float(mp.get("tau_s", 0.0)) > 0.0:
                raise SpecError("multipath.tau_s", f"must be > 0 s, got {mp.get('tau_s')!r}")
            if not float(mp.get("sd", 0.0)) >= 0.0:
                raise SpecError("multipath.sd", f"must be >= 0, got {mp.get('sd')!r}")
            parts.append(P.GaussMarkov(float(mp["tau_s"]), [float(mp["sd"]) * f] * 2 + [0.0, 0.0], n_axes=4))
        parts.append(P.WhiteNoise([n, n, vn, vn], n_axes=4))
        if s.get("dropout_p"):
            parts.append(P.Dropouts(p=float(s["dropout_p"])))
        out = s.get("outages")
        if out and float(out.get("rate_per_h", 0.0)) > 0.0:
            dur = out.get("durations", "exponential")
            if dur not in ("exponential", "fixed"):
                raise SpecError("outages.durations", f"{dur!r} unknown (allowed: exponential, fixed)")
            if not float(out.get("duration_s", 0.0)) > 0.0:
                raise SpecError("outages.duration_s", f"must be > 0 s, got {out.get('duration_s')!r}")
            parts.append(P.Outages(float(out["rate_per_h"]) / 3600.0, float(out["duration_s"]), dur))
        if s.get("latency_s"):
            parts.append(P.Latency(float(s["latency_s"])))
        self.chain = P.Chain(parts)

    def measurand(self, kin, cols):
        p = kin.position()
        v = kin.velocity_world()
        return np.column_stack([p[:, 0], p[:, 1], v[:, 0], v[:, 1]])

    def meta(self):
        m = super().meta()
        # the receiver's stated horizontal accuracy per axis (1σ; data-sheet figure: the catalogue's
        # slowly varying, multipath and white parts together), as a team has it
        s = self.spec
        parts = [float(s.get("gauss_markov", {}).get("sd", 0.0)), float((s.get("multipath") or {}).get("sd", 0.0)),
                 float(s.get("noise", 0.0))]
        m["horizontal_accuracy_m"] = math.sqrt(sum(x * x for x in parts)) * self.f
        # and its time correlation (data-sheet / survey knowledge of DGPS error: slow wander, multipath),
        # per axis as (sd [m], correlation time [s]) pairs of exponentially correlated parts
        m["correlated_errors"] = [[float(p["sd"]) * self.f, float(p["tau_s"])]
                                  for p in (s.get("gauss_markov"), s.get("multipath")) if p and p.get("sd")]
        return m

    def outputs(self, t, y):
        return {"north": y[:, 0], "east": y[:, 1], "sog": np.hypot(y[:, 2], y[:, 3]),
                "cog": _wrap2pi(np.arctan2(y[:, 3], y[:, 2]))}


def _survey_errors(rng: np.random.Generator, sd: float, n: int) -> np.ndarray:
    """(n, 2) north/east errors [m] of n surveyed shore/bottom stations, N(0, sd²) per axis."""
    return sd * rng.standard_normal((n, 2))


def two_range_fix(r1, r2, a, b, side: float):
    """Position from ranges r1, r2 [m] to stations a, b (north, east); the intersection on the given
    side of the baseline a→b (+1 starboard of a→b, −1 port). NaN where the circles do not meet."""
    a = np.asarray(a, float)
    b = np.asarray(b, float)
    d = np.linalg.norm(b - a)
    ex = (b - a) / d
    ey = np.array([-ex[1], ex[0]])  # 90° clockwise in north-east axes: starboard of a→b
    x = (r1 ** 2 - r2 ** 2 + d ** 2) / (2 * d)
    h2 = r1 ** 2 - x ** 2
    h = np.sqrt(np.where(h2 >= 0, h2, np.nan))
    pts = a + np.outer(x, ex) + side * np.outer(h, ey)
    return pts[:, 0], pts[:, 1]


class RangeRadar(Device):
    """Range–range pulse radar (Falcon, seed 002): ranges from the ship's antenna to two shore
    transponders, and the position fix the system computes from them and the surveyed baseline.
    The fix error grows as the range lines' crossing angle narrows (geometric dilution).

    Range errors (catalogue entry falcon_radar), per transponder: ``bias`` — the transponder's reply
    delay not taken out by the calibration, drawn per trial; ``gauss_markov`` — multipath (range
    reflections, seed 002), a time-correlated error; ``noise`` — white. ``survey_sd_m``: the shore
    stations actually stand N(0, sd²) per axis away from their surveyed positions (drawn per trial);
    the ranges are to the actual stations, the fix uses the surveyed ones, so the survey error maps
    through the two-range geometry into a position bias that changes slowly along the track."""

    kind = "range_radar"
    extra_keys = {"survey_sd_m"}
    channels = {"range_a": ("m", "range to transponder A"), "range_b": ("m", "range to transponder B"),
                "north": ("m", "position fix north"), "east": ("m", "position fix east"),
                "crossing_angle": ("rad", "angle between the two range lines at the fix")}
    n_axes = 2

    def build(self):
        site = self.team.get("site", {})
        tr = site.get("transponders")
        if not tr or len(tr) < 2:
            raise SpecError("transponders", "a range-range radar needs two shore transponders in the trial "
                                            "site ([site] transponders = [[north, east], [north, east]])")
        self.a, self.b = np.array(tr[0], float), np.array(tr[1], float)
        self.side = float(site.get("transponder_side", 1.0))
        self.survey_sd = float(self.spec.get("survey_sd_m", 0.0))
        if not (math.isfinite(self.survey_sd) and self.survey_sd >= 0.0):
            raise SpecError("survey_sd_m", f"must be finite and >= 0, got {self.spec.get('survey_sd_m')!r}")
        self.chain = value_chain(self.spec, self.f, 2)
        self.survey_error = np.zeros((2, 2))

    def reset(self, rng):
        r1, r2 = rng.spawn(2)
        self.chain.reset(r1)
        self.survey_error = _survey_errors(r2, self.survey_sd, 2)

    def measurand(self, kin, cols):
        p = kin.position()[:, :2]
        a_true, b_true = self.a + self.survey_error[0], self.b + self.survey_error[1]
        return np.column_stack([np.linalg.norm(p - a_true, axis=1), np.linalg.norm(p - b_true, axis=1)])

    def outputs(self, t, y):
        n, e = two_range_fix(y[:, 0], y[:, 1], self.a, self.b, self.side)
        ua = np.column_stack([n - self.a[0], e - self.a[1]])
        ub = np.column_stack([n - self.b[0], e - self.b[1]])
        cosg = np.sum(ua * ub, axis=1) / (np.linalg.norm(ua, axis=1) * np.linalg.norm(ub, axis=1))
        return {"range_a": y[:, 0], "range_b": y[:, 1], "north": n, "east": e,
                "crossing_angle": np.arccos(np.clip(cosg, -1, 1))}

    def drawn(self):
        return {"survey_error_m": self.survey_error.tolist(), "chain": self.chain.drawn()}

    def meta(self):
        m = super().meta()
        m.update({"transponder_a": self.a.tolist(), "transponder_b": self.b.tolist(), "fix_side": self.side,
                  "station_survey_sd_m": self.survey_sd})
        # the data sheet's range error per transponder and its time correlation, as (sd [m], correlation
        # time [s]) pairs: the multipath's and the white part's (time 0), as the team has them
        gm, noise = self.spec.get("gauss_markov") or {}, float(self.spec.get("noise", 0.0))
        m["range_errors"] = ([[float(gm["sd"]) * self.f, float(gm["tau_s"])]] if gm.get("sd") else []) + \
            ([[noise * self.f, 0.0]] if noise else [])
        return m


class AcousticRange(Device):
    """Acoustic range: a pinger on the hull every 1–4 s, slant ranges to hydrophones on the bottom
    (seed 002); the fix is the least-squares intersection of the horizontal ranges. As for the radar,
    ``survey_sd_m`` draws per trial how far each hydrophone actually lies from its surveyed position
    (the ranges are to the actual positions, the fix uses the surveyed ones)."""

    kind = "acoustic_range"
    extra_keys = {"survey_sd_m"}
    channels = {"north": ("m", "position fix north"), "east": ("m", "position fix east")}

    def build(self):
        site = self.team.get("site", {})
        hy = site.get("hydrophones")
        if not hy or len(hy) < 2:
            raise SpecError("hydrophones", "an acoustic range needs at least two bottom hydrophones in the trial "
                                           "site ([site] hydrophones = [[north, east], ...])")
        self.h = np.array(hy, float)
        self.depth = float(site.get("water_depth_m", 100.0))
        self.side = float(site.get("hydrophone_side", 1.0))
        a, b = self.spec.get("update_s", [1.0, 4.0])
        self.n_axes = len(self.h)
        parts = [P.IrregularUpdates(float(a), float(b), method="linear")]
        self.survey_sd = float(self.spec.get("survey_sd_m", 0.0))
        if not (math.isfinite(self.survey_sd) and self.survey_sd >= 0.0):
            raise SpecError("survey_sd_m", f"must be finite and >= 0, got {self.spec.get('survey_sd_m')!r}")
        self.chain = value_chain({k: v for k, v in self.spec.items() if k not in ("rate_hz", "survey_sd_m")},
                                 self.f, self.n_axes, sampling=parts)
        self.survey_error = np.zeros((len(self.h), 2))

    def reset(self, rng):
        r1, r2 = rng.spawn(2)
        self.chain.reset(r1)
        self.survey_error = _survey_errors(r2, self.survey_sd, len(self.h))

    def measurand(self, kin, cols):
        p = kin.position()
        dz = self.depth - p[:, 2]
        h_true = self.h + self.survey_error
        return np.column_stack([np.sqrt(np.sum((p[:, :2] - hp) ** 2, axis=1) + dz ** 2) for hp in h_true])

    def outputs(self, t, y):
        # horizontal ranges from slant ranges (the pinger's depth is known), then the two-station fix
        # with the first two hydrophones
        r = np.sqrt(np.maximum(y ** 2 - self.depth ** 2, 0.0))
        n, e = two_range_fix(r[:, 0], r[:, 1], self.h[0], self.h[1], self.side)
        return {"north": n, "east": e}

    def drawn(self):
        return {"survey_error_m": self.survey_error.tolist(), "chain": self.chain.drawn()}

    def meta(self):
        m = super().meta()
        m.update({"hydrophones": self.h.tolist(), "hydrophone_depth_m": self.depth,
                  "station_survey_sd_m": self.survey_sd})
        return m


class Loran(Device):
    """LORAN-C receiver (seed 000): position fixes at irregular 15–60 s intervals with a slowly varying
    ground-wave bias; the speed-over-ground display is the average between successive fixes."""

    kind = "loran"
    channels = {"north": ("m", "LORAN fix north"), "east": ("m", "LORAN fix east"),
                "sog": ("m s-1", "displayed speed over ground: distance between the last two fixes / their interval"),
                "cog": ("rad", "displayed course over ground (0..2π)")}
    n_axes = 2

    def build(self):
        a, b = self.spec["update_s"]
        self.chain = value_chain({k: v for k, v in self.spec.items() if k != "rate_hz"}, self.f, 2,
                                 sampling=[P.IrregularUpdates(float(a), float(b), method="linear")])

    def reset(self, rng):
        super().reset(rng)
        self._last = None

    def measurand(self, kin, cols):
        return kin.position()[:, :2]

    def outputs(self, t, y):
        n, e = y[:, 0], y[:, 1]
        tt = t
        if self._last is not None:
            tt = np.concatenate([[self._last[0]], t])
            n = np.concatenate([[self._last[1]], n])
            e = np.concatenate([[self._last[2]], e])
        dn, de, dt = np.diff(n), np.diff(e), np.diff(tt)
        sog = np.hypot(dn, de) / dt if dt.size else np.zeros(0)
        cog = _wrap2pi(np.arctan2(de, dn)) if dt.size else np.zeros(0)
        if self._last is None and t.size:
            sog = np.concatenate([[np.nan], sog])
            cog = np.concatenate([[np.nan], cog])
        if t.size:
            self._last = (t[-1], y[-1, 0], y[-1, 1])
        return {"north": y[:, 0], "east": y[:, 1], "sog": sog, "cog": cog}


# ------------------------------------------------------------------------------------- speed logs
class Knotmeter(Device):
    """Impeller knotmeter (Kenyon, seed 000): one pulse per revolution; the impeller turns with the
    water speed at the sensor, reduced by the hull boundary layer (deficit d), against bearing
    friction (it does not start below a break-away speed and slips by a constant amount above it),
    and under-reads when the flow meets it at an angle (rolling at low speed: the roll rate times the
    sensor's depth below the roll axis adds cross-flow; beyond the stall angle the response drops).
    Break-away with hysteresis (:func:`vtrials.instruments.sensor_errors.breakaway_hysteresis`): at rest
    it starts only above the break-away speed V_b (static friction), once turning it stops only below
    the stall speed V_s = r V_b (kinetic friction, r = ``stall_to_breakaway``).
    Counts are accumulated over a 10-s window every 20 s; the display shows counts/10 s × the nominal
    0.3 kn per count/s and holds it for the cycle.

    Pulse rate f = (1 + s)·((1 − d)·u_s − V₀)·c(θ)/k_nom above break-away (else 0), with u_s the
    axial water speed at the sensor, V₀ the friction slip, c(θ) = 1/(1 + (θ/θ_stall)⁴), k_nom the
    nominal kn per count/s ("above break-away": while the impeller turns, see above). So displayed
    D = (1 + s)((1 − d) V − V₀) for steady straight flow, and the true calibration is
    STW = V₀/(1 − d) + D/((1 + s)(1 − d))."""

    kind = "knotmeter"
    extra_keys = {"nominal_kn_per_count_s", "count_window_s", "cycle_s", "breakaway_kn", "boundary_layer_deficit",
                  "roll_stall_deg", "slip_kn", "stall_to_breakaway"}
    channels = {"counts": ("1", "impeller pulses counted in the window"),
                "speed": ("m s-1", "displayed speed: counts per second × the nominal calibration")}

    def build(self):
        s = self.spec
        self.k_nom = float(s["nominal_kn_per_count_s"]) * KNOT  # m/s per (count/s)
        self.window = float(s.get("count_window_s", 10.0))
        self.cycle = float(s.get("cycle_s", 20.0))
        self.stall = float(s.get("roll_stall_deg", 20.0)) * DEG
        self.stall_ratio = float(s.get("stall_to_breakaway", 1.0))
        if not 0.0 <= self.stall_ratio <= 1.0:
            raise SpecError("stall_to_breakaway", f"{self.stall_ratio} not allowed (0..1: the impeller stops at or "
                                                  f"below the speed at which it starts)")
        self.chain = P.Chain([P.WindowAverage(self.window, period=self.cycle, output="count",
                                              pulses_per_unit=1.0)])

    def reset(self, rng):
        r1, r2 = rng.spawn(2)
        s = self.spec
        br = s.get("breakaway_kn", {"lo": 0.0, "hi": 0.0})
        self.v_break = float(r1.uniform(float(br["lo"]), float(br["hi"]))) * KNOT
        dm, ds = _dist(s, "boundary_layer_deficit")
        self.d = dm + ds * float(r1.standard_normal())
        sm, ss = _dist(s, "scale")
        self.s = sm + ss * float(r1.standard_normal())
        slm, sls = _dist(s, "slip_kn", KNOT)
        self.v0 = slm + sls * float(r1.standard_normal())
        self.v_stall = self.stall_ratio * self.v_break
        self._turning = False
        self.chain.reset(r2)

    def rate(self, kin) -> np.ndarray:
        """True pulse rate [count/s] at the sensor (advances the impeller's turning/stopped state: call once
        per chunk, in order)."""
        v = kin.velocity_body(through_water=True)
        u = v[:, 0]
        cross = np.hypot(v[:, 1], v[:, 2])
        theta = np.arctan2(cross, np.abs(u))
        c = 1.0 / (1.0 + (theta / self.stall) ** 4)
        w = (1.0 - self.d) * u
        f = (1.0 + self.s) * np.maximum(w - self.v0, 0.0) * c / self.k_nom
        on, self._turning = SE.breakaway_hysteresis(np.ascontiguousarray(w), self.v_break, self.v_stall,
                                                    self._turning)
        return np.where(on, f, 0.0)

    def process(self, cols):
        kin = SiteKinematics(cols, self.site)
        t, counts = self.chain.process(cols["t"], self.rate(kin))
        return t, {"counts": counts, "speed": counts / self.window * self.k_nom}

    def true_calibration(self) -> tuple[float, float]:
        """(intercept [m/s], slope) of STW = a + b·displayed in steady straight flow above break-away."""
        return self.v0 / (1.0 - self.d), 1.0 / ((1.0 + self.s) * (1.0 - self.d))

    def drawn(self):
        a, b = self.true_calibration()
        return {"breakaway_mps": self.v_break, "stall_mps": self.v_stall, "boundary_layer_deficit": self.d,
                "scale": self.s,
                "slip_mps": self.v0, "true_calibration_intercept_mps": a, "true_calibration_slope": b,
                "chain": self.chain.drawn()}

    def meta(self):
        m = super().meta()
        m.update({"nominal_calibration_mps_per_count_s": self.k_nom, "count_window_s": self.window,
                  "cycle_s": self.cycle})
        return m


class EMLog(Device):
    """Electromagnetic log: the water velocity at the sensor along its sensing axis (cosine law: the
    flow angle at the sensor — drift angle, leeway and the yaw rate's lever arm — and the axis's yaw
    misalignment ε enter as V cos(β − ε)), changed by heel (the sensor moves in the hull's boundary
    layer: factor 1 + k_h |φ|, ``heel_sensitivity_per_deg`` = k_h per degree, modelled assumption), then
    calibration scale and offset errors, noise and resolution; no output astern (it shows zero:
    seed 002). See :func:`vtrials.instruments.sensor_errors.em_log_response`."""

    kind = "em_log"
    extra_keys = {"heel_sensitivity_per_deg"}
    channels = {"speed": ("m s-1", "EM log speed through the water (zero astern)")}

    def build(self):
        sp = {k: v for k, v in self.spec.items() if k != "misalignment_deg"}
        self.chain = value_chain(sp, self.f, None)
        self.k_heel = float(self.spec.get("heel_sensitivity_per_deg", 0.0)) / DEG

    def reset(self, rng):
        self.chain.reset(rng)    # first, so that the error parts draw as they did before the misalignment existed
        (r1,) = rng.spawn(1)
        self.eps = float(r1.standard_normal()) * float(self.spec.get("misalignment_deg", 0.0)) * DEG

    def measurand(self, kin, cols):
        v = kin.velocity_body(through_water=True)
        return SE.em_log_response(v[:, 0], v[:, 1], cols["roll"], self.eps, self.k_heel)

    def outputs(self, t, y):
        return {"speed": np.maximum(y, 0.0)}

    def true_calibration(self) -> tuple[float, float]:
        """(intercept [m/s], slope) of STW = a + b·reading in steady straight flow, upright: the reading is
        (1 + s)·V cos ε + b₀ (scale error s, then bias b₀, as the chain applies them), so
        STW = (reading − b₀)/((1 + s) cos ε). The Gauss–Markov wander and the noise are not part of the
        line (they average over a leg or show as its scatter)."""
        s = sum(float(np.sum(p.value)) for p in self.chain.parts if isinstance(p, P.ScaleFactor))
        b0 = sum(float(np.sum(p.value)) for p in self.chain.parts if isinstance(p, P.Bias))
        k = 1.0 / ((1.0 + s) * math.cos(self.eps))
        return -b0 * k, k

    def drawn(self):
        return {"misalignment_rad": self.eps, "heel_sensitivity_per_rad": self.k_heel, "chain": self.chain.drawn()}


class DopplerLog(Device):
    """Doppler log (water-track): surge and sway through the water at the transducer; its
    misalignment about the vertical rotates the pair and biases the sideslip (seed 001)."""

    kind = "doppler_log"
    channels = {"u": ("m s-1", "surge through the water at the transducer"),
                "v": ("m s-1", "sway through the water at the transducer")}
    n_axes = 2

    def build(self):
        sp = {k: v for k, v in self.spec.items() if k != "misalignment_deg"}
        self.chain = value_chain(sp, self.f, 2)

    def reset(self, rng):
        r1, r2 = rng.spawn(2)
        self.eps = float(r1.standard_normal()) * float(self.spec.get("misalignment_deg", 0.0)) * DEG
        self.chain.reset(r2)

    def measurand(self, kin, cols):
        v = kin.velocity_body(through_water=True)
        c, s = math.cos(self.eps), math.sin(self.eps)
        return np.column_stack([c * v[:, 0] + s * v[:, 1], -s * v[:, 0] + c * v[:, 1]])

    def drawn(self):
        return {"misalignment_rad": self.eps, "chain": self.chain.drawn()}

    def meta(self):
        m = super().meta()
        # the maker's / installer's stated accuracy (1σ), as a team has it: scale, white noise per
        # sample, alignment of the transducer about the vertical
        s = self.spec
        m.update({"scale_accuracy": float((s.get("scale") or {}).get("sd", 0.0)),
                  "noise_mps": float(s.get("noise", 0.0)) * self.f,
                  "misalignment_accuracy_rad": float(s.get("misalignment_deg", 0.0)) * DEG})
        return m


# ------------------------------------------------------------------------------------ attitude, IMU
class Heading(Device):
    """Gyrocompass: heading with the speed (steaming) error its corrector leaves, the ballistic
    deflection of its north-seeking loop after changes of north velocity (speed or course changes),
    then bias, slow drift, noise, resolution and a small lag; output 0..2π.

    Speed error and loop: :mod:`vtrials.instruments.sensor_errors` (Bowditch; Schuler tuning). The
    speed/latitude corrector is set once per trial to a speed drawn from ``corrector_speed_kn``
    (``{lo, hi}``; 0 = corrector off: the full speed error) and to the site latitude plus an error
    drawn from ``corrector_latitude_error_deg``; the corrector removes arcsin(V_c cos ψ/(R_E Ω cos φ_c)),
    and the loop is Schuler-tuned at φ_c (its latitude setting), so a mis-set latitude also leaves a
    ballistic transient (damping ratio ``damping_ratio``). The site latitude is the scenario's
    ``[site] latitude_deg``. The team knows the corrector settings (they are on the dial: meta).
    ``north_seeking = false`` describes a heading reference that does not seek north by gravity and
    earth rate (a free-running model's heading gyro, a fibre-optic AHRS slaved to GNSS): no speed error
    and no ballistic deflection."""

    kind = "heading"
    extra_keys = {"corrector_speed_kn", "corrector_latitude_error_deg", "damping_ratio", "north_seeking"}
    channels = {"heading": ("rad", "gyrocompass heading (0..2π, clockwise from north)")}

    def build(self):
        super().build()
        s = self.spec
        self.north_seeking = bool(s.get("north_seeking", True))
        cs = s.get("corrector_speed_kn", {"lo": 0.0, "hi": 0.0})
        if not (isinstance(cs, dict) and 0.0 <= float(cs.get("lo", -1)) <= float(cs.get("hi", -1))):
            raise SpecError("corrector_speed_kn", f"expected {{ lo, hi }} with 0 <= lo <= hi [kn], got {cs!r}")
        self.cs_lo, self.cs_hi = float(cs["lo"]) * KNOT, float(cs["hi"]) * KNOT
        self.zeta = float(s.get("damping_ratio", 0.33))
        if not 0.0 <= self.zeta < 1.0:
            raise SpecError("damping_ratio", f"{self.zeta} not allowed (0 <= damping_ratio < 1: an oscillating "
                                             f"north-seeking loop)")
        lat = float(self.team.get("site", {}).get("latitude_deg", 38.0))
        if not -80.0 <= lat <= 80.0:
            raise SpecError("latitude_deg", f"site latitude {lat} deg: a gyrocompass does not settle beyond "
                                            f"±80° (allowed -80..80)")
        self.lat = lat * DEG

    def reset(self, rng):
        self.chain.reset(rng)    # first, so that the error parts draw as they did before the corrector existed
        (r1,) = rng.spawn(1)
        self.v_c = float(r1.uniform(self.cs_lo, self.cs_hi)) if self.cs_hi > 0 else 0.0
        lm, ls = _dist(self.spec, "corrector_latitude_error_deg", DEG)
        self.lat_c = float(np.clip(self.lat + lm + ls * float(r1.standard_normal()), -80 * DEG, 80 * DEG))
        self.c, self.W, self.D = SE.loop_constants(self.lat, self.lat_c, self.zeta)
        self.kappa = SE.ballistic_kappa(self.lat, self.lat_c)
        self._loop = np.zeros(2)
        self._tl = None
        self._vl = 0.0

    def steaming(self, kin, cols) -> np.ndarray:
        """Reading error from speed error, corrector and loop transient [rad] at the simulation samples."""
        t = cols["t"]
        if t.size == 0 or not self.north_seeking:
            return np.zeros(t.size)
        vn = kin.velocity_world()[:, 0]
        if self._tl is None:  # settled before the trial: the loop starts at its settling point
            self._tl, self._vl = float(t[0]), float(vn[0])
        eps, self._tl, self._vl = SE.gyro_loop(t, vn, self.c, self.W, self.D, self.kappa, self._loop,
                                               self._tl, self._vl)
        corr = SE.speed_error(self.v_c * np.cos(cols["heading"]), self.lat_c) if self.v_c > 0 else 0.0
        return SE.speed_error(vn, self.lat) - eps - corr

    def measurand(self, kin, cols):
        return cols["heading"] + self.steaming(kin, cols)

    def outputs(self, t, y):
        return {"heading": _wrap2pi(y)}

    def drawn(self):
        return {"north_seeking": self.north_seeking, "corrector_speed_mps": self.v_c,
                "corrector_latitude_rad": self.lat_c, "site_latitude_rad": self.lat,
                "damping_ratio": self.zeta, "ballistic_kappa_rad_per_mps": self.kappa, "chain": self.chain.drawn()}

    def meta(self):
        m = super().meta()
        # the maker's drift specification (what the team knows): the slow wander's standard deviation
        # and correlation time, and the resolution; the corrector settings as set on the dial
        gm = self.spec.get("gauss_markov", {"sd": 0.0, "tau_s": 1.0})
        m.update({"drift_std_rad": float(gm["sd"]) * self.f, "drift_tau_s": float(gm["tau_s"]),
                  "resolution_rad": float(self.spec.get("resolution", 0.0)) * self.f})
        if hasattr(self, "v_c") and self.north_seeking:
            m.update({"corrector_speed_mps": self.v_c, "corrector_latitude_rad": self.lat_c})
        return m


class Attitude(Device):
    """Vertical gyro: roll and pitch."""

    kind = "attitude"
    channels = {"roll": ("rad", "roll (+ starboard down)"), "pitch": ("rad", "pitch (+ bow up)")}
    n_axes = 2

    def measurand(self, kin, cols):
        return np.column_stack([cols["roll"], cols["pitch"]])


class WaveProbe(Device):
    """Motion-compensated wave probe on a boom ahead of the bow (a shipborne wave meter: downward range
    sensor plus a heave accelerometer at the same point, Tucker 1956): the surface elevation (up) of the
    incident seaway at the site's horizontal position, a point that moves with the ship — the encounter-
    frame wave input of a seakeeping trial. The simulated sea has no radiated or diffracted waves, so
    the footprint ahead of the stem sees the incident wave; the motion compensation's own errors are
    lumped into the chain's gain error, noise and resolution. The seaway is given by :meth:`attach_sea`
    (the instrument set's sea-sensing hook; calm: elevation 0)."""

    kind = "wave_probe"
    needs_sea = True
    channels = {"elevation": ("m", "surface elevation at the probe footprint (up)")}

    def build(self):
        super().build()
        self.components = np.zeros((0, 6))

    def attach_sea(self, field) -> None:
        """The scenario's seaway (a :class:`~vtrials.physics.environment.waves.WaveField`, None: calm)."""
        comp = np.zeros((0, 6)) if field is None else field.components
        self.components = np.asarray(comp, dtype=float).reshape(-1, 6)

    def measurand(self, kin, cols):
        if self.components.shape[0] == 0 or cols["t"].size == 0:
            return np.zeros(cols["t"].size)
        from vtrials.physics.environment.waves import elevation
        pos = kin.position()
        return elevation(self.components, pos[:, 0], pos[:, 1], cols["t"])

    def meta(self):
        m = super().meta()
        sm, ss = _dist(self.spec, "scale")
        m["scale_std"] = ss  # the stated gain accuracy of the probe (1σ, fraction)
        return m


class IMU(Device):
    """Strapdown motion package at its site: triaxial accelerometers (specific force, including the
    lever-arm centripetal and tangential terms) and rate gyros, each with bias, bias instability
    (Gauss–Markov), bias random walk (rate random walk of the gyros, IEEE Std 952-1997 Annex C
    coefficient K: Allan deviation K √(τ/3); the accelerometers' bias random walk likewise), noise,
    scale-factor error and a common misalignment (the mounting's angular error).

    Mounting and timing (issue 13, opt-in catalogue keys): ``lever_arm_sd_m`` — the package actually sits
    N(0, sd²) per body axis away from its surveyed site (drawn per trial; the accelerometers feel the
    lever-arm terms of the actual position, the record gives the surveyed one); ``latency_s`` — each
    sample is stamped that long after the instant it describes (the filter and bus delay of the package,
    :class:`~vtrials.instruments.parts.Latency`); the logger clock's offset and drift are the instrument
    set's (every instrument has one)."""

    kind = "imu"
    extra_keys = {"accel_bias_ug", "accel_gauss_markov_ug", "accel_noise_mps2", "accel_scale", "gyro_bias_dph",
                  "gyro_gauss_markov_dph", "gyro_noise_dps", "gyro_scale", "accel_random_walk_ug_rth",
                  "gyro_random_walk_dph_rth", "lever_arm_sd_m"}
    channels = {"ax": ("m s-2", "specific force x"), "ay": ("m s-2", "specific force y"),
                "az": ("m s-2", "specific force z (≈ −g at rest)"), "p": ("rad s-1", "roll rate"),
                "q": ("rad s-1", "pitch rate"), "r": ("rad s-1", "yaw rate")}
    n_axes = 6

    def build(self):
        s = self.spec
        ug = 9.80665e-6
        dph = DEG / 3600.0
        am, asd = _dist(s, "accel_bias_ug", ug)
        gm_, gsd = _dist(s, "gyro_bias_dph", dph)
        agm = s.get("accel_gauss_markov_ug", {"sd": 0.0, "tau_s": 100.0})
        ggm = s.get("gyro_gauss_markov_dph", {"sd": 0.0, "tau_s": 100.0})
        sa = s.get("accel_scale", {"mean": 0.0, "sd": 0.0})
        sg = s.get("gyro_scale", {"mean": 0.0, "sd": 0.0})
        self.acc = P.Chain([P.Misalignment(sd=float(s.get("misalignment_deg", 0.0)) * DEG, n_axes=3),
                            P.ScaleFactor(sa["mean"], sa["sd"], n_axes=3), P.Bias(am, asd, n_axes=3),
                            P.GaussMarkov(float(agm["tau_s"]), float(agm["sd"]) * ug, n_axes=3),
                            P.WhiteNoise(float(s.get("accel_noise_mps2", 0.0)), n_axes=3),
                            # last (the parts add, so the order is immaterial): the other parts keep their draws
                            P.RandomWalk(float(s.get("accel_random_walk_ug_rth", 0.0)) * ug / 60.0, n_axes=3)])
        self.gyr = P.Chain([P.Misalignment(sd=float(s.get("misalignment_deg", 0.0)) * DEG, n_axes=3),
                            P.ScaleFactor(sg["mean"], sg["sd"], n_axes=3), P.Bias(gm_, gsd, n_axes=3),
                            P.GaussMarkov(float(ggm["tau_s"]), float(ggm["sd"]) * dph, n_axes=3),
                            P.WhiteNoise(float(s.get("gyro_noise_dps", 0.0)) * DEG, n_axes=3),
                            P.RandomWalk(float(s.get("gyro_random_walk_dph_rth", 0.0)) * dph / 60.0, n_axes=3)])
        self.clock = P.Resample(float(s["rate_hz"]))
        self.chain = P.Chain([self.clock])
        self.latency = float(s.get("latency_s", 0.0))
        self.lever_sd = float(s.get("lever_arm_sd_m", 0.0))
        if not (math.isfinite(self.latency) and self.latency >= 0.0):
            raise SpecError("latency_s", f"must be finite and >= 0 s, got {s.get('latency_s')!r}")
        if not (math.isfinite(self.lever_sd) and self.lever_sd >= 0.0):
            raise SpecError("lever_arm_sd_m", f"must be finite and >= 0 m, got {s.get('lever_arm_sd_m')!r}")
        self.lever_error = np.zeros(3)

    def reset(self, rng):
        r1, r2, r3 = rng.spawn(3)
        self.clock.reset(r1)
        self.acc.reset(r2)
        self.gyr.reset(r3)
        if self.lever_sd > 0.0:  # a fourth child only when asked: the other draws stay as they were
            (r4,) = rng.spawn(1)
            self.lever_error = self.lever_sd * r4.standard_normal(3)

    def process(self, cols):
        kin = SiteKinematics(cols, self.site + self.lever_error)
        t, y = self.clock.process(cols["t"], np.column_stack([kin.specific_force(), kin.omega]))
        _, a = self.acc.process(t, y[:, :3])
        _, w = self.gyr.process(t, y[:, 3:])
        if self.latency > 0.0:
            t = t + self.latency
        return t, {"ax": a[:, 0], "ay": a[:, 1], "az": a[:, 2], "p": w[:, 0], "q": w[:, 1], "r": w[:, 2]}

    def drawn(self):
        d = {"clock": self.clock.drawn(), "accelerometers": self.acc.drawn(), "gyros": self.gyr.drawn()}
        if self.lever_sd > 0.0 or self.latency > 0.0:
            d.update(lever_arm_error_m=self.lever_error.tolist(), latency_s=self.latency)
        return d

    def meta(self):
        # the data sheet as the team has it (SI, 1σ): white noise per sample, turn-on bias and its
        # in-run instability (Gauss–Markov σ, τ), bias random walks
        m = super().meta()
        s, ug, dph = self.spec, 9.80665e-6, DEG / 3600.0
        agm = s.get("accel_gauss_markov_ug", {"sd": 0.0, "tau_s": 100.0})
        ggm = s.get("gyro_gauss_markov_dph", {"sd": 0.0, "tau_s": 100.0})
        m.update({"accel_noise_mps2": float(s.get("accel_noise_mps2", 0.0)),
                  "gyro_noise_rps": float(s.get("gyro_noise_dps", 0.0)) * DEG,
                  "accel_bias_std": float(s.get("accel_bias_ug", {}).get("sd", 0.0)) * ug,
                  "gyro_bias_std": float(s.get("gyro_bias_dph", {}).get("sd", 0.0)) * dph,
                  "accel_instability": [float(agm["sd"]) * ug, float(agm["tau_s"])],
                  "gyro_instability": [float(ggm["sd"]) * dph, float(ggm["tau_s"])],
                  "gyro_scale_sd": float(s.get("gyro_scale", {}).get("sd", 0.0)),
                  "accel_random_walk": float(s.get("accel_random_walk_ug_rth", 0.0)) * ug / 60.0,
                  "gyro_random_walk": float(s.get("gyro_random_walk_dph_rth", 0.0)) * dph / 60.0})
        if self.lever_sd > 0.0:
            m["lever_arm_survey_sd_m"] = self.lever_sd  # how well the installation's position was surveyed
        return m


class Anemometer(Device):
    """Anemometer on a mast: apparent wind at the site (true wind at its height minus the site's own
    velocity over ground — the motion-induced part from the mast's lever arm included), distorted by
    the airwake of hull and superstructure (a speed factor 1 + Σ aₖ cos kγ + bₖ sin kγ and a direction
    offset Σ cₖ sin kγ of the relative wind angle γ), lagged by the cups' distance constant
    (first-order, time constant = distance constant / wind speed) and cut below the start threshold;
    vane alignment error, noise and resolution."""

    kind = "anemometer"
    extra_keys = {"distance_constant_m", "start_threshold_mps", "speed_bias_kn", "speed_resolution_kn",
                  "direction_alignment_deg", "direction_noise_deg", "direction_resolution_deg", "airwake_speed",
                  "airwake_direction_deg"}
    channels = {"speed": ("m s-1", "relative wind speed"),
                "angle": ("rad", "relative wind angle it comes from, off the bow, + to starboard (0..2π)")}

    #: the simulated wind's mean profile (power-law exponent, height [m] of the truth's wind speed);
    #: :class:`vtrials.instruments.suite.InstrumentSet` sets the scenario's (``wind_profile``)
    profile = (TRIALS_PROFILE_EXPONENT, Z_REF_10)

    def build(self):
        s = self.spec
        self.dc = float(s.get("distance_constant_m", 0.0))
        self.start = float(s.get("start_threshold_mps", 0.0))
        self.ws = np.asarray(s.get("airwake_speed", [0.0]), float)
        self.wd = np.asarray(s.get("airwake_direction_deg", [0.0]), float) * DEG
        bm, bs = _dist(s, "speed_bias_kn", KNOT)
        am, asd = _dist(s, "direction_alignment_deg", DEG)
        self.clock = P.Resample(float(s["rate_hz"]))
        spd = [P.Bias(bm, bs)]
        if s.get("speed_resolution_kn"):
            spd.append(P.Quantization(float(s["speed_resolution_kn"]) * KNOT))
        drn = [P.Bias(am, asd)]
        if s.get("direction_noise_deg"):
            drn.append(P.WhiteNoise(float(s["direction_noise_deg"]) * DEG))
        if s.get("direction_resolution_deg"):
            drn.append(P.Quantization(float(s["direction_resolution_deg"]) * DEG))
        self.spd = P.Chain(spd)
        self.dir = P.Chain(drn)
        self.chain = P.Chain([self.clock])

    def reset(self, rng):
        r1, r2, r3 = rng.spawn(3)
        self.clock.reset(r1)
        self.spd.reset(r2)
        self.dir.reset(r3)
        self._lag = None
        self._tlast = None

    def airwake(self, speed, gamma):
        k = np.arange(1, (len(self.ws) - 1) // 2 + 1)
        fac = 1.0 + self.ws[0] + sum(self.ws[2 * i - 1] * np.cos(i * gamma) + self.ws[2 * i] * np.sin(i * gamma)
                                     for i in k)
        off = self.wd[0] + sum(self.wd[i] * np.sin(i * gamma) for i in range(1, len(self.wd)))
        return speed * fac, gamma + off

    def process(self, cols):
        kin = SiteKinematics(cols, self.site)
        speed, gamma = kin.apparent_wind(*self.profile)
        speed, gamma = self.airwake(speed, gamma)
        t = cols["t"]
        if self.dc > 0.0 and t.size:
            # cups respond over their distance constant: a first-order lag with τ = d / U
            y0 = speed[0] if self._lag is None else self._lag
            t0 = t[0] if self._tlast is None else self._tlast
            speed, self._lag = first_order_lag(t, speed, self.dc / np.maximum(speed, 0.1), y0, t0)
            self._tlast = t[-1]
        speed = np.where(speed < self.start, 0.0, speed)
        tt, y = self.clock.process(t, np.column_stack([speed, np.cos(gamma), np.sin(gamma)]))
        _, sp = self.spd.process(tt, y[:, 0])
        _, ang = self.dir.process(tt, np.arctan2(y[:, 2], y[:, 1]))
        return tt, {"speed": np.maximum(sp, 0.0), "angle": _wrap2pi(ang)}

    def drawn(self):
        return {"clock": self.clock.drawn(), "speed": self.spd.drawn(), "direction": self.dir.drawn()}

    def meta(self):
        m = super().meta()
        # with the mast's airwake survey (model test / CFD / survey runs), which the team corrects for
        m.update({"distance_constant_m": self.dc, "start_threshold_mps": self.start,
                  "airwake_speed": self.ws.tolist(), "airwake_direction_rad": self.wd.tolist()})
        return m


#: time constant [s] of each of the two cascaded first-order filters that define the ship's "mean
#: motion" for the airwake (the flow round the hull follows the ship's slow velocity, not its wave-frequency
#: oscillation: the oscillating instrument moves through a quasi-steady distorted flow). 2 × 15 s keeps
#: 0.5 % of a 7-s wave-frequency velocity and settles a speed change in about 90 s (assumption).
AIRWAKE_MEAN_MOTION_TAU_S = 15.0


@nb.njit(cache=True)
def _two_lags(t, x, a1, a2, tl, tau):
    y = np.empty_like(x)
    for k in range(t.size):
        al = 1.0 - math.exp(-max(t[k] - tl, 0.0) / tau)
        for j in range(x.shape[1]):
            a1[j] += al * (x[k, j] - a1[j])
            a2[j] += al * (a1[j] - a2[j])
            y[k, j] = a2[j]
        tl = t[k]
    return y, tl


def _mean_motion_filter(t, x, state):
    """Two cascaded first-order low-passes (τ = AIRWAKE_MEAN_MOTION_TAU_S, exact for a sample hold)
    of x (n, k), streaming: state = (y1, y2, t_last) or None (start at x[0])."""
    if state is None:
        state = (x[0].copy(), x[0].copy(), float(t[0]))
    a1, a2, tl = state[0].copy(), state[1].copy(), state[2]
    y, tl = _two_lags(np.ascontiguousarray(t, dtype=np.float64), np.ascontiguousarray(x, dtype=np.float64),
                      a1, a2, float(tl), AIRWAKE_MEAN_MOTION_TAU_S)
    return y, (a1, a2, tl)


class SonicAnemometer(Device):
    """Three-axis ultrasonic anemometer (e.g. on a mobile airwake mast): the air velocity relative to
    the instrument, (u, v, w) in the ship's body axes (x fwd, y stbd, z down) — what seed 003's AWSM
    takes. The air at the head: the true wind at its height (power-law profile, as :class:`Anemometer`),
    relative to the ship's MEAN motion (:data:`AIRWAKE_MEAN_MOTION_TAU_S`), distorted by the ship's airwake
    at the site (:mod:`vtrials.instruments.airwake`, in ship-carried vertical axes), plus that mean motion;
    then minus the head's own velocity (ship velocity and ω × ρ, the motion-induced part). Errors: a common
    misalignment of the transducer head, per-axis scale, bias, white noise, resolution.

    A mobile mast (``mobile = true``) is moved between deck sockets by the crew (:meth:`move_to`); the
    ``position`` channel logs which socket (its index in the ``positions`` attribute). The simulator keeps
    the truth of every sample in memory (:meth:`truth_series`) for the scorer; records never carry it."""

    kind = "sonic_anemometer"
    extra_keys = {"mobile"}
    channels = {"u": ("m s-1", "air velocity relative to the instrument, body x (+ towards the bow)"),
                "v": ("m s-1", "air velocity relative to the instrument, body y (+ towards starboard)"),
                "w": ("m s-1", "air velocity relative to the instrument, body z (+ downwards)"),
                "position": ("1", "mast position code: index into the positions attribute")}
    n_axes = 3
    profile = (TRIALS_PROFILE_EXPONENT, Z_REF_10)

    def build(self):
        s = self.spec
        self.mobile = bool(s.get("mobile", False))
        self.clock = P.Resample(float(s["rate_hz"]))
        self.err = value_chain({k: v for k, v in s.items() if k != "rate_hz"}, self.f, 3, sampling=[])
        self.chain = P.Chain([self.clock])
        self.airwake = None  # vtrials.instruments.airwake.Airwake, set by the instrument set
        self.position_names = [self.site_name]
        self.position_sites = {self.site_name: self.site}

    def set_airwake(self, airwake, vessel_sites: dict) -> None:
        """The ship's airwake (truth) and, for a mobile mast, its deck sockets (surveyed sites)."""
        self.airwake = airwake
        if self.mobile and airwake is not None and airwake.mast_positions:
            names = list(airwake.mast_positions)
            if self.site_name not in names:
                names = [self.site_name] + names
            self.position_names = names
            self.position_sites = {n: np.asarray(vessel_sites[n], float) for n in names}

    def reset(self, rng):
        r1, r2 = rng.spawn(2)
        self.clock.reset(r1)
        self.err.reset(r2)
        self._moves = [(-math.inf, self.site_name)]
        self._state = None
        self._truth = []

    def move_to(self, t: float, site: str) -> None:
        """The crew steps the mast in socket ``site`` at time t [s] (readings after t are from there)."""
        if site not in self.position_sites:
            raise ValueError(f"{self.name}: {site!r} is not a position of this mast ({', '.join(self.position_names)})")
        if t < self._moves[-1][0]:
            raise ValueError(f"{self.name}: moves must come in time order")
        self._moves.append((float(t), site))

    def position_at(self, t: np.ndarray) -> list:
        """Socket name per time."""
        tm = np.array([m[0] for m in self._moves])
        idx = np.searchsorted(tm, t, side="right") - 1
        return [self._moves[i][1] for i in idx]

    def _site_airwake(self, name):
        from vtrials.instruments.airwake import NONE
        if self.airwake is None or name not in self.airwake.sites:
            return NONE
        return self.airwake.sites[name]

    def true_velocities(self, cols: dict) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(error-free reading m (n, 3) body axes, local air velocity over ground at the head (n, 3) NED,
        ship (origin) velocity over ground (n, 3) NED) at the truth rows of ``cols``; advances the
        mean-motion filter."""
        t = cols["t"]
        n = t.size
        kin = SiteKinematics(cols, self.site)
        R = kin.R
        names = self.position_at(t)
        r = np.array([self.position_sites[x] for x in names]).reshape(n, 3)
        nu, om = kin.nu, kin.omega
        v_ned = np.einsum("nij,nj->ni", R, nu)
        slow, self._state = _mean_motion_filter(t, v_ned, self._state)
        h = -(cols["z"] + np.einsum("nj,nj->n", R[:, 2, :], r))
        exponent, z_ref = self.profile
        U = cols["wind_speed"] * (np.maximum(h, 0.5) / z_ref) ** exponent
        d = cols["wind_direction"]
        W = np.column_stack([-U * np.cos(d), -U * np.sin(d), np.zeros(n)])
        psi = cols["heading"]
        cp, sp = np.cos(psi), np.sin(psi)
        z0, o1 = np.zeros(n), np.ones(n)
        Rz = np.stack([np.stack([cp, -sp, z0], -1), np.stack([sp, cp, z0], -1), np.stack([z0, z0, o1], -1)], -2)
        rel = np.einsum("nji,nj->ni", Rz, W - slow)  # Rzᵀ (W − V̄): level axes along the heading
        a_v = np.empty_like(rel)
        for name in set(names):
            sel = np.array([x == name for x in names])
            a_v[sel] = self._site_airwake(name).local(rel[sel])
        air = slow + np.einsum("nij,nj->ni", Rz, a_v)
        m = np.einsum("nji,nj->ni", R, air) - (nu + np.cross(om, r))
        return m, air, v_ned

    def process(self, cols):
        t = cols["t"]
        m, air, v_ned = self.true_velocities(cols)
        ang = np.column_stack([cols["roll"], cols["pitch"], cols["heading"]])
        tt, y = self.clock.process(t, np.column_stack([m, air, v_ned, ang]))
        code = np.array([self.position_names.index(x) for x in self.position_at(tt)], float)
        if tt.size:
            self._truth.append((tt, y[:, 0:3], y[:, 3:6], y[:, 6:9], y[:, 9:12], code))
        _, mm = self.err.process(tt, y[:, :3])
        return tt, {"u": mm[:, 0], "v": mm[:, 1], "w": mm[:, 2], "position": code}

    def truth_series(self) -> dict:
        """The truth of every emitted sample (true time): the error-free reading (body axes), the local
        air velocity over ground at the head (airwake included) and the ship's velocity over ground
        (NED), roll, pitch, heading (unwrapped), position code."""
        keys = ("t", "reading", "air", "ship_velocity", "euler", "position")
        if not self._truth:
            return {k: np.zeros((0, 3)) if k in ("reading", "air", "ship_velocity", "euler") else np.zeros(0)
                    for k in keys}
        return {k: np.concatenate([x[i] for x in self._truth]) for i, k in enumerate(keys)}

    def drawn(self):
        return {"clock": self.clock.drawn(), "errors": self.err.drawn(),
                "moves": [[m[0], m[1]] for m in self._moves[1:]]}

    def meta(self):
        m = super().meta()
        s = self.spec
        m.update({"mobile": self.mobile, "positions": self.position_names,
                  "position_sites_m": [self.position_sites[n].tolist() for n in self.position_names],
                  "noise_std": float(s.get("noise", 0.0)) * self.f,
                  "scale_sd": float(_dist(s, "scale")[1]),
                  "misalignment_sd_rad": float(s.get("misalignment_deg", 0.0)) * DEG})
        return m


class AccelerometerArray(Device):
    """A rigid array of single-axis linear accelerometers (Miles 1986, seed 001): sensor j at
    ``positions_m[j]`` from the array's site (body axes), sensitive axis ``axes[j]`` (unit vector),
    reads e_j · f at its point (specific force incl. the lever-arm terms, :class:`SiteKinematics`);
    per-sensor bias, scale, white noise, resolution from the common keys."""

    kind = "accelerometer_array"
    extra_keys = {"positions_m", "axes"}

    def build(self):
        s = self.spec
        p = np.asarray(s.get("positions_m", []), float)
        e = np.asarray(s.get("axes", []), float)
        if p.ndim != 2 or p.shape[1] != 3 or p.shape[0] < 6:
            raise SpecError("positions_m", f"shape {p.shape}; allowed: at least 6 points [x, y, z] [m]")
        if e.shape != p.shape:
            raise SpecError("axes", f"shape {e.shape}; allowed: {p.shape} (one axis per sensor)")
        if not (np.all(np.isfinite(p)) and np.all(np.isfinite(e))) or np.any(np.abs(np.linalg.norm(e, axis=1) - 1) > 1e-6):
            raise SpecError("axes", "finite unit vectors required")
        self.offsets, self.axes = p, e
        self.n_axes = p.shape[0]
        self.channels = {f"a{j + 1}": ("m s-2", f"specific force along axis {e[j].tolist()} at {p[j].tolist()} m")
                         for j in range(self.n_axes)}
        self.chain = value_chain(s, self.f, self.n_axes)

    def measurand(self, kin, cols):
        out = np.empty((cols["t"].size, self.n_axes))
        for j in range(self.n_axes):
            f = SiteKinematics(cols, self.site + self.offsets[j]).specific_force()
            out[:, j] = f @ self.axes[j]
        return out

    def meta(self):
        m = super().meta()
        m.update({"sensor_offsets_m": self.offsets.tolist(), "sensor_axes": self.axes.tolist(),
                  "noise_std": float(self.spec.get("noise", 0.0)) * self.f})
        return m


# ------------------------------------------------------------------------------------- machinery
class ShaftDevice(Device):
    """Base of the per-shaft instruments (spec key 'shaft' in the suite names the shaft)."""

    full_scale_key = "full_scale"

    def __init__(self, name, spec, site_name, site, team, index: int, full_scale: float | None,
                 friction: float = 0.0):
        self.index = index
        self.full_scale = full_scale
        self.friction = float(friction)  # the shaft line's friction coefficient c_F [N m s] (ship model)
        super().__init__(name, spec, site_name, site, team)

    def build(self):
        if any(k.endswith("_fs") for k in self.spec) and not self.full_scale:
            raise SpecError("full_scale", f"{self.kind} errors are given in % of full scale: the suite must give "
                                          f"its full_scale")
        self.chain = value_chain(self.spec, self.f, None, full_scale=self.full_scale)

    def meta(self):
        m = super().meta()
        m.update({"shaft_index": self.index, "full_scale": self.full_scale})
        return m


class ShaftTorque(ShaftDevice):
    """Strain-gauge torsionmeter: the torque in the shaft at the gauge, between the engine and the stern
    tube: the propeller torque plus the friction of the stern-tube bearing and seal aft of the gauge,
    the share ``stern_tube_share`` of the shaft line's friction c_F n
    (:func:`vtrials.instruments.sensor_errors.gauge_torque`). Power from it is shaft power at the gauge,
    P_S = 2π n Q_gauge (not the delivered power 2π n Q_P); :meth:`loss_power` gives the difference for
    the scoring reference.

    Errors: gauge-factor / shear-modulus scale error, a zero offset (``bias_fs``), noise and
    resolution. Before the trial the team sets the zero (shaft turned slowly ahead and astern on the
    turning gear, readings averaged — ITTC 7.5-04-01-01.1): the zero reading it logs, in the record's
    metadata, is the true offset plus the residual error of that procedure (``zero_set_fs``)."""

    kind = "shaft_torque"
    extra_keys = {"bias_fs", "noise_fs", "resolution_fs", "zero_set_fs", "stern_tube_share"}
    channels = {"torque": ("N m", "shaft torque at the gauge")}

    def build(self):
        super().build()
        self.share = float(self.spec.get("stern_tube_share", 0.0))
        if not 0.0 <= self.share <= 1.0:
            raise SpecError("stern_tube_share", f"{self.share} not allowed (a fraction of the shaft line's "
                                                f"friction, 0..1)")

    def reset(self, rng):
        r1, r2 = rng.spawn(2)
        self.chain.reset(r2)
        offset = 0.0
        for part in self.chain.parts:
            if isinstance(part, P.Bias):
                offset = float(np.ravel(part.value)[0])
        zs = float(self.spec.get("zero_set_fs", 0.0)) * (self.full_scale or 0.0)
        self.zero_reading = offset + zs * float(r1.standard_normal())

    def measurand(self, kin, cols):
        return SE.gauge_torque(cols[f"prop_torque_{self.index}"], cols[f"shaft_n_{self.index}"], self.friction,
                               self.share)

    def loss_power(self, rps: float) -> float:
        """Power lost between the gauge and the propeller at shaft speed ``rps`` [rev/s] in steady running
        [W]: 2π n · s c_F n (shaft power at the gauge minus delivered power)."""
        return 2.0 * math.pi * rps * self.share * self.friction * rps

    def drawn(self):
        return {"zero_reading_N_m": self.zero_reading, "stern_tube_share": self.share,
                "shaft_friction_N_m_s": self.friction, "chain": self.chain.drawn()}

    def meta(self):
        m = super().meta()
        if hasattr(self, "zero_reading"):
            m["zero_reading_N_m"] = self.zero_reading
        # the calibration certificate: standard uncertainties of the zero (after zero setting) and scale
        m["zero_uncertainty_N_m"] = float(self.spec.get("zero_set_fs", 0.0)) * (self.full_scale or 0.0)
        m["scale_uncertainty"] = _dist(self.spec, "scale")[1]
        return m


class ShaftSpeed(ShaftDevice):
    """Shaft revolution counter (reflective strips read by an infrared sensor)."""

    kind = "shaft_rpm"
    extra_keys = {"strips"}
    channels = {"rps": ("s-1", "shaft speed (revolutions per second)")}

    def measurand(self, kin, cols):
        return cols[f"shaft_n_{self.index}"]

    def meta(self):
        m = super().meta()
        # the counter's stated accuracy as a standard uncertainty of its reading [rev/s] (catalogue bias sd)
        m["calibration_uncertainty_rps"] = _dist(self.spec, "bias", self.f)[1]
        return m


class Thrustmeter(ShaftDevice):
    """Thrust-bearing load cells: the propeller thrust plus a static load (submergence, weight,
    inclination) that the team must subtract; the team knows its nominal value."""

    kind = "thrust"
    extra_keys = {"bias_fs", "noise_fs", "resolution_fs", "static_load_fs"}
    channels = {"thrust": ("N", "thrust-bearing load (static load included)")}

    def reset(self, rng):
        r1, r2 = rng.spawn(2)
        m, s = _dist(self.spec, "static_load_fs", self.full_scale or 0.0)
        self.static_nominal = m
        self.static = m + s * float(r1.standard_normal())
        self.chain.reset(r2)

    def measurand(self, kin, cols):
        return cols[f"thrust_{self.index}"] + self.static

    def drawn(self):
        return {"static_load_N": self.static, "chain": self.chain.drawn()}

    def meta(self):
        m = super().meta()
        m["nominal_static_load_N"] = self.static_nominal
        return m


class PitchIndicator(ShaftDevice):
    """Controllable-pitch indicator whose zero drifts with the hub-oil temperature, which rises with
    the power delivered (first-order, time constant oil_temperature_tau_s) — seed 002."""

    kind = "pitch_indicator"
    extra_keys = {"oil_temperature_rise_K", "oil_temperature_tau_s", "bias_per_K"}
    channels = {"pitch": ("1", "indicated pitch ratio")}

    def reset(self, rng):
        super().reset(rng)
        self._T = 0.0
        self._tl = None

    def measurand(self, kin, cols):
        s = self.spec
        P_ = 2 * math.pi * cols[f"shaft_n_{self.index}"] * cols[f"prop_torque_{self.index}"]
        pmax = float(self.team.get("max_power_W", [1.0])[self.index])
        rise = float(s.get("oil_temperature_rise_K", 0.0))
        tau = float(s.get("oil_temperature_tau_s", 1.0))
        t = cols["t"]
        if t.size == 0:
            return cols[f"pitch_{self.index}"]
        t0 = t[0] if self._tl is None else self._tl
        T, self._T = first_order_lag(t, rise * np.abs(P_) / pmax, np.full(t.size, tau), self._T, t0)
        self._tl = t[-1]
        return cols[f"pitch_{self.index}"] + float(s.get("bias_per_K", 0.0)) * T


class RudderAngle(Device):
    """Rudder angle synchro (per rudder: spec key 'rudder' in the suite)."""

    kind = "rudder"
    channels = {"angle": ("rad", "rudder angle (+ trailing edge to starboard)")}

    def __init__(self, name, spec, site_name, site, team, index: int):
        self.index = index
        super().__init__(name, spec, site_name, site, team)

    def measurand(self, kin, cols):
        return cols[f"rudder_{self.index}"]

    def meta(self):
        m = super().meta()
        m["rudder_index"] = self.index
        # the synchro's stated accuracy (calibration certificate), as a standard uncertainty
        m["calibration_uncertainty_rad"] = _dist(self.spec, "bias", self.f)[1]
        return m


KINDS = {"gnss": GNSS, "range_radar": RangeRadar, "acoustic_range": AcousticRange, "loran": Loran,
         "knotmeter": Knotmeter, "em_log": EMLog, "doppler_log": DopplerLog, "heading": Heading,
         "attitude": Attitude, "imu": IMU, "wave_probe": WaveProbe, "anemometer": Anemometer,
         "sonic_anemometer": SonicAnemometer, "accelerometer_array": AccelerometerArray, "shaft_torque": ShaftTorque,
         "shaft_rpm": ShaftSpeed, "thrust": Thrustmeter, "pitch_indicator": PitchIndicator, "rudder": RudderAngle}
