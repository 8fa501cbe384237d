"""artic's errors, by kind: ``except artic.errors.UserError`` catches every wrong input.

- :class:`ArticError`: the base of every error artic raises on purpose;
- :class:`UserError` (a :class:`ValueError`): a vehicle file, a log, an option
  or a model asked of a vehicle it cannot represent is wrong, and the one-line
  message names where and what to change (:class:`artic.VehicleFileError`,
  :class:`artic.LogError` and :class:`UnsupportedVehicleError` are user errors);
- :class:`PlantError` (a :class:`RuntimeError`): the multibody simulation failed.

The command line ends with exit code 2 on a user error, 1 on a plant error, and
prints the traceback of anything else (a bug: please report it). The classes
live in :mod:`artic.mjcf.errors`, artic's lowest layer, so every layer raises them.

Examples
--------
>>> import artic.errors
>>> try:
...     artic.load_vehicle("no-such-truck")
... except artic.errors.UserError as error:
...     print(type(error).__name__)
VehicleFileError
"""

from artic.mjcf.errors import ArticError, PlantError, UnsupportedVehicleError, UserError

__all__ = ["ArticError", "PlantError", "UnsupportedVehicleError", "UserError"]
