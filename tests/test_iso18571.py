"""ISO/TS 18571's rating against values computed by hand on small signals.

Each case's scores follow from the standard's formulas with pencil and paper
(worked in the comments); the tests use only :func:`rate` and :func:`grade`,
none of the module's helpers. The tolerance, 1e-12, is rounding in sums of a
few hundred terms of order one.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from artic.validation.criteria.iso18571 import grade, rate

TOL = 1e-12


def _alternating(n: int = 200) -> np.ndarray:
    """+1, -1, +1, ...: each sample's nearest value in the other signal is its own
    sample's (a scaled or offset copy), so the time warping's least-cost path is the
    diagonal, and the interior central differences are 0."""
    return np.where(np.arange(n) % 2 == 0, 1.0, -1.0)


def test_identical_signals_rate_one():
    t = np.sin(np.linspace(0.0, 6.0, 300))
    r = rate(t, t.copy(), 0.1)
    assert (r.corridor, r.phase, r.magnitude, r.slope, r.overall) == (1.0, 1.0, 1.0, 1.0, 1.0)
    assert r.shift == 0 and r.grade == "excellent"


def test_a_scaled_signal():
    # C = 1.2 T, T = +-1: every |C - T| = 0.2, between the corridors 0.05 and 0.5:
    # Z = ((0.5 - 0.2) / (0.5 - 0.05))**2 = (2/3)**2. No shift (correlation 1 at 0).
    # Magnitude: eps = sum 0.2 / sum 1 = 0.2, E_M = (0.5 - 0.2) / 0.5 = 0.6.
    # Slope: the derivatives scale by 1.2 too, eps = 0.2, E_S = (2 - 0.2) / 2 = 0.9.
    t = _alternating()
    r = rate(t, 1.2 * t, 0.1)
    assert r.shift == 0
    assert r.corridor == pytest.approx(4.0 / 9.0, abs=TOL)
    assert r.phase == 1.0
    assert r.magnitude == pytest.approx(0.6, abs=TOL)
    assert r.slope == pytest.approx(0.9, abs=TOL)
    # R = 0.4 * 4/9 + 0.2 * (1 + 0.6 + 0.9)
    assert r.overall == pytest.approx(0.4 * 4.0 / 9.0 + 0.5, abs=TOL)
    assert r.grade == "fair"


def test_a_slightly_scaled_smooth_signal_stays_in_the_inner_corridor():
    # C = 1.04 T: |C - T| <= 0.04 max|T| < 0.05 max|T|, every sample scores 1; the slope
    # error is 0.04 whatever T is (the smoothed derivative is linear): E_S = 0.98.
    t = np.sin(np.linspace(0.0, 6.0, 300))
    r = rate(t, 1.04 * t, 0.1)
    assert r.corridor == 1.0 and r.phase == 1.0
    assert r.slope == pytest.approx(0.98, abs=TOL)


def test_a_pure_time_shift():
    # A unit step at sample 40 of 100, and the same step 5 samples later. Corridor: the 5
    # samples 40..44 differ by 1 > 0.5 (outside the outer corridor, 0), the 95 others by 0:
    # Z = 0.95. Phase: shifted back by 5 the overlaps are the same (correlation 1), the limit
    # is 0.2 * 100 = 20 samples: E_P = (20 - 5) / 20 = 0.75. Magnitude and slope compare
    # the same shifted signals: 1. R = 0.4 * 0.95 + 0.2 * (0.75 + 1 + 1) = 0.93, good.
    n = 100
    t = (np.arange(n) >= 40).astype(float)
    c = (np.arange(n) >= 45).astype(float)
    r = rate(t, c, 0.01)
    assert r.shift == 5
    assert r.corridor == pytest.approx(0.95, abs=TOL)
    assert r.phase == pytest.approx(0.75, abs=TOL)
    assert r.magnitude == 1.0 and r.slope == 1.0
    assert r.overall == pytest.approx(0.93, abs=TOL)
    assert r.grade == "good"
    # and leading by 5 is a shift of -5, with the same scores
    lead = rate(c, t, 0.01)
    assert lead.shift == -5 and lead.overall == pytest.approx(0.93, abs=TOL)


def test_a_shift_beyond_the_limit_scores_no_phase():
    # a step shifted by 30 of 100 samples: the best correlation within +-20 samples is at
    # the limit or short of it, never at 30; a shift of 20 or more scores 0.
    n = 100
    t = (np.arange(n) >= 30).astype(float)
    c = (np.arange(n) >= 60).astype(float)
    r = rate(t, c, 0.01)
    assert abs(r.shift) <= 20
    assert r.phase == pytest.approx((20 - abs(r.shift)) / 20, abs=TOL)


def test_outside_the_outer_corridor_scores_zero():
    # C = T + 0.6, T = +-1: every |C - T| = 0.6 > 0.5 max|T|: Z = 0. An offset leaves the
    # correlation at 1 (no shift) and the derivatives alone (E_S = 1); the magnitude
    # error is sum 0.6 / sum 1 = 0.6 > 0.5: E_M = 0. R = 0.2 + 0.2 = 0.4, poor.
    t = _alternating()
    r = rate(t, t + 0.6, 0.1)
    assert r.corridor == 0.0 and r.magnitude == 0.0
    assert r.phase == 1.0 and r.slope == 1.0
    assert r.overall == pytest.approx(0.4, abs=TOL)
    assert r.grade == "poor"


def test_grades_at_their_bounds():
    # above each bound and at most the one above it
    assert [grade(x) for x in (1.0, 0.941, 0.94, 0.801, 0.8, 0.581, 0.58, 0.0)] == [
        "excellent", "excellent", "good", "good", "fair", "fair", "poor", "poor"]
    assert grade(math.nan) == "none"


def test_a_reference_without_amplitude_has_no_rating():
    r = rate(np.zeros(50), np.ones(50), 0.1)
    assert math.isnan(r.overall)


def test_bad_input_is_refused_in_one_line():
    with pytest.raises(ValueError, match="one length"):
        rate(np.zeros(5), np.zeros(6), 0.1)
    with pytest.raises(ValueError, match="NaN"):
        rate(np.array([0.0, 1.0, np.nan]), np.zeros(3), 0.1)
