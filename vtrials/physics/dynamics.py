"""The per-step dynamics kernel: from MuJoCo's state to the generalized forces MuJoCo applies.

For every ship, each step:

1. kinematics from the free joint (position, quaternion; linear velocity is world-frame, angular
   velocity body-frame in MuJoCo), heading unwrapped, current at the ship, velocity through the
   water ν_r = ν − [Rᵀ V_C; 0];
2. the helm's rudder order (:mod:`vtrials.physics.steering`) and the governors' engine torques;
3. the force components (hull, propellers, rudders, hydrostatics, damping, wind, ... — whatever the
   ship's list holds: the kernel loops over them through a generated dispatch, see
   :mod:`vtrials.physics.forces.registry`; each may advance its own internal states) → body wrench τ;
4. the exact added-mass solve. With M_RB the rigid-body matrix MuJoCo itself uses (read from
   ``mj_fullM``), M_A the added-mass matrix and C(·) the Kirchhoff Coriolis–centripetal vector,
       (M_RB + M_A) ν̇ = τ + τ_g − C_RB(ν)ν − C_A(ν_r)ν_r + M_A a_C,
   where a_C is the body-frame rate of change of the current seen by the ship
   (−ω × Rᵀ V_C + Rᵀ(∂V_C/∂t + ∇V_C · v)), so that M_A multiplies the relative acceleration
   ν̇_r = ν̇ − a_C (Fossen 2011 §10.3: irrotational current). The wrench handed to MuJoCo is
       f = τ − M_A(ν̇ − a_C) − C_A(ν_r)ν_r,
   for which MuJoCo's rigid body (with its gravity τ_g) reproduces ν̇ exactly at this state —
   no acceleration from the previous step is used;
5. the steering gear (rate-limited follow-up, δ̇ = clip((δ_c − δ)/T, ±δ̇_max), imposed on the
   rudder hinge through its armature) and the shafts (I ω̇ = Q_E − Q_P − c_F n);
6. checks for non-finite or runaway states (a status code per ship) and the truth record row.
"""

from __future__ import annotations

import math
import types

import numba as nb
import numpy as np
from numba.extending import intrinsic
from numba.np.arrayobj import populate_array

from vtrials.physics import steering as H
from vtrials.physics import propulsion as PR
from vtrials.physics.forces import context as L
from vtrials.physics.forces import registry
from vtrials.physics.environment.current import E_DEPTH, current_at
from vtrials.physics.environment.wind import C_WIND_GUST, gust_step

# status codes
OK, NONFINITE, SPEED_RUNAWAY, ATTITUDE_RUNAWAY, RATE_RUNAWAY = 0, 1, 2, 3, 4
STATUS_TEXT = {NONFINITE: "non-finite state or acceleration", SPEED_RUNAWAY: "speed beyond the runaway limit",
               ATTITUDE_RUNAWAY: "heel or trim beyond the capsize limit",
               RATE_RUNAWAY: "angular rate beyond the runaway limit"}

# nav (per ship, persistent between steps); the wind gust's phasor state follows from NV_GUST on
# (vtrials.physics.environment.wind.gust_step; its length depends on the environment block)
NV_PSI_U, NV_DN, NV_DE = 0, 1, 2
NNAV = 4
NV_GUST = NNAV

# limits vector
LIM_SPEED, LIM_ANGLE, LIM_RATE = 0, 1, 2

# the component dispatch the step kernel calls: each compilation of the kernel (step_kernels) binds it
# to the dispatch generated for its component types; likewise the step kernel _run_steps calls
dispatch = None
_step_kernel = None


@intrinsic
def borrow(typingctx, arr):
    """A view of array ``arr`` that takes no part in numba's reference counting (no meminfo).

    Every slice or row of an array (``scratch[i]``, ``comp_par[i, a:b]``) raises and later lowers the
    reference count of the array's memory with an atomic instruction; in the step kernel those were
    ~100 locked operations per ship-step (a fifth of the whole step, perf), and with the ships spread
    over threads every thread hammers the same counters. Views of a borrowed array carry no
    meminfo, so the counting does nothing. The caller keeps ``arr`` alive for as long as the view
    is used (the kernel's arguments outlive the call); the data, and so the arithmetic, are the same.
    """
    sig = arr(arr)

    def codegen(context, builder, sig, args):
        src = context.make_array(sig.args[0])(context, builder, value=args[0])
        out = context.make_array(sig.return_type)(context, builder)
        populate_array(out, data=src.data, shape=src.shape, strides=src.strides, itemsize=src.itemsize,
                       meminfo=None)
        return out._getvalue()

    return sig, codegen


@nb.njit(cache=True)
def quat_to_mat(qw, qx, qy, qz, R):
    """Unit quaternion (MuJoCo order w, x, y, z) → rotation matrix body→world, row major."""
    R[0] = 1.0 - 2.0 * (qy * qy + qz * qz)
    R[1] = 2.0 * (qx * qy - qw * qz)
    R[2] = 2.0 * (qx * qz + qw * qy)
    R[3] = 2.0 * (qx * qy + qw * qz)
    R[4] = 1.0 - 2.0 * (qx * qx + qz * qz)
    R[5] = 2.0 * (qy * qz - qw * qx)
    R[6] = 2.0 * (qx * qz - qw * qy)
    R[7] = 2.0 * (qy * qz + qw * qx)
    R[8] = 1.0 - 2.0 * (qx * qx + qy * qy)


@nb.njit(cache=True)
def coriolis(M, nu1, om, munk, out):
    """Kirchhoff Coriolis–centripetal vector C(ν)ν for a 6×6 inertia M (Fossen 2011 Thm 3.2).

    P = M11 ν1 + M12 ω, Lm = M21 ν1 + M22 ω; C ν = [ω × P; ω × Lm + ν1 × P]. With ``munk`` false the
    ν1 × P term (the ideal-fluid Munk moments) is left out.
    """
    P0 = P1 = P2 = L0 = L1 = L2 = 0.0
    for j in range(3):
        P0 += M[0, j] * nu1[j] + M[0, j + 3] * om[j]
        P1 += M[1, j] * nu1[j] + M[1, j + 3] * om[j]
        P2 += M[2, j] * nu1[j] + M[2, j + 3] * om[j]
        L0 += M[3, j] * nu1[j] + M[3, j + 3] * om[j]
        L1 += M[4, j] * nu1[j] + M[4, j + 3] * om[j]
        L2 += M[5, j] * nu1[j] + M[5, j + 3] * om[j]
    out[0] = om[1] * P2 - om[2] * P1
    out[1] = om[2] * P0 - om[0] * P2
    out[2] = om[0] * P1 - om[1] * P0
    out[3] = om[1] * L2 - om[2] * L1
    out[4] = om[2] * L0 - om[0] * L2
    out[5] = om[0] * L1 - om[1] * L0
    if munk:
        out[3] += nu1[1] * P2 - nu1[2] * P1
        out[4] += nu1[2] * P0 - nu1[0] * P2
        out[5] += nu1[0] * P1 - nu1[1] * P0


@nb.njit(cache=True)
def kinematics(q, v, t, e, steer, shaftp, R, nu1, om, nu1r, c):
    """One ship's kinematics from its MuJoCo state (q = qpos, v = qvel, t time, e environment block):
    fills R (body→world), ν₁ (body-frame velocity over ground), ω, ν₁ᵣ (through the water) and the
    context entries NU_R, NU, POS, EUL, TIME, DEPTH, ROT, CUR, CUR_ACC, DELTA, DELTA_DOT, SHAFT_N;
    returns (φ, θ, ψ, V_C north, V_C east, a_C (body, 3)) with a_C the current's rate seen from the ship.
    """
    qn = math.sqrt(q[3] ** 2 + q[4] ** 2 + q[5] ** 2 + q[6] ** 2)
    quat_to_mat(q[3] / qn, q[4] / qn, q[5] / qn, q[6] / qn, R)
    for j in range(3):
        nu1[j] = R[j] * v[0] + R[3 + j] * v[1] + R[6 + j] * v[2]
        om[j] = v[3 + j]
    x = q[0]
    y = q[1]
    phi = math.atan2(R[7], R[8])
    st = -R[6]
    if st > 1.0:
        st = 1.0
    elif st < -1.0:
        st = -1.0
    theta = math.asin(st)
    psi = math.atan2(R[3], R[0])
    vcn, vce, acn, ace = current_at(e, x, y, t)
    # body-frame current and its rate as seen from the moving ship
    vcb0 = R[0] * vcn + R[3] * vce
    vcb1 = R[1] * vcn + R[4] * vce
    vcb2 = R[2] * vcn + R[5] * vce
    gx = v[0]
    gy = v[1]
    dvn = acn + e[9] * gx + e[10] * gy
    dve = ace + e[11] * gx + e[12] * gy
    ac0 = -(om[1] * vcb2 - om[2] * vcb1) + R[0] * dvn + R[3] * dve
    ac1 = -(om[2] * vcb0 - om[0] * vcb2) + R[1] * dvn + R[4] * dve
    ac2 = -(om[0] * vcb1 - om[1] * vcb0) + R[2] * dvn + R[5] * dve
    nu1r[0] = nu1[0] - vcb0
    nu1r[1] = nu1[1] - vcb1
    nu1r[2] = nu1[2] - vcb2
    for j in range(3):
        c[L.NU_R + j] = nu1r[j]
        c[L.NU_R + 3 + j] = om[j]
        c[L.NU + j] = nu1[j]
        c[L.NU + 3 + j] = om[j]
        c[L.POS + j] = q[j]
    c[L.EUL] = phi
    c[L.EUL + 1] = theta
    c[L.EUL + 2] = psi
    c[L.TIME] = t
    c[L.DEPTH] = e[E_DEPTH]
    for j in range(9):
        c[L.ROT + j] = R[j]
    c[L.CUR] = vcn
    c[L.CUR + 1] = vce
    # material (fluid-particle) acceleration of the current: ∂V/∂t + (V·∇)V
    c[L.CUR_ACC] = acn + e[9] * vcn + e[10] * vce
    c[L.CUR_ACC + 1] = ace + e[11] * vcn + e[12] * vce
    for k in range(steer.shape[0]):
        c[L.DELTA + k] = q[int(steer[k, 3])]
        c[L.DELTA_DOT + k] = v[int(steer[k, 4])]
    for k in range(shaftp.shape[0]):
        c[L.SHAFT_N + int(shaftp[k, PR.S_PROP])] = v[int(shaftp[k, PR.S_DADR])] / (2.0 * math.pi)
    return phi, theta, psi, vcn, vce, ac0, ac1, ac2


@nb.njit(cache=True)
def kinematics_all(qpos, qvel, time, env, steer, shaftp, ctx, scratch):
    """:func:`kinematics` of every ship into ``ctx`` (N, NCTX), the same values a step kernel or an
    evaluation writes there, without the forces; ``scratch`` (N, ≥ 18)."""
    for i in range(qpos.shape[0]):
        sc = scratch[i]
        kinematics(qpos[i], qvel[i], time[i], env[i], steer, shaftp, sc[0:9], sc[9:12], sc[12:15], sc[15:18],
                   ctx[i])


def record_width(n_rudders: int, n_shafts: int, n_components: int) -> int:
    return 34 + 2 * n_rudders + 5 * n_shafts + 3 * n_shafts + n_rudders + 6 * (n_components + 1)


def record_names(n_rudders: int, n_shafts: int, comp_names: list[str]) -> list[str]:
    """Column names of the truth record, in the kernel's order (units in :mod:`vtrials.truth.columns`)."""
    names = ["t", "x", "y", "z", "qw", "qx", "qy", "qz", "roll", "pitch", "heading",
             "u", "v", "w", "p", "q", "r", "u_r", "v_r", "w_r",
             "du", "dv", "dw", "dp", "dq", "dr", "current_n", "current_e", "drift_n", "drift_e",
             "wind_apparent_speed", "wind_apparent_angle", "wind_speed", "wind_direction"]
    names += [f"rudder_{k}" for k in range(n_rudders)] + [f"rudder_order_{k}" for k in range(n_rudders)]
    names += [f"shaft_n_{k}" for k in range(n_shafts)] + [f"shaft_order_{k}" for k in range(n_shafts)]
    names += [f"engine_torque_{k}" for k in range(n_shafts)]
    names += [f"pitch_{k}" for k in range(n_shafts)] + [f"pitch_order_{k}" for k in range(n_shafts)]
    for k in range(n_shafts):
        names += [f"thrust_{k}", f"prop_torque_{k}", f"advance_ratio_{k}"]
    names += [f"rudder_normal_force_{k}" for k in range(n_rudders)]
    for c in list(comp_names) + ["engine_reaction"]:
        names += [f"F_{c}_{a}" for a in ("X", "Y", "Z", "K", "M", "N")]
    return names


def _step_forces(dt, qpos, qvel, time, qfrc,
                 comp_kind, comp_off, comp_par, comp_soff, comp_st, minv, mrb, ma, coriolis_mode, rb, steer, shaftp, env,
                 rud_cmd, shaft_cmd, pitch_cmd, shaft_mode, mach, nav, phases, hs, events, ecount,
                 ctx, aux, comp_w, nudot, limits, status, rec, krec, scratch):
    """Compute MuJoCo's applied generalized forces for every ship; see the module docstring.

    Returns the number of ships whose status is not OK. ``scratch`` is an (N, 64) work array.
    Compiled twice: serially (``prange`` is then ``range``) and with the ships spread over threads;
    each ship's arithmetic is the same either way, so results are bit-identical.
    """
    # views without reference counting (see borrow); same data, same arithmetic
    qpos = borrow(qpos)
    qvel = borrow(qvel)
    time = borrow(time)
    qfrc = borrow(qfrc)
    comp_kind = borrow(comp_kind)
    comp_off = borrow(comp_off)
    comp_par = borrow(comp_par)
    comp_soff = borrow(comp_soff)
    comp_st = borrow(comp_st)
    minv = borrow(minv)
    mrb = borrow(mrb)
    ma = borrow(ma)
    rb = borrow(rb)
    steer = borrow(steer)
    shaftp = borrow(shaftp)
    env = borrow(env)
    rud_cmd = borrow(rud_cmd)
    shaft_cmd = borrow(shaft_cmd)
    pitch_cmd = borrow(pitch_cmd)
    shaft_mode = borrow(shaft_mode)
    mach = borrow(mach)
    nav = borrow(nav)
    phases = borrow(phases)
    hs = borrow(hs)
    events = borrow(events)
    ecount = borrow(ecount)
    ctx = borrow(ctx)
    aux = borrow(aux)
    comp_w = borrow(comp_w)
    nudot = borrow(nudot)
    limits = borrow(limits)
    status = borrow(status)
    rec = borrow(rec)
    scratch = borrow(scratch)
    nbad = 0
    for i in nb.prange(qpos.shape[0]):
        C = comp_kind.shape[0]
        nr = steer.shape[0]
        ns = shaftp.shape[0]
        sc = scratch[i]
        R = sc[0:9]
        nu1 = sc[9:12]
        om = sc[12:15]
        nu1r = sc[15:18]
        cvec = sc[18:24]
        tau = sc[24:30]
        rhs = sc[30:36]
        acc = sc[36:42]
        crb = sc[42:48]
        frc = sc[48:54]
        grav = sc[54:60]
        c = ctx[i]
        a = aux[i]
        t = time[i]
        e = env[i]
        phi, theta, psi, vcn, vce, ac0, ac1, ac2 = kinematics(qpos[i], qvel[i], t, e, steer, shaftp, R, nu1, om,
                                                              nu1r, c)
        psi_u = nav[i, NV_PSI_U] + H.wrap(psi - nav[i, NV_PSI_U])
        nav[i, NV_PSI_U] = psi_u
        c[L.DT] = dt
        c[C_WIND_GUST] = gust_step(e, nav[i, NV_GUST:], t, dt)
        # --- helm: one order for all rudders
        if nr > 0:
            order = H.helm_step(i, t, psi_u, om[2], dt, phases, hs, events, ecount, rud_cmd[i, 0])
            for k in range(nr):
                rud_cmd[i, k] = order
        # --- machinery before the forces: pitch actuators, set-point ramps, engine torque
        for k in range(ns):
            sp = shaftp[k]
            ms = mach[i, k]
            kp = int(sp[PR.S_PROP])
            n = c[L.SHAFT_N + kp]
            PR.machinery_step(sp, ms, n, shaft_cmd[i, k], pitch_cmd[i, k], int(shaft_mode[i, k]), dt)
            c[L.PITCH + kp] = ms[PR.M_PITCH]
            c[L.Q_ENGINE + k] = ms[PR.M_TORQUE]
        # --- force components
        for j in range(6):
            tau[j] = 0.0
        for ci in range(C):
            wc = comp_w[i, ci]
            dispatch(comp_kind[ci], comp_par[i, comp_off[ci]:comp_off[ci + 1]],
                     comp_st[i, comp_soff[ci]:comp_soff[ci + 1]], e, c, a, wc)
            for j in range(6):
                tau[j] += wc[j]
        # --- machinery torque on each shaft, and its reaction on the hull
        qreact = 0.0
        for k in range(ns):
            sp = shaftp[k]
            kp = int(sp[PR.S_PROP])
            n = c[L.SHAFT_N + kp]
            qp = a[L.AUX_PROP + 8 * kp + L.P_TORQUE]
            if int(shaft_mode[i, k]) == PR.LOCKED:
                # the brake holds the shaft: it stops it within one step and then carries the load
                qm = -sp[PR.S_INERTIA] * 2.0 * math.pi * n / dt + qp + sp[PR.S_FRICTION] * n
            else:
                qm = c[L.Q_ENGINE + k]
            c[L.Q_ENGINE + k] = qm
            qreact -= sp[PR.S_ROT] * qm
        wr = comp_w[i, C]
        for j in range(6):
            wr[j] = 0.0
        wr[3] = qreact
        tau[3] += qreact
        # --- exact added-mass solve
        mg = rb[i, 0] * rb[i, 4]
        gb0 = mg * R[6]
        gb1 = mg * R[7]
        gb2 = mg * R[8]
        grav[0] = gb0
        grav[1] = gb1
        grav[2] = gb2
        grav[3] = rb[i, 2] * gb2 - rb[i, 3] * gb1
        grav[4] = rb[i, 3] * gb0 - rb[i, 1] * gb2
        grav[5] = rb[i, 1] * gb1 - rb[i, 2] * gb0
        for j in range(6):
            rhs[j] = tau[j] + grav[j]
        coriolis(mrb[i], nu1, om, True, crb)
        if coriolis_mode == 0:
            for j in range(6):
                cvec[j] = 0.0
        else:
            coriolis(ma[i], nu1r, om, coriolis_mode == 2, cvec)
        for j in range(6):
            rhs[j] -= crb[j] + cvec[j]
            rhs[j] += ma[i, j, 0] * ac0 + ma[i, j, 1] * ac1 + ma[i, j, 2] * ac2
        for j in range(6):
            s = 0.0
            for l in range(6):
                s += minv[i, j, l] * rhs[l]
            acc[j] = s
            nudot[i, j] = s
        # the wrench for which MuJoCo's rigid body (with its own gravity) has acceleration ν̇:
        # f = M_RB ν̇ + C_RB(ν)ν − τ_g  (= τ − M_A(ν̇ − a_C) − C_A(ν_r)ν_r when all 6 DOF are free;
        # with a reduced inverse in ``minv`` the same line holds the locked DOF at zero acceleration)
        for j in range(6):
            s = crb[j] - grav[j]
            for l in range(6):
                s += mrb[i, j, l] * acc[l]
            frc[j] = s
        for j in range(3):
            qfrc[i, j] = R[3 * j] * frc[0] + R[3 * j + 1] * frc[1] + R[3 * j + 2] * frc[2]
            qfrc[i, 3 + j] = frc[3 + j]
        # --- steering gear: follow-up with rate limit, imposed on the hinge through its armature
        for k in range(nr):
            dmax = steer[k, 0]
            dc = rud_cmd[i, k]
            if dc > dmax:
                dc = dmax
            elif dc < -dmax:
                dc = -dmax
            rate = (dc - c[L.DELTA + k]) / steer[k, 2]
            if rate > steer[k, 1]:
                rate = steer[k, 1]
            elif rate < -steer[k, 1]:
                rate = -steer[k, 1]
            qfrc[i, int(steer[k, 4])] = steer[k, 5] * (rate - c[L.DELTA_DOT + k]) / dt
        # --- shafts: I ω̇ = Q_M − Q_P − c_F n
        for k in range(ns):
            sp = shaftp[k]
            kp = int(sp[PR.S_PROP])
            n = c[L.SHAFT_N + kp]
            qp = a[L.AUX_PROP + 8 * kp + L.P_TORQUE]
            qfrc[i, int(sp[PR.S_DADR])] = c[L.Q_ENGINE + k] - qp - sp[PR.S_FRICTION] * n
        # --- checks
        st_code = OK
        for j in range(6):
            if not (math.isfinite(acc[j]) and math.isfinite(qvel[i, j])):
                st_code = NONFINITE
        if not (math.isfinite(qpos[i, 0]) and math.isfinite(qpos[i, 1]) and math.isfinite(qpos[i, 2])):
            st_code = NONFINITE
        if st_code == OK:
            if math.sqrt(nu1r[0] ** 2 + nu1r[1] ** 2 + nu1r[2] ** 2) > limits[LIM_SPEED]:
                st_code = SPEED_RUNAWAY
            elif abs(phi) > limits[LIM_ANGLE] or abs(theta) > limits[LIM_ANGLE]:
                st_code = ATTITUDE_RUNAWAY
            elif abs(om[0]) > limits[LIM_RATE] or abs(om[1]) > limits[LIM_RATE] or abs(om[2]) > limits[LIM_RATE]:
                st_code = RATE_RUNAWAY
        status[i] = st_code
        # --- truth record row (state before this step's integration)
        if krec >= 0:
            row = rec[krec, i]
            row[0] = t
            for j in range(3):
                row[1 + j] = qpos[i, j]
            for j in range(4):
                row[4 + j] = qpos[i, 3 + j]
            row[8] = phi
            row[9] = theta
            row[10] = psi_u
            for j in range(3):
                row[11 + j] = nu1[j]
                row[14 + j] = om[j]
                row[17 + j] = nu1r[j]
            for j in range(6):
                row[20 + j] = acc[j]
            row[26] = vcn
            row[27] = vce
            row[28] = nav[i, NV_DN]
            row[29] = nav[i, NV_DE]
            for j in range(4):
                row[30 + j] = c[L.WIND + j]
            o = 34
            for k in range(nr):
                row[o + k] = c[L.DELTA + k]
                row[o + nr + k] = rud_cmd[i, k]
            o += 2 * nr
            for k in range(ns):
                kp = int(shaftp[k, PR.S_PROP])
                row[o + k] = c[L.SHAFT_N + kp]
                row[o + ns + k] = shaft_cmd[i, k]
                row[o + 2 * ns + k] = c[L.Q_ENGINE + k]
                row[o + 3 * ns + k] = c[L.PITCH + kp]
                row[o + 4 * ns + k] = pitch_cmd[i, k]
            o += 5 * ns
            for k in range(ns):
                b = L.AUX_PROP + 8 * k
                row[o + 3 * k] = a[b + L.P_THRUST]
                row[o + 3 * k + 1] = a[b + L.P_TORQUE]
                row[o + 3 * k + 2] = a[b + L.P_J]
            o += 3 * ns
            for k in range(nr):
                row[o + k] = a[L.AUX_RUD + 8 * k + L.R_FN]
            o += nr
            for ci in range(C + 1):
                for j in range(6):
                    row[o + 6 * ci + j] = comp_w[i, ci, j]
        # water-relative drift: Σ dt V_C (the water track is position minus this)
        nav[i, NV_DN] += dt * vcn
        nav[i, NV_DE] += dt * vce
        if st_code != OK:
            nbad += 1
    return nbad


def _run_steps(nstep, every, step_count, krow, hook_id, wcount,
               dt, qpos, qvel, time, qfrc,
               comp_kind, comp_off, comp_par, comp_soff, comp_st, minv, mrb, ma, coriolis_mode, rb, steer, shaftp, env,
               rud_cmd, shaft_cmd, pitch_cmd, shaft_mode, mach, nav, phases, hs, events, ecount,
               ctx, aux, comp_w, nudot, limits, status, rec, scratch):
    """Up to ``nstep`` whole time steps in one call: the step kernel, then MuJoCo's step of the batch
    (through the simulator's hook, in object mode), then MuJoCo's warning counters ``wcount``.

    The same work and order as one kernel call and one ``Batch.step`` per step from Python, without
    the per-step cost of handing ~40 arrays to the kernel. A truth row is written (into ``rec``, from
    row ``krow`` on) at every step whose count ``step_count + k`` is a multiple of ``every`` (never
    when ``every`` is 0; the caller leaves room). Returns (steps completed, next row, code): code 0
    all done, STOP_STATUS a ship's status is not OK (that step's row written, MuJoCo not stepped),
    STOP_MUJOCO the batch raised (the hook keeps the exception), STOP_WARNING a warning counter rose.
    """
    done = 0
    for k in range(nstep):
        krec = -1
        if every > 0 and (step_count + k) % every == 0:
            krec = krow
            krow += 1
        nbad = _step_kernel(dt, qpos, qvel, time, qfrc,
                            comp_kind, comp_off, comp_par, comp_soff, comp_st, minv, mrb, ma, coriolis_mode, rb, steer,
                            shaftp, env, rud_cmd, shaft_cmd, pitch_cmd, shaft_mode, mach, nav, phases, hs, events,
                            ecount, ctx, aux, comp_w, nudot, limits, status, rec, krec, scratch)
        if nbad:
            return done, krow, STOP_STATUS
        if _hook_step(hook_id) != 0:
            return done, krow, STOP_MUJOCO
        for i in range(wcount.shape[0]):
            for j in range(wcount.shape[1]):
                if wcount[i, j] != 0:
                    return done, krow, STOP_WARNING
        done += 1
    return done, krow, 0


STOP_STATUS, STOP_MUJOCO, STOP_WARNING = 1, 2, 3

# simulators that step through _run_steps, by hook id (weak: a simulator's entry goes with it)
_HOOKS: dict = {}


@nb.njit(cache=True)
def _hook_step(hook_id):
    """:func:`_batch_step` from compiled code (object mode; in a function of its own, the switch to
    object mode costs about half of what it does inside the loop)."""
    with nb.objmode(code="int64"):
        code = _batch_step(hook_id)
    return code


def _batch_step(hook_id: int) -> int:
    """One ``Batch.step`` of the simulator registered under ``hook_id`` (called from _run_steps in
    object mode); 0, or 1 when the batch raised (the exception is kept on the simulator)."""
    sim = _HOOKS[hook_id]()
    try:
        # Batch.step() for all simulations, one substep, no extra stage, without the wrapper's
        # argument handling (~0.7 µs a call, a tenth of a one-ship step); a failure goes through the
        # wrapper's own check, which raises its SimulationError
        nfail = sim.batch._b.step(None, 1, 0)
        if nfail:
            sim.batch._check(None, nfail)
    except BaseException as exc:  # handed back to the simulator, which raises it after the call
        sim._hook_error = exc
        return 1
    return 0


def _twin(f, name, globals_):
    """A copy of function f under another name, resolving its globals in ``globals_``: numba's cache
    is keyed by the function's name, so each compilation of one source gets its own name."""
    g = types.FunctionType(f.__code__, globals_, name, f.__defaults__, f.__closure__)
    g.__qualname__ = name
    g.__doc__ = f.__doc__
    return g


_KERNELS: dict[str, tuple] = {}


def step_kernels(component_types: list) -> tuple:
    """(serial, threaded) step kernels for this list of component types (``kind`` = index in it).

    The step kernel's source is :func:`_step_forces`; only the component dispatch it calls differs,
    generated by :func:`vtrials.physics.forces.registry.dispatcher`. The threaded twin spreads the
    ships over threads (``prange``); each ship's arithmetic is the same, so results are bit-identical.
    """
    dispatch, tag = registry.dispatcher(list(component_types))
    if tag not in _KERNELS:
        g = dict(_step_forces.__globals__)
        g["dispatch"] = dispatch
        serial = nb.njit(cache=True)(_twin(_step_forces, f"_step_forces_{tag}", g))
        threaded = nb.njit(cache=True, parallel=True)(_twin(_step_forces, f"_step_forces_parallel_{tag}", g))
        _KERNELS[tag] = (serial, threaded)
    return _KERNELS[tag]


_LOOPS: dict[str, tuple] = {}


def step_loops(component_types: list) -> tuple:
    """(serial, threaded) multi-step loops (:func:`_run_steps`) around :func:`step_kernels`' kernels."""
    serial, threaded = step_kernels(component_types)
    _, tag = registry.dispatcher(list(component_types))
    if tag not in _LOOPS:
        loops = []
        for kern, name in ((serial, f"_run_steps_{tag}"), (threaded, f"_run_steps_parallel_{tag}")):
            g = dict(_run_steps.__globals__)
            g["_step_kernel"] = kern
            loops.append(nb.njit(cache=True)(_twin(_run_steps, name, g)))
        _LOOPS[tag] = tuple(loops)
    return _LOOPS[tag]
