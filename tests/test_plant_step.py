"""The plant's single step and observation in compiled code against Python's.

``Plant.step`` and ``Plant.observe`` run in C (``artic_step`` and
``artic_observe`` in plant/_loop_c.c) for plants that Python drives one step
at a time, as the synthetic truth's drivers do. Python's own ``step`` and
``observe`` are the reference (``Plant._compiled_step = False``). Both set the
same controls and call the same MuJoCo step and the same libm functions in
the same order, so they agree to the bit: any difference, even one rounding,
is a change in what is computed and fails these tests.
"""

from __future__ import annotations

import dataclasses
import math
import sys
import warnings

import numpy as np
import pytest

from artic.mjcf.interface import InitialState
from artic.plant import Plant, PlantError, PlantWarning, closedloop
from artic.plant.tyre import TyreRangeWarning
from tests.helpers import needs_compiled

# The compiled step against Python's: without it both would be Python's.
pytestmark = needs_compiled("the compiled plant step")


def _drive(vehicle, compiled: bool, speed: str, n: int = 800, plant_kw=None, edit=None):
    """A run through standstill into reverse, steering past the linkage's stop."""
    with Plant(vehicle, speed=speed, **(plant_kw or {})) as p:
        p._compiled_step = compiled
        if edit is not None:
            edit(p)
        p.reset(InitialState(0.0, 0.0, 0.4, 0.1, u1=1.5))
        obs = []
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            for k in range(n):
                obs.append(p.observe())
                u = 1.5 - 3.0 * k / n  # +1.5 to -1.5 m/s
                # Past the wheel's stop turning right between 2 and 3 s.
                delta = -1.0 if 200 <= k < 300 else 0.3 * math.sin(k / 60.0)
                p.pedals = (0.4, 0.0) if k % 200 < 150 else (0.0, 0.3)
                p.step(0.01, delta, u, -3.0 / (n * 0.01))
        return (np.array(obs), p.steer_limited, p._integral, p._psi.copy(),
                [(w.category, str(w.message)) for w in caught])


@pytest.mark.parametrize("speed", ["pedals", "follow", "drive"])
def test_the_compiled_step_is_the_python_step_to_the_bit(loaded, speed):
    a, b = _drive(loaded, True, speed), _drive(loaded, False, speed)
    np.testing.assert_array_equal(a[0], b[0])
    assert a[1] == b[1] == 100  # every step of the second past the stop is counted
    assert a[2] == b[2]
    np.testing.assert_array_equal(a[3], b[3])
    limit = [m for c, m in a[4] if issubclass(c, PlantWarning)]
    assert a[4] == b[4] and len(limit) == 1 and "t = 2.00 s" in limit[0]
    # The run did what it is for: it turned, and it reversed.
    assert np.abs(a[0][:, 12]).max() > 0.05 and a[0][:, 3].min() < -0.04


def test_the_compiled_step_names_tyres_outside_their_file_as_python_does(loaded):
    # A file that claims loads above 10 kN are out of range: every wheel is, at rest.
    def low_fzmax(p):
        p.tyres = [dataclasses.replace(t, FZMAX=1e4) for t in p.tyres]

    a = _drive(loaded, True, "follow", n=50, edit=low_fzmax)
    b = _drive(loaded, False, "follow", n=50, edit=low_fzmax)
    ranges = [m for c, m in a[4] if issubclass(c, TyreRangeWarning)]
    assert len(ranges) == 50 and "Fz = " in ranges[0]  # once per step, as in Python
    assert a[4] == b[4]
    np.testing.assert_array_equal(a[0], b[0])


def test_a_diverged_compiled_step_raises_what_python_raises(loaded):
    errors = []
    for compiled in (True, False):
        with Plant(loaded) as p, warnings.catch_warnings():
            warnings.simplefilter("ignore", PlantWarning)
            p._compiled_step = compiled
            p.reset(InitialState(0.0, 0.0, 0.0, 0.0, u1=1.0))
            for _ in range(30):
                p.step(0.01, 0.0, 1.0, 0.0)
            with pytest.raises(PlantError) as exc:
                p.step(0.01, math.nan, 1.0, 0.0)  # MuJoCo refuses a NaN control
            errors.append(str(exc.value))
    assert errors[0] == errors[1] and "t = 0.300 s" in errors[0]


def test_headings_are_shared_with_the_compiled_loop_and_reset(loaded):
    # The unwrapped headings live in the C struct; Plant._psi is a view of them,
    # so a reset, a Python observation and a compiled one all see the same state.
    with Plant(loaded) as p:
        assert p._stepper is not None
        p.reset(InitialState(0.0, 0.0, 3.0, 0.2))
        assert tuple(p._stepper.struct.psi) == (3.0, 2.8)
        compiled = p.observe()
        p._compiled_step = False
        p._psi[:] = (3.0, 2.8)
        np.testing.assert_array_equal(compiled, p.observe())


def test_plants_without_the_compiled_step_run_in_python(loaded, monkeypatch):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with Plant(loaded, backend="python") as p:  # its callback is Python: no C step
            assert p._stepper is None
            assert "numpy" in closedloop.why_no_step(p) and closedloop.step_available(p) is False
    monkeypatch.setattr(closedloop, "_loaded", lambda: (None, "not built here"))
    with Plant(loaded) as p:
        assert p._stepper is None and closedloop.why_no_step(p) == "not built here"
        p.reset(InitialState(0.0, 0.0, 0.0, 0.0, u1=1.0))
        p.step(0.01, 0.1, 1.0, 0.0)
        assert p.observe()[3] == pytest.approx(1.0, abs=0.01)


# ------------------------------------------------- a docking run's steps per sample
RAMP_N, RAMP_DT = 10, 0.01


def _ramp_targets(steering, k: int) -> np.ndarray:
    """Sample ``k``'s targets: the wheel past either lock and back, the speed through
    standstill; each sample's command takes over from the one before within the sample,
    as a delayed command does."""
    def command(i):
        wheel = steering.steering_wheel(0.0) + (16.0 if (i // 8) % 2 else -16.0) * (i < 40)
        return wheel, -1.5 if (i // 9) % 2 == 0 else 1.0

    targets = np.tile(command(max(k - 1, 0)), (RAMP_N, 1))
    targets[k % RAMP_N:] = command(k)
    return targets


def _ramped(vehicle, compiled: bool, samples: int = 80, edit=None, gamma_max=0.3):
    """A docking run's plant steps, through the compiled :class:`closedloop.Ramp` or
    ``drive``'s Python loop (the reference, written out here as it is there)."""
    steering = vehicle.steering_for("mbd")
    wheel_step, u_step = 30.0 * RAMP_DT, 2.0 * RAMP_DT
    with Plant(vehicle) as p, warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        if edit is not None:
            edit(p)
        p.reset(InitialState(0.0, 0.0, 0.0, 0.0, u1=0.0))
        wheel, u, t = steering.steering_wheel(0.0), 0.0, 0.0
        ramp = closedloop.Ramp(p, steering, RAMP_N, RAMP_DT, (wheel_step, u_step), gamma_max,
                               (wheel, u, t)) if compiled else None
        obs, log, end = [], [], "timeout"
        for k in range(samples):
            targets = _ramp_targets(steering, k)
            if ramp is not None:
                ramp.targets[:] = targets
                rows, steps, code = ramp.run()
                obs += list(rows)
                log += steps.tolist()
                if code == closedloop.DIVERGED:
                    with pytest.raises(PlantError) as exc:
                        ramp.raise_diverged()
                    end = str(exc.value)
                elif code == closedloop.STOPPED:
                    end = f"jackknife at {log[-1][2]}"
                if code != closedloop.DONE:
                    break
                continue
            for j in range(RAMP_N):
                wheel += min(max(targets[j, 0] - wheel, -wheel_step), wheel_step)
                u_next = u + min(max(targets[j, 1] - u, -u_step), u_step)
                try:
                    p.step(RAMP_DT, float(steering.road_wheel(float(wheel))), u,
                           (u_next - u) / RAMP_DT)
                except PlantError as exc:
                    end = str(exc)
                    break
                u = u_next
                t = t + RAMP_DT
                obs.append(p.observe())
                log.append([wheel, u, t])
                if abs(p.gamma) > gamma_max:
                    end = f"jackknife at {t}"
                    break
            if end != "timeout":
                break
        return (np.array(obs), np.array(log), end, p.steer_limited, p._integral,
                [(w.category, str(w.message)) for w in caught])


def test_a_docking_run_s_compiled_steps_are_its_python_loop_s_to_the_bit(unloaded):
    a, b = _ramped(unloaded, True), _ramped(unloaded, False)
    np.testing.assert_array_equal(a[0], b[0])
    np.testing.assert_array_equal(a[1], b[1])
    assert a[2:] == b[2:]
    # The run did what it is for: past the lock (counted, warned once), the wheel and
    # the speed at their rate limits, through standstill, and on until a jackknife.
    assert a[3] > 0 and len([m for c, m in a[5] if issubclass(c, PlantWarning)]) == 1
    assert np.abs(np.diff(a[1][:, 0])).max() == pytest.approx(30.0 * RAMP_DT)
    assert a[1][:, 1].min() < -0.5 and a[1][:, 1].max() > 0.1
    assert a[2].startswith("jackknife") and len(a[0]) % RAMP_N != 0


def test_a_docking_run_s_compiled_steps_name_tyres_and_divergence_as_python_does(unloaded):
    # A file that claims loads above 10 kN are out of range: every wheel is, every step.
    def low_fzmax(p):
        p.tyres = [dataclasses.replace(t, FZMAX=1e4) for t in p.tyres]

    a, b = (_ramped(unloaded, c, samples=3, edit=low_fzmax) for c in (True, False))
    ranges = [m for c, m in a[5] if issubclass(c, TyreRangeWarning)]
    assert len(ranges) == 3 * RAMP_N and a[5] == b[5]
    np.testing.assert_array_equal(a[0], b[0])

    # A NaN target at sample 2, step 4: MuJoCo refuses the control, the run ends there.
    def nan_at(steering, k, targets=_ramp_targets):
        out = targets(steering, k)
        if k == 2:
            out[4:, 0] = math.nan
        return out

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(sys.modules[__name__], "_ramp_targets", nan_at)
        a, b = _ramped(unloaded, True), _ramped(unloaded, False)
    assert a[2] == b[2] and "diverged" in a[2] and len(a[0]) == len(b[0]) == 2 * RAMP_N + 4
    np.testing.assert_array_equal(a[0], b[0])
