"""Index layout of the per-ship context and auxiliary arrays that force components share.

Every force component is a numba kernel ``kernel(p, s, env, ctx, aux, w)`` (see
:mod:`vtrials.physics.forces.registry`):

* ``p``   – the component's own parameter block (float64, packed by its ``pack`` function),
* ``s``   – the component's own internal states (advanced by the kernel over one step ``ctx[DT]``),
* ``env`` – the ship's environment block (current, later wind and waves), see :mod:`vtrials.physics.environment.current`,
* ``ctx`` – the kinematic context below (read only),
* ``aux`` – per-propeller / per-rudder outputs, written by propellers and read by rudders,
* ``w``   – the component's wrench, body frame at the origin (midship, waterline):
  X, Y, Z [N] and K, M, N [N m], axes x forward, y starboard, z down.

Indices are plain module constants so numba folds them at compile time.
"""

# --- context (per ship) --------------------------------------------------------------------
NU_R = 0  # 0..5: u_r, v_r, w_r, p, q, r — velocity relative to the water at the origin, body axes
NU = 6  # 6..11: u, v, w, p, q, r — velocity over ground, body axes
POS = 12  # 12..14: x north, y east, z down [m] of the origin
EUL = 15  # 15..17: roll φ, pitch θ, yaw ψ [rad] (z-y-x convention)
TIME = 18  # simulated time [s]
DEPTH = 19  # water depth [m]
ROT = 20  # 20..28: rotation matrix body→world, row major
CUR = 29  # 29..30: current velocity north, east at the origin [m/s]
CUR_ACC = 31  # 31..32: material acceleration of the current, north, east [m/s²]
WIND = 33  # 33..39: reserved for wind (relative speed, direction, ...)
DELTA = 40  # 40..43: rudder angles [rad], positive turns the ship to starboard
DELTA_DOT = 44  # 44..47: rudder rates [rad/s]
SHAFT_N = 48  # 48..51: shaft speeds [rev/s], positive = ahead rotation
PITCH = 52  # 52..55: propeller pitch ratio P/D (controllable pitch), as set
Q_ENGINE = 56  # 56..59: engine torque delivered to each shaft [N m]
DT = 60  # the time step [s] over which components advance their states
NCTX = 64

MAX_SHAFTS = 4
MAX_RUDDERS = 4

# --- auxiliary outputs (per ship) -----------------------------------------------------------
AUX_PROP = 0  # propeller k occupies AUX_PROP + 8k .. +7
P_THRUST, P_TORQUE, P_J, P_KT, P_KQ, P_UA, P_WAKE, P_N = range(8)
AUX_RUD = 32  # rudder k occupies AUX_RUD + 8k .. +7
R_FN, R_UR, R_VR, R_ALPHA, R_UR2 = range(5)
AUX_FLOW = 64  # 64..66: the waves' cross-flow v_w [m/s], its gradient r_w [1/s], surface heel φ_w [rad]
#               (written by wave_flow, subtracted by the maneuvering components; zero without waves)
NAUX = 72
