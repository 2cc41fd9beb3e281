"""The arithmetic interface (vampc.machine.arith): a word format defined in this file — float64
storage with every result rounded to binary32 — runs through the tick engine, the numpy stream engine
and the graph evaluator, which all do their arithmetic through it, bit-equal to each other, and
differs from float64 by binary32's rounding. The C path, whose rows are doubles, refuses it."""
from __future__ import annotations

import numpy as np
import pytest
from conftest import EXAMPLES

from vampc.compiler import CompileOptions, compile_chain
from vampc.dataflow.evaluate import evaluate
from vampc.emulator import emulate, loaded_from_compiled, native
from vampc.emulator.host import random_trajectory
from vampc.emulator.load import Loaded
from vampc.emulator.stream import flow
from vampc.emulator.timing import derive
from vampc.machine.arith import Float64, Fn
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
    with pytest.raises(native.NativeError, match="no native path for rounded32"):
        native.build(ld, flow(ld, derive(ld)))
