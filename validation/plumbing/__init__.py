"""Process-wide plumbing, the bottom room: every room may import it, it imports none.

- :mod:`~artic.validation.plumbing.budget`: the simulated-time budget, seconds
  and runs of every model run, per kind of model;
- :mod:`~artic.validation.plumbing.progress`: progress lines with counts and the
  time left;
- :mod:`~artic.validation.plumbing.outputs`: output folders checked before the
  work, locked while in use, tidied after a crash;
- :mod:`~artic.validation.plumbing.executors`: local or Dask executors, for the
  campaign and the docking sweeps;
- :mod:`~artic.validation.plumbing.workers`: worker processes that end with their
  parent;
- :mod:`~artic.validation.plumbing.runtime`: process-wide settings (numba's
  cache, MuJoCo's log and timers), made by the entry points;
- :mod:`~artic.validation.plumbing.fingerprint`: what tells a cached run (or log)
  from a stale one;
- :mod:`~artic.validation.plumbing.options`: command-line option types, every
  number finite and in range (``artic`` and ``artic dock`` alike).

It imports only :mod:`artic.mjcf` (and :mod:`artic.plant` for one setting),
never another room of :mod:`artic.validation`; ``pyproject.toml``'s layers
contract checks it.
"""
