"""What the plant had to limit during a run, collected instead of printed as warnings.

The plant warns (:class:`plant.PlantWarning`, :class:`artic.plant.tyre.TyreRangeWarning`)
when it limits something: a steering angle beyond the linkage, a tyre outside
its file's valid range. Printed as Python warnings they carry site-packages
paths and no manoeuvre name, and one validation prints dozens of them.
:func:`collect` gathers them per run instead (per thread, so that runs on a
thread pool keep theirs apart), and :func:`summary` turns them into one line.

Warnings of other kinds, and plant warnings outside :func:`collect`, are shown
as usual.
"""

from __future__ import annotations

import contextlib
import re
import threading
import warnings
from collections.abc import Iterator

from artic.plant import PlantWarning
from artic.plant.tyre import TyreRangeWarning

_local = threading.local()
_lock = threading.Lock()
_shown = None  # the showwarning that :func:`_show` wraps


def _show(message, category, filename, lineno, file=None, line=None):
    sink = getattr(_local, "sink", None)
    if sink is not None and issubclass(category, (PlantWarning, TyreRangeWarning)):
        sink.append(str(message))
        return
    _shown(message, category, filename, lineno, file, line)


def _install() -> None:
    """Route warnings through :func:`_show` (again, if something put the old hook back)."""
    global _shown
    with _lock:
        if warnings.showwarning is not _show:
            _shown = warnings.showwarning
            warnings.showwarning = _show


@contextlib.contextmanager
def collect() -> Iterator[list[str]]:
    """Collect this thread's plant warnings into the list yielded, each every time.

    Yields
    ------
    list of str
        The messages, in order.
    """
    _install()
    sink: list[str] = []
    previous = getattr(_local, "sink", None)
    _local.sink = sink
    try:
        yield sink
    finally:
        _local.sink = previous


_TIME = re.compile(r"t = ([-0-9.]+) s")


def summary(messages: list[str]) -> str:
    """One line for a run's plant warnings: what was limited, how often, from when.

    Returns an empty string when there is nothing to say.
    """
    if not messages:
        return ""
    kinds: dict[str, list[str]] = {}
    for m in messages:
        if "beyond the linkage" in m:
            rng = re.search(r"linkage's (\[[^\]]*\] deg)", m)
            kind = f"steering held at the linkage's range {rng.group(1) if rng else ''}".strip()
        elif "valid range" in m:
            what = sorted({f"{w.split(':')[0].strip()} {w.split(':')[1].split('=')[0].strip()}"
                           for w in m.split("valid range: ", 1)[-1].split("; ") if ":" in w})
            kind = "tyre outside its file's range (" + ", ".join(what) + ")"
        else:
            kind = _TIME.sub("t", m)
        kinds.setdefault(kind, []).append(m)
    parts = []
    for kind, ms in kinds.items():
        t = _TIME.search(ms[0])
        when = f" from t = {t.group(1)} s" if t else ""
        parts.append(f"{kind}{when}" + (f" ({len(ms)} times)" if len(ms) > 1 else ""))
    return "; ".join(parts)
