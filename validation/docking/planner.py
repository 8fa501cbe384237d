"""A path onto the dock: hybrid A* over KIN with a closed-loop final approach.

The planner searches KIN's state ``[X, Y, psi_1, gamma]`` (see
:mod:`artic.reduced.kinematic`) with motion primitives of
:data:`PRIMITIVE_LENGTH` of tractor travel each, integrated with KIN's own
equations (:func:`artic.reduced.integrate.rk4_step` in the distance domain):

- forward: the road-wheel angle turned to one of five values up to
  :data:`STEER_SHARE` of the vehicle's ``delta_max``;
- reverse: the articulation steered towards one of five references up to
  :data:`GAMMA_PLAN`, through the harness's stabilising law
  ``delta = delta_ss(gamma_ref) + K (gamma - gamma_ref)``
  (:func:`artic.validation.harness.feedback.feedback_law`). Held steering in reverse
  would jackknife within a few metres; a primitive that steers the
  articulation is one a reversing controller can follow.

Every primitive keeps ``|gamma| <= GAMMA_PLAN`` and ``|delta| <= STEER_SHARE delta_max``
(:data:`REVERSE_STEER_SHARE` reversing),
turns the steering at most :data:`STEER_RATE` per metre,
and the outlines clear every obstacle by :data:`MARGIN` (the dock face
excepted, which the rear must reach).

The search is weighted A*: cost is travel, plus :data:`CUSP_COST` per
direction change; the heuristic is the semitrailer axle's shortest distance
to the bay's approach around the obstacles (a grid, computed once per yard)
plus :data:`HEADING_COST` per radian of semitrailer heading still to turn.
Expanded nodes are deduplicated on a grid of position, heading, articulation
and direction.

The **final approach** is the analytic expansion: from a node, KIN is rolled
out in reverse under the reversing LQR of :mod:`artic.validation.docking.linear`,
which steers the semitrailer onto the door's centre line, until the rear
reaches the face. If the rollout clears every
obstacle and ends on the line (:data:`LANDING`), the search ends there.
Every popped node tries it, which is cheap (compiled) and lets a start that
a straight reverse can dock from need no search at all.

The search is bounded by :data:`MAX_EXPANSIONS`, not by wall time, so the
same start always gives the same path. :class:`HybridAStar` is the one
replaceable part: anything with its ``plan(yard, vehicle, start)`` works.
"""

from __future__ import annotations

import functools
import heapq
import math
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np
from numba import njit
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra

from artic.mjcf.vehicle import Vehicle
from artic.reduced.integrate import KIN, rk4_step
from artic.validation.docking.geometry import Box, Frames, box_array, first_hit
from artic.validation.docking.linear import APPROACH_WEIGHTS, gains
from artic.validation.docking.scenarios import Start, Yard
from artic.validation.harness.feedback import feedback_law

PRIMITIVE_LENGTH = 3.0
"""Tractor travel of one motion primitive [m]."""

STEP = 0.25
"""Integration and collision-check step along a primitive [m]."""

STEER_SHARE = 0.8
"""Paths steer up to this share of ``delta_max``: the rest is the path follower's."""

REVERSE_STEER_SHARE = 0.6
"""Reversing, paths steer up to this share of ``delta_max``. A follower on the
plant needs more steering than KIN's to hold a sharp curve in reverse (the
tyres scrub), and steering is all it has to keep the semitrailer from
jackknifing: with 80 % of the lock for reversing too, three offset starts in
thirty saturated the steering and two of them jackknifed."""

STEER_RATE = 0.2
"""Largest rate of the road-wheel angle along a path [rad/m]: the steering
actuator's 0.3 rad/s is 0.27 rad/m at 4 km/h, and the rest is the path
follower's."""

GAMMA_PLAN = math.radians(40.0)
"""Largest articulation of a path [rad]: half the presets' 80-degree jackknife
limit, where the steady-state steer (about 18 deg) leaves the reversing
controller more than half of the lock to correct with."""

GAIN = 3.0
"""K of the articulation law in reverse primitives and the final approach
[rad/rad], as the harness's (above the bound ``L1 / (L2 - L1c)`` of about 0.5)."""

MARGIN = 0.3
"""Clearance the path keeps from parked semitrailers and the yard's edge [m],
for the controller's tracking error."""

CUSP_COST = 10.0
"""Cost of a direction change [m of travel]: stopping, changing gear, starting."""

HEADING_COST = 8.0
"""Heuristic cost per radian of semitrailer heading still to turn [m/rad]."""

WEIGHT = 2.0
"""Weight of the heuristic (weighted A*: paths within this factor of the best, found faster)."""

MAX_EXPANSIONS = 5000
"""Nodes the search expands before it gives up."""

CELL = (1.0, math.radians(15.0), math.radians(15.0))
"""Deduplication grid: position [m], tractor heading and articulation [rad]."""

APPROACH = 30.0
"""The bay's approach: the heuristic's goal is the semitrailer axle on the door's
centre line with the rear this far from the face [m]. From 30 m the final
approach lands from offsets of metres; with 20 or 25 m as the goal the search
expanded two to four times as many nodes over the benchmark's starts."""

LANDING = (0.03, math.radians(0.3), math.radians(1.0))
"""A final approach lands when the rear ends this close to the centre line [m],
this close to its heading and this straight [rad]."""

Y_SAT = 3.0
"""The final approach acts on at most this lateral offset [m]: larger ones are
approached at the semitrailer heading this one asks for."""

APPROACH_GAMMA = math.radians(20.0)
"""A final approach starts only where the articulation is below this [rad]:
from a sharper one the steering it asks for swings the path harder than a
follower on the plant holds."""

MAX_APPROACH = 70.0
"""Longest final approach [m of tractor travel]."""


class PlanningError(RuntimeError):
    """No path within the search's bounds; the message says what was tried."""


@dataclass(frozen=True)
class Segment:
    """A stretch of path in one direction.

    Parameters
    ----------
    direction : int
        ``+1`` forward, ``-1`` reverse.
    states : ndarray, shape (n, 4)
        KIN states ``[X, Y, psi_1, gamma]`` along it, :data:`STEP` apart in tractor travel.
    delta : ndarray, shape (n,)
        Road-wheel angle KIN was steered with [rad].
    """

    direction: int
    states: np.ndarray
    delta: np.ndarray

    @property
    def length(self) -> float:
        """Tractor travel [m]."""
        d = np.diff(self.states[:, :2], axis=0)
        return float(np.sum(np.hypot(d[:, 0], d[:, 1])))


@dataclass(frozen=True)
class Plan:
    """A path: segments of alternating direction, and how the search went.

    Parameters
    ----------
    segments : tuple of Segment
        In driving order; the last ends with the rear at the dock face.
    expansions : int
        Nodes the search expanded.
    """

    segments: tuple[Segment, ...]
    expansions: int = 0

    @property
    def length(self) -> float:
        """Tractor travel of the whole path [m]."""
        return sum(s.length for s in self.segments)

    @property
    def direction_changes(self) -> int:
        """Cusps of the path."""
        return max(0, len(self.segments) - 1)

    def states(self) -> np.ndarray:
        """All KIN states, in order, shape (n, 4)."""
        return np.concatenate([s.states for s in self.segments])


class Planner(Protocol):
    """What the benchmark needs of a planner."""

    def plan(self, yard: Yard, vehicle: Vehicle, start: Start) -> Plan:
        """A path from ``start`` to the dock, or :class:`PlanningError`."""


# ---------------------------------------------------------------- compiled core
@njit(cache=True)
def steady_delta(gamma, P):
    """KIN's road-wheel angle that holds articulation ``gamma`` steady [rad].

    ``gamma_dot = 0`` in eq. (1): ``tan(delta) = L1 sin(gamma) / (L2 - L1c cos(gamma))``
    with KIN's lengths ``P = [L1, L1c, L2]``, in either direction of travel.
    """
    return math.atan(P[0] * math.sin(gamma) / (P[2] - P[1] * math.cos(gamma)))


_law = njit(cache=True)(feedback_law)


@njit(cache=True)
def _poses(x, P, x_ref):
    """Drive-axle and kingpin poses of one KIN state (as :class:`Frames` gives them)."""
    c, s = math.cos(x[2]), math.sin(x[2])
    t = np.array([x[0] - x_ref * c, x[1] - x_ref * s, x[2]])
    k = np.array([x[0] + P[1] * c, x[1] + P[1] * s, x[2] - x[3]])
    return t, k


@njit(cache=True)
def rollout(x0, direction, mode, value, steps, ds, kin, outlines):
    """One motion primitive of KIN, checked as it goes.

    Parameters
    ----------
    x0 : ndarray, shape (5,)
        Start state ``[X, Y, psi_1, gamma, delta]``: KIN's and the road-wheel angle.
    direction : float
        ``+1`` forward, ``-1`` reverse.
    mode : int
        0: road-wheel angle turned to ``value``; 1: articulation steered to ``value``.
    value : float
        [rad].
    steps : int
        Steps of ``ds`` [m].
    kin : tuple
        ``(P, delta_max, gamma_max, x_ref)``: KIN's ``[L1, L1c, L2]``, the steering
        and articulation limits [rad] and KIN's point ahead of the drive axle [m].
    outlines : tuple
        ``(tractor_box, trailer_box, boxes)``: outlines and obstacles, as
        :func:`artic.validation.docking.geometry.first_hit`.

    Returns
    -------
    states : ndarray, shape (steps + 1, 5)
        ``x0`` and the states after each step, each with the road-wheel angle
        held over the step that reached it.
    ok : bool
        Whether every state kept the limits and cleared the obstacles (the
        start is the caller's to check).

    The road-wheel angle turns at most :data:`STEER_RATE` per metre.
    """
    P, delta_max, gamma_max, x_ref = kin
    tractor_box, trailer_box, boxes = outlines
    out = np.empty((steps + 1, 5))
    x = x0[:4].copy()
    # Beyond this primitive's limit (a cusp after a sharper forward piece), the
    # wheel is turned back at standstill.
    delta = max(-delta_max, min(delta_max, x0[4]))
    out[0, :4] = x
    out[0, 4] = delta
    t = np.empty((1, 3))
    k = np.empty((1, 3))
    turn = STEER_RATE * ds
    for i in range(1, steps + 1):
        if mode == 0:
            target = value
        else:
            target, _, _ = _law(steady_delta(value, P), x[3], value, 1.0, GAIN, delta_max)
        delta += max(-turn, min(turn, target - delta))
        x = rk4_step(KIN, x, ds, direction, 0.0, delta, P)
        out[i, :4] = x
        out[i, 4] = delta
        if abs(x[3]) > gamma_max:
            return out, False
        tp, kp = _poses(x, P, x_ref)
        t[0] = tp
        k[0] = kp
        if first_hit(t, k, tractor_box, trailer_box, boxes)[0] >= 0:
            return out, False
    return out, True


@njit(cache=True)
def expand(x0, prims, steps, ds, kin, outlines):
    """Every motion primitive from ``x0``, in one compiled call.

    :func:`rollout` of each row ``(direction, mode, value, steering limit)`` of ``prims``,
    with ``kin`` and ``outlines`` as :func:`rollout` takes them (the steering limit the
    smaller of ``kin``'s and the row's).

    Returns
    -------
    pieces : ndarray, shape (n, steps + 1, 5)
    ok : ndarray of bool, shape (n,)
    """
    P, delta_max, gamma_max, x_ref = kin
    n = prims.shape[0]
    pieces = np.empty((n, steps + 1, 5))
    ok = np.empty(n, dtype=np.bool_)
    for j in range(n):
        pieces[j], ok[j] = rollout(x0, prims[j, 0], int(prims[j, 1]), prims[j, 2], steps, ds,
                                   (P, min(delta_max, prims[j, 3]), gamma_max, x_ref),
                                   outlines)
    return pieces, ok


@njit(cache=True)
def final_approach(x0, goal, ds, max_steps, kin, outlines, law):
    """KIN reversed onto the door's centre line until the rear reaches the face.

    The law is the reversing LQR of :mod:`artic.validation.docking.linear`
    (with :data:`~artic.validation.docking.linear.APPROACH_WEIGHTS`) on
    the semitrailer axle's errors and the road-wheel angle,
    ``ddelta/ds = -K (e_y2, psi_2, gamma, delta)``, with the lateral error
    clipped to ``+-y_sat`` so that a large offset asks for a bounded heading
    rather than a jackknife, and the rate to :data:`STEER_RATE`.

    Parameters
    ----------
    x0 : ndarray, shape (5,)
        Start state ``[X, Y, psi_1, gamma, delta]``.
    goal : tuple
        ``(x_dock, y_dock, rear)``: the door's centre on its face [m] and the
        semitrailer's rear behind its kingpin [m].
    ds : float
        Step [m].
    max_steps : int
        Most steps before giving up.
    kin, outlines : tuple
        As :func:`rollout` takes them.
    law : tuple
        ``(K, y_sat, landing)``: the LQR's gains, the clip of the lateral error [m]
        and the landing tolerances.

    Returns
    -------
    states : ndarray, shape (n, 5)
        States up to the face, each with the road-wheel angle held over the
        step that reached it (``x0``'s own first).
    ok : bool
        Whether it landed (``landing``: lateral [m], heading and articulation
        [rad]) without a collision or passing the limits.
    """
    x_dock, y_dock, rear = goal
    P, delta_max, gamma_max, x_ref = kin
    tractor_box, trailer_box, boxes = outlines
    K, y_sat, landing = law
    out = np.empty((max_steps + 1, 5))
    x = x0[:4].copy()
    delta = max(-delta_max, min(delta_max, x0[4]))  # turned back at standstill
    t = np.empty((1, 3))
    k = np.empty((1, 3))
    for i in range(max_steps + 1):
        out[i, :4] = x
        out[i, 4] = delta
        tp, kp = _poses(x, P, x_ref)
        psi_2 = kp[2]
        c2, s2 = math.cos(psi_2), math.sin(psi_2)
        if abs(x[3]) > gamma_max or c2 < 0.5:
            return out[:i + 1], False
        t[0] = tp
        k[0] = kp
        if first_hit(t, k, tractor_box, trailer_box, boxes)[0] >= 0:
            return out[:i + 1], False
        x_rear = kp[0] - rear * c2
        if x_rear <= x_dock + 1e-4:
            y_rear = kp[1] - rear * s2
            ok = (abs(y_rear - y_dock) <= landing[0] and abs(psi_2) <= landing[1]
                  and abs(x[3]) <= landing[2])
            return out[:i + 1], ok
        if i < max_steps:
            e = max(-y_sat, min(y_sat, kp[1] - P[2] * s2 - y_dock))
            rate = -(K[0] * e + K[1] * psi_2 + K[2] * x[3] + K[3] * delta)
            rate = max(-STEER_RATE, min(STEER_RATE, rate))
            # The last step lands the rear on the face: shorten it.
            step = min(ds, (x_rear - x_dock) / c2 + 1e-6)
            delta = max(-delta_max, min(delta_max, delta + step * rate))
            x = rk4_step(KIN, x, step, -1.0, 0.0, delta, P)
    return out, False


# ---------------------------------------------------------------- heuristic
@functools.lru_cache(maxsize=64)
def _distance_field(yard: Yard, half_width: float, goal: tuple[float, float],
                    cell: float = 0.5) -> tuple[np.ndarray, float, float, float]:
    """Shortest distance from every yard cell to ``goal`` around the obstacles [m].

    Obstacles are grown by ``half_width``; 8-connected grid, Dijkstra.
    Returns the field (``inf`` where blocked or cut off), its origin and cell.
    """
    x0, x1, y0, y1 = yard.bounds
    nx, ny = int((x1 - x0) / cell) + 1, int((y1 - y0) / cell) + 1
    xs = x0 + (np.arange(nx) + 0.5) * cell
    ys = y0 + (np.arange(ny) + 0.5) * cell
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    free = np.ones((nx, ny), dtype=bool)
    for b in yard.obstacles:
        free &= ~((X > b.x_min - half_width) & (X < b.x_max + half_width)
                  & (Y > b.y_min - half_width) & (Y < b.y_max + half_width))
    gi = min(max(int((goal[0] - x0) / cell), 0), nx - 1)
    gj = min(max(int((goal[1] - y0) / cell), 0), ny - 1)
    free[gi, gj] = True
    idx = np.arange(nx * ny).reshape(nx, ny)
    rows, cols, w = [], [], []
    for di, dj in ((1, 0), (0, 1), (1, 1), (1, -1)):
        src = (slice(0, nx - di), slice(max(0, -dj), ny - max(0, dj)))
        dst = (slice(di, nx), slice(max(0, dj), ny - max(0, -dj)))
        both = free[src] & free[dst]
        ia, ib = idx[src][both], idx[dst][both]
        rows += [ia, ib]
        cols += [ib, ia]
        w += [np.full(2 * ia.size, cell * math.hypot(di, dj))]
    g = coo_matrix((np.concatenate(w), (np.concatenate(rows), np.concatenate(cols))),
                   shape=(nx * ny, nx * ny)).tocsr()
    dist = dijkstra(g, indices=int(idx[gi, gj])).reshape(nx, ny)
    return dist, x0, y0, cell


@dataclass
class _Node:
    """A state the search reached: its cost, direction, and the piece of path from its parent."""

    g: float
    state: np.ndarray = field(repr=False)
    direction: int
    parent: _Node | None = field(repr=False)
    piece: np.ndarray | None = field(repr=False)


@dataclass
class HybridAStar:
    """Hybrid A* over KIN with a closed-loop final approach (see the module docstring).

    Parameters
    ----------
    max_expansions : int
        Nodes expanded before :class:`PlanningError`.
    margin : float
        Clearance kept from parked semitrailers and the yard's edge [m].
    """

    max_expansions: int = MAX_EXPANSIONS
    margin: float = MARGIN

    def obstacles(self, yard: Yard) -> np.ndarray:
        """The yard's obstacles grown by the margin (the dock's face not: the rear reaches it)."""
        m = self.margin
        grown = []
        for b in yard.obstacles:
            if b.name == "dock":
                grown.append(b)
            else:
                grown.append(Box(b.name, b.x_min - m, b.x_max + m, b.y_min - m, b.y_max + m))
        return box_array(tuple(grown))

    def plan(self, yard: Yard, vehicle: Vehicle, start: Start) -> Plan:
        """A path from ``start`` to the dock.

        Raises
        ------
        PlanningError
            When the start collides, or no path was found within ``max_expansions``.
        """
        fr = Frames.of(vehicle)
        P = fr.P
        boxes = self.obstacles(yard)
        dmax = STEER_SHARE * vehicle.steering.delta_max
        kin = (P, dmax, GAMMA_PLAN, fr.x_ref)
        outlines = (fr.tractor_box, fr.trailer_box, boxes)
        x0 = np.r_[fr.kin_from_rear(start.x_r, start.y_r, start.psi_2, start.gamma), 0.0]
        if abs(start.gamma) > GAMMA_PLAN:
            raise PlanningError(f"the start's articulation {math.degrees(start.gamma):.1f} deg "
                                f"is beyond the planner's {math.degrees(GAMMA_PLAN):.0f} deg")
        t0, k0 = fr.unit_poses_of_kin(x0[:4])
        if first_hit(t0, k0, fr.tractor_box, fr.trailer_box, boxes)[0] >= 0:
            raise PlanningError("the start's outline overlaps an obstacle")
        goal_axle = (yard.x_dock + fr.rear + APPROACH - fr.kin.params.L2, yard.y_dock)
        field_, gx0, gy0, gcell = _distance_field(yard, float(fr.trailer_box[2]), goal_axle)
        nx, ny = field_.shape
        largest = float(np.max(field_[np.isfinite(field_)]))

        L1c_eq, L2 = fr.kin.params.L1c, fr.kin.params.L2

        def h(x: np.ndarray) -> float:
            psi_2 = float(x[2] - x[3])
            ax = (float(x[0]) + L1c_eq * math.cos(x[2]) - L2 * math.cos(psi_2),
                  float(x[1]) + L1c_eq * math.sin(x[2]) - L2 * math.sin(psi_2))
            i = min(max(int((ax[0] - gx0) / gcell), 0), nx - 1)
            j = min(max(int((ax[1] - gy0) / gcell), 0), ny - 1)
            d = field_[i, j]
            if not np.isfinite(d):
                d = largest + math.hypot(ax[0] - goal_axle[0], ax[1] - goal_axle[1])
            return float(d) + HEADING_COST * abs(math.remainder(psi_2, 2.0 * math.pi))

        fractions = (-1.0, -0.5, 0.0, 0.5, 1.0)
        d_rev = REVERSE_STEER_SHARE * vehicle.steering.delta_max
        prims = np.array([(1.0, 0, f * dmax, dmax) for f in fractions]
                         + [(-1.0, 1, f * GAMMA_PLAN, d_rev) for f in fractions])
        steps = round(PRIMITIVE_LENGTH / STEP)
        max_steps = round(MAX_APPROACH / STEP)
        fa = ((yard.x_dock, yard.y_dock, fr.rear), STEP, max_steps,
              (P, REVERSE_STEER_SHARE * vehicle.steering.delta_max, GAMMA_PLAN, fr.x_ref),
              outlines, (gains(fr.kin, -1, STEP, APPROACH_WEIGHTS), Y_SAT, np.array(LANDING)))
        order = 0
        heap = [(WEIGHT * h(x0), order, _Node(0.0, x0, 0, None, None))]
        closed: set[tuple] = set()
        expansions = 0
        while heap and expansions < self.max_expansions:
            node = heapq.heappop(heap)[2]
            key = (round(node.state[0] / CELL[0]), round(node.state[1] / CELL[0]),
                   round(math.remainder(float(node.state[2]), 2 * math.pi) / CELL[1]),
                   round(node.state[3] / CELL[2]), node.direction)
            if key in closed:
                continue
            closed.add(key)
            expansions += 1
            ax = fr.trailer_axle(node.state[:4])
            if (math.cos(ax[2]) > 0.7 and abs(ax[1] - yard.y_dock) < 3.0 * Y_SAT
                    and abs(node.state[3]) < APPROACH_GAMMA):
                approach, ok = final_approach(node.state, *fa)
                if ok:
                    return Plan(self._segments(node, approach), expansions)
            pieces, oks = expand(node.state, prims, steps, STEP, kin, outlines)
            for j in range(len(prims)):
                if not oks[j]:
                    continue
                d = int(prims[j, 0])
                g = node.g + PRIMITIVE_LENGTH + (CUSP_COST if node.direction not in (0, d)
                                                 else 0.0)
                x = pieces[j, -1].copy()
                order += 1
                heapq.heappush(heap, (g + WEIGHT * h(x), order, _Node(g, x, d, node, pieces[j])))
        raise PlanningError(f"no path to the dock within {expansions} expansions of the "
                            f"search (limit {self.max_expansions})")

    @staticmethod
    def _segments(node: _Node, approach: np.ndarray) -> tuple[Segment, ...]:
        """The path to ``node`` and the final approach, merged into segments by direction."""
        pieces: list[tuple[int, np.ndarray]] = [(-1, approach)]
        while node.parent is not None:
            pieces.append((node.direction, node.piece))
            node = node.parent
        pieces.reverse()
        segments: list[Segment] = []
        cur_dir, cur = pieces[0][0], [pieces[0][1]]
        for d, p in pieces[1:]:
            if d == cur_dir:
                cur.append(p[1:])
            else:
                segments.append(_segment(cur_dir, cur))
                cur_dir, cur = d, [p]
        segments.append(_segment(cur_dir, cur))
        return tuple(s for s in segments if len(s.states) > 1)


def _segment(direction: int, pieces: list[np.ndarray]) -> Segment:
    a = np.concatenate(pieces)
    return Segment(direction, a[:, :4].copy(), a[:, 4].copy())
