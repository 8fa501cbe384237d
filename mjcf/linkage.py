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

from artic.mjcf.errors import UserError


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

    @property
    def rod(self) -> float:
        """Tie-rod length: the tips' distance straight ahead [m]."""
        return self.track - 2.0 * self.arm * math.sin(self.beta)

    def right_angles(self, d_left: np.ndarray) -> np.ndarray:
        """Right-wheel angles for left-wheel angles [rad] (left turns positive).

        The right tip lies on two circles: of radius ``arm`` about the right
        kingpin and of radius ``rod`` about the left tip. Their two crossings
        are the linkage's two assembly branches; the assembled one is the
        crossing whose angle is nearer ``d_left`` (straight ahead, it is
        ``d_left`` itself).

        Raises
        ------
        ValueError
            Where the circles do not meet: the linkage cannot reach that angle.
        """
        d_left = np.asarray(d_left, dtype=float)
        lx, ly = -self.arm * math.cos(self.beta), self.arm * math.sin(self.beta)
        c, s = np.cos(d_left), np.sin(d_left)
        # Left tip, from the right kingpin at (0, -track / 2).
        ax, ay = c * lx + s * ly, self.track + s * lx - c * ly
        dist = np.hypot(ax, ay)
        # The crossings: along the kingpin-tip line at e, and off it by +-h.
        e = (dist ** 2 + self.arm ** 2 - self.rod ** 2) / (2.0 * dist)
        h2 = self.arm ** 2 - e ** 2
        if np.any(h2 < 0.0):
            bad = np.atleast_1d(d_left)[np.atleast_1d(h2 < 0.0)][0]
            raise UserError(f"the trapezoid cannot reach a left-wheel angle of {bad} rad")
        h = np.sqrt(h2)
        ux, uy = ax / dist, ay / dist
        base = np.arctan2(ly, lx)  # the arm's angle straight ahead
        best = None
        for sign in (1.0, -1.0):
            px, py = e * ux - sign * h * uy, e * uy + sign * h * ux
            d = np.arctan2(py, px) - base
            d = d_left + (d - d_left + np.pi) % (2.0 * np.pi) - np.pi  # nearest turn to d_left
            best = d if best is None else np.where(np.abs(d - d_left) < np.abs(best - d_left),
                                                   d, best)
        return best

    def right_angle(self, d_left: float) -> float:
        """Right-wheel angle for a left-wheel angle [rad]: :meth:`right_angles` of one."""
        return float(self.right_angles(np.asarray(d_left, dtype=float)))

    def fit(self, d_max: float, degree: int = 4) -> np.ndarray:
        """Polynomial coefficients ``a0..a4`` with ``delta_R = sum a_k delta_L^k``.

        Parameters
        ----------
        d_max : float
            Largest left-wheel angle to fit [rad].
        """
        d = np.linspace(-d_max, d_max, 201)
        r = self.right_angles(d)
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
                raise UserError(f"the linkage locks at a left-wheel angle of {d:.2f} rad, "
                                 f"before a centre angle of {sign * delta_max:.2f} rad; "
                                 "lengthen the steering arm or lower delta_max") from exc
            if sign * c < sign * c_prev:
                break
            if sign * c >= delta_max:
                return _bisect(lambda x: sign * centre(x) - delta_max, prev, float(d))
            prev, c_prev = float(d), c
        raise UserError(f"the linkage does not reach a centre angle of {sign * delta_max} rad")

    return reach(-1.0), reach(1.0)


def _bisect(f: Callable[[float], float], a: float, b: float) -> float:
    """The root of ``f`` in ``[a, b]``, where ``f(a) < 0 <= f(b)``, by bisection.

    Bisection halves the bracket to the spacing of doubles near the root, in
    at most about 60 steps, and is exact about which side it keeps. The
    bracket here is one 0.01 rad step of a smooth monotone function; a
    library root finder would cost an import of ``scipy.optimize`` (about
    0.3 s) at every start of the command line.
    """
    for _ in range(200):
        m = 0.5 * (a + b)
        if m in (a, b):
            break
        if f(m) < 0.0:
            a = m
        else:
            b = m
    return b
