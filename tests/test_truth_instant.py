"""The truth rows' instants (issue 16): MuJoCo's semi-implicit Euler step x_{n+1} = x_n + h v_{n+1} leaves
each row's pose and accelerations at its time t_n and its velocities at t_n − h/2. The instruments read
velocities carried half a step forward (vtrials.instruments.kinematics.SiteKinematics with the integrator
step). Independent reference: the central differences of the row's own positions and heading, which
the midpoint velocities must reproduce to rounding, and which the raw velocities miss by U·ψ̇·h/2 in a
turn (the half-step skew that biased patrol51's identified Y_ur by +3.6 %)."""

import h5py
import numpy as np

from vtrials.instruments.kinematics import SiteKinematics
from vtrials.runner.side_by_side import simulate, write_outputs
from vtrials.scenario import load_scenario
from vtrials.schema import load_toml
from vtrials.score.compat import truth_columns


def test_midpoint_velocities_match_the_positions_of_the_same_rows(tmp_path, scenarios_dir):
    path = scenarios_dir / "patrol51_identification.toml"
    doc = load_toml(path)
    doc["maneuver"] = [m for m in doc["maneuver"] if m["name"] == "turn_20_starboard_standard"]
    doc["maneuver"][0]["approach_s"] = 20.0
    write_outputs(simulate(load_scenario(path, doc=doc)), tmp_path / "out", plot=False)
    with h5py.File(tmp_path / "out" / "truth.nc") as f:
        h = float(f.attrs["timestep_s"][0])
        g = f["turn_20_starboard_standard"]
        tv = {k: g[k][()] for k in g.keys()}
    cols = truth_columns(tv, tv["time"], h)
    assert np.allclose(np.diff(cols["t"]), h)
    kin = SiteKinematics(cols, np.zeros(3))
    raw = SiteKinematics({k: v for k, v in cols.items() if k != "step_s"}, np.zeros(3))
    P = np.column_stack([cols["x"], cols["y"], cols["z"]])
    chord = (P[2:] - P[:-2]) / (2 * h)                        # world velocity at rows 1 … n−2
    turn = np.abs(cols["r"][1:-1]) > 0.03
    assert turn.sum() > 1000
    mid = kin.velocity_world()[1:-1]
    skew = raw.velocity_world()[1:-1]
    assert np.max(np.abs(mid - chord)[turn]) < 1e-6
    assert np.median(np.linalg.norm(skew - chord, axis=1)[turn]) > 1e-3    # U ψ̇ h/2 ≈ 8.5 × 0.056 × 0.01 m/s
    # the heading rate from the midpoint body rates, φ and θ against the heading's central difference
    phi, th = cols["roll"], cols["pitch"]
    psi_c = np.gradient(np.unwrap(cols["heading"]), cols["t"])[1:-1]
    for k, lim in ((kin, 2e-6), (raw, None)):
        w = k.omega
        rate = ((w[:, 1] * np.sin(phi) + w[:, 2] * np.cos(phi)) / np.cos(th))[1:-1]
        err = np.abs(rate - psi_c)[turn]
        if lim is not None:
            assert np.max(err) < lim
        else:
            assert np.max(err) > 10 * 2e-6
