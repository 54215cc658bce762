"""Where independent runs go in parallel: a Dask client on a local cluster of worker processes,
or on a running scheduler. Sweeps (`hybridtrack.sweep`) and fields (`hybridtrack.fields`) use it.

Worker processes, one thread each: a run holds the GIL in the reference loop and in pandas, so
threads would take turns; processes use every core. (A field in one process runs its collectors on
threads all the same: there the compiled kernel, a third of a run, lets go of the GIL, and the
collectors share one computation of their sky; `hybridtrack.fields`.)
"""

from __future__ import annotations

import contextlib
import os
import signal
import threading
import time
from collections.abc import Iterable, Iterator

from . import params
from .errors import HybridtrackError

__all__ = ["dask_client", "check_where", "close", "holding_interrupts", "cores", "finished", "lost", "WorkersGone", "MAX_WORKERS",
           "WORKERS_GONE_AFTER"]

#: The most worker processes a local cluster is asked for.
MAX_WORKERS = 1024


def cores() -> int:
    """The cores this process may run on (its CPU affinity where the system has one)."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - not Linux
        return os.cpu_count() or 1


def check_where(scheduler: str | None, workers: int | None, threads: int | None = None) -> None:
    """Refuse a `scheduler` that is not an address (an empty one is an unset ``$VAR``, not a local
    cluster) or that nothing answers at (`_refuse_unreachable`), a scheduler beside `workers`, a
    count of `workers` out of range, and `threads` of this process beside either: the checks of
    `dask_client` (and of a field's threads), for callers that make them before their work starts
    (a field's command had made its weather and started its progress bar before it found that no
    scheduler answered)."""
    if scheduler is not None and (not isinstance(scheduler, str) or not scheduler.strip()):
        raise HybridtrackError(f"scheduler must be an address such as 'tcp://host:8786', got {scheduler!r:.60}")
    if scheduler and workers is not None:
        raise HybridtrackError("give either --scheduler or --workers, not both")
    if workers is not None:
        params.whole(workers, "workers", 1, MAX_WORKERS)
    if threads is not None and (scheduler is not None or workers is not None):
        raise HybridtrackError("threads (--threads) run the collectors in this process; workers or a scheduler "
                               "(--workers, --scheduler) send them to Dask: give one or the other")
    if scheduler:  # last: the one check that waits on the network
        _refuse_unreachable(scheduler)


#: Seconds a scheduler has to answer: Dask's own connect timeout (10 s) bounds the connection, not
#: the handshake after it, so a port that accepts and never answers (another service) had hung.
ANSWER_SECONDS = 20.0


def _connected(client_type, scheduler: str):
    """A client of the scheduler at `scheduler`, or a refusal within `ANSWER_SECONDS`: the client
    is made on a thread of its own, and left there if nothing answers. A port that speaks another
    protocol (an HTTP proxy's 400) had been read as a message of 3 EiB (numpy's MemoryError)."""
    made: dict = {}

    def connect():
        client = client_type.__new__(client_type)  # kept on failure, to be closed (`_abandoned`)
        try:
            client_type.__init__(client, scheduler, timeout="10s", set_as_default=False)
            made["client"] = client
        # TypeError: distributed's TLS and UCX connectors refuse to start without their setup
        except (OSError, TimeoutError, ValueError, TypeError, MemoryError) as exc:
            made["error"] = exc
            _abandoned(client)

    thread = threading.Thread(target=connect, name="hybridtrack-dask-connect", daemon=True)
    thread.start()
    thread.join(ANSWER_SECONDS)
    if "client" in made:
        return made["client"]
    error = made.get("error")
    why = (f"nothing answered as a scheduler in {ANSWER_SECONDS:g} s" if error is None else
           "something answers there, but not as a Dask scheduler (its reply read as a message too large to hold)"
           if isinstance(error, MemoryError) else f"{error}")
    raise HybridtrackError(f"cannot reach the Dask scheduler at {scheduler}: {why}")


def _abandoned(client) -> None:
    """Close a client whose connection failed, for a moment, and mark it closed: its finaliser had
    waited 20 s for the scheduler that never answered, then printed a TimeoutError's traceback
    as the process ended."""
    with contextlib.suppress(Exception):
        client.close(timeout=1)
    client.status = "closed"


def dask_client(scheduler: str | None, workers: int | None, *, what: str = "parallel runs"):
    """A Dask client and the local cluster it runs on (None on a given `scheduler`).

    Parameters
    ----------
    scheduler : str or None
        Address of a running Dask scheduler (``tcp://host:8786``); None for a local cluster.
    workers : int or None
        Worker processes of the local cluster (one thread each); the machine's cores when None.
    what : str
        What needs Dask, for the message when it is missing.

    Notes
    -----
    The client is not made Dask's default (``set_as_default=False``): the runs are given to it by
    name, and Dask's global scheduler setting stays the caller's. As the default, an open client
    had set it to ``dask.distributed`` for the whole process, and one not closed in turn left it
    so: the next field's save (xarray's netCDF writer asks Dask for its scheduler) then failed with
    "Requested dask.distributed scheduler but no Client active".
    """
    try:
        from dask.distributed import Client, LocalCluster
    except ImportError:  # pragma: no cover - a declared dependency
        raise HybridtrackError(f"{what} need dask.distributed: pip install 'dask[distributed]'") from None
    check_where(scheduler, workers)
    if scheduler:
        client = _connected(Client, scheduler)
        _refuse_no_workers(client, scheduler)
        return client, None
    count = params.whole(workers, "workers", 1, MAX_WORKERS) if workers is not None else cores()
    quieted = _quiet_worker_processes()
    try:
        # the dashboard on a free port: None still takes 8787, and a second cluster on this machine
        # (another sweep, a test run) warned on stderr that the port was in use
        with _workers_starting() as held:
            cluster = LocalCluster(n_workers=count, threads_per_worker=1, processes=True, dashboard_address=":0",
                                   silence_logs=50)  # a failed task is reported by its result, not logged
        cluster.hybridtrack_logging = quieted  # put back when it closes (`close`)
    except BaseException as exc:
        _restore_worker_logging(quieted)
        if not isinstance(exc, RuntimeError):
            raise
        if held:  # the workers were ended by the SIGTERM held meanwhile: end as it asks, not as a failure
            signal.raise_signal(signal.SIGTERM)
        raise HybridtrackError(f"cannot start {count} local Dask workers for {what} ({' '.join(str(exc).split())[:120]}); "
                               "workers are new processes that import the running script again, so a script "
                               "must start its run under `if __name__ == \"__main__\":`") from None
    if held:  # a SIGTERM came while the workers started: stop them, then end as it asks
        close_cluster(cluster)
        signal.raise_signal(signal.SIGTERM)
    return Client(cluster, set_as_default=False), cluster


#: Seconds a scheduler's address is given to answer (`_refuse_unreachable`), as the client is.
CONNECT_TIMEOUT = 10.0
#: The address schemes a scheduler is reached by (``inproc``: a cluster in this very process).
SCHEMES = ("tcp", "tls", "ucx", "ws", "wss", "inproc")


def _refuse_unreachable(scheduler: str) -> None:
    """Refuse an address that is none (``tcp://:abc``, ``file://x``), naming the form, and a TCP
    address nothing answers at or an in-process one no cluster of this process has, before a Dask
    client is made for it: a client whose start failed was left to Python's collector, whose
    close of it waited 20 s at the end of the command and then printed a traceback under the
    one-line refusal."""
    import socket

    from distributed.comm.addressing import parse_address, parse_host_port

    form = "a Dask scheduler's address is such as 'tcp://host:8786'"
    try:
        scheme, location = parse_address(scheduler.strip())
        host, port = parse_host_port(location, 8786) if scheme in ("tcp", "tls") else ("", None)
        if scheme in ("tcp", "tls") and not host:
            raise ValueError("no host")
    except (ValueError, TypeError):  # the parser's own words are about Python ("invalid literal for int()")
        raise HybridtrackError(f"scheduler {scheduler!r} is not an address: {form}") from None
    if scheme not in SCHEMES:
        raise HybridtrackError(f"scheduler {scheduler!r}: {form}; {scheme}:// is not one a scheduler is reached by")
    if scheme == "inproc":
        from distributed.comm.inproc import global_manager

        try:
            listening = global_manager.get_listener_for(location) is not None
        except ValueError:
            raise HybridtrackError(f"scheduler {scheduler!r} is not an address: {form}") from None
        if not listening:
            raise HybridtrackError(f"cannot reach the Dask scheduler at {scheduler}: no cluster of this process "
                                   "listens there")
    if scheme != "tcp":  # TLS and the others need their own setup: the client's start judges them
        return
    try:
        socket.create_connection((host, port), timeout=CONNECT_TIMEOUT).close()
    except OSError as exc:
        raise HybridtrackError(f"cannot reach the Dask scheduler at {scheduler}: {exc}") from None


#: Seconds a running scheduler is given to have a worker: its runs would wait for one forever.
WORKER_WAIT = 10.0


def _refuse_no_workers(client, scheduler: str) -> None:
    """Refuse a scheduler with no worker after `WORKER_WAIT` seconds (a sweep sat at 0 runs)."""
    try:
        client.wait_for_workers(1, timeout=WORKER_WAIT)
    except (TimeoutError, OSError):
        client.close()
        raise HybridtrackError(f"the Dask scheduler at {scheduler} has no workers (waited {WORKER_WAIT:g} s): "
                               f"start some with `dask worker {scheduler}`") from None


#: Seconds the runs left wait, mid-run, at a scheduler that has had no worker all that time before
#: they are given up: distributed queues them for a worker that may never come (a remote worker
#: killed, its machine gone), and a local cluster's nanny restarts a dead worker within seconds.
WORKERS_GONE_AFTER = 60.0
#: Seconds between looks at the futures and the scheduler's workers while none is done.
_LOOK_EVERY = 0.2


class WorkersGone(HybridtrackError):
    """The scheduler has had no worker for `WORKERS_GONE_AFTER` seconds while runs were left."""


def finished(client, futures: Iterable) -> Iterator[tuple]:
    """``(future, result, error)`` for each of `futures` as it is done: its result, or the
    exception it raised or was cancelled with (the other None). Raise `WorkersGone` when the
    scheduler has had no worker for `WORKERS_GONE_AFTER` seconds while some are left.

    distributed's ``as_completed`` alone waits for ever there, and a future it calls done can
    still hang: its result lives on the worker that made it, and when that worker leaves before
    it is fetched, ``Future.result`` waits for the task to run again on a worker that may never
    come. So each result is fetched as the future is done (``with_results``), within the wait.
    A task must not return an exception's (type, value, traceback): distributed gives an error so."""
    from dask.distributed import as_completed

    done = as_completed(futures, loop=client.loop, with_results=True, raise_errors=False)  # not the default client
    alone_since = None
    while not done.is_empty():
        if done.has_ready():
            for future, result in done.next_batch(block=False):
                yield future, *_outcome(result)
            alone_since = None
            continue
        if _has_workers(client):
            alone_since = None
        elif alone_since is None:
            alone_since = time.monotonic()
        elif time.monotonic() - alone_since >= WORKERS_GONE_AFTER:
            raise WorkersGone(f"the Dask scheduler has had no worker for {WORKERS_GONE_AFTER:g} s, with "
                              f"{done.count()} tasks left")
        time.sleep(_LOOK_EVERY)


def _outcome(result) -> tuple:
    """``(result, None)``, or ``(None, error)`` for what ``as_completed(raise_errors=False)`` gives
    in its place: the cancellation itself, or an error's (type, value, traceback)."""
    if isinstance(result, BaseException):
        return None, result
    if isinstance(result, tuple) and len(result) == 3 and isinstance(result[1], BaseException):
        return None, result[1].with_traceback(result[2])
    return result, None


def lost(error: BaseException) -> bool:
    """Whether a task's `error` is its loss on Dask (cancelled, or its worker killed too often),
    not an error of its own."""
    from concurrent.futures import CancelledError

    from dask.distributed import KilledWorker

    return isinstance(error, (CancelledError, KilledWorker))


def _has_workers(client) -> bool:
    try:
        return bool(client.nthreads())
    except (OSError, TimeoutError):  # the scheduler itself is gone: no worker will take the runs
        return False


@contextlib.contextmanager
def _workers_starting() -> Iterator[list]:
    """While worker processes start: ignore Ctrl-C, so that they start deaf to it, and hold a
    SIGTERM until they are up (the list it yields names the signals held).

    A terminal sends SIGINT to the whole process group: each worker printed distributed's
    KeyboardInterrupt traceback while this process, which the user interrupted, stopped them
    anyway. An ignored signal stays ignored in a child, so SIGINT is ignored while the workers
    start, and a Ctrl-C in those seconds is lost: one after them stops the command. (Blocking it
    instead, to deliver it once they are up, was tried: the workers do not keep a blocked mask,
    and numpy's BLAS threads take a process's signal and drop it.) A SIGTERM then is held and
    acted on by the caller once the cluster can be closed: raised amid its start, it left
    distributed's tracebacks of a half-started cluster. A caught signal is the default again in a
    child, so the workers still end on SIGTERM, quietly. Only the main thread may set a handler;
    elsewhere the workers start as they would."""
    held: list = []
    if threading.current_thread() is not threading.main_thread():
        yield held
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN), signal.signal(signal.SIGTERM,
                                                                           lambda signum, frame: held.append(signum))
    try:
        yield held
    finally:
        signal.signal(signal.SIGINT, previous[0])
        signal.signal(signal.SIGTERM, previous[1])


@contextlib.contextmanager
def holding_interrupts() -> Iterator[list]:
    """While a sweep closes its cluster and keeps its finished runs: hold a Ctrl-C or SIGTERM, and
    name the signals held in the list it yields, for the caller to act on after the block.

    A user presses Ctrl-C again when the first seems slow to act: raised amid the cluster's close
    it ended the cleanup and lost the runs the first Ctrl-C was keeping. A signal already ignored
    (a command run in the background) stays ignored; only the main thread may set a handler."""
    held: list = []
    if threading.current_thread() is not threading.main_thread():
        yield held
        return
    previous = {}
    for signum in (signal.SIGINT, signal.SIGTERM):
        if signal.getsignal(signum) not in (signal.SIG_IGN, None):
            previous[signum] = signal.signal(signum, lambda number, frame: held.append(number))
    try:
        yield held
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)


def close(client, cluster) -> None:
    """Close a client from `dask_client` and its local cluster."""
    client.close()
    if cluster is not None:
        close_cluster(cluster)


def close_cluster(cluster) -> None:
    """Close a local cluster of `dask_client`'s and put back the logging setting it changed."""
    cluster.close()
    _restore_worker_logging(getattr(cluster, "hybridtrack_logging", _UNSET))


#: dask's setting, read from the environment as a process imports distributed, of the level of
#: distributed's own logs (`logging.distributed`).
_WORKER_LOGGING = "DASK_LOGGING__DISTRIBUTED"
_UNSET = object()


def _quiet_worker_processes():
    """Start the local workers with distributed's logs at CRITICAL, and return the setting before.

    ``silence_logs`` quiets this process and the nanny's log in a worker, not the rest of the
    worker's: measured, a worker's ``distributed.batched`` logged at INFO, and at a SIGTERM to the
    process group a worker printed "Batched Comm Closed" with its traceback as the scheduler went
    away. A worker process reads this environment variable before it imports distributed (and so
    does one its nanny restarts while the cluster runs)."""
    previous = os.environ.get(_WORKER_LOGGING)
    os.environ[_WORKER_LOGGING] = "critical"
    return previous


def _restore_worker_logging(previous) -> None:
    if previous is _UNSET:
        return
    if previous is None:
        os.environ.pop(_WORKER_LOGGING, None)
    else:
        os.environ[_WORKER_LOGGING] = previous
