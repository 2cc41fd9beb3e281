"""vampc.jsontext writes JSON with msgspec exactly as Python's json module writes it (the module is
the independent reference here): reports, graph annotations and schemas keep their bytes."""
from __future__ import annotations

import json

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from vampc import jsontext

# Hypothesis's default deadline (200 ms an example) and its too_slow health check (1 s to draw
# the first examples) time the machine, not the code: a stall of the process, or a loaded
# machine, fails a run whose examples all pass. What each test checks is unchanged.
UNTIMED = settings(deadline=None, suppress_health_check=[HealthCheck.too_slow])

scalars = st.none() | st.booleans() | st.integers(-2**63, 2**63) | \
    st.floats(allow_nan=False, allow_infinity=False) | st.text(max_size=8)
values = st.recursive(scalars, lambda inner: st.lists(inner, max_size=4) |
                      st.dictionaries(st.text(max_size=5), inner, max_size=4), max_leaves=20)


@UNTIMED
@given(values, st.sampled_from([None, 1, 2]), st.booleans())
def test_dumps_writes_what_the_standard_library_writes(value, indent, sort_keys):
    assert jsontext.dumps(value, indent=indent, sort_keys=sort_keys) == \
        json.dumps(value, indent=indent, sort_keys=sort_keys)


@UNTIMED
@given(values)
def test_loads_reads_what_the_standard_library_reads(value):
    text = json.dumps(value)
    assert jsontext.loads(text) == json.loads(text) == value


def test_escapes_and_floats_as_the_standard_library():
    doc = {"name": "J\u00e9r\u00f4me \u2028 \U0001f916 \x7f \x1f \\ \"", "x": [1e-05, 1e16, -0.0, 5e-324],
           "t": (1, 2.5)}
    for indent in (None, 1):
        assert jsontext.dumps(doc, indent=indent) == json.dumps(doc, indent=indent)


@pytest.mark.parametrize("value", [float("nan"), float("inf"), [1.0, -float("inf")]])
def test_a_non_finite_number_is_refused_not_written(value):
    with pytest.raises(ValueError, match="not a JSON number"):
        jsontext.dumps({"x": value})


@pytest.mark.parametrize("text", ["NaN", "[1, Infinity]", "{\"a\": 1,}", ""])
def test_what_is_not_json_is_a_decode_error(text):
    with pytest.raises(jsontext.DecodeError):
        jsontext.loads(text)


@pytest.mark.parametrize("text, said", [
    ('{"a":\n [1, NaN]}', "NaN is not allowed (line 2, column 6)"),
    ('{"a":\n [1, -Infinity]}', "-Infinity is not allowed (line 2, column 6)"),
    ('{"a": 1,}', "trailing comma in object (line 1, column 9)"),
    # text cut short: said where it ends, just past its last character (no place was said before)
    ('{"program": "x",\n "synth": [1,2', "it ends early (line 2, column 15)"),
    ('{"a": [\n\n  \n', "it ends early (line 1, column 8)"),
    # a lone high surrogate: msgspec says "truncated", and "it ends early" was said of a whole file
    # (a new user's find); an escaped backslash before a u is no escape, a pair is no problem
    ('{"a": 1,\n "x-note": "ok \\\\ud800 \\ud83d\\ude00", "b": "\\ud800"}',
     "\\ud800 is half of a UTF-16 surrogate pair, alone (line 2, column 45)"),
    # a number beyond float64's range: msgspec says no place; nothing in a string is taken for it
    # (a checksum's hex '35670e9337' had been named where 1e999 was: a review's find)
    ('{"checksum": "sha256:35670e9337ab", "note": "\\" 1e999",\n "period": -2.5e999}',
     "the number -2.5e999 is beyond float64's range (about 1.8e308) (line 2, column 12)"),
])
def test_a_decode_problem_is_said_with_its_line_and_column(text, said):
    with pytest.raises(jsontext.DecodeError) as exc:
        jsontext.loads(text)
    assert jsontext.decode_problem(exc.value, text) == said


def test_report_rtl_figures_cut_short_are_said_with_their_place(tmp_path):
    """`report --rtl` of a figures file cut short said "not JSON (Input data was truncated)", no
    line or column (a new user's find)."""
    from click.testing import CliRunner
    from conftest import EXAMPLES

    from vampc.cli import main
    figures = tmp_path / "cut.json"
    figures.write_text('{"program": "x",\n "synth": [1,2')
    r = CliRunner().invoke(main, ["report", str(EXAMPLES / "planar2.yaml"), "--word", "q16.16",
                                  "--rtl", str(figures)])
    assert r.exit_code == 1 and r.stderr == \
        f"vampc: error: {figures}: not JSON: it ends early (line 2, column 15)\n"


def test_number_rows_from_a_flat_array_are_the_rows_written_one_by_one():
    """Rows held as one flat float array (emit.Words) are written as the same rows given as tuples,
    and a non-finite value is refused either way."""
    from array import array

    from vampc.program.emit import Words
    values = [1.0, 0.1, -0.0, 16777215.0, 1e16, 2.5e-7, 3.0, 9007199254740991.0, -4.0]
    flat = Words(array("d", values))
    rows = tuple(tuple(values[k:k + 3]) for k in range(0, len(values), 3))
    assert bytes(jsontext.number_rows(flat)) == bytes(jsontext.number_rows(rows)) == \
        b"[[1.0,0.1,-0.0],[16777215.0,1e+16,2.5e-07],[3.0,9007199254740991.0,-4.0]]"
    for bad in (float("nan"), float("inf")):
        with pytest.raises(ValueError, match="not a JSON number"):
            jsontext.number_rows(Words(array("d", [1.0, bad, 2.0])))


_WHOLE = st.one_of(st.integers(0, 10**7).map(float),      # VAMP numbers and fields, mostly
                   st.integers(-2**53 + 1, 2**53 - 1).map(float),
                   st.sampled_from([0.0, 1.0, -1.0, 9.0, 10.0, 99.0, 100.0, 2.0**32 - 1, 2.0**32,
                                    2.0**32 + 1, -2.0**32, 2.0**53 - 1, -2.0**53 + 1,
                                    9999999999999998.0]))
_ANY = st.one_of(_WHOLE, st.sampled_from([-0.0, 2.0**53, -2.0**53, 1e16, 1e22, 0.5, -2.5e-7,
                                          1e-300, float("inf"), float("-inf"), float("nan")]),
                 st.floats(allow_nan=True, allow_infinity=True))


def _entries(values):
    return st.lists(st.lists(st.tuples(values, values, values), max_size=6), max_size=6)


@settings(max_examples=150, deadline=None)
@given(entries=st.one_of(_entries(_WHOLE), _entries(_ANY)), as_tuples=st.booleans())
def test_number_rows_each_writes_what_python_repr_writes(entries, as_tuples):
    """The program stream's words of a batch written at once (NumPy writing whole numbers' digits)
    are, entry by entry, the bytes number_rows writes value by value with Python's float repr, or
    the same ValueError for a value that is not a JSON number: whole numbers of every length and
    sign, about 2^32 and 2^53, -0.0, fractions, infinities and NaN, empty entries, and rows given
    as tuples rather than a flat array."""
    from array import array

    from vampc.program.emit import Words
    given = [tuple(rows) if as_tuples else Words(array("d", [x for row in rows for x in row]))
             for rows in entries]
    try:
        want = [bytes(jsontext.number_rows(e)) for e in given]
    except ValueError as exc:
        with pytest.raises(ValueError, match="not a JSON number"):
            jsontext.number_rows_each(given)
        assert "not a JSON number" in str(exc)
        return
    assert [bytes(r) for r in jsontext.number_rows_each(given)] == want


def test_number_rows_each_of_rows_of_unequal_or_odd_widths_is_number_rows_of_each():
    """Entries whose widths differ (3 and 3.0 among them: equal, but not the same int) or are
    not ints are written entry by entry, as number_rows writes them, errors and all."""
    from array import array

    class Rows:
        def __init__(self, values, width):
            self.flat, self.width = array("d", values), width
    for widths in ((3, 3.0), (3.0, 3.0), (True, True)):
        entries = [Rows([1.0, 2.0, 3.0], widths[0]), Rows([4.0, 5.0, 6.0], widths[1])]
        try:
            want = [bytes(jsontext.number_rows(e)) for e in entries]
        except TypeError:
            with pytest.raises(TypeError):
                jsontext.number_rows_each(entries)
        else:
            assert [bytes(r) for r in jsontext.number_rows_each(entries)] == want


def test_number_rows_each_of_whole_numbers_is_repr_on_a_program_stream_s_scale():
    """A batch as big as the writer makes (8192 words), of whole numbers of one to eight digits
    and a few negative ones, against Python's repr of each value."""
    import random
    from array import array

    from vampc.program.emit import Words
    rng = random.Random(7)
    entries = []
    for _ in range(300):
        values = [float(rng.choice([rng.randrange(10**rng.randrange(1, 9)), -rng.randrange(1, 99)]))
                  for _ in range(3 * rng.randrange(1, 50))]
        entries.append(Words(array("d", values)))
    want = [("[" + ",".join("[" + ",".join(repr(x) for x in w) + "]" for w in e) + "]").encode()
            for e in entries]
    assert [bytes(r) for r in jsontext.number_rows_each(entries)] == want


def test_json_nested_too_deeply_is_not_json_for_every_reader(tmp_path):
    """`vampc report --rtl` and `faults --results` given a 2000-deep array ended in a traceback
    (exit 3: msgspec's RecursionError; a hostile-input audit's find): loads raises a DecodeError,
    which every reader says as not JSON, that is a RecursionError too (the readers that said
    "nested too deeply" still do)."""
    from click.testing import CliRunner
    from conftest import EXAMPLES

    from vampc.cli import main
    deep = "[" * 2000 + "]" * 2000
    for caught in (jsontext.DecodeError, ValueError, RecursionError):
        with pytest.raises(caught, match="nested too deeply"):
            jsontext.loads(deep)
    figures = tmp_path / "deep.json"
    figures.write_text(deep)
    r = CliRunner().invoke(main, ["report", str(EXAMPLES / "planar2.yaml"), "--rtl", str(figures)])
    assert r.exit_code == 1 and r.stderr == f"vampc: error: {figures}: not JSON: nested too deeply\n"
    program = tmp_path / "p.vamp.json"
    program.write_text(deep)
    r = CliRunner().invoke(main, ["emulate", str(program), "--random", "1"])
    assert r.exit_code == 1 and "nested too deeply" in r.stderr and len(r.stderr.splitlines()) == 1
    # a fault campaign's results file whose first line is that deep (exit 3 before)
    assert CliRunner().invoke(main, ["compile", str(EXAMPLES / "planar2.yaml"), "-o",
                                     str(program)]).exit_code == 0
    results = tmp_path / "r.jsonl"
    results.write_text(deep + "\n")
    r = CliRunner().invoke(main, ["faults", str(program), "--kinds", "dead", "--workers", "1",
                                  "--results", str(results)])
    assert r.exit_code == 1 and r.stderr == (
        f"vampc: error: --results {results} is not a results file of vampc faults (never "
        "overwritten; give another --results file)\n"), r.stderr
    assert results.read_text() == deep + "\n"
