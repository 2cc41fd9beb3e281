"""Canonical text dumps of the compiler's IRs (`vampc compile --dump-after STAGE`, and the goldens
under tests/golden/).

Deterministic: ids and indices in order, no memory addresses, floating-point constants as Python's
shortest round-trip repr. One line per node, unit, VAMP input, slot, buffer, port entry, constant,
output or program word, so a diff shows exactly what changed.
"""
from __future__ import annotations

from vampc.program.words import FIELDS


def dump_graph(graph) -> str:
    """The dataflow graph: `id op args section group name [key | value]`, then the outputs."""
    lines = [f"# {graph.recursion} graph, n = {graph.n}: id op args section group name [key|value]"]
    for nd in graph.nodes:
        args = ",".join(map(str, nd.args)) or "-"
        extra = (f" {nd.key.label}" if nd.key else
                 f" [{', '.join(map(repr, nd.value))}]" if nd.value is not None else "")
        lines.append(f"{nd.id} {nd.op.value} {args} {nd.section} {nd.group} {nd.name}{extra}")
    lines += [f"output tau{o.joint} = node {o.node} component {o.component}"
              for o in sorted(graph.outputs, key=lambda o: o.joint)]
    return "\n".join(lines) + "\n"


def dump_schedule(graph, sched, layout) -> str:
    """The layout and schedule: `id start finish unit` per compute node, then the summary."""
    units = layout.units
    lines = [f"# {layout.name} layout{' (shared passes)' if layout.share_passes else ''}: "
             + (f"{layout.vamp_count} VAMPs" if not layout.grouped else
              f"{len(layout.unit_vamps)} units") +
             f", period {layout.period}, buffer clock {layout.clock}",
             "# id start finish " + ("vamps" if not layout.grouped else "unit")]
    lines += [f"{nd.id} {sched.start[nd.id]} {sched.finish[nd.id]} "
              + (",".join(map(str, layout.placement[nd.id])) if not layout.grouped
                 else str(units[nd.id]))
              for nd in graph.compute_nodes()]
    lines.append(f"latency {sched.latency} = {sched.mults} M + {sched.adds} A + {sched.waits} waiting,"
                 f" interval {sched.interval}")
    lines.append("critical path " + " ".join(map(str, sched.critical_path)))
    return "\n".join(lines) + "\n"


def _operand(op) -> str:
    return "+".join(str(t).replace(" ", ":") for t in op.taps)


def dump_network(net) -> str:
    """The network: per VAMP its multiplexer inputs and slots, then buffers, ports, constants,
    outputs."""
    lines = [f"# network: period {net.period}, buffer clock {net.clock}, {len(net.vamps)} VAMPs, "
             f"{net.slot_count} slots"]
    for v in net.vamps:
        lines.append(f"vamp {v.index} A[{' '.join(map(_operand, v.a))}] "
                     f"B[{' '.join(map(_operand, v.b))}]")
        lines += [f"  slot {k}: node {s.node} {s.op.value}"
                  + (f" column {s.column}" if s.column is not None else "")
                  + f" sel {s.sel_a},{s.sel_b} latch {s.latch_a},{s.latch_b} dump {s.dump}"
                  for k, s in enumerate(v.slots)]
    lines += [f"buffer {b.index} behind vamp {b.source}: {b.stages} stages" for b in net.buffers]
    for p in net.ports:
        entries = " ".join(f"{e.key.label}@{e.block}" for e in p.entries)
        lines.append(f"port {p.index} ({p.size}): {entries or 'program only'}")
    lines += [f"const {c.index} {c.name} [{', '.join(map(repr, c.value))}]" for c in net.consts]
    lines += [f"output tau{o.joint} = vamp {o.vamp} component {o.component} at tick {o.tick}"
              for o in sorted(net.outputs, key=lambda o: o.joint)]
    bus = net.bus
    if bus is not None:
        lines.append(f"bus: {len(bus.tiers)} tiers, stretch {bus.stretch}, wait {bus.wait}")
        lines += [f"tier {k}: span {t.span} offset {t.offset}" for k, t in enumerate(bus.tiers)]
        lines.append("line: " + " ".join(map(str, bus.position)))
        lines += [f"write {str(w.source).replace(' ', ':')} at {w.counter} on tier {w.tier}"
                  for w in bus.writes]
    return "\n".join(lines) + "\n"


def _word(w) -> str:
    return "(" + ", ".join(f"{x:g}" for x in w) + ")"


def dump_program(c) -> str:
    """The programs (per VAMP: number and slot fields), error correction's chain where the network
    has one, and the Program-Mode stream (per root input: target and word, one per tick)."""
    lines = ["# programs: vamp number, then per slot " + " ".join(FIELDS)]
    for v, (number, progs) in enumerate(zip(c.numbering, c.programs)):
        slots = "; ".join(" ".join(str(p.field(f)) for f in FIELDS) for p in progs)
        lines.append(f"vamp {v} #{number}: {slots}")
    checking = c.network.checking
    if checking is not None:     # (--error-correction's chain had not been printed: a new user's)
        lines.append(f"error correction: extraneous vamp {len(checking.chain)}, then chain "
                     f"{' '.join(map(str, checking.chain))}; warm-up {checking.warmup} periods, "
                     f"compare {checking.compare}")
    for e in c.stream:
        lines.append(f"stream {e.root}: {len(e.words)} words")
        lines += [f"  {k} -> vamp {t} depth {d} {_word(w)}"
                  for k, (t, d, w) in enumerate(zip(e.targets, e.depth, e.words))]
    return "\n".join(lines) + "\n"


def dump_after(stage: str, c) -> str:
    """The dump of the IR a compile stage (vampc.compiler.STAGES) hands on."""
    if stage == "graph":
        return dump_graph(c.graph)
    if stage == "schedule":
        return dump_schedule(c.graph, c.schedule, c.layout)
    if stage == "allocate":
        return dump_network(c.network)
    return dump_program(c)
