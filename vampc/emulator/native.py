"""Native code for the stream engine: the delivered programs as generated C, compiled once and cached.

The stream engine's function (every VAMP's ROM sequence applied to its operands, in wiring order) is
rendered as C from the op table (vampc.machine.ops), with exactly the arithmetic the numpy interpreter
(vampc.machine.interp) runs: the same register views, the same products and sums in the same
association order, each product rounded before it is added (the compiler
runs with -ffp-contract=off, so it never fuses a multiply-add). IEEE binary64 arithmetic is then the
same in C as in numpy, and the torques agree bit for bit with the tick engine.

Layout (structure of arrays, so gcc vectorises across states): a scratch buffer of rows of BLOCK
doubles, one row per result component of every VAMP, then one per scalar of every host port. A block
of states is copied from the ports' (count, size) arrays into their rows, every VAMP runs as one loop
over the block, and the output components are copied into the torque array.

The shared object is cached under $XDG_CACHE_HOME/vampc (default ~/.cache/vampc; a private temp folder
if that is not writable), named by a hash of the source, compiler and flags; it is never committed.
Compiling costs more than numpy on short runs, so runs of fewer than MIN_SETS_TO_COMPILE sets are not
compiled for; from CACHED_FROM sets on they run a program the cache already holds (a run of 20 000
sets has compiled it, say), and below that they stay on numpy without generating anything (property
tests that emulate many small random robots never generate or compile anything).

VAMPC_NATIVE=0 forces the numpy path; VAMPC_NATIVE=1 compiles whatever the run length and makes any
failure here an error (for tests); otherwise a failure (no compiler, a failed compile) falls back
silently to numpy.

The module also holds the trajectory reader's native fast path (parse_csv): a fixed C source, cached
the same way.
"""
from __future__ import annotations

import ctypes
import functools
import hashlib
import math
import os
import shutil
import sysconfig
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from vampc.emulator.load import Loaded
from vampc.errors import VampcError, env_switch
from vampc.kinds import FlowKind, unhandled
from vampc.machine import ops
from vampc.machine.arith import FLOAT64
from vampc.machine.ops import ROM

BLOCK = 64          # states per block: all VAMP rows of a Puma (180 x 3 x 64 doubles) fit in L2
CHUNK = 1 << 16     # states per native call, between progress reports
# gcc takes about 5 ms per VAMP, numpy about 0.15 µs per VAMP and set: shorter runs are not compiled
# for (measured 2026-12-04 on a loaded 2-core machine, fresh cache, whole process: a UR5's 180 VAMPs
# 1.55 s numpy against 2.88 s compiling at 20 000 sets, 3.10 against 2.91 s at 60 000; an 8578-VAMP
# log snake 31 against 64 s, 80 against 82 s: a first compile pays for itself from about 60 000
# sets, every later run at once: the cache is what 20 000 buys)
MIN_SETS_TO_COMPILE = 20_000
# generating the source (to look the program up in the cache) costs about as much as numpy running
# 500 sets (0.013 s for the UR5, 0.37 s for the snake), and a cached program runs 2 000 sets in a few
# ms: from here on a cached program is used
CACHED_FROM = 2_000
PART = 32           # VAMP loops per C function: gcc's compile time grows faster than linearly in
                    # the length of a function (alias walks in PRE), so big networks are split
CFLAGS = ("-O2", "-fPIC", "-shared", "-ffp-contract=off", "-fno-fast-math")
# a compile's temporaries in the cache (.vampc-...) this old are a killed compile's (_sweep): a
# day, far beyond any compile (gcc's scratch folder keeps its time while cc1 works for minutes)
STALE_SECONDS = 86400
ENTRY = "vamp_run"
ZERO = "0.0"        # an operand scalar beyond its source's width reads a zeroed register (tick engine)


class NativeError(VampcError):
    """The native path cannot run this program here (no compiler, a failed compile, a bad port):
    numpy runs instead, or, with VAMPC_NATIVE=1, one line of error (it was a traceback, exit 3)."""


# --- entry point --------------------------------------------------------------------------------

def run_native(ld: Loaded, fl, ports: dict[int, np.ndarray], count: int, progress=None):
    """Torques (count, n) computed by native code, or None if the native path is off, failed, or
    would cost more than it saves (VAMPC_NATIVE=1 turns a failure into NativeError instead)."""
    program = prepare(ld, fl, count)
    return None if program is None else program.run(ports, count, progress)


def prepare(ld: Loaded, fl, total: int):
    """The native program for a run of `total` sets, or None where numpy should do the work (the
    native path off, failed, or costing more than it saves; VAMPC_NATIVE=1 turns a failure into
    NativeError instead). A run fed in chunks prepares once and runs each chunk."""
    mode = env_switch("VAMPC_NATIVE")
    if mode == "0" or (mode != "1" and total < CACHED_FROM):
        return None     # short runs: numpy is quick, and generating the source would cost more
    if mode != "1" and total < MIN_SETS_TO_COMPILE and compiler() is None:
        return None     # (nothing can be cached without a compiler: nothing generated, no folder)
    try:
        return build(ld, fl, compile_now=mode == "1" or total >= MIN_SETS_TO_COMPILE)
    except NativeError:
        if mode == "1":
            raise
        return None


@dataclass(frozen=True)
class NativeProgram:
    """A compiled program: the C entry point and what it expects of its arguments."""

    fn: object                           # ctypes function vamp_run(count, ports, tau, scratch)
    ports: tuple[tuple[int, int], ...]   # (input index, scalars) in argument order
    joints: int
    scratch_rows: int
    word: object = FLOAT64               # the word format (vampc.machine.arith)
    overflows: object = None             # the library's overflow counter (ctypes c_long)

    def run(self, ports: dict[int, np.ndarray], count: int, progress=None) -> np.ndarray:
        """Torques (count, n) for the inputs' values (count, size) of every set (words of the
        format; the torques as float64 values). The word's overflows are added to its count."""
        arrays = [_port_array(ports, p, size, count, self.word.dtype) for p, size in self.ports]
        tau = np.empty((count, self.joints))
        # zeros: the tail block computes on rows no state filled; keep them finite and normal
        scratch = np.zeros(self.scratch_rows * BLOCK, dtype=self.word.dtype)
        for lo in range(0, count, CHUNK):
            hi = min(lo + CHUNK, count)
            ptrs = (ctypes.c_void_p * max(len(arrays), 1))(*[a[lo:].ctypes.data for a in arrays])
            before = self.overflows.value if self.overflows is not None else 0
            self.fn(hi - lo, ptrs, tau[lo:].ctypes.data, scratch.ctypes.data)
            if self.overflows is not None:
                self.word.overflows += self.overflows.value - before
            if progress is not None:
                progress(hi, count)
        return tau


def _port_array(ports, index: int, size: int, count: int, dtype=np.float64) -> np.ndarray:
    arr = np.ascontiguousarray(ports[index], dtype=dtype)
    if arr.shape != (count, size):
        raise NativeError(f"input {index}: values of shape {arr.shape}, expected {(count, size)}")
    return arr


def build(ld: Loaded, fl, compile_now: bool = True) -> NativeProgram | None:
    """The native program of `ld`'s flow, compiled now unless the cache holds it (None when it does
    not and not `compile_now`)."""
    layout = Scratch.of(fl)
    source = generate_source(ld, fl, layout)
    if compile_now:
        from vampc import progress
        from vampc.textio import count
        # (gcc says nothing while it runs: an 8578-VAMP network took 30 s before the first set)
        with progress.stages(f"compiling the stream engine's C for {count(len(ld.net.vamps), 'VAMP')} "
                             "(once: it is cached)", ("gcc",)) as stage:
            stage("gcc")
            path = compile_cached(source)
    else:
        path = compile_cached(source, compile_now=False)
        if path is None:
            return None
    lib = _load(path)
    fn = getattr(lib, ENTRY)
    fn.argtypes = (ctypes.c_long, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p)
    fn.restype = None
    ports = tuple((i, size) for i, (_, _, size) in enumerate(fl.inputs))
    counter = ctypes.c_long.in_dll(lib, "vamp_overflows")
    return NativeProgram(fn, ports, ld.chain.n_outputs, layout.rows, ld.arith, counter)


# --- source generation --------------------------------------------------------------------------

@dataclass(frozen=True)
class Scratch:
    """Scratch rows: op i's component c at row 3i + c, then each input's scalars from `port_row`."""

    ops: int
    port_row: dict
    rows: int

    @staticmethod
    def of(fl) -> "Scratch":
        """The layout of a flow."""
        row, port_row = 3 * len(fl.ops), {}
        for i, (_, _, size) in enumerate(fl.inputs):
            port_row[i] = row
            row += size
        return Scratch(len(fl.ops), port_row, row)


def generate_source(ld: Loaded, fl, layout: Scratch) -> str:
    """The C translation unit for a flow: the ops in order, PART loops to a function, and the fixed
    driver that copies inputs in and torques out through tables."""
    word = ld.arith
    loops = [_op_loop(fl, layout, i, word) for i in range(len(fl.ops))]
    parts = [loops[k:k + PART] for k in range(0, len(loops), PART)]
    T = word.c_type
    # float64 runs every block whole (a fixed trip count vectorises); a format that counts its
    # overflows runs only the block's filled sets, so the count is the numpy path's
    end = "B" if word.c_type == "double" else "nb"
    return "\n".join((
        "/* Generated by vampc.emulator.native: the VAMP network of one program file. */",
        f"#define B {BLOCK}", f"#define END {end}", word.c_prelude(), f"typedef {T} word_t;",
        # the scratch rows are numpy arrays of the format's dtype, read here as its c_type: a
        # format whose two differ in size is refused by the compiler, never misread
        f"_Static_assert(sizeof(word_t) == {np.dtype(word.dtype).itemsize}, "
        f"\"{word.name} words: c_type {T} is not the size of dtype {np.dtype(word.dtype)}\");",
        f"#define DECODE(x) {word.c_decode('(x)')}",
        *(f"__attribute__((noinline)) static void part{k}(word_t *restrict S, long nb) {{\n"
          "  long s;\n" + "\n".join(body) + "\n}" for k, body in enumerate(parts)),
        "static void vamps(word_t *restrict S, long nb) {",
        *(f"  part{k}(S, nb);" for k in range(len(parts))), "}",
        _tables(ld, fl, layout), DRIVER))


def _tables(ld: Loaded, fl, layout: Scratch) -> str:
    def table(name: str, values) -> str:
        return f"static const long {name}[] = {{{', '.join(map(str, values)) or '0'}}};"
    return "\n".join((
        f"#define NPORTS {len(fl.inputs)}", f"#define NOUT {len(fl.outputs)}",
        f"#define NJ {ld.chain.n_outputs}",
        table("PORT_SIZE", [size for _, _, size in fl.inputs]),
        table("PORT_ROW", [layout.port_row[i] for i in range(len(fl.inputs))]),
        table("OUT_JOINT", [joint - 1 for joint, _, _ in fl.outputs]),
        table("OUT_ROW", [3 * op + c for _, op, c in fl.outputs])))


# The fixed part: inputs (count, size) into their rows, torques out of the output rows. It is not
# generated per program because gcc's alias walks grow quadratically with straight-line code.
DRIVER = f"""
static void load_ports(const word_t *const *P, long s0, long nb, word_t *restrict S) {{
  long k, c, s;
  for (k = 0; k < NPORTS; k++) {{
    const long size = PORT_SIZE[k];
    const word_t *x = P[k] + s0 * size;
    word_t *row = S + PORT_ROW[k] * B;
    for (c = 0; c < size; c++)
      for (s = 0; s < nb; s++) row[c * B + s] = x[s * size + c];
  }}
}}

static void store_tau(double *restrict tau, long s0, long nb, const word_t *restrict S) {{
  long k, s;
  for (k = 0; k < NOUT; k++) {{
    const word_t *row = S + OUT_ROW[k] * B;
    double *t = tau + s0 * NJ + OUT_JOINT[k];
    for (s = 0; s < nb; s++) t[s * NJ] = DECODE(row[s]);
  }}
}}

void {ENTRY}(long count, const word_t *const *P, double *restrict tau, word_t *restrict S) {{
  long s0;
  for (s0 = 0; s0 < count; s0 += B) {{
    long nb = count - s0 < B ? count - s0 : B;
    load_ports(P, s0, nb, S);
    vamps(S, nb);
    store_tau(tau, s0, nb, S);
  }}
}}
"""


def _op_loop(fl, layout: Scratch, i: int, arith=FLOAT64) -> str:
    rom, a_src, b_src = fl.ops[i]
    a = _operand(fl, layout, a_src, arith)
    b = _operand(fl, layout, b_src, arith)
    am, bm = _registers(rom, a, b)
    lines = [_module(rom, m, am[m], bm[m], _row(3 * i + m), arith) for m in range(3)]
    v, k = fl.names[i]
    head = (f"  /* VAMP {v} slot {k}: {ROM[rom][0].value} (ROM {rom}) */\n"
            "  for (s = 0; s < END; s++) {\n")
    return head + "".join(f"    {line}\n" for line in lines) + "  }"


def _row(row: int) -> str:
    return f"S[{row * BLOCK} + s]"


def _operand(fl, layout: Scratch, sources, word=FLOAT64) -> list[str]:
    """The operand's nine scalars as C expressions (row-major for a matrix)."""
    if len(sources) == 3:   # a matrix as three MM column results: element (i, j) is scalar i of column j
        return [_scalar(fl, layout, sources[j], i, word) for i in range(3) for j in range(3)]
    return [_scalar(fl, layout, sources[0], c, word) for c in range(9)]


def _scalar(fl, layout: Scratch, src, c: int, word=FLOAT64) -> str:
    zero = ZERO if word.c_type == "double" else f"(({word.c_type})0)"
    if src[0] is FlowKind.OP:
        return _row(3 * src[1] + c) if c < 3 else zero
    if src[0] is FlowKind.IN:
        return _row(layout.port_row[src[1]] + c) if c < fl.inputs[src[1]][2] else zero
    if src[0] is FlowKind.CONST:
        value = src[1]
        return _literal(value[c], word) if c < len(value) else zero
    return unhandled(src[0])


def _literal(x: float, word=FLOAT64) -> str:
    """An exact C literal of the word the host writes for `x` (its format's encode)."""
    if not math.isfinite(x):
        raise NativeError(f"constant {x!r} has no exact C literal here")
    return word.c_literal(x)


def _registers(rom: int, a: list[str], b: list[str]):
    """Module m's operand registers (3 x 3 expressions each): the scalars its op's views name, as
    vampc.machine.interp.registers."""
    entry, col = ops.entry(rom)
    return tuple([[x[i] for i in view.scalars(m, col)] for m in range(3)]
                 for x, view in zip((a, b), entry.views))


def _module(rom: int, m: int, am: list[str], bm: list[str], out: str, arith=FLOAT64) -> str:
    """Module m's micro-sequence (`am`, `bm`: its three operand registers each) as one C block,
    rendered from the op table: a local per unit register, each step's assignments made together (a
    step whose assignment writes a unit a later one of the step reads goes through temporaries), the
    result unit stored last."""
    entry, _ = ops.entry(rom)
    regs = {"a": am, "b": bm}

    def ref(r) -> str:
        return f"u{r.i}" if r.kind == "u" else regs[r.kind][r.index(m)]
    body = []
    for step in entry.steps:
        exprs = [(a.unit, arith.c_expr(a.fn, ref(a.x), ref(a.y))) for a in step]
        read = {r.i for a in step for r in (a.x, a.y) if r.kind == "u"}
        if len(step) > 1 and read & {a.unit for a in step[:-1]}:
            body += ["{", *(f"{arith.c_type} t{u} = {e};" for u, e in exprs),
                     *(f"u{u} = t{u};" for u, _ in exprs), "}"]
        else:
            body += [f"u{u} = {e};" for u, e in exprs]
    units = sorted({a.unit for step in entry.steps for a in step})
    decl = f"{arith.c_type} " + ", ".join(f"u{u}" for u in units) + ";"
    return "{ " + " ".join([decl, *body, f"{out} = u{entry.result};"]) + " }"


# --- trajectory CSV ------------------------------------------------------------------------------

_CSV_TEMPLATE = r"""/* vampc.emulator.native: a strict CSV reader of plain decimal numbers, and its writer. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifdef __SIZEOF_INT128__
/* Eisel and Lemire's conversion (D. Lemire, "Number parsing at a gigabyte per second", 2021; the
   steps as in N. Tao's description, nigeltao.github.io/blog/2020/eisel-lemire.html): a decimal of
   at most 19 significant digits, man * 10^e10, to the nearest double, or 0 where it cannot be sure
   (a halfway case, a subnormal or infinite result, e10 beyond the table); strtod then decides.
   POW10[e10 - POW10_MIN] = {high, low} 64 bits of 10^e10's first 128 bits, rounded down. */
#define POW10_MIN (@POW10_MIN@)
#define POW10_MAX (@POW10_MAX@)
static const unsigned long long POW10[][2] = {
@POW10@
};

static int eisel_lemire(unsigned long long man, long e10, int neg, double *out) {
  unsigned __int128 x, y;
  unsigned long long hi, lo, yhi, ylo, mhi, mlo, mant, exp2, bits;
  int clz, msb;
  if (man == 0) { *out = neg ? -0.0 : 0.0; return 1; }
  if (e10 < POW10_MIN || e10 > POW10_MAX) return 0;
  clz = __builtin_clzll(man);
  man <<= clz;
  /* floor(e10 log2 10) + 64 + bias - clz, the exponent if the product's top bit is set */
  exp2 = (unsigned long long)(((217706L * e10) >> 16) + 64 + 1023) - (unsigned long long)clz;
  x = (unsigned __int128)man * POW10[e10 - POW10_MIN][0];
  hi = (unsigned long long)(x >> 64);
  lo = (unsigned long long)x;
  if ((hi & 0x1FF) == 0x1FF && lo + man < man) {      /* the low 64 bits of 10^e10 may matter */
    y = (unsigned __int128)man * POW10[e10 - POW10_MIN][1];
    yhi = (unsigned long long)(y >> 64);
    ylo = (unsigned long long)y;
    mhi = hi;
    mlo = lo + yhi;
    if (mlo < lo) mhi++;
    if ((mhi & 0x1FF) == 0x1FF && mlo + 1 == 0 && ylo + man < man) return 0;
    hi = mhi;
    lo = mlo;
  }
  msb = (int)(hi >> 63);
  mant = hi >> (msb + 9);                               /* 54 bits */
  exp2 -= 1 ^ msb;
  if (lo == 0 && (hi & 0x1FF) == 0 && (mant & 3) == 1) return 0;   /* halfway: undecided */
  mant += mant & 1;                                     /* to 53 bits, to nearest */
  mant >>= 1;
  if (mant >> 53) { mant >>= 1; exp2 += 1; }
  if (exp2 - 1 >= 0x7FF - 1) return 0;                  /* subnormal, infinite */
  bits = exp2 << 52 | (mant & 0x000FFFFFFFFFFFFFULL);
  if (neg) bits |= 0x8000000000000000ULL;
  memcpy(out, &bits, sizeof bits);
  return 1;
}

#endif

/* The byte at p[len] must be NUL or one that cannot continue a number (a caller's bytes object ends
   in NUL): strtod, where it decides a cell, reads on until the number ends.
   Rows of `cols` cells separated by ',' and ended by '\n' (or "\r\n", as in Python's text mode; the
   last line end optional) into out, in one pass over the bytes; the number of rows, or -1 on
   anything else (an empty line, a ragged row, more than rows_max rows, a cell that is not, between
   spaces or tabs, [+-]d[.d][(e|E)[+-]d] with at least one digit in the mantissa, or more than
   longs_max cells of more than 19 significant digits). A cell is converted by Eisel-Lemire, or by
   strtod where that cannot decide (a halfway case, a subnormal or infinite result, an exponent
   beyond 100000 or the table); a cell of more than 19 significant digits is left to the caller,
   which converts it as Python's float() does (the native path had differed from float() on some
   decimals of hundreds of digits; the cause is not traced, glibc's strtod was found exact):
   longs[3k..3k+2] = its index in out, its offset and its length, *n_longs of them. On a refusal
   *bad is the offset of the line's first byte. */
long parse_csv(const char *p, long len, long cols, long rows_max, double *out, long *bad,
               long *longs, long longs_max, long *n_longs) {
  const char *begin = p, *end = p + len, *num, *stop, *ed;
  char *got;
  unsigned long long man;
  long r = 0, c, e10, ex;
  int neg, nd, eneg, mant, fast, lng;
  double x;
  while (p < end) {
    *bad = p - begin;                                   /* the line a refusal is in */
    if (r == rows_max) return -1;
    for (c = 0; c < cols; c++) {
      man = 0; e10 = 0; ex = 0; neg = 0; nd = 0; eneg = 0; mant = 0; fast = 0; lng = 0;
      while (p < end && (*p == ' ' || *p == '\t')) p++;
      num = p;
      if (p < end && (*p == '+' || *p == '-')) { neg = *p == '-'; p++; }
      for (; p < end && *p >= '0' && *p <= '9'; p++) {
        mant = 1;
        if (man == 0 && *p == '0') continue;            /* leading zeros */
        if (nd == 19) { lng = 1; continue; }            /* more digits than 64 bits hold */
        man = man * 10 + (unsigned long long)(*p - '0');
        nd++;
      }
      if (p < end && *p == '.') {
        for (p++; p < end && *p >= '0' && *p <= '9'; p++) {
          mant = 1;
          if (man == 0 && *p == '0') { e10--; continue; }
          if (nd == 19) { lng = 1; continue; }
          man = man * 10 + (unsigned long long)(*p - '0');
          nd++;
          e10--;
        }
      }
      if (!mant) return -1;
      if (p < end && (*p == 'e' || *p == 'E')) {
        p++;
        if (p < end && (*p == '+' || *p == '-')) { eneg = *p == '-'; p++; }
        for (ed = p; p < end && *p >= '0' && *p <= '9'; p++)
          if (ex <= 100000) ex = ex * 10 + (*p - '0');  /* past it: strtod (0, inf, or what the zeros leave) */
        if (p == ed) return -1;
      }
      stop = p;
      if (lng) {                      /* for the caller to convert: its place in out, bytes, length */
        if (*n_longs == longs_max) return -1;
        longs[3 * *n_longs] = r * cols + c;
        longs[3 * *n_longs + 1] = num - begin;
        longs[3 * *n_longs + 2] = stop - num;
        ++*n_longs;
        x = 0.0;
        fast = 1;
      }
#ifdef __SIZEOF_INT128__
      if (!fast && ex <= 100000) fast = eisel_lemire(man, e10 + (eneg ? -ex : ex), neg, &x);
#endif
      if (!fast) {                                      /* the cell ends before a byte strtod stops at */
        x = strtod(num, &got);
        if (got != stop) return -1;
      }
      out[r * cols + c] = x;
      while (p < end && (*p == ' ' || *p == '\t')) p++;
      if (c < cols - 1) {
        if (p == end || *p != ',') return -1;
        p++;
      } else if (p < end) {
        if (*p == '\r' && p + 1 < end && p[1] == '\n') p++;
        if (*p != '\n') return -1;
        p++;
      }
    }
    r++;
  }
  return r;
}

/* The number of '\n' in [p, p + len). */
long count_lines(const char *p, long len) {
  const char *end = p + len;
  long n = 0;
  while (p < end && (p = memchr(p, '\n', (size_t)(end - p))) != NULL) { n++; p++; }
  return n;
}

#ifdef __SIZEOF_INT128__
/* POW5[k] = 5^k, k = 0..55, as {high, low} 64-bit halves (5^55 < 2^128). */
static const unsigned long long POW5[][2] = {
@POW5@
};

/* D = x * 10^k rounded to the nearest integer, ties to even, from x = m * 2^e2 exactly (m * 5^k
   * 2^(e2 + k), or m * 2^(e2 + k) / 5^-k), in 128-bit integers; 0 where they cannot hold it. */
static int scaled_round(unsigned long long m, long e2, long k, unsigned long long *d) {
  unsigned __int128 n, q, rem, half, den;
  long sh = e2 + k;
  if (k >= 0) {
    if (k > 32) return 0;                               /* 2^53 * 5^32 < 2^128 */
    n = (unsigned __int128)m * (((unsigned __int128)POW5[k][0] << 64) | POW5[k][1]);
    if (sh >= 0) {
      if (sh > 60 || n >> (64 - sh) != 0) return 0;
      q = n << sh;
    } else {
      if (-sh >= 128) return 0;
      q = n >> -sh;
      rem = n - (q << -sh);
      half = (unsigned __int128)1 << (-sh - 1);
      if (rem > half || (rem == half && (q & 1))) q++;
    }
  } else {
    if (-k > 55 || sh < 0 || sh > 74) return 0;         /* m * 2^sh < 2^128 */
    den = ((unsigned __int128)POW5[-k][0] << 64) | POW5[-k][1];
    n = (unsigned __int128)m << sh;
    q = n / den;
    rem = n - q * den;
    if (rem > den - rem || (rem == den - rem && (q & 1))) q++;
  }
  if (q >> 64) return 0;
  *d = (unsigned long long)q;
  return 1;
}

/* x (finite) as C's and Python's "%.17g" write it, into out; the number of bytes. Its 17 significant
   digits are x * 10^(16 - X) rounded to nearest, ties to even (X the decimal exponent after
   rounding), worked out exactly in 128-bit integers; sprintf where they cannot hold it. */
static int format_g17(double x, char *out) {
  unsigned long long bits, m, d;
  long e2, xp, i, last;
  int be, neg, tries;
  char dig[17], *p = out;
  memcpy(&bits, &x, sizeof bits);
  neg = (int)(bits >> 63);
  be = (int)((bits >> 52) & 0x7FF);
  m = bits & 0x000FFFFFFFFFFFFFULL;
  if (be == 0 && m == 0) {
    if (neg) *p++ = '-';
    *p++ = '0';
    return (int)(p - out);
  }
  if (be == 0x7FF) return sprintf(out, "%.17g", x);
  if (be == 0) e2 = -1074; else { m |= 1ULL << 52; e2 = be - 1075; }
  /* floor(log10 x) is xp or xp + 1: 2^(bits - 1 + e2) <= x < 2^(bits + e2) */
  {
    double t = (double)(63 - __builtin_clzll(m) + e2) * 0.30102999566398120;
    xp = (long)t;
    if (t < (double)xp) xp--;
  }
  for (tries = 0;; tries++) {
    if (tries == 3 || !scaled_round(m, e2, 16 - xp, &d)) return sprintf(out, "%.17g", x);
    if (d < 10000000000000000ULL) { xp--; continue; }
    if (d > 100000000000000000ULL) { xp++; continue; }
    if (d == 100000000000000000ULL) { xp++; d = 10000000000000000ULL; }   /* rounded up to 10^17 */
    break;
  }
  for (i = 16; i >= 0; i--) { dig[i] = (char)('0' + d % 10); d /= 10; }
  if (neg) *p++ = '-';
  if (xp < -4 || xp >= 17) {                            /* d.ddde+XX */
    *p++ = dig[0];
    for (last = 16; last > 0 && dig[last] == '0'; last--) {}
    if (last > 0) { *p++ = '.'; memcpy(p, dig + 1, (size_t)last); p += last; }
    *p++ = 'e';
    *p++ = xp < 0 ? '-' : '+';
    if (xp < 0) xp = -xp;
    if (xp >= 100) { *p++ = (char)('0' + xp / 100); xp %= 100; }
    *p++ = (char)('0' + xp / 10);
    *p++ = (char)('0' + xp % 10);
  } else if (xp >= 0) {                                 /* ddd.ddd */
    memcpy(p, dig, (size_t)(xp + 1));
    p += xp + 1;
    for (last = 16; last > xp && dig[last] == '0'; last--) {}
    if (last > xp) { *p++ = '.'; memcpy(p, dig + xp + 1, (size_t)(last - xp)); p += last - xp; }
  } else {                                              /* 0.000ddd */
    *p++ = '0';
    *p++ = '.';
    for (i = 0; i < -xp - 1; i++) *p++ = '0';
    for (last = 16; dig[last] == '0'; last--) {}
    memcpy(p, dig, (size_t)(last + 1));
    p += last + 1;
  }
  return (int)(p - out);
}
#else
static int format_g17(double x, char *out) { return sprintf(out, "%.17g", x); }
#endif

/* rows x cols doubles as CSV text, each "%.17g" (format_g17; C's printf and Python round correctly),
   ',' between cells and '\n' after each row, into out (at least rows * cols * 25 bytes: the longest
   "%.17g" is 24 characters); the number of bytes written. */
long format_csv(const double *data, long rows, long cols, char *out) {
  char *p = out;
  long r, c;
  for (r = 0; r < rows; r++) {
    for (c = 0; c < cols; c++) {
      p += format_g17(data[r * cols + c], p);
      *p++ = c == cols - 1 ? '\n' : ',';
    }
  }
  return p - out;
}
"""


POW10_RANGE = (-348, 347)      # the powers of ten of the Eisel-Lemire table: every finite double's


def _pow10_128(e: int) -> tuple[int, int]:
    """The first 128 bits of 10^e (rounded down), as (high, low) 64-bit halves: exact integers."""
    if e >= 0:
        v = 10 ** e
        m = v << (128 - v.bit_length()) if v.bit_length() <= 128 else v >> (v.bit_length() - 128)
    else:
        d = 10 ** -e
        m = (1 << (127 + d.bit_length())) // d        # in [2^127, 2^128): d is no power of two
    return m >> 64, m & (2 ** 64 - 1)


@functools.cache
def csv_source() -> str:
    """The C of the CSV reader and writer, with its table of powers of ten."""
    lo, hi = POW10_RANGE
    rows = ",\n".join("  {0x%016XULL, 0x%016XULL}" % _pow10_128(e) for e in range(lo, hi + 1))
    pow5 = ",\n".join("  {0x%016XULL, 0x%016XULL}" % (5 ** k >> 64, 5 ** k & (2 ** 64 - 1))
                       for k in range(56))
    return (_CSV_TEMPLATE.replace("@POW10_MIN@", str(lo)).replace("@POW10_MAX@", str(hi))
            .replace("@POW10@", rows).replace("@POW5@", pow5))


def _csv_function(name: str, argtypes: tuple):
    """A function of the compiled csv_source(), returning a C long; None when the native path is off
    (VAMPC_NATIVE=0) or unavailable, and the NativeError raised when it is required (=1)."""
    mode = env_switch("VAMPC_NATIVE")
    if mode == "0":
        return None
    try:
        fn = getattr(_load(compile_cached(csv_source())), name)
    except NativeError:
        if mode == "1":
            raise
        return None
    fn.argtypes, fn.restype = argtypes, ctypes.c_long
    return fn


LONG_CELLS = 1 << 16    # cells of more than 19 digits a piece converts in Python (more: the slow way)


def parse_csv(body: bytes, cols: int, start: int = 0, refused: list | None = None,
              stop: int | None = None):
    """The rows of a trajectory CSV from byte `start` of `body` (the line after its header) as an
    array (rows, cols), or None if they are not a plain table of decimal numbers, or if the native
    path is off or unavailable (the caller then parses them otherwise). A cell of more than 19
    significant digits is converted by float() (the native path had differed from float() on some
    decimals of hundreds of digits, the cause not traced: glibc's strtod was found exact; more than
    LONG_CELLS of them in a piece: refused); up to 19, Eisel-Lemire, and
    strtod where it cannot decide, round correctly as Python's float() does (tested against
    float(), bit for bit, on cells of every form).
    `refused`: a list given gets the offset in `body` of the first line refused, if one was.
    `stop`: where the rows end (default the end of `body`); the byte there must not continue a
    number (a blank, a line end)."""
    fn = _csv_function("parse_csv", (ctypes.c_void_p, ctypes.c_long, ctypes.c_long, ctypes.c_long,
                                     ctypes.c_void_p, ctypes.POINTER(ctypes.c_long), ctypes.c_void_p,
                                     ctypes.c_long, ctypes.POINTER(ctypes.c_long)))
    lines = _csv_function("count_lines", (ctypes.c_void_p, ctypes.c_long))
    if fn is None or lines is None:
        return None
    # split at line ends into one piece per thread (ctypes lets go of the GIL during each call, so
    # the pieces' lines are counted and parsed in parallel; the thread count from the first line's
    # length, not from counting every line here, which holds the GIL)
    stop = len(body) if stop is None else stop
    first = body.find(b"\n", start, stop)
    cuts, count = [start], workers((stop - start) // (first - start + 1) + 1 if first >= 0 else 1)
    for k in range(1, count):
        at = body.find(b"\n", max(start + (stop - start) * k // count, cuts[-1]), stop)
        if at < 0:
            break
        cuts.append(at + 1)
    cuts.append(stop)
    base = ctypes.cast(ctypes.c_char_p(body), ctypes.c_void_p).value

    def part(k: int, body=body):
        # (`body` held here: a thread still reading it keeps it alive, though a signal has ended
        # parse_csv on the calling thread; its address alone would not)
        lo, hi = cuts[k], cuts[k + 1]
        out = np.empty((lines(base + lo, hi - lo) + 1, cols))
        bad, count = ctypes.c_long(0), ctypes.c_long(0)
        longs = np.empty(3 * LONG_CELLS, dtype=f"i{ctypes.sizeof(ctypes.c_long)}")   # C longs
        rows = fn(base + lo, hi - lo, cols, len(out), out.ctypes.data, ctypes.byref(bad),
                  longs.ctypes.data, LONG_CELLS, ctypes.byref(count)) if hi > lo else 0
        if rows <= 0 and hi > lo:
            return lo + bad.value
        flat = out.reshape(-1)
        for cell, at, size in longs[:3 * count.value].reshape(-1, 3).tolist():
            flat[cell] = float(body[lo + at:lo + at + size])   # correctly rounded, as the slow path
        return out[:rows]
    pieces = _threaded(part, len(cuts) - 1)
    failed = [p for p in pieces if isinstance(p, int)]
    if failed and refused is not None:
        refused.append(failed[0])         # the first refused line's first byte, in `body`
    if failed or not sum(len(p) for p in pieces):
        return None
    return np.concatenate(pieces) if len(pieces) > 1 else pieces[0]


def format_csv(data: np.ndarray) -> str | None:
    """The rows of a finite float64 array (count, width) as CSV text, "%.17g" each, as
    vampc.emulator.trajectory.format_rows writes them; None when the native path is off or
    unavailable (the caller then formats them in Python)."""
    fn = _csv_function("format_csv", (ctypes.c_void_p, ctypes.c_long, ctypes.c_long, ctypes.c_void_p))
    if fn is None:
        return None
    data = np.ascontiguousarray(data, dtype=np.float64)
    big = np.abs(data)
    if big.size and (not np.all(np.isfinite(big)) or big.max() >= 1e20 or np.any((big > 0) & (big < 1e-20))):
        return None       # far exponents (glibc's exact printf is slow there) and nan/inf: Python's
    rows, cols = data.shape

    def part(lo: int, hi: int) -> bytes:           # ctypes lets go of the GIL during the call
        out = ctypes.create_string_buffer((hi - lo) * cols * 25 + 1)
        size = fn(data[lo:hi].ctypes.data, hi - lo, cols, out)
        return ctypes.string_at(out, size)
    return b"".join(in_threads(part, rows)).decode("ascii")


def _threaded(work, count: int) -> list:
    """work(k) for k in range(count): k = 0 on this thread, the others on threads of their own
    (plain threads: concurrent.futures and the logging it imports add 2 ms to every start-up); the
    results in order, the first error raised here."""
    results: list = [None] * count
    errors: list = []

    def run(k: int) -> None:
        try:
            results[k] = work(k)
        except BaseException as exc:          # raised again on the calling thread
            errors.append(exc)
    import threading
    threads = [threading.Thread(target=run, args=(k,), daemon=True) for k in range(1, count)]
    for t in threads:
        t.start()
    try:
        run(0)
    finally:
        for t in threads:
            t.join()
    if errors:
        raise errors[0]
    return results


def workers(rows: int) -> int:
    """Threads for a table of `rows` rows: one per available core, at least 10 000 rows each."""
    from vampc.background import available_cores
    return max(1, min(available_cores(), rows // 10_000))


def in_threads(work, rows: int) -> list:
    """work(lo, hi) over row ranges, one per thread (workers), for C calls, which run without the
    GIL; the results in row order."""
    count = workers(rows)
    bounds = [rows * k // count for k in range(count + 1)]
    return _threaded(lambda k: work(bounds[k], bounds[k + 1]), count)


# --- compiling and caching ----------------------------------------------------------------------

def compiler() -> str | None:
    """The system C compiler: Python's own (sysconfig CC), else cc, gcc or clang on the PATH."""
    configured = (sysconfig.get_config_var("CC") or "").split()
    for name in configured[:1] + ["cc", "gcc", "clang"]:
        found = shutil.which(name)
        if found:
            return found
    return None


def cache_dir() -> Path:
    """$XDG_CACHE_HOME/vampc (default ~/.cache/vampc), else a private folder in the temp dir."""
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    uid = os.getuid() if hasattr(os, "getuid") else 0
    folders = [Path(base) / "vampc"]
    try:
        folders.append(Path(tempfile.gettempdir()) / f"vampc-{uid}")
    except OSError:        # no usable temp folder at all (a read-only container): numpy, not a
        pass               # traceback (a CI user's find)
    for folder in folders:
        try:
            folder.mkdir(mode=0o700, parents=True, exist_ok=True)
        except OSError:
            continue
        # we load code from here: only a folder of our own that we can write will do
        if os.access(folder, os.W_OK) and folder.stat().st_uid == uid:
            return folder
    raise NativeError("no writable cache folder for compiled programs")


def compile_cached(source: str, compile_now: bool = True) -> Path | None:
    """The shared object for `source`, compiled now unless the cache already holds it (None when it
    does not and not `compile_now`)."""
    cc = compiler()
    if cc is None:
        raise NativeError("no C compiler found (cc, gcc or clang)")
    key = hashlib.sha256("\0".join((cc, *CFLAGS, source)).encode()).hexdigest()[:32]
    target = cache_dir() / f"vampc-{key}.so"
    if not _intact(target):
        # (one the cache holds but damaged, or kept by an earlier vampc without its digest, is
        # compiled again at once, even for a run too short to compile for: it was compiled once)
        if not compile_now and not target.exists():
            return None
        _compile(cc, source, target)
    return target


def _digest_file(target: Path) -> Path:
    return target.with_suffix(".sha256")


def _intact(target: Path) -> bool:
    """Whether the cache holds `target` as it was compiled: its SHA-256 is the one written beside
    it when it was. A cut-short object (a crash or power loss before its blocks reached the disk)
    was loaded as it was and killed the process with SIGBUS, nothing said, and an empty one sent
    every run to numpy in silence (an audit's finds). A damaged one is said, and compiled again by
    `compile_cached`; one without the digest (an earlier vampc's cache), the same without a word.
    The damaged file is left for the compile's rename to replace: removed here, it could be the good
    one another run had just put in its place."""
    try:
        data = target.read_bytes()
    except OSError:
        return False
    try:
        kept = _digest_file(target).read_text(encoding="ascii").strip()
    except (OSError, ValueError):
        return False
    if hashlib.sha256(data).hexdigest() == kept:
        return True
    import warnings

    from vampc.errors import VampcWarning
    warnings.warn(VampcWarning(f"{target}: the cached compiled program does not match the digest "
                               f"kept beside it ({_digest_file(target).name}): one of them is "
                               "damaged; it is compiled again"), stacklevel=3)
    return False


def _write_digest(path: Path, digest: str) -> None:
    """The digest beside its object, written to a temporary name and renamed (atomic)."""
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", dir=path.parent)
    try:
        with os.fdopen(fd, "w", encoding="ascii") as f:
            f.write(digest + "\n")
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    finally:
        Path(tmp).unlink(missing_ok=True)


def _load(path: Path) -> ctypes.CDLL:
    """dlopen a cached object (a temp folder mounted noexec, say, refuses it)."""
    try:
        return ctypes.CDLL(str(path))
    except OSError as exc:
        raise NativeError(f"cannot load {path}: {exc}") from None


def _sweep(folder: Path) -> None:
    """Remove the temporaries a killed compile left in the cache: a SIGKILL (a job runner's time-out
    escalated) gives it no chance to, and a shared cache filled with .vampc-cc.* folders and
    half-written objects that no run removed (a CI engineer's find). Only the names compiles give
    their temporaries (.vampc-...), only a day old or more (STALE_SECONDS): a compile running now
    holds younger ones."""
    import time
    now = time.time()
    try:
        entries = list(os.scandir(folder))
    except OSError:
        return
    for entry in entries:
        if not entry.name.startswith(".vampc-"):
            continue
        try:
            if now - entry.stat(follow_symlinks=False).st_mtime < STALE_SECONDS:
                continue
            if entry.is_dir(follow_symlinks=False):
                shutil.rmtree(entry.path, ignore_errors=True)
            else:
                os.unlink(entry.path)
        except OSError:
            continue


def _compile(cc: str, source: str, target: Path) -> None:
    """Compile from stdin to a temporary name, then rename: concurrent runs never load half a file."""
    _sweep(target.parent)
    fd, tmp = tempfile.mkstemp(prefix=f".{target.stem}.", suffix=".so", dir=target.parent)
    os.close(fd)
    # gcc's own temporaries in a folder of ours, removed whatever happens: a SIGTERM kills the
    # driver, which then cannot remove them (a review found /tmp/ccXXXXXX.s left behind)
    scratch = tempfile.mkdtemp(prefix=".vampc-cc.", dir=target.parent)
    try:
        from vampc.background import run_tool
        proc = run_tool([cc, *CFLAGS, "-x", "c", "-", "-o", tmp], input=source,
                        env={**os.environ, "TMPDIR": scratch})
        if proc.returncode != 0:
            lines = proc.stderr.strip().splitlines() or [""]
            said = next((x for x in lines if "error" in x), lines[-1]).strip()[:300]   # (one line)
            raise NativeError(f"{cc} failed (exit {proc.returncode}): {said}")
        with open(tmp, "rb") as f:            # on the disk before it is named (`_intact`)
            data = f.read()
            os.fsync(f.fileno())
        _write_digest(_digest_file(target), hashlib.sha256(data).hexdigest())
        os.replace(tmp, target)
    except OSError as exc:
        raise NativeError(f"cannot compile with {cc}: {exc}") from None
    finally:
        Path(tmp).unlink(missing_ok=True)
        shutil.rmtree(scratch, ignore_errors=True)
