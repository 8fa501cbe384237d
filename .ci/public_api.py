"""What a user's code does with artic's public API, for the type checker in CI.

``python .ci/staged.py mypy --follow-imports=silent .ci/public_api.py`` must
report no error: the names resolve through ``artic/__init__.pyi``, and the
calls match their signatures. It is type-checked, not run.
"""

from __future__ import annotations

import numpy as np

import artic


def plan(path: str) -> tuple[np.ndarray, np.ndarray]:
    """Linearise KIN about a straight reverse, then drive it from a log."""
    vehicle: artic.Vehicle = artic.load_vehicle("gosar2022-unloaded")
    kin = artic.KIN(vehicle)
    x0, u0 = kin.straight(-1.0)
    a, b = kin.linearise(x0, u0, dt=0.1)
    log: artic.Run = artic.read_log(path, vehicle=vehicle)
    model = artic.build_model("kin", vehicle)
    run: artic.Run = artic.run_closed_loop(model, log, vehicle)
    assert run.frame is not None
    return a, b
