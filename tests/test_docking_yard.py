"""The docking yard: scenarios, their seeded starts, poses and the collision test."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from artic.mjcf import load_vehicle
from artic.mjcf.interface import OBS_INDEX, InitialState
from artic.mjcf.outline import (
    APRON_DEPTH,
    BUMPER_TRAVEL,
    DOCK_FACE,
    DOOR_PITCH,
    outline,
)
from artic.reduced import KIN, Driven
from artic.validation.docking.geometry import Box, Frames, box_array, first_hit, swept_cells
from artic.validation.docking.scenarios import SCENARIOS, make_yard, scenario
from tests.helpers import PRESETS


def test_the_starts_are_seeded_and_the_same_for_every_vehicle():
    s = scenario("alley")
    assert s.start(3) == s.start(3)
    assert s.start(3) != s.start(4)
    # Another scenario draws other numbers from the same seed.
    assert scenario("bay").start(3) != scenario("straight").start(3)


@pytest.mark.parametrize("name", list(SCENARIOS))
def test_each_start_lies_in_its_distribution(name):
    s = SCENARIOS[name]
    x_d, y_d = DOCK_FACE
    for seed in range(20):
        st = s.start(seed)
        assert s.distance[0] <= st.x_r - x_d <= s.distance[1]
        assert abs(st.gamma) <= math.radians(s.gamma_deg)
        if s.across:
            assert abs(abs(st.psi_2) - math.pi / 2) <= math.radians(s.heading_deg)
            # The rear stands past the door in the direction the tractor points.
            assert (st.y_r - y_d) * math.sin(st.psi_2) >= s.lateral[0] - 1e-9
        else:
            assert abs(st.psi_2) <= math.radians(s.heading_deg)
            doors = round((st.y_r - y_d) / DOOR_PITCH)
            assert abs(doors) in s.doors_over


@pytest.mark.parametrize("preset", PRESETS)
@pytest.mark.parametrize("name", list(SCENARIOS))
def test_every_start_is_clear_of_the_obstacles(name, preset):
    v = load_vehicle(preset)
    s = SCENARIOS[name]
    fr = Frames.of(v)
    boxes = box_array(s.yard(v).obstacles)
    for seed in range(20):
        st = s.start(seed)
        t, k = fr.unit_poses_of_kin(fr.kin_from_rear(st.x_r, st.y_r, st.psi_2, st.gamma))
        assert first_hit(t, k, fr.tractor_box, fr.trailer_box, boxes)[0] == -1, (name, seed)


def test_the_parked_semitrailers_are_the_outline_of_the_combinations_own(unloaded):
    o = outline(unloaded)
    yard = make_yard(unloaded, (-1, 1))
    left, right = sorted(yard.parked, key=lambda b: b.y_min)
    for b in (left, right):
        assert b.x_max - b.x_min == pytest.approx(o.trailer_front - o.trailer_rear)
        assert b.y_max - b.y_min == pytest.approx(o.width)
        assert b.x_min == DOCK_FACE[0]  # rear against the bumpers
    # The gap between them is two door pitches less one body.
    assert right.y_min - left.y_max == pytest.approx(2 * DOOR_PITCH - o.width)
    dock = next(b for b in yard.obstacles if b.name == "dock")
    assert dock.x_max == pytest.approx(DOCK_FACE[0] - BUMPER_TRAVEL)
    edge = next(b for b in yard.obstacles if b.name == "yard-edge")
    assert edge.x_min == pytest.approx(DOCK_FACE[0] + APRON_DEPTH)
    with pytest.raises(ValueError, match="target door"):
        make_yard(unloaded, (0,))


def test_an_unknown_scenario_names_the_known_ones():
    with pytest.raises(ValueError, match="straight, alley, offset, bay"):
        scenario("parallel")


# ---------------------------------------------------------------- poses
@pytest.mark.parametrize("preset", PRESETS)
def test_the_rear_pose_and_kin_state_round_trip(preset):
    fr = Frames.of(load_vehicle(preset))
    x = fr.kin_from_rear(3.0, -2.0, 0.4, -0.3)
    assert fr.rear_of_kin(x) == pytest.approx([3.0, -2.0, 0.4])
    assert x[2] - x[3] == pytest.approx(0.4)


@pytest.mark.parametrize("preset", PRESETS)
def test_poses_from_the_signals_are_the_models_own(preset):
    """KIN's signals at its sensors give back its state, its rear and its axle."""
    v = load_vehicle(preset)
    fr = Frames.of(v)
    kin = Driven(KIN(v))
    kin.reset(InitialState(12.0, -3.0, 0.7, 0.35, u1=-1.0))
    for _ in range(100):
        kin.step(0.01, 0.2, -1.0, 0.0)
    obs = kin.observe()
    x = kin.x
    assert fr.kin_of_signals(obs) == pytest.approx(x, abs=1e-9)
    assert fr.rear_of_signals(obs) == pytest.approx(fr.rear_of_kin(x), abs=1e-9)
    assert fr.trailer_axle_of_signals(obs) == pytest.approx(fr.trailer_axle(x), abs=1e-9)
    t1, k1 = fr.unit_poses_of_signals(obs)
    t2, k2 = fr.unit_poses_of_kin(x)
    assert t1 == pytest.approx(t2, abs=1e-9) and k1 == pytest.approx(k2, abs=1e-9)
    assert fr.tractor_sensor_of_kin(x) == pytest.approx(obs[:2], abs=1e-9)



def _numpy_poses(fr, obs):
    """Unit poses as numpy's element-wise operations give them (the first form)."""
    obs = np.atleast_2d(obs)
    out = []
    for i, s in ((1, fr.s1), (2, fr.s2)):
        psi = obs[:, OBS_INDEX[f"psi_{i}"]] - fr.sensor_yaw[i - 1]
        c, sn = np.cos(psi), np.sin(psi)
        out.append(np.column_stack([obs[:, OBS_INDEX[f"x_{i}"]] - (c * s[0] - sn * s[1]),
                                    obs[:, OBS_INDEX[f"y_{i}"]] - (sn * s[0] + c * s[1]),
                                    psi]))
    return out


def test_the_poses_of_signals_are_numpys_to_the_bit():
    # The compiled poses (the run's collision test) and the scalar ones of one set of
    # signals (the dock errors, every observation) are numpy's, so no run's numbers move:
    # the same operations in the same order, and the C library's sine and cosine.
    v = load_vehicle("gosar2022-loaded")
    fr = Frames.of(v)
    mounted = dataclasses.replace(fr, sensor_yaw=(0.013, -0.021), s1=np.array([0.3, -0.1]),
                                  s2=np.array([-1.2, 0.05]))
    rng = np.random.default_rng(11)
    obs = rng.uniform(-80.0, 80.0, (20_000, 13))
    obs[:, [OBS_INDEX["psi_1"], OBS_INDEX["psi_2"]]] = rng.uniform(-20.0, 20.0, (20_000, 2))
    for f in (fr, mounted):
        for rows in (obs, obs[::3]):  # contiguous and strided
            got, want = f.unit_poses_of_signals(rows), _numpy_poses(f, rows)
            assert got[0].tobytes() == want[0].tobytes()
            assert got[1].tobytes() == want[1].tobytes()
        # The run's collision test of a sample's poses, in one call: first_hit's answer.
        boxes = box_array((Box("a", 10.0, 30.0, -5.0, 5.0), Box("b", -40.0, -20.0, 0.0, 9.0)))
        for start in range(0, 2000, 10):
            rows = obs[start:start + 10]
            assert f.first_hit_of_signals(rows, boxes) == first_hit(
                *_numpy_poses(f, rows), f.tractor_box, f.trailer_box, boxes)
        tractor, trailer = _numpy_poses(f, obs[:2000])
        for row, (x1, y1, psi_1), (xk, yk, psi_2) in zip(obs, tractor, trailer, strict=False):
            assert f.rear_of_signals(row).tolist() == [
                xk - f.rear * math.cos(psi_2), yk - f.rear * math.sin(psi_2), psi_2]
            L2 = f.kin.params.L2
            assert f.trailer_axle_of_signals(row).tolist() == [
                xk - L2 * math.cos(psi_2), yk - L2 * math.sin(psi_2), psi_2]
            assert f.kin_of_signals(row).tolist() == [
                x1 + f.x_ref * math.cos(psi_1), y1 + f.x_ref * math.sin(psi_1), psi_1,
                row[OBS_INDEX["gamma"]]]


# ---------------------------------------------------------------- collisions
def _one(x, y, psi):
    return np.array([[x, y, psi]])


def test_a_box_touching_an_obstacle_hits_it_and_one_clear_of_it_does_not():
    unit = np.array([0.0, 2.0, 1.0])  # centred on its origin, 4 m x 2 m
    far = np.array([[100.0, 100.0, 0.0]])
    wall = box_array((Box("wall", 3.0, 4.0, -10.0, 10.0),))
    # Straight: the front at x + 2; it reaches the wall at x = 1.
    assert first_hit(_one(0.9, 0, 0), far, unit, unit, wall)[0] == -1
    assert first_hit(_one(1.1, 0, 0), far, unit, unit, wall) == (0, 0, 0)
    # Turned 90 deg, the unit's half length lies along y: the wall is 2 m off.
    assert first_hit(_one(1.9, 0, math.pi / 2), far, unit, unit, wall)[0] == -1
    assert first_hit(_one(2.1, 0, math.pi / 2), far, unit, unit, wall)[0] == 0
    # At 45 deg its extent along x is 2 cos 45 + 1 sin 45.
    reach = 2.0 * math.cos(math.pi / 4) + 1.0 * math.sin(math.pi / 4)
    assert first_hit(_one(3.0 - reach - 0.01, 0, math.pi / 4), far, unit, unit, wall)[0] == -1
    assert first_hit(_one(3.0 - reach + 0.01, 0, math.pi / 4), far, unit, unit, wall)[0] == 0


def test_a_corner_that_misses_a_corner_is_not_a_hit():
    """Overlapping extents along x and y, but separated along the unit's diagonal axis."""
    unit = np.array([0.0, 1.0, 1.0])
    far = np.array([[100.0, 100.0, 0.0]])
    box = box_array((Box("post", 1.0, 2.0, 1.0, 2.0),))
    # A 2 x 2 square turned 45 deg: its x and y extents overlap the post's before it does.
    assert first_hit(_one(-0.2, -0.2, math.pi / 4), far, unit, unit, box)[0] == -1
    assert first_hit(_one(0.6, 0.6, math.pi / 4), far, unit, unit, box)[0] == 0


def test_the_first_sample_and_the_unit_that_hit_are_reported():
    unit = np.array([0.0, 2.0, 1.0])
    wall = box_array((Box("a", 50.0, 51.0, -1.0, 1.0), Box("b", -5.0, -4.0, -1.0, 1.0)))
    tractor = np.array([[0.0, 0.0, 0.0]] * 3)
    trailer = np.array([[0.0, 0.0, 0.0], [-2.5, 0.0, 0.0], [-3.0, 0.0, 0.0]])  # rear at -4.5
    assert first_hit(tractor, trailer, unit, unit, wall) == (1, 1, 1)


def test_the_swept_cells_of_a_still_box_are_its_area():
    unit = np.array([1.0, 2.0, 0.5])  # 4 m x 1 m, centre 1 m ahead of the origin
    poses = np.array([[0.0, 0.0, 0.3]])
    grid = swept_cells(poses, poses, unit, unit, -10.0, -10.0, 0.05, 400, 400)
    assert grid.sum() * 0.05 ** 2 == pytest.approx(4.0, rel=0.02)
