"""The Gymnasium environments: the checker, the round trip with artic dock, the ends, the reward."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

gym = pytest.importorskip("gymnasium", reason="the gym extra (pip install 'artic[gym]') "
                                              "is not installed")

import artic.gym  # noqa: E402 - registers the environments
import artic.mjcf.steering  # noqa: E402
from artic.mjcf.errors import UserError  # noqa: E402
from artic.validation.docking.controllers import load  # noqa: E402
from artic.validation.docking.gym import reward  # noqa: E402
from artic.validation.docking.gym.env import DockEnv  # noqa: E402
from artic.validation.docking.gym.scripted import Scripted, scripted_policy  # noqa: E402
from artic.validation.docking.gym.spaces import OBSERVATION_NAMES, ActionScale  # noqa: E402
from artic.validation.docking.run import drive  # noqa: E402
from artic.validation.docking.scenarios import scenario  # noqa: E402

VEHICLE = "gosar2022-unloaded"
FINAL = ("success", "lateral_error_m", "longitudinal_error_m", "heading_error_deg", "time_s")


def episode(env: DockEnv, act, start: int, name: str = "straight") -> tuple[dict, list[float]]:
    """Run one episode from ``artic dock``'s start ``start``; the last info and the rewards."""
    obs, info = env.reset(options={"start": start, "scenario": name})
    rewards = []
    while True:
        obs, r, terminated, truncated, info = env.step(act(obs))
        rewards.append(r)
        if terminated or truncated:
            return info, rewards


@pytest.mark.parametrize("env_id", list(artic.gym.ENVIRONMENTS))
def test_gymnasium_s_checker_passes(env_id, tmp_path, monkeypatch):
    from gymnasium.utils.env_checker import check_env

    monkeypatch.chdir(tmp_path)
    env = gym.make(env_id, scenario="straight")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        # The observation is positions in the yard, velocities and angles: a Box
        # without finite bounds, which the checker notes but allows.
        warnings.filterwarnings("ignore", message=".*Box observation space m")
        check_env(env.unwrapped)
    assert env.observation_space.shape == (len(OBSERVATION_NAMES),)
    env.close()
    # The checker resets an environment with render_mode="rerun" and closes it
    # unfinished (issue 46, item 15): an abandoned run writes no recording, so no
    # empty folder and none of numpy's warnings about an empty run.
    assert [str(w.message) for w in caught] == []
    assert not (tmp_path / "recordings").exists()


@pytest.mark.parametrize("yard_model", ["mbd", "kin"])
def test_the_reference_controller_through_the_environment_scores_as_artic_dock(yard_model):
    # An agent that commands what the reference controller commands, through the
    # action's scale, drives artic dock's run itself: the same final errors up to
    # the rounding of the scale and back (one ulp of the steering wheel in a stable
    # closed loop), here 1e-9 m and 1e-7 deg.
    env = DockEnv(scenario="straight", vehicle=VEHICLE, yard_model=yard_model)
    ctrl = load("reference")()
    obs, _ = env.reset(options={"start": 2})
    ctrl.reset(env.task)
    while True:
        action = env.scale.action(ctrl.command(env.observation))
        obs, _, terminated, truncated, info = env.step(action)
        if terminated or truncated:
            break
    row = drive(scenario("straight"), VEHICLE, "reference", 2, yard_model=yard_model).row
    assert info["reason"] == "docked" and terminated and not truncated
    assert info["scores"]["success"] and row["success"]
    for key in FINAL[1:]:
        assert info["scores"][key] == pytest.approx(row[key], abs=1e-7), key


def test_a_policy_scores_the_same_in_the_environment_and_in_artic_dock():
    # The round trip: the scripted policy as an agent and, through the adapter,
    # as artic dock's controller give the same run to the last digit (the same
    # observation vector, the same action scale, the same stop rule).
    env = DockEnv(scenario="straight", vehicle=VEHICLE, yard_model="kin")
    info, _ = episode(env, scripted_policy, start=1)
    row = drive(scenario("straight"), VEHICLE, Scripted, 1, yard_model="kin").row
    assert info["reason"] == "docked"
    for key in FINAL:
        assert info["scores"][key] == row[key], key
    assert load("artic.validation.docking.gym.scripted:Scripted") is Scripted


def test_a_random_policy_ends_with_its_reason():
    env = DockEnv(scenario="alley", vehicle=VEHICLE, yard_model="kin")
    env.action_space.seed(4)
    reasons = set()
    for start in range(2):
        info, _ = episode(env, lambda o: env.action_space.sample(), start, "alley")
        assert info["reason"] in ("collision", "jackknife", "timeout"), info["reason"]
        assert not info["scores"]["success"]
        reasons.add(info["reason"])
    assert reasons  # each episode ended, and said why


def test_the_shaped_rewards_add_up_to_the_progress_and_the_outcome():
    # Potential shaping telescopes: the rewards of an episode sum to the
    # potential's change from the first observation to the last, less the time
    # cost of every step but the last, plus the outcome.
    env = DockEnv(scenario="straight", vehicle=VEHICLE, yard_model="kin")
    first, _ = env.reset(options={"start": 0})
    rewards, obs = [], first
    while True:
        obs, r, terminated, truncated, info = env.step(scripted_policy(obs))
        rewards.append(r)
        if terminated or truncated:
            break
    expected = (reward.potential(*obs[-3:]) - reward.potential(*first[-3:])
                - reward.TIME_COST * (len(rewards) - 1) + reward.DOCKED)
    assert info["reason"] == "docked"
    assert math.isclose(sum(rewards), expected, rel_tol=1e-12, abs_tol=1e-9)
    assert reward.outcome_reward(False, "jackknife") == -reward.CRASH
    assert reward.outcome_reward(False, "timeout") == 0.0


def test_the_action_scale_reaches_each_lock_and_the_speed_limit():
    vehicle = artic.load_vehicle(VEHICLE)
    scale = ActionScale.of(vehicle)
    steering = vehicle.steering_for("kin")
    lock = vehicle.steering.delta_max
    # +1 and -1 reach the road wheels' lock on their side, 0 points them straight.
    for share, delta in ((1.0, lock), (-1.0, -lock), (0.0, 0.0)):
        cmd = scale.command(np.array([share, -1.0]))
        assert float(steering.road_wheel(cmd.delta_h)) == pytest.approx(delta, abs=1e-9)
        assert cmd.u1 == pytest.approx(-scale.speed)
    back = scale.action(scale.command(np.array([0.3, -0.7])))
    assert back == pytest.approx([0.3, -0.7], abs=1e-15)
    assert scale.command(np.array([5.0, 5.0])).u1 == scale.speed  # clipped, not scaled past


def test_a_recorded_episode_writes_artic_dock_s_recording(tmp_path):
    env = DockEnv(scenario="straight", vehicle=VEHICLE, yard_model="kin",
                  render_mode="rerun", recording_dir=tmp_path, timeout=2.0)
    info, _ = episode(env, lambda o: np.array([0.0, -0.5]), start=0)
    assert info["reason"] == "timeout"
    files = list(tmp_path.glob("*.rrd"))
    assert len(files) == 1 and files[0].stat().st_size > 1000


def test_the_sensor_set_reaches_the_run():
    # With the tractor's sensors the semitrailer's entries are the estimator's:
    # the observation differs from full's, the tractor's entries do not (the
    # same noise, sample for sample).
    seen = {}
    for sensors in ("full", "tractor"):
        env = DockEnv(scenario="straight", vehicle=VEHICLE, yard_model="kin", sensors=sensors)
        obs, _ = env.reset(options={"start": 0})
        obs, *_ = env.step(np.array([0.0, -0.5]))
        seen[sensors] = obs
        env.close()
    assert np.array_equal(seen["full"][:6], seen["tractor"][:6])
    assert not np.array_equal(seen["full"][6:13], seen["tractor"][6:13])


def test_bad_options_are_one_line():
    # Named as the Python caller gave them (keywords), not as command-line options.
    with pytest.raises(UserError, match="^scenario 'nowhere': no such scenario"):
        DockEnv(scenario="nowhere")
    with pytest.raises(UserError, match="^sensors lidar: no such sensor set"):
        DockEnv(sensors="lidar")
    with pytest.raises(UserError, match="render_mode"):
        DockEnv(render_mode="human")
    env = DockEnv(scenario="straight", yard_model="kin")
    with pytest.raises(RuntimeError, match="reset"):
        env.step(np.zeros(2))
    with pytest.raises(UserError, match=r"^options\['scenario'\] 'alle': no such scenario"):
        env.reset(options={"scenario": "alle"})
    for timeout in (-1.0, 0.0, math.nan):
        with pytest.raises(UserError, match="time limit must be a positive number of seconds"):
            DockEnv(scenario="straight", yard_model="kin", timeout=timeout).reset(seed=0)


def test_an_action_of_another_shape_or_not_finite_is_one_line():
    env = DockEnv(scenario="straight", vehicle=VEHICLE, yard_model="kin")
    env.reset(options={"start": 0})
    for action in ([0.0], [0.0, 0.0, 0.0], np.zeros((1, 2))):
        with pytest.raises(UserError, match=r"expected shape \(2,\)"):
            env.step(action)
    with pytest.raises(UserError, match="not finite"):
        env.step([math.nan, 0.0])
    # Refused before it reached the run: the episode goes on.
    obs, reward_, terminated, truncated, info = env.step(np.array([0.0, -0.5]))
    assert not terminated and not truncated and info["reason"] == ""
    env.close()


def test_an_unfinished_episode_is_stopped_by_reset_and_close():
    env = DockEnv(scenario="straight", vehicle=VEHICLE, yard_model="kin")
    env.reset(options={"start": 0})
    env.step(np.array([0.0, -0.5]))
    obs, _ = env.reset(options={"start": 1})  # the first run is stopped, a new one starts
    assert obs.shape == (17,)
    env.close()
    assert env._episode is None


@pytest.mark.parametrize("name", artic.gym.__all__)
def test_the_examples_of_the_gym_names_run(name, tmp_path, monkeypatch):
    import doctest

    monkeypatch.chdir(tmp_path)
    obj = getattr(artic.gym, name)
    if isinstance(obj, (dict, tuple)):
        return  # ENVIRONMENTS and the observation's names: data, documented in place
    tests = [t for t in doctest.DocTestFinder(recurse=False).find(obj, name) if t.examples]
    assert tests, f"artic.gym.{name} has no Examples section"
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS)
    for test in tests:
        runner.run(test)
    assert runner.summarize(verbose=False).failed == 0


def test_an_environment_dropped_without_close_stops_its_run():
    import gc

    from artic.plant import callback

    before = callback.active()
    env = DockEnv(scenario="straight", vehicle=VEHICLE)
    env.reset(options={"start": 0})
    assert callback.active() == before + 1  # the run's plant is open, waiting
    del env
    gc.collect()
    assert callback.active() == before


def test_the_environment_keeps_its_own_copies():
    # A wrapper that normalises the observation in place, or writes NaN into it,
    # changes nothing of the episode (issue 46, item 2: a 20-step reward sum went
    # from 0.51 to -244.7); nor does a change to the Observation it shows.
    def rewards(scribble: bool) -> list[float]:
        env = gym.make("artic/DockKIN-v0", scenario="straight")
        obs, _ = env.reset(seed=3)
        out = []
        for _ in range(20):
            if scribble:
                obs *= 100.0
                obs[-3] = math.nan
                env.unwrapped.observation.signals[:] = math.nan
            obs, r, *_ = env.step(np.array([0.0, -0.5]))
            out.append(r)
        env.close()
        return out

    assert rewards(True) == rewards(False)


def test_bad_reset_options_and_keywords_are_one_line_at_the_right_time():
    # Issue 46, item 10: each refused where it is given, naming the key.
    with pytest.raises(UserError, match=r"^keyword 'foo': not an option .*timeout"):
        gym.make("artic/DockKIN-v0", foo=1)  # at make, not at the first reset
    with pytest.raises(UserError, match=r"^keyword 'seed': the environment sets it itself"):
        gym.make("artic/DockKIN-v0", seed=1)
    with pytest.raises(UserError, match="^timeout 'x': a run's time limit"):
        gym.make("artic/DockKIN-v0", timeout="x")
    env = DockEnv(scenario="straight", vehicle=VEHICLE, yard_model="kin")
    with pytest.raises(UserError, match=r"^options\['strat'\]: not a reset option; "
                                        r"expected 'start' or 'scenario'"):
        env.reset(options={"strat": 3})  # a misspelt start drew a random one
    for start in (2.7, -1, 2**31 - 1, True, "2"):
        with pytest.raises(UserError, match=r"^options\['start'\] .*: expected an integer "
                                            r"from 0 to 2147483646"):
            env.reset(options={"start": start})
    obs, info = env.reset(options={"start": np.int64(2)})  # numpy's integers are integers
    assert info["start"] == 2 and obs.shape == (17,)
    env.close()
