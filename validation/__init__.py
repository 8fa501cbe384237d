"""Validation of KIN, STM and the plant: rooms by job, each a sub-package.

At this level, the two modules everything shares:

- :mod:`~artic.validation.models`: the model protocol and the one registry of
  models, built-in and registered from outside;
- :mod:`~artic.validation.testing`: the pytest plugin for users' cross-model checks.

The rooms, top to bottom (each ``__init__`` lists its modules); a room imports
only the rooms below it, and rooms on one line import neither each other:

- ``cli/``: the ``artic`` command line;
- ``campaign/``: the main job: tuning, the efficiency study, the report, several
  trucks | ``docking/``: the docking benchmark;
- ``runs/``: validating runs (``artic validate`` and the campaign alike) |
  ``review/``: the summary tables, Rerun recordings and plots;
- ``synthetic/``: the generated measured campaign, its truth, drivers and sensors;
- ``criteria/``: the paper's criteria, eqs. (8)-(10), the criteria beyond them,
  and the statistics that qualify them;
- ``harness/``: the closed loop and its reversing feedback law, eqs. (5)-(7), many
  logs at once, open-loop simulation;
- ``models.py``: the model protocol and registry;
- ``logs/``: the signal schema, run files, checks and repairs, the importers;
- ``plumbing/``: process-wide: the simulated-time budget, progress, output
  folders, executors, workers, settings.

``pyproject.toml``'s import-linter contracts check the layers (docs/contributing.md
draws them).
"""
