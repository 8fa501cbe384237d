"""Where the campaign's independent runs execute: this machine, or a Dask cluster.

The campaign's expensive stages are many independent runs: the synthetic
manoeuvres on the plant, and every (log, model) pair of the validation. They
are submitted to a ``concurrent.futures.Executor``:

- ``local`` (the default): processes for generation, threads for validation
  (the compiled tyre callback releases the GIL inside MuJoCo's step);
- ``dask``: a Dask cluster's executor, for parameter studies that outgrow one
  machine. Without a scheduler address, a local cluster with one worker
  process per job is started for the run. Install the extra with
  ``pip install "artic[distributed]"``.

Each run is a pure function of its inputs (a manoeuvre and a seed, or a log,
a vehicle, a model and a gain) that returns its result to the caller, which
writes the files. Workers therefore need no shared file system, and the
results do not depend on where or in which order the runs execute.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from concurrent.futures import Executor

EXECUTORS = ("local", "dask")


@contextlib.contextmanager
def cluster_executor(kind: str = "local", jobs: int = 1,
                     address: str | None = None) -> Iterator[Executor | None]:
    """An executor for the campaign's runs, closed on exit.

    Parameters
    ----------
    kind : str
        ``"local"`` yields ``None`` (each stage uses its own local pool) or
        ``"dask"``.
    jobs : int
        Worker processes of a local Dask cluster.
    address : str, optional
        Scheduler of a running Dask cluster (``tcp://host:8786``).

    Raises
    ------
    ValueError
        For an unknown kind, or ``dask`` without the ``distributed`` package.
    """
    if kind not in EXECUTORS:
        raise ValueError(f"executor {kind!r}: expected one of {', '.join(EXECUTORS)}")
    if kind == "local":
        if address:
            raise ValueError("--scheduler needs --executor dask")
        yield None
        return
    try:
        from distributed import Client, LocalCluster
    except ImportError as exc:
        raise ValueError("the dask executor needs the 'distributed' package: "
                         'pip install "artic[distributed]"') from exc
    cluster = None if address else LocalCluster(n_workers=max(1, jobs), threads_per_worker=1,
                                                processes=True, dashboard_address=None)
    client = Client(address or cluster)
    try:
        yield client.get_executor()
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
