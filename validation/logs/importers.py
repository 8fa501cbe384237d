"""``artic logs import``: turn exports into canonical logs.

Accepted sources:

- a canonical log, Parquet or CSV, in the signal schema (checked);
- an OXTS-style export: a folder holding ``tractor.csv``, ``trailer.csv``
  and ``can.csv`` (see :mod:`validation.logs.oxts`), and optionally ``meta.json``
  with the run's metadata (manoeuvre, load, ...);
- a MATLAB ``.mat`` (v5) file with structs ``tractor``, ``trailer``, ``can``.
"""

from __future__ import annotations

import json
from pathlib import Path

import pandas as pd

from validation.logs.oxts import import_mat, import_oxts
from validation.logs.runfile import LogError, Run, check_frame, read_run, write_run


def import_source(path: Path) -> tuple[Run, list[str]]:
    """Import one source into a canonical run.

    Returns
    -------
    run : Run
        Named after the source (file stem or folder name).
    report : list of str
        Repairs and trims made.

    Raises
    ------
    LogError
        For an unknown or unusable source, naming it and the fix.
    """
    path = Path(path)
    if path.is_dir():
        files = [path / f"{n}.csv" for n in ("tractor", "trailer", "can")]
        missing = [f.name for f in files if not f.is_file()]
        if missing:
            raise LogError(f"{path}: an OXTS-style export folder needs tractor.csv, trailer.csv "
                           f"and can.csv; missing {', '.join(missing)}")
        run, report = import_oxts(*files)
        meta = path / "meta.json"
        if meta.is_file():
            run.meta = {**json.loads(meta.read_text()), **run.meta}
    elif path.suffix == ".mat":
        run, report = import_mat(path)
    elif path.suffix == ".parquet":
        run, report = read_run(path), []
    elif path.suffix == ".csv":
        if not path.is_file():
            raise LogError(f"{path}: no such file")
        try:
            frame = pd.read_csv(path)
        except (OSError, pd.errors.ParserError, pd.errors.EmptyDataError) as exc:
            raise LogError(f"{path}: cannot read as CSV ({exc})") from exc
        check_frame(frame, str(path))
        run, report = Run(frame, {"source": "measured"}), []
    else:
        raise LogError(f"{path}: not a log: give a .parquet or .csv canonical log, a .mat file, "
                       "or a folder with tractor.csv, trailer.csv and can.csv")
    run.meta["name"] = path.stem if path.is_file() else path.name
    return run, report


def import_sources(paths: list[Path], out_dir: Path) -> list[Path]:
    """Import every source and write it as ``out_dir/NAME.parquet``, atomically."""
    out = []
    for p in paths:
        run, report = import_source(p)
        for line in report:
            print(f"repaired: {line}")
        out.append(write_run(run, Path(out_dir) / f"{run.name}.parquet"))
    return out
