"""The plant as a standalone MJCF file, and loading one back with the tyres attached.

``artic mjcf`` writes :func:`to_xml`: the combination and the yard, with
everything the tyre callback needs inside the file as MJCF ``custom`` data,
the ``artic.tyre`` numeric (coefficients, wheel ids, tread-state actuators).
Plain MuJoCo loads it; :func:`load` attaches artic's compiled tyre callback,
and then MuJoCo alone simulates the truck::

    m, d = plant.load("truck.xml")
    mujoco.mj_step(m, d, nstep=1000)  # 10 s at the file's 10 ms step

A written block is unsealed (the callback follows only blocks sealed by its
own process); :func:`load` checks it against the model it came with and seals
it. The speed follower and the drive and brake actuators are written inert
(zero gain, zero control): the exported truck rolls where it is pushed, and
its steering holds straight ahead unless ``d.ctrl`` says otherwise.
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np

from artic.mjcf import naming as nm
from artic.mjcf.compiling import compile_spec, load_xml
from artic.mjcf.vehicle import Vehicle
from artic.plant import callback, ctyre
from artic.plant.plant import Plant


def to_xml(vehicle: Vehicle) -> str:
    """The plant of ``vehicle`` as MJCF, tyre data included (needs the compiled callback)."""
    with Plant(vehicle, backend="compiled", speed="drive") as p:
        spec = p.spec
        blk = np.array(p.model.numeric_data, dtype=float)
    blk[1:3] = 0.0  # unsealed: load() seals it for its own process
    blk[ctyre.HEADER_FIELDS.index("checksum")] = 0.0
    spec.numerics[0].data = blk.tolist()
    follower = spec.actuator(nm.SPEED_SERVO)
    follower.gainprm = [0.0] * len(follower.gainprm)
    follower.biasprm = [0.0] * len(follower.biasprm)
    compile_spec(spec)
    return spec.to_xml()


def load(path: str | Path) -> tuple[mujoco.MjModel, mujoco.MjData]:
    """Load an MJCF file that ``artic mjcf`` wrote, with the tyre callback attached.

    Raises
    ------
    artic.plant.ctyre.TyreBlockError
        When the file's tyre data does not fit its model.
    RuntimeError
        When the compiled callback is unavailable
        (see :func:`artic.plant.ctyre.unavailable_reason`).
    """
    if ctyre.library() is None:
        raise RuntimeError(ctyre.unavailable_reason())
    m = load_xml(str(path))
    if m.nnumeric < 1 or m.numeric(0).name != ctyre.BLOCK:
        raise ctyre.TyreBlockError(f"{path}: no '{ctyre.BLOCK}' numeric: not written by "
                                   "'artic mjcf'")
    blk = m.numeric_data[m.numeric_adr[0]:m.numeric_adr[0] + m.numeric_size[0]]
    nh = len(ctyre.HEADER_FIELDS)
    if blk.size < nh:
        raise ctyre.TyreBlockError(f"{path}: '{ctyre.BLOCK}' is shorter than its header")
    blk[1:3] = ctyre.KEY
    blk[nh - 1] = ctyre.checksum(blk[nh:])
    d = mujoco.MjData(m)
    ctyre.check_block(m, d)
    callback.install(m, callback.NATIVE)
    mujoco.mj_forward(m, d)
    return m, d
