"""One unit's channels from the other's and the articulation angle.

Many trucks log one GNSS/inertial unit on the tractor and a hitch-angle
sensor, not a second unit on the semitrailer; many rigs track the semitrailer
instead (a tracker or GNSS on the trailer, an encoder at the kingpin). For a rigid tractor and
semitrailer joined at the kingpin, the tractor's pose and motion and the
articulation angle ``gamma`` fix the semitrailer's, through the vehicle's
geometry (:class:`artic.mjcf.vehicle.Vehicle`: the sensor positions and ``L1c``):

- yaw ``psi_2 = psi_1 - gamma`` and yaw rate ``r_2 = r_1 - gamma_dot``;
- the kingpin ``K`` sits at ``(L1c, 0)`` in the tractor frame, the tractor
  sensor at ``s1``, the semitrailer sensor at ``s2`` in the semitrailer frame
  (origin at the kingpin): ``p_2 = p_1 + R(psi_1) (K - s1) + R(psi_2) s2``;
- velocities by rigid-body kinematics, ``v_K = v_1 + r_1 x (p_K - p_1)`` and
  ``v_2 = v_K + r_2 x (p_2 - p_K)``, expressed in the semitrailer's axes.

:func:`derive_tractor` inverts the same relations: ``psi_1 = psi_2 + gamma``,
``r_1 = r_2 + gamma_dot``, ``p_K = p_2 - R(psi_2) s2``,
``p_1 = p_K - R(psi_1) (K - s1)``, and the velocities from the kingpin's.

``gamma_dot`` is the hitch sensor's rate channel when the log has one, and
otherwise the derivative of ``gamma`` (central differences, or the caller's
smoothing differentiator). The sensor
heights are ignored: the derivation is planar, as the signal schema is.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from artic.mjcf.interface import wrap_angle
from artic.mjcf.vehicle import Vehicle

TRAILER = ("x_2", "y_2", "psi_2", "v_x_2", "v_y_2", "r_2")
"""The semitrailer's channels that :func:`derive_trailer` makes."""

TRACTOR = ("x_1", "y_1", "psi_1", "v_x_1", "v_y_1", "r_1")
"""The tractor's channels that :func:`derive_tractor` makes."""


def _rot(psi: np.ndarray, x, y) -> tuple[np.ndarray, np.ndarray]:
    c, s = np.cos(psi), np.sin(psi)
    return c * x - s * y, s * x + c * y


def derive_trailer(frame: pd.DataFrame, vehicle: Vehicle, gamma_rate: np.ndarray | None = None,
                   rate_from: str | None = None) -> tuple[pd.DataFrame, str]:
    """Add the semitrailer's channels to a frame with the tractor's and ``gamma``.

    Parameters
    ----------
    frame : DataFrame
        ``t``, ``x_1``, ``y_1``, ``psi_1``, ``v_x_1``, ``v_y_1``, ``r_1`` and
        ``gamma`` in the signal schema's units [s, m, rad, m/s, rad/s].
    vehicle : Vehicle
        Its sensor positions and ``L1c`` [m].
    gamma_rate : ndarray, optional
        The articulation rate [rad/s]; differentiated from ``gamma`` when absent.
    rate_from : str, optional
        What ``gamma_rate`` is, for the note (default: the articulation-rate channel).

    Returns
    -------
    frame : DataFrame
        A copy with :data:`TRAILER` filled (and ``gamma`` wrapped).
    note : str
        One line saying what was derived and from what, for the run's
        metadata and the import report.
    """
    t = frame["t"].to_numpy(dtype=float)
    x1, y1, psi1 = (frame[c].to_numpy(dtype=float) for c in ("x_1", "y_1", "psi_1"))
    vx1, vy1, r1 = (frame[c].to_numpy(dtype=float) for c in ("v_x_1", "v_y_1", "r_1"))
    gamma, gamma_dot, rate_from = _gamma(frame, t, gamma_rate, rate_from)
    psi2 = psi1 - gamma
    r2 = r1 - gamma_dot
    s1x, s1y = vehicle.sensor1[0], vehicle.sensor1[1]
    s2x, s2y = vehicle.sensor2[0], vehicle.sensor2[1]
    dkx, dky = _rot(psi1, vehicle.L1c - s1x, -s1y)  # tractor sensor to kingpin, world
    d2x, d2y = _rot(psi2, s2x, s2y)  # kingpin to semitrailer sensor, world
    ve1, vn1 = _rot(psi1, vx1, vy1)
    vke, vkn = ve1 - r1 * dky, vn1 + r1 * dkx
    ve2, vn2 = vke - r2 * d2y, vkn + r2 * d2x
    vx2, vy2 = _rot(-psi2, ve2, vn2)
    out = frame.copy()
    out["x_2"], out["y_2"] = x1 + dkx + d2x, y1 + dky + d2y
    out["psi_2"], out["v_x_2"], out["v_y_2"], out["r_2"] = psi2, vx2, vy2, r2
    out["gamma"] = wrap_angle(gamma)
    note = (f"semitrailer channels {', '.join(TRAILER)} derived from the tractor's, the "
            f"articulation angle and {rate_from}, with the geometry of vehicle "
            f"'{vehicle.name}' (L1c = {vehicle.L1c:g} m, tractor sensor at ({s1x:g}, {s1y:g}) m, "
            f"semitrailer sensor at ({s2x:g}, {s2y:g}) m from the kingpin)")
    return out, note


def _gamma(frame: pd.DataFrame, t: np.ndarray, gamma_rate: np.ndarray | None,
           rate_from: str | None) -> tuple[np.ndarray, np.ndarray, str]:
    """Unwrapped ``gamma``, its rate, and what the rate is."""
    gamma = np.unwrap(frame["gamma"].to_numpy(dtype=float))
    if gamma_rate is None:
        return gamma, np.gradient(gamma, t), "the derivative of gamma"
    return gamma, np.asarray(gamma_rate, dtype=float), rate_from or "the articulation-rate channel"


def derive_tractor(frame: pd.DataFrame, vehicle: Vehicle, gamma_rate: np.ndarray | None = None,
                   rate_from: str | None = None) -> tuple[pd.DataFrame, str]:
    """Add the tractor's channels to a frame with the semitrailer's and ``gamma``.

    The mirror of :func:`derive_trailer` (see the module docstring).

    Parameters
    ----------
    frame : DataFrame
        ``t``, ``x_2``, ``y_2``, ``psi_2``, ``v_x_2``, ``v_y_2``, ``r_2`` and
        ``gamma`` in the signal schema's units [s, m, rad, m/s, rad/s].
    vehicle : Vehicle
        Its sensor positions and ``L1c`` [m].
    gamma_rate : ndarray, optional
        The articulation rate [rad/s]; differentiated from ``gamma`` when absent.
    rate_from : str, optional
        What ``gamma_rate`` is, for the note.

    Returns
    -------
    frame : DataFrame
        A copy with :data:`TRACTOR` filled (and ``gamma`` wrapped).
    note : str
        One line saying what was derived and from what.
    """
    t = frame["t"].to_numpy(dtype=float)
    x2, y2, psi2 = (frame[c].to_numpy(dtype=float) for c in ("x_2", "y_2", "psi_2"))
    vx2, vy2, r2 = (frame[c].to_numpy(dtype=float) for c in ("v_x_2", "v_y_2", "r_2"))
    gamma, gamma_dot, rate_from = _gamma(frame, t, gamma_rate, rate_from)
    psi1 = psi2 + gamma
    r1 = r2 + gamma_dot
    s1x, s1y = vehicle.sensor1[0], vehicle.sensor1[1]
    s2x, s2y = vehicle.sensor2[0], vehicle.sensor2[1]
    d2x, d2y = _rot(psi2, s2x, s2y)  # kingpin to semitrailer sensor, world
    dkx, dky = _rot(psi1, vehicle.L1c - s1x, -s1y)  # tractor sensor to kingpin, world
    ve2, vn2 = _rot(psi2, vx2, vy2)
    vke, vkn = ve2 + r2 * d2y, vn2 - r2 * d2x
    ve1, vn1 = vke + r1 * dky, vkn - r1 * dkx
    vx1, vy1 = _rot(-psi1, ve1, vn1)
    out = frame.copy()
    out["x_1"], out["y_1"] = x2 - d2x - dkx, y2 - d2y - dky
    out["psi_1"], out["v_x_1"], out["v_y_1"], out["r_1"] = psi1, vx1, vy1, r1
    out["gamma"] = wrap_angle(gamma)
    note = (f"tractor channels {', '.join(TRACTOR)} derived from the semitrailer's, the "
            f"articulation angle and {rate_from}, with the geometry of vehicle "
            f"'{vehicle.name}' (L1c = {vehicle.L1c:g} m, tractor sensor at ({s1x:g}, {s1y:g}) m, "
            f"semitrailer sensor at ({s2x:g}, {s2y:g}) m from the kingpin)")
    return out, note
