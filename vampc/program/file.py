"""The program file (`*.vamp.json`): writer and validating reader. Its types are
vampc.program.format's Structs, from which `schemas/program.schema.json` is generated.

Sections (format "vampc-program", version 2):

    robot           what the host needs: joint types, Φ_i, offsets, p*, r*, masses, inertias, limits,
                    gravity and endpoint values (so it can compute A_i(q) and check torques)
    options         how it was compiled (recursion, prefix shape, latencies)
    graph           the dataflow graph (for reports and the layout-versus-graph check; never executed)
    schedule        ASAP start/finish per graph node, latency, critical path, interval
    network         VAMPs (logical index, burned-in number, operand taps), buffers, ports, constants
    programs        per VAMP: delay-A, delay-B, delay-R, ROM pointer, and the packed word
    program_stream  per input buffer: the words the host writes in Program Mode, in order
    io              when the host writes each port (tick of set 0; set j is j·C later) and where and
                    when each τ_i appears
    summary         latency, interval, counts
    checksum        sha256 of the canonical JSON of everything else

Written atomically (temporary file, then rename). A reader decodes the file into the Structs, which
checks every type and range as it parses, then the checksum, before anything else looks at the data.

Compact form: a name ending in `.gz` (`-o robot.vamp.json.gz`) writes the same text gzip-compressed
(level GZIP_LEVEL, no timestamp, so the same Python and zlib give the same bytes) as two members,
the line holding the checksum and then the rest (the writer streams the text and knows the checksum
only at its end; `gunzip`, `zcat` and Python's gzip read the members as one text), and any program
file that starts with gzip's magic bytes is read decompressed, to the same IRs (several gzip members
one after another, as `cat a.gz b.gz` makes, are read as one text). Measured on a 512-joint log program
(35 MB of JSON): level 1 makes 4.7 MB in 0.17 s, level 3 4.3 MB in 0.21 s, level 6 3.8 MB in 0.50 s,
level 9 3.5 MB in 2.1 s; decompression 0.1 s at every level. Level 3 is most of the size for little
of the time. A compressed file decompresses to at most GUNZIP_LIMIT bytes (a gzip bomb is refused).
"""
from __future__ import annotations

import codecs
import functools
import hashlib
from collections.abc import Iterator
from pathlib import Path

import msgspec
import numpy as np

from vampc.errors import VampcError
from vampc.gcpause import gc_paused
from vampc.jsontext import (  # noqa: F401 - number, numbers, number_rows: the writer's, from here
    OUT_OF_RANGE,
    DecodeError,
    ascii_bytes,
    ascii_text,
    decode_problem,
    encode,
    encode_lines,
    loads,
    number,
    number_rows,
    number_rows_each,
    numbers,
    rendered,
)
from vampc.program.format import ProgramFile, check_summary, decode, from_builtins

FORMAT, VERSION = "vampc-program", 2
GZIP_LEVEL = 3
GZIP_MAGIC = b"\x1f\x8b"
GUNZIP_LIMIT = 4 << 30          # 4 GiB: a 4096-joint log program is under 0.4 GB


def canonical(doc) -> str:
    """Deterministic JSON text (sorted keys, no whitespace, ASCII, floats as Python's repr) of a
    document: dicts and lists as json.loads gives them, or vampc.program.format's Structs."""
    return encode(rendered(doc))


def checksum(doc: dict) -> str:
    """sha256 over the canonical JSON of the document without its checksum field."""
    body = {k: v for k, v in doc.items() if k != "checksum"}
    return _digest(canonical(body))


def _digest(text: str) -> str:
    return _stamp(hashlib.sha256(text.encode()))


def _stamp(digest) -> str:
    """A checksum as the file holds it: "sha256:" and the hash's hex digits."""
    return "sha256:" + digest.hexdigest()


def _fields(value):
    """(key, value) of a dict or a Struct as the encoder writes them: sorted; a Struct's fields
    left out when it omits defaults and they are."""
    if isinstance(value, dict):
        return sorted(value.items())
    out = []
    for name, key, default in _struct_fields(type(value)):
        v = getattr(value, name)
        if v is msgspec.UNSET or default is not msgspec.NODEFAULT and v == default:
            continue
        out.append((key, v))
    return sorted(out)


@functools.lru_cache(maxsize=None)
def _struct_fields(cls) -> tuple:
    """(name, key, default left out) of a Struct class's fields; the default NODEFAULT when the
    class does not omit defaults. Kept per class: msgspec.structs.fields evaluates the class's
    annotations each call (2 ms of a Puma compile's 7)."""
    omit = cls.__struct_config__.omit_defaults
    return tuple((f.name, f.encode_name, f.default if omit else msgspec.NODEFAULT)
                 for f in msgspec.structs.fields(cls))


ROW_BATCH = 8192     # rows encoded at once: bounded pieces, however big the section


class Rows:
    """A list of rows (Structs) made a batch at a time, as the writer reaches them: `make(lo, hi)`
    gives rows lo..hi-1, as Structs or as their text already encoded (bytes, a line a row, each
    ended by a newline: vampc.program.document.programs_doc). The big sections of a program file
    are written this way (a 4096-joint log program has about a million VAMPs; holding every row's
    Struct, and the whole text, at once doubled the compile's peak memory). Only `layout_chunks`
    reads it: a row list at the depth where `layout` puts one row per line. `weights`, if given,
    is each row's size in items (a stream entry's words): a batch then holds at most ROW_BATCH
    items, or one row (a 4096-joint log program's 8192 stream entries took 100 MB of text at
    once)."""

    __slots__ = ("count", "make", "weights")

    def __init__(self, count: int, make, weights=None):
        self.count, self.make, self.weights = count, make, weights

    def __len__(self) -> int:
        return self.count

    def batches(self):
        size = ROW_BATCH
        if self.weights is None:
            for lo in range(0, self.count, size):
                yield self.make(lo, min(lo + size, self.count))
            return
        lo, held = 0, 0
        for k, weight in enumerate(self.weights):
            if k > lo and held + weight > size:
                yield self.make(lo, k)
                lo, held = k, 0
            held += weight
        if lo < self.count:
            yield self.make(lo, self.count)


def layout(doc) -> str:
    """The canonical JSON of `doc` (dicts and lists, or the program writer's Structs) with line
    breaks added: one line per key of the document and of its sections, and one line per row of a
    list of objects or lists among them (a VAMP, a program, a graph node). Only newlines are added,
    and a JSON encoder never writes a raw newline (it escapes them inside strings), so deleting
    every newline gives canonical(doc) back."""
    return b"".join(layout_chunks(doc)).decode("ascii")


def layout_chunks(doc) -> Iterator[bytes]:
    """`layout`'s text as ASCII bytes, in pieces of at most ROW_BATCH rows (a `Rows` is made as it
    is reached): what write_program streams."""
    rows = (dict, list, tuple, msgspec.Struct)

    def block(value, depth: int) -> Iterator[bytes]:
        if depth < 2 and (isinstance(value, dict) and value or isinstance(value, msgspec.Struct)
                          and not value.__struct_config__.array_like):
            yield b"{\n"
            for k, (key, v) in enumerate(_fields(value)):
                yield (b",\n" if k else b"") + encode(key).encode() + b":"
                yield from block(v, depth + 1)
            yield b"\n}"
        elif isinstance(value, Rows) and value.count or isinstance(value, (list, tuple)) and \
                value and isinstance(value[0], rows) and depth <= 2:
            # one row per line: msgspec writes rows newline-delimited, and JSON text has no raw
            # newline of its own, so each newline is a row's end
            if not isinstance(value, Rows):
                value = Rows(len(value), lambda lo, hi, whole=value: whole[lo:hi])
            yield b"[\n"
            held = None         # each batch's rows end ",\n"; the last one's without (one copy)
            for batch in value.batches():
                if held is not None:
                    yield held
                lines = batch if isinstance(batch, bytes) else encode_lines(batch)
                held = ascii_bytes(lines).replace(b"\n", b",\n")
            yield held[:-2]
            yield b"\n]"
        elif isinstance(value, Rows):
            yield b"[]"
        else:
            yield encode(value).encode()
    return block(rendered(doc), 0)


def write_text_atomic(path, text: str, what: str = "output") -> None:
    """Write text to path by the output rules of vampc.outputs (temporary file, then rename; no
    partial files; symlinks written through; devices written as streams)."""
    from vampc.outputs import PlannedOutput, output_for, write_output
    write_output(path if isinstance(path, PlannedOutput) else output_for(path), text, what)


@gc_paused()
def write_program(doc, path) -> None:
    """Stamp the checksum and write the document atomically, laid out by `layout`. `doc` is a document,
    its text as layout made it, or that text as ASCII byte pieces (layout_chunks; what
    vampc.program.document.program_chunks gives): either way it is serialised once, and the
    checksum is taken over that text with its newlines removed, which is the canonical JSON.
    "checksum" sorts before every other key, so it goes first. `path` is a path or a planned
    vampc.outputs.PlannedOutput.

    Pieces are streamed: hashed and written (compressed for `.gz`) as they come, so the whole text
    is never held. A regular file gets a placeholder checksum of the same length, filled in at the
    end; the compact form is two gzip members, the first line with the checksum and then the rest,
    which read as one text (module docstring); standard output and devices get the text once it is
    all made."""
    if isinstance(doc, str):
        pieces = iter((doc.encode(),))
    elif isinstance(doc, dict):
        body = {k: v for k, v in doc.items() if k != "checksum"}
        if not body or min(body) <= "checksum":
            raise ValueError("a program document's keys must all sort after 'checksum'")
        pieces = layout_chunks(body)
    else:
        pieces = iter(doc)
    from vampc.outputs import PlannedOutput, output_for, writing
    out = path if isinstance(path, PlannedOutput) else output_for(path)
    digest, rest = hashlib.sha256(), _after_open_brace(pieces)
    digest.update(b"{")
    def head() -> bytes:
        return b'{\n"checksum":' + encode(_stamp(digest)).encode() + b","
    placeholder = len(head())
    with writing(out, "program file", binary=True) as fh:
        if str(out.path).lower().endswith(".gz"):            # the compact form
            import shutil
            import zlib
            packer = zlib.compressobj(GZIP_LEVEL, zlib.DEFLATED, 31)
            with _aside(out) as spool:      # the rest's member, until the checksum's is written
                _overlapped(rest, digest, lambda piece: spool.write(packer.compress(piece)))
                spool.write(packer.compress(b"\n") + packer.flush())
                fh.write(zlib.compress(head(), GZIP_LEVEL, wbits=31))
                spool.seek(0)
                shutil.copyfileobj(spool, fh, 1 << 20)
        elif out.kind == "file":                               # seekable: the checksum last
            fh.write(b" " * placeholder)
            _overlapped(rest, digest, fh.write)
            fh.write(b"\n")
            fh.seek(0)
            fh.write(head())
        else:
            held: list[bytes] = []
            _overlapped(rest, digest, held.append)
            fh.write(head())
            _write_each(fh, held)
            fh.write(b"\n")


ASIDE_IN_MEMORY = 16 << 20     # bytes of a compact form's second member held in memory at most


def _aside(out):
    """Where the compact form's second member waits for its first: memory up to ASIDE_IN_MEMORY,
    and past that an unnamed file beside the output (gone however the run ends; a 4096-joint log
    program's 44 MB are not held in memory, at the cost of that much more disk until the file is
    whole); memory only when the output is a pipe or a device."""
    import io
    import tempfile
    if out.kind != "file":
        return io.BytesIO()
    return tempfile.SpooledTemporaryFile(ASIDE_IN_MEMORY, dir=Path(out.path).resolve().parent)


def _write_each(fh, pieces) -> None:
    """fh.write each piece in turn. (Not fh.writelines: on standard output, into a pipe nobody
    reads, Python 3.11's writelines does not let a SIGTERM or Ctrl-C through, and vampc would wait
    for the reader; write returns to the interpreter, which runs the signal's handler.)"""
    for piece in pieces:
        fh.write(piece)


def _overlapped(pieces, digest, put, in_flight: int = 4) -> None:
    """Hash each piece with its newlines removed (`digest`) and put(piece), in order, on a thread
    of its own while this one makes the next pieces: zlib, hashlib and file writes let go of the
    interpreter on big buffers, so on two cores compressing and hashing hide behind the making of
    the rows. At most `in_flight` pieces wait: memory stays bounded, and an error (a full disk) is
    raised here, the pieces after it dropped."""
    from collections import deque
    from concurrent.futures import ThreadPoolExecutor
    def take(piece: bytes) -> None:
        digest.update(piece.replace(b"\n", b""))
        put(piece)
    with ThreadPoolExecutor(1, thread_name_prefix="vampc-write") as pool:
        pending: deque = deque()
        try:
            for piece in _runs(pieces):
                if len(pending) == in_flight:
                    pending.popleft().result()
                pending.append(pool.submit(take, piece))
            while pending:
                pending.popleft().result()
        except BaseException:
            pool.shutdown(cancel_futures=True)
            raise


RUN_BYTES = 1 << 18      # the least bytes _overlapped hands its thread at once (but the last)


def _runs(pieces, least: int = RUN_BYTES) -> Iterator[bytes]:
    """The pieces, in order, joined into runs of at least `least` bytes: a piece that long goes
    alone, uncopied, after the run before it (which, as the last, may be shorter); empty pieces
    make no run. The same bytes: hashing, compressing and writing a run give what its pieces give
    one by one. (A small program is hundreds of short pieces, a key or a section each, and handing
    each to the writing thread took 13 ms of a 2-joint compile's 17.)"""
    run: list[bytes] = []
    size = 0
    for piece in pieces:
        if len(piece) >= least:             # alone, after the run before it
            if size:
                yield b"".join(run)
            run, size = [], 0
            yield piece
            continue
        run.append(piece)
        size += len(piece)
        if size >= least:
            yield b"".join(run)
            run, size = [], 0
    if size:                                # (empty pieces alone make no run)
        yield b"".join(run)


def _after_open_brace(pieces) -> Iterator[bytes]:
    """The pieces of a laid-out document without its first character, "{" (ValueError otherwise)."""
    for first in pieces:
        if not first:
            continue
        if first[:1] != b"{":
            raise ValueError("a program file's text starts with '{'")
        if first[1:]:
            yield first[1:]
        break
    yield from pieces


@gc_paused()
def read_program_file(path: str | Path) -> ProgramFile:
    """Load a program file as its Structs (vampc.program.format), its types, ranges, version and
    checksum checked; VampcError on any problem, naming the place."""
    return _read(path)[0]


@gc_paused()
def read_program(path: str | Path) -> dict:
    """A program file checked as read_program_file does, as plain dicts and lists (for scripts and
    tests that edit documents; vampc itself reads the Structs)."""
    return loads(_read(path)[1])


def _read(path) -> tuple[ProgramFile, bytes]:
    """The file's Structs and its bytes (decompressed; UTF-8, without a byte-order mark). The
    bytes are held once: no copy of the text is made unless something is wrong with it (a 400 MB
    file had taken three times its size)."""
    from vampc.textio import decode_utf8
    try:
        from vampc.textio import read_whole
        raw = read_whole(path, text=True)
    except OSError as exc:
        raise VampcError(f"{path}: cannot read program file: {exc.strerror}") from None
    packed = raw.startswith(GZIP_MAGIC)
    if packed:
        raw = gunzip(raw, path)
    if not raw or raw.isspace():
        what = "compressed file holding nothing" if packed else "empty file"
        raise VampcError(f"{path}: {what}, not a vampc program file (vampc compile writes one)")
    if not raw.isascii():             # (ASCII is UTF-8: what vampc writes, checked without a copy)
        decode_utf8(raw, path, "program file")        # UTF-8, or a clear message
    # msgspec reads the bytes faster than the text
    data = memoryview(raw)[len(codecs.BOM_UTF8):] if raw.startswith(codecs.BOM_UTF8) else raw
    try:
        doc = decode(data)
    except msgspec.ValidationError as exc:
        _refuse_version(_untyped(data, path), path)
        raise VampcError(f"{path}: {_where(exc)}") from None
    except msgspec.DecodeError as exc:
        if packed and "truncated" in str(exc):
            # every gzip member whole, the text short: a copy cut between members (the compact
            # form has two)
            raise VampcError(f"{path}: compressed program file is truncated (its text ends "
                             "early, after a whole gzip member)") from None
        _untyped(data, path)         # says why, when it is not JSON
        raise VampcError(f"{path}: not a vampc program file ({exc})") from None
    lacks = check_summary(doc)
    if lacks:
        raise VampcError(f"{path}: {lacks}")
    if doc.checksum != _laid_out_digest(data, doc.checksum):
        # not as vampc lays it out (reformatted, or edited): its checksum is over the document the
        # text gives, where a key said twice is its last value, so a key put in before its own
        # passed unseen (an audit's find); refused as an edit
        if doc.checksum != checksum(loads(data)):
            raise VampcError(f"{path}: checksum mismatch: the file was modified or damaged; "
                             "recompile it (vampc compile)")
        from vampc.jsontext import duplicate_key
        twice = duplicate_key(bytes(data).decode("utf-8"))
        if twice is not None:
            key, line = twice
            raise VampcError(f"{path}: line {line}: duplicate key {key!r}: the file was edited (vampc "
                             "writes each key once); recompile it (vampc compile)")
    return doc, data


BLANK_LIMIT = 1 << 24     # leading whitespace a compressed program may have (vampc writes none)


def gunzip(data: bytes, path, limit: int = GUNZIP_LIMIT) -> bytes:
    """A gzip-compressed program file's text, every member in turn (VampcError if it is damaged or
    decompresses to more than `limit` bytes: read 16 MiB at a time, so a bomb stops there, and
    held once, growing: no list of pieces joined at the end)."""
    import zlib
    out, size, rest, begun = bytearray(), 0, data, False
    try:
        while rest:
            d = zlib.decompressobj(wbits=31)            # one member: gzip header and trailer
            chunk = d.decompress(rest, 1 << 24)
            while True:
                size += len(chunk)
                if size > limit:
                    raise VampcError(f"{path}: decompresses to more than {limit:,} bytes; not a "
                                     "program file vampc reads")
                out += chunk
                if not begun:                           # (a bomb of zeros stops at its first chunk)
                    begun = _starts_as_json_object(chunk, size == len(chunk), path)
                    if not begun and size >= BLANK_LIMIT:    # (and one of spaces at 16 MiB)
                        raise VampcError(f"{path}: decompressed, its first {size:,} bytes are blank: "
                                         "not a vampc program file")
                if not d.unconsumed_tail:
                    break
                chunk = d.decompress(d.unconsumed_tail, 1 << 24)
            if not d.eof:     # (cut short, or a damaged header or block reads on past the end:
                # "truncated" alone was said of 48 single-bit flips, a faults audit's)
                raise VampcError(f"{path}: compressed program file is truncated or damaged (its "
                                 "compressed data ends before a gzip member does)")
            rest = d.unused_data
    except zlib.error as exc:
        raise VampcError(f"{path}: damaged compressed program file ({exc})") from None
    return out


def _starts_as_json_object(chunk: bytes, first: bool, path) -> bool:
    """Whether a decompressed program's `chunk` (the `first` one: a byte-order mark may lead) comes,
    past whitespace, to the '{' a program file starts with (False: whitespace only, so far);
    VampcError if it comes to anything else."""
    body = (chunk.removeprefix(b"\xef\xbb\xbf") if first else chunk).lstrip(b" \t\r\n")
    if body and body[:1] != b"{":
        raise VampcError(f"{path}: decompressed, it is not a vampc program file (a program file is a JSON "
                         f"object; this starts {body[:12]!r})")
    return bool(body)


def _untyped(data, path):
    """The JSON value of a file whose typed decode failed (VampcError if it is not JSON)."""
    text = bytes(data) if isinstance(data, memoryview) else data       # (bytes: no copy)
    try:
        return loads(text)
    except RecursionError:
        raise VampcError(f"{path}: not a vampc program file (JSON nested too deeply)") from None
    except DecodeError as exc:         # NaN and infinities included: JSON has no such number
        from vampc.sniff import DESCRIPTIONS, sniff
        # (a DH table named *.vamp.json was "invalid JSON: invalid character": a new user's find;
        # not a gzip file, which this reader decompressed itself: a damaged compact program was
        # told to be decompressed, a review's find)
        kind = sniff(path) if isinstance(path, (str, Path)) else None
        if kind not in (None, "program", "json", "gzip"):
            raise VampcError(f"{path}: not a vampc program file (it looks like "
                             f"{DESCRIPTIONS[kind]})") from None
        problem = decode_problem(exc, text)
        if OUT_OF_RANGE in problem:          # (JSON: a number, which float64 cannot hold)
            raise VampcError(f"{path}: {problem}") from None
        raise VampcError(f"{path}: not a vampc program file (invalid JSON: {problem})") from None


def _refuse_version(doc, path) -> None:
    """A document that is not a program file of this version, said as such (VampcError)."""
    if not isinstance(doc, dict) or doc.get("format") != FORMAT:
        from vampc.sniff import vampc_output
        what = vampc_output(doc)
        if what is None and isinstance(doc, dict) and "format" not in doc and \
                isinstance(doc.get("joints"), list):
            # (`vampc compile arm.vamp.json` took a DH table so named, by its .json; emulate,
            # report and lookahead said only "format is not 'vampc-program'": a new user's find)
            what = ("a DH table in JSON: named .vamp.json, it is taken for a program file; name it "
                    ".json and it compiles on the fly")
        raise VampcError(f"{path}: not a vampc program file (" + (f"it looks like {what}" if what else
                                                                   f"format is not {FORMAT!r}") + ")")
    if doc.get("version") == 1:
        raise VampcError(f"{path}: program format version 1 (one op per VAMP) is not read by this "
                         f"vampc, which writes version {VERSION} (VAMPs with slots); recompile the "
                         "robot with `vampc compile`")
    if "version" not in doc:           # (it said "version None is not supported")
        raise VampcError(f"{path}: the program file has no \"version\" (this vampc reads version "
                         f"{VERSION}); was it edited?")
    version = doc.get("version")
    if type(version) is not int and str(version).strip() in (str(VERSION), f"{VERSION}.0"):
        # ("2" was "version '2' is not supported (this vampc reads version 2)": a new user's find)
        raise VampcError(f"{path}: \"version\" must be the number {VERSION}, not "
                         f"{type(version).__name__} {version!r} (was it edited?)")
    if version != VERSION:
        raise VampcError(f"{path}: program format version {version!r} is not supported "
                         f"(this vampc reads version {VERSION})")


def _where(exc: msgspec.ValidationError) -> str:
    """msgspec's "Expected `int` >= 0 - at `$.network.vamps[0].index`" as "network.vamps[0].index:
    expected `int` >= 0" (and "document: ..." for the top level)."""
    message, _, where = str(exc).partition(" - at `$")
    where = where.rstrip("`").lstrip(".") or "document"
    if len(message) > 300:
        message = message[:297] + "..."
    return f"{where}: {message[:1].lower()}{message[1:]}"


def _laid_out_digest(data: bytes, stored: str) -> str | None:
    """The checksum of a file as write_program lays it out, taken from its UTF-8 bytes (its newlines
    removed, they are the canonical JSON the checksum covers), which spares encoding a big document
    again; None for a file laid out otherwise (then the document is encoded: `checksum`)."""
    head = ('{\n"checksum":' + encode(stored) + ",").encode()
    if bytes(data[:len(head)]) != head:
        return None
    digest, rest = hashlib.sha256(b"{"), memoryview(data)[len(head):]
    for at in range(0, len(rest), DIGEST_PIECE):       # a piece at a time: no copy of the whole
        digest.update(bytes(rest[at:at + DIGEST_PIECE]).replace(b"\n", b""))
    return _stamp(digest)


DIGEST_PIECE = 16 << 20


def validate_program(doc, path) -> ProgramFile:
    """A program document held as dicts and lists, checked like a file's (format, version, types
    and ranges; not its checksum, which it may lack: vampc.compiler.program_document has none)
    and returned as its Structs; VampcError otherwise."""
    _refuse_version(doc, path)
    if "checksum" not in doc:
        doc = dict(doc, checksum=_digest(""))
    try:
        out = from_builtins(doc)
    except msgspec.ValidationError as exc:
        raise VampcError(f"{path}: {_where(exc)}") from None
    lacks = check_summary(out)
    if lacks:
        raise VampcError(f"{path}: {lacks}")
    return out


def tolist(x) -> list:
    """numpy array (or nested sequence) to plain lists of floats."""
    return np.asarray(x, dtype=float).tolist()
