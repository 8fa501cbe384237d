"""The semitrailer's channels from a tractor-only log and the articulation angle.

Many trucks log one GNSS/inertial unit on the tractor and a hitch-angle
sensor, not a second unit on the semitrailer. For a rigid tractor and
semitrailer joined at the kingpin, the tractor's pose and motion and the
articulation angle ``gamma`` fix the semitrailer's, through the vehicle's
geometry (:class:`artic.mjcf.vehicle.Vehicle`: the sensor positions and ``L1c``):

- yaw ``psi_2 = psi_1 - gamma`` and yaw rate ``r_2 = r_1 - gamma_dot``;
- the kingpin ``K`` sits at ``(L1c, 0)`` in the tractor frame, the tractor
  sensor at ``s1``, the semitrailer sensor at ``s2`` in the semitrailer frame
  (origin at the kingpin): ``p_2 = p_1 + R(psi_1) (K - s1) + R(psi_2) s2``;
- velocities by rigid-body kinematics, ``v_K = v_1 + r_1 x (p_K - p_1)`` and
  ``v_2 = v_K + r_2 x (p_2 - p_K)``, expressed in the semitrailer's axes.

``gamma_dot`` is the hitch sensor's rate channel when the log has one, and
otherwise the derivative of ``gamma`` (central differences). The sensor
heights are ignored: the derivation is planar, as the signal schema is.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from artic.mjcf.interface import wrap_angle
from artic.mjcf.vehicle import Vehicle

TRAILER = ("x_2", "y_2", "psi_2", "v_x_2", "v_y_2", "r_2")
"""The semitrailer's channels that :func:`derive_trailer` makes."""


def _rot(psi: np.ndarray, x, y) -> tuple[np.ndarray, np.ndarray]:
    c, s = np.cos(psi), np.sin(psi)
    return c * x - s * y, s * x + c * y


def derive_trailer(frame: pd.DataFrame, vehicle: Vehicle,
                   gamma_rate: np.ndarray | None = None) -> tuple[pd.DataFrame, str]:
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
    gamma = np.unwrap(frame["gamma"].to_numpy(dtype=float))
    if gamma_rate is None:
        gamma_dot = np.gradient(gamma, t)
        rate_from = "the derivative of gamma"
    else:
        gamma_dot = np.asarray(gamma_rate, dtype=float)
        rate_from = "the articulation-rate channel"
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
