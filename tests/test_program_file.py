"""Program words (vampc.program.words), numbering and stream (vampc.program.emit), the program file
(vampc.program.file) and its document (vampc.program.document).

The packing under test is the one documented in words.py: a compact word (scalar 1 the VAMP number,
scalar 2 delay-A·4096 + delay-B, scalar 3 delay-R·4096 + ROM pointer) and extended words (-number,
slot·8 + field, value) for further slots, selects and long delays.
"""
from __future__ import annotations

import dataclasses
import gzip
import json
import os
import re
from pathlib import Path

import msgspec
import numpy as np
import pytest
from click.testing import CliRunner
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from json_mutation import json_values

from vampc.cli import main
from vampc.compiler import CompileOptions, compile_chain, program_document, program_text
from vampc.errors import VampcError
from vampc.machine.ops import Op
from vampc.network.model import Tap
from vampc.program import document, emit
from vampc.program.file import (
    canonical,
    checksum,
    layout,
    read_program,
    read_program_file,
    write_program,
)
from vampc.program.words import (
    FIELD,
    FIELDS,
    ROM,
    Program,
    apply_word,
    decode,
    encode,
    programs_of,
    rom_pointer,
    vamp_words,
)
from vampc.robot.random import random_chain

# Hypothesis's default deadline (200 ms an example) and its too_slow health check (1 s to draw
# the first examples) time the machine, not the code: a stall of the process, or a loaded
# machine, fails a run whose examples all pass. What each test checks is unchanged.
UNTIMED = settings(deadline=None, suppress_health_check=[HealthCheck.too_slow])

fields = st.integers(0, FIELD - 1)
programs = st.builds(Program, fields, fields, fields, fields)


@pytest.fixture(scope="module")
def compiled():
    return compile_chain(random_chain(3, 5, prismatic_fraction=0.34))


@pytest.fixture
def program_path(compiled, tmp_path):
    path = tmp_path / "arm.vamp.json"
    write_program(program_document(compiled), path)
    return path


def rewrite(path, edit, restamp: bool = True):
    """Load a program file, apply `edit` to the document, write it back (checksum re-stamped)."""
    doc = json.loads(path.read_text())
    edit(doc)
    if restamp:
        doc["checksum"] = checksum(doc)
    path.write_text(json.dumps(doc))


# --- words ---------------------------------------------------------------------------------------------

def test_word_packing_is_the_documented_one():
    assert encode(7, Program(1, 2, 3, 4)) == (7.0, 1 * 4096 + 2, 3 * 4096 + 4)
    assert decode((7.0, 4098.0, 12292.0)) == (7, Program(1, 2, 3, 4))


@UNTIMED
@given(number=st.integers(1, 2**24 - 1), prog=programs)
def test_words_roundtrip_and_are_exact_in_binary32(number, prog):
    word = encode(number, prog)
    assert decode(word) == (number, prog)
    assert all(float(np.float32(x)) == x and 0 <= x < 2**24 for x in word)


@pytest.mark.parametrize("field", ["delay_a", "delay_b", "delay_r", "rom"])
@pytest.mark.parametrize("value", [-1, FIELD])
def test_field_out_of_range_is_refused(field, value):
    prog = Program(**dict(dict.fromkeys(("delay_a", "delay_b", "delay_r", "rom"), 0), **{field: value}))
    with pytest.raises(VampcError, match=rf"^VAMP 9: {field} {value} does not fit in a word$"):
        encode(9, prog)


slot_programs = st.builds(Program, st.integers(0, 2**24 - 1), st.integers(0, 2**24 - 1),
                          st.integers(0, 2**24 - 1), st.integers(0, len(ROM) - 1),
                          st.integers(0, 100), st.integers(0, 100))


@UNTIMED
@given(number=st.integers(1, 2**24 - 1), slots=st.lists(slot_programs, min_size=1, max_size=5))
def test_slot_words_rebuild_the_table_and_are_exact(number, slots):
    table = None
    for word in vamp_words(number, tuple(slots)):
        assert all(float(np.float32(x)) == x and abs(x) < 2**24 for x in word)
        assert abs(word[0]) == number
        table = apply_word(table, word)
    assert programs_of(table) == tuple(slots)


def test_a_systolic_vamp_gets_one_compact_word():
    assert vamp_words(5, (Program(1, 2, 3, 4),)) == [encode(5, Program(1, 2, 3, 4))]
    words = vamp_words(5, (Program(1, 2, 3, 4, 1, 0),))
    assert words == [encode(5, Program(1, 2, 3, 4)), (-5.0, 4.0, 1.0)]   # sel-A of slot 0


def test_a_compact_word_resets_the_table():
    table = apply_word([[9] * 6, [8] * 6], encode(3, Program(1, 2, 3, 4)))
    assert programs_of(table) == (Program(1, 2, 3, 4, 0, 0),)


def test_rom_pointers_are_distinct_and_fit():
    keys = [(op, None) for op in Op if op.is_compute and op is not Op.MM] + [(Op.MM, c) for c in range(3)]
    pointers = [rom_pointer(op, col) for op, col in keys]
    assert sorted(pointers) == list(range(len(ROM)))
    assert all(ROM[p] == k for p, k in zip(pointers, keys))


# --- numbering and stream ------------------------------------------------------------------------------

def test_default_numbering_is_one_to_v(compiled):
    assert compiled.numbering == tuple(range(1, len(compiled.network.vamps) + 1))


def test_numbering_file_sets_the_burned_in_numbers(tmp_path):
    chain = random_chain(1, 2, prismatic_fraction=0.0)
    count = len(compile_chain(chain).network.vamps)
    path = tmp_path / "numbers.txt"
    path.write_text("# burned in\n" + "\n".join(str(1000 + 3 * k) for k in range(count)) + "\n\n")
    c = compile_chain(chain, CompileOptions(numbering=str(path)))
    assert c.numbering == tuple(1000 + 3 * k for k in range(count))
    doc = program_document(c)
    assert [v["number"] for v in doc["network"]["vamps"]] == list(c.numbering)
    words = {t: w for e in doc["program_stream"] for t, w in zip(e["targets"], e["words"])}
    assert [words[v][0] for v in range(count)] == [float(x) for x in c.numbering]


@pytest.mark.parametrize("text,message", [
    ("1\n2\n\n2\n", "line 4: VAMP number 2 appears twice (first on line 2)"),
    # digits of other scripts: '٣' is a digit to str.isdigit() (read as 3), '²' too (int() raised)
    ("1\n2\n٣\n", "line 3: '٣' is not a VAMP number (1..16777215)"),
    ("1\n2\n²\n", "line 3: '²' is not a VAMP number (1..16777215)"),
    ("1\n2\n", "2 VAMP numbers given, the network needs 3"),
    ("1\nabc\n3\n", "line 2: 'abc' is not a VAMP number (1..16777215)"),
    ("1\n2.5\n3\n", "line 2: '2.5' is not a VAMP number (1..16777215)"),
    ("0\n1\n2\n", "line 1: '0' is not a VAMP number (1..16777215)"),
    ("1\n2\n16777216\n", "line 3: '16777216' is not a VAMP number (1..16777215)"),
])
def test_numbering_file_errors(tmp_path, text, message):
    path = tmp_path / "numbers.txt"
    path.write_text(text)
    with pytest.raises(VampcError) as err:
        emit.read_numbering(path, 3)
    assert str(err.value) == f"{path}: {message}"


def test_missing_numbering_file(tmp_path):
    with pytest.raises(VampcError, match=r"^.*nope\.txt: cannot read numbering file: No such file"):
        emit.read_numbering(tmp_path / "nope.txt", 3)


def a_depth(net, vamp: int) -> tuple[tuple[str, int], int]:
    """Root input buffer and register count of a VAMP's Operand-A path (Program Mode: a VAMP passes
    Operand A to its Result one tick later; a buffer stage adds one tick)."""
    tap, depth = net.vamps[vamp].a[0].taps[0], 0
    while tap.kind in ("vamp", "buffer"):
        src = tap.index if tap.kind == "vamp" else net.buffers[tap.index].source
        depth += 1 + (tap.stage if tap.kind == "buffer" else 0)
        tap = net.vamps[src].a[0].taps[0]
    return (tap.kind, tap.index), depth


@pytest.mark.parametrize("layout", ["systolic", "folded"])
def test_stream_reaches_every_vamp_deepest_first(compiled, layout):
    if layout != "systolic":
        compiled = compile_chain(compiled.chain, CompileOptions(layout=layout))
    net, stream = compiled.network, compiled.stream
    targets = [v for e in stream for v in e.targets]
    assert sorted(set(targets)) == list(range(len(net.vamps)))
    for e in stream:
        assert e.root.kind in ("port", "const")
        assert list(e.depth) == sorted(e.depth, reverse=True)
        for v, d in zip(e.targets, e.depth):
            assert a_depth(net, v) == ((e.root.kind, e.root.index), d)
    assert emit.load_ticks(stream) == max(k + d + 1 for e in stream for k, d in enumerate(e.depth))


@pytest.mark.parametrize("recursion", ["linear", "log"])
@pytest.mark.parametrize("layout", ["systolic", "folded"])
def test_a_roots_are_those_of_a_walk_along_each_path(recursion, layout):
    """a_roots walks each path once and reuses roots found before; a plain walk per VAMP agrees."""
    net = compile_chain(random_chain(6, 3), CompileOptions(recursion=recursion,
                                                           layout=layout)).network
    roots, depths = emit.a_roots(net)
    assert len(roots) == len(depths) == len(net.vamps)
    for v, found in enumerate(zip(roots, depths)):
        assert found == (Tap(*a_depth(net, v)[0]), a_depth(net, v)[1])


@pytest.mark.parametrize("layout", ["systolic", "folded"])
def test_programs_are_period_relative(compiled, layout):
    if layout != "systolic":
        compiled = compile_chain(compiled.chain, CompileOptions(layout=layout))
    P = compiled.network.period
    for v, progs in zip(compiled.network.vamps, compiled.programs):
        assert len(progs) == len(v.slots)
        for s, p in zip(v.slots, progs):
            assert (p.delay_a, p.delay_b, p.delay_r) == (s.latch_a % P, s.latch_b % P, s.dump % P)
            assert ROM[p.rom] == (s.op, s.column) and (p.sel_a, p.sel_b) == (s.sel_a, s.sel_b)


@pytest.mark.parametrize("layout", ["systolic", "folded", "k-vamp"])
def test_programs_section_text_is_each_row_encoded_alone(compiled, layout, monkeypatch):
    """The programs section's rows, written from each one-slot listing's text with its node and
    VAMP put in, are the bytes of each row's Struct encoded on its own (a folded network's
    several-slot VAMPs among them), and so are the rows when no text may be kept."""
    options = {"systolic": CompileOptions(), "folded": CompileOptions(layout="folded"),
               "k-vamp": CompileOptions(vamps=7)}[layout]
    c = compiled if layout == "systolic" else compile_chain(compiled.chain, options)
    net, progs = c.network, c.programs
    want = b"".join(msgspec.json.encode(
        msgspec.structs.asdict(document.F.ProgramDoc(v.index, [
            document.F.SlotDoc(s.node, s.op.value, p.delay_a, p.delay_b, p.delay_r, p.rom,
                               p.sel_a, p.sel_b) for s, p in zip(v.slots, ps)])),
        order="sorted") + b"\n" for v, ps in zip(net.vamps, progs))
    several = sum(len(v.slots) > 1 for v in net.vamps)
    assert (several > 0) == (layout != "systolic")
    kept_at_most = document.TEMPLATES
    for kept in (0, kept_at_most):
        monkeypatch.setattr(document, "TEMPLATES", kept)
        rows = document.programs_doc(net, progs)
        assert b"".join(rows.make(lo, min(lo + 5, len(rows))) for lo in range(0, len(rows), 5)) \
            == want
    # a node that is not a plain int is written by the encoder, as its Struct is (True as true;
    # a NumPy integer refused), not by a template's %d (a review's find)
    v = next((v for v in net.vamps if len(v.slots) == 1), None)
    if v is not None:
        for node, written in ((True, b'"node":true'), (np.int64(v.slots[0].node), None)):
            odd = msgspec.structs.replace(v, slots=(msgspec.structs.replace(v.slots[0], node=node),))
            vamps = net.vamps[:v.index] + (odd,) + net.vamps[v.index + 1:]
            rows = document.programs_doc(dataclasses.replace(net, vamps=vamps), progs)
            if written is None:
                with pytest.raises(TypeError):
                    rows.make(v.index, v.index + 1)
            else:
                assert written in rows.make(v.index, v.index + 1)


# --- the program file ----------------------------------------------------------------------------------

def test_program_file_roundtrip(compiled, program_path):
    doc = read_program(program_path)
    assert doc == dict(program_document(compiled), checksum=doc["checksum"])
    assert doc["checksum"] == checksum(doc)
    typed = read_program_file(program_path)
    assert json.loads(json.dumps(msgspec.to_builtins(typed))) == doc   # the Structs hold it all
    assert document.graph_from_doc(typed.graph) == compiled.graph
    chain = document.chain_from_doc(typed.robot)
    for a, b in zip(chain.joints, compiled.chain.joints):
        assert (a.name, a.type, a.offset, a.mass) == (b.name, b.type, b.offset, b.mass)
        for f in ("phi", "p_fixed", "com", "inertia"):
            assert np.array_equal(getattr(a, f), getattr(b, f))
    assert document.programs_from_doc(typed) == compiled.programs
    assert document.stream_from_doc(typed) == compiled.stream


def test_written_netlist_is_the_compiled_one(compiled, program_path):
    """The netlist rows are formatted straight from the IR: read back, they give its wiring."""
    net = document.network_from_doc(read_program_file(program_path))
    want = compiled.network
    def wiring(vamps):
        return [(v.index, v.a, v.b, [(s.node, s.op, s.column, s.sel_a, s.sel_b) for s in v.slots])
                for v in vamps]
    assert wiring(net.vamps) == wiring(want.vamps)
    assert (net.buffers, net.ports, net.consts, net.outputs) == \
           (want.buffers, want.ports, want.consts, want.outputs)


@UNTIMED
@given(st.dictionaries(st.text(max_size=6), json_values, max_size=5))
def test_layout_only_adds_newlines_to_the_canonical_json(doc):
    text = layout(doc)
    assert text.replace("\n", "") == canonical(doc)
    assert json.loads(text) == doc


@UNTIMED
@given(st.dictionaries(st.text(max_size=6), json_values, max_size=5))
def test_canonical_json_is_what_the_standard_library_writes(doc):
    """The encoder (msgspec, floats written as Python's repr, non-ASCII escaped) writes exactly the
    text Python's json module writes with sorted keys and no spaces: program files keep their bytes."""
    want = json.dumps(doc, sort_keys=True, separators=(",", ":"), allow_nan=False)
    assert canonical(doc) == want


def test_canonical_json_escapes_as_the_standard_library():
    doc = {"name": "J\u00e9r\u00f4me \u2028 \U0001f916 \x7f \x1f \\ \"", "x": [1e-05, 1e16, -0.0, 5e-324]}
    assert canonical(doc) == json.dumps(doc, sort_keys=True, separators=(",", ":"))


def test_non_finite_numbers_are_refused_not_written():
    with pytest.raises(ValueError):
        canonical({"x": [1.0, float("nan")]})
    with pytest.raises(ValueError):
        canonical({"x": float("inf")})


@pytest.mark.parametrize("recursion", ["linear", "log"])
def test_rows_formatted_from_the_irs_are_what_json_writes(recursion):
    """program_text formats its big sections itself (a row per node, VAMP, buffer, program, stream
    entry); the text must be exactly what the generic JSON layout makes of the parsed document."""
    c = compile_chain(random_chain(5, 11, prismatic_fraction=0.4), CompileOptions(recursion=recursion))
    text = program_text(c)
    assert text == layout(json.loads(text))
    lines = text.splitlines()
    assert sum(line.startswith('{"a":') for line in lines) == len(c.network.vamps)
    assert sum(line.startswith('{"slots":') for line in lines) == len(c.network.vamps)
    assert sum(line.startswith('{"args":') for line in lines) == len(c.graph.nodes)


def test_the_text_made_in_small_pieces_is_the_same(monkeypatch, tmp_path):
    """program_chunks makes its big sections a batch of rows at a time (Rows) and write_program
    streams the pieces, hashing as they pass: with batches of 3 rows, every way of writing gives
    the text of the whole document laid out at once, checksum included."""
    import vampc.program.file as program_file
    from vampc.compiler import program_chunks
    c = compile_chain(random_chain(4, 7, prismatic_fraction=0.3), CompileOptions(recursion="log"))
    whole = layout(program_document(c))
    monkeypatch.setattr(program_file, "ROW_BATCH", 3)
    pieces = list(program_chunks(c))
    assert len(pieces) > len(c.network.vamps) // 3 > 10        # batches of 3 rows, not a section each
    assert b"".join(pieces).decode() == whole == layout(json.loads(whole))
    doc = json.loads(whole)
    want = '{\n"checksum":"' + checksum(doc) + '",' + whole[1:] + "\n"
    for name, source in [("a.vamp.json", program_chunks(c)), ("b.vamp.json", whole),
                         ("c.vamp.json", doc), ("d.vamp.json.gz", program_chunks(c))]:
        write_program(source, tmp_path / name)
        raw = (tmp_path / name).read_bytes()
        assert (gzip.decompress(raw) if name.endswith(".gz") else raw).decode() == want, name
    assert read_program(tmp_path / "d.vamp.json.gz") == doc | {"checksum": checksum(doc)}


def test_written_file_is_canonical_json_one_row_per_line(compiled, program_path):
    text = program_path.read_text()
    doc = json.loads(text)
    assert text.replace("\n", "") == canonical(doc)
    assert text.splitlines()[1] == f'"checksum":"{checksum(doc)}",'
    assert sum(line.startswith('{"a":') for line in text.splitlines()) == len(compiled.network.vamps)


PLANAR = program_document(compile_chain(random_chain(2, 4, prismatic_fraction=0.5),
                                        CompileOptions(recursion="log")))
PLANAR["checksum"] = checksum(PLANAR)


def test_written_words_decode_to_the_programs(program_path):
    doc = read_program(program_path)
    tables: dict = {}
    for e in doc["program_stream"]:
        for v, word in zip(e["targets"], e["words"]):
            assert abs(word[0]) == doc["network"]["vamps"][v]["number"]
            tables[v] = apply_word(tables.get(v), word)
    for row in doc["programs"]:
        assert programs_of(tables[row["vamp"]]) == tuple(
            Program(*(s[f] for f in FIELDS)) for s in row["slots"])


def test_a_file_laid_out_otherwise_still_verifies(program_path, tmp_path):
    # The checksum is read off the text as vampc lays it out; any other layout of the same JSON
    # (pretty-printed, CRLF) is checked by encoding the document again.
    doc = json.loads(program_path.read_text())
    other = tmp_path / "pretty.vamp.json"
    other.write_text(json.dumps(doc, indent=2).replace("\n", "\r\n"))
    assert read_program(other) == doc


@pytest.mark.parametrize("layout", ["vampc's", "pretty"])
def test_a_key_put_in_twice_is_an_edit(program_path, tmp_path, layout):
    """A key put in before its own ("load_ticks": 99, "load_ticks": 13) left the document the same,
    its last value winning, so the checksum of the document matched and the edit passed unseen
    (an audit's find); it is refused, naming the line."""
    text = program_path.read_text()
    if layout == "pretty":
        text = json.dumps(json.loads(text), indent=1)
    m = re.search(r'"load_ticks": ?(\d+)', text)
    assert m
    edited = text[:m.start()] + '"load_ticks": 99, ' + text[m.start():]
    line = text.count("\n", 0, m.start()) + 1
    assert json.loads(edited) == json.loads(text)            # the same document
    path = tmp_path / "dup.vamp.json"
    path.write_text(edited)
    r = CliRunner().invoke(main, ["emulate", str(path), "--random", "2"])
    assert r.exit_code == 1 and r.stderr == (
        f"vampc: error: {path}: line {line}: duplicate key 'load_ticks': the file was edited (vampc "
        "writes each key once); recompile it (vampc compile)\n"), r.output


def test_flipped_byte_fails_the_checksum_with_exit_1(program_path):
    data = bytearray(program_path.read_bytes())
    at = data.index(b"<random>") + 1
    data[at] ^= 0x20                                   # 'r' -> 'R': still valid JSON and schema
    program_path.write_bytes(bytes(data))
    with pytest.raises(VampcError) as err:
        read_program(program_path)
    assert str(err.value) == f"{program_path}: checksum mismatch: the file was modified or damaged; " \
        "recompile it (vampc compile)"
    result = CliRunner().invoke(main, ["report", str(program_path)])
    assert result.exit_code == 1
    assert result.stderr == f"vampc: error: {err.value}\n"


@pytest.mark.parametrize("edit,message", [
    (lambda d: d["programs"][0]["slots"][0].pop("delay_a"),
     "programs[0].slots[0]: object missing required field `delay_a`"),
    (lambda d: d["network"].__setitem__("period", 0), "network.period: expected `int` >= 1"),
    (lambda d: d["network"]["vamps"][1].__setitem__("number", "7"), "network.vamps[1].number: expected `int`, got `str`"),
    (lambda d: d.pop("io"), "document: object missing required field `io`"),
])
def test_schema_violations_are_named(program_path, edit, message):
    rewrite(program_path, edit)
    with pytest.raises(VampcError) as err:
        read_program(program_path)
    assert str(err.value) == f"{program_path}: {message}"


def test_wrong_version(program_path):
    rewrite(program_path, lambda d: d.__setitem__("version", 3))
    with pytest.raises(VampcError) as err:
        read_program(program_path)
    assert str(err.value) == (f"{program_path}: program format version 3 is not supported "
                              "(this vampc reads version 2)")


@pytest.mark.parametrize("version, said", [("2", "str '2'"), (2.0, "float 2.0")])
def test_a_version_written_as_a_string_is_said_so(program_path, version, said):
    """"version": "2" was said as "version '2' is not supported (this vampc reads version 2)" (a new
    user's find)."""
    rewrite(program_path, lambda d: d.__setitem__("version", version))
    with pytest.raises(VampcError) as err:
        read_program(program_path)
    assert str(err.value) == f'{program_path}: "version" must be the number 2, not {said} (was it edited?)'


def test_a_robot_file_named_as_a_program_says_what_it_looks_like(tmp_path):
    """A DH table named *.vamp.json was "invalid JSON: invalid character (line 1, column 1)"."""
    path = tmp_path / "arm.vamp.json"
    path.write_text((Path(__file__).parent.parent / "examples" / "planar2.yaml").read_text())
    with pytest.raises(VampcError) as err:
        read_program(path)
    assert str(err.value) == f"{path}: not a vampc program file (it looks like YAML (a DH table?))"


def test_a_damaged_compact_program_is_said_to_be_invalid_json_not_compressed(tmp_path):
    """A .vamp.json.gz whose JSON is damaged was told to be decompressed first (a review's find on
    the what-it-looks-like message): vampc decompresses it itself."""
    path = tmp_path / "bad.vamp.json.gz"
    path.write_bytes(gzip.compress(b'{"version": 2, "kind": x}\n'))
    with pytest.raises(VampcError) as err:
        read_program(path)
    assert str(err.value) == f"{path}: not a vampc program file (invalid JSON: invalid character " \
        "(line 1, column 24))"


def test_version_1_says_to_recompile(program_path):
    rewrite(program_path, lambda d: d.__setitem__("version", 1))
    with pytest.raises(VampcError) as err:
        read_program(program_path)
    assert str(err.value) == (f"{program_path}: program format version 1 (one op per VAMP) is not "
                              "read by this vampc, which writes version 2 (VAMPs with slots); "
                              "recompile the robot with `vampc compile`")


def test_wrong_format(program_path):
    rewrite(program_path, lambda d: d.__setitem__("format", "something-else"))
    with pytest.raises(VampcError) as err:
        read_program(program_path)
    assert str(err.value) == f"{program_path}: not a vampc program file (format is not 'vampc-program')"


@pytest.mark.parametrize("text", ["{not json", "[1, 2", "\x00\x01"])
def test_not_json(tmp_path, text):
    path = tmp_path / "bad.vamp.json"
    path.write_text(text)
    with pytest.raises(VampcError, match=rf"^{path}: not a vampc program file \(invalid JSON: .*\)$"):
        read_program(path)


@pytest.mark.parametrize("text", ["", "\n  \n"])
def test_an_empty_file_is_called_empty(tmp_path, text):
    path = tmp_path / "empty.vamp.json"
    path.write_text(text)
    with pytest.raises(VampcError, match=rf"^{path}: empty file, not a vampc program file \(vampc "
                                         r"compile writes one\)$"):
        read_program(path)


def test_a_compressed_file_of_nothing_is_called_so(tmp_path):
    """A gzip of nothing was called an 'empty file' (its 20 bytes are not empty)."""
    import gzip
    path = tmp_path / "empty.vamp.json.gz"
    path.write_bytes(gzip.compress(b""))
    with pytest.raises(VampcError, match=rf"^{path}: compressed file holding nothing, not a vampc "
                                         r"program file \(vampc compile writes one\)$"):
        read_program(path)


@pytest.mark.parametrize("constant", ["NaN", "Infinity", "-Infinity"])
def test_nan_in_a_file_is_refused(program_path, constant):
    text = program_path.read_text()
    start = text.index('"gravity":[') + len('"gravity":[')
    end = text.index(",", start)
    program_path.write_text(text[:start] + constant + text[end:])
    with pytest.raises(VampcError, match=rf"^{program_path}: not a vampc program file \(invalid JSON: "
                                         rf"{constant} is not allowed"):
        read_program(program_path)


def test_nan_is_never_written(compiled, tmp_path):
    doc = program_document(compiled)
    doc["robot"]["gravity"] = [0.0, float("nan"), 0.0]
    path = tmp_path / "nan.vamp.json"
    with pytest.raises(ValueError, match="nan is not a JSON number"):
        write_program(doc, path)
    assert list(tmp_path.iterdir()) == []


def test_missing_program_file(tmp_path):
    with pytest.raises(VampcError, match=r"^.*none\.vamp\.json: cannot read program file: No such file"):
        read_program(tmp_path / "none.vamp.json")


class _FailingHandle:
    """Wraps a file handle: writes half of the text, then the disk is full."""

    def __init__(self, handle):
        self.handle = handle

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.handle.close()

    def close(self):
        self.handle.close()

    def write(self, text):
        self.handle.write(text[: len(text) // 2])
        raise OSError(28, "No space left on device")


def test_failed_write_leaves_no_partial_file(compiled, tmp_path, monkeypatch):
    path = tmp_path / "arm.vamp.json"
    write_program(program_document(compiled), path)
    before = path.read_bytes()
    real_fdopen = os.fdopen
    monkeypatch.setattr(os, "fdopen", lambda *a, **k: _FailingHandle(real_fdopen(*a, **k)))
    doc = program_document(compiled)
    doc["robot"]["name"] = "changed"
    with pytest.raises(VampcError) as err:
        write_program(doc, path)
    assert str(err.value) == (f"{path}: cannot write program file: No space left on device (the "
                              "previous file is unchanged)")
    assert path.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["arm.vamp.json"]


def test_failed_rename_leaves_no_temporary_file(compiled, tmp_path, monkeypatch):
    def fail(*args):
        raise OSError(13, "Permission denied")
    monkeypatch.setattr(os, "replace", fail)
    with pytest.raises(VampcError, match=r"cannot write program file: Permission denied$"):
        write_program(program_document(compiled), tmp_path / "arm.vamp.json")
    assert list(tmp_path.iterdir()) == []


def test_written_file_respects_the_umask(compiled, tmp_path):
    old = os.umask(0o027)
    try:
        write_program(program_document(compiled), tmp_path / "arm.vamp.json")
    finally:
        os.umask(old)
    assert (tmp_path / "arm.vamp.json").stat().st_mode & 0o777 == 0o640


def test_a_network_beyond_24_bit_numbers_is_refused():
    from types import SimpleNamespace
    with pytest.raises(VampcError, match=r"^the network needs 16777216 VAMPs, but VAMP numbers have "
                                         r"24 bits \(at most 16777215\)"):
        emit.default_numbering(SimpleNamespace(vamps=range(1 << 24)))


def test_an_edited_robot_section_fails_the_check(program_path):
    """The robot's parameters are baked into the constant buffers: an edited `robot` section (its
    checksum re-stamped) is what --check compares against, so the check fails (README, Program file)."""
    res = CliRunner().invoke(main, ["emulate", str(program_path), "--random", "5", "--check"])
    assert res.exit_code == 0, res.output

    def heavier(doc):
        doc["robot"]["joints"][0]["mass"] *= 1.5

    rewrite(program_path, heavier)
    res = CliRunner().invoke(main, ["emulate", str(program_path), "--random", "5", "--check"])
    assert res.exit_code == 1 and "FAILED" in res.output, res.output


def test_rows_with_weights_batch_by_items(monkeypatch):
    """A weighted Rows (the program stream: a row per input buffer, weighed in words) cuts a batch
    before it would pass ROW_BATCH items; a row heavier than that is a batch of its own."""
    import vampc.program.file as program_file
    monkeypatch.setattr(program_file, "ROW_BATCH", 10)
    weights = [3, 4, 2, 30, 1, 9, 5, 5]
    rows = program_file.Rows(len(weights), lambda lo, hi: list(range(lo, hi)), weights)
    batches = list(rows.batches())
    assert batches == [[0, 1, 2], [3], [4, 5], [6, 7]]
    assert [sum(weights[i] for i in b) for b in batches if len(b) > 1] == [9, 10, 10]
    plain = program_file.Rows(len(weights), lambda lo, hi: list(range(lo, hi)))
    assert list(plain.batches()) == [list(range(8))]


def test_compiled_stream_words_read_as_tuples_of_floats(compiled):
    """A compiled stream's words (emit.Words: one float64 array) read, compare and hash as the tuple
    of (number, field, field) tuples a program file's stream reads back as."""
    from array import array

    import numpy as np
    entry = max(compiled.stream, key=lambda e: len(e.words))
    words = entry.words
    assert isinstance(words, emit.Words) and len(words) >= 2
    plain = tuple(words)
    assert all(type(w) is tuple and len(w) == 3 and all(type(x) is float for x in w) for w in plain)
    assert words == plain and plain == words and hash(words) == hash(plain)
    assert words != plain[:-1] and words != list(plain)
    assert words[-1] == plain[-1] and words[0] == plain[0] and words[1:] == plain[1:]
    with pytest.raises(IndexError):
        words[len(plain)]
    got = np.asarray(words, dtype=np.float64)
    assert got.shape == (len(plain), 3) and got.tolist() == [list(w) for w in plain]
    assert emit.Words(array("d", [1.0, 2.0, 3.0])) == ((1.0, 2.0, 3.0),)
    import pickle
    for protocol in range(pickle.HIGHEST_PROTOCOL + 1):
        assert pickle.loads(pickle.dumps(entry, protocol)) == entry


@settings(max_examples=60, deadline=None)
@given(sizes=st.lists(st.integers(0, 40), max_size=30), least=st.integers(1, 30))
def test_the_writers_runs_are_its_pieces_joined_in_order(sizes, least):
    """The program writer hands its thread runs of pieces (vampc.program.file._runs): the same
    bytes in order, none empty; a piece of `least` bytes or more alone and not copied; every other
    run at least `least` bytes, but the last and one cut short by such a piece."""
    from vampc.program.file import _runs
    pieces = [bytes([65 + k % 26]) * n for k, n in enumerate(sizes)]
    runs = list(_runs(iter(pieces), least))
    assert b"".join(runs) == b"".join(pieces)
    assert all(runs)
    big = [piece for piece in pieces if len(piece) >= least]
    assert [r for r in runs if len(r) >= least and any(r is p for p in big)] == big
    for k, r in enumerate(runs[:-1]):
        assert len(r) >= least or any(runs[k + 1] is p for p in big), (k, runs)


def test_a_dh_table_named_like_a_program_says_what_it_is(tmp_path):
    """`vampc compile arm.vamp.json` took a DH table so named (by its .json); emulate, report and
    lookahead said only "format is not 'vampc-program'" (a new user's find): they say it looks like a
    DH table and how to name it."""
    import yaml
    table = yaml.safe_load(Path("examples/planar2.yaml").read_text())
    path = tmp_path / "arm.vamp.json"
    path.write_text(json.dumps(table))
    said = (f"vampc: error: {path}: not a vampc program file (it looks like a DH table in JSON: named "
            ".vamp.json, it is taken for a program file; name it .json and it compiles on the fly)\n")
    for args in (["emulate", str(path), "--random", "2"], ["report", str(path)],
                 ["lookahead", str(path), "--trajectory", "examples/puma560-path.csv", "--rate", "1kHz",
                  "--window", "8"]):
        r = CliRunner().invoke(main, args)
        assert (r.exit_code, r.stderr) == (1, said), (args, r.output)
    # and compile, which had compiled it (writing arm.vamp.vamp.json: a new user's find), refuses
    # it too, writing nothing
    r = CliRunner().invoke(main, ["compile", str(path), "-o", str(tmp_path / "out.vamp.json")])
    assert (r.exit_code, r.stderr) == (1, f"vampc: error: {path}: named .vamp.json, it is taken for "
                                          "a program file (as emulate, precision, report and "
                                          "lookahead take it); a DH table in JSON is named .json\n")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["arm.vamp.json"]
    renamed = tmp_path / "arm.json"                 # as the message says
    renamed.write_text(path.read_text())
    assert CliRunner().invoke(main, ["emulate", str(renamed), "--random", "2", "--check"]).exit_code == 0



@pytest.mark.parametrize("options", [dict(layout="folded"), dict(vamps=20),
                                     dict(layout="folded", bus="mlb"),
                                     dict(recursion="log", layout="folded")])
def test_a_select_of_one_input_gets_no_word_and_the_rest_still_program_it(options, monkeypatch):
    """A multiplexer of one input has no select register (README, Layouts; the report and the RTL
    count and build none), so the stream sends it no word: until 2026-12-07 every slot after the
    first got both select words, planar2 folded 210 words in 119 ticks where 171 in 92 do (a hardware
    user's find, the RTL co-simulated without them). Each VAMP's select words are counted here from
    the network alone: one a slot after the first (the first's only where it is not 0) for each
    operand of several inputs."""
    import vampc
    from vampc.emulator.load import loaded_from_compiled
    from vampc.emulator.tick import TickEngine
    chain = vampc.load_robot(str(Path(__file__).parent.parent / "examples" / "planar2.yaml"))
    c = compile_chain(chain, CompileOptions(**options))
    fields: dict[int, list[int]] = {}             # per VAMP, the field each extended word sets
    for e in c.stream:
        for v, word in zip(e.targets, e.words):
            if word[0] < 0:
                fields.setdefault(v, []).append(int(word[1]) % 8)
    assert any(len(v.slots) > 1 and 1 in (len(v.a), len(v.b)) for v in c.network.vamps)
    for v, vamp in enumerate(c.network.vamps):
        first = c.programs[v][0]
        for f, inputs, at_first in ((4, vamp.a, first.sel_a), (5, vamp.b, first.sel_b)):
            want = (len(vamp.slots) - 1 + (at_first != 0)) if len(inputs) > 1 else 0
            assert fields.get(v, []).count(f) == want, (v, FIELDS[f])
    # the programs delivered are the compiled ones, and the tick engine runs them, its power-on
    # select fields random (a multiplexer of one input passes input 0 whatever they hold)
    ld = loaded_from_compiled(c)
    assert ld.programs == c.programs
    engine = TickEngine(ld, seed=3)
    engine.program()
    assert engine.programs() == c.programs      # (it showed the power-on fields of such selects)
    traj = vampc.random_trajectory(chain, 4, 5)
    from vampc.emulator.host import port_values
    np.testing.assert_array_equal(engine.run(port_values(ld, traj), 4), vampc.emulate(ld, traj).tau)
    # a program written before (every select word sent) still loads to the same programs
    old = emit.vamp_words
    monkeypatch.setattr(emit, "vamp_words", lambda n, s, p, inputs: old(n, s, p))
    before = compile_chain(chain, CompileOptions(**options))
    assert sum(len(e.targets) for e in before.stream) > sum(len(e.targets) for e in c.stream)
    assert loaded_from_compiled(before).programs == c.programs
