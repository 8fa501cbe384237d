"""The campaign's one cache: each stage's outputs under the key of the inputs that made them.

A stage's key (:meth:`StageCache.key`) is the hash of

- artic's code and data (:func:`artic.validation.plumbing.fingerprint.code`: every
  module, preset and tyre file that computes results, the MuJoCo and numpy
  versions), and a registered model's own code where the stage runs it;
- the :class:`~artic.validation.campaign.config.CampaignConfig` fields the
  stage's results depend on (say, the gain for validation, not for tuning);
- the keys of the stages whose outputs it reads. Same inputs give the same
  numbers, so an upstream key stands for its outputs' contents; an input
  file from outside artic enters by its content hash (:func:`file_hash`).

An entry, ``OUT/cache/STAGE.json``, holds the key, each output file's path
(relative to ``OUT``) with its size and modification time, and a small JSON
payload a stage may keep there (the gain sweep's rows, the efficiency). It is
written atomically, after the outputs. :meth:`StageCache.lookup` trusts an
entry only if it parses, its key is the one asked for, and every output it
names is still there with the size and time it was recorded with; anything
else (a corrupted entry, another key, an output deleted, rewritten or cut
short) is a miss, and the stage computes again. A stage that computes may
still resume inside itself from what an interrupted run finished (the
generated exports, the fits so far in ``tuning.json``, the run files, each
carrying this stage's key), which is what makes an interrupted campaign pick
up where it stopped.

Each stage returns a :class:`StageResult`: what it produced, its key, and
whether it was reused.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from artic.validation.logs.runfile import atomic_write_text
from artic.validation.plumbing import fingerprint

FOLDER = "cache"
"""The entries' folder under the campaign's output folder."""


@dataclass(frozen=True)
class StageResult:
    """What one stage produced.

    Parameters
    ----------
    name : str
        The stage (``logs``, ``tuning``, ...).
    key : str
        Its cache key (:meth:`StageCache.key`); the stages that read its
        outputs put it into theirs.
    reused : bool
        Whether its outputs came from an earlier run's entry, nothing computed.
    outputs : dict of str to Path
        Its result files by name.
    value : object
        The in-memory result the next stages use (logs, a metrics table, ...).
    """

    name: str
    key: str
    reused: bool
    outputs: dict[str, Path] = field(default_factory=dict)
    value: Any = None


@dataclass(frozen=True)
class Entry:
    """A valid cache entry: its outputs (absolute paths by name) and its payload."""

    key: str
    outputs: dict[str, Path]
    data: dict[str, Any]


def file_hash(path: Path) -> str:
    """SHA-256 of a file's bytes (an input from outside artic, for a key) [hex, 16 digits]."""
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()[:16]


class StageCache:
    r"""The stage entries of one campaign's output folder (see the module docstring).

    Parameters
    ----------
    out_dir : Path
        The campaign's output folder; entries go to ``out_dir/cache``.
    progress : callable, optional
        Receives one line when an entry is found but not trusted, saying why.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from artic.validation.campaign.cache import StageCache
    >>> out = Path(tempfile.mkdtemp())
    >>> cache = StageCache(out)
    >>> key = cache.key("tables", {"gain": 1.0})
    >>> _ = (out / "t.csv").write_text("a\\n1\\n")
    >>> cache.store("tables", key, {"table": out / "t.csv"})
    >>> cache.lookup("tables", key).outputs["table"].name
    't.csv'
    >>> _ = (out / "t.csv").write_text("a\\n2 changed\\n")  # an output rewritten: a miss
    >>> cache.lookup("tables", key) is None
    True
    """

    def __init__(self, out_dir: Path, progress: Any = None) -> None:
        self.out_dir = Path(out_dir)
        self.progress = progress

    def path(self, stage: str) -> Path:
        """The entry file of ``stage``."""
        return self.out_dir / FOLDER / f"{stage.replace(' ', '_')}.json"

    @staticmethod
    def key(stage: str, fields: Mapping[str, Any],
            upstream: Iterable[StageResult | str] = ()) -> str:
        """The key of ``stage`` from its config ``fields`` and the stages it reads.

        Parameters
        ----------
        stage : str
            The stage's name (two stages never share a key).
        fields : mapping
            The configuration fields (and any other inputs, file hashes
            included) its results depend on; JSON-serialisable, or by ``str``.
        upstream : iterable of StageResult or str
            The stages (or their keys) whose outputs it reads.

        Returns
        -------
        str
            16 hex digits, with artic's code fingerprint in them.
        """
        ups = [u.key if isinstance(u, StageResult) else str(u) for u in upstream]
        return fingerprint.key("stage", stage, dict(fields), ups)

    def lookup(self, stage: str, key: str, quiet: bool = False) -> Entry | None:
        """The entry of ``stage`` if it was stored with ``key`` and its outputs are intact.

        ``quiet``: say nothing about an entry not trusted (a look ahead).
        """
        say = (lambda line: None) if quiet else self._say
        path = self.path(stage)
        if not path.is_file():
            return None
        why = None
        try:
            saved = json.loads(path.read_text(encoding="utf-8"))
            if not isinstance(saved, dict) or not isinstance(saved.get("outputs"), dict):
                raise ValueError("not an entry")
        except (OSError, ValueError, RecursionError) as exc:
            say(f"{path}: unreadable ({type(exc).__name__}); the stage computes again")
            return None
        if saved.get("key") != key:
            return None  # another campaign's, or other code's: not an error
        outputs = {}
        for name, rec in saved["outputs"].items():
            try:
                target = self.out_dir / rec["path"]
                st = target.stat()
                if (st.st_size, st.st_mtime_ns) != (rec["size"], rec["mtime_ns"]):
                    why = f"{rec['path']} changed since it was made"
            except (OSError, KeyError, TypeError):
                why = f"output {name} missing"
            if why:
                say(f"{stage}: {why}; the stage computes again")
                return None
            outputs[name] = target
        data = saved.get("data")
        return Entry(key, outputs, data if isinstance(data, dict) else {})

    def store(self, stage: str, key: str, outputs: Mapping[str, Path],
              data: Mapping[str, Any] | None = None) -> Path:
        """Record ``stage``'s ``outputs`` (files under the output folder) under ``key``; atomic."""
        recs = {}
        for name, p in outputs.items():
            st = Path(p).stat()
            recs[name] = {"path": Path(p).resolve().relative_to(self.out_dir.resolve()).as_posix(),
                          "size": st.st_size, "mtime_ns": st.st_mtime_ns}
        entry = {"stage": stage, "key": key, "outputs": recs, "data": dict(data or {})}
        path = self.path(stage)
        path.parent.mkdir(parents=True, exist_ok=True)
        return atomic_write_text(path, json.dumps(entry, indent=1) + "\n")

    def forget(self, stage: str) -> None:
        """Remove ``stage``'s entry (before it computes: a half-done stage is never a hit)."""
        self.path(stage).unlink(missing_ok=True)

    def _say(self, line: str) -> None:
        if self.progress is not None:
            self.progress(line)
