"""Sites (vampc.report.sites): the recursion or device node each VAMP belongs to."""
from __future__ import annotations

from collections import Counter

from conftest import EXAMPLES

from vampc.compiler import CompileOptions, compile_chain
from vampc.report.sites import Site, node_table, vamp_sites, vamp_units
from vampc.robot import load_robot

PUMA = load_robot(EXAMPLES / "puma560.yaml")


def test_systolic_sites_are_recursion_nodes():
    c = compile_chain(PUMA)
    sites = vamp_sites(c.graph, c.layout)
    assert len(sites) == len(c.network.vamps)
    assert Counter(sites)[Site("bwd", 1)] == 12 and Counter(sites)[Site("fwd", 6)] == 8
    assert vamp_sites(c.graph, c.layout) is sites              # asked again: the same answer


def test_folded_sites_are_device_nodes():
    c = compile_chain(PUMA, CompileOptions(recursion="log", layout="folded"))
    sites = Counter(vamp_sites(c.graph, c.layout))
    assert {s.section for s in sites} == {"bwd", "npv", "fwd"}
    assert sum(sites.values()) == len(c.network.vamps)


def test_mm_units_take_three_vamps():
    c = compile_chain(PUMA, CompileOptions(recursion="log"))
    units = vamp_units(c.layout)
    assert len(units) == len(c.network.vamps)
    assert max(Counter(units).values()) == 3


def test_node_table():
    linear = compile_chain(PUMA).graph
    assert node_table(linear) == {"bwd": [], "fwd": []}
    log = compile_chain(PUMA, CompileOptions(recursion="log", uniform_leaves=True)).graph
    rows = node_table(log)
    assert len(rows["bwd"]) == 13 and max(r[4] for r in rows["bwd"]) == 3   # 6 leaves, 3 tiers
