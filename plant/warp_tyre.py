"""The plant's tyre as Warp kernels over (worlds, wheel ends), for :mod:`artic.plant.warp_plant`.

The same equations as the C callback (``_tyre_c.c``) and :mod:`artic.plant.tyre`,
term by term and in the same order: PAC2002 forces and aligning moment with
combined slip, the bore (turn-slip) torque, rolling resistance, the three tread
deflection states, and the wheel-spin/tread mode fitted to the step
(:mod:`artic.plant.spinmode`). :func:`passive_kernel` is the whole passive
callback for one wheel end of one world: kinematics from MuJoCo Warp's data,
forces, the spin fit, the tread rates written to the tread actuators' controls,
and the force and torque added to ``qfrc_passive`` along the wheel's chain of
dofs (atomically: the wheel ends of one world share the chassis' dofs).

MuJoCo Warp computes in float32 (its ``float`` is Warp's ``float32``), and so
do these kernels. :func:`tyre_eval_kernel` evaluates the tyre alone, for the
tests against the C tyre.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import warp as wp

from artic.plant.tyre import TyreParams

PARAM_NAMES = tuple(f.name for f in dataclasses.fields(TyreParams)
                    if f.name not in ("path", "side"))
"""The coefficients a tyre set carries on the device, the file's keys."""

TyreSet = wp.struct(type("TyreSet", (), {
    "__annotations__": {n: wp.float32 for n in PARAM_NAMES},
    "__module__": __name__,
    "__doc__": "One tyre coefficient set on the device (:data:`PARAM_NAMES`).",
}))

PI = wp.constant(3.14159265358979323846)
EPS = wp.constant(1e-6)              # tyre.EPS
V_SIGN = wp.constant(0.05)           # tyre.V_SIGN
TWIST_STIFFNESS = wp.constant(1.33)  # tyre.TWIST_STIFFNESS
TWIST_LIMIT = wp.constant(2.5)       # tyre.TWIST_LIMIT
TWIST_MIN = wp.constant(1e-3)        # tyre.TWIST_MIN
PATCH_MIN = wp.constant(0.02)        # tyre.PATCH_MIN
TINY = wp.constant(1e-12)            # the C callback's floor of every divisor
DET_MIN = wp.constant(0.5)           # spinmode.DET_MIN


def tyre_sets(sets: list[TyreParams]) -> np.ndarray:
    """``sets`` as a structured array of :data:`TyreSet`, shape ``(len(sets),)``."""
    out = np.zeros(len(sets), dtype=TyreSet.numpy_dtype())
    for i, p in enumerate(sets):
        for n in PARAM_NAMES:
            out[i][n] = getattr(p, n)
    return out


@wp.func
def sgn1(x: float):
    """The sign with sgn(0) = 1, the book's."""
    if x >= 0.0:
        return 1.0
    return -1.0


@wp.func
def nz(x: float):
    """``x`` kept at least TINY from zero, with its sign."""
    if wp.abs(x) > TINY:
        return x
    if x < 0.0:
        return -TINY
    return TINY


@wp.func
def mf(B: float, C: float, D: float, E: float, x: float):
    """The Magic Formula ``D sin(C atan(B x - E (B x - atan(B x))))``."""
    bx = B * x
    return D * wp.sin(C * wp.atan(bx - E * (bx - wp.atan(bx))))


@wp.func
def g_of(B: float, C: float, E: float, z: float):
    """The combined-slip weighting's cosine form at ``z``."""
    bz = B * z
    return wp.cos(C * wp.atan(bz - E * (bz - wp.atan(bz))))


@wp.func
def weight(B: float, C: float, E: float, x: float, shift: float):
    """The combined-slip weight at ``x``, normalised at ``-shift``."""
    if shift == 0.0:
        return g_of(B, C, E, x)
    return g_of(B, C, E, x + shift) / nz(g_of(B, C, E, shift))


@wp.func
def cos_atan(x: float):
    """``cos(atan(x))`` without the trigonometry."""
    return 1.0 / wp.sqrt(1.0 + x * x)


@wp.func
def sin_2atan(x: float):
    """``sin(2 atan(x))`` without the trigonometry."""
    return 2.0 * x / (1.0 + x * x)


@wp.func
def fz0(p: TyreSet):
    """The scaled nominal load ``FNOMIN LFZO`` [N]."""
    return nz(p.FNOMIN * p.LFZO)


@wp.func
def sigma_alpha(p: TyreSet, Fz: float):
    """Lateral relaxation length [m] at load ``Fz`` [N]."""
    return nz(p.PTY1 * sin_2atan(Fz / nz(p.PTY2 * fz0(p))) * p.UNLOADED_RADIUS * p.LFZO
              * p.LSGAL)


@wp.func
def sigma_kappa(p: TyreSet, Fz: float):
    """Longitudinal relaxation length [m] at load ``Fz`` [N]."""
    Fz0 = fz0(p)
    dfz = (Fz - Fz0) / Fz0
    e = 1.0
    if p.PTX3 != 0.0:
        e = wp.exp(-p.PTX3 * dfz)
    return nz(Fz * (p.PTX1 + p.PTX2 * dfz) * e * p.UNLOADED_RADIUS / Fz0 * p.LSGKP)


@wp.func
def cornering_stiffness(p: TyreSet, Fz: float):
    """Cornering stiffness [N/rad] at load ``Fz`` [N]."""
    Fz0 = fz0(p)
    return wp.abs(p.PKY1 * Fz0 * sin_2atan(Fz / nz(p.PKY2 * Fz0)) * p.LKY)


@wp.func
def patch_half_length(p: TyreSet, Fz: float):
    """Contact patch half-length [m] at load ``Fz`` [N]."""
    return wp.max(wp.sqrt(p.UNLOADED_RADIUS * wp.max(Fz, 0.0) / nz(p.VERTICAL_STIFFNESS)),
                  PATCH_MIN)


@wp.func
def steady_state(p: TyreSet, Fz_in: float, kappa: float, alpha: float, v_sign: float,
                 moments: int):
    """PAC2002 at zero camber: ``(Fx, Fy, Mz)`` (tyre.steady_state)."""
    Fz = wp.max(Fz_in, 0.0)
    a = -alpha
    k = kappa
    ta = wp.tan(a)
    ca = wp.cos(a)
    Fz0 = fz0(p)
    dfz = (Fz - Fz0) / Fz0
    # longitudinal, pure slip
    SHx = (p.PHX1 + p.PHX2 * dfz) * p.LHX
    kx = k + SHx
    Cx = p.PCX1 * p.LCX
    Dx = (p.PDX1 + p.PDX2 * dfz) * p.LMUX * Fz
    Ex = wp.min((p.PEX1 + p.PEX2 * dfz + p.PEX3 * dfz * dfz) * (1.0 - p.PEX4 * sgn1(kx))
                * p.LEX, 1.0)
    ekx = 1.0
    if p.PKX3 != 0.0:
        ekx = wp.exp(p.PKX3 * dfz)
    Kx = Fz * (p.PKX1 + p.PKX2 * dfz) * ekx * p.LKX
    CDx = Cx * Dx
    if CDx == 0.0:
        CDx = 1.0
    Bx = Kx / CDx
    SVx = Fz * (p.PVX1 + p.PVX2 * dfz) * p.LVX * p.LMUX
    Fx0 = mf(Bx, Cx, Dx, Ex, kx) + SVx
    # lateral, pure slip, at alpha* = tan(alpha)
    SHy = (p.PHY1 + p.PHY2 * dfz) * p.LHY
    ay = ta + SHy
    Cy = p.PCY1 * p.LCY
    muy = (p.PDY1 + p.PDY2 * dfz) * p.LMUY
    Dy = muy * Fz
    Ey = wp.min((p.PEY1 + p.PEY2 * dfz) * (1.0 - p.PEY3 * sgn1(ay)) * p.LEY, 1.0)
    Ky = p.PKY1 * Fz0 * sin_2atan(Fz / nz(p.PKY2 * Fz0)) * p.LKY
    CDy = Cy * Dy
    if CDy == 0.0:
        CDy = 1.0
    By = Ky / CDy
    SVy = Fz * (p.PVY1 + p.PVY2 * dfz) * p.LVY * p.LMUY
    Fy0 = mf(By, Cy, Dy, Ey, ay) + SVy
    # combined slip
    Bxa = p.RBX1 * cos_atan(p.RBX2 * k) * p.LXAL
    Gxa = weight(Bxa, p.RCX1, p.REX1 + p.REX2 * dfz, ta, p.RHX1)
    Byk = p.RBY1 * cos_atan(p.RBY2 * (ta - p.RBY3)) * p.LYKA
    Gyk = weight(Byk, p.RCY1, p.REY1 + p.REY2 * dfz, k, p.RHY1 + p.RHY2 * dfz)
    DVyk = muy * Fz * (p.RVY1 + p.RVY2 * dfz) * cos_atan(p.RVY4 * ta)
    SVyk = 0.0
    if DVyk != 0.0:
        SVyk = DVyk * wp.sin(p.RVY5 * wp.atan(p.RVY6 * k)) * p.LVYKA
    Fx = Gxa * Fx0
    Fy = Gyk * Fy0 + SVyk
    Mz = 0.0
    if moments != 0:
        sKy = 1.0
        if Ky < 0.0:
            sKy = -1.0
        Kyp = Ky + EPS * sKy
        SHt = p.QHZ1 + p.QHZ2 * dfz
        SHf = SHy + SVy / Kyp
        a_t = ta + SHt
        a_r = ta + SHf
        kk = (Kx / Kyp) * (Kx / Kyp) * k * k
        at_eq = wp.sqrt(a_t * a_t + kk) * sgn1(a_t)
        ar_eq = wp.sqrt(a_r * a_r + kk) * sgn1(a_r)
        lmuy = nz(p.LMUY)
        Bt = (p.QBZ1 + p.QBZ2 * dfz + p.QBZ3 * dfz * dfz) * p.LKY / lmuy
        Ct = p.QCZ1
        Dt = Fz * (p.UNLOADED_RADIUS / Fz0) * (p.QDZ1 + p.QDZ2 * dfz) * p.LTR * v_sign
        Et = wp.min((p.QEZ1 + p.QEZ2 * dfz + p.QEZ3 * dfz * dfz)
                    * (1.0 + p.QEZ4 * (2.0 / PI) * wp.atan(Bt * Ct * a_t)), 1.0)
        bt = Bt * at_eq
        trail = Dt * wp.cos(Ct * wp.atan(bt - Et * (bt - wp.atan(bt)))) * ca
        Br = p.QBZ9 * p.LKY / lmuy + p.QBZ10 * By * Cy
        Dr = (Fz * p.UNLOADED_RADIUS * (p.QDZ6 + p.QDZ7 * dfz) * p.LRES * p.LMUY * v_sign
              * ca)
        Mzr = Dr * cos_atan(Br * ar_eq)
        s_arm = p.UNLOADED_RADIUS * (p.SSZ1 + p.SSZ2 * (Fy / Fz0)) * p.LS
        Mz = -trail * (Gyk * Fy0) + Mzr + s_arm * Fx
    return Fx, Fy, Mz


@wp.func
def twist_scale(p: TyreSet, Fzc: float, a: float):
    """The twist's scale [rad] at load ``Fzc`` [N] and half-length ``a`` [m]."""
    Fz0 = fz0(p)
    dfz = (Fzc - Fz0) / Fz0
    mu = (p.PDY1 + p.PDY2 * dfz) * p.LMUY
    return wp.max((2.0 / 3.0) * mu * a / TWIST_STIFFNESS, TWIST_MIN)


@wp.func
def bore_max(p: TyreSet, Fz_in: float):
    """The bore torque's friction limit [N m] at load ``Fz_in`` [N]."""
    Fz = wp.max(Fz_in, 0.0)
    Fz0 = fz0(p)
    dfz = (Fz - Fz0) / Fz0
    mu = wp.max((p.PDY1 + p.PDY2 * dfz) * p.LMUY, 0.0)
    return (2.0 / 3.0) * mu * Fz * patch_half_length(p, Fz)


@wp.func
def wheel_rates(p: TyreSet, Fz: float, Vx: float, Vsx: float, Vy: float, omega_z: float,
                u: float, v: float, phi: float):
    """Tread deflection rates ``(du, dv, dphi)`` and the slips ``(kappa, alpha)``."""
    Fzc = wp.max(Fz, p.FZMIN)
    sk = sigma_kappa(p, Fzc)
    sa = sigma_alpha(p, Fzc)
    ax = wp.abs(Vx)
    a = patch_half_length(p, Fzc)
    phi_s = twist_scale(p, Fzc, a)
    du = -Vsx - ax * u / sk
    dv = -Vy - ax * v / sa
    dphi = -omega_z - wp.abs(omega_z) * phi / (TWIST_LIMIT * phi_s) - ax * phi / a
    return du, dv, dphi, u / sk, wp.atan(v / sa)


@wp.func
def wheel_forces(p: TyreSet, Fz: float, Vx: float, Vsx: float, Vy: float, u: float, v: float,
                 phi: float, dphi: float, moments: int):
    """Transient ``(Fx, Fy, Mz, My)`` and the tread's ``(k_x, c_x, b_x)`` (the C ``wheel``)."""
    Fzc = wp.max(Fz, p.FZMIN)
    sk = sigma_kappa(p, Fzc)
    sa = sigma_alpha(p, Fzc)
    ax = wp.abs(Vx)
    kappa = u / sk
    alpha = wp.atan(v / sa)
    a = patch_half_length(p, Fzc)
    phi_s = twist_scale(p, Fzc, a)
    v_sign = wp.tanh(Vx / V_SIGN)
    Fx, Fy, Mz = steady_state(p, Fz, kappa, alpha, v_sign, moments)
    vxlow = TINY
    if p.VXLOW > 0.0:
        vxlow = p.VXLOW
    fade = 0.0
    if ax < vxlow:
        fade = 0.5 * (1.0 + wp.cos(PI * ax / vxlow))
    Fzp = wp.max(Fz, 0.0)
    Kx = Fzp * p.PKX1 * p.LKX
    Ky = cornering_stiffness(p, Fzp)
    Fx = Fx - fade * p.PTX4 * Kx / sk * Vsx * 0.25
    Fy = Fy - fade * p.PTX4 * Ky / sa * Vy * 0.25
    k_x = Kx / sk
    c_x = fade * p.PTX4 * Kx / sk * 0.25
    b_x = ax / sk
    if moments != 0:
        th = wp.tanh(phi / phi_s)
        elastic = (1.0 - th * th) * dphi
        Mz = Mz + bore_max(p, Fz) * th + fade * p.PTX4 * TWIST_STIFFNESS * Fzp * elastic * 0.25
    else:
        Mz = 0.0
    vr = ax / nz(p.LONGVL)
    mag = (p.UNLOADED_RADIUS * Fzp
           * (p.QSY1 + p.QSY2 * Fx / fz0(p) + p.QSY3 * vr + p.QSY4 * (vr * vr) * (vr * vr))
           * p.LMY)
    My = -mag * v_sign
    return Fx, Fy, Mz, My, k_x, c_x, b_x


@wp.func
def out_of_range(p: TyreSet, Fz: float, kappa: float, alpha: float):
    """1 for a loaded wheel outside the file's ranges of Fz, kappa and alpha."""
    if Fz > 0.0 and (Fz < p.FZMIN or Fz > p.FZMAX or kappa < p.KPUMIN or kappa > p.KPUMAX
                     or alpha < p.ALPMIN or alpha > p.ALPMAX):
        return 1
    return 0


@wp.struct
class SpinMode:
    """One wheel end's spin/tread mode (:class:`artic.plant.spinmode.Mode`), units as there."""

    inv_inertia: float
    q_x: float
    n: float
    Re: float
    k: float
    c: float
    b: float


@wp.func
def spin_fit(h: float, scale: float, mode: SpinMode, f_spin: float, f_u: float):
    """spinmode.fit, term by term: ``(dFx, ddu)``."""
    if not (scale > 0.0 and h > 0.0):
        return 0.0, 0.0
    g = mode.q_x * mode.n * mode.inv_inertia
    s = h / scale
    p0 = s * g * mode.c * mode.Re
    p1 = s * g * mode.k
    p2 = s * mode.Re
    p3 = -s * mode.b
    w0 = s * f_spin
    w1 = s * f_u
    for _i in range(3):
        t0 = p0 * w0 + p1 * w1
        t1 = p2 * w0 + p3 * w1
        w0 = t0
        w1 = t1
    q0 = p0 * p0 + p1 * p2
    q1 = p0 * p1 + p1 * p3
    q2 = p2 * p0 + p3 * p2
    q3 = p2 * p1 + p3 * p3
    n0 = 1.0 + q0 * q0 + q1 * q2
    n1 = q0 * q1 + q1 * q3
    n2 = q2 * q0 + q3 * q2
    n3 = 1.0 + q2 * q1 + q3 * q3
    det = n0 * n3 - n1 * n2
    if not (det > DET_MIN):
        return 0.0, 0.0
    y0 = -(n3 * w0 - n1 * w1) / det
    y1 = -(-n2 * w0 + n0 * w1) / det
    return mode.c * mode.Re * y0 + mode.k * y1, mode.Re * y0 - mode.b * y1


@wp.kernel
def tyre_eval_kernel(tyre: wp.array(dtype=TyreSet), moments: int,
                     state: wp.array2d(dtype=float),
                     out: wp.array2d(dtype=float)):
    """The tyre alone, as the C ``artic_tyre_eval``.

    One state per row ``(Fz, Vx, Vsx, Vy, omega_z, u, v, phi)`` to
    ``(Fx, Fy, Mz, My, du, dv, dphi)``.
    """
    i = wp.tid()
    p = tyre[0]
    Fz = state[i, 0]
    Vx = state[i, 1]
    Vsx = state[i, 2]
    Vy = state[i, 3]
    om = state[i, 4]
    u = state[i, 5]
    v = state[i, 6]
    phi = state[i, 7]
    du, dv, dphi, _kappa, _alpha = wheel_rates(p, Fz, Vx, Vsx, Vy, om, u, v, phi)
    Fx, Fy, Mz, My, _k, _c, _b = wheel_forces(p, Fz, Vx, Vsx, Vy, u, v, phi, dphi, moments)
    out[i, 0] = Fx
    out[i, 1] = Fy
    out[i, 2] = Mz
    out[i, 3] = My
    out[i, 4] = du
    out[i, 5] = dv
    out[i, 6] = dphi


@wp.func
def cdof_dot(cdof: wp.spatial_vector, tc: wp.vec3, F: wp.vec3):
    """The generalized force on a dof of axis ``cdof`` of torque ``tc`` and force ``F``."""
    return wp.dot(wp.spatial_top(cdof), tc) + wp.dot(wp.spatial_bottom(cdof), F)


@wp.struct
class Tree:
    """The model's kinematic tree: MuJoCo Warp's model fields of the same names."""

    body_parentid: wp.array(dtype=int)
    body_rootid: wp.array(dtype=int)
    body_dofnum: wp.array(dtype=int)
    body_dofadr: wp.array(dtype=int)
    dof_parentid: wp.array(dtype=int)


@wp.struct
class SpinModel:
    """What the spin fit reads of the model: MuJoCo Warp's model fields of the same names.

    The step, the spin dofs' inverse inertias and friction, the drive and brake
    motors' gains, ranges and gears, and ``clamp_ctrl`` (1 where MuJoCo clamps
    the controls to their ranges).
    """

    timestep: wp.array(dtype=float)
    dof_invweight0: wp.array2d(dtype=float)
    dof_frictionloss: wp.array2d(dtype=float)
    actuator_gainprm: wp.array2d(dtype=wp.types.vector(10, wp.float32))
    actuator_ctrlrange: wp.array2d(dtype=wp.vec2)
    actuator_forcerange: wp.array2d(dtype=wp.vec2)
    actuator_gear: wp.array2d(dtype=wp.spatial_vector)
    actuator_ctrllimited: wp.array(dtype=bool)
    actuator_forcelimited: wp.array(dtype=bool)
    clamp_ctrl: int


@wp.struct
class Motion:
    """What the tyre reads of the data: MuJoCo Warp's data fields of the same names.

    The hubs' frames, the bodies' velocities and the dofs' axes, the spins, the
    tread states (activations) and the applied forces.
    """

    site_xpos: wp.array2d(dtype=wp.vec3)
    site_xmat: wp.array2d(dtype=wp.mat33)
    cvel: wp.array2d(dtype=wp.spatial_vector)
    subtree_com: wp.array2d(dtype=wp.vec3)
    cdof: wp.array2d(dtype=wp.spatial_vector)
    qvel: wp.array2d(dtype=float)
    act: wp.array2d(dtype=float)
    qfrc_applied: wp.array2d(dtype=float)


@wp.struct
class Wheels:
    """The plant's wheel ends and tyres on the device.

    ``table``: per wheel end the hub site, hub body, root body, wheel body, spin
    dof, the three tread activations, the three tread actuators and the tyre set;
    ``spin_act``: the drive and brake motors on its spin (-1: none); ``n_tyres``:
    its tyres; ``tyres``: per world, the tyre sets; ``moments``: 1 for the aligning
    and bore moments; ``fit_scale``: the spin fit's ``z_0`` (0: no fit).
    """

    table: wp.array2d(dtype=int)
    spin_act: wp.array2d(dtype=int)
    n_tyres: wp.array(dtype=float)
    tyres: wp.array2d(dtype=TyreSet)
    moments: int
    fit_scale: float


def gather(kind, source=None, **values):
    """A ``kind`` struct: each field from ``values``, or else ``source``'s of its name.

    ``kind`` is a Warp struct (:class:`Tree`...); ``source`` a MuJoCo Warp model or data.
    """
    out = kind()
    for name in kind.vars:
        setattr(out, name, values[name] if name in values else getattr(source, name))
    return out


@wp.kernel
def passive_kernel(tree: Tree, model: SpinModel, motion: Motion, wheels: Wheels,
                   ctrl: wp.array2d(dtype=float), qfrc_passive: wp.array2d(dtype=float),
                   forces: wp.array2d(dtype=wp.vec3), outside: wp.array(dtype=int)):
    """The tyre of wheel end ``i`` of world ``w``: the C ``artic_passive``'s loop body."""
    w, i = wp.tid()
    hub = wheels.table[i, 0]
    hub_body = wheels.table[i, 1]
    root = wheels.table[i, 2]
    wheel_body = wheels.table[i, 3]
    spin = wheels.table[i, 4]
    n = wheels.n_tyres[i]
    p = wheels.tyres[w, wheels.table[i, 11]]
    R0 = p.UNLOADED_RADIUS
    pos = motion.site_xpos[w, hub]
    R = motion.site_xmat[w, hub]
    hx = wp.vec3(R[0, 0], R[1, 0], 0.0)
    norm = wp.sqrt(hx[0] * hx[0] + hx[1] * hx[1])
    if norm < 1e-9:  # hub axis vertical: no heading, no tyre force
        forces[w, i] = wp.vec3(0.0, 0.0, 0.0)
        ctrl[w, wheels.table[i, 8]] = 0.0
        ctrl[w, wheels.table[i, 9]] = 0.0
        ctrl[w, wheels.table[i, 10]] = 0.0
        return
    hx = hx / norm
    hy = wp.vec3(-hx[1], hx[0], 0.0)
    cv = motion.cvel[w, hub_body]
    om = wp.spatial_top(cv)
    r = pos - motion.subtree_com[w, root]
    vel = wp.spatial_bottom(cv) + wp.cross(om, r)
    rho = R0 - pos[2]
    Fz = 0.0
    if rho > 0.0:
        Fz = p.VERTICAL_STIFFNESS * rho - p.VERTICAL_DAMPING * vel[2]
    Fz = wp.max(Fz, 0.0)
    Vx = wp.dot(vel, hx)
    Vy = wp.dot(vel, hy)
    Re = R0 - wp.max(rho, 0.0) / 3.0
    Vsx = Vx - motion.qvel[w, spin] * Re
    u = motion.act[w, wheels.table[i, 5]]
    v = motion.act[w, wheels.table[i, 6]]
    phi = motion.act[w, wheels.table[i, 7]]
    du, dv, dphi, kappa, alpha = wheel_rates(p, Fz, Vx, Vsx, Vy, om[2], u, v, phi)
    Fx, Fy, Mz, My, k_x, c_x, b_x = wheel_forces(p, Fz, Vx, Vsx, Vy, u, v, phi, dphi,
                                                 wheels.moments)
    point = wp.vec3(pos[0], pos[1], 0.0)
    F = (n * Fx) * hx + (n * Fy) * hy + wp.vec3(0.0, 0.0, n * Fz)
    T = (n * My) * hy + wp.vec3(0.0, 0.0, n * Mz)
    # the torque about the root's subtree centre of mass (cdof's reference point)
    com = motion.subtree_com[w, tree.body_rootid[wheel_body]]
    lever = point - com
    frictionloss = model.dof_frictionloss[w % model.dof_frictionloss.shape[0], spin]
    if wheels.fit_scale > 0.0 and frictionloss == 0.0:
        q_x = cdof_dot(motion.cdof[w, spin], wp.cross(lever, hx), hx)
        Q = cdof_dot(motion.cdof[w, spin], T + wp.cross(lever, F), F)
        # the drive and brake on the spin joint, as mj_fwdActuation will compute them
        q_act = 0.0
        for j in range(2):
            a = wheels.spin_act[i, j]
            if a >= 0:
                x = ctrl[w, a]
                if model.actuator_ctrllimited[a] and model.clamp_ctrl != 0:
                    cr = model.actuator_ctrlrange[w % model.actuator_ctrlrange.shape[0], a]
                    x = wp.min(wp.max(x, cr[0]), cr[1])
                f = model.actuator_gainprm[w % model.actuator_gainprm.shape[0], a][0] * x
                if model.actuator_forcelimited[a]:
                    fr = model.actuator_forcerange[w % model.actuator_forcerange.shape[0], a]
                    f = wp.min(wp.max(f, fr[0]), fr[1])
                q_act += model.actuator_gear[w % model.actuator_gear.shape[0], a][0] * f
        inv_I = model.dof_invweight0[w % model.dof_invweight0.shape[0], spin]
        f_spin = (Q + q_act + qfrc_passive[w, spin] + motion.qfrc_applied[w, spin]) * inv_I
        h = model.timestep[w % model.timestep.shape[0]]
        mode = SpinMode()
        mode.inv_inertia = inv_I
        mode.q_x = q_x
        mode.n = n
        mode.Re = Re
        mode.k = k_x
        mode.c = c_x
        mode.b = b_x
        dFx, ddu = spin_fit(h, wheels.fit_scale, mode, f_spin, du)
        du = du + ddu
        F = F + (n * dFx) * hx
    ctrl[w, wheels.table[i, 8]] = du
    ctrl[w, wheels.table[i, 9]] = dv
    ctrl[w, wheels.table[i, 10]] = dphi
    forces[w, i] = F
    if out_of_range(p, Fz, kappa, alpha) != 0:
        wp.atomic_add(outside, w, 1)
    # qfrc_passive += J' [F; T] along the wheel body's chain of dofs
    body = wheel_body
    while body > 0 and tree.body_dofnum[body] == 0:
        body = tree.body_parentid[body]
    if body <= 0:
        return
    tc = T + wp.cross(lever, F)
    j = tree.body_dofadr[body] + tree.body_dofnum[body] - 1
    while j >= 0:
        wp.atomic_add(qfrc_passive, w, j, cdof_dot(motion.cdof[w, j], tc, F))
        j = tree.dof_parentid[j]
