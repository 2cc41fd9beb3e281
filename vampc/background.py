"""Running a check in a forked process while the main one goes on, for the few long checks whose
only result is "passed" or an error (the static check of a big program file, done while its report
is built: the machine has two cores or more, and the check is a third of the work).

`in_background(fn, *args)` forks (POSIX) and runs fn in the child; `.wait()` returns when it is done
and raises what it raised: a VampcError with its one line, anything else as a VampcInternalError
carrying the child's traceback. Where there is no fork, or when asked not to (`inline=True`, or the
environment variable VAMPC_FORK=0), fn runs at once and `.wait()` does nothing. The child never
writes to the terminal and leaves with os._exit, so nothing of the parent's (buffers, atexit
handlers, a test runner) runs twice.
"""
from __future__ import annotations

import contextlib
import os
import pickle
import traceback

from vampc.errors import VampcError, VampcInternalError, env_switch


def available_cores() -> int:
    """The cores this process may run on (its CPU affinity where the platform says)."""
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1


_LIVE: set = set()      # children not yet waited for or abandoned (abandon_all's)


def abandon_all() -> None:
    """Stop and reap every check still running: a command ends (cli), however it ends. A SIGTERM
    while `report --tradeoff` waited for its check left the child running, orphaned, for 45 s at
    up to 4.7 GB (a file-safety audit)."""
    for deferred in list(_LIVE):
        deferred.abandon()


class Deferred:
    """A check running in a child process (or already done inline)."""

    def __init__(self, pid: int | None = None, fd: int | None = None):
        self.pid, self.fd = pid, fd
        if pid is not None:
            _LIVE.add(self)

    def wait(self) -> None:
        """Block until the check is done; raise what it raised."""
        if self.pid is None:
            return
        chunks = []
        try:
            with os.fdopen(self.fd, "rb") as pipe:
                while chunk := pipe.read(1 << 16):
                    chunks.append(chunk)
        finally:      # (closed: an interrupt here then abandons the child, which closed it again,
            self.fd = None       # EBADF, a traceback and exit 3 for a SIGTERM: a review's find)
        _, status = os.waitpid(self.pid, 0)
        self.pid = None
        _LIVE.discard(self)
        code = os.waitstatus_to_exitcode(status)
        if code == 0:
            return
        if not chunks:        # killed before it could report: by a signal (the OOM killer, say)
            import signal
            how = (f"was killed by {signal.Signals(-code).name}" if code < 0
                   else f"exited with status {code}")
            raise VampcInternalError(f"the check running beside this command {how} before it "
                                     "could report (out of memory?)")
        kind, message = pickle.loads(b"".join(chunks))
        if kind == "user":
            raise VampcError(message)
        raise VampcInternalError(f"background check failed:\n{message}")

    def abandon(self) -> None:
        """Stop a check whose result is no longer wanted (the main work failed), and reap it."""
        if self.pid is None:
            return
        import signal
        try:
            os.kill(self.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        with contextlib.suppress(ChildProcessError):
            os.waitpid(self.pid, 0)
        if self.fd is not None:
            os.close(self.fd)
        self.pid, self.fd = None, None
        _LIVE.discard(self)


def in_background(fn, *args, inline: bool = False) -> Deferred:
    """Start fn(*args) in a forked child (see the module docstring)."""
    if inline or not hasattr(os, "fork") or env_switch("VAMPC_FORK") == "0":
        fn(*args)
        return Deferred()
    read, write = os.pipe()
    pid = os.fork()
    if pid == 0:                                     # the child: run, report, leave at once
        os.close(read)
        code, payload = 0, b""
        try:
            fn(*args)
        except VampcError as exc:
            code, payload = 1, pickle.dumps(("user", str(exc)))
        except BaseException:                        # noqa: BLE001 - reported to the parent
            code, payload = 3, pickle.dumps(("internal", traceback.format_exc()))
        try:
            view = memoryview(payload)
            while view:
                view = view[os.write(write, view):]
        finally:
            os._exit(code)
    os.close(write)
    return Deferred(pid, read)


def run_tool(cmd: list, *, input: str | None = None, cwd=None, env: dict | None = None,
             timeout: float | None = None):
    """An outside tool run to its end (a subprocess.CompletedProcess of text), in a process group of
    its own, the whole group killed if this process stops waiting for it: a signal or Ctrl-C (the
    handlers raise), or `timeout` seconds (subprocess.TimeoutExpired, as subprocess.run raises).
    Killing the tool alone left the processes it had started running, owned by init, after vampc
    had exited: gcc's cc1 (an audit's find), iverilog's ivlpp and ivl (a review's)."""
    import signal
    import subprocess
    proc = subprocess.Popen(cmd, stdin=subprocess.PIPE if input is not None else subprocess.DEVNULL,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=cwd,
                            env=env, start_new_session=True)
    try:
        out, err = proc.communicate(input, timeout=timeout)
    except BaseException:
        with contextlib.suppress(OSError):
            os.killpg(proc.pid, signal.SIGKILL)
        proc.communicate()
        raise
    return subprocess.CompletedProcess(cmd, proc.returncode, out, err)
