"""The feedback gain sweep and each model's stability bound."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from artic.mjcf import load_vehicle
from artic.reduced.kinematic import kin_rhs
from artic.reduced.single_track import N_BODY, stm_parameters, stm_rhs
from artic.validation.criteria.metrics import run_metrics
from artic.validation.harness.loop import run_closed_loop
from artic.validation.models import spec
from artic.validation.runs.gainsweep import (
    gain_sweep,
    model_lengths,
    plot_gain_sweep,
    stability_bound,
    sweep_table,
)
from tests.helpers import straight_log


def test_bound_is_eq7_on_each_models_lengths(unloaded):
    v = unloaded
    assert stability_bound(v, "paper") == pytest.approx(v.L1 / (v.L2 - v.L1c))
    L1, L1c, L2 = model_lengths(v, "kin")
    assert stability_bound(v, "kin") == pytest.approx(L1 / (L2 - L1c))
    # KIN's equivalent lengths move the bound off the paper's (0.504 against 0.556 on this
    # preset): the tridem's no-slip point lies behind its middle axle.
    assert stability_bound(v, "kin") < 0.95 * stability_bound(v, "paper")


def slowest_pole(rhs, P, nx: int, u1: float, K: float) -> float:
    """Largest real part of the closed loop's poles about straight reversing [1/s].

    The harness's feedback ``delta = K (gamma_model - gamma_measured)`` with the
    measurement straight; the Jacobian of ``rhs`` by central differences over
    the states from the articulation on (position and heading are neutral).
    """
    x0, h = np.zeros(nx), 1e-7
    J = np.zeros((nx - 3, nx - 3))
    for j, k in enumerate(range(3, nx)):
        xp, xm = x0.copy(), x0.copy()
        xp[k] += h
        xm[k] -= h
        J[:, j] = ((rhs(xp, u1, 0.0, K * xp[3], P) - rhs(xm, u1, 0.0, K * xm[3], P))
                   / (2 * h))[3:]
    return float(max(np.linalg.eigvals(J).real))


@pytest.mark.parametrize("preset", ["gosar2022-unloaded", "six-axle"])
@pytest.mark.parametrize("u1", [-0.3, -1.5])
def test_each_models_loop_turns_stable_at_its_own_bound(preset, u1):
    # 3 % either side of the bound the slowest pole changes sign, for KIN (its
    # eigenvalue u1 (K (L2 - L1c) - L1) / (L1 L2) vanishes exactly there) and for
    # the STM with its tyres and inertia (its low-speed limit; at 1.5 m/s the
    # inertia shifts the pole by well under the 3 % margin's 0.003 /s). The paper's
    # lengths miss: 3 % above their bound the six-axle tractor's loop is unstable.
    v = load_vehicle(preset)
    P_stm = stm_parameters(v)
    nx = N_BODY + int(P_stm[7] + P_stm[8])
    kin_P = np.array(model_lengths(v, "kin"))
    for model, rhs, P, n in (("kin", kin_rhs, kin_P, 4), ("stm", stm_rhs, P_stm, nx)):
        k_min = stability_bound(v, model)
        assert slowest_pole(rhs, P, n, u1, 0.97 * k_min) > 0, model
        assert slowest_pole(rhs, P, n, u1, 1.03 * k_min) < 0, model
    if preset == "six-axle":
        assert slowest_pole(kin_rhs, kin_P, 4, u1, 1.03 * stability_bound(v, "paper")) > 0


def test_sweep_separates_at_the_bound(unloaded, tmp_path):
    # Straight reversing from 0.1 rad of articulation: below K_min the model's
    # articulation runs away from the log's and eps_n grows; above it the
    # feedback pulls it back. Far above, the feedback costs steering effort.
    k_min = stability_bound(unloaded, "kin")
    logs = {"unloaded": (unloaded, [straight_log(n=3000, u=-0.8, gamma0=0.1)])}
    sweep = gain_sweep(logs, ["kin"], gains=(0.5 * k_min, 2 * k_min, 8.0))
    by_k = sweep.set_index("K")
    err = by_k["eps_a"]
    assert err[0.5 * k_min] > 3 * err[2 * k_min]
    assert sweep.attrs["K_min"] == {"kin": pytest.approx(k_min)}
    assert sweep["K_min"].to_numpy() == pytest.approx(np.full(len(sweep), k_min))
    table = sweep_table(sweep)
    assert list(table["stable"]) == ["no", "bound", "yes", "yes"]
    plot_gain_sweep(sweep, tmp_path / "sweep.png", 3.0)
    assert (tmp_path / "sweep.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_sweep_rows_are_the_means_of_the_harness_runs_criteria(unloaded):
    # The sweep derives each log's inputs once for every K, runs the gains side
    # by side and leaves out the position errors it does not report: its rows
    # must be what one harness run per (model, K, log) and its criteria give,
    # at any number of threads.
    logs = [straight_log(n=1500, u=-0.8, gamma0=0.1), straight_log(n=900, u=-1.0, gamma0=-0.05)]
    for i, log in enumerate(logs):
        log.meta["name"] = f"log{i}"
    by_load = {"unloaded": (unloaded, logs)}
    sweep = gain_sweep(by_load, ["kin", "stm"], gains=(0.25, 3.0), jobs=2)
    pd.testing.assert_frame_equal(sweep, gain_sweep(by_load, ["kin", "stm"], gains=(0.25, 3.0)))
    assert len(sweep) == 2 * 3  # the two gains and the bound, per model
    for row in sweep.itertuples():
        direct = pd.DataFrame([run_metrics(log.frame, run_closed_loop(
            spec(row.model).build(unloaded), log, unloaded, row.K).frame) for log in logs])
        # eps_n is NaN on a straight log, which has no yaw rate to normalise by.
        assert np.isfinite([row.J_steer, row.eps_a, row.eps_v]).all() and row.J_steer > 0
        for c in ("J_steer", "eps_n", "eps_a", "eps_v"):
            assert getattr(row, c) == pytest.approx(direct[c].mean(), rel=1e-12, abs=0,
                                                    nan_ok=True), c


def test_sweep_table_has_one_bound_per_model_when_they_differ():
    import pandas as pd

    rows = [{"model": m, "K": k, "J_steer": 1.0, "J_steer_lo": 0.5, "J_steer_hi": 1.5,
             "eps_n": 2.0, "eps_n_lo": 1.0, "eps_n_hi": 3.0, "stopped": 0, "n": 2}
            for m in ("kin", "mbd") for k in (0.5, 0.6, 1.0)]
    sweep = pd.DataFrame(rows)
    sweep.attrs["K_min"] = {"kin": 0.5, "mbd": 0.6}
    table = sweep_table(sweep)
    assert list(table["stable_kin"]) == ["bound", "yes", "yes"]
    assert list(table["stable_mbd"]) == ["no", "bound", "yes"]
    assert {"J_steer_kin", "J_steer_kin_lo", "J_steer_kin_hi", "eps_n_mbd_hi"} <= set(table)
