"""The numpy BCa bootstrap of a mean equals scipy's to the bit (artic.validation.criteria.bca)."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from scipy import stats

from artic.validation.criteria import statistics as st
from artic.validation.criteria.bca import bca_mean


def scipy_bca(x: np.ndarray, level: float, n_resamples: int, seed: int) -> np.ndarray:
    """scipy's BCa interval of the mean, as the tables computed it before."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the degenerate cases warn; their NaN is compared
        res = stats.bootstrap((x,), np.mean, confidence_level=level, n_resamples=n_resamples,
                              method="BCa", vectorized=True, rng=np.random.default_rng(seed))
    return np.array([float(res.confidence_interval.low), float(res.confidence_interval.high)])


def samples(count: int, seed: int):
    """``count`` samples of 8 to 90 values: normal, skewed, heavy-tailed, tied, near-constant."""
    gen = np.random.default_rng(seed)
    for k in range(count):
        n = int(gen.integers(8, 91))
        kind = k % 7
        if kind == 0:
            x = gen.normal(1.0, 0.5, n)
        elif kind == 1:
            x = gen.lognormal(0.0, 1.5, n)  # the criteria's long upper tail
        elif kind == 2:
            x = gen.choice([0.1, 0.2, 0.5], n)  # heavy ties
        elif kind == 3:
            x = gen.integers(-5, 6, n).astype(float)
        elif kind == 4:
            x = gen.standard_cauchy(n)
        elif kind == 5:
            x = np.r_[np.full(n - 1, 3.0), 3.0 + 1e-9]  # one value off, just above mean_ci's ptp
        else:
            x = 1e3 + gen.normal(0.0, 1e-6, n)  # near-constant on a large offset
        yield x, int(gen.integers(0, 1000))


def test_bca_equals_scipy_to_the_bit():
    # 280 samples at the tables' resamples and expanded level, and at 95 % and 99 %.
    levels = (0.95, 0.99)
    for i, (x, seed) in enumerate(samples(280, 42)):
        level = st.expanded_level(x.size) if i % 3 == 0 else levels[i % 2]
        want = scipy_bca(x, level, st.RESAMPLES, seed)
        got = np.array(bca_mean(x, level, st.RESAMPLES, seed))
        assert got.tobytes() == want.tobytes(), (x.size, seed, level, got - want)


@pytest.mark.parametrize("n_resamples", [1, 2, 3, 7, 50])
def test_bca_equals_scipy_with_few_resamples(n_resamples):
    # Few resamples put theta outside the bootstrap distribution (z0 infinite)
    # or at one of its ends: scipy's interval there, NaN or an end, is kept.
    nan = 0
    for x, seed in samples(60, n_resamples):
        want = scipy_bca(x, 0.95, n_resamples, seed)
        got = np.array(bca_mean(x, 0.95, n_resamples, seed))
        assert got.tobytes() == want.tobytes(), (x.size, seed, got, want)
        nan += bool(np.isnan(want).any())
    if n_resamples == 1:
        assert nan > 0  # the degenerate path was exercised


def test_bca_degenerate_jackknife_gives_scipy_nan():
    # Values unequal, but every leave-one-out mean rounds to the same number:
    # the acceleration is 0/0 and scipy's interval NaN (with a warning).
    x = np.r_[np.full(7, 1e17), 1e17 + 16.0]
    want = scipy_bca(x, 0.95, 999, 0)
    assert np.isnan(want).all()
    lo, hi = bca_mean(x, 0.95, 999, 0)
    assert np.isnan(lo) and np.isnan(hi)
    # and two values, the fewest scipy takes
    x2 = np.array([1.0, 2.0])
    assert np.array(bca_mean(x2, 0.95, 99, 3)).tobytes() == scipy_bca(x2, 0.95, 99, 3).tobytes()


def test_mean_ci_uses_the_same_interval_as_scipy():
    x = np.random.default_rng(5).lognormal(0.0, 1.0, 33)
    iv = st._mean_ci(x, st.SEED, st.CONFIDENCE)
    lo, hi = scipy_bca(x, st.expanded_level(x.size), st.RESAMPLES, st.SEED)
    assert (iv.lo, iv.hi) == (min(lo, iv.mean), max(hi, iv.mean))
    assert iv.method == "BCa bootstrap (expanded)"


def test_kept_draws_give_scipys_interval_for_every_sample_of_a_size():
    # The resamples' indices are kept per (seed, n): the second and later
    # samples of a size reuse them, and their intervals are still scipy's.
    from artic.validation.criteria import bca

    bca._DRAWS.clear()
    gen = np.random.default_rng(9)
    for i in range(12):
        n = (17, 33, 8)[i % 3]
        x = gen.lognormal(0.0, 1.0, n)
        want = scipy_bca(x, 0.95, st.RESAMPLES, 0)
        assert np.array(bca_mean(x, 0.95, st.RESAMPLES, 0)).tobytes() == want.tobytes()
    assert set(bca._DRAWS) == {(0, 17, st.RESAMPLES), (0, 33, st.RESAMPLES),
                               (0, 8, st.RESAMPLES)}
    for i in range(bca.DRAWS_KEPT + 2):  # the oldest sizes make way
        bca_mean(gen.normal(size=40 + i), 0.95, 99, 0)
    assert len(bca._DRAWS) == bca.DRAWS_KEPT and (0, 8, st.RESAMPLES) not in bca._DRAWS
