"""The timing chart (vampc.report.timing_chart): a well-formed, deterministic SVG with exactly one bar
per scheduled op, the critical path's bars the ones the schedule names, and the torque-set strip."""
from __future__ import annotations

import re
import xml.etree.ElementTree as ET

import pytest
from conftest import EXAMPLES

from vampc.compiler import CompileOptions, compile_chain
from vampc.report import timing_chart
from vampc.robot import load_robot

SVG = "{http://www.w3.org/2000/svg}"
CONFIGS = [dict(), dict(layout="folded"), dict(layout="folded", share_passes=True),
           dict(recursion="log"), dict(recursion="log", uniform_leaves=True, layout="folded"),
           dict(recursion="log", prefix="kogge-stone", layout="folded", share_passes=True)]


def groups(svg: str) -> dict[str, ET.Element]:
    """Every <g> with an id, by id (parsing also proves the SVG well-formed)."""
    root = ET.fromstring(svg)
    return {g.get("id"): g for g in root.iter(f"{SVG}g") if g.get("id")}


def bars(svg: str) -> tuple[set[int], set[int]]:
    """(ops with a bar, ops whose bar is marked critical); each bar group holds one <path>."""
    ops, critical = set(), set()
    for gid, g in groups(svg).items():
        m = re.fullmatch(r"op-(\d+)(-critical)?", gid)
        if m:
            assert len(g.findall(f"{SVG}path")) == 1
            node = int(m.group(1))
            assert node not in ops, f"two bars for op {node}"
            ops.add(node)
            if m.group(2):
                critical.add(node)
    return ops, critical


@pytest.fixture(scope="module")
def puma():
    return load_robot(EXAMPLES / "puma560.yaml")


@pytest.mark.parametrize("opts", CONFIGS, ids=lambda o: ",".join(f"{k}={v}" for k, v in o.items())
                         or "default")
def test_one_bar_per_op_and_the_critical_path_marked(puma, opts):
    c = compile_chain(puma, CompileOptions(**opts))
    svg = timing_chart.timing_svg(c.graph, c.layout, c.schedule, "t")
    ops, critical = bars(svg)
    assert ops == {nd.id for nd in c.graph.compute_nodes()}
    assert critical == set(c.schedule.critical_path)
    g = groups(svg)
    assert "critical-path" in g
    title = g[f"op-{c.schedule.critical_path[-1]}-critical"].find(f"{SVG}title").text
    assert "on the critical path" in title


@pytest.mark.parametrize("opts", [dict(), dict(layout="folded"), dict(recursion="log")],
                         ids=["systolic", "folded", "log"])
def test_each_bar_spans_its_ops_flops(puma, opts):
    """Where a bar is drawn, not only that it is: its left and right edges, read from the SVG path,
    at the op's start and finish flops on the axes' scale (the plot area's rectangle spans flops 0
    to the chart's span). A chart drawing every bar a flop late passed every chart test (a test
    audit's find)."""
    c = compile_chain(puma, CompileOptions(**opts))
    svg = timing_chart.timing_svg(c.graph, c.layout, c.schedule, "t")
    rects = re.findall(r'<clipPath id="[^"]+">\s*<rect x="([\d.]+)" y="[\d.]+" width="([\d.]+)"', svg)
    assert len(set(rects)) == 1, rects
    x0, width = map(float, rects[0])
    per_flop = width / timing_chart.chart(c.graph, c.layout, c.schedule).span
    checked = 0
    for gid, g in groups(svg).items():
        m = re.fullmatch(r"op-(\d+)(-critical)?", gid)
        if not m:
            continue
        xs = [float(x) for x in re.findall(r"[ML] ([\d.]+) [\d.]+", g.find(f"{SVG}path").get("d"))]
        i = int(m.group(1))
        want = (x0 + c.schedule.start[i] * per_flop, x0 + c.schedule.finish[i] * per_flop)
        assert min(xs) == pytest.approx(want[0], abs=0.06) and max(xs) == pytest.approx(want[1], abs=0.06), \
            (gid, xs, want)
        checked += 1
    assert checked == len(list(c.graph.compute_nodes()))


def test_successive_torque_sets_are_visible(puma):
    systolic = compile_chain(puma)
    sets = [k for k in groups(timing_chart.timing_svg(systolic.graph, systolic.layout,
                                                      systolic.schedule, "t")) if k.startswith("set-")]
    assert len(sets) == timing_chart.MAX_SETS       # 61 flops of latency, a set every 4: 8 shown
    chart = timing_chart.chart(systolic.graph, systolic.layout, systolic.schedule)
    assert chart.sets == (0, 4, 8, 12, 16, 20, 24, 28)
    folded = compile_chain(puma, CompileOptions(layout="folded"))
    chart = timing_chart.chart(folded.graph, folded.layout, folded.schedule)
    assert chart.sets == (0, folded.schedule.interval)       # one set at a time


def test_rows_are_variables_for_systolic_and_vamps_for_folded(puma):
    c = compile_chain(puma)
    rows = timing_chart.chart(c.graph, c.layout, c.schedule).rows
    assert rows[0].label == "bwd T2 (VA)" and len(rows) == 30         # Table III.1's 22 + 8
    assert all(len(r.lanes) == 1 for r in rows)     # a variable's joints never overlap in time
    f = compile_chain(puma, CompileOptions(layout="folded"))
    rows = timing_chart.chart(f.graph, f.layout, f.schedule).rows
    assert len(rows) == len(f.layout.unit_vamps) and rows[0].label.startswith("VAMP 0: bwd")


def test_the_chart_holds_no_date_or_version(puma):
    # (the same bytes from one run to the next: tests/test_report_network_drawing.py, two processes)
    c = compile_chain(puma, CompileOptions(layout="folded"))
    a = timing_chart.timing_svg(c.graph, c.layout, c.schedule, "t")
    assert "<dc:date>" not in a and "Matplotlib v" not in a


def test_a_big_chart_merges_bars_per_variable(puma, monkeypatch):
    c = compile_chain(puma, CompileOptions(recursion="log"))
    monkeypatch.setattr(timing_chart, "MAX_BARS", 10)
    svg = timing_chart.timing_svg(c.graph, c.layout, c.schedule, "t")
    g = groups(svg)
    # every op merged, except the critical path's, kept one by one and joined
    assert {k for k in g if k.startswith("op-")} == {f"op-{i}-critical" for i in c.schedule.critical_path}
    assert "critical-path" in g
    busy = [k for k in g if k.startswith("busy-")]
    assert busy and "merged per variable" in svg
    total = sum(int(re.search(r": (\d+) ops", g[k].find(f"{SVG}title").text).group(1)) for k in busy)
    assert total == len(c.graph.compute_nodes())


def test_a_chart_of_many_rows_merges_and_stays_readable_in_size(monkeypatch):
    """A 64-joint log network has 1 952 lanes of bars: the chart merges per variable, keeps the
    critical path, and is at most about 2 000 px (1 500 pt) wide and tall and under 1 MB."""
    from vampc.robot.random import random_chain
    c = compile_chain(random_chain(64, 3), CompileOptions(recursion="log"))
    svg = timing_chart.timing_svg(c.graph, c.layout, c.schedule, "t")
    width, height = (float(x) for x in re.search(r'width="([0-9.]+)pt" height="([0-9.]+)pt"', svg).groups())
    assert width <= 1500 and height <= 1500 and len(svg) < 1_000_000
    g = groups(svg)
    assert "merged per variable" in svg and "critical-path" in g
    assert {k for k in g if k.startswith("op-")} == {f"op-{i}-critical" for i in c.schedule.critical_path}


def test_a_long_schedule_merges_bars_closer_than_the_plot_can_show(monkeypatch):
    """A chart whose span is wider than the plot merges spans less than a point apart, and a long
    critical path's ops per row the same way: a 300-joint linear chain's chart (11 000 staggered ops, a
    span of 1 000+ flops) stays small."""
    from vampc.robot.random import random_chain
    monkeypatch.setattr(timing_chart, "MAX_CRITICAL_BARS", 50)
    c = compile_chain(random_chain(300, 2))
    svg = timing_chart.timing_svg(c.graph, c.layout, c.schedule, "t")
    assert "merged per variable" in svg and len(svg) < 400_000
    g = groups(svg)
    assert "critical-path" in g and any(k.startswith("critical-") and k != "critical-path" for k in g)
    assert not any(k.startswith("op-") for k in g)
    # fewer ops than MAX_BARS, merged as their bars would be under 2 pt wide: the title said only
    # "charts of at most 10,000 ops and 300 rows show every op" (an audit's find)
    assert len(c.graph.compute_nodes()) < timing_chart.MAX_BARS
    assert "unless more than 4,000 of them would each be under 2 pt wide" in svg


def test_a_rows_label_names_the_kind_of_every_op_in_it(puma, monkeypatch):
    """The log recursion computes omega by an MTV in a combining node and a VA in a leaf: both were
    drawn in one row labelled "bwd omega (MTV)", and a merged chart coloured the VAs as MTVs (a new
    user's find). A row holds ops of the kind its label names, and a merged row counts exactly the
    graph's ops of that name, pass and kind."""
    from collections import Counter
    c = compile_chain(puma, CompileOptions(recursion="log"))
    data = timing_chart.chart(c.graph, c.layout, c.schedule)
    assert not data.merged
    kinds = set()
    for row in data.rows:
        kind = re.fullmatch(r"\w+ \S+ \((\w+)\)", row.label).group(1)
        ops = {c.graph.nodes[i].op.value for lane in row.lanes for i in lane}
        assert ops == {kind}, (row.label, ops)
        kinds.add((row.label.split(" (")[0], kind))
    assert ("bwd omega", "MTV") in kinds and ("bwd omega", "VA") in kinds
    monkeypatch.setattr(timing_chart, "MAX_BARS", 10)
    merged = timing_chart.chart(c.graph, c.layout, c.schedule)
    assert merged.merged
    want = Counter(f"{nd.section} {nd.name} ({nd.op.value})" for nd in c.graph.compute_nodes())
    got = Counter({row.label: sum(n for _, _, n in row.lanes[0]) for row in merged.rows})
    assert got == want and all(row.label.endswith(f"({row.op})") for row in merged.rows)


def test_the_critical_path_runs_along_its_bars_lower_edges(tmp_path):
    """The red line joining the critical path ran through the middle of each bar and struck its
    label out (a new user's find): it runs along each critical bar's lower edge."""
    c = compile_chain(load_robot(EXAMPLES / "planar2.yaml"), CompileOptions())
    svg = timing_chart.timing_svg(c.graph, c.layout, c.schedule, "t")
    g = groups(svg)
    points = [tuple(map(float, p)) for p in
              re.findall(r"[ML] ([\d.]+) ([\d.]+)", g["critical-path"].find(f".//{SVG}path").get("d"))]
    for i in c.schedule.critical_path:
        corners = [tuple(map(float, p)) for p in re.findall(
            r"[ML] ([\d.]+) ([\d.]+)", g[f"op-{i}-critical"].find(f".//{SVG}path").get("d"))]
        left, right = min(x for x, _ in corners), max(x for x, _ in corners)
        lower = max(y for _, y in corners)          # (SVG's y grows downwards)
        assert (left, lower) in points and (right, lower) in points, (i, corners)
