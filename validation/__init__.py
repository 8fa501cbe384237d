"""Validation of KIN, STM and the plant: the harness, the criteria, and what feeds them.

At this level, what every validation shares:

- :mod:`~artic.validation.harness`: the closed-loop harness and its reversing
  feedback law, eqs. (5)-(7); :mod:`~artic.validation.reversing`: when that
  feedback is on (hysteresis on the speed);
- :mod:`~artic.validation.metrics`: the distance-based error criteria, eqs. (8)-(10),
  with :mod:`~artic.validation.pathdist` for the lateral position error;
- :mod:`~artic.validation.steering`: the steering map, eq. (3);
- :mod:`~artic.validation.models`: the model protocol and the one registry of models,
  built-in and registered from outside;
- :mod:`~artic.validation.batch`: many logs through the harness at once;
- :mod:`~artic.validation.simulate`: open-loop simulation of a manoeuvre;
- :mod:`~artic.validation.testing`: the pytest plugin for users' cross-model checks;
- :mod:`~artic.validation.cli` (and :mod:`~artic.validation.entry`, the console script):
  the ``artic`` command line; :mod:`~artic.validation.runtime`: process-wide settings.

Sub-packages: :mod:`artic.validation.logs` (schema, run files, checks, importers),
:mod:`artic.validation.synthetic` (the generated measured campaign) and
:mod:`artic.validation.campaign` (the main job, tuning, tables, report, recordings).
"""
