"""When the harness's feedback is on: reversing decided with hysteresis on the speed.

The harness (:mod:`artic.validation.harness.loop`) closes its articulation loop
only while the tractor reverses. Deciding that sample by sample from the sign
of a measured speed switches the feedback on in forward runs: at standstill
the speed is noise about zero, and every negative sample would count. The
decision here is on the harness's own speed input ``u1`` (the measured speed,
smoothed over :data:`artic.validation.logs.differentiate.SPEED_WINDOW`), once per log, with
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

The handover. The feedback does not switch on and off in one sample: its
weight (:func:`feedback_weight`, the ``w`` of
``delta = delta_c + w K wrap(gamma_model - gamma_meas)``) rises linearly from
0 over :data:`HANDOVER` where a stretch starts and falls back to 0 over as
long where it ends, and is 1 in between and 0 outside. Switched in one
sample, the road-wheel command steps by the whole feedback term, which
reaches 15 deg where a model's articulation is 5 deg off the log's at a
stop (4.7 deg at most in the default campaign); no driver or actuator steers
like that, and the plant's steering servo answering such a step was the only
place where its 10 ms step missed the yaw-rate accuracy of the timestep study
(``docs/design/timestep.md``). The ramp's length is set by what it costs
either way:

- *steering rate*: the handover turns the wheels at ``K |e| / HANDOVER``
  beside what the log's steering does; 1 s keeps that within a truck
  steering actuator's 0.3 rad/s of road wheel (the synthetic driver's and
  the docking runs' limit, 360 deg/s at the steering wheel through 21:1) for
  a feedback term up to 17 deg, more than the 15 deg above;
- *distance with partial feedback*: a stretch's edges are where the smoothed
  speed passes ``-v_off``, at a standstill, so a ramp covers at most
  ``v_off HANDOVER + a HANDOVER**2 / 2`` of travel: 0.18 m at 0.3 m/s^2,
  0.28 m at the 0.5 m/s^2 of the docking driver's pedal, 0.53 m at the
  synthetic logs' hardest braking (1 m/s^2). Even open loop over the whole
  ramp the articulation's error would grow by ``exp(s / L2)``: 2.4 %, 3.7 %
  and 7 % (L2 = 7.5 m); a shorter ramp would cost less here and more in
  steering rate. And the loop is already stable once ``w K`` passes
  ``K_min = L1 / (L2 - L1c)`` (0.50 to 0.56 on the gosar presets: a fifth of
  the way at K = 3).

A stretch at the log's first sample starts at weight 1: the model starts on
the log's state, so the feedback term starts at zero there and nothing steps;
likewise a stretch that ends with the log ends at 1. The ramp runs between
the sample outside the stretch (weight 0) and the stretch's samples, so the
weight is positive on exactly the reversing samples (:func:`reversing`):
``weight > 0`` is still which samples reverse. Like the dead band, the
ramp's time scales with the vehicle's ``speed_ratio`` (Froude: times as the
square root of the length, so the distance over the ramp stays the same
fraction of ``L2``). The command is held over each sample, so the plant
sees a staircase whatever the ramp's shape; a linear ramp gives the lowest
peak rate for its length.
"""

from __future__ import annotations

import numpy as np

DEFAULT_GAIN = 3.0
"""The paper's feedback gain K [rad/rad]."""

DEAD_BAND = 0.05
"""Speed the tractor must reverse faster than for a stretch to count, full-size [m/s]."""

MIN_DURATION = 1.0
"""Shortest reversing stretch [s]: two of the harness's speed-filter windows."""

HANDOVER = 1.0
"""Time over which the feedback's weight rises from 0 to 1, and falls back, full-size [s]."""


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
    out = np.zeros(below.size, dtype=bool)
    for a, b in _stretches(below):
        if t[b - 1] - t[a] >= MIN_DURATION and float(np.min(u1[a:b])) < -v_on:
            out[a:b] = True
    return out


def feedback_weight(t: np.ndarray, u1: np.ndarray, speed_ratio: float = 1.0) -> np.ndarray:
    """The harness feedback's weight per sample, in [0, 1] (see the module docstring).

    0 outside the reversing stretches of :func:`reversing`, 1 inside them,
    with linear ramps of :data:`HANDOVER` (times ``speed_ratio``) where a
    stretch starts or ends inside the log. Positive on exactly the reversing
    samples.

    Parameters
    ----------
    t : ndarray
        Time [s].
    u1 : ndarray
        The tractor's (smoothed) longitudinal speed [m/s].
    speed_ratio : float
        The vehicle's speeds over the full-size reference's [-]; scales the
        dead band and the ramp's time.

    Returns
    -------
    ndarray of float
        The weight ``w`` of the feedback term [-].
    """
    t = np.asarray(t, dtype=float)
    rev = reversing(t, u1, speed_ratio)
    ramp = HANDOVER * speed_ratio
    w = np.zeros(rev.size)
    for a, b in _stretches(rev):
        part = np.ones(b - a)
        if a > 0:  # from 0 at the sample before the stretch
            part = np.minimum(part, (t[a:b] - t[a - 1]) / ramp)
        if b < rev.size:  # to 0 at the sample after it
            part = np.minimum(part, (t[b] - t[a:b]) / ramp)
        w[a:b] = part
    return w


def _stretches(mask: np.ndarray) -> list[tuple[int, int]]:
    """The runs of True in a boolean array, as half-open index ranges ``[a, b)``."""
    edges = np.flatnonzero(np.diff(np.concatenate([[0], mask.view(np.int8), [0]])))
    return list(zip(edges[0::2].tolist(), edges[1::2].tolist(), strict=True))
