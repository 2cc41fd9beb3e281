"""Allocation: a layout's units become VAMPs with slots, multiplexers, delay buffers, host ports and
constant buffers (README, *Layouts*; the hardware is described in vampc.network.model).

Every VAMP of a unit runs one slot per node bound to the unit, in the order of their dumps (three
VAMPs per MM unit, one per column). A slot latches both operands at its node's scheduled start and
dumps at its finish. An operand comes from:

- a constant: the constant buffer holding that value (two constant buffers never hold the same value);
- a host input: the entry for (quantity, joint, block of the read) of a port; entries of one quantity
  share a port when their blocks differ within the period (systolic: one block per period, so one
  port per (quantity, cycle), and the host writes each value when it is needed: no input is buffered);
- a result: the producing VAMP's Result while the value is still on it, else stage s of the delay
  buffer behind that VAMP, s = (block of the read) - (block the value appeared in). One buffer chain
  per producing VAMP serves all its later readers, of every slot.

The distinct sources an operand of a VAMP reads over its slots are its multiplexer's inputs, in order
of first use, except that input 0 of operand A is what the VAMP passes on in Program Mode: a host port
or constant buffer, or a VAMP already reached from one. A VAMP whose operand-A sources all lead back
round a loop (a folded VAMP feeding itself) gets one more input: a program port the host writes only
in Program Mode. Everything is counted in the report.
"""
from __future__ import annotations

import operator

from vampc.dataflow.graph import Graph, InputKey
from vampc.errors import VampcInternalError
from vampc.kinds import Quantity, TapKind
from vampc.machine.ops import VAMPS_PER_OP, Op
from vampc.machine.timing import buffer_stage, buffer_window, result_windows
from vampc.memo import counting
from vampc.network.model import (
    Buffer,
    Const,
    Network,
    Operand,
    OutputPoint,
    Port,
    PortEntry,
    Slot,
    Tap,
    Vamp,
    tap_source,
)
from vampc.schedule.asap import Schedule
from vampc.schedule.layout import Layout

_BLOCK = operator.attrgetter("block")


def repeats_dropped(entries: list[PortEntry], per_period: int) -> list[PortEntry]:
    """A port's entries without the writes that repeat what it shows already: an entry whose
    predecessor in the period's order (vampc.machine.timing.PortSchedule) carries the same key and
    was written for the same set in the blocks just before it (its absolute block is where the
    predecessor's window ends) adds nothing, so the predecessor's window runs on over its blocks.
    The allocator makes an entry per block a folded layout reads the port in; a folded Puma wrote
    A_1 in blocks 0 and 1 and A_6 in blocks 6, 8 and 9 of one set (54 writes a set on the log
    folded Puma where 46 carry every value: a hardware user's find, 2026-12-07). Network.verify
    checks what each read then sees, as for any entry."""
    if len(entries) < 2:
        return entries
    order = sorted(entries, key=lambda e: e.block % per_period)
    while len(order) > 1:
        again = next((k for k, e in enumerate(order) if e.key == order[k - 1].key and
                      0 < e.block - order[k - 1].block < per_period), None)
        if again is None:
            return order
        del order[again]
    return order


class _Allocator:
    """One pass over the compute nodes in topological order. An operand depends only on its source
    and on where it is read (a result's buffer stage, an input's block), so each distinct one is made
    once and shared by all its readers (log recursion, n = 4096: 1.16 M distinct operands for 1.84 M
    operand reads)."""

    def __init__(self, graph: Graph, sched: Schedule, layout: Layout):
        self.g, self.s, self.lay = graph, sched, layout
        self.P, self.B = layout.period, layout.clock
        self.stages: dict[int, int] = {}          # producer VAMP -> buffer stages needed
        self.buffer_of: dict[int, int] = {}       # producer VAMP -> buffer index (in order of first use)
        self.entries: dict[tuple[InputKey, int], int] = {}   # (key, block) -> port index
        self.taken: dict[tuple[str, int], int] = {}            # (quantity, block mod K) -> ports
        self.port_entries: list[list[PortEntry]] = []
        self.port_size: list[int] = []
        self.by_quantity: dict[str, list[int]] = {}
        self.consts: dict[tuple[float, ...], Const] = {}
        # Each operand is kept as the one-input tuple a one-slot VAMP's multiplexer is, so that
        # its readers share that tuple too (4096 joints: 40 MB): read from a node's Result, by
        # source node (a list: most operands are these); from a buffer stage, by (source node,
        # stage).
        self.at_result: list[tuple[Operand] | None] = [None] * len(graph.nodes)
        self.buffered: dict[tuple[int, int], tuple[Operand]] = {}
        self.port_operands: list[tuple[Operand]] = []
        self.const_operands: list[tuple[Operand]] = []
        self.place = layout.vamps_of()
        self.first, self.more = self._on_vamps()
        self.next_emit = self._next_emits()

    def _on_vamps(self) -> tuple[list[int], dict[int, list[int]]]:
        """Per VAMP: the first node it runs (-1 for none); and per VAMP running several, all its
        nodes in order of their dumps. (Lists and a dict of the few, not a list per VAMP: a
        4096-joint log network has a million VAMPs of one node each.)"""
        first = [-1] * self.lay.vamp_count
        more: dict[int, list[int]] = {}
        place = self.place
        for nd in self.g.compute_nodes():
            i = nd.id
            for v in place[i]:
                if first[v] < 0:
                    first[v] = i
                elif v in more:
                    more[v].append(i)
                else:
                    more[v] = [first[v], i]
        finish = self.s.finish
        for nodes in more.values():
            nodes.sort(key=lambda i: finish[i])
        return first, more

    def _next_emits(self) -> list[int | None]:
        """Per graph node: the tick the next dump of its VAMP shows (the end of its Result window;
        the earliest over an MM's three VAMPs), counted round the period; None for inputs and
        constants."""
        finish, P = self.s.finish, self.P
        out: list[int | None] = [None] * len(self.g.nodes)
        more = self.more
        for v, i in enumerate(self.first):
            if v not in more:
                if i >= 0:
                    nxt = finish[i] + P
                    if out[i] is None or nxt < out[i]:
                        out[i] = nxt
                continue
            nodes = more[v]
            for i, (_, nxt) in zip(nodes, result_windows([finish[i] - 1 for i in nodes], P)):
                if out[i] is None or nxt < out[i]:
                    out[i] = nxt
        return out

    def run(self) -> Network:
        start, finish, nxt, B = self.s.start, self.s.finish, self.next_emit, self.B
        at_result, buffered = self.at_result, self.buffered

        def read(arg: int, t: int) -> tuple[Operand]:
            # The common case: a result (a node with a next emit: not an input or a constant)
            # read at a stage already wired for another reader. The stage is 0 while the Result
            # still shows it, else buffer_stage's.
            n = nxt[arg]
            if n is None:
                return self._operand(arg, t)
            e = finish[arg]
            if e <= t < n:                   # still on the Result
                return at_result[arg] or self._result(arg, 0, t)
            stage = buffer_stage(e, n, t, B)
            return buffered.get((arg, stage)) or self._result(arg, stage, t)

        # per graph node: its operands A and B, each as (operand,); None for inputs and constants
        # (two lists, not a pair per node: a 4096-joint log graph's pairs took 60 MB)
        reads_a: list[tuple[Operand] | None] = [None] * len(self.g.nodes)
        reads_b: list[tuple[Operand] | None] = [None] * len(self.g.nodes)
        result = self._result
        for nd in self.g.compute_nodes():
            i = nd.id
            t = start[i]
            a, b = nd.args
            # read's common case in line: a result still on its Result, its operand made before
            n = nxt[a]
            reads_a[i] = (at_result[a] or result(a, 0, t)) if n is not None and \
                finish[a] <= t < n else read(a, t)
            n = nxt[b]
            reads_b[i] = (at_result[b] or result(b, 0, t)) if n is not None and \
                finish[b] <= t < n else read(b, t)
        return self._network(reads_a, reads_b)

    def _operand(self, arg: int, t: int) -> tuple[Operand]:
        """The operand reading constant or host input `arg` at tick t, as (operand,), made if new."""
        src = self.g.nodes[arg]
        if src.op is Op.CONST:
            if src.value not in self.consts:
                index = len(self.consts)
                self.consts[src.value] = Const(index, src.name, src.value)
                self.const_operands.append((Operand((Tap(TapKind.CONST, index),)),))
            return self.const_operands[self.consts[src.value].index]
        if src.op is Op.INPUT:
            return self.port_operands[self._port(src.key, t // self.B)]
        raise VampcInternalError(f"node {arg} ({src.op}) runs on no VAMP")

    def _result(self, arg: int, stage: int, t: int) -> tuple[Operand]:
        """The new operand reading node `arg`'s result at tick t, from its VAMPs' Results (stage 0)
        or stage `stage` of the buffers behind them, as (operand,) (kept in `at_result` or
        `buffered`)."""
        vamps = self.place[arg]
        emit = self.s.finish[arg]
        if stage == 0:         # (one VAMP, most nodes: its tap without a list)
            taps = (Tap(_VAMP, vamps[0]),) if len(vamps) == 1 else \
                tuple([Tap(_VAMP, v) for v in vamps])
        elif t < emit or buffer_window(emit, self.next_emit[arg], stage, self.B)[0] > t:
            raise VampcInternalError(f"VAMP {vamps[0]}: node {arg}'s result (shown from tick "
                                     f"{emit}) is gone at tick {t}: nothing buffered it")
        else:
            taps = (self._buffer_tap(vamps[0], stage),) if len(vamps) == 1 else \
                tuple([self._buffer_tap(v, stage) for v in vamps])
        operand = (Operand(taps),)
        if stage == 0:
            self.at_result[arg] = operand
        else:
            self.buffered[(arg, stage)] = operand
        return operand

    def _port(self, key: InputKey, block: int) -> int:
        """The port carrying `key` written at `block`: an existing port of the quantity whose other
        entries fall in other blocks of the period, else a new one."""
        found = self.entries.get((key, block))
        if found is not None:
            return found
        # First fit: the ports of a quantity taking this block of the period are always the first
        # `taken` of them, so the next one (or a new port) is the first free one.
        at = (key.quantity, block % (self.P // self.B))
        taken = self.taken.get(at, 0)
        ports = self.by_quantity.setdefault(key.quantity, [])
        if taken < len(ports):
            p = ports[taken]
        else:
            p = len(self.port_entries)
            self.port_entries.append([])
            self.port_size.append(9 if key.quantity is Quantity.A else 3)
            ports.append(p)
            self.port_operands.append((Operand((Tap(TapKind.PORT, p),)),))
        self.taken[at] = taken + 1
        self.port_entries[p].append(PortEntry(key, block))
        self.entries[(key, block)] = p
        return p

    def _buffer_tap(self, vamp: int, stage: int) -> Tap:
        stages = self.stages
        if stages.get(vamp, 0) < stage:
            stages[vamp] = stage
        buf = self.buffer_of.setdefault(vamp, len(self.buffer_of))
        return Tap(_BUFFER, buf, stage)

    def _network(self, reads_a, reads_b) -> Network:
        vamps = self._vamps(reads_a, reads_b)
        buffers = tuple(Buffer(i, v, self.stages[v]) for v, i in self.buffer_of.items())
        K = self.P // self.B
        ports = tuple(Port(i, size, tuple(sorted(repeats_dropped(entries, K), key=_BLOCK)))
                      for i, (size, entries) in enumerate(zip(self.port_size, self.port_entries)))
        ports = ports + self.program_ports
        outputs = tuple(OutputPoint(o.joint, self.place[o.node][0], o.component,
                                    self.s.finish[o.node]) for o in self.g.outputs)
        return Network(self.P, self.B, vamps, buffers, ports, tuple(self.consts.values()), outputs)

    def _vamps(self, reads_a, reads_b) -> tuple[Vamp, ...]:
        nodes, start, finish = self.g.nodes, self.s.start, self.s.finish
        vamps: list[Vamp] = []
        self.program_ports: tuple[Port, ...] = ()
        muxed = False
        more, place, add = self.more, self.place, vamps.append
        for v, i in zip(counting(len(self.first)), self.first):   # (shared ints: vampc.memo)
            if v not in more and i >= 0:   # the systolic case: one slot, one input per operand
                a, b = reads_a[i], reads_b[i]
                op = nodes[i].op
                t = start[i]
                where = place[i]
                add(Vamp(v, a, b, (Slot(i, op, where.index(v) if len(where) > 1 else None, 0, 0,
                                        t, t, finish[i] - 1),)))
                continue
            if i < 0:
                raise VampcInternalError(f"VAMP {v} runs no op")
            muxed = True
            vamps.append(self._muxed(v, more[v], reads_a, reads_b))
        if muxed:
            vamps = self._order_program_inputs(vamps)
        return tuple(vamps)

    def _muxed(self, v: int, mine: list[int], reads_a, reads_b) -> Vamp:
        """A VAMP running several nodes: its multiplexer inputs in order of first use."""
        nodes, start, finish = self.g.nodes, self.s.start, self.s.finish
        ins_a: dict[Operand, int] = {}
        ins_b: dict[Operand, int] = {}
        slots = []
        for i in mine:
            (a,), (b,) = reads_a[i], reads_b[i]
            sa = ins_a.setdefault(a, len(ins_a))
            sb = ins_b.setdefault(b, len(ins_b))
            col = self.place[i].index(v) if VAMPS_PER_OP[nodes[i].op] > 1 else None
            slots.append(Slot(i, nodes[i].op, col, sa, sb, start[i], start[i], finish[i] - 1))
        return Vamp(v, tuple(ins_a), tuple(ins_b), tuple(slots))

    def _order_program_inputs(self, vamps: list[Vamp]) -> list[Vamp]:
        """Make operand-A input 0 of every VAMP lead, without a loop, to a port or constant buffer
        (Program Mode passes input 0 on); a VAMP with no such input gets a program port."""
        buffers_source = {i: v for v, i in self.buffer_of.items()}
        rooted = [None] * len(vamps)       # the chosen A input of each VAMP, once it reaches a root
        pending = list(range(len(vamps)))
        while pending:
            later = []
            for v in pending:
                choice = next((k for k, op in enumerate(vamps[v].a)
                               if _reaches(op.taps[0], rooted, buffers_source)), None)
                if choice is None:
                    later.append(v)
                else:
                    rooted[v] = choice
            if len(later) == len(pending):
                break
            pending = later
        extra = []
        for v in pending:                  # nothing reaches a root: a program port of its own
            index = len(self.port_entries) + len(extra)
            extra.append(Port(index, 3, ()))
            vamp = vamps[v]
            vamps[v] = Vamp(vamp.index, (Operand((Tap(TapKind.PORT, index),)),) + vamp.a, vamp.b,
                            tuple(_shift_a(s, 1) for s in vamp.slots))
            rooted[v] = 0
        self.program_ports = tuple(extra)
        return [_with_input_first(vamps[v], rooted[v]) for v in range(len(vamps))]


_VAMP, _BUFFER = TapKind.VAMP, TapKind.BUFFER   # (an Enum member read from its class: 85 ns)


def _reaches(tap: Tap, rooted, buffers_source) -> bool:
    src = tap_source(tap, buffers_source)
    return src is None or rooted[src] is not None


def _shift_a(slot: Slot, by: int) -> Slot:
    return Slot(slot.node, slot.op, slot.column, slot.sel_a + by, slot.sel_b, slot.latch_a,
                slot.latch_b, slot.dump)


def _with_input_first(vamp: Vamp, k: int) -> Vamp:
    """Move operand-A input k to position 0, renumbering the slots' selects."""
    if k == 0:
        return vamp
    order = [k] + [j for j in range(len(vamp.a)) if j != k]
    new = {old: pos for pos, old in enumerate(order)}
    slots = tuple(Slot(s.node, s.op, s.column, new[s.sel_a], s.sel_b, s.latch_a, s.latch_b, s.dump)
                  for s in vamp.slots)
    return Vamp(vamp.index, tuple(vamp.a[j] for j in order), vamp.b, slots)


def allocate(graph: Graph, sched: Schedule, layout: Layout, verify: bool = True) -> Network:
    """Bind every op of the schedule to its VAMPs and slots, with multiplexers, buffers, ports and
    constants."""
    net = _Allocator(graph, sched, layout).run()
    if verify:       # once the allocator's tables are gone (a 4096-joint log network: 0.3 GB)
        net.verify(graph, sched)
    return net


def allocate_systolic(graph: Graph, sched: Schedule, verify: bool = True) -> Network:
    """The systolic network of an ASAP schedule (one VAMP per op, three per MM)."""
    from vampc.schedule.layout import systolic_layout
    return allocate(graph, sched, systolic_layout(graph, sched), verify)
