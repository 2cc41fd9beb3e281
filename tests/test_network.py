"""Allocation (vampc.network.allocate) and the network IR's timing model (vampc.network.model), for the
systolic layout (one op per VAMP) and the folded layouts (VAMPs with slots and multiplexers).

VAMP counts come from the paper (section VI, "VAMPs - Totals, n = 6": linear systolic pipeline 132
backward + 48 forward; single device 22 + 8, or 22 with the passes sharing processors). Tap windows
are recomputed here from the rules in the model's docstring, not with the model's window functions.
"""
from __future__ import annotations

import dataclasses
from collections import Counter

import msgspec
import pytest

from vampc.dataflow.linear import build_linear
from vampc.dataflow.logarithmic import build_log
from vampc.errors import VampcInternalError
from vampc.machine.ops import Op, Timing
from vampc.network.allocate import allocate
from vampc.network.verify import verify_network
from vampc.program.emit import a_roots
from vampc.robot.random import random_chain
from vampc.schedule.layout import layout_and_schedule
from vampc.schedule.registry import LayoutRequest

CASES = [(6, 0.0, Timing()), (6, 0.5, Timing()), (1, 0.0, Timing()), (9, 0.3, Timing(2, 3))]
CASE_IDS = ["rotary6", "mixed6", "rotary1", "mixed9-m2a3"]
LAYOUTS = [("systolic", False), ("folded", False), ("folded", True)]
LAYOUT_IDS = ["systolic", "folded", "shared"]


def build(n: int, prismatic: float = 0.0, timing: Timing = Timing(), seed: int = 0,
          layout: str = "systolic", share: bool = False, log: bool = False):
    """(graph, schedule, network) of a random chain."""
    chain = random_chain(n, seed, prismatic_fraction=prismatic)
    graph = build_log(chain) if log else build_linear(chain)
    lay, sched = layout_and_schedule(graph, timing, layout, LayoutRequest(share))
    return graph, sched, allocate(graph, sched, lay)


def slot_windows(net):
    """(vamp, slot) -> [emit, next emit): a slot's value stays on the Result until the VAMP's next
    dump shows (the next slot in dump order; the first one again a period later)."""
    out = {}
    for v in net.vamps:
        emits = sorted(s.dump + 1 for s in v.slots)
        for k, s in enumerate(v.slots):
            later = [e for e in emits if e > s.dump + 1]
            out[(v.index, k)] = (s.dump + 1, later[0] if later else emits[0] + net.period)
    return out


def shown(net, wins, tap, tick):
    """What `tap` shows at absolute tick `tick` of set 0, by the model docstring: ("slot", v, k),
    ("input", key) or ("const", value); None if nothing of set 0."""
    B = net.clock
    if tap.kind == "const":
        return ("const", net.consts[tap.index].value)
    if tap.kind == "port":
        port = net.ports[tap.index]
        for j, e in enumerate(port.entries):
            nxt = port.entries[(j + 1) % len(port.entries)].block
            end = nxt if nxt > e.block else nxt + net.period // B
            if e.block * B <= tick < end * B:
                return ("input", e.key)
        return None
    v = tap.index if tap.kind == "vamp" else net.buffers[tap.index].source
    for k in range(len(net.vamps[v].slots)):
        emit, nxt = wins[(v, k)]
        if tap.kind == "vamp" and emit <= tick < nxt:
            return ("slot", v, k)
        if tap.kind == "buffer" and (emit // B + tap.stage) * B <= tick < (nxt // B + tap.stage) * B:
            return ("slot", v, k)
    return None


def reads(net):
    """(vamp, slot index, slot, 'A'|'B', latch tick, operand) for every operand latch."""
    for v in net.vamps:
        for k, s in enumerate(v.slots):
            yield v, k, s, "A", s.latch_a, v.a[s.sel_a]
            yield v, k, s, "B", s.latch_b, v.b[s.sel_b]


def carried(graph, net, src):
    if src is None:
        return None
    if src[0] == "slot":
        return graph.nodes[net.vamps[src[1]].slots[src[2]].node]
    return src[1]


def test_systolic_n6_totals_match_paper():
    graph, _, net = build(6)
    sections = Counter(graph.nodes[v.node].section for v in net.vamps)
    assert sections["bwd"] + sections["npv"] == 132
    assert (sections["bwd"], sections["npv"], sections["fwd"]) == (72, 60, 48)
    assert len(net.vamps) == 180 and all(len(v.slots) == 1 for v in net.vamps)
    assert net.period == net.clock == 4


def test_folded_n6_single_device_matches_paper():
    graph, _, net = build(6, layout="folded")
    kinds = Counter("fwd" if {graph.nodes[s.node].section for s in v.slots} == {"fwd"} else "bwd"
                    for v in net.vamps)
    assert (kinds["bwd"], kinds["fwd"]) == (22, 8)        # one node each way (Figure VI.1a)
    assert len(build(6, layout="folded", share=True)[2].vamps) == 22    # Figure VI.1b


@pytest.mark.parametrize("layout,share", LAYOUTS, ids=LAYOUT_IDS)
@pytest.mark.parametrize("n,prismatic,timing", CASES, ids=CASE_IDS)
def test_every_op_in_one_slot_reading_its_graph_operands(n, prismatic, timing, layout, share):
    graph, sched, net = build(n, prismatic, timing, layout=layout, share=share)
    wins = slot_windows(net)
    placed = Counter(s.node for v in net.vamps for s in v.slots)
    ops = {nd.id: (3 if nd.op is Op.MM else 1) for nd in graph.compute_nodes()}
    assert dict(placed) == ops
    for v, k, s, name, latch, operand in reads(net):
        nd = graph.nodes[s.node]
        assert s.op is nd.op
        assert (s.latch_a, s.latch_b, s.dump + 1) == (sched.start[nd.id],) * 2 + (sched.finish[nd.id],)
        src = graph.nodes[nd.args[0 if name == "A" else 1]]
        want = src.key if src.key else src.value if src.value is not None else src
        got = [carried(graph, net, shown(net, wins, t, latch)) for t in operand.taps]
        assert got == [want] * len(operand.taps), (v.index, k, name)


@pytest.mark.parametrize("layout,share", LAYOUTS, ids=LAYOUT_IDS)
@pytest.mark.parametrize("n,prismatic,timing", CASES, ids=CASE_IDS)
def test_slots_never_overlap_and_every_input_is_used(n, prismatic, timing, layout, share):
    graph, sched, net = build(n, prismatic, timing, layout=layout, share=share)
    verify_network(net, graph, sched)
    P = net.period
    for v in net.vamps:
        busy = Counter(t % P for s in v.slots for t in range(s.latch_a, s.dump + 1))
        assert max(busy.values()) == 1, v.index
        assert {s.sel_a for s in v.slots} | ({0} if not _reaches_data(net, v.a[0]) else set()) \
            == set(range(len(v.a)))
        assert {s.sel_b for s in v.slots} == set(range(len(v.b)))
    a_roots(net)        # every VAMP can be programmed through its operand-A input 0


def _reaches_data(net, operand) -> bool:
    tap = operand.taps[0]
    return not (tap.kind == "port" and not net.ports[tap.index].entries)


@pytest.mark.parametrize("n,prismatic,timing", CASES, ids=CASE_IDS)
def test_buffers_are_as_long_as_their_latest_reader_needs(n, prismatic, timing):
    graph, sched, net = build(n, prismatic, timing)
    C, need = net.period, Counter()
    vamp_of = {v.node: v.index for v in net.vamps}
    for nd in graph.compute_nodes():
        for arg in nd.args:
            if arg in vamp_of and sched.start[nd.id] >= sched.finish[arg] + C:
                stage = sched.start[nd.id] // C - sched.finish[arg] // C
                need[vamp_of[arg]] = max(need[vamp_of[arg]], stage)
    assert {b.source: b.stages for b in net.buffers} == dict(need)
    assert net.buffer_stages == sum(need.values())


def _buffered(net):
    for v, k, s, _, _, operand in reads(net):
        for tap in operand.taps:
            if tap.kind == "buffer":
                yield s, tap


def test_no_buffer_between_successive_recursion_nodes():
    # Section VI: "Buffering between nodes is not needed in the linear case".
    graph, _, net = build(8, 0.3)
    for s, tap in _buffered(net):
        src = graph.nodes[net.vamps[net.buffers[tap.index].source].node]
        dst = graph.nodes[s.node]
        assert src.group == dst.group, (src.label, dst.label)


def test_buffers_only_carry_backward_results_to_the_forward_recursion():
    graph, _, net = build(6)
    for s, tap in _buffered(net):
        src = graph.nodes[net.vamps[net.buffers[tap.index].source].node]
        dst = graph.nodes[s.node]
        assert dst.section == "fwd", (src.label, dst.label)
        assert not _reads_forward_recursion(graph, src.id), (src.label, dst.label)


def _reads_forward_recursion(graph, node_id: int) -> bool:
    """True if the node depends on f_{n+1}, n_{n+1} or a forward-recursion f, n."""
    nd = graph.nodes[node_id]
    if nd.name in ("f_tip", "n_tip") or (nd.section, nd.name) in (("fwd", "f"), ("fwd", "n")):
        return True
    return any(_reads_forward_recursion(graph, a) for a in nd.args)


@pytest.mark.parametrize("layout,share", LAYOUTS, ids=LAYOUT_IDS)
def test_ports_constants_and_outputs(layout, share):
    graph, sched, net = build(5, 0.4, layout=layout, share=share)
    B, K = net.clock, net.period // net.clock
    for v, k, s, name, latch, operand in reads(net):
        for tap in operand.taps:
            if tap.kind == "port":      # the entry written last before the read: its key, set 0
                shown = _port_shows(net.ports[tap.index], latch // B, K)
                key = graph.nodes[graph.nodes[s.node].args["AB".index(name)]].key
                assert shown == (key, 0)
    for p in net.ports:
        blocks = [e.block % K for e in p.entries]
        assert len(blocks) == len(set(blocks))          # one write per block of the period
    entries = [(e.key, e.block) for p in net.ports for e in p.entries]
    assert len(entries) == len(set(entries))
    values = [c.value for c in net.consts]
    assert len(values) == len(set(values))
    assert sorted(o.joint for o in net.outputs) == [1, 2, 3, 4, 5]
    for o, go in zip(sorted(net.outputs, key=lambda o: o.joint), graph.outputs):
        slot = next(s for s in net.vamps[o.vamp].slots if s.dump + 1 == o.tick)
        assert (slot.node, o.component, o.tick) == (go.node, go.component, sched.finish[go.node])
    assert net.latency == sched.latency < net.period or layout == "systolic"


def _port_shows(port, block: int, K: int):
    """(key, set) a port shows during absolute block `block` of set 0's ticks: written last at or
    before it, each entry again every K blocks for the next set (README, Timing model)."""
    written = [(e.block + K * ((block - e.block) // K), e) for e in port.entries]
    at, e = max(written, key=lambda w: w[0])
    return e.key, (at - e.block) // K


@pytest.mark.parametrize("options", [dict(layout="folded"), dict(layout="folded", share=True),
                                     dict(layout="folded", log=True), dict(layout="budget3"),
                                     dict(layout="budget12")],
                         ids=["folded", "shared", "log-folded", "budget3", "budget12"])
def test_a_port_is_written_once_for_each_run_of_reads_of_one_value(options):
    """The host writes a port when what its reads need changes: counted here from the reads alone,
    in the period's order of their ticks, a new write wherever a read needs another key, or the
    same key of another set, than the read before it (cyclically). The allocator had an entry for
    each block a read fell in, so a folded Puma wrote A_1 in blocks 0 and 1 and A_6 in 6, 8 and 9 of
    one set (54 writes a set on the log folded Puma where 46 carry every value: a hardware user's
    find); the reads still see their values (the test above, and Network.verify)."""
    budget = options.pop("layout", "") if str(options.get("layout", "")).startswith("budget") else ""
    if budget:
        chain = random_chain(6, 0, prismatic_fraction=0.3)
        graph = build_linear(chain)
        lay, sched = layout_and_schedule(graph, Timing(), "systolic",
                                         LayoutRequest(vamps=int(budget[6:])))
        net = allocate(graph, sched, lay)
    else:
        graph, sched, net = build(6, 0.3, **options)
    B, P = net.clock, net.period
    needs: dict[int, list[tuple[int, object, int]]] = {}
    for v, k, s, name, latch, operand in reads(net):
        for tap in operand.taps:
            if tap.kind == "port":
                key = graph.nodes[graph.nodes[s.node].args["AB".index(name)]].key
                needs.setdefault(tap.index, []).append((latch // B * B, key, latch // B * B // P))
    runs = 0
    for port, rs in needs.items():
        rs = sorted(set(rs), key=lambda r: (r[0] % P, r[0]))
        for (t0, key0, _), (t1, key1, _) in zip([rs[-1]] + rs[:-1], rs):
            same = key0 == key1 and 0 <= t1 - t0 < P
            runs += not same or len(rs) == 1
    writes = sum(len(p.entries) for p in net.ports)
    assert writes == runs
    assert any(len(p.entries) > 1 for p in net.ports)


def test_folded_ports_are_written_per_joint():
    # The folded linear node reads A_i of joint i in its cycle: one port, written once per joint.
    _, _, net = build(6, layout="folded")
    a_ports = [p for p in net.ports if p.size == 9]
    assert sum(len(p.entries) for p in a_ports) >= 6 and len(a_ports) <= 2


def _replace_slot(net, v, k, **changes):
    vamp = net.vamps[v]
    slots = vamp.slots[:k] + (msgspec.structs.replace(vamp.slots[k], **changes),) + vamp.slots[k + 1:]
    new = msgspec.structs.replace(vamp, slots=slots)
    return dataclasses.replace(net, vamps=net.vamps[:v] + (new,) + net.vamps[v + 1:])


def test_shifted_latch_is_rejected_naming_vamp_tick_and_operand():
    graph, sched, net = build(3)
    v = next(v for v in net.vamps if v.a[0].taps[0].kind == "vamp")
    src = v.a[0].taps[0].index
    emit = net.vamps[src].slots[0].dump + 1
    latch = v.slots[0].latch_a + net.period
    broken = _replace_slot(net, v.index, 0, latch_a=latch, dump=v.slots[0].dump + net.period)
    with pytest.raises(VampcInternalError) as err:
        verify_network(broken, graph, sched)
    assert str(err.value) == (f"VAMP {v.index}: operand A latched at tick {latch} outside vamp "
                              f"{src}'s window [{emit}, {emit + net.period})")


def test_shifted_operand_b_latch_is_rejected():
    graph, sched, net = build(3)
    v = next(v for v in net.vamps if v.b[0].taps[0].kind == "vamp")
    broken = _replace_slot(net, v.index, 0, latch_b=v.slots[0].latch_b - 1)
    with pytest.raises(VampcInternalError,
                       match=rf"^VAMP {v.index}: operand B latched at tick {v.slots[0].latch_b - 1} "
                             rf"outside vamp \d+'s window \[\d+, \d+\)$"):
        verify_network(broken, graph, sched)


@pytest.mark.parametrize("kind", ["vamp", "buffer"])
def test_tap_of_another_node_shown_at_the_same_time_is_rejected(kind):
    """An operand wired to the Result (or the buffer behind it) of a one-slot VAMP whose window
    covers the latch, but which runs another node: the check names the tap and the node."""
    graph, sched, net = build(4)
    sources = {b.index: b.source for b in net.buffers}
    for v, k, s, name, latch, operand in reads(net):
        tap = operand.taps[0]
        if len(operand.taps) != 1 or tap.kind != kind:
            continue
        src = net.vamps[tap.index if kind == "vamp" else sources[tap.index]].slots[0]
        others = [t for t in (net.buffers if kind == "buffer" else net.vamps)
                  for w in [net.vamps[t.source if kind == "buffer" else t.index].slots]
                  if len(w) == 1 and w[0].node != src.node
                  and (w[0].dump == src.dump if kind == "vamp"        # a buffer's window: by block
                       else (w[0].dump + 1) // net.clock == (src.dump + 1) // net.clock
                       and t.stages >= tap.stage)]
        if others:
            break
    else:
        pytest.fail(f"no {kind} operand with another source shown at the same time")
    other = msgspec.structs.replace(tap, index=others[0].index)
    field = "a" if name == "A" else "b"
    vamp = msgspec.structs.replace(v, **{field: (type(operand)((other,)),)
                                         + getattr(v, field)[1:]})
    broken = dataclasses.replace(net, vamps=net.vamps[:v.index] + (vamp,) + net.vamps[v.index + 1:])
    assert (s.sel_a if name == "A" else s.sel_b) == 0
    with pytest.raises(VampcInternalError,
                       match=rf"^VAMP {v.index} slot {k}: operand {name} is wired to {kind} "
                             rf"{others[0].index}.*, which does not carry node "):
        verify_network(broken, graph, sched)


def test_overlapping_slots_are_rejected():
    graph, sched, net = build(4, layout="folded")
    v = next(v for v in net.vamps if len(v.slots) > 1)
    s0 = v.slots[0]
    broken = _replace_slot(net, v.index, 1, latch_a=s0.latch_a, latch_b=s0.latch_b, dump=s0.dump)
    with pytest.raises(VampcInternalError, match=rf"^VAMP {v.index}: slots \d and \d overlap$"):
        verify_network(broken, graph, sched)


def test_a_programmed_network_is_refused_by_its_check():
    """Slots as a program holds them (Cycle-Counter values, not ticks) are refused by name, whichever
    VAMP holds the first of them (a VAMP in the middle here, the others scheduled)."""
    from vampc.network.model import ProgrammedSlot
    graph, sched, net = build(4, layout="folded")
    k = len(net.vamps) // 2
    v = net.vamps[k]
    s = v.slots[0]
    programmed = ProgrammedSlot(s.node, s.op, s.column, s.sel_a, s.sel_b, 0, 0, 0)
    vamps = list(net.vamps)
    vamps[k] = msgspec.structs.replace(v, slots=(programmed,) + v.slots[1:])
    broken = dataclasses.replace(net, vamps=tuple(vamps))
    for check in (lambda: verify_network(broken, graph, sched), lambda: broken.verify(graph, sched)):
        with pytest.raises(VampcInternalError, match="^a programmed network holds Cycle-Counter values"):
            check()


def test_tap_past_the_end_of_a_buffer_is_rejected():
    graph, sched, net = build(4)
    v, _, _, name, _, operand = next(x for x in reads(net) if x[5].taps[0].kind == "buffer")
    tap = operand.taps[0]
    short = msgspec.structs.replace(net.buffers[tap.index], stages=tap.stage - 1)
    broken = dataclasses.replace(net, buffers=net.buffers[:tap.index] + (short,)
                                 + net.buffers[tap.index + 1:])
    with pytest.raises(VampcInternalError,
                       match=rf"^VAMP {v.index}: operand {name} taps missing buffer {tap.index} "
                             rf"stage {tap.stage}$"):
        verify_network(broken, graph, sched)


@pytest.mark.parametrize("share", [False, True])
def test_folded_log_networks_verify(share):
    graph, sched, net = build(7, 0.3, log=True, layout="folded", share=share)
    verify_network(net, graph, sched)
    assert net.period >= sched.latency + 1 and net.period % net.clock == 0


def _with_operand(net, v, k, name, operand):
    """`net` with input sel of slot k's operand `name` of VAMP v replaced by `operand`."""
    vamp = net.vamps[v]
    field = "a" if name == "A" else "b"
    sel = vamp.slots[k].sel_a if name == "A" else vamp.slots[k].sel_b
    inputs = getattr(vamp, field)
    vamp = msgspec.structs.replace(vamp, **{field: inputs[:sel] + (operand,) + inputs[sel + 1:]})
    return dataclasses.replace(net, vamps=net.vamps[:v] + (vamp,) + net.vamps[v + 1:])


@pytest.mark.parametrize("change", ["reversed", "cut", "first", "last", "repeated", "none"])
def test_a_matrix_operand_needs_its_three_columns_in_order(change):
    """An operand reading an MM's result (a matrix made by three VAMPs, a column each) has one tap
    per column, in column order (one tap, of the first column or the last, is not the matrix);
    an operand with no tap at all carries nothing."""
    graph, sched, net = build(3, log=True)
    v, k, _, name, _, operand = next(x for x in reads(net) if len(x[5].taps) == 3)
    taps = operand.taps
    wrong = {"reversed": taps[::-1], "cut": taps[:2], "first": taps[:1], "last": taps[2:],
             "repeated": (taps[0],) * 3, "none": ()}[change]
    broken = _with_operand(net, v.index, k, name, type(operand)(wrong))
    message = (rf"operand {name}'s tap \d \(.*\) carries column \d of node "
               if change in ("reversed", "repeated") else
               rf"operand {name} has {len(wrong)} taps, but node .* comes from 3 ")
    with pytest.raises(VampcInternalError, match=rf"^VAMP {v.index} slot {k}: {message}"):
        verify_network(broken, graph, sched)
    verify_network(net, graph, sched)


def test_vamps_out_of_their_index_order_are_rejected():
    graph, sched, net = build(2)
    vamps = list(net.vamps)
    vamps[3], vamps[5] = vamps[5], vamps[3]
    with pytest.raises(VampcInternalError, match=r"^VAMP 5 is at position 3$"):
        verify_network(dataclasses.replace(net, vamps=tuple(vamps)), graph, sched)
