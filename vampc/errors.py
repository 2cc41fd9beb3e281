"""The two roots of every error vampc raises.

A `VampcError` is the user's to fix (a bad file, a bad option): the CLI prints its one-line message and exits
with status 1, without a traceback. A `VampcInternalError` is a compiler bug: the CLI shows the full context
and asks for a report.
"""


class VampcError(Exception):
    """A user error: bad input file or option. Its message is one line naming the file and the place."""


class VampcWarning(UserWarning):
    """Something the user should know that does not stop the work (an option with no effect, input
    that was not used). The CLI prints it as one line `vampc: warning: ...` on stderr."""


class VampcInternalError(Exception):
    """A broken invariant inside vampc (a bug, not the user's fault)."""


def located(path, where: str, what: str) -> VampcError:
    """Build the standard one-line message `FILE: WHERE: WHAT` (WHERE may be empty)."""
    parts = [str(path)] if path else []
    if where:
        parts.append(where)
    parts.append(what)
    return VampcError(": ".join(parts))


class VampcUsageError(VampcError):
    """A usage error: an option value or a combination of options no command can honour. The CLI
    prints it as one line with the help to read, and exits with status 2."""


class Terminated(KeyboardInterrupt):
    """SIGTERM or SIGHUP, raised where the program is, like Ctrl-C: every output being written is
    removed on the way out (vampc.outputs), so no partial or temporary file is left."""

    def __init__(self, signum: int):
        import signal
        super().__init__(signal.Signals(signum).name)
        self.signum = signum


# The signal received, kept beside the exception its handler raises: an exception raised inside
# an import or a finaliser (a weakref callback, a __del__ run by the garbage collector) is printed
# and swallowed there, so long loops, and every output before it is put in place, also ask
# (raise_if_terminated).
_terminated: list[int] = []


# Set once the command has begun to put its outputs in place (vampc.outputs.Pending.commit): a
# termination signal or Ctrl-C from then on comes too late to stop it. Its handlers then let it
# finish (exit 0, every output in place) instead of raising, which had left a run that reported
# "terminated", exit 143, with its files already replaced, or only some of them.
_committing: list[bool] = []


# Set while the command line is parsed (from terminate_like_interrupt until the command begins:
# `begin`): a signal then is remembered, not raised, and the command raises it as it begins. Raised
# during parsing, it went through click, which took it for an interrupted prompt: a blank line,
# "vampc: interrupted" and exit 1 for a SIGTERM, whose run must say so and exit 143 (a CI engineer's
# find: a job's time-out looked like a failure).
_parsing: list[bool] = []


# What an interrupted command keeps, said beside "interrupted" (a fault campaign's runs): set by
# the command once it keeps something (`keeps`), read where the interrupt ends it (`kept_note`).
# An exception's own note is lost where the signal's exception is swallowed on the way and raised
# again later (raise_if_terminated): a campaign on a Dask cluster said "interrupted" alone.
_keeps: list = []


def keeps(note) -> None:
    """From here on, an interrupt of this command says `note()` (what it keeps)."""
    _keeps[:] = [note]


def kept_note() -> str:
    """What the command said it keeps (`keeps`), or ''."""
    return _keeps[0]() if _keeps else ""


def begin() -> None:
    """The command begins (its options parsed): a signal that came during parsing is raised now."""
    _parsing.clear()
    _keeps.clear()
    raise_if_terminated()


def committing() -> None:
    """The command puts its outputs in place from here on: a signal no longer stops it."""
    if not _committing:
        _committing.append(True)


def remember(signum: int) -> None:
    """Keep the first termination signal or Ctrl-C of this command (raise_if_terminated raises it)."""
    if not _terminated:
        _terminated.append(signum)


def terminate(signum: int):
    """The SIGTERM/SIGHUP handler's work: remember the signal, raise Terminated (nothing once the
    outputs are being put in place: `committing`)."""
    if _committing:
        return
    remember(signum)
    if not _parsing:
        raise Terminated(signum)


def interrupt(signum: int):
    """The Ctrl-C (SIGINT) handler's work: remember it, raise KeyboardInterrupt as Python's own
    handler does (nothing once the outputs are being put in place: `committing`)."""
    if _committing:
        return
    remember(signum)
    if not _parsing:
        raise KeyboardInterrupt


def raise_if_terminated() -> None:
    """Raise again what a termination signal or Ctrl-C raised, if it came and its exception was
    lost."""
    if _terminated:
        import signal
        if _terminated[0] == signal.SIGINT:
            raise KeyboardInterrupt
        raise Terminated(_terminated[0])


def terminate_like_interrupt():
    """Make SIGTERM and SIGHUP end a command as an interrupt does (`terminate`), and remember a
    Ctrl-C (`interrupt`) where Python's own handler is in place: install the handlers (in the main
    thread only: Python allows no other) and return what puts the previous ones back."""
    import signal
    import threading
    if threading.current_thread() is not threading.main_thread():
        return lambda: None
    def handler(signum, frame):
        terminate(signum)
    def ctrl_c(signum, frame):
        interrupt(signum)
    _committing.clear()              # (a library call's outputs, before this command, do not count)
    _parsing[:] = [True]
    previous = {}
    for name in ("SIGTERM", "SIGHUP"):
        if hasattr(signal, name):
            sig = getattr(signal, name)
            previous[sig] = signal.signal(sig, handler)
    if signal.getsignal(signal.SIGINT) is signal.default_int_handler:
        previous[signal.SIGINT] = signal.signal(signal.SIGINT, ctrl_c)
    def restore():
        # the console script's process ends with its command: once the outputs were put in place,
        # a signal during Python's teardown must not kill it either (it did, exit 143)
        # likewise once a signal has ended it: a second one during the teardown had killed the
        # process by that signal after its line was said (a CI engineer's find)
        leaving = (_committing or _terminated) and LEAVING_AFTER_COMMAND
        for sig, old in previous.items():
            signal.signal(sig, signal.SIG_IGN if leaving else old)
        _terminated.clear()          # a signal belongs to the command it ended, not to the next one
        _committing.clear()
        _parsing.clear()
    return restore


def stopping() -> None:
    """A command is ending on a signal (its one line about to be said): from here the console
    script's process leaves, so further signals are ignored (a second SIGTERM within milliseconds
    of the first, from a job runner, had killed it by that signal, exit -15 instead of 143)."""
    if LEAVING_AFTER_COMMAND:
        import signal
        for name in ("SIGTERM", "SIGHUP", "SIGINT"):
            if hasattr(signal, name):
                signal.signal(getattr(signal, name), signal.SIG_IGN)


def signalled_while_parsing() -> int | None:
    """The signal that came while the command line was parsed, if the command never began to raise
    it (help printed, or a usage error)."""
    return _terminated[0] if _terminated and _parsing else None


# Set by the console script (vampc.launch): the process ends when its command does. Library callers
# (tests running commands in process) get their own signal handlers back after each command.
LEAVING_AFTER_COMMAND = False


_SAID_SWITCHES: set = set()


def env_switch(name: str) -> str:
    """An environment switch of vampc's (VAMPC_PROGRESS, VAMPC_NATIVE, VAMPC_FORK): "0", "1", or ""
    when unset, empty or any other value, which is said once, in a warning (VAMPC_PROGRESS=yes
    had shown no bar, without a word)."""
    import os
    value = os.environ.get(name, "")
    if value.strip() in ("0", "1"):
        return value.strip()
    if value and name not in _SAID_SWITCHES:
        _SAID_SWITCHES.add(name)
        import warnings
        warnings.warn(VampcWarning(f"{name}={value!r}: give 1 (on) or 0 (off); taken as unset"),
                      stacklevel=2)
    return ""
