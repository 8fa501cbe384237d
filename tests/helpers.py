"""Helpers the tests share: logs made by hand, a steady turn, a rates Jacobian.

Imported as ``from tests.helpers import ...`` (``tests`` is a package); the
fixtures are in ``conftest.py``.
"""

from __future__ import annotations

import numpy as np
import pytest

from artic.mjcf import extensions
from artic.validation.logs.runfile import Run
from artic.validation.logs.schema import COLUMNS

PRESETS = ("gosar2022-unloaded", "gosar2022-loaded", "six-axle")
"""The presets the tests run on every model."""

SMALL_CAMPAIGN = {"models": ("kin",), "only": ("00-", "28-"), "jobs": 2,
                  "sweep_models": ("kin",), "recordings": False, "closing": False}
"""The smallest campaign with every cached stage: logs with twins, tuning, validation,
references, twins, the oracle rows, efficiency and the gain sweep (KIN alone on a forward tuning
constant steer and a reverse ramp steer, no recordings)."""


def needs_compiled(what: str) -> pytest.MarkDecorator:
    """Skip a test of ``what``, a compiled part with no Python version, where artic runs
    without its compiled parts on purpose (``ARTIC_NO_EXTENSIONS=1``).

    Where they are merely missing the test runs, and fails: CI builds them, so
    their absence is a failed build, not a reason to skip.
    """
    return pytest.mark.skipif(
        extensions.switched_off(),
        reason=f"{what}: compiled, with no Python version, and {extensions.NO_EXTENSIONS} "
               "switches artic's compiled parts off")


FIRST_ROLLOUT = """
import json, time
import numpy as np
import artic
from artic.reduced import control

kin = artic.KIN(artic.load_vehicle("gosar2022-unloaded"))
x0, u = np.zeros(4), np.tile([0.0, -1.0], (200, 1))  # 2 s straight back in 10 ms steps
wall, cpu = time.perf_counter(), time.process_time()
x = kin.rollout(x0, u, 0.01)
wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
stats = control.rollout_steps.stats
print(json.dumps({"wall": wall, "cpu": cpu, "hits": sum(stats.cache_hits.values()),
                  "misses": sum(stats.cache_misses.values()), "final": x[-1].tolist()}))
"""
"""A script: the first ``KIN.rollout`` of a fresh process, timed, and whether numba loaded
it from its cache; prints one JSON line."""


def as_log(run: Run, name: str = "log") -> Run:
    """Strip a model run down to the signal schema, as a measured log."""
    meta = {**run.meta, "name": name, "source": "synthetic"}
    return Run(run.frame[list(COLUMNS)].copy(), meta)


def straight_log(n: int = 2000, u: float = -0.8, gamma0: float = 0.0, dt: float = 0.01,
                 delta_h: float = 0.0) -> Run:
    """A log of a combination reversing (or driving) straight along x, gamma = 0.

    Every signal is what an ideal straight run shows; ``gamma0`` sets the
    first sample's articulation (the models start from it).
    """
    t = np.arange(n) * dt
    z = np.zeros(n)
    x = u * t
    frame = {
        "t": t, "delta_h": np.full(n, delta_h), "x_1": x, "y_1": z, "psi_1": z,
        "v_x_1": np.full(n, u), "v_y_1": z, "r_1": z, "x_2": x - 14.0, "y_2": z,
        "psi_2": z, "v_x_2": np.full(n, u), "v_y_2": z, "r_2": z, "gamma": z,
    }
    import pandas as pd

    df = pd.DataFrame(frame)
    df.loc[0, "gamma"] = gamma0
    df.loc[0, "psi_2"] = -gamma0
    return Run(df, {"name": "straight", "direction": "reverse" if u < 0 else "forward"})


def steady_turn(model, delta: float, u: float, seconds: float, tail: int) -> tuple[float, float]:
    """Mean tractor yaw rate [rad/s] and articulation [rad] over the last ``tail`` samples
    of ``seconds`` at a fixed road-wheel angle ``delta`` and speed ``u``, from straight."""
    from artic.mjcf.interface import InitialState
    from artic.validation.models import driven

    model = driven(model)  # artic.KIN and artic.STM: the harness holds their state
    model.reset(InitialState(0.0, 0.0, 0.0, 0.0, u1=u))
    out = []
    for _ in range(int(seconds / 0.01)):
        model.step(0.01, delta, u, 0.0)
        out.append(model.observe())
    y = np.array(out)[-tail:]
    return float(y[:, 5].mean()), float(y[:, 12].mean())


def rates_jacobian(p, eps: float = 1e-6) -> np.ndarray:
    """The continuous-time Jacobian of a MuJoCo model's rates at its state [1/s].

    Central differences in the state's tangent space (``qpos`` through
    ``mj_integratePos``, ``qvel``, ``act``), of ``(qvel, qacc, act_dot)``; the
    controls are restored before each evaluation (a callback writes rates into
    them). ``p`` has ``model`` and ``data`` (the plant, the truth); its state is
    restored at the end.
    """
    import mujoco

    m, d = p.model, p.data
    q0, v0, a0, c0 = d.qpos.copy(), d.qvel.copy(), d.act.copy(), d.ctrl.copy()
    nv = m.nv

    def rate(dx: np.ndarray) -> np.ndarray:
        d.qpos[:] = q0
        mujoco.mj_integratePos(m, d.qpos, dx[:nv], 1.0)
        d.qvel[:] = v0 + dx[nv:2 * nv]
        d.act[:] = a0 + dx[2 * nv:]
        d.ctrl[:] = c0
        mujoco.mj_forward(m, d)
        return np.concatenate([d.qvel, d.qacc, d.act_dot])

    n = 2 * nv + m.na
    A = np.empty((n, n))
    for k in range(n):
        e = np.zeros(n)
        e[k] = eps
        A[:, k] = (rate(e) - rate(-e)) / (2.0 * eps)
    rate(np.zeros(n))
    return A


def check_recordings(out):
    """Read every recording back: each holds every sample of each model's run."""
    # Imported here: the conftest imports this module, and a test session need
    # not load Rerun and pandas before a test asks for them.
    import math

    import pandas as pd

    from artic.validation.logs.importers import import_source
    from artic.validation.review.recording import PLOT_RATE, read_rows

    metrics = pd.read_csv(out / "metrics.csv")
    for path in (out / "recordings").glob("*.rrd"):
        rows = read_rows(path)
        if path.stem == "campaign":
            assert rows["/criteria/eps_n/kin"] == metrics.log.nunique()
            continue
        log, _ = import_source(out / "synthetic" / path.stem)
        # One plot row per PLOT_RATE sample of the log, every model's line in it.
        every = round(1.0 / (PLOT_RATE * 0.01))
        assert rows["/signals/articulation"] == math.ceil(len(log.frame) / every), path.name
        if "mbd" in set(metrics.model):
            assert rows["/yard/mbd/axle.front/wheel.front.L"] > 0
            assert rows["/yard/mbd/tyre_forces"] > 0
