"""Limited automatic error correction (section VII, Figure VII.5b) in the tick engine: VAMPs that
check their successors, excise a faulty one and play its role; Maintenance Mode names it.

The hardware (what the report counts, vampc.report.checking): the VAMPs in a chain of successors
(network.error_correction.chain, the logical order) after one extraneous VAMP E (index V). Each
VAMP with a successor has Operand-A' and Operand-B' inputs wired to its successor's operand inputs
(every multiplexer input of them: the same wires reach both), a Result' input/output on its
successor's Result line, Test-in/out, Test-back-in/out and Inhibit-in/out, and a second set of
control registers matching its successor's slot table. Program Mode loads the second set like the
first: a VAMP latches, from its Operand-A' input 0 (its successor's Operand-A input 0, where its
successor's words pass), every word carrying its successor's number; the program stream is the
same as without checking. E has no role of its own and carries the number after the largest.

A VAMP is in one mode at a time; the modes change only at period boundaries (Global-Reset):

    normal     its own slot table on its own inputs, driving its Result line;
    warm       its own slot table, driving nothing (taking its own role back);
    check      the second table on the primed inputs, comparing each result with the successor's
               Result line after `warmup` periods (its own line is driven by its predecessor);
    fill       the second table, driving its successor's line through Result';
    inhibited  excised: its outputs tri-stated (Inhibit-in), its control outputs false.

What the paper leaves open, decided here:

- The sweep. Forward stage k (k = 0 .. V-1) lasts warmup + K periods: chain position k checks
  position k + 1, positions before it fill their successors' roles, those after are normal. The
  checker computes its successor's slots from the stage's start and compares every one of their
  results, bit for bit, in the stage's last K periods (after `warmup` periods every op dumped ran
  whole after the switch, vampc.network.checking). K (`compare`, --check-cycles) is 1 in the
  paper ("for that cycle"); a stuck bit a cycle's data happen to mask (a stuck 1 where the value
  has a 1) escapes one compare cycle but rarely K. A match moves the check on: the checker starts
  filling the role it has just computed (it is warm), its successor starts checking. After the last
  VAMP is checked the sequence reverses (the last VAMP's Test-out fed to its Test-back-in): back
  stage j (j = V-1 .. 1) lasts `warmup` periods, position j computing its own role again (warm)
  while its predecessor still drives it, then driving it (normal) as its predecessor turns warm in
  turn. E then starts the next sweep. A full sweep is V·(warmup + K) + (V - 1)·warmup periods.
- The checker's own Result is tri-stated while it checks; its result register holds its copy of
  the successor's result, which the comparator reads beside the successor's line (Result').
- On a mismatch the checker inhibits its successor at once and drives its line from the next tick;
  the chain stays shifted (every VAMP before the excised one plays its successor's role, E the
  first's) and the checking stops: there is no spare left. A second fault is not corrected.
- Maintenance Mode (`maintenance`): the fault-finder drives its VAMP-number onto the line it
  fills; every VAMP drives onto its line any fault notification on any of its multiplexer inputs
  (A or B; buffers shift every tick, as in Program Mode), and the host reads the numbers where the
  torques emerge. The faulty VAMP is the finder's successor in the chain.
- Folded and budget layouts: the second table holds every slot of the successor and the primed
  inputs every multiplexer input, so each slot is checked in the compare period. The Mostly-Local
  Bus is not supported (a usage error at compile time).
- A dead VAMP's control outputs are false: a dead checker never raises Test-out, a dead VAMP
  never Test-back-out, so the sweep stalls there for good (`stalled`): the roles stay as they are
  (a dead checker's own role is played by its predecessor, so nothing it drove is lost), but
  nothing is checked any more and nothing is named.
- Escapes, by construction: a fault in E, or in a VAMP's second control registers (`control2`
  faults) or comparator, can make it excise a healthy successor and play its role wrongly (the
  paper's "failures in the error-correcting circuitry itself"); a stuck data bit the data of a
  VAMP's own check mask but not the data of its successor's (the checker then excises its healthy
  successor); a fault that leaves the checked results equal in the compare periods waits for the
  next sweep; a VAMP dying while it fills its successor's role leaves that line undriven until
  the back sweep reaches it, then stalls it; transient and intermittent faults are caught only if
  active in a compare period.
"""
from __future__ import annotations

import numpy as np

from vampc.emulator.tick import UNKNOWN, TickEngine
from vampc.errors import VampcError
from vampc.kinds import TapKind

NORMAL, WARM, CHECK, FILL, INHIBITED, IDLE = range(6)
MODE_NAMES = ("normal", "warm", "check", "fill", "inhibited", "idle")


class CheckingTickEngine(TickEngine):
    """The tick engine of a program compiled with --error-correction (see the module docstring)."""

    CHECKS = True

    def __init__(self, ld, seed: int = 0, vcd=None, faults=(), strict: bool | None = None):
        self.checking = ld.net.checking
        V = len(ld.net.vamps)
        self.order = list(self.checking.order)               # physical VAMPs, E (= V) first
        self.pos = {p: i for i, p in enumerate(self.order)}
        self.succ = {self.order[i]: self.order[i + 1] for i in range(V)}
        self.pred = {s: p for p, s in self.succ.items()}
        self.w = self.checking.warmup
        self.k = self.checking.compare
        from vampc.program.emit import extraneous_number
        from vampc.program.words import Packing
        try:
            self.e_number = extraneous_number(ld.numbers, Packing.of(ld.arith))
        except VampcError as exc:
            raise VampcError(f"{ld.path}: {exc}") from None
        super().__init__(ld, seed, vcd, faults, strict)

    # --- state --------------------------------------------------------------------------------
    def _random_state(self) -> None:
        super()._random_state()
        rng, V, word = self.rng, self.V, self.ld.arith
        # one more VAMP (E) in every per-VAMP register; result registers apart from the lines
        self.op_a = np.vstack([self.op_a, word.random(rng, (1, 9))])
        self.op_b = np.vstack([self.op_b, word.random(rng, (1, 9))])
        self.units = np.concatenate([self.units, word.random(rng, (1, 3, 3))])
        for name in ("tag_a", "tag_b", "utag"):
            setattr(self, name, np.append(getattr(self, name), UNKNOWN))
        for name in ("owner_a", "owner_b", "uslot"):
            setattr(self, name, np.append(getattr(self, name), -1))
        self.res = word.random(rng, (V + 1, 9), 1e3)
        self.res_tag = np.full(V + 1, UNKNOWN, dtype=np.int64)
        self.tables2 = {p: [self._random_row() for _ in range(int(rng.integers(1, 4)))]
                        for p in self.succ}
        self.programmed2 = {p: False for p in self.succ}

    def _name(self, v: int, slot: int | None = None) -> str:
        if v == self.V:
            return f"the extraneous VAMP {v} (number {self.e_number})"
        return super()._name(v, slot)

    # --- Program Mode -------------------------------------------------------------------------
    def _program_tick(self) -> None:
        """Every checker latches, from its Operand-A' input 0, the words carrying its successor's
        number into its second control registers; then the tick as without checking."""
        words = self.bus[self.input0, :3]
        for p, s in self.succ.items():
            w = words[s]
            if abs(w[0]) == self.numbers[s]:
                self._apply(p, w.copy(), self.tables2, self.programmed2)
        super()._program_tick()

    def program(self, ticks: int | None = None) -> int:
        ticks = super().program(ticks)
        missing = [p for p, done in self.programmed2.items() if not done]
        if missing:
            raise VampcError(f"{self.ld.path}: Program Mode: {self._name(missing[0])} saw no word "
                             f"for its successor's second control registers in {ticks} ticks")
        return ticks

    # --- Data Mode ----------------------------------------------------------------------------
    def _slots(self) -> None:
        """Both slot tables of every VAMP as one set of slot arrays (TickEngine._build_slots: per
        slot its physical VAMP, the role whose program it is, which table)."""
        self._build_slots([(p, p, 1, t) for p, t in enumerate(self.tables)]
                          + [(p, self.succ[p], 2, t) for p, t in sorted(self.tables2.items())])
        if not hasattr(self, "mode"):
            self._start_sweep()
        self._activate()

    def _start_sweep(self) -> None:
        """Data Mode starts with forward stage 0: E checks the first VAMP, the rest are normal."""
        V = self.V
        self.mode = np.full(V + 1, NORMAL, dtype=np.int64)
        self.since = np.full(V + 1, self.tick, dtype=np.int64)   # tick each took its table
        self.phase, self.stage, self.left = "fwd", 0, self.w + self.k
        self.mode[V] = CHECK
        self.detections: list[dict] = []
        self.stalled: dict | None = None     # where a dead VAMP stopped the sweep
        self.sweeps = 0
        self.checked = np.zeros(V, dtype=np.int64)        # times each VAMP passed a check

    def _activate(self) -> None:
        """Which slots run, and which VAMP drives each Result line, from the modes."""
        m = self.mode[self.slot_vamp]
        first = (m == NORMAL) | (m == WARM)
        second = (m == CHECK) | (m == FILL)
        self.active = np.where(self.slot_kind == 1, first, second)
        self.driver = np.full(self.V, -1, dtype=np.int64)
        for p in np.flatnonzero(self.mode == NORMAL):
            if p < self.V:
                self.driver[p] = p
        for p in np.flatnonzero(self.mode == FILL):
            self.driver[self.succ[int(p)]] = p

    _CHECKING_STATE = ("mode", "since", "phase", "stage", "left", "detections", "stalled", "sweeps",
                       "checked", "active", "driver")

    def _finish_dead_ops(self, ports: dict, count: int, last_tick: int) -> None:
        """TickEngine's, with what the checking has done kept as it was at the last torque: the
        ops finish, and what the run reports of its checks (status, Maintenance Mode) is as
        before."""
        import copy
        kept = {name: copy.deepcopy(getattr(self, name)) for name in self._CHECKING_STATE}
        try:
            super()._finish_dead_ops(ports, count, last_tick)
        finally:
            for name, value in kept.items():
                setattr(self, name, value)

    def _drives(self, slots):
        """A slot computes the data path's values where its VAMP drives the Result line of the
        program it runs: its own (normal), or its successor's (filling in for it); a checker's
        copy of its successor's op, compared and dropped, does not (its overflows were counted a
        second time: a --vamps 7 Puma in q5.11 said 63 where the stream engine said 47)."""
        role = self.slot_role[slots]
        driver = self.driver[np.minimum(role, self.V - 1)]
        return (role < self.V) & (driver == self.slot_vamp[slots])

    def _watched(self, slots):
        """Slots of VAMPs past the warm-up of the table they run (a VAMP that has just switched
        tables runs ops on operands the other table's slots latched, by design)."""
        ok = self.tick - self.since[self.slot_vamp[slots]] >= self.w * self.P
        return slots[ok]

    def _on(self, slots):
        return None if slots is None else slots[self.active[slots]]

    def _data_tick(self, c: int, t: int) -> None:
        if self.faults:
            self._control_faults(t)
        self._latch(self._on(self.latch_a_at.get(c)), "a")
        self._latch(self._on(self.latch_b_at.get(c)), "b")
        if self.faults:
            self._register_faults(t, ("a", "b"))
        for r, j, slots in self.step_at.get(c, ()):
            on = self._on(slots)
            if on.size:
                self._step(r, j, on, t)
        new_stages = self._shifted_stages(every_tick=False, tick=t)
        dumps = self._on(self.dump_at.get(c))
        if dumps is not None and dumps.size:
            self._dump(dumps, self.res, self.res_tag)
        if self.faults:
            self._register_faults(t, ("result", "dead"))
        self._drive_lines()
        self._commit_stages(new_stages)
        if dumps is not None and dumps.size and self.mode_compare():
            self._compare(dumps, t)
        self._vcd_dump()
        self.tick += 1
        if (t + 1) % self.P == 0:
            self._period_end(t)

    def _control_tables(self, register: str):
        """`control2` faults change the second set (the successor's copy)."""
        return self.tables2 if register == "control2" else super()._control_tables(register)

    def _register_faults(self, t: int, registers) -> None:
        """As without checking, on the physical result registers (not the lines)."""
        lines, self.bus = self.bus, self.res
        lines_tag, self.tag = self.tag, self.res_tag
        try:
            super()._register_faults(t, registers)
        finally:
            self.bus, self.tag = lines, lines_tag

    def _drive_lines(self) -> None:
        """Every Result line shows the result register of the VAMP driving it."""
        d = self.driver
        on = d >= 0
        self.bus[:self.V][on] = self.res[d[on]]
        self.tag[:self.V][on] = self.res_tag[d[on]]

    def mode_compare(self) -> bool:
        """Whether this tick is in a forward stage's compare period."""
        return self.phase == "fwd" and self.left <= self.k and not self.detections \
            and self.stalled is None

    def _compare(self, dumps, t: int) -> None:
        """The checker's results against its successor's line, bit for bit, at its own dumps."""
        p = self.order[self.stage]
        if self.mode[p] != CHECK or not (self.slot_vamp[dumps] == p).any() or self._dead(p, t):
            return
        s = self.succ[p]
        mine, theirs = self.res[p, :3], self.bus[s, :3]
        if np.array_equal(_bits(mine), _bits(theirs)):
            return
        # Inhibit-out: the successor is excised, the checker drives its line from the next tick
        self.mode[s] = INHIBITED
        self.mode[p] = FILL
        self.detections.append({"tick": t, "finder": int(p), "excised": int(s)})
        self._activate()

    def _period_end(self, t: int) -> None:
        """Global-Reset after Data-Mode tick t: the sweep moves on when a stage's periods are
        done. A dead VAMP whose signal would move it on (a checker's Test-out, a VAMP's
        Test-back-out) holds it false: the sweep stalls there for good."""
        if self.detections or self.stalled is not None:
            return
        self.left -= 1
        if self.left:
            return
        V, order, now = self.V, self.order, self.tick
        if self._dead(order[self.stage], t):
            self.stalled = {"tick": t, "vamp": int(order[self.stage]), "phase": self.phase}
            return
        if self.phase == "fwd":
            p, s = order[self.stage], order[self.stage + 1]
            self.checked[s] += 1
            if self.stage + 1 < V:           # the checker fills the role it checked; s checks
                self.mode[p], self.mode[s] = FILL, CHECK
                self.since[s] = now
                self.stage += 1
                self.left = self.w + self.k
            elif V == 1:                     # E checks the only VAMP, again and again
                self.sweeps += 1
                self.left = self.w + self.k
            else:                            # the last VAMP checked: the sequence reverses
                self.phase, self.stage, self.left = "back", V - 1, self.w
                self.mode[p] = WARM if p != V else IDLE
                self.since[p] = now
        else:                                # back stage done: position `stage` drives its role
            p = order[self.stage]
            self.mode[p] = NORMAL
            q = order[self.stage - 1]
            if self.stage - 1 > 0:
                self.mode[q] = WARM
                self.since[q] = now
                self.stage -= 1
                self.left = self.w
            else:                            # E hands the first role back: the next sweep
                self.sweeps += 1
                self.mode[q] = CHECK
                self.since[q] = now
                self.phase, self.stage, self.left = "fwd", 0, self.w + self.k
        self._activate()

    def _dead(self, p: int, t: int) -> bool:
        """Whether VAMP p is dead at tick t (its control outputs false: no Inhibit-out, no
        Test-out)."""
        return any(f.kind == "dead" and f.vamp == p and f.at <= t for f in self.faults)

    # --- Maintenance Mode ---------------------------------------------------------------------
    def maintenance(self) -> dict:
        """Maintenance Mode after the run: the fault-finders' numbers broadcast to where the
        torques emerge. Returns the ticks it took, the numbers the host reads at the outputs, and
        the VAMPs they name (each finder's successor)."""
        finders = {d["finder"] for d in self.detections}
        note = np.zeros(self.rows, dtype=np.int64)          # a fault notification: a VAMP-number
        number = lambda p: self.e_number if p == self.V else int(self.ld.numbers[p])  # noqa: E731
        net = self.ld.net
        reads = [sorted({self._row(tap, r) for op in net.vamps[r].a + net.vamps[r].b
                         for tap in op.taps if tap.kind is not TapKind.BUS})
                 for r in range(self.V)]
        outs = sorted({o.vamp for o in net.outputs})
        ticks, seen = 0, set()
        for ticks in range(1, self.rows + 2):
            new = note.copy()
            for r in range(self.V):
                p = int(self.driver[r])
                if p < 0:
                    continue
                new[r] = number(p) if p in finders and self.succ.get(p) == r else \
                    max((int(note[x]) for x in reads[r]), default=0)
            lo, hi = self.stages                            # buffers shift every tick
            new[lo + 1:hi] = note[lo:hi - 1]
            new[self.first_row] = note[self.first_src]
            note = new
            seen = {int(note[o]) for o in outs} - {0}
            if finders and {number(p) for p in finders} <= seen:
                break
        by_number = {number(p): p for p in range(self.V + 1)}
        named = sorted(self.succ[by_number[n]] for n in seen if n in by_number
                       and by_number[n] in self.succ)
        from vampc.network.checking import unnameable
        lost = sorted(self.succ[p] for p in finders if number(p) not in seen)
        dead_ends = set(unnameable(net)) if lost else set()
        return {"ticks": ticks if finders else 0, "numbers": sorted(seen), "named": named,
                "unreachable": [v for v in lost if v in dead_ends]}

    def status(self) -> dict:
        """What the checking did: detections, sweeps completed, where the check is now."""
        return {"detections": list(self.detections), "sweeps": self.sweeps,
                "stalled": self.stalled,
                "stage": [self.phase, self.stage],
                "checked": int((self.checked > 0).sum()),
                "modes": {MODE_NAMES[m]: int((self.mode == m).sum())
                          for m in range(len(MODE_NAMES)) if (self.mode == m).any()}}


def sweep_periods(vamps: int, warmup: int, compare: int = 1) -> int:
    """Periods of one full sweep (forward and back) over `vamps` VAMPs."""
    return vamps * (warmup + compare) + (vamps - 1) * warmup


def check_periods(position: int, warmup: int, compare: int = 1) -> int:
    """Periods from Data Mode's start to the end of the compare periods checking chain position
    `position` (1 .. V) in the first sweep."""
    return position * (warmup + compare)


def _bits(values: np.ndarray) -> np.ndarray:
    """Words as the comparator sees them: their bit patterns."""
    a = np.ascontiguousarray(values)
    return a.view(f"i{a.dtype.itemsize}")     # (of any word's size: binary16's had failed)
