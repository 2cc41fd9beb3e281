"""Faults injected into the tick engine (`vampc emulate --engine tick --fault SPEC`): the fault model
of the error-correction work (section VII), on the registers the engine holds.

A fault is comma-separated key=value fields:

    vamp=N           the VAMP, by logical index (as messages name it: "VAMP 12 (number 13, ...)")
    stuck=REG:BIT    permanent: bit BIT of register REG holds `value` from Data-Mode tick `at` on
    flip=REG:BIT     transient: bit BIT of REG flips once, at the end of Data-Mode tick `at`
    dead             the VAMP's outputs tri-state from tick `at` on: its Result shows no set's value
    value=0|1        the stuck-at value (stuck only; default 0)
    at=T             the Data-Mode tick the fault starts (stuck, dead: default 0) or happens (flip:
                     required)
    rate=F           intermittent: a stuck fault on a Result or operand register active in a random
                     fraction F of the cycles (0 < F < 1; drawn from the engine's --seed)

Registers: `result.x`, `result.y`, `result.z` (the Result's three scalars); `a.K`, `b.K` (operand
registers A and B, scalar K of 0..8, or x, y, z for 0..2); `control.FIELD` or `control.FIELD.SLOT`,
FIELD one of delay_a, delay_b, delay_r, rom, sel_a, sel_b (each as wide as the hardware holds it:
control_widths; slot 0 by default);
`control2.FIELD[.SLOT]`, with error correction, the second set (the copy of the successor's). A
flipped control bit stays flipped: the registers are written only in Program Mode.

Bits count from 0, the least significant, in the word as the network's format holds it: a float
format's IEEE bit pattern (binary64, binary32, of its dtype's size), or a fixed-point word's
two's-complement raw bits (a stuck or
flipped bit of a qI.F word is a bit of the real word). How the engine applies them: a Result fault
after the tick's dumps (the register holds it until the next dump), an operand fault after the
tick's latches, a control fault by changing the field the slot tables hold (the engine's slot
arrays are made again), a dead VAMP by leaving its Result row undriven (random contents, no set's
value) every tick.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vampc.program.words import FIELDS
from vampc.textio import ascii_digits

REGISTERS = ("result", "a", "b", "control", "control2")


class NoSuchRegister(ValueError):
    """A well-formed fault naming a register no VAMP has (a VampcError, exit 1, not a usage error)."""
AXES = {"x": 0, "y": 1, "z": 2}


@dataclass(frozen=True)
class Fault:
    """One fault (see the module docstring)."""

    vamp: int
    kind: str                 # "stuck", "flip" or "dead"
    register: str = ""        # "result", "a", "b", "control"
    component: int = 0        # a scalar of the register, or a control field's index in FIELDS
    slot: int = 0             # control faults: the slot
    bit: int = 0
    value: int = 0
    at: int = 0
    rate: float | None = None
    text: str = ""

    def active(self, t: int, period: int, rng_draws) -> bool:
        """Whether the fault holds at Data-Mode tick t (an intermittent one: in this cycle)."""
        if t < self.at:
            return False
        if self.rate is None:
            return True
        return bool(rng_draws(t // period) < self.rate)


def parse_fault(text: str) -> Fault:
    """A --fault SPEC as a Fault; ValueError saying what is wrong with it."""
    fields: dict[str, str] = {}
    for part in text.split(","):
        key, sep, value = part.strip().partition("=")
        if not key:
            continue
        if key in fields:
            raise ValueError(f"--fault {text!r}: {key} given twice")
        fields[key] = value if sep else ""
    known = {"vamp", "stuck", "flip", "dead", "value", "at", "rate"}
    extra = sorted(set(fields) - known)
    if extra:
        raise ValueError(f"--fault {text!r}: unknown field {extra[0]!r} (give vamp=, stuck= or "
                         "flip= or dead, and value=, at=, rate=)")
    kinds = [k for k in ("stuck", "flip", "dead") if k in fields]
    if len(kinds) != 1:
        raise ValueError(f"--fault {text!r}: give one of stuck=REG:BIT, flip=REG:BIT or dead")
    kind = kinds[0]
    if "vamp" not in fields:
        raise ValueError(f"--fault {text!r}: give vamp=N (the VAMP's index)")
    vamp = _whole(fields["vamp"], "vamp", text)
    at = _whole(fields["at"], "at", text) if "at" in fields else None
    if kind == "flip" and at is None:
        raise ValueError(f"--fault {text!r}: a flip happens at one tick: give at=T")
    rate = None
    if "rate" in fields:
        try:
            rate = float(fields["rate"])
        except ValueError:
            rate = -1.0
        if not 0 < rate < 1 or kind != "stuck":
            raise ValueError(f"--fault {text!r}: rate=F (0 < F < 1) makes a stuck fault "
                             "intermittent")
    if "value" in fields and (kind != "stuck" or fields["value"] not in ("0", "1")):
        raise ValueError(f"--fault {text!r}: value=0 or value=1 is a stuck fault's value")
    if kind == "dead":
        if fields["dead"]:
            raise ValueError(f"--fault {text!r}: dead takes no value")
        return Fault(vamp, "dead", at=at or 0, text=text)
    register, component, slot, bit = _register(fields[kind], text)
    if rate is not None and register in ("control", "control2"):
        raise ValueError(f"--fault {text!r}: rate= applies to Result and operand registers")
    return Fault(vamp, kind, register, component, slot, bit, int(fields.get("value", "0")),
                 at or 0, rate, text)


def canonical(faults) -> tuple:
    """The faults in the order the tick engine applies them, whatever order they were given in
    (each draws its intermittent cycles by its place, and two acting on one register in one tick
    act in turn: swapping two --fault options changed the torques, a review found): by VAMP and
    register, a dead VAMP's fault last, so its undriven outputs hide a bit stuck before it died,
    as the hardware's would."""
    return tuple(sorted(faults, key=lambda f: (f.kind == "dead", f.vamp, f.register, f.component,
                                               f.slot, f.bit, f.kind, f.at, f.value, f.rate or 0.0)))


def check_conflicts(faults) -> None:
    """ValueError naming two faults that fight over one thing at one time, or one of which does
    nothing: a fault on a VAMP from the tick it is dead on (its outputs tri-stated; a second dead
    fault, later, too); one bit stuck at 0 and at 1 (a control field's, at one tick: those are
    set once, at their tick); a bit stuck from the same tick or earlier at the same value, for good
    (the later does nothing); a flip of a bit at or after the tick it is stuck from; a fault given
    twice, however spelled (two flips of one bit at one tick, which cancel). Faults on one bit or
    VAMP at other times run (a review: a stuck bit before the VAMP dies, a flip before the bit
    sticks had been refused), in the order `canonical` gives, so the order given does not matter."""
    from dataclasses import replace
    for k, f in enumerate(faults):
        for g in faults[:k]:
            if f.vamp != g.vamp:
                continue
            both = f"--fault {g.text!r} and --fault {f.text!r}"
            if replace(f, text="") == replace(g, text=""):
                raise ValueError(f"{both}: the same fault given twice (a fault is injected once)")
            if "dead" in (f.kind, g.kind):
                dead, other = (f, g) if f.kind == "dead" and (g.kind != "dead" or f.at <= g.at) \
                    else (g, f)
                if other.at >= dead.at:
                    raise ValueError(f"{both}: VAMP {f.vamp} is dead from tick {dead.at} (its outputs "
                                     f"tri-stated), so --fault {other.text!r} does nothing; give it "
                                     "an earlier at= or leave it out")
                continue
            if (f.register, f.component, f.slot, f.bit) != (g.register, g.component, g.slot, g.bit):
                continue
            control = f.register in ("control", "control2")     # (set once, at the fault's tick)
            if f.kind == g.kind == "flip" or (control and f.at != g.at):
                continue             # (at other ticks, one after the other: at one, given twice)
            if f.kind == g.kind == "stuck":
                if f.value != g.value:
                    raise ValueError(f"{both}: the same bit of VAMP {f.vamp} stuck at 0 and at 1"
                                     + (" at one tick" if control else "") + "; give one of them")
                first, then = (f, g) if (f.at, f.rate is not None) <= (g.at, g.rate is not None) \
                    else (g, f)
                if first.rate is None:
                    raise ValueError(f"{both}: the same bit of VAMP {f.vamp} stuck at {f.value} "
                                     f"from tick {first.at}, so --fault {then.text!r} does nothing; "
                                     "give one of them")
            else:
                stuck, flip = (f, g) if f.kind == "stuck" else (g, f)
                if flip.at >= stuck.at:
                    raise ValueError(f"{both}: the bit of VAMP {f.vamp} is stuck from tick "
                                     f"{stuck.at}, so a flip at tick {flip.at} does nothing or "
                                     "fights it; flip it before the tick it sticks, or give one")


def _whole(value: str, key: str, text: str) -> int:
    if not ascii_digits(value):
        raise ValueError(f"--fault {text!r}: {key}={value!r} is not a whole number")
    return int(value)


def _register(spec: str, text: str) -> tuple[str, int, int, int]:
    """(register, component, slot, bit) of REG:BIT."""
    reg, sep, bit = spec.partition(":")
    if not sep or not ascii_digits(bit):
        raise ValueError(f"--fault {text!r}: give REGISTER:BIT, e.g. result.z:62")
    parts = reg.split(".")
    name = parts[0]
    if name == "result" and len(parts) == 2 and parts[1] in AXES:
        return "result", AXES[parts[1]], 0, int(bit)
    if name in ("a", "b") and len(parts) == 2 and (parts[1] in AXES or ascii_digits(parts[1])):
        k = AXES[parts[1]] if parts[1] in AXES else int(parts[1])
        if k < 9:
            return name, k, 0, int(bit)
    if name in ("control", "control2") and len(parts) in (2, 3) and parts[1] in FIELDS and (
            len(parts) == 2 or ascii_digits(parts[2])):
        return name, FIELDS.index(parts[1]), int(parts[2]) if len(parts) == 3 else 0, int(bit)
    raise NoSuchRegister(f"--fault {text!r}: {reg!r} is no register (result.x|y|z, a.K, b.K with K "
                     f"0..8 or x|y|z, control.FIELD[.SLOT] or, with error correction, control2.FIELD[.SLOT], "
                         f"with FIELD one of {', '.join(FIELDS)})")


def check_faults(faults, ld, last_tick: int) -> None:
    """Each fault names what the loaded network has (VampcError naming the fault otherwise)."""
    from vampc.errors import VampcError
    word_bits = ld.arith.bits
    for f in faults:
        where = f"--fault {f.text!r}"
        V = len(ld.net.vamps) + (ld.net.checking is not None)   # with checking: E is VAMP V
        if not 0 <= f.vamp < V:
            raise VampcError(f"{where}: there is no VAMP {f.vamp} (0..{V - 1})")
        if f.at > last_tick:
            raise VampcError(f"{where}: tick {f.at} is after the run's last tick ({last_tick})")
        if f.kind == "dead":
            continue
        if f.register == "control" and f.vamp == len(ld.net.vamps):
            raise VampcError(f"{where}: the extraneous VAMP {f.vamp} has no control registers of "
                             "its own (its second set is its successor's)")
        if f.register not in ("control", "control2"):
            if f.bit >= word_bits:
                raise VampcError(f"{where}: bit {f.bit}: the register has {word_bits} bits "
                                 f"(0..{word_bits - 1})")
        if f.register == "control2":
            order = ld.net.checking.order if ld.net.checking is not None else ()
            if f.vamp not in order[:-1]:
                # (the last VAMP of a checked network was told to compile --error-correction, as
                # it had: a hardware audit) which case it is, said
                why = ("this program has no error correction (compile --error-correction)"
                       if not order else f"VAMP {f.vamp} is the last of the chain, with no successor")
                raise VampcError(f"{where}: control2 is the second set of control registers a "
                                 f"VAMP with a successor holds under error correction: {why}")
            owner = succ = order[order.index(f.vamp) + 1]     # (its fields are the successor's)
            if f.slot >= len(ld.programs[succ]):
                raise VampcError(f"{where}: VAMP {f.vamp}'s second set copies VAMP {succ}'s "
                                 f"{len(ld.programs[succ])} slot(s): no slot {f.slot}")
        if f.register == "control":
            owner = f.vamp
            if f.slot >= len(ld.programs[f.vamp]):
                raise VampcError(f"{where}: {ld.vamp_name(f.vamp)} has "
                                 f"{len(ld.programs[f.vamp])} slot(s), no slot {f.slot}")
        if f.register in ("control", "control2"):
            field, bits = FIELDS[f.component], control_widths(ld, owner)[f.component]
            if f.bit >= bits:
                held = (f"no bits: VAMP {owner}'s {'A' if field == 'sel_a' else 'B'} multiplexer "
                        "has one input, nothing to select" if bits == 0 else
                        f"{bits} bit{'s' * (bits > 1)} (0..{bits - 1})")
                raise VampcError(f"{where}: bit {f.bit}: {field} has {held}, as the hardware "
                                 "holds it (README, Faults)")


def control_widths(ld, v: int) -> tuple[int, ...]:
    """VAMP v's control fields (FIELDS' order) in bits, as the hardware holds them
    (vampc.program.words.field_widths: the report counts them, the RTL builds them)."""
    from vampc.program.words import field_widths
    vamp = ld.net.vamps[v]
    return field_widths(ld.net.period, len(vamp.a), len(vamp.b))


def set_bit(word, values: np.ndarray, bit: int, how: str) -> np.ndarray:
    """`values` (words of the format `word`) with bit `bit` set to 1 ("set"), 0 ("clear") or
    flipped ("flip"), as the hardware word holds it."""
    if np.dtype(word.dtype).kind == "i":            # fixed point: two's complement, `bits` wide
        width = word.bits
        raw = values.astype(np.int64) & np.int64((1 << width) - 1 if width < 64 else -1)
        mask = np.int64(1 << bit) if bit < 63 else np.int64(-(1 << 63))
        raw = _apply(raw, mask, how)
        if width < 64:                               # sign-extend from bit width - 1 (at 63 bits,
            shift = np.int64(64 - width)             # raw - 2**63 was out of int64's reach)
            raw = (raw << shift) >> shift
        return raw.astype(np.int64)
    dtype = np.dtype(word.dtype)                     # a float word: its IEEE bits, of its size
    u = np.ascontiguousarray(values, dtype=dtype).view(f"u{dtype.itemsize}")
    out = _apply(u, u.dtype.type(1 << bit), how).view(dtype)
    return out.astype(values.dtype, copy=False)


def _apply(u, mask, how: str):
    if how == "set":
        return u | mask
    if how == "clear":
        return u & ~mask
    return u ^ mask


def set_field(value: int, bit: int, how: str) -> int:
    """A control field with one bit (within its width: check_faults) set, cleared or flipped."""
    mask = 1 << bit
    return value | mask if how == "set" else value & ~mask if how == "clear" else value ^ mask
