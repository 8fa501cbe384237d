"""The independent truth's own model: its steering column, tie rod and twin tyres."""

from __future__ import annotations

import math

import numpy as np
import pytest

from artic.mjcf import load_vehicle
from artic.mjcf.interface import InitialState
from artic.mjcf.linkage import Trapezoid
from artic.validation.synthetic.column import Column
from artic.validation.synthetic.truthplant import TruthPlant, second_tread
from tests.helpers import needs_compiled

pytestmark = needs_compiled("the truth's compiled tyres and steering")

PLAY = math.radians(2.0)


@pytest.fixture(scope="module")
def vehicle():
    return load_vehicle("gosar2022-unloaded")


@pytest.fixture(scope="module")
def column(vehicle):
    return Column.of(vehicle, play=PLAY)


def test_the_column_law_has_play_a_torsion_bar_and_a_saturating_assist(column):
    c = column
    # Inside the play nothing turns the wheel (but the smoothing's trace).
    inside = c.law(ref=0.4 * c.play / c.i_s, dl=0.0, dr=0.0)
    assert abs(inside["tb"]) < 1e-3 * c.k_tb * c.play and abs(inside["box"]) < 1.0
    # Past it, the torsion bar twists by i_s (ref - dl) less half the play.
    ref = math.radians(1.0)
    out = c.law(ref=ref, dl=0.0, dr=0.0)
    assert out["tb"] == pytest.approx(c.k_tb * (c.i_s * ref - 0.5 * c.play), rel=1e-4)
    # The assist settles (dTa = 0) at its target, boost i_s T_tb in its linear
    # range, saturating at assist_max; the box is i_s T_tb plus the assist.
    target = c.assist_max * math.tanh(c.boost * c.i_s * out["tb"] / c.assist_max)
    settled = c.law(ref=ref, dl=0.0, dr=0.0, assist=target)
    assert settled["dTa"] == pytest.approx(0.0, abs=1e-9 * target)
    assert settled["box"] == pytest.approx(c.i_s * out["tb"] + target, rel=1e-12)
    assert out["dTa"] == pytest.approx(target / c.assist_tau, rel=1e-12)  # from zero, 1/tau
    huge = c.law(ref=1.0, dl=0.0, dr=0.0)
    assert huge["dTa"] * c.assist_tau == pytest.approx(c.assist_max, rel=1e-9)
    # The stiffness past the play: d(box)/d(dl) = -i_s^2 k_tb (1 + boost) for a
    # settled assist in its linear range (small torques).
    e, ref = 1e-7, math.radians(0.2)

    def box(dl):
        tb = c.law(ref=ref, dl=dl, dr=0.0)["tb"]
        lin = c.boost * c.i_s * tb  # tanh's slope 1 at small torque
        return c.law(ref=ref, dl=dl, dr=0.0, assist=lin)["box"]

    assert (box(e) - box(-e)) / (2 * e) == pytest.approx(-c.stiffness(), rel=1e-3)
    # Kingpin damping resists turning.
    assert c.law(ref=0.0, dl=0.0, dr=0.0, wl=1.0)["TL"] < -0.9 * c.c_kingpin


def test_the_tie_rod_holds_the_trapezoids_exact_right_angle(column, vehicle):
    c = column
    trap = Trapezoid(c.track, vehicle.L1, c.arm)
    for dl in np.radians([-30.0, -10.0, 0.0, 5.0, 20.0, 35.0]):
        dr = trap.right_angle(dl)
        assert abs(c.law(ref=dl, dl=dl, dr=dr)["rod"]) < 1e-3  # [N m]: no stretch, no force
        # Off it, the rod pulls the right wheel back, with the stiffness it was given.
        off = c.law(ref=dl, dl=dl, dr=dr + 1e-4)["rod"]
        assert off < 0
        if abs(dl) < 1e-9:
            from artic.validation.synthetic.column import TIE_ROD_STIFFNESS
            assert -off / 1e-4 == pytest.approx(TIE_ROD_STIFFNESS, rel=1e-3)


def test_at_standstill_the_wheels_follow_the_steering_wheel_through_the_column(vehicle,
                                                                                column):
    c = column
    ref = math.radians(10.0)
    with TruthPlant(vehicle, c, speed="pedals") as p:
        p.reset(InitialState(0.0, 0.0, 0.0, 0.0, u1=0.0))
        p.parking_brake = True
        for k in range(300):  # the driver turns the wheel in 1 s and holds it 2 s
            p.step(0.01, ref * min(1.0, k / 100), 0.0, 0.0)
        dl, dr = float(p.data.qpos[p._steer_L][0]), float(p.data.qpos[p._steer_R][0])
        torques = p.column_torques
    tb, box = torques["torsion_bar"], torques["box"]
    # The tyres' bore torque holds the wheels back: the torsion bar is twisted
    # past the play by what the box must give, and the assist has settled.
    assert box > 1000.0  # [N m]: turning a truck's wheels on the spot
    assert c.i_s * (ref - dl) == pytest.approx(tb / c.k_tb + 0.5 * c.play, rel=1e-3)
    # (Within 1 %: the bore torque creeps off at v_N's pace, about 10 % a
    # second here, and the assist trails it by its 50 ms.)
    settled = c.i_s * tb + c.assist_max * math.tanh(c.boost * c.i_s * tb / c.assist_max)
    assert box == pytest.approx(settled, rel=0.01)
    # The right wheel follows the exact trapezoid, short by the rod's compliance.
    from artic.validation.synthetic.column import TIE_ROD_STIFFNESS

    exact = Trapezoid(c.track, vehicle.L1, c.arm).right_angle(dl)
    assert dr == pytest.approx(exact - torques["tie_rod"] / TIE_ROD_STIFFNESS,
                               abs=math.radians(0.02))
    assert abs(dr - exact) > math.radians(0.05)  # and the compliance is there


def test_twin_tyres_are_two_tyres_that_scrub_in_a_turn(vehicle):
    with TruthPlant(vehicle, Column.of(vehicle), speed="follow") as p:
        m = p.model
        p.reset(InitialState(0.0, 0.0, 0.0, 0.0, u1=1.0))
        for _ in range(1000):  # 10 s into a left turn at 1 m/s
            p.step(0.01, math.radians(20.0), 1.0, 0.0)
        drive = next(a.name for a in vehicle.axles if a.dual)
        for side in ("L", "R"):
            first = p.data.act[m.actuator_actadr[m.actuator(f"tread.{drive}.{side}.u").id]]
            second = p.data.act[m.actuator_actadr[m.actuator(second_tread(drive, side, "u")).id]]
            # The twin further left runs slower over the ground on the same
            # wheel speed: it drives, the other brakes, and the pair resists the turn.
            assert first > 0.0 > second, (side, first, second)
    # Single tyres have no second set of states.
    assert sum(a.dual for a in vehicle.axles) == 1
    assert m.na == 3 * p.n_wheels + 1 + 3 * 2  # treads, the assist, the twins' second tyres


def test_the_truths_brakes_hold_it_on_a_slope(vehicle):
    # Dry friction: a truck braked to a stop on a 2 % grade stays where it is.
    import dataclasses

    sloped = dataclasses.replace(vehicle, plant=dataclasses.replace(vehicle.plant,
                                                                    grade=math.atan(0.02)))
    with TruthPlant(sloped, speed="pedals") as p:
        p.reset(InitialState(0.0, 0.0, 0.0, 0.0, u1=0.0))
        p.pedals = (0.0, 0.3)
        for _ in range(300):
            p.step(0.01, 0.0, 0.0, 0.0)
        x0 = p.observe()[0]
        for _ in range(200):
            p.step(0.01, 0.0, 0.0, 0.0)
        assert abs(p.observe()[0] - x0) < 1e-3  # [m] in 2 s: held
        assert p.parking_brake is False
        p.pedals = (0.0, 0.0)  # released, it rolls down
        for _ in range(200):
            p.step(0.01, 0.0, 0.0, 0.0)
        assert p.observe()[0] < x0 - 0.05
