"""artic's docking environments for Gymnasium (``pip install "artic[gym]"``).

Importing this module registers

- ``artic/Dock-v0``: the docking scenarios on the multibody plant;
- ``artic/DockKIN-v0``: the same on KIN, for fast prototyping.

``gymnasium.make("artic.gym:artic/Dock-v0")`` imports it for you, and
``gymnasium.make_vec(..., vectorization_mode="vector_entry_point")`` gives
:class:`DockVectorEnv`, the environments stepped side by side in one process
(with ``backend="warp", device="cuda"``, ``artic/Dock-v0``'s plants as the worlds
of one Warp plant on a GPU, ``pip install "artic[gpu]"``). The
environment is :class:`~artic.validation.docking.gym.env.DockEnv`; a trained
policy goes back into ``artic dock --controller`` through
:func:`policy_controller`. The docking guide shows the round trip.
"""

from __future__ import annotations

import gymnasium as gym

from artic.validation.docking.gym.env import DockEnv
from artic.validation.docking.gym.policy import PolicyController, policy_controller
from artic.validation.docking.gym.spaces import (
    OBSERVATION_NAMES,
    OBSERVATION_UNITS,
    ActionScale,
    observation_vector,
)
from artic.validation.docking.gym.vector import DockVectorEnv

__all__ = ["DockEnv", "DockVectorEnv", "PolicyController", "policy_controller", "ActionScale",
           "OBSERVATION_NAMES", "OBSERVATION_UNITS", "observation_vector", "ENVIRONMENTS"]

ENVIRONMENTS = {"artic/Dock-v0": "mbd", "artic/DockKIN-v0": "kin"}
"""The registered environments and what each drives."""

for _id, _model in ENVIRONMENTS.items():
    if _id not in gym.registry:
        gym.register(id=_id, entry_point="artic.validation.docking.gym.env:DockEnv",
                     vector_entry_point="artic.validation.docking.gym.vector:vector_env",
                     kwargs={"yard_model": _model})
