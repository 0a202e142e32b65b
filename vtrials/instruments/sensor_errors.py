"""Sensor-specific error physics of the heading, speed-log, IMU and shaft-torque instruments (issue 17
item 6): the pieces that are not generic error parts (parts.py) because they depend on what the
sensor is and where it sits.

* Gyrocompass speed (steaming) error and the ballistic deflection of its north-seeking loop.
  A north-seeking gyrocompass settles with its spin axis in the plane of the *apparent* earth rate:
  the ship's north velocity V_N over the curved earth adds a rotation V_N/R_E about east, so the
  axis settles off the meridian by δ = −arcsin(V_N/(R_E Ω cos φ)) (west of north on northerly
  courses): the compass then reads HIGH by −δ ("westerly" speed error on northerly courses, easterly on
  southerly; zero on east–west courses). Source: Bowditch, The American Practical Navigator (NGA
  Pub. 9), chapter "Compasses", gyrocompass errors (speed error, ballistic deflection); the formula is
  the standard one of gyrocompass texts (e.g. Arnold & Maunder, Gyrodynamics and its Engineering
  Applications, 1961, ch. on the gyrocompass). A speed/latitude corrector subtracts the error computed
  from the speed and latitude set on it; the residual is what a mis-set corrector leaves.

  Loop dynamics (the linearised pendulous gyrocompass, same sources; sign convention: azimuth a of
  the spin axis east of north, tilt θ north end up, W = Ω cos φ):
      a' = c θ − (c/g) a_N                (precession by the pendulous torque; a_N tilts the apparent vertical)
      θ' = −W a − V_N/R_E − D θ           (earth rate and transport rate; tilt damping D)
  Undamped frequency ω_n² = c W. The compass is Schuler-tuned at latitude φ_t when c = g/(R_E Ω cos φ_t):
  then ω_n = √(g/R_E), period 2π√(R_E/g) = 84.4 min (Schuler 1923), and the ballistic deflection an
  acceleration produces, −(c/g) ΔV_N, equals the change of the speed error exactly, so the compass goes
  straight to its new settling point. At another latitude φ the ballistic deflection is wrong by
  κ ΔV_N with κ = (1/(R_E Ω))(1/cos φ − 1/cos φ_t), and the error about the settling point ε = a − a_s
  obeys ε'' + 2ζω_n ε' + ω_n² ε = 0 after the change, from ε(0) = κ ΔV_N, ε'(0) = 0:
      ε(t) = κ ΔV_N e^{−ζω_n t} (cos ω_d t + ζω_n/ω_d sin ω_d t),  ω_d = ω_n √(1 − ζ²).
  (:func:`ballistic_transient`). The integration (:func:`gyro_loop`) is exact per step for the free
  motion (closed-form 2×2 transition matrix) with each step's north-velocity change applied as an
  impulse (the acceleration lasts seconds, the loop's period is 84 min).

* Knotmeter break-away with hysteresis (:func:`breakaway_hysteresis`): an impeller held by static
  bearing friction starts only when the hydrodynamic torque exceeds the static friction (water speed
  above the break-away speed V_b, seed 000: "does not turn until some break-away speed is reached
  between zero and 6 knots"); once turning, kinetic friction is lower, so it keeps turning down to a
  stall speed V_s < V_b. With the driving torque ∝ speed², V_s/V_b = √(μ_k/μ_s).

* EM log response (:func:`em_log_response`): an electromagnetic log measures the water velocity
  component along its sensing axis (Faraday induction across the electrode pair: the cosine law),
  so with the horizontal flow at the sensor V at flow angle β (drift/leeway plus the yaw rate's lever
  arm) and the axis misaligned by ε in yaw it reads V cos(β − ε). Heel moves the sensor relative to the
  hull's boundary layer; modelled assumption (documented parameter k_h): the local speed changes by the
  factor (1 + k_h |φ|).

* Stern-tube loss between torsionmeter and propeller (:func:`gauge_torque`): the gauge is on the shaft
  between the engine and the stern tube, so in steady running it carries the propeller torque plus the
  friction of the bearings and seal aft of it: Q_gauge = Q_P + s c_F n, with c_F n the shaft line's
  friction torque (ship model) and s the share of it that lies aft of the gauge.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from vtrials.units import G

EARTH_RADIUS = 6_371_000.0   # mean earth radius [m] (IUGG mean radius R1 = 6 371 008.8 m, rounded)
EARTH_RATE = 7.2921150e-5    # earth's sidereal rotation rate [rad/s] (IERS conventions 2010)


def schuler_period() -> float:
    """Schuler period 2π√(R_E/g) [s] (84.4 min)."""
    return 2.0 * math.pi * math.sqrt(EARTH_RADIUS / G)


def speed_error(v_north, latitude):
    """Gyrocompass speed error as the compass READS it (reading − true) [rad]:
    +arcsin(V_N/(R_E Ω cos φ)) for north velocity V_N [m/s] at latitude φ [rad] (Bowditch)."""
    x = np.asarray(v_north, float) / (EARTH_RADIUS * EARTH_RATE * math.cos(latitude))
    return np.arcsin(np.clip(x, -1.0, 1.0))


def ballistic_kappa(latitude: float, tuned_latitude: float) -> float:
    """Mis-tuning κ [rad per m/s]: the ballistic deflection's excess over the change of speed error."""
    return (1.0 / math.cos(latitude) - 1.0 / math.cos(tuned_latitude)) / (EARTH_RADIUS * EARTH_RATE)


def loop_constants(latitude: float, tuned_latitude: float, damping_ratio: float) -> tuple[float, float, float]:
    """(c, W, D): precession constant c = g/(R_E Ω cos φ_t) [1/s·rad/rad], W = Ω cos φ [rad/s], tilt damping
    D = 2 ζ ω_n [1/s] with ω_n² = c W."""
    c = G / (EARTH_RADIUS * EARTH_RATE * math.cos(tuned_latitude))
    W = EARTH_RATE * math.cos(latitude)
    return c, W, 2.0 * damping_ratio * math.sqrt(c * W)


def ballistic_transient(t, dv_north: float, latitude: float, tuned_latitude: float, damping_ratio: float):
    """Analytic error of the spin axis about its settling point [rad] a time t [s] after a quick change
    dv_north [m/s] of north velocity (see the module docstring). The READING error is its negative."""
    c, W, D = loop_constants(latitude, tuned_latitude, damping_ratio)
    wn = math.sqrt(c * W)
    sig = 0.5 * D
    wd = math.sqrt(wn * wn - sig * sig)
    t = np.asarray(t, float)
    return ballistic_kappa(latitude, tuned_latitude) * dv_north * np.exp(-sig * t) * (
        np.cos(wd * t) + sig / wd * np.sin(wd * t))


@nb.njit(cache=True)
def gyro_loop(t, v_north, c, W, D, kappa, state, t_prev, v_prev):
    """Spin-axis error about the settling point ε [rad] at each sample (see the module docstring).

    ``state`` = (ε, θ) at ``t_prev`` with north velocity ``v_prev`` (carried across chunks; updated in
    place). Between samples the free loop evolves with its exact transition matrix
    Φ(h) = e^{−σh}[cos(ω_d h) I + sin(ω_d h)/ω_d (A + σ I)], A = [[0, c], [−W, −D]], σ = D/2; the
    change of V_N over the step enters as the impulse κ ΔV_N on ε at its end."""
    n = t.size
    out = np.empty(n)
    sig = 0.5 * D
    wd = math.sqrt(c * W - sig * sig)
    e = state[0]
    th = state[1]
    tl = t_prev
    vl = v_prev
    for k in range(n):
        h = t[k] - tl
        if h > 0.0:
            ex = math.exp(-sig * h)
            co = math.cos(wd * h)
            si = math.sin(wd * h) / wd
            e_new = ex * (co * e + si * (sig * e + c * th))
            th_new = ex * (co * th + si * (-W * e + (sig - D) * th))
            e = e_new
            th = th_new
        e += kappa * (v_north[k] - vl)
        vl = v_north[k]
        tl = t[k]
        out[k] = e
    state[0] = e
    state[1] = th
    return out, tl, vl


@nb.njit(cache=True)
def breakaway_hysteresis(w, v_break, v_stall, turning0):
    """Impeller state per sample: starts when the water speed w rises above v_break, stops when it
    falls below v_stall (v_stall <= v_break). Returns (turning flags, final state)."""
    out = np.empty(w.size, dtype=np.bool_)
    on = turning0
    for k in range(w.size):
        if on:
            if w[k] < v_stall:
                on = False
        elif w[k] > v_break:
            on = True
        out[k] = on
    return out, on


def em_log_response(u, v, heel, misalignment: float, heel_sensitivity: float):
    """EM-log speed [m/s] from the water velocity at the sensor (u along, v across the ship [m/s]) and
    heel [rad]: V cos(β − ε)(1 + k_h |φ|) = (u cos ε + v sin ε)(1 + k_h |φ|) (cosine law of a
    single-axis electromagnetic sensor; heel factor: modelled assumption, see the module docstring)."""
    u = np.asarray(u, float)
    v = np.asarray(v, float)
    return (u * math.cos(misalignment) + v * math.sin(misalignment)) * (1.0 + heel_sensitivity * np.abs(heel))


def gauge_torque(q_prop, n, friction: float, aft_share: float):
    """Torque at the torsionmeter [N m]: propeller torque plus the share ``aft_share`` of the shaft
    line's friction c_F n that lies between the gauge and the propeller (stern-tube bearing and seal)."""
    return np.asarray(q_prop, float) + aft_share * friction * np.asarray(n, float)
