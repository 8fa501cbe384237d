"""KIN linearised about a straight path, and the LQR gains of the path followers.

The linearisation is :meth:`artic.reduced.control.KIN.linearise`, KIN's
analytic Jacobians (:mod:`artic.reduced.jacobians`); nothing here
differentiates eq. (1) again.

Path following works in **distance**: per metre of tractor travel, KIN is the
same at every speed (``u1 = +-1``). Its errors about a straight path along x:

- reversing, the semitrailer's axle: ``z = (e_y2, e_psi2, e_gamma)``, lateral
  offset of KIN's semitrailer axle, semitrailer heading and articulation. The
  axle lies at ``Y + L1c sin(psi_1) - L2 sin(psi_1 - gamma)``, so about the
  straight path ``z = T (Y, psi_1, gamma)`` with
  ``T = [[1, L1c - L2, L2], [0, 1, -1], [0, 0, 1]]``;
- forward, the tractor's point: ``z = (e_y1, e_psi1)``.

A controller sampled every ``dt`` at speed ``u`` sees the distance step
``|u| dt``: :func:`gains` discretises the model over that step and solves the
discrete LQR, so that the gains are scheduled with speed.
"""

from __future__ import annotations

import numpy as np
from scipy.linalg import expm, solve_discrete_are

from artic.reduced.control import KIN


def linearise(kin: KIN, direction: float) -> tuple[np.ndarray, np.ndarray]:
    """KIN's Jacobians ``A`` (4x4) and ``B`` (4x1, the road-wheel angle's) per metre of travel.

    About the straight path along x, ``u1 = direction`` (``+1`` forward,
    ``-1`` reverse): :meth:`artic.reduced.control.KIN.linearise` at
    :meth:`~artic.reduced.control.KIN.straight`.
    """
    x0, u0 = kin.straight(float(direction))
    A, B = kin.linearise(x0, u0)
    return A, B[:, kin.find_input("delta")].reshape(4, 1)


def trailer_error_model(kin: KIN, direction: float) -> tuple[np.ndarray, np.ndarray]:
    """Per-metre model of the semitrailer axle's errors ``(e_y2, e_psi2, e_gamma)``.

    Parameters
    ----------
    kin : KIN
        The vehicle's KIN.
    direction : float
        ``+1`` forward, ``-1`` reverse.
    """
    A, B = linearise(kin, direction)
    p = kin.params
    T = np.array([[1.0, p.L1c - p.L2, p.L2], [0.0, 1.0, -1.0], [0.0, 0.0, 1.0]])
    sub = [1, 2, 3]  # Y, psi_1, gamma: X enters nothing
    Ti = np.linalg.inv(T)
    return T @ A[np.ix_(sub, sub)] @ Ti, T @ B[sub]


def tractor_error_model(kin: KIN, direction: float) -> tuple[np.ndarray, np.ndarray]:
    """Per-metre model of the tractor point's errors ``(e_y1, e_psi1)``."""
    A, B = linearise(kin, direction)
    sub = [1, 2]
    return A[np.ix_(sub, sub)], B[sub]


def discretise(A: np.ndarray, B: np.ndarray, ds: float) -> tuple[np.ndarray, np.ndarray]:
    """Zero-order-hold discretisation over ``ds`` [m] (the input held over the step)."""
    n, m = B.shape
    M = np.zeros((n + m, n + m))
    M[:n, :n] = A * ds
    M[:n, n:] = B * ds
    E = expm(M)
    return E[:n, :n], E[:n, n:]


def lqr(A: np.ndarray, B: np.ndarray, Q: np.ndarray, R: np.ndarray, ds: float) -> np.ndarray:
    """Discrete LQR gain ``K`` (``delta = -K z``) of the model over a step ``ds`` [m]."""
    Ad, Bd = discretise(A, B, ds)
    S = solve_discrete_are(Ad, Bd, Q, R)
    return np.linalg.solve(R + Bd.T @ S @ Bd, Bd.T @ S @ Ad)


def with_steering_state(A: np.ndarray, B: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The model with the road-wheel angle as a state and its rate per metre as the input.

    ``d/ds (z, delta) = [[A, B], [0, 0]] (z, delta) + [0, 1] ddelta/ds``: the
    controller turns the steering wheel at a finite rate, and the LQR weighs
    that rate.
    """
    n = A.shape[0]
    Aa = np.zeros((n + 1, n + 1))
    Aa[:n, :n] = A
    Aa[:n, n:] = B
    Ba = np.zeros((n + 1, 1))
    Ba[n, 0] = 1.0
    return Aa, Ba


REVERSE_WEIGHTS = (0.1, np.radians(1.0), np.radians(5.0), np.radians(20.0), 0.1)
"""Bryson's rule for the reversing path follower: the sizes that each cost as
much (semitrailer axle offset [m], heading and articulation [rad], road-wheel
angle [rad], and its rate per metre of travel [rad/m]). Chosen among a few
on the plant (straight, alley and bay dock of gosar2022-unloaded, six starts
each): the set with the smallest final errors that never oscillated."""

APPROACH_WEIGHTS = (0.2, np.radians(4.0), np.radians(10.0), np.radians(20.0), 0.05)
"""The same for the planner's final approach (:mod:`artic.validation.docking.planner`):
gentler, chosen over a grid for KIN reversing onto a line from 20-30 m out,
0.5-4 m off or 5 deg askew, with the steering rate limited as the planner
limits it: the set that landed most often and closest. The path it shapes
is then the follower's to hold."""

FORWARD_WEIGHTS = (0.3, np.radians(5.0), np.radians(20.0), 0.05)
"""The same for driving forward (tractor offset [m], heading [rad], steer [rad],
steer rate [rad/m])."""


_CACHE: dict[tuple, np.ndarray] = {}


def gains(kin: KIN, direction: int, ds: float,
          weights: tuple[float, ...] | None = None) -> np.ndarray:
    """LQR gains of the path follower for a distance step ``ds`` [m].

    The state is the errors and the road-wheel angle's departure from the
    path's, the input the steering rate per metre: ``ddelta/ds = -K (z, delta - delta_path)``.

    Parameters
    ----------
    kin : KIN
        The vehicle's KIN.
    direction : int
        ``-1``: semitrailer-axle errors, reversing; ``+1``: tractor errors, forward.
    ds : float
        Travel per control step, ``|u| dt`` [m]; rounded to the millimetre, so
        that the gains of nearby speeds are computed once per process.
    weights : tuple of float, optional
        :data:`REVERSE_WEIGHTS` or :data:`FORWARD_WEIGHTS` by default.
    """
    d = int(np.sign(direction))
    w = tuple(float(x) for x in (weights or (REVERSE_WEIGHTS if d < 0 else FORWARD_WEIGHTS)))
    ds = max(round(float(ds), 3), 1e-3)
    key = (tuple(float(p) for p in kin.P), d, ds, w)
    if key not in _CACHE:
        model = trailer_error_model if d < 0 else tractor_error_model
        A, B = with_steering_state(*model(kin, float(d)))
        Q = np.diag([1.0 / x ** 2 for x in w[:-1]])
        R = np.array([[1.0 / w[-1] ** 2]])
        _CACHE[key] = lqr(A, B, Q, R, ds)[0]
    return _CACHE[key].copy()


SCHEDULE_SPEEDS = np.linspace(0.1, 2.0, 20)
"""Speeds of the gain schedule [m/s]: 0.1 m/s apart, from a crawl past the yard's limit."""


class GainSchedule:
    """LQR gains tabulated over speed and interpolated, for a controller sampled every ``dt``.

    With the gains it tabulates the design model over one sample, so that a
    controller can predict its own closed loop (:meth:`closed_loop`).

    Parameters
    ----------
    kin : KIN
        The vehicle's KIN.
    direction : int
        ``-1`` reversing, ``+1`` forward.
    dt : float
        Sample period [s].
    weights : tuple of float, optional
        As :func:`gains`.
    """

    def __init__(self, kin: KIN, direction: int, dt: float,
                 weights: tuple[float, ...] | None = None) -> None:
        self.speeds = SCHEDULE_SPEEDS
        self.table = np.array([gains(kin, direction, v * dt, weights) for v in self.speeds])
        d = float(np.sign(direction))
        model = trailer_error_model if d < 0 else tractor_error_model
        A, B = with_steering_state(*model(kin, d))
        steps = [discretise(A, B, v * dt) for v in self.speeds]
        self.Ad = np.array([a for a, _ in steps])
        self.Bd = np.array([b for _, b in steps])

    def __call__(self, speed: float) -> np.ndarray:
        """The gains at ``|speed|`` [m/s], interpolated (held beyond the table's ends)."""
        v = abs(float(speed))
        return np.array([np.interp(v, self.speeds, col) for col in self.table.T])

    def closed_loop(self, speed: float) -> np.ndarray:
        """The errors' transition over a sample at ``|speed|`` [m/s] under the gains, ``Ad - Bd K``.

        ``(z, delta - delta_path)`` one sample on is this matrix times its value
        now, on the design model (KIN linearised about the path) with the
        gains of :meth:`__call__`; the model over the sample is interpolated
        over the table's speeds as the gains are (``expm(A |u| dt)`` is smooth
        in the speed: with the table's 0.1 m/s steps the interpolation errs by
        at most 1.1e-4 of ``Ad - I``, at the slowest speeds).
        """
        v = min(max(abs(float(speed)), self.speeds[0]), self.speeds[-1])
        i = min(int(np.searchsorted(self.speeds, v, side="right")) - 1, len(self.speeds) - 2)
        w = (v - self.speeds[i]) / (self.speeds[i + 1] - self.speeds[i])
        Ad = (1.0 - w) * self.Ad[i] + w * self.Ad[i + 1]
        Bd = (1.0 - w) * self.Bd[i] + w * self.Bd[i + 1]
        return Ad - Bd @ self(v)[None, :]
