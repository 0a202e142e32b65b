"""Issue 13 item 1 (ship half): the bow relative-motion meter against an independent computation of the
sea surface at the moving, pitching bow, and the motion package's mounting (lever arm) and timing
(latency) errors against the analytic specific force of a steady turn."""

from __future__ import annotations

import math

import numpy as np
import pytest

from vtrials.instruments.devices import IMU
from vtrials.instruments.suite import load_catalogue
from vtrials.instruments.wave_sensors import RelativeMotion
from vtrials.physics.environment.waves import Waves, elevation, realize
from vtrials.units import G


def _spec(name, **over):
    s = dict(load_catalogue()[name])
    s.update(over)
    return s


def _pitching_ship(t, U=6.0, Z=0.8, theta=math.radians(3.0), w=0.7, phase=0.6):
    """Truth columns of a ship going north at U, heaving Z sin ωt (z down) and pitching θ sin(ωt + φ)."""
    z0 = np.zeros(t.size)
    th = theta * np.sin(w * t + phase)
    return {"t": t, "x": U * t, "y": z0, "z": Z * np.sin(w * t), "qw": np.cos(th / 2), "qx": z0,
            "qy": np.sin(th / 2), "qz": z0, "u": np.full(t.size, U), "v": z0, "w": z0, "p": z0, "q": z0,
            "r": z0}, th


def test_relative_motion_is_the_sea_at_the_bow_minus_its_height():
    field = realize(Waves(hs_m=2.0, tp_s=8.0, direction_deg=0.0), math.inf, np.random.default_rng(4))
    bow = np.array([40.0, 1.5, -5.0])  # forward, starboard, 5 m above the waterline (z down)
    d = RelativeMotion("tsk", _spec("tsk_relative_motion", noise=0.0, resolution=0.0, scale={"mean": 0.0, "sd": 0.0},
                                    latency_s=0.0), "bow", bow, {})
    d.attach_sea(field)
    d.reset(np.random.default_rng(1))
    t = np.arange(0.0, 120.0, 0.02)
    cols, th = _pitching_ship(t)
    ts, ch = d.process(cols)
    # independent: rotate the bow by the pitch angle about the y axis, add the ship's position
    xw = cols["x"] + np.cos(th) * bow[0] + np.sin(th) * bow[2]
    yw = bow[1] + 0.0 * t
    zw = cols["z"] - np.sin(th) * bow[0] + np.cos(th) * bow[2]
    r = elevation(field.components, xw, yw, t) + zw
    assert ts.size > 2000
    np.testing.assert_allclose(ch["relative_motion"], np.interp(ts, t, r), atol=1e-9)
    # the ship's own motion matters: with it frozen, the meter would read something else
    assert np.std(r - (elevation(field.components, xw, yw, t) + bow[2])) > 0.5


def test_relative_motion_latency_and_scale():
    field = realize(Waves(hs_m=1.0, tp_s=6.0), math.inf, np.random.default_rng(2))
    base = dict(noise=0.0, resolution=0.0)
    d0 = RelativeMotion("a", _spec("tsk_relative_motion", latency_s=0.0, scale={"mean": 0.0, "sd": 0.0}, **base),
                        "bow", np.array([40.0, 0.0, -5.0]), {})
    d1 = RelativeMotion("a", _spec("tsk_relative_motion", latency_s=0.05, scale={"mean": 0.0, "sd": 0.0}, **base),
                        "bow", np.array([40.0, 0.0, -5.0]), {})
    for d in (d0, d1):
        d.attach_sea(field)
        d.reset(np.random.default_rng(3))
    cols, _ = _pitching_ship(np.arange(0.0, 30.0, 0.02))
    t0, c0 = d0.process(cols)
    t1, c1 = d1.process(cols)
    np.testing.assert_allclose(t1 - t0, 0.05, atol=1e-12)
    np.testing.assert_array_equal(c1["relative_motion"], c0["relative_motion"])


def _turn(t, r=0.05):
    z = np.zeros(t.size)
    psi = r * t
    return {"t": t, "x": z, "y": z, "z": z, "qw": np.cos(psi / 2), "qx": z, "qy": z, "qz": np.sin(psi / 2),
            "u": z, "v": z, "w": z, "p": z, "q": z, "r": np.full(t.size, r), "du": z, "dv": z, "dw": z, "dp": z,
            "dq": z, "dr": z}


IDEAL_IMU = dict(accel_bias_ug={"mean": 0.0, "sd": 0.0}, accel_gauss_markov_ug={"sd": 0.0, "tau_s": 100.0},
                 accel_noise_mps2=0.0, accel_scale={"mean": 0.0, "sd": 0.0}, accel_random_walk_ug_rth=0.0,
                 misalignment_deg=0.0)


def test_motion_package_lever_arm_error_is_a_centripetal_term():
    """Turning on the spot at r: the accelerometers read −r² × (actual position) in x, y and −g in z; the actual
    position is the surveyed site plus the drawn lever-arm error. Everything else the package draws is as
    it would be without the mounting error (the lever arm draws from a child stream of its own)."""
    site = np.array([-3.0, 0.5, 0.5])
    r = 0.05
    cols = _turn(np.arange(0.0, 20.0, 0.01), r)
    a = IMU("imu", _spec("ship_motion_package", **IDEAL_IMU, latency_s=0.0), "imu", site, {})
    a.reset(np.random.default_rng(11))
    ta, ca = a.process(cols)
    d = np.array(a.drawn()["lever_arm_error_m"])
    assert np.linalg.norm(d) > 0.0
    np.testing.assert_allclose(ca["ax"], -r * r * (site[0] + d[0]), atol=1e-12)
    np.testing.assert_allclose(ca["ay"], -r * r * (site[1] + d[1]), atol=1e-12)
    np.testing.assert_allclose(ca["az"], -G, atol=1e-12)
    # the same package without the mounting error: identical gyro draws, accelerometers off by r² d only
    b = IMU("imu", _spec("ship_motion_package", latency_s=0.0, lever_arm_sd_m=0.0), "imu", site, {})
    c = IMU("imu", _spec("ship_motion_package", latency_s=0.0), "imu", site, {})
    b.reset(np.random.default_rng(5))
    c.reset(np.random.default_rng(5))
    tb, cb = b.process(cols)
    tc, cc = c.process(cols)
    dc = np.array(c.drawn()["lever_arm_error_m"])
    np.testing.assert_array_equal(tb, tc)
    np.testing.assert_array_equal(cb["r"], cc["r"])
    # the misalignment mixes the lever-arm term into the other axes by at most ~0.1° (1.7e-3 of it)
    np.testing.assert_allclose(cc["ax"] - cb["ax"], -r * r * dc[0], atol=2e-3 * r * r * np.linalg.norm(dc) + 1e-12)


def test_motion_package_latency_shifts_the_stamps():
    cols = _turn(np.arange(0.0, 5.0, 0.01))
    x = IMU("imu", _spec("ship_motion_package"), "imu", np.zeros(3), {})
    y = IMU("imu", _spec("ship_motion_package", latency_s=0.0), "imu", np.zeros(3), {})
    x.reset(np.random.default_rng(9))
    y.reset(np.random.default_rng(9))
    tx, cx = x.process(cols)
    ty, cy = y.process(cols)
    np.testing.assert_allclose(tx - ty, 0.02, atol=1e-12)
    np.testing.assert_array_equal(cx["p"], cy["p"])
    assert x.meta()["latency_s"] == pytest.approx(0.02)


def test_tactical_imu_unchanged_without_the_new_keys():
    """imu_tactical (the shipped suites') has neither key: no extra draw, no stamp shift, meta as before."""
    m = IMU("imu", _spec("imu_tactical"), "imu", np.zeros(3), {})
    m.reset(np.random.default_rng(1))
    assert "lever_arm_error_m" not in m.drawn() and "lever_arm_survey_sd_m" not in m.meta()
    assert "latency_s" not in m.meta()


def test_every_sea_sensor_entry_names_its_source_and_builds():
    from vtrials.instruments.wave_sensors import WAVE_KINDS
    cat = load_catalogue()
    names = [k for k, v in cat.items() if isinstance(v, dict) and v.get("kind") in WAVE_KINDS]
    assert len(names) >= 6
    for n in names:
        spec = dict(cat[n])
        assert len(spec.get("source", "")) > 40, n
        d = WAVE_KINDS[spec["kind"]](n, spec, "sea", np.array([10.0, 0.0, -2.0]), {"site": {}})
        d.attach_sea(None)
        d.reset(np.random.default_rng(0))
        assert d.meta()["kind"] == spec["kind"]
