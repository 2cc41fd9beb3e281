"""Golden dump of the planar2 linear graph and its ASAP schedule (tests/golden/planar2-linear.txt).

The dump is canonical: one node per line in id order, `id op args section group name start finish`,
then the outputs and the schedule summary; no floating-point values, no memory ids. Rewrite it only
with `pytest --update-golden`, then read the diff against Table III.1 before committing.
"""
from __future__ import annotations

import difflib

from conftest import EXAMPLES, GOLDEN
from vampc.dataflow.linear import build_linear
from vampc.robot import load_robot
from vampc.schedule.asap import schedule_asap


def dump(graph, sched) -> str:
    """The canonical text of a graph and its schedule."""
    lines = [f"# {graph.recursion} graph, n = {graph.n}: id op args section group name start finish"]
    for nd in sorted(graph.nodes, key=lambda nd: nd.id):
        args = ",".join(map(str, nd.args)) or "-"
        lines.append(f"{nd.id} {nd.op.value} {args} {nd.section} {nd.group} {nd.name} "
                     f"{sched.start[nd.id]} {sched.finish[nd.id]}")
    lines += [f"output tau{o.joint} = node {o.node} component {o.component}"
              for o in sorted(graph.outputs, key=lambda o: o.joint)]
    lines.append(f"latency {sched.latency} = {sched.mults} M + {sched.adds} A, interval {sched.interval}")
    lines.append("critical path " + " ".join(map(str, sched.critical_path)))
    return "\n".join(lines) + "\n"


def test_planar2_linear_golden(update_golden):
    chain = load_robot(EXAMPLES / "planar2.yaml")
    graph = build_linear(chain)
    text = dump(graph, schedule_asap(graph))
    path = GOLDEN / "planar2-linear.txt"
    if update_golden:
        path.parent.mkdir(exist_ok=True)
        path.write_text(text)
    want = path.read_text()
    diff = "".join(difflib.unified_diff(want.splitlines(True), text.splitlines(True), str(path), "now"))
    assert text == want, "golden mismatch (rerun with --update-golden if intended):\n" + diff


# --- the IR dumps of `vampc compile --dump-after STAGE` ----------------------------------------------

import pytest  # noqa: E402

from vampc.compiler import CompileOptions, compile_chain  # noqa: E402
from vampc.dump import dump_after  # noqa: E402

DUMPS = [  # (robot, what, stage, options)
    (robot, what, stage, opts)
    for robot in ("planar2", "puma560")
    for what, stage, opts in (
        ("graph-linear", "graph", {}), ("graph-log", "graph", {"recursion": "log"}),
        ("network-systolic", "allocate", {}), ("network-folded", "allocate", {"layout": "folded"}),
        ("program-systolic", "emit", {}),
        ("program-folded", "emit", {"layout": "folded", "share_passes": True}))
]


@pytest.mark.parametrize("robot,what,stage,opts", DUMPS, ids=[f"{r}-{w}" for r, w, _, _ in DUMPS])
def test_ir_dump_golden(robot, what, stage, opts, update_golden):
    c = compile_chain(load_robot(EXAMPLES / f"{robot}.yaml"), CompileOptions(**opts))
    text = dump_after(stage, c)
    path = GOLDEN / f"{robot}-{what}.txt"
    if update_golden:
        path.write_text(text)
    want = path.read_text()
    diff = "".join(difflib.unified_diff(want.splitlines(True), text.splitlines(True), str(path), "now"))
    assert text == want, "golden mismatch (rerun with --update-golden if intended):\n" + diff
