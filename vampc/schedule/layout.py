"""Layouts: which VAMPs run which ops, and how often a new torque set enters (README, *Layouts*).

A layout binds every compute node of the graph to a *unit* — one VAMP, or three for an MM — and fixes
the period P (ticks between successive torque sets) and the buffer clock B. Every VAMP of a unit runs
one slot per node bound to the unit.

systolic   one unit per op, P = B = C (the basic cycle, 4 flops): a new torque set every C ticks
           (Figures III.1, VI.3). The ASAP schedule is kept as it is.
folded     the paper's single device (Figure VI.1a): one recursion node's VAMPs (linear) or one
           tier's (log) run every joint or tier in turn. Ops are bound by role: in the linear graph
           op T4 of every backward node runs on one unit, and so on for each name; in the log graph
           the combining node at position p of its tier runs on device node p (leaves and the
           non-propagated variables are dealt round the device nodes), again one unit per op name.
           The forward pass has its own device unless `share_passes` (Figure VI.1b) puts its ops on
           the backward device's units, which are idle by then. The schedule is a list schedule
           under that binding (below); one torque set at a time: P is the span of one set, rounded
           up to a multiple of B = C.

The list schedule (`schedule_bound`) takes the compute nodes most urgent first (by the latest start
that keeps the ASAP latency: a topological order, and an op with slack never takes a unit from one on
the critical path) and starts each at the earliest tick that (1) follows its operands,
(2) is no earlier than its ASAP start (an op that reads only inputs and constants starts as late as its
consumers allow, as in the systolic schedule, so no result waits long), (3) leaves its unit free: no two
ops of one unit overlap, and (4) lets the buffer capture the unit's previous result: a unit's next dump
shows no earlier than the end of the block in which its previous result appeared (so every later
reader finds that result on the Result or in a buffer stage). The latency is then the ASAP latency
plus whatever (3) and (4) cost; the report shows both.
"""
from __future__ import annotations

import collections
import functools
import itertools
import math
import operator
from dataclasses import dataclass

from vampc import jsontext
from vampc.dataflow.graph import Graph
from vampc.errors import VampcError, VampcInternalError
from vampc.kinds import Recursion, Section, unhandled
from vampc.machine.ops import VAMPS_PER_OP, Timing
from vampc.machine.timing import next_capture
from vampc.memo import counting, keep_last
from vampc.schedule.asap import Schedule, schedule_asap


@dataclass(frozen=True)
class Layout:
    """Where every compute node runs, and the period and buffer clock: one shape for every layout.
    `placement` gives, per graph node, the VAMPs that run it (three for an MM, in column order; empty
    for inputs and constants). In a `grouped` layout (systolic, folded) the VAMPs form fixed units —
    one VAMP, or three for an MM — numbered unit by unit, and a node runs on all of its unit's; a
    budgeted layout places each node on VAMPs of its own choosing, VAMPs an MM shares with other
    ops included."""

    name: str
    placement: tuple[tuple[int, ...], ...]
    period: int
    clock: int
    share_passes: bool = False
    grouped: bool = True
    proof: str = ""               # what an exact solver proved about a budgeted layout

    @staticmethod
    def of_units(name: str, units, sizes, period: int, clock: int,
                 share_passes: bool = False) -> "Layout":
        """A grouped layout from a unit per node (-1 for inputs and constants) and each unit's size;
        VAMPs are numbered unit by unit."""
        vamps, first = [], 0          # per unit, its VAMPs (one tuple, shared by its nodes)
        ints = counting(sum(sizes))   # (the VAMP indices as the network's ints: vampc.memo)
        for size in sizes:
            vamps.append(ints[first:first + size])
            first += size
        placement = tuple(vamps[u] if u >= 0 else () for u in units)
        layout = Layout(name, placement, period, clock, share_passes)
        if len(set(units) - {-1}) == len(sizes):   # every unit runs a node: what _units and
            units = tuple(units)                    # vamp_count would work out from placement
            layout.__dict__["_units"] = (units, tuple(sizes))
            layout.__dict__["vamp_count"] = first
        return layout

    def vamps_of(self) -> tuple[tuple[int, ...], ...]:
        """Per graph node: the VAMPs that run it (empty for inputs and constants)."""
        return self.placement

    @functools.cached_property
    def vamp_count(self) -> int:
        """VAMPs in the network (kept: a big layout's reports ask often)."""
        return 1 + max((v for p in self.placement for v in p), default=-1)

    @property
    def units(self) -> tuple[int, ...]:
        """A grouped layout's unit per node (-1 for inputs and constants), units in VAMP order."""
        return self._units[0]

    @property
    def unit_vamps(self) -> tuple[int, ...]:
        """A grouped layout's VAMPs per unit (3 for an MM group)."""
        return self._units[1]

    @functools.cached_property
    def _units(self):
        firsts = sorted({p[0]: len(p) for p in self.placement if p}.items())
        index = {first: u for u, (first, _) in enumerate(firsts)}
        return (tuple(index[p[0]] if p else -1 for p in self.placement),
                tuple(size for _, size in firsts))

    def verify(self, graph: Graph) -> None:
        """Compute nodes are placed on as many distinct VAMPs as their op takes, inputs and
        constants on none; in a grouped layout, nodes sharing a VAMP share all its unit's; the
        period is a multiple of the clock."""
        if self.clock < 1 or self.period % self.clock:
            raise VampcInternalError(f"layout: period {self.period} is not a multiple of the "
                                     f"buffer clock {self.clock}")
        if len(self.placement) != len(graph.nodes):
            raise VampcInternalError("layout: one placement per graph node expected")
        wants = {op: VAMPS_PER_OP[op] if op.is_compute else 0 for op in {nd.op for nd in graph.nodes}}
        for nd, where in zip(graph.nodes, self.placement):
            want = wants[nd.op]
            if len(where) != want or (where[0] < 0 if want == 1 else want and (
                    min(where) < 0 or len(set(where)) < want)):
                raise VampcInternalError(f"node {nd.label}: placed on {where}")
        if self.grouped:        # units: two placements share a VAMP only if they are the same
            units = dict.fromkeys(self.placement)     # (in the placement's order: read fast)
            units.pop((), None)
            if sum(map(len, units)) != len(set(itertools.chain.from_iterable(units))):
                raise VampcInternalError("layout: a VAMP belongs to two units")


def layout_and_schedule(graph: Graph, timing: Timing, name: str = "systolic",
                        request=None) -> tuple[Layout, Schedule]:
    """The layout `name` (vampc.schedule.registry) of `graph` and the schedule it runs, as
    `request` (a LayoutRequest: shared passes, a VAMP budget or interval and its exact solver,
    verification) asks; a budget or an interval makes the layout "budget"."""
    from vampc.schedule.registry import BUDGET, LayoutRequest, layout_kind
    request = request if request is not None else LayoutRequest()
    budget = request.vamps is not None or request.interval is not None
    try:
        kind = BUDGET if budget else layout_kind(name)
    except ValueError as exc:
        raise VampcError(str(exc)) from None
    if request.share_passes and not kind.shares_passes:
        raise VampcError(f"--share-passes does not apply to the {kind.name} layout")
    return kind.build(graph, timing, request)


def systolic(graph: Graph, timing: Timing, verify: bool = True) -> tuple[Layout, Schedule]:
    """The systolic layout: the ASAP schedule, one unit per op."""
    asap = schedule_asap(graph, timing, verify)
    layout = systolic_layout(graph, asap)
    if verify:
        layout.verify(graph)
    return layout, asap


def folded(graph: Graph, timing: Timing, share_passes: bool = False,
           verify: bool = True) -> tuple[Layout, Schedule]:
    """The folded layout (the paper's single device), the forward pass on the backward pass's units
    with `share_passes`."""
    asap = schedule_asap(graph, timing, verify)
    units, sizes = folded_binding(graph, share_passes)
    sched = schedule_bound(graph, timing, asap, units, sizes, clock=timing.cycle, verify=verify)
    layout = Layout.of_units("folded", units, sizes, sched.interval, timing.cycle, share_passes)
    if verify:
        layout.verify(graph)
    return layout, sched


def systolic_layout(graph: Graph, sched: Schedule) -> Layout:
    """One unit per compute node, in graph order; P = B = the schedule's interval."""
    units, sizes = [-1] * len(graph.nodes), []
    ints = counting(len(graph.nodes))
    for nd in graph.compute_nodes():
        units[nd.id] = ints[len(sizes)]
        sizes.append(VAMPS_PER_OP[nd.op])
    return Layout.of_units("systolic", units, sizes, sched.interval, sched.interval)


# --- binding by role -----------------------------------------------------------------------------

def folded_binding(graph: Graph, share_passes: bool) -> tuple[tuple[int, ...], tuple[int, ...]]:
    """Units by role: (device, device node, op name), numbered in order of their first node. The
    forward pass's roles go onto the backward device's units of the same size when `share_passes`,
    in order (MM groups onto MM groups); a forward role that finds no free unit of its size gets a
    new one. (With numpy: a 4 096-joint log graph has a million nodes.)"""
    import numpy as np
    ids, code, size, fwd = _role_codes(graph)
    units = np.full(len(graph.nodes), -1, dtype=np.int64)
    own = ~fwd if share_passes else np.ones(len(ids), dtype=bool)
    unit_of, firsts = _first_appearance(code[own])
    units[ids[own]] = unit_of
    sizes = size[own][firsts].tolist()
    if share_passes and fwd.any():
        role_of, firsts = _first_appearance(code[fwd])        # the forward roles, in order
        free = {k: collections.deque(u for u, s in enumerate(sizes) if s == k) for k in (1, 3)}
        taken = []
        for k in size[fwd][firsts].tolist():
            if free[k]:
                taken.append(free[k].popleft())
            else:
                taken.append(len(sizes))
                sizes.append(k)
        units[ids[fwd]] = np.asarray(taken, dtype=np.int64)[role_of]
    return tuple(units.tolist()), tuple(sizes)


def _first_appearance(codes):
    """(per entry, the rank of its value in order of first appearance; the index of each value's
    first entry, in that order)."""
    import numpy as np
    order = np.argsort(codes, kind="stable")
    ordered = codes[order]
    start = np.ones(len(codes), dtype=bool)
    start[1:] = ordered[1:] != ordered[:-1]
    first = order[start]                   # (stable: the smallest index of each value)
    rank = np.empty(len(first), dtype=np.int64)
    rank[np.argsort(first)] = np.arange(len(first))
    out = np.empty(len(codes), dtype=np.int64)
    out[order] = rank[np.cumsum(start) - 1]
    return out, np.sort(first)


_SECTION_CODES = {Section.BWD: 0, Section.NPV: 1, Section.FWD: 2}


@keep_last()
def _role_codes(graph: Graph):
    """Per compute node (arrays, in graph order): its id, its role (device, device node, op name,
    VAMPs) as one integer, its VAMPs and whether it is a forward node (kept: the folded and
    shared-pass bindings of one graph both ask)."""
    import numpy as np
    nodes = graph.compute_nodes()
    count = len(nodes)

    def column(name: str, table=None):
        values = map(operator.attrgetter(name), nodes)
        return np.fromiter(values if table is None else map(table.__getitem__, values),
                           dtype=np.int64, count=count)
    ids, group = column("id"), column("group")
    section = column("section", _SECTION_CODES)
    size = column("op", VAMPS_PER_OP)
    names = {name: k for k, name in enumerate(dict.fromkeys(nd.name for nd in nodes))}
    name = column("name", names)
    pos = np.zeros(count, dtype=np.int64)
    places = _device_places(graph)
    if places is not None:
        place, npv_width = places
        npv = section == _SECTION_CODES[Section.NPV]
        pos[npv] = (group[npv] - 1) % npv_width
        for sec, code in _SECTION_CODES.items():
            mine = (section == code) & ~npv
            if not mine.any():
                continue
            table = np.full(int(group[mine].max()) + 1, -1, dtype=np.int64)
            for (s, g), p in place.items():
                if s == sec and 0 <= g < len(table):
                    table[g] = p
            pos[mine] = table[group[mine]]
            if (pos[mine] < 0).any():
                bad = nodes[int(np.flatnonzero(mine)[np.argmax(pos[mine] < 0)])]
                raise VampcInternalError(f"node {bad.label}: its recursion node has no place on "
                                         "the device")
    width = int(pos.max(initial=0)) + 1
    code = ((section * width + pos) * max(len(names), 1) + name) * 4 + size
    return ids, code, size, section == _SECTION_CODES[Section.FWD]


def device_nodes(graph: Graph):
    """node -> (device, position on the device): linear "bwd"/"npv"/"fwd" at position 0; log: the
    position of its recursion node in its tier, leaves and non-propagated groups dealt round."""
    places = _device_places(graph)
    if places is None:
        return lambda nd: (nd.section, 0)
    place, npv_width = places
    return lambda nd: ((nd.section, (nd.group - 1) % npv_width) if nd.section is Section.NPV
                       else (nd.section, place[(nd.section, nd.group)]))


def _device_places(graph: Graph):
    """None for the linear graph (every node at position 0 of its device); for the log graph, the
    place of each (section, recursion node) on its device and the non-propagated device's width."""
    match graph.recursion:
        case Recursion.LINEAR:
            return None
        case Recursion.LOG:
            pass
        case other:
            unhandled(other)
    meta = dict(graph.meta)
    place = {}
    for section in (Section.BWD, Section.FWD):
        rows = jsontext.loads(meta[f"{section}_nodes"])
        combining = [r for r in rows if r[4] > 0]
        width = max((sum(1 for r in combining if r[4] == t) for t in {r[4] for r in combining}),
                    default=1)
        tiers = max((r[4] for r in rows), default=0)
        seen: dict[int, int] = {}
        leaf = 0
        for group, _a, _k, _b, tier in rows:
            if tier == 0:
                place[(section, group)] = leaf % width
                leaf += 1
            else:
                place[(section, group)] = seen.get(tier, 0)
                seen[tier] = seen.get(tier, 0) + 1
        if section == Section.BWD:
            npv_width = max(1, math.ceil(graph.n / max(tiers, 1)))
    return place, npv_width


# --- the list schedule ---------------------------------------------------------------------------

def schedule_bound(graph: Graph, timing: Timing, asap: Schedule, units, sizes, clock: int,
                   verify: bool = True, admit=None) -> Schedule:
    """List-schedule `graph` with every compute node on its unit (see the module docstring); one
    torque set at a time: the period is the span of a set rounded up to a multiple of `clock`.
    `admit(node, t)`: whether an op may start at a tick its unit has free, reserving whatever else
    it needs there when it says yes (the Mostly-Local Bus's buses, vampc.network.bus); the op
    tries its unit's next free tick otherwise."""
    duration = timing.durations
    nodes = graph.nodes
    height, arrays = _heights(graph, duration)
    placed = (admit is None and arrays is not None
              and _native_schedule(arrays, height, asap, units, sizes, clock))
    if placed:
        start, finish, order = placed
    else:
        # urgent first: by the latest start that keeps the ASAP latency (a topological order), so
        # an op with slack never takes a unit from one on the critical path
        order = sorted((nd.id for nd in nodes if nd.op.is_compute),
                       key=lambda i: (-height[i] - duration[nodes[i].op], asap.start[i], i))
        start = list(asap.start)
        finish = list(asap.finish)
        busy = [_Timeline(clock) for _ in sizes]
        is_compute = [nd.op.is_compute for nd in nodes]
        for i in order:
            nd = nodes[i]
            ready = asap.start[i]
            for a in nd.args:          # (a loop, not max() of a list: this runs once per op)
                if is_compute[a] and finish[a] > ready:
                    ready = finish[a]
            t = busy[units[i]].earliest(ready, duration[nd.op])
            while admit is not None and not admit(i, t):
                t = busy[units[i]].earliest(t + 1, duration[nd.op])
            start[i], finish[i] = t, t + duration[nd.op]
            busy[units[i]].add(t, finish[i])
    latency = max(finish[o.node] for o in graph.outputs)
    span = max(finish[i] for i in order) + 1      # ops no torque reads may finish after the last
    period = -(-span // clock) * clock
    # the critical path is the data path (the graph's, as ASAP finds it): what the paper's formula
    # counts; the rest of the latency is waiting for a busy VAMP (Schedule.waits)
    sched = Schedule(timing, tuple(start), tuple(finish), latency, asap.critical_path, asap.mults,
                     asap.adds, period)
    if verify:
        sched.verify(graph)
        _verify_units(graph, sched, units, clock)
    return sched


class _Timeline:
    """A unit's busy ticks and the blocks its dumps show in. The capture rule (a dump shows no
    earlier than the block after the previous dump's) says exactly that no two dumps of a unit show in
    one block, so an op fits at t when [t, t + length) is free and the block of t + length holds no
    dump; both are a byte per tick or block, searched at C speed (a folded VAMP of an n-joint robot
    holds n ops, and walking them for every op was quadratic)."""

    def __init__(self, clock: int):
        self.clock = clock
        self.busy = bytearray()      # per tick: 1 = an op runs
        self.shown = bytearray()     # per block: 1 = a dump shows in it

    def earliest(self, ready: int, length: int) -> int:
        """The first start t >= ready at which the op fits (see the class docstring)."""
        B, t = self.clock, ready
        while True:
            t = _find_free(self.busy, t, length)
            block = (t + length) // B
            free_block = _find_free(self.shown, block, 1)
            if free_block == block:
                return t
            t = max(t, free_block * B - length)

    def add(self, start: int, finish: int) -> None:
        """Mark [start, finish) busy and the block `finish` (its dump shows then) taken."""
        busy, shown = self.busy, self.shown
        if len(busy) < finish:                       # grown in line: this runs once per op
            busy.extend(bytes(finish - len(busy)))
        busy[start:finish] = b"\x01" * (finish - start)
        block = finish // self.clock
        if len(shown) <= block:
            shown.extend(bytes(block + 1 - len(shown)))
        shown[block] = 1


_ZEROS = [bytes(k) for k in range(64)]


def _find_free(buf: bytearray, start: int, length: int) -> int:
    """The first index >= start of `length` zero bytes (beyond the end everything is zero)."""
    if len(buf) < start + length:                    # grown in line: millions of calls
        buf.extend(bytes(start + length - len(buf)))
    at = buf.find(_ZEROS[length] if length < 64 else bytes(length), start)
    if at >= 0:
        return at
    last = buf.rfind(1, start)
    return start if last < 0 else last + 1


@keep_last()
def _heights(graph: Graph, duration) -> tuple[list[int], object]:
    """Longest path (ticks) from each node to the end of any output (the list priority), and the
    graph's arrays when it is big enough to be list-scheduled in C (vampc.schedule.native; else
    None); the last answer is kept (a report's folded and shared-pass layouts list-schedule the
    same graph; `duration` is a Timing's table, one object per Timing)."""
    from vampc.schedule import native
    height = arrays = None
    if native.wanted(len(graph.compute_nodes())):
        arrays = native.Arrays(graph, duration)
        height = native.longest_to_end(graph, duration, arrays)
        if height is None:            # no C compiler here: the Python loops
            arrays = None
    if height is None:
        height = _longest_to_end(graph, duration)
    return height, arrays


def _native_schedule(arrays, height, asap: Schedule, units, sizes, clock: int):
    """schedule_bound's order and loop in C: (start, finish, order), or None without the library.
    The order is the Python loop's: by (-height - duration, ASAP start, node id)."""
    import numpy as np

    from vampc.schedule import native
    ids = np.flatnonzero(arrays.is_compute)
    urgency = -(np.asarray(height, dtype=np.int64)[ids] + arrays.dur[ids])
    order = ids[np.lexsort((ids, np.asarray(asap.start, dtype=np.int64)[ids], urgency))]
    placed = native.list_schedule(arrays, order, asap, units, len(sizes), clock)
    if placed is None:
        return None
    return placed[0], placed[1], order.tolist()


def _longest_to_end(graph: Graph, duration) -> list[int]:
    height = [0] * len(graph.nodes)
    for nd in reversed(graph.nodes):
        d = duration[nd.op]
        for a in nd.args:
            height[a] = max(height[a], height[nd.id] + d)
    return height


def _verify_units(graph: Graph, sched: Schedule, units, clock: int) -> None:
    """No two ops of a unit overlap, and each unit's dumps leave the buffer time to capture."""
    per: dict[int, list[tuple[int, int, int]]] = {}
    for nd in graph.compute_nodes():
        per.setdefault(units[nd.id], []).append((sched.start[nd.id], sched.finish[nd.id], nd.id))
    for unit, spans in per.items():
        spans.sort()
        for (s0, f0, a), (s1, f1, b) in zip(spans, spans[1:]):
            if s1 < f0 or f1 < next_capture(f0, clock):
                raise VampcInternalError(f"unit {unit}: nodes {graph.nodes[a].label} and "
                                         f"{graph.nodes[b].label} collide")
        if spans[-1][1] - spans[0][0] > sched.interval:
            raise VampcInternalError(f"unit {unit}: busy longer than the period")
