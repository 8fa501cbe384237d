"""KIN and STM: one class per model, for the harness, planners and controllers alike.

:class:`KIN` and :class:`STM` are what artic means by KIN and the STM
everywhere: the registry builds them (``artic.build_model("kin", v)``), the
harness drives them (``artic.run_closed_loop(artic.KIN(v), log, v)``), and a
planner calls their named signals, discrete step and linearisations.

The classes follow python-control's conventions for nonlinear input/output
systems: named states, inputs and outputs (``state_labels``, ``input_labels``,
``output_labels``, ``nstates``, ``ninputs``, ``noutputs``, ``find_state`` ...),
a continuous-time right-hand side and an output function, and
:meth:`~KIN.updfcn` / :meth:`~KIN.outfcn` with python-control's signature
``(t, x, u, params)``, so that ``control.nlsys(kin.updfcn, kin.outfcn,
states=kin.state_labels, inputs=kin.input_labels, outputs=kin.output_labels)``
wraps one without artic depending on python-control.

Every method takes one state ``x`` of shape ``(n,)`` or a batch ``(batch, n)``,
and inputs ``u`` of shape ``(m,)`` or ``(batch, m)``; a single state or input
is broadcast against a batch of the other. The physics is the harness's: the
right-hand sides are :func:`artic.reduced.kinematic.kin_rhs` and
:func:`artic.reduced.single_track.stm_rhs`, the step is
:func:`artic.reduced.integrate.rk4_step`, equal to the bit. The Jacobians are
derived by hand in :mod:`artic.reduced.jacobians`.

A planner writes::

    kin = artic.KIN(vehicle)
    x1 = kin.step(x, u, dt)
    A, B = kin.linearise(x0, u0)

**Which point the states describe.** ``X_1, Y_1`` is the tractor's
(equivalent) rear axle in KIN, its centre of gravity in the STM, and the
tractor's sensor in logs and in the harness's observations (``x_1, y_1``).
:meth:`~KIN.initial_state` and :meth:`~KIN.signals` convert between them.

**Subclasses.** The harness runs a model through a compiled loop
(:mod:`artic.validation.harness.reducedloop`), and :meth:`~KIN.step` and
:meth:`~KIN.rollout` run compiled too. A subclass that replaces what a
compiled path computes is never bypassed: a replaced :meth:`~KIN.rhs` makes
:meth:`~KIN.step`, :meth:`~KIN.advance`, :meth:`~KIN.rollout` and the harness
integrate it in Python (the same fourth-order Runge-Kutta), and the
Jacobians become finite differences of it; a replaced :meth:`~KIN.step` is
what :meth:`~KIN.rollout` and the harness take; a replaced
:meth:`~KIN.signals` is what the harness observes. A subclass whose
replacements compute what the built-in does (a wrapper that counts calls,
say) sets ``compiled_equivalent = True`` to keep the compiled paths.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from artic.mjcf.errors import UserError
from artic.mjcf.interface import InitialState, rotate, wrap_angle
from artic.mjcf.plausible import check_tyre_data
from artic.mjcf.vehicle import Vehicle
from artic.reduced import integrate
from artic.reduced.jacobians import kin_jacobian, stm_jacobian_batch
from artic.reduced.kinematic import KinParameters, equivalent_length, kin_params, wheelbases
from artic.reduced.single_track import N_BODY, StmParameters, axle_velocities, stm_params
from artic.reduced.tyre_linear import slip_angle

U_SLIP_KNOWN = 0.5
"""Axle speed above which a log's initial slip angle is taken as known [m/s]."""

_F8 = np.dtype(np.float64)

_COMPILED = ("rhs", "step", "advance", "signals")
"""What the harness's compiled loop computes: a class replacing any of them runs in Python."""


@njit(cache=True)
def rhs_batch(kind, x, u, P):
    """:func:`artic.reduced.integrate.rhs` for rows of ``x`` and ``u`` (delta, u1, u1_dot)."""
    out = np.empty_like(x)
    for i in range(x.shape[0]):
        integrate.rhs_into(kind, x[i], u[i, 1], u[i, 2], u[i, 0], P, out[i])
    return out


@njit(cache=True)
def step_batch(kind, x, u, dt, P):
    """:func:`artic.reduced.integrate.rk4_step` for rows of ``x`` and ``u`` (delta, u1, u1_dot)."""
    out = np.empty_like(x)
    if kind == integrate.KIN:  # scalars, no views: a fraction of the generic step's cost
        L1, L1c, L2 = P[0], P[1], P[2]
        for i in range(x.shape[0]):
            out[i, 0], out[i, 1], out[i, 2], out[i, 3] = integrate.kin_rk4(
                (x[i, 0], x[i, 1], x[i, 2], x[i, 3]), dt, u[i, 1], u[i, 2], u[i, 0],
                (L1, L1c, L2))
        return out
    work = np.empty((5, x.shape[1]))
    for i in range(x.shape[0]):
        integrate.rk4_step_into(kind, x[i], dt, u[i, 1], u[i, 2], u[i, 0], P, work, out[i])
    return out


@njit(cache=True)
def rollout_steps(kind, x0, u, dt, P):
    """:func:`artic.reduced.integrate.rk4_step` repeated from ``x0`` over the rows of ``u``.

    Returns the states ``(len(u) + 1, n)``, ``x0`` first.
    """
    out = np.empty((u.shape[0] + 1, x0.size))
    work = np.empty((5, x0.size))
    out[0] = x0
    for k in range(u.shape[0]):
        integrate.rk4_step_into(kind, out[k], dt, u[k, 1], u[k, 2], u[k, 0], P, work,
                                out[k + 1])
    return out


@njit(cache=True)
def rollout_batch(kind, x0, u, dt, P):
    """:func:`rollout_steps` for every row of ``x0`` (batch, n) and ``u`` (batch, steps, 3).

    Returns the states ``(batch, steps + 1, n)``, each row's ``x0`` first.
    Each row takes the steps :func:`rollout_steps` takes, so equal to it to the bit.
    """
    B, H = u.shape[0], u.shape[1]
    n = x0.shape[1]
    out = np.empty((B, H + 1, n))
    if kind == integrate.KIN:  # scalars, no views (see step_batch)
        L1, L1c, L2 = P[0], P[1], P[2]
        for b in range(B):
            X, Y, psi, gamma = x0[b, 0], x0[b, 1], x0[b, 2], x0[b, 3]
            out[b, 0, 0], out[b, 0, 1], out[b, 0, 2], out[b, 0, 3] = X, Y, psi, gamma
            for k in range(H):
                X, Y, psi, gamma = integrate.kin_rk4((X, Y, psi, gamma), dt, u[b, k, 1],
                                                     u[b, k, 2], u[b, k, 0], (L1, L1c, L2))
                out[b, k + 1, 0], out[b, k + 1, 1] = X, Y
                out[b, k + 1, 2], out[b, k + 1, 3] = psi, gamma
        return out
    work = np.empty((5, n))
    for b in range(B):
        out[b, 0] = x0[b]
        for k in range(H):
            integrate.rk4_step_into(kind, out[b, k], dt, u[b, k, 1], u[b, k, 2], u[b, k, 0], P,
                                    work, out[b, k + 1])
    return out


@njit(cache=True)
def step_one(kind, x, u, dt, P):
    """One step of a single state ``x`` (n,) with inputs ``u`` (m,): :meth:`ReducedModel.step`.

    Returns an empty array when an entry of ``x`` or ``u`` is not finite, for
    the caller to name it (a compiled function's error cannot carry the shapes).
    """
    for i in range(x.size):
        if not math.isfinite(x[i]):
            return np.empty(0)
    for i in range(u.size):
        if not math.isfinite(u[i]):
            return np.empty(0)
    u1_dot = u[2] if u.size > 2 else 0.0
    out = np.empty(x.size)
    integrate.rk4_step_into(kind, x, dt, u[1], u1_dot, u[0], P, np.empty((5, x.size)), out)
    return out


class BatchError(UserError):
    """A state, input or batch a reduced model cannot take: one line naming it and its shape.

    A :class:`artic.errors.UserError`, so a :class:`ValueError` too.
    """


class ReducedModel:
    """What KIN and STM share: signals, batches, the step, its Jacobians, the harness's calls.

    A subclass sets ``kind`` (:data:`artic.reduced.integrate.KIN` or ``STM``),
    ``name``, :attr:`params`, the labels, the sensors ``_s1`` (tractor sensor
    from the state's point, tractor axes [m]) and ``_s2`` (semitrailer sensor
    from the kingpin [m]), the output geometry ``_x_hitch`` (kingpin ahead of
    the state's point [m]) and ``_l2`` (semitrailer axle behind the kingpin
    [m]), and implements :meth:`initial_state` and :meth:`_jacobians3`.
    """

    kind: int
    name: str
    compiled_equivalent: bool = False
    """Set ``True`` in a subclass whose replaced methods compute what the built-in's
    do, to keep the compiled paths (see the module docstring)."""
    _s1: np.ndarray
    _s2: np.ndarray
    state_labels: tuple[str, ...]
    input_labels: tuple[str, ...]
    output_labels: tuple[str, ...] = ("X_1", "Y_1", "psi_1", "X_2", "Y_2", "psi_2")
    _x_hitch: float
    _l2: float

    @property
    def params(self) -> KinParameters | StmParameters:
        """The model's parameters, by name (a ``NamedTuple``).

        Assign a changed copy to study a parameter, e.g.
        ``kin.params = kin.params._replace(L1=1.4 * kin.params.L1)``.
        """
        return self._params

    @params.setter
    def params(self, value: KinParameters | StmParameters) -> None:
        self._params = value
        self.P = value.packed()

    P: np.ndarray
    """:attr:`params` packed as the compiled functions take them (internal)."""

    @property
    def nstates(self) -> int:
        """Number of states."""
        return len(self.state_labels)

    @property
    def ninputs(self) -> int:
        """Number of inputs."""
        return len(self.input_labels)

    @property
    def noutputs(self) -> int:
        """Number of outputs."""
        return len(self.output_labels)

    def find_state(self, name: str) -> int:
        """Index of the state ``name`` (python-control's ``find_state``)."""
        return self._find(name, self.state_labels, "state")

    def find_input(self, name: str) -> int:
        """Index of the input ``name``."""
        return self._find(name, self.input_labels, "input")

    def find_output(self, name: str) -> int:
        """Index of the output ``name``."""
        return self._find(name, self.output_labels, "output")

    def _find(self, name: str, labels: tuple[str, ...], what: str) -> int:
        try:
            return labels.index(name)
        except ValueError:
            raise UserError(f"{type(self).__name__} has no {what} {name!r}: its {what}s are "
                             f"{', '.join(labels)}") from None

    def __repr__(self) -> str:
        return (f"<{type(self).__name__}: states {', '.join(self.state_labels)}; "
                f"inputs {', '.join(self.input_labels)}; "
                f"outputs {', '.join(self.output_labels)}>")

    # -- batches -------------------------------------------------------------

    def _batch(self, x, u, finite: bool = True) -> tuple[np.ndarray, np.ndarray, bool]:
        """``x`` (batch, n), ``u`` as (batch, 3: delta, u1, u1_dot), and whether both were 1-D.

        Refuses, in one line naming the argument and its shape, a wrong shape,
        an empty batch and (with ``finite``) a state or input that is not finite.
        """
        x = np.asarray(x, dtype=float)
        u = np.asarray(u, dtype=float)
        for name, a, labels in (("x", x, self.state_labels), ("u", u, self.input_labels)):
            if a.ndim not in (1, 2) or a.shape[-1] != len(labels):
                raise BatchError(f"{type(self).__name__}: {name} has shape {a.shape}; expected "
                                 f"({len(labels)},) or (batch, {len(labels)}) for "
                                 f"{', '.join(labels)}")
            self._check(name, a, finite)
        single = x.ndim == 1 and u.ndim == 1
        x2, u2 = np.atleast_2d(x), np.atleast_2d(u)
        try:
            b = np.broadcast_shapes(x2.shape[:1], u2.shape[:1])[0]
        except ValueError:
            raise BatchError(f"{type(self).__name__}: a batch of {x2.shape[0]} states and one "
                             f"of {u2.shape[0]} inputs (x {x.shape}, u {u.shape}): give equal "
                             f"batches, or one of either") from None
        X = np.ascontiguousarray(np.broadcast_to(x2, (b, x2.shape[1])))
        U = np.zeros((b, 3))
        U[:, :u2.shape[1]] = u2
        return X, U, single

    def _check(self, name: str, a: np.ndarray, finite: bool = True) -> None:
        """Refuse an empty batch and, with ``finite``, a NaN or infinite entry, by ``name``."""
        if a.size == 0:
            raise BatchError(f"{type(self).__name__}: {name} has shape {a.shape}: an empty "
                             f"batch; give at least one row")
        if finite and not np.isfinite(a).all():
            bad = np.argwhere(~np.isfinite(a))[0]
            raise BatchError(f"{type(self).__name__}: {name} has shape {a.shape} and a "
                             f"{a[tuple(bad)]} at index {tuple(int(i) for i in bad)}; give "
                             f"finite states and inputs")

    @staticmethod
    def _out(a: np.ndarray, single: bool) -> np.ndarray:
        return a[0] if single else a

    # -- what a subclass replaced --------------------------------------------

    def replaced(self, *names: str) -> tuple[str, ...]:
        """Which of the methods ``names`` this object's class (or the object) replaced.

        Compared with the built-in model it derives from (:class:`KIN` or
        :class:`STM`); nothing counts as replaced where the class sets
        ``compiled_equivalent = True``.
        """
        if type(self).compiled_equivalent:
            return ()
        base = next((c for c in type(self).__mro__ if c in _BUILT_IN), ReducedModel)
        return tuple(n for n in names if n in vars(self)
                     or getattr(type(self), n) is not getattr(base, n))

    def _inputs(self, delta: float, u1: float, u1_dot: float) -> np.ndarray:
        """The inputs ``(delta, u_1[, u_1_dot])`` by this model's ``input_labels``."""
        return np.array([delta, u1, u1_dot][:self.ninputs], dtype=float)

    def _rhs3(self, X: np.ndarray, U: np.ndarray) -> np.ndarray:
        """:meth:`rhs` of rows ``X`` and ``U`` (batch, 3: delta, u1, u1_dot).

        Compiled unless a subclass replaced it.
        """
        if self.replaced("rhs"):
            return np.atleast_2d(np.asarray(self.rhs(X, U[:, :self.ninputs]), dtype=float))
        return rhs_batch(self.kind, X, U, self.P)

    def _rk4(self, X: np.ndarray, U: np.ndarray, dt: float) -> np.ndarray:
        """One fourth-order Runge-Kutta step of :meth:`rhs` (in Python, a subclass's).

        The same stages as :func:`artic.reduced.integrate.rk4_step`: ``delta``
        and ``u1_dot`` held, the speed ``u1 + u1_dot t`` over the step.
        """
        h2 = 0.5 * dt
        Um = U.copy()
        Um[:, 1] = U[:, 1] + h2 * U[:, 2]
        Ue = U.copy()
        Ue[:, 1] = U[:, 1] + dt * U[:, 2]
        k1 = self._rhs3(X, U)
        k2 = self._rhs3(X + h2 * k1, Um)
        k3 = self._rhs3(X + h2 * k2, Um)
        k4 = self._rhs3(X + dt * k3, Ue)
        return X + (dt / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4)

    # -- the system ----------------------------------------------------------

    def rhs(self, x, u) -> np.ndarray:
        """Continuous-time right-hand side ``dx/dt = f(x, u)``.

        Parameters
        ----------
        x : array_like, shape (n,) or (batch, n)
            State, see ``state_labels``.
        u : array_like, shape (m,) or (batch, m)
            Inputs, see ``input_labels``.

        Returns
        -------
        ndarray, shape (n,) or (batch, n)
            State derivative, in the state's units per second.
        """
        X, U, single = self._batch(x, u)
        return self._out(rhs_batch(self.kind, X, U, self.P), single)

    def _native(self) -> bool:
        """Whether :meth:`rhs` is the built-in one, so the compiled step may run (fast check)."""
        t = type(self)
        if t is KIN or t is STM:
            return "rhs" not in self.__dict__
        return not self.replaced("rhs")

    def step(self, x, u, dt: float) -> np.ndarray:
        """The state ``dt`` [s] later: one fourth-order Runge-Kutta step, as the harness takes.

        The inputs are held over the step (see the class's notes on ``u_1``
        for the STM). This is :func:`artic.reduced.integrate.rk4_step`, so a
        planner's prediction and artic's validation integrate alike, to the bit.
        A batch of states, inputs or both is stepped in one compiled call,
        each row equal to the bit to its single step.

        Parameters
        ----------
        x : array_like, shape (n,) or (batch, n)
            State.
        u : array_like, shape (m,) or (batch, m)
            Inputs.
        dt : float
            Step [s].

        Returns
        -------
        ndarray, shape (n,) or (batch, n)

        Raises
        ------
        BatchError
            A shape that is not the model's, an empty batch, batches of two
            sizes, or a state or input that is not finite (one line naming it).
        """
        # The fast path: one float64 state and input, as a planner's loop passes them.
        if (type(x) is np.ndarray and type(u) is np.ndarray and x.ndim == 1 and u.ndim == 1
                and x.dtype == _F8 and u.dtype == _F8 and x.shape[0] == len(self.state_labels)
                and u.shape[0] == len(self.input_labels) and self._native()):
            out = step_one(self.kind, x, u, float(dt), self.P)
            if out.size:
                return out
        X, U, single = self._batch(x, u)
        if not self._native():
            return self._out(self._rk4(X, U, float(dt)), single)
        return self._out(step_batch(self.kind, X, U, float(dt), self.P), single)

    def rollout(self, x0, u, dt: float) -> np.ndarray:
        """The states of :meth:`step` taken once per row of ``u``, in one compiled call.

        Equal to the bit to calling :meth:`step` in a loop; a prediction over
        a horizon of many steps costs one call instead of one per step. A
        batch, ``u`` of shape ``(batch, steps, m)`` from one state ``x0`` or a
        batch of them, rolls every row out in the same call, each equal to the
        bit to its own rollout: what a sampling planner (MPPI, CEM) asks for.

        Parameters
        ----------
        x0 : array_like, shape (n,) or (batch, n)
            State now; one state is shared by every row of a batch of ``u``.
        u : array_like, shape (steps, m) or (batch, steps, m)
            Inputs held over each step.
        dt : float
            Step [s].

        Returns
        -------
        ndarray, shape (steps + 1, n) or (batch, steps + 1, n)
            ``x0`` first, then the state after each step.

        Raises
        ------
        BatchError
            ``x0`` of shape (batch, n) with ``u`` of shape (steps, m), batches of
            two sizes, a wrong width, an empty batch or horizon, or an entry
            that is not finite (one line naming the argument and its shape).
        """
        x0 = np.ascontiguousarray(x0, dtype=float)
        u = np.asarray(u, dtype=float)
        name = type(self).__name__
        n, m = self.nstates, self.ninputs
        if (x0.ndim, u.ndim) not in ((1, 2), (1, 3), (2, 3)) or x0.shape[-1] != n \
                or u.shape[-1] != m:
            raise BatchError(f"{name}.rollout: x0 has shape {x0.shape} and u {u.shape}; "
                             f"expected ({n},) and (steps, {m}), or ({n},) or (batch, {n}) and "
                             f"(batch, steps, {m})")
        if x0.ndim == 2 and x0.shape[0] != u.shape[0]:
            raise BatchError(f"{name}.rollout: x0 has shape {x0.shape} and u {u.shape}: "
                             f"{x0.shape[0]} states for {u.shape[0]} input sequences; give "
                             f"equal batches, or one state")
        self._check("x0", x0)
        self._check("u", u)
        if u.ndim == 2:
            if self.replaced("rhs", "step"):  # a subclass's step, called as it always was
                out = np.empty((u.shape[0] + 1, n))
                out[0] = x0
                for k in range(u.shape[0]):
                    out[k + 1] = self.step(out[k], u[k], dt)
                return out
            U = np.zeros((u.shape[0], 3))
            U[:, :m] = u
            return rollout_steps(self.kind, x0, U, float(dt), self.P)
        x0 = np.broadcast_to(x0, (u.shape[0], n))
        return self._rollout_batch(x0, u, float(dt))

    def _rollout_batch(self, X0: np.ndarray, u: np.ndarray, dt: float) -> np.ndarray:
        """:meth:`rollout` of checked ``X0`` (batch, n) and ``u`` (batch, steps, m)."""
        B, H = u.shape[0], u.shape[1]
        U = np.zeros((B, H, 3))
        U[:, :, :self.ninputs] = u
        if self.replaced("rhs", "step"):
            # A subclass's own rhs or step, over the whole batch at once, step by step.
            out = np.empty((B, H + 1, X0.shape[1]))
            out[:, 0] = X0
            for k in range(H):
                out[:, k + 1] = self.step(out[:, k], u[:, k], dt)
            return out
        return rollout_batch(self.kind, np.ascontiguousarray(X0), U, dt, self.P)

    def output(self, x, u=None) -> np.ndarray:
        """Poses of both units: ``X_1, Y_1, psi_1`` (the state's point) and the semitrailer's.

        ``(X_2, Y_2)`` is the semitrailer's (equivalent) axle behind the kingpin
        (see the class), and ``psi_2 = psi_1 - gamma``. The inputs do not enter.

        Parameters
        ----------
        x : array_like, shape (n,) or (batch, n)
            State.
        u : array_like, optional
            Inputs (unused; python-control passes them).

        Returns
        -------
        ndarray, shape (6,) or (batch, 6)
            [m, m, rad, m, m, rad].
        """
        X, _, single = self._batch(x, np.zeros(self.ninputs) if u is None else u, finite=False)
        psi1, gamma = X[:, 2], X[:, 3]
        psi2 = psi1 - gamma
        y = np.empty((X.shape[0], 6))
        y[:, 0] = X[:, 0]
        y[:, 1] = X[:, 1]
        y[:, 2] = psi1
        y[:, 3] = X[:, 0] + self._x_hitch * np.cos(psi1) - self._l2 * np.cos(psi2)
        y[:, 4] = X[:, 1] + self._x_hitch * np.sin(psi1) - self._l2 * np.sin(psi2)
        y[:, 5] = psi2
        return self._out(y, single)

    def output_jacobians(self, x, u=None) -> tuple[np.ndarray, np.ndarray]:
        """``C = dy/dx`` and ``D = dy/du`` (zero) of :meth:`output`.

        With ``psi_2 = psi_1 - gamma``: ``dX_2/dpsi_1 = -x_h sin(psi_1) + l2 sin(psi_2)``,
        ``dX_2/dgamma = -l2 sin(psi_2)``, ``dY_2/dpsi_1 = x_h cos(psi_1) - l2 cos(psi_2)``,
        ``dY_2/dgamma = l2 cos(psi_2)``, ``x_h`` the kingpin ahead of the state's point.

        Returns
        -------
        C : ndarray, shape (6, n) or (batch, 6, n)
        D : ndarray, shape (6, m) or (batch, 6, m)
        """
        X, _, single = self._batch(x, np.zeros(self.ninputs) if u is None else u, finite=False)
        b = X.shape[0]
        psi1, psi2 = X[:, 2], X[:, 2] - X[:, 3]
        C = np.zeros((b, 6, self.nstates))
        C[:, 0, 0] = C[:, 1, 1] = C[:, 2, 2] = C[:, 3, 0] = C[:, 4, 1] = C[:, 5, 2] = 1.0
        C[:, 5, 3] = -1.0
        C[:, 3, 2] = -self._x_hitch * np.sin(psi1) + self._l2 * np.sin(psi2)
        C[:, 3, 3] = -self._l2 * np.sin(psi2)
        C[:, 4, 2] = self._x_hitch * np.cos(psi1) - self._l2 * np.cos(psi2)
        C[:, 4, 3] = self._l2 * np.cos(psi2)
        D = np.zeros((b, 6, self.ninputs))
        return self._out(C, single), self._out(D, single)

    def updfcn(self, t: float, x, u, params=None) -> np.ndarray:
        """:meth:`rhs` with python-control's signature; ``t`` and ``params`` are unused."""
        return self.rhs(x, u)

    def outfcn(self, t: float, x, u, params=None) -> np.ndarray:
        """:meth:`output` with python-control's signature; ``t`` and ``params`` are unused."""
        return self.output(x, u)

    # -- the harness's calls ---------------------------------------------------

    def initial_state(self, initial: InitialState) -> np.ndarray:
        """The state of a log's first sample: its pose and motion at the tractor's sensor.

        Parameters
        ----------
        initial : InitialState
            The tractor sensor's position ``(x_1, y_1)`` [m], the yaw, the
            articulation and the rates, as a log gives them.

        Returns
        -------
        ndarray, shape (n,)
            The state, whose ``X_1, Y_1`` is this model's point (see the class).
        """
        raise NotImplementedError

    def signals(self, x, u) -> np.ndarray:
        """What a log measures, at the sensor points, in ``OBSERVATION`` order.

        ``x_1, y_1`` is the tractor's sensor, not the state's point: the
        signals of :data:`artic.mjcf.interface.OBSERVATION` (SI, ISO 8855).

        Parameters
        ----------
        x : array_like, shape (n,)
            State.
        u : array_like, shape (m,)
            Inputs; KIN's yaw rates follow ``delta`` at once (the STM's
            velocities are states and do not jump).

        Returns
        -------
        ndarray, shape (13,)
        """
        x = np.asarray(x, dtype=float)
        u = np.asarray(u, dtype=float)
        y = integrate.observe(self.kind, x, float(u[1]), float(u[0]), self.P, self._s1,
                              self._s2)
        y[12] = wrap_angle(y[12])
        return y

    def advance(self, x, dt: float, delta: float, u1: float, u1_dot: float) -> np.ndarray:
        """The harness's step: the state ``dt`` [s] later, ``delta`` held, the speed ramping.

        The speed rises linearly from ``u1`` [m/s] at ``u1_dot`` [m/s^2] over
        the step, as the harness feeds a log. Compiled
        (:func:`artic.reduced.integrate.rk4_step`) unless a subclass replaced
        :meth:`step` (then its ``step`` with the inputs at the step's start,
        held) or :meth:`rhs` (then the same Runge-Kutta step of its ``rhs``).

        Returns
        -------
        ndarray, shape (n,)
        """
        if self.replaced("step"):
            return np.asarray(self.step(x, self._inputs(delta, u1, u1_dot), dt), dtype=float)
        x = np.asarray(x, dtype=float)
        if self.replaced("rhs"):
            U = np.array([[delta, u1, u1_dot]], dtype=float)
            return self._rk4(x[None, :], U, float(dt))[0]
        return integrate.rk4_step(self.kind, x, float(dt), float(u1), float(u1_dot),
                                  float(delta), self.P)

    def close(self) -> None:
        """Nothing to release: a reduced model holds only arrays (the plant's ``close`` does)."""

    def compiled(self) -> tuple | None:
        """``(kind, P, s1, s2)`` for the harness's compiled loop, or ``None``.

        ``None`` where a subclass replaced what that loop computes
        (:meth:`rhs`, :meth:`step`, :meth:`advance`, :meth:`signals`) and did
        not declare ``compiled_equivalent``: the harness then drives the
        model through those methods.
        """
        if self.replaced(*_COMPILED):
            return None
        return self.kind, self.P, self._s1, self._s2

    # -- Jacobians -----------------------------------------------------------

    def _jacobians3(self, X: np.ndarray, U: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``A`` (batch, n, n) and ``B`` (batch, n, 3) in ``(delta, u1, u1_dot)``."""
        raise NotImplementedError

    def jacobians(self, x, u) -> tuple[np.ndarray, np.ndarray]:
        """``A = df/dx`` and ``B = df/du`` of :meth:`rhs`, analytic.

        The derivation is in :mod:`artic.reduced.jacobians`.

        Returns
        -------
        A : ndarray, shape (n, n) or (batch, n, n)
        B : ndarray, shape (n, m) or (batch, n, m)
        """
        X, U, single = self._batch(x, u)
        A, B = self._jacobians_of_rhs(X, U)
        return self._out(A, single), self._out(B[:, :, :self.ninputs], single)

    def _jacobians_of_rhs(self, X: np.ndarray, U: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`_jacobians3`, or central differences of a subclass's own :meth:`rhs`.

        The analytic Jacobians are the built-in equations'; a replaced ``rhs``
        that does not replace them too gets differences, with steps of
        ``eps^(1/3)`` relative (the central difference's truncation and
        round-off errors balance there, about ``eps^(2/3)`` ~ 4e-11 relative).
        """
        if not self.replaced("rhs") or self.replaced("_jacobians3"):
            return self._jacobians3(X, U)
        b, n = X.shape
        A = np.empty((b, n, n))
        B = np.zeros((b, n, 3))
        for j in range(n):
            h = np.finfo(float).eps ** (1 / 3) * np.maximum(1.0, np.abs(X[:, j]))
            Xp, Xm = X.copy(), X.copy()
            Xp[:, j] += h
            Xm[:, j] -= h
            A[:, :, j] = (self._rhs3(Xp, U) - self._rhs3(Xm, U)) / (2.0 * h[:, None])
        for j in range(self.ninputs):
            h = np.finfo(float).eps ** (1 / 3) * np.maximum(1.0, np.abs(U[:, j]))
            Up, Um = U.copy(), U.copy()
            Up[:, j] += h
            Um[:, j] -= h
            B[:, :, j] = (self._rhs3(X, Up) - self._rhs3(X, Um)) / (2.0 * h[:, None])
        return A, B

    def step_jacobians(self, x, u, dt: float) -> tuple[np.ndarray, np.ndarray]:
        """``A_d = dx_next/dx`` and ``B_d = dx_next/du`` of :meth:`step`.

        The chain rule through the four stages: with ``x_s`` the stage states
        (``x_1 = x``, ``x_2 = x + dt/2 k_1``, ``x_3 = x + dt/2 k_2``,
        ``x_4 = x + dt k_3``), ``k_s = f(x_s, u_s)`` and ``u_s`` the stage
        inputs, ``dk_s = A_s dx_s + B_s du_s``, ``dx_s = I + c_s dt dk_{s-1}``,
        and ``x_next = x + dt/6 (k_1 + 2 k_2 + 2 k_3 + k_4)``. For the STM the
        stage speed is ``u_1 + c_s dt u_1_dot``, so ``du_s`` carries ``c_s dt``
        from ``u_1_dot`` to ``u_1``.

        Returns
        -------
        A_d : ndarray, shape (n, n) or (batch, n, n)
        B_d : ndarray, shape (n, m) or (batch, n, m)
        """
        if self.replaced("step"):
            raise NotImplementedError(
                f"{type(self).__name__} replaces step: its Jacobians are not the Runge-Kutta "
                "step's; give the subclass a step_jacobians of its own")
        X, U, single = self._batch(x, u)
        h = float(dt)
        b, n = X.shape
        eye = np.broadcast_to(np.eye(n), (b, n, n))
        xs, dxs_dx, dxs_du = X, eye, np.zeros((b, n, 3))
        Ad = eye.copy()
        Bd = np.zeros((b, n, 3))
        for c_in, c_next, w in ((0.0, 0.5, 1.0), (0.5, 0.5, 2.0), (0.5, 1.0, 2.0),
                                (1.0, None, 1.0)):
            Us = U.copy()
            Us[:, 1] += c_in * h * U[:, 2]
            E = np.eye(3)
            E[1, 2] = c_in * h  # d(stage speed)/d(u1_dot)
            A, B = self._jacobians_of_rhs(xs, Us)
            dk_dx = A @ dxs_dx
            dk_du = A @ dxs_du + B @ E
            Ad += (h / 6.0) * w * dk_dx
            Bd += (h / 6.0) * w * dk_du
            if c_next is not None:
                k = self._rhs3(xs, Us)
                xs = X + c_next * h * k
                dxs_dx = eye + c_next * h * dk_dx
                dxs_du = c_next * h * dk_du
        return self._out(Ad, single), self._out(Bd[:, :, :self.ninputs], single)

    def linearise(self, x0, u0, dt: float | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Linearisation about ``(x0, u0)``: continuous, or discrete with ``dt``.

        Parameters
        ----------
        x0 : array_like, shape (n,) or (batch, n)
            Operating state, e.g. from :meth:`straight` or :meth:`steady_turn`.
        u0 : array_like, shape (m,) or (batch, m)
            Operating inputs.
        dt : float, optional
            Step [s]: the Jacobians of :meth:`step` instead of :meth:`rhs`.

        Returns
        -------
        A, B : ndarray
            ``dx/dt ~ A dx + B du``, or with ``dt``, ``x_next ~ A dx + B du``
            about the step from ``(x0, u0)``.
        """
        if dt is None:
            return self.jacobians(x0, u0)
        return self.step_jacobians(x0, u0, dt)


class KIN(ReducedModel):
    """KIN, eq. (1): the kinematic model, for the harness, planners and controllers.

    States ``X_1, Y_1`` [m]: **the tractor's (equivalent) rear axle**, its
    no-slip point (the drive axle for ``wheelbase="paper"``), not the
    centre of gravity (the STM's ``X_1, Y_1``) nor the sensor (a log's
    ``x_1, y_1``); ``psi_1`` [rad] (tractor yaw) and ``gamma`` [rad]
    (articulation, ``psi_1 - psi_2``). Inputs ``delta`` [rad] (road-wheel
    angle) and ``u_1`` [m/s] (tractor longitudinal speed, negative in
    reverse). Outputs ``X_1, Y_1, psi_1`` and the semitrailer's equivalent
    axle ``X_2, Y_2`` [m] with its yaw ``psi_2`` [rad].

    The harness drives it as it is (``artic.run_closed_loop(artic.KIN(v),
    log, v)``), and :meth:`signals` gives what a log measures at the sensors.

    Parameters
    ----------
    vehicle : Vehicle
        Geometry, static axle loads and sensor positions.
    wheelbase : str
        ``"equivalent"`` (default): each unit's axle group enters through its
        no-slip point, so a tag axle or a tridem counts; ``"paper"``: the
        drive axle and the middle trailer axle, as the paper has it. See
        :mod:`artic.reduced.kinematic`.

    Raises
    ------
    UnsupportedVehicleError
        When a wheelbase of the vehicle is not positive and finite.

    See Also
    --------
    artic.STM : the single-track model, with tyres and inertia.
    artic.Plant : the multibody reference.
    artic.run_closed_loop : drive it through a log.
    artic.simulate : drive it through a profile.

    Examples
    --------
    Reversing straight is open-loop unstable: linearised about a straight
    reverse at 1 m/s and sampled at 0.1 s, one eigenvalue lies outside the unit
    circle (the articulation's, growing by ``exp(u1 / L2 * dt)``):

    >>> import numpy as np
    >>> import artic
    >>> kin = artic.KIN(artic.load_vehicle("gosar2022-unloaded"))
    >>> x0, u0 = kin.straight(-1.0)  # states X_1, Y_1, psi_1, gamma; inputs delta, u_1
    >>> A, B = kin.linearise(x0, u0, dt=0.1)
    >>> round(float(np.abs(np.linalg.eigvals(A)).max()), 3)
    1.013
    >>> kin.rollout(x0, np.tile(u0, (50, 1)), 0.1).shape  # 50 steps of 0.1 s, from x0
    (51, 4)
    """

    kind = integrate.KIN
    name = "kin"
    state_labels = ("X_1", "Y_1", "psi_1", "gamma")
    """``X_1, Y_1`` [m]: the tractor's (equivalent) rear axle, not its sensor (a log's
    ``x_1, y_1``) nor its centre of gravity (the STM's); ``psi_1``, ``gamma`` [rad]."""
    input_labels = ("delta", "u_1")

    def __init__(self, vehicle: Vehicle, wheelbase: str = "equivalent") -> None:
        self.vehicle = vehicle
        self.wheelbase = wheelbase
        self.params = kin_params(vehicle, wheelbase)
        x_rear = wheelbases(vehicle, wheelbase)[2]
        # The state's point is the (equivalent) rear axle: the sensor from there.
        self._s1 = np.array([vehicle.sensor1[0] - x_rear, vehicle.sensor1[1]])
        self._s2 = np.array(vehicle.sensor2[:2])

    @property
    def L1(self) -> float:
        """Tractor wheelbase [m] (:attr:`params`)."""
        return float(self.params.L1)

    @property
    def L1c(self) -> float:
        """Fifth wheel ahead of the (equivalent) rear axle [m]."""
        return float(self.params.L1c)

    @property
    def L2(self) -> float:
        """Semitrailer's (equivalent) axle behind the kingpin [m]."""
        return float(self.params.L2)

    @property
    def _x_hitch(self) -> float:
        return self.L1c

    @property
    def _l2(self) -> float:
        return self.L2

    def initial_state(self, initial: InitialState) -> np.ndarray:
        """The rear axle placed so that the tractor sensor is at ``(x_1, y_1)``.

        Parameters
        ----------
        initial : InitialState
            A log's first sample.

        Returns
        -------
        ndarray, shape (4,)
            ``[X_1, Y_1, psi_1, gamma]``, ``X_1, Y_1`` the rear axle [m].
        """
        dx, dy = rotate(initial.psi_1, self._s1[0], self._s1[1])
        return np.array([initial.x_1 - dx, initial.y_1 - dy, initial.psi_1,
                         wrap_angle(initial.gamma)])

    def _jacobians3(self, X, U):
        A, B2 = kin_jacobian(X, U, self.P)
        B = np.zeros((X.shape[0], 4, 3))
        B[:, :, :2] = B2
        return A, B

    def straight(self, u: float) -> tuple[np.ndarray, np.ndarray]:
        """Operating point driving straight along ``X`` at speed ``u`` [m/s] (< 0: reverse).

        Returns
        -------
        x0 : ndarray, shape (4,)
            Zero.
        u0 : ndarray, shape (2,)
            ``[0, u]``.
        """
        return np.zeros(4), np.array([0.0, float(u)])

    def steady_turn(self, delta: float, u: float) -> tuple[np.ndarray, np.ndarray]:
        """The trim of a steady turn: articulation from ``gamma_dot = 0`` in eq. (1).

        ``L1 sin(gamma) + L1c tan(delta) cos(gamma) = L2 tan(delta)`` gives
        ``gamma = asin(L2 tan(delta) / rho) - atan2(L1c tan(delta), L1)``,
        ``rho = hypot(L1, L1c tan(delta))``, the same forward and in reverse
        (``u`` factors out; in reverse the trim is unstable). Both units then
        yaw at ``u tan(delta) / L1``.

        Parameters
        ----------
        delta : float
            Road-wheel angle [rad].
        u : float
            Tractor speed [m/s].

        Returns
        -------
        x0 : ndarray, shape (4,)
            ``[0, 0, 0, gamma]``: at the origin, heading along ``X``.
        u0 : ndarray, shape (2,)
            ``[delta, u]``.
        """
        t = math.tan(delta)
        rho = math.hypot(self.L1, self.L1c * t)
        if abs(self.L2 * t) > rho:
            raise UserError(f"KIN.steady_turn: delta = {delta} rad turns the tractor tighter "
                             f"than the semitrailer can follow (|L2 tan(delta)| > "
                             f"hypot(L1, L1c tan(delta))): no steady articulation; use a "
                             f"smaller |delta|")
        gamma = math.asin(self.L2 * t / rho) - math.atan2(self.L1c * t, self.L1)
        return np.array([0.0, 0.0, 0.0, gamma]), np.array([float(delta), float(u)])


class STM(ReducedModel):
    """STM, eq. (2): the single-track model, for the harness, planners and controllers.

    States ``X_1, Y_1`` [m]: **the tractor's centre of gravity** (not KIN's
    rear axle nor a log's sensor, ``x_1, y_1``), ``psi_1``
    [rad], ``gamma`` [rad], ``v_1`` [m/s] (the centre of gravity's lateral
    velocity in tractor axes), ``r_1`` [rad/s] (tractor yaw rate),
    ``gamma_dot`` [rad/s] and the lagged slip angle ``alpha_i`` [rad] of
    every axle, tractor first, in the vehicle file's order.

    Inputs ``delta`` [rad], ``u_1`` [m/s] and ``u_1_dot`` [m/s^2]. The
    tractor's speed is prescribed, not a state, and its rate enters the
    dynamics: the semitrailer's inertia pushes on the hitch as the speed
    changes (the ``M[1:, 0] u_1_dot`` terms of :mod:`artic.reduced.single_track`).
    So the STM needs ``u_1_dot`` as an input, and the caller keeps ``u_1``
    consistent with it. :meth:`step` integrates as the harness does:
    ``delta`` and ``u_1_dot`` held, the speed ``u_1 + u_1_dot t`` over the
    step, so the next step's ``u_1`` is ``u_1 + u_1_dot dt``. With
    ``u_1_dot = 0`` every input is held.

    Outputs ``X_1, Y_1, psi_1`` and the semitrailer's equivalent axle
    ``X_2, Y_2`` [m], ``sum C l^2 / sum C l`` behind the kingpin (its
    low-speed no-slip point, KIN's ``L2``), with its yaw ``psi_2`` [rad].

    The harness drives it as it is (``artic.run_closed_loop(artic.STM(v),
    log, v)``), and :meth:`signals` gives what a log measures at the sensors.

    Parameters
    ----------
    vehicle : Vehicle
        Masses, inertias, every axle, ``f`` and ``sigma_alpha``.
    f : float, optional
        Override of the normalised cornering stiffness [1/rad].
    trailer_axles : ndarray, optional
        Override of the trailer axle distances behind the kingpin [m].

    Raises
    ------
    VehicleFileError
        For a vehicle without the tyre data the STM needs (a scale model's
        file may leave ``[tyre] f`` out): one line naming the file and the key.

    See Also
    --------
    artic.KIN : the kinematic model.
    artic.Plant : the multibody reference.
    artic.run_closed_loop : drive it through a log.

    Examples
    --------
    In a slow steady turn the STM's yaw rate is close to KIN's ``u_1 tan(delta) / L1``
    (the tyres slip a little):

    >>> import math
    >>> import artic
    >>> vehicle = artic.load_vehicle("gosar2022-unloaded")
    >>> stm = artic.STM(vehicle)
    >>> x, u = stm.steady_turn(0.1, 2.0)  # road-wheel angle [rad], speed [m/s]
    >>> r_1 = x[stm.find_state("r_1")]
    >>> kinematic = 2.0 * math.tan(0.1) / vehicle.L1
    >>> bool(abs(r_1 - kinematic) / kinematic < 0.1)
    True
    """

    kind = integrate.STM
    name = "stm"
    input_labels = ("delta", "u_1", "u_1_dot")

    def __init__(self, vehicle: Vehicle, f: float | None = None,
                 trailer_axles: np.ndarray | None = None) -> None:
        check_tyre_data(vehicle, "stm")  # a scale model may have none: refused, by key
        self.vehicle = vehicle
        self.params = stm_params(vehicle, f, trailer_axles)
        self._s1 = np.array([vehicle.sensor1[0] - vehicle.b1, vehicle.sensor1[1]])
        self._s2 = np.array(vehicle.sensor2[:2])

    @property
    def state_labels(self) -> tuple[str, ...]:
        """``X_1, Y_1, psi_1, gamma, v_1, r_1, gamma_dot`` and ``alpha_i`` per axle.

        ``X_1, Y_1`` [m] is the tractor's centre of gravity, not its sensor (a
        log's ``x_1, y_1``) nor its rear axle (KIN's).
        """
        return ("X_1", "Y_1", "psi_1", "gamma", "v_1", "r_1", "gamma_dot",
                *(f"alpha_{i + 1}" for i in range(self.params.n_axles)))

    @property
    def n_axles(self) -> int:
        """Number of axles, both units."""
        return self.params.n_axles

    @property
    def _x_hitch(self) -> float:
        return -float(self.params.Lc)

    @property
    def _l2(self) -> float:
        p = self.params
        return equivalent_length(p.tr_l, p.C[p.ax_x.size:])

    def initial_state(self, initial: InitialState) -> np.ndarray:
        """The combination at ``initial``, tyres at steady-state slip.

        The steady-state slip angle is the travel direction's, which a
        measured velocity only gives when the axle moves well above the
        sensors' noise: with 1 cm/s of noise it is uncertain by 45 deg at
        1 cm/s and by 1 deg at 0.5 m/s. So the initial lagged slip is the
        steady-state one scaled by ``min(1, |v| / U_SLIP_KNOWN)``: relaxed
        tyres for a log that starts at rest, steady state for one that starts
        rolling. (Steady-state slip from a noisy 1 cm/s start gives slip
        angles near 90 deg and an oscillation of metres per second.) The
        steered axles' slip is at ``initial.delta``: a log that starts in a
        turn would otherwise start with its slip off by that angle.

        Parameters
        ----------
        initial : InitialState
            A log's first sample.

        Returns
        -------
        ndarray, shape (n,)
            ``X_1, Y_1`` the centre of gravity [m].
        """
        s1x, s1y = self._s1
        dx, dy = rotate(initial.psi_1, s1x, s1y)
        v = initial.v_y_1 - initial.r_1 * s1x
        x = np.zeros(self.nstates)
        x[:N_BODY] = [initial.x_1 - dx, initial.y_1 - dy, initial.psi_1,
                      wrap_angle(initial.gamma), v, initial.r_1, initial.r_1 - initial.r_2]
        v_long, v_lat = self.axle_velocities(x, initial.u1, initial.delta)
        x[N_BODY:] = [slip_angle(a, b) * min(1.0, math.hypot(a, b) / U_SLIP_KNOWN)
                      for a, b in zip(v_long, v_lat, strict=True)]
        return x

    def axle_velocities(self, x, u1: float, delta: float) -> tuple[np.ndarray, np.ndarray]:
        """Axle-centre velocities ``(v_long, v_lat)`` in wheel frames [m/s], tractor first.

        Parameters
        ----------
        x : array_like, shape (n,)
            State.
        u1 : float
            Tractor speed [m/s].
        delta : float
            Road-wheel angle [rad].
        """
        p = self.params
        return axle_velocities(u1, x[4], x[5], x[3], x[6], delta, p.ax_x, p.ax_steer, p.tr_l,
                               p.Lc)

    def tyre_forces(self, x) -> np.ndarray:
        """Lateral force of every axle at state ``x``, tractor first [N]."""
        return self.params.C * np.asarray(x, dtype=float)[N_BODY:]

    def _jacobians3(self, X, U):
        return stm_jacobian_batch(X, U, self.P)

    def straight(self, u: float) -> tuple[np.ndarray, np.ndarray]:
        """Operating point driving straight along ``X`` at speed ``u`` [m/s] (< 0: reverse).

        Returns
        -------
        x0 : ndarray, shape (n,)
            Zero: no lateral velocity, yaw or slip.
        u0 : ndarray, shape (3,)
            ``[0, u, 0]``.
        """
        return np.zeros(self.nstates), np.array([0.0, float(u), 0.0])

    def steady_turn(self, delta: float, u: float, tol: float = 1e-12,
                    max_iter: int = 50) -> tuple[np.ndarray, np.ndarray]:
        """The trim of a steady turn at constant speed, solved by Newton's method.

        Unknowns ``gamma, v_1, r_1`` and the slip angles, with ``gamma_dot = 0``;
        equations: the velocity rows and the slip rates of :meth:`rhs` vanish.
        Newton's iteration uses the analytic :meth:`jacobians`, from KIN's
        trim with equivalent wheelbases (the STM's low-speed limit). In
        reverse the trim exists but is unstable.

        Parameters
        ----------
        delta : float
            Road-wheel angle [rad].
        u : float
            Tractor speed [m/s], not zero (at standstill every slip angle is a
            trim).
        tol : float
            Newton step at which to stop [rad, m/s, rad/s].
        max_iter : int
            Iterations before giving up.

        Returns
        -------
        x0 : ndarray, shape (n,)
            At the origin, heading along ``X``.
        u0 : ndarray, shape (3,)
            ``[delta, u, 0]``.
        """
        if u == 0.0:
            raise UserError("STM.steady_turn: u = 0: at standstill the tyres' slip angles "
                             "are frozen and every articulation is a trim; give u != 0")
        L1, _, x_n = wheelbases(self.vehicle)
        try:
            kin_trim = KIN(self.vehicle).steady_turn(delta, u)[0]
        except ValueError:
            raise UserError(f"STM.steady_turn: delta = {delta} rad turns the tractor tighter "
                             f"than the semitrailer can follow even without tyre slip: no "
                             f"steady articulation; use a smaller |delta|") from None
        r = u * math.tan(delta) / L1
        x = np.zeros(self.nstates)
        x[3] = kin_trim[3]
        x[5] = r
        x[4] = r * (self.vehicle.b1 - x_n)  # zero lateral velocity at the no-slip point
        x[N_BODY:] = self._steady_slips(x, u, delta)
        u0 = np.array([float(delta), float(u), 0.0])
        idx = np.r_[3, 4, 5, N_BODY:self.nstates]
        rows = np.r_[4, 5, 6, N_BODY:self.nstates]
        for _ in range(max_iter):
            A, _ = self.jacobians(x, u0)
            dz = np.linalg.solve(A[np.ix_(rows, idx)], -self.rhs(x, u0)[rows])
            x[idx] += dz
            if np.max(np.abs(dz)) < tol:
                return x, u0
        raise UserError(f"STM.steady_turn: no trim found at delta = {delta} rad, u = {u} m/s "
                         f"in {max_iter} Newton steps (last step {np.max(np.abs(dz)):.3g}); "
                         f"the turn may be past the tyres' or the hitch's reach: try a smaller "
                         f"|delta| or |u|")

    def _steady_slips(self, x: np.ndarray, u1: float, delta: float) -> np.ndarray:
        """Every axle's steady-state slip angle at state ``x`` [rad]."""
        v_long, v_lat = self.axle_velocities(x, u1, delta)
        return np.array([slip_angle(a, b) for a, b in zip(v_long, v_lat, strict=True)])


_BUILT_IN = (KIN, STM)
"""The built-in models a subclass's replaced methods are compared with."""

ControlModel = ReducedModel
"""The former name of :class:`ReducedModel`."""
