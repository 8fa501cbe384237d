"""``artic logs import``: turn exports into canonical logs.

Accepted sources:

- a canonical log, Parquet or CSV, in the signal schema (checked);
- an OXTS-style export: a folder holding ``tractor.csv``, ``trailer.csv``
  and ``can.csv``, each possibly gzip-compressed (``tractor.csv.gz``; see
  :mod:`artic.validation.logs.oxts`), and optionally ``meta.json`` with the
  run's metadata (manoeuvre, load, ...);
- a MATLAB ``.mat`` (v5) file with structs ``tractor``, ``trailer``, ``can``;
- a CSV with its own column names, units and time stamps, or a ROS 1 bag, a
  ROS 2 bag (sqlite3 or MCAP storage) or an MCAP file, through a channel map
  (:mod:`artic.validation.logs.channels`); what the log lacks is derived (one
  unit from the other and the articulation angle, rates from poses, the
  steering from the yaw rate) and marked as derived. A canonical CSV without
  the semitrailer's channels but with ``gamma`` is such a log too. A mapped
  log with gaps becomes one run per gap-free segment, ``NAME.seg1``,
  ``NAME.seg2``, ...

Every source, canonical ones included, passes the structural checks of
:func:`artic.validation.logs.runfile.check_frame` and the consistency checks of
:mod:`artic.validation.logs.consistency` (gaps, jumps, units and signs, the hitch).
:func:`read_log` is the same reader for the commands that take canonical
logs (``validate``, ``tune``).
"""

from __future__ import annotations

from collections.abc import Collection
from pathlib import Path

import pandas as pd

from artic.mjcf.vehicle import load_vehicle
from artic.validation.logs import consistency
from artic.validation.logs.bags import is_bag
from artic.validation.logs.channels import import_mapped, map_context, tractor_only_map
from artic.validation.logs.oxts import import_mat, import_oxts, read_csv
from artic.validation.logs.runfile import (
    LogError,
    Run,
    check_frame,
    parse_meta,
    read_run,
    write_run,
)
from artic.validation.logs.scale import LogScale
from artic.validation.logs.schema import SOURCES


def _checked(run: Run, source: str, vehicle, accept: Collection[str],
             ctx: consistency.Context = consistency.CANONICAL) -> Run:
    """The run, after the consistency checks; accepted findings recorded in its metadata.

    The checks accepted when the run was imported (``meta["accepted"]``) stay
    accepted: ``validate`` and ``tune`` remember an ``--accept`` given to ``logs import``.
    """
    accept = tuple(dict.fromkeys([*accept, *consistency.accepted_in(run.meta)]))
    derived = run.meta.get("derived") or {}
    channels = derived.get("channels", []) if isinstance(derived, dict) else []
    tracked = 2 if "x_1" in channels else 1 if "x_2" in channels else None
    accepted = consistency.check_log(run.frame, source, vehicle, accept, ctx,
                                     derived=bool(derived), tracked=tracked, meta=run.meta)
    if accept:
        run.meta["accepted"] = list(accept)
    if accepted:
        lines = [*run.meta.get("accepted_checks", []), *accepted]
        run.meta["accepted_checks"] = list(dict.fromkeys(lines))
    return run


def read_log(path: Path | str, vehicle=None, accept: Collection[str] = ()) -> Run:
    """Read a canonical log and run every check on it.

    Parameters
    ----------
    path : Path or str
        A ``.parquet`` log in the signal schema. An export (a folder, a CSV, a
        ``.mat`` file, a bag) is refused with the ``artic logs import`` line
        that makes one: the import repairs, derives and reports once, and
        writes what every later reader reads.
    vehicle : Vehicle, optional
        For the steering and hitch checks (see :func:`artic.validation.logs.consistency.findings`).
    accept : collection of str
        Checks whose findings are accepted knowingly; recorded in
        ``meta["accepted_checks"]``.

    Raises
    ------
    LogError
        For an unreadable file or the first finding not accepted.

    See Also
    --------
    artic.read_run : a run file as it is, without checks.
    artic.write_run : write one.
    artic.validate_runs : validate models on logs.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> import artic
    >>> vehicle = artic.load_vehicle("gosar2022-unloaded")
    >>> log = artic.simulate(artic.build_model("kin", vehicle), vehicle,
    ...                      artic.make_profile("constant-steer", duration=8.0))
    >>> path = artic.write_run(log, Path(tempfile.mkdtemp()) / "run.parquet")
    >>> artic.read_log(path, vehicle=vehicle).frame.shape
    (801, 17)
    """
    path = Path(path)
    if path.suffix != ".parquet":
        raise LogError(f"{path}: not a canonical log (.parquet); import it first: artic logs "
                       f"import {path} --out-dir DIR writes DIR/{source_name(path)}.parquet")
    run = read_run(path, check=False)
    check_frame(run.frame, str(path), LogScale.of(vehicle))
    return _checked(run, str(path), vehicle, accept)


def _meta_json(path: Path) -> dict:
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise LogError(f"{path}: cannot read ({exc.strerror})") from exc
    return parse_meta(raw, str(path))


def _with_included(meta: dict, folder: Path, report: list[str]) -> dict:
    """``meta`` with the keys it lacks from the file its ``meta_from`` names.

    An export may leave metadata it shares with another export to that one's
    ``meta.json`` (a noise-free twin the truth's records of its measured log,
    :func:`artic.validation.synthetic.generate.write_export`), naming it
    relative to its own folder. Where that file is gone, the import goes on
    without those keys and its report says so.
    """
    ref = meta.pop("meta_from", None)
    if not isinstance(ref, str):
        return meta
    other = folder / ref
    try:
        shared = _meta_json(other)
    except LogError as exc:
        report.append(f"{folder / 'meta.json'}: meta_from {ref}: {exc}; imported without "
                      "the metadata it holds")
        return meta
    return {**shared, **meta}


def source_name(path: Path) -> str:
    """The name a source's canonical log gets: its file stem or folder name."""
    path = Path(path)
    return path.name if path.is_dir() else path.stem


def import_runs(path: Path, accept: Collection[str] = (), vehicle=None,
                channels: Path | None = None) -> tuple[list[Run], list[str]]:
    """Import one source into canonical runs: one, or one per gap-free segment.

    Parameters
    ----------
    path : Path
        The source (see the module docstring).
    accept : collection of str
        Consistency checks accepted knowingly (see :mod:`artic.validation.logs.consistency`).
    vehicle : Vehicle, optional
        For the steering and hitch checks.
    channels : Path, optional
        A channel map for a CSV with its own column names, units and time
        stamps, or for a bag (:mod:`artic.validation.logs.channels`). With it,
        or for a canonical CSV without the semitrailer's channels, what the
        log lacks is derived with ``vehicle``'s geometry (gosar2022-unloaded's
        without one).

    Returns
    -------
    runs : list of Run
        Named after the source (file stem or folder name), with ``.segK``
        appended when a mapped log was split at its gaps (``meta["segment"]``
        then says which part of which log).
    report : list of str
        Repairs and trims made.

    Raises
    ------
    LogError
        For an unknown or unusable source, naming it and the fix.
    """
    path = Path(path)
    accept = tuple(accept)
    if not path.exists():
        raise LogError(f"{path}: no such file or folder")
    if channels is None and is_bag(path):
        raise LogError(f"{path}: a ROS bag or MCAP file is read through a channel map that "
                       "names a topic and field per channel: pass --channels MAP.toml (the "
                       "logs guide of artic's documentation has an example)")
    if channels is not None or _tractor_only(path):
        geometry = vehicle if vehicle is not None else load_vehicle("gosar2022-unloaded")
        spec = channels or tractor_only_map(path)
        runs, report = import_mapped(path, spec, geometry, accept, LogScale.of(vehicle))
        ctx = map_context(path, spec)
        name = source_name(path)
        for run in runs:
            seg = run.meta.get("segment")
            where = str(path) if seg is None else f"{path} (segment {seg['index']} of {seg['of']})"
            _checked(run, where, vehicle, accept, ctx)
            run.meta["name"] = name if seg is None else f"{name}.seg{seg['index']}"
            if seg is not None:
                seg["log"] = name
        return runs, report
    run, report = _import_export(path, accept, vehicle)
    run.meta["name"] = source_name(path)
    return [run], report


def import_source(path: Path, accept: Collection[str] = (), vehicle=None,
                  channels: Path | None = None) -> tuple[Run, list[str]]:
    """Import one source that is one run (see :func:`import_runs`).

    Raises
    ------
    LogError
        Also when a mapped log was split at gaps into several runs.
    """
    runs, report = import_runs(path, accept, vehicle, channels)
    if len(runs) > 1:
        raise LogError(f"{path}: split at its gaps into {len(runs)} segments; import it with "
                       "import_runs (artic logs import writes one file per segment)")
    return runs[0], report


def _import_export(path: Path, accept: tuple[str, ...], vehicle) -> tuple[Run, list[str]]:
    """An export in artic's own layouts: a canonical log, an OXTS folder, a ``.mat``."""
    if path.is_dir():
        # Each table as the logger wrote it, or gzip-compressed (the campaign's exports).
        files = [path / f"{n}.csv" if not (path / f"{n}.csv.gz").is_file()
                 or (path / f"{n}.csv").is_file() else path / f"{n}.csv.gz"
                 for n in ("tractor", "trailer", "can")]
        missing = [f.name for f in files if not f.is_file()]
        if missing:
            raise LogError(f"{path}: an OXTS-style export folder needs tractor.csv, trailer.csv "
                           f"and can.csv; missing {', '.join(missing)}")
        run, report = import_oxts(*files, accept=accept, vehicle=vehicle)
        meta = path / "meta.json"
        if meta.is_file():
            run.meta = {**_with_included(_meta_json(meta), path, report), **run.meta}
    elif path.suffix == ".mat":
        run, report = import_mat(path, accept=accept, vehicle=vehicle)
    elif path.suffix == ".parquet":
        run, report = read_log(path, vehicle, accept), []
    elif path.suffix == ".csv":
        if not path.is_file():
            raise LogError(f"{path}: no such file")
        frame = read_csv(path)
        check_frame(frame, str(path), LogScale.of(vehicle))
        run, report = _checked(Run(frame, {"source": "measured"}), str(path), vehicle,
                               accept), []
    else:
        raise LogError(f"{path}: not a log: give {SOURCES}")
    return run, report


def _tractor_only(path: Path) -> bool:
    """A canonical CSV with the tractor's channels and ``gamma`` but not the semitrailer's."""
    if path.suffix != ".csv" or not path.is_file():
        return False
    try:
        head = pd.read_csv(path, nrows=0).columns
    except (OSError, pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError):
        return False
    return "gamma" in head and "x_1" in head and "x_2" not in head


def import_sources(paths: list[Path], out_dir: Path, accept: Collection[str] = (),
                   vehicle=None, channels: Path | None = None) -> list[Path]:
    """Import every source and write it as ``out_dir/NAME.parquet``, atomically.

    Two sources that would get the same name are refused before anything is
    written: the second would silently replace the first. A log split at its
    gaps is written as ``NAME.seg1.parquet``, ... and the files of an earlier
    import of the same source under the other layout (``NAME.parquet`` or
    other segments) are removed, so that ``validate`` never counts it twice.
    """
    targets: dict[str, Path] = {}
    for p in paths:
        name = source_name(p)
        if name in targets:
            raise LogError(f"{p} and {targets[name]} would both be written as "
                           f"{Path(out_dir) / (name + '.parquet')}; rename one of them or "
                           "import them into different folders")
        targets[name] = Path(p)
    for p in paths:  # all there before anything is written
        if not Path(p).exists():
            raise LogError(f"{p}: no such file or folder")
    out = []
    written: dict[str, Path] = {}
    for p in paths:
        runs, report = import_runs(p, accept, vehicle, channels)
        for line in report:
            print(f"repaired: {line}")
        names = {run.name for run in runs}
        for run in runs:
            for line in run.meta.get("accepted_checks", []):
                print(line)
            if run.name in written:
                raise LogError(f"{p}: its run {run.name} would replace the one written from "
                               f"{written[run.name]}; rename one of the sources")
            written[run.name] = Path(p)
            out.append(write_run(run, Path(out_dir) / f"{run.name}.parquet"))
        for stale in _stale(Path(out_dir), source_name(p), names, Path(p)):
            stale.unlink()
            print(f"removed {stale}: an earlier import of {p} in another layout")
    return out


def _stale(out_dir: Path, name: str, keep: set[str], source: Path) -> list[Path]:
    """Runs in ``out_dir`` written from ``source`` earlier under other names than ``keep``."""
    candidates = [out_dir / f"{name}.parquet", *out_dir.glob(f"{name}.seg*.parquet")]
    stale = []
    for f in candidates:
        if f.stem in keep or not f.is_file():
            continue
        try:
            meta = read_run(f, check=False, columns=["t"]).meta
        except LogError:
            continue
        if str(meta.get("import", {}).get("file")) == str(source):
            stale.append(f)
    return stale
