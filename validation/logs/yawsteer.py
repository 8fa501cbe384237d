"""Steering from the measured yaw rate, for logs without a steering channel.

``--steer-from yaw-rate`` (and any log whose ``delta_h`` was derived at
import) drives every model with the road-wheel angle that makes its tractor
turn as the measured one does in a low-speed steady turn:

    delta = atan(L1 r_1 u_1 / (u_1**2 + u_eps**2))

with ``u_1`` the tractor's speed and ``r_1`` its measured yaw rate (both
smoothed as the harness smooths the speed), and ``L1`` the equivalent
wheelbase of :func:`artic.reduced.kinematic.wheelbases`: KIN's own, and the
low-speed steady-turn curvature per steer of the linear single-track model,
so the inverse is exact for KIN and holds for the STM and the plant up to
their understeer and tyre lag.

The plain inverse ``atan(L1 r_1 / u_1)`` is ill-conditioned near standstill,
where noise on ``r_1`` over a speed near zero makes any angle. The
regularised form equals it to within ``(u_eps / u_1)**2`` once
``|u_1| >> u_eps`` and fades to zero below, where the steering hardly
moves the vehicle: a tractor that creeps through a distance ``s`` below
``u_eps`` loses at most the curvature times ``s`` of heading.
``u_eps`` is :data:`SPEED_FLOOR` times the log's 95th-percentile speed, so the
floor scales with the vehicle and its manoeuvre (5 cm/s for a truck at 1 m/s,
5 mm/s for a scale model at 0.1 m/s).

What it means for the criteria: the tractor then follows the measured yaw
rate by construction (for KIN exactly), so ``eps_r1`` and ``eps_y1`` no
longer test the models' steering response; the comparison is about the
semitrailer (``eps_y2``, ``eps_r2``, ``eps_vy2`` and the articulation).
``J_steer`` is relative to this derived road-wheel angle.
"""

from __future__ import annotations

import numpy as np

from artic.mjcf.vehicle import Vehicle

SPEED_FLOOR = 0.05
"""``u_eps`` as a fraction of the log's 95th-percentile speed [-]."""

MODES = ("log", "yaw-rate")
"""Values of ``--steer-from``: the log's steering wheel (unless it was derived), or the yaw rate."""


def speed_floor(u1: np.ndarray) -> float:
    """``u_eps`` of a log [m/s] (see the module docstring); 1 mm/s at the least."""
    u = np.abs(np.asarray(u1, dtype=float))
    return max(SPEED_FLOOR * float(np.percentile(u, 95)) if u.size else 0.0, 1e-3)


def equivalent_wheelbase(vehicle: Vehicle) -> float:
    """The tractor's low-speed steady-turn wheelbase ``L1`` [m] (KIN's)."""
    # Here, not at the top: numba loads only for a log steered from its yaw rate.
    from artic.reduced.kinematic import wheelbases

    return wheelbases(vehicle)[0]


def road_wheel_from_yaw_rate(u1: np.ndarray, r1: np.ndarray, L1: float,
                             u_eps: float | None = None) -> np.ndarray:
    """The road-wheel angle that turns the tractor at ``r1`` [rad].

    Parameters
    ----------
    u1 : ndarray
        Tractor speed, signed [m/s].
    r1 : ndarray
        Tractor yaw rate [rad/s].
    L1 : float
        Equivalent wheelbase [m].
    u_eps : float, optional
        Speed floor [m/s]; :func:`speed_floor` of ``u1`` by default.
    """
    u1 = np.asarray(u1, dtype=float)
    u_eps = speed_floor(u1) if u_eps is None else float(u_eps)
    return np.arctan(L1 * np.asarray(r1, dtype=float) * u1 / (u1 * u1 + u_eps * u_eps))


def wants_yaw_rate(meta: dict) -> bool:
    """Whether a log is steered from its yaw rate: asked for, or its ``delta_h`` was derived."""
    derived = meta.get("derived") or {}
    return meta.get("steer_from") == "yaw-rate" or "delta_h" in derived.get("channels", [])


def steering_wheel(smap, delta: np.ndarray, delta_max: float) -> np.ndarray:
    """The steering-wheel angle that gives ``delta`` through ``smap``, for the record [rad].

    ``delta`` is limited to ``delta_max`` and to the map's reach (its fold) first.

    Parameters
    ----------
    smap : Steering
        Eq. (3) of a model.
    delta : ndarray
        Road-wheel angle [rad].
    delta_max : float
        The vehicle's lock [rad].
    """
    reach = delta_max
    if smap.q:  # the inverse ends at the fold's road-wheel angle, 1 / (4 q i_s)
        reach = min(reach, 0.95 * abs(smap.fold) / (2.0 * smap.i_s))
    return np.asarray(smap.steering_wheel(np.clip(delta, -reach, reach)))
