"""The VAMP operation repertoire (DESIGN §4, Tables III.1, V.1, VII.1) and its costs.

Every compute node of a dataflow graph is one of these ops. Operand A comes first, operand B second;
a vector is 3 scalars, a matrix 9 (row-major).

    op   result                       time (micro-steps)        VAMPs  serial work
    VA   A + B                        1 Addn                     1      3 A
    SV   A[0] * B   (scalar in A[0])  1 Mult                     1      3 M
    VC   A × B                        1 Mult + 1 Addn            1      6 M + 3 A
    MV   A @ B      (A a matrix)      1 Mult + 2 Addns           1      9 M + 6 A
    MTV  Aᵀ @ B     (A a matrix)      1 Mult + 2 Addns           1      9 M + 6 A
    MM   A @ B      (both matrices)   1 Mult + 2 Addns           3      27 M + 18 A
    VD   [A·B, A·B, A·B]              1 Mult + 2 Addns           1      3 M + 2 A

Non-compute nodes: INPUT (a value the host writes every cycle, e.g. A_i or z q̇_i) and CONST (a value
sitting in a constant input buffer, e.g. p*_i or m_i).

The micro-step shape of each op (which unit works in each step) is what both the scheduler's durations
and the emulator's ROM follow: MV's second step runs a multiplier and the adder in parallel, so with
separate Mult and Addn latencies a step lasts as long as its slowest unit.
"""
from __future__ import annotations

import enum
import functools
from dataclasses import dataclass


class Op(enum.Enum):
    """Node kinds of the dataflow graph; see the module docstring for the contract table."""

    VA = "VA"
    SV = "SV"
    VC = "VC"
    MV = "MV"
    MTV = "MTV"
    MM = "MM"
    VD = "VD"
    INPUT = "INPUT"
    CONST = "CONST"

    # Members are singletons compared by identity, so identity hashing agrees with equality, and it
    # is C-speed: Enum's own __hash__ is Python code, and the back end looks ops up millions of times.
    __hash__ = object.__hash__

    def __init__(self, value: str):
        # A plain attribute, not a property: the back end asks this once per node and operand.
        self.is_compute = value not in ("INPUT", "CONST")   # True for ops a VAMP executes


# Units active in each micro-step (Table VII.1): "M" a multiplier, "A" the adder/subtractor.
MICRO_STEPS: dict[Op, tuple[frozenset, ...]] = {
    Op.VA: (frozenset("A"),),
    Op.SV: (frozenset("M"),),
    Op.VC: (frozenset("M"), frozenset("A")),
    Op.MV: (frozenset("M"), frozenset("AM"), frozenset("A")),
    Op.MTV: (frozenset("M"), frozenset("AM"), frozenset("A")),
    Op.MM: (frozenset("M"), frozenset("AM"), frozenset("A")),
    Op.VD: (frozenset("M"), frozenset("AM"), frozenset("A")),
}

# Serial scalar work of one op (multiplications, additions).
SERIAL_WORK: dict[Op, tuple[int, int]] = {
    Op.VA: (0, 3), Op.SV: (3, 0), Op.VC: (6, 3), Op.MV: (9, 6), Op.MTV: (9, 6),
    Op.MM: (27, 18), Op.VD: (3, 2),
}

VAMPS_PER_OP: dict[Op, int] = {op: (3 if op is Op.MM else 1) for op in MICRO_STEPS}

# Operand shapes: "v" a 3-vector, "m" a 3x3 matrix.
OPERAND_SHAPES: dict[Op, tuple[str, str]] = {
    Op.VA: ("v", "v"), Op.SV: ("v", "v"), Op.VC: ("v", "v"), Op.MV: ("m", "v"),
    Op.MTV: ("m", "v"), Op.MM: ("m", "m"), Op.VD: ("v", "v"),
}


def result_shape(op: Op) -> str:
    """Shape of the value a compute op produces."""
    return "m" if op is Op.MM else "v"


@dataclass(frozen=True)
class Timing:
    """Latencies of one multiplication and one addition, in flops (ticks)."""

    mult: int = 1
    add: int = 1

    def step(self, units: frozenset) -> int:
        """Duration of one micro-step: its slowest active unit."""
        return max(self.mult if u == "M" else self.add for u in units)

    def duration(self, op: Op) -> int:
        """Flops from operands latched to result ready (0 for inputs and constants)."""
        return _durations(self)[op]

    @property
    def durations(self) -> dict[Op, int]:
        """Every op's duration (the cached table behind `duration`: a loop over a million nodes
        looks ops up in it directly rather than hashing this Timing each time). Do not modify."""
        return _durations(self)

    def path_counts(self, op: Op) -> tuple[int, int]:
        """(Mults, Addns) the op contributes to a critical path, in the paper's accounting: a step
        running a multiplier and the adder together counts as its slower unit (an Addn on a tie, so MV
        is 1 Mult + 2 Addns), which keeps mults·Mult + adds·Addn equal to the duration."""
        if not op.is_compute:
            return (0, 0)
        mults = adds = 0
        for units in MICRO_STEPS[op]:
            if "A" in units and (self.add >= self.mult or "M" not in units):
                adds += 1
            else:
                mults += 1
        return mults, adds

    def _duration(self, op: Op) -> int:
        if not op.is_compute:
            return 0
        return sum(self.step(s) for s in MICRO_STEPS[op])

    @property
    def cycle(self) -> int:
        """The systolic basic cycle C = MV + VA (4 flops with unit latencies)."""
        return self.duration(Op.MV) + self.duration(Op.VA)


@functools.lru_cache(maxsize=None)
def _durations(timing: Timing) -> dict[Op, int]:
    """Every op's duration under `timing` (looked up once per node by the scheduler: cache it)."""
    return {op: timing._duration(op) for op in Op}
