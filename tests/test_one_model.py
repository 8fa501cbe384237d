"""One class per model: artic.KIN and artic.STM are what the harness, the registry and
the control API mean, and a subclass that replaces the dynamics is never bypassed."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import artic
from artic.mjcf.errors import ArticError, UserError
from artic.mjcf.schema import VehicleFileError
from artic.reduced import Driven, InitialState
from artic.reduced.kinematic import KinParameters, kin_parameters
from artic.reduced.single_track import StmParameters, stm_parameters
from artic.validation.harness.batch import run_batch
from artic.validation.harness.loop import loop_inputs, run_closed_loop
from artic.validation.harness.simulate import simulate
from artic.validation.synthetic.manoeuvres import make_profile

STEER_ERROR = 1.4
"""The subclass's steering error: 40 % more road-wheel angle than commanded."""


class Oversteered(artic.KIN):
    """KIN whose tyres turn 40 % further than the road-wheel angle says: a new rhs."""

    name = "kin"  # KIN's steering map ([steering.kin]), so both apply the same angle

    def rhs(self, x, u):
        u = np.array(u, dtype=float)
        u[..., 0] *= STEER_ERROR
        return super().rhs(x, u)


class SameRhs(artic.KIN):
    """KIN's own rhs, replaced by itself: the Python path with the built-in's physics."""

    def rhs(self, x, u):
        return super().rhs(x, u)


class Counted(SameRhs):
    """The same, declared equivalent: it keeps the compiled paths."""

    compiled_equivalent = True


class Frozen(artic.KIN):
    """A step of its own that never moves: the harness must take it."""

    def step(self, x, u, dt):
        return np.array(x, dtype=float)


@pytest.fixture(scope="module")
def logs(unloaded):
    """A forward and a reversing STM log, 20 s each (the STM is not KIN: KIN tracks it
    with errors, so a change of KIN shows)."""
    return {kind: simulate(artic.STM(unloaded), unloaded, make_profile(kind, duration=20.0))
            for kind in ("constant-steer", "ramp-steer-reverse")}


def numbers(run) -> np.ndarray:
    return run.frame.select_dtypes("number").to_numpy(dtype=float)


def test_the_registry_builds_the_public_classes(unloaded):
    assert type(artic.build_model("kin", unloaded)) is artic.KIN
    assert type(artic.build_model("stm", unloaded)) is artic.STM
    assert artic.KIN(unloaded).name == "kin" and artic.STM(unloaded).name == "stm"


def test_run_closed_loop_takes_artic_kin(unloaded, logs):
    # The control API's class goes into the harness as it is, and gives the
    # registry's KIN's run, to the bit (the same compiled loop).
    for log in logs.values():
        a = run_closed_loop(artic.KIN(unloaded), log, unloaded)
        b = run_closed_loop(artic.build_model("kin", unloaded), log, unloaded)
        assert a.meta["model"] == "kin" and a.meta["status"] == "ok"
        np.testing.assert_array_equal(numbers(a), numbers(b))
    run = run_closed_loop(artic.STM(unloaded), logs["constant-steer"], unloaded)
    assert run.meta["status"] == "ok"


def test_a_replaced_rhs_changes_the_harness_result(unloaded, logs):
    kin = artic.KIN(unloaded)
    over = Oversteered(unloaded)
    assert kin.compiled() is not None and over.compiled() is None
    log = logs["constant-steer"]
    a = run_closed_loop(kin, log, unloaded).frame
    b = run_closed_loop(over, log, unloaded).frame
    # Forward, the feedback is off: both apply the same road-wheel angle, and
    # KIN's heading changes at u tan(delta) / L1, the subclass's at
    # u tan(1.4 delta) / L1. Their heading changes are in the ratio of the two
    # integrals; RK4 and the speed ramp within a step agree with the
    # trapezoid of the 10 ms samples far inside 1 %.
    np.testing.assert_array_equal(a["delta"], b["delta"])
    u = log.frame["v_x_1"].to_numpy()[:len(a)]
    t, d = a["t"].to_numpy(), a["delta"].to_numpy()
    want = (np.trapezoid(u * np.tan(STEER_ERROR * d), t) / np.trapezoid(u * np.tan(d), t))
    turn_a = np.unwrap(a["psi_1"].to_numpy())
    turn_b = np.unwrap(b["psi_1"].to_numpy())
    got = (turn_b[-1] - turn_b[0]) / (turn_a[-1] - turn_a[0])
    assert got == pytest.approx(want, rel=0.01)
    assert abs(got - 1.0) > 0.3  # not KIN's result


def test_the_batch_honours_a_replaced_rhs(unloaded, logs):
    # The campaign's path (run_batch) takes no compiled path for the subclass either.
    log = logs["constant-steer"]
    inp = loop_inputs(log, unloaded, unloaded.steering_for("kin"))
    kin = run_batch(artic.KIN, unloaded, [inp], 3.0, 1)
    over = run_batch(Oversteered, unloaded, [inp], 3.0, 1)
    direct = run_closed_loop(Oversteered(unloaded), log, unloaded)
    n = int(over.n_done[0])
    np.testing.assert_array_equal(over.obs[0][:n], direct.frame.iloc[:, 2:15].to_numpy())
    # 40 % more yaw over a turn of about a radian: tenths of a radian apart.
    assert abs(over.obs[0][n - 1, 2] - kin.obs[0][n - 1, 2]) > 0.1


def test_the_python_path_is_the_compiled_one(unloaded, logs):
    # A replaced rhs that computes the built-in's runs through the Python
    # Runge-Kutta step and loop: the same operations, so the same numbers to
    # round-off (1e-16 per operation, a few thousand steps: far below 1e-11).
    for log in logs.values():
        a = numbers(run_closed_loop(artic.KIN(unloaded), log, unloaded))
        b = numbers(run_closed_loop(SameRhs(unloaded), log, unloaded))
        assert a.shape == b.shape
        np.testing.assert_allclose(b, a, rtol=0, atol=1e-11)


def test_a_subclass_may_declare_itself_equivalent(unloaded, logs):
    assert SameRhs(unloaded).compiled() is None
    assert Counted(unloaded).compiled() is not None
    log = logs["constant-steer"]
    np.testing.assert_array_equal(numbers(run_closed_loop(Counted(unloaded), log, unloaded)),
                                  numbers(run_closed_loop(artic.KIN(unloaded), log, unloaded)))


def test_a_replaced_step_is_what_the_harness_and_rollout_take(unloaded, logs):
    frozen = Frozen(unloaded)
    run = run_closed_loop(frozen, logs["constant-steer"], unloaded).frame
    assert np.ptp(run["x_1"]) == 0.0 and np.ptp(run["psi_1"]) == 0.0
    x0, u0 = frozen.straight(1.0)
    np.testing.assert_array_equal(frozen.rollout(x0, np.tile(u0, (5, 1)), 0.1),
                                  np.zeros((6, 4)))
    with pytest.raises(NotImplementedError, match="replaces step"):
        frozen.linearise(x0, u0, dt=0.1)


def test_a_replaced_rhs_has_its_own_jacobians(unloaded):
    # Central differences of the subclass's rhs: straight ahead, d(psi_1_dot)/d(delta)
    # is 1.4 u / L1 (KIN's u / L1 times the steering error).
    over, kin = Oversteered(unloaded), artic.KIN(unloaded)
    x0, u0 = kin.straight(2.0)
    A, B = over.linearise(x0, u0)
    A0, B0 = kin.linearise(x0, u0)
    assert B[2, 0] == pytest.approx(STEER_ERROR * B0[2, 0], rel=1e-8)
    np.testing.assert_allclose(A, A0, atol=1e-8)
    x1 = over.step(x0 + [0, 0, 0, 0.1], [0.1, 2.0], 0.1)
    assert x1[2] == pytest.approx(over.rhs(x0, [0.1, 2.0])[2] * 0.1, rel=1e-9)


def test_parameters_by_name(unloaded):
    kin = artic.KIN(unloaded)
    assert isinstance(kin.params, KinParameters)
    np.testing.assert_array_equal(kin.P, kin_parameters(unloaded))
    assert (kin.L1, kin.L1c, kin.L2) == tuple(kin.params)
    longer = artic.KIN(unloaded)
    longer.params = longer.params._replace(L1=1.4 * kin.params.L1)
    assert longer.P[0] == 1.4 * kin.params.L1 and longer.L1 == longer.params.L1
    x0, u0 = kin.straight(1.0)
    u = [0.1, 1.0]
    assert longer.rhs(x0, u)[2] == pytest.approx(kin.rhs(x0, u)[2] / 1.4, rel=1e-12)
    stm = artic.STM(unloaded)
    p = stm.params
    assert isinstance(p, StmParameters) and p.Lc == unloaded.Lc and p.m2 == unloaded.m2
    np.testing.assert_array_equal(stm.P, stm_parameters(unloaded))
    q = StmParameters.from_packed(stm.P)
    assert q.Lc == p.Lc and np.array_equal(q.C, p.C) and q.n_axles == p.n_axles == 5
    assert stm.state_labels[-1] == f"alpha_{p.n_axles}"


def test_a_vehicle_a_model_cannot_represent_is_refused_at_construction():
    scale = artic.load_vehicle("scale-model-1to14")
    artic.KIN(scale)  # KIN needs no tyre data
    with pytest.raises(VehicleFileError) as direct:
        artic.STM(scale)
    with pytest.raises(VehicleFileError) as built:
        artic.build_model("stm", scale)
    assert str(direct.value) == str(built.value)
    assert "\n" not in str(direct.value) and "tyre.f" in str(direct.value)
    assert isinstance(direct.value, UserError) and isinstance(direct.value, ArticError)


def test_the_states_point_is_documented_where_a_planner_looks():
    # X_1, Y_1: KIN's rear axle, the STM's centre of gravity, a log's sensor.
    assert "rear axle" in artic.KIN.__doc__ and "sensor" in artic.KIN.__doc__
    assert "centre of gravity" in artic.STM.__doc__ and "sensor" in artic.STM.__doc__


def test_initial_state_places_the_sensor_at_the_logs_point(unloaded):
    # The state's point is not the sensor: the signals put the sensor back
    # where the log has it, for either model.
    init = InitialState(3.0, -2.0, 0.7, 0.2, u1=1.0)
    for model in (artic.KIN(unloaded), artic.STM(unloaded)):
        x = model.initial_state(init)
        y = model.signals(x, np.r_[0.0, 1.0, 0.0][:model.ninputs])
        np.testing.assert_allclose(y[:3], [3.0, -2.0, 0.7], atol=1e-12)
        assert math.hypot(x[0] - 3.0, x[1] + 2.0) > 0.1  # a point apart from the sensor
        d = Driven(model)
        d.reset(init)
        np.testing.assert_array_equal(d.observe(0.0), y)


def test_the_former_names_warn_and_are_the_same_classes():
    from artic.reduced import models

    with pytest.warns(DeprecationWarning, match="artic.KIN"):
        assert models.KinematicModel is artic.KIN
    with pytest.warns(DeprecationWarning, match="artic.STM"):
        assert models.SingleTrackModel is artic.STM
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert artic.reduced.control.ControlModel is artic.reduced.control.ReducedModel


def test_kin_refuses_a_vehicle_whose_semitrailer_axles_lead_its_kingpin(unloaded):
    # Axles ahead of the kingpin: the semitrailer's no-slip point is ahead of
    # the hitch, L2 < 0, which eq. (1) cannot describe (its articulation
    # dynamics divide by L2 and their sign turns). One line, at construction.
    import dataclasses

    from artic.mjcf.errors import UnsupportedVehicleError

    axles = list(unloaded.axles)
    n1 = len(unloaded.tractor_axles)
    axles[n1:] = [dataclasses.replace(a, x=-a.x) for a in axles[n1:]]
    bad = dataclasses.replace(unloaded, axles=tuple(axles))
    assert np.all(bad.trailer_axle_distances < 0)
    with pytest.raises(UnsupportedVehicleError, match=r"KIN cannot represent .* L2 = -") as e:
        artic.KIN(bad)
    assert "\n" not in str(e.value)
    with pytest.raises(UnsupportedVehicleError):
        artic.build_model("kin", bad)
