"""Reader for tyre property files (``.tir``, ADAMS/TNO format, PAC2002).

A ``.tir`` file has ``[SECTION]`` headers and ``KEY = value`` lines. Values
are numbers or quoted strings. ``$`` starts a comment, and ``!`` starts a
comment line. The reader keeps the sections, converts numbers, and refuses
what it cannot read, with the file and line in the message.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

_SECTION = re.compile(r"^\[(?P<name>[A-Z0-9_]+)\]\s*$")
_ENTRY = re.compile(r"^(?P<key>[A-Za-z_][A-Za-z0-9_]*)\s*=\s*(?P<value>.+?)\s*$")


class TirError(ValueError):
    """A tyre property file cannot be used; the message names the file and key or line."""


@dataclass(frozen=True)
class TirFile:
    """The contents of a ``.tir`` file.

    Parameters
    ----------
    path : str
        Where it was read from.
    sections : dict
        ``{SECTION: {KEY: float or str}}``.
    """

    path: str
    sections: dict[str, dict[str, float | str]]

    def number(self, key: str, default: float | None = None) -> float:
        """A numeric value, looked up in any section.

        Raises
        ------
        TirError
            If the key is absent (and no default is given) or not a number.
        """
        for sec in self.sections.values():
            if key in sec:
                value = sec[key]
                if isinstance(value, str):
                    raise TirError(f"{self.path}: key {key}: expected a number, got '{value}'")
                return value
        if default is None:
            raise TirError(f"{self.path}: key {key}: missing; a PAC2002 file needs it")
        return default

    def text(self, key: str, default: str = "") -> str:
        """A string value, looked up in any section."""
        for sec in self.sections.values():
            if key in sec:
                return str(sec[key])
        return default


def read_tir(path: str | Path) -> TirFile:
    """Read a ``.tir`` file.

    Parameters
    ----------
    path : str or Path
        The file.

    Raises
    ------
    TirError
        For a missing file, a line that is neither section, entry nor
        comment, or a value that is neither a number nor a quoted string.
    """
    path = Path(path)
    if not path.is_file():
        raise TirError(f"{path}: no such tyre property file")
    sections: dict[str, dict[str, float | str]] = {}
    current = "_"
    for n, raw in enumerate(path.read_text(encoding="latin-1").splitlines(), start=1):
        line = raw.split("$", 1)[0].strip()
        if not line or line.startswith("!"):
            continue
        m = _SECTION.match(line)
        if m:
            current = m["name"]
            sections.setdefault(current, {})
            continue
        m = _ENTRY.match(line)
        if not m:
            raise TirError(f"{path}:{n}: cannot read line {raw.strip()!r}")
        value = m["value"]
        if value[:1] in "'\"":
            parsed: float | str = value.strip("'\"").strip()
        else:
            try:
                parsed = float(value)
            except ValueError as exc:
                raise TirError(f"{path}:{n}: key {m['key']}: {value!r} is not a number; "
                               "quote text values") from exc
        sections.setdefault(current, {})[m["key"]] = parsed
    fmt = sections.get("MODEL", {}).get("PROPERTY_FILE_FORMAT", "")
    if fmt and str(fmt).upper() not in ("PAC2002", "MF_05", "PAC2002_05"):
        raise TirError(f"{path}: key PROPERTY_FILE_FORMAT: '{fmt}' is not PAC2002")
    return TirFile(str(path), sections)
