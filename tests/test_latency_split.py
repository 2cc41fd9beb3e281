"""The latency split of every layout (issue "The report a hardware engineer trusts", part 1): the data
path's Mults + Addns equal the graph's critical path, found here by networkx's longest path over the
graph (independent of vampc's schedulers), and Mults + Addns + waiting equal the latency, for every
example robot, both recursions, every layout and a few budgets; and the report's text and JSON say the
same."""
from __future__ import annotations

import networkx as nx
import pytest
from conftest import EXAMPLES

from vampc.compiler import CompileOptions, compile_chain
from vampc.report.counts import summary
from vampc.robot import load_robot

LAYOUTS = [dict(), dict(layout="folded"), dict(layout="folded", share_passes=True)]
CONFIGS = [dict(recursion=r, **x) for r in ("linear", "log") for x in LAYOUTS]
BUDGETS = [("puma560.yaml", dict(vamps=3)), ("puma560.yaml", dict(vamps=7)), ("puma560.yaml", dict(vamps=12)),
           ("puma560.yaml", dict(vamps=12, recursion="log")), ("quadruped.urdf", dict(vamps=9)),
           ("planar2.yaml", dict(vamps=3)), ("puma560.yaml", dict(mult_latency=3, add_latency=2)),
           ("puma560.yaml", dict(mult_latency=3, add_latency=2, layout="folded", recursion="log")),
           ("snake64.yaml", dict()), ("snake64.yaml", dict(recursion="log", layout="folded"))]
ROBOTS = ["planar2.yaml", "puma560.yaml", "stanford.yaml", "arm6.urdf", "quadruped.urdf", "ur5.urdf"]


def longest_path(graph, timing) -> int:
    """The latest finish of a torque with unlimited VAMPs: the longest path through the compute ops
    (weight = duration), by networkx."""
    g = nx.DiGraph()
    g.add_node("src")
    duration = timing.durations
    for nd in graph.nodes:
        if not nd.op.is_compute:
            continue
        g.add_edge("src", nd.id, weight=duration[nd.op])
        for a in nd.args:
            if graph.nodes[a].op.is_compute:
                g.add_edge(a, nd.id, weight=duration[nd.op])
    length = nx.single_source_bellman_ford_path_length(nx.DiGraph(
        (u, v, {"weight": -d["weight"]}) for u, v, d in g.edges(data=True)), "src")
    return max(-length[o.node] for o in graph.outputs)


def check(robot: str, options: dict, chain=None) -> None:
    c = compile_chain(chain or load_robot(EXAMPLES / robot), CompileOptions(**options))
    s, t = c.schedule, c.schedule.timing
    lat = summary(c)["latency"]
    data_path = lat["mults"] * t.mult + lat["adds"] * t.add
    assert data_path == longest_path(c.graph, t), (robot, options)
    assert data_path + lat["waits"] == lat["flops"] == s.latency and lat["waits"] >= 0
    # the stored critical path is a chain of operands ending at a torque, with those counts
    path = s.critical_path
    assert path[-1] in {o.node for o in c.graph.outputs}
    assert all(a in c.graph.nodes[b].args for a, b in zip(path, path[1:]))
    assert sum(t.duration(c.graph.nodes[i].op) for i in path) == data_path


@pytest.mark.parametrize("robot", ROBOTS)
def test_every_layout_splits_its_latency_into_the_data_path_and_waiting(robot):
    """Every layout and recursion of one robot (one test per robot: the URDF is read once)."""
    chain = load_robot(EXAMPLES / robot)
    for options in CONFIGS:
        check(robot, options, chain)


@pytest.mark.parametrize("robot, options", BUDGETS, ids=lambda x: x if isinstance(x, str) else
                         "-".join(f"{k}{v}" for k, v in x.items()))
def test_budgets_and_latencies_split_the_same_way(robot, options):
    check(robot, options)


def test_a_budget_that_waits_says_so_against_the_paper():
    """Puma --vamps 12 linear: 16 M + 45 A (61 flops, the systolic figure) + 6 waiting = 67; the
    comparison with the paper is the data path's (+1 M, +2 A: the output correction)."""
    from click.testing import CliRunner

    from vampc.cli import main
    r = CliRunner().invoke(main, ["report", str(EXAMPLES / "puma560.yaml"), "--vamps", "12"])
    assert r.exit_code == 0, r.output
    assert "67 flops = 16 Mults + 45 Addns + 6 waiting" in r.output
    assert "(+1 Mults, +2 Addns, 6 waiting) against the paper's formula" in r.output


def test_another_prefix_is_sized_where_the_other_reasons_are_counts():
    """Kogge-Stone on 1 and 3 joints: its reason gives the rest of the difference from the paper's
    formula, so the reasons add up to the difference (they had come to -1 A against -2 A on one
    joint with a rotating base, and a 3-joint arm's -1 M -3 A had no size: a report audit's)."""
    from vampc.report.counts import ACCOUNTED, latency_reasons
    base = dict(paper={"mults": 9, "adds": 22}, recursion="log", uniform_leaves=False,
                timing={"mult_latency": 1, "add_latency": 1}, prismatic_joints=[])
    for n, got, extra, size in ((3, (9, 21), {}, "−1 M, −3 A"),
                                (1, (7, 14), {"base_rotates": True}, "−1 A")):
        rep = dict(base, joints=n, latency={"mults": got[0], "adds": got[1]}, prefix="kogge-stone",
                   **extra)
        if n == 1:
            rep["paper"] = {"mults": 7, "adds": 16}
        shorts = [short for short, _ in latency_reasons(rep)]
        assert shorts[-1] == f"a kogge-stone prefix, {size}", shorts
        counted = [ACCOUNTED[s] for s in shorts[:-1]]
        m = sum(c[0] for c in counted) + (-1 if "M" in size else 0)
        a = sum(c[1] for c in counted) + int(size.split()[-2].replace("−", "-"))
        assert (m, a) == (got[0] - rep["paper"]["mults"], got[1] - rep["paper"]["adds"])


def test_the_compile_summary_weighs_mults_and_addns_by_their_latencies(tmp_path):
    """With 3-flop Mults and 2-flop Addns the summary said 'latency 150 flops (28 M + 33 A)', which
    do not add up to it (a new user's find): each count is said with its latency, and they do."""
    import re

    from click.testing import CliRunner
    from conftest import EXAMPLES

    from vampc.cli import main
    res = CliRunner().invoke(main, ["compile", str(EXAMPLES / "puma560.yaml"), "--mult-latency", "3",
                                    "--add-latency", "2", "-o", str(tmp_path / "p.vamp.json")])
    assert res.exit_code == 0, res.output
    m = re.search(r"latency (\d+) flops \((\d+) M × 3 \+ (\d+) A × 2\)", res.output)
    assert m, res.output
    total, mults, adds = map(int, m.groups())
    assert total == 3 * mults + 2 * adds
    res = CliRunner().invoke(main, ["compile", str(EXAMPLES / "puma560.yaml"), "-o",
                                    str(tmp_path / "q.vamp.json")])
    m = re.search(r"latency (\d+) flops \((\d+) M \+ (\d+) A\)", res.output)
    assert m and int(m[1]) == int(m[2]) + int(m[3]), res.output


def test_a_folded_reports_ops_by_kind_are_said_to_be_ops():
    """'VAMPs 30' and below it 'by op MTV 18, MV 24, SV 6, VA 72, VC 60', which sum to 180 (a new
    user's find): the line says they are ops, their sum, and the VAMPs that run them."""
    from click.testing import CliRunner
    from conftest import EXAMPLES

    from vampc.cli import main
    out = CliRunner().invoke(main, ["report", str(EXAMPLES / "puma560.yaml"), "--layout",
                                    "folded"]).output
    line = next(x for x in out.splitlines() if x.startswith("  by op"))
    assert line.endswith("MTV 18, MV 24, SV 6, VA 72, VC 60 (ops, 180 in all, run on these 30 VAMPs)")
    out = CliRunner().invoke(main, ["report", str(EXAMPLES / "puma560.yaml")]).output
    line = next(x for x in out.splitlines() if x.startswith("  by op"))
    assert line.endswith("VC 60")              # (systolic: an op a VAMP, nothing to add)
