"""The documentation: its API page lists exactly the public API, and its examples run.

Every ```` ```python ```` block of the README and of the docs' pages runs here, in
page order, in one namespace per page and a fresh working folder, so an example
cannot rot. A block whose info string says ``python fragment`` is a fragment
(it leans on text around it) and is only compiled. What a page tells its reader
to have first (a log from the command line, their own ``MyModel``) is made by
:data:`SETUP`, and each command it runs there must appear in the page's text.
A block that defines ``test_*`` functions is a user's test file: each runs with
the fixtures of artic's pytest plugin.
"""

from __future__ import annotations

import inspect
import re
import textwrap
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

import artic

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"

FENCE = re.compile(r"(?ms)^(?P<indent> *)```python(?P<info>[^\n]*)\n(?P<code>.*?)"
                   r"^(?P=indent)```[ \t]*$")
"""A fenced Python block, also one indented in a list; ``info`` is the rest of its info
string."""


def python_blocks(text: str) -> list[tuple[int, bool, str]]:
    """The Python blocks of a page: (line of the fence, whether it runs, its code)."""
    return [(text.count("\n", 0, m.start()) + 1, "fragment" not in m.group("info").split(),
             textwrap.dedent(m.group("code"))) for m in FENCE.finditer(text)]


def _pages() -> list[Path]:
    pages = [ROOT / "README.md", *sorted(DOCS.rglob("*.md"))]
    return [p for p in pages if not {"_build", "generated"} & set(p.parts)
            and python_blocks(p.read_text())]


def _my_model():
    """The reader's own model of the models guide and the README: KIN under its own name."""
    from artic import KIN

    class MyModel(KIN):
        name = "mine"

    return MyModel


SETUP: dict[str, tuple[list[list[str]], Callable[[], dict]]] = {
    # page: (the artic commands it runs first, the names it assumes)
    "README.md": ([["simulate", "--model", "stm", "--manoeuvre", "ramp-steer-reverse",
                    "--duration", "30", "--out", "run.parquet"]],
                  lambda: {"MyModel": _my_model()}),
    "docs/guide/cli.md": ([["mjcf", "--vehicle", "six-axle", "-o", "six-axle.xml"]], dict),
    "docs/guide/models.md": ([], lambda: {"MyModel": _my_model()}),
}


def _check_readme(ns: dict) -> None:
    # KIN driven by the STM's reversing run: its articulation stays on the log's
    # through the feedback, so it runs to within the speed filter's last few
    # samples of the log's end and its criteria are finite.
    metrics = ns["artic"].run_metrics(ns["log"].frame, ns["run"].frame)
    # The example's log runs to its end (it jackknifed at 37.9 s of the 60 s default).
    assert ns["log"].meta["status"] == "ok" and len(ns["log"].frame) == 3001
    assert len(ns["run"].frame) >= 0.99 * len(ns["log"].frame)
    assert 0 < metrics["eps_p"] < 5.0 and metrics["J_steer"] > 0
    # The criteria that catch a model that does not follow the run are there too.
    assert 0 < metrics["eps_cover"] < 5.0 and 0 < metrics["eps_gamma"] < 0.5  # [m], [rad]


def _check_models(ns: dict) -> None:
    assert {"mine", "euler_kin"} <= set(artic.model_names())
    # The subclass of artic.KIN with a 40 % steering error is not bypassed:
    # forward (no feedback) its heading turns about 40 % further than KIN's.
    turn = [float(np.ptp(np.unwrap(r.frame["psi_1"]))) for r in (ns["kin"], ns["over"])]
    assert turn[1] / turn[0] == pytest.approx(1.4, rel=0.05)
    # The outside model, public names only, runs the whole reversing log and
    # follows KIN with the same (paper's) lengths: explicit Euler's error at
    # 10 ms steps on a motion whose time constant is L2 / |u| ~ 9 s is a
    # fraction of a percent of the articulation (about 0.1 rad here).
    run, paper = ns["run"].frame, ns["paper"].frame
    assert ns["run"].meta["status"] == "ok" and len(run) == len(paper)
    assert np.max(np.abs(run["gamma"] - paper["gamma"])) < 1e-3


def _check_docking(ns: dict) -> None:
    # Docking on the plant with it is tests/test_docking_run.py's, which reads the block.
    from artic.validation.docking.controllers import Controller

    assert issubclass(ns["Proportional"], Controller)


def _check_cli(ns: dict) -> None:
    # The slalom ran to its end, and the plant stepped 10 s of simulated time.
    run, profile = ns["run"], ns["profile"]
    assert run.meta["status"] == "ok" and len(run.frame) == len(profile.t)
    assert ns["d"].time == pytest.approx(1000 * ns["m"].opt.timestep) == pytest.approx(10.0)


CHECKS: dict[str, Callable[[dict], None]] = {
    "README.md": _check_readme, "docs/guide/models.md": _check_models,
    "docs/guide/docking.md": _check_docking, "docs/guide/cli.md": _check_cli,
}
"""What a page's examples must have done, beyond running."""


def _release_plants(namespace: dict) -> None:
    """Detach the tyre callback from the MuJoCo models an example loaded (artic.plant.load)."""
    import sys

    if "mujoco" not in sys.modules:
        return
    import mujoco

    from artic.plant import callback

    for value in namespace.values():
        if isinstance(value, mujoco.MjModel):
            callback.uninstall(value)


@pytest.mark.parametrize("page", _pages(), ids=lambda p: str(p.relative_to(ROOT)))
def test_the_pages_python_examples_run(page, tmp_path, monkeypatch, request):
    from artic.validation.cli.commands import main
    from artic.validation.models import names, unregister_model

    key = str(page.relative_to(ROOT))
    text = page.read_text()
    commands, names_of = SETUP.get(key, ([], dict))
    monkeypatch.chdir(tmp_path)
    for argv in commands:
        assert " ".join(["artic", *argv]) in " ".join(text.split()), (key, argv)
        assert main(argv) == 0, argv
    namespace = {"__name__": "docs_example", **names_of()}
    before, ran = set(names()), []
    try:
        for line, runs, code in python_blocks(text):
            compiled = compile("\n" * (line - 1) + code, str(page), "exec")
            if not runs:
                continue
            exec(compiled, namespace)  # noqa: S102
            for name, fn in list(namespace.items()):
                if name.startswith("test_") and getattr(fn, "__module__", "") == "docs_example":
                    args = inspect.signature(fn).parameters
                    fn(**{a: request.getfixturevalue(a) for a in args})
                    ran.append(name)
                    del namespace[name]
        CHECKS.get(key, lambda ns: None)(namespace)
        assert len(ran) == len(re.findall(r"(?m)^def test_", text)), ran
    finally:
        for added in set(names()) - before:
            unregister_model(added)
        _release_plants(namespace)


def _sh_blocks(text: str) -> list[str]:
    return [b.strip() for b in re.findall(r"(?ms)^```sh\n(.*?)^```", text)]


def test_the_two_commands_are_the_same_everywhere_and_ci_runs_the_second():
    # The README, the install guide and .ci/run give one line each; a change to
    # one (a new check) must reach the others.
    ci = (ROOT / ".ci" / "run").read_text().strip().splitlines()[-1]
    readme = _sh_blocks((ROOT / "README.md").read_text())[:2]
    install = _sh_blocks((DOCS / "guide" / "install.md").read_text())[:2]
    assert readme == install, (readme, install)
    assert readme[1] == ci
    assert "sphinx-build -W" in ci and "artic campaign" in readme[0]


def test_every_page_with_setup_or_checks_has_examples():
    # A renamed page would otherwise leave its setup unused and its checks unrun.
    keys = {str(p.relative_to(ROOT)) for p in _pages()}
    assert set(SETUP) | set(CHECKS) <= keys, (set(SETUP) | set(CHECKS)) - keys


def test_a_fragment_is_compiled_not_run():
    text = ("x\n```python\na = 1\n```\n\n```python fragment\nb = a\n```\n```sh\nc\n```\n"
            "1. in a list:\n\n   ```python\n   c = 2\n   ```\n")
    assert python_blocks(text) == [(2, True, "a = 1\n"), (6, False, "b = a\n"),
                                   (14, True, "c = 2\n")]


def test_the_api_page_lists_the_public_names():
    text = (DOCS / "api.md").read_text()
    block = text.split(".. currentmodule:: artic\n", 1)[1].split(".. currentmodule::", 1)[0]
    listed = set(re.findall(r"(?m)^   ([A-Za-z_]\w*)\s*$", block))
    assert listed == set(artic.__all__) - {"__version__"}


def test_every_page_is_in_a_table_of_contents():
    index = (DOCS / "index.md").read_text()
    pages = {str(p.relative_to(DOCS).with_suffix("")) for p in DOCS.rglob("*.md")
             if p.name != "index.md" and "generated" not in p.parts and "_build" not in p.parts}
    listed = set(re.findall(r"(?m)^((?:guide|design)/[\w-]+|api|contributing)\s*$", index))
    assert pages == listed, pages ^ listed


def test_command_times_are_stated_once_in_the_speed_page():
    # The README, the install guide and campaign --help gave three different times for the
    # same things (issue 46, item 19): they now point to one table of measured times.
    import re as _re

    from artic.validation.cli.commands import build_parser

    table = (DOCS / "design" / "speed.md").read_text().split("## Measured times", 1)[1]
    table = table.split("\n## ", 1)[0]
    for row in ("`artic campaign --out-dir DIR`", "`artic campaign --seeds 5 --no-recordings`",
                "the second command from a fresh clone", '`pytest -m "not slow"`',
                "`artic dock --sweep` of 1 000 runs"):
        assert f"| {row}" in table, row
    camp = build_parser()._subparsers._group_actions[0].choices["campaign"]
    seeds = next(a for a in camp._actions if "--seeds" in a.option_strings).help
    quoted = {"README.md": (ROOT / "README.md").read_text(),
              "install.md": (DOCS / "guide" / "install.md").read_text(), "--seeds": seeds}
    for name, text in quoted.items():
        assert "speed.md" in text, name
        found = _re.findall(r"\b\d+(?:\.\d+)? ?(?:min|minutes|h|hours?)\b|\b\d+ s wall|"
                            r"quarter of an hour", text)
        assert not found, (name, found)
