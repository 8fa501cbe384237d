"""The floor's open-loop predictions: the truth of a log replaying its own actuation.

The registry's ``floor`` (:mod:`artic.validation.models`) is the truth that made
each log without its random processes, driven through the harness; for the
open-loop predictions it takes instead, at every step, the pedals and steering
the truth was given then (:func:`floor_replay`).
"""

from __future__ import annotations

from artic.mjcf.vehicle import Vehicle
from artic.validation.criteria.prediction import Replay, recorded_actuation
from artic.validation.logs.runfile import Run
from artic.validation.models import Model
from artic.validation.synthetic.truthmodel import truth_model


def floor_replay(vehicle: Vehicle, log: Run) -> Model | None:
    """The floor replaying the truth's own actuation, for the open-loop predictions.

    The truth of ``log`` in the speed mode that made it (its driver's pedals),
    wrapped to take at every step what it was given then
    (:class:`artic.validation.criteria.prediction.Replay`): the reference of
    what a perfect model could predict. ``None`` when the log holds no
    recorded actuation (a log made before it was recorded): the floor then
    predicts through the harness's speed follower.
    """
    actuation = recorded_actuation(log.meta)
    if actuation is None:
        return None
    return Replay(truth_model(vehicle, log.meta.get("truth") or {}, speed=actuation.speed),
                  actuation)
