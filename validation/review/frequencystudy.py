"""The swept sine through the truth and each model, and their frequency responses.

The truth drives the test matrix's swept sine
(:data:`artic.validation.synthetic.testmatrix.SWEEP`) and its sensors measure
it (:func:`artic.validation.synthetic.generate.simulate_manoeuvre`); each model
is then driven open loop by the log's own steering-wheel angle and speed
(:func:`artic.validation.harness.simulate.simulate`), and
:mod:`artic.validation.review.frequency` compares the responses.
"""

from __future__ import annotations

from collections.abc import Sequence

import pandas as pd

from artic.mjcf.vehicle import load_vehicle
from artic.validation.harness.simulate import simulate
from artic.validation.logs.profile import Profile
from artic.validation.logs.runfile import Run
from artic.validation.models import build
from artic.validation.review.frequency import compare, departure


def sweep_log(seed: int = 0) -> Run:
    """The truth's measured log of the swept sine for campaign seed ``seed``."""
    from artic.validation.synthetic.generate import simulate_manoeuvre
    from artic.validation.synthetic.testmatrix import MATRIX

    m = next(m for m in MATRIX if m.kind == "swept-sine")
    return simulate_manoeuvre(m, seed)


def driven_by(log: Run, model: str, vehicle_name: str | None = None) -> Run:
    """A model's open-loop run on a log's steering-wheel angle and tractor speed."""
    vehicle = load_vehicle(vehicle_name or f"gosar2022-{log.meta['load']}")
    f = log.frame
    u1 = f["v_x_1"].to_numpy(dtype=float)
    profile = Profile("swept-sine", f["t"].to_numpy(dtype=float),
                      f["delta_h"].to_numpy(dtype=float), u1, {"manoeuvre": "swept-sine"})
    return simulate(build(model, vehicle), vehicle, profile)


def frequency_study(seed: int = 0, models: Sequence[str] = ("kin", "stm", "mbd"),
                    vehicle_name: str | None = None) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Each model's frequency response against the truth's, and where it departs.

    Parameters
    ----------
    seed : int
        The campaign seed of the truth's log.
    models : sequence of str
        Registered model names.
    vehicle_name : str, optional
        The models' vehicle file or preset; the log's load condition's preset otherwise.

    Returns
    -------
    (DataFrame, DataFrame)
        :func:`~artic.validation.review.frequency.compare`'s table and
        :func:`~artic.validation.review.frequency.departure`'s.
    """
    log = sweep_log(seed)
    table = compare(log, {m: driven_by(log, m, vehicle_name) for m in models})
    return table, departure(table)
