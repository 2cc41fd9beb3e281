"""The VAMP's micro-code ROM: Table VII.1's sequences on three primitive modules (one per result
component), each with two multipliers, one adder/subtractor and operand register pairs.

This is the one place where op semantics live; both emulator engines call it, so they agree bit for bit.
Arrays carry any leading batch shape (VAMPs in the tick engine, torque sets in the stream engine).

Module m (0-based) sees its operand registers OP-A-1..3 / OP-B-1..3 as follows (`module_registers`):

    VA, SV, VC, VD   both operands as latched (3 scalars each)
    MV               A: row m of the matrix      B: the vector
    MTV              A: column m of the matrix   B: the vector
    MM column k      A: row m of the matrix      B: column k of the second matrix

Micro-steps (every step of every module runs in the same tick; with 1 Mult = 1 Addn = 1 flop a step
takes one tick, otherwise as long as its slowest unit, and runs at the last of its ticks):

    VA   1: ADDER ⇐ A_m + B_m                                   result in the adder
    SV   1: MULT-1 ⇐ A_1 · B_m (scalar in A's first scalar)     result in multiplier 1
    VC   1: MULT-1 ⇐ A_i · B_j, MULT-2 ⇐ A_j · B_i   (i, j = m+1, m+2 mod 3)
         2: ADDER ⇐ MULT-1 − MULT-2                             result in the adder
    dot  1: MULT-1 ⇐ A_3 · B_3, MULT-2 ⇐ A_2 · B_2   (VD, MV, MTV, MM)
         2: ADDER ⇐ MULT-1 + MULT-2, MULT-1 ⇐ A_1 · B_1
         3: ADDER ⇐ MULT-1 + ADDER                              result in the adder

(Table VII.1 prints "result in multiplier-1" under the dot sequence, but its third step leaves the sum
in the adder; we take the adder.) No fused multiply-add: each product is rounded before it is added.
"""
from __future__ import annotations

import functools

import numpy as np

from vampc.dataflow.ops import MICRO_STEPS, Op, Timing
from vampc.program.words import ROM

_M = np.arange(3)
_I, _J = (_M + 1) % 3, (_M + 2) % 3
_DOT = (Op.VD, Op.MV, Op.MTV, Op.MM)


def steps(rom: int) -> int:
    """Number of micro-steps of a ROM entry."""
    return len(MICRO_STEPS[ROM[rom][0]])


@functools.lru_cache(maxsize=None)
def step_ends(rom: int, timing: Timing = Timing()) -> tuple[int, ...]:
    """When each micro-step completes, in ticks from the op's first tick (1-based): a step lasts as
    long as its slowest unit (Timing.step), and its registers take their new values at the end of
    its last tick, which is when the engines run it. With 1 Mult = 1 Addn = 1 tick: 1, 2, 3.
    Cached: the static checks ask once per slot of a network of a hundred thousand VAMPs."""
    out, t = [], 0
    for units in MICRO_STEPS[ROM[rom][0]]:
        t += timing.step(units)
        out.append(t)
    return tuple(out)


def duration(rom: int, timing: Timing = Timing()) -> int:
    """Ticks from an op's first tick to its dump (inclusive)."""
    return step_ends(rom, timing)[-1]


def reading_end(rom: int, timing: Timing = Timing()) -> int:
    """Ticks from the op's first tick to the end of its last step that reads the operand registers."""
    return step_ends(rom, timing)[operand_steps(rom) - 1]


def operand_steps(rom: int) -> int:
    """How many leading micro-steps read the operand registers (the rest work on unit registers
    only, so an operand may be re-latched while they run)."""
    op = ROM[rom][0]
    return 2 if op in _DOT else 1


def module_registers(rom: int, op_a: np.ndarray, op_b: np.ndarray):
    """Each module's operand registers: two arrays (..., 3 modules, 3 registers)."""
    op, col = ROM[rom]
    vec_a = np.repeat(op_a[..., None, 0:3], 3, axis=-2)
    vec_b = np.repeat(op_b[..., None, 0:3], 3, axis=-2)
    if op is Op.MV:
        return op_a[..., 0:9].reshape(op_a.shape[:-1] + (3, 3)), vec_b
    if op is Op.MTV:
        return np.swapaxes(op_a[..., 0:9].reshape(op_a.shape[:-1] + (3, 3)), -1, -2), vec_b
    if op is Op.MM:
        rows = op_a[..., 0:9].reshape(op_a.shape[:-1] + (3, 3))
        column = op_b[..., [col, 3 + col, 6 + col]]
        return rows, np.repeat(column[..., None, :], 3, axis=-2)
    return vec_a, vec_b


def step(rom: int, k: int, am: np.ndarray, bm: np.ndarray, units: np.ndarray) -> None:
    """Run micro-step k (0-based) of ROM entry `rom` in place on `units` (..., 3 registers, 3 modules):
    units[..., 0, m] is MULT-1 of module m, [..., 1, m] MULT-2, [..., 2, m] the adder."""
    op = ROM[rom][0]
    if op is Op.VA:
        units[..., 2, :] = am[..., _M, _M] + bm[..., _M, _M]
    elif op is Op.SV:
        units[..., 0, :] = am[..., _M, 0] * bm[..., _M, _M]
    elif op is Op.VC:
        _vc_step(k, am, bm, units)
    elif op in _DOT:
        _dot_step(k, am, bm, units)
    else:  # pragma: no cover - ROM and Op are defined together
        raise AssertionError(op)


def _vc_step(k: int, am, bm, units) -> None:
    if k == 0:
        units[..., 0, :] = am[..., _M, _I] * bm[..., _M, _J]
        units[..., 1, :] = am[..., _M, _J] * bm[..., _M, _I]
    else:
        units[..., 2, :] = units[..., 0, :] - units[..., 1, :]


def _dot_step(k: int, am, bm, units) -> None:
    if k == 0:
        units[..., 0, :] = am[..., _M, 2] * bm[..., _M, 2]
        units[..., 1, :] = am[..., _M, 1] * bm[..., _M, 1]
    elif k == 1:
        units[..., 2, :] = units[..., 0, :] + units[..., 1, :]
        units[..., 0, :] = am[..., _M, 0] * bm[..., _M, 0]
    else:
        units[..., 2, :] = units[..., 0, :] + units[..., 2, :]


def result_unit(rom: int) -> int:
    """Which unit register holds the result: 0 (multiplier 1) for SV, else 2 (the adder)."""
    return 0 if ROM[rom][0] is Op.SV else 2


def run(rom: int, op_a: np.ndarray, op_b: np.ndarray) -> np.ndarray:
    """The whole micro-sequence at once (the stream engine): the 3-scalar result, batch-shaped."""
    am, bm = module_registers(rom, op_a, op_b)
    units = np.zeros(op_a.shape[:-1] + (3, 3))
    for k in range(steps(rom)):
        step(rom, k, am, bm, units)
    return units[..., result_unit(rom), :]
