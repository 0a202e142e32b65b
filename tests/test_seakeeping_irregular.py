"""Irregular head seas on the simulated patrol51: RMS heave and pitch against the frequency domain.

Sea: JONSWAP H_s 1.5 m, T_p 8 s, long-crested from ahead, 120 components (realization seeded). Prediction
per component: σ² = Σ_j ½ a_j² |RAO(ω_j, β = π, U)|² with the RAO at each component's encounter
frequency (the encounter transform taken component by component, so no Jacobian is needed), and the
same from the target spectrum with the encounter Jacobian, m₀ = ∫ |RAO(ω)|² S(ω) dω (variable ω:
S_e(ω_e) dω_e = S(ω) dω; head seas map ω → ω_e one to one). The record: 2000 s after a 100 s start-up.
Requirement (issue 10): within 10 %. The RAO includes the time-domain model's speed term
(``body_axes_added_mass``, see :func:`vtrials.physics.seakeeping.rao.rao`).

Measured (U = 5 m/s, heading held by the ship's autopilot within 1e-4 rad): heave −2.3 %, pitch −4.1 %.

Zero speed is not tested here: the ship creeps ahead (≈ 0.6 m/s mean, a second-order surge force
whose source is not identified; the drift component is off and patrol51 runs without added-mass
Coriolis terms) and turns beam-on within a few hundred seconds, which neither rudder nor autopilot can
stop at that speed (a restrained-heading comparison needs a test harness that holds yaw).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from vtrials.physics.environment.waves import Waves, realize, spectrum, peak_frequency
from vtrials.physics.seakeeping import linearize as LZ
from vtrials.physics.seakeeping import rao as rao_mod
from vtrials.physics.seakeeping.database import load_database
from vtrials.physics.seakeeping.timedomain import memory_model
from vtrials.physics.seakeeping.timedomain import flow_geometry, roll_damping_of, seakeeping_vessel
from vtrials.physics import steering as H
from vtrials.physics.simulator import ShipState, Simulator
from vtrials.physics.vessel import load_vessel, model_dir

DT = 0.02
HS, TP = 1.5, 8.0
HS_BEAM = 0.3


@pytest.fixture(scope="module")
def patrol():
    ves = load_vessel("patrol51")
    db = load_database(model_dir("patrol51") / "hydro" / "patrol51_hydro.nc")
    return ves, db, memory_model(db)


@pytest.mark.parametrize("speed", [5.0])
def test_irregular_head_seas_rms(patrol, speed):
    ves, db, model = patrol
    waves = Waves(spectrum="jonswap", hs_m=HS, tp_s=TP, direction_deg=0.0, spreading="none", n_components=120)
    field = realize(waves, math.inf, np.random.default_rng(2026))
    comp = field.components
    comp = comp[(comp[:, 1] >= db.omega[0]) & (comp[:, 1] <= db.omega[-1])]
    start = ShipState(shaft_rps=(0.0,) * len(ves.shafts))
    if speed > 0.0:
        start = Simulator(ves, 1, DT).self_propulsion(0, speed)
    v2, _ = seakeeping_vessel(ves, db, comp, DT, model=model, excitation_dofs=(2, 3, 4), drift=False)
    sim = Simulator(v2, 1, DT)
    sim.set_state(0, start)
    for k, n in enumerate(start.shaft_rps):
        sim.set_shaft_order(0, n, shaft=k)
    ap = ves.autopilot             # hold the heading (a free ship is course-unstable and turns beam-on)
    if speed > 0.0:
        sim.set_helm(0, [(H.HEADING, 0.0, math.radians(ap.rudder_limit_deg), *ap.pid, 0.0)])
    sim.step(int(round(2100.0 / DT)))
    tr = sim.truth()[:, 0, :]
    t = tr[:, sim.rec_names.index("t")]
    keep = t > 100.0
    hdg = tr[keep, sim.rec_names.index("heading")]
    print(f"heading over the record: {hdg.min():.4f} .. {hdg.max():.4f} rad")
    assert np.max(np.abs(hdg)) < 0.05              # still head seas
    u_mean = float(np.mean(tr[keep, sim.rec_names.index("u")]))
    bv = np.zeros((6, 6))
    bv[3, 3] = float(roll_damping_of(ves, db).B1(u_mean))      # no roll in head seas: not exercised
    kw = dict(M=ves.M_RB, C=ves.restoring_matrix(), B_visc=bv, body_axes_added_mass=True)
    # the ship heads north, the sea comes from north: β = π for every component
    R = rao_mod.rao(db, comp[:, 1], math.pi, u_mean, (2, 3, 4), **kw)
    w = np.linspace(db.omega[0], db.omega[-1], 2000)
    S = spectrum("jonswap", w, HS, peak_frequency("jonswap", 3.3, tp=TP), 3.3)
    Rs = rao_mod.rao(db, w, math.pi, u_mean, (2, 3, 4), **kw)
    for d, col in ((2, "z"), (4, "pitch")):
        y = tr[keep, sim.rec_names.index(col)]
        rms_td = float(np.std(y))
        rms_comp = math.sqrt(float(np.sum(0.5 * comp[:, 0] ** 2 * np.abs(R[:, d]) ** 2)))
        rms_spec = math.sqrt(float(np.trapezoid(np.abs(Rs[:, d]) ** 2 * S, w)))
        print(f"U={u_mean:.2f} {col}: time domain {rms_td:.5g}, components {rms_comp:.5g}, spectrum {rms_spec:.5g}")
        assert abs(rms_td - rms_comp) <= 0.10 * rms_comp, (col, rms_td, rms_comp)
        assert abs(rms_td - rms_spec) <= 0.10 * rms_spec, (col, rms_td, rms_spec)


def test_irregular_beam_seas_rms_roll(patrol):
    """Long-crested JONSWAP beam seas (H_s 0.3 m, T_p 8 s: the peak 0.79 rad/s below the roll resonance
    1.14 rad/s; small waves keep the roll linear) on patrol51 at 5 m/s, heading held by its autopilot, excitation on all six DOFs. Prediction:
    the coupled six-DOF RAO (:mod:`vtrials.physics.seakeeping.linearize`, the simulator's own horizontal
    dynamics and autopilot) with the quadratic roll damping linearised stochastically,
    B_eq = B₁ + √(8/π) σ_p B₂, σ_p iterated from the predicted roll-rate spectrum; per component
    σ² = Σ ½ a_j² |RAO_j|² and from the spectrum. Issue 10: RMS heave, roll, pitch within 10 %.
    Step 0.01 s (the radiation memory's one-step lag lowers the roll peak by ~6 % at 0.02 s)."""
    ves, db, model = patrol
    dt = 0.01
    waves = Waves(spectrum="jonswap", hs_m=HS_BEAM, tp_s=TP, direction_deg=90.0, spreading="none", n_components=120)
    field = realize(waves, math.inf, np.random.default_rng(2027))
    comp = field.components
    comp = comp[(comp[:, 1] >= db.omega[0]) & (comp[:, 1] <= db.omega[-1])]
    start = Simulator(ves, 1, dt).self_propulsion(0, 5.0)
    v2, _ = seakeeping_vessel(ves, db, comp, dt, model=model, drift=False)
    rd = roll_damping_of(ves, db)
    v0, _ = seakeeping_vessel(ves, db, np.zeros((0, 6)), dt, model=model, drift=False)
    _, Jv, Je, Jd, Jf = LZ.force_jacobians(v0, start, dt, with_flow=True)
    fl = dict(Jf=Jf, flow=flow_geometry(ves))   # the maneuvering forces see the waves' flow, as in the time domain
    Jc = LZ.coriolis_jacobian(v0, start.u)
    ap = ves.autopilot
    auto = (*ap.pid, float(ves.steering[0, 2]))
    sim = Simulator(v2, 1, dt)
    sim.set_state(0, start)
    for k, n in enumerate(start.shaft_rps):
        sim.set_shaft_order(0, n, shaft=k)
    sim.set_helm(0, [(H.HEADING, 0.0, math.radians(ap.rudder_limit_deg), auto[0], auto[1], auto[2], 0.0)])
    sim.step(int(round(2100.0 / dt)))
    tr = sim.truth()[:, 0, :]
    t = tr[:, sim.rec_names.index("t")]
    keep = t > 100.0
    hdg = tr[keep, sim.rec_names.index("heading")]
    assert np.max(np.abs(hdg)) < 0.05
    u_mean = float(np.mean(tr[keep, sim.rec_names.index("u")]))
    # the sea travels east (μ = 90°), the ship heads north: β = π/2 for every component
    beta = math.pi / 2
    we_c = rao_mod.encounter_frequency(comp[:, 1], beta, u_mean, db.g)
    sigma_p = 0.0
    for _ in range(50):
        beq = float(rd.stochastic(u_mean, sigma_p)) - float(rd.B1(u_mean))   # B₁ is in Jv already
        R = LZ.coupled_rao(v2, db, comp[:, 1], beta, u_mean, Jv, Je, Jc, roll_beq=beq, Jd=Jd, autopilot=auto, **fl)
        new = math.sqrt(float(np.sum(0.5 * comp[:, 0] ** 2 * np.abs(we_c * R[:, 3]) ** 2)))
        if abs(new - sigma_p) < 1e-9:
            break
        sigma_p = new
    w = np.linspace(db.omega[0], db.omega[-1], 1500)
    S = spectrum("jonswap", w, HS_BEAM, peak_frequency("jonswap", 3.3, tp=TP), 3.3)
    Rs = LZ.coupled_rao(v2, db, w, beta, u_mean, Jv, Je, Jc, roll_beq=beq, Jd=Jd, autopilot=auto, **fl)
    p_td = float(np.std(tr[keep, sim.rec_names.index("p")]))
    print(f"U={u_mean:.2f}: σ_p time domain {p_td:.5g}, linearised {sigma_p:.5g}; B_eq {float(rd.stochastic(u_mean, sigma_p)):.4g}")
    for d, col in ((2, "z"), (3, "roll"), (4, "pitch")):
        y = tr[keep, sim.rec_names.index(col)]
        rms_td = float(np.std(y))
        rms_comp = math.sqrt(float(np.sum(0.5 * comp[:, 0] ** 2 * np.abs(R[:, d]) ** 2)))
        rms_spec = math.sqrt(float(np.trapezoid(np.abs(Rs[:, d]) ** 2 * S, w)))
        print(f"{col}: time domain {rms_td:.5g}, components {rms_comp:.5g} ({rms_td / rms_comp - 1:+.3f}), "
              f"spectrum {rms_spec:.5g} ({rms_td / rms_spec - 1:+.3f})")
        assert abs(rms_td - rms_comp) <= 0.10 * rms_comp, (col, rms_td, rms_comp)
        assert abs(rms_td - rms_spec) <= 0.10 * rms_spec, (col, rms_td, rms_spec)
