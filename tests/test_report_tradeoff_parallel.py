"""`report --tradeoff` in parallel (issue "Fast at every size", part 4): local worker processes
(--workers) and a Dask cluster (--scheduler) give the points one process gives."""
from __future__ import annotations

import pytest
from click.testing import CliRunner

from vampc.cli import main
from vampc.compiler import CompileOptions
from vampc.errors import VampcError
from vampc.report import tradeoff as tr
from vampc.robot import load_robot


@pytest.mark.parametrize("recursion", ["linear", "log"])
def test_worker_processes_give_the_serial_points(recursion):
    chain = load_robot("examples/planar2.yaml")
    options = CompileOptions(recursion=recursion)
    seen = []
    serial = tr.tradeoff(chain, options, workers=1)
    parallel = tr.tradeoff(chain, options, progress=lambda done, total: seen.append((done, total)),
                           workers=2)
    assert parallel == serial and len(serial) > 3
    assert seen[-1][0] == seen[-1][1] and len(seen) == seen[-1][1]     # every budget reported


def test_a_dask_cluster_gives_the_serial_points():
    distributed = pytest.importorskip("distributed")
    runner = CliRunner()
    args = ["report", "examples/planar2.yaml", "--tradeoff", "--format", "json"]
    serial = runner.invoke(main, [*args, "--workers", "1"])
    with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False,
                                  dashboard_address=None) as cluster:
        r = runner.invoke(main, [*args, "--scheduler", cluster.scheduler_address])
    assert r.exit_code == 0 and serial.exit_code == 0, r.output
    assert r.output == serial.output


def test_an_unreachable_scheduler_is_one_line(monkeypatch):
    pytest.importorskip("distributed")
    monkeypatch.setattr(tr, "SCHEDULER_TIMEOUT", "1s")
    r = CliRunner().invoke(main, ["report", "examples/planar2.yaml", "--tradeoff", "--scheduler",
                                  "tcp://127.0.0.1:9"])
    assert r.exit_code == 1
    assert r.output.startswith("vampc: error: --scheduler tcp://127.0.0.1:9: cannot reach a Dask scheduler")
    assert len(r.output.strip().splitlines()) == 1


@pytest.mark.parametrize("args, message", [
    (["--workers", "2"], "--workers applies with --tradeoff"),
    (["--scheduler", "tcp://x:1"], "--scheduler applies with --tradeoff"),
    (["--tradeoff", "--workers", "2", "--scheduler", "tcp://x:1"], "--workers and --scheduler: give one"),
    (["--tradeoff", "--workers", "0"], "--workers"),
    (["--tradeoff", "--scheduler", "http://127.0.0.1:8786"], "http:// is not a Dask address"),
    # options the sweep's points do not depend on were taken and ignored (the same output)
    (["--tradeoff", "--error-correction", "--check-cycles", "4"], "--error-correction does not apply to --tradeoff"),
    (["--tradeoff", "--word", "q8.8", "--rounding", "truncate"], "does not apply to --tradeoff, whose points"),
])
def test_usage(args, message):
    r = CliRunner().invoke(main, ["report", "examples/planar2.yaml", *args])
    assert r.exit_code == 2 and message in r.output, r.output


def _ctrl_c_as_at_a_terminal():
    """Ctrl-C's default action in the child, whatever this process has: a test run started as a
    shell's background job (`pytest &`) ignores SIGINT, the child would inherit that, Python would
    then leave Ctrl-C ignored (as it should for a background job) and the sweep would run on."""
    import signal
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def test_ctrl_c_stops_the_workers_at_once(tmp_path):
    """The review found an interrupted sweep running on for 10 s (the pool waited for its queue,
    and each worker took Ctrl-C as one task's failure). Now: exit 130 within a second or so, and
    no worker left behind (the whole sweep takes about 13 s)."""
    import os
    import signal
    import subprocess
    import sys
    import time
    if not hasattr(os, "killpg") or not os.path.isdir("/proc"):
        pytest.skip("needs process groups and /proc")
    proc = subprocess.Popen([sys.executable, "-c", "from vampc.cli import main; main()", "report",
                             "examples/stanford.yaml", "--mult-latency", "3", "--tradeoff", "--workers", "2"],
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, start_new_session=True,
                            preexec_fn=_ctrl_c_as_at_a_terminal)

    def workers() -> list[str]:
        try:
            with open(f"/proc/{proc.pid}/task/{proc.pid}/children") as fh:
                return fh.read().split()
        except OSError:
            return []
    # Ctrl-C once the sweep's two workers run (a fixed 3 s wait could, on a loaded machine, land
    # while Python was still importing, before vampc's handler: a traceback, not 130)
    try:
        deadline = time.monotonic() + 120
        while len(workers()) < 2 and proc.poll() is None and time.monotonic() < deadline:
            time.sleep(0.05)
        assert len(workers()) >= 2, "the sweep started no workers"
        sent = time.perf_counter()
        os.killpg(proc.pid, signal.SIGINT)              # as a terminal's Ctrl-C does
        assert proc.wait(timeout=30) == 130
    finally:
        if proc.poll() is None:                         # (a failed check leaves no sweep running)
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    assert time.perf_counter() - sent < 3
    assert b"vampc: interrupted" in proc.stderr.read()
    time.sleep(0.3)
    left = []
    for entry in os.listdir("/proc"):
        try:
            with open(f"/proc/{entry}/stat") as fh:
                fields = fh.read().rsplit(")", 1)[1].split()
        except (OSError, IndexError):
            continue
        if int(fields[3]) == proc.pid:                  # the session the sweep started
            left.append(entry)
    assert not left


def test_an_empty_scheduler_address_is_a_usage_error():
    r = CliRunner().invoke(main, ["report", "examples/planar2.yaml", "--tradeoff", "--scheduler", ""])
    assert r.exit_code == 2 and "--scheduler: give the scheduler's address" in r.output


# Run in a process of its own: forking a pool inside a pytest-xdist worker (its channel threads and
# pipes copied into every child) once crashed that worker under the whole suite's load.
FORKED_CTRL_C = """
import json, multiprocessing, signal, time
from concurrent.futures import ProcessPoolExecutor
from vampc import errors, parallel

def square(context, item):
    return item * item

made = []
real = ProcessPoolExecutor.submit

def submit(self, *args, **kwargs):
    future = real(self, *args, **kwargs)
    made.append(future)
    if len(made) == 1:                                  # the workers are forked by now
        signal.getsignal(signal.SIGINT)(signal.SIGINT, None)      # Ctrl-C's handler runs here
    return future

ProcessPoolExecutor.submit = submit
signal.signal(signal.SIGINT, signal.default_int_handler)          # as at a terminal
try:
    parallel.run_tasks(square, None, list(range(8)), lambda i, r: None, workers=2)
    raised = False
except KeyboardInterrupt:
    raised = True
deadline = time.time() + 10
while multiprocessing.active_children() and time.time() < deadline:
    time.sleep(0.05)
print(json.dumps({"raised": raised, "made": len(made), "kept": list(errors._terminated),
                  "left": len(multiprocessing.active_children())}))
"""


def test_a_ctrl_c_while_the_workers_are_forked_waits_until_the_pool_knows_them():
    """Ctrl-C's handler running in the middle of the submissions (where the workers are forked)
    only notes it; the interrupt is raised once every submission is made, so the kill that
    follows reaches every worker, and none is left; nothing of it outlives the call."""
    import json
    import subprocess
    import sys
    done = subprocess.run([sys.executable, "-c", FORKED_CTRL_C], capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 0, done.stderr
    got = json.loads(done.stdout.strip().splitlines()[-1])
    assert got["raised"]
    assert got["made"] == 8                 # raised after the last submission
    assert got["kept"] == []                # nothing kept for a later call (a notebook's)
    assert got["left"] == 0                 # every worker killed


# Run in a process of its own, like FORKED_CTRL_C below: a worker killed inside a pytest-xdist
# worker's pool crashed that xdist worker once in CI ("node down: Not properly terminated").
WORKER_DIES = """
import os, signal
from vampc.errors import VampcError
from vampc.parallel import run_tasks

def dies(context, item):            # a worker killed as the out-of-memory killer would, on item 2
    if item == 2:
        os.kill(os.getpid(), signal.SIGKILL)
    return item

try:
    run_tasks(dies, None, list(range(6)), lambda i, r: None, workers=2)
except VampcError as exc:
    print("VampcError:", exc)
"""


def test_a_worker_that_dies_is_one_line():
    """A worker killed mid-sweep was a BrokenProcessPool traceback and exit 3 (internal error)."""
    import re
    import subprocess
    import sys
    done = subprocess.run([sys.executable, "-c", WORKER_DIES], capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 0 and done.stderr == "", done.stderr
    assert re.fullmatch(r"VampcError: a worker process ended before its task did \(.*\); "
                        r"nothing is written: run again, with fewer --workers if memory is short\n",
                        done.stdout), done.stdout


def test_the_cluster_librarys_own_log_is_quiet():
    """What the cluster does wrong is one line (the module's): distributed's loggers, some of which
    dask's configuration gives levels of their own, printed two tracebacks when the scheduler went
    away mid-sweep."""
    pytest.importorskip("distributed")
    import logging

    from vampc.errors import VampcError
    from vampc.parallel import connect
    with pytest.raises(VampcError, match="cannot reach a Dask scheduler there"):
        connect("tcp://127.0.0.1:1", timeout="1s")
    for name in ("distributed", "distributed.client", "distributed.core"):
        assert logging.getLogger(name).getEffectiveLevel() > logging.CRITICAL, name


def test_a_port_where_something_else_listens_is_one_line_within_the_deadline(monkeypatch):
    """A port that accepts the connection and never answers Dask's handshake (a web server) left
    Client waiting forever, its timeout unheeded: the connection now has an overall deadline."""
    pytest.importorskip("distributed")
    import socket
    import time

    from vampc import parallel
    monkeypatch.setattr(tr, "SCHEDULER_TIMEOUT", "1s")
    monkeypatch.setattr(parallel, "CONNECT_GRACE", 1.0, raising=False)
    with socket.socket() as listener:
        listener.bind(("127.0.0.1", 0))
        listener.listen(4)                      # accepts (the kernel's backlog), never answers
        address = f"tcp://127.0.0.1:{listener.getsockname()[1]}"
        start = time.monotonic()
        r = CliRunner().invoke(main, ["report", "examples/planar2.yaml", "--tradeoff", "--scheduler",
                                      address])
        took = time.monotonic() - start
    assert r.exit_code == 1 and r.stderr == (
        f"vampc: error: --scheduler {address}: cannot reach a Dask scheduler there (no Dask answer "
        "in 2 s: does something else listen on that port?)\n"), r.stderr
    assert took < 30


def test_a_port_where_another_protocol_answers_says_so(monkeypatch):
    """A web server's 400 read by Dask as a frame length: "cannot reach a Dask scheduler there
    (MemoryError: Unable to allocate 3.07 EiB ...)" (a new user's). It says what answers is not
    Dask."""
    pytest.importorskip("distributed")
    import socket
    import threading

    from vampc import parallel
    monkeypatch.setattr(tr, "SCHEDULER_TIMEOUT", "5s")
    listener = socket.socket()
    listener.bind(("127.0.0.1", 0))
    listener.listen(4)
    address = f"tcp://127.0.0.1:{listener.getsockname()[1]}"
    stop = threading.Event()

    def answer() -> None:
        listener.settimeout(0.2)
        while not stop.is_set():
            try:
                conn, _ = listener.accept()
            except OSError:
                continue
            with conn:
                conn.settimeout(1.0)
                try:
                    conn.recv(65536)
                    conn.sendall(b"HTTP/1.1 400 Bad Request\r\nconnection: close\r\n"
                                 b"content-length: 0\r\n\r\n")
                except OSError:
                    pass
    server = threading.Thread(target=answer, daemon=True)
    server.start()
    try:
        with pytest.raises(VampcError) as info:
            parallel.connect(address, "5s")
    finally:
        stop.set()
        server.join()
        listener.close()
    assert str(info.value) == (f"--scheduler {address}: cannot reach a Dask scheduler there (what "
                               "answers is not Dask: does something else listen on that port?)")


def test_a_cluster_that_fails_mid_run_says_what_is_kept(monkeypatch):
    """A campaign whose scheduler went away said only Dask's words, while its runs were kept (a new
    user's): the message says what is kept, as a dead local worker's does."""
    from vampc import parallel

    class Gone:
        def scatter(self, *args, **kwargs):
            raise OSError("scheduler-connection-lost")

        def close(self):
            pass
    with pytest.raises(VampcError) as info:
        parallel.run_tasks(lambda c, i: i, None, [1, 2], lambda *a: None, scheduler="tcp://h:1",
                           client=Gone(), kept="the runs finished are kept in r.jsonl")
    assert str(info.value) == ("--scheduler tcp://h:1: the cluster failed (OSError: "
                               "scheduler-connection-lost); the runs finished are kept in r.jsonl")


@pytest.mark.skipif(not __import__("sys").platform.startswith("linux"), reason="PR_SET_PDEATHSIG")
def test_workers_end_when_their_parent_is_killed_outright(tmp_path):
    """A parent killed with SIGKILL (the out-of-memory killer) left its --workers processes
    waiting forever, idle, their parent PID 1: they now end with it."""
    import os
    import signal
    import subprocess
    import sys
    import time
    snake = tmp_path / "snake32.yaml"
    snake.write_text(subprocess.run([sys.executable, "examples/make_snake.py", "32"],
                                    capture_output=True, text=True, check=True).stdout)
    proc = subprocess.Popen([sys.executable, "-m", "vampc", "report", str(snake), "--tradeoff",
                             "--workers", "2"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)

    def children() -> list[int]:
        try:
            with open(f"/proc/{proc.pid}/task/{proc.pid}/children") as fh:
                return [int(x) for x in fh.read().split()]
        except OSError:
            return []
    deadline = time.monotonic() + 60
    while len(children()) < 2 and time.monotonic() < deadline and proc.poll() is None:
        time.sleep(0.2)
    workers = children()
    assert len(workers) >= 2, "the sweep started no workers"
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    deadline = time.monotonic() + 20
    while time.monotonic() < deadline:
        alive = [w for w in workers if os.path.exists(f"/proc/{w}") and
                 open(f"/proc/{w}/stat").read().split()[2] != "Z"]
        if not alive:
            break
        time.sleep(0.2)
    assert not alive, f"workers {alive} outlived their parent"


def test_a_programs_error_correction_and_word_are_said_to_be_left_out(tmp_path):
    """A robot file's --error-correction and --word are refused with --tradeoff, but a program
    compiled with them was swept without a word about either (a --bus mlb one was warned of)."""
    for args, said in ((["--error-correction"], "has error correction: the trade-off sweeps its "
                                                "robot's budgets without it"),
                       (["--word", "q16.16"], "computes in q16.16: the trade-off's figures (flops, "
                                              "VAMPs) are the same in every word"),
                       ([], None)):
        program = tmp_path / "p.vamp.json"
        assert CliRunner().invoke(main, ["compile", "examples/planar2.yaml", *args, "-o",
                                         str(program)]).exit_code == 0
        r = CliRunner().invoke(main, ["report", str(program), "--tradeoff", "--workers", "1"])
        assert r.exit_code == 0, r.stderr
        assert (said in r.stderr) if said else r.stderr == "", r.stderr


@pytest.mark.parametrize("address, says", [
    ("nonsense", "give the scheduler's host and port"), ("127.0.0.1", "give the scheduler's host and port"),
    ("tcp://127.0.0.1:99999", "the port 1 to 65535"), ("tcp://:8786", "give the scheduler's host")])
def test_an_address_that_cannot_be_a_schedulers_is_a_usage_error(address, says):
    """A name with no port or a port out of range waited for the connection's timeout (10 s),
    then said 'cannot reach', exit 1: a usage error at once. (inproc:// stays: a script running
    the command line beside its own in-process cluster uses it, as the tests do.)"""
    for command in (["report", "examples/planar2.yaml", "--tradeoff"], ["faults", "examples/planar2.yaml"]):
        r = CliRunner().invoke(main, [*command, "--scheduler", address])
        assert r.exit_code == 2 and says in r.stderr and r.stderr.count("\n") == 1, r.stderr


def test_an_ipv6_host_needs_its_brackets():
    """tcp://::1 read as host ':' and port 1, taken, then 'cannot reach' after the timeout."""
    r = CliRunner().invoke(main, ["report", "examples/planar2.yaml", "--tradeoff", "--scheduler",
                                  "tcp://::1"])
    assert r.exit_code == 2 and "an IPv6 host in brackets, tcp://[::1]:8786" in r.stderr, r.stderr


def test_the_sweep_checks_every_point_unless_no_verify(monkeypatch):
    """--verify (the default) was taken and ignored by --tradeoff, every stage run with verify=False:
    now each budget's network is checked (a check made to fail says so), not with --no-verify; the
    points are the same either way."""
    from vampc.errors import VampcInternalError
    from vampc.network.model import Network
    args = ["report", "examples/planar2.yaml", "--tradeoff", "--format", "csv", "--workers", "1"]
    checked = CliRunner().invoke(main, args)
    plain = CliRunner().invoke(main, [*args, "--no-verify"])
    assert plain.exit_code == 0 and checked.exit_code == 0 and checked.output == plain.output
    calls = []

    def failing(self, graph, sched):
        calls.append(len(self.vamps))
        raise VampcInternalError("the check ran")
    monkeypatch.setattr(Network, "verify", failing)
    assert CliRunner().invoke(main, [*args, "--no-verify"]).exit_code == 0 and not calls
    for given in ([], ["--verify"]):
        r = CliRunner().invoke(main, [*args, *given])
        assert r.exit_code != 0 and "the check ran" in r.output and calls, r.output


@pytest.mark.parametrize("address, says", [
    (" tcp://127.0.0.1:8786", "spaces round the address"),
    ("tcp://user@127.0.0.1:8786", "a Dask address has no user part"),
    ("inproc://x", "an inproc:// address is an in-process cluster's own"),
    ("TCP://127.0.0.1:8786", "Dask reads the scheme in lower case only; give tcp://127.0.0.1:8786"),
], ids=["spaces", "user", "inproc", "upper-case"])
def test_an_address_dask_would_fail_on_is_a_usage_error(address, says):
    """These passed the address check and failed in Dask with its exception's text, exit 1, after
    a wait for some ('tcp:// is not a Dask address' for the one with a space before it)."""
    for command in (["report", "examples/planar2.yaml", "--tradeoff"], ["faults", "examples/planar2.yaml"]):
        r = CliRunner().invoke(main, [*command, "--scheduler", address])
        assert r.exit_code == 2 and says in r.stderr and r.stderr.count("\n") == 1, r.stderr


def test_a_port_where_nothing_listens_is_said_to_refuse(monkeypatch):
    """Dask retried a refused connection for its whole timeout, then said it had timed out (12 s on
    tcp://127.0.0.1:1, an audit's): a refused connection is said as such, before Dask is asked."""
    pytest.importorskip("distributed")
    import socket
    monkeypatch.setattr(tr, "SCHEDULER_TIMEOUT", "3s")
    with socket.socket() as s:              # a port just freed: nothing listens there
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    for address in (f"tcp://127.0.0.1:{port}", f"127.0.0.1:{port}"):     # (Dask reads both)
        r = CliRunner().invoke(main, ["report", "examples/planar2.yaml", "--tradeoff",
                                      "--scheduler", address])
        assert r.exit_code == 1 and len(r.output.strip().splitlines()) == 1
        assert "cannot reach a Dask scheduler there (the connection was refused" in r.output


def test_a_scheduler_host_name_that_does_not_resolve_is_said_so(monkeypatch):
    """A host name that does not resolve (7 ms) was said as Dask's 10 s time-out (a new user's)."""
    pytest.importorskip("distributed")
    import socket

    def no_name(*a, **k):
        raise socket.gaierror(-2, "Name or service not known")
    monkeypatch.setattr(socket, "create_connection", no_name)
    r = CliRunner().invoke(main, ["report", "examples/planar2.yaml", "--tradeoff", "--scheduler",
                                  "tcp://nosuchhost.invalid:8786"])
    assert r.exit_code == 1 and len(r.output.strip().splitlines()) == 1
    assert "(the host name 'nosuchhost.invalid' does not resolve: Name or service not known)" \
        in r.output, r.output


def test_what_dask_says_is_said_in_plain_words_on_one_line():
    """New users' clusters: Dask's version table came out as one line of literal \\n, workers from
    a Python without vampc said only ModuleNotFoundError, and every worker restarting mid-run said
    FutureCancelledError "already forgotten"."""
    import re

    from vampc.cli import _library_text
    from vampc.parallel import _why
    mismatch = type("VersionMismatchWarning", (Warning,), {})
    assert _library_text(UserWarning, "two\nlines  of it") == "two lines of it"   # (no \n)
    assert _why(Exception(ModuleNotFoundError("No module named 'vampc'"))).startswith(
        ": the workers' Python cannot import vampc; install vampc")
    cancelled = type("FutureCancelledError", (Exception,), {})
    assert _why(cancelled("_budget_task-1 cancelled for reason: already forgotten.")).startswith(
        ": the cluster lost what this run had sent its workers")
    assert _why(OSError("Timed out")) == ""
    # Dask's own tables: workers of two versions, a package missing, no worker at all, notes
    versions = pytest.importorskip("distributed.versions")
    here = {"packages": {"numpy": "2.4.6", "msgpack": "1.0", "lz4": "4.0"}}
    scheduler = {"packages": {"numpy": "2.4.6", "msgpack": "1.1", "lz4": "4.1"}}
    workers = {"a": {"packages": {"numpy": "1.25", "msgpack": "1.0"}},
               "b": {"packages": {"numpy": "1.26", "msgpack": "1.0"}}}
    said = _library_text(mismatch, versions.error_message(scheduler, workers, here)["warning"])
    assert re.fullmatch(r"the cluster's Python packages are not this Python's \(lz4 4\.0 here, 4\.1 on "
                        r"the scheduler, missing on the workers; msgpack 1\.0 here, 1\.1 on the "
                        r"scheduler, 1\.0 on the workers; numpy 2\.4\.6 here, 2\.4\.6 on the scheduler, "
                        r"1\.2[56] or 1\.2[56] on the workers\): vampc's tasks run on the workers, "
                        r"which need vampc and what it needs, as installed here", said), said
    said = _library_text(mismatch, versions.error_message(scheduler, {}, here)["warning"])
    assert said == ("the cluster's Python packages are not this Python's (lz4 4.0 here, 4.1 on the "
                    "scheduler, no worker to ask; msgpack 1.0 here, 1.1 on the scheduler, no worker "
                    "to ask)"), said
    noted = versions.error_message(scheduler, {}, here)["warning"] + "\nNotes: \n-  lz4: ok to vary"
    assert _library_text(mismatch, noted).endswith("; Dask's notes: - lz4: ok to vary")   # (one space)


def test_an_inproc_address_from_a_command_and_ucx_without_its_support_are_said_so():
    """`--scheduler inproc://...` from a shell got Dask's "does not match host or pid", and `ucx://`
    without its package "Can't instantiate abstract class UCXConnector" (a new user's)."""
    pytest.importorskip("distributed")
    from vampc.parallel import _protocol_hint
    res = CliRunner().invoke(main, ["report", "examples/planar2.yaml", "--tradeoff",
                                    "--scheduler", "inproc://127.0.0.1/1/1"])
    assert res.exit_code == 1 and res.stderr.count("\n") == 1, res.output
    assert res.stderr.rstrip().endswith(
        ": an inproc:// cluster runs inside one Python process and is reached only from that "
        "process (vampc's API called there), not from a command"), res.stderr
    assert _protocol_hint("ucx://h:1", TypeError("Can't instantiate abstract class UCXConnector")) \
        .startswith(": ucx:// needs Dask's UCX support installed")
    assert _protocol_hint("ucxx://h:1", ValueError("unknown address scheme 'ucxx'")) \
        .startswith(": ucxx:// needs Dask's UCX support installed")
    assert _protocol_hint("tcp://h:1", OSError("Timed out")) == ""
    res = CliRunner().invoke(main, ["report", "examples/planar2.yaml", "--tradeoff", "--scheduler",
                                    "inproc://x"])          # (the usage error says it too)
    assert res.exit_code == 2 and "reached only from that process (vampc's API called there), not " \
        "from a command" in res.output, res.output



def test_more_workers_than_cores_is_warned_of(monkeypatch):
    """--workers 1000 on a 2-core machine forked a process per task, each with its own memory,
    unsaid (report --tradeoff and faults check their --workers alike: check_parallel). Warned of,
    with the cores there are; as many as the cores, not."""
    import warnings
    from types import SimpleNamespace

    import vampc.background as background
    from vampc.errors import VampcWarning
    from vampc.options import check_parallel
    monkeypatch.setattr(background, "available_cores", lambda: 2)
    for workers, warned in ((3, True), (2, False), (None, False)):
        with warnings.catch_warnings(record=True) as seen:
            warnings.simplefilter("always")
            check_parallel(SimpleNamespace(workers=workers, scheduler=None))
        said = [str(w.message) for w in seen if issubclass(w.category, VampcWarning)]
        assert said == ([f"--workers {workers}: this machine gives vampc 2 cores; the workers share "
                         "them (no faster than 2) and each holds its own memory"] if warned else []), said
