"""The network check (Network.verify): every slot's operands show its graph node's operands at its latch
ticks, by the timing rules of vampc.machine.timing, and no two slots of a VAMP overlap. It is run on
every network the allocator makes when verification is on (always in the tests)."""
from __future__ import annotations

from vampc.dataflow.graph import Graph
from vampc.errors import VampcInternalError
from vampc.kinds import TapKind
from vampc.machine.ops import Op
from vampc.machine.timing import (
    PortSchedule,
    overlapping_spans,
    port_window,
    result_windows,
    window,
)
from vampc.network.model import Network, Vamp
from vampc.schedule.asap import Schedule


def slot_windows(net: Network) -> dict[tuple[int, int], tuple[int, int]]:
    """(VAMP, slot) -> (emit, next emit): the ticks its value is on the Result (set 0)."""
    out = {}
    P = net.period
    for v in net.vamps:
        if len(v.slots) == 1:       # a systolic VAMP: the common case by far
            emit = v.slots[0].dump + 1
            out[(v.index, 0)] = (emit, emit + P)
            continue
        windows = result_windows([s.dump for s in v.slots], P)
        out.update({(v.index, k): w for k, w in enumerate(windows)})
    return out


def verify_network(net: Network, graph: Graph, sched: Schedule) -> None:
    """Every slot's operands show its graph node's operands at its latch ticks, by the rules of
    vampc.network.model; slots of a VAMP never overlap. Raise VampcInternalError naming the VAMP,
    the slot, the tick and the operand."""
    wins = slot_windows(net)
    slot_of = {(v.index, s.node): k for v in net.vamps for k, s in enumerate(v.slots)}
    ports = _PortIndex(net)
    P, B = net.period, net.clock
    checked: set = set()     # (id(operand), latch, arg) already found right
    for v in net.vamps:
        _verify_slots(v, P)
        for k, s in enumerate(v.slots):
            nd = graph.nodes[s.node]
            for name, operand, latch, arg in (("A", v.a[s.sel_a], s.latch_a, nd.args[0]),
                                              ("B", v.b[s.sel_b], s.latch_b, nd.args[1])):
                key = (id(operand), latch, arg)
                if key not in checked:
                    checked.add(key)
                    _verify_operand(net, graph, wins, slot_of, ports, v, k, name, operand, latch,
                                    arg, B)


def _verify_slots(v: Vamp, P: int) -> None:
    """Each slot's latch..dump fits in a period and no two slots' spans meet (cyclically)."""
    for s in v.slots:
        if not s.latch_a <= s.dump < s.latch_a + P:
            raise VampcInternalError(f"VAMP {v.index}: slot latched at {s.latch_a} dumps at {s.dump}")
    met = overlapping_spans([(s.latch_a, s.dump - s.latch_a + 1) for s in v.slots], P)
    if met is not None:
        raise VampcInternalError(f"VAMP {v.index}: slots {met[0]} and {met[1]} overlap")


def _verify_operand(net, graph, wins, slot_of, ports, v, k, name, operand, latch, arg, B) -> None:
    src = graph.nodes[arg]
    for tap in operand.taps:
        if tap.kind is TapKind.CONST:
            ok = src.op is Op.CONST and tuple(net.consts[tap.index].value) == src.value
            lo, hi = -float("inf"), float("inf")
        elif tap.kind is TapKind.PORT:
            lo, hi, key = ports.showing(tap.index, latch)
            ok = src.op is Op.INPUT and key == src.key
        else:
            vamp = tap.index if tap.kind is TapKind.VAMP else net.buffers[tap.index].source
            if not (tap.kind is TapKind.VAMP or 1 <= tap.stage <= net.buffers[tap.index].stages):
                raise VampcInternalError(f"VAMP {v.index}: operand {name} taps missing {tap}")
            src_slot = slot_of.get((vamp, arg))
            ok = src_slot is not None
            emit, nxt = wins[(vamp, src_slot)] if ok else (0, 0)
            lo, hi = window(tap, B, emit, nxt)
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
