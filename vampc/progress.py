"""Progress on stderr for long work, drawn by tqdm (a kept library: rate, ETA and terminal handling
we would otherwise write by hand). Nothing is shown for work that ends within two seconds, and
nothing at all unless stderr is a terminal or VAMPC_PROGRESS=1 (so logs and pipes stay clean)."""
from __future__ import annotations

import contextlib
import os
import sys
import threading

DELAY = 2.0   # seconds into a command before a bar appears
_BEGUN: list[float] = []     # when the command began (`begin`), monotonic seconds
_NOTES: list = []            # the drawn stages bars' `note` callables, innermost last


def begin() -> None:
    """A command begins: its bars appear once it has run DELAY seconds, not each DELAY seconds after
    it starts (a report's second bar, after the compile's, left 2 s blank: a new user's find)."""
    import time
    _BEGUN[:] = [time.monotonic()]


def end() -> None:
    """The command has ended: later bars (a library caller's) wait DELAY seconds of their own."""
    _BEGUN.clear()


def _delay() -> float:
    import time
    return DELAY if not _BEGUN else max(0.0, DELAY - (time.monotonic() - _BEGUN[0]))


def enabled() -> bool:
    """Whether progress is shown at all."""
    from vampc.errors import env_switch
    if sys.stderr is None:            # (closed, `2>&-`: isatty of None was an internal error)
        return False
    flag = env_switch("VAMPC_PROGRESS")
    if flag:
        return flag == "1"
    if os.environ.get("VAMPC_PROGRESS") == "":       # (set empty: off, as it always was)
        return False
    return sys.stderr.isatty()


def _width() -> dict:
    """tqdm's width options: the terminal's, followed as it is resized, or 80 columns where the
    terminal says it has none (a pty left at 0 × 0, as `script` makes: tqdm then drew nothing, a
    104-second run without a bar, a new user's find)."""
    try:
        columns = os.get_terminal_size(sys.stderr.fileno()).columns
    except (OSError, ValueError, AttributeError):
        columns = None
    return {"ncols": 80} if columns == 0 else {"dynamic_ncols": True}


class _Stderr:
    """Where bars are drawn: standard error, whose reader going away (`2> >(head -c 150)`) drops the
    bars, as say() drops a warning, instead of failing the run (the bar's redraw raised a broken
    pipe in the clock thread and then in the command: exit 1, no file written: a review's find)."""

    def __init__(self, stream):
        self._stream, self._gone = stream, False

    def write(self, text: str) -> int:
        if self._gone:
            return len(text)
        try:
            return self._stream.write(text)
        except (BlockingIOError, InterruptedError):   # (full for now: this redraw dropped)
            return len(text)
        except (OSError, ValueError):       # (ValueError: the stream closed; OSError: its reader
            self._drop()                    # gone, or full, or read-only: a review's find)
            return len(text)

    def flush(self) -> None:
        if self._gone:
            return
        try:
            self._stream.flush()
        except (BlockingIOError, InterruptedError):
            pass
        except (OSError, ValueError):
            self._drop()

    def _drop(self) -> None:
        from vampc.outputs import silence
        self._gone = True
        silence(self._stream)     # (as say() does)

    def __getattr__(self, name):
        return getattr(self._stream, name)


@contextlib.contextmanager
def counter(label: str, total: int, unit: str = "set", even: bool = True):
    """A callable `update(done, total)` that advances a bar to `done` of `total`. `even`: the
    things counted take about as long each, so a time left is shown; else the elapsed time alone
    (the trade-off's budgets do not: 15 of 47 done said 13 s left of a run that took 50 s, a new
    user's find)."""
    if not enabled():
        yield lambda done, total: None
        return
    from tqdm import tqdm
    shape = {} if even else {"bar_format": "{l_bar}{bar}| {n_fmt}/{total_fmt} [{elapsed}]{postfix}"}
    with tqdm(total=total, desc=label, unit=unit, delay=_delay(),
              file=_Stderr(sys.stderr),
              leave=False, **_width(), **shape) as bar:
        def update(done: int, total_now: int) -> None:
            if total_now != bar.total:
                bar.total = total_now
            if done == 0 == bar.n:    # (work starts now: what came before is not the sets' time;
                bar.start_t = bar.last_print_t = bar._time()   # not reset(), which draws at once)
            bar.update(done - bar.n)
        yield update


def note(text: str) -> None:
    """Say what the running stage is doing now, beside its name on the innermost stages bar (`vampc
    compile --exact`'s solver at one interval after another: minutes in one stage that said only
    "schedule"); nothing where no bar is drawn."""
    if _NOTES:
        _NOTES[-1](text)


@contextlib.contextmanager
def stages(label: str, names: tuple[str, ...]):
    """A callable `stage(name)` that shows which of the named stages is running (and `note`, what it
    is doing)."""
    if not enabled():
        yield lambda name: None
        return
    from tqdm import tqdm
    with tqdm(total=len(names), desc=label, unit="stage", delay=_delay(),
              file=_Stderr(sys.stderr),
              leave=False, **_width(),
              # (one stage: "0/1 stages" never moved, only the time did: a new user's find)
              bar_format="{desc}: {n_fmt}/{total_fmt} stages [{elapsed}]{postfix}" if len(names) > 1
              else "{desc} [{elapsed}]{postfix}") as bar:
        running = [""]          # the stage's name, which a note follows

        def stage(name: str) -> None:
            # (set_postfix_str's own redraw would draw the bar at once, before DELAY, and a bar
            # tqdm drew that way is not cleared when it closes: it was left on the line, the
            # command's output glued to it; update() draws only once DELAY has passed)
            bar.set_postfix_str(name, refresh=False)
            running[0] = name
            if name in names:
                bar.update(names.index(name) - bar.n)

        def noted(text: str) -> None:
            bar.set_postfix_str(f"{running[0]}: {text}" if running[0] else text, refresh=False)
        # tqdm draws a delayed bar only when it is updated: a stage that runs long (rtl's Verilog,
        # 76 s for the Puma) showed nothing at all; a clock draws it once DELAY has passed, and
        # every second after, so its elapsed time moves
        stop = threading.Event()

        def tick() -> None:
            if stop.wait(max(0.0, bar.start_t + bar.delay - bar._time())):
                return
            while True:
                with bar.get_lock():
                    if stop.is_set():
                        return
                    bar.refresh(nolock=True)
                    bar.last_print_t = bar._time()   # (drawn: its close() clears it, as update's)
                if stop.wait(1.0):
                    return
        clock = threading.Thread(target=tick, name="vampc-progress", daemon=True)
        clock.start()
        _NOTES.append(noted)
        try:
            yield stage
        finally:
            _NOTES.remove(noted)
            stop.set()
            # (not for ever: a signal raised in the middle of a redraw can leave tqdm's lock held,
            # and the clock, waiting for it, would hold the command's exit; it is a daemon)
            clock.join(timeout=2.0)


@contextlib.contextmanager
def aside():
    """A line printed while a bar is drawn: the bar is cleared first and drawn again below it (a
    line printed over a drawn bar was glued to its end: `vampc rtl`'s step estimates, a warning).
    A bar not yet shown (within its DELAY) is left alone: tqdm's external_write_mode drew it at
    once, and a bar drawn that way is not cleared when it closes (a review's find)."""
    tqdm = sys.modules.get("tqdm")
    if tqdm is None or not getattr(tqdm.tqdm, "_instances", None):
        yield
        return
    with tqdm.tqdm.get_lock():
        shown = [bar for bar in list(tqdm.tqdm._instances) if _shown(bar)]
        for bar in shown:
            bar.clear(nolock=True)
        try:
            yield
        finally:
            for bar in shown:
                bar.refresh(nolock=True)


def _shown(bar) -> bool:
    """Whether tqdm has drawn `bar` (what its close() asks before clearing it)."""
    return (hasattr(bar, "last_print_t") and not bar.disable
            and bar.last_print_t >= bar.start_t + bar.delay)
