"""The prescribed paths of the low-speed manoeuvres: a straight, an arc, a straight.

A :class:`TurnPath` starts at the origin heading +x, runs ``entry`` metres
straight, turns through ``angle`` on a circle of ``radius`` (left or right,
entered and left without a spiral) and runs ``exit`` metres straight. Its
path coordinates (:meth:`TurnPath.frenet`) are the station ``s`` along it and
the offset ``n`` to its left, measured perpendicular to it: radially on the
arc, so that a swept width measured across the path is the width measured
radially about the turn's centre, as the standards measure it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class TurnPath:
    """Tangent, arc, tangent.

    Parameters
    ----------
    entry : float
        Straight before the arc [m].
    radius : float
        Radius of the arc [m].
    angle : float
        Angle turned on the arc [rad], positive.
    exit : float
        Straight after the arc [m].
    side : float
        +1 turning left, -1 turning right.
    """

    entry: float
    radius: float
    angle: float
    exit: float
    side: float = 1.0

    @property
    def arc(self) -> float:
        """Length of the arc [m]."""
        return self.radius * self.angle

    @property
    def length(self) -> float:
        """Length of the whole path [m]."""
        return self.entry + self.arc + self.exit

    @property
    def centre(self) -> tuple[float, float]:
        """Centre of the arc [m]."""
        return self.entry, self.side * self.radius

    def pose(self, s: np.ndarray | float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Position [m] and heading [rad] of the path at stations ``s`` [m] (clipped to it)."""
        s = np.clip(np.asarray(s, dtype=float), -np.inf, self.length + 1e3)
        cx, cy = self.centre
        phi = np.clip((s - self.entry) / self.radius, 0.0, self.angle)  # angle turned
        heading = self.side * phi
        # On the arc: the point at angle phi about the centre.
        x = cx + self.radius * np.sin(phi)
        y = cy - self.side * self.radius * np.cos(phi)
        before = s < self.entry
        after = s > self.entry + self.arc
        x = np.where(before, s, x)
        y = np.where(before, 0.0, y)
        extra = s - self.entry - self.arc
        x = np.where(after, x + extra * np.cos(heading), x)
        y = np.where(after, y + extra * np.sin(heading), y)
        return x, y, heading

    def frenet(self, x: np.ndarray, y: np.ndarray,
               turned: np.ndarray | float | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Station ``s`` [m] and offset ``n`` to the left [m] of points ``(x, y)``.

        A point is on the arc's part when its bearing from the centre lies within
        the arc's angle, before it when behind the arc's start line, after it
        otherwise. On the arc, ``n`` is radial: ``R - r`` turning left.
        ``turned`` [rad], for an arc of more than half a turn: about how far
        round the arc each point is; the bearing is taken in the turn nearest it
        (without it, within half a turn either side of the arc's start).
        """
        x = np.asarray(x, dtype=float)
        ym = np.asarray(y, dtype=float) * self.side  # mirrored onto a left turn
        R, A = self.radius, self.angle
        dx, dy = x - self.entry, ym - R
        phi = np.arctan2(dx, -dy)  # angle turned at the point's bearing from the centre
        if turned is not None:
            phi = phi + 2.0 * np.pi * np.round((np.asarray(turned, dtype=float) - phi)
                                               / (2.0 * np.pi))
        on_arc = (phi >= 0.0) & (phi <= A)
        before = ~on_arc & (x < self.entry)
        # The exit straight: from the arc's end along its heading A.
        ex, ey = self.entry + R * math.sin(A), R - R * math.cos(A)
        rx, ry = x - ex, ym - ey
        c, sn = math.cos(A), math.sin(A)
        s = np.where(on_arc, self.entry + R * phi,
                     np.where(before, x, self.entry + self.arc + rx * c + ry * sn))
        n = np.where(on_arc, R - np.hypot(dx, dy), np.where(before, ym, -rx * sn + ry * c))
        return s, n * self.side

    def curvature(self, s: np.ndarray | float) -> np.ndarray:
        """Curvature at stations ``s`` [1/m], positive turning left."""
        s = np.asarray(s, dtype=float)
        on = (s >= self.entry) & (s <= self.entry + self.arc)
        return np.where(on, self.side / self.radius, 0.0)
