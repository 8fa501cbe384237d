"""The ``artic`` console script.

The process-wide settings of :mod:`artic.validation.plumbing.runtime` (numba's cache
folder, MuJoCo's warnings and timers) must be made before the compiled models are
imported: :func:`artic.validation.cli.commands.main` makes them once the command line
is parsed, so that ``artic --help`` loads neither numba nor MuJoCo. This module
imports nothing of artic's at its top, so that the console script's own start costs
nothing either.
"""

from __future__ import annotations

from collections.abc import Sequence


def main(argv: Sequence[str] | None = None) -> int:
    """Run :func:`artic.validation.cli.commands.main`, which configures the process.

    Returns the exit code.
    """
    from artic.validation.cli.commands import main as cli_main

    return cli_main(argv)
