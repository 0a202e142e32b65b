"""Where the step kernel's time goes, per ship-step (issue 15 follow-up): micro-benchmarks in one run.

For one ship and sea of the gymnasium environments (the state of ``ShipBatch`` after a reset and a
few control periods) and N ships, interleaved rounds of

* ``bare``    a bare ``mujoco.batch`` step of the same model (no forces),
* ``batch``   the simulator's own batch stepped from Python (``sim.batch.step()``, its bound fields),
* ``kernel``  the step kernel alone (``Simulator._kernel``, time advanced so the gust rotates),
* ``loop``    the simulator's whole step (``Simulator.step``: kernel + batch step through the hook),
* ``hook``    the object-mode hook alone, with a no-op in place of the batch step,
* one line per force component (its kernel over the N ships, the context of the current state),
  the gust synthesis, the kinematics, and the rest of the step kernel (by difference),

reported as ns per ship-step and as a fraction of the kernel. Medians over the rounds; the
machine may be shared (the 1-minute load average is written with the results).

    python benchmarks/bench_kernel.py [--ship patrol51] [--sea wind_current] [--n 256] [--nthread 1]
                                      [--rounds 7] [--seconds 0.3] [--json out.json]
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
import types
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import numba as nb  # noqa: E402
import numpy as np  # noqa: E402

from vtrials.physics.dynamics import _hook_step, kinematics  # noqa: E402

try:
    from vtrials.physics.dynamics import borrow  # noqa: E402
except ImportError:  # an older tree (before/after comparisons)
    @nb.njit
    def borrow(a):
        return a
from vtrials.physics.environment.wind import gust_step  # noqa: E402


CLOCK = time.perf_counter  # main() switches to the thread's CPU time with --cpu-time


def _rate(fn, seconds):
    k, t0 = 0, CLOCK()
    while True:
        fn()
        k += 1
        dt = CLOCK() - t0
        if dt >= seconds:
            return k / dt


@nb.njit(cache=True)
def _comp_loop(kern, reps, par, st, env, ctx, aux, w):
    """``reps`` evaluations of one component kernel for every ship (states on a scratch copy)."""
    par, st, env, ctx, aux, w = borrow(par), borrow(st), borrow(env), borrow(ctx), borrow(aux), borrow(w)
    for _ in range(reps):
        for i in range(par.shape[0]):
            kern(par[i], st[i], env[i], ctx[i], aux[i], w[i])


@nb.njit(cache=True)
def _gust_loop(reps, env, nav, t0, dt):
    env, nav, t0 = borrow(env), borrow(nav), borrow(t0)
    u = 0.0
    for r in range(reps):
        for i in range(env.shape[0]):
            u += gust_step(env[i], nav[i, 4:], t0[i], dt)
            t0[i] += dt  # as MuJoCo advances the time: the gust keeps rotating its phasors
    return u


@nb.njit(cache=True)
def _kin_loop(reps, qpos, qvel, time_, env, steer, shaftp, ctx, scratch):
    qpos, qvel, time_, env, ctx, scratch = borrow(qpos), borrow(qvel), borrow(time_), borrow(env), borrow(ctx), \
        borrow(scratch)
    for _ in range(reps):
        for i in range(qpos.shape[0]):
            sc = scratch[i]
            kinematics(qpos[i], qvel[i], time_[i], env[i], steer, shaftp, sc[0:9], sc[9:12], sc[12:15], sc[15:18],
                       ctx[i])


@nb.njit(cache=True)
def _hook_loop(reps, hook_id):
    s = 0
    for _ in range(reps):
        s += _hook_step(hook_id)
    return s


class _NoCore:
    """A batch core whose step does nothing and succeeds."""

    def step(self, ids=None, nstep=1, stage=0):
        return 0


class _NoBatch:
    """A batch whose step does nothing (the hook reaches the core, older trees the wrapper)."""

    _b = _NoCore()

    def step(self):
        pass


def measure(ship, sea, n, nthread, rounds, seconds, task="CourseKeeping"):
    from mujoco import batch as mjbatch
    from vtrials.envs.core import ShipBatch
    from vtrials.physics import dynamics as DY
    from vtrials.physics.forces.registry import component_type  # noqa: F401
    core = ShipBatch(task, ship, n, sea, nthread=nthread)
    core.reset_ships(np.arange(n), list(range(n)))
    act = np.zeros((n, 2))
    for _ in range(3):
        core.step(act)
    sim = core.sim
    bare = mjbatch.Batch(sim.model, n, nthread=sim.batch.nthread)
    bare.step()
    # kernel alone: advance the time each call so that the gust takes its per-step path
    t_saved = sim.time.copy()

    def kernel():
        sim._call(krec=-1)
        sim.time[:] += sim.dt

    # components: the context of the current state (one kernel call fills ctx/aux)
    sim._call(krec=-1)
    sim.time[:] = t_saved
    comps = []
    for ci, name in enumerate(sim.comp_names):
        ct = sim.comp_types[int(sim.comp_kind[ci])]
        kern = ct.kernel()
        a, b = int(sim.comp_off[ci]), int(sim.comp_off[ci + 1])
        sa, sb = int(sim.comp_soff[ci]), int(sim.comp_soff[ci + 1])
        par = np.ascontiguousarray(sim.comp_par[:, a:b])
        st = np.ascontiguousarray(sim.comp_st[:, sa:sb])
        ctx = sim.ctx.copy()
        aux = sim.aux.copy()
        w = np.zeros((n, 6))
        comps.append((name, kern, par, st, ctx, aux, w))
    nav = sim.nav.copy()
    env = sim.env
    kscr = np.zeros((n, 18))
    kctx = sim.ctx.copy()
    # the hook with a no-op batch
    fake = types.SimpleNamespace(batch=_NoBatch(), _hook_error=None)
    hid = -12345
    DY._HOOKS[hid] = lambda: fake
    REP = 50
    rates = {k: [] for k in ["bare", "batch", "kernel", "loop", "hook", "gust", "kinematics"] + [c[0] for c in comps]}
    # warm-ups (compilation)
    _hook_loop(1, hid)
    _gust_loop(1, env, nav.copy(), sim.time.copy(), sim.dt)
    _kin_loop(1, sim.qpos, sim.qvel, sim.time, env, sim.steer, sim.shaftp, kctx, kscr)
    for name, kern, par, st, ctx, aux, w in comps:
        _comp_loop(kern, 1, par, st.copy(), env, ctx, aux, w)
    for _ in range(rounds):
        rates["bare"].append(_rate(bare.step, seconds) * n)
        state = sim.batch.state.copy()
        rates["batch"].append(_rate(sim.batch.step, seconds) * n)
        sim.batch.state[:] = state  # the batch alone (stale forces) would drift away
        keep = [a.copy() for a in (sim.nav, sim.mach, sim.hs, sim.events, sim.ecount, sim.rud_cmd, sim.comp_st)]
        rates["kernel"].append(_rate(kernel, seconds) * n)
        sim.batch.state[:] = state
        for a, b in zip((sim.nav, sim.mach, sim.hs, sim.events, sim.ecount, sim.rud_cmd, sim.comp_st), keep):
            a[...] = b
        rates["loop"].append(_rate(lambda: sim.step(REP), seconds) * n * REP)
        rates["hook"].append(_rate(lambda: _hook_loop(REP * 20, hid), seconds) * REP * 20)
        t0 = sim.time.copy()
        navc = nav.copy()
        rates["gust"].append(_rate(lambda: _gust_loop(REP, env, navc, t0, sim.dt), seconds) * n * REP)
        rates["kinematics"].append(_rate(lambda: _kin_loop(REP, sim.qpos, sim.qvel, sim.time, env, sim.steer,
                                                           sim.shaftp, kctx, kscr), seconds) * n * REP)
        for name, kern, par, st, ctx, aux, w in comps:
            stc = st.copy()
            rates[name].append(_rate(lambda: _comp_loop(kern, REP, par, stc, env, ctx, aux, w), seconds) * n * REP)
    DY._HOOKS.pop(hid, None)
    ns = {k: 1e9 / float(np.median(v)) for k, v in rates.items()}  # ns per ship-step (hook: per call)
    ns["hook_per_ship"] = ns["hook"] / n
    parts = ["gust", "kinematics"] + [c[0] for c in comps]
    ns["kernel_rest"] = ns["kernel"] - sum(ns[p] for p in parts)
    return ns


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--ship", default="patrol51")
    ap.add_argument("--sea", default="wind_current")
    ap.add_argument("--n", type=int, default=256)
    ap.add_argument("--nthread", type=int, default=1)
    ap.add_argument("--rounds", type=int, default=7)
    ap.add_argument("--seconds", type=float, default=0.3)
    ap.add_argument("--cpu-time", action="store_true",
                    help="time by the thread's CPU time (robust on a shared machine; --nthread 1 only)")
    ap.add_argument("--json", default=None)
    a = ap.parse_args(argv)
    if a.cpu_time:
        if a.nthread != 1:
            ap.error("--cpu-time needs --nthread 1")
        global CLOCK
        CLOCK = time.thread_time
    load0 = os.getloadavg()[0]
    ns = measure(a.ship, a.sea, a.n, a.nthread, a.rounds, a.seconds)
    load1 = os.getloadavg()[0]
    k = ns["kernel"]
    print(f"{a.ship} sea={a.sea} N={a.n} nthread={a.nthread} cpu_time={a.cpu_time} load {load0:.1f}→{load1:.1f}")
    for key, v in ns.items():
        print(f"  {key:>24} {v:9.1f} ns/ship-step  {v / k:6.3f} of kernel  {v / ns['bare']:6.3f} of bare")
    if a.json:
        Path(a.json).write_text(json.dumps({"ship": a.ship, "sea": a.sea, "N": a.n, "nthread": a.nthread, "cpu_time": a.cpu_time,
                                            "load_average_1min": [load0, load1], "ns_per_ship_step": ns},
                                           indent=1))


if __name__ == "__main__":
    main()
