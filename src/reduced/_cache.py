"""Where numba keeps artic's compiled functions, so that a stale one is never loaded.

numba's on-disk cache checks only the source file of the function it caches.
A cached function that calls into another module (``rk4_step`` into the STM's
right-hand side, the harness loop into both) keeps the old callee after that
module is edited, and silently computes the old equations. So artic's
functions are cached in a folder named by the hash of every artic source
file: editing any of them moves the cache to a fresh folder. Folders no
version has used for :data:`STALE_DAYS` are removed. Setting
``NUMBA_CACHE_DIR`` yourself overrides this.

Imported by ``reduced`` before any compiled function is defined; the folder
is chosen when a function is decorated.
"""

from __future__ import annotations

import hashlib
import os
import shutil
import time
from pathlib import Path

import numba

PACKAGES = ("mjcf", "plant", "reduced", "validation")

STALE_DAYS = 30
"""Cache folders unused for this long are removed [days]."""


def source_hash(root: Path | None = None) -> str:
    """Hash of the artic packages' Python sources under ``root`` (beside this package)."""
    root = Path(__file__).resolve().parents[1] if root is None else Path(root)
    h = hashlib.sha256(numba.__version__.encode())
    for pkg in PACKAGES:
        for p in sorted((root / pkg).glob("*.py")):
            h.update(p.name.encode())
            h.update(p.read_bytes())
    return h.hexdigest()[:12]


def configure() -> Path | None:
    """Point numba's cache at ``$XDG_CACHE_HOME/artic/numba/<hash>`` (or ~/.cache).

    Returns the folder, or ``None`` when ``NUMBA_CACHE_DIR`` is set by the user.
    """
    if os.environ.get("NUMBA_CACHE_DIR"):
        return None
    base = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "artic" / "numba"
    folder = base / source_hash()
    try:
        folder.mkdir(parents=True, exist_ok=True)
        os.utime(folder)  # in use: its age counts from now
        # Folders of other versions (another environment may still use one)
        # go once nothing has used them for STALE_DAYS.
        cutoff = time.time() - STALE_DAYS * 86400.0
        for old in base.iterdir():
            if old != folder and old.is_dir() and old.stat().st_mtime < cutoff:
                shutil.rmtree(old, ignore_errors=True)
    except OSError:  # a read-only home: numba falls back to its own locations
        return None
    numba.config.CACHE_DIR = str(folder)
    return folder


CACHE_DIR = configure()
