"""Build the multibody model of a combination with ``mujoco.MjSpec``.

The tree, for each unit:

    tractor (free joint)                      trailer (hitch.yaw, hitch.pitch)
    ├── axle.<name> (suspension slide)        ├── axle.<name> ...
    │   ├── knuckle.<name>.L|R (steer hinge)  └── sensor.trailer (site)
    │   │   └── wheel.<name>.L|R (spin hinge)
    │   └── wheel.<name>.L|R (spin hinge, unsteered axles)
    ├── sensor.tractor (site)
    └── trailer ...

- Tyres are force elements. The wheels have no contact geometry: the plant's
  tyre callback computes the vertical, longitudinal and lateral forces and
  applies them. Every geom here is visual only (contype 0).
- The fifth wheel leaves yaw free and pitch free within ``hitch_pitch``. It
  is stiff in roll, as a fifth-wheel plate is to first order at yard speeds.
- Each axle is rigid and slides vertically on a linear spring and damper;
  the chassis rolls only on the tyres' vertical compliance.
- The left front wheel turns by a position servo; the right one follows it
  through a joint equality, the polynomial fitted to the tie-rod trapezoid
  (:mod:`artic.mjcf.linkage`).
- Each wheel end has two integrator actuators of zero gain, ``tread.*.u`` and
  ``tread.*.v``. Their activations hold the tyre's tread deflections in
  MuJoCo's own state, so every integrator stage sees consistent tyre states.

Ground, light, camera and dock are added by :func:`add_scene`, apart from
the vehicle.
"""

from __future__ import annotations

import functools
import math

import mujoco
import numpy as np

from artic.mjcf import naming as nm
from artic.mjcf.compiling import compile_spec
from artic.mjcf.linkage import Trapezoid, left_range
from artic.mjcf.masses import AxleLayout, Body, layout
from artic.mjcf.outline import DOCK_DEPTH, DOCK_FACE, outline
from artic.mjcf.vehicle import G, Vehicle

SOLVERS = {"pgs": mujoco.mjtSolver.mjSOL_PGS, "newton": mujoco.mjtSolver.mjSOL_NEWTON}
"""The constraint solvers the generator can set (:func:`build_vehicle`'s ``solver``)."""

TIMESTEP = 1e-2
"""Default plant timestep [s], with the RK4 integrator: the logs' 10 ms sample.

The plant's fastest mode is each wheel's spin on its damped tread at
standstill, a real root near -430 1/s, beyond plain RK4's reach at 10 ms
(``h lambda = -4.3`` against -2.785): the tyre callback fits it to the step
(:mod:`artic.plant.spinmode`), an ``O(h^4)`` change that keeps 10 ms stable.
The convergence study (``benchmarks/bench_convergence.py``,
``docs/design/timestep.md``) against plain RK4 at 1 ms: on every manoeuvre
kind of the three presets and on all 58 campaign logs, on their own preset
and on ``six-axle``, within 0.73 mm, 0.0023 deg and 3.9e-4 rad/s (targets
1 cm, 0.05 deg, 1e-3 rad/s). What 10 ms resolves less well than 5 ms is a
steering servo's response to a step of its command (1.1e-3 rad/s of yaw rate
after a 15 deg step); the harness hands its feedback over in ramps
(:mod:`artic.validation.harness.reversing`) rather than stepping it.
``5e-3`` (1.5e-5 m, 4.4e-5 deg, 2.2e-5 rad/s) at twice the cost: pass
``timestep=5e-3`` to :class:`artic.Plant` where a servo step must be resolved."""

SERVO_KP = 2.0e5
"""Steering servo stiffness [N m/rad]."""

SPEED_SERVO_RATE = 20.0
"""Bandwidth of the speed follower's velocity servo [1/s]: its gain is this times
the combination's mass, a 50 ms time constant."""

STEER_ARMATURE = 20.0
"""Inertia reflected to each steering hinge [kg m^2]: steering box, column and arms."""


_QX90 = [math.sqrt(0.5), math.sqrt(0.5), 0.0, 0.0]
"""Quaternion turning a cylinder's axis from z to y (wheels, axles)."""


def _visual(body, **kw) -> None:
    g = body.add_geom(**kw)
    g.contype, g.conaffinity, g.group = 0, 0, 1


def _inertial(body, b: Body, at_origin: bool = False) -> None:
    body.explicitinertial = True
    body.mass = float(b.mass)
    body.ipos = [0.0, 0.0, 0.0] if at_origin else [float(x) for x in b.pos]
    body.inertia = [float(x) for x in b.inertia]


def linkage(v: Vehicle) -> tuple[Trapezoid, np.ndarray, tuple[float, float]]:
    """The front axle's trapezoid, its fitted polynomial ``a0..a4`` and the left wheel's range.

    The range [rad] is the left-wheel angles that give centre angles of
    ``-delta_max`` and ``+delta_max``; the fit covers it with 2 deg to spare.

    A quartic (what a MuJoCo joint equality takes) cannot follow the
    trapezoid's steep rise near lock on the inside of right turns. The fit
    is weighted ``1 / (1 + (delta_L / 0.45)^2)`` toward the angles of yard
    driving. For the presets it is within 0.16 deg up to 20 deg of
    left-wheel angle, 0.6 deg up to 30 deg, and 0.95 deg at lock.
    """
    front = max((a for a in v.tractor_axles if a.steered), key=lambda a: a.x)
    trap, coef, rng = _linkage(front.track, v.L1, v.steering.steering_arm,
                               v.steering.delta_max)
    return trap, coef.copy(), rng


@functools.lru_cache(maxsize=64)
def _linkage(track: float, L1: float, arm: float,
             delta_max: float) -> tuple[Trapezoid, np.ndarray, tuple[float, float]]:
    """:func:`linkage` for the four numbers it depends on, cached."""
    trap = Trapezoid(track, L1, arm)
    lo, hi = left_range(trap.right_angle, delta_max)
    d = np.linspace(lo - math.radians(2.0), hi + math.radians(2.0), 301)
    r = trap.right_angles(d)
    # Weighted least squares through the origin: straight ahead is straight ahead,
    # with no toe from a fitted constant.
    w = 1.0 / (1.0 + (d / 0.45) ** 2)
    basis = np.column_stack([d ** k for k in range(1, 5)])
    coef = np.linalg.lstsq(basis * w[:, None], r * w, rcond=None)[0]
    poly = np.concatenate([[0.0], coef])
    # The servo's range, through the fitted linkage the model really has.
    return trap, poly, left_range(lambda x: np.polynomial.polynomial.polyval(x, poly),
                                  delta_max)


def _add_axle(parent, a: AxleLayout, R0: float) -> None:
    ax = a.axle
    body = parent.add_body(name=nm.axle(ax.name), pos=[float(x) for x in a.centre])
    _inertial(body, a.body, at_origin=True)
    j = body.add_joint(name=nm.suspension(ax.name), type=mujoco.mjtJoint.mjJNT_SLIDE,
                       axis=[0, 0, 1])
    j.stiffness = [ax.suspension_stiffness, 0.0, 0.0]
    j.damping = [ax.suspension_damping, 0.0, 0.0]
    j.springref = float(a.springref)
    _visual(body, type=mujoco.mjtGeom.mjGEOM_CAPSULE, size=[0.06, 0.5 * ax.track, 0],
            quat=_QX90, rgba=[0.3, 0.3, 0.3, 1])
    half_width = 0.3 if ax.dual else 0.16
    for sign, side in ((1.0, "L"), (-1.0, "R")):
        pos = [0.0, sign * 0.5 * ax.track, 0.0]
        carrier = body
        if ax.steered:
            carrier = body.add_body(name=nm.knuckle(ax.name, side), pos=pos)
            _inertial(carrier, a.knuckle, at_origin=True)
            h = carrier.add_joint(name=nm.steer(ax.name, side),
                                  type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0, 0, 1])
            h.armature = STEER_ARMATURE
            h.limited = mujoco.mjtLimited.mjLIMITED_TRUE
            h.range = [-1.3, 1.3]
            pos = [0.0, 0.0, 0.0]
        carrier.add_site(name=nm.hub(ax.name, side), pos=pos, size=[0.05, 0.0, 0.0])
        wheel = carrier.add_body(name=nm.wheel(ax.name, side), pos=pos)
        _inertial(wheel, a.wheel, at_origin=True)
        spin = wheel.add_joint(name=nm.spin(ax.name, side), type=mujoco.mjtJoint.mjJNT_HINGE,
                               axis=[0, 1, 0])
        # The parking brake is dry friction on this joint (plant.Plant.parking_brake):
        # a hard friction constraint, so a parked wheel creeps at 0.1 mm/s, not cm/s.
        spin.solimp_friction = [0.999, 0.9999, 0.001, 0.5, 2.0]
        _visual(wheel, type=mujoco.mjtGeom.mjGEOM_CYLINDER, size=[R0, half_width, 0],
                quat=_QX90, rgba=[0.1, 0.1, 0.1, 1])


def gravity(v: Vehicle) -> list[float]:
    """Gravity in the yard's ground-aligned frame [m/s^2].

    The model's ground is the plane ``z = 0``; a sloped yard tilts gravity
    instead. With grade ``theta`` (+x uphill) and crossfall ``phi`` (+y uphill)
    the ground's normal is ``R_x(phi) R_y(-theta) e_z`` in a level frame, so in
    ground axes gravity is ``-G (sin theta, cos theta sin phi, cos theta cos phi)``:
    its along-slope parts point downhill.
    """
    th, ph = v.plant.grade, v.plant.crossfall
    return [-G * math.sin(th), -G * math.cos(th) * math.sin(ph),
            -G * math.cos(th) * math.cos(ph)]


def build_vehicle(v: Vehicle, solver: str = "pgs") -> mujoco.MjSpec:
    """The combination as an ``MjSpec``, without scene.

    Parameters
    ----------
    v : Vehicle
        Every number comes from here (and from its tyre file).
    solver : str
        The constraint solver, a key of :data:`SOLVERS`: ``"pgs"`` (the CPU
        plant's) or ``"newton"`` (what MuJoCo Warp supports; the plant's signals
        change by rounding only, see ``docs/design/warp-plant.md``).
    """
    if solver not in SOLVERS:
        raise ValueError(f"solver {solver!r}: expected one of {', '.join(SOLVERS)}")
    v = v.with_payload()
    lay = layout(v)
    spec = mujoco.MjSpec()
    spec.modelname = f"artic-{v.name}"
    spec.compiler.degree = False
    spec.compiler.inertiafromgeom = mujoco.mjtInertiaFromGeom.mjINERTIAFROMGEOM_FALSE
    spec.option.timestep = TIMESTEP
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_RK4
    # The constraints are few and small (the tie rods, the hitch's pitch stops,
    # friction on the hitch and on braked wheels): the dual PGS solver handles
    # them without Newton's factorisation of the whole nv x nv system (a step
    # about 15 % cheaper), and every geom is visual, so collision is off. PGS
    # solves the constraints as one system, so MuJoCo's island discovery is
    # work for nothing (4 % of a step); without it the steps are bitwise equal.
    spec.option.solver = SOLVERS[solver]
    spec.option.disableflags |= (mujoco.mjtDisableBit.mjDSBL_CONTACT
                                 | mujoco.mjtDisableBit.mjDSBL_ISLAND)
    spec.option.gravity = gravity(v)
    tractor = spec.worldbody.add_body(name=nm.TRACTOR, pos=[0.0, 0.0, 0.0])
    tractor.add_freejoint(name=nm.ROOT)
    _inertial(tractor, lay.chassis[1])
    body = outline(v)
    frame_half = 0.5 * (body.tractor_front - body.tractor_rear)
    _visual(tractor, type=mujoco.mjtGeom.mjGEOM_BOX, size=[frame_half, 0.5 * body.width, 0.35],
            pos=[body.tractor_rear + frame_half, 0.0, 1.0], rgba=[0.75, 0.1, 0.1, 1])
    _visual(tractor, type=mujoco.mjtGeom.mjGEOM_BOX, size=[0.9, 0.5 * body.width, 1.1],
            pos=[body.tractor_front - 1.2, 0.0, 2.1], rgba=[0.8, 0.15, 0.15, 1])
    s1 = v.sensor1
    z_drive = lay.unit_axles(1)[[a.axle.x for a in lay.unit_axles(1)].index(0.0)].centre[2]
    tractor.add_site(name=nm.sensor(1), pos=[s1[0], s1[1], z_drive + s1[2]],
                     size=[0.08, 0.0, 0.0], rgba=[0, 0.6, 1, 1])
    for a in lay.unit_axles(1):
        _add_axle(tractor, a, lay.R0)
    drive = next((a for a in lay.unit_axles(1) if a.axle.driven), lay.unit_axles(1)[0])
    spec.body(nm.axle(drive.axle.name)).add_site(name=nm.SPEED_SITE,
                                                 pos=[0.0, 0.0, -float(drive.centre[2])],
                                                 size=[0.05, 0.0, 0.0])
    trailer = tractor.add_body(name=nm.TRAILER, pos=[v.L1c, 0.0, v.h5])
    yaw = trailer.add_joint(name=nm.HITCH_YAW, type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0, 0, 1])
    yaw.limited = mujoco.mjtLimited.mjLIMITED_FALSE
    yaw.frictionloss = v.plant.fifth_wheel_friction
    yaw.damping = [v.plant.hitch_damping, 0.0, 0.0]
    pitch = trailer.add_joint(name=nm.HITCH_PITCH, type=mujoco.mjtJoint.mjJNT_HINGE,
                              axis=[0, 1, 0])
    pitch.limited = mujoco.mjtLimited.mjLIMITED_TRUE
    pitch.range = [-v.hitch_pitch, v.hitch_pitch]
    _inertial(trailer, lay.chassis[2])
    length = body.trailer_front - body.trailer_rear
    _visual(trailer, type=mujoco.mjtGeom.mjGEOM_BOX, size=[0.5 * length, 0.5 * body.width, 1.35],
            pos=[body.trailer_front - 0.5 * length, 0.0, 1.5], rgba=[0.85, 0.85, 0.8, 0.6])
    s2 = v.sensor2
    trailer.add_site(name=nm.sensor(2), pos=[s2[0], s2[1], z_drive + s2[2] - v.h5],
                     size=[0.08, 0.0, 0.0], rgba=[0, 0.6, 1, 1])
    for a in lay.unit_axles(2):
        _add_axle(trailer, a, lay.R0)
    _add_actuators(spec, v, lay)
    return spec


def _add_actuators(spec: mujoco.MjSpec, v: Vehicle, lay) -> None:
    _, poly, (lo, hi) = linkage(v)
    for a in lay.unit_axles(1):
        ax = a.axle
        if not ax.steered:
            continue
        servo = spec.add_actuator(name=nm.servo(ax.name), target=nm.steer(ax.name, "L"),
                                  trntype=mujoco.mjtTrn.mjTRN_JOINT)
        servo.set_to_position(kp=SERVO_KP, dampratio=1.0)
        servo.ctrllimited = mujoco.mjtLimited.mjLIMITED_TRUE
        servo.ctrlrange = [lo, hi]
        eq = spec.add_equality(name=nm.tie_rod(ax.name), type=mujoco.mjtEq.mjEQ_JOINT,
                               name1=nm.steer(ax.name, "R"), name2=nm.steer(ax.name, "L"))
        data = np.zeros(eq.data.size)
        data[:5] = poly
        eq.data = data
    for a in lay.axles:
        for side in nm.SIDES:
            ax = a.axle
            if ax.driven:
                d = spec.add_actuator(name=nm.drive(ax.name, side), target=nm.spin(ax.name, side),
                                      trntype=mujoco.mjtTrn.mjTRN_JOINT)
                d.set_to_motor()
            b = spec.add_actuator(name=nm.brake(ax.name, side), target=nm.spin(ax.name, side),
                                  trntype=mujoco.mjtTrn.mjTRN_JOINT)
            b.set_to_motor()
    # The speed follower: a velocity servo pushing the drive axle along the
    # tractor's x-axis at ground level, where traction acts. The plant sets its
    # gain to zero when it drives with wheel torques instead (artic.plant.plant).
    follower = spec.add_actuator(name=nm.SPEED_SERVO, target=nm.SPEED_SITE,
                                 trntype=mujoco.mjtTrn.mjTRN_SITE)
    follower.gear = [1.0, 0.0, 0.0, 0.0, 0.0, 0.0]
    follower.set_to_velocity(kv=SPEED_SERVO_RATE * (v.m1 + v.m2))
    follower.ctrllimited = mujoco.mjtLimited.mjLIMITED_FALSE
    for a in lay.axles:
        for side in nm.SIDES:
            for direction in ("u", "v", "w"):  # tread: along, across, twist
                t = spec.add_actuator(name=nm.tread(a.axle.name, side, direction),
                                      target=nm.spin(a.axle.name, side),
                                      trntype=mujoco.mjtTrn.mjTRN_JOINT)
                t.dyntype = mujoco.mjtDyn.mjDYN_INTEGRATOR
                t.gaintype = mujoco.mjtGain.mjGAIN_FIXED
                gain = np.zeros(t.gainprm.size)
                t.gainprm = gain
                t.biastype = mujoco.mjtBias.mjBIAS_NONE
                t.ctrllimited = mujoco.mjtLimited.mjLIMITED_FALSE
                t.actlimited = mujoco.mjtLimited.mjLIMITED_FALSE


def add_scene(spec: mujoco.MjSpec) -> None:
    """Add the yard: a ground plane, light, a chase camera and the dock."""
    world = spec.worldbody
    ground = world.add_geom(name="ground", type=mujoco.mjtGeom.mjGEOM_PLANE,
                            size=[200.0, 200.0, 0.1], rgba=[0.55, 0.55, 0.5, 1])
    ground.contype, ground.conaffinity = 0, 0
    world.add_light(name="sun", pos=[0.0, 0.0, 50.0], dir=[0.2, 0.2, -1.0])
    dock = world.add_body(name=nm.DOCK, pos=[DOCK_FACE[0] - 0.5 * DOCK_DEPTH, DOCK_FACE[1], 0.0])
    _visual(dock, type=mujoco.mjtGeom.mjGEOM_BOX, size=[0.5 * DOCK_DEPTH, 3.0, 1.3],
            pos=[0.0, 0.0, 1.3],
            rgba=[0.4, 0.4, 0.45, 1])
    tractor = spec.body(nm.TRACTOR)
    if tractor is not None:
        cam = tractor.add_camera(name="chase", pos=[-25.0, -18.0, 14.0])
        cam.mode = mujoco.mjtCamLight.mjCAMLIGHT_TRACKCOM
        cam.targetbody = nm.TRACTOR


def build_model(v: Vehicle, scene: bool = True, solver: str = "pgs") -> mujoco.MjSpec:
    """The combination and, if ``scene``, the yard; ``solver`` as in :func:`build_vehicle`."""
    spec = build_vehicle(v, solver)
    if scene:
        add_scene(spec)
    return spec


def to_xml(v: Vehicle, scene: bool = True) -> str:
    """Canonical MJCF of the combination (and the yard), as MuJoCo writes it."""
    spec = build_model(v, scene)
    compile_spec(spec)
    return spec.to_xml()
