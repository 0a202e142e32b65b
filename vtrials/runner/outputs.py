"""What every run writes the same way: JSON without NaN or numpy scalars."""

from __future__ import annotations

import math

import numpy as np


def json_clean(x):
    """x with non-finite floats as None and numpy scalars as Python numbers (JSON-ready)."""
    if isinstance(x, float):
        return x if math.isfinite(x) else None
    if isinstance(x, dict):
        return {k: json_clean(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [json_clean(v) for v in x]
    if isinstance(x, np.generic):
        return json_clean(x.item())
    return x
