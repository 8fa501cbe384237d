"""The pedal driver's per-step command gives, to the bit, what its first form gave."""

from __future__ import annotations

import math
from collections import deque

import numpy as np

from artic.mjcf.vehicle import G
from artic.validation.synthetic.actuation import PedalDriver


def _reference(d: PedalDriver, state: dict, u_target: float, a_target: float, u: float):
    """The command as first written (builtin min and max), on its own copy of the state."""
    state["seen"].append(abs(u))
    seen = state["seen"].popleft()
    err = abs(u_target) - seen
    if abs(u_target) > 0.05:
        state["trim"] += 0.25 * d.gain ** 2 * err * d.dt
    else:
        state["trim"] = 0.0
    a = a_target + d.gain * err + state["trim"]
    need = a / G + d.resistance * (1.0 if abs(u_target) > 0.05 else 0.0)
    want_t = min(max(need / d.drive_force_max, 0.0), 1.0)
    want_b = min(max(-need / d.brake_decel_max, 0.0), 1.0)
    if abs(u_target) < 1e-3 and seen < 0.05:
        want_t, want_b = 0.0, max(want_b, 0.3)
    step = d.pedal_rate * d.dt
    if want_b > 0.0 and state["throttle"] > 0.0:
        want_t = 0.0
    if want_t > 0.0 and state["brake"] > 0.0:
        want_b = 0.0
    state["throttle"] += min(max(want_t - state["throttle"], -step), step)
    state["brake"] += min(max(want_b - state["brake"], -step), step)
    if state["throttle"] > 0.0 and state["brake"] > 0.0:
        state["brake"] = max(state["brake"] - step, 0.0) if want_t > 0.0 else state["brake"]
        state["throttle"] = (max(state["throttle"] - step, 0.0) if want_b > 0.0
                             else state["throttle"])
    return state["throttle"], state["brake"]


def _bits(x: float) -> int:
    return np.float64(x).view(np.int64).item()


def test_command_as_first_written():
    """Random targets and speeds (stops, creeping, both gears) and a pedal swap forced
    by hand every few steps (both pedals down, the case the crossing branch handles)."""
    rng = np.random.default_rng(3)
    d = PedalDriver(40_000.0, delay=0.3, gain=1.7)
    d.reset(1.0)
    state = {"seen": deque(d._seen), "trim": 0.0, "throttle": 0.0, "brake": 0.0}
    n_both = 0
    for k in range(20_000):
        u_target = float(rng.choice([0.0, 5e-4, 0.04, -0.8, 1.5, 3.0]) + rng.normal() * 0.3
                         * (k % 3 == 0))
        a_target = float(rng.normal() * 0.5) if k % 5 else 0.0
        u = float(abs(u_target) + rng.normal() * 0.5) if k % 7 else -0.0
        if k % 11 == 0:  # both pedals pressed: the crossing
            d.throttle = d.brake = state["throttle"] = state["brake"] = float(rng.uniform(0, 1))
            n_both += 1
        got = d.command(u_target, a_target, u)
        want = _reference(d, state, u_target, a_target, u)
        assert [_bits(v) for v in got] == [_bits(v) for v in want], k
        assert _bits(d._trim) == _bits(state["trim"]), k
        assert math.copysign(1.0, got[0]) == math.copysign(1.0, want[0])
    assert n_both > 1000
