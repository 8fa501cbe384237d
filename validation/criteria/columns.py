"""The criteria beyond the paper's: one table of their columns, units, computation and pooling.

In ``metrics.csv`` and ``metrics_vs_plant.csv`` they follow the paper's
criteria (:data:`artic.validation.criteria.metrics.CRITERIA`), in the order of
:data:`TABLE`:

- ``eps_gamma`` [rad]: :mod:`artic.validation.criteria.articulation`;
- ``eps_cover`` [m], the progress term: :mod:`artic.validation.criteria.coverage`;
- ``steer_fb`` [deg], the steering correction (``J_steer``'s absolute counterpart):
  :mod:`artic.validation.criteria.correction`;
- ``eps_n_fixed`` [%]: :mod:`artic.validation.criteria.fixedscale`;
- ``pred_p_2m``, ``pred_p_5m``, ``pred_p_10m`` [m] and ``pred_gamma_2m``,
  ``pred_gamma_5m``, ``pred_gamma_10m`` [rad]:
  :mod:`artic.validation.criteria.prediction`;
- ``dock_lat``, ``dock_lon`` [m] and ``dock_psi`` [rad]:
  :mod:`artic.validation.criteria.dock`;
- ``iso_gap_r1``, ``iso_gap_r2``, ``iso_gap_vy1``, ``iso_gap_vy2``, ``iso_gap_gamma`` and
  ``iso_gap`` [-], ISO/TS 18571's rating's shortfall ``1 - R``:
  :mod:`artic.validation.criteria.rating`.

:data:`TABLE` is the one place that lists them. The runs
(:mod:`artic.validation.runs.validate`) compute every row of it for every
(log, model) pair, a log split at its gaps pools them as each row says
(:mod:`artic.validation.criteria.pooled`), and the tables, the paired
comparisons and the report show every column that has values. A new criterion
of a log and a model run is therefore a module in ``criteria/`` with a function
``of_run(log, run, vehicle)`` and one row here.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass
from typing import TYPE_CHECKING

from artic.mjcf.errors import UserError
from artic.validation.criteria import dock, prediction, rating

if TYPE_CHECKING:
    from artic.mjcf.vehicle import Vehicle
    from artic.validation.logs.runfile import Run

POOLING = ("rms", "mean", "last", "set")
"""How a log split at its gaps pools a criterion over its segments (see :class:`Criterion`)."""


@dataclass(frozen=True)
class Criterion:
    """One row of :data:`TABLE`: a criterion beyond the paper's, one column or several.

    Attributes
    ----------
    units : dict of str to str
        Its columns in ``metrics.csv``, in order, and the unit of each.
    compute : str
        ``"package.module:function"``: ``function(log, run, vehicle)`` of the
        log (:class:`~artic.validation.logs.runfile.Run`), the model's run
        through the harness and the vehicle the model was built from, returning
        a float per column (NaN where the criterion does not apply); the runs
        call it for every pair with a result. ``"model"``: it needs the model
        itself, driven again from points along the log (the open-loop
        predictions, :func:`artic.validation.runs.validate._simulate`).
        ``"set"``: it needs the whole set of logs (the fixed scale of
        ``eps_n_fixed``), and the runs add it per row.
    pool : str
        Over the segments of a log split at its gaps: ``"rms"``, a
        distance-RMS error as eq. (8), pooled exactly by the distance of each
        segment; ``"mean"``, the distance-weighted mean of the segments that
        have a value; ``"last"``, the last segment's (where the log ends);
        ``"set"``, recomputed from the pooled paper criteria.
    """

    units: dict[str, str]
    compute: str
    pool: str

    def __post_init__(self) -> None:
        if self.pool not in POOLING:
            raise UserError(f"criterion {', '.join(self.units)}: pool {self.pool!r}; "
                             f"choose from {', '.join(POOLING)}")
        if self.compute not in ("model", "set") and ":" not in self.compute:
            raise UserError(f"criterion {', '.join(self.units)}: compute {self.compute!r}; "
                             "give 'package.module:function', 'model' or 'set'")


TABLE: tuple[Criterion, ...] = (
    Criterion({"eps_gamma": "rad"}, "artic.validation.criteria.articulation:of_run", "rms"),
    Criterion({"eps_cover": "m"}, "artic.validation.criteria.coverage:of_run", "rms"),
    Criterion({"steer_fb": "deg"}, "artic.validation.criteria.correction:of_run", "rms"),
    Criterion({"eps_n_fixed": "%"}, "set", "set"),
    Criterion({c: prediction.UNITS[c] for c in prediction.COLUMNS}, "model", "mean"),
    Criterion({c: dock.UNITS[c] for c in dock.COLUMNS}, "artic.validation.criteria.dock:of_run",
              "last"),
    Criterion(rating.UNITS, "artic.validation.criteria.rating:of_run", "mean"),
)
"""The criteria beyond the paper's, in ``metrics.csv`` order."""

COLUMNS = tuple(c for row in TABLE for c in row.units)
"""The added columns, in order."""

UNITS = {c: u for row in TABLE for c, u in row.units.items()}
"""Unit of each added column."""

POOL = {c: row.pool for row in TABLE for c in row.units}
"""How each added column is pooled over a log's segments."""

COMPUTE = {c: row.compute for row in TABLE for c in row.units}
"""How each added column is computed."""

COUNTERPARTS = {"J_steer": "steer_fb", "eps_n": "eps_p"}
"""Each normalised criterion's absolute counterpart, shown beside it in every table:
``J_steer`` [%] beside ``steer_fb`` [deg] (the RMS feedback part of the road-wheel
angle), ``eps_n`` [%] beside the lateral position error ``eps_p`` [m]. A normalised
criterion divides by a mean of the manoeuvre's own signals, so it cannot be
compared across manoeuvre classes; its counterpart can."""


def of_run(log: Run, run: Run, vehicle: Vehicle) -> dict[str, float]:
    """Every criterion of :data:`TABLE` that is a function of a log and a model run.

    Parameters
    ----------
    log : Run
        The measured log.
    run : Run
        The model's run through the harness, sample for sample.
    vehicle : Vehicle
        The vehicle the model was built from.

    Returns
    -------
    dict
        Per column of those rows, its value.
    """
    out: dict[str, float] = {}
    for row in TABLE:
        if ":" in row.compute:
            module, _, name = row.compute.partition(":")
            values = getattr(importlib.import_module(module), name)(log, run, vehicle)
            out |= {c: float(values[c]) for c in row.units}
    return out
