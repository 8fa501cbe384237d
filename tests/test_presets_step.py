"""Every vehicle preset builds and steps a simulated second without a MuJoCo warning.

As MuJoCo Menagerie checks its models: a preset whose model compiles but whose
first second warns (a contact buffer full, a bad inertia, a non-finite value)
fails here by name, before a campaign meets it. A preset without a tyre file
(the 1:14 scale model, for KIN alone) has no multibody model: building one is
refused, and that refusal is what is checked of it.
"""

from __future__ import annotations

import math
import warnings

import mujoco
import numpy as np
import pytest

import artic
from artic.mjcf.interface import InitialState

MULTIBODY = [n for n in artic.preset_names() if artic.load_vehicle(n).tyre_file]
"""The presets with a tyre file, which the plant builds."""


def test_the_presets_without_a_multibody_model_are_refused():
    others = sorted(set(artic.preset_names()) - set(MULTIBODY))
    assert len(MULTIBODY) >= 3 and others == ["scale-model-1to14"]
    for name in others:
        with pytest.raises(artic.VehicleFileError, match="tyre file"):
            artic.Plant(artic.load_vehicle(name))


@pytest.mark.parametrize("preset", MULTIBODY)
@pytest.mark.parametrize("u1", [1.5, -1.0])
def test_every_preset_steps_a_second_without_a_mujoco_warning(preset, u1):
    vehicle = artic.load_vehicle(preset)
    dt = 0.01
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a warning the plant passes on fails the test too
        with artic.Plant(vehicle) as plant:
            plant.reset(InitialState(0.0, 0.0, 0.0, 0.0, u1=u1))
            for k in range(round(1.0 / dt)):  # steering 0.1 rad each way at 1 Hz
                plant.step(dt, 0.1 * math.sin(2.0 * math.pi * k * dt), u1, 0.0)
            warned = {mujoco.mjtWarning(i).name: int(w.number)
                      for i, w in enumerate(plant.data.warning) if w.number}
            assert not warned, f"{preset}: MuJoCo warned {warned}"
            assert plant.data.time == pytest.approx(1.0, abs=1e-9)
            obs = plant.observe()
    assert np.isfinite(obs).all()
    # It moved as commanded: a metre and a half forward or a metre back, within 10 %.
    assert math.hypot(obs[0], obs[1]) == pytest.approx(abs(u1), rel=0.1), preset
