"""Driving the simulator from outside: controllers act between steps; one driver owns the loop.

The split of the best control suites (dm_control's physics / task / environment):

* **physics** — :class:`~vtrials.physics.simulator.Simulator`: N ships in one MuJoCo batch, with
  per-ship commands (rudder order, shaft r/min, pitch, shaft mode, engine order; or a compiled helm
  programme that reacts inside the step kernel) set between steps;
* **controllers** — whatever sets those commands: the virtual crew, the maneuver programmes, a
  gymnasium agent, a system-identification input design, or a hand-written PID in a test. A
  :class:`Controller` says at which step it next wants to act and then acts;
* **driver** — :class:`Driver`: steps the simulator, streams the truth into each ship's instruments
  (so the instruments sample the same truth stream whoever drives), hands truth rows to whoever
  keeps them, and gives the controllers their turns.

A controller sees the ship as the trials team does, through ``driver.instruments[ship]`` (and may
look at ``driver.sim`` where its role allows, e.g. a scoring reward); the driver never decides
anything itself.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Protocol

import numpy as np

from vtrials.physics.simulator import Simulator
from vtrials.truth.columns import row_columns

MAX_SLICE_S = 60.0  # longest stretch simulated between two handovers of truth to the instruments
FLUSH_ALL_S = 600.0  # instruments nobody is watching take their truth in chunks this long


class Controller(Protocol):
    """Something that sets ship commands between simulation steps."""

    def next_step(self, driver: Driver) -> int:
        """The step count at which :meth:`act` should run next (``driver.step_count`` or later)."""

    def act(self, driver: Driver) -> None:
        """Read what the controller may read and set the commands of the ships it drives."""

    def done(self, driver: Driver) -> bool:
        """True when the controller has nothing more to do."""


TruthSink = Callable[[int, np.ndarray], None]  # (ship, truth rows (K, width)) after each slice


class Driver:
    """Steps ``sim``, streams truth into ``instruments`` ({ship: InstrumentSet}) and calls ``sinks``.

    Truth is handed over in slices of at most ``slice_s`` seconds (shorter when a controller wants to
    act sooner); each ship's instruments get every truth row, the crew's displays flush on demand and
    the rest of the instruments every ``flush_every_s``. With neither instruments nor sinks the truth
    stays in the simulator (``sim.truth()``) for the caller.
    """

    def __init__(self, sim: Simulator, instruments: dict | None = None, sinks: list[TruthSink] | None = None,
                 slice_s: float = MAX_SLICE_S, flush_every_s: float = FLUSH_ALL_S):
        self.sim = sim
        self.instruments = dict(instruments or {})
        self.sinks = list(sinks or [])
        self.slice_steps = max(1, int(round(slice_s / sim.dt)))
        self.flush_every_s = float(flush_every_s)
        self.step_count = 0
        self.instrument_wall_s = 0.0  # wall time spent in the instruments (benchmarks)
        self.names = sim.rec_names
        self._unflushed = 0

    @property
    def streaming(self) -> bool:
        return bool(self.instruments or self.sinks)

    def time(self, ship: int = 0) -> float:
        return float(self.sim.time[ship])

    def columns(self, rows: np.ndarray) -> dict:
        """Truth rows (K, width) of one ship as named columns, with the track through the water and the
        integrator step ``step_s``."""
        return row_columns(rows, self.names, self.sim.dt)

    # ------------------------------------------------------------------ stepping
    def advance_steps(self, n: int) -> None:
        """Simulate ``n`` steps, handing the truth over after every slice."""
        if not self.streaming:
            self.sim.step(n)
            self.step_count += n
            return
        while n > 0:
            k = min(n, self.slice_steps)
            try:
                self._step(k)
                self.step_count += k
            finally:
                self._hand_over()
            n -= k

    def _step(self, k: int) -> None:
        self.sim.step(k)

    def _take_truth(self) -> dict:
        """The truth rows since the last hand-over, {ship: rows (K, width)}, taken out of the simulator."""
        rec = self.sim.truth()
        self.sim.clear_truth()
        if rec.shape[0] == 0:
            return {}
        return {ship: np.ascontiguousarray(rec[:, ship, :]) for ship in range(rec.shape[1])}

    def advance(self, seconds: float) -> None:
        """Simulate ``seconds`` more (rounded to whole steps)."""
        self.advance_steps(int(round(seconds / self.sim.dt)))

    def _hand_over(self) -> None:
        import time
        taken = self._take_truth()
        if not taken:
            return
        flush = False
        if self.instruments:
            self._unflushed += next(iter(taken.values())).shape[0]
            flush = self._unflushed * self.sim.dt * self.sim.record_every >= self.flush_every_s - 1e-9
        for ship, rows in taken.items():
            iset = self.instruments.get(ship)
            if iset is not None:
                iset.push(self.columns(rows))
                if flush:
                    t0 = time.perf_counter()
                    iset.flush()
                    self.instrument_wall_s += time.perf_counter() - t0
            for sink in self.sinks:
                sink(ship, rows)
        if flush:
            self._unflushed = 0

    # ------------------------------------------------------------------ control loop
    def run(self, controllers: list[Controller], max_steps: int | None = None) -> None:
        """Give the controllers their turns until all are done (or ``max_steps`` more steps).

        Each round: every controller says when it next wants to act, the earliest of those steps is
        simulated to, and every controller whose step has come acts, in the order given.
        """
        limit = None if max_steps is None else self.step_count + int(max_steps)
        active = [c for c in controllers if not c.done(self)]
        while active:
            wants = [c.next_step(self) for c in active]
            target = min(wants)
            if limit is not None and target > limit:
                self.advance_steps(limit - self.step_count)
                return
            if target > self.step_count:
                self.advance_steps(target - self.step_count)
            for c, w in zip(active, wants):
                if w <= self.step_count:
                    c.act(self)
            active = [c for c in active if not c.done(self)]


class PeriodicController:
    """A controller that acts every ``period_s`` on one ship, for ``duration_s`` (base for simple laws)."""

    def __init__(self, ship: int, period_s: float, duration_s: float):
        self.ship = ship
        self.period_s = float(period_s)
        self.duration_s = float(duration_s)
        self._next = None
        self._end = None

    def next_step(self, driver: Driver) -> int:
        if self._next is None:
            self._next = driver.step_count
            self._end = driver.step_count + int(round(self.duration_s / driver.sim.dt))
        return self._next

    def act(self, driver: Driver) -> None:
        self.control(driver)
        self._next = driver.step_count + max(1, int(round(self.period_s / driver.sim.dt)))

    def done(self, driver: Driver) -> bool:
        return self._end is not None and driver.step_count >= self._end

    def control(self, driver: Driver) -> None:
        raise NotImplementedError
