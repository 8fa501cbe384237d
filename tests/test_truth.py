"""The synthetic campaign's truth: its draws, its files, and that it differs in structure."""

from __future__ import annotations

import dataclasses
import math
import warnings

import numpy as np
import pytest

from artic.mjcf import load_vehicle
from artic.validation.synthetic.actuation import PedalDriver, SteeringColumn
from artic.validation.synthetic.truth import (
    TRAILER_TYRE,
    body_values,
    slope,
    truth_configuration,
    truth_vehicle,
    write_truth_files,
)


def test_the_truth_is_drawn_from_the_seed_and_legacy_is_a_part_of_it():
    a, b = truth_configuration(0), truth_configuration(0)
    assert a == b and truth_configuration(1) != a
    assert a["kind"] == "independent"  # the default
    legacy = truth_configuration(0, "legacy")
    # Every kind shares the first draws: the steering and the tyres' scaling.
    assert {k: a[k] for k in legacy if k != "kind"} == {k: v for k, v in legacy.items()
                                                        if k != "kind"}
    # The independent truth draws what the structural one does, and then its
    # own body and tyres (tests/test_yard_truth.py).
    structural = truth_configuration(0, "structural")
    assert {k: v for k, v in a.items() if k not in ("kind", "body", "tyres")} == {
        k: v for k, v in structural.items() if k != "kind"}
    assert set(a) - set(structural) == {"body", "tyres"}
    assert 1000.0 <= a["fifth_wheel_friction"] <= 4000.0
    assert math.radians(1.0) <= a["backlash"] <= math.radians(3.0)
    # Without drift, only the drift changes.
    still = truth_configuration(0, drift=False)
    assert still["drift_rate"] == 0.0 != a["drift_rate"]
    assert {k: v for k, v in still.items() if k != "drift_rate"} == {
        k: v for k, v in a.items() if k != "drift_rate"}
    with pytest.raises(ValueError, match="expected one of independent, structural, legacy"):
        truth_configuration(0, "made-up")


def test_the_yard_slope_changes_per_manoeuvre_within_drainage_slopes():
    truth = truth_configuration(0)
    slopes = [slope(0, i, truth) for i in range(58)]
    grades = np.array([s["grade"] for s in slopes])
    cross = np.array([s["crossfall"] for s in slopes])
    assert np.all(np.abs(grades) <= math.atan(0.015)) and np.all(np.abs(cross) <= math.atan(0.02))
    assert np.std(grades) > 0.004  # it does vary along the yard
    assert slope(0, 3, truth_configuration(0, "legacy")) == {"grade": 0.0, "crossfall": 0.0}


def test_truth_files_carry_the_structure(tmp_path):
    paths = write_truth_files(tmp_path, 0)
    truth = truth_configuration(0)
    v = load_vehicle(paths["loaded"])
    preset = load_vehicle("gosar2022-loaded")
    assert all(a.tyre_file.endswith(TRAILER_TYRE) for a in v.trailer_axles)
    assert all(a.tyre_file == "" for a in v.tractor_axles)
    assert v.plant.fifth_wheel_friction == pytest.approx(truth["fifth_wheel_friction"])
    assert v.plant.tyre_moments
    # The independent truth's payload sits in its drawn a2, h2 and J2 (off the
    # presets by the stated offsets); only its lateral offset stays a payload's.
    assert v.plant.payload_offset[0] == 0.0
    assert v.plant.payload_offset[1] == pytest.approx(truth["payload"]["loaded"]["offset"][1])
    drawn = body_values(preset, "loaded", truth)
    for key in ("m1", "J1", "a1", "b1", "h1", "L1c", "m2", "J2", "a2", "h2"):
        assert getattr(v, key) == pytest.approx(drawn[key]), key
    assert v.a2 != preset.a2 and v.m1 != preset.m1
    assert v.sensor1_yaw == pytest.approx(truth["sensor1_yaw"])
    np.testing.assert_allclose(np.subtract(v.sensor2, preset.sensor2), truth["sensor2_offset"])
    # The file is the truth: it equals the vehicle the generator drives.
    made = truth_vehicle("loaded", truth, 0)
    assert made.plant == v.plant and made.steering_for("mbd") == v.steering_for("mbd")


def test_the_steering_column_has_play_and_drift():
    col = SteeringColumn(backlash=math.radians(2.0), drift_rate=math.radians(1.0))
    col.reset(0.0)
    # Inside the play the box does not move.
    assert col(math.radians(0.9), 0.0) == pytest.approx(0.0)
    # Beyond it the box follows, lagging by half the play.
    assert col(math.radians(5.0), 0.0) == pytest.approx(math.radians(4.0))
    # Turning back, the play is taken up the other way first.
    assert col(math.radians(4.0), 0.0) == pytest.approx(math.radians(4.0))
    assert col(math.radians(2.0), 0.0) == pytest.approx(math.radians(3.0))
    # The zero drifts: after 2 s the box sees 2 deg less.
    assert col(math.radians(2.0), 2.0) == pytest.approx(math.radians(1.0))


def test_the_pedal_driver_uses_one_pedal_at_a_time_and_reacts_late():
    d = PedalDriver(mass=20_000.0, delay=0.4, gain=0.6)
    d.reset(1.0)
    # Too slow: throttle, rising at the pedal rate, no brake.
    t, b = d.command(2.0, 0.0, 1.0)
    assert 0.0 < t <= d.pedal_rate * d.dt and b == 0.0
    # Suddenly far too fast: he has not seen it yet (0.4 s), so he keeps on.
    for _ in range(20):
        t, b = d.command(2.0, 0.0, 5.0)
    assert t > 0.0 and b == 0.0
    for _ in range(200):
        t, b = d.command(2.0, 0.0, 5.0)
    assert t == 0.0 and b > 0.0


@pytest.mark.slow
def test_the_structural_truth_differs_in_structure_the_legacy_one_does_not():
    # The plant in its preset configuration, given the truth's steering map (what
    # tuning would find), against logs from each truth, beside the floor: the
    # truth's own plant. From the legacy truth only LKY and LMUY differ, so the
    # preset plant sits near the floor; from the structural truth it is well above.
    from artic.plant import Plant, PlantWarning
    from artic.validation.criteria.metrics import run_metrics
    from artic.validation.harness.loop import run_closed_loop
    from artic.validation.synthetic.generate import simulate_manoeuvre
    from artic.validation.synthetic.testmatrix import MATRIX

    names = ("02-constant-steer", "25-ramp-steer-reverse", "43-docking")
    gap = {}
    for kind in ("legacy", "structural"):
        truth = truth_configuration(0, kind)
        excess = []
        for name in names:
            m = next(x for x in MATRIX if x.name.startswith(name))
            log = simulate_manoeuvre(m, 0, truth_kind=kind)
            vt = truth_vehicle(m.load, truth, 0, log.meta["slope"])
            preset = load_vehicle(f"gosar2022-{m.load}")
            preset = dataclasses.replace(preset, steering_overrides={
                **preset.steering_overrides, "mbd": dataclasses.asdict(vt.steering_for("mbd"))})
            eps = {}
            for label, v in (("floor", vt), ("preset", preset)):
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore", PlantWarning)
                    with Plant(v) as p:
                        run = run_closed_loop(p, log, v)
                eps[label] = run_metrics(log.frame, run.frame)["eps_n"]
            excess.append(eps["preset"] - eps["floor"])
        gap[kind] = float(np.mean(excess))
    # eps_n in percentage points above the floor.
    assert gap["legacy"] < 1.0, gap
    assert gap["structural"] > 3.0 * max(gap["legacy"], 0.3), gap
