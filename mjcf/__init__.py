"""Vehicle description and MJCF generation.

``artic.mjcf.vehicle`` reads the vehicle parameter file that every other part of
artic derives its numbers from. The MJCF generator (which needs mujoco) is
imported from its own module, so importing this package stays light.
"""

from artic.mjcf.schema import VehicleFileError
from artic.mjcf.vehicle import Axle, Steering, Vehicle, load_vehicle, preset_names

__all__ = ["Axle", "Steering", "Vehicle", "VehicleFileError", "load_vehicle", "preset_names"]
