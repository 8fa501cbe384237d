"""The oracle vehicles: each model with the truth's own parameters, to separate form from fit.

A model's error above the floor has two parts: its **form** (what its
equations cannot represent) and its **parameters** (how far its tuned values
are from the truck's). The campaign runs every model a second time, untuned,
on a vehicle that carries the truth's own parameters, as rows
``kin-oracle``, ``stm-oracle`` and ``mbd-oracle``: the oracle row against the
floor is the form's share, the tuned row against the oracle row the
parameters'.

The oracle vehicle of a load condition is the truth's vehicle file
(:func:`artic.validation.synthetic.truth.truth_data`: its geometry, masses,
inertias and centres of gravity as drawn off the presets, its sensor
positions, and its steering gear ``[steering.mbd]``, the map the floor's
harness uses), without the yard's slope, with:

- the truth's steering ratio and steering-wheel offset for KIN and the STM too
  (``[steering.kin]``, ``[steering.stm]``; their asymmetry ``q`` stays the
  preset's, the Ackermann trapezoid's map, since their road wheel is one);
- the STM's normalised cornering stiffness ``f`` equivalent to the truth's
  TMeasy tyres (:func:`equivalent_f`): each tyre's initial slope ``dF0`` of its
  lateral curve at its static load, interpolated as TMeasy does between the
  nominal load and twice it (:func:`tmeasy_cornering`), summed over the tyres
  of the combination and divided by the combination's static load;
- the plant's PAC2002 tyres scaled (``LKY``) so that the combination's
  cornering stiffness at the static loads is the same sum (:func:`equivalent_lky`).

The truth's random processes (the column's drift, its play, the sensors) and
its tyres' shape beyond the initial slope are not parameters any of the
models has: they stay in the form's share.
"""

from __future__ import annotations

import copy
from collections.abc import Callable, Mapping
from pathlib import Path

import numpy as np
import pandas as pd

from artic.mjcf.vehicle import Vehicle, resolve_vehicle_path, vehicle_from_dict
from artic.mjcf.writer import write_vehicle
from artic.validation.campaign.rankings import ORACLE
from artic.validation.synthetic import yardtyres
from artic.validation.synthetic.truth import truth_configuration, truth_data
from artic.validation.synthetic.yardtruth import YardSetup

FLOOR = "floor"

MODELS = ("kin", "stm", "mbd")
"""The models that have an oracle row (those whose parameters the vehicle file holds)."""


def tmeasy_cornering(tyre: yardtyres.YardTyre, Fz: float) -> float:
    """A TMeasy tyre's initial lateral slope ``dF0`` at a vertical load [N/rad].

    TMeasy gives ``dfy0`` at the nominal load ``fzn`` and at twice it, and
    interpolates quadratically through zero (Rill, eq. 3.95; the truth's
    ``interp_q``): ``r (x1 (2 - r) + x2 (r - 1) / 2)`` with ``r = Fz / fzn``,
    the load capped at ``fzmax``. The slip is ``-v_y / |v_x|``, so for small
    angles the slope is per radian.
    """
    r = min(float(Fz), tyre.fzmax) / tyre.fzn
    return max(0.0, r * (tyre.dfy0_1 * (2.0 - r) + tyre.dfy0_2 * 0.5 * (r - 1.0)))


def truth_cornering(vehicle: Vehicle, setup: YardSetup) -> np.ndarray:
    """The truth's cornering stiffness of every axle at its static load [N/rad], in file order.

    Each axle's load divides evenly among its tyres (two per axle, four with
    twins); each tyre is the yard truth's
    (:func:`artic.validation.synthetic.yardtyres.yard_tyre`, with the truth's
    pressure, friction and cornering draws).
    """
    out = []
    for axle, Fz in zip(vehicle.axles, vehicle.static_loads, strict=True):
        tyre = yardtyres.yard_tyre(yardtyres.size_of(vehicle.tyre_file_for(axle)), axle.dual,
                                   setup.pressure, setup.friction, setup.cornering)
        n = 4 if axle.dual else 2  # tyres on the axle: one or a twin pair per end
        out.append(n * tmeasy_cornering(tyre, Fz / n))
    return np.array(out)


def equivalent_f(vehicle: Vehicle, setup: YardSetup) -> float:
    """The STM's ``f`` [1/rad] whose ``f Fz`` sums to the truth's cornering stiffness.

    The STM has one normalised stiffness for every axle (``C_i = f Fz_i``): the
    one that keeps the combination's total, ``sum C_i / sum Fz_i``.
    """
    return float(truth_cornering(vehicle, setup).sum() / vehicle.static_loads.sum())


def equivalent_lky(vehicle: Vehicle, setup: YardSetup) -> float:
    """The PAC2002 ``LKY`` that gives the plant the truth's total cornering stiffness.

    ``LKY`` scales every tyre's ``Kya`` linearly, so it is the file's ``LKY``
    times the truth's total over the plant's at the same static loads.
    """
    from artic.plant.plant import scaled
    from artic.plant.tyre import TyreParams

    plant = 0.0
    for axle, Fz in zip(vehicle.axles, vehicle.static_loads, strict=True):
        p = scaled(TyreParams.from_tir(vehicle.tyre_file_for(axle)), vehicle.tyre_scaling)
        n = 4 if axle.dual else 2  # tyres on the axle: one or a twin pair per end
        plant += n * float(p.cornering_stiffness(Fz / n))
    lky = dict(vehicle.tyre_scaling).get("LKY", 1.0)
    return float(lky * truth_cornering(vehicle, setup).sum() / plant)


def oracle_data(load: str, truth: Mapping, seed: int) -> dict:
    """The oracle vehicle of one load condition as vehicle-file data (module docstring)."""
    data = copy.deepcopy(truth_data(load, dict(truth), seed))
    base = resolve_vehicle_path(f"gosar2022-{load}")
    v = vehicle_from_dict(data, base)
    setup = YardSetup.of(truth)
    gear = data["steering"]["mbd"]
    for m in ("kin", "stm"):
        data["steering"][m] = {"i_s": gear["i_s"], "delta_h_offset": gear["delta_h_offset"]}
    data["tyre"]["f"] = equivalent_f(v, setup)
    data["tyre"].setdefault("scaling", {})["LKY"] = equivalent_lky(v, setup)
    data["vehicle"]["name"] = f"oracle-{load}"
    data["vehicle"]["sources"] = [*data["vehicle"].get("sources", []),
                                  "The truth's own parameters for every model "
                                  "(artic.validation.campaign.oracle): f and LKY equivalent "
                                  "to the truth's TMeasy tyres at the static loads"]
    return data


def oracle_vehicle(load: str, seed: int, kind: str, path: Path | None = None) -> Vehicle:
    """The oracle vehicle of a campaign's truth (seed, kind) and load condition.

    With ``path``, written there as a vehicle file (atomically) and read back.
    """
    data = oracle_data(load, truth_configuration(seed, kind), seed)
    if path is not None:
        return write_vehicle(data, path)
    return vehicle_from_dict(data, resolve_vehicle_path(f"gosar2022-{load}"))


def applies(truth: str) -> bool:
    """Whether a campaign's truth has oracle vehicles: the independent truth's TMeasy tyres."""
    return truth == "independent"


def oracle_metrics(metrics: pd.DataFrame, oracle: pd.DataFrame | None) -> pd.DataFrame:
    """``metrics`` with the oracle rows (``oracle``, already renamed) appended."""
    if oracle is None or oracle.empty:
        return metrics
    return pd.concat([metrics, oracle], ignore_index=True)


def split(metrics: pd.DataFrame, direction: str,
          summarise: Callable[[pd.DataFrame, str], pd.DataFrame] | None = None) -> pd.DataFrame:
    """Each model's error split into form and parameters, per criterion, with intervals.

    Parameters
    ----------
    metrics : DataFrame
        Rows of the tuned models, the floor and the oracle rows (:func:`oracle_metrics`).
    direction : str
        ``forward`` or ``reverse``.
    summarise : callable, optional
        What makes a table of the differences: ``summary`` (the default, one
        truck) or ``pooled`` (several trucks, ``metrics`` with ``seed``).

    Returns
    -------
    DataFrame
        Two rows per model with an oracle row, as :func:`artic.validation.review.tables.summary`
        of paired per-manoeuvre differences: ``MODEL form`` (the oracle row minus
        the floor: what the model's equations cannot represent with the truth's own
        parameters) and ``MODEL parameters`` (the tuned row minus the oracle row:
        what the tuned parameters add, negative where tuning absorbs more than the
        truth's values do). The two add up to the tuned row's excess over the floor.
    """
    from artic.validation.review.tables import differences, summary

    summarise = summarise or summary
    present = set(metrics["model"])
    parts = []
    for m in MODELS:
        o = m + ORACLE
        if o not in present:
            continue
        form = differences(metrics[metrics["model"].isin([o, FLOOR])], direction, FLOOR)
        if len(form):
            t = summarise(form, direction)
            parts.append(t.rename(index={o: f"{m} form"}))
        if m in present:
            params = differences(metrics[metrics["model"].isin([m, o])], direction, o)
            if len(params):
                t = summarise(params, direction)
                parts.append(t.rename(index={m: f"{m} parameters"}))
    if not parts:
        return pd.DataFrame()
    out = pd.concat(parts)
    out.index.name = "model"
    return out


def form_pairs(metrics: pd.DataFrame, direction: str,
               pair: Callable[[pd.DataFrame, str], pd.DataFrame] | None = None) -> pd.DataFrame:
    """The paired table of the oracle rows and the floor: the findings on model form.

    Holm over this table's own rows; the oracle rows run on the logs only (not
    on their twins), so a finding here is a ranking resolved after the
    correction on the logs (:func:`artic.validation.campaign.findings.mark` without twins).
    ``pair`` makes the paired table: ``paired_table`` (the default) or ``pooled_paired``.
    """
    from artic.validation.campaign.findings import mark
    from artic.validation.review.tables import paired_table

    keep = metrics["model"].str.endswith(ORACLE) | (metrics["model"] == FLOOR)
    part = metrics[keep]
    if not part["model"].str.endswith(ORACLE).any():
        return pd.DataFrame()
    return mark((pair or paired_table)(part, direction), None)
