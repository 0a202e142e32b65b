"""The waves' flow past the hull that the maneuvering forces see (vtrials.physics.forces.wave_flow).

Independent references: the Airy orbital velocity and surface of every component evaluated point by point
along the hull and averaged numerically (trapezoid over 2001 points, least-squares line for the gradient,
central differences across the ship for the slope), not the closed forms S(z), F(z) the kernel uses; and
the maneuvering components themselves: a ship moving with the water (its sway, yaw rate and heel equal to
the flow's) feels the hull, rudder and propeller forces of calm water.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from vtrials.physics.forces import context as L
from vtrials.physics.forces import wave_flow as WF
from vtrials.units import G


def _components(rng, n=6):
    w = rng.uniform(0.3, 1.6, n)
    mu = rng.uniform(-math.pi, math.pi, n)
    return np.column_stack([rng.uniform(0.1, 0.8, n), w, w * w / G, np.cos(mu), np.sin(mu),
                            rng.uniform(0, 2 * math.pi, n)])


def _kernel(comp, length, depth, x, y, t, psi):
    p = WF.pack(comp, length, depth)
    ctx = np.zeros(L.NCTX)
    ctx[L.POS], ctx[L.POS + 1], ctx[L.TIME], ctx[L.EUL + 2] = x, y, t, psi
    aux = np.zeros(L.NAUX)
    w = np.full(6, np.nan)
    WF.flow_kernel(p, np.zeros(0), np.zeros(16), ctx, aux, w)
    assert np.all(w == 0.0)
    return aux[L.AUX_FLOW:L.AUX_FLOW + 3]


def _direct(comp, length, depth, x, y, t, psi):
    """Point-by-point Airy flow along the hull, averaged numerically."""
    xb = np.linspace(-length / 2, length / 2, 2001)
    lat = np.array([-math.sin(psi), math.cos(psi)])           # body +y (starboard) in (north, east)
    X = x + xb * math.cos(psi)
    Y = y + xb * math.sin(psi)
    v = np.zeros_like(xb)
    slope = np.zeros_like(xb)
    h = 1e-3
    for a, w, k, cm, sm, eps in comp:
        th = w * t - k * (X * cm + Y * sm) + eps
        v += a * w * math.exp(-k * depth) * np.cos(th) * (cm * lat[0] + sm * lat[1])

        def eta(off):
            return a * np.cos(w * t - k * ((X + off * lat[0]) * cm + (Y + off * lat[1]) * sm) + eps)
        slope += (eta(h) - eta(-h)) / (2 * h)
    vw = np.trapezoid(v, xb) / length
    rw = np.trapezoid(xb * v, xb) / np.trapezoid(xb * xb, xb)
    fw = -np.trapezoid(slope, xb) / length
    return np.array([vw, rw, fw])


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_kernel_matches_the_flow_averaged_point_by_point(seed):
    rng = np.random.default_rng(seed)
    comp = _components(rng)
    for length, depth in ((51.5, 1.15), (320.0, 10.4)):
        x, y, t, psi = rng.uniform(-300, 300), rng.uniform(-300, 300), rng.uniform(0, 900), rng.uniform(-3, 3)
        got = _kernel(comp, length, depth, x, y, t, psi)
        ref = _direct(comp, length, depth, x, y, t, psi)
        scale = np.array([np.sum(comp[:, 0] * comp[:, 1]), np.sum(comp[:, 0] * comp[:, 1] * comp[:, 2]),
                          np.sum(comp[:, 0] * comp[:, 2])])
        np.testing.assert_allclose(got, ref, rtol=0, atol=2e-6 * scale.max())
        assert np.all(np.abs(ref) > 1e-4 * scale)          # nothing trivially zero


def test_flow_rao_is_the_kernel_in_complex_form():
    """A single component seen from a ship at the origin: kernel(t) = Re{f̂ a e^{iθ(t)}} with f̂ from flow_rao,
    over headings including head, beam and following seas (β = μ − ψ)."""
    length, depth = 51.5, 1.15
    for beta in (0.0, 0.4, math.pi / 2, 2.2, math.pi, -1.0):
        w, a, eps = 0.8, 0.7, 0.4
        comp = np.array([[a, w, w * w / G, math.cos(beta), math.sin(beta), eps]])
        f = WF.flow_rao([w], beta, length, depth)[:, 0]
        for t in (0.0, 1.3, 4.9):
            th = w * t + eps
            np.testing.assert_allclose(_kernel(comp, length, depth, 0.0, 0.0, t, 0.0),
                                       (f * a * np.exp(1j * th)).real, atol=1e-12)


def test_a_ship_moving_with_the_water_feels_calm_water_maneuvering_forces():
    """patrol51 at 9 m/s: the hull, rudder and propeller wrenches at sway velocity v_w, yaw rate r_w and heel
    φ_w with that flow in aux are those at v = r = φ = 0 in calm water (BC93's φ³ roll restoring, which
    stays on the absolute heel, taken out); and a cross-flow alone acts as the opposite sway velocity."""
    from vtrials.physics.seakeeping import linearize as LZ
    from vtrials.physics.seakeeping.database import load_database
    from vtrials.physics.seakeeping.timedomain import memory_model, seakeeping_vessel
    from vtrials.physics.simulator import Simulator
    from vtrials.physics.vessel import load_vessel, model_dir
    ves = load_vessel("patrol51")
    db = load_database(model_dir("patrol51") / "hydro" / "patrol51_hydro.nc")
    v0, _ = seakeeping_vessel(ves, db, np.zeros((0, 6)), 0.05, model=memory_model(db), drift=False)
    start = Simulator(ves, 1, 0.05).self_propulsion(0, 9.0)
    sim = Simulator(v0, 1, 0.05)
    sim.set_state(0, start)
    base_q, base_v = sim.qpos[0].copy(), sim.qvel[0].copy()
    man = [k for k, c in enumerate(v0.components) if c.type in ("hull_blanke", "rudder", "propeller")]
    assert len(man) == 5                                    # hull, two rudders, two propellers
    hull = next(c for c in v0.components if c.type == "hull_blanke")

    def wrench(nu, phi, flow):
        LZ._set(sim, base_q, base_v, np.array([0, 0, 0, phi, 0, 0.0]), nu)
        sim.aux[0, L.AUX_FLOW:L.AUX_FLOW + 3] = flow
        sim.evaluate()
        return sim.comp_w[0, man].copy()

    vw, rw, fw = 0.4, 0.012, 0.03
    calm = wrench(np.array([start.u, 0, 0, 0, 0, 0.0]), 0.0, (0.0, 0.0, 0.0))
    moving = wrench(np.array([start.u, vw, 0, 0, 0, rw]), fw, (vw, rw, fw))
    k_phi3 = hull.params[20] * fw ** 3
    moving[man.index(next(k for k in man if v0.components[k].type == "hull_blanke")), 3] -= k_phi3
    np.testing.assert_allclose(moving, calm, rtol=1e-12, atol=1e-9 * np.abs(calm).max())
    drift = wrench(np.array([start.u, -vw, 0, 0, 0, 0.0]), 0.0, (0.0, 0.0, 0.0))
    crossflow = wrench(np.array([start.u, 0, 0, 0, 0, 0.0]), 0.0, (vw, 0.0, 0.0))
    np.testing.assert_allclose(crossflow, drift, rtol=1e-12, atol=1e-9 * np.abs(calm).max())
    assert np.abs(drift - calm)[:, 1].max() > 1e3           # the lift is there [N]


def test_bad_geometry_is_named():
    from vtrials.errors import InputError
    with pytest.raises(InputError, match="length"):
        WF.pack(np.zeros((1, 6)), 0.0, 1.0)


def test_long_beam_waves_at_speed_no_longer_heel_the_ship_by_the_lift():
    """patrol51 at 9 m/s in long beam waves (0.2–0.3 rad/s), the coupled frequency-domain model of the
    simulator (verified against the time domain in tests/test_seakeeping_sim.py): with the maneuvering
    forces on the motion relative to the flow the ship sways about with the water (measured 1.09–1.12 of
    the amplitude) and heels less than the slope (0.58–0.65 ×: the waves' yaw moment turns it, and at speed
    a heading change is a drift angle); on the absolute motion the lift of the sway it shares with the
    water heeled it 3.0–3.6 × the slope (1.08 × at rest)."""
    from vtrials.physics.seakeeping import linearize as LZ
    from vtrials.truth.motion_rao import TruthRAO
    T = TruthRAO("patrol51", 9.0)
    w = np.array([0.2, 0.25, 0.3])
    slope = w * w / G

    def coupled(**kw):
        return LZ.coupled_rao(T.v0, T.db, w, math.pi / 2, T.U, T.Jv, T.Je, T.Jc, roll_beq=0.0, Jd=T.Jd,
                              autopilot=T.auto, **kw)
    rel = coupled(Jf=T.Jf, flow=T.flow)
    absolute = coupled()
    print("roll/slope relative", np.round(np.abs(rel[:, 3]) / slope, 3), "absolute",
          np.round(np.abs(absolute[:, 3]) / slope, 3), "sway", np.round(np.abs(rel[:, 1]), 3))
    assert np.all(np.abs(rel[:, 3]) / slope < 1.3)
    assert np.all(np.abs(np.abs(rel[:, 1]) - 1.0) < 0.25)
    assert np.all(np.abs(absolute[:, 3]) / slope > 2.5)      # what the flow takes away


def test_steady_states_leave_out_the_first_order_wave_forces():
    """Self-propulsion and the steady speed of an order on a simulator whose ship carries wave components are
    solved without the first-order ones (a frozen wave force and flow at t = 0 used to enter the balance,
    and with the waves' flow one airwake-survey replicate found no root): without a mean wave force they
    equal the calm vessel's; the mean drift force stays in (the speed in bow seas is lower)."""
    from vtrials.physics.environment.waves import Waves, realize
    from vtrials.physics.seakeeping.database import load_database
    from vtrials.physics.seakeeping.timedomain import memory_model, seakeeping_vessel
    from vtrials.physics.simulator import Simulator
    from vtrials.physics.vessel import load_vessel, model_dir
    ves = load_vessel("patrol51")
    db = load_database(model_dir("patrol51") / "hydro" / "patrol51_hydro.nc")
    comp = realize(Waves(hs_m=3.0, tp_s=8.0, direction_deg=40.0, spreading_s=10.0, n_components=60),
                   math.inf, np.random.default_rng(5)).components
    comp = comp[(comp[:, 1] >= db.omega[0]) & (comp[:, 1] <= db.omega[-1])]
    model = memory_model(db)
    v2, _ = seakeeping_vessel(ves, db, comp, 0.05, model=model, drift=False)
    sea, calm = Simulator(v2, 1, 0.05), Simulator(ves, 1, 0.05)
    a, b = sea.self_propulsion(0, 9.0), calm.self_propulsion(0, 9.0)
    np.testing.assert_allclose(a.shaft_rps, b.shaft_rps, rtol=1e-9)
    np.testing.assert_allclose([a.z, a.roll, a.pitch], [b.z, b.roll, b.pitch], atol=1e-9)
    rps = ves.telegraph["standard"][0]
    a, b = sea.steady_at_order(0, (rps,) * sea.ns), calm.steady_at_order(0, (rps,) * calm.ns)
    assert a.u == pytest.approx(b.u, rel=1e-9)
    v3, _ = seakeeping_vessel(ves, db, comp, 0.05, model=model, drift=True)     # waves from 40° off the bow
    c = Simulator(v3, 1, 0.05).steady_at_order(0, (rps,) * sea.ns)
    print(f"steady speed at standard: calm {b.u:.4f} m/s, with the mean drift {c.u:.4f} m/s")
    assert c.u < b.u - 1e-3
