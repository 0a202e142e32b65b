"""What the timing of the radiation memory changes, measured on patrol51 (issue 13).

The memory force was taken before its state was advanced (lagging the motion by a step); it is now
taken after (:mod:`vtrials.physics.forces.radiation`). Two clean experiments, each against an
independent reference:

1. Mean surge force in regular waves. Self-propelled patrol51 (shaft speed for 7.3 and 12.25 m/s in
   calm water, the slow and fast spots of tests/data/patrol51_standardization_sea3_short.toml),
   autopilot on course, one regular wave (amplitude 0.5 m; ω 0.7, 1.0, 1.3 rad/s; head seas, 35° off
   the bow, 35° off the stern) and NO mean wave force (``mean_force = "none"``): linear theory has no
   mean surge force from the first-order loads, so the reference for the speed loss is ~0 (what is
   left is the second order of the time-domain model itself: the excitation at the displaced
   position, and the body-axis A∞ and its Coriolis term). Reported: the speed loss and every
   component's mean force along the horizontal heading (world frame; the A∞ inertia of the exact
   solve is not a component and is in the loss only).
2. Roll, heave and pitch at the roll resonance (beam seas, ω 1.14 rad/s since the roll fix of stop 33 —
   0.86 rad/s before, with the earlier stand-in hull and BC93's sway added mass —, zero speed, 2 mm waves)
   against the frequency-domain RAO of the same coupled system (:func:`vtrials.physics.seakeeping.
   linearize.coupled_rao`, as tests/test_seakeeping_sim.py) at dt 0.05 (the scenarios' step), 0.02 and
   0.01 s: the ratio of the simulated to the reference amplitude.
3. The scatter of a run's mean speed in the irregular sea of the sea-trial test (its wave field for
   seeds 2002–2009; patrol51 free-running at the shaft speed for 7.3 m/s, 35° off the stern, autopilot
   with 3° of rudder as the test's agenda, dt 0.05 s, 1500 s): the mean speed of each of the seven
   disjoint 180-s windows after 200 s, pooled: their mean and standard deviation.

Run: ``python benchmarks/radiation_timing.py [--out FILE]``; results in
benchmarks/results/radiation_timing.json (and radiation_timing_before.json: the same script with the
kernel of main before the change); radiation_timing_consistent_roll.json: rerun after the roll fix.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import time
from pathlib import Path

import numpy as np

from vtrials.physics import steering as H
from vtrials.physics.environment.waves import elevation_at
from vtrials.physics.seakeeping import linearize as LZ
from vtrials.physics.seakeeping.database import load_database
from vtrials.physics.seakeeping.timedomain import memory_model
from vtrials.physics.seakeeping.sea_ship import sea_ship
from vtrials.physics.seakeeping.timedomain import roll_damping_of, seakeeping_vessel
from vtrials.physics.simulator import ShipState, Simulator
from vtrials.physics.vessel import load_vessel, model_dir

ROOT = Path(__file__).resolve().parents[1]


def mean_surge(ves, db, model, U0: float, omega: float, beta_deg: float, dt: float = 0.02,
               amp: float = 0.5, t_end: float = 400.0, t0: float = 150.0) -> dict:
    calm = Simulator(ves, 1, dt)
    s0 = calm.self_propulsion(0, U0)
    mu = math.radians(beta_deg)                          # the ship heads north: β = μ
    comp = np.array([[amp, omega, omega ** 2 / db.g, math.cos(mu), math.sin(mu), 0.3]])
    v2, _ = sea_ship(ves, db, comp, dt, model=model, mean_force="none")
    sim = Simulator(v2, 1, dt)
    sim.set_state(0, s0)
    for k, n in enumerate(s0.shaft_rps):
        sim.set_shaft_order(0, n, shaft=k)
    ap = ves.autopilot
    sim.set_helm(0, [(H.HEADING, 0.0, math.radians(ap.rudder_limit_deg), *ap.pid, 0.0)])
    sim.step(int(round(t_end / dt)))
    tr = sim.truth()[:, 0, :]
    c = {n: tr[:, i] for i, n in enumerate(sim.rec_names)}
    keep = c["t"] > t0
    ph, th = c["roll"][keep], c["pitch"][keep]
    fwd = {}
    for n in sim.comp_names:
        fx, fy, fz = (c[f"F_{n}_{a}"][keep] for a in "XYZ")
        fwd[n] = float(np.mean(np.cos(th) * fx + np.sin(th) * (np.sin(ph) * fy + np.cos(ph) * fz)))
    return {"U0": U0, "omega": omega, "beta_deg": beta_deg, "speed_loss": s0.u - float(np.mean(c["u"][keep])),
            "rms_pitch_deg": float(np.degrees(np.std(th))), "rms_roll_deg": float(np.degrees(np.std(ph))),
            "mean_forward_force_N": fwd}


def resonance(ves, db, model, rd, dt: float, omega: float = 1.14, beta_deg: float = 90.0, amp: float = 0.002,
              t_end: float = 400.0) -> dict:
    beta = math.radians(beta_deg)
    start = ShipState(shaft_rps=(0.0,) * len(ves.shafts))
    v0, _ = seakeeping_vessel(ves, db, np.zeros((0, 6)), dt, model=model, drift=False)
    _, Jv, Je, Jd = LZ.force_jacobians(v0, start, dt)
    Jc = LZ.coriolis_jacobian(v0, start.u)
    comp = np.array([[amp, omega, omega ** 2 / db.g, math.cos(beta), math.sin(beta), 0.3]])
    v2, _ = seakeeping_vessel(ves, db, comp, dt, model=model, drift=False)
    kw = dict(Jd=Jd, autopilot=None)
    ss = LZ.coupled_rao(v2, db, [omega], beta, 0.0, Jv, Je, Jc, rd, amp, **kw)[0] * amp * np.exp(0.3j)
    nu_ss = (1j * omega * ss).real
    M = v2.M_RB + v2.M_A
    hz = (1, 5)
    v_r = np.linalg.solve(M[np.ix_(hz, hz)], (M @ nu_ss)[list(hz)])   # as tests/test_seakeeping_sim.py
    sim = Simulator(v2, 1, dt)
    sim.set_state(0, dataclasses.replace(start, v=float(v_r[0]), r=float(v_r[1])))
    sim.step(int(round(t_end / dt)))
    tr = sim.truth()[:, 0, :]
    r = {c: tr[:, sim.rec_names.index(c)] for c in ("t", "x", "y", "z", "roll", "pitch", "heading")}
    t = r["t"]
    last = t > t[-1] - 4.0 * 2.0 * math.pi / omega
    hd = float(np.mean(r["heading"][last]))
    basis = np.stack([np.cos(omega * t[last]), -np.sin(omega * t[last])], axis=1)
    eta = np.array([elevation_at(comp, x, y, tt) for x, y, tt in zip(r["x"][last], r["y"][last], t[last])])
    ce = np.linalg.lstsq(basis, eta, rcond=None)[0]
    ce = ce[0] + 1j * ce[1]
    fd = LZ.coupled_rao(v2, db, [omega], beta - hd, 0.0, Jv, Je, Jc, rd, amp, **kw)[0]
    out = {"dt": dt, "omega": omega, "beta_deg": beta_deg}
    for d, col in ((2, "z"), (3, "roll"), (4, "pitch")):
        y = r[col][last]
        c = np.linalg.lstsq(np.column_stack([basis, np.ones(y.size)]), y, rcond=None)[0]
        td = (c[0] + 1j * c[1]) / ce
        out[col] = {"amplitude_ratio": float(abs(td) / abs(fd[d])), "phase_deg": float(np.degrees(np.angle(td / fd[d])))}
    return out


def following_run_scatter(ves, db, model, seeds=range(2002, 2010), U0: float = 7.3, heading_deg: float = 225.0,
                          dt: float = 0.05, t_end: float = 1500.0, t0: float = 200.0, window: float = 180.0) -> list:
    import re
    import tempfile
    from vtrials.physics.seakeeping.sea_ship import in_database_band
    from vtrials.scenario import load_scenario, wave_field
    src = (ROOT / "tests" / "data" / "patrol51_standardization_sea3_short.toml").read_text()
    psi = math.radians(heading_deg)
    s0 = Simulator(ves, 1, dt).self_propulsion(0, U0, heading=psi)
    out = []
    for seed in seeds:
        with tempfile.TemporaryDirectory() as d:
            f = Path(d) / "s.toml"
            f.write_text(re.sub(r"(?m)^seed = \d+", f"seed = {seed}", src))
            comp, _ = in_database_band(db, wave_field(load_scenario(f)).components)
        v2, _ = sea_ship(ves, db, comp, dt, model=model)
        sim = Simulator(v2, 1, dt)
        sim.set_state(0, s0)
        for k, n in enumerate(s0.shaft_rps):
            sim.set_shaft_order(0, n, shaft=k)
        ap = ves.autopilot
        sim.set_helm(0, [(H.HEADING, psi, math.radians(3.0), *ap.pid, 0.0)])
        sim.step(int(round(t_end / dt)))
        tr = sim.truth()[:, 0, :]
        t, u = tr[:, sim.rec_names.index("t")], tr[:, sim.rec_names.index("u")]
        means = [float(np.mean(u[(t >= a) & (t < a + window)])) for a in np.arange(t0, t_end - window + 1.0, window)]
        out.append({"seed": seed, "window_means": means})
    return out


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=str(ROOT / "benchmarks" / "results" / "radiation_timing.json"))
    a = ap.parse_args(argv)
    ves = load_vessel("patrol51")
    db = load_database(model_dir("patrol51") / "hydro" / "patrol51_hydro.nc")
    model = memory_model(db)
    rd = roll_damping_of(ves, db)
    t_start = time.time()
    surge = []
    for U0 in (7.3, 12.25):
        for omega in (0.7, 1.0, 1.3):
            for beta in (180.0, 145.0, 35.0):
                row = mean_surge(ves, db, model, U0, omega, beta)
                print(f"U {U0} ω {omega} β {beta}: speed loss {row['speed_loss']:+.4f} m/s, pitch {row['rms_pitch_deg']:.2f}°, "
                      f"roll {row['rms_roll_deg']:.2f}°", flush=True)
                surge.append(row)
    res = []
    for dt in (0.05, 0.02, 0.01):
        row = resonance(ves, db, model, rd, dt)
        print(f"dt {dt}: " + ", ".join(f"{c} {row[c]['amplitude_ratio']:.4f} ({row[c]['phase_deg']:+.2f}°)"
                                       for c in ("z", "roll", "pitch")), flush=True)
        res.append(row)
    blocks = following_run_scatter(ves, db, model)
    b = np.concatenate([x["window_means"] for x in blocks])
    print(f"180-s window means, 35° off the stern at 7.3 m/s: n {b.size}, mean {b.mean():.4f}, sd {b.std(ddof=1):.4f} m/s")
    Path(a.out).write_text(json.dumps({"ship": "patrol51", "regular_wave_mean_surge": surge, "resonance": res,
                                       "following_run_scatter": {"per_seed": blocks, "n": int(b.size), "mean": float(b.mean()),
                                                                 "sd": float(b.std(ddof=1))},
                                       "wall_s": time.time() - t_start}, indent=1))
    print("wrote", a.out)


if __name__ == "__main__":
    main()
