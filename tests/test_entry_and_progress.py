"""`python -m vampc` runs the command line (there was no vampc/__main__.py), and progress bars count
in whole numbers ('53.0/904' had been printed: tqdm's unit_scale)."""
from __future__ import annotations

import os
import subprocess
import sys

import pytest
from conftest import EXAMPLES


def test_python_dash_m_vampc_runs(tmp_path):
    done = subprocess.run([sys.executable, "-m", "vampc", "--help"], capture_output=True, text=True)
    assert done.returncode == 0 and done.stdout.startswith("Usage: python -m vampc "), done.stderr
    out = tmp_path / "p.vamp.json"
    done = subprocess.run([sys.executable, "-m", "vampc", "compile", str(EXAMPLES / "planar2.yaml"),
                           "-o", str(out)], capture_output=True, text=True)
    assert done.returncode == 0 and out.exists(), done.stderr
    done = subprocess.run([sys.executable, "-m", "vampc", "compile"], capture_output=True, text=True)
    assert done.returncode == 2 and "Missing argument 'ROBOT'" in done.stderr


def test_a_progress_bar_counts_whole_runs(monkeypatch, capsys):
    from vampc import progress
    monkeypatch.setenv("VAMPC_PROGRESS", "1")
    monkeypatch.setattr(progress, "DELAY", 0.0)
    import re
    import time
    with progress.counter("fault runs", 904, unit="run") as update:
        update(52, 904)
        time.sleep(0.3)                  # (tqdm redraws at most every 0.1 s)
        update(53, 904)
    err = capsys.readouterr().err
    # 53 is drawn, or 52 when a stall of 0.1 s before the first update drew that one (tqdm then
    # raises its minimum step and skips 53): either way a count, whole
    assert re.search(r"\b5[23]/904\b", err) and not re.search(r"\b(5[23]|904)\.0", err), err


def test_lookahead_shows_its_stages(monkeypatch, tmp_path):
    """The README says work over two seconds shows a bar; a look-ahead of 20 000 rows ran five
    seconds with nothing on stderr, even with VAMPC_PROGRESS=1 (a new user's run)."""
    from click.testing import CliRunner

    from vampc import progress
    from vampc.cli import main
    monkeypatch.setenv("VAMPC_PROGRESS", "1")
    monkeypatch.setattr(progress, "DELAY", 0.0)
    r = CliRunner().invoke(main, ["lookahead", str(EXAMPLES / "puma560.yaml"), "--trajectory",
                                  str(EXAMPLES / "puma560-path.csv"), "--rate", "1kHz", "--window",
                                  "64", "--limits", str(EXAMPLES / "puma560-limits.csv"),
                                  "--retime", "window"])
    assert r.exit_code == 0, r.output
    assert "look-ahead over puma560-path.csv: 0/5 stages" in r.stderr, r.stderr   # (window: five)


@pytest.mark.parametrize("command", ["compile", "lookahead"])
def test_no_bar_is_drawn_before_its_delay(monkeypatch, tmp_path, command):
    """A stage's name was drawn at once (tqdm's set_postfix_str redraws, whatever its delay), and a
    bar drawn that way was not cleared when it closed: every interactive run of lookahead left
    'look-ahead over ...: 5/6 stages' on the line, its output glued to it (a review's run)."""
    from click.testing import CliRunner

    from vampc import progress
    from vampc.cli import main
    monkeypatch.setenv("VAMPC_PROGRESS", "1")
    monkeypatch.setattr(progress, "DELAY", 60.0)        # no bar at all within a minute
    args = (["compile", str(EXAMPLES / "puma560.yaml"), "-o", str(tmp_path / "p.vamp.json")]
            if command == "compile" else
            ["lookahead", str(EXAMPLES / "puma560.yaml"), "--trajectory",
             str(EXAMPLES / "puma560-path.csv"), "--rate", "1kHz", "--window", "64", "--limits",
             str(EXAMPLES / "puma560-limits.csv"), "--retime", "window"])
    r = CliRunner().invoke(main, args)
    assert r.exit_code == 0, r.output
    assert "stages" not in r.stderr, r.stderr


def test_a_bar_waits_for_the_command_not_for_itself(monkeypatch):
    """Each bar waited its own 2 s: a report's bar, after the compile's, left 2 s blank in the middle
    of a run (a new user's find). A bar appears once the command has run DELAY seconds."""
    import time

    from vampc import progress
    clock = [100.0]
    monkeypatch.setattr(time, "monotonic", lambda: clock[0])
    monkeypatch.setattr(progress, "DELAY", 2.0)
    monkeypatch.setattr(progress, "_BEGUN", [])
    progress.begin()
    assert progress._delay() == 2.0
    clock[0] = 101.5
    assert progress._delay() == 0.5
    clock[0] = 104.0
    assert progress._delay() == 0.0            # (a later bar: at once)
    # a command begins the clock and ends it: a library caller's bar afterwards waits its own
    # DELAY (review: the first command's start had been kept for good)
    from click.testing import CliRunner

    from vampc.cli import main
    begun = []
    real = progress.begin
    monkeypatch.setattr(progress, "begin", lambda: (begun.append(1), real()))
    assert CliRunner().invoke(main, ["compile", "examples/planar2.yaml", "-o", "-"]).exit_code == 0
    clock[0] = 110.0                           # (later: a bar of its own waits its own 2 s)
    assert begun == [1] and progress._delay() == 2.0


def test_a_line_said_over_a_bar_starts_its_own_line(monkeypatch, capsys):
    """A line printed while a bar was drawn was glued to the bar's end (`vampc rtl`'s step estimates
    as '... stages [00:20] , co-simulationvampc rtl: co-simulating ...')."""
    import re
    import time

    from vampc import progress
    from vampc.cli import say
    monkeypatch.setenv("VAMPC_PROGRESS", "1")
    monkeypatch.setattr(progress, "DELAY", 0.0)
    with progress.stages("work", ("one", "two")) as stage:
        stage("one")
        time.sleep(0.15)
        stage("two")                       # drawn: the bar is on the line
        say("vampc rtl: a note", err=True)
    err = capsys.readouterr().err
    line = next(x for x in err.split("\n") if "a note" in x)
    assert line.split("\r")[-1] == "vampc rtl: a note", repr(err)
    # (not "[00:00] , two"; the elapsed time is whatever a loaded machine took)
    assert re.search(r"work: 1/2 stages \[\d\d:\d\d\], two", err), repr(err)


def test_rtl_shows_its_steps(monkeypatch, tmp_path):
    """`vampc rtl -o` wrote a network's Verilog for over a minute with no bar (Amaranth's back end
    says nothing while it runs); its steps are now a bar. (The Verilog writer is stubbed: the test is
    of the bar, and writing even a one-joint network's Verilog takes 10-20 s.)"""
    pytest.importorskip("amaranth")
    from click.testing import CliRunner

    from vampc import progress
    from vampc.cli import main
    from vampc.rtl import verilog
    monkeypatch.setenv("VAMPC_PROGRESS", "1")
    monkeypatch.setattr(progress, "DELAY", 0.0)
    monkeypatch.setattr(verilog, "verilog_text", lambda design: "// stub\n")
    r = CliRunner().invoke(main, ["rtl", str(EXAMPLES / "planar2.yaml"), "--word", "q16.16",
                                  "-o", str(tmp_path / "p.v")])
    assert r.exit_code == 0, r.output
    assert "vampc rtl of planar2.yaml [" in r.stderr and ", Verilog" in r.stderr, r.stderr


def test_a_line_said_within_a_bars_delay_draws_no_bar(monkeypatch, capsys):
    """A line said while a bar was within its DELAY drew the bar at once (tqdm's external_write_mode
    redraws every bar), and a bar drawn that way is not cleared when it closes: the command's result
    was glued to '... 0/2 stages [00:00], one' (a review's find)."""
    from vampc import progress
    from vampc.cli import say
    monkeypatch.setenv("VAMPC_PROGRESS", "1")
    monkeypatch.setattr(progress, "DELAY", 60.0)
    with progress.stages("work", ("one", "two")) as stage:
        stage("one")
        say("vampc rtl: a note", err=True)
    say("the result", err=True)
    err = capsys.readouterr().err
    assert err == "vampc rtl: a note\nthe result\n", repr(err)


def test_a_long_stage_shows_its_bar_once_the_delay_has_passed(monkeypatch, capsys):
    """A bar is drawn by tqdm only when it is updated: one long stage (rtl's Verilog, 76 s) showed
    nothing. It appears once DELAY has passed, its elapsed time moving, and is cleared at the end;
    a bar of one stage says no count of stages ("0/1 stages" never moved: a new user's find)."""
    import re
    import time

    from vampc import progress
    from vampc.cli import say
    monkeypatch.setenv("VAMPC_PROGRESS", "1")
    monkeypatch.setattr(progress, "DELAY", 0.2)
    drawn = re.compile(r"work \[\d\d:\d\d\], one")
    err = ""
    progress.begin()
    try:
        with progress.stages("work", ("one",)) as stage:
            stage("one")
            # one long step, no update: wait for the clock's draw, due 0.2 s in (a fixed 0.6 s
            # sleep saw no bar when a stall of the process outlasted it: the step ended first)
            deadline = time.monotonic() + 60
            while not drawn.search(err) and time.monotonic() < deadline:
                time.sleep(0.05)
                err += capsys.readouterr().err
        say("the result", err=True)
    finally:
        progress.end()
    err += capsys.readouterr().err
    assert drawn.search(err) and "stages" not in err, repr(err)
    assert err.split("\n")[-2].split("\r")[-1] == "the result", repr(err)    # cleared, not glued


def test_the_tick_engines_bar_counts_torque_sets():
    """The tick engine reported ticks to a bar counting sets: 6000 Puma sets showed '23552set'
    (a new user's find). It reports sets, never more than the run has."""
    from vampc.compiler import compile_chain
    from vampc.emulator.driver import States, run
    from vampc.emulator.load import loaded_from_compiled
    from vampc.robot import load_robot
    ld = loaded_from_compiled(compile_chain(load_robot(EXAMPLES / "planar2.yaml")), "<test>")
    seen = []
    run(ld, States.random(600, 0), engine="tick", progress=lambda done, total: seen.append((done, total)))
    assert seen and all(total == 600 and 0 <= done <= 600 for done, total in seen), seen[-3:]
    assert seen[-1][0] >= 500, seen[-3:]


def test_a_bar_whose_reader_is_gone_is_dropped_not_the_run(monkeypatch, tmp_path):
    """With progress on and standard error's reader gone (`2> >(head -c 150)`), a bar's redraw raised
    a broken pipe, in the clock thread and then in the command: exit 1, no file written (a review's
    find). The bars are dropped, as a warning is, and the run goes on."""
    import sys
    import time

    from vampc import progress

    class Gone:
        def __init__(self):
            self.fd = open(tmp_path / "stderr", "w")          # noqa: SIM115 (a real descriptor)

        def write(self, text):
            raise BrokenPipeError(32, "Broken pipe")

        def flush(self):
            raise BrokenPipeError(32, "Broken pipe")

        def fileno(self):
            return self.fd.fileno()

        def isatty(self):
            return False
    monkeypatch.setattr(sys, "stderr", Gone())
    monkeypatch.setenv("VAMPC_PROGRESS", "1")
    monkeypatch.setattr(progress, "DELAY", 0.0)
    with progress.stages("work", ("one", "two")) as stage:
        stage("one")
        time.sleep(1.2)                   # the clock redraws
        stage("two")
    with progress.counter("sets", 10) as update:
        update(5, 10)
    # standard error closed (2>&-): no bar at all, where isatty of None was an internal error
    monkeypatch.setattr(sys, "stderr", None)
    assert progress.enabled() is False


def test_an_encoding_that_cannot_hold_the_report_is_one_line(tmp_path):
    """PYTHONIOENCODING=latin-1 made `vampc report` an internal error (τ, µ): one line, exit 1."""
    import os
    done = subprocess.run([sys.executable, "-m", "vampc", "report", str(EXAMPLES / "planar2.yaml")],
                          capture_output=True, env={**os.environ, "PYTHONIOENCODING": "latin-1"})
    assert done.returncode == 1 and done.stdout == b"", done.stderr
    assert done.stderr == (b"vampc: error: cannot write to standard output: its encoding (latin-1) "
                           b"cannot hold '\\u03c4'; use a UTF-8 locale or PYTHONIOENCODING=utf-8\n")


def test_a_warning_raised_while_a_warning_is_said_does_not_recurse(monkeypatch):
    """click 8.5 deprecates get_text_stream, which say() called: the DeprecationWarning was said
    through say(), which warned again, without end: every command was an internal error in a fresh
    install (CI). A library's warning raised while one is said is dropped; the first is said."""
    import warnings

    from click.testing import CliRunner

    from vampc import cli
    real = cli.WholeText

    class Warns(real):
        def write(self, text):
            warnings.warn("a library's deprecation", DeprecationWarning, stacklevel=1)
            return super().write(text)
    monkeypatch.setattr(cli, "WholeText", Warns)
    r = CliRunner().invoke(cli.main, ["compile", str(EXAMPLES / "planar2.yaml"), "-o", "-"])
    assert r.exit_code == 0, r.output
    assert "vampc: warning: DeprecationWarning: a library's deprecation" in r.stderr, r.stderr


@pytest.mark.parametrize("check", [False, True])
def test_emulates_bar_says_when_it_counts_the_check_too(monkeypatch, check):
    """The check runs chunk by chunk beside the engine: the bar said "stream engine" for 3.6 s of a
    run whose engine took 0.52 s (a new user's find). With --check it says so."""
    from contextlib import contextmanager

    from click.testing import CliRunner

    from vampc import progress
    from vampc.cli import main
    labels = []

    @contextmanager
    def counter(label, total, unit="set"):
        labels.append(label)
        yield lambda done, total=None: None
    monkeypatch.setattr(progress, "counter", counter)
    r = CliRunner().invoke(main, ["emulate", str(EXAMPLES / "planar2.yaml"), "--random", "5",
                                  *(["--check"] if check else [])])
    assert r.exit_code == 0, r.output
    assert labels == (["stream engine and check"] if check else ["stream engine"]), labels


def test_a_note_says_what_the_running_stage_is_doing(monkeypatch, capsys):
    """`vampc compile --exact` spends minutes in its schedule stage, the solver at one interval
    after another; the bar said only "schedule". A note is drawn beside the stage's name, and the
    next stage's name replaces both; outside a bar a note is nothing."""
    import re
    import time

    from vampc import progress
    monkeypatch.setenv("VAMPC_PROGRESS", "1")
    monkeypatch.setattr(progress, "DELAY", 0.0)
    progress.note("no bar: nothing")
    err = ""
    noted = re.compile(r"work: 0/2 stages \[\d\d:\d\d\], one: --exact at interval 12")
    with progress.stages("work", ("one", "two")) as stage:
        stage("one")
        progress.note("--exact at interval 12")
        deadline = time.monotonic() + 60       # the clock draws it within a second
        while not noted.search(err) and time.monotonic() < deadline:
            time.sleep(0.05)
            err += capsys.readouterr().err
        stage("two")
        drawn = re.compile(r"work: 1/2 stages \[\d\d:\d\d\], two(?!:)")
        while not drawn.search(err) and time.monotonic() < deadline:
            time.sleep(0.05)
            err += capsys.readouterr().err
    err += capsys.readouterr().err
    assert noted.search(err) and drawn.search(err), repr(err)
    assert "no bar" not in err and progress._NOTES == []


def test_a_counters_clock_starts_with_the_work_it_counts(monkeypatch, capsys):
    """emulate's bar counted the static check of a big program (13 s) as the sets' time, `20/20
    [00:13, 1.39set/s]` for an engine of 0.64 s (a new user's find): an update to 0 of 0 starts
    its clock."""
    import re
    import time

    from vampc import progress
    monkeypatch.setenv("VAMPC_PROGRESS", "1")
    monkeypatch.setattr(progress, "DELAY", 0.0)
    with progress.counter("stream engine", 10) as update:
        time.sleep(2.2)                  # the loading and checking before the first set
        update(0, 10)
        time.sleep(0.3)
        update(10, 10)
    err = capsys.readouterr().err
    assert re.search(r"10/10 \[00:00", err) and not re.search(r"10/10 \[00:0[2-9]", err), err


def test_a_bar_is_drawn_on_a_terminal_that_says_it_has_no_columns():
    """A pty left at 0 × 0 (as `script` makes one): tqdm, told to follow the terminal's width, drew
    nothing, and a 104-second run showed no bar (a new user's find). It draws 80 columns there."""
    import fcntl
    import pty
    import select
    import struct
    import termios
    master, slave = pty.openpty()
    assert struct.unpack("HHHH", fcntl.ioctl(slave, termios.TIOCGWINSZ, b"\0" * 8))[:2] == (0, 0)
    code = ("import time\nimport vampc.progress as p\np.DELAY = 0\n"
            "with p.counter('sets', 20) as update:\n"
            "    for i in range(21):\n        update(i, 20)\n        time.sleep(0.02)\n")
    env = {k: v for k, v in os.environ.items() if k not in ("VAMPC_PROGRESS", "COLUMNS", "LINES")}
    proc = subprocess.Popen([sys.executable, "-c", code], stdin=subprocess.DEVNULL, stdout=slave,
                            stderr=slave, env=env)
    os.close(slave)
    out = b""
    while True:
        ready, _, _ = select.select([master], [], [], 10)
        if not ready:
            break
        try:
            chunk = os.read(master, 4096)
        except OSError:                       # (the pty closed: Linux says EIO)
            break
        if not chunk:
            break
        out += chunk
    os.close(master)
    assert proc.wait() == 0
    # a bar 80 columns wide, with its count (its last frame, 20/20, is drawn or not as tqdm's
    # throttle has it: on a loaded machine it was not, and the bar is cleared at its end)
    frames = [f.decode() for f in out.split(b"\r") if f.startswith(b"sets:")]
    assert frames and all(len(f) == 80 and "/20 [" in f for f in frames), out[-400:]


@pytest.mark.parametrize("command", ["emulate", "report"])
def test_reading_a_program_and_preparing_the_engine_show_bars(monkeypatch, tmp_path, command):
    """A 1000-joint log program: reading it took 4 s and the stream engine's static check and
    data flow 10 s more, under no bar (report) or a sets bar at 0 that said nothing of them
    (emulate; a new user's find). Each now has its bar."""
    from click.testing import CliRunner

    from vampc import progress
    from vampc.cli import main
    program = tmp_path / "p.vamp.json"
    assert CliRunner().invoke(main, ["compile", str(EXAMPLES / "planar2.yaml"), "-o",
                                     str(program)]).exit_code == 0
    monkeypatch.setenv("VAMPC_PROGRESS", "1")
    monkeypatch.setattr(progress, "DELAY", 0.0)
    args = ["--random", "3"] if command == "emulate" else []
    r = CliRunner().invoke(main, [command, str(program), *args])
    assert r.exit_code == 0, r.output
    assert "reading p.vamp.json [" in r.stderr, r.stderr
    if command == "emulate":
        assert "preparing the stream engine [" in r.stderr, r.stderr


def test_the_tick_engines_bar_moves_within_a_set(monkeypatch):
    """A 93 810-VAMP network's 3 sets on the tick engine showed 0/3 and an elapsed time stuck at
    00:00 for minutes (a new user's find): the engine reported whole sets every 1024 ticks, and a
    bar at 0 restarts its clock. It reports hundredths of a set, twice a second (here on a clock
    that moves 0.6 s each time it is read, as a big network's ticks take that long), and the whole
    run at its end."""
    import itertools
    import types

    from vampc.compiler import compile_chain
    from vampc.emulator import tick
    from vampc.emulator.driver import States, run
    from vampc.emulator.load import loaded_from_compiled
    from vampc.robot import load_robot
    ld = loaded_from_compiled(compile_chain(load_robot(EXAMPLES / "puma560.yaml")), "<test>")
    clock = itertools.count(0.0, 0.6)
    monkeypatch.setattr(tick, "time", types.SimpleNamespace(monotonic=lambda: next(clock)))
    seen = []
    run(ld, States.random(3, 0), engine="tick", progress=lambda done, total: seen.append(done))
    inside = [d for d in seen if 0 < d < 3]
    assert len(inside) >= 2 and any(d != int(d) for d in inside), seen
    assert seen == sorted(seen) and seen[-1] == 3, seen


def test_a_bar_of_uneven_things_shows_no_time_left(monkeypatch, capsys):
    """The trade-off's bar said 13 s left with 15 of 47 budgets done, of a run that took 50 s (its
    later budgets cost more: a new user's find): a bar of things that take uneven times shows the
    elapsed time alone; a bar of even ones its time left too."""
    from vampc import progress
    monkeypatch.setenv("VAMPC_PROGRESS", "1")
    monkeypatch.setattr(progress, "DELAY", 0.0)
    shown = {}
    progress.begin()
    try:
        for even in (True, False):
            with progress.counter("things", 4, unit="thing", even=even) as update:
                update(1, 4)
            shown[even] = capsys.readouterr().err
    finally:
        progress.end()
    assert "things:" in shown[True] and "4 [00:00<" in shown[True] and "thing/s" in shown[True], shown
    assert "things:" in shown[False] and "4 [00:00]" in shown[False], shown
    assert "<" not in shown[False] and "/s" not in shown[False], shown


def test_the_trade_offs_bar_is_one_of_uneven_things(monkeypatch):
    """(The bar above is the trade-off's: its budgets take uneven times.)"""
    import contextlib

    from click.testing import CliRunner
    from conftest import EXAMPLES

    from vampc import progress
    from vampc.cli import main
    asked = []
    real = progress.counter

    @contextlib.contextmanager
    def counter(label, total, unit="set", even=True):
        asked.append((label, even))
        with real(label, total, unit, even) as update:
            yield update
    monkeypatch.setattr(progress, "counter", counter)
    r = CliRunner().invoke(main, ["report", str(EXAMPLES / "planar2.yaml"), "--tradeoff",
                                  "--workers", "1", "--format", "csv"])
    assert r.exit_code == 0 and ("trade-off", False) in asked, (r.output, asked)
