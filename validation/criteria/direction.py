"""A log's direction of travel: its metadata's, or what most of its samples do.

The synthetic campaign's logs say ``direction`` in their metadata; a real
log need not. Then a log whose tractor reverses (``v_x_1 < 0``) for most of
its samples is a reverse log, the same rule ``artic validate --gain-sweep``
and ``artic tune`` apply.
"""

from __future__ import annotations

from artic.validation.logs.runfile import Run

DIRECTIONS = ("forward", "reverse")


def direction_of(run: Run) -> str:
    """``"forward"`` or ``"reverse"``: ``run.meta["direction"]``, else by the majority of samples.

    Parameters
    ----------
    run : Run
        A log in the signal schema.
    """
    given = run.meta.get("direction")
    if given in DIRECTIONS:
        return str(given)
    v = run.frame["v_x_1"].to_numpy(dtype=float)
    return "reverse" if v.size and float((v < 0.0).mean()) > 0.5 else "forward"
