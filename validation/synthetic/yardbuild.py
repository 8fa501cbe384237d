"""The yard truth's own MuJoCo model: its bodies, joints and mechanisms.

The independent truth (:mod:`artic.validation.synthetic.yardtruth`) is built
here from the truth's vehicle file, with nothing of the plant's builder
(``artic.mjcf.builder`` and its helpers): its own body tree, masses spread
over its own bodies, its own joints, and mechanisms the plant does not have:

- **frame torsion**: the tractor's ladder frame is two bodies, the rear one
  (drive axle, fifth wheel) free, the front one (front axle, cab) on a hinge
  about the frame's long axis between the axles, with the frame's torsional
  stiffness :data:`FRAME_TORSION`;
- **cab on its mounts**: the cab is a body of its own on roll and pitch hinges
  of the mounts' stiffness and damping;
- **the fifth wheel**: the plate rocks in pitch on its brackets (limited by
  the vehicle file's ``hitch_pitch``) and rolls on rubber bushes that take up
  the lash :data:`FIFTH_WHEEL_LASH` before they carry (the compiled loop
  applies that law); the kingpin turns in the plate with the file's friction;
- **suspension roll steer**: every axle is a body on a heave slide, a roll
  hinge and a yaw hinge that an equality ties to the roll (:data:`ROLL_STEER`);
- **steering**: knuckles on kingpins with caster trail, the left one turned by
  the column, the right one by the tie rod of an Ackermann trapezoid solved
  here from the vehicle file's track, wheelbase and steering arm.

Tyres are not MuJoCo contacts: the compiled loop applies them
(``_truth_c.c``, ``artic_yard_advance``). The yard's slope tilts gravity.
"""

from __future__ import annotations

import dataclasses
import math

import mujoco
import numpy as np

from artic.mjcf.compiling import compile_spec
from artic.mjcf.errors import UnsupportedVehicleError
from artic.mjcf.vehicle import Vehicle

G = 9.81

TIMESTEP = 2.5e-3
"""The yard truth's step [s] (``docs/design/truth.md``: its loop is MuJoCo's
semi-implicit Euler with the tyres' and column's forces explicit; every
linearised mode of the truth lies inside that scheme's stability region at 2.5 ms,
four steps per 10 ms sample)."""

FRAME_TORSION = math.degrees(3000.0)
"""Torsional stiffness of the tractor's frame between its axles [N m/rad]:
3 kN m/deg, a ladder frame's (heavy-truck frames are 1-5 kN m/deg)."""

FRAME_TORSION_DAMPING = 8000.0
"""Damping of the frame's torsion [N m s/rad]: a damping ratio near 0.1 against the
front end's roll inertia."""

FRAME_HINGE = 0.55
"""Where the frame twists, as a share of the wheelbase ahead of the drive axle [-]."""

CAB_MASS = 1100.0
"""The cab's mass [kg] (part of the tractor's m1): a sleeper cab's."""

CAB_ROLL_STIFFNESS = 1.2e5
"""The cab mounts' roll stiffness [N m/rad]: about 1.5 Hz in roll, an air-sprung cab's."""

CAB_PITCH_STIFFNESS = 2.0e5
"""The cab mounts' pitch stiffness [N m/rad]."""

CAB_DAMPING = 8000.0
"""The cab mounts' roll and pitch damping [N m s/rad]."""

FIFTH_WHEEL_LASH = math.radians(1.0)
"""Total roll lash of the fifth-wheel plate in its bushes [rad]."""

FIFTH_WHEEL_ROLL = 4.0e6
"""Roll stiffness of the fifth wheel's bushes past the lash [N m/rad]."""

FIFTH_WHEEL_ROLL_DAMPING = 4.0e4
"""Roll damping of the fifth wheel's bushes [N m s/rad]."""

ROLL_STEER = {"front": 0.10, "drive": 0.06, "trailer": 0.03}
"""Roll steer of each kind of axle [rad of axle yaw per rad of axle roll against the
frame], understeering: the front axle on leaf springs, the drive axle on trailing
links, the semitrailer's axles on trailing arms."""

ANTI_ROLL = {"front": 6.0e5, "drive": 1.2e6, "trailer": 7.0e5}
"""Roll stiffness per axle against its frame, from its springs' spread and anti-roll
bar [N m/rad]: heavy-truck axles have 0.5-2 MN m/rad."""

ROLL_DAMPING = 3.0e4
"""Roll damping of each axle against its frame [N m s/rad]."""

KNUCKLE_INERTIA = 18.0
"""Inertia about the kingpin of each knuckle with its wheel, brake and the share
of the steering gear it drives [kg m^2]."""

KINGPIN_LIMIT = 0.95
"""The knuckles' stops [rad]: past any lock the column reaches."""

BRAKE_SOLIMP = [0.999, 0.9999, 0.001, 0.5, 2.0]
"""The brakes' (the spin joints' friction) constraint impedance: near 1, a dry
friction that holds (MuJoCo's default 0.9-0.95 lets a braked wheel creep at a
speed proportional to its torque)."""

TWIN_SPACING = 0.35
"""Centre distance of twin tyres [m]."""


@dataclasses.dataclass(frozen=True)
class Layout:
    """Names and indices of the built model that the truth's loop reads."""

    ends: tuple[dict, ...]
    steer_l: int
    steer_r: int
    fifth_roll: int
    hitch: int
    drive_site: int
    drive_body: int
    sensor_sites: tuple[int, int]
    free_joint: int
    mass: float
    weight_shares: tuple[float, ...]


def static_loads(v: Vehicle) -> dict[str, float]:
    """Each axle's static load [N] on level ground (trailer axles share their group's evenly)."""
    trailer = v.trailer_axles
    # kingpin load: moment of the semitrailer about its axle group's centre
    xg = sum(a.x for a in trailer) / len(trailer)
    w2 = v.m2 * G
    wk = w2 * (-xg - v.a2) / (-xg)
    out = {a.name: (w2 - wk) / len(trailer) for a in trailer}
    front = next(a for a in v.tractor_axles if a.steered)
    drive = [a for a in v.tractor_axles if not a.steered]
    w1 = v.m1 * G
    f_front = (w1 * v.b1 + wk * v.L1c) / v.L1
    out[front.name] = f_front
    for a in drive:
        out[a.name] = (w1 + wk - f_front) / len(drive)
    return out


def trapezoid(track: float, wheelbase: float, arm: float) -> tuple[float, float]:
    """The Ackermann trapezoid's arm angle ``beta`` [rad] and rod length [m].

    The steering arms point back and inward so that their lines meet at the
    rear axle's centre: ``tan(beta) = (track / 2) / wheelbase``; the rod joins
    their tips.
    """
    beta = math.atan2(0.5 * track, wheelbase)
    return beta, track - 2.0 * arm * math.sin(beta)


def ackermann_right(delta_l: float, track: float, wheelbase: float) -> float:
    """The right wheel's angle [rad] that the exact Ackermann condition gives for the left's."""
    if abs(delta_l) < 1e-12:
        return 0.0
    return math.atan(1.0 / (1.0 / math.tan(delta_l) + track / wheelbase))


def _box(mass: float, ixx: float, iyy: float, izz: float) -> list[float]:
    """Principal inertias [kg m^2]: at least 1e-3 of the mass, none above the other two's sum.

    A rigid body's principal moments obey the triangle inequality (``A + B >= C``:
    ``A + B - C = 2 * int(z^2 dm)``); a drawn truck whose yaw budget leaves a
    frame half little yaw and pitch inertia would otherwise be given a roll
    inertia no body has, which MuJoCo refuses. Such a moment is lowered to the
    sum of the other two (a body flat in that axis).
    """
    moments = [max(ixx, 1e-3 * mass), max(iyy, 1e-3 * mass), max(izz, 1e-3 * mass)]
    for k in range(3):
        moments[k] = min(moments[k], moments[(k + 1) % 3] + moments[(k + 2) % 3])
    return moments


def build(v: Vehicle, tyre_radius: dict[str, float], timestep: float = TIMESTEP
          ) -> tuple[mujoco.MjModel, Layout]:
    """The truth's model of vehicle ``v`` and the layout its loop reads.

    Parameters
    ----------
    v : Vehicle
        The truth's vehicle (the truth's masses, geometry and yard slope).
    tyre_radius : dict
        Each axle's unloaded tyre radius [m], by axle name.
    timestep : float
        MuJoCo's step [s].
    """
    spec = mujoco.MjSpec()
    spec.modelname = "artic-yard-truth"
    spec.compiler.degree = False  # every angle here is in radians
    spec.option.timestep = timestep
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    th, ph = v.plant.grade, v.plant.crossfall
    spec.option.gravity = [-G * math.sin(th), -G * math.cos(th) * math.sin(ph),
                           -G * math.cos(th) * math.cos(ph)]
    loads = static_loads(v)
    front = next(a for a in v.tractor_axles if a.steered)
    tractor_unsprung = sum(a.unsprung_mass for a in v.tractor_axles)
    trailer_unsprung = sum(a.unsprung_mass for a in v.trailer_axles)
    # ------------------------------------------------------------ tractor masses
    # The tractor's centre of gravity lies b1 ahead of the drive axle at h1. The
    # unsprung axles sit at their wheel centres, the cab above the front axle,
    # the two frame halves share what remains so that the whole meets (b1, h1).
    x_cg, z_cg = v.b1, v.h1
    cab_x, cab_z = front.x - 0.2, 2.1
    fifth_mass = 20.0
    un = [(a.unsprung_mass, a.x, tyre_radius[a.name]) for a in v.tractor_axles]
    m_frames = v.m1 - tractor_unsprung - CAB_MASS - fifth_mass
    if m_frames <= 0.2 * v.m1:
        raise UnsupportedVehicleError(f"{v.name}: tractor mass {v.m1:.0f} kg too small for its "
                                      "axles and cab in the yard truth's model")
    rest_x = (v.m1 * x_cg - sum(m * x for m, x, _ in un) - CAB_MASS * cab_x
              - fifth_mass * v.L1c) / m_frames
    rest_z = (v.m1 * z_cg - sum(m * z for m, _, z in un) - CAB_MASS * cab_z
              - fifth_mass * v.h5) / m_frames
    hinge_x = FRAME_HINGE * v.L1
    m_rear, m_front = 0.55 * m_frames, 0.45 * m_frames
    x_rear = x_front = rest_x  # the halves' centres together: the yaw inertia is tight
    # yaw inertia: what the point masses do not carry goes to the cab's and the
    # frames' own (the presets' J1 leaves little beyond the axles)
    j_points = (sum(m * (x - x_cg) ** 2 for m, x, _ in un) + CAB_MASS * (cab_x - x_cg) ** 2
                + fifth_mass * (v.L1c - x_cg) ** 2 + m_frames * (rest_x - x_cg) ** 2)
    j_budget = v.J1 - j_points
    if j_budget <= 0.0:
        raise UnsupportedVehicleError(f"{v.name}: tractor yaw inertia J1 = {v.J1:.0f} kg m^2 is "
                                      "below what its masses' positions carry in the yard "
                                      "truth's model")
    j_cab = min(CAB_MASS * (2.3 ** 2 + 2.5 ** 2) / 12.0, 0.4 * j_budget)
    j_rear = (j_budget - j_cab) * 0.55
    j_front = (j_budget - j_cab) * 0.45

    world = spec.worldbody
    rear = world.add_body(name="rear", pos=[0.0, 0.0, 0.0])
    rear.add_freejoint(name="root")
    rear.mass = m_rear
    rear.ipos = [x_rear, 0.0, rest_z]
    rear.inertia = _box(m_rear, m_rear * 0.45 ** 2, j_rear, j_rear)
    rear.add_site(name="drive", pos=[0.0, 0.0, 0.0])
    fr = rear.add_body(name="front", pos=[hinge_x, 0.0, rest_z])
    fr.add_joint(name="frame_torsion", type=mujoco.mjtJoint.mjJNT_HINGE, axis=[1, 0, 0],
                 stiffness=FRAME_TORSION, damping=FRAME_TORSION_DAMPING)
    fr.mass = m_front
    fr.ipos = [x_front - hinge_x, 0.0, 0.0]
    fr.inertia = _box(m_front, m_front * 0.45 ** 2, j_front, j_front)
    # the cab on its mounts: roll and pitch hinges under its centre of gravity
    cab = fr.add_body(name="cab", pos=[cab_x - hinge_x, 0.0, 1.4 - rest_z])
    for name, axis, k in (("cab_roll", [1, 0, 0], CAB_ROLL_STIFFNESS),
                          ("cab_pitch", [0, 1, 0], CAB_PITCH_STIFFNESS)):
        cab.add_joint(name=name, type=mujoco.mjtJoint.mjJNT_HINGE, axis=axis, stiffness=k,
                      damping=CAB_DAMPING)
    cab.mass = CAB_MASS
    cab.ipos = [0.0, 0.0, cab_z - 1.4]
    cab.inertia = _box(CAB_MASS, CAB_MASS * (2.5 ** 2 + 2.2 ** 2) / 12.0,
                       CAB_MASS * (2.3 ** 2 + 2.2 ** 2) / 12.0, j_cab)
    fr.add_site(name="sensor1", pos=[v.sensor1[0] - hinge_x, v.sensor1[1],
                                               v.sensor1[2] - rest_z])
    # ------------------------------------------------------------ fifth wheel, trailer
    fifth = rear.add_body(name="fifth", pos=[v.L1c, 0.0, v.h5])
    fifth.add_joint(name="fifth_pitch", type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0, 1, 0],
                    range=[-v.hitch_pitch, v.hitch_pitch], damping=2000.0)
    fifth.add_joint(name="fifth_roll", type=mujoco.mjtJoint.mjJNT_HINGE, axis=[1, 0, 0],
                    armature=5.0)
    fifth.mass = fifth_mass
    fifth.inertia = [5.0, 5.0, 8.0]
    trailer = fifth.add_body(name="trailer", pos=[0.0, 0.0, 0.0])
    trailer.add_joint(name="kingpin", type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0, 0, 1],
                      frictionloss=v.plant.fifth_wheel_friction, damping=50.0)
    dy = v.plant.payload_offset[1]
    mb = v.m2 - trailer_unsprung
    # the semitrailer's centre of gravity a2 behind the kingpin at h2: its body's
    # centre so that the axles with it meet that
    bx = (v.m2 * -v.a2 - sum(a.unsprung_mass * a.x for a in v.trailer_axles)) / mb
    bz = (v.m2 * v.h2 - sum(a.unsprung_mass * tyre_radius[a.name]
                            for a in v.trailer_axles)) / mb
    j2_points = (sum(a.unsprung_mass * (a.x + v.a2) ** 2 for a in v.trailer_axles)
                 + mb * (bx + v.a2) ** 2)
    j2_own = v.J2 - j2_points
    if j2_own <= 0.0:
        raise UnsupportedVehicleError(f"{v.name}: semitrailer yaw inertia J2 below what its "
                                      "axles carry")
    trailer.mass = mb
    trailer.ipos = [bx, dy * v.m2 / mb, bz - v.h5]
    trailer.inertia = _box(mb, mb * 0.8 ** 2, j2_own, j2_own)
    trailer.add_site(name="sensor2", pos=[v.sensor2[0], v.sensor2[1],
                                                    v.sensor2[2] - v.h5])
    # ------------------------------------------------------------ axles
    ends: list[dict] = []
    driven = [a for a in v.axles if a.driven]
    total_w = sum(loads.values())
    for a in v.axles:
        kind = "front" if a.steered else ("drive" if a.unit == 1 else "trailer")
        r0 = tyre_radius[a.name]
        if a.unit == 1:
            parent = fr if a.steered else rear
            origin = [a.x - (hinge_x if a.steered else 0.0), 0.0,
                      r0 - (rest_z if a.steered else 0.0)]
        else:
            parent, origin = trailer, [a.x, 0.0, r0 - v.h5]
        # the spring's free length: at the design height (q = 0) it carries the
        # axle's static sprung load, pushing the axle down and the frame up
        sprung = loads[a.name] - a.unsprung_mass * G
        body = parent.add_body(name=f"axle.{a.name}", pos=origin)
        body.add_joint(name=f"heave.{a.name}", type=mujoco.mjtJoint.mjJNT_SLIDE, axis=[0, 0, 1],
                       stiffness=a.suspension_stiffness, damping=a.suspension_damping,
                       springref=-sprung / a.suspension_stiffness)
        body.add_joint(name=f"roll.{a.name}", type=mujoco.mjtJoint.mjJNT_HINGE, axis=[1, 0, 0],
                       stiffness=ANTI_ROLL[kind], damping=ROLL_DAMPING)
        body.add_joint(name=f"yaw.{a.name}", type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0, 0, 1],
                       damping=1.0e4)
        # understeer: the front axle yaws out of the turn, the rear ones into it
        sign = 1.0 if a.steered else -1.0
        poly = np.zeros(mujoco.mjNEQDATA)
        poly[1] = sign * ROLL_STEER[kind]  # yaw = c1 roll
        spec.add_equality(type=mujoco.mjtEq.mjEQ_JOINT, objtype=mujoco.mjtObj.mjOBJ_JOINT,
                          name1=f"yaw.{a.name}", name2=f"roll.{a.name}", data=poly)
        wheel_mass = 0.3 * a.unsprung_mass
        body.mass = a.unsprung_mass - 2.0 * wheel_mass
        body.inertia = _box(body.mass, body.mass * a.track ** 2 / 12.0, 10.0,
                            body.mass * a.track ** 2 / 12.0)
        for side, sy in (("L", 1.0), ("R", -1.0)):
            hub_parent = body
            if a.steered:
                hub_parent = body.add_body(name=f"knuckle.{side}", pos=[0.0, sy * 0.5 * a.track,
                                                                         0.0])
                hub_parent.add_joint(name=f"steer.{side}", type=mujoco.mjtJoint.mjJNT_HINGE,
                                     axis=[0, 0, 1], range=[-KINGPIN_LIMIT, KINGPIN_LIMIT],
                                     armature=KNUCKLE_INERTIA)
                hub_parent.mass = 1.0
                hub_parent.inertia = [0.1, 0.1, 0.1]
                hub_pos = [0.0, 0.0, 0.0]
            else:
                hub_pos = [0.0, sy * 0.5 * a.track, 0.0]
            hub_parent.add_site(name=f"hub.{a.name}.{side}", pos=hub_pos)
            wheel = hub_parent.add_body(name=f"wheel.{a.name}.{side}", pos=hub_pos)
            # the brakes are dry friction on the spin (set as the pedal asks); near-hard,
            # so that a braked truck stands instead of creeping on the solver's softness
            wheel.add_joint(name=f"spin.{a.name}.{side}", type=mujoco.mjtJoint.mjJNT_HINGE,
                            axis=[0, 1, 0], solimp_friction=BRAKE_SOLIMP)
            wheel.mass = wheel_mass
            wheel.inertia = [0.6 * a.wheel_inertia, a.wheel_inertia, 0.6 * a.wheel_inertia]
            ends.append({"axle": a.name, "side": side, "dual": a.dual, "steered": a.steered,
                         "drive_share": (1.0 / (2 * len(driven))) if a.driven else 0.0,
                         "brake_share": loads[a.name] / (2.0 * total_w)})
    for b in spec.bodies:  # every inertia about its body's origin unless set above
        if b.name not in ("rear", "front", "cab", "trailer") and b.name != "world":
            b.ipos = [0.0, 0.0, 0.0]
            b.iquat = [1.0, 0.0, 0.0, 0.0]
    model = compile_spec(spec)
    for e in ends:
        e["hub_site"] = model.site(f"hub.{e['axle']}.{e['side']}").id
        spin = model.joint(f"spin.{e['axle']}.{e['side']}")
        e["wheel_body"] = int(spin.bodyid[0])
        e["spin_dof"] = int(model.jnt_dofadr[spin.id])
        e["hub_body"] = int(model.site_bodyid[e["hub_site"]])
        if e["steered"]:
            e["steer_dof"] = int(model.jnt_dofadr[model.joint(f"steer.{e['side']}").id])
    sl, sr = model.joint("steer.L").id, model.joint("steer.R").id
    layout = Layout(
        ends=tuple(ends), steer_l=sl, steer_r=sr,
        fifth_roll=int(model.jnt_dofadr[model.joint("fifth_roll").id]),
        hitch=model.joint("kingpin").id, drive_site=model.site("drive").id,
        drive_body=model.body("rear").id,
        sensor_sites=(model.site("sensor1").id, model.site("sensor2").id),
        free_joint=model.joint("root").id, mass=float(v.m1 + v.m2),
        weight_shares=tuple(e["brake_share"] for e in ends))
    return model, layout
