"""``artic mjcf`` writes a model that plain MuJoCo simulates once plant.load attaches the tyres."""

from __future__ import annotations

import mujoco
import numpy as np

import plant
from mjcf import load_vehicle, naming
from plant import callback
from validation.cli import main


def test_the_exported_truck_rolls_straight_on_its_tyres(tmp_path):
    path = tmp_path / "truck.xml"
    assert main(["mjcf", "--vehicle", "gosar2022-unloaded", "-o", str(path)]) == 0
    # Plain MuJoCo loads the file as it is.
    mujoco.MjModel.from_xml_path(str(path))
    m, d = plant.load(path)
    try:
        z0 = None
        d.qvel[0] = 2.0  # rolling forward at 2 m/s, wheels spinning with it
        v = load_vehicle("gosar2022-unloaded")
        for a in v.axles:
            for s in naming.SIDES:
                d.qvel[m.jnt_dofadr[m.joint(naming.spin(a.name, s)).id]] = 2.0 / 0.538
        mujoco.mj_forward(m, d)
        z0 = d.qpos[2]
        zs = []
        for _ in range(2000):  # 10 s at 5 ms
            mujoco.mj_step(m, d)
            zs.append(d.qpos[2])
        # On its tyres: the chassis height stays within 5 cm of where it started
        # (without the tyre forces it falls 4.9 m in a second), and it travels
        # straight, coasting to a stop against rolling resistance.
        assert np.max(np.abs(np.array(zs) - z0)) < 0.05
        assert d.qpos[0] > 5.0 and abs(d.qpos[1]) < 0.05
        assert np.all(np.isfinite(d.qpos))
    finally:
        callback.uninstall(m)


def test_a_file_without_tyre_data_is_refused(tmp_path):
    import pytest

    from plant.ctyre import TyreBlockError

    path = tmp_path / "bare.xml"
    assert main(["mjcf", "--vehicle", "gosar2022-unloaded", "--no-scene", "-o", str(path)]) == 0
    with pytest.raises(TyreBlockError, match="not written by 'artic mjcf'"):
        plant.load(path)
