"""The compact program file (issue "Fast at every size", part 2): a name ending in .gz writes the same
text gzip-compressed, and any program file starting with gzip's magic is read back to the same IRs."""
from __future__ import annotations

import gzip

import numpy as np
import pytest
from click.testing import CliRunner

from vampc.cli import main
from vampc.emulator import emulate, load_program
from vampc.emulator.host import random_trajectory
from vampc.errors import VampcError
from vampc.program.file import GZIP_MAGIC, gunzip, read_program_file

PUMA = "examples/puma560.yaml"


@pytest.fixture(scope="module")
def programs(tmp_path_factory):
    folder = tmp_path_factory.mktemp("gz")
    plain, packed = folder / "p.vamp.json", folder / "p.vamp.json.gz"
    for out in (plain, packed):
        r = CliRunner().invoke(main, ["compile", PUMA, "--recursion", "log", "-o", str(out)])
        assert r.exit_code == 0, r.output
    return plain, packed


def test_the_compact_form_is_the_same_text_gzipped(programs):
    plain, packed = programs
    data = packed.read_bytes()
    assert data.startswith(GZIP_MAGIC) and len(data) * 5 < plain.stat().st_size
    assert gzip.decompress(data) == plain.read_bytes()      # Python's gzip, not vampc's reader


def test_it_reads_back_to_the_same_program(programs):
    plain, packed = programs
    assert read_program_file(packed) == read_program_file(plain)
    a, b = load_program(str(plain)), load_program(str(packed))
    traj = random_trajectory(a.chain, 50, 3)
    assert np.array_equal(emulate(a, traj, "stream").tau, emulate(b, traj, "stream").tau)


def test_writing_twice_gives_the_same_bytes(programs, tmp_path):
    again = tmp_path / "again.vamp.json.gz"
    assert CliRunner().invoke(main, ["compile", PUMA, "--recursion", "log", "-o", str(again)]).exit_code == 0
    assert again.read_bytes() == programs[1].read_bytes()      # no timestamp in the header


def test_a_compressed_program_is_known_by_its_content(programs, tmp_path):
    renamed = tmp_path / "whatever.bin"
    renamed.write_bytes(programs[1].read_bytes())
    r = CliRunner().invoke(main, ["emulate", str(renamed), "--random", "5", "--check"])
    assert r.exit_code == 0 and ": OK" in r.output, r.output


def _first_member(data: bytes) -> int:
    """The length of the first gzip member of `data` (the compact form's checksum line)."""
    import zlib
    d = zlib.decompressobj(wbits=31)
    d.decompress(data)
    return len(data) - len(d.unused_data)


@pytest.mark.parametrize("cut, message", [
    (200, "compressed program file is truncated"),
    (None, "damaged compressed program file"),
    # cut between the two members: the gzip is whole, its text short (found by a user trial)
    (_first_member, "compressed program file is truncated (its text ends early")])
def test_a_damaged_compressed_file_is_one_line(programs, tmp_path, cut, message):
    data = programs[1].read_bytes()
    bad = tmp_path / "bad.vamp.json.gz"
    if callable(cut):
        cut = cut(data)
        assert 0 < cut < len(data)
    bad.write_bytes(data[:cut] if cut else data[:10] + bytes(255 - b for b in data[10:]))
    r = CliRunner().invoke(main, ["emulate", str(bad), "--random", "5"])
    assert r.exit_code == 1 and f"{bad}: {message}" in r.output, r.output


@pytest.mark.parametrize("cut", [60, 3000])
def test_a_truncated_compact_form_under_any_name_is_known_as_a_program(programs, tmp_path, cut):
    """Cut within its first member (the checksum line) or its second, a compact program named
    otherwise (t.gz) is still known by its content, and said to be truncated: it was called
    'gzip-compressed data: decompress it first' (the content was read to the end, or only the
    first member was looked at)."""
    bad = tmp_path / "t.gz"
    bad.write_bytes(programs[1].read_bytes()[:cut])
    r = CliRunner().invoke(main, ["emulate", str(bad), "--random", "5"])
    assert r.exit_code == 1 and f"{bad}: compressed program file is truncated" in r.output, r.output


@pytest.mark.parametrize("name", ["t.gz", "t.bin", "t.yaml"])
def test_a_compact_form_cut_inside_its_gzip_header_is_said_to_be_cut(programs, tmp_path, name):
    """Cut before any byte of its content shows (10 bytes, a gzip header), a compact program named
    otherwise was "unknown robot file extension '.gz' (it looks like gzip-compressed data:
    decompress it first (gunzip))", which gunzip cannot (a new user's find)."""
    bad = tmp_path / name
    bad.write_bytes(programs[1].read_bytes()[:10])
    for command in (["emulate", str(bad), "--random", "5"], ["report", str(bad)]):
        r = CliRunner().invoke(main, command)
        assert r.exit_code == 1 and r.stderr.count("\n") == 1, r.output
        assert r.stderr.endswith(f"{bad}: {'this is ' if name == 't.yaml' else ''}gzip-compressed "
                                 "data cut short or damaged before any of its content (a compact "
                                 "program file, *.vamp.json.gz, truncated?)\n"), r.stderr
    whole = tmp_path / "empty.gz"             # a whole gzip file of no text is not cut
    whole.write_bytes(gzip.compress(b""))
    r = CliRunner().invoke(main, ["emulate", str(whole), "--random", "5"])
    assert r.exit_code == 1 and "decompress it first (gunzip)" in r.stderr, r.stderr


def test_a_gzip_bomb_is_refused():
    bomb = gzip.compress(b" " * (3 << 20))
    with pytest.raises(VampcError, match="decompresses to more than"):
        gunzip(bomb, "bomb.vamp.json.gz", limit=1 << 20)
    assert gunzip(bomb, "bomb.vamp.json.gz", limit=4 << 20) == b" " * (3 << 20)


def test_a_bomb_of_whitespace_stops_at_16_mib():
    """Whitespace may lead a program's text, but not 16 MiB of it: a bomb of spaces was read to the
    4 GiB limit (the review of the change that stops other texts at their first chunk)."""
    bomb = gzip.compress(b" " * (40 << 20), 1)
    with pytest.raises(VampcError, match=r"decompressed, its first 16,777,216 bytes are blank"):
        gunzip(bomb, "bomb.vamp.json.gz")


def test_a_big_text_that_is_no_program_is_held_once(tmp_path):
    """64 MB of zeros, gzipped: refused, with the text held once, as it grows (it had been held
    three times over: the pieces, their join and a decoded copy; 1.3 GB for 400 MB)."""
    import tracemalloc
    size = 64 << 20
    path = tmp_path / "zeros.vamp.json.gz"
    path.write_bytes(gzip.compress(bytes(size), 1))
    tracemalloc.start()
    try:
        with pytest.raises(VampcError, match="not a vampc program file"):
            read_program_file(path)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 2 * size, peak / size      # 1.5 times: the text, growing


def test_members_one_after_another_are_one_text(programs, tmp_path):
    """As `cat a.gz b.gz` or bgzip make them (the review found them refused as 'trailing data')."""
    text = programs[0].read_bytes()
    split = tmp_path / "two.vamp.json.gz"
    split.write_bytes(gzip.compress(text[:1000]) + gzip.compress(text[1000:]))
    assert read_program_file(split) == read_program_file(programs[0])


def test_an_upper_case_suffix_compresses_too(tmp_path):
    out = tmp_path / "P.VAMP.JSON.GZ"
    assert CliRunner().invoke(main, ["compile", "examples/planar2.yaml", "-o", str(out)]).exit_code == 0
    assert out.read_bytes().startswith(GZIP_MAGIC)


def test_a_compressed_robot_file_says_so(tmp_path):
    robot = tmp_path / "arm.urdf"
    robot.write_bytes(gzip.compress(open("examples/arm6.urdf", "rb").read()))
    r = CliRunner().invoke(main, ["compile", str(robot)])
    assert r.exit_code == 1 and "arm.urdf: this is gzip-compressed; decompress it first (gunzip)" in r.output


def test_the_compact_form_to_a_file_and_to_a_pipe_is_the_same_and_a_failure_leaves_nothing(
        programs, tmp_path, monkeypatch):
    """The second member waits for the first in memory, past ASIDE_IN_MEMORY bytes in an unnamed
    file beside a regular output (in memory for standard output): the same bytes every way; a run
    that fails while writing leaves the folder as it was, an earlier file unchanged and no
    temporary."""
    import io

    import vampc.compiler
    import vampc.program.file as program_file
    held = tmp_path / "held.vamp.json.gz"
    for how in ("pipe", "spilled"):
        with monkeypatch.context() as m:
            if how == "pipe":                   # the member held in memory
                m.setattr(program_file, "_aside", lambda out: io.BytesIO())
            else:                               # past a few bytes, on disk
                m.setattr(program_file, "ASIDE_IN_MEMORY", 100)
            assert CliRunner().invoke(main, ["compile", PUMA, "--recursion", "log", "-o",
                                             str(held)]).exit_code == 0
        assert held.read_bytes() == programs[1].read_bytes(), how
        held.unlink()
    out = tmp_path / "kept.vamp.json.gz"
    out.write_bytes(b"earlier")
    real = vampc.compiler.program_chunks

    def failing(c):
        for k, piece in enumerate(real(c)):
            if k == 40:
                raise OSError(28, "No space left on device")
            yield piece
    monkeypatch.setattr(vampc.compiler, "program_chunks", failing)
    r = CliRunner().invoke(main, ["compile", PUMA, "--recursion", "log", "-o", str(out)])
    assert r.exit_code == 1 and "No space left on device" in r.output
    assert out.read_bytes() == b"earlier" and [p.name for p in tmp_path.iterdir()] == [out.name]


@pytest.mark.parametrize("kind, starts", [("zeros", r"b'\\x00"), ("array", r"b'\[1, 2\]")],
                         ids=["zeros", "array"])
def test_a_text_that_cannot_be_a_program_stops_at_its_first_chunk(kind, starts):
    """A program file is a JSON object: text that comes, past whitespace, to anything but '{' is
    refused as its first 16 MiB come out. A 4.5 GB bomb of zeros (20 MB gzipped) was decompressed to
    the 4 GiB limit, 4.3 GB of memory and 11 s, before its refusal (a new user's run)."""
    import tracemalloc
    bomb = gzip.compress(bytes(64 << 20) if kind == "zeros" else b"\n [1, 2]" * 10, 1)
    tracemalloc.start()
    try:
        with pytest.raises(VampcError, match=f"decompressed, it is not a vampc program file .*starts {starts}"):
            gunzip(bomb, "b.vamp.json.gz")
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 40 << 20, peak


def test_a_byte_order_mark_and_whitespace_may_lead_a_compressed_program(programs, tmp_path):
    text = programs[0].read_bytes()
    led = tmp_path / "led.vamp.json.gz"
    led.write_bytes(gzip.compress(b"\xef\xbb\xbf" + b" \n" * 10 + text))
    assert gunzip(led.read_bytes(), led).endswith(text)
