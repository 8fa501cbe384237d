"""The p values of the paired tables and their correction for multiplicity."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats

from artic.validation.criteria.multiplicity import (
    benjamini_hochberg,
    hall_p,
    holm,
    paired_p,
    paired_test,
    sign_flip_p,
    truck_p,
)

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


def test_holm_is_statsmodels_holm_to_the_bit(monkeypatch):
    # artic computes Holm itself (statsmodels' ends in a gc.collect() a call);
    # on families with ties, NaN, p values near 1 and a single one, every bit agrees.
    import gc

    from statsmodels.stats.multitest import multipletests

    # That collection frees nothing the p values depend on; in a process that has run
    # many tests it took half a second a call (100 calls, 52 s in the fast suite): skipped here.
    monkeypatch.setattr(gc, "collect", lambda generation=2: 0)

    rng = np.random.default_rng(7)
    for m in (1, 2, 5, 33, 96):
        for _ in range(20):
            p = rng.uniform(0.0, 1.0, m) ** rng.uniform(0.5, 4.0)
            p[rng.random(m) < 0.2] = p[0]  # ties
            nan = rng.random(m) < 0.1
            p[nan] = math.nan
            got = holm(p)
            want = np.full(m, math.nan)
            if (~nan).any():
                want[~nan] = multipletests(p[~nan], method="holm")[1]
            assert np.array_equal(got, want, equal_nan=True), (m, p)


def test_halls_skewness_and_t_tail_are_scipys_to_the_bit():
    # _hall computes scipy.stats.skew(bias=False) and stats.t.sf without scipy's
    # wrappers; on rows normal, skewed, tied, heavy-tailed, near-constant on a
    # large offset and exactly constant (NaN skewness), every bit agrees.
    import warnings

    from artic.validation.criteria import multiplicity as mp

    rng = np.random.default_rng(11)
    for k in range(600):
        n, rows = int(rng.integers(3, 91)), int(rng.integers(1, 6))
        x = [rng.normal(0.1, 1.0, (rows, n)), rng.lognormal(0.0, 1.5, (rows, n)) - 1.0,
             rng.choice([0.1, -0.2, 0.5], (rows, n)), 1e3 + rng.normal(0.0, 1e-9, (rows, n)),
             rng.standard_t(2, (rows, n))][k % 5]
        if k % 50 == 0:
            x[0] = 5.0
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # scipy's precision-loss warning on the constant rows
            want = np.asarray(stats.skew(x, axis=1, bias=False), dtype=float)
        assert mp._skew(x).tobytes() == want.tobytes(), (n, rows)
        t = np.abs(rng.standard_t(3, rows)) * 10.0 ** rng.uniform(-3.0, 2.0, rows)
        t[0] = [t[0], math.inf, math.nan][k % 3]
        want = np.asarray(stats.t.sf(t, n - 1), dtype=float)
        got = np.asarray(mp.special.stdtr(n - 1, -t), dtype=float)
        assert got.tobytes() == want.tobytes(), (n, t)


def test_signed_sums_are_the_concatenated_ones_to_the_bit():
    # The sign-flip test's enumeration built in one array: every sum in the
    # order and to the bit of concatenating [s + a_i, s - a_i] value by value.
    from artic.validation.criteria import multiplicity as mp

    rng = np.random.default_rng(5)
    for k in (0, 1, 2, 7, 12, 17):
        a = np.abs(rng.standard_t(2, k))
        want = np.zeros(1)
        for v in a:
            want = np.concatenate([want + v, want - v])
        assert mp._sums(a).tobytes() == want.tobytes(), k


def test_benjamini_hochberg_leaves_nan_out_of_the_family():
    got = benjamini_hochberg([0.02, math.nan, 0.04])
    assert math.isnan(got[1]) and got[[0, 2]] == pytest.approx([0.04, 0.04])  # m = 2


@pytest.mark.parametrize("seed", range(4))
def test_the_p_value_is_the_larger_of_the_sign_flip_and_halls(seed):
    rng = np.random.default_rng(seed)
    n = (9, 17, 33, 50)[seed]  # exact enumeration up to 34 values, random patterns above
    x = rng.normal(0.5, 1.0, n)
    t = paired_test(x)
    assert t.testable and t.n == n
    assert t.p == max(sign_flip_p(x), hall_p(x))
    # Hall's correction is zero for a sample without skewness: Student's t
    sym = np.concatenate([x - x.mean(), x.mean() - x]) + 0.3
    assert hall_p(sym) == pytest.approx(stats.ttest_1samp(sym, 0.0).pvalue, rel=1e-9)


def test_halls_correction_moves_the_p_value_away_from_the_long_tail():
    # Right-skewed differences with a negative mean: the t test overstates the
    # evidence for "below zero" (a sample that lacks the long tail); Hall's p is larger.
    x = np.array([-0.9, -0.8, -0.85, -0.7, -0.95, -0.6, -0.75, -0.5, -0.88, -0.3, -0.65,
                  -0.92, -0.4, -0.8, 0.9, -0.7, 0.4])
    assert stats.skew(x, bias=False) > 0 and x.mean() < 0
    assert hall_p(x) > stats.ttest_1samp(x, 0.0).pvalue


def test_p_value_edges():
    assert math.isnan(paired_p([1.0]))
    assert not paired_test([1.0, 2.0]).testable  # no skewness from two values
    # Equal differences: the sign-flip test alone, 2 of 2^n patterns as extreme.
    assert paired_p([2.0, 2.0, 2.0]) == pytest.approx(2 / 8)
    assert paired_p([0.0, 0.0, 0.0]) == 1.0
    assert paired_p([1.0, -1.0, 1.0, -1.0]) == 1.0  # a mean of zero
    assert sign_flip_p(np.linspace(10.0, 11.0, 20)) == pytest.approx(2 / 2 ** 20)


def test_means_over_trucks_take_students_t():
    x = [0.3, 0.5, 0.1, 0.4, 0.35]
    assert truck_p(x) == pytest.approx(stats.ttest_1samp(x, 0.0).pvalue)
    assert math.isnan(truck_p([0.3]))


def test_paired_test_kept_results_are_the_computed_ones():
    """A paired test kept for the leave-one-class-out tables is the one computed, to the bit."""
    from artic.validation.criteria import multiplicity as mp

    x = np.random.default_rng(3).normal(0.2, 1.0, 12)
    first = mp.paired_test(x)
    assert mp.paired_test(x.copy()) is first
    assert mp._paired_test(x, mp.SEED) == first
    assert mp.paired_test(x[:-1]) != first  # another sample: its own test
