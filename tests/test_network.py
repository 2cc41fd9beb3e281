"""Systolic allocation (vampc.network.allocate) and the network IR's timing model (vampc.network.model).

VAMP counts come from the paper (section VI, "VAMPs - Totals, n = 6": linear systolic pipeline 132
backward + 48 forward). Tap windows are recomputed here from the timing model in the model's docstring,
not with vampc.network.allocate.tap_window.
"""
from __future__ import annotations

import dataclasses
from collections import Counter

import pytest

from vampc.dataflow.linear import build_linear
from vampc.dataflow.ops import Timing
from vampc.errors import VampcInternalError
from vampc.network.allocate import allocate_systolic, verify_network
from vampc.robot.random import random_chain
from vampc.schedule.asap import schedule_asap

CASES = [(6, 0.0, Timing()), (6, 0.5, Timing()), (1, 0.0, Timing()), (9, 0.3, Timing(2, 3))]
CASE_IDS = ["rotary6", "mixed6", "rotary1", "mixed9-m2a3"]


def build(n: int, prismatic: float = 0.0, timing: Timing = Timing(), seed: int = 0):
    """(graph, schedule, network) of a random chain."""
    graph = build_linear(random_chain(n, seed, prismatic_fraction=prismatic))
    sched = schedule_asap(graph, timing)
    return graph, sched, allocate_systolic(graph, sched)


def window(net, tap) -> tuple[float, float]:
    """[first, last + 1) tick at which `tap` shows torque set 0's value, from the model docstring."""
    C = net.cycle
    if tap.kind == "const":
        return (float("-inf"), float("inf"))
    if tap.kind == "port":
        c = net.ports[tap.index].cycle
        return (c * C, (c + 1) * C)
    if tap.kind == "vamp":
        return (net.vamps[tap.index].dump + 1, net.vamps[tap.index].dump + 1 + C)
    buf = net.buffers[tap.index]
    c = (net.vamps[buf.source].dump + 1) // C + tap.stage
    return (c * C, (c + 1) * C)


def tap_source(graph, net, tap):
    """The graph node whose value a tap carries (a VAMP's or buffer source's node, a port's key,
    a constant's value)."""
    if tap.kind == "vamp":
        return graph.nodes[net.vamps[tap.index].node]
    if tap.kind == "buffer":
        return graph.nodes[net.vamps[net.buffers[tap.index].source].node]
    if tap.kind == "port":
        return net.ports[tap.index].key
    return net.consts[tap.index].value


def operands(net):
    """(vamp, 'A'|'B', latch tick, tap) for every operand tap."""
    for v in net.vamps:
        for name, op, latch in (("A", v.a, v.latch_a), ("B", v.b, v.latch_b)):
            for tap in op.taps:
                yield v, name, latch, tap


def test_systolic_n6_totals_match_paper():
    graph, _, net = build(6)
    sections = Counter(graph.nodes[v.node].section for v in net.vamps)
    assert sections["bwd"] + sections["npv"] == 132
    assert (sections["bwd"], sections["npv"], sections["fwd"]) == (72, 60, 48)
    assert len(net.vamps) == 180


@pytest.mark.parametrize("n,prismatic,timing", CASES, ids=CASE_IDS)
def test_one_vamp_per_op_with_its_graph_operands(n, prismatic, timing):
    graph, sched, net = build(n, prismatic, timing)
    assert sorted(v.node for v in net.vamps) == sorted(nd.id for nd in graph.compute_nodes())
    for v in net.vamps:
        nd = graph.nodes[v.node]
        assert v.op is nd.op
        for arg, op in zip(nd.args, (v.a, v.b)):
            src = graph.nodes[arg]
            want = src.key if src.key else src.value if src.value is not None else src
            assert [tap_source(graph, net, t) for t in op.taps] == [want]
        assert (v.latch_a, v.latch_b, v.dump + 1) == (sched.start[nd.id],) * 2 + (sched.finish[nd.id],)


@pytest.mark.parametrize("n,prismatic,timing", CASES, ids=CASE_IDS)
def test_every_tap_window_contains_its_latch_tick(n, prismatic, timing):
    _, _, net = build(n, prismatic, timing)
    verify_network(net)
    for v, name, latch, tap in operands(net):
        lo, hi = window(net, tap)
        assert lo <= latch < hi, (v.index, name, tap)
        if tap.kind == "buffer":
            assert 1 <= tap.stage <= net.buffers[tap.index].stages


@pytest.mark.parametrize("n,prismatic,timing", CASES, ids=CASE_IDS)
def test_buffers_are_as_long_as_their_latest_reader_needs(n, prismatic, timing):
    graph, sched, net = build(n, prismatic, timing)
    C, need = net.cycle, Counter()
    vamp_of = {v.node: v.index for v in net.vamps}
    for nd in graph.compute_nodes():
        for arg in nd.args:
            if arg in vamp_of and sched.start[nd.id] >= sched.finish[arg] + C:
                stage = sched.start[nd.id] // C - sched.finish[arg] // C
                need[vamp_of[arg]] = max(need[vamp_of[arg]], stage)
    assert {b.source: b.stages for b in net.buffers} == dict(need)
    assert net.buffer_stages == sum(need.values())


def test_no_buffer_between_successive_recursion_nodes():
    # Section VI: "Buffering between nodes is not needed in the linear case".
    graph, _, net = build(8, 0.3)
    for v, _, _, tap in operands(net):
        if tap.kind == "buffer":
            src, dst = tap_source(graph, net, tap), graph.nodes[v.node]
            assert src.group == dst.group, (src.label, dst.label)


def test_buffers_only_carry_backward_results_to_the_forward_recursion():
    graph, _, net = build(6)
    for v, _, _, tap in operands(net):
        if tap.kind == "buffer":
            src, dst = tap_source(graph, net, tap), graph.nodes[v.node]
            assert dst.section == "fwd", (src.label, dst.label)
            assert not _reads_forward_recursion(graph, src.id), (src.label, dst.label)


def _reads_forward_recursion(graph, node_id: int) -> bool:
    """True if the node depends on f_{n+1}, n_{n+1} or a forward-recursion f, n."""
    nd = graph.nodes[node_id]
    if nd.name in ("f_tip", "n_tip") or (nd.section, nd.name) in (("fwd", "f"), ("fwd", "n")):
        return True
    return any(_reads_forward_recursion(graph, a) for a in nd.args)


def test_ports_constants_and_outputs():
    graph, sched, net = build(5, 0.4)
    C = net.cycle
    for v, _, latch, tap in operands(net):
        if tap.kind == "port":
            assert net.ports[tap.index].cycle == latch // C
    keys = [(p.key, p.cycle) for p in net.ports]
    assert len(keys) == len(set(keys))
    values = [c.value for c in net.consts]
    assert len(values) == len(set(values))
    assert sorted(o.joint for o in net.outputs) == [1, 2, 3, 4, 5]
    for o, go in zip(sorted(net.outputs, key=lambda o: o.joint), graph.outputs):
        assert (net.vamps[o.vamp].node, o.component, o.tick) == (go.node, go.component,
                                                                 sched.finish[go.node])
    assert net.latency == sched.latency


def test_shifted_latch_is_rejected_naming_vamp_tick_and_operand():
    _, _, net = build(3)
    v = next(v for v in net.vamps if v.a.taps[0].kind == "vamp")
    src = v.a.taps[0].index
    emit = net.vamps[src].dump + 1
    bad = dataclasses.replace(v, latch_a=v.latch_a + net.cycle)
    broken = dataclasses.replace(net, vamps=net.vamps[:v.index] + (bad,) + net.vamps[v.index + 1:])
    with pytest.raises(VampcInternalError) as err:
        verify_network(broken)
    assert str(err.value) == (f"VAMP {v.index}: operand A latched at tick {v.latch_a + net.cycle} "
                              f"outside vamp {src}'s window [{emit}, {emit + net.cycle})")


def test_shifted_operand_b_latch_is_rejected():
    _, _, net = build(3)
    v = next(v for v in net.vamps if v.b.taps[0].kind == "vamp")
    bad = dataclasses.replace(v, latch_b=v.latch_b - 1)
    broken = dataclasses.replace(net, vamps=net.vamps[:v.index] + (bad,) + net.vamps[v.index + 1:])
    with pytest.raises(VampcInternalError,
                       match=rf"^VAMP {v.index}: operand B latched at tick {v.latch_b - 1} outside "
                             rf"vamp \d+'s window \[\d+, \d+\)$"):
        verify_network(broken)


def test_tap_past_the_end_of_a_buffer_is_rejected():
    _, _, net = build(4)
    v, name, _, tap = next(x for x in operands(net) if x[3].kind == "buffer")
    short = dataclasses.replace(net.buffers[tap.index], stages=tap.stage - 1)
    broken = dataclasses.replace(net, buffers=net.buffers[:tap.index] + (short,)
                                 + net.buffers[tap.index + 1:])
    with pytest.raises(VampcInternalError,
                       match=rf"^VAMP {v.index}: operand {name} taps missing buffer {tap.index} "
                             rf"stage {tap.stage}$"):
        verify_network(broken)
