"""The stream engine: the loaded programs evaluated over a whole trajectory at once.

After the static checks (vampc.emulator.check) have resolved, by the tick rules alone, which slot,
port entry or constant every operand latch holds, and proved that each holds the value of the same
torque set, the network is a pure function per set: each slot's result is its ROM sequence applied to
its operands. That function is the *flow*: the slots in dataflow order, each naming its operands'
sources. This engine evaluates it vectorised over all sets, with the same ROM code as the tick engine,
so the two agree bit for bit; the generated C (vampc.emulator.native) evaluates the same flow.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vampc.emulator.load import Loaded
from vampc.kinds import FlowKind, SourceKind, unhandled
from vampc.machine import interp as rom
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

    def run(self, ports: dict, count: int, progress=None) -> np.ndarray:
        """Torques (count, n) of `count` sets given their input values, by input index."""
        if self.native is not None:
            return self.native.run(ports, count, progress)
        return run_numpy(self.ld, self.flow, ports, count, progress)


def run_numpy(ld: Loaded, fl: Flow, ports: dict, count: int, progress=None) -> np.ndarray:
    """The numpy path: rom.run per op over chunks of sets."""
    outs = []
    consts: dict = {}       # each constant converted once a run, as the host writes it once
    for lo in range(0, count, CHUNK):
        chunk = {p: a[lo:lo + CHUNK] for p, a in ports.items()}
        outs.append(_run_chunk(ld, fl, chunk, min(CHUNK, count - lo), consts))
        if progress is not None:
            progress(min(lo + CHUNK, count), count)
    return np.concatenate(outs, axis=0) if outs else np.zeros((0, ld.chain.n_outputs))


def _run_chunk(ld: Loaded, fl: Flow, ports, count, consts: dict) -> np.ndarray:
    vals: list[np.ndarray] = []
    arith = ld.arith
    for r, a, b in fl.ops:
        vals.append(rom.run(r, _operand(a, vals, ports, count, consts, arith),
                            _operand(b, vals, ports, count, consts, arith), arith))
    tau = np.empty((count, ld.chain.n_outputs))
    for joint, op, component in fl.outputs:
        tau[:, joint - 1] = arith.decode(vals[op][:, component])
    return tau


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
        value = consts.get(src[1])
        if value is None:        # converted by the host once a run: counted once (constant_overflows)
            value = consts[src[1]] = arith.fresh().encode(src[1])
        return np.broadcast_to(value, (count, value.size))
    return unhandled(src[0])


def overflow_sites(ld: Loaded, fl: Flow, traj, limit: int = 5, start: int = 0) -> list[str]:
    """Where the first overflows of a run of `traj` happen, in set order, at most `limit`: the
    host's conversion of an input (its port and quantity, the set, the tick it is written) or an
    op's result (the VAMP, slot and op, the set, the tick it is dumped). The numpy path runs the
    sets again with a copy of the word that notes which sets overflowed. `start`: the run's index
    of traj's first set."""
    from vampc.emulator.host import host_values
    word = ld.arith.fresh()
    word.track = []
    P, B = ld.net.period, ld.net.clock
    found: list[tuple[int, int, str]] = []          # (set, tick, what)
    ports = {}
    for i, (p, e, _) in enumerate(fl.inputs):
        entry = ld.net.ports[p].entries[e]
        word.track.clear()
        ports[i] = word.encode(host_values(ld, traj, entry.key))
        for s in _sets(word.track, start)[:limit]:
            tick = s * P + entry.block * B
            found.append((s, tick, f"set {s + 1}, tick {tick}: the host's {entry.key.quantity}"
                                   f"{entry.key.joint} for port {p}"))
    for c in ld.net.consts if start == 0 else ():     # written once, before the first set
        if constant_overflows(ld, (c,)):
            found.append((start, 0, f"set {start + 1}, tick 0: the host's constant {c.name}"))
    consts: dict = {}
    vals: list[np.ndarray] = []
    for i, (r, a, b) in enumerate(fl.ops):
        word.track.clear()
        vals.append(rom.run(r, _operand(a, vals, ports, traj.count, consts, word),
                            _operand(b, vals, ports, traj.count, consts, word), word))
        v, k = fl.names[i]
        dump = ld.schedule.finish[ld.net.vamps[v].slots[k].node] - 1     # set 0's, absolute
        for s in _sets(word.track, start)[:limit]:
            found.append((s, s * P + dump, f"set {s + 1}, tick {s * P + dump}: "
                                           f"{ld.vamp_name(v, k)}, the result of "
                                           f"{ROM[r][0].value}"))
    return [what for _, _, what in sorted(found)[:limit]]


def constant_overflows(ld: Loaded, consts=None) -> int:
    """How many scalars of the constant buffers (all, or `consts`) the host's conversion to the
    network's word overflows: counted once a run, as the host writes them once."""
    return sum(conversion_overflows(ld.arith, c.value)
               for c in (ld.net.consts if consts is None else consts))


def conversion_overflows(word, value) -> int:
    """How many scalars of `value` the host's conversion to `word` overflows (a fresh count)."""
    w = word.fresh()
    w.encode(value)
    return w.overflows


def _sets(track: list, start: int) -> list[int]:
    """The sets (rows, numbered from `start`) any of the noted calls overflowed in."""
    if not track:
        return []
    return [start + int(s) for s in np.flatnonzero(np.sum(np.stack(track), axis=0))]
