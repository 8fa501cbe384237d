"""The vector environments: equal to Gymnasium's SyncVectorEnv of single ones, bad actions."""

from __future__ import annotations

import math

import numpy as np
import pytest

gym = pytest.importorskip("gymnasium", reason="the gym extra (pip install 'artic[gym]') "
                                              "is not installed")

import artic.gym  # noqa: E402, F401 - registers the environments
from artic.mjcf.errors import UserError  # noqa: E402
from artic.validation.docking.gym.kinbatch import KinVectorEnv  # noqa: E402
from artic.validation.docking.gym.scripted import scripted_policy  # noqa: E402
from artic.validation.docking.gym.vector import DockVectorEnv  # noqa: E402

TIMINGS = ("solve_ms", "solve_ms_p50", "solve_ms_p99", "plan_ms", "late_commands")
"""The row's compute times (the wait for the agent, the commands it made late, the planner's
clock): never equal between two runs of anything, the single environment's own included."""


def make(env_id: str, mode: str, n: int, **kwargs):
    return gym.make_vec(f"artic.gym:{env_id}", num_envs=n, vectorization_mode=mode, **kwargs)


def same(a, b, where: str = "") -> None:
    """``a`` and ``b`` equal bit for bit (NaN equal to NaN), nested infos included."""
    if isinstance(a, tuple):
        assert isinstance(b, tuple) and len(a) == len(b), where
        for k, (x, y) in enumerate(zip(a, b, strict=True)):
            same(x, y, f"{where}[{k}]")
        return
    if isinstance(a, dict):
        assert isinstance(b, dict) and a.keys() == b.keys(), (where, a.keys(), b.keys())
        for key in a:
            if key.lstrip("_") not in TIMINGS:
                same(a[key], b[key], f"{where}[{key!r}]")
        return
    a, b = np.asarray(a), np.asarray(b)
    assert a.shape == b.shape and a.dtype == b.dtype, (where, a, b)
    if a.dtype.kind == "f":
        assert np.array_equal(a, b, equal_nan=True), (where, a, b)
    else:
        for k, (x, y) in enumerate(zip(a.ravel(), b.ravel(), strict=True)):
            if isinstance(x, np.ndarray | dict | tuple):
                same(x, y, f"{where}[{k}]")
            else:
                assert x == y or (x != x and y != y), (where, x, y)


def actions(observations: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """The scripted policy for the first sub-environment (it docks), straight back at full
    speed for the second (into the dock), at random for the others (they jackknife)."""
    out = np.column_stack([rng.uniform(-1.0, 1.0, len(observations)),
                           rng.uniform(-1.0, -0.2, len(observations))])
    out[0] = scripted_policy(observations[0])
    out[1] = (0.0, -1.0)
    return out


CASES = [
    # id, keywords, the vector environment make_vec gives, the ends the run must see
    ("artic/Dock-v0", {"scenario": "straight", "timeout": 30.0}, DockVectorEnv, {"docked"}),
    ("artic/DockKIN-v0", {"scenario": "straight", "timeout": 30.0}, KinVectorEnv,
     {"docked", "collision", "jackknife"}),
    ("artic/DockKIN-v0", {"scenario": "alley", "timeout": 12.0}, KinVectorEnv, {"timeout"}),
    ("artic/DockKIN-v0", {"scenario": "straight", "timeout": 30.0, "sensors": "tractor"},
     DockVectorEnv, {"docked"}),
]


@pytest.mark.parametrize(("env_id", "kwargs", "cls", "seen"), CASES)
def test_the_vector_environment_is_sync_vector_env_of_single_ones_bit_for_bit(
        env_id, kwargs, cls, seen):
    # Four sub-environments over episodes that end (docked, after the settling
    # steps; a random policy: a crash, terminated, or the time limit, truncated)
    # and autoreset, against Gymnasium's SyncVectorEnv of the single environment.
    native, sync = make(env_id, "vector_entry_point", 4, **kwargs), make(env_id, "sync", 4,
                                                                       **kwargs)
    assert type(native.unwrapped) is cls
    assert native.metadata["autoreset_mode"] == sync.metadata["autoreset_mode"] \
        == gym.vector.AutoresetMode.NEXT_STEP
    got, want = native.reset(seed=7), sync.reset(seed=7)
    same(got, want)
    rng = np.random.default_rng(3)
    reasons, resets, observations = set(), 0, got[0]
    for _ in range(1000):
        a = actions(observations, rng)
        got, want = native.step(a), sync.step(a)
        same(got, want)
        observations = got[0]
        reasons |= {str(r) for r, m in zip(got[4].get("reason", []),
                                           got[4].get("_reason", []), strict=False)
                    if m and r}
        resets += int(np.count_nonzero(got[4].get("_start", [])))
        if seen <= reasons and resets >= 2:
            break
    assert seen <= reasons and resets >= 2, (reasons, resets)
    native.close()
    sync.close()


def test_a_bad_action_is_refused_before_anything_steps():
    kwargs = {"scenario": "straight", "timeout": 5.0}
    native, sync = make("artic/DockKIN-v0", "vector_entry_point", 3, **kwargs), \
        make("artic/DockKIN-v0", "sync", 3, **kwargs)
    same(native.reset(seed=1), sync.reset(seed=1))
    good = np.array([[0.0, -0.5], [0.2, -0.5], [-0.2, -0.5]])
    bad = good.copy()
    bad[1, 0] = math.nan
    with pytest.raises(UserError, match=r"^actions\[1\] .*not finite .*nothing was stepped"):
        native.step(bad)
    bad[2] = math.inf
    with pytest.raises(UserError, match=r"^actions\[1\] .*sub-environment 1 and 1 more"):
        native.step(bad)
    for shape in ((3,), (2, 2), (3, 3)):
        with pytest.raises(UserError, match=r"expected \(3, 2\).*nothing was stepped"):
            native.step(np.zeros(shape))
    # No sub-environment moved: the next good step is the first step of the sync ones.
    same(native.step(good), sync.step(good))
    native.close()
    sync.close()


def test_the_vector_environment_keeps_its_own_copies():
    # Overwriting what it returned changes nothing of the episodes (issue 46, item 2).
    def rewards(scribble: bool) -> np.ndarray:
        envs = make("artic/DockKIN-v0", "vector_entry_point", 2, scenario="straight")
        obs, _ = envs.reset(seed=4)
        total = np.zeros(2)
        for _ in range(20):
            if scribble:
                obs *= 100.0
                obs[:, -3] = math.nan
            obs, r, *_ = envs.step(np.array([[0.0, -0.5], [0.1, -0.5]]))
            total += r
            if scribble:
                r[:] = math.nan
        envs.close()
        return total

    assert np.array_equal(rewards(False), rewards(True))


def test_bad_vector_arguments_are_one_line():
    with pytest.raises(UserError, match="^num_envs 0: expected a positive integer"):
        DockVectorEnv(0, scenario="straight", yard_model="kin")
    with pytest.raises(UserError, match="^keyword 'foo'"):
        make("artic/DockKIN-v0", "vector_entry_point", 2, foo=1)
    envs = make("artic/DockKIN-v0", "vector_entry_point", 2, scenario="straight")
    with pytest.raises(RuntimeError, match="reset"):
        envs.step(np.zeros((2, 2)))
    with pytest.raises(UserError, match="^seed: a list of 3 seeds for 2 environments"):
        envs.reset(seed=[1, 2, 3])
    with pytest.raises(UserError, match=r"^options\['strat'\]: not a reset option"):
        envs.reset(options={"strat": 1})
    envs.close()


@pytest.mark.parametrize("env_id", list(artic.gym.ENVIRONMENTS))
def test_a_partial_reset_and_a_given_start_are_sync_vector_env_s(env_id):
    # options["reset_mask"] resets those sub-environments alone (their seeds from the
    # list), and options["start"] gives every reset one artic dock start.
    kwargs = {"scenario": "straight,offset", "timeout": 5.0}
    native, sync = make(env_id, "vector_entry_point", 3, **kwargs), make(env_id, "sync", 3,
                                                                       **kwargs)
    same(native.reset(seed=2), sync.reset(seed=2))
    a = np.array([[0.0, -0.5], [0.3, -0.5], [-0.3, -0.5]])
    for _ in range(3):
        same(native.step(a), sync.step(a))
    mask = np.array([False, True, True])
    same(native.reset(seed=[None, 11, 12], options={"reset_mask": mask.copy()}),
         sync.reset(seed=[None, 11, 12], options={"reset_mask": mask.copy()}))
    same(native.reset(options={"start": 4}), sync.reset(options={"start": 4}))
    for _ in range(3):
        same(native.step(a), sync.step(a))
    native.close()
    sync.close()
