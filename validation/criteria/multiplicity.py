"""p values of the paired comparisons, and their correction for multiplicity.

A paired table compares every two models on every criterion of one
direction: some 40 comparisons forward and 90 in reverse. At 5 % each, a few
of them resolve by chance alone, so a ranking is a *finding* only where it
survives a correction over the family of comparisons of one table
(:func:`holm`), and the campaign requires in addition that it hold on the
noise-free twins (:mod:`artic.validation.campaign.findings`).

**The p value** (:func:`paired_p`) is the one the table's own interval
inverts (:func:`artic.validation.criteria.statistics.mean_ci`): the smallest
``1 - confidence`` at which the interval of the mean difference excludes zero.
Below :data:`~artic.validation.criteria.statistics.BOOTSTRAP_MIN` values that
is Student's t test; from it on, the BCa bootstrap's: with the bootstrap means
``theta_b``, the bias correction ``z0`` and the acceleration ``a`` of the
interval, zero sits at the fraction ``q`` of ``theta_b`` (as
:func:`numpy.percentile` interpolates), so the interval's end reaches zero at
the one-sided level ``alpha = Phi(w - z0)``, ``w = c / (1 + a c)``,
``c = Phi^-1(q) - z0`` (the BCa endpoint formula solved for its level), and
Hesterberg's expansion maps the two-sided ``2 alpha`` back to the nominal
level. So ``p < 0.05`` exactly where the table says "resolved" (to the
interpolation of one resample), and a p value below ``1 / (resamples + 1)``
is reported as that bound: the bootstrap cannot resolve smaller ones.

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
true, not most. Both adjustments are here; the campaign uses Holm.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from scipy import stats

from artic.validation.criteria.statistics import (
    BOOTSTRAP_MIN,
    CONFIDENCE,
    RESAMPLES,
    SEED,
    expanded_level,
)

ALPHA = 1.0 - CONFIDENCE
"""Family-wise error rate of the correction [-]: 5 %."""

CORRECTION = "Holm"
"""The correction the campaign's paired tables apply, as they name it."""

P_MIN = 1.0 / (RESAMPLES + 1)
"""The smallest p value a bootstrap of :data:`RESAMPLES` resamples reports [-]."""


def _family(p) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The p values as floats, an all-NaN result, and the finite ones' indices, p ascending."""
    p = np.asarray(p, dtype=float)
    ok = np.flatnonzero(np.isfinite(p))
    return p, np.full(p.shape, math.nan), ok[np.argsort(p[ok], kind="stable")]


def holm(p: Sequence[float] | np.ndarray) -> np.ndarray:
    """Holm's step-down adjusted p values.

    Sorted ascending, the ``k``-th smallest of ``m`` p values (``k`` from 1)
    becomes ``min(1, max over j <= k of (m - j + 1) p_(j))``; a hypothesis is
    rejected at family-wise level ``alpha`` where its adjusted p is below
    ``alpha``. NaN entries are left out of the family and stay NaN.

    Parameters
    ----------
    p : array_like
        Unadjusted p values [-].

    Returns
    -------
    ndarray
        Adjusted p values, in the input's order [-].
    """
    p, out, order = _family(p)
    m = order.size
    scaled = (m - np.arange(m)) * p[order]
    out[order] = np.minimum(1.0, np.maximum.accumulate(scaled))
    return out


def benjamini_hochberg(p: Sequence[float] | np.ndarray) -> np.ndarray:
    """Benjamini-Hochberg's step-up adjusted p values (false-discovery rate).

    Sorted ascending, the ``k``-th smallest of ``m`` p values becomes
    ``min(1, min over j >= k of m p_(j) / j)``. NaN entries are left out.

    Parameters
    ----------
    p : array_like
        Unadjusted p values [-].

    Returns
    -------
    ndarray
        Adjusted p values (q values), in the input's order [-].
    """
    p, out, order = _family(p)
    m = order.size
    scaled = m * p[order] / np.arange(1, m + 1)
    out[order] = np.minimum(1.0, np.minimum.accumulate(scaled[::-1])[::-1])
    return out


def _t_p(x: np.ndarray) -> float:
    """Student's two-sided p value of the mean of ``x`` against zero."""
    n = x.size
    sd = float(np.std(x, ddof=1))
    if sd == 0.0:
        return 0.0 if float(np.mean(x)) != 0.0 else 1.0
    t = float(np.mean(x)) / (sd / math.sqrt(n))
    return float(2.0 * stats.t.sf(abs(t), n - 1))


def _fraction_below(sorted_b: np.ndarray, value: float) -> float:
    """The fraction ``f`` with ``numpy.percentile(b, 100 f) == value`` (linear interpolation)."""
    n = sorted_b.size
    if value <= sorted_b[0]:
        return 0.0
    if value >= sorted_b[-1]:
        return 1.0
    k = int(np.searchsorted(sorted_b, value, side="right")) - 1
    lo, hi = sorted_b[k], sorted_b[k + 1]
    pos = k + (value - lo) / (hi - lo) if hi > lo else float(k)
    return pos / (n - 1)


def bootstrap_p(x: Sequence[float] | np.ndarray, seed: int = SEED) -> float:
    """The two-sided p value that the BCa interval of ``mean_ci`` inverts (module docstring).

    Parameters
    ----------
    x : array_like
        The differences, at least :data:`BOOTSTRAP_MIN` finite values.
    seed : int
        The bootstrap's seed, the interval's.

    Returns
    -------
    float
        p in [:data:`P_MIN`, 1] [-].
    """
    x = np.asarray(x, dtype=float)
    x = x[np.isfinite(x)]
    n = x.size
    mean = float(np.mean(x))
    res = stats.bootstrap((x,), np.mean, confidence_level=expanded_level(n),
                          n_resamples=RESAMPLES, method="BCa", vectorized=True,
                          rng=np.random.default_rng(seed))
    b = np.sort(np.asarray(res.bootstrap_distribution, dtype=float))
    # scipy's BCa: z0 from the share of resamples below the estimate (ties half),
    # a from the jackknife means.
    share = (np.sum(b < mean) + np.sum(b <= mean)) / (2.0 * b.size)
    z0 = float(stats.norm.ppf(share))
    jack = (np.sum(x) - x) / (n - 1)
    d = np.mean(jack) - jack
    den = 6.0 * float(np.sum(d * d)) ** 1.5
    a = float(np.sum(d ** 3)) / den if den > 0 else 0.0
    q = _fraction_below(b, 0.0)
    if mean < 0:  # zero above the mean: the upper end reaches it
        q = 1.0 - q
        z0, a = -z0, -a  # the mirror image of the lower end's formula
    if q <= 0.0:
        return P_MIN
    if q >= 1.0:
        return 1.0
    c = float(stats.norm.ppf(q)) - z0
    w = c / (1.0 + a * c)
    alpha = float(stats.norm.cdf(w - z0))  # one-sided level at which the end is zero
    if not math.isfinite(alpha) or alpha >= 0.5:
        return 1.0
    # Hesterberg's expansion: the bootstrap level 1 - 2 alpha is the nominal level
    # whose t quantile, scaled by sqrt(n / (n - 1)), is its normal quantile.
    t = float(stats.norm.ppf(1.0 - alpha)) * math.sqrt((n - 1) / n)
    return float(min(1.0, max(P_MIN, 2.0 * stats.t.sf(t, n - 1))))


def paired_p(x: Sequence[float] | np.ndarray, seed: int = SEED) -> float:
    """The two-sided p value of a mean difference, as its interval's method gives it.

    Student's t below :data:`BOOTSTRAP_MIN` values, the BCa bootstrap's
    (:func:`bootstrap_p`) from it on; NaN with fewer than two values; 0 for
    values all equal and not zero (the interval is that value), 1 for all zero.

    Parameters
    ----------
    x : array_like
        The per-manoeuvre differences ``a - b``; NaN entries are left out.
    seed : int
        The bootstrap's seed.

    Returns
    -------
    float
        p [-].
    """
    x = np.asarray(x, dtype=float)
    x = x[np.isfinite(x)]
    n = x.size
    if n < 2:
        return math.nan
    mean = float(np.mean(x))
    if np.ptp(x) <= 1e-12 * max(1.0, abs(mean)):
        return 0.0 if mean != 0.0 else 1.0
    if n < BOOTSTRAP_MIN:
        return _t_p(x)
    return bootstrap_p(x, seed)
