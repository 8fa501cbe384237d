"""Logs: the signal schema, run files, checks and repairs, and the importers.

- :mod:`~artic.validation.logs.schema`: the columns every run has (SI, ISO 8855);
- :mod:`~artic.validation.logs.runfile`: reading and writing runs (Parquet with
  their metadata), atomically;
- :mod:`~artic.validation.logs.checks`: checks and repairs of raw channels, each
  reported or refused with the file, the channel and the time;
  :mod:`~artic.validation.logs.consistency`: do the channels describe one motion;
  :mod:`~artic.validation.logs.scale`: the checks' thresholds for a vehicle's size;
- :mod:`~artic.validation.logs.oxts`: OXTS-style unit CSVs, CAN CSVs and ``.mat``;
- :mod:`~artic.validation.logs.importers`: ``artic logs import``, any source to a
  canonical run;
- :mod:`~artic.validation.logs.channels`, :mod:`~artic.validation.logs.channelmap`,
  :mod:`~artic.validation.logs.bags`, :mod:`~artic.validation.logs.assemble`: CSVs,
  ROS bags and MCAP files through channel maps, split at gaps, onto 100 Hz;
- :mod:`~artic.validation.logs.differentiate`, :mod:`~artic.validation.logs.derive`:
  what such a log lacks (rates from poses, one unit from the other).
"""
