"""Where renders run when they leave this process: a Dask cluster
(``dask.distributed``), a local one on this machine by default, an existing one
when its scheduler's address is given.

Threads. Dask runs one task per worker *slot* (``dask worker --nthreads``);
each task renders with native threads of its own. Unless a thread count is
asked for, a task renders with ``max(1, cores // slots)`` threads, where
``cores`` are the CPUs of the worker's machine and ``slots`` the Dask slots of
all workers on that machine, so that workers × threads ≤ cores. The local
cluster has one slot per worker, so ``--workers N`` renders with
``cores // N`` threads each.
"""

from __future__ import annotations

import contextlib
import logging
import os
import socket
import threading
from dataclasses import dataclass

from .errors import ExternalError, InputError

__all__ = ["Cluster", "open_cluster", "check_cluster_options", "machine_cores", "task_threads", "worker_name", "run_calls",
           "CONNECT_TIMEOUT_S"]

CONNECT_TIMEOUT_S = 4.0
"""How long to try to reach a scheduler before giving up (exit 1)."""

WORKER_WAIT_S = 60.0
"""How long to wait for a reachable scheduler to have at least one worker."""


def machine_cores() -> int:
    """CPUs this process may run on (the affinity mask where there is one)."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


@dataclass(frozen=True)
class Cluster:
    """An open Dask client and what the tasks need to know about its workers.

    Attributes
    ----------
    client : distributed.Client
    address : str
        The scheduler's address (``tcp://HOST:PORT``).
    local : bool
        True for the cluster started on this machine.
    slots_by_host : dict of str to int
        Dask slots (task threads) of all workers per machine, when opened;
        :func:`task_threads` divides each machine's cores by it.
    """

    client: object
    address: str
    local: bool
    slots_by_host: dict

    @property
    def workers(self) -> int:
        return len(self.client.nthreads())

    def describe(self) -> str:
        where = "local cluster" if self.local else "Dask cluster"
        return f"{where} at {self.address}: {self.workers} workers, {sum(self.slots_by_host.values())} slots"


@contextlib.contextmanager
def open_cluster(scheduler: str | None = None, *, workers: int | None = None,
                 connect_timeout_s: float = CONNECT_TIMEOUT_S, worker_wait_s: float = WORKER_WAIT_S):
    """Open a Dask client for the duration of a ``with`` block.

    Parameters
    ----------
    scheduler : str, optional
        Address of an existing scheduler (``tcp://HOST:PORT``). Default: a
        local cluster of ``workers`` single-slot worker processes on
        127.0.0.1, closed again at the end of the block.
    workers : int, optional
        Workers of the local cluster (default: one per core). Not allowed with
        ``scheduler``, whose cluster has its own workers.

    Yields
    ------
    Cluster

    Raises
    ------
    InputError
        ``workers`` is not positive, or given with ``scheduler``; the address
        is malformed.
    ExternalError
        The scheduler cannot be reached within ``connect_timeout_s``, or has
        no worker within ``worker_wait_s``.
    """
    # distributed takes over a second to import; only cluster runs need it.
    import distributed  # noqa: PLC0415 - imported on use, see above

    check_cluster_options(scheduler, workers)
    with contextlib.ExitStack() as stack:
        if scheduler is None:
            # Its HTTP endpoints on a free loopback port: the usual 8787 clashes
            # with any other cluster on the machine.
            local = stack.enter_context(distributed.LocalCluster(
                n_workers=workers or machine_cores(), threads_per_worker=1, processes=True, host="127.0.0.1",
                dashboard_address="127.0.0.1:0", silence_logs=logging.ERROR))
            client = stack.enter_context(distributed.Client(local, set_as_default=False))
        else:
            client = stack.enter_context(_connect(distributed, scheduler, connect_timeout_s))
            try:
                client.wait_for_workers(1, timeout=worker_wait_s)
            except TimeoutError:
                raise ExternalError(f"the Dask scheduler at {scheduler} has no workers (waited "
                                    f"{worker_wait_s:g} s)") from None
        slots: dict[str, int] = {}
        for address, nthreads in client.nthreads().items():  # every worker (scheduler_info may list a few)
            host = distributed.comm.get_address_host(address)
            slots[host] = slots.get(host, 0) + int(nthreads)
        yield Cluster(client=client, address=client.scheduler.address, local=scheduler is None, slots_by_host=slots)


def check_cluster_options(scheduler: str | None, workers: int | None) -> None:
    """The options' own errors (exit 2), before any work starts."""
    if workers is not None and workers < 1:
        raise InputError("--workers", f"expected a positive integer, got {workers}")
    if scheduler is not None and workers is not None:
        raise InputError("--workers", "applies to the local cluster only; the cluster at --scheduler has its own "
                                      "workers")


def _connect(distributed, address: str, timeout_s: float):
    """A client of the scheduler at ``address``, or a one-line error."""
    if "://" not in address and ":" not in address:
        raise InputError("--scheduler", f"expected an address like tcp://HOST:PORT, got {address!r}")
    try:
        host, port = distributed.comm.get_address_host_port(distributed.comm.resolve_address(address))
    except (ValueError, TypeError) as error:
        raise InputError("--scheduler", f"{address!r} is not a scheduler address ({error})") from None
    # A plain TCP probe first: a refused or unanswered address fails at once,
    # where the client would retry until its timeout.
    try:
        socket.create_connection((host, port), timeout=timeout_s).close()
    except OSError as error:
        raise ExternalError(f"cannot reach the Dask scheduler at {address} ({error.strerror or error})") from None
    logging.getLogger("distributed.client").setLevel(logging.CRITICAL)
    # In a thread with a deadline: a server that accepts the connection but
    # never answers the handshake (not a scheduler) would hold the client.
    outcome: dict = {}

    def connect() -> None:
        try:
            outcome["client"] = distributed.Client(address, timeout=timeout_s, set_as_default=False)
        except Exception as error:  # noqa: BLE001 - whatever answers there is not a scheduler we can use
            outcome["error"] = error

    thread = threading.Thread(target=connect, daemon=True, name="lenscompare-connect")
    thread.start()
    thread.join(timeout_s + 1.0)
    if "client" in outcome:
        return outcome["client"]
    error = outcome.get("error")
    why = f"{error.__class__.__name__}: {str(error)[:120]}" if error else "no answer to the handshake"
    raise ExternalError(f"cannot reach the Dask scheduler at {address} within {timeout_s:g} s ({why})")


def task_threads(requested: int | None, slots_by_host: dict) -> int:
    """Native threads for the task running on this Dask worker (see the module
    docstring); ``requested`` wins when given."""
    if requested:
        return requested
    # distributed is imported already wherever a task runs.
    from distributed import get_worker  # noqa: PLC0415 - imported on use, see open_cluster
    from distributed.comm import get_address_host  # noqa: PLC0415 - as above

    worker = get_worker()
    slots = slots_by_host.get(get_address_host(worker.address)) or worker.state.nthreads
    return max(1, machine_cores() // max(1, slots))


def worker_name() -> str:
    """The Dask worker this runs on (its name, else its address), or this
    machine's name outside a worker."""
    from distributed import get_worker  # noqa: PLC0415 - imported on use, see open_cluster

    try:
        worker = get_worker()
    except ValueError:  # not on a worker
        return socket.gethostname()
    return str(worker.name if worker.name is not None else worker.address)


def run_calls(cluster: Cluster | None, fn, calls, *, threads: int | None, catch: tuple = (), progress=None) -> list:
    """``fn(*args, threads=T, **kwargs)`` for each ``(args, kwargs)`` in ``calls``.

    Without a cluster, here, one after another, with ``threads`` as given;
    with one, as tasks on its workers, each with :func:`task_threads`. Results
    come back in the order of ``calls``; an exception of a type in ``catch``
    is returned in place of its result, any other is raised. ``progress`` (a
    progress bar) advances once per call.
    """
    results = []
    if cluster is None:
        for args, kwargs in calls:
            try:
                results.append(fn(*args, threads=threads, **kwargs))
            except catch as error:
                results.append(error)
            if progress:
                progress.update(1)
        return results
    futures = [cluster.client.submit(_call_with_threads, fn, args, kwargs, threads, cluster.slots_by_host,
                                     pure=False) for args, kwargs in calls]
    for future in futures:
        try:
            results.append(future.result())
        except catch as error:
            results.append(error)
        if progress:
            progress.update(1)
    return results


def _call_with_threads(fn, args, kwargs, threads, slots_by_host):
    return fn(*args, threads=task_threads(threads, slots_by_host), **kwargs)
