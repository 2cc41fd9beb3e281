"""Static checks run before either engine: the program's timing by the tick rules (timing.py), the
timing against the compiler's recorded schedule, and the netlist against the dataflow graph it claims
to implement (a layout-versus-schematic check).

The graph is never executed; it only names what each slot, wire and ROM pointer should be, so a
damaged word, select or wire that would happen to give the right torques on today's data is still
reported.
"""
from __future__ import annotations

from vampc.emulator import timing as tm
from vampc.emulator.load import Loaded
from vampc.errors import VampcError
from vampc.kinds import SourceKind, TapKind, unhandled
from vampc.machine.ops import Op
from vampc.memo import keep_last
from vampc.program.words import ROM
from vampc.textio import numbers_shown


@keep_last(2)
def check_program(ld: Loaded) -> tm.StaticTiming:
    """All static checks; returns the derived timing. VampcError on the first problem found. A
    program is frozen, so the last two checked are not checked again (both engines on one program)."""
    check_words(ld)
    timing = tm.derive(ld)
    check_against_schedule(ld, timing)
    check_against_graph(ld, timing)
    check_bus(ld)
    return timing


def check_bus(ld: Loaded) -> None:
    """On the Mostly-Local Bus: no two writes drive one bus at one Cycle-Counter, and every write
    is latched by some slot (derive has already found a writer for every bus a slot latches)."""
    bus = ld.net.bus
    if bus is None:
        return
    drivers = bus.drivers([b.source for b in ld.net.buffers], ld.period)
    for (k, b, c), writes in drivers.items():
        if len(writes) > 1:
            raise VampcError(f"{ld.path}: bus {b} of tier {k} is driven by {len(writes)} writers "
                             f"at Cycle-Counter {c} ({', '.join(str(w.source) for w in writes)})")
    sources = [b.source for b in ld.net.buffers]
    by_source: dict = {}                 # (source tap, counter) -> its writes
    for w in bus.writes:
        by_source.setdefault((w.source, w.counter % ld.period), []).append(w)
    read = set()
    for v, vamp in enumerate(ld.net.vamps):
        here = bus.position[v]
        for k, prog in enumerate(ld.programs[v]):
            for name, operand, counter in (("A", vamp.a[prog.sel_a], prog.delay_a),
                                           ("B", vamp.b[prog.sel_b], prog.delay_b)):
                for tap in operand.taps:
                    if tap.kind is not TapKind.BUS:
                        continue
                    tier = bus.tiers[tap.index]
                    key = (tap.index, tier.bus_at(here), counter)
                    read.add(key)
                    # the shortest of the writer's buses reaching this reader (the compiler's rule)
                    w = drivers[key][0]
                    there = bus.writer_position(w.source, sources)
                    lo, hi = min(here, there), max(here, there)
                    best = min((x.tier for x in by_source[(w.source, counter)]
                                if bus.tiers[x.tier].carries(lo, hi)),
                               key=lambda j: (bus.tiers[j].span, j))
                    if best != tap.index:
                        raise VampcError(f"{ld.path}: {ld.vamp_name(v, k)}: operand {name} latches "
                                         f"tier {tap.index}'s bus, but its writer ({w.source}) "
                                         f"drives the shorter tier {best} to it at Cycle-Counter "
                                         f"{counter} too (a damaged tier select)")
    for key, writes in drivers.items():
        if key not in read:
            k, b, c = key
            raise VampcError(f"{ld.path}: {writes[0].source} drives bus {b} of tier {k} at "
                             f"Cycle-Counter {c}, but no VAMP latches it then")


def check_words(ld: Loaded) -> None:
    """Each slot's own words before any timing is derived: its ROM pointer runs its graph node's op
    (and column), its delays are the schedule's ticks modulo the period. Checked after the timing,
    an edited delay or ROM pointer was blamed on the VAMP its result then reached at the wrong tick
    (VAMP 5's delay-R said as VAMP 26's operand re-latched: a new user's find)."""
    nodes, start, finish, P = ld.graph.nodes, ld.schedule.start, ld.schedule.finish, ld.period
    members: dict[int, list[int]] = {}
    for v in ld.net.vamps:
        for s in v.slots:
            members.setdefault(s.node, []).append(v.index)
    for v, vamp in enumerate(ld.net.vamps):
        for k, slot in enumerate(vamp.slots):
            prog = ld.programs[v][k]
            _check_rom(ld, v, k, prog.rom, nodes[slot.node], members[slot.node])
            for reg, delay, tick in (("A", prog.delay_a, start[slot.node]),
                                     ("B", prog.delay_b, start[slot.node]),
                                     ("R", prog.delay_r, finish[slot.node] - 1)):
                if delay != tick % P:
                    what = "drives its result" if reg == "R" else f"latches operand {reg}"
                    raise VampcError(f"{ld.path}: {ld.vamp_name(v, k)}: delay-{reg} {delay} {what} "
                                     f"at counter {delay}, the schedule has tick {tick} (counter "
                                     f"{tick % P})")


def _check_rom(ld: Loaded, v: int, k: int, rom: int, node, members: list) -> None:
    """The slot's ROM pointer selects its graph node's op (and, of a matrix op spread over several
    VAMPs, this VAMP's column)."""
    op, col = ROM[rom]
    if op is not node.op or (col is not None and col != members.index(v)):
        raise VampcError(f"{ld.path}: {ld.vamp_name(v, k)}: ROM pointer {rom} selects {op.value}"
                         + (f" column {col}" if col is not None else "")
                         + f", the graph node is {node.op.value}")


def check_against_schedule(ld: Loaded, timing: tm.StaticTiming) -> None:
    """Latch and dump ticks implied by the programs equal those the compiler scheduled (the delays
    themselves, a counter within the period, are check_words', first: a latch of a constant is
    harmless at any tick, but a changed word is damage)."""
    start, finish = ld.schedule.start, ld.schedule.finish
    for v, vamp in enumerate(ld.net.vamps):
        for k, slot in enumerate(vamp.slots):
            t = timing.slots[(v, k)]
            if t.periodic:
                continue
            prog = ld.programs[v][k]
            for reg, tick, want, delay in (("A", t.latch_a, start[slot.node], prog.delay_a),
                                           ("B", t.latch_b, start[slot.node], prog.delay_b),
                                           ("R", t.last, finish[slot.node] - 1, prog.delay_r)):
                if abs(tick) != tm.INF and tick != want:
                    what = "drives its result" if reg == "R" else f"latches operand {reg}"
                    raise VampcError(f"{ld.path}: {ld.vamp_name(v, k)}: delay-{reg} {delay} "
                                     f"{what} at tick {tick:g}, the schedule has tick {want}")


def check_against_graph(ld: Loaded, timing: tm.StaticTiming) -> None:
    """The sources every slot's operands resolve to match its graph node (its ROM op: check_words,
    first); outputs read the right slots."""
    nodes = ld.graph.nodes
    for v, vamp in enumerate(ld.net.vamps):
        for k, slot in enumerate(vamp.slots):
            node = nodes[slot.node]
            t = timing.slots[(v, k)]
            for name, sources, arg in (("A", t.src_a, node.args[0]), ("B", t.src_b, node.args[1])):
                carried = {_carried(ld, src) for src in sources}
                if carried != {_expected(nodes[arg])}:
                    raise VampcError(f"{ld.path}: {ld.vamp_name(v, k)}: operand {name} holds "
                                     + _not_node(ld, sources[0], nodes[arg]))
                if len(sources) > 1:
                    _check_columns(ld, v, k, name, sources, nodes[arg])
    want = {o.joint: o for o in ld.graph.outputs}
    for o, (v, k) in zip(ld.net.outputs, timing.outputs):
        node = want[o.joint].node if o.joint in want else None
        if ld.net.vamps[v].slots[k].node != node:
            raise VampcError(f"{ld.path}: τ{o.joint} is read from {ld.vamp_name(v, k)}, "
                             f"not from graph node {node}")
        if o.component != want[o.joint].component:
            raise VampcError(f"{ld.path}: io.outputs: τ{o.joint} is read from component {o.component} of "
                             f"{ld.vamp_name(v, k)}'s result, the graph's is component "
                             f"{want[o.joint].component} of node {node}")


def _check_columns(ld: Loaded, v: int, k: int, name: str, sources, node) -> None:
    """A matrix operand's taps carry its producer's columns in order: tap j column j, the column
    the producing slot's ROM entry computes (checked against the graph above). Two swapped taps
    had passed, the torques computed with the matrix's columns swapped, exit 0; on VAMPs no torque
    reads, even --check passed; `vampc report` refused the file (a new user's find). A tap from a
    port or constant buffer is not checked here: a matrix the host writes is one 9-scalar entry, one
    tap (a port of three column taps would need its columns checked too)."""
    for j, src in enumerate(sources):
        col = ROM[ld.programs[src[1]][src[2]].rom][1] if src[0] is SourceKind.SLOT else j
        if col != j:
            raise VampcError(f"{ld.path}: {ld.vamp_name(v, k)}: operand {name}'s tap {j} carries "
                             f"column {col} of node {node.label}, where column {j} belongs (the "
                             "file was edited)")


def _carried(ld: Loaded, src):
    """What a resolved source carries, in graph terms."""
    if src[0] is SourceKind.SLOT:
        return ("node", ld.net.vamps[src[1]].slots[src[2]].node)
    if src[0] is SourceKind.PORT:
        key = ld.net.ports[src[1]].entries[src[2]].key
        return ("input", key.quantity, key.joint)
    if src[0] is SourceKind.CONST:
        return ("const", tuple(ld.net.consts[src[1]].value))
    return unhandled(src[0])


def _not_node(ld: Loaded, src, node) -> str:
    """What an operand holds instead of graph node `node`: a constant of the node's name whose value
    was edited is said so (it read as another constant, named as the node is)."""
    if src[0] is SourceKind.CONST and node.op is Op.CONST and \
            ld.net.consts[src[1]].name == node.name:
        return (f"constant {node.name} (network.consts[{src[1]}]), whose value "
                f"{numbers_shown(ld.net.consts[src[1]].value)} differs from graph node {node.id}'s "
                f"{numbers_shown(node.value)} (the file was edited); recompile it")
    return f"{_describe(ld, src)}, not graph node {node.id} ({node.name})"


def _describe(ld: Loaded, src) -> str:
    if src[0] is SourceKind.SLOT:
        return f"the result of {ld.vamp_name(src[1], src[2])}"
    if src[0] is SourceKind.PORT:
        key = ld.net.ports[src[1]].entries[src[2]].key
        return f"port {src[1]}'s {key.label}"
    if src[0] is SourceKind.CONST:
        return f"constant {ld.net.consts[src[1]].name}"
    return unhandled(src[0])


def _expected(node):
    if node.op is Op.INPUT:
        return ("input", node.key.quantity, node.key.joint)
    if node.op is Op.CONST:
        return ("const", tuple(node.value))
    return ("node", node.id)
