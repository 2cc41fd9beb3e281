"""The op table interpreted on numpy arrays: what the tick engine runs one micro-step at a time, and
what the stream engine and the graph evaluator run a whole op at a time (vampc.machine.ops has the
table; vampc.emulator.native renders the same table as C).

Arrays carry any leading batch shape (VAMPs in the tick engine, torque sets in the stream engine). An
operand is its nine scalars (a vector: three, the rest never read); module m's registers are the
scalars its op's `View` names, so `registers` returns two arrays (..., 3 modules, 3 registers). The
unit registers are one array (..., 3 units, 3 modules): units[..., 0, m] is MULT-1 of module m,
[..., 1, m] MULT-2, [..., 2, m] the adder.
"""
from __future__ import annotations

import functools

import numpy as np

from vampc.machine import ops
from vampc.machine.arith import FLOAT64
from vampc.machine.ops import ROM, TABLE, Timing

_M = np.arange(3)


@functools.lru_cache(maxsize=None)
def _views(rom: int):
    entry, col = ops.entry(rom)
    return tuple(np.array([view.scalars(m, col) for m in range(3)]) for view in entry.views)


@functools.lru_cache(maxsize=None)
def _program(rom: int):
    """Per micro-step: (unit, fn, x, y) with x, y as ("a"|"b", register index per module) or
    ("u", unit)."""
    entry, _ = ops.entry(rom)

    def ref(r):
        return (r.kind, r.i) if r.kind == "u" else (r.kind, np.array([r.index(m) for m in range(3)]))
    return tuple(tuple((a.unit, a.fn, ref(a.x), ref(a.y)) for a in step) for step in entry.steps)


@functools.lru_cache(maxsize=None)
def steps(rom: int) -> int:
    """Number of micro-steps of a ROM entry."""
    return len(TABLE[ROM[rom][0]].steps)


def step_ends(rom: int, timing: Timing = Timing()) -> tuple[int, ...]:
    """When each micro-step completes, in ticks from the op's first tick (Timing.step_ends)."""
    return timing.step_ends(rom)


def duration(rom: int, timing: Timing = Timing()) -> int:
    """Ticks from an op's first tick to its dump (inclusive)."""
    return timing.step_ends(rom)[-1]


def reading_end(rom: int, timing: Timing = Timing()) -> int:
    """Ticks from the op's first tick to the end of its last step that reads the operand registers."""
    return timing.step_ends(rom)[operand_steps(rom) - 1]


@functools.lru_cache(maxsize=None)
def operand_steps(rom: int) -> int:
    """How many leading micro-steps read the operand registers (OpDef.operand_steps; the tick
    engine asks this of every micro-step it runs, so it is worked out once per entry)."""
    return TABLE[ROM[rom][0]].operand_steps


@functools.lru_cache(maxsize=None)
def _direct(rom: int):
    """_program's micro-steps with each register reference as the operand scalar every module
    reads (its View's scalar of that register): ("a"|"b", 3 scalar indices) or ("u", unit)."""
    va, vb = _views(rom)
    views = {"a": va, "b": vb}

    def ref(r):
        kind, i = r
        return r if kind == "u" else (kind, views[kind][_M, i])
    return tuple(tuple((unit, fn, ref(x), ref(y)) for unit, fn, x, y in step) for step in _program(rom))


for _cached in (_views, _program, _direct, steps, operand_steps):     # (the op table can be changed)
    ops.on_change(_cached.cache_clear)


def result_unit(rom: int) -> int:
    """Which unit register holds the result."""
    return TABLE[ROM[rom][0]].result


def registers(rom: int, op_a: np.ndarray, op_b: np.ndarray, rows: np.ndarray | None = None):
    """Each module's operand registers: two arrays (..., 3 modules, 3 registers); with `rows`, of
    those rows of op_a and op_b (2-D) only, gathered at once (the tick engine's VAMPs)."""
    va, vb = _views(rom)
    if rows is None:
        return op_a[..., va], op_b[..., vb]
    r = rows[:, None, None]
    return op_a[r, va], op_b[r, vb]


def step(rom: int, k: int, am: np.ndarray, bm: np.ndarray, units: np.ndarray,
         arith=FLOAT64) -> None:
    """Run micro-step k (0-based) of ROM entry `rom` in place on `units`: every assignment of the
    step reads the registers as they were when it began, then all are written."""
    regs = {"a": am, "b": bm}
    new = []
    for unit, fn, x, y in _program(rom)[k]:
        new.append((unit, arith.apply(fn, _read(x, regs, units), _read(y, regs, units))))
    for unit, value in new:
        units[..., unit, :] = value


def step_rows(rom: int, k: int, op_a: np.ndarray, op_b: np.ndarray, rows: np.ndarray,
              units: np.ndarray, arith=FLOAT64) -> None:
    """step() on the VAMPs `rows` of op_a and op_b (2-D, 9 scalars a row), each register read
    straight from them (the tick engine's): the values step(rom, k, *registers(rom, op_a, op_b,
    rows), units, arith) reads, without gathering all nine of every module first."""
    r = rows[:, None]
    regs = {"a": op_a, "b": op_b}
    new = []
    for unit, fn, x, y in _direct(rom)[k]:
        xv = units[:, x[1], :] if x[0] == "u" else regs[x[0]][r, x[1]]
        yv = units[:, y[1], :] if y[0] == "u" else regs[y[0]][r, y[1]]
        new.append((unit, arith.apply(fn, xv, yv)))
    for unit, value in new:
        units[:, unit, :] = value


def _read(ref, regs, units):
    kind, i = ref
    if kind == "u":
        return units[..., i, :]
    return regs[kind][..., _M, i]


def run(rom: int, op_a: np.ndarray, op_b: np.ndarray, arith=FLOAT64,
        canonical: bool = True) -> np.ndarray:
    """The whole micro-sequence at once: the 3-scalar result, batch-shaped, as the Result register
    holds it (arith.result: a NaN is the canonical NaN). `canonical` off leaves a NaN as the
    arithmetic made it, for a caller that makes its outputs canonical instead (the stream engine:
    a NaN goes on being NaN through every later op, so its torques are the same bits)."""
    am, bm = registers(rom, op_a, op_b)
    units = np.zeros(op_a.shape[:-1] + (3, 3), dtype=arith.dtype)
    for k in range(steps(rom)):
        step(rom, k, am, bm, units, arith)
    out = units[..., result_unit(rom), :]
    return arith.result(out) if canonical else out


def apply(op: ops.Op, a: np.ndarray, b: np.ndarray, arith=FLOAT64,
          canonical: bool = True) -> np.ndarray:
    """A compute op on whole values, as the VAMPs compute it: `a`, `b` (..., 3) vectors or (..., 3, 3)
    matrices; the result (..., 3), or (..., 3, 3) for a 3-column op (column k from VAMP k).
    `canonical`: as `run`'s."""
    entry = TABLE[op]
    flat_a, flat_b = (x.reshape(x.shape[:-2] + (9,)) if shape == "m" else x
                      for x, shape in zip((a, b), entry.operands))
    if entry.columns == 1:
        return run(ops.rom_pointer(op, None), flat_a, flat_b, arith, canonical)
    return np.stack([run(ops.rom_pointer(op, k), flat_a, flat_b, arith, canonical)
                     for k in range(entry.columns)], axis=-1)
