"""Loading a program file into the emulator's typed IRs, read once from the file.

The programs the emulator runs are those the Program-Mode stream delivers: a VAMP latches every word
carrying its number (or its negated number: an extended word) among the words written to the root of
its Operand-A path (vampc.program.emit), and its slot table is what those words leave
(vampc.program.words.apply_word). The file's `programs` section is a readable listing; it must agree
with the stream, and it names the graph node each slot claims to implement (which the static checks
hold it to).
"""
from __future__ import annotations

from dataclasses import dataclass

from vampc.dataflow.graph import Graph
from vampc.errors import VampcError
from vampc.gcpause import gc_paused
from vampc.kinds import TapKind
from vampc.machine.ops import Op, Timing
from vampc.network.model import (
    PROGRAM_WIRE_READ,
    Network,
    Tap,
    program_wire,
    tap_source,
)
from vampc.program.document import (
    chain_from_doc,
    graph_from_doc,
    network_from_doc,
    programs_from_doc,
    schedule_of,
    stream_from_doc,
    typed,
)
from vampc.program.emit import StreamEntry, a_roots, load_ticks
from vampc.program.file import read_program_file
from vampc.program.words import (
    FIELDS,
    PACKING,
    ROM,
    Packing,
    Program,
    apply_word,
    word_number,
)
from vampc.robot.chain import Chain
from vampc.schedule.asap import Schedule
from vampc.textio import shown


@dataclass(frozen=True)
class Loaded:
    """A program file ready to emulate: typed IRs only."""

    path: str
    chain: Chain
    graph: Graph                     # what the network claims to implement (never executed)
    schedule: Schedule               # the compiler's recorded schedule (checked, never used to run)
    timing: Timing                   # the VAMP's Mult and Addn latencies, in ticks
    net: Network                     # wiring; slot fields are the listing's Cycle-Counter values
    numbers: tuple[int, ...]         # burned-in VAMP numbers, by logical index
    stream: tuple[StreamEntry, ...]  # what the host writes in Program Mode
    programs: tuple[tuple[Program, ...], ...]   # what Program Mode delivers to each VAMP
    load_ticks: int
    compiled_with: tuple = ()        # the compile options recorded in the file, as (name, value)
    word: object = None              # the word format (vampc.machine.arith); None: float64
    packing: object = PACKING        # how the recorded word carries Program-Mode words

    @property
    def options(self) -> dict:
        """The compile options recorded in the file."""
        return dict(self.compiled_with)

    @property
    def arith(self):
        """The word format the network computes in (vampc.machine.arith), which every engine
        calls or renders, and which counts its overflows; float64 unless one is given."""
        from vampc.machine.arith import FLOAT64
        return FLOAT64 if self.word is None else self.word

    @property
    def period(self) -> int:
        """P: ticks between successive torque sets."""
        return self.net.period

    @property
    def cycle(self) -> int:
        """The period (the name the systolic layout's code used: there P = C)."""
        return self.net.period

    def vamp_name(self, index: int, slot: int | None = None) -> str:
        """'VAMP 12 (number 13, bwd2.T4)': how messages name a VAMP (and one of its slots)."""
        slots = self.net.vamps[index].slots
        k = 0 if slot is None else slot
        node = self.graph.nodes[slots[k].node].label if k < len(slots) else "?"
        where = f" slot {slot}" if slot is not None and len(slots) > 1 else ""
        return f"VAMP {index}{where} (number {self.numbers[index]}, {node})"


def load_program(path: str) -> Loaded:
    """Read, validate and decode a program file."""
    return loaded_from_doc(read_program_file(path), str(path))


@gc_paused()
def loaded_from_doc(doc, path: str = "<program>", decoded=None) -> Loaded:
    """Decode a document: a vampc.program.format.ProgramFile as a file reads, or the same as dicts
    (tests corrupt documents and call this directly; checked as a file's Structs are).
    `decoded`: the (chain, graph, network, listed programs) already read from this same document,
    which a report has (vampc.program.document.compiled_from_doc): they are used instead of
    decoding again."""
    doc = typed(doc, path)
    chain, graph, net, listed = decoded or (None, graph_from_doc(doc.graph, path),
                                            network_from_doc(doc, path), None)
    if decoded is None:       # (a report's decoded IRs were checked so: compiled_from_doc)
        from vampc.program.document import recorded_options, schedule_from_doc
        options = recorded_options(doc, graph, path)
        sched = schedule_from_doc(doc.schedule, graph, path)
    else:
        sched = schedule_of(doc.schedule)
    numbers = tuple(v.number for v in doc.network.vamps)
    ld = _loaded(str(path), chain or chain_from_doc(doc.robot, graph, path), graph, sched, net,
                 numbers,
                 stream_from_doc(doc), listed or programs_from_doc(doc),
                 tuple(sorted(doc.options.recorded().items())), recorded_word(doc.options.recorded(), path))
    if doc.io.load_ticks != ld.load_ticks:
        raise VampcError(f"{path}: io.load_ticks {doc.io.load_ticks} is not the {ld.load_ticks} "
                         "ticks the program stream takes")
    if sched.interval != net.period:           # (after the network's own checks: said first)
        raise VampcError(f"{path}: schedule.interval {sched.interval} is not the network's "
                         f"period {net.period}")
    from vampc.program.document import check_port_writes, check_tiers
    check_port_writes(doc.network, doc.io.port_writes, path)   # (last: a missing port said first)
    if decoded is None:       # (a report's: compiled_from_doc)
        check_tiers(doc, options, path)
    return ld


def loaded_from_compiled(c, path: str = "<compiled>") -> Loaded:
    """The emulator's IRs straight from the compiler's (a vampc.compiler.Compiled), in the same
    process: no program document is made or parsed. The same checks as a file's: the stream must
    deliver the listed programs."""
    net = counter_network(c.network, c.programs)
    opts = c.options.record()
    return _loaded(path, c.chain, c.graph, c.schedule, net, c.numbering, c.stream, c.programs,
                   tuple(sorted(opts.items())), recorded_word(opts, path))


def counter_network(net: Network, programs) -> Network:
    """The network with its scheduled slots as programmed ones: Cycle-Counter values (what a loaded
    network holds: absolute times are the emulator's to derive)."""
    from dataclasses import replace

    import msgspec

    from vampc.network.model import ProgrammedSlot
    vamps = tuple(msgspec.structs.replace(v, slots=tuple(ProgrammedSlot(s.node, s.op, s.column, p.sel_a, p.sel_b,
                                                        p.delay_a, p.delay_b, p.delay_r)
                                         for s, p in zip(v.slots, progs)))
                  for v, progs in zip(net.vamps, programs))
    return replace(net, vamps=vamps)


def _loaded(path: str, chain, graph, sched, net, numbers, stream, listed, options,
            word=None) -> Loaded:
    """The one loader both engines run from: indices checked, the programs the stream delivers
    (which must be the listed ones), the Program-Mode length."""
    check_indices(net, numbers, graph, path)
    progs = delivered_programs(net, numbers, stream, path, Packing.of(word))
    _check_listing(listed, progs, path)
    from vampc.network.checking import check_checking
    recorded = dict(options)
    check_checking(net, progs, sched.timing, recorded.get("error_correction", False), path,
                   recorded.get("check_cycles", 1))
    return Loaded(path, chain, graph, sched, sched.timing, net, numbers, stream, progs,
                  load_ticks(stream), options, word, Packing.of(word))


def in_word(ld: Loaded, word) -> Loaded:
    """The program run in another word format (a what-if; None: float64). Its Program-Mode words,
    packed for the word it records, must travel in the new one (ValueError saying why not), so
    both engines take or refuse it alike."""
    from dataclasses import replace

    from vampc.program.words import number_problem
    problem = number_problem(max(ld.numbers, default=1), Packing.of(word))
    if problem:     # (the advice to compile for the word failed on this: a new user's find)
        raise ValueError(f"{problem}: no program of this network can be packed for that word")
    ld = replace(ld, word=word)
    for entry in ld.stream:
        ld.arith.program_words(entry.words)
    return ld


def recorded_word(options: dict, path):
    """The word format a program records (vampc.machine.arith); None for float64."""
    if options.get("word", "float64") == "float64":
        return None
    from vampc.machine.arith import parse_word
    try:
        return parse_word(options["word"], options.get("rounding", "nearest"),
                          options.get("overflow", "saturate"))
    except ValueError as exc:
        raise VampcError(f"{path}: options.word: {exc}") from None


def _whole(x) -> str:
    """A word's scalar as written: an integer in full (16777216 read '1.67772e+07': a hardware
    audit), anything else with 6 significant digits."""
    x = float(x)
    return str(int(x)) if x.is_integer() and abs(x) < 1e18 else f"{x:.6g}"


def delivered_programs(net: Network, numbers, stream, path,
                       packing=PACKING) -> tuple[tuple[Program, ...], ...]:
    """The slot table each VAMP holds after Program Mode; VampcError if one gets none or a bad one."""
    index_of = {n: v for v, n in enumerate(numbers)}
    try:
        roots, depths = a_roots(net)
    except VampcError as exc:    # (an edited file's A path that loops: said with the file's name)
        raise VampcError(f"{path}: {exc}") from None
    tables: list[list | None] = [None] * len(net.vamps)
    writes: list[list] = [[] for _ in net.vamps]          # bus-write registers (the bus's)
    seen: set = set()
    for entry in stream:
        # one input buffer, one entry: two for one root were run by the stream engine as if the
        # buffer took two words a tick, refused by the tick engine, and counted as two buffers by
        # the report (a hardware audit)
        if entry.root in seen:
            raise VampcError(f"{path}: program stream: {entry.root} has two entries (an input "
                             "buffer takes its words as one sequence, one a tick)")
        seen.add(entry.root)
        if not len(entry.words) == len(entry.targets) == len(entry.depth):
            raise VampcError(f"{path}: program stream of {entry.root}: {len(entry.words)} words but "
                             f"{len(entry.targets)} targets and {len(entry.depth)} depths")
        for k, word in enumerate(entry.words):
            # the hardware takes a control field as an integer: a corrupted 4097.5 would be
            # latched as 4097 and go unseen, so the file's words must hold integers
            # (scalar 1, the VAMP number, too: 1.0000001 was said to match no VAMP on the path,
            # where VAMP 1 was: a new user's find)
            x = next((x for x in word[:3] if x != int(x)), None)
            if x is not None:
                raise VampcError(f"{path}: program stream of {entry.root}, word {k}: scalar "
                                 f"{float(x)!r} is not an integer (every scalar of a Program-Mode "
                                 "word is)")
            if not (abs(word[1]) < packing.limit and abs(word[2]) < packing.limit):
                # (a 1e300 unpacked into a field of 300 digits, which the error then printed)
                x = word[1] if not abs(word[1]) < packing.limit else word[2]
                raise VampcError(f"{path}: program stream of {entry.root}, word {k}: scalar "
                                 f"{_whole(x)} does not fit in a {packing.limit.bit_length()}-bit "
                                 f"Program-Mode word (at most {packing.limit - 1} in magnitude, "
                                 "as this program packs them)")
            if float(word[0]) > 0 and min(float(word[1]), float(word[2])) < 0:
                # (unpacked, a negative scalar was said as other fields: "delay-b 4095 never
                # matches the Cycle-Counter" of a -4097: a new user's find)
                raise VampcError(f"{path}: program stream of {entry.root}, word {k}: scalar "
                                 f"{_whole(min(word[1], word[2]))} is negative: a compact word packs "
                                 "two fields in each (delay-A and delay-B, delay-R and the ROM "
                                 "pointer), each from 0")
            v = index_of.get(word_number(word))
            if v is None or roots[v] != entry.root:
                raise VampcError(f"{path}: program stream of {entry.root}, word {k}: number "
                                 f"{_whole(word[0])} matches no VAMP on that input's Operand-A paths")
            # the listing says where each word goes and how deep; Program Mode lasts as long as
            # it says the deepest word needs, so it must be the network's truth (the tick engine
            # clocks the words by it)
            if (entry.targets[k], entry.depth[k]) != (v, depths[v]):
                raise VampcError(f"{path}: program stream of {entry.root}, word {k}: it is for VAMP "
                                 f"{v} at depth {depths[v]}, but the stream lists VAMP "
                                 f"{entry.targets[k]} at depth {entry.depth[k]}")
            if float(word[0]) > 0 or tables[v] is not None:     # an extended word needs a table
                try:
                    tables[v] = apply_word(tables[v], word, packing, writes[v])
                except VampcError as exc:
                    raise VampcError(f"{path}: program stream of {entry.root}, word {k}: "
                                     f"{exc}") from None
    progs = tuple(_program(net, numbers, v, tables[v], roots, path) for v in range(len(net.vamps)))
    _check_inputs_used(net, numbers, progs, path)
    _check_bus_registers(net, numbers, writes, path)
    return progs


def _check_bus_registers(net: Network, numbers, writes, path) -> None:
    """The bus-write registers Program Mode delivers (`writes`: per VAMP, [counter, source · 64 +
    tier] rows) must be complete, valid and the ones network.bus lists."""
    from vampc.program.emit import bus_registers, bus_writes
    from vampc.program.words import TIER_CODES
    if net.bus is None:
        v = next((v for v, regs in enumerate(writes) if regs), None)
        if v is not None:
            raise VampcError(f"{path}: the program stream loads bus-write registers into VAMP {v} "
                             f"(number {numbers[v]}), but the network has no bus")
        return
    bus_writes(net, writes, path)            # each one complete and naming what exists
    for v, regs in enumerate(bus_registers(net)):
        listed = [[r.counter, r.source * TIER_CODES + r.tier] for r in regs]
        if listed == writes[v]:
            continue
        if len(listed) != len(writes[v]):
            raise VampcError(f"{path}: network.bus.writes lists {len(listed)} bus-write "
                             f"register(s) for VAMP {v} (number {numbers[v]}), but the program "
                             f"stream delivers {len(writes[v])} (the file was edited); recompile it")
        # (the same number: which register and field differ, a new user's)
        j = next(j for j, (a, b) in enumerate(zip(listed, writes[v])) if a != b)
        (counter, code), (got_counter, got_code) = listed[j], writes[v][j]
        sources = [b.source for b in net.buffers]
        entry = [i for i, w in enumerate(net.bus.writes) if tap_source(w.source, sources) == v][j]
        what = (f"Cycle-Counter {counter}, the program stream's {got_counter}"
                if counter != got_counter else
                f"source {code // TIER_CODES} on tier {code % TIER_CODES}, the program stream's "
                f"source {got_code // TIER_CODES} on tier {got_code % TIER_CODES}")
        raise VampcError(f"{path}: VAMP {v} (number {numbers[v]}): bus-write register {j}: "
                         f"network.bus.writes[{entry}] gives {what} (the file was edited); "
                         "recompile it")


def _check_inputs_used(net: Network, numbers, progs, path) -> None:
    """Every multiplexer input is selected by some slot (the compiler wires no other), except a
    program port as operand A's input 0: so a damaged select that happens to reach a wire carrying
    the same value still leaves an unused input behind, and is reported."""
    for v, (vamp, slots) in enumerate(zip(net.vamps, progs)):
        if net.bus is not None and program_wire(vamp):
            k = next((k for k, p in enumerate(slots) if p.sel_a == 0), None)
            if k is not None:
                raise VampcError(f"{path}: VAMP {v} (number {numbers[v]}) slot {k}: "
                                 f"{PROGRAM_WIRE_READ}")
        for name, inputs, used in (("A", vamp.a, {p.sel_a for p in slots}),
                                   ("B", vamp.b, {p.sel_b for p in slots})):
            for k in range(len(inputs)):
                tap = inputs[k].taps[0]
                program_port = (name == "A" and k == 0 and tap.kind is TapKind.PORT
                                and not net.ports[tap.index].entries)
                on_wire = name == "A" and k == 0 and net.bus is not None   # (Program Mode's)
                if k not in used and not program_port and not on_wire:
                    raise VampcError(f"{path}: VAMP {v} (number {numbers[v]}): input {k} of operand "
                                     f"{name}'s multiplexer ({tap}) is selected by no slot")


def _program(net: Network, numbers, v: int, table, roots, path) -> tuple[Program, ...]:
    name = f"VAMP {v} (number {numbers[v]})"
    if table is None:
        raise VampcError(f"{path}: {name} is never programmed: no word written to {roots[v]} "
                         "carries its number")
    vamp = net.vamps[v]
    for k, row in enumerate(table):
        where = f"{name} slot {k}"
        for f, inputs in ((4, vamp.a), (5, vamp.b)):
            if row[f] is None and len(inputs) == 1:
                row[f] = 0           # no register: a multiplexer of one input passes input 0
        for f, value in zip(FIELDS, row):
            if value is None:
                raise VampcError(f"{path}: {where}: {f.replace('_', '-')} is never programmed")
        for f in range(3):
            if row[f] >= net.period:
                raise VampcError(f"{path}: {where}: {FIELDS[f].replace('_', '-')} {row[f]} never "
                                 f"matches the Cycle-Counter (0..{net.period - 1}: the period is "
                                 f"{net.period})")
        if row[3] >= len(ROM):
            raise VampcError(f"{path}: {where}: ROM pointer {row[3]} is not in the ROM "
                             f"(0..{len(ROM) - 1})")
        for f, inputs in ((4, vamp.a), (5, vamp.b)):
            if row[f] >= len(inputs):
                raise VampcError(f"{path}: {where}: {FIELDS[f].replace('_', '-')} {row[f]} selects "
                                 f"no input (operand {'AB'[f - 4]} has {len(inputs)})")
    return tuple(Program(*row) for row in table)


def _check_listing(listed, progs, path) -> None:
    """The readable `programs` section must say what the stream delivers."""
    for v, (want, got) in enumerate(zip(listed, progs)):
        if len(want) != len(got):
            raise VampcError(f"{path}: programs[{v}] lists {len(want)} slots but the program stream "
                             f"delivers {len(got)}")
        for k, (a, b) in enumerate(zip(want, got)):
            if a != b:
                name = next(f for f in FIELDS if a.field(f) != b.field(f))
                raise VampcError(f"{path}: programs[{v}] slot {k} lists {name.replace('_', '-')} "
                                 f"{a.field(name)} but the program stream delivers {b.field(name)}")


def check_indices(net: Network, numbers, graph: Graph, path) -> None:
    """Taps must name existing VAMPs, buffers, stages, ports and constants; slots existing nodes."""
    if net.period % net.clock:
        raise VampcError(f"{path}: network.period {net.period} is not a multiple of network.clock "
                         f"{net.clock}")
    sizes = {"vamp": len(net.vamps), "buffer": len(net.buffers), "port": len(net.ports),
             "const": len(net.consts), "bus": len(net.bus.tiers) if net.bus else 0}
    for v in net.vamps:
        for name, inputs in (("A", v.a), ("B", v.b)):
            for operand in inputs:
                for tap in operand.taps:
                    bad = _bad_tap(net, sizes, tap)
                    if bad:
                        raise VampcError(f"{path}: VAMP {v.index}: operand {name} is wired to {bad}")
        for k, s in enumerate(v.slots):
            if not 0 <= s.node < len(graph.nodes) or not graph.nodes[s.node].op.is_compute:
                raise VampcError(f"{path}: programs[{v.index}] slot {k}: node {s.node} is not a "
                                 "compute node of the graph")
    first: dict[int, int] = {}            # number -> the first VAMP burned with it
    for v, number in enumerate(numbers):
        if number in first:
            raise VampcError(f"{path}: VAMPs {first[number]} and {v} share the number {number} "
                             "(the file was edited); recompile it")
        first[number] = v
    for b in net.buffers:
        if b.source >= len(net.vamps):
            raise VampcError(f"{path}: buffer {b.index} is fed by missing VAMP {b.source}")
    for j, w in enumerate(net.bus.writes if net.bus else ()):
        bad = _bad_tap(net, sizes, w.source)
        if bad:
            raise VampcError(f"{path}: network.bus.writes[{j}] is driven by {bad}")
        if w.counter >= net.period:
            raise VampcError(f"{path}: network.bus.writes[{j}]: counter {w.counter} never matches "
                             f"the Cycle-Counter (0..{net.period - 1})")
    for o in net.outputs:
        if o.vamp >= len(net.vamps):
            raise VampcError(f"{path}: τ{o.joint} is read from missing VAMP {o.vamp}")
    if net.consts:   # each constant is named after a graph constant of its value (the report
        named: dict[tuple, set] = {}          # lists them by name; an edited value is said below)
        for nd in graph.nodes:
            if nd.op is Op.CONST:
                named.setdefault(nd.value, set()).add(nd.name)
        for c in net.consts:
            if c.name not in named.get(tuple(c.value), {c.name}):
                raise VampcError(f"{path}: network.consts[{c.index}].name: {shown(c.name)} names no "
                                 "constant of the graph with its value (the file was edited); "
                                 "recompile it")
    # every torque the graph gives is read once (an output dropped from io.outputs left its column
    # unwritten: the stream engine returned whatever memory held, exit 0)
    want = sorted(o.joint for o in graph.outputs)
    got = sorted(o.joint for o in net.outputs)
    if got != want:
        missing = sorted(set(want) - set(got))
        what = (f"τ{missing[0]} is read from no VAMP" if missing else
                f"it reads joints {got}, the graph gives {want}")
        raise VampcError(f"{path}: io.outputs: {what}")


def _bad_tap(net: Network, sizes, tap: Tap) -> str | None:
    """What is wrong with `tap`, as "a missing vamp 7" (an index out of range, a buffer stage it does
    not have) or a stage on anything but a buffer (only a buffer has stages: the emulator would not
    read it, and a corrupted stage would go unseen); None when it names something that exists."""
    if not tap.index < sizes[tap.kind] or (
            tap.kind is TapKind.BUFFER and not 1 <= tap.stage <= net.buffers[tap.index].stages):
        return f"a missing {tap}"
    if tap.kind is not TapKind.BUFFER and tap.stage != 0:
        return f"{tap.kind.value} {tap.index} at stage {tap.stage} (only a buffer has stages)"
    return None
