"""The harness's closed loop around the yard truth, compiled: a whole log in one call.

The floor (the truth that made a log, :mod:`artic.validation.models`) and its
open-loop predictions' replay (:class:`artic.validation.criteria.prediction.Replay`)
run the harness's loop per sample: the feedback law on the truth's
articulation, :meth:`~artic.validation.synthetic.yardtruth.YardTruth.observe`,
the stop, :meth:`~artic.validation.synthetic.yardtruth.YardTruth.step`. In
Python that loop costs about half as much again as the truth's own steps.
``artic_yard_run_loop`` (``_truth_c.c``) does the same per sample in C, in the
same order and with the same IEEE operations, so that every row is the
harness's Python loop's to the bit (``tests/test_yard_loop.py``); ctypes
releases the GIL for the call, so truths on threads run in parallel.

:meth:`~artic.validation.synthetic.yardtruth.YardTruth.closed_loop` offers it
to the harness (:func:`artic.validation.harness.loop.run_inputs`) where the
compiled truth has it; without it the harness's Python loop runs as before.
"""

from __future__ import annotations

import ctypes
import functools
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from artic.validation.logs.limits import OBSERVATION_LIMIT

if TYPE_CHECKING:
    from artic.mjcf.interface import LoopArgs
    from artic.validation.synthetic.yardtruth import YardTruth

MAX_ENDS = 32
N_OBS = 13
DONE, STOPPED, DIVERGED, BAD, REPLAY_END = 0, 1, 4, 5, 6

_D = ctypes.c_double


class _YardLoop(ctypes.Structure):
    _fields_ = [
        ("sensor_site", ctypes.c_int * 2), ("sensor_body", ctypes.c_int * 2),
        ("eps", _D * 2),
        ("gain", _D), ("delta_max", _D), ("gamma_max", _D), ("lock", _D),
        ("obs_limit", _D * N_OBS),
        ("pedals", ctypes.c_int), ("throttle", _D), ("brake", _D),
        ("drive_max", _D), ("brake_max", _D), ("parking", _D), ("weight", _D),
        ("r0_mean", _D),
        ("parked", ctypes.c_int),
        ("n_ends", ctypes.c_int), ("spin", ctypes.c_int * MAX_ENDS),
        ("r0", _D * MAX_ENDS), ("brake_share", _D * MAX_ENDS),
        ("act", ctypes.POINTER(_D)), ("n_act", ctypes.c_int),
        ("psi", _D * 2), ("decel", _D),
        ("act_k", ctypes.c_int), ("steer_limited", ctypes.c_int),
    ]


class LoopResult(NamedTuple):
    """What the harness reads of a whole-log loop (as :func:`artic.plant.closedloop.run`)."""

    obs: np.ndarray
    delta: np.ndarray
    delta_fb: np.ndarray
    saturated: np.ndarray
    n_done: int
    raw: None
    act_k: int
    """The recorded actuation's next row after the run (a replay's)."""


@functools.cache
def _prepared(lib: ctypes.CDLL | None) -> ctypes.CDLL | None:
    """The compiled truth ``lib`` with the loop's signature set, or ``None`` without the loop."""
    if lib is None or not hasattr(lib, "artic_yard_run_loop"):
        return None
    if lib.artic_yard_loop_size() != ctypes.sizeof(_YardLoop):
        return None  # built from another version of artic: the Python loop runs
    dp, bp = ctypes.POINTER(_D), ctypes.POINTER(ctypes.c_ubyte)
    lib.artic_yard_run_loop.restype = ctypes.c_int
    lib.artic_yard_run_loop.argtypes = [ctypes.c_void_p, ctypes.c_void_p, dp, dp, dp, dp, dp,
                                        ctypes.POINTER(_YardLoop), ctypes.c_int, dp, dp, dp, dp,
                                        dp, dp, dp, dp, dp, bp, ctypes.POINTER(ctypes.c_int)]
    return lib


def available(lib: ctypes.CDLL | None) -> bool:
    """Whether the compiled truth ``lib`` has the whole-log loop (a build of this version)."""
    return _prepared(lib) is not None


def _dp(a: np.ndarray):
    return a.ctypes.data_as(ctypes.POINTER(_D))


def run(truth: YardTruth, args: LoopArgs,
        replay: tuple[np.ndarray, int] | None = None) -> LoopResult:
    """Drive ``truth`` from its present state through a log's loop arguments.

    Parameters
    ----------
    truth : YardTruth
        Started (``reset`` or ``set_full_state``).
    args : LoopArgs
        The harness's per-log arguments (:func:`artic.validation.harness.loop.loop_args`).
    replay : tuple, optional
        ``(rows, first)``: the recorded actuation (one row of steering [rad], speed [m/s],
        its rate [m/s^2], throttle and brake [-] per step) and the row of the first
        step, taken in place of the harness's demand as
        :meth:`artic.validation.criteria.prediction.Replay.step` takes them.

    Raises
    ------
    FloatingPointError
        The truth's state stopped being finite (as its ``step``).
    ValueError
        The recorded actuation ran out (as ``Replay.step``).
    """
    lib = _prepared(truth._lib)
    if lib is None:
        raise RuntimeError("the compiled truth has no whole-log loop; reinstall artic")
    dt, delta_c, u1, u1_dot, gamma_meas, weight, gain, delta_max, gamma_max = args
    arrays = [np.ascontiguousarray(a, dtype=float)
              for a in (dt, delta_c, u1, u1_dot, gamma_meas, weight)]
    n = arrays[1].size
    obs = np.full((n, N_OBS), np.nan)
    delta, delta_fb = np.full(n, np.nan), np.full(n, np.nan)
    sat = np.zeros(n, dtype=np.uint8)
    s = _state(truth, float(gain), float(delta_max), float(gamma_max))
    rows = None
    if replay is not None:
        rows = np.ascontiguousarray(replay[0], dtype=float).reshape(-1, 5)
        s.act, s.n_act, s.act_k = _dp(rows), len(rows), int(replay[1])
    done = ctypes.c_int(0)
    par, ctl, z, zdot, out = truth._ptrs
    code = lib.artic_yard_run_loop(truth.model._address, truth.data._address, par, ctl, z,
                                   zdot, out, ctypes.byref(s), n, *map(_dp, arrays),
                                   _dp(obs), _dp(delta), _dp(delta_fb),
                                   sat.ctypes.data_as(ctypes.POINTER(ctypes.c_ubyte)),
                                   ctypes.byref(done))
    truth._psi[:] = list(s.psi)
    truth._decel = s.decel
    truth.steer_limited = s.steer_limited
    truth.pedals = (s.throttle, s.brake)
    if code == BAD:
        raise RuntimeError("the yard truth's compiled loop refused its indices; reinstall artic")
    if code == DIVERGED:
        truth.diverged()
    if code == REPLAY_END:
        raise ValueError(f"the recorded actuation ends after {len(rows)} steps")
    return LoopResult(obs, delta, delta_fb, sat.astype(bool), int(done.value), None,
                      int(s.act_k))


def _state(truth: YardTruth, gain: float, delta_max: float,
           gamma_max: float) -> _YardLoop:
    """The loop's struct from ``truth``'s present state and the harness's limits."""
    s = _YardLoop()
    ends = truth.layout.ends
    if len(ends) > MAX_ENDS:
        raise RuntimeError(f"{len(ends)} wheel ends; the compiled loop takes {MAX_ENDS}")
    for i, (site, body) in enumerate(truth._sensor_bodies):
        s.sensor_site[i], s.sensor_body[i] = site, body
        s.eps[i] = float(truth._eps[i])
        s.psi[i] = float(truth._psi[i])
    s.gain, s.delta_max, s.gamma_max = gain, delta_max, gamma_max
    s.lock = float(truth.vehicle.steering.delta_max)
    s.obs_limit[:] = [float(v) for v in OBSERVATION_LIMIT]
    s.pedals = int(truth.speed_mode == "pedals")
    s.throttle, s.brake = (float(p) for p in truth.pedals)
    s.drive_max, s.brake_max, s.parking = truth.PEDALS
    s.weight = float(truth._weight)
    s.r0_mean, s.parked = float(truth._r0_mean), int(truth._parked)
    s.n_ends = len(ends)
    for i, e in enumerate(ends):
        s.spin[i] = int(e["spin_dof"])
        s.r0[i] = float(truth.tyres[e["axle"]].r0)
        s.brake_share[i] = float(e["brake_share"])
    s.decel = float(truth._decel)
    return s
