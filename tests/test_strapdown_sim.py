"""Strapdown reconstruction (Miles 1986, seed 001) from an accelerometer array on the simulator's motion.

* the array instrument (catalogue ``miles_accelerometer_array``) reads e_j · f at each sensor point —
  checked against :class:`SiteKinematics` directly;
* Miles' scheme with FFT integration recovers a periodic record almost exactly (NRE < 0.5 %) and
  degrades on a record that is not periodic (a 0.2013-Hz pitch over 300 s: NRE 12 %): the FFT
  integrations treat the record as periodic; the "mirror" integration (time domain, detrended,
  mirror-extended zero-phase high-pass) keeps such a record under 2 %;
* a short record of patrol51 in a quartering sea (benchmarks/strapdown_sim.py, 200 s): roll of several
  degrees RMS reconstructed within the measured NRE (the mirror integration well under the FFT's), and
  the nonlinear scheme beats Miles' linearised
  analysis (his claim) — by a factor > 1.5 on pitch (measured 1.6–2.2 over seeds 1–4).
Measured figures over longer records: benchmarks/results/strapdown_sim.json.
"""

from __future__ import annotations

import importlib.util
import math
from pathlib import Path

import numpy as np
import pytest

from vtrials.instruments.devices import AccelerometerArray as ArrayDevice
from vtrials.instruments.kinematics import SiteKinematics
from vtrials.instruments.suite import load_catalogue
from vtrials.reduce.strapdown import AccelerometerArray, nre, strapdown_linear, strapdown_motion

ROOT = Path(__file__).resolve().parents[1]


def _bench():
    spec = importlib.util.spec_from_file_location("strapdown_sim", ROOT / "benchmarks" / "strapdown_sim.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _pitching(f0, n=6000, dt=0.05, amp=math.radians(2.0)):
    t = np.arange(n) * dt
    w = 2 * math.pi * f0
    th = amp * np.sin(w * t + 0.7)
    z = np.zeros(n)
    return {"t": t, "qw": np.cos(th / 2), "qx": z, "qy": np.sin(th / 2), "qz": z, "u": np.full(n, 6.0), "v": z,
            "w": z, "p": z, "q": amp * w * np.cos(w * t + 0.7), "r": z, "du": z, "dv": z, "dw": z, "dp": z,
            "dq": -amp * w * w * np.sin(w * t + 0.7), "dr": z, "x": z, "y": z, "z": z}, th


def _ideal_array():
    spec = {k: v for k, v in load_catalogue()["miles_accelerometer_array"].items() if k not in ("noise", "bias", "scale")}
    dev = ArrayDevice("array", spec, "imu", np.array([-3.0, 0.0, 0.5]), {})
    dev.reset(np.random.default_rng(1))
    return dev


def test_array_reads_the_specific_force_along_each_axis():
    cols, _ = _pitching(0.2, n=400)
    dev = _ideal_array()
    y = dev.measurand(SiteKinematics(cols, dev.site), cols)
    for j in range(7):
        f = SiteKinematics(cols, dev.site + dev.offsets[j]).specific_force()
        assert np.allclose(y[:, j], f @ dev.axes[j], atol=1e-12)
    # the vertical sensors read about −g (specific force, z down)
    assert abs(np.mean(y[:, 0]) + 9.80665) < 0.01


@pytest.mark.parametrize("f0, periodic", [(0.2, True), (0.2013, False)])
def test_periodic_and_non_periodic_records(f0, periodic):
    cols, th = _pitching(f0)
    dev = _ideal_array()
    t, ch = dev.process(cols)
    acc = np.column_stack([ch[c] for c in dev.channels])
    m = strapdown_motion(np.linspace(t[0], t[-1], t.size), acc, AccelerometerArray(dev.offsets, dev.axes), 0.04)
    e = nre(m.euler[:, 1], np.interp(t, cols["t"], th))
    if periodic:
        assert e < 0.5
    else:  # 60.39 cycles in the record: the FFT integrations' periodic wrap
        assert e > 3.0


@pytest.mark.parametrize("f0", [0.2, 0.2013, 0.1971, 0.2037])
def test_mirror_integration_on_non_periodic_records(f0):
    """The time-domain integration with a mirror-extended zero-phase high-pass (integration="mirror")
    does not need a whole number of cycles: pitch NRE < 2 % whatever the record length (measured
    1.3–1.9 %; the FFT integration: 0.3 % periodic, 3.9–12.5 % not)."""
    cols, th = _pitching(f0)
    dev = _ideal_array()
    t, ch = dev.process(cols)
    acc = np.column_stack([ch[c] for c in dev.channels])
    m = strapdown_motion(np.linspace(t[0], t[-1], t.size), acc, AccelerometerArray(dev.offsets, dev.axes), 0.04,
                         integration="mirror")
    e = nre(m.euler[:, 1], np.interp(t, cols["t"], th))
    print(f"f0 {f0} Hz: pitch NRE {e:.3f} %")
    assert e < 2.0


def test_strapdown_on_a_short_simulated_record():
    S = _bench()
    # A record where the nonlinear (rotation) terms matter: T_p 5.5 s, the peak on patrol51's roll resonance
    # (1.14 rad/s since its stand-in hull was fitted to BC93's KM and its sway added mass made consistent
    # with the wave excitation), seed 1: 8.5° RMS roll since the maneuvering forces see the waves' flow
    # (9.4° before). Measured: roll NRE 6.0 % (mirror) vs 11.9 % (FFT); pitch NRE 4.9 % vs 9.7 % for the
    # linear strapdown (1.95×; seeds 2–4: 2.2×, 1.8×, 1.6×, and 2.3× on this seed before the flow: the
    # factor is the record's, hence > 1.5 here). The mirror integration's margin over the FFT one depends
    # on the record (it is an end effect): same sea, seeds 2 and 4, 4.6 vs 5.4 % and 5.9 vs 5.8 %.
    # (Before, with the hull's roll excitation 2.4 times too stiff, T_p 7 s seed 3 rolled 10.5°; it now
    # rolls 5.2°.)
    rec = S.simulate_array(3.0, 5.5, 120.0, 10.0, 200.0, seed=1, n_components=60)
    r = S.reconstruct(rec)
    assert r["rms_roll"] > 8.0                       # a large roll: the nonlinear terms matter
    # the mirror integration (default) against the periodic FFT integration on this non-periodic record
    assert r["nre_roll_pct"] < 0.7 * S.reconstruct(rec, integration="fft")["nre_roll_pct"]
    assert r["nre_roll_pct"] < 10.0 and r["nre_pitch_pct"] < 10.0 and r["nre_heave_pct"] < 20.0
    t = rec["t"]
    lin = strapdown_linear(np.linspace(t[0], t[-1], t.size), rec["acc"], AccelerometerArray(rec["offsets"], rec["axes"]), 0.04)
    assert nre(lin[:, 1], rec["truth"]["pitch"]) > 1.5 * r["nre_pitch_pct"]
    assert nre(lin[:, 0], rec["truth"]["roll"]) > r["nre_roll_pct"]
