"""numba's cache of artic's compiled functions follows exactly the compiled sources."""

from __future__ import annotations

import os
import shutil
import time
from pathlib import Path

import numba

from artic.validation.plumbing import runtime

ROOT = Path(__file__).resolve().parents[1]


def copies(tmp_path: Path) -> list[Path]:
    out = []
    for src in runtime.compiled_sources():
        dst = tmp_path / src.parent.name / src.name
        dst.parent.mkdir(exist_ok=True)
        shutil.copy(src, dst)
        out.append(dst)
    return out


def test_compiled_sources_are_the_reduced_package_and_the_harness_loops():
    names = {(p.parent.name, p.name) for p in runtime.compiled_sources()}
    assert ("reduced", "single_track.py") in names and ("harness", "reducedloop.py") in names
    assert ("cli", "commands.py") not in names
    # Every module that defines compiled code is among them, and so is every
    # module whose plain functions a compiled module compiles.
    for pkg in ("mjcf", "plant", "reduced", "validation"):
        for p in (ROOT / pkg).rglob("*.py"):
            text = p.read_text()
            if "@njit" in text or "njit(" in text:
                assert (p.parent.name, p.name) in names, p
    assert ("harness", "feedback.py") in names  # reducedloop compiles its law


def test_editing_a_compiled_module_moves_the_cache(tmp_path):
    files = copies(tmp_path)
    before = runtime.source_hash(files)
    assert before == runtime.source_hash()
    # A callee's module: numba alone would keep its callers' stale machine code.
    f = next(p for p in files if p.name == "single_track.py")
    f.write_text(f.read_text() + "\n# edited\n")
    assert runtime.source_hash(files) != before


def test_editing_the_report_keeps_the_cache():
    # The report is not among the hashed files, so a comment there costs no recompile.
    assert all(p.name != "report.py" for p in runtime.compiled_sources())


def test_cache_folder_in_use():
    # conftest configured the process as the artic command does.
    folder = runtime.configure()
    if folder == runtime.install_cache():  # the install's: numba's default folders
        assert runtime.install_cache_current() and not numba.config.CACHE_DIR
        return
    assert folder is None or numba.config.CACHE_DIR == str(folder)
    if folder is not None:
        assert folder.name == runtime.source_hash()


def test_user_setting_wins(monkeypatch):
    monkeypatch.setenv("NUMBA_CACHE_DIR", "/somewhere")
    assert runtime.configure() is None


def test_importing_reduced_sets_nothing():
    import subprocess
    import sys

    code = ("import numba; before = numba.config.CACHE_DIR; "
            "import artic.reduced, artic.validation.harness.loop, "
            "artic.validation.harness.reducedloop; "
            "print(numba.config.CACHE_DIR == before)")
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True, env=env)
    assert out.stdout.strip() == "True"


def test_old_folders_go_after_a_month(tmp_path, monkeypatch):
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    monkeypatch.setattr(runtime, "install_cache_current", lambda: False)  # sources edited
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    saved = numba.config.CACHE_DIR
    base = tmp_path / "artic" / "numba"
    recent, stale = base / "recent", base / "stale"
    for d in (recent, stale):
        d.mkdir(parents=True)
    old = time.time() - (runtime.STALE_DAYS + 1) * 86400
    os.utime(stale, (old, old))
    try:
        folder = runtime.configure()
    finally:
        numba.config.CACHE_DIR = saved
    assert folder == base / runtime.source_hash()
    assert recent.is_dir() and not stale.exists()  # another environment may use "recent"


def test_run_caches_follow_the_computing_code_only(tmp_path):
    from artic.validation.plumbing import fingerprint

    roots = {}
    for pkg in fingerprint.PACKAGES:
        roots[pkg] = tmp_path / pkg
        shutil.copytree(ROOT / pkg, roots[pkg],
                        ignore=shutil.ignore_patterns("__pycache__", "*.so"))
    before = fingerprint.code_hash(roots)
    assert before == fingerprint.code()
    report = roots["validation"] / "campaign" / "report.py"
    report.write_text(report.read_text() + "\n# a comment in the report\n")
    assert fingerprint.code_hash(roots) == before  # the runs stay reusable
    harness = roots["validation"] / "harness" / "loop.py"
    harness.write_text(harness.read_text() + "\n# an edit of the harness\n")
    assert fingerprint.code_hash(roots) != before  # the runs are recomputed


def test_the_install_clears_entries_of_other_sources_and_marks_its_cache(tmp_path, monkeypatch):
    from artic.reduced import precompile

    src = tmp_path / "reduced" / "model.py"
    cache = src.parent / "__pycache__"
    cache.mkdir(parents=True)
    src.write_text("x = 1\n")
    entries = [cache / "model.f-3.py311.nbi", cache / "model.f-3.py311.1.nbc"]
    pyc = cache / "model.cpython-311.pyc"
    for f in (*entries, pyc):
        f.write_bytes(b"old")
    (cache / runtime.INSTALL_MARK).write_text("other-sources\n")
    calls = []
    monkeypatch.setattr(runtime, "compiled_sources", lambda: [src])
    monkeypatch.setattr(precompile, "compile_all", lambda: calls.append(1))
    assert runtime.install_cache() == cache and not runtime.install_cache_current()
    runtime.fill_install_cache()
    # numba would keep a caller whose callee changed: entries of other sources go.
    assert calls == [1] and not any(f.exists() for f in entries) and pyc.exists()
    assert (cache / runtime.INSTALL_MARK).read_text().strip() == runtime.source_hash([src])
    assert runtime.install_cache_current()
    entries[0].write_bytes(b"today's")  # compiled from today's sources: kept
    runtime.fill_install_cache()
    assert entries[0].exists() and calls == [1, 1]
    src.write_text("x = 2\n")  # an edit: the command leaves the install's cache
    assert not runtime.install_cache_current()
