"""Reduced models for planning and control: KIN (eq. 1) and STM (eq. 2).

This package depends on numpy and numba only: never on mujoco, rerun or pandas.
"""

from reduced import _cache  # noqa: F401 - before any compiled function is defined
from reduced.interface import OBSERVATION, InitialState, Model, wrap_angle
from reduced.models import KinematicModel, SingleTrackModel

MODELS = {"kin": KinematicModel, "stm": SingleTrackModel}

__all__ = ["MODELS", "OBSERVATION", "InitialState", "KinematicModel", "Model",
           "SingleTrackModel", "wrap_angle"]
