"""A VAMP budget (not in the paper): schedule the graph onto the network a user can afford.

`--vamps K` places every op on at most K VAMPs (an MM on three at once, as in the systolic layout) and
pipelines successive torque sets at the smallest interval II it can reach — never below ⌈W/K⌉, W the
graph's work in VAMP-ticks — with the shortest latency it finds at that interval. `--interval T`
fixes the rate and looks for the fewest VAMPs.

The scheduler is an iterative modulo list scheduler (Rau's scheme without backtracking): every VAMP
has a reservation table of II ticks; the compute nodes are taken most urgent first (by the latest start
that keeps the ASAP latency, a topological order) and each starts at the first tick, from the time its
operands are ready (and no earlier than its ASAP start: an op that reads only inputs starts as late as
its consumers allow), at which some VAMP (three for an MM) is free for its whole duration modulo II; of the VAMPs free
there it takes those it fits most tightly (busy on both sides of it, then on one: best fit, so the
free ticks stay in runs long enough for the ops still to come — at an interval of ⌈W/K⌉ every tick
is needed), and with `pack` an op waits a few ticks, within its window, for a gap it fills exactly.
An op that finds no such tick within II ticks of its ready time never will: the interval is then
infeasible and the next one is tried. `modulo_schedule` is the one function an exact solver would
replace.

Buffers are clocked every tick (B = 1) while scheduling, so a result can always be buffered the tick
it appears; afterwards the largest buffer clock dividing II under which every buffered result is still
captured is chosen (fewer, longer stages). Every budgeted result is reported beside certified lower
bounds (`bounds`): II ≥ ⌈W/K⌉; latency ≥ the critical path, ≥ ⌈W/K⌉, and the level bound
max over q of (q + ⌈work of the ops whose longest path to the outputs exceeds q, divided by K⌉).
"""
from __future__ import annotations

import heapq
import math
from dataclasses import dataclass

from vampc import progress
from vampc.dataflow.graph import Graph
from vampc.errors import VampcError, VampcInternalError
from vampc.machine.ops import VAMPS_PER_OP, Timing
from vampc.machine.timing import next_capture, result_windows
from vampc.schedule.asap import Schedule, schedule_asap
from vampc.textio import count


@dataclass(frozen=True)
class Bounds:
    """Certified lower bounds for a graph on K VAMPs."""

    work: int            # W: VAMP-ticks of one torque set
    vamps: int
    interval: int        # ⌈W/K⌉
    critical_path: int
    level: int           # the level bound (includes the critical path and ⌈W/K⌉)
    longest: int         # the longest op's duration (no interval is shorter)

    @property
    def interval_bound(self) -> int:
        """The interval bound reported and searched from: max(⌈W/K⌉, the longest op)."""
        return max(self.interval, self.longest)

    @property
    def latency(self) -> int:
        """The best latency bound (the level bound at q = 0 is ⌈work of the ops the torques need / K⌉;
        ⌈W/K⌉ itself is not one: ops no torque reads may finish after the last torque)."""
        return max(self.critical_path, self.level)


def work(graph: Graph, timing: Timing) -> int:
    """W: the VAMP-ticks one torque set takes (an MM holds three VAMPs)."""
    d = timing.durations
    return sum(d[nd.op] * VAMPS_PER_OP[nd.op] for nd in graph.compute_nodes())


def vamp_ops(graph: Graph) -> int:
    """VAMP-ops of one torque set (an MM counts three): the VAMPs of the systolic layout."""
    return sum(VAMPS_PER_OP[nd.op] for nd in graph.compute_nodes())


def tails(graph: Graph, timing: Timing) -> list[int | None]:
    """Per node: the longest path, in ticks, from its start to the end of an output (its own
    duration included); None for a node no output depends on."""
    d = timing.durations
    tail: list[int | None] = [None] * len(graph.nodes)
    for o in graph.outputs:
        tail[o.node] = 0
    for nd in reversed(graph.nodes):
        if tail[nd.id] is None:
            continue
        tail[nd.id] += d[nd.op]
        for a in nd.args:
            tail[a] = max(tail[a] or 0, tail[nd.id])
    return tail


def bounds(graph: Graph, timing: Timing, k: int) -> Bounds:
    """The lower bounds for `graph` on `k` VAMPs (see the module docstring). The level bound: an op
    with tail τ (its longest path to the end of an output, its own duration d included) must start by
    L - τ, so by L - q it has done at least min(d, τ - q) of its work; all of that fits in K VAMPs
    over L - q ticks: L >= q + ⌈Σ m·min(d, τ - q)⁺ / K⌉ for every q (m = 3 for an MM). It counts the
    whole work of every op whose path after it exceeds q, as the issue asks, and more."""
    d = timing.durations
    tail = tails(graph, timing)
    live = [(tail[nd.id], d[nd.op], VAMPS_PER_OP[nd.op]) for nd in graph.compute_nodes()
            if tail[nd.id] is not None]
    w = work(graph, timing)
    cp = max((t for t, _, _ in live), default=0)
    level = 0
    for q in range(cp + 1):
        must = sum(m * min(dur, t - q) for t, dur, m in live if t > q)
        level = max(level, q + -(-must // k))
    return Bounds(w, k, -(-w // k), cp, level, max((d[nd.op] for nd in graph.compute_nodes()),
                                                   default=0))


def smallest_network(graph: Graph) -> int:
    """The fewest VAMPs any schedule needs: the most any one op takes (3 for an MM), else 1."""
    return max((VAMPS_PER_OP[nd.op] for nd in graph.compute_nodes()), default=1)


@dataclass(frozen=True)
class Placed:
    """A modulo schedule: start per node, the VAMPs each compute node runs on, the interval."""

    start: tuple[int, ...]
    finish: tuple[int, ...]
    placement: tuple[tuple[int, ...], ...]
    interval: int


@dataclass(frozen=True)
class Attempt:
    """How one placement attempt orders and places the ops (modulo_schedule): `effort` placements
    per op, `scan`, `seed`, `swing`, `pack` and `big` as its docstring says. A portfolio is a tuple
    of them (ATTEMPTS)."""

    effort: int = 4
    scan: bool = False
    seed: int = 0
    swing: bool = False
    pack: int = 0
    big: bool = False


def modulo_schedule(graph: Graph, timing: Timing, k: int, ii: int,
                    asap: Schedule | None = None, latency: int | None = None,
                    attempt: Attempt = Attempt()) -> Placed | None:
    """Place every op on `k` VAMPs with successive torque sets every `ii` ticks — every torque set
    within `latency` ticks if given — or None if this scheduler finds no placement within `effort`
    placements per op (see the module docstring). `scan`: when an op must evict, it evicts at the
    tick of its window where the fewest ops are, not at its first tick. `seed` > 0 perturbs the
    priorities by up to 2 ticks (a portfolio of orders tries its luck where the plain one fails).
    `swing` (with `latency`): the ops least free to move first — by their slack between the ASAP
    start and the latest start the latency allows, the critical path first — each placed between
    its placed operands and its placed consumers (as swing modulo scheduling does), so the ops that
    fix the latency get their ticks before the others fill the rest. `pack` > 0: an op may wait up
    to that many ticks (within its window) for a gap it fills exactly. `big`: the ops taking the most
    VAMP-ticks first (bin packing's rule; the order above breaks ties), which packs nearly full
    networks the urgency order cannot."""
    effort, scan, seed, swing, pack, big = (attempt.effort, attempt.scan, attempt.seed,
                                            attempt.swing, attempt.pack, attempt.big)
    # (the bar of a 256-joint log chain's --vamps 2000 said "schedule" alone for minutes: a new
    # user's find; each attempt says what it tries, as --exact's solver does)
    said = f"{count(k, 'VAMP')}, interval {ii}" + (f", latency ≤ {latency}" if latency is not None else "")
    progress.note(said)
    d = timing.durations
    asap = asap or schedule_asap(graph, timing, verify=False)
    nodes = graph.nodes
    if max((d[nd.op] for nd in graph.compute_nodes()), default=0) > ii:
        return None
    tail = tails(graph, timing)
    jitter = _jitter(len(nodes), seed)
    order = sorted((nd.id for nd in nodes if nd.op.is_compute),
                   key=lambda i: (-(tail[i] if tail[i] is not None else -1) + jitter[i],
                                  asap.start[i], i))
    deadline = None
    if latency is not None:      # the latest start that lets the torques be out by then
        deadline = {i: latency - tail[i] for i in order if tail[i] is not None}
        if swing:
            order.sort(key=lambda i: (deadline.get(i, latency) - asap.start[i], asap.start[i], i))
    if big:              # the longest ops first (bin packing's rule), then as above
        rank = {i: r for r, i in enumerate(order)}
        order.sort(key=lambda i: (-d[nodes[i].op] * VAMPS_PER_OP[nodes[i].op], rank[i]))
    return _Modulo(graph, d, k, ii, asap, deadline, scan, swing, pack).run(order, effort, said)


def _jitter(count: int, seed: int) -> list[float]:
    if not seed:
        return [0.0] * count
    import random
    rng = random.Random(seed)
    return [rng.uniform(-2.0, 2.0) for _ in range(count)]


SCAN = 16      # ticks an evicting op looks ahead for the fewest ops to displace
NOTE_EVERY = 1 << 15   # steps between the notes of one attempt's progress (about 0.5 s)


class _Modulo:
    """Iterative modulo scheduling (after Rau): ops are placed most urgent first at the earliest tick
    a VAMP is free for them modulo the interval; an op that finds none within one interval is placed
    anyway, evicting what occupies that VAMP, and the evicted ops (and any successor the move put
    too early) go back in the queue. A budget of steps (ops taken from the queue, a placed one
    skipped too) bounds the work."""

    def __init__(self, graph: Graph, d, k: int, ii: int, asap: Schedule, deadline=None,
                 scan: bool = False, swing: bool = False, pack: int = 0):
        self.g, self.d, self.k, self.ii, self.asap = graph, d, k, ii, asap
        self.pack = pack
        self.deadline = deadline or {}
        self.swing = swing
        self.scan = scan      # evict where the fewest ops are (else at the first tick, as Rau)
        self.free = [(1 << k) - 1] * ii          # per tick of the period: bit v set = VAMP v free
        self.occupant: list[dict[int, int]] = [{} for _ in range(ii)]
        self.start: dict[int, int] = {}
        self.placement: dict[int, tuple[int, ...]] = {}
        self.consumers = graph.consumers()
        # per (duration, VAMPs needed) of the graph's ops: bit t set when that many VAMPs are free
        # for that many ticks from tick t (so the first fit is a bit search, not a scan)
        self.shapes = sorted({(d[nd.op], VAMPS_PER_OP[nd.op]) for nd in graph.compute_nodes()})
        self.longest = max(dur for dur, _ in self.shapes)
        self.avail = {shape: bytearray([shape[1] <= k]) * ii for shape in self.shapes}
        # the same tables as _refresh walks them: (duration - 1, VAMPs needed, table)
        self.tables = [(dur - 1, need, self.avail[(dur, need)]) for dur, need in self.shapes]

    def run(self, order: list[int], effort: int, said: str = "") -> Placed | None:
        import heapq
        rank = {i: r for r, i in enumerate(order)}
        queue = [(rank[i], i) for i in order]
        heapq.heapify(queue)
        last: dict[int, int] = {}
        steps = budget = effort * len(order)     # steps: ops taken from the queue
        made = 0                                 # placements (evictions put some back)
        while queue:
            if steps == 0:
                return None
            if said and (budget - steps) % NOTE_EVERY == 0 and steps != budget:
                # (one attempt on a 256-joint log chain's 2000 VAMPs ran 40 s under one unmoving
                # note: a new user's find; how far it is, said)
                # (its budget counts steps, ops taken from the queue, one already placed too: the
                # note had called them placements; the steps taken so far, this one not yet)
                progress.note(f"{said}: {len(self.start):,} of {len(order):,} ops placed; "
                              f"{made:,} placements, {budget - steps:,} of at most {budget:,} steps")
            steps -= 1
            _, i = heapq.heappop(queue)
            if i in self.start:
                continue
            made += 1
            try:
                for evicted in self._place(i, last):
                    heapq.heappush(queue, (rank[evicted], evicted))
            except _Late:
                return None
        return self._placed()

    def _place(self, i: int, last: dict[int, int]) -> list[int]:
        nodes, d = self.g.nodes, self.d
        nd = nodes[i]
        need, dur = VAMPS_PER_OP[nd.op], d[nd.op]
        ready = max([self.start[a] + d[nodes[a].op] for a in nd.args if a in self.start]
                    + [self.asap.start[i]])
        end = min(ready + self.ii - 1, self.deadline.get(i, ready + self.ii - 1))
        if end < ready:
            raise _Late(i)
        evicted = []
        if self.swing:        # also before the consumers already placed
            placed = [self.start[c] for c in self.consumers[i] if c in self.start]
            if placed and min(placed) - dur >= ready:
                end = min(end, min(placed) - dur)
        got = self._fit(ready, dur, need, end - ready + 1)
        if got is None:       # no room in time: take VAMPs from others
            first = ready if i not in last or ready > last[i] else last[i] + 1
            if first > end:
                first = ready
            ticks = range(first, min(end, first + SCAN) + 1) if self.scan else (first,)
            best = None
            for tick in ticks:
                c = self._conflicts(tick, dur, need)
                if best is None or c < best:
                    best = c
                    if c[0] <= 1:
                        # no later tick evicts fewer: none evicts no op, since _fit found no
                        # start in [ready, end] with `need` VAMPs free throughout (and a tie goes
                        # to the earlier tick, as min() over ticks in order gives)
                        break
            t, vamps = best[1:]
            evicted = sorted({self.occupant[tick % self.ii][v] for tick in range(t, t + dur)
                              for v in vamps if v in self.occupant[tick % self.ii]})
            for e in evicted:
                self._remove(e)
            got = (t, vamps)
        t, vamps = got
        self._reserve(i, t, vamps)
        last[i] = t
        late = [c for c in self.consumers[i] if c in self.start and self.start[c] < t + dur]
        for c in late:
            self._remove(c)
        return evicted + late

    def _conflicts(self, t: int, dur: int, need: int):
        """(ops to evict, t, VAMPs): `need` VAMPs for ticks t .. t + dur - 1 — those free for all of
        them first, then those holding an op at tick t: with deadlines the op with the most slack
        first, else the lowest numbers (cheap: a network of thousands of VAMPs evicts often)."""
        ii = self.ii
        mask = self._free_for(t, dur)
        vamps = []
        while mask and len(vamps) < need:
            low = mask & -mask
            vamps.append(low.bit_length() - 1)
            mask ^= low
        busy = self.occupant[t % ii]
        short = need - len(vamps)
        if short > 0:         # the first `short` of the busy VAMPs in order, not yet taken
            if self.deadline:     # with deadlines: displace the ops with the most slack first
                inf, deadline, start = float("inf"), self.deadline.get, self.start.get
                keys = [(start(op, 0) - deadline(op, inf), v) for v, op in busy.items()
                        if v not in vamps]
                vamps.extend(v for _, v in heapq.nsmallest(short, keys))
            else:     # the lowest-numbered: the clear bits of `free` at tick t are busy's keys
                taken = ~self.free[t % ii] & ((1 << self.k) - 1)   # (and none of vamps: free)
                while taken and short:
                    low = taken & -taken
                    vamps.append(low.bit_length() - 1)
                    taken ^= low
                    short -= 1
        for v in range(self.k):          # only when fewer than `need` VAMPs are busy at tick t
            if len(vamps) == need:
                break
            if v not in vamps:
                vamps.append(v)
        ops = {self.occupant[tick % ii].get(v) for tick in range(t, t + dur) for v in vamps}
        return len(ops - {None}), t, tuple(sorted(vamps))   # an MM's columns go in VAMP order

    def _fit(self, ready: int, dur: int, need: int, window: int):
        """(start, VAMPs): the first start from `ready`, within `window` ticks (at most one
        interval), at which `need` VAMPs are free for `dur` ticks; None if there is none."""
        ii = self.ii
        avail, r = self.avail[(dur, need)], ready % ii
        at = avail.find(1, r, min(ii, r + window))
        if at >= 0:
            t = ready + at - r
        else:
            at = avail.find(1, 0, r + window - ii) if r + window > ii else -1
            if at < 0:
                return None
            t = ready + ii - r + at
        mask = self._free_for(t, dur)
        if self.pack and dur < ii:         # wait up to `pack` ticks for a gap it fills exactly
            for later in range(t, min(t + self.pack, ready + window - 1) + 1):
                m = self._free_for(later, dur)
                if (m & ~self.free[(later - 1) % ii] & ~self.free[(later + dur) % ii]
                        ).bit_count() >= need:
                    t, mask = later, m
                    break
        return t, self._tightest(mask, t, dur, need)

    def _free_for(self, t: int, dur: int) -> int:
        """The VAMPs (bit v for VAMP v) free for all of ticks t .. t + dur - 1, round the period."""
        ii, free = self.ii, self.free
        mask = free[t % ii]
        for tick in range(t + 1, t + dur):
            mask &= free[tick % ii]
        return mask

    def _tightest(self, mask: int, t: int, dur: int, need: int) -> tuple[int, ...]:
        """`need` of the VAMPs in `mask` (free for ticks t .. t + dur - 1), those the op fits most
        tightly first: busy on both sides of the span, then on one side, then any (best fit: the
        free ticks left over stay in long runs, so a later long op still finds room; at an interval
        of ⌈W/K⌉ the VAMPs must be packed without a gap). Lowest numbers first within a tier."""
        ii = self.ii
        if dur >= ii:
            tiers = (mask,)
        else:
            left, right = ~self.free[(t - 1) % ii], ~self.free[(t + dur) % ii]
            tiers = (mask & left & right, mask & (left | right), mask)
        vamps: list[int] = []
        for tier in tiers:
            tier &= mask
            while tier and len(vamps) < need:
                low = tier & -tier
                vamps.append(low.bit_length() - 1)
                tier ^= low
                mask ^= low
            if len(vamps) == need:
                break
        return tuple(sorted(vamps))

    def _refresh(self, t: int, dur: int) -> None:
        """Recompute the availability bits of every start whose span meets ticks t .. t + dur - 1."""
        ii, free, longest, tables = self.ii, self.free, self.longest, self.tables
        # (each start of the period once: at a short interval the range went round it, a start's
        # bits recomputed up to three times, the same each time)
        for start in range(t + dur - min(longest + dur - 1, ii), t + dur):
            s0 = start % ii
            # the VAMPs free for 1, 2, ... ticks from `start` (_free_for of each length, built up)
            mask = free[s0]
            spans = [mask]
            for tick in range(start + 1, start + longest):
                mask &= free[tick % ii]
                spans.append(mask)
            for last, need, table in tables:
                table[s0] = spans[last].bit_count() >= need if need > 1 else spans[last] != 0

    def _reserve(self, i: int, t: int, vamps: tuple[int, ...]) -> None:
        dur = self.d[self.g.nodes[i].op]
        for tick in range(t, t + dur):
            slot = tick % self.ii
            for v in vamps:
                self.free[slot] &= ~(1 << v)
                self.occupant[slot][v] = i
        self._refresh(t, dur)
        self.start[i], self.placement[i] = t, vamps

    def _remove(self, i: int) -> None:
        t, vamps = self.start.pop(i), self.placement.pop(i)
        dur = self.d[self.g.nodes[i].op]
        for tick in range(t, t + dur):
            slot = tick % self.ii
            for v in vamps:
                self.free[slot] |= 1 << v
                del self.occupant[slot][v]
        self._refresh(t, dur)

    def _placed(self) -> Placed:
        start, finish = list(self.asap.start), list(self.asap.finish)
        placement: list[tuple[int, ...]] = [()] * len(self.g.nodes)
        for i, t in self.start.items():
            start[i], finish[i] = t, t + self.d[self.g.nodes[i].op]
            placement[i] = self.placement[i]
        return Placed(tuple(start), tuple(finish), tuple(placement), self.ii)


class _Late(Exception):
    """An op whose operands are ready after its deadline: this latency cannot be met."""


def budget_schedule(graph: Graph, timing: Timing, k: int | None = None,
                    interval: int | None = None, verify: bool = True, thorough: bool = True,
                    exact: bool = False):
    """(Layout, Schedule, Bounds) for a budget: `k` VAMPs at the smallest interval this scheduler
    reaches, or the fewest VAMPs that reach `interval`, or both (K VAMPs at that interval). One line
    saying what is feasible when the request is not. `thorough`: search the portfolio for a shorter
    latency (vampc compile); without it, the cheap pass of _quick_for (sweeps of big graphs).
    `exact`: OR-Tools CP-SAT instead of the heuristic (vampc.schedule.exact; K must be given)."""
    asap = schedule_asap(graph, timing, verify=False)
    smallest = smallest_network(graph)
    longest = max(timing.durations[nd.op] for nd in graph.compute_nodes())
    if k is not None and k < smallest:
        raise VampcError(f"--vamps {k}: the smallest network that runs this graph has {smallest} "
                         "VAMPs (an MM takes three)" if smallest == 3 else
                         f"--vamps {k}: at least one VAMP is needed")
    if interval is not None and interval < longest:
        raise VampcError(f"--interval {interval}: the smallest interval any network reaches is "
                         f"{longest} flops (the longest op)")
    asked_k, asked = k, interval
    k, interval = usable(graph, timing, k, interval, longest)
    proof = ""
    if exact:
        if k is None:
            raise VampcError("--exact needs --vamps K (it proves the best interval and latency for "
                             "K VAMPs)")
        from vampc.schedule.exact import exact_budget
        b = bounds(graph, timing, k)
        # the list scheduler first: where it reaches both bounds (the interval asked, or the
        # interval bound), nothing is shorter, and the solver is not run (it had searched 496 s to
        # find what the list scheduler gives in a second: a new user's find)
        # (an --interval below the bound goes straight to the solver's refusal, at once: the list
        # scheduler had run first, 38 s on a 64-joint log graph: a review's find)
        heuristic = _for_vamps(graph, timing, k, asap, thorough) \
            if interval is None or interval >= b.interval_bound else None
        if heuristic is not None and interval is not None:   # (as without --exact)
            heuristic = _within(graph, modulo_schedule(graph, timing, k, interval, asap), heuristic,
                                interval)
        if heuristic is not None and heuristic.interval <= (interval or b.interval_bound) and \
                _latency(graph, heuristic) == b.latency:
            placed = heuristic
            proof = ("interval proven optimal, latency proven optimal (at their bounds, which the "
                     if interval is None else "latency proven optimal (at its bound, which the ") + \
                "list scheduler reached: the solver was not run)"
        else:
            e = exact_budget(graph, timing, k, interval=interval)
            placed = e.placed
            # a latency at its bound is optimal, whether the solver's search finished or not (it
            # said "interval proven optimal" alone beside a latency gap of 0.0%: a new user's find)
            at_bound = _latency(graph, placed) == b.latency
            proof = ", ".join(p for p, ok in (("interval proven optimal", e.interval_optimal),
                                              ("latency proven optimal",
                                               e.latency_optimal or at_bound)) if ok) \
                or "not proven optimal (the solver's time limit)"
    elif k is None:
        k, placed = _fewest_vamps(graph, timing, interval, asap, smallest)
        # on those K VAMPs, what --vamps K reaches where its interval is within T and its latency
        # shorter than the placement's at exactly T (the intervals between are not tried)
        best = _for_vamps(graph, timing, k, asap, thorough)
        if best.interval <= asked and (_latency(graph, best), best.interval) < (
                _latency(graph, placed), placed.interval):
            placed = best
        # fewer VAMPs: the search one attempt at a time missed some that --vamps K's portfolio
        # reaches the interval with (--interval 18 took 19 VAMPs where --vamps 18 reaches 18)
        # Not every budget reaches what a smaller one does (with latencies 3 and 2, planar2's 21
        # VAMPs reach interval 13 and 23 do not: --interval 13 took 24, a new user's find), so
        # the search goes on past a budget that misses, to MISSES in a row
        floor = _vamps_floor(graph, timing, interval, smallest)
        tried, missed = k - 1, 0
        while thorough and tried >= floor and missed < MISSES:
            fewer = _for_vamps(graph, timing, tried, asap, thorough)
            if fewer.interval > interval:
                missed += 1
            else:
                k, placed, missed = tried, fewer, 0
            tried -= 1
    elif interval is None:
        placed = _for_vamps(graph, timing, k, asap, thorough)
    else:
        placed = modulo_schedule(graph, timing, k, interval, asap)
        # what --vamps K alone reaches (an unheld search can say more): taken where its interval
        # is within T and its latency shorter (one attempt at T had given --vamps 7 --interval 48
        # a latency of 100 where --vamps 7 alone reaches 48 and 66), or where T failed
        best = _for_vamps(graph, timing, k, asap, thorough)
        if placed is None and best.interval > interval:
            # fewer VAMPs, within K: a smaller budget may reach T where K does not (planar2 at
            # latencies 3 and 2: --vamps 23 --interval 13 was refused, where 21 reach 13: a new
            # user's find)
            floor = _vamps_floor(graph, timing, interval, smallest)
            for fewer in range(k - 1, max(floor, k - FEWER_TRIED) - 1, -1):
                at = _for_vamps(graph, timing, fewer, asap, thorough)
                if at.interval <= interval:
                    placed = best = at
                    break
        if placed is None and best.interval > interval:
            # the interval it does reach from T up, tried one at a time (it had named --vamps K's
            # own interval, 37 where --vamps 3 --interval 36 works: a new user's find), and the
            # bound no schedule beats, where T is below it
            found = next((t for t in range(interval + 1, min(best.interval, interval + 64))
                          if modulo_schedule(graph, timing, k, t, asap) is not None), best.interval)
            floor = bounds(graph, timing, k).interval_bound
            below = (f": below ⌈W/K⌉ = {floor} flops, the least any schedule on {count(k, 'VAMP')} "
                     "reaches" if interval < floor else "")
            raise VampcError(f"--vamps {asked_k} --interval {asked}: this scheduler places no "
                             f"torque set every {interval} flops on {count(k, 'VAMP')}{below}; the smallest "
                             f"interval from there it reaches is {found} flops")
        placed = _within(graph, placed, best, interval)    # a set at least every T flops
    return _finish(graph, timing, placed, k, verify, proof, asap)


def _within(graph, at: Placed | None, best: Placed, interval: int) -> Placed | None:
    """What --vamps K --interval T takes of `at` (a placement at exactly T, or None) and `best`
    (what --vamps K reaches): `best` where its interval is T or less and its latency shorter, or as
    short at a smaller interval; else `at`."""
    if best.interval <= interval and (at is None or (_latency(graph, best), best.interval)
                                      < (_latency(graph, at), at.interval)):
        return best
    return at


def usable(graph: Graph, timing: Timing, k: int | None, interval: int | None, longest: int):
    """(K, T) capped at what the graph can use: no placement uses more VAMPs than the graph has
    VAMP-ops (vamp_ops), and at an interval of W (the work) or more the smallest network already
    runs every op of a set before the next set starts, so a longer interval needs no fewer VAMPs
    and is served by one of max(W, the longest op). So a huge --vamps or --interval costs what the
    graph needs, not what was asked (each VAMP and each tick of the period is a bit of the
    scheduler's reservation tables). `longest`: the longest op's duration."""
    if k is not None:
        k = min(k, vamp_ops(graph))
    if interval is not None:
        interval = min(interval, max(work(graph, timing), longest))
    return k, interval


def _for_vamps(graph, timing, k, asap, thorough: bool) -> Placed:
    return _best_for(graph, timing, k, asap) if thorough else _quick_for(graph, timing, k, asap)


TOLERANCE = 0.05       # intervals up to 5% above the bound may be taken for a shorter latency
LATENCY_SLACK = 0.10   # a placement is first held to 10% above the latency bound


def _targets(graph, timing, k):
    """(bounds, interval bound, largest interval within TOLERANCE of it, latency held to)."""
    b = bounds(graph, timing, k)
    floor = b.interval_bound
    return b, floor, max(floor, int(floor * (1 + TOLERANCE))), int(b.latency * (1 + LATENCY_SLACK))


def _best_for(graph, timing, k, asap) -> Placed:
    """K VAMPs: the interval and latency of the module docstring, searched in two steps.

    1. **Held.** From the interval bound up to TOLERANCE above it, the first interval at which some
       attempt of the portfolio (ATTEMPTS) places every op with the torques out within
       LATENCY_SLACK of the latency bound; each is tried at the bound itself at once, and the
       best of them are then held to ever shorter latencies (halving).
    2. **Otherwise** the smallest interval the list scheduler reaches unheld, and among that and the
       intervals up to TOLERANCE above the bound, the placement with the shortest latency (the
       critical path placed first at the bound — swing order — then the portfolio held to ever
       shorter latencies).

    Held placements reach intervals unheld ones do not: with a deadline an op that must evict
    displaces the op with the most slack, and an op with slack waits for a gap it fills exactly
    (`pack`) rather than cut a long one."""
    b, floor, limit, target = _targets(graph, timing, k)
    for ii in _intervals(floor, limit):
        held = []
        for n, attempt in enumerate(ATTEMPTS):
            placed = modulo_schedule(graph, timing, k, ii, asap, latency=target, attempt=attempt)
            if placed is None:
                continue
            if _latency(graph, placed) > b.latency:    # the bound itself, at once
                placed = modulo_schedule(graph, timing, k, ii, asap, latency=b.latency,
                                         attempt=attempt) or placed
            held.append((_latency(graph, placed), ii, n, placed))
            if held[-1][0] <= b.latency:     # none does better (and a failing attempt can
                break                         # take a minute on a big graph)
        if held:
            held.sort(key=lambda x: x[:3])       # (each failed at the bound already)
            return _refine(graph, timing, k, asap, b.latency, held[0][3], held, at_bound=False)
    first = _smallest_interval(graph, timing, k, asap, floor)
    limit = max(first.interval, limit)
    step = max(1, (limit - first.interval) // 3)
    tops = []                 # (latency, interval, attempt, placement) of every first placement
    for ii in range(first.interval, limit + 1, step):
        for n, attempt in enumerate(ATTEMPTS):
            top = first if (ii, n) == (first.interval, 0) else \
                modulo_schedule(graph, timing, k, ii, asap, attempt=attempt)
            if top is not None:
                tops.append((_latency(graph, top), ii, n, top))
    tops.sort(key=lambda x: x[:3])
    best = tops[0][3]
    for ii in range(first.interval, limit + 1, step):      # the critical path first, at the bound
        swung = _swing_latency(graph, timing, k, ii, asap, b.latency, _latency(graph, best))
        if swung is not None and _latency(graph, swung) < _latency(graph, best):
            best = swung
        if _latency(graph, best) <= b.latency:
            return best
    return _refine(graph, timing, k, asap, b.latency, best, tops)


def _refine(graph, timing, k, asap, bound: int, best: Placed, found: list,
            at_bound: bool = True) -> Placed:
    """`best`, or a shorter latency from holding the REFINED most promising of `found` —
    (latency, interval, attempt, placement), best first — to ever shorter latencies (`at_bound`:
    see _shortest_latency)."""
    for _, ii, n, top in found[:REFINED]:
        if _latency(graph, best) <= bound:
            break
        shorter = _shortest_latency(graph, timing, k, ii, asap, bound, top, ATTEMPTS[n], at_bound)
        if _latency(graph, shorter) < _latency(graph, best):
            best = shorter
    return best


def _intervals(floor: int, limit: int) -> list[int]:
    """The intervals a held search tries, from `floor` to `limit`: all of them up to 4, else 4
    spread evenly (a few budgets of a big graph allow a hundred)."""
    step = max(1, -(-(limit - floor) // 3))
    return sorted({*range(floor, limit, step), limit})


def _first_held(graph, timing, k, asap, intervals, attempts, latency: int) -> Placed | None:
    """The first placement held to `latency` over `intervals` × `attempts`, or None."""
    for ii in intervals:
        for attempt in attempts:
            placed = modulo_schedule(graph, timing, k, ii, asap, latency=latency, attempt=attempt)
            if placed is not None:
                return placed
    return None


def _quick_for(graph, timing, k, asap) -> Placed:
    """K VAMPs, cheaply (the trade-off sweep of big graphs), the first of these found: the first
    placement at the smallest interval the list scheduler reaches, if that interval is within
    TOLERANCE of the bound and its latency within LATENCY_SLACK of the latency bound; one held to
    that latency with the longest ops first (BIG), at the first interval from the bound up to
    TOLERANCE above it; if the first placement's latency is within the slack, one more such try
    (evicting where the fewest ops are: `scan`), else that placement; one held to it by QUICK over
    the same intervals; one held to it at the largest interval within TOLERANCE of the
    bound (swing order, then the urgency order); the first placement. No shortening. Near
    saturation successive torque sets crowd the VAMPs and an unheld placement's latency can be
    several times the bound (a 32-joint log graph on 241 VAMPs, II 32: 220 flops against a bound of
    58). QUICK's attempts, which wait for exact fits, are slow where they fail on a big graph (a
    64-joint log graph at II 4 on 4357 VAMPs: two minutes), so they come after the cheap ones."""
    b, floor, limit, target = _targets(graph, timing, k)
    first = _smallest_interval(graph, timing, k, asap, floor)
    if first.interval <= limit and _latency(graph, first) <= target:
        return first
    intervals = _intervals(floor, limit)
    placed = _first_held(graph, timing, k, asap, intervals, BIG, target)
    if placed is None and _latency(graph, first) <= target:    # only the interval is over
        placed = _first_held(graph, timing, k, asap, intervals, (Attempt(big=True, scan=True),),
                             target) or first
    if placed is None:
        placed = _first_held(graph, timing, k, asap, intervals, QUICK, target)
    if placed is None:
        placed = _first_held(graph, timing, k, asap, [max(first.interval, limit)],
                             (Attempt(swing=True), Attempt()), target)
    return placed or first


# The portfolio _best_for tries at each interval (keyword arguments of modulo_schedule); the
# REFINED placements with the shortest latencies are then held to shorter ones.
ATTEMPTS = (Attempt(big=True), Attempt(pack=1), Attempt(big=True, scan=True), Attempt(),
            Attempt(seed=1), Attempt(pack=2, seed=1), Attempt(scan=True), Attempt(scan=True, seed=2),
            Attempt(pack=4))
REFINED = 3
BIG = (Attempt(big=True), Attempt(big=True, seed=1))     # _quick_for's cheap attempts, then its
QUICK = (Attempt(pack=1), Attempt(pack=2, seed=1))      # slower ones


def _swing_latency(graph, timing, k, ii, asap, bound: int, worse: int) -> Placed | None:
    """The shortest latency from `bound` up (doubling the slack, then halving back) at which the
    swing order places every op at interval `ii`; None if none below `worse`."""
    found, step, lo = None, 1, bound
    while lo < worse:
        placed = modulo_schedule(graph, timing, k, ii, asap, latency=lo, attempt=Attempt(swing=True))
        if placed is not None:
            found = placed
            break
        lo, step = lo + step, step * 2
    if found is None:
        return None
    hi, lo = _latency(graph, found) - 1, max(bound, lo - step // 2 + 1)
    while lo <= hi:
        mid = (lo + hi) // 2
        placed = modulo_schedule(graph, timing, k, ii, asap, latency=mid, attempt=Attempt(swing=True))
        if placed is None:
            lo = mid + 1
        else:
            found, hi = placed, min(mid, _latency(graph, placed)) - 1
    return found


def _latency(graph, placed: Placed) -> int:
    return max(placed.finish[o.node] for o in graph.outputs)


def _shortest_latency(graph, timing, k, ii, asap, bound: int, top: Placed,
                      attempt: Attempt, at_bound: bool = True) -> Placed:
    """Halve the latency a placement at interval `ii` is held to, from `top`'s down to `bound`
    (`attempt`: the Attempt that found `top`). The bound is tried
    first (unless `at_bound` is off: the caller tried it): a held placement is not monotone in the
    latency (a 32-joint linear graph on 22 VAMPs at II 79 is placed at its bound, 269, but not at
    275)."""
    if at_bound and _latency(graph, top) > bound:
        placed = modulo_schedule(graph, timing, k, ii, asap, latency=bound, attempt=attempt)
        if placed is not None:
            return placed
    best, lo, hi = top, bound + 1, _latency(graph, top) - 1
    while lo <= hi:
        mid = (lo + hi) // 2
        placed = modulo_schedule(graph, timing, k, ii, asap, latency=mid, attempt=attempt)
        if placed is None:
            lo = mid + 1
        else:
            best, hi = placed, min(mid, _latency(graph, placed)) - 1
    return best


def _smallest_interval(graph, timing, k, asap, floor: int) -> Placed:
    """The first interval from `floor` (the interval bound) up at which the list scheduler places
    every op."""
    ii = floor
    while True:
        placed = modulo_schedule(graph, timing, k, ii, asap)
        if placed is not None:
            return placed
        ii += 1


MISSES = 2          # --interval T: budgets in a row that miss T before the search for fewer stops
FEWER_TRIED = 8     # --vamps K --interval T where K misses T: the smaller budgets tried


def _vamps_floor(graph, timing, interval: int, smallest: int) -> int:
    """The fewest VAMPs that could reach `interval`: ⌈W/T⌉, and the smallest network."""
    return max(smallest, -(-work(graph, timing) // interval))


def _fewest_vamps(graph, timing, interval, asap, smallest) -> tuple[int, Placed]:
    """The fewest VAMPs at which the scheduler reaches `interval` (binary search from ⌈W/T⌉ up to
    one VAMP per VAMP-op, where it always does)."""
    lo = _vamps_floor(graph, timing, interval, smallest)
    hi = vamp_ops(graph)
    best = modulo_schedule(graph, timing, hi, interval, asap)
    if best is None:      # a VAMP per VAMP-op is always free: only a bug gets here
        raise VampcInternalError(f"no placement at interval {interval} with a VAMP per op")
    while lo < hi:
        mid = (lo + hi) // 2
        placed = modulo_schedule(graph, timing, mid, interval, asap)
        if placed is None:
            lo = mid + 1
        else:
            hi, best = mid, placed
    return hi, best


def _finish(graph: Graph, timing: Timing, placed: Placed, k: int, verify: bool, proof: str = "",
            asap: Schedule | None = None):
    from vampc.schedule.layout import Layout
    latency = max(placed.finish[o.node] for o in graph.outputs)
    # the critical path is the data path (the graph's, as ASAP finds it): what the paper's formula
    # counts; the rest of the latency is waiting for a busy VAMP (Schedule.waits)
    asap = asap or schedule_asap(graph, timing, verify=False)
    sched = Schedule(timing, placed.start, placed.finish, latency, asap.critical_path, asap.mults,
                     asap.adds, placed.interval)
    used = sorted({v for p in placed.placement for v in p})
    renumber = {v: j for j, v in enumerate(used)}          # VAMPs the schedule left idle go
    placement = tuple(tuple(renumber[v] for v in p) for p in placed.placement)
    clock = buffer_clock(graph, sched, placement)
    layout = Layout("budget", placement, placed.interval, clock, grouped=False, proof=proof)
    if verify:
        sched.verify(graph)
        layout.verify(graph)
    return layout, sched, bounds(graph, timing, k)


def buffer_clock(graph: Graph, sched: Schedule, placement) -> int:
    """The largest buffer clock B dividing the period under which every result a later reader takes
    from a buffer is still on its VAMP's Result at the end of the block it appeared in."""
    P = sched.interval
    need = _buffered_results(graph, sched, placement)
    for clock in sorted((b for b in range(1, P + 1) if P % b == 0), reverse=True):
        if all(nxt >= next_capture(emit, clock) for emit, nxt in need):
            return clock
    return 1


def _buffered_results(graph, sched, placement) -> list[tuple[int, int]]:
    """(emit, next emit) of every result some reader takes after its VAMP's next dump."""
    P = sched.interval
    on: dict[int, list[int]] = {}
    for nd in graph.compute_nodes():
        for v in placement[nd.id]:
            on.setdefault(v, []).append(nd.id)
    nxt: dict[int, int] = {}
    for nodes in on.values():
        for i, (_, after) in zip(nodes, result_windows([sched.finish[i] - 1 for i in nodes], P)):
            nxt[i] = min(nxt.get(i, math.inf), after)
    late = {a for nd in graph.compute_nodes() for a in nd.args
            if a in nxt and sched.start[nd.id] >= nxt[a]}
    return [(sched.finish[a], nxt[a]) for a in late]
