"""Reading, checking and writing runs in the signal schema.

A run is stored as Parquet with its metadata inside, under the key ``artic``
as JSON: manoeuvre, direction, load condition, vehicle, sensor positions and
source. Files are written atomically: to a temporary file beside the target,
then renamed, so a reader never sees half a file.
"""

from __future__ import annotations

import json
import os
import tempfile
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq

from artic.mjcf.errors import UserError
from artic.mjcf.files import TEMP_SUFFIX, public_mode
from artic.mjcf.interface import wrap_angle
from artic.validation.logs.scale import FULL_SIZE, LogScale
from artic.validation.logs.schema import COLUMNS, UNIT_HINT

META_KEY = b"artic"

MAX_POSITION = 1e7
"""Largest position coordinate [m]: a quarter meridian. No point on the earth lies further
from the origin of a local plane or a UTM grid; beyond it the column is in another unit
or offset by mistake (float64 then also loses the millimetres)."""

MAX_HEADING_START = 1e3
"""Largest yaw angle at a run's first sample [rad]: 160 turns. An unwrapped heading carried
over from before the run stays far below; beyond it the column is in another unit."""

MAX_TIME = 1e10
"""Largest time stamp [s], 300 years: Unix time fits; beyond it float64 cannot resolve the
100 Hz samples."""


class LogError(UserError):
    """A log cannot be used as it is; the message names the file, the column and the fix.

    Examples
    --------
    >>> import artic
    >>> try:
    ...     artic.read_run("no-such-run.parquet")
    ... except artic.LogError as error:
    ...     print(type(error).__name__)
    LogError
    """


@dataclass
class Run:
    """A run in the signal schema with its metadata.

    Parameters
    ----------
    frame : DataFrame
        One row per sample; at least the schema's columns.
    meta : dict
        JSON-serialisable metadata.

    See Also
    --------
    artic.read_log : a log from a file.
    artic.read_run : a run file as it is.
    artic.write_run : write one.

    Examples
    --------
    >>> import pandas as pd
    >>> import artic
    >>> run = artic.Run(pd.DataFrame({"t": [0.0, 0.01]}), {"name": "two samples"})
    >>> run.meta["name"], len(run.frame)
    ('two samples', 2)
    """

    frame: pd.DataFrame
    meta: dict[str, Any] = field(default_factory=dict)

    @property
    def name(self) -> str:
        """The run's name, from its metadata."""
        return str(self.meta.get("name", "run"))


def atomic_write(path: Path | str, write: Callable[[Path], None]) -> Path:
    """Write a file atomically: ``write(tmp)`` then rename ``tmp`` onto ``path``.

    The temporary ``.NAME.XXXX.part`` has a unique name, so concurrent writers never
    share one, and gets the mode the umask allows before it takes the target's name.

    Parameters
    ----------
    path : Path or str
        Target file; its folder is created if needed.
    write : callable
        Writes the content to the temporary path it is given.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=TEMP_SUFFIX, dir=path.parent)
    os.close(fd)
    try:
        write(Path(tmp))
        public_mode(tmp)  # mkstemp's 0600 would ignore the umask
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path


def atomic_write_text(path: Path | str, text: str) -> Path:
    """Write text atomically (see :func:`atomic_write`)."""
    return atomic_write(path, lambda p: p.write_text(text, encoding="utf-8"))


SINGLE_SIGNALS = tuple(c for c in COLUMNS if c != "t")
"""The schema's signals a run file may store in single precision (``write_run(single=)``):
every one but the time. float32 resolves 6e-8 relative: a position on a 300 m
yard to 0.03 mm (the exports' latitude and longitude carry 0.01 mm, the RTK
noise a centimetre), a heading of 30 rad (unwrapped) to 2e-6 rad, a speed of
15 m/s to 1e-6 m/s (the exports carry 1e-5), a yaw rate, an articulation or a
steering angle below 4 rad to 2.4e-7: below the measurement's noise by three
orders and below every printed digit of the criteria. The time stays double:
at 240 s float32 resolves only 1.5e-5 s, which the speed's differences over a
10 ms sample would feel."""

ZSTD_LEVEL = 6
"""zstd's level for run files: within a few per cent of its best on runs, at a
fraction of the best's time."""


def write_run(run: Run, path: Path | str, single: Sequence[str] = ()) -> Path:
    """Write a run as Parquet with its metadata, atomically.

    The samples are stored losslessly unless ``single`` names them: zstd
    over each floating column's bytes split by significance (Parquet's
    byte-stream split, which lets the compressor see the slowly changing
    sign, exponent and leading mantissa bytes apart from the noisy ones),
    the metadata once (Parquet's key-value metadata; not again in an Arrow
    schema copy, which doubled the footer of a log holding the truth's
    states). A log's file is about two thirds of its plain float64 size.

    Parameters
    ----------
    run : Run
        Frame and metadata.
    path : Path or str
        Target ``.parquet`` file.
    single : sequence of str
        Columns to store in single precision (float32: 6e-8 relative, a
        hundredth of a millimetre on a yard of 300 m). :func:`read_run`
        returns the schema's and the model signals' columns in float64
        again (exactly the stored values). For model runs, whose criteria
        are computed before they are written (``artic.validation.runs.validate``).

    See Also
    --------
    artic.read_run : read one back.
    artic.Run : what it writes.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> import artic
    >>> vehicle = artic.load_vehicle("gosar2022-unloaded")
    >>> log = artic.simulate(artic.build_model("kin", vehicle), vehicle,
    ...                      artic.make_profile("constant-steer", duration=8.0))
    >>> path = artic.write_run(log, Path(tempfile.mkdtemp()) / "run.parquet")
    >>> artic.read_run(path).frame.equals(log.frame)
    True
    """
    table = _arrow_table(run.frame, single)
    meta = dict(table.schema.metadata or {})
    meta[META_KEY] = json.dumps(run.meta, sort_keys=True, default=_json_default).encode()
    floats = [f.name for f in table.schema if pa.types.is_floating(f.type)]
    others = [f.name for f in table.schema if f.name not in floats]

    def write(p: Path) -> None:
        with pq.ParquetWriter(p, table.schema, compression="zstd",
                              compression_level=ZSTD_LEVEL, use_dictionary=others,
                              use_byte_stream_split=floats or False,
                              store_schema=False) as w:
            w.write_table(table)
            w.add_key_value_metadata(meta)  # once: no Arrow schema copy holds it again

    return atomic_write(path, write)


_EMPTY_SCHEMAS: dict[tuple, pa.Schema] = {}
"""The Arrow schema of each empty frame's columns and dtypes :func:`write_run` has met."""


def _arrow_table(frame: pd.DataFrame, single: Sequence[str]) -> pa.Table:
    """``frame`` as Arrow, the ``single`` columns it has in float32.

    A frame without rows (a campaign's run file that keeps the metadata alone)
    takes the schema converted once for its columns and dtypes: pandas' and
    Arrow's conversion of a frame of 150 columns costs about ten milliseconds
    whatever its length, and the schema (its pandas metadata included) depends
    on the columns and dtypes alone, so the file is the same to the byte.
    """
    single = [c for c in single if c in frame.columns]
    key = None
    if len(frame) == 0 and frame.columns.is_unique:
        cast = frozenset(single)
        key = (frame.columns.name, str(frame.columns.dtype),
               tuple((c, "float32" if c in cast else str(t))
                     for c, t in zip(frame.columns, frame.dtypes, strict=True)))
        schema = _EMPTY_SCHEMAS.get(key)
        if schema is not None:
            return schema.empty_table()
    if single:
        frame = frame.astype(dict.fromkeys(single, np.float32))
    table = pa.Table.from_pandas(frame, preserve_index=False)
    if key is not None:
        _EMPTY_SCHEMAS[key] = table.schema
    return table


def _json_default(o: Any) -> Any:
    if isinstance(o, np.generic):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    if isinstance(o, Path):
        return str(o)
    raise TypeError(f"metadata value {o!r} is not JSON-serialisable")


def read_run(path: Path | str, check: bool = True,
             columns: Sequence[str] | None = None) -> Run:
    """Read a run written by :func:`write_run` (or any Parquet in the schema).

    Parameters
    ----------
    path : Path or str
        The ``.parquet`` file.
    check : bool
        Check the frame with :func:`check_frame`.
    columns : sequence of str, optional
        Read only these columns, of those the file has (a plant run's
        drawing columns are most of its file); all of them by default.

    Raises
    ------
    LogError
        If the file is missing, not Parquet, or fails the checks.

    See Also
    --------
    artic.read_log : a log, checked.
    artic.write_run : write one.
    artic.Run : what it returns.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> import artic
    >>> bad = Path(tempfile.mkdtemp()) / "bad.parquet"
    >>> _ = bad.write_text("not parquet")
    >>> try:
    ...     artic.read_run(bad)
    ... except artic.LogError as error:
    ...     print("refused:", "not a readable Parquet file" in str(error))
    refused: True
    """
    path = Path(path)
    if not path.is_file():
        raise LogError(f"{path}: no such file")
    try:
        if columns is not None:
            have = set(pq.read_schema(path).names)
            columns = [c for c in columns if c in have]
        table = pq.read_table(path, columns=columns)
        kv = table.schema.metadata or {}
    except (pa.ArrowInvalid, OSError) as exc:
        raise LogError(f"{path}: not a readable Parquet file ({exc}); it may be truncated: "
                       "write it again") from exc
    raw = kv.get(META_KEY)
    meta = parse_meta(raw, f"{path}: Parquet metadata '{META_KEY.decode()}'") if raw else {}
    # A run read from disk is known by its file: two files never share a name.
    meta["name"] = path.stem
    frame = table.to_pandas()
    # Columns a model run stored in single precision (write_run's ``single``)
    # come back in float64, the precision every reader computes in.
    back = [c for c in frame.columns if frame[c].dtype == np.float32
            and (c in COLUMNS or c in DOUBLE_ON_READ)]
    if back:
        frame = frame.astype(dict.fromkeys(back, np.float64))
    if check:
        check_frame(frame, str(path))
    return Run(frame, meta)


DOUBLE_ON_READ = ("delta", "delta_fb")
"""Model-run columns beyond the schema that :func:`read_run` returns in float64."""


def parse_meta(raw: bytes | str, source: str) -> dict[str, Any]:
    """Run metadata from JSON text: an object, or a :class:`LogError` naming ``source``."""
    try:
        meta = json.loads(raw)
    except UnicodeDecodeError as exc:
        raise LogError(f"{source}: not UTF-8 text (byte {exc.start})") from exc
    except ValueError as exc:
        raise LogError(f"{source}: not valid JSON ({exc})") from exc
    except RecursionError as exc:
        raise LogError(f"{source}: JSON nested too deeply") from exc
    if not isinstance(meta, dict):
        raise LogError(f"{source}: expected a JSON object of run metadata "
                       f"({{\"manoeuvre\": ..., \"load\": ...}}), got {type(meta).__name__}")
    check_meta(meta, source)
    return meta


META_VALUES: dict[str, tuple[Callable[[Any], bool], str]] = {
    "direction": (lambda v: v in ("forward", "reverse"), '"forward" or "reverse"'),
    "manoeuvre": (lambda v: isinstance(v, str), "a string (the manoeuvre's kind)"),
    "load": (lambda v: isinstance(v, str), 'a string ("unloaded", "loaded")'),
    "name": (lambda v: isinstance(v, str), "a string"),
    "sensor_noise": (lambda v: isinstance(v, dict),
                     'an object of channels ({"x_1": {"sigma": 0.01}, ...}, SI units)'),
}
"""The metadata keys artic reads, with what each must hold. A value outside it is refused
when the log is read: a ``direction`` of ``"sideways"`` would otherwise leave the log out of
every table (forward and reverse) without a word, a ``sensor_noise`` of ``"loud"`` read as
none declared. Other keys are the user's, kept as they are."""


def check_meta(meta: dict, source: str) -> None:
    """Refuse a metadata value artic reads that is not of its kind (:data:`META_VALUES`).

    Raises
    ------
    LogError
        Naming ``source``, the key, the value and what it must hold.
    """
    for key, (ok, expected) in META_VALUES.items():
        if key in meta and meta[key] is not None and not ok(meta[key]):
            raise LogError(f"{source}: metadata {key!r} is {json.dumps(meta[key])[:60]}; it "
                           f"must be {expected}: correct it, or remove the key")


def check_frame(df: pd.DataFrame, source: str = "log", scale: LogScale = FULL_SIZE,
                derived: Sequence[str] = ()) -> None:
    """Check a frame against the signal schema; raise on anything unusable.

    Checks, in order: the columns are there; the run has at least two
    samples; every column holds numbers (not text); nothing is NaN or
    infinite; time strictly increases; magnitudes are plausible for their
    units (speeds and yaw rates for the vehicle's scale, positions within
    :data:`MAX_POSITION`, headings within :data:`MAX_HEADING_START` at the
    start and turning no faster than the yaw-rate limit allows, time within
    :data:`MAX_TIME`); ``gamma`` agrees with ``psi_1 - psi_2``.

    Parameters
    ----------
    df : DataFrame
        The frame.
    source : str
        File or name, for the message.
    scale : LogScale
        The vehicle's scale, for the limits of speeds and yaw rates
        (:mod:`artic.validation.logs.scale`); full-size by default.
    derived : sequence of str
        Columns derived at import: a limit they break is blamed on the channels
        they come from, not on their own unit.

    Raises
    ------
    LogError
        Naming the source, the column, the first bad row and the fix.
    """
    missing = [c for c in COLUMNS if c not in df.columns]
    if missing:
        raise LogError(f"{source}: missing column(s) {', '.join(missing)}; a log needs "
                       f"{', '.join(COLUMNS)} (SI units, radians)")
    if len(df) < 2:
        raise LogError(f"{source}: {len(df)} sample(s); a run needs at least two: "
                       "the file may be truncated")
    for c in COLUMNS:
        if not pd.api.types.is_numeric_dtype(df[c]):
            as_number = pd.to_numeric(df[c], errors="coerce").to_numpy(dtype=float)
            text = ~np.isfinite(as_number) & df[c].notna().to_numpy()
            i = int(np.argmax(text)) if text.any() else 0
            raise LogError(f"{source}: column {c}: holds {df[c].dtype} values, not numbers "
                           f"(row {i}: {str(df[c].iloc[i])[:20]!r}); store it as a number "
                           "column in SI units")
        col = df[c].to_numpy(dtype=float)
        bad = ~np.isfinite(col)
        if bad.any():
            i = int(np.argmax(bad))
            raise LogError(f"{source}: column {c}: {int(bad.sum())} NaN or infinite value(s), "
                           f"first at row {i}; repair or cut the run before validating")
    t = df["t"].to_numpy(dtype=float)
    if float(np.max(np.abs(t))) > MAX_TIME:
        raise LogError(f"{source}: column t: {float(np.max(np.abs(t))):.4g} s is beyond "
                       f"{MAX_TIME:g} s; time is seconds since the start of the run")
    dt = np.diff(t)
    if np.any(dt <= 0):
        i = int(np.argmax(dt <= 0)) + 1
        raise LogError(f"{source}: column t: time does not increase at row {i} "
                       f"(t = {float(t[i - 1])!r} then {float(t[i])!r}); sort the run and drop "
                       "duplicate samples before validating")
    for c in ("x_1", "y_1", "x_2", "y_2"):
        peak = float(np.max(np.abs(df[c].to_numpy(dtype=float))))
        if peak > MAX_POSITION:
            raise LogError(f"{source}: column {c}: {peak:.4g} m is beyond {MAX_POSITION:g} m, "
                           "further than any point on the earth from a local plane's origin; "
                           "subtract the offset or convert the unit at import")
    limits = scale.plausible
    for c, limit in limits.items():
        peak = float(np.max(np.abs(df[c].to_numpy(dtype=float))))
        if peak > limit:
            where = "" if scale.length == 1.0 else f" at the vehicle's scale ({scale.length:.3g})"
            if c in derived:
                raise LogError(f"{source}: column {c} (derived at import, not in the log): peak "
                               f"{peak:.4g} is beyond {limit:.4g} (SI) for a yard "
                               f"manoeuvre{where}; the channels it is derived from are in "
                               "another unit: positions in too large a unit, time stamps in "
                               "too small a one, or a heading off. Check their units in the "
                               "channel map.")
            raise LogError(f"{source}: column {c}: peak {peak:.4g} is beyond {limit:.4g} "
                           f"(SI) for a yard manoeuvre{where}; this looks like {UNIT_HINT[c]}. "
                           "Convert units at import.")
    duration = float(t[-1] - t[0])
    for c, r in (("psi_1", "r_1"), ("psi_2", "r_2")):
        psi = df[c].to_numpy(dtype=float)
        if abs(psi[0]) > MAX_HEADING_START:
            raise LogError(f"{source}: column {c}: {psi[0]:.4g} rad at the start is beyond "
                           f"{MAX_HEADING_START:g} rad; a yaw angle is in radians, "
                           "counter-clockwise from x: convert the unit at import")
        turn = float(np.ptp(psi))
        most = limits[r] * duration + 2.0 * np.pi
        if turn > most:
            raise LogError(f"{source}: column {c}: turns {turn:.4g} rad in {duration:.4g} s, "
                           f"more than the {limits[r]:.3g} rad/s yaw-rate limit allows "
                           f"({most:.4g} rad); this looks like degrees or another unit read "
                           "as radians. Convert units at import.")
    g = df["gamma"].to_numpy(dtype=float)
    g2 = wrap_angle(df["psi_1"].to_numpy(dtype=float) - df["psi_2"].to_numpy(dtype=float))
    err = np.abs(wrap_angle(g - g2))
    if np.max(err) > np.radians(1.0):
        i = int(np.argmax(err))
        raise LogError(f"{source}: column gamma: differs from psi_1 - psi_2 by "
                       f"{np.degrees(err[i]):.1f} deg at row {i}; gamma is tractor yaw minus "
                       "semitrailer yaw (check its sign and unit)")


def new_frame(t: np.ndarray, delta_h: np.ndarray, obs: np.ndarray) -> pd.DataFrame:
    """Assemble a schema frame from time, steering-wheel angle and observations.

    Parameters
    ----------
    t : ndarray, shape (N,)
        Time [s].
    delta_h : ndarray, shape (N,)
        Steering-wheel angle [rad].
    obs : ndarray, shape (N, 13)
        Signals in ``OBSERVATION`` order.
    """
    df = pd.DataFrame(obs, columns=list(COLUMNS[2:]))
    df.insert(0, "delta_h", np.asarray(delta_h, dtype=float))
    df.insert(0, "t", np.asarray(t, dtype=float))
    return df
