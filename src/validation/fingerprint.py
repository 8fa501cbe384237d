"""Fingerprints that tell a cached result from a stale one.

The campaign reuses what an earlier run wrote (generated logs, tuned
parameters, model runs) only when the fingerprint stored with it matches:
the hash of artic's own code and data files, of the MuJoCo and numpy
versions, and of the inputs of that result. Editing any module, preset or
tyre file therefore regenerates what depends on it instead of reusing it.
"""

from __future__ import annotations

import functools
import hashlib
import json
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

PACKAGES = ("mjcf", "plant", "reduced", "validation")
SUFFIXES = (".py", ".c", ".toml", ".tir")


@functools.cache
def code() -> str:
    """Hash of artic's source and data files and of the numeric libraries' versions."""
    h = hashlib.sha256()
    h.update(f"mujoco {mujoco.__version__} numpy {np.__version__}".encode())
    for pkg in PACKAGES:
        root = Path(__import__(pkg).__file__).parent
        for p in sorted(root.rglob("*")):
            if p.suffix in SUFFIXES and "__pycache__" not in p.parts:
                h.update(str(p.relative_to(root)).encode())
                h.update(p.read_bytes())
    return h.hexdigest()[:16]


def key(*parts: Any) -> str:
    """Hash of the code fingerprint and ``parts`` (JSON-serialisable, or by ``str``)."""
    text = json.dumps([code(), *parts], sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()[:16]
