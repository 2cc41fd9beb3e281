"""The Mostly-Local Bus (paper section VII, Figure VII.4): operands travel on tiers of buses instead of
point-to-point wires.

The model. The VAMPs stand in a line (`Bus.position`). Tier k is made of buses of `span` VAMPs each,
laid end to end (vampc.network.model.Tier); Figure VII.4 draws tiers on both sides of the line,
and every VAMP is connected to the one bus of every tier that passes it, on either side. A transfer is legal when the destination latches the bus of a tier in the same tick the
source drives it, and both (and every other VAMP reading that write) are in front of that one bus.
Different transfers share a bus at different Cycle-Counter values of the basic cycle. The default
tiers are the paper's illustration: spans 2, 2, 4, 4, 8, 8, ... (doubling every second tier), the
second tier of each pair offset by half a span, while shorter than the line; then six tiers of one
bus over the whole line, because an MM latches two matrices (six results) in one tick and its
operands may come from anywhere.

What each VAMP holds (loaded with its program, counted by the report):

- a reader selects a tier as a multiplexer input: its slot's sel-A / sel-B field picks an input
  that is a tier (a `bus` tap) at its delay-A / delay-B tick, as any other input;
- a writer has one bus-write register per (tick, source, tier) it drives: a Cycle-Counter value
  (as wide as the VAMPs' Cycle-Counter: vampc.report.mlb.write_register_bits), what it drives (its Result, or a stage of the delay buffer behind it) and a tier.

Decisions where the paper is silent:

- Only results travel on the bus (a VAMP's Result or a stage of the buffer behind it: the buffer
  sits at its VAMP's place). Host ports and constant buffers stay wired to their readers, as the
  host's own I/O.
- Program Mode. Bus-write registers are empty until programmed, so the bus cannot carry Program
  Mode's words: operand A's input 0 keeps the point-to-point wire Program Mode passes words along
  (the program path of the point-to-point network); Data Mode never reads it over the bus's
  transfers. The report counts these wires.
- A source may drive more than one tier in a tick (two readers too far apart for one bus); a
  reader then latches the shortest of its source's buses that reaches it (the lowest tier of that
  span), so a program has one reading of each transfer and a tier select damaged into another bus
  of the same source is still reported.
- Placement along the line: the units (one VAMP, or an MM's three, which stand together) start
  in a reverse Cuthill-McKee order of their producer-consumer graph (networkx), then 200 rounds
  move each towards the mean place of its neighbours (a barycentre ordering, which approaches the
  graph's spectral ordering without an eigensolver); the order with the least total message
  length is kept. On the Puma 560 this halves the log graph's total length (15 939 to 7 748 unit
  pitches) and cuts the linear one's from 2 652 to 1 530.
- Conflicts. Ops are scheduled again, in graph order (producers first): each starts at the first tick,
  from when its operands are ready, at which every operand it latches finds a free bus of a tier
  that spans the source and the readers (the shortest tier first, keeping long buses for long
  messages). Where no tick of a whole basic cycle does, the cycle is stretched (the paper's "extra
  length into the basic cycle") and the schedule made again: the stretch is searched upwards in
  doubling steps, then halved back to the shortest that worked (a longer cycle is not always
  easier, so a shorter one may exist between two that failed). The report gives the stretch
  (interval) and the wait (latency) the bus added.

Layouts: systolic (the cycle stretched by searching, as above) and folded (one torque set at a
time: the folded list schedule with each op also waiting for its buses, so the cycle grows by what
the waits cost). A budget layout places each op on VAMPs of its own choosing and is refused with a
usage error.
"""
from __future__ import annotations

import math

from vampc.dataflow.graph import Graph
from vampc.errors import VampcError, VampcInternalError
from vampc.kinds import TapKind
from vampc.machine.ops import Timing
from vampc.memo import keep_last
from vampc.network.model import (
    Bus,
    BusWrite,
    Network,
    Operand,
    Tap,
    Tier,
    Vamp,
    tap_source,
)
from vampc.schedule.asap import Schedule, schedule_asap
from vampc.schedule.layout import Layout, systolic_layout
from vampc.textio import ascii_digits

LAYOUTS = ("systolic", "folded")   # the layouts a bus is built for


# --- tiers --------------------------------------------------------------------------------------------

def tiers_of(spans, vamps: int) -> tuple[Tier, ...]:
    """Tiers of the given spans over a line of `vamps` VAMPs; a tier of the same span as the one
    before it is offset by half a span from it (the paper's even and odd tiers), unless one bus of
    that span covers the whole line."""
    out: list[Tier] = []
    for span in spans:
        prev = out[-1] if out else None
        offset = (span // 2 if prev is not None and prev.span == span and prev.offset == 0
                  and span < vamps else 0)
        out.append(Tier(span, offset))
    return tuple(out)


FULL_LINE = 6   # the most results one op latches in a tick: two matrices, three columns each


def default_spans(vamps: int) -> list[int]:
    """2, 2, 4, 4, 8, 8, ...: doubling every second tier while shorter than the line, then six tiers
    of one bus over the whole line (an MM of two matrices latches six results at once, and they may
    come from anywhere)."""
    spans, span = [], 2
    while span < vamps:
        spans += [span, span]
        span *= 2
    return spans + [max(span, 1)] * FULL_LINE


def parse_tiers(text: str) -> list[int] | str:
    """`--tiers`: 'auto', or spans separated by commas (each at least 1); ValueError saying why not."""
    text = text.strip()
    if text == "auto":
        return "auto"
    parts = [p.strip() for p in text.split(",")]
    spans = []
    for p in parts:
        if not ascii_digits(p) or int(p) < 1:        # (ASCII: '٢' is a digit to isdigit())
            raise ValueError(f"{text!r}: a tier's span is a whole number of VAMPs, at least 1 "
                             f"(got {p!r}); give spans like 2,2,4,4,8 or 'auto'")
        if int(p) > 16_777_215:
            raise ValueError(f"{text!r}: a span of {p} VAMPs is more than a network has "
                             "(at most 16777215)")
        spans.append(int(p))
    if not spans:
        raise ValueError("no tiers given")
    if len(spans) > 64:
        raise ValueError(f"{len(spans)} tiers: at most 64 (a tier select is 6 bits)")
    return spans


# --- placement ----------------------------------------------------------------------------------------

def _unit_graph(graph: Graph, layout: Layout):
    """(how many units, the producer-consumer pairs of units) of a grouped layout."""
    units = layout.units
    compute = [nd.op.is_compute for nd in graph.nodes]
    edges = set()
    for nd in graph.compute_nodes():
        for a in nd.args:
            if compute[a] and units[a] != units[nd.id]:
                edges.add((units[a], units[nd.id]))
    return len(layout.unit_vamps), edges


def line_positions(graph: Graph, layout: Layout, rounds: int = 200) -> tuple[int, ...]:
    """Each VAMP's place on the line (see the module docstring)."""
    import networkx as nx
    import numpy as np
    count, edges = _unit_graph(graph, layout)
    sizes = np.asarray(layout.unit_vamps, dtype=np.int64)
    g = nx.Graph()
    g.add_nodes_from(range(count))
    g.add_edges_from(edges)
    rank = np.empty(count, dtype=np.float64)
    rank[list(nx.utils.reverse_cuthill_mckee_ordering(g))] = np.arange(count)
    pairs = np.array(sorted(edges), dtype=np.int64).reshape(-1, 2)
    a, b = pairs[:, 0], pairs[:, 1]
    degree = np.bincount(a, minlength=count) + np.bincount(b, minlength=count)

    def length(r):
        return float(np.abs(r[a] - r[b]).sum())

    best = (length(rank), rank)
    for _ in range(rounds if len(pairs) else 0):
        pull = np.zeros(count)
        np.add.at(pull, a, rank[b])
        np.add.at(pull, b, rank[a])
        order = np.argsort((pull + rank) / (degree + 1), kind="stable")
        rank = np.empty(count, dtype=np.float64)
        rank[order] = np.arange(count)
        if length(rank) < best[0]:
            best = (length(rank), rank)
    order = np.argsort(best[1], kind="stable")          # units along the line
    first = np.empty(count, dtype=np.int64)
    first[order] = np.concatenate(([0], np.cumsum(sizes[order])[:-1]))
    base = np.concatenate(([0], np.cumsum(sizes)[:-1]))  # each unit's first VAMP index
    position = np.empty(int(sizes.sum()), dtype=np.int64)
    for j in range(int(sizes.max(initial=1))):
        units = np.flatnonzero(sizes > j)
        position[base[units] + j] = first[units] + j
    return tuple(position.tolist())


# --- scheduling on the bus ----------------------------------------------------------------------------

class _Full(Exception):
    """No tick of a whole basic cycle had a bus for some op's operands."""


def _unmatched(wanted):
    """An op whose results cannot all have a bus at once, whatever the tick: (node, the producer
    whose result finds none, lo, hi, how many results it latches, whether any bus reaches from lo
    to hi at all), or None. `wanted`: transfers()."""
    for i, wants in wanted:
        for src, lo, hi, buses in wants:
            if not buses:
                return i, src[0], lo, hi, len(wants), False
        owner: dict = {}
        for j, (src, lo, hi, buses) in enumerate(wants):
            if not _augment(j, wants, owner, set()):
                return i, src[0], lo, hi, len(wants), True
    return None


def _augment(j: int, wants, owner: dict, seen: set) -> bool:
    """Kuhn's augmenting path: give want j a bus, moving others along if need be."""
    for bus in wants[j][3]:
        if bus in seen:
            continue
        seen.add(bus)
        if bus not in owner or _augment(owner[bus], wants, owner, seen):
            owner[bus] = j
            return True
    return False


def baseline(graph: Graph, timing: Timing, layout: str, share_passes: bool):
    """`graph` in `layout` wired point to point (vampc.schedule.layout's systolic or folded): the
    (layout, schedule) a bus network's stretch and wait are counted from."""
    from vampc.schedule.layout import folded, systolic
    if layout == "systolic":
        return systolic(graph, timing, verify=False)
    return folded(graph, timing, share_passes, verify=False)


class _Uncarried(VampcError):
    """The tiers cannot carry some transfer at any tick (the message says which)."""


class _Problem:
    """A graph to schedule on the bus in one layout: the point-to-point layout and schedule it is
    measured against, its units, and the VAMPs' places on the line."""

    def __init__(self, graph: Graph, timing: Timing, layout: str, share_passes: bool,
                 verify: bool):
        self.graph, self.timing, self.verify = graph, timing, verify
        self.layout, self.share_passes = layout, share_passes
        self.asap = schedule_asap(graph, timing, verify)
        self.base, self.base_sched = baseline(graph, timing, layout, share_passes)
        self.place = self.base.vamps_of()
        self.position = line_positions(graph, self.base)

    def run(self, tiers, progress=None):
        """(layout, schedule, plan) on `tiers`; VampcError when they cannot carry a transfer."""
        graph = self.graph
        wanted = transfers(graph, self.place, self.position, tiers)
        bad = _unmatched(wanted)
        if bad is not None:
            i, a, lo, hi, count, reached = bad
            nodes = graph.nodes
            span, longest = hi - lo + 1, max(t.span for t in tiers)
            if not reached and longest < span:
                why = f"it needs a bus spanning {span} VAMPs, the longest tier spans {longest}"
            elif not reached:
                why = (f"it needs a bus spanning {span} VAMPs (places {lo} to {hi} on the line), "
                       "and no tier has one bus in front of both: each bus covers only its own "
                       "stretch of the line")
            else:
                why = (f"it latches {count} results in one tick, and the tiers have too few buses "
                       f"reaching places {lo} to {hi} to carry them all at once")
            raise _Uncarried(f"the tiers cannot carry node {nodes[a].label}'s result to node "
                             f"{nodes[i].label}: {why} (give more or longer tiers, or --tiers "
                             "auto)")
        if self.layout == "systolic":
            return self._systolic(tiers, wanted, progress)
        return self._folded(tiers, dict(wanted))

    def _plan(self, tiers, sched, carried, spans) -> _Plan:
        return _Plan(tiers, self.position, carried, sched.interval - self.base_sched.interval,
                     sched.latency - self.base_sched.latency, spans)

    def _systolic(self, tiers, wanted, progress):
        graph, timing, asap = self.graph, self.timing, self.asap

        def attempt(period):
            try:
                return _attempt(graph, timing, asap, wanted, tiers, period)
            except _Full:
                return None

        # The smallest stretch found: up by doubling steps, then halving back. A period longer
        # than all the writes together always has a free tick for every op (each op's buses were
        # matched above), so the search ends.
        low, step = asap.interval - 1, 1
        period = asap.interval
        found = attempt(period)
        while found is None:
            low, period = period, asap.interval + step
            step *= 2
            if progress is not None:
                progress(period)
            found = attempt(period)
        high, best = period, found
        while high - low > 1:
            mid = (low + high) // 2
            if progress is not None:
                progress(mid)
            got = attempt(mid)
            if got is None:
                low = mid
            else:
                high, best = mid, got
        period, (start, finish, (carried, spans)) = high, best
        latency = max(finish[o.node] for o in graph.outputs)
        # the critical path is the graph's data path, as every layout reports it (the ASAP
        # schedule's): the rest of the latency is waiting for a bus (Schedule.waits)
        sched = Schedule(timing, tuple(start), tuple(finish), latency, asap.critical_path,
                         asap.mults, asap.adds, period)
        if self.verify:
            sched.verify(graph)
        layout = systolic_layout(graph, sched)
        if self.verify:
            layout.verify(graph)
        return layout, sched, self._plan(tiers, sched, carried, spans)

    def _folded(self, tiers, wanted):
        """The folded layout's list schedule (vampc.schedule.layout.schedule_bound: the same
        order, units and capture rule) with each op also waiting for free buses. One torque set
        at a time, so every tick of a set has its own Cycle-Counter value: a bus is taken per
        tick, and the cycle grows by the ticks the buses cost."""
        from vampc.schedule.layout import Layout, schedule_bound
        taken: dict[tuple[int, int], int] = {}
        carried: dict[tuple, list[tuple[int, int]]] = {}
        spans: list[int] = []

        def admit(i: int, t: int) -> bool:
            got = _reserve(wanted.get(i, ()), t, t, taken, carried, tiers)
            if got is None:
                return False
            for key, kb, span in got:
                spans.append(span)
                carried.setdefault(key, []).append(kb)
                taken[kb] = taken.get(kb, 0) | (1 << t)
            return True

        units, sizes = self.base.units, self.base.unit_vamps
        sched = schedule_bound(self.graph, self.timing, self.asap, units, sizes,
                               self.timing.cycle, self.verify, admit)
        layout = Layout.of_units(self.layout, units, sizes, sched.interval, self.timing.cycle,
                                 self.share_passes)
        if self.verify:
            layout.verify(self.graph)
        return layout, sched, self._plan(tiers, sched, carried, spans)


def schedule_on_bus(graph: Graph, timing: Timing, tiers_option: str | None = None,
                    verify: bool = True, layout: str = "systolic", share_passes: bool = False,
                    progress=None):
    """The `layout` (systolic or folded) and schedule of `graph` with every result transfer on a
    bus of the tiers `--tiers` gives (None: the default; 'auto': tuned): (layout, schedule, bus
    plan). VampcError when the tiers cannot carry some transfer."""
    problem = _Problem(graph, timing, layout, share_passes, verify)
    V = problem.base.vamp_count
    spans = default_spans(V) if tiers_option is None else parse_tiers(tiers_option)
    if spans == "auto":
        return _tuned(problem, progress)
    return problem.run(tiers_of(spans, V), progress)


def _tuned(problem: _Problem, progress):
    """--tiers auto: as many tiers as the default, the buses of each length roughly proportional
    to the share of messages of about that length (the paper's rule), then refined by measurement:
    the rule applied again to the messages the schedule actually sends, and the default tried
    too; the tiers with the least stretch (then wait, then total bus length) are kept."""
    V = len(problem.position)
    default = default_spans(V)
    spans = _needed_spans(problem.graph, problem.place, problem.position)
    best, tried = None, []
    for round_ in range(3):
        cand = default if round_ == 0 else _proportional(spans, len(default), V)
        if cand in tried:
            continue
        tried.append(cand)
        try:
            got = problem.run(tiers_of(cand, V), progress)
        except _Uncarried:
            continue
        plan = got[2]
        score = (plan.stretch, plan.wait, sum(t.span * t.buses(V) for t in plan.tiers))
        if best is None or score < best[0]:
            best = (score, got)
        if round_ > 0:
            spans = plan.spans          # what the schedule sent: the rule once more
    return best[1]


def _needed_spans(graph: Graph, place, position) -> list[int]:
    """The span of every transfer (source to its farthest reader of one op)."""
    return [hi - lo + 1 for _, wants in transfers(graph, place, position, ())
            for _, lo, hi, _ in wants]


def _proportional(spans, count: int, vamps: int) -> list[int]:
    """`count` tiers of power-of-two spans (2 .. the whole line) whose numbers of buses are
    proportional to the share of messages needing about that span: a message of span s is
    carried by one of a pair of offset tiers of span 2s (rounded up to a power of two), and a tier
    of span S has vamps / S buses, so the tiers of span S are proportional to share x S. Six tiers
    span the whole line (two matrices latched at once), as in the default."""
    top = 1 << max(1, math.ceil(math.log2(max(vamps, 2))))
    share: dict[int, float] = {}
    for s in spans:
        S = min(top, 1 << max(1, math.ceil(math.log2(max(2 * s - 1, 2)))))
        share[S] = share.get(S, 0) + 1
    free = count - FULL_LINE
    weight = {S: n * S for S, n in share.items() if S < top}
    total = sum(weight.values())
    tiers: dict[int, int] = {}
    if total and free > 0:
        exact = {S: free * w / total for S, w in weight.items()}
        tiers = {S: int(x) for S, x in exact.items()}
        left = free - sum(tiers.values())
        for S in sorted(exact, key=lambda S: exact[S] - tiers[S], reverse=True)[:left]:
            tiers[S] += 1
    out = []
    for S in sorted(tiers):
        out += [S] * tiers[S]
    return out + [top] * (count - len(out))


class _Plan:
    """What the scheduler decided: per (node, its VAMP, tick) the (tier, bus) pairs carrying
    that node's result from that VAMP at that tick."""

    def __init__(self, tiers, position, carried, stretch: int, wait: int, spans):
        self.tiers, self.position, self.carried = tiers, position, carried
        self.stretch, self.wait, self.spans = stretch, wait, spans


def transfers(graph: Graph, place, position, tiers) -> list:
    """Per compute node reading results, in graph order: (node, the results it latches as
    ((producer, its VAMP), lo, hi, the (tier, bus) pairs able to carry it, shortest tier first)).
    They do not depend on the cycle's length, so every attempt shares them."""
    order = sorted(range(len(tiers)), key=lambda k: (tiers[k].span, k))
    compute = [nd.op.is_compute for nd in graph.nodes]
    reach: dict[tuple[int, int], list] = {}     # (lo, hi) -> carrying buses
    out = []
    for nd in graph.compute_nodes():
        srcs = [a for a in dict.fromkeys(nd.args) if compute[a]]
        if not srcs:
            continue                    # reads only inputs and constants: as the ASAP schedule
        readers = [position[v] for v in place[nd.id]]
        r_lo, r_hi = min(readers), max(readers)
        wants = []
        for a in srcs:
            for u in place[a]:
                p = position[u]
                lo, hi = min(p, r_lo), max(p, r_hi)
                buses = reach.get((lo, hi))
                if buses is None:
                    buses = reach[(lo, hi)] = [(k, tiers[k].bus_at(lo)) for k in order
                                               if tiers[k].carries(lo, hi)]
                wants.append(((a, u), lo, hi, buses))
        out.append((nd.id, wants))
    return out


def _attempt(graph: Graph, timing: Timing, asap: Schedule, wanted, tiers, period: int):
    """One list schedule at `period` (see the module docstring) of the ops `wanted` (transfers());
    _Full when an op finds no tick. A bus's taken counters are the bits of an int, so the ticks
    worth trying for an op are those at which each of its transfers has some free bus."""
    nodes = graph.nodes
    duration = timing.durations
    start, finish = list(asap.start), list(asap.finish)
    full = (1 << period) - 1
    taken: dict[tuple[int, int], int] = {}                       # (tier, bus) -> counters in use
    carried: dict[tuple, list[tuple[int, int]]] = {}   # (node, vamp, tick) -> (tier, bus)
    sent: dict[tuple, list] = {}                       # (node, vamp) -> (tick, (tier, bus))
    spans: list[int] = []                                        # of each write, when made
    for i, wants in wanted:
        nd = nodes[i]
        ready = 0
        for a in nd.args:
            if finish[a] > ready:
                ready = finish[a]
        free = full
        for src, lo, hi, buses in wants:
            some = 0
            for kb in buses:
                some |= full & ~taken.get(kb, 0)
            for t0, (k, b) in sent.get(src, ()):   # or share a write of the same result
                if tiers[k].covers(b, lo, hi):
                    some |= 1 << (t0 % period)
            free &= some
            if not free:
                break
        # try the free counters in tick order from `ready`, once round the cycle
        r = ready % period
        rotated = ((free >> r) | (free << (period - r))) & full
        while rotated:
            low = rotated & -rotated
            d = low.bit_length() - 1
            rotated ^= low
            t = ready + d
            got = _reserve(wants, t, t % period, taken, carried, tiers)
            if got is not None:
                bit = 1 << (t % period)
                for key, kb, span in got:
                    spans.append(span)
                    carried.setdefault(key, []).append(kb)
                    sent.setdefault(key[:2], []).append((t, kb))
                    taken[kb] = taken.get(kb, 0) | bit
                start[i], finish[i] = t, t + duration[nd.op]
                break
        else:
            raise _Full()
    return start, finish, (carried, spans)


def _reserve(wants, t: int, counter: int, taken, carried, tiers):
    """The new (key, (tier, bus)) writes that carry every want at tick t, or None if one finds no
    free bus (nothing is reserved then)."""
    bit = 1 << counter
    new: list = []
    mine: set = set()
    for src, lo, hi, buses in wants:
        key = (*src, t)          # node a's result on VAMP u at tick t: one tap shows it
        if any(tiers[k].covers(b, lo, hi)
               for k, b in [*carried.get(key, ()), *(kb for kk, kb, _ in new if kk == key)]):
            continue                   # the source already drives a bus in front of all of them
        for kb in buses:
            if taken.get(kb, 0) & bit or kb in mine:
                continue
            new.append((key, kb, hi - lo + 1))
            mine.add(kb)
            break
        else:
            return None
    return new


# --- the network on the bus ---------------------------------------------------------------------------

def with_bus(net: Network, plan: _Plan, graph: Graph, verify: bool = False) -> Network:
    """The allocated point-to-point network (of `graph`) with every result operand read from a bus
    tier: the bus taps, and the bus-write registers of the writers. `verify`: the bus network
    resolved back to wires must read what the network it was made from reads."""
    from dataclasses import replace
    sources = [b.source for b in net.buffers]
    P = net.period
    writes: dict[tuple[Tap, int, int], None] = {}
    vamps = []
    for v in net.vamps:
        ins = {"a": list(v.a), "b": list(v.b)}
        slots = []
        for s in v.slots:
            sel = {}
            args = graph.nodes[s.node].args
            for name, tick, arg in (("a", s.latch_a, args[0]), ("b", s.latch_b, args[1])):
                operand = ins[name][getattr(s, "sel_" + name)]
                if all(t.kind in (TapKind.PORT, TapKind.CONST) for t in operand.taps):
                    sel[name] = getattr(s, "sel_" + name)
                    continue
                taps = []
                for tap in operand.taps:
                    u = tap_source(tap, sources)
                    lo = min(plan.position[u], plan.position[v.index])
                    hi = max(plan.position[u], plan.position[v.index])
                    k = min((k for k, b in plan.carried.get((arg, u, tick), ())
                             if plan.tiers[k].covers(b, lo, hi)),
                            key=lambda k: (plan.tiers[k].span, k), default=None)
                    if k is None:
                        raise VampcInternalError(f"VAMP {v.index}: no bus carries VAMP {u}'s "
                                                 f"result at tick {tick}")
                    writes[(tap, tick % P, k)] = None
                    taps.append(Tap(TapKind.BUS, k))
                bus_operand = Operand(tuple(taps))
                if bus_operand not in ins[name]:
                    ins[name].append(bus_operand)
                sel[name] = ins[name].index(bus_operand)
            slots.append(replace_slot(s, sel["a"], sel["b"]))
        vamps.append(_drop_unused(Vamp(v.index, tuple(ins["a"]), tuple(ins["b"]), tuple(slots))))
    bus = Bus(plan.tiers, plan.position,
              tuple(BusWrite(tap, c, k) for tap, c, k in writes), plan.stretch, plan.wait)
    out = replace(net, vamps=tuple(vamps), bus=bus)
    if verify:
        wired = resolved(out)
        for v, w in zip(net.vamps, wired.vamps):
            for s, t in zip(v.slots, w.slots):
                if (v.a[s.sel_a], v.b[s.sel_b]) != (w.a[t.sel_a], w.b[t.sel_b]):
                    raise VampcInternalError(f"VAMP {v.index}: over the bus it reads "
                                             f"{w.a[t.sel_a]}, {w.b[t.sel_b]} instead of "
                                             f"{v.a[s.sel_a]}, {v.b[s.sel_b]}")
    return out


@keep_last(2)
def wired(net: Network) -> Network:
    """The point-to-point network a bus network implements (the network itself without a bus): what
    the report's wiring figures and pictures count as logical connections."""
    return net if net.bus is None else resolved(net)


def resolved(net: Network, path: str = "<network>") -> Network:
    """The network with each bus tap replaced by the source driving that bus when the slot latches
    it: the point-to-point network the bus implements (multiplexer inputs deduplicated, selects
    renumbered). VampcError naming the VAMP, slot, tier and counter where a bus has no writer or
    two."""
    from dataclasses import replace
    bus = net.bus
    if bus is None:
        return net
    sources = [b.source for b in net.buffers]
    drivers = bus.drivers(sources, net.period)
    vamps = []
    for v in net.vamps:
        ins = {"a": [], "b": []}
        slots = []
        if v.a and not any(t.kind is TapKind.BUS for t in v.a[0].taps):
            ins["a"].append(v.a[0])          # the Program-Mode wire stays input 0
        for k, s in enumerate(v.slots):
            sel = {}
            for name in ("a", "b"):
                operand = (v.a if name == "a" else v.b)[getattr(s, "sel_" + name)]
                counter = getattr(s, "latch_" + name, None)
                counter = getattr(s, "delay_" + name) if counter is None else counter
                taps = []
                for tap in operand.taps:
                    if tap.kind is not TapKind.BUS:
                        taps.append(tap)
                        continue
                    w, why = bus_source(bus, drivers, v.index, tap.index, counter, net.period)
                    if w is None:
                        raise VampcError(f"{path}: VAMP {v.index} slot {k}: operand "
                                         f"{name.upper()} reads tier {tap.index}'s bus: {why}")
                    taps.append(w.source)
                op = Operand(tuple(taps))
                if op not in ins[name]:
                    ins[name].append(op)
                sel[name] = ins[name].index(op)
            slots.append(replace_slot(s, sel["a"], sel["b"]))
        vamps.append(Vamp(v.index, tuple(ins["a"]), tuple(ins["b"]), tuple(slots)))
    return replace(net, vamps=tuple(vamps), bus=None)


def replace_slot(s, sel_a: int, sel_b: int):
    """A slot with other multiplexer selects."""
    import msgspec
    return msgspec.structs.replace(s, sel_a=sel_a, sel_b=sel_b)


def _drop_unused(v: Vamp) -> Vamp:
    """The VAMP without the multiplexer inputs no slot selects any more (the results now come over
    the bus), except operand A's input 0: the wire Program Mode passes words along."""
    keep = {}
    for name, inputs in (("a", v.a), ("b", v.b)):
        used = {getattr(s, "sel_" + name) for s in v.slots} | ({0} if name == "a" else set())
        kept = [k for k in range(len(inputs)) if k in used]
        keep[name] = (tuple(inputs[k] for k in kept), {k: j for j, k in enumerate(kept)})
    slots = tuple(replace_slot(s, keep["a"][1][s.sel_a], keep["b"][1][s.sel_b]) for s in v.slots)
    return Vamp(v.index, keep["a"][0], keep["b"][0], slots)


def bus_source(bus: Bus, drivers, reader: int, tier: int, counter: int, period: int):
    """The write on the bus of `tier` in front of VAMP `reader` at `counter`: its BusWrite, or a
    message saying why there is none (no writer, or two)."""
    t = bus.tiers[tier] if 0 <= tier < len(bus.tiers) else None
    if t is None:
        return None, f"tier {tier} does not exist ({len(bus.tiers)} tiers)"
    b = t.bus_at(bus.position[reader])
    found = drivers.get((tier, b, counter % period), [])
    if len(found) == 1:
        return found[0], None
    if not found:
        return None, f"no VAMP drives bus {b} of tier {tier} at Cycle-Counter {counter}"
    return None, (f"{len(found)} writers drive bus {b} of tier {tier} at Cycle-Counter {counter} "
                  f"({', '.join(str(w.source) for w in found)})")


def latched(net: Network) -> dict[tuple[int, int, int], list[int]]:
    """Per (tier, bus, Cycle-Counter): the VAMPs latching that bus then (scheduled slots' latch
    ticks, or a loaded network's delays)."""
    bus = net.bus
    out: dict[tuple[int, int, int], list[int]] = {}
    for v in net.vamps:
        here = bus.position[v.index]
        for s in v.slots:
            for name in ("a", "b"):
                counter = getattr(s, "latch_" + name, None)
                counter = getattr(s, "delay_" + name) if counter is None else counter
                for tap in (v.a if name == "a" else v.b)[getattr(s, "sel_" + name)].taps:
                    if tap.kind is TapKind.BUS:
                        key = (tap.index, bus.tiers[tap.index].bus_at(here), counter % net.period)
                        out.setdefault(key, []).append(v.index)
    return out


def message_spans(net: Network) -> list[int]:
    """The span (VAMPs from the writer to the farthest reader, both counted) of every bus write."""
    bus = net.bus
    sources = [b.source for b in net.buffers]
    drivers = bus.drivers(sources, net.period)
    out = []
    for key, readers in latched(net).items():
        p = bus.writer_position(drivers[key][0].source, sources)
        out.append(max(abs(p - bus.position[r]) for r in readers) + 1)
    return out
