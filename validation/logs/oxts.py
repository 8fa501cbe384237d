"""OXTS-style exports: one CSV per inertial unit, one CAN CSV; and ``.mat`` files.

An inertial unit's CSV holds, in the unit's own conventions (x forward, y
right, z down, heading clockwise from north):

| channel | accepted column names | unit |
|---|---|---|
| time | ``Time``, ``GpsTime``, ``TimeFromStart`` | s |
| latitude | ``PosLat``, ``Lat`` | deg |
| longitude | ``PosLon``, ``Long``, ``Lon`` | deg |
| local east / north (instead of lat/lon) | ``PosLocalX``, ``PosLocalY`` | m |
| heading | ``AngleHeading``, ``Heading`` | deg, clockwise from north |
| forward velocity | ``VelForward`` | m/s |
| lateral velocity | ``VelLateral`` | m/s, to the right |
| yaw rate | ``AngRateZ`` | deg/s, about z down |

The CAN CSV holds ``Time`` [s] and ``SteeringWheelAngle`` (or ``SWA``) [deg],
counter-clockwise (left) positive, at 10 Hz.

On import, latitude and longitude become a local east/north plane around the
tractor's first fix. The plane is tangent there, with the WGS84 radii of
curvature at that latitude; over the few hundred metres of a yard its error
stays well under a millimetre. Heading and rates turn into ISO yaw
(counter-clockwise from east) and rates. The units are put on one 100 Hz time base over the span
all three files cover: linear interpolation for the inertial units, hold for
the CAN samples, as the CAN bus delivers them. Everything outside that span
is reported.

A ``.mat`` (v5) file holds the same channels as structs ``tractor``,
``trailer`` and ``can``.
"""

from __future__ import annotations

import gzip
import math
from pathlib import Path

import numpy as np
import pandas as pd

from artic.mjcf.interface import wrap_angle
from artic.validation.logs import consistency
from artic.validation.logs.checks import (
    MAX_GAP,
    MAX_GAP_CAN,
    MAX_JUMP,
    Report,
    check_jumps,
    clean_time,
    fill_nan_runs,
    require,
)
from artic.validation.logs.csvtext import csv_text
from artic.validation.logs.runfile import LogError, Run, atomic_write, check_frame
from artic.validation.logs.scale import FULL_SIZE, LogScale
from artic.validation.logs.schema import COLUMNS

RATE = 100.0
"""Sample rate of the canonical log [Hz]."""

WGS84_A = 6378137.0
WGS84_E2 = 6.69437999014e-3

UNIT = {
    "time": ("Time", "GpsTime", "TimeFromStart"),
    "heading": ("AngleHeading", "Heading"),
    "vel_forward": ("VelForward",),
    "vel_lateral": ("VelLateral",),
    "yaw_rate": ("AngRateZ",),
}
LATLON = {"lat": ("PosLat", "Lat"), "lon": ("PosLon", "Long", "Lon")}
LOCAL = {"east": ("PosLocalX",), "north": ("PosLocalY",)}
CAN = {"time": ("Time", "GpsTime", "TimeFromStart"), "swa": ("SteeringWheelAngle", "SWA")}


def radii(lat0: float) -> tuple[float, float]:
    """WGS84 meridional and prime-vertical radii of curvature at ``lat0`` [rad] [m]."""
    s2 = math.sin(lat0) ** 2
    w = math.sqrt(1.0 - WGS84_E2 * s2)
    return WGS84_A * (1.0 - WGS84_E2) / w ** 3, WGS84_A / w


def read_csv(path: Path) -> pd.DataFrame:
    """Read a CSV table; any failure is a :class:`LogError` naming the file.

    Raises
    ------
    LogError
        For a missing, unreadable, empty or non-UTF-8 file, or a malformed table.
    """
    try:
        return pd.read_csv(path, encoding="utf-8")
    except UnicodeDecodeError as exc:
        raise LogError(f"{path}: not UTF-8 text (byte {exc.start}); save it as UTF-8 "
                       "CSV") from exc
    except (OSError, pd.errors.ParserError, pd.errors.EmptyDataError, ValueError) as exc:
        raise LogError(f"{path}: cannot read as CSV ({str(exc).splitlines()[0]})") from exc



def _enough_rows(df: pd.DataFrame, source: str) -> None:
    if len(df) < 2:
        raise LogError(f"{source}: {len(df)} data row(s) after the header; a run needs at "
                       "least two: the file may be truncated")


def _unit(df: pd.DataFrame, origin: tuple[float, float] | None, source: str,
          report: Report, accept: tuple[str, ...] = (),
          scale: LogScale = FULL_SIZE) -> tuple[pd.DataFrame, tuple[float, float] | None]:
    """One inertial unit's channels in ISO conventions, time cleaned."""
    cols = require(df, UNIT, source)
    uses_latlon = all(any(n in df.columns for n in names) for names in LATLON.values())
    pos = require(df, LATLON if uses_latlon else LOCAL, source)
    _enough_rows(df, source)
    df = clean_time(df, cols["time"], report, max_gap=math.inf if "gap" in accept else MAX_GAP)
    wanted = [cols[k] for k in ("heading", "vel_forward", "vel_lateral", "yaw_rate")]
    df = fill_nan_runs(df, wanted + list(pos.values()), cols["time"], report)
    t = df[cols["time"]].to_numpy(dtype=float)
    if uses_latlon:
        lat = np.radians(df[pos["lat"]].to_numpy(dtype=float))
        lon = np.radians(df[pos["lon"]].to_numpy(dtype=float))
        if origin is None:
            origin = (float(lat[0]), float(lon[0]))
        M, N = radii(origin[0])
        east = N * math.cos(origin[0]) * (lon - origin[1])
        north = M * (lat - origin[0])
    else:
        east = df[pos["east"]].to_numpy(dtype=float)
        north = df[pos["north"]].to_numpy(dtype=float)
    psi = np.unwrap(math.pi / 2 - np.radians(df[cols["heading"]].to_numpy(dtype=float)))
    vx = df[cols["vel_forward"]].to_numpy(dtype=float)
    vy = -df[cols["vel_lateral"]].to_numpy(dtype=float)
    r = -np.radians(df[cols["yaw_rate"]].to_numpy(dtype=float))
    if "jump" not in accept:
        ve = np.cos(psi) * vx - np.sin(psi) * vy
        vn = np.sin(psi) * vx + np.cos(psi) * vy
        check_jumps(t, east, north, ve, vn, report, scale.distance(MAX_JUMP))
    out = pd.DataFrame({"t": t, "x": east, "y": north, "psi": psi, "v_x": vx, "v_y": vy, "r": r})
    out.attrs["columns"] = {**cols, "pos": "/".join(pos.values())}
    return out, origin


def import_oxts(tractor: Path, trailer: Path, can: Path, accept: tuple[str, ...] = (),
                vehicle=None) -> tuple[Run, list[str]]:
    """Import an OXTS-style export (three CSV files) into a canonical run.

    See :func:`import_tables` for the arguments, what is returned and raised.
    """
    tables = [read_csv(Path(p)) for p in (tractor, trailer, can)]
    return import_tables(*tables, sources=(str(tractor), str(trailer), str(can)),
                         accept=accept, vehicle=vehicle)


def import_tables(tractor: pd.DataFrame, trailer: pd.DataFrame, can: pd.DataFrame,
                  sources: tuple[str, str, str], accept: tuple[str, ...] = (),
                  vehicle=None) -> tuple[Run, list[str]]:
    """Import the three raw tables of an export into a canonical run.

    Parameters
    ----------
    tractor, trailer : DataFrame
        Inertial-unit channels.
    can : DataFrame
        CAN channels with the steering-wheel angle.
    sources : tuple of str
        Where each table came from, for messages.
    accept : tuple of str
        Consistency checks whose findings are accepted knowingly (see
        :mod:`artic.validation.logs.consistency`); recorded in ``meta["accepted_checks"]``.
    vehicle : Vehicle, optional
        For the steering and hitch checks.

    Returns
    -------
    run : Run
        Canonical, 100 Hz, time from zero.
    report : list of str
        Every repair and trim made.

    Raises
    ------
    LogError
        For anything it cannot repair; the message names the file, the
        channel and the fix.
    """
    s1, s2, s3 = sources
    scale = LogScale.of(vehicle)
    report = Report(s1)
    u1, origin = _unit(tractor, None, s1, report, accept, scale)
    r2 = Report(s2)
    u2, _ = _unit(trailer, origin, s2, r2, accept, scale)
    r3 = Report(s3)
    cdf = can
    ccols = require(cdf, CAN, s3)
    _enough_rows(cdf, s3)
    cdf = clean_time(cdf, ccols["time"], r3,
                     max_gap=math.inf if "gap" in accept else MAX_GAP_CAN)
    cdf = fill_nan_runs(cdf, [ccols["swa"]], ccols["time"], r3)
    tc = cdf[ccols["time"]].to_numpy(dtype=float)
    swa = np.radians(cdf[ccols["swa"]].to_numpy(dtype=float))
    lines = report.lines + r2.lines + r3.lines
    t0 = max(u1.t.iloc[0], u2.t.iloc[0], tc[0])
    t1 = min(u1.t.iloc[-1], u2.t.iloc[-1], tc[-1] + 0.1)
    if t1 - t0 < 2.0 / RATE:
        raise LogError(f"{s1}, {s2}, {s3}: the three tables share no common time "
                       f"span ({t0!r} to {t1!r}); they are not from one run")
    t = t0 + np.arange(int(math.floor((t1 - t0) * RATE + 1e-9)) + 1) / RATE
    for name, tt in (("tractor", u1.t), ("trailer", u2.t), ("can", tc)):
        before = int(np.sum(tt < t0 - 1e-9))
        after = int(np.sum(tt > t[-1] + 1e-9 + (0.1 if name == "can" else 0.0)))
        if before or after:
            lines.append(f"{name}: {before} sample(s) before and {after} after the span all "
                         f"files cover ({t0:.2f} to {t[-1]:.2f} s) left out")
    frame = {"t": t - t0}
    idx = np.clip(np.searchsorted(tc, t + 1e-9, side="right") - 1, 0, len(tc) - 1)
    frame["delta_h"] = swa[idx]
    for i, u in ((1, u1), (2, u2)):
        for c in ("x", "y", "psi", "v_x", "v_y", "r"):
            frame[f"{c}_{i}"] = np.interp(t, u.t.to_numpy(), u[c].to_numpy())
    frame["gamma"] = wrap_angle(frame["psi_1"] - frame["psi_2"])
    df = pd.DataFrame(frame)[list(COLUMNS)]
    check_frame(df, f"{s1} (imported)", scale)
    cols = {**u1.attrs["columns"], "swa": ccols["swa"]}
    ctx = consistency.export_context(s1, s2, s3, cols)
    accepted = consistency.check_log(df, f"{s1} (imported)", vehicle, accept, ctx)
    meta = {"source": "measured", "import": {"tractor": s1, "trailer": s2, "can": s3,
                                             "origin_lat_lon_rad": origin, "report": lines}}
    if accepted:
        meta["accepted_checks"] = accepted
    return Run(df, meta), lines


GZIP_LEVEL = 1
"""How :func:`export_oxts` compresses with ``compress=True``: gzip at this
level, as loggers rotate their CSV files, with neither a time stamp nor a file
name inside (the same run, the same bytes). Level 1 writes a log's tables in
about a tenth of level 6's time, 14 % larger (107 against 94 kB for a 67 s
constant steer's 268 kB ``tractor.csv``): the synthetic campaign compresses
hundreds of them."""


def _write_csv(path: Path, table: pd.DataFrame, compress: bool) -> None:
    text = csv_text(table).encode("utf-8")
    path.write_bytes(gzip.compress(text, GZIP_LEVEL, mtime=0) if compress else text)


def export_oxts(run: Run, out_dir: Path, origin_deg: tuple[float, float] = (51.45, 5.39),
                can_rate: float = 10.0, can_step_deg: float = 0.1,
                compress: bool = False) -> dict[str, Path]:
    """Write a canonical run as an OXTS-style export (the inverse of :func:`import_oxts`).

    Parameters
    ----------
    run : Run
        Canonical run.
    out_dir : Path
        Folder for ``tractor.csv``, ``trailer.csv``, ``can.csv``.
    origin_deg : tuple
        Latitude and longitude of the local plane's origin [deg].
    can_rate : float
        CAN sample rate [Hz].
    can_step_deg : float
        CAN quantisation of the steering-wheel angle [deg]; 0 for none.
    compress : bool
        Write ``tractor.csv.gz`` and so on (:data:`GZIP_LEVEL`): the same tables in
        about two fifths of the space; the importers read either.
    """
    df = run.frame
    ext = ".csv.gz" if compress else ".csv"
    lat0, lon0 = math.radians(origin_deg[0]), math.radians(origin_deg[1])
    M, N = radii(lat0)
    paths = {}
    for i, name in ((1, "tractor"), (2, "trailer")):
        lat = np.degrees(lat0 + df[f"y_{i}"].to_numpy() / M)
        lon = np.degrees(lon0 + df[f"x_{i}"].to_numpy() / (N * math.cos(lat0)))
        heading = np.mod(90.0 - np.degrees(df[f"psi_{i}"].to_numpy()), 360.0)
        table = pd.DataFrame({
            "Time": df["t"].round(4), "PosLat": lat.round(10), "PosLon": lon.round(10),
            "AngleHeading": heading.round(5), "VelForward": df[f"v_x_{i}"].round(5),
            "VelLateral": (-df[f"v_y_{i}"]).round(5),
            "AngRateZ": (-np.degrees(df[f"r_{i}"])).round(5)})
        paths[name] = atomic_write(Path(out_dir) / f"{name}{ext}",
                                   lambda p, tb=table: _write_csv(p, tb, compress))
    step = max(1, int(round(RATE / can_rate)))
    can = df.iloc[::step]
    swa = np.degrees(can["delta_h"].to_numpy())
    if can_step_deg > 0:
        swa = np.round(swa / can_step_deg) * can_step_deg
    table = pd.DataFrame({"Time": can["t"].round(4), "SteeringWheelAngle": np.round(swa, 6)})
    paths["can"] = atomic_write(Path(out_dir) / f"can{ext}",
                                lambda p: _write_csv(p, table, compress))
    return paths


def import_mat(path: Path, accept: tuple[str, ...] = (), vehicle=None) -> tuple[Run, list[str]]:
    """Import a ``.mat`` (v5) file with structs ``tractor``, ``trailer`` and ``can``.

    The structs' fields are the CSV channel names, each a vector of one
    sample per row; the import then runs as for CSVs (see :func:`import_tables`).

    Raises
    ------
    LogError
        For a file that is not MATLAB v5, a missing struct, a struct array or a
        variable that is not a struct, or a field that is not a numeric vector
        as long as the others; naming the file, the struct and the field.
    """
    path = Path(path)
    try:
        if path.stat().st_size == 0:
            raise LogError(f"{path}: the file is empty (0 bytes); export it again")
        import scipy.io  # here: it takes 0.1 s to import, and most commands read no .mat

        data = scipy.io.loadmat(path, squeeze_me=True, struct_as_record=False)
    except LogError:
        raise
    except (OSError, ValueError, NotImplementedError, TypeError, KeyError,
            IndexError) as exc:
        raise LogError(f"{path}: cannot read as a MATLAB v5 file "
                       f"({str(exc).splitlines()[0] if str(exc) else type(exc).__name__})"
                       ) from exc
    tables = {}
    for name in ("tractor", "trailer", "can"):
        if name not in data:
            raise LogError(f"{path}: missing struct {name}; expected tractor, trailer and can")
        tables[name] = _struct_table(data[name], f"{path}:{name}")
    return import_tables(tables["tractor"], tables["trailer"], tables["can"],
                         sources=tuple(f"{path}:{n}" for n in ("tractor", "trailer", "can")),
                         accept=accept, vehicle=vehicle)


def _struct_table(s, source: str) -> pd.DataFrame:
    """A scalar MATLAB struct of equally long numeric vectors as a table."""
    fields = getattr(s, "_fieldnames", None)
    if fields is None:
        kind = (f"a struct array of {s.size} elements" if isinstance(s, np.ndarray)
                and s.dtype == object else f"a {type(s).__name__}")
        raise LogError(f"{source}: expected a scalar struct whose fields are channels, got "
                       f"{kind}; save one struct per unit")
    cols, length = {}, None
    for f in fields:
        raw = getattr(s, f)
        value = np.atleast_1d(np.asarray(raw))
        if value.ndim != 1 or not (np.issubdtype(value.dtype, np.number)
                                   or value.dtype == bool):
            raise LogError(f"{source}: field {f}: expected a numeric vector, got "
                           f"{type(raw).__name__} of shape {np.shape(raw)}; a field holds one "
                           "channel, one sample per row")
        if length is not None and value.size != length:
            raise LogError(f"{source}: field {f}: {value.size} samples where the fields before "
                           f"it have {length}")
        length = value.size
        cols[f] = value.astype(float)
    return pd.DataFrame(cols)


def export_mat(run: Run, path: Path, **kw) -> Path:
    """Write a canonical run as a ``.mat`` file with the export's channels."""
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        paths = export_oxts(run, Path(tmp), **kw)
        structs = {name: {c: pd.read_csv(p)[c].to_numpy() for c in pd.read_csv(p).columns}
                   for name, p in paths.items()}
    import scipy.io

    return atomic_write(path, lambda p: scipy.io.savemat(p, structs, format="5"))
