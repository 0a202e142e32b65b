"""Mean wave drift on the simulated ship, and the speed loss it causes.

* The drift component's wrench for an irregular, multi-directional set of components on a heeled,
  trimmed ship on an arbitrary heading equals Σ a² D(ω, β) from the database's own heading
  interpolation (:meth:`HydroDatabase.drift_at`), turned from the horizontal seakeeping frame into body axes.
* Self-propelled patrol51 at a fixed shaft speed (7 m/s in calm water) meets regular head waves: the
  speed loss of the full time-domain run (first-order excitation, radiation memory, drift, and the
  horizontal added-mass Coriolis terms of the A∞ block that :func:`sea_ship` adds for a hull model
  without its own) agrees within 10 % with the calm-water force balance with the drift force added
  (steady_at_order of a ship carrying the drift alone). Without those Coriolis terms the motions leave
  a spurious mean surge force of −1.0 kN here (10 % of the drift) and the ship loses 10 % more speed.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from vtrials.physics.seakeeping.database import load_database
from vtrials.physics.seakeeping.timedomain import memory_model
from vtrials.physics.seakeeping.sea_ship import sea_ship
from vtrials.physics.seakeeping.timedomain import seakeeping_vessel
from vtrials.physics.simulator import ShipState, Simulator
from vtrials.physics.vessel import load_vessel, model_dir

DT = 0.02


@pytest.fixture(scope="module")
def patrol():
    ves = load_vessel("patrol51")
    db = load_database(model_dir("patrol51") / "hydro" / "patrol51_hydro.nc")
    return ves, db, memory_model(db)


def test_drift_wrench_matches_database(patrol):
    ves, db, model = patrol
    rng = np.random.default_rng(7)
    n = 12
    w = rng.uniform(0.4, 2.8, n)
    mu = rng.uniform(-math.pi, math.pi, n)
    comp = np.stack([rng.uniform(0.1, 0.6, n), w, w ** 2 / db.g, np.cos(mu), np.sin(mu), rng.uniform(0, 6, n)], 1)
    v2, _ = seakeeping_vessel(ves, db, comp, DT, model=model)
    sim = Simulator(v2, 1, DT)
    psi, phi, theta = 0.7, 0.05, -0.02
    sim.set_state(0, ShipState(heading=psi, roll=phi, pitch=theta, shaft_rps=(0.0,) * len(ves.shafts)))
    sim.evaluate()
    got = sim.comp_w[0, sim.comp_names.index("wave_drift")]
    F = np.zeros(3)
    for a, om, _k, cm, sm, _e in comp:
        D = db.drift_at(math.atan2(sm, cm) - psi)
        F += a * a * np.array([np.interp(om, db.omega, D[:, j]) for j in range(3)])
    # seakeeping frame → world → body (z-y-x Euler angles)
    cps, sps = math.cos(psi), math.sin(psi)
    f_world = np.array([cps * F[0] - sps * F[1], sps * F[0] + cps * F[1], 0.0])
    m_world = np.array([0.0, 0.0, F[2]])

    def R(ph, th, ps):
        cx, sx, cy, sy, cz, sz = math.cos(ph), math.sin(ph), math.cos(th), math.sin(th), math.cos(ps), math.sin(ps)
        Rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
        Ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
        Rx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
        return Rz @ Ry @ Rx

    Rm = R(phi, theta, psi)
    want = np.concatenate([Rm.T @ f_world, Rm.T @ m_world])
    np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-9 * np.abs(want).max())


def test_speed_loss_in_head_seas_matches_drift_force(patrol):
    ves, db, model = patrol
    omega, amp = 1.4, 1.0                          # λ = 31 m on a 51 m ship: short waves, large drift
    comp = np.array([[amp, omega, omega ** 2 / db.g, -1.0, 0.0, 0.0]])   # travelling south: head seas
    calm = Simulator(ves, 1, DT)
    s0 = calm.self_propulsion(0, 7.0)
    rps = s0.shaft_rps
    v_drift, _ = seakeeping_vessel(ves, db, comp, DT, model=model, excitation_dofs=())
    pred = Simulator(v_drift, 1, DT).steady_at_order(0, rps)
    F = amp ** 2 * np.interp(omega, db.omega, db.drift_at(math.pi)[:, 0])
    assert F < 0.0
    v_full, _ = sea_ship(ves, db, comp, DT, model=model, mean_force="database")  # as the runners build it
    sim = Simulator(v_full, 1, DT)
    sim.set_state(0, s0)
    for k, n in enumerate(rps):
        sim.set_shaft_order(0, n, shaft=k)
    sim.step(int(round(240.0 / DT)))
    tr = sim.truth()[:, 0, :]
    t = tr[:, sim.rec_names.index("t")]
    u = tr[:, sim.rec_names.index("u")]
    u_sim = float(np.mean(u[t > 140.0]))
    loss_pred = s0.u - pred.u
    loss_sim = s0.u - u_sim
    print(f"drift {F:.0f} N, calm {s0.u:.4f} m/s, predicted loss {loss_pred:.4f}, simulated {loss_sim:.4f}")
    assert loss_pred > 0.05
    assert abs(loss_sim - loss_pred) <= 0.10 * loss_pred, (loss_pred, loss_sim)
