"""Measured-looking logs for the tests of hostile input: a slalom and a docking manoeuvre.

Both are driven on the single-track model (fast) and measured through the
synthetic campaign's sensor models (GNSS, inertial unit, CAN), so that they
carry the noise the consistency checks must tolerate.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from artic.mjcf import load_vehicle
from artic.reduced import STM, InitialState
from artic.validation.harness.simulate import simulate
from artic.validation.logs.runfile import Run, new_frame
from artic.validation.synthetic.driver import DockingDriver, drive_to_dock
from artic.validation.synthetic.manoeuvres import make_profile
from artic.validation.synthetic.sensors import measure


@functools.cache
def _slalom() -> Run:
    v = load_vehicle("gosar2022-unloaded")
    s = v.steering_for("stm")
    prof = make_profile("slalom", amplitude_deg=200, speed_kph=8, duration=30.0,
                        delta_h_offset=s.delta_h_offset, L1=v.L1, i_s=s.i_s)
    run = simulate(STM(v), v, prof)
    frame = measure(run.frame[list(new_frame(np.zeros(1), np.zeros(1),
                                             np.zeros((1, 13))).columns)],
                    np.random.default_rng(11))
    return Run(frame, {"name": "slalom", "manoeuvre": "slalom", "direction": "forward",
                       "load": "unloaded", "source": "synthetic"})


@functools.cache
def _docking() -> Run:
    v = load_vehicle("gosar2022-unloaded")
    drv = DockingDriver(v)
    t, obs, delta, _, docked = drive_to_dock(
        STM(v), drv, InitialState(10.0, 3.0, math.radians(5.0), 0.0))
    assert docked
    dh = v.steering_for("stm").steering_wheel(delta)
    frame = measure(new_frame(t, dh, obs), np.random.default_rng(12))
    return Run(frame, {"name": "docking", "manoeuvre": "docking", "direction": "reverse",
                       "load": "unloaded", "source": "synthetic"})


def slalom() -> Run:
    """A measured 30 s slalom at 8 km/h (a copy: change it freely)."""
    r = _slalom()
    return Run(r.frame.copy(), dict(r.meta))


def docking() -> Run:
    """A measured docking manoeuvre, mostly reversing (a copy)."""
    r = _docking()
    return Run(r.frame.copy(), dict(r.meta))
