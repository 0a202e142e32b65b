"""Radiation memory: retardation kernel, state-space fit and its discretisation.

Independent references:
* the kernel integral against a closed form: for a triangular B(ω) (0 at 0, 1 at ω = 1, 0 at ω = 2)
  K(t) = (2/π)(2 cos t − 1 − cos 2t)/t² (elementary integration);
* vector fitting against a known rational function with K(0) = 0 (poles and response recovered);
* the fits on both shipped databases against the databases' own A(ω), B(ω) (Ogilvie 1964:
  K(jω) = B(ω) + jω(A(ω) − A∞)) and the kernel from the cosine transform of B(ω);
* the ZOH step against an independent adaptive integration (scipy solve_ivp, rtol 1e-10) and the
  steady sinusoidal response against K̂(jω).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from vtrials.errors import InputError
from vtrials.physics.seakeeping import radiation as rad
from vtrials.physics.seakeeping.database import load_database

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module", params=["patrol51", "kvlcc2"])
def fitted(request):
    db = load_database(ROOT / "models" / request.param / "hydro" / f"{request.param}_hydro.nc")
    return db, rad.fit_radiation(db, dofs=(2, 3, 4))


def test_kernel_integral_matches_closed_form():
    omega = np.array([1.0, 2.0])
    b = np.array([1.0, 0.0])          # with B(0) = 0: a triangle; zero tail since B(ω_max) = 0
    t = np.array([0.0, 0.3, 1.0, 2.5, 7.0])
    k = rad.retardation_kernel(omega, b, t)
    exact = np.where(t == 0.0, 1.0, (2.0 * np.cos(t) - 1.0 - np.cos(2.0 * t)) / np.where(t == 0, 1, t) ** 2)
    np.testing.assert_allclose(k, 2.0 / math.pi * exact, rtol=1e-12, atol=1e-14)


def test_vector_fit_recovers_a_known_rational_kernel():
    poles = np.array([-0.4 + 1.1j, -0.4 - 1.1j, -0.15 + 2.3j, -0.15 - 2.3j])
    A0, b0 = rad._realization(poles)
    g = rad._basis(np.array([0.0j]), poles)[0].real
    c0 = np.array([1.0, 0.5, -0.3, 0.0])
    c0[3] = -(g[:3] @ c0[:3]) / g[3]                    # K(0) = 0
    w = np.linspace(0.1, 3.0, 40)
    K = np.array([c0 @ np.linalg.solve(1j * x * np.eye(4) - A0, b0) for x in w])
    A, b, c = rad._vector_fit(1j * w, K, np.ones(w.size), 4)
    Kf = np.array([c @ np.linalg.solve(1j * x * np.eye(4) - A, b) for x in w])
    assert np.max(np.abs(Kf - K)) < 1e-8 * np.max(np.abs(K))
    np.testing.assert_allclose(np.sort_complex(np.linalg.eigvals(A)), np.sort_complex(poles), atol=1e-8)


def test_fit_quality_on_shipped_database(fitted):
    db, model = fitted
    diag = {(p.i, p.j) for p in model.pairs if p.i == p.j}
    assert diag == {(2, 2), (3, 3), (4, 4)}
    assert {(2, 4), (4, 2)} <= {(p.i, p.j) for p in model.pairs}
    for p in model.pairs:
        assert p.order <= rad.MAX_ORDER
        assert p.max_real_pole < 0.0, (p.i, p.j)
        assert p.r2_kernel >= 0.99, (p.i, p.j, p.r2_kernel)
        assert p.err_A <= 0.05 and p.err_B <= 0.05, (p.i, p.j, p.err_A, p.err_B)
        assert p.response(np.array([0.0]))[0] == pytest.approx(0.0, abs=1e-9 * np.abs(p.c).sum())
    # passivity of the assembled model: Re K(jω) positive semidefinite up to fit noise (measured:
    # patrol51 −2.2e-5, kvlcc2 −2.3e-6 of the largest damping peak)
    assert model.passivity_min >= -1e-3
    assert np.all(np.linalg.eigvals(model.A).real < 0.0)


def test_fit_reproduces_database_band_independently(fitted):
    """Recompute A(ω), B(ω) of the assembled model (not the per-pair report) in each pair's band."""
    db, model = fitted
    K = model.response(db.omega)
    for p in model.pairs:
        band = (db.omega >= p.band[0]) & (db.omega <= p.band[1])
        a_fit = db.A_inf[p.i, p.j] + K[:, p.i, p.j].imag / db.omega
        b_fit = K[:, p.i, p.j].real
        assert np.max(np.abs(a_fit - db.A[:, p.i, p.j])[band]) <= 0.05 * np.abs(db.A[:, p.i, p.j]).max()
        assert np.max(np.abs(b_fit - db.B[:, p.i, p.j])[band]) <= 0.05 * np.abs(db.B[:, p.i, p.j]).max()


def test_zoh_step_matches_adaptive_integration(fitted):
    db, model = fitted
    h = 0.05
    Phi, Gam = model.discretize(h)
    rng = np.random.default_rng(3)
    x0 = rng.normal(size=model.n_states) * 1e3
    u = rng.normal(size=6)
    sol = solve_ivp(lambda t, x: model.A @ x + model.B @ u, (0.0, h), x0, rtol=1e-11, atol=1e-9)
    np.testing.assert_allclose(Phi @ x0 + Gam @ u, sol.y[:, -1], rtol=1e-8, atol=1e-6)


def test_steady_sinusoid_gives_frequency_response(fitted):
    """Heave velocity cos ωt through the discrete model: μ_heave → Re{K̂_33(jω) e^{iωt}}."""
    db, model = fitted
    w = db.omega[db.omega.size // 3]
    h = 2.0 * math.pi / w / 400.0
    Phi, Gam = model.discretize(h)
    n = int(60.0 * 2.0 * math.pi / w / h)
    x = np.zeros(model.n_states)
    mu = np.empty(n)
    for k in range(n):
        u = np.zeros(6)
        u[2] = math.cos(w * (k + 0.5) * h)          # midpoint value over the held step
        x = Phi @ x + Gam @ u
        mu[k] = (model.C @ x)[2]
    t = (np.arange(n) + 1) * h
    last = t > t[-1] - 4.0 * 2.0 * math.pi / w
    basis = np.stack([np.cos(w * t[last]), -np.sin(w * t[last])], axis=1)
    re, im = np.linalg.lstsq(basis, mu[last], rcond=None)[0]
    K = model.response(np.array([w]))[0, 2, 2]
    assert abs(complex(re, im) - K) <= 0.01 * abs(K)


def test_selection_by_rao_beats_the_first_admissible_fits(fitted):
    """The selected fits (default) against the lowest admissible orders (select="first"): the zero-speed
    heave–pitch–roll RAOs with each model's A(ω), B(ω) against the database's own, by an independent
    evaluation (:func:`rao.rao` on a copy of the database whose coefficients are the model's).
    Measured worst relative error where the response is ≥ 10 % of its peak (40 frequencies, five
    headings): patrol51 0.133 → 0.011 (beam-sea pitch, a near-cancellation of the pitch excitation and
    the heave-coupled moment), kvlcc2 0.052 → 0.041 (pitch near its cancellation at 0.58 rad/s; the
    passivity floor keeps it there)."""
    import dataclasses

    from vtrials.physics.seakeeping import rao as rao_mod
    db, model = fitted
    first = rad.fit_radiation(db, dofs=(2, 3, 4), select="first")
    w = np.linspace(db.omega[1], db.omega[-2], 40)
    worst = {}
    for label, m in (("first", first), ("selected", model)):
        K = m.response(db.omega)
        A, B = db.A.copy(), db.B.copy()
        for p in m.pairs:
            A[:, p.i, p.j] = db.A_inf[p.i, p.j] + K[:, p.i, p.j].imag / db.omega
            B[:, p.i, p.j] = K[:, p.i, p.j].real
        dbm = dataclasses.replace(db, A=A, B=B)
        err = 0.0
        for beta in np.radians([0.0, 45.0, 90.0, 135.0, 180.0]):
            ref = rao_mod.rao(db, w, beta, 0.0, (2, 3, 4))
            got = rao_mod.rao(dbm, w, beta, 0.0, (2, 3, 4))
            for d in (2, 3, 4):
                if d == 3 and abs(math.sin(beta)) < 1e-9:
                    continue
                keep = np.abs(ref[:, d]) >= 0.1 * np.abs(ref[:, d]).max()
                err = max(err, float(np.max(np.abs(got[keep, d] - ref[keep, d]) / np.abs(ref[keep, d]))))
        worst[label] = err
    assert worst["selected"] <= 0.05, worst     # issue 10's RAO tolerance
    assert worst["selected"] < worst["first"], worst
    assert model.passivity_min >= rad.PASSIVITY_FLOOR


def test_fit_is_cached_and_blocks_step_alone(fitted):
    db, model = fitted
    assert rad.fit_radiation(db, dofs=(2, 3, 4)) is model
    Phi, Gam = model.discretize(0.05)
    mask = np.zeros_like(Phi, dtype=bool)
    for k, m in model.blocks():
        mask[k:k + m, k:k + m] = True
    assert np.all(Phi[~mask] == 0.0)
    # the block exponential equals the exponential of the whole system
    from scipy.linalg import expm
    n = model.n_states
    M = np.zeros((n + 6, n + 6))
    M[:n, :n] = model.A
    M[:n, n:] = model.B
    E = expm(M * 0.05)
    np.testing.assert_allclose(Phi, E[:n, :n], atol=1e-12)
    np.testing.assert_allclose(Gam, E[:n, n:], rtol=1e-9, atol=1e-12 * np.abs(Gam).max())


def test_bad_input_is_named():
    db = load_database(ROOT / "models" / "kvlcc2" / "hydro" / "kvlcc2_hydro.nc")
    with pytest.raises(InputError, match="dofs"):
        rad.fit_radiation(db, dofs=(2, 7))
    with pytest.raises(InputError, match="select"):
        rad.fit_radiation(db, select="best")
    model = rad.RadiationModel((2,), (), np.zeros((0, 0)), np.zeros((0, 6)), np.zeros((6, 0)), 0.0)
    with pytest.raises(InputError, match="step"):
        model.discretize(0.0)
