"""Fill numba's cache of KIN and the STM, so that their first call in a process is fast.

From an empty cache, numba compiles a reduced model's functions at their first
call: about 5 s for the first :meth:`artic.KIN.rollout`. ``pip install`` runs
:func:`compile_all` once, after the build (``setup.py``'s ``build_ext``), in a
process of its own with ``NUMBA_CACHE_DIR`` unset, so numba writes its cache
where it reads it by default: ``__pycache__`` beside ``reduced/*.py`` (the
checkout's for ``pip install -e .``, the wheel's for a wheel, which carries it
into ``site-packages``). numba (0.68 and later) stamps a cache entry with a
hash of its source file's contents, not its path or time, so the entries stay
valid wherever the files are installed; an entry also names the CPU it was
compiled for and numba's version, and numba compiles afresh where either
differs (a wheel built on another machine).

``pip install`` runs it through
:func:`artic.validation.plumbing.runtime.fill_install_cache`, which also marks
the folder with the hash of the compiled sources, so that the ``artic`` command
and the tests read this same cache while the sources are unchanged. It is not
used, and the first call compiles once, where numba looks elsewhere:
``NUMBA_CACHE_DIR`` set by the user, sources edited since the install, or a
``site-packages`` that the user cannot write.

Run by hand (``python -m artic.reduced.precompile``) it does the same for the
environment it runs in.
"""

from __future__ import annotations

import numpy as np

from artic.mjcf.interface import InitialState
from artic.mjcf.vehicle import load_vehicle
from artic.reduced.control import KIN, STM


def compile_all() -> None:
    """Call every compiled path of :class:`KIN` and :class:`STM` once, with the types users pass.

    The public methods convert their arguments to C-contiguous float64 arrays
    and Python floats, so one call per method covers every call a user makes.
    """
    vehicle = load_vehicle("gosar2022-unloaded")
    for model in (KIN(vehicle), STM(vehicle)):
        x = model.initial_state(InitialState(0.0, 0.0, 0.0, 0.05, u1=-1.0, delta=0.02))
        u = np.zeros(model.ninputs)
        u[:2] = 0.02, -1.0
        model.rhs(x, u)
        model.rhs(np.stack([x, x]), u)
        model.step(x, u, 0.01)
        model.step(np.stack([x, x]), u, 0.01)
        model.rollout(x, np.tile(u, (3, 1)), 0.01)
        model.rollout(np.stack([x, x]), np.tile(u, (2, 3, 1)), 0.01)
        model.advance(x, 0.01, 0.02, -1.0, 0.0)
        model.signals(x, u)
        model.output(x, u)
        model.output_jacobians(x, u)
        model.linearise(x, u)
        model.linearise(x, u, 0.01)
        model.steady_turn(0.02, 1.0)


if __name__ == "__main__":
    compile_all()
