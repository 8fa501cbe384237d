"""A docking run and the conditions it runs under, as two objects.

:func:`artic.validation.docking.run.dock` takes a :class:`DockRun` (what runs:
scenario, vehicle, controller, seed, and how it is run) and its
:class:`Conditions` (what the yard does to it: sensors and their noise, the
synthetic truth, the semitrailer, the actuators, the road);
:func:`split_options` makes both from the keywords of
:func:`artic.validation.docking.run.drive` (``artic dock``'s options).
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path
from typing import Any

STEER_RATE = math.radians(360.0)
"""Largest steering-wheel rate [rad/s]: an electric steering actuator's, and
what the synthetic driver turns (0.3 rad/s of road wheel through 21:1)."""


@dataclasses.dataclass(frozen=True)
class DockRun:
    """What runs: one start of a scenario, a vehicle and a controller.

    The fields are :func:`artic.validation.docking.run.drive`'s parameters of the same
    names (``scenario`` its ``scen``, ``vehicle`` its ``vehicle_name``).
    """

    scenario: Any
    vehicle: str
    controller: Any
    seed: int
    planner: Any = None
    timeout: float | None = None
    yard_model: str = "mbd"
    record: Path | None = None
    realtime: bool = True


@dataclasses.dataclass(frozen=True)
class Conditions:
    """What the yard does to a run: sensors, truth, semitrailer, actuators, road.

    The fields are :func:`artic.validation.docking.run.drive`'s keywords of the same
    names; the defaults are the benchmark's.
    """

    sensors: Any = None
    sensor_set: str = "full"
    articulation_noise_deg: float | None = None
    truth: int | None = None
    trailer: Any = "nominal"
    delay: float = 0.0
    steer_rate: float = STEER_RATE
    friction: float = 1.0
    grade: float = 0.0


RUN_OPTIONS = tuple(f.name for f in dataclasses.fields(DockRun))[4:]
"""The keywords that go to :class:`DockRun`."""

CONDITIONS = tuple(f.name for f in dataclasses.fields(Conditions))
"""The keywords that go to :class:`Conditions`."""


OPTIONS = ("planner", "sensors", "timeout", "yard_model", "record", "truth", "realtime",
           "sensor_set", "articulation_noise_deg", "trailer", "delay", "steer_rate",
           "friction", "grade")
"""Every keyword of :func:`artic.validation.docking.run.drive`, in its documentation's order."""


def split_options(options: dict[str, Any]) -> tuple[dict[str, Any], Conditions]:
    """``drive``'s keywords split into :class:`DockRun`'s and the :class:`Conditions`.

    Raises
    ------
    TypeError
        For a keyword that is neither, as a function given an unknown keyword does.
    """
    unknown = sorted(set(options) - set(RUN_OPTIONS) - set(CONDITIONS))
    if unknown:
        raise TypeError(f"drive() got an unexpected keyword argument {unknown[0]!r}")
    run = {k: v for k, v in options.items() if k in RUN_OPTIONS}
    return run, Conditions(**{k: v for k, v in options.items() if k in CONDITIONS})
