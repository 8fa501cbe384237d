"""The ``artic`` console script.

The process-wide settings of :mod:`artic.validation.plumbing.runtime` (numba's cache
folder, MuJoCo's warnings and timers) must be made before the compiled models are
imported: :func:`artic.validation.cli.commands.main` makes them once the command line
is parsed, so that ``artic --help`` loads neither numba nor MuJoCo. This module
imports nothing of artic's at its top, so that the console script's own start costs
nothing either; ``artic``, ``artic --help`` and ``artic --version`` are answered by
:mod:`artic.validation.cli.toplevel` alone, without importing the commands.
"""

from __future__ import annotations

import sys
from collections.abc import Sequence


def main(argv: Sequence[str] | None = None) -> int:
    """Run :func:`artic.validation.cli.commands.main`, which configures the process.

    Returns the exit code.
    """
    from artic.validation.cli import toplevel

    if toplevel.answers(list(sys.argv[1:] if argv is None else argv)):
        try:
            toplevel.parser()[0].parse_args(argv)
        except SystemExit as exc:  # --help, --version, or no command (exit 2)
            return int(exc.code or 0) if isinstance(exc.code, int | None) else 2
    from artic.validation.cli.commands import main as cli_main

    return cli_main(argv)
