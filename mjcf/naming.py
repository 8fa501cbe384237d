"""Every MJCF name, generated in one place.

Bodies, joints, sites, actuators and equalities of the generated model are
named here and nowhere else, so the plant finds them by the same functions
that made them. Sides are ``L`` and ``R``; axles keep the parameter file's names.
"""

from __future__ import annotations

SIDES = ("L", "R")

TRACTOR = "tractor"
TRAILER = "trailer"
ROOT = "root"
HITCH_YAW = "hitch.yaw"
HITCH_PITCH = "hitch.pitch"
DOCK = "dock"
SPEED_SITE = "speed.follower"
"""Site on the drive axle at ground level where the speed follower pushes."""
SPEED_SERVO = "speed.servo"
"""The speed follower's velocity servo (see :mod:`artic.plant.plant`)."""


def unit(u: int) -> str:
    """Body of unit 1 (tractor) or 2 (semitrailer)."""
    return TRACTOR if u == 1 else TRAILER


def sensor(u: int) -> str:
    """Site of a unit's motion sensor."""
    return f"sensor.{unit(u)}"


def axle(name: str) -> str:
    """Body of an axle (its unsprung mass), sliding on the suspension."""
    return f"axle.{name}"


def suspension(name: str) -> str:
    """Slide joint of an axle's suspension."""
    return f"suspension.{name}"


def knuckle(name: str, side: str) -> str:
    """Steering knuckle body of a steered wheel end."""
    return f"knuckle.{name}.{side}"


def steer(name: str, side: str) -> str:
    """Steering hinge of a steered wheel end."""
    return f"steer.{name}.{side}"


def wheel(name: str, side: str) -> str:
    """Wheel body (a wheel, or a dual pair) of a wheel end."""
    return f"wheel.{name}.{side}"


def spin(name: str, side: str) -> str:
    """Spin hinge of a wheel end."""
    return f"spin.{name}.{side}"


def hub(name: str, side: str) -> str:
    """Site at a wheel centre, on the non-spinning carrier: the tyre's frame."""
    return f"hub.{name}.{side}"


def servo(name: str) -> str:
    """Position servo that turns a steered axle's left wheel."""
    return f"servo.{name}"


def tie_rod(name: str) -> str:
    """Joint equality that makes the right wheel follow the left."""
    return f"tierod.{name}"


def drive(name: str, side: str) -> str:
    """Drive-torque actuator of a driven wheel end."""
    return f"drive.{name}.{side}"


def brake(name: str, side: str) -> str:
    """Brake-torque actuator of a wheel end."""
    return f"brake.{name}.{side}"


def tread(name: str, side: str, direction: str) -> str:
    """Integrator actuator holding a tyre's tread deflection, ``u`` or ``v``."""
    return f"tread.{name}.{side}.{direction}"
