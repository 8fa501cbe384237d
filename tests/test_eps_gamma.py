"""The articulation error eps_gamma: eq. (8) applied to the articulation angle."""

from __future__ import annotations

import math

import numpy as np
import pytest

from artic.validation.criteria.articulation import eps_gamma
from tests.helpers import straight_log


def test_constant_offset_gives_that_offset():
    log = straight_log(n=1500, u=-0.9).frame
    for offset in (0.05, -0.2):
        run = log.copy()
        run["gamma"] += offset
        # A constant error's distance-RMS is the constant: the weights sum to s_max.
        assert eps_gamma(log, run) == pytest.approx(abs(offset), rel=1e-12)
    assert eps_gamma(log, log.copy()) == 0.0


def test_difference_is_wrapped():
    log = straight_log(n=500, u=-0.9).frame
    log["gamma"] = math.pi - 0.01
    run = log.copy()
    run["gamma"] = -math.pi + 0.01  # 0.02 rad away across the cut, not 2 pi - 0.02
    assert eps_gamma(log, run) == pytest.approx(0.02, rel=1e-9)


def test_weighted_by_distance_not_time():
    # Standing still for the first half (no distance), an error of 0.1 rad
    # while moving in the second half: eq. (8) sees only the second half.
    log = straight_log(n=2000, u=-0.9).frame
    log.loc[:999, ["v_x_1", "v_x_2"]] = 0.0
    run = log.copy()
    run.loc[1000:, "gamma"] += 0.1
    run.loc[:999, "gamma"] += 0.3  # at standstill: weighs nothing
    # Sample 999 (at rest) and 1000 (moving) share half a trapezoid: exact to 1/1000.
    assert eps_gamma(log, run) == pytest.approx(0.1, rel=2e-3)
    time_rms = float(np.sqrt(np.mean((run["gamma"] - log["gamma"]) ** 2)))
    assert time_rms > 0.2  # what a time average would have said


def test_only_the_model_rows_count():
    log = straight_log(n=1000, u=-0.9).frame
    run = log.iloc[:400].copy()  # stopped early
    run["gamma"] += 0.07
    assert eps_gamma(log, run) == pytest.approx(0.07, rel=1e-12)
