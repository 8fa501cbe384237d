"""artic: tractor-semitrailer dynamics at yard speeds, forward and in reverse.

The names listed in ``__all__`` are artic's public, stable API, and so is
the pytest plugin :mod:`artic.validation.testing` (its fixtures and
assertions); everything else (the sub-packages :mod:`artic.mjcf`,
:mod:`artic.plant`, :mod:`artic.reduced`, :mod:`artic.validation` and their
modules) is internal and may change between minor versions. The public names
are loaded on first use, so ``import artic`` stays light.

Vehicles and logs
    :func:`load_vehicle`, :func:`preset_names`, :class:`Vehicle` (a bad
    vehicle file raises :class:`VehicleFileError`); :func:`read_log` (a
    canonical run file, ``.parquet``; ``artic logs import`` makes one from
    other formats), :func:`read_run` and :func:`write_run` (run files as they
    are, without checks), :class:`Run`; a bad log raises :class:`LogError`.
Models
    :class:`KIN` and :class:`STM`, the reduced models for planners and
    controllers (named states and inputs, ``rhs``, a discrete ``step``,
    analytic Jacobians, ``linearise`` about a straight line or a steady turn,
    over batches), the same classes the harness drives and the registry
    builds (:class:`KinematicModel` and :class:`SingleTrackModel` are their
    former names, which warn); :class:`Plant`, the MuJoCo
    multibody reference (its errors raise :class:`PlantError`);
    :func:`build_model` builds any of the harness's by name.
    :func:`register_model` adds a model of your own (or :func:`model_spec`
    for an ``artic.models`` entry point); :func:`model_names` lists them all.
Simulating and validating
    :func:`simulate` (open loop, through a :class:`Profile` of inputs, such
    as :func:`make_profile` builds), :func:`run_closed_loop` (the harness
    with the reversing feedback of eqs. (5)-(7)), :func:`run_metrics` (the
    criteria of eqs. (8)-(10)), :func:`validate_runs` (many logs and models
    at once).
The campaign
    :func:`run_campaign`, with a :class:`CampaignConfig` of its choices.
Errors
    :mod:`errors`: the base of artic's errors, the user's (a wrong file, log,
    option or vehicle) and the plant's, as the command line tells them apart.
Docking controllers
    :class:`Controller`, the base of a controller of your own for
    ``artic dock --controller module:Class``, and the :class:`Command` it
    returns.
"""

from __future__ import annotations

import importlib
import sys
import types
from typing import Any

# artic.mjcf, .plant, .reduced and .validation are the folders mjcf/, plant/,
# reduced/ and validation/ at the repository root: setup.py maps them under this
# name (package-dir), a wheel stores them as artic/mjcf/..., and an editable
# install's finder maps each to its folder. This package's search path is its
# own folder alone.

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
    "errors": ("artic.errors", ""),
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
    "CampaignConfig": ("artic.validation.campaign.config", "CampaignConfig"),
    "Profile": ("artic.validation.logs.profile", "Profile"),
    "make_profile": ("artic.validation.synthetic.manoeuvres", "make_profile"),
    "Controller": ("artic.validation.docking.controllers.base", "Controller"),
    "Command": ("artic.validation.docking.controllers.base", "Command"),
}

__all__ = sorted(_PUBLIC) + ["__version__"]


def _version() -> str:
    """The installed version of artic, or ``0+unknown`` from a checkout never installed.

    Read on first use: ``importlib.metadata`` takes about a tenth of a second to
    import, which ``import artic`` and ``artic --help`` should not pay.
    """
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("artic")
    except PackageNotFoundError:
        return "0+unknown"


class _Artic(types.ModuleType):
    """The module ``artic``, with its public names imported on first use.

    The loading lives on the module's class rather than as module-level
    ``__getattr__`` and ``__dir__`` functions (PEP 562), so that ``help(artic)``
    lists the public API and not the machinery.
    """

    def __getattr__(self, name: str) -> Any:
        if name == "__version__":
            value = _version()
            setattr(self, name, value)
            return value
        try:
            module, attr = _PUBLIC[name]
        except KeyError:
            raise AttributeError(f"module 'artic' has no attribute {name!r}") from None
        value = importlib.import_module(module)
        value = getattr(value, attr) if attr else value  # "": the module itself
        setattr(self, name, value)  # later look-ups skip this method
        return value

    def __dir__(self) -> list[str]:
        return sorted(set(vars(self)) | set(__all__))


sys.modules[__name__].__class__ = _Artic
