"""Body outlines and the yard: the one source of how big each unit is and where the dock is.

The MJCF builder draws the bodies with these outlines, the docking driver
backs the trailer's rear to the dock face, and the recordings draw the same
boxes and the same dock. None of them keeps a length of its own.

Lengths along x are in each unit's own frame, ISO (x forward): the tractor's
origin is its drive axle, the semitrailer's its kingpin. The defaults are
those of an EU 13.6 m box semitrailer (kingpin 1.6 m behind the front wall)
and of a cab-over tractor; the trailer's rear lies behind its last axle and
behind its own sensor, which sits on the trailer.
"""

from __future__ import annotations

from dataclasses import dataclass

from artic.mjcf.vehicle import Vehicle

TRAILER_LENGTH = 13.6
"""Semitrailer body length [m]: the EU standard box (Directive 96/53/EC allows 13.6 m)."""

KINGPIN_SETBACK = 1.6
"""Front wall of the semitrailer ahead of the kingpin [m]."""

TRACTOR_FRONT_OVERHANG = 1.4
"""Bumper ahead of the front axle [m] (cab-over tractor)."""

TRACTOR_REAR_OVERHANG = 1.0
"""Frame behind the last tractor axle [m]."""

BODY_CLEARANCE = 0.25
"""Body wider than the widest track, per side [m] (tyre and mudguard)."""

DOCK_FACE = (-40.0, 0.0)
"""The dock face in the yard ``(x, y)`` [m]: 40 m behind the starting tractor's
drive axle, facing +x, on the start's centre line."""

DOCK_DEPTH = 2.0
"""Depth of the dock's block behind its face [m]."""

DOOR_PITCH = 4.0
"""Distance between the centre lines of neighbouring dock doors [m]. Distribution
centres space doors 3.6-4.3 m apart; at 4 m two parked 2.55 m semitrailers leave
a 5.45 m gap for the one between them."""

DOCK_DOORS = 11
"""Doors in the dock row: the one at :data:`DOCK_FACE` and five either side."""

APRON_DEPTH = 50.0
"""Depth of the yard in front of the dock face to its far edge [m]: three times
a 16.5 m combination, so that one can line up in front of a door and back
from up to 30 m."""

BUMPER_TRAVEL = 0.05
"""How far a trailer's rear may press into the dock's rubber bumpers [m] before
it hits the dock itself."""


@dataclass(frozen=True)
class Outline:
    """Box outline of each unit, in its own frame [m].

    Attributes
    ----------
    tractor_front, tractor_rear : float
        x of the tractor's front and rear ends, from the drive axle (rear negative).
    trailer_front, trailer_rear : float
        x of the semitrailer's front wall and rear end, from the kingpin (rear negative).
    width : float
        Body width of both units.
    """

    tractor_front: float
    tractor_rear: float
    trailer_front: float
    trailer_rear: float
    width: float

    @property
    def rear_behind_kingpin(self) -> float:
        """Distance from the kingpin back to the trailer's rear end [m]."""
        return -self.trailer_rear


def outline(v: Vehicle) -> Outline:
    """The outline of ``v``'s units.

    The trailer's front wall is :data:`KINGPIN_SETBACK` ahead of the kingpin
    and its body :data:`TRAILER_LENGTH` long, unless its sensor or last axle
    lies further back: then the rear is 0.5 m behind the further of them.
    """
    xs = [a.x for a in v.tractor_axles]
    last = float(max(v.trailer_axle_distances))
    rear = max(TRAILER_LENGTH - KINGPIN_SETBACK, -v.sensor2[0] + 0.5, last + 0.5)
    width = max(a.track for a in v.axles) + 2.0 * BODY_CLEARANCE
    return Outline(tractor_front=max(xs) + TRACTOR_FRONT_OVERHANG,
                   tractor_rear=min(xs) - TRACTOR_REAR_OVERHANG,
                   trailer_front=KINGPIN_SETBACK, trailer_rear=-rear, width=width)
