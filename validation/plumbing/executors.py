"""Where the campaign's independent runs execute: this machine, or a Dask cluster.

The campaign's expensive stages are many independent runs: the synthetic
manoeuvres on the plant, and every (log, model) pair of the validation; so
are a docking robustness sweep's runs (:mod:`artic.validation.docking.sweep`).
They are submitted to a ``concurrent.futures.Executor``:

- ``local`` (the default): processes for generation, threads for validation
  (the plant's compiled closed loop runs a whole log without the GIL);
- ``dask``: a Dask cluster's executor, for parameter studies that outgrow one
  machine. Without a scheduler address, a local cluster with one worker
  process per job is started for the run. Install the extra with
  ``pip install "artic[distributed]"``.

Each run is a pure function of its inputs (a manoeuvre and a seed, or a log,
a vehicle, a model and a gain) that returns its result to the caller, which
writes the files. Workers therefore need no shared file system, and the
results do not depend on where or in which order the runs execute.

**A cluster must be trusted.** Dask sends results back pickled, and
unpickling runs code: whoever controls a worker or the scheduler can run code
in the process that started the campaign. Use a cluster that only you and
people you trust can join, and reach it over ``tls://`` (:class:`DaskOptions`)
when the network between you is not yours. What artic itself takes from a
result is limited: every file name, folder and cache key comes from what the
client submitted (the manoeuvre, the log's name, the model), never from the
returned result, so a worker cannot direct a write or a deletion elsewhere.

An unreachable scheduler is reported after :attr:`DaskOptions.timeout`
seconds in one line, instead of a traceback or a wait without end.
"""

from __future__ import annotations

import contextlib
import importlib.util
from collections.abc import Iterator
from concurrent.futures import Executor
from dataclasses import dataclass
from pathlib import Path

from artic.mjcf.errors import UserError
from artic.validation.plumbing.runtime import mujoco_settings

NO_DISTRIBUTED = ("the dask executor needs the 'distributed' package: "
                  'pip install "artic[distributed]"')
"""The one line for ``--executor dask`` where ``distributed`` is not installed."""

EXECUTORS = ("local", "dask")


@dataclass(frozen=True)
class DaskOptions:
    """How to reach a Dask scheduler.

    Parameters
    ----------
    timeout : float
        Seconds to wait for the scheduler before giving up.
    tls_ca_file, tls_cert, tls_key : Path, optional
        With a ``tls://`` address: the CA certificate that signs the cluster's
        certificates, and this client's certificate and private key (PEM);
        all three are needed, and encryption is then required.
    """

    timeout: float = 10.0
    tls_ca_file: Path | None = None
    tls_cert: Path | None = None
    tls_key: Path | None = None

    @property
    def tls(self) -> tuple[Path | None, Path | None, Path | None]:
        """The three TLS files."""
        return (self.tls_ca_file, self.tls_cert, self.tls_key)

    def check(self, kind: str, address: str | None) -> None:
        """Refuse options that do not fit the address (one-line ``ValueError``)."""
        given = [p for p in self.tls if p is not None]
        scheme = (address or "").split("://", 1)[0] if address and "://" in address else "tcp"
        if address and scheme not in ("tcp", "tls"):
            raise UserError(f"--scheduler {address}: expected tcp://HOST:PORT or "
                             "tls://HOST:PORT")
        if scheme == "tls" and len(given) != 3:
            raise UserError(f"--scheduler {address}: a tls:// scheduler needs --tls-ca-file, "
                             "--tls-cert and --tls-key")
        if given and scheme != "tls":
            raise UserError("--tls-ca-file, --tls-cert and --tls-key need a tls:// "
                             "--scheduler address")
        if address and kind != "dask":
            raise UserError("--scheduler needs --executor dask")
        for opt, p in zip(("--tls-ca-file", "--tls-cert", "--tls-key"), self.tls, strict=True):
            if p is not None and not Path(p).is_file():
                raise UserError(f"{opt} {p}: no such file")
        if kind == "dask" and importlib.util.find_spec("distributed") is None:
            raise UserError(NO_DISTRIBUTED)

    def security(self):
        """A ``distributed.Security`` for the TLS files, or ``None`` without them."""
        if self.tls_ca_file is None:
            return None
        from distributed.security import Security

        return Security(tls_ca_file=str(self.tls_ca_file),
                        tls_client_cert=str(self.tls_cert), tls_client_key=str(self.tls_key),
                        require_encryption=True)


@contextlib.contextmanager
def cluster_executor(kind: str = "local", jobs: int = 1, address: str | None = None,
                     dask: DaskOptions | None = None) -> Iterator[Executor | None]:
    """An executor for the campaign's runs, closed on exit.

    Parameters
    ----------
    kind : str
        ``"local"`` yields ``None`` (each stage uses its own local pool) or
        ``"dask"``.
    jobs : int
        Worker processes of a local Dask cluster.
    address : str, optional
        Scheduler of a running Dask cluster (``tcp://host:8786``, ``tls://host:8786``).
    dask : DaskOptions, optional
        Timeout and TLS files for ``address``.

    Raises
    ------
    ValueError
        For an unknown kind, ``dask`` without the ``distributed`` package,
        options that do not fit the address, or a scheduler not reached within
        the timeout.
    """
    dask = dask or DaskOptions()
    if kind not in EXECUTORS:
        raise UserError(f"executor {kind!r}: expected one of {', '.join(EXECUTORS)}")
    dask.check(kind, address)
    if kind == "local":
        yield None
        return
    try:
        from distributed import Client, LocalCluster
    except ImportError as exc:
        raise UserError(NO_DISTRIBUTED) from exc
    cluster = None if address else LocalCluster(n_workers=max(1, jobs), threads_per_worker=1,
                                                processes=True, dashboard_address=None)
    try:
        client = Client(address or cluster, timeout=dask.timeout, security=dask.security())
    except (OSError, TimeoutError) as exc:
        if cluster is not None:
            cluster.close()
        raise UserError(f"--scheduler {address or 'local'}: not reached within "
                         f"{dask.timeout:g} s ({type(exc).__name__}); check the address, or "
                         "raise --scheduler-timeout") from None
    try:
        # no MUJOCO_LOG.TXT in the workers' folders, and no step timers
        client.run(mujoco_settings)
    except Exception:  # noqa: BLE001 - a worker without mujoco, or gone: nothing to route
        pass
    try:
        yield client.get_executor()
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
