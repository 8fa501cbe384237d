"""The low-speed measures on cases with a closed-form answer.

Every expected value is computed here from the geometry of the case (the
book's formulas), sharing no code with :mod:`artic.validation.pbs`: the
motions are generated here, the measures only read them.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from artic.mjcf.vehicle import load_vehicle
from artic.validation.pbs import friction, offtracking, standards, sweep, swing
from artic.validation.pbs.motion import Motion
from artic.validation.pbs.paths import TurnPath
from artic.validation.pbs.sweep import swept

# A rigid single unit: rear axle at its frame's origin, the front at LF ahead,
# the tail E behind, half width W; its rear axle on a circle of radius RR.
RR, LF, E, W = 9.0, 5.2, 2.5, 1.275


def _rigid_points(theta: np.ndarray, local: np.ndarray | None = None) -> np.ndarray:
    """The unit's points (its outline at 1 cm by default), turning left about (0, RR), (N, M, 2).

    At ``theta = 0`` its rear axle is at the origin heading +x.
    """
    if local is None:
        xs = np.linspace(-E, LF, round((LF + E) / 0.01) + 1)
        ys = np.linspace(-W, W, round(2 * W / 0.01) + 1)
        local = np.vstack([np.c_[xs, np.full(xs.size, -W)], np.c_[xs, np.full(xs.size, W)],
                           np.c_[np.full(ys.size, -E), ys], np.c_[np.full(ys.size, LF), ys]])
    c, s = np.cos(theta)[:, None], np.sin(theta)[:, None]
    ax, ay = RR * np.sin(theta)[:, None], RR * (1.0 - np.cos(theta))[:, None]
    return np.stack([ax + c * local[:, 0] - s * local[:, 1],
                     ay + s * local[:, 0] + c * local[:, 1]], axis=-1)


def test_rigid_unit_swept_width_in_a_steady_turn():
    # Steady, every point turns about the centre: the swept annulus runs from
    # the inner side at the rear axle (RR - W) to the front outer corner,
    # sqrt((RR + W)^2 + LF^2). Mid-arc, every point of the body has passed.
    theta = np.linspace(0.0, 2.6, 2601)  # 1 mrad: the corner moves 1.5 cm a step
    path = TurnPath(0.0, RR, 2.6, 0.0, 1.0)
    sw = swept(path, _rigid_points(theta))
    expected = math.hypot(RR + W, LF) - (RR - W)
    mid = (sw.station > 0.4 * path.arc) & (sw.station < 0.6 * path.arc)
    # On a circle the envelope's radii are the extreme points' own, sampled at
    # the extreme points themselves (1 cm outline): exact to rounding.
    assert sw.width[mid] == pytest.approx(expected, abs=1e-9)
    # And the rigid unit's off-tracking: front axle centre radius less the rear's.
    front = np.c_[RR * np.sin(theta) + LF * np.cos(theta),
                  RR * (1 - np.cos(theta)) + LF * np.sin(theta)]
    rear = np.c_[RR * np.sin(theta), RR * (1 - np.cos(theta))]
    assert offtracking.steady_offtracking((0.0, RR), front, rear) == pytest.approx(
        math.hypot(RR, LF) - RR, abs=1e-9)


def test_swept_in_chunks_is_the_envelope_of_one_call():
    # The envelope is taken from the points' path coordinates computed a chunk
    # at a time (for memory); frenet is elementwise and max/min are exact, so
    # the envelope equals the one from a single frenet call to the bit, chunk
    # edges falling inside a sample's outline included.
    theta = np.linspace(0.0, 2.6, 301)
    path = TurnPath(0.0, RR, 2.6, 0.0, 1.0)
    points = _rigid_points(theta)
    assert points.reshape(-1, 2).shape[0] > 3 * sweep.CHUNK  # several chunks
    sw = swept(path, points)
    p = points.reshape(-1, 2)
    s, n = path.frenet(p[:, 0], p[:, 1])
    lo = np.floor(np.nanmin(s) / sweep.BIN)
    k = (np.floor(s / sweep.BIN) - lo).astype(np.int64)
    outer, inner = np.full(k.max() + 1, -np.inf), np.full(k.max() + 1, np.inf)
    np.maximum.at(outer, k, n)
    np.minimum.at(inner, k, n)
    assert np.array_equal(sw.outer, outer) and np.array_equal(sw.inner, inner)


def test_rigid_unit_tail_swing_turning_about_a_point():
    # The rear outside corner (-E, -W) at distance rho = sqrt(E^2 + (RR + W)^2)
    # from the centre dips to y = RR - rho from y = -W: the tail swing is
    # rho - (RR + W), the book's formula for a body turning about a point.
    theta = np.linspace(0.0, math.pi / 2, 200_001)
    corner = _rigid_points(theta, np.array([[-E, -W]]))[:, 0]
    expected = math.hypot(E, RR + W) - (RR + W)
    # Sampled at 7.9 micro-rad: the minimum is missed by at most rho dtheta^2 / 8 < 1e-9 m.
    assert swing.tail_swing_of(corner, 1.0) == pytest.approx(expected, abs=1e-9)
    mirrored = corner * np.array([1.0, -1.0])  # the same turn to the right
    assert swing.tail_swing_of(mirrored, -1.0) == pytest.approx(expected, abs=1e-9)


def _kinematic_circle(v, R: float, distance: float, ds: float = 0.02):
    """A no-slip tractor-semitrailer whose steer axle runs on a circle of radius R about (0, 0).

    The tractor turns about the centre with its drive axle on radius
    sqrt(R^2 - L1^2); the semitrailer's axle (L2 behind the kingpin) moves along
    its own heading (a tractrix), integrated here by RK4 over the kingpin's path.
    Starts straight (articulation 0). Returns the signal columns (t, x_1, y_1,
    psi_1, psi_2).
    """
    L1 = max(a.x for a in v.tractor_axles)
    L1c, L2 = v.L1c, v.L2
    R1 = math.sqrt(R * R - L1 * L1)
    sx, sy = v.sensor1[0], v.sensor1[1]
    n = int(distance / ds)
    phi = np.arange(n + 1) * ds / R1  # the drive axle's angle round the centre

    def dpsi2(p, psi2):
        # Trailer yaw rate per unit drive-axle angle: the kingpin's velocity across
        # the trailer over L2. The drive axle at angle p round the origin (radius
        # R1), heading h = p + pi/2; the kingpin L1c ahead; its velocity d/dp.
        h = p + math.pi / 2
        vx = -R1 * math.sin(p) - L1c * math.sin(h)
        vy = R1 * math.cos(p) + L1c * math.cos(h)
        return (-math.sin(psi2) * vx + math.cos(psi2) * vy) / L2

    psi2 = np.empty(n + 1)
    psi2[0] = math.pi / 2
    h = ds / R1
    for k in range(n):
        p, y = phi[k], psi2[k]
        k1 = dpsi2(p, y)
        k2 = dpsi2(p + h / 2, y + h / 2 * k1)
        k3 = dpsi2(p + h / 2, y + h / 2 * k2)
        k4 = dpsi2(p + h, y + h * k3)
        psi2[k + 1] = y + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    psi1 = phi + math.pi / 2
    ax, ay = R1 * np.cos(phi), R1 * np.sin(phi)
    x1 = ax + np.cos(psi1) * sx - np.sin(psi1) * sy
    y1 = ay + np.sin(psi1) * sx + np.cos(psi1) * sy
    return np.arange(n + 1) * 0.01, x1, y1, psi1, psi2


def test_kinematic_steady_offtracking_is_j695s_formula():
    # SAE J695's steady off-tracking of a no-slip combination: the sum over the
    # units of R^2 - L^2 terms, each unit's rear radius from its front's:
    # R_drive^2 = R^2 - L1^2, R_kingpin^2 = R_drive^2 + L1c^2 (the fifth wheel
    # ahead of the drive axle), R_trailer^2 = R_kingpin^2 - L2^2.
    v = load_vehicle("gosar2022-loaded")
    L1 = max(a.x for a in v.tractor_axles)
    R = standards.J695_RADIUS
    expected = R - math.sqrt(R * R - L1 * L1 + v.L1c ** 2 - v.L2 ** 2)
    t, x1, y1, psi1, psi2 = _kinematic_circle(v, R, 300.0)
    m = Motion.from_signals(v, t, x1, y1, psi1, psi2)
    # 300 m of drive-axle travel is 30 semitrailer wheelbases: the start's transient
    # has decayed to e**-30 of itself; RK4 at 2 cm errs by ~1e-12 per step.
    got = offtracking.steady_offtracking((0.0, 0.0), m.steer_axle, m.trailer_axle)
    assert got == pytest.approx(expected, abs=1e-6)
    # The steer axle is where the test put it: on the circle.
    assert np.hypot(*m.steer_axle.T) == pytest.approx(R, abs=1e-9)


def test_frenet_offsets_are_radial_on_the_arc_and_lateral_on_the_straights():
    for side in (1.0, -1.0):
        p = TurnPath(10.0, 12.0, math.pi / 2, 20.0, side)
        s = np.linspace(0.0, p.length, 50)
        x, y, h = p.pose(s)
        for off in (-1.5, 0.0, 2.0):
            s2, n2 = p.frenet(x - off * np.sin(h), y + off * np.cos(h))
            assert s2 == pytest.approx(s, abs=1e-9)
            assert n2 == pytest.approx(np.full(s.size, off), abs=1e-9)


def test_friction_demand_is_the_force_ratio_over_the_road_friction():
    # Two steer wheels, each 20 kN load, 6 kN lateral and 2 kN longitudinal:
    # |F| / Fz = sqrt(12^2 + 4^2) / 40 of the axle, over 0.8.
    f = np.zeros((3, 2, 3))
    f[1, :, :] = [2e3, 6e3, 20e3]
    f[[0, 2], :, 2] = 20e3
    expected = 100.0 * math.hypot(12e3, 4e3) / 40e3 / 0.8
    assert friction.friction_demand(f) == pytest.approx(expected, rel=1e-12)


def test_levels_are_the_best_limit_met():
    assert standards.level("swept_width", 7.4) == "1"
    assert standards.level("swept_width", 7.41) == "2"
    assert standards.level("swept_width", 14.0) == "none"
    assert standards.level("tail_swing", 0.31) == "2"
    assert standards.level("fhwa_offtracking", 1.0) == ""
    assert standards.level("steer_friction", float("nan")) == ""


def test_a_vehicle_without_a_tyre_file_has_its_steer_edge_at_the_track():
    # The scale-model preset is for KIN alone and names no tyre file: the steer
    # tyre's edge is its track's half, and with a file it lies half the WIDTH outside.
    from artic.validation.pbs.motion import Geometry

    scale = load_vehicle("scale-model-1to14")
    assert not scale.tyre_file
    front = max(scale.tractor_axles, key=lambda a: a.x)
    assert Geometry.of(scale).steer_edge == pytest.approx(0.5 * front.track, abs=1e-12)
    truck = load_vehicle("gosar2022-loaded")
    front = max(truck.tractor_axles, key=lambda a: a.x)
    assert Geometry.of(truck).steer_edge > 0.5 * front.track + 0.1  # a 315 mm truck tyre
