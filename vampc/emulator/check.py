"""Static checks run before either engine: the program's timing by the tick rules (timing.py), the
timing against the compiler's recorded schedule, and the netlist against the dataflow graph it claims
to implement (a layout-versus-schematic check).

The graph is never executed; it only names what each wire and ROM pointer should be, so a damaged word
or wire that would happen to give the right torques on today's data is still reported.
"""
from __future__ import annotations

from vampc.dataflow.ops import Op
from vampc.emulator import timing as tm
from vampc.emulator.load import Loaded
from vampc.errors import VampcError
from vampc.program.words import ROM


def check_program(ld: Loaded) -> tuple[tm.VampTiming, ...]:
    """All static checks; returns the derived timing. VampcError on the first problem found."""
    timing = tm.derive(ld)
    tm.check_outputs(ld, timing)
    check_against_schedule(ld, timing)
    check_against_graph(ld)
    return timing


def check_against_schedule(ld: Loaded, timing) -> None:
    """Latch and dump ticks implied by the programs equal those the compiler scheduled, and so do the
    delays themselves (a latch of a constant is harmless at any tick, but a changed word is damage)."""
    start, finish = ld.doc["schedule"]["start"], ld.doc["schedule"]["finish"]
    C = ld.cycle
    for v, t in zip(ld.net.vamps, timing):
        want = {"A": start[v.node], "B": start[v.node], "R": finish[v.node] - 1}
        got = {"A": t.latch_a, "B": t.latch_b, "R": t.last}
        prog = ld.programs[v.index]
        delay = {"A": prog.delay_a, "B": prog.delay_b, "R": prog.delay_r}
        for reg in ("A", "B", "R"):
            tick = got[reg] if abs(got[reg]) != tm.INF else None
            if delay[reg] != want[reg] % C or tick not in (None, want[reg]):
                what = "drives its result" if reg == "R" else f"latches operand {reg}"
                at = f"at tick {tick:g}" if tick is not None else f"at counter {delay[reg]}"
                raise VampcError(f"{ld.path}: {ld.vamp_name(v.index)}: delay-{reg} {delay[reg]} "
                                 f"{what} {at}, the schedule has tick {want[reg]}")


def check_against_graph(ld: Loaded) -> None:
    """Every VAMP's ROM op and operand wires match its graph node; outputs read the right VAMPs."""
    nodes = ld.doc["graph"]["nodes"]
    members: dict[int, list[int]] = {}
    for v in ld.net.vamps:
        members.setdefault(v.node, []).append(v.index)
    for v in ld.net.vamps:
        node = nodes[v.node]
        op, col = ROM[ld.programs[v.index].rom]
        if op.value != node["op"] or (op is Op.MM and col != members[v.node].index(v.index)):
            raise VampcError(f"{ld.path}: {ld.vamp_name(v.index)}: ROM pointer "
                             f"{ld.programs[v.index].rom} selects {op.value}"
                             + (f" column {col}" if op is Op.MM else "")
                             + f", the graph node is {node['op']}")
        for name, operand, arg in (("A", v.a, node["args"][0]), ("B", v.b, node["args"][1])):
            carried = {_carried(ld, tap) for tap in operand.taps}
            if carried != {_expected(nodes[arg])}:
                raise VampcError(f"{ld.path}: {ld.vamp_name(v.index)}: operand {name} is wired to "
                                 f"{operand.taps[0]}, which does not carry graph node {arg} "
                                 f"({nodes[arg]['name']})")
    for o in ld.net.outputs:
        want = next(out[1] for out in ld.doc["graph"]["outputs"] if out[0] == o.joint)
        if ld.net.vamps[o.vamp].node != want:
            raise VampcError(f"{ld.path}: τ{o.joint} is read from {ld.vamp_name(o.vamp)}, "
                             f"not from graph node {want}")


def _carried(ld: Loaded, tap):
    """What a tap carries, in graph terms."""
    if tap.kind == "vamp":
        return ("node", ld.net.vamps[tap.index].node)
    if tap.kind == "buffer":
        return ("node", ld.net.vamps[ld.net.buffers[tap.index].source].node)
    if tap.kind == "port":
        key = ld.net.ports[tap.index].key
        return ("input", key.quantity, key.joint)
    return ("const", tuple(ld.net.consts[tap.index].value))


def _expected(node: dict):
    if node["op"] == "INPUT":
        return ("input", node["key"][0], node["key"][1])
    if node["op"] == "CONST":
        return ("const", tuple(node["value"]))
    return ("node", node["id"])
