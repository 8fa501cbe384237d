"""The docking MPCs designed on KIN and on the STM (CasADi, an optional extra)."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("casadi", reason="the docking MPCs need CasADi: pip install 'artic[mpc]'")

from artic.mjcf import load_vehicle  # noqa: E402
from artic.mjcf.outline import DOCK_FACE  # noqa: E402
from artic.validation.docking.controllers import Task  # noqa: E402
from artic.validation.docking.controllers.mpc import HORIZON, MPCKin, MPCStm  # noqa: E402
from artic.validation.docking.planner import HybridAStar  # noqa: E402
from artic.validation.docking.run import drive  # noqa: E402
from artic.validation.docking.scenarios import scenario  # noqa: E402

VEHICLE = "gosar2022-unloaded"


@pytest.mark.parametrize("cls", [MPCKin, MPCStm])
def test_the_predicted_sensitivity_is_the_rollouts(cls):
    """``X + S dz`` against the design model rolled out with the moved steering: O(dz^2)."""
    v = load_vehicle(VEHICLE)
    s = scenario("straight")
    yard = s.yard(v)
    c = cls()
    c.reset(Task(v, yard, HybridAStar().plan(yard, v, s.start(0)), 0.1, 1.1, 1.67, 0.5, 6.3))
    x = np.array(c.model.straight(-1.1)[0], dtype=float)
    x[:4] = [DOCK_FACE[0] + 25.0, 0.3, 0.05, 0.1]
    base = np.linspace(0.0, 0.1, HORIZON)
    X, S, _ = c.predict(x, base, -1.1)
    dz = 1e-4 * np.sin(np.arange(HORIZON))
    moved, _, _ = c.predict(x, base + np.cumsum(dz), -1.1)
    lin = X[1:] + S @ dz
    change = np.abs(moved[1:] - X[1:]).max()
    assert change > 1e-6  # the moves do move the prediction
    assert np.abs(moved[1:] - lin).max() < 1e-3 * change


@pytest.mark.parametrize("name", ["mpc-kin", "mpc-stm"])
def test_the_mpcs_dock_a_straight_start_on_the_plant(name):
    r = drive(scenario("straight"), VEHICLE, name, 0)
    row = r.row
    assert row["success"], row["failure"]
    assert abs(row["lateral_error_m"]) <= 0.10
    assert abs(row["heading_error_deg"]) <= 1.0
    # Every sample that moves gives its predicted horizon for the recording, from
    # where the semitrailer axle is, and the plan's points it was compared with.
    given = [(h, ref) for h, ref in zip(r.trace.horizons, r.trace.references, strict=True)
             if h is not None]
    assert len(given) > 100 and given[-1][0].shape == given[-1][1].shape == (HORIZON + 1, 2)


@pytest.mark.slow
@pytest.mark.parametrize("name", ["mpc-kin", "mpc-stm"])
def test_the_mpcs_dock_the_bay(name):
    for seed in range(2):
        row = drive(scenario("bay"), VEHICLE, name, seed).row
        assert row["success"], (name, seed, row["failure"])
