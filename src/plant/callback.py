"""One passive-force callback for every plant in the process.

``mujoco.set_mjcb_passive`` is process-global: whichever function was set
last serves every model. This dispatcher is that function. It keeps, per
model, the handler of the plant that owns the model, and calls the handler
of the model being stepped. A model without a handler goes to whatever
callback was installed before artic's, so artic does not take over other
users' models. When the last plant closes, that previous callback is restored.
"""

from __future__ import annotations

import threading
from collections.abc import Callable

import mujoco

Handler = Callable[[mujoco.MjModel, mujoco.MjData], None]

_handlers: dict[int, Handler] = {}
_previous: Handler | None = None
_lock = threading.Lock()


def _dispatch(m: mujoco.MjModel, d: mujoco.MjData) -> None:
    handler = _handlers.get(m._address)
    if handler is not None:
        handler(m, d)
    elif _previous is not None:
        _previous(m, d)


def install(model: mujoco.MjModel, handler: Handler) -> None:
    """Serve ``model`` with ``handler`` from now on.

    Raises
    ------
    ValueError
        If the model already has a handler.
    """
    global _previous
    with _lock:
        if model._address in _handlers:
            raise ValueError("this MjModel already has a passive-force handler")
        if not _handlers:
            current = mujoco.get_mjcb_passive()
            _previous = None if current is _dispatch else current
            mujoco.set_mjcb_passive(_dispatch)
        _handlers[model._address] = handler


def uninstall(model: mujoco.MjModel) -> None:
    """Stop serving ``model``; restore the earlier callback after the last one."""
    global _previous
    with _lock:
        _handlers.pop(model._address, None)
        if not _handlers:
            mujoco.set_mjcb_passive(_previous)
            _previous = None


def active() -> int:
    """Number of models served now."""
    return len(_handlers)
