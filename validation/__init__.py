"""Validation of KIN, STM and the plant: the harness, the criteria, and what feeds them.

At this level, what every validation shares:

- :mod:`~validation.harness`: the closed-loop harness and its reversing
  feedback law, eqs. (5)-(7);
- :mod:`~validation.metrics`: the distance-based error criteria, eqs. (8)-(10),
  with :mod:`~validation.pathdist` for the lateral position error;
- :mod:`~validation.steering`: the steering map, eq. (3);
- :mod:`~validation.models`: the model protocol and the one registry of models;
- :mod:`~validation.batch`: many logs through the harness at once;
- :mod:`~validation.simulate`: open-loop simulation of a manoeuvre;
- :mod:`~validation.cli` (and :mod:`~validation.entry`, the console script):
  the ``artic`` command line; :mod:`~validation.runtime`: process-wide settings.

Sub-packages: :mod:`validation.logs` (schema, run files, checks, importers),
:mod:`validation.synthetic` (the generated measured campaign) and
:mod:`validation.campaign` (the main job, tuning, tables, report, recordings).
"""
