"""The Warp plant's per-step kernels: steering and speed control, the divergence check, the sensors.

:class:`Tables` holds, on the device, what :class:`artic.plant.warp_plant.WarpPlant`
needs around MuJoCo Warp's step, one row per world:

- :func:`control_kernel`, before the step: the steering servo's command limited
  to the linkage, and the speed follower's set-point or the driver's drive and
  brake torques, as :meth:`artic.plant.Plant._control` computes them (sampled
  once per call, at the middle of the interval);
- :func:`check_kernel`, after it: a world whose state is not finite, or beyond
  MuJoCo's ``mjMAXVAL``, is marked failed with its last sound time and put back
  to the state before the step; a failed world stays there;
- :func:`observe_kernel`: the 13 signals of :meth:`artic.plant.Plant.observe`.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import warp as wp

from artic.mjcf.vehicle import G
from artic.plant.plant import BRAKE_SPIN_SCALE, FOLLOW_KI, SPEED_KI, SPEED_KP
from artic.plant.warp_tyre import gather

MAX_VALUE = 1e10
"""Largest state magnitude a sound world has (MuJoCo's ``mjMAXVAL``)."""

_FOLLOW_KI = wp.constant(FOLLOW_KI)
_KP = wp.constant(SPEED_KP)
_KI = wp.constant(SPEED_KI)
_BRAKE_SPIN = wp.constant(BRAKE_SPIN_SCALE)
_MAX = wp.constant(MAX_VALUE)
_PI = wp.constant(3.14159265358979323846)


@wp.struct
class Actuation:
    """The actuators the controls set, and each world's constants for them.

    ``tractor``: the tractor's body (its forward speed is followed); ``servo``: the
    steering servos, ``servo_range`` per world their command's range [rad];
    ``follower``: the speed follower; ``drive``, ``brake``: the drive and brake
    motors, ``spin_dof`` the spin dofs the brakes act on and ``brake_share`` per
    world each brake's share; ``consts`` per world the mass [kg], the effective
    mass [kg], the follower's gain [N s/m], the rolling resistance [N] and the
    driven wheels' radius [m].
    """

    tractor: int
    servo: wp.array(dtype=int)
    servo_range: wp.array2d(dtype=float)
    follower: int
    drive: wp.array(dtype=int)
    brake: wp.array(dtype=int)
    spin_dof: wp.array(dtype=int)
    consts: wp.array2d(dtype=float)
    brake_share: wp.array2d(dtype=float)


@wp.struct
class ControlState:
    """Per world, the controllers' state and the failures.

    The speed controller's integral [m], the steps whose steering the linkage
    limited, whether the world failed (1), and its last sound time [s].
    """

    integral: wp.array(dtype=float)
    steer_limited: wp.array(dtype=int)
    failed: wp.array(dtype=int)
    fail_time: wp.array(dtype=float)


@wp.kernel
def control_kernel(span: float, mode: int, command: wp.array2d(dtype=float),
                   xmat: wp.array2d(dtype=wp.mat33), qvel: wp.array2d(dtype=float),
                   actuation: Actuation, state: ControlState, ctrl: wp.array2d(dtype=float)):
    """The steering and speed controls of world ``w`` (``Plant.step`` and ``Plant._control``)."""
    w = wp.tid()
    if state.failed[w] != 0:
        return
    delta = command[w, 0]
    u_dot = command[w, 2]
    u_cmd = command[w, 1] + u_dot * 0.5 * span
    lo = actuation.servo_range[w, 0]
    hi = actuation.servo_range[w, 1]
    if delta < lo or delta > hi:
        state.steer_limited[w] = state.steer_limited[w] + 1
    dc = wp.min(wp.max(delta, lo), hi)
    for s in range(actuation.servo.shape[0]):
        ctrl[w, actuation.servo[s]] = dc
    R = xmat[w, actuation.tractor]
    u = R[0, 0] * qvel[w, 0] + R[1, 0] * qvel[w, 1] + R[2, 0] * qvel[w, 2]
    e = u_cmd - u
    state.integral[w] = state.integral[w] + e * span
    mass = actuation.consts[w, 0]
    mass_eff = actuation.consts[w, 1]
    kv = actuation.consts[w, 2]
    R0 = actuation.consts[w, 4]
    rr = actuation.consts[w, 3] * wp.tanh(u_cmd / 0.1)
    if mode == 0:
        ff = mass_eff * u_dot + rr
        ctrl[w, actuation.follower] = u_cmd + ff / kv + _FOLLOW_KI * state.integral[w]
        return
    F = mass * (u_dot + _KP * e + _KI * state.integral[w]) + rr
    direction = 1.0
    if wp.abs(u_cmd) > 0.05:
        if u_cmd < 0.0:
            direction = -1.0
    elif F < 0.0:
        direction = -1.0
    for i in range(actuation.brake.shape[0]):
        ctrl[w, actuation.brake[i]] = 0.0
    for i in range(actuation.drive.shape[0]):
        ctrl[w, actuation.drive[i]] = 0.0
    if F * direction >= 0.0:
        for i in range(actuation.drive.shape[0]):
            ctrl[w, actuation.drive[i]] = F * R0 / float(actuation.drive.shape[0])
    else:
        for i in range(actuation.brake.shape[0]):
            ctrl[w, actuation.brake[i]] = (-wp.abs(F) * R0 * actuation.brake_share[w, i]
                                           * wp.tanh(qvel[w, actuation.spin_dof[i]]
                                                     / _BRAKE_SPIN))


@wp.kernel
def save_kernel(qpos: wp.array2d(dtype=float), qvel: wp.array2d(dtype=float),
                act: wp.array2d(dtype=float), time: wp.array(dtype=float),
                qpos_0: wp.array2d(dtype=float), qvel_0: wp.array2d(dtype=float),
                act_0: wp.array2d(dtype=float), time_0: wp.array(dtype=float)):
    """Keep world ``w``'s state before the step."""
    w = wp.tid()
    for j in range(qpos.shape[1]):
        qpos_0[w, j] = qpos[w, j]
    for j in range(qvel.shape[1]):
        qvel_0[w, j] = qvel[w, j]
    for j in range(act.shape[1]):
        act_0[w, j] = act[w, j]
    time_0[w] = time[w]


@wp.func
def sound(x: float):
    """Whether ``x`` is finite and within MuJoCo's largest value."""
    return wp.isfinite(x) and wp.abs(x) < _MAX


@wp.kernel
def check_kernel(qpos: wp.array2d(dtype=float), qvel: wp.array2d(dtype=float),
                 act: wp.array2d(dtype=float), time: wp.array(dtype=float),
                 qpos_0: wp.array2d(dtype=float), qvel_0: wp.array2d(dtype=float),
                 act_0: wp.array2d(dtype=float), time_0: wp.array(dtype=float),
                 state: ControlState):
    """Mark world ``w`` failed if its state is not sound, and hold a failed world."""
    w = wp.tid()
    ok = state.failed[w] == 0
    if ok:
        for j in range(qpos.shape[1]):
            if not sound(qpos[w, j]):
                ok = False
        for j in range(qvel.shape[1]):
            if not sound(qvel[w, j]):
                ok = False
        for j in range(act.shape[1]):
            if not sound(act[w, j]):
                ok = False
        if not ok:
            state.failed[w] = 1
            state.fail_time[w] = time_0[w]
    if not ok:
        for j in range(qpos.shape[1]):
            qpos[w, j] = qpos_0[w, j]
        for j in range(qvel.shape[1]):
            qvel[w, j] = qvel_0[w, j]
        for j in range(act.shape[1]):
            act[w, j] = act_0[w, j]
        time[w] = time_0[w]


@wp.func
def wrap(a: float):
    """The angle ``a`` [rad] in [-pi, pi)."""
    return a - 2.0 * _PI * wp.floor((a + _PI) / (2.0 * _PI))


@wp.struct
class Frames:
    """What the sensors read of the data: MuJoCo Warp's data fields of the same names."""

    xmat: wp.array2d(dtype=wp.mat33)
    site_xpos: wp.array2d(dtype=wp.vec3)
    site_xmat: wp.array2d(dtype=wp.mat33)
    cvel: wp.array2d(dtype=wp.spatial_vector)
    subtree_com: wp.array2d(dtype=wp.vec3)


@wp.struct
class Sensors:
    """The two inertial units, where they sit and how they read.

    The model's ``site_bodyid`` and ``body_rootid``, the units' sites, the units'
    bodies (tractor, semitrailer), and per world each unit's yaw misalignment [rad].
    """

    site_bodyid: wp.array(dtype=int)
    body_rootid: wp.array(dtype=int)
    site: wp.array(dtype=int)
    unit_body: wp.array(dtype=int)
    yaw: wp.array2d(dtype=float)


@wp.kernel
def observe_kernel(frames: Frames, sensors: Sensors, psi: wp.array2d(dtype=float),
                   signals: wp.array2d(dtype=float)):
    """World ``w``'s 13 signals, as ``Plant.observe`` (headings unwrapped against ``psi``)."""
    w = wp.tid()
    for k in range(2):
        R = frames.xmat[w, sensors.unit_body[k]]
        heading = wp.atan2(R[1, 0], R[0, 0])
        heading = psi[w, k] + wrap(heading - psi[w, k])
        psi[w, k] = heading
        site = sensors.site[k]
        pos = frames.site_xpos[w, site]
        body = sensors.site_bodyid[site]
        cv = frames.cvel[w, body]
        om = wp.spatial_top(cv)
        com = frames.subtree_com[w, sensors.body_rootid[body]]
        lin = wp.spatial_bottom(cv) + wp.cross(om, pos - com)
        S = frames.site_xmat[w, site]
        lin_l = wp.transpose(S) * lin
        om_l = wp.transpose(S) * om
        vx = lin_l[0]
        vy = lin_l[1]
        eps = sensors.yaw[w, k]
        if eps != 0.0:
            c = wp.cos(eps)
            s = wp.sin(eps)
            vx_ = c * vx + s * vy
            vy = -s * vx + c * vy
            vx = vx_
        signals[w, 6 * k + 0] = pos[0]
        signals[w, 6 * k + 1] = pos[1]
        signals[w, 6 * k + 2] = heading + eps
        signals[w, 6 * k + 3] = vx
        signals[w, 6 * k + 4] = vy
        signals[w, 6 * k + 5] = om_l[2]
    signals[w, 12] = wrap(signals[w, 2] - signals[w, 8])


@dataclasses.dataclass
class Tables:
    """The per-world controller state and constants on the device (module docstring)."""

    command: wp.array
    """Per world: ``delta`` [rad], ``u1`` [m/s], ``u1_dot`` [m/s^2] of the next step."""
    actuation: Actuation
    state: ControlState
    sensors: Sensors
    psi: wp.array
    """Per world, the two units' unwrapped headings [rad]."""
    signals: wp.array
    """Per world, the 13 signals of the last :meth:`observe`."""
    saved: tuple

    @classmethod
    def build(cls, plant, tyre_sets: list) -> Tables:
        """The tables of ``plant`` (a :class:`~artic.plant.warp_plant.WarpPlant`)."""
        n, hosts, var = plant.n_worlds, plant.hosts, plant._variant
        h0 = hosts[0]
        consts = np.array([[hosts[var[w]].mass, hosts[var[w]].mass_eff,
                            hosts[var[w]]._follower_kv,
                            tyre_sets[w][0].QSY1 * hosts[var[w]].mass * G, hosts[var[w]].R0]
                           for w in range(n)])
        m = plant.mj_model
        nq, nv, na = m.nq, m.nv, m.na

        def f32(x):
            return wp.array(np.asarray(x, dtype=np.float32), dtype=float)

        def i32(x):
            return wp.array(np.asarray(x, dtype=np.int32).ravel(), dtype=int)

        return cls(
            command=wp.zeros((n, 3), dtype=float),
            actuation=gather(
                Actuation, tractor=int(h0._tractor), servo=i32(h0._servo),
                servo_range=f32([hosts[var[w]]._servo_range for w in range(n)]),
                follower=int(h0._follower), drive=i32(h0._drive), brake=i32(h0._brake),
                spin_dof=i32(h0._spin_dof), consts=f32(consts),
                brake_share=f32([hosts[var[w]]._brake_share for w in range(n)])),
            state=gather(ControlState, integral=wp.zeros(n, dtype=float),
                         steer_limited=wp.zeros(n, dtype=int), failed=wp.zeros(n, dtype=int),
                         fail_time=wp.zeros(n, dtype=float)),
            sensors=gather(Sensors, plant.m, site=i32(h0._sensor),
                           unit_body=i32([h0._tractor, h0._trailer]),
                           yaw=f32([hosts[var[w]]._sensor_yaw for w in range(n)])),
            psi=wp.zeros((n, 2), dtype=float),
            signals=wp.zeros((n, 13), dtype=float),
            saved=(wp.zeros((n, nq), dtype=float), wp.zeros((n, nv), dtype=float),
                   wp.zeros((n, na), dtype=float), wp.zeros(n, dtype=float)))

    def reset(self, psi: np.ndarray) -> None:
        """Zero the controllers and the failures; ``psi`` the unwrapped headings [rad]."""
        self.state.integral.zero_()
        self.state.steer_limited.zero_()
        self.state.failed.zero_()
        self.state.fail_time.zero_()
        self.psi.assign(np.asarray(psi, dtype=np.float32))

    def before(self, plant, span: float) -> None:
        """Keep the state, and set the controls for a call of ``span`` [s]."""
        d = plant.d
        wp.launch(save_kernel, dim=plant.n_worlds, inputs=[d.qpos, d.qvel, d.act, d.time],
                  outputs=list(self.saved))
        wp.launch(control_kernel, dim=plant.n_worlds, inputs=[
            float(span), 0 if plant.speed_mode == "follow" else 1, self.command, d.xmat, d.qvel,
            self.actuation, self.state], outputs=[d.ctrl])

    def after(self, plant) -> None:
        """Check every world's state after the step (:func:`check_kernel`)."""
        d = plant.d
        wp.launch(check_kernel, dim=plant.n_worlds,
                  inputs=[d.qpos, d.qvel, d.act, d.time, *self.saved], outputs=[self.state])

    def observe(self, plant) -> None:
        """Write :attr:`signals` from the state now."""
        wp.launch(observe_kernel, dim=plant.n_worlds,
                  inputs=[gather(Frames, plant.d), self.sensors], outputs=[self.psi, self.signals])
