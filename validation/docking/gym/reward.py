"""The environment's reward: progress to the dock, shaped, with the run's outcome at its end.

Each step earns the decrease of the potential

    Phi = -(sqrt(distance^2 + lateral^2) + HEADING_LENGTH * |heading|)

of the observed dock errors (:meth:`artic.Controller.dock_errors`: the rear's
distance short of the face and offset from the door's centre line [m], its
heading [rad]) less :data:`TIME_COST`. Shaping by a potential's difference
leaves the optimal policies of the outcome's reward unchanged (Ng, Harada and
Russell, "Policy invariance under reward transformations", ICML 1999), so the
shaping speeds learning without changing what is best. The last step adds the
outcome: :data:`DOCKED` for a run the benchmark scores as docked, minus
:data:`CRASH` for a collision or a jackknife; a timeout adds nothing (it is a
truncation, not an outcome).
"""

from __future__ import annotations

import numpy as np

HEADING_LENGTH = 5.0
"""Metres of position error that one radian of heading error weighs as much as [m/rad]:
at the door, 3 deg askew moves the rear's corners by about 0.13 m, like 0.26 rad x 0.5 m."""

TIME_COST = 0.01
"""Reward spent per step (0.1 s): a slow docking earns less [1/step]."""

DOCKED = 10.0
"""Reward of a docked run at its end."""

CRASH = 10.0
"""Penalty of a collision or a jackknife at the end."""

CRASHES = ("collision", "jackknife")
"""The outcomes :data:`CRASH` punishes (the failure reason's first word)."""


def potential(distance: float, lateral: float, heading: float) -> float:
    """The potential Phi of the dock errors [m, m, rad]."""
    # numpy's hypot, not math's: the vector environment computes the same for a
    # batch (potentials), and the two must agree to the bit.
    return -(float(np.hypot(distance, lateral)) + HEADING_LENGTH * abs(heading))


def potentials(errors: np.ndarray) -> np.ndarray:
    """:func:`potential` of rows of dock errors ``(n, 3)`` [m, m, rad], the same to the bit."""
    return -(np.hypot(errors[:, 0], errors[:, 1]) + HEADING_LENGTH * np.abs(errors[:, 2]))


def step_reward(before: tuple[float, float, float], after: tuple[float, float, float]) -> float:
    """Shaped reward of a step from dock errors ``before`` to ``after`` [m, m, rad]."""
    return potential(*after) - potential(*before) - TIME_COST


def step_rewards(before: np.ndarray, after: np.ndarray) -> np.ndarray:
    """:func:`step_reward` of rows of dock errors ``(n, 3)``, the same to the bit."""
    return potentials(after) - potentials(before) - TIME_COST


def outcome_reward(success: bool, reason: str) -> float:
    """The reward added at the end: docked, crashed (``reason``'s first word) or neither."""
    if success:
        return DOCKED
    return -CRASH if reason in CRASHES else 0.0
