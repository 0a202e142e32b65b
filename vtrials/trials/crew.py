"""The virtual trials crew: executes an agenda's runs one after another on one simulated ship.

What the crew does for each run (seed 002, "How the trials are conducted"):

1. Sets the run's shaft settings (engine order, or r/min and pitch; shafts trailed or locked) and
   comes to the run's course — a Williamson turn (``turn_rudder`` until the heading has changed 60°,
   then the same rudder the other way until the reciprocal is ``turn_lead`` away, then the helm meets
   the swing) when the course is reversed, a plain turn otherwise.
2. Waits until the ship is steady, judged — as the director judges it — from the instruments only:
   trends of shaft r/min, torque and log speed over the last window, and the mean heading error
   (:func:`judge`). Twin-screw CP ships are balanced on the way: r/min matched, pitch trimmed until
   the torque meters agree. If steadiness does not come within ``settle_max_s`` the run goes ahead,
   flagged.
3. COMEX, one minute of steady approach, EXECUTE, the run (heading held by the helm within the
   trial's rudder limit, settings untouched), FINEX. The data window is judged again; an unsteady run
   is repeated if the agenda allows.

The crew never reads truth to decide anything: its decisions come from the instrument readings it
has streamed so far. Truth flows past it into the truth store and the per-run truth references used
for scoring (kept apart from the log sheet that goes into the record).
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections import deque

import numpy as np

from vtrials.physics import steering as H
from vtrials.trials.agenda import Agenda, Run
from vtrials.physics.dynamics import NV_PSI_U
from vtrials.errors import SimulationError
from vtrials.instruments import sensor_errors as SE
from vtrials.instruments.devices import UNIT_FACTORS
from vtrials.physics.propulsion import MODE_NAMES, S_CP
from vtrials.physics.simulator import Simulator
from vtrials.trials.driver import MAX_SLICE_S, Driver
from vtrials.units import DEG, KNOT, RPM

EV_COMEX, EV_EXECUTE, EV_FINEX = 1, 2, 3
TURN_LEAD_DEG = 10.0  # the helm eases the turn this far before the new course and meets the swing
MAX_BALANCE_TRIMS = 4


# ----------------------------------------------------------------------------------- the director
def _trend(t: np.ndarray, y: np.ndarray) -> tuple[float, float]:
    """(mean, change across the window from a least-squares line) of a reading series."""
    if t.size < 3:
        return (float(np.mean(y)) if y.size else math.nan), math.nan
    tc = t - t.mean()
    den = float(tc @ tc)
    slope = float(tc @ (y - y.mean())) / den if den > 0 else 0.0
    return float(y.mean()), slope * float(t[-1] - t[0])


def trend_noise_sd(t: np.ndarray, white_sd: float = 0.0, resolution: float = 0.0, gm_sd: float = 0.0,
                   gm_tau_s: float = math.inf) -> float:
    """Standard deviation of the change across a window that :func:`_trend` reads from an instrument's
    own errors alone, for a steady quantity: white noise (sd ``white_sd``), quantisation (step
    ``resolution``, variance step²/12) and a first-order Gauss–Markov error (sd ``gm_sd``, correlation
    time ``gm_tau_s``: covariance gm_sd² e^{−|Δt|/τ}). The least-squares change is T Σ cᵢ yᵢ with
    cᵢ = (tᵢ − t̄)/Σ(tⱼ − t̄)², so var = T² cᵀ Σ c (exact for these error models; Bendat & Piersol,
    *Random Data*, 4th ed., 2010, §4.6 for the Gauss–Markov covariance)."""
    t = np.asarray(t, dtype=float)
    if t.size < 3:
        return math.inf
    tc = t - t.mean()
    den = float(tc @ tc)
    if den <= 0:
        return math.inf
    c = tc / den
    var = (white_sd ** 2 + resolution ** 2 / 12.0) * float(c @ c)
    if gm_sd > 0:
        if math.isfinite(gm_tau_s):
            K = np.exp(-np.abs(t[:, None] - t[None, :]) / gm_tau_s)
            var += gm_sd ** 2 * float(c @ K @ c)
    T = float(t[-1] - t[0])
    return math.sqrt(var) * T


def judge(display: dict, course: float | None, st, modes: tuple, torque_floor: float = 0.0) -> tuple[bool, list[str]]:
    """The director's steadiness verdict over a window of instrument readings.

    ``display``: {"rps": [(t, x) per shaft or None], "torque": [(t, x) per shaft or None],
    "heading": (t, ψ) or None, "log": (t, speed) or None}; ``course`` [rad]; ``st`` the agenda's
    :class:`~vtrials.trials.agenda.Steadiness` (``course`` None: heading not judged, e.g. stopped or astern);
    ``modes`` per shaft; ``torque_floor`` [N m]: the torque tolerance is relative to at least this
    (a shaft at zero pitch carries almost no torque). Returns (steady, reasons it is not). Shafts that
    are locked are not judged; a trailing shaft's torque is not judged.
    """
    why = []
    for k, mode in enumerate(modes):
        if mode == "locked":
            continue
        rd = display["rps"][k]
        if rd is not None:
            m, ch = _trend(*rd)
            if not math.isfinite(ch) or abs(ch) > st.rpm_pct / 100 * max(abs(m), 1e-6):
                why.append(f"shaft {k} r/min changing {ch * 60:+.2f} r/min over the window")
        qd = display["torque"][k]
        if mode == "governed" and qd is not None:
            m, ch = _trend(*qd)
            if not math.isfinite(ch) or abs(ch) > st.torque_pct / 100 * max(abs(m), torque_floor, 1e-6):
                why.append(f"shaft {k} torque changing {ch / 1e3:+.2f} kN m over the window")
    hd = display["heading"]
    if course is not None and hd is not None and hd[0].size:
        err = math.atan2(float(np.mean(np.sin(hd[1] - course))), float(np.mean(np.cos(hd[1] - course))))
        if abs(err) > st.heading_deg * DEG:
            why.append(f"heading {math.degrees(err):+.1f}° off the course")
    ld = display["log"]
    if ld is not None:
        # a log-speed trend is called only when it exceeds the tolerance by more than the log's own
        # errors could produce over the window (2 × :func:`trend_noise_sd` of its stated noise,
        # resolution and drift): the director does not chase the log's drift and quantisation
        m, ch = _trend(*ld)
        noise = display.get("log_noise") or {}
        sd = trend_noise_sd(ld[0], **noise) if noise and ld[0].size >= 3 else 0.0
        if not math.isfinite(ch) or abs(ch) > st.speed_kn * KNOT + 2.0 * sd:
            why.append(f"log speed changing {ch / KNOT:+.2f} kn over the window (allowed {st.speed_kn:.2f} kn "
                       f"+ {2.0 * sd / KNOT:.2f} kn for the log's own noise and drift)")
    return not why, why


def _stated_noise(spec: dict) -> dict:
    """The log's stated errors (its catalogue entry, in SI) that the director allows for when judging
    a trend: white noise, resolution and the Gauss–Markov drift."""
    f = UNIT_FACTORS.get(spec.get("units", "SI"), 1.0)
    gm = spec.get("gauss_markov") or {}
    return {"white_sd": float(spec.get("noise", 0.0) or 0.0) * f,
            "resolution": float(spec.get("resolution", 0.0) or 0.0) * f,
            "gm_sd": float(gm.get("sd", 0.0)) * f if isinstance(gm, dict) else 0.0,
            "gm_tau_s": float(gm.get("tau_s", math.inf)) if isinstance(gm, dict) else math.inf}


# ----------------------------------------------------------------------------------- records kept
@dataclasses.dataclass
class Attempt:
    """One execution of a run, as the director's log sheet has it (goes into the record)."""

    run: Run
    attempt: int
    course_deg: float
    rpm_ordered: list
    pitch_ordered: list
    modes: list
    t_start: float  # the crew started preparing this run (after the previous FINEX)
    t_comex: float = math.nan
    t_execute: float = math.nan
    t_finex: float = math.nan
    approach_steady: bool = False
    approach_notes: list = dataclasses.field(default_factory=list)
    run_steady: bool = False
    run_notes: list = dataclasses.field(default_factory=list)
    accepted: bool = False
    balance_trims: int = 0
    completed: bool = True  # maneuvers: FINEX condition reached
    settings: list = dataclasses.field(default_factory=list)  # spirals: one entry per setting
    t_release: float = math.nan  # pull-out: rudder centred

    def log(self) -> dict:
        r = self.run
        return {"run": r.number, "attempt": self.attempt, "trial": r.trial, "label": r.label, "kind": r.kind,
                "group": r.group, "leg": r.leg, "course_deg": self.course_deg, "order": r.order,
                "rpm_ordered": self.rpm_ordered, "pitch_ordered": self.pitch_ordered, "shaft_modes": self.modes,
                "t_start": self.t_start, "t_comex": self.t_comex, "t_execute": self.t_execute,
                "t_finex": self.t_finex, "approach_steady": self.approach_steady,
                "approach_notes": self.approach_notes, "run_steady": self.run_steady, "run_notes": self.run_notes,
                "accepted": self.accepted, "balance_trims": self.balance_trims,
                "elapsed_s": self.t_finex - self.t_start, "completed": self.completed,
                "maneuver": {k: v for k, v in r.params.items()}, "settings": self.settings,
                "t_release": self.t_release}


def window_truth(cols: dict, t0: float, t1: float) -> dict:
    """Truth references of a run window [t0, t1] by their own definitions (SI):

    speed through water = mean of √(u_r² + v_r²); surge through water = mean u_r; speed over ground =
    straight-line distance between the window's end positions / its length; current = mean current
    vector at the ship; per shaft: mean r/s, propeller torque, thrust, pitch, delivered power
    mean(2π n Q); true wind (10 m) mean speed and direction; mean heading (circular) and rudders.
    """
    t = cols["t"]
    w = (t >= t0 - 1e-9) & (t <= t1 + 1e-9)
    c = {k: v[w] for k, v in cols.items()}
    dtw = c["t"][-1] - c["t"][0]
    out = {"t0": float(c["t"][0]), "t1": float(c["t"][-1]),
           "stw": float(np.mean(np.hypot(c["u_r"], c["v_r"]))), "surge": float(np.mean(c["u_r"])),
           "sog": float(math.hypot(c["x"][-1] - c["x"][0], c["y"][-1] - c["y"][0]) / dtw) if dtw > 0 else math.nan,
           "cog": float(math.atan2(c["y"][-1] - c["y"][0], c["x"][-1] - c["x"][0])),
           "current_n": float(np.mean(c["current_n"])), "current_e": float(np.mean(c["current_e"])),
           "heading": float(math.atan2(np.mean(np.sin(c["heading"])), np.mean(np.cos(c["heading"])))),
           "wind_speed": float(np.mean(c["wind_speed"])),
           "wind_direction": float(math.atan2(np.mean(np.sin(c["wind_direction"])),
                                              np.mean(np.cos(c["wind_direction"])))),
           "wind_apparent_speed": float(np.mean(c["wind_apparent_speed"])),
           "drift_angle": float(np.mean(np.arctan2(c["v_r"], c["u_r"])))}
    k = 0
    shafts = []
    while f"shaft_n_{k}" in c:
        n = c[f"shaft_n_{k}"]
        q = c[f"prop_torque_{k}"]
        shafts.append({"rps": float(np.mean(n)), "torque": float(np.mean(q)),
                       "thrust": float(np.mean(c[f"thrust_{k}"])), "pitch": float(np.mean(c[f"pitch_{k}"])),
                       "power": float(np.mean(2 * math.pi * n * q))})
        k += 1
    out["shafts"] = shafts
    out["power"] = float(sum(s["power"] for s in shafts))
    k = 0
    rud = []
    while f"rudder_{k}" in c:
        rud.append(float(np.mean(c[f"rudder_{k}"])))
        k += 1
    out["rudders"] = rud
    return out


# ----------------------------------------------------------------------------------- the crew
class Crew:
    """Runs an :class:`~vtrials.trials.agenda.Agenda` on ship ``ship`` of a :class:`Simulator`.

    ``iset``: the ship's :class:`~vtrials.instruments.suite.InstrumentSet` (reset by the caller);
    ``truth_every``: keep every k-th truth row for the truth file (instruments see every row);
    ``progress``: a callable taking one line of text (None: silent);
    ``driver``: who steps the simulator — a :class:`~vtrials.trials.driver.Driver` of this crew alone
    (default), or a fleet's :class:`~vtrials.trials.fleet.ShipDriver` when many crews share one
    simulator, each its own ship.
    """

    def __init__(self, sim: Simulator, agenda: Agenda, iset, truth_every: int = 1, progress=None,
                 ship: int = 0, driver: Driver | None = None):
        self.sim = sim
        self.ship = int(ship)
        self._t_done: float | None = None
        self.agenda = agenda
        self.rules = agenda.rules
        self.st = agenda.steadiness
        self.iset = iset
        self.vessel = sim.vessel
        self.truth_every = int(truth_every)
        self.say = progress or (lambda s: None)
        self.names = sim.rec_names
        self.col = {n: j for j, n in enumerate(self.names)}
        ap = self.vessel.autopilot
        self.gains = ap.pid
        self.events: list[tuple[float, int, int]] = []
        self.orders: list[tuple[float, str]] = []
        self.settings: list[tuple[float, int, float, float, int]] = []  # t, shaft, rps, pitch, mode
        self.attempts: list[Attempt] = []
        self.truth_refs: list[dict] = []
        self.truth_rows: list[np.ndarray] = []
        self._recent: deque = deque()
        self._row_count = 0
        self._keep_from = math.inf  # truth rows after this time are kept for the running attempt
        # the crew drives the ship through the driver, which streams the truth into the instruments
        if driver is None:
            driver = Driver(sim)
        driver.instruments[self.ship] = iset
        driver.sinks.append(self._keep)
        self.driver = driver
        self._t_change = 0.0
        self._final_phase = 0
        self._course = 0.0
        self._judged_course = 0.0
        L = self.vessel.length
        self._catch_s = 30.0 + 3.0 * L / max(1.0, 0.1 * math.sqrt(9.81 * L))
        ns = sim.ns
        self.rps_order = [0.0] * ns
        self.pitch_order = [float(sim.shaftp[k, 16]) for k in range(ns)]  # S_PITCH_DESIGN
        self.modes = ["governed"] * ns
        self._cp = [bool(sim.shaftp[k, S_CP] > 0) for k in range(ns)]
        self._torque_floor = 0.02 * min(sh.max_torque for sh in self.vessel.shafts)
        # which instrument the director looks at for what
        self._by_kind = {k: iset.of_kind(k) for k in ("shaft_rpm", "shaft_torque", "heading", "em_log",
                                                       "knotmeter", "doppler_log")}
        self._shaft_inst = {"rps": [None] * ns, "torque": [None] * ns}
        for key, kind in (("rps", "shaft_rpm"), ("torque", "shaft_torque")):
            for name in self._by_kind[kind]:
                k = iset.devices[name].index
                if k < ns and self._shaft_inst[key][k] is None:
                    self._shaft_inst[key][k] = name
        tracks = [n for k in ("range_radar", "gnss", "acoustic_range") for n in iset.of_kind(k)]
        self._track = tracks[0] if tracks else None
        site = iset.team.get("site", {})
        self._center = np.asarray(site.get("range_center", [0.0, 0.0]), float)
        self._runs_done = 0
        logs = self._by_kind["em_log"] or self._by_kind["knotmeter"] or self._by_kind["doppler_log"]
        self._log_inst = logs[0] if logs else None
        self._log_noise = _stated_noise(self.iset.devices[self._log_inst].spec) if logs else None
        self._gyro = self._by_kind["heading"][0] if self._by_kind["heading"] else None

    # ------------------------------------------------------------------ time
    @property
    def t(self) -> float:
        if self._t_done is not None:  # the day is over (in a fleet the ship may go on being stepped)
            return self._t_done
        return float(self.sim.time[self.ship])

    def advance(self, seconds: float) -> None:
        """Simulate ``seconds`` more; the driver streams the truth into the instruments as it goes."""
        self.driver.advance(seconds)

    @property
    def instrument_wall_s(self) -> float:
        """Wall time spent in the instruments (benchmarks)."""
        return self.driver.instrument_wall_s

    @instrument_wall_s.setter
    def instrument_wall_s(self, value: float) -> None:
        self.driver.instrument_wall_s = value

    def _keep(self, ship: int, rows: np.ndarray) -> None:
        """Truth sink: every k-th row for the truth file, and a recent window for the references."""
        k0 = (-self._row_count) % self.truth_every
        self.truth_rows.append(rows[k0::self.truth_every])
        self._row_count += rows.shape[0]
        self._recent.append(rows)
        keep_s = self.rules.approach_s + max(r.duration for r in self.agenda.runs) + 2 * MAX_SLICE_S
        keep_from = min(self.t - keep_s, self._keep_from)
        while len(self._recent) > 1 and self._recent[1][0, 0] < keep_from:
            self._recent.popleft()

    def columns(self, rows: np.ndarray) -> dict:
        return self.driver.columns(rows)

    def recent_truth(self) -> dict:
        return self.columns(np.concatenate(list(self._recent), axis=0))

    # ------------------------------------------------------------------ displays
    def display(self, t0: float) -> dict:
        def get(name, ch):
            if name is None:
                return None
            w0 = time.perf_counter()
            t, c = self.iset.window(name, t0)
            self.instrument_wall_s += time.perf_counter() - w0
            return (t, c[ch])
        def torque(name):  # less the zero logged at the pre-trial zero setting
            d = get(name, "torque")
            return None if d is None else (d[0], d[1] - self.iset.devices[name].meta().get("zero_reading_N_m", 0.0))
        d = {"rps": [get(n, "rps") for n in self._shaft_inst["rps"]],
             "torque": [torque(n) for n in self._shaft_inst["torque"]],
             "heading": get(self._gyro, "heading"), "log": None}
        if d["heading"] is not None:
            d["heading"] = self._gyro_corrected(t0, *d["heading"])
        if self._log_inst is not None:
            kind = self.iset.devices[self._log_inst].kind
            d["log"] = get(self._log_inst, "u" if kind == "doppler_log" else "speed")
            d["log_noise"] = self._log_noise
        return d

    def _gyro_corrected(self, t0: float, t: np.ndarray, h: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The gyro heading as the officer of the watch reads it: less the residual speed error of the
        compass's corrector settings at the ship's north velocity over the window (from the tracking
        fixes) and the site latitude (the speed-error table; vtrials.instruments.sensor_errors)."""
        m = self.iset.devices[self._gyro].meta()
        if "corrector_speed_mps" not in m or self._track is None or h.size == 0:
            return t, h
        tt, c = self.iset.window(self._track, t0)
        ok = np.isfinite(c["north"])
        if np.count_nonzero(ok) < 2 or np.ptp(tt[ok]) <= 0.0:
            return t, h
        vn = float(np.polyfit(tt[ok] - tt[ok][0], c["north"][ok], 1)[0])
        lat = math.radians(float(self.iset.team.get("site", {}).get("latitude_deg", 38.0)))
        err = SE.speed_error(vn, lat)
        if m["corrector_speed_mps"] > 0.0:
            err = err - SE.speed_error(m["corrector_speed_mps"] * np.cos(h), m["corrector_latitude_rad"])
        return t, h - err

    # ------------------------------------------------------------------ orders
    def set_shafts(self, run: Run) -> bool:
        """Give the run's shaft settings; True if anything changed."""
        changed = False
        sim = self.sim
        if run.order is not None and (not self.orders or self.orders[-1][1] != run.order):
            self.orders.append((self.t, run.order))
        for k in range(sim.ns):
            mode = run.modes[k]
            rps = 0.0 if mode == "locked" else run.rps
            pitch = run.pitch if (run.pitch is not None and self._cp[k]) else self.pitch_order[k]
            if mode != self.modes[k] or abs(rps - self.rps_order[k]) > 1e-12 or \
                    (self._cp[k] and run.pitch is not None and abs(pitch - self.pitch_order[k]) > 1e-12):
                changed = True
                self._order_shaft(k, rps, pitch, mode)
        if changed:
            self._t_change = self.t
        return changed

    def _order_all(self, rps: float, pitch: float | None, order: str | None) -> None:
        """An engine order to every governed shaft (a speed change's EXECUTE)."""
        if order is not None:
            self.orders.append((self.t, order))
        for k in range(self.sim.ns):
            if self.modes[k] == "governed":
                self._order_shaft(k, rps, pitch if (pitch is not None and self._cp[k]) else self.pitch_order[k],
                                  "governed")

    def _order_shaft(self, k: int, rps: float, pitch: float, mode: str) -> None:
        sim = self.sim
        sim.set_shaft_order(self.ship, rps, k)
        sim.set_pitch_order(self.ship, pitch, k)
        sim.set_shaft_mode(self.ship, mode, k)
        self.rps_order[k], self.pitch_order[k], self.modes[k] = rps, pitch, mode
        self.settings.append((self.t, k, rps, pitch, MODE_NAMES[mode]))

    def _helm(self, phases: list) -> None:
        self.sim.set_helm(self.ship, phases)
        self._final_phase = len(phases) - 1

    def hold(self, course: float, limit: float) -> None:
        self._course = self._judged_course = course
        self._helm([(H.HEADING, course, limit, *self.gains, 0.0)])

    def come_to(self, course: float, limit: float) -> None:
        """Turn onto ``course``: a Williamson turn for a reversal, else a turn with the turning rudder,
        easing ``TURN_LEAD_DEG`` before the new course; the helm then meets the swing with the turning
        rudder available before settling to the run's limit."""
        psi = float(self.sim.nav[self.ship, NV_PSI_U])
        d = math.atan2(math.sin(course - psi), math.cos(course - psi))
        dt = self.rules.turn_rudder_deg * DEG
        lead = TURN_LEAD_DEG * DEG
        kp, ki, kd = self.gains
        catch = (H.HEADING, course, dt, kp, ki, kd, self._catch_s)
        final = (H.HEADING, course, limit, kp, ki, kd, 0.0)
        self._course = self._judged_course = course
        if abs(d) < 5 * DEG:
            self._helm([catch, final])
        elif abs(d) > 150 * DEG:
            # Williamson turn: starboard rudder until 60° off, then port rudder round to the new course
            # (reached through the original heading: a change of d − 2π for d > 0)
            back = d - 2 * math.pi if d > 0 else d
            self._helm([(H.TURN_UNTIL, dt, 60 * DEG, psi, 1.0),
                        (H.TURN_UNTIL, -dt, back + lead, psi, 1.0),
                        catch, final])
        else:
            s = math.copysign(1.0, d)
            self._helm([(H.TURN_UNTIL, s * dt, d - s * lead, psi, 1.0), catch, final])
        self._t_change = self.t

    def _helm_settled_since(self) -> float | None:
        """Time the helm entered its final (course-holding) phase, None if still turning."""
        if self.sim.helm_phase(self.ship) < self._final_phase:
            return None
        ts = float(self.sim.hs[self.ship, H.H_TSTART])
        return ts if ts >= 0 else self.t

    # ------------------------------------------------------------------ where the ship is
    def position(self) -> np.ndarray | None:
        """Latest fix of the tracking system (north, east) [m], as the director's display shows it."""
        if self._track is None:
            return None
        t, c = self.iset.window(self._track, self.t - 30.0)
        ok = np.isfinite(c["north"]) & np.isfinite(c["east"])
        if not ok.any():
            return None
        return np.array([c["north"][ok][-1], c["east"][ok][-1]])

    def along(self, course: float) -> float:
        """Distance of the ship past the range centre along ``course`` [m] (negative: before it)."""
        p = self.position()
        if p is None:
            return math.nan
        d = p - self._center
        return float(d[0] * math.cos(course) + d[1] * math.sin(course))

    def log_speed(self) -> float:
        """Speed the log shows, averaged over the last half minute [m/s] (at least 0.5 m/s)."""
        if self._log_inst is None:
            return 1.0
        d = self.display(self.t - 30.0)["log"]
        return max(float(np.mean(d[1])) if d is not None and d[1].size else 0.0, 0.5)

    def comex_distance(self, run: Run) -> float:
        """Distance before the centre at which COMEX is given so the run is centred on it [m]."""
        return self.log_speed() * (self.rules.approach_s + 0.5 * run.duration)

    def run_out(self, course: float, distance: float) -> None:
        """Hold ``course`` until the ship is ``distance`` past the range centre (30 min at most)."""
        t_end = self.t + 1800.0
        while self.t < t_end:
            a = self.along(course)
            if not math.isfinite(a) or a >= distance:
                return
            self.advance(min(max((distance - a) / self.log_speed(), self.sim.dt), MAX_SLICE_S))

    def reach_comex_point(self, run: Run, att: Attempt) -> None:
        """Hold the course until the COMEX point before the range centre; note it if already past."""
        for _ in range(100):
            a = self.along(run.heading)
            if not math.isfinite(a):
                return
            rest = -self.comex_distance(run) - a
            if rest <= 0.5 * self.log_speed():
                if rest < -0.1 * self.comex_distance(run):
                    att.approach_notes.append(f"run displaced {-rest:.0f} m past the planned COMEX point")
                return
            self.advance(min(rest / self.log_speed(), MAX_SLICE_S))

    # ------------------------------------------------------------------ settling
    def settle(self, run: Run, att: Attempt) -> None:
        """Wait until steady (or give up at settle_max_s); balance the shafts on the way."""
        r = self.rules
        t_begin = self.t
        while True:
            since = self._helm_settled_since()
            if since is not None:  # no need to look before the earliest moment a verdict can pass
                t_ok = max(since, self._t_change) + max(r.settle_min_s, self.st.window_s)
                self.advance(max(r.check_every_s, min(t_ok - self.t, t_begin + r.settle_max_s - self.t)))
            else:
                self.advance(r.check_every_s)
            since = self._helm_settled_since()
            waited = self.t - t_begin
            if since is not None:
                t_ok = max(since, self._t_change) + max(r.settle_min_s, self.st.window_s)
                if self.t >= t_ok - 1e-9:
                    ok, why = judge(self.display(self.t - self.st.window_s), self._judged_course, self.st,
                                     run.modes, self._torque_floor)
                    if ok:
                        if self._balance(run, att):
                            continue
                        att.approach_steady = True
                        return
                    att.approach_notes = why
            if waited >= r.settle_max_s:
                att.approach_notes = (att.approach_notes or ["helm still turning"]) + \
                    [f"not steady after {waited:.0f} s: run goes ahead, flagged"]
                return

    def _balance(self, run: Run, att: Attempt) -> bool:
        """Twin-shaft balancing (seed 002): CP ships match r/min, then trim pitch until the torque meters
        agree within the tolerance. Returns True when a trim was ordered (the crew settles again)."""
        gov = [k for k in range(self.sim.ns) if self.modes[k] == "governed"]
        if not self.rules.balance_shafts or len(gov) < 2 or not all(self._cp[k] for k in gov) or \
                att.balance_trims >= MAX_BALANCE_TRIMS:
            return False
        d = self.display(self.t - self.st.window_s)
        q = [float(np.mean(d["torque"][k][1])) if d["torque"][k] is not None and d["torque"][k][1].size
             else math.nan for k in gov]
        if not all(math.isfinite(x) for x in q):
            return False
        qm = float(np.mean(q))
        mis = [(x - qm) / qm for x in q]
        if max(abs(m) for m in mis) <= self.rules.balance_tolerance_pct / 100:
            return False
        # torque ∝ (P/D)^~2 at fixed r/min and speed: trim each pitch by half the relative mismatch
        for k, m in zip(gov, mis):
            self._order_shaft(k, self.rps_order[k], self.pitch_order[k] * (1.0 - 0.5 * m), "governed")
        att.balance_trims += 1
        self._t_change = self.t
        return True

    # ------------------------------------------------------------------ runs
    def execute(self, run: Run, attempt: int) -> Attempt:
        if run.kind == "airwake":
            from vtrials.trials import airwake_survey
            return airwake_survey.execute(self, run, attempt)
        if run.kind == "seakeeping":
            return self.execute_seakeeping(run, attempt)
        if run.kind != "speed":
            return self.execute_maneuver(run, attempt)
        att = Attempt(run, attempt, math.degrees(run.heading) % 360.0, [], [], list(run.modes), self.t)
        if attempt == 1:
            self.set_shafts(run)
        psi = float(self.sim.nav[self.ship, NV_PSI_U])
        change = abs(math.atan2(math.sin(run.heading - psi), math.cos(run.heading - psi)))
        placed = self.rules.measured_course and self._track is not None and attempt == 1 and \
            (change > 150 * DEG or self._runs_done == 0)
        if placed and change > 150 * DEG:
            # measured course: run out past the range, far enough to turn and settle before COMEX
            self.run_out(self._course, self.comex_distance(run) + self.log_speed() * self.rules.runout_s)
        if attempt == 1 or change > 5 * DEG:
            self.come_to(run.heading, run.helm_limit)
        self.settle(run, att)
        if placed:
            self.reach_comex_point(run, att)
        self.measure_straight(run, att, run.heading)
        ref = window_truth(self.recent_truth(), att.t_execute, att.t_finex)
        ref.update({"run": run.number, "attempt": attempt})
        self.truth_refs.append(ref)
        self._runs_done += 1
        self.attempts.append(att)
        return att

    def measure_straight(self, run: Run, att: Attempt, course: float) -> None:
        """The measured part of a straight run, once settled on ``course``: the settings ordered,
        COMEX, the approach, EXECUTE, the run held for its duration, FINEX, and the director's verdict
        on its steadiness (a measured-course run and a seakeeping leg alike)."""
        att.rpm_ordered = [x / RPM for x in self.rps_order]
        att.pitch_ordered = [x if self._cp[k] else None for k, x in enumerate(self.pitch_order)]
        self.hold(course, run.helm_limit)
        att.t_comex = self.t
        self.events.append((self.t, run.number, EV_COMEX))
        self.advance(self.rules.approach_s)
        att.t_execute = self.t
        self.events.append((self.t, run.number, EV_EXECUTE))
        self.advance(run.duration)
        att.t_finex = self.t
        self.events.append((self.t, run.number, EV_FINEX))
        att.run_steady, att.run_notes = judge(self.display(att.t_execute), course, self.st, run.modes,
                                              self._torque_floor)

    # ------------------------------------------------------------------ seakeeping legs
    def execute_seakeeping(self, run: Run, attempt: int) -> Attempt:
        """A leg of the star pattern: come to the course relative to the observed waves, settle, COMEX,
        approach, EXECUTE, hold the course for the leg, FINEX (no measured-course placement)."""
        from vtrials.trials import seakeeping as SK
        course = SK.leg_course(self.iset.team, run)
        run = dataclasses.replace(run, heading=course)
        att = Attempt(run, attempt, math.degrees(course) % 360.0, [], [], list(run.modes), self.t)
        self.set_shafts(run)
        self.come_to(course, run.helm_limit)
        self.settle(run, att)
        self.measure_straight(run, att, course)
        cols = self.recent_truth()
        ref = window_truth(cols, att.t_execute, att.t_finex)
        ref.update(SK.leg_truth(cols, att.t_execute, att.t_finex, SK.motion_site(self.iset)))
        ref.update({"run": run.number, "attempt": attempt})
        self.truth_refs.append(ref)
        self._runs_done += 1
        self.attempts.append(att)
        return att

    # ------------------------------------------------------------------ maneuvering runs
    def true_wind_from(self) -> float | None:
        """Direction the wind blows from [rad], from the mast anemometer and the tracked velocity."""
        anem = self.iset.of_kind("anemometer")
        if not anem or self._gyro is None or self._track is None:
            return None
        t, c = self.iset.window(anem[0], self.t - 60.0)
        _, g = self.iset.window(self._gyro, self.t - 60.0)
        tt, fx = self.iset.window(self._track, self.t - 60.0)
        if t.size < 3 or tt.size < 3:
            return None
        psi = math.atan2(np.mean(np.sin(g["heading"])), np.mean(np.cos(g["heading"])))
        # apparent wind (from-direction) in the world, plus the ship's own velocity over ground
        a = psi + c["angle"]
        vn = -np.mean(c["speed"] * np.cos(a))
        ve = -np.mean(c["speed"] * np.sin(a))
        from vtrials.trials.maneuvering import _rate
        ok = np.isfinite(fx["north"]) & np.isfinite(fx["east"])
        gn, ge = _rate(tt[ok], fx["north"][ok]), _rate(tt[ok], fx["east"][ok])
        # true wind velocity = apparent + ship velocity; it blows from the opposite direction
        return math.atan2(-(ve + ge), -(vn + gn))

    def back_to_range(self, run: Run) -> None:
        """If the ship has wandered more than the range radius from the centre, steam back towards it."""
        pos = self.position()
        if pos is None:
            return
        d = pos - self._center
        if math.hypot(*d) <= self.rules.range_radius_m:
            return
        course = math.atan2(-d[1], -d[0])
        self.come_to(course, self.vessel.autopilot.rudder_limit_deg * DEG)
        t_end = self.t + 3600.0
        while self.t < t_end:
            self.advance(MAX_SLICE_S)
            pos = self.position()
            if pos is None or math.hypot(*(pos - self._center)) < 0.5 * self.rules.range_radius_m:
                break

    def execute_maneuver(self, run: Run, attempt: int) -> Attempt:
        from vtrials.trials import maneuvering as MV
        p = run.params
        course = run.heading
        att = Attempt(run, attempt, math.degrees(course) % 360.0, [], [], list(run.modes), self.t)
        self.set_shafts(run)
        underway = run.order not in ("stop", "back_1_3", "back_2_3", "back_full", "back_emergency") and run.rps > 0 \
            and (run.pitch is None or run.pitch > 0.1)
        if underway:
            self.back_to_range(run)
            if p.get("course_rule") in ("into_wind", "with_wind"):
                w = self.true_wind_from()
                if w is None:  # nothing on the anemometer display yet: steam a minute and look again
                    self.advance(MAX_SLICE_S)
                    w = self.true_wind_from()
                if w is not None:
                    course = w if p["course_rule"] == "into_wind" else w + math.pi
                    course = math.atan2(math.sin(course), math.cos(course))
                    att.course_deg = math.degrees(course) % 360.0
            self.come_to(course, run.helm_limit)
        else:  # stopped or going astern: no course to hold, rudder amidships
            self._helm([(H.HOLD, 0.0, 0.0)])
            self._judged_course = None
            self._t_change = self.t
        self.settle(run, att)
        att.rpm_ordered = [x / RPM for x in self.rps_order]
        att.pitch_ordered = [x if self._cp[k] else None for k, x in enumerate(self.pitch_order)]
        if underway:
            self.hold(course, run.helm_limit)
        att.t_comex = self.t
        self._keep_from = self.t - 1.0
        self.events.append((self.t, run.number, EV_COMEX))
        self.advance(self.rules.approach_s)
        att.t_execute = self.t
        self.events.append((self.t, run.number, EV_EXECUTE))
        MV.execute(self, run, att)
        att.t_finex = self.t
        self.events.append((self.t, run.number, EV_FINEX))
        att.run_steady = True  # the maneuver itself is not judged for steadiness; completion is
        cols = self.recent_truth()
        ref = window_truth(cols, att.t_execute, att.t_finex)
        ref.update(MV.maneuver_truth(run, att, cols))
        ref.update({"run": run.number, "attempt": attempt})
        self.truth_refs.append(ref)
        self._keep_from = math.inf
        self._runs_done += 1
        self.attempts.append(att)
        return att

    def run_agenda(self) -> None:
        """Execute every run; repeat unsteady ones as the agenda allows."""
        total0 = self.t
        runs = self.agenda.runs
        self.say(f"agenda: {len(runs)} runs in {len(self.agenda.trials)} trial(s)")
        for run in runs:
            attempt = 1
            while True:
                att = self.execute(run, attempt)
                verdict = "steady" if (att.approach_steady and att.run_steady) else \
                    "UNSTEADY: " + "; ".join(att.approach_notes + att.run_notes)
                self.say(f"  run {run.number:3d} {run.trial}: {run.label:<18s} course {att.course_deg:05.1f}°  "
                         f"{self._setting_text()}  COMEX {_clock(att.t_comex)}  FINEX {_clock(att.t_finex)}  "
                         f"run time {(att.t_finex - att.t_start) / 60:5.1f} min  {verdict}")
                steady = att.approach_steady and att.run_steady
                if steady or attempt > self.rules.repeat_unsteady:
                    att.accepted = True
                    break
                attempt += 1
                self.say(f"      repeating run {run.number} (attempt {attempt})")
        self.say(f"agenda complete: {len(self.attempts)} runs executed in {(self.t - total0) / 3600:.2f} h of "
                 f"trial time")
        self._t_done = self.t

    def _setting_text(self) -> str:
        parts = []
        for k in range(self.sim.ns):
            m = self.modes[k]
            if m != "governed":
                parts.append(m)
            elif self._cp[k]:
                parts.append(f"{self.rps_order[k] / RPM:.0f} r/min P/D {self.pitch_order[k]:.3f}")
            else:
                parts.append(f"{self.rps_order[k] / RPM:.1f} r/min")
        return " | ".join(parts)


def _clock(t: float) -> str:
    if not math.isfinite(t):
        return "--:--:--"
    s = int(round(t))
    return f"{s // 3600:02d}:{s % 3600 // 60:02d}:{s % 60:02d}"


__all__ = ["Attempt", "Crew", "judge", "window_truth", "SimulationError"]
