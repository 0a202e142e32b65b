"""Gymnasium environments: API conformance, reproducibility, the native vector env against the scalar
env, the physics against a directly driven Simulator, the vectorised observation model against the
InstrumentSet, and the autopilot baselines."""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import vtrials.envs.registration as REG
from vtrials.envs.baselines import PIDPolicy, run_episode
from vtrials.envs.core import ShipBatch
from vtrials.envs.observe import CHANNELS, ObservationModel, default_site, suite_parts
from vtrials.envs.ship_env import ShipEnv
from vtrials.envs.tasks import wrap
from vtrials.envs.vector import ShipVectorEnv
from vtrials.errors import InputError


@pytest.mark.parametrize("env_id", REG.env_ids())
def test_check_env_passes(env_id):
    env = gym.make(env_id, sea="wind_current")
    check_env(env.unwrapped, skip_render_check=True)
    env.close()


@pytest.mark.parametrize("kw", [dict(discrete=True), dict(engine_action=True, stack=3),
                                dict(task="Stopping", discrete=True),
                                dict(task_options={"heading_integral": True}, stack=2)])
def test_check_env_variants(kw):
    check_env(ShipEnv(**{"sea": "current", **kw}), skip_render_check=True)


def test_course_keeping_heading_integral_observation():
    """Option heading_integral: one more feature, the integral of the measured (gyro) heading error,
    clipped at ±5°, over 10° L/U₀, recomputed here from the measured headings in ``info``; the other
    features and the episode are those of the default environment (the option draws nothing)."""
    opts = {"heading_integral": True, "course_change_deg": 3.0}
    env_i = ShipEnv("CourseKeeping", "patrol51", sea="wind_current", task_options=opts)
    env_d = ShipEnv("CourseKeeping", "patrol51", sea="wind_current", task_options={"course_change_deg": 3.0})
    assert env_i.observation_space.shape == (env_d.observation_space.shape[0] + 1,)
    a = np.array([0.15], dtype=np.float32)
    oi, ri, _ = _episode(env_i, 5, 40, a)
    od, rd, _ = _episode(env_d, 5, 40, a)
    assert np.array_equal(oi[:, :-1], od) and np.array_equal(ri, rd)
    core = env_i.core
    ref, T, dt = core.task.ref[0], core.task.T[0], core.period
    obs, info = env_i.reset(seed=5)
    assert obs[-1] == 0.0
    z, errs = 0.0, []
    for _ in range(40):
        obs, *_, info = env_i.step(a)
        e = float(wrap(info["measured"]["heading"] - ref))
        errs.append(e)
        z += min(max(e, -5 * math.pi / 180), 5 * math.pi / 180) * dt
        assert obs[-1] == pytest.approx(z / (10 * math.pi / 180 * T), rel=1e-5, abs=1e-7)
    errs = np.abs(errs)
    assert errs.min() < 5 * math.pi / 180 < errs.max()  # both the linear and the clipped part exercised


def _episode(env, seed, n, action):
    obs, info = env.reset(seed=seed)
    out = [obs]
    rew = []
    for _ in range(n):
        obs, r, term, trunc, info = env.step(action)
        out.append(obs)
        rew.append(r)
    return np.array(out), np.array(rew), info


def test_same_seed_same_episode_and_domain_draws_differ():
    env = ShipEnv("CourseKeeping", "patrol51", sea="wind_current")
    a = np.array([0.3], dtype=np.float32)
    o1, r1, i1 = _episode(env, 11, 40, a)
    o2, r2, i2 = _episode(env, 11, 40, a)
    o3, r3, i3 = _episode(env, 12, 40, a)
    assert np.array_equal(o1, o2) and np.array_equal(r1, r2)
    assert i1["drawn"] == i2["drawn"]
    assert i1["drawn"]["wind_kn"] != i3["drawn"]["wind_kn"]  # the domain is randomised per seed
    assert not np.array_equal(o1, o3)
    # a fresh instance reproduces it too (no hidden global state)
    o4, r4, _ = _episode(ShipEnv("CourseKeeping", "patrol51", sea="wind_current"), 11, 40, a)
    assert np.array_equal(o1, o4) and np.array_equal(r1, r4)


def test_reset_options_override_the_draws_and_are_checked():
    env = ShipEnv("CourseKeeping", "patrol51", sea="wind")
    _, info = env.reset(seed=1, options={"wind_kn": 22.0, "wind_from_deg": 90.0, "order": "full"})
    assert info["drawn"]["wind_kn"] == 22.0 and info["drawn"]["order"] == "full"
    with pytest.raises(InputError, match="order"):
        env.reset(seed=1, options={"order": "warp"})
    with pytest.raises(InputError, match="sea"):
        ShipEnv(sea="tsunami")
    with pytest.raises(InputError, match="task"):
        ShipEnv(task="Parking")


def test_vector_env_ship_i_is_the_scalar_env_with_seed_plus_i():
    n, seed, steps = 3, 40, 25
    venv = ShipVectorEnv(n, "TrackFollowing", "patrol51", sea="wind_current")
    acts = np.linspace(-0.5, 0.5, n)[:, None].astype(np.float32)
    obs, _ = venv.reset(seed=seed)
    vo, vr = [obs], []
    for _ in range(steps):
        obs, r, term, trunc, _ = venv.step(acts)
        vo.append(obs)
        vr.append(r)
    vo, vr = np.array(vo), np.array(vr)
    for i in range(n):
        so, sr, _ = _episode(ShipEnv("TrackFollowing", "patrol51", sea="wind_current"), seed + i, steps, acts[i])
        assert np.array_equal(vo[:, i], so), f"ship {i}: observations differ from the scalar env"
        assert np.array_equal(vr[:, i], sr)


def test_vector_autoreset_next_step():
    """Gymnasium 1.x NEXT_STEP: the step after the end returns the reset observation, reward 0."""
    venv = ShipVectorEnv(2, "Stopping", "patrol51", sea="calm")
    obs, _ = venv.reset(seed=7)
    env = ShipEnv("Stopping", "patrol51", sea="calm")
    env.reset(seed=7)
    act = np.array([[0.0, -1.0], [0.0, 1.0]], dtype=np.float32)  # ship 0 goes full astern and stops
    for k in range(400):
        obs, r, term, trunc, _ = venv.step(act)
        so, sr, st, _, _ = env.step(act[0])
        assert sr == r[0]
        if term[0]:
            break
    assert term[0] and st and not term[1], "ship 0 should stop at rest well within 400 steps"
    obs, r, term, trunc, _ = venv.step(act)
    assert r[0] == 0.0 and not term[0] and not trunc[0]
    so, _ = env.reset()  # the scalar env's next episode from the same Generator
    assert np.array_equal(obs[0], so)


def test_env_ship_follows_the_simulator_driven_directly():
    """The environment's ship is the simulator's ship: driven through the Simulator's command API
    with the same environment block, a separate Simulator gives bit-identical truth."""
    from vtrials.physics.simulator import Simulator
    env = ShipEnv("Stopping", "patrol51", sea="wind_current")
    env.reset(seed=5)
    core = env.core
    sim = Simulator(core.vessel, 1, core.dt, envs=core.sim.env[0].copy(), record_every=0)
    s0 = core._steady_state(core.drawn[0]["order"])
    import dataclasses
    sim.set_state(0, dataclasses.replace(s0, heading=core.task.psi0[0]))
    rps0, pitch0 = core.vessel.telegraph["back_emergency"]  # lever −1 (exact in float32)
    for k in range(30):
        env.step(np.array([0.5, -1.0], dtype=np.float32))
        sim.set_rudder_order(0, 0.5 * core.delta_max)
        sim.set_shaft_order(0, rps0)
        sim.set_pitch_order(0, pitch0)
        sim.step(core.substeps)
    assert np.array_equal(sim.qpos[0], core.sim.qpos[0]) and np.array_equal(sim.qvel[0], core.sim.qvel[0])
    # and it is a ship, not a kinematic boat: the stern swings out (drift angle) in the turn
    u, v = core.truth["u_r"][0], core.truth["v_r"][0]
    assert abs(math.degrees(math.atan2(-v, u))) > 1.0


def _straight_run_truth():
    from vtrials.physics.simulator import Simulator
    from vtrials.physics.vessel import load_vessel
    from vtrials.trials.driver import Driver
    v = load_vessel("patrol51")
    sim = Simulator(v, 1, 0.02, record_every=1)
    sim.steady_at_order(0, (7.5, 7.5), (1.22, 1.22), heading=0.7)
    sim.step(1100)
    cols = Driver(sim).columns(np.ascontiguousarray(sim.truth()[:, 0, :]))
    return v, cols


def test_observation_model_matches_instrument_set_statistics():
    """Errors of the vectorised observation model vs those of the InstrumentSet devices on the same
    straight-run truth, over many instrument draws: same spread per channel (ratio of standard
    deviations within ±20 %, ≈ 6 standard errors at 400 draws) and means within 4 standard errors."""
    from vtrials.instruments.suite import InstrumentSet
    v, cols = _straight_run_truth()
    parts, sites, dev, index = suite_parts(v)
    M = 400
    t_s = 20.0
    k = int(np.argmin(np.abs(cols["t"] - t_s)))
    c, s = math.cos(cols["heading"][k]), math.sin(cols["heading"][k])
    truth = {"psi": cols["heading"][k], "r": cols["r"][k], "x": cols["x"][k], "y": cols["y"][k],
             "vn": c * cols["u"][k] - s * cols["v"][k], "ve": s * cols["u"][k] + c * cols["v"][k],
             "u_r": cols["u_r"][k], "rudder": cols[f"rudder_{index['rudder']}"][k],
             "shaft_rps": cols[f"shaft_n_{index['shaft_rps']}"][k]}
    om = ObservationModel(parts, sites, M, 0.34, 4)
    for i in range(M):
        om.reset(i, np.random.default_rng(1000 + i))
    y = om.sample({kk: np.full(M, vv) for kk, vv in truth.items()})
    # the InstrumentSet devices: reading nearest t_s minus the truth at the reading's time
    sel = slice(0, int(np.searchsorted(cols["t"], t_s + 1.5)))
    part = {kk: vv[sel] for kk, vv in cols.items()}
    want = {"heading": ("heading", "heading"), "yaw_rate": ("yaw_rate", "r"), "north": ("north", "north"),
            "east": ("north", "east"), "sog": ("north", "sog"), "log_speed": ("log_speed", "speed"),
            "rudder": ("rudder", "angle"), "shaft_rps": ("shaft_rps", "rps")}
    ref = {ch: np.zeros(M) for ch in CHANNELS}
    gx, gy = sites["north"][0], sites["north"][1]
    ant = (truth["x"] + c * gx - s * gy, truth["y"] + s * gx + c * gy)
    tv = {"heading": truth["psi"], "yaw_rate": truth["r"], "north": ant[0], "east": ant[1],
          "sog": math.hypot(truth["vn"], truth["ve"]), "log_speed": truth["u_r"], "rudder": truth["rudder"],
          "shaft_rps": truth["shaft_rps"]}
    # the truth at a device's own sample time (the ship moves ~7.5 m between 1 Hz fixes)
    series = {"north": part["x"] + c * gx - s * gy, "east": part["y"] + s * gx + c * gy}
    iset = InstrumentSet(v, 0, default_site())
    for i in range(M):
        iset.seed = 5000 + i  # a new draw of every instrument (their streams are keyed on the seed)
        iset.reset()
        out = {}
        for ch, (src, chan) in want.items():
            name = dev[src]
            if name not in out:
                out[name] = iset.devices[name].process(part)
            t, vals = out[name]
            j = int(np.argmin(np.abs(t - t_s)))
            at = float(np.interp(t[j], part["t"], series[ch])) if ch in series else tv[ch]
            ref[ch][i] = vals[chan][j] - at
    for j, ch in enumerate(CHANNELS):
        e = y[:, j] - tv[ch]
        r = ref[ch]
        if ch == "heading":
            e, r = wrap(e), wrap(r)
        sd_m, sd_r = e.std(ddof=1), r.std(ddof=1)
        assert sd_r > 0, ch
        print(f"{ch}: sd model {sd_m:.4g}, InstrumentSet {sd_r:.4g} (ratio {sd_m / sd_r:.3f}); "
              f"means {e.mean():.3g}, {r.mean():.3g}")
        assert 0.8 < sd_m / sd_r < 1.25, f"{ch}: model sd {sd_m:.4g} vs InstrumentSet sd {sd_r:.4g}"
        se = math.hypot(sd_m, sd_r) / math.sqrt(M)
        assert abs(e.mean() - r.mean()) < 4 * se + 1e-12, f"{ch}: means {e.mean():.4g} vs {r.mean():.4g}"


def test_observation_model_gauss_markov_correlation():
    """Between control instants the slow error decorrelates as exp(−Δ/τ) (GNSS: τ = 120 s; multipath 10 s)."""
    from vtrials.physics.vessel import load_vessel
    parts, sites, _, _ = suite_parts(load_vessel("patrol51"))
    M, period = 4000, 60.0
    om = ObservationModel(parts, sites, M, period, 3)
    for i in range(M):
        om.reset(i, np.random.default_rng(i))
    truth = {k: np.zeros(M) for k in ("psi", "r", "x", "y", "vn", "ve", "u_r", "rudder", "shaft_rps")}
    y0 = om.sample(truth)[:, 2].copy()
    y1 = om.sample(truth)[:, 2].copy()
    p = parts["north"]
    # the slow error and the multipath (a second Gauss–Markov error) over white noise and resolution
    rho_expected = ((p.gm_sd ** 2 * math.exp(-period / p.gm_tau) + p.gm2_sd ** 2 * math.exp(-period / p.gm2_tau))
                    / (p.gm_sd ** 2 + p.gm2_sd ** 2 + p.noise ** 2 + p.resolution ** 2 / 12))
    rho = np.corrcoef(y0, y1)[0, 1]
    assert abs(rho - rho_expected) < 4 * (1 - rho_expected ** 2) / math.sqrt(M) + 0.01


def test_pid_baseline_keeps_course_in_wind_and_current():
    """The autopilot holds the commanded course through gusty wind and current (RMS heading error
    after the course change under 1°), far better than leaving the rudder amidships."""
    env = ShipEnv("CourseKeeping", "patrol51", sea="wind_current")
    pid = PIDPolicy(env.core)
    opts = {"wind_kn": 25.0, "current_kn": 1.5}
    _, errs, k = run_episode(env, pid, 3, opts, max_steps=300)
    rms = math.degrees(float(np.sqrt(np.mean(errs[100:] ** 2))))
    env.reset(seed=3, options=opts)
    e0 = []
    for _ in range(300):
        env.step(np.zeros(1, dtype=np.float32))
        e0.append(float(wrap(env.core.truth["psi"][0] - env.core.task.ref[0])))
    rms0 = math.degrees(float(np.sqrt(np.mean(np.square(e0[100:])))))
    assert rms < 1.0 and rms0 > 5 * rms, (rms, rms0)


@pytest.mark.parametrize("task", ["ZigZag", "Williamson", "Stopping", "TrackFollowing"])
def test_pid_baselines_do_their_tasks(task):
    env = ShipEnv(task, "patrol51", sea="calm")
    pid = PIDPolicy(env.core)
    total, _, k = run_episode(env, pid, 2)
    c = env.core
    if task == "ZigZag":
        assert c.task.switches[0] >= 4 and total / k > -0.3  # rudder reversals on time, mostly
    elif task == "Williamson":
        assert k < c.task_steps()[0]  # back on the reciprocal course on the track: success
    elif task == "Stopping":
        ect, along = c.task.track_errors(c.truth["x"], c.truth["y"], c.truth["psi"], np.arange(1))
        assert c.truth["sog"][0] < 0.05 * c.task.U0[0] and abs(c.task.mark[0] - along[0]) < 1.5 * c.L
    else:
        ect, _ = c.task.track_errors(c.truth["x"], c.truth["y"], c.truth["psi"], np.arange(1))
        assert abs(ect[0]) < 0.05 * c.L
