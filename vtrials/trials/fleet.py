"""Several blocking controllers (virtual crews) on the ships of one simulator, stepped together.

A crew is written in blocking style: it orders, then ``advance(seconds)``, then looks at its
instruments. Stepping many replicates of a trial day in one :class:`~vtrials.physics.simulator.Simulator`
(one MuJoCo batch and one compiled force loop for all of them) amortizes the per-step cost over the
ships — bench_layout.json: 9.3 µs per ship-step for one KVLCC2 alone, 3.7 µs for each of 100 — so a
campaign steps its replicates in groups (issue 11, deliverable 5).

Each crew runs in a greenlet (a coroutine with its own stack; the crew's code is unchanged). Its
driver, a :class:`ShipDriver`, does what a :class:`~vtrials.trials.driver.Driver` does for one ship,
except that "step k" hands control to the :class:`Fleet`, which steps the whole batch to the earliest
step any crew waits for, files each ship's truth rows, and resumes the crews whose step has come, in
ship order. A crew's instruments and truth sinks receive exactly the slices a lone driver would hand
them (its own ``advance`` calls cut at ``slice_s``), and the ships do not interact, so every
replicate's records are bit-identical to its day run alone (tests/test_fleet.py).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from greenlet import greenlet

from vtrials.physics.simulator import Simulator
from vtrials.trials.driver import FLUSH_ALL_S, MAX_SLICE_S, Driver


class ShipDriver(Driver):
    """The driver one crew sees in a fleet: its ship's instruments and sinks, the fleet's steps."""

    def __init__(self, fleet: Fleet, ship: int, slice_s: float = MAX_SLICE_S, flush_every_s: float = FLUSH_ALL_S):
        super().__init__(fleet.sim, {}, [], slice_s=slice_s, flush_every_s=flush_every_s)
        self.fleet = fleet
        self.ship = int(ship)

    def _step(self, k: int) -> None:
        self.fleet._wait(self.ship, self.step_count + k)

    def _take_truth(self) -> dict:
        return self.fleet._take(self.ship)


class Fleet:
    """Steps ``sim`` for one blocking task per ship (see the module docstring)."""

    def __init__(self, sim: Simulator):
        self.sim = sim
        self.step_count = 0
        self._rows: dict[int, list] = {}
        self._waiting: dict[int, tuple[int, greenlet]] = {}
        self._hub: greenlet | None = None

    def driver(self, ship: int, **kw) -> ShipDriver:
        return ShipDriver(self, ship, **kw)

    # called from a task's greenlet
    def _wait(self, ship: int, target: int) -> None:
        if self._hub is None or greenlet.getcurrent() is self._hub:
            raise RuntimeError("a fleet's ship driver steps only inside Fleet.run")
        self._waiting[ship] = (int(target), greenlet.getcurrent())
        self._hub.switch()

    def _take(self, ship: int) -> dict:
        rows = self._rows.get(ship)
        if not rows:
            return {}
        self._rows[ship] = []
        return {ship: rows[0] if len(rows) == 1 else np.concatenate(rows, axis=0)}

    # the scheduler
    def run(self, tasks: list[tuple[int, Callable[[], None]]]) -> None:
        """Run ``tasks`` — (ship, callable) pairs, one per ship, each driving its ship through
        ``self.driver(ship)`` — until all have returned. A task's exception (or the simulator's, e.g. a
        :class:`~vtrials.errors.SimulationError` of any ship) stops the whole fleet and is raised here."""
        ships = [int(s) for s, _ in tasks]
        if len(set(ships)) != len(ships) or any(not 0 <= s < self.sim.n for s in ships):
            raise ValueError(f"one task per ship of the simulator (0..{self.sim.n - 1}), got ships {ships}")
        self._hub = greenlet.getcurrent()
        self._rows = {s: [] for s in ships}
        try:
            for ship, fn in sorted(tasks, key=lambda x: x[0]):
                self._resume(ship, greenlet(fn))
            while self._waiting:
                target = min(t for t, _ in self._waiting.values())
                if target > self.step_count:
                    self.sim.step(target - self.step_count)
                    self.step_count = target
                    rec = self.sim.truth()
                    self.sim.clear_truth()
                    if rec.shape[0]:
                        for s in self._waiting:
                            self._rows[s].append(rec[:, s, :].copy())
                for s in sorted(s for s, (t, _) in self._waiting.items() if t <= self.step_count):
                    _, g = self._waiting.pop(s)
                    self._resume(s, g)
        finally:
            self._waiting.clear()
            self._hub = None

    def _resume(self, ship: int, g: greenlet) -> None:
        g.switch()
        if g.dead:
            self._rows.pop(ship, None)


__all__ = ["Fleet", "ShipDriver"]
