"""KIN: the single-axle kinematic tractor-semitrailer model, eq. (1).

No axle slips sideways: the tractor turns about a point on its drive-axle
line and the semitrailer about a point on its equivalent axle, ``L2`` behind
the kingpin. With the fifth wheel ``L1c`` ahead of the drive axle,

    psi_1_dot = u1 tan(delta) / L1
    gamma_dot = -u1 sin(gamma) / L2 + (1 - L1c cos(gamma) / L2) u1 tan(delta) / L1

Derivation: the hitch moves at ``(u1, r1 L1c)`` in tractor axes. The trailer
axle does not slip, so the trailer yaw rate is the hitch velocity across the
trailer, ``u1 sin(gamma) + r1 L1c cos(gamma)``, over ``L2``; and
``gamma_dot = r1 - r2``.

State: ``[X, Y, psi_1, gamma]`` with ``(X, Y)`` the centre of the tractor's
(equivalent) rear axle [m] (not its centre of gravity, as in the STM, nor the
sensor, as in logs: :class:`artic.KIN` says which point each model's states
describe).

**Equivalent wheelbases.** A unit with several unsteered axles has no axle
that does not slip: at low speed its axles scrub. The semitrailer's tridem
turns about the point where its lateral velocity is zero, and its scrub pushes
on the hitch, which makes the tractor's axles slip too. KIN takes this in
through equivalent lengths from the low-speed steady turn of the linear
single-track model (Winkler's analysis of the steady turning of complex
vehicles): side forces ``C_i alpha_i`` with ``C_i = f Fz_i``, no inertia, small
angles, so that every slip is geometric and ``f`` cancels.

- Semitrailer: no moment about the kingpin puts its no-slip point at
  ``L2 = l_0 = sum C_i l_i^2 / sum C_i l_i`` behind the kingpin (Fancher's
  effective wheelbase; for an equal tandem of spread ``s`` about ``l`` it is
  ``l + s^2 / (4 l)``). Its tyres' net force ``rho sum C_i (l_i - l_0)``,
  ``rho`` the path curvature, acts on the tractor at the hitch.
- Tractor: force and moment balance of its axles and that hitch force give,
  per radian of steer, its curvature and the lateral slip of its drive-axle
  point. ``L1 = delta / rho``, and the tractor turns about its no-slip point
  ``x_n`` on its centre line, which becomes KIN's rear axle:
  ``L1c = x_hitch - x_n``.

This is the default (``wheelbase="equivalent"``). For a 4x2 tractor with a
single-axle trailer it is the paper's geometry exactly. ``wheelbase="paper"``
keeps the paper's choice: the drive axle and the middle trailer axle, ``L1``
and ``L2``.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from artic.mjcf.errors import UnsupportedVehicleError, UserError
from artic.mjcf.vehicle import Vehicle
from artic.reduced.sensors import sensor_signals


@njit(cache=True)
def kin_rhs(x, u1, u1_dot, delta, P):
    """Time derivative of the KIN state, eq. (1).

    Parameters
    ----------
    x : ndarray, shape (4,)
        ``[X, Y, psi_1, gamma]`` [m, m, rad, rad].
    u1 : float
        Drive-axle longitudinal speed [m/s].
    u1_dot : float
        Its rate [m/s^2] (unused: KIN has no inertia).
    delta : float
        Road-wheel angle [rad].
    P : ndarray
        ``[L1, L1c, L2]`` [m], see :func:`kin_parameters`.
    """
    out = np.empty(4)
    kin_rhs_into(x, u1, u1_dot, delta, P, out)
    return out


@njit(cache=True)
def kin_rhs_into(x, u1, u1_dot, delta, P, out):
    """:func:`kin_rhs` written into ``out`` (shape (4,)), allocating nothing.

    The one copy of eq. (1): :func:`kin_rhs` and the batched steps of
    :mod:`artic.reduced.integrate` both call it, so they agree to the bit.
    """
    out[0], out[1], out[2], out[3] = kin_rates(x[2], x[3], u1, delta, P[0], P[1], P[2])


@njit(cache=True)
def kin_rates(psi, gamma, u1, delta, L1, L1c, L2):
    """Eq. (1) of scalars: ``(X_dot, Y_dot, psi_1_dot, gamma_dot)`` [m/s, m/s, rad/s, rad/s].

    The one copy of KIN's equations (:func:`kin_rhs`, :func:`kin_rhs_into`
    and :func:`artic.reduced.integrate.rk4_step_into` call it): scalars in and
    out, so that a compiled loop over a batch allocates nothing per step.
    """
    r1 = u1 * math.tan(delta) / L1
    return (u1 * math.cos(psi), u1 * math.sin(psi), r1,
            -u1 * math.sin(gamma) / L2 + (1.0 - L1c * math.cos(gamma) / L2) * r1)


@njit(cache=True)
def kin_observe(x, u1, delta, P, s1, s2):
    """Signals at the two sensor points, in ``OBSERVATION`` order.

    Parameters
    ----------
    x : ndarray, shape (4,)
        State.
    u1 : float
        Drive-axle longitudinal speed [m/s].
    delta : float
        Road-wheel angle [rad].
    P : ndarray
        ``[L1, L1c, L2]`` [m].
    s1 : ndarray, shape (2,)
        Tractor sensor ``(x, y)`` from the drive axle [m].
    s2 : ndarray, shape (2,)
        Semitrailer sensor ``(x, y)`` from the kingpin [m].
    """
    L1, L1c, L2 = P[0], P[1], P[2]
    gamma = x[3]
    r1 = u1 * math.tan(delta) / L1
    r2 = (u1 * math.sin(gamma) + r1 * L1c * math.cos(gamma)) / L2
    return sensor_signals(x[0], x[1], x[2], gamma, u1, 0.0, r1, r2, L1c, (s1, s2))


WHEELBASES = ("equivalent", "paper")
"""Choices of KIN's wheelbases (see the module docstring)."""


def equivalent_length(d: np.ndarray, C: np.ndarray) -> float:
    """``sum C d^2 / sum C d``: the no-slip point of an axle group [m].

    Parameters
    ----------
    d : ndarray
        Axle distances from the point that carries the unit's other force [m].
    C : ndarray
        Their cornering stiffnesses (any common unit, or loads).
    """
    return float(np.sum(C * d ** 2) / np.sum(C * d))


def wheelbases(vehicle: Vehicle, wheelbase: str = "equivalent") -> tuple[float, float, float]:
    """KIN's tractor lengths ``(L1, L1c, x_rear)`` [m]; see the module docstring.

    ``x_rear`` is the tractor's (equivalent) rear axle, its no-slip point, on
    the drive-axle frame's x-axis [m]: zero for the paper's choice.
    """
    if wheelbase == "paper":
        return vehicle.L1, vehicle.L1c, 0.0
    n1 = len(vehicle.tractor_axles)
    C = vehicle.static_loads  # proportional to the cornering stiffnesses; f cancels
    ell = vehicle.trailer_axle_distances
    Ct = C[n1:]
    l0 = equivalent_length(ell, Ct)
    T = float(np.sum(Ct * (ell - l0)))  # trailer tyres' net force per unit curvature
    x = np.array([a.x for a in vehicle.tractor_axles])
    Cc = C[:n1]
    steer = np.array([1.0 if a.steered else 0.0 for a in vehicle.tractor_axles])
    x_h = vehicle.L1c
    # Slip of axle j: steer_j delta - beta - rho x_j, with beta the drive-axle
    # point's lateral velocity over u and rho the curvature. Force and moment
    # (about the drive axle) balance with the hitch force T rho at x_h:
    A = np.array([[Cc.sum(), (Cc * x).sum() - T],
                  [(Cc * x).sum(), (Cc * x * x).sum() - T * x_h]])
    b = np.array([(Cc * steer).sum(), (Cc * steer * x).sum()])
    beta, rho = np.linalg.solve(A, b)  # per radian of steer
    x_n = -beta / rho
    return float(1.0 / rho), float(x_h - x_n), float(x_n)


class KinParameters(NamedTuple):
    """KIN's parameters, by name [m].

    Attributes
    ----------
    L1 : float
        Tractor wheelbase: front axle to the (equivalent) rear axle [m].
    L1c : float
        Fifth wheel ahead of the (equivalent) rear axle [m].
    L2 : float
        Semitrailer's (equivalent) axle behind the kingpin [m].
    """

    L1: float
    L1c: float
    L2: float

    def packed(self) -> np.ndarray:
        """The flat array the compiled functions take, ``[L1, L1c, L2]`` [m]."""
        return np.array([self.L1, self.L1c, self.L2], dtype=float)


def kin_params(vehicle: Vehicle, wheelbase: str = "equivalent") -> KinParameters:
    """KIN's parameters of a vehicle, by name.

    Parameters
    ----------
    vehicle : Vehicle
        Geometry and static axle loads.
    wheelbase : str
        ``"equivalent"`` (default): the axle groups' no-slip points, see the
        module docstring; ``"paper"``: the drive axle and ``L2``.

    Raises
    ------
    UnsupportedVehicleError
        When a length is not positive and finite: KIN cannot represent the vehicle.
    """
    if wheelbase not in WHEELBASES:
        raise UserError(f"wheelbase {wheelbase!r}: expected one of {', '.join(WHEELBASES)}")
    L1, L1c, _ = wheelbases(vehicle, wheelbase)
    if wheelbase == "paper":
        L2 = vehicle.L2
    else:
        n1 = len(vehicle.tractor_axles)
        L2 = equivalent_length(vehicle.trailer_axle_distances, vehicle.static_loads[n1:])
    p = KinParameters(float(L1), float(L1c), float(L2))
    if not (math.isfinite(p.L1c) and all(math.isfinite(q) and q > 0.0 for q in (p.L1, p.L2))):
        raise UnsupportedVehicleError(
            f"{vehicle.path or vehicle.name}: KIN cannot represent this vehicle: its "
            f"({wheelbase}) wheelbases L1 = {p.L1:.4g} m, L2 = {p.L2:.4g} m must be positive "
            "and finite; check the axle positions and loads")
    return p


def kin_parameters(vehicle: Vehicle, wheelbase: str = "equivalent") -> np.ndarray:
    """KIN's parameters as the compiled functions take them, ``[L1, L1c, L2]`` [m].

    :func:`kin_params` packed (:meth:`KinParameters.packed`); see there for
    the parameters.
    """
    return kin_params(vehicle, wheelbase).packed()
