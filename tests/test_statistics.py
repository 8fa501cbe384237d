"""Confidence intervals, paired comparisons and the digit rule (artic.validation.criteria)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats

from artic.validation.criteria import statistics as st
from artic.validation.criteria.statistics import Interval, format_ci, mean_ci, paired


def plain_bootstrap_coverage(n: int) -> float:
    """What the plain 95 % bootstrap interval of a normal mean covers at ``n`` values.

    Its spread is the sample's with divisor n, so it covers when
    |t_{n-1}| < 1.96 sqrt((n - 1) / n).
    """
    return float(2 * stats.t.cdf(1.959964 * math.sqrt((n - 1) / n), n - 1) - 1)


@pytest.mark.parametrize("n", [5, 17])
def test_coverage_on_normal_data_is_95_percent(n, monkeypatch):
    # 1000 samples of n normal values, each bootstrapped with its own seed: the
    # intervals hold the true mean 95 % of the time, within three binomial
    # standard deviations (0.021). n = 5 takes Student's t; at n = 17 the plain
    # bootstrap would cover only 92.5 % (outside the tolerance), which the
    # expanded level corrects. 1999 resamples instead of the tables' 9999 keep
    # the test fast; they move an interval's ends by about 1 % of its width.
    monkeypatch.setattr(st, "RESAMPLES", 1999)
    trials, mu = 1000, 3.0
    rng = np.random.default_rng(20260)
    hits = 0
    for k in range(trials):
        iv = mean_ci(rng.normal(mu, 2.0, n), seed=k)
        hits += iv.lo <= mu <= iv.hi
        assert iv.method == ("Student t" if n < st.BOOTSTRAP_MIN else "BCa bootstrap (expanded)")
    tol = 3 * math.sqrt(0.95 * 0.05 / trials)
    assert abs(hits / trials - 0.95) < tol
    if n == 17:
        assert plain_bootstrap_coverage(n) < 0.95 - tol


def test_expanded_level_matches_student_t_width():
    # A normal interval with the bootstrap's spread (divisor n) at the expanded
    # level is exactly as wide as Student's t with divisor n - 1.
    for n in (8, 17, 33):
        z = stats.norm.ppf(0.5 + st.expanded_level(n) / 2)
        assert z * math.sqrt((n - 1) / n) == pytest.approx(stats.t.ppf(0.975, n - 1), rel=1e-9)


def test_same_values_and_seed_give_the_same_interval():
    x = np.random.default_rng(3).normal(5.0, 1.0, 25)
    assert mean_ci(x, seed=11) == mean_ci(x.copy(), seed=11)
    other = mean_ci(x, seed=12)
    assert other.mean == mean_ci(x).mean and other.lo != mean_ci(x, seed=11).lo
    # ... and the seeds move the ends by about 1 % of the interval's width.
    a, b = mean_ci(x, seed=11), other
    assert abs(a.lo - b.lo) < 0.02 * (a.hi - a.lo) and abs(a.hi - b.hi) < 0.02 * (a.hi - a.lo)


def test_small_and_degenerate_samples_fall_back_clearly():
    none = mean_ci([4.2])
    assert none.n == 1 and math.isnan(none.lo) and none.method == "none"
    assert format_ci(none) == "4.2 (n = 1)"
    two = mean_ci([1.0, 3.0])  # Student t, 1 degree of freedom: mean ± 12.71 * 1 / 1
    assert two.method == "Student t"
    assert (two.lo, two.hi) == pytest.approx((2.0 - 12.706205, 2.0 + 12.706205), rel=1e-6)
    flat = mean_ci(np.zeros(20))
    assert (flat.lo, flat.hi, flat.method) == (0.0, 0.0, "constant")
    assert format_ci(flat) == "0 ± 0"
    assert mean_ci([math.nan, 1.0, 2.0, 3.0]).n == 3  # NaN is a missing result
    assert format_ci(mean_ci([])) == "-"


def test_a_known_paired_difference_is_resolved_and_a_zero_one_is_not():
    # Manoeuvre-to-manoeuvre variation (SD 5) far larger than the models'
    # difference (0.8, SD 0.3 of the differences): unpaired, the intervals
    # overlap; paired, the difference is resolved and its interval holds 0.8.
    rng = np.random.default_rng(7)
    base = rng.normal(30.0, 5.0, 33)
    a = base + 0.8 + rng.normal(0.0, 0.3, 33)
    b = base
    ia, ib = mean_ci(a), mean_ci(b)
    assert ia.lo < ib.hi  # the means alone do not separate
    p = paired(a, b, ("stm", "mbd"))
    assert p.resolved and p.lower == "mbd"
    assert p.diff.lo < 0.8 < p.diff.hi
    assert paired(b, a, ("mbd", "stm")).lower == "mbd"
    # No difference but noise: not resolved, no lower model.
    c = base + rng.normal(0.0, 0.3, 33)
    q = paired(c, b, ("kin", "mbd"))
    assert not q.resolved and q.lower is None and q.diff.lo < 0 < q.diff.hi


def test_paired_leaves_out_a_manoeuvre_either_lacks():
    p = paired([1.0, math.nan, 3.0, 4.0], [0.5, 2.0, math.nan, 3.0])
    assert p.diff.n == 2 and p.diff.mean == pytest.approx(0.75)
    with pytest.raises(ValueError, match="one value per manoeuvre"):
        paired([1.0, 2.0], [1.0])


@pytest.mark.parametrize(("mean", "lo", "hi", "text"), [
    (5.37, 4.97, 5.77, "5.4 ± 0.4"),          # one digit of the half-width
    (47.2, 36.0, 58.9, "47 ± 12"),            # a leading 1 keeps two
    (0.00300, 0.00258, 0.00342, "0.0030 ± 0.0004"),
    (123.0, 86.0, 160.0, "120 ± 40"),         # rounded to tens
    (0.5, 0.4004, 0.5996, "0.50 ± 0.10"),     # 0.0996 rounds to 0.10: a leading 1
    (-0.02, -0.5, 0.46, "0.0 ± 0.5"),         # never "-0.0"
    (5.37, 4.24, 8.92, "5.4 [4.2, 8.9]"),     # skewed: the bounds, digits from the short side
    (35.0, 22.0, 48.0, "35 ± 13"),
])
def test_digit_rule(mean, lo, hi, text):
    assert format_ci(mean, lo, hi) == text
    assert format_ci(Interval(mean, lo, hi, 10, "")) == text


def test_digits_never_print_nan():
    for args in ((math.nan, math.nan, math.nan), (1.0, math.nan, math.nan), (math.inf, 0, 1)):
        assert "nan" not in format_ci(*args).lower() and "inf" not in format_ci(*args)


def test_mean_ci_kept_results_are_the_computed_ones():
    """The tables ask for the same sample many times; a kept interval is the one computed."""
    from artic.validation.criteria import statistics as st

    rng = np.random.default_rng(7)
    x = rng.normal(1.0, 0.5, 40)  # a bootstrap sample (BOOTSTRAP_MIN or more values)
    first = st.mean_ci(x)
    assert st.mean_ci(x.copy()) is first  # the same values: kept
    assert st.mean_ci(np.append(x, np.nan)) is first  # NaN is left out before the key
    assert st._mean_ci(x, st.SEED, st.CONFIDENCE) == first  # computed afresh, to the bit
    other = st.mean_ci(x, seed=st.SEED + 1)  # another seed draws other resamples
    assert other is not first and other.lo != first.lo
    y = x.copy()
    y[0] += 1e-12  # another sample, however close: computed, not taken from the memo
    assert st.mean_ci(y).mean != first.mean
