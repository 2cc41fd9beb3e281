"""The hardware's timing rules, stated once (README, *Timing model*): when a value shows on a
Result, a buffer stage or a port, when a slot's registers change, and how the Cycle-Counter places
events in a period. The allocator, the budget scheduler, the network check (Network.verify), the
static timing check and the tick engine all take them from here.

The rules (vampc.network.model describes the hardware they belong to):

- Periods. Everything repeats with the period P (ticks between successive torque sets); the
  Cycle-Counter runs 0..P-1 and an event of a slot happens at the tick whose counter is its field.
  Several events of one kind on one VAMP (say its slots' dumps) follow one another round the period:
  `cyclic_gaps` gives, for each, the ticks until the next one (P if it is alone, 0 if another has
  the same counter: two events of one register in one tick).
- Result. A slot dumping at the end of tick d shows its value from d + 1 until the VAMP's next dump
  shows: `result_windows`.
- Buffers. A delay buffer behind a VAMP is clocked every B ticks (B divides P): at the end of each
  tick t with (t + 1) % B == 0 (`captures`) stage 1 takes the Result and stage s takes stage s - 1. So
  stage s shows during block b what the Result showed at the end of block b - s (`capture_counter`),
  and a value on the Result during [emit, next_emit) shows on stage s during `buffer_window`.
- Ports. A host port entry written at the start of block k shows until the port's next entry is
  written: `port_window`. A constant buffer always shows its value.
- Micro-steps. Step j of a slot runs at the last tick of its span; the spans end at the slot's
  delay-R (`step_counter`), each as long as its slowest unit (vampc.machine.ops.Timing.step_ends).
- Slots. A slot's latch..dump span fits in one period and the spans of one VAMP's slots never meet,
  cyclically (`overlapping_spans`).
"""
from __future__ import annotations

import math
from bisect import bisect_right

from vampc.kinds import TapKind, unhandled


def cyclic_gaps(counters, period: int) -> list[int]:
    """For each counter of a VAMP's slots (say their delay-A values): the ticks until the next one
    comes round, cyclically — P if it is alone, 0 if another slot has the same counter (two events
    of one register in one tick)."""
    if len(counters) == 1:          # a systolic VAMP: one slot, the common case by far
        return [period]
    order = sorted(range(len(counters)), key=lambda k: counters[k])
    gaps = [period] * len(counters)
    for pos, k in enumerate(order):
        nxt = counters[order[(pos + 1) % len(order)]]
        gaps[k] = (nxt - counters[k]) % period or (0 if nxt == counters[k] else period)
    return gaps


def result_windows(dumps, period: int) -> list[tuple[int, int]]:
    """For each dump tick of one VAMP's slots (absolute, set 0): the [emit, next emit) ticks its
    value shows on the Result — from the tick after its dump until the VAMP's next dump shows."""
    gaps = cyclic_gaps([d % period for d in dumps], period)
    return [(d + 1, d + 1 + (g or period)) for d, g in zip(dumps, gaps)]


def result_window(emit: float, next_emit: float) -> tuple[float, float]:
    """A Result shows a slot's value from its emit tick until the VAMP's next dump shows."""
    return (emit, next_emit)


def captures(tick: int, clock: int) -> bool:
    """Whether the buffer stages take their inputs at the end of `tick`."""
    return (tick + 1) % clock == 0


def shift_compares(period: int, clock: int) -> list[int]:
    """The ticks of the period the buffers' Cycle-Counter is compared against, one comparator each:
    those at whose end the stages shift (captures), none where they shift at every tick's end (a
    clock of one tick needs no comparator: vampc.rtl.design builds none, vampc.report.counts counts
    none; their OR, always true, had been built and counted, a review's find)."""
    ends = [t for t in range(period) if captures(t, clock)]
    return [] if len(ends) == period else ends


def next_capture(emit: int, clock: int) -> int:
    """The earliest tick a VAMP's next value may show on its Result so that its buffer captured the
    value that appeared at `emit`: the start of the next block."""
    return (emit // clock + 1) * clock


def capture_counter(counter: int, stage: int, clock: int, period: int) -> int:
    """The counter at whose end stage `stage` of a buffer captured (from its VAMP's Result, `stage`
    block ends back) what it shows at `counter`."""
    return ((counter // clock - stage + 1) * clock - 1) % period


def buffer_window(emit: float, next_emit: float, stage: int, clock: int) -> tuple[float, float]:
    """[first, end) ticks in which stage `stage` of a buffer shows a value its VAMP showed during
    [emit, next_emit): stage 1 captures it at every block end inside that span. Empty (first >= end)
    when the span holds no block end: the value is never captured."""
    if math.isinf(emit):
        return (-math.inf, math.inf)
    first = (emit // clock + stage) * clock
    end = (next_emit // clock + stage) * clock
    return (first, end)


def buffer_stage(emit: int, next_emit: int, tick: int, clock: int) -> int:
    """0 if a value on its VAMP's Result during [emit, next_emit) is read from the Result at `tick`,
    else the first buffer stage that shows it then."""
    if emit <= tick < next_emit:
        return 0
    return max(1, tick // clock - next_emit // clock + 1)


class PortSchedule:
    """When the entries of one host port show: entry j is written at the start of its block (taken
    mod the K blocks of a period) and shows until the port's next entry is written."""

    def __init__(self, blocks, per_period: int):
        self.K = per_period
        self.order = sorted((b % per_period, j) for j, b in enumerate(blocks))
        self._blocks = [b for b, _ in self.order]      # (bisected: ints compare faster than pairs)
        gaps = cyclic_gaps([b for b, _ in self.order], per_period)
        self.gap = {j: g or per_period for (_, j), g in zip(self.order, gaps)}   # blocks it shows

    def entry_at(self, block: int) -> int | None:
        """The entry showing during `block`: the one written latest at or before it, cyclically
        (None for a port without entries, a program port)."""
        if not self.order:
            return None
        k = bisect_right(self._blocks, block % self.K) - 1   # -1: the last, a period ago
        return self.order[k][1]


def port_writes(entries, block: int, per_period: int):
    """(entry, torque set) for each entry of a host port written at the start of `block`: entry j
    (first written at its block, for set 0) is written again every period (`per_period` blocks), for
    the next set. The set may be outside the run (negative, or past the last set)."""
    for j, e in enumerate(entries):
        since = block - e.block
        if since % per_period == 0:
            yield j, since // per_period


def port_window(block: int, next_block: int, clock: int) -> tuple[int, int]:
    """A port entry written at the start of `block` holds until the port's next entry is written."""
    return (block * clock, next_block * clock)


def window(tap, clock: int, emit: float = 0, next_emit: float = 0, block: int = 0,
           next_block: int = 0) -> tuple[float, float]:
    """[first, end) ticks in which `tap` (a vampc.network.model.Tap) shows the value of interest:
    `emit` and `next_emit` bound the source VAMP's value on its Result (vamp and buffer taps;
    infinite for a VAMP that always shows the same value), `block` and `next_block` a port entry."""
    if tap.kind is TapKind.CONST:
        return (-math.inf, math.inf)
    if tap.kind is TapKind.PORT:
        return port_window(block, next_block, clock)
    if tap.kind is TapKind.VAMP:
        return (-math.inf, math.inf) if math.isinf(emit) else result_window(emit, next_emit)
    if tap.kind is TapKind.BUFFER:
        return buffer_window(emit, next_emit, tap.stage, clock)
    if tap.kind is TapKind.BUS:
        from vampc.errors import VampcInternalError
        raise VampcInternalError("a bus tap shows what its writer drives in that tick: resolve it "
                                 "to the writer's tap first (vampc.network.bus.bus_source)")
    return unhandled(tap.kind)


def step_counter(delay_r: int, ends: tuple[int, ...], j: int, period: int) -> int:
    """The counter at which micro-step j of a slot dumping at `delay_r` runs (`ends`: the steps'
    end ticks from the op's first tick, vampc.machine.ops.Timing.step_ends)."""
    return (delay_r - (ends[-1] - ends[j])) % period


def overlapping_spans(spans, period: int) -> tuple[int, int] | None:
    """The first two of `spans` (latch tick, ticks) of one VAMP's slots that meet, cyclically, as
    their indices; None when none do."""
    if len(spans) < 2:
        return None
    order = sorted((start % period, length, k) for k, (start, length) in enumerate(spans))
    for (l0, n0, k0), (l1, _, k1) in zip(order, order[1:] + [(order[0][0] + period,) + order[0][1:]]):
        if l1 < l0 + n0:
            return k0, k1
    return None
