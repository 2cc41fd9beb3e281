"""The stream engine: the loaded programs evaluated over a whole trajectory at once.

After the static checks (vampc.emulator.check) have resolved, by the tick rules alone, which slot,
port entry or constant every operand latch holds, and proved that each holds the value of the same
torque set, the network is a pure function per set: each slot's result is its ROM sequence applied to
its operands. That function is the *flow*: the slots in dataflow order, each naming its operands'
sources. This engine evaluates it vectorised over all sets, with the same ROM code as the tick engine,
so the two agree bit for bit; the generated C (vampc.emulator.native) evaluates the same flow. Big
networks and short runs go in batches (`Batches`: every op of one level and ROM entry in one call),
and the sets in chunks whose values fit in VALUE_BYTES.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vampc.emulator.load import Loaded
from vampc.kinds import FlowKind, SourceKind, unhandled
from vampc.machine import interp as rom
from vampc.machine.arith import canonical_nan
from vampc.machine.ops import ROM

CHUNK = 4096   # torque sets evaluated together: keeps the working set in cache


@dataclass(frozen=True)
class Flow:
    """The network as a function per torque set. Sources are (FlowKind.OP, i): the result of op i;
    (FlowKind.IN, i): input i (a port entry, written by the host each set); (FlowKind.CONST,
    values)."""

    ops: tuple[tuple[int, tuple, tuple], ...]      # (ROM pointer, A's sources, B's sources)
    names: tuple[tuple[int, int], ...]             # (VAMP, slot) of each op
    inputs: tuple[tuple[int, int, int], ...]       # (port, entry, scalars) of each input
    outputs: tuple[tuple[int, int, int], ...]      # (joint, op, component)


def flow(ld: Loaded, timing) -> Flow:
    """The flow of a checked program (`timing`: vampc.emulator.timing.derive's result)."""
    op_of = {slot: i for i, slot in enumerate(timing.order)}
    inputs: dict[tuple[int, int], int] = {}

    def source(src):
        if src[0] is SourceKind.SLOT:
            return (FlowKind.OP, op_of[(src[1], src[2])])
        if src[0] is SourceKind.PORT:
            key = (src[1], src[2])
            if key not in inputs:
                inputs[key] = len(inputs)
            return (FlowKind.IN, inputs[key])
        if src[0] is SourceKind.CONST:
            return (FlowKind.CONST, tuple(ld.net.consts[src[1]].value))
        return unhandled(src[0])

    ops = []
    for v, k in timing.order:
        t = timing.slots[(v, k)]
        ops.append((ld.programs[v][k].rom, tuple(map(source, t.src_a)), tuple(map(source, t.src_b))))
    ins = tuple((p, e, ld.net.ports[p].size) for (p, e), _ in sorted(inputs.items(),
                                                                     key=lambda kv: kv[1]))
    outs = tuple((o.joint, op_of[slot], o.component)
                 for o, slot in zip(ld.net.outputs, timing.outputs))
    return Flow(tuple(ops), tuple(timing.order), ins, outs)


def run_stream(ld: Loaded, fl: Flow, ports: dict, count: int, progress=None) -> np.ndarray:
    """Torques (count, n) given each input's values (count, 3|9) for every set.
    `progress(done, total)` is called after each chunk if given."""
    return StreamEngine(ld, fl, count).run(ports, count, progress)


class StreamEngine:
    """The stream engine prepared once for a run of `total` sets, which may arrive in chunks."""

    def __init__(self, ld: Loaded, fl: Flow, total: int):
        # --- native fast path (vampc.emulator.native): the same arithmetic as generated C. None
        # when off (VAMPC_NATIVE=0), when no compiler works, or for a run too short to pay for
        # compiling; numpy does the work then ---
        from vampc.emulator.native import prepare
        self.ld, self.flow = ld, fl
        self.native = prepare(ld, fl, total)
        self.batches = (Batches(fl) if self.native is None and batched_pays(fl, ld.arith, total)
                        else None)

    def run(self, ports: dict, count: int, progress=None) -> np.ndarray:
        """Torques (count, n) of `count` sets given their input values, by input index."""
        if self.native is not None:
            return canonical_nan(self.native.run(ports, count, progress))
        if self.batches is None and batched_pays(self.flow, self.ld.arith, count):
            self.batches = Batches(self.flow)      # (a short last chunk of a long run: made once)
        return run_numpy(self.ld, self.flow, ports, count, progress, self.batches)


def run_numpy(ld: Loaded, fl: Flow, ports: dict, count: int, progress=None,
              plan: Batches | None = None) -> np.ndarray:
    """The numpy path over chunks of sets, sized so the values of every op of a chunk fit in
    VALUE_BYTES: one rom.run per op (each over the whole chunk) while a chunk holds at least
    BATCHED_BELOW sets; below that (a big network, or a short run), the per-call cost of a
    network's every op outweighs its arithmetic, and the flow runs in `Batches` (one rom.run per
    level and ROM entry). `plan`: the flow's Batches, if already made."""
    if batched_pays(fl, ld.arith, count):
        plan = plan or Batches(fl)
        if plan.plain:
            return _chunks(ld, count, progress, plan.chunk(ld.arith), ports,
                           lambda chunk, n, consts: plan.run(ld, chunk, n, consts))
    return _chunks(ld, count, progress, _sets_per_chunk(len(fl.ops), ld.arith), ports,
                   lambda chunk, n, consts: _run_chunk(ld, fl, chunk, n, consts))


def _chunks(ld: Loaded, count: int, progress, size: int, ports: dict, run) -> np.ndarray:
    """run(ports of a chunk, its sets, constants) over chunks of `size` sets, their torques."""
    outs = []
    consts: dict = {}       # each constant converted once a run, as the host writes it once
    for lo in range(0, count, size):
        chunk = {p: a[lo:lo + size] for p, a in ports.items()}
        outs.append(run(chunk, min(size, count - lo), consts))
        if progress is not None:
            progress(min(lo + size, count), count)
    return np.concatenate(outs, axis=0) if outs else np.zeros((0, ld.chain.n_outputs))


def _sets_per_chunk(rows: int, arith) -> int:
    """Sets whose values of `rows` rows of 3 words fit in VALUE_BYTES: at most CHUNK, at least 1."""
    per_set = max(rows, 1) * 3 * np.dtype(arith.dtype).itemsize
    return int(max(1, min(CHUNK, VALUE_BYTES // per_set)))


def batched_pays(fl: Flow, arith, total: int) -> bool:
    """Whether run_numpy runs a run of `total` sets of this flow in Batches."""
    return min(_sets_per_chunk(len(fl.ops), arith), total) < BATCHED_BELOW


def run_per_op(ld: Loaded, fl: Flow, ports: dict, count: int) -> np.ndarray:
    """The flow one op at a time (rom.run per op, over every set at once): the plain reading of
    the flow, against which the batched path is tested."""
    return _run_chunk(ld, fl, ports, count, {})


VALUE_BYTES = 256 << 20   # the values of every op for a chunk of sets, at most (a 1024-joint log
# network's 215 042 ops took 5.2 MB a set: 4096 sets would have been 21 GB)
BATCHED_BELOW = 512       # sets per chunk below which the flow runs in Batches (measured: above
# it, one call per op over the chunk is as fast or faster, the batches' gathers copying the values)


class Batches:
    """The flow rearranged for batched evaluation. Every value is held in rows of 3 scalars of a
    table (rows, sets, 3): an op's result (row = its index), an input or constant of 3 scalars (one
    row) or of 9 (three rows, its columns: column j is scalars j, j+3, j+6, so that stacking
    them back gives the 9 scalars, as `_operand` stacks an MM group's three columns). An operand
    is 1 row (a vector) or 3 (a matrix by columns). Each op's level is one more than the highest
    of the ops it reads (0: reads no op); the ops of one level and ROM entry, whose operands have
    the same number of rows, are one batch, run in one rom.run call. Elementwise, the same
    arithmetic in the same order per value as one op at a time: the same bits."""

    def __init__(self, fl: Flow):
        n_ops = len(fl.ops)
        rows = n_ops
        self.outputs = fl.outputs
        self.inputs: list[tuple[int, int, int]] = []     # (input index, first row, rows)
        self.consts: list[tuple[tuple, int, int]] = []   # (values, first row, rows)
        placed_in: dict[int, int] = {}
        placed_const: dict[tuple, int] = {}
        sizes = {i: size for i, (_, _, size) in enumerate(fl.inputs)}

        def rows_of(src) -> list[int]:          # (an input's or a constant's: `operand` reads ops)
            nonlocal rows
            kind, what = src
            if kind is FlowKind.IN:
                placed, listed, scalars = placed_in, self.inputs, sizes[what]
            elif kind is FlowKind.CONST:
                placed, listed, scalars = placed_const, self.consts, len(what)
            else:
                unhandled(kind)
            span = 3 if scalars == 9 else 1
            first = placed.get(what)
            if first is None:
                first = placed[what] = rows
                listed.append((what, first, span))
                rows += span
            return list(range(first, first + span))

        level = [0] * n_ops
        groups: dict[tuple, tuple[list, list, list]] = {}
        OP = FlowKind.OP
        self.plain = True        # False: an operand this layout cannot hold (run op by op)

        def operand(x) -> tuple[tuple, int]:        # (its rows, the level of an op reading it)
            if len(x) == 1:
                kind, what = x[0]
                if kind is OP:                       # (the common case by far)
                    return (what,), level[what] + 1
                return tuple(rows_of(x[0])), 0       # (an input or a constant: level 0)
            if any(src[0] is not OP for src in x):
                return (), -1                        # a matrix of columns not all op results
            return tuple(what for _, what in x), max(level[what] for _, what in x) + 1
        for i, (r, a, b) in enumerate(fl.ops):
            ra, la = operand(a)
            rb, lb = operand(b)
            if la < 0 or lb < 0:
                self.plain = False
                return
            deepest = level[i] = la if la > lb else lb
            members, ras, rbs = groups.setdefault((deepest, r, len(ra), len(rb)), ([], [], []))
            members.append(i)
            ras.append(ra)
            rbs.append(rb)
        self.rows = rows
        self.batches = tuple((r, np.array(members), np.array(ras), np.array(rbs))
                             for (_, r, _, _), (members, ras, rbs) in sorted(groups.items()))

    def chunk(self, arith) -> int:
        """Sets per chunk: every row's values within VALUE_BYTES, at most CHUNK, at least 1."""
        return _sets_per_chunk(self.rows, arith)

    def run(self, ld: Loaded, ports, count: int, consts: dict) -> np.ndarray:
        arith = ld.arith
        table = np.zeros((self.rows, count, 3), dtype=arith.dtype)
        for i, first, span in self.inputs:
            value = ports[i]
            if span == 1:
                table[first] = value
            else:
                table[first:first + 3] = value.reshape(count, 3, 3).transpose(2, 0, 1)
        for values, first, span in self.consts:
            value = _constant(values, consts, arith)
            table[first:first + span] = value.reshape(3, 3).T[:, None, :] if span == 3 else value
        for r, members, ra, rb in self.batches:
            out = rom.run(r, _gathered(table, ra, count), _gathered(table, rb, count), arith,
                          canonical=False)
            table[members] = out
        tau = np.empty((count, ld.chain.n_outputs))
        for joint, op, component in self.outputs:
            tau[:, joint - 1] = arith.decode(table[op, :, component])
        return canonical_nan(tau)


def _gathered(table: np.ndarray, rows: np.ndarray, count: int) -> np.ndarray:
    """A batch's operands (k, sets, 3) from rows (k, 1), or (k, sets, 9) from rows (k, 3), the
    scalars of each matrix in the order `_operand` stacks its columns."""
    if rows.shape[1] == 1:
        return table[rows[:, 0]]
    cols = table[rows]                               # (k, column, set, scalar)
    return cols.transpose(0, 2, 3, 1).reshape(len(rows), count, 9)


def _run_chunk(ld: Loaded, fl: Flow, ports, count, consts: dict) -> np.ndarray:
    vals: list[np.ndarray] = []
    arith = ld.arith
    for r, a, b in fl.ops:
        vals.append(rom.run(r, _operand(a, vals, ports, count, consts, arith),
                            _operand(b, vals, ports, count, consts, arith), arith, canonical=False))
    tau = np.empty((count, ld.chain.n_outputs))
    for joint, op, component in fl.outputs:
        tau[:, joint - 1] = arith.decode(vals[op][:, component])
    return canonical_nan(tau)


def _operand(sources, vals, ports, count, consts, arith) -> np.ndarray:
    if len(sources) == 3:   # a matrix delivered as three column results of an MM group
        cols = [_value(s, vals, ports, count, consts, arith)[:, :3] for s in sources]
        return np.stack(cols, axis=-1).reshape(count, 9)
    return _value(sources[0], vals, ports, count, consts, arith)


def _value(src, vals, ports, count, consts, arith) -> np.ndarray:
    if src[0] is FlowKind.OP:
        return vals[src[1]]
    if src[0] is FlowKind.IN:
        return ports[src[1]]
    if src[0] is FlowKind.CONST:
        value = _constant(src[1], consts, arith)
        return np.broadcast_to(value, (count, value.size))
    return unhandled(src[0])


def _constant(values: tuple, consts: dict, arith) -> np.ndarray:
    """A constant's words, converted by the host once a run (`consts`: those converted so far):
    its overflows counted once (constant_overflows)."""
    value = consts.get(values)
    if value is None:
        value = consts[values] = arith.fresh().encode(values)
    return value


def overflow_sites(ld: Loaded, fl: Flow, traj, limit: int = 5, start: int = 0) -> list[str]:
    """Where the first overflows of a run of `traj` happen, in set order, at most `limit`: the
    host's conversion of an input (its port and quantity, the set, the tick it is written) or an
    op's result (the VAMP, slot and op, the set, the tick it is dumped). The numpy path runs the
    sets again with a copy of the word that notes which sets overflowed, one op at a time over
    chunks whose values fit in VALUE_BYTES (all of a run's sets at once had taken 1.5 GB for a
    128-joint log program's 980 sets). `start`: the run's index of traj's first set."""
    from dataclasses import replace
    size = _sets_per_chunk(len(fl.ops), ld.arith)
    found: list[str] = []
    for lo in range(0, traj.count, size):
        part = replace(traj, **{k: getattr(traj, k)[lo:lo + size] for k in ("q", "qd", "qdd", "t", "base")
                                if getattr(traj, k) is not None})
        found += _overflow_sites(ld, fl, part, limit - len(found), start + lo)
        if len(found) >= limit:
            break
    return found[:limit]


def _overflow_sites(ld: Loaded, fl: Flow, traj, limit: int, start: int) -> list[str]:
    from vampc.emulator.host import host_values
    word = ld.arith.fresh()
    word.track = []
    P, B = ld.net.period, ld.net.clock
    found: list[tuple[int, int, str]] = []          # (set, tick, what)
    ports = {}
    # one value the host converts once and writes to several ports is one overflow (as counted),
    # said once with its ports (2 overflows had been listed in 3 places: an audit's)
    written: dict[tuple, list] = {}       # (set, quantity, joint) -> [first tick, ports]
    for i, (p, e, _) in enumerate(fl.inputs):
        entry = ld.net.ports[p].entries[e]
        word.track.clear()
        ports[i] = word.encode(host_values(ld, traj, entry.key))
        for s, n in _sets(word.track, start)[:limit]:
            tick = s * P + entry.block * B
            site = written.setdefault((s, str(entry.key.quantity), entry.key.joint), [tick, [], n])
            site[0] = min(site[0], tick)
            site[1].append(p)
    for (s, quantity, joint), (tick, where, n) in written.items():
        listed = (f"port {where[0]}" if len(where) == 1 else
                  f"ports {', '.join(map(str, where[:-1]))} and {where[-1]}")
        found.append((s, tick, f"set {s + 1}, tick {tick}: the host's "
                               f"{quantity}{joint if joint else ''} for "
                               f"{listed}{_scalars(n)}"))
    for c in ld.net.consts if start == 0 else ():     # written once, before the first set
        n = constant_overflows(ld, (c,))
        if n:
            found.append((start, 0, f"set {start + 1}, tick 0: the host's constant {c.name}{_scalars(n)}"))
    consts: dict = {}
    vals: list[np.ndarray] = []
    for i, (r, a, b) in enumerate(fl.ops):
        word.track.clear()
        vals.append(rom.run(r, _operand(a, vals, ports, traj.count, consts, word),
                            _operand(b, vals, ports, traj.count, consts, word), word))
        v, k = fl.names[i]
        dump = ld.schedule.finish[ld.net.vamps[v].slots[k].node] - 1     # set 0's, absolute
        for s, n in _sets(word.track, start)[:limit]:
            found.append((s, s * P + dump, f"set {s + 1}, tick {s * P + dump}: "
                                           f"{ld.vamp_name(v, k)}, the result of "
                                           f"{ROM[r][0].value}{_scalars(n)}"))
    return [what for _, _, what in sorted(found)[:limit]]


def constant_overflows(ld: Loaded, consts=None) -> int:
    """How many scalars of the constant buffers (all, or `consts`) the host's conversion to the
    network's word overflows: counted once a run, as the host writes them once."""
    return sum(conversion_overflows(ld.arith, c.value)
               for c in (ld.net.consts if consts is None else consts))


def count_overflows_from_here(ld: Loaded) -> None:
    """Start a run's overflow count on the network's word: the constants' conversion, which the
    host writes once a run, then every result and host word the run overflows (ld.arith.overflows
    after it)."""
    ld.arith.overflows = constant_overflows(ld)


def conversion_overflows(word, value) -> int:
    """How many scalars of `value` the host's conversion to `word` overflows (a fresh count)."""
    w = word.fresh()
    w.encode(value)
    return w.overflows


def _sets(track: list, start: int) -> list[tuple[int, int]]:
    """The sets (rows, numbered from `start`) any of the noted calls overflowed in, each with how
    many scalars overflowed there (the run's count is of scalars: a VC overflowing in two
    components had been listed once beside a count of 2, a new user's find)."""
    if not track:
        return []
    per = np.sum(np.stack(track), axis=0)
    return [(start + int(s), int(per[s])) for s in np.flatnonzero(per)]


def _scalars(n: int) -> str:
    """' (2 scalars)' where a site overflowed in more than one scalar, else ''."""
    return f" ({n} scalars)" if n > 1 else ""
