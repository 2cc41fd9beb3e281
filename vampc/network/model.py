"""The network IR: VAMPs, delay buffers, host ports and constant buffers, wired by taps (DESIGN §6–7).

Timing model (1 tick = 1 flop; the basic cycle is C ticks; tick t belongs to cycle t // C and has
Cycle-Counter t % C). All absolute ticks below are for torque set 0; set j happens j·C ticks later.

- A VAMP latches operand A at the tick whose counter is delay-A, operand B at delay-B, runs its
  micro-steps in the ticks ending with the one whose counter is delay-R, and drives its Result from the
  next tick: the Result holds for exactly C ticks (until the next dump).
- A delay buffer is a chain of passive stages clocked at cycle boundaries: stage s holds its source's
  value during the whole cycle (e // C) + s, where e is the tick the source's value appeared.
- A host port holds the value the host wrote at the start of its cycle for that whole cycle.
- A constant buffer always holds its value.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from vampc.dataflow.graph import InputKey
from vampc.dataflow.ops import Op


@dataclass(frozen=True, slots=True)
class Tap:
    """Where an operand is read: a VAMP's Result, stage `stage` of a buffer, a host port or a constant."""

    kind: str       # "vamp" | "buffer" | "port" | "const"
    index: int
    stage: int = 0  # buffers only, 1-based

    def __str__(self) -> str:
        return f"{self.kind} {self.index}" + (f" stage {self.stage}" if self.kind == "buffer" else "")


def window(tap: Tap, cycle: int, emit: float = 0, port_cycle: int = 0) -> tuple[float, float]:
    """[first, end) ticks in which `tap` shows set 0's value, by the rules above: `emit` is the first
    tick of the source VAMP's value (vamp and buffer taps; infinite for a constant-valued VAMP),
    `port_cycle` the cycle a port is written in. The compiler and the emulator both use this."""
    if tap.kind == "const" or math.isinf(emit):
        return (-math.inf, math.inf)
    if tap.kind == "port":
        return (port_cycle * cycle, port_cycle * cycle + cycle)
    if tap.kind == "vamp":
        return (emit, emit + cycle)
    start = (emit // cycle + tap.stage) * cycle
    return (start, start + cycle)


@dataclass(frozen=True, slots=True)
class Operand:
    """One operand: one tap, or three taps carrying the columns of a matrix made by an MM group."""

    taps: tuple[Tap, ...]


@dataclass(frozen=True, slots=True)
class Vamp:
    """One VAMP bound to graph node `node` (an MM node has three VAMPs, `column` 0..2)."""

    index: int
    node: int
    op: Op
    column: int | None
    a: Operand
    b: Operand
    latch_a: int   # absolute tick at which operand A is latched
    latch_b: int
    dump: int      # absolute tick at the end of which the result is driven

    @property
    def emit(self) -> int:
        """First tick at which the Result shows this VAMP's value (for set 0)."""
        return self.dump + 1


@dataclass(frozen=True, slots=True)
class Buffer:
    """A delay buffer of `stages` stages behind VAMP `source`."""

    index: int
    source: int
    stages: int


@dataclass(frozen=True, slots=True)
class Port:
    """A host input port: the host writes `key` of set j at the start of cycle j + `cycle`."""

    index: int
    key: InputKey
    cycle: int
    size: int   # scalars: 3 or 9


@dataclass(frozen=True, slots=True)
class Const:
    """A constant input buffer (p*, r*, m, J, endpoint values, ...)."""

    index: int
    name: str
    value: tuple[float, ...]


@dataclass(frozen=True, slots=True)
class OutputPoint:
    """τ_joint of set j is scalar `component` of VAMP `vamp`'s Result at tick j·C + `tick`."""

    joint: int
    vamp: int
    component: int
    tick: int


@dataclass(frozen=True, slots=True)
class Network:
    """A systolic VAMP network for one graph and schedule."""

    cycle: int
    vamps: tuple[Vamp, ...]
    buffers: tuple[Buffer, ...]
    ports: tuple[Port, ...]
    consts: tuple[Const, ...]
    outputs: tuple[OutputPoint, ...]

    @property
    def buffer_stages(self) -> int:
        """Total delay-buffer stages (each holds one vector for one cycle)."""
        return sum(b.stages for b in self.buffers)

    @property
    def latency(self) -> int:
        """Ticks from the first input write of a set to the last of its torques being readable."""
        return max(o.tick for o in self.outputs)
