"""One number's possible and plausible ranges (:class:`Range`), and its warning.

The ranges themselves are the vehicle file's (:mod:`artic.mjcf.plausible`) and the
tyre file's (:mod:`artic.mjcf.tir`); both judge a value through this class.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

from artic.mjcf.errors import UserError


class PlausibilityWarning(UserWarning):
    """A parameter lies outside the range usual for a tractor-semitrailer."""


@dataclass(frozen=True)
class Range:
    """Possible ``[lo, hi]`` and plausible ``[plo, phi]`` values of one number, in its unit."""

    lo: float
    plo: float
    phi: float
    hi: float
    unit: str = ""

    def judge(self, value: float, where: str) -> None:
        """Refuse ``value`` outside the possible range, warn outside the plausible one.

        Parameters
        ----------
        value : float
            The number.
        where : str
            ``"FILE: key 'KEY'"``, for the messages.

        Raises
        ------
        ValueError
            Outside the possible range (the caller turns it into its file error).
        """
        if not math.isfinite(value):
            raise UserError(f"{where}: {value!r} is not a finite number")
        if not self.possible(value):
            raise UserError(f"{where}: {value:g}{self._u} is impossible for a "
                             f"tractor-semitrailer (possible: {self.span}); check the value "
                             "and its unit")
        self.warn(value, where, stacklevel=4)

    @property
    def _u(self) -> str:
        return f" {self.unit}" if self.unit else ""

    @property
    def span(self) -> str:
        """The possible range as text, ``"1 to 15 m"``."""
        return f"{self.lo:g} to {self.hi:g}{self._u}"

    def possible(self, value: float) -> bool:
        """Whether ``value`` lies in the possible range."""
        return self.lo <= value <= self.hi

    def warn(self, value: float, where: str, stacklevel: int = 3) -> None:
        """Warn (:class:`PlausibilityWarning`) when ``value`` is outside the plausible range."""
        if not self.plo <= value <= self.phi:
            warnings.warn(f"{where}: {value:g}{self._u} is unusual (usual: {self.plo:g} to "
                          f"{self.phi:g}{self._u}); check it", PlausibilityWarning,
                          stacklevel=stacklevel)
