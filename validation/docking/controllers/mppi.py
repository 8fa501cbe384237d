"""Sampling model-predictive docking controllers (MPPI) on KIN and on the STM.

Model-predictive path integral control: every sample it draws :data:`SAMPLES`
steering sequences about the last one, rolls them all out on the design
model in one compiled call (:meth:`artic.reduced.control.KIN.rollout` with a
batch of input sequences), scores each, and steers by their average weighted
by ``exp(-(cost - least cost) / lambda)``. The temperature ``lambda`` is
:data:`TEMPERATURE` times the spread of the costs (their median less the
least), so that the weighting does not depend on the cost's scale.

Same plan, same segments, same speed and stops as the reference controller
(:mod:`artic.validation.docking.controllers.reference`), as the MPCs
(:mod:`artic.validation.docking.controllers.mpc`): only the reversing
steering differs, and the semitrailer's rear reaches the dock along the
planner's last segment. A sequence holds a road-wheel angle over each of
:data:`HORIZON` steps of :data:`STEP` [s] (5 s ahead), and its cost is

    sum_k  q_y e_y2,k^2 + q_psi e_psi2,k^2 + q_gamma e_gamma,k^2
           + q_delta (delta_k - delta_path,k)^2 + r (delta_k - delta_k-1)^2
    + (TERMINAL - 1) q_y e_y2,HORIZON^2
    + COLLISION_COST (2 - k_hit / HORIZON)   where an outline first touches an obstacle
    + GAMMA_COST sum_k max(0, |gamma_k| - GAMMA_SOFT)^2
    + COLLISION_COST                         where |gamma_k| passes GAMMA_HARD

with the reference controller's Bryson weights
(:data:`artic.validation.docking.linear.REVERSE_WEIGHTS`, the rate's per
metre turned into per step at the commanded speed, at least
:data:`~artic.validation.docking.controllers.reference.MIN_SPEED`'s), as the
MPCs have them. The prediction drives at the commanded speed as far as the
segment's end and stands there (the run stops there; driving on, it would
find the dock in its way), and the semitrailer axle's predicted errors are
taken after the offset between where its own sensor puts it and where the
design model's state does (a model's bias, taken off each step).
The collision test is the run's own (:func:`artic.validation.docking.geometry.first_hits`,
the outlines' boxes against the obstacles), on obstacles grown by
:data:`MARGIN` (all but the dock, whose face the rear must reach): the
prediction is a model's, so it keeps a margin.

The samples are drawn as random walks of the steering about the last
solution (a first increment of standard deviation :data:`NOISE_FIRST`, then
:data:`NOISE` per step), each
increment held to what the actuator turns in a step and each angle to the
lock: a weighted average of such sequences keeps both limits. The last
solution itself and the path's own steering are two of the samples. The
generator is seeded per run (:data:`SEED`), so the same observations give
the same commands.

- ``mppi-kin`` predicts with KIN (4 states), 1 024 samples;
- ``mppi-stm`` with the STM (12 states for the tridem), 256 samples, each
  step in :data:`STM_SUBSTEPS` Runge-Kutta substeps of 0.1 s: its
  tyre-and-inertia modes near 17 rad/s need ``h |lambda| <= 2.8`` for RK4 to
  be stable (``mpc-stm`` takes 50 ms substeps for accuracy; a sampling
  controller averages over its samples' error instead).
"""

from __future__ import annotations

import math

import numpy as np

from artic.mjcf.interface import InitialState
from artic.validation.docking.controllers.base import Command, Observation, Task
from artic.validation.docking.controllers.reference import MIN_SPEED, ReferenceController
from artic.validation.docking.geometry import Box, box_array, first_hits
from artic.validation.docking.linear import REVERSE_WEIGHTS
from artic.validation.docking.planner import GAMMA_PLAN

HORIZON = 25
"""Prediction steps."""

STEP = 0.2
"""Prediction step [s]: 25 steps look 5 s ahead."""

STM_SUBSTEPS = 2
"""Runge-Kutta substeps of the STM's prediction step (see the module docstring)."""

SAMPLES = {"kin": 1024, "stm": 256}
"""Steering sequences drawn per sample, by design model."""

NOISE = math.radians(0.5)
"""Standard deviation of a sample's steering increment per prediction step [rad]."""

NOISE_FIRST = math.radians(2.0)
"""The same for its first step [rad]: a sample is mostly a new angle held, then
drifting. The steering's rate costs in every step a sample moves, so walks that
move every step cost more for their noise than a small tracking error does, and
the weighting would favour stillness over tracking."""

TEMPERATURE = 0.1
"""``lambda`` as a share of the costs' spread (median less least)."""

MARGIN = 0.2
"""Growth of the obstacles other than the dock in the prediction [m]."""

COLLISION_COST = 1e6
"""Cost of a sequence whose predicted outline touches an obstacle (more the sooner)."""

GAMMA_SOFT = GAMMA_PLAN
"""Articulation beyond which a prediction pays :data:`GAMMA_COST` [rad]: the planner's limit."""

GAMMA_COST = 1e5
"""Weight of the articulation beyond :data:`GAMMA_SOFT` [1/rad^2 per step]."""

GAMMA_HARD = 0.9
"""Share of the vehicle's ``gamma_max`` (jackknife) a prediction must not pass."""

TERMINAL = 10.0
"""Weight of the last step's offset from the path, in steps': within a horizon of
5 s the heading error a correction takes costs more than the offset it removes, so
the last step stands for the offset beyond the horizon."""

SEED = 0
"""The samples' seed, the same every run."""


def penalties(tractor: np.ndarray, trailer: np.ndarray, gamma: np.ndarray, boxes: np.ndarray,
              tractor_box: np.ndarray, trailer_box: np.ndarray,
              gamma_max: float) -> np.ndarray:
    """The collision and articulation-limit part of each sequence's cost.

    Parameters
    ----------
    tractor, trailer : ndarray, shape (batch, steps, 3)
        Drive-axle and kingpin poses ``(x, y, psi)`` of each predicted step [m, m, rad].
    gamma : ndarray, shape (batch, steps)
        Predicted articulation [rad].
    boxes : ndarray, shape (k, 4)
        Obstacles ``(cx, cy, hx, hy)`` [m] (:func:`~artic.validation.docking.geometry.box_array`).
    tractor_box, trailer_box : ndarray, shape (3,)
        The outlines, as :class:`~artic.validation.docking.geometry.Frames` gives them.
    gamma_max : float
        The vehicle's jackknife articulation [rad].

    Returns
    -------
    ndarray, shape (batch,)
        Zero for a sequence that stays clear and within :data:`GAMMA_SOFT`.
    """
    steps = gamma.shape[1]
    hit = first_hits(np.ascontiguousarray(tractor), np.ascontiguousarray(trailer),
                     tractor_box, trailer_box, boxes)
    cost = np.where(hit >= 0, COLLISION_COST * (2.0 - hit / steps), 0.0)
    excess = np.maximum(np.abs(gamma) - GAMMA_SOFT, 0.0)
    cost += GAMMA_COST * np.sum(excess * excess, axis=1)
    cost += np.where(np.any(np.abs(gamma) > GAMMA_HARD * gamma_max, axis=1), COLLISION_COST,
                     0.0)
    return cost


class MPPI(ReferenceController):
    """Sampling MPC of the reversing steering (see the module docstring)."""

    name = "mppi"
    design = "kin"

    def reset(self, task: Task) -> None:
        """Build the design model, the grown obstacles and the seeded generator."""
        super().reset(task)
        from artic.reduced.control import KIN, STM

        v = task.vehicle
        if self.design == "kin":
            self.model = KIN(v)
            self.substeps = 1
            self.offset = self.frames.x_ref  # the state's point ahead of the drive axle
        else:
            self.model = STM(v)
            self.substeps = STM_SUBSTEPS
            self.offset = v.b1  # the centre of gravity ahead of the drive axle
        self.samples = SAMPLES[self.design]
        self.i_delta = self.model.find_input("delta")
        self.i_u1 = self.model.find_input("u_1")
        self.i_gamma = self.model.find_state("gamma")
        self.boxes = box_array(tuple(
            b if b.name == "dock" else Box(b.name, b.x_min - MARGIN, b.x_max + MARGIN,
                                           b.y_min - MARGIN, b.y_max + MARGIN)
            for b in task.yard.obstacles))
        self.rng = np.random.default_rng(SEED)
        self.delta_traj: np.ndarray | None = None
        w = REVERSE_WEIGHTS
        self.q = (1.0 / w[0] ** 2, 1.0 / w[1] ** 2, 1.0 / w[2] ** 2, 1.0 / w[3] ** 2)
        self._warm_up()

    def _warm_up(self) -> None:
        """Load the compiled rollout and collision test from numba's cache before the run."""
        self.model.initial_state(InitialState(0.0, 0.0, 0.0, 0.0, v_y_1=0.0, r_1=0.0, r_2=0.0,
                                              u1=-1.0))
        x, _ = self.model.straight(-1.0)
        D = np.zeros((2, HORIZON))
        self._predict(np.asarray(x, dtype=float), D, -1.0)

    def _state(self, obs: Observation) -> np.ndarray:
        """The design model's state from the sensors (its ``initial_state`` of measured signals)."""
        return np.array(self.model.initial_state(
            InitialState(obs["x_1"], obs["y_1"], obs["psi_1"], obs["gamma"], v_y_1=obs["v_y_1"],
                         r_1=obs["r_1"], r_2=obs["r_2"], u1=obs["v_x_1"])), dtype=float)

    def _predict(self, x: np.ndarray, D: np.ndarray, u: float | np.ndarray) -> np.ndarray:
        """States at the prediction steps' ends ``(batch, HORIZON, n)`` of sequences ``D``.

        ``u`` is the speed [m/s], one or one per step.
        """
        m = self.substeps
        U = np.zeros((D.shape[0], D.shape[1] * m, self.model.ninputs))
        U[:, :, self.i_delta] = np.repeat(D, m, axis=1)
        U[:, :, self.i_u1] = np.repeat(np.broadcast_to(u, (D.shape[1],)), m)
        return self.model.rollout(x, U, STEP / m)[:, m::m]

    @staticmethod
    def _speeds(u: float, here: float, end: float) -> tuple[np.ndarray, np.ndarray]:
        """The prediction's speed per step and the path's position after each [m/s, m].

        The commanded speed until the segment's end, then as far as it is
        left, then standing: the run stops there, and a prediction that drove
        on would find the dock in its way.
        """
        ds = abs(u) * STEP
        at = here + ds * np.arange(1, HORIZON + 1)
        travel = np.clip(np.minimum(at, end) - (at - ds), 0.0, ds)
        return math.copysign(1.0, u) * travel / STEP, np.minimum(at, end)

    def _poses(self, X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Drive-axle and kingpin poses ``(..., 3)`` of design-model states ``(..., n)``."""
        psi1 = X[..., 2]
        c, s = np.cos(psi1), np.sin(psi1)
        xh = self.model._x_hitch
        tractor = np.stack([X[..., 0] - self.offset * c, X[..., 1] - self.offset * s, psi1],
                           axis=-1)
        trailer = np.stack([X[..., 0] + xh * c, X[..., 1] + xh * s, psi1 - X[..., 3]], axis=-1)
        return tractor, trailer

    def command(self, obs: Observation) -> Command:
        """The reference controller's, with the reversing steering from the samples."""
        before = self.delta
        cmd = self._follow(obs)
        d = self.refs[self.k][0]
        if d > 0 or self.waiting or cmd.done or cmd.u1 == 0.0 or before is None:
            self.delta_traj = None  # the next reversing stretch starts afresh
            return self._intent(cmd)
        self.delta = before  # the samples' steering instead of the LQR's
        return self._mppi(obs, cmd)

    def _samples(self, delta0: float, nominal: np.ndarray, path: np.ndarray) -> np.ndarray:
        """Steering sequences ``(SAMPLES, HORIZON)``: random walks about ``nominal``, limited."""
        n, N = HORIZON, self.samples
        step = self.delta_rate * STEP
        dmax = self.vehicle.steering.delta_max
        eps = self.rng.normal(0.0, 1.0, (N, n))
        eps[:, 0] *= NOISE_FIRST
        eps[:, 1:] *= NOISE
        eps[0] = 0.0  # the last solution itself
        base = np.broadcast_to(np.diff(np.r_[delta0, nominal]), (N, n)).copy()
        base[1] = np.diff(np.r_[delta0, path])  # the path's own steering
        D = np.empty((N, n))
        prev = np.full(N, delta0)
        for k in range(n):
            prev = np.clip(prev + np.clip(base[:, k] + eps[:, k], -step, step), -dmax, dmax)
            D[:, k] = prev
        return D

    def _mppi(self, obs: Observation, cmd: Command) -> Command:
        n = HORIZON
        _, p, g_ref, d_ref, s = self.refs[self.k]
        u = float(cmd.u1)
        ds = abs(u) * STEP
        me = self.frames.trailer_axle_of_signals(obs.signals)
        here = self.now[3]
        speeds, at = self._speeds(u, here, float(s[-1]))
        at = np.clip(at, s[0], s[-1])
        ref = np.column_stack([np.interp(at, s, p[:, j]) for j in range(3)])
        gam = np.interp(at, s, g_ref)
        dref = np.interp(at - ds, s, d_ref)
        delta0 = float(self.delta)
        if self.delta_traj is None:
            nominal = np.full(n, delta0)
        else:  # the last solution, a sample period on
            t = STEP * np.arange(n)
            nominal = np.interp(t + self.task.dt, t, self.delta_traj)
        D = self._samples(delta0, nominal, dref)
        x = self._state(obs)
        X = self._predict(x, D, speeds)
        # Where the semitrailer axle is by its own sensor, less where the design model's
        # state puts it: the offset the model's prediction carries, taken off each step.
        y0 = self.model.output(x)
        bias = (me[0] - y0[3], me[1] - y0[4], (me[2] - y0[5] + math.pi) % (2 * math.pi) - math.pi)
        cost = self._cost(X, D, delta0, ref, gam, dref, ds, bias)
        lam = TEMPERATURE * max(float(np.median(cost) - cost.min()), 1e-12)
        w = np.exp(-(cost - cost.min()) / lam)
        best = w @ D / w.sum()
        self.delta_traj = best
        wheel = self._turn(float(best[0]))
        # The predicted path of the semitrailer axle under the chosen steering, for the recording.
        Y = self.model.output(self._predict(x, best[None], speeds)[0])
        horizon = np.vstack([me[:2], Y[:, 3:5] + bias[:2]])
        foot = [np.interp(here, s, p[:, 0]), np.interp(here, s, p[:, 1])]
        return Command(wheel, cmd.u1, cmd.done, horizon, np.vstack([foot, ref[:, :2]]))

    def _cost(self, X: np.ndarray, D: np.ndarray, delta0: float, ref: np.ndarray,
              gam: np.ndarray, dref: np.ndarray, ds: float,
              bias: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> np.ndarray:
        """Each sequence's cost (see the module docstring): tracking, steering, penalties.

        ``bias`` is added to the predicted semitrailer axle ``(x, y, psi_2)``
        [m, m, rad] before its errors from the path are taken.
        """
        N, n, nx = X.shape
        Y = self.model.output(X.reshape(-1, nx)).reshape(N, n, -1)
        cr, sr = np.cos(ref[:, 2]), np.sin(ref[:, 2])
        e_y = (-sr * (Y[:, :, 3] + bias[0] - ref[:, 0])
               + cr * (Y[:, :, 4] + bias[1] - ref[:, 1]))
        e_p = np.remainder(Y[:, :, 5] + bias[2] - ref[:, 2] + math.pi, 2 * math.pi) - math.pi
        gamma = X[:, :, self.i_gamma]
        e_g = gamma - gam
        q = self.q
        # The rate's weight per metre, per step of ds, as the reference's gains
        # take it: at least MIN_SPEED's, so that the creep can still steer.
        r = 1.0 / (REVERSE_WEIGHTS[4] * max(ds, MIN_SPEED * STEP)) ** 2
        moves = np.diff(np.concatenate([np.full((N, 1), delta0), D], axis=1), axis=1)
        stage = q[0] * e_y ** 2 + q[1] * e_p ** 2 + q[2] * e_g ** 2
        cost = (np.sum(stage + q[3] * (D - dref) ** 2 + r * moves ** 2, axis=1)
                + (TERMINAL - 1.0) * q[0] * e_y[:, -1] ** 2)
        tractor, trailer = self._poses(X)
        return cost + penalties(tractor, trailer, gamma, self.boxes, self.frames.tractor_box,
                                self.frames.trailer_box, self.vehicle.gamma_max)


class MPPIKin(MPPI):
    """MPPI designed on KIN."""

    name = "mppi-kin"
    design = "kin"


class MPPIStm(MPPI):
    """MPPI designed on the STM."""

    name = "mppi-stm"
    design = "stm"
