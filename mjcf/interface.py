"""What every model shares with the harness: signals, initial state, angle helpers.

KIN, STM and the multibody plant are each built from a
:class:`artic.mjcf.vehicle.Vehicle` and driven by the harness through the calls of
:class:`artic.validation.models.Model`: reset to an :class:`InitialState`, step, and
observe the :data:`OBSERVATION` signals at the two sensor points.

``u1`` is the longitudinal velocity of the tractor in its own axes. For a rigid
tractor it is the same at every point on its centre line, so the drive axle,
the centre of gravity and a sensor with ``y = 0`` all see it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

OBSERVATION = (
    "x_1", "y_1", "psi_1", "v_x_1", "v_y_1", "r_1",
    "x_2", "y_2", "psi_2", "v_x_2", "v_y_2", "r_2",
    "gamma",
)
"""Observed signals, in the order ``observe()`` returns them (SI, ISO 8855)."""

OBS_INDEX = {name: i for i, name in enumerate(OBSERVATION)}


@dataclass(frozen=True)
class InitialState:
    """Pose and motion of the combination at the start of a run.

    Parameters
    ----------
    x_1, y_1 : float
        Tractor sensor position in the earth-fixed plane [m].
    psi_1 : float
        Tractor yaw [rad].
    gamma : float
        Articulation angle ``psi_1 - psi_2`` [rad].
    v_y_1 : float
        Lateral velocity of the tractor sensor in tractor axes [m/s].
    r_1, r_2 : float
        Yaw rates of tractor and semitrailer [rad/s].
    u1 : float
        Tractor longitudinal speed [m/s].
    delta : float
        Road-wheel angle at the start [rad]: a log that starts in a turn (a
        segment after a gap) has its steered tyres at that angle's slip.
    """

    x_1: float
    y_1: float
    psi_1: float
    gamma: float
    v_y_1: float = 0.0
    r_1: float = 0.0
    r_2: float = 0.0
    u1: float = 0.0
    delta: float = 0.0


def wrap_angle(a: float | np.ndarray) -> float | np.ndarray:
    """Wrap an angle to (-pi, pi] [rad].

    A Python float takes the scalar path (the simulation loops call this per
    step): Python's float ``%`` and ``np.mod`` both take ``fmod`` and add the
    divisor when the signs differ, so the two paths agree to the bit.
    """
    if isinstance(a, float):  # float and numpy.float64
        return float(math.pi - (math.pi - a) % (2.0 * math.pi))
    out = np.pi - np.mod(np.pi - np.asarray(a, dtype=float), 2.0 * np.pi)
    return float(out) if out.ndim == 0 else out


def rotate(psi: float, x: float, y: float) -> tuple[float, float]:
    """Rotate a body-frame vector by yaw ``psi`` into the earth-fixed plane."""
    c, s = math.cos(psi), math.sin(psi)
    return c * x - s * y, s * x + c * y


class LoopArgs(NamedTuple):
    """A log's arguments to a closed loop, whichever loop runs it (one object, not nine).

    The harness's Python loop, the reduced models' compiled loop
    (:mod:`artic.validation.harness.reducedloop`) and the plant's loop in C
    (:func:`artic.plant.closedloop.run`) take it. A named tuple, immutable, so
    that numba's loop takes it as a plain tuple.
    """

    dt: np.ndarray
    """Step to the next sample [s], one fewer than the samples (or as many)."""
    delta_c: np.ndarray
    """Road-wheel angle from the steering map, per sample [rad]."""
    u1: np.ndarray
    """Tractor speed, per sample [m/s]."""
    u1_dot: np.ndarray
    """Its rate, per sample [m/s^2]."""
    gamma_meas: np.ndarray
    """The log's articulation, per sample [rad]."""
    weight: np.ndarray
    """The reversing feedback's weight in [0, 1], per sample [-]."""
    gain: float
    """Feedback gain K [rad/rad]."""
    delta_max: float
    """Road-wheel limit [rad]."""
    gamma_max: float
    """Jackknife limit [rad]."""
