"""The independent truth: a vehicle with its own skeleton, tyres, steering and loop.

:class:`YardTruth` is the measured vehicle of the synthetic campaign's
``independent`` truth. It shares no code with the plant under validation
(``artic.plant``, ``artic.mjcf.builder`` and its helpers): from the truth's
vehicle file it takes only the data, and MuJoCo only as the integrator of
its own model (``tests/test_yard_truth.py`` reads the import graph):

==================  ================================  ===============================
                    the plant (``artic.plant``)        the truth (this)
==================  ================================  ===============================
model               ``artic.mjcf.builder``            :mod:`.yardbuild`: frame torsion,
                                                      cab on mounts, fifth wheel with
                                                      roll lash and compliance, roll
                                                      steer on every axle
tyres               PAC2002 from the ``.tir`` file    TMeasy from a published truck-tyre
                                                      set (:mod:`.yardtyres`), twins as
                                                      two tyres
steering            position servo, fitted quartic    torsion bar with play, lagged
                                                      assist, tie rod on its own
                                                      Ackermann trapezoid, caster
speed               velocity servo on the drive       its own follower (the floor) or
                    axle                              pedals: drive torque on the
                                                      driven wheels, dry-friction
                                                      brakes on all
loop                RK4 with a global MuJoCo          its own: ``mj_step1``, its forces
                    passive callback                  into ``qfrc_applied`` in C,
                                                      ``mj_step2`` (no callback)
==================  ================================  ===============================

The steering's input is the left-wheel angle the steering wheel stands for
(``step``'s ``delta``); :class:`YardSeat` is the driver's seat that turns a
steering-wheel angle into it with the truth's own gear (linear, the truth
file's ``[steering.mbd]`` ratio and offset) and works the pedals.
"""

from __future__ import annotations

import ctypes
import dataclasses
import functools
import math
from collections.abc import Callable, Mapping

import mujoco
import numpy as np

from artic.mjcf import extensions
from artic.mjcf.interface import InitialState, wrap_angle
from artic.mjcf.vehicle import Vehicle
from artic.validation.synthetic import yardbuild, yardtyres

TIMESTEP = yardbuild.TIMESTEP

DRIVE_FORCE_MAX = 0.16
"""Full throttle's tractive force over the combination's weight [-]."""

BRAKE_DECEL_MAX = 0.55
"""Full brake's deceleration [g]."""

PARKING_GRADE = 0.2
"""The grade the parking brake holds [-]."""

FOLLOW_TAU = 0.1
"""The floor's speed follower: the time constant of its critically damped
proportional and integral answer to the speed error [s]. Its force is held to
what the drive (:data:`DRIVE_FORCE_MAX`) and the brakes (:data:`BRAKE_DECEL_MAX`)
give, as the truth's driver's pedals are."""

TORSION_BAR = math.degrees(1.8)
"""The column's torsion bar [N m/rad at the steering wheel]: 1.8 N m/deg."""

BOOST = 7.0
"""Assist over the driver's torque in its linear range [-]."""

ASSIST_MAX = 9000.0
"""The assist's relief torque at the knuckle [N m]."""

ASSIST_TAU = 0.06
"""The assist's lag [s]."""

KINGPIN_DAMPING = 2500.0
"""Viscous friction of each kingpin [N m s/rad]."""

TIE_ROD = (4.0e5, 400.0)
"""The tie rod's stiffness [N m/rad] and damping [N m s/rad] seen at the knuckle."""

CASTER = math.radians(3.5)
"""Caster of the steered axle [rad]: the kingpin leads the contact by ``r0 tan``."""

FOLLOW_TRACTION = 0.4
"""The floor's follower drives with at most this share of the driven axles' static
load [-]: below the tyres' sliding force (0.42-0.46 of the load in the pattern at
the yard's friction), so that it cannot spin the driven wheels up without end when
a log's speed asks for more than the truck can (as a driver backs off a spinning
wheel). With the unladen semitrailer it is about 0.9 m/s^2; a yard asks for 0.5."""

SETTLE_TIME = 1.5
"""How long a new truth settles on its tyres before its first reset [s]."""


TRUTH_ABI = 1
"""The ABI of ``_truth_c.c`` (its ``TRUTH_ABI``; :data:`artic.validation.synthetic.truthc.ABI`,
which imports the plant, as this module must not)."""


_SITE = mujoco.mjtObj.mjOBJ_SITE


class YardUnavailable(RuntimeError):
    """The compiled truth cannot be used; the message says why."""


@functools.cache
def _library() -> tuple[ctypes.CDLL | None, str]:
    lib, why = extensions.load("artic.validation.synthetic._truth_c", "artic_truth", TRUTH_ABI,
                               "the yard truth's compiled loop",
                               "reinstall artic with a C compiler, or generate with --truth "
                               "structural")
    if lib is None:
        return None, why
    if not hasattr(lib, "artic_yard_advance"):
        return None, "the compiled truth has no yard truth; reinstall artic"
    dp = ctypes.POINTER(ctypes.c_double)
    lib.artic_yard_advance.restype = ctypes.c_int
    lib.artic_yard_advance.argtypes = [ctypes.c_void_p, ctypes.c_void_p, dp, dp, dp, dp,
                                       ctypes.c_int, dp]
    lib.artic_yard_kinematics.restype = None
    lib.artic_yard_kinematics.argtypes = [ctypes.c_void_p, ctypes.c_void_p]
    for name in ("artic_yard_end_names", "artic_truth_tyre_names", "artic_truth_column_names"):
        getattr(lib, name).restype = ctypes.c_char_p
    return lib, ""


def library() -> ctypes.CDLL:
    """The compiled loop; raises :class:`YardUnavailable` without it."""
    lib, why = _library()
    if lib is None:
        raise YardUnavailable(why)
    return lib


def _names(fn: str) -> tuple[str, ...]:
    return tuple(getattr(library(), fn)().decode().rstrip(",").split(","))


@dataclasses.dataclass(frozen=True)
class YardSetup:
    """What the truth's configuration sets beyond its vehicle file.

    Parameters
    ----------
    play : float
        The column's free play at the steering wheel [rad].
    pressure, friction, cornering : float
        The tyres' inflation over the rated pressure, the yard's friction over the
        tyre pattern's, and the scale of the cornering slope [-]
        (:func:`artic.validation.synthetic.yardtyres.yard_tyre`).
    """

    play: float = 0.0
    pressure: float = 1.0
    friction: float = 1.0
    cornering: float = 1.0

    @classmethod
    def of(cls, truth: Mapping) -> YardSetup:
        """The setup of a truth configuration (:mod:`artic.validation.synthetic.truth`)."""
        t = truth.get("tyres") or {}
        return cls(play=float(truth.get("backlash", 0.0)), pressure=float(t.get("pressure", 1.0)),
                   friction=float(t.get("friction", 1.0)),
                   cornering=float(t.get("cornering", 1.0)))


class YardTruth:
    """The independent truth (module docstring), with the harness's model calls.

    Parameters
    ----------
    vehicle : Vehicle
        The truth's vehicle (its file and the yard's slope).
    setup : YardSetup, optional
        The column's play and the tyres' draws.
    speed : str
        ``"follow"``: a speed follower (the floor, under the harness);
        ``"pedals"``: :attr:`pedals` (throttle, brake) as the truth's driver works them.
    timestep : float
        MuJoCo's step [s]; a whole number of them makes each ``step``.
    """

    budget_kind = "multibody"
    """What its runs count as in the process's budget of simulated time."""

    PEDALS = (DRIVE_FORCE_MAX, BRAKE_DECEL_MAX, PARKING_GRADE)
    """What the pedals give (for the compiled loop): full throttle's force over the weight,
    full brake's deceleration [g], the grade the parking brake holds [-]."""

    name = "mbd"
    """The harness maps the steering wheel with the truth file's ``[steering.mbd]``."""

    def __init__(self, vehicle: Vehicle, setup: YardSetup | None = None, speed: str = "follow",
                 timestep: float = TIMESTEP) -> None:
        if speed not in ("follow", "pedals"):
            raise ValueError(f"speed {speed!r}: the yard truth follows or takes pedals")
        lib = library()
        self.vehicle = vehicle
        self._weight = (vehicle.m1 + vehicle.m2) * yardbuild.G
        self.setup = setup or YardSetup()
        self.speed_mode = speed
        self.tyres = {}
        radius = {}
        for a in vehicle.axles:
            t = yardtyres.yard_tyre(yardtyres.size_of(vehicle.tyre_file_for(a)), a.dual,
                                    self.setup.pressure, self.setup.friction,
                                    self.setup.cornering)
            self.tyres[a.name] = t
            radius[a.name] = t.r0
        self.model, self.layout = yardbuild.build(vehicle, radius, timestep)
        self.data = mujoco.MjData(self.model)
        if _names("artic_truth_tyre_names") != yardtyres.FIELDS:
            raise YardUnavailable("the compiled truth's tyre coefficients are not the yard "
                                  "tyre's; reinstall artic")
        self._lib = lib
        self._par, self.n_z, self._assist = self._parameters()
        self.z = np.zeros(self.n_z)
        self._zdot = np.zeros(self.n_z)
        self._out = np.zeros(3 * len(self.layout.ends) + 4)
        self._ctl = np.zeros(5)
        self.pedals = (0.0, 0.0)
        """Throttle and brake in [0, 1], with ``speed="pedals"``."""
        self.steer_limited = 0
        """Steps whose steering demand lay past the lock (the box held it there)."""
        self._parked = False
        self._decel = -1.0
        self._psi = np.zeros(2)
        self._weight = self.layout.mass * yardbuild.G
        self._spin = np.array([e["spin_dof"] for e in self.layout.ends])
        self._brake_share = np.array([e["brake_share"] for e in self.layout.ends])
        self._eps = (vehicle.sensor1_yaw, vehicle.sensor2_yaw)
        # What every step hands the compiled loop, made once: the arrays' pointers
        # (they are only ever written in place) and the mean rolling radius the
        # drive force uses (the tyres are fixed). numpy's ctypes.data_as and a
        # mean per step cost about a tenth of a step of the truth's loop.
        dp = ctypes.POINTER(ctypes.c_double)
        self._ptrs = tuple(a.ctypes.data_as(dp) for a in (self._par, self._ctl, self.z,
                                                             self._zdot, self._out))
        self._r0_mean = float(np.mean([t.r0 for t in self.tyres.values()]))
        self._vel = np.zeros(6)
        self._sensor_bodies = [(int(site), int(self.model.site_bodyid[site]))
                               for site in self.layout.sensor_sites]
        # Per step, cached: MjData's arrays as views (each attribute read makes a
        # new one), the wheel ends' radii the brakes scale, the integration
        # state's size, the lock and MuJoCo's steps a 10 ms step takes.
        self._site_xmat, self._site_xpos = self.data.site_xmat, self.data.site_xpos
        self._xmat = self.data.xmat
        self._r0_ends = np.array([self.tyres[e["axle"]].r0 for e in self.layout.ends])
        self._state_size = mujoco.mj_stateSize(self.model, mujoco.mjtState.mjSTATE_INTEGRATION)
        self._lock = float(vehicle.steering.delta_max)
        self._sub = (None, 0)
        self._settled = self._settle()

    # ------------------------------------------------------------ construction
    def _parameters(self) -> tuple[np.ndarray, int, int]:
        v, lay, m = self.vehicle, self.layout, self.model
        sets = list(self.tyres)  # one set per axle
        end_names = _names("artic_yard_end_names")
        rows, nz = [], 0
        for e in lay.ends:
            n_t = 2 if e["dual"] else 1
            t = self.tyres[e["axle"]]
            row = {"hub_site": e["hub_site"], "hub_body": e["hub_body"],
                   "wheel_body": e["wheel_body"], "spin_dof": e["spin_dof"], "n_tyres": n_t,
                   "tyre_set": sets.index(e["axle"]), "half_spacing": 0.5 * yardbuild.TWIN_SPACING,
                   "trail": t.r0 * math.tan(CASTER) if e["steered"] else 0.0,
                   "steer_dof": e.get("steer_dof", 0), "drive_share": e["drive_share"],
                   "brake_share": e["brake_share"], "z_first": nz}
            nz += 3 * n_t
            rows.append([float(row[k]) for k in end_names])
        front = next(a for a in v.tractor_axles if a.steered)
        arm = v.steering.steering_arm
        beta, rod = yardbuild.trapezoid(front.track, v.L1, arm)
        lever = arm * math.cos(beta)
        s = v.steering_for("mbd")
        column = {"i_s": s.i_s, "k_tb": TORSION_BAR, "play": self.setup.play,
                  "play_smooth": max(0.02 * self.setup.play, 1e-4), "boost": BOOST,
                  "assist_max": ASSIST_MAX, "assist_tau": ASSIST_TAU,
                  "c_kingpin": KINGPIN_DAMPING, "track": front.track, "arm": arm, "beta": beta,
                  "rod": rod, "k_rod": TIE_ROD[0] / lever ** 2, "c_rod": TIE_ROD[1] / lever ** 2,
                  "slot": 0, "steer_l_qpos": m.jnt_qposadr[lay.steer_l],
                  "steer_l_dof": m.jnt_dofadr[lay.steer_l],
                  "steer_r_qpos": m.jnt_qposadr[lay.steer_r],
                  "steer_r_dof": m.jnt_dofadr[lay.steer_r], "assist_act": nz, "assist_ctrl": 0}
        assist = nz
        nz += 2  # the assist's torque, the follower's integral
        col = [float(column[k]) for k in _names("artic_truth_column_names")]
        static = yardbuild.static_loads(v)
        driven = sum(static[a.name] for a in v.axles if a.driven)
        head = [len(sets), len(lay.ends), nz, 1.0 if self.speed_mode == "follow" else 0.0,
                lay.mass, FOLLOW_TAU, lay.fifth_roll, yardbuild.FIFTH_WHEEL_LASH,
                0.02 * yardbuild.FIFTH_WHEEL_LASH, yardbuild.FIFTH_WHEEL_ROLL,
                yardbuild.FIFTH_WHEEL_ROLL_DAMPING, lay.drive_site, lay.drive_body, 1.0,
                assist + 1, min(DRIVE_FORCE_MAX * self._weight, FOLLOW_TRACTION * driven),
                BRAKE_DECEL_MAX * self._weight]
        if len(head) != int(library().artic_yard_header()):
            raise YardUnavailable("the compiled yard truth's header differs; reinstall artic")
        par = np.concatenate([head, *[self.tyres[a].vector() for a in sets], col,
                              np.ravel(rows)])
        return np.ascontiguousarray(par, dtype=float), nz, assist

    def _advance(self, n: int) -> None:
        par, ctl, z, zdot, out = self._ptrs
        bad = self._lib.artic_yard_advance(self.model._address, self.data._address, par, ctl,
                                           z, zdot, n, out)
        if bad:
            self.diverged()

    def diverged(self) -> None:
        """Raise the truth's error for a state that stopped being finite in its last step."""
        raise FloatingPointError(f"{self.vehicle.name}: the yard truth's state stopped "
                                 f"being finite at t = {self.data.time:.2f} s")

    def _set_brakes(self, decel: float) -> None:
        if decel != self._decel:
            self.model.dof_frictionloss[self._spin] = (decel * self._weight * self._r0_ends
                                                       * self._brake_share)
            self._decel = decel

    def _settle(self) -> tuple[np.ndarray, np.ndarray]:
        """The truth standing on its tyres, braked, at the origin (reset's starting point)."""
        mujoco.mj_resetData(self.model, self.data)
        self.z[:] = 0.0
        follow = self._par[3]
        self._par[3] = 0.0
        self._set_brakes(PARKING_GRADE)
        self._ctl[:] = 0.0
        self._advance(int(round(SETTLE_TIME / self.model.opt.timestep)))
        self._par[3] = follow
        self._set_brakes(0.0)
        return self.data.qpos.copy(), self.z.copy()

    # ------------------------------------------------------------ the model protocol
    def reset(self, initial: InitialState) -> None:
        """Place the settled truth at ``initial`` (pose, speed, yaw rates, steering)."""
        m, d, lay = self.model, self.data, self.layout
        qpos, z = self._settled
        mujoco.mj_resetData(m, d)
        d.qpos[:] = qpos
        self.z[:] = z
        self._zdot[:] = 0.0
        self.steer_limited = 0
        self._parked = False
        self.pedals = (0.0, 0.0)
        self._set_brakes(0.0)
        self._lib.artic_yard_kinematics(m._address, d._address)
        # turn about the vertical so that the tractor's unit heads psi_1 and sits at (x_1, y_1)
        s1, s2 = lay.sensor_sites
        psi_now = math.atan2(d.site_xmat[s1][3], d.site_xmat[s1][0])
        turn = initial.psi_1 - self._eps[0] - psi_now
        qa = m.jnt_qposadr[lay.free_joint]
        c, s = math.cos(turn), math.sin(turn)
        x, y = d.qpos[qa], d.qpos[qa + 1]
        d.qpos[qa:qa + 2] = [c * x - s * y, s * x + c * y]
        qz = np.array([math.cos(0.5 * turn), 0.0, 0.0, math.sin(0.5 * turn)])
        quat = np.empty(4)
        mujoco.mju_mulQuat(quat, qz, d.qpos[qa + 3:qa + 7])
        d.qpos[qa + 3:qa + 7] = quat
        hitch = m.jnt_qposadr[lay.hitch]
        d.qpos[hitch] = -(initial.gamma - self._eps[0] + self._eps[1])
        sl, sr = m.jnt_qposadr[lay.steer_l], m.jnt_qposadr[lay.steer_r]
        front = next(a for a in self.vehicle.tractor_axles if a.steered)
        d.qpos[sl] = initial.delta
        d.qpos[sr] = yardbuild.ackermann_right(initial.delta, front.track, self.vehicle.L1)
        self._lib.artic_yard_kinematics(m._address, d._address)
        for _ in range(2):  # the heading's and the hitch's correction of the settled pose
            err1 = float(wrap_angle(initial.psi_1 - self._eps[0]
                                    - math.atan2(d.site_xmat[s1][3], d.site_xmat[s1][0])))
            mujoco.mju_mulQuat(quat, np.array([math.cos(0.5 * err1), 0, 0, math.sin(0.5 * err1)]),
                               d.qpos[qa + 3:qa + 7])
            d.qpos[qa + 3:qa + 7] = quat
            self._lib.artic_yard_kinematics(m._address, d._address)
            psi2 = math.atan2(d.site_xmat[s2][3], d.site_xmat[s2][0])
            psi1 = math.atan2(d.site_xmat[s1][3], d.site_xmat[s1][0])
            err2 = float(wrap_angle(initial.gamma - (psi1 + self._eps[0] - psi2 - self._eps[1])))
            d.qpos[hitch] -= err2
            self._lib.artic_yard_kinematics(m._address, d._address)
        p = d.site_xpos[s1]
        d.qpos[qa] += initial.x_1 - p[0]
        d.qpos[qa + 1] += initial.y_1 - p[1]
        self._lib.artic_yard_kinematics(m._address, d._address)
        # motion: the tractor's unit moves at (u1, v_y_1) in its axes, yawing at r_1
        psi = initial.psi_1 - self._eps[0]
        ex, ey = np.array([math.cos(psi), math.sin(psi), 0.0]), np.array(
            [-math.sin(psi), math.cos(psi), 0.0])
        w = np.array([0.0, 0.0, initial.r_1])
        rel = d.site_xpos[s1] - d.xpos[lay.drive_body]
        v_origin = initial.u1 * ex + initial.v_y_1 * ey - np.cross(w, rel)
        va = m.jnt_dofadr[lay.free_joint]
        R = d.xmat[lay.drive_body].reshape(3, 3)
        d.qvel[va:va + 3] = v_origin
        d.qvel[va + 3:va + 6] = R.T @ w
        d.qvel[m.jnt_dofadr[lay.hitch]] = initial.r_2 - initial.r_1
        self._lib.artic_yard_kinematics(m._address, d._address)
        for e in lay.ends:  # the wheels roll with the ground
            hub = e["hub_site"]
            Rh = d.site_xmat[hub].reshape(3, 3)
            vel = np.zeros(6)
            mujoco.mj_objectVelocity(m, d, mujoco.mjtObj.mjOBJ_SITE, hub, vel, 0)
            t = self.tyres[e["axle"]]
            d.qvel[e["spin_dof"]] = float(vel[3:] @ Rh[:, 0]) / (t.r0 - 0.01)
        self._lib.artic_yard_kinematics(m._address, d._address)
        self._psi[:] = [self._heading(0), self._heading(1)]
        self._ctl[:] = [initial.delta, initial.u1, 0.0, d.time, 0.0]

    def _heading(self, i: int) -> float:
        R = self.data.site_xmat[self.layout.sensor_sites[i]]
        return math.atan2(R[3], R[0])

    def step(self, dt: float, delta: float, u1: float, u1_dot: float) -> None:
        """Advance ``dt`` [s]: steering demand ``delta`` (the left wheel's) [rad], speed ``u1``."""
        sub_dt, n = self._sub
        if dt != sub_dt:  # MuJoCo's steps in one of ``dt``, worked out once per ``dt``
            n = max(1, int(round(dt / self.model.opt.timestep)))
            self._sub = (dt, n)
        lock = self._lock
        if abs(delta) > lock:
            self.steer_limited += 1
            delta = math.copysign(lock, delta)
        drive = 0.0
        if self.speed_mode == "pedals":
            throttle = min(max(float(self.pedals[0]), 0.0), 1.0)
            brake = min(max(float(self.pedals[1]), 0.0), 1.0)
            gear = 1.0 if u1 >= 0.0 else -1.0
            drive = gear * throttle * DRIVE_FORCE_MAX * self._weight * self._r0_mean
            decel = max(brake * BRAKE_DECEL_MAX, PARKING_GRADE if self._parked else 0.0)
            if decel != self._decel:
                self._set_brakes(decel)
        ctl = self._ctl
        ctl[0], ctl[1], ctl[2], ctl[3], ctl[4] = delta, u1, u1_dot, self.data.time, drive
        self._advance(n)

    def observe(self, delta: float | None = None) -> np.ndarray:
        """The signals at the two units' sensors, in ``OBSERVATION`` order.

        Heading: the unit's x axis over the ground, plus its mounting yaw;
        velocities: the unit's ground velocity in its heading's axes; yaw rate:
        the unit's rotation about its own vertical (a strapdown gyro).
        """
        # Once per harness sample: Python floats throughout (the same IEEE operations
        # as on numpy's scalars, and wrap_angle's scalar path written out), the
        # sensors' bodies looked up once.
        d, m = self.data, self.model
        vel, two_pi = self._vel, 2.0 * math.pi
        xmat, xpos, bmat, psis = self._site_xmat, self._site_xpos, self._xmat, self._psi
        row = []
        for i, (site, body) in enumerate(self._sensor_bodies):
            R = xmat[site]
            prev = float(psis[i])
            psi = prev + (math.pi - (math.pi - (math.atan2(R[3], R[0]) - prev)) % two_pi)
            psis[i] = psi
            mujoco.mj_objectVelocity(m, d, _SITE, site, vel, 0)  # every entry written
            v0, v1, v2, v3, v4, _ = vel.tolist()
            h = psi + self._eps[i]
            c, s = math.cos(h), math.sin(h)
            B = bmat[body].tolist()
            x, y, _ = xpos[site].tolist()
            row += [x, y, h, c * v3 + s * v4, -s * v3 + c * v4, v0 * B[2] + v1 * B[5] + v2 * B[8]]
        row.append(math.pi - (math.pi - (row[2] - row[8])) % two_pi)  # wrap_angle's scalar path
        return np.array(row)

    def sensor_speed(self) -> float:
        """The tractor's unit's longitudinal velocity [m/s]: :meth:`observe`'s ``v_x_1`` alone.

        The drivers ask for it every step; the rest of the signals would cost as
        much again. Both units' continuous headings advance here as ``observe``
        advances them, so that what is observed next is the same to the bit.
        """
        xmat, psis, two_pi = self._site_xmat, self._psi, 2.0 * math.pi
        (s0, _), (s1, _) = self._sensor_bodies
        for i, site in ((0, s0), (1, s1)):  # observe's (and wrap_angle's) scalar path
            R = xmat[site]
            prev = float(psis[i])
            psis[i] = prev + (math.pi - (math.pi - (math.atan2(R[3], R[0]) - prev)) % two_pi)
        vel = self._vel
        mujoco.mj_objectVelocity(self.model, self.data, _SITE, s0, vel, 0)
        h = float(psis[0]) + self._eps[0]
        _, _, _, v3, v4, _ = vel.tolist()
        return math.cos(h) * v3 + math.sin(h) * v4

    @property
    def gamma(self) -> float:
        """Articulation angle as the units report it [rad]."""
        return float(wrap_angle(self._heading(0) + self._eps[0] - self._heading(1)
                                - self._eps[1]))

    @property
    def parking_brake(self) -> bool:
        """Whether the parking brake holds every wheel."""
        return self._parked

    @parking_brake.setter
    def parking_brake(self, on: bool) -> None:
        self._parked = bool(on)
        self._set_brakes(PARKING_GRADE if on else 0.0)

    @property
    def column_torques(self) -> dict[str, float]:
        """The column's torques of the last step [N m]: box, torsion bar, tie rod."""
        k = 3 * len(self.layout.ends)
        return {"box": float(self._out[k]), "torsion_bar": float(self._out[k + 1]),
                "tie_rod": float(self._out[k + 2])}

    @property
    def fifth_wheel_torque(self) -> float:
        """The fifth wheel's bushes' roll torque on the plate of the last step [N m]."""
        return float(self._out[3 * len(self.layout.ends) + 3])

    def wheel_loads(self) -> np.ndarray:
        """Each wheel end's vertical tyre force of the last step [N]."""
        return self._out[2:3 * len(self.layout.ends):3].copy()

    def compiled(self) -> None:
        """No compiled form for the harness's numba loop."""
        return None

    def closed_loop(self) -> Callable | None:
        """The harness's loop in C (:mod:`artic.validation.synthetic.yardloop`), or ``None``.

        ``None`` where the compiled truth lacks it: the harness's Python loop
        then drives the truth, to the same bits.
        """
        return self.replay_loop(None)

    def replay_loop(self, replay: Callable[[], tuple[np.ndarray, int]] | None
                    ) -> Callable | None:
        """:meth:`closed_loop`, its steps taken from a recorded actuation with ``replay``.

        ``replay()`` gives the rows and the first row's index when the loop starts
        (:class:`artic.validation.criteria.prediction.Replay`); the loop's result
        carries the next row's as ``act_k``.
        """
        # Here, not at the top: only the harness asks for the loop; making a log
        # needs none of it.
        from artic.validation.synthetic import yardloop

        if not yardloop.available(self._lib):
            return None

        def loop(args, extras: bool = False):  # the truth has no extras() columns
            return yardloop.run(self, args, None if replay is None else replay())

        return loop

    def close(self) -> None:
        """Nothing held beyond Python's own objects."""

    def __enter__(self) -> YardTruth:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    # ------------------------------------------------------------ full state
    def full_state(self) -> np.ndarray:
        """Everything a continued run needs, bit for bit [mixed units].

        MuJoCo's integration state (time, qpos, qvel, act, warm start, controls,
        applied forces), the hidden states (tyre deflections and twists, the
        assist torque), the brakes' level, the parking brake, the units' unwrapped
        headings, the steering-limit count, the pedals and the last controls.
        """
        n, n_z = self._state_size, self.n_z
        x = np.empty(n + n_z + 12)
        mujoco.mj_getState(self.model, self.data, x[:n], mujoco.mjtState.mjSTATE_INTEGRATION)
        x[n:n + n_z] = self.z
        x[n + n_z:n + n_z + 5] = (self._decel, float(self._parked), *self._psi.tolist(),
                                  float(self.steer_limited))
        x[n + n_z + 5:n + n_z + 7] = self.pedals
        x[n + n_z + 7:] = self._ctl
        return x

    def set_full_state(self, x: np.ndarray) -> None:
        """Restore a :meth:`full_state` of this truth."""
        spec = mujoco.mjtState.mjSTATE_INTEGRATION
        n = mujoco.mj_stateSize(self.model, spec)
        x = np.asarray(x, dtype=float)
        if x.size != n + self.n_z + 12:
            raise ValueError(f"full state of {x.size} numbers; this truth has "
                             f"{n + self.n_z + 12}")
        mujoco.mj_setState(self.model, self.data, x[:n], spec)
        self.z[:] = x[n:n + self.n_z]
        e = x[n + self.n_z:]
        self._set_brakes(float(e[0]))
        self._parked = bool(e[1])
        self._psi[:] = e[2:4]
        self.steer_limited = int(e[4])
        self.pedals = (float(e[5]), float(e[6]))
        self._ctl[:] = e[7:12]
        self._lib.artic_yard_kinematics(self.model._address, self.data._address)


class YardSeat:
    """The driver's seat of the yard truth: steering wheel, column drift and pedals.

    The generators drive it as they drove the plant's actuation
    (:class:`artic.validation.synthetic.actuation.TruthActuation`): it records
    the steering-wheel angle held at every step. The steering wheel reaches the
    box less the column's drifting zero (``column``, its play is the truth's
    own, in the compiled column), and the box turns the left knuckle by the
    truth's own gear, ``(delta_h - offset) / i_s`` with the truth file's
    ``[steering.mbd]`` ratio and offset.

    Parameters
    ----------
    truth : YardTruth
        Built with ``speed="pedals"`` when ``pedals`` is given.
    column : object
        ``column(delta_h, t)``: the steering-wheel angle at the box [rad]
        (:class:`artic.validation.synthetic.actuation.SteeringColumn`, without play).
    pedals : object, optional
        ``command(u_target, a_target, u)`` -> (throttle, brake)
        (:class:`artic.validation.synthetic.actuation.PedalDriver`).
    """

    name = "mbd"

    def __init__(self, truth: YardTruth, column, pedals=None, record: bool = False) -> None:
        self.plant = truth
        self.column = column
        self.pedals = pedals
        s = truth.vehicle.steering_for("mbd")
        self.i_s, self.offset = s.i_s, s.delta_h_offset
        self.steering = self
        """The gear as a steering map (``steering_wheel``, ``road_wheel``), for the docking run."""
        self.delta_h: list[float] = []
        self.t = 0.0
        self.states: list[np.ndarray] | None = [] if record else None
        """The truth's full state at every :meth:`observe` since :meth:`reset` (``record``)."""
        self.held: list[tuple[float, ...]] | None = [] if record else None
        """What the truth was given at every step since :meth:`reset` (``record``):
        its ``step`` arguments (steering demand [rad], speed [m/s], its rate
        [m/s^2]) and the pedals (throttle, brake) [-]."""

    def gear(self, delta_h: float) -> float:
        """The left wheel's angle the steering wheel at ``delta_h`` stands for [rad]."""
        return (delta_h - self.offset) / self.i_s

    def steering_wheel(self, delta: float) -> float:
        """The steering-wheel angle that stands for left-wheel angle ``delta`` [rad]."""
        return delta * self.i_s + self.offset

    road_wheel = gear

    def reset(self, initial: InitialState) -> None:
        """Reset the truth, the column's play and drift, and the driver."""
        self.plant.reset(initial)
        self.column.reset(self.steering_wheel(0.0))
        if self.pedals is not None:
            self.pedals.reset(initial.u1)
        self.delta_h = []
        self.t = 0.0
        if self.states is not None:
            self.states = []
            self.held = []

    def step_steering_wheel(self, dt: float, delta_h: float, u1: float, u1_dot: float) -> None:
        """Advance ``dt`` [s] with the steering wheel at ``delta_h`` [rad], target speed ``u1``."""
        self.delta_h.append(delta_h)
        ref = self.gear(float(self.column(delta_h, self.t)))
        if self.pedals is not None:
            a = math.copysign(1.0, u1) * u1_dot if u1 else 0.0
            self.plant.pedals = self.pedals.command(u1, a, self.plant.sensor_speed())
        if self.held is not None:
            self.held.append((ref, u1, u1_dot, *map(float, self.plant.pedals)))
        self.plant.step(dt, ref, u1, u1_dot)
        self.t += dt

    def step(self, dt: float, delta: float, u1: float, u1_dot: float) -> None:
        """Advance with the road-wheel angle the driver wants: he turns the wheel for it."""
        self.step_steering_wheel(dt, self.steering_wheel(delta), u1, u1_dot)

    def observe(self, delta: float | None = None) -> np.ndarray:
        """The truth's signals (and, recording, its full state now)."""
        if self.states is not None:
            self.states.append(self.plant.full_state())
        return self.plant.observe(delta)

    @property
    def gamma(self) -> float:
        """Articulation angle [rad]."""
        return self.plant.gamma

    def compiled(self) -> None:
        """No compiled form."""
        return None

    def close(self) -> None:
        """The truth is closed by its owner."""
