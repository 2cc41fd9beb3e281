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
