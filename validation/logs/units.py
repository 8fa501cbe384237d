"""Unit names and each channel's dimension: what a channel map and a noise declaration write.

A channel map (:mod:`artic.validation.logs.channelmap`) names each channel's
unit, and a noise declaration (:mod:`artic.validation.logs.noise`) its
sigma's; both are checked against the channel's dimension here.
"""

from __future__ import annotations

import math

UNITS: dict[str, tuple[str, float]] = {
    "s": ("time", 1.0), "ms": ("time", 1e-3),
    "m": ("length", 1.0), "cm": ("length", 0.01), "mm": ("length", 1e-3),
    "m/s": ("speed", 1.0), "km/h": ("speed", 1 / 3.6), "mph": ("speed", 0.44704),
    "rad": ("angle", 1.0), "deg": ("angle", math.pi / 180),
    "rad/s": ("rate", 1.0), "deg/s": ("rate", math.pi / 180),
    "quaternion": ("angle", 1.0),
    "latitude": ("length", math.pi / 180), "longitude": ("length", math.pi / 180),
}
"""Unit name to (dimension, factor to SI)."""

DIMENSION: dict[str, str] = {
    "delta_h": "angle", "gamma": "angle", "gamma_rate": "rate",
    **{f"{c}_{i}": d for i in (1, 2) for c, d in (("x", "length"), ("y", "length"),
                                                  ("psi", "angle"), ("v_x", "speed"),
                                                  ("v_y", "speed"), ("r", "rate"))},
}
"""Every channel a map may name, with its dimension."""
