"""The log checks' thresholds for a vehicle's size and speed range.

The structural limits of :data:`artic.validation.logs.schema.PLAUSIBLE` (a speed
beyond them is km/h read as m/s), the GNSS-jump distance
(:data:`artic.validation.logs.checks.MAX_JUMP`) and the consistency checks'
distances and speed floors (:mod:`artic.validation.logs.consistency`) were set for
full-size tractor-semitrailers. A scale model covers the same manoeuvres at a
fraction of the length and, by Froude similitude (the same ratio of lateral
acceleration to gravity), of the speed: lengths scale by ``length`` =
:attr:`artic.mjcf.vehicle.Vehicle.length_ratio`, speeds by ``speed = sqrt(length)``,
times by ``sqrt(length)`` and yaw rates by ``1 / sqrt(length)``. Angles, and the
noise of the heading, are the same at any scale. A full-size vehicle, and a log
checked without a vehicle, keep the full-size thresholds (``length = 1``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from artic.validation.logs.schema import PLAUSIBLE

_KIND = {"r_1": "rate", "r_2": "rate", "v_x_1": "speed", "v_x_2": "speed",
         "v_y_1": "speed", "v_y_2": "speed", "gamma": "angle", "delta_h": "angle"}


@dataclass(frozen=True)
class LogScale:
    """How a vehicle's logs scale against the full-size reference.

    Parameters
    ----------
    length : float
        Length ratio [-]; 1 for full-size.
    """

    length: float = 1.0

    @classmethod
    def of(cls, vehicle=None) -> LogScale:
        """The scale of ``vehicle``'s logs (full-size without one)."""
        return cls(1.0 if vehicle is None else float(vehicle.length_ratio))

    @property
    def speed(self) -> float:
        """Speed ratio ``sqrt(length)`` [-]."""
        return math.sqrt(self.length)

    def distance(self, d: float) -> float:
        """A full-size distance [m] at this scale."""
        return d * self.length

    def speed_of(self, v: float) -> float:
        """A full-size speed [m/s] at this scale."""
        return v * self.speed

    @property
    def plausible(self) -> dict[str, float]:
        """:data:`~artic.validation.logs.schema.PLAUSIBLE` at this scale [SI]."""
        factor = {"rate": 1.0 / self.speed, "speed": self.speed, "angle": 1.0}
        return {c: v * factor[_KIND[c]] for c, v in PLAUSIBLE.items()}


FULL_SIZE = LogScale()
"""The scale every threshold was set for."""
