"""The plant's optional effects ([plant], sensor yaw, tyre scaling), each with its sign checked.

Every option is off in the presets; each test turns one on and checks a
consequence whose sign (and roughly whose size) follows from statics or
kinematics, so that a flipped sign or a lost factor fails.
"""

from __future__ import annotations

import dataclasses
import math

import mujoco
import numpy as np
import pytest

from artic.mjcf import load_vehicle
from artic.mjcf.builder import gravity
from artic.mjcf.interface import InitialState
from artic.mjcf.vehicle import G, PlantOptions
from artic.plant import Plant


def with_options(v, **kw):
    return dataclasses.replace(v, plant=dataclasses.replace(v.plant, **kw))


def rest(p: Plant, seconds: float) -> None:
    """Let the plant run with every actuator at zero: no drive, no brake, no follower."""
    for _ in range(int(round(seconds / p.model.opt.timestep))):
        mujoco.mj_step(p.model, p.data)


def test_gravity_points_downhill():
    v = load_vehicle("gosar2022-unloaded")
    g = gravity(with_options(v, grade=0.05, crossfall=0.02))
    assert g[0] < 0 and g[1] < 0 and g[2] < 0  # +x and +y run uphill
    assert np.linalg.norm(g) == pytest.approx(G)
    assert g[0] == pytest.approx(-G * math.sin(0.05))
    assert gravity(v) == pytest.approx([0.0, 0.0, -G])


def test_on_a_grade_a_parked_truck_creeps_downhill_without_brakes_and_holds_with_them(unloaded):
    theta = 0.03  # a 3 % yard ramp
    v = with_options(unloaded, grade=theta)
    with Plant(v, speed="drive") as p:
        p.reset(InitialState(0.0, 0.0, 0.0, 0.0))
        x0 = p.observe()[0]
        rest(p, 4.0)
        free = p.observe()[0] - x0
        # Rolling free, the combination accelerates down the slope at most at
        # g sin(theta) scaled by its mass over its mass plus the wheels' spin
        # inertia, less rolling resistance (QSY1 g): between those bounds.
        t = 4.0
        upper = 0.5 * G * math.sin(theta) * p.mass / p.mass_eff * t ** 2
        lower = 0.5 * G * (math.sin(theta) - 2 * p.tyre.QSY1) * p.mass / p.mass_eff * t ** 2
        assert -upper * 1.05 < free < -lower * 0.8, (free, lower, upper)
        # Held by the parking brake, with every actuator still at zero.
        p.reset(InitialState(0.0, 0.0, 0.0, 0.0))
        p.parking_brake = True
        rest(p, 4.0)
        held = p.observe()[0] - x0
        p.parking_brake = False
        assert not p.parking_brake
    # What remains is the tyres' tread springs taking the slope's force.
    assert abs(held) < 0.01 * abs(free), (held, free)


@pytest.mark.long_on_numpy
def test_on_crossfall_the_truck_drifts_downhill(unloaded):
    phi = 0.03  # +y runs uphill
    v = with_options(unloaded, crossfall=phi)
    with Plant(v) as p:
        u = 5 / 3.6
        p.reset(InitialState(0.0, 0.0, 0.0, 0.0, u1=u))
        for _ in range(2000):
            p.step(0.01, 0.0, u, 0.0)
        y = p.observe()[1]
    with Plant(unloaded) as p:
        p.reset(InitialState(0.0, 0.0, 0.0, 0.0, u1=u))
        for _ in range(2000):
            p.step(0.01, 0.0, u, 0.0)
        y_level = p.observe()[1]
    # The tyres take the slope's side force m g sin(phi) with slip angles of
    # about phi / f (0.3 deg): over 28 m that is a drift of decimetres, downhill.
    assert y - y_level < -0.05


def _peak_articulation_rate(v) -> float:
    """Largest |gamma rate| [rad/s] after a 15 deg steer step at 10 km/h."""
    u = 10 / 3.6
    with Plant(v) as p:
        p.reset(InitialState(0.0, 0.0, 0.0, 0.0, u1=u))
        gamma = []
        for k in range(400):
            p.step(0.01, 0.0 if k < 50 else math.radians(15.0), u, 0.0)
            gamma.append(p.gamma)
    return float(np.abs(np.diff(gamma)).max() / 0.01)


@pytest.mark.long_on_numpy
@pytest.mark.parametrize("option", [{"fifth_wheel_friction": 3.0e4},
                                    {"hitch_damping": 1.0e5}])
def test_hitch_friction_and_damping_damp_an_articulation_transient(unloaded, option):
    # The tractor turns into the step and the trailer follows through the
    # kingpin. A torque that opposes the relative yaw rate drags the trailer
    # round with the tractor, so the articulation opens more slowly; a torque
    # with the wrong sign would speed it up. (Real fifth-wheel friction, about
    # 3 kN m, is small beside the trailer tyres' moments; these values are
    # large enough to see.)
    free = _peak_articulation_rate(unloaded)
    damped = _peak_articulation_rate(with_options(unloaded, **option))
    assert damped < 0.9 * free, (damped, free)
    twice = {k: 2 * val for k, val in option.items()}
    assert _peak_articulation_rate(with_options(unloaded, **twice)) < damped


def test_payload_offset_moves_load_forward_and_left(unloaded):
    dx, dy = 0.5, 0.2
    v = with_options(unloaded, payload_offset=(dx, dy, 0.0))
    with Plant(v) as p:
        rest(p, 0.0)
        p.reset(InitialState(0.0, 0.0, 0.0, 0.0))
        for _ in range(200):
            p.step(0.01, 0.0, 0.0, 0.0)
        loads = p.wheel_loads().reshape(-1, 2)  # per axle: left, right
    n_tr = len(unloaded.tractor_axles)
    trailer, tractor = loads[n_tr:], loads[:n_tr]
    # Statics of the semitrailer: moving its weight m2 g forward by dx moves
    # m2 g dx / L2 from its axle group onto the kingpin, that is, onto the tractor.
    shifted = unloaded.m2 * G * dx / unloaded.L2
    assert trailer.sum() == pytest.approx(unloaded.static_loads[n_tr:].sum() - shifted, rel=0.02)
    assert tractor.sum() == pytest.approx(unloaded.static_loads[:n_tr].sum() + shifted, rel=0.02)
    # Leftward offset: the left trailer wheels carry more.
    assert np.all(trailer[:, 0] > trailer[:, 1])


def test_with_payload_is_folded_once(unloaded):
    v = with_options(unloaded, payload_offset=(0.5, 0.1, 0.2), payload_yaw_inertia=5000.0)
    once = v.with_payload()
    assert once.a2 == pytest.approx(unloaded.a2 - 0.5)
    assert once.h2 == pytest.approx(unloaded.h2 + 0.2)
    assert once.J2 == pytest.approx(unloaded.J2 + 5000.0)
    assert once.with_payload() == once
    assert once.plant.payload_offset == (0.0, 0.1, 0.0)


def test_sensor_mounting_yaw_turns_heading_and_velocity_axes(unloaded):
    eps = math.radians(2.0)
    v = dataclasses.replace(unloaded, sensor1_yaw=eps)
    u = 2.0
    with Plant(v) as p:
        # What the units read when the combination heads straight along x.
        p.reset(InitialState(0.0, 0.0, eps, eps, v_y_1=-u * math.sin(eps), u1=u))
        assert p.data.xmat[p._tractor][3] == pytest.approx(0.0, abs=1e-12)  # the body: along x
        for _ in range(200):
            p.step(0.01, 0.0, u, 0.0)
        o = p.observe()
        gamma = p.gamma
    # Driving straight along x, a unit turned eps to the left reads heading
    # eps and sees the ground move to its right: v_y = -u sin(eps).
    assert o[2] == pytest.approx(eps, abs=1e-4)
    assert o[4] == pytest.approx(-u * math.sin(eps), rel=0.02)
    assert o[3] == pytest.approx(u * math.cos(eps), rel=0.01)
    # The articulation column is the two headings' difference, as a log has it,
    # and the articulation the harness feeds back is that one too.
    assert o[12] == pytest.approx(eps, abs=1e-3)
    assert gamma == pytest.approx(o[12], abs=1e-9)


def test_reset_places_the_bodies_so_the_units_read_the_initial_state(unloaded):
    # A log's first sample is what the units read; reset and observe are inverse.
    v = dataclasses.replace(unloaded, sensor1_yaw=math.radians(0.3),
                            sensor2_yaw=math.radians(-0.2))
    start = InitialState(3.0, -1.0, 0.4, 0.1, v_y_1=0.02, r_1=0.0, r_2=0.0, u1=1.5)
    with Plant(v) as p:
        p.reset(start)
        o = p.observe()
    assert o[0] == pytest.approx(start.x_1, abs=1e-9)
    assert o[1] == pytest.approx(start.y_1, abs=1e-9)
    assert o[2] == pytest.approx(start.psi_1, abs=1e-12)
    assert o[12] == pytest.approx(start.gamma, abs=1e-12)
    # The lateral velocity to within the rotation of u1 by the small yaw (u1 is
    # taken along the tractor).
    assert o[4] == pytest.approx(start.v_y_1, abs=2e-4)


def test_tyre_scaling_from_the_vehicle_file(unloaded):
    v = dataclasses.replace(unloaded, tyre_scaling=(("LKY", 1.2), ("LMUY", 0.9)))
    with Plant(unloaded) as a, Plant(v) as b:
        assert b.tyre.LKY == pytest.approx(1.2 * a.tyre.LKY)
        assert b.tyre.LMUY == pytest.approx(0.9 * a.tyre.LMUY)


def test_options_default_off(unloaded):
    assert unloaded.plant == PlantOptions()
    assert unloaded.sensor1_yaw == unloaded.sensor2_yaw == 0.0
    assert unloaded.tyre_scaling == ()


def test_island_discovery_is_off_and_changes_nothing(unloaded):
    # The builder disables MuJoCo's island discovery because PGS solves all
    # constraints as one system. With constraints active (the parking brake on
    # a grade, dry friction in the fifth wheel, the tie rod), the steps with
    # and without it must agree to the bit; a solver that used the islands
    # would order its sweeps differently and differ in the last digits.
    v = with_options(unloaded, grade=0.03, fifth_wheel_friction=3.0e4)
    spec = mujoco.mjtState.mjSTATE_INTEGRATION
    states = []
    with Plant(v, speed="drive") as p:
        assert p.model.opt.disableflags & mujoco.mjtDisableBit.mjDSBL_ISLAND
        for flags in (p.model.opt.disableflags,
                      p.model.opt.disableflags & ~int(mujoco.mjtDisableBit.mjDSBL_ISLAND)):
            p.model.opt.disableflags = flags
            p.reset(InitialState(0.0, 0.0, 0.0, 0.1))
            p.parking_brake = True
            rest(p, 1.0)
            assert p.data.nefc > 2  # the constraints are there to be solved
            s = np.empty(mujoco.mj_stateSize(p.model, spec))
            mujoco.mj_getState(p.model, p.data, s, spec)
            states.append(s)
    np.testing.assert_array_equal(states[0], states[1])
