"""artic's errors: one base, the user's errors and the plant's.

Every error artic raises on purpose derives from :class:`ArticError`, and is
one of two kinds:

- :class:`UserError`: the input (a vehicle file, a log, an option, a model
  asked of a vehicle it cannot represent) is wrong, and the one-line message
  names the file, column or option and what to change. The command line ends
  with exit code 2 and that line, without a traceback. It is a
  :class:`ValueError`, so code that caught ``ValueError`` still does.
- :class:`PlantError`: the multibody simulation failed (diverged); the
  message names the time and the wheel. The command line ends with exit code 1.

Anything else that escapes a command is a bug in artic: the command line
prints its traceback and asks for a report.

This module is artic's lowest layer (:mod:`artic.mjcf`), so that every layer
may raise these errors; it imports nothing.
"""

from __future__ import annotations

__all__ = ["ArticError", "PlantError", "UnsupportedVehicleError", "UserError", "one_line"]


class ArticError(Exception):
    """The base of every error artic raises on purpose."""


class UserError(ArticError, ValueError):
    """The user's input is wrong; the message says where and what to change."""


class UnsupportedVehicleError(UserError):
    """A model cannot represent this vehicle (for example the STM without tyre data)."""


class PlantError(ArticError, RuntimeError):
    """The simulation diverged; the message names the time and the wheel.

    Examples
    --------
    >>> import artic
    >>> issubclass(artic.PlantError, artic.errors.ArticError)
    True
    >>> issubclass(artic.PlantError, artic.errors.UserError)  # not the user's fault
    False
    """


def one_line(what: BaseException | str) -> str:
    """``what`` as one line: its message with every run of whitespace one space.

    An exception without a message is named by its type, so a line never ends
    empty (``"failed: KeyError"`` rather than ``"failed: "``). The command line's
    messages and the failed runs' statuses are written with it.
    """
    text = " ".join(str(what).split())
    if not text and isinstance(what, BaseException):
        return type(what).__name__
    return text
