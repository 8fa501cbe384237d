"""The main job and its studies: tuning, the efficiency study, the report, several trucks.

What ``artic validate`` shares with it lives in the rooms beside it: validating runs
and the gain sweep in ``runs/``, the tables, recordings and plots in ``review/``.

- :mod:`~artic.validation.campaign.main`: ``artic campaign``, its stages and resuming;
- :mod:`~artic.validation.campaign.tuning`: fitting each model's free parameters;
- :mod:`~artic.validation.campaign.efficiency`: wall time per simulated second;
- :mod:`~artic.validation.campaign.report`: ``report.md``;
- :mod:`~artic.validation.campaign.rankings`: rankings in words, only where resolved;
- :mod:`~artic.validation.campaign.classes`: tables and findings per manoeuvre class, the
  classes that carry a pooled finding, and the answer for docking and parking;
- :mod:`~artic.validation.campaign.oracle`: every model with the truth's own parameters
  (the oracle rows), and each model's error split into form and parameters;
- :mod:`~artic.validation.campaign.seeds`, :mod:`~artic.validation.campaign.seedreport`:
  several trucks (``--seeds N``) and their pooled report;
- :mod:`~artic.validation.campaign.executors`: local processes or a Dask cluster;
- :mod:`~artic.validation.campaign.frequency`: the swept sine's frequency response, per
  truck and over trucks.
"""
