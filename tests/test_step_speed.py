"""The speed-ups of the step path change no result: each fast path against the plain computation.

* the propeller's own curve by two-variable Horner over dense tables, against the term-by-term sum
  (pure Python, every power raised afresh) — to rounding (a bound of 64 ε times the sum of the
  terms' magnitudes; a misplaced coefficient is off by orders of magnitude more);
* ``Simulator.step(n)`` (runs of steps in one compiled call, the batch stepped through a hook)
  against the plain loop it replaces (one kernel call and one ``Batch.step`` per step from Python):
  truth rows, states and the stop at a runaway, bit for bit; a failure of the batch's step (reached
  without its Python wrapper) still stops with MuJoCo's message;
* ``Simulator.kinematics()`` against the context a full force evaluation writes;
* the heading fold of the wave tables against its definition (β = μ − ψ wrapped, mirror for β < 0).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from vtrials.errors import SimulationError
from vtrials.physics.environment import wind as W
from vtrials.physics.environment.current import Current
from vtrials.physics.environment.current import pack as pack_current
from vtrials.physics.forces import context as L
from vtrials.physics.forces._wavetable import heading_fold
from vtrials.physics.forces.propeller import P_NQ, P_NT, P_TERMS, own_curve, pack
from vtrials.physics.simulator import Simulator
from vtrials.physics.vessel import load_vessel


@pytest.mark.parametrize("ship", ["patrol51", "kvlcc2"])
def test_own_curve_horner_equals_the_term_by_term_sum(ship):
    """B-series (patrol51) and polynomial (KVLCC2) curves over J × P/D, including J < 0 (the taper
    below J = 0) and P/D outside the series' range: Σ C' J^s (P/D)^t raised term by term, to
    rounding."""
    pr = load_vessel(ship).propellers[0]
    blk = pack(pr, 0, 100.0, 1025.0, 0.01, 1)
    nt, nq = int(blk[P_NT]), int(blk[P_NQ])
    terms = blk[P_TERMS:P_TERMS + 3 * (nt + nq)].reshape(-1, 3)
    n = 0
    for J in np.linspace(-0.2, 1.5, 23):
        for pd in (0.45, 0.6, 0.83, 1.0, 1.27, 1.4, 1.55):
            vt = [float(c) * float(J) ** float(s) * pd ** float(t) for c, s, t in terms[:nt]]
            vq = [float(c) * float(J) ** float(s) * pd ** float(t) for c, s, t in terms[nt:]]
            kt, kq = own_curve(blk, float(J), pd)
            for got, v in ((kt, vt), (kq, vq)):
                bound = 64.0 * np.finfo(float).eps * sum(abs(x) for x in v)
                assert abs(got - sum(v)) <= bound, (J, pd, got - sum(v), bound)
            n += 1
    assert n == 23 * 7


def _sim(ship: str, n: int, dt: float, record_every: int = 1) -> Simulator:
    """n ships in current (with a gradient) and gusty wind, in varied conditions: steady ahead, hard
    over, backing, one shaft locked (twin screws)."""
    v = load_vessel(ship)
    rng = np.random.default_rng(3)
    envs = []
    for k in range(n):
        e = pack_current(Current(speed_kn=0.6 * k, direction_deg=50.0 * k), 1e4)
        e[9] = 1e-4 * k
        e = W.pack_env(W.Wind(speed_kn=12.0 + 5 * k, direction_deg=30.0 * k, gust_spectrum="npd",
                              gust_components=32), e, rng)
        envs.append(e)
    sim = Simulator(v, n, dt, envs=np.stack(envs), record_every=record_every)
    ns = sim.ns
    for i in range(n):
        st = sim.steady_at_order(0, (v.telegraph["full"][0] * (0.5 + 0.1 * i),) * ns)
        st.heading = 0.4 * i
        sim.set_state(i, st)
    sim.set_rudder_order(0, math.radians(25.0))
    if n > 1:
        sim.set_order(1, -v.telegraph["full"][0])
    if n > 2 and ns > 1:
        sim.set_shaft_mode(2, "locked", 0)
    return sim


def _plain_step(sim: Simulator, nstep: int) -> None:
    """The stepping loop Simulator.step replaces: one kernel call and one Batch.step per step."""
    every = sim.record_every
    for _ in range(nstep):
        krec, rec = -1, sim._no_rec
        if every and sim._step_count % every == 0:
            if sim._chunk is None or sim._krow >= sim._chunk.shape[0]:
                sim._new_chunk()
            krec, rec = sim._krow, sim._chunk
            sim._krow += 1
        if sim._call(krec=krec, rec=rec):
            sim._raise_status()
        sim.batch.step()
        if sim._wcount.any():
            raise AssertionError("MuJoCo warning in the reference loop")
        sim._step_count += 1


@pytest.mark.parametrize("ship,dt,every", [("patrol51", 0.02, 1), ("kvlcc2", 0.05, 3), ("kvlcc2_l7", 0.01, 2)])
def test_step_runs_bit_identical_to_plain_loop(ship, dt, every):
    fast, plain = _sim(ship, 3, dt, every), _sim(ship, 3, dt, every)
    for k in (1, 7, 150, 2):       # runs of several lengths, recorded rows at every `every`-th step
        fast.step(k)
        _plain_step(plain, k)
    a, b = fast.truth(), plain.truth()
    assert a.shape == b.shape and a.shape[0] == len(range(0, 160, every))
    assert np.array_equal(a, b)
    for name in ("qpos", "qvel", "time", "mach", "nav", "comp_st", "rud_cmd"):
        assert np.array_equal(getattr(fast, name), getattr(plain, name)), name
    # not a still sea: the ships moved and the one under helm began to turn
    assert np.ptp(a[:, 0, 1]) > 1.0 and np.ptp(a[:, 0, 10]) > 1e-4


def test_step_crosses_truth_chunks_like_plain_loop():
    """Recorded rows across the 4096-row chunk boundary of the truth buffer."""
    fast, plain = _sim("kvlcc2_l7", 1, 0.01), _sim("kvlcc2_l7", 1, 0.01)
    fast.step(4100)
    for _ in range(41):
        _plain_step(plain, 100)
    assert fast.truth().shape[0] == 4100 and np.array_equal(fast.truth(), plain.truth())


def test_runaway_stops_at_the_same_step_with_the_same_rows():
    """A ship pushed past the speed limit stops both loops at the same step, time and message."""
    out = []
    for stepper in ("fast", "plain"):
        sim = _sim("patrol51", 2, 0.02)
        u0 = np.hypot(sim.kinematics()[:, L.NU_R], sim.kinematics()[:, L.NU_R + 1])
        sim.limits[0] = u0.max() + 0.3  # ship 0, ordered past full, goes beyond within seconds
        sim.set_order(0, load_vessel("patrol51").telegraph["full"][0] * 1.2)
        with pytest.raises(SimulationError) as e:
            if stepper == "fast":
                sim.step(100000)
            else:
                _plain_step(sim, 100000)
        out.append((str(e.value), sim._step_count, sim.truth(), sim.qpos.copy()))
    (m1, c1, t1, q1), (m2, c2, t2, q2) = out
    assert "speed beyond the runaway limit" in m1 and 0 < c1 < 100000
    assert m1 == m2 and c1 == c2 and np.array_equal(t1, t2) and np.array_equal(q1, q2)


class _FailingBatch:
    """In place of a Batch's compiled core: every step fails in simulation 1 (as MuJoCo reports it)."""

    nsim = 2

    def step(self, ids, nstep, stage):
        return 1

    def error(self, sim):
        return f"simulated MuJoCo error in {sim}"


def test_batch_failure_through_the_hook_stops_with_mujocos_message():
    """The hook steps the batch's core directly; a failed simulation still raises MuJoCo's
    SimulationError through the batch's own check, and the simulator stops with its message."""
    sim = _sim("patrol51", 2, 0.02)
    sim.step(3)
    sim.batch._b = _FailingBatch()
    sim.batch.status = np.array([0, 1], dtype=np.int32)
    with pytest.raises(SimulationError) as e:
        sim.step(5)
    msg = str(e.value)
    assert "(ship 1)" in msg and "simulated MuJoCo error in 1" in msg and "MuJoCo raised in 1 of 2" in msg
    assert sim._step_count == 3 and sim._hook_error is None


def test_kinematics_equals_the_evaluated_context():
    sim = _sim("patrol51", 3, 0.02)
    sim.step(40)
    kin = sim.kinematics().copy()
    ctx_before = sim.ctx.copy()
    sim.evaluate()
    idx = (list(range(L.NU_R, L.NU_R + 6)) + list(range(L.NU, L.NU + 6)) + list(range(L.POS, L.POS + 3))
           + list(range(L.EUL, L.EUL + 3)) + [L.TIME, L.DEPTH] + list(range(L.ROT, L.ROT + 9))
           + [L.CUR, L.CUR + 1, L.CUR_ACC, L.CUR_ACC + 1]
           + [L.DELTA + k for k in range(sim.nr)] + [L.DELTA_DOT + k for k in range(sim.nr)]
           + [L.SHAFT_N + k for k in range(sim.ns)])
    assert np.array_equal(kin[:, idx], sim.ctx[:, idx])
    assert not np.array_equal(ctx_before[:, idx], sim.ctx[:, idx])  # evaluate did refresh the context
    assert np.any(kin[:, L.CUR] != 0.0) and np.any(kin[:, L.DELTA] != 0.0)


def test_heading_fold_matches_its_definition():
    nbeta = 37
    dh = math.pi / (nbeta - 1)
    for mu in np.linspace(-3 * math.pi, 3 * math.pi, 61):
        for psi in np.linspace(-2 * math.pi, 2 * math.pi, 41):
            i0, fr, sgn = heading_fold(math.cos(mu), math.sin(mu), math.cos(psi), math.sin(psi), dh, nbeta)
            beta = (mu - psi + math.pi) % (2 * math.pi) - math.pi  # in [−π, π)
            assert 0 <= i0 <= nbeta - 2 and -1e-9 <= fr <= 1.0 + 1e-9
            assert (i0 + fr) * dh == pytest.approx(abs(beta), abs=1e-9) or \
                abs(abs(beta) - math.pi) < 1e-9 and (i0 + fr) * dh == pytest.approx(math.pi, abs=1e-9)
            if abs(beta) > 1e-9 and abs(abs(beta) - math.pi) > 1e-9:
                assert sgn == math.copysign(1.0, beta)
