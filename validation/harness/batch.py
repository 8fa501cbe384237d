"""Many logs through the harness at once, one log per call, on a thread pool.

KIN and STM run :func:`artic.validation.harness.reducedloop.compiled_loop`, the plant its
compiled closed loop (:mod:`artic.plant.closedloop`). Both release the GIL for a
whole log, so the logs of a batch spread over ``jobs`` threads and scale
with cores. Each log is the very call :func:`artic.validation.harness.loop.run_inputs`
makes, so a batch returns exactly what one call per log returns, at any
number of threads.

An earlier batch integrated the reduced models' logs in one numba ``prange``
kernel. It was no faster than these threads, and compiling it from nothing
cost about 9 s, twice the compiled loop itself (``benchmarks/bench_batch.py``).
"""

from __future__ import annotations

from collections.abc import Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field

import numpy as np

from artic.mjcf.vehicle import Vehicle
from artic.validation.harness.loop import (
    DEFAULT_GAIN,
    LoopInputs,
    count_run,
    loop_args,
    run_inputs,
)
from artic.validation.harness.reducedloop import compiled_loop
from artic.validation.models import close, compiled_form, driven


@dataclass(frozen=True)
class BatchResult:
    """Per log: observations, applied and feedback steering, saturation, rows computed.

    ``limited`` holds, per log, what the model had to limit (the plant's
    warnings as one line, :mod:`artic.validation.harness.plantnotes`), or ``""``.
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


def run_batch(model_factory, vehicle: Vehicle, inputs: Sequence[LoopInputs],
              gain: float = DEFAULT_GAIN, jobs: int = 1) -> BatchResult:
    """Drive one model configuration through a batch of prepared logs.

    Parameters
    ----------
    model_factory : callable
        Builds the model from ``vehicle`` (``artic.KIN``, ``artic.STM``,
        ``Plant``, a model of the protocol, or a ``functools.partial`` of one).
    vehicle : Vehicle
        For the limits ``delta_max`` and ``gamma_max``.
    inputs : sequence of LoopInputs
        One per log, from :func:`artic.validation.harness.loop.loop_inputs`.
    gain : float
        Reversing feedback gain K [rad/rad].
    jobs : int
        Threads: logs run at once.
    """
    probe = driven(model_factory(vehicle))
    if compiled_form(probe) is not None:
        forms = []
        for inp in inputs:
            probe.reset(inp.initial)
            kind, x0, P, s1, s2 = compiled_form(probe)
            forms.append((kind, x0.copy(), P, s1, s2))

        def one(i):
            return compiled_loop(forms[i], tuple(loop_args(inputs[i], vehicle, gain)))

        runs = _on_threads(one, inputs, jobs)
        for inp, run in zip(inputs, runs, strict=True):
            count_run("reduced", inp.t, run[4])
        return _result(runs, [""] * len(inputs))
    close(probe)
    return run_many(model_factory, [vehicle] * len(inputs), inputs, gain, jobs)


def _result(runs: list[tuple], limited: list[str]) -> BatchResult:
    """A batch from one ``run_inputs`` tuple per log (obs, delta, delta_fb, saturated, n_done)."""
    if not runs:
        return BatchResult([], [], [], [], np.zeros(0, dtype=int), [])
    obs, delta, delta_fb, saturated, n_done = (list(x) for x in zip(*runs, strict=True))
    return BatchResult(obs, delta, delta_fb, saturated, np.array(n_done), limited)


def _on_threads(one, inputs: Sequence[LoopInputs], jobs: int) -> list:
    """``[one(i) for i in range(len(inputs))]`` on ``jobs`` threads, longest log first."""
    order = sorted(range(len(inputs)), key=lambda i: -inputs[i].t.size)
    if jobs <= 1 or len(inputs) < 2:
        done = {i: one(i) for i in order}
    else:
        with ThreadPoolExecutor(min(jobs, len(inputs))) as pool:
            done = dict(zip(order, pool.map(one, order), strict=True))
    return [done[i] for i in range(len(inputs))]


def run_many(model_factory, vehicles: Sequence[Vehicle], inputs: Sequence[LoopInputs],
             gain: float = DEFAULT_GAIN, jobs: int = 1) -> BatchResult:
    """Drive a model without a compiled form (the plant) through logs on a thread pool.

    Run ``i`` builds its model from ``vehicles[i]`` and drives it through
    ``inputs[i]``. The plant's compiled closed loop (:mod:`artic.plant.closedloop`)
    releases the GIL for a whole log, so the runs scale with ``jobs``; each
    run is independent of the others, so the numbers do not depend on ``jobs``.
    The longest runs start first, which keeps the threads busy to the end.
    """
    # Here, not at the top: the notes load MuJoCo, which a batch of KIN or the STM needs not.
    from artic.validation.harness.plantnotes import collect, summary

    def one(i):
        v, inp = vehicles[i], inputs[i]
        with collect() as notes:
            model = model_factory(v)
            try:
                return (*run_inputs(model, inp, v, gain), summary(notes))
            finally:
                close(model)

    out = _on_threads(one, inputs, jobs)
    return _result([o[:5] for o in out], [o[5] for o in out])
