"""Instruments: lever arms, the knotmeter, range–range geometry, LORAN, seeds and streams."""

from __future__ import annotations

import math

import numpy as np
import pytest

from vtrials.physics import steering as H
from vtrials.instruments.devices import EMLog, Knotmeter, Loran, RangeRadar
from vtrials.instruments.suite import InstrumentSet, load_catalogue
from vtrials.physics.simulator import ShipState, Simulator
from vtrials.truth.columns import ship_columns
from vtrials.units import DEG, KNOT
from vtrials.physics.vessel import load_vessel

SITE = {"transponders": [[-10000.0, -6000.0], [-10000.0, 6000.0]], "transponder_side": -1.0,
        "hydrophones": [[-600.0, -800.0], [-600.0, 800.0]], "hydrophone_side": -1.0, "water_depth_m": 200.0}
IDEAL_IMU = {"accel_bias_ug": 0.0, "accel_gauss_markov_ug": {"sd": 0.0, "tau_s": 100.0}, "accel_noise_mps2": 0.0,
             "accel_scale": {"mean": 0.0, "sd": 0.0}, "gyro_bias_dph": 0.0,
             "gyro_gauss_markov_dph": {"sd": 0.0, "tau_s": 100.0}, "gyro_noise_dps": 0.0,
             "gyro_scale": {"mean": 0.0, "sd": 0.0}, "misalignment_deg": 0.0, "rate_hz": 20.0,
             "accel_random_walk_ug_rth": 0.0, "gyro_random_walk_dph_rth": 0.0}


def _columns(sim):
    return ship_columns(sim.truth(), sim.rec_names, 0, sim.dt)


def _run_instruments(vessel, items, cols, seed=5):
    iset = InstrumentSet(vessel, seed, SITE, items, "test")
    iset.reset()
    for a in range(0, len(cols["t"]), 777):  # odd chunking on purpose
        iset.process({k: v[a:a + 777] for k, v in cols.items()})
    return iset


def test_accelerometer_lever_arm_in_a_steady_turn():
    """Planar steady turn: an ideal accelerometer at site S reads a_x = −r v − r² x_S,
    a_y = r u − r² y_S (centripetal term of the lever arm), a_z = −g."""
    v = load_vessel("kvlcc2_l7")
    sim = Simulator(v, 1, 0.01, planar=True)
    sim.self_propulsion(0, 1.1765)
    sim.set_helm(0, [(H.HOLD, 35 * DEG)])
    sim.step(20000)
    cols = _columns(sim)
    items = [{"name": "imu_fwd", "spec": "imu_tactical", "site": "speed_log", "set": IDEAL_IMU},
             {"name": "imu_aft", "spec": "imu_tactical", "site": "gnss_antenna", "set": IDEAL_IMU}]
    iset = _run_instruments(v, items, cols)
    steady = cols["t"] > 150.0
    r = cols["r"][steady].mean()
    u = cols["u"][steady].mean()
    vv = cols["v"][steady].mean()
    assert abs(np.degrees(r)) > 2.0
    for name, site in (("imu_fwd", "speed_log"), ("imu_aft", "gnss_antenna")):
        x, y, _ = v.sites[site]
        t, ch = iset.readings(name)
        m = t > 150.0
        assert ch["ax"][m].mean() == pytest.approx(-r * vv - r * r * x, abs=2e-4)
        assert ch["ay"][m].mean() == pytest.approx(r * u - r * r * y, abs=2e-4)
        assert ch["az"][m].mean() == pytest.approx(-9.80665, abs=1e-6)
        assert ch["r"][m].mean() == pytest.approx(r, rel=1e-3)
    # the two sites differ by exactly the centripetal term of their separation
    tf, cf = iset.readings("imu_fwd")
    ta, ca = iset.readings("imu_aft")
    dx = v.sites["speed_log"][0] - v.sites["gnss_antenna"][0]
    diff = cf["ax"][tf > 150].mean() - ca["ax"][ta > 150].mean()
    assert diff == pytest.approx(-r * r * dx, rel=0.02)


def test_anemometer_reads_the_motion_of_a_rolling_mast():
    """Calm air, ship at rest and rolling: the mast-top anemometer sees the air coming at it at the
    speed of the mast's own motion, v = ω × r (here mostly −p z for a mast z < 0)."""
    v = load_vessel("patrol51")
    sim = Simulator(v, 1, 0.02)
    sim.set_state(0, ShipState(roll=math.radians(8.0), shaft_rps=(0.0, 0.0)))
    sim.set_helm(0, [(H.HOLD, 0.0)])
    sim.step(1500)
    cols = _columns(sim)
    ideal = {"distance_constant_m": 0.0, "start_threshold_mps": 0.0, "speed_bias_kn": 0.0,
             "speed_resolution_kn": 0.0, "direction_alignment_deg": 0.0, "direction_noise_deg": 0.0,
             "direction_resolution_deg": 0.0, "airwake_speed": [0.0], "airwake_direction_deg": [0.0],
             "rate_hz": 20.0}
    iset = _run_instruments(v, [{"name": "mast", "spec": "cup_vane_anemometer", "site": "anemometer",
                                 "clock": "none", "set": ideal}], cols)  # stamps in true time
    t, ch = iset.readings("mast")
    rs = v.sites["anemometer"]
    om = np.column_stack([cols["p"], cols["q"], cols["r"]])
    vel = np.column_stack([cols["u"], cols["v"], cols["w"]]) + np.cross(om, rs)
    # horizontal velocity of the mast top in the ship's level frame, from its own positions (central
    # differences of p_O + R r_S at the rows' instants: independent of the truth's velocity columns)
    from vtrials.instruments.kinematics import rotation_matrices
    R = rotation_matrices(cols["qw"], cols["qx"], cols["qy"], cols["qz"])
    top = np.column_stack([cols["x"], cols["y"], cols["z"]]) + R @ rs
    vn, ve = np.gradient(top[:, 0], cols["t"]), np.gradient(top[:, 1], cols["t"])
    psi = cols["heading"]
    vx, vy = np.cos(psi) * vn + np.sin(psi) * ve, -np.sin(psi) * vn + np.cos(psi) * ve
    pred = np.interp(t, cols["t"], np.hypot(vx, vy))
    assert pred.max() > 0.5  # a real motion: several knots at the mast top
    np.testing.assert_allclose(ch["speed"], pred, atol=2e-3 * pred.max() + 1e-3)
    # most of it is the lever-arm term ω × r_S (the hull itself only sways a little as it rolls)
    lever = np.cross(om, rs)
    share = np.hypot(lever[:, 0], lever[:, 1]).max() / np.hypot(vel[:, 0], vel[:, 1]).max()
    assert share > 0.9


def _knot_cols(speeds, T=600.0, dt=0.05, roll_amp=0.0, roll_period=8.0):
    """Synthetic truth: straight run at piecewise-constant speed through the water, optional rolling."""
    t = np.arange(0.0, T * len(speeds), dt)
    u = np.repeat(speeds, int(round(T / dt)))[: t.size]
    n = t.size
    z = np.zeros(n)
    w = 2 * math.pi / roll_period
    roll = roll_amp * np.sin(w * t)
    p = roll_amp * w * np.cos(w * t)
    cols = {"t": t, "u": u, "v": z, "w": z, "u_r": u, "v_r": z, "w_r": z, "p": p, "q": z, "r": z, "x": np.cumsum(u) * dt,
            "y": z, "z": z, "qw": np.cos(roll / 2), "qx": np.sin(roll / 2), "qy": z, "qz": z, "roll": roll,
            "pitch": z, "heading": z}
    return cols


def _knotmeter(over=None):
    spec = dict(load_catalogue()["kenyon_knotmeter"])
    spec.update(over or {})
    k = Knotmeter("k", spec, "knotmeter", np.array([10.0, -0.8, 2.1]), {})
    k.reset(np.random.default_rng(3))
    return k


def test_em_log_true_calibration_is_the_line_its_readings_follow():
    """The EM log's true calibration (its drawn scale and bias and its axis misalignment, upright straight
    flow): the mean reading over each 10-min leg, mapped through the line, gives the leg's speed through
    the water to within what the log's noise and 300-s Gauss–Markov wander leave on a leg mean."""
    spec = dict(load_catalogue()["em_log"])
    e = EMLog("em", spec, "speed_log", np.array([10.0, 0.0, 2.0]), {})
    e.reset(np.random.default_rng(11))
    a, b = e.true_calibration()
    s = next(p.value for p in e.chain.parts if type(p).__name__ == "ScaleFactor")
    assert b == pytest.approx(1.0 / (1.0 + float(s)), rel=1e-3) and abs(a) > 0.0
    speeds = np.array([4.0, 8.0, 12.0, 16.0]) * KNOT
    cols = _knot_cols(speeds)
    t, ch = e.process(cols)
    raw = []
    for V in speeds:
        seg = np.interp(t, cols["t"], cols["u"]) == V
        stw = a + b * ch["speed"][seg].mean()
        assert stw == pytest.approx(V, abs=0.03), (V, stw)
        raw.append(ch["speed"][seg].mean() - V)
    # this draw's bias and scale put the raw readings off by more than that (the line does the work)
    assert max(abs(x) for x in raw) > 0.06, raw


def test_knotmeter_breakaway_counts_and_calibration():
    k = _knotmeter({"breakaway_kn": {"lo": 4.0, "hi": 4.0}})
    speeds = np.array([3.0, 8.0, 15.0, 25.0]) * KNOT
    cols = _knot_cols(speeds)
    t, ch = k.process(cols)
    a, b = k.true_calibration()
    for V in speeds:
        seg = (np.interp(t - 10.0, cols["t"], cols["u"]) == V) & (np.interp(t, cols["t"], cols["u"]) == V)
        counts = ch["counts"][seg]
        assert counts.size > 20
        if V < 4 * KNOT:
            assert np.all(counts == 0)  # below break-away the impeller does not turn
            continue
        expected = (V - a) / b / k.k_nom * k.window  # counts per window from the true calibration
        # integer counts, each within one count of the expected (quantization ±1), unbiased on average
        assert np.all(np.abs(counts - expected) <= 1.0 + 1e-9)
        assert np.all(counts == np.round(counts))
        assert counts.mean() == pytest.approx(expected, abs=0.25)
        assert ch["speed"][seg].mean() == pytest.approx(expected * k.k_nom / k.window, abs=0.25 * k.k_nom / k.window)
    # count noise: the ±1 jitter gives a displayed-speed scatter of about one count (0.03 kn per 10-s window)
    step = k.k_nom / k.window
    assert step == pytest.approx(0.03 * KNOT, rel=1e-9)


def test_knotmeter_under_reads_when_rolling_at_low_speed():
    k1 = _knotmeter({"breakaway_kn": {"lo": 1.0, "hi": 1.0}})
    k2 = _knotmeter({"breakaway_kn": {"lo": 1.0, "hi": 1.0}})
    V = np.array([5.0]) * KNOT
    calm = _knot_cols(V, T=1200.0)
    rolling = _knot_cols(V, T=1200.0, roll_amp=math.radians(15.0), roll_period=6.0)
    _, c1 = k1.process(calm)
    _, c2 = k2.process(rolling)
    loss = 1 - c2["speed"].mean() / c1["speed"].mean()
    # cross-flow at the sensor: p·z_S with roll rate amplitude 2π/6·15°, sensor 2.1 m below the roll axis
    # (plus y_S·p); the stall response 1/(1 + (θ/θ_s)⁴) predicts the loss
    p = math.radians(15.0) * 2 * math.pi / 6.0 * np.cos(np.linspace(0, 2 * math.pi, 2001))
    cross = np.abs(p) * math.hypot(2.1, 0.8)
    theta = np.arctan2(cross, (1 - k2.d) * V[0])
    pred = 1 - np.mean(1.0 / (1.0 + (theta / k2.stall) ** 4))
    assert loss > 0.02
    assert loss == pytest.approx(pred, rel=0.25)


def _static_cols(north, east, T=2000.0, dt=1.0):
    t = np.arange(0.0, T, dt)
    z = np.zeros(t.size)
    o = np.ones(t.size)
    return {"t": t, "x": north * o, "y": east * o, "z": z, "qw": o, "qx": z, "qy": z, "qz": z,
            "u": z, "v": z, "w": z, "p": z, "q": z, "r": z, "heading": z}


@pytest.mark.parametrize("north,east", [(0.0, 0.0), (-6000.0, 0.0), (8000.0, 0.0), (-9000.0, 0.0), (20000.0, 3000.0)])
def test_range_range_error_follows_geometry(north, east):
    spec = dict(load_catalogue()["falcon_radar"])
    spec.pop("clock_offset_s")
    dev = RangeRadar("falcon", spec, "mast", np.zeros(3), {"site": SITE})
    dev.reset(np.random.default_rng(11))
    t, ch = dev.process(_static_cols(north, east, T=20000.0))
    err = np.column_stack([ch["north"] - north, ch["east"] - east])
    a, b = np.array(SITE["transponders"][0]), np.array(SITE["transponders"][1])
    ua = (np.array([north, east]) - a) / np.linalg.norm([north, east] - a)
    ub = (np.array([north, east]) - b) / np.linalg.norm([north, east] - b)
    J = np.vstack([ua, ub])
    cov_pred = 2.7 ** 2 * np.linalg.inv(J.T @ J)  # σ_r² (JᵀJ)⁻¹; trace = 2σ_r²/sin²γ
    gamma = math.acos(np.clip(ua @ ub, -1, 1))
    assert np.trace(cov_pred) == pytest.approx(2 * 2.7 ** 2 / math.sin(gamma) ** 2, rel=1e-9)
    cov = np.cov(err.T)
    n = err.shape[0]
    assert np.trace(cov) == pytest.approx(np.trace(cov_pred), rel=6 * math.sqrt(2 / n) + 0.02)
    assert np.mean(ch["crossing_angle"]) == pytest.approx(gamma, abs=1e-3)


def test_loran_updates_and_average_between_fixes():
    spec = dict(load_catalogue()["loran_c"])
    dev = Loran("loran", spec, "antenna", np.zeros(3), {})
    dev.reset(np.random.default_rng(2))
    T = 8 * 3600.0
    t = np.arange(0.0, T, 0.5)
    z = np.zeros(t.size)
    o = np.ones(t.size)
    U = 5.0
    cols = {"t": t, "x": U * t, "y": z, "z": z, "qw": o, "qx": z, "qy": z, "qz": z, "u": U * o, "v": z, "w": z,
            "p": z, "q": z, "r": z}
    tt = []
    out = {k: [] for k in ("north", "east", "sog", "cog")}
    for a in range(0, t.size, 3001):
        ti, ch = dev.process({k: v[a:a + 3001] for k, v in cols.items()})
        tt.append(ti)
        for k in out:
            out[k].append(ch[k])
    tt = np.concatenate(tt)
    out = {k: np.concatenate(v) for k, v in out.items()}
    dt = np.diff(tt)
    assert dt.min() >= 15.0 - 1e-9 and dt.max() <= 60.0 + 1e-9
    assert np.mean(dt) == pytest.approx(37.5, rel=0.03)
    # the display is the average between the last two fixes, exactly
    sog_fix = np.hypot(np.diff(out["north"]), np.diff(out["east"])) / dt
    np.testing.assert_allclose(out["sog"][1:], sog_fix, rtol=1e-12)
    # and its error is of the seed's ±0.25 kn order: the fixes' white scatter over 15-60 s intervals
    err = out["sog"][1:] - U
    assert abs(err.mean()) < 0.05 * KNOT * 3
    assert 0.03 * KNOT < err.std() < 0.3 * KNOT


def test_instrument_streams_are_seeded_and_independent():
    v = load_vessel("kvlcc2")
    sim = Simulator(v, 1, 0.05)
    sim.self_propulsion(0, 7.9)
    sim.set_helm(0, [(H.HOLD, 0.0)])
    sim.step(6000)
    cols = _columns(sim)
    twin = [{"name": "gyro_a", "spec": "gyrocompass", "site": "gyro"},
            {"name": "gyro_b", "spec": "gyrocompass", "site": "gyro"}]
    s1 = _run_instruments(v, twin, cols, seed=9)
    s2 = _run_instruments(v, twin, cols, seed=9)
    s3 = _run_instruments(v, twin + [{"name": "extra", "spec": "dgps", "site": "gnss_antenna"}], cols, seed=9)
    s4 = _run_instruments(v, twin, cols, seed=10)
    a1 = s1.readings("gyro_a")[1]["heading"]
    assert np.array_equal(a1, s2.readings("gyro_a")[1]["heading"])   # same seed: identical
    assert np.array_equal(a1, s3.readings("gyro_a")[1]["heading"])   # another instrument changes nothing
    assert not np.array_equal(a1, s4.readings("gyro_a")[1]["heading"])
    b1 = s1.readings("gyro_b")[1]["heading"]
    n = min(a1.size, b1.size)
    ea = np.angle(np.exp(1j * (a1[:n] - np.median(a1))))
    eb = np.angle(np.exp(1j * (b1[:n] - np.median(b1))))
    assert abs(np.corrcoef(np.diff(ea), np.diff(eb))[0, 1]) < 0.1  # independent noise
    assert s1.drawn()["gyro_a"] != s1.drawn()["gyro_b"]
