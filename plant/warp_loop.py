"""The harness's reversing feedback around the Warp plant, on the device: many logs at once.

:func:`run` is :func:`artic.plant.closedloop.run` (the C loop around one plant) for
every world of an :class:`artic.plant.warp_plant.WarpPlant` at once, one log per
world (or one for all). Per sample ``k``, on the device and without returning to
the host (on a GPU one CUDA graph per sample):

1. the signals at the sensor points (``Plant.observe``);
2. the steering law of the seed paper's eqs. (5)-(7) with the stabilising sign,
   ``delta = delta_c + w K wrap(gamma - gamma_meas)`` limited to ``+-delta_max``,
   ``gamma`` the articulation as the inertial units report it (``Plant.gamma``)
   and ``w`` the feedback's weight (1 reversing, 0 forward, ramps between);
3. the stop: a world whose articulation passes ``gamma_max``, or whose signals are
   not finite, ends its run at that sample (its later rows stay NaN);
4. the plant's step to the next sample, with the speed controls of ``u1`` and ``u1_dot``.

The law is the harness's (``artic.validation.harness.feedback``), written again
here as the C loop writes it, since the plant does not import the harness.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import warp as wp

from artic.mjcf.errors import UserError
from artic.plant.warp_control import wrap
from artic.plant.warp_plant import WarpPlant
from artic.plant.warp_tyre import gather

_PI = wp.constant(3.14159265358979323846)


@wp.func
def wrap_angle(a: float):
    """``artic.mjcf.interface.wrap_angle``: ``pi - mod(pi - a, 2 pi)`` [rad]."""
    x = _PI - a
    return _PI - (x - 2.0 * _PI * wp.floor(x / (2.0 * _PI)))


@wp.struct
class Logs:
    """The logs' inputs, one row per log (one for all worlds, or one per world).

    Per sample: the road-wheel angle from the steering map [rad], the measured
    articulation [rad], the feedback's weight [-], the speed [m/s] and its rate [m/s^2].
    """

    delta_c: wp.array2d(dtype=float)
    gamma_meas: wp.array2d(dtype=float)
    weight: wp.array2d(dtype=float)
    u1: wp.array2d(dtype=float)
    u1_dot: wp.array2d(dtype=float)


@wp.struct
class Law:
    """The steering law's constants, one for all worlds.

    The feedback's gain K [rad/rad], the road-wheel limit and the jackknife limit
    [rad], and the hitch's ``qpos`` address.
    """

    gain: float
    delta_max: float
    gamma_max: float
    hitch_qpos: int


@wp.struct
class Records:
    """Per world and sample, what :class:`BatchResult` returns, and which worlds stopped."""

    obs: wp.array3d(dtype=float)
    delta: wp.array2d(dtype=float)
    delta_fb: wp.array2d(dtype=float)
    saturated: wp.array2d(dtype=int)
    n_done: wp.array(dtype=int)
    stopped: wp.array(dtype=int)


@wp.kernel
def law_kernel(counter: wp.array(dtype=int), logs: Logs, law: Law, qpos: wp.array2d(dtype=float),
               sensor_yaw: wp.array2d(dtype=float), signals: wp.array2d(dtype=float),
               command: wp.array2d(dtype=float), records: Records):
    """Sample ``counter[0]`` of world ``w``: the law, the records and the stop."""
    w = wp.tid()
    k = counter[0]
    if records.stopped[w] != 0:
        return
    # slot of the world's log: one log for all worlds, or one each
    lw = w % logs.delta_c.shape[0]
    gamma = wrap_angle(-qpos[w, law.hitch_qpos] + sensor_yaw[w, 0] - sensor_yaw[w, 1])
    fb = 0.0
    if logs.weight[lw, k] != 0.0:
        fb = logs.weight[lw, k] * law.gain * wrap(gamma - logs.gamma_meas[lw, k])
    dl = logs.delta_c[lw, k] + fb
    limited = 0
    if dl > law.delta_max:
        dl = law.delta_max
        limited = 1
    elif dl < -law.delta_max:
        dl = -law.delta_max
        limited = 1
    finite = True
    for j in range(13):
        records.obs[w, k, j] = signals[w, j]
        if not wp.isfinite(signals[w, j]):
            finite = False
    records.delta[w, k] = dl
    records.delta_fb[w, k] = dl - logs.delta_c[lw, k]
    records.saturated[w, k] = limited
    records.n_done[w] = k + 1
    if wp.abs(signals[w, 12]) > law.gamma_max or not finite:
        records.stopped[w] = 1
        return
    command[w, 0] = dl
    command[w, 1] = logs.u1[lw, k]
    command[w, 2] = logs.u1_dot[lw, k]


@wp.kernel
def advance_kernel(counter: wp.array(dtype=int)):
    """The next sample."""
    counter[0] = counter[0] + 1


class BatchResult(NamedTuple):
    """Per world, what :func:`artic.plant.closedloop.run` gives for one log."""

    obs: np.ndarray
    """``(n_worlds, n, 13)`` signals at each sample, NaN after a world's stop."""
    delta: np.ndarray
    """``(n_worlds, n)`` road-wheel angle applied [rad]."""
    delta_fb: np.ndarray
    """``(n_worlds, n)`` the feedback's part of it [rad]."""
    saturated: np.ndarray
    """``(n_worlds, n)`` whether ``delta_max`` limited it."""
    n_done: np.ndarray
    """``(n_worlds,)`` samples each world ran."""
    failures: dict[int, str]
    """The worlds that diverged (:meth:`WarpPlant.failures`)."""


def run(plant: WarpPlant, dt: float, delta_c, u1, u1_dot, gamma_meas, weight, gain: float,
        delta_max: float, gamma_max: float) -> BatchResult:
    """Drive every world of ``plant`` (already reset) through its log on the device.

    Parameters
    ----------
    plant : WarpPlant
        Reset to the logs' first samples (:meth:`WarpPlant.reset`).
    dt : float
        The logs' sample [s], one for all (the worlds step together).
    delta_c, u1, u1_dot, gamma_meas, weight : array_like
        Shape ``(n,)`` for one log driving every world, or ``(n_worlds, n)``: road-wheel
        angle from the steering map [rad], speed [m/s] and its rate [m/s^2], the log's
        articulation [rad], and the feedback's weight in [0, 1] [-].
    gain, delta_max, gamma_max : float
        Feedback gain K [rad/rad], road-wheel limit and jackknife limit [rad].

    Returns
    -------
    BatchResult
    """
    logs = [np.atleast_2d(np.asarray(a, dtype=np.float32))
            for a in (delta_c, gamma_meas, weight, u1, u1_dot)]
    n = logs[0].shape[1]
    rows = max(a.shape[0] for a in logs)
    for name, a in zip(("delta_c", "gamma_meas", "weight", "u1", "u1_dot"), logs, strict=True):
        if a.ndim != 2 or a.shape[1] != n or a.shape[0] not in (1, rows):
            raise UserError(f"{name}: shape {a.shape} does not fit the logs' {n} samples; "
                            "give each input as (n,) or as (n_worlds, n)")
    if rows not in (1, plant.n_worlds):
        raise UserError(f"the logs: {rows} rows for {plant.n_worlds} worlds; give one log "
                        "per world, or one for all")
    logs = [np.ascontiguousarray(np.broadcast_to(a, (rows, n))) for a in logs]
    nw, dev = plant.n_worlds, plant.device
    nsub = max(1, round(dt / plant.h))
    with wp.ScopedDevice(dev):
        inputs = gather(Logs, **{k: wp.array(a, dtype=float) for k, a in zip(
            ("delta_c", "gamma_meas", "weight", "u1", "u1_dot"), logs, strict=True)})
        hitch = int(plant.mj_model.jnt_qposadr[plant.hosts[0]._hitch_yaw])
        law = gather(Law, gain=float(gain), delta_max=float(delta_max),
                     gamma_max=float(gamma_max), hitch_qpos=hitch)
        counter = wp.zeros(1, dtype=int)
        records = gather(
            Records, obs=wp.array(np.full((nw, n, 13), np.nan, dtype=np.float32), dtype=float),
            delta=wp.array(np.full((nw, n), np.nan, dtype=np.float32), dtype=float),
            delta_fb=wp.array(np.full((nw, n), np.nan, dtype=np.float32), dtype=float),
            saturated=wp.zeros((nw, n), dtype=int), n_done=wp.zeros(nw, dtype=int),
            stopped=wp.zeros(nw, dtype=int))

        def sample(step: bool) -> None:
            plant.ctl.observe(plant)
            wp.launch(law_kernel, dim=nw, inputs=[
                counter, inputs, law, plant.d.qpos, plant.ctl.sensors.yaw, plant.ctl.signals],
                outputs=[plant.ctl.command, records])
            if step:
                plant._step_launches(nsub)
            wp.launch(advance_kernel, dim=1, inputs=[counter])

        graph = None
        for k in range(n):
            if graph is not None and k + 1 < n:
                wp.capture_launch(graph)
                continue
            sample(k + 1 < n)  # the first eagerly: the kernels load before the capture
            if plant._graph and k == 0 and n > 2:
                with wp.ScopedCapture() as capture:  # recorded, not run
                    sample(True)
                graph = capture.graph
    return BatchResult(records.obs.numpy().astype(float), records.delta.numpy().astype(float),
                       records.delta_fb.numpy().astype(float),
                       records.saturated.numpy().astype(bool),
                       records.n_done.numpy().astype(int), plant.failures())
