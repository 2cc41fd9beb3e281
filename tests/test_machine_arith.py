"""The arithmetic interface (vampc.machine.arith): a word format defined in this file — float64
storage with every result rounded to binary32 — runs through the tick engine, the numpy stream engine
and the graph evaluator, which all do their arithmetic through it, bit-equal to each other, and
differs from float64 by binary32's rounding. The C path, whose rows are doubles, refuses it.

A word format added as README's *Extending vampc* says (a class in vampc.machine.arith, named by
parse_word) — IEEE binary16 here — packs its Program-Mode words, runs in the tick engine, numpy and
the generated C alike, and has its bits flipped by faults, each from the class alone: the integers it
holds and a half's bit pattern are worked out here independently (Python's struct)."""
from __future__ import annotations

import math
import struct

import numpy as np
import pytest
from conftest import EXAMPLES

from vampc.compiler import CompileOptions, compile_chain
from vampc.dataflow.evaluate import evaluate
from vampc.emulator import emulate, loaded_from_compiled, native
from vampc.emulator.faults import set_bit
from vampc.emulator.host import random_trajectory
from vampc.emulator.load import Loaded
from vampc.emulator.stream import flow
from vampc.emulator.timing import derive
from vampc.machine import arith
from vampc.machine.arith import Float32, Float64, Fn
from vampc.program.words import Packing
from vampc.robot import load_robot


class Rounded32(Float64):
    """Each unit's result rounded to the nearest binary32 (stored as a float64)."""

    name = "rounded32"
    c_type = "float"

    def apply(self, fn: Fn, x, y):
        return np.asarray(super().apply(fn, x, y), dtype=np.float32).astype(np.float64)


def test_a_word_format_defined_here_runs_in_every_python_engine(monkeypatch):
    chain = load_robot(EXAMPLES / "puma560.yaml")
    c = compile_chain(chain, CompileOptions(recursion="log"))
    ld = loaded_from_compiled(c)
    traj = random_trajectory(chain, 20, 7)
    exact = emulate(ld, traj, "stream").tau
    monkeypatch.setenv("VAMPC_NATIVE", "0")
    monkeypatch.setattr(Loaded, "arith", property(lambda self: Rounded32()))
    stream = emulate(ld, traj, "stream").tau
    tick = emulate(ld, traj, "tick").tau
    evaluated = evaluate(c.graph, chain, traj.q, traj.qd, traj.qdd, arith=Rounded32())
    assert np.array_equal(stream, tick) and np.array_equal(stream, evaluated)
    assert not np.array_equal(stream, exact)
    np.testing.assert_allclose(stream, exact, rtol=1e-4, atol=1e-4 * np.abs(exact).max())
    if native.compiler() is not None:   # (its c_type, float, is not its dtype's size: refused)
        with pytest.raises(native.NativeError,
                           match="rounded32 words: c_type float is not the size of dtype float64"):
            native.build(ld, flow(ld, derive(ld)))


class Float16(Float32):
    """IEEE binary16, as a developer would add it: numpy's float16, C's _Float16 (each result
    computed in binary32, where a sum or product of two halves is exact or rounded harmlessly
    before its one rounding to a half, as numpy computes float16)."""

    name = "float16"
    c_type = "_Float16"
    dtype = np.float16
    bits = 16
    check_tolerance = 1e-2

    def rounding_error(self, magnitude: float) -> float:
        return magnitude * 2.0 ** -11

    def c_expr(self, fn: Fn, x: str, y: str) -> str:
        return f"h_{fn.value}({x}, {y})"

    def c_prelude(self) -> str:
        return "#include <math.h>\nlong vamp_overflows;\n" + "".join(
            f"static inline _Float16 h_{fn.value}(_Float16 x, _Float16 y) {{ _Float16 r = "
            f"(_Float16)((float)x {op} (float)y); if (!isfinite((float)r)) vamp_overflows++; "
            "return r; }\n" for fn, op in self._C.items())

    def c_literal(self, value: float) -> str:
        x = float(self.fresh().encode(value))
        assert math.isfinite(x)
        return f"((_Float16){x.hex()})"


def test_a_word_format_added_to_arith_packs_runs_in_every_engine_and_flips(monkeypatch):
    named = arith.parse_word
    monkeypatch.setattr(arith, "parse_word",
                        lambda text, *a: Float16() if text == "float16" else named(text, *a))
    # the integers a half holds exactly, found here: all below 2^11, and 2^11 + 1 not
    b = next(k for k in range(1, 17) if any(struct.unpack("<e", struct.pack("<e", i))[0] != i
                                          for i in range(1 << k, 1 << (k + 1)) if i < 65504))
    assert b == 11 and Packing.of(Float16()) == Packing(1 << 5, 1 << 11)
    chain = load_robot(EXAMPLES / "planar2.yaml")
    c = compile_chain(chain, CompileOptions(word="float16", layout="folded"))
    words = np.array([w for e in c.stream for w in e.words])
    assert np.abs(words).max() < 1 << 11 and np.abs(words).max() >= 1 << 5   # packed for a half
    ld = loaded_from_compiled(c)          # (the stream must deliver the listed programs)
    assert ld.arith.name == "float16"
    traj = random_trajectory(chain, 70, 3)
    monkeypatch.setenv("VAMPC_NATIVE", "0")
    numpy_tau = emulate(ld, traj, "stream").tau
    tick = emulate(ld, traj, "tick").tau
    evaluated = evaluate(c.graph, chain, traj.q, traj.qd, traj.qdd, arith=Float16())
    assert np.array_equal(numpy_tau, tick) and np.array_equal(numpy_tau, evaluated)
    exact = emulate(loaded_from_compiled(compile_chain(chain, CompileOptions(layout="folded"))),
                    traj, "stream").tau
    assert not np.array_equal(numpy_tau, exact)
    assert np.abs(numpy_tau - exact).max() <= 1e-2 * np.abs(exact).max()
    if native.compiler() is not None:
        monkeypatch.setenv("VAMPC_NATIVE", "1")
        assert np.array_equal(emulate(ld, traj, "stream").tau, numpy_tau)
    # with error correction: the checking engine compares the half's own bits, flags nothing
    checked = loaded_from_compiled(compile_chain(chain, CompileOptions(
        word="float16", layout="folded", error_correction=True)))
    assert np.array_equal(emulate(checked, traj, "tick").tau, numpy_tau)
    # a fault flips the half's own bit (its pattern by struct, not numpy)
    values = np.array([1.0, -2.5, 0.0, 65504.0, 3e-5], dtype=np.float16)
    for bit in (0, 9, 10, 14, 15):
        flipped = set_bit(Float16(), values, bit, "flip")
        assert flipped.dtype == np.float16
        for v, f in zip(values.tolist(), flipped.tolist()):
            (raw,) = struct.unpack("<H", struct.pack("<e", v))
            want = struct.unpack("<e", struct.pack("<H", raw ^ (1 << bit)))[0]
            assert f == want or (math.isnan(f) and math.isnan(want))
