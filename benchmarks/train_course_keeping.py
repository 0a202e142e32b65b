"""Train a PPO agent (stable-baselines3, optional extra ``vtrials[rl]``) on course keeping in gusty wind
and current, and compare it with the ship's PID autopilot on unseen seeds (issue 15 acceptance: the
agent, trained ≤ 30 min on 2 cores, should beat the autopilot on RMS heading error).

    python benchmarks/train_course_keeping.py --minutes 26 --integral --out bench_out/ppo_ck

Environment: vtrials/CourseKeeping-v0 (patrol51), sea="wind_current" (wind 10–30 kn from any
direction with NPD gusts, current 0.5–2 kn; drawn per episode), observations from the instruments;
``--integral`` adds the task option ``heading_integral`` (the integral of the measured heading error,
the state of an autopilot's integral action). Training steps ``--n-envs`` ships in one ShipBatch (one
``mujoco.batch``) through a small stable-baselines3 VecEnv; 1 torch thread.
Score: RMS of the TRUE heading error to the commanded course over the last two thirds of each episode
(after the course change), evaluation seeds 10_000 + k (never used in training: training episodes
start from seeds below 10_000 and go on drawing from each ship's Generator; the curve uses 15_000 + k).
Writes curve.csv, curve.png, summary.json and the model to --out.

Both controllers see the heading only through the gyrocompass, whose drawn bias and drift (σ ≈ 0.17°)
neither can observe, so the true RMS carries that bias for both. The comparison therefore also gives,
per episode, the RMS of the MEASURED heading error (what the controller can act on) and the standard
deviation of the true error about its episode mean (the dynamic part, free of any constant offset), and
over the seeds the paired statistics: the fraction of seeds PPO wins (Wilson 95 % interval) and the
mean paired difference with its t interval. ``--evaluate MODEL`` re-runs only the comparison for a
saved model:

    python benchmarks/train_course_keeping.py --evaluate bench_out/ppo_ck/model.zip --eval-seeds 200
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import numpy as np  # noqa: E402

EVAL_SEED0 = 10_000


def _stats(errs: np.ndarray, meas: np.ndarray) -> dict:
    k = len(errs) // 3
    e, m = errs[k:], meas[k:]
    return {"true": math.degrees(float(np.sqrt(np.mean(e ** 2)))), "dynamic": math.degrees(float(np.std(e))),
            "measured": math.degrees(float(np.sqrt(np.mean(m ** 2)))),
            "true_mean": math.degrees(float(np.mean(e))), "measured_mean": math.degrees(float(np.mean(m)))}


def evaluate(model_or_pid, seeds, sea: str, integral: bool = False, norm=None) -> list[dict]:
    """Heading-error statistics [deg] of one episode per seed, over the last two thirds of each episode:
    ``true`` (RMS of the true heading error), ``dynamic`` (its standard deviation about the episode
    mean), ``measured`` (RMS of the gyrocompass heading error the controller sees) and the two means.

    All seeds run at once as the ships of one ShipBatch (ship i's episode depends only on its seed:
    the same episode as ``ShipEnv(...).reset(seed=s)``, tests/test_envs.py); each ship is scored until
    its own episode ends (truncation at its task duration, or a failure)."""
    from vtrials.envs.baselines import PIDPolicy
    from vtrials.envs.core import ShipBatch
    from vtrials.envs.tasks import wrap
    n = len(seeds)
    core = ShipBatch("CourseKeeping", "patrol51", n, sea, task_options={"heading_integral": bool(integral)})
    core.reset_ships(np.arange(n), list(seeds))
    if model_or_pid == "pid":
        pid = PIDPolicy(core)
        pid.reset()
        act = lambda obs: pid()  # noqa: E731
    else:
        def act(obs):
            return model_or_pid.predict(obs if norm is None else norm.normalize_obs(obs), deterministic=True)[0]
    steps = core.task_steps()
    live = np.ones(n, dtype=bool)
    errs, meas, alive = [], [], []
    while live.any():
        _, term, trunc, _ = core.step(act(core.observations().copy()))
        errs.append(wrap(core.truth["psi"] - core.task.ref))
        meas.append(wrap(core.meas[:, 0] - core.task.ref))
        alive.append(live.copy())
        live &= ~(term | (core.steps >= steps))
    E, M, A = np.array(errs), np.array(meas), np.array(alive)
    return [_stats(E[A[:, i], i], M[A[:, i], i]) for i in range(n)]


def batch_vec_env(n: int, sea: str, integral: bool, seed: int):
    """A stable-baselines3 VecEnv of ``n`` CourseKeeping ships stepped in one ShipBatch (one
    ``mujoco.batch``), resetting a ship as soon as its episode ends (SB3's convention: the last
    observation in ``infos[i]["terminal_observation"]``)."""
    from stable_baselines3.common.vec_env import VecEnv
    from vtrials.envs.core import ShipBatch
    from vtrials.envs.ship_env import spaces_of

    class ShipBatchVecEnv(VecEnv):
        def __init__(self):
            self.core = ShipBatch("CourseKeeping", "patrol51", n, sea, task_options={"heading_integral": integral})
            super().__init__(n, *spaces_of(self.core))
            self._a = None

        def reset(self):
            # training seeds < EVAL_SEED0; later episodes go on drawing from each ship's Generator
            self.core.reset_ships(np.arange(n), [seed * 1000 + i for i in range(n)])
            return self.core.observations().copy()

        def step_async(self, actions):
            self._a = np.asarray(actions).reshape(n, -1)

        def step_wait(self):
            r, term, trunc, _ = self.core.step(self._a)
            obs = self.core.observations().copy()
            done = term | trunc
            infos = [{} for _ in range(n)]
            idx = np.flatnonzero(done)
            for i in idx:
                infos[i]["terminal_observation"] = obs[i].copy()
                infos[i]["TimeLimit.truncated"] = bool(trunc[i] and not term[i])
            if idx.size:
                self.core.reset_ships(idx)
                obs = self.core.observations().copy()
            return obs, r.astype(np.float32), done, infos

        def close(self):
            pass

        def get_attr(self, attr_name, indices=None):
            return [getattr(self, attr_name)] * len(self._get_indices(indices))

        def set_attr(self, attr_name, value, indices=None):
            setattr(self, attr_name, value)

        def env_method(self, method_name, *args, indices=None, **kwargs):
            raise NotImplementedError(method_name)

        def env_is_wrapped(self, wrapper_class, indices=None):
            return [False] * len(self._get_indices(indices))

        def seed(self, seed=None):
            return [None] * n

    return ShipBatchVecEnv()


def paired(ppo: list[dict], pid: list[dict]) -> dict:
    """Per metric: means, the fraction of seeds PPO is lower (Wilson 95 % interval) and the mean paired
    difference PPO − PID with its 95 % t interval [deg]."""
    from scipy import stats
    out = {}
    n = len(ppo)
    for key in ("true", "dynamic", "measured"):
        a = np.array([r[key] for r in ppo])
        b = np.array([r[key] for r in pid])
        d = a - b
        wins = int(np.sum(d < 0))
        z = 1.959964
        ph = wins / n
        centre = (ph + z * z / (2 * n)) / (1 + z * z / n)
        half = z * math.sqrt(ph * (1 - ph) / n + z * z / (4 * n * n)) / (1 + z * z / n)
        t = stats.t.ppf(0.975, n - 1) if n > 1 else float("nan")
        se = float(np.std(d, ddof=1) / math.sqrt(n)) if n > 1 else float("nan")
        out[key] = {"ppo_mean_deg": float(a.mean()), "pid_mean_deg": float(b.mean()), "ppo_wins": wins, "n": n,
                    "win_fraction_95": [centre - half, centre + half],
                    "mean_difference_deg": float(d.mean()),
                    "mean_difference_95_deg": [float(d.mean() - t * se), float(d.mean() + t * se)]}
    return out


def _report(stats_: dict) -> None:
    for key, r in stats_.items():
        print(f"{key:>9}: PPO {r['ppo_mean_deg']:.3f} vs PID {r['pid_mean_deg']:.3f} deg; PPO lower on "
              f"{r['ppo_wins']}/{r['n']} seeds (95 % {r['win_fraction_95'][0]:.2f}-{r['win_fraction_95'][1]:.2f}); "
              f"difference {r['mean_difference_deg']:+.3f} deg "
              f"[{r['mean_difference_95_deg'][0]:+.3f}, {r['mean_difference_95_deg'][1]:+.3f}]")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--minutes", type=float, default=25.0, help="wall-clock training budget (curve points included)")
    ap.add_argument("--n-envs", type=int, default=32, help="ships stepped together in one ShipBatch")
    ap.add_argument("--n-steps", type=int, default=512, help="PPO rollout length per ship")
    ap.add_argument("--batch-size", type=int, default=512)
    ap.add_argument("--sea", default="wind_current")
    ap.add_argument("--integral", action="store_true",
                    help="observe the integral of the measured heading error (task option heading_integral)")
    ap.add_argument("--normalize", action="store_true",
                    help="running normalisation of observations and rewards (SB3 VecNormalize, saved with the model)")
    ap.add_argument("--eval-every", type=int, default=200_000, help="timesteps between curve points")
    ap.add_argument("--curve-seeds", type=int, default=20, help="held-out seeds of each curve point")
    ap.add_argument("--eval-seeds", type=int, default=200, help="unseen seeds in the final comparison")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", default="bench_out/ppo_course_keeping")
    ap.add_argument("--evaluate", default=None, help="a saved model (.zip): only compare it with the PID")
    a = ap.parse_args(argv)
    try:
        import torch
        from stable_baselines3 import PPO
        from stable_baselines3.common.callbacks import BaseCallback
    except ImportError:
        raise SystemExit("needs the optional RL extra: pip install 'vtrials[rl]' (stable-baselines3, torch)")
    import os
    torch.set_num_threads(1)
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    seeds = [EVAL_SEED0 + k for k in range(a.eval_seeds)]
    if a.evaluate:
        model = PPO.load(a.evaluate, device="cpu")
        integral = model.observation_space.shape[0] == 13  # 9 common + 3 task features (+ 1 integral)
        norm = None
        npath = Path(a.evaluate).with_name("vecnormalize.pkl")
        if npath.exists():
            import pickle
            with open(npath, "rb") as f:
                norm = pickle.load(f)
        t1 = time.perf_counter()
        ppo, pid = evaluate(model, seeds, a.sea, integral, norm), evaluate("pid", seeds, a.sea)
        st = paired(ppo, pid)
        (out / "evaluation.json").write_text(json.dumps({"model": str(a.evaluate), "sea": a.sea, "integral": integral,
                                                         "eval_seeds": [seeds[0], seeds[-1]],
                                                         "eval_minutes": (time.perf_counter() - t1) / 60,
                                                         "paired": st, "ppo": ppo, "pid": pid}, indent=1))
        _report(st)
        return

    venv = batch_vec_env(a.n_envs, a.sea, a.integral, a.seed)
    norm = None
    if a.normalize:
        from stable_baselines3.common.vec_env import VecNormalize
        venv = norm = VecNormalize(venv, norm_obs=True, norm_reward=True, clip_obs=10.0, gamma=0.99)
    model = PPO("MlpPolicy", venv, n_steps=a.n_steps, batch_size=a.batch_size, n_epochs=10, learning_rate=3e-4,
                gamma=0.99, gae_lambda=0.95, clip_range=0.2, ent_coef=0.0, seed=a.seed, verbose=0, device="cpu",
                policy_kwargs={"net_arch": [64, 64]})
    # curve seeds: unseen in training and apart from the final evaluation's (EVAL_SEED0 + 0 … eval_seeds − 1)
    curve_seeds = [EVAL_SEED0 + 5000 + k for k in range(a.curve_seeds)]
    pid_curve = evaluate("pid", curve_seeds, a.sea)
    curve = []
    t0 = time.perf_counter()
    deadline = t0 + 60.0 * a.minutes

    class Stop(BaseCallback):
        def _on_step(self):
            return time.perf_counter() < deadline

    done = 0
    while time.perf_counter() < deadline:
        model.learn(a.eval_every, reset_num_timesteps=False, callback=Stop())
        done = model.num_timesteps
        r = evaluate(model, curve_seeds, a.sea, a.integral, norm)
        curve.append({"timesteps": done, "minutes": (time.perf_counter() - t0) / 60,
                      "true_rms_deg": float(np.mean([x["true"] for x in r])),
                      "measured_rms_deg": float(np.mean([x["measured"] for x in r])),
                      "load_1min": os.getloadavg()[0]})
        c = curve[-1]
        print(f"{done:>9d} steps {c['minutes']:6.1f} min  RMS heading error true {c['true_rms_deg']:.3f}, measured "
              f"{c['measured_rms_deg']:.3f} deg (load {c['load_1min']:.1f})", flush=True)
    train_min = (time.perf_counter() - t0) / 60.0
    model.save(out / "model")
    if norm is not None:
        norm.save(out / "vecnormalize.pkl")
    t1 = time.perf_counter()
    ppo = evaluate(model, seeds, a.sea, a.integral, norm)
    pid = evaluate("pid", seeds, a.sea)
    eval_min = (time.perf_counter() - t1) / 60.0
    st = paired(ppo, pid)
    pid_c = {k: float(np.mean([x[k] for x in pid_curve])) for k in ("true", "measured")}
    summary = {"timesteps": done, "train_minutes": train_min, "n_envs": a.n_envs, "n_steps": a.n_steps,
               "batch_size": a.batch_size, "integral": a.integral, "normalize": a.normalize, "sea": a.sea,
               "torch_threads": 1,
               "load_1min_during_training": [c["load_1min"] for c in curve], "eval_minutes": eval_min,
               "eval_seeds": [seeds[0], seeds[-1]], "paired": st,
               "curve": curve, "curve_seeds": [curve_seeds[0], curve_seeds[-1]], "pid_on_curve_seeds_deg": pid_c,
               "ppo": ppo, "pid": pid}
    (out / "summary.json").write_text(json.dumps(summary, indent=1))
    with open(out / "curve.csv", "w") as f:
        f.write("timesteps,minutes,ppo_true_rms_deg,ppo_measured_rms_deg,load_1min\n")
        for c in curve:
            f.write(f"{c['timesteps']},{c['minutes']:.3f},{c['true_rms_deg']:.5f},{c['measured_rms_deg']:.5f},"
                    f"{c['load_1min']:.2f}\n")
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(6, 3.5))
        x = [c["timesteps"] for c in curve]
        ax.plot(x, [c["true_rms_deg"] for c in curve], "o-", color="C0", label="PPO, true")
        ax.plot(x, [c["measured_rms_deg"] for c in curve], "s--", color="C0", alpha=0.6, label="PPO, measured")
        ax.axhline(pid_c["true"], color="k", ls="-", label="PID autopilot, true")
        ax.axhline(pid_c["measured"], color="k", ls="--", alpha=0.6, label="PID autopilot, measured")
        ax.set_xlabel("training timesteps")
        ax.set_ylabel(f"mean RMS heading error [deg] ({len(curve_seeds)} seeds)")
        ax.set_yscale("log")
        ax.legend(fontsize=8)
        ax.grid(True, alpha=0.3)
        fig.tight_layout()
        fig.savefig(out / "curve.png", dpi=100)
    except Exception as exc:  # noqa: BLE001 — the numbers are in summary.json either way
        print(f"no plot: {exc}")
    print(f"{done} steps in {train_min:.1f} min; on {len(seeds)} unseen seeds:")
    _report(st)


if __name__ == "__main__":
    main()
