"""Irregular seas at zero speed on the simulated patrol51: the traced "creep" and RMS motions vs the RAO.

The creep. A free patrol51 at zero speed in head seas used to creep ahead (≈ 0.4–0.6 m/s) with no mean
wave force in the model. Traced (see :mod:`vtrials.physics.forces.seakeeping_coriolis`): the A∞ of
heave/roll/pitch acts on body-axis accelerations but patrol51's vessel file (coriolis = "none", the
Blanke–Christensen derivatives carry their own) applies no added-mass Coriolis terms, so the
block's horizontal Kirchhoff terms are missing; their surge part −q P_z (P_z = A33 w + A34 p + A35 q)
has a mean ≈ −A33 ⟨q w⟩ of about 1.2–1.3 kN in this sea. The test runs the ship without any mean wave
force, sway and yaw held by a soft restraint (below), surge free: without the component the ship
creeps ahead; with it (as :func:`vtrials.physics.seakeeping.sea_ship.sea_ship` builds the ship) it
stays.

RMS motions. JONSWAP T_p 8 s, γ 3.3, long-crested, 120 components (seeded), from ahead (β = π, H_s
1.5 m, the database's drift on) and from the beam (β = π/2, H_s 0.5 m, no mean force: see the case); ship at zero speed held on station by a soft horizontal restraint
(surge, sway, yaw springs with 30 s periods, critically damped: well below the wave frequencies, so the
first-order motions are those of a free ship; the restraint carries the mean drift). Reference: σ² = Σ_j ½ a_j² |RAO(ω_j, β)|² per
component and ∫ |RAO|² S dω from the target spectrum (U = 0: ω_e = ω), RAO from
:func:`vtrials.physics.seakeeping.rao.rao` with heave, roll and pitch free (the horizontal DOFs held:
the restraint and the excitation mask do the same in the time domain). Requirement (issue 10): 10 %.
Roll in beam seas is printed, not asserted: its damping model is being replaced on the ``roll`` branch
(Ikeda damping, free sway/yaw RAO).

Why a restraint: at zero speed neither rudder nor autopilot can hold the heading, and a free ship
turns beam-on within a few hundred seconds.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np
import pytest

from vtrials.physics.environment.waves import Waves, peak_frequency, realize, spectrum
from vtrials.physics.forces import context as L
from vtrials.physics.forces.registry import Component, register
from vtrials.physics.seakeeping import rao as rao_mod
from vtrials.physics.seakeeping.database import load_database
from vtrials.physics.seakeeping.timedomain import memory_model
from vtrials.physics.seakeeping.sea_ship import sea_ship
from vtrials.physics.seakeeping.timedomain import roll_damping_of
from vtrials.physics.simulator import ShipState, Simulator
from vtrials.physics.vessel import load_vessel, model_dir

DT = 0.02
HS, TP = 1.5, 8.0
T_RESTRAINT = 30.0  # s, natural period of each restraint spring


@nb.njit(cache=True)
def station_restraint(p, s, env, ctx, aux, w):
    """Springs and dampers on world north (p[0], p[1]), east (p[2], p[3]) and heading (p[4], p[5]),
    about (0, 0, 0); a test harness (a soft mooring), not ship physics."""
    fn = -p[0] * ctx[L.POS] - p[1] * (ctx[L.ROT + 0] * ctx[L.NU] + ctx[L.ROT + 1] * ctx[L.NU + 1]
                                       + ctx[L.ROT + 2] * ctx[L.NU + 2])
    fe = -p[2] * ctx[L.POS + 1] - p[3] * (ctx[L.ROT + 3] * ctx[L.NU] + ctx[L.ROT + 4] * ctx[L.NU + 1]
                                           + ctx[L.ROT + 5] * ctx[L.NU + 2])
    mz = -p[4] * ctx[L.EUL + 2] - p[5] * ctx[L.NU + 5]
    for k in range(3):
        w[k] = ctx[L.ROT + k] * fn + ctx[L.ROT + 3 + k] * fe
        w[3 + k] = ctx[L.ROT + 6 + k] * mz


register("test_station_restraint", station_restraint)


def restraint(ves, surge: bool) -> Component:
    w0 = 2.0 * math.pi / T_RESTRAINT
    m_x = ves.M_RB[0, 0] + ves.M_A[0, 0]
    m_y = ves.M_RB[1, 1] + ves.M_A[1, 1]
    i_z = ves.M_RB[5, 5] + ves.M_A[5, 5]
    kx = m_x * w0 ** 2 if surge else 0.0
    p = np.array([kx, 2.0 * math.sqrt(kx * m_x), m_y * w0 ** 2, 2.0 * m_y * w0, i_z * w0 ** 2, 2.0 * i_z * w0])
    return Component("restraint", "test_station_restraint", p)


@pytest.fixture(scope="module")
def patrol():
    ves = load_vessel("patrol51")
    db = load_database(model_dir("patrol51") / "hydro" / "patrol51_hydro.nc")
    return ves, db, memory_model(db)


def _sea(db, direction_deg, hs=HS):
    waves = Waves(spectrum="jonswap", hs_m=hs, tp_s=TP, direction_deg=direction_deg, spreading="none",
                  n_components=120)
    comp = realize(waves, math.inf, np.random.default_rng(2026)).components
    return comp[(comp[:, 1] >= db.omega[0]) & (comp[:, 1] <= db.omega[-1])]


def _run(ves, db, model, comp, mean_force, surge_held, coriolis=True, duration=1600.0):
    v2, _ = sea_ship(ves, db, comp, DT, model=model, mean_force=mean_force, excitation_dofs=(2, 3, 4))
    v2.components = [c for c in v2.components if coriolis or c.name != "seakeeping_coriolis"]
    v2.components = v2.components + [restraint(ves, surge_held)]
    sim = Simulator(v2, 1, DT)
    sim.set_state(0, ShipState(shaft_rps=(0.0,) * len(ves.shafts)))
    sim.step(int(round(duration / DT)))
    tr = sim.truth()[:, 0, :]
    return {n: tr[:, sim.rec_names.index(n)] for n in ("t", "u", "z", "roll", "pitch", "heading", "x")}


def test_creep_at_zero_speed_is_the_missing_added_mass_coriolis_force(patrol):
    ves, db, model = patrol
    comp = _sea(db, 0.0)                      # from the north; the ship heads north: head seas
    assert "seakeeping_coriolis" in [c.name for c in sea_ship(ves, db, comp, DT, model=model)[0].components]
    out = {}
    for fix in (False, True):
        r = _run(ves, db, model, comp, "none", surge_held=False, coriolis=fix, duration=800.0)
        keep = r["t"] > 300.0
        out[fix] = float(np.mean(r["u"][keep]))
        print(f"coriolis component {fix}: mean u {out[fix]:.4f} m/s, x at end {r['x'][-1]:.1f} m, "
              f"|heading| max {np.max(np.abs(r['heading'])):.2e} rad")
    assert out[False] > 0.2                   # the creep this test was written for
    assert abs(out[True]) < 0.03, out         # gone with the missing term in place


@pytest.mark.parametrize("direction_deg,beta,hs,asserted,mean_force", [
    (0.0, math.pi, HS, (2, 4), "database"),
    # beam seas: H_s 0.25 m and no mean force. Pitch in beam seas is tiny (0.008° RMS here) and the roll's
    # second-order terms add to it: at H_s 0.5 m (roll 4.4° RMS) the pitch was +11 % over this linear
    # reference, at 0.25 m (2.3°) +4 %. Roll is not asserted against this held-DOF reference: the ship is
    # free to sway (−34 % here); tests/test_seakeeping_sim.py checks roll against the coupled RAO
    (270.0, 0.5 * math.pi, 0.25, (2, 4), "none")], ids=["head", "beam"])
def test_zero_speed_rms_motions_match_rao(patrol, direction_deg, beta, hs, asserted, mean_force):
    ves, db, model = patrol
    comp = _sea(db, direction_deg, hs)
    r = _run(ves, db, model, comp, mean_force, surge_held=True)
    keep = r["t"] > 100.0
    print(f"heading over the record {np.min(r['heading'][keep]):.2e} .. {np.max(r['heading'][keep]):.2e} rad, "
          f"mean u {np.mean(r['u'][keep]):.4f} m/s")
    assert np.max(np.abs(r["heading"][keep])) < 0.05
    bv = np.zeros((6, 6))
    bv[3, 3] = float(roll_damping_of(ves, db).B1(0.0))   # the roll damping's linear part at zero speed
    kw = dict(M=ves.M_RB, C=ves.restoring_matrix(), B_visc=bv)
    R = rao_mod.rao(db, comp[:, 1], beta, 0.0, (2, 3, 4), **kw)
    w = np.linspace(db.omega[0], db.omega[-1], 4000)
    S = spectrum("jonswap", w, hs, peak_frequency("jonswap", 3.3, tp=TP), 3.3)
    Rs = rao_mod.rao(db, w, beta, 0.0, (2, 3, 4), **kw)
    for d, col in ((2, "z"), (3, "roll"), (4, "pitch")):
        y = r[col][keep]
        rms_td = float(np.std(y))
        rms_comp = math.sqrt(float(np.sum(0.5 * comp[:, 0] ** 2 * np.abs(R[:, d]) ** 2)))
        rms_spec = math.sqrt(float(np.trapezoid(np.abs(Rs[:, d]) ** 2 * S, w)))
        print(f"β={math.degrees(beta):.0f}° {col}: time domain {rms_td:.5g}, components {rms_comp:.5g} "
              f"({rms_td / rms_comp - 1:+.1%}), spectrum {rms_spec:.5g} ({rms_td / rms_spec - 1:+.1%})")
        if d in asserted:
            assert abs(rms_td - rms_comp) <= 0.10 * rms_comp, (col, rms_td, rms_comp)
            assert abs(rms_td - rms_spec) <= 0.10 * rms_spec, (col, rms_td, rms_spec)
