"""Logs: the signal schema, run files, checks and repairs, and the importers.

- :mod:`~artic.validation.logs.schema`: the columns every run has (SI, ISO 8855);
- :mod:`~artic.validation.logs.runfile`: reading and writing runs (Parquet with
  their metadata), atomically;
- :mod:`~artic.validation.logs.checks`: checks and repairs of raw channels, each
  reported or refused with the file, the channel and the time;
- :mod:`~artic.validation.logs.oxts`: OXTS-style unit CSVs, CAN CSVs and ``.mat``;
- :mod:`~artic.validation.logs.importers`: ``artic logs import``, any source to a
  canonical run.
"""
