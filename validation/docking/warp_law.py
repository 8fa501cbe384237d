"""The reference docking controller's law as Warp functions, one thread per world.

:class:`~artic.validation.docking.controllers.reference.ReferenceController`'s
``command`` (without what it intends, ``Command.horizon`` and ``reference``, which
only the recording draws), written again for the device in float64: the nearest
sample of the current segment's path in the window behind and ahead of the last,
the tracking errors ``z``, the LQR gains interpolated at the measured speed, the
path's steering ahead plus ``-|u| dt K z``, the wheel turned at the actuator's rate,
the speed profile with its stop at a cusp or at the dock face, and the wait at a
cusp while the wheel turns to the next segment's angle at standstill.

Everything the host's controller computes in ``reset`` (each segment's path of the
tracked point, its articulation, steering and distance; the gain tables) is packed
per world by :func:`artic.validation.docking.warp_dock.prepare` into :class:`Paths`,
:class:`Gains` and the constants' columns below.
"""

from __future__ import annotations

import warp as wp

from artic.validation.docking.controllers import reference

f64 = wp.float64

_PI = wp.constant(wp.float64(3.14159265358979323846))
_BEHIND = wp.constant(reference.WINDOW[0])
_AHEAD = wp.constant(reference.WINDOW[1])
_CREEP = wp.constant(wp.float64(reference.CREEP))
_STANDSTILL = wp.constant(wp.float64(reference.STANDSTILL))
_MIN_SPEED = wp.constant(wp.float64(reference.MIN_SPEED))

# Columns of the law's per-world constants (Law.consts), the controller's vehicle file's.
S2X, S2Y, YAW2, S1X, S1Y, YAW1, X_REF, L2, REAR, HALF_WIDTH, X_DOCK, I_S, Q, OFFSET, \
    DELTA_MAX, DELTA_RATE, SPEED, ACCEL, DT = range(19)
N_CONSTS = 19

# Columns of a path sample (Paths.rows).
PX, PY, PPSI, PGAMMA, PDELTA, PS = range(6)


@wp.struct
class Paths:
    """Every world's plan: segment ``g`` of world ``w`` is rows ``first[w, g]`` on, ``count[w, g]``.

    ``rows``: the tracked point ``(x, y, psi)`` (the semitrailer axle reversing, the
    tractor's point forward) [m, rad], the path's articulation and road-wheel angle
    [rad] and its distance [m]; ``direction`` -1 or +1, ``segments`` per world.
    """

    first: wp.array2d(dtype=int)
    count: wp.array2d(dtype=int)
    direction: wp.array2d(dtype=int)
    segments: wp.array(dtype=int)
    rows: wp.array2d(dtype=wp.float64)


@wp.struct
class Gains:
    """The gain schedules: ``speeds`` [m/s], per world ``reverse`` (n, 4) and ``forward`` (n, 3)."""

    speeds: wp.array(dtype=wp.float64)
    reverse: wp.array3d(dtype=wp.float64)
    forward: wp.array3d(dtype=wp.float64)


@wp.struct
class Law:
    """The law's inputs and its state per world.

    ``consts`` per world the columns above; the state: the segment, the last nearest
    sample, whether it waits at a cusp, the commanded road-wheel angle [rad] and
    whether that has been read from the wheel (1) yet.
    """

    paths: Paths
    gains: Gains
    consts: wp.array2d(dtype=wp.float64)
    segment: wp.array(dtype=int)
    nearest: wp.array(dtype=int)
    waiting: wp.array(dtype=int)
    delta: wp.array(dtype=wp.float64)
    started: wp.array(dtype=int)


@wp.func
def wrap_angle(a: wp.float64):
    """``artic.mjcf.interface.wrap_angle``: ``pi - mod(pi - a, 2 pi)`` [rad]."""
    x = _PI - a
    two = f64(2.0) * _PI
    return _PI - (x - two * wp.floor(x / two))


@wp.func
def clamp(x: wp.float64, lo: wp.float64, hi: wp.float64):
    """``min(max(x, lo), hi)``."""
    return wp.min(wp.max(x, lo), hi)


@wp.func
def path_at(rows: wp.array2d(dtype=wp.float64), first: int, n: int, col: int, x: wp.float64):
    """``numpy.interp(x, s, rows[:, col])`` over a segment's rows (held beyond its ends)."""
    if x <= rows[first, PS]:
        return rows[first, col]
    last = first + n - 1
    if x >= rows[last, PS]:
        return rows[last, col]
    lo = first
    hi = last
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if rows[mid, PS] <= x:
            lo = mid
        else:
            hi = mid
    a = rows[lo, PS]
    return rows[lo, col] + (x - a) * (rows[hi, col] - rows[lo, col]) / (rows[hi, PS] - a)


@wp.func
def gain_at(speeds: wp.array(dtype=wp.float64), table: wp.array3d(dtype=wp.float64), w: int,
            col: int, v: wp.float64):
    """``GainSchedule.__call__``'s column ``col`` at speed ``v`` [m/s] (held beyond the table)."""
    n = speeds.shape[0]
    if v <= speeds[0]:
        return table[w, 0, col]
    if v >= speeds[n - 1]:
        return table[w, n - 1, col]
    i = int(0)  # noqa: UP018 - Warp: a variable the loop may change, not a constant
    while speeds[i + 1] <= v:
        i = i + 1
    a = speeds[i]
    return table[w, i, col] + (v - a) * (table[w, i + 1, col] - table[w, i, col]) / (
        speeds[i + 1] - a)


@wp.func
def steering_wheel(c: wp.array2d(dtype=wp.float64), w: int, delta: wp.float64):
    """``Controller.steering_wheel``: eq. (3)'s inverse, within the lock [rad]."""
    d = c[w, DELTA_MAX]
    x = clamp(delta, -d, d) * c[w, I_S]
    q = c[w, Q]
    if q == f64(0.0):
        return x + c[w, OFFSET]
    disc = wp.max(f64(1.0) - f64(4.0) * q * x, f64(0.0))
    return f64(2.0) * x / (f64(1.0) + wp.sqrt(disc)) + c[w, OFFSET]


@wp.func
def road_wheel(i_s: wp.float64, q: wp.float64, offset: wp.float64, delta_h: wp.float64):
    """Eq. (3): the road-wheel angle of a steering-wheel angle [rad]."""
    d = delta_h - offset
    return (d - q * d * d) / i_s


@wp.func
def turn(law: Law, w: int, target: wp.float64):
    """``ReferenceController._turn``: the steering wheel of the angle moved towards ``target``."""
    c = law.consts
    step = c[w, DELTA_RATE] * c[w, DT]
    d = c[w, DELTA_MAX]
    law.delta[w] = clamp(law.delta[w] + clamp(target - law.delta[w], -step, step), -d, d)
    return steering_wheel(c, w, law.delta[w])


@wp.func
def unit_pose(c: wp.array2d(dtype=wp.float64), w: int, x: wp.float64, y: wp.float64,
              psi: wp.float64, trailer: int):
    """``Frames._pose_of_signals``: a unit's origin ``(x, y, psi)`` from its sensor's signals."""
    sx = c[w, S1X]
    sy = c[w, S1Y]
    yaw = c[w, YAW1]
    if trailer != 0:
        sx = c[w, S2X]
        sy = c[w, S2Y]
        yaw = c[w, YAW2]
    p = psi - yaw
    cs = wp.cos(p)
    sn = wp.sin(p)
    return wp.vec3d(x - (cs * sx - sn * sy), y - (sn * sx + cs * sy), p)


@wp.func
def tracked_point(c: wp.array2d(dtype=wp.float64), w: int, m: wp.array3d(dtype=wp.float64),
                  k: int, direction: int):
    """``ReferenceController._point``: the semitrailer axle reversing, else the tractor's point."""
    if direction < 0:
        p = unit_pose(c, w, m[w, k, 6], m[w, k, 7], m[w, k, 8], 1)
        return wp.vec3d(p[0] - c[w, L2] * wp.cos(p[2]), p[1] - c[w, L2] * wp.sin(p[2]), p[2])
    p = unit_pose(c, w, m[w, k, 0], m[w, k, 1], m[w, k, 2], 0)
    return wp.vec3d(p[0] + c[w, X_REF] * wp.cos(p[2]), p[1] + c[w, X_REF] * wp.sin(p[2]), p[2])


@wp.func
def remaining_to_face(c: wp.array2d(dtype=wp.float64), w: int, m: wp.array3d(dtype=wp.float64),
                      k: int):
    """The rear's distance to the dock face by its sensor, its nearer corner when askew [m]."""
    p = unit_pose(c, w, m[w, k, 6], m[w, k, 7], m[w, k, 8], 1)
    x_r = p[0] - c[w, REAR] * wp.cos(p[2])
    head = wrap_angle(p[2])
    return (x_r - c[w, X_DOCK]) - c[w, HALF_WIDTH] * wp.abs(wp.sin(head))


@wp.func
def command(law: Law, w: int, m: wp.array3d(dtype=wp.float64), k: int, delta_h: wp.float64):
    """``ReferenceController._follow`` at sample ``k`` of world ``w``, signals ``m[w, k]``.

    Returns the steering-wheel angle [rad], the speed [m/s] and whether it is done (1).
    """
    c = law.consts
    P = law.paths
    if law.started[w] == 0:  # start from where the wheel is
        law.delta[w] = road_wheel(c[w, I_S], c[w, Q], c[w, OFFSET], delta_h)
        law.started[w] = 1
    v_meas = wp.abs(m[w, k, 3])
    if law.waiting[w] != 0:
        g1 = law.segment[w] + 1
        d_next = P.rows[P.first[w, g1], PDELTA]
        if v_meas >= _STANDSTILL or wp.abs(law.delta[w] - d_next) > f64(1e-3):
            # Stop, and turn the wheel to the next segment's angle at standstill.
            return turn(law, w, d_next), f64(0.0), 0
        law.segment[w] = g1
        law.nearest[w] = 0
        law.waiting[w] = 0
    g = law.segment[w]
    first = P.first[w, g]
    n = P.count[w, g]
    d = P.direction[w, g]
    last = g == P.segments[w] - 1
    me = tracked_point(c, w, m, k, d)
    lo = wp.max(0, law.nearest[w] - _BEHIND)
    hi = wp.min(n, law.nearest[w] + _AHEAD)
    best = lo
    best_d2 = f64(1e300)
    for i in range(lo, hi):
        dx = P.rows[first + i, PX] - me[0]
        dy = P.rows[first + i, PY] - me[1]
        d2 = dx * dx + dy * dy
        if d2 < best_d2:
            best_d2 = d2
            best = i
    law.nearest[w] = best
    r = first + best
    psi_ref = P.rows[r, PPSI]
    cs = wp.cos(psi_ref)
    sn = wp.sin(psi_ref)
    dx = me[0] - P.rows[r, PX]
    dy = me[1] - P.rows[r, PY]
    e_y = -sn * dx + cs * dy
    # How far along the path: the offset from the nearest sample along its heading.
    here = P.rows[r, PS] + f64(d) * (cs * dx + sn * dy)
    e_psi = wrap_angle(me[2] - psi_ref)
    v = wp.max(v_meas, _MIN_SPEED)
    ds = v * c[w, DT]
    err = law.delta[w] - path_at(P.rows, first, n, PDELTA, here)
    G = law.gains
    if d < 0:
        e_gamma = m[w, k, 12] - path_at(P.rows, first, n, PGAMMA, here)
        kz = (gain_at(G.speeds, G.reverse, w, 0, v) * e_y
              + gain_at(G.speeds, G.reverse, w, 1, v) * e_psi
              + gain_at(G.speeds, G.reverse, w, 2, v) * e_gamma
              + gain_at(G.speeds, G.reverse, w, 3, v) * err)
    else:
        kz = (gain_at(G.speeds, G.forward, w, 0, v) * e_y
              + gain_at(G.speeds, G.forward, w, 1, v) * e_psi
              + gain_at(G.speeds, G.forward, w, 2, v) * err)
    # The path's own steering where the point will be after this sample, plus the correction.
    target = path_at(P.rows, first, n, PDELTA, here + ds) + err - ds * kz
    wheel = turn(law, w, target)
    remaining = P.rows[first + n - 1, PS] - here
    if last:
        remaining = remaining_to_face(c, w, m, k)
    a = f64(0.5) * c[w, ACCEL]
    speed = wp.min(c[w, SPEED], _CREEP + wp.sqrt(f64(2.0) * a * wp.max(remaining - f64(0.5),
                                                                         f64(0.0))))
    stop_at = v_meas * v_meas / (f64(2.0) * c[w, ACCEL]) + f64(0.5) * v_meas * c[w, DT]
    if remaining <= stop_at:
        if last:
            return wheel, f64(0.0), 1
        law.waiting[w] = 1
        return wheel, f64(0.0), 0
    return wheel, f64(d) * speed, 0
