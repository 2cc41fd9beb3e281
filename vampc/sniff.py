"""What a file looks like, from its first bytes: so a program file given where a robot is expected,
or a robot file with the wrong extension, gets a message that says what it is, not a schema error."""
from __future__ import annotations

import codecs
from pathlib import Path

from vampc.textio import NPY_MAGIC

HEAD = 4096
TABLE_BYTES = 1 << 24      # (a DH table is far smaller: a bigger YAML or JSON is not read as one)
PROGRAM_SUFFIX = ".vamp.json"

# Compressed files by their first bytes (gzip's: vampc reads a program file's compact form)
COMPRESSIONS = ((b"\x1f\x8b", "gzip"), (b"\xfd7zXZ\x00", "xz"), (b"BZh", "bzip2"),
                (b"\x28\xb5\x2f\xfd", "zstd"), (b"7z\xbc\xaf\x27\x1c", "7-zip"),
                (b"\x5d\x00\x00", "lzma"))
OTHER_COMPRESSIONS = tuple(name for _, name in COMPRESSIONS if name != "gzip")   # none read
OTHER_COMPRESSION = ("vampc reads a program file gzip-compressed (.gz) and no other compressed "
                     "file: decompress it first")

DESCRIPTIONS = {"program": "a vampc program file", "urdf": "XML (a URDF)",
                "faults-results": "a results file of vampc faults",
                "svg": "an SVG picture (vampc report's pictures write them)",
                "vcd": "a VCD waveform (vampc emulate --vcd writes them)",
                "gzip": "gzip-compressed data: decompress it first (gunzip)",
                # (a compact program cut inside its gzip header was told to be decompressed, as
                # one cut later was called truncated: a new user's find)
                "gzip-cut": "gzip-compressed data cut short or damaged before any of its content (a "
                            "compact program file, *.vamp.json.gz, truncated?)",
                "json": "JSON (a DH table?)", "yaml": "YAML (a DH table?)",
                "npy": "a NumPy array (.npy: a trajectory or torques?)",
                **{name: f"{name}-compressed data" for name in OTHER_COMPRESSIONS}}


def compression(head: bytes) -> str | None:
    """'gzip', 'xz', 'bzip2', 'zstd', '7-zip' or 'lzma': how a file whose first bytes are `head` is
    compressed (None: it is not, as far as these show; a zip, numpy's .npz, is not listed)."""
    name = next((name for magic, name in COMPRESSIONS if head.startswith(magic)), None)
    if name == "bzip2" and not (head[3:4] in b"123456789" and head[3:4]
                                and head[4:10] in (b"1AY&SY", b"\x17rE8P\x90")):
        return None          # ('BZh' alone may start a text: bzip2's block or end marker follows)
    return name


def sniff(path) -> str | None:
    """"program", "urdf", "json", "yaml", "vcd", "gzip" (compressed, not a program) or "gzip-cut"
    (compressed, no byte of content readable) by content;
    None if unreadable or none of these (the loaders then say what is wrong). Only a regular file is
    looked at: a FIFO's first bytes, once read, are gone, and the loader must read them."""
    try:
        if not Path(path).is_file():
            return None
        with open(path, "rb") as fh:
            head = fh.read(HEAD)
    except OSError:
        return None
    if head.startswith(b"\x1f\x8b"):               # gzip: a compact program file (or nothing we read)
        head, ended = _gunzipped_head(path)
        if not head and not ended:
            return "gzip-cut"
        if not _program_text(head):
            return "gzip"
    elif packed := compression(head):
        return packed                 # (one of OTHER_COMPRESSIONS)
    if head.startswith(codecs.BOM_UTF8):
        head = head[len(codecs.BOM_UTF8):]
    head = head.lstrip()
    if head.startswith(NPY_MAGIC):                  # (a robot file's "not UTF-8 text (byte 0)")
        return "npy"
    if head.startswith(b"<"):
        return "svg" if b"<svg" in head and b"<robot" not in head else "urdf"
    if head.startswith(b"$") and b"$end" in head:    # (a waveform: "YAML (a DH table?)", a new user's)
        return "vcd"
    if head.startswith((b"{", b"[")):
        if head.startswith(b'{"vampc_faults":'):       # (a results file: "JSON (a DH table?)")
            return "faults-results"
        return "program" if _program_text(head) else "json"
    try:
        text = head.decode("utf-8")
    except UnicodeDecodeError:
        return None
    return "yaml" if ":" in text else None


def _yaml_table(path) -> bool:
    """Whether the file reads as YAML to a mapping with joints (a DH table in YAML)."""
    import yaml
    try:
        doc = yaml.load(Path(path).read_text(encoding="utf-8"),
                        Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader))
    except (yaml.YAMLError, OSError, UnicodeDecodeError, RecursionError):
        return False
    return isinstance(doc, dict) and "joints" in doc


def _program_text(head: bytes) -> bool:
    """Whether a text's start is a program file's: its format named, or the checksum line vampc
    writes first (all a compact form's first member holds)."""
    return b'"vampc-program"' in head or head.startswith(b'{\n"checksum":"sha256:')


def is_program(path) -> bool:
    """A program file: named *.vamp.json or *.vamp.json.gz, or a JSON file (gzip-compressed or not)
    whose first bytes say "vampc-program"."""
    return str(path).endswith((PROGRAM_SUFFIX, PROGRAM_SUFFIX + ".gz")) or sniff(path) == "program"


def _gunzipped_head(path) -> tuple[bytes, bool]:
    """The first HEAD bytes of a gzip file's content, as far as they go (b"" if it is not readable
    gzip), and whether a member ended whole. A truncated file still shows its start: reading it
    whole to EOF had called a cut program file "gzip-compressed data" (the reader then says it is
    truncated)."""
    import zlib
    out, ended = b"", False
    try:
        with open(path, "rb") as fh:
            packed = fh.read(1 << 16)
        while packed and len(out) < HEAD:     # member after member (vampc's compact form has two)
            d = zlib.decompressobj(wbits=31)
            out += d.decompress(packed, HEAD - len(out))
            ended = ended or d.eof
            packed = d.unused_data if d.eof else b""
    except (OSError, zlib.error):
        pass
    return out, ended


def vampc_output(doc) -> str | None:
    """What a parsed JSON document is when it is one of vampc's own outputs ('a vampc report (JSON)'),
    by the keys each has; None otherwise. `vampc emulate report.json` said "Additional properties
    are not allowed ('allocation' was unexpected)" (a new user's find)."""
    if not isinstance(doc, dict):
        return None
    for keys, what in ((("report_version", "table_o1"), "a vampc report (vampc report --format json)"),
                       (("campaign", "runs", "summary"), "a vampc faults report (--format json)"),
                       (("vampc_faults",), "the header of a vampc faults results file"),
                       (("rows", "narrowest_bound"), "a vampc precision report (--format json)"),
                       (("robot", "recursion", "points"), "a vampc report --tradeoff (JSON)")):
        if all(k in doc for k in keys):
            return what
    return None


def robot_or_program(path) -> str | None:
    """What a file is when it is a robot description or a program file, the user's work an output
    must not replace ('a URDF', 'an MJCF model', 'a DH table', 'a vampc program file'), by its
    content; None otherwise (a table, a picture, a report, Verilog, a DOT graph...)."""
    kind = sniff(path)
    if kind == "program":
        return DESCRIPTIONS["program"]
    if kind == "urdf":
        with open(path, "rb") as fh:
            head = fh.read(HEAD)
        return "a URDF" if b"<robot" in head else "an MJCF model" if b"<mujoco" in head else None
    if kind in ("yaml", "json") and Path(path).stat().st_size <= TABLE_BYTES and _yaml_table(path):
        # (JSON is YAML: one reader for both; a big text, a report, is no DH table)
        return "a DH table"
    return None


def looks_like(path) -> str:
    """' (it looks like ...)' for a message, or '' when the content says nothing."""
    kind = sniff(path)
    return f" (it looks like {DESCRIPTIONS[kind]})" if kind else ""


def suffix_mismatch(path, expected: str) -> str | None:
    """Why a robot file's content does not match its extension's loader ("urdf" or "dh"), or None."""
    kind = sniff(path)
    if kind == "program":
        return ("this is a vampc program file, not a robot description; use "
                "`vampc emulate` or `vampc report` with it")
    if kind == "gzip":
        return "this is gzip-compressed; decompress it first (gunzip)"
    if kind == "gzip-cut":
        return f"this is {DESCRIPTIONS[kind]}"
    if kind in OTHER_COMPRESSIONS:
        return f"this is {kind}-compressed; decompress it first"
    if kind == "vcd":
        return f"this is {DESCRIPTIONS['vcd']}, not a robot description"
    if kind == "npy":        # (a DH table's "not UTF-8 text (byte 0)", a URDF's "not well-formed")
        return f"this is {DESCRIPTIONS['npy']}, not a robot description"
    if expected == "dh" and str(path).endswith(PROGRAM_SUFFIX):      # (is_program's test)
        # (compile took a DH table so named, writing arm.vamp.vamp.json, where emulate, precision
        # and report refuse it as a program file that is not one: a new user's find)
        return ("named .vamp.json, it is taken for a program file (as emulate, precision, report "
                "and lookahead take it); a DH table in JSON is named .json")
    if expected == "dh" and kind == "urdf":
        return "this is XML (a URDF?), not a DH table; name it .urdf to load it as a URDF"
    if expected == "dh" and kind == "yaml" and Path(path).suffix.lower() == ".json" and \
            _yaml_table(path):
        # (it was "not valid JSON: invalid character (line 1, column 1)" alone: an audit's find;
        # a JSON file with a comment before its table, which YAML does not read either, is left
        # to the JSON reader's message and place: a review's find)
        return "this is YAML, not JSON; a DH table in YAML is named .yaml or .yml"
    if expected == "urdf" and kind in ("json", "yaml"):
        return f"this is {kind.upper()}, not XML; a DH table is named .yaml, .yml or .json"
    return None
