"""The plant replays a log it generated: the reference is a reference for its own logs.

A log made by the plant in a configuration C (the legacy truth: a vehicle file
and the plant's own speed controller), measured by ideal sensors, and replayed
through the harness by the plant built from the truth vehicle file that
generation writes, must match it: the harness's speed following adds no lag
of its own, and the reversing feedback stays nearly idle. (The structural
truth has a steering column and a driver on the pedals, which no vehicle file
describes; it is meant to differ.)
"""

from __future__ import annotations

import warnings

import pytest

from artic.mjcf import load_vehicle
from artic.plant import Plant, PlantWarning
from artic.validation.criteria.metrics import run_metrics
from artic.validation.harness.loop import run_closed_loop
from artic.validation.synthetic.generate import simulate_manoeuvre
from artic.validation.synthetic.sensors import SensorModel
from artic.validation.synthetic.testmatrix import MATRIX
from artic.validation.synthetic.truth import write_truth_files

SEED = 0

# The criteria of a replay. The follower reproduces the speed within millimetres
# per second; what remains is what it gives up on purpose: the drive axle's
# traction slip (the truth drives with wheel torque, the replay pushes the
# axle) and, in reverse, the truth's braked trailer wheels against the
# replay's pushed trailer when the driver stops. Forward that is far below the
# criteria; in reverse the feedback that corrects it stays under 1 %.
FORWARD_EPS_N = 0.5  # [%]
FORWARD_EPS_P = 0.02  # [m]
REVERSE_J_STEER = 1.0  # [%]

KINDS = sorted({m.kind for m in MATRIX})


def first_of(kind: str):
    return next(m for m in MATRIX if m.kind == kind)


@pytest.fixture(scope="module")
def truth_files(tmp_path_factory):
    return write_truth_files(tmp_path_factory.mktemp("truth"), SEED, "legacy")


def replay(kind: str, truth_files) -> dict:
    m = first_of(kind)
    log = simulate_manoeuvre(m, SEED, SensorModel.ideal(), "legacy")
    vt = load_vehicle(truth_files[m.load])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PlantWarning)  # docking asks for lock; both limit alike
        with Plant(vt) as p:
            run = run_closed_loop(p, log, vt)
    assert run.meta["status"] == "ok"
    return {"direction": m.direction, **run_metrics(log.frame, run.frame)}


def check(result: dict) -> None:
    if result["direction"] == "forward":
        assert result["eps_n"] <= FORWARD_EPS_N, result
        assert result["eps_p"] <= FORWARD_EPS_P, result
    else:
        assert result["J_steer"] <= REVERSE_J_STEER, result


def test_truth_files_load_as_the_truth(truth_files):
    from artic.validation.synthetic.truth import truth_configuration, truth_vehicle

    truth = truth_configuration(SEED, "legacy")
    for load, path in truth_files.items():
        made = truth_vehicle(load, truth, SEED)
        read = load_vehicle(path)
        assert read.steering_for("mbd") == pytest.approx(made.steering_for("mbd"))
        assert dict(read.tyre_scaling) == pytest.approx(dict(made.tyre_scaling))
        assert read.steering_for("mbd").i_s != load_vehicle(f"gosar2022-{load}").steering_for(
            "mbd").i_s


def test_a_constant_steer_is_replayed(truth_files):
    check(replay("constant-steer", truth_files))


@pytest.mark.slow
@pytest.mark.parametrize("kind", KINDS)
def test_every_manoeuvre_kind_is_replayed(kind, truth_files):
    check(replay(kind, truth_files))


def test_ideal_sensors_report_the_truth():
    import numpy as np
    import pandas as pd

    from artic.validation.synthetic.sensors import measure

    t = np.arange(50) * 0.01
    frame = pd.DataFrame({"t": t, "delta_h": np.sin(t), "x_1": t, "y_1": 0 * t, "psi_1": 0 * t,
                          "v_x_1": 1 + 0 * t, "v_y_1": 0 * t, "r_1": 0 * t, "x_2": t - 10,
                          "y_2": 0 * t, "psi_2": 0 * t, "v_x_2": 1 + 0 * t, "v_y_2": 0 * t,
                          "r_2": 0 * t, "gamma": 0 * t})
    out = measure(frame, np.random.default_rng(0), SensorModel.ideal())
    pd.testing.assert_frame_equal(out, frame)
    noisy = measure(frame, np.random.default_rng(0), SensorModel())
    assert not noisy["x_1"].equals(frame["x_1"])
