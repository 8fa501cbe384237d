"""Loading artic's compiled extensions: one loader for the plant's and the truths'.

artic's C parts (the plant's tyre callback and closed loop in ``plant/``, the
synthetic truths' callback and loop in ``validation/synthetic/``) are optional
extensions that ``pip install`` builds where a C compiler is present. Each is
loaded here, with ctypes, and checked the same way: built at all, loadable,
of the ABI this artic expects, and against the MuJoCo installed now. Each
exports those answers under its own prefix (``<prefix>_abi``,
``<prefix>_mj_version``; ``mjcf/extensions.h``'s ``ARTIC_EXPORTS``), and
:func:`load` gives the library or the reason it cannot be used, one line that
says what to do.

Every extension gets this process's :data:`KEY`: a compiled callback follows
only parameter blocks sealed with it (``mjcf/extensions.h``).

This module lives in :mod:`artic.mjcf`, artic's lowest layer, so that the
plant and the synthetic truths load their extensions alike while the
independent yard truth still imports nothing of the plant.
"""

from __future__ import annotations

import ctypes
import functools
import glob
import importlib.util
import os
import secrets

import mujoco

NO_EXTENSIONS = "ARTIC_NO_EXTENSIONS"
"""An environment variable: set to 1, artic runs as if its C parts were not built
(the numpy tyre, the Python loops, no yard truth), as an install without a C
compiler does. Read when an extension is first loaded."""

KEY = (secrets.randbits(31) + 1, secrets.randbits(31) + 1)
"""This process's key: the compiled callbacks follow only blocks sealed with it."""

_DOUBLE_P = ctypes.POINTER(ctypes.c_double)


def switched_off() -> bool:
    """Whether :data:`NO_EXTENSIONS` asks artic to run without its compiled parts."""
    return os.environ.get(NO_EXTENSIONS, "") not in ("", "0")


@functools.cache
def _mujoco_visible() -> None:
    """Load MuJoCo's library, which the bindings use, with global symbols.

    The extensions call MuJoCo (``mj_step``) and leave its symbols to the loader.
    """
    here = os.path.dirname(mujoco.__file__)
    found = glob.glob(os.path.join(here, "libmujoco.so*")) or glob.glob(
        os.path.join(here, "libmujoco*.dylib"))
    if found:
        ctypes.CDLL(found[0], mode=ctypes.RTLD_GLOBAL)


def load(module: str, prefix: str, abi: int, what: str,
         fix: str = "reinstall artic with a C compiler to get it") -> tuple[ctypes.CDLL | None,
                                                                            str]:
    """Load the compiled extension ``module`` and check it.

    Parameters
    ----------
    module : str
        Its import name, e.g. ``"artic.plant._tyre_c"``.
    prefix : str
        The prefix of its exports (``"artic"``: ``artic_abi``, ``artic_mj_version``).
    abi : int
        The ABI this artic expects of it.
    what : str
        What it is, for the messages (``"the compiled tyre callback"``).
    fix : str
        What to do when it was not built.

    Returns
    -------
    lib : ctypes.CDLL or None
        The library, with its key set where it takes one; ``None`` when it
        cannot be used.
    reason : str
        Why it cannot (empty when it can).
    """
    if switched_off():
        return None, (f"the compiled parts are switched off ({NO_EXTENSIONS} is set), as "
                      "without a C compiler at install time")
    spec = importlib.util.find_spec(module)
    if spec is None or spec.origin is None:
        return None, f"{what} was not built (no C compiler at install time?); {fix}"
    try:
        _mujoco_visible()
        lib = ctypes.CDLL(spec.origin)
    except OSError as exc:
        return None, f"{spec.origin} does not load: {exc}"
    try:
        got_abi = getattr(lib, f"{prefix}_abi")()
        built = getattr(lib, f"{prefix}_mj_version")()
    except AttributeError:
        return None, f"{spec.origin} was built from another version of artic; reinstall artic"
    if got_abi != abi:
        return None, f"{spec.origin} has ABI {got_abi}, this artic expects {abi}; reinstall artic"
    if built != mujoco.mj_version():
        return None, (f"{spec.origin} was built against MuJoCo {built}, but "
                      f"{mujoco.mj_version()} is installed; reinstall artic")
    set_key = getattr(lib, f"{prefix}_set_key")
    set_key.restype = None
    set_key.argtypes = [ctypes.c_uint32, ctypes.c_uint32]
    set_key(*KEY)
    checksum = getattr(lib, f"{prefix}_checksum")
    checksum.restype = ctypes.c_double
    checksum.argtypes = [_DOUBLE_P, ctypes.c_int]
    return lib, ""
