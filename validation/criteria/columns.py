"""The columns the criteria beyond the paper's add to ``metrics.csv``, and their units.

In ``metrics.csv`` and ``metrics_vs_plant.csv`` they follow the paper's
criteria (:data:`artic.validation.criteria.metrics.CRITERIA`):

- ``eps_gamma`` [rad]: :mod:`artic.validation.criteria.articulation`;
- ``eps_n_fixed`` [%]: :mod:`artic.validation.criteria.fixedscale`;
- ``pred_p_2m``, ``pred_p_5m``, ``pred_p_10m`` [m] and ``pred_gamma_2m``,
  ``pred_gamma_5m``, ``pred_gamma_10m`` [rad]:
  :mod:`artic.validation.criteria.prediction`;
- ``dock_lat``, ``dock_lon`` [m] and ``dock_psi`` [rad]:
  :mod:`artic.validation.criteria.dock`.
"""

from __future__ import annotations

from artic.validation.criteria import dock, prediction

COLUMNS = ("eps_gamma", "eps_n_fixed", *prediction.COLUMNS, *dock.COLUMNS)
"""The added columns, in order."""

UNITS = {"eps_gamma": "rad", "eps_n_fixed": "%", **prediction.UNITS, **dock.UNITS}
"""Unit of each added column."""
