"""The manoeuvres and limits of the standards the low-speed measures come from.

- **PBS**: the National Transport Commission's *Performance Based Standards
  Scheme - The Standards and Vehicle Assessment Rules* (as at 10 November
  2008), the Australian scheme now administered by the National Heavy
  Vehicle Regulator. Its low-speed turn is a 90-degree turn in which the
  outer edge of the steer axle's outer tyre follows a 12.5 m radius, at no
  more than 5 km/h; in it, the low-speed swept path, frontal swing, tail swing
  and steer-tyre friction demand are measured. Each standard has performance
  levels 1 (general access) to 4 (road trains); a vehicle meets a level if
  its measure is within that level's limit (:data:`LIMITS`).
- **FHWA**: the low-speed off-tracking manoeuvre of the FHWA's *Comprehensive
  Truck Size and Weight Limits Study* (MAP-21), its highway safety and truck
  crash comparative analysis (Appendix C, Figure C1): 5 mph, 60 ft straight,
  a 41 ft radius curve entered and left without a spiral, a 90-degree bend,
  105 ft straight; the path is the steer axle's.
- **SAE J695**, *Turning Ability and Off Tracking - Motor Vehicles*: the
  steady off-tracking on a circle, and its closed form for a kinematic
  combination (a sum over the units of squared radii less squared lengths).
"""

from __future__ import annotations

import math

PBS_RULES = ("Performance Based Standards Scheme - The Standards and Vehicle Assessment Rules "
             "(National Transport Commission, as at 10 November 2008)")
FHWA_STUDY = ("FHWA Comprehensive Truck Size and Weight Limits Study (MAP-21): highway safety and "
              "truck crash comparative analysis, Appendix C (low-speed off-tracking, Figure C1)")
SAE_J695 = "SAE J695, Turning Ability and Off Tracking - Motor Vehicles"

FOOT = 0.3048
"""[m]"""
MPH = 0.44704
"""[m/s]"""

PBS_RADIUS = 12.5
"""Radius of the steer tyre's outer edge in the PBS low-speed turn [m]."""
PBS_SPEED = 5.0 / 3.6
"""Speed of the PBS low-speed turn [m/s]: its limit, 5 km/h."""
PBS_ANGLE = math.pi / 2

FHWA_RADIUS = 41.0 * FOOT
"""Radius of the FHWA turn's path [m] (41 ft)."""
FHWA_ENTRY = 60.0 * FOOT
FHWA_EXIT = 105.0 * FOOT
FHWA_SPEED = 5.0 * MPH

J695_RADIUS = FHWA_RADIUS
"""Radius of the steer axle's centre on the steady circle [m]: the FHWA turn's,
so that the steady off-tracking is the value the FHWA turn approaches."""

LIMITS: dict[str, dict[int, float]] = {
    # measure: {level: largest value that meets it}
    "swept_width": {1: 7.4, 2: 8.7, 3: 10.6, 4: 13.7},  # [m]
    "tail_swing": {1: 0.30, 2: 0.35, 3: 0.35, 4: 0.50},  # [m]
    "frontal_swing": {1: 0.7, 2: 0.7, 3: 0.7, 4: 0.7},  # [m], prime mover
    "steer_friction": {1: 80.0, 2: 80.0, 3: 80.0, 4: 80.0},  # [%] of the peak friction
}
"""The PBS Rules' limits per performance level (the same at every level where the
standard has one limit). The semitrailer's frontal swing has none here: the
Rules limit it by two measures of their own (the maximum of the difference
and the difference of the maxima of the two units' swings), which artic's
measure, the semitrailer's corner outside the tractor's side, is not."""


def level(measure: str, value: float) -> str:
    """The best PBS level ``value`` meets for ``measure``: ``"1"`` to ``"4"``, ``"none"``, ``""``.

    ``""`` where the measure has no PBS limit or the value is not available.
    """
    limits = LIMITS.get(measure)
    if limits is None or not math.isfinite(value):
        return ""
    for lv in sorted(limits):
        if value <= limits[lv]:
            return str(lv)
    return "none"
