"""ISO/TS 18571's objective rating ("Objective rating metric for non-ambiguous signals").

Rates a comparison signal ``C`` (a model's) against a reference signal ``T``
(the measured one), both sampled on one uniform grid, with four scores in
[0, 1] combined into one rating ``R`` in [0, 1] (1: the same signal):

- **corridor** ``Z``: around ``T``, an inner corridor of half-width
  ``a_0 * max|T|`` and an outer one of ``b_0 * max|T|``; a sample inside the
  inner scores 1, outside the outer 0, in between
  ``((b_0 max|T| - |C - T|) / ((b_0 - a_0) max|T|)) ** k_Z``; ``Z`` is the mean
  over the samples;
- **phase** ``E_P``: ``C`` is shifted against ``T`` by ``n`` samples, up to
  ``eps_P * N``, and the shift whose overlapping parts have the largest Pearson
  correlation is the phase error ``n_eps``;
  ``E_P = ((eps_P N - |n_eps|) / (eps_P N)) ** k_P``, 0 at or beyond the limit;
- **magnitude** ``E_M`` (EEARTH): the two shifted signals are aligned by dynamic
  time warping (squared difference as the local cost, steps (1, 0), (0, 1),
  (1, 1) of weight 1, a Sakoe-Chiba band of ``DTW_WINDOW * N`` samples), and
  ``eps_mag = sum|C_w - T_w| / sum|T_w|`` over the warped pair;
  ``E_M = ((eps_M - eps_mag) / eps_M) ** k_M``, 0 beyond ``eps_M``;
- **slope** ``E_S``: the derivatives of the shifted signals (central
  differences, then a centred 9-sample moving average, shortened to 1, 3, 5 and
  7 samples at the ends), ``eps_slope = sum|C' - T'| / sum|T'|``;
  ``E_S = ((eps_S - eps_slope) / eps_S) ** k_S``, 0 beyond ``eps_S``;

``R = w_Z Z + w_P E_P + w_M E_M + w_S E_S``, graded by :data:`GRADES`.

The parameters are the standard's (:data:`PARAMETERS`); this module chooses
only what the standard leaves to an implementation: a tie between shifts of
equal correlation goes to the smallest shift, and a reference with no
amplitude (``max|T| = 0``) or no slope (``sum|T'| = 0``) has no rating (NaN),
since its corridor or slope error divides by zero. The standard asks for
signals sampled at 10 kHz, as crash-test channels are; a vehicle's handling
signals change over seconds, and :mod:`artic.validation.criteria.rating` rates
them at a stated lower rate. The metric is the standard's; its grades were set
for crash-test channels, and they read the same here only by analogy.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

PARAMETERS: dict[str, float] = {
    "a_0": 0.05, "b_0": 0.5, "k_Z": 2.0,
    "eps_P": 0.2, "k_P": 1.0,
    "eps_M": 0.5, "k_M": 1.0,
    "eps_S": 2.0, "k_S": 1.0,
    "w_Z": 0.4, "w_P": 0.2, "w_M": 0.2, "w_S": 0.2,
}
"""The standard's parameters: corridor half-widths ``a_0``, ``b_0`` [-] (of
``max|T|``) and exponent ``k_Z``; the largest phase shift ``eps_P`` [-] (of the
signal's length) and exponent ``k_P``; the magnitude and slope error limits
``eps_M``, ``eps_S`` [-] and exponents ``k_M``, ``k_S``; the weights of the four
scores, which add to 1."""

DTW_WINDOW = 0.1
"""Half-width of the Sakoe-Chiba band of the magnitude score's time warping [-], of the
shifted signals' length (the standard's)."""

SLOPE_SMOOTHING = 9
"""Samples of the centred moving average over the slope score's derivatives (the standard's)."""

GRADES: tuple[tuple[float, str], ...] = (
    (0.94, "excellent"), (0.8, "good"), (0.58, "fair"), (-math.inf, "poor"))
"""The standard's grades: a rating above each bound (and at most the one above it)
has its name."""


@dataclass(frozen=True)
class Rating:
    """The four scores and the rating of one signal against its reference, each in [0, 1].

    Attributes
    ----------
    corridor, phase, magnitude, slope : float
        ``Z``, ``E_P``, ``E_M``, ``E_S`` [-].
    overall : float
        ``R`` [-], their weighted sum.
    shift : int
        ``n_eps`` [samples]: positive where ``C`` lags ``T``.
    """

    corridor: float
    phase: float
    magnitude: float
    slope: float
    overall: float
    shift: int

    @property
    def grade(self) -> str:
        """The standard's grade of :attr:`overall`."""
        return grade(self.overall)


def grade(rating: float) -> str:
    """The standard's grade of a rating: excellent, good, fair or poor ("none" for NaN)."""
    if not math.isfinite(rating):
        return "none"
    return next(name for bound, name in GRADES if rating > bound)


def _score(error: float, limit: float, exponent: float) -> float:
    """``((limit - error) / limit) ** exponent``, 1 at no error and 0 at or beyond the limit."""
    if error >= limit:
        return 0.0
    return ((limit - max(error, 0.0)) / limit) ** exponent


def corridor_score(reference: np.ndarray, comparison: np.ndarray) -> float:
    """``Z`` [-]: the mean over the samples of each one's corridor score."""
    p = PARAMETERS
    t_norm = float(np.max(np.abs(reference)))
    if t_norm == 0.0:
        return math.nan
    inner, outer = p["a_0"] * t_norm, p["b_0"] * t_norm
    e = np.abs(comparison - reference)
    z = np.clip((outer - e) / (outer - inner), 0.0, 1.0) ** p["k_Z"]
    return float(np.mean(np.where(e <= inner, 1.0, z)))


def phase_shift(reference: np.ndarray, comparison: np.ndarray) -> int:
    """``n_eps`` [samples]: the shift of ``comparison`` of largest correlation with ``reference``.

    Positive where ``comparison`` lags (``comparison[n:]`` against
    ``reference[:N - n]``); shifts up to ``eps_P * N``, the smallest of equal
    correlation.
    """
    n_total = reference.size
    limit = int(math.floor(PARAMETERS["eps_P"] * n_total))
    rho = _shift_correlations(np.asarray(reference, float), np.asarray(comparison, float), limit)
    order = sorted(range(-limit, limit + 1), key=lambda k: (abs(k), k))
    best, best_rho = 0, -math.inf
    for n in order:
        if rho[n + limit] > best_rho + 1e-12:  # a tie to rounding keeps the smaller shift
            best, best_rho = n, rho[n + limit]
    return best


def _shift_correlations(t: np.ndarray, c: np.ndarray, limit: int) -> np.ndarray:
    """Pearson correlation of the overlaps at shifts ``-limit..limit`` (-inf where undefined)."""
    n_total = t.size
    shifts = np.arange(-limit, limit + 1)
    length = n_total - np.abs(shifts)
    # sum of t[i] c[i + n] over the overlap, every n at once (circular correlation by FFT,
    # padded beyond 2 N so that no shift wraps)
    size = 1 << (2 * n_total).bit_length()
    circ = np.fft.irfft(np.fft.rfft(c, size) * np.conj(np.fft.rfft(t, size)), size)
    cross = circ[shifts % size]
    ct, ct2 = np.concatenate(([0.0], np.cumsum(t))), np.concatenate(([0.0], np.cumsum(t * t)))
    cc, cc2 = np.concatenate(([0.0], np.cumsum(c))), np.concatenate(([0.0], np.cumsum(c * c)))
    pos = shifts >= 0  # t[:N - n] against c[n:]; else t[-n:] against c[:N + n]
    t0 = np.where(pos, 0, -shifts)
    c0 = np.where(pos, shifts, 0)
    st, st2 = ct[t0 + length] - ct[t0], ct2[t0 + length] - ct2[t0]
    sc, sc2 = cc[c0 + length] - cc[c0], cc2[c0 + length] - cc2[c0]
    cov = cross - st * sc / length
    var_t, var_c = st2 - st * st / length, sc2 - sc * sc / length
    with np.errstate(invalid="ignore", divide="ignore"):
        rho = cov / np.sqrt(var_t * var_c)
    # a constant overlap has no correlation: rounding leaves its variance a hair above 0
    flat = (var_t <= 1e-12 * st2.clip(1e-300)) | (var_c <= 1e-12 * sc2.clip(1e-300)) | (length < 2)
    return np.where(flat | ~np.isfinite(rho), -np.inf, rho)


def _overlap(reference: np.ndarray, comparison: np.ndarray,
             n: int) -> tuple[np.ndarray, np.ndarray]:
    """The overlapping parts of ``reference`` and ``comparison`` shifted back by ``n`` samples."""
    if n >= 0:
        return reference[:reference.size - n], comparison[n:]
    return reference[-n:], comparison[:comparison.size + n]


def phase_score(shift: int, n_samples: int) -> float:
    """``E_P`` [-] of a phase error of ``shift`` samples in a signal of ``n_samples``."""
    p = PARAMETERS
    return _score(abs(shift), p["eps_P"] * n_samples, p["k_P"])


@njit(cache=True)
def _dtw_path(x: np.ndarray, y: np.ndarray, radius: int) -> tuple[np.ndarray, np.ndarray]:
    """Indices into ``x`` and ``y`` along the warping path of least summed squared difference.

    The accumulated cost is kept for the band alone: ``cost[i, j - i + radius]``.
    """
    n, m = x.size, y.size
    w = 2 * radius + 1
    cost = np.full((n, w), np.inf)
    for i in range(n):
        for j in range(max(0, i - radius), min(m, i + radius + 1)):
            d = (x[i] - y[j]) ** 2
            if i == 0 and j == 0:
                cost[0, radius] = d
                continue
            best = np.inf
            if i > 0 and j - i + 1 + radius < w and cost[i - 1, j - i + 1 + radius] < best:
                best = cost[i - 1, j - i + 1 + radius]  # (i - 1, j)
            if j > 0 and j - 1 - i + radius >= 0 and cost[i, j - 1 - i + radius] < best:
                best = cost[i, j - 1 - i + radius]  # (i, j - 1)
            if i > 0 and j > 0 and cost[i - 1, j - i + radius] < best:
                best = cost[i - 1, j - i + radius]  # (i - 1, j - 1)
            cost[i, j - i + radius] = d + best
    ix = np.empty(n + m, np.int64)
    iy = np.empty(n + m, np.int64)
    i, j, k = n - 1, m - 1, 0
    while True:
        ix[k], iy[k] = i, j
        k += 1
        if i == 0 and j == 0:
            break
        # the predecessor of least accumulated cost; the diagonal wins a tie
        step, best = 0, np.inf
        if i > 0 and j > 0:
            step, best = 2, cost[i - 1, j - i + radius]
        if i > 0 and j - i + 1 + radius < w and cost[i - 1, j - i + 1 + radius] < best:
            step, best = 0, cost[i - 1, j - i + 1 + radius]
        if j > 0 and j - 1 - i + radius >= 0 and cost[i, j - 1 - i + radius] < best:
            step, best = 1, cost[i, j - 1 - i + radius]
        if step == 2:
            i, j = i - 1, j - 1
        elif step == 0:
            i -= 1
        else:
            j -= 1
    return ix[:k][::-1], iy[:k][::-1]


def warp(reference: np.ndarray, comparison: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The two signals aligned by dynamic time warping, as the magnitude score aligns them."""
    radius = max(1, math.ceil(DTW_WINDOW * reference.size))
    ix, iy = _dtw_path(np.ascontiguousarray(reference, dtype=np.float64),
                       np.ascontiguousarray(comparison, dtype=np.float64), radius)
    return reference[ix], comparison[iy]


def magnitude_score(reference: np.ndarray, comparison: np.ndarray) -> float:
    """``E_M`` [-] of two signals already shifted by their phase error."""
    t_w, c_w = warp(reference, comparison)
    scale = float(np.sum(np.abs(t_w)))
    if scale == 0.0:
        return math.nan
    p = PARAMETERS
    return _score(float(np.sum(np.abs(c_w - t_w))) / scale, p["eps_M"], p["k_M"])


def smoothed_derivative(signal: np.ndarray, dt: float) -> np.ndarray:
    """Central-difference derivative [unit/s], averaged over :data:`SLOPE_SMOOTHING` samples."""
    d = np.gradient(np.asarray(signal, dtype=float), dt)
    half = SLOPE_SMOOTHING // 2
    c = np.concatenate(([0.0], np.cumsum(d)))
    i = np.arange(d.size)
    h = np.minimum(half, np.minimum(i, d.size - 1 - i))  # shrinks symmetrically at the ends
    return (c[i + h + 1] - c[i - h]) / (2 * h + 1)


def slope_score(reference: np.ndarray, comparison: np.ndarray, dt: float) -> float:
    """``E_S`` [-] of two signals already shifted by their phase error, sampled every ``dt`` [s]."""
    dt_ref, dc = smoothed_derivative(reference, dt), smoothed_derivative(comparison, dt)
    scale = float(np.sum(np.abs(dt_ref)))
    if scale == 0.0:
        return math.nan
    p = PARAMETERS
    return _score(float(np.sum(np.abs(dc - dt_ref))) / scale, p["eps_S"], p["k_S"])


def rate(reference: np.ndarray, comparison: np.ndarray, dt: float) -> Rating:
    """The rating of ``comparison`` against ``reference``, both sampled every ``dt`` [s].

    Parameters
    ----------
    reference : ndarray
        ``T``, the measured signal, at least 3 samples.
    comparison : ndarray
        ``C``, the model's, as many samples.
    dt : float
        Sample period [s].

    Returns
    -------
    Rating
        NaN scores where the reference has no amplitude or no slope.

    Raises
    ------
    ValueError
        Signals of different lengths, fewer than 3 samples, or not finite.
    """
    t = np.asarray(reference, dtype=float)
    c = np.asarray(comparison, dtype=float)
    if t.shape != c.shape or t.ndim != 1 or t.size < 3:
        raise ValueError(f"rate: reference and comparison must be 1-D and of one length of at "
                         f"least 3 samples, got {t.shape} and {c.shape}")
    if not (np.isfinite(t).all() and np.isfinite(c).all()):
        raise ValueError("rate: the signals have NaN or infinite samples; rate a finite stretch")
    z = corridor_score(t, c)
    shift = phase_shift(t, c)
    e_p = phase_score(shift, t.size)
    t_s, c_s = _overlap(t, c, shift)
    e_m = magnitude_score(t_s, c_s)
    e_s = slope_score(t_s, c_s, dt)
    p = PARAMETERS
    r = p["w_Z"] * z + p["w_P"] * e_p + p["w_M"] * e_m + p["w_S"] * e_s
    return Rating(z, e_p, e_m, e_s, float(r), shift)
