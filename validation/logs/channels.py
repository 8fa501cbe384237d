"""Mapped logs: a CSV, a ROS bag or an MCAP file through a channel map.

``artic logs import LOG --channels MAP.toml`` reads a log whose layout is not
artic's own: a CSV with its own column names, units and time stamps, or a
ROS 1 bag, a ROS 2 bag (sqlite3 or MCAP storage) or an MCAP file
(:mod:`artic.validation.logs.bags`). The map (:mod:`artic.validation.logs.channelmap`)
names, for each canonical channel, its column or its topic and field, and its
unit:

.. code-block:: toml

    [time]
    column = "t"
    unit = "s"

    [channels]
    delta_h = { column = "steer_ang", unit = "deg" }
    x_1 = { column = "X", unit = "m" }
    gamma = { column = "hitch", unit = "deg", scale = -1.0 }

The channels then become canonical runs as
:mod:`artic.validation.logs.assemble` describes: stamps checked, the log split
at gaps into gap-free segments, every channel interpolated onto the 100 Hz
base, and what the map does not name derived (a unit's rates from its pose,
one unit from the other and ``gamma``, the steering from the yaw rate), each
step a line of the report. The importer then runs the consistency checks
(:mod:`artic.validation.logs.consistency`: units, signs, the hitch, jumps) on
each segment.
"""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from artic.mjcf.vehicle import Vehicle
from artic.validation.logs import consistency
from artic.validation.logs.assemble import RATE, Stream, assemble
from artic.validation.logs.bags import is_bag, read_bag
from artic.validation.logs.channelmap import DIMENSION, ChannelMap, read_map
from artic.validation.logs.checks import Report
from artic.validation.logs.derive import TRACTOR
from artic.validation.logs.runfile import LogError, Run
from artic.validation.logs.scale import FULL_SIZE, LogScale

__all__ = ["RATE", "import_mapped", "map_context", "read_map", "tractor_only_map"]


def import_mapped(path: Path, map_path: Path | dict, vehicle: Vehicle,
                  accept: tuple[str, ...] = (),
                  scale: LogScale = FULL_SIZE) -> tuple[list[Run], list[str]]:
    """Import a CSV or a bag through a channel map onto the 100 Hz base.

    Parameters
    ----------
    path : Path
        The log: a CSV, a ``.bag``, a ROS 2 bag folder, an ``.mcap`` file.
    map_path : Path or dict
        Its channel map, or the map's data.
    vehicle : Vehicle
        Geometry for the derived unit, steering map for a derived ``delta_h``.
    accept : tuple of str
        Consistency checks accepted knowingly: ``gap`` interpolates across gaps
        instead of splitting the log there; ``jump`` and ``velocity`` skip the
        import's jump and velocity-unit checks (the canonical log's checks
        still record them).
    scale : LogScale
        The vehicle's scale, for the jump distance and the limits of speeds
        and yaw rates (:mod:`artic.validation.logs.scale`).

    Returns
    -------
    runs : list of Run
        Canonical, 100 Hz, time from zero: one per gap-free segment
        (``meta["segment"]`` when there are several); ``meta["derived"]``
        says which channels were derived and how.
    report : list of str
        Every repair, trim, split, resampling and derivation.
    """
    path = Path(path)
    chmap = read_map(map_path)
    report = Report(str(path))
    checks = {"accept": tuple(accept), "scale": scale, "ctx": map_context(path, chmap)}
    bag = is_bag(path)
    if bag != chmap.bag:
        what = ("names CSV columns (column = ...) but the log is a ROS bag or MCAP file: give "
                "topic and field" if bag else "names bag topics (topic, field) but the log is "
                "not a ROS bag or MCAP file (.bag, .mcap, .db3, or a folder with metadata.yaml)")
        raise LogError(f"{chmap.path}: the map {what}")
    if bag:
        streams, lines = read_bag(path, chmap)
        for line in lines:
            report.add(line)
        runs = assemble(streams, chmap, vehicle, str(path), report, **checks)
    else:
        runs = assemble([_csv_stream(path, chmap, report)], chmap, vehicle, str(path), report,
                        chmap.time_factor, **checks)
    return runs, report.lines


def map_context(path: Path | str, chmap: ChannelMap | Path | dict) -> consistency.Context:
    """Names and declared units of a mapped log's channels, for the consistency messages.

    Parameters
    ----------
    path : Path or str
        The log.
    chmap : ChannelMap, Path or dict
        Its map, read or to read.
    """
    if not isinstance(chmap, ChannelMap):
        chmap = read_map(chmap)
    names = {c: f"{path}: {e.label}" for c, e in chmap.entries.items()}
    units = {c: e.unit for c, e in chmap.entries.items() if e.unit != "quaternion"}
    return consistency.Context(names, units, dict(consistency.CANONICAL.signs))


def _csv_stream(csv: Path, chmap: ChannelMap, report: Report) -> Stream:
    try:
        raw = pd.read_csv(csv)
    except FileNotFoundError as exc:
        raise LogError(f"{csv}: no such file") from exc
    except (OSError, pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as exc:
        raise LogError(f"{csv}: cannot read as CSV ({exc})") from exc
    named = {chmap.time_column, *(e.source for e in chmap.entries.values())}
    absent = [c for c in named if c not in raw.columns]
    if absent:
        raise LogError(f"{csv}: column {absent[0]} (named in {chmap.path}) is not in the file; "
                       f"it has {', '.join(map(str, raw.columns))}")
    unused = [str(c) for c in raw.columns if c not in named]
    if unused:
        report.add(f"column(s) {', '.join(unused)} not in the channel map, left out")
    sources = list(dict.fromkeys(e.source for e in chmap.entries.values()))
    return Stream(name=f"column {chmap.time_column}",
                  t=pd.to_numeric(raw[chmap.time_column], errors="coerce").to_numpy(float),
                  raw={s: raw[s].to_numpy() for s in sources},
                  entries=list(chmap.entries.values()))


def tractor_only_map(csv: Path) -> dict:
    """The channel map (as TOML data) of a canonical CSV with ``gamma`` but no semitrailer.

    It names the schema's own columns in SI units, and ``gamma_rate`` if the
    file has it.
    """
    head = pd.read_csv(csv, nrows=0).columns
    names = ["delta_h", *TRACTOR, "gamma"] + (["gamma_rate"] if "gamma_rate" in head else [])
    si = {"time": "s", "length": "m", "angle": "rad", "speed": "m/s", "rate": "rad/s"}
    return {"time": {"column": "t", "unit": "s"},
            "channels": {c: {"column": c, "unit": si[DIMENSION[c]]} for c in names}}
