"""One malloc arena for the campaign's command (artic.validation.plumbing.heap)."""

from __future__ import annotations

import subprocess
import sys
import textwrap

import pytest

from artic.validation.plumbing import heap

# Threads that allocate through glibc's malloc; malloc_info then lists the
# process's arenas as <heap nr="..."> entries. Run in a fresh process: the
# setting is the process's, and arenas made before it stay.
_PROBE = textwrap.dedent("""
    import ctypes, sys, threading, tempfile
    from artic.validation.plumbing import heap
    if sys.argv[1] == "one":
        assert heap.single_arena()
    libc = ctypes.CDLL("libc.so.6")
    libc.malloc.restype = ctypes.c_void_p
    libc.fopen.restype = ctypes.c_void_p
    gate = threading.Barrier(4)
    def work():
        gate.wait()  # all four allocate while the others are alive
        blocks = [libc.malloc(4096) for _ in range(100)]
        gate.wait()
    threads = [threading.Thread(target=work) for _ in range(4)]
    for t in threads: t.start()
    for t in threads: t.join()
    path = tempfile.mktemp()
    fp = libc.fopen(path.encode(), b"w")
    libc.malloc_info(0, ctypes.c_void_p(fp))
    libc.fclose(ctypes.c_void_p(fp))
    print(open(path).read().count("<heap nr="))
""")


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="glibc's mallopt: Linux only")
def test_single_arena_keeps_threads_in_one_arena():
    def arenas(mode: str) -> int:
        out = subprocess.run([sys.executable, "-c", _PROBE, mode], capture_output=True,
                             text=True, check=True)
        return int(out.stdout)

    # glibc's default gives threads their own arenas (up to 8 per core, so at
    # least two here); with the setting every thread shares the main arena.
    assert arenas("default") > 1
    assert arenas("one") == 1


def test_single_arena_is_a_no_op_elsewhere(monkeypatch):
    monkeypatch.setattr(heap.sys, "platform", "darwin")
    assert heap.single_arena() is False
