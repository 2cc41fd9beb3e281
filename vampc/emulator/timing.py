"""Static timing: when, by the tick rules, each slot latches, computes and shows set 0's values, and
which slot, port entry or constant each operand it latches actually holds then.

Derived only from the wiring, the delivered programs and the host's port schedule (the rules are in
vampc/machine/timing.py); the graph and the recorded schedule are not looked at here. Every source
shows a value during a window no longer than the period P, so a latch at Cycle-Counter d falls on
exactly one tick of it:

- what a VAMP's Result shows at counter d is the slot whose dump shows latest at or before d
  (cyclically); what stage s of a buffer shows during block b is what its VAMP's Result showed at the
  end of block b - s; what a port shows is the entry written latest at or before d's block;
- so every operand resolves, by counters alone, to a producing slot (or port entry, or constant), and
  the slots form a dataflow graph, which must have no loop;
- in topological order, a slot's latch tick for set 0 is the tick ≡ its delay (mod P) inside its
  producer's set-0 window; the slot then runs its micro-steps in the ticks ending with the first tick
  whose counter is its delay-R that leaves room for them after both latches; an operand register must
  not be latched again (by any slot of the VAMP, or the same slot a period later) before the last
  micro-step that reads it.

A slot whose operands are all constants (or such slots' results) shows the same value every period:
it is *periodic*, and only counters matter for it and its readers.
"""
from __future__ import annotations

import math
from bisect import bisect_right
from dataclasses import dataclass
from graphlib import CycleError, TopologicalSorter

from vampc.emulator.load import Loaded
from vampc.errors import VampcError, VampcInternalError
from vampc.kinds import SourceKind, TapKind, unhandled
from vampc.machine.interp import duration, reading_end
from vampc.machine.timing import (
    PortSchedule,
    capture_counter,
    cyclic_gaps,
    port_window,
    window,
)

INF = math.inf

# A source: (SourceKind.SLOT, vamp, slot) | (SourceKind.PORT, port, entry) | (SourceKind.CONST, index)
Source = tuple


@dataclass(frozen=True)
class SlotTiming:
    """Absolute ticks (set 0) of a slot: latches (-inf: constant), last micro-step (its dump), the end
    of its Result window; periodic slots give Cycle-Counter values instead. `src_a`, `src_b`: the
    source of each tap of the operands it latches."""

    latch_a: float
    latch_b: float
    last: float
    next_emit: float
    periodic: bool
    src_a: tuple[Source, ...]
    src_b: tuple[Source, ...]

    @property
    def emit(self) -> float:
        """First tick its Result shows set 0's value."""
        return self.last + 1


@dataclass(frozen=True)
class StaticTiming:
    """Every slot's timing (by (vamp, slot)), the slots in dataflow order, and each output's slot."""

    slots: dict
    order: tuple[tuple[int, int], ...]
    outputs: tuple[tuple[int, int], ...]


class _Deriver:
    def __init__(self, ld: Loaded):
        self.ld, self.net = ld, ld.net
        self.P, self.B = ld.net.period, ld.net.clock
        self.K = self.P // self.B
        self.emits = []         # per VAMP: sorted (emit counter, slot)
        for v, progs in enumerate(ld.programs):
            self.emits.append(sorted(((p.delay_r + 1) % self.P, k) for k, p in enumerate(progs)))
        self.ports = [PortSchedule([e.block for e in p.entries], self.K) for p in ld.net.ports]
        self.sources: dict = {}  # (vamp, slot) -> operand_sources, each derived once
        # per VAMP, per slot: ticks until the next dump, the next A latch and the next B latch (a
        # one-slot VAMP's, the common case by far: P each, one tuple shared)
        alone = ((self.P,),) * 3
        self.gaps = [alone if len(progs) == 1 else
                     tuple(cyclic_gaps([getattr(p, f) for p in progs], self.P)
                           for f in ("delay_r", "delay_a", "delay_b")) for progs in ld.programs]
        self._rom_ticks: dict = {}  # ROM pointer -> (duration, reading_end), each worked out once
        bus = ld.net.bus                  # the Mostly-Local Bus: who drives each bus when
        self.drivers = (bus.drivers([b.source for b in ld.net.buffers], self.P)
                        if bus is not None else None)

    # --- which source a tap shows at a counter (counters only) ---------------------------------
    def showing(self, v: int, counter: int) -> int:
        """The slot of VAMP v whose value its Result shows at `counter`."""
        emits = self.emits[v]
        k = bisect_right(emits, (counter, INF)) - 1
        return emits[k][1]      # k = -1 wraps round to the latest emit of the previous period

    def entry(self, port: int, block: int) -> int | None:
        """The entry of `port` written latest at or before `block` (mod K)."""
        return self.ports[port].entry_at(block)

    def source(self, tap, counter: int) -> Source:
        """What `tap` shows at Cycle-Counter `counter`."""
        if tap.kind is TapKind.CONST:
            return (SourceKind.CONST, tap.index)
        if tap.kind is TapKind.PORT:
            return (SourceKind.PORT, tap.index, self.entry(tap.index, counter // self.B))
        if tap.kind is TapKind.VAMP:
            return (SourceKind.SLOT, tap.index, self.showing(tap.index, counter))
        if tap.kind is not TapKind.BUFFER:
            unhandled(tap.kind)
        capture = capture_counter(counter, tap.stage, self.B, self.P)
        src = self.net.buffers[tap.index].source
        return (SourceKind.SLOT, src, self.showing(src, capture))

    def operand_sources(self, v: int, k: int):
        """(operand taps, sources) of both operands of slot (v, k)."""
        got = self.sources.get((v, k))
        if got is None:
            got = self.sources[(v, k)] = self._operand_sources(v, k)
        return got

    def _operand_sources(self, v: int, k: int):
        prog = self.ld.programs[v][k]
        vamp = self.net.vamps[v]
        a = vamp.a[prog.sel_a].taps
        b = vamp.b[prog.sel_b].taps
        if self.drivers is not None:      # a bus tap carries what its writer drives then
            a = self._over_bus(v, k, "A", a, prog.delay_a)
            b = self._over_bus(v, k, "B", b, prog.delay_b)
        return ((a, tuple(self.source(t, prog.delay_a) for t in a)),
                (b, tuple(self.source(t, prog.delay_b) for t in b)))

    def _over_bus(self, v: int, k: int, name: str, taps, counter: int):
        """The taps with each bus tap replaced by the source driving that bus at `counter`."""
        from vampc.network.bus import bus_source
        if not any(t.kind is TapKind.BUS for t in taps):
            return taps
        out = []
        for tap in taps:
            if tap.kind is TapKind.BUS:
                w, why = bus_source(self.net.bus, self.drivers, v, tap.index, counter, self.P)
                if w is None:
                    self.fail(v, k, f"operand {name} latches tier {tap.index}'s bus at "
                                    f"Cycle-Counter {counter}, but {why}")
                tap = w.source
            out.append(tap)
        return tuple(out)

    def rom_ticks(self, rom: int) -> tuple[int, int]:
        """(duration, reading_end) of a ROM entry on this program's timing (vampc.machine.interp)."""
        got = self._rom_ticks.get(rom)
        if got is None:
            got = self._rom_ticks[rom] = (duration(rom, self.ld.timing),
                                          reading_end(rom, self.ld.timing))
        return got

    # --- absolute timing in dataflow order ------------------------------------------------------
    def next_emit(self, v: int, k: int, emit: float) -> float:
        return emit + (self.gaps[v][0][k] or self.P)

    def window(self, tap, src: Source, done: dict) -> tuple[float, float, bool]:
        """[lo, hi) ticks (set 0) in which `tap` shows `src`; periodic: counters, True."""
        kind = src[0]
        if kind is SourceKind.CONST:
            return -INF, INF, False
        if kind is SourceKind.PORT:
            port, j = src[1], src[2]
            if j is None:
                raise VampcError(f"{self.ld.path}: port {port} holds no data (a program port) but "
                                 "an operand reads it")
            block = self.net.ports[port].entries[j].block
            lo, hi = port_window(block, block + self.ports[port].gap[j], self.B)
            return lo, hi, False
        t = done[(src[1], src[2])]            # a slot's result, on its Result or a buffer stage
        lo, hi = window(tap, self.B, t.emit, t.next_emit)
        return lo, hi, t.periodic

    def latch(self, v, k, name, taps, sources, delay, done) -> tuple[float, bool]:
        """The set-0 tick operand `name` is latched (-inf: constant), and whether it is periodic."""
        ticks, periodic = set(), False
        for tap, src in zip(taps, sources):
            lo, hi, per = self.window(tap, src, done)
            if lo == -INF:
                ticks.add(-INF)
                continue
            if per:
                periodic = True
                if not (delay - lo) % self.P < hi - lo:
                    self.fail(v, k, f"operand {name} latched at counter {delay} outside {tap}'s "
                                    f"window (counters {lo:g} .. {hi - 1:g})")
                ticks.add(-INF)
                continue
            t = lo + (delay - lo) % self.P
            if not t < hi:
                self.fail(v, k, f"operand {name} latched at tick {t:g} outside {tap}'s window "
                                f"[{lo:g}, {hi:g})")
            ticks.add(t)
        if len(ticks - {-INF}) > 1:
            self.fail(v, k, f"operand {name} reads matrix columns that show set 0 at different "
                            f"ticks {sorted(ticks - {-INF})}")
        real = ticks - {-INF}
        return (real.pop() if real else -INF), periodic

    def slot(self, v: int, k: int, done: dict) -> SlotTiming:
        prog = self.ld.programs[v][k]
        (ta, sa), (tb, sb) = self.operand_sources(v, k)
        t_a, per_a = self.latch(v, k, "A", ta, sa, prog.delay_a, done)
        t_b, per_b = self.latch(v, k, "B", tb, sb, prog.delay_b, done)
        d = self.rom_ticks(prog.rom)[0]
        if d > self.P:
            self.fail(v, k, f"a {d}-tick op does not fit a {self.P}-tick period")
        ready = max(t_a, t_b)
        if ready == -INF:          # constants (or periodic values) only: the same every period
            last = prog.delay_r
            self.check_relatch(v, k, last, None, None)
            return SlotTiming(t_a, t_b, last, self.next_emit(v, k, last + 1), True, sa, sb)
        earliest = ready + d - 1
        last = earliest + (prog.delay_r - earliest) % self.P
        self.check_relatch(v, k, last, t_a, t_b)
        return SlotTiming(t_a, t_b, last, self.next_emit(v, k, last + 1), False, sa, sb)

    def check_relatch(self, v, k, last, t_a, t_b) -> None:
        """Operand registers hold what the slot latched until its last reading micro-step."""
        progs = self.ld.programs[v]
        prog = progs[k]
        d, reading = self.rom_ticks(prog.rom)
        reader = last - d + reading
        for name, t, gaps, mine in (("A", t_a, self.gaps[v][1], prog.delay_a),
                                    ("B", t_b, self.gaps[v][2], prog.delay_b)):
            gap = gaps[k]
            if t is not None and t != -INF:
                if reader - t >= gap:
                    # (the cause may be the other operand, latched later: an operand-B source edited
                    # to a later VAMP was said of operand A alone, a field the user never touched)
                    other, t_other = ("B", t_b) if name == "A" else ("A", t_a)
                    waits = (f"; the op waits for operand {other}, latched at tick {t_other:g}"
                             if t_other is not None and t_other != -INF and t_other > t else "")
                    self.fail(v, k, f"operand {name} latched at tick {t:g} is re-latched at tick "
                                    f"{t + gap:g}, before the micro-step at tick {reader:g} that "
                                    f"still reads it (delay-R {prog.delay_r}{waits})")
                continue
            if (reader - mine) % self.P >= gap:
                self.fail(v, k, f"operand {name} latched at counter {mine} is re-latched at counter "
                                f"{(mine + gap) % self.P}, before the micro-step at counter "
                                f"{reader % self.P:g} that still reads it (delay-R {prog.delay_r})")

    def fail(self, v: int, k: int, what: str):
        raise VampcError(f"{self.ld.path}: {self.ld.vamp_name(v, k)}: {what}")


def derive(ld: Loaded) -> StaticTiming:
    """Every slot's timing; VampcError naming the VAMP, slot, tick and operand on a violation."""
    der = _Deriver(ld)
    deps: dict[tuple[int, int], set] = {}
    for v, progs in enumerate(ld.programs):
        _check_units(ld, der, v)
        for k in range(len(progs)):
            (_, sa), (_, sb) = der.operand_sources(v, k)
            deps[(v, k)] = {(s[1], s[2]) for s in sa + sb if s[0] is SourceKind.SLOT}
    order = _dataflow_order(ld, deps)
    done: dict = {}
    for v, k in order:
        done[(v, k)] = der.slot(v, k, done)
    outputs = tuple(_output(ld, der, o, done) for o in ld.net.outputs)
    return StaticTiming(done, order, outputs)


def _dataflow_order(ld: Loaded, deps: dict) -> tuple:
    """The slots with every producer before its readers (Kahn's algorithm on plain lists: a hundred
    thousand slots take a fraction of graphlib's time); VampcError naming the loop if there is one."""
    keys = list(deps)
    index = {key: i for i, key in enumerate(keys)}
    waiting = [0] * len(keys)
    readers: list[list[int]] = [[] for _ in keys]
    for i, key in enumerate(keys):
        for src in deps[key]:
            j = index.get(src)
            if j is not None:
                waiting[i] += 1
                readers[j].append(i)
    ready = [i for i, w in enumerate(waiting) if w == 0]
    order = []
    while ready:
        i = ready.pop()
        order.append(i)
        for r in readers[i]:
            waiting[r] -= 1
            if waiting[r] == 0:
                ready.append(r)
    if len(order) < len(keys):
        try:                            # graphlib names the loop
            tuple(TopologicalSorter(deps).static_order())
        except CycleError as exc:
            loop = exc.args[1]
            names = " -> ".join(ld.vamp_name(v, k) for v, k in loop)
            raise VampcError(f"{ld.path}: the wiring has a loop: {names}") from None
        raise VampcInternalError("static timing: slots left unordered without a loop")
    return tuple(keys[i] for i in order)


def _check_units(ld: Loaded, der: _Deriver, v: int) -> None:
    """The micro-steps of a VAMP's slots never share a tick (they use the same units)."""
    progs = ld.programs[v]
    if len(progs) < 2:
        return
    spans = sorted(((p.delay_r - duration(p.rom, ld.timing) + 1) % der.P, duration(p.rom, ld.timing), k)
                   for k, p in enumerate(progs))
    for (s0, n0, k0), (s1, _, k1) in zip(spans, spans[1:] + [(spans[0][0] + der.P,) + spans[0][1:]]):
        if s1 < s0 + n0:
            raise VampcError(f"{ld.path}: {ld.vamp_name(v, k0)} and slot {k1} run micro-steps in "
                             f"the same tick (counters {s0} .. {s0 + n0 - 1} and {s1 % der.P} ..)")


def _output(ld: Loaded, der: _Deriver, o, done) -> tuple[int, int]:
    """The slot τ_joint is read from; VampcError unless it shows set 0 at the read tick."""
    k = der.showing(o.vamp, o.tick % der.P)
    t = done[(o.vamp, k)]
    if not t.periodic and not t.emit <= o.tick < t.next_emit:
        raise VampcError(f"{ld.path}: τ{o.joint} is read from {ld.vamp_name(o.vamp, k)} at tick "
                         f"{o.tick}, but it shows set 0 during ticks [{t.emit:g}, {t.next_emit:g})")
    if not t.periodic and o.tick != t.emit:
        # (a tick moved within the hold window read the same torques, but the latency printed was
        # the edited tick: an audit's find)
        raise VampcError(f"{ld.path}: τ{o.joint} is read from {ld.vamp_name(o.vamp, k)} at tick "
                         f"{o.tick}, but it appears at tick {t.emit:g}, where the compiler reads it "
                         "(the file was edited); recompile it")
    return (o.vamp, k)
