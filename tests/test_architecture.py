"""Dependency rules: validation -> {plant, reduced} -> mjcf."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[1] / "src"


def modules_after_import(package: str) -> set[str]:
    code = f"import sys, json, {package}; print(json.dumps(sorted(sys.modules)))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    return {m.split(".")[0] for m in json.loads(out.stdout)}


@pytest.mark.parametrize("package", ["reduced", "mjcf"])
def test_light_packages_do_not_import_heavy_ones(package):
    loaded = modules_after_import(package)
    assert not loaded & {"mujoco", "rerun", "pandas", "validation"}, loaded


def test_reduced_does_not_import_validation_or_plant():
    loaded = modules_after_import("reduced")
    assert "plant" not in loaded and "validation" not in loaded


def test_only_one_module_imports_rerun():
    users = [p for p in SRC.rglob("*.py")
             if any(line.strip().startswith(("import rerun", "from rerun"))
                    for line in p.read_text().splitlines())]
    assert len(users) <= 1, users
