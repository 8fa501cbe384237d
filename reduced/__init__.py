"""Reduced models for planning and control: KIN (eq. 1) and STM (eq. 2).

This package depends on numpy, numba and :mod:`mjcf` (the vehicle file and the
signals): never on mujoco, rerun, pandas, :mod:`plant` or :mod:`validation`.
Where numba caches the compiled models is the entry point's choice
(:mod:`artic.validation.plumbing.runtime`).
"""

from artic.mjcf.interface import OBSERVATION, InitialState, wrap_angle
from artic.reduced import models
from artic.reduced.control import KIN, STM
from artic.reduced.models import Driven

__all__ = ["KIN", "OBSERVATION", "STM", "Driven", "InitialState", "wrap_angle"]


def __getattr__(name: str):
    if name in ("KinematicModel", "SingleTrackModel"):  # former names: they warn
        return getattr(models, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
