"""Nothing lost, nothing silent (issue 8): output-path safety, one-line errors for a user's mistakes,
no silently ignored option, no silently wrong number, named joints in every file."""
from __future__ import annotations

import contextlib
import json
import os
import re
import stat
import sys
import threading
import zipfile
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from conftest import ARM1, EXAMPLES
from program_util import edited_program

from vampc.cli import main
from vampc.dynamics.reference import rnea
from vampc.emulator import driver
from vampc.emulator.host import CheckResult
from vampc.errors import VampcError
from vampc.robot import load_robot

PLANAR = EXAMPLES / "planar2.yaml"
ARM6 = EXAMPLES / "arm6.urdf"
ERROR = re.compile(r"^vampc: error: [^\n]+\n$")
IS_ROOT = hasattr(os, "geteuid") and os.geteuid() == 0


def run(*args, input=None):
    """The CLI in process; stdout and stderr apart."""
    return CliRunner().invoke(main, [str(a) for a in args], input=input)


def user_error(res, pattern: str) -> None:
    """Exit 1 with exactly one stderr line `vampc: error: ...` matching `pattern` (a regex)."""
    assert res.exit_code == 1, (res.stdout, res.stderr)
    assert ERROR.match(res.stderr), res.stderr
    assert re.search(pattern, res.stderr), res.stderr
    assert "Traceback" not in res.stderr and "internal error" not in res.stderr


@pytest.fixture(scope="module")
def program(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("prog") / "planar.vamp.json"
    assert run("compile", PLANAR, "-o", path).exit_code == 0
    return path


@pytest.fixture
def robot(tmp_path) -> Path:
    path = tmp_path / "robot.yaml"
    path.write_bytes(PLANAR.read_bytes())
    return path


def _csv(path: Path, text: str | bytes) -> Path:
    if isinstance(text, str):
        text = text.encode()
    path.write_bytes(text)
    return path


HEAD = "q1,q2,qd1,qd2,qdd1,qdd2\n"
ROW = "0.1,0.2,0.3,0.4,0.5,0.6\n"


# --- 1. never destroy what the user did not ask to replace -------------------------------------------

def test_compile_refuses_to_write_over_its_robot_file(robot):
    before = robot.read_bytes()
    res = run("compile", robot, "-o", robot)
    user_error(res, rf"^vampc: error: {re.escape(str(robot))}: -o is the input file "
                    rf"{re.escape(str(robot))}; vampc never writes over its inputs$")
    assert robot.read_bytes() == before


@pytest.mark.parametrize("link", ["symlink", "hardlink"])
def test_an_input_reached_through_a_link_is_refused_too(robot, tmp_path, link):
    other = tmp_path / "other.yaml"
    (os.symlink if link == "symlink" else os.link)(robot, other)
    before = robot.read_bytes()
    res = run("compile", robot, "-o", other)
    words = "through a symlink" if link == "symlink" else "a hard link to it"
    user_error(res, rf"-o is the input file .*robot\.yaml \({words}\); vampc never writes over")
    assert robot.read_bytes() == before and (other.is_symlink() == (link == "symlink"))


@pytest.mark.parametrize("which", ["-o", "--vcd", "--save-states"])
def test_emulate_outputs_never_overwrite_the_program_or_the_trajectory(tmp_path, program, which):
    traj = _csv(tmp_path / "traj.csv", HEAD + ROW)
    prog = tmp_path / "p.vamp.json"
    prog.write_bytes(program.read_bytes())
    for victim in (prog, traj):
        if which == "--save-states" and victim == prog:
            continue      # --save-states writes states, not a program (a .csv or .npy name)
        before = victim.read_bytes()
        extra = ["--engine", "tick"] if which == "--vcd" else []
        res = run("emulate", prog, "--trajectory", traj, which, victim, *extra)
        user_error(res, rf"{which} is the input file .*{victim.name}; vampc never writes over")
        assert victim.read_bytes() == before


def test_two_outputs_naming_one_file_are_refused(tmp_path, program):
    res = run("emulate", program, "--random", 3, "-o", tmp_path / "x.csv", "--save-states",
              tmp_path / "x.csv")
    user_error(res, r"x\.csv: --save-states and -o name the same file$")
    assert not (tmp_path / "x.csv").exists()


def test_two_outputs_may_share_dev_null(tmp_path, program):
    """/dev/null takes each write as it comes: '-o /dev/null --save-states /dev/null' was refused as
    naming the same file (a new user's run)."""
    res = run("emulate", program, "--random", 3, "-o", "/dev/null", "--save-states", "/dev/null")
    assert res.exit_code == 0, res.output


def test_a_symlink_output_is_written_through_and_stays_a_link(tmp_path, program):
    target, link = tmp_path / "tau.csv", tmp_path / "link.csv"
    target.write_text("old\n")
    link.symlink_to(target)
    assert run("emulate", program, "--random", 4, "-o", link).exit_code == 0
    assert link.is_symlink() and os.readlink(link) == str(target)
    assert target.read_text().startswith("tau_shoulder,tau_elbow\n")
    assert len(target.read_text().splitlines()) == 5


def test_a_fifo_is_written_as_a_stream_not_replaced(tmp_path, program):
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    got = []
    reader = threading.Thread(target=lambda: got.append(fifo.read_text()))
    reader.start()
    res = run("emulate", program, "--random", 3, "-o", fifo)
    reader.join(timeout=30)
    assert res.exit_code == 0, res.stderr
    assert stat.S_ISFIFO(os.stat(fifo).st_mode)
    assert got and got[0].startswith("tau_shoulder,tau_elbow\n") and len(got[0].splitlines()) == 4


@pytest.mark.skipif(not IS_ROOT, reason="creating a character device needs root")
def test_a_character_device_is_written_through_not_replaced(tmp_path, program):
    dev = tmp_path / "null"
    os.mknod(dev, 0o666 | stat.S_IFCHR, os.makedev(1, 3))     # a private /dev/null
    assert run("emulate", program, "--random", 3, "-o", dev).exit_code == 0
    assert run("compile", PLANAR, "-o", dev).exit_code == 0
    assert stat.S_ISCHR(os.stat(dev).st_mode)


def test_a_socket_is_refused_before_any_work_not_written_as_a_stream(tmp_path, program):
    """README "Output files": a character device or a FIFO is written as a stream; a folder, socket
    or block device is refused (a mutation audit: taken as a stream, a socket failed only after the
    emulation, with "No such device or address")."""
    import socket
    sock = tmp_path / "s.csv"
    with socket.socket(socket.AF_UNIX) as s:
        s.bind(str(sock))
        res = run("emulate", program, "--random", 3, "-o", sock)
        user_error(res, r"s\.csv: is not a regular file; give a file name for -o$")
        assert stat.S_ISSOCK(os.stat(sock).st_mode)


def test_standard_output_takes_the_torques_and_the_summary_goes_to_stderr(program):
    res = run("emulate", program, "--random", 3, "-o", "-")
    assert res.exit_code == 0
    assert res.stdout.splitlines()[0] == "tau_shoulder,tau_elbow" and len(res.stdout.splitlines()) == 4
    assert "stream engine: 3 torque sets" in res.stderr


def test_compile_to_standard_output(tmp_path):
    res = run("compile", PLANAR, "-o", "-")
    assert res.exit_code == 0 and '"vampc-program"' in res.stdout.splitlines()[2]
    assert res.stderr.startswith("-: 2 joints")


def test_an_unwritable_location_is_refused_before_any_work(tmp_path, program, monkeypatch):
    def never(*args, **kwargs):
        raise AssertionError("the emulation ran")
    monkeypatch.setattr(driver, "run", never)
    res = run("emulate", program, "--random", 10, "-o", tmp_path / "missing" / "tau.csv")
    user_error(res, r"tau\.csv: folder .*missing does not exist$")
    res = run("emulate", program, "--random", 10, "--engine", "tick", "--vcd", tmp_path)
    assert res.exit_code == 2           # a folder is not an output file (click says so)


def test_a_path_through_a_missing_folder_is_not_shortened_as_text(tmp_path, program, monkeypatch):
    """'nosuchdir/../x.csv' was resolved as text to './x.csv' and written there, exit 0, while
    the kernel opens no such path (a tester's find). An existing folder's '..' is followed."""
    monkeypatch.chdir(tmp_path)
    res = run("emulate", program, "--random", 3, "-o", "nosuchdir/../x.csv")
    user_error(res, r"nosuchdir/\.\./x\.csv: folder nosuchdir/\.\. does not exist$")
    assert not (tmp_path / "x.csv").exists()
    res = run("compile", PLANAR, "-o", "nosuchdir/../y.vamp.json")
    user_error(res, r"folder nosuchdir/\.\. does not exist$")
    assert not (tmp_path / "y.vamp.json").exists()
    (tmp_path / "real").mkdir()
    res = run("emulate", program, "--random", 3, "-o", "real/../x.csv")
    assert res.exit_code == 0 and (tmp_path / "x.csv").exists(), res.output


def test_a_default_output_in_a_folder_it_cannot_write_says_how_to_put_it_elsewhere(
        tmp_path, program, monkeypatch):
    """`vampc faults` in a read-only folder: "cannot write in folder ...: Read-only file system",
    its results file a default the user had not named (a new user's): it says to give --results.
    The same for compile's default program file; a name the user gave is told as before. (The
    folder is made read-only by the probe's own failure, as root writes where modes forbid.)"""
    import errno

    from vampc import outputs

    def read_only(path):
        raise OSError(errno.EROFS, "Read-only file system")
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(outputs, "_new_temporary", read_only)
    for args, said in (
            (("compile", PLANAR), r"planar2\.vamp\.json: cannot write in folder \S+: Read-only file "
             r"system \(the default program file: give -o FILE to write it elsewhere\)$"),
            (("faults", program, "--campaign", "random", "--count", 2, "--sets", 2),
             r"\.random\.faults\.jsonl: cannot write in folder \S+: Read-only file system \(the "
             r"default results file: give --results FILE to write it elsewhere\)$"),
            (("compile", PLANAR, "-o", "p.vamp.json"), r"p\.vamp\.json: cannot write in folder "
             r"\S+: Read-only file system$")):
        user_error(run(*args), said)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.skipif(IS_ROOT, reason="root writes in read-only folders")
def test_a_read_only_folder_is_refused_before_any_work(tmp_path, program):
    folder = tmp_path / "ro"
    folder.mkdir()
    folder.chmod(0o555)
    try:
        res = run("emulate", program, "--random", 10, "-o", folder / "tau.csv")
        user_error(res, r"cannot write in folder .*ro: Permission denied$")
    finally:
        folder.chmod(0o755)


def _failing_check(monkeypatch):
    def bad(chain, traj, tau, tol=1e-9):
        return CheckResult(1.0, 0.5, 0, False)
    monkeypatch.setattr(driver, "check_torques", bad)


def test_a_failed_check_does_not_replace_an_existing_torque_file(tmp_path, program, monkeypatch):
    _failing_check(monkeypatch)
    out = tmp_path / "tau.csv"
    out.write_text("precious\n")
    res = run("emulate", program, "--random", 3, "--check", "-o", out)
    assert res.exit_code == 1 and out.read_text() == "precious\n"
    assert "torques NOT written: the check failed and" in res.stderr
    assert "FAILED" in res.stdout
    res = run("emulate", program, "--random", 3, "--check", "-o", out, "--write-failed")
    assert res.exit_code == 1 and out.read_text().startswith("tau_shoulder")
    assert "although the check failed" in res.stderr


def test_a_failed_check_replaces_no_existing_output(tmp_path, program, monkeypatch):
    """Nor the states or the waveform beside the torques: the states file was replaced while the
    torques were kept, a pair that no longer matched."""
    _failing_check(monkeypatch)
    files = {"--save-states": tmp_path / "states.csv", "--vcd": tmp_path / "w.vcd", "-o": tmp_path / "tau.csv"}
    for path in files.values():
        path.write_text("precious\n")
    args = [x for option, path in files.items() for x in (option, path)]
    res = run("emulate", program, "--random", 3, "--check", "--engine", "tick", *args)
    assert res.exit_code == 1 and all(p.read_text() == "precious\n" for p in files.values())
    for what in ("states", "waveform", "torques"):
        assert f"{what} NOT written: the check failed and" in res.stderr, res.stderr
    res = run("emulate", program, "--random", 3, "--check", "--engine", "tick", *args, "--write-failed")
    assert res.exit_code == 1 and not any(p.read_text() == "precious\n" for p in files.values())


def test_a_failed_check_writes_a_new_file_and_says_so(tmp_path, program, monkeypatch):
    _failing_check(monkeypatch)
    out = tmp_path / "tau.csv"
    res = run("emulate", program, "--random", 3, "--check", "-o", out)
    assert res.exit_code == 1 and out.read_text().startswith("tau_shoulder")
    assert f"torques written to {out} although the check failed" in res.stderr


def test_write_failed_needs_check_and_output(program):
    assert run("emulate", program, "--random", 3, "--write-failed").exit_code == 2


@pytest.mark.parametrize("outputs", [["-o", "-"], ["--save-states", "-"],
                                     ["--engine", "tick", "--vcd", "-"]])
def test_write_failed_to_standard_output_only_does_not_apply(program, outputs):
    """Standard output is written whether the check fails or not, so --write-failed changed nothing
    there and was taken silently (lookahead refused it: an options audit's find)."""
    res = run("emulate", program, "--random", 3, "--check", *outputs, "--write-failed")
    assert res.exit_code == 2 and "to a file (standard output is never held back)" in res.stderr, \
        res.stderr


@pytest.mark.parametrize("option", ["-o", "--vcd", "--save-states"])
def test_a_full_device_is_one_line(program, option):
    if not os.path.exists("/dev/full"):
        pytest.skip("no /dev/full here")
    extra = ["--engine", "tick"] if option == "--vcd" else []
    res = run("emulate", program, "--random", 3, option, "/dev/full", *extra)
    user_error(res, r"^vampc: error: /dev/full: cannot write \w+: No space left on device$")


@pytest.mark.parametrize("command,option", [("emulate", "-o"), ("emulate", "--vcd"),
                                            ("emulate", "--save-states"), ("lookahead", "--torques"),
                                            ("lookahead", "-o")])
def test_a_full_device_prints_no_result(tmp_path, program, command, option):
    """An output that cannot be written ends the run with its error alone: the emulation's summary
    line and lookahead's violations report were on standard output before it (an audit's find;
    compile -o and report --timing already said nothing)."""
    if not os.path.exists("/dev/full"):
        pytest.skip("no /dev/full here")
    if command == "emulate":
        extra = ["--engine", "tick"] if option == "--vcd" else []
        res = run("emulate", program, "--random", 2, option, "/dev/full", *extra)
    else:
        puma = tmp_path / "puma.vamp.json"
        assert run("compile", EXAMPLES / "puma560.yaml", "-o", puma).exit_code == 0
        res = run("lookahead", puma, "--trajectory", EXAMPLES / "puma560-path.csv", "--rate", "1kHz",
                  "--window", 8, "--limits", EXAMPLES / "puma560-limits.csv", option, "/dev/full",
                  *(["--retime", "uniform"] if option == "-o" else []))
    user_error(res, r"^vampc: error: /dev/full: cannot write \w+: No space left on device$")
    assert res.stdout == "", res.stdout


def test_a_path_warning_comes_only_once_the_outputs_are_written(tmp_path):
    """lookahead's warning that a path's q̇ disagrees with its q came before an output that could
    not be written, beside the error (a review's find): with --torques /dev/full the error alone."""
    if not os.path.exists("/dev/full"):
        pytest.skip("no /dev/full here")
    import numpy as np
    rows = np.loadtxt(EXAMPLES / "puma560-path.csv", delimiter=",", skiprows=1)
    rows[:, 8] = 3 * rows[:, 8] + 0.5                  # qd2 no longer q2's rate of change
    path = tmp_path / "dis.csv"
    head = (EXAMPLES / "puma560-path.csv").read_text().splitlines()[0]
    np.savetxt(path, rows, delimiter=",", header=head, comments="", fmt="%.17g")
    puma = tmp_path / "puma.vamp.json"
    assert run("compile", EXAMPLES / "puma560.yaml", "-o", puma).exit_code == 0
    args = ("lookahead", puma, "--trajectory", path, "--rate", "1kHz", "--window", 8, "--limits",
            EXAMPLES / "puma560-limits.csv")
    said = run(*args)
    assert said.exit_code == 0 and "qd2" in said.stderr, said.stderr     # (it does disagree)
    res = run(*args, "--torques", "/dev/full")
    user_error(res, r"^vampc: error: /dev/full: cannot write \w+: No space left on device$")
    assert res.stdout == "", res.stdout


@pytest.mark.parametrize("option", ["-o", "--vcd", "--save-states"])
def test_a_full_disk_leaves_nothing_partial(tmp_path, program, monkeypatch, option):
    out = tmp_path / ("w.vcd" if option == "--vcd" else "out.csv")
    out.write_text("previous\n")
    real_fdopen = os.fdopen

    class Full:
        def __init__(self, fh):
            self.fh = fh

        def write(self, text):
            self.fh.write(text[: len(text) // 2])
            raise OSError(28, "No space left on device")

        def __getattr__(self, name):
            return getattr(self.fh, name)

    monkeypatch.setattr(os, "fdopen", lambda *a, **k: Full(real_fdopen(*a, **k)))
    extra = ["--engine", "tick"] if option == "--vcd" else []
    res = run("emulate", program, "--random", 3, option, out, *extra)
    user_error(res, rf"{out.name}: cannot write \w+: No space left on device \(the previous file "
                    r"is unchanged\)$")
    assert out.read_text() == "previous\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == [out.name]


@pytest.mark.parametrize("option", ["-o", "--save-states"])
@pytest.mark.parametrize("which", [".vampc-probe.", ".out.csv."])
def test_a_signal_landing_just_after_a_temporary_file_is_made_leaves_nothing(tmp_path, program,
                                                                              monkeypatch, option, which):
    """SIGTERM between the temporary file's creation and anything after it (the moment a loaded
    machine once caught: with worker threads running, holding the signal in the main thread did
    not stop its handler there) still leaves no file: the name is known before the file exists."""
    from vampc.errors import Terminated
    real_open = os.open

    def open_then_signal(path, flags, *args, **kwargs):
        fd = real_open(path, flags, *args, **kwargs)
        if flags & os.O_CREAT and Path(path).name.startswith(which):
            os.close(fd)                          # (this stand-in's own: not left open in the process)
            raise Terminated(15)                  # as the handler raises it, right after the file is made
        return fd

    monkeypatch.setattr(os, "open", open_then_signal)
    res = run("emulate", program, "--random", 3, option, tmp_path / "out.csv")
    assert res.exit_code == 128 + 15 and "terminated (SIGTERM)" in res.output, res.output
    assert list(tmp_path.iterdir()) == []


@pytest.mark.filterwarnings("ignore::pytest.PytestUnraisableExceptionWarning")   # the swallowing itself
@pytest.mark.parametrize("where", ["file", "stdout"])
def test_a_ctrl_c_swallowed_by_a_finaliser_still_stops_the_command(tmp_path, monkeypatch, where):
    """Ctrl-C's KeyboardInterrupt raised inside a __del__ (the garbage collector runs them anywhere)
    is printed and dropped by Python; vampc remembers the signal, so nothing is put in place or
    printed, and the exit is the interrupt's (a sweep once ran to the end and exited 0 after a
    Ctrl-C on a loaded machine)."""
    import signal

    import vampc.compiler
    from vampc import errors
    monkeypatch.setattr(errors, "_terminated", [])

    class Finaliser:
        def __del__(self):
            errors.interrupt(signal.SIGINT)        # what the handler does, landing in a finaliser

    real = vampc.compiler.program_chunks

    def program_chunks(c):
        Finaliser()                                # made and dropped: its __del__ runs here
        return real(c)

    monkeypatch.setattr(vampc.compiler, "program_chunks", program_chunks)
    out = tmp_path / "p.vamp.json"
    res = run("compile", PLANAR, "-o", "-" if where == "stdout" else out)
    assert res.exit_code == 130 and "vampc: interrupted" in res.output, res.output
    assert '"format"' not in res.output and list(tmp_path.iterdir()) == []


def test_the_program_file_keeps_the_permissions_of_the_file_it_replaces(tmp_path):
    out = tmp_path / "p.vamp.json"
    out.write_text("{}")
    out.chmod(0o640)
    assert run("compile", PLANAR, "-o", out).exit_code == 0
    assert stat.S_IMODE(os.stat(out).st_mode) == 0o640


# --- 3. no traceback for a user's mistake -------------------------------------------------------------

@pytest.mark.parametrize("raw,pattern", [
    (HEAD.encode() + b"0.1,0.\xff2,0,0,0,0\n", r"bad\.csv: line 2: byte 0xff is not UTF-8 \(the "
                                               r"trajectory must be UTF-8 text\)$"),
    ((HEAD + ROW).encode("utf-16"), r"bad\.csv: trajectory is UTF-16 text; save it as UTF-8$"),
    ((HEAD + ROW).encode("utf-32"), r"bad\.csv: trajectory is UTF-32 text; save it as UTF-8$"),
    (HEAD.encode() + "0.1,0.2,0,0,0,é\n".encode("latin-1"), r"line 2: byte 0xe9 is not UTF-8"),
    (__import__("gzip").compress((HEAD + ROW).encode(), mtime=0), r"bad\.csv: gzip-compressed; give the "
     r"trajectory as plain CSV \(decompress it first\)$"),   # (was: 'byte 0x8b is not UTF-8')
], ids=["byte-ff", "utf-16", "utf-32", "latin-1", "gzip"])     # (ids: the bytes made poor names)
def test_trajectory_not_utf8(tmp_path, program, raw, pattern):
    res = run("emulate", program, "--trajectory", _csv(tmp_path / "bad.csv", raw))
    user_error(res, pattern)


def test_program_file_not_utf8(tmp_path, program):
    bad = tmp_path / "bad.vamp.json"
    bad.write_bytes(program.read_bytes().replace(b'"planar2"', b'"planar\xff"', 1))
    user_error(run("emulate", bad, "--random", 1), r"bad\.vamp\.json: line \d+: byte 0xff is not "
                                                   r"UTF-8 \(the program file must be UTF-8 text\)$")


def test_program_file_nested_too_deeply(tmp_path):
    deep = tmp_path / "deep.vamp.json"
    deep.write_text("[" * 100_000 + "]" * 100_000)
    user_error(run("emulate", deep, "--random", 1), r"deep\.vamp\.json: not a vampc program file "
                                                    r"\(JSON nested too deeply\)$")
    user_error(run("report", deep), r"JSON nested too deeply")


def _npz(path: Path, **arrays) -> Path:
    np.savez(path, **arrays)
    return path


@pytest.mark.parametrize("make,pattern", [
    (lambda p: _npz(p / "t.npz", q=np.array([[1, 2]], dtype=object), qd=np.zeros((1, 2)),
                    qdd=np.zeros((1, 2))),
     r"t\.npz: array q: it holds Python objects \(dtype object\); save plain numbers$"),
    (lambda p: _npz(p / "t.npz", q=np.zeros((1, 2), complex), qd=np.zeros((1, 2)), qdd=np.zeros((1, 2))),
     r"t\.npz: array q is complex \(complex128\); states must be real numbers$"),
    (lambda p: _npz(p / "t.npz", q=np.array([["a", "b"]]), qd=np.zeros((1, 2)), qdd=np.zeros((1, 2))),
     r"t\.npz: array q holds str\w* values, not numbers$"),
    (lambda p: _npz(p / "t.npz", q=np.zeros((1, 2), bool), qd=np.zeros((1, 2)), qdd=np.zeros((1, 2))),
     r"t\.npz: array q holds bool values, not numbers$"),
    (lambda p: _npz(p / "t.npz", q=np.zeros((2, 2)), qd=np.zeros((2, 2)), qdd=np.zeros((2, 2)),
                    t=np.zeros(3)),
     r"t\.npz: array t has shape \(3,\); expected \(2,\)$"),
    (lambda p: (np.save(p / "t.npy", np.zeros((2, 6), complex)), p / "t.npy")[1],
     r"t\.npy: the array is complex \(complex128\); states must be real numbers$"),
    (lambda p: (np.save(p / "t.npy", np.zeros((2, 6), "datetime64[s]")), p / "t.npy")[1],
     r"t\.npy: the array holds datetime64\[s\] values, not numbers$"),
    (lambda p: (np.save(p / "t.npy", np.zeros((2, 6), object)), p / "t.npy")[1],
     r"t\.npy: not a numpy array file \(it holds Python objects \(dtype object\); save plain "
     r"numbers\)$"),
    (lambda p: _csv(p / "t.npz", "not a zip"), r"t\.npz: not a numpy \.npz archive \(it does not start "
     r"as numpy writes one: b'not a '\)"),
    (lambda p: _csv(p / "t.npy", b"\x93NUMPY\x01\x00v\x00{'descr': '<f8', 'fortran_order': False, "
                                 b"'shape': (2, 6), }" + b" " * 60 + b"\n" + b"\0" * 16),
     r"t\.npy: its header announces an array of shape \(2, 6\) \(96 bytes\) but the file holds "
     r"18 bytes of data \(truncated or damaged\)$"),
    (lambda p: (np.savez(p / "x.npz", q=np.zeros((1, 2)), qd=np.zeros((1, 2)), qdd=np.zeros((1, 2))),
                os.replace(p / "x.npz", p / "t.npy"), p / "t.npy")[2],
     r"t\.npy: a \.npz archive, not a \.npy array; rename it \.npz$"),
])
def test_numpy_files_of_the_wrong_kind(tmp_path, program, make, pattern):
    made = make(tmp_path)
    res = run("emulate", program, "--trajectory", made)
    user_error(res, pattern)
    # the file refused is not held open (an .npz archive named .npy was, by the archive np.load
    # opened, for as long as the error was kept: a library caller's leak)
    fds = "/proc/self/fd"
    if os.path.isdir(fds):
        held = []
        for fd in os.listdir(fds):
            try:
                held.append(os.readlink(f"{fds}/{fd}"))
            except OSError:          # (the listing's own descriptor, closed by now)
                pass
        assert str(made) not in held, held


@pytest.mark.filterwarnings("ignore:Duplicate name")
def test_a_damaged_npz_member(tmp_path, program):
    path = _npz(tmp_path / "t.npz", qd=np.zeros((1, 2)), qdd=np.zeros((1, 2)))
    with zipfile.ZipFile(path, "a") as z:      # a q.npy that is not an array (a second one: refused
        z.writestr("q.npy", b"garbage")        # as such, test_an_npz_holding_one_array_twice...)
    res = run("emulate", program, "--trajectory", path)
    user_error(res, r"t\.npz: (array q: |not a numpy \.npz file)")


@pytest.mark.parametrize("args", [["--seed", "-1"], ["--random", "0"], ["--random", str(10**30)],
                                  ["--random", "-5"]])
def test_bad_counts_are_usage_errors(program, args):
    args = args if "--random" in args else ["--random", "3", *args]
    res = run("emulate", program, *args)
    assert res.exit_code == 2 and "Traceback" not in res.output


def test_seed_without_random_or_tick_is_a_usage_error(tmp_path, program):
    traj = _csv(tmp_path / "t.csv", HEAD + ROW)
    res = run("emulate", program, "--trajectory", traj, "--seed", "3")
    assert res.exit_code == 2 and "--seed applies to --random and to the tick engine" in res.stderr


@pytest.mark.parametrize("action", ["ignore", "error"])
def test_a_warning_is_said_whatever_pythons_own_warning_filters_say(tmp_path, program, action):
    """README: something worth knowing that does not stop the work is one line `vampc: warning:
    ...`, and an option that has no effect is never silently ignored: Python's own filters
    (PYTHONWARNINGS, -W) neither drop it (ignore) nor make it an internal error (error). A mutation
    audit: without vampc's own filter, `ignore` dropped it and `error` was a traceback, exit 3."""
    import subprocess
    traj = _csv(tmp_path / "t.csv", HEAD + ROW)
    done = subprocess.run([sys.executable, "-m", "vampc", "emulate", str(program), "--trajectory",
                           str(traj), "--engine", "tick", "--seed", "7", "-o", str(tmp_path / "t.tau")],
                          capture_output=True, text=True,
                          env={**os.environ, "PYTHONWARNINGS": action, "VAMPC_PROGRESS": "0"})
    assert done.returncode == 0, done.stderr
    assert "vampc: warning: --seed 7: with --trajectory, and no --vcd or --fault, it has no " \
           "effect" in done.stderr and "Traceback" not in done.stderr, done.stderr
    assert (tmp_path / "t.tau").read_text().startswith("tau_shoulder,tau_elbow\n")


def test_seed_on_the_tick_engine_with_a_trajectory_alone_is_warned_of(tmp_path, program):
    """`--trajectory st.csv --engine tick --seed 7` gave the torques of any seed, unsaid (a new
    user's find): the seed fills the tick engine's power-on registers, which reach no torque; it
    shows with --vcd and --fault, and draws the states of --random."""
    traj = _csv(tmp_path / "t.csv", HEAD + ROW + ROW)
    said = "vampc: warning: --seed 7: with --trajectory, and no --vcd or --fault, it has no effect"
    outs = []
    for seed in ("7", "8"):
        out = tmp_path / f"tau{seed}.csv"
        res = run("emulate", program, "--trajectory", traj, "--engine", "tick", "--seed", seed,
                  "-o", out)
        assert res.exit_code == 0, res.output
        outs.append(out.read_bytes())
    assert outs[0] == outs[1]                # (what the warning says)
    assert res.stderr.count("vampc: warning:") == 1 and said.replace("7", "8", 1) in res.stderr, \
        res.stderr
    for args in (["--trajectory", traj, "--vcd", tmp_path / "w.vcd"],
                 ["--trajectory", traj, "--fault", "vamp=5,dead"], ["--random", "2"]):
        res = run("emulate", program, *args, "--engine", "tick", "--seed", "7", "-o",
                  tmp_path / "tau.csv")
        assert res.exit_code == 0 and "--seed" not in res.stderr, res.output


# --- --random N streams in chunks ------------------------------------------------------------------

def test_random_states_depend_on_position_not_on_chunking():
    chain = load_robot(PLANAR)
    whole = driver.random_states(chain, 0, 3000, seed=5)
    part = driver.random_states(chain, 1000, 1500, seed=5)
    assert np.array_equal(part.q, whole.q[1000:2500]) and np.array_equal(part.qdd, whole.qdd[1000:2500])
    assert not np.array_equal(driver.random_states(chain, 0, 10, seed=6).q, whole.q[:10])


def test_a_long_run_goes_in_bounded_chunks_and_equals_one_run(program, monkeypatch):
    from vampc.emulator import emulate, load_program
    ld = load_program(program)
    monkeypatch.setattr(driver, "chunk_size", lambda ld: 7)
    sizes, taus, states = [], [], []
    def sink(traj, tau):
        sizes.append(traj.count)
        taus.append(tau.copy())
        states.append(traj.q.copy())
    out = driver.run(ld, driver.States.random(50, 3), check=True, sink=sink)
    assert sizes == [7] * 7 + [1] and out.count == 50 and out.check.ok
    whole = driver.random_states(ld.chain, 0, 50, 3)
    assert np.array_equal(np.concatenate(states), whole.q)
    assert np.array_equal(np.concatenate(taus), emulate(ld, whole).tau)
    assert out.data_ticks == 49 * 4 + out.first_tick + 1


def test_chunks_keep_port_memory_bounded():
    from vampc.compiler import compile_chain, program_document
    from vampc.emulator import loaded_from_doc
    from vampc.robot.random import random_chain
    ld = loaded_from_doc(program_document(compile_chain(random_chain(40, 1))))
    size = driver.chunk_size(ld)
    per_set = 8 * sum(p.size for p in ld.net.ports)
    assert 1 <= size <= driver.MAX_CHUNK and size * per_set <= driver.CHUNK_BYTES


def test_tick_runs_that_cannot_fit_are_refused(program, monkeypatch):
    monkeypatch.setattr(driver, "_available_memory", lambda: 1 << 20)
    res = run("emulate", program, "--random", 100_000, "--engine", "tick")
    user_error(res, r"planar\.vamp\.json: 100000 torque sets need about [\d.]+ GiB in the tick "
                    r"engine \([\d.]+ GiB available\); run fewer sets or use --engine stream")


# --- 4. no silently ignored option, no silently wrong number ----------------------------------------

@pytest.mark.parametrize("command", ["report", "emulate"])
@pytest.mark.parametrize("args,pattern", [
    (["--recursion", "log"], r"--recursion log: .* was compiled with --recursion linear; compile "
                             r"options apply to robot files"),
    (["--mult-latency", "4"], r"--mult-latency 4: .* was compiled with --mult-latency 1"),
    # (the program is linear: it has no prefix; "was compiled with --prefix sklansky" misled)
    (["--prefix", "serial"], r"--prefix applies to the log recursion only; .* was compiled with "
                             r"--recursion linear"),
    (["--tip", "x"], r"--tip applies when compiling a robot file; .* is a program file"),
    (["--base", "x"], r"--base applies when compiling a robot file"),
    (["--lock", "j=1"], r"--lock applies when compiling a robot file"),
    (["--no-verify"], r"--no-verify applies when compiling a robot file"),   # (as typed: it said --verify)
])
def test_compile_options_on_a_program_file(program, command, args, pattern):
    extra = ["--random", "2"] if command == "emulate" else []
    res = run(command, program, *args, *extra)
    assert res.exit_code == 2 and re.search(pattern, res.stderr), res.stderr


def test_compile_options_that_agree_with_the_program_file_are_fine(program):
    assert run("report", program, "--recursion", "linear", "--mult-latency", "1").exit_code == 0


@pytest.mark.parametrize("command", ["compile", "report", "emulate"])
@pytest.mark.parametrize("option", [["--prefix", "kogge-stone"], ["--uniform-leaves"]])
def test_log_options_with_the_linear_recursion(tmp_path, command, option):
    extra = {"compile": ["-o", tmp_path / "x.vamp.json"], "emulate": ["--random", "2"]}.get(command, [])
    res = run(command, PLANAR, *option, *extra)
    assert res.exit_code == 2
    assert f"{option[0]} applies to the log recursion only (add --recursion log)" in res.stderr
    assert not (tmp_path / "x.vamp.json").exists()


def test_the_same_joint_locked_twice_with_different_values(tmp_path):
    res = run("compile", ARM6, "--lock", "flange=0.1", "--lock", "flange=0.2", "-o",
              tmp_path / "x.vamp.json")
    assert res.exit_code == 2 and "joint 'flange' is locked twice, at 0.1 and 0.2" in res.stderr


def test_a_numbering_file_with_more_numbers_than_vamps_warns(tmp_path):
    numbers = tmp_path / "n.txt"
    numbers.write_text("\n".join(str(k) for k in range(1, 71)) + "\n")
    res = run("compile", PLANAR, "--numbering", numbers, "-o", tmp_path / "p.vamp.json")
    assert res.exit_code == 0
    assert res.stderr == (f"vampc: warning: {numbers}: 70 VAMP numbers given, the network has 60 "
                          "VAMPs: the last 10 are not used\n")


@pytest.mark.parametrize("edit", ["a: 0.5", "mass: 1.5"])
def test_absurd_but_finite_inputs_give_an_error_not_nan_torques(tmp_path, edit):
    text = PLANAR.read_text()
    key = edit.split(":")[0]
    assert edit in text
    big = tmp_path / "big.yaml"
    big.write_text(text.replace(edit, f"{key}: 1.0e200" if key == "a" else f"{key}: 1.0e300"))
    out = tmp_path / "tau.csv"
    res = run("emulate", big, "--trajectory", _csv(tmp_path / "t.csv", HEAD + "0,0,1e200,1e200,0,0\n"),
              "--allow-out-of-limits", "-o", out)
    user_error(res, r"big\.yaml: set 1 \(line 2 of \S*t\.csv\), joint \d \((shoulder|elbow)\): the torque is -?(nan|inf) "
                    r"\(float64 overflow")
    assert not out.exists()


def test_a_bom_and_trailing_blank_lines_are_accepted(tmp_path, program):
    src = _csv(tmp_path / "t.csv", b"\xef\xbb\xbf" + (HEAD + ROW + "\n\n  \n").encode())
    res = run("emulate", program, "--trajectory", src, "-o", "-", "--check")
    assert res.exit_code == 0, res.stderr
    assert len(res.stdout.splitlines()) == 2


def test_an_invisible_character_in_a_header_is_shown_escaped(tmp_path, program):
    src = _csv(tmp_path / "t.csv", "q1\u200b,q2,qd1,qd2,qdd1,qdd2\n" + ROW)
    res = run("emulate", program, "--trajectory", src)
    user_error(res, r"t\.csv: header: column 1 is 'q1\\u200b', expected 'q1'")
    assert "\u200b" not in res.stderr


def test_report_recomputes_a_hand_edited_summary(tmp_path, program):
    def edit(doc):
        doc["summary"]["latency"] = {"flops": 7, "mults": 16, "adds": 45}
    res = run("report", edited_program(program, tmp_path, edit), "--format", "json")
    assert res.exit_code == 0
    assert json.loads(res.stdout)["latency"] == {"flops": 29, "mults": 8, "adds": 21, "waits": 0}
    assert res.stderr == ("vampc: warning: " + str(tmp_path / "edited.vamp.json") + ": the stored "
                          "summary disagrees with the file's graph, schedule and network (latency): "
                          "the file was edited; showing figures recomputed from them\n")


@pytest.mark.parametrize("change,section", [
    (lambda d: d["schedule"].update(latency=7), "schedule.latency"),
    (lambda d: d["schedule"]["finish"].__setitem__(-1, 99), "schedule.finish"),
])
def test_report_refuses_a_schedule_that_is_not_its_graphs(tmp_path, program, change, section):
    res = run("report", edited_program(program, tmp_path, change))
    user_error(res, rf"edited\.vamp\.json: {re.escape(section)} is not the schedule of the file's "
                    r"graph \(the file was edited\); recompile it$")


def test_report_of_a_rewired_program_is_refused(tmp_path, program):
    def rewire(doc):
        doc["network"]["vamps"][5]["b"] = doc["network"]["vamps"][6]["b"]
    res = run("report", edited_program(program, tmp_path, rewire))
    assert res.exit_code == 1 and "VAMP" in res.stderr


def test_reports_cite_only_what_ships():
    for args in (["report", EXAMPLES / "puma560.yaml"], ["report", PLANAR, "--recursion", "log"]):
        res = run(*args)
        assert res.exit_code == 0 and "DESIGN" not in res.stdout and "README" in res.stdout


# --- 5. which column is which joint --------------------------------------------------------------------

def test_report_lists_the_joints_in_order():
    res = run("report", ARM6, "--format", "json")
    rep = json.loads(res.stdout)
    assert rep["joint_names"] == ["waist", "shoulder", "elbow", "wrist_roll", "wrist_bend", "flange"]
    assert rep["joint_types"] == ["revolute"] * 6
    text = run("report", EXAMPLES / "stanford.yaml").stdout
    assert re.search(r"^joints +1 \S+ \(R\), 2 \S+ \(R\), 3 \S+ \(P\),", text, re.M)


def test_saved_states_pair_with_their_torques(tmp_path, program):
    states, tau = tmp_path / "s.csv", tmp_path / "tau.csv"
    assert run("emulate", program, "--random", 20, "--seed", 9, "--save-states", states, "-o",
               tau).exit_code == 0
    chain = load_robot(PLANAR)
    data = np.loadtxt(states, delimiter=",", skiprows=1)
    assert states.read_text().splitlines()[0] == HEAD.strip()
    q, qd, qdd = data[:, :2], data[:, 2:4], data[:, 4:]
    assert np.allclose(np.loadtxt(tau, delimiter=",", skiprows=1), rnea(chain, q, qd, qdd),
                       rtol=1e-12, atol=1e-12)
    again = tmp_path / "again.csv"      # and the saved file runs as a trajectory
    assert run("emulate", program, "--trajectory", states, "-o", again).exit_code == 0
    assert again.read_text() == tau.read_text()


def test_save_states_writes_csv_or_npy_not_npz(tmp_path, program):
    res = run("emulate", program, "--random", 2, "--save-states", tmp_path / "s.npz")
    assert res.exit_code == 2 and "not .npz" in res.output and not (tmp_path / "s.npz").exists()
    assert run("emulate", program, "--random", 2, "--save-states", tmp_path / "s.npy").exit_code == 0


@pytest.mark.parametrize("args, message", [
    # a .gz name was written as plain CSV; --allow-out-of-limits with random states did nothing
    (["-o", "tau.csv.gz"], "-o writes torques as CSV or, for a name ending in .npy, as a NumPy array: "
                           "not .gz (compress the file afterwards)"),
    (["--save-states", "s.csv.gz"], "--save-states writes a trajectory as CSV or, for a name ending in "
                                    ".npy, as a NumPy array: not .gz"),
    (["--allow-out-of-limits"], "--allow-out-of-limits applies with --trajectory"),
    # written as plain CSV under a compressed file's name, as .gz had been
    (["-o", "tau.csv.bz2"], "not .bz2 (compress the file afterwards)"),
    (["-o", "tau.csv.xz"], "not .xz (compress the file afterwards)"),
    (["--save-states", "s.zip"], "not .zip (compress the file afterwards)"),
    # options that change nothing here, and a waveform under a compressed file's name (a mutation
    # audit: each was taken in silence when unchecked)
    (["--vcd-as", "word"], "--vcd-as applies with --vcd"),
    (["--tolerance", "1e-3"], "--tolerance applies with --check"),
    (["--engine", "tick", "--vcd", "w.vcd.gz"], "--vcd writes a VCD text file: not .gz (compress "
                                                "the file afterwards)"),
])
def test_emulate_options_it_would_not_honour_are_usage_errors(tmp_path, program, args, message):
    res = run("emulate", program, "--random", 2, *[tmp_path / a if "." in a else a for a in args])
    assert res.exit_code == 2 and message in res.output, res.output
    assert list(tmp_path.iterdir()) == []


def test_a_program_file_given_to_compile(tmp_path, program):
    res = run("compile", program, "-o", tmp_path / "x.vamp.json")
    user_error(res, r"planar\.vamp\.json: this is a vampc program file, not a robot "
                    r"description; use `vampc emulate` or `vampc report` with it$")
    renamed = tmp_path / "prog.json"
    renamed.write_bytes(program.read_bytes())
    user_error(run("compile", renamed), r"prog\.json: this is a vampc program file, not a robot")


def test_a_program_file_without_its_suffix_still_runs(tmp_path, program):
    renamed = tmp_path / "prog.json"
    renamed.write_bytes(program.read_bytes())
    assert run("emulate", renamed, "--random", 2).exit_code == 0
    assert run("report", renamed).exit_code == 0


@pytest.mark.parametrize("name,content,pattern", [
    ("arm.txt", ARM6, r"arm\.txt: unknown robot file extension '\.txt' \(it looks like XML \(a "
                      r"URDF\)\)"),
    ("arm.yaml", ARM6, r"arm\.yaml: this is XML \(a URDF\?\), not a DH table; name it \.urdf"),
    ("planar.urdf", PLANAR, r"planar\.urdf: this is YAML, not XML; a DH table is named \.yaml"),
    ("planar.dat", PLANAR, r"planar\.dat: unknown robot file extension '\.dat' \(it looks like YAML "
                           r"\(a DH table\?\)\)"),
])
def test_a_robot_file_with_the_wrong_extension_says_what_it_looks_like(tmp_path, name, content,
                                                                        pattern):
    path = tmp_path / name
    path.write_bytes(content.read_bytes())
    user_error(run("compile", path, "-o", tmp_path / "x.vamp.json"), pattern)


def test_a_waveform_given_as_the_program_says_it_is_one(tmp_path, program):
    """`vampc emulate w.vcd` said the waveform looked like YAML (a DH table?) (a new user's)."""
    vcd = tmp_path / "w.vcd"
    assert run("emulate", program, "--random", 2, "--engine", "tick", "--vcd", vcd).exit_code == 0
    named = tmp_path / "w.urdf"
    named.write_bytes(vcd.read_bytes())
    user_error(run("compile", named), r"w\.urdf: this is a VCD waveform \(vampc emulate --vcd "
               r"writes them\), not a robot description")
    for args in (("emulate", vcd, "--random", 2), ("report", vcd)):
        user_error(run(*args), r"w\.vcd: unknown robot file extension '\.vcd' \(it looks "
                   r"like a VCD waveform \(vampc emulate --vcd writes them\)\)")


def test_the_printed_times_say_what_they_cover(program):
    res = run("emulate", program, "--random", 3)
    assert re.search(r"engine wall time [\d.]+ s \([\d,]+ sets/s\); whole command [\d.]+ s$",
                     res.stdout.strip())


# --- 6. progress ------------------------------------------------------------------------------------

def test_progress_is_drawn_by_tqdm_when_asked(program, monkeypatch):
    from vampc import progress
    monkeypatch.setenv("VAMPC_PROGRESS", "1")
    monkeypatch.setattr(progress, "DELAY", 0.0)
    res = run("emulate", program, "--random", 5000)
    assert res.exit_code == 0 and "stream engine:" in res.stderr and "/5000" in res.stderr  # (whole counts)
    res = run("compile", PLANAR, "-o", "-")
    assert "compiling planar2.yaml" in res.stderr


def test_no_progress_when_not_a_terminal(program, monkeypatch, tmp_path):
    monkeypatch.delenv("VAMPC_PROGRESS", raising=False)
    # (with -o: a run that writes no torques says so on stderr, test_cli_emulate's
    # test_a_run_that_writes_no_torques_says_so; here nothing at all is said there)
    res = run("emulate", program, "--random", 5000, "-o", tmp_path / "tau.csv")
    assert res.exit_code == 0 and res.stderr == ""


# --- trees and floating bases (issue 12) --------------------------------------------------------------

QUAD = EXAMPLES / "quadruped.urdf"
DH_ROW = ("{name: %s, type: revolute, %sa: 0.1, alpha: 0.3, d: 0.05, theta: 0, mass: 1, com: [0.05, 0, 0], "
          "inertia: [0.01, 0.01, 0.01, 0, 0, 0]}")


def _dh_tree(tmp_path, rows) -> Path:
    path = tmp_path / "tree.yaml"
    body = "\n".join("  - " + DH_ROW % (name, f"parent: {parent}, " if parent is not None else "")
                     for name, parent in rows)
    path.write_text(f"name: t\njoints:\n{body}\n")
    return path


def test_dh_parent_that_names_nothing(tmp_path):
    robot = _dh_tree(tmp_path, [("a", None), ("b", "nope")])
    user_error(run("compile", robot, "-o", tmp_path / "t.vamp.json"),
               r"tree\.yaml: joints\[1\]\.parent \(joint 2\): 'nope' names no joint$")
    assert not (tmp_path / "t.vamp.json").exists()


def test_dh_parent_row_number_out_of_range(tmp_path):
    robot = _dh_tree(tmp_path, [("a", None), ("b", 7)])
    user_error(run("compile", robot, "-o", tmp_path / "t.vamp.json"),
               r"joints\[1\]\.parent \(joint 2\): 7 is not a row number \(1\.\.2, or 0 for the base\)$")


def test_dh_parent_cycle(tmp_path):
    robot = _dh_tree(tmp_path, [("a", None), ("b", "c"), ("c", "b")])
    user_error(run("compile", robot, "-o", tmp_path / "t.vamp.json"),
               r"joints\[1\]\.parent \(joint 2\): parents form a cycle through joints 'b', 'c': none of "
               r"them reaches the base$")
    assert not (tmp_path / "t.vamp.json").exists()


def test_dh_tree_is_numbered_depth_first(tmp_path):
    robot = _dh_tree(tmp_path, [("torso", None), ("l1", "torso"), ("r1", "torso"), ("l2", "l1"), ("r2", 3)])
    rep = json.loads(run("report", robot, "--format", "json").stdout)
    assert rep["joint_names"] == ["torso", "l1", "l2", "r1", "r2"]
    assert rep["tree"]["parents"] == [0, 1, 2, 1, 4] and rep["tree"]["leaves"] == 2


def _urdf(tmp_path, text: str) -> Path:
    path = tmp_path / "robot.urdf"
    path.write_text(text)
    return path


LINK = '<link name="%s"><inertial><mass value="1"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>'
JOINT = '<joint name="%s" type="%s"><parent link="%s"/><child link="%s"/><axis xyz="0 0 1"/></joint>'


def test_urdf_two_roots(tmp_path):
    robot = _urdf(tmp_path, '<robot name="r">' + LINK % "a" + LINK % "b" + LINK % "c"
                  + JOINT % ("j", "revolute", "a", "c") + "</robot>")
    user_error(run("compile", robot, "-o", tmp_path / "r.vamp.json"),
               r"robot\.urdf: several root links \('a', 'b'\); choose one with --base$")


def test_urdf_floating_joint_not_at_the_root(tmp_path):
    robot = _urdf(tmp_path, '<robot name="r">' + LINK % "a" + LINK % "b" + LINK % "c" + LINK % "d"
                  + JOINT % ("j1", "revolute", "a", "b") + JOINT % ("free", "floating", "b", "c")
                  + JOINT % ("j2", "revolute", "c", "d") + "</robot>")
    user_error(run("compile", robot, "-o", tmp_path / "r.vamp.json"),
               r"robot\.urdf: joint 'free': a floating joint is taken only as the one joint of the root "
               r"link \(the base then floats; README, Trees and floating bases\), and this one is not; "
               r"--base c --floating-base floats 'c', what is above it left out$")
    assert not (tmp_path / "r.vamp.json").exists()
    # the way said works (it went unsaid: a new user's find)
    assert run("compile", robot, "--base", "c", "--floating-base", "-o", "-").exit_code == 0


def test_urdf_root_floating_joint_floats(tmp_path):
    robot = _urdf(tmp_path, '<robot name="r"><link name="world"/>' + LINK % "a" + LINK % "b"
                  + JOINT % ("free", "floating", "world", "a") + JOINT % ("j1", "revolute", "a", "b") + "</robot>")
    rep = json.loads(run("report", robot, "--format", "json").stdout)
    assert rep["tree"]["floating"] and rep["tree"]["outputs"] == 7


@pytest.fixture(scope="module")
def floating_program(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("quad") / "quad.vamp.json"
    assert run("compile", QUAD, "--floating-base", "--recursion", "log", "-o", path).exit_code == 0
    return path


def test_trajectory_missing_base_columns(floating_program, tmp_path):
    states = tmp_path / "states.csv"
    assert run("emulate", floating_program, "--random", "3", "--save-states", states).exit_code == 0
    head, *rows = states.read_text().splitlines()
    cut = tmp_path / "nobase.csv"
    cut.write_text("\n".join(",".join(line.split(",")[:36]) for line in [head] + rows) + "\n")
    user_error(run("emulate", floating_program, "--trajectory", cut, "-o", tmp_path / "tau.csv"),
               r"nobase\.csv: header: missing column base_wx \(a floating-base program needs the base's motion")
    assert not (tmp_path / "tau.csv").exists()


def test_floating_quadruped_end_to_end(floating_program, tmp_path):
    states, tau = tmp_path / "states.csv", tmp_path / "tau.csv"
    res = run("emulate", floating_program, "--random", "20", "--check", "--save-states", states, "-o", tau)
    assert res.exit_code == 0, res.stderr
    head = tau.read_text().splitlines()[0].split(",")
    assert head[:2] == ["tau_FL_HAA", "tau_FL_HFE"] and head[-6:] == ["base_fx", "base_fy", "base_fz",
                                                                      "base_nx", "base_ny", "base_nz"]
    tick = run("emulate", floating_program, "--trajectory", states, "--engine", "tick", "-o", tmp_path / "t2.csv")
    assert tick.exit_code == 0 and (tmp_path / "t2.csv").read_text() == tau.read_text()


def test_floating_base_option_applies_to_robot_files(floating_program):
    res = run("emulate", floating_program, "--random", "2", "--floating-base")
    assert res.exit_code == 2 and "--floating-base applies when compiling a robot file" in res.stderr


@pytest.mark.parametrize("args", [("compile", PLANAR, "-o", ""), ("compile", ""),
                                  ("report", PLANAR, "--timing", " ")])
def test_an_empty_file_name_is_a_usage_error(args, tmp_path, monkeypatch):
    """`-o "$UNSET"` must not fall back on the default name (or the current folder)."""
    monkeypatch.chdir(tmp_path)
    res = run(*args)
    assert res.exit_code == 2 and "an empty file name" in res.stderr, res.stderr
    assert list(tmp_path.iterdir()) == []


def test_a_read_only_file_is_kept_even_for_root(tmp_path):
    """The owner's write bit decides, not os.access (which lets root write anything)."""
    target = tmp_path / "kept.vamp.json"
    target.write_text("mine\n")
    target.chmod(0o444)
    res = run("compile", PLANAR, "-o", target)
    user_error(res, r"kept\.vamp\.json: exists and is read-only; vampc does not replace it$")
    assert target.read_text() == "mine\n"


def test_a_writable_file_on_a_read_only_file_system_is_said_so(tmp_path, monkeypatch):
    """A file of mode 644 on a file system mounted read-only was said to exist and be read-only
    (a new user's find, on a read-only bind mount): the file system is. (The kernel's answers for
    such a mount, os.access and statvfs's ST_RDONLY, are given here: mounting needs root.)"""
    import os
    target = tmp_path / "kept.vamp.json"
    target.write_text("mine\n")
    real_access, real_statvfs = os.access, os.statvfs

    class ReadOnly:
        def __init__(self, real):
            self.f_flag = real.f_flag | os.ST_RDONLY
    monkeypatch.setattr(os, "access", lambda p, mode, **k: False if str(p) == str(target) and
                        mode == os.W_OK else real_access(p, mode, **k))
    monkeypatch.setattr(os, "statvfs", lambda p: ReadOnly(real_statvfs(p)) if str(p) == str(target)
                        else real_statvfs(p))
    res = run("compile", PLANAR, "-o", target)
    user_error(res, r"kept\.vamp\.json: is on a read-only file system; vampc cannot replace it$")
    assert target.read_text() == "mine\n"


def test_the_default_output_onto_an_input_is_said_as_the_default(tmp_path, monkeypatch):
    """`vampc compile planar2.yaml --numbering planar2.vamp.json` (the default program file's name)
    was refused saying "-o is the input file", an option the user never gave (a new user's find)."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "planar2.yaml").write_bytes(PLANAR.read_bytes())
    numbering = tmp_path / "planar2.vamp.json"
    numbering.write_text("".join(f"{k}\n" for k in range(1, 61)))
    res = run("compile", "planar2.yaml", "--numbering", "planar2.vamp.json")
    user_error(res, r"planar2\.vamp\.json: the default program file is the input file "
                    r"planar2\.vamp\.json; vampc never writes over its inputs \(give -o FILE to write "
                    r"it elsewhere\)$")
    assert numbering.read_text() == "".join(f"{k}\n" for k in range(1, 61))


@pytest.mark.parametrize("args, message", [
    ((PLANAR, "--lock", "shoulder=0"), "--lock applies to URDF and MJCF files only"),
    ((PLANAR, "--base", "a", "--tip", "b"), "--base, --tip apply to URDF and MJCF files only"),
    ((EXAMPLES / "quadruped.urdf", "--lock", "x=nan"), "the position must be a finite number"),
    # float() read '1_0' as 10 and '١' as 1, which every other number option refuses
    ((EXAMPLES / "arm6.urdf", "--lock", "waist=1_0"), "'waist=1_0': '1_0' is not a number written in ASCII digits"),
    ((EXAMPLES / "arm6.urdf", "--lock", "waist=١"), "'waist=١': '١' is not a number written in ASCII digits"),
    # given, though it is the default: taken unsaid, as --mimic couple was refused
    ((PLANAR, "--mimic", "ordinary"), "--mimic applies to URDF and MJCF files only"),
    # each with its own reason (the joints' one was given for --mimic and the inertia: an audit)
    ((PLANAR, "--mimic", "couple"), "is a DH table, which has no mimic joints"),
    ((PLANAR, "--accept-improper-inertia"), "is a DH table, whose inertias are refused when "
                                             "improper (correct the table's numbers)"),
    ((PLANAR, "--tip", "b"), "is a DH table, whose joints (a chain, or a tree by their parent "
                             "fields) are all read"),
    ((PLANAR, "--tip", "b", "--accept-improper-inertia"), "is a DH table, whose joints (a chain, or "
     "a tree by their parent fields) are all read and whose inertias are refused when improper"),
])
def test_lock_base_tip_misuse_is_a_usage_error(args, message, tmp_path):
    res = run("compile", *args, "-o", tmp_path / "x.vamp.json")
    assert res.exit_code == 2 and message in res.stderr, res.stderr
    assert len(res.stderr.splitlines()) == 1 and not (tmp_path / "x.vamp.json").exists()


def test_a_ctrl_c_ends_its_own_command_only(tmp_path, monkeypatch):
    """The remembered Ctrl-C is forgotten when its command ends: the next command in the same
    process (a notebook, a test runner) runs (it exited 130 at its first output, having done
    nothing)."""
    import signal

    import vampc.compiler
    from vampc import errors
    monkeypatch.setattr(errors, "_terminated", [])        # a failure here must not reach other tests
    real = vampc.compiler.program_chunks

    def interrupted(c):
        try:
            errors.interrupt(signal.SIGINT)                 # the handler's work, its exception lost
        except KeyboardInterrupt:
            pass
        return real(c)

    monkeypatch.setattr(vampc.compiler, "program_chunks", interrupted)
    assert run("compile", PLANAR, "-o", tmp_path / "a.vamp.json").exit_code == 130
    monkeypatch.setattr(vampc.compiler, "program_chunks", real)
    res = run("compile", PLANAR, "-o", tmp_path / "b.vamp.json")
    assert res.exit_code == 0, res.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["b.vamp.json"]


def test_a_ctrl_c_while_the_command_line_is_imported_is_one_line(monkeypatch, capsys):
    """The console script (vampc.launch) catches a Ctrl-C that lands while vampc.cli and its
    imports load: `vampc: interrupted`, exit 130, no traceback."""
    import builtins

    from vampc import launch
    real = builtins.__import__

    def interrupted(name, *args, **kwargs):
        if name == "vampc.cli":
            raise KeyboardInterrupt
        return real(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", interrupted)
    with pytest.raises(SystemExit) as exit_:
        launch.main()
    assert exit_.value.code == 130 and capsys.readouterr().err == "vampc: interrupted\n"


LEAVING = """
import atexit, sys, threading, time
import vampc.commands
from vampc import launch
vampc.commands.BIG_NETWORK_SLOTS = int(sys.argv[1])     # 0: every compile counts as big
atexit.register(lambda: print("atexit ran", file=sys.stderr))
mode, sys.argv = sys.argv[2], ["vampc", *sys.argv[3:]]
if mode == "stale":              # an earlier run in this process asked; this one does not
    launch.skip_teardown()
if mode == "daemon":             # (the progress bar's monitor is one)
    threading.Thread(target=time.sleep, args=(60,), daemon=True).start()
if mode == "no stdout":          # as Python starts with its standard output closed
    sys.stdout = None
launch.main()
"""


@pytest.mark.parametrize("big, mode", [(True, ""), (False, ""), (False, "stale"), (True, "daemon"),
                                       (True, "no stdout")])
def test_a_big_compile_leaves_without_teardown_its_output_whole(tmp_path, big, mode):
    """A compile of a big network leaves with os._exit once it has succeeded (vampc.launch): its
    summary line, written to a pipe, and its program file are whole, the exit status 0; only the
    exit handlers are skipped. A small one leaves the normal way and runs them, also after an
    earlier run in the process asked to skip them; a daemon thread does not hold the exit, and a
    closed standard output is no error. A failing command never leaves that way."""
    import subprocess
    import sys
    out = tmp_path / "p.vamp.json"
    limit = "0" if big else str(10 ** 9)
    done = subprocess.run([sys.executable, "-c", LEAVING, limit, mode, "compile", str(PLANAR),
                           "-o", str(out)], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    if mode != "no stdout":
        assert done.stdout.startswith(f"{out}: ") and done.stdout.count("\n") == 1
    assert ("atexit ran" in done.stderr) is not big, done.stderr
    assert main_emulates(out)
    failed = subprocess.run([sys.executable, "-c", LEAVING, limit, mode, "compile", str(PLANAR),
                             "-o", str(tmp_path / "missing" / "q.vamp.json")],
                            capture_output=True, text=True, timeout=120)
    assert failed.returncode == 1 and "atexit ran" in failed.stderr


FAILING_BIG_CHECK = """
import sys
import vampc.commands
from vampc import launch
from vampc.emulator import driver
from vampc.emulator.host import CheckResult
vampc.commands.BIG_NETWORK_SLOTS = 0                  # every network counts as big
driver.check_torques = lambda chain, traj, tau, tol=1e-9: CheckResult(1.0, 0.5, 0, False)
sys.argv = ["vampc", *sys.argv[1:]]
launch.main()
"""


def test_a_big_emulation_whose_check_fails_exits_1_though_it_asked_to_skip_the_teardown(program):
    """`emulate --check` says by its exit status whether the check passed (README), also for a big
    network, whose run asks to leave without teardown (vampc.launch) before its failed check ends it
    with status 1: only a run that succeeded leaves so (a mutation audit: leaving so on any status
    made the failed check exit 0)."""
    import subprocess
    done = subprocess.run([sys.executable, "-c", FAILING_BIG_CHECK, "emulate", str(program),
                           "--random", "3", "--check"], capture_output=True, text=True, timeout=120)
    assert done.returncode == 1, (done.stdout, done.stderr)
    assert "FAILED" in done.stdout, done.stdout


def main_emulates(program) -> bool:
    """Whether `vampc emulate PROGRAM --random 3 --check` passes (the file is whole and sound)."""
    res = CliRunner().invoke(main, ["emulate", str(program), "--random", "3", "--check"])
    return res.exit_code == 0


@pytest.mark.parametrize("big", [True, False])
def test_a_big_compile_keeps_its_objects_from_the_cyclic_collector(tmp_path, monkeypatch, big):
    """The compile and its file are made under one pause of the cyclic collector; a big one then
    freezes its objects (gc.freeze), so that the collector, once resumed, does not walk the millions
    of tuples it made (a 4096-joint log compile: one 0.5 s collection that found nothing). A small
    one leaves them to the collector as before. Either way the collector is on again afterwards."""
    import gc

    import vampc.commands
    from vampc import launch
    monkeypatch.setattr(vampc.commands, "BIG_NETWORK_SLOTS", 0 if big else 10 ** 9)
    monkeypatch.setattr(launch, "_SKIP_TEARDOWN", False)     # (a big compile asks for it: put back)
    gc.unfreeze()
    try:
        r = CliRunner().invoke(main, ["compile", "examples/planar2.yaml", "-o", str(tmp_path / "p.vamp.json")])
        assert r.exit_code == 0, r.output
        assert (gc.get_freeze_count() > 0) == big and gc.isenabled()
    finally:
        gc.unfreeze()


@pytest.mark.parametrize("big", [True, False])
def test_a_big_report_keeps_its_objects_from_the_cyclic_collector_too(tmp_path, monkeypatch, big):
    """A report of a big network freezes its objects as a big compile does (a 4096-joint chain's
    report: 8.8-9.1 s before, 7.9-8.2 s after), and asks to leave without teardown; the report is
    the same."""
    import gc

    import vampc.commands
    from vampc import launch
    monkeypatch.setattr(vampc.commands, "BIG_NETWORK_SLOTS", 0 if big else 10 ** 9)
    monkeypatch.setattr(launch, "_SKIP_TEARDOWN", False)
    gc.unfreeze()
    try:
        r = CliRunner().invoke(main, ["report", "examples/planar2.yaml"])
        assert r.exit_code == 0, r.output
        assert (gc.get_freeze_count() > 0) == big and launch._SKIP_TEARDOWN == big and gc.isenabled()
    finally:
        gc.unfreeze()
    monkeypatch.setattr(vampc.commands, "BIG_NETWORK_SLOTS", 10 ** 9)
    assert CliRunner().invoke(main, ["report", "examples/planar2.yaml"]).output == r.output


SIGNAL_AFTER_FIRST_RENAME = """
import os, signal, sys
from vampc import launch
real, done = os.replace, []
def replace(a, b):                    # the first output is in place when a SIGTERM lands
    real(a, b)
    if not done:
        done.append(1)
        os.kill(os.getpid(), signal.SIGTERM)
os.replace = replace
sys.argv = ["vampc", *sys.argv[1:]]
launch.main()
"""


def test_a_signal_once_the_outputs_are_being_put_in_place_lets_the_run_finish(tmp_path):
    """A SIGTERM that lands after the first output has replaced its file comes too late to stop
    the run: every output is put in place and the exit status is 0. It was 'terminated', exit 143,
    with the first file new and the others old (vampc lookahead's three outputs here)."""
    import subprocess
    import sys
    files = [tmp_path / "r.csv", tmp_path / "tau.csv", tmp_path / "p.svg"]
    for f in files:
        f.write_text("before\n")
    done = subprocess.run(
        [sys.executable, "-c", SIGNAL_AFTER_FIRST_RENAME, "lookahead", str(EXAMPLES / "puma560.yaml"),
         "--trajectory", str(EXAMPLES / "puma560-path.csv"), "--rate", "1kHz", "--window", "64",
         "--limits", str(EXAMPLES / "puma560-limits.csv"), "--retime", "uniform", "-o", str(files[0]),
         "--torques", str(files[1]), "--plot", str(files[2])], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert all(f.read_text() != "before\n" for f in files)
    assert not [p for p in tmp_path.iterdir() if p not in files]       # no temporary left


def test_a_summary_whose_reader_went_away_is_dropped_and_the_files_written(tmp_path):
    """The summary line goes to standard output after the run; with its reader gone (`vampc
    emulate ... -o tau.csv | head -1`) it is dropped, as with standard output closed, and the files
    are written whole, exit 0 (the run failed with "cannot write to standard output" and dropped the
    files the user asked for; before that their temporary files had stayed beside them)."""
    import subprocess
    import sys
    outs = ["-o", str(tmp_path / "tau.csv"), "--save-states", str(tmp_path / "s.csv"),
            "--vcd", str(tmp_path / "w.vcd")]
    proc = subprocess.Popen([sys.executable, "-m", "vampc.cli", "emulate", str(PLANAR), "--random", "3",
                             "--engine", "tick", *outs], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    proc.stdout.close()               # the reader gone before the summary is said
    err = proc.stderr.read().decode()
    assert proc.wait(timeout=120) == 0 and err == "", err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.csv", "tau.csv", "w.vcd"]
    tau = np.loadtxt(tmp_path / "tau.csv", delimiter=",", skiprows=1)
    assert tau.shape[0] == 3 and np.isfinite(tau).all()
    assert "$enddefinitions" in (tmp_path / "w.vcd").read_text()


def test_a_check_that_fails_still_says_so_by_exit_status_with_the_reader_gone(tmp_path):
    """The summary dropped with its reader gone: the exit status is still the --check's."""
    import subprocess
    import sys
    proc = subprocess.Popen([sys.executable, "-m", "vampc.cli", "emulate", str(PLANAR), "--random", "3",
                             "--engine", "tick", "--fault", "vamp=9,dead", "--check", "-o",
                             str(tmp_path / "tau.csv")], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    proc.stdout.close()
    err = proc.stderr.read().decode()
    assert proc.wait(timeout=120) == 1, err
    assert "cannot write to standard output" not in err


def test_after_the_outputs_are_in_place_the_console_script_ignores_signals_to_its_end(monkeypatch):
    """The console script's process ends with its command: once its outputs were put in place, a
    SIGTERM during Python's teardown killed it (exit 143, the files whole: a new user's run). Its
    handlers are then left ignoring signals; a library caller gets its own back. (Ctrl-C's too:
    it was left ignored in this test process, and a later test that sent itself SIGINT there
    waited for ever.)"""
    import signal

    from vampc import errors
    original = {s: signal.getsignal(s) for s in (signal.SIGTERM, signal.SIGHUP, signal.SIGINT)}
    signal.signal(signal.SIGINT, signal.default_int_handler)     # (as at a terminal)
    before = {s: signal.getsignal(s) for s in original}
    try:
        for leaving in (True, False):
            monkeypatch.setattr(errors, "LEAVING_AFTER_COMMAND", leaving)
            restore = errors.terminate_like_interrupt()
            errors.committing()
            restore()
            for sig, old in before.items():
                assert signal.getsignal(sig) == (signal.SIG_IGN if leaving else old)
                signal.signal(sig, old)
            restore = errors.terminate_like_interrupt()      # nothing committed: put back
            restore()
            assert all(signal.getsignal(s) == old for s, old in before.items())
    finally:
        for sig, old in original.items():
            signal.signal(sig, old)


def test_an_output_that_cannot_be_put_in_place_leaves_no_temporary_of_the_others(tmp_path, monkeypatch):
    """vampc.outputs.write_together: the second of three renames fails (a full or read-only
    folder): one line, and the third output's temporary file is dropped too (it stayed)."""
    from vampc.outputs import output_for, write_together
    real, calls = os.replace, []

    def replace(a, b):
        calls.append(b)
        if len(calls) == 2:
            raise OSError(28, "No space left on device")
        real(a, b)
    monkeypatch.setattr(os, "replace", replace)
    outs = [output_for(tmp_path / f"{k}.txt") for k in range(3)]
    with pytest.raises(VampcError, match=r"1\.txt: cannot write x: No space left on device"):
        write_together([(out, "new\n", "x") for out in outs])
    assert sorted(p.name for p in tmp_path.iterdir()) == ["0.txt"]


def test_a_later_stream_that_cannot_take_its_bytes_leaves_the_earlier_files_as_they_were(tmp_path):
    """vampc.outputs.write_together (README "Output files": every output is written out, a stream
    flushed, before any is renamed into place, so one that fails leaves the others' files as they
    were): a few bytes for /dev/full sit in its buffer until flushed, and flushed only as it was put
    in place, the file before it had been replaced already (a mutation audit)."""
    if not os.path.exists("/dev/full"):
        pytest.skip("no /dev/full here")
    from vampc.outputs import output_for, write_together
    kept = tmp_path / "kept.txt"
    kept.write_text("previous\n")
    with pytest.raises(VampcError, match=r"/dev/full: cannot write y: No space left on device"):
        write_together([(output_for(kept), "new\n", "x"),
                        (output_for("/dev/full", "--torques"), "small\n", "y")])
    assert kept.read_text() == "previous\n" and sorted(p.name for p in tmp_path.iterdir()) == ["kept.txt"]


CLOSED_STDOUT = """
import json, sys
from vampc import launch
assert sys.stdout is None               # (descriptor 1 closed before Python started)
for argv in json.loads(sys.argv[1]):
    sys.argv = ["vampc", *argv]
    try:
        launch.main()
        code = 0
    except SystemExit as done:
        code = done.code
    print(f"exit {code}", file=sys.stderr, flush=True)
"""


def test_a_result_for_a_closed_standard_output_is_an_error_before_any_work(tmp_path):
    """With standard output closed (`vampc report ... >&-`: Python starts with sys.stdout None), a
    command whose result goes there says so, exit 1, instead of dropping the report with exit 0
    (report, precision, faults, the trade-off) or an internal error (`-o -`); it writes nothing. A
    compile to a file still runs: its summary line is not its result."""
    import subprocess
    import sys
    program = tmp_path / "p.vamp.json"
    path = tmp_path.parent / f"{tmp_path.name}-path.csv"         # (outside: the folder must stay empty)
    path.write_text("q1,q2,qd1,qd2,qdd1,qdd2\n" + "0,0,0,0,0,0\n" * 4)
    runs = [["report", str(PLANAR), "--timing", str(tmp_path / "timing.svg")],
            ["report", str(PLANAR), "--tradeoff"],
            ["precision", str(PLANAR)],
            ["compile", str(PLANAR), "-o", "-"],
            ["compile", str(PLANAR), "-o", str(program)],
            ["emulate", str(program), "--random", "3", "-o", "-"],
            ["faults", str(program), "--results", str(tmp_path / "r.jsonl")],
            ["compile", str(PLANAR), "--dump-after", "graph"],
            ["lookahead", str(PLANAR), "--trajectory", str(path), "--rate", "1kHz", "--window", "2"]]
    done = subprocess.run([sys.executable, "-c", CLOSED_STDOUT, json.dumps(runs)], stderr=subprocess.PIPE,
                          text=True, timeout=300, preexec_fn=lambda: os.close(1))
    assert done.returncode == 0, done.stderr
    lines = done.stderr.splitlines()
    assert [line for line in lines if line.startswith("exit ")] == ["exit 1"] * 4 + ["exit 0"] + ["exit 1"] * 4
    said = [line for line in lines if not line.startswith("exit ")]
    assert len(said) == len(runs) - 1, lines
    assert all(ERROR.match(line + "\n") and "standard output is closed" in line for line in said), said
    assert program.exists() and sorted(p.name for p in tmp_path.iterdir()) == ["p.vamp.json"]


@pytest.mark.parametrize("args", [
    ["emulate", "{program}", "--random", "1_0"], ["emulate", "{program}", "--random", "١٠"],
    ["precision", "{program}", "--sets", "1_0"], ["precision", "{program}", "--tolerance", "０.１"],
    ["precision", "{program}", "--sweep", "２０:２１"],
    ["emulate", "{program}", "--random", "2", "--engine", "tick", "--fault", "vamp=１,dead"],
    ["emulate", "{program}", "--random", "2", "--engine", "tick", "--fault", "vamp=1,stuck=result.z:٣"]])
def test_numbers_on_the_command_line_are_ascii_digits(program, args):
    """int() and float() read '١٠', '６４' and '1_0': --random, --window, --sets, --tolerance,
    --sweep and --fault took them while the file readers and --rate refused them."""
    res = run(*[a.format(program=program) for a in args])
    assert res.exit_code == 2 and res.stderr.count("\n") == 1, res.output
    assert "not a number written in ASCII digits" in res.stderr or "give A:B" in res.stderr or \
        "not a whole number" in res.stderr or "give REGISTER:BIT" in res.stderr, res.stderr


@pytest.mark.parametrize("command", [["compile", "{robot}"], ["report", "{robot}"],
                                     ["precision", "{robot}", "--sets", "2"],
                                     ["emulate", "{robot}", "--trajectory", "{traj}"],
                                     ["compile", "{robot}", "--dump-after", "graph"],
                                     ["compile", "{robot}", "--numbering", "{numbering}",
                                      "--dump-after", "emit"]])
def test_standard_output_appended_to_an_input_is_refused(tmp_path, command):
    """`vampc emulate ... --trajectory in.csv >> in.csv` appended the command's lines to the
    trajectory it read: standard output onto an input file is refused and the file left as it was.
    (`compile --dump-after`, which plans no output file, had appended its dump to the robot file or
    the numbering file, exit 0: a new user's find.)"""
    import subprocess
    import sys
    robot = tmp_path / "planar2.yaml"
    robot.write_bytes(PLANAR.read_bytes())
    traj = tmp_path / "traj.csv"
    traj.write_text("q1,q2,qd1,qd2,qdd1,qdd2\n" + "0,0,0,0,0,0\n" * 3)
    numbering = tmp_path / "numbering.txt"
    numbering.write_text("".join(f"{k}\n" for k in range(1, 61)))
    args = [a.format(robot=robot, traj=traj, numbering=numbering) for a in command]
    victim = traj if "--trajectory" in command else numbering if "--numbering" in command else robot
    before = victim.read_bytes()
    with open(victim, "ab") as fh:
        done = subprocess.run([sys.executable, "-m", "vampc.cli", *args], stdout=fh,
                              stderr=subprocess.PIPE, text=True, cwd=tmp_path)
    assert done.returncode == 1 and done.stderr == (
        f"vampc: error: {victim}: standard output is this input file (redirected onto it); vampc "
        "never writes over its inputs: send standard output elsewhere\n"), done.stderr
    assert victim.read_bytes() == before


@pytest.mark.parametrize("stdin", [False, True], ids=["named", "standard-input"])
def test_standard_output_onto_an_input_says_the_shell_emptied_it(tmp_path, stdin):
    """`vampc precision a.yaml > a.yaml`: the shell empties a.yaml before vampc starts, so "vampc
    never writes over its inputs" alone read as if the file were safe; the refusal says it is empty
    now. (An input read through standard input, `--trajectory - < t.csv > t.csv`, likewise.)"""
    import subprocess
    import sys
    robot = tmp_path / "planar2.yaml"
    robot.write_bytes(PLANAR.read_bytes())
    victim = tmp_path / "traj.csv" if stdin else robot
    victim.write_text("")                                  # as `>` leaves it
    args = ["emulate", str(robot), "--trajectory", "-"] if stdin else ["precision", str(robot)]
    with open(victim, "rb") as given, open(victim, "wb") as fh:
        done = subprocess.run([sys.executable, "-m", "vampc.cli", *args], stdin=given, stdout=fh,
                              stderr=subprocess.PIPE, text=True, cwd=tmp_path)
    said = ("standard output is the file standard input reads (an input given as -, redirected "
            "onto it)" if stdin else f"{robot}: standard output is this input file (redirected "
            "onto it)")
    assert done.returncode == 1 and done.stderr == (
        f"vampc: error: {said}; vampc never writes over its inputs: send standard output "
        "elsewhere (the file is empty now: the shell empties a file it redirects to with > before "
        "vampc starts)\n"), done.stderr


@pytest.mark.parametrize("args, name", [
    (["compile", PLANAR], "planar.vamp.json.gz/"),
    (["emulate", "PROGRAM", "--random", "2"], "tau.npy/"),
    (["report", PLANAR, "--tradeoff", "--curve"], "curve.svg/"),
], ids=["compile", "emulate", "curve"])
def test_an_output_name_ending_in_a_slash_is_refused(tmp_path, program, args, name):
    """A name ending in '/' names a folder: the file would be made by the name without it, in
    another format than the name says (x.gz/ was plain text in x.gz, tau.npy/ CSV in tau.npy)."""
    args = [program if a == "PROGRAM" else a for a in args]
    res = run(*args, *([] if args[-1] == "--curve" else ["-o"]), f"{tmp_path}/{name}")
    user_error(res, r"ends in '/', as a folder's name does; give a file name for (-o|--curve)")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("name, pack, as_trajectory, says", [
    ("p.vamp.json.xz", "xz", False, r"xz-compressed; vampc reads a program file gzip-compressed \(\.gz\)"),
    ("p.vamp.json.bz2", "bz2", False, r"bzip2-compressed; vampc reads a program file gzip-compressed"),
    ("states.npy", "gzip", True, r"gzip-compressed; give the numpy \.npy array file as numpy saved it"),
    ("states.csv", "bz2", True, r"bzip2-compressed; give the trajectory as plain CSV"),
], ids=["xz-program", "bz2-program", "gz-npy", "bz2-csv"])
def test_a_compressed_file_is_said_to_be_one(tmp_path, program, name, pack, as_trajectory, says):
    """An .xz or .bz2 program was 'unknown robot file extension', a gzipped .npy 'does not start as
    numpy writes one: b'\\x1f\\x8b...'', a bzip2 CSV 'byte ... is not UTF-8' (a new user's run)."""
    import bz2
    import gzip
    import lzma
    if as_trajectory:
        plain = tmp_path / ("plain" + Path(name).suffix)
        assert run("emulate", program, "--random", "3", "--save-states", plain, "-o", tmp_path / "t.csv").exit_code == 0
        raw = plain.read_bytes()
    else:
        raw = program.read_bytes()
    packed = tmp_path / name
    packed.write_bytes({"xz": lzma.compress, "bz2": bz2.compress, "gzip": gzip.compress}[pack](raw))
    res = run("emulate", program, "--trajectory", packed) if as_trajectory else run("report", packed)
    user_error(res, says)


def test_an_environment_switch_of_another_value_is_said_once(monkeypatch, tmp_path):
    """VAMPC_PROGRESS=yes showed no bar and VAMPC_FORK=maybe ran as unset, without a word."""
    from vampc import errors
    monkeypatch.setattr(errors, "_SAID_SWITCHES", set())
    monkeypatch.setenv("VAMPC_PROGRESS", "yes")
    res = run("compile", PLANAR, "-o", tmp_path / "p.vamp.json")
    assert res.exit_code == 0
    assert res.stderr.count("vampc: warning: VAMPC_PROGRESS='yes': give 1 (on) or 0 (off); taken as "
                            "unset") == 1, res.stderr
    monkeypatch.setenv("VAMPC_PROGRESS", " 0 ")
    monkeypatch.setattr(errors, "_SAID_SWITCHES", set())
    assert errors.env_switch("VAMPC_PROGRESS") == "0"


def test_a_text_starting_as_a_magic_number_does_is_not_called_compressed():
    """'BZh' starts a bzip2 file, and may start a text: the block or end marker after it decides."""
    import bz2

    from vampc.sniff import compression
    assert compression(bz2.compress(b"q1\n1\n")[:16]) == compression(bz2.compress(b"")[:16]) == "bzip2"
    assert compression(b"BZh: 1\nBZh9 x") is None and compression(b"BZh91AY") is None


CONT = """<robot name="cont">
  <link name="base"/>
  <link name="arm"><inertial><origin xyz="0.3 0 0"/><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="hand"><inertial><origin xyz="0.1 0 0"/><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="{first}" type="{kind}"><parent link="base"/><child link="arm"/><axis xyz="1 0 0"/></joint>
  <joint name="j2" type="continuous"><parent link="arm"/><child link="hand"/><origin xyz="0.3 0 0"/><axis xyz="0 1 0"/></joint>
</robot>"""


@pytest.mark.parametrize("kind, first, args, said", [
    ("floating", "float", ["--lock", "float=0.5"],
     "joint 'float' is the floating base's own joint (its motion is the host's input); --lock "
     "float=... has no effect"),
])
def test_a_lock_of_a_joint_not_in_the_robot_is_warned_of(tmp_path, kind, first, args, said):
    """(A new user's find.) A --lock of the floating base's own joint was taken and ignored, saying
    nothing; the program is the one without it. (One of a joint --base cuts away places it where
    gravity is turned into the base's frame: tests/test_robot_urdf.py.)"""
    robot = tmp_path / "r.urdf"
    robot.write_text(CONT.format(kind=kind, first=first))
    res = run("compile", robot, *args, "-o", tmp_path / "a.vamp.json")
    said = said.format(robot=robot)
    assert res.exit_code == 0 and res.stderr == f"vampc: warning: {robot}: {said}\n", res.stderr
    plain = [a for a in args if not a.startswith(("--lock", f"{first}="))]
    assert run("compile", robot, *plain, "-o", tmp_path / "b.vamp.json").exit_code == 0
    assert (tmp_path / "a.vamp.json").read_bytes() == (tmp_path / "b.vamp.json").read_bytes()


@pytest.mark.parametrize("suffix", [".urdf", ".yaml", ".mjcf"])
def test_an_mjcf_model_under_another_name_is_told_its_name(tmp_path, suffix):
    """An MJCF model named .urdf was told its root must be <robot> 'or <mujoco>' (it is <mujoco>),
    named .yaml to name it .urdf (which then failed), .mjcf that it looks like a URDF (a new user's
    finds). It is told what it is and what to name it; nothing is written."""
    model = tmp_path / f"m{suffix}"
    model.write_text('<mujoco model="m"><worldbody><body name="a"><joint name="j"/>'
                     '<geom type="sphere" size="0.1"/></body></worldbody></mujoco>')
    res = run("compile", model, "-o", tmp_path / "x.vamp.json")
    assert res.exit_code == 1 and res.stderr == (f"vampc: error: {model}: this is an MJCF model (a "
                                                 "<mujoco> root); name it .xml to load it as one\n")
    assert not (tmp_path / "x.vamp.json").exists()


def test_mimic_couple_with_every_follower_cut_away_is_warned_of(tmp_path):
    """--base below every <mimic> follower left --mimic couple with nothing to couple, saying
    nothing (a new user's find); with the pair inside the robot it couples, unwarned."""
    inertial = ('<inertial><origin xyz="0.1 0 0"/><mass value="1"/><inertia ixx="0.01" iyy="0.01" '
                'izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>')
    links = "".join(f'<link name="{n}">{inertial}</link>' for n in ("base", "l1", "l2", "l3", "l4"))
    joints = "".join(f'<joint name="{j}" type="continuous"><parent link="{p}"/><child link="{c}"/>'
                     f'<origin xyz="0.2 0 0"/><axis xyz="0 0 1"/>{extra}</joint>'
                     for j, p, c, extra in (("j1", "base", "l1", ""),
                                            ("j2", "l1", "l2", '<mimic joint="j1" multiplier="2"/>'),
                                            ("j3", "l2", "l3", ""), ("j4", "l3", "l4", "")))
    robot = tmp_path / "m.urdf"
    robot.write_text(f'<robot name="m">{links}{joints}</robot>')
    res = run("compile", robot, "--base", "l2", "--mimic", "couple", "-o", tmp_path / "a.vamp.json")
    assert res.exit_code == 0 and res.stderr == (f"vampc: warning: {robot}: no joint below the base "
                                                 "link 'l2' has a <mimic>; --mimic couple has no "
                                                 f"effect\nvampc: warning: {robot}: --base l2: the "
                                                 "joints above it are cut away (j1 at 0, j2 at 0: j2 "
                                                 "by a coupled mimic's leader; j1 by default); "
                                                 "gravity is turned into l2's frame through them "
                                                 "there\n"), res.stderr
    res = run("compile", robot, "--mimic", "couple", "-o", tmp_path / "b.vamp.json")
    assert res.exit_code == 0 and not res.stderr and "1 coupled mimic joint" in res.stdout, res.output
    # j1 locked: j2 follows it, placed by its leader, not by --lock (an audit's: said "by --lock")
    res = run("compile", robot, "--base", "l2", "--mimic", "couple", "--lock", "j1=0.2", "-o",
              tmp_path / "c.vamp.json")
    assert res.exit_code == 0 and "cut away (j1 at 0.2, j2 at 0.4: j1 by --lock; j2 by a coupled " \
        "mimic's leader);" in res.stderr, res.stderr
    res = run("compile", robot, "--base", "l2", "--mimic", "couple", "--lock", "j1=0.2", "--lock",
              "j2=0.4", "-o", tmp_path / "d.vamp.json")
    assert res.exit_code == 0 and "cut away (j1 at 0.2, j2 at 0.4: by --lock);" in res.stderr, \
        res.stderr


@pytest.mark.parametrize("outs", [["-o", "{in}"], ["--save-states", "{in}", "-o", "{other}"],
                                  ["-o", "-", ">>"], [">>"]])
def test_an_output_onto_the_file_standard_input_reads_is_refused(tmp_path, outs):
    """`vampc emulate p --trajectory - -o in.csv < in.csv` replaced the states with the torques (exit
    0; --trajectory /dev/stdin was refused); so did --save-states, and standard output appended onto
    it (a new user's find). Each is refused, the file unchanged."""
    import subprocess
    import sys
    states = tmp_path / "in.csv"
    before = "q1,q2,qd1,qd2,qdd1,qdd2\n0.1,0.2,0.3,0.4,0.5,0.6\n"
    states.write_text(before)
    append = outs[-1] == ">>"
    args = [a.format(**{"in": states, "other": tmp_path / "tau.csv"}) for a in outs if a != ">>"]
    with open(states) as stdin, open(states, "a") if append else open(os.devnull, "w") as stdout:
        done = subprocess.run([sys.executable, "-m", "vampc.cli", "emulate", str(PLANAR), "--trajectory",
                               "-", *args], stdin=stdin, stdout=stdout, stderr=subprocess.PIPE,
                              text=True, timeout=120)
    assert done.returncode == 1 and done.stderr.count("\n") == 1, done.stderr
    assert "the file standard input reads" in done.stderr and "never writes over its inputs" in done.stderr
    assert states.read_text() == before and not (tmp_path / "tau.csv").exists()


@pytest.mark.parametrize("name", ["/dev/stdin", "/dev/fd/0", "/proc/self/fd/0", "link"])
def test_an_output_named_as_standard_input_is_refused(tmp_path, name):
    """`vampc emulate p --random 2 -o /dev/stdin < keep.csv` replaced keep.csv with the torques
    (through /proc/self/fd/0), exit 0 (an audit's find): an output naming standard input, or a
    symlink to it, is a usage error, the file unchanged."""
    import subprocess
    import sys
    if not os.path.exists("/dev/stdin") or not os.path.exists("/proc/self/fd/0"):
        pytest.skip("no /dev/stdin or /proc here")
    keep = tmp_path / "keep.csv"
    keep.write_text("keep\n")
    if name == "link":
        name = str(tmp_path / "link")
        os.symlink("/dev/stdin", name)
    with open(keep) as stdin:
        done = subprocess.run([sys.executable, "-m", "vampc.cli", "emulate", str(PLANAR), "--random",
                               "2", "-o", name], stdin=stdin, capture_output=True, text=True,
                              timeout=120)
    assert done.returncode == 2 and done.stderr.count("\n") == 1, done.stderr
    assert f"-o {name}: that is standard input" in done.stderr and done.stdout == ""
    assert keep.read_text() == "keep\n"


def test_standard_input_or_output_closed_beside_an_input_given_as_dash(tmp_path):
    """With standard output closed, the check of standard input's file crashed (os.stat(None): exit
    3; a review's find); with standard input closed, --trajectory - crashed (sys.stdin None). A file
    named - given to --limits is an input as any other (a review's find: it was overwritten)."""
    import subprocess
    import sys
    states = tmp_path / "in.csv"
    states.write_text("q1,q2,qd1,qd2,qdd1,qdd2\n0.1,0.2,0.3,0.4,0.5,0.6\n")
    cmd = [sys.executable, "-m", "vampc.cli", "emulate", str(PLANAR), "--trajectory", "-", "-o",
           str(tmp_path / "out.csv")]
    with open(states) as stdin:
        done = subprocess.run(cmd, stdin=stdin, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                              text=True, timeout=120, pass_fds=(), close_fds=True,
                              preexec_fn=lambda: os.close(1))
    assert done.returncode == 0 and done.stderr == "", done.stderr
    assert (tmp_path / "out.csv").read_text().count("\n") == 2
    done = subprocess.run(cmd[:-1] + [str(tmp_path / "out2.csv")], stdin=subprocess.DEVNULL,
                          capture_output=True, text=True, timeout=120, preexec_fn=lambda: os.close(0))
    assert done.returncode == 1 and done.stderr.count("\n") == 1, done.stderr
    assert "-: standard input is closed" in done.stderr and not (tmp_path / "out2.csv").exists()
    limits = tmp_path / "-"
    limits.write_text("joint,tau,qd\nshoulder,50,\nelbow,25,\n")
    done = subprocess.run([sys.executable, "-m", "vampc.cli", "lookahead", str(PLANAR), "--trajectory",
                           str(states), "--rate", "1kHz", "--window", "1", "--limits", "-", "--torques",
                           "./-"], cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert done.returncode == 1 and "--torques is the input file -" in done.stderr, done.stderr
    assert limits.read_text().startswith("joint,tau,qd")
    # with a file named - in the folder, --trajectory - is still standard input (a review's find:
    # "-o is the input file -")
    with open(states) as stdin:
        done = subprocess.run([sys.executable, "-m", "vampc.cli", "emulate", str(PLANAR), "--trajectory", "-",
                               "-o", "./-"], stdin=stdin, cwd=tmp_path, capture_output=True, text=True,
                              timeout=120)
    assert done.returncode == 0, done.stderr
    assert limits.read_text().startswith("tau_shoulder,tau_elbow")


def test_an_input_from_standard_input_by_pipe_is_read_and_the_output_written(tmp_path):
    """Standard input a pipe (or another file): no refusal, the torques written."""
    import subprocess
    import sys
    states = "q1,q2,qd1,qd2,qdd1,qdd2\n0.1,0.2,0.3,0.4,0.5,0.6\n"
    done = subprocess.run([sys.executable, "-m", "vampc.cli", "lookahead", str(PLANAR), "--trajectory", "-",
                           "--rate", "1kHz", "--window", "1", "--torques", str(tmp_path / "t.csv")],
                          input=states, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "t.csv").read_text().count("\n") == 2


def test_a_warning_whose_reader_went_away_is_dropped_and_the_file_written(tmp_path):
    """A warning to a standard error whose reader had gone failed the run silently (exit 1, nothing
    said, no file; a review's find): warnings go as the summary does, dropped, the run goes on."""
    import subprocess
    import sys
    out = tmp_path / "w.vamp.json"
    proc = subprocess.Popen([sys.executable, "-m", "vampc.cli", "compile", str(EXAMPLES / "arm6.urdf"), "--base",
                             "link2", "-o", str(out)], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    proc.stderr.close()               # the reader gone before the warning is said
    assert proc.wait(timeout=120) == 0
    assert json.loads(out.read_text())["robot"]["name"]


def test_every_byte_is_written_or_the_run_fails(program, tmp_path):
    """A buffered file's write() may take part of a long piece and say how much, with no error (a
    file-size limit or a full disk reached mid-piece): 251 594 bytes of torques sent to standard
    output under `ulimit -f 100` left 102 400 and exit 0 (a new user's find). In a child process
    under that limit: standard output, /dev/stdout and a regular file each fail in one line, and
    the regular file is not left behind; without the limit the same bytes arrive whole."""
    import resource
    import subprocess
    import sys
    states = tmp_path / "s.npy"
    assert run("emulate", program, "--random", 6000, "--save-states", states, "-o", "/dev/null").exit_code == 0
    whole = run("emulate", program, "--trajectory", states, "-o", "-").stdout_bytes
    assert len(whole) > 200_000

    def limited():
        resource.setrlimit(resource.RLIMIT_FSIZE, (100_000, 100_000))
    for target in ("-", "/dev/stdout", str(tmp_path / "tau.csv")):
        with open(tmp_path / "stdout.bin", "wb") as sink:
            done = subprocess.run([sys.executable, "-m", "vampc.cli", "emulate", str(program), "--trajectory",
                                   str(states), "-o", target], stdout=sink, stderr=subprocess.PIPE, text=True,
                                  preexec_fn=limited)
        assert done.returncode == 1, (target, done.stderr)
        sent = "" if target not in ("-", "/dev/stdout") else \
            rf"; -o {re.escape(target)} had sent its header, and part of the first sets \(its last " \
            r"line perhaps cut short\) to standard output"   # (what went out, as a signal says it)
        assert re.fullmatch(rf"vampc: error: {re.escape(target)}: cannot write torques: File too "
                            rf"large{sent}\n", done.stderr), done.stderr
        assert not (tmp_path / "tau.csv").exists()
    done = subprocess.run([sys.executable, "-m", "vampc.cli", "emulate", str(program), "--trajectory",
                           str(states), "-o", "-"], capture_output=True)
    assert done.returncode == 0 and done.stdout == whole


def test_the_outputs_are_all_written_out_before_any_is_put_in_place(program, tmp_path):
    """-o onto a full device failed after --save-states had replaced the states file, or made a new
    one (a new user's find): a failed run leaves every existing file as it was and makes none."""
    if not os.path.exists("/dev/full"):
        pytest.skip("no /dev/full here")
    kept, new = tmp_path / "kept.csv", tmp_path / "new.csv"
    kept.write_text("previous\n")
    for states in (kept, new):
        res = run("emulate", program, "--random", 20, "-o", "/dev/full", "--save-states", states)
        user_error(res, r"^vampc: error: /dev/full: cannot write torques: No space left on device$")
    assert kept.read_text() == "previous\n" and not new.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["kept.csv"]      # (no temporary left)


@pytest.mark.parametrize("suffix", [".npy", ".npz", ".csv"])
def test_a_trajectory_from_a_fifo_is_read_once(program, tmp_path, suffix):
    """A FIFO named .npy was opened three times (its magic, its size, then numpy's load): the second
    open waited for a writer long gone, for good (a new user's find). Read once, as a file would be:
    the same torques."""
    states = tmp_path / "s.npy"
    assert run("emulate", program, "--random", 50, "--save-states", states, "-o", "/dev/null").exit_code == 0
    data = np.load(states)
    source = tmp_path / f"states{suffix}"
    if suffix == ".npz":
        np.savez(source, q=data[:, :2], qd=data[:, 2:4], qdd=data[:, 4:6])
    elif suffix == ".csv":
        np.savetxt(source, data, delimiter=",", header="q1,q2,qd1,qd2,qdd1,qdd2", comments="", fmt="%.17g")
    else:
        np.save(source, data)
    fifo = tmp_path / f"fifo{suffix}"
    os.mkfifo(fifo)
    feeder = threading.Thread(target=lambda: fifo.write_bytes(source.read_bytes()), daemon=True)
    feeder.start()
    import subprocess
    import sys
    try:                  # (in a child, so that a reader waiting for good fails the test, not hangs it)
        done = subprocess.run([sys.executable, "-m", "vampc.cli", "emulate", str(program), "--trajectory",
                               str(fifo), "-o", "-"], capture_output=True, text=True, timeout=60)
    finally:
        if feeder.is_alive():                # (unblock the feeder: open the FIFO for reading once)
            with open(os.open(fifo, os.O_RDONLY | os.O_NONBLOCK), "rb") as drain:
                drain.read()
    feeder.join(10)
    assert done.returncode == 0, done.stderr
    assert done.stdout == run("emulate", program, "--trajectory", states, "-o", "-").stdout


@pytest.mark.parametrize("where", ["--trajectory", "--limits", "robot"])
def test_a_character_device_with_no_end_is_not_read(program, tmp_path, where):
    """--trajectory /dev/zero read 10 GB in 15 s, and SIGTERM did not stop it (a new user's find): a
    character device other than /dev/null is refused, also as a limits file and as a robot."""
    if not os.path.exists("/dev/zero"):
        pytest.skip("no /dev/zero here")
    if where == "--trajectory":
        res = run("emulate", program, "--trajectory", "/dev/zero", "-o", tmp_path / "t.csv")
        user_error(res, r"^vampc: error: /dev/zero: cannot read trajectory: it is a character device, which "
                        r"has no end: give a file or a pipe$")
    elif where == "--limits":
        path = tmp_path / "p.csv"
        path.write_text("t,q1,q2,qd1,qd2,qdd1,qdd2\n" + "".join(f"{k / 1000},0,0,0,0,0,0\n" for k in range(8)))
        res = run("lookahead", program, "--trajectory", path, "--rate", "1kHz", "--window", 4,
                  "--limits", "/dev/zero")
        user_error(res, r"^vampc: error: /dev/zero: cannot read limits: it is a character device")
    else:
        user_error(run("compile", "/dev/zero", "-o", tmp_path / "x.vamp.json"), r"^vampc: error: /dev/zero: ")
    assert not (tmp_path / "t.csv").exists()


@pytest.mark.parametrize("feed", ["device", "pipe of NULs", "header then NULs", "gzip"])
def test_standard_input_with_no_end_or_no_text_is_refused(program, tmp_path, feed):
    """`--trajectory - < /dev/zero` and `cat /dev/zero | ... --trajectory -` were read until memory
    ran out (24 GB on a shared machine: an audit's find): standard input from a character device
    (not a terminal) is refused as a named one is, and a pipe's NUL byte, which no CSV has, as it
    arrives; a compressed CSV through a pipe is still said to be one."""
    import subprocess
    if not os.path.exists("/dev/zero"):
        pytest.skip("no /dev/zero here")
    command = f"{sys.executable} -m vampc emulate {program} --trajectory - -o {tmp_path / 't.csv'}"
    # (capped, so that a reader that regresses fails here without taking the machine's memory: a
    # review's find)
    command = f"(ulimit -v 4000000; {command})"
    shell = {"device": f"{command} < /dev/zero",
             "pipe of NULs": f"head -c 64M /dev/zero | {command}",
             "header then NULs": f"(echo q1,q2,qd1,qd2,qdd1,qdd2; head -c 64M /dev/zero) | {command}",
             "gzip": f"(echo q1,q2,qd1,qd2,qdd1,qdd2; echo 0,0,0,0,0,0) | gzip | {command}"}[feed]
    done = subprocess.run(["bash", "-c", shell], capture_output=True, text=True, timeout=120)
    said = {"device": r"standard input is a character device, which has no end: give a file or a "
                      r"pipe",
            "pipe of NULs": r"cannot read trajectory: byte 0 is a NUL byte, which no text has \(a "
                            r"text file is expected\)$",
            "header then NULs": r"cannot read trajectory: byte 24 is a NUL byte",
            "gzip": r"gzip-compressed; give the trajectory as plain CSV"}[feed]
    assert done.returncode == 1 and re.match(r"vampc: error: -: .*" + said, done.stderr), done.stderr
    assert len(done.stderr.splitlines()) == 1 and not (tmp_path / "t.csv").exists()


def test_every_text_reader_refuses_a_pipes_nul_byte_and_a_device(tmp_path):
    """The NUL refusal had covered the trajectory readers only: a FIFO named .urdf fed zeros was read
    whole before 'not well-formed XML', and `report --rtl /dev/zero` (read by open(), not as every
    input is) ran until memory ran out (a review's find)."""
    import subprocess
    if not os.path.exists("/dev/zero") or not hasattr(os, "mkfifo"):
        pytest.skip("no /dev/zero or FIFOs here")
    fifo = tmp_path / "r.urdf"
    os.mkfifo(fifo)
    shell = (f"(head -c 8M /dev/zero > {fifo} &) ; (ulimit -v 4000000; {sys.executable} -m vampc "
             f"compile {fifo} -o {tmp_path / 'x.vamp.json'})")
    done = subprocess.run(["bash", "-c", shell], capture_output=True, text=True, timeout=120)
    assert done.returncode == 1 and done.stderr == (f"vampc: error: {fifo}: cannot read: byte 0 is a "
                                                    "NUL byte, which no text has (a text file is "
                                                    "expected)\n"), done.stderr
    res = run("report", PLANAR, "--word", "q16.16", "--rtl", "/dev/zero")
    user_error(res, r"^vampc: error: /dev/zero: cannot read: it is a character device, which has no "
                    r"end: give a file or a pipe$")


def test_an_integer_a_float64_cannot_hold_is_refused(program, tmp_path):
    """Integer arrays are read as float64: nanosecond times 2**53 + 1, + 2, ... were rounded, saying
    nothing, some to repeats (a new user's find); so were int64 positions with --allow-out-of-limits.
    Refused, naming the array, the state and the value; integers float64 holds exactly still read."""
    z = np.zeros((5, 2))
    odd = tmp_path / "odd.npz"
    np.savez(odd, q=z, qd=z, qdd=z, t=np.arange(5, dtype=np.int64) + 2 ** 53 + 1)
    user_error(run("emulate", program, "--trajectory", odd, "-o", tmp_path / "t.csv"),
               r"^vampc: error: .*odd\.npz: array t, state 1: the integer 9007199254740993 is not a float64 "
               r"\(vampc computes in float64, where it is 9007199254740992\.0\); give it as a float, or in a "
               r"unit that keeps it within 2\*\*53$")
    states = np.zeros((5, 7), dtype=np.uint64)
    states[:, 0] = np.arange(5)
    states[3, 2] = 2 ** 64 - 1
    np.save(tmp_path / "big.npy", states)
    user_error(run("emulate", program, "--trajectory", tmp_path / "big.npy", "-o", tmp_path / "t.csv",
                   "--allow-out-of-limits"), r"the array, state 4, column q2: the integer 18446744073709551615 ")
    even = tmp_path / "even.npz"
    np.savez(even, q=z, qd=z, qdd=z, t=np.arange(5, dtype=np.int64) * 2 + 2 ** 53)
    res = run("emulate", program, "--trajectory", even, "-o", "-")
    assert res.exit_code == 0, res.stderr
    assert [line.split(",")[0] for line in res.stdout.splitlines()[1:]] == [str(2 ** 53 + 2 * k) for k in range(5)]
    assert not (tmp_path / "t.csv").exists()


def test_a_long_double_a_float64_cannot_hold_is_refused(program, tmp_path):
    """A long-double (float128) array is read as float64: 1 + 2**-60 was rounded to 1.0, saying
    nothing, as integers past 2**53 were. Refused, naming the array, the state and the column; long
    doubles float64 holds exactly still read, to the torques of the same float64 states."""
    if np.finfo(np.longdouble).nmant <= 52:
        pytest.skip("long double is float64 here")
    states = np.full((5, 6), 0.1).astype(np.longdouble)
    exact = tmp_path / "exact.npy"
    np.save(exact, states)
    states[1, 2] = np.longdouble(1) + np.longdouble(2) ** -60
    np.save(tmp_path / "fine.npy", states)
    user_error(run("emulate", program, "--trajectory", tmp_path / "fine.npy", "-o", tmp_path / "t.csv"),
               r"^vampc: error: .*fine\.npy: the array, state 2, column qd1: the long double "
               r"1\.0000000000000000009 is not a float64 \(vampc computes in float64, where it is 1\.0\); "
               r"save the array as float64 if that rounding will do$")
    nan = np.full((5, 6), 0.1)
    nan[1, 2] = np.nan             # the same cell, named the same way by the finiteness check
    np.save(tmp_path / "nan.npy", nan)
    user_error(run("emulate", program, "--trajectory", tmp_path / "nan.npy", "-o", tmp_path / "t.csv"),
               r"^vampc: error: .*nan\.npy: state 2, column qd1: nan is not finite$")
    np.savez(tmp_path / "fine.npz", q=states[:, :2], qd=states[:, 2:4], qdd=states[:, 4:])
    user_error(run("emulate", program, "--trajectory", tmp_path / "fine.npz", "-o", tmp_path / "t.csv"),
               r"^vampc: error: .*fine\.npz: array qd, state 2, column qd1: the long double ")
    assert not (tmp_path / "t.csv").exists()
    np.save(tmp_path / "f64.npy", np.full((5, 6), 0.1))
    res, res64 = (run("emulate", program, "--trajectory", tmp_path / f, "-o", "-")
                  for f in ("exact.npy", "f64.npy"))
    assert res.exit_code == 0 and res.stdout == res64.stdout and res.stdout.count("\n") == 6, res.stderr


def test_a_failed_check_writes_no_new_file_beside_one_it_keeps(tmp_path, program, monkeypatch):
    """--check failed, --save-states onto an existing file (kept) and -o a new one: the new torques
    were written beside the old states, which they do not match (a new user's find). Neither now;
    with --write-failed, both."""
    _failing_check(monkeypatch)
    states, tau = tmp_path / "states.csv", tmp_path / "tau.csv"
    states.write_text("old states\n")
    res = run("emulate", program, "--random", 3, "--check", "-o", tau, "--save-states", states)
    assert res.exit_code == 1
    assert states.read_text() == "old states\n" and not tau.exists()
    assert (f"torques NOT written: the check failed and {states} is kept, which a new {tau} would not "
            "match (--write-failed writes them all)") in res.stderr
    res = run("emulate", program, "--random", 3, "--check", "-o", tau, "--save-states", states,
              "--write-failed")
    assert res.exit_code == 1 and tau.exists() and states.read_text().startswith("q1,")


def test_an_npz_holding_one_array_twice_is_refused(program, tmp_path):
    """A zip holding q.npy twice ran on the last copy, saying nothing (a new user's find)."""
    import io
    z = np.zeros((3, 2))
    path = tmp_path / "twice.npz"
    with zipfile.ZipFile(path, "w") as archive:
        for name, value in (("q", z), ("qd", z), ("qdd", z), ("q", z + 1)):
            buffer = io.BytesIO()
            np.save(buffer, value)
            with pytest.warns(UserWarning, match="Duplicate name") if name == "q" and value[0, 0] else \
                    contextlib.nullcontext():
                archive.writestr(f"{name}.npy", buffer.getvalue())
    user_error(run("emulate", program, "--trajectory", path, "-o", tmp_path / "t.csv"),
               r"twice\.npz: the archive holds 'q\.npy' more than once \(which is the array\?\); save it "
               r"again with numpy\.savez$")


def test_a_floating_bases_columns_for_a_fixed_base_say_what_to_give(program, tmp_path):
    """A floating-base trajectory given to a fixed-base robot said only "15 columns, expected 6"
    (a new user's find): the CSV's and the .npy's messages name --floating-base."""
    from vampc.emulator.trajectory import BASE_COLUMNS
    head = ["q1", "q2", "qd1", "qd2", "qdd1", "qdd2"] + BASE_COLUMNS
    path = _csv(tmp_path / "f.csv", ",".join(head) + "\n" + ",".join(["0"] * 15) + "\n")
    user_error(run("emulate", program, "--trajectory", path, "-o", tmp_path / "t.csv"),
               r"header: 15 columns, expected 6 \(expected 6 columns q1,q2\.\.\.qdd2: the program is for 2 "
               r"joints\); the base columns are a floating base's: give the robot --floating-base \(README, "
               r"Trees and floating bases\)$")
    np.save(tmp_path / "f.npy", np.zeros((3, 15)))
    user_error(run("emulate", program, "--trajectory", tmp_path / "f.npy", "-o", tmp_path / "t.csv"),
               r"array of shape \(3, 15\); expected \(states, 6\) or \(states, 7\) with t first; if the "
               r"last 9 columns are a floating base's, give the robot --floating-base")


def test_int64s_least_value_is_a_float64(program, tmp_path):
    """int64's least value, -2**63, is a float64 and was refused (review): it reads (as a position
    out of limits, here allowed)."""
    least = np.zeros((2, 2), dtype=np.int64)
    least[1, 0] = -2 ** 63
    np.savez(tmp_path / "least.npz", q=least, qd=np.zeros((2, 2)), qdd=np.zeros((2, 2)))
    res = run("emulate", program, "--trajectory", tmp_path / "least.npz", "-o", "-", "--allow-out-of-limits")
    assert "is not a float64" not in res.stderr


def test_a_dash_names_a_file_for_every_reader_but_the_trajectory(program, tmp_path, monkeypatch):
    """Reading inputs through one reader made `--limits -` (and a program or robot file named -)
    read standard input (review); only --trajectory takes - for standard input."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "-").write_text("joint,tau,qd\nshoulder,100,\nelbow,100,\n")
    path = _csv(tmp_path / "p.csv", "t," + HEAD + "".join(f"{k / 1000}," + ROW for k in range(8)))
    res = run("lookahead", program, "--trajectory", path, "--rate", "1kHz", "--window", 4, "--limits", "-",
              input="garbage\n")
    assert res.exit_code == 0, res.stderr


def test_a_yaml_robot_that_is_a_character_device_is_not_read(tmp_path):
    """The DH reader read a .yaml linked to /dev/zero until memory ran out (review)."""
    if not os.path.exists("/dev/zero"):
        pytest.skip("no /dev/zero here")
    link = tmp_path / "z.yaml"
    link.symlink_to("/dev/zero")
    user_error(run("compile", link, "-o", tmp_path / "z.vamp.json"),
               r"z\.yaml: cannot read: it is a character device, which has no end: give a file or a pipe$")


def test_bytes_for_a_standard_output_that_takes_only_text_are_one_line(program, tmp_path, monkeypatch):
    """With standard output replaced by a text-only stream (Jupyter's, a library caller's), a program
    file (bytes) sent there ended in a TypeError (review): one line; text still goes there."""
    import io
    import sys

    from vampc.errors import VampcError
    from vampc.outputs import plan_outputs, write_output
    monkeypatch.setattr(sys, "stdout", io.StringIO())
    out = plan_outputs([], {"-o": "-"}, stdout_ok=("-o",))["-o"]
    with pytest.raises(VampcError, match=r"^-: standard output here takes text, not the program file "
                                         r"\(bytes\): write it to a file$"):
        write_output(out, b"{}", "program file")
    write_output(out, "text\n", "report")
    assert sys.stdout.getvalue() == "text\n"


def test_a_sigterm_while_vampc_is_imported_is_one_line():
    """A SIGTERM in the first tenth of a second, while the console script imported vampc.cli,
    ended the process by the signal, nothing said (an audit's find); Ctrl-C there was already one
    line. The signal here comes as click, which only vampc.cli imports, is looked up."""
    import subprocess
    import sys
    code = (
        "import importlib.abc, os, signal, sys\n"
        "sys.argv = ['vampc', '--version']\n"
        "class Hook(importlib.abc.MetaPathFinder):\n"
        "    def find_spec(self, name, path, target=None):\n"
        "        if name == 'click':\n"
        "            os.kill(os.getpid(), signal.SIGTERM)\n"
        "        return None\n"
        "sys.meta_path.insert(0, Hook())\n"
        "from vampc.launch import main\n"
        "main()\n")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert (r.returncode, r.stderr, r.stdout) == (143, "vampc: terminated (SIGTERM)\n", ""), r


def test_a_library_that_will_not_load_is_one_line():
    """Under `ulimit -v` numpy's import failed ("failed to map segment from shared object") and the
    console script showed a traceback and numpy's page of advice (a CI engineer's find): one line
    naming the library and its loader's reason, exit 1. (numpy refused here by sys.modules.)"""
    import subprocess
    import sys
    code = ("import sys\nsys.modules['numpy'] = None\nsys.argv = ['vampc', '--version']\n"
            "from vampc.launch import main\nmain()\n")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert r.returncode == 1 and r.stdout == "" and r.stderr.count("\n") == 1, r
    assert r.stderr.startswith("vampc: error: cannot load numpy: import of numpy halted"), r


@pytest.mark.parametrize("sig, status, line", [("SIGTERM", 143, "vampc: terminated (SIGTERM)"),
                                               ("SIGINT", 130, "vampc: interrupted")])
def test_a_signal_while_the_command_line_is_parsed_is_the_signals_line_and_status(tmp_path, sig,
                                                                                  status, line):
    """A SIGTERM or Ctrl-C while click parsed the command line went through click, which took it
    for an interrupted prompt: a blank line, "vampc: interrupted" and exit 1, so a CI job's
    time-out looked like a failure (a CI engineer's find). Now the command raises it as it begins:
    its own line and 128 + the signal, nothing written; and after --help, the same status."""
    import subprocess
    import sys
    code = (
        "import os, signal, sys, click\n"
        "parse = click.core.Command.parse_args\n"
        "def parse_args(self, ctx, args):\n"
        "    if not isinstance(self, click.Group):\n"
        f"        os.kill(os.getpid(), signal.{sig})\n"
        "    return parse(self, ctx, args)\n"
        "click.core.Command.parse_args = parse_args\n"
        "sys.argv = ['vampc', *sys.argv[1:]]\n"
        "from vampc.launch import main\n"
        "main()\n")
    out = tmp_path / "tau.csv"
    import signal

    def ctrl_c_as_at_a_terminal():      # (a test runner's worker may start children ignoring it)
        signal.signal(signal.SIGINT, signal.SIG_DFL)
    r = subprocess.run([sys.executable, "-c", code, "emulate", str(EXAMPLES / "planar2.yaml"),
                        "--random", "5", "-o", str(out)], capture_output=True, text=True, timeout=120,
                       preexec_fn=ctrl_c_as_at_a_terminal)
    assert (r.returncode, r.stderr, r.stdout) == (status, line + "\n", ""), r
    assert not out.exists() and list(tmp_path.iterdir()) == []
    r = subprocess.run([sys.executable, "-c", code, "emulate", "--help"], capture_output=True,
                       text=True, timeout=120, preexec_fn=ctrl_c_as_at_a_terminal)
    assert (r.returncode, r.stderr) == (status, line + "\n") and "--random" in r.stdout, r


def test_a_second_signal_while_the_first_is_said_does_not_kill_the_run(tmp_path):
    """A job runner's second SIGTERM a few milliseconds after the first, while the run said its
    line and removed its outputs, killed the process by that signal (status -15, not 143: a CI
    engineer's find). The second lands here as the run discards its outputs."""
    import subprocess
    import sys
    code = (
        "import os, signal, sys\n"
        "sys.argv = ['vampc', *sys.argv[1:]]\n"
        "import vampc.cli, vampc.commands\n"
        "emulate, discard = vampc.commands.emulate_command, vampc.cli.discard_all\n"
        "def first(*a, **k):\n"
        "    os.kill(os.getpid(), signal.SIGTERM)\n"
        "    return emulate(*a, **k)\n"
        "def second():\n"
        "    os.kill(os.getpid(), signal.SIGTERM)\n"
        "    discard()\n"
        "vampc.commands.emulate_command, vampc.cli.discard_all = first, second\n"
        "from vampc.launch import main\n"
        "main()\n")
    out = tmp_path / "tau.csv"
    r = subprocess.run([sys.executable, "-c", code, "emulate", str(EXAMPLES / "planar2.yaml"),
                        "--random", "5", "-o", str(out)], capture_output=True, text=True, timeout=120)
    assert (r.returncode, r.stderr, r.stdout) == (143, "vampc: terminated (SIGTERM)\n", ""), r
    assert list(tmp_path.iterdir()) == []


def _a_refused_fork():
    def _launch():          # (as multiprocessing's Popen._launch, where os.fork raises it)
        raise BlockingIOError(11, "Resource temporarily unavailable")
    _launch()


@pytest.mark.parametrize("raised", [BlockingIOError(11, "Resource temporarily unavailable"),
                                    "met while handling"])
def test_what_the_system_did_not_refuse_is_still_an_internal_error(monkeypatch, raised):
    """A non-blocking read's EAGAIN is not a refused process, and a bug met while handling a
    refused resource is a bug (a review's finds): both shown in full, exit 3."""
    import vampc.commands

    def bug(*args, **kwargs):
        if isinstance(raised, BaseException):
            raise raised
        try:
            raise OSError(24, "Too many open files")
        except OSError:
            {}["a bug"]
    monkeypatch.setattr(vampc.commands, "emulate_command", bug)
    res = CliRunner().invoke(main, ["emulate", str(EXAMPLES / "planar2.yaml"), "--random", "3"])
    assert res.exit_code == 3 and "internal error" in res.output, res.output


def _chained_emfile():
    try:
        raise OSError(24, "Too many open files")
    except OSError as exc:
        raise ValueError("a library's own wrapping") from exc


@pytest.mark.parametrize("raised, said", [
    (RuntimeError("can't start new thread"), "cannot start a thread"),
    (OSError(24, "Too many open files"), "too many open files"),
    (_chained_emfile, "too many open files"),
    (_a_refused_fork, "the system refused the run a resource"),
    (OSError(12, "Cannot allocate memory"), "the system refused the run a resource")])
def test_what_the_system_refuses_is_one_line_not_an_internal_error(tmp_path, monkeypatch, raised,
                                                                   said):
    """Under `ulimit -v` a thread pool's submit raised "can't start new thread", under `ulimit -n`
    a worker pool's pipe "Too many open files": each a traceback, "internal error", exit 3 (a CI
    engineer's finds). Now one line saying what the system refused, exit 1, nothing written."""
    import vampc.commands

    def refuse(*args, **kwargs):
        if callable(raised):
            raised()
        raise raised
    monkeypatch.setattr(vampc.commands, "emulate_command", refuse)
    out = tmp_path / "tau.csv"
    res = CliRunner().invoke(main, ["emulate", str(EXAMPLES / "planar2.yaml"), "--random", "3",
                                    "-o", str(out)])
    assert res.exit_code == 1 and "Traceback" not in res.output, res.output
    assert res.output.count("\n") == 1 and res.output.startswith(f"vampc: error: {said}")
    assert not out.exists()


def test_outputs_are_put_in_place_under_their_folders_lock(tmp_path):
    """Two runs writing the same -o and --save-states at once had left one run's torques beside
    another's states (each file replaced whole, the pair not: an audit's find). The outputs are put
    in place holding an exclusive lock on their folder: while another process holds it, the run
    waits with its outputs written aside, and puts both in place once it is released."""
    import fcntl
    import os
    import subprocess
    import sys
    import time
    out = tmp_path / "out"
    out.mkdir()
    fd = os.open(out, os.O_RDONLY)
    fcntl.flock(fd, fcntl.LOCK_EX)
    try:
        proc = subprocess.Popen([sys.executable, "-m", "vampc", "emulate", "examples/planar2.yaml",
                                 "--random", "50", "-o", str(out / "tau.csv"), "--save-states",
                                 str(out / "states.csv")], stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, text=True)
        deadline = time.monotonic() + 60
        while len(list(out.iterdir())) < 2 and proc.poll() is None and time.monotonic() < deadline:
            time.sleep(0.05)              # (both written aside: two temporaries in the folder)
        time.sleep(0.5)
        assert proc.poll() is None, proc.communicate()          # waiting for the folder
        assert not (out / "tau.csv").exists() and not (out / "states.csv").exists()
    finally:
        fcntl.flock(fd, fcntl.LOCK_UN)
        os.close(fd)
    stdout, stderr = proc.communicate(timeout=120)
    assert proc.returncode == 0, stderr
    assert sorted(p.name for p in out.iterdir()) == ["states.csv", "tau.csv"]


def test_a_tick_run_of_a_network_too_big_is_refused_whatever_its_sets(program, monkeypatch):
    """A 5000-joint chain's tick run took 16.3 GB with two sets: the check counted only the sets'
    values, not the engine's row of registers for each of its 50 million delay-buffer stages. When
    those alone do not fit, fewer sets would not help, and the message does not say they would."""
    from vampc.emulator import load_program
    ld = load_program(str(program))
    stages = sum(b.stages for b in ld.net.buffers)
    monkeypatch.setattr(driver, "_available_memory", lambda: 4 * driver.TICK_BYTES_PER_STAGE * stages)
    assert run("emulate", program, "--random", 1, "--engine", "tick").exit_code == 0
    monkeypatch.setattr(driver, "_available_memory", lambda: driver.TICK_BYTES_PER_STAGE * stages)
    res = run("emulate", program, "--random", 1, "--engine", "tick")
    user_error(res, rf"planar\.vamp\.json: the network's {stages:,} delay-buffer stages need about "
                    r"[\d.]+ GiB in the tick engine, whatever the sets \([\d.]+ GiB available\); use "
                    r"--engine stream, which holds no register per stage")


def test_the_memory_available_is_memavailable_within_a_cgroups_limit(tmp_path):
    """The memory checks read the free pages alone (SC_AVPHYS_PAGES), which leave out the page
    cache the system can reclaim, and no container's limit (a review's find): MemAvailable, within
    what every cgroup limit from the process's own up to the root leaves (a parent's applies below
    it: a second review's find), its usage without the reclaimable cache. Worked out here by hand."""
    from vampc.emulator import driver
    meminfo = tmp_path / "meminfo"
    meminfo.write_text("MemTotal:       24000000 kB\nMemFree:          500000 kB\n"
                       "MemAvailable:   20000000 kB\n")
    assert driver.mem_available(str(meminfo)) == 20000000 * 1024
    meminfo.write_text("MemTotal:       24000000 kB\n")
    assert driver.mem_available(str(meminfo)) is None
    assert driver.mem_available(str(tmp_path / "none")) is None
    root, own = tmp_path / "cgroup", tmp_path / "self"
    job = root / "user" / "job"
    job.mkdir(parents=True)
    own.write_text("0::/user/job\n")
    assert driver.cgroup_room(str(root), str(own)) is None                  # no limit files
    (job / "memory.max").write_text("max\n")
    assert driver.cgroup_room(str(root), str(own)) is None
    (job / "memory.max").write_text("3000000000\n")
    (job / "memory.current").write_text("1000000000\n")
    assert driver.cgroup_room(str(root), str(own)) == 2000000000
    (job / "memory.stat").write_text("anon 1\ninactive_file 400000000\nactive_file 5\n")
    assert driver.cgroup_room(str(root), str(own)) == 2400000000          # the cache reclaimable
    (job / "memory.max").write_text("max\n")                               # a parent's limit only
    (root / "user" / "memory.max").write_text("1500000000\n")
    (root / "user" / "memory.current").write_text("1000000000\n")
    assert driver.cgroup_room(str(root), str(own)) == 500000000
    (root / "memory.max").write_text("1000\n")                             # the least of all
    (root / "memory.current").write_text("4000\n")
    assert driver.cgroup_room(str(root), str(own)) == 0
    own.write_bytes(b"0::/us\xe9r/job\n")                                   # odd bytes: no crash
    assert driver.cgroup_room(str(root), str(own)) == 0
    v1 = tmp_path / "v1"
    (v1 / "memory" / "box").mkdir(parents=True)
    own.write_text("4:memory:/box\n0::/\n")
    (v1 / "memory" / "box" / "memory.limit_in_bytes").write_text("5000\n")
    (v1 / "memory" / "box" / "memory.usage_in_bytes").write_text("1000\n")
    (v1 / "memory" / "box" / "memory.stat").write_text("cache 600\ntotal_inactive_file 300\n")
    assert driver.cgroup_room(str(v1), str(own)) == 4300
    (v1 / "memory" / "box" / "memory.limit_in_bytes").write_text(f"{2 ** 63 - 4096}\n")  # v1's none
    assert driver.cgroup_room(str(v1), str(own)) is None


def test_standard_errors_own_file_is_never_replaced_by_an_output(tmp_path):
    """`-o /dev/stderr 2>>log.txt` (or /proc/self/fd/2) replaced the log with the torques by a
    rename, exit 0, and later messages went to the deleted file (a file-safety audit): standard
    error's own regular file is refused, exit 2, the log kept and the message appended to it."""
    import subprocess
    import sys
    log = tmp_path / "log.txt"
    log.write_text("line 1 of my build log\n")
    for name in ("/dev/stderr", "/proc/self/fd/2"):
        with open(log, "a") as err:
            r = subprocess.run([sys.executable, "-m", "vampc", "emulate", str(EXAMPLES / "planar2.yaml"),
                                "--random", "2", "-o", name], stderr=err, stdout=subprocess.PIPE,
                               cwd=tmp_path)
        text = log.read_text()
        assert r.returncode == 2 and text.startswith("line 1 of my build log\n"), text
        assert f"-o {name}: that is standard error" in text.splitlines()[-1]


def test_a_long_output_name_is_written_though_its_temporary_would_be_too_long(tmp_path):
    """A name of 234 to 255 bytes made a temporary ('.NAME.<16 hex>.tmp') past the file system's
    255 bytes, and the output failed after all the work ('File name too long'), an existing file of
    that name never replaced (a file-safety audit): the temporary keeps a shorter part of the name."""
    name = tmp_path / ("t" * 240 + ".csv")
    for _ in range(2):                          # written, then replaced
        r = CliRunner().invoke(main, ["emulate", str(EXAMPLES / "planar2.yaml"), "--random", "2",
                                      "-o", str(name)])
        assert r.exit_code == 0, r.output
        assert name.read_text().startswith("tau_shoulder,tau_elbow\n")
    assert sorted(p.name for p in tmp_path.iterdir()) == [name.name]


def _each_refused_and_kept(folder, read: list[str]) -> None:
    """Each of `read` (the first an XML file the model includes, the others written here) refused
    as -o of main.xml's command, and left as it was."""
    from vampc.errors import VampcError
    from vampc.outputs import plan_outputs
    for name in read[1:]:
        (folder / name).write_bytes(b"keep me")
    before = {name: (folder / name).read_bytes() for name in read}
    for name in read:
        with pytest.raises(VampcError, match=r"is the input file .*; vampc never writes over its inputs"):
            plan_outputs([folder / "main.xml"], {"-o": str(folder / name)})
        assert (folder / name).read_bytes() == before[name]


def test_the_files_an_mjcf_model_reads_are_inputs_too(tmp_path):
    """`vampc compile main.xml -o body.xml`, body.xml being the file main.xml includes, replaced it
    with the program file, exit 0 (a file-safety audit): an MJCF model's includes, and the meshes,
    skins, textures and height fields it names (from <compiler meshdir|texturedir|assetdir>), are
    refused as outputs like the model itself. A URDF's mesh files are not read, nor guarded."""
    from vampc.outputs import plan_outputs
    (tmp_path / "m").mkdir()
    (tmp_path / "main.xml").write_text(
        '<mujoco model="two"><compiler meshdir="m" texturedir="t"/><include file="body.xml"/>'
        '<asset><mesh file="link.stl"/><texture file="skin.png" type="2d"/></asset></mujoco>')
    (tmp_path / "body.xml").write_text(
        '<mujoco><worldbody><body name="a"><joint name="j1" type="hinge" axis="0 0 1"/>'
        '<inertial pos="0.1 0 0" mass="1" diaginertia="0.01 0.01 0.01"/></body></worldbody>'
        '<asset><hfield file="ground.png" size="1 1 1 1"/></asset></mujoco>')
    (tmp_path / "t").mkdir()
    read = ["body.xml", "m/link.stl", "t/skin.png", "t/ground.png"]
    _each_refused_and_kept(tmp_path, read)
    plan_outputs([tmp_path / "main.xml"], {"-o": str(tmp_path / "p.vamp.json")})   # others are free
    urdf = tmp_path / "r.urdf"
    urdf.write_text('<robot name="r"><link name="a"><visual><geometry><mesh filename="m/link.stl"/>'
                    '</geometry></visual></link></robot>')
    plan_outputs([urdf], {"-o": str(tmp_path / "m" / "link.stl")})


def test_a_line_break_in_a_name_keeps_the_error_and_the_warning_on_one_line(tmp_path):
    """A file name holding a line break made the one-line error two or three lines (a file-safety
    audit): it is written as \\n, so a script reading the last line of stderr gets all of it."""
    r = CliRunner().invoke(main, ["emulate", str(EXAMPLES / "planar2.yaml"), "--random", "2", "-o",
                                  str(tmp_path / "nodir\nx" / "a.csv")])
    assert r.exit_code == 1 and r.stderr.count("\n") == 1, r.stderr
    assert "nodir\\nx/a.csv: folder " in r.stderr
    r = CliRunner().invoke(main, ["compile", str(tmp_path / "no\nsuch.yaml")])
    assert r.exit_code == 1 and r.stderr == f"vampc: error: {tmp_path}/no\\nsuch.yaml: no such file\n"
    robot = tmp_path / "a\nb.yaml"             # alpha: 90, degrees: a warning naming the file
    robot.write_text((EXAMPLES / "planar2.yaml").read_text().replace("alpha: 0.0", "alpha: 90.0", 1))
    r = CliRunner().invoke(main, ["compile", str(robot), "-o", str(tmp_path / "p.vamp.json")])
    lines = r.stderr.splitlines()
    assert r.exit_code == 0 and len(lines) == 1 and lines[0].startswith("vampc: warning: ") \
        and "a\\nb.yaml" in lines[0] and "DH angles are radians" in lines[0], r.stderr


def test_two_outputs_to_standard_output_are_a_usage_error_in_every_command(tmp_path):
    """`emulate -o - --save-states -` was exit 1 ('name the same file'), `lookahead -o - --torques -`
    exit 2 (a file-safety audit): the same mistake, options alone, is a usage error in both."""
    r = CliRunner().invoke(main, ["emulate", str(EXAMPLES / "planar2.yaml"), "--random", "2", "-o",
                                  "-", "--save-states", "-"])
    assert r.exit_code == 2 and "-o - and --save-states -: only one can be standard output" \
        in r.output, r.output


def test_a_blank_line_in_a_piped_trajectory_is_said_at_once(tmp_path):
    """Whether a blank line came of CR CR LF line ends was asked by opening the trajectory again by
    name: a FIFO's writer was gone by then and the run hung for good (a review's find); it is read
    off the bytes already in memory, also for standard input."""
    import subprocess
    import sys
    import threading
    fifo = tmp_path / "states"
    os.mkfifo(fifo)
    body = b"q1,q2,qd1,qd2,qdd1,qdd2\n0,0,0,0,0,0\n\n0,0,0,0,0,0\n"
    writer = threading.Thread(target=lambda: fifo.write_bytes(body), daemon=True)
    writer.start()
    r = subprocess.run([sys.executable, "-m", "vampc", "emulate", str(EXAMPLES / "planar2.yaml"),
                        "--trajectory", str(fifo)], capture_output=True, timeout=60)
    assert r.returncode == 1 and r.stderr.decode().endswith(
        "line 3 is blank: blank lines can only end the table\n"), r.stderr
    crcr = body.replace(b"\n", b"\r\r\n")
    r = subprocess.run([sys.executable, "-m", "vampc", "emulate", str(EXAMPLES / "planar2.yaml"),
                        "--trajectory", "-"], input=crcr, capture_output=True, timeout=60)
    assert r.returncode == 1 and b"(lines ended CR CR LF" in r.stderr, r.stderr


def test_an_include_of_an_include_and_its_assets_are_inputs_where_mujoco_finds_them(tmp_path):
    """MuJoCo finds an include's include, and the meshes an included file names, beside the
    including file; they were looked for beside the model only, and `compile main.xml -o
    sub/b.xml` replaced the nested include, exit 0 (a review's find). A cube texture's six files
    (fileright ... fileback) are inputs too."""
    (tmp_path / "sub").mkdir()
    (tmp_path / "main.xml").write_text('<mujoco model="nested"><include file="sub/a.xml"/></mujoco>')
    (tmp_path / "sub" / "a.xml").write_text(
        '<mujoco><include file="b.xml"/><asset><mesh file="m.obj"/>'
        '<texture type="skybox" fileright="r.png" fileleft="l.png" fileup="u.png" filedown="d.png" '
        'filefront="f.png" fileback="k.png"/></asset></mujoco>')
    (tmp_path / "sub" / "b.xml").write_text('<mujoco><worldbody/></mujoco>')
    read = ["sub/b.xml", "sub/m.obj", *(f"sub/{c}.png" for c in "rludfk")]
    _each_refused_and_kept(tmp_path, read)


def test_vampcs_own_outputs_given_as_a_robot_are_named(tmp_path):
    """`vampc emulate report.json` said "Additional properties are not allowed ('allocation' was
    unexpected)", a faults results file 'JSON (a DH table?)', a picture 'XML (a URDF)' (a new
    user's finds): each of vampc's own outputs given where a robot is expected is named."""
    run = CliRunner().invoke
    planar = str(EXAMPLES / "planar2.yaml")
    outs = {
        "report.json": (["report", planar, "--format", "json"], "a vampc report (vampc report --format json)"),
        "tradeoff.json": (["report", planar, "--tradeoff", "--format", "json"], "a vampc report --tradeoff"),
        "precision.json": (["precision", planar, "--sweep", "20:21", "--format", "json"],
                           "a vampc precision report"),
    }
    for name, (args, said) in outs.items():
        r = run(main, args)
        assert r.exit_code == 0, r.output
        (tmp_path / name).write_text(r.stdout)
        e = run(main, ["compile", str(tmp_path / name)])
        assert e.exit_code == 1 and f"this is {said}" in e.stderr and "not a robot description" in \
            e.stderr, e.stderr
    (tmp_path / "r.jsonl").write_text('{"vampc_faults": 1, "program": "x"}\n')
    e = run(main, ["compile", str(tmp_path / "r.jsonl")])
    assert "it looks like a results file of vampc faults" in e.stderr, e.stderr
    assert run(main, ["report", planar, "--timing", str(tmp_path / "t.svg")]).exit_code == 0
    e = run(main, ["compile", str(tmp_path / "t.svg")])
    assert "it looks like an SVG picture" in e.stderr, e.stderr


def test_a_misspelled_value_gets_the_name_it_is_closest_to(tmp_path):
    """A misspelled option name gets click's "Did you mean", a misspelled value nothing (`--kinds
    dea`, a limits row `waste`: a new user's finds): where a name is chosen from a list, the
    closest is offered, and nothing when none is close."""
    run = CliRunner().invoke
    ur5 = str(EXAMPLES / "ur5.urdf")
    for args, said in (
            (["compile", ur5, "--tip", "wrist_3_lnk"], "unknown tip link 'wrist_3_lnk' (did you mean "
                                                       "'wrist_3_link'?)"),
            (["compile", ur5, "--base", "base_lnk"], "unknown base link 'base_lnk' (did you mean "
                                                     "'base_link'?)"),
            (["compile", ur5, "--lock", "shoulder_pan=0"], "no joint named 'shoulder_pan' (did you "
                                                            "mean 'shoulder_pan_joint'?)"),
            (["faults", str(EXAMPLES / "planar2.yaml"), "--kinds", "dea"],
             "(did you mean 'dead'?)")):
        r = run(main, [*args, "-o", str(tmp_path / "x.out")] if args[0] == "compile" else args)
        assert r.exit_code in (1, 2) and said in r.output, r.output
    r = run(main, ["compile", ur5, "--tip", "zzzz"])
    assert r.exit_code == 1 and "did you mean" not in r.output
    limits = tmp_path / "lim.csv"
    limits.write_text("joint,tau,qd\nwaste,10,1\n")
    path = tmp_path / "path.csv"
    path.write_text((EXAMPLES / "puma560-path.csv").read_text())
    r = run(main, ["lookahead", str(EXAMPLES / "puma560.yaml"), "--trajectory", str(path), "--rate",
                   "1kHz", "--window", "8", "--limits", str(limits)])
    assert r.exit_code == 1 and "no joint named 'waste' (did you mean 'waist'?)" in r.output, r.output


@pytest.mark.parametrize("extra, option", [([], "--network"), (["--tradeoff"], "--curve")])
def test_a_report_whose_text_cannot_be_written_leaves_its_pictures_old_files(tmp_path, extra,
                                                                             option):
    """`report --network n.svg > /dev/full` exited 1 with n.svg already replaced (the pictures were
    put in place before the text was written; an audit's): the text goes first."""
    import subprocess
    import sys
    picture = tmp_path / "n.svg"
    picture.write_text("OLD\n")
    with open("/dev/full", "w") as full:
        done = subprocess.run([sys.executable, "-m", "vampc", "report", "examples/planar2.yaml",
                               *extra, option, str(picture)], stdout=full, stderr=subprocess.PIPE,
                              text=True, env={**os.environ, "VAMPC_PROGRESS": "0"})
    assert done.returncode == 1 and "cannot write to standard output" in done.stderr, done.stderr
    assert picture.read_text() == "OLD\n" and sorted(p.name for p in tmp_path.iterdir()) == ["n.svg"]


def _vampc(*args, **kw):
    """vampc as a process, its standard streams as given (the tests below need real ones)."""
    import subprocess
    return subprocess.run([sys.executable, "-m", "vampc", *map(str, args)], capture_output=False,
                          text=True, **kw)


def test_a_summary_standard_output_cannot_take_is_dropped_with_the_files_written(tmp_path, program):
    """`emulate -o a.csv --save-states b.csv > /dev/full` (and `compile`, `lookahead`) replaced the
    files, then said "cannot write to standard output", exit 1: new files beside a failed status
    (a new user's find). The summary lines are dropped, said once on standard error; the files
    are written and the exit status is the run's. A result on standard output (report) is still
    an error."""
    import subprocess
    if not os.path.exists("/dev/full"):
        pytest.skip("no /dev/full here")
    a, b = tmp_path / "a.csv", tmp_path / "b.csv"
    a.write_text("old\n")
    b.write_text("old\n")
    with open("/dev/full", "w") as full:
        done = _vampc("emulate", program, "--random", 5, "-o", a, "--save-states", b, stdout=full,
                      stderr=subprocess.PIPE)
    assert done.returncode == 0, done.stderr
    assert done.stderr == ("vampc: warning: standard output cannot take the summary lines (No space "
                           "left on device): they are dropped; files are written as without them\n")
    assert a.read_text().startswith("tau_") and b.read_text().startswith("q1,")
    with open("/dev/full", "w") as full:
        done = _vampc("report", program, stdout=full, stderr=subprocess.PIPE)
    assert done.returncode == 1 and "cannot write to standard output: No space left" in done.stderr


def test_standard_errors_own_pipe_is_not_an_output(tmp_path, program):
    """`-o /dev/stderr 2>&1 | cat` wrote the torques into the pipe that carries the messages, exit 0
    (refused only where standard error was a regular file: a new user's find)."""
    import subprocess
    done = subprocess.run(f"{sys.executable} -m vampc emulate {program} --random 2 -o /dev/stderr "
                          "2>&1 >/dev/null | cat; exit ${PIPESTATUS[0]}", shell=True, text=True,
                          capture_output=True, executable="/bin/bash")
    assert done.returncode == 2 and "-o /dev/stderr: that is standard error, which carries the " \
        "command's messages" in done.stdout, (done.stdout, done.stderr)


@pytest.mark.parametrize("extra", [[], ["--tradeoff", "--workers", "1", "--curve"]])
def test_a_picture_that_cannot_be_written_leaves_no_report_text(extra):
    """`report --reservation /dev/full` printed the whole report, then failed on the picture, exit 1
    (a new user's find): "a full disk is one line naming the file, exit 1, and nothing else"."""
    if not os.path.exists("/dev/full"):
        pytest.skip("no /dev/full here")
    picture = [] if extra else ["--reservation"]
    res = run("report", EXAMPLES / "planar2.yaml", *extra, *picture, "/dev/full")
    user_error(res, r"^vampc: error: /dev/full: cannot write \w+: No space left on device$")
    assert res.stdout == "", res.stdout[:200]


def test_rtl_figures_standard_output_cannot_take_leave_the_old_verilog(tmp_path):
    """`rtl -o out.v --cosim 1 > /dev/full` put the Verilog in place, then failed on its figures,
    exit 1 (a review's find): the figures are printed before the file is put in place."""
    import subprocess
    pytest.importorskip("amaranth")
    if not os.path.exists("/dev/full"):
        pytest.skip("no /dev/full here")
    out = tmp_path / "out.v"
    out.write_text("OLD\n")
    robot = tmp_path / "arm1.yaml"       # one joint on one VAMP: 3 s, where planar2 on 3 took 6.4 s
    robot.write_text(ARM1)
    with open("/dev/full", "w") as full:
        done = _vampc("rtl", robot, "--word", "q16.16", "--vamps", 1, "-o", out,
                      "--cosim", 1, stdout=full, stderr=subprocess.PIPE)
    assert done.returncode == 1 and "cannot write to standard output: No space left" in done.stderr
    assert out.read_text() == "OLD\n"


def test_a_file_name_that_is_not_utf8_is_written_as_its_bytes(tmp_path):
    """A robot file named b'b\\xff.yaml' (Python hands the name over with a lone surrogate, which
    UTF-8 has no bytes for) ended `compile` and `faults --format json` in an internal error (an
    audit's find): the name is written into the JSON as its bytes read, 'b\\\\xff.yaml'."""
    robot = Path(os.fsdecode(bytes(tmp_path) + b"/b\xff.yaml"))
    robot.write_bytes((EXAMPLES / "planar2.yaml").read_bytes())
    program = tmp_path / "p.vamp.json"
    res = run("compile", robot, "-o", program)
    assert res.exit_code == 0, res.output
    source = json.loads(program.read_text())["robot"]["source"]
    assert source.endswith("b\\xff.yaml"), source
    res = run("emulate", program, "--random", "3", "--check")
    assert res.exit_code == 0 and "OK" in res.output, res.output
    results = Path(os.fsdecode(bytes(tmp_path) + b"/r\xff.jsonl"))
    res = run("faults", program, "--workers", "1", "--kinds", "dead", "--results", results,
              "--format", "json")
    assert res.exit_code == 0, res.output
    assert json.loads(res.stdout)["results"].endswith("r\\xff.jsonl") and results.exists()


def test_a_replaced_output_keeps_its_owner_and_a_hard_link_is_said(program, tmp_path):
    """Root replacing a file of another user's made it root's (the owner could no longer write
    it), and a hard link to the output was split without a word (an audit's find): the owner and
    group are kept where the user may give them, and the other names of a hard-linked file, which
    keep the old content, are said."""
    out, other = tmp_path / "t.csv", tmp_path / "other.csv"
    out.write_text("OLD\n")
    os.link(out, other)
    if IS_ROOT:
        os.chown(out, 65534, 65534)
    res = run("emulate", program, "--random", "2", "-o", out)
    assert res.exit_code == 0, res.output
    assert re.search(rf"warning: -o {re.escape(str(out))}: the file has 1 other hard link\(s\), which "
                     r"keep the old content: the new file replaces this name only", res.stderr)
    assert other.read_text() == "OLD\n" and out.read_text().startswith("tau_")
    if IS_ROOT:
        assert (out.stat().st_uid, out.stat().st_gid) == (65534, 65534)
    res = run("emulate", program, "--random", "2", "-o", out)          # one name now: nothing said
    assert res.exit_code == 0 and "warning" not in res.stderr


@pytest.mark.skipif(not IS_ROOT, reason="a file of another user's needs root to make")
def test_an_owner_that_cannot_be_kept_is_said(program, tmp_path, monkeypatch):
    """Where the owner or group cannot be given (a user not root, root on NFS with root_squash: here
    chown refused as it would be), the new file's owner was changed without a word (a review's
    find): said, with both."""
    out = tmp_path / "t.csv"
    out.write_text("OLD\n")
    os.chown(out, 65534, 65534)

    def refused(*args, **kwargs):
        raise PermissionError(1, "Operation not permitted")
    monkeypatch.setattr(os, "chown", refused)
    res = run("emulate", program, "--random", "2", "-o", out)
    assert res.exit_code == 0, res.output
    assert re.search(rf"warning: -o {re.escape(str(out))}: the new file's owner and group are "
                     r"0:0, not the old file's 65534:65534, which this user cannot give", res.stderr)


@pytest.mark.parametrize("command", [["emulate", "{program}", "--random", "3", "--word", "float32"],
                                     ["compile", "{robot}", "-o", "out.yaml"]])
def test_standard_error_appended_to_an_input_is_refused_before_a_word(tmp_path, command):
    """`vampc emulate p.vamp.json --word float32 2>> p.vamp.json` appended its warning to the
    program file and ran on, exit 0, and the file no longer read; `compile r.yaml -o out.yaml 2>>
    r.yaml` wrote its warning into the robot file, then called the file bad YAML (a new user's
    find). Refused before anything is said, the refusal on standard output, the file as it was;
    a word of the command line that names standard error's file but no input (`--recursion log
    2> log`) is no input (a review's find: the first check, on every word, refused it)."""
    import subprocess
    import sys
    robot = tmp_path / "planar2.yaml"
    robot.write_bytes(PLANAR.read_bytes())
    program = tmp_path / "p.vamp.json"
    subprocess.run([sys.executable, "-m", "vampc.cli", "compile", str(robot), "-o", str(program)],
                   check=True, capture_output=True)
    args = [a.format(robot=robot, program=program) for a in command]
    victim = program if "{program}" in command else robot
    before = victim.read_bytes()
    with open(victim, "ab") as fh:
        done = subprocess.run([sys.executable, "-m", "vampc.cli", *args], stdout=subprocess.PIPE,
                              stderr=fh, text=True, cwd=tmp_path)
    assert done.returncode == 1 and done.stdout == (
        f"vampc: error: {victim}: standard error is this input file (redirected onto it); vampc "
        "never writes over its inputs: send standard error elsewhere\n")
    assert victim.read_bytes() == before and not (tmp_path / "out.yaml").exists()
    with open(tmp_path / "log", "wb") as fh:
        done = subprocess.run([sys.executable, "-m", "vampc.cli", "compile", str(robot),
                               "--recursion", "log", "-o", "p.json"], stdout=subprocess.PIPE,
                              stderr=fh, text=True, cwd=tmp_path)
    assert done.returncode == 0 and (tmp_path / "p.json").exists()


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="no /dev/full")
def test_a_full_standard_output_says_what_had_gone_out(tmp_path):
    """`-o - > /dev/full` (a full disk, or a file-size limit) said only "cannot write torques",
    where a signal's stop says what had gone out (a new user's find): the write error says it too.
    Against a file-size limit the sets written whole are counted."""
    import resource
    import subprocess
    import sys
    program = tmp_path / "p.vamp.json"
    subprocess.run([sys.executable, "-m", "vampc.cli", "compile", str(PLANAR), "-o", str(program)],
                   check=True, capture_output=True)
    with open("/dev/full", "wb") as full:
        done = subprocess.run([sys.executable, "-m", "vampc.cli", "emulate", str(program),
                               "--random", "50", "-o", "-"], stdout=full, stderr=subprocess.PIPE,
                              text=True)
    assert done.returncode == 1 and done.stderr == (
        "vampc: error: -: cannot write torques: No space left on device; -o - had sent at most part "
        "of its header, and no set to standard output\n"), done.stderr
    out = tmp_path / "t.csv"

    def small():          # (Python ignores SIGXFSZ: a write past the limit fails with EFBIG)
        resource.setrlimit(resource.RLIMIT_FSIZE, (8192, 8192))
    with open(out, "wb") as fh:
        done = subprocess.run([sys.executable, "-m", "vampc.cli", "emulate", str(program),
                               "--random", "100000", "-o", "-"], stdout=fh,
                              stderr=subprocess.PIPE, text=True, preexec_fn=small)
    assert done.returncode == 1 and done.stderr.startswith(
        "vampc: error: -: cannot write torques: File too large; -o - had sent "), done.stderr
    assert done.stderr.endswith(" to standard output\n") and out.stat().st_size == 8192


@pytest.mark.parametrize("case", ["usage", "output", "results", "stdin"])
def test_standard_error_onto_a_file_given_is_refused_before_any_message(tmp_path, case):
    """Standard error onto a file the command line gives was checked only once the command ran (a
    review's find): a usage error (`--recursion bogus 2>> r.yaml`) was written into the robot file,
    `-o p.json 2>> p.json`'s own refusal into the program, which then no longer read, and a
    `--results` file's next resume failed on the line; standard error onto the file standard input
    reads (`--trajectory - < st.csv 2>> st.csv`) read the warning back as data. Each is refused
    before a word is said (an output exit 2, as its other refusals; an input 1), the file kept."""
    import subprocess
    import sys
    robot = tmp_path / "planar2.yaml"
    robot.write_bytes(PLANAR.read_bytes())
    program = tmp_path / "p.vamp.json"
    subprocess.run([sys.executable, "-m", "vampc.cli", "compile", str(robot), "-o", str(program)],
                   check=True, capture_output=True)
    states = tmp_path / "st.csv"
    states.write_text("q1,q2,qd1,qd2,qdd1,qdd2\n" + "0,0,0,0,0,0\n" * 3)
    results = tmp_path / "r.jsonl"
    results.write_text("not yet\n")
    args, victim, code, said = {
        "usage": (["compile", str(robot), "--recursion", "bogus", "-o", "x.json"], robot, 1,
                  f"{robot}: standard error is this input file"),
        "output": (["compile", str(robot), "-o", str(program)], program, 2,
                   f"-o {program}: standard error is this output file"),
        "results": (["faults", str(program), "--results", str(results)], results, 1,
                    f"{results}: standard error is this input file"),
        "stdin": (["emulate", str(program), "--trajectory", "-", "--word", "float32"], states, 1,
                  "the file standard input reads (an input given as -): standard error is this "
                  "input file"),
    }[case]
    before = victim.read_bytes()
    with open(victim, "ab") as err, open(states, "rb") as stdin:
        done = subprocess.run([sys.executable, "-m", "vampc.cli", *args], stdin=stdin,
                              stdout=subprocess.PIPE, stderr=err, text=True, cwd=tmp_path)
    assert done.returncode == code and done.stdout.startswith(f"vampc: error: {said} (redirected "
                                                              "onto it); "), done.stdout
    assert victim.read_bytes() == before


def test_a_write_error_says_what_the_other_table_had_sent(tmp_path):
    """`-o t.csv --save-states -` under a file-size limit: the torques' file failed and the error
    did not say the states had gone out to standard output, as a signal's note does (a review's
    find); `-o /dev/stdout` is named as given, not as `-o -`."""
    import resource
    import subprocess
    import sys
    program = tmp_path / "p.vamp.json"
    subprocess.run([sys.executable, "-m", "vampc.cli", "compile", str(PLANAR), "-o", str(program)],
                   check=True, capture_output=True)

    def small():
        resource.setrlimit(resource.RLIMIT_FSIZE, (300_000, 300_000))
    done = subprocess.run([sys.executable, "-m", "vampc.cli", "emulate", str(program), "--random",
                           "20000", "-o", str(tmp_path / "t.csv"), "--save-states", "-"],
                          stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                          preexec_fn=small)
    assert done.returncode == 1 and f"{tmp_path / 't.csv'}: cannot write torques: File too large; " \
        "--save-states - had sent " in done.stderr, done.stderr
    with open("/dev/full", "wb") as full:
        done = subprocess.run([sys.executable, "-m", "vampc.cli", "emulate", str(program),
                               "--random", "5", "-o", "/dev/stdout"], stdout=full,
                              stderr=subprocess.PIPE, text=True)
    assert done.returncode == 1 and "; -o /dev/stdout had sent at most part of its header" in \
        done.stderr, done.stderr
