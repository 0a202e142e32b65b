"""Composable error-model parts for virtual instruments (instruments.md: "compose error models from
small parts rather than writing one class per quirk").

An instrument is a :class:`Chain` of :class:`Part` objects. The simulation hands the true signal to
the chain in successive chunks ``(t, x)`` — ``t`` an increasing 1-D array of times [s], ``x`` an
``(n,)`` or ``(n, k)`` array of values in SI units — and each part returns the samples it emits for
that chunk, ``(t_out, x_out)``, which may be fewer, more, later or none.

Contract (every part, tested in tests/test_instrument_parts.py)
---------------------------------------------------------------
* ``reset(rng)`` starts a run: it clears all state and draws the run's error parameters.
  Call it before the first ``process`` of every run.
* Streaming invariance: for a given seed the emitted samples are bitwise identical whether the truth
  arrives as one array or in any chunking (including empty and one-sample chunks). Three rules make
  this hold:

  1. Each part draws from its OWN generator, spawned from the one handed to ``reset``
     (``Generator.spawn``), so parts never interleave draws on a shared stream; per-sample noise is
     drawn one value per processed sample, in order (numpy's Generator fills arrays sequentially,
     so ``n1`` then ``n2`` draws equal ``n1 + n2`` draws). A part that needs two independent
     streams (:class:`Dropouts`) spawns two.
  2. A value at an instant ``s`` that lies between input samples is produced only once an input
     sample strictly later than ``s`` has arrived, always from the bracketing pair
     ``t_j <= s < t_{j+1}``; the last sample of the previous chunk is kept for this. Emission may
     therefore lag the simulation by up to one input interval (for a sparse input: one input
     period); the last such instants of a run are not emitted.
  3. Recursions (Gauss–Markov, random walk, update instants) run sequentially with the state
     carried across chunks; window integrals are computed from the buffered samples of that window
     in one call, never as running sums that chunking would split differently.

* ``drawn()`` returns a plain dict (floats, lists, strings: JSON-serialisable) with the part's
  configuration and the error parameters actually drawn this run, for the truth file.
* Dropped samples are removed, never replaced by NaN (:class:`Dropouts`).
* Errors are added in the units of the signal (SI). Angles are in radians.

Recommended order in a chain
----------------------------
::

    sampling stage            Resample | SampleHold | IrregularUpdates | WindowAverage | AverageBetweenUpdates
    geometric/calibration     Misalignment -> ScaleFactor -> Bias
    sensor noise processes    GaussMarkov -> RandomWalk -> WhiteNoise
    range and digitisation    Saturation -> Quantization (Resolution)
    data path                 Dropouts -> Latency -> ClockOffset

Why: (a) sampling first, so that noise is drawn once per instrument sample (white noise added at the
simulation rate and then interpolated would have the wrong variance and spectrum) and so that the
stochastic processes evolve over the instrument's own sample intervals; if the sensor noise is
averaged by the instrument (a count window, a filter), put the noise *before* the averaging stage
instead — that is the physics of that instrument, not a rule. (b) The sensor axes see the rotated
true vector, then each axis applies its own scale factor, then its offset. (c) The analogue range
clips before the converter digitises. (d) Latency and clock offset touch only time stamps, so they
come last; the noise processes must see true time intervals, hence they come before ClockOffset.

Defaults of every part mean "no error"; the numbers come from the instrument catalogue
(instruments.md). Sources for the models are given in each class.
"""

from __future__ import annotations

import math
from typing import Sequence

import numba as nb
import numpy as np

__all__ = [
    "Part", "Chain", "Bias", "ScaleFactor", "Misalignment", "WhiteNoise", "GaussMarkov", "RandomWalk",
    "Quantization", "Resolution", "Saturation", "Latency", "SampleHold", "IrregularUpdates",
    "WindowAverage", "AverageBetweenUpdates", "Dropouts", "ClockOffset", "Resample", "Outages",
]

_METHODS = ("linear", "previous")


# --------------------------------------------------------------------------------------------------
# helpers
# --------------------------------------------------------------------------------------------------

def _plain(v):
    """numpy scalars/arrays -> float / nested lists, for a JSON-serialisable drawn() dict."""
    if v is None:
        return None
    if isinstance(v, np.ndarray):
        return v.tolist()
    if isinstance(v, (np.floating, np.integer, np.bool_)):
        return v.item()
    return v


def _child(rng: np.random.Generator, n: int = 1) -> list[np.random.Generator]:
    """Independent child generators of ``rng`` (numpy SeedSequence spawning, as architecture.md asks)."""
    if not isinstance(rng, np.random.Generator):
        raise TypeError(f"reset() needs a numpy.random.Generator, got {type(rng).__name__}")
    try:
        return list(rng.spawn(n))
    except (AttributeError, TypeError, ValueError):
        # a bit generator without a seed sequence: seed children from the parent's stream instead
        return [np.random.default_rng(s) for s in rng.integers(0, 2**63, size=(n, 4))]


def _shaped(name: str, n_axes: int | None, **params) -> tuple[dict[str, np.ndarray], tuple]:
    """Broadcast per-axis parameters to a common shape: () for a scalar signal or (k,) for k axes."""
    arrs = {k: np.asarray(v, dtype=float) for k, v in params.items()}
    try:
        shape = np.broadcast_shapes(*(a.shape for a in arrs.values()))
        if n_axes is not None:
            if int(n_axes) < 1:
                raise ValueError
            shape = np.broadcast_shapes(shape, (int(n_axes),))
            if shape != (int(n_axes),):
                raise ValueError
    except ValueError:
        raise ValueError(f"{name}: parameters {', '.join(arrs)} do not broadcast to n_axes={n_axes}") from None
    if len(shape) > 1:
        raise ValueError(f"{name}: parameters must be scalars or 1-D per-axis sequences")
    out = {k: np.broadcast_to(a, shape).astype(float) for k, a in arrs.items()}
    for k, a in out.items():
        if not np.all(np.isfinite(a)):
            raise ValueError(f"{name}: {k} must be finite")
    return out, shape


def _nonneg(name: str, **params) -> None:
    for k, v in params.items():
        if np.any(np.asarray(v, dtype=float) < 0) or not np.all(np.isfinite(v)):
            raise ValueError(f"{name}: {k} must be finite and >= 0, got {v}")


def _positive(name: str, **params) -> None:
    for k, v in params.items():
        if not (np.all(np.asarray(v, dtype=float) > 0) and np.all(np.isfinite(v))):
            raise ValueError(f"{name}: {k} must be finite and > 0, got {v}")


def _empty(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    return np.empty(0), np.empty((0,) + x.shape[1:])


def _stack(values: list, trailing: tuple) -> np.ndarray:
    return np.array(values, dtype=float).reshape((len(values),) + trailing)


class _Clock:
    """Regular instants ``k * period + phase`` (k integer), handed out in order, each once."""

    def __init__(self, period: float, phase: float):
        self.period, self.phase = float(period), float(phase)
        self.k: int | None = None

    def _at(self, k: np.ndarray | int):
        return np.asarray(k, dtype=float) * self.period + self.phase

    def start(self, t0: float) -> None:
        """First instant is the first one at or after ``t0``."""
        k = math.ceil((t0 - self.phase) / self.period)
        while self._at(k) < t0:
            k += 1
        while self._at(k - 1) >= t0:
            k -= 1
        self.k = k

    def take_before(self, t_end: float) -> np.ndarray:
        """All not-yet-taken instants strictly before ``t_end``."""
        k_hi = math.floor((t_end - self.phase) / self.period) + 2
        if k_hi < self.k:
            return np.empty(0)
        s = self._at(np.arange(self.k, k_hi + 1))
        s = s[s < t_end]
        self.k += s.size
        return s


class _Buffer:
    """The recent input samples a part needs to evaluate instants and window integrals."""

    def __init__(self):
        self.t = np.empty(0)
        self.x: np.ndarray | None = None

    def push(self, t: np.ndarray, x: np.ndarray) -> None:
        if self.x is None:
            self.t, self.x = t.copy(), x.copy()
        elif t.size:
            self.t = np.concatenate([self.t, t])
            self.x = np.concatenate([self.x, x])

    @property
    def latest(self) -> float:
        return self.t[-1] if self.t.size else -math.inf

    def _seg(self, s: np.ndarray) -> np.ndarray:
        """Index j of the bracketing pair t_j <= s < t_{j+1} (the caller guarantees s < latest)."""
        j = np.searchsorted(self.t, s, side="right") - 1
        if np.any(j < 0) or np.any(j >= self.t.size - 1):
            raise AssertionError("instant outside the buffered input")  # a bug, not a user error
        return j

    def value_at(self, s: np.ndarray, method: str) -> np.ndarray:
        """Input at instants s: linear interpolation on the bracketing pair, or the previous sample."""
        s = np.asarray(s, dtype=float)
        j = self._seg(s)
        if method == "previous":
            return self.x[j].copy()
        f = (s - self.t[j]) / (self.t[j + 1] - self.t[j])
        if self.x.ndim == 2:
            f = f[:, None]
        x0 = self.x[j]
        return x0 + (self.x[j + 1] - x0) * f

    def integral(self, b0: float, b1: float) -> np.ndarray:
        """Integral over [b0, b1] of the piecewise-linear interpolant of the input (trapezoids)."""
        i0, i1 = self._seg(np.array([b0, b1]))
        knots = np.concatenate([[b0], self.t[i0 + 1:i1 + 1], [b1]])
        ends = self.value_at(np.array([b0, b1]), "linear")
        vals = np.concatenate([ends[:1], self.x[i0 + 1:i1 + 1], ends[1:]])
        h = np.diff(knots)
        if vals.ndim == 2:
            h = h[:, None]
        return np.sum(0.5 * (vals[1:] + vals[:-1]) * h, axis=0)

    def prune(self, keep_from: float) -> None:
        """Drop samples not needed for instants >= keep_from (always keeps the latest sample)."""
        if self.t.size == 0:
            return
        j = int(np.searchsorted(self.t, keep_from, side="right")) - 1
        j = min(max(j, 0), self.t.size - 1)
        if j > 0:
            self.t, self.x = self.t[j:].copy(), self.x[j:].copy()


# --------------------------------------------------------------------------------------------------
# base classes
# --------------------------------------------------------------------------------------------------

class Part:
    """One stage of an instrument's error model. See the module docstring for the contract.

    Subclasses implement ``_reset(rng)`` (``rng`` is the part's own child generator), ``_process(t, x)``
    and ``_drawn()``. The base class validates chunks (1-D strictly increasing ``t``, also across
    chunks; ``x`` with ``len(t)`` rows) and refuses to run before ``reset``.
    """

    _ready = False

    def reset(self, rng: np.random.Generator) -> None:
        """Start a run: clear state and draw this run's random parameters from a child of ``rng``."""
        (own,) = _child(rng, 1)
        self._t_last = -math.inf
        self._ready = True
        self._reset(own)

    def process(self, t, x) -> tuple[np.ndarray, np.ndarray]:
        """Feed one chunk of input; return the ``(t_out, x_out)`` this part emits for it."""
        if not self._ready:
            raise RuntimeError(f"{type(self).__name__}: call reset(rng) before process()")
        t = np.asarray(t, dtype=float)
        x = np.asarray(x, dtype=float)
        if t.ndim != 1:
            raise ValueError(f"{type(self).__name__}: t must be 1-D, got shape {t.shape}")
        if x.ndim not in (1, 2) or x.shape[0] != t.shape[0]:
            raise ValueError(f"{type(self).__name__}: x must be (n,) or (n, k) with n = len(t) = {t.size}, "
                             f"got shape {x.shape}")
        if t.size:
            if not np.all(np.isfinite(t)):
                raise ValueError(f"{type(self).__name__}: times must be finite")
            if t[0] <= self._t_last or (t.size > 1 and not np.all(t[1:] > t[:-1])):
                raise ValueError(f"{type(self).__name__}: times must increase strictly, also across chunks")
            self._t_last = t[-1]
        return self._process(t, x)

    def drawn(self) -> dict:
        """Configuration and the error parameters drawn this run (None before the first reset/sample)."""
        d = {"part": type(self).__name__}
        d.update({k: _plain(v) for k, v in self._drawn().items()})
        return d

    # hooks
    def _reset(self, rng: np.random.Generator) -> None:
        pass

    def _process(self, t: np.ndarray, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        raise NotImplementedError

    def _drawn(self) -> dict:
        return {}

    def _check_axes(self, x: np.ndarray, shape: tuple) -> None:
        if x.shape[1:] != shape:
            raise ValueError(f"{type(self).__name__}: input has per-sample shape {x.shape[1:]}, the part is "
                             f"configured for {shape} (give per-axis parameters or n_axes)")


class Chain(Part):
    """Parts applied in sequence: each part's output is the next part's input.

    ``reset`` hands the same generator to every part in order; each part spawns its own child from it,
    so the parts' draws are independent and do not depend on chunking. ``drawn()`` lists the parts'
    dicts in chain order.
    """

    def __init__(self, parts: Sequence[Part]):
        self.parts = list(parts)
        for p in self.parts:
            if not isinstance(p, Part):
                raise TypeError(f"Chain: {p!r} is not a Part")

    def _reset(self, rng):
        for p in self.parts:
            p.reset(rng)

    def _process(self, t, x):
        for p in self.parts:
            t, x = p.process(t, x)
        return t, x

    def drawn(self) -> dict:
        return {"part": "Chain", "parts": [p.drawn() for p in self.parts]}


# --------------------------------------------------------------------------------------------------
# value errors
# --------------------------------------------------------------------------------------------------

class Bias(Part):
    """Constant offset b added to the signal, drawn once per run: b ~ N(mean, sd²) per axis.

    Parameters: ``mean``, ``sd`` [signal units], scalars or per-axis sequences; ``n_axes`` to draw k
    independent biases from scalar ``mean``/``sd``. Model: "constant bias" (instruments.md; IEEE Std
    952-1997 Annex C lists the constant bias as a deterministic term of the gyro model).
    """

    def __init__(self, mean=0.0, sd=0.0, n_axes: int | None = None):
        _nonneg("Bias", sd=sd)
        p, self.shape = _shaped("Bias", n_axes, mean=mean, sd=sd)
        self.mean, self.sd = p["mean"], p["sd"]
        self.value = None

    def _reset(self, rng):
        self.value = self.mean + self.sd * rng.standard_normal(self.shape)

    def _process(self, t, x):
        self._check_axes(x, self.shape)
        return t, x + self.value

    def _drawn(self):
        return {"mean": self.mean, "sd": self.sd, "bias": self.value}


class ScaleFactor(Part):
    """Scale-factor error: y = x (1 + s), s ~ N(mean, sd²) drawn once per run per axis.

    ``mean``, ``sd`` are dimensionless fractions (0.02 = 2 %). E.g. the Kenyon knotmeter's calibrated
    slope ~2 % above nominal (seed 000, instruments.md). Model: IEEE Std 952-1997 scale-factor term.
    """

    def __init__(self, mean=0.0, sd=0.0, n_axes: int | None = None):
        _nonneg("ScaleFactor", sd=sd)
        p, self.shape = _shaped("ScaleFactor", n_axes, mean=mean, sd=sd)
        self.mean, self.sd = p["mean"], p["sd"]
        self.value = None

    def _reset(self, rng):
        self.value = self.mean + self.sd * rng.standard_normal(self.shape)

    def _process(self, t, x):
        self._check_axes(x, self.shape)
        return t, x * (1.0 + self.value)

    def _drawn(self):
        return {"mean": self.mean, "sd": self.sd, "scale_factor_error": self.value}


def _rotation(v: np.ndarray) -> np.ndarray:
    """Rotation matrix exp([v]x) of the rotation vector v [rad] (Rodrigues' formula), exact for any size."""
    th = float(np.linalg.norm(v))
    if th == 0.0:
        return np.eye(3)
    k = v / th
    K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + math.sin(th) * K + (1.0 - math.cos(th)) * (K @ K)


class Misalignment(Part):
    """Mounting misalignment, drawn once per run.

    * ``n_axes=3`` (3-vectors, e.g. accelerometer or rate-gyro triads): three small angles
      θ ~ N(mean, sd²) (about the x, y, z axes) form a rotation vector; y = R x with
      R = exp([θ]ₓ) (Rodrigues). For small angles θ equals roll/pitch/yaw mounting errors to first order.
      The norm of x is preserved exactly.
    * ``n_axes=2`` (planar vectors, e.g. Doppler log surge/sway; seed 001: up to 1° misalignment,
      which biases sideslip): one angle θ, y = [[cos θ, −sin θ], [sin θ, cos θ]] x.
    * ``n_axes=1`` (a scalar angle signal, e.g. heading or wind direction; seed 002: ±5° vane
      alignment): y = x + θ, optionally wrapped: ``wrap="positive"`` to [0, 2π), ``"signed"`` to [−π, π).

    ``sd``, ``mean`` in rad (``mean`` scalar, or one value per angle).
    """

    def __init__(self, sd=0.0, mean=0.0, n_axes: int = 3, wrap: str | None = None):
        if n_axes not in (1, 2, 3):
            raise ValueError(f"Misalignment: n_axes must be 1, 2 or 3, got {n_axes}")
        if wrap not in (None, "positive", "signed"):
            raise ValueError(f"Misalignment: wrap must be None, 'positive' or 'signed', got {wrap!r}")
        if wrap is not None and n_axes != 1:
            raise ValueError("Misalignment: wrap applies to a scalar angle signal (n_axes=1) only")
        _nonneg("Misalignment", sd=sd)
        n_ang = 3 if n_axes == 3 else 1
        p, _ = _shaped("Misalignment", n_ang, mean=mean, sd=sd)
        self.mean, self.sd, self.n_axes, self.wrap = p["mean"], p["sd"], n_axes, wrap
        self.angles = None
        self.matrix = None

    def _reset(self, rng):
        self.angles = self.mean + self.sd * rng.standard_normal(self.mean.shape)
        if self.n_axes == 3:
            self.matrix = _rotation(self.angles)
        elif self.n_axes == 2:
            c, s = math.cos(self.angles[0]), math.sin(self.angles[0])
            self.matrix = np.array([[c, -s], [s, c]])

    def _process(self, t, x):
        if self.n_axes == 1:
            self._check_axes(x, ())
            y = x + self.angles[0]
            if self.wrap == "positive":
                y = np.mod(y, 2.0 * math.pi)
            elif self.wrap == "signed":
                y = np.mod(y + math.pi, 2.0 * math.pi) - math.pi
            return t, y
        self._check_axes(x, (self.n_axes,))
        # explicit row-wise sums, not x @ R.T: BLAS picks kernels by array size and alignment, so a
        # matrix product can differ in the last bit between a whole series and its chunks
        R = self.matrix
        y = np.empty_like(x)
        for i in range(self.n_axes):
            acc = R[i, 0] * x[:, 0]
            for j in range(1, self.n_axes):
                acc = acc + R[i, j] * x[:, j]
            y[:, i] = acc
        return t, y

    def _drawn(self):
        return {"mean_rad": self.mean, "sd_rad": self.sd, "n_axes": self.n_axes, "wrap": self.wrap,
                "angles_rad": self.angles, "matrix": self.matrix}


class WhiteNoise(Part):
    """Additive white noise, independent N(0, sd²) per emitted sample and axis.

    Give either ``sd`` [signal units] or the noise density ``density`` [signal units · √s, i.e. per √Hz]
    together with the NOMINAL sample ``interval`` [s]; then sd = density / √interval (IEEE Std 952-1997
    Annex C: angle random walk coefficient N, σ(τ) = N/√τ for averaging time τ). The nominal interval
    is used, not the actual spacing of the samples seen, so the per-sample sd is constant even for
    irregular sampling (assumption: the sensor's averaging time is its nominal sample interval).
    Place after the sampling stage: noise at the simulation rate would be interpolated/held.
    """

    def __init__(self, sd=None, density=None, interval: float | None = None, n_axes: int | None = None):
        if (sd is None) == (density is None):
            raise ValueError("WhiteNoise: give exactly one of sd or density")
        if density is not None:
            if interval is None:
                raise ValueError("WhiteNoise: density needs the nominal sample interval [s]")
            _positive("WhiteNoise", interval=interval)
            _nonneg("WhiteNoise", density=density)
            sd = np.asarray(density, dtype=float) / math.sqrt(interval)
        _nonneg("WhiteNoise", sd=sd)
        p, self.shape = _shaped("WhiteNoise", n_axes, sd=sd)
        self.sd = p["sd"]
        self.density = None if density is None else np.broadcast_to(np.asarray(density, float), self.shape)
        self.interval = interval

    def _reset(self, rng):
        self._rng = rng

    def _process(self, t, x):
        self._check_axes(x, self.shape)
        return t, x + self.sd * self._rng.standard_normal(x.shape)

    def _drawn(self):
        return {"sd": self.sd, "density": self.density, "interval_s": self.interval}


@nb.njit(cache=True)
def _ar1(a, b, w, x0):
    """x_i = a_i x_{i-1} + b_i w_i per column, starting from x0; returns all x_i (sequential scan)."""
    n, k = w.shape
    out = np.empty((n, k))
    x = x0.copy()
    for i in range(n):
        for j in range(k):
            x[j] = a[i, j] * x[j] + b[i, j] * w[i, j]
            out[i, j] = x[j]
    return out


class GaussMarkov(Part):
    """First-order Gauss–Markov (Ornstein–Uhlenbeck) error: bias instability, time-correlated GNSS error.

    Stationary sd ``sigma`` [signal units], correlation time ``tau`` [s] (scalars or per axis).
    Exact discretisation for any (irregular) interval Δ between emitted samples:
    e_{k+1} = exp(−Δ/τ) e_k + σ √(1 − exp(−2Δ/τ)) w_k, w_k ~ N(0, 1); autocorrelation
    σ² exp(−|Δt|/τ). The first value is drawn from the stationary distribution N(0, σ²), so the error is
    stationary from the first sample. Source: Brown & Hwang, Introduction to Random Signals and Applied
    Kalman Filtering (4th ed., 2012), first-order Gauss–Markov process and its discrete model;
    Gelb (ed.), Applied Optimal Estimation (1974). Typical numbers: accelerometer bias correlation time
    ~100 s; GNSS errors Gauss–Markov (instruments.md).
    """

    def __init__(self, tau, sigma, n_axes: int | None = None):
        _positive("GaussMarkov", tau=tau)
        _nonneg("GaussMarkov", sigma=sigma)
        p, self.shape = _shaped("GaussMarkov", n_axes, tau=tau, sigma=sigma)
        self.tau, self.sigma = p["tau"], p["sigma"]
        self.initial = None

    def _reset(self, rng):
        self._rng = rng
        self._t_prev = -math.inf            # first Δ = inf -> a = 0, b = σ: stationary start
        self._e = np.zeros(max(1, self.tau.size))
        self.initial = None

    def _process(self, t, x):
        self._check_axes(x, self.shape)
        if t.size == 0:
            return t, x.copy()
        dt = np.diff(t, prepend=self._t_prev)[:, None]
        tau, sig = self.tau.reshape(-1)[None, :], self.sigma.reshape(-1)[None, :]
        r = dt / tau
        a = np.exp(-r)
        b = sig * np.sqrt(-np.expm1(-2.0 * r))
        w = self._rng.standard_normal(x.shape).reshape(t.size, -1)
        e = _ar1(np.ascontiguousarray(a), np.ascontiguousarray(b), np.ascontiguousarray(w), self._e)
        if self.initial is None:
            self.initial = e[0].reshape(self.shape).copy()
        self._e = e[-1].copy()
        self._t_prev = t[-1]
        return t, x + e.reshape(x.shape)

    def _drawn(self):
        return {"tau_s": self.tau, "sigma": self.sigma, "initial": self.initial}


class RandomWalk(Part):
    """Random walk added to the signal: r_0 = 0 at the first emitted sample, r_k = r_{k−1} + q √Δ_k w_k.

    ``q`` [signal units / √s] (scalar or per axis); Var[r(t+T) − r(t)] = q² T. Use on a rate output
    for rate random walk (IEEE Std 952-1997 Annex C, coefficient K), or on an integrated angle output
    for angle random walk (coefficient N; on the rate output itself ARW is WhiteNoise(density=N)).
    Δ_k is the actual interval between emitted samples. Starting at zero is an assumption: an initial
    offset is a Bias.
    """

    def __init__(self, q, n_axes: int | None = None):
        _nonneg("RandomWalk", q=q)
        p, self.shape = _shaped("RandomWalk", n_axes, q=q)
        self.q = p["q"]

    def _reset(self, rng):
        self._rng = rng
        self._t_prev = None
        self._r = np.zeros(self.shape)

    def _process(self, t, x):
        self._check_axes(x, self.shape)
        if t.size == 0:
            return t, x.copy()
        dt = np.diff(t, prepend=t[0] if self._t_prev is None else self._t_prev)
        if x.ndim == 2:
            dt = dt[:, None]
        inc = self.q * np.sqrt(dt) * self._rng.standard_normal(x.shape)
        r = np.cumsum(np.concatenate([self._r[None], inc]), axis=0)[1:]   # sequential scan
        self._r = r[-1].copy()
        self._t_prev = t[-1]
        return t, x + r

    def _drawn(self):
        return {"q": self.q}


class Quantization(Part):
    """Resolution of a display or converter: y = step · round(x / step).

    ``mode``: ``"round"`` (to nearest; ties to even), ``"floor"`` (towards −∞) or ``"trunc"``
    (towards 0, as a display that drops digits). For an input varying over many steps the rounding
    error is ~U(−q/2, q/2), variance q²/12 (Widrow & Kollár, Quantization Noise, 2008). E.g. heading
    0.1° (seed 002), 0.01 kn steady radar speed. ``step`` scalar or per axis.
    """

    def __init__(self, step, mode: str = "round", n_axes: int | None = None):
        _positive("Quantization", step=step)
        if mode not in ("round", "floor", "trunc"):
            raise ValueError(f"Quantization: mode must be 'round', 'floor' or 'trunc', got {mode!r}")
        p, self.shape = _shaped("Quantization", n_axes, step=step)
        self.step, self.mode = p["step"], mode

    def _process(self, t, x):
        if self.shape != ():
            self._check_axes(x, self.shape)
        f = {"round": np.round, "floor": np.floor, "trunc": np.trunc}[self.mode]
        return t, self.step * f(x / self.step)

    def _drawn(self):
        return {"step": self.step, "mode": self.mode}


Resolution = Quantization
"""Alias: an instrument's stated resolution is modelled as quantization to that step."""


class Saturation(Part):
    """Range limit: y = clip(x, lo, hi) [signal units; scalars or per axis]. E.g. % FS ranges (seed 002)."""

    def __init__(self, lo=-math.inf, hi=math.inf):
        lo_a, hi_a = np.asarray(lo, float), np.asarray(hi, float)
        if np.any(np.isnan(lo_a)) or np.any(np.isnan(hi_a)) or np.any(lo_a > hi_a):
            raise ValueError(f"Saturation: need lo <= hi, got lo={lo}, hi={hi}")
        self.lo, self.hi = lo_a, hi_a

    def _process(self, t, x):
        return t, np.clip(x, self.lo, self.hi)

    def _drawn(self):
        return {"lo": self.lo, "hi": self.hi}


# --------------------------------------------------------------------------------------------------
# time-stamp errors
# --------------------------------------------------------------------------------------------------

class Latency(Part):
    """Fixed delay: the value of input time t is emitted stamped t + ``delay`` [s] (delay >= 0).

    The sample is emitted at once with its later stamp (no buffering); samples stamped after the end of
    a run are the record writer's to drop. Fixed, no jitter (assumption).
    """

    def __init__(self, delay: float):
        _nonneg("Latency", delay=delay)
        self.delay = float(delay)

    def _process(self, t, x):
        return t + self.delay, x.copy()

    def _drawn(self):
        return {"delay_s": self.delay}


class ClockOffset(Part):
    """The instrument clock's error: stamps become t + c + d·(t − t_ref); the values are unchanged.

    c ~ N(``mean``, ``sd``²) [s] and d ~ N(``drift_ppm_mean``, ``drift_ppm_sd``²)·10⁻⁶ are drawn once per
    run; ``t_ref`` [s] is the simulation time at which the offset equals c (default 0, the run's time
    origin). Ship/shore clocks must be synchronised; an offset is an error source (seed 002,
    instruments.md).
    """

    def __init__(self, sd: float = 0.0, mean: float = 0.0, drift_ppm_sd: float = 0.0,
                 drift_ppm_mean: float = 0.0, t_ref: float = 0.0):
        _nonneg("ClockOffset", sd=sd, drift_ppm_sd=drift_ppm_sd)
        for k, v in {"mean": mean, "drift_ppm_mean": drift_ppm_mean, "t_ref": t_ref}.items():
            if not math.isfinite(v):
                raise ValueError(f"ClockOffset: {k} must be finite")
        self.sd, self.mean = float(sd), float(mean)
        self.drift_ppm_sd, self.drift_ppm_mean, self.t_ref = float(drift_ppm_sd), float(drift_ppm_mean), float(t_ref)
        self.offset = self.drift_ppm = None

    def _reset(self, rng):
        self.offset = self.mean + self.sd * float(rng.standard_normal())
        self.drift_ppm = self.drift_ppm_mean + self.drift_ppm_sd * float(rng.standard_normal())
        if not self.drift_ppm > -1e6:
            raise ValueError("ClockOffset: drawn drift <= -1e6 ppm would reverse time")

    def _process(self, t, x):
        return t + self.offset + (self.drift_ppm * 1e-6) * (t - self.t_ref), x.copy()

    def _drawn(self):
        return {"mean_s": self.mean, "sd_s": self.sd, "drift_ppm_mean": self.drift_ppm_mean,
                "drift_ppm_sd": self.drift_ppm_sd, "t_ref_s": self.t_ref,
                "offset_s": self.offset, "drift_ppm": self.drift_ppm}


# --------------------------------------------------------------------------------------------------
# sampling stages
# --------------------------------------------------------------------------------------------------

def _method(name, method):
    if method not in _METHODS:
        raise ValueError(f"{name}: method must be one of {_METHODS}, got {method!r}")
    return method


def _phase(name, phase, period):
    if phase is None:
        return None
    if not (0.0 <= phase < period):
        raise ValueError(f"{name}: phase must lie in [0, {period}) s, got {phase}")
    return float(phase)


class Resample(Part):
    """The instrument's own sampling clock: emits the input at instants k/``rate`` + phase.

    ``rate`` [Hz]; ``phase`` [s] in [0, 1/rate), drawn U(0, 1/rate) per run if None (assumption: the
    instrument clock is not synchronised to the simulation). ``method="linear"`` interpolates between
    the bracketing input samples (the best estimate of a continuous true signal); ``"previous"`` takes
    the latest input sample at or before the instant (a zero-order hold, e.g. reading a display that
    shows a sparse upstream stream). Instants before the first input sample are not emitted; an instant
    is emitted once an input sample later than it has arrived (the last input sample of each chunk is
    kept to interpolate across chunk boundaries).
    """

    def __init__(self, rate: float, phase: float | None = None, method: str = "linear"):
        _positive("Resample", rate=rate)
        self.rate, self.method = float(rate), _method("Resample", method)
        self.period = 1.0 / self.rate
        self.phase_given = _phase("Resample", phase, self.period)
        self.phase = self.phase_given

    def _reset(self, rng):
        self.phase = self.phase_given if self.phase_given is not None else float(rng.uniform(0.0, self.period))
        self._clock = _Clock(self.period, self.phase)
        self._buf = _Buffer()

    def _process(self, t, x):
        if t.size == 0:
            return _empty(x)
        if self._clock.k is None:
            self._clock.start(t[0])
        self._buf.push(t, x)
        s = self._clock.take_before(self._buf.latest)
        v = self._buf.value_at(s, self.method) if s.size else _empty(x)[1]
        self._buf.prune(self._buf.latest)
        return s, v

    def _drawn(self):
        return {"rate_hz": self.rate, "method": self.method, "phase_s": self.phase}


class SampleHold(Part):
    """A value latched every ``period`` [s] (its own clock phase) and emitted at the output ``rate``.

    Update instants u_j = j·period + ``phase`` take the input at u_j (``method``: ``"previous"`` =
    the latest input sample at or before u_j, the digital value present at that instant — default;
    ``"linear"`` = interpolated). Output instants o_k = k/``rate`` + ``out_phase`` emit the value of the
    latest update u_j <= o_k (nothing before the first update). E.g. a display updated every 10 s read
    at 1 Hz: SampleHold(10.0, rate=1.0). ``rate=None`` emits at the update instants only. Phases are
    drawn U(0, period) and U(0, 1/rate) per run if None (assumption: unsynchronised clocks).
    """

    def __init__(self, period: float, rate: float | None = None, phase: float | None = None,
                 out_phase: float | None = None, method: str = "previous"):
        _positive("SampleHold", period=period)
        if rate is not None:
            _positive("SampleHold", rate=rate)
        self.period, self.rate, self.method = float(period), rate, _method("SampleHold", method)
        self.phase_given = _phase("SampleHold", phase, self.period)
        self.out_phase_given = None if rate is None else _phase("SampleHold", out_phase, 1.0 / rate)
        self.phase = self.out_phase = None

    def _reset(self, rng):
        self.phase = self.phase_given if self.phase_given is not None else float(rng.uniform(0.0, self.period))
        self._upd = _Clock(self.period, self.phase)
        self._out = None
        if self.rate is not None:
            op = 1.0 / self.rate
            self.out_phase = self.out_phase_given if self.out_phase_given is not None else float(rng.uniform(0.0, op))
            self._out = _Clock(op, self.out_phase)
        self._buf = _Buffer()
        self._held_t = np.empty(0)
        self._held_x = None

    def _process(self, t, x):
        if t.size == 0:
            return _empty(x)
        if self._upd.k is None:
            self._upd.start(t[0])
            if self._out is not None:
                self._out.start(t[0])
            self._held_x = np.empty((0,) + x.shape[1:])
        self._buf.push(t, x)
        end = self._buf.latest
        u = self._upd.take_before(end)
        uv = self._buf.value_at(u, self.method) if u.size else _empty(x)[1]
        self._buf.prune(end)
        if self._out is None:
            return u, uv
        ht = np.concatenate([self._held_t, u])
        hx = np.concatenate([self._held_x, uv])
        o = self._out.take_before(end)
        j = np.searchsorted(ht, o, side="right") - 1
        ok = j >= 0
        self._held_t, self._held_x = ht[-1:].copy(), hx[-1:].copy()
        return o[ok], hx[j[ok]]

    def _drawn(self):
        return {"period_s": self.period, "rate_hz": self.rate, "method": self.method,
                "phase_s": self.phase, "out_phase_s": self.out_phase}


def _equilibrium_first_wait(v: float, a: float, b: float) -> float:
    """Forward recurrence time of a renewal process with U(a, b) intervals, by inversion of its CDF.

    Density (1 − F(s))/m on [0, b], m = (a+b)/2 (Cox, Renewal Theory, 1962: the equilibrium renewal
    process), so that the update instants are stationary from the start of the record.
    """
    m = 0.5 * (a + b)
    if v <= a / m:
        return v * m
    return b - math.sqrt(max((b - a) ** 2 - 2.0 * m * (b - a) * (v - a / m), 0.0))


class IrregularUpdates(Part):
    """Updates at random instants with intervals ~U(``a``, ``b``) [s]; emits only at the updates.

    E.g. LORAN-C fixes / the speed-over-ground display, updated irregularly every 15–60 s (seed 000).
    The emitted value is the input at the update instant (``method`` as in :class:`SampleHold`), or,
    with ``average=True`` (see :class:`AverageBetweenUpdates`), the mean of the input over the interval
    since the previous update (from the second update on). The first update comes after the forward
    recurrence time of the renewal process (see :func:`_equilibrium_first_wait`) measured from the first
    input sample; intervals are drawn one per update, in order, from the part's own stream.
    """

    def __init__(self, a: float, b: float, method: str = "previous", average: bool = False):
        _positive("IrregularUpdates", a=a, b=b)   # a > 0 keeps the update instants strictly increasing
        if not a <= b:
            raise ValueError(f"IrregularUpdates: need a <= b, got a={a}, b={b}")
        self.a, self.b, self.method, self.average = float(a), float(b), _method(type(self).__name__, method), average

    def _reset(self, rng):
        self._rng = rng
        self._buf = _Buffer()
        self._pending = np.empty(0)   # drawn update instants not yet emitted
        self._last = None             # the latest drawn update instant
        self._prev_u = None           # the previous emitted update (start of the next average window)

    def _draw_until(self, end: float) -> None:
        m = 0.5 * (self.a + self.b)
        while self._last <= end:
            n = int((end - self._last) / m) + 2
            d = self.a + (self.b - self.a) * self._rng.random(n)
            u = np.cumsum(np.concatenate([[self._last], d]))[1:]   # sequential: identical for any batching
            self._pending = np.concatenate([self._pending, u])
            self._last = u[-1]

    def _process(self, t, x):
        if t.size == 0:
            return _empty(x)
        if self._last is None:
            self._last = t[0] + _equilibrium_first_wait(float(self._rng.random()), self.a, self.b)
            self._pending = np.array([self._last])
        self._buf.push(t, x)
        end = self._buf.latest
        self._draw_until(end)
        n = int(np.searchsorted(self._pending, end, side="left"))   # pending instants < end
        u, self._pending = self._pending[:n], self._pending[n:]
        if not self.average:
            v = self._buf.value_at(u, self.method) if n else _empty(x)[1]
            self._buf.prune(end)
            return u, v
        ts, vs = [], []
        for uj in u:
            if self._prev_u is not None:
                vs.append(self._buf.integral(self._prev_u, uj) / (uj - self._prev_u))
                ts.append(uj)
            self._prev_u = uj
        self._buf.prune(self._prev_u if self._prev_u is not None else end)
        return np.array(ts, dtype=float), _stack(vs, x.shape[1:])

    def _drawn(self):
        return {"a_s": self.a, "b_s": self.b, "method": self.method, "average": self.average}


class AverageBetweenUpdates(IrregularUpdates):
    """LORAN-C speed-over-ground display: at each irregular update (intervals ~U(a, b) s) it shows the
    mean of the input (e.g. the true velocity over ground) since the previous update — "the average
    between fixes" (seed 000). The same update process as :class:`IrregularUpdates` with
    ``average=True``; the mean is the time integral of the piecewise-linear input over the interval
    divided by its length. Emits from the second update on.
    """

    def __init__(self, a: float, b: float):
        super().__init__(a, b, average=True)


class WindowAverage(Part):
    """Counting/averaging windows: emits, at the end of each window, the mean, integral or pulse count.

    Windows are [s_k, s_k + ``window``] with s_k = k·``period`` + ``phase`` (``period`` defaults to
    ``window``: back-to-back windows; phase drawn U(0, period) if None — assumption). E.g. the Kenyon
    knotmeter (seed 000): counts over 10 s, held and displayed 10 s — WindowAverage(10, period=20,
    output="count", pulses_per_unit=...) followed by Resample(1.0, method="previous") to read the display.

    ``output``:
      * ``"mean"`` — time mean of the input over the window (piecewise-linear input, trapezoids);
      * ``"integral"`` — the time integral [signal units · s];
      * ``"count"`` — whole pulses counted in the window when the pulse rate is ``pulses_per_unit``·x
        (e.g. pulses per metre with x a speed in m/s): count = ⌊C(e)⌋ − ⌊C(s)⌋ with C the running
        integral of the pulse rate from the first input sample plus a pulse phase ~U(0, 1) drawn per
        run. This gives the ±1 count jitter of a real counter, unbiased on average. Signed (negative
        rates count down: assumption; use |x| upstream for a counter without direction sense).
    Windows starting before the first input sample are skipped.
    """

    def __init__(self, window: float, period: float | None = None, phase: float | None = None,
                 output: str = "mean", pulses_per_unit: float = 1.0):
        _positive("WindowAverage", window=window, pulses_per_unit=pulses_per_unit)
        period = window if period is None else period
        _positive("WindowAverage", period=period)
        if window > period:
            raise ValueError(f"WindowAverage: window {window} s longer than period {period} s")
        if output not in ("mean", "integral", "count"):
            raise ValueError(f"WindowAverage: output must be 'mean', 'integral' or 'count', got {output!r}")
        self.window, self.period, self.output = float(window), float(period), output
        self.pulses_per_unit = float(pulses_per_unit)
        self.contiguous = self.window == self.period
        self.phase_given = _phase("WindowAverage", phase, self.period)
        self.phase = self.pulse_phase = None

    def _reset(self, rng):
        self.phase = self.phase_given if self.phase_given is not None else float(rng.uniform(0.0, self.period))
        self.pulse_phase = float(rng.random()) if self.output == "count" else None
        self._buf = _Buffer()
        self._k = None            # index of the current/next window
        self._b = None            # last processed boundary
        self._in = False          # whether the next boundary closes a window
        self._c = None            # running pulse count C (count mode)

    def _start(self, k):
        return k * self.period + self.phase

    def _end(self, k):
        return self._start(k + 1) if self.contiguous else self._start(k) + self.window

    def _process(self, t, x):
        if t.size == 0:
            return _empty(x)
        if self._k is None:
            self._k = math.ceil((t[0] - self.phase) / self.period)
            while self._start(self._k) < t[0]:
                self._k += 1
            while self._start(self._k - 1) >= t[0]:
                self._k -= 1
            self._b = float(t[0])
            self._c = np.full(x.shape[1:], self.pulse_phase) if self.output == "count" else None
        self._buf.push(t, x)
        end = self._buf.latest
        count = self.output == "count"
        ts, vs = [], []
        while True:
            nb_ = self._end(self._k) if self._in else self._start(self._k)
            if not nb_ < end:
                break
            if self._in or count:
                integ = self._buf.integral(self._b, nb_)
                if self._in:
                    if self.output == "mean":
                        vs.append(integ / (nb_ - self._b))
                    elif self.output == "integral":
                        vs.append(integ)
                    else:
                        c_new = self._c + self.pulses_per_unit * integ
                        vs.append(np.floor(c_new) - np.floor(self._c))
                    ts.append(nb_)
                if count:
                    self._c = self._c + self.pulses_per_unit * integ
            if self._in:
                self._k += 1
                self._in = self.contiguous   # back-to-back: the end is the next window's start
            else:
                self._in = True
            self._b = nb_
        self._buf.prune(self._b)
        return np.array(ts, dtype=float), _stack(vs, x.shape[1:])

    def _drawn(self):
        return {"window_s": self.window, "period_s": self.period, "output": self.output,
                "pulses_per_unit": self.pulses_per_unit, "phase_s": self.phase, "pulse_phase": self.pulse_phase}


# --------------------------------------------------------------------------------------------------
# missing data
# --------------------------------------------------------------------------------------------------

class Dropouts(Part):
    """Missing samples, removed from the output (not NaN: a record simply has no sample there).

    Two independent mechanisms, each with its own random stream:
      * per sample: each input sample is lost with probability ``p`` (Bernoulli), one uniform draw per
        input sample in order;
      * outages: a two-state (up/down) continuous-time Markov process — while up, outages begin at rate
        ``outage_rate`` [1/s]; durations ~Exp(mean ``outage_mean`` [s]). Samples inside an outage are
        lost. Memoryless, so it is started in its stationary state at the first input sample
        (down with probability D/(U + D), U = 1/outage_rate, D = outage_mean) and the long-run lost
        fraction is D/(U + D). Assumption (a Gilbert–Elliott-type burst model, Gilbert 1960).
    """

    def __init__(self, p: float = 0.0, outage_rate: float = 0.0, outage_mean: float = 0.0):
        _nonneg("Dropouts", p=p, outage_rate=outage_rate, outage_mean=outage_mean)
        if p > 1:
            raise ValueError(f"Dropouts: p must be in [0, 1], got {p}")
        if (outage_rate > 0) != (outage_mean > 0):
            raise ValueError("Dropouts: give both outage_rate and outage_mean (or neither)")
        self.p, self.outage_rate, self.outage_mean = float(p), float(outage_rate), float(outage_mean)
        self.initially_down = None

    def _reset(self, rng):
        self._rb, self._ro = _child(rng, 2)
        self._sw = []            # pending switch times (> latest input time), ascending
        self._down = None        # state now (before the pending switches)
        self._gen_down = None    # state after the last generated switch
        self.initially_down = None

    def _generate(self, end: float) -> None:
        """Draw switch times (one exponential each, in order) until one lies after ``end``."""
        up_mean = 1.0 / self.outage_rate
        while self._last_sw <= end:
            mean = self.outage_mean if self._gen_down else up_mean
            self._last_sw = self._last_sw + mean * float(self._ro.standard_exponential())
            self._sw.append(self._last_sw)
            self._gen_down = not self._gen_down

    def _process(self, t, x):
        if t.size == 0:
            return _empty(x)
        keep = np.ones(t.size, dtype=bool)
        if self.p > 0:
            keep &= self._rb.random(t.size) >= self.p
        if self.outage_rate > 0:
            if self._down is None:
                d, u = self.outage_mean, 1.0 / self.outage_rate
                self._down = bool(self._ro.random() < d / (u + d))
                self.initially_down = self._down
                self._gen_down = self._down
                self._last_sw = float(t[0])   # the memoryless process starts at the first sample
            self._generate(t[-1])
            sw = np.array(self._sw)
            idx = np.searchsorted(sw, t, side="right")
            down = np.logical_xor(self._down, idx % 2 == 1)
            keep &= ~down
            m = int(np.searchsorted(sw, t[-1], side="right"))
            self._down = bool(self._down ^ (m % 2 == 1))
            self._sw = self._sw[m:]
        return t[keep], x[keep]

    def _drawn(self):
        return {"p": self.p, "outage_rate_per_s": self.outage_rate, "outage_mean_s": self.outage_mean,
                "initially_down": self.initially_down}


class Outages(Part):
    """Signal outages: gaps in the output whose starts are Poisson arrivals and whose lengths are
    exponential or fixed — e.g. GNSS fixes lost while masts or superstructure shadow the antenna or the
    differential corrections drop out. Samples inside an outage are removed (not NaN).

    An alternating renewal process (Cox, Renewal Theory, 1962): up periods ~Exp(mean 1/``rate``)
    (so outages begin at ``rate`` [1/s] while the signal is up), down periods of length ``duration``
    [s], ``durations="exponential"`` (mean ``duration``) or ``"fixed"``. Long-run lost fraction
    D/(U + D), U = 1/rate, D = ``duration``; outages begin at 1/(U + D) per unit time overall. Started
    in its stationary state at the first input sample: down with probability D/(U + D), and then the
    rest of that outage is the forward recurrence time of the down period (Exp(D) for exponential,
    U(0, D) for fixed lengths); otherwise the rest of the up period is Exp(U) (memoryless). One
    standard-uniform or standard-exponential draw per switch, in order, from the part's own stream
    (streaming-invariant). ``outages()`` lists the (start, end) of the outages generated so far.
    """

    def __init__(self, rate: float, duration: float, durations: str = "exponential"):
        _nonneg("Outages", rate=rate)
        _positive("Outages", duration=duration)
        if durations not in ("exponential", "fixed"):
            raise ValueError(f"Outages: durations must be 'exponential' or 'fixed', got {durations!r}")
        self.rate, self.duration, self.durations = float(rate), float(duration), durations
        self.initially_down = None

    def _reset(self, rng):
        self._rng = rng
        self._sw: list[float] = []     # pending switch times (> latest input time), ascending
        self._down = None              # state at the latest input time (before the pending switches)
        self._gen_down = None          # state after the last generated switch
        self._last_sw = None
        self._log: list[float] = []    # every switch time generated (for outages())
        self.initially_down = None

    def _down_length(self) -> float:
        if self.durations == "fixed":
            return self.duration
        return self.duration * float(self._rng.standard_exponential())

    def _generate(self, end: float) -> None:
        while self._last_sw <= end:
            if self._gen_down:           # now down: the outage ends after its length
                step = self._down_length()
            else:                        # now up: the next outage starts after Exp(1/rate)
                step = float(self._rng.standard_exponential()) / self.rate
            self._last_sw += step
            self._sw.append(self._last_sw)
            self._log.append(self._last_sw)
            self._gen_down = not self._gen_down

    def _process(self, t, x):
        if t.size == 0 or self.rate == 0.0:
            return t, x.copy()
        if self._down is None:
            u, d = 1.0 / self.rate, self.duration
            self._down = bool(self._rng.random() < d / (u + d))
            self.initially_down = self._down
            self._gen_down = self._down
            if self._down:   # the rest of the outage in progress (forward recurrence time)
                rest = d * float(self._rng.random()) if self.durations == "fixed" else self._down_length()
            else:
                rest = float(self._rng.standard_exponential()) / self.rate
            self._t0 = float(t[0])
            self._last_sw = float(t[0]) + rest
            self._sw = [self._last_sw]
            self._log = [self._last_sw]
            self._gen_down = not self._gen_down
        self._generate(float(t[-1]))
        sw = np.array(self._sw)
        idx = np.searchsorted(sw, t, side="right")
        down = np.logical_xor(self._down, idx % 2 == 1)
        m = int(np.searchsorted(sw, t[-1], side="right"))
        self._down = bool(self._down ^ (m % 2 == 1))
        self._sw = self._sw[m:]
        return t[~down], x[~down]

    def outages(self) -> list[tuple[float, float]]:
        """(start, end) [s] of the outages generated so far (an outage in progress at the first sample
        starts there; the last may end after the latest input)."""
        if self.initially_down is None:
            return []
        sw = list(self._log)
        if self.initially_down:
            sw = [self._t0] + sw
        return [(sw[i], sw[i + 1]) for i in range(0, len(sw) - 1, 2)]

    def _drawn(self):
        return {"rate_per_s": self.rate, "duration_s": self.duration, "durations": self.durations,
                "initially_down": self.initially_down,
                "outages_s": [list(o) for o in self.outages()]}
