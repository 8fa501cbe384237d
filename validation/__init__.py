"""Validation of KIN, STM and the plant: rooms by job, each a sub-package.

At this level, the two modules everything shares:

- :mod:`~artic.validation.models`: the model protocol and the one registry of
  models, built-in and registered from outside;
- :mod:`~artic.validation.testing`: the pytest plugin for users' cross-model checks.

The rooms (each ``__init__`` lists its modules):

- ``harness/``: the closed loop and its reversing feedback law, eqs. (5)-(7), the
  steering map, when reversing is on, many logs at once, open-loop simulation;
- ``criteria/``: the paper's criteria, eqs. (8)-(10), the criteria beyond them,
  and the statistics that qualify them;
- ``logs/``: the signal schema, run files, checks and repairs, the importers;
- ``synthetic/``: the generated measured campaign, its truth, drivers and sensors;
- ``runs/``: validating runs (``artic validate`` and the campaign alike), and the
  processes and output folders they run in;
- ``review/``: the summary tables, Rerun recordings and plots;
- ``campaign/``: the main job: tuning, the efficiency study, the report, several trucks;
- ``docking/``: the docking benchmark;
- ``cli/``: the ``artic`` command line.
"""
