"""The op table (vampc.machine.ops): each op defined once, as data, and everything derived from it.

The built-in entries are checked against figures written out here from the paper (Table VII.1's
step shapes, the durations of section III, the ROM pointers of program format v2) and against plain
numpy algebra. An op defined in this file — nothing under vampc/ edited — is compiled, and runs on
the tick engine, the numpy and the generated-C stream engine and the graph evaluator, bit-equal.
"""
from __future__ import annotations

import csv
import io

import numpy as np
import pytest
from click.testing import CliRunner
from conftest import EXAMPLES

from vampc.cli import main
from vampc.compiler import CompileOptions, compile_graph, program_text
from vampc.dataflow.evaluate import evaluate
from vampc.dataflow.graph import GraphBuilder
from vampc.machine import interp, ops
from vampc.machine.ops import (
    ADDER,
    MULT1,
    ROM,
    A,
    B,
    Op,
    OpDef,
    Timing,
    U,
    View,
    add,
    mul,
    registered,
)
from vampc.program.file import write_program
from vampc.robot import load_robot


def test_builtin_shapes_are_table_vii1():
    M, AM, AD = frozenset("M"), frozenset("AM"), frozenset("A")
    want = {"VA": (AD,), "SV": (M,), "VC": (M, AD), "MV": (M, AM, AD), "MTV": (M, AM, AD),
            "MM": (M, AM, AD), "VD": (M, AM, AD)}
    assert {op.value: ops.MICRO_STEPS[op] for op in ops.compute_ops()} == want
    durations = {op.value: Timing().duration(op) for op in ops.compute_ops()}
    assert durations == {"VA": 1, "SV": 1, "VC": 2, "MV": 3, "MTV": 3, "MM": 3, "VD": 3}
    assert Timing().cycle == 4
    assert Timing(3, 2).duration(Op.MV) == 3 + 3 + 2          # M, then max(A, M), then A
    assert [Timing(3, 2).path_counts(op) for op in (Op.VA, Op.VC, Op.MV)] == [(0, 1), (1, 1), (2, 1)]
    assert {op.value: ops.VAMPS_PER_OP[op] for op in ops.compute_ops()} == {
        "VA": 1, "SV": 1, "VC": 1, "MV": 1, "MTV": 1, "MM": 3, "VD": 1}


def test_rom_pointers_are_format_v2():
    assert [(op.value, col) for op, col in ROM] == [
        ("VA", None), ("SV", None), ("VC", None), ("MV", None), ("MTV", None), ("VD", None),
        ("MM", 0), ("MM", 1), ("MM", 2)]


def test_builtin_semantics_against_numpy_algebra():
    rng = np.random.default_rng(5)
    a, b = rng.normal(size=(50, 3)), rng.normal(size=(50, 3))
    m, n = rng.normal(size=(50, 3, 3)), rng.normal(size=(50, 3, 3))
    want = {Op.VA: (a, b, a + b), Op.SV: (a, b, a[:, :1] * b), Op.VC: (a, b, np.cross(a, b)),
            Op.MV: (m, b, np.einsum("nij,nj->ni", m, b)), Op.MTV: (m, b, np.einsum("nji,nj->ni", m, b)),
            Op.MM: (m, n, m @ n), Op.VD: (a, b, np.repeat((a * b).sum(1)[:, None], 3, axis=1))}
    for op, (x, y, expect) in want.items():
        np.testing.assert_allclose(interp.apply(op, x, y), expect, rtol=0, atol=1e-14, err_msg=op.value)
    # the dot sequence's association order, exactly: (A3·B3 + A2·B2) + A1·B1
    got = interp.apply(Op.MV, m, b)[:, 0]
    assert np.array_equal(got, (m[:, 0, 2] * b[:, 2] + m[:, 0, 1] * b[:, 1]) + m[:, 0, 0] * b[:, 0])


def test_malformed_entries_are_refused():
    def entry(steps, result=ADDER):
        return OpDef("BAD", "", ("v", "v"), (View.VECTOR, View.VECTOR), steps, result, (0, 0))
    with pytest.raises(ValueError, match="reads ADDER before"):
        ops.register(entry(((add(ADDER, U(ADDER), A(0)),),)))
    with pytest.raises(ValueError, match="result unit"):
        ops.register(entry(((mul(MULT1, A(0), B(0)),),)))
    with pytest.raises(ValueError, match="already defined"):
        ops.register(OpDef("VA", "", ("v", "v"), (View.VECTOR, View.VECTOR),
                           ((add(ADDER, A(0), B(0)),),), ADDER, (0, 3)))
    assert "BAD" not in [op.value for op in Op] and len(ROM) == 9


# A toy op, defined here only: vector scale-and-add, R = A[0]·B + B, in two steps; its second step
# reads operand B again, so it also exercises the re-latch rules.
SCALE_ADD = OpDef("VSA", "A[0]·B + B", ("v", "v"), (View.VECTOR, View.VECTOR),
                  ((mul(MULT1, A(0), B(0, rot=True)),), (add(ADDER, U(MULT1), B(0, rot=True)),)),
                  ADDER, (3, 3), colour="#e7969c")


def _toy_graph(chain, vsa):
    g = GraphBuilder(chain.n, "linear")
    g.at("bwd", 1)
    v = g.op(Op.MV, g.input("A", 1), g.const([0.3, -1.2, 0.7], "c1"), "v")
    w = g.op(Op.MV, g.input("A", 2), g.const([1.1, 0.4, -0.5], "c2"), "w")
    t = g.op(vsa, v, w, "t")
    u = g.op(Op.VC, t, v, "u")
    s = g.op(vsa, u, t, "s")
    g.output(1, t, 1)
    g.output(2, s, 2)
    return g.build()


def _torques(text: str) -> np.ndarray:
    rows = list(csv.reader(io.StringIO(text)))
    return np.array([[float(x) for x in r] for r in rows[1:]])


@pytest.mark.parametrize("budget", [None, 2], ids=["systolic", "budget-2"])
def test_an_op_defined_in_a_test_runs_everywhere(tmp_path, monkeypatch, budget):
    chain = load_robot(EXAMPLES / "planar2.yaml")
    with registered(SCALE_ADD) as vsa:
        assert ROM[-1] == (vsa, None) and Timing().duration(vsa) == 2
        graph = _toy_graph(chain, vsa)
        compiled = compile_graph(chain, graph, CompileOptions(vamps=budget))
        prog = tmp_path / "toy.vamp.json"
        write_program(program_text(compiled), str(prog))
        states = tmp_path / "states.csv"
        runner = CliRunner()
        got = {}
        for engine, native in (("tick", "0"), ("stream", "0"), ("stream", "1")):
            monkeypatch.setenv("VAMPC_NATIVE", native)
            res = runner.invoke(main, ["emulate", str(prog), "--random", "40", "--seed", "2",
                                       "--engine", engine, "-o", "-", "--save-states", str(states)])
            assert res.exit_code == 0, res.output
            got[(engine, native)] = _torques(res.stdout)
        data = np.loadtxt(states, delimiter=",", skiprows=1, ndmin=2)
        q, qd, qdd = data[:, 0:2], data[:, 2:4], data[:, 4:6]
        evaluated = evaluate(graph, chain, q, qd, qdd)
    for key, tau in got.items():
        assert np.array_equal(tau, evaluated), key           # bit for bit, every engine
    # and the op means what its entry says: A[0]·B + B, against plain numpy
    a1, a2 = (np.array([_dh(chain, i, qi) for qi in q[:, i]]) for i in range(2))
    v = np.einsum("nij,j->ni", a1, [0.3, -1.2, 0.7])
    w = np.einsum("nij,j->ni", a2, [1.1, 0.4, -0.5])
    t = v[:, :1] * w + w
    s = np.cross(t, v)[:, :1] * t + t
    np.testing.assert_allclose(evaluated, np.stack([t[:, 1], s[:, 2]], axis=1), rtol=1e-12, atol=1e-12)
    assert "VSA" not in [op.value for op in Op] and len(ROM) == 9     # unregistered again


def _dh(chain, i, qi):
    """A_i(q_i) = Rz(θ) Rx(α) of a revolute DH joint, computed here independently."""
    joint = chain.joints[i]
    th = qi + joint.offset
    c, s = np.cos(th), np.sin(th)
    rz = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
    return rz @ np.asarray(joint.phi)
