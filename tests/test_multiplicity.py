"""The p values of the paired tables and their correction for multiplicity."""

from __future__ import annotations

import math

import numpy as np
import pytest

from artic.validation.criteria.multiplicity import (
    P_MIN,
    benjamini_hochberg,
    bootstrap_p,
    holm,
    paired_p,
)
from artic.validation.criteria.statistics import mean_ci

# A family of five p values, adjusted by hand.
P = [0.01, 0.04, 0.03, 0.005, 0.20]
# Holm: sorted 0.005, 0.01, 0.03, 0.04, 0.20 times 5, 4, 3, 2, 1 gives 0.025,
# 0.04, 0.09, 0.08, 0.20; the running maximum makes the fourth 0.09.
HOLM = [0.04, 0.09, 0.09, 0.025, 0.20]
# Benjamini-Hochberg: m p_(k) / k = 0.025, 0.025, 0.05, 0.05, 0.20; the running
# minimum from the top changes nothing here.
BH = [0.025, 0.05, 0.05, 0.025, 0.20]


def test_holm_against_a_hand_computed_family():
    assert holm(P) == pytest.approx(HOLM, abs=1e-15)
    # At 5 %: Holm rejects 0.005 (< 0.05/5) and 0.01 (< 0.05/4), then stops at
    # 0.03 (> 0.05/3), although 0.03 and 0.04 are below 0.05 alone.
    assert list(np.asarray(holm(P)) < 0.05) == [True, False, False, True, False]


def test_benjamini_hochberg_against_a_hand_computed_family():
    assert benjamini_hochberg(P) == pytest.approx(BH, abs=1e-15)
    # The step-up: the largest k with p_(k) <= k/m 0.05 is k = 2 (0.01 <= 0.02);
    # 0.03 > 0.03? no: 0.03 <= 0.03, so k = 3, and 0.04 <= 0.04 gives k = 4.
    assert list(np.asarray(benjamini_hochberg(P)) <= 0.05) == [True, True, True, True, False]


def test_adjustments_leave_nan_out_of_the_family_and_cap_at_one():
    got = holm([0.3, math.nan, 0.6])
    assert math.isnan(got[1])
    assert got[0] == pytest.approx(0.6) and got[2] == pytest.approx(0.6)  # m = 2, not 3
    assert holm([0.9, 0.8])[0] == 1.0
    assert len(holm([])) == 0


@pytest.mark.parametrize("seed", range(6))
def test_the_p_value_is_the_one_the_interval_inverts(seed):
    # p < 1 - confidence exactly where mean_ci's interval at that confidence
    # excludes zero: a 2 % wider or narrower level flips the verdict.
    rng = np.random.default_rng(seed)
    n = (5, 9, 17, 33, 33, 50)[seed]  # Student's t below 8 values, BCa from it on
    x = (rng.gamma(2.0, 1.0, n) - 2.0) * (1 if seed % 2 else -1) + rng.normal(0.0, 1.0, n)
    x += 2.0 * x.std() / math.sqrt(n) - np.mean(x)  # t near 2: a p near the usual levels
    p = paired_p(x)
    assert 1e-3 < p < 0.9, p
    assert not mean_ci(x, confidence=1.0 - 0.98 * p).excludes(0.0)
    assert mean_ci(x, confidence=1.0 - 1.02 * p).excludes(0.0)


def test_p_value_edges():
    assert math.isnan(paired_p([1.0]))
    assert paired_p([2.0, 2.0, 2.0]) == 0.0  # no spread, not zero: its interval is the value
    assert paired_p([0.0, 0.0]) == 1.0
    far = np.linspace(10.0, 11.0, 20)  # every resample on one side
    assert bootstrap_p(far) == P_MIN
