"""The program file (`*.vamp.json`): writer and validating reader (schema `program.schema.json`).

Sections (format "vampc-program", version 1):

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

Written atomically (temporary file, then rename). A reader validates the schema, the version and the
checksum before anything else looks at the data.
"""
from __future__ import annotations

import hashlib
import json
from pathlib import Path

import numpy as np

from vampc.errors import VampcError
from vampc.gcpause import gc_paused

FORMAT, VERSION = "vampc-program", 2


def canonical(doc: dict) -> str:
    """Deterministic JSON text (sorted keys, no whitespace variation)."""
    return json.dumps(doc, sort_keys=True, separators=(",", ":"), allow_nan=False,
                      check_circular=False)   # documents are trees (built or parsed)


def checksum(doc: dict) -> str:
    """sha256 over the canonical JSON of the document without its checksum field."""
    body = {k: v for k, v in doc.items() if k != "checksum"}
    return _digest(canonical(body))


def _digest(text: str) -> str:
    return "sha256:" + hashlib.sha256(text.encode()).hexdigest()


class Rows(list):
    """A list whose items are already canonical JSON text (one row each): `layout` writes them as they
    are, one per line. The program document's big sections (a row per VAMP, per program, per graph
    node) are formatted this way, straight from the IRs, because building a million dicts and encoding
    them again cost most of a large compile."""


def compact_encoder():
    """obj -> canonical JSON text (sorted keys, no spaces, ASCII). The encoder object is made once
    and reused for every row (json.dumps would make one per call)."""
    return json.JSONEncoder(sort_keys=True, separators=(",", ":"), allow_nan=False,
                            check_circular=False).encode


def layout(doc: dict) -> str:
    """The canonical JSON of `doc` with line breaks added: one line per key of the document and of
    its sections, and one line per row of a list of objects or lists among them (a VAMP, a program,
    a graph node). Only newlines are added, and a JSON encoder never writes a raw newline (it escapes
    them inside strings), so deleting every newline gives canonical(doc) back."""
    enc = compact_encoder()

    def block(value, depth: int) -> str:
        if isinstance(value, Rows):
            return "[\n" + ",\n".join(value) + "\n]" if value else "[]"
        if isinstance(value, dict) and value and depth < 2:
            return "{\n" + ",\n".join(enc(k) + ":" + block(value[k], depth + 1)
                                       for k in sorted(value)) + "\n}"
        if isinstance(value, list) and value and isinstance(value[0], (dict, list)) and depth <= 2:
            return "[\n" + ",\n".join(map(enc, value)) + "\n]"
        return enc(value)
    return block(doc, 0)


def write_text_atomic(path, text: str, what: str = "output") -> None:
    """Write text to path by the output rules of vampc.outputs (temporary file, then rename; no
    partial files; symlinks written through; devices written as streams)."""
    from vampc.outputs import PlannedOutput, output_for, write_output
    write_output(path if isinstance(path, PlannedOutput) else output_for(path), text, what)


@gc_paused()
def write_program(doc: dict | str, path) -> None:
    """Stamp the checksum and write the document atomically, laid out by `layout`. `doc` is a document
    or its text as layout made it (vampc.program.document.program_text): either way it is serialised
    once, and the checksum is taken over that text with its newlines removed, which is the canonical
    JSON. "checksum" sorts before every other key, so it goes first. `path` is a path or a planned
    vampc.outputs.PlannedOutput."""
    if isinstance(doc, str):
        text = doc
    else:
        body = {k: v for k, v in doc.items() if k != "checksum"}
        if not body or min(body) <= "checksum":
            raise ValueError("a program document's keys must all sort after 'checksum'")
        text = layout(body)
    stamped = '{\n"checksum":' + json.dumps(_digest(text.replace("\n", ""))) + "," + text[1:] + "\n"
    write_text_atomic(path, stamped, "program file")


@gc_paused()
def read_program(path: str | Path) -> dict:
    """Load, schema-validate and checksum-verify a program file; VampcError on any problem."""
    from vampc.textio import decode_utf8
    try:
        raw = Path(path).read_bytes()
    except OSError as exc:
        raise VampcError(f"{path}: cannot read program file: {exc.strerror}") from None
    text = decode_utf8(raw, path, "program file")
    try:
        doc = json.loads(text, parse_constant=_reject_constant)
    except RecursionError:
        raise VampcError(f"{path}: not a vampc program file (JSON nested too deeply)") from None
    except (json.JSONDecodeError, ValueError) as exc:
        raise VampcError(f"{path}: not a vampc program file (invalid JSON: {exc})") from None
    validate_program(doc, path)
    if doc["checksum"] != _laid_out_digest(text, doc["checksum"]) and doc["checksum"] != checksum(doc):
        raise VampcError(f"{path}: checksum mismatch: the file was modified or damaged")
    return doc


def _laid_out_digest(text: str, stored: str) -> str | None:
    """The checksum of a file as write_program lays it out, taken from its text (its newlines
    removed, it is the canonical JSON the checksum covers), which spares encoding a big document
    again; None for text laid out otherwise (then the document is encoded: `checksum`)."""
    head = '{\n"checksum":' + json.dumps(stored) + ","
    if not text.startswith(head):
        return None
    return _digest(("{" + text[len(head):]).replace("\n", ""))


def validate_program(doc, path) -> None:
    """Schema and version check."""
    from vampc.schemas_util import schema_errors
    if not isinstance(doc, dict) or doc.get("format") != FORMAT:
        raise VampcError(f"{path}: not a vampc program file (format is not {FORMAT!r})")
    if doc.get("version") == 1:
        raise VampcError(f"{path}: program format version 1 (one op per VAMP) is not read by this "
                         f"vampc, which writes version {VERSION} (VAMPs with slots); recompile the "
                         "robot with `vampc compile`")
    if doc.get("version") != VERSION:
        raise VampcError(f"{path}: program format version {doc.get('version')!r} is not supported "
                         f"(this vampc reads version {VERSION})")
    errors = schema_errors("program.schema.json", doc)
    if errors:
        err = errors[0]
        where = "".join(f"[{p}]" if isinstance(p, int) else f".{p}" for p in err.path).lstrip(".")
        message = err.message
        if len(message) > 300:   # the validator quotes whole values
            message = message[:297] + "..."
        raise VampcError(f"{path}: {where or 'document'}: {message}")


def _reject_constant(name: str):
    raise ValueError(f"{name} is not allowed")


def tolist(x) -> list:
    """numpy array (or nested sequence) to plain lists of floats."""
    return np.asarray(x, dtype=float).tolist()
