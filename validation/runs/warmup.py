"""Compile artic's numba functions ahead of their first use, in a process of their own.

From an empty cache, numba compiles the reduced models' harness loop and the
path-distance tree in about 4 s, on one core, the first time a campaign tunes
KIN and computes a criterion. :func:`start` does it in a background process
while the campaign generates its logs, and writes numba's on-disk cache
(:mod:`artic.validation.plumbing.runtime` chooses its folder); the campaign then loads the
compiled functions from it in a fraction of a second. A warm cache makes the
process a no-op. Nothing computed here is kept but the compiled code, so the
campaign's numbers are the same with or without it.

The compile is driven through the very calls the campaign makes (a short
reversing log through :func:`artic.validation.harness.batch.run_batch` and
:func:`artic.validation.criteria.metrics.run_metrics`), so numba compiles the argument types
the campaign passes and no others.
"""

from __future__ import annotations

import multiprocessing
import os

import numpy as np


def compile_all() -> None:
    """Run a 0.2 s reversing log through KIN's compiled loop and the criteria."""
    # Here, not at the top: the compiling is the child process's; the parent loads none of it.
    from artic.mjcf.vehicle import load_vehicle
    from artic.validation.criteria.metrics import run_metrics
    from artic.validation.harness.batch import run_batch
    from artic.validation.harness.loop import loop_inputs
    from artic.validation.logs.runfile import Run, new_frame
    from artic.validation.models import spec

    vehicle = load_vehicle("gosar2022-unloaded")
    t = np.arange(21) * 0.01
    obs = np.zeros((t.size, 13))
    obs[:, 3] = obs[:, 9] = -1.0  # both units reversing at 1 m/s
    obs[:, 0] = obs[:, 6] = -t
    obs[:, 6] += -8.0  # the semitrailer's sensor behind the tractor's
    log = Run(new_frame(t, np.zeros(t.size), obs), {"name": "warm-up"})
    steering = vehicle.steering_for("kin")
    res = run_batch(spec("kin").build, vehicle, [loop_inputs(log, vehicle, steering)])
    run_metrics(log.frame, new_frame(t, np.zeros(t.size), res.obs[0]), beyond=False)


def _child(parent: int) -> None:
    # Here, not at the top: in the child process only.
    from artic.validation.plumbing.workers import init_worker

    init_worker(parent)  # ends with the campaign, if the campaign is killed
    compile_all()


def start() -> multiprocessing.Process:
    """Start :func:`compile_all` in a daemon process; ``join`` it before the first use."""
    proc = multiprocessing.get_context("fork").Process(
        target=_child, args=(os.getpid(),), name="artic-numba-warm-up", daemon=True)
    proc.start()
    return proc
