"""The truth's compiled tyres and steering: loading ``_truth_c`` and its block.

``_truth_c.c`` is the synthetic truth's passive callback (TMeasy tyres, a
compliant steering column and tie rod; see its header). It is registered with
the plant's compiled callback as the kind ``artic.truth``
(:func:`artic.plant.ctyre.register_kind`): MuJoCo calls one C function for
every model, which hands the truth's models to this one, without Python in
between. The block is sealed with the same process key as the plant's.

The order of the coefficients and fields is the C code's
(``artic_truth_tyre_names()`` and its siblings); Python reads it from there.
The seal (the key, the checksum) and the loader are the plant's as well
(``mjcf/extensions.h``, :func:`artic.mjcf.extensions.load`).
"""

from __future__ import annotations

import ctypes
import functools

import mujoco
import numpy as np

from artic.mjcf import extensions
from artic.plant import ctyre

BLOCK = "artic.truth"
"""Name of the truth model's numeric 0."""

ABI = 1

_DOUBLE_P = ctypes.POINTER(ctypes.c_double)


class TruthUnavailable(RuntimeError):
    """The compiled truth cannot be used; the message says why and what to do."""


def _load() -> tuple[ctypes.CDLL | None, str]:
    if ctyre.library() is None:  # the plant's callback hands the truth's models to this one
        return None, ctyre.unavailable_reason()
    lib, why = extensions.load("artic.validation.synthetic._truth_c", "artic_truth", ABI,
                               "the synthetic truth's compiled tyres",
                               "reinstall artic with a C compiler, or generate with "
                               "--truth structural")
    if lib is None:
        return None, why
    for name in ("artic_truth_tyre_names", "artic_truth_column_names", "artic_truth_end_names"):
        getattr(lib, name).restype = ctypes.c_char_p
    lib.artic_truth_block_ok.restype = ctypes.c_int
    lib.artic_truth_block_ok.argtypes = [ctypes.c_void_p]
    lib.artic_truth_steady.restype = None
    lib.artic_truth_steady.argtypes = [_DOUBLE_P, ctypes.c_int] + [_DOUBLE_P] * 7
    lib.artic_truth_tyre.restype = None
    lib.artic_truth_tyre.argtypes = [_DOUBLE_P, ctypes.c_int] + [_DOUBLE_P] * 15
    lib.artic_truth_column.restype = None
    lib.artic_truth_column.argtypes = [_DOUBLE_P] + [ctypes.c_double] * 6 + [_DOUBLE_P]
    ctyre.register_kind(BLOCK, lib.artic_truth_passive)
    return lib, ""


@functools.cache
def _loaded() -> tuple[ctypes.CDLL | None, str]:
    return _load()


def library() -> ctypes.CDLL:
    """The compiled truth, registered with the plant's callback.

    Raises
    ------
    TruthUnavailable
        When it was not built or does not match this MuJoCo.
    """
    lib, why = _loaded()
    if lib is None:
        raise TruthUnavailable(why)
    return lib


def _names(what: str) -> tuple[str, ...]:
    raw = getattr(library(), f"artic_truth_{what}_names")().decode()
    return tuple(raw.rstrip(",").split(","))


@functools.cache
def tyre_names() -> tuple[str, ...]:
    """A tyre set's coefficients, in block order."""
    return _names("tyre")


@functools.cache
def column_names() -> tuple[str, ...]:
    """The steering column's parameters and model ids, in block order."""
    return _names("column")


@functools.cache
def end_names() -> tuple[str, ...]:
    """A wheel end's fields, in block order."""
    return _names("end")


SEALED = 8
"""Header entries before the sealed body (the follower's four and all after)."""


def header_size() -> int:
    """Entries before the tyre sets: the seal's eight and the speed follower's four."""
    return int(library().artic_truth_header())


def diagnostics() -> int:
    """``userdata`` entries after the wheel forces and the range count."""
    return int(library().artic_truth_diagnostics())


def block_size(n_ends: int, n_sets: int, n_columns: int) -> int:
    """Length of the ``artic.truth`` numeric."""
    return (header_size() + n_sets * len(tyre_names()) + n_columns * len(column_names())
            + n_ends * len(end_names()))


def seal(follower: tuple[bool, float, int, int], sets: list[np.ndarray],
         column: np.ndarray | None, ends: np.ndarray) -> np.ndarray:
    """The block, sealed with the process's key and a checksum.

    Parameters
    ----------
    follower : tuple
        Whether the speed follower acts, its gain [N s/m], its actuator and its site.
    sets : list of ndarray
        The tyre sets, each in :func:`tyre_names` order.
    column : ndarray or None
        The steering column (:func:`column_names` order), if the model steers.
    ends : ndarray
        One row per wheel end, :func:`end_names` order.
    """
    follow, kv, actuator, site = follower
    body = np.concatenate([[float(follow), kv, actuator, site], *sets,
                           *([] if column is None else [column]), ends.ravel()])
    body = np.ascontiguousarray(body, dtype=float)
    total = float(library().artic_truth_checksum(body.ctypes.data_as(_DOUBLE_P), body.size))
    head = [ABI, *extensions.KEY, len(ends), len(sets), len(tyre_names()),
            0 if column is None else 1, total]
    return np.concatenate([np.array(head, dtype=float), body])


def block_ok(model: mujoco.MjModel) -> bool:
    """Whether the compiled truth follows this model's block."""
    return bool(library().artic_truth_block_ok(model._address))


def _arrays(*xs):
    return [np.ascontiguousarray(a, dtype=float).ravel() for a in np.broadcast_arrays(*xs)]


def steady(p: np.ndarray, Fz, sx, sy, sB=0.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Steady-state ``Fx, Fy`` [N] and ``Mz`` [N m] (aligning forward, plus bore) at given slips.

    Parameters
    ----------
    p : ndarray
        One tyre set, in :func:`tyre_names` order.
    Fz : array_like
        Load [N].
    sx, sy, sB : array_like
        TMeasy's longitudinal, lateral and bore slips [-], broadcast together.
    """
    args = _arrays(Fz, sx, sy, sB)
    out = [np.empty(args[0].size) for _ in range(3)]
    pv = np.ascontiguousarray(p, dtype=float)
    library().artic_truth_steady(pv.ctypes.data_as(_DOUBLE_P), args[0].size,
                                 *(a.ctypes.data_as(_DOUBLE_P) for a in args + out))
    shape = np.broadcast_shapes(*(np.shape(x) for x in (Fz, sx, sy, sB)))
    return tuple(o.reshape(shape) for o in out)


def dynamic(p: np.ndarray, Fz, vx, vy, v_roll, omega_n, xe, ye, pe) -> dict[str, np.ndarray]:
    """The tyre with its deflection states: forces, moments and the states' rates.

    Returns a dict of ``Fx, Fy`` [N], ``Mz, My`` [N m], ``dxe, dye`` [m/s], ``dpe`` [rad/s].
    """
    args = _arrays(Fz, vx, vy, v_roll, omega_n, xe, ye, pe)
    names = ("Fx", "Fy", "Mz", "My", "dxe", "dye", "dpe")
    out = [np.empty(args[0].size) for _ in names]
    pv = np.ascontiguousarray(p, dtype=float)
    library().artic_truth_tyre(pv.ctypes.data_as(_DOUBLE_P), args[0].size,
                               *(a.ctypes.data_as(_DOUBLE_P) for a in args + out))
    return dict(zip(names, out, strict=True))


def column_law(c: np.ndarray, ref: float, dl: float, dr: float, wl: float = 0.0,
               wr: float = 0.0, assist: float = 0.0) -> dict[str, float]:
    """The column's torques at one state (see ``_truth_c.c``), for the tests.

    Returns ``TL, TR`` (knuckle torques [N m]), ``dTa`` (assist rate [N m/s]),
    ``box`` (the box's torque on the left knuckle), ``tb`` (torsion-bar torque
    at the steering wheel) and ``rod`` (the tie rod's torque on the right knuckle).
    """
    cv = np.ascontiguousarray(c, dtype=float)
    out = np.empty(6)
    library().artic_truth_column(cv.ctypes.data_as(_DOUBLE_P), ref, dl, dr, wl, wr, assist,
                                 out.ctypes.data_as(_DOUBLE_P))
    return dict(zip(("TL", "TR", "dTa", "box", "tb", "rod"), map(float, out), strict=True))
