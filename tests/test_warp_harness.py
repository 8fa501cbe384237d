"""The harness's batch of logs on the Warp plant (validation.harness.warpbatch) against the CPU's.

Skipped where the optional ``gpu`` extra is not installed. Short logs: Warp's CPU
device is slow; the tolerances are tests/test_warp_plant.py's (float32 plant).
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

pytest.importorskip("warp", reason="the gpu extra (warp-lang) is not installed")
pytest.importorskip("mujoco_warp", reason="the gpu extra (mujoco-warp) is not installed")

import warp as wp  # noqa: E402

import artic  # noqa: E402
from artic.mjcf.errors import UserError  # noqa: E402
from artic.mjcf.interface import InitialState  # noqa: E402
from artic.plant import closedloop  # noqa: E402
from artic.plant.warp_check import DT, reverse_commands  # noqa: E402
from artic.validation.harness.batch import run_many  # noqa: E402
from artic.validation.harness.loop import LoopInputs  # noqa: E402
from artic.validation.harness.warpbatch import run_many_on_warp  # noqa: E402

wp.config.quiet = True

POS_TOL = 1e-4  # [m], float32 over about a second (tests/test_warp_plant.py)
GAMMA_TOL = 1e-3  # [deg]


def _log(duration: float, sign: float, dt: float = DT) -> LoopInputs:
    cmds = reverse_commands(duration, dt)
    n = len(cmds)
    t = np.arange(n) * dt
    gamma_meas = sign * 0.02 * np.sin(2 * np.pi * t / 1.2)  # the feedback pulls towards it
    weight = np.clip((t - 0.2) / 0.3, 0.0, 1.0)
    return LoopInputs(t, cmds[:, 0] * 17.0, cmds[:, 0], cmds[:, 1], cmds[:, 2], gamma_meas,
                      weight, InitialState(0.0, 0.0, 0.0, 0.0, u1=0.0))


@pytest.mark.skipif(bool(closedloop.unavailable_reason()),
                    reason="the compiled closed loop is not built")
def test_many_trucks_and_logs_match_the_cpu_batch():
    trucks = [artic.load_vehicle("gosar2022-unloaded"), artic.load_vehicle("gosar2022-loaded")]
    logs = [_log(1.2, 1.0), _log(0.8, -1.0)]  # of different lengths
    got = run_many_on_warp(trucks, logs, gain=1.5)
    want = run_many(artic.Plant, trucks, logs, gain=1.5)
    assert list(got.n_done) == list(want.n_done) == [len(log.t) for log in logs]
    for w in range(2):
        assert got.obs[w].shape == want.obs[w].shape
        assert np.abs(got.obs[w][:, [0, 1, 6, 7]] - want.obs[w][:, [0, 1, 6, 7]]).max() < POS_TOL
        assert np.degrees(np.abs(got.obs[w][:, 12] - want.obs[w][:, 12]).max()) < GAMMA_TOL
        # the feedback's part: float32 of a law of gain 1.5 on articulations of 0.02 rad
        assert np.abs(got.delta_fb[w] - want.delta_fb[w]).max() < 1e-6
        assert np.abs(want.delta_fb[w]).max() > 1e-3  # the feedback acted
    # the two trucks and logs differ by far more than the Warp plant from the C plant
    assert np.abs(got.obs[0][-1, :2] - got.obs[1][-1, :2]).max() > 100 * POS_TOL


def test_bad_batches_are_one_line():
    v = artic.load_vehicle("gosar2022-unloaded")
    with pytest.raises(UserError, match="one per log"):
        run_many_on_warp([v], [_log(0.3, 1.0), _log(0.3, 1.0)])
    with pytest.raises(UserError, match="resample them to one period"):
        run_many_on_warp([v, v], [_log(0.3, 1.0), _log(0.3, 1.0, dt=0.02)])
    other = dataclasses.replace(v, gamma_max=0.5 * v.gamma_max)
    with pytest.raises(UserError, match="batch such trucks apart"):
        run_many_on_warp([v, other], [_log(0.3, 1.0), _log(0.3, 1.0)])
    with pytest.raises(UserError, match="no logs"):
        run_many_on_warp([], [])


def test_a_diverged_world_is_its_log_s_failure_alone(monkeypatch):
    from artic.plant.warp_plant import WarpPlant

    reset = WarpPlant.reset

    def poisoned(self, initial, steady=False):  # world 1's state is not finite at the start
        reset(self, initial, steady)
        qvel = self.d.qvel.numpy()
        qvel[1, 0] = np.nan
        self.d.qvel.assign(qvel)

    v = artic.load_vehicle("gosar2022-unloaded")
    logs = [_log(0.5, 1.0), _log(0.5, 1.0)]
    healthy = run_many_on_warp([v, v], logs)
    monkeypatch.setattr(WarpPlant, "reset", poisoned)
    got = run_many_on_warp([v, v], logs)
    assert got.n_done[0] == len(logs[0].t) and got.limited[0] == ""
    assert np.array_equal(got.obs[0], healthy.obs[0])  # the other world went on, unchanged
    assert got.n_done[1] == 1 and got.limited[1].startswith("world 1: the simulation diverged")
