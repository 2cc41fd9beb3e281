"""The network IR: VAMPs with time-multiplexed slots, delay buffers, host ports and constant buffers,
wired by taps through operand multiplexers (README, *Layouts*, *Program file*).

A layout binds every graph op to a (VAMP, slot) and repeats with a period P: the initiation interval,
in ticks, between successive torque sets. Everything below is periodic with P; absolute ticks are
those of torque set 0, and set j happens j·P ticks later. The systolic layout is the special case of
one slot per VAMP, one input per multiplexer and P = C (4 flops); the folded layouts reuse a node's
or a tier's VAMPs for every joint or tier, one torque set at a time.

Hardware (what the report counts):

- A VAMP has one pair of operand registers, three primitive modules and one Result register, and a
  table of slots. Each slot holds the paper's four control fields (delay-A, delay-B, delay-R, ROM
  pointer) plus two multiplexer selects (sel-A, sel-B): which of the VAMP's operand-A and operand-B
  inputs the slot latches (a select of a multiplexer of one input is always 0 and has no register:
  the report counts, and the RTL builds, a select only where an operand has several inputs). The Cycle-Counter runs 0..P-1 (Global-Reset pulses every P ticks); a slot
  latches operand A from input sel-A at the tick whose counter is its delay-A, operand B likewise, runs
  its micro-steps in the ticks ending with the one whose counter is delay-R, and drives the Result
  from the next tick. The Result holds until the VAMP's next dump (for one slot: exactly P ticks).
  In Program Mode every multiplexer passes input 0.
- A delay buffer is a chain of passive stages behind one VAMP, clocked every B ticks (the buffer
  clock; B divides P; systolic B = C): at the end of every tick t with (t + 1) % B == 0, stage 1 takes
  the VAMP's Result and stage s takes stage s - 1. So stage s shows, during block b (ticks bB..bB+B-1),
  what the Result showed at the end of block b - s: one chain serves every slot of its VAMP.
- A host port shows, during the blocks from one of its entries to the next, the value the host
  wrote at the start of that entry's block: entry k is written at tick block_k·B of each set. A port
  with one entry (the systolic case) is written once per period and holds for P ticks.
- A constant buffer always shows its value.

vampc.machine.timing states these rules once; the allocator, the budget scheduler, the network check
(Network.verify), the emulator's timing derivation and its tick engine all use them.
"""
from __future__ import annotations

from dataclasses import dataclass

from msgspec import Struct

from vampc.dataflow.graph import InputKey
from vampc.kinds import TapKind, unhandled
from vampc.machine.ops import Op


class Tap(Struct, frozen=True, gc=False, array_like=True):
    """Where an operand is read: a VAMP's Result, stage `stage` of a buffer, a host port or a constant.
    Encoded as the program file writes a tap, [kind, index, stage] (vampc.program.document)."""

    kind: TapKind
    index: int
    stage: int = 0  # buffers only, 1-based

    def __str__(self) -> str:
        return f"{self.kind} {self.index}" + (f" stage {self.stage}" if self.kind is TapKind.BUFFER else "")


def tap_source(tap: Tap, buffer_sources) -> int | None:
    """The VAMP whose Result `tap` carries: the VAMP itself, or the VAMP a buffer delays
    (`buffer_sources[b]`: buffer b's source VAMP); None for a host port, a constant buffer or a bus
    (whose source depends on the tick: Bus.source)."""
    kind = tap.kind
    if kind is _VAMP:          # (the members bound once: an Enum member read from its class costs
        return tap.index       # 85 ns, and a program walk asks this of every VAMP)
    if kind is _BUFFER:
        return buffer_sources[tap.index]
    if kind is _PORT or kind is _CONST or kind is _BUS:
        return None
    return unhandled(kind)


_VAMP, _BUFFER, _PORT, _CONST, _BUS = (TapKind.VAMP, TapKind.BUFFER, TapKind.PORT, TapKind.CONST,
                                      TapKind.BUS)


# On the Mostly-Local Bus, operand A's input 0 of a VAMP reading a Result or a buffer stage is
# the point-to-point wire Program Mode passes words along (the bus-write registers are empty until
# programmed): the compiler never selects it in Data Mode, whose results travel on the bus, so a
# select of it is a damaged word (it read the same value over the wire, answer unchanged: an
# audit's).
PROGRAM_WIRE_READ = ("sel-a 0 reads operand A's input 0, Program Mode's wire, which a network on "
                     "the Mostly-Local Bus reads in Program Mode only (results reach their readers "
                     "over the bus): the file was damaged; recompile it")


def program_wire(vamp) -> bool:
    """Whether `vamp`'s operand-A input 0 is Program Mode's wire alone, on a bus network (a VAMP's
    Result or a buffer stage, not a host port or constant buffer, which Data Mode reads too)."""
    return bool(vamp.a) and vamp.a[0].taps[0].kind in (TapKind.VAMP, TapKind.BUFFER)


class Operand(Struct, frozen=True, gc=False):
    """One multiplexer input: one tap, or three taps carrying the columns of a matrix made by an MM
    group."""

    taps: tuple[Tap, ...]


class Slot(Struct, frozen=True, gc=False):
    """One op a VAMP runs each period: graph node `node` (an MM member computes `column`), reading
    inputs `sel_a` and `sel_b` of its multiplexers. Ticks are absolute, for set 0."""

    node: int
    op: Op
    column: int | None
    sel_a: int
    sel_b: int
    latch_a: int   # tick at which operand A is latched
    latch_b: int
    dump: int      # tick at the end of which the result is driven

    @property
    def emit(self) -> int:
        """First tick at which the Result shows this slot's value (for set 0)."""
        return self.dump + 1


class ProgrammedSlot(Struct, frozen=True, gc=False):
    """A slot as a VAMP's program holds it: the same op and selects as a scheduled `Slot`, but its
    events as Cycle-Counter values (delay-A, delay-B, delay-R, 0..P-1), not absolute ticks. A network
    loaded for the emulator has these; its absolute times are the emulator's to derive
    (vampc.emulator.timing), or the schedule's (vampc.program.document.scheduled_network_from_doc,
    what a report reads)."""

    node: int
    op: Op
    column: int | None
    sel_a: int
    sel_b: int
    delay_a: int
    delay_b: int
    delay_r: int


class Vamp(Struct, frozen=True, gc=False):
    """One VAMP: its multiplexer inputs for operands A and B and its slots, in dump order (scheduled
    `Slot`s after allocation, `ProgrammedSlot`s once loaded from a program)."""

    index: int
    a: tuple[Operand, ...]
    b: tuple[Operand, ...]
    slots: tuple[Slot, ...]

    @property
    def node(self) -> int:
        """The graph node of the first slot (for messages)."""
        return self.slots[0].node

    @property
    def kind(self) -> tuple[int, int, int]:
        """(slots, operand-A inputs, operand-B inputs): the shape of its hardware (what `vampc rtl`
        synthesizes once per kind, and its estimates and the report's --rtl check count)."""
        return len(self.slots), len(self.a), len(self.b)


class Buffer(Struct, frozen=True, gc=False):
    """A delay buffer of `stages` stages behind VAMP `source`."""

    index: int
    source: int
    stages: int


class PortEntry(Struct, frozen=True, gc=False):
    """What the host writes to a port at the start of `block` (absolute, set 0) of every set."""

    key: InputKey
    block: int


class Port(Struct, frozen=True, gc=False):
    """A host input port: `size` scalars (3 or 9), written with each entry's value at its block."""

    index: int
    size: int
    entries: tuple[PortEntry, ...]


class Const(Struct, frozen=True, gc=False):
    """A constant input buffer (p*, r*, m, J, endpoint values, ...)."""

    index: int
    name: str
    value: tuple[float, ...]


class OutputPoint(Struct, frozen=True, gc=False):
    """τ_joint of set j is scalar `component` of VAMP `vamp`'s Result at tick j·P + `tick`."""

    joint: int
    vamp: int
    component: int
    tick: int


class Tier(Struct, frozen=True, gc=False):
    """One tier of the Mostly-Local Bus: buses of `span` VAMPs each, laid end to end along the line
    of VAMPs from position `offset` (the first bus, before it, is shorter)."""

    span: int
    offset: int = 0

    def bus_at(self, position: int) -> int:
        """The bus of this tier in front of the VAMP at `position` (-1 for the short first bus)."""
        return (position - self.offset) // self.span

    def buses(self, vamps: int) -> int:
        """Buses of this tier over a line of `vamps` VAMPs."""
        return self.bus_at(vamps - 1) - self.bus_at(0) + 1

    def carries(self, lo: int, hi: int) -> bool:
        """Whether one bus of this tier is in front of every position from `lo` to `hi`."""
        return self.bus_at(lo) == self.bus_at(hi)

    def covers(self, bus: int, lo: int, hi: int) -> bool:
        """Whether bus `bus` of this tier is in front of every position from `lo` to `hi`."""
        return self.bus_at(lo) == bus == self.bus_at(hi)


class BusWrite(Struct, frozen=True, gc=False):
    """A bus-write register: at Cycle-Counter `counter` the VAMP behind `source` (its Result, or a
    stage of its delay buffer) drives the bus of tier `tier` in front of it."""

    source: Tap
    counter: int
    tier: int


class Bus(Struct, frozen=True, gc=False):
    """A network's Mostly-Local Bus (vampc.network.bus): the tiers, each VAMP's place on the line,
    the bus-write registers, and the ticks the bus added to the basic cycle (`stretch`) and to the
    latency (`wait`) over the point-to-point network of the same layout."""

    tiers: tuple[Tier, ...]
    position: tuple[int, ...]
    writes: tuple[BusWrite, ...]
    stretch: int = 0
    wait: int = 0

    def writer_position(self, tap: Tap, buffer_sources) -> int:
        """Where on the line the VAMP (or the buffer behind it) driving `tap` sits."""
        return self.position[tap_source(tap, buffer_sources)]

    def drivers(self, buffer_sources, period: int) -> dict[tuple[int, int, int], list[BusWrite]]:
        """Per (tier, bus, counter): the writes driving that bus then (one, unless they collide)."""
        out: dict[tuple[int, int, int], list[BusWrite]] = {}
        for w in self.writes:
            bus = self.tiers[w.tier].bus_at(self.writer_position(w.source, buffer_sources))
            out.setdefault((w.tier, bus, w.counter % period), []).append(w)
        return out


class Checking(Struct, frozen=True, gc=False):
    """Limited automatic error correction (section VII; vampc.emulator.checking): the VAMPs in a
    chain of successors after one extraneous VAMP (index V, after the network's), each holding a
    second slot table matching its successor's and wired to its successor's operand inputs and
    Result; `warmup`: the Cycle-Counter periods a VAMP computes a role it has just taken before its
    results are compared or driven; `compare`: the periods a checker then compares them."""

    chain: tuple[int, ...]
    warmup: int
    compare: int = 1

    @property
    def order(self) -> tuple[int, ...]:
        """Physical VAMPs in chain order: the extraneous one first."""
        return (len(self.chain),) + self.chain


@dataclass(frozen=True, slots=True)
class Network:
    """A VAMP network for one graph, schedule and layout (see the module docstring)."""

    period: int        # P: ticks between successive torque sets
    clock: int         # B: the buffer clock, in ticks (divides P)
    vamps: tuple[Vamp, ...]
    buffers: tuple[Buffer, ...]
    ports: tuple[Port, ...]
    consts: tuple[Const, ...]
    outputs: tuple[OutputPoint, ...]
    bus: Bus | None = None    # the Mostly-Local Bus, when operands travel on it (TapKind.BUS taps)
    checking: Checking | None = None   # limited automatic error correction (--error-correction)

    @property
    def buffer_stages(self) -> int:
        """Total delay-buffer stages (each holds one vector for one block)."""
        return sum(b.stages for b in self.buffers)

    @property
    def latency(self) -> int:
        """Ticks from the first input write of a set to the last of its torques being readable."""
        return max(o.tick for o in self.outputs)

    @property
    def slot_count(self) -> int:
        """Slots over all VAMPs (ops run per period)."""
        return sum(len(v.slots) for v in self.vamps)

    def has_slots(self, count: int) -> bool:
        """Whether the network has at least `count` slots: without counting them when it has that
        many VAMPs (each runs one at least; counting a million VAMPs' slots took 0.24 s)."""
        return len(self.vamps) >= count or self.slot_count >= count

    @property
    def blocks(self) -> int:
        """Buffer-clock blocks per period."""
        return self.period // self.clock

    def verify(self, graph, sched, path: str = "<network>") -> None:
        """Every slot's operands show its graph node's operands at its latch ticks, by the rules of
        vampc.machine.timing; slots of a VAMP never overlap (VampcInternalError otherwise, naming
        the VAMP, the slot, the tick and the operand). `graph`, `sched`: what it was allocated from;
        `path`: the file it was read from, which a bus without a writer is said of."""
        from vampc.network.verify import verify_network
        # (a programmed network's slots, ProgrammedSlot, are refused by verify_network in its first
        # walk over the VAMPs: a walk of their own over a million slots took 0.13 s)
        if self.bus is not None:          # the bus network checked as the wires it implements
            from vampc.network.bus import resolved
            verify_network(resolved(self, path), graph, sched)
            return
        verify_network(self, graph, sched)
