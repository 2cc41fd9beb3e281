"""JSON text, written and read with one library, msgspec, as vampc's files have always held it.

Program files, reports, graph annotations and DH tables in JSON all go through here. msgspec
(chosen by measuring: a typed program decode takes 0.016-0.019 s where json.loads, which checks
nothing, takes 0.036-0.050 s) writes floats its own way (0.00001 where Python's repr writes 1e-05)
and characters beyond ASCII as UTF-8, so floats reach it already written (`number`, `rendered`) and
its output is escaped to ASCII afterwards: the text is the same, byte for byte, as Python's json
module wrote (`dumps`; a test holds them equal on generated values). NaN and infinities, which JSON
has no number for, are a ValueError, never written.
"""
from __future__ import annotations

import math
import re

import msgspec

_PLAIN = msgspec.json.Encoder()
_SORTED = msgspec.json.Encoder(order="sorted")
_DECODER = msgspec.json.Decoder()
_NOT_ASCII = re.compile(rb"[\x7f-\xff]")
_ESCAPE = re.compile("[^\x00-\x7e]")      # DEL and beyond ("[\x7f-\U0010ffff]" took 19 ms to compile)

DecodeError = msgspec.DecodeError


def number(x) -> msgspec.Raw:
    """A float as vampc writes it: Python's repr (shortest round trip); ValueError for NaN and
    infinities, which JSON has no number for."""
    text = float.__repr__(float(x))
    if "n" in text:                      # nan, inf: no finite float's repr has an n
        raise ValueError(f"{text} is not a JSON number")
    return msgspec.Raw(text.encode())


def numbers(xs) -> msgspec.Raw:
    """A list of floats, written as `number` writes each, at once."""
    text = _reprs(xs)
    if "n" in text:
        raise ValueError(f"[{text}] holds a value that is not a JSON number")
    return msgspec.Raw(f"[{text}]".encode())


def number_rows(rows) -> msgspec.Raw:
    """A list of lists of floats (a program stream's words), at once. Rows held as one flat array
    of floats (`rows.flat`, `rows.width` per row: vampc.program.emit.Words) are written from it
    without a tuple per row."""
    flat = getattr(rows, "flat", None)
    if flat is not None:
        reprs = iter(list(map(float.__repr__, flat)))
        row = "[" + ",".join(["%s"] * rows.width) + "]"
        text = ",".join(map(row.__mod__, zip(*[reprs] * rows.width)))
    else:
        text = ",".join(["[" + _reprs(r) + "]" for r in rows])
    if "n" in text:
        raise ValueError("a row holds a value that is not a JSON number")
    return msgspec.Raw(f"[{text}]".encode())


def number_rows_each(entries) -> list[msgspec.Raw]:
    """number_rows of each of `entries`, made at once. Where each entry's rows are one flat
    array("d") (`flat`, `width` floats a row, as vampc.program.emit.Words holds them) and every
    value is a whole number below 2^53 in magnitude, none -0.0 (a program stream's VAMP numbers
    and fields), NumPy writes their digits: repr writes such a float as its integer and ".0" (a
    4096-joint log program's three million values took 0.74 s an entry at a time, 0.26 s so).
    Otherwise each entry is number_rows', value by value."""
    flats = [getattr(e, "flat", None) for e in entries]
    widths = {(type(w), w) for w in (getattr(e, "width", None) for e in entries)}
    if not entries or len(widths) != 1 or next(iter(widths))[0] is not int or \
            any(getattr(f, "typecode", None) != "d" for f in flats):      # (array("d") only)
        return [number_rows(e) for e in entries]
    import numpy as np
    width = widths.pop()[1]
    sizes = np.fromiter(map(len, flats), dtype=np.int64, count=len(flats))
    if width < 1 or not sizes.all() or (sizes % width).any():
        return [number_rows(e) for e in entries]
    x = np.frombuffer(b"".join(flats), dtype=np.float64)
    if not (np.abs(x) < 2.0 ** 53).all():                  # (NaN and infinities too)
        return [number_rows(e) for e in entries]
    ints = x.astype(np.int64)
    if (ints != x).any() or (np.signbit(x) & (x == 0)).any():     # a fraction, or -0.0
        return [number_rows(e) for e in entries]
    # A row of a character table per value: open, open, sign, its digits right-aligned, ".", "0",
    # close, close; and which of its characters are written. The first value of an entry opens it
    # and its first row ("[["); a row's first value after that, ",["; any other value, ",".
    m = np.abs(ints)
    top = int(m.max())
    m = m.astype(np.uint32) if top < 2 ** 32 else m         # (a narrower division: 3 times faster)
    digits = len(str(top))
    count = len(x)
    first = np.zeros(count, dtype=bool)          # a row's first value, and its last
    first[::width] = True
    last = np.zeros(count, dtype=bool)
    last[width - 1::width] = True
    ends = np.cumsum(sizes)
    entry_first = np.zeros(count, dtype=bool)
    entry_first[ends - sizes] = True
    entry_last = np.zeros(count, dtype=bool)
    entry_last[ends - 1] = True
    table = np.empty((count, digits + 7), dtype=np.uint8)
    shown = np.empty((count, digits + 7), dtype=bool)
    table[:, 0] = np.where(entry_first, ord("["), ord(","))
    shown[:, 0] = first
    table[:, 1] = np.where(first, ord("["), ord(","))
    shown[:, 1] = True
    table[:, 2] = ord("-")
    shown[:, 2] = negative = ints < 0
    length = first.astype(np.int64) + negative + 3        # each value's characters
    left = m
    for place in range(digits):                           # the units first, rightmost
        tens = left // 10
        table[:, 2 + digits - place] = left - tens * 10 + ord("0")
        shown[:, 2 + digits - place] = written = m >= 10 ** place if place else True
        length += written
        left = tens
    table[:, digits + 3] = ord(".")
    table[:, digits + 4] = ord("0")
    shown[:, digits + 3:digits + 5] = True
    table[:, digits + 5:digits + 7] = ord("]")
    shown[:, digits + 5] = last
    shown[:, digits + 6] = entry_last
    text = np.compress(shown.ravel(), table.ravel()).tobytes()     # value by value, in order
    bounds = np.cumsum(length + last + entry_last)[ends - 1].tolist()
    return [msgspec.Raw(text[a:b]) for a, b in zip([0] + bounds[:-1], bounds)]


def _reprs(xs) -> str:
    try:
        return ",".join(map(float.__repr__, xs))
    except TypeError:                 # ints among them
        return ",".join([float.__repr__(float(x)) for x in xs])


def rendered(value):
    """A document of dicts, lists and scalars with its floats written (`number`); Structs (the
    program writer's, their floats already written) are left as they are."""
    if isinstance(value, float):
        return number(value)
    if isinstance(value, dict):
        return {k: rendered(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        if _AS_THEY_ARE.issuperset(map(type, value)):   # (a row of ints, say: nothing to write)
            return list(value)
        return [rendered(v) for v in value]
    return value


_AS_THEY_ARE = frozenset({int, str, bool, type(None)})    # what rendered leaves as it is


def ascii_text(out: bytes) -> str:
    """msgspec's bytes as text, characters beyond ASCII (and DEL) escaped as Python's json escapes
    them: they occur in strings only."""
    text = out.decode()
    if not _NOT_ASCII.search(out):
        return text
    def escape(m) -> str:
        c = ord(m.group())
        if c < 0x10000:
            return f"\\u{c:04x}"
        c -= 0x10000
        return f"\\u{0xd800 | (c >> 10):04x}\\u{0xdc00 | (c & 0x3ff):04x}"
    return _ESCAPE.sub(escape, text)


def ascii_bytes(out: bytes) -> bytes:
    """ascii_text's escaping, bytes to bytes (the bytes themselves when they are ASCII without DEL:
    told by two scans in C, 20 times faster than the pattern's search over a big program's text)."""
    return out if out.isascii() and b"\x7f" not in out else ascii_text(out).encode()


def encode(value, sort_keys: bool = True) -> str:
    """Compact JSON text (no whitespace) of a value whose floats are already written."""
    return ascii_text(_encoded(_SORTED if sort_keys else _PLAIN, value))


def encode_lines(values) -> bytes:
    """Newline-delimited compact JSON of each value (sorted keys), floats already written."""
    try:
        return _SORTED.encode_lines(values)
    except UnicodeEncodeError:
        return _SORTED.encode_lines([_unsurrogated(v) for v in values])


def _encoded(encoder, value) -> bytes:
    """encoder.encode(value); a string holding a lone surrogate, which UTF-8 has no bytes for (a
    file name that is not UTF-8, as Python hands it over: 'b\\udcff.yaml' had been an internal
    error, an audit's find), written as `_unsurrogated` says."""
    try:
        return encoder.encode(value)
    except UnicodeEncodeError:
        return encoder.encode(_unsurrogated(value))


def _unsurrogated(value):
    """`value` with each string's lone surrogates written out: a byte Python kept as a surrogate
    as it was in the name (\\xff), another as its code (\\ud800)."""
    if isinstance(value, str):
        try:
            return value.encode("utf-8", "surrogateescape").decode("utf-8", "backslashreplace")
        except UnicodeEncodeError:
            return value.encode("utf-8", "backslashreplace").decode()
    if isinstance(value, dict):
        return {_unsurrogated(k): _unsurrogated(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_unsurrogated(v) for v in value]
    if isinstance(value, msgspec.Struct):
        return msgspec.structs.replace(value, **{f: _unsurrogated(getattr(value, f))
                                                 for f in value.__struct_fields__})
    return value


def dumps(value, indent: int | None = None, sort_keys: bool = False) -> str:
    """The text json.dumps(value, indent=indent, sort_keys=sort_keys) writes: one line with ", "
    and ": " between items without `indent`, else an item per line indented by `indent` spaces
    (at least 1)."""
    if indent is not None and indent < 1:
        raise ValueError(f"indent {indent}: give None (one line) or at least 1")
    out = _encoded(_SORTED if sort_keys else _PLAIN, rendered(value))
    return ascii_text(msgspec.json.format(out, indent=0 if indent is None else indent))


_AT_BYTE = re.compile(r"\s*\(byte (\d+)\)$")
_CONSTANTS = ("NaN", "Infinity", "-Infinity")


# a JSON string, taken whole (so nothing in it is read as a number: a checksum's hex digits
# '35670e9337' had been), or a number with its fraction and exponent
_STRING_OR_NUMBER = re.compile(rb'"(?:[^"\\]|\\.)*"|(-?\d+(?:\.\d+)?(?:[eE][+-]?\d+)?)')
OUT_OF_RANGE = "is beyond float64's range (about 1.8e308)"


def _huge_number(data: bytes) -> tuple[bytes, int] | None:
    """The first JSON number of `data` too large for a float, and where it starts; None if none is
    found (msgspec says "Number out of range" with no place: `$[...][...]`)."""
    for m in _STRING_OR_NUMBER.finditer(data):
        token = m.group(1)
        if token is not None and (b"e" in token or b"E" in token or len(token) > 300) and \
                float(token) in (math.inf, -math.inf):
            return token, m.start(1)
    return None


_STRING_BYTES = re.compile(rb'"(?:[^"\\]|\\.)*"')
_BACKSLASHED = re.compile(rb'\\(u[0-9a-fA-F]{4}|.)')
_HIGH = re.compile(rb'\\u[dD][89abAB]')


def _lone_surrogate(data: bytes) -> tuple[str, int] | None:
    """The first \\uD800-\\uDBFF escape of a JSON string not followed by a low surrogate's, and
    where it starts; None if there is none. Only a text holding such an escape is scanned string by
    string (a cut-short 60 MB program file's message had taken 6 s more: a review's find)."""
    if _HIGH.search(data) is None:
        return None
    for m in _STRING_BYTES.finditer(data):
        escapes = list(_BACKSLASHED.finditer(m.group()))
        for k, e in enumerate(escapes):
            code = e.group(1)
            if len(code) == 5 and 0xD800 <= int(code[1:], 16) <= 0xDBFF:
                after = escapes[k + 1] if k + 1 < len(escapes) else None
                low = (after is not None and after.start() == e.end() and len(after.group(1)) == 5
                       and 0xDC00 <= int(after.group(1)[1:], 16) <= 0xDFFF)
                if not low:
                    return "\\" + code.decode(), m.start() + e.start()
    return None


def decode_problem(exc: DecodeError, text: str | bytes) -> str:
    """msgspec's "JSON is malformed: invalid character (byte 81)" said for a person: what is wrong
    and where, as line and column ("NaN is not allowed (line 3, column 12)"; "the number 1e999 is
    beyond float64's range (about 1.8e308) (line 3, column 12)")."""
    message = str(exc).removeprefix("JSON is malformed: ")
    m = _AT_BYTE.search(message)
    data = text.encode() if isinstance(text, str) else text
    if message.startswith("Number out of range"):     # (said with no place: a new user's find)
        found = _huge_number(data)
        if found is not None:
            token, at = found
            return f"the number {token.decode()} {OUT_OF_RANGE} ({_place(data, at)})"
    if m is None:
        lone = _lone_surrogate(data) if message == "Input data was truncated" else None
        if lone is not None:   # (msgspec says "truncated" of '"\ud800"': "it ends early" was said)
            escape, at = lone
            return f"{escape} is half of a UTF-16 surrogate pair, alone ({_place(data, at)})"
        if message == "Input data was truncated":     # said where: at its end (a new user's find)
            return f"it ends early ({_place(data, len(data.rstrip()))})"
        return message
    at = int(m.group(1))
    if data[at - 1:at] == b"-" and data.startswith(b"Infinity", at):     # msgspec points past "-"
        at -= 1
    constant = next((c for c in _CONSTANTS if data.startswith(c.encode(), at)), None)
    what = f"{constant} is not allowed" if constant else message[:m.start()]
    return f"{what} ({_place(data, at)})"


def _place(data: bytes, at: int) -> str:
    """'line L, column C' of byte `at` of `data` (both from 1)."""
    line, column = data.count(b"\n", 0, at) + 1, at - data.rfind(b"\n", 0, at)
    return f"line {line}, column {column}"


class NestedTooDeeply(DecodeError, RecursionError):
    """JSON nested more deeply than the decoder goes: a DecodeError, so a caller that says "not
    JSON" says so of it too (`vampc report --rtl` and `faults --results` given a 2000-deep array
    ended in a traceback, exit 3: a hostile-input audit's find), and a RecursionError, as before."""


def loads(text: str | bytes):
    """The value of JSON text: dicts, lists and scalars (DecodeError if it is not JSON, NaN and
    infinities included; NestedTooDeeply, a DecodeError and a RecursionError, if nested too
    deeply)."""
    try:
        return _DECODER.decode(text)
    except RecursionError:
        raise NestedTooDeeply("nested too deeply") from None


_TOKEN = re.compile(r'"(?:[^"\\]|\\.)*"|[{}\[\]:]')


def duplicate_key(text: str) -> tuple[str, int] | None:
    """The first key a mapping of valid JSON text repeats, and its line; None if none does (msgspec
    keeps the last silently, as a dict would). Every string is one token, so no scan starts inside
    one; a string followed by a colon is a key of the innermost mapping."""
    stack: list[set | None] = []
    pending = None             # the last string token, a key if a colon follows
    for m in _TOKEN.finditer(text):
        token = m.group()
        if token[0] == '"':
            pending = m
            continue
        if token == ":" and pending is not None:
            key = _DECODER.decode(pending.group())
            if key in stack[-1]:
                return key, text.count("\n", 0, pending.start()) + 1
            stack[-1].add(key)
        elif token == "{":
            stack.append(set())
        elif token == "[":
            stack.append(None)
        elif token in "}]":
            stack.pop()
        pending = None
    return None
