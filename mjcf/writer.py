"""Write a vehicle parameter file: a base file with some values replaced.

Used by tuning, which writes the fitted steering parameters and cornering
stiffness into a copy of the vehicle file it tuned, with a line in
``vehicle.sources`` that says where the new numbers came from. The file is
re-read and checked before it replaces anything on disk.
"""

from __future__ import annotations

import copy
import tomllib
from pathlib import Path
from typing import Any

import tomli_w

from mjcf.vehicle import Vehicle, load_vehicle, resolve_tyre_file, resolve_vehicle_path


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
    data = tomllib.loads(path.read_text(encoding="utf-8"))
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
    if "file" in tyre:  # keep the tyre reachable from wherever the copy goes
        tyre["file"] = str(resolve_tyre_file(tyre["file"], path).resolve())
    return out


def write_vehicle(data: dict[str, Any], path: str | Path) -> Vehicle:
    """Write ``data`` as a vehicle file, atomically, after checking it loads.

    Returns
    -------
    Vehicle
        The vehicle read back from the written file.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.tmp.toml")
    try:
        tmp.write_text("# Written by artic; see vehicle.sources for the origin of every value.\n"
                       + tomli_w.dumps(data), encoding="utf-8")
        load_vehicle(tmp)
        tmp.replace(path)
    finally:
        tmp.unlink(missing_ok=True)
    return load_vehicle(path)


def fitted_changes(vehicle: Vehicle, fits: dict[str, dict[str, float]]) -> dict[str, dict]:
    """Sections to change for fitted values per model (see :mod:`validation.campaign.tuning`)."""
    changes: dict[str, dict[str, float]] = {}
    for model, values in fits.items():
        steer = {k: v for k, v in values.items() if k in ("i_s", "q", "delta_h_offset")}
        if steer:
            changes[f"steering.{model}"] = steer
        if "f" in values:
            changes["tyre"] = {"f": values["f"]}
    return changes
