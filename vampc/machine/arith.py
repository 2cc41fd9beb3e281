"""The arithmetic of a VAMP's units, behind one small interface (README, *Word formats*,
*Extending vampc*): the word formats.

Every engine does its arithmetic through a word format: the tick engine and the numpy stream engine
call `apply`, the stream engine's generated C renders `c_expr`, and later a Verilog generator renders
the same functions again. A format decides how a value is held (`dtype`), where a result is rounded
and what happens on overflow, so every engine rounds and saturates at the same points, bit for bit.
The host converts what it writes (A_i, constants, q̇, q̈) with `encode` and reads torques with
`decode`.

    format     held as                 mul x · y                     add x + y, sub x − y
    float64    IEEE binary64           one rounded product (never    one rounded sum or difference
                                       fused with a following add)
    float32    IEEE binary32           the same in binary32          the same in binary32
    qI.F       signed integers of      the exact product, shifted    exact, then the overflow rule
               W = I + F bits, value   right by F bits with the
               raw · 2^-F (I counts    rounding rule, then the
               the sign bit)           overflow rule

Fixed-point rules. Rounding `nearest` adds 2^(F-1) before the shift (ties go up, towards +inf);
`truncate` drops the bits (towards −inf, two's complement). Overflow `saturate` clips a result to
[−2^(W-1), 2^(W-1) − 1]; `wrap` keeps its low W bits (two's complement). Either way every overflow is
counted (`overflows`): it is never silent. The host's conversion rounds and overflows by the same
rules. A float format's overflow is a non-finite result, also counted.

What a VAMP's Result register holds of its result unit is `result`: the value, but a NaN is held
as the canonical quiet NaN (binary64 0x7FF8000000000000, binary32 0x7FC00000:
positive, payload zero), as RISC-V's F and D extensions and Arm's default-NaN mode make every NaN
result. IEEE 754 leaves the payload of a NaN result open, and numpy's loops give one operand's or
the other's depending on how the arrays lie in memory: a checker computing its successor's op on
the same two NaN operands held other bits than its successor, found a mismatch and excised a
healthy VAMP (a new user's find). A NaN result goes on being NaN through every later op, so
canonical Results make every NaN a line carries, a comparator sees or a torque holds the same bits
in every engine; inside a module the units' NaNs are left as the arithmetic makes them. The tick
engine holds every Result so where their bits are seen beyond the torques (a fault on a register,
the checking's comparators, a waveform), and otherwise, as the stream engines and the graph
evaluator do, makes the torques canonical at the end: the same bits (a check on every op or dump
had cost their runs 5-17%; generated C keeps its arithmetic as it was).
"""
from __future__ import annotations

import enum
import math
import re

import numpy as np


class Fn(enum.Enum):
    """An arithmetic function of a unit: what one micro-step assignment computes."""

    MUL = "mul"
    ADD = "add"
    SUB = "sub"

    @property
    def unit(self) -> str:
        """The kind of unit that computes it: "M" a multiplier, "A" the adder/subtractor."""
        return "M" if self is Fn.MUL else "A"


class Float64:
    """IEEE binary64 words: numpy's float64 in Python, `double` in C (compiled with
    -ffp-contract=off, so a product is rounded before it is added, as numpy rounds it)."""

    name = "float64"
    c_type = "double"
    dtype = np.float64
    bits = 64
    # `emulate --check`'s default tolerance (README, Word formats): of each set's largest |τ| in
    # float64, of the run's largest |τ| of any joint in a narrower word
    check_tolerance = 1e-9
    _C = {Fn.MUL: "*", Fn.ADD: "+", Fn.SUB: "-"}

    def __init__(self):
        self.overflows = 0
        self.track = None      # a list to collect, per overflowing call, each batch row's overflows

    def rounding_error(self, magnitude: float) -> float:
        """The most one rounding to this word moves a value of at most `magnitude` (vampc
        precision's bounds)."""
        return magnitude * 2.0 ** -53

    def apply(self, fn: Fn, x, y):
        """fn(x, y) on numpy arrays (any broadcastable shapes)."""
        if fn is Fn.MUL:
            return x * y
        if fn is Fn.ADD:
            return x + y
        return x - y

    def result(self, values):
        """What a Result register holds of its result unit's `values` (a fresh array, changed in
        place and returned): a NaN as the canonical quiet NaN (the module docstring)."""
        return canonical_nan(values)

    def c_expr(self, fn: Fn, x: str, y: str) -> str:
        """fn(x, y) as a C expression of two C expressions of type `c_type`."""
        return f"{x} {self._C[fn]} {y}"

    def c_prelude(self) -> str:
        """C definitions c_expr's expressions use (and the overflow counter `vamp_overflows`)."""
        return "long vamp_overflows;"

    def c_literal(self, value: float) -> str:
        """An exact C literal of the word encoding `value` (the host's conversion, encode)."""
        return f"({float(self.encode(value)).hex()})"

    def c_decode(self, x: str) -> str:
        """A C expression of the double a word `x` stands for (decode)."""
        return x

    def encode(self, values) -> np.ndarray:
        """Real values (float64) as words of this format."""
        return np.asarray(values, dtype=np.float64)

    def decode(self, words) -> np.ndarray:
        """Words of this format as float64 values."""
        return np.asarray(words, dtype=np.float64)

    def fresh(self):
        """The same format with its overflow count at zero (one per run)."""
        return type(self)()

    @property
    def program_bits(self) -> int:
        """Every integer below 2**program_bits in magnitude travels exactly in a Program-Mode word
        of this format (vampc.program.words.Packing): a float's significand, its dtype's (53 bits
        in float64, 24 in float32)."""
        return int(np.finfo(self.dtype).nmant) + 1

    def random(self, rng, shape, scale: float = 1.0) -> np.ndarray:
        """Words a register may hold at power-on (the tick engine's random start)."""
        return (rng.normal(size=shape) * scale).astype(self.dtype)

    def program_words(self, words) -> np.ndarray:
        """Program-Mode words (VAMP numbers and packed fields: integers) as this format carries
        them: as values in a float format, which must hold them exactly (ValueError otherwise)."""
        w = np.asarray(words, dtype=np.float64)
        out = w.astype(self.dtype)
        if not np.array_equal(out.astype(np.float64), w):
            bad = w.ravel()[np.argmax(out.astype(np.float64).ravel() != w.ravel())]
            raise ValueError(f"a Program-Mode word holds {bad:.0f}, which {self.name} does not "
                             "hold exactly")
        return out

    def __eq__(self, other) -> bool:
        return type(other) is type(self) and other.name == self.name

    def __hash__(self) -> int:
        return hash(self.name)

    def __repr__(self) -> str:
        return self.name


class Float32(Float64):
    """IEEE binary32 words: numpy's float32, `float` in C. A result too large for binary32 is an
    infinity: counted as an overflow."""

    name = "float32"
    c_type = "float"
    dtype = np.float32
    bits = 32
    check_tolerance = 1e-5

    def rounding_error(self, magnitude: float) -> float:
        return magnitude * 2.0 ** -24

    def apply(self, fn: Fn, x, y):
        with np.errstate(over="ignore", invalid="ignore"):
            out = super().apply(fn, x, y)
        bad = ~np.isfinite(out)
        if bad.any():
            self.overflows += int(np.count_nonzero(bad))
            _tracked(self, bad)
        return out

    def encode(self, values) -> np.ndarray:
        with np.errstate(over="ignore"):     # (its dtype's: a narrower float format inherits it)
            out = np.asarray(values, dtype=np.float64).astype(self.dtype)
        bad = ~np.isfinite(out)
        if bad.any():
            self.overflows += int(np.count_nonzero(bad))
            _tracked(self, bad)
        return out

    def c_expr(self, fn: Fn, x: str, y: str) -> str:
        return f"f_{fn.value}({x}, {y})"

    def c_prelude(self) -> str:
        ops = "".join(f"static inline float f_{fn.value}(float x, float y) {{ float r = x {op} y; "
                      "if (!isfinite(r)) vamp_overflows++; return r; }\n"
                      for fn, op in self._C.items())
        return "#include <math.h>\nlong vamp_overflows;\n" + ops

    def c_literal(self, value: float) -> str:
        x = float(self.fresh().encode(value))
        if not math.isfinite(x):      # (float.hex writes 'inf', which no C compiler reads: an
            #                            audit's float32 gravity of 1e39 failed in gcc)
            return "((float)NAN)" if x != x else f"({'-' if x < 0 else ''}(float)INFINITY)"
        return f"((float){x.hex()})"

    def c_decode(self, x: str) -> str:
        return f"(double)({x})"


class Rounding(enum.Enum):
    """How a fixed-point result drops fraction bits."""

    NEAREST = "nearest"       # add half an LSB, then drop: ties towards +inf
    TRUNCATE = "truncate"     # drop: towards -inf (two's complement)


class Overflow(enum.Enum):
    """What a fixed-point result outside the word's range becomes (counted either way)."""

    SATURATE = "saturate"
    WRAP = "wrap"


class Fixed(Float64):
    """Signed fixed point qI.F held as int64 raw values (see the module docstring)."""

    c_type = "int64_t"
    dtype = np.int64
    check_tolerance = 1e-3

    def __init__(self, integer: int, fraction: int, rounding: Rounding = Rounding.NEAREST,
                 overflow: Overflow = Overflow.SATURATE):
        super().__init__()
        self.integer, self.fraction = integer, fraction
        self.rounding, self.overflow = Rounding(rounding), Overflow(overflow)
        self.bits = integer + fraction
        if integer < 1 or fraction < 0 or not 2 <= self.bits <= 64:
            raise ValueError(f"q{integer}.{fraction}: a fixed-point word has at least 1 integer bit "
                             "(the sign) and 2 to 64 bits in all")
        self.lo, self.hi = -(1 << (self.bits - 1)), (1 << (self.bits - 1)) - 1
        self.name = f"q{integer}.{fraction}"

    @property
    def top(self) -> float:
        """The word holds the values [-top, top)."""
        return (self.hi + 1) * 2.0 ** -self.fraction

    def fresh(self):
        return Fixed(self.integer, self.fraction, self.rounding, self.overflow)

    @property
    def program_bits(self) -> int:
        """A scalar travels as its raw bits (program_words), so below the sign bit."""
        return self.bits - 1

    def rounding_error(self, magnitude: float) -> float:
        """Whatever the magnitude: half a last place (nearest), a whole one (truncate)."""
        return 2.0 ** -self.fraction * (1.0 if self.rounding is Rounding.TRUNCATE else 0.5)

    def result(self, values):
        return values                   # (integers: no NaN)

    def __eq__(self, other) -> bool:
        return type(other) is Fixed and (other.name, other.rounding, other.overflow) == \
            (self.name, self.rounding, self.overflow)

    def __hash__(self) -> int:
        return hash((self.name, self.rounding, self.overflow))

    def __repr__(self) -> str:
        return f"{self.name} ({self.rounding.value}, {self.overflow.value})"

    # --- arithmetic ----------------------------------------------------------------------------
    def apply(self, fn: Fn, x, y):
        x, y = np.asarray(x, dtype=np.int64), np.asarray(y, dtype=np.int64)
        if fn is Fn.MUL:
            return self._fit(self._shift(self._product(x, y)))
        if self.bits <= 63:        # |x|, |y| <= 2^62: the sum is exact in int64
            return self._fit(x + y if fn is Fn.ADD else x - y)
        # 64-bit words: int64 arithmetic wraps as the word does; an overflow is a result whose sign
        # is wrong (operands of one sign for a sum, of opposite signs for a difference)
        with np.errstate(over="ignore"):
            out = x + y if fn is Fn.ADD else x - y
        over = (((x ^ out) & (y ^ out)) < 0) if fn is Fn.ADD else (((x ^ y) & (x ^ out)) < 0)
        return self._overflowed(out, over, np.where(x < 0, self.lo, self.hi))

    def _product(self, x, y):
        """The exact product: int64 when it fits (words of at most 32 bits), Python integers
        otherwise."""
        if self.bits <= 32:
            return x * y
        return x.astype(object) * y.astype(object)

    def _shift(self, p):
        """The product with its F extra fraction bits dropped by the rounding rule."""
        F = self.fraction
        if F == 0:
            return p
        if self.rounding is Rounding.NEAREST:
            return (p + (1 << (F - 1))) >> F
        return p >> F

    def _fit(self, r):
        """A result of any size (int64 or Python integers) in the word: saturated or wrapped
        (sign-extending its low W bits), counted."""
        r = np.asarray(r)
        over = (r < self.lo) | (r > self.hi)
        if not np.any(over):
            return r.astype(np.int64)
        # (np.where, not np.minimum/np.maximum: on a 0-d array of Python integers those return a
        # bare int, which the next call converts to a C long: an OverflowError for one constant
        # beyond a 64-bit word, as the generated C's literals are made)
        if self.overflow is Overflow.SATURATE:
            fitted = np.where(r < self.lo, self.lo, np.where(r > self.hi, self.hi, r))
        elif r.dtype == np.int64:
            # int64 (a word under 64 bits: one of 64 holds every int64): wrapped without leaving
            # int64, 1 << W taken off in two halves (for a 63-bit word 1 << 63 is past int64: a
            # q3.60 constant of 4.0 was an OverflowError, exit 3, an independent oracle's find)
            half = 1 << (self.bits - 1)
            low = r & ((1 << self.bits) - 1)
            fitted = np.where(low > self.hi, (low - half) - half, low)
        else:
            # Python integers of any size (np.asarray makes 2**63 a uint64 and 2**64 an object),
            # each made one by astype (a 0-d array could hold a numpy int64)
            low = np.asarray(r.astype(object) & ((1 << self.bits) - 1), dtype=object)
            fitted = np.where(low > self.hi, low - (1 << self.bits), low)
        return self._overflowed(np.asarray(fitted).astype(np.int64), over, None)

    def _overflowed(self, out, over, saturated):
        n = int(np.count_nonzero(over))
        if n:
            self.overflows += n
            _tracked(self, over)
            if saturated is not None and self.overflow is Overflow.SATURATE:
                out = np.where(over, saturated, out)
        return out

    def c_expr(self, fn: Fn, x: str, y: str) -> str:
        return f"q_{fn.value}({x}, {y})"

    def c_prelude(self) -> str:
        """The fixed-point rules in C: the exact product (in int64_t for words of at most 32 bits,
        whose products fit; in __int128 beyond), the compiler's arithmetic shift of a signed integer
        (towards -inf), then the overflow rule."""
        W, F = self.bits, self.fraction
        wide = "__int128" if W > 32 else "int64_t"     # holds any product and any sum exactly
        half = f"(({wide})1 << {F - 1})" if F else "0"
        shift = ("p" if F == 0 else f"(p + {half}) >> {F}" if self.rounding is Rounding.NEAREST
                 else f"p >> {F}")
        if self.overflow is Overflow.SATURATE:
            out = "r < QLO ? QLO : QHI"
        else:          # the low W bits, sign-extended
            out = ("(int64_t)(((uint64_t)r & MASK) ^ SIGN) - (int64_t)SIGN" if W < 64
                   else "(int64_t)(uint64_t)r")
        return "\n".join((
            "#include <stdint.h>", "long vamp_overflows;", f"typedef {wide} wide_t;",
            f"#define QLO ((wide_t)({self.lo}LL))" if W < 64 else "#define QLO ((wide_t)INT64_MIN)",
            f"#define QHI ((wide_t)({self.hi}LL))" if W < 64 else "#define QHI ((wide_t)INT64_MAX)",
            f"#define MASK ((uint64_t){(1 << W) - 1 if W < 64 else 0}ULL)",
            f"#define SIGN ((uint64_t){1 << (W - 1) if W < 64 else 0}ULL)",
            "static inline int64_t q_fit(wide_t r) {",
            f"  if (r < QLO || r > QHI) {{ vamp_overflows++; return {out}; }}",
            "  return (int64_t)r; }",
            f"static inline int64_t q_mul(int64_t x, int64_t y) {{ wide_t p = (wide_t)x * y; "
            f"return q_fit({shift}); }}",
            "static inline int64_t q_add(int64_t x, int64_t y) { return q_fit((wide_t)x + y); }",
            "static inline int64_t q_sub(int64_t x, int64_t y) { return q_fit((wide_t)x - y); }",
            ""))

    def c_literal(self, value: float) -> str:
        return f"((int64_t){int(self.fresh().encode(value))}LL)"

    def c_decode(self, x: str) -> str:
        return f"((double)({x}) * {2.0 ** -self.fraction!r})"

    # --- the host's conversions ----------------------------------------------------------------
    def rounded(self, values) -> np.ndarray:
        """The raw integers (as floats, before the overflow rule) the host's conversion rounds
        real values to: value · 2^F rounded by the rounding rule (inf where that overflows)."""
        x = np.asarray(values, dtype=np.float64)
        if not np.all(np.isfinite(x)):
            raise ValueError("a value that is not a finite number has no fixed-point word")
        with np.errstate(over="ignore", invalid="ignore"):
            v = x * 2.0 ** self.fraction             # exact (a power of two) unless it overflows
            r = np.floor(v)
            if self.rounding is Rounding.NEAREST:
                r = r + (v - r >= 0.5)
        return r

    def beyond(self, values) -> np.ndarray:
        """Which values (a mask of their shape) the host's conversion cannot hold: rounded past
        the word's range."""
        raw = self.rounded(values)
        return (raw < self.lo) | (raw > self.hi)

    def encode(self, values) -> np.ndarray:
        x = np.asarray(values, dtype=np.float64)
        r = self.rounded(x)
        if np.all(np.abs(r) <= 2.0 ** 62):
            return self._fit(r.astype(np.int64))
        # beyond int64, in Python's integers: the scaled value is exact unless it overflowed (then
        # the value, far beyond 2^53, is an integer itself)
        exact = [int(a) if math.isfinite(a) else int(b) << self.fraction
                 for a, b in zip(r.ravel(), x.ravel())]
        return self._fit(np.array(exact, dtype=object).reshape(r.shape))

    def decode(self, words) -> np.ndarray:
        return np.asarray(words, dtype=np.int64).astype(np.float64) * 2.0 ** -self.fraction

    def random(self, rng, shape, scale: float = 1.0) -> np.ndarray:
        return rng.integers(self.lo, self.hi, size=shape, endpoint=True, dtype=np.int64)

    def program_words(self, words) -> np.ndarray:
        """Program-Mode words as raw bits: the integer a field packs is the word's bit pattern,
        which must fit in the word (ValueError otherwise: the program was packed for a wider word,
        vampc.program.words.Packing)."""
        w = np.asarray(words, dtype=np.float64)
        if w.size and (w.min() < self.lo or w.max() > self.hi):
            bad = w.min() if w.min() < self.lo else w.max()
            raise ValueError(f"a Program-Mode word holds {bad:.0f}, beyond the {self.bits}-bit "
                             f"words of {self.name}: the program was packed for a wider word "
                             f"(compile it with --word {self.name} to pack it for this one)")
        return w.astype(np.int64)


def canonical_nan(values):
    """`values` (a float array, changed in place and returned) with every NaN the canonical quiet
    NaN (numpy's: positive, payload zero)."""
    if values.size:     # (a NaN anywhere makes the minimum NaN: one pass, no array made)
        low = np.minimum.reduce(values, axis=None)
        if low != low:
            values[values != values] = np.nan
    return values


def _tracked(word, over) -> None:
    """Note how many results of each row (first axis: torque sets in the stream engine, VAMPs in
    the tick engine) of a call overflowed."""
    if word.track is not None:
        over = np.broadcast_to(np.asarray(over), np.shape(over))
        word.track.append(over.reshape(over.shape[0], -1).sum(axis=1) if over.ndim else over)


FLOAT64 = Float64()
_Q = re.compile(r"q(\d+)\.(\d+)", re.ASCII)     # ('q١٦.١٦' was q16.16: \d takes any digits)


def parse_word(text: str, rounding: str = "nearest", overflow: str = "saturate"):
    """The word format named `text` ("float64", "float32" or "qI.F"), with the fixed-point rounding
    and overflow rules; ValueError saying what is wrong otherwise."""
    if text in ("float64", "float32"):
        return Float64() if text == "float64" else Float32()
    m = _Q.fullmatch(text)
    if m is None:
        raise ValueError(f"unknown word format {text!r} (float64, float32, or qI.F: I integer bits "
                         "including the sign, F fraction bits, I + F from 2 to 64, e.g. q16.16)")
    return Fixed(int(m.group(1)), int(m.group(2)), Rounding(rounding), Overflow(overflow))
