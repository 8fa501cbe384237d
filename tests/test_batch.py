"""Batched harness runs equal one run per log, at any number of threads."""

from __future__ import annotations

import numpy as np
import pytest

from artic.plant import Plant
from artic.reduced import KIN, STM, Driven
from artic.validation.harness.batch import run_batch
from artic.validation.harness.loop import loop_args, loop_inputs, run_inputs
from artic.validation.harness.reducedloop import compiled_loop
from tests.helpers import straight_log


def inputs_for(vehicle, name):
    steering = vehicle.steering_for(name)
    logs = [straight_log(n=400, u=-0.8, gamma0=0.05), straight_log(n=250, u=1.5, delta_h=2.0),
            straight_log(n=2000, u=-1.0, gamma0=0.3)]
    return [loop_inputs(log, vehicle, steering) for log in logs]


@pytest.mark.parametrize("cls", [KIN, STM])
@pytest.mark.parametrize("gain", [0.0, 3.0])
@pytest.mark.parametrize("jobs", [1, 2])
def test_batch_equals_one_call_per_log(unloaded, cls, gain, jobs):
    inputs = inputs_for(unloaded, cls.name)
    res = run_batch(cls, unloaded, inputs, gain, jobs)
    for i, inp in enumerate(inputs):
        obs, delta, fb, sat, n = run_inputs(cls(unloaded), inp, unloaded, gain)
        assert res.n_done[i] == n
        np.testing.assert_array_equal(res.obs[i][:n], obs[:n])
        np.testing.assert_array_equal(res.delta_fb[i][:n], fb[:n])
    # Open loop, the 0.3 rad start jackknifes before the end; closed loop it does not.
    assert (res.n_done[2] < inputs[2].t.size) == (gain == 0.0)
    assert res.limited == [""] * len(inputs)


def test_the_reduced_loop_releases_the_gil(unloaded):
    # The thread pool of run_batch scales only if the compiled loop runs
    # without the GIL: a pure-Python counter on another thread must keep
    # counting while a long log runs. With the GIL held it would stall for
    # the whole call, but for a switch interval or two (5 ms each) at its ends.
    import threading
    import time

    inp = inputs_for(unloaded, "kin")[2]
    reps = 80
    long = type(inp)(**{**inp.__dict__, **{k: np.tile(getattr(inp, k), reps) for k in
                                           ("delta_h", "delta_c", "u1", "u1_dot",
                                            "gamma_meas", "weight")},
                        "t": np.arange(inp.t.size * reps) * 0.01})
    model = Driven(KIN(unloaded))
    model.reset(long.initial)
    args = (model.compiled(), tuple(loop_args(long, unloaded, 3.0)))
    compiled_loop(model.compiled(), tuple(loop_args(inp, unloaded, 3.0)))  # compiled beforehand
    ticks, running = [0], threading.Event()

    def count():
        while running.is_set():
            ticks[0] += 1

    def counted(fn) -> tuple[int, float]:
        running.set()
        counter = threading.Thread(target=count)
        counter.start()
        time.sleep(0.01)  # the counter is counting
        seen, t0 = ticks[0], time.perf_counter()
        try:
            fn()
            return ticks[0] - seen, time.perf_counter() - t0
        finally:
            running.clear()
            counter.join()

    alone, wall_alone = counted(lambda: time.sleep(0.1))
    during, wall = counted(lambda: compiled_loop(*args))
    assert wall > 0.05  # long enough for two 5 ms switch intervals to be a small share
    share = (during / wall) / (alone / wall_alone)
    # Free, the counter keeps most of its pace on the second core; held, it
    # would get 10 ms at most of the call's wall (under a fifth of it).
    assert share > 0.4, f"the counter ran at {share:.0%} of its pace during the compiled call"


def test_plant_batch_on_threads_equals_serial(unloaded):
    inputs = inputs_for(unloaded, "mbd")[:2]
    one = run_batch(Plant, unloaded, inputs, 3.0, jobs=1)
    two = run_batch(Plant, unloaded, inputs, 3.0, jobs=2)
    for a, b in zip(one.obs, two.obs, strict=True):
        np.testing.assert_array_equal(a, b)
