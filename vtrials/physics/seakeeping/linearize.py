"""Linearisation of a seakeeping vessel's force model about steady straight motion, and the RAO of the
same coupled six-DOF system the simulator integrates (maneuvering model in surge, sway and yaw).

The simulator's ship is free in all six DOFs: surge, sway and yaw carry the maneuvering model (its
added mass, hull, propeller and rudder forces, no radiation memory), heave, roll and pitch the
database's A∞ and radiation memory, the restoring of the hydrostatics component and the viscous roll
damping. A frequency-domain reference for roll in oblique and beam seas must therefore hold the same
horizontal dynamics, not the BEM sway/yaw of :func:`.rao.rao` nor held horizontal DOFs.

Construction (independent of the time integration): the force components' sum τ (all but the wave
components) is differentiated by central finite differences of the kernels about the operating point
(speed U on heading 0, zero angles): J_ν = ∂τ/∂ν (body velocities), J_η = ∂(τ + τ_g)/∂(z, φ, θ)
(τ_g the weight, computed here). The rigid-body and added-mass Coriolis–centripetal vectors
(Kirchhoff form, Fossen 2011 Thm 3.2, written out again here) are differentiated likewise. Linear
kinematics about U (Fossen 2011 §7.5): ẏ = v + Uψ, ż = w − Uθ, φ̇ = p, θ̇ = q, ψ̇ = r, so with
η̂ = (x, y, z, φ, θ, ψ) the body velocities are ν̂ = T η̂, T = iω_e I + U E (E_vψ = −1, E_wθ = +1).
The radiation memory adds −K̂(ω_e) ξ̂ with K̂ = B(ω_e) + iω_e (A(ω_e) − A∞) (Ogilvie 1964) over its
DOFs (sway, heave, roll, pitch), its inputs ξ̂ being the body sway velocity v̂ = iω_e ŷ − U ψ̂, the world
vertical velocity iω_e ẑ and the roll and pitch rates iω_e φ̂, iω_e θ̂. Quadratic roll damping: harmonic equivalent linearisation B_eq = (8/3π) ω_e φ_a B₂ at the
response amplitude (iterated). Then

    [iω_e (M_RB + M_A) T − J_ν T + C_ν T − J_η + iω_e K̂ + iω_e B_eq] η̂ = (X(ω, β) + J_f f̂(ω, β)) a,

J_f f̂ the maneuvering forces of the waves' flow (cross-flow, its gradient, surface heel: the maneuvering
components act on the motion relative to it, :mod:`vtrials.physics.forces.wave_flow`), J_f = ∂τ/∂(v_w,
r_w, φ_w) by the same central differences.
"""

from __future__ import annotations

import math

import numpy as np

from vtrials.physics.forces import context as L
from vtrials.physics.forces import wave_flow
from vtrials.physics.seakeeping.radiation import extended_coefficients
from vtrials.physics.seakeeping.rao import encounter_frequency

WAVE_COMPONENTS = ("radiation", "wave_excitation", "wave_drift", "wave_flow")


def kirchhoff_coriolis(M: np.ndarray, nu: np.ndarray, munk: bool = True) -> np.ndarray:
    """C(ν)ν for a 6×6 inertia matrix M (Fossen 2011, Handbook of Marine Craft Hydrodynamics, Thm 3.2):
    with P = M₁₁ν₁ + M₁₂ω, Λ = M₂₁ν₁ + M₂₂ω: [ω × P; ω × Λ + ν₁ × P] (ν₁ × P dropped if not munk)."""
    nu1, om = nu[:3], nu[3:]
    h = M @ nu
    P, Lm = h[:3], h[3:]
    out = np.concatenate([np.cross(om, P), np.cross(om, Lm)])
    if munk:
        out[3:] += np.cross(nu1, P)
    return out


def _set(sim, base_q, base_v, eta, nu, delta=0.0):
    """Place ship 0: position/angles perturbed by eta (x, y, z, φ, θ, ψ), body velocities nu, all
    rudders at angle delta [rad]."""
    from vtrials.physics.simulator import euler_to_quat
    from vtrials.physics import dynamics as DY
    q = sim.qpos[0]
    v = sim.qvel[0]
    q[:] = base_q
    v[:] = base_v
    q[0:3] = eta[0:3]
    quat = euler_to_quat(eta[3], eta[4], eta[5])
    q[3:7] = quat
    for k in range(sim.nr):
        q[int(sim.steer[k, 3])] = delta
    R = np.zeros(9)
    DY.quat_to_mat(*quat, R)
    v[0:3] = R.reshape(3, 3) @ nu[:3]
    v[3:6] = nu[3:]
    return R


def force_jacobians(vessel, start, dt: float = 0.02, eps_v: float = 1e-4, eps_a: float = 1e-5,
                    with_flow: bool = False):
    """(τ0, J_ν, J_η, R_η) of a seakeeping vessel at ``start`` (a :class:`~vtrials.physics.simulator.ShipState`
    with speed u, zero angles and the shaft speeds): the sum of its force components other than the wave
    components, by central differences of the kernels (via ``Simulator.evaluate``: forces at a state, no
    time step). J_ν (6×6) per body velocity, J_η (6×6) per (x, y, z, φ, θ, ψ) including the weight,
    J_δ (6,) per rudder angle (all rudders together). Returns (τ0, J_ν, J_η, J_δ), and with ``with_flow``
    also J_f (6×3) per (v_w, r_w, φ_w), the waves' flow the maneuvering components see
    (:mod:`vtrials.physics.forces.wave_flow`)."""
    from vtrials.physics.simulator import Simulator
    sim = Simulator(vessel, 1, dt)
    sim.set_state(0, start)
    base_q = sim.qpos[0].copy()
    base_v = sim.qvel[0].copy()
    keep = [k for k, n in enumerate(sim.comp_names) if n not in WAVE_COMPONENTS] + [len(sim.comp_names)]
    nu0 = np.array([start.u, 0.0, 0.0, 0.0, 0.0, 0.0])
    eta0 = np.zeros(6)
    mg = vessel.mass * 9.80665
    rG = vessel.r_G

    def tau(eta, nu, delta=0.0, flow=(0.0, 0.0, 0.0)):
        R = _set(sim, base_q, base_v, eta, nu, delta)
        sim.aux[0, L.AUX_FLOW:L.AUX_FLOW + 3] = flow     # the waves' flow (no wave_flow component here)
        sim.evaluate()
        t = sim.comp_w[0, keep].sum(axis=0)
        g = mg * R[6:9]                              # weight in body axes (world z down)
        return t + np.concatenate([g, np.cross(rG, g)])

    t0 = tau(eta0, nu0)
    Jv = np.zeros((6, 6))
    Je = np.zeros((6, 6))
    for j in range(6):
        d = np.zeros(6)
        d[j] = eps_v
        Jv[:, j] = (tau(eta0, nu0 + d) - tau(eta0, nu0 - d)) / (2 * eps_v)
        d = np.zeros(6)
        d[j] = eps_a
        Je[:, j] = (tau(eta0 + d, nu0) - tau(eta0 - d, nu0)) / (2 * eps_a)
    Jd = (tau(eta0, nu0, eps_a) - tau(eta0, nu0, -eps_a)) / (2 * eps_a)
    Jf = np.zeros((6, 3))
    for j, e in enumerate((eps_v, eps_v, eps_a)):
        f = np.zeros(3)
        f[j] = e
        Jf[:, j] = (tau(eta0, nu0, 0.0, f) - tau(eta0, nu0, 0.0, -f)) / (2 * e)
    _set(sim, base_q, base_v, eta0, nu0)
    sim.aux[0, L.AUX_FLOW:L.AUX_FLOW + 3] = 0.0
    if with_flow:
        return t0, Jv, Je, Jd, Jf
    return t0, Jv, Je, Jd


def coriolis_jacobian(vessel, U: float, eps: float = 1e-4) -> np.ndarray:
    """∂/∂ν of C_RB(ν)ν + C_A(ν)ν at ν = (U, 0, …) as the dynamics apply them (added-mass part per the
    ship file's ``coriolis``: none, no_munk or kirchhoff)."""
    mode = vessel.added_mass.coriolis

    def c(nu):
        out = kirchhoff_coriolis(vessel.M_RB, nu, True)
        if mode != "none":
            out = out + kirchhoff_coriolis(vessel.M_A, nu, mode == "kirchhoff")
        return out

    nu0 = np.array([U, 0, 0, 0, 0, 0.0])
    J = np.zeros((6, 6))
    for j in range(6):
        d = np.zeros(6)
        d[j] = eps
        J[:, j] = (c(nu0 + d) - c(nu0 - d)) / (2 * eps)
    return J


def _memory_dofs_of(vessel) -> list[int]:
    """The DOFs of ``vessel``'s radiation memory component (read from its packed parameters; none if it
    has no memory)."""
    for c in vessel.components:
        if c.type == "radiation":
            m = int(c.params[1])
            return [int(d) for d in c.params[2:2 + m]]
    return []


def coupled_rao(vessel, db, omega, beta: float, U: float, Jv, Je, Jc, roll_damping=None, amplitude: float = 0.0,
                iters: int = 30, excitation_dofs=(0, 1, 2, 3, 4, 5), Jd=None, autopilot=None,
                roll_beq=None, memory_dofs=None, Jf=None, flow=None) -> np.ndarray:
    """Complex RAO (nω, 6) of (x, y, z, φ, θ, ψ) per metre of wave amplitude of the coupled system above.

    vessel: the seakeeping vessel (its M_RB and M_A, i.e. A∞ in heave/roll/pitch); Jv, Je, Jc from
    :func:`force_jacobians` and :func:`coriolis_jacobian`; roll_damping: its quadratic part B₂(U) is
    linearised at the roll amplitude ``amplitude`` × |RAO_φ| (iterated); its linear part is already in Jv.
    ``excitation_dofs``: the DOFs the wave excitation acts on (as the wave_excitation component's mask).
    ``autopilot`` = (K_p, K_i [1/s], K_d [s], T [s]) with ``Jd``: the heading autopilot of
    :mod:`vtrials.physics.steering` (δ_c = −(K_p ψ + K_i ∫ψ + K_d r)) through the steering gear's
    first-order follow-up δ̇ = (δ_c − δ)/T (rate limit not reached), i.e. a rudder force
    J_δ δ̂ with δ̂ = −(K_p + K_i/(iω_e) + K_d iω_e) ψ̂ / (1 + iω_e T).
    ``roll_beq``: a fixed equivalent linear roll damping [N m s] added instead of the harmonic
    linearisation of B₂ (e.g. the stochastic one for irregular seas). ``memory_dofs``: the DOFs of the
    radiation memory (default: those of the vessel's radiation component). ``Jf`` (from
    :func:`force_jacobians` ``with_flow``) with ``flow`` = (length, depth) of
    :func:`.timedomain.flow_geometry`: the maneuvering forces see the waves' flow, an excitation
    J_f (v̂_w, r̂_w, φ̂_w) (:func:`vtrials.physics.forces.wave_flow.flow_rao`)."""
    omega = np.atleast_1d(np.asarray(omega, dtype=float))
    we = encounter_frequency(omega, beta, U, db.g)
    A, B = extended_coefficients(db.omega, db.A, db.B, db.A_inf, np.abs(we))
    X = db.excitation(beta)
    Xw = np.array([[np.interp(w, db.omega, X[:, j].real) + 1j * np.interp(w, db.omega, X[:, j].imag)
                    for j in range(6)] for w in omega])
    mask = np.zeros(6)
    mask[list(excitation_dofs)] = 1.0
    Xw = Xw * mask
    if Jf is not None:
        Xw = Xw + (np.asarray(Jf) @ wave_flow.flow_rao(omega, beta, flow[0], flow[1], db.g)).T
    M = vessel.M_RB + vessel.M_A
    E = np.zeros((6, 6))
    E[1, 5] = -1.0
    E[2, 4] = 1.0
    mem = list(memory_dofs) if memory_dofs is not None else _memory_dofs_of(vessel)
    Kh_rows = np.ix_(mem, mem)
    b2 = 0.0 if roll_damping is None else float(roll_damping.B2(U))
    out = np.zeros((omega.size, 6), dtype=complex)
    for n, w in enumerate(we):
        T = 1j * w * np.eye(6) + U * E
        Z = 1j * w * M @ T - Jv @ T + Jc @ T - Je
        if autopilot is not None:
            kp, ki, kd, tg = autopilot
            Z[:, 5] += np.asarray(Jd) * (kp + ki / (1j * w) + kd * 1j * w) / (1.0 + 1j * w * tg)
        Kh = B[n] + 1j * w * (A[n] - db.A_inf)
        Tin = 1j * w * np.eye(6)          # the memory's inputs: heave as ż, roll and pitch rates,
        Tin[1] = T[1]                     # sway as the body sway velocity v = ẏ − Uψ
        Z[mem] += Kh[Kh_rows] @ Tin[mem]
        if roll_beq is not None:
            Zn = Z.copy()
            Zn[3, 3] += 1j * w * roll_beq
            out[n] = np.linalg.solve(Zn, Xw[n])
            continue
        phi_a = 0.0
        for _ in range(iters):
            Zn = Z.copy()
            Zn[3, 3] += 1j * w * 8.0 / (3.0 * math.pi) * abs(w) * phi_a * b2
            r = np.linalg.solve(Zn, Xw[n])
            new = amplitude * abs(r[3])
            if abs(new - phi_a) <= 1e-10 * max(new, 1e-12):
                break
            phi_a = 0.5 * (phi_a + new) if _ > 5 else new
        out[n] = r
    return out
