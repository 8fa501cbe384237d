"""``artic``'s top level: its description, its commands' one-line help, the parser class.

``artic``, ``artic --help`` and ``artic --version`` need nothing below the top
level, so :func:`artic.validation.cli.entry.main` answers them from :func:`parser`
alone, without importing the commands (their defaults come from modules that load
numpy: 0.6 s of a 0.9 s ``--help``). The full parser
(:func:`artic.validation.cli.commands.build_parser`) starts from the same
:func:`parser` and adds each command's options to the subparser of the same help,
so the two print the same top-level help (tests/test_startup.py holds them equal).
This module imports nothing of artic's at its top.
"""

from __future__ import annotations

import argparse

DESCRIPTION = ("Tractor-semitrailer models at yard speeds, forward and in reverse, and their "
               "validation.")

COMMANDS = {
    "vehicle": "inspect vehicle parameter files",
    "simulate": "simulate a manoeuvre open loop",
    "validate": "validate models against logs",
    "tune": "fit f, i_s, q and the offset on forward logs",
    "mjcf": "write the multibody model as MJCF",
    "logs": "import measured logs",
    "tyre": "inspect tyre property files",
    "campaign": "the main job: generate the synthetic measured campaign and validate every "
                "model on it",
    "dock": "the docking benchmark: controllers dock the plant in a yard",
    "pbs": "low-speed performance measures (swept path, swings, off-tracking) on every model "
           "and the truth",
}
"""Each command's one-line help, in the order ``--help`` lists them."""


class Parser(argparse.ArgumentParser):
    """``argparse`` with the one-line errors of the rest of the command line."""

    def error(self, message: str) -> None:  # type: ignore[override]
        """Print ``artic: error: MESSAGE`` and exit with code 2 (no usage block)."""
        self.exit(2, f"artic: error: {message}; see {self.prog} --help\n")


class Version(argparse.Action):
    """``--version``: artic's version, read when asked (reading it costs ``--help`` 0.1 s)."""

    def __call__(self, parser, namespace, values, option_string=None):
        """Print ``artic VERSION`` and exit."""
        import artic

        print(f"artic {artic.__version__}")
        parser.exit()


def parser() -> tuple[Parser, dict[str, Parser]]:
    """The top-level parser and an empty subparser per command, keyed by name."""
    p = Parser(prog="artic", description=DESCRIPTION)
    p.add_argument("--version", action=Version, nargs=0,
                   help="show the program's version number and exit")
    sub = p.add_subparsers(dest="command", required=True, parser_class=Parser)
    return p, {name: sub.add_parser(name, help=text) for name, text in COMMANDS.items()}


def answers(argv: list[str]) -> bool:
    """Whether :func:`parser` alone answers ``argv``: no command, only ``-h``/``--version``."""
    return all(a in ("-h", "--help", "--version") for a in argv)
