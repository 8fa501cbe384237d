"""Docking runs in supervised worker processes: nothing a controller does ends the benchmark.

A controller is the user's code, and runs in the benchmark's process tree. In
the run itself (:func:`artic.validation.docking.run.drive`) an exception, a
``sys.exit`` or a non-finite command from ``reset`` or ``command`` is a failed
run with its reason. What cannot be caught there is caught here:

- a controller that ends its process (``os._exit``, a crash in compiled code,
  a signal): the worker dies, its run becomes a failed row naming the exit
  code or the signal, a new worker takes the next run;
- a controller that hangs: every call of ``reset`` or ``command`` stamps the
  worker's heartbeat (:func:`calling`); a call longer than :data:`CALL_DEADLINE`
  gets its worker killed, and its run is a failed row saying which call hung.

:func:`supervised` runs the tasks on ``jobs`` long-lived worker processes
(forked from the benchmark's, so a controller found on ``sys.path`` there is
found in them), one run at a time each, and yields each task's result as it
comes, or the row :func:`failed_row` makes of a run that ended its worker. A
worker is started per ``jobs``, not per run: the supervision costs a pipe
message per run, as a process pool's does.

On a Dask cluster, whose worker processes may not start others the
multiprocessing way (they are daemons), :func:`in_child` runs each run in a
forked child of the task's worker: a controller that ends its process ends the
child, and its run is a failed row naming the exit code, as here, where the
cluster would otherwise lose the worker, retry the run on three more and report
``KilledWorker``.
"""

from __future__ import annotations

import contextlib
import multiprocessing as mp
import os
import pickle
import signal
import time
from collections import deque
from collections.abc import Callable, Iterator, Sequence
from multiprocessing.connection import wait

from artic.mjcf.errors import one_line

CALL_DEADLINE = 60.0
"""Longest a controller's ``reset`` or one ``command`` may take before its run is ended as
hung [s]: 600 sample periods, far beyond what the real-time criterion fails (a controller
that slow has failed it long before), and room for a first call that compiles (numba, an
MPC's solver) on a loaded machine."""

POLL = 0.2
"""How often the supervisor looks at the workers' heartbeats [s]."""

CALLS = ("reset()", "command()")
"""The controller's calls the heartbeat names."""

_heartbeat = None
"""This worker's heartbeat (three shared doubles): when its controller call started
(``time.monotonic``, 0 between calls), which call (an index of :data:`CALLS`) and the
run's time then [s]; ``None`` outside a supervised worker."""


def calling(what: str, t: float = 0.0) -> contextlib.AbstractContextManager[None]:
    """Stamp the heartbeat while the controller's ``what`` runs (nothing outside a worker).

    Parameters
    ----------
    what : str
        One of :data:`CALLS`.
    t : float
        The run's time [s], for the message of a hang.
    """
    hb = _heartbeat
    if hb is None:  # not in a worker: a run in this process, a Gymnasium environment's
        return _UNWATCHED
    return _stamping(hb, what, t)


_UNWATCHED = contextlib.nullcontext()


@contextlib.contextmanager
def _stamping(hb, what: str, t: float) -> Iterator[None]:
    hb[1], hb[2] = float(CALLS.index(what)), float(t)
    hb[0] = time.monotonic()
    try:
        yield
    finally:
        hb[0] = 0.0


def _worker(conn, hb, parent: int) -> None:
    """A worker's loop: receive ``(fn, args)``, send back ``("ok", result)`` or the error."""
    global _heartbeat
    from artic.validation.plumbing.workers import init_worker

    init_worker(parent)
    _heartbeat = hb
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # the supervisor ends the workers
    while True:
        try:
            job = conn.recv()
        except (EOFError, OSError):
            return
        if job is None:
            return
        fn, args = job
        try:
            out = ("ok", fn(*args))
        except KeyboardInterrupt:
            return
        except BaseException as exc:  # noqa: BLE001 - reported as the run's failure
            out = ("error", one_line(f"{type(exc).__name__}: {exc}"))
        hb[0] = 0.0
        try:
            conn.send(out)
        except (OSError, ValueError):
            return


class _Slot:
    """One worker process and the task it runs."""

    def __init__(self, ctx) -> None:
        self.conn, child = ctx.Pipe()
        self.hb = ctx.Array("d", 3, lock=False)
        self.proc = ctx.Process(target=_worker, args=(child, self.hb, os.getpid()),
                                name="artic-dock-worker", daemon=True)
        self.proc.start()
        child.close()
        self.task: tuple | None = None

    def stop(self, kill: bool = False) -> None:
        if kill and self.proc.is_alive():
            self.proc.kill()
        else:
            with contextlib.suppress(OSError, ValueError):
                self.conn.send(None)
        self.proc.join(timeout=5.0)
        if self.proc.is_alive():
            self.proc.kill()
            self.proc.join()
        self.conn.close()


def _ended(code: int | None) -> str:
    """How a worker ended, for the row."""
    if code is None:
        return "it ended"
    if code < 0:
        try:
            return f"killed by signal {signal.Signals(-code).name}"
        except ValueError:
            return f"killed by signal {-code}"
    return f"exit code {code}"


ENDED = "controller ended the run's process"
"""How the failure of a run that ended its worker process begins."""


def _ended_reason(code: int | None) -> str:
    return f"{ENDED} ({_ended(code)}): a sys.exit, os._exit or crash outside Python"


class ChildEnded(RuntimeError):
    """The forked child of :func:`in_child` ended before it answered; the message says how."""


def in_child(fn: Callable, *args: object) -> object:
    """``fn(*args)`` in a forked child of this process; its result, or its exception's line.

    Raises
    ------
    ChildEnded
        The child ended without an answer (``os._exit``, a signal): the message names the
        exit code or the signal, as :func:`supervised`'s failed rows do.
    RuntimeError
        ``fn`` raised: its type and message, on one line.
    """
    if not hasattr(os, "fork"):  # pragma: no cover - no fork on this platform: run it here
        return fn(*args)
    r, w = os.pipe()
    pid = os.fork()
    if pid == 0:  # the child: answer through the pipe, then end without the parent's cleanup
        code = 0
        try:
            os.close(r)
            try:
                out = ("ok", fn(*args))
            except BaseException as exc:  # noqa: BLE001 - reported to the parent
                out = ("error", one_line(f"{type(exc).__name__}: {exc}"))
            try:
                data = pickle.dumps(out)
            except Exception as exc:  # noqa: BLE001 - an answer that cannot travel is one
                data = pickle.dumps(("error", "its result cannot be sent back ("
                                     + one_line(f"{type(exc).__name__}: {exc}") + ")"))
            with os.fdopen(w, "wb") as f:
                f.write(data)
        except BaseException:  # noqa: BLE001 - the parent reports the missing answer
            code = 70
        finally:
            os._exit(code)
    os.close(w)
    with os.fdopen(r, "rb") as f:
        data = f.read()
    _, status = os.waitpid(pid, 0)
    if not data:
        raise ChildEnded(_ended_reason(os.waitstatus_to_exitcode(status)))
    kind, value = pickle.loads(data)
    if kind != "ok":
        raise RuntimeError(value)
    return value


def supervised(fn: Callable, tasks: Sequence[tuple[object, tuple]], jobs: int,
               failed: Callable[[object, tuple, str], object],
               deadline: float | None = None) -> Iterator[tuple[object, object]]:
    """``(key, fn(*args))`` for each task as it finishes, on supervised workers.

    Parameters
    ----------
    fn : callable
        The task, a module-level function (one docking run).
    tasks : sequence of (key, args)
        What to run.
    jobs : int
        Worker processes.
    failed : callable
        ``failed(key, args, reason)``: the result of a task whose worker died or hung,
        or whose ``fn`` raised.
    deadline : float, optional
        Longest controller call [s]; :data:`CALL_DEADLINE` by default.
    """
    deadline = CALL_DEADLINE if deadline is None else float(deadline)
    ctx = mp.get_context("fork") if "fork" in mp.get_all_start_methods() else mp.get_context()
    pending = deque(tasks)
    slots: list[_Slot] = []
    try:
        slots = [_Slot(ctx) for _ in range(max(1, min(jobs, len(pending))))]
        while pending or any(s.task is not None for s in slots):
            for s in slots:
                if s.task is None and pending:
                    s.task = pending.popleft()
                    with contextlib.suppress(OSError):  # a dead worker is found below
                        s.conn.send((fn, s.task[1]))
            busy = [s for s in slots if s.task is not None]
            ready = wait([s.conn for s in busy] + [s.proc.sentinel for s in busy], timeout=POLL)
            for k, s in enumerate(slots):
                if s.task is None:
                    continue
                key, args = s.task
                reason = None
                if s.conn in ready or s.proc.sentinel in ready:
                    try:
                        if s.conn.poll():
                            status, value = s.conn.recv()
                            s.task = None
                            yield key, (value if status == "ok" else failed(key, args, value))
                            continue
                    except (EOFError, OSError):
                        pass
                    if not s.proc.is_alive() or s.proc.sentinel in ready:
                        s.proc.join(timeout=1.0)
                        reason = _ended_reason(s.proc.exitcode)
                started = s.hb[0]
                if reason is None and started > 0.0 and time.monotonic() - started > deadline:
                    call = CALLS[int(s.hb[1])]
                    when = f" at t = {s.hb[2]:.1f} s" if call == "command()" else ""
                    reason = (f"controller hang: {call}{when} did not return within "
                              f"{deadline:g} s")
                if reason is not None:
                    s.task = None
                    s.stop(kill=True)
                    slots[k] = _Slot(ctx)
                    yield key, failed(key, args, reason)
    finally:
        for s in slots:
            s.stop(kill=s.task is not None)
