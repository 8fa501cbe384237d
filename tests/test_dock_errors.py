"""Dock errors: the semitrailer's rear and heading at the end, in the measured one's frame."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from artic.mjcf.interface import InitialState
from artic.mjcf.outline import outline
from artic.reduced import KIN, Driven
from artic.validation.criteria.dock import dock_errors, end_pose_error
from artic.validation.criteria.points import rear_x, trailer_point
from artic.validation.synthetic.driver import DockingDriver


def pose_row(vehicle, rear: tuple[float, float], psi_2: float) -> pd.Series:
    """The semitrailer sensor's signals of a semitrailer whose rear centre is at ``rear``.

    Built from the kingpin (independent of the code under test): the rear
    lies ``rear_behind_kingpin`` behind it and the sensor at ``sensor2``.
    """
    c, s = math.cos(psi_2), math.sin(psi_2)
    back = outline(vehicle).rear_behind_kingpin
    kx, ky = rear[0] + back * c, rear[1] + back * s
    sx, sy = vehicle.sensor2[:2]
    return pd.Series({"x_2": kx + c * sx - s * sy, "y_2": ky + s * sx + c * sy, "psi_2": psi_2})


@pytest.mark.parametrize("psi_m", [0.0, 0.4, -2.5])
def test_a_known_shift_and_rotation_comes_back(unloaded, psi_m):
    measured_rear = (-40.0, 1.5)
    d_lon, d_lat, d_psi = 0.30, -0.12, math.radians(3.0)
    c, s = math.cos(psi_m), math.sin(psi_m)
    model_rear = (measured_rear[0] + c * d_lon - s * d_lat,
                  measured_rear[1] + s * d_lon + c * d_lat)
    got = end_pose_error(pose_row(unloaded, measured_rear, psi_m),
                         pose_row(unloaded, model_rear, psi_m + d_psi), unloaded)
    assert got["dock_lon"] == pytest.approx(d_lon, abs=1e-12)
    assert got["dock_lat"] == pytest.approx(d_lat, abs=1e-12)
    assert got["dock_psi"] == pytest.approx(d_psi, abs=1e-12)


def test_heading_error_is_wrapped(unloaded):
    a = pose_row(unloaded, (0.0, 0.0), math.pi - 0.01)
    b = pose_row(unloaded, (0.0, 0.0), -math.pi + 0.02)
    got = end_pose_error(a, b, unloaded)
    assert got["dock_psi"] == pytest.approx(0.03, abs=1e-12)
    assert got["dock_lon"] == pytest.approx(0.0, abs=1e-12)


def test_rear_point_is_the_docking_drivers(unloaded):
    # The driver finds the rear from the tractor's sensor and the articulation;
    # the criterion from the semitrailer's own sensor. On a model's (consistent)
    # observation they are one point.
    model = Driven(KIN(unloaded, wheelbase="paper"))
    model.reset(InitialState(3.0, -2.0, 0.7, 0.35, u1=-1.0))
    obs = model.observe(0.0)
    want = DockingDriver(unloaded).rear_point(obs)
    got = trailer_point(unloaded, rear_x(unloaded), obs[6], obs[7], obs[8])
    np.testing.assert_allclose([float(got[0]), float(got[1])], want, atol=1e-9)
    assert rear_x(unloaded) < -unloaded.L2  # the rear edge, behind the axles


def frames(vehicle, n: int = 50) -> tuple[pd.DataFrame, pd.DataFrame]:
    meas = pd.DataFrame({"x_2": np.linspace(0, -5, n), "y_2": 0.0, "psi_2": 0.0})
    model = meas.copy()
    model.loc[n - 1, "x_2"] += 0.25  # stopped 25 cm short of where the log ended
    return meas, model


def test_only_docking_and_parking_runs_that_reach_the_end(unloaded):
    meas, model = frames(unloaded)
    got = dock_errors(meas, model, unloaded, "docking")
    assert got["dock_lon"] == pytest.approx(0.25, abs=1e-12)  # short of the dock: +
    assert got["dock_lat"] == pytest.approx(0.0, abs=1e-12)
    assert np.isfinite(dock_errors(meas, model, unloaded, "parking")["dock_lat"])
    for kind in ("ramp-steer-reverse", "constant-steer", ""):
        assert all(math.isnan(v) for v in dock_errors(meas, model, unloaded, kind).values())
    stopped = dock_errors(meas, model.iloc[:30], unloaded, "docking")
    assert all(math.isnan(v) for v in stopped.values())
