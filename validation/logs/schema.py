"""The signal schema shared by measured and simulated runs.

One row per sample, SI units and radians, ISO 8855 axes (x forward, y left,
z up, yaw counter-clockwise). Positions are in an earth-fixed local plane. Yaw
angles are continuous (unwrapped); the articulation angle is wrapped to (-pi, pi].

The names that describe a log without reading one live here too (the shortest
segment kept, the sources the importers read, the consistency checks' names):
the command line's help needs them, and this module imports neither pandas nor
the readers.
"""

from __future__ import annotations

from artic.mjcf.interface import OBSERVATION

SIGNALS: dict[str, tuple[str, str]] = {
    "t": ("s", "time since the start of the run"),
    "delta_h": ("rad", "steering-wheel angle as measured, offset included"),
    "x_1": ("m", "tractor sensor position, east"),
    "y_1": ("m", "tractor sensor position, north"),
    "psi_1": ("rad", "tractor yaw, continuous"),
    "v_x_1": ("m/s", "tractor sensor velocity along the tractor"),
    "v_y_1": ("m/s", "tractor sensor velocity across the tractor, left positive"),
    "r_1": ("rad/s", "tractor yaw rate, counter-clockwise positive"),
    "x_2": ("m", "semitrailer sensor position, east"),
    "y_2": ("m", "semitrailer sensor position, north"),
    "psi_2": ("rad", "semitrailer yaw, continuous"),
    "v_x_2": ("m/s", "semitrailer sensor velocity along the semitrailer"),
    "v_y_2": ("m/s", "semitrailer sensor velocity across the semitrailer"),
    "r_2": ("rad/s", "semitrailer yaw rate"),
    "gamma": ("rad", "articulation angle psi_1 - psi_2, wrapped to (-pi, pi]"),
}
"""Column name to (unit, meaning)."""

MODEL_SIGNALS: dict[str, tuple[str, str]] = {
    "delta": ("rad", "road-wheel angle applied to the model"),
    "delta_fb": ("rad", "part of delta from the reversing feedback (and saturation)"),
    "delta_saturated": ("-", "delta was limited to the vehicle's delta_max"),
}
"""Columns that model runs add."""

COLUMNS = tuple(SIGNALS)
"""Schema columns in order; ``COLUMNS[2:]`` is the models' ``OBSERVATION``."""

if COLUMNS[2:] != OBSERVATION:  # pragma: no cover - a programming error
    raise ImportError("artic.validation.logs.schema and artic.mjcf.interface.OBSERVATION disagree")

PLAUSIBLE = {
    "r_1": 3.0, "r_2": 3.0, "gamma": 3.1416, "v_x_1": 15.0, "v_x_2": 15.0,
    "v_y_1": 5.0, "v_y_2": 5.0, "delta_h": 20.0,
}
"""Largest magnitude a yard log can show [SI]; beyond it the unit is wrong."""

UNIT_HINT = {
    "r_1": "deg/s read as rad/s", "r_2": "deg/s read as rad/s",
    "gamma": "degrees read as radians", "delta_h": "degrees read as radians",
    "v_x_1": "km/h read as m/s", "v_x_2": "km/h read as m/s",
    "v_y_1": "km/h read as m/s", "v_y_2": "km/h read as m/s",
}

MIN_SEGMENT = 1.0
"""Shortest gap-free segment kept [s]: the differentiator and the criteria need a second."""

SOURCES = ("a canonical .parquet or .csv log, a .mat file, a folder with tractor.csv, "
           "trailer.csv and can.csv, or with --channels a CSV, a ROS 1 .bag, a ROS 2 bag "
           "folder or an .mcap file")
"""What ``artic logs import`` reads, for its help and its errors: one list to extend."""

CHECKS: dict[str, str] = {
    "gap": "no time step longer than the longest gap accepted",
    "yaw-rate": "integrated yaw rate against the heading change",
    "turning": "no unit turns tighter than its geometry allows (positions in too small a unit)",
    "axes": "each unit's axle travels along its heading (x and y swapped or mirrored)",
    "curvature": "course of the position track against the integrated yaw rate",
    "velocity": "integrated velocity against the position track: sign, scale, direction",
    "jump": "position steps the velocity does not explain",
    "steering": "steering wheel against the steering map's reach and the observed curvature",
    "hitch": "semitrailer against tractor through one hitch point",
    "articulation": "articulation against the derived unit's kinematics: its axle rolls along "
                    "its heading, which fixes gamma's sign and scale (logs with a derived "
                    "unit); against psi_1 - psi_2 where both units are measured (an offset)",
    "metadata": "the direction the metadata states (or its manoeuvre implies) against the "
                "motion",
}
"""Every check of :mod:`artic.validation.logs.consistency` by the name ``--accept`` takes,
in the order they run."""
