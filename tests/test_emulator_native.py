"""The stream engine's native code (vampc.emulator.native) against the numpy stream path and the tick
engine, bit for bit; its fallbacks and cache; and the native trajectory reader and the trajectory
fast paths it serves (vampc.emulator.trajectory).
"""
from __future__ import annotations

import os
import platform
import re
import shutil
import subprocess
import warnings
from pathlib import Path

import numpy as np
import pytest

from vampc.compiler import CompileOptions, compile_chain, program_document
from vampc.emulator import check_program, loaded_from_doc, native
from vampc.emulator.host import port_values, random_trajectory
from vampc.emulator.stream import flow, run_numpy, run_stream
from vampc.emulator.tick import TickEngine
from vampc.emulator.trajectory import header, read, write_torques
from vampc.errors import VampcError
from vampc.robot import load_robot
from vampc.robot.random import random_chain

EXAMPLES = sorted(p for p in (Path(__file__).resolve().parent.parent / "examples").iterdir()
                  if p.suffix in (".yaml", ".urdf"))
FMA = re.compile(r"\b(v?fn?m(add|sub)\w*|fml[as])\b")   # x86 FMA3/FMA4, AArch64 fmadd/fmla


def _loaded(chain, **opts):
    return loaded_from_doc(program_document(compile_chain(chain, CompileOptions(**opts))))


def _prepared(ld, traj):
    """The program's flow, the host's values per (port, entry), and per flow input."""
    fl = flow(ld, check_program(ld))
    values = port_values(ld, traj)
    return fl, values, {i: values[(p, e)] for i, (p, e, _) in enumerate(fl.inputs)}


def _three_ways(ld, count: int, tick_count: int | None = None, seed: int = 1):
    """Native, numpy and tick torques on the same random states (tick on the first tick_count)."""
    traj = random_trajectory(ld.chain, count, seed)
    fl, values, ports = _prepared(ld, traj)
    fast = native.build(ld, fl).run(ports, count)
    slow = run_numpy(ld, fl, ports, count)
    k = count if tick_count is None else tick_count
    engine = TickEngine(ld, seed=1)
    engine.program()
    tick = engine.run({p: a[:k] for p, a in values.items()}, k)
    return fast, slow, tick


def _assert_bit_equal(ld, count=133, tick_count=None):
    # 133 sets: two full blocks of 64 and a tail block of 5
    fast, slow, tick = _three_ways(ld, count, tick_count)
    assert np.array_equal(fast, slow)
    assert np.array_equal(fast[:tick.shape[0]], tick)


needs_cc = pytest.mark.skipif(native.compiler() is None, reason="no C compiler")


# --- bit for bit ----------------------------------------------------------------------------------

@needs_cc
@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.name)
def test_examples_native_equals_numpy_and_tick(path):
    ld = _loaded(load_robot(path))
    _assert_bit_equal(ld, tick_count=3 if "snake" in path.name else None)


@needs_cc
@pytest.mark.parametrize("n, seed, frac", [(1, 0, 1.0), (4, 11, 0.5), (9, 23, 0.4)])
def test_random_chains_native_equals_numpy_and_tick(n, seed, frac):
    _assert_bit_equal(_loaded(random_chain(n, seed, prismatic_fraction=frac, endpoints=True)))


@needs_cc
@pytest.mark.parametrize("opts", [dict(layout="folded"), dict(layout="folded", share_passes=True),
                                  dict(recursion="log", layout="folded", share_passes=True),
                                  dict(mult_latency=3, add_latency=2),
                                  dict(recursion="log", layout="folded", mult_latency=1,
                                       add_latency=4)], ids=str)
def test_other_layouts_and_latencies_native_equals_numpy_and_tick(opts):
    chain = random_chain(5, 7, prismatic_fraction=0.4, endpoints=True)
    _assert_bit_equal(_loaded(chain, **opts), count=70, tick_count=10)


@needs_cc
@pytest.mark.parametrize("prefix", ["sklansky", "kogge-stone"])
def test_log_recursion_native_equals_numpy_and_tick(prefix):
    chain = random_chain(5, 3, prismatic_fraction=0.5, endpoints=True)
    _assert_bit_equal(_loaded(chain, recursion="log", prefix=prefix), count=70)


@needs_cc
def test_puma_log_recursion_native_equals_numpy():
    ld = _loaded(load_robot(EXAMPLES[[p.name for p in EXAMPLES].index("puma560.yaml")]),
                 recursion="log")
    _assert_bit_equal(ld, count=65, tick_count=8)


@needs_cc
@pytest.mark.parametrize("count", [0, 1, 64, 65])
def test_block_edges(count):
    ld = _loaded(random_chain(3, 5, prismatic_fraction=0.5, endpoints=True))
    traj = random_trajectory(ld.chain, max(count, 1), 2)
    fl, _, ports = _prepared(ld, traj)
    ports = {p: a[:count] for p, a in ports.items()}
    fast = native.build(ld, fl).run(ports, count)
    assert fast.shape == (count, 3)
    assert np.array_equal(fast, run_numpy(ld, fl, ports, count))


@needs_cc
def test_chunks_report_progress(monkeypatch):
    monkeypatch.setattr(native, "CHUNK", 100)
    ld = _loaded(random_chain(2, 8, endpoints=True))
    fl, _, ports = _prepared(ld, random_trajectory(ld.chain, 250, 4))
    seen = []
    fast = native.build(ld, fl).run(ports, 250, lambda done, total: seen.append((done, total)))
    assert seen == [(100, 250), (200, 250), (250, 250)]
    assert np.array_equal(fast, run_numpy(ld, fl, ports, 250))


@needs_cc
@pytest.mark.skipif(shutil.which("objdump") is None, reason="no objdump")
def test_no_fused_multiply_add_in_the_shared_object():
    ld = _loaded(load_robot(EXAMPLES[[p.name for p in EXAMPLES].index("puma560.yaml")]))
    fl = flow(ld, check_program(ld))
    so = native.compile_cached(native.generate_source(ld, fl, native.Scratch.of(fl)))
    text = subprocess.run(["objdump", "-d", str(so)], capture_output=True, text=True, check=True).stdout
    assert not FMA.search(text), FMA.search(text).group(0)
    if platform.machine() == "x86_64":
        assert "mulpd" in text    # vectorised across states (two doubles per SSE2 register)


# --- choosing the path, falling back, caching ------------------------------------------------------

@pytest.fixture
def small():
    ld = _loaded(random_chain(2, 9, prismatic_fraction=0.5, endpoints=True))
    fl, _, ports = _prepared(ld, random_trajectory(ld.chain, 10, 1))
    return ld, fl, ports


@pytest.fixture
def cache(tmp_path, monkeypatch):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    return tmp_path / "cache" / "vampc"


def test_native_off(small, monkeypatch):
    ld, fl, ports = small
    monkeypatch.setenv("VAMPC_NATIVE", "0")
    assert native.run_native(ld, fl, ports, 10) is None
    assert np.array_equal(run_stream(ld, fl, ports, 10), run_numpy(ld, fl, ports, 10))


def test_no_compiler_falls_back_silently(small, monkeypatch, capsys):
    ld, fl, ports = small
    monkeypatch.setattr(native, "compiler", lambda: None)
    monkeypatch.delenv("VAMPC_NATIVE", raising=False)
    assert native.run_native(ld, fl, ports, 10**6) is None
    assert np.array_equal(run_stream(ld, fl, ports, 10), run_numpy(ld, fl, ports, 10))
    assert capsys.readouterr() == ("", "")
    monkeypatch.setenv("VAMPC_NATIVE", "1")
    with pytest.raises(native.NativeError, match=r"^no C compiler found"):
        native.run_native(ld, fl, ports, 10)


@needs_cc
def test_failed_compile_falls_back(small, cache, monkeypatch, capsys):
    ld, fl, ports = small
    monkeypatch.setattr(native, "CFLAGS", native.CFLAGS + ("-fno-such-flag-vampc",))
    monkeypatch.delenv("VAMPC_NATIVE", raising=False)
    assert native.run_native(ld, fl, ports, 10**6) is None
    assert capsys.readouterr() == ("", "")
    assert not list(cache.iterdir())     # no half-written object left behind
    monkeypatch.setenv("VAMPC_NATIVE", "1")
    with pytest.raises(native.NativeError, match=r"failed \(exit \d+\)") as err:
        native.run_native(ld, fl, ports, 10)
    # one line (gcc's whole stderr had been the message), and a user error, not a traceback
    assert "\n" not in str(err.value) and isinstance(err.value, native.VampcError)
    assert not list(cache.iterdir())     # gcc's scratch folder removed too


@needs_cc
def test_short_runs_stay_on_numpy(small, cache, monkeypatch):
    ld, fl, ports = small
    monkeypatch.delenv("VAMPC_NATIVE", raising=False)
    monkeypatch.setattr(native, "generate_source", _must_not_compile)
    assert native.run_native(ld, fl, ports, 10) is None
    monkeypatch.undo()
    monkeypatch.setenv("XDG_CACHE_HOME", str(cache.parent))
    monkeypatch.setenv("VAMPC_NATIVE", "1")          # forced: compiled whatever the length
    assert np.array_equal(native.run_native(ld, fl, ports, 10), run_numpy(ld, fl, ports, 10))
    assert len(list(cache.glob("*.so"))) == 1


@needs_cc
def test_a_middle_run_uses_a_cached_program_and_compiles_none(small, cache, monkeypatch):
    """Runs under MIN_SETS_TO_COMPILE stayed on numpy although the cache held their program (a run of
    20 000 sets had compiled it): from CACHED_FROM sets a cached program runs; none is compiled."""
    ld, fl, ports = small
    monkeypatch.delenv("VAMPC_NATIVE", raising=False)
    middle = native.CACHED_FROM
    assert native.CACHED_FROM < native.MIN_SETS_TO_COMPILE
    monkeypatch.setattr(native, "_compile", _must_not_compile)
    assert native.prepare(ld, fl, middle) is None                 # nothing cached: numpy
    assert not list(cache.glob("*.so"))
    monkeypatch.undo()
    monkeypatch.setenv("XDG_CACHE_HOME", str(cache.parent))
    monkeypatch.delenv("VAMPC_NATIVE", raising=False)
    assert native.prepare(ld, fl, native.MIN_SETS_TO_COMPILE) is not None    # a long run compiles
    monkeypatch.setattr(native, "_compile", _must_not_compile)
    program = native.prepare(ld, fl, middle)                      # now cached: used, not compiled
    assert program is not None
    assert np.array_equal(program.run(ports, 10), run_numpy(ld, fl, ports, 10))
    monkeypatch.setattr(native, "generate_source", _must_not_compile)
    assert native.prepare(ld, fl, middle - 1) is None             # below: nothing generated
    monkeypatch.setattr(native, "compiler", lambda: None)
    assert native.prepare(ld, fl, middle) is None       # no compiler: nothing generated either


def _must_not_compile(*args):
    raise AssertionError("compiled although the cache holds the object or the run is short")


@needs_cc
def test_cache_is_keyed_by_source(small, cache, monkeypatch):
    ld, fl, ports = small
    native.build(ld, fl)
    objects = list(cache.glob("vampc-*.so"))
    assert len(objects) == 1
    monkeypatch.setattr(native, "_compile", _must_not_compile)
    assert np.array_equal(native.build(ld, fl).run(ports, 10), run_numpy(ld, fl, ports, 10))
    other = _loaded(random_chain(2, 10, endpoints=True))
    with pytest.raises(AssertionError, match="compiled although"):
        native.build(other, flow(other, check_program(other)))


@needs_cc
def test_a_killed_compiles_temporaries_are_removed_by_a_later_compile(small, cache):
    """A SIGKILL during a compile left its .vampc-cc.* folder and half-written .vampc-*.so in the
    cache for good (a CI engineer's find): the next compile removes those a day old or more,
    and leaves fresh ones (a compile running now) and everything else alone."""
    import os
    import time
    ld, fl, _ = small
    cache.mkdir(parents=True)
    old, fresh = time.time() - native.STALE_SECONDS - 60, time.time() - 60
    left = {cache / ".vampc-cc.abc123": old, cache / ".vampc-0123.k9x.so": old,
            cache / ".vampc-0123.sha256.k9x": old, cache / ".vampc-cc.now456": fresh,
            cache / ".vampc-4567.now.so": fresh, cache / "mine.txt": old, cache / ".other": old}
    for path, when in left.items():
        if "cc." in path.name:
            path.mkdir()
            (path / "ccXYZ.s").write_text("left")
        else:
            path.write_text("left")
        os.utime(path, (when, when))
    native.build(ld, fl)
    stays = {p.name for p in cache.iterdir()}
    assert {".vampc-cc.now456", ".vampc-4567.now.so", "mine.txt", ".other"} <= stays
    assert not stays & {".vampc-cc.abc123", ".vampc-0123.k9x.so", ".vampc-0123.sha256.k9x"}


@needs_cc
def test_a_damaged_cached_object_is_said_and_compiled_again(small, cache):
    """A cut-short cached object was loaded as it was and killed the process with SIGBUS, nothing
    said; an empty one sent every run to numpy in silence (an audit's finds). Each is now found by
    the digest kept beside it, said once, and compiled again. (The damaged file is put in place by
    a rename, as a crash leaves it: this process has the good one mapped.)"""
    import os

    from vampc.errors import VampcWarning
    ld, fl, ports = small
    native.build(ld, fl)
    (obj,) = cache.glob("vampc-*.so")
    good = obj.read_bytes()
    for damaged in (good[:5000], b"", good[:-1] + bytes([good[-1] ^ 1])):
        spoiled = obj.with_name("spoiled")
        spoiled.write_bytes(damaged)
        os.replace(spoiled, obj)
        with pytest.warns(VampcWarning, match=r"the cached compiled program does not match the "
                                              r"digest kept beside it \(vampc-\w+\.sha256\): one of "
                                              r"them is damaged; it is compiled again"):
            program = native.build(ld, fl)
        assert obj.read_bytes() == good
        assert np.array_equal(program.run(ports, 10), run_numpy(ld, fl, ports, 10))
    obj.with_suffix(".sha256").unlink()        # an earlier vampc's cache: compiled again, unsaid
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        native.build(ld, fl)
    assert obj.with_suffix(".sha256").exists()
    # a run too short to compile for (a cached program runs; none is compiled) compiles a damaged
    # one again too: it had been said "compiled again", removed, and the run left on numpy
    spoiled.write_bytes(good[:5000])
    os.replace(spoiled, obj)
    with pytest.warns(VampcWarning, match=r"one of them is damaged; it is compiled again"):
        program = native.build(ld, fl, compile_now=False)
    assert program is not None and obj.read_bytes() == good


def test_unwritable_cache_falls_back_to_temp(tmp_path, monkeypatch):
    blocker = tmp_path / "not-a-folder"
    blocker.write_text("")
    monkeypatch.setenv("XDG_CACHE_HOME", str(blocker))
    folder = native.cache_dir()
    assert folder.name.startswith("vampc-") and folder.is_dir()


ATOM = r"(S\[\d+ \+ s\]|\(-?0x[0-9a-f.]+p[+-]\d+\)|0\.0|u\d|t\d)"
ONE_OP = re.compile(rf"^[ut]\d = {ATOM} [-+*] {ATOM}$")           # one rounding
MOVE = re.compile(r"^(S\[\d+ \+ s\] = u\d|u\d = t\d|u\d(, u\d)*)$")    # a store, a copy, a declaration


def test_generated_statements_have_one_rounding_each():
    ld = _loaded(random_chain(3, 9, prismatic_fraction=0.5, endpoints=True))
    fl = flow(ld, check_program(ld))
    src = native.generate_source(ld, fl, native.Scratch.of(fl))
    parts = src.split("static void vamps(")[0]
    body = [line for line in parts.splitlines() if line.startswith("    ")]   # the VAMP loop bodies
    statements = [st.strip(" {}").removeprefix("double ") for line in body for st in line.split(";")]
    statements = [st for st in statements if st]
    assert statements and all(ONE_OP.match(st) or MOVE.match(st) for st in statements), \
        [st for st in statements if not (ONE_OP.match(st) or MOVE.match(st))][:3]
    assert any(ONE_OP.match(st) for st in statements)
    # the ROM's order: A3·B3 and A2·B2, their sum, then A1·B1 added to it; a cross product as the
    # difference of two rounded products
    assert "u2 = u0 + u1; u0 = " in src and "u2 = u0 + u2;" in src and "u2 = u0 - u1;" in src


# --- the trajectory reader --------------------------------------------------------------------------

def _floats_as_python(lines, cols):
    return np.array([[float(c) for c in line.split(",")] for line in lines]).reshape(-1, cols)


@needs_cc
def test_parse_csv_gives_float_values(monkeypatch):
    monkeypatch.setenv("VAMPC_NATIVE", "1")     # the reader under test, whatever the caller's setting
    rng = np.random.default_rng(0)
    x = rng.normal(size=4000) * 10.0 ** rng.integers(-320, 300, 4000).astype(float)
    cells = [repr(float(v)) for v in x[:1000]] + [f"{v:.17g}" for v in x[1000:2000]] + \
            [f"{v:.3e}" for v in x[2000:3000]] + [f" {v:.15g}\t" for v in x[3000:]]
    cells[:6] = ["1.", ".5", "+1", "-0", "1e400", "-1e-400"]
    lines = [",".join(cells[k:k + 4]) for k in range(0, len(cells), 4)]
    got = native.parse_csv(("\n".join(lines) + "\n").encode(), 4)
    want = _floats_as_python(lines, 4)
    assert np.array_equal(got, want) and np.array_equal(np.signbit(got), np.signbit(want))
    assert np.array_equal(native.parse_csv(("\r\n".join(lines)).encode(), 4), want)


@needs_cc
def test_parse_csv_rounds_every_decimal_as_float_does(monkeypatch, tmp_path):
    """The reader's own conversion (Eisel-Lemire, strtod where it cannot decide) against Python's
    float(), bit for bit: doubles of every bit pattern written in five ways, random digit strings
    of up to 25 digits with exponents to the ends of the range, halfway cases, the subnormal and
    overflow boundaries."""
    import random
    import struct
    monkeypatch.setenv("VAMPC_NATIVE", "1")
    rng = random.Random(11)
    cells = []
    for _ in range(60_000):
        x = struct.unpack("<d", struct.pack("<Q", rng.getrandbits(64)))[0] if rng.random() < 0.5 \
            else rng.uniform(-1, 1) * 10.0 ** rng.randint(-9, 6)
        if not np.isfinite(x):
            continue
        form = rng.choice(["%.17g", "repr", "%.6f", "%.3e", "%.20e", "digits"])
        if form == "repr":
            cells.append(repr(x))
        elif form == "digits":
            d = "".join(rng.choice("0123456789") for _ in range(rng.randint(1, 25)))
            at = rng.randint(0, len(d))
            cell = (d[:at] + "." + d[at:]).strip(".") or "0"
            cells.append(rng.choice(["", "-", "+"]) + cell + (f"e{rng.randint(-345, 310)}" if rng.random() < 0.5
                                                            else ""))
        else:
            cells.append(form % x)
    cells += ["9007199254740993", "9007199254740995", "-9007199254740993e-10", "4.9e-324", "2.4703282292062327e-324",
              "2.2250738585072011e-308", "2.2250738585072014e-308", "1.7976931348623157e308",
              "1.7976931348623158e308", "1.7976931348623159e308", "1234567890123456789",
              "12345678901234567890", "0.000000000000000000000000000001", "-0.0", "0e5", "1e-348", "1e-349"]
    cells += ["0." + "0" * 99_999 + "1e1000000", "0." + "0" * 99_990 + "1e100001234",   # exponents past
              "1e0000000000000000000001", "-1e-100000000000000000000"]                   # the clamp
    short = [c for c in cells if _significant_digits(c) <= 19]
    body = ("header\n" + "\n".join(short) + "\n").encode()
    got = native.parse_csv(body, 1, start=len("header\n"))[:, 0]
    want = np.array([float(c) for c in short])
    bad = np.flatnonzero(got.view(np.uint64) != want.view(np.uint64))
    assert not bad.size, [short[i] for i in bad[:5]]
    # more than 19 significant digits: converted by float() (glibc's strtod misrounds some long
    # decimals), here and by the trajectory reader
    long = [c for c in cells if _significant_digits(c) > 19][:2000]
    got = native.parse_csv(("\n".join(long) + "\n").encode(), 1)[:, 0]
    assert len(long) > 500 and np.array_equal(got.view(np.uint64),
                                              np.array([float(c) for c in long]).view(np.uint64))
    path = tmp_path / "long.csv"
    path.write_text("q1,qd1,qdd1\n" + "".join(f"{c},0,0\n" for c in long))
    got = read(path, 1).q[:, 0]
    want = np.array([float(c) for c in long])
    assert np.array_equal(got.view(np.uint64), want.view(np.uint64))


_CELL = re.compile(r"[+-]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")


def _table_as_python(body: str, cols: int):
    """What the native reader is to give, worked out independently of it: lines at '\n' (the last
    one may end the text; a '\r' before a '\n' is dropped), `cols` cells each a plain decimal
    between spaces or tabs, converted by float(); None for anything else or no row."""
    lines = body.split("\n")
    if lines[-1] == "":
        lines.pop()
    rows = []
    for k, line in enumerate(lines):
        if line.endswith("\r") and k < len(body.split("\n")) - 1:
            line = line[:-1]
        cells = [c.strip(" \t") for c in line.split(",")]
        if len(cells) != cols or not all(_CELL.fullmatch(c) for c in cells):
            return None
        rows.append([float(c) for c in cells])
    return np.array(rows) if rows else None


@needs_cc
def test_parse_csv_reads_random_tables_as_python_does(monkeypatch):
    """Random tables, most of them well formed, some with a byte put in, taken out or changed
    (a line end, a comma, a sign, a CR, a space): the reader accepts exactly the tables the
    grammar above does, and gives float()'s values, bit for bit."""
    import random
    monkeypatch.setenv("VAMPC_NATIVE", "1")
    rng = random.Random(5)

    def number() -> str:
        f = rng.random()
        if f < 0.3:
            return rng.choice(["%.17g", "%s", "%.3f", "%.5e", "%g"]) % rng.uniform(-1e3, 1e3)
        if f < 0.6:
            d = "".join(rng.choice("0123456789") for _ in range(rng.randint(1, 22)))
            at = rng.randint(0, len(d))
            e = rng.choice("eE") + rng.choice(["", "+", "-"]) + str(rng.randint(0, 400))
            return rng.choice(["", "-", "+"]) + d[:at] + "." + d[at:] + (e if rng.random() < 0.4 else "")
        return rng.choice(["0", "-0", "0.", ".0", "1e-400", "1e400", "1e999999", "4.9e-324", "00012",
                           "2.4703282292062327e-324", "1.7976931348623159e308"])
    accepted = 0
    for _ in range(3000):           # (6000 until 2026-12-06: 2 s of the suite more)
        cols = rng.randint(1, 4)
        lines = [",".join(rng.choice(["", "", " ", "\t"]) + number() + rng.choice(["", "", " ", "\t"])
                          for _ in range(cols)) for _ in range(rng.randint(1, 4))]
        body = rng.choice(["\n", "\r\n"]).join(lines) + rng.choice(["", "\n", "\r\n"])
        if rng.random() < 0.4:
            at = rng.randrange(len(body) + 1)
            body = body[:at] + rng.choice(["\r", ",", "\n", " ", "e", "-", ".", "x", ""]) + \
                body[at + rng.randint(0, 1):]
        want, got = _table_as_python(body, cols), native.parse_csv(body.encode(), cols)
        assert (got is None) == (want is None), (body, cols)
        if want is not None:
            accepted += 1
            assert np.array_equal(got.view(np.uint64), want.view(np.uint64)), (body, cols)
    assert accepted > 1000


def _significant_digits(cell: str) -> int:
    mantissa = cell.lstrip("+-").lower().split("e")[0].replace(".", "")
    return len(mantissa.lstrip("0"))


@needs_cc
@pytest.mark.parametrize("body", ["1,2\n\n3,4\n", "1,2,\n", "1,,2", "1\n", "0x10,1", "1_0,2", "nan,1",
                                  "inf,2", "1e,2", ".,1", "1 2,3", '"1",2', "1,2\r", "1\r,2",
                                  "\uff11,2", "", "\n"])
def test_parse_csv_refuses_anything_else(body):
    assert native.parse_csv(body.encode(), 2) is None


def _traj_file(tmp_path, body: str, n=2, t=False, newline="\n") -> Path:
    names = (["t"] if t else []) + header(n)
    path = tmp_path / "traj.csv"
    path.write_bytes((",".join(names) + "\n" + body).replace("\n", newline).encode())
    return path


@pytest.mark.parametrize("mode", ["native", "loadtxt", "slow"])
@pytest.mark.parametrize("newline", ["\n", "\r\n"])
def test_every_path_reads_the_same(tmp_path, monkeypatch, mode, newline):
    rng = np.random.default_rng(1)
    data = rng.normal(size=(50, 7)) * 3
    body = "".join(",".join(map(repr, row.tolist())) + "\n" for row in data)
    path = _traj_file(tmp_path, body, n=2, t=True, newline=newline)
    if mode == "native" and native.compiler() is None:
        pytest.skip("no C compiler")
    monkeypatch.setenv("VAMPC_NATIVE", "1" if mode == "native" else "0")   # 1: no silent fallback
    if mode == "slow":
        from vampc.emulator import trajectory
        monkeypatch.setattr(trajectory, "_loadtxt", lambda body, cols: None)
    traj = read(path, 2)
    assert np.array_equal(traj.t, data[:, 0])
    assert np.array_equal(np.hstack([traj.q, traj.qd, traj.qdd]), data[:, 1:])


@pytest.mark.parametrize("body, message", [
    # (the CR CR LF explanation only where the lines end so: it was given for a plain blank line)
    ("1,2,3,4,5,6\n\n1,2,3,4,5,6\n", r"line 3 is blank: blank lines can only end the table$"),
    ("1,2,3,4,5,6\r\r\n1,2,3,4,5,6\r\r\n", r"line 3 is blank: blank lines can only end the table "
     r"\(lines ended CR CR LF, as a CRLF file saved again as text ends them"),
    ("1,2,3,4,5,6\n1,2,3\n", r"line 3: 3 columns, expected 6$"),
    ("1,2,3,4,x,6\n", r"line 2, column qdd1: 'x' is not a number$"),
    ("1,2,3,4,nan,6\n", r"line 2 \(state 1\), column qdd1: nan is not finite$"),
    ("1,2,3,inf,5,6\n", r"line 2 \(state 1\), column qd2: inf is not finite \(written so, or a number "
                         r"beyond float64's range, about 1\.8e308\)$"),
    ("", r"the trajectory has no states$"),
])
def test_errors_name_the_line_whatever_path(tmp_path, body, message):
    with pytest.raises(VampcError, match=r"^.*traj\.csv: " + message):
        read(_traj_file(tmp_path, body), 2)


def test_a_npy_state_that_is_not_finite_is_named_by_state_and_column(tmp_path):
    data = np.zeros((3, 7))
    data[2, 4] = np.nan                                  # t, q1, q2, qd1, qd2: qd2 of state 3
    np.save(tmp_path / "traj.npy", data)
    with pytest.raises(VampcError, match=r"traj\.npy: state 3, column qd2: nan is not finite$"):
        read(tmp_path / "traj.npy", 2)


def test_quoted_cells_still_read_and_underscored_ones_are_refused(tmp_path):
    # the slow path's float() takes quotes; the fast paths refuse them and hand over. float() also
    # reads 1_0 as 10, which is a typo, not a number: refused with its line and column
    traj = read(_traj_file(tmp_path, '"1",2,3,4,5,6\n'), 2)
    assert traj.q.tolist() == [[1.0, 2.0]] and traj.qdd.tolist() == [[5.0, 6.0]]
    with pytest.raises(VampcError, match=r"line 2, column qdd2: '1_0' is not a number"):
        read(_traj_file(tmp_path, '"1",2,3,4,5,1_0\n'), 2)


def test_write_torques_round_trips(tmp_path):
    tau = np.random.default_rng(2).normal(size=(20, 3)) * 10.0 ** np.arange(-5, 15, 1)[:, None]
    tau[0, 0], tau[0, 1] = -0.0, 0.1
    path = tmp_path / "tau.csv"
    write_torques(path, tau)
    lines = path.read_text().splitlines()
    assert lines[0] == "tau1,tau2,tau3" and len(lines) == 21
    back = np.array([[float(c) for c in line.split(",")] for line in lines[1:]])
    assert np.array_equal(back, tau) and np.signbit(back[0, 0])


@pytest.mark.parametrize("how", ["signal", "timeout"])
def test_an_interrupted_tool_is_killed_with_what_it_started(tmp_path, how):
    """A SIGTERM while gcc ran killed the driver only: its cc1, owned by init, went on compiling
    after vampc had exited (an audit's find); iverilog's ivlpp and ivl likewise (a review's).
    Outside tools run in a process group of their own (background.run_tool), killed whole when the
    run stops waiting: a signal's handler raising, or a timeout. A shell stands for the driver and
    a sleep for what it started. The run stops at once: killed alone, the driver left the sleep
    holding the pipes, and the run waited out its 30 s before it stopped (a mutation audit)."""
    import signal
    import time

    from vampc.background import run_tool
    pidfile = tmp_path / "pid"
    cmd = ["sh", "-c", f"sleep 30 & echo $! > {pidfile}; wait"]
    begun = time.monotonic()
    if how == "signal":
        def interrupt(*_):
            raise KeyboardInterrupt
        old = signal.signal(signal.SIGALRM, interrupt)
        signal.setitimer(signal.ITIMER_REAL, 0.5)
        try:
            with pytest.raises(KeyboardInterrupt):
                run_tool(cmd, input="")
        finally:
            signal.setitimer(signal.ITIMER_REAL, 0)
            signal.signal(signal.SIGALRM, old)
    else:
        with pytest.raises(subprocess.TimeoutExpired):
            run_tool(cmd, timeout=0.5)
    assert time.monotonic() - begun < 10
    pid = int(pidfile.read_text())
    deadline = time.monotonic() + 5
    while time.monotonic() < deadline:
        try:
            state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
        except FileNotFoundError:
            break                                  # gone
        if state in ("Z", "X"):                    # dead, not yet reaped by its new parent
            break
        time.sleep(0.05)
    else:
        os.kill(pid, signal.SIGKILL)
        raise AssertionError(f"the tool's child {pid} still runs")


def test_the_rtl_tools_run_through_the_same_helper(monkeypatch, tmp_path):
    """iverilog (cosim._run) and the YoWASP tools (synth._tool) go through background.run_tool,
    whose whole process group is killed on a signal (the test above): reverting either to
    subprocess.run passed every test (a review's find)."""
    import subprocess as sp

    from vampc import background
    from vampc.rtl import cosim, synth
    calls = []

    def fake(cmd, **kw):
        calls.append(cmd)
        return sp.CompletedProcess(cmd, 0, "out", "")
    monkeypatch.setattr(background, "run_tool", fake)
    cosim._run(["iverilog", "-o", "x"], str(tmp_path))
    assert synth._tool("print(1)", ["a"], str(tmp_path), 5, "yosys") == "out"
    assert calls[0] == ["iverilog", "-o", "x"] and calls[1][1:] == ["-c", "print(1)", "a"]
