"""Program words: the one place where VAMP programs are packed and unpacked
(README, *Program file*).

A VAMP's program is a table of slots. Each slot is the paper's four control fields — delay-A,
delay-B, delay-R (Cycle-Counter values at which operand A is latched, operand B is latched and the
Result is driven) and a ROM pointer (which micro-sequence of Table VII.1 runs) — plus two multiplexer
selects, sel-A and sel-B (which of the VAMP's operand inputs the slot latches). In Program Mode a word
travels as one 3-scalar vector, of one of two kinds:

    compact    scalar 1  VAMP-number (burned in; 1..16777215)
               scalar 2  delay-A · 4096 + delay-B
               scalar 3  delay-R · 4096 + ROM-pointer
               Sets the slot table to exactly one slot with these fields and both selects 0. It is the
               paper's word, and all a systolic VAMP ever gets.

    extended   scalar 1  -(VAMP-number)
               scalar 2  slot · 8 + field   (field 0 delay-A, 1 delay-B, 2 delay-R, 3 ROM, 4 sel-A,
                                             5 sel-B)
               scalar 3  the field's value
               Sets one field of one slot; writing slot k makes the table at least k + 1 slots long.

A VAMP gets its compact word first, then an extended word for every field of slot 0 the compact word
cannot carry (a delay of 4096 or more in a long period, a select other than 0) and for all six fields
of every further slot.

On the Mostly-Local Bus a VAMP also has bus-write registers (vampc.network.bus), addressed by the
two fields an extended word's slot address leaves free: field 6 of address j is register j's
Cycle-Counter value, field 7 its source · 64 + tier (source 0: the VAMP's Result; s ≥ 1: stage s
of the delay buffer behind it). They follow the slot words. A compact word clears them, as it
clears the slot table, so a VAMP driving no bus holds none after Program Mode. Every scalar is an integer below 2^24 in magnitude, exact in IEEE binary32 or
binary64.

Narrow words (`Packing`). A fixed-point word of W bits carries a scalar as its raw bits, so below
2^(W-1) (the sign bit); a float word of a p-bit significand holds the integers below 2^p exactly.
Where that bound, 2^b, is below 2^24 (W < 25; p < 24), the compact word's two fields per scalar
shrink to ⌊b/2⌋ bits each (4096 becomes 2^⌊b/2⌋ above), and whatever does not fit travels in
extended words, whose values must then be below 2^b: more words per VAMP, the same tables
delivered. The packing follows from the word format the program records (its `program_bits`, b);
float64, float32 and fixed words of 25 bits or more use the one above.
"""
from __future__ import annotations

from msgspec import Struct

from vampc.errors import VampcError
from vampc.machine.ops import ROM, rom_pointer  # noqa: F401  (the ROM is the op table's)

FIELD = 4096
LIMIT = 1 << 24


class Packing(Struct, frozen=True):
    """How wide a Program-Mode scalar may be: each compact field below `field`, every scalar below
    `limit` in magnitude."""

    field: int = FIELD
    limit: int = LIMIT

    @staticmethod
    def of(word) -> "Packing":
        """The packing a word format carries (see the module docstring): from the integers its
        words hold exactly (`program_bits`: a float's significand, a fixed word's bits below the
        sign), so a format added to vampc.machine.arith packs as it must."""
        bits = getattr(word, "program_bits", 53)        # (None: float64)
        if bits >= LIMIT.bit_length() - 1:
            return PACKING
        return Packing(1 << (bits // 2), 1 << bits)


PACKING = Packing()
FIELDS = ("delay_a", "delay_b", "delay_r", "rom", "sel_a", "sel_b")


def counter_bits(period: int) -> int:
    """A Cycle-Counter's bits: it counts 0 .. P (P in the tick before Global-Reset returns it to 0),
    so P.bit_length() bits."""
    return max(1, int(period).bit_length())


def values_bits(values: int) -> int:
    """Bits to tell `values` things apart (0 for one): a ROM pointer's, a select's."""
    return (int(values) - 1).bit_length()


def rom_pointer_bits() -> int:
    """A ROM pointer's bits: one of the ROM's entries (the op table's, which may grow: asked each
    time)."""
    return values_bits(len(ROM))


def field_widths(period: int, inputs_a: int, inputs_b: int) -> tuple[int, ...]:
    """A slot's control fields (FIELDS' order) in bits, as the hardware holds them: each delay as
    wide as the Cycle-Counter it is compared with, the ROM pointer as the ROM's entries need, each
    select as its multiplexer's `inputs_a`/`inputs_b` inputs need (none for one input: nothing to
    select). The one definition the report counts (vampc.report.counts), the RTL builds
    (vampc.rtl.design) and the fault model's control bits are (vampc.emulator.faults): faults had
    taken every field as 24 bits, and the RTL a select of one input as one bit that nothing read
    (a new user's find)."""
    counter = counter_bits(period)
    return (counter, counter, counter, rom_pointer_bits(), values_bits(inputs_a),
            values_bits(inputs_b))
ADDRESS = 8          # addresses per slot in an extended word


class Program(Struct, frozen=True, gc=False):
    """One slot's control registers (a frozen msgspec Struct, like the network's records)."""

    delay_a: int
    delay_b: int
    delay_r: int
    rom: int
    sel_a: int = 0
    sel_b: int = 0

    def field(self, name: str) -> int:
        """A field by name (FIELDS)."""
        return getattr(self, name)


def number_problem(number: int, packing: Packing = PACKING) -> str | None:
    """Why VAMP number `number` cannot travel in the packing's Program-Mode words, or None."""
    if 0 < number < packing.limit:
        return None
    return (f"VAMP number {number} does not fit in a {packing.limit.bit_length()}-bit Program-Mode "
            f"word (at most {packing.limit - 1})")


def encode(number: int, prog: Program, packing: Packing = PACKING) -> tuple[float, float, float]:
    """The compact Program-Mode word carrying `prog` (delays below the packing's field) for VAMP
    `number`."""
    problem = number_problem(number, packing)
    if problem:
        raise VampcError(f"{problem}; give a wider --word")
    fields = compact_fields(prog, packing)
    if fields is None:
        name = next(n for n in ("delay_a", "delay_b", "delay_r", "rom")
                    if not 0 <= prog.field(n) < packing.field)
        raise VampcError(f"VAMP {number}: {name} {prog.field(name)} does not fit in a word")
    return (float(number), *fields)


def compact_fields(prog: Program, packing: Packing = PACKING) -> tuple[float, float] | None:
    """The two fields after the VAMP-number of `prog`'s compact word (delays and ROM pointer packed
    in pairs), or None when one of them does not fit (encode says which)."""
    F = packing.field
    if not all(0 <= prog.field(n) < F for n in ("delay_a", "delay_b", "delay_r", "rom")):
        return None
    return float(prog.delay_a * F + prog.delay_b), float(prog.delay_r * F + prog.rom)


def decode(word, packing: Packing = PACKING) -> tuple[int, Program]:
    """(VAMP-number, program) from a compact word; inverse of encode."""
    F = packing.field
    number, s2, s3 = (int(x) for x in word[:3])
    return number, Program(s2 // F, s2 % F, s3 // F, s3 % F)


def fits_compact(prog: Program, packing: Packing = PACKING) -> bool:
    """Whether a compact word can carry `prog`'s delays and ROM pointer."""
    return all(prog.field(n) < packing.field for n in ("delay_a", "delay_b", "delay_r", "rom"))


def vamp_words(number: int, slots: tuple[Program, ...], packing: Packing = PACKING,
               inputs: tuple[int, int] | None = None) -> list[tuple[float, float, float]]:
    """Every word that programs VAMP `number` with `slots`, in the order they must arrive.
    `inputs`: its operand-A and operand-B multiplexers' input counts; a select of a multiplexer of
    one input has no register (field_widths), so no word is sent for it: it is always 0 (until
    2026-12-07 every slot after the first had both select words, which the RTL ignored: planar2
    folded loaded 210 words in 119 ticks where 171 in 92 program it, a hardware user's find).
    None: every select has a register."""
    first = slots[0]
    muxed = (True, True) if inputs is None else (inputs[0] > 1, inputs[1] > 1)
    rom_fits = first.rom < packing.field
    delays_fit = rom_fits and all(first.field(n) < packing.field
                                  for n in ("delay_a", "delay_b", "delay_r"))
    words = [encode(number, first if delays_fit else
                    Program(0, 0, 0, first.rom if rom_fits else 0), packing)]
    for k, slot in enumerate(slots):
        for f, name in enumerate(FIELDS):
            value = slot.field(name)
            if k == 0 and (name in ("sel_a", "sel_b") and value == 0 or name == "rom" and rom_fits
                           or name in ("delay_a", "delay_b", "delay_r") and delays_fit):
                continue     # carried by the compact word
            if name == "sel_a" and not muxed[0] or name == "sel_b" and not muxed[1]:
                if value:
                    raise VampcError(f"VAMP {number}: slot {k} {name} {value} selects no input "
                                     "of its multiplexer of one input")
                continue     # no register: always input 0
            if not 0 <= value < packing.limit:
                raise VampcError(f"VAMP {number}: slot {k} {name} {value} does not fit in a word")
            if k * ADDRESS + f >= packing.limit:
                raise VampcError(f"VAMP {number}: slot {k} is beyond what a "
                                 f"{packing.limit.bit_length()}-bit Program-Mode word addresses "
                                 f"(slots 0..{(packing.limit - 1) // ADDRESS}); give a wider --word")
            words.append((float(-number), float(k * ADDRESS + f), float(value)))
    return words


WRITE_FIELDS = (6, 7)   # an extended word's fields for bus-write register j (address j · 8 + f)
TIER_CODES = 64         # tiers per source code in field 7


class BusRegister(Struct, frozen=True, gc=False):
    """One bus-write register as Program Mode delivers it: at Cycle-Counter `counter` drive the
    bus of tier `tier` with `source` (0: the Result; s: stage s of the VAMP's delay buffer)."""

    counter: int
    source: int
    tier: int


def bus_words(number: int, registers, packing: Packing = PACKING) -> list[tuple[float, float, float]]:
    """The extended words that load VAMP `number`'s bus-write registers (after its slot words)."""
    words = []
    for j, r in enumerate(registers):
        for f, value in zip(WRITE_FIELDS, (r.counter, r.source * TIER_CODES + r.tier)):
            if not 0 <= value < packing.limit or j * ADDRESS + f >= packing.limit:
                raise VampcError(f"VAMP {number}: bus-write register {j} does not fit in a "
                                 f"{packing.limit.bit_length()}-bit Program-Mode word; give a "
                                 "wider --word")
            words.append((float(-number), float(j * ADDRESS + f), float(value)))
    return words


def word_number(word) -> int:
    """The VAMP number a word addresses (its own or negated), or -1 if scalar 1 is not an integer."""
    x = float(word[0])
    return abs(int(x)) if x.is_integer() and x != 0 else -1


def apply_word(table: list[list[int]] | None, word, packing: Packing = PACKING,
               writes: list | None = None) -> list[list[int]]:
    """The slot table after a VAMP latches `word` (addressed to it): a compact word replaces the
    table with one slot; an extended word sets one field of `table` (in place), growing it to reach
    its slot. The
    fields of a new slot hold whatever the registers held before: None here (the loader refuses a
    program that leaves one so); the tick engine keeps its random register contents there. Rows are
    [delay-A, delay-B, delay-R, ROM, sel-A, sel-B]. `writes`: the VAMP's bus-write registers as
    [counter, field 7] rows, updated in place (cleared by a compact word, grown by fields 6 and 7;
    None: such words are ignored)."""
    if float(word[0]) > 0:
        _, p = decode(word, packing)
        if writes is not None:
            writes.clear()
        return [[p.delay_a, p.delay_b, p.delay_r, p.rom, 0, 0]]
    address, value = int(word[1]), int(word[2])
    slot, f = divmod(address, ADDRESS)
    if slot < 0:
        raise VampcError(f"an extended word's address {address} names no slot")
    table = table if table is not None else []     # updated in place: a VAMP has many words
    if f in WRITE_FIELDS:
        if writes is not None:
            while len(writes) <= slot:
                writes.append([None, None])
            writes[slot][f - WRITE_FIELDS[0]] = value
        return table
    while len(table) <= slot:
        table.append([None] * 6)
    if f < len(FIELDS):
        table[slot][f] = value
    return table


def programs_of(table: list[list[int]]) -> tuple[Program, ...]:
    """The slot table as Programs."""
    return tuple(Program(*row) for row in table)
