"""Dependency rules: validation -> {plant, reduced} -> mjcf, under one import name.

The layer contract itself is static: ``lint-imports`` checks it in ``.ci/run``
against ``[tool.importlinter]`` in pyproject.toml. These tests check what a
static import graph cannot: that the contract is there and breakable, what
importing a light package loads at run time, and that the wheel installs one
top-level name, ``artic``.
"""

from __future__ import annotations

import importlib
import importlib.util
import json
import os
import shutil
import subprocess
import sys
import sysconfig
import venv
import zipfile
from pathlib import Path

import pytest

from tests.helpers import FIRST_ROLLOUT

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("mjcf", "plant", "reduced", "validation")


def modules_after_import(package: str) -> set[str]:
    """artic's sub-packages and the other top-level packages that importing ``package`` loads."""
    code = f"import sys, json, {package}; print(json.dumps(sorted(sys.modules)))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    names = json.loads(out.stdout)
    return ({m.split(".")[1] for m in names if m.startswith("artic.")}
            | {m.split(".")[0] for m in names if not m.startswith("artic")})


@pytest.mark.parametrize("package", ["artic.reduced", "artic.mjcf"])
def test_light_packages_do_not_import_heavy_ones(package):
    loaded = modules_after_import(package)
    assert not loaded & {"mujoco", "rerun", "pandas", "validation", "plant"}, loaded


def test_plant_does_not_load_numba():
    # Importing the plant must not touch the reduced models' compiled code.
    assert not modules_after_import("artic.plant") & {"numba", "reduced", "validation"}


def test_the_front_door_is_light_and_lists_the_public_api():
    # `import artic` loads none of the sub-packages: the public names come on first use.
    assert not modules_after_import("artic") & {"numba", "mujoco", "pandas", *PACKAGES}
    import artic

    missing = [n for n in artic.__all__ if getattr(artic, n, None) is None]
    assert not missing, missing
    assert set(artic.__all__) <= set(dir(artic))
    with pytest.raises(AttributeError, match="no attribute 'nothing_here'"):
        artic.nothing_here  # noqa: B018


def test_help_lists_every_public_name_and_not_the_lazy_loading():
    # help(artic): its summary names each public name, and the machinery that
    # loads them on first use is not listed among its functions.
    import pydoc
    import re

    import artic

    summary = artic.__doc__.split("``__all__``", 1)[1]
    unnamed = [n for n in artic.__all__ if n != "__version__"
               and not re.search(rf":(func|class|mod):`{n}`", summary)]
    assert not unnamed, unnamed
    text = pydoc.render_doc(artic, renderer=pydoc.plaintext)
    functions = text.split("FUNCTIONS", 1)[1].split("DATA", 1)[0]
    assert "__getattr__" not in text and "__dir__" not in text, functions
    assert "load_vehicle(" in functions and "Controller" in text
    assert artic.__all__ == sorted(artic.__all__[:-1]) + ["__version__"]


def test_only_one_module_imports_rerun():
    users = [p for pkg in PACKAGES for p in (ROOT / pkg).rglob("*.py")
             if any(line.strip().startswith(("import rerun", "from rerun"))
                    for line in p.read_text().splitlines())]
    assert len(users) <= 1, users


def test_the_four_root_folders_are_artic_without_links():
    # The design card keeps the four folders at the root; setup.py maps them
    # under artic (package-dir), and no file in the repository is a link.
    import artic

    links = [p for p in ROOT.rglob("*") if p.is_symlink()
             and not {".venv", ".git", "build"} & set(p.relative_to(ROOT).parts)]
    assert not links, links
    for pkg in PACKAGES:
        module = importlib.import_module(f"artic.{pkg}")
        assert Path(module.__file__).resolve() == (ROOT / pkg / "__init__.py").resolve()
    assert Path(artic.__file__).resolve() == (ROOT / "artic" / "__init__.py").resolve()


def test_artic_searches_its_own_folder_alone():
    # The checkout's other files (setup.py, the tests' conftest, the docs'
    # conf.py) are no modules of artic: its search path is artic/ alone, and
    # the install maps the four folders by name (package-dir).
    import artic

    assert [Path(p).resolve() for p in artic.__path__] == [(ROOT / "artic").resolve()]
    for name in ("artic.setup", "artic.tests", "artic.docs", "artic.benchmarks"):
        assert importlib.util.find_spec(name) is None, name


def test_the_stub_lists_the_public_api():
    # artic/__init__.pyi is what type checkers read; it must name each public
    # name from the module the front door loads it from.
    import ast

    import artic

    tree = ast.parse((ROOT / "artic" / "__init__.pyi").read_text())
    stub = {}
    for node in tree.body:
        if isinstance(node, ast.ImportFrom):
            for alias in node.names:
                name = alias.asname or alias.name
                # `from artic import errors`: a module of the front door itself
                stub[name] = ((f"artic.{name}", "") if node.module == "artic"
                              else (node.module, alias.name))
    assert stub == artic._PUBLIC
    listed = next(n.value for n in tree.body if isinstance(n, ast.Assign)
                  and n.targets[0].id == "__all__")
    assert ast.literal_eval(listed) == artic.__all__
    assert (ROOT / "artic" / "py.typed").is_file()


def test_the_staged_tree_is_the_wheels(tmp_path):
    # .ci/staged.py lays the package out as the wheel does; lint-imports and
    # mypy read that tree. Every module of the four folders is in it.
    spec = importlib.util.spec_from_file_location("staged", ROOT / ".ci" / "staged.py")
    staged = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(staged)
    tree = staged.stage(tmp_path)
    want = {str(p.relative_to(ROOT)) for pkg in PACKAGES for p in (ROOT / pkg).rglob("*.py")
            if "__pycache__" not in p.parts}
    want |= {p.name for p in (ROOT / "artic").glob("*.py")}  # the front door's own
    got = {str(p.relative_to(tree / "artic")) for p in (tree / "artic").rglob("*.py")}
    assert got == want, sorted(want ^ got)[:10]


def _lint():
    lint = shutil.which("lint-imports") or str(Path(sys.executable).parent / "lint-imports")
    return lint if Path(lint).exists() or shutil.which("lint-imports") else None


@pytest.mark.skipif(_lint() is None,
                    reason="import-linter is not installed (it is in the [test] extra)")
def test_a_forbidden_import_breaks_its_contract(tmp_path):
    # A copy of the tree that keeps every contract, then one forbidden import at a
    # time: sideways between the packages (reduced -> plant), upward between
    # validation's rooms (logs -> harness), and a cycle (units <-> noise in logs/).
    (tmp_path / "artic").mkdir()
    shutil.copy(ROOT / "artic" / "__init__.py", tmp_path / "artic" / "__init__.py")
    for pkg in PACKAGES:
        shutil.copytree(ROOT / pkg, tmp_path / "artic" / pkg,
                        ignore=shutil.ignore_patterns("__pycache__", "*.so"))
    shutil.copy(ROOT / "pyproject.toml", tmp_path / "pyproject.toml")
    env = {"PATH": "", "PYTHONPATH": str(tmp_path)}
    ok = subprocess.run([_lint()], cwd=tmp_path, capture_output=True, text=True, env=env)
    assert ok.returncode == 0, ok.stdout[-2000:]
    for module, line, contract in (
            ("reduced/models.py", "import artic.plant", "validation -> {plant, reduced} -> mjcf"),
            ("validation/logs/schema.py", "import artic.validation.harness.loop",
             "validation's rooms in layers"),
            ("validation/logs/units.py", "import artic.validation.logs.noise",
             "no import cycles")):
        f = tmp_path / "artic" / module
        before = f.read_text()
        f.write_text(before + f"\n{line}  # noqa\n")
        broken = subprocess.run([_lint()], cwd=tmp_path, capture_output=True, text=True,
                                env=env)
        f.write_text(before)
        # The list of contracts, each followed by KEPT or BROKEN (long names wrap).
        listed = " ".join(broken.stdout.split()).split("Contracts: ")[0]
        verdict = listed[listed.index(contract) + len(contract):]
        verdict = min((verdict.find(v), v) for v in (" KEPT", " BROKEN") if v in verdict)[1]
        assert broken.returncode != 0 and verdict == " BROKEN", (module, broken.stdout[-3000:])


@pytest.mark.slow
def test_the_wheel_installs_one_import_name(tmp_path):
    # Build the wheel as pip would (no build isolation: the test environment
    # has setuptools and mujoco's headers), then install it into a fresh
    # virtual environment that borrows only the dependencies of this one.
    # From a clone without symbolic links (Git for Windows' default), where
    # this is a checkout; an unpacked sdist is built as it is.
    source = ROOT
    if (ROOT / ".git").exists() and shutil.which("git"):
        source = tmp_path / "clone"
        subprocess.run(["git", "clone", "-q", "-c", "core.symlinks=false", str(ROOT),
                        str(source)], check=True, capture_output=True)
    wheels = tmp_path / "wheels"
    subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation",
                    "-q", "-w", str(wheels), str(source)], check=True, capture_output=True)
    (wheel,) = wheels.glob("artic-*.whl")
    names = zipfile.ZipFile(wheel).namelist()
    top = {n.split("/")[0] for n in names}
    # Every module of the four folders, under artic/ (a checkout without links
    # once gave a wheel of artic/__init__.py alone).
    want = {f"artic/{p.relative_to(ROOT).as_posix()}" for pkg in PACKAGES
            for p in (ROOT / pkg).rglob("*.py") if "__pycache__" not in p.parts}
    assert want <= set(names), sorted(want - set(names))[:10]
    assert "artic/py.typed" in names and "artic/__init__.pyi" in names
    assert {t for t in top if not t.endswith((".dist-info", ".data"))} == {"artic"}, top

    env_dir = tmp_path / "env"
    venv.EnvBuilder(with_pip=False).create(env_dir)
    py = env_dir / "bin" / "python"
    site = Path(subprocess.run([str(py), "-c", "import sysconfig; print(sysconfig.get_path("
                                "'purelib'))"], capture_output=True, text=True,
                               check=True).stdout.strip())
    before = set(os.listdir(site))
    subprocess.run([sys.executable, "-m", "pip", "--python", str(py), "install", "--no-deps",
                    "--no-index", "-q", str(wheel)], check=True, capture_output=True)
    added = {n for n in set(os.listdir(site)) - before
             if not n.endswith((".dist-info", ".pth")) and n != "__pycache__"}
    assert added == {"artic"}, added
    # The dependencies come from this environment's site-packages, through a
    # path file; the editable artic there is not on that path (its own .pth
    # files are not read for a directory that a .pth adds).
    (site / "deps.pth").write_text(sysconfig.get_path("purelib") + "\n")
    clean = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    code = ("import artic, sys; v = artic.load_vehicle('gosar2022-unloaded'); "
            "print(artic.__file__, v.L1 if hasattr(v, 'L1') else 'ok')")
    ok = subprocess.run([str(py), "-c", code], cwd=tmp_path, capture_output=True, text=True,
                        env=clean)
    assert ok.returncode == 0 and str(site) in ok.stdout, ok.stderr[-2000:]
    gone = subprocess.run([str(py), "-c", "import validation"], cwd=tmp_path,
                          capture_output=True, text=True, env=clean)
    assert gone.returncode != 0 and "No module named 'validation'" in gone.stderr
    # The wheel carries numba's cache of KIN and the STM (setup.py's build_ext),
    # and in site-packages the first rollout loads it instead of compiling.
    assert any(n.startswith("artic/reduced/__pycache__/control.rollout_steps")
               and n.endswith(".nbi") for n in names), "the wheel carries no numba cache"
    user = {k: v for k, v in clean.items() if k != "NUMBA_CACHE_DIR"}
    first = subprocess.run([str(py), "-c", FIRST_ROLLOUT], cwd=tmp_path, capture_output=True,
                           text=True, env=user)
    assert first.returncode == 0, first.stderr[-2000:]
    got = json.loads(first.stdout.strip().splitlines()[-1])
    assert got["hits"] == 1 and got["misses"] == 0, got
