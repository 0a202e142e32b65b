"""Heave, roll and pitch decay: the simulated periods and decay rates against linear theory.

Theory: the eigenvalues of M ẍ + B ẋ + C x = 0 with M = M_RB + M_A (rigid body from MuJoCo's own
mass matrix, added mass from the model file), C the hydrostatic stiffness from displacement,
GM_T, GM_L and the waterplane, and B the documented damping. Roll is released from a heel
angle (a classic decay test; it couples only to the zero-stiffness sway and yaw). Heave and
pitch are coupled through x_G, so they are released in their own mode shapes, which makes each
decay a single damped oscillation whose period can be measured without ambiguity.
The simulated record is fitted with A e^(−σt) cos(ωt + φ) + c.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.linalg import eig
from scipy.optimize import curve_fit

from vtrials.physics.simulator import ShipState, Simulator
from vtrials.physics.vessel import load_vessel


def linear_modes(v):
    M = v.M_RB + v.M_A
    C = v.restoring_matrix()
    B = np.diag([0.0, 0.0, *v.B_lin, 0.0])
    A = np.block([[np.zeros((6, 6)), np.eye(6)], [-np.linalg.solve(M, C), -np.linalg.solve(M, B)]])
    lam, V = eig(A)
    return [(lam[k], V[:, k]) for k in range(12) if lam[k].imag > 1e-9]


def damped(t, a, s, w, p, c):
    return a * np.exp(-s * t) * np.cos(w * t + p) + c


@pytest.mark.parametrize("ship,dt", [("kvlcc2_l7", 0.005), ("kvlcc2", 0.02)])
@pytest.mark.parametrize("dof,column", [(2, "z"), (3, "roll"), (4, "pitch")])
def test_decay_period_matches_linear_theory(ship, dt, dof, column):
    v = load_vessel(ship)
    modes = linear_modes(v)
    lam, vec = max(modes, key=lambda lv: abs(lv[1][dof]) / np.linalg.norm(lv[1][:6]))
    T_theory = 2 * math.pi / lam.imag
    amp = {2: 0.02 * v.particulars.draught, 3: math.radians(3.0), 4: math.radians(0.3)}[dof]
    sim = Simulator(v, 1, dt)
    if dof == 3:
        sim.set_state(0, ShipState(roll=amp))
    else:
        x = (vec[:6] / vec[dof]).real * amp
        xd = (lam * vec[:6] / vec[dof]).real * amp
        sim.set_state(0, ShipState(x=x[0], y=x[1], z=x[2], roll=x[3], pitch=x[4], heading=x[5],
                                   u=xd[0], v=xd[1], r=xd[5]))
        sim.qvel[0, 2:5] = xd[2:5]
    sim.step(int(4 * T_theory / dt))
    tr = sim.truth()
    t = tr[:, 0, 0]
    y = tr[:, 0, sim.rec_names.index(column)]
    p, _ = curve_fit(damped, t, y, p0=[amp, -lam.real, lam.imag, 0.0, 0.0])
    T_sim = 2 * math.pi / p[2]
    assert T_sim == pytest.approx(T_theory, rel=0.02)      # acceptance bound
    assert T_sim == pytest.approx(T_theory, rel=0.003)     # what the model actually achieves
    assert p[1] == pytest.approx(-lam.real, rel=0.03)      # decay rate from the documented damping


def test_uncoupled_roll_period_formula():
    """The textbook T_φ = 2π √((I_xx + A_44)/(ρ g ∇ GM_T)) about the centre of gravity is within 2 % of
    the coupled roll period for both KVLCC2 models (the coupling to free sway is weak)."""
    for ship in ("kvlcc2_l7", "kvlcc2"):
        v = load_vessel(ship)
        lam, _ = max(linear_modes(v), key=lambda lv: abs(lv[1][3]) / np.linalg.norm(lv[1][:6]))
        Ixx = v.mass * v.inertia.k_xx ** 2 * (1 + v.added_mass.roll_ratio)
        T = 2 * math.pi * math.sqrt(Ixx / (v.particulars.water_density * 9.80665 * v.particulars.displacement
                                           * v.hydrostatics.GM_T))
        assert 2 * math.pi / lam.imag == pytest.approx(T, rel=0.02)


def test_restoring_signs_and_equilibrium():
    """At rest in calm water the hull floats in equilibrium; displaced, it is pushed back."""
    v = load_vessel("kvlcc2_l7")
    sim = Simulator(v, 1, 0.01)
    sim.set_state(0, ShipState())
    assert np.abs(sim.evaluate()[0]).max() < 1e-12
    for field, idx in (("z", 2), ("roll", 3), ("pitch", 4)):
        sim.set_state(0, ShipState(**{field: 0.01}))
        acc = sim.evaluate()[0]
        assert acc[idx] < 0, field
