"""Process-wide settings, made by the entry points (the ``artic`` command, the tests).

Importing a library module changes nothing process-wide; an entry point calls
:func:`configure` once, before it imports the compiled models.

**Where numba keeps artic's compiled functions.** numba's on-disk cache checks
only the source file of the function it caches. A cached function that calls
into another module (``rk4_step`` into the STM's right-hand side, the harness
loop into both) keeps the old callee after that module is edited, and silently
computes the old equations. So artic's compiled functions are cached in a
folder named by the hash of exactly the sources that compiled code is built
from: the ``reduced`` package and the harness's compiled loops
(:data:`COMPILED_MODULES`). Editing a report or a plot leaves the cache alone;
editing any equation moves it to a fresh folder. Folders no version has used
for :data:`STALE_DAYS` are removed. Setting ``NUMBA_CACHE_DIR`` yourself
overrides this.

**The install's cache is that cache.** ``pip install`` compiles KIN and the STM
(:func:`fill_install_cache`) into numba's default folder beside the sources,
``reduced/__pycache__``, which a library user's process reads, and marks it
with the hash of the sources it was compiled from (:data:`INSTALL_MARK`). While
that mark is the hash of today's sources and the folder is writable,
:func:`configure` leaves numba there, so the command, the tests and the library
read one cache and a fresh machine compiles nothing twice; once a compiled
source is edited, the command moves to the hashed folder as above.

**MuJoCo's log.** MuJoCo reports its warnings (a simulation gone unstable)
through a process-wide handler; without one it appends them to
``MUJOCO_LOG.TXT`` in the current folder, wherever the user happens to be.
:func:`route_mujoco_warnings` turns them into Python warnings of class
:class:`MujocoWarning` instead, which the command line prints as one line.

**MuJoCo's step timers.** MuJoCo's Python bindings install a timer that
reads the system clock at every stage of every step to fill ``MjData.timer``,
about 5 % of the plant's step. :func:`quiet_mujoco_timers` replaces it with a
compiled clock that reads zero, so ``MjData.timer`` durations stay zero in
artic's processes (the step counts still count). A timer of your own, set
with ``mujoco.set_mjcb_time`` before, is kept.

matplotlib needs no setting: artic draws on ``matplotlib.figure.Figure``
objects with the Agg canvas, never through pyplot's global backend.
"""

from __future__ import annotations

import hashlib
import importlib.util
import os
import shutil
import sys
import time
from pathlib import Path

STALE_DAYS = 30
"""Cache folders unused for this long are removed [days]."""

COMPILED_MODULES = ("harness/feedback.py", "harness/reducedloop.py", "criteria/pathdist.py",
                    "criteria/iso18571.py",
                    "docking/geometry.py", "docking/planner.py", "docking/gym/kinbatch.py")
"""Modules of :mod:`validation` whose functions numba compiles (``feedback.py``'s
plain-Python law is compiled by ``reducedloop.py`` and the docking planner)."""


def compiled_sources() -> list[Path]:
    """The source files that artic's compiled functions are built from.

    Found without importing ``reduced``, so that the cache folder is chosen
    before any compiled function is defined.
    """
    spec = importlib.util.find_spec("artic.reduced")
    reduced_dir = Path(next(iter(spec.submodule_search_locations)))
    here = Path(__file__).resolve().parents[1]  # validation/
    return sorted(reduced_dir.glob("*.py")) + [here / m for m in COMPILED_MODULES]


def source_hash(files: list[Path] | None = None) -> str:
    """Hash of numba's version and of ``files`` (default :func:`compiled_sources`).

    numba's version comes from its installed metadata: importing numba takes
    about 0.15 s, which commands that never compile anything (the plant's
    runs) should not pay.
    """
    from importlib.metadata import version

    files = compiled_sources() if files is None else files
    h = hashlib.sha256(version("numba").encode())
    for p in files:
        h.update(p.name.encode())
        h.update(p.read_bytes())
    return h.hexdigest()[:12]


INSTALL_MARK = "artic-numba-sources.txt"
"""The file in :func:`install_cache` naming the sources' hash it was compiled from."""


def install_cache() -> Path:
    """The default numba cache folder of the reduced models, ``reduced/__pycache__``."""
    return compiled_sources()[0].parent / "__pycache__"


def install_cache_current() -> bool:
    """Whether :func:`install_cache` was filled from today's sources and can be written."""
    folder = install_cache()
    try:
        mark = (folder / INSTALL_MARK).read_text().strip()
    except OSError:
        return False
    return mark == source_hash() and os.access(folder, os.W_OK)


def fill_install_cache() -> None:
    """Compile KIN and the STM into :func:`install_cache` and mark it (run by ``pip install``).

    numba must use its default folders (``NUMBA_CACHE_DIR`` unset). Entries left
    there by other sources are removed first: numba would keep a caller whose
    callee changed.
    """
    folder = install_cache()
    if not install_cache_current():
        for d in {p.parent / "__pycache__" for p in compiled_sources()}:
            for f in (*d.glob("*.nbi"), *d.glob("*.nbc")):
                f.unlink(missing_ok=True)
    from artic.reduced.precompile import compile_all

    compile_all()
    folder.mkdir(exist_ok=True)
    part = folder / f".{INSTALL_MARK}.part"
    part.write_text(source_hash() + "\n")
    part.replace(folder / INSTALL_MARK)


class MujocoWarning(UserWarning):
    """A warning MuJoCo itself raised (see :func:`route_mujoco_warnings`)."""


def _mujoco_warning(message: str) -> None:
    import warnings

    warnings.warn(f"MuJoCo: {message}", MujocoWarning, stacklevel=2)


def route_mujoco_warnings() -> None:
    """Send MuJoCo's warnings to Python's ``warnings`` instead of ``./MUJOCO_LOG.TXT``."""
    try:
        import mujoco
    except ImportError:  # pragma: no cover - mujoco is a dependency
        return
    mujoco.set_mju_user_warning(_mujoco_warning)


def quiet_mujoco_timers() -> None:
    """Replace the bindings' default step timer by a clock reading zero (see above).

    Without the compiled tyre library, or with a timer of the user's, nothing changes.
    """
    import mujoco

    if mujoco.get_mjcb_time() is not None:  # the user's (or ours, already)
        return
    # Here, not at the top: MuJoCo loads only in a process that steps the plant.
    from artic.plant.ctyre import zero_clock

    clock = zero_clock()
    if clock is not None:
        mujoco.set_mjcb_time(clock)


def mujoco_settings() -> None:
    """Make the MuJoCo settings of one process: warnings routed, timers quiet."""
    route_mujoco_warnings()
    quiet_mujoco_timers()


def configure() -> Path | None:
    """Point numba's cache at the install's, or at ``$XDG_CACHE_HOME/artic/numba/<hash>``.

    The install's (:func:`install_cache`, numba's default folders) while it is
    current (:func:`install_cache_current`); otherwise the hashed folder under
    ``$XDG_CACHE_HOME`` (or ~/.cache). Also makes the MuJoCo settings of
    :func:`mujoco_settings`.

    Returns the folder (:func:`install_cache` for the install's), or ``None``
    when ``NUMBA_CACHE_DIR`` is set by the user or the home folder is
    read-only (numba then uses its own locations).
    """
    mujoco_settings()
    if os.environ.get("NUMBA_CACHE_DIR") in (None, "") and install_cache_current():
        return install_cache()
    base = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "artic" / "numba"
    folder = base / source_hash()
    if os.environ.get("NUMBA_CACHE_DIR") not in (None, "", str(folder)):
        return None  # the user's
    try:
        folder.mkdir(parents=True, exist_ok=True)
        os.utime(folder)  # in use: its age counts from now
        # Folders of other versions (another environment may still use one)
        # go once nothing has used them for STALE_DAYS.
        cutoff = time.time() - STALE_DAYS * 86400.0
        for old in base.iterdir():
            if old != folder and old.is_dir() and old.stat().st_mtime < cutoff:
                shutil.rmtree(old, ignore_errors=True)
    except OSError:
        return None
    # numba reads the variable when it is first imported (here, in the worker
    # processes, which inherit it, and in any later import); a numba imported
    # already has read its configuration, so it is told directly.
    os.environ["NUMBA_CACHE_DIR"] = str(folder)
    if "numba" in sys.modules:
        sys.modules["numba"].config.CACHE_DIR = str(folder)
    return folder
