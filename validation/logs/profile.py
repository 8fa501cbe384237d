"""The inputs of a manoeuvre as time series: what the open-loop simulation drives.

:func:`artic.validation.synthetic.manoeuvres.make_profile` builds the test
matrix's; :func:`artic.validation.harness.simulate.simulate` drives any model
through one. The class lives with the logs, below both: the generator of the
synthetic campaign never imports the harness its logs validate.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Profile:
    """Inputs of a manoeuvre.

    Parameters
    ----------
    kind : str
        One of :data:`artic.validation.synthetic.manoeuvres.KINDS`.
    t, delta_h, u1 : ndarray
        Time [s], steering-wheel angle [rad], tractor speed [m/s].
    meta : dict
        Manoeuvre parameters, for the run's metadata.

    See Also
    --------
    artic.make_profile : make one of the campaign's manoeuvres.
    artic.simulate : drive a model through it.

    Examples
    --------
    >>> import artic
    >>> profile = artic.make_profile("ramp-steer-reverse", duration=10.0)
    >>> bool((profile.u1 <= 0).all()), profile.kind
    (True, 'ramp-steer-reverse')
    """

    kind: str
    t: np.ndarray
    delta_h: np.ndarray
    u1: np.ndarray
    meta: dict
