"""The folded binding (vampc.schedule.layout.folded_binding, on numpy arrays) against the plain loop
over the nodes it replaced: the same unit for every node and the same unit sizes, with and without
shared passes, for the example robots, random chains and trees, both recursions and every prefix."""
from __future__ import annotations

import collections
from pathlib import Path

import pytest

from vampc.compiler import CompileOptions, build_graph
from vampc.machine.ops import VAMPS_PER_OP
from vampc.robot import load_robot
from vampc.robot.random import random_chain, random_tree
from vampc.schedule.layout import device_nodes, folded_binding

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


def plain(graph, share_passes: bool):
    """Units by role (device, device node, op name, VAMPs) in order of first node; forward roles onto
    the backward units of their size in order when shared, a new unit when none is left."""
    device = device_nodes(graph)
    roles, sizes, units, forward = {}, [], [-1] * len(graph.nodes), []
    for nd in graph.compute_nodes():
        role = (*device(nd), nd.name, VAMPS_PER_OP[nd.op])
        if share_passes and role[0] == "fwd":
            forward.append((nd, role))
            continue
        if role not in roles:
            roles[role] = len(sizes)
            sizes.append(role[3])
        units[nd.id] = roles[role]
    free = {k: collections.deque(u for u, s in enumerate(sizes) if s == k) for k in (1, 3)}
    taken = {}
    for nd, role in forward:
        if role not in taken:
            taken[role] = free[role[3]].popleft() if free[role[3]] else len(sizes)
            if taken[role] == len(sizes):
                sizes.append(role[3])
        units[nd.id] = taken[role]
    return tuple(units), tuple(sizes)


ROBOTS = sorted(p for p in EXAMPLES.iterdir() if p.suffix in (".yaml", ".urdf"))


@pytest.mark.parametrize("recursion", ["linear", "log"])
@pytest.mark.parametrize("path", ROBOTS, ids=lambda p: p.name)
def test_example_robots(path, recursion):
    graph = build_graph(load_robot(path), CompileOptions(recursion=recursion))
    for share in (False, True):
        got = folded_binding(graph, share)
        assert got == plain(graph, share)
        assert all(u >= 0 for nd, u in zip(graph.nodes, got[0]) if nd.op.is_compute)


@pytest.mark.parametrize("prefix", ["sklansky", "brent-kung", "kogge-stone", "ladner-fischer",
                                    "serial"])
@pytest.mark.parametrize("seed", range(3))
def test_random_chains_and_trees(seed, prefix):
    for chain in (random_chain(5 + 7 * seed, seed), random_tree(4 + 6 * seed, seed)):
        for uniform in (False, True):
            graph = build_graph(chain, CompileOptions(recursion="log", prefix=prefix,
                                                      uniform_leaves=uniform))
            for share in (False, True):
                assert folded_binding(graph, share) == plain(graph, share)
