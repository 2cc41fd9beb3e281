"""The `vampc` console script: the command line of vampc.cli, with a Ctrl-C that lands while Python
is still importing it (the first few tenths of a second) ending as every other interrupt does: one
line, `vampc: interrupted`, exit status 130, instead of an import's traceback.

A command that has built millions of objects (a 4096-joint log compile: about ten million) asks
for `skip_teardown()`: when it has succeeded, the script then flushes its output, shuts logging
down and leaves with os._exit, instead of having Python free every object one by one on the way
out (0.7-0.9 s at 4096 joints), as C compilers do. Its files are closed by then; the only exit
handlers vampc's commands register are logging's (run here) and the thread pools' (whose threads
have ended: checked; a daemon thread, such as the progress bar's monitor, does not hold the exit).
The request holds for the run that made it only."""
from __future__ import annotations

import sys

_SKIP_TEARDOWN = False


def skip_teardown() -> None:
    """Leave without freeing memory if the command succeeds (when run as the console script)."""
    global _SKIP_TEARDOWN
    _SKIP_TEARDOWN = True


class _Ended(BaseException):
    """SIGTERM or SIGHUP while vampc.cli is being imported (before its own handlers are in)."""


def _ended(signum, frame):
    raise _Ended(signum)


def main() -> None:
    global _SKIP_TEARDOWN
    _SKIP_TEARDOWN = False            # (asked for by this run's command only)
    import signal
    # (a SIGTERM in the first tenth of a second, while the imports ran, ended the process by the
    # signal with nothing said: an audit's find; Python's own start-up before this line stays so)
    early = [getattr(signal, name) for name in ("SIGTERM", "SIGHUP") if hasattr(signal, name)]
    previous = {sig: signal.signal(sig, _ended) for sig in early}
    try:
        from vampc.cli import main as command_line
    except KeyboardInterrupt:
        sys.stderr.write("vampc: interrupted\n")
        sys.exit(130)
    except _Ended as ended:
        signum = ended.args[0]
        sys.stderr.write(f"vampc: terminated ({signal.Signals(signum).name})\n")
        sys.exit(128 + signum)
    except MemoryError:
        sys.stderr.write("vampc: error: out of memory while starting (the process may have too "
                         "little memory: `ulimit -v`)\n")
        sys.exit(1)
    except ImportError as exc:
        # a library vampc needs that will not load (under `ulimit -v` numpy's "failed to map
        # segment from shared object" was a traceback: a CI engineer's find); vampc's own
        # modules failing to import is a bug, shown in full
        if (exc.name or "").split(".")[0] == "vampc":
            raise
        first = exc             # (numpy's own is a page of advice raised from the loader's line)
        while isinstance(first.__cause__, ImportError):
            first = first.__cause__
        module = next((m for m in _importing(exc.__traceback__) if m.split(".")[0] != "vampc"),
                      exc.name or first.name or "a library vampc needs")
        what = " ".join(str(first).split())[:300]
        sys.stderr.write(f"vampc: error: cannot load {module.split('.')[0]}: {what} (out of "
                         "memory under `ulimit -v`, or an installation to mend: pip install "
                         "--force-reinstall vampc)\n")
        sys.exit(1)
    finally:
        for sig, old in previous.items():
            signal.signal(sig, old)
    from vampc import errors
    errors.LEAVING_AFTER_COMMAND = True       # (signals after the outputs are in place: ignored)
    try:
        command_line()
    except SystemExit as done:
        if _SKIP_TEARDOWN and done.code in (0, None):
            _leave_now()
        raise


def _importing(tb) -> list[str]:
    """The modules being imported along a traceback, outermost first (their frames' __name__)."""
    names = []
    while tb is not None:
        name = tb.tb_frame.f_globals.get("__name__", "")
        if tb.tb_frame.f_code.co_name == "<module>" and name not in names:
            names.append(name)
        tb = tb.tb_next
    return names


def _leave_now() -> None:
    import logging
    import os
    import threading
    if any(t.is_alive() and not t.daemon for t in threading.enumerate()
           if t is not threading.main_thread()):     # work still running: leave the normal way
        return
    try:
        for stream in (sys.stdout, sys.stderr):
            if stream is not None:                     # (None: started with the stream closed)
                stream.flush()
    except (OSError, ValueError):          # a closed pipe or file: let Python handle it as it would
        return
    logging.shutdown()
    os._exit(0)
