"""A policy function as a docking controller: ``artic dock --controller module:Class``.

A policy maps the environment's observation vector
(:func:`~artic.validation.docking.gym.spaces.observation_vector`) to an action
in [-1, 1]^2 (:class:`~artic.validation.docking.gym.spaces.ActionScale`).
:func:`policy_controller` wraps one in a :class:`~artic.Controller`, so a
learned controller is scored with the same table, intervals and recordings as
the built-in ones, and sees exactly what the environment showed it in training.

A user's module, for ``artic dock --controller my_policies:Learned``::

    import numpy as np
    from artic.gym import policy_controller

    weights = np.load("policy.npz")        # whatever the policy needs

    def act(observation):                  # 17 numbers -> 2 in [-1, 1]
        return np.tanh(weights["W"] @ observation)

    Learned = policy_controller(act, name="learned")
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from artic.validation.docking.controllers.base import Command, Controller, Observation, Task
from artic.validation.docking.gym.spaces import ActionScale, observation_vector, stopped_at_dock

Policy = Callable[[np.ndarray], np.ndarray]
"""Observation vector (17,) -> action (2,) in [-1, 1]."""


class PolicyController(Controller):
    """A controller that asks :attr:`policy` for each command.

    Subclass it and set ``policy``, or use :func:`policy_controller`.
    The run ends when the policy stops at the dock
    (:func:`~artic.validation.docking.gym.spaces.stopped_at_dock`).

    Examples
    --------
    A policy that reverses straight at half the speed limit:

    >>> import numpy as np
    >>> import artic
    >>> from artic.gym import policy_controller
    >>> from artic.validation.docking.controllers.base import Observation, Task
    >>> from artic.validation.docking.scenarios import make_yard
    >>> Straight = policy_controller(lambda o: np.array([0.0, -0.5]), name="straight")
    >>> vehicle = artic.load_vehicle("gosar2022-unloaded")
    >>> ctrl = Straight()
    >>> ctrl.reset(Task(vehicle, make_yard(vehicle), None, dt=0.1, speed=1.0,
    ...                 speed_max=1.67, accel_max=0.5, steer_rate=6.3))
    >>> cmd = ctrl.command(Observation(t=0.0, signals=np.zeros(13), delta_h=0.0))
    >>> round(cmd.u1, 3), cmd.done
    (-0.833, False)
    """

    name = "policy"
    policy: Policy

    def reset(self, task: Task) -> None:
        """Start a run: the base's helpers and the vehicle's action scale."""
        super().reset(task)
        self.scale = ActionScale.of(task.vehicle)

    def command(self, obs: Observation) -> Command:
        """The policy's action as a command; done when it stops at the dock."""
        vector = observation_vector(obs, self)
        action = np.asarray(self.policy(vector), float)
        if action.shape != (2,):
            raise ValueError(f"the policy returned shape {action.shape}; expected (2,): "
                             "steering wheel and speed in [-1, 1]")
        cmd = self.scale.command(action)
        if stopped_at_dock(cmd, float(vector[-3])):
            return Command(cmd.delta_h, 0.0, done=True)
        return cmd


def policy_controller(policy: Policy, name: str = "policy") -> type[PolicyController]:
    """A :class:`PolicyController` class that calls ``policy``.

    Parameters
    ----------
    policy : callable
        Observation vector (17,) [m, rad, m/s, rad/s] -> action (2,) in [-1, 1].
    name : str
        The controller's name in tables.

    Returns
    -------
    type
        A class with a no-argument constructor, for ``artic dock --controller``
        (bind it to a module-level name) or :func:`artic.validation.docking.run.drive`.

    Examples
    --------
    >>> import numpy as np
    >>> from artic.gym import policy_controller
    >>> Creep = policy_controller(lambda observation: np.array([0.0, -0.1]), name="creep")
    >>> Creep.name, Creep().policy(np.zeros(17)).tolist()
    ('creep', [0.0, -0.1])
    """
    return type(f"Policy_{name}", (PolicyController,),
                {"name": name, "policy": staticmethod(policy)})
