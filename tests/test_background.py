"""Checks run in a forked process (vampc.background), and the report's use of it for big programs."""
from __future__ import annotations

import json
import os

import pytest
from click.testing import CliRunner
from conftest import EXAMPLES

from vampc import background
from vampc.cli import main
from vampc.errors import VampcError, VampcInternalError
from vampc.program.file import checksum

FORKS = hasattr(os, "fork")


def ok():
    pass


def user_error(what):
    raise VampcError(what)


def crash():
    raise ZeroDivisionError("boom")


def test_inline_runs_at_once():
    with pytest.raises(VampcError, match="^now$"):
        background.in_background(user_error, "now", inline=True)
    background.in_background(ok, inline=True).wait()


@pytest.mark.skipif(not FORKS, reason="no os.fork here")
def test_a_forked_check_reports_its_error_when_waited_for():
    pending = background.in_background(user_error, "the wiring has a loop")
    assert pending.pid is not None
    with pytest.raises(VampcError, match="^the wiring has a loop$"):
        pending.wait()
    background.in_background(ok).wait()


@pytest.mark.skipif(not FORKS, reason="no os.fork here")
def test_a_crash_in_the_child_is_an_internal_error_with_its_traceback():
    with pytest.raises(VampcInternalError, match="ZeroDivisionError: boom"):
        background.in_background(crash).wait()


def test_vampc_fork_0_runs_inline(monkeypatch):
    monkeypatch.setenv("VAMPC_FORK", "0")
    assert background.in_background(ok).pid is None


@pytest.mark.skipif(not FORKS, reason="no os.fork here")
def test_a_rewired_big_program_is_refused_and_nothing_written(tmp_path, monkeypatch):
    import vampc.commands as commands
    monkeypatch.setattr(commands, "BACKGROUND_CHECK_SLOTS", 0)       # every program is "big"
    runner = CliRunner()
    program = tmp_path / "p.vamp.json"
    compiled = runner.invoke(main, ["compile", str(EXAMPLES / "planar2.yaml"), "-o", str(program)])
    assert compiled.exit_code == 0
    picture = tmp_path / "t.svg"
    good = runner.invoke(main, ["report", str(program), "--timing", str(picture)])
    assert good.exit_code == 0 and picture.exists()
    picture.unlink()
    doc = json.loads(program.read_text())
    doc["network"]["vamps"][5]["b"] = doc["network"]["vamps"][6]["b"]
    doc["checksum"] = checksum(doc)
    program.write_text(json.dumps(doc))
    res = runner.invoke(main, ["report", str(program), "--timing", str(picture)])
    assert res.exit_code == 1 and res.stdout == ""
    assert res.stderr.startswith("vampc: error: ") and len(res.stderr.splitlines()) == 1
    assert "VAMP" in res.stderr and not picture.exists()


@pytest.mark.skipif(not FORKS, reason="no os.fork here")
def test_an_abandoned_check_is_stopped_and_reaped():
    import time
    pending = background.in_background(time.sleep, 60)
    pid = pending.pid
    pending.abandon()
    assert pending.pid is None
    with pytest.raises(ChildProcessError):
        os.waitpid(pid, os.WNOHANG)
    pending.wait()                                   # nothing left to wait for


@pytest.mark.skipif(not FORKS, reason="no os.fork here")
@pytest.mark.parametrize("big", [False, True], ids=["inline", "forked"])
def test_a_robot_reports_network_check_failure_stops_the_report(tmp_path, monkeypatch, big):
    # a robot file's network is checked beside the report when big (in line otherwise); a network
    # that fails its check gets no report and no picture, and --no-verify skips the check
    import vampc.commands as commands
    from vampc.network.model import Network
    if big:
        monkeypatch.setattr(commands, "BACKGROUND_CHECK_SLOTS", 0)
    runs = []
    real = Network.verify

    def broken(self, graph, sched):
        real(self, graph, sched)
        runs.append(os.getpid())
        raise VampcInternalError("the network check failed on purpose")
    monkeypatch.setattr(Network, "verify", broken)
    runner = CliRunner()
    picture = tmp_path / "t.svg"
    res = runner.invoke(main, ["report", str(EXAMPLES / "planar2.yaml"), "--timing", str(picture)])
    assert res.exit_code != 0 and res.stdout == "" and not picture.exists()
    assert "the network check failed on purpose" in res.stderr
    assert runs == ([] if big else [os.getpid()])        # a forked check ran in the child
    skipped = runner.invoke(main, ["report", str(EXAMPLES / "planar2.yaml"), "--no-verify",
                                   "--timing", str(picture)])
    assert skipped.exit_code == 0 and picture.exists()


@pytest.mark.skipif(not FORKS, reason="no os.fork here")
def test_a_wait_interrupted_then_abandoned_stops_the_child_without_an_error():
    """SIGTERM (an interrupt) while the report waited on its check: the pipe was closed by wait's
    `with`, and abandon closed it again: OSError EBADF, a traceback and exit 3 (a review's find)."""
    import signal
    import time

    def interrupt(*_):
        raise KeyboardInterrupt
    pending = background.in_background(time.sleep, 60)
    pid = pending.pid
    before = signal.signal(signal.SIGALRM, interrupt)
    try:
        signal.setitimer(signal.ITIMER_REAL, 0.3)
        with pytest.raises(KeyboardInterrupt):
            pending.wait()
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, before)
    pending.abandon()                                # (raised OSError: Bad file descriptor)
    assert pending.pid is None
    with pytest.raises(ChildProcessError):
        os.waitpid(pid, os.WNOHANG)


@pytest.mark.skipif(not FORKS, reason="no os.fork here")
def test_a_check_killed_before_it_reports_says_so():
    import signal
    import time
    pending = background.in_background(time.sleep, 60)
    os.kill(pending.pid, signal.SIGKILL)
    with pytest.raises(VampcInternalError, match="killed by SIGKILL before it could report"):
        pending.wait()


@pytest.mark.skipif(not FORKS, reason="no os.fork here")
def test_a_failing_network_check_is_reported_before_a_report_that_then_crashed(monkeypatch):
    # a broken network can crash the report's figures; the check's one line is what the user sees
    import vampc.commands as commands
    import vampc.report.build as build
    from vampc.network.model import Network
    monkeypatch.setattr(commands, "BACKGROUND_CHECK_SLOTS", 0)

    def broken(self, graph, sched):
        raise VampcError("VAMP 3: operand A is not wired")

    def crash(*args, **kwargs):
        raise IndexError("list index out of range")
    monkeypatch.setattr(Network, "verify", broken)
    monkeypatch.setattr(build, "build_report", crash)
    res = CliRunner().invoke(main, ["report", str(EXAMPLES / "planar2.yaml")])
    assert res.exit_code == 1 and res.stderr == "vampc: error: VAMP 3: operand A is not wired\n"


@pytest.mark.skipif(not FORKS, reason="no os.fork here")
@pytest.mark.parametrize("how", ["terminated", "error", "interrupted"])
def test_a_command_that_ends_early_stops_the_check_it_started(how):
    """A SIGTERM while `report --tradeoff` waited for its check (or during the summary, before
    the report's own abandon) left the forked check running, orphaned, for 45 s at up to 4.7 GB (a
    file-safety audit): every command's ending stops and reaps the checks still running."""
    import time

    import click

    from vampc.cli import handle_errors
    from vampc.errors import Terminated
    started = []

    @click.command()
    @handle_errors
    def command():
        started.append(background.in_background(time.sleep, 60).pid)
        if how == "terminated":
            raise Terminated(15)
        if how == "interrupted":
            raise KeyboardInterrupt
        raise VampcError("something else went wrong")
    r = CliRunner().invoke(command, [])
    assert r.exit_code == {"terminated": 143, "error": 1, "interrupted": 130}[how], r.output
    with pytest.raises(ChildProcessError):          # reaped: no child of that number is left
        os.waitpid(started[0], os.WNOHANG)
    assert not background._LIVE
