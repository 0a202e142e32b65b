"""The trials team's correction of the gyrocompass speed error (the standard table/formula correction).

A north-seeking gyrocompass reads high by arcsin(V_N/(R_E Ω cos φ)) — V_N the ship's north velocity
over ground, φ the latitude (Bowditch, The American Practical Navigator, NGA Pub. 9, ch. Compasses:
speed error, westerly on northerly courses). A speed/latitude corrector set to speed V_c and latitude
φ_c has already removed arcsin(V_c cos ψ/(R_E Ω cos φ_c)). The team knows only its own tracking fixes
(V_N from the track), the site latitude and the corrector settings written in the log, and removes
the remainder. It cannot remove the ballistic transient of a mis-tuned compass (it does not know the
mis-tuning), nor the compass's bias and drift.
"""

from __future__ import annotations

import math

import numpy as np

EARTH_RADIUS = 6_371_000.0   # mean earth radius [m] (IUGG R1, rounded)
EARTH_RATE = 7.2921150e-5    # earth rotation rate [rad/s] (IERS conventions 2010)


def speed_error(v_north, latitude: float):
    """Speed error as read (reading − true) [rad] for north velocity [m/s] at latitude [rad]."""
    x = np.asarray(v_north, float) / (EARTH_RADIUS * EARTH_RATE * math.cos(latitude))
    return np.arcsin(np.clip(x, -1.0, 1.0))


def track_north_velocity(t, north, t_out, window_s: float = 30.0):
    """North velocity [m/s] at times t_out from position fixes (t [s], north [m]): slope of a straight
    line fitted to the fixes within ±window_s/2 of each output time (centred differences of a noisy
    track; a fix error of a few metres over 30 s is ~0.1 m/s, i.e. 0.01° of speed error)."""
    t = np.asarray(t, float)
    north = np.asarray(north, float)
    t_out = np.asarray(t_out, float)
    if t.size < 2:
        raise ValueError("need at least two fixes for the north velocity")
    # running sums for least-squares slopes in windows (vectorised)
    c = np.concatenate([[0.0], np.cumsum(t)])
    cy = np.concatenate([[0.0], np.cumsum(north)])
    ctt = np.concatenate([[0.0], np.cumsum(t * t)])
    cty = np.concatenate([[0.0], np.cumsum(t * north)])
    lo = np.searchsorted(t, t_out - 0.5 * window_s, side="left")
    hi = np.searchsorted(t, t_out + 0.5 * window_s, side="right")
    n = (hi - lo).astype(float)
    st, sy, stt, sty = c[hi] - c[lo], cy[hi] - cy[lo], ctt[hi] - ctt[lo], cty[hi] - cty[lo]
    den = n * stt - st * st
    with np.errstate(invalid="ignore", divide="ignore"):
        slope = (n * sty - st * sy) / den
    ok = (n >= 3) & (den > 0)
    if not np.any(ok):
        return np.gradient(north, t)[np.clip(np.searchsorted(t, t_out), 0, t.size - 1)]
    return np.interp(t_out, t_out[ok], slope[ok])


def correct_heading(t_heading, heading, t_fix, north_fix, latitude: float, corrector_speed: float = 0.0,
                    corrector_latitude: float | None = None, v_north=None):
    """Gyro heading [rad] with the residual speed error removed: ψ − [e(V̂_N, φ) − e(V_c cos ψ, φ_c)],
    V̂_N from the track (:func:`track_north_velocity`), φ the site latitude, (V_c, φ_c) the corrector
    settings (V_c = 0: corrector off). ``v_north``: optional (t [s], V_N [m/s]) measured by the
    receiver itself (GNSS Doppler), interpolated to the gyro's times instead of the track's slopes:
    in a tight turn the 30-s slopes of the track lose ~12 % of the swing of V_N (patrol vessel, 84-s
    circle), and next to a change of maneuver they mix in the motion after it."""
    heading = np.asarray(heading, float)
    if v_north is not None:
        vn = np.interp(np.asarray(t_heading, float), np.asarray(v_north[0], float), np.asarray(v_north[1], float))
    else:
        vn = track_north_velocity(t_fix, north_fix, t_heading)
    err = speed_error(vn, latitude)
    if corrector_speed > 0.0:
        err = err - speed_error(corrector_speed * np.cos(heading),
                                latitude if corrector_latitude is None else corrector_latitude)
    return heading - err
