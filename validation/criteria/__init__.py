"""The error criteria: the paper's eqs. (8)-(10), those beyond them, and their statistics.

- :mod:`~artic.validation.criteria.metrics`: the paper's distance-based criteria,
  eqs. (8)-(10), with :mod:`~artic.validation.criteria.pathdist` for the lateral
  position error (the distance to the measured path);
- :mod:`~artic.validation.criteria.articulation`: the articulation error ``eps_gamma``;
- :mod:`~artic.validation.criteria.prediction`: open-loop prediction errors of reverse logs;
- :mod:`~artic.validation.criteria.dock`: dock errors, with
  :mod:`~artic.validation.criteria.points`, points of the semitrailer from its sensor;
- :mod:`~artic.validation.criteria.fixedscale`: ``eps_n_fixed``, one scale per direction,
  with :mod:`~artic.validation.criteria.direction`, a log's direction of travel;
- :mod:`~artic.validation.criteria.columns`: the criteria beyond the paper's, their
  columns and units, in the one table the runs, the tables and the report read;
- :mod:`~artic.validation.criteria.pooled`: the criteria of a log split at its gaps;
- :mod:`~artic.validation.criteria.statistics`: confidence intervals, paired
  comparisons and the digits a mean deserves.
"""
