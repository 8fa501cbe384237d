"""Many logs through the harness at once: KIN and STM compiled, the plant on threads.

The reduced models integrate a batch of manoeuvres in one compiled call,
:func:`batch_loop`, with the manoeuvres spread over cores by numba's
``prange``. Each manoeuvre runs the very loop of :func:`validation.harness.compiled_loop`
on its own slice of the concatenated inputs, so a batch returns exactly what
one call per log returns, at any number of threads.

The plant runs one MuJoCo model per log on a thread pool (:func:`run_many`);
its compiled closed loop (:mod:`plant.closedloop`) runs a whole log without
the GIL, so the runs scale with cores.
"""

from __future__ import annotations

from collections.abc import Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field

import numpy as np
from numba import njit, prange

from mjcf.vehicle import Vehicle
from validation.harness import DEFAULT_GAIN, LoopInputs, compiled_loop, run_inputs


@njit(parallel=True, cache=True)
def batch_loop(kind, X0, P, s1, s2, starts, dt, delta_c, u1, u1_dot, gamma_meas, reversing,
               gain, delta_max, gamma_max):
    """:func:`validation.harness.compiled_loop` over a batch of logs.

    Parameters
    ----------
    kind : int
        ``reduced.integrate.KIN`` or ``STM``.
    X0 : ndarray, shape (n_logs, n_states)
        Initial states.
    P, s1, s2 : ndarray
        Parameters and sensors, shared by the batch.
    starts : ndarray of int, shape (n_logs + 1,)
        Log ``i`` occupies rows ``starts[i]:starts[i + 1]`` of the inputs.
    dt : ndarray
        Step to the next sample [s]; the last entry of each log is unused.
    delta_c, u1, u1_dot, gamma_meas, reversing : ndarray
        Concatenated per-sample inputs, as for ``compiled_loop``.
    gain, delta_max, gamma_max : float
        As for ``compiled_loop``.

    Returns
    -------
    obs, delta, delta_fb, saturated : ndarray
        Concatenated outputs; rows after a log stopped stay NaN.
    n_done : ndarray of int
        Rows computed per log.
    """
    n_logs = starts.size - 1
    n = starts[-1]
    obs = np.full((n, 13), np.nan)
    delta = np.full(n, np.nan)
    delta_fb = np.full(n, np.nan)
    sat = np.zeros(n, dtype=np.bool_)
    n_done = np.zeros(n_logs, dtype=np.int64)
    for i in prange(n_logs):
        a, b = starts[i], starts[i + 1]
        o, d, f, s, k = compiled_loop(kind, X0[i], P, s1, s2, dt[a:b], delta_c[a:b], u1[a:b],
                                      u1_dot[a:b], gamma_meas[a:b], reversing[a:b], gain,
                                      delta_max, gamma_max)
        obs[a:b] = o
        delta[a:b] = d
        delta_fb[a:b] = f
        sat[a:b] = s
        n_done[i] = k
    return obs, delta, delta_fb, sat, n_done


@dataclass(frozen=True)
class BatchResult:
    """Per log: observations, applied and feedback steering, saturation, rows computed.

    ``limited`` holds, per log, what the model had to limit (the plant's
    warnings as one line, :mod:`validation.plantnotes`), or ``""``.
    """

    obs: list[np.ndarray]
    delta: list[np.ndarray]
    delta_fb: list[np.ndarray]
    saturated: list[np.ndarray]
    n_done: np.ndarray
    limited: list[str] = field(default_factory=list)

    def part(self, a: int, b: int) -> BatchResult:
        """Logs ``a`` to ``b - 1`` of the batch."""
        return BatchResult(self.obs[a:b], self.delta[a:b], self.delta_fb[a:b],
                           self.saturated[a:b], self.n_done[a:b], self.limited[a:b])


def _split(starts, *arrays):
    return [[a[starts[i]:starts[i + 1]] for i in range(starts.size - 1)] for a in arrays]


def run_batch(model_factory, vehicle: Vehicle, inputs: Sequence[LoopInputs],
              gain: float = DEFAULT_GAIN, jobs: int = 1) -> BatchResult:
    """Drive one model configuration through a batch of prepared logs.

    Parameters
    ----------
    model_factory : callable
        Builds the model from ``vehicle`` (a reduced model class, ``Plant``,
        or a ``functools.partial`` of one).
    vehicle : Vehicle
        For the limits ``delta_max`` and ``gamma_max``.
    inputs : sequence of LoopInputs
        One per log, from :func:`validation.harness.loop_inputs`.
    gain : float
        Reversing feedback gain K [rad/rad].
    jobs : int
        Threads for models without a compiled form (the plant).
    """
    probe = model_factory(vehicle)
    if probe.compiled() is not None:
        X0 = []
        for inp in inputs:
            probe.reset(inp.initial)
            X0.append(probe.x.copy())
        kind, _, P, s1, s2 = probe.compiled()
        lengths = np.array([inp.t.size for inp in inputs])
        starts = np.concatenate([[0], np.cumsum(lengths)]).astype(np.int64)

        def cat(name):
            return np.concatenate([getattr(inp, name) for inp in inputs])

        dt = np.concatenate([np.append(np.diff(inp.t), 0.0) for inp in inputs])
        obs, d, f, s, n_done = batch_loop(
            kind, np.array(X0), P, s1, s2, starts, dt, cat("delta_c"), cat("u1"),
            cat("u1_dot"), cat("gamma_meas"), cat("reversing"), float(gain),
            vehicle.steering.delta_max, vehicle.gamma_max)
        return BatchResult(*_split(starts, obs, d, f, s), n_done)
    probe.close()
    return run_many(model_factory, [vehicle] * len(inputs), inputs, gain, jobs)


def run_many(model_factory, vehicles: Sequence[Vehicle], inputs: Sequence[LoopInputs],
             gain: float = DEFAULT_GAIN, jobs: int = 1) -> BatchResult:
    """Drive a model without a compiled form (the plant) through logs on a thread pool.

    Run ``i`` builds its model from ``vehicles[i]`` and drives it through
    ``inputs[i]``. The plant's compiled closed loop (:mod:`plant.closedloop`)
    releases the GIL for a whole log, so the runs scale with ``jobs``; each
    run is independent of the others, so the numbers do not depend on ``jobs``.
    The longest runs start first, which keeps the threads busy to the end.
    """
    from validation.plantnotes import collect, summary

    def one(i):
        v, inp = vehicles[i], inputs[i]
        with collect() as notes:
            model = model_factory(v)
            try:
                return (*run_inputs(model, inp, v, gain), summary(notes))
            finally:
                model.close()

    order = sorted(range(len(inputs)), key=lambda i: -inputs[i].t.size)
    with ThreadPoolExecutor(max(1, jobs)) as pool:
        done = dict(zip(order, pool.map(one, order), strict=True))
    out = [done[i] for i in range(len(inputs))]
    return BatchResult([o[0] for o in out], [o[1] for o in out], [o[2] for o in out],
                       [o[3] for o in out], np.array([o[4] for o in out]),
                       [o[5] for o in out])
