"""The speed follower's integral gain, which the plant and its compiled loop share.

A module of its own so that :mod:`artic.plant.closedloop` reads it without
importing :mod:`artic.plant.plant`, which imports the loop.
"""

FOLLOW_KI = 5.0
"""Speed follower: integral gain [1/s] on the speed error, added to the servo's
set-point. With the servo's 20 /s bandwidth the loop is critically damped
(``s^2 + 20 s + 100``)."""
