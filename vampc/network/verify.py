"""The network check (Network.verify): every slot's operands show its graph node's operands at its latch
ticks, by the timing rules of vampc.machine.timing, and no two slots of a VAMP overlap. It is run on
every network the allocator makes when verification is on (always in the tests)."""
from __future__ import annotations

import math

from vampc.dataflow.graph import Graph
from vampc.errors import VampcInternalError
from vampc.kinds import TapKind, unhandled
from vampc.machine.ops import Op
from vampc.machine.timing import (
    PortSchedule,
    buffer_window,
    overlapping_spans,
    port_window,
    result_window,
    result_windows,
)
from vampc.network.model import Network, Vamp
from vampc.schedule.asap import Schedule


def shown_windows(net: Network) -> dict[tuple[int, int], tuple[int, int]]:
    """(VAMP, node) -> (emit, next emit): the ticks the VAMP's Result shows that node's value
    (set 0)."""
    out = {}
    P = net.period
    for v in net.vamps:
        if len(v.slots) == 1:       # a systolic VAMP: the common case by far
            s = v.slots[0]
            out[(v.index, s.node)] = (s.dump + 1, s.dump + 1 + P)
            continue
        windows = result_windows([s.dump for s in v.slots], P)
        out.update({(v.index, s.node): w for s, w in zip(v.slots, windows)})
    return out


def verify_network(net: Network, graph: Graph, sched: Schedule) -> None:
    """Every slot's operands show its graph node's operands at its latch ticks, by the rules of
    vampc.network.model; slots of a VAMP never overlap. Raise VampcInternalError naming the VAMP,
    the slot, the tick and the operand."""
    shown = shown_windows(net)
    ports = _PortIndex(net)
    P, B = net.period, net.clock
    nodes = graph.nodes
    VAMP = TapKind.VAMP
    for v in net.vamps:
        _verify_slots(v, P)
        for k, s in enumerate(v.slots):
            arg_a, arg_b = nodes[s.node].args
            # most operands are one other VAMP's Result, shown over its window: checked here
            taps = v.a[s.sel_a].taps
            window = shown.get((taps[0].index, arg_a)) if taps[0].kind is VAMP else None
            if len(taps) != 1 or window is None or not window[0] <= s.latch_a < window[1]:
                _verify_operand(net, graph, shown, ports, v, k, "A", v.a[s.sel_a], s.latch_a,
                                arg_a, B)
            taps = v.b[s.sel_b].taps
            window = shown.get((taps[0].index, arg_b)) if taps[0].kind is VAMP else None
            if len(taps) != 1 or window is None or not window[0] <= s.latch_b < window[1]:
                _verify_operand(net, graph, shown, ports, v, k, "B", v.b[s.sel_b], s.latch_b,
                                arg_b, B)


def _verify_slots(v: Vamp, P: int) -> None:
    """Each slot's latch..dump fits in a period and no two slots' spans meet (cyclically)."""
    for s in v.slots:
        if not s.latch_a <= s.dump < s.latch_a + P:
            raise VampcInternalError(f"VAMP {v.index}: slot latched at {s.latch_a} dumps at {s.dump}")
    if len(v.slots) < 2:
        return
    met = overlapping_spans([(s.latch_a, s.dump - s.latch_a + 1) for s in v.slots], P)
    if met is not None:
        raise VampcInternalError(f"VAMP {v.index}: slots {met[0]} and {met[1]} overlap")


def _verify_operand(net, graph, shown, ports, v, k, name, operand, latch, arg, B) -> None:
    src = graph.nodes[arg]
    for tap in operand.taps:
        kind = tap.kind
        if kind is TapKind.VAMP:
            emit_next = shown.get((tap.index, arg))
            ok = emit_next is not None
            lo, hi = result_window(*emit_next) if ok else (0, 0)
        elif kind is TapKind.BUFFER:
            buffer = net.buffers[tap.index]
            if not 1 <= tap.stage <= buffer.stages:
                raise VampcInternalError(f"VAMP {v.index}: operand {name} taps missing {tap}")
            emit_next = shown.get((buffer.source, arg))
            ok = emit_next is not None
            lo, hi = buffer_window(*emit_next, tap.stage, B) if ok else (0, 0)
        elif kind is TapKind.PORT:
            lo, hi, key = ports.showing(tap.index, latch)
            ok = src.op is Op.INPUT and key == src.key
        elif kind is TapKind.CONST:
            ok = src.op is Op.CONST and tuple(net.consts[tap.index].value) == src.value
            lo, hi = -math.inf, math.inf
        else:
            unhandled(kind)
        if not ok:
            raise VampcInternalError(f"VAMP {v.index} slot {k}: operand {name} is wired to {tap}, "
                                     f"which does not carry node {src.label}")
        if not lo <= latch < hi:
            raise VampcInternalError(f"VAMP {v.index}: operand {name} latched at tick {latch} outside "
                                     f"{tap}'s window [{lo}, {hi})")


class _PortIndex:
    """Which entry of a port shows at a tick (the rule: machine.timing.PortSchedule)."""

    def __init__(self, net: Network):
        self.net, self.B, self.K = net, net.clock, net.period // net.clock
        self.schedules = [PortSchedule([e.block for e in p.entries], self.K) for p in net.ports]

    def showing(self, port: int, tick: int):
        """(first, end, key): the window of the entry a port shows at absolute tick `tick` (set 0),
        and its key; key None if that entry belongs to another set or the port has none."""
        schedule = self.schedules[port]
        block = tick // self.B
        j = schedule.entry_at(block)
        if j is None:
            return 0, 0, None
        e = self.net.ports[port].entries[j]
        written = block - ((block - e.block) % self.K)
        lo, hi = port_window(written, written + schedule.gap[j], self.B)
        return lo, hi, (e.key if written == e.block else None)
