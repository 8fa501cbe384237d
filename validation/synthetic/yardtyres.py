"""The yard truth's tyres: a published TMeasy truck-tyre parameter set, not a fit to artic.

The independent truth (:mod:`artic.validation.synthetic.yardtruth`) runs TMeasy
tyres (G. Rill, "Road Vehicle Dynamics: Fundamentals and Modeling", CRC Press
2011, chapter 3) whose parameters come from a source that artic's PAC2002 code
did not produce: the normalised truck-tyre pattern of Project Chrono's TMeasy
implementation (``ChTMeasyTire::GuessTruck80Par``,
``src/chrono_vehicle/wheeled_vehicle/tire/ChTMeasyTire.cpp``, BSD-3; its comment:
"Normalized Parameters gained from data set containing original data from
Pacejka book", a truck tyre of 80 % aspect ratio on a road of friction 0.8).
Every force and slope is given there over the nominal load ``p_n`` and at twice
it; the pattern is scaled by each tyre's size and load rating:

- ``p_n = 0.5 F_max (p_use / p_LI)^0.8``: half the rated load ``F_max`` of the
  tyre's load index, lowered with the inflation pressure below its rating
  (Chrono's law);
- vertical stiffness: the rated load deflects the tyre by 16 % of its section
  height (Chrono's law), ``c_z = F_max / (0.16 w r)``;
- ``r0 = w r + d_rim / 2`` from the size (``315/80R22.5``: width ``w``, ratio ``r``,
  rim diameter ``d_rim``).

What the pattern does not give is stated here and in ``docs/design/truth.md``:
the tread's stiffnesses (from assumed relaxation lengths), its dampers, the
bore torque's twist and the rolling resistance (the EU tyre label's class C for
truck tyres, 6 N/kN). Nothing here reads a ``.tir`` file: only the tyre's size
from the vehicle file's tyre-file name and its load index from
:data:`LOAD_RATING`.
"""

from __future__ import annotations

import dataclasses
import math
import re

import numpy as np

from artic.mjcf.errors import UnsupportedVehicleError, UserError

G = 9.81
"""Gravity [m/s^2] (the load ratings are in kg)."""

PATTERN = {
    "dfx0_1": 17.7764, "dfx0_2": 14.5301, "fxm_1": 0.89965, "fxm_2": 0.77751,
    "fxs_1": 0.46183, "fxs_2": 0.42349, "sxm_1": 0.10811, "sxm_2": 0.12389,
    "sxs_1": 0.66667, "sxs_2": 0.66667,
    "dfy0_1": 7.4013, "dfy0_2": 6.8505, "fym_1": 0.75876, "fym_2": 0.72628,
    "fys_1": 0.68276, "fys_2": 0.65319, "sym_1": 0.33167, "sym_2": 0.33216,
    "sys_1": 1.0296, "sys_2": 1.0296,
    "nto0_1": 0.178, "nto0_2": 0.19, "synto0_1": 0.36484, "synto0_2": 0.36538,
    "syntoe_1": 1.0296, "syntoe_2": 1.0296,
}
"""Chrono's ``GuessTruck80Par`` pattern: forces and slopes over the load they are
given at (``_1`` at ``p_n``, ``_2`` at ``2 p_n``), slips and trail ratios as they are."""

PATTERN_FRICTION = 0.8
"""The road friction the pattern stands for (Chrono's ``mu_0``)."""

LOAD_RATING = {
    "315/80R22.5": (4000.0, 3350.0),
    "385/65R22.5": (4500.0, 4500.0),
}
"""Rated load per tyre [kg], single and twin fitment, of the campaign's sizes at their
rated pressure: load index 156/150 (315/80R22.5) and 160 (385/65R22.5), the ETRTO
load-index table's 4000, 3350 and 4500 kg."""

RELAXATION_X = 0.5
"""The longitudinal relaxation length at the nominal load, over ``r0`` [-] (assumed:
a truck tyre's is about half its radius)."""

RELAXATION_Y = 1.0
"""The lateral relaxation length at the nominal load, over ``r0`` [-] (assumed: about
one radius for a radial truck tyre)."""

DAMPING_TIME = 0.01
"""Each tread deflection's damper over its spring [s]; with the spring it keeps a
wheel's spin on its tread a damped oscillation (``docs/design/truth.md``)."""

VERTICAL_DAMPING_RATIO = 0.5
"""The tyre's vertical damping ratio against a 60 kg tyre-and-rim mass (Chrono's
pattern uses 0.5 against the tyre's mass) [-]."""

BORE_TWIST = math.radians(5.0)
"""Twist at which a standing tyre's bore torque slides at the nominal load [rad]."""

ROLLING_RESISTANCE = 0.006
"""Rolling-resistance coefficient [-]: class C of the EU tyre label for truck tyres
(5.1-6.0 N/kN)."""

V_N = 0.01
"""TMeasy's fictitious speed [m/s] (Rill's value)."""

_SIZE = re.compile(r"(\d{3})[-/](\d{2})R(\d{2}(?:\.\d)?)")

FIELDS = ("r0", "cz", "dz", "fzn", "width", "fzmax", "dfx0_1", "dfx0_2", "fxm_1", "fxm_2",
          "sxm_1", "sxm_2", "fxs_1", "fxs_2", "sxs_1", "sxs_2", "dfy0_1", "dfy0_2", "fym_1",
          "fym_2", "sym_1", "sym_2", "fys_1", "fys_2", "sys_1", "sys_2", "nto0_1", "nto0_2",
          "synto0_1", "synto0_2", "syntoe_1", "syntoe_2", "cx", "dx", "cy", "dy", "cpsi",
          "dpsi", "fr", "vn")
"""The coefficients in the compiled truth's order (``TYRE_PARAMS`` of ``_truth_c.c``)."""


@dataclasses.dataclass(frozen=True)
class YardTyre:
    """One tyre's TMeasy coefficients (SI, the compiled truth's names; see :data:`FIELDS`)."""

    values: dict

    def vector(self) -> np.ndarray:
        """The coefficients in :data:`FIELDS` order."""
        return np.array([self.values[k] for k in FIELDS], dtype=float)

    def __getattr__(self, name: str) -> float:
        try:
            return self.values[name]
        except KeyError as exc:
            raise AttributeError(name) from exc


def size_of(tyre_file: str) -> str:
    """The tyre size ``WWW/RRRDD.D`` in a tyre file's name (``artic-truck-315-80R22.5.tir``)."""
    m = _SIZE.search(str(tyre_file))
    if m is None:
        raise UserError(f"{tyre_file}: no tyre size such as 315-80R22.5 in the file's name; "
                         "the yard truth reads its tyres' size from it")
    return f"{m.group(1)}/{m.group(2)}R{m.group(3)}"


def yard_tyre(size: str, twin: bool = False, pressure: float = 1.0, friction: float = 1.0,
              cornering: float = 1.0) -> YardTyre:
    """The TMeasy tyre of a truck tyre size from Chrono's pattern (module docstring).

    Parameters
    ----------
    size : str
        ``"315/80R22.5"`` and the like; its load rating from :data:`LOAD_RATING`.
    twin : bool
        Twin fitment (the lower load rating).
    pressure : float
        Inflation pressure over the rated one [-]: the nominal load scales with it
        to the power 0.8.
    friction : float
        The yard's friction over the pattern's 0.8 [-]: scales the peak and sliding forces.
    cornering : float
        Scale of the lateral slope at zero slip [-] (tread wear, temperature).
    """
    if size not in LOAD_RATING:
        raise UnsupportedVehicleError(f"tyre size {size}: the yard truth knows "
                                      f"{', '.join(LOAD_RATING)}")
    m = re.fullmatch(r"(\d{3})/(\d{2})R(\d{2}(?:\.\d)?)", size)
    w, ratio, rim = float(m.group(1)) / 1000.0, float(m.group(2)) / 100.0, float(m.group(3))
    fmax = LOAD_RATING[size][1 if twin else 0] * G
    pn = 0.5 * fmax * pressure ** 0.8
    secth = w * ratio
    r0 = secth + 0.5 * rim * 0.0254
    cz = fmax / (0.16 * secth)
    v: dict[str, float] = {"r0": r0, "cz": cz, "dz": 2.0 * VERTICAL_DAMPING_RATIO * math.sqrt(
        cz * 60.0), "fzn": pn, "width": w, "fzmax": 3.0 * pn}
    for k, x in PATTERN.items():
        load = pn if k.endswith("_1") else 2.0 * pn
        if k.startswith(("df", "fxm", "fxs", "fym", "fys")):
            x = x * load
            if k.startswith(("fxm", "fxs", "fym", "fys")):
                x *= friction
            if k.startswith("dfy0"):
                x *= cornering
        v[k] = x
    cx = v["dfx0_1"] / (RELAXATION_X * r0)
    cy = v["dfy0_1"] / (RELAXATION_Y * r0)
    patch = 2.0 * math.sqrt(r0 * pn / cz)
    rb = (0.5 * patch + 0.5 * w) / 3.0
    cpsi = rb * v["fym_1"] / BORE_TWIST
    v.update(cx=cx, dx=DAMPING_TIME * cx, cy=cy, dy=DAMPING_TIME * cy, cpsi=cpsi,
             dpsi=DAMPING_TIME * cpsi, fr=ROLLING_RESISTANCE, vn=V_N)
    return YardTyre(v)
