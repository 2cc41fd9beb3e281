"""The emulator's file I/O at speed (issue "Fast at every size", part 3): the native CSV writer and
the threaded native reader give exactly what Python's formatting and parsing give, and `-o NAME.npy`
writes the torques as a NumPy array equal to the CSV's."""
from __future__ import annotations

import numpy as np
import pytest
from click.testing import CliRunner

from vampc.cli import main
from vampc.emulator import native
from vampc.emulator.trajectory import NATIVE_CELLS, format_rows

pytestmark = pytest.mark.skipif(native.compiler() is None, reason="no C compiler")


def python_rows(data: np.ndarray) -> str:
    """What format_rows wrote before the native writer, independent of it: '%.17g' per cell."""
    return "".join(",".join("%.17g" % x for x in row) + "\n" for row in data)


def test_the_native_writer_writes_what_python_writes():
    rng = np.random.default_rng(7)
    data = rng.normal(size=(NATIVE_CELLS // 4 + 3, 4)) * 10.0 ** rng.integers(-15, 15, (NATIVE_CELLS // 4 + 3, 4))
    data[0] = [0.0, -0.0, 0.1, 2.5]
    data[1] = [1e-5, 123456789012345678.0, 9007199254740993.0, -1.0000000000000002]
    text = native.format_csv(data)
    assert text is not None and text == python_rows(data)
    assert format_rows(data) == text


def test_the_native_writer_rounds_every_double_as_python_does():
    """The writer's own 17 digits (exact 128-bit integers, sprintf where they cannot hold them)
    against Python's '%.17g', byte for byte: doubles of random bit patterns and of random
    magnitudes across the range it writes (10^-20 to 10^20), exact halfway cases (a binary fraction
    of 18 significant digits: (2^53 - 1) / 4 is ...47.75, to even ...47.8), integers past 2^53,
    short decimals, and the doubles on both sides of every power of ten, where the exponent and
    the %g style change."""
    rng = np.random.default_rng(17)
    # random mantissa bits under random exponents of the range written (2^-67 < 10^-20, 2^67 > 10^20)
    mantissas = rng.integers(0, 2 ** 52, 400_000, dtype=np.uint64)
    exponents = rng.integers(1023 - 67, 1023 + 67, 400_000).astype(np.uint64)
    patterns = (exponents << np.uint64(52) | mantissas).view(np.float64)
    magnitudes = rng.uniform(1, 10, 200_000) * 10.0 ** rng.integers(-20, 20, 200_000)
    halves = rng.integers(1, 2 ** 53, 50_000) / 2.0 ** rng.integers(1, 70, 50_000)
    tens = 10.0 ** np.arange(-19, 20)
    x = np.concatenate([patterns, magnitudes, halves, (2 ** 53 - 1) / 2.0 ** np.arange(80),
                        rng.integers(2 ** 53, 2 ** 63, 10_000).astype(float),
                        np.round(rng.uniform(-1000, 1000, 50_000), 3), tens,
                        np.nextafter(tens, 0), np.nextafter(tens, np.inf), [0.5, 2.5, 1e17, 5e-5]])
    x = x[np.isfinite(x) & (np.abs(x) < 1e20) & (np.abs(x) >= 1e-20)]
    x = np.concatenate([x, -x])
    x = x[: len(x) // 4 * 4].reshape(-1, 4)
    assert x.size > 1_300_000
    assert native.format_csv(x) == python_rows(x)


def test_far_exponents_are_left_to_python():
    """glibc's exact printf is slow on exponents near ±300: the native writer declines them and
    format_rows still gives Python's text."""
    data = np.full((NATIVE_CELLS, 1), 1e300)
    data[5] = 5e-324
    assert native.format_csv(data) is None
    assert format_rows(data) == python_rows(data)


def test_the_threaded_reader_reads_what_numpy_reads():
    rng = np.random.default_rng(3)
    data = rng.normal(size=(45_001, 3)) * 10.0 ** rng.integers(-8, 8, (45_001, 3))
    body = python_rows(data).encode()
    assert native.workers(45_001) >= 1
    got = native.parse_csv(body, 3)
    assert got is not None and np.array_equal(got, data)
    assert np.array_equal(native.parse_csv(body.rstrip(b"\n"), 3), data)       # no final newline
    assert native.parse_csv(body.replace(b"\n", b"\n\n", 1), 3) is None          # an empty line
    cut = body.index(b"\n", len(body) // 2) + 1           # a two-cell row half-way down
    ragged = body[:cut] + b"1,2\n" + body[cut:]
    assert native.parse_csv(ragged, 3) is None


@pytest.mark.parametrize("robot, extra", [("examples/puma560.yaml", []),
                                          ("examples/planar2.yaml", ["--floating-base"])])
def test_torques_as_npy_equal_the_csv(tmp_path, robot, extra):
    runner = CliRunner()
    program, states = tmp_path / "p.vamp.json", tmp_path / "s.csv"
    assert runner.invoke(main, ["compile", robot, *extra, "-o", str(program)]).exit_code == 0
    r = runner.invoke(main, ["emulate", str(program), "--random", "300", "--save-states", str(states)])
    assert r.exit_code == 0, r.output
    lines = states.read_text().splitlines()              # a t column, carried to both outputs
    states.write_text("t," + lines[0] + "\n" + "".join(f"{k * 0.001!r},{line}\n"
                                                        for k, line in enumerate(lines[1:])))
    for out in ("tau.csv", "tau.npy"):
        r = runner.invoke(main, ["emulate", str(program), "--trajectory", str(states), "-o", str(tmp_path / out)])
        assert r.exit_code == 0, r.output
    want = np.loadtxt(tmp_path / "tau.csv", delimiter=",", skiprows=1)
    got = np.load(tmp_path / "tau.npy")
    assert got.dtype == np.float64 and np.array_equal(got, want)
    # --save-states NAME.npy: the states in the CSV's columns (t first), read back by --trajectory
    r = runner.invoke(main, ["emulate", str(program), "--trajectory", str(states), "--save-states",
                             str(tmp_path / "again.npy"), "-o", str(tmp_path / "tau2.csv")])
    assert r.exit_code == 0, r.output
    saved = np.load(tmp_path / "again.npy")
    assert saved.dtype == np.float64 and np.array_equal(saved, np.loadtxt(states, delimiter=",", skiprows=1))
    r = runner.invoke(main, ["emulate", str(program), "--trajectory", str(tmp_path / "again.npy"), "-o",
                             str(tmp_path / "tau3.csv")])
    assert r.exit_code == 0 and (tmp_path / "tau3.csv").read_text() == (tmp_path / "tau.csv").read_text()


def test_states_saved_as_npy_over_several_chunks(tmp_path, monkeypatch):
    from vampc.emulator import driver
    monkeypatch.setattr(driver, "MAX_CHUNK", 64)                 # 300 states: five chunks
    runner = CliRunner()
    program = tmp_path / "p.vamp.json"
    assert runner.invoke(main, ["compile", "examples/planar2.yaml", "-o", str(program)]).exit_code == 0
    for name in ("s.csv", "s.npy"):
        r = runner.invoke(main, ["emulate", str(program), "--random", "300", "--seed", "4", "--save-states",
                                 str(tmp_path / name)])
        assert r.exit_code == 0, r.output
    assert np.array_equal(np.load(tmp_path / "s.npy"), np.loadtxt(tmp_path / "s.csv", delimiter=",", skiprows=1))


def test_npz_is_not_a_torque_file():
    r = CliRunner().invoke(main, ["emulate", "examples/planar2.yaml", "--random", "3", "-o", "x.npz"])
    assert r.exit_code == 2 and "not .npz" in r.output


def test_non_finite_values_are_left_to_python():
    data = np.zeros((NATIVE_CELLS, 1))
    data[3] = np.nan
    assert native.format_csv(data) is None


def test_a_base_array_for_a_fixed_base_program_is_refused(tmp_path):
    """As the CSV's and .npy's extra columns are: the base's motion is never silently dropped."""
    from vampc.emulator.trajectory import read
    from vampc.errors import VampcError
    path = tmp_path / "b.npz"
    np.savez(path, q=np.zeros((3, 2)), qd=np.zeros((3, 2)), qdd=np.zeros((3, 2)), base=np.zeros((3, 9)))
    with pytest.raises(VampcError, match=r"b\.npz: array base: the program has a fixed base"):
        read(path, 2)
    assert read(path, 2, floating=True).base.shape == (3, 9)


def test_an_array_a_npz_holds_beside_the_states_is_refused(tmp_path):
    """An .npz holding `T` (meant as `t`) ran without times and said nothing: every array is q,
    qd, qdd, t or base, or the file is refused naming it."""
    from vampc.emulator.trajectory import read
    from vampc.errors import VampcError
    path = tmp_path / "T.npz"
    states = {k: np.zeros((3, 2)) for k in ("q", "qd", "qdd")}
    np.savez(path, **states, T=np.arange(3.0))
    with pytest.raises(VampcError, match=r"T\.npz: array 'T' is not read \(the arrays are q, qd, qdd"):
        read(path, 2)
    np.savez(path, **states, t=np.arange(3.0))
    assert read(path, 2).t.tolist() == [0.0, 1.0, 2.0]


def test_npz_arrays_of_different_lengths_are_said_to_be(tmp_path):
    """q of 1 row and qdd of 2 was 'array qdd has shape (2, 2); expected (states, 2)', a shape that
    fits that pattern (a new user's run)."""
    from vampc.emulator.trajectory import read
    from vampc.errors import VampcError
    path = tmp_path / "d.npz"
    np.savez(path, q=np.zeros((1, 2)), qd=np.zeros((1, 2)), qdd=np.zeros((2, 2)))
    with pytest.raises(VampcError, match=r"d\.npz: array qdd has 2 rows and array q 1; the arrays hold "
                                         r"one row per state$"):
        read(path, 2)
    np.savez(path, q=np.zeros((1, 2)), qd=np.zeros((1, 3)), qdd=np.zeros((1, 2)))
    with pytest.raises(VampcError, match=r"array qd has shape \(1, 3\); expected \(states, 2\)$"):
        read(path, 2)


def test_a_t_column_last_is_told_to_come_first(tmp_path):
    """'header: 19 columns, expected 18' did not say why (a new user's run)."""
    from vampc.emulator.trajectory import read
    from vampc.errors import VampcError
    path = tmp_path / "tl.csv"
    path.write_text("q1,q2,qd1,qd2,qdd1,qdd2,t\n" + "0," * 6 + "0\n")
    with pytest.raises(VampcError, match=r"tl\.csv: header: 7 columns, expected 6 \(.*\); a t column "
                                         r"comes first$"):
        read(path, 2)
    path.write_text("t,q1,q2,qd1,qd2,qdd1,qdd2\n" + "0," * 6 + "0\n")
    assert read(path, 2).t.tolist() == [0.0]


def _read_both(path, monkeypatch):
    """read() of a trajectory file with the native reader and without it: (array or error text)."""
    from vampc.emulator.trajectory import read
    from vampc.errors import VampcError
    out = []
    for mode in ("1", "0"):
        monkeypatch.setenv("VAMPC_NATIVE", mode)
        try:
            t = read(path, 2)
            out.append(np.hstack([t.q, t.qd, t.qdd]))
        except VampcError as exc:
            out.append(str(exc))
    return out


@pytest.mark.parametrize("change, want", [
    (lambda lines: lines.__setitem__(30_000, lines[30_000].replace(",", ",x", 1)),
     r"line 30001, column q2: 'x[0-9.e-]+' is not a number"),
    (lambda lines: lines.__setitem__(30_000, lines[30_000] + ",1"), r"line 30001: 7 columns, expected 6"),
    (lambda lines: lines.__setitem__(30_000, "x" * 1000 + lines[30_000]),
     r"line 30001, column q1: 'x{60}\.\.\.' is not a number"),
    (lambda lines: lines.__setitem__(30_000, "0.1234567890123456789012345," + lines[30_000].split(",", 1)[1]),
     None),
    (lambda lines: lines.__setitem__(30_000, '"1.5",' + lines[30_000].split(",", 1)[1]), None),
    (lambda lines: lines.append("\n  \n"), None),
    (lambda lines: lines.append(" , ,,\t,,"), None),        # a trailing line of commas and blanks
])
def test_a_line_the_native_reader_refuses_is_read_or_refused_as_the_slow_parser_does(tmp_path, monkeypatch,
                                                                                      change, want):
    """The native reader stops at the first line it refuses: a bad cell there is named at once, as
    the slow parser names it (a bad cell a million lines down had taken 40 s and 7.9 GB to name),
    and a line it only refuses (quotes, more than 19 digits, trailing blank lines) is read as the
    slow parser reads it; the two agree bit for bit or word for word."""
    rng = np.random.default_rng(2)
    lines = ["q1,q2,qd1,qd2,qdd1,qdd2"] + [",".join("%.17g" % x for x in row)
                                              for row in rng.uniform(-1, 1, (40_000, 6))]
    change(lines)
    path = tmp_path / "t.csv"
    path.write_text("\n".join(lines) + "\n")
    native_got, slow_got = _read_both(path, monkeypatch)
    if want is None:
        assert isinstance(native_got, np.ndarray) and np.array_equal(native_got.view(np.uint64),
                                                                     slow_got.view(np.uint64))
    else:
        import re
        assert native_got == slow_got and re.search(want, native_got), (native_got, slow_got)


@pytest.mark.parametrize("rows, want", [
    # an infinity, then a cell that is not a number two lines further on
    (["0,0,inf,0,0,0", "0,0,0,0,0,0", "0,x,0,0,0,0"], r"line 3 \(state 2\), column qd1: inf is not finite"),
    # a t that is not a number before a state that is not finite, and the other way round
    (["nan,0,0,0,0,0,0", "1,0,0,-inf,0,0,0"], r"line 3 \(state 2\), column t: nan is not finite$"),
    (["0,0,0,0,0,0,0", "1,0,0,1e999,0,0,0", "inf,0,0,0,0,0,0"],
     r"line 4 \(state 3\), column qd1: inf is not finite \(written so, or a number beyond"),
])
def test_the_first_line_in_the_file_that_is_wrong_is_named(tmp_path, monkeypatch, rows, want):
    """A number that is not finite and a cell further on that is not a number: the error names the
    first in the file, as it names the first of two bad cells (the cell had been named, a file
    being read the slow way to its end before its numbers were checked), with either reader."""
    import re
    header = ("t," if len(rows[0].split(",")) == 7 else "") + "q1,q2,qd1,qd2,qdd1,qdd2"
    path = tmp_path / "t.csv"
    path.write_text("\n".join([header, "0,0,0,0,0,0" if not header.startswith("t") else "0,0,0,0,0,0,0",
                                *rows]) + "\n")
    native_got, slow_got = _read_both(path, monkeypatch)
    assert native_got == slow_got and re.search(want, native_got), (native_got, slow_got)


def test_lines_ended_by_cr_alone_read_as_lf(tmp_path, monkeypatch):
    rng = np.random.default_rng(4)
    body = "".join(",".join("%.17g" % x for x in row) + "\n" for row in rng.uniform(-1, 1, (30_000, 6)))
    (tmp_path / "lf.csv").write_text("q1,q2,qd1,qd2,qdd1,qdd2\n" + body)
    (tmp_path / "cr.csv").write_bytes(("q1,q2,qd1,qd2,qdd1,qdd2\n" + body).replace("\n", "\r").encode())
    want = _read_both(tmp_path / "lf.csv", monkeypatch)[0]
    for got in _read_both(tmp_path / "cr.csv", monkeypatch):
        assert np.array_equal(got, want)


def test_a_trajectory_from_standard_input(tmp_path):
    runner = CliRunner()
    program, states = tmp_path / "p.vamp.json", tmp_path / "s.csv"
    assert runner.invoke(main, ["compile", "examples/planar2.yaml", "-o", str(program)]).exit_code == 0
    assert runner.invoke(main, ["emulate", str(program), "--random", "5", "--save-states", str(states),
                                "-o", str(tmp_path / "want.csv")]).exit_code == 0
    res = runner.invoke(main, ["emulate", str(program), "--trajectory", "-", "-o", str(tmp_path / "got.csv")],
                        input=states.read_text())
    assert res.exit_code == 0, res.output
    assert (tmp_path / "got.csv").read_text() == (tmp_path / "want.csv").read_text()


def test_out_of_memory_is_one_line_and_no_output(tmp_path, monkeypatch):
    from vampc.emulator import trajectory
    def no_memory(*args, **kwargs):
        raise MemoryError
    monkeypatch.setattr(trajectory, "read_table", no_memory)
    states = tmp_path / "s.csv"
    states.write_text("q1,q2,qd1,qd2,qdd1,qdd2\n0,0,0,0,0,0\n")
    out = tmp_path / "tau.csv"
    res = CliRunner().invoke(main, ["emulate", "examples/planar2.yaml", "--trajectory", str(states), "-o", str(out)])
    assert res.exit_code == 1 and res.output.startswith("vampc: error: out of memory") and \
        res.output.count("\n") == 1 and not out.exists(), res.output


def test_more_long_cells_than_a_piece_converts_go_the_slow_way(tmp_path, monkeypatch):
    """Cells of more than 19 significant digits are converted by float() on the native path, up to
    LONG_CELLS a piece; past that the file is read the slow way: the same values either way."""
    rows = [",".join(["0.12345678901234567890123", "1", "2", "3", "4", "5"]) for _ in range(5)]
    path = tmp_path / "t.csv"
    path.write_text("q1,q2,qd1,qd2,qdd1,qdd2\n" + "\n".join(rows) + "\n")
    want = np.array([[float("0.12345678901234567890123"), 1, 2, 3, 4, 5]] * 5)
    for limit in (native.LONG_CELLS, 2):
        monkeypatch.setattr(native, "LONG_CELLS", limit)
        body = path.read_bytes()
        got = native.parse_csv(body, 6, start=body.index(b"\n") + 1)
        assert (got is None) == (limit == 2)
        for read_got in _read_both(path, monkeypatch):
            assert np.array_equal(read_got, want)


def test_a_damaged_compressed_npz_and_a_npy_on_standard_input_are_one_line(tmp_path):
    """A byte damaged inside a compressed .npz member was a zlib traceback, exit 3; a .npy piped to
    `--trajectory -` was told to be named .npy, which standard input cannot be (an audit's)."""
    import zipfile

    from conftest import EXAMPLES
    rng = np.random.default_rng(0)
    bad = tmp_path / "bad.npz"
    np.savez_compressed(bad, q=rng.uniform(-1, 1, (50, 2)), qd=rng.uniform(-1, 1, (50, 2)),
                        qdd=rng.uniform(-1, 1, (50, 2)))
    data = bytearray(bad.read_bytes())
    info = zipfile.ZipFile(bad).getinfo("q.npy")
    data[info.header_offset + 30 + len("q.npy") + 100] ^= 0xFF
    bad.write_bytes(bytes(data))
    out = tmp_path / "tau.csv"
    r = CliRunner().invoke(main, ["emulate", str(EXAMPLES / "planar2.yaml"), "--trajectory",
                                  str(bad), "-o", str(out)])
    assert r.exit_code == 1 and r.stderr.startswith(f"vampc: error: {bad}: array q: ")
    assert r.stderr.count("\n") == 1 and not out.exists()
    good = tmp_path / "good.npy"
    np.save(good, np.zeros((3, 6)))
    r = CliRunner().invoke(main, ["emulate", str(EXAMPLES / "planar2.yaml"), "--trajectory", "-",
                                  "-o", str(out)], input=good.read_bytes())
    assert r.exit_code == 1 and "-: a NumPy .npy array on standard input, which takes trajectory " \
        "text (CSV) only; give the array as a file named .npy" in r.stderr, r.stderr


def _npy_with_header(path, header: bytes, data: bytes) -> None:
    """A version-1.0 .npy of `header` (padded as numpy pads it) and `data`, as a damaged or
    hand-made file would be."""
    header = header + b" " * (117 - len(header)) + b"\n"
    path.write_bytes(b"\x93NUMPY\x01\x00" + len(header).to_bytes(2, "little") + header + data)


def test_odd_npy_headers_and_arrays_are_one_line_each(tmp_path):
    """A new user's: a header whose brace is never closed was a traceback, exit 3 (numpy raised
    tokenize's TokenError); a call in a header was said with an object's address; a negative
    length as "-152 bytes" of data; no states and a structured array as a shape alone; a long
    double that is no float64 came after a RuntimeWarning line."""
    from conftest import EXAMPLES
    data = np.zeros((3, 6)).tobytes()
    cases = {
        "open": (b"{'descr': '<f8', 'fortran_order': False, 'shape': (3, 6), ",
                 "not a numpy array file (its header does not parse: EOF in multi-line statement)"),
        "call": (b"{'descr': f(), 'fortran_order': False, 'shape': (3, 6), }",
                 "not a numpy array file (malformed node or string on line 1: a Call expression)"),
        "negative": (b"{'descr': '<f8', 'fortran_order': False, 'shape': (-1, 6), }",
                     "its header announces a negative length, shape (-1, 6) (damaged, or not "
                     "written by numpy)"),
    }
    for name, (header, _) in cases.items():
        _npy_with_header(tmp_path / f"{name}.npy", header, data)
    np.save(tmp_path / "empty.npy", np.zeros((0, 7)))
    np.save(tmp_path / "fields.npy", np.zeros(3, dtype=[("q1", "f8"), ("q2", "f8")]))
    cases["empty"] = (None, "the array has no states (shape (0, 7))")
    cases["fields"] = (None, "a structured array (named fields q1, q2); save a plain array of "
                             "numbers, (states, 6) or (states, 7) with t first")
    if np.finfo(np.longdouble).nmant > 52:
        size = 18 * np.dtype(np.longdouble).itemsize     # bytes no float64 holds, some no number
        noise = np.random.default_rng(1).integers(0, 256, size, dtype=np.uint8).tobytes()
        np.save(tmp_path / "wide.npy", np.frombuffer(noise, dtype=np.longdouble).reshape(3, 6))
        cases["wide"] = (None, "the array, state 1, column ")
    out = tmp_path / "tau.npy"
    for name, (_, said) in cases.items():
        r = CliRunner().invoke(main, ["emulate", str(EXAMPLES / "planar2.yaml"), "--trajectory",
                                      str(tmp_path / f"{name}.npy"), "-o", str(out)])
        assert r.exit_code == 1, (name, r.output, r.exception)
        assert r.stderr.startswith(f"vampc: error: {tmp_path / name}.npy: {said}"), r.stderr
        assert r.stderr.count("\n") == 1 and "0x" not in r.stderr and not out.exists(), r.stderr
    empty = tmp_path / "empty.npz"              # (and an archive's member: a review's)
    np.savez(empty, q=np.zeros((0, 2)), qd=np.zeros((0, 2)), qdd=np.zeros((0, 2)))
    r = CliRunner().invoke(main, ["emulate", str(EXAMPLES / "planar2.yaml"), "--trajectory",
                                  str(empty), "-o", str(out)])
    assert r.exit_code == 1 and r.stderr == f"vampc: error: {empty}: array q holds no states " \
        "(shape (0, 2))\n", r.stderr


def test_a_blank_first_line_and_a_quote_never_closed_are_said_so(tmp_path):
    """A new user's: a blank line before the header was "header: 0 columns, expected 6"; a quote
    opened and never closed was "line 3: 4 columns, expected 6" (the csv reader took the lines
    after it into the cell)."""
    from conftest import EXAMPLES
    header, row = "q1,q2,qd1,qd2,qdd1,qdd2\n", "0.1,0.2,0.3,0.4,0.5,0.6\n"
    cases = {"blank": ("\n" + header + row, "line 1 is blank: the header line comes first "
                                            "(q1,q2...qdd2, t first if the rows have times)"),
             "quote": (header + row + '0.1,"0.2,0.3,0.4,0.5,0.6\n' + row * 2,
                       "line 3, column q2: a quoted cell holds a line break (a quote opened and "
                       "not closed?)"),
             "commas": (",,,,,\n" + header + row, "line 1 holds no column names, only commas: the "
                        "header line comes first (q1,q2...qdd2, t first if the rows have times)")}
    out = tmp_path / "tau.csv"
    for name, (text, said) in cases.items():
        path = tmp_path / f"{name}.csv"
        path.write_text(text)
        r = CliRunner().invoke(main, ["emulate", str(EXAMPLES / "planar2.yaml"), "--trajectory",
                                      str(path), "-o", str(out)])
        assert r.exit_code == 1 and r.stderr == f"vampc: error: {path}: {said}\n", r.stderr
        assert not out.exists()
