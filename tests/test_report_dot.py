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
