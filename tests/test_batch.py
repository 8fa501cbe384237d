"""Batched harness runs equal one run per log, at any number of threads."""

from __future__ import annotations

import numpy as np
import pytest

from conftest import straight_log
from plant import Plant
from reduced import KinematicModel, SingleTrackModel
from validation.batch import run_batch
from validation.harness import loop_inputs, run_inputs
from validation.steering import SteeringMap


def inputs_for(vehicle, name):
    steering = SteeringMap.from_steering(vehicle.steering_for(name))
    logs = [straight_log(n=400, u=-0.8, gamma0=0.05), straight_log(n=250, u=1.5, delta_h=2.0),
            straight_log(n=2000, u=-1.0, gamma0=0.3)]
    return [loop_inputs(log, vehicle, steering) for log in logs]


@pytest.mark.parametrize("cls", [KinematicModel, SingleTrackModel])
@pytest.mark.parametrize("gain", [0.0, 3.0])
def test_batch_equals_one_call_per_log(unloaded, cls, gain):
    inputs = inputs_for(unloaded, cls.name)
    res = run_batch(cls, unloaded, inputs, gain)
    for i, inp in enumerate(inputs):
        obs, delta, fb, sat, n = run_inputs(cls(unloaded), inp, unloaded, gain)
        assert res.n_done[i] == n
        np.testing.assert_array_equal(res.obs[i][:n], obs[:n])
        np.testing.assert_array_equal(res.delta_fb[i][:n], fb[:n])
    # Open loop, the 0.3 rad start jackknifes before the end; closed loop it does not.
    assert (res.n_done[2] < inputs[2].t.size) == (gain == 0.0)


def test_plant_batch_on_threads_equals_serial(unloaded):
    inputs = inputs_for(unloaded, "mbd")[:2]
    one = run_batch(Plant, unloaded, inputs, 3.0, jobs=1)
    two = run_batch(Plant, unloaded, inputs, 3.0, jobs=2)
    for a, b in zip(one.obs, two.obs, strict=True):
        np.testing.assert_array_equal(a, b)
