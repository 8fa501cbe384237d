"""The ``artic`` command line, the top room: it imports the others, none imports it.

- :mod:`~artic.validation.cli.commands`: the commands and their parser (``artic
  dock`` adds its own, :mod:`artic.validation.docking.command`);
- :mod:`~artic.validation.cli.entry`: the console script, process settings first.

Option types and progress lines, which ``artic dock`` shares, are
:mod:`artic.validation.plumbing`'s.
"""
