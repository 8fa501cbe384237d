"""Write a vehicle parameter file: a base file with some values replaced.

Used by tuning, which writes the fitted steering parameters and cornering
stiffness into a copy of the vehicle file it tuned, with a line in
``vehicle.sources`` that says where the new numbers came from. The file is
re-read and checked before it replaces anything on disk.

The copy names its tyre file portably: by its bare name when it is one
shipped with artic, otherwise by a path relative to the copy's folder, so the
copy works on another machine and from another installation.
"""

from __future__ import annotations

import copy
import os
import tempfile
from importlib import resources
from pathlib import Path
from typing import Any

import tomli_w

from artic.mjcf.files import TEMP_SUFFIX, public_mode
from artic.mjcf.vehicle import (
    Vehicle,
    load_vehicle,
    read_vehicle_toml,
    resolve_tyre_file,
    resolve_vehicle_path,
)


def updated(base: str | Path, changes: dict[str, dict[str, Any]], source: str,
            name: str | None = None) -> dict[str, Any]:
    """The base file's data with ``changes`` merged in.

    Parameters
    ----------
    base : str or Path
        Preset name or file path.
    changes : dict
        Section path (``"steering.stm"``, ``"tyre"``) to keys and values.
    source : str
        Appended to ``vehicle.sources``.
    name : str, optional
        New ``vehicle.name``.
    """
    path = resolve_vehicle_path(base)
    data = read_vehicle_toml(path)
    out = copy.deepcopy(data)
    for section, values in changes.items():
        node = out
        for part in section.split("."):
            node = node.setdefault(part, {})
        node.update({k: v if isinstance(v, bool) else [float(x) for x in v]
                     if isinstance(v, list | tuple) else float(v) for k, v in values.items()})
    vehicle = out.setdefault("vehicle", {})
    vehicle["sources"] = [*vehicle.get("sources", []), source]
    if name:
        vehicle["name"] = name
    tyre = out.get("tyre", {})
    if isinstance(tyre.get("file"), str):  # resolved now; made portable by write_vehicle
        tyre["file"] = str(resolve_tyre_file(tyre["file"], path).resolve())
    return out


def portable_tyre(tyre_file: str | Path, target: str | Path) -> str:
    """How a vehicle file at ``target`` names ``tyre_file``: shipped name or relative path."""
    tyre_file = Path(tyre_file).resolve()
    shipped = Path(str(resources.files("artic.mjcf") / "tyres" / tyre_file.name))
    beside = Path(target).resolve().parent / tyre_file.name
    if shipped.is_file() and shipped.resolve() == tyre_file and not beside.is_file():
        return tyre_file.name
    return Path(os.path.relpath(tyre_file, Path(target).resolve().parent)).as_posix()


def write_vehicle(data: dict[str, Any], path: str | Path) -> Vehicle:
    """Write ``data`` as a vehicle file, atomically, after checking it loads.

    The temporary has a unique name (concurrent writers of one target never
    share it) and gets the umask's mode; ``tyre.file`` is written portably
    (see :func:`portable_tyre`).

    Returns
    -------
    Vehicle
        The vehicle read back from the written file.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    data = copy.deepcopy(data)
    tyre = data.get("tyre", {})
    if isinstance(tyre, dict) and isinstance(tyre.get("file"), str) \
            and Path(tyre["file"]).is_absolute():
        tyre["file"] = portable_tyre(tyre["file"], path)
    text = ("# Written by artic; see vehicle.sources for the origin of every value.\n"
            + tomli_w.dumps(data))
    fd, name = tempfile.mkstemp(prefix=f".{path.name}.", suffix=TEMP_SUFFIX, dir=path.parent)
    tmp = Path(name)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text)
        load_vehicle(tmp)
        public_mode(tmp)
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)
    return load_vehicle(path)


def fitted_changes(vehicle: Vehicle, fits: dict[str, dict[str, float]]) -> dict[str, dict]:
    """Sections to change for fitted values per model.

    See :mod:`artic.validation.campaign.tuning`.
    """
    changes: dict[str, dict[str, float]] = {}
    for model, values in fits.items():
        steer = {k: v for k, v in values.items() if k in ("i_s", "q", "delta_h_offset")}
        if steer:
            changes[f"steering.{model}"] = steer
        if "f" in values:
            changes["tyre"] = {"f": values["f"]}
    return changes
