"""Program emission: VAMP numbering, per-VAMP program words and the Program-Mode stream (section VII).

Program Mode: every VAMP passes the word on its Operand-A input to its Result one tick later, every
buffer stage passes its input on one tick later, and a VAMP latches the program of the word that carries
its own number. So the words for a VAMP must be written to the input buffer (host port or constant
buffer) at the root of its Operand-A path. Each root's words are written one per tick, deepest target
first, which makes the load time max over roots of (words + depth of the last word's target).
"""
from __future__ import annotations

import operator
from array import array
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from vampc.errors import VampcError, VampcInternalError
from vampc.kinds import TapKind
from vampc.memo import counting
from vampc.network.model import Network, Tap, tap_source
from vampc.program.words import (
    PACKING,
    TIER_CODES,
    BusRegister,
    Program,
    bus_words,
    compact_fields,
    encode,
    fits_compact,
    rom_pointer,
    vamp_words,
)


class Words(Sequence):
    """A stream entry's words as the compiler makes them: a sequence of (number, field, field)
    tuples of floats, held as one array of float64 (24 bytes a word, where a tuple of three floats
    takes 88: a 4096-joint log program has a million words). Equal to the tuple of the same words
    (what a program file's stream reads back as); NumPy reads it as a words x 3 array."""

    __slots__ = ("_data",)
    width = 3          # floats a word

    def __init__(self, data: array):
        self._data = data

    @property
    def flat(self) -> array:
        """The words' floats, word after word (what vampc.jsontext.number_rows writes from)."""
        return self._data

    def __len__(self) -> int:
        return len(self._data) // 3

    def __getitem__(self, k):
        if isinstance(k, slice):
            return tuple(self)[k]
        if not -len(self) <= k < len(self):
            raise IndexError("word index out of range")
        k %= len(self)
        return tuple(self._data[3 * k:3 * k + 3])

    def __iter__(self):
        d = self._data
        return zip(d[0::3], d[1::3], d[2::3])

    def __eq__(self, other) -> bool:
        if isinstance(other, Words):
            return self._data == other._data
        if isinstance(other, tuple):
            return tuple(self) == other
        return NotImplemented

    def __hash__(self) -> int:
        return hash(tuple(self))

    def __reduce__(self):
        return (Words, (self._data,))

    def __repr__(self) -> str:
        return f"Words({list(self)!r})"

    def __array__(self, dtype=None, copy=None):
        import numpy as np
        out = np.array(self._data, dtype=np.float64).reshape(-1, 3)
        return out if dtype is None else out.astype(dtype)


@dataclass(frozen=True)
class StreamEntry:
    """Words the host writes to one input buffer in Program Mode, in order (one per tick)."""

    root: Tap                      # a "port" or "const" tap
    targets: tuple[int, ...]       # logical VAMP index of each word
    depth: tuple[int, ...]         # registers between the root and each target's Operand-A input
    words: Sequence[tuple[float, float, float]] = ()   # a tuple, or Words (as compiled)


def default_numbering(net: Network) -> tuple[int, ...]:
    """Burned-in numbers 1..V in logical order (VampcError if V does not fit the 24-bit numbers)."""
    if len(net.vamps) >= 1 << 24:
        raise VampcError(f"the network needs {len(net.vamps)} VAMPs, but VAMP numbers have 24 bits "
                         "(at most 16777215): use the linear recursion or --layout folded")
    count = len(net.vamps)
    return counting(count + 1)[1:count + 1]       # (shared ints: vampc.memo)


def extraneous_number(numbering, packing) -> int:
    """The number error correction's extraneous VAMP takes, one past the largest burned in
    (vampc.emulator.checking); VampcError when it does not fit a VAMP number or the word (a
    numbering ending at 16777215 made it 16777216, and in q9.7 32768, with no word said)."""
    largest = max(numbering)
    limit = min(1 << 24, packing.limit)
    if largest + 1 >= limit:
        # (a wider word helps only where the word's scalars, not the 24 bits, are the bound)
        wider = " or a wider --word" if packing.limit < 1 << 24 else ""
        raise VampcError(f"with --error-correction the extraneous VAMP takes number {largest + 1}, "
                         f"one past the largest burned in ({largest}), and VAMP numbers here are "
                         f"at most {limit - 1} (24 bits, and the word's Program-Mode scalars): "
                         f"give smaller numbers (--numbering){wider}")
    return largest + 1


def read_numbering(path: str | Path, count: int, limit: int | None = None) -> tuple[int, ...]:
    """VAMP numbers from a text file, one positive integer per line (blank lines and #comments
    skipped); `limit`: the Program-Mode word's (a number the network uses must be below it)."""
    from vampc.textio import ascii_digits, decode_utf8
    numbers = []
    first: dict[int, int] = {}           # each number's line
    try:
        from vampc.textio import read_whole, stdin_hint
        raw = read_whole(path, text=True)
    except OSError as exc:
        raise VampcError(f"{path}: cannot read numbering file: {exc.strerror}"
                         f"{stdin_hint(path, exc)}") from None
    lines = decode_utf8(raw, path, "numbering file").splitlines()
    for lineno, line in enumerate(lines, 1):
        text = line.split("#", 1)[0].strip()
        if not text:
            continue
        # (ASCII digits: str.isdigit() took '٣٣٣' for 333, and '²' to int() raised ValueError)
        number = int(text) if ascii_digits(text) else 0
        if not 1 <= number < 2**24:
            raise VampcError(f"{path}: line {lineno}: {text!r} is not a VAMP number (1..16777215)")
        if limit is not None and number >= limit and len(numbers) < count:
            raise VampcError(f"{path}: line {lineno}: VAMP number {text} (VAMP {len(numbers)}) does "
                             f"not fit in a {limit.bit_length()}-bit Program-Mode word (at most "
                             f"{limit - 1}); give a wider --word")
        if number in first:
            raise VampcError(f"{path}: line {lineno}: VAMP number {number} appears twice (first "
                             f"on line {first[number]})")
        first[number] = lineno
        numbers.append(number)
    if len(numbers) < count:
        raise VampcError(f"{path}: {len(numbers)} VAMP numbers given, the network needs {count}")
    if len(numbers) > count:
        import warnings

        from vampc.errors import VampcWarning
        warnings.warn(VampcWarning(f"{path}: {len(numbers)} VAMP numbers given, the network has "
                                   f"{count} VAMPs: the last {len(numbers) - count} are not used"),
                      stacklevel=2)
    return tuple(numbers[:count])


def programs(net: Network) -> tuple[tuple[Program, ...], ...]:
    """Each VAMP's program: per slot the Cycle-Counter values of its latches and dump, its ROM
    pointer and its multiplexer selects. Equal programs are one object (Programs are frozen), and so
    are equal one-slot listings: a systolic network of a million VAMPs has a few hundred distinct
    programs, and a Program and a tuple each per VAMP took 120 MB."""
    P = net.period
    known: dict[Program, Program] = {}
    alone: dict[tuple, tuple[Program]] = {}     # a one-slot listing by its slot's fields
    def program(s) -> Program:
        made = Program(s.latch_a % P, s.latch_b % P, s.dump % P, rom_pointer(s.op, s.column),
                       s.sel_a, s.sel_b)
        return known.setdefault(made, made)
    def listing(slots) -> tuple[Program, ...]:
        if len(slots) == 1:
            s = slots[0]
            key = (s.latch_a % P, s.latch_b % P, s.dump % P, s.op, s.column, s.sel_a, s.sel_b)
            made = alone.get(key)
            if made is None:
                made = alone[key] = (program(s),)
            return made
        return tuple(map(program, slots))
    return tuple([listing(v.slots) for v in net.vamps])


def a_roots(net: Network) -> tuple[list[Tap], list[int]]:
    """For every VAMP, the input buffer at the root of its Operand-A path — through input 0 of each
    operand-A multiplexer, which Program Mode passes on — and the registers in between (a register
    per VAMP passed, 1 + stage per buffer tap), as two lists (not a pair per VAMP: a million pairs
    were 60 MB). Each path is walked once: a walk stops at the first VAMP whose root is known.
    VampcError if a path loops (no input buffer could ever program those VAMPs)."""
    roots: list[Tap | None] = [None] * len(net.vamps)
    depths: list[int] = [0] * len(net.vamps)
    sources = [b.source for b in net.buffers]
    vamps = net.vamps
    for vamp in range(len(vamps)):
        if roots[vamp] is not None:
            continue
        tap = vamps[vamp].a[0].taps[0]
        if tap.kind is _VAMP and roots[tap.index] is not None:    # (the next case, in line, for
            roots[vamp] = roots[tap.index]                        # a Result's tap: 1 register)
            depths[vamp] = depths[tap.index] + 1
            continue
        src = tap_source(tap, sources)
        if src is not None and roots[src] is not None:    # one step to a known root: most VAMPs
            roots[vamp] = roots[src]
            depths[vamp] = depths[src] + _registers(tap)
            continue
        v, walked, seen = vamp, [], {vamp}
        while roots[v] is None:
            tap = net.vamps[v].a[0].taps[0]
            src = tap_source(tap, sources)
            if src is None:          # a host port or a constant buffer: the path's root
                roots[v] = Tap(tap.kind, tap.index)
                break
            if src in seen:
                raise VampcError(f"VAMP {vamp}: its Operand-A path loops back through VAMP {src}, "
                                 "so no input buffer can program it")
            seen.add(src)
            walked.append((v, _registers(tap)))
            v = src
        root, depth = roots[v], depths[v]
        for u, step in reversed(walked):
            depth += step
            roots[u], depths[u] = root, depth
    return roots, depths


def _registers(tap: Tap) -> int:
    """Registers an Operand-A path passes through a VAMP's input `tap`: the VAMP's own, and a
    buffer's stages."""
    return 1 if tap.kind is _VAMP else 1 + tap.stage


_VAMP = TapKind.VAMP          # (an Enum member read from its class: 85 ns, at every VAMP)


def bus_registers(net: Network) -> list[list[BusRegister]]:
    """Each VAMP's bus-write registers (none without a bus), in the order of network.bus.writes."""
    out: list[list[BusRegister]] = [[] for _ in net.vamps]
    if net.bus is None:
        return out
    sources = [b.source for b in net.buffers]
    for w in net.bus.writes:
        stage = w.source.stage if w.source.kind is TapKind.BUFFER else 0
        out[tap_source(w.source, sources)].append(BusRegister(w.counter, stage, w.tier))
    return out


def bus_writes(net: Network, registers, path: str = "<program>"):
    """The bus writes the VAMPs' registers make (network.bus.writes' form); VampcError naming the
    VAMP and register when one is incomplete or names a missing buffer stage or tier."""
    from vampc.network.model import BusWrite
    buffer_of = {b.source: b for b in net.buffers}
    out = []
    for v, regs in enumerate(registers):
        for j, row in enumerate(regs):
            if any(x is None for x in row):
                raise VampcError(f"{path}: VAMP {v}: bus-write register {j}: field "
                                 f"{6 + row.index(None)} is never programmed")
            counter, code = row
            stage, tier = divmod(code, TIER_CODES)
            where = f"{path}: VAMP {v}: bus-write register {j}"
            if counter >= net.period:
                raise VampcError(f"{where}: counter {counter} never matches the Cycle-Counter "
                                 f"(0..{net.period - 1})")
            if net.bus is None or tier >= len(net.bus.tiers):
                raise VampcError(f"{where}: tier {tier} does not exist")
            if stage == 0:
                tap = Tap(TapKind.VAMP, v)
            elif v in buffer_of and stage <= buffer_of[v].stages:
                tap = Tap(TapKind.BUFFER, buffer_of[v].index, stage)
            else:
                raise VampcError(f"{where}: the buffer behind it has no stage {stage}")
            out.append(BusWrite(tap, counter, tier))
    return out


def program_stream(net: Network, progs, numbering, packing=PACKING) -> tuple[StreamEntry, ...]:
    """The Program-Mode stream: per root input buffer, the words of the VAMPs it programs, deepest
    target first, each VAMP's words in the order vampc.program.words.vamp_words gives them, packed
    for the word format (vampc.program.words.Packing)."""
    by_root: dict[Tap, list[int]] = {}         # per root, its VAMPs in index order
    roots, depth_of = a_roots(net)             # per VAMP, the registers before it
    for index, root in zip(counting(len(net.vamps)), roots):   # (shared ints: vampc.memo)
        by_root.setdefault(root, []).append(index)
    entries = []
    # a one-slot listing's two fields (None if not compact), by the listing's identity: programs
    # interns them, and a Program's hash is worked out anew each time
    compact: dict[int, tuple[float, float] | None] = {}
    limit = packing.limit
    registers = bus_registers(net) if net.bus is not None else None
    for root in sorted(by_root, key=lambda t: (t.kind, t.index)):
        targets, depths, words = [], [], array("d")
        # deepest first, then by index (a stable sort keeps the index order of equal depths)
        for v in sorted(by_root[root], key=depth_of.__getitem__, reverse=True):
            slots, number = progs[v], numbering[v]
            pair = None
            regs = registers[v] if registers is not None else ()   # bus-write registers
            if len(slots) == 1 and not regs:    # the common, systolic case: one compact word
                pair = compact.get(id(slots), compact)
                if pair is compact:             # (worked out once per distinct listing)
                    prog = slots[0]
                    pair = compact[id(slots)] = (compact_fields(prog, packing)
                                                 if prog.sel_a == prog.sel_b == 0 else None)
            if pair is not None and 0 < number < limit:        # encode's word, in line
                targets.append(v)
                depths.append(depth_of[v])
                words.extend((float(number), pair[0], pair[1]))
                continue
            if len(slots) == 1 and slots[0].sel_a == slots[0].sel_b == 0 and \
                    fits_compact(slots[0], packing):
                mine = [encode(number, slots[0], packing)]     # (says what does not fit)
            else:
                vamp = net.vamps[v]
                mine = vamp_words(number, slots, packing, (len(vamp.a), len(vamp.b)))
            if regs:                            # after the slot words (vampc.program.words)
                mine = mine + bus_words(number, regs, packing)
            targets.extend([v] * len(mine))
            depths.extend([depth_of[v]] * len(mine))
            for word in mine:
                if len(word) != 3:
                    raise VampcInternalError(f"VAMP {v}: a program word of {len(word)} fields")
                words.extend(word)
        entries.append(StreamEntry(root, tuple(targets), tuple(depths), Words(words)))
    return tuple(entries)


def load_ticks(stream: tuple[StreamEntry, ...]) -> int:
    """Ticks of Program Mode needed for every VAMP to have latched its words."""
    return max((max(map(operator.add, range(1, len(e.depth) + 1), e.depth)) for e in stream
                if e.depth), default=0)
