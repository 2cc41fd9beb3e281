"""Independent tasks run here, on local worker processes, or on a Dask cluster, with the same results
whichever runs them: `report --tradeoff`'s budgets and `vampc faults`' runs.

`run_tasks(task, context, items, ...)` calls `task(context, item)` for every item and hands each
result to `done(index, result)` as it arrives (in any order; the caller orders them). Local workers
are forked (each inherits `context` when it starts); they ignore Ctrl-C, and an interrupt, a signal
or a failed task here stops them at once. A Dask cluster (`scheduler`, an address such as
tcp://HOST:8786; dask.distributed, the `dask` extra) gets `context` broadcast once and one task per
item; the scheduler is reached before anything runs, and anything the cluster does wrong (no
workers, a worker without vampc, a lost worker, an address it cannot use) is one line.
"""
from __future__ import annotations

import os
import sys
from collections.abc import Callable, Sequence

from vampc.errors import VampcError, raise_if_terminated

CONNECT_GRACE = 5.0      # seconds past the timeout before connect gives up on a silent port
SCHEDULER_TIMEOUT = "10s"       # how long to try to reach a Dask scheduler
_CONTEXT = None                 # a forked worker's (task, context)


def _refused(address: str) -> None:
    """A tcp:// address where nothing listens is said at once (Dask retried a refused connection
    for its whole timeout, then said it had timed out: 12 s, an audit's)."""
    import re
    import socket
    m = re.fullmatch(r"(?:tcp://)?(\[[^\]]+\]|[^:/\[\]]+):(\d+)/?", address.strip())
    if m is None or not 0 < int(m.group(2)) < 65536:
        return                      # (other protocols and forms: Dask says what it makes of them)
    host = m.group(1).strip("[]")
    try:
        socket.create_connection((host, int(m.group(2))), timeout=2).close()
    except ConnectionRefusedError:
        raise VampcError(f"--scheduler {address}: cannot reach a Dask scheduler there (the "
                         "connection was refused: nothing listens on that port)") from None
    except socket.gaierror as exc:   # (said as a 10 s time-out by Dask: a new user's)
        raise VampcError(f"--scheduler {address}: cannot reach a Dask scheduler there (the host "
                         f"name {host!r} does not resolve: {exc.strerror or exc})") from None
    except OSError:
        return                      # (a time-out, no route: Dask says it)


def connect(address: str, timeout: str = SCHEDULER_TIMEOUT):
    """A dask.distributed Client of the scheduler at `address` (VampcError, one line, if there is
    none or dask.distributed is missing)."""
    try:
        from distributed import Client
    except ImportError:
        raise VampcError("--scheduler needs dask.distributed: pip install \"vampc[dask]\"") from None
    import logging
    quiet = ("distributed", "tornado", "asyncio")
    for name in [*quiet, *logging.root.manager.loggerDict]:
        # what goes wrong on the cluster is said in one line (_on_cluster); its library's own log
        # printed tracebacks when the scheduler went away mid-run (dask's configuration gives
        # some of its loggers levels of their own: each is set)
        if name.split(".")[0] in quiet:
            logging.getLogger(name).setLevel(logging.CRITICAL + 1)
    _refused(address)
    import threading
    got: dict = {}

    def reach() -> None:
        try:
            got["client"] = Client(address, timeout=timeout)
        except BaseException as exc:  # noqa: BLE001 - OSError, TimeoutError, TypeError for tls:// ...
            got["error"] = exc
    # An overall deadline: a port where something else listens (a web server) accepts the
    # connection and never answers Dask's handshake, and Client waited forever, its timeout unheeded
    seconds = float(timeout.rstrip("s")) + CONNECT_GRACE
    thread = threading.Thread(target=reach, name="vampc-dask-connect", daemon=True)
    thread.start()
    thread.join(seconds)
    if thread.is_alive():
        raise VampcError(f"--scheduler {address}: cannot reach a Dask scheduler there (no Dask "
                         f"answer in {seconds:g} s: does something else listen on that port?)")
    if "error" in got:
        exc = got["error"]
        if isinstance(exc, (KeyboardInterrupt, SystemExit)):
            raise exc
        if isinstance(exc, MemoryError):   # (Dask reading another protocol's answer as a frame
            # length: "Unable to allocate 3.07 EiB", a new user's, of a web server's 400)
            raise VampcError(f"--scheduler {address}: cannot reach a Dask scheduler there (what "
                             "answers is not Dask: does something else listen on that port?)") \
                from None
        raise VampcError(f"--scheduler {address}: cannot reach a Dask scheduler there "
                         f"({type(exc).__name__}: {one_line(exc)}){_protocol_hint(address, exc)}") from None
    return got["client"]


def _protocol_hint(address: str, exc: BaseException) -> str:
    """What Dask's words mean for the protocols a shell cannot use as given (a new user's
    `inproc://` and `ucx://` got only Dask's internals), else ''."""
    scheme = address.split("://", 1)[0]      # (spaces and capitals: refused before, options.py)
    if scheme == "inproc":
        return (": an inproc:// cluster runs inside one Python process and is reached only from "
                "that process (vampc's API called there), not from a command")
    if scheme in ("ucx", "ucxx") and ("UCX" in str(exc) or "unknown address scheme" in str(exc)):
        return (f": {scheme}:// needs Dask's UCX support installed (distributed-ucxx), here and on "
                "the cluster")
    return ""


def run_tasks(task: Callable, context, items: Sequence, done: Callable[[int, object], None],
              workers: int = 1, scheduler: str | None = None, client=None, progress=None,
              warn_stack: int = 3, kept: str | Callable[[], str] = "nothing is written") -> None:
    """Run `task(context, item)` for every item (see the module docstring). `client`: a Client
    already connected to `scheduler` (connect); `progress(done, total)` after each result; `kept`:
    what is left of a run a dead worker or the cluster stops, for its message (or a function
    saying it then)."""
    if scheduler is not None:
        _on_cluster(task, context, items, done, scheduler, client, progress, kept)
        return
    import multiprocessing
    if workers > 1 and not hasattr(os, "fork"):
        import warnings

        from vampc.errors import VampcWarning
        warnings.warn(VampcWarning(f"--workers {workers}: this platform cannot fork; the tasks run "
                                   "in this process"), stacklevel=warn_stack)
    if workers <= 1 or len(items) <= 1 or not hasattr(os, "fork") or \
            multiprocessing.current_process().daemon:
        for i, item in enumerate(items):
            raise_if_terminated()
            done(i, task(context, item))
            if progress is not None:
                progress(i + 1, len(items))
        return
    from concurrent.futures import ProcessPoolExecutor, as_completed
    pool = ProcessPoolExecutor(min(workers, len(items)),
                               mp_context=multiprocessing.get_context("fork"),
                               initializer=_worker_start, initargs=(task, context, os.getpid()))
    try:
        with _ctrl_c_held():       # the workers are forked here: none takes Ctrl-C before it ignores it
            futures = {pool.submit(_worker_task, item): i for i, item in enumerate(items)}
        for n, future in enumerate(as_completed(futures), 1):
            raise_if_terminated()      # a Ctrl-C its exception lost in a finaliser still stops
            done(futures[future], future.result())
            if progress is not None:
                progress(n, len(items))
        raise_if_terminated()
    except BaseException as exc:
        manager = getattr(pool, "_executor_manager_thread", None)
        for proc in list(getattr(pool, "_processes", {}).values()):     # do not wait for the queue
            proc.kill()
        pool.shutdown(wait=False, cancel_futures=True)
        if manager is not None:
            # The pool's thread sees its workers gone and closes its pipes, at once. Let it finish:
            # at exit, Python's own hook writes to one of those pipes without the pool's lock, and
            # a write racing the close printed "OSError: [Errno 9] Bad file descriptor" under a
            # Ctrl-C (1 run in about 50 on a loaded machine).
            manager.join(timeout=5)
        from concurrent.futures.process import BrokenProcessPool
        if isinstance(exc, BrokenProcessPool):       # a worker killed (a signal, out of memory)
            raise VampcError(f"a worker process ended before its task did ({one_line(exc)}); "
                             f"{_said(kept)}: run again, with fewer --workers if memory is short") from None
        raise
    pool.shutdown()


class _ctrl_c_held:
    """Ctrl-C held while the workers are forked, in two ways.

    - Blocked in this thread: a forked worker starts with it blocked (a Ctrl-C to the process
      group then waits, instead of raising in a worker that has not yet set it aside) and unblocks
      it once it ignores it (_worker_start).
    - Deferred here: the kernel may still hand it to another thread (NumPy's BLAS threads do not
      block it), and Python then runs its handler in this thread, which could land between a
      worker's fork and the pool's note of it, leaving that worker out of the kill. So a handler
      that only notes it stands in until the pool knows every worker, and the block's end raises
      it (as KeyboardInterrupt; nothing of it is kept beyond the block).
    """

    def __enter__(self):
        import signal
        try:
            self.old = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
        except (AttributeError, ValueError, OSError):
            self.old = None
        self.handler, self.caught = None, False

        def note(signum, frame):
            self.caught = True
        try:
            if callable(signal.getsignal(signal.SIGINT)):     # not ignored (a background job)
                self.handler = signal.signal(signal.SIGINT, note)
        except ValueError:                   # not the main thread: Python runs no handler here
            pass

    def __exit__(self, kind, value, tb):
        import signal
        if self.handler is not None:
            signal.signal(signal.SIGINT, self.handler)
        if self.old is not None:
            signal.pthread_sigmask(signal.SIG_SETMASK, self.old)
        if kind is None and self.caught:
            raise KeyboardInterrupt           # the Ctrl-C that came meanwhile, now that all is known


def _worker_start(task, context, parent: int | None = None) -> None:
    """A worker's start: keep the task and its context; leave Ctrl-C to the process that started
    it; end with it (`parent`), however it ends."""
    import signal
    global _CONTEXT
    _CONTEXT = (task, context)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    if hasattr(signal, "pthread_sigmask"):   # forked with it blocked (_ctrl_c_held): ignored now
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})
    for name in ("SIGTERM", "SIGHUP"):     # not vampc's handlers: a worker holds nothing to clean up
        if hasattr(signal, name):
            signal.signal(getattr(signal, name), signal.SIG_DFL)
    if parent is not None:                 # (after SIGTERM's default is back: it is what ends it)
        die_with(parent)


def die_with(parent: int) -> None:
    """Have the kernel end this (forked) process with SIGTERM when `parent` ends (Linux's
    PR_SET_PDEATHSIG): a parent killed outright (SIGKILL, the out-of-memory killer) left its
    workers waiting forever, idle. Elsewhere nothing is done."""
    import signal
    if not sys.platform.startswith("linux"):
        return
    try:
        import ctypes
        ctypes.CDLL(None, use_errno=True).prctl(1, int(signal.SIGTERM))   # 1: PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        return
    if os.getppid() != parent:          # it ended before the request was made
        os._exit(1)


def _worker_task(item):
    task, context = _CONTEXT
    return task(context, item)


def _said(kept: str | Callable[[], str]) -> str:
    """What is kept of a stopped run, said when it stops."""
    return kept() if callable(kept) else kept


def _on_cluster(task, context, items, done, address: str, client, progress, kept) -> None:
    own = client is None
    client = client or connect(address)
    try:
        from distributed import as_completed
        shared = client.scatter(context, broadcast=True)
        futures = [client.submit(task, shared, item, pure=False) for item in items]
        index = {f.key: i for i, f in enumerate(futures)}
        for n, future in enumerate(as_completed(futures), 1):
            done(index[future.key], future.result())
            if progress is not None:
                progress(n, len(items))
    except VampcError:
        raise
    except Exception as exc:  # noqa: BLE001 - whatever the cluster raises
        # (what is kept said, as for a dead local worker: a campaign whose scheduler went away
        # said only Dask's words, and its runs were kept: a new user's)
        raise VampcError(f"--scheduler {address}: the cluster failed ({type(exc).__name__}: "
                         f"{one_line(exc)}){_why(exc)}; {_said(kept)}") from None
    finally:
        if own:
            client.close()


def _why(exc: Exception) -> str:
    """What Dask's words for a failure mean, where they are not plain (new users' clusters: workers
    from a Python without vampc; every worker restarted mid-run), else ''."""
    said = str(exc)
    if "No module named 'vampc" in said:
        return (": the workers' Python cannot import vampc; install vampc, the version run here, "
                "where the workers run")
    if type(exc).__name__ == "FutureCancelledError" and "forgotten" in said:
        return (": the cluster lost what this run had sent its workers (every worker holding it "
                "restarted or left); run again")
    return ""


def one_line(exc: Exception) -> str:
    """An exception's message on one line (vampc.textio.one_line)."""
    from vampc.textio import one_line as collapsed
    return collapsed(str(exc))
