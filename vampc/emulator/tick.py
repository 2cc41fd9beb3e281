"""The tick engine: the VAMP network clocked one flop at a time. It is the executable specification.

State: every VAMP's operand registers (9 scalars each), its three primitive modules' MULT-1, MULT-2 and
ADDER, its Result register and its four program registers; every buffer stage; every host port and
constant buffer. All of it starts random (Program Mode must work from any state).

Order of events in one tick (every register updates at the end of the tick, from values visible during
it):

Program Mode (Global-Reset held true)
  1. the host writes the next word of each input buffer's stream (then null words);
  2. every VAMP copies the word on its Operand-A input to its Result, and latches the word's program
     into its program registers if the word's first scalar is its own number;
  3. every buffer stage takes its input.

Data Mode (Global-Reset pulses at each cycle start: Cycle-Counter c = tick mod C)
  1. at the start of each cycle the host writes the ports for the set due in that cycle;
  2. a VAMP latches operand A if c = delay-A and operand B if c = delay-B (a latch is seen by a
     micro-step in the same tick);
  3. the micro-steps due at c run (a d-step op runs at counters delay-R − d + 1 .. delay-R);
  4. a VAMP whose delay-R is c drives its result register onto Result (visible from the next tick);
  5. at the last tick of a cycle every buffer stage takes its input (stage 1 its VAMP's Result).

Beside the data, every value carries a tag: the torque set it belongs to (-1 unknown, -2 constant). A
VAMP latching operands of two different sets is a timing violation; so is, in the steady state (from
the tick the first torque set is due until the last set has entered), starting an op on an operand that
holds no set's value (never latched, or latched from a source that had none); an operand re-latched
with another set while a later micro-step still reads it; and a torque read at its scheduled tick must
carry the set the host expects. The tags are observation only; they never change a
value.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from vampc.emulator import rom
from vampc.emulator.load import Loaded
from vampc.errors import VampcError
from vampc.program.words import ROM, Program, decode

UNKNOWN, CONST = -1, -2


@dataclass
class TickStats:
    """What the tick engine observed."""

    load_ticks: int = 0
    data_ticks: int = 0
    first_set_tick: int | None = None              # tick at which set 0's last torque appeared
    appear: list = field(default_factory=list)     # per set: tick its last torque first appeared


class TickEngine:
    """A network loaded from a program file, ready to be programmed and run."""

    def __init__(self, ld: Loaded, seed: int = 0, vcd=None):
        self.ld, self.C = ld, ld.cycle
        self.rng = np.random.default_rng(seed)
        self.vcd = vcd
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
        # Stage s of a buffer takes stage s - 1 (stage 1 takes its VAMP's Result).
        self.stage_dst = np.array(list(self.stage_row.values()), dtype=np.int64)
        self.stage_src = np.array([b_src if s == 1 else self.stage_row[(b, s - 1)]
                                   for (b, s), b_src in ((k, ld.net.buffers[k[0]].source)
                                                         for k in self.stage_row)], dtype=np.int64)
        self.port_row = {p.index: row + k for k, p in enumerate(ld.net.ports)}
        row += len(ld.net.ports)
        self.const_row = {c.index: row + k for k, c in enumerate(ld.net.consts)}
        self.rows = row + len(ld.net.consts)
        self.V = V
        self.ga_rows, self.ga_cols, self.ga_taps = self._gather("a")
        self.gb_rows, self.gb_cols, self.gb_taps = self._gather("b")
        self.numbers = np.array(ld.numbers, dtype=float)

    def _row(self, tap) -> int:
        if tap.kind == "vamp":
            return tap.index
        if tap.kind == "buffer":
            return self.stage_row[(tap.index, tap.stage)]
        if tap.kind == "port":
            return self.port_row[tap.index]
        return self.const_row[tap.index]

    def _gather(self, which: str):
        rows = np.zeros((self.V, 9), dtype=np.int64)
        cols = np.zeros((self.V, 9), dtype=np.int64)
        taps = np.zeros((self.V, 3), dtype=np.int64)
        for v in self.ld.net.vamps:
            t = getattr(v, which).taps
            r = [self._row(x) for x in t]
            taps[v.index] = (r * 3)[:3]
            if len(t) == 3:   # matrix as three columns: element (i, j) is scalar i of column j
                rows[v.index] = [r[j] for i in range(3) for j in range(3)]
                cols[v.index] = [i for i in range(3) for j in range(3)]
            else:
                rows[v.index], cols[v.index] = r[0], np.arange(9)
        return rows, cols, taps

    def _random_state(self) -> None:
        rng, V = self.rng, self.V
        self.bus = rng.normal(size=(self.rows, 9)) * 1e3
        # Some registers start out looking like program words for real VAMPs.
        fake = rng.random(self.rows) < 0.5
        self.bus[fake, 0] = rng.choice(self.numbers, size=int(fake.sum()))
        self.tag = np.full(self.rows, UNKNOWN, dtype=np.int64)
        self.op_a, self.op_b = rng.normal(size=(V, 9)), rng.normal(size=(V, 9))
        self.tag_a = np.full(V, UNKNOWN, dtype=np.int64)
        self.tag_b = np.full(V, UNKNOWN, dtype=np.int64)
        self.units = rng.normal(size=(V, 3, 3))
        self.utag = np.full(V, UNKNOWN, dtype=np.int64)
        self.prog = rng.integers(0, 4096, size=(V, 3))
        self.rom = rng.integers(0, len(ROM), size=V)
        self.programmed = np.zeros(V, bool)
        self.tick = 0

    # --- Program Mode -------------------------------------------------------------------------
    def program(self, ticks: int | None = None) -> int:
        """Clock the Program-Mode stream through the network; returns ticks used. VampcError if a
        VAMP never latched a program."""
        stream = self.ld.stream
        roots = [self.port_row[r.index] if r.kind == "port" else self.const_row[r.index]
                 for r, _ in stream]
        ticks = ticks if ticks is not None else self.ld.doc["io"]["load_ticks"]
        for k in range(ticks):
            for row, (_, words) in zip(roots, stream):
                self.bus[row, :] = 0.0
                if k < len(words):
                    self.bus[row, :3] = words[k]
            self._program_tick()
        missing = np.flatnonzero(~self.programmed)
        if missing.size:
            names = ", ".join(self.ld.vamp_name(int(v)) for v in missing[:3])
            raise VampcError(f"{self.ld.path}: Program Mode: {missing.size} VAMP(s) saw no word with "
                             f"their number in {ticks} ticks: {names}")
        return ticks

    def _program_tick(self) -> None:
        words = self.bus[self.ga_taps[:, 0], :3]
        mine = words[:, 0] == self.numbers
        for v in np.flatnonzero(mine):
            _, p = decode(words[v])
            self.prog[v] = (p.delay_a, p.delay_b, p.delay_r)
            self.rom[v] = p.rom
            self.programmed[v] = True
        new_stages = self._shifted_stages(every_tick=True)
        self.bus[:self.V, :3] = words
        self.bus[:self.V, 3:] = 0.0
        self._commit_stages(new_stages)
        self._vcd_dump()
        self.tick += 1

    def programs(self) -> tuple[Program, ...]:
        """The programs the VAMPs hold now."""
        return tuple(Program(int(a), int(b), int(r), int(m))
                     for (a, b, r), m in zip(self.prog, self.rom))

    # --- Data Mode ----------------------------------------------------------------------------
    def run(self, ports: dict[int, np.ndarray], count: int, stats: TickStats | None = None,
            progress=None):
        """Data Mode for `count` torque sets; returns torques (count, n). VampcError on a timing
        violation seen in the data (mixed sets at a latch, a torque of the wrong set).
        `progress(done, total)` is called every 1024 ticks if given."""
        stats = stats or TickStats()
        self._data_setup()
        self.steady = (max(o.tick for o in self.ld.net.outputs), count * self.C)
        outs = self.ld.net.outputs
        last_tick = (count - 1) * self.C + max(o.tick for o in outs)
        tau = np.full((count, self.ld.chain.n), np.nan)
        seen = np.full((count, len(outs)), -1, dtype=np.int64)
        for t in range(last_tick + 1):
            if t % self.C == 0:
                self._write_ports(ports, t // self.C, count)
            self._observe(t, outs, tau, seen, count)
            self._data_tick(t % self.C, t)
            if progress is not None and t % 1024 == 0:
                progress(t, last_tick + 1)
        stats.data_ticks = last_tick + 1
        stats.appear = [int(s.max()) for s in seen]
        stats.first_set_tick = stats.appear[0] if count else None
        return tau

    def _data_setup(self) -> None:
        for c in self.ld.net.consts:
            self.bus[self.const_row[c.index], :] = 0.0
            self.bus[self.const_row[c.index], :len(c.value)] = c.value
            self.tag[self.const_row[c.index]] = CONST
        self._plan = [self._counter_plan(c) for c in range(self.C)]

    def _counter_plan(self, c: int):
        """Which VAMPs latch, step and dump at Cycle-Counter c (from their program registers)."""
        C = self.C
        la = np.flatnonzero(self.prog[:, 0] == c)
        lb = np.flatnonzero(self.prog[:, 1] == c)
        groups = []
        for r in range(len(ROM)):
            d = rom.steps(r)
            for k in range(d):
                due = (self.prog[:, 2] - d + 1 + k) % C == c
                idx = np.flatnonzero((self.rom == r) & due & (self.prog[:, 2] < C))
                if idx.size:
                    groups.append((r, k, idx))
        dumps = [(r, np.flatnonzero((self.prog[:, 2] == c) & (self.rom == r)))
                 for r in range(len(ROM))]
        return la, lb, groups, [(r, i) for r, i in dumps if i.size]

    def _write_ports(self, ports, cycle: int, count: int) -> None:
        for p in self.ld.net.ports:
            row, j = self.port_row[p.index], cycle - p.cycle
            self.bus[row, :] = 0.0
            if 0 <= j < count:
                self.bus[row, :p.size] = ports[p.index][j]
                self.tag[row] = j
            else:
                self.tag[row] = UNKNOWN

    def _observe(self, t: int, outs, tau, seen, count) -> None:
        for k, o in enumerate(outs):
            tg = self.tag[o.vamp]
            if 0 <= tg < count and seen[tg, k] < 0:
                seen[tg, k] = t
            j, rem = divmod(t - o.tick, self.C)
            if rem == 0 and 0 <= j < count:
                if tg != j:
                    raise VampcError(
                        f"{self.ld.path}: tick {t}: τ{o.joint} of set {j} is read from "
                        f"{self.ld.vamp_name(o.vamp)}, whose Result holds "
                        + (f"set {tg}" if tg >= 0 else "no set's value") + " (a timing error)")
                tau[j, o.joint - 1] = self.bus[o.vamp, o.component]

    def _data_tick(self, c: int, t: int) -> None:
        la, lb, groups, dumps = self._plan[c]
        self._latch(la, "a", t)
        self._latch(lb, "b", t)
        for r, k, idx in groups:
            self._step(r, k, idx, t)
        new_stages = self._shifted_stages(every_tick=False, counter=c)
        for r, idx in dumps:
            self.bus[idx, :3] = self.units[idx, rom.result_unit(r), :]
            self.tag[idx] = self.utag[idx]
        self._commit_stages(new_stages)
        self._vcd_dump()
        self.tick += 1

    def _latch(self, idx, which: str, t: int) -> None:
        if not idx.size:
            return
        rows, cols, taps = (self.ga_rows, self.ga_cols, self.ga_taps) if which == "a" else \
            (self.gb_rows, self.gb_cols, self.gb_taps)
        reg = self.op_a if which == "a" else self.op_b
        reg[idx] = self.bus[rows[idx], cols[idx]]
        tags = self.tag[taps[idx]]
        (self.tag_a if which == "a" else self.tag_b)[idx] = _combine(tags)

    def _step(self, r: int, k: int, idx, t: int) -> None:
        am, bm = rom.module_registers(r, self.op_a[idx], self.op_b[idx])
        units = self.units[idx]
        rom.step(r, k, am, bm, units)
        self.units[idx] = units
        if 0 < k < rom.operand_steps(r):
            self._check_relatch(r, k, idx, t)
        if k == 0:
            tags = np.stack([self.tag_a[idx], self.tag_b[idx]], axis=1)
            self.utag[idx] = _combine(tags)
            mixed = (tags >= 0).all(axis=1) & (tags[:, 0] != tags[:, 1])
            if self.steady[0] <= t < self.steady[1] and (tags == UNKNOWN).any():
                v = int(idx[np.argmax((tags == UNKNOWN).any(axis=1))])
                which = "A" if self.tag_a[v] == UNKNOWN else "B"
                raise VampcError(f"{self.ld.path}: tick {t}: {self.ld.vamp_name(v)} starts "
                                 f"{ROM[r][0].value} with operand {which} holding no set's value "
                                 "(a timing error)")
            if mixed.any():
                v = int(idx[np.argmax(mixed)])
                raise VampcError(f"{self.ld.path}: tick {t}: {self.ld.vamp_name(v)} starts "
                                 f"{ROM[r][0].value} with operand A of set {self.tag_a[v]} and "
                                 f"operand B of set {self.tag_b[v]} (a timing error)")

    def _check_relatch(self, r: int, k: int, idx, t: int) -> None:
        """A later operand-reading step must still see the set the op started with."""
        started = self.utag[idx]
        for name, tags in (("A", self.tag_a[idx]), ("B", self.tag_b[idx])):
            moved = (started >= 0) & (tags >= 0) & (tags != started)
            if moved.any():
                v = int(idx[np.argmax(moved)])
                raise VampcError(f"{self.ld.path}: tick {t}: {self.ld.vamp_name(v)} is in step "
                                 f"{k + 1} of {ROM[r][0].value} on set {self.utag[v]}, but operand "
                                 f"{name} was re-latched with set {tags[np.argmax(moved)]} (a timing "
                                 "error)")

    # --- buffers and waveforms ----------------------------------------------------------------
    def _shifted_stages(self, every_tick: bool, counter: int = 0):
        """Values and tags every buffer stage takes at the end of this tick (None: no shift now)."""
        if not (every_tick or counter == self.C - 1) or not self.stage_dst.size:
            return None
        return self.bus[self.stage_src, :3].copy(), self.tag[self.stage_src].copy()

    def _commit_stages(self, new) -> None:
        if new is not None:
            self.bus[self.stage_dst, :3], self.tag[self.stage_dst] = new

    def _vcd_dump(self) -> None:
        if self.vcd is not None:
            self.vcd.sample(self.tick + 1, self.bus[:self.V, :3])


def _combine(tags: np.ndarray) -> np.ndarray:
    """Set tag of a value computed from several: the common set; CONST if all constant; else UNKNOWN."""
    valid = np.where(tags == CONST, np.iinfo(np.int64).max, tags)
    lo = valid.min(axis=1)
    hi = np.where(tags == CONST, np.iinfo(np.int64).min, tags).max(axis=1)
    out = np.where(lo == hi, lo, UNKNOWN)
    out = np.where((tags == CONST).all(axis=1), CONST, out)
    return np.where((tags == UNKNOWN).any(axis=1), UNKNOWN, out)
