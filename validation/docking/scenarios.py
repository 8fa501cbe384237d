"""The docking scenarios: a distribution centre's yard and where each run starts.

The yard is built from :mod:`artic.mjcf.outline`, the one source of the dock's
place and the units' outlines that the plant and the recordings draw:

- the dock row: a building whose face is at :data:`~artic.mjcf.outline.DOCK_FACE`,
  facing +x, :data:`~artic.mjcf.outline.DOCK_DOORS` doors
  :data:`~artic.mjcf.outline.DOOR_PITCH` apart; the target door is the one at
  ``DOCK_FACE``. The rear may press :data:`~artic.mjcf.outline.BUMPER_TRAVEL`
  into the bumpers before the trailer hits the dock;
- the yard's far edge, :data:`~artic.mjcf.outline.APRON_DEPTH` in front of the face;
- parked semitrailers at neighbouring doors, as long and wide as the
  combination's own semitrailer (its outline), rear against the bumpers.

A run docks when the semitrailer's rear stands at the face, on the door's
centre line, heading +x (the tractor pointing away from the dock).

Four scenarios, each with a seeded distribution of starts (semitrailer rear
pose and articulation, drawn from ``numpy.random.default_rng([seed, number])``
so that every controller and vehicle meets the same starts):

- ``straight``: lined up with the door, 20-28 m out, up to 1 m and 4 deg off;
- ``alley``: the 90-degree alley dock: the combination stands across the dock
  row, 26-30 m out, its rear 2-8 m past the door, and reverses through a
  right angle into its bay;
- ``offset``: lined up in front of the door one or two doors away (4 or 8 m),
  24-30 m out;
- ``bay``: the alley dock with a semitrailer parked at each neighbouring door,
  so that the combination backs into a 5.45 m gap.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from artic.mjcf.errors import UserError
from artic.mjcf.outline import (
    APRON_DEPTH,
    BUMPER_TRAVEL,
    DOCK_DEPTH,
    DOCK_DOORS,
    DOCK_FACE,
    DOOR_PITCH,
    outline,
)
from artic.mjcf.vehicle import Vehicle
from artic.validation.docking.geometry import Box

YARD_HALF_LENGTH = 60.0
"""The yard runs this far along the dock row either side of the door [m]."""


@dataclass(frozen=True)
class Yard:
    """The dock, the target door and the obstacles around it.

    Parameters
    ----------
    x_dock, y_dock : float
        The dock face and the target door's centre line [m].
    obstacles : tuple of Box
        The dock (its face pushed back by the bumpers' travel), the yard's far
        edge and any parked semitrailers.
    doors : tuple of float
        Centre lines of all doors in the row [m] (for drawings).
    """

    x_dock: float
    y_dock: float
    obstacles: tuple[Box, ...]
    doors: tuple[float, ...]

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """``(x_min, x_max, y_min, y_max)`` of the yard in front of the dock [m]."""
        return (self.x_dock, self.x_dock + APRON_DEPTH, self.y_dock - YARD_HALF_LENGTH,
                self.y_dock + YARD_HALF_LENGTH)

    @property
    def parked(self) -> tuple[Box, ...]:
        """The parked semitrailers."""
        return tuple(b for b in self.obstacles if b.name.startswith("neighbour"))


def make_yard(vehicle: Vehicle, neighbours: tuple[int, ...] = ()) -> Yard:
    """The yard, with semitrailers parked at the doors ``neighbours`` away from the target.

    Parameters
    ----------
    vehicle : Vehicle
        Its semitrailer's outline gives the parked semitrailers' size.
    neighbours : tuple of int
        Doors, counted from the target (``-1``: the next one at lower y).
    """
    x_d, y_d = DOCK_FACE
    o = outline(vehicle)
    half_row = YARD_HALF_LENGTH
    obstacles = [
        Box("dock", x_d - DOCK_DEPTH, x_d - BUMPER_TRAVEL, y_d - half_row, y_d + half_row),
        Box("yard-edge", x_d + APRON_DEPTH, x_d + APRON_DEPTH + 2.0, y_d - half_row,
            y_d + half_row),
    ]
    length = o.trailer_front - o.trailer_rear
    for n in neighbours:
        if n == 0:
            raise UserError("a neighbour cannot park at the target door (0)")
        yc = y_d + n * DOOR_PITCH
        side = "left" if n > 0 else "right"
        obstacles.append(Box(f"neighbour-{side}-{abs(n)}", x_d, x_d + length,
                             yc - o.width / 2, yc + o.width / 2))
    doors = tuple(y_d + (k - DOCK_DOORS // 2) * DOOR_PITCH for k in range(DOCK_DOORS))
    return Yard(x_d, y_d, tuple(obstacles), doors)


@dataclass(frozen=True)
class Start:
    """Where a run starts: the semitrailer's rear, its heading and the articulation.

    Parameters
    ----------
    x_r, y_r : float
        Semitrailer rear centre [m].
    psi_2 : float
        Semitrailer heading [rad].
    gamma : float
        Articulation ``psi_1 - psi_2`` [rad].
    """

    x_r: float
    y_r: float
    psi_2: float
    gamma: float


@dataclass(frozen=True)
class Scenario:
    """A docking task: its yard and its distribution of starts.

    Parameters
    ----------
    name : str
        What ``--scenario`` takes.
    number : int
        Fixed per scenario; the random starts are drawn from ``(seed, number)``.
    description : str
        One line for ``artic dock --list``.
    across : bool
        Whether the combination starts across the dock row (heading +-90 deg).
    distance : tuple of float
        Range of the start's distance from the face [m]: of the rear when
        lined up, of the semitrailer's centre line when across.
    lateral : tuple of float
        Range of the rear's offset from the door's centre line [m] (its
        magnitude when across: past the door).
    doors_over : tuple of int
        Doors away from the target that the start lines up with (0: the target).
    heading_deg, gamma_deg : float
        Largest heading deviation and articulation of the start [deg].
    neighbours : tuple of int
        Doors with a parked semitrailer.
    timeout : float
        Longest run [s].
    """

    name: str
    number: int
    description: str
    across: bool
    distance: tuple[float, float]
    lateral: tuple[float, float]
    doors_over: tuple[int, ...]
    heading_deg: float
    gamma_deg: float
    neighbours: tuple[int, ...]
    timeout: float

    def yard(self, vehicle: Vehicle) -> Yard:
        """The yard of this scenario for ``vehicle``."""
        return make_yard(vehicle, self.neighbours)

    def start(self, seed: int) -> Start:
        """The start of seeded run ``seed``: the same for every vehicle and controller."""
        if not isinstance(seed, int | np.integer) or seed < 0:
            raise UserError(f"seed must be a non-negative integer, got {seed!r}")
        rng = np.random.default_rng([int(seed), self.number])
        side = 1.0 if rng.random() < 0.5 else -1.0
        dist = rng.uniform(*self.distance)
        lat = rng.uniform(*self.lateral)
        doors = self.doors_over[int(rng.integers(len(self.doors_over)))]
        dpsi = math.radians(rng.uniform(-self.heading_deg, self.heading_deg))
        gamma = math.radians(rng.uniform(-self.gamma_deg, self.gamma_deg))
        x_d, y_d = DOCK_FACE
        if self.across:
            # Heading along the row, the rear `lat` past the door in the direction of travel.
            return Start(x_d + dist, y_d + side * abs(lat), side * math.pi / 2 + dpsi, gamma)
        return Start(x_d + dist, y_d + side * doors * DOOR_PITCH + lat, dpsi, gamma)


SCENARIOS: dict[str, Scenario] = {s.name: s for s in (
    Scenario("straight", 1, "straight back onto the door from 20-28 m, up to 1 m and 4 deg off",
             False, (20.0, 28.0), (-1.0, 1.0), (0,), 4.0, 3.0, (), 150.0),
    Scenario("alley", 2, "the 90-degree alley dock: across the dock row 26-30 m out, "
             "reversing through a right angle into the bay", True, (26.0, 30.0), (2.0, 8.0),
             (0,), 3.0, 2.0, (), 240.0),
    Scenario("offset", 3, "lined up one or two doors (4 or 8 m) from the bay, 24-30 m out",
             False, (24.0, 30.0), (-0.5, 0.5), (1, 2), 3.0, 2.0, (), 200.0),
    Scenario("bay", 4, "the alley dock into a bay between two parked semitrailers (5.45 m gap)",
             True, (26.0, 30.0), (2.0, 8.0), (0,), 3.0, 2.0, (-1, 1), 240.0),
)}
"""The scenarios by name."""


def scenario(name: str, given: str = "--scenario") -> Scenario:
    """The scenario called ``name``; ``given`` names what gave it, for the message.

    Raises
    ------
    ValueError
        Naming the scenarios there are.
    """
    try:
        return SCENARIOS[name]
    except KeyError:
        raise UserError(f"{given} {name!r}: no such scenario; choose one of "
                         f"{', '.join(SCENARIOS)}") from None
