"""The MuJoCo simulator with the seakeeping components, in regular waves, against the frequency-domain
RAO computed from the same database (:func:`vtrials.physics.seakeeping.rao.rao`, with the vessel's own
rigid-body mass matrix, the ship file's restoring and its roll damping as B_visc).

The simulated ship is free in all six DOFs (maneuvering model for surge, sway, yaw). Excitation is
applied to heave, roll and pitch only (the RAO holds the horizontal DOFs), and the response is taken
relative to the wave elevation at the ship's actual position (the ship drifts slowly under second-order
forces that linear theory leaves out: a small drift changes the phase of the wave at the ship).

Head seas (first test): heave and pitch against the RAO with the horizontal DOFs held.

Head, bow (135°), beam (90°) and quartering (45°) seas, zero and forward speed (second test): heave,
roll and pitch against the RAO of the same coupled six-DOF system the simulator integrates
(:mod:`vtrials.physics.seakeeping.linearize`: the maneuvering model's sway and yaw, linearised by
finite differences of the force kernels, the autopilot and steering gear at forward speed, the
database's radiation in heave/roll/pitch, the viscous roll damping harmonically linearised), with
the wave excitation on all six DOFs.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from vtrials.physics.environment.waves import elevation_at
import dataclasses

from vtrials.physics import steering as H
from vtrials.physics.seakeeping import linearize as LZ
from vtrials.physics.seakeeping import rao as rao_mod
from vtrials.physics.seakeeping.database import load_database
from vtrials.physics.seakeeping.timedomain import memory_model
from vtrials.physics.seakeeping.timedomain import flow_geometry, roll_damping_of, seakeeping_vessel
from vtrials.physics.simulator import ShipState, Simulator
from vtrials.physics.vessel import load_vessel, model_dir

DT = 0.02
AMP = 0.05


@pytest.fixture(scope="module")
def patrol():
    ves = load_vessel("patrol51")
    db = load_database(model_dir("patrol51") / "hydro" / "patrol51_hydro.nc")
    return ves, db, memory_model(db)


def _run(ves, db, model, omega, mu, speed, t_end, dt=DT):
    comp = np.array([[AMP, omega, omega ** 2 / db.g, math.cos(mu), math.sin(mu), 0.3]])
    start = ShipState(shaft_rps=(0.0,) * len(ves.shafts))
    if speed > 0.0:
        calm = Simulator(ves, 1, dt)
        start = calm.self_propulsion(0, speed)
    v2, _ = seakeeping_vessel(ves, db, comp, dt, model=model, excitation_dofs=(2, 3, 4))
    sim = Simulator(v2, 1, dt)
    sim.set_state(0, start)
    for k, n in enumerate(start.shaft_rps):
        sim.set_shaft_order(0, n, shaft=k)
    sim.step(int(round(t_end / dt)))
    tr = sim.truth()[:, 0, :]
    return comp, {c: tr[:, sim.rec_names.index(c)] for c in ("t", "x", "y", "z", "roll", "pitch", "u")}


# At forward speed the RAO carries the time-domain model's one speed term (body_axes_added_mass: A∞
# multiplies body-axis accelerations, w = ż + Uθ). Without it: 3.3 %, 14 % and 49 % heave error at
# ω = 0.5, 0.7, 1.0 rad/s and 5 m/s; with it 0.5 %, 1.2 %, 2.8 % (pitch 0.6 %, 1.5 %, 3.2 %).
@pytest.mark.parametrize("omega,speed", [(0.5, 0.0), (0.7, 0.0), (1.0, 0.0), (0.5, 5.0), (0.7, 5.0), (1.0, 5.0)])
def test_head_seas_heave_pitch_match_rao(patrol, omega, speed):
    ves, db, model = patrol
    mu = math.pi                       # waves travelling south; the ship heads north: β = π
    comp, r = _run(ves, db, model, omega, mu, speed, 150.0)
    t = r["t"]
    u_mean = float(np.mean(r["u"][t > 100.0]))
    we = float(rao_mod.encounter_frequency(omega, math.pi, u_mean, db.g))
    last = t > t[-1] - 4.0 * 2.0 * math.pi / we
    basis = np.stack([np.cos(we * t[last]), -np.sin(we * t[last])], axis=1)
    eta = np.array([elevation_at(comp, x, y, tt) for x, y, tt in zip(r["x"][last], r["y"][last], t[last])])
    ce = np.linalg.lstsq(basis, eta, rcond=None)[0]
    ce = ce[0] + 1j * ce[1]
    bv = np.zeros((6, 6))
    bv[3, 3] = float(roll_damping_of(ves, db).B1(u_mean))     # no roll in head seas: not exercised
    kw = dict(M=ves.M_RB, C=ves.restoring_matrix(), B_visc=bv, body_axes_added_mass=True)
    w_dense = np.linspace(0.3, 2.5, 120)
    peak = np.abs(rao_mod.rao(db, w_dense, math.pi, u_mean, (2, 3, 4), **kw)).max(axis=0)
    fd = rao_mod.rao(db, [omega], math.pi, u_mean, (2, 3, 4), **kw)[0]
    for d, col in ((2, "z"), (4, "pitch")):
        assert abs(fd[d]) >= 0.10 * peak[d]
        y = r[col][last]
        c = np.linalg.lstsq(basis, y - y.mean(), rcond=None)[0]
        td = (c[0] + 1j * c[1]) / ce
        err = abs(td - fd[d]) / abs(fd[d])
        assert err <= 0.05, (omega, speed, col, td, fd[d], err)


def _complex_response(r, comp, we, col):
    """Complex amplitude of ``col`` per unit wave amplitude at the ship, over the last 6 periods."""
    t = r["t"]
    last = t > t[-1] - 6.0 * 2.0 * math.pi / we
    basis = np.stack([np.cos(we * t[last]), -np.sin(we * t[last])], axis=1)
    eta = np.array([elevation_at(comp, x, y, tt) for x, y, tt in zip(r["x"][last], r["y"][last], t[last])])
    ce = np.linalg.lstsq(basis, eta, rcond=None)[0]
    y = r[col][last]
    c = np.linalg.lstsq(basis, y - y.mean(), rcond=None)[0]
    return (c[0] + 1j * c[1]) / (ce[0] + 1j * ce[1])


# The time step's own error: the same regular-wave response at dt 0.02 s and 0.01 s. The radiation
# memory's state is advanced over the step just completed by that step's mean (secant) velocity before
# its force is taken, so the memory is centred in time; when the force was taken before the advance, it
# lagged the motion by a whole step and heave at ω = 2 rad/s led the RAO by 3.4° at dt 0.02 s and 2.0° at
# 0.01 s (2.3 % complex difference between the two); now 0.74° and 0.72° (the radiation fit's own error).
@pytest.mark.parametrize("col", ["z", "pitch"])
def test_response_converges_in_the_time_step(patrol, col):
    ves, db, model = patrol
    omega = 2.0
    out = []
    for dt in (0.02, 0.01):
        comp, r = _run(ves, db, model, omega, math.pi, 0.0, 80.0, dt=dt)
        out.append(_complex_response(r, comp, omega, col))
    diff = abs(out[0] - out[1]) / abs(out[1])
    assert diff <= 0.004, (col, out, diff)


def test_radiation_states_refuse_another_step(patrol):
    """The memory is discretised for one step: a simulator with another step stops on a non-finite force."""
    ves, db, model = patrol
    comp = np.array([[AMP, 0.7, 0.7 ** 2 / db.g, -1.0, 0.0, 0.0]])
    v2, _ = seakeeping_vessel(ves, db, comp, DT, model=model)
    sim = Simulator(v2, 1, 2 * DT)
    sim.set_state(0, ShipState(shaft_rps=(0.0,) * len(ves.shafts)))
    sim.evaluate()
    assert np.all(np.isnan(sim.comp_w[0, sim.comp_names.index("radiation")]))


# ---- coupled six-DOF RAO: the maneuvering model's sway and yaw are free ----------------------------
#
# Wave amplitude 2 mm and step 0.01 s (both stated): the free sway and yaw of a ship at zero speed have
# neither restoring nor (linear) damping, so the second-order mean forces (from the excitation at the
# displaced position) make it drift and turn as a² t²; at 2 mm the heading changes by < 0.003 rad in
# 400 s, at 1 cm by 0.05–0.4 rad. When the radiation memory's force was taken before its state was
# advanced, it lagged the kinematics by a step, which turns ω dt of its ω(A − A∞) part into damping:
# the lightly damped patrol51 roll peak (beam seas, ω 0.86 rad/s, with the earlier stand-in hull and BC93's
# sway added mass) came out at 0.901, 0.963 and 0.986
# of this reference at dt = 0.05, 0.02 and 0.01 s. With the memory centred in time: 1.004, 1.008 and
# 1.008 (heave 0.998, pitch 0.999–1.000 at all three; measured with this test's set-up, 2 mm waves,
# 400 s, at each step). The scenarios run at 0.05 s: their roll was 10 % too small at resonance.
# The start: the free sway and yaw keep any momentum of the start-up transient for ever (a constant
# drift and turn), so the ship starts with the sway velocity and yaw rate whose sway and yaw momentum
# equal those of the reference's steady state at t = 0 (p, w, q cannot be set: they start at zero).
DT_C = 0.01
AMP_C = 0.002
COUPLED_CASES = [  # (beta_deg, U [m/s], omega [rad/s])
    (90.0, 0.0, 0.3), (90.0, 0.0, 0.6), (90.0, 0.0, 1.14), (90.0, 0.0, 1.2), (135.0, 0.0, 0.86), (45.0, 0.0, 0.86),
    (180.0, 0.0, 0.7),
    (90.0, 5.0, 0.86), (135.0, 5.0, 0.6), (45.0, 5.0, 0.86), (180.0, 5.0, 0.7),
]


@pytest.fixture(scope="module")
def linearised(patrol):
    ves, db, model = patrol
    rd = roll_damping_of(ves, db)
    v0, _ = seakeeping_vessel(ves, db, np.zeros((0, 6)), DT_C, model=model, drift=False)
    out = {}
    for U in sorted({c[1] for c in COUPLED_CASES}):
        start = ShipState(shaft_rps=(0.0,) * len(ves.shafts))
        if U > 0.0:
            start = Simulator(ves, 1, DT_C).self_propulsion(0, U)
        _, Jv, Je, Jd, Jf = LZ.force_jacobians(v0, start, DT_C, with_flow=True)
        Jc = LZ.coriolis_jacobian(v0, start.u)
        ap = ves.autopilot
        auto = (*ap.pid, float(ves.steering[0, 2])) \
            if U > 0.0 else None
        out[U] = (start, Jv, Je, Jc, Jd, auto, Jf)
    return rd, out


@pytest.mark.parametrize("beta_deg,speed,omega", COUPLED_CASES)
def test_coupled_heave_roll_pitch_match_rao(patrol, linearised, beta_deg, speed, omega):
    ves, db, model = patrol
    rd, lin = linearised
    start, Jv, Je, Jc, Jd, auto, Jf = lin[speed]
    beta = math.radians(beta_deg)
    kw = dict(Jd=Jd, autopilot=auto, Jf=Jf, flow=flow_geometry(ves))   # waves' flow, as in the time domain
    comp = np.array([[AMP_C, omega, omega ** 2 / db.g, math.cos(beta), math.sin(beta), 0.3]])
    v2, _ = seakeeping_vessel(ves, db, comp, DT_C, model=model, drift=False)
    we0 = float(rao_mod.encounter_frequency(omega, beta, start.u, db.g))
    ss = LZ.coupled_rao(v2, db, [omega], beta, start.u, Jv, Je, Jc, rd, AMP_C, **kw)[0] * AMP_C * np.exp(0.3j)
    E = np.zeros((6, 6))
    E[1, 5], E[2, 4] = -1.0, 1.0
    nu_ss = ((1j * we0 * np.eye(6) + start.u * E) @ ss).real
    M = v2.M_RB + v2.M_A
    hz = (1, 5)
    v_r = np.linalg.solve(M[np.ix_(hz, hz)], (M @ nu_ss)[list(hz)])   # same sway/yaw momentum, p = w = q = 0
    sim = Simulator(v2, 1, DT_C)
    sim.set_state(0, dataclasses.replace(start, v=float(v_r[0]), r=float(v_r[1])))
    for k, n in enumerate(start.shaft_rps):
        sim.set_shaft_order(0, n, shaft=k)
    if auto is not None:
        ap = ves.autopilot
        sim.set_helm(0, [(H.HEADING, 0.0, math.radians(ap.rudder_limit_deg), auto[0], auto[1], auto[2], 0.0)])
    sim.step(int(round(400.0 / DT_C)))
    tr = sim.truth()[:, 0, :]
    r = {c: tr[:, sim.rec_names.index(c)] for c in ("t", "x", "y", "z", "roll", "pitch", "heading", "u")}
    t = r["t"]
    last = t > t[-1] - 4.0 * 2.0 * math.pi / abs(we0)
    hd = float(np.mean(r["heading"][last]))
    assert abs(hd) < 0.05, hd         # near the nominal heading (the reference takes the measured mean)
    u_mean = float(np.mean(r["u"][last]))
    we = float(rao_mod.encounter_frequency(omega, beta - hd, u_mean, db.g))
    basis = np.stack([np.cos(we * t[last]), -np.sin(we * t[last])], axis=1)
    eta = np.array([elevation_at(comp, x, y, tt) for x, y, tt in zip(r["x"][last], r["y"][last], t[last])])
    ce = np.linalg.lstsq(basis, eta, rcond=None)[0]
    ce = ce[0] + 1j * ce[1]
    fd = LZ.coupled_rao(v2, db, [omega], beta - hd, u_mean, Jv, Je, Jc, rd, AMP_C, **kw)[0]
    w_dense = np.linspace(0.3, 2.5, 111)
    w_dense = w_dense[np.abs(rao_mod.encounter_frequency(w_dense, beta, u_mean, db.g)) > 0.15 * w_dense]
    peak = np.abs(LZ.coupled_rao(v2, db, w_dense, beta - hd, u_mean, Jv, Je, Jc, rd, AMP_C, **kw)).max(axis=0)
    checked = 0
    for d, col in ((2, "z"), (3, "roll"), (4, "pitch")):
        long_wave_roll = d == 3 and omega < 0.7 and beta_deg == 90.0 and speed == 0.0
        if (abs(fd[d]) < 0.10 * peak[d] and not long_wave_roll) or (d == 3 and beta_deg == 180.0):
            continue                       # below 10 % of the peak (issue 10), or no roll in head seas;
            # roll in long beam waves is checked however small (the long-wave limit below rests on it)
        checked += 1
        y = r[col][last]
        bb = np.column_stack([basis, np.ones(y.size)])
        c = np.linalg.lstsq(bb, y, rcond=None)[0]
        td = (c[0] + 1j * c[1]) / ce
        err = abs(td - fd[d]) / abs(fd[d])
        print(f"beta {beta_deg} U {u_mean:.2f} omega {omega} {col}: |td| {abs(td):.4g} |fd| {abs(fd[d]):.4g} err {err:.4f}")
        # roll in long beam waves is the small remainder of two large moments (the Froude–Krylov moment
        # and that of the sway-coupled inertia) that cancel to the wave slope, so a memory fit error in the
        # sway–roll A24(ω) − A∞ shows up several-fold: with the first admissible fits (1–2 % of the pair's
        # peak) roll was 6.9 % off at 0.3 rad/s; with the most accurate ones (radiation.fit_radiation
        # ``extra``) 1.2 % at 0.3, 1.3 % at 0.6, 2.8 % at the resonance 1.14
        assert err <= 0.05, (beta_deg, speed, omega, col, td, fd[d], err)
    assert checked >= 2


# The long-wave limit (an analytic reference for the whole model, not only its integration): a ship free to
# sway, with no sway restoring, in a beam wave much longer than its beam moves with the water — sway
# amplitude a, heave amplitude a — and heels with the wave slope k a, amplified quasi-statically by
# 1/(1 − (ω/ω_n)²). This holds only when the wave excitation (Froude–Krylov of the meshed hull, with the
# diffraction that carries its A22(ω), A42(ω)) meets the same hull in the dynamics: the same waterplane
# (BM_T) in the restoring and the same sway and sway–roll added mass. Measured (coupled RAO, zero speed,
# ω 0.2 / 0.25 / 0.3 rad/s, λ 1540 / 986 / 685 m): roll ÷ slope 1.081 / 1.120 / 1.126 against the
# quasi-static 1.032 / 1.051 / 1.074; sway 0.992 / 1.014 / 1.001; heave 1.000 / 0.999 / 1.000.
# Before the stand-in hull was fitted to BC93's KM and the sway added mass taken from the database,
# roll ÷ slope was 4.7–5.0 (2.8–2.9 with the refitted hull but BC93's Y_v̇ and antisymmetric Y_ṗ = −K_v̇,
# 1.5–1.6 with BC93's Y_v̇ alone). Below 0.2 rad/s the database has no data (its excitation is held at
# its lowest frequency), so the test stops there.
LONG_WAVES = (0.2, 0.25, 0.3)


def test_long_beam_waves_sway_with_the_water_and_heel_with_the_slope(patrol, linearised):
    ves, db, model = patrol
    rd, lin = linearised
    start, Jv, Je, Jc, Jd, auto, _ = lin[0.0]
    v0, _ = seakeeping_vessel(ves, db, np.zeros((0, 6)), DT_C, model=model, drift=False)
    w = np.array(LONG_WAVES)
    r = LZ.coupled_rao(v0, db, w, math.pi / 2, 0.0, Jv, Je, Jc, rd, AMP_C)
    slope = w ** 2 / db.g
    heel = np.abs(r[:, 3]) / slope
    # the simulated ship's own roll natural frequency: the peak of the same RAO
    wd = np.linspace(0.6, 2.0, 281)
    wn = float(wd[np.argmax(np.abs(LZ.coupled_rao(v0, db, wd, math.pi / 2, 0.0, Jv, Je, Jc, rd, AMP_C)[:, 3]))])
    quasi_static = 1.0 / (1.0 - (w / wn) ** 2)
    print("roll/slope", heel, "quasi-static", quasi_static, "omega_n", wn)
    print("sway", np.abs(r[:, 1]), "heave", np.abs(r[:, 2]))
    assert np.all(np.abs(heel / quasi_static - 1.0) < 0.10), (heel, quasi_static)
    assert np.all(np.abs(np.abs(r[:, 1]) - 1.0) < 0.03), np.abs(r[:, 1])
    assert np.all(np.abs(np.abs(r[:, 2]) - 1.0) < 0.01), np.abs(r[:, 2])
    # in phase with the slope (starboard down as the crest passes to starboard), to a few degrees
    lag = np.degrees(np.angle(r[:, 3] / (1j * slope)))
    assert np.all(np.abs(lag) < 5.0), lag
