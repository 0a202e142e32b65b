"""A force component added from outside the package, with an internal state, without touching the
step kernel: a body-frame surge force that follows its target through a first-order lag.

    F(t) = F₀ (1 − e^{−t/τ}),   (m + m_x) u̇ = F   →   u(t) = F₀/(m + m_x) · (t − τ (1 − e^{−t/τ}))

for a ship with no other force (gravity off, so nothing else acts; surge, sway and yaw free) starting
at rest.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np
import pytest

from vtrials.physics.forces import context as L
from vtrials.physics.forces.registry import Component, register
from vtrials.physics.simulator import ShipState, Simulator
from vtrials.physics.vessel import load_vessel

P_TARGET, P_TAU = 0, 1


@nb.njit(cache=True)
def lagged_surge_force(p, s, env, ctx, aux, w):
    """Surge force s[0] [N] lagging towards p[0] with time constant p[1] [s] (exact over one step)."""
    for j in range(6):
        w[j] = 0.0
    w[0] = s[0]
    s[0] = p[P_TARGET] + (s[0] - p[P_TARGET]) * math.exp(-ctx[L.DT] / p[P_TAU])


LAGGED = register("test_lagged_surge_force", lagged_surge_force)

F0, TAU, DT, T_END = 2.0, 3.0, 0.01, 20.0


@pytest.fixture(scope="module")
def vessel():
    return load_vessel("kvlcc2_l7")


def _sim(vessel, n=1):
    comp = Component("push", "test_lagged_surge_force", np.array([F0, TAU]), states=np.array([0.0]))
    # 3-DOF mode: the force at the origin would otherwise also pitch the ship about G (z_G ≠ 0)
    sim = Simulator(vessel, n, DT, components=[comp], gravity=0.0, planar=True)
    for i in range(n):
        sim.set_state(i, ShipState())
    return sim


def test_lagged_force_matches_the_analytic_response(vessel):
    sim = _sim(vessel)
    n = int(round(T_END / DT))
    sim.step(n)
    M = vessel.M_RB[0, 0] + vessel.M_A[0, 0]
    t = n * DT
    u_exact = F0 / M * (t - TAU * (1.0 - math.exp(-t / TAU)))
    # the discrete solution of the same equations (exact lag, semi-implicit Euler): Σ dt F_k / M
    a = math.exp(-DT / TAU)
    u_discrete = DT / M * F0 * sum(1.0 - a ** k for k in range(n))
    u = float(sim.qvel[0, 0])
    assert u == pytest.approx(u_discrete, rel=1e-9)
    assert u == pytest.approx(u_exact, rel=DT / TAU)  # O(dt) integration error only
    # the component's state is the lagged force at the end of the run
    assert sim.component_states(0, "push")[0] == pytest.approx(F0 * (1.0 - a ** n), rel=1e-12)
    # nothing else moved the ship
    assert abs(sim.qvel[0, 1]) < 1e-12 and abs(sim.qvel[0, 5]) < 1e-12


def test_states_are_per_ship_and_evaluation_leaves_them(vessel):
    sim = _sim(vessel, n=2)
    sim.set_component_params(1, "push", np.array([2 * F0, TAU]))
    sim.step(50)
    s0 = sim.component_states(0, "push").copy()
    s1 = sim.component_states(1, "push").copy()
    assert s1[0] == pytest.approx(2 * s0[0], rel=1e-12)
    sim.evaluate()
    sim.evaluate()
    assert np.array_equal(sim.component_states(0, "push"), s0)
    sim.set_state(0, ShipState())  # a new start resets the component's states
    assert sim.component_states(0, "push")[0] == 0.0
    assert sim.component_states(1, "push")[0] == s1[0]


def test_registry_refuses_what_it_cannot_dispatch():
    def plain(p, s, env, ctx, aux, w):
        pass

    with pytest.raises(TypeError):
        register("not_compiled", plain)
    with pytest.raises(KeyError, match="unknown force component type"):
        Component("x", "no_such_component", np.zeros(1))
