"""One passive-force callback for every plant in the process.

``mujoco.set_mjcb_passive`` is process-global: whichever function was set
last serves every model. This module decides what is set:

- while every open plant uses the compiled tyre callback (:mod:`artic.plant.ctyre`),
  and nothing else had a callback before, the C function itself, which MuJoCo
  calls without the GIL, so plants can step on threads;
- otherwise :func:`_dispatch`, a Python function that calls, per model, the
  numpy handler of the plant that owns it, the C function for a compiled
  plant, and whatever callback was installed before artic's for other models.

When the last plant closes, that previous callback is restored.

Plants may step on other threads while one opens or closes, so the callback
changes only in ways a step in flight survives. MuJoCo's bindings keep a Python
callback as two globals, the C trampoline MuJoCo calls and the Python object the
trampoline then calls; a step that has read the trampoline and then finds the
object replaced by a C function (or by nothing) fails with "Python exception
raised" and MuJoCo ends the process. So once :func:`_dispatch` serves, it stays
until the last plant closes, even when the plants still open are all compiled
(they then run through it, slower, but right). From the C function to
:func:`_dispatch` is safe: a step reads either the C function or the trampoline,
and the trampoline finds :func:`_dispatch`.
"""

from __future__ import annotations

import ctypes
import threading
from collections.abc import Callable

import mujoco

from artic.mjcf.errors import UserError
from artic.plant import ctyre

Handler = Callable[[mujoco.MjModel, mujoco.MjData], None]

NATIVE = "native"
"""Handler marker: the model carries an ``artic.tyre`` block for the C callback."""

_handlers: dict[int, Handler | str] = {}
_previous: Handler | None = None
_lock = threading.Lock()


def _dispatch(m: mujoco.MjModel, d: mujoco.MjData) -> None:
    handler = _handlers.get(m._address)
    if handler is NATIVE:
        ctyre.call_passive(m, d)
    elif handler is not None:
        handler(m, d)
    elif _previous is not None:
        _previous(m, d)


def _is_ours(cb) -> bool:
    if cb is _dispatch:
        return True
    lib = ctyre.library()
    if lib is None or not isinstance(cb, ctypes._CFuncPtr):
        return False
    return ctypes.cast(cb, ctypes.c_void_p).value == \
        ctypes.cast(lib.artic_passive, ctypes.c_void_p).value


def _refresh() -> None:
    if not _handlers:
        mujoco.set_mjcb_passive(_previous)
    elif mujoco.get_mjcb_passive() is _dispatch:
        pass  # never from Python back to C while plants are open: see below
    elif (_previous is None and all(h is NATIVE for h in _handlers.values())
          and ctyre.library() is not None):
        mujoco.set_mjcb_passive(ctyre.passive_function())
    else:
        mujoco.set_mjcb_passive(_dispatch)


def install(model: mujoco.MjModel, handler: Handler | str) -> None:
    """Serve ``model`` with ``handler`` (a Python function, or :data:`NATIVE`) from now on.

    Raises
    ------
    ValueError
        If the model already has a handler.
    """
    global _previous
    with _lock:
        if model._address in _handlers:
            raise UserError("this MjModel already has a passive-force handler")
        if not _handlers:
            current = mujoco.get_mjcb_passive()
            _previous = None if current is None or _is_ours(current) else current
        _handlers[model._address] = handler
        _refresh()


def uninstall(model: mujoco.MjModel) -> None:
    """Stop serving ``model``; restore the earlier callback after the last one."""
    global _previous
    with _lock:
        _handlers.pop(model._address, None)
        _refresh()
        if not _handlers:
            _previous = None


def python_installed() -> bool:
    """Whether a Python function is MuJoCo's passive callback now."""
    cb = mujoco.get_mjcb_passive()
    return cb is not None and not isinstance(cb, ctypes._CFuncPtr)


def active() -> int:
    """Number of models served now."""
    return len(_handlers)
