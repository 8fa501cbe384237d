"""Validating runs, for ``artic validate`` and the campaign alike, and where they run.

- :mod:`~artic.validation.runs.validate`: every (log, model) pair through the
  harness and the criteria: one metrics row and one run file per pair;
- :mod:`~artic.validation.runs.gainsweep`: the reversing criteria against the
  feedback gain K, and its stability bound;
- :mod:`~artic.validation.runs.fingerprint`: what tells a cached run (or log) from
  a stale one;
- :mod:`~artic.validation.runs.outputs`: output folders checked before the work,
  locked while in use, tidied after a crash;
- :mod:`~artic.validation.runs.runtime`: process-wide settings (numba's cache,
  MuJoCo's log and timers), made by the entry points;
- :mod:`~artic.validation.runs.workers`: worker processes that end with their parent;
- :mod:`~artic.validation.runs.warmup`: numba's compile ahead of first use, in a
  process of its own;
- :mod:`~artic.validation.runs.frequency`: the swept sine through the truth and each
  model, and their frequency responses.
"""
