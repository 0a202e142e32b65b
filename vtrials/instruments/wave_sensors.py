"""Instruments that sense the SEA, not the ship: directional wave buoys (moored, drifting), the X-band
wave radar (WaMoS-like), and the bow relative-motion meter (the sea at a hull site minus the site's
own vertical motion).

How they read the sea. Ship instruments read truth columns (the ship's state per step). These read the
scenario's seaway itself: the realized wave components (:class:`vtrials.physics.environment.waves.WaveField`,
the same components the ship's wave loads are built from) are attached to the device before the run
(:meth:`vtrials.instruments.suite.InstrumentSet.attach_sea`, done by :func:`vtrials.scenario.instrument_set`
only when a suite or scenario lists such a device — existing scenarios are untouched), and the device
evaluates the linear sea (elevation, slopes, orbital displacements) at its own position and its own
sample instants. The truth chunks only drive the device's clock (and, for the relative-motion meter and
the radar, give the ship's position). A calm scenario attaches ``None``: the devices read a flat sea.

Directions μ [rad] are where waves go TOWARDS, from north clockwise (as in
:mod:`vtrials.physics.environment.waves` and :mod:`vtrials.reduce.directional`); nautical "from" is μ + π.

1. X-band wave radar (:class:`WaveRadar`, seed 004: WaMoS II, Stredulinsky & Thornhill 2009, DRDC Atlantic
   TM 2009-…): every ``cycle_s`` (2 min: 32 images) a directional spectrum of the sea around the ship on a
   frequency × direction grid (WaMoS II: 64 frequencies up to 0.35 Hz, 90 directions at 4°). Shape: the
   truth components' energy a²/2 spread by the radar's resolution kernels — Gaussian in ω (σ = 2π ×
   ``frequency_resolution_hz``) and wrapped Gaussian in μ (σ = ``direction_resolution_deg``) — times a
   per-bin sampling fluctuation χ²_ν/ν (ν = ``spectral_dof``), rotated by the installation's heading
   alignment error (``direction_bias_deg``). Height: H_s is not measured from the image but from the
   signal-to-noise ratio through a calibration (seed 004 §2), so the spectrum is scaled to
       H_s,radar = K (1 + g(t)) (1 + e_k) H_s,sea,
   K ~ N(``hs_scale``) per installation and trial (the calibration's scale: seed 004's trial calibration
   read 1.51× the buoys on average, the best-fit recalibration 1.04×), g a Gauss–Markov process
   (``hs_gauss_markov``: SNR depends on wind and surface roughness, so the error wanders run to run; seed
   004: sd 0.23 of the run-mean ratio after recalibration) and e_k white per 2-min spectrum (``hs_noise``:
   the within-run scatter, seed 004 Fig. 6 / Tables 2–4). Peak period and peak direction are the radar
   processor's: of its own spectrum (good, since the shape is good). H_s,sea = 4 √(Σ a²/2) of the seaway.

2. Directional wave buoy (:class:`WaveBuoy`; Datawell DWR-MkIII / Triaxys, seed 004), moored at a point or
   drifting from it at a velocity drawn per trial. It measures, at its own position x_b(t) and sample
   instants (``sample_hz``), the heave η and either the horizontal displacements (accelerometer / GPS
   buoys: a surface particle moves a coth(kh) sin θ along μ) or the surface slopes (heave–pitch–roll
   discus: k sin θ along μ), θ = ω t − k·x_b(t) + ε (a drifting buoy sees Doppler-shifted frequencies).
   Its response is applied per component, exactly in the steady state: the buoy's band-pass of the
   double-integrating filter as the maker states it, magnitude only (a phase-linear FIR whose delay the
   buoy removes): |H(f)| = [1 + (f_hp/f)^{2n_hp}]^{-1/2} [1 + (f/f_lp)^{2n_lp}]^{-1/2} (Butterworth
   magnitudes; Datawell: 3 dB at 0.033 and 0.6 Hz, 24 dB/octave on the low side), times (1 + s) with the
   gain error s drawn per trial. Then white noise, resolution, and the compass error (a rotation of the
   horizontal pair by the heading bias drawn per trial). Every ``record_s`` (30 min) the buoy transmits what
   a real one does: the spectrum S(ω) and the first five Fourier coefficients a₁, b₁, a₂, b₂ per frequency
   (Longuet-Higgins et al. 1963) from Welch cross-spectra of its record (Hann, ``segment_s``, 50 % overlap),
   bulk H_s, peak period, mean direction and circular spread (Kuik et al. 1988) over its band, and its
   position. ``output = "series"`` emits the raw series instead (heave and the horizontal pair).

3. Bow relative-motion meter (:class:`RelativeMotion`, seed 004: TSK at 20 Hz): the distance of the sea
   surface below a fixed point on the hull, as a relative vertical motion r = η(x_s, y_s, t) + z_s(t)
   (z down: the site's height above the mean surface is −z_s), at the site's horizontal position; the
   incident seaway only (the ship's own radiated and diffracted waves and the bow wave are not modelled).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np
from scipy import signal

from vtrials.instruments import parts as P
from vtrials.instruments.devices import Device, SpecError, _dist
from vtrials.instruments.kinematics import SiteKinematics
from vtrials.physics.environment.waves import elevation
from vtrials.units import DEG

TWO_PI = 2.0 * math.pi


class SeaDevice(Device):
    """A device that evaluates the seaway (attached with :meth:`attach_sea` before ``process``)."""

    needs_sea = True
    hull_site_required = False  # the suite lets these go without an MJCF site (off-ship or area sensors)
    _sea_attached = False
    comp = np.zeros((0, 6))
    depth = math.inf

    def attach_sea(self, field) -> None:
        """The seaway it senses: a :class:`~vtrials.physics.environment.waves.WaveField` or None (calm)."""
        if field is None:
            self.comp, self.depth = np.zeros((0, 6)), math.inf
        else:
            self.comp = np.ascontiguousarray(field.components, dtype=np.float64)
            self.depth = float(field.depth_m)
        self._sea_attached = True
        self._base = None

    def _need_sea(self) -> None:
        if not self._sea_attached:
            raise RuntimeError(f"{self.kind} {self.name!r}: no seaway attached (InstrumentSet.attach_sea, "
                               f"done by vtrials.scenario.instrument_set)")

    @property
    def hs_sea(self) -> float:
        """H_s of the attached seaway, 4 √(Σ a²/2) [m]."""
        return 4.0 * math.sqrt(0.5 * float(np.sum(self.comp[:, 0] ** 2)))


def _num(spec: dict, key: str, default=None, lo: float | None = None, lo_open: bool = False, hi: float | None = None):
    v = spec.get(key, default)
    if v is None:
        raise SpecError(key, "missing")
    try:
        x = float(v)
    except (TypeError, ValueError):
        raise SpecError(key, f"expected a number, got {v!r}") from None
    bad = not math.isfinite(x) or (lo is not None and (x <= lo if lo_open else x < lo)) or (hi is not None and x > hi)
    if bad:
        rng = f"{'>' if lo_open else '>='} {lo}" if lo is not None else ""
        raise SpecError(key, f"{x!r} not allowed (expected a finite number {rng}{' and <= ' + str(hi) if hi is not None else ''})")
    return x


def wrapped_gaussian(d, sigma: float, n_wrap: int = 2):
    """Density [1/rad] of a Gaussian of sd ``sigma`` [rad] wrapped onto the circle, at angles d [rad]."""
    d = np.angle(np.exp(1j * np.asarray(d, dtype=float)))
    out = np.zeros(np.shape(d))
    for m in range(-n_wrap, n_wrap + 1):
        out = out + np.exp(-0.5 * ((d + TWO_PI * m) / sigma) ** 2)
    return out / (math.sqrt(TWO_PI) * sigma)


def smoothed_spectrum(comp, omega, mu, sigma_omega: float, sigma_mu: float, mu_offset: float = 0.0):
    """S(ω, μ) [m² s/rad²] on the grid omega × mu: each component's energy a²/2 spread by a Gaussian in
    ω (sd ``sigma_omega`` [rad/s]) and a wrapped Gaussian in μ (sd ``sigma_mu`` [rad]) about (ω_j, μ_j +
    ``mu_offset``). The kernels are densities, so the grid integral is the energy within the band."""
    comp = np.asarray(comp, dtype=float)
    if comp.shape[0] == 0:
        return np.zeros((np.size(omega), np.size(mu)))
    e = 0.5 * comp[:, 0] ** 2
    mu_j = np.arctan2(comp[:, 4], comp[:, 3]) + mu_offset
    Kw = np.exp(-0.5 * ((np.asarray(omega)[None, :] - comp[:, 1:2]) / sigma_omega) ** 2) / (math.sqrt(TWO_PI) * sigma_omega)
    Km = wrapped_gaussian(np.asarray(mu)[None, :] - mu_j[:, None], sigma_mu)
    return (Kw * e[:, None]).T @ Km


class WaveRadar(SeaDevice):
    """X-band wave radar (WaMoS-like): a directional spectrum every ``cycle_s``; module doc, section 1.

    Channels: ``hs`` (the radar's H_s from its signal-to-noise calibration), ``tp`` (peak period of its
    spectrum), ``peak_direction_to`` (direction of the spectrum's peak, towards), ``spectrum`` (time ×
    frequency × direction, m² s/rad², directions towards; grids in the record's metadata). Each spectrum
    is stamped at the end of its acquisition window.
    """

    kind = "wave_radar"
    extra_keys = {"cycle_s", "frequencies_hz", "n_directions", "frequency_resolution_hz", "direction_resolution_deg",
                  "spectral_dof", "hs_scale", "hs_gauss_markov", "hs_noise", "direction_bias_deg"}
    channels = {"hs": ("m", "significant wave height from the radar's signal-to-noise calibration"),
                "tp": ("s", "peak period of the radar spectrum"),
                "peak_direction_to": ("rad", "direction of the radar spectrum's peak, waves going towards (0..2π)"),
                "spectrum": ("m2 s rad-2", "directional wave spectrum S(omega, mu), mu towards (grids in metadata)")}

    def build(self):
        s = self.spec
        self.cycle = _num(s, "cycle_s", 120.0, lo=1.0)
        fr = s.get("frequencies_hz", [0.03, 0.35, 64])
        if not (isinstance(fr, list) and len(fr) == 3):
            raise SpecError("frequencies_hz", f"expected [lowest, highest, count], got {fr!r}")
        f_lo, f_hi, n_f = float(fr[0]), float(fr[1]), int(fr[2])
        if not (0.0 < f_lo < f_hi and n_f >= 4):
            raise SpecError("frequencies_hz", f"expected 0 < lowest < highest and count >= 4, got {fr!r}")
        self.omega = TWO_PI * np.linspace(f_lo, f_hi, n_f)
        n_d = int(_num(s, "n_directions", 90, lo=8))
        self.mu = (np.arange(n_d) + 0.5) * TWO_PI / n_d
        self.sig_w = TWO_PI * _num(s, "frequency_resolution_hz", 0.006, lo=0.0, lo_open=True)
        self.sig_mu = _num(s, "direction_resolution_deg", 6.0, lo=0.0, lo_open=True) * DEG
        self.nu = _num(s, "spectral_dof", 30.0, lo=2.0)
        self.k_mean, self.k_sd = _dist(s, "hs_scale")
        self.k_mean = self.k_mean or 1.0
        gm = s.get("hs_gauss_markov", {"sd": 0.0, "tau_s": 3600.0})
        self.gm = P.GaussMarkov(_num(gm, "tau_s", lo=0.0, lo_open=True), _num(gm, "sd", lo=0.0))
        self.white = P.WhiteNoise(_num(s, "hs_noise", 0.0, lo=0.0))
        self.dir_mean, self.dir_sd = _dist(s, "direction_bias_deg", DEG)
        self.chain = P.Chain([])
        self.channels = dict(type(self).channels)

    def reset(self, rng):
        r1, r2, r3, r4, r5 = rng.spawn(5)
        self.K = self.k_mean + self.k_sd * float(r1.standard_normal())
        self.dir_bias = self.dir_mean + self.dir_sd * float(r1.standard_normal())
        self.gm.reset(r2)
        self.white.reset(r3)
        self._bins = r4
        self._clock = P._Clock(self.cycle, float(r5.uniform(0.0, self.cycle)))
        self._started = False
        self._base = None

    def spectrum_at(self, factor: float) -> tuple[np.ndarray, float]:
        """(S (n_f, n_dir), H_s,radar) of one acquisition with H_s factor K(1 + g)(1 + e) = ``factor``."""
        if self._base is None:  # the seaway is stationary: its smoothed image is the same every cycle
            self._base = smoothed_spectrum(self.comp, self.omega, self.mu, self.sig_w, self.sig_mu, self.dir_bias)
        S = self._base * (self._bins.chisquare(self.nu, self._base.shape) / self.nu)
        hs = max(factor, 0.0) * self.hs_sea
        dw = self.omega[1] - self.omega[0]
        m0 = float(np.sum(S)) * dw * (TWO_PI / self.mu.size)
        if m0 > 0.0:
            S = S * (hs * hs / 16.0) / m0
        return S, hs

    def process(self, cols):
        self._need_sea()
        t = np.asarray(cols["t"], dtype=float)
        nf, nd = self.omega.size, self.mu.size
        if t.size == 0:
            return np.zeros(0), self._empty(nf, nd)
        if not self._started:
            self._clock.start(t[0] + self.cycle)  # the first spectrum needs a whole acquisition window
            self._started = True
        ts = self._clock.take_before(t[-1])
        if ts.size == 0:
            return ts, self._empty(nf, nd)
        _, g = self.gm.process(ts, np.zeros(ts.size))
        _, e = self.white.process(ts, np.zeros(ts.size))
        fac = self.K * (1.0 + g) * (1.0 + e)
        spec = np.empty((ts.size, nf, nd))
        hs = np.empty(ts.size)
        tp = np.full(ts.size, np.nan)
        pdir = np.full(ts.size, np.nan)
        for i in range(ts.size):
            spec[i], hs[i] = self.spectrum_at(float(fac[i]))
            if hs[i] > 0.0:
                S1 = spec[i].sum(axis=1)
                k = int(np.argmax(S1))
                w = self.omega[k]
                if 0 < k < nf - 1:
                    d = S1[k - 1] - 2.0 * S1[k] + S1[k + 1]
                    if d < 0.0:
                        w = w + 0.5 * (S1[k - 1] - S1[k + 1]) / d * (self.omega[1] - self.omega[0])
                tp[i] = TWO_PI / w
                pdir[i] = self.mu[int(np.argmax(spec[i][k]))]
        return ts, {"hs": hs, "tp": tp, "peak_direction_to": pdir, "spectrum": spec}

    @staticmethod
    def _empty(nf, nd):
        return {"hs": np.zeros(0), "tp": np.zeros(0), "peak_direction_to": np.zeros(0),
                "spectrum": np.zeros((0, nf, nd))}

    def drawn(self):
        return {"hs_calibration_scale": getattr(self, "K", None), "direction_bias_rad": getattr(self, "dir_bias", None),
                "hs_gauss_markov": self.gm.drawn(), "hs_noise": self.white.drawn(),
                "clock_phase_s": self._clock.phase if hasattr(self, "_clock") else None}

    def meta(self):
        m = super().meta()
        m.update({"omega_rad_s": self.omega.tolist(), "directions_to_rad": self.mu.tolist(), "cycle_s": self.cycle,
                  "frequency_resolution_rad_s": self.sig_w, "direction_resolution_rad": self.sig_mu,
                  "spectrum_axes": "time, omega, direction (towards)",
                  # what the team knows of the height: a calibrated signal-to-noise estimate, not a measured
                  # one (its actual calibration error is the truth's: drawn())
                  "hs_method": "signal-to-noise calibration"})
        return m


# ------------------------------------------------------------------------------------------- buoy
@nb.njit(cache=True)
def buoy_series(comp, gain, hfac, x, y, t, out):
    """Measured heave and horizontal pair at (x[i], y[i], t[i]) into out (3, n): Σ g a cos θ and
    Σ g a h (cos μ, sin μ) sin θ, with per-component gains g (the buoy's response) and horizontal factors
    h (coth kh for displacements, k for slopes)."""
    for i in range(t.size):
        e = 0.0
        hn = 0.0
        he = 0.0
        for j in range(comp.shape[0]):
            th = comp[j, 1] * t[i] - comp[j, 2] * (x[i] * comp[j, 3] + y[i] * comp[j, 4]) + comp[j, 5]
            ga = gain[j] * comp[j, 0]
            e += ga * math.cos(th)
            s = ga * hfac[j] * math.sin(th)
            hn += s * comp[j, 3]
            he += s * comp[j, 4]
        out[0, i] = e
        out[1, i] = hn
        out[2, i] = he


def band_response(f, f_hp: float, n_hp: int, f_lp: float, n_lp: int):
    """|H(f)| of the buoy's band-pass: Butterworth magnitudes of orders n_hp (high-pass at f_hp [Hz]) and
    n_lp (low-pass at f_lp [Hz])."""
    f = np.asarray(f, dtype=float)
    with np.errstate(divide="ignore"):
        hp = 1.0 / np.sqrt(1.0 + (f_hp / np.maximum(f, 1e-300)) ** (2 * n_hp))
    return hp / np.sqrt(1.0 + (f / f_lp) ** (2 * n_lp))


def fourier_five(eta, h1, h2, fs: float, nperseg: int):
    """The buoy's on-board analysis: (ω [rad/s], S [m² s/rad], a₁, b₁, a₂, b₂) from heave and a horizontal
    pair in quadrature with it (displacements or slopes), Welch cross-spectra (Hann, 50 % overlap)."""
    kw = dict(fs=fs, nperseg=nperseg, window="hann", detrend="constant")
    f, g11 = signal.welch(eta, **kw)
    _, g22 = signal.welch(h1, **kw)
    _, g33 = signal.welch(h2, **kw)
    _, g12 = signal.csd(eta, h1, **kw)
    _, g13 = signal.csd(eta, h2, **kw)
    _, g23 = signal.csd(h1, h2, **kw)
    with np.errstate(invalid="ignore", divide="ignore"):
        den = np.sqrt(g11 * (g22 + g33))
        a1 = -g12.imag / den
        b1 = -g13.imag / den
        a2 = (g22 - g33) / (g22 + g33)
        b2 = 2.0 * g23.real / (g22 + g33)
    return TWO_PI * f, g11 / TWO_PI, a1, b1, a2, b2


class WaveBuoy(SeaDevice):
    """Directional wave buoy, moored or drifting (module doc, section 2)."""

    kind = "wave_buoy"
    extra_keys = {"measures", "mooring", "sample_hz", "record_s", "segment_s", "frequencies_hz", "band_hz",
                  "band_orders", "heave_scale", "heave_noise_m", "horizontal_noise", "compass_bias_deg",
                  "drift_mps", "position_m", "output"}
    SPECTRA = {"hs": ("m", "significant wave height 4 sqrt(m0) over the reporting band"),
               "tp": ("s", "peak period of the spectrum"),
               "mean_direction_to": ("rad", "mean direction (towards, 0..2π) from the S-weighted a1, b1"),
               "spread": ("rad", "circular spread sigma_1 = sqrt(2(1 - r1)) from the S-weighted a1, b1"),
               "north": ("m", "buoy position north at the end of the record"),
               "east": ("m", "buoy position east at the end of the record"),
               "S": ("m2 s rad-1", "heave spectrum per frequency (grid in metadata)"),
               "a1": ("1", "first Fourier coefficient a1 per frequency (directions towards)"),
               "b1": ("1", "first Fourier coefficient b1 per frequency"),
               "a2": ("1", "second Fourier coefficient a2 per frequency"),
               "b2": ("1", "second Fourier coefficient b2 per frequency")}

    def build(self):
        s = self.spec
        self.measures = s.get("measures", "displacements")
        if self.measures not in ("displacements", "slopes"):
            raise SpecError("measures", f"{self.measures!r} unknown (allowed: displacements, slopes)")
        self.mooring = s.get("mooring", "moored")
        if self.mooring not in ("moored", "drifting"):
            raise SpecError("mooring", f"{self.mooring!r} unknown (allowed: moored, drifting)")
        self.output = s.get("output", "spectra")
        if self.output not in ("spectra", "series"):
            raise SpecError("output", f"{self.output!r} unknown (allowed: spectra, series)")
        self.fs = _num(s, "sample_hz", 1.28, lo=0.1)
        self.record = _num(s, "record_s", 1800.0, lo=60.0)
        self.nperseg = int(round(_num(s, "segment_s", 200.0, lo=10.0) * self.fs))
        if self.nperseg > int(self.record * self.fs):
            raise SpecError("segment_s", f"{self.nperseg / self.fs:g} s is longer than the record ({self.record:g} s)")
        fr = s.get("frequencies_hz", [0.03, 0.58])
        bd = s.get("band_hz", [0.033, 0.6])
        od = s.get("band_orders", [4, 12])
        for key, v in (("frequencies_hz", fr), ("band_hz", bd), ("band_orders", od)):
            if not (isinstance(v, list) and len(v) == 2 and 0 < float(v[0]) and float(v[0]) <= float(v[1])):
                raise SpecError(key, f"expected [low, high] with 0 < low <= high, got {v!r}")
        self.f_report = (float(fr[0]), float(fr[1]))
        self.band = (float(bd[0]), float(bd[1]))
        self.orders = (int(od[0]), int(od[1]))
        self.scale_mean, self.scale_sd = _dist(s, "heave_scale")
        self.noise_z = _num(s, "heave_noise_m", 0.0, lo=0.0)
        self.noise_h = _num(s, "horizontal_noise", 0.0, lo=0.0)
        self.res = _num(s, "resolution", 0.0, lo=0.0)
        self.compass_mean, self.compass_sd = _dist(s, "compass_bias_deg", DEG)
        self.drift_mean, self.drift_sd = _dist(s, "drift_mps")
        pos = s.get("position_m")
        if pos is None:
            pos = self.team.get("site", {}).get("range_center", [0.0, 0.0])
        if not (isinstance(pos, (list, tuple)) and len(pos) == 2 and all(math.isfinite(float(v)) for v in pos)):
            raise SpecError("position_m", f"expected [north, east] in metres, got {pos!r}")
        self.position = np.array([float(pos[0]), float(pos[1])])
        self.chain = P.Chain([])
        hname = "displacement" if self.measures == "displacements" else "slope"
        hunit = "m" if self.measures == "displacements" else "1"
        if self.output == "series":
            self.channels = {"heave": ("m", "heave (up)"), "h_north": (hunit, f"{hname} north"),
                             "h_east": (hunit, f"{hname} east")}
        else:
            self.channels = dict(self.SPECTRA)

    def reset(self, rng):
        r1, r2, r3, r4 = rng.spawn(4)
        self.gain_error = self.scale_mean + self.scale_sd * float(r1.standard_normal())
        self.compass = self.compass_mean + self.compass_sd * float(r1.standard_normal())
        v = self.drift_sd * r1.standard_normal(2) + self.drift_mean if self.mooring == "drifting" else np.zeros(2)
        self.drift = np.asarray(v, dtype=float)
        self._noise = r2
        self._clock = P._Clock(1.0 / self.fs, float(r3.uniform(0.0, 1.0 / self.fs)))
        self._started = False
        self._t0 = None
        self._buf = np.zeros((3, 0))
        self._tbuf = np.zeros(0)
        self._gains = None

    def _component_gains(self):
        c = self.comp
        g = (1.0 + self.gain_error) * band_response(c[:, 1] / TWO_PI, self.band[0], self.orders[0], self.band[1],
                                                   self.orders[1])
        if self.measures == "slopes":
            h = c[:, 2].copy()
        elif math.isinf(self.depth):
            h = np.ones(c.shape[0])
        else:
            h = 1.0 / np.tanh(c[:, 2] * self.depth)
        return np.ascontiguousarray(g), np.ascontiguousarray(h)

    def position_at(self, t) -> tuple[np.ndarray, np.ndarray]:
        """The buoy's (north, east) [m] at times t [s] (drifting: from its position at the first sample)."""
        t = np.asarray(t, dtype=float)
        t0 = self._t0 if self._t0 is not None else 0.0
        return self.position[0] + self.drift[0] * (t - t0), self.position[1] + self.drift[1] * (t - t0)

    def true_series(self, t) -> np.ndarray:
        """(3, n): heave and the horizontal pair as the buoy's sensor sees them (response applied, no noise)."""
        if self._gains is None:
            self._gains = self._component_gains()
        t = np.ascontiguousarray(t, dtype=float)
        x, y = self.position_at(t)
        out = np.empty((3, t.size))
        buoy_series(self.comp, self._gains[0], self._gains[1], np.ascontiguousarray(x), np.ascontiguousarray(y), t, out)
        return out

    def measure(self, t) -> np.ndarray:
        """(3, n): the measured series (response, noise, resolution, compass rotation) at instants t."""
        y = self.true_series(t)
        n = t.size
        y[0] += self.noise_z * self._noise.standard_normal(n)
        y[1:] += self.noise_h * self._noise.standard_normal((2, n))
        c, s_ = math.cos(self.compass), math.sin(self.compass)
        # the compass reads heading + bias: horizontal axes resolved into 'north'/'east' are rotated by it
        hn, he = c * y[1] + s_ * y[2], -s_ * y[1] + c * y[2]
        y[1], y[2] = hn, he
        if self.res > 0.0:
            y[0] = np.round(y[0] / self.res) * self.res
        return y

    def process(self, cols):
        self._need_sea()
        t = np.asarray(cols["t"], dtype=float)
        if t.size == 0:
            return np.zeros(0), self._empty()
        if not self._started:
            self._clock.start(t[0])
            self._started = True
        ts = self._clock.take_before(t[-1])
        if ts.size and self._t0 is None:
            self._t0 = float(ts[0])
        y = self.measure(ts) if ts.size else np.zeros((3, 0))
        if self.output == "series":
            return ts, {"heave": y[0], "h_north": y[1], "h_east": y[2]}
        self._buf = np.concatenate([self._buf, y], axis=1)
        self._tbuf = np.concatenate([self._tbuf, ts])
        n = int(round(self.record * self.fs))
        out_t, rows = [], []
        while self._tbuf.size >= n:
            rows.append(self.analyse(self._buf[:, :n], float(self._tbuf[n - 1])))
            out_t.append(float(self._tbuf[n - 1]))
            self._buf, self._tbuf = self._buf[:, n:], self._tbuf[n:]
        if not rows:
            return np.zeros(0), self._empty()
        return np.array(out_t), {k: np.array([r[k] for r in rows]) for k in self.channels}

    def frequency_grid(self) -> np.ndarray:
        f = np.fft.rfftfreq(self.nperseg, 1.0 / self.fs)
        return f[(f >= self.f_report[0]) & (f <= self.f_report[1])]

    def analyse(self, y, t_end: float) -> dict:
        """One transmitted report from a record y (3, n) (module doc, section 2)."""
        w, S, a1, b1, a2, b2 = fourier_five(y[0], y[1], y[2], self.fs, self.nperseg)
        f = w / TWO_PI
        m = (f >= self.f_report[0]) & (f <= self.f_report[1])
        w, S, a1, b1, a2, b2 = w[m], S[m], a1[m], b1[m], a2[m], b2[m]
        m0 = float(np.trapezoid(S, w))
        A1 = float(np.trapezoid(S * a1, w)) / m0 if m0 > 0 else math.nan
        B1 = float(np.trapezoid(S * b1, w)) / m0 if m0 > 0 else math.nan
        k = int(np.argmax(S))
        x, yy = self.position_at(np.array([t_end]))
        return {"hs": 4.0 * math.sqrt(max(m0, 0.0)), "tp": TWO_PI / w[k] if S[k] > 0 else math.nan,
                "mean_direction_to": math.atan2(B1, A1) % TWO_PI,
                "spread": math.sqrt(2.0 * (1.0 - min(1.0, math.hypot(A1, B1)))),
                "north": float(x[0]), "east": float(yy[0]), "S": S, "a1": a1, "b1": b1, "a2": a2, "b2": b2}

    def _empty(self):
        nf = self.frequency_grid().size
        return {k: np.zeros((0, nf)) if k in ("S", "a1", "b1", "a2", "b2") else np.zeros(0) for k in self.channels}

    def drawn(self):
        return {"heave_gain_error": getattr(self, "gain_error", None), "compass_bias_rad": getattr(self, "compass", None),
                "drift_mps": getattr(self, "drift", np.zeros(2)).tolist(), "start_s": self._t0 if hasattr(self, "_t0") else None,
                "clock_phase_s": self._clock.phase if hasattr(self, "_clock") else None}

    def meta(self):
        m = super().meta()
        m.update({"nominal_rate_hz": self.fs, "measures": self.measures, "mooring": self.mooring, "output": self.output,
                  "record_s": self.record, "segment_s": self.nperseg / self.fs,
                  "omega_rad_s": (TWO_PI * self.frequency_grid()).tolist(),
                  "deployed_position_m": self.position.tolist(), "band_hz": list(self.band),
                  # the data sheet as the team has it (1σ): heave gain, compass heading
                  "heave_scale_sd": self.scale_sd, "compass_sd_rad": self.compass_sd,
                  "welch_dof": _welch_dof(int(round(self.record * self.fs)), self.nperseg)})
        return m


def _welch_dof(n: int, nperseg: int) -> float:
    """Equivalent degrees of freedom of a Hann, 50 %-overlap Welch bin (Welch 1967): 2K/(1 + 2 Σ(1 − m/K)ρ_m²)."""
    step = nperseg // 2
    K = 1 + (n - nperseg) // step
    h = signal.get_window("hann", nperseg)
    h = h / math.sqrt(float(np.sum(h * h)))
    rho1 = float(np.sum(h[:-step] * h[step:])) if step < nperseg else 0.0
    return 2.0 * K / (1.0 + 2.0 * (1.0 - 1.0 / K) * rho1 ** 2) if K > 1 else 2.0


# ---------------------------------------------------------------------------------- relative motion
class RelativeMotion(SeaDevice):
    """Bow relative-motion meter (module doc, section 3): r = η(x_s, y_s, t) + z_s(t) at a hull site."""

    kind = "relative_motion"
    hull_site_required = True
    channels = {"relative_motion": ("m", "sea surface elevation relative to the site's mean height (up)")}

    def measurand(self, kin, cols):
        p = kin.position()
        eta = elevation(self.comp, p[:, 0], p[:, 1], kin.t) if self.comp.shape[0] else np.zeros(kin.t.size)
        return eta + p[:, 2]

    def process(self, cols):
        self._need_sea()
        return super().process(cols)


WAVE_KINDS = {"wave_radar": WaveRadar, "wave_buoy": WaveBuoy, "relative_motion": RelativeMotion}
