"""Independent reference implementation of the 3-DOF MMG standard model.

Yasukawa, H. & Yoshimura, Y. (2015) "Introduction of MMG standard method for
ship maneuvering predictions", J. Mar. Sci. Technol. 20:37-52 (below "Y&Y").
Ship: KVLCC2 L7 model.  Only numpy/scipy are used; nothing is shared with the
simulator under test.

Conventions: body axes at midship, x forward, y starboard, z down; u surge,
v_m sway at midship (+ to starboard), r yaw rate (+ turning to starboard),
psi heading (rad, clockwise from earth x / north); delta > 0 turns the ship to
starboard.  State vector: [x, y, psi, u, v_m, r, delta].
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from types import MappingProxyType

import numpy as np
from scipy.integrate import solve_ivp, trapezoid
from scipy.optimize import brentq

G = 9.80665  # m/s^2

#: KVLCC2 L7 parameters (Y&Y Tables 1-3), typed in from the test specification.
KVLCC2_L7 = MappingProxyType(dict(
    L=7.00, B=1.27, d=0.46, disp=3.27, x_G=0.25, D_P=0.216, H_R=0.345,
    A_R=0.0539, rho=1000.0, k_zz=0.25,           # k_zz as a fraction of L
    mx=0.022, my=0.223, Jz=0.011,                  # added masses (non-dim.)
    R0=0.022, Xvv=-0.040, Xvr=0.002, Xrr=0.011, Xvvvv=0.771,
    Yv=-0.315, Yr=0.083, Yvvv=-1.607, Yvvr=0.379, Yvrr=-0.391, Yrrr=0.008,
    Nv=-0.137, Nr=-0.049, Nvvv=-0.030, Nvvr=-0.294, Nvrr=0.055, Nrrr=-0.013,
    t_P=0.220, w_P0=0.40, xP=-0.48, k0=0.2931, k1=-0.2753, k2=-0.1385,
    C1=2.0, C2_pos=1.6, C2_neg=1.1,               # C2: beta_P > 0 / beta_P <= 0
    t_R=0.387, a_H=0.312, xH=-0.464, gammaR_neg=0.395, gammaR_pos=0.640,
    lR=-0.710, eps=1.09, kappa=0.50, f_alpha=2.747,
    delta_rate_max=math.radians(15.8), T_delta=0.1,  # steering gear
))


# --------------------------------------------------------------------------
# Model
# --------------------------------------------------------------------------
def self_propulsion_rps(params, U):
    """Propeller rps n giving zero surge force straight ahead at speed U.

    Solves -R0' 1/2 rho L d U^2 + (1-t_P) rho n^2 D^4 K_T(J) = 0 with
    J = U (1-w_P0)/(n D) and K_T = k0 + k1 J + k2 J^2, i.e.
    (1-t_P) rho [k0 D^4 n^2 + k1 D^3 a n + k2 D^2 a^2] = R,  a = U (1-w_P0);
    the positive root of this quadratic in n is returned.
    """
    p = params
    R = p["R0"] * 0.5 * p["rho"] * p["L"] * p["d"] * U**2
    a = U * (1.0 - p["w_P0"])
    c = (1.0 - p["t_P"]) * p["rho"]
    D = p["D_P"]
    A, B, C = c * p["k0"] * D**4, c * p["k1"] * D**3 * a, c * p["k2"] * D**2 * a**2 - R
    return (-B + math.sqrt(B * B - 4 * A * C)) / (2 * A)


def forces(params, u, v, r, delta, n):
    """Hull, propeller and rudder forces (X, Y, N) about midship, Y&Y eqs (4)-(10), (35)-(46)."""
    p = params
    L, d, rho = p["L"], p["d"], p["rho"]
    U = math.hypot(u, v)
    beta = math.atan2(-v, u)
    vp, rp = v / U, r * L / U                       # v', r'
    q = 0.5 * rho * L * d * U**2
    # Hull (Y&Y eq. 10)
    XH = q * (-p["R0"] + p["Xvv"] * vp**2 + p["Xvr"] * vp * rp + p["Xrr"] * rp**2
              + p["Xvvvv"] * vp**4)
    YH = q * (p["Yv"] * vp + p["Yr"] * rp + p["Yvvv"] * vp**3 + p["Yvvr"] * vp**2 * rp
              + p["Yvrr"] * vp * rp**2 + p["Yrrr"] * rp**3)
    NH = q * L * (p["Nv"] * vp + p["Nr"] * rp + p["Nvvv"] * vp**3 + p["Nvvr"] * vp**2 * rp
                  + p["Nvrr"] * vp * rp**2 + p["Nrrr"] * rp**3)
    # Propeller (Y&Y eqs. 35-38, 16-17 of the standard wake model)
    D = p["D_P"]
    betaP = beta - p["xP"] * rp
    C2 = p["C2_pos"] if betaP > 0 else p["C2_neg"]
    one_m_wP = (1 - p["w_P0"]) * (1 + (1 - math.exp(-p["C1"] * abs(betaP))) * (C2 - 1))
    J = u * one_m_wP / (n * D)
    KT = p["k0"] + p["k1"] * J + p["k2"] * J**2
    XP = (1 - p["t_P"]) * rho * n**2 * D**4 * KT
    # Rudder (Y&Y eqs. 39-46)
    eta = D / p["H_R"]
    uR = p["eps"] * u * one_m_wP * math.sqrt(
        eta * (1 + p["kappa"] * (math.sqrt(1 + 8 * KT / (math.pi * J**2)) - 1))**2 + (1 - eta))
    betaR = beta - p["lR"] * rp
    gammaR = p["gammaR_neg"] if betaR < 0 else p["gammaR_pos"]
    vR = U * gammaR * betaR
    alphaR = delta - math.atan(vR / uR)
    FN = 0.5 * rho * p["A_R"] * (uR**2 + vR**2) * p["f_alpha"] * math.sin(alphaR)
    XR = -(1 - p["t_R"]) * FN * math.sin(delta)
    YR = -(1 + p["a_H"]) * FN * math.cos(delta)
    NR = -(-0.5 * L + p["a_H"] * p["xH"] * L) * FN * math.cos(delta)
    return XH + XR + XP, YH + YR, NH + NR


def _mass(params):
    """m, m_x, m_y, I_zG, J_z (dimensional)."""
    p = params
    L, d, rho = p["L"], p["d"], p["rho"]
    m = rho * p["disp"]
    return (m, p["mx"] * 0.5 * rho * L**2 * d, p["my"] * 0.5 * rho * L**2 * d,
            m * (p["k_zz"] * L)**2, p["Jz"] * 0.5 * rho * L**4 * d)


def rhs(params, n, state, delta_c, sat_sign):
    """Time derivative of [x, y, psi, u, v_m, r, delta] (Y&Y eq. 4 + kinematics + steering gear).

    Steering gear: delta_dot = clip((delta_c - delta)/T_delta, -rate, +rate).  The branch
    is passed explicitly (sat_sign = +-1: saturated, 0: linear) so that the right-hand side
    is smooth within each integration segment; `simulate` switches it at the exact kink.
    """
    p = params
    _, _, psi, u, v, r, delta = state
    m, mx, my, Iz, Jz = _mass(p)
    xG = p["x_G"]
    X, Y, N = forces(p, u, v, r, delta, n)
    udot = (X + (m + my) * v * r + xG * m * r**2) / (m + mx)
    # coupled sway-yaw: [[m+my, xG m], [xG m, Iz + xG^2 m + Jz]] [vdot, rdot] = rhs
    a11, a12, a22 = m + my, xG * m, Iz + xG**2 * m + Jz
    b1 = Y - (m + mx) * u * r
    b2 = N - xG * m * u * r
    det = a11 * a22 - a12 * a12
    vdot = (b1 * a22 - a12 * b2) / det
    rdot = (a11 * b2 - a12 * b1) / det
    ddot = sat_sign * p["delta_rate_max"] if sat_sign else (delta_c - delta) / p["T_delta"]
    return [u * math.cos(psi) - v * math.sin(psi), u * math.sin(psi) + v * math.cos(psi),
            r, udot, vdot, rdot, ddot]


# --------------------------------------------------------------------------
# Rudder programs.  k = number of program events so far; dpsi = psi - psi0.
# --------------------------------------------------------------------------
@dataclass(frozen=True)
class TurningCircle:
    """Constant rudder order delta_order_deg from t = 0; stops when |dpsi| = stop_deg (> 720)."""
    delta_order_deg: float
    stop_deg: float = 725.0
    n_events_stop: int = field(default=1, init=False)

    def command(self, k):
        return math.radians(self.delta_order_deg)

    def event(self, k, dpsi):
        return math.copysign(1.0, self.delta_order_deg) * dpsi - math.radians(self.stop_deg)


@dataclass(frozen=True)
class ZigZag:
    """delta_a/psi_a zig-zag, first side s (+1 starboard, -1 port); stops at the 3rd switch.

    sigma_k = s (-1)^k; command delta_c = sigma_k delta_a; switch when sigma_k dpsi = psi_a.
    """
    delta_a_deg: float
    psi_a_deg: float
    side: int = 1
    n_events_stop: int = field(default=3, init=False)

    def command(self, k):
        return self.side * (-1) ** k * math.radians(self.delta_a_deg)

    def event(self, k, dpsi):
        return self.side * (-1) ** k * dpsi - math.radians(self.psi_a_deg)


# --------------------------------------------------------------------------
# Integration
# --------------------------------------------------------------------------
@dataclass
class Result:
    """Piecewise dense trajectory. `t`, `y`: solver step points; `event_times`: program events."""
    program: object
    psi0: float
    U0: float
    n: float
    t: np.ndarray
    y: np.ndarray
    segments: list                     # [(t0, t1, OdeSolution)]
    event_times: list

    def __call__(self, t):
        """State(s) at time(s) t from the dense output; shape (7,) or (7, len(t))."""
        tt = np.atleast_1d(np.asarray(t, float))
        out = np.empty((7, tt.size))
        starts = np.array([s[0] for s in self.segments])
        idx = np.clip(np.searchsorted(starts, tt, side="right") - 1, 0, len(self.segments) - 1)
        for i in np.unique(idx):
            sel = idx == i
            out[:, sel] = self.segments[i][2](tt[sel])
        return out[:, 0] if np.ndim(t) == 0 else out


def simulate(params, U0, n, rudder_program, t_end, psi0=0.0, method="DOP853",
             rtol=1e-9, atol=1e-10):
    """Integrate the MMG model from straight-ahead motion at U0 with constant rps n.

    Integration restarts (a) at each rudder-program event (zig-zag switch / turning stop),
    located by solve_ivp event detection, and (b) at the steering-gear kink where the rate
    limit stops being active.  Returns a `Result`.
    """
    p = params
    y = np.array([0.0, 0.0, psi0, U0, 0.0, 0.0, 0.0])
    t, k = 0.0, 0
    dc = rudder_program.command(k)
    thr = p["T_delta"] * p["delta_rate_max"]

    def regime(dc, delta):
        return float(np.sign(dc - delta)) if abs(dc - delta) > thr else 0.0

    sat = regime(dc, y[6])
    segs, ts, ys, ev_times = [], [], [], []
    while t < t_end:
        ev_prog = lambda tt, yy, k=k: rudder_program.event(k, yy[2] - psi0)
        ev_prog.terminal, ev_prog.direction = True, 1
        events = [ev_prog]
        if sat:
            # signed (monotone) gap, so large saturated steps cannot jump over the kink
            ev_kink = lambda tt, yy, dc=dc, sg=sat: sg * (dc - yy[6]) - thr
            ev_kink.terminal, ev_kink.direction = True, -1
            events.append(ev_kink)
        sol = solve_ivp(lambda tt, yy, dc=dc, sat=sat: rhs(p, n, yy, dc, sat), (t, t_end), y,
                        method=method, rtol=rtol, atol=atol, dense_output=True, events=events)
        if sol.status < 0:
            raise RuntimeError(sol.message)
        segs.append((float(t), float(sol.t[-1]), sol.sol))
        ts.append(sol.t)
        ys.append(sol.y)
        t, y = sol.t[-1], sol.y[:, -1].copy()
        if sol.status != 1:
            break
        if sol.t_events[0].size:                 # rudder-program event
            ev_times.append(float(t))
            k += 1
            if k >= rudder_program.n_events_stop:
                break
            dc = rudder_program.command(k)
            sat = regime(dc, y[6])
        else:                                    # steering-gear kink: enter linear branch
            sat = 0.0
    return Result(rudder_program, psi0, U0, n, np.concatenate(ts), np.concatenate(ys, axis=1),
                  segs, ev_times)


# --------------------------------------------------------------------------
# Metrics
# --------------------------------------------------------------------------
def _first_crossing(res, f, t_lo=-np.inf, t_hi=np.inf):
    """First t in [t_lo, t_hi] where f (on the dense output) goes from < 0 to >= 0 (brentq)."""
    t = res.t[(res.t >= t_lo) & (res.t <= t_hi)]
    t = np.unique(np.concatenate(([max(t_lo, res.t[0])], t, [min(t_hi, res.t[-1])])))
    vals = np.array([f(ti) for ti in t])
    i = np.flatnonzero(vals >= 0)
    if i.size == 0:
        raise ValueError("crossing not reached")
    i = i[0]
    if i == 0:
        return t[0]
    return brentq(f, t[i - 1], t[i], xtol=1e-13, rtol=4 * np.finfo(float).eps, maxiter=200)


def turning_metrics(result, L):
    """Turning-circle metrics (m, m/s, deg/s), track in initial-heading axes (xi, eta)."""
    res, psi0 = result, result.psi0
    s = math.copysign(1.0, res.y[2, -1] - psi0)
    x0, y0 = res.y[0, 0], res.y[1, 0]
    c, sn = math.cos(psi0), math.sin(psi0)

    def xi_eta(st):
        dx, dy = st[0] - x0, st[1] - y0
        return dx * c + dy * sn, -dx * sn + dy * c

    def t_at(deg):
        return _first_crossing(res, lambda tt: s * (res(tt)[2] - psi0) - math.radians(deg))

    t90, t180, t360, t720 = (t_at(a) for a in (90, 180, 360, 720))
    xi90, eta90 = xi_eta(res(t90))
    _, eta180 = xi_eta(res(t180))
    tw = np.linspace(t360, t720, 4001)
    st = res(tw)
    X, Y = st[0], st[1]
    A = np.column_stack([X, Y, np.ones_like(X)])          # Kasa: x^2+y^2 = a x + b y + c
    a, b, cc = np.linalg.lstsq(A, X**2 + Y**2, rcond=None)[0]
    R = math.sqrt(cc + (a * a + b * b) / 4)
    T = t720 - t360
    return dict(
        advance_m=xi90, transfer_m=abs(eta90), tactical_diameter_m=abs(eta180),
        steady_turning_diameter_m=2 * R,
        steady_speed_mps=trapezoid(np.hypot(st[3], st[4]), tw) / T,
        steady_rate_of_turn_dps=math.degrees(trapezoid(np.abs(st[5]), tw) / T),
        advance_L=xi90 / L, transfer_L=abs(eta90) / L, tactical_diameter_L=abs(eta180) / L,
        steady_turning_diameter_L=2 * R / L,
        t90_s=t90, t180_s=t180, t360_s=t360, t720_s=t720,
    )


def zigzag_metrics(result):
    """Initial turning time and first/second overshoot angles of a zig-zag run (deg, s)."""
    res, prog, psi0 = result, result.program, result.psi0
    if len(res.event_times) < 3:
        raise ValueError("zig-zag did not reach the third switch")
    s, psi_a = prog.side, prog.psi_a_deg
    t1, t2, t3 = res.event_times[:3]

    def peak(sign, ta, tb):
        # max of sign*dpsi on [ta, tb]: root of sign*r going + -> -
        tm = _first_crossing(res, lambda tt: -sign * res(tt)[5], ta, tb)
        return tm, math.degrees(sign * (res(tm)[2] - psi0))

    tm1, p1 = peak(s, t1, t2)
    tm2, p2 = peak(-s, t2, t3)
    return dict(initial_turning_time_s=t1, first_overshoot_deg=p1 - psi_a,
                second_overshoot_deg=p2 - psi_a, first_overshoot_time_s=tm1,
                second_overshoot_time_s=tm2, switch_times_s=(t1, t2, t3))


def run_all(params=KVLCC2_L7, Fn=0.142, **kw):
    """Standard maneuvers from U0 = Fn sqrt(g L) at self-propulsion rps. Returns a dict."""
    L = params["L"]
    U0 = Fn * math.sqrt(G * L)
    n = self_propulsion_rps(params, U0)
    out = dict(U0=U0, n=n)
    for d in (35.0, -35.0):
        out[f"turn{d:+.0f}"] = turning_metrics(
            simulate(params, U0, n, TurningCircle(d), 2000.0, **kw), L)
    for a in (10.0, 20.0):
        for side in (1, -1):
            out[f"zz{a:.0f}/{a:.0f}{'S' if side > 0 else 'P'}"] = zigzag_metrics(
                simulate(params, U0, n, ZigZag(a, a, side), 2000.0, **kw))
    return out


if __name__ == "__main__":
    r = run_all()
    print(f"U0 = {r['U0']:.6f} m/s, self-propulsion n = {r['n']:.6f} rps")
    for key, m in r.items():
        if key.startswith("turn"):
            print(f"{key}: advance {m['advance_m']:.4f} m ({m['advance_L']:.4f} L), "
                  f"transfer {m['transfer_m']:.4f} m ({m['transfer_L']:.4f} L), "
                  f"tactical {m['tactical_diameter_m']:.4f} m ({m['tactical_diameter_L']:.4f} L), "
                  f"steady D {m['steady_turning_diameter_m']:.4f} m "
                  f"({m['steady_turning_diameter_L']:.4f} L), "
                  f"U_ss {m['steady_speed_mps']:.5f} m/s, r_ss {m['steady_rate_of_turn_dps']:.5f} deg/s")
        elif key.startswith("zz"):
            print(f"{key}: t_init {m['initial_turning_time_s']:.4f} s, "
                  f"1st OS {m['first_overshoot_deg']:.4f} deg, "
                  f"2nd OS {m['second_overshoot_deg']:.4f} deg")
