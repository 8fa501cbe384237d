"""The synthetic measured campaign: matrix, driver, sensors, generation."""

from __future__ import annotations

import math
from collections import Counter

import numpy as np
import pytest

from artic.reduced import KIN, InitialState
from artic.validation.logs.importers import import_source
from artic.validation.synthetic.driver import DockingDriver, drive_to_dock
from artic.validation.synthetic.sensors import SensorModel, measure
from artic.validation.synthetic.testmatrix import MATRIX, PAPER, TUNING, TUNING_SETS
from tests.helpers import straight_log


def test_matrix_has_the_seed_counts_and_every_cell():
    paper = MATRIX[:PAPER]
    kinds = Counter(m.direction for m in paper)
    assert kinds == {"forward": 25, "reverse": 33}
    assert len({m.name for m in MATRIX}) == 63
    for load in ("unloaded", "loaded"):
        cs = {(m.amplitude_deg, m.speed_kph, m.side) for m in paper
              if m.kind == "constant-steer" and m.load == load}
        ramps = {(m.amplitude_deg, m.speed_kph, m.side) for m in paper
                 if m.kind == "ramp-steer-reverse" and m.load == load}
        assert len(ramps) == 8
        assert len(cs) == (12 if load == "unloaded" else 11)
        assert {m.kind for m in MATRIX if m.load == load} >= {"docking", "parking"}
    assert {(m.amplitude_deg, m.speed_kph, m.side) for m in MATRIX
            if m.kind == "constant-steer"} == {(a, s, side) for a in (200.0, 360.0, 500.0)
                                              for s in (5.0, 10.0)
                                              for side in ("left", "right")}
    assert Counter(m.kind for m in MATRIX)["docking"] == 9
    assert Counter(m.kind for m in MATRIX)["parking"] == 8
    # Tuning: 4 per load condition, of two kinds; the paper's matrix less them is validated.
    assert len(TUNING) == 8
    for load in ("unloaded", "loaded"):
        assert sum(f"constant-steer-{load}-200deg-5kph" in n for n in TUNING) == 2
        assert sum(f"slalom-{load}-360deg-8kph" in n for n in TUNING) == 2
    # beyond the paper's: the 4 tuning slaloms, then the swept sine, validated, never tuned
    assert [m.name in TUNING for m in MATRIX[PAPER:]] == [True] * 4 + [False]
    assert MATRIX[-1].kind == "swept-sine" and MATRIX[-1].direction == "forward"
    assert sum(m.direction == "forward" and m.name not in TUNING for m in MATRIX) == 22
    for name in ("slaloms", "transient"):  # and no tuning set takes it
        assert MATRIX[-1].name not in TUNING_SETS[name]


@pytest.mark.parametrize("y0,psi0", [(3.0, 0.0), (-4.0, 8.0)])
def test_docking_driver_docks_kin(unloaded, y0, psi0):
    drv = DockingDriver(unloaded)
    t, obs, delta, u, docked = drive_to_dock(
        KIN(unloaded), drv, InitialState(10.0, y0, math.radians(psi0), 0.0))
    dist, e_y, e_psi = drv.errors(obs[-1])
    assert docked
    assert abs(e_y) < 0.5 and abs(e_psi) < math.radians(3.0)
    # The driver's hand turns the steering wheel at a limited rate; delta is its gear's.
    assert np.max(np.abs(np.diff(delta))) <= drv.rate * drv.dt / drv.i_s + 1e-12


def test_sensor_model():
    true = straight_log(n=3000, u=2.0).frame
    true["delta_h"] = np.radians(30.0) * np.sin(true["t"])
    sm = SensorModel()
    a = measure(true, np.random.default_rng(1), sm)
    b = measure(true, np.random.default_rng(1), sm)
    assert a.equals(b)
    # CAN: 10 Hz, held, 50 ms late, 0.1 deg steps.
    dh = a["delta_h"].to_numpy()
    assert np.all(dh[5:10] == dh[5]) and np.allclose(np.round(np.degrees(dh) / 0.1) * 0.1,
                                                     np.degrees(dh))
    late = np.interp(true["t"] - 0.05 - 0.045, true["t"], true["delta_h"])
    assert np.max(np.abs(dh[200:] - late[200:])) < np.radians(2.0)
    # Position noise near its 10 mm standard deviation.
    assert 0.003 < np.std(a["y_1"] - true["y_1"]) < 0.03


@pytest.mark.slow
def test_generated_manoeuvres(tmp_path):
    from artic.validation.synthetic.generate import generate_campaign

    names = ["28-ramp-steer-reverse-unloaded-30deg-6kph-right", "45-docking-unloaded-left"]
    with pytest.raises(ValueError, match="no manoeuvre matches 99-nothing"):
        generate_campaign(tmp_path, only=["99-nothing"])
    paths = generate_campaign(tmp_path, seed=3, only=names)
    assert [p.name for p in paths] == names
    ramp, _ = import_source(paths[0])
    dock, _ = import_source(paths[1])
    # A reverse ramp steer stops at 30-50 deg of articulation, no jackknife.
    assert math.radians(30) < ramp.meta["peak_articulation"] < math.radians(50)
    assert ramp.meta["direction"] == "reverse" and ramp.meta["load"] == "unloaded"
    # Docking ends at the dock within 0.5 m and 3 deg.
    assert dock.meta["docked"]
    assert abs(dock.meta["final_lateral_error"]) < 0.5
    assert abs(dock.meta["final_heading_error"]) < math.radians(3.0)
    # The same seed gives byte-identical files; complete folders are reused.
    first = {p: p.read_bytes() for p in paths[1].iterdir()}
    for p in paths[1].iterdir():
        p.unlink()
    paths[1].rmdir()
    generate_campaign(tmp_path, seed=3, only=names)
    assert {p: p.read_bytes() for p in paths[1].iterdir()} == first
