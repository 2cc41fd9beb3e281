"""Where vampc writes its output files, and the rules that keep the user's files safe (README
"Output files").

1. An output that is one of the command's inputs (the same file, also through a symlink or a hard
   link), or two outputs that are the same file, are refused before any work is done.
2. The folder of every output must exist and take a new file; that too is checked (by creating and
   removing a probe file) before any work is done, so an unwritable location fails in a second, not
   after a long emulation.
3. A regular file (or a path that does not exist yet) is written to a temporary file in the same
   folder and renamed over the target once complete: a failed run — an error, a full disk, an
   interrupt — leaves the previous file as it was and no partial file behind. The new file keeps the
   old file's permission bits (a new one gets the umask's).
4. A symlink is written through: the file it points to is replaced as in 3, the link stays a link.
5. An existing path that is not a regular file is never replaced: a character device (/dev/null) or
   a FIFO is written as a stream; a directory, socket or block device is refused.
6. `-` is standard output, where a command allows it.

Every failure is one `VampcError` line naming the file (disk full included).
"""
from __future__ import annotations

import contextlib
import errno
import io
import os
import stat
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Iterator

from vampc.errors import VampcError, VampcUsageError, committing, raise_if_terminated

STDOUT = "-"
STDIN = "-"          # (an input given as -: standard input)


@dataclass(frozen=True)
class PlannedOutput:
    """A planned output: `kind` is "file" (atomic replace of `target`), "stream" (an existing device
    or FIFO, written in place) or "stdout"."""

    option: str          # the command-line option that named it, e.g. "-o"
    path: str            # as the user gave it
    kind: str
    target: Path | None  # the file actually written (symlinks resolved); None for stdout

    @property
    def is_stdout(self) -> bool:
        """True when this output goes to standard output."""
        return self.kind == "stdout"


def named_file(path):
    """An input path of an option that reads files only (`--limits -` reads the file named -), as
    plan_outputs takes it: not standard input."""
    return os.path.join(os.curdir, path) if path is not None and str(path) == STDIN else path


def plan_outputs(inputs, outputs: dict, stdout_ok: tuple[str, ...] = (),
                 writes: dict | None = None, labels: dict | None = None) -> dict[str, PlannedOutput]:
    """Check every output against the rules above and return them by option name. `inputs` are the
    command's input paths (None entries ignored), `outputs` maps an option name to its path or None,
    `stdout_ok` names the options that may be `-`, `writes` what an option of this command writes
    where WRITES does not say (its kind and names, as WRITES holds them; `vampc rtl -o`: Verilog),
    `labels` how an output the user did not give is called ('the default results file')."""
    labels = labels or {}
    inputs, stdin = stdout_apart(inputs)
    planned: dict[str, PlannedOutput] = {}
    for option, path in outputs.items():
        if path is None:
            continue
        try:
            out = _plan(option, str(path), stdout_ok)
        except VampcError as exc:
            if option not in labels or isinstance(exc, VampcUsageError):
                raise
            # (a default name in a folder it cannot write: say how to put it elsewhere: a new
            # user's, of `vampc faults` in a read-only folder)
            raise VampcError(f"{exc} ({labels[option]}: give {option} FILE to write it "
                             "elsewhere)") from None
        _refuse_input(out, inputs, labels.get(option))
        if stdin is not None and out.target is not None and out.target.exists() and \
                _same_stat(stdin, out.target):
            raise VampcError(f"{out.path}: {option} is the file standard input reads (an input "
                             "given as -); vampc never writes over its inputs")
        for other in planned.values():
            if out.kind == other.kind == "stdout":
                # (a usage error, exit 2, as lookahead's options say it: it was exit 1 here)
                raise VampcUsageError(f"{other.option} {other.path} and {option} {out.path}: only "
                                      "one can be standard output")
            if _same(out, other):
                raise VampcError(f"{path}: {labels.get(option, option)} and "
                                 f"{labels.get(other.option, other.option)} name the same file")
        planned[option] = out
    kinds = {**WRITES, **(writes or {})}
    for option, out in planned.items():          # a robot file or program the output would replace
        if out.kind == "file":
            _refuse_users_work(option, str(outputs[option]), out.target, kinds.get(option))
    for option, out in planned.items():          # accepted: say when the name misleads
        if out.kind == "file":                   # (a device or standard output has no suffix to mind)
            _warn_suffix(option, str(outputs[option]), kinds)
    return planned


def _plan(option: str, path: str, stdout_ok) -> PlannedOutput:
    if path == STDOUT:
        if option not in stdout_ok:
            raise VampcUsageError(f"{option} -: standard output is not available for this output")
        need_stdout(f"{option} -")
        return PlannedOutput(option, path, "stdout", None)
    if names_descriptor(path, (0,)):
        # (through /proc/self/fd/0 it is the file the shell redirected into the command: `-o
        # /dev/stdin < keep.csv` replaced keep.csv with the torques, exit status 0)
        raise VampcUsageError(f"{option} {path}: that is standard input, which vampc never writes "
                              f"to; give a file name for {option}")
    target = Path(os.path.realpath(path))
    try:
        # through any symlink: /dev/stdout resolves to /proc/PID/fd/pipe:[N], a name, not a path
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        mode = None
    except OSError as exc:
        raise VampcError(f"{path}: cannot write: {exc.strerror}") from None
    if mode is not None and _is_stdout(path):
        # /dev/stdout, /proc/self/fd/1: standard output's own file, whatever it is (a pipe, or a
        # file it is appended to, which a rename would replace)
        if option in stdout_ok:
            return PlannedOutput(option, path, "stdout", None)
        if not stat.S_ISCHR(mode):      # (a terminal, /dev/null: a stream, as any device)
            raise VampcUsageError(f"{option} {path}: that is standard output, which carries the "
                                  "command's own text; standard output is not available for "
                                  "this output")
    if mode is not None and not stat.S_ISCHR(mode) and _same_file(path, sys.stderr):
        # (/dev/stderr, /proc/self/fd/2 with 2>>log.txt: the rename replaced the log with the
        # output, exit 0, and later messages went to the deleted file: a file-safety audit; and
        # with 2>&1 >/dev/null | cat, a pipe, the warnings went into the torque CSV: a new user's
        # find. A terminal is a stream, as for standard output)
        raise VampcUsageError(f"{option} {path}: that is standard error, which carries the "
                              "command's messages; give another file")
    if mode is None and path.endswith(("/", os.sep)):
        # (a new file under it would be made by the name without the slash, in another format
        # than the name says: 'x.gz/' wrote plain text to x.gz)
        raise VampcError(f"{path}: ends in '/', as a folder's name does; give a file name for "
                         f"{option}")
    if mode is not None and not stat.S_ISREG(mode):
        if stat.S_ISCHR(mode) or stat.S_ISFIFO(mode):
            if not os.access(path, os.W_OK):
                raise VampcError(f"{path}: cannot write: permission denied")
            return PlannedOutput(option, path, "stream", Path(path))
        what = "a folder" if stat.S_ISDIR(mode) else "not a regular file"
        raise VampcError(f"{path}: is {what}; give a file name for {option}")
    if mode is not None and (not mode & stat.S_IWUSR or not os.access(target, os.W_OK)):
        # the owner's write bit, too: root may write anything, but a file made read-only is kept
        if mode & stat.S_IWUSR and _read_only_mount(target):   # (said of the file: a new user's)
            raise VampcError(f"{path}: is on a read-only file system; vampc cannot replace it")
        raise VampcError(f"{path}: exists and is read-only; vampc does not replace it")
    if mode is None:
        # the folder as the kernel finds it: realpath drops 'nosuchdir/..' as text, and the output
        # went to the folder above a folder that does not exist (a tester's find; an open() of
        # the path fails there)
        given = os.path.dirname(path) or "."
        if not os.path.isdir(given):
            raise VampcError(f"{path}: folder {given} does not exist")
    _probe_folder(path, target.parent)
    return PlannedOutput(option, path, "file", target)


_RESULT_ON_STDOUT = False


def command_begins() -> None:
    """A command starts: nothing of its result goes to standard output yet (see need_stdout)."""
    global _RESULT_ON_STDOUT
    _RESULT_ON_STDOUT = False


def result_on_stdout() -> bool:
    """Whether this command's result goes to standard output (need_stdout was asked): then a reader
    that goes away loses it; otherwise standard output has only the lines beside its files."""
    return _RESULT_ON_STDOUT


def need_stdout(what: str) -> None:
    """VampcError when standard output is closed (Python starts with sys.stdout None when its file
    descriptor 1 is: `vampc report ... >&-`) and `what`, the command's result, would go there: said
    before any work, instead of a result dropped with exit status 0. The lines a command prints
    beside its files (a compile's summary) are not its result, and are dropped then."""
    global _RESULT_ON_STDOUT
    _RESULT_ON_STDOUT = True
    if sys.stdout is None:
        raise VampcError(f"{what}: standard output is closed, so the result has nowhere to go "
                         "(redirect it to a file, or to /dev/null to drop it)")


def names_descriptor(path: str, fds=(0, 1, 2)) -> bool:
    """Whether `path` names one of the standard streams `fds` (0: standard input): /dev/stdin,
    /dev/fd/0, /proc/self/fd/0 (or this process's number for self), or a symlink to one of them;
    not a file of the user's."""
    std = {0: "stdin", 1: "stdout", 2: "stderr"}
    aliases = {alias for fd in fds for alias in (
        os.path.join(os.sep, "dev", std[fd]), os.path.join(os.sep, "proc", "self", "fd", str(fd)),
        os.path.join(os.sep, "proc", str(os.getpid()), "fd", str(fd)))}
    here = os.path.abspath(path)
    for _ in range(40):                  # (a loop of links ends the walk: the kernel's limit)
        name = os.path.join(os.path.realpath(os.path.dirname(here)), os.path.basename(here))
        if here in aliases or name in aliases:
            return True
        if not os.path.islink(name):
            return False
        here = os.path.normpath(os.path.join(os.path.dirname(name), os.readlink(name)))
    return False


def _is_stdout(path: str) -> bool:
    """Whether `path` is the file standard output writes to: then it is written as `-` is, and
    the command's own lines go to stderr instead of into the data."""
    return _same_file(path, sys.stdout)


def _same_file(path: str, stream) -> bool:
    """Whether `path` is the file `stream` (sys.stdout, sys.stderr) writes to."""
    try:
        here = os.stat(path)
    except OSError:
        return False
    return _same_stat(here, stream)


def _probe_folder(path: str, folder: Path) -> None:
    """Create and remove a temporary file where the output will go (os.access is no proof: root, a
    read-only file system, a full inode table)."""
    if not folder.is_dir():
        raise VampcError(f"{path}: folder {folder} does not exist")
    try:
        fd, tmp = _new_temporary(folder / "vampc-probe")
    except OSError as exc:
        raise VampcError(f"{path}: cannot write in folder {folder}: {exc.strerror}") from None
    os.close(fd)
    os.unlink(tmp)
    _TEMPORARIES.discard(tmp)


def _regular_file(stream) -> os.stat_result | None:
    """The status of the regular file a standard stream reads or writes (`< in.csv`, `>> in.csv`),
    or None (a pipe, a terminal, closed)."""
    try:
        here = os.fstat(stream.fileno())
    except (OSError, ValueError, AttributeError):
        return None
    return here if stat.S_ISREG(here.st_mode) else None


def _same_stat(here: os.stat_result, other) -> bool:
    """Whether `other` (a path, or a stream with a file descriptor) is the file of `here`."""
    if other is None:                    # (standard output closed: Python's sys.stdout is None)
        return False
    try:
        there = os.fstat(other.fileno()) if hasattr(other, "fileno") else os.stat(other)
    except (OSError, ValueError, AttributeError):
        return False
    return (here.st_dev, here.st_ino) == (there.st_dev, there.st_ino)


def _files_read_with(inputs: list[Path]) -> list[Path]:
    """The files an input reads in turn: an MJCF model's includes and assets (vampc.robot.mjcf)."""
    xml = [p for p in inputs if p.suffix.lower() == ".xml"]
    if not xml:
        return []
    from vampc.robot.mjcf import files_read
    return [f for p in xml for f in files_read(p)]


def _read_only_mount(path) -> bool:
    """Whether `path` is on a file system mounted read-only."""
    try:
        return bool(os.statvfs(path).f_flag & os.ST_RDONLY)
    except (OSError, AttributeError):        # (no statvfs: not POSIX)
        return False


def _refuse_input(out: PlannedOutput, inputs: list[Path], label: str | None = None) -> None:
    """VampcError when the output is one of the inputs (`label`: how an output the user did not
    name is called: 'the default program file', not '-o', which the user never gave)."""
    if out.target is None or not out.target.exists():
        return
    for src in inputs:
        try:
            same = os.path.samefile(out.target, src)
        except OSError:
            same = False
        if same:
            link = (" (through a symlink)" if os.path.islink(out.path) else
                    "" if out.target == Path(os.path.realpath(src)) else " (a hard link to it)")
            raise VampcError(f"{out.path}: {label or out.option} is the input file {src}{link}; "
                             "vampc never writes over its inputs"
                             + (f" (give {out.option} FILE to write it elsewhere)" if label else ""))


def stdout_apart(inputs) -> tuple[list[Path], os.stat_result | None]:
    """VampcError when standard output is one of the command's input files (None entries ignored;
    the files they read with them too) or the file standard input reads; every command checks it
    before it writes a byte there (plan_outputs; `compile --dump-after`, which plans no output file,
    had appended its dump to its own robot file, exit 0: a new user's find). The inputs given as
    paths, and the file standard input reads where an input is - (an output must not replace it)."""
    # (an input given as - is standard input; a file so named, given to an option that reads
    # files only, comes as ./-: `named_file`)
    reads_stdin = any(p is not None and str(p) == STDIN for p in inputs)
    inputs = [Path(p) for p in inputs if p is not None and str(p) != STDIN]
    inputs += _files_read_with(inputs)
    stdin = _regular_file(sys.stdin) if reads_stdin else None
    _refuse_stderr_input(inputs, stdin)
    _refuse_stdout_input(inputs)
    if stdin is not None and _same_stat(stdin, sys.stdout):
        raise VampcError("standard output is the file standard input reads (an input given as -, "
                         "redirected onto it); vampc never writes over its inputs: send standard "
                         "output elsewhere" + _emptied(stdin))
    return inputs, stdin


# the file options that name outputs (any other file option, and a command's source, is an input)
OUTPUT_OPTIONS = frozenset(("-o", "--output", "--vcd", "--save-states", "--timing", "--network",
                            "--reservation", "--dot", "--bus-chart", "--html", "--curve",
                            "--torques", "--plot"))


def stderr_apart(given: list[tuple[str, str]]) -> None:
    """Exit before anything is said when standard error is redirected onto a file a command line
    gives, as (option, name) pairs (option "" for its source; vampc.cli finds them before parsing):
    `vampc emulate p.vamp.json --word float32 2>> p.vamp.json` appended its warning to the program
    file and ran on, exit 0; a usage error, or `-o p.json 2>> p.json`'s own refusal, was written
    into the file (new users' and a review's finds). Exit 1 for an input, 2 for an output (in
    OUTPUT_OPTIONS), as their other refusals; the refusal said where _elsewhere says."""
    there = _regular_file(sys.stderr)        # (None: a terminal, a pipe, a test's capture)
    if there is None:
        return
    for option, name in given:
        if not name or name == STDIN or names_descriptor(name) or \
                not _same_file(name, sys.stderr):
            continue             # (-o /dev/stderr: the output's own refusal, exit 2)
        output = option in OUTPUT_OPTIONS
        what = (f"{option} {name}: standard error is this output file" if output else
                f"{name}: standard error is this input file")
        with contextlib.suppress(OSError, ValueError):
            print(f"vampc: error: {what} (redirected onto it); " + (
                "the command's messages would spoil it: send standard error elsewhere, or give "
                "another file" if output else "vampc never writes over its inputs: send standard "
                f"error elsewhere{_emptied(there)}"), file=_elsewhere(there, [n for _, n in given]),
                flush=True)
        sys.exit(2 if output else 1)


def _elsewhere(there: os.stat_result, files):
    """Where a refusal of standard error onto one of `files` (paths, or a stream with a file
    descriptor) goes: standard output, or nowhere when that is standard error's file or one of
    `files` too."""
    out = _regular_file(sys.stdout)
    spoiled = out is not None and ((out.st_dev, out.st_ino) == (there.st_dev, there.st_ino) or
                                   any(_same_stat(out, f) for f in files))
    return open(os.devnull, "w") if spoiled else sys.stdout  # noqa: SIM115


def _refuse_stderr_input(inputs: list[Path], stdin: os.stat_result | None) -> None:
    """VampcError when standard error is one of the input files, the files they read (an MJCF's
    includes) or the file standard input reads for an input given as - (the command line's own
    are refused before it is parsed: stderr_apart): said where _elsewhere says."""
    there = _regular_file(sys.stderr)        # (None: a terminal, a pipe, a test's capture)
    if there is None:
        return
    said = [src for src in inputs if _same_stat(there, src)]
    if stdin is not None and (stdin.st_dev, stdin.st_ino) == (there.st_dev, there.st_ino):
        said.append("the file standard input reads (an input given as -)")
    if not said:
        return
    sys.stderr = _elsewhere(there, inputs + ([sys.stdin] if stdin is not None else []))
    raise VampcError(f"{said[0]}: standard error is this input file (redirected onto it); vampc "
                     "never writes over its inputs: send standard error elsewhere" + _emptied(there))


def _refuse_stdout_input(inputs: list[Path]) -> None:
    """VampcError when standard output is one of the input files (`vampc emulate p.vamp.json
    --trajectory in.csv >> in.csv` appended the torques to the trajectory): every command prints
    to standard output, its result or its summary."""
    there = _regular_file(sys.stdout)        # (None: closed, a pipe, a test's capture)
    if there is None:
        return
    for src in inputs:
        if _same_stat(there, src):
            raise VampcError(f"{src}: standard output is this input file (redirected onto it); "
                             "vampc never writes over its inputs: send standard output elsewhere"
                             + _emptied(there))


def _emptied(here: os.stat_result) -> str:
    """What to add to the refusal of standard output onto an input when that input is empty now:
    `vampc precision a.urdf > a.urdf` had its input emptied by the shell before vampc started, and
    "never writes over its inputs" read as if the file were safe."""
    return (" (the file is empty now: the shell empties a file it redirects to with > before "
            "vampc starts)") if here.st_size == 0 else ""


def _same(a: PlannedOutput, b: PlannedOutput) -> bool:
    """Whether two outputs would write one file (or both standard output). A character device
    (/dev/null) takes each write as it comes, so two outputs may share one."""
    if a.is_stdout or b.is_stdout:
        return a.is_stdout and b.is_stdout
    if a.kind == b.kind == "stream" and _character_device(a.target):
        return False
    if a.target == b.target:
        return True
    try:
        return os.path.samefile(a.target, b.target)
    except OSError:
        return False


def _character_device(path: Path) -> bool:
    import stat
    try:
        return stat.S_ISCHR(os.stat(path).st_mode)
    except OSError:
        return False


# Every temporary file an output is being written to, until it is renamed into place or removed:
# what an interrupted command removes on its way out (discard_all), wherever the signal landed. A
# name goes in before its file is made and leaves after the file is renamed or removed, so no
# file exists that the registry does not name. (Holding the signals around those steps is not
# enough: with worker threads running, the kernel hands a signal to a thread that does not hold
# it, and Python then runs the handler in the main thread, inside the held block.)
_TEMPORARIES: set[str] = set()


def _new_temporary(target: Path) -> tuple[int, str]:
    """Create a new temporary file beside `target` (mode 0o600) with the name in the registry
    first; (its descriptor, its name)."""
    # (a name of 234 to 255 bytes made a temporary past the file system's 255, and the output
    # failed after all the work: a file-safety audit) the target's name cut to what the folder's
    # own name limit leaves beside '.', 16 hex digits and '.tmp' (eCryptfs allows 143 bytes)
    try:
        room = os.pathconf(target.parent, "PC_NAME_MAX") - 22
    except (OSError, ValueError):
        room = 255 - 22
    # (its bytes, cut, and back as the file system's name: decoded as UTF-8 it could not be
    # encoded again under a non-UTF-8 locale, a traceback for `-o "tau ü.csv"`: a CI user's find)
    # (a character cut in two is dropped: a name of whole characters, which a file system that
    # holds only UTF-8 names takes)
    stem = os.fsencode(target.name)[:max(1, room)].decode(sys.getfilesystemencoding(), "ignore")
    for _ in range(100):
        name = str(target.parent / f".{stem}.{os.urandom(8).hex()}.tmp")
        _TEMPORARIES.add(name)
        try:
            return os.open(name, os.O_RDWR | os.O_CREAT | os.O_EXCL | getattr(os, "O_BINARY", 0), 0o600), name
        except FileExistsError:
            _TEMPORARIES.discard(name)            # somebody else's: never removed by discard_all
    raise FileExistsError(errno.EEXIST, "no free temporary name", str(target.parent))


def discard_all() -> None:
    """Remove every temporary output file still open (an interrupted or terminated command)."""
    for tmp in list(_TEMPORARIES):
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        _TEMPORARIES.discard(tmp)


def silence(stream) -> None:
    """Point `stream`'s file descriptor at /dev/null: nothing more reaches it, at exit either (a
    standard error whose reader is gone, or that is full or read-only, loses its lines, not the
    run). A stream without a descriptor of its own is left as it is."""
    with contextlib.suppress(OSError, ValueError, AttributeError, io.UnsupportedOperation):
        os.dup2(os.open(os.devnull, os.O_WRONLY), stream.fileno())


def unencodable(exc: UnicodeEncodeError) -> VampcError:
    """The one line for a result standard output's encoding cannot hold."""
    return VampcError(f"cannot write to standard output: its encoding ({exc.encoding}) cannot hold "
                      f"{exc.object[exc.start]!r}; use a UTF-8 locale or PYTHONIOENCODING=utf-8")


class _Whole:
    """A binary file (the output's) whose write() takes all it is given or raises the OSError that
    stopped it. A buffered file's write() may take part of a long piece and return how much, with no
    error (a file-size limit or a full disk reached mid-piece; the next write raises), and text files
    drop that count: 251 594 bytes of torques sent to standard output under a file-size limit left
    102 400 and exit status 0 (a new user's find). Text (`binary` False) is encoded here: in UTF-8
    for a file (as the program file and JSON are: a torque CSV's header had been written in the
    locale's encoding, other bytes under Latin-1 and a traceback for a name it cannot hold, and the
    pictures an internal error: a CI user's find), in standard output's own encoding for it;
    anything else of the file (seek, flush, close) is its own."""

    def __init__(self, file, binary: bool, encoding: str | None = None, errors: str | None = None,
                 result: bool = False):
        self._file = file
        self._encoding = None if binary else (encoding or "utf-8")
        self._errors = errors or "strict"
        self._result = result       # an output (standard output's): a character it cannot hold is
        # a one-line error; else (say's lines) the UnicodeEncodeError, for the caller to escape

    def write(self, data) -> int:
        if isinstance(data, str):
            if self._encoding is None:
                raise TypeError("a binary output takes bytes, not str")
            given = len(data)
            if os.linesep != "\n":
                data = data.replace("\n", os.linesep)
            try:
                data = data.encode(self._encoding, self._errors)
            except UnicodeEncodeError as exc:     # (only standard output's can be other than UTF-8:
                # a joint named beyond ASCII to `-o -` under the C locale was an internal error)
                if not self._result:
                    raise
                raise unencodable(exc) from None
        else:
            given = None
        view = memoryview(data).cast("B")
        total = len(view)
        while view:
            n = self._file.write(view)
            if n is None:                    # (a non-blocking stream that would block)
                raise BlockingIOError(errno.EAGAIN, "the output would block")
            if n <= 0:
                raise OSError(errno.EIO, "the output took nothing")
            view = view[n:]
        return total if given is None else given

    def __getattr__(self, name):
        return getattr(self._file, name)


class WholeText:
    """A standard text stream (vampc.cli.say's: a command's text) whose write() puts all it is
    given or raises the OSError that stopped it, as `_Whole` does for the outputs. A text stream
    drops the count its file's write() returns, and with Python unbuffered (`python -u`,
    PYTHONUNBUFFERED) that file is the raw one, which takes part of a long piece when a file-size
    limit or a full disk is reached or the reader goes away mid-way: a 700 kB report cut at the
    limit with exit status 0 and nothing said (a tester's find). The text goes to the bytes
    beneath, encoded as the stream would (what the stream holds goes first); a stream without
    bytes beneath (a StringIO, Jupyter's) takes it as it does."""

    def __init__(self, stream):
        self._stream = stream
        buffer = getattr(stream, "buffer", None)
        self._whole = None if buffer is None else _Whole(
            buffer, False, getattr(stream, "encoding", None), getattr(stream, "errors", None))

    def write(self, text: str) -> int:
        if self._whole is None:
            return self._stream.write(text)
        self._stream.flush()
        return self._whole.write(text)

    def flush(self) -> None:
        self._stream.flush()
        if self._whole is not None:
            self._whole.flush()

    def __getattr__(self, name):
        return getattr(self._stream, name)


class Pending:
    """An output being written: `fh` takes the content; `commit()` puts it in place, `discard()`
    drops it (a regular file's previous content stays). Used by `writing`."""

    def __init__(self, out: PlannedOutput, what: str, binary: bool):
        self.out, self.what, self.tmp = out, what, None
        raise_if_terminated()              # an interrupt swallowed on the way: nothing begun
        try:
            if out.kind == "stdout":
                sys.stdout.flush()                  # (what was printed before goes first)
                buffer = getattr(sys.stdout, "buffer", None)
                # (a standard output without bytes underneath, Jupyter's, say: text as it takes it,
                # bytes refused in one line; a TypeError had ended the command)
                if buffer is None and binary:
                    raise VampcError(f"{out.path}: standard output here takes text, not the "
                                     f"{what} (bytes): write it to a file")
                self.fh = sys.stdout if buffer is None else \
                    _Whole(buffer, binary, getattr(sys.stdout, "encoding", None),
                           getattr(sys.stdout, "errors", None), result=True)
            elif out.kind == "stream":
                self.fh = _Whole(open(out.target, "wb"), binary)   # noqa: SIM115 - closed in commit/discard
            else:
                fd, self.tmp = _new_temporary(out.target)
                self.fh = _Whole(os.fdopen(fd, "wb"), binary)
        except OSError as exc:
            raise self.error(exc) from None

    def error(self, exc: OSError) -> VampcError:
        """The one-line message for a failed write."""
        reason = exc.strerror or str(exc)
        kept = " (the previous file is unchanged)" if self.out.kind == "file" and \
            self.out.target.exists() else ""
        return VampcError(f"{self.out.path}: cannot write {self.what}: {reason}{kept}")

    def prepare(self) -> None:
        """Everything written out (a stream flushed; a new file's temporary closed, as far as the
        disk takes it) but nothing put in place: an output that fails here has replaced nothing,
        and neither have the others made with it (commit each once all are prepared: an -o onto a
        full device had failed after --save-states was put in place; a new user's find)."""
        try:
            if self.out.kind == "file":
                self.fh.close()
            else:
                self.fh.flush()
        except OSError as exc:
            self.discard()
            raise self.error(exc) from None

    def commit(self) -> None:
        """Flush and put the content in place (rename over the target for a regular file)."""
        try:
            if self.out.kind == "stdout":
                self.fh.flush()
                return
            self.fh.close()
            raise_if_terminated()          # an interrupt swallowed on the way: not put in place
            if self.tmp is not None:
                committing()               # from here a signal lets the command finish
                _like_the_old(self.tmp, self.out)
                os.replace(self.tmp, self.out.target)
                _TEMPORARIES.discard(self.tmp)    # after the rename: a signal between the two finds no file
                self.tmp = None
        except OSError as exc:
            self.discard()
            raise self.error(exc) from None

    def discard(self) -> None:
        """Drop what was written (a stream keeps what it already took)."""
        if self.out.kind != "stdout":
            with contextlib.suppress(OSError):
                self.fh.close()
        if self.tmp is not None:
            Path(self.tmp).unlink(missing_ok=True)
            _TEMPORARIES.discard(self.tmp)
            self.tmp = None


@contextlib.contextmanager
def placing(pending) -> Iterator[None]:
    """Hold an exclusive lock on the folder of each file output of `pending` while they are put in
    place, so that two runs writing the same files put theirs in place one after the other: the
    files on disk are one run's set (two runs writing -o and --save-states at once had left the
    torques of one beside the states of another: an audit's find). Where folders cannot be locked
    (no fcntl, a file system without locks) the outputs are put in place without."""
    try:
        import fcntl
    except ImportError:                 # (not POSIX)
        yield
        return
    folders = sorted({str(p.out.target.parent) for p in pending
                      if p.out.kind == "file" and p.tmp is not None})
    held = []
    try:
        for folder in folders:
            try:
                fd = os.open(folder, os.O_RDONLY)
            except OSError:
                continue
            try:
                fcntl.flock(fd, fcntl.LOCK_EX)
            except OSError:
                os.close(fd)
                continue
            held.append(fd)
        yield
    finally:
        for fd in held:
            with contextlib.suppress(OSError):
                fcntl.flock(fd, fcntl.LOCK_UN)
            os.close(fd)


def _like_the_old(tmp: str, out: PlannedOutput) -> None:
    """Before `tmp` replaces `out.target`, from one look at the old file: its permission bits (a new
    file's, by the umask, where there is none), its owner and group where the user may give them
    (root may; others only a group of theirs; said where not), and a warning where it has other
    hard links, which keep the old content (root replacing a file of another user's had made it
    root's, unsaid, and a hard link had been split without a word: an audit's find)."""
    try:
        old = os.stat(out.target)
    except FileNotFoundError:
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        return
    import warnings

    from vampc.errors import VampcWarning
    mine = os.stat(tmp)
    if (old.st_uid, old.st_gid) != (mine.st_uid, mine.st_gid):
        try:
            os.chown(tmp, old.st_uid if os.geteuid() == 0 else -1, old.st_gid)
        except OSError:
            pass
        now = os.stat(tmp)
        if (now.st_uid, now.st_gid) != (old.st_uid, old.st_gid):     # (said: a review's find)
            warnings.warn(VampcWarning(f"{out.option} {out.path}: the new file's owner and group "
                                       f"are {now.st_uid}:{now.st_gid}, not the old file's "
                                       f"{old.st_uid}:{old.st_gid}, which this user cannot give"),
                          stacklevel=2)
    os.chmod(tmp, stat.S_IMODE(old.st_mode))        # (after chown, which may clear set-id bits)
    if old.st_nlink > 1:
        warnings.warn(VampcWarning(f"{out.option} {out.path}: the file has {old.st_nlink - 1} other "
                                   "hard link(s), which keep the old content: the new file replaces "
                                   "this name only"),
                      stacklevel=2)


@contextlib.contextmanager
def writing(out: PlannedOutput, what: str, binary: bool = False) -> Iterator[IO]:
    """Write `out` through a file handle; committed if the block completes, discarded if it raises.
    An OSError inside the block (a full disk) becomes the one-line VampcError."""
    pending = Pending(out, what, binary)
    try:
        yield pending.fh
    except OSError as exc:
        pending.discard()
        raise pending.error(exc) from None
    except BaseException:
        pending.discard()
        raise
    pending.commit()


def write_output(out: PlannedOutput, content: str | bytes, what: str) -> None:
    """Write the whole of `content` to `out` by the rules above."""
    with writing(out, what, binary=isinstance(content, bytes)) as fh:
        fh.write(content)


def write_together(items, between=None) -> None:
    """Write each (out, content, what) of `items`, each by the rules above, and put none in place
    unless all were written: a failure or an interrupt while they are made leaves every existing
    file as it was. `between()`, where given, runs once they are written and before any is put in
    place (a command's text on standard output: neither a text nor a file that cannot be written
    leaves the other, a report's picture on a full device had failed after the whole text was
    printed, a new user's find); if it raises, none is put in place."""
    pending = _prepare_together(items)
    if between is not None:
        try:
            between()
        except BaseException:
            _discard_together(pending)
            raise
    _commit_together(pending)


def _prepare_together(items) -> list[Pending]:
    """Each (out, content, what) of `items` written out and prepared (Pending.prepare), none put in
    place. A failure here drops every one."""
    pending: list[Pending] = []
    try:
        for out, content, what in items:
            pending.append(Pending(out, what, isinstance(content, bytes)))
            pending[-1].fh.write(content)
        for p in pending:
            p.prepare()
    except VampcError:
        _discard_together(pending)
        raise
    except OSError as exc:
        _discard_together(pending)
        raise pending[-1].error(exc) from None
    except BaseException:
        _discard_together(pending)
        raise
    return pending


def _discard_together(pending: list[Pending]) -> None:
    for p in pending:
        p.discard()


def _commit_together(pending: list[Pending]) -> None:
    """Put every prepared output in place (_prepare_together)."""
    with placing(pending):
        for k, p in enumerate(pending):
            try:
                p.commit()
            except BaseException:     # (one that cannot be put in place: drop the others' temporaries)
                for rest in pending[k + 1:]:
                    rest.discard()
                raise


def output_for(path, option: str = "-o", inputs=()) -> PlannedOutput:
    """Plan one output (library callers that write a single file)."""
    return plan_outputs(inputs, {option: path})[option]


# what each picture option writes, and the names that say so
PICTURE = ("SVG", (".svg", ".png", ".pdf"))     # (PNG, PDF by those names: vampc.report.svg)
WRITES = {"--timing": PICTURE, "--network": PICTURE, "--reservation": PICTURE,
          "--bus-chart": PICTURE, "--curve": PICTURE, "--plot": PICTURE,
          "--html": ("HTML", (".html", ".htm")), "--dot": ("Graphviz DOT", (".dot", ".gv"))}


# names that say a format: a table (CSV) or text going to one of them is warned of (t.json gets
# CSV), to a name of none (.txt, .dat, no suffix), as tables often have, is not
OTHER_FORMATS = (".json", ".jsonl", ".yaml", ".yml", ".xml", ".urdf", ".html", ".htm", ".svg",
                 ".png", ".jpg", ".jpeg", ".pdf", ".dot", ".gv", ".vcd", ".v", ".sv", ".npy", ".npz",
                 ".csv", ".tsv", ".tab", ".xlsx", ".xls", ".ods", ".parquet", ".feather", ".h5",
                 ".hdf5", ".mat")
CSV_TABLE = ("CSV", (".csv",), OTHER_FORMATS)


def _refuse_users_work(option: str, path: str, target: Path | None, kind) -> None:
    """Refuse an output over an existing robot description (vampc writes none) or program file (but
    by `compile -o`, which writes one): the user's work. `report --timing arm.yaml` had replaced the
    DH table with SVG and `emulate -o arm.yaml` with torques, each with a warning of the name
    alone, and `compile -o dh.json` a DH table in JSON with none (a new user's slip, found by a
    trial; a review's). A program file is replaced by an output of no kind said (a library
    caller's, vampc.program.file.write_program). By content, not by name: a text, DOT or Verilog
    file an earlier run wrote under a misnamed name is replaced, as warned."""
    from vampc.sniff import DESCRIPTIONS, robot_or_program
    held = robot_or_program(target) if target is not None and target.exists() else None
    if held is None or held == DESCRIPTIONS["program"] and (kind is None or kind[0] == "a program file"):
        return       # (an output of no kind said, a library caller's: write_program, say)
    writes = f"writes {kind[0]}" if kind is not None else "writes another kind of file"
    name = f" (name it {kind[1][0]})" if kind is not None else ""
    raise VampcError(f"{path}: is {held}; {option} {writes}, and vampc does not replace it: give "
                     f"another file name{name}")


def _warn_suffix(option: str, path: str, writes: dict) -> None:
    """A one-line warning when an output goes to a name that says otherwise (x.png gets SVG). An
    entry of `writes` with a third item, the names of other formats, is warned of only for those
    (CSV_TABLE: a table named .txt or .dat is not misnamed)."""
    import warnings

    from vampc.errors import VampcWarning
    kind = writes.get(option)
    name = path.lower()
    if kind and path.strip() not in ("", "-") and not name.endswith(kind[1]) and \
            (len(kind) < 3 or name.endswith(kind[2])):
        also = f", or {' or '.join(kind[1][1:])} for that format" if kind is PICTURE else ""
        warnings.warn(VampcWarning(f"{option} {path}: writes {kind[0]}, whatever the name says "
                                   f"(name it {kind[1][0]}{also})"))
