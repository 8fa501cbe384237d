"""The sampling docking controllers (MPPI) on KIN and on the STM."""

from __future__ import annotations

import math

import numpy as np
import pytest

from artic.mjcf import load_vehicle
from artic.mjcf.outline import DOCK_FACE
from artic.validation.docking.controllers import BUILTIN, Task, load
from artic.validation.docking.controllers.mppi import (
    COLLISION_COST,
    GAMMA_SOFT,
    HORIZON,
    MPPIKin,
    MPPIStm,
    penalties,
)
from artic.validation.docking.geometry import box_array
from artic.validation.docking.planner import HybridAStar
from artic.validation.docking.run import drive
from artic.validation.docking.scenarios import scenario

VEHICLE = "gosar2022-unloaded"


@pytest.fixture(scope="module")
def task():
    v = load_vehicle(VEHICLE)
    s = scenario("straight")
    yard = s.yard(v)
    return Task(v, yard, HybridAStar().plan(yard, v, s.start(0)), 0.1, 1.1, 1.67, 0.5, 6.3)


def straight_back(controller, x_rear: float, gamma: float = 0.0) -> np.ndarray:
    """Design-model states (1, HORIZON, n) reversing along the door's centre line."""
    X = np.zeros((1, HORIZON, controller.model.nstates))
    # The kingpin is the rear plus the semitrailer's length ahead; the state's
    # point sits -x_hitch behind the kingpin along the tractor.
    kingpin = x_rear + controller.frames.rear + np.linspace(2.0, 0.0, HORIZON)
    X[0, :, 0] = kingpin - controller.model._x_hitch
    X[0, :, 1] = DOCK_FACE[1]
    X[0, :, 3] = gamma
    return X


def test_both_are_registered():
    assert load("mppi-kin") is MPPIKin and load("mppi-stm") is MPPIStm
    assert "MPPI" in BUILTIN["mppi-kin"][1] and "STM" in BUILTIN["mppi-stm"][1]


@pytest.mark.parametrize("cls", [MPPIKin, MPPIStm])
def test_a_collision_and_the_articulation_limit_raise_the_cost(cls, task):
    c = cls()
    c.reset(task)
    clear = straight_back(c, DOCK_FACE[0] + 3.0)
    tractor, trailer = c._poses(clear)
    args = (c.boxes, c.frames.tractor_box, c.frames.trailer_box, c.vehicle.gamma_max)
    assert penalties(tractor, trailer, clear[:, :, 3], *args)[0] == 0.0
    # The same motion 2 m further back: the rear passes the dock face into the dock.
    into = straight_back(c, DOCK_FACE[0] - 2.0)
    tractor, trailer = c._poses(into)
    assert penalties(tractor, trailer, into[:, :, 3], *args)[0] >= COLLISION_COST
    # Articulated past the planner's limit, and past the jackknife guard.
    for gamma, least in ((GAMMA_SOFT + 0.1, 1.0), (0.95 * c.vehicle.gamma_max, COLLISION_COST)):
        bent = straight_back(c, DOCK_FACE[0] + 3.0, gamma)
        tractor, trailer = c._poses(bent)
        assert penalties(tractor, trailer, bent[:, :, 3], *args)[0] >= least
    # And the whole cost ranks them so: tracking alike, the collision far dearer.
    D = np.zeros((2, HORIZON))
    ref = np.column_stack([np.full(HORIZON, DOCK_FACE[0] + 5.0), np.full(HORIZON, DOCK_FACE[1]),
                           np.zeros(HORIZON)])
    both = np.concatenate([clear, into])
    cost = c._cost(both, D, 0.0, ref, np.zeros(HORIZON), np.zeros(HORIZON), 0.2)
    assert cost[1] - cost[0] >= COLLISION_COST
    # A collision is dearer the sooner it comes.
    boxes = box_array(task.yard.obstacles)
    early = straight_back(c, DOCK_FACE[0] - 6.0)
    t1, k1 = c._poses(early)
    t2, k2 = c._poses(into)
    assert penalties(t1, k1, early[:, :, 3], boxes, *args[1:])[0] > \
        penalties(t2, k2, into[:, :, 3], boxes, *args[1:])[0]


def test_the_samples_keep_the_rate_and_the_lock_and_are_seeded(task):
    c = MPPIKin()
    c.reset(task)
    nominal = np.linspace(0.0, 0.6, HORIZON)
    D = c._samples(0.05, nominal, np.zeros(HORIZON))
    step = c.delta_rate * 0.2
    moves = np.diff(np.concatenate([np.full((D.shape[0], 1), 0.05), D], axis=1), axis=1)
    assert np.abs(moves).max() <= step + 1e-12
    assert np.abs(D).max() <= c.vehicle.steering.delta_max + 1e-12
    again = MPPIKin()
    again.reset(task)
    assert np.array_equal(D, again._samples(0.05, nominal, np.zeros(HORIZON)))


@pytest.mark.slow
def test_mppi_kin_docks_a_straight_start_on_the_plant():
    # realtime=False: the test judges the docking; the compute time is the benchmark's.
    r = drive(scenario("straight"), VEHICLE, "mppi-kin", 0, realtime=False)
    row = r.row
    assert row["success"], row["failure"]
    assert abs(row["lateral_error_m"]) <= 0.10
    assert abs(row["heading_error_deg"]) <= 1.0
    assert row["max_gamma_deg"] < math.degrees(GAMMA_SOFT)
    given = [h for h in r.trace.horizons if h is not None]
    assert len(given) > 100 and given[-1].shape == (HORIZON + 1, 2)
