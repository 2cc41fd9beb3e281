"""The VAMP op table: every op defined once, as data (README, *Extending vampc*; the
paper's Tables III.1, V.1, VII.1).

A VAMP is three primitive modules, one per result component; module m (0-based) has two multipliers,
one adder/subtractor and operand registers OP-A-1..3 / OP-B-1..3. An op's entry says

- `operands`, `views`: the shape of operands A and B ("v" a 3-vector, "m" a 3x3 matrix, row-major)
  and which three of an operand's nine scalars each module's registers hold (`View`);
- `steps`: its micro-steps, each a set of unit assignments ``unit ⇐ fn(x, y)`` made together (every
  assignment of a step reads the registers as they were when the step began); x and y are operand
  registers (`A(i)`, `B(i)`, rotated by the module number with `rot=True`) or unit registers;
- `result`: the unit whose register is driven onto Result;
- `columns`: VAMPs per op — an op of three columns (MM) runs on three VAMPs, VAMP k computing column
  k of the result with `View.BCOLUMN` selecting column k of operand B;
- `serial`: the serial work (multiplications, additions) the paper's counts charge it with;
- `colour`, `report_rank`: how the report's tables and timing chart show it.

Everything else follows from the entries: the micro-step units and so every duration (`Timing`), the
ROM (one pointer per op column), the tick engine's and the stream engine's numpy interpreter
(vampc.machine.interp), the stream engine's generated C (vampc.emulator.native), the graph evaluator
(vampc.dataflow.evaluate), the RTL's microcode (vampc.rtl.design), the allocator's and schedulers'
VAMP counts, the report's op columns and colours and the op names a program file is read with (its
schema says only that an op is a name). Arithmetic goes through vampc.machine.arith.

    op   result                       steps (Table VII.1)                        VAMPs  serial work
    VA   A + B                        1: ADD ⇐ A_m + B_m                          1      3 A
    SV   A[0] * B   (scalar in A[0])  1: M1 ⇐ A_1 · B_m                           1      3 M
    VC   A × B                        1: M1 ⇐ A_i·B_j, M2 ⇐ A_j·B_i; 2: ADD ⇐ M1−M2  1      6 M + 3 A
    MV   A @ B      (A a matrix)      dot: 1: M1 ⇐ A_3·B_3, M2 ⇐ A_2·B_2           1      9 M + 6 A
    MTV  Aᵀ @ B     (A a matrix)           2: ADD ⇐ M1 + M2, M1 ⇐ A_1·B_1         1      9 M + 6 A
    MM   A @ B      (both matrices)        3: ADD ⇐ M1 + ADD                        3      27 M + 18 A
    VD   [A·B, A·B, A·B]                                                           1      3 M + 2 A

(i, j = m+1, m+2 mod 3. Table VII.1 prints "result in multiplier-1" under the dot sequence, but its
third step leaves the sum in the adder; we take the adder. No fused multiply-add: each product is
rounded before it is added.)

Non-compute nodes: INPUT (a value the host writes every cycle, e.g. A_i or z q̇_i) and CONST (a value
sitting in a constant input buffer, e.g. p*_i or m_i).

New ops are added with `register` (or, for a test, the `registered` context manager): the ROM grows by
one pointer per column and every engine runs the op from its entry (tests/test_machine_ops.py adds
one and runs it on every engine).
"""
from __future__ import annotations

import contextlib
import enum
import functools
import math
from dataclasses import dataclass

from vampc.machine.arith import Fn


class _OpType(type):
    """Iterating `Op` gives every op, in registration order (like an Enum's members)."""

    def __iter__(cls):
        return iter(tuple(cls._all.values()))

    def __len__(cls):
        return len(cls._all)


class Op(metaclass=_OpType):
    """A node kind of the dataflow graph. `Op("VA")` is the op named VA (ValueError if none is);
    ops are singletons compared by identity. The compute ops are those with an `OpDef` in the table."""

    __slots__ = ("value", "is_compute")
    _all: dict[str, "Op"] = {}

    VA: "Op"
    SV: "Op"
    VC: "Op"
    MV: "Op"
    MTV: "Op"
    MM: "Op"
    VD: "Op"
    INPUT: "Op"
    CONST: "Op"

    def __new__(cls, value: str) -> "Op":
        try:
            return cls._all[value]
        except (KeyError, TypeError):
            raise ValueError(f"{value!r} is not an op") from None

    @classmethod
    def _make(cls, value: str, is_compute: bool) -> "Op":
        op = object.__new__(cls)
        op.value, op.is_compute = value, is_compute
        cls._all[value] = op
        if value.isidentifier() and value.isupper():
            setattr(cls, value, op)
        return op

    @property
    def name(self) -> str:
        """The op's name (its value), as an Enum member would have it."""
        return self.value

    def __repr__(self) -> str:
        return f"Op.{self.value}"

    def __reduce__(self):
        return (Op, (self.value,))


class View(enum.Enum):
    """Which scalars of a 9-scalar operand module m's three registers hold (col: an op column)."""

    VECTOR = "vector"        # scalars 0, 1, 2 (the same in every module)
    ROW = "row"              # row m of a matrix: 3m, 3m+1, 3m+2
    COLUMN = "column"        # column m of a matrix: m, 3+m, 6+m
    BCOLUMN = "bcolumn"      # column `col` of a matrix (the op's column): col, 3+col, 6+col

    def scalars(self, m: int, col: int) -> tuple[int, int, int]:
        """The operand scalars module m's registers 1..3 hold."""
        if self is View.VECTOR:
            return (0, 1, 2)
        if self is View.ROW:
            return (3 * m, 3 * m + 1, 3 * m + 2)
        if self is View.COLUMN:
            return (m, 3 + m, 6 + m)
        return (col, 3 + col, 6 + col)


MULT1, MULT2, ADDER = 0, 1, 2          # a module's unit registers
UNIT_NAMES = ("MULT-1", "MULT-2", "ADDER")
# what a primitive module computes with (section VII): two multipliers and one adder/subtractor,
# shared by every op; a micro-step uses at most these (OpDef.verify; the RTL builds them)
MULTIPLIERS, ADDERS = 2, 1


@dataclass(frozen=True)
class Ref:
    """A register a micro-step reads: "a" / "b" an operand register of the module (index
    (i + m) mod 3 when `rot`, else i), "u" a unit register (MULT1, MULT2, ADDER)."""

    kind: str
    i: int
    rot: bool = False

    def index(self, m: int) -> int:
        """The register index in module m."""
        return (self.i + m) % 3 if self.rot else self.i


def A(i: int, rot: bool = False) -> Ref:
    """Operand register A_i (A_{i+m} with rot)."""
    return Ref("a", i, rot)


def B(i: int, rot: bool = False) -> Ref:
    """Operand register B_i (B_{i+m} with rot)."""
    return Ref("b", i, rot)


def U(unit: int) -> Ref:
    """A unit register: MULT1, MULT2 or ADDER."""
    return Ref("u", unit)


@dataclass(frozen=True)
class Assign:
    """One assignment of a micro-step: unit register `unit` ⇐ fn(x, y)."""

    unit: int
    fn: Fn
    x: Ref
    y: Ref


def mul(unit: int, x: Ref, y: Ref) -> Assign:
    """unit ⇐ x · y"""
    return Assign(unit, Fn.MUL, x, y)


def add(unit: int, x: Ref, y: Ref) -> Assign:
    """unit ⇐ x + y"""
    return Assign(unit, Fn.ADD, x, y)


def sub(unit: int, x: Ref, y: Ref) -> Assign:
    """unit ⇐ x − y"""
    return Assign(unit, Fn.SUB, x, y)


@dataclass(frozen=True)
class OpDef:
    """One op of the table; see the module docstring."""

    name: str
    meaning: str
    operands: tuple[str, str]
    views: tuple[View, View]
    steps: tuple[tuple[Assign, ...], ...]
    result: int
    serial: tuple[int, int]
    columns: int = 1
    colour: str = "#dddddd"
    report_rank: float = math.inf
    rom: int | None = None           # the first ROM pointer (None: the next free one)
    # how the result's norm bounds by the operands' (vampc.precision): ("sum", 1) |A| + |B|, or
    # ("product", g) g |A| |B| (a matrix's norm its spectral norm); None: no bound known
    norm: tuple[str, float] | None = None

    @property
    def op(self) -> Op:
        """The graph node kind."""
        return Op(self.name)

    @property
    def result_shape(self) -> str:
        """"m" for an op whose columns make a matrix, else "v"."""
        return "m" if self.columns == 3 else "v"

    @property
    def units(self) -> tuple[frozenset, ...]:
        """The kinds of unit ("M", "A") each micro-step runs."""
        return tuple(frozenset(a.fn.unit for a in step) for step in self.steps)

    @property
    def operand_steps(self) -> int:
        """How many leading micro-steps read the operand registers (the rest work on unit
        registers only, so an operand may be re-latched while they run)."""
        reads = [k for k, step in enumerate(self.steps)
                 if any(r.kind in "ab" for a in step for r in (a.x, a.y))]
        return reads[-1] + 1 if reads else 0

    def verify(self) -> None:
        """Reject an entry no engine can run (ValueError)."""
        where = f"op {self.name}"
        if not self.steps or not all(self.steps):
            raise ValueError(f"{where}: every op needs at least one micro-step, each assigning")
        if self.columns not in (1, 3):
            raise ValueError(f"{where}: columns must be 1 or 3")
        if any(s not in ("v", "m") for s in self.operands):
            raise ValueError(f"{where}: operand shapes are 'v' or 'm'")
        for shape, view in zip(self.operands, self.views):
            if shape == "v" and view is not View.VECTOR:
                raise ValueError(f"{where}: a vector operand is read as View.VECTOR")
        written: set[int] = set()
        for k, step in enumerate(self.steps):
            targets = [a.unit for a in step]
            if len(set(targets)) != len(targets) or not set(targets) <= {MULT1, MULT2, ADDER}:
                raise ValueError(f"{where}: step {k + 1} assigns a unit twice or no unit")
            kinds = [a.fn.unit for a in step]
            if kinds.count("M") > MULTIPLIERS or kinds.count("A") > ADDERS:
                # (the RTL alone refused such a step; the emulators ran it: a new developer's find)
                raise ValueError(f"{where}: step {k + 1} needs {kinds.count('M')} multipliers and "
                                 f"{kinds.count('A')} adders, where a module has {MULTIPLIERS} and "
                                 f"{ADDERS}")
            for a in step:
                for r in (a.x, a.y):
                    if r.kind not in ("a", "b", "u") or not 0 <= r.i < 3:
                        raise ValueError(f"{where}: step {k + 1} reads no register ({r})")
                    if r.kind == "u" and r.i not in written:
                        raise ValueError(f"{where}: step {k + 1} reads {UNIT_NAMES[r.i]} before "
                                         "any step wrote it")
            written |= set(targets)
        if self.result not in [a.unit for a in self.steps[-1]]:
            raise ValueError(f"{where}: the result unit is not written by the last step")


_M1, _M2, _AD = U(MULT1), U(MULT2), U(ADDER)
_DOT = ((mul(MULT1, A(2), B(2)), mul(MULT2, A(1), B(1))),
        (add(ADDER, _M1, _M2), mul(MULT1, A(0), B(0))),
        (add(ADDER, _M1, _AD),))
_VEC = (View.VECTOR, View.VECTOR)

# The built-in ops, in the order the timing chart's key lists them; `rom` keeps the ROM pointers of
# program format v2 (VA 0, SV 1, VC 2, MV 3, MTV 4, VD 5, MM columns 6-8).
BUILTIN = (
    OpDef("VA", "A + B", ("v", "v"), _VEC, ((add(ADDER, A(0, True), B(0, True)),),), ADDER, (0, 3),
          colour="#9ecae1", report_rank=2, rom=0, norm=("sum", 1.0)),
    OpDef("SV", "A[0] · B (scalar in A's first scalar)", ("v", "v"), _VEC,
          ((mul(MULT1, A(0), B(0, True)),),), MULT1, (3, 0), colour="#c6dbef", report_rank=4, rom=1,
          norm=("product", 1.0)),
    OpDef("VC", "A × B", ("v", "v"), _VEC,
          ((mul(MULT1, A(1, True), B(2, True)), mul(MULT2, A(2, True), B(1, True))),
           (sub(ADDER, _M1, _M2),)), ADDER, (6, 3), colour="#a1d99b", report_rank=3, rom=2,
          norm=("product", 1.0)),
    OpDef("MV", "A @ B (A a matrix)", ("m", "v"), (View.ROW, View.VECTOR), _DOT, ADDER, (9, 6),
          colour="#fdae6b", report_rank=0, rom=3, norm=("product", 1.0)),
    OpDef("MTV", "Aᵀ @ B (A a matrix)", ("m", "v"), (View.COLUMN, View.VECTOR), _DOT, ADDER, (9, 6),
          colour="#fdd0a2", report_rank=1, rom=4, norm=("product", 1.0)),
    OpDef("MM", "A @ B (both matrices)", ("m", "m"), (View.ROW, View.BCOLUMN), _DOT, ADDER, (27, 18),
          columns=3, colour="#bcbddc", report_rank=5, rom=6, norm=("product", 1.0)),
    OpDef("VD", "[A·B, A·B, A·B]", ("v", "v"), _VEC, _DOT, ADDER, (3, 2), colour="#fcbba1",
          report_rank=6, rom=5, norm=("product", math.sqrt(3))),
)

# --- the registry and the tables derived from it (updated in place: modules import them) --------

TABLE: dict[Op, OpDef] = {}
ROM: list[tuple[Op, int | None]] = []     # pointer -> (op, its column for a 3-column op, else None)
MICRO_STEPS: dict[Op, tuple[frozenset, ...]] = {}
SERIAL_WORK: dict[Op, tuple[int, int]] = {}
VAMPS_PER_OP: dict[Op, int] = {}
OPERAND_SHAPES: dict[Op, tuple[str, str]] = {}
_POINTER: dict[tuple[Op, int | None], int] = {}
_rom_of: dict[int, tuple[Op, int | None]] = {}
_listeners: list = []


def register(entry: OpDef) -> Op:
    """Add an op to the table (ValueError if its name or ROM pointers are taken, or the entry is
    malformed); every engine, the timing model and the report take it from here on."""
    entry.verify()
    if entry.name in Op._all and Op(entry.name) in TABLE or entry.name in ("INPUT", "CONST"):
        raise ValueError(f"op {entry.name} is already defined")
    first = len(_rom_of) if entry.rom is None else entry.rom
    if first != len(_rom_of):
        raise ValueError(f"op {entry.name}: ROM pointer {first} is not the next free one, "
                         f"{len(_rom_of)}")
    pointers = range(first, first + entry.columns)
    op = Op._all.get(entry.name) or Op._make(entry.name, True)
    TABLE[op] = entry
    for k, p in enumerate(pointers):
        _rom_of[p] = (op, k if entry.columns > 1 else None)
    _derive()
    return op


def unregister(op: Op) -> None:
    """Remove an op registered with `register` (tests; the built-in ops stay)."""
    if op not in TABLE or TABLE[op] in BUILTIN:
        raise ValueError(f"op {op.value} is not a registered extra op")
    if max(p for p, (o, _) in _rom_of.items() if o is op) != len(_rom_of) - 1:
        raise ValueError(f"op {op.value}: unregister the ops registered after it first")
    del TABLE[op]
    for p in [p for p, (o, _) in _rom_of.items() if o is op]:
        del _rom_of[p]
    del Op._all[op.value]
    if getattr(Op, op.value, None) is op:
        delattr(Op, op.value)
    _derive()


@contextlib.contextmanager
def registered(entry: OpDef):
    """`register(entry)` for the duration of a with block (tests)."""
    op = register(entry)
    try:
        yield op
    finally:
        unregister(op)


def on_change(callback) -> None:
    """Call `callback()` whenever the table changes (caches of derived data clear themselves)."""
    _listeners.append(callback)


def _derive() -> None:
    if sorted(_rom_of) != list(range(len(_rom_of))):     # an explicit `rom` left a gap
        holes = sorted(set(range(max(_rom_of) + 1)) - set(_rom_of))
        raise ValueError(f"the ROM has no entry at pointers {holes}")
    ROM[:] = [_rom_of[p] for p in sorted(_rom_of)]
    _POINTER.clear()
    _POINTER.update({entry: p for p, entry in enumerate(ROM)})
    for table, fn in ((MICRO_STEPS, lambda e: e.units), (SERIAL_WORK, lambda e: e.serial),
                      (VAMPS_PER_OP, lambda e: e.columns), (OPERAND_SHAPES, lambda e: e.operands)):
        table.clear()
        table.update({op: fn(e) for op, e in TABLE.items()})
    _durations.cache_clear()
    for callback in _listeners:
        callback()


def rom_pointer(op: Op, column: int | None) -> int:
    """The ROM pointer of an op (a member of a 3-column op names the column it computes)."""
    return _POINTER[(op, column if TABLE[op].columns > 1 else None)]


def entry(rom: int) -> tuple[OpDef, int]:
    """The op entry and column (0 for a one-column op) a ROM pointer runs."""
    op, col = ROM[rom]
    return TABLE[op], col or 0


def result_shape(op: Op) -> str:
    """Shape of the value a compute op produces."""
    return TABLE[op].result_shape


def compute_ops() -> tuple[Op, ...]:
    """Every compute op, in table order."""
    return tuple(TABLE)


def report_kinds() -> tuple[str, ...]:
    """The op names the report's per-op columns show, in their order."""
    return tuple(e.name for e in sorted(TABLE.values(), key=lambda e: e.report_rank))


def colours() -> dict[str, str]:
    """Each op's colour in the timing chart, in table order."""
    return {e.name: e.colour for e in TABLE.values()}


# --- timing: durations follow from the micro-steps ----------------------------------------------

@dataclass(frozen=True)
class Timing:
    """Latencies of one multiplication and one addition, in flops (ticks)."""

    mult: int = 1
    add: int = 1

    def flops(self, mults: int, adds: int) -> int:
        """The flops of `mults` Mults and `adds` Addns at these latencies (the one weighting every
        figure of Mults and Addns uses: the paper's formulas, Table O.1's rows, a path's counts)."""
        return mults * self.mult + adds * self.add

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

    def step_ends(self, rom: int) -> tuple[int, ...]:
        """When each micro-step of ROM entry `rom` completes, in ticks from the op's first tick
        (1-based): a step lasts as long as its slowest unit, and its registers take their new values
        at the end of its last tick. With 1 Mult = 1 Addn = 1 tick: 1, 2, 3."""
        return _step_ends(self, rom)

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


@functools.lru_cache(maxsize=None)
def _step_ends(timing: Timing, rom: int) -> tuple[int, ...]:
    out, t = [], 0
    for units in MICRO_STEPS[ROM[rom][0]]:
        t += timing.step(units)
        out.append(t)
    return tuple(out)


on_change(_step_ends.cache_clear)


def _first_pointers(entries) -> list[int]:
    """Each entry's first ROM pointer: its `rom`, or where that is None the next free one after
    every pointer given, in the entries' order (a built-in entry without `rom` had failed the
    import: a new developer's find)."""
    following = max((e.rom + e.columns for e in entries if e.rom is not None), default=0)
    out = []
    for e in entries:
        out.append(following if e.rom is None else e.rom)
        following += e.columns if e.rom is None else 0
    return out


for _e in BUILTIN:
    Op._make(_e.name, True)
Op._make("INPUT", False)
Op._make("CONST", False)
for _e, _first in zip(BUILTIN, _first_pointers(BUILTIN)):
    _e.verify()
    TABLE[_e.op] = _e
    for _k in range(_e.columns):
        _rom_of[_first + _k] = (_e.op, _k if _e.columns > 1 else None)
_derive()
