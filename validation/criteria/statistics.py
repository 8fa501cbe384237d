"""Confidence intervals, paired comparisons and the digits a mean deserves.

One synthetic seed is one truck; its manoeuvres are repeated measurements of
it. A table's mean over manoeuvres therefore carries a 95 % confidence
interval over manoeuvres, two models are compared paired per manoeuvre (the
difference on the same log removes most of the manoeuvre-to-manoeuvre
variation), and a value is printed with only the digits its interval supports.

**The interval** (:func:`mean_ci`). For ``n >= BOOTSTRAP_MIN`` values: a
seeded bias-corrected and accelerated (BCa) bootstrap of the mean
(:func:`scipy.stats.bootstrap`'s, computed as it computes it to the bit by
:func:`artic.validation.criteria.bca.bca_mean`), at the *expanded* confidence level of
Hesterberg (2015, "What teachers should know about the bootstrap", The
American Statistician 69(4)). BCa, not the plain percentile interval,
because the per-manoeuvre criteria are positive and skewed (a few hard
manoeuvres make a long upper tail) and BCa corrects the interval for the
skewness and bias of the mean's distribution. The expansion corrects the
bootstrap's narrowness: a resample's spread is the sample's with divisor
``n``, not ``n - 1``, so the plain 95 % interval covers the mean of normal
data only ``P(|t_{n-1}| < 1.96 sqrt((n - 1)/n))`` of the time, 92.5 % at
``n = 17`` and 84 % at ``n = 5``. The expanded level ``2 Phi(sqrt(n/(n-1))
t_{0.975, n-1}) - 1`` gives back the Student-t width for normal data and
keeps BCa's skew correction. Below ``BOOTSTRAP_MIN`` (8) values the bootstrap
distribution is lumpy (three values have ten distinct resamples) and BCa's
acceleration, estimated from ``n`` jackknife values, is poor; there the
interval is Student's t, exact for normal data (the intervals over a few
trucks of ``artic campaign --seeds N`` are of this kind). With one value there is no interval
(``lo`` and ``hi`` are NaN and :func:`format_ci` says ``n = 1``). With values
all equal the interval is that value (nothing varies to resample).

**The digits** (:func:`format_ci`): the interval's shorter side is rounded
to one significant digit, or two when that digit is a 1 (rounding 0.14 to
0.1 would shrink it by a third), and the value and the bounds are rounded at
that decimal place. An interval whose longer side is at most
:data:`SYMMETRIC` times the shorter prints as ``value ± longer side``, so that
the printed interval never understates the uncertainty; a skewed one (BCa
intervals follow a long tail) prints as ``value [lo, hi]``. Examples: 5.37
with [4.97, 5.77] prints ``5.4 ± 0.4``; 47.2 with [36.0, 58.9] prints ``47 ±
12``; 0.00300 with [0.00258, 0.00342] prints ``0.0030 ± 0.0004``; 5.37 with
[4.24, 8.92] prints ``5.4 [4.2, 8.9]``. The CSV tables keep the exact bounds.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy import stats

from artic.mjcf.errors import UserError
from artic.validation.criteria.bca import bca_mean

CONFIDENCE = 0.95
"""Confidence level of every interval."""

BOOTSTRAP_MIN = 8
"""Fewest values bootstrapped; below, Student's t (see the module docstring)."""

RESAMPLES = 9999
"""Bootstrap resamples [-].

Between seeds an interval's ends move by about 1 % of its width, and up to
4 % at the far end of a skewed sample (one manoeuvre far out, which the
resamples hold zero to several times): at most one unit in the printed last
digit."""

SYMMETRIC = 1.5
"""Largest ratio of an interval's sides printed as ``value ± half-width``; beyond, ``[lo, hi]``."""

SEED = 0
"""Seed of every bootstrap unless given: the same values give the same interval."""


@dataclass(frozen=True)
class Interval:
    """A mean and its confidence interval.

    Attributes
    ----------
    mean : float
        Mean of the values (NaN without values).
    lo, hi : float
        Interval bounds (NaN without an interval, ``n < 2``).
    n : int
        Number of finite values.
    method : str
        ``"BCa bootstrap (expanded)"``, ``"Student t"``, ``"constant"`` or ``"none"``.
    """

    mean: float
    lo: float
    hi: float
    n: int
    method: str

    @property
    def half_width(self) -> float:
        """The larger side of the interval (NaN without one) [unit of the values]."""
        return max(self.hi - self.mean, self.mean - self.lo)

    @property
    def short_side(self) -> float:
        """The smaller side of the interval (NaN without one) [unit of the values]."""
        return min(self.hi - self.mean, self.mean - self.lo)

    def excludes(self, value: float = 0.0) -> bool:
        """Whether the interval lies wholly above or below ``value``."""
        return bool(np.isfinite(self.lo) and (self.lo > value or self.hi < value))


@functools.lru_cache(maxsize=1024)
def expanded_level(n: int, confidence: float = CONFIDENCE) -> float:
    """Hesterberg's expanded confidence level for a bootstrap of ``n`` values.

    The level at which a normal interval with the bootstrap's spread (divisor
    ``n``) is as wide as Student's t interval (divisor ``n - 1``). Kept per
    ``(n, confidence)``: scipy's distributions take 0.4 ms a call, and the
    tables ask for the same few ``n`` thousands of times.
    """
    t = stats.t.ppf(0.5 + confidence / 2, n - 1)
    return float(2.0 * stats.norm.cdf(math.sqrt(n / (n - 1)) * t) - 1.0)


def mean_ci(values: Sequence[float] | np.ndarray, seed: int = SEED,
            confidence: float = CONFIDENCE) -> Interval:
    """The mean of ``values`` with its confidence interval (see the module docstring).

    Parameters
    ----------
    values : array_like
        One value per manoeuvre (or per truck); NaN entries are left out.
    seed : int
        Seed of the bootstrap's resampling.
    confidence : float
        Confidence level.

    Returns
    -------
    Interval
    """
    x = np.asarray(values, dtype=float)
    x = np.ascontiguousarray(x[np.isfinite(x)])
    key = (x.tobytes(), int(seed), float(confidence))
    got = _MEAN_CI.get(key)
    if got is None:
        got = _mean_ci(x, seed, confidence)
        if len(_MEAN_CI) >= MEMO_SIZE:
            _MEAN_CI.clear()
        _MEAN_CI[key] = got
    return got


MEMO_SIZE = 16384
"""Most results :func:`mean_ci` keeps (then it starts again).

It is a function of the finite values, the seed and the level alone (the
bootstrap draws from a generator of its own seed), and the campaign's tables ask
for the same sample many times over: a class's rows in its own table and in the
pooled one, a pair's differences in every leave-one-class-out table that keeps
the class's manoeuvres (:func:`artic.validation.campaign.classes.carried_by`).
The values' bytes are the key, so a kept result is the one computed again, to
the bit; an entry holds about 60 values (one per manoeuvre), under 1 kB.
"""

_MEAN_CI: dict[tuple[bytes, int, float], Interval] = {}


def _mean_ci(x: np.ndarray, seed: int, confidence: float) -> Interval:
    """:func:`mean_ci` of the finite values ``x``, computed."""
    n = int(x.size)
    if n == 0:
        return Interval(math.nan, math.nan, math.nan, 0, "none")
    mean = float(np.mean(x))
    if n == 1:
        return Interval(mean, math.nan, math.nan, 1, "none")
    if np.ptp(x) <= 1e-12 * max(1.0, abs(mean)):
        return Interval(mean, mean, mean, n, "constant")
    if n < BOOTSTRAP_MIN:
        half = float(stats.t.ppf(0.5 + confidence / 2, n - 1) * np.std(x, ddof=1) / math.sqrt(n))
        return Interval(mean, mean - half, mean + half, n, "Student t")
    # scipy.stats.bootstrap((x,), np.mean, method="BCa", vectorized=True,
    # rng=np.random.default_rng(seed)) to the bit, without its overhead (bca.py)
    lo, hi = bca_mean(x, expanded_level(n, confidence), RESAMPLES, seed)
    # The mean lies inside its own BCa interval unless the data are nearly
    # degenerate (one outlier among equal values); never report less than the mean.
    return Interval(mean, min(lo, mean), max(hi, mean), n, "BCa bootstrap (expanded)")


@dataclass(frozen=True)
class Paired:
    """The paired comparison of two models on the same manoeuvres.

    Attributes
    ----------
    a, b : str
        The models; the difference is ``a - b``.
    diff : Interval
        Mean per-manoeuvre difference ``a - b`` with its interval.
    """

    a: str
    b: str
    diff: Interval

    @property
    def resolved(self) -> bool:
        """Whether the interval of the difference excludes zero."""
        return self.diff.excludes(0.0)

    @property
    def lower(self) -> str | None:
        """The model with the smaller criterion, if resolved; ``None`` otherwise."""
        if not self.resolved:
            return None
        return self.a if self.diff.mean < 0 else self.b


def paired(a: Sequence[float] | np.ndarray, b: Sequence[float] | np.ndarray,
           names: tuple[str, str] = ("a", "b"), seed: int = SEED) -> Paired:
    """Compare two models' criteria on the same manoeuvres, paired.

    Parameters
    ----------
    a, b : array_like
        One value per manoeuvre, in the same order; manoeuvres where either
        is NaN (a pair without a result) are left out of both.
    names : tuple of str
        The two models' names.
    seed : int
        Seed of the bootstrap.
    """
    x, y = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    if x.shape != y.shape:
        raise UserError(f"paired comparison of {names[0]} and {names[1]}: {x.size} and "
                         f"{y.size} values; pass one value per manoeuvre for both")
    ok = np.isfinite(x) & np.isfinite(y)
    return Paired(names[0], names[1], mean_ci(x[ok] - y[ok], seed=seed))


def _place(half: float) -> int:
    """Decimal place (power of ten) of a half-width's last printed digit.

    One significant digit, two when the leading one is a 1 (after rounding to
    two, so that 0.0996 counts as 0.10).
    """
    mantissa, exponent = f"{half:.1e}".split("e")
    e = int(exponent)
    return e - 1 if mantissa[0] == "1" else e


def round_to(value: float, place: int) -> str:
    """``value`` rounded at the decimal place ``10**place``, as text (never ``-0``)."""
    r = round(float(value), -place)
    return f"{(r if r != 0 else 0.0):.{max(0, -place)}f}"


def format_ci(iv: Interval | float, lo: float | None = None, hi: float | None = None,
              n: int | None = None) -> str:
    """A value with the digits its interval supports, as ``"value ± half-width"``.

    Parameters
    ----------
    iv : Interval or float
        The interval, or its mean with ``lo`` and ``hi``.
    lo, hi : float, optional
        With a float ``iv``: the bounds.
    n : int, optional
        With a float ``iv``: the number of values (for the text without an interval).

    Returns
    -------
    str
        ``"5.4 ± 0.4"``; ``"5.4 (n = 1)"`` with two significant digits when
        there is no interval; ``"-"`` without a value. Never ``"nan"``.
    """
    if not isinstance(iv, Interval):
        mean = float(iv)
        iv = Interval(mean, math.nan if lo is None else float(lo),
                      math.nan if hi is None else float(hi), n if n is not None else 0, "")
    if not math.isfinite(iv.mean):
        return "-"
    if not (math.isfinite(iv.lo) and math.isfinite(iv.hi)):
        text = f"{iv.mean:.2g}" if iv.mean != 0 else "0"
        return f"{text} (n = {iv.n})" if iv.n else text
    place = digits_place(iv)
    if place is None:  # every value equal: show it as it is
        return f"{iv.mean:.3g} ± 0"
    if iv.half_width <= SYMMETRIC * iv.short_side:
        return f"{round_to(iv.mean, place)} ± {round_to(iv.half_width, place)}"
    return f"{round_to(iv.mean, place)} [{round_to(iv.lo, place)}, {round_to(iv.hi, place)}]"


def digits_place(iv: Interval) -> int | None:
    """The decimal place :func:`format_ci` rounds ``iv`` to (``None`` without a spread).

    Set by the interval's shorter side (its longer one where the mean sits on
    a bound), so that the better-determined end keeps its digit.
    """
    if not (math.isfinite(iv.lo) and math.isfinite(iv.hi)):
        return None
    tiny = 1e-9 * max(abs(iv.mean), abs(iv.lo), abs(iv.hi))
    side = iv.short_side if iv.short_side > tiny else iv.half_width
    return _place(side) if side > tiny else None
