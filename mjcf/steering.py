"""The steering map of eq. (3): its parameters, and steering-wheel angle to road-wheel angle.

``delta = (d - q d**2) / i_s`` with ``d = delta_h - delta_h_offset``.

A positive ``q`` lowers the road-wheel angle for left turns (``d > 0``) and
raises it for right turns, as a tie-rod linkage driven from the left wheel
does. The map is monotonic only while ``d < 1 / (2 q)``; :class:`Steering`
refuses a range in use beyond that instead of folding back silently.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from artic.mjcf.errors import UserError


class SteeringRangeError(UserError):
    """The steering-wheel angles in use reach the fold of the quadratic map."""


@dataclass(frozen=True)
class Steering:
    """The steering map of eq. (3) and its parameters, as the vehicle file gives them.

    Parameters
    ----------
    i_s : float
        Steering ratio [-].
    q : float
        Asymmetry factor [1/rad].
    delta_h_offset : float
        Steering-wheel angle read while driving straight [rad].
    delta_max : float
        Largest road-wheel angle [rad].
    steering_arm : float
        Steering-arm length of the tie-rod trapezoid [m].
    """

    i_s: float
    q: float
    delta_h_offset: float
    delta_max: float
    steering_arm: float = 0.25

    @property
    def fold(self) -> float:
        """Offset-free steering-wheel angle where the map stops rising [rad].

        Positive for ``q > 0`` (left turns), negative for ``q < 0``.
        """
        return np.inf if self.q == 0 else 1.0 / (2.0 * self.q)

    def check_range(self, delta_h: np.ndarray, source: str = "input") -> None:
        """Refuse steering-wheel angles past the fold of the map.

        Parameters
        ----------
        delta_h : array_like
            Steering-wheel angles in use [rad].
        source : str
            What the angles came from, for the message.

        Raises
        ------
        SteeringRangeError
            If any angle reaches 95 % of the fold, where the slope has fallen
            to a tenth of its value at zero.
        """
        d = np.asarray(delta_h, dtype=float) - self.delta_h_offset
        if d.size == 0 or not np.isfinite(self.fold):
            return
        # Rising while 1 - 2 q d > 0: the fold is on the side q points to.
        peak = float(np.nanmax(d) if self.q > 0 else np.nanmin(d))
        if peak / self.fold >= 0.95:
            raise SteeringRangeError(
                f"{source}: steering-wheel angle reaches {np.degrees(peak):.0f} deg past the "
                f"offset, but eq. (3) with q = {self.q} /rad stops being monotonic at "
                f"{np.degrees(self.fold):.0f} deg. Lower q (a tie-rod linkage gives about "
                f"0.01 /rad) or check that delta_h is in radians.")

    def road_wheel(self, delta_h: np.ndarray | float) -> np.ndarray | float:
        """Road-wheel angle at the centre of the front axle [rad].

        Parameters
        ----------
        delta_h : float or ndarray
            Steering-wheel angle as measured, offset included [rad].
        """
        if isinstance(delta_h, float):  # the loops' per-step path, the same arithmetic
            d = delta_h - self.delta_h_offset
            return float((d - self.q * d * d) / self.i_s)
        d = np.asarray(delta_h, dtype=float) - self.delta_h_offset
        out = (d - self.q * d * d) / self.i_s
        return float(out) if out.ndim == 0 else out

    def steering_wheel(self, delta: np.ndarray | float) -> np.ndarray | float:
        """Inverse map: the steering-wheel angle that gives a road-wheel angle [rad].

        Parameters
        ----------
        delta : float or ndarray
            Road-wheel angle [rad]; must lie below the map's maximum
            ``fold / (2 i_s)``.
        """
        if isinstance(delta, float):  # the per-step path, the same arithmetic
            x = delta * self.i_s
            disc = 1.0 - 4.0 * self.q * x
            if self.q == 0:
                return float(x + self.delta_h_offset)
            if disc >= 0.0:  # (IEEE square roots are exact-rounded in math and numpy alike)
                return float(2.0 * x / (1.0 + math.sqrt(disc)) + self.delta_h_offset)
        x = np.asarray(delta, dtype=float) * self.i_s
        if self.q == 0:
            d = x
        else:
            disc = 1.0 - 4.0 * self.q * x
            if np.any(disc < 0):
                raise SteeringRangeError(
                    f"road-wheel angle {np.degrees(np.max(x) / self.i_s):.1f} deg is beyond "
                    f"what eq. (3) with q = {self.q} /rad reaches")
            # The root on the rising branch, written to stay accurate as q -> 0.
            d = 2.0 * x / (1.0 + np.sqrt(disc))
        out = d + self.delta_h_offset
        return float(out) if out.ndim == 0 else out
