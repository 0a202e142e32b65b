"""A reduced value with its uncertainty."""

from __future__ import annotations

import dataclasses
import math

from scipy import stats


@dataclasses.dataclass(frozen=True)
class Estimate:
    """value ± standard uncertainty, with degrees of freedom for the coverage interval.

    ``dof`` None means a normal (large-sample) interval. ``interval(0.95)`` gives the two-sided
    interval; ``covers(x)`` whether it contains x.
    """

    value: float
    std: float
    dof: float | None = None

    def interval(self, level: float = 0.95) -> tuple[float, float]:
        if not math.isfinite(self.std):
            return (-math.inf, math.inf)
        q = stats.norm.ppf(0.5 + level / 2) if self.dof is None or self.dof <= 0 else \
            stats.t.ppf(0.5 + level / 2, self.dof)
        return (self.value - q * self.std, self.value + q * self.std)

    def covers(self, x: float, level: float = 0.95) -> bool:
        lo, hi = self.interval(level)
        return lo <= x <= hi

    def to_dict(self, level: float = 0.95) -> dict:
        lo, hi = self.interval(level)
        return {"value": self.value, "std": self.std, "dof": self.dof, "lo95": lo, "hi95": hi}
