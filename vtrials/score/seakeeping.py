"""Scoring a seakeeping trial: each leg's transfer functions against the true ones of the simulated
ship in the realised sea, its RMS motions against the true motions, the probe's H_s against the sea's.

True transfer function of a leg (what H₁ estimates, computed from truth, never from the records):

* the ship's RAO per wave component j (amplitude a_j, frequency ω_j, direction μ_j) at the leg's true
  mean speed through the water U and heading ψ, relative heading β_j = μ_j − ψ: the coupled six-DOF RAO
  of the system the simulator integrates (:func:`vtrials.physics.seakeeping.linearize.coupled_rao`:
  maneuvering model in the horizontal DOFs, the ship's heading autopilot and steering gear, radiation
  memory, the quadratic roll damping linearised stochastically at the roll-rate RMS predicted for this
  sea, iterated); its phase refers to a crest at the body origin O;
* at the probe's footprint r_p = (x_p, y_p) the wave phase is −k_j(x_p cos β_j + y_p sin β_j), so the
  component's probe-referred transfer function is RAO_j e^{+i k_j (x_p cos β_j + y_p sin β_j)}; heave of
  the IMU's site (up) is −(ξ₃ + y_s ξ₄ − x_s ξ₅), its vertical acceleration −ω_e² times that; roll ξ₄,
  pitch ξ₅. Components met at a negative encounter frequency ω_e,j = ω_j − k_j V_g·(cos μ_j, sin μ_j)
  (V_g the true mean ground velocity: the waves are fixed to the earth) are recorded at |ω_e,j| with the
  conjugate transfer function; components outside the hydrodynamic database's band do not move the
  ship (as in :func:`vtrials.scenario.sea_vessel`);
* in a Welch bin ω_b the expected cross-spectra are the components' sums weighted by the Hann
  window's spectral window |W(|ω_e,j| − ω_b)|² (segment length T_s: W ∝ sinc(x)/(1 − x²), x =
  (|ω_e,j| − ω_b) T_s/2π): H_true(ω_b) = Σ a_j² W_jb H_j / Σ a_j² W_jb. In a short-crested sea this is a
  direction-average of the RAO (the point probe cannot separate directions); the long-crested RAO at the
  sea's mean direction (``H_rao_mean_direction``) is reported beside it.

Scored in the bins the reduction reports as determined (γ² > 0.8, issue 13, and the response holding
at least 1 % of its spectral peak: :mod:`vtrials.reduce.seakeeping`): relative amplitude error, phase
error, whether the 95 % intervals cover the truth; the same over all γ² > 0.8 bins as ``all_coherent``.
"""

from __future__ import annotations

import math

import numpy as np
from scipy import stats

from vtrials.units import G

RESP = ("heave", "vertical_acc", "roll", "pitch")


def _window_weight(x: np.ndarray) -> np.ndarray:
    """|W|² of the Hann window at x bins from its centre (continuous-time form, normalised to 1 at 0)."""
    x = np.asarray(x, float)
    d = 1.0 - x * x
    near = np.abs(d) < 1e-9
    w = np.where(near, 0.5, np.sinc(x) / np.where(near, 1.0, d))
    return w * w


def binned_transfer(amp, omega_e, H, wb, Ts: float) -> tuple[np.ndarray, np.ndarray]:
    """(H_true, γ²_true) on Welch bins ``wb`` [rad/s] of segment length ``Ts`` [s] from components of
    amplitude ``amp`` met at signed encounter frequencies ``omega_e`` with complex transfer functions
    ``H`` (input → output, e^{+iω_e t} convention): the ratio of the expected Hann-window cross- and
    auto-spectra (module doc); a component met at ω_e < 0 is recorded at |ω_e| with H conjugated."""
    amp, we, H = (np.asarray(v) for v in (amp, omega_e, H))
    x = (np.abs(we)[:, None] - np.asarray(wb, float)[None, :]) * Ts / (2 * math.pi)
    Wt = _window_weight(x) * (0.5 * np.asarray(amp, float) ** 2)[:, None]  # (n, nb)
    hp = np.where(we < 0, np.conj(H), H)[:, None]
    sxx = Wt.sum(axis=0)
    sxy = (Wt * hp).sum(axis=0)
    with np.errstate(invalid="ignore", divide="ignore"):
        return sxy / sxx, np.abs(sxy) ** 2 / (sxx * (Wt * np.abs(hp) ** 2).sum(axis=0))


class _ShipModel:
    """The simulated ship's linearisation pieces, built once per scenario (speed-dependent parts cached)."""

    def __init__(self, scn, hydro_path):
        from vtrials.physics.seakeeping.database import load_database
        from vtrials.physics.seakeeping.sea_ship import sea_ship
        from vtrials.physics.seakeeping.timedomain import roll_damping_of
        self.scn = scn
        self.ves = scn.vessel
        self.db = load_database(hydro_path)
        self.dt = scn.head.timestep_s
        self.v0, _ = sea_ship(scn.vessel, self.db, np.zeros((0, 6)), self.dt, mean_force="none")
        self.rd = roll_damping_of(scn.vessel, self.db)
        self._jac = {}
        self._flow = {}

    def jacobians(self, U: float):
        from vtrials.physics.seakeeping import linearize as LZ
        from vtrials.physics.seakeeping.timedomain import flow_geometry
        from vtrials.physics.simulator import Simulator
        key = round(U, 3)
        if key not in self._jac:
            start = Simulator(self.ves, 1, self.dt).self_propulsion(0, U)
            _, Jv, Je, Jd, Jf = LZ.force_jacobians(self.v0, start, self.dt, with_flow=True)
            Jc = LZ.coriolis_jacobian(self.v0, start.u)
            self._jac[key] = (start.u, Jv, Je, Jd, Jc)
            self._flow[key] = dict(Jf=Jf, flow=flow_geometry(self.ves))
        return self._jac[key]

    def flow_kw(self, U: float) -> dict:
        """The waves'-flow arguments of :func:`~vtrials.physics.seakeeping.linearize.coupled_rao` at speed U
        (the maneuvering forces see the motion relative to the waves' flow, as in the time domain)."""
        self.jacobians(U)
        return self._flow[round(U, 3)]

    def linear_parts(self, U: float):
        """(u, J_ν, J_η, J_δ, J_c, autopilot) of the linearisation at speed U (the ship's own heading
        autopilot: PID gains and the steering gear's time constant)."""
        u, Jv, Je, Jd, Jc = self.jacobians(U)
        ap = self.ves.autopilot
        auto = (*ap.pid, float(self.ves.steering[0, 2]))
        return u, Jv, Je, Jd, Jc, auto

    def component_raos(self, comp: np.ndarray, psi: float, U: float) -> tuple[np.ndarray, np.ndarray, float]:
        """RAOs (n, 6) of every component at heading ψ and speed U, their β, and the roll-rate RMS used."""
        from vtrials.physics.seakeeping import linearize as LZ
        from vtrials.physics.seakeeping.rao import encounter_frequency
        u, Jv, Je, Jd, Jc, auto = self.linear_parts(U)
        mu = np.arctan2(comp[:, 4], comp[:, 3])
        beta = np.remainder(mu - psi + math.pi, 2 * math.pi) - math.pi
        n = comp.shape[0]
        R = np.zeros((n, 6), dtype=complex)
        we = encounter_frequency(comp[:, 1], beta, U, self.db.g)
        sigma_p = 0.0
        b1 = float(self.rd.B1(U))
        for _ in range(30):
            beq = float(self.rd.stochastic(U, sigma_p)) - b1  # B₁ is in J_ν already
            for j in range(n):
                R[j] = LZ.coupled_rao(self.v0, self.db, comp[j:j + 1, 1], float(beta[j]), U, Jv, Je, Jc, roll_beq=beq,
                                      Jd=Jd, autopilot=auto, **self.flow_kw(U))[0]
            new = math.sqrt(float(np.sum(0.5 * comp[:, 0] ** 2 * np.abs(we * R[:, 3]) ** 2)))
            if abs(new - sigma_p) <= 1e-4 * max(new, 1e-9):
                sigma_p = new
                break
            sigma_p = new
        return R, beta, sigma_p


def true_transfer(model: _ShipModel, comp: np.ndarray, ref: dict, leg: dict, probe_xy, imu_xy) -> dict:
    """Probe-referred true transfer functions on the leg's Welch bins (module doc)."""
    db = model.db
    U = float(ref["u_r_mean"])
    psi = float(ref["heading"])
    vg = np.asarray(ref["ground_velocity_ne"], float)
    band = (comp[:, 1] >= 0.5 * db.omega[0]) & (comp[:, 1] <= db.omega[-1])
    R = np.zeros((comp.shape[0], 6), dtype=complex)
    Rb, beta_b, sigma_p = model.component_raos(comp[band], psi, U)
    R[band] = Rb
    mu = np.arctan2(comp[:, 4], comp[:, 3])
    beta = np.remainder(mu - psi + math.pi, 2 * math.pi) - math.pi
    k = comp[:, 2]
    we = comp[:, 1] - k * (vg[0] * comp[:, 3] + vg[1] * comp[:, 4])
    xp, yp = probe_xy
    xs, ys = imu_xy
    ph = np.exp(1j * k * (xp * np.cos(beta) + yp * np.sin(beta)))
    heave = -(R[:, 2] + ys * R[:, 3] - xs * R[:, 4])
    H = {"heave": heave, "vertical_acc": -we ** 2 * heave, "roll": R[:, 3], "pitch": R[:, 4]}
    wb = np.asarray(leg["omega_e"], float)
    Ts = float(leg["segment_s"])
    out = {"u_r": U, "heading": psi, "sigma_roll_rate": sigma_p}
    for name, h in H.items():
        Ht, coh = binned_transfer(comp[:, 0], we, h * ph, wb, Ts)
        out[name] = {"H_re": Ht.real.tolist(), "H_im": Ht.imag.tolist(), "coherence": coh.tolist()}
    # the long-crested RAO at the sea's true mean direction (for the plots), where ω_e has one wave frequency
    from vtrials.reduce.encounter import wave_frequencies
    w = model.scn.waves
    mu0 = math.radians(w.direction_deg) + math.pi
    beta0 = math.remainder(mu0 - psi, 2 * math.pi)
    W = wave_frequencies(wb, U, beta0)
    unique = ~np.isfinite(W[:, 1]) & np.isfinite(W[:, 0]) & (W[:, 0] >= db.omega[0]) & (W[:, 0] <= db.omega[-1])
    from vtrials.physics.seakeeping import linearize as LZ
    u, Jv, Je, Jd, Jc, auto = model.linear_parts(U)
    beq = float(model.rd.stochastic(U, sigma_p)) - float(model.rd.B1(U))
    rao0 = {n: np.full(wb.size, np.nan + 0j) for n in RESP}
    if np.any(unique):
        om = W[unique, 0]
        R0 = LZ.coupled_rao(model.v0, db, om, beta0, U, Jv, Je, Jc, roll_beq=beq, Jd=Jd, autopilot=auto,
                            **model.flow_kw(U))
        k0 = om ** 2 / G
        we0 = om - k0 * U * math.cos(beta0)
        ph0 = np.exp(1j * k0 * (xp * math.cos(beta0) + yp * math.sin(beta0)))
        hv = -(R0[:, 2] + ys * R0[:, 3] - xs * R0[:, 4])
        for n, h in (("heave", hv), ("vertical_acc", -we0 ** 2 * hv), ("roll", R0[:, 3]), ("pitch", R0[:, 4])):
            rao0[n][unique] = h * ph0
    for n in RESP:
        out[n]["H_rao_mean_direction_re"] = rao0[n].real.tolist()
        out[n]["H_rao_mean_direction_im"] = rao0[n].imag.tolist()
    return out


def _score_tf(red: dict, tru: dict, wb: np.ndarray, coh_min: float, omega_min: float) -> dict:
    """Errors and coverage in the bins the reduction reports as determined; ``all_coherent``: the same
    statistics over every bin with γ² > coh_min above omega_min (the tails included), for transparency."""
    H = np.asarray(red["H_re"]) + 1j * np.asarray(red["H_im"])
    Ht = np.asarray(tru["H_re"]) + 1j * np.asarray(tru["H_im"])
    coh = np.asarray(red["coherence"])
    allc = (coh > coh_min) & (wb > omega_min) & np.isfinite(Ht) & (np.abs(Ht) > 0)
    sel = allc & np.asarray(red["determined"], bool)
    amp_err = np.abs(H) / np.abs(Ht) - 1.0
    ph_err = np.angle(H * np.conj(Ht))
    lo, hi = np.asarray(red["amp_lo95"]), np.asarray(red["amp_hi95"])
    eps = np.asarray(red["phase_error"])
    cov_a = (lo <= np.abs(Ht)) & (np.abs(Ht) <= hi)
    cov_p = np.abs(ph_err) <= float(red.get("z95", 1.959963984540054)) * eps
    n = int(sel.sum())
    d = {"bins": n, "omega_e": wb[sel].tolist(), "amp_error": amp_err[sel].tolist(), "phase_error": ph_err[sel].tolist(),
         "amp_covered": cov_a[sel].tolist(), "phase_covered": cov_p[sel].tolist(),
         "amp_half_width": (0.5 * (hi - lo) / np.abs(Ht))[sel].tolist()}
    if n:
        # the share of bins within 10 % that the reduction's own random error allows: per bin
        # P(|t_ν| ≤ 0.10/ε_b), ν = 2n_d − 2, ε_b the bin's relative amplitude error (module doc of
        # vtrials.reduce.seakeeping) — the 25-min acceptance "within 10 %" read against the random error
        nu = max(2.0 * float(red["n_d"]) - 2.0, 1.0)
        ea = np.asarray(red["amp_error"], float)[sel]
        p = 2.0 * stats.t.cdf(0.10 / ea, nu) - 1.0
        d["expected_within_10pct"] = float(np.mean(p))
        d["expected_within_10pct_var"] = float(np.sum(p * (1.0 - p))) / n ** 2
        d.update({"median_abs_amp_error": float(np.median(np.abs(amp_err[sel]))),
                  "max_abs_amp_error": float(np.max(np.abs(amp_err[sel]))),
                  "within_10pct": float(np.mean(np.abs(amp_err[sel]) <= 0.10)),
                  "amp_coverage": float(np.mean(cov_a[sel])), "phase_coverage": float(np.mean(cov_p[sel]))})
    if allc.any():
        d["all_coherent"] = {"bins": int(allc.sum()), "median_abs_amp_error": float(np.median(np.abs(amp_err[allc]))),
                             "within_10pct": float(np.mean(np.abs(amp_err[allc]) <= 0.10)),
                             "amp_coverage": float(np.mean(cov_a[allc]))}
    return d


def score_seakeeping(reduced: dict, res, name: str) -> dict:
    """Per leg: the true transfer functions and motions, the errors and coverage (module doc)."""
    from vtrials.score.trials import _truth_of
    scn = res.scenario
    truth = _truth_of(res.crew, name)
    comp = np.asarray(res.seaway, float)
    model = _ShipModel(scn, res.hydro_path) if reduced.get("legs") else None
    iset = res.crew.iset
    probe = [d for d in iset.devices.values() if d.kind == "wave_probe"]
    imu = [d for d in iset.devices.values() if d.kind == "imu"]
    hs_true = 4.0 * math.sqrt(float(np.sum(0.5 * comp[:, 0] ** 2)))
    legs = []
    coh_min = float(reduced.get("coherence_min", 0.8))
    for leg in reduced.get("legs", []):
        ref = truth.get(leg["run"])
        if ref is None or not probe or not imu:
            continue
        tt = true_transfer(model, comp, ref, leg, probe[0].site[:2], imu[0].site[:2])
        wb = np.asarray(leg["omega_e"], float)
        sc = {"run": leg["run"], "label": leg["label"], "truth": {"hs": hs_true, "u_r": ref["u_r_mean"],
                                                                   "heading": ref["heading"], "stw": ref["stw"]}}
        h = leg["hs_probe"]
        sc["hs_probe"] = {"truth": hs_true, "reduced": h["value"], "error": h["value"] / hs_true - 1.0,
                          "covered": bool(h["lo95"] <= hs_true <= h["hi95"])}
        sc["rms"] = {}
        sc["transfer"] = {}
        for n in RESP:
            r = leg["responses"][n]
            tr = ref.get(f"{n}_rms")
            if tr is not None:
                sc["rms"][n] = {"truth": tr, "reduced": r["rms"]["value"], "error": r["rms"]["value"] / tr - 1.0,
                                "lo95": r["rms"]["lo95"], "hi95": r["rms"]["hi95"]}
            sc["transfer"][n] = _score_tf(r, tt[n], wb, coh_min, 1.2 * float(leg["omega_c"]))
        sc["true_transfer"] = tt
        legs.append(sc)
    summary = {}
    for n in RESP:
        errs = [e for L in legs for e in L["transfer"][n]["amp_error"]]
        cov = [c for L in legs for c in L["transfer"][n]["amp_covered"]]
        pcov = [c for L in legs for c in L["transfer"][n]["phase_covered"]]
        if errs:
            a = np.abs(np.asarray(errs))
            m = [L["transfer"][n]["bins"] for L in legs]
            ew = sum(L["transfer"][n].get("expected_within_10pct", 0.0) * k for L, k in zip(legs, m)) / len(errs)
            summary[n] = {"bins": len(errs), "median_abs_amp_error": float(np.median(a)), "max_abs_amp_error": float(a.max()),
                          "within_10pct": float(np.mean(a <= 0.10)), "expected_within_10pct": float(ew),
                          "amp_coverage": float(np.mean(cov)), "phase_coverage": float(np.mean(pcov))}
    out = {"reduced": reduced, "truth": {"hs": hs_true, "directional_spectrum": directional_spectrum(comp)},
           "legs": legs, "summary": summary}
    if reduced.get("ship_buoy"):
        out["ship_buoy"] = score_ship_buoy(reduced["ship_buoy"], comp, truth)
    if reduced.get("wave_fusion"):
        out["wave_fusion"] = score_wave_fusion(reduced["wave_fusion"], comp)
    return out


def score_wave_fusion(wf: dict, comp: np.ndarray) -> dict:
    """Seed 004's comparison on one trial: per leg the radar's and each fused H_s over the sea's
    (:func:`vtrials.truth.seaway.sea_truth`); over the legs the standard deviation of each ratio, the
    radar's over the fused one (seed 004's scatter reduction) and the legs within 15 % of the truth."""
    from vtrials.truth.seaway import sea_truth
    hs = sea_truth(comp)["hs"]
    legs = [{"run": L["run"], "label": L["label"], "hs_true": hs, "radar_ratio": L["hs_radar"] / hs,
             "fused_ratio": {k: v / hs for k, v in L["hs_fused"].items()}} for L in wf["legs"]]
    summary = {}
    if legs:
        rad = np.array([L["radar_ratio"] for L in legs])
        sd_r = float(np.std(rad, ddof=1)) if rad.size > 1 else float("nan")
        summary["radar"] = {"mean": float(np.mean(rad)), "std": sd_r, "within_15pct": int(np.sum(np.abs(rad - 1) <= 0.15))}
        for k in wf["combos"]:
            f = np.array([L["fused_ratio"][k] for L in legs])
            sd = float(np.std(f, ddof=1)) if f.size > 1 else float("nan")
            summary[k] = {"mean": float(np.mean(f)), "std": sd, "scatter_reduction": sd_r / sd if sd > 0 else float("nan"),
                          "within_15pct": int(np.sum(np.abs(f - 1) <= 0.15))}
    return {"hs_true": hs, "legs": legs, "summary": summary}


#: Acceptance of a ship-as-buoy estimate (issue 13): H_s within 15 %, mean direction within 15°.
BUOY_HS_TOL, BUOY_DIR_TOL_DEG = 0.15, 15.0


def score_ship_buoy(sb: dict, comp: np.ndarray, truth: dict) -> dict:
    """The ship-as-buoy sea (:func:`vtrials.reduce.seakeeping.ship_buoy_block`) against the true sea, per leg:
    H_s against the components' (:func:`vtrials.truth.seaway.sea_truth`), the direction the waves come from
    relative to the bow against the components' mean direction relative to the leg's true mean heading,
    and the side (port/starboard; legs whose true waves are within 10° of the bow–stern line have none).
    Summaries over all legs and over the legs flagged reliable."""
    from vtrials.truth.seaway import sea_truth
    legs = []
    for leg in sb["legs"]:
        ref = truth.get(leg["run"])
        if ref is None:
            continue
        st = sea_truth(comp, ref["heading"])
        d = math.degrees(math.remainder(math.radians(leg["from_rel_deg"] - st["from_rel_deg"]), 2 * math.pi))
        true_rel = st["from_rel_deg"]
        legs.append({"run": leg["run"], "label": leg["label"], "reliable": leg["reliable"], "hs_true": st["hs"],
                     "hs_error": sb["hs"] / st["hs"] - 1.0, "from_rel_true_deg": true_rel,
                     "from_rel_deg": leg["from_rel_deg"], "dir_error_deg": d,
                     "side_right": bool(abs(true_rel) < 10.0 or abs(true_rel) > 170.0
                                        or math.copysign(1.0, leg["from_rel_deg"]) == math.copysign(1.0, true_rel))})
    summary = {}
    for key, sel in (("all", legs), ("reliable", [L for L in legs if L["reliable"]])):
        if sel:
            ok_h = [abs(L["hs_error"]) <= BUOY_HS_TOL for L in sel]
            ok_d = [abs(L["dir_error_deg"]) <= BUOY_DIR_TOL_DEG for L in sel]
            summary[key] = {"legs": len(sel), "hs_within_15pct": int(sum(ok_h)), "dir_within_15deg": int(sum(ok_d)),
                            "side_right": int(sum(L["side_right"] for L in sel)),
                            "both": int(sum(a and b for a, b in zip(ok_h, ok_d))),
                            "max_abs_dir_error_deg": float(max(abs(L["dir_error_deg"]) for L in sel))}
    return {"legs": legs, "summary": summary}


def directional_spectrum(comp: np.ndarray, n_dir: int = 36, n_omega: int = 30, omega_max: float = 2.5) -> dict:
    """The sea's directional spectrum S(ω, θ) [m² s/rad/rad] binned from its components: θ the direction
    the waves come FROM (from north, clockwise) in ``n_dir`` sectors, ω in ``n_omega`` bins up to
    ``omega_max``; each component's variance a²/2 goes to its bin. ∬ S dω dθ = m0 (of the components
    below ``omega_max``)."""
    frm = np.remainder(np.arctan2(comp[:, 4], comp[:, 3]) + math.pi, 2 * math.pi)
    de = np.linspace(0.0, 2 * math.pi, n_dir + 1)
    we = np.linspace(0.0, omega_max, n_omega + 1)
    H, _, _ = np.histogram2d(comp[:, 1], frm, bins=(we, de), weights=0.5 * comp[:, 0] ** 2)
    S = H / (np.diff(we)[:, None] * np.diff(de)[None, :])
    return {"omega_edges": we.tolist(), "from_edges_rad": de.tolist(), "S": S.tolist()}
