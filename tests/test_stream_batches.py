"""The stream engine's batched numpy path (vampc.emulator.stream.Batches: one rom.run per level and
ROM entry) against the flow run one op at a time (run_per_op), bit for bit and overflow for
overflow, over layouts, recursions, words and robots; chunks of sets kept within VALUE_BYTES. The
batched path is what runs a big network (a 1024-joint log network over 4096 sets had taken 21 GB
one op at a time) and short runs."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from vampc.compiler import CompileOptions, compile_chain, program_document
from vampc.emulator import check_program, loaded_from_doc
from vampc.emulator import stream as st
from vampc.emulator.host import port_values, random_trajectory
from vampc.kinds import FlowKind
from vampc.robot import load_robot
from vampc.robot.random import random_chain

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


def _prepared(chain, count=37, seed=3, scale=1.0, **opts):
    ld = loaded_from_doc(program_document(compile_chain(chain, CompileOptions(**opts))))
    traj = random_trajectory(ld.chain, count, seed)
    if scale != 1.0:
        from dataclasses import replace
        traj = replace(traj, qd=traj.qd * scale, qdd=traj.qdd * scale ** 2)
    fl = st.flow(ld, check_program(ld))
    values = port_values(ld, traj)
    return ld, fl, {i: values[(p, e)] for i, (p, e, _) in enumerate(fl.inputs)}, count


def _both(ld, fl, ports, count):
    """(batched torques, its overflows, per-op torques, its overflows)."""
    ld.arith.overflows = 0
    plan = st.Batches(fl)
    assert plan.plain
    batched = st._chunks(ld, count, None, plan.chunk(ld.arith), ports,
                         lambda chunk, n, consts: plan.run(ld, chunk, n, consts))
    over_b, ld.arith.overflows = ld.arith.overflows, 0
    one = st.run_per_op(ld, fl, ports, count)
    return batched, over_b, one, ld.arith.overflows


CASES = [("puma560.yaml", {}), ("puma560.yaml", {"recursion": "log"}),
         ("puma560.yaml", {"layout": "folded"}), ("puma560.yaml", {"vamps": 12}),
         ("stanford.yaml", {"recursion": "log", "layout": "folded"}),
         ("quadruped.urdf", {}), ("arm6.urdf", {"recursion": "log"}),
         ("puma560.yaml", {"word": "float32"}), ("puma560.yaml", {"word": "q16.16"}),
         ("planar2.yaml", {"word": "q24.40", "recursion": "log"}),
         ("puma560.yaml", {"word": "q12.20", "rounding": "truncate", "overflow": "wrap"})]


@pytest.mark.parametrize("robot, opts", CASES, ids=[f"{r}-{o}" for r, o in CASES])
def test_batches_give_the_per_op_bits(robot, opts):
    fast, over_b, one, over_o = _both(*_prepared(load_robot(EXAMPLES / robot), **opts))
    assert np.count_nonzero(one) > one.size // 2           # torques, not zeros
    assert fast.tobytes() == one.tobytes() and over_b == over_o      # (bits: -0.0 is not 0.0)


def test_overflows_are_counted_alike():
    ld, fl, ports, count = _prepared(load_robot(EXAMPLES / "puma560.yaml"), scale=40.0, word="q8.8")
    fast, over_b, one, over_o = _both(ld, fl, ports, count)
    assert over_o > 0 and over_b == over_o and fast.tobytes() == one.tobytes()


def test_a_floating_base_and_random_chains():
    for chain, opts in ((load_robot(EXAMPLES / "quadruped.urdf", floating=True), {}),
                        (random_chain(7, 5), {"recursion": "log"}),
                        (random_chain(9, 2), {"layout": "folded", "recursion": "log"})):
        fast, _, one, _ = _both(*_prepared(chain, **opts))
        assert fast.tobytes() == one.tobytes()


def test_chunks_stay_within_the_value_budget_and_give_the_same_bits(monkeypatch):
    ld, fl, ports, count = _prepared(load_robot(EXAMPLES / "puma560.yaml"), count=50,
                                     recursion="log")
    whole = st.run_per_op(ld, fl, ports, count)
    plan = st.Batches(fl)
    monkeypatch.setattr(st, "VALUE_BYTES", plan.rows * 3 * 8 * 7)      # 7 sets a chunk
    seen = []
    got = st.run_numpy(ld, fl, ports, count, progress=lambda done, total: seen.append(done))
    assert seen == [7 * k for k in range(1, 8)] + [50]                  # batched, 8 chunks
    assert got.tobytes() == whole.tobytes()
    monkeypatch.setattr(st, "BATCHED_BELOW", 1)                         # one op at a time
    seen.clear()
    got = st.run_numpy(ld, fl, ports, count, progress=lambda done, total: seen.append(done))
    size = plan.rows * 7 // len(fl.ops)              # its values: every op's, not the inputs'
    assert seen == list(range(size, count, size)) + [count] and got.tobytes() == whole.tobytes()


def test_a_matrix_not_made_of_op_results_runs_op_by_op():
    """A three-column operand whose columns are not all op results (no compiled program has one):
    Batches says it cannot hold it, and run_numpy runs the flow one op at a time."""
    ld, fl, ports, count = _prepared(load_robot(EXAMPLES / "puma560.yaml"), recursion="log")
    i = next(i for i, (_, a, _) in enumerate(fl.ops) if len(a) == 3)
    r, a, b = fl.ops[i]
    some_input = next(src for _, x, y in fl.ops for src in x + y if src[0] is FlowKind.IN
                      and fl.inputs[src[1]][2] == 3)
    ops = list(fl.ops)
    ops[i] = (r, (some_input,) + a[1:], b)
    edited = st.Flow(tuple(ops), fl.names, fl.inputs, fl.outputs)
    assert not st.Batches(edited).plain

    def refused(*args):
        raise AssertionError("Batches.run on a flow it cannot hold")
    import pytest as _pytest
    with _pytest.MonkeyPatch.context() as mp:
        mp.setattr(st.Batches, "run", refused)
        got = st.run_numpy(ld, edited, ports, count)               # (short: batched if it could)
    assert got.tobytes() == st.run_per_op(ld, edited, ports, count).tobytes()


def test_overflow_sites_are_found_chunk_by_chunk_alike(monkeypatch):
    """overflow_sites ran a run's every set at once, one op at a time, keeping every op's values:
    the memory the chunks above bound. Chunked, it finds the same first sites, in set order."""
    chain = load_robot(EXAMPLES / "puma560.yaml")
    ld, fl, _, count = _prepared(chain, count=40, word="q10.16")
    traj = random_trajectory(ld.chain, count, 3)
    fast = np.arange(count)[:, None] % 5 == 2             # sets 3, 8, 13, ...: fast, overflowing
    traj.qd[:] = np.where(fast, traj.qd * 30.0, traj.qd)
    traj.qdd[:] = np.where(fast, traj.qdd * 900.0, traj.qdd)
    whole = st.overflow_sites(ld, fl, traj, limit=400)
    sets = {int(w.split(",")[0].split()[1]) for w in whole}
    assert len(sets) > 3 and min(sets) == 3, sorted(sets)
    monkeypatch.setattr(st, "VALUE_BYTES", len(fl.ops) * 3 * 8 * 4)           # 4 sets a chunk
    assert st.overflow_sites(ld, fl, traj, limit=400) == whole
    assert st.overflow_sites(ld, fl, traj, limit=5) == whole[:5]
