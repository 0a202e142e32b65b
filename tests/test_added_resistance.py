"""Added resistance in waves at forward speed (SNNM, :mod:`vtrials.physics.forces.added_resistance`).

* The component's force for a short-crested seaway (the State 3 sea of
  scenarios/patrol51_standardization_sea3.toml, realized from its seed, 150 components) on a ship at
  speed U and heading ψ (head, 35° off the bow as on the scenario's base course, 35° off the stern,
following, zero speed) equals, within 10 % (issue 10), the spectral integral of the same regular-wave
  formula over the target directional spectrum, R̄ = 2 ∫∫ S(ω) D(μ) R_AW(ω, μ − ψ, U)/ζ² dω dμ (numerical
  quadrature on a fine grid), for head, bow-quartering and following seas; it points against the
  ship's horizontal heading, turned into body axes on a heeled and trimmed ship.
* Self-propelled speed loss: patrol51 at fixed shaft speed (7 m/s in calm water) in long-crested head
  seas with the full seakeeping model (:func:`vtrials.physics.seakeeping.sea_ship.sea_ship`, mean force
  "snnm") loses, within 10 %, the speed that the force balance with the added resistance alone predicts
  (steady_at_order of the calm-water ship carrying only the SNNM component, which depends on the speed).
* Regular-wave checks of the formula's structure: at zero speed in long waves (λ > 2.5 L: no
  reflection part) following over head seas is −(1/3)(0.87/C_B)^{−2} (a₁'s factors (1 − 2 cos α)/3 and
  (0.87/C_B)^{−cos α} at α = 0 and π; the waves push the ship along from astern); in very short head
  waves the motion part vanishes and the reflection part is (2.25/4) ρ g B α_T [sin²(E₁ − π) + sin²(E₁ + π)
  + 2 (2ωU/g)(cos E₁ cos(E₁ + π) + 1)] (0.87/C_B)^{1+4√Fn} (written out independently in the test).
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

from vtrials.physics.environment.waves import realize
from vtrials.physics.forces import added_resistance as AR
from vtrials.physics.forces.registry import Component
from vtrials.physics.seakeeping.database import load_database
from vtrials.physics.seakeeping.timedomain import memory_model
from vtrials.physics.seakeeping.sea_ship import sea_ship
from vtrials.physics import steering as H
from vtrials.physics.environment.waves import Waves, spectrum, peak_frequency
from vtrials.physics.simulator import ShipState, Simulator
from vtrials.physics.vessel import load_vessel, model_dir
from vtrials.scenario import load_scenario, wave_field

ROOT = Path(__file__).resolve().parents[1]
SEA3 = ROOT / "scenarios" / "patrol51_standardization_sea3.toml"
DT = 0.02


@pytest.fixture(scope="module")
def patrol():
    ves = load_vessel("patrol51")
    db = load_database(model_dir("patrol51") / "hydro" / "patrol51_hydro.nc")
    return ves, db, AR.snnm_hull(ves)


def test_hull_data_of_patrol51(patrol):
    ves, _db, h = patrol
    assert h.C_B == pytest.approx(357.0 / (51.5 * 8.6 * 2.3))
    assert h.k_yy == pytest.approx(10.999577092597752 / 51.5)
    # the parametric waterline reaches 99 % of B just forward of midship (no parallel body forward)
    # and just aft of the aft parallel body's end (0.05 L aft of midship) towards the 0.75 B transom
    assert 0.4 * 51.5 < h.entrance_length < 0.5 * 51.5
    assert 0.4 * 51.5 < h.run_length < 0.45 * 51.5


@pytest.mark.parametrize("U,psi_deg", [(7.0, 10.0), (7.0, 45.0), (7.0, 225.0), (4.0, 190.0), (0.0, 10.0)],
                         ids=["head", "bow-quartering", "stern-quartering", "following", "zero-speed-head"])
def test_component_mean_equals_spectral_integral(patrol, U, psi_deg):
    ves, db, hull = patrol
    scn = load_scenario(SEA3)
    # the scenario's sea with 3000 components instead of 150: the component sum samples the directional
    # spectrum (each component's direction is drawn), so with 150 its error is a sampling error of
    # ~CV/√150 (5–12 % here, the response being peaked in direction); 3000 make it ~2 %
    field = realize(dataclasses.replace(scn.waves, n_components=3000), scn.environment.water_depth_m,
                    np.random.default_rng(2027))
    comp = field.components
    psi = math.radians(psi_deg)        # the sea comes from 010° (travels towards 190°): ψ = 10° is head seas
    v = ves
    sim = Simulator(v, 1, DT, components=list(v.components) + [
        Component("added_resistance", "added_resistance", AR.pack(hull, comp))])
    phi, theta = 0.04, -0.015
    sim.set_state(0, ShipState(heading=psi, u=U, roll=phi, pitch=theta, shaft_rps=(0.0,) * len(ves.shafts)))
    sim.evaluate()
    w = sim.comp_w[0, sim.comp_names.index("added_resistance")]
    # body wrench back to the horizontal: world force = R f_body; along the heading: −R̄
    cx, sx, cy, sy, cz, sz = math.cos(phi), math.sin(phi), math.cos(theta), math.sin(theta), math.cos(psi), math.sin(psi)
    Rm = (np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]]) @ np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
          @ np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]]))
    fw = Rm @ w[:3]
    along, across = fw[0] * cz + fw[1] * sz, -fw[0] * sz + fw[1] * cz
    assert abs(fw[2]) < 1e-9 * abs(along) and abs(across) < 1e-9 * abs(along)
    np.testing.assert_allclose(w[3:], 0.0)
    r_td = -along
    # the spectral integral over the target spectrum (the sea system of the scenario; no swell)
    om = np.linspace(0.15, 4.0, 700)
    mu = np.linspace(-math.pi, math.pi, 721)
    Sd = field.directional_spectrum(om, mu)                              # [m² s/rad²], (nω, nμ)
    Raw = AR.regular(hull, om[:, None], mu[None, :] - psi, U)
    r_spec = 2.0 * float(np.trapezoid(np.trapezoid(Sd * Raw, mu, axis=1), om))
    m0 = float(np.trapezoid(np.trapezoid(Sd, mu, axis=1), om))
    print(f"U {U} ψ {psi_deg}°: component sum {r_td:.1f} N, spectral integral {r_spec:.1f} N "
          f"({r_td / r_spec - 1:+.2%}); m0 of the grid {m0:.4f} vs H_s²/16 {0.88 ** 2 / 16:.4f}")
    assert m0 == pytest.approx(0.88 ** 2 / 16, rel=0.02)
    assert abs(r_td - r_spec) <= 0.05 * abs(r_spec), (r_td, r_spec)   # measured 0.1–1.4 %


def test_regular_wave_limits(patrol):
    _ves, _db, h = patrol
    g, rho = h.g, h.rho
    # long waves (λ/L > 2.5: α_T = 0, no reflection), zero speed: following = −head × (1/3)/1 × (0.87/C_B)^(−2)
    w = math.sqrt(g * 2.0 * math.pi / (3.0 * h.length))
    head = AR.regular(h, w, math.pi, 0.0)
    foll = AR.regular(h, w, 0.0, 0.0)
    assert head > 0.0 and foll < 0.0
    assert foll / head == pytest.approx(-(1.0 / 3.0) * (0.87 / h.C_B) ** (-2.0), rel=1e-12)
    # very short head waves: the motion part vanishes (ω̄^−8.5 exp(...)), reflection with α_T → 1
    U = 5.0
    w = 12.0
    fn = U / math.sqrt(g * h.length)
    E1 = h.E1
    seg = (math.sin(E1 - math.pi) ** 2 + math.sin(E1 + math.pi) ** 2
           + 2 * (2 * w * U / g) * (math.cos(E1) * math.cos(E1 + math.pi) + 1.0))
    want = rho * g * 2.25 / 4.0 * h.beam * seg * (0.87 / h.C_B) ** (1 + 4 * math.sqrt(fn))
    lam = 2 * math.pi * g / w ** 2
    aT = 1 - math.exp(-4 * math.pi * (h.draught / lam - h.draught / (2.5 * h.length)))
    assert aT > 0.999
    assert float(AR.regular(h, w, math.pi, U)) == pytest.approx(want * aT, rel=2e-3)


def test_self_propelled_speed_loss_matches_the_added_resistance(patrol):
    ves, db, hull = patrol
    waves = Waves(spectrum="jonswap", hs_m=1.5, tp_s=6.0, direction_deg=0.0, spreading="none", n_components=120)
    comp = realize(waves, math.inf, np.random.default_rng(11)).components
    comp = comp[(comp[:, 1] >= db.omega[0]) & (comp[:, 1] <= db.omega[-1])]
    calm = Simulator(ves, 1, DT)
    s0 = calm.self_propulsion(0, 7.0)
    rps = s0.shaft_rps
    pred_sim = Simulator(ves, 1, DT, components=list(ves.components) + [
        Component("added_resistance", "added_resistance", AR.pack(hull, comp))])
    pred = pred_sim.steady_at_order(0, rps)
    R_pred = -float(pred_sim.comp_w[0, pred_sim.comp_names.index("added_resistance"), 0])
    v2, _ = sea_ship(ves, db, comp, DT, model=memory_model(db), mean_force="snnm")
    sim = Simulator(v2, 1, DT)
    sim.set_state(0, s0)
    for k, n in enumerate(rps):
        sim.set_shaft_order(0, n, shaft=k)
    ap = ves.autopilot
    sim.set_helm(0, [(H.HEADING, 0.0, math.radians(ap.rudder_limit_deg), *ap.pid, 0.0)])
    sim.step(int(round(700.0 / DT)))
    tr = sim.truth()[:, 0, :]
    t = tr[:, sim.rec_names.index("t")]
    keep = t > 200.0
    u_sim = float(np.mean(tr[keep, sim.rec_names.index("u")]))
    hdg = tr[keep, sim.rec_names.index("heading")]
    loss_pred = s0.u - pred.u
    loss_sim = s0.u - u_sim
    print(f"added resistance {R_pred:.0f} N at {pred.u:.3f} m/s; calm {s0.u:.4f} m/s, predicted loss {loss_pred:.4f}, "
          f"simulated {loss_sim:.4f} ({loss_sim / loss_pred - 1:+.1%}); heading {hdg.min():.4f}..{hdg.max():.4f}")
    assert np.max(np.abs(hdg)) < 0.05
    assert loss_pred > 0.1
    assert abs(loss_sim - loss_pred) <= 0.10 * loss_pred, (loss_pred, loss_sim)
