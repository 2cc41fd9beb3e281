"""The network check (Network.verify): every slot's operands show its graph node's operands at its latch
ticks, by the timing rules of vampc.machine.timing, and no two slots of a VAMP overlap. It is run on
every network the allocator makes when verification is on (always in the tests)."""
from __future__ import annotations

import math
import operator

from vampc.dataflow.graph import Graph
from vampc.errors import VampcInternalError
from vampc.kinds import TapKind, unhandled
from vampc.machine.ops import VAMPS_PER_OP, Op
from vampc.machine.timing import (
    PortSchedule,
    buffer_window,
    overlapping_spans,
    port_window,
    result_window,
    result_windows,
)
from vampc.network.model import PROGRAM_WIRE_READ, Network, Slot, Vamp, program_wire
from vampc.schedule.asap import Schedule

# (slots as a program holds them, ProgrammedSlot: refused by _Shown, which walks every VAMP first)
_PROGRAMMED = ("a programmed network holds Cycle-Counter values: verify the network at the "
               "schedule's ticks (scheduled_network_from_doc)")


class _Shown:
    """(VAMP, node) -> (emit, next emit): the ticks the VAMP's Result shows that node's value (set
    0), None if the VAMP does not run the node. A one-slot VAMP's window is worked out when asked
    (the common case by far: a dict of a million such windows took a second and 200 MB)."""

    def __init__(self, net: Network):
        self.vamps, self.P = net.vamps, net.period
        self.multi = {}         # (VAMP, node) -> (window, column), for VAMPs of several slots
        for v in net.vamps:
            slots = v.slots
            if len(slots) < 2:                     # (one slot, the common case: in line)
                if slots and type(slots[0]) is not Slot:
                    raise VampcInternalError(_PROGRAMMED)
                continue
            if not all(type(s) is Slot for s in slots):
                raise VampcInternalError(_PROGRAMMED)
            windows = result_windows([s.dump for s in slots], net.period)
            self.multi.update({(v.index, s.node): (w, s.column) for s, w in zip(slots, windows)})

    def column(self, v: int, node: int) -> int | None:
        """The column of `node` that VAMP `v` computes (None for a whole vector; `get` first)."""
        slots = self.vamps[v].slots
        return slots[0].column if len(slots) == 1 else self.multi[(v, node)][1]

    def get(self, key: tuple[int, int]) -> tuple[int, int] | None:
        v, node = key
        if not 0 <= v < len(self.vamps):
            return None
        slots = self.vamps[v].slots
        if len(slots) != 1:
            hit = self.multi.get(key)
            return None if hit is None else hit[0]
        s = slots[0]
        return (s.dump + 1, s.dump + 1 + self.P) if s.node == node else None


_VAMP, _BUFFER = TapKind.VAMP, TapKind.BUFFER     # (an Enum member read from its class: 85 ns)
_index = operator.attrgetter("index")


def verify_network(net: Network, graph: Graph, sched: Schedule) -> None:
    """Every slot's operands show its graph node's operands at its latch ticks, by the rules of
    vampc.network.model; slots of a VAMP never overlap. Raise VampcInternalError naming the VAMP,
    the slot, the tick and the operand."""
    if not all(map(operator.eq, map(_index, net.vamps), range(len(net.vamps)))):
        k = next(k for k, v in enumerate(net.vamps) if v.index != k)   # (taps name VAMPs by index)
        raise VampcInternalError(f"VAMP {net.vamps[k].index} is at position {k}")
    shown = _Shown(net)
    ports = _PortIndex(net)
    P, B = net.period, net.clock
    nodes, count = graph.nodes, len(net.vamps)
    bus = net.bus is not None
    for v in net.vamps:
        _verify_slots(v, P)
        for k, s in enumerate(v.slots):
            if bus and s.sel_a == 0 and program_wire(v):
                raise VampcInternalError(f"VAMP {v.index} slot {k}: {PROGRAM_WIRE_READ}")
            arg_a, arg_b = nodes[s.node].args
            a, b = v.a[s.sel_a], v.b[s.sel_b]
            if not _on_results(a.taps, arg_a, s.latch_a, net, count, P, B):
                _verify_operand(net, graph, shown, ports, v, k, "A", a, s.latch_a, arg_a, B)
            if not _on_results(b.taps, arg_b, s.latch_b, net, count, P, B):
                _verify_operand(net, graph, shown, ports, v, k, "B", b, s.latch_b, arg_b, B)


def _on_results(taps, arg: int, latch: int, net: Network, count: int, P: int, B: int) -> bool:
    """Whether every tap of an operand shows node `arg` at tick `latch` from the Result of a
    one-slot VAMP running it, or from a stage of the buffer behind one (windows: vampc.machine.
    timing). Most operands are such, and are checked here; False sends the operand to
    _verify_operand, which checks every kind of tap and says what is wrong."""
    vamps, n = net.vamps, len(taps)
    for j, t in enumerate(taps):
        if t.kind is _VAMP:
            source, stage = t.index, 0
        elif t.kind is _BUFFER and 0 <= t.index < len(net.buffers):
            buffer = net.buffers[t.index]
            if not 1 <= t.stage <= buffer.stages:
                return False
            source, stage = buffer.source, t.stage
        else:
            return False
        if not 0 <= source < count:
            return False
        slots = vamps[source].slots
        if len(slots) != 1 or slots[0].node != arg:
            return False
        if slots[0].column != (j if n > 1 else None) or n > 1 and n != VAMPS_PER_OP[slots[0].op]:
            return False            # (a matrix's columns, one per tap and in order)
        emit = slots[0].dump + 1
        lo, hi = (emit, emit + P) if stage == 0 else buffer_window(emit, emit + P, stage, B)
        if not lo <= latch < hi:
            return False
    return n > 0


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
    want = VAMPS_PER_OP[src.op] if src.op.is_compute else 1
    if len(operand.taps) != want:       # a matrix made by three VAMPs: a tap per column
        raise VampcInternalError(f"VAMP {v.index} slot {k}: operand {name} has "
                                 f"{len(operand.taps)} taps, but node {src.label} comes from "
                                 f"{want} (VAMPs, or an input or constant buffer)")
    for j, tap in enumerate(operand.taps):
        kind, source = tap.kind, None       # source: the VAMP whose Result the tap carries
        if kind is TapKind.VAMP:
            source = tap.index
            emit_next = shown.get((source, arg))
            ok = emit_next is not None
            lo, hi = result_window(*emit_next) if ok else (0, 0)
        elif kind is TapKind.BUFFER:
            buffer = net.buffers[tap.index]
            if not 1 <= tap.stage <= buffer.stages:
                raise VampcInternalError(f"VAMP {v.index}: operand {name} taps missing {tap}")
            source = buffer.source
            emit_next = shown.get((source, arg))
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
        if not ok and kind is TapKind.CONST and src.op is Op.CONST and \
                net.consts[tap.index].name == src.name:     # (an edited value: said as one)
            raise VampcInternalError(f"VAMP {v.index} slot {k}: operand {name} is wired to {tap} "
                                     f"({src.name}), whose value differs from node {src.label}'s")
        if not ok:
            raise VampcInternalError(f"VAMP {v.index} slot {k}: operand {name} is wired to {tap}, "
                                     f"which does not carry node {src.label}")
        if source is not None:
            column = shown.column(source, arg)
            if column != (j if want > 1 else None):
                raise VampcInternalError(f"VAMP {v.index} slot {k}: operand {name}'s tap {j} "
                                         f"({tap}) carries column {column} of node {src.label}")
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
