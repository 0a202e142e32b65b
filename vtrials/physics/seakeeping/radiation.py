"""Radiation memory of a ship: retardation kernels and their state-space approximation.

Cummins (1962): F_rad(t) = −A∞ ξ̈(t) − μ(t), μ_i(t) = Σ_j ∫₀ᵗ K_ij(t − τ) ξ̇_j(τ) dτ, with the
retardation kernel K_ij(t) = (2/π) ∫₀^∞ B_ij(ω) cos ωt dω and, in the frequency domain (Ogilvie 1964),
K_ij(jω) = B_ij(ω) + jω (A_ij(ω) − A∞_ij).

Each DOF pair (i, j) is fitted with a strictly proper rational function K̂(s) = Σ_k r_k / (s − p_k) of
order ≤ 12 by frequency-domain identification (vector fitting: Gustavsen & Semlyen 1999, IEEE Trans.
Power Delivery 14(3); used for ship radiation kernels as in Perez & Fossen 2009, Modeling,
Identification and Control 30(1)):

* stability is enforced: a pole found in the right half-plane is reflected into the left one;
* K̂(0) = 0 is imposed as an equality constraint on the residues (B(0) = 0: no steady damping force
  from a steady velocity, Perez & Fossen's structural property 2);
* strictly proper (relative degree 1): Re K̂(jω) ~ ω⁻², Im K̂(jω) ~ ω⁻¹ at high frequency (property 3).

High-frequency tail (the shipped databases stop at 3.0 rad/s, patrol51, and 1.5 rad/s, kvlcc2, where
B(ω) has not decayed): beyond ω_max we extend B(ω) = B(ω_max) (1 + κ)/((ω/ω_max)² + κ) and likewise
A(ω) − A∞, with κ matching the slope of the last database interval (:func:`tail_shape`). It decays
as ω⁻², the asymptotic form of a strictly proper rational kernel, and joins the data smoothly.
The same extension is used for the reference kernel and by :mod:`.rao` above the database's range.

Fit report per pair: R² of the kernel K̂(t) against the reference K(t) (cosine transform of the
extended B(ω), exact for piecewise-linear B), the largest error of the fitted A(ω) = A∞ + Im K̂(jω)/ω
and B(ω) = Re K̂(jω) over the energetic band (the frequencies where B_ii(ω) ≥ 10 % of its peak,
errors relative to the peak of |A(ω)| resp. |B(ω)| of the pair over the database range), the poles'
stability and a passivity check of the assembled matrix: the smallest eigenvalue of the symmetric part
of Re K̂(jω) over a dense grid (≥ 0 for a passive model).

Which fit of each pair (order, weighting of the energetic band and the tail) is used: among the admissible
ones (stable, kernel R² ≥ 0.99, A and B within 5 % over the band), the combination whose zero-speed RAOs
best match the database's, keeping the assembled model passive (:func:`fit_radiation`, ``select="rao"``).

State-space form used for stepping: ẋ = A_r x + B_r ξ̇ (ξ̇: the 6 body velocities), μ = C_r x; the
exact zero-order-hold discretisation over a step h is x⁺ = Φ x + Γ ξ̇ with Φ = e^{A_r h},
Γ = ∫₀ʰ e^{A_r τ} dτ B_r (Van Loan's block exponential).
"""

from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass

import numpy as np
from scipy.linalg import expm

from vtrials.errors import InputError

DOF_NAMES = ("surge", "sway", "heave", "roll", "pitch", "yaw")
#: Pairs that couple for a port-starboard symmetric hull at zero speed (others vanish by symmetry).
SYMMETRIC_COUPLINGS = ((0, 2), (0, 4), (2, 4), (1, 3), (1, 5), (3, 5))
MAX_ORDER = 12
#: Extra fit points on the ω⁻² tail, as multiples of ω_max, and their weight relative to the data.
TAIL_FIT_POINTS = np.geomspace(1.1, 30.0, 16)
TAIL_FIT_WEIGHT = 0.3


# ----------------------------------------------------------------------------- frequency data
def extended_coefficients(omega: np.ndarray, A: np.ndarray, B: np.ndarray, A_inf: np.ndarray,
                          w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A(w), B(w) [(n, ...) like A[0]] at any frequencies w [rad/s] from database values (omega, A, B).

    Inside the range: linear interpolation. Below ω_min: A held at A(ω_min), B linear to B(0) = 0.
    Above ω_max: the ω⁻² tail of the module docstring. A, B: (nω, ...) arrays; A_inf: A[0]-shaped.
    """
    w = np.asarray(w, dtype=float)
    om = np.asarray(omega, dtype=float)
    flat_a = A.reshape(om.size, -1)
    flat_b = B.reshape(om.size, -1)
    ainf = np.asarray(A_inf, dtype=float).reshape(-1)
    out_a = np.empty((w.size, flat_a.shape[1]))
    out_b = np.empty_like(out_a)
    wb = np.concatenate(([0.0], om))
    for c in range(flat_a.shape[1]):
        out_a[:, c] = np.interp(w, om, flat_a[:, c])
        out_b[:, c] = np.interp(w, wb, np.concatenate(([0.0], flat_b[:, c])))
    hi = w > om[-1]
    if np.any(hi):
        x2 = (w[hi] / om[-1])[:, None] ** 2
        ka = tail_shape(om, flat_a - ainf)
        kb = tail_shape(om, flat_b)
        out_a[hi] = ainf + (flat_a[-1] - ainf) * (1.0 + ka) / (x2 + ka)
        out_b[hi] = flat_b[-1] * (1.0 + kb) / (x2 + kb)
    shape = (w.size,) + A.shape[1:]
    return out_a.reshape(shape), out_b.reshape(shape)


def tail_shape(omega: np.ndarray, y: np.ndarray) -> np.ndarray:
    """κ of the tail y(ω) = y(ω_max) (1 + κ)/((ω/ω_max)² + κ) per column of y (nω, m), chosen so the
    tail's slope at ω_max matches the database's last interval (C¹ join; κ = 2/σ − 1 for the
    logarithmic slope σ = −d ln y / d ln ω, clamped to 0 ≤ κ ≤ 10; κ = 0 where y changes sign)."""
    y = np.asarray(y, dtype=float).reshape(np.asarray(omega).size, -1)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = y[-1] / y[-2]
        sigma = -np.log(ratio) / math.log(omega[-1] / omega[-2])
        kappa = np.where(ratio > 0.0, 2.0 / np.maximum(sigma, 0.2) - 1.0, 0.0)
    return np.clip(np.nan_to_num(kappa, nan=0.0), 0.0, 10.0)


def retardation_kernel(omega: np.ndarray, b: np.ndarray, t: np.ndarray) -> np.ndarray:
    """K(t) = (2/π) ∫₀^∞ B(ω) cos ωt dω [N/m or N m/rad per s, per (m/s)] for one DOF pair.

    omega (n,) [rad/s] increasing, b (n,) the database damping; B is taken piecewise linear through
    (0, 0) and the database points (integrated exactly, Filon-type), and beyond ω_max the tail of
    :func:`extended_coefficients` is integrated on a geometric grid to 400 ω_max (remainder < 0.3 % (1 + κ) of the
    tail at t = 0, and smaller for t > 0 where it oscillates).
    """
    om = np.asarray(omega, dtype=float)
    b = np.asarray(b, dtype=float)
    tail_w = om[-1] * np.geomspace(1.0, 400.0, 4000)[1:]
    kb = float(tail_shape(om, b)[0])
    ws = np.concatenate(([0.0], om, tail_w))
    bs = np.concatenate(([0.0], b, b[-1] * (1.0 + kb) / ((tail_w / om[-1]) ** 2 + kb)))
    t = np.asarray(t, dtype=float)
    w0, w1 = ws[:-1], ws[1:]
    b0, b1 = bs[:-1], bs[1:]
    slope = (b1 - b0) / (w1 - w0)
    out = np.empty(t.size)
    for n, tt in enumerate(t):
        if tt == 0.0:
            out[n] = np.sum(0.5 * (b0 + b1) * (w1 - w0))
        else:
            # ∫ (b0 + s (ω − w0)) cos ωt dω, exact
            s1, s0 = np.sin(w1 * tt), np.sin(w0 * tt)
            c1, c0 = np.cos(w1 * tt), np.cos(w0 * tt)
            out[n] = np.sum((b1 * s1 - b0 * s0) / tt + slope * (c1 - c0) / tt ** 2)
    return 2.0 / math.pi * out


# ----------------------------------------------------------------------------- vector fitting
def _basis(s: np.ndarray, poles: np.ndarray) -> np.ndarray:
    """Real-coefficient partial-fraction basis (m, n): 1/(s−a) for a real pole; for a complex pair
    (a, a*) the two columns 1/(s−a) + 1/(s−a*) and j/(s−a) − j/(s−a*)."""
    cols = []
    k = 0
    while k < poles.size:
        a = poles[k]
        if a.imag == 0.0:
            cols.append(1.0 / (s - a.real))
            k += 1
        else:
            cols.append(1.0 / (s - a) + 1.0 / (s - np.conj(a)))
            cols.append(1j / (s - a) - 1j / (s - np.conj(a)))
            k += 2
    return np.stack(cols, axis=1)


def _realization(poles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Real (A, b) with c (sI − A)⁻¹ b equal to the basis of :func:`_basis` weighted by c."""
    n = poles.size
    A = np.zeros((n, n))
    b = np.zeros(n)
    k = 0
    while k < n:
        a = poles[k]
        if a.imag == 0.0:
            A[k, k] = a.real
            b[k] = 1.0
            k += 1
        else:
            A[k:k + 2, k:k + 2] = [[a.real, a.imag], [-a.imag, a.real]]
            b[k] = 2.0
            k += 2
    return A, b


def _sorted_poles(eigs: np.ndarray) -> np.ndarray:
    """Poles in the left half-plane (unstable ones reflected), complex pairs as (a, a*) with Im a > 0."""
    eigs = np.where(eigs.real > 0.0, -eigs.real + 1j * eigs.imag, eigs)
    real = np.sort(eigs[np.abs(eigs.imag) <= 1e-9 * np.maximum(1.0, np.abs(eigs))].real)
    cplx = eigs[eigs.imag > 1e-9 * np.maximum(1.0, np.abs(eigs))]
    cplx = cplx[np.argsort(cplx.imag)]
    out = [complex(r, 0.0) for r in real]
    for a in cplx:
        out += [a, np.conj(a)]
    return np.array(out, dtype=complex)


def _vector_fit(s: np.ndarray, f: np.ndarray, weight: np.ndarray, order: int, iters: int = 30):
    """Vector fitting of f(s) ≈ Σ r_k/(s − p_k) with K(0) = 0; returns (A, b, c) real, stable."""
    beta = np.linspace(abs(s[0].imag), abs(s[-1].imag), order // 2)
    beta = np.maximum(beta, 1e-3)
    poles = np.empty(order, dtype=complex)
    poles[0::2] = -0.01 * beta + 1j * beta
    poles[1::2] = -0.01 * beta - 1j * beta
    W = weight[:, None]
    for _ in range(iters):
        phi = _basis(s, poles)
        lhs = np.hstack([phi, -f[:, None] * phi]) * W
        rhs = f * weight
        M = np.vstack([lhs.real, lhs.imag])
        r = np.concatenate([rhs.real, rhs.imag])
        scale = np.linalg.norm(M, axis=0)
        scale[scale == 0.0] = 1.0
        sol = np.linalg.lstsq(M / scale, r, rcond=None)[0] / scale
        ct = sol[order:]
        A, b = _realization(poles)
        new = np.linalg.eigvals(A - np.outer(b, ct))
        new_sorted = _sorted_poles(new)
        if new_sorted.size != order:
            break
        poles = new_sorted
    # final residues with the constraint K(0) = Σ c φ(0) = 0
    phi = _basis(s, poles) * W
    M = np.vstack([phi.real, phi.imag])
    r = np.concatenate([(f * weight).real, (f * weight).imag])
    g = _basis(np.array([0.0j]), poles)[0].real
    n = order
    kkt = np.zeros((n + 1, n + 1))
    kkt[:n, :n] = M.T @ M
    kkt[:n, n] = g
    kkt[n, :n] = g
    rhs = np.concatenate([M.T @ r, [0.0]])
    c = np.linalg.lstsq(kkt, rhs, rcond=None)[0][:n]
    A, b = _realization(poles)
    return A, b, c


# ----------------------------------------------------------------------------- fit per pair
@dataclass(frozen=True)
class PairFit:
    """State-space model of the retardation kernel of DOF pair (i, j): ẋ = A x + b ξ̇_j, μ_i = c x.

    A (n, n) [1/s], b (n,), c (n,) in SI units (μ_i in N or N m for ξ̇_j in m/s or rad/s). Fit report:
    r2_kernel, err_A, err_B (largest error over the energetic band relative to the pair's peak), the
    band [rad/s], max_real_pole [1/s] (< 0: stable); weighting: the fit's (band weight, tail weight)
    relative to the other database points (:func:`pair_candidates`).
    """

    i: int
    j: int
    A: np.ndarray
    b: np.ndarray
    c: np.ndarray
    r2_kernel: float
    err_A: float
    err_B: float
    band: tuple[float, float]
    max_real_pole: float
    weighting: tuple[float, float] = (1.0, TAIL_FIT_WEIGHT)

    @property
    def order(self) -> int:
        return self.A.shape[0]

    def response(self, w: np.ndarray) -> np.ndarray:
        """K̂(jω) (complex) at frequencies w [rad/s]."""
        eye = np.eye(self.order)
        return np.array([self.c @ np.linalg.solve(1j * x * eye - self.A, self.b) for x in np.atleast_1d(w)])

    def kernel(self, t: np.ndarray) -> np.ndarray:
        """K̂(t) = c e^{A t} b at times t [s]."""
        lam, V = np.linalg.eig(self.A)
        cv = self.c @ V
        vb = np.linalg.solve(V, self.b)
        return np.real(np.exp(np.outer(np.atleast_1d(t), lam)) @ (cv * vb))


def _energetic_band(omega, b_diag):
    """Frequencies where the diagonal damping is ≥ 10 % of its peak (first to last such point)."""
    idx = np.nonzero(b_diag >= 0.1 * b_diag.max())[0]
    return omega[idx[0]], omega[idx[-1]]


def kernel_times(omega) -> np.ndarray:
    """Times [s] for the kernel R² check: step π/(10 ω_max) (10 points per period of the highest
    database frequency), up to 6 periods of the lowest frequency (12π/ω_min) or 2000 steps."""
    dt = math.pi / (10.0 * omega[-1])
    n = int(min(12.0 * math.pi / omega[0] / dt, 2000))
    return dt * np.arange(n + 1)


def _pair_data(omega, A_ij, B_ij, A_inf_ij):
    """Fit data of one pair: frequencies with the ω⁻² tail points appended and K(jω) there."""
    Kd = B_ij + 1j * omega * (A_ij - A_inf_ij)
    tail = omega[-1] * TAIL_FIT_POINTS
    a_t, b_t = extended_coefficients(omega, A_ij[:, None], B_ij[:, None], np.array([A_inf_ij]), tail)
    Kt = b_t[:, 0] + 1j * tail * (a_t[:, 0] - A_inf_ij)
    return np.concatenate([omega, tail]), np.concatenate([Kd, Kt]), max(np.abs(Kd).max(), 1e-30)


def pair_candidates(omega, A_ij, B_ij, A_inf_ij, band, max_order: int = MAX_ORDER, i: int = 0, j: int = 0,
                    orders=None, weightings=((1.0, TAIL_FIT_WEIGHT),)) -> list[PairFit]:
    """Stable fits of one DOF pair, one per (order, weighting): orders 2, 4, … ``max_order`` (or
    ``orders``); a weighting is (weight of the energetic band's points, weight of the tail points),
    relative to 1 for the other database points. Each carries its fit report (:class:`PairFit`)."""
    omega = np.asarray(omega, dtype=float)
    w_all, K_all, k_scale = _pair_data(omega, A_ij, B_ij, A_inf_ij)
    w_ref = omega[-1]
    s = 1j * w_all / w_ref
    t = kernel_times(omega)
    K_ref = retardation_kernel(omega, B_ij, t)
    ss_ref = np.sum((K_ref - K_ref.mean()) ** 2)
    in_band = (omega >= band[0]) & (omega <= band[1])
    a_scale = max(np.abs(A_ij).max(), 1e-30)
    b_scale = max(np.abs(B_ij).max(), 1e-30)
    out = []
    for band_w, tail_w in weightings:
        wt = np.concatenate([np.where(in_band, band_w, 1.0), tail_w * np.ones(w_all.size - omega.size)])
        for order in (orders if orders is not None else range(2, max_order + 1, 2)):
            A_n, b, c_n = _vector_fit(s, K_all / k_scale, wt, order)
            A = A_n * w_ref
            c = c_n * k_scale * w_ref
            pole = float(np.linalg.eigvals(A).real.max())
            if pole >= 0.0:
                continue
            fit = PairFit(i, j, A, b, c, 0.0, 0.0, 0.0, tuple(band), pole)
            Kf = fit.response(omega)
            r2 = 1.0 - np.sum((fit.kernel(t) - K_ref) ** 2) / ss_ref if ss_ref > 0 else 1.0
            eA = float(np.max(np.abs(A_inf_ij + Kf.imag / omega - A_ij)[in_band]) / a_scale)
            eB = float(np.max(np.abs(Kf.real - B_ij)[in_band]) / b_scale)
            out.append(PairFit(i, j, A, b, c, float(r2), eA, eB, tuple(band), pole, (band_w, tail_w)))
    return out


def _admissible(fit: PairFit, r2_min: float, tol: float) -> bool:
    return fit.r2_kernel >= r2_min and fit.err_A <= tol and fit.err_B <= tol


def _pick(fits: list[PairFit], r2_min: float, tol: float) -> PairFit | None:
    """The first admissible fit of ``fits``, else the one with the smallest
    max((1 − R²)/(1 − r2_min), err_A/tol, err_B/tol)."""
    for f in fits:
        if _admissible(f, r2_min, tol):
            return f
    return min(fits, key=lambda f: max((1.0 - f.r2_kernel) / (1.0 - r2_min), f.err_A / tol, f.err_B / tol),
               default=None)


def fit_pair(omega, A_ij, B_ij, A_inf_ij, band, max_order: int = MAX_ORDER, i: int = 0, j: int = 0,
             r2_min: float = 0.99, tol: float = 0.05, orders=None) -> PairFit:
    """Fit one DOF pair with orders 2, 4, … ``max_order`` (or ``orders``), uniform weights. The lowest
    stable order that meets R² ≥ r2_min and the A/B tolerance ``tol`` over ``band`` is returned; if none
    does, the one with the smallest max((1 − R²)/(1 − r2_min), err_A/tol, err_B/tol)."""
    fits = pair_candidates(omega, A_ij, B_ij, A_inf_ij, band, max_order, i, j, orders)
    return _pick(fits, r2_min, tol)


# ----------------------------------------------------------------------------- assembled model
@dataclass(frozen=True)
class RadiationModel:
    """Radiation memory of one ship for the DOFs ``dofs`` (e.g. heave, roll, pitch = (2, 3, 4)).

    ẋ = A x + B ξ̇, μ = C x, F_rad = −A∞ ξ̈ − μ. A (n, n), B (n, 6), C (6, n): block-diagonal over
    ``pairs`` (one :class:`PairFit` per ordered pair (i, j) of coupled DOFs in ``dofs``).
    ``passivity_min``: smallest eigenvalue of the symmetric part of Re K̂(jω) over 0.01 … 10 ω_max,
    relative to the largest diagonal peak of B over its DOFs (≥ 0: passive; small negative values are
    fit noise, reported not corrected).
    """

    dofs: tuple[int, ...]
    pairs: tuple[PairFit, ...]
    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    passivity_min: float

    @property
    def n_states(self) -> int:
        return self.A.shape[0]

    def response(self, w: np.ndarray) -> np.ndarray:
        """K̂(jω) (nw, 6, 6) complex."""
        w = np.atleast_1d(np.asarray(w, dtype=float))
        out = np.zeros((w.size, 6, 6), dtype=complex)
        for p in self.pairs:
            out[:, p.i, p.j] = p.response(w)
        return out

    def blocks(self) -> list[tuple[int, int]]:
        """(first state, number of states) of each pair's block of A (block-diagonal)."""
        out, k = [], 0
        for p in self.pairs:
            out.append((k, p.order))
            k += p.order
        return out

    def discretize(self, h: float) -> tuple[np.ndarray, np.ndarray]:
        """Exact zero-order-hold (Φ, Γ) for the step h [s]: x⁺ = Φ x + Γ ξ̇ (Van Loan 1978), block by
        block (Φ is block-diagonal like A, with exact zeros between the pairs' blocks)."""
        if not (math.isfinite(h) and h > 0.0):
            raise InputError("radiation", "step", f"must be a positive number of seconds, got {h!r}")
        n = self.n_states
        Phi = np.zeros((n, n))
        Gam = np.zeros((n, 6))
        for k, m in self.blocks():
            M = np.zeros((m + 6, m + 6))
            M[:m, :m] = self.A[k:k + m, k:k + m]
            M[:m, m:] = self.B[k:k + m]
            E = expm(M * h)
            Phi[k:k + m, k:k + m] = E[:m, :m]
            Gam[k:k + m] = E[:m, m:]
        return Phi, Gam


#: Weightings (band weight, tail weight) tried per pair when fits are selected by the RAO.
SELECTION_WEIGHTINGS = tuple((bw, tw) for tw in (TAIL_FIT_WEIGHT, 0.1) for bw in (1.0, 3.0, 10.0))
#: Wave headings [deg] (180: head seas) of the zero-speed RAOs the selection compares.
SELECTION_HEADINGS_DEG = (0.0, 45.0, 90.0, 135.0, 180.0)
#: Smallest passivity (:attr:`RadiationModel.passivity_min`) the selection accepts (fit noise level).
PASSIVITY_FLOOR = -1e-4
#: Smallest fall of the RAO score (a sum of relative errors) for which the selection changes a fit:
#: below it the extra states cost more than they bring.
SELECTION_MIN_GAIN = 2e-3


def _assemble(dofs, pairs, db) -> "RadiationModel":
    n = sum(p.order for p in pairs)
    A = np.zeros((n, n))
    B = np.zeros((n, 6))
    C = np.zeros((6, n))
    k = 0
    for p in pairs:
        m = p.order
        A[k:k + m, k:k + m] = p.A
        B[k:k + m, p.j] = p.b
        C[p.i, k:k + m] = p.c
        k += m
    model = RadiationModel(dofs, tuple(pairs), A, B, C, 0.0)
    Kf = model.response(_passivity_grid(db.omega))
    return RadiationModel(dofs, tuple(pairs), A, B, C, _passivity(Kf, dofs, db))


def _passivity_grid(omega):
    return omega[-1] * np.geomspace(0.01, 10.0, 400)


def _passivity(K, dofs, db) -> float:
    """Smallest eigenvalue of the symmetric part of Re K (nw, 6, 6) over ``dofs``, relative to the
    largest diagonal damping peak."""
    idx = np.array(dofs)
    sub = K[:, idx][:, :, idx].real
    lam = float(np.linalg.eigvalsh(0.5 * (sub + np.transpose(sub, (0, 2, 1)))).min())
    return lam / max(db.B[:, i, i].max() for i in dofs)


class _RaoScore:
    """Zero-speed held-DOF RAOs (:func:`.rao.rao`'s equation, no viscous damping) with given A(ω), B(ω)
    against the database's own (its coefficients and excitation interpolated as :func:`.rao.rao` does),
    at the database frequencies and two more in each interval (a response that changes fast between
    database points, e.g. near a pitch cancellation, is seen). Score = Σ over DOFs of the worst relative
    error where the response is ≥ 10 % of its peak at that heading (headings where a DOF's peak is
    below 0.1 % of its largest, e.g. roll in head seas, are noise and skipped)."""

    def __init__(self, db, dofs):
        self.idx = np.array(dofs)
        self.db = db
        om = db.omega
        self.w = np.interp(np.linspace(0.0, om.size - 1.0, 3 * om.size - 2), np.arange(om.size), om)
        self.X = []
        for b in SELECTION_HEADINGS_DEG:
            x = db.excitation(math.radians(b))[:, self.idx]
            self.X.append(np.stack([np.interp(self.w, om, x[:, c].real) + 1j * np.interp(self.w, om, x[:, c].imag)
                                    for c in range(self.idx.size)], axis=1))
        self.M = db.mass_matrix[np.ix_(self.idx, self.idx)]
        self.C = db.C[np.ix_(self.idx, self.idx)]
        sub = np.ix_(range(om.size), self.idx, self.idx)
        A, B = extended_coefficients(om, db.A[sub], db.B[sub], db.A_inf[np.ix_(self.idx, self.idx)], self.w)
        self.ref = self._rao(A, B)
        mag = np.abs(self.ref)
        peak = mag.max(axis=1, keepdims=True)
        self.mask = (mag >= 0.1 * peak) & (peak >= 1e-3 * peak.max(axis=0, keepdims=True))

    def _rao(self, A, B):
        w = self.w[:, None, None]
        Z = -w ** 2 * (self.M + A) + 1j * w * B + self.C
        return np.stack([np.linalg.solve(Z, x[:, :, None])[:, :, 0] for x in self.X])

    def __call__(self, K) -> float:
        """K (nw, 6, 6): the model's K̂(jω) at the frequencies ``self.w``."""
        sub = np.ix_(range(self.w.size), self.idx, self.idx)
        A = self.db.A_inf[np.ix_(self.idx, self.idx)] + K[sub].imag / self.w[:, None, None]
        err = np.where(self.mask, np.abs(self._rao(A, K[sub].real) - self.ref) / np.abs(self.ref), 0.0)
        return float(err.max(axis=(0, 1)).sum())


def _select_by_rao(db, dofs, keys, first, cands) -> list:
    """Coordinate descent over the pairs' admissible fits from ``first``. A move changes one diagonal
    pair, or a coupled pair (i, j) together with (j, i) to fits of the same order and weighting (their
    data are nearly equal, and fitting them alike keeps the coupling symmetric); it is taken when the
    RAO score (:class:`_RaoScore`) falls and the model stays passive (≥ PASSIVITY_FLOOR, or no worse
    than ``first``)."""
    score = _RaoScore(db, dofs)
    om, wp = score.w, _passivity_grid(db.omega)
    tag = {k: {(f.order, f.weighting): f for f in reversed(cands[k])} for k in keys}
    groups = []
    for k in keys:
        mate = (k[1], k[0])
        if k[0] == k[1] or mate not in tag:
            groups.append((k,))
        elif k[0] < k[1]:
            groups.append((k, mate))
    resp = {}
    K = np.zeros((om.size, 6, 6), dtype=complex)
    Kp = np.zeros((wp.size, 6, 6), dtype=complex)

    def put(k, f):
        if id(f) not in resp:
            resp[id(f)] = (f.response(om), f.response(wp))
        K[:, k[0], k[1]], Kp[:, k[0], k[1]] = resp[id(f)]

    choice = dict(first)
    for k in keys:
        put(k, choice[k])
    best = score(K)
    floor = min(PASSIVITY_FLOOR, _passivity(Kp, dofs, db))
    for _sweep in range(4):
        improved = False
        for g in groups:
            common = set.intersection(*(set(tag[k]) for k in g))
            for t in sorted(common, key=lambda x: (x[0], x[1])):
                trial = {k: tag[k][t] for k in g}
                if all(trial[k] is choice[k] for k in g):
                    continue
                for k in g:
                    put(k, trial[k])
                val = score(K)
                if val < best - SELECTION_MIN_GAIN and _passivity(Kp, dofs, db) >= floor:
                    best, improved = val, True
                    choice.update(trial)
                else:
                    for k in g:
                        put(k, choice[k])
        if not improved:
            break
    return [choice[k] for k in keys]


def fit_radiation(db, dofs=(2, 3, 4), max_order: int = MAX_ORDER, couplings: bool = True,
                  coupling_threshold: float = 0.02, select: str = "rao", extra=()) -> RadiationModel:
    """Fit the radiation memory of database ``db`` (:class:`.database.HydroDatabase`) for ``dofs``.

    ``extra``: further DOFs (e.g. sway, (1,)) whose own pairs and couplings with ``dofs`` are added after
    the fit of ``dofs``, each by its first admissible fit, leaving the pairs of ``dofs`` exactly as fitted
    alone (the RAO selection below is made for the seakeeping DOFs; the model's DOFs are the union).

    Diagonal pairs are always fitted; an off-diagonal pair (i, j) of :data:`SYMMETRIC_COUPLINGS` is
    fitted when ``couplings`` and max|B_ij| ≥ threshold · sqrt(max B_ii · max B_jj) (else neglected).

    ``select``: "first" takes per pair the lowest order that meets R² ≥ 0.99 and A, B within 5 % over
    its band (uniform weights, :func:`fit_pair`). "rao" (default) starts there and, among each pair's
    admissible fits (same thresholds; orders 2 … max_order, :data:`SELECTION_WEIGHTINGS`), chooses the
    combination whose zero-speed RAOs best match the database's own (:class:`_RaoScore`), keeping the
    model passive. Reason: a fit error of 1 % of a pair's peak is admissible alone but can move a
    response that results from near-cancelling forces by 10 % (patrol51's pitch in beam seas: the pitch
    excitation against the heave-coupled moment); judged by the response, the fits are chosen for what
    they are used for.
    """
    if select not in ("rao", "first"):
        raise InputError("radiation", "select", f"must be 'rao' or 'first', got {select!r}")
    dofs = tuple(int(d) for d in dofs)
    for d in dofs:
        if d not in range(6):
            raise InputError("radiation", "dofs", f"must be DOF indices 0..5 {DOF_NAMES}, got {dofs!r}")
    extra = tuple(int(d) for d in extra if int(d) not in dofs)
    for d in extra:
        if d not in range(6):
            raise InputError("radiation", "extra", f"must be DOF indices 0..5 {DOF_NAMES}, got {extra!r}")
    if extra:
        base = fit_radiation(db, dofs, max_order, couplings, coupling_threshold, select)
        return _cached(db, ("extra", dofs, extra, max_order, couplings, coupling_threshold, select),
                       lambda: _add_pairs(db, base, extra, max_order, couplings, coupling_threshold))
    return _cached(db, (dofs, max_order, couplings, coupling_threshold, select),
                   lambda: _fit_radiation(db, dofs, max_order, couplings, coupling_threshold, select))


def _cached(db, args, fit):
    """``fit()``'s model, kept under a digest of the database's arrays and ``args``."""
    h = hashlib.sha1(repr(args).encode())
    for arr in (db.omega, db.A, db.B, db.A_inf, db.C, db.mass_matrix, db.X, db.headings):
        h.update(np.ascontiguousarray(arr).tobytes())
    key = h.hexdigest()
    if key not in _FIT_CACHE:
        _FIT_CACHE[key] = fit()
    return _FIT_CACHE[key]


#: Fitted models by a digest of the database's arrays and the fit's arguments (the fit is deterministic
#: and takes seconds; a campaign of wave runs fits each ship once per process).
_FIT_CACHE: dict[str, RadiationModel] = {}


def _pair_keys(db, dofs, couplings, coupling_threshold, new=None):
    """The DOF pairs (i, j) fitted and each one's band: the diagonal of each DOF, and the couplings of
    :data:`SYMMETRIC_COUPLINGS` whose damping reaches the threshold; ``new``: only pairs involving these."""
    om = db.omega
    bands = {i: _energetic_band(om, db.B[:, i, i]) for i in dofs}
    keys, pair_band = [], {}
    for i in dofs:
        for j in dofs:
            if new is not None and i not in new and j not in new:
                continue
            if i != j:
                if not couplings or (min(i, j), max(i, j)) not in SYMMETRIC_COUPLINGS:
                    continue
                ref = math.sqrt(db.B[:, i, i].max() * db.B[:, j, j].max())
                if np.abs(db.B[:, i, j]).max() < coupling_threshold * ref:
                    continue
                band = (max(bands[i][0], bands[j][0]), min(bands[i][1], bands[j][1]))
                if band[0] > band[1]:
                    band = (min(bands[i][0], bands[j][0]), max(bands[i][1], bands[j][1]))
            else:
                band = bands[i]
            keys.append((i, j))
            pair_band[(i, j)] = band
    return keys, pair_band


def _add_pairs(db, base, extra, max_order, couplings, coupling_threshold) -> RadiationModel:
    dofs = tuple(sorted(set(base.dofs) | set(extra)))
    keys, pair_band = _pair_keys(db, dofs, couplings, coupling_threshold, new=set(extra))
    om = db.omega
    added = []
    for k in keys:
        fits = pair_candidates(om, db.A[:, k[0], k[1]], db.B[:, k[0], k[1]], db.A_inf[k], pair_band[k],
                               max_order, k[0], k[1])
        good = [f for f in fits if f.r2_kernel >= 0.99]
        # the most accurate stable fit (not the first admissible): these couplings enter roll in long
        # waves as the small remainder of two large moments (vtrials.physics.seakeeping.timedomain)
        added.append(min(good, key=lambda f: max(f.err_A, f.err_B)) if good else _pick(fits, 0.99, 0.05))
    return _assemble(dofs, list(base.pairs) + added, db)


def _fit_radiation(db, dofs, max_order, couplings, coupling_threshold, select) -> RadiationModel:
    om = db.omega
    keys, pair_band = _pair_keys(db, dofs, couplings, coupling_threshold)
    first = {k: fit_pair(om, db.A[:, k[0], k[1]], db.B[:, k[0], k[1]], db.A_inf[k], pair_band[k],
                         max_order=max_order, i=k[0], j=k[1]) for k in keys}
    if select == "first":
        return _assemble(dofs, [first[k] for k in keys], db)
    cands = {}
    for k in keys:
        fits = pair_candidates(om, db.A[:, k[0], k[1]], db.B[:, k[0], k[1]], db.A_inf[k], pair_band[k],
                               max_order, k[0], k[1], weightings=SELECTION_WEIGHTINGS)
        cands[k] = [first[k]] + [f for f in fits if _admissible(f, 0.99, 0.05)]
    return _assemble(dofs, _select_by_rao(db, dofs, keys, first, cands), db)
