"""The main job and its studies: tuning, validation runs, tables and the report.

- :mod:`~artic.validation.campaign.main`: ``artic campaign``, its stages and resuming;
- :mod:`~artic.validation.campaign.tuning`: fitting each model's free parameters;
- :mod:`~artic.validation.runs.validate`: every (log, model) pair through the harness;
- :mod:`~artic.validation.review.tables`: the paper's Tables 2 and 3 with intervals,
  paired comparisons, the excess over the floor, pooling over trucks;
- :mod:`~artic.validation.campaign.rankings`: rankings in words, only where resolved;
- :mod:`~artic.validation.campaign.seeds`, :mod:`~artic.validation.campaign.seedreport`:
  several trucks (``--seeds N``) and their pooled report;
- :mod:`~artic.validation.runs.gainsweep`: the criteria against the feedback gain K;
- :mod:`~artic.validation.campaign.efficiency`: wall time per simulated second;
- :mod:`~artic.validation.campaign.report`: ``report.md``;
- :mod:`~artic.validation.review.plots`, :mod:`~artic.validation.review.recording`:
  static plots, and Rerun recordings (artic's only rerun user);
- :mod:`~artic.validation.campaign.executors`: local processes or a Dask cluster;
- :mod:`~artic.validation.runs.fingerprint`: what a cached result depends on.
"""
