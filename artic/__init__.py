"""artic: tractor-semitrailer dynamics at yard speeds, forward and in reverse.

The names listed in ``__all__`` are artic's public, stable API; everything
else (the sub-packages :mod:`artic.mjcf`, :mod:`artic.plant`,
:mod:`artic.reduced`, :mod:`artic.validation` and their modules) is internal
and may change between minor versions. The public names are loaded on first
use, so ``import artic`` stays light.

Vehicles and logs
    :func:`load_vehicle`, :func:`preset_names`, :class:`Vehicle`,
    :func:`read_log` (any supported log file), :func:`read_run` (a canonical
    run file), :class:`Run`.
Models
    :class:`KIN` and :class:`STM`, the reduced models for planners and
    controllers (named states and inputs, ``rhs``, a discrete ``step``,
    analytic Jacobians, ``linearise`` about a straight line or a steady turn,
    over batches); :class:`KinematicModel` and :class:`SingleTrackModel`, the
    same models as the harness drives them; :class:`Plant`, the MuJoCo
    multibody reference; :func:`build_model` builds any of the harness's by
    name. :func:`register_model` adds a model of your own (or
    :func:`model_spec` for an ``artic.models`` entry point);
    :func:`model_names` lists them all.
Simulating and validating
    :func:`simulate` (open loop), :func:`run_closed_loop` (the harness with the
    reversing feedback of eqs. (5)-(7)), :func:`run_metrics` (the criteria of
    eqs. (8)-(10)), :func:`validate_runs` (many logs and models at once).
The campaign
    :func:`run_campaign`.
"""

from __future__ import annotations

import importlib
from typing import Any

try:
    from importlib.metadata import PackageNotFoundError, version

    __version__ = version("artic")
except PackageNotFoundError:  # run from a checkout that was never installed
    __version__ = "0+unknown"

# name -> (module, attribute): the public API, imported on first use.
_PUBLIC = {
    "Vehicle": ("artic.mjcf.vehicle", "Vehicle"),
    "VehicleFileError": ("artic.mjcf.schema", "VehicleFileError"),
    "load_vehicle": ("artic.mjcf.vehicle", "load_vehicle"),
    "preset_names": ("artic.mjcf.vehicle", "preset_names"),
    "Run": ("artic.validation.logs.runfile", "Run"),
    "LogError": ("artic.validation.logs.runfile", "LogError"),
    "read_run": ("artic.validation.logs.runfile", "read_run"),
    "write_run": ("artic.validation.logs.runfile", "write_run"),
    "read_log": ("artic.validation.logs.importers", "read_log"),
    "KIN": ("artic.reduced.control", "KIN"),
    "STM": ("artic.reduced.control", "STM"),
    "KinematicModel": ("artic.reduced.models", "KinematicModel"),
    "SingleTrackModel": ("artic.reduced.models", "SingleTrackModel"),
    "Plant": ("artic.plant.plant", "Plant"),
    "PlantError": ("artic.plant.plant", "PlantError"),
    "build_model": ("artic.validation.models", "build"),
    "register_model": ("artic.validation.models", "register_model"),
    "model_spec": ("artic.validation.models", "model_spec"),
    "model_names": ("artic.validation.models", "names"),
    "simulate": ("artic.validation.harness.simulate", "simulate"),
    "run_closed_loop": ("artic.validation.harness.loop", "run_closed_loop"),
    "run_metrics": ("artic.validation.criteria.metrics", "run_metrics"),
    "validate_runs": ("artic.validation.runs.validate", "validate_runs"),
    "run_campaign": ("artic.validation.campaign.main", "run_campaign"),
}

__all__ = sorted(_PUBLIC) + ["__version__"]


def __getattr__(name: str) -> Any:
    """Import a public name on first use (PEP 562)."""
    try:
        module, attr = _PUBLIC[name]
    except KeyError:
        raise AttributeError(f"module 'artic' has no attribute {name!r}") from None
    value = getattr(importlib.import_module(module), attr)
    globals()[name] = value  # later look-ups skip this function
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
