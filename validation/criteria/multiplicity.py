"""p values of the paired comparisons, and their correction for multiplicity.

A paired table compares every two models on every criterion of one
direction: some 40 comparisons forward and 90 in reverse. At 5 % each, a few
of them resolve by chance alone, so a ranking is a *finding* only where it
survives a correction over the family of comparisons of one table
(:func:`holm`), and the campaign requires in addition that it hold on the
noise-free twins (:mod:`artic.validation.campaign.findings`). Holm's first
step tests the smallest p value at ``alpha / m`` (5.2e-4 for the 96
comparisons of the reverse table), so the test must hold its level there,
not only at 5 %.

**The test** (:func:`paired_test`) of a mean per-manoeuvre difference
``x`` against zero is two tests, and a ranking is resolved only where both
resolve it (the p value is the larger of the two):

- the exact **sign-flip** (randomisation) test of the mean
  (:func:`sign_flip_p`): under the null that the two models are
  interchangeable on each manoeuvre, each difference is as likely ``+|x_i|``
  as ``-|x_i|``, so the ``2^n`` sign patterns give the exact null
  distribution of the mean. It is exact for any null symmetric about zero,
  whatever its tails (the heavy-tailed rows), and enumerated in full up to
  :data:`EXACT_MAX` values (meeting in the middle: two halves of ``2^(n/2)``
  sums); above, :data:`SIGN_RESAMPLES` seeded random patterns, whose p
  value ``(1 + b) / (B + 1)`` is exact as well and resolves ``alpha / m``.
  Its smallest p value is ``2 / 2^n``: 3.9e-3 at ``n = 9``, so a row of 9
  manoeuvres cannot pass Holm's first step of a 96-row table.
- Student's t with **Hall's skewness correction** (:func:`hall_p`; Hall
  1992, "On the removal of skewness by transformation", JRSS B 54(1)): with
  ``T = sqrt(n) mean / s`` and the sample skewness ``g``, ``T + g T^2 /
  (3 sqrt(n)) + g^2 T^3 / (27 n) + g / (6 sqrt(n))`` against ``t_{n-1}``.
  A skewed null with mean zero is not symmetric, and there the sign-flip
  test (and the plain t test) rejects in the direction away from the long
  tail far too often: a sample that lacks the tail has a mean well off zero
  and a small spread. The correction removes the first term of that error.
  Hall's test alone is not calibrated for symmetric heavy tails (it rejects
  t-distributed nulls with 2 degrees of freedom too often), which the
  sign-flip test is; together they hold the level for both.

**Not testable.** The correction is the first term of an expansion in
``g / sqrt(n)``; where the sample skewness exceeds
``SKEW_PER_ROOT_N * sqrt(n)`` (1.5 at ``n = 9``, 2.1 at 17, 2.9 at 33) the
data are more skewed than the calibration covers at this ``n`` (below) and
no test at hand holds its level: the p value is NaN and the status says
"not testable at n = ...". Such a row is never a finding; its table shows
the mean difference with its interval instead. Fewer than 3 values are not
testable either (no skewness).

**Calibration** (``tests/test_calibration.py``): true nulls drawn from the
normal, the exponential less its mean (skewness 2) and Student's t with 2
and 3 degrees of freedom (no variance, no fourth moment), at ``n`` = 9, 17
and 33; the rate at which the test rejects at 5 % and at ``0.05 / 96``
stays within the binomial band of nominal, for the symmetric nulls at every
``n``. Measured on 20 000 draws each, the exponential rejects at
``0.05 / 96`` about 3 times nominal at ``n = 17`` (1.7e-3) and 1.6 times at
33, and within nominal at 5 %. Where the null is more skewed than that and
the sample does not show it, no test on so few values can tell (Bahadur and
Savage 1956: no test of a mean holds its level over every distribution with
a mean); the lognormal with ``sigma = 1`` (skewness 6) is rejected at
``0.05 / 96`` 12 times nominal at ``n = 17`` and 5 times at 33 (at 5 %:
7 % and 6 %). The former p value (the BCa bootstrap's, floored at 1e-4)
rejected normal nulls at ``0.05 / 96`` 24 times nominal at ``n = 9`` and 8
times at 17, the lognormal 90 times at 17 (the test module's table).

**Means over trucks** (:func:`truck_p`): with several trucks the pooled
tables test the per-truck mean differences, a few values (one per seed),
each the mean of a truck's 17 to 33 manoeuvres and so nearer normal than the
manoeuvres; the sign-flip test cannot resolve anything below ``2 / 2^n``
there (0.0625 with 5 trucks), and Student's t is the test.

**The correction** (:func:`holm`): Holm's step-down adjustment, which keeps
the family-wise error rate (the chance that *any* ranking stated is false) at
5 % under any dependence between the comparisons. The comparisons of one
table are strongly dependent: the same manoeuvres, and criteria built from
the same errors (eps_n sums eps_a's and eps_v's terms; the 2, 5 and 10 m
prediction errors share their start points). Benjamini-Hochberg
(:func:`benjamini_hochberg`) would keep the false-discovery rate instead (the
expected share of false rankings among those stated) and only under
positive dependence, which two-sided tests of correlated criteria do not
guarantee; and the README states each finding on its own, so each must be
true, not most. Both adjustments are statsmodels'
(:func:`statsmodels.stats.multitest.multipletests`), Holm's recomputed here
with its operations (statsmodels' runs a full garbage collection a call); the
campaign uses Holm.
A NaN p value (a row not testable) is left out of the family: it states
nothing, so it is no hypothesis tested.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy import special, stats

from artic.validation.criteria.statistics import CONFIDENCE, MEMO_SIZE, SEED

ALPHA = 1.0 - CONFIDENCE
"""Family-wise error rate of the correction [-]: 5 %."""

CORRECTION = "Holm"
"""The correction the campaign's paired tables apply, as they name it."""

TEST = "sign-flip and Hall's t"
"""The paired test, as the tables name it."""

EXACT_MAX = 34
"""Most values whose ``2^n`` sign patterns the sign-flip test enumerates [-].

Two halves of at most ``2^17`` sums each: some 20 ms a row."""

SIGN_RESAMPLES = 2 ** 17 - 1
"""Random sign patterns of the sign-flip test above :data:`EXACT_MAX` values [-].

The smallest p value is ``1 / 2^17`` = 7.6e-6, so ``0.05 / 96`` is resolved
with some 70 patterns beyond the observed mean to spare."""

SKEW_PER_ROOT_N = 0.5
"""Largest sample skewness per ``sqrt(n)`` of a testable row [-].

The exponential's skewness, 2, at ``n = 17`` (2 / sqrt(17) = 0.49): the most
skewed null the calibration draws, at the size of the forward table."""

TESTED = "tested"
NOT_TESTABLE = "not testable"
"""The first words of a :class:`PairedTest`'s status."""


@dataclass(frozen=True)
class PairedTest:
    """The outcome of :func:`paired_test`.

    Attributes
    ----------
    p : float
        Two-sided p value [-]; NaN where not testable.
    status : str
        ``"tested"``, or ``"not testable at n = N (...)"`` saying why.
    n : int
        Number of finite differences.
    """

    p: float
    status: str
    n: int

    @property
    def testable(self) -> bool:
        """Whether the p value holds its level (see the module docstring)."""
        return self.status == TESTED


def _family(p) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The p values as floats, an all-NaN result, and the finite ones' indices."""
    p = np.asarray(p, dtype=float)
    return p, np.full(p.shape, math.nan), np.flatnonzero(np.isfinite(p))


def _adjusted(p, method: str) -> np.ndarray:
    p, out, ok = _family(p)
    if ok.size:
        from statsmodels.stats.multitest import multipletests  # ~1 s to import: when needed

        out[ok] = multipletests(p[ok], alpha=ALPHA, method=method)[1]
    return out


def _holm(p) -> np.ndarray:
    """Holm's adjustment as statsmodels computes it (the same operations, the same bits).

    Written here because statsmodels' ``holm`` ends in a full ``gc.collect()``,
    which in a campaign's heap costs 0.1 s a call: 7 of the tables stage's 60 s
    (66 families). Ties give the same adjusted value whichever comes first.
    ``tests/test_multiplicity.py`` holds it equal to statsmodels' to the bit.
    """
    p, out, ok = _family(p)
    if ok.size:
        q = p[ok]
        order = np.argsort(q)
        adjusted = np.maximum.accumulate(q[order] * np.arange(q.size, 0, -1))
        adjusted[adjusted > 1] = 1
        out[ok[order]] = adjusted
    return out


def holm(p: Sequence[float] | np.ndarray) -> np.ndarray:
    """Holm's step-down adjusted p values (statsmodels' ``holm``, bit for bit).

    Sorted ascending, the ``k``-th smallest of ``m`` p values (``k`` from 1)
    becomes ``min(1, max over j <= k of (m - j + 1) p_(j))``; a hypothesis is
    rejected at family-wise level ``alpha`` where its adjusted p is below
    ``alpha``. NaN entries (rows not testable) are left out of the family
    (``m`` counts the finite ones) and stay NaN.

    Parameters
    ----------
    p : array_like
        Unadjusted p values [-].

    Returns
    -------
    ndarray
        Adjusted p values, in the input's order [-].
    """
    return _holm(p)


def benjamini_hochberg(p: Sequence[float] | np.ndarray) -> np.ndarray:
    """Benjamini-Hochberg's step-up adjusted p values (statsmodels' ``fdr_bh``).

    Sorted ascending, the ``k``-th smallest of ``m`` p values becomes
    ``min(1, min over j >= k of m p_(j) / j)``. NaN entries are left out of
    the family and stay NaN.

    Parameters
    ----------
    p : array_like
        Unadjusted p values [-].

    Returns
    -------
    ndarray
        Adjusted p values (q values), in the input's order [-].
    """
    return _adjusted(p, "fdr_bh")


def _sums(a: np.ndarray) -> np.ndarray:
    """Every signed sum ``sum(s_i a_i)``, ``s_i = +-1``: ``2^len(a)`` values.

    Built in one array, each value in turn doubling the sums so far (the
    first half ``+ a_i``, the second ``- a_i``), the order and every bit of
    concatenating ``[s + a_i, s - a_i]`` anew (a fresh 1 MB array per value at
    17 values, 10 times slower).
    """
    s = np.empty(2 ** a.size)
    s[0] = 0.0
    m = 1
    for v in a:
        np.subtract(s[:m], v, out=s[m:2 * m])
        s[:m] += v
        m *= 2
    return s


def sign_flip_p(x: Sequence[float] | np.ndarray, seed: int = SEED) -> float:
    """The two-sided p value of the sign-flip test of the mean of ``x`` against zero.

    The share of sign patterns ``s`` with ``|sum(s_i |x_i|)| >= |sum(x_i)|``:
    all ``2^n`` up to :data:`EXACT_MAX` values, else :data:`SIGN_RESAMPLES`
    random ones, ``(1 + b) / (B + 1)``.

    Parameters
    ----------
    x : array_like
        The differences; NaN entries are left out.
    seed : int
        The random patterns' seed (above :data:`EXACT_MAX` values).

    Returns
    -------
    float
        p in (0, 1] [-]; 1 where every difference is zero, NaN without values.
    """
    x = np.asarray(x, dtype=float)
    x = x[np.isfinite(x)]
    if x.size == 0:
        return math.nan
    a = np.abs(x[x != 0.0])
    if a.size == 0:
        return 1.0
    tol = 1e-10 * float(a.sum())  # sums of the same values in another order
    t = abs(float(x.sum())) - tol
    if t <= 0.0:
        return 1.0
    n = a.size
    if n <= EXACT_MAX:
        k = n // 2
        head, tail = _sums(a[:k]), np.sort(_sums(a[k:]))
        count = tail.size * head.size - int(np.searchsorted(tail, t - head, side="left").sum())
        return min(1.0, 2.0 * count / 2.0 ** n)  # |S| >= t: twice S >= t
    rng = np.random.default_rng(seed)
    beyond, chunk = 0, max(1, 2 ** 22 // n)
    for start in range(0, SIGN_RESAMPLES, chunk):
        m = min(chunk, SIGN_RESAMPLES - start)
        s = rng.integers(0, 2, size=(m, n), dtype=np.int8).astype(float) * 2.0 - 1.0
        beyond += int(np.count_nonzero(np.abs(s @ a) >= t))
    return (1.0 + beyond) / (SIGN_RESAMPLES + 1.0)


def _hall(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Hall's p values and the sample skewness of the rows of ``x`` (2-D, no NaN, spread)."""
    n = x.shape[1]
    root = math.sqrt(n)
    t = root * x.mean(axis=1) / x.std(axis=1, ddof=1)
    g = _skew(x)
    th = t + g * t ** 2 / (3.0 * root) + g ** 2 * t ** 3 / (27.0 * n) + g / (6.0 * root)
    # stats.t.sf(|th|, n - 1) is special.stdtr(n - 1, -|th|) (t_gen._sf), 0 at |th| = inf
    return 2.0 * special.stdtr(n - 1, -np.abs(th)), g


def _skew(x: np.ndarray) -> np.ndarray:
    """``scipy.stats.skew(x, axis=1, bias=False)`` of the rows of ``x``, to the bit.

    The same arithmetic as scipy's ``skew`` and ``_moment`` (the central
    moments ``m2 = mean(d^2)`` and ``m3 = mean(d^2 d)`` of ``d = x - mean``,
    NaN where ``m2 <= (eps mean)^2``, the bias correction ``sqrt((n - 1) n) /
    (n - 2) m3 / m2^1.5``) without its ``nan_policy`` wrapper, which took
    0.5 ms a call, 20 times the arithmetic (``tests/test_multiplicity.py``
    holds the two equal); and without its precision-loss warning.
    """
    n = x.shape[1]
    mean = np.mean(x, axis=1, keepdims=True)
    d = x - mean
    m2 = np.mean(d**2, axis=1)
    s = d**2
    s *= d
    m3 = np.mean(s, axis=1)
    with np.errstate(all="ignore"):
        zero = m2 <= (np.finfo(m2.dtype).eps * mean[:, 0])**2
        vals = np.where(zero, np.nan, m3 / m2**1.5)
        if n > 2:
            vals = np.where(~zero, ((n - 1.0) * n)**0.5 / (n - 2.0) * m3 / m2**1.5, vals)
    return vals


def hall_p(x: Sequence[float] | np.ndarray) -> float:
    """Student's two-sided p value with Hall's skewness correction (module docstring).

    Parameters
    ----------
    x : array_like
        The differences, at least 3 finite values not all equal; NaN entries
        are left out.

    Returns
    -------
    float
        p [-]; NaN with fewer than 3 values or none of them different.
    """
    x = np.asarray(x, dtype=float)
    x = x[np.isfinite(x)]
    if x.size < 3 or np.ptp(x) <= 1e-12 * max(1.0, abs(float(np.mean(x)))):
        return math.nan
    return float(_hall(x[None, :])[0][0])


def paired_tests(x: np.ndarray, seed: int = SEED,
                 decide_below: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """:func:`paired_test` of every row of ``x`` at once.

    Parameters
    ----------
    x : ndarray
        One sample of differences per row, all ``n`` values finite.
    seed : int
        The sign-flip test's seed (above :data:`EXACT_MAX` values).
    decide_below : float
        The largest level the p values are to be compared with [-]: a row
        whose Hall p exceeds it needs no sign-flip test (the larger of the two
        is above the level already) and keeps Hall's p, a lower bound of its
        own; 1 computes every p value in full.

    Returns
    -------
    p : ndarray
        Two-sided p values [-]; NaN where not testable.
    testable : ndarray of bool
        Whether each row is testable.
    """
    x = np.atleast_2d(np.asarray(x, dtype=float))
    rows, n = x.shape
    p = np.full(rows, math.nan)
    testable = np.zeros(rows, dtype=bool)
    if n < 3:
        return p, testable
    mean = x.mean(axis=1)
    flat = np.ptp(x, axis=1) <= 1e-12 * np.maximum(1.0, np.abs(mean))
    for i in np.flatnonzero(flat):  # no spread: the sign-flip test alone (no skewness)
        p[i], testable[i] = sign_flip_p(x[i], seed), True
    live = np.flatnonzero(~flat)
    if live.size:
        hp, g = _hall(x[live])
        ok = np.abs(g) <= SKEW_PER_ROOT_N * math.sqrt(n)
        testable[live] = ok
        p[live[ok]] = hp[ok]
        for i, h in zip(live[ok], hp[ok], strict=True):
            if h <= decide_below:
                p[i] = max(h, sign_flip_p(x[i], seed))
    return p, testable


def paired_test(x: Sequence[float] | np.ndarray, seed: int = SEED) -> PairedTest:
    """The test of a mean per-manoeuvre difference against zero (module docstring).

    Parameters
    ----------
    x : array_like
        The per-manoeuvre differences ``a - b``; NaN entries are left out.
    seed : int
        The sign-flip test's seed (above :data:`EXACT_MAX` values).

    Returns
    -------
    PairedTest
        The p value (the larger of the sign-flip test's and Hall's; only the
        sign-flip test's where every difference is equal, 1 where all are
        zero), or NaN and why the row is not testable.
    """
    x = np.asarray(x, dtype=float)
    x = np.ascontiguousarray(x[np.isfinite(x)])
    key = (x.tobytes(), int(seed))
    got = _PAIRED_TEST.get(key)
    if got is None:
        got = _paired_test(x, seed)
        if len(_PAIRED_TEST) >= MEMO_SIZE:
            _PAIRED_TEST.clear()
        _PAIRED_TEST[key] = got
    return got


_PAIRED_TEST: dict[tuple[bytes, int], PairedTest] = {}
"""What :func:`paired_test` computed, by the differences' bytes and the seed: the
tables test the same differences in the pooled, per-class and leave-one-class-out
tables (see :data:`artic.validation.criteria.statistics.MEMO_SIZE`)."""


def _paired_test(x: np.ndarray, seed: int) -> PairedTest:
    """:func:`paired_test` of the finite differences ``x``, computed."""
    n = int(x.size)
    if n < 3:
        return PairedTest(math.nan, f"{NOT_TESTABLE} at n = {n} (fewer than 3 values)", n)
    p, ok = paired_tests(x[None, :], seed)
    if ok[0]:
        return PairedTest(float(p[0]), TESTED, n)
    g = float(stats.skew(x, bias=False))
    return PairedTest(math.nan, f"{NOT_TESTABLE} at n = {n} (skewness {g:.1f}, beyond "
                      f"{SKEW_PER_ROOT_N * math.sqrt(n):.1f})", n)


def paired_p(x: Sequence[float] | np.ndarray, seed: int = SEED) -> float:
    """The p value of :func:`paired_test`: NaN where the row is not testable.

    Parameters
    ----------
    x : array_like
        The per-manoeuvre differences ``a - b``; NaN entries are left out.
    seed : int
        The sign-flip test's seed.

    Returns
    -------
    float
        p [-], or NaN.
    """
    return paired_test(x, seed).p


def truck_p(x: Sequence[float] | np.ndarray) -> float:
    """Student's two-sided p value of a mean over trucks (module docstring).

    Parameters
    ----------
    x : array_like
        One mean difference per truck; NaN entries are left out.

    Returns
    -------
    float
        p [-]; NaN with fewer than 2 values, 1 where all are zero and the
        sign-flip test's where all are equal.
    """
    x = np.asarray(x, dtype=float)
    x = x[np.isfinite(x)]
    n = x.size
    if n < 2:
        return math.nan
    mean = float(np.mean(x))
    if np.ptp(x) <= 1e-12 * max(1.0, abs(mean)):
        return sign_flip_p(x)
    return float(stats.ttest_1samp(x, 0.0).pvalue)
