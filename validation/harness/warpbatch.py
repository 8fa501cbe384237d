"""Many logs through the harness on the Warp plant at once: one world per (truck, log).

:func:`run_many_on_warp` is :func:`artic.validation.harness.batch.run_many` with the
plant for every log on one :class:`artic.plant.warp_plant.WarpPlant` (the gpu extra):
the reversing feedback of eqs. (5)-(7) runs on the device for all logs together
(:func:`artic.plant.warp_loop.run`), one world per log, each with its own truck
(payload, semitrailer variant: trucks of one model layout). It returns the
harness's :class:`~artic.validation.harness.batch.BatchResult`, so a batch
validation of many trucks reads as the CPU's does.

The worlds step together, so the logs must share one sample period; shorter logs
are padded by holding their last inputs at standstill, and each log's result is cut
to its own length. The steering and jackknife limits are one for all worlds: the
trucks must share ``delta_max`` and ``gamma_max``. A world that diverges is that
log's failure (its rows stop there, ``limited`` says so); the others go on.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from artic.mjcf.errors import UserError
from artic.mjcf.vehicle import Vehicle
from artic.validation.harness.batch import BatchResult
from artic.validation.harness.loop import DEFAULT_GAIN, LoopInputs, count_run


def _padded(inputs: Sequence[LoopInputs], name: str, n: int, hold: bool) -> np.ndarray:
    """Input ``name`` of every log, shape ``(len(inputs), n)``: held (or zero) past a log's end."""
    out = np.zeros((len(inputs), n))
    for i, inp in enumerate(inputs):
        a = np.asarray(getattr(inp, name), dtype=float)
        out[i, :a.size] = a
        if hold and a.size:
            out[i, a.size:] = a[-1]
    return out


def sample_period(inputs: Sequence[LoopInputs]) -> float:
    """The logs' one sample period [s]; one line when they have none in common."""
    periods = set()
    for inp in inputs:
        dt = np.diff(np.asarray(inp.t, dtype=float))
        if dt.size == 0:
            raise UserError("a log of one sample: give logs of at least two samples")
        if np.ptp(dt) > 1e-9 * max(1.0, float(dt.max())):
            raise UserError("a log with an uneven sample period: the Warp plant steps every "
                            "world together; resample the logs to one period (or run them on "
                            "the CPU plant)")
        periods.add(round(float(dt.mean()), 9))
    if len(periods) != 1:
        raise UserError(f"logs sampled at {', '.join(f'{p:g}' for p in sorted(periods))} s: the "
                        "Warp plant steps every world together; resample them to one period")
    return periods.pop()


def run_many_on_warp(vehicles: Sequence[Vehicle], inputs: Sequence[LoopInputs],
                     gain: float = DEFAULT_GAIN, device: str = "cpu") -> BatchResult:
    """Drive the plant of ``vehicles[i]`` through ``inputs[i]`` for every ``i``, on the device.

    Parameters
    ----------
    vehicles : sequence of Vehicle
        One truck per log (of one model layout, one ``delta_max`` and ``gamma_max``).
    inputs : sequence of LoopInputs
        One per log (:func:`artic.validation.harness.loop.loop_inputs`), one sample period.
    gain : float
        Reversing feedback gain K [rad/rad].
    device : str
        The Warp device, ``"cpu"`` or ``"cuda"``.

    Returns
    -------
    BatchResult
        As :func:`artic.validation.harness.batch.run_many`; ``limited`` names a world that
        diverged or the steps whose steering the linkage limited.
    """
    from artic.plant import warp_loop
    from artic.plant.warp_plant import WarpPlant

    vehicles, inputs = list(vehicles), list(inputs)
    if len(vehicles) != len(inputs):
        raise UserError(f"vehicles: {len(vehicles)} for {len(inputs)} logs; give one per log")
    if not inputs:
        raise UserError("run_many_on_warp: no logs given; give at least one")
    limits = {(v.steering.delta_max, v.gamma_max) for v in vehicles}
    if len(limits) != 1:
        raise UserError("vehicles: their steering and jackknife limits (delta_max, gamma_max) "
                        "differ; the Warp loop takes one pair: batch such trucks apart")
    delta_max, gamma_max = limits.pop()
    dt = sample_period(inputs)
    n = max(inp.t.size for inp in inputs)
    arrays = {name: _padded(inputs, name, n, hold) for name, hold in (
        ("delta_c", True), ("gamma_meas", True), ("u1", False), ("u1_dot", False),
        ("weight", False))}
    with WarpPlant(vehicles, device=device) as plant:
        plant.reset([inp.initial for inp in inputs])
        res = warp_loop.run(plant, dt, arrays["delta_c"], arrays["u1"], arrays["u1_dot"],
                            arrays["gamma_meas"], arrays["weight"], gain, delta_max, gamma_max)
        limited_steps = plant.steer_limited()
        sound = plant.ctl.state.fail_time.numpy().astype(float)  # a failed world's last time
    out = []
    for w, inp in enumerate(inputs):
        m = inp.t.size
        done = min(int(res.n_done[w]), m)
        if w in res.failures:  # held at its last sound state: the samples up to it
            done = min(done, int(np.floor(sound[w] / dt + 1e-6)) + 1)
        count_run("multibody", inp.t, done)
        note = res.failures.get(w, "")
        if not note and limited_steps[w]:
            note = (f"the linkage limited the steering command in {limited_steps[w]} plant "
                    "step(s)")
        out.append((res.obs[w, :m], res.delta[w, :m], res.delta_fb[w, :m],
                    res.saturated[w, :m], done, note))
    obs, delta, delta_fb, sat, n_done, notes = (list(x) for x in zip(*out, strict=True))
    return BatchResult(obs, delta, delta_fb, sat, np.array(n_done), notes)
