"""The documentation site: its API page lists exactly the public API."""

from __future__ import annotations

import re
from pathlib import Path

import artic

DOCS = Path(__file__).resolve().parents[1] / "docs"


def test_the_api_page_lists_the_public_names():
    text = (DOCS / "api.md").read_text()
    block = text.split(".. autosummary::", 1)[1]
    listed = set(re.findall(r"(?m)^   ([A-Za-z_]\w*)\s*$", block))
    assert listed == set(artic.__all__) - {"__version__"}


def test_every_page_is_in_a_table_of_contents():
    index = (DOCS / "index.md").read_text()
    pages = {str(p.relative_to(DOCS).with_suffix("")) for p in DOCS.rglob("*.md")
             if p.name != "index.md" and "generated" not in p.parts and "_build" not in p.parts}
    listed = set(re.findall(r"(?m)^((?:guide|design)/[\w-]+|api|contributing)\s*$", index))
    assert pages == listed, pages ^ listed


def test_the_readme_library_example_runs(tmp_path, monkeypatch):
    # The README's Python example, on a log the command line makes.
    from artic.validation.cli.commands import main

    readme = (DOCS.parent / "README.md").read_text()
    code = readme.split("```python\n", 1)[1].split("```", 1)[0]
    monkeypatch.chdir(tmp_path)
    assert main(["simulate", "--model", "stm", "--vehicle", "gosar2022-unloaded",
                 "--manoeuvre", "ramp-steer-reverse", "--out", "run.parquet"]) == 0
    namespace: dict = {}
    exec(compile(code, "README.md", "exec"), namespace)  # noqa: S102
    metrics = namespace["artic"].run_metrics(namespace["log"].frame, namespace["run"].frame)
    # KIN driven by STM's reversing run: its articulation stays on the log's
    # through the feedback, so it runs to within the speed filter's last few
    # samples of the log's end and its criteria are finite.
    assert len(namespace["run"].frame) >= 0.99 * len(namespace["log"].frame)
    assert 0 < metrics["eps_p"] < 5.0 and metrics["J_steer"] > 0
