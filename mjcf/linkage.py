"""The tie-rod trapezoid: how the right front wheel follows the left one.

The steering box turns the left wheel. A tie rod joins the two steering arms,
each of length ``l``, which point back and inward at ``beta`` from the
wheel's heading. ``tan(beta) = (w / 2) / L1`` is the classic Ackermann
layout: the arms aim at the drive-axle centre. The rod length stays
``w - 2 l sin(beta)``, with ``w`` the axle track, so for every left-wheel angle
there is one right-wheel angle. For a left turn the left wheel is the inner
wheel and turns more than the right one.

The right-wheel angle is solved from the rod length and fitted by a
fourth-order polynomial, the form a MuJoCo joint equality takes. The
equivalent single-track angle at the axle centre,
``cot(delta_c) = (cot(delta_L) + cot(delta_R)) / 2``, is not symmetric in
``delta_L``: the left/right asymmetry that the paper's eq. (3) models with ``q``.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Trapezoid:
    """A tie-rod steering trapezoid.

    Parameters
    ----------
    track : float
        Distance between the kingpins [m].
    wheelbase : float
        Front axle to drive axle [m].
    arm : float
        Steering-arm length [m].
    """

    track: float
    wheelbase: float
    arm: float

    @property
    def beta(self) -> float:
        """Arm angle from the wheel heading, inward [rad]."""
        return math.atan(0.5 * self.track / self.wheelbase)

    def _tips(self, d_left: float, d_right: float) -> tuple[np.ndarray, np.ndarray]:
        lx, ly = -self.arm * math.cos(self.beta), self.arm * math.sin(self.beta)

        def tip(kingpin_y: float, d: float, inward: float) -> np.ndarray:
            c, s = math.cos(d), math.sin(d)
            x, y = lx, inward * ly
            return np.array([c * x - s * y, kingpin_y + s * x + c * y])

        return tip(0.5 * self.track, d_left, -1.0), tip(-0.5 * self.track, d_right, 1.0)

    def right_angle(self, d_left: float) -> float:
        """Right-wheel angle for a left-wheel angle [rad] (left turns positive)."""
        rod = self.track - 2.0 * self.arm * math.sin(self.beta)

        def gap(d_right: float) -> float:
            a, b = self._tips(d_left, d_right)
            return float(np.linalg.norm(a - b)) - rod

        # The rod closes on two branches; the assembled one is the sign change
        # nearest to d_left. The grid is scanned at once (the right tip for all
        # candidate angles), then the root refined by brentq on gap().
        grid = d_left + np.linspace(-1.2, 1.2, 961)
        a, _ = self._tips(d_left, 0.0)
        lx, ly = -self.arm * math.cos(self.beta), self.arm * math.sin(self.beta)
        c, s = np.cos(grid), np.sin(grid)
        bx, by = c * lx - s * ly, -0.5 * self.track + s * lx + c * ly
        g = np.hypot(a[0] - bx, a[1] - by) - rod
        changes = np.flatnonzero(np.sign(g[:-1]) != np.sign(g[1:]))
        if changes.size == 0:
            raise ValueError(f"the trapezoid cannot reach a left-wheel angle of {d_left} rad")
        i = changes[np.argmin(np.abs(grid[changes] - d_left))]
        from scipy.optimize import brentq  # here: scipy.optimize takes 0.4 s to import

        return brentq(gap, grid[i], grid[i + 1], xtol=1e-14)

    def fit(self, d_max: float, degree: int = 4) -> np.ndarray:
        """Polynomial coefficients ``a0..a4`` with ``delta_R = sum a_k delta_L^k``.

        Parameters
        ----------
        d_max : float
            Largest left-wheel angle to fit [rad].
        """
        d = np.linspace(-d_max, d_max, 201)
        r = np.array([self.right_angle(x) for x in d])
        return np.polynomial.polynomial.polyfit(d, r, degree)


def centre_angle(d_left: np.ndarray, d_right: np.ndarray) -> np.ndarray:
    """Equivalent single-track angle at the axle centre [rad].

    ``cot(delta_c) = (cot(delta_L) + cot(delta_R)) / 2``, written with tangents so
    that it is smooth through zero: ``tan(delta_c) = 2 tL tR / (tL + tR)``.
    """
    tl, tr = np.tan(d_left), np.tan(d_right)
    den = tl + tr
    with np.errstate(invalid="ignore", divide="ignore"):
        t = np.where(np.abs(den) > 1e-12, 2.0 * tl * tr / den, 0.5 * den)
    return np.arctan(t)


def left_range(right: Callable[[float], float], delta_max: float) -> tuple[float, float]:
    """Left-wheel angles that give centre angles of ``-delta_max`` and ``+delta_max`` [rad].

    Parameters
    ----------
    right : callable
        Right-wheel angle for a left-wheel angle: :meth:`Trapezoid.right_angle`
        or a fit of it.
    delta_max : float
        Largest centre angle [rad].

    Raises
    ------
    ValueError
        When the linkage locks or turns back before reaching ``delta_max``.
    """
    def centre(d_left: float) -> float:
        return float(centre_angle(np.array(d_left), np.array(right(d_left))))

    def reach(sign: float) -> float:
        # Step out from straight ahead until the centre angle passes delta_max.
        prev, c_prev = 0.0, 0.0
        for d in sign * np.arange(0.01, 1.5, 0.01):
            try:
                c = centre(float(d))
            except ValueError as exc:
                raise ValueError(f"the linkage locks at a left-wheel angle of {d:.2f} rad, "
                                 f"before a centre angle of {sign * delta_max:.2f} rad; "
                                 "lengthen the steering arm or lower delta_max") from exc
            if sign * c < sign * c_prev:
                break
            if sign * c >= delta_max:
                from scipy.optimize import brentq

                return brentq(lambda x: centre(x) - sign * delta_max, prev, float(d),
                              xtol=1e-13)
            prev, c_prev = float(d), c
        raise ValueError(f"the linkage does not reach a centre angle of {sign * delta_max} rad")

    return reach(-1.0), reach(1.0)
