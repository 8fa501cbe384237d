"""Reader for tyre property files (``.tir``, ADAMS/TNO format, PAC2002).

A ``.tir`` file has ``[SECTION]`` headers and ``KEY = value`` lines. Values
are numbers or quoted strings. ``$`` starts a comment, and ``!`` starts a
comment line. The reader keeps the sections, converts numbers, and refuses
what it cannot read, with the file and line in the message; it never quotes
the file's content, so that a misnamed file is not echoed to the terminal.

Every number must be finite. The coefficients the plant uses are judged
against :data:`COEFFICIENT_RANGES` (see :class:`artic.mjcf.ranges.Range`): an
impossible value (a zero relaxation length, a negative radius, a friction
of 50) is refused naming the key, an unusual one warned about. Pairs of
range limits must be ordered.
"""

from __future__ import annotations

import functools
import math
import re
from dataclasses import dataclass
from pathlib import Path

from artic.mjcf.errors import UserError
from artic.mjcf.ranges import Range

_SECTION = re.compile(r"^\[(?P<name>[A-Z0-9_]+)\]\s*$")
_ENTRY = re.compile(r"^(?P<key>[A-Za-z_][A-Za-z0-9_]*)\s*=\s*(?P<value>.+?)\s*$")


class TirError(UserError):
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
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise TirError(f"{path}: cannot read ({exc.strerror or exc})") from exc
    if len(data) > MAX_BYTES:
        raise TirError(f"{path}: {len(data)} bytes; a tyre property file is at most "
                       f"{MAX_BYTES} bytes")
    if b"\0" in data:
        raise TirError(f"{path}: a binary file, not a tyre property file")
    parsed = _parse(str(path), data)
    tir = TirFile(str(path), {name: dict(entries) for name, entries in parsed.items()})
    check_coefficients(tir)
    return tir


@functools.lru_cache(maxsize=16)
def _parse(path: str, data: bytes) -> dict[str, dict[str, float | str]]:
    """The sections of a ``.tir`` file's bytes (``path`` names it in errors).

    Kept for the last few files: a campaign builds its vehicles hundreds of
    times from the same two or three tyre files, and parsing one takes about
    half a millisecond. :func:`read_tir` hands every caller its own copy.
    """
    sections: dict[str, dict[str, float | str]] = {}
    current = "_"
    for n, raw in enumerate(data.decode("latin-1").splitlines(), start=1):
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
            raise TirError(f"{path}:{n}: line {n} is neither a [SECTION], a KEY = value entry "
                           "nor a comment: is this a .tir file?")
        value = m["value"]
        if value[:1] in "'\"":
            parsed: float | str = value.strip("'\"").strip()
        else:
            try:
                parsed = float(value)
            except ValueError as exc:
                raise TirError(f"{path}:{n}: key {m['key']}: the value is not a number; "
                               "quote text values") from exc
            if not math.isfinite(parsed):
                raise TirError(f"{path}:{n}: key {m['key']}: {parsed!r} is not a finite "
                               "number")
        sections.setdefault(current, {})[m["key"]] = parsed
    fmt = sections.get("MODEL", {}).get("PROPERTY_FILE_FORMAT", "")
    if fmt and str(fmt).upper() not in ("PAC2002", "MF_05", "PAC2002_05"):
        raise TirError(f"{path}: key PROPERTY_FILE_FORMAT: the format is not PAC2002")
    return sections


MAX_BYTES = 1 << 20
"""Largest tyre property file read [B]."""

_SCALE = Range(0.0, 0.1, 10.0, 100.0)

COEFFICIENT_RANGES: dict[str, Range] = {
    "UNLOADED_RADIUS": Range(0.05, 0.2, 1.0, 3.0, "m"),
    "VERTICAL_STIFFNESS": Range(1e3, 1e5, 1e7, 1e10, "N/m"),
    "VERTICAL_DAMPING": Range(0.0, 0.0, 1e5, 1e8, "N s/m"),
    "FNOMIN": Range(10.0, 1e3, 1e5, 1e7, "N"),
    "LONGVL": Range(0.1, 1.0, 50.0, 1e3, "m/s"),
    "VXLOW": Range(1e-3, 0.1, 5.0, 100.0, "m/s"),
    "FZMIN": Range(0.0, 0.0, 1e4, 1e7, "N"),
    "FZMAX": Range(1.0, 1e3, 1e6, 1e8, "N"),
    "PCX1": Range(0.1, 1.0, 2.5, 10.0),
    "PDX1": Range(0.01, 0.3, 1.5, 5.0),
    "PKX1": Range(0.01, 2.0, 80.0, 1e3),
    "PEX1": Range(-100.0, -10.0, 1.0, 100.0),
    "PCY1": Range(0.1, 1.0, 2.5, 10.0),
    "PDY1": Range(-5.0, -1.5, 1.5, 5.0),
    "PEY1": Range(-100.0, -10.0, 1.0, 100.0),
    "PKY1": Range(-1e3, -80.0, 80.0, 1e3),
    "PKY2": Range(0.01, 0.5, 10.0, 1e3),
    "PTX1": Range(1e-3, 0.1, 10.0, 100.0),
    "PTX3": Range(-10.0, -3.0, 3.0, 10.0),
    "PTX4": Range(0.0, 0.0, 2.0, 100.0),
    "PTY1": Range(1e-3, 0.1, 10.0, 100.0),
    "PTY2": Range(0.01, 0.5, 10.0, 1e3),
    "RBX1": Range(0.0, 0.0, 100.0, 1e4),
    "RBY1": Range(0.0, 0.0, 100.0, 1e4),
    "QSY1": Range(0.0, 0.0, 0.05, 1.0),
    **{k: _SCALE for k in ("LFZO", "LCX", "LMUX", "LKX", "LCY", "LMUY", "LKY", "LXAL",
                           "LYKA", "LSGKP", "LSGAL", "LMY", "LEX", "LEY")},
}
"""Coefficients the plant uses and their possible and plausible values. ``PDY1`` and
``PKY1`` carry the file's slip-angle sign, so either sign is possible; the divisions of the
model (by ``FNOMIN * LFZO``, ``PKY2``, ``PTY1``, ``PTY2``, ``PTX1``, ``LONGVL``, ``VXLOW``)
make zero impossible for those."""

_NONZERO = ("PDY1", "PKY1", "LFZO", "LSGKP", "LSGAL")
"""Coefficients that the model divides by, or whose zero leaves a tyre without force."""

_ORDERED = (("FZMIN", "FZMAX"), ("KPUMIN", "KPUMAX"), ("ALPMIN", "ALPMAX"))


def check_coefficients(tir: TirFile) -> None:
    """Judge the coefficients present in ``tir`` (see :data:`COEFFICIENT_RANGES`).

    Raises
    ------
    TirError
        For an impossible value or a range whose limits are not in order, naming the key.
    """
    for sec in tir.sections.values():
        for key, value in sec.items():
            if isinstance(value, str):
                continue
            rng = COEFFICIENT_RANGES.get(key)
            if rng is not None:
                try:
                    rng.judge(value, f"{tir.path}: key {key}")
                except ValueError as exc:
                    raise TirError(str(exc)) from None
            if key in _NONZERO and value == 0.0:
                raise TirError(f"{tir.path}: key {key}: must not be zero")
    for lo, hi in _ORDERED:
        a, b = tir.number(lo, math.nan), tir.number(hi, math.nan)
        if math.isfinite(a) and math.isfinite(b) and not a < b:
            raise TirError(f"{tir.path}: keys {lo}, {hi}: {lo} = {a:g} must be below "
                           f"{hi} = {b:g}")
