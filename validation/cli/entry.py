"""The ``artic`` console script: process-wide settings first, then the command line.

The settings of :mod:`artic.validation.runs.runtime` must be made before the compiled
models are imported, so this module imports nothing of artic's at its top.
"""

from __future__ import annotations

from collections.abc import Sequence


def main(argv: Sequence[str] | None = None) -> int:
    """Configure the process, then run :func:`artic.validation.cli.commands.main`.

    Returns the exit code.
    """
    from artic.validation.runs import runtime

    runtime.configure()
    from artic.validation.cli.commands import main as cli_main

    return cli_main(argv)
