"""The compiled tyre callback: loading it, and the parameter block it reads.

``_tyre_c.c`` implements :mod:`artic.plant.tyre` (the reference) and the plant's
wheel kinematics in C, as a MuJoCo passive callback (``mjfGeneric``) with no
global state. A model carries what the callback needs in its numeric
``artic.tyre``: a header, the tyre coefficients in the order
``artic_param_names()`` gives, and per wheel end the ids listed in
:data:`WHEEL_FIELDS`. The callback writes each wheel's contact force to
``d.userdata``.

Models of another kind, whose numeric 0 has a name that another compiled
extension registered (:func:`register_kind`), are handed to that extension's
callback by the same C function, without Python in between: the synthetic
truth of :mod:`artic.validation` has its own tyres and steering that way.

The extension is built by ``pip install`` when a C compiler is present, and
loaded by :func:`artic.mjcf.extensions.load`. When it is missing, or was built
against another MuJoCo version, :func:`library` returns ``None`` and
:func:`unavailable_reason` says why; the plant then uses the numpy reference
and warns once. The block's seal (the process's key, the checksum) is
``mjcf/extensions.h``'s, which the synthetic truth's callback shares.
"""

from __future__ import annotations

import ctypes
import functools
from typing import NamedTuple

import mujoco
import numpy as np

from artic.mjcf import extensions
from artic.mjcf.errors import UserError
from artic.plant import spinmode
from artic.plant.spinmode import FIT_SCALE
from artic.plant.tyre import TyreParams

BLOCK = "artic.tyre"
"""Name of the numeric that carries the callback's parameters; it must be numeric 0."""

ABI = 3
HEADER_FIELDS = ("abi", "key_hi", "key_lo", "n_wheels", "n_params", "n_sets", "moments",
                 "spin_fit", "checksum")
"""Header entries, in block order; then ``n_sets`` coefficient sets, then the wheels.

``spin_fit`` is the scale ``z_0`` of the wheel-spin mode's fit to the step
(:data:`artic.plant.spinmode.FIT_SCALE`), 0 for none."""

WHEEL_FIELDS = ("hub_site", "hub_body", "root_body", "wheel_body", "spin_dof", "act_u",
                "act_v", "act_w", "ctrl_u", "ctrl_v", "ctrl_w", "n_tyres", "tyre_set")
"""Per wheel end, in block order."""

_ID_LIMITS = {"hub_site": "nsite", "hub_body": "nbody", "root_body": "nbody",
              "wheel_body": "nbody", "spin_dof": "nv", "act_u": "na", "act_v": "na",
              "act_w": "na", "ctrl_u": "nu", "ctrl_v": "nu", "ctrl_w": "nu"}

POSITIVE = ("UNLOADED_RADIUS", "VERTICAL_STIFFNESS", "FNOMIN", "LONGVL", "VXLOW", "FZMIN",
            "LFZO", "PKY2", "PTY1", "PTY2", "PTX1")
"""Coefficients a block refuses unless finite and positive (divisors of the callback)."""

MAX_TYRES_PER_END = 4
"""Most tyres one wheel end carries (a dual pair is 2); the C code refuses more."""

_DOUBLE_P = ctypes.POINTER(ctypes.c_double)


class TyreBlockError(UserError):
    """An ``artic.tyre`` block is malformed; the message names what is wrong."""


class TyreOutputs(NamedTuple):
    """Per wheel end: forces [N], moments [N m], deflection rates [m/s, rad/s]."""

    Fx: np.ndarray
    Fy: np.ndarray
    Mz: np.ndarray
    My: np.ndarray
    du: np.ndarray
    dv: np.ndarray
    dphi: np.ndarray


NO_EXTENSIONS = extensions.NO_EXTENSIONS
"""An environment variable: set to 1, artic runs as if its C parts were not built
(:data:`artic.mjcf.extensions.NO_EXTENSIONS`)."""

KEY = extensions.KEY
"""This process's key: the callback follows only blocks sealed with it."""


def _load() -> tuple[ctypes.CDLL | None, str]:
    lib, why = extensions.load("artic.plant._tyre_c", "artic", ABI,
                               "the compiled tyre callback")
    if lib is None:
        return None, why
    if lib.artic_header() != len(HEADER_FIELDS) or lib.artic_per_wheel() != len(WHEEL_FIELDS):
        return None, "the compiled tyre callback lays its block out differently; reinstall artic"
    lib.artic_param_names.restype = ctypes.c_char_p
    lib.artic_tyre_eval.restype = None
    lib.artic_tyre_eval.argtypes = [_DOUBLE_P, ctypes.c_int, ctypes.c_int] + [_DOUBLE_P] * 15
    lib.artic_spin_fit.restype = None
    lib.artic_spin_fit.argtypes = [ctypes.c_double] * 11 + [_DOUBLE_P] * 2
    lib.artic_passive.restype = None
    lib.artic_passive.argtypes = [ctypes.c_void_p, ctypes.c_void_p]
    lib.artic_block_ok.restype = ctypes.c_int
    lib.artic_block_ok.argtypes = [ctypes.c_void_p, ctypes.c_void_p]
    lib.artic_register_kind.restype = ctypes.c_int
    lib.artic_register_kind.argtypes = [ctypes.c_char_p, ctypes.c_void_p]
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


def _lib() -> ctypes.CDLL:
    lib = library()
    if lib is None:
        raise RuntimeError(unavailable_reason())
    return lib


def param_names() -> list[str]:
    """Coefficient names in set order, as the C code defines them."""
    return _lib().artic_param_names().decode().rstrip(",").split(",")


def param_vector(p: TyreParams) -> np.ndarray:
    """The coefficients of ``p`` in set order."""
    return np.array([getattr(p, n) for n in param_names()], dtype=float)


def block_size(n_wheels: int, n_sets: int = 1) -> int:
    """Length of the ``artic.tyre`` numeric for ``n_wheels`` wheel ends and ``n_sets`` tyres."""
    return len(HEADER_FIELDS) + n_sets * len(param_names()) + len(WHEEL_FIELDS) * n_wheels


def check_set(p: TyreParams) -> None:
    """Refuse a coefficient set the callback cannot evaluate, naming the coefficient.

    Raises
    ------
    TyreBlockError
        For a non-finite coefficient, or a non-positive divisor (:data:`POSITIVE`).
    """
    _check_values(p.path, dict(zip(param_names(), param_vector(p), strict=True)))


def _check_values(where: str, values: dict[str, float]) -> None:
    for n, x in values.items():
        if not np.isfinite(x):
            raise TyreBlockError(f"{where}: tyre coefficient {n} = {float(x)!r} is not finite")
        if n in POSITIVE and x <= 0.0:
            raise TyreBlockError(f"{where}: tyre coefficient {n} = {float(x)!r} must be positive")


def block(sets: list[TyreParams], wheels: np.ndarray, moments: bool,
          spin_fit: float = FIT_SCALE) -> np.ndarray:
    """The ``artic.tyre`` numeric, sealed with this process's key.

    Parameters
    ----------
    sets : list of TyreParams
        One coefficient set per tyre file in use.
    wheels : ndarray, shape (n_wheels, len(WHEEL_FIELDS))
        Per wheel end, the ids and values named by :data:`WHEEL_FIELDS`.
    moments : bool
        Whether the tyres' aligning and bore torques act.
    spin_fit : float
        The scale of the spin mode's fit to the step (:mod:`artic.plant.spinmode`);
        0 integrates the mode plainly.
    """
    for p in sets:
        check_set(p)
    if not (np.isfinite(spin_fit) and spin_fit >= 0.0):
        raise TyreBlockError(f"spin_fit = {spin_fit!r}: the fit's scale must be finite and "
                             "not negative (0 for no fit)")
    wheels = np.asarray(wheels, dtype=float).reshape(-1, len(WHEEL_FIELDS))
    body = np.concatenate([*(param_vector(p) for p in sets), wheels.ravel()])
    head = [ABI, *KEY, len(wheels), len(param_names()), len(sets), float(moments),
            float(spin_fit), 0.0]
    head[-1] = checksum(body)
    return np.concatenate([head, body])


def checksum(body: np.ndarray) -> float:
    """The C code's seal of a block's body."""
    body = np.ascontiguousarray(body, dtype=float)
    return float(_lib().artic_checksum(body.ctypes.data_as(_DOUBLE_P), body.size))


def check_block(m: mujoco.MjModel, d: mujoco.MjData | None = None) -> None:
    """Check the block a model carries against the model, before any callback runs.

    Raises
    ------
    TyreBlockError
        Naming what is wrong: no block, a size that disagrees with its counts,
        an id outside the model's dimensions, a set index out of range, a
        wheel end with no (or too many) tyres, a coefficient that is not
        finite or a divisor that is not positive, or a seal that does not match.
    """
    if m.nnumeric < 1 or m.numeric(0).name != BLOCK:
        raise TyreBlockError(f"the model has no '{BLOCK}' numeric as its numeric 0")
    blk = np.asarray(m.numeric_data[m.numeric_adr[0]:m.numeric_adr[0] + m.numeric_size[0]])
    nh = len(HEADER_FIELDS)
    if blk.size < nh:
        raise TyreBlockError(f"'{BLOCK}' has {blk.size} values, fewer than its header's {nh}")
    h = dict(zip(HEADER_FIELDS, blk[:nh], strict=True))
    if h["abi"] != ABI:
        raise TyreBlockError(f"'{BLOCK}' has ABI {h['abi']:g}, this artic writes {ABI}")
    if (h["key_hi"], h["key_lo"]) != KEY:
        raise TyreBlockError(f"'{BLOCK}' is not sealed by this process (a foreign block)")
    npar = len(param_names())
    if h["n_params"] != npar:
        raise TyreBlockError(f"'{BLOCK}' has sets of {h['n_params']:g} coefficients, not {npar}")
    nw, ns = h["n_wheels"], h["n_sets"]
    if not (np.isfinite(h["spin_fit"]) and h["spin_fit"] >= 0.0):
        raise TyreBlockError(f"'{BLOCK}': spin_fit = {h['spin_fit']!r} must be finite and not "
                             "negative (0 for no fit)")
    if not (nw >= 0 and nw == int(nw) and 1 <= ns <= 64 and ns == int(ns)):
        raise TyreBlockError(f"'{BLOCK}': bad counts n_wheels = {nw:g}, n_sets = {ns:g}")
    nw, ns = int(nw), int(ns)
    want = block_size(nw, ns)
    if blk.size != want:
        raise TyreBlockError(f"'{BLOCK}' has {blk.size} values; {nw} wheels and {ns} tyre "
                             f"sets need {want}")
    bad = np.flatnonzero(~np.isfinite(blk[nh:]))
    if bad.size:  # named before the seal, which a NaN would only call damaged
        k = int(bad[0])
        if k < ns * npar:
            what = f"tyre set {k // npar}: tyre coefficient {param_names()[k % npar]}"
        else:
            k -= ns * npar
            what = f"wheel {k // len(WHEEL_FIELDS)}: {WHEEL_FIELDS[k % len(WHEEL_FIELDS)]}"
        raise TyreBlockError(f"'{BLOCK}' {what} = {float(blk[nh:][bad[0]])!r} is not finite")
    if checksum(blk[nh:]) != h["checksum"]:
        raise TyreBlockError(f"'{BLOCK}': its seal does not match its contents (damaged)")
    if m.nuserdata < 3 * nw + 1:
        raise TyreBlockError(f"the model has nuserdata = {m.nuserdata}; {nw} wheels need "
                             f"{3 * nw + 1}")
    wheels = blk[nh + ns * npar:].reshape(nw, len(WHEEL_FIELDS))
    for i, row in enumerate(wheels):
        for name, x in zip(WHEEL_FIELDS, row, strict=True):
            limit = ns if name == "tyre_set" else getattr(m, _ID_LIMITS.get(name, ""), None)
            if limit is None:  # n_tyres: a count, checked below
                continue
            if not (0 <= x < limit and x == int(x)):
                raise TyreBlockError(f"'{BLOCK}' wheel {i}: {name} = {x:g} is outside the "
                                     f"model's range [0, {limit})")
    for i, n in enumerate(wheels[:, WHEEL_FIELDS.index("n_tyres")]):
        if not 0 < n <= MAX_TYRES_PER_END:
            raise TyreBlockError(f"'{BLOCK}' wheel {i}: n_tyres = {n:g}; a wheel end carries "
                                 f"1 to {MAX_TYRES_PER_END} tyres")
    for k in range(ns):  # a block sealed elsewhere (plant.load) was never check_set
        values = blk[nh + k * npar:nh + (k + 1) * npar]
        _check_values(f"'{BLOCK}' tyre set {k}", dict(zip(param_names(), values, strict=True)))
    if d is not None and not _lib().artic_block_ok(m._address, d._address):
        raise TyreBlockError(f"'{BLOCK}' is refused by the compiled callback")


def evaluate(p: TyreParams, Fz, Vx, Vsx, Vy, omega_z, u, v, phi,
             moments: bool = True) -> TyreOutputs:
    """Evaluate wheel states with the compiled code, for comparison with :mod:`artic.plant.tyre`.

    Arguments are as in :func:`artic.plant.tyre.transient_forces`, broadcast to one shape.
    """
    lib = _lib()
    args = [np.ascontiguousarray(a, dtype=float).ravel()
            for a in np.broadcast_arrays(Fz, Vx, Vsx, Vy, omega_z, u, v, phi)]
    n = args[0].size
    out = [np.empty(n) for _ in range(7)]
    pv = param_vector(p)
    lib.artic_tyre_eval(pv.ctypes.data_as(_DOUBLE_P), n, int(moments),
                        *(a.ctypes.data_as(_DOUBLE_P) for a in args + out))
    return TyreOutputs(*out)


def spin_fit(h: float, scale: float, mode: spinmode.Mode, f_spin: float,
             f_u: float) -> tuple[float, float]:
    """The compiled ``artic_spin_fit`` of one wheel end: ``(dFx, ddu)``.

    For comparison with :func:`artic.plant.spinmode.fit`: the same arguments
    (``mode`` of floats, one wheel end), with the fit's scale second.
    """
    dFx, ddu = ctypes.c_double(), ctypes.c_double()
    m = mode
    _lib().artic_spin_fit(h, scale, m.inv_inertia, m.q_x, m.n, m.Re, m.k, m.c, m.b, f_spin, f_u,
                          ctypes.byref(dFx), ctypes.byref(ddu))
    return dFx.value, ddu.value


def zero_clock():
    """A C clock that reads zero, as a ctypes function pointer for ``mujoco.set_mjcb_time``.

    ``None`` without the compiled library. A Python clock would hold the GIL
    at every stage of every step.
    """
    lib = library()
    if lib is None:
        return None
    f = lib.artic_zero_clock
    f.restype = ctypes.c_double
    f.argtypes = []
    return f


def register_kind(name: str, function) -> None:
    """Hand models whose numeric 0 is named ``name`` to ``function``, a compiled callback.

    Parameters
    ----------
    name : str
        The numeric's name; not :data:`BLOCK`, at most 63 bytes.
    function : ctypes function pointer
        A C function ``void f(const mjModel*, mjData*)`` of a loaded library,
        which must check its models' blocks itself. The first one registered
        for a name stays for the life of the process.

    Raises
    ------
    ValueError
        For :data:`BLOCK`, a name too long, or a full table (8 kinds).
    """
    address = ctypes.cast(function, ctypes.c_void_p).value
    if _lib().artic_register_kind(name.encode(), address) < 0:
        raise UserError(f"cannot register the callback kind {name!r} (the plant's own name, "
                         "too long, or 8 kinds already)")


def passive_function():
    """The C callback as a ctypes function pointer, for ``mujoco.set_mjcb_passive``."""
    return _lib().artic_passive


def call_passive(m: mujoco.MjModel, d: mujoco.MjData) -> None:
    """Run the C callback on one model from Python (when a Python callback is installed)."""
    passive_function()(m._address, d._address)
