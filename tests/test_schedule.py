"""ASAP schedule and critical path (vampc.schedule.asap) against the paper's latency formula.

Expected latencies: the paper's (2n+3) Mults + (6n+7) Addns (section III, Appendix A) plus the documented
output correction of 1 Mult + 2 Addns (vampc/dataflow/linear.py: one MV, A_1, lies on the path to τ_1).
In op durations (Appendix A with that MV added):

    τ_1 = 2(n-1)(MV + VA) + SV + 2 MV + 3 VC + 8 VA

Op durations for separate Mult and Addn latencies m, a follow Table VII.1's micro-steps: VA = a, SV = m,
VC = m + a, MV = m + max(m, a) + a (its middle step runs a multiplier and the adder together).
"""
from __future__ import annotations

import networkx as nx
import pytest

from vampc.dataflow.linear import build_linear
from vampc.errors import VampcInternalError
from vampc.machine.ops import Op, Timing
from vampc.robot.random import random_chain
from vampc.schedule.asap import Schedule, schedule_asap


def durations(m: int, a: int) -> dict[Op, int]:
    """Op durations from Table VII.1's micro-steps, written out by hand."""
    mv = m + max(m, a) + a
    return {Op.VA: a, Op.SV: m, Op.VC: m + a, Op.MV: mv, Op.MTV: mv, Op.INPUT: 0, Op.CONST: 0}


def paper_flops(n: int, m: int = 1, a: int = 1) -> int:
    """Appendix A's τ_1 with the extra MV of the output correction, in flops."""
    d = durations(m, a)
    return 2 * (n - 1) * (d[Op.MV] + d[Op.VA]) + d[Op.SV] + 2 * d[Op.MV] + 3 * d[Op.VC] + 8 * d[Op.VA]


def longest_path(graph, d: dict[Op, int]) -> int:
    """Latency computed independently: longest weighted path to an output, through networkx."""
    g = graph.to_networkx()
    for u, v in g.edges:
        g.edges[u, v]["w"] = d[graph.nodes[v].op]
    finish = {}
    for v in nx.topological_sort(g):
        finish[v] = max((finish[u] + g.edges[u, v]["w"] for u in g.predecessors(v)),
                        default=d[graph.nodes[v].op])
    return max(finish[o.node] for o in graph.outputs)


def rotary(n: int):
    """A general rotary arm (the paper's case): random Φ_i, revolute joints only."""
    return random_chain(n, n, prismatic_fraction=0.0)


@pytest.mark.parametrize("n", range(1, 65))
def test_latency_is_paper_formula_plus_output_correction(n):
    graph = build_linear(rotary(n))
    s = schedule_asap(graph)
    assert (s.mults, s.adds) == (2 * n + 3 + 1, 6 * n + 7 + 2)
    assert s.latency == (2 * n + 3) + (6 * n + 7) + 3
    assert s.interval == 4
    s.verify(graph)


@pytest.mark.parametrize("n", [1, 6, 17])
def test_latency_equals_independent_longest_path(n):
    graph = build_linear(random_chain(n, 3, prismatic_fraction=0.4))
    assert schedule_asap(graph).latency == longest_path(graph, durations(1, 1))


@pytest.mark.parametrize("n", [1, 6, 20])
def test_separate_latencies_follow_the_micro_steps(n):
    graph = build_linear(rotary(n))
    s = schedule_asap(graph, Timing(mult=2, add=3))
    d = durations(2, 3)
    assert all(s.finish[nd.id] - s.start[nd.id] == d[nd.op] for nd in graph.nodes)
    assert s.interval == d[Op.MV] + d[Op.VA] == 11
    assert s.latency == paper_flops(n, 2, 3) == longest_path(graph, d) == 22 * n + 35
    assert s.latency == 2 * s.mults + 3 * s.adds
    s.verify(graph)


def test_timing_durations_match_the_hand_table():
    for m, a in [(1, 1), (2, 3), (3, 2), (5, 1)]:
        d = durations(m, a)
        assert {op: Timing(m, a).duration(op) for op in d} == d
        assert Timing(m, a).cycle == d[Op.MV] + d[Op.VA]


@pytest.mark.parametrize("n", [1, 4, 9])
@pytest.mark.parametrize("timing", [Timing(), Timing(2, 3)], ids=["unit", "m2a3"])
def test_critical_path_is_a_connected_chain(n, timing):
    graph = build_linear(random_chain(n, 11, prismatic_fraction=0.3))
    s = schedule_asap(graph, timing)
    path = s.critical_path
    assert s.start[path[0]] == 0
    assert s.finish[path[-1]] == s.latency
    assert path[-1] in {o.node for o in graph.outputs}
    for u, v in zip(path, path[1:]):
        assert u in graph.nodes[v].args
        assert s.finish[u] == s.start[v]
    assert sum(timing.duration(graph.nodes[i].op) for i in path) == s.latency


def test_critical_path_of_a_rotary_arm_ends_at_tau_1():
    graph = build_linear(rotary(5))
    s = schedule_asap(graph)
    last = graph.nodes[s.critical_path[-1]]
    assert (last.name, last.section, last.group) == ("n", "fwd", 1)


def test_verify_rejects_a_node_started_too_early():
    graph = build_linear(rotary(2))
    s = schedule_asap(graph)
    victim = graph.nodes[s.critical_path[3]]
    start, finish = list(s.start), list(s.finish)
    start[victim.id] -= 1
    finish[victim.id] -= 1
    broken = Schedule(s.timing, tuple(start), tuple(finish), s.latency, s.critical_path, s.mults, s.adds)
    with pytest.raises(VampcInternalError,
                       match=rf"^node {victim.section}{victim.group}\.{victim.name} starts before "
                             rf"operand \d+ ends$"):
        broken.verify(graph)


def test_verify_rejects_a_wrong_duration():
    graph = build_linear(rotary(2))
    s = schedule_asap(graph)
    victim = graph.compute_nodes()[0]
    finish = list(s.finish)
    finish[victim.id] += 1
    broken = Schedule(s.timing, s.start, tuple(finish), s.latency, s.critical_path, s.mults, s.adds)
    with pytest.raises(VampcInternalError, match=rf"^node {victim.label}: duration mismatch$"):
        broken.verify(graph)


def test_mults_and_adds_add_up_to_the_latency_when_mults_are_slower():
    graph = build_linear(rotary(6))
    s = schedule_asap(graph, Timing(mult=3, add=2))
    assert s.latency == paper_flops(6, 3, 2) == 3 * s.mults + 2 * s.adds


def test_an_unchecked_schedule_starts_a_node_as_the_loop_over_its_operands_does():
    """Unverified, a schedule under latencies that are not numbers (NaN) starts each node at the
    latest of 0 and its operands' finishes that compare greater, as a loop over them does: a NaN
    finish is passed over (a review found the in-line two-operand case taking it)."""
    graph = build_linear(random_chain(2, 1))
    timing = Timing(mult=float("nan"))
    sched = schedule_asap(graph, timing, verify=False)
    finish, durations = [], timing.durations
    for nd in graph.nodes:
        s = 0
        for a in nd.args:
            if finish[a] > s:
                s = finish[a]
        finish.append(s + durations[nd.op])
    import math
    assert [math.isnan(x) for x in sched.finish] == [math.isnan(x) for x in finish]
    assert [x for x in sched.finish if not math.isnan(x)] == [x for x in finish if not math.isnan(x)]
