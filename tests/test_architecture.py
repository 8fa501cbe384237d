"""Dependency rules: validation -> {plant, reduced} -> mjcf.

The layer contract itself is static: ``lint-imports`` checks it in ``.ci/run``
against ``[tool.importlinter]`` in pyproject.toml. These tests check what a
static import graph cannot: that the contract is there and breakable, and
what importing a light package loads at run time.
"""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("mjcf", "plant", "reduced", "validation")


def modules_after_import(package: str) -> set[str]:
    code = f"import sys, json, {package}; print(json.dumps(sorted(sys.modules)))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    return {m.split(".")[0] for m in json.loads(out.stdout)}


@pytest.mark.parametrize("package", ["reduced", "mjcf"])
def test_light_packages_do_not_import_heavy_ones(package):
    loaded = modules_after_import(package)
    assert not loaded & {"mujoco", "rerun", "pandas", "validation", "plant"}, loaded


def test_plant_does_not_load_numba():
    # Importing the plant must not touch the reduced models' compiled code.
    assert not modules_after_import("plant") & {"numba", "reduced", "validation"}


def test_only_one_module_imports_rerun():
    users = [p for pkg in PACKAGES for p in (ROOT / pkg).rglob("*.py")
             if any(line.strip().startswith(("import rerun", "from rerun"))
                    for line in p.read_text().splitlines())]
    assert len(users) <= 1, users


def test_the_layer_contract_is_declared():
    cfg = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["importlinter"]
    layers = [c for c in cfg["contracts"] if c["type"] == "layers"]
    assert layers and layers[0]["layers"] == ["validation", "plant | reduced", "mjcf"]


@pytest.mark.skipif(shutil.which("lint-imports") is None and not (
    Path(sys.executable).parent / "lint-imports").exists(),
    reason="import-linter is not installed (it is in the [test] extra)")
def test_a_sideways_import_breaks_the_contract(tmp_path):
    # A copy of the tree with one forbidden import added: reduced -> plant.
    for pkg in PACKAGES:
        shutil.copytree(ROOT / pkg, tmp_path / pkg,
                        ignore=shutil.ignore_patterns("__pycache__", "*.so"))
    shutil.copy(ROOT / "pyproject.toml", tmp_path / "pyproject.toml")
    lint = shutil.which("lint-imports") or str(Path(sys.executable).parent / "lint-imports")
    env = {"PATH": "", "PYTHONPATH": str(tmp_path)}
    ok = subprocess.run([lint], cwd=tmp_path, capture_output=True, text=True, env=env)
    assert ok.returncode == 0, ok.stdout[-2000:]
    f = tmp_path / "reduced" / "models.py"
    f.write_text(f.read_text() + "\nimport plant  # noqa\n")
    broken = subprocess.run([lint], cwd=tmp_path, capture_output=True, text=True, env=env)
    assert broken.returncode != 0 and "BROKEN" in broken.stdout, broken.stdout[-2000:]
