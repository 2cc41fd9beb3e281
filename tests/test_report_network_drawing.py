"""The network drawing (vampc.report.network_drawing): recursion or device nodes as circles placed as
in the paper's figures, delay buffers as squares, host ports and outputs at the edges."""
from __future__ import annotations

import xml.etree.ElementTree as ET
from collections import Counter

import pytest
from conftest import EXAMPLES

from vampc.compiler import CompileOptions, compile_chain
from vampc.report import network_drawing as nd
from vampc.robot import load_robot

SVG = "{http://www.w3.org/2000/svg}"


def ids(svg: str) -> list[str]:
    return [g.get("id") for g in ET.fromstring(svg).iter(f"{SVG}g") if g.get("id")]


@pytest.fixture(scope="module")
def puma():
    return load_robot(EXAMPLES / "puma560.yaml")


def test_linear_systolic_is_three_rows_of_joints(puma):
    c = compile_chain(puma)
    d = nd.drawing(c.graph, c.layout, c.network)
    places = {f"{s.section}{s.index}": p for s, p in d.places.items()}
    assert places["bwd1"] == (0, 0) and places["npv6"] == (5, 1) and places["fwd3"] == (2, 2)
    assert d.labels[next(s for s in d.places if s.section == "fwd" and s.index == 1)] == "fwd 1\n(1,6)"
    got = ids(nd.network_svg(c.graph, c.layout, c.network, "t"))
    assert sum(i.startswith("site-") for i in got) == 18
    assert sum(i.startswith("buffer-") for i in got) == len(d.buffered)
    assert sum(i.startswith("tau-") for i in got) == 6
    assert sum(i.startswith("port-") for i in got) == len([p for p in d.ports if p[1]])


def test_log_systolic_places_nodes_by_tier(puma):
    c = compile_chain(puma, CompileOptions(recursion="log", uniform_leaves=True))
    d = nd.drawing(c.graph, c.layout, c.network)
    bwd = [p for s, p in d.places.items() if s.section == "bwd"]
    assert len(bwd) == 13 and max(y for _, y in bwd) == 3      # leaves and three tiers (n = 6)
    assert d.vamps[next(s for s in d.places if s.section == "bwd")] == 26


def test_folded_draws_device_nodes_with_feedback_buffers(puma):
    c = compile_chain(puma, CompileOptions(layout="folded", share_passes=True))
    d = nd.drawing(c.graph, c.layout, c.network)
    assert {s.section for s in d.places} == {"bwd", "npv"}      # the forward pass runs on bwd's VAMPs
    assert sum(d.vamps.values()) == len(c.network.vamps) == 22
    assert any(a == b for a, b in d.buffered)                   # a device feeding itself


def test_a_folded_drawings_tooltips_name_its_nodes_as_its_circles_do(puma):
    """The circles of a folded drawing say 'bwd dev 0'; the tooltips of its buffers, ports and
    outputs said 'bwd 0' (a new user's find): each names a node as its circle does."""
    import re
    c = compile_chain(puma, CompileOptions(layout="folded"))
    svg = nd.network_svg(c.graph, c.layout, c.network, "t")
    said = re.findall(r"(?:read by|delay buffers from|to|leave[s]?) ((?:bwd|npv|fwd)(?: dev)? \d+)", svg)
    assert said and all(" dev " in name for name in said), sorted(set(said))[:8]


def test_a_big_drawing_uses_one_path_per_kind(puma, monkeypatch):
    c = compile_chain(puma, CompileOptions(recursion="log"))
    monkeypatch.setattr(nd, "DETAIL", 3)
    got = ids(nd.network_svg(c.graph, c.layout, c.network, "t"))
    assert not any(i.startswith("site-") for i in got)
    assert {"sites-bwd", "sites-npv", "sites-fwd", "buffers", "ports"} <= set(got)


_PICTURES = """
import sys
from click.testing import CliRunner
from vampc.cli import main
robot, out = sys.argv[1], sys.argv[2]
for args in (["report", robot, "--html", out + "/systolic.html"],
             ["report", robot, "--vamps", "6", "--html", out + "/budget.html"],
             ["report", robot, "--layout", "folded", "--html", out + "/folded.html"],
             ["report", robot, "--recursion", "log", "--html", out + "/log.html"],
             ["emulate", robot, "--random", "5", "--engine", "tick", "--vcd", out + "/ticks.vcd"]):
    res = CliRunner().invoke(main, args)
    assert res.exit_code == 0, res.output
"""


def test_pictures_and_waveforms_are_the_same_bytes_whatever_the_hash_seed(tmp_path):
    # the order of a set or dict of strings changes with PYTHONHASHSEED from one process to the
    # next, which drawing the same network twice in one process cannot show: two processes, two seeds
    import os
    import subprocess
    import sys
    made = []
    for seed in ("1", "2"):
        out = tmp_path / seed
        out.mkdir()
        subprocess.run([sys.executable, "-c", _PICTURES, str(EXAMPLES / "planar2.yaml"), str(out)],
                       check=True, env={**os.environ, "PYTHONHASHSEED": seed}, timeout=300)
        made.append({p.name: p.read_bytes() for p in sorted(out.iterdir())})
    assert list(made[0]) == ["budget.html", "folded.html", "log.html", "systolic.html", "ticks.vcd"]
    assert made[0]["folded.html"].count(b"<svg") >= 2 and b"$enddefinitions" in made[0]["ticks.vcd"]
    assert made[0] == made[1]


def test_a_budget_is_drawn_by_the_passes_its_vamps_serve():
    """Puma --vamps 12: the report counts 3 backward VAMPs and 9 shared by both passes; the drawing
    has exactly those circles, each VAMP its own (a budget's VAMPs serve many nodes in turn)."""
    from vampc.report.counts import vamp_counts
    from vampc.report.network_drawing import drawing
    c = compile_chain(load_robot(EXAMPLES / "puma560.yaml"), CompileOptions(vamps=12))
    counts = vamp_counts(c)
    d = drawing(c.graph, c.layout, c.network)
    rows = Counter(site.section for site in d.labels)
    assert rows == Counter({"bwd": counts["backward"], "both": counts["shared"], "fwd": counts["forward"]}) - Counter()
    assert sum(d.vamps.values()) == 12 and set(d.vamps.values()) == {1}


def test_a_tree_forward_node_spans_its_own_subtree():
    """Quadruped: joint 1 starts a leg of three joints, so its forward node is (1,3), not (1,12)."""
    c = compile_chain(load_robot(EXAMPLES / "quadruped.urdf"))
    d = nd.drawing(c.graph, c.layout, c.network)
    fwd = {s.index: label.split("\n")[1] for s, label in d.labels.items() if s.section == "fwd"}
    assert fwd[1] == "(1,3)" and fwd[4] == "(4,6)" and fwd[3] == "(3,3)"


@pytest.mark.parametrize("options", [dict(), dict(recursion="log"), dict(layout="folded"), dict(vamps=20)])
def test_a_buffer_square_says_how_the_buffering_table_counts_its_chains(puma, options):
    """The picture's squares are buses between sites (the forward node holding values it computes
    ahead from backward results: "from fwd 1 to fwd 1"), the buffering table counts by the values'
    pass (backward to forward): they seemed to disagree (a new user's find). Each square says how
    the table counts its chains; for the systolic Puma, whose chains are each read at one site,
    those add up to the table's; every square's id is its own (a grouped drawing's were not)."""
    import re

    from vampc.report.network_drawing import FLOW_WORDS
    from vampc.report.wiring import delay_buffers
    c = compile_chain(puma, CompileOptions(**options))
    svg = nd.network_svg(c.graph, c.layout, c.network, "t")
    squares = [e for e in ET.fromstring(svg).iter() if (e.get("id") or "").startswith("buffer-")]
    titles = [t.text for t in ET.fromstring(svg).iter(f"{SVG}title") if t.text and "delay buffers" in t.text]
    assert titles and len({g.get("id") for g in squares}) == len(squares)
    said: Counter = Counter()
    for text in titles:
        chains = int(re.search(r": (\d+) chains?,", text)[1])
        parts = re.search(r"the buffering table counts these chains as (.*) \(a chain read", text)[1].split(", ")
        counts = {words: int(k) for k, words in (p.split(" ", 1) for p in parts)}
        assert sum(counts.values()) == chains
        said.update(counts)
    table = {FLOW_WORDS[f]: v["chains"] for f, v in delay_buffers(c.graph, c.network)["by_flow"].items()
             if v["chains"]}
    assert set(said) == set(table) and all(said[k] >= v for k, v in table.items())
    if "vamps" not in options:          # (each chain read at one site: they add up exactly)
        assert dict(said) == table


def test_a_grouped_drawings_buffer_squares_have_ids_of_their_own():
    """A grouped drawing's sites share section and index across rows, and so did its squares' ids:
    260 squares, 51 ids on snake64's log network (review), a tooltip showing another's counts."""
    c = compile_chain(load_robot(EXAMPLES / "snake64.yaml"), CompileOptions(recursion="log"))
    svg = nd.network_svg(c.graph, c.layout, c.network, "t")
    ids = [e.get("id") for e in ET.fromstring(svg).iter() if (e.get("id") or "").startswith("buffer-")]
    assert len(ids) > 100 and len(set(ids)) == len(ids)


TREE = """<robot name="fork">
 <link name="base"/>
 {links}
 {joints}
</robot>"""


def _fork_urdf(tmp_path):
    """base - j1 - l1, whose two children are j2 - l2 - j3 - l3 and j4 - l4: joint 1's bus to
    joint 4 passes joints 2 and 3 on its row (depth-first order 1, 2, 3, 4)."""
    inertial = ('<inertial><mass value="1"/><origin xyz="0 0 0.1"/>'
                '<inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>')
    links = "".join(f'<link name="l{i}">{inertial}</link>' for i in range(1, 5))
    joints = "".join(
        f'<joint name="j{i}" type="revolute"><parent link="{p}"/><child link="l{i}"/>'
        f'<origin xyz="0 0 0.2"/><axis xyz="0 1 0"/>'
        f'<limit effort="10" velocity="1" lower="-1" upper="1"/></joint>'
        for i, p in ((1, "base"), (2, "l1"), (3, "l2"), (4, "l1")))
    path = tmp_path / "fork.urdf"
    path.write_text(TREE.format(links=links, joints=joints))
    return path


def test_a_bus_past_nodes_of_its_row_is_drawn_as_a_curve_over_them(tmp_path, puma):
    """A tree's bus from a node to a child further along its row ran straight behind the nodes
    between, and the tree looked a chain (a new user's find): it is a curve (SVG 'Q'), and a
    chain's buses stay straight."""
    c = compile_chain(load_robot(_fork_urdf(tmp_path)))
    d = nd.drawing(c.graph, c.layout, c.network)
    places = {s: d.places[s] for s in d.places}
    far = [(a, b) for a, b in d.buses if a != b and places[a][1] == places[b][1]
           and abs(places[a][0] - places[b][0]) > 1]
    assert far, "the fork has a bus past nodes of its row"
    svg = nd.network_svg(c.graph, c.layout, c.network, "t")
    buses = [p.get("d") for g in ET.fromstring(svg).iter(f"{SVG}g")
             if (g.get("id") or "").startswith("wires-buses") for p in g.iter(f"{SVG}path")]
    assert sum(path.count("Q") for path in buses) == len(far)
    c = compile_chain(puma)
    svg = nd.network_svg(c.graph, c.layout, c.network, "t")
    assert not any("Q" in (p.get("d") or "") for g in ET.fromstring(svg).iter(f"{SVG}g")
                   if (g.get("id") or "").startswith("wires-buses") for p in g.iter(f"{SVG}path"))


@pytest.mark.parametrize("robot, opts", [("planar2.yaml", {}), ("stanford.yaml", {}),
                                         ("puma560.yaml", {"recursion": "log"})])
def test_every_host_port_is_drawn_where_it_can_be_seen(robot, opts):
    """Ports under one column were stacked four places wide: the fifth and later were drawn on the
    first ones (planar2: 12 ports at 8 places, port 10 nowhere to be seen; a new user's find). Each
    port's triangle has its own apex now, read from the SVG, and the ports are spread under their
    column."""
    import re
    c = compile_chain(load_robot(EXAMPLES / robot), CompileOptions(**opts))
    d = nd.drawing(c.graph, c.layout, c.network)
    text = nd.network_svg(c.graph, c.layout, c.network, "t")
    apex = dict(re.findall(r'<g id="port-(\d+)"><title>[^<]*</title>\s*<path d="M ([\d.]+ [\d.]+)', text))
    wanted = [str(index) for index, readers, _ in d.ports if readers]
    assert sorted(apex) == sorted(wanted) and len(wanted) > 8
    assert len(set(apex.values())) == len(apex), Counter(apex.values()).most_common(3)
    # and no two triangles overlap: their x extents, read from each path, apart (a review found
    # neighbours overlapping, 40 of 45 pairs on the Puma's log network)
    spans = sorted((min(xs), max(xs)) for xs in (
        [float(x) for x in re.findall(r"[ML] ([\d.]+) [\d.]+", path)]
        for path in re.findall(r'<g id="port-\d+"><title>[^<]*</title>\s*<path d="([^"]+)"', text)))
    assert len(spans) == len(apex)
    assert all(a[1] < b[0] for a, b in zip(spans, spans[1:])), \
        [(a, b) for a, b in zip(spans, spans[1:]) if a[1] >= b[0]][:3]
    per = Counter(round(nd._xy(d, readers[0])[0], 3) for _, readers, _ in d.ports if readers)
    assert max(per.values()) > 4                      # (the case that had hidden ports)
