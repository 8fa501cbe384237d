"""Model-predictive docking controllers designed on KIN and on STM (CasADi, optional).

Same plan, same segments, same speed and stops as the reference controller
(:mod:`artic.validation.docking.controllers.reference`); only the reversing
steering differs. Every sample it solves, over a horizon of
:data:`HORIZON` steps of :data:`STEP` [s]:

    min sum_k  q_y e_y2,k^2 + q_psi e_psi2,k^2 + q_gamma e_gamma,k^2
               + q_delta (delta_k - delta_path,k)^2 + r (delta_k - delta_k-1)^2
    s.t. |delta_k| <= delta_max,  |delta_k - delta_k-1| <= the actuator's rate x STEP

with the reference controller's cost (the Bryson weights of
:data:`artic.validation.docking.linear.REVERSE_WEIGHTS`, the rate's per metre
turned into per step at the commanded speed), on the design model's
prediction. It is a real-time iteration of sequential quadratic
programming: the model is rolled out with the previous sample's solution
(the warm start), and linearised along that rollout with its
own discrete step's Jacobians (:meth:`artic.reduced.control.KIN.step_jacobians`,
``STM.step_jacobians``: the harness's RK4, so the MPC predicts with exactly
the model the validation judges, and no second copy of its equations). The
condensed QP in the steering moves is solved by **qpOASES** through
``casadi.conic``: an online active-set method, which CasADi hot-starts from
the previous sample's active set (``SQProblem::hotstart``), so that a QP
like the last costs a few working-set changes; an interior-point solver
(IPOPT, OSQP's ADMM) cannot reuse an active set that way, and a fixed
``max_nWSR`` bounds the work per sample.

The QP is a small part of a sample's work; the rest is the prediction,
which takes one compiled rollout of the design model
(:meth:`artic.reduced.control.KIN.rollout`) and one batch of step
Jacobians, composed into each prediction step's for all steps at once. The
one-off costs of a process's first sample (numba's cache, qpOASES' plugin)
are paid in ``reset``. None of it changes a number the controller computes.

- ``mpc-kin`` predicts with KIN (4 states), its state (the rear axle) from
  the tractor sensor by :meth:`artic.KIN.initial_state`;
- ``mpc-stm`` with the STM (7 body states and a lagged slip per axle), its
  state (the centre of gravity) from the sensors by
  :meth:`artic.STM.initial_state` (lateral velocity and yaw rates measured,
  the slips at their steady state).

Forward segments, short and stable, are the reference controller's.
CasADi is an optional extra: ``pip install "artic[mpc]"``.
"""

from __future__ import annotations

import contextlib
import math
import os
import sys

import numpy as np

from artic.mjcf.errors import UserError
from artic.mjcf.interface import InitialState
from artic.validation.docking.controllers.base import Command, Observation, Task
from artic.validation.docking.controllers.reference import ReferenceController
from artic.validation.docking.linear import REVERSE_WEIGHTS

HORIZON = 25
"""Prediction steps."""

STEP = 0.3
"""Prediction step [s]: 25 steps look 7.5 s ahead, about a semitrailer's
length at 4 km/h."""

STM_SUBSTEPS = 6
"""Substeps of the STM's prediction step (50 ms each): its lightly damped
tyre-and-inertia modes near 17 rad/s (2.8 Hz, at every yard speed) need
``h |lambda| <= 2.8`` for RK4 to be stable, and a fraction of that to be
accurate; KIN, first order and without such modes, takes one."""

MAX_NWSR = 100
"""Most working-set changes qpOASES may take per sample."""


@contextlib.contextmanager
def _quiet_stdout():
    """Hold the process's standard output (file descriptor 1) while qpOASES prints its banner."""
    import ctypes

    libc = ctypes.CDLL(None)
    sys.stdout.flush()
    saved = os.dup(1)
    try:
        with open(os.devnull, "w") as null:
            os.dup2(null.fileno(), 1)
            try:
                yield
            finally:
                libc.fflush(None)  # what C's stdio still holds goes to /dev/null too
    finally:
        os.dup2(saved, 1)
        os.close(saved)


def _casadi():
    try:
        import casadi
    except ImportError:  # pragma: no cover - depends on the install
        raise UserError("the MPC controllers need CasADi: pip install \"artic[mpc]\"") from None
    return casadi


class MPC(ReferenceController):
    """Linear time-varying MPC by real-time iteration (see the module docstring)."""

    name = "mpc"
    design = "kin"
    requires = (("casadi", 'pip install "artic[mpc]"'),)

    def reset(self, task: Task) -> None:
        """Build the design model, the QP solver, and the warm start."""
        super().reset(task)
        ca = _casadi()
        from artic.reduced.control import KIN, STM

        v = task.vehicle
        if self.design == "kin":
            self.model = KIN(v)
            self.substeps = 1
        else:
            self.model = STM(v)
            self.substeps = STM_SUBSTEPS
        self.i_delta = self.model.find_input("delta")
        n = HORIZON
        L = np.tril(np.ones((n, n)))
        self.L = L
        with _quiet_stdout():
            self.qp = self._conic(ca, n)
        self.moves = np.zeros(n)
        self.delta_traj: np.ndarray | None = None
        self.first = True
        self._warm_up(ca, n)

    def _warm_up(self, ca, n: int) -> None:
        """Pay the one-off costs before the run, not in its first sample.

        The first calls of the state estimate and the compiled prediction
        load them from numba's cache, and the first solve of a qpOASES
        instance in a process loads the plugin and prints its banner: tens of
        milliseconds, once. An estimate and a prediction on the straight line
        and a solve on a throwaway instance take them here, leaving
        :attr:`qp` untouched, so that its first solve is the cold start it
        always was and the results do not change.
        """
        self.model.initial_state(InitialState(0.0, 0.0, 0.0, 0.0, v_y_1=0.0, r_1=0.0, r_2=0.0,
                                              u1=-1.0))
        x, u = self.model.straight(-1.0)
        self.predict(np.asarray(x, dtype=float), np.zeros(n), float(u[1]))
        with _quiet_stdout():
            self._conic(ca, n)(h=np.eye(n), g=np.zeros(n), a=self.L, lbx=-np.ones(n),
                               ubx=np.ones(n), lba=-np.ones(n), uba=np.ones(n))

    @staticmethod
    def _conic(ca, n: int):
        """The dense QP of ``n`` steering moves with ``n`` wheel-angle constraints."""
        return ca.conic("docking_mpc", "qpoases",
                        {"h": ca.Sparsity.dense(n, n), "a": ca.Sparsity.dense(n, n)},
                        {"printLevel": "none", "nWSR": MAX_NWSR, "error_on_fail": False})

    def _state(self, obs: Observation) -> np.ndarray:
        """The design model's state from the sensors (its ``initial_state`` of measured signals)."""
        s = obs.signals
        return np.array(self.model.initial_state(
            InitialState(obs["x_1"], obs["y_1"], obs["psi_1"], obs["gamma"], v_y_1=obs["v_y_1"],
                         r_1=obs["r_1"], r_2=obs["r_2"], u1=float(s[3]))), dtype=float)

    def _inputs(self, delta: np.ndarray, u: float) -> np.ndarray:
        U = np.zeros((delta.size, self.model.ninputs))
        U[:, self.i_delta] = delta
        U[:, self.model.find_input("u_1")] = u
        return U

    def predict(self, x: np.ndarray, delta_bar: np.ndarray,
                u: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The design model's rollout and its sensitivity to the steering moves.

        Parameters
        ----------
        x : ndarray
            State now.
        delta_bar : ndarray, shape (HORIZON,)
            Road-wheel angle held over each prediction step [rad].
        u : float
            Speed [m/s].

        Returns
        -------
        X : ndarray, shape (HORIZON + 1, n)
            The states at the steps' ends, ``x`` first.
        S : ndarray, shape (HORIZON, n, HORIZON)
            ``d X[k + 1] / d moves``, where ``delta_k = delta_bar_k + sum_{j <= k} moves_j``.
        U : ndarray, shape (HORIZON, m)
            The inputs of each step.
        """
        n = HORIZON
        m = self.substeps
        h = STEP / m
        nx = x.size
        U = self._inputs(delta_bar, u)
        Us = np.repeat(U, m, axis=0)
        Xs = self.model.rollout(x, Us, h)  # one compiled call, as model.step in a loop
        # Each prediction step's Jacobians (one batch call), composed from its
        # substeps' for all steps at once: Ak = A_m ... A_1, Bk = sum A_m ... A_j+1 B_j.
        As, Bs = self.model.step_jacobians(Xs[:-1], Us, h)
        As = As.reshape(n, m, nx, nx)
        Bs = Bs[:, :, self.i_delta].reshape(n, m, nx, 1)
        Ak, Bk = As[:, 0], Bs[:, 0]
        for j in range(1, m):
            Ak, Bk = As[:, j] @ Ak, As[:, j] @ Bk + Bs[:, j]
        S = np.zeros((n + 1, nx, n))
        for k in range(n):
            S[k + 1] = Ak[k] @ S[k]
            S[k + 1, :, k] += Bk[k, :, 0]
        # delta_j is the sum of the moves up to j.
        return Xs[::m], S[1:] @ self.L, U

    def command(self, obs: Observation) -> Command:
        """The reference controller's, with the reversing steering from the QP."""
        before = self.delta
        cmd = self._follow(obs)
        d = self.refs[self.k][0]
        if d > 0 or self.waiting or cmd.done or cmd.u1 == 0.0 or before is None:
            self.delta_traj = None  # the next reversing stretch starts afresh
            return self._intent(cmd)  # the reference's, and its closed-loop prediction
        self.delta = before  # the QP's steering instead of the LQR's
        return self._mpc(obs, cmd)

    def _mpc(self, obs: Observation, cmd: Command) -> Command:
        n = HORIZON
        _, p, g_ref, d_ref, s = self.refs[self.k]
        u = float(cmd.u1)
        ds = abs(u) * STEP
        # The path ahead, by the semitrailer axle's travel, from where the
        # reference's step found it now.
        me = self.frames.trailer_axle_of_signals(obs.signals)
        here = self.now[3]
        at = np.clip(here + ds * np.arange(1, n + 1), s[0], s[-1])
        ref = np.column_stack([np.interp(at, s, p[:, j]) for j in range(3)])
        gam = np.interp(at, s, g_ref)
        dref = np.interp(at - ds, s, d_ref)
        # The warm start: the last solution's steering, from the wheel now. A sample
        # (0.1 s) is a third of a prediction step, so the steps stay where they were.
        delta0 = float(self.delta)
        delta_bar = self.delta_traj if self.delta_traj is not None else np.full(n, delta0)
        moves = np.diff(np.r_[delta0, delta_bar])
        x = self._state(obs)
        X, S, U = self.predict(x, delta_bar, u)
        # Errors of the semitrailer axle and their Jacobians along the rollout.
        Y = self.model.output(X[1:])
        Cy, _ = self.model.output_jacobians(X[1:], U)
        ix, iy, ip = (self.model.output_labels.index(k) for k in ("X_2", "Y_2", "psi_2"))
        cr, sr = np.cos(ref[:, 2]), np.sin(ref[:, 2])
        e_y = -sr * (Y[:, ix] - ref[:, 0]) + cr * (Y[:, iy] - ref[:, 1])
        e_p = np.remainder(Y[:, ip] - ref[:, 2] + math.pi, 2 * math.pi) - math.pi
        J_y = (-sr[:, None] * Cy[:, ix] + cr[:, None] * Cy[:, iy])
        J_p = Cy[:, ip]
        ig = self.model.find_state("gamma")
        e_g = X[1:, ig] - gam
        w = REVERSE_WEIGHTS
        q = [1.0 / w[0] ** 2, 1.0 / w[1] ** 2, 1.0 / w[2] ** 2, 1.0 / w[3] ** 2]
        r = 1.0 / (w[4] * ds) ** 2  # the rate's weight per metre, per step of ds
        H = r * np.eye(n) + q[3] * self.L.T @ self.L
        g = r * moves + q[3] * self.L.T @ (delta_bar - dref)
        for e, J, qq in ((e_y, J_y, q[0]), (e_p, J_p, q[1])):
            G = np.einsum("kn,knm->km", J, S)  # d e_k / d moves
            H += qq * G.T @ G
            g += qq * G.T @ e
        G = S[:, ig, :]
        H += q[2] * G.T @ G
        g += q[2] * G.T @ e_g
        # Moves about the warm start: bounds on the rate and on the wheel.
        step = self.delta_rate * STEP
        dmax = self.vehicle.steering.delta_max
        bounds = {"h": H, "g": g, "a": self.L, "lbx": -step - moves, "ubx": step - moves,
                  "lba": -dmax - delta_bar, "uba": dmax - delta_bar}
        if self.first:  # qpOASES prints its licence on the first solve
            with _quiet_stdout():
                sol = self.qp(**bounds)
            self.first = False
        else:
            sol = self.qp(**bounds)
        dz = np.asarray(sol["x"]).ravel()
        if not np.all(np.isfinite(dz)):
            dz = np.zeros(n)
        self.moves = moves + dz
        self.delta_traj = delta0 + np.cumsum(self.moves)
        # The first step's wheel, as far as the actuator turns it in one control period.
        wheel = self._turn(delta0 + self.moves[0])
        # The predicted path of the semitrailer axle from where it is, and the path's
        # points it was compared with, for the recording.
        horizon = np.vstack([me[:2], np.column_stack(
            [Y[:, ix] + np.einsum("kn,knm->km", Cy[:, ix], S) @ dz,
             Y[:, iy] + np.einsum("kn,knm->km", Cy[:, iy], S) @ dz])])
        foot = [np.interp(here, s, p[:, 0]), np.interp(here, s, p[:, 1])]
        return Command(wheel, cmd.u1, cmd.done, horizon, np.vstack([foot, ref[:, :2]]))


class MPCKin(MPC):
    """MPC designed on KIN."""

    name = "mpc-kin"
    design = "kin"


class MPCStm(MPC):
    """MPC designed on the STM."""

    name = "mpc-stm"
    design = "stm"
