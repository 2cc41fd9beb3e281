"""ASAP scheduling and the critical path of a dataflow graph (README, *Timing model*).

Every INPUT and CONST is available at flop 0; a compute node starts when its last operand is ready and
takes Timing.duration(op) flops. One exception: an op that reads only inputs and constants (e.g. T11 of
node 1, A_1ᵀ p̈_0) has nothing to wait for, so it starts as late as its first consumer allows; that never
moves the critical path and spares the delay buffer its result would otherwise wait in. The latency is the finish of the last torque output: the lower bound
for that graph. The critical path is reported as "x Mults + y Addns" in the paper's accounting.
"""
from __future__ import annotations

from dataclasses import dataclass

from vampc.dataflow.graph import Graph
from vampc.errors import VampcInternalError
from vampc.machine.ops import Timing


@dataclass(frozen=True)
class Schedule:
    """Start and finish flop of every node (indexed by node id), the critical-path summary and the
    interval (flops between successive torque sets: the cycle C for the systolic pipeline, the
    layout's period otherwise). `critical_path` is the graph's data path (the longest chain of
    operands, as the ASAP schedule finds it, for every layout) and `mults` + `adds` count it in the
    paper's accounting; a layout that makes ops wait for their VAMP adds `latency` -
    (mults·Mult + adds·Addn) flops of waiting (`waits`), so the two always add up to the latency."""

    timing: Timing
    start: tuple[int, ...]
    finish: tuple[int, ...]
    latency: int
    critical_path: tuple[int, ...]
    mults: int
    adds: int
    interval: int = 0

    def __post_init__(self):
        if not self.interval:
            object.__setattr__(self, "interval", self.timing.cycle)

    @property
    def waits(self) -> int:
        """Flops on the critical path spent waiting for a VAMP (0 for an ASAP schedule)."""
        return self.latency - self.timing.flops(self.mults, self.adds)

    def verify(self, graph: Graph) -> None:
        """Every node starts after its operands finish and lasts its op's duration."""
        duration = self.timing.durations
        start, finish = self.start, self.finish
        for nd in graph.nodes:
            i = nd.id
            if finish[i] - start[i] != duration[nd.op]:
                raise VampcInternalError(f"node {nd.label}: duration mismatch")
            args = nd.args
            if len(args) == 2 and finish[args[0]] <= start[i] and finish[args[1]] <= start[i]:
                continue            # (a compute node: its two operands, in line)
            for a in args:
                if finish[a] > start[i]:
                    raise VampcInternalError(f"node {nd.label} starts before operand {a} ends")
        if self.latency != max(self.finish[o.node] for o in graph.outputs):
            raise VampcInternalError("latency is not the last output's finish")


_CACHE: dict = {}


def schedule_asap(graph: Graph, timing: Timing = Timing(), verify: bool = True) -> Schedule:
    """As-soon-as-possible schedule of `graph` under `timing` (checked unless `verify` is off). The
    last few answers are kept (graphs are frozen; a report asks for each recursion's schedule once
    per layout it compares, a few seconds each for a 4 096-joint log graph)."""
    key = (id(graph), timing.mult, timing.add)
    hit = _CACHE.get(key)
    if hit is not None and hit[0] is graph:
        if verify and not hit[2]:
            hit[1].verify(graph)
            _CACHE[key] = (graph, hit[1], True)
        return hit[1]
    sched = _schedule_asap(graph, timing, verify)
    if len(_CACHE) >= 4:
        _CACHE.pop(next(iter(_CACHE)))
    _CACHE[key] = (graph, sched, verify)
    return sched


def _schedule_asap(graph: Graph, timing: Timing, verify: bool) -> Schedule:
    start, finish = [], []
    duration = timing.durations
    for nd in graph.nodes:
        args = nd.args
        s = 0
        if len(args) == 2:       # (a compute node's two operands in line: a million nodes)
            if finish[args[0]] > s:
                s = finish[args[0]]
            if finish[args[1]] > s:
                s = finish[args[1]]
        else:
            for a in args:
                if finish[a] > s:
                    s = finish[a]
        start.append(s)
        finish.append(s + duration[nd.op])
    last = max(graph.outputs, key=lambda o: (finish[o.node], o.joint))
    path, mults, adds = critical_path_counts(graph, timing, finish, last.node)  # ASAP times:
    _delay_source_ops(graph, timing, start, finish)                     # delays below never bind
    sched = Schedule(timing, tuple(start), tuple(finish), finish[last.node], tuple(path), mults, adds)
    if verify:
        sched.verify(graph)
    return sched


def _delay_source_ops(graph: Graph, timing: Timing, start: list[int], finish: list[int]) -> None:
    """Move ops whose operands are all inputs/constants to just before their first consumer (no
    source op reads another, so consumers' starts do not move meanwhile)."""
    nodes = graph.nodes
    compute = [nd.op.is_compute for nd in nodes]
    is_compute = compute.__getitem__
    source = [c and not any(map(is_compute, nd.args)) for c, nd in zip(compute, nodes)]
    latest: dict[int, int] = {}
    for nd, t in zip(nodes, start):
        for a in nd.args:
            if source[a] and latest.get(a, t) >= t:
                latest[a] = t
    for i, t in latest.items():
        finish[i] = max(finish[i], t)
        start[i] = finish[i] - timing.duration(nodes[i].op)


def critical_path_counts(graph: Graph, timing: Timing, finish, end: int):
    """The critical path ending at node `end` and its (Mults, Addns) in the paper's accounting."""
    path = _critical_path(graph, finish, end)
    mults = sum(timing.path_counts(graph.nodes[i].op)[0] for i in path)
    adds = sum(timing.path_counts(graph.nodes[i].op)[1] for i in path)
    return path, mults, adds


def _critical_path(graph: Graph, finish, end: int) -> list[int]:
    """Walk back from `end` through the operand that finished last (the binding dependency)."""
    path = [end]
    node = graph.nodes[end]
    while node.args:
        node = graph.nodes[max(node.args, key=lambda a: (finish[a], -a))]
        if not node.op.is_compute:
            break
        path.append(node.id)
    return path[::-1]
