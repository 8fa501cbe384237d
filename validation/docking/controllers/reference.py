"""The reference docking controller: it follows the plan, segment by segment.

Reversing, it holds the semitrailer on the path through the articulation:
the errors of KIN's semitrailer axle from the path, ``z = (e_y2, e_psi2,
e_gamma)`` (offset, heading, and articulation from the path's), are fed
back through the LQR gains of KIN linearised about the path
(:mod:`artic.validation.docking.linear`), on top of the path's own steering::

    delta = delta_path - K(|u| dt) z

Written as a cascade, ``-K z`` is ``k_gamma (gamma - gamma_ref)`` with a
reference articulation ``gamma_ref = gamma_path - (k_y e_y2 + k_psi e_psi2) / k_gamma``:
the offset and heading ask for an articulation, and the steering holds it.
The gains are those of the discrete LQR over the distance travelled in one
sample, ``|u| dt``, tabulated over speed when a run starts and interpolated
at the measured speed (:class:`~artic.validation.docking.linear.GainSchedule`).

Forward, it follows the tractor's point the same way with ``z = (e_y1, e_psi1)``.

Speed: the task's cruising speed, slowing so that the speed could come to
zero at the end of the segment with half the actuator's deceleration, and
creeping at :data:`CREEP` over the last metres. At a cusp it stops, turns the
steering wheel to the next segment's angle at standstill, and sets off. On
the last segment the end is the dock face, by the rear's sensor (its nearer
corner, when askew): it asks for zero speed when the rear is as far from the
face as it will still roll, and is then done.

What it intends (``Command.horizon``): the prediction of its own closed
loop on its design model, the errors ``z`` propagated by KIN linearised
about the path under its gains (``Ad - Bd K`` per sample,
:meth:`~artic.validation.docking.linear.GainSchedule.closed_loop`) over
:data:`PREDICTION_STEPS` steps of :data:`PREDICTION_STEP`, at the commanded
speed, and laid onto the path as offsets from it. That, not the preview of
the path alone, is what an LQR expects of itself: where the tracked point
will go while the errors decay as the gains were designed to make them
decay, and so where the plant departs from the design model shows in the
recording as the plant leaving the horizon. It costs about 25 products of
4x4 matrices per sample. ``Command.reference`` is the path's points the
horizon is laid on: the tracked point's foot on the path now, then one per
prediction step.

Everything comes from the sensors and the vehicle file; the plant's state
is never read.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from artic.mjcf.errors import UserError
from artic.mjcf.interface import wrap_angle
from artic.validation.docking.controllers.base import Command, Controller, Observation, Task
from artic.validation.docking.linear import GainSchedule

CREEP = 0.15
"""Speed over the last metres of a segment [m/s]."""

STANDSTILL = 0.03
"""Measured speed below which the combination stands [m/s]."""

WINDOW = (2, 40)
"""Samples of the path searched behind and ahead of the last nearest one."""

MIN_SPEED = 0.3
"""Speed floor of the gain schedule [m/s]: at rest the gains of a crawl."""

PREDICTION_STEPS = 25
"""Steps of the closed-loop prediction given as the horizon (the MPC's number)."""

PREDICTION_STEP = 0.3
"""Its step [s]: 25 steps look 7.5 s ahead, as the MPC does."""


class ReferenceController(Controller):
    """Path follower on KIN's linearisation (see the module docstring)."""

    name = "reference"
    weights: tuple[tuple[float, ...], tuple[float, ...]] | None = None
    """LQR weights ``(reverse, forward)``; :mod:`artic.validation.docking.linear`'s by default."""

    def reset(self, task: Task) -> None:
        """Precompute each segment's reference: the tracked point's path, heading, articulation."""
        super().reset(task)
        if task.plan is None:
            raise UserError("the reference controller follows a plan; the run has none")
        fr = self.frames
        self.refs = []
        for seg in task.plan.segments:
            if seg.direction < 0:
                p = fr.trailer_axle(seg.states)
            else:
                p = seg.states[:, :3]
            s = np.r_[0.0, np.cumsum(np.hypot(*np.diff(p[:, :2], axis=0).T))]
            self.refs.append((seg.direction, p, seg.states[:, 3], seg.delta, s))
        w = self.weights or (None, None)
        self.schedule = {-1: GainSchedule(fr.kin, -1, task.dt, w[0]),
                         1: GainSchedule(fr.kin, 1, task.dt, w[1])}
        self.k = 0
        self.i = 0
        self.waiting = False
        self.delta: float | None = None
        self.now: tuple | None = None
        # The road-wheel rate the steering wheel allows [rad/s], from the vehicle's map.
        self.delta_rate = task.steer_rate / self.steering.i_s

    def _point(self, obs: Observation, direction: int) -> np.ndarray:
        if direction < 0:
            return self.frames.trailer_axle_of_signals(obs.signals)
        kin = self.frames.kin_of_signals(obs.signals)
        return kin[:3]

    def _turn(self, target: float) -> float:
        """Move the commanded road-wheel angle towards ``target`` at the actuator's rate."""
        step = self.delta_rate * self.task.dt
        d = self.vehicle.steering.delta_max
        self.delta = min(max(self.delta + min(max(target - self.delta, -step), step), -d), d)
        return self.steering_wheel(self.delta)

    def command(self, obs: Observation) -> Command:
        """Steer onto the current segment's path; manage speed, cusps and the stop.

        The command carries the closed-loop prediction and the path it is laid
        on (see the module docstring).
        """
        return self._intent(self._follow(obs))

    def _intent(self, cmd: Command) -> Command:
        """``cmd`` with the closed-loop prediction and its path, where it follows one."""
        if self.now is None:
            return cmd
        d, p, s, here, z = self.now
        return dataclasses.replace(cmd, horizon=self._prediction(d, p, s, here, z, abs(cmd.u1)),
                                   reference=self._preview(p, s, here, abs(cmd.u1)))

    def _preview(self, p: np.ndarray, s: np.ndarray, here: float, speed: float) -> np.ndarray:
        """The path's points ``(x, y)`` at ``here`` and a prediction step apart at ``speed``.

        Only the point at ``here`` when the command stands still.
        """
        n = PREDICTION_STEPS + 1 if speed > 0.0 else 1
        travel = max(speed, MIN_SPEED) * PREDICTION_STEP
        at = np.clip(here + travel * np.arange(n), s[0], s[-1])
        return np.column_stack([np.interp(at, s, p[:, 0]), np.interp(at, s, p[:, 1])])

    def _prediction(self, d: int, p: np.ndarray, s: np.ndarray, here: float, z: np.ndarray,
                    speed: float) -> np.ndarray | None:
        """The closed loop's predicted path of the tracked point ``(x, y)`` [m], now first.

        ``z`` is propagated by the design model under the gains at ``speed``
        (at least :data:`MIN_SPEED`, as the law's gains are) and its offset
        ``e_y`` laid off the path, to the left of its heading. ``None`` when
        the command stands still.
        """
        if speed <= 0.0:
            return None
        v = max(speed, MIN_SPEED)
        samples = max(1, round(PREDICTION_STEP / self.task.dt))
        step = self.schedule[d].closed_loop(v)
        M = step
        for _ in range(samples - 1):
            M = M @ step
        e_y = np.empty(PREDICTION_STEPS + 1)
        zk = z
        e_y[0] = zk[0]
        for k in range(1, PREDICTION_STEPS + 1):
            zk = M @ zk
            e_y[k] = zk[0]
        at = np.clip(here + v * samples * self.task.dt * np.arange(PREDICTION_STEPS + 1),
                     s[0], s[-1])
        psi = np.interp(at, s, p[:, 2])
        return np.column_stack([np.interp(at, s, p[:, 0]) - np.sin(psi) * e_y,
                                np.interp(at, s, p[:, 1]) + np.cos(psi) * e_y])

    def _limit(self, z: np.ndarray, direction: int, gamma_path: float,
               K: np.ndarray) -> np.ndarray:
        """The errors the gains act on; the reference's are the measured ones.

        A subclass may limit what they ask for (see
        :class:`~artic.validation.docking.controllers.adaptive.AdaptiveReferenceController`).
        """
        return z

    def _follow(self, obs: Observation) -> Command:
        """The reference's command, without what it intends; keeps ``now`` for that."""
        self.now = None
        if self.delta is None:  # start from where the wheel is
            self.delta = self.road_wheel(obs.delta_h)
        v_meas = abs(obs["v_x_1"])
        if self.waiting:
            nxt = self.refs[self.k + 1]
            if v_meas >= STANDSTILL or abs(self.delta - float(nxt[3][0])) > 1e-3:
                # Stop, and turn the wheel to the next segment's angle at standstill.
                return Command(self._turn(float(nxt[3][0])), 0.0)
            self.k, self.i, self.waiting = self.k + 1, 0, False
        d, p, g_ref, d_ref, s = self.refs[self.k]
        last = self.k == len(self.refs) - 1
        me = self._point(obs, d)
        lo, hi = max(0, self.i - WINDOW[0]), min(len(p), self.i + WINDOW[1])
        dist2 = (p[lo:hi, 0] - me[0]) ** 2 + (p[lo:hi, 1] - me[1]) ** 2
        self.i = i = lo + int(np.argmin(dist2))
        psi_ref = float(p[i, 2])
        c, sn = math.cos(psi_ref), math.sin(psi_ref)
        dx, dy = me[0] - p[i, 0], me[1] - p[i, 1]
        e_y = -sn * dx + c * dy
        # How far along the path the point is: its offset from the nearest
        # sample along the path's heading, which the travel follows forward
        # and runs against in reverse.
        here = float(s[i]) + d * (c * dx + sn * dy)
        e_psi = float(wrap_angle(float(me[2]) - psi_ref))
        ds = max(v_meas, MIN_SPEED) * self.task.dt
        K = self.schedule[d](max(v_meas, MIN_SPEED))
        err = self.delta - float(np.interp(here, s, d_ref))
        if d < 0:
            z = np.array([e_y, e_psi, obs["gamma"] - float(np.interp(here, s, g_ref)), err])
        else:
            z = np.array([e_y, e_psi, err])
        z = self._limit(z, d, float(np.interp(here, s, g_ref)), K)
        self.now = (d, p, s, here, z)
        # The path's own steering where the point will be after this sample, plus the correction.
        target = float(np.interp(here + ds, s, d_ref)) + err - ds * float(K @ z)
        wheel = self._turn(target)
        # Distance left: to the face by the rear's sensor on the last segment.
        if last:
            # The rear's nearer corner touches first when the semitrailer is askew.
            dist, _, head = self.dock_errors(obs)
            remaining = dist - float(self.frames.trailer_box[2]) * abs(math.sin(head))
        else:
            remaining = float(s[-1]) - here
        a = 0.5 * self.task.accel_max
        v = min(self.task.speed, CREEP + math.sqrt(2.0 * a * max(remaining - 0.5, 0.0)))
        stop_at = v_meas * v_meas / (2.0 * self.task.accel_max) + 0.5 * v_meas * self.task.dt
        if remaining <= stop_at:
            if last:
                return Command(wheel, 0.0, done=True)
            self.waiting = True
            return Command(wheel, 0.0)
        return Command(wheel, d * v)
