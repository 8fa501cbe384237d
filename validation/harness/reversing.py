"""When the harness's feedback is on: reversing decided with hysteresis on the speed.

The harness (:mod:`artic.validation.harness.loop`) closes its articulation loop
only while the tractor reverses. Deciding that sample by sample from the sign
of a measured speed switches the feedback on in forward runs: at standstill
the speed is noise about zero, and every negative sample would count. The
decision here is on the harness's own speed input ``u1`` (the measured speed,
smoothed over :data:`artic.validation.harness.loop.SPEED_WINDOW`), once per log, with
a dead band and a minimum duration:

- a *reversing stretch* is a run of samples with ``u1 < -v_off`` that reaches
  ``u1 < -v_on`` and lasts at least :data:`MIN_DURATION`; its samples, from the
  first to the last below ``-v_off``, are reversing, and no other sample is.
- ``v_on`` = :data:`DEAD_BAND` and ``v_off = v_on / 2`` (the hysteresis), both times
  the vehicle's :attr:`~artic.mjcf.vehicle.Vehicle.speed_ratio` (1 full-size;
  ``sqrt(1/14)`` for a 1:14 model, whose Froude-scaled speeds are that much lower).

Why these values. Speed noise at standstill (1 cm/s at 100 Hz from an
inertial unit, smoothed to about 2 mm/s) would need to stay below ``-v_off``
(25 mm/s, twelve times that) for a whole second, across four filter windows,
to count: it never does, so a forward log gets no feedback at all. The cost
is what reversing goes without feedback. Open loop, the articulation's error
grows as ``exp(s / L2)`` over the distance ``s`` reversed (eq. (6) with
``K = 0``: the eigenvalue is ``-u1 / L2``). The decision is made on the whole
log, so a stretch counts from its first sample below ``-v_off``, not from the
second that confirms it: a reverse from standstill at deceleration ``a``
goes ``v_off**2 / (2 a)`` without feedback (1 mm at 0.3 m/s^2), and creeping
slower than ``v_off``, or for less than a second, ``v_off`` metres per second
of it. Both are far below ``L2`` (7.5 m full-size, 0.54 m at 1:14).
:data:`MIN_DURATION` is two filter windows, so that one outlier, which the
filter spreads over one window, never makes a stretch.
"""

from __future__ import annotations

import numpy as np

DEAD_BAND = 0.05
"""Speed the tractor must reverse faster than for a stretch to count, full-size [m/s]."""

MIN_DURATION = 1.0
"""Shortest reversing stretch [s]: two of the harness's speed-filter windows."""


def reversing(t: np.ndarray, u1: np.ndarray, speed_ratio: float = 1.0) -> np.ndarray:
    """Which samples of a log reverse, with hysteresis (see the module docstring).

    Parameters
    ----------
    t : ndarray
        Time [s].
    u1 : ndarray
        The tractor's (smoothed) longitudinal speed [m/s].
    speed_ratio : float
        The vehicle's speeds over the full-size reference's [-]; scales the dead band.

    Returns
    -------
    ndarray of bool
        True where the harness's feedback is on.
    """
    v_on = DEAD_BAND * speed_ratio
    v_off = 0.5 * v_on
    below = np.asarray(u1, dtype=float) < -v_off
    edges = np.flatnonzero(np.diff(np.concatenate([[0], below.view(np.int8), [0]])))
    out = np.zeros(below.size, dtype=bool)
    for a, b in zip(edges[0::2], edges[1::2], strict=True):  # stretches [a, b)
        if t[b - 1] - t[a] >= MIN_DURATION and float(np.min(u1[a:b])) < -v_on:
            out[a:b] = True
    return out
