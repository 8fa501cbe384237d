"""Logs: the signal schema, run files, checks and repairs, and the importers.

- :mod:`~validation.logs.schema`: the columns every run has (SI, ISO 8855);
- :mod:`~validation.logs.runfile`: reading and writing runs (Parquet with
  their metadata), atomically;
- :mod:`~validation.logs.checks`: checks and repairs of raw channels, each
  reported or refused with the file, the channel and the time;
- :mod:`~validation.logs.oxts`: OXTS-style unit CSVs, CAN CSVs and ``.mat``;
- :mod:`~validation.logs.importers`: ``artic logs import``, any source to a
  canonical run.
"""
