"""Systolic allocation: one VAMP per op (three per MM), buffers, ports and constants (DESIGN §6).

Each VAMP latches both operands at its op's scheduled start and dumps at its finish. A consumer reading a
VAMP's result L >= 1 cycles after it is dumped taps stage L of a delay buffer behind that VAMP (one
buffer chain per producer, shared by all its late consumers). Host inputs get one port per (quantity,
cycle in which it is read), so the host writes each value when it is needed and no input is buffered.
Constants are deduplicated by value: two constant buffers never hold the same value.
"""
from __future__ import annotations

from vampc.dataflow.graph import Graph, InputKey
from vampc.dataflow.ops import VAMPS_PER_OP, Op
from vampc.errors import VampcInternalError
from vampc.network.model import (Buffer, Const, Network, Operand, OutputPoint, Port, Tap, Vamp,
                                 window)
from vampc.schedule.asap import Schedule


class _Allocator:
    def __init__(self, graph: Graph, sched: Schedule, verify: bool):
        self.verify = verify
        self.g, self.s, self.C = graph, sched, sched.interval
        self.vamps_of: dict[int, list[int]] = {}
        self.stages: dict[int, int] = {}          # producer VAMP -> buffer stages needed
        self.buffer_of: dict[int, int] = {}       # producer VAMP -> buffer index (in order of first use)
        self.ports: dict[tuple[InputKey, int], int] = {}
        self.consts: dict[tuple[float, ...], Const] = {}
        self.vamps: list[Vamp] = []

    def run(self) -> Network:
        first = 0
        for nd in self.g.compute_nodes():
            count = VAMPS_PER_OP[nd.op]
            self.vamps_of[nd.id] = list(range(first, first + count))
            first += count
        for nd in self.g.compute_nodes():
            for col, idx in enumerate(self.vamps_of[nd.id]):
                self.vamps.append(self._vamp(nd, idx, col if nd.op is Op.MM else None))
        return self._network()

    def _vamp(self, nd, idx: int, column) -> Vamp:
        t = self.s.start[nd.id]
        a, b = (self._operand(arg, t) for arg in nd.args)
        return Vamp(idx, nd.id, nd.op, column, a, b, t, t, self.s.finish[nd.id] - 1)

    def _operand(self, arg: int, t: int) -> Operand:
        src = self.g.nodes[arg]
        if src.op is Op.CONST:
            return Operand((self._const(src),))
        if src.op is Op.INPUT:
            key = (src.key, t // self.C)
            self.ports.setdefault(key, len(self.ports))
            return Operand((Tap("port", self.ports[key]),))
        return Operand(tuple(self._vamp_tap(v, self.s.finish[arg], t) for v in self.vamps_of[arg]))

    def _vamp_tap(self, vamp: int, emit: int, t: int) -> Tap:
        if emit <= t < emit + self.C:
            return Tap("vamp", vamp)
        stage = t // self.C - emit // self.C
        if stage < 1:
            raise VampcInternalError(f"VAMP {vamp}: read at tick {t} before its result at {emit}")
        self.stages[vamp] = max(self.stages.get(vamp, 0), stage)
        buf = self.buffer_of.setdefault(vamp, len(self.buffer_of))
        return Tap("buffer", buf, stage)

    def _const(self, nd) -> Tap:
        if nd.value not in self.consts:
            self.consts[nd.value] = Const(len(self.consts), nd.name, nd.value)
        return Tap("const", self.consts[nd.value].index)

    def _network(self) -> Network:
        buffers = tuple(Buffer(i, v, self.stages[v]) for v, i in self.buffer_of.items())
        vamps = tuple(self.vamps)
        ports = tuple(Port(i, key, cyc, 9 if key.quantity == "A" else 3)
                      for (key, cyc), i in sorted(self.ports.items(), key=lambda kv: kv[1]))
        outputs = tuple(OutputPoint(o.joint, self.vamps_of[o.node][0], o.component,
                                    self.s.finish[o.node]) for o in self.g.outputs)
        net = Network(self.C, vamps, buffers, ports, tuple(self.consts.values()), outputs)
        if self.verify:
            verify_network(net)
        return net


def allocate_systolic(graph: Graph, sched: Schedule, verify: bool = True) -> Network:
    """Bind every op of the systolic schedule to a numbered VAMP, with buffers, ports and constants."""
    return _Allocator(graph, sched, verify).run()


def tap_window(net: Network, tap: Tap) -> tuple[float, float]:
    """[first, last+1) ticks during which `tap` shows set 0's value (constants: always)."""
    port_cycle = net.ports[tap.index].cycle if tap.kind == "port" else 0
    src = tap.index if tap.kind == "vamp" else (
        net.buffers[tap.index].source if tap.kind == "buffer" else None)
    return window(tap, net.cycle, net.vamps[src].emit if src is not None else 0, port_cycle)


def verify_network(net: Network) -> None:
    """Every tap shows the right set at its latch tick; every micro-sequence fits between latch and the
    next latch; buffers are long enough. Raise VampcInternalError naming VAMP, tick and operand."""
    for v in net.vamps:
        for name, operand, latch in (("A", v.a, v.latch_a), ("B", v.b, v.latch_b)):
            for tap in operand.taps:
                if tap.kind == "buffer" and not 1 <= tap.stage <= net.buffers[tap.index].stages:
                    raise VampcInternalError(f"VAMP {v.index}: operand {name} taps missing {tap}")
                lo, hi = tap_window(net, tap)
                if not lo <= latch < hi:
                    raise VampcInternalError(
                        f"VAMP {v.index}: operand {name} latched at tick {latch} outside {tap}'s "
                        f"window [{lo}, {hi})")
            if not latch <= v.dump < latch + net.cycle:
                raise VampcInternalError(f"VAMP {v.index}: operand {name} re-latched before dump")
