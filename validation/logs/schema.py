"""The signal schema shared by measured and simulated runs.

One row per sample, SI units and radians, ISO 8855 axes (x forward, y left,
z up, yaw counter-clockwise). Positions are in an earth-fixed local plane. Yaw
angles are continuous (unwrapped); the articulation angle is wrapped to (-pi, pi].
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
