"""One outline per unit: the plant's bodies, the docking driver and the drawings agree."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from artic.mjcf import load_vehicle, naming
from artic.mjcf.builder import build_model
from artic.mjcf.outline import DOCK_DEPTH, DOCK_FACE, outline
from tests.helpers import PRESETS


@pytest.mark.parametrize("preset", PRESETS)
def test_the_sensor_and_every_axle_lie_inside_the_trailer(preset):
    v = load_vehicle(preset)
    o = outline(v)
    assert o.trailer_rear < v.sensor2[0] < o.trailer_front
    assert o.rear_behind_kingpin > max(v.trailer_axle_distances)
    assert o.tractor_rear < min(a.x for a in v.tractor_axles)
    assert o.tractor_front > max(a.x for a in v.tractor_axles)


def test_the_plant_draws_the_outline_and_the_dock(unloaded):
    o = outline(unloaded)
    m = build_model(unloaded).compile()
    trailer = m.body(naming.TRAILER).id
    boxes = [g for g in range(m.ngeom) if m.geom_bodyid[g] == trailer
             and m.geom_type[g] == mujoco.mjtGeom.mjGEOM_BOX]
    assert len(boxes) == 1
    g = boxes[0]
    front = m.geom_pos[g][0] + m.geom_size[g][0]
    rear = m.geom_pos[g][0] - m.geom_size[g][0]
    assert front == pytest.approx(o.trailer_front) and rear == pytest.approx(o.trailer_rear)
    dock = m.body(naming.DOCK).id
    (dg,) = [g for g in range(m.ngeom) if m.geom_bodyid[g] == dock]
    face = m.body_pos[dock][0] + m.geom_pos[dg][0] + m.geom_size[dg][0]
    assert face == pytest.approx(DOCK_FACE[0])
    assert 2 * m.geom_size[dg][0] == pytest.approx(DOCK_DEPTH)


def test_the_driver_backs_the_outline_rear_to_the_dock(unloaded):
    from artic.validation.synthetic.driver import DockingDriver

    d = DockingDriver(unloaded)
    assert d.rear == pytest.approx(outline(unloaded).rear_behind_kingpin)
    assert (d.x_dock, d.y_dock) == DOCK_FACE
    # Straight, gamma = 0, tractor sensor at x: the rear lies at the kingpin minus the rear.
    obs = np.zeros(13)
    obs[0] = 50.0
    x, _ = d.rear_point(obs)
    kingpin = 50.0 - (unloaded.sensor1[0] - unloaded.L1c)
    assert x == pytest.approx(kingpin - outline(unloaded).rear_behind_kingpin)


def test_the_recording_draws_the_outline(unloaded):
    from artic.validation.review.recording import _Geometry

    g, o = _Geometry(unloaded), outline(unloaded)
    cx, hx, _ = g.trailer_body
    assert cx - hx == pytest.approx(o.trailer_rear) and cx + hx == pytest.approx(o.trailer_front)
