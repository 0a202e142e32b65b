"""The ship as a wave buoy: fit the directional wave spectrum whose predicted response cross-spectra match
the measured ones.

Method (parametric, after Iseki & Ohtsu 2000, J. Mar. Sci. Technol. 5:1–13, and Nielsen 2006, Ocean Eng.
33:1237–1255 — the idea, not their Bayesian/discretised formulations): the sea is a JONSWAP spectrum
(γ = 3.3, Hasselmann et al. 1973) times a cos-2s spreading D(μ − μ₀) (Longuet-Higgins et al. 1963),
parameters θ = (H_s, T_p, μ₀, s). For responses m, n with complex RAOs H_m(ω, μ) (per metre of wave
amplitude; μ the wave propagation direction relative to the heading, 0 following, π head seas) the
predicted one-sided cross-spectrum at the measured |ω_e| is

    G_mn(|ω_e|) = Σ over (ω, μ) with |ω − ω²U cos μ/g| = |ω_e|  of  c_mn S(ω) D(μ) / |dω_e/dω|,
    c_mn = H_m* H_n for ω_e > 0 and H_m H_n* for ω_e < 0 (the response's phase reverses),

evaluated by sharing each cell of a fine (ω, μ) grid into the measurement's ω_e bins (so every branch of
following seas counts, :mod:`vtrials.reduce.encounter`). θ minimises the sum over bins and over the
upper triangle of G (real and imaginary parts) of ((G_pred − G_meas)/σ_mn)², σ_mn = √(max G_mm max G_nn)
(scipy.optimize.least_squares, several starting directions; the best fit is kept).

Port and starboard: heave and pitch RAOs are symmetric in μ ↔ −μ, roll antisymmetric, so only the
cross-spectra between roll and heave/pitch (their sign) tell the side the waves come from; the fit uses
them. The spectrum model is written out here (the reductions may not import the environment).

Several legs (:func:`fit_legs`, :func:`ship_buoy_from_legs`): one sea, fixed to the earth, fitted to the
cross-spectra of legs sailed on different headings (a star pattern). The mirror image of the sea differs
from leg to leg, so the legs' headings tell port from starboard where one leg needs roll — the least
certain response of a design-stage model, and at speed in bow seas one whose phase is far off the
ship's (lift on the waves' cross-flow). The idea is that of fusing several ships' motions into one sea
estimate (Nielsen, Brodtkorb & Sørensen 2019, Ocean Eng. 177:12–23), with one ship on several headings.

Roll tuning: a design-stage model's roll is the least certain of its responses (its damping is assumed,
its GM is the design one), and a wrong roll pulls the fitted direction. As Han, Sævik & Leira (2021,
Ocean Eng. 233:109084) tune a vessel's roll damping with the sea state, the fit can carry two more
parameters, a roll stiffness change ΔC₄₄ = κ_C C₄₄ and a roll damping change ΔB₄₄ = κ_B B_crit (the
design's C₄₄ and critical damping 2C₄₄/ω_n). Being a rank-one change of the design's impedance matrix Z,
it rescales the roll RAO exactly (Sherman–Morrison; heave and pitch are uncoupled from roll by symmetry):

    φ̂' = φ̂ / (1 + (ΔC₄₄ + iω_e ΔB₄₄) h_φ(ω_e)),   h_φ = (Z⁻¹)_φφ the design's roll receptance,

so the fit needs no new RAO solves.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
from scipy import optimize
from scipy.special import gammaln

from vtrials.errors import InputError
from vtrials.units import G

TWO_PI = 2.0 * math.pi
#: Bounds of a fitted roll stiffness change ΔC₄₄/C₄₄ and the largest roll damping change ΔB₄₄/B_crit.
ROLL_STIFFNESS_BOUNDS = (-0.3, 0.4)
ROLL_DAMPING_MAX = 0.3
GAMMA = 3.3  # JONSWAP peak enhancement (Hasselmann et al. 1973 mean)


def jonswap(omega, hs: float, tp: float, gamma: float = GAMMA):
    """JONSWAP S(ω) [m² s/rad], peak enhancement γ (default 3.3; 1 = Pierson–Moskowitz), σ = 0.07/0.09,
    scaled on the given grid so ∫S dω = H_s²/16."""
    w = np.asarray(omega, dtype=float)
    wp = TWO_PI / tp
    with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
        pm = np.where(w > 0.0, w ** -5.0 * np.exp(-1.25 * (wp / np.where(w > 0, w, 1.0)) ** 4), 0.0)
    sig = np.where(w <= wp, 0.07, 0.09)
    S = pm * gamma ** np.exp(-((w - wp) ** 2) / (2.0 * sig * sig * wp * wp))
    m0 = np.trapezoid(S, w)
    return S * (hs * hs / 16.0) / m0


def cos2s(dmu, s: float):
    """D(Δμ) = D₀ cos^{2s}(Δμ/2) [1/rad], D₀ = 2^{2s−1} Γ²(s+1)/(π Γ(2s+1))."""
    d0 = math.exp((2.0 * s - 1.0) * math.log(2.0) + 2.0 * gammaln(s + 1.0) - gammaln(2.0 * s + 1.0)) / math.pi
    return d0 * np.abs(np.cos(0.5 * np.asarray(dmu, dtype=float))) ** (2.0 * s)


@dataclasses.dataclass(frozen=True)
class ShipBuoyFit:
    """Fitted sea: H_s [m], T_p [s], μ₀ relative to the heading (towards, [rad], (−π, π]; from north for
    :func:`fit_legs`), s; residual cost."""

    hs: float
    tp: float
    mu0: float
    s: float
    cost: float
    G_pred: np.ndarray | tuple   # (n_bins, n, n); a tuple of them, one per leg, from :func:`fit_legs`
    gamma: float = GAMMA
    gains: tuple = ()
    roll: tuple = ()        # fitted (ΔC₄₄/C₄₄, ΔB₄₄/B_crit) when the roll was tuned, else ()

    def direction_from(self, heading: float) -> float:
        """Nautical direction the waves come FROM [rad], for the ship's heading [rad]."""
        return (heading + self.mu0 + math.pi) % TWO_PI


class ResponseModel:
    """Predicted response cross-spectra on measured ω_e bins for a sea (the forward model of the fit).

    ``omega`` (n_ω,) [rad/s] and ``mu`` (n_μ,) uniform over one turn [rad] form the grid on which the RAOs
    ``rao`` (n_resp, n_ω, n_μ) (complex, per metre of wave amplitude) are given; ``U`` [m/s] the speed;
    ``omega_e`` (n_bins,) the centres of the measurement's uniform encounter-frequency bins [rad/s].
    For roll tuning (module doc): ``roll_part`` (n_resp, n_ω, n_μ), the responses' part that comes from
    roll; ``roll_receptance`` (n_ω, n_μ) [rad/(N m)]; ``roll_scales`` (C₄₄ [N m/rad], B_crit [N m s/rad]).
    """

    def __init__(self, omega, mu, rao, U: float, omega_e, roll_part=None, roll_receptance=None,
                 roll_scales=(1.0, 1.0)):
        self.omega = np.asarray(omega, dtype=float)
        self.mu = np.asarray(mu, dtype=float)
        rao = np.asarray(rao, dtype=complex)
        if rao.ndim != 3 or rao.shape[1:] != (self.omega.size, self.mu.size):
            raise InputError("record", "rao", f"shape {rao.shape}: expected (n_responses, {self.omega.size}, "
                             f"{self.mu.size})")
        if not (math.isfinite(U) and U >= 0.0):
            raise InputError("record", "U", f"ship speed {U!r} m/s: must be a finite number ≥ 0")
        self.omega_e = np.asarray(omega_e, dtype=float)
        de = float(self.omega_e[1] - self.omega_e[0])
        n = rao.shape[0]
        W, M = np.meshgrid(self.omega, self.mu, indexing="ij")
        we = W - W * W * U * np.cos(M) / G
        # cell weights Δω Δμ (trapezoid in ω, rectangle in μ)
        dw = np.gradient(self.omega) if self.omega.size > 1 else np.ones(1)
        dw[0] *= 0.5 if self.omega.size > 1 else 1.0
        dw[-1] *= 0.5 if self.omega.size > 1 else 1.0
        cell = dw[:, None] * np.full(self.mu.size, TWO_PI / self.mu.size)[None, :]
        idx = np.rint((np.abs(we) - self.omega_e[0]) / de).astype(int)
        ok = (idx >= 0) & (idx < self.omega_e.size)
        self._idx = idx[ok]
        self._cell = cell[ok] / de
        self._ok = ok
        iu = np.triu_indices(n)
        self.pairs = iu
        Hm, Hn = rao[iu[0]][:, ok], rao[iu[1]][:, ok]
        pos = (we[ok] >= 0.0)[None, :]
        self._pos = pos
        self._c = np.where(pos, np.conj(Hm) * Hn, Hm * np.conj(Hn))  # (n_pairs, n_cells)
        self.n = n
        self.tunable = roll_part is not None and roll_receptance is not None
        if self.tunable:                  # roll stiffness/damping changes rescale the roll part (module doc)
            self._H = rao[:, ok]
            self._Hr = np.asarray(roll_part, dtype=complex)[:, ok]
            self._h = np.asarray(roll_receptance, dtype=complex)[ok]
            self._we = we[ok]
            self.roll_scales = (float(roll_scales[0]), float(roll_scales[1]))

    def _products(self, roll) -> np.ndarray:
        """c_mn per cell for roll stiffness/damping changes ``roll`` = (ΔC₄₄/C₄₄, ΔB₄₄/B_crit) (module doc)."""
        if roll is None or not self.tunable:
            return self._c
        c44, bc = self.roll_scales
        q = 1.0 / (1.0 + (roll[0] * c44 + 1j * self._we * roll[1] * bc) * self._h)
        H = self._H + self._Hr * (q - 1.0)[None, :]
        i, j = self.pairs
        return np.where(self._pos, np.conj(H[i]) * H[j], H[i] * np.conj(H[j]))

    def cross_spectra(self, hs: float, tp: float, mu0: float, s: float, gamma: float = GAMMA,
                      roll=None) -> np.ndarray:
        """G (n_bins, n_resp, n_resp) [response² s/rad] for the sea (H_s, T_p, μ₀, s; peak enhancement γ) and
        the ship's roll stiffness and damping changed by ``roll`` = (ΔC₄₄/C₄₄, ΔB₄₄/B_crit) (None: the model's)."""
        c = self._products(roll)
        S = jonswap(self.omega, hs, tp, gamma)
        D = cos2s(self.mu - mu0, s)
        E = (S[:, None] * D[None, :])[self._ok] * self._cell
        out = np.zeros((self.n * (self.n + 1) // 2, self.omega_e.size), dtype=complex)
        for p in range(out.shape[0]):
            out[p] = np.bincount(self._idx, weights=(c[p] * E).real, minlength=self.omega_e.size) + \
                1j * np.bincount(self._idx, weights=(c[p] * E).imag, minlength=self.omega_e.size)
        G_ = np.zeros((self.omega_e.size, self.n, self.n), dtype=complex)
        i, j = self.pairs
        G_[:, i, j] = out.T
        G_[:, j, i] = np.conj(out.T)
        return G_


def fit_directional_spectrum(model: ResponseModel, G_meas, starts: int = 8, hs0: float = 2.0,
                             tp0: float = 8.0, s0: float = 5.0, fit_gamma: bool = False,
                             free_gain=(), tune_roll: bool = False, roll_damping_min: float = -0.05) -> ShipBuoyFit:
    """Least-squares fit of (H_s, T_p, μ₀, s) to measured cross-spectra G_meas (n_bins, n, n) on model.omega_e.

    ``starts`` starting directions evenly spaced over one turn; bounds T_p ∈ [3, 25] s, s ∈ [0.5, 60].
    ``fit_gamma``: the peak enhancement γ is a fifth parameter, γ ∈ [1, 7] (1 Pierson–Moskowitz; 7 the
    upper end of JONSWAP's observed range, Hasselmann et al. 1973), started at 3.3; otherwise γ = 3.3.
    A ship filters out the short waves of a broad sea (most in head seas at speed): with γ fixed at 3.3
    a fully developed sea's H_s is under-read (measured on simulator records: benchmarks/shipbuoy_sim.py).
    ``free_gain``: indices of responses whose RAO is trusted in shape and phase but not in size (e.g. roll
    of a design-stage model with an assumed damping ratio): each gets a free scale κ ∈ [0.5, 2] on its
    RAO (G_mn → κ_m κ_n G_mn), so it tells direction and side without setting H_s.
    ``tune_roll`` (a model built with ``roll_part`` and ``roll_receptance``): the roll stiffness and damping
    changes (ΔC₄₄/C₄₄ within :data:`ROLL_STIFFNESS_BOUNDS`, ΔB₄₄/B_crit from ``roll_damping_min`` to
    :data:`ROLL_DAMPING_MAX`) are two more parameters fitted with the sea (module doc), started at 0.
    """
    return fit_legs([model], [G_meas], [0.0], starts=starts, hs0=hs0, tp0=tp0, s0=s0, fit_gamma=fit_gamma,
                    free_gain=free_gain, tune_roll=tune_roll, roll_damping_min=roll_damping_min)


def fit_legs(models, G_meas, headings, starts: int = 8, hs0: float = 2.0, tp0: float = 8.0, s0: float = 5.0,
             fit_gamma: bool = False, free_gain=(), tune_roll: bool = False,
             roll_damping_min: float = -0.05) -> ShipBuoyFit:
    """One sea fitted to the cross-spectra of several legs sailed on different ``headings`` [rad] (towards,
    from north): leg k sees the waves at μ₀ − ψ_k, so the fitted μ₀ is the waves' direction of travel from
    north (:meth:`ShipBuoyFit.direction_from` with heading 0 gives where they come from). ``models`` and
    ``G_meas`` are per leg as in :func:`fit_directional_spectrum` (which is this with one leg at heading 0);
    each leg's residuals are scaled by its own σ_mn. The roll stiffness and damping changes and the free
    gains are the ship's, shared by the legs. ``G_pred`` of the result is a tuple, one array per leg.

    Why several headings: heave and pitch are symmetric in μ ↔ −μ, so on one leg they cannot tell port
    from starboard and only roll (the design model's least certain response) can. On legs at different
    headings the mirror images of one sea disagree (a sea at θ seen from ψ₁ and ψ₂ mirrors to 2ψ₁ − θ and
    2ψ₂ − θ), so the headings fix the side; legs on reciprocal or equal courses do not (2ψ₁ = 2ψ₂ mod 2π).
    The legs must share one sea (stationary over the pattern, one or two hours).
    """
    models = list(models)
    G_meas = [np.asarray(G, dtype=complex) for G in G_meas]
    headings = [float(h) for h in headings]
    if not models or len(G_meas) != len(models) or len(headings) != len(models):
        raise InputError("record", "legs", f"{len(models)} models, {len(G_meas)} spectra, {len(headings)} "
                         "headings: need one of each per leg, at least one leg")
    n = models[0].n
    free_gain = tuple(int(k) for k in free_gain)
    nf = len(free_gain)
    base = 5 if fit_gamma else 4
    nt = 2 if tune_roll else 0
    if tune_roll and not all(m.tunable for m in models):
        raise InputError("record", "tune_roll", "the response model has no roll part and receptance")
    kt = base + nf

    def roll_of(x):
        return (x[kt], x[kt + 1]) if nt else None

    def gains(x):
        g = np.ones(n)
        for j, k in enumerate(free_gain):
            g[k] = math.exp(x[base + j])
        return g
    legs = []
    for k, (model, G, hd) in enumerate(zip(models, G_meas, headings)):
        if model.n != n or G.shape != (model.omega_e.size, n, n):
            raise InputError("record", "G_meas", f"leg {k}: shape {G.shape}: expected ({model.omega_e.size}, "
                             f"{n}, {n})")
        i, j = model.pairs
        diag = np.max(np.abs(np.diagonal(G, axis1=1, axis2=2)), axis=0)
        legs.append((model, G, hd, i, j, np.sqrt(diag[i] * diag[j])))

    def predict(x):
        hs, tp, s = math.exp(x[0]), math.exp(x[1]), math.exp(x[3])
        gamma = math.exp(x[4]) if fit_gamma else GAMMA
        g = gains(x)
        return [m.cross_spectra(hs, tp, x[2] - hd, s, gamma, roll_of(x)) * (g[:, None] * g[None, :])[None]
                for m, _, hd, _, _, _ in legs]

    def resid(x):
        out = []
        for Gp, (_, G, _, i, j, sigma) in zip(predict(x), legs):
            d = (Gp[:, i, j] - G[:, i, j]) / sigma[None, :]
            out += [d.real.ravel(), d.imag.ravel()]
        return np.concatenate(out)

    lo = [math.log(0.05), math.log(3.0), -np.inf, math.log(0.5)] + ([0.0] if fit_gamma else [])
    hi = [math.log(20.0), math.log(25.0), np.inf, math.log(60.0)] + ([math.log(7.0)] if fit_gamma else [])
    scale = [0.3, 0.2, 0.5, 0.5] + ([0.5] if fit_gamma else [])
    lo += [math.log(0.5)] * nf
    hi += [math.log(2.0)] * nf
    scale += [0.3] * nf
    lo += [ROLL_STIFFNESS_BOUNDS[0], float(roll_damping_min)][:nt]
    hi += [ROLL_STIFFNESS_BOUNDS[1], ROLL_DAMPING_MAX][:nt]
    scale += [0.1, 0.05][:nt]
    best = None
    for k in range(starts):
        x0 = [math.log(hs0), math.log(tp0), -math.pi + TWO_PI * (k + 0.5) / starts, math.log(s0)]
        x0 += ([math.log(GAMMA)] if fit_gamma else []) + [0.0] * nf + [0.0] * nt
        r = optimize.least_squares(resid, x0, bounds=(lo, hi), x_scale=scale, max_nfev=200)
        if best is None or r.cost < best.cost:
            best = r
    x = np.array(best.x)
    x[2] = math.remainder(x[2], TWO_PI)
    Gp = predict(x)
    return ShipBuoyFit(math.exp(x[0]), math.exp(x[1]), float(x[2]), math.exp(x[3]),
                       float(best.cost), Gp[0] if len(Gp) == 1 else tuple(Gp),
                       math.exp(x[4]) if fit_gamma else GAMMA, tuple(float(v) for v in gains(x)),
                       tuple(float(v) for v in roll_of(x)) if nt else ())


#: Smallest fraction of each fitted response's variance that must lie inside the fitted encounter band
#: for the run's result to count as reliable (:attr:`RecordBuoy.reliable`).
OBSERVED_MIN = 0.8


def observed_fraction(model: "ResponseModel", full: "ResponseModel", fit: ShipBuoyFit) -> tuple:
    """Per response: the fitted sea's response variance on ``model``'s bins ÷ that on ``full``'s bins (the
    same bins from 0 up to the band's upper edge)."""
    roll = fit.roll or None
    a = np.real(np.diagonal(model.cross_spectra(fit.hs, fit.tp, fit.mu0, fit.s, fit.gamma, roll), axis1=1, axis2=2))
    b = np.real(np.diagonal(full.cross_spectra(fit.hs, fit.tp, fit.mu0, fit.s, fit.gamma, roll), axis1=1, axis2=2))
    return tuple(float(x) for x in a.sum(axis=0) / np.maximum(b.sum(axis=0), 1e-300))


@dataclasses.dataclass(frozen=True)
class RecordBuoy:
    """Ship-as-a-wave-buoy result of one run: the fit, the ship's mean heading and speed, the components."""

    fit: ShipBuoyFit
    heading: float
    U: float
    components: tuple
    duration_s: float
    observed: tuple = ()          # per component: fraction of the fitted sea's response inside the band
    min_observed: float = OBSERVED_MIN

    @property
    def reliable(self) -> bool:
        """Whether the fit saw most of the responses it explains (every component's in-band fraction ≥
        ``min_observed``). Where the encounter frequencies fold (following seas at speed) much of the
        response lies below the band's lower edge, where the motions are high-passed away, and H_s is
        extrapolated from the spectrum's tail (Nielsen 2006 notes the same limit)."""
        return bool(self.observed) and min(self.observed) >= self.min_observed

    @property
    def from_relative_deg(self) -> float:
        """Where the waves come FROM relative to the bow [deg], + starboard, − port, in (−180, 180]."""
        return math.degrees(math.remainder(self.fit.mu0 + math.pi, TWO_PI))


@dataclasses.dataclass(frozen=True)
class LegSpectra:
    """One run's measured motion cross-spectra and the design model's forward models for them: ``model``
    on the fitted encounter band, ``full`` on the same bins from 0 up to the band's top (for the observed
    fraction); ``G`` (n_bins, n, n) measured on ``model.omega_e``; mean gyro heading [rad], log speed
    [m/s], duration [s], and the smallest roll damping change that leaves the design 2 % of critical."""

    model: ResponseModel
    full: ResponseModel
    G: np.ndarray
    heading: float
    U: float
    duration_s: float
    components: tuple
    roll_damping_min: float
    hs0: float


def leg_spectra(record, t0: float, t1: float, design, components=("heave", "roll", "pitch"),
                seg_s: float = 128.0, band=(0.2, 2.0), fs: float = 2.0, tune_roll: bool = True,
                instruments: dict | None = None) -> LegSpectra:
    """The run's motions by :func:`vtrials.reduce.seamotion.run_motions` between t0 and t1 [s], their
    cross-spectra by Welch with segments of ``seg_s`` [s] on the encounter-frequency ``band`` [rad/s], and
    the RAOs of ``design`` (a :class:`vtrials.reduce.design_rao.DesignRAO`) at the run's mean log speed on a
    0.2–2.5 rad/s × 5° grid — with the roll part and receptance when roll is tuned (module doc).
    ``instruments``: the record's instrument names by run_motions' role (imu, attitude, log, compass)
    where they are not the default ones."""
    from vtrials.reduce.seamotion import design_responses, run_motions
    from vtrials.reduce.spectra import cross_spectral_matrix

    components = tuple(components)
    mot = run_motions(record, t0, t1, fs_out=fs, **(instruments or {}))
    rec = mot.series(components)
    G_ = cross_spectral_matrix(rec, mot.fs, int(round(seg_s * mot.fs)))
    keep = (G_.omega >= band[0]) & (G_.omega <= band[1])
    omega = np.linspace(0.2, 2.5, 200)
    mu = np.linspace(-math.pi, math.pi, 72, endpoint=False)
    W, M = np.meshgrid(omega, mu, indexing="ij")
    R = design.rao(W, M, mot.U)
    rao = design_responses(design, components, W, M, mot.U, mot.site, R=R)
    tune = dict(roll_part=None, roll_receptance=None)
    if tune_roll and "roll" in components:
        Rr = R.copy()
        Rr[0] = 0.0
        Rr[2] = 0.0
        tune = dict(roll_part=design_responses(design, components, W, M, mot.U, mot.site, R=Rr),
                    roll_receptance=design.roll_receptance(W, M, mot.U), roll_scales=design.roll_scales)
    model = ResponseModel(omega, mu, rao, mot.U, G_.omega[keep], **tune)
    full = ResponseModel(omega, mu, rao, mot.U, G_.omega[G_.omega <= band[1]], **tune)
    hs0 = 4.0 * float(np.std(mot.heave)) if "heave" in components else 2.0
    return LegSpectra(model, full, G_.S[keep], mot.heading, mot.U, float(mot.t[-1] - mot.t[0]), components,
                      0.02 - design.roll_damping_ratio(mot.U) if model.tunable else 0.0, max(hs0, 0.2))


def ship_buoy_from_record(record, t0: float, t1: float, design, components=("heave", "roll", "pitch"),
                          seg_s: float = 128.0, band=(0.2, 2.0), fs: float = 2.0, starts: int = 8,
                          fit_gamma: bool = True, free_gain=(), tune_roll: bool = True) -> RecordBuoy:
    """Fit the directional sea to a run's measured motions (records only) with the team's design RAOs.

    Cross-spectra and forward models by :func:`leg_spectra` (``seg_s``, ``band``, ``fs``).
    γ is fitted (``fit_gamma``), and with roll among the components its stiffness and damping are tuned
    with the sea (``tune_roll``, module doc; the damping may fall to 2 % of critical at the least).
    On one leg only roll tells port from starboard, and at speed in bow seas the design model's roll
    phase is far from the ship's (benchmarks/results/campaign_wavefusion.json: 12 of 48 reliable star
    legs within 15°); :func:`ship_buoy_from_legs` fits one sea to several headings instead. A free roll
    gain (``free_gain`` names components given a free scale) gave worse directions. The result carries
    each component's observed fraction (the fitted sea's response inside the band ÷ from 0 to the band's
    top) and :attr:`RecordBuoy.reliable`.
    """
    leg = leg_spectra(record, t0, t1, design, components, seg_s, band, fs, tune_roll)
    fit = fit_directional_spectrum(leg.model, leg.G, starts=starts, hs0=leg.hs0, fit_gamma=fit_gamma,
                                   free_gain=[leg.components.index(c) for c in free_gain if c in leg.components],
                                   tune_roll=leg.model.tunable, roll_damping_min=leg.roll_damping_min)
    return RecordBuoy(fit, leg.heading, leg.U, leg.components, leg.duration_s,
                      observed_fraction(leg.model, leg.full, fit))


#: Smallest angle between two legs' courses (mod 180°) for the headings to tell port from starboard.
SIDE_MIN_ANGLE = math.radians(20.0)


@dataclasses.dataclass(frozen=True)
class StarBuoy:
    """One sea fitted to several legs (:func:`ship_buoy_from_legs`): the fit (μ₀ the waves' direction of
    travel from north), per leg the mean gyro heading [rad], log speed [m/s], duration [s] and observed
    fractions; ``side_from``: what tells port from starboard — "headings" (two courses at least
    :data:`SIDE_MIN_ANGLE` apart, mod 180°), "roll" (roll among the components, on parallel courses) or
    "none"."""

    fit: ShipBuoyFit
    headings: tuple
    U: tuple
    durations_s: tuple
    components: tuple
    observed: tuple
    side_from: str
    min_observed: float = OBSERVED_MIN

    @property
    def from_deg(self) -> float:
        """Nautical direction the waves come FROM [deg] (gyro north)."""
        return math.degrees(self.fit.direction_from(0.0))

    def from_relative_deg(self, k: int) -> float:
        """Where the waves came from relative to leg k's bow [deg], + starboard, − port, in (−180, 180]."""
        return math.degrees(math.remainder(self.fit.mu0 - self.headings[k] + math.pi, TWO_PI))

    def reliable(self, k: int) -> bool:
        """Whether the fitted sea's responses on leg k lie mostly inside the band (:attr:`RecordBuoy.reliable`)."""
        return bool(self.observed[k]) and min(self.observed[k]) >= self.min_observed


def side_evidence(headings, components) -> str:
    """"headings" when two courses differ by at least :data:`SIDE_MIN_ANGLE` mod 180° (their mirror images of
    one sea disagree, :func:`fit_legs`), else "roll" when roll is measured, else "none"."""
    h = [float(v) for v in headings]
    for a in range(len(h)):
        for b in range(a + 1, len(h)):
            if abs(math.sin(h[a] - h[b])) >= math.sin(SIDE_MIN_ANGLE):
                return "headings"
    return "roll" if "roll" in components else "none"


def ship_buoy_from_legs(record, windows, design, components=("heave", "roll", "pitch"), seg_s: float = 128.0,
                        band=(0.2, 2.0), fs: float = 2.0, starts: int = 8, fit_gamma: bool = True,
                        tune_roll: bool = True, instruments: dict | None = None) -> StarBuoy:
    """One directional sea fitted to the motions of several runs of one record — the legs of a star
    pattern, each held on its course — with the team's design RAOs (records only).

    ``windows``: the legs' (t0, t1) [s]; ``instruments`` as in :func:`leg_spectra`. Each leg's
    cross-spectra and forward model by :func:`leg_spectra`, the fit by :func:`fit_legs` (the sea in the
    earth frame, the roll tuning shared). On legs at different headings the geometry tells port from
    starboard, not roll's phase (``side_from``). On the seakeeping campaign of
    benchmarks/campaign_wavefusion.py (16 star patterns of patrol51 at 9 m/s over H_s 1.5–5 m: head, both
    bows and following, 25 min each): H_s within 15 % and direction within 15° on all 64 legs (largest
    direction error 8°), where leg by leg the directions held on 12 of the 48 reliable legs. On
    reciprocal courses (a standardization day) roll alone tells the side and, with the design model's
    roll at speed, does not (benchmarks/results/shipbuoy_sim.json, "day_fit"). The legs must share one
    sea: in a real sea, legs within an hour or two.
    """
    windows = [(float(a), float(b)) for a, b in windows]
    if not windows:
        raise InputError(str(getattr(record, "path", "record")), "windows", "no legs: give at least one (t0, t1)")
    legs = [leg_spectra(record, t0, t1, design, components, seg_s, band, fs, tune_roll, instruments)
            for t0, t1 in windows]
    tunable = all(leg.model.tunable for leg in legs)
    fit = fit_legs([leg.model for leg in legs], [leg.G for leg in legs], [leg.heading for leg in legs],
                   starts=starts, hs0=float(np.median([leg.hs0 for leg in legs])), fit_gamma=fit_gamma,
                   tune_roll=tunable, roll_damping_min=max(leg.roll_damping_min for leg in legs) if tunable else 0.0)
    observed = []
    for leg in legs:
        one = dataclasses.replace(fit, mu0=math.remainder(fit.mu0 - leg.heading, TWO_PI))
        observed.append(observed_fraction(leg.model, leg.full, one))
    return StarBuoy(fit, tuple(leg.heading for leg in legs), tuple(leg.U for leg in legs),
                    tuple(leg.duration_s for leg in legs), tuple(components), tuple(observed),
                    side_evidence([leg.heading for leg in legs], components))
