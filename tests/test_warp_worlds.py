"""Some worlds of the Warp plant at a time (artic.plant.warp_worlds): reset them, or hold them.

Skipped where the optional ``gpu`` extra (``mujoco-warp``, ``warp-lang``) is not installed.
"""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("warp", reason="the gpu extra (warp-lang) is not installed")
pytest.importorskip("mujoco_warp", reason="the gpu extra (mujoco-warp) is not installed")

import warp as wp  # noqa: E402

import artic  # noqa: E402
from artic.mjcf.errors import UserError  # noqa: E402
from artic.mjcf.interface import InitialState  # noqa: E402
from artic.plant.warp_plant import WarpPlant  # noqa: E402
from artic.plant.warp_worlds import Worlds  # noqa: E402

wp.config.quiet = True

HERE = InitialState(0.0, 0.0, 0.0, 0.0, u1=0.0)
THERE = InitialState(5.0, 1.0, 0.3, 0.05, u1=0.0)


def test_a_reset_world_is_a_fresh_plant_s_and_the_others_are_untouched():
    vehicle = artic.load_vehicle("gosar2022-unloaded")
    with WarpPlant(vehicle, n_worlds=3) as plant, WarpPlant(vehicle) as fresh:
        plant.reset(HERE)
        worlds = Worlds(plant)
        plant.step(0.05, 0.05, -1.0, 0.0)
        before, signals = plant.state(), plant.observe()
        got = worlds.reset([1], [THERE])
        after = plant.state()
        fresh.reset(THERE)
        # the reset world: what a plant reset there has, to the bit
        assert np.array_equal(after["qpos"][1], fresh.state()["qpos"][0])
        assert np.array_equal(got[0], fresh.observe()[0])
        assert not np.array_equal(after["qpos"][1], before["qpos"][1])
        for key in after:  # the others, to the bit
            assert np.array_equal(after[key][[0, 2]], before[key][[0, 2]]), key
        assert np.array_equal(plant.observe()[[0, 2]], signals[[0, 2]])
        # held: stepped with the batch and put back as kept; the others moved on
        worlds.keep()
        plant.step(0.05, 0.05, -1.0, 0.0)
        worlds.restore(wp.array(np.array([1, 0, 0], dtype=np.int32), dtype=int))
        held = plant.state()
        assert np.array_equal(held["qpos"][0], after["qpos"][0])
        assert not np.array_equal(held["qpos"][2], after["qpos"][2])


def test_bad_worlds_are_one_line():
    with WarpPlant(artic.load_vehicle("gosar2022-unloaded"), n_worlds=2) as plant:
        worlds = Worlds(plant)
        with pytest.raises(UserError, match=r"^world 2: not in the batch of 2 worlds; give "
                                            r"worlds from 0 to 1$"):
            worlds.reset([2], [HERE])
        with pytest.raises(UserError, match=r"^initial: 1 starts for 2 worlds; give one per "
                                            r"world$"):
            worlds.reset([0, 1], [HERE])
