"""``artic mjcf`` writes a model that plain MuJoCo simulates once plant.load attaches the tyres."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

import artic.plant as plant
from artic.mjcf import load_vehicle, naming
from artic.plant import callback
from artic.validation.cli.commands import main
from tests.helpers import needs_compiled

# The file carries the compiled callback's block: plain MuJoCo needs the callback.
pytestmark = needs_compiled("the standalone model's compiled tyre callback")


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
    from artic.plant.ctyre import TyreBlockError

    path = tmp_path / "bare.xml"
    assert main(["mjcf", "--vehicle", "gosar2022-unloaded", "--no-scene", "-o", str(path)]) == 0
    with pytest.raises(TyreBlockError, match="not written by 'artic mjcf'"):
        plant.load(path)


def _written_block(path):
    import re

    text = path.read_text()
    m = re.search(r'(<numeric name="artic\.tyre"[^>]*data=")([^"]*)(")', text)
    return text, m, np.array(m.group(2).split(), dtype=float)


BAD_DATA = {  # what a hand-edited file may carry: (coefficient or wheel field, value, words)
    "zero relaxation length": ("PTY1", 0.0, "PTY1 = 0.0 must be positive"),
    "NaN trail": ("QDZ1", float("nan"), "tyre set 0: tyre coefficient QDZ1 = nan is not finite"),
    "infinite tyre count": ("n_tyres", float("inf"), "wheel 0: n_tyres = inf is not finite"),
    "no tyre": ("n_tyres", 0.0, "wheel 0: n_tyres = 0"),
    "hub site out of range": ("hub_site", 1e4, "hub_site = 10000 is outside"),
}


@pytest.mark.filterwarnings("ignore:MuJoCo. XML contains a 'NaN'")
def test_a_file_with_bad_tyre_data_is_refused_naming_it(tmp_path):
    # plant.load seals whatever block a file carries, so it must check every
    # value itself: before, a zero relaxation length or an infinite tyre count
    # was sealed, attached and diverged (NaN state) instead of being refused.
    from artic.plant import ctyre

    good = tmp_path / "truck.xml"
    assert main(["mjcf", "--vehicle", "gosar2022-unloaded", "-o", str(good)]) == 0
    text, match, blk = _written_block(good)
    names, nh = ctyre.param_names(), len(ctyre.HEADER_FIELDS)
    ns = int(blk[ctyre.HEADER_FIELDS.index("n_sets")])
    for case, (key, value, words) in BAD_DATA.items():
        bad_blk = blk.copy()
        if key in ctyre.WHEEL_FIELDS:  # the first wheel end's
            bad_blk[nh + ns * len(names) + ctyre.WHEEL_FIELDS.index(key)] = value
        else:  # the first set's
            bad_blk[nh + names.index(key)] = value
        data = " ".join(repr(float(x)) for x in bad_blk)
        bad = tmp_path / "bad.xml"
        bad.write_text(text[:match.start(2)] + data + text[match.end(2):])
        with pytest.raises(ctyre.TyreBlockError, match=words):
            plant.load(bad)
        assert callback.active() == 0, case  # nothing attached
