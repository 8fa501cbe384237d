"""Logs: the signal schema, run files, checks and repairs, and the importers.

- :mod:`~artic.validation.logs.schema`: the columns every run has (SI, ISO 8855);
- :mod:`~artic.validation.logs.runfile`: reading and writing runs (Parquet with
  their metadata), atomically;
- :mod:`~artic.validation.logs.checks`: checks and repairs of raw channels, each
  reported or refused with the file, the channel and the time;
  :mod:`~artic.validation.logs.consistency`: do the channels describe one motion;
  :mod:`~artic.validation.logs.scale`: the checks' thresholds for a vehicle's size;
- :mod:`~artic.validation.logs.importers`: ``artic logs import``, any source to a
  canonical run (which source goes where), and the canonical CSV itself (the
  schema's columns, one file): :func:`~artic.validation.logs.importers.read_log`
  reads the canonical Parquet every later command takes;
- :mod:`~artic.validation.logs.oxts`: an OXTS-style export, the three CSVs of one
  folder (``tractor.csv``, ``trailer.csv``, ``can.csv``) in the logger's own
  names and units, or the same in a ``.mat``;
- :mod:`~artic.validation.logs.channels`, :mod:`~artic.validation.logs.channelmap`,
  :mod:`~artic.validation.logs.bags`, :mod:`~artic.validation.logs.assemble`: any
  other CSV (its own names, units and clock), ROS bags and MCAP files, through a
  channel map, split at gaps, onto 100 Hz; :mod:`~artic.validation.logs.units`:
  the unit names a map may write, and each channel's dimension;
  :mod:`~artic.validation.logs.noise`: the sensors' noise a map declares;
- :mod:`~artic.validation.logs.differentiate`, :mod:`~artic.validation.logs.derive`:
  what such a log lacks (rates from poses, one unit from the other), and the
  speed smoothed as the harness reads it;
  :mod:`~artic.validation.logs.yawsteer`: steering from the measured yaw rate,
  for logs without a steering channel;
- :mod:`~artic.validation.logs.profile`: a manoeuvre's inputs as time series, which
  the synthetic campaign makes and the harness's open-loop simulation drives.

The logs sit below the harness and every other room of :mod:`artic.validation`
but the plumbing, which they may import; they import no room above.
"""
