"""Channel maps: logs with their own column names, units and time stamps.

``artic logs import LOG.csv --channels MAP.toml`` reads a CSV whose columns
are not the accepted NCOM-style names. The map (TOML) names, for each
canonical channel, the column that holds it and its unit:

.. code-block:: toml

    [time]
    column = "t"
    unit = "s"

    [channels]
    delta_h = { column = "steer_ang", unit = "deg" }
    x_1 = { column = "X", unit = "m" }
    gamma = { column = "hitch", unit = "deg", scale = -1.0 }

Canonical channels: ``delta_h``; the tractor's ``x_1, y_1, psi_1, v_x_1,
v_y_1, r_1`` (all required, in the schema's ISO axes at the tractor sensor
of the vehicle file); and either the semitrailer's ``x_2 ... r_2`` or the
articulation ``gamma`` (with ``gamma_rate`` if the log has it), from which
:mod:`artic.validation.logs.derive` derives the semitrailer's. A channel's value is
``unit * (scale * column + offset)``, with ``scale`` (default 1) and
``offset`` (default 0, in the column's unit) for other signs and zeros.
Units: ``s, ms``; ``m, cm, mm``; ``m/s, km/h, mph``; ``rad, deg``;
``rad/s, deg/s``. Columns the map does not name (image paths, say) are left
out, and the report says which.

The time stamps may be irregular. The import runs the same checks and
repairs as for exports (:mod:`artic.validation.logs.checks`): exact duplicates
dropped, short NaN runs interpolated, time going back, gaps (longer than
``max_gap`` in ``[time]``, by default 2.5 times the median interval) and GNSS
jumps refused; then every channel is interpolated linearly onto the 100 Hz
base, and the report says so. The importer then runs the consistency checks
(:mod:`artic.validation.logs.consistency`: units, signs, the hitch) on the result.
"""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import numpy as np
import pandas as pd

from artic.mjcf.interface import wrap_angle
from artic.mjcf.vehicle import Vehicle
from artic.validation.logs import consistency
from artic.validation.logs.checks import (
    MAX_JUMP,
    Report,
    check_jumps,
    clean_time,
    fill_nan_runs,
)
from artic.validation.logs.derive import TRAILER, derive_trailer
from artic.validation.logs.runfile import LogError, Run, check_frame
from artic.validation.logs.scale import FULL_SIZE, LogScale
from artic.validation.logs.schema import COLUMNS

RATE = 100.0
"""Sample rate of the canonical log [Hz]."""

UNITS: dict[str, tuple[str, float]] = {
    "s": ("time", 1.0), "ms": ("time", 1e-3),
    "m": ("length", 1.0), "cm": ("length", 0.01), "mm": ("length", 1e-3),
    "m/s": ("speed", 1.0), "km/h": ("speed", 1 / 3.6), "mph": ("speed", 0.44704),
    "rad": ("angle", 1.0), "deg": ("angle", math.pi / 180),
    "rad/s": ("rate", 1.0), "deg/s": ("rate", math.pi / 180),
}
"""Unit name to (dimension, factor to SI)."""

TRACTOR = ("x_1", "y_1", "psi_1", "v_x_1", "v_y_1", "r_1")

DIMENSION: dict[str, str] = {
    "delta_h": "angle", "gamma": "angle", "gamma_rate": "rate",
    **{f"{c}_{i}": d for i in (1, 2) for c, d in (("x", "length"), ("y", "length"),
                                                  ("psi", "angle"), ("v_x", "speed"),
                                                  ("v_y", "speed"), ("r", "rate"))},
}
"""Every channel a map may name, with its dimension."""

ANGLES = ("delta_h", "psi_1", "psi_2", "gamma")
"""Channels unwrapped before interpolation."""


def _units_of(dim: str) -> str:
    return ", ".join(u for u, (d, _) in UNITS.items() if d == dim)


def read_map(path: Path | dict) -> dict:
    """Read and check a channel map (a TOML file, or its data); see the module docstring.

    Returns
    -------
    dict
        ``time``: (column, factor); ``max_gap`` [s] or None; ``channels``:
        channel to (column, factor, scale, offset).

    Raises
    ------
    LogError
        Naming the map file, the key and the fix.
    """
    if isinstance(path, dict):  # a map made here (see tractor_only_map)
        data, path = path, "the canonical columns"
    else:
        path = Path(path)
        try:
            data = tomllib.loads(path.read_text(encoding="utf-8"))
        except FileNotFoundError as exc:
            raise LogError(f"{path}: no such channel map") from exc
        except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError) as exc:
            raise LogError(f"{path}: cannot read as TOML ({exc})") from exc
    unknown = sorted(set(data) - {"time", "channels"})
    if unknown:
        raise LogError(f"{path}: unknown section(s) {', '.join(unknown)}; a channel map has "
                       "[time] and [channels]")

    def entry(key: str, spec, dim: str) -> tuple[str, float, float, float]:
        if not isinstance(spec, dict) or "column" not in spec or "unit" not in spec:
            example = _units_of(dim).split(",")[0]
            raise LogError(f"{path}: {key}: give a table with column and unit, for example "
                           f'{key.split(".")[-1]} = {{ column = "NAME", unit = "{example}" }}')
        allowed = {"column", "unit", "scale", "offset"} | ({"max_gap"} if key == "time" else set())
        extra = sorted(set(spec) - allowed)
        if extra:
            raise LogError(f"{path}: {key}: unknown key(s) {', '.join(extra)}; use column, unit, "
                           "scale, offset")
        unit = str(spec["unit"])
        if unit not in UNITS or UNITS[unit][0] != dim:
            raise LogError(f"{path}: {key}: unit {unit!r} is not a unit of {dim}; use one of "
                           f"{_units_of(dim)}")
        try:
            scale, offset = float(spec.get("scale", 1.0)), float(spec.get("offset", 0.0))
        except (TypeError, ValueError) as exc:
            raise LogError(f"{path}: {key}: scale and offset must be numbers") from exc
        return str(spec["column"]), UNITS[unit][1], scale, offset

    if "time" not in data:
        raise LogError(f'{path}: missing [time]; add column = "..." and unit = "s"')
    t_col, t_factor, _, _ = entry("time", data["time"], "time")
    max_gap = data["time"].get("max_gap")
    channels = data.get("channels", {})
    bad = sorted(set(channels) - set(DIMENSION))
    if bad:
        raise LogError(f"{path}: channels.{bad[0]}: not a channel; the map can name "
                       f"{', '.join(DIMENSION)}")
    parsed = {c: entry(f"channels.{c}", spec, DIMENSION[c]) for c, spec in channels.items()}
    missing = [c for c in ("delta_h", *TRACTOR) if c not in channels]
    if missing:
        raise LogError(f"{path}: [channels] is missing {', '.join(missing)}; a log needs the "
                       "steering-wheel angle and the tractor's six channels")
    has_trailer = all(c in channels for c in TRAILER)
    if not has_trailer and "gamma" not in channels:
        raise LogError(f"{path}: [channels] has neither the semitrailer's "
                       f"{', '.join(TRAILER)} nor gamma (the articulation angle) to derive them")
    return {"time": (t_col, t_factor), "max_gap": None if max_gap is None else float(max_gap),
            "channels": parsed}


def import_mapped(csv: Path, map_path: Path | dict, vehicle: Vehicle,
                  accept: tuple[str, ...] = (),
                  scale: LogScale = FULL_SIZE) -> tuple[Run, list[str]]:
    """Import a CSV through a channel map onto the 100 Hz base.

    Parameters
    ----------
    csv : Path
        The log.
    map_path : Path or dict
        Its channel map (see the module docstring), or the map's data.
    vehicle : Vehicle
        Geometry for deriving the semitrailer's channels, when the log has
        only the tractor's and the articulation angle.
    accept : tuple of str
        Consistency checks accepted knowingly: ``gap`` and ``jump`` let the
        raw samples' gaps and jumps through to the canonical log's checks, which
        record them; ``velocity`` skips the raw velocity's unit check.
    scale : LogScale
        The vehicle's scale, for the jump distance and the limits of speeds
        and yaw rates (:mod:`artic.validation.logs.scale`).

    Returns
    -------
    run : Run
        Canonical, 100 Hz, time from zero; ``meta["derived"]`` says which
        channels were derived and how.
    report : list of str
        Every repair, trim, resampling and derivation.
    """
    csv = Path(csv)
    spec = read_map(map_path)
    if isinstance(map_path, dict):
        map_path = "the canonical columns"
    try:
        raw = pd.read_csv(csv)
    except FileNotFoundError as exc:
        raise LogError(f"{csv}: no such file") from exc
    except (OSError, pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as exc:
        raise LogError(f"{csv}: cannot read as CSV ({exc})") from exc
    t_col, t_factor = spec["time"]
    named = {t_col, *(c for c, _, _, _ in spec["channels"].values())}
    absent = [c for c in named if c not in raw.columns]
    if absent:
        raise LogError(f"{csv}: column {absent[0]} (named in {map_path}) is not in the file; it "
                       f"has {', '.join(map(str, raw.columns))}")
    report = Report(str(csv))
    unused = [str(c) for c in raw.columns if c not in named]
    if unused:
        report.add(f"column(s) {', '.join(unused)} not in the channel map, left out")
    raw = raw[[c for c in raw.columns if c in named]]
    t_raw = pd.to_numeric(raw[t_col], errors="coerce").to_numpy(dtype=float)
    finite = np.diff(t_raw[np.isfinite(t_raw)])
    median_dt = float(np.median(finite[finite > 0])) if (finite > 0).any() else 0.0
    max_gap = spec["max_gap"] if spec["max_gap"] is not None else 2.5 * median_dt * t_factor
    max_gap = math.inf if "gap" in accept else max_gap
    raw = clean_time(raw, t_col, report, max_gap=max_gap / t_factor)
    cols = [c for c, _, _, _ in spec["channels"].values()]
    raw = fill_nan_runs(raw, list(dict.fromkeys(cols)), t_col, report)
    t = raw[t_col].to_numpy(dtype=float) * t_factor
    si = {name: factor * (scale * raw[col].to_numpy(dtype=float) + offset)
          for name, (col, factor, scale, offset) in spec["channels"].items()}
    for name in ANGLES:
        if name in si:
            si[name] = np.unwrap(si[name])
    ctx = map_context(csv, spec)
    for i in (1, 2):
        if f"psi_{i}" not in si:
            continue
        psi = si[f"psi_{i}"]
        if "velocity" not in accept:  # a speed in km/h is named as such, not as a jump
            _check_velocity_unit(t, si, i, ctx, scale, csv)
        if "jump" not in accept:
            ve, vn = _world(psi, si[f"v_x_{i}"], si[f"v_y_{i}"])
            check_jumps(t, si[f"x_{i}"], si[f"y_{i}"], ve, vn, report,
                        scale.distance(MAX_JUMP))
    if len(t) < 2:
        raise LogError(f"{csv}: fewer than two samples; the file may be truncated")
    grid = t[0] + np.arange(int(math.floor((t[-1] - t[0]) * RATE + 1e-9)) + 1) / RATE
    dt = np.diff(t)
    report.add(f"{len(t)} samples at intervals of {dt.min():.3f} to {dt.max():.3f} s (median "
               f"{float(np.median(dt)):.3f} s) interpolated linearly onto {RATE:g} Hz "
               f"({len(grid)} samples)")
    frame = {"t": grid - grid[0]}
    frame.update({name: np.interp(grid, t, v) for name, v in si.items()})
    meta: dict = {"source": "measured", "import": {"file": str(csv), "channels": str(map_path)}}
    df = pd.DataFrame(frame)
    if all(c in df for c in TRAILER):
        df["gamma"] = wrap_angle(df["psi_1"].to_numpy() - df["psi_2"].to_numpy())
    else:
        if "gamma" not in df:  # pragma: no cover - read_map refuses it
            raise LogError(f"{map_path}: no gamma")
        rate = df["gamma_rate"].to_numpy() if "gamma_rate" in df else None
        df, note = derive_trailer(df, vehicle, rate)
        report.add(note)
        meta["derived"] = {"channels": list(TRAILER), "vehicle": vehicle.name,
                           "vehicle_path": str(vehicle.path), "note": note,
                           "rate": "gamma_rate" if rate is not None else "d gamma / dt"}
    df["gamma"] = wrap_angle(df["gamma"].to_numpy())
    df = df[list(COLUMNS)]
    check_frame(df, f"{csv} (imported through {map_path})", scale)
    meta["import"]["report"] = report.lines
    return Run(df, meta), report.lines


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


def map_context(csv: Path | str, spec: dict) -> consistency.Context:
    """Names and declared units of a mapped log's columns, for the consistency messages.

    Parameters
    ----------
    csv : Path or str
        The log.
    spec : dict
        Its map, as :func:`read_map` returns it (or the map itself).
    """
    if not isinstance(spec, dict) or "channels" not in spec or not all(
            isinstance(v, tuple) for v in spec["channels"].values()):
        spec = read_map(spec)
    names, units = {}, {}
    for name, (col, factor, _, _) in spec["channels"].items():
        names[name] = f"{csv}: {col}"
        units[name] = next((u for u, (d, f) in UNITS.items()
                            if d == DIMENSION[name] and f == factor), "")
    return consistency.Context(names, units, dict(consistency.CANONICAL.signs))


def _check_velocity_unit(t: np.ndarray, si: dict, i: int, ctx: consistency.Context,
                         scale: LogScale, csv: Path) -> None:
    """Refuse a velocity in the wrong unit or sign, on the raw samples, naming the unit.

    Run before the jump check: a speed 3.6 times too large also moves every
    position step away from what the velocity explains, which would otherwise
    be named as a GNSS jump.
    """
    if t.size < 2:  # refused as truncated further on
        return
    cols = [f"{c}_{i}" for c in ("x", "y", "psi", "v_x", "v_y")]
    frame = pd.DataFrame({c: si[c] for c in cols})
    found = consistency.check_velocity(t, frame, i, ctx, scale)
    if found is not None and not found.direction:
        raise LogError(found.finding.message(str(csv)))


def _world(psi: np.ndarray, vx: np.ndarray, vy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    c, s = np.cos(psi), np.sin(psi)
    return c * vx - s * vy, s * vx + c * vy
