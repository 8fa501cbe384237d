"""Tuning: the objective is the criteria, and a model tuned on its own output finds its truth."""

from __future__ import annotations

import math

import numpy as np
import pytest

from conftest import as_log
from mjcf.writer import fitted_changes, updated, write_vehicle
from reduced import KinematicModel, SingleTrackModel
from validation.campaign.tuning import Objective, apply, bounds_for, tune_model
from validation.harness import run_closed_loop
from validation.metrics import run_metrics
from validation.simulate import simulate
from validation.synthetic.manoeuvres import make_profile

TRUTH = {"stm": {"f": 7.4, "i_s": 22.3, "q": 0.006, "delta_h_offset": 0.061},
         "kin": {"i_s": 19.8, "q": 0.012, "delta_h_offset": -0.03}}


def own_logs(vehicle, model: str, truth: dict) -> list:
    """Constant steers of the model itself at its truth parameters: four, left and right."""
    v = apply(vehicle, model, truth)
    s = v.steering_for(model)
    cls = {"kin": KinematicModel, "stm": SingleTrackModel}[model]
    logs = []
    for amp in (200.0, 500.0):
        for side in ("left", "right"):
            p = make_profile("constant-steer", amplitude_deg=amp, speed_kph=8.0, side=side,
                             duration=15.0, delta_h_offset=s.delta_h_offset)
            logs.append(as_log(simulate(cls(v), v, p), f"{model}-{amp:.0f}-{side}"))
    return logs


@pytest.mark.parametrize("model", ["kin", "stm"])
def test_tuning_recovers_its_own_truth(unloaded, model):
    # Noise-free logs of the model itself: the least-squares optimum is the
    # truth exactly, so the fit must land on it to the solver's tolerance
    # (xtol 1e-6 of each bound's span: 1e-5 in i_s, 5e-7 rad in the offset).
    truth = TRUTH[model]
    logs = own_logs(unloaded, model, truth)
    fit = tune_model(model, unloaded, logs)
    for k, v in truth.items():
        assert fit.fitted[k] == pytest.approx(v, rel=1e-3, abs=1e-4), k
    assert fit.eps_n_before > 5.0 > 0.05 > fit.eps_n_after
    assert fit.cost_after < 1e-6 * fit.cost_before
    assert not fit.at_bound


def test_objective_is_the_criterion(unloaded):
    # The residuals' norms per signal are eps / mean_abs, so their sum is eps_n
    # exactly as the metrics module computes it.
    logs = own_logs(unloaded, "kin", TRUTH["kin"])
    obj = Objective("kin", unloaded, logs)
    x = np.array([b.nominal for b in obj.bounds])
    v = obj.vehicle_at(x)
    direct = np.mean([run_metrics(log.frame, run_closed_loop(KinematicModel(v), log, v).frame)
                      ["eps_n"] for log in logs])
    assert obj.eps_n(x) == pytest.approx(direct, rel=1e-9)


def test_bounds_keep_the_map_monotonic(unloaded):
    logs = own_logs(unloaded, "kin", TRUTH["kin"])
    b = {x.name: x for x in bounds_for("kin", unloaded, logs)}
    peak = max(np.abs(log.frame["delta_h"]).max() for log in logs)
    # 90 % of the fold 1/(2q) lies beyond the largest angle plus the largest offset.
    assert 0.9 / (2 * b["q"].hi) >= peak + math.radians(15) - 1e-12
    assert b["i_s"].lo == pytest.approx(0.75 * 20.5) and b["i_s"].hi == pytest.approx(1.25 * 20.5)


def test_tuned_file_round_trips(unloaded, tmp_path):
    fitted = {"stm": {"f": 7.5, "i_s": 21.9, "q": 0.008, "delta_h_offset": 0.07},
              "kin": {"i_s": 20.1, "q": 0.009, "delta_h_offset": 0.08}}
    data = updated("gosar2022-unloaded", fitted_changes(unloaded, fitted), "test fit",
                   name="tuned")
    v = write_vehicle(data, tmp_path / "sub" / "tuned.toml")
    assert v.name == "tuned" and v.f == 7.5 and v.sources[-1] == "test fit"
    assert v.steering_for("stm").i_s == 21.9 and v.steering_for("kin").q == 0.009
    assert v.steering_for("mbd") == unloaded.steering_for("mbd")
    assert v.tyre_file == unloaded.tyre_file  # still found, from another folder
    assert list((tmp_path / "sub").iterdir()) == [tmp_path / "sub" / "tuned.toml"]
