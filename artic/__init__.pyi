"""The types of artic's public API, for type checkers (mypy, pyright).

``artic/__init__.py`` imports these names on first use, which a type checker
cannot follow; this stub names each one where it lives. A test checks that
the two list the same names.
"""

from artic import errors as errors
from artic.mjcf.schema import VehicleFileError
from artic.mjcf.vehicle import Vehicle, load_vehicle, preset_names
from artic.plant.plant import Plant, PlantError
from artic.reduced.control import KIN, STM
from artic.reduced.models import KinematicModel, SingleTrackModel
from artic.validation.campaign.config import CampaignConfig
from artic.validation.campaign.main import run_campaign
from artic.validation.criteria.metrics import run_metrics
from artic.validation.docking.controllers.base import Command, Controller
from artic.validation.harness.loop import run_closed_loop
from artic.validation.harness.simulate import simulate
from artic.validation.logs.importers import read_log
from artic.validation.logs.profile import Profile
from artic.validation.logs.runfile import LogError, Run, read_run, write_run
from artic.validation.models import build as build_model
from artic.validation.models import model_spec, register_model
from artic.validation.models import names as model_names
from artic.validation.runs.validate import validate_runs
from artic.validation.synthetic.manoeuvres import make_profile

__version__: str
__all__ = [
    "CampaignConfig",
    "Command",
    "Controller",
    "KIN",
    "KinematicModel",
    "LogError",
    "Plant",
    "PlantError",
    "Profile",
    "Run",
    "STM",
    "SingleTrackModel",
    "Vehicle",
    "VehicleFileError",
    "build_model",
    "errors",
    "load_vehicle",
    "make_profile",
    "model_names",
    "model_spec",
    "preset_names",
    "read_log",
    "read_run",
    "register_model",
    "run_campaign",
    "run_closed_loop",
    "run_metrics",
    "simulate",
    "validate_runs",
    "write_run",
    "__version__",
]
