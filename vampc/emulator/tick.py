"""The tick engine: the VAMP network clocked one flop at a time. It is the executable specification.

State: every VAMP's operand registers (9 scalars each), its three primitive modules' MULT-1, MULT-2 and
ADDER, its Result register and its slot table (per slot delay-A, delay-B, delay-R, ROM pointer, sel-A,
sel-B); every buffer stage; every host port and constant buffer. All of it starts random (Program Mode
must work from any state, including slot tables of any length).

Order of events in one tick (every register updates at the end of the tick, from values visible during
it):

Program Mode (Global-Reset held true; every multiplexer passes its input 0)
  1. the host writes the next word of each input buffer's stream (then null words);
  2. every VAMP copies the word on its operand-A input 0 to its Result, and if the word carries its
     number applies it to its slot table (vampc.program.words.apply_word: a compact word replaces the
     table, an extended word sets one field; a table grown by it keeps random fields until written);
  3. every buffer stage takes its input.

Data Mode (Global-Reset pulses every P ticks: Cycle-Counter c = tick mod P)
  1. at the start of each block of B ticks the host writes every port entry due in that block, for
     the set it belongs to;
  2. a VAMP latches operand A from input sel-A of each slot whose delay-A is c, operand B likewise
     (a latch is seen by a micro-step in the same tick);
  3. the micro-steps due at c run: step j of a slot runs at the last tick of its span, the spans
     ending at delay-R (vampc.machine.ops.Timing.step_ends);
  4. a VAMP with a slot whose delay-R is c drives its result register onto Result (visible from the
     next tick);
  5. at the last tick of a block every buffer stage takes its input (stage 1 its VAMP's Result).

Beside the data, every value carries a tag: the torque set it belongs to (-1 unknown, -2 constant). A
slot starting its op with operands of two different sets is a timing violation; so is, in the steady
state (from the tick set 0's last op is done — its torques are due by then — until the last set has
entered), starting an op on an operand that holds no set's value (never latched, or latched from a source that had none); an operand
re-latched with another set while a later micro-step still reads it; and a torque read at its scheduled
tick must carry the set the host expects. Likewise every operand register remembers which slot last
latched it: from the second period on, an op must read operands its own slot latched. The tags and owners are
observation only; they never change a value.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from vampc.emulator.load import Loaded
from vampc.errors import VampcError
from vampc.kinds import TapKind, unhandled
from vampc.machine import interp as rom
from vampc.machine.arith import canonical_nan
from vampc.machine.timing import captures, port_writes, step_counter
from vampc.program.words import (
    ADDRESS,
    ROM,
    TIER_CODES,
    WRITE_FIELDS,
    Program,
    apply_word,
    word_number,
)

UNKNOWN, CONST = -1, -2
count_nonzero = np.count_nonzero    # (a C function: ndarray.any() goes through Python)


@dataclass
class TickStats:
    """What the tick engine observed."""

    load_ticks: int = 0
    data_ticks: int = 0
    first_set_tick: int | None = None              # tick at which set 0's last torque was read
    appear: list = field(default_factory=list)     # per set: tick its last torque was read


def held_selects(vamp, sel_a: int, sel_b: int) -> tuple[int, int]:
    """The selects `vamp`'s multiplexers act on, from its slot table's fields: a multiplexer of one
    input has no select register and passes input 0 whatever the field holds (no word is written
    to it: vampc.program.words.vamp_words)."""
    return (sel_a if len(vamp.a) > 1 else 0), (sel_b if len(vamp.b) > 1 else 0)


class TickEngine:
    """A network loaded from a program file, ready to be programmed and run."""

    CHECKS = False        # a checker compares Results bit for bit (CheckingTickEngine)

    def __init__(self, ld: Loaded, seed: int = 0, vcd=None, faults=(), strict: bool | None = None):
        self.ld, self.P, self.B = ld, ld.net.period, ld.net.clock
        self.rng = np.random.default_rng(seed)
        self.vcd = vcd
        from vampc.emulator.faults import canonical
        self.faults = canonical(faults)    # injected in Data Mode (vampc.emulator.faults)
        # timing violations seen in the set tags are errors; with faults injected they are what
        # the faults do, and the torques say what came of them
        self.strict = not self.faults if strict is None else strict
        # the tags feed the timing checks and a fixed-point word's overflow count (once a set);
        # a float64 run with faults needs neither
        self.tagged = self.strict or ld.word is not None
        self.word = ld.arith
        # Results held as arith.result defines them (a NaN canonical) at every dump where their bits
        # are seen beyond the torques: a fault on a register, a checker's comparator (checking), a
        # waveform; else the torques are made so at the end, the same bits (a NaN goes on being
        # NaN), without a check on every dump (it cost a plain run 5-15%)
        self.held = bool(self.faults) or vcd is not None or self.CHECKS
        self.fault_rng = np.random.default_rng([seed, 0xFA])
        self._layout()
        self._random_state()

    # --- construction -------------------------------------------------------------------------
    def _layout(self) -> None:
        ld = self.ld
        V = len(ld.net.vamps)
        self.stage_row, row = {}, V
        for b in ld.net.buffers:
            for s in range(1, b.stages + 1):
                self.stage_row[(b.index, s)] = row
                row += 1
        # Stage s of a buffer takes stage s - 1 (stage 1 takes its VAMP's Result). A buffer's
        # stages are consecutive rows, so the stage rows move down one row as a block and each
        # buffer's first row then takes its VAMP's Result.
        self.stages = (V, row)
        self.first_row = np.array([self.stage_row[(b.index, 1)] for b in ld.net.buffers
                                   if b.stages], dtype=np.int64)
        self.first_src = np.array([b.source for b in ld.net.buffers if b.stages], dtype=np.int64)
        # Program Mode moves words only along operand A's input 0: the buffers read there (rows
        # and first row, source) are the ones whose shifting Program Mode can see; the others
        # hold power-on contents of no set whether they shift or not, so they are left alone then
        read0 = {v.a[0].taps[0].index for v in ld.net.vamps if v.a[0].taps[0].kind is TapKind.BUFFER}
        self.program_buffers = [(self.stage_row[(b.index, 1)], self.stage_row[(b.index, b.stages)] + 1,
                                 b.source) for b in ld.net.buffers if b.index in read0 and b.stages]
        self.port_row = {p.index: row + k for k, p in enumerate(ld.net.ports)}
        row += len(ld.net.ports)
        self.const_row = {c.index: row + k for k, c in enumerate(ld.net.consts)}
        row += len(ld.net.consts)
        # the Mostly-Local Bus: a row per bus of every tier, driven afresh every tick
        self.bus_row: dict[tuple[int, int], int] = {}
        bus = ld.net.bus
        for k, tier in enumerate(bus.tiers if bus is not None else ()):
            for b in range(tier.bus_at(0), tier.bus_at(V - 1) + 1):
                self.bus_row[(k, b)] = row
                row += 1
        self.buses = (row - len(self.bus_row), row)
        self.rows = row
        self.V = V
        self.input0 = np.array([self._row(v.a[0].taps[0], v.index) for v in ld.net.vamps],
                               dtype=np.int64)
        self.numbers = np.array(ld.numbers, dtype=float)

    def _row(self, tap, reader: int) -> int:
        """The row `tap` reads; a bus tap, the bus of its tier in front of VAMP `reader`."""
        if tap.kind is TapKind.VAMP:
            return tap.index
        if tap.kind is TapKind.BUFFER:
            return self.stage_row[(tap.index, tap.stage)]
        if tap.kind is TapKind.PORT:
            return self.port_row[tap.index]
        if tap.kind is TapKind.CONST:
            return self.const_row[tap.index]
        if tap.kind is TapKind.BUS:
            bus = self.ld.net.bus
            return self.bus_row[(tap.index, bus.tiers[tap.index].bus_at(bus.position[reader]))]
        return unhandled(tap.kind)

    def _root_row(self, root) -> int:
        """The bus row of an input buffer at the root of a Program-Mode stream."""
        match root.kind:
            case TapKind.PORT:
                return self.port_row[root.index]
            case TapKind.CONST:
                return self.const_row[root.index]
            case _:
                return unhandled(root.kind)

    def _gather(self, operand, reader: int):
        """Rows and columns of an operand's nine scalars, and the rows carrying its set tags."""
        r = [self._row(x, reader) for x in operand.taps]
        if len(r) == 3:   # matrix as three columns: element (i, j) is scalar i of column j
            return [r[j] for i in range(3) for j in range(3)], [i for i in range(3) for j in range(3)], r
        return [r[0]] * 9, list(range(9)), r * 3

    def _random_state(self) -> None:
        rng, V, word = self.rng, self.V, self.ld.arith
        # every register holds words of the network's format (vampc.machine.arith)
        self.bus = word.random(rng, (self.rows, 9), 1e3)
        # Some registers start out looking like program words for real VAMPs.
        fake = rng.random(self.rows) < 0.5
        self.bus[fake, 0] = rng.choice(self.numbers, size=int(fake.sum()))
        self.tag = np.full(self.rows, UNKNOWN, dtype=np.int64)
        self.op_a, self.op_b = word.random(rng, (V, 9)), word.random(rng, (V, 9))
        self.tag_a = np.full(V, UNKNOWN, dtype=np.int64)
        self.tag_b = np.full(V, UNKNOWN, dtype=np.int64)
        self.owner_a = np.full(V, -1, dtype=np.int64)   # the slot that last latched each register
        self.owner_b = np.full(V, -1, dtype=np.int64)
        self.units = word.random(rng, (V, 3, 3))
        self.utag = np.full(V, UNKNOWN, dtype=np.int64)
        self.uslot = np.full(V, -1, dtype=np.int64)     # the slot whose op's first step set utag
        self.tables = [[self._random_row() for _ in range(int(rng.integers(1, 4)))] for _ in range(V)]
        # bus-write registers (a bus network's): power-on garbage until a compact word clears them
        self.wtables = [[[int(x) for x in rng.integers(0, 4096, size=2)]
                         for _ in range(int(rng.integers(0, 3)))] for _ in range(V)]
        self.programmed = np.zeros(V, bool)
        self.tick = 0

    def _random_row(self) -> list[int]:
        return [int(x) for x in self.rng.integers(0, 4096, size=6)]

    # --- Program Mode -------------------------------------------------------------------------
    def program(self, ticks: int | None = None) -> int:
        """Clock the Program-Mode stream through the network; returns ticks used. VampcError if a
        VAMP never latched a program."""
        stream = self.ld.stream
        roots = [self._root_row(e.root) for e in stream]
        try:       # the words as the network's format carries them
            words = [self.ld.arith.program_words(e.words) for e in stream]
        except ValueError as exc:
            raise VampcError(f"{self.ld.path}: Program Mode: {exc}") from None
        ticks = ticks if ticks is not None else self.ld.load_ticks
        for k in range(ticks):
            for row, entry in zip(roots, words):
                self.bus[row, :] = 0
                if k < len(entry):
                    self.bus[row, :3] = entry[k]
            self._program_tick()
        missing = np.flatnonzero(~self.programmed)
        if missing.size:
            names = ", ".join(self._name(int(v)) for v in missing[:3])
            raise VampcError(f"{self.ld.path}: Program Mode: {missing.size} VAMP(s) saw no word with "
                             f"their number in {ticks} ticks: {names}")
        return ticks

    def _program_tick(self) -> None:
        words = self.bus[self.input0, :3].copy()
        mine = np.abs(words[:, 0]) == self.numbers
        for v in np.flatnonzero(mine):
            self._apply(int(v), words[v])
        firsts = [(self.bus[src, :3].copy(), self.tag[src]) for _, _, src in self.program_buffers]
        self.bus[:self.V, :3] = words
        self.bus[:self.V, 3:] = 0
        for (lo, hi, _), (value, tag) in zip(self.program_buffers, firsts):   # every tick
            self.bus[lo + 1:hi, :3] = self.bus[lo:hi - 1, :3]
            self.tag[lo + 1:hi] = self.tag[lo:hi - 1]
            self.bus[lo, :3], self.tag[lo] = value, tag
        self._vcd_dump()
        self.tick += 1

    def _apply(self, v: int, word, tables=None, programmed=None) -> None:
        """Apply a Program-Mode word to VAMP v's slot table (or to `tables[v]`, a second set)."""
        if word_number(word) < 0:
            return
        tables = self.tables if tables is None else tables
        programmed = self.programmed if programmed is None else programmed
        table, writes = tables[v], self.wtables[v] if tables is self.tables else []
        if word[0] < 0:                       # an extended word may grow the table: random fields
            slot, f = divmod(int(word[1]), ADDRESS)
            if f in WRITE_FIELDS:             # a bus-write register (a bus network's)
                if not 0 <= slot < self.P * TIER_CODES:   # past any register (a power-on word)
                    return
                while len(writes) <= slot:
                    writes.append([int(x) for x in self.rng.integers(0, 4096, size=2)])
            else:
                if not 0 <= slot < self.P:    # no slot has that address (a power-on word): ignored
                    return
                while len(table) <= slot:
                    table.append(self._random_row())
        else:
            programmed[v] = True
        tables[v] = apply_word(table, word, self.ld.packing, writes)

    def programs(self) -> tuple[tuple[Program, ...], ...]:
        """The slot tables the VAMPs hold now (a select of a multiplexer of one input, which has no
        register, as the 0 it passes: it showed the field's power-on contents)."""
        return tuple(tuple(Program(*row[:4], *held_selects(v, row[4], row[5])) for row in table)
                     for v, table in zip(self.ld.net.vamps, self.tables))

    # --- Data Mode ----------------------------------------------------------------------------
    def run(self, ports: dict, count: int, stats: TickStats | None = None, progress=None,
            until=None):
        """Data Mode for `count` torque sets; `ports` maps (port, entry) to that entry's values for
        every set. Returns torques (count, n). VampcError on a timing violation seen in the data
        (mixed sets at a latch, a torque of the wrong set). `progress(done, total)` (torque sets, in
        proportion to the ticks run) is called every 1024 ticks if given; `until(t, tau, seen)`, if given, is asked at the end of every period
        whether to stop there (sets not complete then keep NaN torques; `last_seen` says which
        are)."""
        stats = stats or TickStats()
        self._data_setup()
        P = self.P
        # the steady state: from the tick set 0's last op has finished (ops no torque reads may run
        # after the torques are out: before that tick they still work on the set before set 0)
        # until the last set has entered
        span = max([o.tick for o in self.ld.net.outputs] + list(self.ld.schedule.finish))
        self.steady = (span, count * P)
        outs = self.ld.net.outputs
        last_tick = (count - 1) * P + self.ld.net.latency
        if self.faults:
            from vampc.emulator.faults import check_faults
            check_faults(self.faults, self.ld, last_tick)
            cycles = last_tick // P + 1       # an intermittent fault's cycles, drawn once
            self.fault_draws = [self.fault_rng.random(cycles) for _ in self.faults]
        tau = np.full((count, self.ld.chain.n_outputs), np.nan)
        seen = np.full((count, len(outs)), -1, dtype=np.int64)
        shown, end = time.monotonic(), last_tick
        for t in range(last_tick + 1):
            if t % self.B == 0:
                self._write_ports(ports, t // self.B, count)
            self._observe(t, tau, seen, count)
            self._data_tick(t % P, t)
            if progress is not None and t % 16 == 0 and time.monotonic() - shown >= 0.5:
                # in torque sets, as the bar counts (ticks had been counted as sets: a 6000-set
                # run showed '23552set'), to a hundredth, twice a second: every 1024 ticks, in
                # whole sets, a 93 810-VAMP network's 3 sets had shown 0/3 and an elapsed time
                # stuck at 00:00 for minutes (a new user's find)
                shown = time.monotonic()
                progress(round(t * count / (last_tick + 1), 2), count)
            if until is not None and (t + 1) % P == 0 and until(t, tau, seen):
                last_tick = t
                break
        else:
            self._finish_dead_ops(ports, count, last_tick)
        if progress is not None:               # (the ticks run, whatever the last report said)
            progress(round((last_tick + 1) * count / (end + 1), 2), count)
        if not self.held:
            canonical_nan(tau)                 # (the Results' NaNs as they would have been held)
        self.last_seen = (seen >= 0).all(axis=1)
        stats.data_ticks = last_tick + 1
        stats.appear = [int(s.max()) for s in seen]
        stats.first_set_tick = stats.appear[0] if count else None
        return tau

    def _data_setup(self) -> None:
        for c in self.ld.net.consts:
            self.bus[self.const_row[c.index], :] = 0
            # the host's conversion, counted once a run (vampc.emulator.stream.constant_overflows)
            self.bus[self.const_row[c.index], :len(c.value)] = self.ld.arith.fresh().encode(c.value)
            self.tag[self.const_row[c.index]] = CONST
        self._slots()
        self._port_plan()
        self.outs_at: dict[int, list] = {}       # per counter: the torques read then (k, output)
        for k, o in enumerate(self.ld.net.outputs):
            self.outs_at.setdefault(o.tick % self.P, []).append((k, o))
        self._bus_drives()

    def _bus_drives(self) -> None:
        """Per Cycle-Counter: the rows the bus-write registers copy onto their buses (source rows,
        bus rows), and the first two writes that drive one bus together, if any."""
        self.drive_at: dict[int, tuple] = {}
        bus = self.ld.net.bus
        if bus is None:
            return
        from msgspec.structs import replace

        from vampc.program.emit import bus_writes
        # what Program Mode left in the bus-write registers drives the buses
        bus = replace(bus, writes=tuple(bus_writes(self.ld.net, self.wtables, self.ld.path)))
        sources = [b.source for b in self.ld.net.buffers]
        for (k, b, c), writes in sorted(bus.drivers(sources, self.P).items()):
            src, dst, clash = self.drive_at.get(c, ([], [], None))
            for w in writes:
                src.append(self._row(w.source, 0))
                dst.append(self.bus_row[(k, b)])
            if len(writes) > 1 and clash is None:
                clash = (k, b, writes[0].source, writes[1].source)
            self.drive_at[c] = (src, dst, clash)
        self.drive_at = {c: (np.array(s, dtype=np.int64), np.array(d, dtype=np.int64), x)
                         for c, (s, d, x) in self.drive_at.items()}

    def _drive_buses(self, c: int, t: int) -> None:
        """The buses at the start of tick t: what their writers drive (a bus no one drives holds
        no set's value); VampcError if two drive one bus."""
        lo, hi = self.buses
        self.tag[lo:hi] = UNKNOWN
        drive = self.drive_at.get(c)
        if drive is None:
            return
        src, dst, clash = drive
        if clash is not None:
            k, b, w0, w1 = clash
            raise VampcError(f"{self.ld.path}: tick {t}: bus {b} of tier {k} is driven by two "
                             f"writers at once ({w0} and {w1}): a bus collision")
        self.bus[dst] = self.bus[src]
        self.tag[dst] = self.tag[src]

    def _slots(self) -> None:
        """Flatten the programmed slot tables: per slot its VAMP, fields and operand gathers."""
        self._build_slots([(v, v, 1, table) for v, table in enumerate(self.tables)])

    def _build_slots(self, tables) -> None:
        """The slot arrays of `tables`, (VAMP, role, table number, slot table) each: the VAMP whose
        registers run the slots, the VAMP whose program and inputs they are (another with error
        correction's second tables). A slot whose fields point at no ROM entry or multiplexer
        input is an error; with faults (not strict) it is broken: it runs no op and its dumps are
        garbage, as the hardware's would be."""
        P, net = self.P, self.ld.net
        rows = []
        for p, r, kind, table in tables:
            inputs = net.vamps[r]
            for k, (da, db, dr, rr, sa, sb) in enumerate(table):
                sa, sb = held_selects(inputs, sa, sb)
                bad = rr >= len(ROM) or sa >= len(inputs.a) or sb >= len(inputs.b)
                if bad and self.strict:
                    what = (f"ROM pointer {rr} is not in the ROM (0..{len(ROM) - 1})"
                            if rr >= len(ROM) else "a select points at no multiplexer input")
                    raise VampcError(f"{self.ld.path}: {self._name(p, k)}: {what}")
                rows.append((p, r, kind, bad, (da, db, dr, 0 if bad else rr),
                             self._gather(inputs.a[0 if bad else sa], r),
                             self._gather(inputs.b[0 if bad else sb], r)))
        rows.sort(key=lambda x: x[0])                     # a VAMP's slots together, stably
        vamp = [x[0] for x in rows]
        self.slot_vamp = np.array(vamp, dtype=np.int64)
        self.slot_role = np.array([x[1] for x in rows], dtype=np.int64)
        self.slot_kind = np.array([x[2] for x in rows], dtype=np.int64)
        self.broken = np.array([x[3] for x in rows], dtype=bool)
        fields = [x[4] for x in rows]
        ga, gb = [x[5] for x in rows], [x[6] for x in rows]
        self.counted = np.full(len(vamp), -1, dtype=np.int64)   # the last set whose overflows count
        f = np.array(fields, dtype=np.int64).reshape(-1, 4)
        self.s_da, self.s_db, self.s_dr, self.s_rom = f[:, 0], f[:, 1], f[:, 2], f[:, 3]
        self.ga_rows, self.ga_cols, self.ga_taps = (np.array([g[i] for g in ga], dtype=np.int64)
                                                    for i in range(3))
        self.gb_rows, self.gb_cols, self.gb_taps = (np.array([g[i] for g in gb], dtype=np.int64)
                                                    for i in range(3))
        # per slot: whether each operand's three tag rows are one row (a vector's: its set tag
        # is that row's, _combine of three equal tags), and the unit its op's result is in
        self.ga_single, self.gb_single = ((taps[:, 0] == taps[:, 1]) & (taps[:, 1] == taps[:, 2])
                                          for taps in (self.ga_taps.reshape(-1, 3),
                                                       self.gb_taps.reshape(-1, 3)))
        self.s_result = np.array([rom.result_unit(int(r)) for r in self.s_rom], dtype=np.int64)
        self.step_at = {}               # counter -> [(rom, step, slots)]
        timing = self.ld.timing
        for r in range(len(ROM)):
            ends = rom.step_ends(r, timing)
            for j in range(len(ends)):
                mine = np.flatnonzero((self.s_rom == r) & (self.s_dr < P) & ~self.broken)
                for c, group in _by_counter(step_counter(self.s_dr[mine], ends, j, P), mine):
                    self.step_at.setdefault(c, []).append((r, j, group))
        every = np.arange(len(vamp))
        self.latch_a_at = dict(_by_counter(self.s_da, every))
        self.latch_b_at = dict(_by_counter(self.s_db, every))
        self.dump_at = dict(_by_counter(self.s_dr, every))
        # whether two slots of one VAMP dump at one counter (a damaged table's doing, or error
        # correction's two tables): _dump then looks for such a pair among the slots it dumps
        self.dump_shared = any(np.unique(self.slot_vamp[g]).size < g.size
                               for g in self.dump_at.values())

    def _dump(self, dumps, regs, tags) -> None:
        """The slots `dumps` drive their VAMPs' result registers `regs` (and set tags `tags`): a
        broken slot's with garbage."""
        v = self.slot_vamp[dumps]
        if self.dump_shared and np.unique(v).size < v.size:
            # each ROM entry's slots in turn: the later entry's result stays
            for r in np.unique(self.s_rom[dumps]):
                sel = v[self.s_rom[dumps] == r]
                out = self.units[sel, rom.result_unit(int(r)), :]
                regs[sel, :3] = self.word.result(out) if self.held else out
                regs[sel, 3:] = 0
        else:                     # one slot a VAMP: each its op's result unit, in one gather
            out = self.units[v, self.s_result[dumps], :]
            regs[v, :3] = self.word.result(out) if self.held else out
            regs[v, 3:] = 0
        tags[v] = self.utag[v]
        bad = self.broken[dumps]
        if bad.any():
            regs[v[bad], :3] = self.word.random(self.rng, (int(bad.sum()), 3), 1e3)
            tags[v[bad]] = UNKNOWN

    def _port_plan(self) -> None:
        """Per block of a period (block mod K): the port entries the host writes at its start, as
        (row, size, (port, entry), torque set in the run's first period) in the order written; a
        period later the same entries are written for the next set (port_writes)."""
        K = self.P // self.B
        self.ports_at = [[(self.port_row[p.index], p.size, (p.index, j), s)
                          for p in self.ld.net.ports for j, s in port_writes(p.entries, b, K)]
                         for b in range(K)]

    def _write_ports(self, ports, block: int, count: int) -> None:
        period, b = divmod(block, self.P // self.B)
        for row, size, key, first in self.ports_at[b]:
            s = first + period
            self.bus[row, :] = 0
            if 0 <= s < count:
                self.bus[row, :size] = ports[key][s]
                self.tag[row] = s
            else:
                self.tag[row] = UNKNOWN

    def _observe(self, t: int, tau, seen, count) -> None:
        """Read the torques due at tick t (output k of set j at o.tick + j P)."""
        for k, o in self.outs_at.get(t % self.P, ()):
            tg = self.tag[o.vamp]
            j = (t - o.tick) // self.P
            if 0 <= j < count:
                seen[j, k] = t
                if tg != j and self.strict:
                    raise VampcError(
                        f"{self.ld.path}: tick {t}: τ{o.joint} of set {j} is read from "
                        f"{self._name(o.vamp)}, whose Result holds "
                        + (f"set {tg}" if tg >= 0 else "no set's value") + " (a timing error)")
                tau[j, o.joint - 1] = self.ld.arith.decode(self.bus[o.vamp, o.component])

    def _data_tick(self, c: int, t: int) -> None:
        if self.bus_row:
            self._drive_buses(c, t)
        if self.faults:
            self._control_faults(t)
        self._latch(self.latch_a_at.get(c), "a")
        self._latch(self.latch_b_at.get(c), "b")
        if self.faults:
            self._register_faults(t, ("a", "b"))
        for r, j, slots in self.step_at.get(c, ()):
            self._step(r, j, slots, t)
        new_stages = self._shifted_stages(every_tick=False, tick=t)
        dumps = self.dump_at.get(c)
        if dumps is not None:
            self._dump(dumps, self.bus, self.tag)
        self._commit_stages(new_stages)
        if self.faults:
            self._register_faults(t, ("result", "dead"))
        self._vcd_dump()
        self.tick += 1

    # --- faults (vampc.emulator.faults) -------------------------------------------------------
    def _holds(self, k: int, f, t: int) -> bool:
        """Whether fault k acts at tick t (a flip only at its tick)."""
        if f.kind == "flip":
            return t == f.at
        return f.active(t, self.P, lambda cycle: self.fault_draws[k][cycle])

    def _register_faults(self, t: int, registers) -> None:
        """Result and operand faults after the tick's latches or dumps; a dead VAMP's Result
        left undriven."""
        from vampc.emulator.faults import set_bit
        word = self.ld.arith
        for k, f in enumerate(self.faults):
            which = "dead" if f.kind == "dead" else f.register
            if which not in registers or not self._holds(k, f, t):
                continue
            v = f.vamp
            if f.kind == "dead":
                self.bus[v, :] = word.random(self.rng, (9,), 1e3)
                self.tag[v] = UNKNOWN
                continue
            how = "flip" if f.kind == "flip" else "set" if f.value else "clear"
            reg = self.bus if f.register == "result" else self.op_a if f.register == "a" \
                else self.op_b
            reg[v, f.component] = set_bit(word, reg[v, f.component:f.component + 1], f.bit, how)[0]

    def _control_faults(self, t: int) -> None:
        """A control-register fault changes the field the slot table holds when it starts (the
        register keeps it); the slot arrays are made again."""
        from vampc.emulator.faults import set_field
        changed = False
        for f in self.faults:
            tables = self._control_tables(f.register)
            if tables is not None and t == f.at:
                row = tables[f.vamp][f.slot]
                how = "flip" if f.kind == "flip" else "set" if f.value else "clear"
                row[f.component] = set_field(int(row[f.component]), f.bit, how)
                changed = True
        if changed:
            self._slots()

    def _control_tables(self, register: str):
        """The slot tables a control fault on `register` changes (None: not a control register)."""
        return self.tables if register == "control" else None

    def _latch(self, slots, which: str) -> None:
        if slots is None:
            return
        rows, cols, taps = (self.ga_rows, self.ga_cols, self.ga_taps) if which == "a" else \
            (self.gb_rows, self.gb_cols, self.gb_taps)
        v = self.slot_vamp[slots]
        (self.op_a if which == "a" else self.op_b)[v] = self.bus[rows[slots], cols[slots]]
        if self.tagged:
            single = (self.ga_single if which == "a" else self.gb_single)[slots]
            # a vector's tag rows are one row: its tag is that row's (_combine of three equal)
            tags = self.tag[taps[slots, 0]] if single.all() else _combine(self.tag[taps[slots]])
            (self.tag_a if which == "a" else self.tag_b)[v] = tags
            (self.owner_a if which == "a" else self.owner_b)[v] = slots

    def _step(self, r: int, j: int, slots, t: int) -> None:
        idx = self.slot_vamp[slots]
        units = self.units[idx]
        word = self.word
        before, word.track = word.overflows, []
        rom.step_rows(r, j, self.op_a, self.op_b, idx, units, word)
        if word.overflows != before:
            self._count_overflows(r, j, slots, idx, word, before)
        word.track = None
        self.units[idx] = units
        if j == 0 and self.tagged:
            self.utag[idx] = _combine2(self.tag_a[idx], self.tag_b[idx])
            self.uslot[idx] = slots
        if self.strict:
            slots = self._watched(slots)
            if slots.size:
                self._timing_checks(r, j, slots, self.slot_vamp[slots], t)

    def _name(self, v: int, slot: int | None = None) -> str:
        """How messages name VAMP v (and one of its slots)."""
        return self.ld.vamp_name(v, slot)

    def _watched(self, slots):
        """The slots whose timing the tags check now (every one here)."""
        return slots

    def _timing_checks(self, r: int, j: int, slots, idx, t: int) -> None:
        """VampcError on a timing violation the tags show at step j of these slots."""
        reading = rom.operand_steps(r)
        if j < reading:
            self._check_owner(r, j, slots, idx, t)
        if 0 < j < reading:
            self._check_relatch(r, j, idx, t)
        # the tag the op's first step took (_combine2 of its operands') is UNKNOWN where an operand
        # holds no set's value or the two hold different sets: else neither check below can fail
        if j == 0 and count_nonzero(self.utag[idx] == UNKNOWN):
            ta, tb = self.tag_a[idx], self.tag_b[idx]
            mixed = (ta >= 0) & (tb >= 0) & (ta != tb)
            if self.steady[0] <= t < self.steady[1]:
                unknown = (ta == UNKNOWN) | (tb == UNKNOWN)
                if count_nonzero(unknown):
                    v = int(idx[np.argmax(unknown)])
                    which = "A" if self.tag_a[v] == UNKNOWN else "B"
                    raise VampcError(f"{self.ld.path}: tick {t}: {self._name(v)} starts "
                                     f"{ROM[r][0].value} with operand {which} holding no set's "
                                     "value (a timing error)")
            if count_nonzero(mixed):
                v = int(idx[np.argmax(mixed)])
                raise VampcError(f"{self.ld.path}: tick {t}: {self._name(v)} starts "
                                 f"{ROM[r][0].value} with operand A of set {self.tag_a[v]} and "
                                 f"operand B of set {self.tag_b[v]} (a timing error)")

    def _count_overflows(self, r: int, j: int, slots, idx, word, before: int) -> None:
        """Count an op's overflows once per torque set, as the stream engine computes each op once
        a set: not those on registers holding no set's value (the power-on state, the warm-up),
        nor an op run again on a set it has done, nor a later step of an op whose first step this
        slot did not run (its units hold another op's values: error correction's checker taking
        up its successor's program mid-op counted overflows the stream engine has not)."""
        tags = _combine2(self.tag_a[idx], self.tag_b[idx]) if j == 0 else self.utag[idx]
        fresh = (tags >= 0) & (tags > self.counted[slots]) & self._drives(slots)
        if j > 0:
            fresh &= self.uslot[idx] == slots
        per_row = np.sum(np.stack(word.track), axis=0)
        word.overflows = before + int(per_row[fresh].sum())
        if j == rom.steps(r) - 1:
            self.counted[slots[fresh]] = tags[fresh]

    # whether a run goes on past the last torque until every op of the last sets has finished
    FINISHES_DEAD_OPS = True

    def _finish_dead_ops(self, ports: dict, count: int, last_tick: int) -> None:
        """A fixed-point word's run goes on past the last torque until every op of the last sets
        has finished: ops no torque reads (a log recursion's padding) may be scheduled after the
        torques are out, and their overflows, which the stream engine counts (each op once a
        set), went uncounted (a --vamps 9 log Puma in q8.16: 2 overflows against 4). Nothing else
        of the run changes: no torque is read, the waveform ends with the last torque, and the
        emulated time is the torques'. (Not with faults or the checking engine: their ticks are
        counted and their checks would run on.)"""
        if self.ld.word is None or self.faults or not count or not self.FINISHES_DEAD_OPS:
            return
        end = (count - 1) * self.P + max(self.ld.schedule.finish, default=0)
        vcd, self.vcd = self.vcd, None
        try:
            for t in range(last_tick + 1, end + 1):
                if t % self.B == 0:
                    self._write_ports(ports, t // self.B, count)
                self._data_tick(t % self.P, t)
        finally:
            self.vcd = vcd

    def _drives(self, slots):
        """Which of these slots compute the data path's values (every one here; with error
        correction's checking, not a checker's copy of its successor's op)."""
        return True

    def _check_owner(self, r: int, j: int, slots, idx, t: int) -> None:
        """An op reads the operands its own slot latched (in data mode, once data flows): not what
        another slot of the VAMP left in the registers, nor nothing. (From the second period on:
        in the first an op may run before its own latch comes round.)"""
        if t < self.P:
            return
        for name, owner in (("A", self.owner_a[idx]), ("B", self.owner_b[idx])):
            bad = owner != slots
            if count_nonzero(bad):
                i = int(np.argmax(bad))
                v, k = int(idx[i]), int(slots[i])
                other = int(owner[i])
                who = "no slot" if other < 0 else f"slot {self._slot_in_vamp(other)}"
                raise VampcError(f"{self.ld.path}: tick {t}: {self._name(v, self._slot_in_vamp(k))} "
                                 f"runs step {j + 1} of {ROM[r][0].value} on operand {name} latched "
                                 f"by {who} (a timing error)")

    def _slot_in_vamp(self, s: int) -> int:
        """The position of global slot s in its VAMP's table."""
        return int(s - np.searchsorted(self.slot_vamp, self.slot_vamp[s]))

    def _check_relatch(self, r: int, j: int, idx, t: int) -> None:
        """A later operand-reading step must still see the set the op started with."""
        started = self.utag[idx]
        for name, tags in (("A", self.tag_a[idx]), ("B", self.tag_b[idx])):
            moved = (started >= 0) & (tags >= 0) & (tags != started)
            if count_nonzero(moved):
                v = int(idx[np.argmax(moved)])
                raise VampcError(f"{self.ld.path}: tick {t}: {self._name(v)} is in step "
                                 f"{j + 1} of {ROM[r][0].value} on set {self.utag[v]}, but operand "
                                 f"{name} was re-latched with set {tags[np.argmax(moved)]} (a timing "
                                 "error)")

    # --- buffers and waveforms ----------------------------------------------------------------
    def _shifted_stages(self, every_tick: bool, tick: int = 0):
        """What each buffer's first stage takes at the end of this tick, its VAMP's Result (None:
        no shift now); the other stages take their predecessors' when committed."""
        if not (every_tick or captures(tick, self.B)) or not self.first_row.size:
            return None
        return self.bus[self.first_src, :3].copy(), self.tag[self.first_src].copy()

    def _commit_stages(self, new) -> None:
        """Shift every buffer one stage (only stage rows change between _shifted_stages and this)."""
        if new is not None:
            lo, hi = self.stages
            self.bus[lo + 1:hi, :3] = self.bus[lo:hi - 1, :3]   # overlapping: numpy copies safely
            self.tag[lo + 1:hi] = self.tag[lo:hi - 1]
            self.bus[self.first_row, :3], self.tag[self.first_row] = new

    def _vcd_dump(self) -> None:
        if self.vcd is not None:
            words = self.bus[:self.V, :3]
            raw = getattr(self.vcd, "words", False)      # (a writer of the words themselves)
            self.vcd.sample(self.tick + 1, words if raw else self.ld.arith.decode(words))


def _by_counter(counters: np.ndarray, slots: np.ndarray):
    """(counter, slots with that counter) for every counter that occurs."""
    if not len(slots):
        return []
    order = np.argsort(counters, kind="stable")
    keys = counters[order]
    cuts = np.flatnonzero(np.diff(keys)) + 1
    return [(int(keys[g[0]]), slots[order][g]) for g in np.split(np.arange(len(keys)), cuts)]


_BIG, _SMALL = np.iinfo(np.int64).max, np.iinfo(np.int64).min


def _combine2(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """_combine of two tags a value is computed from (an op's operands), without stacking them:
    UNKNOWN if either is; the other if one is CONST; the common set if both are of one; else
    UNKNOWN (UNKNOWN and CONST are distinct negative sentinels, sets are >= 0)."""
    return np.where(a == CONST, b, np.where((b == CONST) | (a == b), a, UNKNOWN))


def _combine(tags: np.ndarray) -> np.ndarray:
    """Set tag of a value computed from several: the common set; CONST if all constant; else UNKNOWN."""
    const = tags == CONST
    lo = np.where(const, _BIG, tags).min(axis=1)
    hi = np.where(const, _SMALL, tags).max(axis=1)
    out = np.where(lo == hi, lo, UNKNOWN)
    out = np.where(const.all(axis=1), CONST, out)
    return np.where((tags == UNKNOWN).any(axis=1), UNKNOWN, out)
