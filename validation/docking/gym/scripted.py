"""A scripted policy: the round trip's stand-in for a trained one.

It reverses onto the door by a cascade a driver would recognise: the
articulation it wants grows with the rear's offset from the door's line and
its heading error, and the steering wheel turns the articulation towards it
(reversing, the articulation follows the steering against its sign). The speed
falls as the rear nears the face, and it stops within a quarter metre. It
docks the ``straight`` scenario; it is no match for the reference controller in
the alley. ``artic dock --controller artic.validation.docking.gym.scripted:Scripted``
scores it; ``DockEnv`` runs it as an agent.
"""

from __future__ import annotations

import numpy as np

from artic.validation.docking.gym.policy import policy_controller

LATERAL_GAIN = 0.15
"""Articulation wanted per metre of offset from the door's line [rad/m]."""

HEADING_GAIN = 1.0
"""Articulation wanted per radian of the semitrailer's heading error [-]."""

ARTICULATION_GAIN = 3.0
"""Steering-wheel share per radian of articulation error [1/rad]."""

GAMMA_WANTED_MAX = 0.4
"""Largest articulation it asks for [rad]."""


def scripted_policy(observation: np.ndarray) -> np.ndarray:
    """Action in [-1, 1]^2 for an observation vector (17,) [m, rad, m/s, rad/s].

    Examples
    --------
    Square and on the line, 10 m out: straight back at 60 % of the speed limit.

    >>> import numpy as np
    >>> o = np.zeros(17); o[-3] = 10.0
    >>> scripted_policy(o).tolist()
    [0.0, -0.6]
    """
    distance, lateral, heading = observation[-3:]
    gamma = observation[12]
    wanted = np.clip(-LATERAL_GAIN * lateral + HEADING_GAIN * heading,
                     -GAMMA_WANTED_MAX, GAMMA_WANTED_MAX)
    steer = float(np.clip(-ARTICULATION_GAIN * (wanted - gamma), -1.0, 1.0))
    speed = -0.6 if distance > 1.5 else (-0.2 if distance > 0.25 else 0.0)
    return np.array([steer + 0.0, speed])


Scripted = policy_controller(scripted_policy, name="scripted")
""":func:`scripted_policy` as a controller."""
