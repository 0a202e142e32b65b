"""The trials team's design-stage RAO model of patrol51 (models/patrol51/design): what it is, and that it is
NOT the simulator's truth — different as a real design-stage model would be, and not wildly so.

Truth here: the coupled six-DOF frequency-domain RAO of the simulated ship (:mod:`vtrials.truth.motion_rao`:
truth database at its finest mesh, ship.toml restoring and mass, the maneuvering model in sway and yaw with
its autopilot, hull.toml's roll damping), which tests/test_seakeeping_irregular.py and
tests/test_seakeeping_sim.py hold to the simulated ship; benchmarks/design_rao_vs_truth.py tabulates the
differences over speeds, headings and periods (README beside the file).
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from vtrials.errors import InputError
from vtrials.physics.environment.waves import peak_frequency, spectrum
from vtrials.physics.seakeeping.database import load_database
from vtrials.physics.vessel import model_dir
from vtrials.reduce.design_rao import DesignRAO, load_design_rao
from vtrials.units import G


@pytest.fixture(scope="module")
def design():
    return load_design_rao("patrol51")


def test_design_file_states_how_it_differs(design):
    truth = load_database(model_dir("patrol51") / "hydro" / "patrol51_hydro.nc")
    a = design.attrs
    assert "NOT the simulator's truth" in a["content"]
    assert a["mesh_panels_half_hull"] < json.loads(truth.attrs["convergence"])["levels"][-1]["panels_half"] / 3
    doc = json.loads(a["design_toml"])
    assert doc["condition"]["KG"]["value"] != 3.36                  # design KG, not the as-inclined one
    assert abs(float(a["GM_T"]) - 1.1) > 0.1                          # so its GM_T is not the simulator's
    assert doc["model"]["roll_damping_ratio"]["value"] == pytest.approx(float(a["roll_damping_ratio"]))
    for sec in ("design", "condition", "model"):                      # every parameter names its source
        for k, v in doc[sec].items():
            if isinstance(v, dict):
                assert v.get("source"), (sec, k)


def test_long_wave_limits_and_symmetry(design):
    """Independent limits: in long waves the ship follows the surface (heave → 1 m/m, pitch → the wave
    slope k in head seas); heave and pitch are symmetric port/starboard, roll antisymmetric."""
    w = np.array([0.2])
    R = design.rao(w, math.pi, 0.0)[:, 0]
    assert abs(R[0]) == pytest.approx(1.0, abs=0.01)
    assert abs(R[2]) == pytest.approx(w[0] ** 2 / G, rel=0.05)
    # in long beam waves the ship, free to sway, heels with the wave slope (×1/(1 − (ω/ω_n)²) ≈ 1.03 at
    # 0.2 rad/s; measured 1.02); held in sway, or with yaw free and no heading control, it did not
    Rb = design.rao(w, math.pi / 2, 0.0)[:, 0]
    assert abs(Rb[1]) == pytest.approx(w[0] ** 2 / G, rel=0.05)
    assert abs(Rb[0]) == pytest.approx(1.0, abs=0.01)
    ww = np.linspace(0.3, 2.0, 30)
    for mu in (0.4, 1.2, 2.5):
        a, b = design.rao(ww, mu, 4.0), design.rao(ww, -mu, 4.0)
        np.testing.assert_allclose(a[0], b[0], rtol=1e-12)
        np.testing.assert_allclose(a[2], b[2], rtol=1e-12)
        np.testing.assert_allclose(a[1], -b[1], rtol=1e-12)
    # a point forward of O on the centreline heaves with z − xθ (down): vertical() at x = 0 is −heave
    np.testing.assert_allclose(design.vertical(R[:, None], 0.0)[0], -R[0])


def test_design_differs_from_truth_but_not_wildly(design):
    """RMS response in a long-crested JONSWAP sea (H_s 2 m, T_p 8 s) at 5 m/s, design vs the simulator's
    coupled truth. Measured: head seas heave +14 %, pitch +11 %; 135°: heave +11 %, roll +106 %, pitch
    +9 %; beam: heave +1 %, roll −9 % (pitch in beam seas is a few per cent of its head-sea value).
    Neither identical (some component ≥ 5 % off at each heading) nor wildly off in heave and pitch (within
    30 % where they matter) and beam-sea roll (within 35 %). Bow-sea roll at speed is the exception, stated
    and bounded (within +130 %): the truth's maneuvering forces act on the motion relative to the waves'
    cross-flow (vtrials.physics.forces.wave_flow), whose lift roughly halves its bow-sea roll at 5 m/s,
    and this zero-speed design model has no such term (before that change, with the lift on the
    absolute motion, the design was −2 % here; models/patrol51/design/README.md)."""
    from vtrials.truth.motion_rao import TruthRAO
    U = 5.0
    truth = TruthRAO("patrol51", U)
    w = np.linspace(0.25, 2.5, 400)
    S = spectrum("jonswap", w, 2.0, peak_frequency("jonswap", 3.3, tp=8.0), 3.3)
    diffs = {}
    for hd in (180, 135, 90):
        b = math.radians(hd)
        sp = truth.roll_rate_std(w, S, b)
        T = truth.rao(w, b, sp)
        D = design.rao(w, b, truth.U)
        diffs[hd] = [math.sqrt(np.trapezoid(np.abs(D[k]) ** 2 * S, w) / np.trapezoid(np.abs(T[k]) ** 2 * S, w)) - 1.0
                     for k in range(3)]
        print(hd, "heave, roll, pitch RMS design/truth − 1:", np.round(diffs[hd], 3))
    for hd, (dh, dr, dp) in diffs.items():
        relevant = [dh] + ([dr] if hd != 180 else []) + ([dp] if hd != 90 else [])
        assert max(abs(x) for x in relevant) >= 0.05, hd            # not the truth
        assert abs(dh) <= 0.30, hd
        if hd != 90:
            assert abs(dp) <= 0.30, hd
        if hd == 90:
            assert abs(dr) <= 0.35, hd
        elif hd == 135:
            assert 0.35 < dr <= 1.3, hd                              # the design lacks the lift (above)


def test_missing_file_is_named(tmp_path):
    with pytest.raises(InputError, match="not found"):
        DesignRAO(tmp_path / "nothing.nc")


def test_roll_receptance_is_the_roll_of_a_changed_design(design):
    """The ship-as-buoy fit changes the design's roll stiffness and damping through the roll receptance
    h_φ (Sherman–Morrison, vtrials.reduce.shipbuoy): checked against the design re-solved with C₄₄ and
    B₄₄ changed in its matrices, at zero speed and at 9 m/s, in head, bow, beam and quartering seas;
    heave and pitch do not change (uncoupled from roll by symmetry)."""
    c44, bcrit = design.roll_scales
    assert c44 > 0.0 and bcrit > 0.0
    w = np.linspace(0.25, 2.4, 40)
    for U in (0.0, 9.0):
        for mu in (math.pi, 2.4, math.pi / 2, 0.7):
            R = design.rao(w, mu, U)
            h = design.roll_receptance(w, mu, U)
            for kc, kb in ((-0.25, 0.04), (0.3, -0.03)):
                other = DesignRAO(design.path)
                r = other._out[1]
                other.C[r, r] += kc * c44
                other.B44 += kb * bcrit
                R2 = other.rao(w, mu, U)
                we = w - w * w * U * math.cos(mu) / G
                q = 1.0 / (1.0 + (kc * c44 + 1j * we * kb * bcrit) * h)
                np.testing.assert_allclose(R2[1], R[1] * q, rtol=1e-9, atol=1e-14)
                np.testing.assert_allclose(R2[[0, 2]], R[[0, 2]], rtol=1e-9, atol=1e-14)
    # the design's own damping at speed, in the same units: the fixed ratio plus the hull-lift term
    assert design.roll_damping_ratio(0.0) == pytest.approx(float(design.attrs["roll_damping_ratio"]))
    assert design.roll_damping_ratio(9.0) > design.roll_damping_ratio(0.0)
