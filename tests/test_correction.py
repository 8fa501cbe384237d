"""steer_fb: the RMS feedback part of the road-wheel angle over distance, in degrees.

On a constructed log at constant speed the distance weights are the time
steps', so the value is known by hand: a feedback of 0.5 deg on the first
half of the samples and none on the rest has an RMS of 0.5 / sqrt(2) deg.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from artic.validation.criteria import columns
from artic.validation.criteria.correction import of_run, steer_fb
from artic.validation.criteria.metrics import run_metrics
from artic.validation.logs.runfile import Run
from tests.helpers import straight_log


def _run_with_feedback(log: Run, fb_deg: np.ndarray, centre_deg: float) -> Run:
    run = log.frame.copy()
    run["delta_fb"] = np.radians(fb_deg)
    run["delta"] = np.radians(centre_deg) + run["delta_fb"]
    return Run(run, dict(log.meta))


def test_steer_fb_is_the_hand_computed_rms_in_degrees():
    log = straight_log(2001, u=-1.0)
    n = len(log.frame)
    fb = np.where(np.arange(n) < n // 2, 0.5, 0.0)
    run = _run_with_feedback(log, fb, centre_deg=2.0)
    # Trapezoidal weights at constant speed: each interior sample weighs dt, the
    # ends dt / 2, and the step at n // 2 splits one interval; the sum of squares
    # over the distance is 0.25 deg^2 on 1000 of 2000 intervals (the half
    # interval at the step adds 0.25 * 0.5).
    expected = math.sqrt(0.25 * (n // 2 - 0.5) / (n - 1))
    assert steer_fb(log.frame, run.frame) == pytest.approx(expected, rel=1e-9)
    assert expected == pytest.approx(0.5 / math.sqrt(2.0), rel=1e-3)
    assert of_run(log, run, None) == {"steer_fb": pytest.approx(expected, rel=1e-9)}
    # J_steer is the same RMS over the mean |delta_center| (2 deg here), in percent.
    j = run_metrics(log.frame, run.frame)["J_steer"]
    assert j == pytest.approx(100.0 * expected / 2.0, rel=1e-9)


def test_steer_fb_needs_the_feedback_column_and_joins_the_table_beside_j_steer():
    log = straight_log(200, u=-1.0)
    assert math.isnan(steer_fb(log.frame, log.frame))  # no delta_fb: no value, not zero
    assert columns.UNITS["steer_fb"] == "deg" and columns.POOL["steer_fb"] == "rms"
    assert columns.COUNTERPARTS["J_steer"] == "steer_fb"
