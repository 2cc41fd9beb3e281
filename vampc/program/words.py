"""Program words: the one place where VAMP programs are packed and unpacked (DESIGN §7).

A VAMP's program is four small integers: delay-A, delay-B, delay-R (Cycle-Counter values at which
operand A is latched, operand B is latched, and the Result is driven) and a ROM pointer (which
micro-sequence of Table VII.1 runs). In Program Mode a word travels as one 3-scalar vector:

    scalar 1   VAMP-number (burned in; positive integer)
    scalar 2   delay-A · 4096 + delay-B
    scalar 3   delay-R · 4096 + ROM-pointer

Every field is a non-negative integer below 4096, so the scalars are integers below 2^24, exact in any
IEEE binary32 or binary64 word.
"""
from __future__ import annotations

from dataclasses import dataclass

from vampc.dataflow.ops import Op
from vampc.errors import VampcError

FIELD = 4096

# ROM contents: pointer -> (op, column of operand B used by an MM member, or None).
ROM: tuple[tuple[Op, int | None], ...] = (
    (Op.VA, None), (Op.SV, None), (Op.VC, None), (Op.MV, None), (Op.MTV, None), (Op.VD, None),
    (Op.MM, 0), (Op.MM, 1), (Op.MM, 2),
)


_POINTER = {entry: pointer for pointer, entry in enumerate(ROM)}


def rom_pointer(op: Op, column: int | None) -> int:
    """The ROM pointer of an op (an MM member names the column of B it multiplies)."""
    return _POINTER[(op, column if op is Op.MM else None)]


@dataclass(frozen=True, slots=True)
class Program:
    """A VAMP's four control registers."""

    delay_a: int
    delay_b: int
    delay_r: int
    rom: int


def encode(number: int, prog: Program) -> tuple[float, float, float]:
    """The Program-Mode word carrying `prog` for VAMP `number`."""
    if not (0 <= prog.delay_a < FIELD and 0 <= prog.delay_b < FIELD and 0 <= prog.delay_r < FIELD
            and 0 <= prog.rom < FIELD):
        name = next(k for k in ("delay_a", "delay_b", "delay_r", "rom")
                    if not 0 <= getattr(prog, k) < FIELD)
        raise VampcError(f"VAMP {number}: {name} {getattr(prog, name)} does not fit in a word")
    return (float(number), float(prog.delay_a * FIELD + prog.delay_b),
            float(prog.delay_r * FIELD + prog.rom))


def decode(word) -> tuple[int, Program]:
    """(VAMP-number, program) from a word; inverse of encode."""
    number, s2, s3 = (int(x) for x in word[:3])
    return number, Program(s2 // FIELD, s2 % FIELD, s3 // FIELD, s3 % FIELD)
