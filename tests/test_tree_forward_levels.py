"""The report's forward addition levels of a log tree graph are the graph's own.

`vampc report` of a tree (or of any robot with a floating base) gives the log recursion's "forward N
addition levels": the depth of the forward subtree sums (vampc.dataflow.logtree: block sums Bf, Bn and
range sums Rf, Rn, each one VA). It was treeprefix.sum_levels(n) (removed), the worst range [lo, n) of n
positions, a chain's ranges: a fixed-base tree with several joints on the base never sums [0, n)
(its base takes no wrench), and the quadruped got 4 where its graph has 2. The expected figure here is
read from the compiled graph alone: the longest run of consecutive forward-sum additions along
operand edges, in the force sums (Bf, Rf) and in the moment sums (Bn, Rn), the larger of the two (the
pruning drops a base joint's force sum when only its moment gives a torque, and a prismatic joint's
moment sum: the force family alone can be a level short). A floating base's wrench additions f0, n0
are the base wrench's, not the subtree sums', and are not counted.
"""
from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import pytest

from vampc.compiler import CompileOptions, compile_chain
from vampc.dataflow.prefix import SHAPES
from vampc.report.counts import tree_summary
from vampc.robot import load_robot
from vampc.robot.random import random_tree

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
FAMILIES = (("Bf", "Rf"), ("Bn", "Rn"))

# a DH tree: an arm of 2 joints and one of 5 on the base (rows without `parent` hang on the row above)
DH_ROW = ("  - {name: %s, %stype: revolute, a: 0.3, alpha: 0.5, d: 0.1, theta: 0.0, mass: 1.0, "
          "com: [-0.15, 0, 0], inertia: [0.01, 0.01, 0.01, 0, 0, 0], limits: {q: [-3, 3], qd: 3, tau: 50}}")
DH_TREE = "name: arms25\ngravity: [0.0, 0.0, -9.81]\njoints:\n" + "\n".join(
    DH_ROW % (name, "parent: 0, " if name in ("a1", "b1") else "")
    for name in ("a1", "a2", "b1", "b2", "b3", "b4", "b5")) + "\n"


def graph_forward_levels(graph) -> int:
    """The most consecutive forward-sum VAs on a dependency path of the compiled graph."""
    worst = 0
    for names in FAMILIES:
        depth: dict[int, int] = {}
        for nd in graph.nodes:                          # topological order
            if nd.name in names:
                depth[nd.id] = 1 + max((depth.get(a, 0) for a in nd.args), default=0)
        worst = max(worst, max(depth.values(), default=0))
    return worst


def arms(lengths) -> tuple[int, ...]:
    """Parents of chains of the given lengths on the base, numbered depth-first."""
    parents: list[int] = []
    for length in lengths:
        parents += [0] + [len(parents) + k for k in range(1, length)]
    return tuple(parents)


def comb(spine: int, tooth: int) -> tuple[int, ...]:
    """A spine of `spine` joints, each with a chain of `tooth` joints hanging off it."""
    parents: list[int] = []
    previous = 0
    for _ in range(spine):
        parents.append(previous)
        previous = len(parents)
        parents += [previous + k for k in range(tooth)]
    return tuple(parents)


def shaped(parents, floating: bool):
    chain = random_tree(len(parents), 5, "chain", prismatic_fraction=0.3, floating=floating)
    return replace(chain, parents=tuple(parents), name="shaped")


def robots(tmp_path: Path):
    """(name, chain): the example quadruped, a DH tree, stars of equal and unequal arms, combs, binary
    and random trees, each with a fixed and a floating base."""
    (tmp_path / "arms25.yaml").write_text(DH_TREE)
    for floating in (False, True):
        tag = " floating" if floating else ""
        yield f"quadruped{tag}", load_robot(EXAMPLES / "quadruped.urdf", floating=floating)
        yield f"dh arms 2+5{tag}", load_robot(tmp_path / "arms25.yaml", floating=floating)
        for lengths in ((3, 3, 3, 3), (2,) * 8, (1,) * 6, (1, 7), (3, 9), (13, 2, 1), (6, 6, 6, 1), (5, 5, 5)):
            yield f"arms {lengths}{tag}", shaped(arms(lengths), floating)
        for spine, tooth in ((4, 2), (5, 1), (3, 3)):
            yield f"comb {spine}x{tooth}{tag}", shaped(comb(spine, tooth), floating)
        for n, seed, shape in ((7, 1, "binary"), (16, 1, "binary"), (33, 1, "binary"), (12, 12, "random"),
                               (20, 20, "random"), (33, 33, "random"), (30, 2, "star")):
            yield f"{shape} {n}{tag}", random_tree(n, seed, shape, prismatic_fraction=0.3, floating=floating)


def test_comb_is_a_tree():
    assert comb(3, 2) == (0, 1, 2, 1, 4, 5, 4, 7, 8)


@pytest.mark.parametrize("prefix", SHAPES)
def test_the_reports_forward_levels_are_the_graphs(tmp_path, prefix):
    """For every tree and prefix shape: the report's figure (counts.tree_summary, what `vampc report`
    prints) and the graph's own metadata equal the forward-sum depth measured in the compiled graph;
    the quadruped's 2, not 4."""
    wrong = []
    for name, chain in robots(tmp_path):
        assert not chain.is_fixed_chain, name
        c = compile_chain(chain, CompileOptions(recursion="log", prefix=prefix, verify=False), until="graph")
        want = graph_forward_levels(c.graph)
        got = (tree_summary(chain, prefix)["forward_levels"],
               json.loads(dict(c.graph.meta)["tree"])["forward_levels"])
        if got != (want, want):
            wrong.append((name, got, want))
        if name == "quadruped":
            assert want == 2
    assert not wrong, f"report, meta against the graph: {wrong}"


@pytest.mark.parametrize("recursion", ["linear", "log"])
def test_a_tree_program_stored_with_a_chains_forward_levels_is_not_called_edited(tmp_path, recursion):
    """A tree's program compiled before 2026-12-08 stores the chain's worst range as its forward
    addition levels (the quadruped's 4), in its summary and, for the log recursion, in its graph's
    meta: read back, a report took it for an edit (the log program refused, "recompile it"). Taken as
    counted before; another figure there is an edit."""
    import sys

    from click.testing import CliRunner
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from program_util import edited_program

    from vampc.cli import main
    program = tmp_path / "q.vamp.json"
    r = CliRunner().invoke(main, ["compile", str(EXAMPLES / "quadruped.urdf"), "--recursion", recursion,
                                  "-o", str(program)])
    assert r.exit_code == 0, r.output
    assert json.loads(program.read_text())["summary"]["tree"]["forward_levels"] == 2

    def stored(levels):
        def change(doc):
            doc["summary"]["tree"]["forward_levels"] = levels
            if recursion == "log":
                tree = json.loads(doc["graph"]["meta"]["tree"])
                tree["forward_levels"] = levels
                doc["graph"]["meta"]["tree"] = json.dumps(tree, separators=(",", ":"))
        return change
    for levels, edited in ((4, False), (3, True)):
        old = edited_program(program, tmp_path, stored(levels))
        r = CliRunner().invoke(main, ["report", str(old)])
        said = "edited" in r.stderr
        assert said == edited and r.exit_code == (1 if edited and recursion == "log" else 0), r.stderr
