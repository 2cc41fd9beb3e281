"""What a pipeline's machine may be: a locale that is not UTF-8, a standard error that cannot be
written, no usable temporary folder (a CI user's finds). Outputs are the same bytes whatever the
locale; a help text or a warning never fails a run."""
from __future__ import annotations

import importlib.util
import os
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import EXAMPLES

PACKAGE_ROOT = Path(importlib.util.find_spec("vampc").origin).parent.parent


def vampc(*args, cwd, stderr=subprocess.PIPE, ascii_locale: bool = True, **extra_env):
    """`python -m vampc ARGS` as a real process, in the C locale without Python's UTF-8 coercion
    (standard streams and file names ASCII: what a Latin-1 or ASCII runner gives)."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(PACKAGE_ROOT),
                                                       os.environ.get("PYTHONPATH", "")]))
    if ascii_locale:
        env.update(LC_ALL="C", LANG="C", PYTHONUTF8="0", PYTHONCOERCECLOCALE="0")
        env.pop("PYTHONIOENCODING", None)
    env.update(extra_env)
    return subprocess.run([sys.executable, "-m", "vampc", *map(str, args)], cwd=cwd, env=env,
                          stdout=subprocess.PIPE, stderr=stderr, timeout=120)


def ascii_child(tmp_path) -> None:
    """Skip where the C locale without coercion is not ASCII here (nothing would be tested)."""
    code = "import locale, sys; print(locale.getpreferredencoding(False), sys.stdout.encoding)"
    env = dict(os.environ, LC_ALL="C", LANG="C", PYTHONUTF8="0", PYTHONCOERCECLOCALE="0")
    env.pop("PYTHONIOENCODING", None)
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                         cwd=tmp_path).stdout.split()
    if any("utf" in e.lower().replace("-", "") for e in out):
        pytest.skip(f"the C locale is {out} here, not ASCII")


def umlaut_robot(folder: Path) -> Path:
    text = (EXAMPLES / "planar2.yaml").read_text(encoding="utf-8")
    path = folder / "plänar.yaml"
    path.write_text(text.replace("name: planar2", "name: plänar").replace("name: elbow",
                                                                          "name: ellbögen"),
                    encoding="utf-8")
    return path


def test_help_under_an_ascii_locale_escapes_what_it_cannot_hold(tmp_path):
    ascii_child(tmp_path)
    # (every command's --help was a UnicodeEncodeError traceback, exit 1, nothing on stdout)
    for command in ("compile", "report", "emulate", "lookahead", "precision", "rtl", "faults"):
        res = vampc(command, "--help", cwd=tmp_path)
        assert res.returncode == 0 and b"Traceback" not in res.stderr, (command, res.stderr)
        assert res.stdout.startswith(b"Usage: ") and b"--help" in res.stdout
    assert b"\\u2308" in vampc("report", "--help", cwd=tmp_path).stdout      # ⌈, escaped


def test_outputs_are_utf8_whatever_the_locale_and_names_beyond_it_are_written(tmp_path):
    """A torque CSV's header was written in the locale's encoding (other bytes under Latin-1, a
    traceback for a name it cannot hold), a picture was an internal error, and an output file named
    beyond ASCII was a traceback; each is now the UTF-8 run's bytes. Standard output keeps its
    own encoding: a result it cannot hold is refused in one line, a summary line escaped."""
    ascii_child(tmp_path)
    robot = umlaut_robot(tmp_path)
    program = tmp_path / "p.vamp.json"
    assert vampc("compile", robot, "-o", program, cwd=tmp_path, ascii_locale=False).returncode == 0
    outs = {}
    for ascii_locale in (False, True):
        folder = tmp_path / ("c" if ascii_locale else "utf8")
        folder.mkdir()
        torques = folder / "tau ü.csv"
        res = vampc("emulate", program, "--random", "3", "-o", torques, cwd=folder,
                    ascii_locale=ascii_locale)
        assert res.returncode == 0 and b"Traceback" not in res.stderr, res.stderr
        res = vampc("report", program, "--format", "json", "--network", folder / "n.svg", "--dot",
                    folder / "d.dot", "--reservation", folder / "r.svg", "--html",
                    folder / "ä.html", cwd=folder, ascii_locale=ascii_locale)
        assert res.returncode == 0 and b"Traceback" not in res.stderr, res.stderr
        outs[ascii_locale] = {p.name: p.read_bytes() for p in folder.iterdir()}
    assert outs[True] == outs[False]
    assert "tau_ellbögen".encode() in outs[True]["tau ü.csv"]
    assert sorted(outs[True]) == ["d.dot", "n.svg", "r.svg", "tau ü.csv", "ä.html"]
    # the torques to standard output (their header names ellbögen): refused in one line, not an
    # internal error; a compile's summary line naming ö.vamp.json: its bytes as given (standard
    # output's surrogate escapes), the program written
    res = vampc("emulate", program, "--random", "3", "-o", "-", cwd=tmp_path)
    assert res.returncode == 1 and res.stdout == b"", res.stderr
    assert res.stderr.decode().splitlines() == [
        "vampc: error: cannot write to standard output: its encoding (ascii) cannot hold 'ö'; use a "
        "UTF-8 locale or PYTHONIOENCODING=utf-8"]
    res = vampc("compile", robot, "-o", tmp_path / "ö.vamp.json", cwd=tmp_path)
    assert res.returncode == 0 and (tmp_path / "ö.vamp.json").read_bytes() == program.read_bytes()
    assert "ö.vamp.json: 2 joints".encode() in res.stdout, res.stdout
    # standard output that is strictly ASCII (PYTHONIOENCODING): the summary line escaped (it had
    # failed the run after the program was written, exit 1: a review's find)
    res = vampc("compile", robot, "-o", tmp_path / "ö2.vamp.json", cwd=tmp_path, ascii_locale=False,
                PYTHONIOENCODING="ascii")
    assert res.returncode == 0 and b"\\xf62.vamp.json: 2 joints" in res.stdout, (res.stdout, res.stderr)


def test_a_standard_error_that_cannot_be_written_drops_the_warnings_not_the_run(tmp_path):
    # (a warning to a full or read-only standard error failed the run: exit 1, no program, nothing
    # said); an error is still the exit status, a usage error's 2 too (the last line to a full
    # standard error had made it 1: a review's find)
    targets = [(os.devnull, "r")] + ([("/dev/full", "w")] if os.path.exists("/dev/full") else [])
    for target, mode in targets:
        with open(target, mode) as err:
            out = tmp_path / "a.vamp.json"
            res = vampc("compile", EXAMPLES / "arm6.urdf", "--lock", "camera_mount=0", "-o", out,
                        cwd=tmp_path, stderr=err, ascii_locale=False)
            assert res.returncode == 0 and out.exists(), target
            out.unlink()
            res = vampc("compile", tmp_path / "missing.urdf", cwd=tmp_path, stderr=err,
                        ascii_locale=False)
            assert res.returncode == 1 and not list(tmp_path.glob("*.vamp.json"))
            res = vampc("compile", EXAMPLES / "planar2.yaml", "--no-such-option", cwd=tmp_path,
                        stderr=err, ascii_locale=False)
            assert res.returncode == 2 and not list(tmp_path.glob("*.vamp.json"))


def test_a_progress_bar_to_a_standard_error_that_cannot_be_written_is_dropped_not_the_run(
        tmp_path, monkeypatch):
    """The bar's redraw to a full standard error (ENOSPC) ended the run with an OSError: exit 1, no
    file (a review's find); a momentarily full non-blocking one (EAGAIN) drops that redraw only."""
    import errno

    from vampc import progress
    class Failing:
        def __init__(self, error):
            self.error, self.tries = error, 0
        def write(self, text):
            self.tries += 1
            raise OSError(self.error, os.strerror(self.error))
        def flush(self):
            raise OSError(self.error, os.strerror(self.error))
        def fileno(self):
            raise OSError(errno.EBADF, "no descriptor")
    full = progress._Stderr(Failing(errno.ENOSPC))
    assert full.write("bar") == 3
    full.flush()
    assert full._gone and full.write("more") == 4 and full._stream.tries == 1
    class Busy(Failing):
        def write(self, text):
            self.tries += 1
            raise BlockingIOError(errno.EAGAIN, "would block")
        def flush(self):
            raise BlockingIOError(errno.EAGAIN, "would block")
    busy = progress._Stderr(Busy(errno.EAGAIN))
    assert busy.write("bar") == 3 and busy.write("bar") == 3
    busy.flush()
    assert not busy._gone and busy._stream.tries == 2


def test_no_usable_cache_or_temporary_folder_means_numpy_not_a_traceback(tmp_path, monkeypatch):
    import tempfile

    from vampc.emulator import native
    def no_temporary_folder():
        raise FileNotFoundError(2, "No usable temporary directory found")
    monkeypatch.setattr(tempfile, "gettempdir", no_temporary_folder)
    blocked = tmp_path / "not-a-folder"
    blocked.write_text("")
    monkeypatch.setenv("XDG_CACHE_HOME", str(blocked))
    try:
        native.cache_dir()
    except native.NativeError as exc:
        assert "no writable cache folder" in str(exc)
    else:
        raise AssertionError("a cache folder was found under a file")
