"""The simulator's own heave, roll and pitch RAOs at forward speed: the truth the design-stage model is
compared with (models/<ship>/design/README.md, benchmarks/design_rao_vs_truth.py).

The coupled six-DOF frequency-domain model of :func:`vtrials.physics.seakeeping.linearize.coupled_rao`
(the truth database's coefficients, ship.toml's restoring, the maneuvering model in surge/sway/yaw acting
on the motion relative to the waves' flow, the heading autopilot through the steering gear, the viscous roll damping of hull.toml, its quadratic part
linearised stochastically for a given roll-rate standard deviation) — the model the simulator
integrates, verified against it in tests/test_seakeeping_irregular.py.
"""

from __future__ import annotations

import math

import numpy as np

from vtrials.physics.seakeeping import linearize as LZ
from vtrials.physics.seakeeping.database import load_database
from vtrials.physics.seakeeping.timedomain import memory_model
from vtrials.physics.seakeeping.timedomain import flow_geometry, roll_damping_of, seakeeping_vessel
from vtrials.physics.simulator import Simulator
from vtrials.physics.vessel import load_vessel, model_dir


class TruthRAO:
    """Truth RAOs of ``ship`` at speed U [m/s] (self-propelled, heading held by its autopilot)."""

    def __init__(self, ship: str, U: float, dt: float = 0.05):
        self.vessel = load_vessel(ship)
        self.db = load_database(model_dir(ship) / "hydro" / f"{ship}_hydro.nc")
        model = memory_model(self.db)
        start = Simulator(self.vessel, 1, dt).self_propulsion(0, U)
        self.U = float(start.u)
        self.v0, _ = seakeeping_vessel(self.vessel, self.db, np.zeros((0, 6)), dt, model=model, drift=False)
        _, self.Jv, self.Je, self.Jd, self.Jf = LZ.force_jacobians(self.v0, start, dt, with_flow=True)
        self.flow = flow_geometry(self.vessel)
        self.Jc = LZ.coriolis_jacobian(self.v0, self.U)
        self.rd = roll_damping_of(self.vessel, self.db)
        ap = self.vessel.autopilot
        self.auto = (*ap.pid, float(self.vessel.steering[0, 2]))

    def rao(self, omega, mu: float, sigma_p: float = 0.0) -> np.ndarray:
        """(3, nω) complex heave (z down) [m/m], roll, pitch [rad/m] at O for waves travelling at μ [rad]
        relative to the heading (π head seas); quadratic roll damping linearised at roll-rate std σ_p [rad/s]."""
        beq = float(self.rd.stochastic(self.U, sigma_p)) - float(self.rd.B1(self.U))
        R = LZ.coupled_rao(self.v0, self.db, np.atleast_1d(omega), float(mu), self.U, self.Jv, self.Je, self.Jc,
                           roll_beq=beq, Jd=self.Jd, autopilot=self.auto, Jf=self.Jf, flow=self.flow)
        return R[:, 2:5].T

    def roll_rate_std(self, omega, S, mu: float, iters: int = 60) -> float:
        """σ_p of the roll rate in a long-crested sea S(ω) [m² s/rad] from μ (iterated with the damping)."""
        w = np.asarray(omega, dtype=float)
        we = np.abs(w - w * w * self.U * math.cos(mu) / self.db.g)
        sp = 0.0
        for _ in range(iters):
            R = self.rao(w, mu, sp)
            new = math.sqrt(float(np.trapezoid(np.abs(we * R[1]) ** 2 * S, w)))
            if abs(new - sp) < 1e-9:
                break
            sp = 0.5 * (sp + new)
        return sp
