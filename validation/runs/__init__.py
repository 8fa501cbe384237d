"""Validating runs, for ``artic validate`` and the campaign alike.

- :mod:`~artic.validation.runs.validate`: every (log, model) pair through the
  harness and the criteria: one metrics row and one run file per pair;
- :mod:`~artic.validation.runs.gainsweep`: the reversing criteria against the
  feedback gain K, and its stability bound;
- :mod:`~artic.validation.runs.warmup`: numba's compile ahead of first use, in a
  process of its own.

The processes and output folders they run in are :mod:`artic.validation.plumbing`'s.
"""
