"""Trajectory files in and torque files out.

CSV: a header `q1..qn,qd1..qdn,qdd1..qddn`, optionally with a leading `t` column, then one state per row.
.npy: an array (count, 3n) or (count, 3n + 1) with t first. .npz: arrays `q`, `qd`, `qdd` (count, n) and
optionally `t`. Torques are written as CSV with the header `tau1..taun`, atomically.

A floating-base program also needs the base's motion per state, 9 columns after qdd (BASE_COLUMNS: ω_0,
ω̇_0 and the classical acceleration a_0 of O_0's origin, all in O_0); in .npy 9 more columns, in .npz an
array `base` (count, 9). Its torque files end with the base wrench (WRENCH_COLUMNS).
"""
from __future__ import annotations

import codecs
import contextlib
import csv
import io
import math
import re
import sys
import tokenize
import zipfile
import zlib
from pathlib import Path

import numpy as np

from vampc.errors import VampcError
from vampc.textio import NPY_MAGIC, ZIP_MAGIC, count, plain_number, shown

BASE_COLUMNS = ["base_wx", "base_wy", "base_wz", "base_dwx", "base_dwy", "base_dwz",
                "base_ax", "base_ay", "base_az"]
# Tables of at least this many cells are formatted by the native writer (smaller ones are not worth
# loading it for).
NATIVE_CELLS = 20_000
WRENCH_COLUMNS = ["base_fx", "base_fy", "base_fz", "base_nx", "base_ny", "base_nz"]


def header(n: int, floating: bool = False) -> list[str]:
    """The expected CSV column names (without t); a floating base adds BASE_COLUMNS."""
    return ([f"q{i}" for i in range(1, n + 1)] + [f"qd{i}" for i in range(1, n + 1)]
            + [f"qdd{i}" for i in range(1, n + 1)] + (BASE_COLUMNS if floating else []))


def read(path, n: int, floating: bool = False, of: int | None = None):
    """A Trajectory from a .csv, .npy or .npz file; VampcError naming the row and column on bad data.
    `floating`: the states carry the base's motion (BASE_COLUMNS) too. `of`: the robot's joints when
    the file gives only n of them (coupled mimic followers follow their leaders)."""
    from vampc.emulator.host import Trajectory
    path = Path(path)
    suffix = path.suffix.lower()
    try:
        source = None        # a pipe or FIFO: its bytes, read once (a second open waited for good)
        if str(path) != "-" and not path.is_file():
            from vampc.textio import read_whole
            source = io.BytesIO(read_whole(path, text=suffix not in (".npy", ".npz")))
        # (an array's width short of coupled followers: said why, as a CSV's header is)
        why = "" if of is None or of == n else f": {program_joints(n, of)}"
        if suffix == ".npz":
            data, t = _read_npz(path, n, floating, source, why)
        elif suffix == ".npy":
            data, t = _read_npy(path, n, header(n, floating), source, why)
        else:
            data, t = read_table(path, header(n, floating), program_joints(n, of), floating,
                                 arrays=True, source=source)
    except OSError as exc:
        raise VampcError(f"{path}: cannot read trajectory: {exc.strerror or exc}") from None
    line = None if numpy_file(path) else 2       # a CSV's states start on line 2
    if t is not None:
        t = np.asarray(t, dtype=float)
    _check_finite(path, data, header(n, floating), line, t)
    base = data[:, 3 * n:].copy() if floating else None
    return Trajectory(data[:, :n].copy(), data[:, n:2 * n].copy(), data[:, 2 * n:3 * n].copy(), t, base)


def _missing_base(path: Path, names: list[str], want: list[str]) -> None:
    """A floating-base trajectory whose header stops before (or leaves out) the base columns."""
    absent = [c for c in BASE_COLUMNS if c in want and c not in names]
    if absent and [c for c in names if c not in BASE_COLUMNS] == [c for c in want if c not in BASE_COLUMNS]:
        raise VampcError(f"{path}: header: missing column {absent[0]} (a floating-base program needs the "
                         f"base's motion: {','.join(BASE_COLUMNS)} after the qdd columns)")


def cell_number(cell: str) -> float:
    """A cell of a table the user gives as a number, as float() reads it, but for 1_0 and non-ASCII
    digits or spaces: float() reads 1_0 as 10 and '١' (Arabic-Indic) or '１' (full width) as 1,
    and in a table they are typos, not numbers (ValueError); the fast native parser takes neither."""
    if not plain_number(cell):
        raise ValueError(cell)
    return float(cell)


def program_joints(n: int, of: int | None = None) -> str:
    """'the program is for 6 joints', or for n independent joints of `of` (coupled followers)."""
    if of is None or of == n:
        return f"the program is for {count(n, 'joint')}"
    return (f"the program is for {count(of, 'joint')}, {n} independent (coupled followers follow "
            "their leaders: give the independent joints' columns)")


def _header_hint(names: list[str], columns: list[str]) -> str:
    """What a header line that is not the expected one seems to be, for its message ('' if
    nothing): its column 1 was said to be '# t' where only numpy.savetxt's '# ' was wrong, and a
    program file, a URDF, a torque file or a limits file was said to start with the wrong column
    (a new user's find)."""
    if not names:
        return ""
    head = names[0]
    if head.startswith("#"):
        fixed = [head.lstrip("#").strip(), *names[1:]]
        right = fixed in (list(columns), ["t", *columns])
        if right:
            return ("; the header line starts with '#', which is all that is wrong with it "
                    "(numpy.savetxt writes one before its header unless given comments='')")
        return ("; the first line starts with '#': no line is a comment here, the first is the "
                "header (numpy.savetxt writes '# ' before its header unless given comments='')")
    if head.startswith(("{", "[")):
        return "; the file looks like JSON (a program file?), not a CSV table"
    if head.startswith("<"):
        return "; the file looks like XML (a URDF?), not a CSV table"
    if all(_is_number(c) for c in names):
        return "; the first line is numbers: the header line is missing"
    if any(c.startswith("tau_") for c in names):
        return "; the file looks like torques (vampc emulate's output), not states"
    if head == "joint" and names[1:2] == ["tau"]:
        return "; the file looks like a limits file (joint,tau,qd)"
    # (a new user's files: columns split by ';' or tabs, a 'time' column, names in capitals)
    for sep, said in ((";", "semicolons"), ("\t", "tabs")):
        if len(names) == 1 and sep in head:
            return f"; its columns are separated by {said}: a CSV table's are by commas"
    wanted = {c.lower() for c in ("t", *columns)}
    if all(c.lower() in wanted for c in names) and any(c != c.lower() for c in names):
        return f"; write the column names in lower case ({columns[0]}, not {columns[0].upper()})"
    if head.lower() in ("time", "time_s", "t_s", "timestamp") and names[1:] in (list(columns), []):
        return "; a time column is named t"
    # named by joint: some name after q, qd and qdd alike (q_shoulder, qd_shoulder, qdd_shoulder;
    # not qdot1 or a column 'quality', which a review found told so)
    parts: dict[str, set] = {"q": set(), "qd": set(), "qdd": set()}
    kind = {"qddot": "qdd", "qdd": "qdd", "qdot": "qd", "qd": "qd", "q": "q"}   # (qdot_shoulder too)
    for m in (re.fullmatch(r"(qddot|qdd|qdot|qd|q)[_ .-]?(\w+)", c) for c in names):
        if m and not m.group(2).isdigit():
            parts[kind[m.group(1)]].add(m.group(2))
    if parts["q"] & parts["qd"] & parts["qdd"]:
        # (q_shoulder...: named by joint, where the columns are numbered; which joint is q1 went
        # unsaid: a new user's find)
        return ("; the columns are numbered, not named by joint: q1 is the first joint in joint "
                "order (depth-first for a tree), the order of the torque file's tau_<joint> columns "
                "and of `vampc report --format json`'s joint_names")
    return ""


def _is_number(cell: str) -> bool:
    try:
        float(cell)
    except ValueError:
        return False
    return bool(cell.strip())


def read_table(path: Path, columns: list[str], why: str, floating: bool = False,
               what: str = "trajectory", arrays: bool = False, source=None):
    """(data, t) of a CSV table whose header is `columns`, with an optional leading t (`why`: what
    the columns follow from, for the header's message; `floating`: a floating base's columns may be
    what is missing; `arrays`: the caller reads .npy and .npz files too, by their suffix).
    VampcError naming the line and column of anything else."""
    # --- fast paths: native code on the raw bytes, else np.loadtxt on the text; whatever neither
    # takes goes through the cell-by-cell parser below, which names the bad line and column ---
    from vampc.outputs import STDIN
    from vampc.textio import decode_utf8, read_whole
    if str(path) == STDIN and sys.stdin is None:
        raise VampcError(f"-: standard input is closed, so the {what} has nowhere to come from "
                         "(give it as a file, or redirect standard input from one)")
    raw = read_whole(path, stdin=True, text=True) if source is None else source.getvalue()  # (-: stdin)
    from vampc.sniff import compression
    packed = compression(raw[:16])
    if packed:                               # (was: 'line 1: byte 0x8b is not UTF-8')
        raise VampcError(f"{path}: {packed}-compressed; give the {what} as plain CSV (decompress it "
                         "first)")
    if raw.startswith(codecs.BOM_UTF8):
        raw = raw[len(codecs.BOM_UTF8):]     # Excel writes one
    refused: list = []
    fast = _read_csv_native(raw, columns, refused)
    if refused:                 # one line the native reader refused: wrong for the slow parser too?
        _refused_line(path, *refused[0])
    text = None
    if fast is None:
        text = decode_utf8(raw, path, what, arrays)
        # (np.loadtxt reads '١' or '１' as 1, as float() does: a text beyond ASCII goes the slow
        # way, which names the cell)
        fast = _read_csv_loadtxt(text, columns) if text.isascii() else None
    if fast is not None:
        return fast
    # --- end of fast paths ---
    # universal newlines: a file ending its lines with CR alone (old Mac tools) reads as CRLF and
    # LF do; csv's own error was a traceback ("new-line character seen in unquoted field")
    reader = csv.reader(io.StringIO(text, newline=None))
    rows = _rows(path, reader)
    head = next(rows, None)
    if head is None:
        raise VampcError(f"{path}: empty {what} file")
    if not "".join(head).strip():      # (it said "header: 0 columns, expected 18": a new user's)
        what = "is blank" if len(head) < 2 else "holds no column names, only commas"
        raise VampcError(f"{path}: line 1 {what}: the header line comes first ({_listed(columns)}, "
                         "t first if the rows have times)")
    names = [c.strip() for c in head]
    has_t = bool(names) and names[0] == "t"
    want = (["t"] if has_t else []) + list(columns)
    if names != want:
        if floating:
            _missing_base(path, names, want)
        bad = next((k for k, (got, exp) in enumerate(zip(names, want)) if got != exp), None)
        which = (f"column {bad + 1} is {shown(names[bad])}, expected {want[bad]!r}" if bad is not None
                 else f"{len(names)} columns, expected {len(want)}")
        first = ("; a t column comes first" if "t" in names and names[0] != "t" and
                 [c for c in names if c != "t"] == list(columns) else "")
        if not floating and names[len(want):] == BASE_COLUMNS and names[:len(want)] == want:
            first += ("; the base columns are a floating base's: give the robot --floating-base "
                      "(README, Trees and floating bases)")
        first += _header_hint(names, columns)
        raise VampcError(f"{path}: header: {which} (expected {count(len(want), 'column')} "
                         f"{_listed(want)}: {why}){first}")
    # row by row into blocks of an array (a list of every row's strings took 7.9 GB for a 730 MB file)
    blocks, block, k = [], np.empty((4096, len(want))), 0
    for r, row in enumerate(rows, 2):
        if k == len(block):
            blocks.append(block)
            block, k = np.empty((len(block) * 2, len(want))), 0
        block[k] = _row_values(path, row, r, want, raw)
        k += 1
    data = np.concatenate(blocks + [block[:k]])
    if data.shape[0] == 0:
        raise VampcError(f"{path}: the {what} has no {'states' if what == 'trajectory' else 'rows'}")
    return (data[:, 1:], data[:, 0]) if has_t else (data, None)


def _listed(columns) -> str:
    """A header's columns, the middle ones left out past three."""
    columns = list(columns)
    return ",".join(columns) if len(columns) <= 3 else f"{','.join(columns[:2])}...{columns[-1]}"


def _rows(path: Path, reader):
    """The csv reader's rows, one at a time, but for the blank ones that end the table (trailing
    blank lines are no states; a blank row with rows after it is given as it is)."""
    blank = []
    try:
        for row in reader:
            if not "".join(row).strip():
                blank.append(row)
                continue
            yield from blank
            blank.clear()
            yield row
    except csv.Error as exc:
        raise VampcError(f"{path}: line {reader.line_num}: {exc}") from None


def _row_values(path: Path, row: list[str], r: int, want: list[str], raw: bytes = b"",
                finite: bool = True) -> list[float]:
    """Line r's cells as numbers (VampcError naming the line and the column otherwise), each finite
    unless not `finite`; `raw`, the file's bytes, says whether a blank line comes of lines ended CR
    CR LF (read in memory: a FIFO or standard input cannot be opened again, and a run hung on it, a
    review's find)."""
    if not "".join(row).strip():      # (a CRLF file saved again as text ends its lines \r\r\n)
        # (the CR CR LF reason only where the lines end so: it was said of every blank line)
        raise VampcError(f"{path}: line {r} is blank: blank lines can only end the table" + (
            " (lines ended CR CR LF, as a CRLF file saved again as text ends them, read as a "
            "blank line after each)" if b"\r\r\n" in raw else ""))
    spread = next((c for c, cell in enumerate(row) if "\n" in cell or "\r" in cell), None)
    if spread is not None:      # (said as "4 columns, expected 19", the lines after it taken in)
        column = want[spread] if spread < len(want) else f"{spread + 1}"
        raise VampcError(f"{path}: line {r}, column {column}: a quoted cell holds a line break (a "
                         "quote opened and not closed?)")
    if len(row) != len(want):
        raise VampcError(f"{path}: line {r}: {len(row)} columns, expected {len(want)}")
    out = []
    for c, cell in enumerate(row):
        try:
            out.append(cell_number(cell))
        except ValueError:
            raise VampcError(f"{path}: line {r}, column {want[c]}: {shown(cell)} is not a "
                             "number") from None
        if finite and not math.isfinite(out[-1]):   # (said here, as _check_finite says it, so
            raise _not_finite(path, out[-1], r - 2, want[c], 2)   # that the first bad line is
    return out              # named: an inf, then a bad cell further on, had named the cell)


def _refused_line(path: Path, raw: bytes, at: int, want: list[str]) -> None:
    """The line at byte `at` of `raw` (its columns `want`), which the native reader refused after
    reading every line before it: the slow parser's error for it, said now, if it has one (a bad
    cell on the millionth line of a big file took 40 s and 7.9 GB to name through the slow
    parser). A line the slow parser could read otherwise (quotes, characters beyond ASCII, more
    cells of over 19 digits than the native reader converts) is left to it."""
    nl = raw.find(b"\n", at)
    line = raw[at:len(raw) if nl < 0 else nl]
    if line.endswith(b"\r"):
        line = line[:-1]
    if b'"' in line or b"\r" in line or not line.isascii() or \
            not line.decode("ascii").replace(",", "").strip():
        return                        # (a blank line, commas and spaces too: the slow parser's)
    # (a number that is not finite is left to the slow parser too: a line before this one that
    # the native reader took may hold one, 1e999 read as inf, which comes first)
    _row_values(path, line.decode("ascii").split(","), raw.count(b"\n", 0, at) + 1, want, raw,
                finite=False)


# The fast paths return (data, t), or None whenever the file is anything but a plain well-formed
# table: the slow parser then reads it the same way or reports the precise error. Both give each cell
# the value float() gives it.

def _plain_header(head: str, columns: list[str]):
    """Whether the header line has a t column (True/False), or None if it is not the expected one."""
    names = [c.strip() for c in head.split(",")]
    has_t = bool(names) and names[0] == "t"
    return has_t if names == (["t"] if has_t else []) + list(columns) else None


def _read_csv_native(raw: bytes, columns: list[str], refused: list | None = None):
    """vampc.emulator.native.parse_csv (strict decimal cells, Eisel-Lemire then strtod) on the bytes after
    the header, read in place; trailing blank lines are no states, and a file whose lines end in a
    CR alone (old Mac tools) reads as the slow parser's universal newlines read it. `refused`: a
    list given gets the first byte of the first line refused (in `raw`), when one was."""
    end = raw.find(b"\n")                 # the body is read in place: no copy of a big file
    end = len(raw) if end < 0 else end
    if _lone_cr(raw, 0, end + 1):         # (a CRLF header is read as it is)
        return _read_csv_native(_universal(raw), columns, refused)
    try:
        has_t = _plain_header(raw[:end].decode("ascii"), columns)
    except UnicodeDecodeError:
        return None
    if has_t is None:
        return None
    from vampc.emulator.native import parse_csv
    start, stop = min(end + 1, len(raw)), len(raw)
    while stop > start and raw[stop - 1] in b" \t\r\n":
        stop -= 1                          # (a cell's trailing blanks are allowed anyway)
    cols = len(columns) + has_t
    where: list = []
    data = parse_csv(raw, cols, start=start, refused=where, stop=stop)
    if data is None and where and _lone_cr(raw, where[0], len(raw)):
        return _read_csv_native(_universal(raw), columns, refused)   # a CR alone ends a line
    if data is None:
        if where and refused is not None:
            refused.append((raw, where[0], (["t"] if has_t else []) + list(columns)))
        return None
    return (data[:, 1:], data[:, 0]) if has_t else (data, None)


def _lone_cr(raw: bytes, start: int, end: int) -> bool:
    """Whether raw[start:end] holds a CR that is not part of a CRLF (counted in C, not copied)."""
    return raw.count(b"\r", start, end) != raw.count(b"\r\n", start, end)


def _universal(raw: bytes) -> bytes:
    """The bytes with CRLF and CR line ends made LF, as Python's universal newlines read them."""
    return raw.replace(b"\r\n", b"\n").replace(b"\r", b"\n")


def _read_csv_loadtxt(text: str, columns: list[str]):
    """np.loadtxt on the text after the header."""
    head, _, body = text.partition("\n")
    has_t = _plain_header(head, columns)
    data = None if has_t is None else _loadtxt(body, len(columns) + has_t)
    if data is None:
        return None
    return (data[:, 1:], data[:, 0]) if has_t else (data, None)


def _loadtxt(body: str, cols: int):
    """np.loadtxt converts as float() does (PyOS_string_to_double) but, unlike the csv module, skips
    blank lines and takes no quotes: refuse what csv would read differently."""
    lines = body.split("\n")
    while lines and not lines[-1].strip():
        lines.pop()     # the final newline (and trailing blank lines) end the table
    if not lines:
        return None
    try:
        data = np.loadtxt(lines, delimiter=",", comments=None, quotechar=None, ndmin=2, dtype=float)
    except ValueError:
        return None
    return data if data.shape == (len(lines), cols) else None   # no skipped blank line, not ragged


# What np.load raises on a damaged or unexpected file: a truncated array (EOFError, ValueError), an
# object array (ValueError: pickles are refused), a file that is not a zip (BadZipFile), a bad member.
_NUMPY_ERRORS = (ValueError, EOFError, zipfile.BadZipFile, KeyError, TypeError, UnicodeError,
                 zlib.error,    # (a damaged compressed member: a traceback, exit 3, an audit's)
                 tokenize.TokenError)   # (a header whose brace is never closed: the same, a new user's)


def _npy_fits(path: Path, member: str | None = None, z=None, source=None) -> None:
    """A .npy file (or member `member` of the .npz `z`) holds the data its header announces
    (VampcError otherwise), read before numpy allocates the array the header asks for, whatever
    size that claims."""
    try:
        if member is None and source is not None:    # (kept open: np.load reads it next)
            source.seek(0)
            f, size = contextlib.nullcontext(source), len(source.getbuffer())
        elif member is None:
            f, size = open(path, "rb"), path.stat().st_size
        else:
            f, size = z.zip.open(f"{member}.npy"), z.zip.getinfo(f"{member}.npy").file_size
        with f as g:
            version = np.lib.format.read_magic(g)
            read = (np.lib.format.read_array_header_1_0 if version == (1, 0)
                    else np.lib.format.read_array_header_2_0)
            shape, _, dtype = read(g)
            start = g.tell()
    except (OSError, AttributeError, *_NUMPY_ERRORS):
        return                      # np.load says why
    if dtype.hasobject:
        return
    what = f"{path}: array {member}" if member is not None else f"{path}"
    if any(d < 0 for d in shape):     # (said as "-152 bytes" of data announced)
        raise VampcError(f"{what}: its header announces a negative length, shape {tuple(shape)} "
                         "(damaged, or not written by numpy)")
    need = math.prod(shape) * dtype.itemsize
    if need != size - start:          # short: truncated; long: data numpy would leave unread
        why = "truncated or damaged" if need > size - start else "damaged, or another file after it"
        raise VampcError(f"{what}: its header announces an array of shape {tuple(shape)} "
                         f"({need:,} bytes) but the file holds {size - start:,} bytes of data "
                         f"({why})")


def _head(path: Path, size: int, source=None) -> bytes | None:
    """The file's first `size` bytes (None if it cannot be read: np.load then says why)."""
    if source is not None:
        return source.getvalue()[:size]
    try:
        with open(path, "rb") as f:
            return f.read(size)
    except OSError:
        return None


def _magic(path: Path, what: str, source=None) -> None:
    """VampcError unless the file starts as a .npy or a .npz does (either: a misnamed one is said
    below): numpy's load reads any other file as a pickle, and its refusal said 'it holds Python
    objects' of a text file."""
    head = _head(path, 16, source)
    from vampc.sniff import compression
    packed = None if head is None else compression(head)
    if packed:
        raise VampcError(f"{path}: {packed}-compressed; give the {what} as numpy saved it "
                         "(decompress it first)")
    head = None if head is None else head[:len(NPY_MAGIC)]
    if head is not None and not (head.startswith(NPY_MAGIC) or head.startswith(ZIP_MAGIC)):
        raise VampcError(f"{path}: not a {what} (it does not start as numpy writes one: "
                         f"{head!r}{'' if head else ', empty'}); give a .npy or .npz that numpy "
                         "saved, or a .csv")


def _read_npy(path: Path, n: int, names: list[str], source=None, why: str = ""):
    width = len(names)
    _magic(path, "numpy .npy array file", source)
    _npy_fits(path, source=source)
    if source is not None:
        source.seek(0)
    try:
        arr = np.load(path if source is None else source, allow_pickle=False)
    except _NUMPY_ERRORS as exc:
        raise VampcError(f"{path}: not a numpy array file ({_numpy_reason(exc)})") from None
    if not isinstance(arr, np.ndarray):
        arr.close()         # (np.load's NpzFile holds the file open: a library caller's leak)
        raise VampcError(f"{path}: a .npz archive, not a .npy array; rename it .npz")
    if arr.dtype.names:     # (said as "array of shape (3,)", its fields unsaid)
        raise VampcError(f"{path}: a structured array (named fields {', '.join(arr.dtype.names)}); "
                         f"save a plain array of numbers, (states, {width}) or (states, {width + 1}) "
                         "with t first")
    if arr.ndim == 2 and arr.shape[1] in (width, width + 1) and arr.shape[0] == 0:
        raise VampcError(f"{path}: the array has no states (shape {arr.shape})")
    if arr.ndim != 2 or arr.shape[1] not in (width, width + 1) or arr.shape[0] == 0:
        base = (" (a floating base: q, qd, qdd, then the 9 base columns)" if width > 3 * n else
                "; if the last 9 columns are a floating base's, give the robot --floating-base "
                "(README, Trees and floating bases)" if arr.ndim == 2 and arr.shape[1] in (width + 9, width + 10)
                else "")
        raise VampcError(f"{path}: array of shape {arr.shape}; expected (states, {width}) or "
                         f"(states, {width + 1}) with t first{base}{why}")
    arr = _as_float(path, arr, columns=(["t"] if arr.shape[1] == width + 1 else []) + names)
    return (arr[:, 1:], arr[:, 0]) if arr.shape[1] == width + 1 else (arr, None)


def _read_npz(path: Path, n: int, floating: bool = False, source=None, why: str = ""):
    _magic(path, "numpy .npz archive", source)
    if source is not None:
        source.seek(0)
    try:
        z = np.load(path if source is None else source, allow_pickle=False)
    except _NUMPY_ERRORS as exc:
        raise VampcError(f"{path}: not a numpy .npz file ({_numpy_reason(exc)})") from None
    if not isinstance(z, np.lib.npyio.NpzFile):
        raise VampcError(f"{path}: a .npy array, not a .npz archive; rename it .npy")
    with z:
        names = z.zip.namelist()
        twice = sorted({m for m in names if names.count(m) > 1})
        if twice:          # (numpy reads the last, zip tools the first: it ran on the last, unsaid)
            raise VampcError(f"{path}: the archive holds {twice[0]!r} more than once (which is the "
                             "array?); save it again with numpy.savez")
        return _npz_arrays(path, z, n, floating, why)


def _npz_arrays(path: Path, z, n: int, floating: bool, why: str = ""):
    """(data, t) from an open .npz archive (`why`: what a width short of n says, if anything)."""
    missing = [k for k in ("q", "qd", "qdd") if k not in z.files]
    if missing:
        raise VampcError(f"{path}: missing arrays {missing} (need q, qd, qdd; optional t)")
    extra = sorted(set(z.files) - {"q", "qd", "qdd", "t", "base"})
    if extra:               # (a `T` for `t` ran without times, unsaid: never silently dropped)
        raise VampcError(f"{path}: array {extra[0]!r} is not read (the arrays are q, qd, qdd, "
                         "optional t, and base for a floating base)")
    parts = [_as_float(path, _member(path, z, k), k, [f"{k}{i}" for i in range(1, n + 1)])
             for k in ("q", "qd", "qdd")]
    t = _as_float(path, _member(path, z, "t"), "t") if "t" in z.files else None
    for k, p in zip(("q", "qd", "qdd"), parts):
        if p.ndim == 2 and p.shape[1] == n and p.shape[0] and p.shape[0] != parts[0].shape[0] and \
                parts[0].ndim == 2 and parts[0].shape[1] == n:
            raise VampcError(f"{path}: array {k} has {p.shape[0]} rows and array q "
                             f"{parts[0].shape[0]}; the arrays hold one row per state")
        if p.shape == (0, n):            # (said as a shape alone, a review's find)
            raise VampcError(f"{path}: array {k} holds no states (shape {p.shape})")
        if p.ndim != 2 or p.shape != (parts[0].shape[0], n) or p.shape[0] == 0:
            raise VampcError(f"{path}: array {k} has shape {p.shape}; expected (states, {n}){why}")
    if t is not None and t.shape != (parts[0].shape[0],):
        raise VampcError(f"{path}: array t has shape {t.shape}; expected ({parts[0].shape[0]},)")
    if floating:
        parts.append(_npz_base(path, z, parts[0].shape[0]))
    elif "base" in z.files:         # as the CSV's and .npy's extra columns are: never silently dropped
        raise VampcError(f"{path}: array base: the program has a fixed base, so the base's motion does "
                         "not apply (compile with --floating-base, or leave it out)")
    return np.concatenate(parts, axis=1), t


def _npz_base(path: Path, z, count: int) -> np.ndarray:
    """The `base` member of a floating-base .npz trajectory: (count, 9)."""
    if "base" not in z.files:
        raise VampcError(f"{path}: missing array base (a floating-base program needs the base's motion, "
                         f"(states, 9): {','.join(BASE_COLUMNS)})")
    base = _as_float(path, _member(path, z, "base"), "base", BASE_COLUMNS)
    if base.shape != (count, 9):
        raise VampcError(f"{path}: array base has shape {base.shape}; expected ({count}, 9)")
    return base


def _member(path, z, key: str) -> np.ndarray:
    _npy_fits(path, key, z)
    try:
        value = z[key]
    except _NUMPY_ERRORS as exc:
        raise VampcError(f"{path}: array {key}: {_numpy_reason(exc)}") from None
    if not isinstance(value, np.ndarray):    # a member that is not a .npy file comes back as bytes
        raise VampcError(f"{path}: array {key}: not a numpy array")
    return value


def _numpy_reason(exc: Exception) -> str:
    if isinstance(exc, tokenize.TokenError):
        return f"its header does not parse: {exc.args[0]}"
    text = " ".join(str(exc).split())
    text = re.sub(r"<ast\.(\w+) object at 0x[0-9a-fA-F]+>", r"a \1 expression", text)  # (an address)
    if "allow_pickle" in text:
        return "it holds Python objects (dtype object); save plain numbers"
    return text[:200] or type(exc).__name__


def _as_float(path, arr, name: str = "", columns: list[str] | None = None) -> np.ndarray:
    """`arr` as float64; VampcError at a value it cannot be exactly. `columns`: the names of a 2-D
    array's columns, by which a message names the column (by its number otherwise)."""
    what = f"array {name}" if name else "the array"
    if np.issubdtype(arr.dtype, np.complexfloating):
        raise VampcError(f"{path}: {what} is complex ({arr.dtype}); states must be real numbers")
    if arr.dtype.kind not in "fiu":     # (timedelta64 is an integer to NumPy: refused as datetime64 is)
        raise VampcError(f"{path}: {what} holds {arr.dtype.name} values, not numbers")
    with np.errstate(over="ignore", invalid="ignore"):   # (a long double past float64, or no number:
        # inf or nan, said by the finiteness check; a RuntimeWarning line came before that error)
        out = np.asarray(arr, dtype=float)
    if arr.dtype.kind in "iu":
        _exact_integers(path, what, arr, out, columns)
    elif arr.dtype.itemsize > 8:        # a long double (float128): more bits than float64's 53
        _exact_long_doubles(path, what, arr, out, columns)
    return out


def _exact_integers(path, what: str, arr: np.ndarray, out: np.ndarray, columns=None) -> None:
    """VampcError at the first integer that float64 cannot hold (past 2**53, an odd one, say): it was
    rounded, saying nothing (nanosecond times 2**53 + 1, + 2, + 3 read as 2**53, 2**53 + 2, 2**53 + 4,
    repeats among them; a new user's find)."""
    big = np.abs(out) >= 2.0 ** 53
    if not big.any():
        return
    values, rounded = arr[big], out[big]
    top = 2.0 ** (arr.dtype.itemsize * 8 - (arr.dtype.kind == "i"))
    fits = (rounded >= -top) & (rounded < top)   # (a rounding up to 2**63 is no int64: inexact)
    exact = np.zeros(values.shape, dtype=bool)
    exact[fits] = rounded[fits].astype(arr.dtype) == values[fits]
    if exact.all():
        return
    k = int(np.flatnonzero(~exact)[0])
    place = _cell(np.argwhere(big)[k], columns)
    raise VampcError(f"{path}: {what}, {place}: the integer {int(values[k])} is not a float64 (vampc "
                     f"computes in float64, where it is {float(rounded[k])!r}); give it as a float, or in a "
                     "unit that keeps it within 2**53")


def _exact_long_doubles(path, what: str, arr: np.ndarray, out: np.ndarray, columns=None) -> None:
    """VampcError at the first long double that float64 does not hold exactly: 1 + 2**-60 was
    rounded to 1.0, saying nothing, as integers past 2**53 were (one past float64's range is inf
    in `out`, refused as not finite)."""
    lost = np.isfinite(out) & (out.astype(arr.dtype) != arr)
    if not lost.any():
        return
    at = np.argwhere(lost)[0]
    raise VampcError(f"{path}: {what}, {_cell(at, columns)}: the long double {arr[tuple(at)]!s} is not a "
                     f"float64 (vampc computes in float64, where it is {float(out[tuple(at)])!r}); "
                     "save the array as float64 if that rounding will do")


def _cell(at, columns=None) -> str:
    """Where index `at` of a NumPy trajectory array is: its state (from 1) and its column (by its
    name in `columns` where given, as the finiteness check names it; by its number otherwise)."""
    if len(at) < 2:
        return f"state {at[0] + 1}"
    named = columns is not None and at[1] < len(columns)      # (a member not yet of its shape: by number)
    return f"state {at[0] + 1}, column {columns[at[1]] if named else at[1] + 1}"


def numpy_file(path) -> bool:
    """Whether a trajectory file is read as a NumPy .npy or .npz (by its suffix), not as CSV."""
    return str(path).lower().endswith((".npy", ".npz"))


def state_at(path, row: int) -> str:
    """Where state `row` (from 0) of a trajectory file is: its line in a CSV (the states start on
    line 2, as every message about a CSV's cells says), its number in a NumPy file."""
    return _place(row, None if numpy_file(path) else 2)


def _place(row: int, first_line: int | None) -> str:
    """State `row` (from 0), with its line where the states start on `first_line` of a text."""
    return f"state {row + 1}" if first_line is None else f"line {row + first_line} (state {row + 1})"


def _check_finite(path, data: np.ndarray, columns: list[str] | None = None,
                  first_line: int | None = None, t: np.ndarray | None = None) -> None:
    """VampcError naming the first state (from 1; with its line where the states start on
    `first_line` of a text file) and column (by name where given) that is not finite, `t` (the
    states' times, if given) its first column (a t not finite on line 3 had been named after a
    state's cell on line 4)."""
    first = []                                   # (state, column: -1 for t) of each's first
    bad_t = np.flatnonzero(~np.isfinite(t)) if t is not None else ()
    if len(bad_t):
        first.append((int(bad_t[0]), -1))
    bad = ~np.isfinite(data)
    if bad.any():
        first.append(tuple(int(x) for x in np.argwhere(bad)[0]))
    if first:
        r, c = min(first)
        column = "t" if c < 0 else columns[c] if columns is not None and c < len(columns) else c + 1
        raise _not_finite(path, t[r] if c < 0 else data[r, c], r, column, first_line)


def _not_finite(path, value: float, row: int, column, first_line: int | None) -> VampcError:
    """The error for state `row`'s (from 0) `value` in `column`, which is not finite."""
    why = (" (written so, or a number beyond float64's range, about 1.8e308)" if math.isinf(value)
           else "")
    return VampcError(f"{path}: {_place(row, first_line)}, column {column}: {value} is not "
                      f"finite{why}")


def torque_columns(names, floating: bool = False) -> list[str]:
    """Torque CSV column names: `tau_<joint name>` in joint order, then a floating base's wrench
    (WRENCH_COLUMNS) (README "Torque files")."""
    return [f"tau_{name}" for name in names] + (WRENCH_COLUMNS if floating else [])


def csv_line(cells) -> str:
    """One CSV line (cells quoted only where a name needs it)."""
    out = io.StringIO()
    csv.writer(out, lineterminator="\n").writerow(cells)
    return out.getvalue()


def side_by_side(*columns: np.ndarray | None) -> np.ndarray:
    """The given (count,) or (count, k) arrays side by side as one float array (None skipped)."""
    parts = [np.asarray(c, dtype=float).reshape(len(c), -1) for c in columns if c is not None]
    return np.hstack(parts) if len(parts) > 1 else parts[0]


def format_rows(*columns: np.ndarray | None) -> str:
    """CSV rows of the given (count,) or (count, k) arrays side by side (None skipped), full
    precision: %.17g round-trips like repr."""
    data = side_by_side(*columns)
    count, width = data.shape
    if count * width >= NATIVE_CELLS:          # in C on two threads: 7.6 times as fast (median of 5)
        from vampc.emulator.native import format_csv
        text = format_csv(data)
        if text is not None:
            return text
    # --- fast path: one %-format over all rows at C speed; %.17g round-trips like repr, faster ---
    row = ",".join(["%.17g"] * width) + "\n"
    return (row * count) % tuple(data.ravel().tolist())
    # --- end of fast path ---


def write_torques(path, tau: np.ndarray, names=None, t: np.ndarray | None = None) -> None:
    """Torque CSV (header `t` if given, then `tau_<name>`; `tau1..taun` without names), written by
    the output rules of vampc.outputs."""
    from vampc.program.file import write_text_atomic
    columns = torque_columns(names) if names is not None else [f"tau{i}" for i in
                                                                range(1, tau.shape[1] + 1)]
    head = csv_line((["t"] if t is not None else []) + columns)
    write_text_atomic(path, head + format_rows(t, tau), "torques")


def write_states(path, traj) -> None:
    """States in the trajectory CSV format (`t` first if the trajectory has it)."""
    from vampc.program.file import write_text_atomic
    head = csv_line((["t"] if traj.t is not None else []) + header(traj.q.shape[1], traj.base is not None))
    write_text_atomic(path, head + format_rows(traj.t, traj.q, traj.qd, traj.qdd, traj.base), "states")
