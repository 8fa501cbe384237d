"""File permissions and temporary names shared by every writer of artic.

Writers put their content into a temporary ``.NAME.XXXX.part`` beside the
target (a unique name from :mod:`tempfile`, so concurrent writers never share
one) and rename it onto the target. ``tempfile`` creates such files 0600 and
folders 0700 whatever the umask; :func:`public_mode` gives them the mode a
plain ``open`` would have.
"""

from __future__ import annotations

import os
from pathlib import Path

TEMP_SUFFIX = ".part"
"""Suffix of every temporary artic writes beside a target."""


def umask() -> int:
    """The process's umask, read without changing it where the system allows."""
    try:
        with open("/proc/self/status", encoding="ascii") as f:
            for line in f:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError, IndexError):
        pass
    mask = os.umask(0o022)  # pragma: no cover - not Linux; brief, and not thread-safe
    os.umask(mask)  # pragma: no cover
    return mask  # pragma: no cover


def public_mode(path: Path | str) -> None:
    """Set a new file's mode to ``0666 & ~umask`` (a folder's to ``0777 & ~umask``)."""
    base = 0o777 if os.path.isdir(path) else 0o666
    os.chmod(path, base & ~umask())
