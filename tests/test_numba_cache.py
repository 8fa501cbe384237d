"""numba's cache of artic's compiled functions follows every source file."""

from __future__ import annotations

import shutil
from pathlib import Path

import numba

from reduced import _cache

SRC = Path(__file__).resolve().parents[1] / "src"


def test_editing_any_module_moves_the_cache(tmp_path):
    for pkg in _cache.PACKAGES:
        shutil.copytree(SRC / pkg, tmp_path / pkg, ignore=shutil.ignore_patterns("__pycache__"))
    before = _cache.source_hash(tmp_path)
    assert before == _cache.source_hash(SRC)
    # A callee's module: numba alone would keep its callers' stale machine code.
    f = tmp_path / "reduced" / "single_track.py"
    f.write_text(f.read_text() + "\n# edited\n")
    assert _cache.source_hash(tmp_path) != before


def test_cache_folder_in_use():
    assert _cache.CACHE_DIR is None or numba.config.CACHE_DIR == str(_cache.CACHE_DIR)
    if _cache.CACHE_DIR is not None:
        assert _cache.CACHE_DIR.name == _cache.source_hash()


def test_user_setting_wins(monkeypatch):
    monkeypatch.setenv("NUMBA_CACHE_DIR", "/somewhere")
    assert _cache.configure() is None


def test_old_folders_go_after_a_month(tmp_path, monkeypatch):
    import os
    import time

    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    saved = numba.config.CACHE_DIR
    base = tmp_path / "artic" / "numba"
    recent, stale = base / "recent", base / "stale"
    for d in (recent, stale):
        d.mkdir(parents=True)
    old = time.time() - (_cache.STALE_DAYS + 1) * 86400
    os.utime(stale, (old, old))
    try:
        folder = _cache.configure()
    finally:
        numba.config.CACHE_DIR = saved
    assert folder == base / _cache.source_hash()
    assert recent.is_dir() and not stale.exists()  # another environment may use "recent"
