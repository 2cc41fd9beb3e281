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
    MULT2,
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
    # a step needing more than a module's two multipliers and one adder: the RTL alone refused it,
    # and both emulators ran it (a new developer's find)
    with pytest.raises(ValueError, match="step 1 needs 3 multipliers and 0 adders, where a module has 2 and 1"):
        ops.register(entry(((mul(MULT1, A(0), B(0)), mul(MULT2, A(1), B(1)), mul(ADDER, A(2), B(2))),)))
    with pytest.raises(ValueError, match="step 2 needs 0 multipliers and 2 adders"):
        ops.register(entry(((mul(MULT1, A(0), B(0)),),
                            (add(ADDER, U(MULT1), A(1)), add(MULT2, U(MULT1), B(1))))))
    assert "BAD" not in [op.value for op in Op] and len(ROM) == 9


def test_an_entry_without_rom_takes_the_pointers_after_those_given():
    """A built-in entry without `rom` had failed the import (None + column); it takes the next free
    pointers after every one the entries give, wherever it stands among them."""
    new = OpDef("NEW", "", ("v", "v"), (View.VECTOR, View.VECTOR), ((add(ADDER, A(0), B(0)),),),
                ADDER, (0, 3))
    wide = OpDef("WIDE", "", ("m", "m"), (View.ROW, View.BCOLUMN), ops.BUILTIN[-2].steps, ADDER,
                 (27, 18), columns=3)
    builtin = list(ops.BUILTIN)
    assert ops._first_pointers(builtin) == [0, 1, 2, 3, 4, 6, 5]
    assert ops._first_pointers(builtin[:3] + [wide, new] + builtin[3:]) == [0, 1, 2, 9, 12, 3, 4, 6, 5]


def test_each_ops_serial_work_is_what_its_steps_compute():
    """`serial` (the paper's charge, which the report's serial counts and Table O.1 take) against
    the micro-steps: every module's products and sums, over the op's columns. VD alone is charged a
    third: its three modules compute the same dot product, which a serial machine computes once."""
    for op in ops.compute_ops():
        entry = ops.TABLE[op]
        kinds = [a.fn.unit for step in entry.steps for a in step]
        work = (3 * entry.columns * kinds.count("M"), 3 * entry.columns * kinds.count("A"))
        repeated = 3 if op is Op.VD else 1
        assert tuple(w // repeated for w in work) == entry.serial, op
        assert all(w % repeated == 0 for w in work)


# A toy op, defined here only: vector scale-and-add, R = A[0]·B + B, in two steps; its second step
# reads operand B again, so it also exercises the re-latch rules.
SCALE_ADD = OpDef("VSA", "A[0]·B + B", ("v", "v"), (View.VECTOR, View.VECTOR),
                  ((mul(MULT1, A(0), B(0, rot=True)),), (add(ADDER, U(MULT1), B(0, rot=True)),)),
                  ADDER, (3, 3), colour="#e7969c")
# Another, R = (A[0]·B + B) + A[1]·B, whose second step overwrites MULT-1 while the adder reads it:
# the step's assignments read the registers as the step began, which the generated C keeps with
# temporaries (no built-in op orders a step so; breaking that path had passed every test: a new
# developer's find).
SCALE_ADD_TWICE = OpDef("VSA2", "(A[0]·B + B) + A[1]·B", ("v", "v"), (View.VECTOR, View.VECTOR),
                        ((mul(MULT1, A(0), B(0, rot=True)),),
                         (mul(MULT1, A(1), B(0, rot=True)), add(ADDER, U(MULT1), B(0, rot=True))),
                         (add(ADDER, U(ADDER), U(MULT1)),)),
                        ADDER, (6, 6), colour="#e7969c")
_MEANING = {"VSA": lambda a, b: a[:, :1] * b + b,
            "VSA2": lambda a, b: (a[:, :1] * b + b) + a[:, 1:2] * b}


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


@pytest.mark.parametrize("toy, budget", [(SCALE_ADD, None), (SCALE_ADD, 2), (SCALE_ADD_TWICE, None)],
                         ids=["systolic", "budget-2", "overwrite-while-read"])
def test_an_op_defined_in_a_test_runs_everywhere(tmp_path, monkeypatch, toy, budget):
    chain = load_robot(EXAMPLES / "planar2.yaml")
    with registered(toy) as vsa:
        assert ROM[-1] == (vsa, None) and Timing().duration(vsa) == len(toy.steps)
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
    # and the op means what its entry says, against plain numpy
    a1, a2 = (np.array([_dh(chain, i, qi) for qi in q[:, i]]) for i in range(2))
    v = np.einsum("nij,j->ni", a1, [0.3, -1.2, 0.7])
    w = np.einsum("nij,j->ni", a2, [1.1, 0.4, -0.5])
    meaning = _MEANING[toy.name]
    t = meaning(v, w)
    s = meaning(np.cross(t, v), t)
    np.testing.assert_allclose(evaluated, np.stack([t[:, 1], s[:, 2]], axis=1), rtol=1e-12, atol=1e-12)
    assert toy.name not in [op.value for op in Op] and len(ROM) == 9     # unregistered again


def _dh(chain, i, qi):
    """A_i(q_i) = Rz(θ) Rx(α) of a revolute DH joint, computed here independently."""
    joint = chain.joints[i]
    th = qi + joint.offset
    c, s = np.cos(th), np.sin(th)
    rz = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
    return rz @ np.asarray(joint.phi)


@pytest.mark.parametrize("word", ["float64", "q8.8"])
def test_a_step_on_gathered_rows_reads_what_the_registers_hold(word):
    """The tick engine's micro-step (interp.step_rows: each module's register read straight from
    the operand rows) against interp.step on interp.registers (every module's nine registers
    gathered first), for every ROM entry and step: the same unit values, bit for bit, and in a
    narrow word the same overflows, counted row by row."""
    from vampc.machine.arith import parse_word
    rng = np.random.default_rng(7)
    overflowed = 0
    for r in range(len(ROM)):
        gathered, direct, host = parse_word(word), parse_word(word), parse_word(word)
        op_a, op_b = (host.encode(rng.normal(0, 20, (12, 9))) for _ in range(2))
        rows = np.array([3, 0, 11, 3, 7])
        start = host.encode(rng.normal(0, 20, (len(rows), 3, 3)))
        units_g, units_d = start.copy(), start.copy()
        am, bm = interp.registers(r, op_a, op_b, rows)
        for k in range(interp.steps(r)):
            gathered.track, direct.track = [], []
            interp.step(r, k, am, bm, units_g, gathered)
            interp.step_rows(r, k, op_a, op_b, rows, units_d, direct)
            assert units_g.tobytes() == units_d.tobytes(), (ROM[r], k)
            assert [t.tolist() for t in gathered.track] == [t.tolist() for t in direct.track]
        assert gathered.overflows == direct.overflows
        overflowed = overflowed or direct.overflows
    assert word == "float64" or overflowed      # (q8.8: some products overflowed)
