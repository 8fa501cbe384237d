"""The compiled tyre callback: loading it, and the parameter block it reads.

``_tyre_c.c`` implements :mod:`plant.tyre` (the reference) and the plant's
wheel kinematics in C, as a MuJoCo passive callback (``mjfGeneric``) with no
global state. A model carries what the callback needs in its numeric
``artic.tyre``: a header, the tyre coefficients in the order
``artic_param_names()`` gives, and per wheel end the ids listed in
:data:`WHEEL_FIELDS`. The callback writes each wheel's contact force to
``d.userdata``.

The extension is built by ``pip install`` when a C compiler is present. When
it is missing, or was built against another MuJoCo version, :func:`library`
returns ``None`` and :func:`unavailable_reason` says why; the plant then uses
the numpy reference and warns once.
"""

from __future__ import annotations

import ctypes
import functools
import glob
import importlib.util
import os
from typing import NamedTuple

import mujoco
import numpy as np

from plant.tyre import TyreParams

BLOCK = "artic.tyre"
"""Name of the numeric that carries the callback's parameters; it must be numeric 0."""

ABI = 1
HEADER = 6
"""Header entries: abi, n_wheels, R0 [m], k_t [N/m], c_t [N s/m], n_params."""

WHEEL_FIELDS = ("hub_site", "hub_body", "root_body", "wheel_body", "spin_dof", "act_u",
                "act_v", "ctrl_u", "ctrl_v", "n_tyres", "side")
"""Per wheel end, in block order."""

_DOUBLE_P = ctypes.POINTER(ctypes.c_double)


class TyreOutputs(NamedTuple):
    """Per wheel end: forces [N], rolling-resistance moment [N m], deflection rates [m/s]."""

    Fx: np.ndarray
    Fy: np.ndarray
    My: np.ndarray
    du: np.ndarray
    dv: np.ndarray


def _load() -> tuple[ctypes.CDLL | None, str]:
    spec = importlib.util.find_spec("plant._tyre_c")
    if spec is None or spec.origin is None:
        return None, ("the compiled tyre callback was not built (no C compiler at install "
                      "time?); reinstall artic with a C compiler to get it")
    # The extension leaves MuJoCo's symbols (mj_applyFT) to the loader: make the
    # library the bindings already loaded visible to it.
    found = glob.glob(os.path.join(os.path.dirname(mujoco.__file__), "libmujoco.so*")) or \
        glob.glob(os.path.join(os.path.dirname(mujoco.__file__), "libmujoco*.dylib"))
    try:
        if found:
            ctypes.CDLL(found[0], mode=ctypes.RTLD_GLOBAL)
        lib = ctypes.CDLL(spec.origin)
    except OSError as exc:
        return None, f"{spec.origin} does not load: {exc}"
    if lib.artic_abi() != ABI:
        return None, f"{spec.origin} has ABI {lib.artic_abi()}, this artic expects {ABI}"
    if lib.artic_mj_version() != mujoco.mj_version():
        return None, (f"{spec.origin} was built against MuJoCo {lib.artic_mj_version()}, but "
                      f"{mujoco.mj_version()} is installed; reinstall artic")
    lib.artic_param_names.restype = ctypes.c_char_p
    lib.artic_tyre_eval.restype = None
    lib.artic_tyre_eval.argtypes = [_DOUBLE_P, ctypes.c_int] + [_DOUBLE_P] * 12
    lib.artic_passive.restype = None
    lib.artic_passive.argtypes = [ctypes.c_void_p, ctypes.c_void_p]
    return lib, ""


@functools.cache
def _loaded() -> tuple[ctypes.CDLL | None, str]:
    return _load()


def library() -> ctypes.CDLL | None:
    """The compiled callback's library, or ``None`` when it cannot be used."""
    return _loaded()[0]


def unavailable_reason() -> str:
    """Why :func:`library` is ``None`` (empty when it is not)."""
    return _loaded()[1]


def param_names() -> list[str]:
    """Coefficient names in block order, as the C code defines them."""
    lib = library()
    if lib is None:
        raise RuntimeError(unavailable_reason())
    return lib.artic_param_names().decode().rstrip(",").split(",")


def param_vector(p: TyreParams) -> np.ndarray:
    """The coefficients of ``p`` in block order (``FILE_SIDE`` is ``p.side``)."""
    return np.array([p.side if n == "FILE_SIDE" else getattr(p, n) for n in param_names()])


def block_size(n_wheels: int) -> int:
    """Length of the ``artic.tyre`` numeric for ``n_wheels`` wheel ends."""
    return HEADER + len(param_names()) + len(WHEEL_FIELDS) * n_wheels


def block(p: TyreParams, R0: float, k_t: float, c_t: float, wheels: np.ndarray) -> np.ndarray:
    """The ``artic.tyre`` numeric.

    Parameters
    ----------
    p : TyreParams
        Tyre coefficients.
    R0, k_t, c_t : float
        Unloaded radius [m], vertical stiffness [N/m] and damping [N s/m].
    wheels : ndarray, shape (n_wheels, len(WHEEL_FIELDS))
        Per wheel end, the ids and values named by :data:`WHEEL_FIELDS`.
    """
    pv = param_vector(p)
    head = [ABI, len(wheels), R0, k_t, c_t, len(pv)]
    return np.concatenate([head, pv, np.asarray(wheels, dtype=float).ravel()])


def evaluate(p: TyreParams, Fz, Vx, Vsx, Vy, u, v, side) -> TyreOutputs:
    """Evaluate wheel states with the compiled code, for comparison with :mod:`plant.tyre`.

    Arguments are as in :func:`plant.tyre.transient_forces`, broadcast to one shape.
    """
    lib = library()
    if lib is None:
        raise RuntimeError(unavailable_reason())
    args = [np.ascontiguousarray(a, dtype=float).ravel()
            for a in np.broadcast_arrays(Fz, Vx, Vsx, Vy, u, v, side)]
    n = args[0].size
    out = [np.empty(n) for _ in range(5)]
    pv = param_vector(p)
    lib.artic_tyre_eval(pv.ctypes.data_as(_DOUBLE_P), n,
                        *(a.ctypes.data_as(_DOUBLE_P) for a in args + out))
    return TyreOutputs(*out)


def passive_function():
    """The C callback as a ctypes function pointer, for ``mujoco.set_mjcb_passive``."""
    lib = library()
    if lib is None:
        raise RuntimeError(unavailable_reason())
    return lib.artic_passive


def call_passive(m: mujoco.MjModel, d: mujoco.MjData) -> None:
    """Run the C callback on one model from Python (when a Python callback is installed)."""
    passive_function()(m._address, d._address)
