"""The front door's docstrings link their neighbours (python-control's See Also sections).

Each public function and class of ``artic`` (its ``__all__``) names, under
``See Also``, the public names a user reaches for next, and only public names,
so that every link resolves in the API reference.
"""

from __future__ import annotations

import inspect
import re

import pytest

import artic

WITHOUT = {
    "__version__": "a string",
    "errors": "a module of error classes",
    "KinematicModel": "a former name of KIN",
    "SingleTrackModel": "a former name of STM",
    "LogError": "an error class", "PlantError": "an error class",
    "VehicleFileError": "an error class",
}
"""Public names without a See Also section, and why."""

LINKED = sorted(set(artic.__all__) - set(WITHOUT))


def see_also(obj: object) -> list[str]:
    """The ``artic.NAME`` entries of ``obj``'s See Also section, in order."""
    doc = inspect.cleandoc(obj.__doc__ or "")
    found = re.search(r"^See Also\n-+\n(.*?)(?:\n\n|\Z)", doc, re.S | re.M)
    if found is None:
        return []
    return re.findall(r"^artic\.(\w+) : \S", found.group(1), re.M)


@pytest.mark.parametrize("name", LINKED)
def test_every_public_name_links_its_neighbours(name):
    links = see_also(getattr(artic, name))
    assert links, f"artic.{name}: no See Also section naming artic.NAME : description lines"
    assert set(links) <= set(artic.__all__), f"artic.{name} links non-public names: {links}"
    assert name not in links, f"artic.{name} links itself"


def test_the_section_is_found_and_read():
    # The parser reads a section of two entries and stops at the blank line after it.
    class Example:
        """One line.

        See Also
        --------
        artic.KIN : the kinematic model.
        artic.STM : the single-track model.

        Examples
        --------
        artic.Plant : not a link.
        """

    assert see_also(Example) == ["KIN", "STM"]
