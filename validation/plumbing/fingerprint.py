"""Fingerprints that tell a cached result from a stale one.

The campaign reuses what an earlier run wrote (generated logs, tuned
parameters, model runs) only when the fingerprint stored with it matches:
the hash of artic's own code and data files, of the MuJoCo and numpy
versions, and of the inputs of that result. Editing any module, preset or
tyre file that computes results therefore regenerates what depends on it
instead of reusing it. The modules that only present results
(:data:`PRESENTATION`: the report, tables, plots, recordings, the command
line and the pytest plugin) are left out: the campaign redraws those on
every run, so editing them reuses every cached simulation.
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
PRESENTATION = frozenset({
    "validation/campaign/report.py", "validation/review/tables.py",
    "validation/review/plots.py", "validation/review/recording.py",
    "validation/cli/commands.py", "validation/cli/entry.py", "validation/review/plantshape.py",
    "validation/plumbing/progress.py", "validation/campaign/rankings.py",
    "validation/campaign/seeds.py", "validation/campaign/seedreport.py",
    "validation/testing.py",
})
"""Files that turn results into text and pictures; no cached result depends on them."""


def code_hash(roots: dict[str, Path]) -> str:
    """Hash of the computing files under each package folder of ``roots`` (by package name)."""
    h = hashlib.sha256()
    h.update(f"mujoco {mujoco.__version__} numpy {np.__version__}".encode())
    for pkg in PACKAGES:
        root = Path(roots[pkg])
        for p in sorted(root.rglob("*")):
            rel = f"{pkg}/{p.relative_to(root).as_posix()}"
            if p.suffix in SUFFIXES and "__pycache__" not in p.parts and rel not in PRESENTATION:
                h.update(str(p.relative_to(root)).encode())
                h.update(p.read_bytes())
    return h.hexdigest()[:16]


@functools.cache
def code() -> str:
    """:func:`code_hash` of the installed artic packages.

    Found, not imported: hashing the plant's files does not load the plant
    (generating logs must not, ``tests/test_truth_driver.py``).
    """
    import importlib.util

    return code_hash({pkg: Path(importlib.util.find_spec(f"artic.{pkg}").origin).parent
                      for pkg in PACKAGES})


def key(*parts: Any) -> str:
    """Hash of the code fingerprint and ``parts`` (JSON-serialisable, or by ``str``)."""
    text = json.dumps([code(), *parts], sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()[:16]
