"""The truth's own docking driver: it shares nothing with what its logs validate.

The synthetic truth's docking and parking driver
(:mod:`artic.validation.synthetic.driver`) steers with a law of its own, not
the harness's (``artic.validation.harness``) nor anything of the reduced
models (``artic.reduced``); making logs loads neither them nor the plant. Read
here: the import graph, a call trace of one docking log, and the driver's own
behaviour (its preview geometry, its delay, its hand's rate and the lock).
"""

from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pytest

from artic.mjcf.interface import OBS_INDEX, InitialState
from artic.reduced import KIN
from artic.validation.synthetic.driver import DockingDriver, drive_dock
from artic.validation.synthetic.testmatrix import MATRIX
from tests.helpers import needs_compiled

YARD = "the yard truth's compiled loop (artic_yard_advance)"

VALIDATED = ("artic.plant", "artic.validation.harness", "artic.reduced")
"""What the truth's logs validate: the plant, the harness and the reduced models."""

DOCKING = [m for m in MATRIX if m.kind in ("docking", "parking")]


def _fresh(code: str) -> str:
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    return out.stdout.strip()


def test_importing_the_generator_loads_neither_the_plant_nor_the_harness():
    loaded = _fresh(
        "import sys\n"
        "import artic.validation.synthetic.generate\n"
        f"print(','.join(m for m in sys.modules if m.startswith({VALIDATED!r})))\n")
    assert loaded == ""


def test_the_probe_sees_a_loaded_module():
    # The same probe, after an import of the harness, names it: the check above can fail.
    loaded = _fresh(
        "import sys\n"
        "import artic.validation.synthetic.generate\n"
        "import artic.validation.harness.feedback\n"
        f"print(','.join(m for m in sys.modules if m.startswith({VALIDATED!r})))\n")
    assert "artic.validation.harness.feedback" in loaded.split(",")


@needs_compiled(YARD)
def test_generating_a_docking_log_loads_neither():
    # Behaviour as well as imports: a process that drives, measures and records
    # a docking log has loaded none of them.
    loaded = _fresh(
        "import sys\n"
        "from artic.validation.synthetic.generate import simulate_manoeuvre\n"
        "from artic.validation.synthetic.testmatrix import MATRIX\n"
        "m = next(m for m in MATRIX if m.kind == 'docking')\n"
        "run = simulate_manoeuvre(m, 0)\n"
        "assert run.meta['docked']\n"
        f"print(','.join(m for m in sys.modules if m.startswith({VALIDATED!r})))\n")
    assert loaded == ""


class _Calls:
    """A profiler (``sys.setprofile``) that keeps the modules of every function called."""

    def __init__(self) -> None:
        self.modules: dict[str, int] = {}

    def __call__(self, frame, event, arg) -> None:
        if event == "call":
            name = frame.f_globals.get("__name__", "")
        elif event == "c_call":  # compiled callables (numba's dispatchers, builtins)
            name = getattr(arg, "__module__", None) or ""
        else:
            return
        self.modules[name] = self.modules.get(name, 0) + 1

    def of(self, prefixes: tuple[str, ...]) -> dict[str, int]:
        return {m: n for m, n in self.modules.items() if m.startswith(prefixes)}

    def __enter__(self) -> _Calls:
        sys.setprofile(self)
        return self

    def __exit__(self, *exc) -> None:
        sys.setprofile(None)


def test_the_call_trace_sees_a_harness_call():
    # The tracer below, shown to see what it must not find.
    from artic.validation.harness.feedback import feedback_law

    with _Calls() as calls:
        feedback_law(0.0, 0.1, 0.0, 1.0, 3.0, 0.6)
    assert calls.of(VALIDATED) == {"artic.validation.harness.feedback": 1}


@needs_compiled(YARD)
def test_the_truths_driver_calls_nothing_of_what_it_validates():
    # Loaded, so that they could be called; then one docking log generated
    # under the profiler: not one function of theirs runs.
    import artic.reduced.control  # noqa: F401
    import artic.validation.harness.loop  # noqa: F401
    from artic.validation.synthetic.generate import simulate_manoeuvre

    m = DOCKING[0]
    with _Calls() as calls:
        run = simulate_manoeuvre(m, 0)
    assert run.meta["docked"]
    assert calls.of(VALIDATED) == {}
    # ... while the driver itself was called at every sample.
    assert calls.modules["artic.validation.synthetic.driver"] >= len(run.frame)


def test_the_preview_asks_for_the_pure_pursuit_arc(unloaded):
    # A point e off the line, heading along it, reversing: the aim point lies on
    # the line at distance D, and the arc through it has curvature 2 e / D^2,
    # turning (in the direction of travel, -x) towards the line.
    d = DockingDriver(unloaded)
    for e in (-2.0, 0.5, 3.0):
        kappa = d.aim_curvature(5.0, d.y_dock + e, 0.0, -1.0, d.preview)
        assert kappa == pytest.approx(2.0 * e / d.preview ** 2, rel=1e-12)
        # Forward, the same point turns the other way (the line is on its other side).
        assert d.aim_curvature(5.0, d.y_dock + e, 0.0, 1.0, 8.0) == pytest.approx(
            -2.0 * e / 8.0 ** 2, rel=1e-12)
    # On the line and along it: no arc.
    assert d.aim_curvature(5.0, d.y_dock, 0.0, -1.0, d.preview) == pytest.approx(0.0, abs=1e-15)


def test_the_reference_articulation_steers_the_trailer_at_its_kingpin(unloaded):
    # Straight combination, its trailer axle e off the line: gamma_ref = -atan(L2 kappa).
    d = DockingDriver(unloaded)
    obs = np.zeros(13)
    obs[OBS_INDEX["x_1"]] = 10.0
    obs[OBS_INDEX["y_1"]] = 1.0 + unloaded.sensor1[1]  # the kingpin, and so the axle, at y = 1
    kappa = 2.0 * 1.0 / d.preview ** 2
    assert d.reference_articulation(obs) == pytest.approx(-math.atan(unloaded.L2 * kappa),
                                                          rel=1e-12)


def _obs_with_articulation(vehicle, gamma: float) -> np.ndarray:
    """Both units on the dock's line, far from it, and an articulation ``gamma`` seen."""
    obs = np.zeros(13)
    obs[OBS_INDEX["x_1"]] = 200.0
    obs[OBS_INDEX["y_1"]] = vehicle.sensor1[1]  # the kingpin on the line
    obs[OBS_INDEX["gamma"]] = gamma
    return obs


def test_the_reaction_delay_delays_the_wheel_by_exactly_its_value(unloaded):
    d = DockingDriver(unloaded, delay=0.25, dt=0.01)
    still = _obs_with_articulation(unloaded, 0.0)
    for _ in range(50):
        wheel, _, _ = d.command(still)
    assert wheel == d.straight  # nothing to correct
    switch = 50
    moved = None
    for k in range(switch, switch + 100):
        wheel, _, _ = d.command(_obs_with_articulation(unloaded, math.radians(2.0)))
        if moved is None and wheel != d.straight:
            moved = k
    # The first decision after the switch reaches the wheel 25 steps (0.25 s) later.
    assert (moved - switch) * d.dt == pytest.approx(d.delay, abs=1e-12)


def test_the_wheel_turns_at_the_hands_rate_and_stops_at_lock(unloaded):
    d = DockingDriver(unloaded, delay=0.0)
    far_off = _obs_with_articulation(unloaded, math.radians(60.0))
    wheels = [d.command(far_off)[0] for _ in range(600)]
    steps = np.diff([d.straight, *wheels])
    assert np.max(np.abs(steps)) <= d.rate * d.dt + 1e-12
    assert np.isclose(steps[0], d.rate * d.dt, rtol=1e-12)  # the rate is what limits here
    # 60 deg of articulation error asks for far more than the lock: the wheel stops there.
    lock = unloaded.steering_for("mbd").i_s * unloaded.steering_for("mbd").delta_max
    assert wheels[-1] == pytest.approx(d.straight + lock, rel=1e-12)
    assert max(wheels) <= d.straight + lock + 1e-12


def test_off_line_near_the_dock_he_pulls_forward_onto_the_line(unloaded):
    # 7 m from the face and 1 m off the line (the tolerance is 0.3 m): a
    # shuffle. Forward, his drive axle follows the line by pure pursuit: the
    # road wheels at atan(L1 kappa), kappa = -2 e / D_f^2 (the line on his right).
    d = DockingDriver(unloaded, delay=0.0, rate=1e9, max_shuffles=1)
    obs = np.zeros(13)
    obs[OBS_INDEX["y_1"]] = 1.0 + unloaded.sensor1[1]  # drive axle, kingpin and rear at y = 1
    obs[OBS_INDEX["x_1"]] = 0.0
    obs[OBS_INDEX["x_1"]] = 7.0 - d.errors(obs)[0]
    assert d.errors(obs)[:2] == pytest.approx((7.0, 1.0), abs=1e-12)
    d.command(obs)
    assert (d.mode, d.shuffles) == ("forward", 1)
    wheel, u, done = d.command(obs)
    assert u == d.speed and not done
    kappa = -2.0 * 1.0 / d.preview_forward ** 2
    assert wheel == pytest.approx(d.straight + d.i_s * math.atan(unloaded.L1 * kappa), rel=1e-12)


@pytest.mark.parametrize("y0,psi0", [(2.0, 0.0), (-3.0, 0.0), (4.0, 8.0)])
def test_a_straight_reverse_with_an_offset_converges(unloaded, y0, psi0):
    # On KIN (the vehicle here, not the driver's model): from 2-4 m off the
    # dock's line, the driver brings the trailer onto it within his own
    # tolerance (0.3 m, 2.5 deg) 8 m before the face, and docks without a
    # shuffle.
    d = DockingDriver(unloaded, max_shuffles=0)
    run = drive_dock(KIN(unloaded), d, InitialState(10.0, y0, math.radians(psi0), 0.0))
    assert run.docked
    errs = np.array([d.errors(o) for o in run.obs])
    at8 = errs[np.argmax(errs[:, 0] < 8.0)]
    assert abs(at8[1]) < 0.3 and abs(at8[2]) < math.radians(2.5)
    assert abs(errs[-1, 1]) < 0.1 * abs(y0)
    assert np.max(np.abs(np.diff(run.delta_h))) <= d.rate * d.dt + 1e-12
    assert np.max(np.abs(run.obs[:, OBS_INDEX["gamma"]])) < unloaded.gamma_max


@pytest.mark.slow
@needs_compiled(YARD)
def test_every_docking_and_parking_manoeuvre_of_a_seed_completes():
    from artic.validation.synthetic.generate import simulate_manoeuvre
    from artic.validation.synthetic.truth import slope, truth_configuration, truth_vehicle

    seed = 0
    truth = truth_configuration(seed)
    for m in DOCKING:
        meta = simulate_manoeuvre(m, seed).meta
        vt = truth_vehicle(m.load, truth, seed, slope(seed, m.index, truth))
        assert meta["docked"], m.name
        # At the face within the driver's own tolerance, and never jackknifed.
        assert abs(meta["final_lateral_error"]) < 0.3, m.name
        assert abs(meta["final_heading_error"]) < math.radians(2.5), m.name
        assert meta["peak_articulation"] < vt.gamma_max, m.name
