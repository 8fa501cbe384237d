"""Channel maps (TOML): where each canonical channel is in a CSV or a ROS bag, and its unit.

A map names, for each canonical channel it has, either a CSV ``column`` or a
bag's ``topic`` and ``field`` (a dotted path into the message, with ``[k]``
for an element of an array or ``[name]`` for a JointState's joint by name),
its ``unit``, and optionally ``scale`` (default 1) and ``offset`` (default 0,
in the source's unit): the channel is ``unit * (scale * value + offset)``.

.. code-block:: toml

    [time]
    column = "t"            # a CSV: the time column and its unit
    unit = "s"
    # source = "header"     # a bag: the messages' header stamps, or "receive"
    max_gap = 0.3           # [s] longer intervals split the log (default 2.5 medians, >= 0.1 s)

    [derive]
    window = 0.5            # [s] Savitzky-Golay window of derived rates

    [channels]
    x_1 = { topic = "/vive/pose", field = "pose.position.x", unit = "m" }
    psi_1 = { topic = "/vive/pose", field = "pose.orientation", unit = "quaternion" }
    gamma = { topic = "/encoder/angle", field = "data", unit = "rad", scale = -1.0,
              time = "receive" }

Units: ``s, ms``; ``m, cm, mm``; ``m/s, km/h, mph``; ``rad, deg``; ``rad/s,
deg/s``; ``quaternion`` (the yaw of a ``geometry_msgs/Quaternion``, for
``psi_1``, ``psi_2`` and ``gamma``); ``latitude`` and ``longitude`` in degrees
(a NavSatFix's, for ``y_i`` and ``x_i``), which become a local east/north
plane tangent at the log's first fix. A bag channel may take its stamps from
the other source than ``[time]`` says with ``time = "header" | "receive"``
(a std_msgs value has no header). The two components of one position or
velocity (``x_i, y_i``; ``v_x_i, v_y_i``) come in one unit; a map that
declares them in two is refused.

What a map must name: the pose ``x_i, y_i, psi_i`` of at least one unit
(``i = 1`` the tractor, ``2`` the semitrailer, at the sensor positions of the
vehicle file, ISO axes); with one unit only, also ``gamma``, from which the
other unit's channels are derived (:mod:`artic.validation.logs.derive`).
Velocities ``v_x_i, v_y_i`` and yaw rates ``r_i`` not named are derived from
the pose (:mod:`artic.validation.logs.differentiate`); ``gamma_rate`` is
optional; without ``delta_h`` the models are steered from the measured yaw
rate (:mod:`artic.validation.logs.yawsteer`). Everything derived is marked as
derived in the run's metadata, the import report and ``artic validate``.

A map may also declare its sensors' noise in a ``[noise]`` table (standard
deviation, correlation time and bias per channel,
:mod:`artic.validation.logs.noise`); the logs imported through it carry the
declaration in their metadata, and ``artic validate`` prints the score a
perfect model would get from that noise alone.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

from artic.validation.logs.differentiate import WINDOW
from artic.validation.logs.noise import parse_noise
from artic.validation.logs.runfile import LogError
from artic.validation.logs.units import DIMENSION, UNITS

QUATERNION_CHANNELS = ("psi_1", "psi_2", "gamma")
"""Channels that may be given as a quaternion (its yaw)."""

GEODETIC = {"latitude": ("y_1", "y_2"), "longitude": ("x_1", "x_2")}
"""Channels that may be given as latitude or longitude [deg] (north and east)."""

POSE = {i: (f"x_{i}", f"y_{i}", f"psi_{i}") for i in (1, 2)}
RATES = {i: (f"v_x_{i}", f"v_y_{i}", f"r_{i}") for i in (1, 2)}

TIME_SOURCES = ("header", "receive")


@dataclass(frozen=True)
class Entry:
    """Where one canonical channel is, and how to make it SI.

    Parameters
    ----------
    channel : str
        Canonical name.
    source : str
        CSV column, or bag topic.
    field : str or None
        Field path in the topic's messages (bags only).
    unit : str
        A key of :data:`UNITS`.
    scale, offset : float
        ``SI = factor * (scale * value + offset)``.
    time : str or None
        A bag channel's own time source, overriding ``[time] source``.
    """

    channel: str
    source: str
    field: str | None
    unit: str
    scale: float = 1.0
    offset: float = 0.0
    time: str | None = None

    @property
    def factor(self) -> float:
        """Factor of the unit to SI."""
        return UNITS[self.unit][1]

    @property
    def label(self) -> str:
        """The source's name of the channel, for messages: a column, or a topic and field."""
        return self.source if self.field is None else f"{self.source} (field {self.field})"


@dataclass(frozen=True)
class ChannelMap:
    """A checked channel map (see the module docstring)."""

    path: str
    entries: dict[str, Entry]
    time_column: str | None = None
    time_factor: float = 1.0
    time_source: str = "header"
    max_gap: float | None = None
    window: float = WINDOW
    bag: bool = False
    notes: list[str] = field(default_factory=list)
    noise: dict = field(default_factory=dict)
    """The declared sensor noise per channel (:class:`artic.validation.logs.noise.ChannelNoise`)."""

    def units(self) -> tuple[int, ...]:
        """The units (1, 2) whose pose the map names."""
        return tuple(i for i in (1, 2) if POSE[i][0] in self.entries)


def _units_of(dim: str) -> str:
    return ", ".join(u for u, (d, _) in UNITS.items()
                     if d == dim and u not in ("quaternion", *GEODETIC))


def _number(path, key: str, spec: dict, name: str, default: float) -> float:
    try:
        value = float(spec.get(name, default))
    except (TypeError, ValueError) as exc:
        raise LogError(f"{path}: {key}: {name} must be a number") from exc
    if not math.isfinite(value):
        raise LogError(f"{path}: {key}: {name} must be finite")
    return value


def _entry(path, key: str, spec, bag: bool) -> Entry:
    channel = key.split(".")[-1]
    dim = DIMENSION[channel]
    where = ("topic", "field") if bag else ("column",)
    if not isinstance(spec, dict) or any(w not in spec for w in where) or "unit" not in spec:
        example = _units_of(dim).split(",")[0]
        shown = ('topic = "/TOPIC", field = "FIELD.PATH"' if bag else 'column = "NAME"')
        raise LogError(f"{path}: {key}: give a table with {', '.join(where)} and unit, for "
                       f'example {channel} = {{ {shown}, unit = "{example}" }}')
    allowed = {*where, "unit", "scale", "offset"} | ({"time"} if bag else set())
    extra = sorted(set(spec) - allowed)
    if extra:
        raise LogError(f"{path}: {key}: unknown key(s) {', '.join(extra)}; use "
                       f"{', '.join(sorted(allowed))}")
    unit = str(spec["unit"])
    allowed_units = [u for u, (d, _) in UNITS.items() if d == dim and (
        u != "quaternion" or (bag and channel in QUATERNION_CHANNELS))
        and channel in GEODETIC.get(u, (channel,))]
    if unit not in allowed_units:
        raise LogError(f"{path}: {key}: unit {unit!r} is not a unit of {dim} here; use one of "
                       f"{', '.join(allowed_units)}")
    scale = _number(path, key, spec, "scale", 1.0)
    offset = _number(path, key, spec, "offset", 0.0)
    time = spec.get("time")
    if time is not None and time not in TIME_SOURCES:
        raise LogError(f'{path}: {key}: time = {time!r}; use "header" or "receive"')
    for w in where:
        if not isinstance(spec[w], str) or not spec[w].strip():
            raise LogError(f"{path}: {key}: {w} must be a non-empty string")
    return Entry(channel, str(spec[where[0]]), str(spec["field"]) if bag else None, unit,
                 scale, offset, time)


def read_map(path: Path | dict) -> ChannelMap:
    """Read and check a channel map (a TOML file, or its data); see the module docstring.

    Raises
    ------
    LogError
        Naming the map file, the key and the fix.
    """
    if isinstance(path, dict):  # a map made here (see channels.tractor_only_map)
        data, path = path, "the canonical columns"
    else:
        path = Path(path)
        try:
            data = tomllib.loads(path.read_text(encoding="utf-8"))
        except FileNotFoundError as exc:
            raise LogError(f"{path}: no such channel map") from exc
        except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError) as exc:
            raise LogError(f"{path}: cannot read as TOML ({exc})") from exc
    unknown = sorted(set(data) - {"time", "channels", "derive", "noise"})
    if unknown:
        raise LogError(f"{path}: unknown section(s) {', '.join(unknown)}; a channel map has "
                       "[time], [channels] and optionally [derive] and [noise]")
    noise = {}
    if "noise" in data:
        noise = parse_noise(data["noise"], str(path))
    time = data.get("time")
    if not isinstance(time, dict):
        raise LogError(f'{path}: missing [time]; add column = "..." and unit = "s" for a CSV, '
                       'or source = "header" (or "receive") for a ROS bag or MCAP file')
    channels = data.get("channels", {})
    if not isinstance(channels, dict) or not channels:
        raise LogError(f"{path}: [channels] is missing or empty; name at least x_1, y_1, psi_1")
    bag = "column" not in time
    if bag:
        extra = sorted(set(time) - {"source", "max_gap"})
        if extra:
            raise LogError(f"{path}: time: unknown key(s) {', '.join(extra)}; a bag's [time] has "
                           'source = "header" or "receive", and max_gap')
        source = time.get("source", "header")
        if source not in TIME_SOURCES:
            raise LogError(f'{path}: time.source = {source!r}; use "header" (the messages\' '
                           'header stamps) or "receive" (the bag\'s receive time)')
        t_col, t_factor = None, 1.0
    else:
        t = _time_entry(path, time)
        t_col, t_factor, source = t.source, t.factor, "header"
    max_gap = time.get("max_gap")
    if max_gap is not None:
        max_gap = _number(path, "time", time, "max_gap", 0.0)
        if max_gap <= 0:
            raise LogError(f"{path}: time: max_gap must be positive [s]")
    derive = data.get("derive", {})
    if not isinstance(derive, dict) or set(derive) - {"window"}:
        raise LogError(f"{path}: [derive] takes window = SECONDS (the Savitzky-Golay window "
                       "of derived velocities and yaw rates)")
    window = _number(path, "derive", derive, "window", WINDOW)
    if not 0.02 <= window <= 10.0:
        raise LogError(f"{path}: derive: window = {window:g} s; give 0.02 to 10 s")
    bad = sorted(set(channels) - set(DIMENSION))
    if bad:
        raise LogError(f"{path}: channels.{bad[0]}: not a channel; the map can name "
                       f"{', '.join(DIMENSION)}")
    entries = {c: _entry(path, f"channels.{c}", spec, bag) for c, spec in channels.items()}
    _check_coverage(path, entries)
    _check_vector_units(path, entries)
    return ChannelMap(str(path), entries, t_col, t_factor, source,
                      None if max_gap is None else float(max_gap), window, bag, noise=noise)


def _time_entry(path, spec: dict) -> Entry:
    if "unit" not in spec:
        raise LogError(f'{path}: time: give column = "NAME" and unit = "s" (or "ms")')
    extra = sorted(set(spec) - {"column", "unit", "max_gap"})
    if extra:
        raise LogError(f"{path}: time: unknown key(s) {', '.join(extra)}; use column, unit, "
                       "max_gap")
    unit = str(spec["unit"])
    if UNITS.get(unit, ("",))[0] != "time":
        raise LogError(f"{path}: time: unit {unit!r} is not a unit of time; use one of "
                       f"{_units_of('time')}")
    return Entry("t", str(spec["column"]), None, unit)


def _check_coverage(path, entries: dict[str, Entry]) -> None:
    """At least one unit's pose; partial poses and rates without a pose refused."""
    for i in (1, 2):
        have = [c for c in POSE[i] if c in entries]
        if have and len(have) < 3:
            missing = [c for c in POSE[i] if c not in entries]
            raise LogError(f"{path}: [channels] has {', '.join(have)} but not "
                           f"{', '.join(missing)}; a unit's pose needs all three")
        rates = [c for c in RATES[i] if c in entries]
        if rates and not have:
            raise LogError(f"{path}: [channels] has {', '.join(rates)} without x_{i}, y_{i}, "
                           f"psi_{i}; a unit needs its pose")
    units = [i for i in (1, 2) if POSE[i][0] in entries]
    if not units:
        raise LogError(f"{path}: [channels] has no unit's pose; name x_1, y_1, psi_1 (the "
                       "tractor) or x_2, y_2, psi_2 (the semitrailer)")
    if len(units) == 1 and "gamma" not in entries:
        other = "semitrailer's x_2, y_2, psi_2" if units == [1] else "tractor's x_1, y_1, psi_1"
        raise LogError(f"{path}: [channels] has neither the {other} nor gamma (the "
                       "articulation angle) to derive them")


VECTORS = tuple((f"x_{i}", f"y_{i}") for i in (1, 2)) + tuple(
    (f"v_x_{i}", f"v_y_{i}") for i in (1, 2))
"""Pairs of channels that are the two components of one vector (a position, a velocity)."""


def _check_vector_units(path, entries: dict[str, Entry]) -> None:
    """Refuse a vector whose two components are declared in different units.

    One in metres, the other in millimetres is a map's mistake (a source writes
    a position's x and y alike), and it slips past the physical checks when the
    unit moves along the other axis: a docking log whose x is shrunk a thousand
    times still moves along y, too slowly per window for the axes check.
    """
    for a, b in VECTORS:
        if a not in entries or b not in entries:
            continue
        ea, eb = entries[a], entries[b]
        geo_a, geo_b = ea.unit in GEODETIC, eb.unit in GEODETIC
        if geo_a or geo_b:
            if geo_a != geo_b:
                raise LogError(f"{path}: channels.{a} is in {ea.unit} and channels.{b} in "
                               f"{eb.unit}: a position is either longitude and latitude or "
                               "two lengths; declare both alike")
            continue
        fa, fb = ea.factor * abs(ea.scale), eb.factor * abs(eb.scale)
        if not math.isclose(fa, fb, rel_tol=1e-9):
            def said(e: Entry) -> str:
                return e.unit + (f" x {abs(e.scale):g}" if abs(e.scale) != 1.0 else "")

            raise LogError(f"{path}: channels.{a} is in {said(ea)} and channels.{b} in "
                           f"{said(eb)}: the two components of one vector come in one unit "
                           f"(a {fa / fb:g} times larger {a} makes the unit move along the "
                           f"wrong line); give {a} and {b} the unit the source writes")

