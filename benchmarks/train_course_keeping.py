"""Train a PPO agent (stable-baselines3, optional extra ``vtrials[rl]``) on course keeping in gusty wind
and current, and compare it with the ship's PID autopilot on unseen seeds (issue 15 acceptance: the
agent, trained ≤ 30 min on 2 cores, should beat the autopilot on RMS heading error).

    python benchmarks/train_course_keeping.py --minutes 25 --out bench_out/ppo_ck

Environment: vtrials/CourseKeeping-v0 (patrol51), sea="wind_current" (wind 10–30 kn from any
direction with NPD gusts, current 0.5–2 kn; drawn per episode), observations from the instruments.
Score: RMS of the TRUE heading error to the commanded course over the last two thirds of each episode
(after the course change), evaluation seeds 10_000 + k (never used in training: training episodes
draw from seeds below 10_000). Writes curve.csv, curve.png, summary.json and the model to --out.

Both controllers see the heading only through the gyrocompass, whose drawn bias and drift (σ ≈ 0.17°)
neither can observe, so the true RMS carries that bias for both. The comparison therefore also gives,
per episode, the RMS of the MEASURED heading error (what the controller can act on) and the standard
deviation of the true error about its episode mean (the dynamic part, free of any constant offset), and
over the seeds the paired statistics: the fraction of seeds PPO wins (Wilson 95 % interval) and the
mean paired difference with its t interval. ``--evaluate MODEL`` re-runs only the comparison (e.g. on
100 seeds) for a saved model:

    python benchmarks/train_course_keeping.py --evaluate bench_out/ppo_ck/model.zip --eval-seeds 100
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


def rms_heading_error(env, act_fn, seed: int) -> dict:
    """Heading-error statistics [deg] over the last two thirds of one episode: ``true`` (RMS of the true
    heading error), ``dynamic`` (its standard deviation about the episode mean), ``measured`` (RMS of
    the gyrocompass heading error the controller sees)."""
    from vtrials.envs.tasks import wrap
    obs, _ = env.reset(seed=seed)
    core = env.unwrapped.core
    errs, meas = [], []
    while True:
        obs, r, term, trunc, _ = env.step(act_fn(obs))
        errs.append(float(wrap(core.truth["psi"][0] - core.task.ref[0])))
        meas.append(float(wrap(core.meas[0, 0] - core.task.ref[0])))
        if term or trunc:
            break
    k = len(errs) // 3
    e, m = np.array(errs[k:]), np.array(meas[k:])
    return {"true": math.degrees(float(np.sqrt(np.mean(e ** 2)))), "dynamic": math.degrees(float(np.std(e))),
            "measured": math.degrees(float(np.sqrt(np.mean(m ** 2))))}


def evaluate(model_or_pid, seeds, sea: str) -> list[dict]:
    from vtrials.envs.baselines import PIDPolicy
    from vtrials.envs.ship_env import ShipEnv
    env = ShipEnv("CourseKeeping", "patrol51", sea=sea)
    if model_or_pid == "pid":
        pid = PIDPolicy(env.core)

        def act(obs):
            return pid()[0]
        out = []
        for s in seeds:
            pid.reset()
            out.append(rms_heading_error(env, act, s))
        return out
    return [rms_heading_error(env, lambda o: model_or_pid.predict(o, deterministic=True)[0], s) for s in seeds]


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
    ap.add_argument("--minutes", type=float, default=25.0, help="wall-clock training budget")
    ap.add_argument("--n-envs", type=int, default=8)
    ap.add_argument("--sea", default="wind_current")
    ap.add_argument("--eval-every", type=int, default=50_000, help="timesteps between curve points")
    ap.add_argument("--eval-seeds", type=int, default=10, help="unseen seeds in the final comparison")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", default="bench_out/ppo_course_keeping")
    ap.add_argument("--evaluate", default=None, help="a saved model (.zip): only compare it with the PID")
    a = ap.parse_args(argv)
    try:
        import torch
        from stable_baselines3 import PPO
        from stable_baselines3.common.callbacks import BaseCallback
        from stable_baselines3.common.vec_env import DummyVecEnv
    except ImportError:
        raise SystemExit("needs the optional RL extra: pip install 'vtrials[rl]' (stable-baselines3, torch)")
    from vtrials.envs.ship_env import ShipEnv
    torch.set_num_threads(1)
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    seeds = [EVAL_SEED0 + k for k in range(a.eval_seeds)]
    if a.evaluate:
        model = PPO.load(a.evaluate)
        ppo, pid = evaluate(model, seeds, a.sea), evaluate("pid", seeds, a.sea)
        st = paired(ppo, pid)
        (out / "evaluation.json").write_text(json.dumps({"model": str(a.evaluate), "sea": a.sea, "eval_seeds": seeds,
                                                         "ppo": ppo, "pid": pid, "paired": st}, indent=1))
        _report(st)
        return

    def make(i):
        def f():
            env = ShipEnv("CourseKeeping", "patrol51", sea=a.sea)
            env.reset(seed=a.seed * 1000 + i)  # training seeds < EVAL_SEED0; later episodes go on drawing
            return env
        return f

    venv = DummyVecEnv([make(i) for i in range(a.n_envs)])
    model = PPO("MlpPolicy", venv, n_steps=512, batch_size=256, n_epochs=10, learning_rate=3e-4, gamma=0.99,
                gae_lambda=0.95, clip_range=0.2, ent_coef=0.0, seed=a.seed, verbose=0,
                policy_kwargs={"net_arch": [64, 64]})
    curve_seeds = [EVAL_SEED0 + 500 + k for k in range(3)]
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
        rms = [r["true"] for r in evaluate(model, curve_seeds, a.sea)]
        curve.append((done, time.perf_counter() - t0, float(np.mean(rms))))
        print(f"{done:>9d} steps {curve[-1][1] / 60:6.1f} min  RMS heading error {curve[-1][2]:.3f} deg", flush=True)
    train_min = (time.perf_counter() - t0) / 60.0
    model.save(out / "model")
    ppo = evaluate(model, seeds, a.sea)
    pid = evaluate("pid", seeds, a.sea)
    pid_curve = float(np.mean([r["true"] for r in evaluate("pid", curve_seeds, a.sea)]))
    st = paired(ppo, pid)
    summary = {"timesteps": done, "train_minutes": train_min, "n_envs": a.n_envs, "sea": a.sea,
               "eval_seeds": seeds, "ppo": ppo, "pid": pid, "paired": st,
               "ppo_mean_rms_deg": st["true"]["ppo_mean_deg"], "pid_mean_rms_deg": st["true"]["pid_mean_deg"],
               "ppo_better_on": st["true"]["ppo_wins"],
               "curve": [{"timesteps": c[0], "minutes": c[1] / 60, "rms_deg": c[2]} for c in curve],
               "pid_rms_on_curve_seeds_deg": pid_curve}
    (out / "summary.json").write_text(json.dumps(summary, indent=1))
    with open(out / "curve.csv", "w") as f:
        f.write("timesteps,minutes,ppo_rms_deg\n")
        for c in curve:
            f.write(f"{c[0]},{c[1] / 60:.3f},{c[2]:.5f}\n")
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(6, 3.5))
        ax.plot([c[0] for c in curve], [c[2] for c in curve], "o-", label="PPO")
        ax.axhline(pid_curve, color="k", ls="--", label="PID autopilot")
        ax.set_xlabel("training timesteps")
        ax.set_ylabel("RMS heading error [deg]")
        ax.set_yscale("log")
        ax.legend()
        ax.grid(True, alpha=0.3)
        fig.tight_layout()
        fig.savefig(out / "curve.png", dpi=100)
    except Exception as exc:  # noqa: BLE001 — the numbers are in summary.json either way
        print(f"no plot: {exc}")
    print(f"{done} steps in {train_min:.1f} min; on {len(seeds)} unseen seeds:")
    _report(st)


if __name__ == "__main__":
    main()
