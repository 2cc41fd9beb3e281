"""Graphviz output (vampc.report.dot): the network and the dataflow graph as two digraphs."""
from __future__ import annotations

import re
import shutil
import subprocess

import pytest
from conftest import EXAMPLES

from vampc.compiler import CompileOptions, compile_chain
from vampc.report.dot import quote, report_dot
from vampc.robot import load_robot


@pytest.fixture(scope="module", params=[dict(), dict(recursion="log", layout="folded")],
                ids=["linear-systolic", "log-folded"])
def compiled(request):
    return compile_chain(load_robot(EXAMPLES / "planar2.yaml"), CompileOptions(**request.param))


def test_every_vamp_buffer_port_and_node_appears(compiled):
    text = report_dot(compiled.graph, compiled.layout, compiled.network, "planar2")
    net, flow = text.split("\ndigraph dataflow {")
    assert net.startswith("digraph network {")
    assert len(set(re.findall(r"^\s+v(\d+) \[label=", net, re.M))) == len(compiled.network.vamps)
    assert len(re.findall(r"^\s+b\d+ \[shape=square", net, re.M)) == len(compiled.network.buffers)
    assert len(re.findall(r"^\s+p\d+ \[shape=invtriangle", net, re.M)) == len(compiled.network.ports)
    inputs = sum(len(op.taps) for v in compiled.network.vamps for op in v.a + v.b)
    assert len(re.findall(r"-> v\d+ \[label=", net)) == inputs
    assert len(re.findall(r"^\s+n\d+ \[", flow, re.M)) == len(compiled.graph.nodes)
    assert len(re.findall(r"^\s+n\d+ -> n\d+;", flow, re.M)) == \
        sum(len(nd.args) for nd in compiled.graph.nodes)


@pytest.mark.skipif(shutil.which("dot") is None, reason="Graphviz (dot) is not installed")
def test_graphviz_reads_both_graphs(compiled, tmp_path):
    path = tmp_path / "n.dot"
    path.write_text(report_dot(compiled.graph, compiled.layout, compiled.network, "planar2"))
    out = subprocess.run(["dot", "-Tsvg", str(path)], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    assert out.stdout.count("<svg") == 2


def test_quote():
    assert quote('a "b"\\c\nd') == '"a \\"b\\"\\\\c\\nd"'


@pytest.mark.parametrize("aggregate", [False, True])
def test_a_floating_bases_wrench_outputs_are_named_as_the_torque_files_columns(aggregate,
                                                                             monkeypatch):
    """The quadruped on a floating base has 12 joints and 18 outputs: the DOT labelled the last six
    τ13..τ18, joints it does not have, where the drawing and the torque file say base_fx..base_nz
    (an audit's)."""
    from vampc.emulator.trajectory import WRENCH_COLUMNS
    from vampc.report import dot
    if aggregate:
        monkeypatch.setattr(dot, "DETAIL_VAMPS", 1)
    chain = load_robot(EXAMPLES / "quadruped.urdf", floating=True)
    c = compile_chain(chain, CompileOptions())
    text = report_dot(c.graph, c.layout, c.network, chain.name)
    labels = dict(re.findall(r"  tau(\d+) \[shape=house[^]]*label=\"([^\"]+)\"", text))
    assert sorted(map(int, labels)) == list(range(1, 19))
    assert [labels[str(j)].rstrip("…") for j in range(13, 19)] == list(WRENCH_COLUMNS)
    assert all(labels[str(j)].rstrip("…") == f"τ{j}" for j in range(1, 13))


def test_an_mm_members_operand_b_is_one_wire_from_its_columns_vamp():
    """The VAMP computing column c of A·B reads column c of B: one wire, from the VAMP making that
    column (found here from the graph: the node B comes from, the column computed), as the pins
    count it; the DOT had drawn three (a hardware user counted 12 pins from it where the report
    said 10), and the fan-out counted them too. The fan-out and the most pins a VAMP needs are
    worked out again from the edges drawn."""
    from vampc.report.compare import max_fan_out
    from vampc.report.processors import vamp_pins
    c = compile_chain(load_robot(EXAMPLES / "puma560.yaml"), CompileOptions(recursion="log"))
    net = report_dot(c.graph, c.layout, c.network, "puma").split("\ndigraph dataflow {")[0]
    edges = re.findall(r'^\s+([vbpk])(\d+) -> v(\d+) \[label="([AB])\d+', net, re.M)
    buffer_of = {int(b): int(v) for v, b in re.findall(r"v(\d+) -> b(\d+);", net)}
    vamps = c.network.vamps
    members = [v for v in vamps if v.slots[0].op.name == "MM"]
    made_by_vamps = 0
    for v in members:
        s = v.slots[0]
        b_from = [(kind, int(i)) for kind, i, to, side in edges if int(to) == v.index and side == "B"]
        assert len(b_from) == 1, (v.index, b_from)
        kind, i = b_from[0]
        arg = c.graph.nodes[c.graph.nodes[s.node].args[1]]
        if kind in "pk":         # (a host port's or constant's matrix: one input of its own)
            assert not arg.op.is_compute
            continue
        source = vamps[i if kind == "v" else buffer_of[i]].slots[0]
        assert source.node == arg.id and source.column == s.column
        made_by_vamps += 1
    assert made_by_vamps == 18       # (the MM members reading a matrix other VAMPs make)
    drives = {}
    for kind, i, _, _ in edges:
        if kind in "vb":
            src = int(i) if kind == "v" else buffer_of[int(i)]
            drives[src] = drives.get(src, 0) + 1
    assert max_fan_out(c.network) == max(drives.values())
    into = {}
    for _, _, to, _ in edges:
        into[int(to)] = into.get(int(to), 0) + 1
    assert max(vamp_pins(v)["separate"] for v in vamps) == 6 + max(into.values()) == 10
