"""The ``artic`` command line.

- :mod:`~artic.validation.cli.commands`: the commands and their parser (``artic
  dock`` adds its own, :mod:`artic.validation.docking.command`);
- :mod:`~artic.validation.cli.entry`: the console script, process settings first;
- :mod:`~artic.validation.cli.options`: option types, every number finite and in range;
- :mod:`~artic.validation.cli.progress`: progress lines with counts and the time left.
"""
