"""The plant's compiled closed loop (plant/_loop_c.c) against the Python loop it replaces.

The Python loop of :mod:`artic.validation.harness.loop` driving :class:`plant.Plant`
through ``step`` and ``observe`` is the reference. Both call the same MuJoCo
step with the same controls, so they agree to rounding; the bound 1e-9 is
far above double rounding over these runs (they agree exactly here) and far
below any physical effect (a micrometre, a microradian).
"""

from __future__ import annotations

import math
import warnings
from concurrent.futures import ThreadPoolExecutor
from dataclasses import replace

import numpy as np
import pytest

from artic.mjcf.interface import LoopArgs
from artic.plant import Plant, PlantError, PlantWarning, closedloop
from artic.validation.harness.loop import loop_inputs, run_inputs
from tests.helpers import straight_log

TOL = 1e-9

needs_loop = pytest.mark.skipif(
    bool(closedloop.unavailable_reason()),
    reason=f"the compiled loop is not built here ({closedloop.unavailable_reason()}): these "
           "tests compare it with the Python loop, which the rest of the suite runs")


def _speed_log(n: int = 1500, dt: float = 0.01):
    """Forward at 2 m/s, braking through standstill into reverse at -1 m/s, steering."""
    log = straight_log(n=n, u=2.0, dt=dt, delta_h=math.radians(150.0))
    t = log.frame["t"].to_numpy()
    u = np.interp(t, [0.0, 4.0, 9.0, t[-1]], [2.0, 2.0, -1.0, -1.0])
    log.frame["v_x_1"] = u
    log.frame["v_x_2"] = u
    return log


def _both(vehicle, log, gain=3.0, inputs=None, plant_kw=None):
    steering = vehicle.steering_for("mbd")
    inp = inputs if inputs is not None else loop_inputs(log, vehicle, steering)
    out = []
    for compiled in (True, False):
        with Plant(vehicle, **(plant_kw or {})) as p:
            p._compiled_loop = compiled
            p._compiled_step = compiled  # the reference: Plant.step in Python
            assert (p.closed_loop() is not None) == compiled
            extras: dict = {}
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                res = run_inputs(p, inp, vehicle, gain, extras)
            out.append((res, extras, [str(w.message) for w in caught
                                      if issubclass(w.category, PlantWarning)], p))
    return out


@needs_loop
@pytest.mark.parametrize("which", ["through-standstill", "reverse-feedback"])
def test_compiled_loop_equals_python_loop(unloaded, which):
    log = _speed_log() if which == "through-standstill" else \
        straight_log(n=1500, u=-1.0, gamma0=0.25)
    (a, ea, wa, pa), (b, eb, wb, pb) = _both(unloaded, log)
    assert a[4] == b[4] == log.frame.shape[0]
    for x, y in zip(a[:4], b[:4], strict=True):
        np.testing.assert_allclose(x, y, rtol=0.0, atol=TOL)
    assert ea.keys() == eb.keys() and len(ea) == len(pa.extra_columns)
    for c in ea:
        assert ea[c].dtype == np.float32
        np.testing.assert_allclose(ea[c], eb[c], rtol=0.0, atol=TOL, err_msg=c)
    # The loop's state is handed back: the plant can go on stepping from it.
    assert pa.steer_limited == pb.steer_limited
    assert pa._integral == pytest.approx(pb._integral, abs=TOL)
    np.testing.assert_allclose(pa._psi, pb._psi, atol=TOL)
    assert wa == wb
    if which == "reverse-feedback":  # the feedback did act
        assert np.abs(a[2]).max() > 0.05


@needs_loop
def test_compiled_loop_weighs_the_feedback_as_python_does(unloaded):
    # The handover's fractional weights (reversing.feedback_weight), here a weight
    # that sweeps 0..1 twice over a reverse with the feedback busy (the model starts
    # on the log's 0.25 rad, the log's articulation then is 0): C = Python, and the
    # term is w K wrap(e) sample by sample.
    log = straight_log(n=800, u=-1.0, gamma0=0.25)
    steering = unloaded.steering_for("mbd")
    inp = loop_inputs(log, unloaded, steering)
    w = 0.5 - 0.5 * np.cos(2 * math.pi * inp.t / 4.0)
    inp = replace(inp, weight=w)
    (a, _, _, _), (b, _, _, _) = _both(unloaded, log, inputs=inp)
    assert a[4] == b[4] == inp.t.size
    for x, y in zip(a[:4], b[:4], strict=True):
        np.testing.assert_allclose(x, y, rtol=0.0, atol=TOL)
    # The law reads the hitch joint's angle, the signal is the two units' headings'
    # difference: they differ by the units' small roll and pitch, 1e-5 of the angle.
    e = np.angle(np.exp(1j * (a[0][:, 12] - inp.gamma_meas)))
    unsat = ~a[3]
    np.testing.assert_allclose(a[2][unsat], (w * 3.0 * e)[unsat], rtol=1e-4, atol=1e-12)
    part = (w > 0.05) & (w < 0.95)
    assert part.sum() > 100 and np.abs(a[2][part]).max() > 0.05  # the partial weights act


@needs_loop
def test_the_loop_stops_at_the_jackknife_limit_where_python_does(unloaded):
    (a, _, _, _), (b, _, _, _) = _both(unloaded, straight_log(n=3000, u=-1.5, gamma0=0.3),
                                       gain=0.0)
    assert a[4] == b[4] < 3000  # open loop, reversing from 0.3 rad jackknifes
    assert abs(a[0][a[4] - 1, 12]) > unloaded.gamma_max
    np.testing.assert_allclose(a[0][:a[4]], b[0][:b[4]], rtol=0.0, atol=TOL)


@needs_loop
def test_steering_beyond_the_linkage_is_warned_once_as_in_python(unloaded):
    # 900 deg at the steering wheel asks for the road-wheel limit, 43 deg, past the
    # linkage's 37 deg stop of the left wheel turning right.
    log = straight_log(n=300, u=2.0, delta_h=-math.radians(900.0))
    (a, _, wa, pa), (b, _, wb, pb) = _both(unloaded, log)
    assert pa.steer_limited == pb.steer_limited > 0
    assert len(wa) == 1 and wa == wb and "beyond the linkage" in wa[0]
    np.testing.assert_allclose(a[0], b[0], rtol=0.0, atol=TOL)


@needs_loop
def test_a_diverged_step_raises_the_same_error(unloaded):
    steering = unloaded.steering_for("mbd")
    inp = loop_inputs(straight_log(n=200, u=2.0), unloaded, steering)
    inp.delta_c[50] = np.nan  # a NaN steering command: MuJoCo refuses the control
    errors = []
    for compiled in (True, False):
        with Plant(unloaded) as p, warnings.catch_warnings():
            warnings.simplefilter("ignore", PlantWarning)
            p._compiled_loop = p._compiled_step = compiled
            with pytest.raises(PlantError) as exc:
                run_inputs(p, inp, unloaded, 3.0)
            errors.append(str(exc.value))
    assert errors[0] == errors[1] and "t = 0.50" in errors[0]


@needs_loop
def test_plants_on_threads_give_the_serial_numbers(unloaded):
    steering = unloaded.steering_for("mbd")
    logs = [straight_log(n=600, u=-1.0, gamma0=g) for g in (0.1, -0.2, 0.3)]
    inputs = [loop_inputs(log, unloaded, steering) for log in logs]

    def one(inp):
        with Plant(unloaded) as p:
            return run_inputs(p, inp, unloaded, 3.0)[0]

    serial = [one(i) for i in inputs]
    with ThreadPoolExecutor(2) as pool:
        threaded = list(pool.map(one, inputs))
    for s, t in zip(serial, threaded, strict=True):
        np.testing.assert_array_equal(s, t)


@needs_loop
def test_the_predicates_are_booleans(unloaded):
    # available() is True where the loop runs (a reason would be falsy there and
    # truthy where it cannot: the inverted reading this replaced).
    with Plant(unloaded) as p:
        assert closedloop.available(p) is True and closedloop.step_available(p) is True
        assert closedloop.why_no_loop(p) == "" and closedloop.why_no_step(p) == ""
        assert p.closed_loop() is not None


@needs_loop
@pytest.mark.parametrize("kw, why", [({"backend": "python"}, "numpy tyre callback"),
                                     ({"speed": "drive"}, "speed mode is 'drive'")])
def test_plants_the_loop_cannot_run_use_the_python_loop(unloaded, kw, why):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        p = Plant(unloaded, **kw)
    with p:
        assert p.closed_loop() is None
        assert why in closedloop.why_no_loop(p) and closedloop.available(p) is False
        with pytest.raises(RuntimeError, match=why):
            closedloop.run(p, LoopArgs(np.full(1, 0.01), *np.zeros((5, 2)), 3.0, 0.5, 1.5))


@needs_loop
def test_without_the_extension_the_python_loop_runs_and_says_so(unloaded, monkeypatch):
    # An install without a C compiler has no _loop_c: the harness falls back to the
    # Python loop, with one warning, and the run is the same.
    import artic.plant.plant as plant_module

    steering = unloaded.steering_for("mbd")
    inp = loop_inputs(straight_log(n=300, u=-1.0, gamma0=0.2), unloaded, steering)
    with Plant(unloaded) as p:
        compiled = run_inputs(p, inp, unloaded, 3.0)
    monkeypatch.setattr(closedloop, "_loaded", lambda: (None, "not built here"))
    monkeypatch.setattr(plant_module, "_warned", set())
    with Plant(unloaded) as p:
        with pytest.warns(PlantWarning, match="closed loop is unavailable .not built here"):
            assert p.closed_loop() is None
        python = run_inputs(p, inp, unloaded, 3.0)
    assert compiled[4] == python[4]
    np.testing.assert_allclose(compiled[0], python[0], rtol=0.0, atol=TOL)
