"""The main job and its studies: tuning, validation runs, tables and the report.

- :mod:`~validation.campaign.main`: ``artic campaign``, its stages and resuming;
- :mod:`~validation.campaign.tuning`: fitting each model's free parameters;
- :mod:`~validation.campaign.validate`: every (log, model) pair through the harness;
- :mod:`~validation.campaign.tables`: the paper's Tables 2 and 3;
- :mod:`~validation.campaign.gainsweep`: the criteria against the feedback gain K;
- :mod:`~validation.campaign.efficiency`: wall time per simulated second;
- :mod:`~validation.campaign.report`: ``report.md``;
- :mod:`~validation.campaign.plots`, :mod:`~validation.campaign.recording`:
  static plots, and Rerun recordings (artic's only rerun user);
- :mod:`~validation.campaign.executors`: local processes or a Dask cluster;
- :mod:`~validation.campaign.fingerprint`: what a cached result depends on.
"""
