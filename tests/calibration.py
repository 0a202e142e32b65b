"""The shaft meters' drawn calibration errors of a trial, read from its truth file, as the relative error
they put into the measured power 2π Σ n Q. Scoring-side only (tests): no analysis can remove a
torsionmeter's scale error, the zero offset left after zero setting or a counter's bias — the
reduction's stated interval carries them (seed 002 Table 2 accuracies) — so the tests of a reduction's
fidelity take them out, and check separately that the full error is inside the stated interval."""

from __future__ import annotations

import json

import h5py


def _part(chain: dict, name: str) -> dict:
    return next(p for p in chain["parts"] if p["part"] == name)


def drawn_meter_errors(truth_path) -> dict:
    """{shaft suffix: (scale s, zero residual z [N m], counter bias b [rev/s])} for every torsionmeter
    'torque*' paired with its counter 'rpm*' (same suffix)."""
    with h5py.File(truth_path) as f:
        drawn = json.loads(f["agenda"].attrs["instrument_errors"])
    out = {}
    for name, d in drawn.items():
        if not (name.startswith("torque") and "zero_reading_N_m" in d):
            continue
        suffix = name[len("torque"):]
        s = _part(d["chain"], "ScaleFactor")["scale_factor_error"]
        z = _part(d["chain"], "Bias")["bias"] - d["zero_reading_N_m"]
        b = _part(drawn["rpm" + suffix]["chain"], "Bias")["bias"]
        out[suffix] = (s, z, b)
    return out


def calibration_power_error(meters: dict, torque_total: float, rps: float) -> float:
    """Relative error of the measured 2π Σ n Q at total torque ``torque_total`` [N m] shared equally by
    the shafts turning at ``rps`` [rev/s]: Σ (1 + s + z/Q)(1 + b/n) / N − 1."""
    q = torque_total / len(meters)
    return sum((1.0 + s + z / q) * (1.0 + b / rps) for s, z, b in meters.values()) / len(meters) - 1.0


def net_of_calibration(error: float, meters: dict, torque_total: float, rps: float) -> float:
    """A relative power error with the meters' calibration taken out."""
    return (1.0 + error) / (1.0 + calibration_power_error(meters, torque_total, rps)) - 1.0
