"""KIN and STM for planners and controllers: named signals, a discrete step, linearisations.

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
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from artic.mjcf.vehicle import Vehicle
from artic.reduced import integrate
from artic.reduced.jacobians import kin_jacobian, stm_jacobian_batch
from artic.reduced.kinematic import equivalent_length, kin_parameters, wheelbases
from artic.reduced.single_track import N_BODY, axle_velocities, stm_parameters, stm_unpack
from artic.reduced.tyre_linear import slip_angle


@njit(cache=True)
def rhs_batch(kind, x, u, P):
    """:func:`artic.reduced.integrate.rhs` for rows of ``x`` and ``u`` (delta, u1, u1_dot)."""
    out = np.empty_like(x)
    for i in range(x.shape[0]):
        out[i] = integrate.rhs(kind, x[i], u[i, 1], u[i, 2], u[i, 0], P)
    return out


@njit(cache=True)
def step_batch(kind, x, u, dt, P):
    """:func:`artic.reduced.integrate.rk4_step` for rows of ``x`` and ``u`` (delta, u1, u1_dot)."""
    out = np.empty_like(x)
    for i in range(x.shape[0]):
        out[i] = integrate.rk4_step(kind, x[i], dt, u[i, 1], u[i, 2], u[i, 0], P)
    return out


@njit(cache=True)
def rollout_steps(kind, x0, u, dt, P):
    """:func:`artic.reduced.integrate.rk4_step` repeated from ``x0`` over the rows of ``u``.

    Returns the states ``(len(u) + 1, n)``, ``x0`` first.
    """
    out = np.empty((u.shape[0] + 1, x0.size))
    out[0] = x0
    for k in range(u.shape[0]):
        out[k + 1] = integrate.rk4_step(kind, out[k], dt, u[k, 1], u[k, 2], u[k, 0], P)
    return out


class ControlModel:
    """What KIN and STM share: signals, batches, the step and its Jacobians.

    A subclass sets ``kind`` (:data:`artic.reduced.integrate.KIN` or ``STM``),
    ``P``, the labels, the output geometry ``_x_hitch`` (kingpin ahead of the
    state's point [m]) and ``_l2`` (semitrailer axle behind the kingpin [m]),
    and implements :meth:`_jacobians3`.
    """

    kind: int
    P: np.ndarray
    state_labels: tuple[str, ...]
    input_labels: tuple[str, ...]
    output_labels: tuple[str, ...] = ("X_1", "Y_1", "psi_1", "X_2", "Y_2", "psi_2")
    _x_hitch: float
    _l2: float

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
            raise ValueError(f"{type(self).__name__} has no {what} {name!r}: its {what}s are "
                             f"{', '.join(labels)}") from None

    def __repr__(self) -> str:
        return (f"<{type(self).__name__}: states {', '.join(self.state_labels)}; "
                f"inputs {', '.join(self.input_labels)}; "
                f"outputs {', '.join(self.output_labels)}>")

    # -- batches -------------------------------------------------------------

    def _batch(self, x, u) -> tuple[np.ndarray, np.ndarray, bool]:
        """``x`` (batch, n), ``u`` as (batch, 3: delta, u1, u1_dot), and whether both were 1-D."""
        x = np.asarray(x, dtype=float)
        u = np.asarray(u, dtype=float)
        for name, a, labels in (("x", x, self.state_labels), ("u", u, self.input_labels)):
            if a.ndim not in (1, 2) or a.shape[-1] != len(labels):
                raise ValueError(f"{type(self).__name__}: {name} has shape {a.shape}; expected "
                                 f"({len(labels)},) or (batch, {len(labels)}) for "
                                 f"{', '.join(labels)}")
        single = x.ndim == 1 and u.ndim == 1
        x2, u2 = np.atleast_2d(x), np.atleast_2d(u)
        try:
            b = np.broadcast_shapes(x2.shape[:1], u2.shape[:1])[0]
        except ValueError:
            raise ValueError(f"{type(self).__name__}: a batch of {x2.shape[0]} states and one "
                             f"of {u2.shape[0]} inputs: give equal batches, or one of either"
                             ) from None
        X = np.ascontiguousarray(np.broadcast_to(x2, (b, x2.shape[1])))
        U = np.zeros((b, 3))
        U[:, :u2.shape[1]] = u2
        return X, U, single

    @staticmethod
    def _out(a: np.ndarray, single: bool) -> np.ndarray:
        return a[0] if single else a

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

    def step(self, x, u, dt: float) -> np.ndarray:
        """The state ``dt`` [s] later: one fourth-order Runge-Kutta step, as the harness takes.

        The inputs are held over the step (see the class's notes on ``u_1``
        for the STM). This is :func:`artic.reduced.integrate.rk4_step`, so a
        planner's prediction and artic's validation integrate alike, to the bit.

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
        """
        X, U, single = self._batch(x, u)
        return self._out(step_batch(self.kind, X, U, float(dt), self.P), single)

    def rollout(self, x0, u, dt: float) -> np.ndarray:
        """The states of :meth:`step` taken once per row of ``u``, in one compiled call.

        Equal to the bit to calling :meth:`step` in a loop; a prediction over
        a horizon of many steps costs one call instead of one per step.

        Parameters
        ----------
        x0 : array_like, shape (n,)
            State now.
        u : array_like, shape (steps, m)
            Inputs held over each step.
        dt : float
            Step [s].

        Returns
        -------
        ndarray, shape (steps + 1, n)
            ``x0`` first, then the state after each step.
        """
        x0 = np.asarray(x0, dtype=float)
        u = np.asarray(u, dtype=float)
        if x0.ndim != 1 or u.ndim != 2:
            raise ValueError(f"{type(self).__name__}.rollout: x0 has shape {x0.shape} and u "
                             f"{u.shape}; expected ({self.nstates},) and (steps, "
                             f"{self.ninputs})")
        X, U, _ = self._batch(x0, u)
        return rollout_steps(self.kind, X[0], U, float(dt), self.P)

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
        X, _, single = self._batch(x, np.zeros(self.ninputs) if u is None else u)
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
        X, _, single = self._batch(x, np.zeros(self.ninputs) if u is None else u)
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
        A, B = self._jacobians3(X, U)
        return self._out(A, single), self._out(B[:, :, :self.ninputs], single)

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
            A, B = self._jacobians3(xs, Us)
            dk_dx = A @ dxs_dx
            dk_du = A @ dxs_du + B @ E
            Ad += (h / 6.0) * w * dk_dx
            Bd += (h / 6.0) * w * dk_du
            if c_next is not None:
                k = rhs_batch(self.kind, xs, Us, self.P)
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


class KIN(ControlModel):
    """KIN, eq. (1), for planning and control.

    States ``X_1, Y_1`` [m] (the tractor's (equivalent) rear axle, the
    drive axle for ``wheelbase="paper"``), ``psi_1`` [rad] (tractor yaw) and
    ``gamma`` [rad] (articulation, ``psi_1 - psi_2``). Inputs ``delta`` [rad]
    (road-wheel angle) and ``u_1`` [m/s] (tractor longitudinal speed, negative
    in reverse). Outputs ``X_1, Y_1, psi_1`` and the semitrailer's equivalent
    axle ``X_2, Y_2`` [m] with its yaw ``psi_2`` [rad].

    Parameters
    ----------
    vehicle : Vehicle
        Geometry and static axle loads.
    wheelbase : str
        ``"equivalent"`` (default) or ``"paper"``, see
        :mod:`artic.reduced.kinematic`.
    """

    kind = integrate.KIN
    state_labels = ("X_1", "Y_1", "psi_1", "gamma")
    input_labels = ("delta", "u_1")

    def __init__(self, vehicle: Vehicle, wheelbase: str = "equivalent") -> None:
        self.vehicle = vehicle
        self.wheelbase = wheelbase
        self.P = kin_parameters(vehicle, wheelbase)
        self.L1, self.L1c, self.L2 = (float(p) for p in self.P)
        self._x_hitch, self._l2 = self.L1c, self.L2

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
            raise ValueError(f"KIN.steady_turn: delta = {delta} rad turns the tractor tighter "
                             f"than the semitrailer can follow (|L2 tan(delta)| > "
                             f"hypot(L1, L1c tan(delta))): no steady articulation; use a "
                             f"smaller |delta|")
        gamma = math.asin(self.L2 * t / rho) - math.atan2(self.L1c * t, self.L1)
        return np.array([0.0, 0.0, 0.0, gamma]), np.array([float(delta), float(u)])


class STM(ControlModel):
    """STM, eq. (2), for planning and control.

    States ``X_1, Y_1`` [m] (the tractor's centre of gravity), ``psi_1``
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

    Parameters
    ----------
    vehicle : Vehicle
        Masses, inertias, every axle, ``f`` and ``sigma_alpha``.
    f : float, optional
        Override of the normalised cornering stiffness [1/rad].
    trailer_axles : ndarray, optional
        Override of the trailer axle distances behind the kingpin [m].
    """

    kind = integrate.STM
    input_labels = ("delta", "u_1", "u_1_dot")

    def __init__(self, vehicle: Vehicle, f: float | None = None,
                 trailer_axles: np.ndarray | None = None) -> None:
        self.vehicle = vehicle
        self.P = stm_parameters(vehicle, f, trailer_axles)
        _, _, _, _, Lc, _, _, ax_x, _, tr_l, C = stm_unpack(self.P)
        n_axles = C.size
        self.state_labels = ("X_1", "Y_1", "psi_1", "gamma", "v_1", "r_1", "gamma_dot",
                             *(f"alpha_{i + 1}" for i in range(n_axles)))
        self._x_hitch = -float(Lc)
        self._l2 = equivalent_length(tr_l, C[ax_x.size:])

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
            raise ValueError("STM.steady_turn: u = 0: at standstill the tyres' slip angles "
                             "are frozen and every articulation is a trim; give u != 0")
        L1, _, x_n = wheelbases(self.vehicle)
        try:
            kin_trim = KIN(self.vehicle).steady_turn(delta, u)[0]
        except ValueError:
            raise ValueError(f"STM.steady_turn: delta = {delta} rad turns the tractor tighter "
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
        raise ValueError(f"STM.steady_turn: no trim found at delta = {delta} rad, u = {u} m/s "
                         f"in {max_iter} Newton steps (last step {np.max(np.abs(dz)):.3g}); "
                         f"the turn may be past the tyres' or the hitch's reach: try a smaller "
                         f"|delta| or |u|")

    def _steady_slips(self, x: np.ndarray, u1: float, delta: float) -> np.ndarray:
        """Every axle's steady-state slip angle at state ``x`` [rad]."""
        _, _, _, _, Lc, _, _, ax_x, ax_steer, tr_l, _ = stm_unpack(self.P)
        v_long, v_lat = axle_velocities(u1, x[4], x[5], x[3], x[6], delta, ax_x, ax_steer,
                                        tr_l, Lc)
        return np.array([slip_angle(a, b) for a, b in zip(v_long, v_lat, strict=True)])
