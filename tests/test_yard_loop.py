"""The yard truth's compiled closed loop is the harness's Python loop, to the bit.

The floor (the truth that made a log) and its open-loop predictions' replay run
the harness's loop in C (:mod:`artic.validation.synthetic.yardloop`); the
harness's Python loop (``_python_loop``) is the reference it replaces. Every
comparison here is exact (``np.array_equal``): the C loop does the same IEEE
operations in the same order, so no tolerance is due, and the campaign's
floor rows must not move by a digit.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from artic.validation.criteria.prediction import Replay, prediction_errors, truth_states
from artic.validation.harness import loop as harness
from artic.validation.models import build, steering_for
from artic.validation.synthetic import yardloop
from artic.validation.synthetic.floor import floor_replay
from artic.validation.synthetic.generate import simulate_manoeuvre
from artic.validation.synthetic.sensors import SensorModel
from artic.validation.synthetic.testmatrix import MATRIX
from artic.validation.synthetic.truth import truth_vehicle
from artic.validation.synthetic.yardtruth import YardTruth
from tests.helpers import needs_compiled

pytestmark = needs_compiled("the yard truth's compiled loop")

SEED = 0
GAIN = 3.0  # the campaign's K [rad/rad]


@pytest.fixture(scope="module")
def docking():
    """A measured docking log (noisy sensors, as the campaign's) and its truth's vehicle."""
    m = next(m for m in MATRIX if m.name.startswith("44-docking"))
    log = simulate_manoeuvre(m, SEED, SensorModel(), "independent")
    return log, truth_vehicle(m.load, log.meta["truth"], SEED, log.meta["slope"])


def _both(make, run):
    """``run(model)`` with the Python loop, then with the compiled one, each on a new model."""
    out = []
    for compiled in (False, True):
        model = make()
        with pytest.MonkeyPatch.context() as mp:
            mp.setattr(yardloop, "available", lambda _lib, on=compiled: on)
            out.append((run(model), model))
    return out


def test_the_loop_is_there(docking):
    # Without it every check below would compare the Python loop with itself.
    log, vt = docking
    assert yardloop.available(build("floor", vt, log)._lib)


def test_the_floors_run_is_the_python_loops(docking):
    log, vt = docking
    floor = build("floor", vt, log)
    assert isinstance(floor, YardTruth) and floor.closed_loop() is not None
    inputs = harness.loop_inputs(log, vt, steering_for(vt, floor))

    def run(model):
        return harness.run_inputs(model, inputs, vt, GAIN)

    (py, m_py), (c, m_c) = _both(lambda: build("floor", vt, log), run)
    assert py[4] == c[4] == inputs.t.size  # every sample, and the feedback worked in both
    assert np.abs(py[2]).max() > 0.0
    for a, b in zip(py[:4], c[:4], strict=True):
        assert np.array_equal(a, b, equal_nan=True)
    # The state it leaves (MuJoCo's, the hidden states, the headings, the counts) is the same.
    assert np.array_equal(m_py.full_state(), m_c.full_state())


def test_a_stop_at_the_jackknife_limit_is_the_python_loops(docking):
    log, vt = docking
    inputs = harness.loop_inputs(log, vt, steering_for(vt, build("floor", vt, log)))
    limit = 0.5 * float(np.abs(log.frame["gamma"]).max())  # passed halfway through the log
    args = harness.loop_args(inputs, vt, GAIN)._replace(gamma_max=limit)
    ref_model, model = build("floor", vt, log), build("floor", vt, log)
    ref_model.reset(inputs.initial)
    ref = harness._python_loop(ref_model, args)
    model.reset(inputs.initial)
    got = model.closed_loop()(args)
    assert 1 < ref[4] < inputs.t.size and got.n_done == ref[4]
    for a, b in zip(ref[:4], (got.obs, got.delta, got.delta_fb, got.saturated), strict=True):
        assert np.array_equal(a, b, equal_nan=True)
    assert np.array_equal(ref_model.full_state(), model.full_state())


def test_the_replays_predictions_are_the_python_loops(docking):
    log, vt = docking
    states = truth_states(log.meta)

    def run(model):
        return prediction_errors(model, log, vt, states=states, per_start=True, share=True)

    (py, _), (c, _) = _both(lambda: floor_replay(vt, log), run)
    assert isinstance(floor_replay(vt, log), Replay)
    assert py["starts"] > 0 and py["starts"] == c["starts"]
    for key in ("p", "gamma"):
        assert np.array_equal(py["per_start"][key], c["per_start"][key], equal_nan=True)
    assert py["replays"].runs.keys() == c["replays"].runs.keys()
    for k, (obs, n) in py["replays"].runs.items():
        assert c["replays"].runs[k][1] == n
        assert np.array_equal(c["replays"].runs[k][0], obs, equal_nan=True)


def test_a_replay_past_its_recorded_steps_fails_as_in_python(docking):
    log, vt = docking
    states = truth_states(log.meta)
    inputs = harness.loop_inputs(log, vt, steering_for(vt, floor_replay(vt, log)))
    t_start = float(states.t[states.t.size // 2])  # a state the log holds, halfway
    k = int(np.argmin(np.abs(inputs.t - t_start)))
    window = harness.window(inputs, log.frame, k, inputs.t.size)
    x = states.at(float(inputs.t[k]))
    assert x is not None
    errors = []
    for compiled in (False, True):
        whole = floor_replay(vt, log)
        first = whole.actuation.index(float(inputs.t[k]))
        # five steps of actuation left where the window asks for hundreds
        short = dataclasses.replace(whole.actuation, x=whole.actuation.x[:first + 5])
        model = Replay(whole.truth, short)
        with pytest.MonkeyPatch.context() as mp:
            mp.setattr(yardloop, "available", lambda _lib, on=compiled: on)
            with pytest.raises(ValueError, match="recorded actuation ends") as err:
                harness.run_inputs(model, window, vt, gain=0.0,
                                   start=lambda _i, m=model, i=first: m.start(x, i))
        errors.append(str(err.value))
    assert errors[0] == errors[1]
