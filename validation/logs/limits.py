"""How large a model's observed signals may be and still be scored.

The harness's loops stop a run whose output passes these limits
(:func:`artic.validation.harness.loop.beyond_limits`): the Python loop, and
the yard truth's compiled loop (:mod:`artic.validation.synthetic.yardloop`),
which reads them from here without loading the harness.
"""

from __future__ import annotations

import numpy as np

from artic.validation.logs.runfile import MAX_POSITION

OBSERVATION_LIMIT = np.array([MAX_POSITION, MAX_POSITION, 1e4, 100.0, 100.0, 100.0] * 2
                             + [1e4])
"""Largest magnitude of each observed signal (``OBSERVATION`` order, SI) a model's output may
have and still be scored: positions within :data:`~artic.validation.logs.runfile.MAX_POSITION`
(a quarter meridian), headings within 1e4 rad, speeds within 100 m/s (360 km/h) and rates
within 100 rad/s. A model beyond them (an output of 1e300) has diverged as surely as one
that is no longer finite: its run stops there, with its status saying so, instead of an
``eps_p`` of infinity with the status ``ok``."""
