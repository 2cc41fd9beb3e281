"""Text files from users: decoding with messages that say where and what, and showing a user's
text in a message without letting invisible characters through."""
from __future__ import annotations

import codecs
import unicodedata

from vampc.errors import VampcError

_OTHER_BOMS = ((codecs.BOM_UTF32_LE, "UTF-32"), (codecs.BOM_UTF32_BE, "UTF-32"),
               (codecs.BOM_UTF16_LE, "UTF-16"), (codecs.BOM_UTF16_BE, "UTF-16"))


def stdin_hint(path, exc: BaseException | None = None) -> str:
    """What follows "no such file" (`exc`: the error of opening it, if that is how it was found
    missing) for an input named `-` where `-` is a file's name: standard input is read for a
    trajectory only (`--limits - < lim.csv` said only "-: cannot read limits: No such file or
    directory": a new user's)."""
    if str(path) == "-" and (exc is None or isinstance(exc, FileNotFoundError)):
        return (" (standard input is read as `-` only for a trajectory, --trajectory or "
                "--accelerations; give this file's name)")
    return ""


def read_whole(path, stdin: bool = False, text: bool = False) -> bytes:
    """The bytes of a user's input, read once: a regular file as Path.read_bytes reads it (into
    one buffer of its size), a pipe or FIFO in pieces, between which a termination signal or Ctrl-C
    ends the read (in one C call Python's handlers do not run: `yes | vampc emulate ... -` could
    not be stopped but by SIGKILL). A character device other than /dev/null (/dev/zero,
    /dev/urandom: no end; 10 GB read in 15 s) is refused with an OSError, which each caller's
    'cannot read' line words. `stdin`: `-` is standard input (a terminal included), for a reader
    that takes it so (a trajectory); elsewhere `-` is a file of that name. Standard input from a
    character device other than a terminal or /dev/null is refused as a named one is (`- <
    /dev/zero` had been read until memory ran out: an audit's find). `text`: the reader takes text
    only (CSV, XML, YAML, JSON), so a pipe's NUL byte, which no such text has, is refused as it arrives (`cat
    /dev/zero |` had been, too)."""
    import errno
    import os
    import stat
    import sys
    if stdin and str(path) == "-":
        try:
            fd = sys.stdin.fileno()
        except (AttributeError, OSError, ValueError):   # (a stream without one: a test's, Jupyter's)
            data = sys.stdin.buffer.read() if hasattr(sys.stdin, "buffer") else sys.stdin.read()
            return data.encode() if isinstance(data, str) else data
        mode = os.fstat(fd).st_mode
        if stat.S_ISREG(mode):                    # (a file redirected in: one buffer of its size)
            return sys.stdin.buffer.read()
        if stat.S_ISCHR(mode) and not os.isatty(fd) and not _null(fd):
            raise OSError(errno.EINVAL, "standard input is a character device, which has no end: "
                                        "give a file or a pipe")
        return _pieces(fd, text)
    fd = os.open(path, os.O_RDONLY)
    try:
        mode = os.fstat(fd).st_mode
        if stat.S_ISREG(mode):
            with open(fd, "rb", closefd=False) as f:
                return f.read()
        if stat.S_ISCHR(mode) and not _null(fd):
            raise OSError(errno.EINVAL, "it is a character device, which has no end: give a file "
                                        "or a pipe")
        return _pieces(fd, text)
    finally:
        os.close(fd)


def _pieces(fd: int, text: bool = False) -> bytes:
    """What a descriptor gives until its end, a MiB at a time (signal handlers run between); with
    `text`, an OSError at the first NUL byte, unless the first 16 bytes say the content is of a
    known kind that is not UTF-8 text (the reader then says what it is)."""
    import errno
    import os
    pieces, size, checked = [], 0, not text      # checked: the bytes so far looked at
    while piece := os.read(fd, 1 << 20):
        pieces.append(piece)
        size += len(piece)
        if not checked and size >= 16:
            head = b"".join(pieces)
            if _binary(head[:16]):
                text = False         # (compressed, an array, UTF-16: the reader says what it is)
            checked = True
            piece = head
        if text and checked and b"\0" in piece:
            at = size - len(piece) + piece.index(b"\0")
            raise OSError(errno.EINVAL, _NUL.format(at))
    data = b"".join(pieces)
    if text and not checked and b"\0" in data and not _binary(data):
        raise OSError(errno.EINVAL, _NUL.format(data.index(b"\0")))
    return data


_NUL = "byte {} is a NUL byte, which no text has (a text file is expected)"


def _binary(head: bytes) -> bool:
    """Whether bytes starting so are a known kind that is not UTF-8 text: compressed, a NumPy
    array, a zip, or text with another byte-order mark."""
    from vampc.sniff import compression
    return bool(compression(head[:16])) or head.startswith((NPY_MAGIC, ZIP_MAGIC)) or \
        any(head.startswith(bom) for bom, _ in _OTHER_BOMS)


def _null(fd: int) -> bool:
    import os
    try:
        return os.fstat(fd).st_rdev == os.stat(os.devnull).st_rdev
    except OSError:
        return False


def plain_number(text: str) -> bool:
    """Whether a number the user typed is in ASCII without separators: float() and int() also read
    '1_0' as 10 and '١' (Arabic-Indic) or '１' (full width) as 1, and those are typos, not numbers
    (the file readers, the command line, --fault and --sweep all refuse them)."""
    return text.isascii() and "_" not in text


def ascii_digits(text: str) -> bool:
    """A whole number in ASCII digits (str.isdigit() also takes '١' and '３', and int() reads them)."""
    return plain_number(text) and text.isdigit()


NPY_MAGIC, ZIP_MAGIC = b"\x93NUMPY", b"PK\x03\x04"     # how a .npy and a .npz (a zip) start


def decode_utf8(raw: bytes, path, what: str, arrays: bool = False) -> str:
    """The text of a UTF-8 file (a leading byte-order mark, as Excel writes, is dropped). Anything
    else is one VampcError naming the line and the byte. `arrays`: the reader also takes NumPy
    files by their suffix (a trajectory), so an .npy or .npz given another name is told to rename
    it; other readers say they take text only."""
    if raw.startswith(codecs.BOM_UTF8):
        raw = raw[len(codecs.BOM_UTF8):]
    for bom, name in _OTHER_BOMS:
        if raw.startswith(bom):
            raise VampcError(f"{path}: {what} is {name} text; save it as UTF-8")
    for magic, kind, suffix in ((NPY_MAGIC, "a NumPy .npy array", ".npy"),
                                (ZIP_MAGIC, "a zip archive (a NumPy .npz?)", ".npz")):
        if raw.startswith(magic):     # (it said "byte 0x93 is not UTF-8")
            if arrays and str(path) == "-":     # (standard input has no name to change)
                raise VampcError(f"-: {kind} on standard input, which takes {what} text (CSV) "
                                 f"only; give the array as a file named {suffix}")
            if arrays:
                raise VampcError(f"{path}: {kind}, not {what} text; name it {suffix} if it holds "
                                 "one")
            raise VampcError(f"{path}: {kind}; the {what} must be UTF-8 text")
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = raw.count(b"\n", 0, exc.start) + 1
        raise VampcError(f"{path}: line {line}: byte 0x{raw[exc.start]:02x} is not UTF-8 "
                         f"(the {what} must be UTF-8 text)") from None


def count(k: int, noun: str) -> str:
    """'1 VAMP', '12 VAMPs', '1 chain', '3 flops' (the noun's plural is noun + 's')."""
    return f"{k} {noun}" + ("" if k == 1 else "s")


def rough_time(seconds: float) -> str:
    """A time to wait, as an estimate gives it: '16 s' below two minutes, else '7 min'."""
    return f"{seconds:.0f} s" if seconds < 120 else f"{seconds / 60:.0f} min"


def shown(text: str, limit: int = 60) -> str:
    """`text` quoted for a message: control, format (zero-width, BOM) and other invisible characters
    escaped as \\uXXXX, cut to `limit` characters."""
    out = []
    for ch in text[:limit]:
        if ch == " " or unicodedata.category(ch)[0] not in "CZ":
            out.append(ch)
        else:
            out.append(ch.encode("unicode_escape").decode("ascii"))
    more = "..." if len(text) > limit else ""
    return "'" + "".join(out).replace("'", "\\'") + more + "'"


def numbers_shown(xs) -> str:
    """A list of numbers as a program file writes them, each its shortest repr: [0.0, 1.0, 6.1e-17]."""
    return "[" + ", ".join(repr(float(x)) for x in xs) + "]"


def listed(name: str) -> str:
    """A name as a list or a sentence shows it: as it is, or quoted (`shown`) when it holds a comma,
    a quote or spaces round it, which would blur where it ends ('my shoulder, left 0.53')."""
    if not name or name != name.strip() or any(c in name for c in ",'\"") or \
            any(ch != " " and unicodedata.category(ch)[0] in "CZ" for ch in name):
        return shown(name, len(name))          # (whole: two names cut alike would read as one)
    return name


# the characters that reorder the text around them (Unicode's bidirectional controls and marks)
BIDI_CONTROLS = frozenset([0x061C, 0x200E, 0x200F, *range(0x202A, 0x202F), *range(0x2066, 0x206A)])


def name_problem(name: str) -> str | None:
    """Why `name` (a robot's, a joint's or a link's) cannot be printed on one line as it is, or None:
    a control character, a bidirectional control or a line or paragraph separator (a newline in a
    joint's name split the text report's rows and every one-line message naming it; a U+202E
    right-to-left override reversed the text after it). Other format characters are taken: the
    zero-width joiners and the soft hyphen belong in names written in Persian or Indic scripts."""
    bad = next((ch for ch in name if unicodedata.category(ch) in ("Cc", "Zl", "Zp")
                or ord(ch) in BIDI_CONTROLS), None)
    if bad is None:
        return None
    what = {"Cc": "control character", "Cf": "bidirectional control"}.get(unicodedata.category(bad),
                                                                          "line separator")
    return (f"its name {shown(name)} holds the {what} U+{ord(bad):04X}: names are printed in "
            "one-line messages, text reports and CSV headers")


def first_name_problem(named) -> tuple[str, str] | None:
    """The first (place, name_problem) of `named`, pairs (place, name), or None."""
    for where, name in named:
        problem = name_problem(name)
        if problem:
            return where, problem
    return None


def one_line(text: str, limit: int = 300) -> str:
    """Collapse whitespace and cut very long messages (a parser's, or one quoting a whole value)."""
    text = " ".join(text.split())
    return text if len(text) <= limit else text[:limit - 3] + "..."


def did_you_mean(word: str, choices, cutoff: float = 0.6, quote: bool = True) -> str:
    """' (did you mean 'dead'?)' for a word close to one of `choices` (difflib's, at least `cutoff`
    alike; unquoted where `quote` is false: ' (did you mean <axis>?)'), else '': a misspelled value
    got no hint where a misspelled option name does (a new user's find)."""
    import difflib
    close = difflib.get_close_matches(word, [str(c) for c in choices], n=1, cutoff=cutoff)
    if not close:
        return ""
    return f" (did you mean {close[0]!r}?)" if quote else f" (did you mean {close[0]}?)"


def apart(x: float, y: float, least: int = 6) -> tuple[str, str]:
    """Two numbers written with as few significant digits (`least` at least) as tell them apart:
    'speed 3 beyond 3' was said of 3.0000000001, a clock's '1 ms need 1 ms' of 1.00025 (a review's
    and a look-ahead audit's finds)."""
    for digits in range(least, 18):
        a, b = f"{x:.{digits}g}", f"{y:.{digits}g}"
        if a != b:
            return a, b
    return repr(x), repr(y)
