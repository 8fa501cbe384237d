"""The error criteria, each an error (lower is better): the paper's, those beyond, their statistics.

The paper's criteria, eqs. (8)-(10), are all in
:mod:`~artic.validation.criteria.metrics` (:func:`~artic.validation.criteria.metrics.run_metrics`,
``CRITERIA``), averaged over the distance travelled:

- ``eps_y1``, ``eps_y2`` and their sum ``eps_p`` [m]: the lateral position
  errors, the distance to the measured path
  (:mod:`~artic.validation.criteria.pathdist`);
- ``eps_r1``, ``eps_r2`` and ``eps_a`` [rad/s]: the yaw-rate errors;
- ``eps_vy1``, ``eps_vy2`` and ``eps_v`` [m/s]: the lateral-velocity errors;
- ``eps_n`` [%], eq. (9): ``eps_a`` and ``eps_v`` normalised and added;
- ``J_steer`` [%], eq. (10): the steering the harness's feedback added.

Those beyond the paper's are the rows of one table,
:data:`artic.validation.criteria.columns.TABLE` (:mod:`~artic.validation.criteria.columns`:
their columns, units, computation and pooling), each in its own module:

- ``eps_gamma`` [rad], the articulation error: :mod:`~artic.validation.criteria.articulation`;
- ``eps_cover`` [m], the progress term (how far the measured path lies from the
  model's): :mod:`~artic.validation.criteria.coverage`;
- ``steer_fb`` [deg], the steering correction in degrees of road-wheel angle,
  ``J_steer``'s absolute counterpart: :mod:`~artic.validation.criteria.correction`;
- ``eps_n_fixed`` [%], ``eps_n`` with one fixed scale per direction:
  :mod:`~artic.validation.criteria.fixedscale`, with
  :mod:`~artic.validation.criteria.direction` (a log's direction of travel);
- ``pred_p_2m`` ... ``pred_gamma_10m`` [m, rad], open-loop prediction errors of
  reverse logs: :mod:`~artic.validation.criteria.prediction`, with
  :mod:`~artic.validation.criteria.truthrecords` (the truth's states and actuation
  that generation records in a log for the floor's predictions);
- ``dock_lat``, ``dock_lon`` [m], ``dock_psi`` [rad], dock errors:
  :mod:`~artic.validation.criteria.dock`, with :mod:`~artic.validation.criteria.points`
  (points of the semitrailer from its sensor);
- ``iso_gap_r1`` ... ``iso_gap`` [-], ISO/TS 18571's rating's shortfall ``1 - R`` per
  signal: :mod:`~artic.validation.criteria.rating`, with
  :mod:`~artic.validation.criteria.iso18571` (the standard's scores and rating).

Then :mod:`~artic.validation.criteria.pooled`, the criteria of a log split at
its gaps, and :mod:`~artic.validation.criteria.statistics`, confidence
intervals, paired comparisons and the digits a mean deserves. Every column is
ranked lower-is-better by the tables' paired comparisons: a new criterion is
an error or a magnitude, never a signed quantity.
"""
