"""Start-up: ``artic --help`` loads none of the heavy libraries, a command still configures.

A behaviour test, not a timed one: the 0.3 s of ``artic --help`` is measured by
``benchmarks/bench_commands.py`` on a quiet machine; here what it loads.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

HEAVY = ("mujoco", "numba", "rerun", "pandas", "scipy", "pyarrow", "matplotlib")
"""What ``--help`` must not load: the simulator, the compiler, the viewer, the tables."""


def loaded_after(argv: list[str], env: dict[str, str] | None = None,
                 edited: bool = False) -> tuple[int, dict]:
    """Exit code of the ``artic`` entry point on ``argv`` in a fresh process, and what it loaded.

    ``edited``: as if a compiled source had changed since the install.
    """
    code = (
        "import json, os, sys\n"
        + ("from artic.validation.plumbing import runtime\n"
           "runtime.install_cache_current = lambda: False\n" if edited else ""))
    code += (
        "from artic.validation.cli.entry import main\n"
        f"rc = main({argv!r})\n"
        "print(json.dumps({'rc': rc, 'heavy': [m for m in " + repr(HEAVY)
        + " if m in sys.modules], 'cache': os.environ.get('NUMBA_CACHE_DIR')}))\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=300, env=env)
    assert done.returncode == 0, done.stderr[-2000:]
    out = json.loads(done.stdout.splitlines()[-1])
    return out["rc"], out


@pytest.mark.parametrize("argv", [["--help"], ["campaign", "--help"], ["dock", "--help"],
                                  ["campaign", "--seeds", "0"]])
def test_help_and_option_errors_load_no_simulator_compiler_or_viewer(argv):
    rc, out = loaded_after(argv)
    assert rc == (2 if "--seeds" in argv else 0)
    assert out["heavy"] == [], out


def test_a_command_configures_numbas_cache_once_parsed(tmp_path):
    # The configuration moved from the console script's start to after the parse: a
    # command that runs still points numba at artic's folder before compiling anything.
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    env["XDG_CACHE_HOME"] = str(tmp_path)
    rc, out = loaded_after(["vehicle", "show", "gosar2022-unloaded", "--json"], env, edited=True)
    assert rc == 0
    assert out["cache"] is not None and out["cache"].startswith(str(tmp_path / "artic" / "numba"))
    assert "mujoco" in out["heavy"]  # its warnings and timers are set for the command


def test_import_artic_loads_no_numpy_nor_metadata():
    code = ("import json, sys, artic; print(json.dumps([m for m in ('numpy', "
            "'importlib.metadata') + " + repr(HEAVY) + " if m in sys.modules]))")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          check=True, timeout=120)
    assert json.loads(done.stdout) == []


@pytest.mark.parametrize("argv", [["--help"], ["--version"], []])
def test_the_top_level_is_answered_without_the_commands_or_numpy(argv):
    # `artic`, `artic --help` and `artic --version` need no command's options: the
    # commands' modules (and numpy under their defaults) stay unloaded.
    code = ("import json, sys\nfrom artic.validation.cli.entry import main\n"
            f"rc = main({argv!r})\n"
            "print(json.dumps({'rc': rc, 'loaded': [m for m in ('numpy', "
            "'artic.validation.cli.commands') if m in sys.modules]}))\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=120)
    out = json.loads(done.stdout.splitlines()[-1])
    assert out == {"rc": 2 if argv == [] else 0, "loaded": []}, done.stderr
    if argv == []:  # the full parser's one-line error
        assert "artic: error: the following arguments are required: command" in done.stderr


def test_the_top_level_help_is_the_full_parsers():
    from artic.validation.cli import toplevel
    from artic.validation.cli.commands import build_parser

    full = build_parser()
    assert toplevel.parser()[0].format_help() == full.format_help()
    assert toplevel.answers(["-h", "--version"]) and not toplevel.answers(["dock", "--help"])
