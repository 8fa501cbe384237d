"""The bias-corrected and accelerated (BCa) bootstrap interval of a mean, in numpy.

The interval is Efron and Tibshirani's (1993, *An Introduction to the
Bootstrap*, Chapman & Hall, ch. 14.3, eq. 14.9-14.15): the percentiles
``alpha_1 = Phi(z0 + (z0 + z_alpha) / (1 - a (z0 + z_alpha)))`` and
``alpha_2`` (the same with ``z_{1-alpha}``) of the bootstrap distribution,
with the bias correction ``z0 = Phi^-1(#{theta*_b < theta} / B)`` and the
acceleration ``a = sum U_i^3 / (6 (sum U_i^2)^(3/2))`` from the jackknife
values ``U_i = (n - 1)(theta_(.) - theta_(i))``.

:func:`bca_mean` computes what :func:`scipy.stats.bootstrap` computes for
``bootstrap((x,), np.mean, method="BCa", vectorized=True,
rng=np.random.default_rng(seed))`` (its ``_resampling.py``: ``bootstrap``,
``_bca_interval``, ``_percentile_of_score``, ``_jackknife_resample``; and
``scipy.stats.quantile``'s ``linear`` method), to the bit: the same
resampling draws from the same generator in the same order and shape (one
batch of ``n_resamples`` rows of ``n`` indices), the same reductions over
arrays of the same shape and layout, the percentile of score counted
``(#{< theta} + #{<= theta}) / 2B`` and the percentile interpolated as
``quantile`` does (a full sort, as scipy's, so that even the sign of a zero
end is scipy's). It leaves out the array-API dispatch, the input checks and
the ellipsis indexing that took about half of scipy's time on the
campaign's few dozen values. The resamples' indices depend on the seed,
``n`` and ``n_resamples`` alone, not on the values: drawn once
(``Generator.integers``, 60 % of what was left) and kept for the next
sample of as many values (:data:`DRAWS_KEPT`). Where scipy returns NaN
bounds (a degenerate bootstrap distribution: an infinite ``z0``, a 0/0
acceleration), so does this, without scipy's warning.
"""

from __future__ import annotations

import threading
from collections import OrderedDict

import numpy as np
from scipy.special import ndtr, ndtri


def bca_mean(x: np.ndarray, confidence_level: float, n_resamples: int,
             seed: int) -> tuple[float, float]:
    """The two-sided BCa bootstrap interval of the mean of ``x``.

    Parameters
    ----------
    x : ndarray
        Finite values, two or more [any unit].
    confidence_level : float
        Confidence level of the interval [-].
    n_resamples : int
        Bootstrap resamples [-].
    seed : int
        Seed of ``np.random.default_rng`` that draws the resamples.

    Returns
    -------
    tuple of float
        ``(lo, hi)`` [unit of ``x``], equal to the bit to
        ``scipy.stats.bootstrap``'s ``confidence_interval`` for the same
        arguments; NaN where scipy's are (it warns there, this does not).
    """
    x = np.asarray(x, dtype=float)
    n = int(x.shape[-1])
    theta_b = _resample_means(x, _draws(seed, n, n_resamples))
    theta = np.mean(x, axis=-1)
    # z0 from the percentile of score, scipy's 'mean' kind
    count = np.count_nonzero(theta_b < theta) + np.count_nonzero(theta_b <= theta)
    z0 = ndtri(np.float64(count) / (2 * n_resamples))
    # a degenerate case divides 0 by 0 or infinities, as scipy's does: NaN, no warning
    with np.errstate(invalid="ignore", divide="ignore"):
        # acceleration from the jackknife means (one batch of n rows of n - 1 values)
        theta_i = np.mean(x[_jackknife(n)], axis=-1)
        n_f = float(n)
        u = (n_f - 1) * (np.mean(theta_i, axis=-1, keepdims=True) - theta_i)
        num = np.sum(u**3, axis=-1) / n_f**3
        den = np.sum(u**2, axis=-1) / n_f**2
        a_hat = 1 / 6 * num / den**(3 / 2)
        z_alpha = float(ndtri((1 - confidence_level) / 2))
        num1 = z0 + z_alpha
        num2 = z0 - z_alpha
        alpha = np.stack((ndtr(z0 + num1 / (1 - a_hat * num1)),
                          ndtr(z0 + num2 / (1 - a_hat * num2))))
    lo, hi = _quantile_linear(np.sort(theta_b), alpha)
    return float(lo), float(hi)


CHUNK_ROWS = 1024
"""Resamples gathered and summed at a time by :func:`_resample_means` [-]."""


def _resample_means(x: np.ndarray, draws: np.ndarray) -> np.ndarray:
    """``np.mean(x[draws], axis=-1)`` to the bit, a block of rows at a time.

    Each row is summed as ``np.mean`` sums it (``add.reduce`` over the row,
    then divided by ``n``), so the blocks change no bit; they keep the
    gathered values in the cache instead of a fresh ``n_resamples * n``
    array per sample (half the time of the whole under load).
    """
    rows, n = draws.shape
    out = np.empty(rows)
    block = np.empty((min(rows, CHUNK_ROWS), n))
    for start in range(0, rows, CHUNK_ROWS):
        stop = min(rows, start + CHUNK_ROWS)
        values = np.take(x, draws[start:stop], out=block[:stop - start])
        np.add.reduce(values, axis=-1, out=out[start:stop])
    out /= n
    return out


def _quantile_linear(y: np.ndarray, p: np.ndarray) -> np.ndarray:
    """``scipy.stats.quantile(y, p)`` (``linear``) of sorted ``y``; NaN for ``p`` not in [0, 1]."""
    bad = (p > 1) | (p < 0) | np.isnan(p)
    p = np.where(bad, 0.5, p)
    n = np.asarray([float(y.size)])
    jg = p * n + (1 - p)
    jp1 = jg // 1
    j = jp1 - 1
    g = jg % 1
    g[j < 0] = 0
    j = np.clip(j, 0., n - 1)
    jp1 = np.clip(jp1, 0., n - 1)
    res = (1 - g) * y[j.astype(np.int64)] + g * y[jp1.astype(np.int64)]
    if np.isnan(y).any():  # scipy's nan_policy='propagate'
        res[:] = np.nan
    res[bad] = np.nan
    return res


_JACKKNIFE: dict[int, np.ndarray] = {}


def _jackknife(n: int) -> np.ndarray:
    """Indices of the ``n`` leave-one-out samples, row ``i`` without ``i`` (scipy's order)."""
    got = _JACKKNIFE.get(n)
    if got is None:
        keep = ~np.eye(n, dtype=bool)
        got = np.broadcast_to(np.arange(n), (n, n))[keep].reshape(n, n - 1)
        got.setflags(write=False)
        _JACKKNIFE[n] = got
    return got


DRAWS_KEPT = 4
"""Index sets :func:`bca_mean` keeps, the latest used [-].

The campaign's tables bootstrap thousands of samples of a dozen sizes (8 to
33 manoeuvres), asked for in runs of one size: four keep 99.6 % of them; one
set of ``n_resamples`` rows of ``n`` indices takes ``80 n`` kB (2.6 MB at
``n = 33``)."""

_DRAWS: OrderedDict[tuple[int, int, int], np.ndarray] = OrderedDict()
_DRAWS_LOCK = threading.Lock()  # tables made in threads share the kept sets


def _draws(seed: int, n: int, n_resamples: int) -> np.ndarray:
    """``np.random.default_rng(seed).integers(0, n, (n_resamples, n))``, kept (read-only)."""
    key = (int(seed), n, n_resamples)
    with _DRAWS_LOCK:
        got = _DRAWS.get(key)
        if got is not None:
            _DRAWS.move_to_end(key)
            return got
    got = np.random.default_rng(seed).integers(0, n, (n_resamples, n))
    got.setflags(write=False)
    with _DRAWS_LOCK:
        _DRAWS[key] = got
        while len(_DRAWS) > DRAWS_KEPT:
            _DRAWS.popitem(last=False)
    return got
