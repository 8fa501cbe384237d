"""The vehicle parameter file format: every key, its unit, and its checks.

A vehicle parameter file is TOML in SI units and radians. Each section below
lists its keys as ``key: Field(unit, description, check)``. The loader rejects
unknown keys, missing keys and values that fail their check, and names the file
and the key in the error.

The tables here are the documentation of the format as well: ``artic vehicle
keys`` prints them.
"""

from __future__ import annotations

import difflib
import math
import unicodedata
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from artic.mjcf.errors import UserError


class VehicleFileError(UserError):
    """A vehicle parameter file is malformed; the message names file and key.

    Examples
    --------
    >>> import artic
    >>> try:
    ...     artic.load_vehicle("no-such-truck")
    ... except artic.VehicleFileError as error:
    ...     print(str(error).split(";")[0])
    'no-such-truck' is neither a preset nor a file
    """


@dataclass(frozen=True)
class Field:
    """One key of the parameter file.

    Parameters
    ----------
    unit : str
        SI unit, shown in brackets in messages and docs.
    doc : str
        What the number means.
    kind : str
        ``"positive"``, ``"nonneg"``, ``"real"``, ``"angle"``, ``"limit"`` (a
        positive angle: a joint's freedom either way), ``"bool"``, ``"str"``,
        ``"vec3"`` or ``"strlist"``.
    optional : bool
        Whether the key may be left out.
    default : Any
        Value used when an optional key is absent.
    """

    unit: str
    doc: str
    kind: str = "positive"
    optional: bool = False
    default: Any = None


CLASSES = ("full-size", "scale-model")
"""Vehicle classes ``[vehicle] class`` may name: each has its own plausibility ranges
(:mod:`artic.mjcf.plausible`); a ``scale-model`` may leave out its tyre data."""

VEHICLE = {
    "name": Field("", "preset or vehicle name", "str"),
    "description": Field("", "one-line description", "str"),
    "sources": Field("", "where every number comes from", "strlist"),
    "class": Field("", f"vehicle class, one of {', '.join(CLASSES)}: the plausibility ranges "
                   "its numbers are judged by", "str", optional=True, default=CLASSES[0]),
}

TRACTOR = {
    "m1": Field("kg", "tractor mass"),
    "J1": Field("kg m^2", "tractor yaw inertia about its centre of gravity"),
    "a1": Field("m", "tractor centre of gravity to front axle"),
    "b1": Field("m", "tractor centre of gravity to drive axle"),
    "L1c": Field("m", "drive axle to fifth wheel, positive when ahead of the axle", "real"),
    "h1": Field("m", "tractor centre-of-gravity height above ground"),
    "h5": Field("m", "fifth-wheel (hitch) height above ground"),
    "sensor": Field("m", "tractor sensor position from the drive-axle centre, ISO axes", "vec3"),
    "sensor_yaw": Field("rad", "mounting yaw of the tractor's inertial unit: its x-axis turned "
                        "this far left of the tractor's (plant and generated logs)", "angle",
                        optional=True, default=0.0),
}

TRAILER = {
    "m2": Field("kg", "semitrailer mass"),
    "J2": Field("kg m^2", "semitrailer yaw inertia about its centre of gravity"),
    "a2": Field("m", "kingpin to semitrailer centre of gravity"),
    "L2": Field("m", "kingpin to the centre of the trailer axle group"),
    "j": Field("m", "trailer axle spacing", "nonneg"),
    "h2": Field("m", "semitrailer centre-of-gravity height above ground"),
    "sensor": Field("m", "semitrailer sensor position from the kingpin, ISO axes", "vec3"),
    "sensor_yaw": Field("rad", "mounting yaw of the semitrailer's inertial unit (plant and "
                        "generated logs)", "angle", optional=True, default=0.0),
}

AXLE = {
    "name": Field("", "axle name, unique in the file", "str"),
    "x": Field("m", "axle position along the unit: from the drive axle (tractor) or the "
               "kingpin (semitrailer), forward positive", "real"),
    "track": Field("m", "track width, between the centres of the left and right tyres"),
    "steered": Field("", "steered by the steering wheel", "bool"),
    "driven": Field("", "carries drive torque", "bool"),
    "dual": Field("", "twin tyres at each end", "bool"),
    "load_share": Field("", "share of its group's static load (group: the steered axles, "
                        "the other tractor axles, the semitrailer axles); default equal",
                        "positive", optional=True),
    "unsprung_mass": Field("kg", "axle, hubs, brakes and wheels (plant)"),
    "suspension_stiffness": Field("N/m", "vertical rate of the axle's suspension, both "
                                  "sides together (plant)"),
    "suspension_damping": Field("N s/m", "vertical damping of the axle's suspension, both "
                                "sides together (plant)"),
    "wheel_inertia": Field("kg m^2", "spin inertia of one wheel end: a wheel, or a dual "
                           "pair (plant)"),
    "tyre_file": Field("", "this axle's PAC2002 tyre property file, if not [tyre] file "
                       "(plant)", "str", optional=True, default=""),
}

STEERING = {
    "i_s": Field("", "steering ratio, steering-wheel angle over road-wheel angle"),
    "q": Field("1/rad", "steering asymmetry factor of eq. (3)", "nonneg"),
    "delta_h_offset": Field("rad", "steering-wheel angle read while driving straight", "angle"),
    "delta_max": Field("rad", "largest road-wheel angle the linkage reaches", "angle"),
    "steering_arm": Field("m", "steering-arm length of the tie-rod trapezoid (plant)"),
}

STEERING_OVERRIDE = {
    "i_s": Field("", "steering ratio for this model", optional=True),
    "q": Field("1/rad", "asymmetry factor for this model", "nonneg", optional=True),
    "delta_h_offset": Field("rad", "steering-wheel offset for this model", "angle",
                            optional=True),
}

TYRE = {
    "f": Field("1/rad", "normalised cornering stiffness: axle cornering stiffness over axle load"),
    "sigma_alpha": Field("m", "lateral relaxation length of the single-track model's tyres"),
    "file": Field("", "PAC2002 tyre property file of the plant: a path relative to this "
                  "file, or the name of one shipped with artic", "str"),
}

TYRE_SCALE_MODEL = {
    key: Field(f.unit, f.doc + " (a scale model may leave it out: KIN needs no tyre data)",
               f.kind, optional=True, default=None) for key, f in TYRE.items()}
"""``[tyre]`` of a ``scale-model``: optional, as full-size tyre data does not fit a model's
tyres; the STM and the plant refuse such a vehicle, naming the key."""

TYRE_SCALING = ("LFZO", "LCX", "LMUX", "LEX", "LKX", "LHX", "LVX", "LCY", "LMUY", "LEY",
                "LKY", "LHY", "LVY", "LTR", "LRES", "LXAL", "LYKA", "LVYKA", "LS", "LMY",
                "LGAY", "LGAZ")
"""Magic Formula scaling factors that ``[tyre.scaling]`` may multiply (plant)."""

PLANT = {
    "fifth_wheel_friction": Field("N m", "dry friction torque of the fifth wheel about its "
                                  "vertical axis, with a smooth sign through zero",
                                  "nonneg", optional=True, default=0.0),
    "hitch_damping": Field("N m s/rad", "viscous yaw damping of the fifth wheel", "nonneg",
                           optional=True, default=0.0),
    "grade": Field("rad", "ground slope along the yard's x-axis, positive when +x runs uphill",
                   "angle", optional=True, default=0.0),
    "crossfall": Field("rad", "ground slope across the yard, positive when +y runs uphill",
                       "angle", optional=True, default=0.0),
    "payload_offset": Field("m", "shift of the semitrailer's centre of gravity from a2, h2 "
                            "in semitrailer axes [forward, left, up]", "vec3", optional=True,
                            default=(0.0, 0.0, 0.0)),
    "payload_yaw_inertia": Field("kg m^2", "change of the semitrailer's yaw inertia J2",
                                 "real", optional=True, default=0.0),
    "tyre_moments": Field("", "the tyres' aligning moment and turn-slip (bore) torque",
                          "bool", optional=True, default=False),
}
"""Optional ``[plant]`` section: effects only the multibody plant has, each off by default."""

LIMITS = {
    "gamma_max": Field("rad", "articulation at which the cab and trailer touch (jackknife)",
                       "limit"),
    "hitch_pitch": Field("rad", "pitch freedom of the fifth wheel, either way (plant)",
                         "limit"),
}

MODELS = ("kin", "stm", "mbd")
"""The built-in models, each of which may have a ``[steering.NAME]`` table."""

MODEL_NAME = r"[a-z][a-z0-9_]{0,31}"
"""What a model's name looks like: a ``[steering.NAME]`` table may name a model from
outside artic too (:func:`artic.validation.models.register_model`)."""

SECTIONS = {
    "vehicle": VEHICLE,
    "tractor": TRACTOR,
    "trailer": TRAILER,
    "steering": STEERING,
    "tyre": TYRE,
    "limits": LIMITS,
}

OPTIONAL_SECTIONS = {"plant": PLANT}
"""Sections a file may leave out; their keys take their defaults."""


def _fail(path: Path | str, key: str, message: str) -> VehicleFileError:
    return VehicleFileError(f"{path}: key '{key}': {message}")


def _one_line_text(path: Path | str, key: str, value: str) -> str:
    """``value`` if it has no line break or other control character; refused otherwise.

    A name or description is printed in tables, progress lines and file names: a
    newline in one splits a table's row or a log line.
    """
    bad = next((c for c in value if unicodedata.category(c) == "Cc"), None)
    if bad is not None:
        raise _fail(path, key, f"{value!r} holds the control character {bad!r} (a line break, "
                               "tab or other); give it on one line, without them")
    return value


def check_value(path: Path | str, key: str, field: Field, value: Any) -> Any:
    """Check one value against its field and return it converted.

    Parameters
    ----------
    path : Path or str
        File the value came from, for the message.
    key : str
        Dotted key, for the message.
    field : Field
        The key's definition.
    value : Any
        The parsed TOML value.

    Returns
    -------
    Any
        ``float`` for numbers, ``tuple`` for vectors, the value otherwise.

    Raises
    ------
    VehicleFileError
        If the value has the wrong type or fails its check.
    """
    kind = field.kind
    unit = f" [{field.unit}]" if field.unit else ""
    if kind == "str":
        if not isinstance(value, str):
            raise _fail(path, key, f"expected a string, got {value!r}")
        return _one_line_text(path, key, value)
    if kind == "strlist":
        if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
            raise _fail(path, key, f"expected a list of strings, got {value!r}")
        return tuple(_one_line_text(path, key, v) for v in value)
    if kind == "bool":
        if not isinstance(value, bool):
            raise _fail(path, key, f"expected true or false, got {value!r}")
        return value
    if kind == "vec3":
        if (not isinstance(value, list) or len(value) != 3
                or not all(_is_number(v) and math.isfinite(v) for v in value)):
            raise _fail(path, key, f"expected three finite numbers [x, y, z]{unit}, got "
                                   f"{value!r}")
        return tuple(float(v) for v in value)
    if not _is_number(value):
        raise _fail(path, key, f"expected a number{unit}, got {value!r}")
    x = float(value)
    if not math.isfinite(x):
        raise _fail(path, key, f"expected a finite number{unit}, got {value!r}")
    if kind == "positive" and x <= 0.0:
        raise _fail(path, key, f"must be positive{unit}, got {x!r}")
    if kind == "nonneg" and x < 0.0:
        raise _fail(path, key, f"must not be negative{unit}, got {x!r}")
    if kind == "limit" and x <= 0.0:
        raise _fail(path, key, f"must be positive{unit}, got {x!r}: it is the freedom either "
                               "way, and a joint needs some (the plant's joint range would be "
                               "empty)")
    if kind in ("angle", "limit") and abs(x) > math.pi:
        raise _fail(path, key, f"{x!r} is larger than pi: angles are in radians; "
                               f"{x!r} deg is {math.radians(x):.6g} rad")
    return x


def _is_number(v: Any) -> bool:
    return isinstance(v, int | float) and not isinstance(v, bool)


def _unknown_key(prefix: str, key: str, table: dict, fields: dict[str, Field],
                 tables: tuple[str, ...]) -> str:
    """What to say of an unknown key: the likely one, the keys, the sub-tables apart."""
    lower = {k.lower(): k for k in fields}
    near = difflib.get_close_matches(key.lower(), lower, n=1)
    hint = f" (did you mean {lower[near[0]]}?)" if near else ""
    text = f"unknown key{hint}; known keys of [{prefix}] are: {', '.join(sorted(fields))}"
    if tables:
        shown = [f"[[{prefix}.{t}]]" if isinstance(table.get(t), list) else f"[{prefix}.{t}]"
                 for t in tables]
        text += f"; its tables: {', '.join(shown)}"
    return text


def check_table(path: Path | str, prefix: str, table: Any,
                fields: dict[str, Field], allow: tuple[str, ...] = ()) -> dict[str, Any]:
    """Check a TOML table: no unknown key, no missing key, every value valid.

    Parameters
    ----------
    path : Path or str
        File the table came from, for messages.
    prefix : str
        Dotted name of the table, for messages.
    table : Any
        The parsed table.
    fields : dict of str to Field
        Its keys.
    allow : tuple of str
        Further keys that the caller checks itself (sub-tables).

    Returns
    -------
    dict
        Checked values, with defaults filled in for absent optional keys.
    """
    if not isinstance(table, dict):
        raise _fail(path, prefix, f"expected a table, got {table!r}")
    out: dict[str, Any] = {}
    for key in table:
        if key not in fields and key not in allow:
            raise _fail(path, f"{prefix}.{key}", _unknown_key(prefix, key, table, fields, allow))
    for key, field in fields.items():
        dotted = f"{prefix}.{key}"
        if key not in table:
            if field.optional:
                out[key] = field.default
                continue
            unit = f" [{field.unit}]" if field.unit else ""
            raise _fail(path, dotted, f"missing; add it: {field.doc}{unit}")
        out[key] = check_value(path, dotted, field, table[key])
    return out


def describe() -> str:
    """Return the file format as text, one line per key."""
    lines = []
    groups = [*SECTIONS.items(), *OPTIONAL_SECTIONS.items(),
              ("tractor.axle / trailer.axle", AXLE),
              ("steering.kin / .stm / .mbd / .NAME of a registered model", STEERING_OVERRIDE)]
    width = max(len(key) for _, fields in groups for key in fields) + 2  # the longest key fits
    for section, fields in groups:
        lines.append(f"[{section}]")
        for key, f in fields.items():
            unit = f" [{f.unit}]" if f.unit else ""
            opt = " (optional)" if f.optional else ""
            lines.append(f"  {key:<{width}}{f.doc}{unit}{opt}")
    lines.append("[tyre.scaling]  (optional, plant) a factor per Magic Formula scaling "
                 f"coefficient: {', '.join(TYRE_SCALING)}")
    return "\n".join(lines)
