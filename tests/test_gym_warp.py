"""artic/Dock-v0 vectorised on the Warp plant, on Warp's CPU device, against the C plant.

Skipped where the optional ``gpu`` extra (``mujoco-warp``, ``warp-lang``) or the
``gym`` extra is not installed. Warp's CPU device is slow, so the episodes are
cut at 2 s (20 steps) and the batches hold three environments.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

gym = pytest.importorskip("gymnasium", reason="the gym extra (pip install 'artic[gym]') "
                                              "is not installed")
pytest.importorskip("warp", reason="the gpu extra (warp-lang) is not installed")
pytest.importorskip("mujoco_warp", reason="the gpu extra (mujoco-warp) is not installed")

import warp as wp  # noqa: E402

import artic.gym  # noqa: E402, F401 - registers the environments
from artic.mjcf.errors import UserError  # noqa: E402
from artic.validation.docking import warp_dock  # noqa: E402
from artic.validation.docking.gym import kinbatch, spaces  # noqa: E402
from artic.validation.docking.gym.warpbatch import WarpDockVectorEnv  # noqa: E402

wp.config.quiet = True

KWARGS = {"scenario": "straight", "timeout": 2.0}

# Tolerances. The Warp plant is float32, the C plant float64. A position of some
# 30 m in the yard carries float32's rounding of ~2e-6 m; over the 2 s of these
# episodes the two plants part by about that much (measured 3e-6 m; the plant alone
# parts by 1e-6 m in 1 s, docs/design/warp-plant.md), so 1e-4 m, as
# tests/test_warp_dock.py. The velocities follow from the same states: measured
# 1e-6 m/s and rad/s, so 1e-4. Headings and the articulation: measured 5e-8 rad,
# float32's rounding of ~3 rad is 2.4e-7, so 2e-5 rad (1e-3 deg, test_warp_dock's).
# The steering wheel from the bus is computed in float64 from the same actions on
# both: equal but for the last bits.
POS, VEL, ANGLE = 1e-4, 1e-4, 2e-5
TOLERANCE = np.array([POS, POS, ANGLE, VEL, VEL, VEL,   # tractor x, y, psi, vx, vy, r
                      POS, POS, ANGLE, VEL, VEL, VEL,   # semitrailer
                      ANGLE, 1e-9,                      # gamma, delta_h
                      POS, POS, ANGLE])                 # the dock errors
# The reward is a difference of potentials: a distance (1e-4 m each way) and five
# times a heading (2e-5 rad each way).
REWARD = 2 * (POS + 5 * ANGLE)


def make(mode: str, n: int, **kwargs):
    extra = {"backend": "warp", "device": "cpu"} if mode == "warp" else {}
    return gym.make_vec("artic.gym:artic/Dock-v0", num_envs=n,
                        vectorization_mode="sync" if mode == "sync" else "vector_entry_point",
                        **extra, **kwargs)


def close(got, want, where: str) -> None:
    """One vector step's results within the tolerances: observations, rewards, ends, infos."""
    obs, rew, term, trunc, info = got
    obs_, rew_, term_, trunc_, info_ = want
    assert obs.shape == obs_.shape and obs.dtype == obs_.dtype, where
    assert np.all(np.abs(obs - obs_) <= TOLERANCE), (where, np.abs(obs - obs_).max(axis=0))
    assert np.all(np.abs(rew - rew_) <= REWARD), (where, rew, rew_)
    assert np.array_equal(term, term_) and np.array_equal(trunc, trunc_), where
    for key in ("reason", "_reason", "start", "_start", "scenario", "_t", "_scores"):
        if key in info_:
            assert np.array_equal(info[key], info_[key]), (where, key, info[key], info_[key])
    for i in np.flatnonzero(info_.get("_scores", [])):  # the rows' columns, one array each
        row, row_ = info["scores"], info_["scores"]
        assert row["plant"][i] == "mbd-warp" and row_["plant"][i] == "mbd"
        for key in ("success", "failure", "seed", "scenario"):
            assert row[key][i] == row_[key][i], (where, key)
        for key in ("lateral_error_m", "longitudinal_error_m"):
            x, y = row[key][i], row_[key][i]
            assert abs(x - y) <= POS or (math.isnan(x) and math.isnan(y)), (where, key, x, y)


def test_the_warp_batch_is_the_single_environments_within_float32(monkeypatch):
    # Three episodes of 2 s: the first stops after five steps (a stop counts as
    # docked anywhere here, so its run settles for some steps while the others wait,
    # and ends), is reset and goes on; the other two steer at random to the time
    # limit. Against Gymnasium's SyncVectorEnv of DockEnv on the C plant.
    for module in (spaces, kinbatch):
        monkeypatch.setattr(module, "STOP_DISTANCE", 1e3)
    warp, sync = make("warp", 3, **KWARGS), make("sync", 3, **KWARGS)
    assert type(warp.unwrapped) is WarpDockVectorEnv
    assert warp.metadata["autoreset_mode"] == gym.vector.AutoresetMode.NEXT_STEP
    held = []  # the settling run's plant steps beyond a step's first: the others wait
    period = warp.unwrapped._period
    monkeypatch.setattr(warp.unwrapped, "_period", lambda live, first: (
        held.append(int(np.count_nonzero(~live))) if not first else None, period(live, first))[1])
    got, want = warp.reset(seed=5), sync.reset(seed=5)
    close((got[0], np.zeros(3), np.zeros(3, bool), np.zeros(3, bool), got[1]),
          (want[0], np.zeros(3), np.zeros(3, bool), np.zeros(3, bool), want[1]), "reset")
    rng = np.random.default_rng(2)
    reasons, ends = [], 0
    for k in range(24):
        a = np.column_stack([rng.uniform(-0.5, 0.5, 3), np.full(3, -0.8)])
        if k == 5:
            a[0, 1] = 0.0  # stop: done
        got, want = warp.step(a), sync.step(a)
        close(got, want, f"step {k}")
        reasons += [str(r) for r, m in zip(got[4].get("reason", []), got[4].get("_reason", []),
                                           strict=False) if m and r]
        ends += int(np.count_nonzero(got[2] | got[3]))
    assert held and min(held) == 2, held  # the two others held while the first settled
    assert ends >= 3 and "timeout" in reasons, reasons  # the settled one and the time limits
    assert any(r not in ("", "timeout") for r in reasons), reasons
    warp.close()
    sync.close()


def test_a_diverged_or_jackknifed_world_ends_its_own_episode():
    warp, sync = make("warp", 3, **KWARGS), make("sync", 3, **KWARGS)
    env = warp.unwrapped
    warp.reset(seed=1)
    sync.reset(seed=1)
    # World 1 diverges (a velocity that is not finite), world 2 jackknifes (its limit
    # below the start's articulation); world 0 drives on, and its numbers stay the C
    # plant's through the others' ends and resets.
    qvel = env.plant.d.qvel.numpy()
    qvel[1, 0] = np.nan
    env.plant.d.qvel.assign(qvel)
    consts = env._loop.consts.numpy()
    saved = consts[2, warp_dock.GAMMA_MAX]
    consts[2, warp_dock.GAMMA_MAX] = 1e-4
    env._loop.consts.assign(consts)
    a = np.array([[0.1, -0.6], [0.0, -0.6], [0.0, -0.6]])
    obs, rew, term, trunc, info = warp.step(a)
    want = sync.step(a)
    assert term.tolist() == [False, True, True] and not trunc.any()
    assert info["reason"][1] == "plant diverged" and info["reason"][2] == "jackknife"
    assert info["scores"]["failure"][1].startswith("plant diverged: world 1: the simulation")
    assert rew[1] == 0.0 and rew[2] == -10.0  # a diverged plant is no crash; a jackknife is
    assert np.all(np.abs(obs[0] - want[0][0]) <= TOLERANCE)
    consts[2, warp_dock.GAMMA_MAX] = saved
    env._loop.consts.assign(consts)
    obs, rew, term, trunc, info = warp.step(a)  # 1 and 2 reset, 0 steps on
    want = sync.step(a)
    assert info["_start"].tolist() == [False, True, True] and not (term | trunc).any()
    assert np.all(np.isfinite(obs)) and rew[1] == rew[2] == 0.0
    assert np.all(np.abs(obs[0] - want[0][0]) <= TOLERANCE)
    obs, rew, term, trunc, info = warp.step(a)  # the reset worlds drive again
    assert not (term | trunc).any() and np.all(np.isfinite(obs))
    assert np.all(np.abs(obs[1:, 3]) > 0.0)  # moving: no longer the failed worlds held
    warp.close()
    sync.close()


def test_bad_input_is_one_line():
    with pytest.raises(UserError, match=r"^num_envs 0: expected a positive integer$"):
        make("warp", 0, **KWARGS)
    with pytest.raises(UserError, match=r"^num_envs 1000000000: about .* GiB, more than "
                                        r"cpu's free memory .* use at most about \d+ "
                                        r"environments \(num_envs\)$"):
        make("warp", 10**9, **KWARGS)
    if not any(d.is_cuda for d in wp.get_devices()):
        with pytest.raises(UserError, match=r"^device 'cuda': Warp finds no CUDA GPU here .*"
                                            r"use device='cpu'"):
            gym.make_vec("artic.gym:artic/Dock-v0", num_envs=2,
                         vectorization_mode="vector_entry_point", backend="warp",
                         device="cuda", **KWARGS)
    with pytest.raises(UserError, match=r"^backend 'gpu': expected 'cpu' .* or 'warp'"):
        make("native", 2, backend="gpu", **KWARGS)
    with pytest.raises(UserError, match=r"^device 'cuda': only with backend='warp'"):
        make("native", 2, device="cuda", **KWARGS)
    with pytest.raises(UserError, match=r"^backend='warp': artic/Dock-v0 with the full sensor "
                                        r"set.*leave backend out"):
        make("warp", 2, sensors="tractor", **KWARGS)
    warp = make("warp", 2, **KWARGS)
    warp.reset(seed=0)
    with pytest.raises(UserError, match=r"^actions\[1\] .*not finite.*nothing was stepped"):
        warp.step(np.array([[0.0, -0.5], [math.nan, -0.5]]))
    warp.close()
