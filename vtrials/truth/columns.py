"""The truth record: names, units and meaning of every column the dynamics kernel writes.

The truth is the full simulated state at simulation rate. It is written to its own file and is
never read by reductions; scoring computes references from it by their own definitions.
"""

from __future__ import annotations

import re

import numpy as np

_FIXED = {
    "t": ("s", "simulated time"),
    "x": ("m", "north position of the hull origin (midship, waterline)"),
    "y": ("m", "east position of the hull origin"),
    "z": ("m", "downward displacement of the hull origin from the calm waterline"),
    "qw": ("1", "attitude quaternion w (body to north-east-down)"),
    "qx": ("1", "attitude quaternion x"),
    "qy": ("1", "attitude quaternion y"),
    "qz": ("1", "attitude quaternion z"),
    "roll": ("rad", "roll angle, positive starboard down"),
    "pitch": ("rad", "pitch angle, positive bow up"),
    "heading": ("rad", "heading from north, clockwise, unwrapped"),
    "u": ("m s-1", "surge velocity over ground, body axes"),
    "v": ("m s-1", "sway velocity over ground at the origin, body axes (+ starboard)"),
    "w": ("m s-1", "heave velocity over ground, body axes (+ down)"),
    "p": ("rad s-1", "roll rate"),
    "q": ("rad s-1", "pitch rate"),
    "r": ("rad s-1", "yaw rate (+ turning to starboard)"),
    "u_r": ("m s-1", "surge velocity through the water"),
    "v_r": ("m s-1", "sway velocity through the water at the origin"),
    "w_r": ("m s-1", "heave velocity through the water"),
    "du": ("m s-2", "body-frame time derivative of u"),
    "dv": ("m s-2", "body-frame time derivative of v"),
    "dw": ("m s-2", "body-frame time derivative of w"),
    "dp": ("rad s-2", "roll acceleration"),
    "dq": ("rad s-2", "pitch acceleration"),
    "dr": ("rad s-2", "yaw acceleration"),
    "current_n": ("m s-1", "current at the ship, north component"),
    "current_e": ("m s-1", "current at the ship, east component"),
    "drift_n": ("m", "integrated current (north): position minus this is the track through the water"),
    "drift_e": ("m", "integrated current (east)"),
    "wind_apparent_speed": ("m s-1", "apparent (relative) wind speed at the ship's wind-load reference height"),
    "wind_apparent_angle": ("rad", "angle the apparent wind comes from, off the bow, + to starboard"),
    "wind_speed": ("m s-1", "true wind speed at the reference height, gusts included"),
    "wind_direction": ("rad", "direction the true wind blows from (north = 0, clockwise)"),
}
_PATTERNS = [
    (r"rudder_order_(\d+)", ("rad", "rudder order of rudder {0} (+ starboard turn)")),
    (r"rudder_normal_force_(\d+)", ("N", "rudder normal force F_N of rudder {0}")),
    (r"rudder_(\d+)", ("rad", "rudder angle of rudder {0} (+ trailing edge to starboard)")),
    (r"shaft_order_(\d+)", ("s-1", "shaft speed order of shaft {0} (rev/s)")),
    (r"shaft_n_(\d+)", ("s-1", "shaft speed of shaft {0} (rev/s, + ahead)")),
    (r"engine_torque_(\d+)", ("N m", "machinery torque on shaft {0} (engine; brake torque when locked)")),
    (r"pitch_order_(\d+)", ("1", "pitch ratio order of propeller {0}")),
    (r"pitch_(\d+)", ("1", "pitch ratio P/D of propeller {0} at 0.7R")),
    (r"thrust_(\d+)", ("N", "thrust of propeller {0}")),
    (r"prop_torque_(\d+)", ("N m", "hydrodynamic torque of propeller {0}")),
    (r"advance_ratio_(\d+)", ("1", "advance ratio J of propeller {0}")),
    (r"F_(.+)_([XYZ])", ("N", "force of component {0} along body {1}")),
    (r"F_(.+)_([KMN])", ("N m", "moment of component {0} about the body axis ({1}) at the origin")),
]


def describe(name: str) -> tuple[str, str]:
    """(units, long_name) of a truth column."""
    if name in _FIXED:
        return _FIXED[name]
    for pat, (units, text) in _PATTERNS:
        m = re.fullmatch(pat, name)
        if m:
            return units, text.format(*m.groups())
    raise KeyError(name)


def row_columns(rows: np.ndarray, names: list[str], step_s: float) -> dict[str, np.ndarray]:
    """One ship's truth rows (K, width) as a dict of columns, plus the track through the water (x_w,
    y_w) and the integrator step ``step_s`` [s] of every row: the rows' velocities are those of the step
    just taken, half a step before the row's instant, and the instruments carry them forward
    (:mod:`vtrials.instruments.kinematics`)."""
    cols = {n: rows[:, j] for j, n in enumerate(names)}
    cols["x_w"] = cols["x"] - cols["drift_n"]
    cols["y_w"] = cols["y"] - cols["drift_e"]
    cols["step_s"] = np.full(rows.shape[0], float(step_s))
    return cols


def ship_columns(rec: np.ndarray, names: list[str], ship: int, step_s: float) -> dict[str, np.ndarray]:
    """Ship ``ship``'s truth from a batch record (K, ships, width): :func:`row_columns`."""
    return row_columns(rec[:, ship, :], names, step_s)
