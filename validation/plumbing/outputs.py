"""Output folders and files: checked before the work, locked while in use, tidy after a crash.

- :func:`check_output_dir` and :func:`check_output_file` try the output
  location before any long computation, so a read-only or wrong-type path is a
  one-line error at once, not a traceback an hour later; they make nothing, so
  a command refused for another input leaves no folder behind.
- :class:`OutDirLock` holds ``DIR/.artic.lock`` while a command writes into
  ``DIR``. A second command on the same folder is refused with the holder's
  process id, host, command and start time. The lock is ``filelock``'s, an
  advisory ``flock`` on the open file (a ``LockFileEx`` on Windows), so a
  killed holder releases it with its last file descriptor: a crash never
  leaves the folder locked.
- :func:`clean_stale` removes the temporaries (``.NAME.XXXX.part``, and the
  recordings' ``.NAME.rrd.PID.tmp``) that a killed writer left behind. Every
  atomic write in artic writes such a temporary beside its target and renames
  it; under the lock nobody else writes into the folder, so any temporary
  there is stale.
- :func:`public_mode` gives a new file or folder the permissions the umask
  allows, as ``open`` would: the temporaries of ``tempfile`` are 0600 and
  0700 whatever the umask.
"""

from __future__ import annotations

import datetime
import json
import os
import shutil
import socket
import sys
import tempfile
from pathlib import Path

import filelock

from artic.mjcf.errors import UserError
from artic.mjcf.files import TEMP_SUFFIX, public_mode, umask

__all__ = ["LOCK_NAME", "TEMP_SUFFIX", "LockedError", "OutDirLock", "OutputError",
           "check_output_dir", "check_output_file", "clean_stale", "public_mode", "umask"]

LOCK_NAME = ".artic.lock"
"""The lock file in an output folder."""

class OutputError(UserError):
    """An output location cannot be used; the message names it and the fix."""


def _describe(exc: OSError) -> str:
    return exc.strerror or str(exc)


def check_output_dir(path: Path | str, option: str = "--out-dir") -> Path:
    """Prove ``path`` is, or can be made, a writable folder; one-line :class:`OutputError` if not.

    Nothing is made: the folder is created by what first writes into it (the
    command's :class:`OutDirLock`, or the writer itself), after every input is
    checked, so a refused command leaves no empty folder behind. Where ``path``
    does not exist yet, the nearest folder above it that does must be writable.
    """
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise OutputError(f"{option} {path}: exists and is not a folder; choose a folder")
    there = path
    while not there.exists() and there != there.parent:
        there = there.parent
    if not there.is_dir():
        raise OutputError(f"{option} {path}: {there} is a file, not a folder; choose a folder")
    try:
        fd, probe = tempfile.mkstemp(prefix=".artic-probe.", suffix=TEMP_SUFFIX, dir=there)
        os.close(fd)
        os.unlink(probe)
    except OSError as exc:
        raise OutputError(f"{option} {path}: cannot write there ({_describe(exc)}); choose a "
                          "writable folder") from exc
    return path


def check_output_file(path: Path | str, option: str = "--out") -> Path:
    """Check that ``path`` can be written atomically: a writable folder, not a folder itself.

    Its folder must exist: a file is written into a folder the user made (a mistyped
    ``/nonexistnt/run.parquet`` would otherwise make folders anywhere, even at the root),
    while ``--out-dir`` names a folder of artic's own, made with its parents.
    """
    path = Path(path)
    if path.is_dir():
        raise OutputError(f"{option} {path}: is a folder; give a file name")
    parent = path.parent if str(path.parent) else Path(".")
    if not parent.exists():
        raise OutputError(f"{option} {path}: the folder {parent} does not exist; make it "
                          "first, or give a file in a folder that does")
    check_output_dir(path.parent if str(path.parent) else Path("."), option=f"{option} folder")
    return path


class LockedError(OutputError):
    """Another artic process is writing into the same output folder."""


class OutDirLock:
    """Exclusive use of an output folder for one command (see the module docstring).

    The lock is :class:`filelock.FileLock` (``flock`` on POSIX, ``LockFileEx`` on
    Windows), tried once; what holds it is written into the lock file when it is
    taken, for the refusal of a second command to name.

    Parameters
    ----------
    out_dir : Path
        The folder; created if needed.
    what : str
        What holds it (``"campaign"``), written into the lock file.
    """

    def __init__(self, out_dir: Path | str, what: str) -> None:
        self.out_dir = Path(out_dir)
        self.what = what
        self.path = self.out_dir / LOCK_NAME
        self._lock = filelock.FileLock(self.path, timeout=0, mode=0o666 & ~umask(),
                                       thread_local=False, on_acquired=self._write_holder)

    def _write_holder(self, fd: int) -> None:
        info = {"what": self.what, "pid": os.getpid(), "host": socket.gethostname(),
                "started": datetime.datetime.now().isoformat(timespec="seconds"),
                "command": " ".join(os.path.basename(a) if i == 0 else a
                                    for i, a in enumerate(sys.argv))}
        os.ftruncate(fd, 0)
        os.pwrite(fd, (json.dumps(info) + "\n").encode(), 0)

    def __enter__(self) -> OutDirLock:
        self.out_dir.mkdir(parents=True, exist_ok=True)
        try:
            self._lock.acquire()
        except filelock.Timeout:
            raise LockedError(f"{self.out_dir}: in use by another artic {_read_holder(self.path)}; "
                              "wait for it to finish or choose another --out-dir") from None
        return self

    def __exit__(self, *exc) -> None:
        self._lock.release()


def _read_holder(path: Path) -> str:
    try:
        info = json.loads(path.read_bytes()[:4096] or b"{}")
        return (f"{info.get('what', 'command')} (process {info.get('pid', '?')} on "
                f"{info.get('host', '?')}, started {info.get('started', '?')}: "
                f"{info.get('command', '?')})")
    except (OSError, ValueError, AttributeError):
        return "command (its lock file does not say which)"


def _temporary(name: str) -> bool:
    """Whether ``name`` is one of artic's temporaries.

    ``.NAME.XXXX.part`` (the atomic writes) or ``.NAME.PID.tmp`` (the Rerun
    recordings, saved under a name of their own before the rename).
    """
    return name.startswith(".") and (name.endswith(TEMP_SUFFIX) or name.endswith(".tmp"))


def clean_stale(out_dir: Path | str) -> list[Path]:
    """Remove the temporaries (``.*.part``, ``.*.tmp``) left in ``out_dir`` by killed writers.

    Call it only while holding :class:`OutDirLock` on ``out_dir``.

    Returns
    -------
    list of Path
        What was removed.
    """
    removed = []
    root = Path(out_dir)
    if not root.is_dir():
        return removed
    for dirpath, dirnames, filenames in os.walk(root):
        here = Path(dirpath)
        for name in [*filenames, *dirnames]:
            if _temporary(name):
                p = here / name
                try:
                    if p.is_dir() and not p.is_symlink():
                        shutil.rmtree(p)
                    else:
                        p.unlink()
                    removed.append(p)
                except OSError:
                    continue
        dirnames[:] = [d for d in dirnames if not _temporary(d)]
    return removed
