"""The worker processes of artic.validation.plumbing.workers: forked, fresh, or none."""

from __future__ import annotations

import contextlib
import os

import pytest

from artic.validation.plumbing import workers
from artic.validation.plumbing.workers import completed


def _where(x: int) -> tuple[int, int, bool]:
    """The task's value, the process that ran it, and whether it has this process's mark."""
    return x * x, os.getpid(), hasattr(workers, "_test_mark")


@pytest.fixture(autouse=True)
def _mark(monkeypatch):
    # a mark in this process's memory: a forked worker has it, a fresh one does not
    monkeypatch.setattr(workers, "_test_mark", True, raising=False)


def _run(jobs: int, fresh: bool) -> dict:
    with contextlib.closing(completed(_where, [(k, (k,)) for k in range(3)], jobs,
                                      fresh=fresh)) as done:
        return dict(done)


def test_one_job_runs_in_this_process():
    out = _run(1, fresh=False)
    assert {k: v[0] for k, v in out.items()} == {0: 0, 1: 1, 2: 4}
    assert {v[1] for v in out.values()} == {os.getpid()}


def test_fresh_workers_start_anew_even_for_one_job():
    # spawned, not forked: nothing of this process's memory is in them
    out = _run(1, fresh=True)
    assert {k: v[0] for k, v in out.items()} == {0: 0, 1: 1, 2: 4}
    assert os.getpid() not in {v[1] for v in out.values()}
    assert not any(v[2] for v in out.values())


def test_forked_workers_share_this_process_memory():
    out = _run(2, fresh=False)
    assert os.getpid() not in {v[1] for v in out.values()}
    assert all(v[2] for v in out.values())  # forked: the mark came along
