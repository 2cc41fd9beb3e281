"""Conversion between the compiler's IRs and the program-file document (see vampc.program.file)."""
from __future__ import annotations

import itertools
from collections.abc import Iterator

import numpy as np

from vampc.dataflow.graph import (
    LINEAR_META,
    LOG_CONVENTION,
    LOG_GROUNDS,
    LOG_LEAVES,
    LOG_TREE_CONVENTION,
    Graph,
    InputKey,
    Node,
    Output,
)
from vampc.errors import VampcError, VampcInternalError, located
from vampc.gcpause import gc_paused
from vampc.kinds import Quantity, Recursion, TapKind
from vampc.machine.ops import Op
from vampc.network.model import (
    Buffer,
    Bus,
    BusWrite,
    Checking,
    Const,
    Network,
    Operand,
    OutputPoint,
    Port,
    PortEntry,
    ProgrammedSlot,
    Slot,
    Tap,
    Tier,
    Vamp,
)
from vampc.program import format as F
from vampc.program.emit import StreamEntry, load_ticks
from vampc.program.file import (
    FORMAT,
    VERSION,
    Rows,
    layout_chunks,
    number,
    number_rows_each,
    numbers,
    rendered,
)
from vampc.program.words import ROM, Program
from vampc.robot.chain import Chain, Joint, JointType, Limits, Mimic, rotation_problem
from vampc.schedule.asap import Schedule
from vampc.schedule.layout import Layout
from vampc.schedule.registry import LAYOUTS, SYSTOLIC, is_layout
from vampc.textio import numbers_shown, shown


def robot_doc(chain: Chain) -> F.RobotDoc:
    """The robot section (a tree adds `parents`; a floating base `floating` and the base inertia).
    Floats as program files write them (vampc.program.file.number), like every section's."""
    def floats(x):       # a vector or a matrix's rows
        x = np.asarray(x, dtype=float)
        return numbers(x) if x.ndim == 1 else [numbers(row) for row in x]
    joints = [F.JointDoc(
        j.name, j.type.value, floats(j.phi), floats(j.p_fixed), number(j.offset), number(j.mass),
        floats(j.com), floats(j.inertia), floats(j.axis),
        F.Limits(*rendered([list(j.limits.q) if j.limits.q else None, j.limits.qd,
                             j.limits.tau])),
        # a tree's joint frame (absent for a chain: its files are unchanged)
        floats(j.pre) if j.pre is not None else None,
        floats(j.shift) if j.shift is not None else None) for j in chain.joints]
    out = F.RobotDoc(chain.name, chain.n, chain.source, joints, floats(chain.gravity),
                     floats(chain.base_omega), floats(chain.base_omega_dot),
                     floats(chain.tip_force), floats(chain.tip_torque))
    if not chain.is_chain:
        out.parents = list(chain.parent_of)
    if chain.floating:
        out.floating, out.base_mass = True, number(chain.base_mass)
        out.base_com, out.base_inertia = floats(chain.base_com), floats(chain.base_inertia)
    if chain.mimic:
        out.mimic = [F.MimicDoc(m.follower, m.leader, *rendered([m.multiplier, m.offset]))
                     for m in chain.mimic]
    if chain.locked:
        out.locked = list(chain.locked)
    if chain.left_out:
        out.left_out = list(chain.left_out)
    return out


def chain_from_doc(doc: F.RobotDoc, graph: Graph | None = None, path="<program>") -> Chain:
    """Inverse of robot_doc; with `graph`, the robot must have the graph's joints (VampcError)."""
    if len(doc.joints) != doc.n:
        raise VampcError(f"{path}: robot: n is {doc.n} but {len(doc.joints)} joints are listed "
                         "(the file was edited); recompile it")
    if graph is not None and graph.n != doc.n:
        raise VampcError(f"{path}: robot: {doc.n} joints, but the graph is of {graph.n} (the file "
                         "was edited); recompile it")
    from vampc.textio import first_name_problem
    found = first_name_problem([("robot.name", doc.name)] + [(f"robot.joints[{i}].name", j.name)
                                                             for i, j in enumerate(doc.joints)])
    if found:
        raise located(path, *found)
    _check_joints(doc, path)
    for i, j in enumerate(doc.joints):
        q = j.limits.q
        if q is not None and not q[0] <= q[1]:
            raise located(path, f"robot.joints[{i}].limits.q", f"lower limit {q[0]!r} is above upper "
                          f"limit {q[1]!r} (the file was edited)")
    joints = tuple(Joint(
        name=j.name, type=JointType(j.type), phi=np.array(j.phi), p_fixed=np.array(j.p_fixed),
        offset=j.offset, mass=j.mass, com=np.array(j.com), inertia=np.array(j.inertia),
        limits=Limits(tuple(j.limits.q) if j.limits.q else None, j.limits.qd, j.limits.tau),
        pre=np.array(j.pre) if j.pre is not None else None,
        shift=np.array(j.shift) if j.shift is not None else None) for j in doc.joints)
    tree = {}
    if doc.parents is not None:
        tree["parents"] = tuple(doc.parents)
    if doc.floating:
        for name in ("base_mass", "base_com", "base_inertia"):
            if getattr(doc, name) is None:
                raise VampcError(f"{path}: robot.{name}: a floating base needs it")
        tree.update(floating=True, base_mass=doc.base_mass, base_com=np.array(doc.base_com),
                    base_inertia=np.array(doc.base_inertia))
    if doc.mimic:
        tree["mimic"] = tuple(Mimic(m.follower, m.leader, m.multiplier, m.offset) for m in doc.mimic)
    chain = Chain(doc.name, joints, np.array(doc.gravity), np.array(doc.base_omega),
                  np.array(doc.base_omega_dot), np.array(doc.tip_force),
                  np.array(doc.tip_torque), doc.source, locked=tuple(doc.locked or ()),
                  left_out=tuple(doc.left_out or ()), **tree)
    if graph is not None and len(graph.outputs) != chain.n_outputs:
        raise VampcError(f"{path}: robot.floating: {str(bool(doc.floating)).lower()}, but the graph "
                         f"has {len(graph.outputs)} outputs, not the {chain.n_outputs} of "
                         f"{chain.n} torques{' and the base wrench' if chain.floating else ''} "
                         "(the file was edited); recompile it")
    _warn_improper_inertias(chain, path)
    if tree:      # the host walks the tree: parents must be a depth-first tree of n joints
        try:
            chain._verify_tree()
        except VampcInternalError as exc:
            raise VampcError(f"{path}: robot.parents: {exc}") from None
        try:
            chain._verify_mimic()
        except VampcInternalError as exc:
            raise VampcError(f"{path}: robot.mimic: {exc}") from None
    return chain


def _warn_improper_inertias(chain: Chain, path) -> None:
    """A warning for each inertia of the robot section that is not symmetric positive semi-definite
    beyond a rounding error: a robot file's is refused so (a DH table's always, a URDF's or MJCF's
    unless --accept-improper-inertia, which a program does not record), and an edited one had run
    and been reported unsaid (a new user's find). Taken, since a program compiled with that option
    holds one."""
    from vampc.robot.inertia import (
        NEARLY_PSD,
        NEARLY_PSD_ABS,
        improper_inertias,
        inertia_problem,
    )
    places = [f"robot.joints[{i}].inertia" for i in range(chain.n)]
    stack = [j.inertia for j in chain.joints]
    if chain.floating:
        places.append("robot.base_inertia")
        stack.append(np.asarray(chain.base_inertia))
    stack = np.asarray(stack, dtype=float).reshape(-1, 3, 3)
    suspect = np.flatnonzero(improper_inertias(stack))     # (a file's numbers are finite: JSON's)
    if not suspect.size:
        return
    import warnings

    from vampc.errors import VampcWarning
    for k in suspect:
        problem = inertia_problem(stack[k], tolerance=NEARLY_PSD, floor=NEARLY_PSD_ABS)
        if problem:
            warnings.warn(VampcWarning(f"{path}: {places[k]}: {problem}: taken as the file holds it "
                                       "(no rigid body has it: a robot file's is refused so, unless "
                                       "--accept-improper-inertia)"), stacklevel=2)


def _check_joints(doc: F.RobotDoc, path) -> None:
    """Joint names are distinct (the torque columns are named after them; compile refuses a
    repeated one), each Φ, and a tree joint's pre-rotation, is a proper rotation as Chain.verify
    requires (an edited Φ was emulated, and checked against a reference using it), and each axis is
    Φ's last row (an edited axis was read by nobody: the answer stayed the same, exit 0)."""
    seen = set()
    for i, j in enumerate(doc.joints):
        if not j.name.strip():      # (a torque column 'tau_': a robot file refuses such a name)
            raise located(path, f"robot.joints[{i}].name", f"{shown(j.name)} is blank (the file "
                          "was edited); recompile it")
        if j.name in seen:
            raise located(path, f"robot.joints[{i}].name", f"duplicate joint name {shown(j.name)} "
                          "(the file was edited); recompile it")
        seen.add(j.name)
        for field, m in (("phi", j.phi), ("pre", j.pre)):
            problem = None if m is None else rotation_problem(np.array(m, dtype=float))
            if problem:
                raise located(path, f"robot.joints[{i}].{field}", f"{problem} (the file was "
                              "edited); recompile it")
        if list(j.axis) != list(j.phi[2]):    # (written from Φ's last row, exactly)
            raise located(path, f"robot.joints[{i}].axis", f"{numbers_shown(j.axis)} is not the "
                          f"joint's axis, Φ's last row {numbers_shown(j.phi[2])} (the file was "
                          "edited; the axis is written for readers and follows from Φ); recompile it")


def graph_doc(g: Graph) -> F.GraphDoc:
    """The graph section: one row per node, made as the writer reaches them (vampc.program.file.Rows:
    a big program's rows are never all held at once). A node's operands are written from its tuple
    (the encoder writes a tuple as a list), not copied into a list."""
    def rows(lo: int, hi: int) -> list[F.NodeDoc]:
        return [F.NodeDoc(nd.id, nd.op.value, nd.args, nd.name, nd.section, nd.group,
                          (nd.key.quantity, nd.key.joint) if nd.key else None,
                          numbers(nd.value) if nd.value is not None else None)
                for nd in g.nodes[lo:hi]]
    return F.GraphDoc(g.n, g.recursion, Rows(len(g.nodes), rows),
                      [(o.joint, o.node, o.component) for o in g.outputs], dict(g.meta))


def graph_from_doc(d: F.GraphDoc, path="<program>") -> Graph:
    """Inverse of graph_doc, verified (Graph.verify: ids, operand order, arities, shapes, keys and
    values); VampcError naming the node that fails, or whose op the table does not know."""
    ops = _ops(graph=True)
    nodes = []
    for r in d.nodes:
        op = ops.get(r.op)
        if op is None:
            raise VampcError(f"{path}: graph.nodes[{len(nodes)}].op: {r.op!r} is not an op "
                             f"({', '.join(ops)})")
        nodes.append(Node(r.id, op, tuple(r.args), r.name, r.section, r.group,
                          InputKey(*r.key) if r.key is not None else None,
                          tuple(r.value) if r.value is not None else None))
    for k, (joint, node, component) in enumerate(d.outputs):
        if not 0 <= node < len(nodes) or not 1 <= joint or not 0 <= component <= 2:
            raise VampcError(f"{path}: graph.outputs[{k}]: [{joint}, {node}, {component}] names no "
                             "torque of the graph (the file was edited); recompile it")
    graph = Graph(tuple(nodes), tuple(Output(*o) for o in d.outputs), d.n, d.recursion,
                  tuple(sorted(d.meta.items())))
    try:          # every reader's: the schedule and emulator checks index the graph by its ids
        graph.verify()
    except VampcInternalError as exc:
        raise VampcError(f"{path}: {exc} (the file was edited); recompile it") from None
    return graph


def _ops(graph: bool) -> dict[str, Op]:
    """Op names a file may use: the table's compute ops (and INPUT, CONST in a graph)."""
    return {op.value: op for op in Op if op.is_compute or graph}


def schedule_doc(s: Schedule) -> F.ScheduleDoc:
    """The schedule section (start and finish as the schedule holds them, not copied: the encoder
    writes a tuple as a list, and a 4096-joint log schedule's are a million entries each)."""
    return F.ScheduleDoc(s.timing.mult, s.timing.add, s.latency, s.interval, s.mults, s.adds,
                         s.start, s.finish, list(s.critical_path))


def network_doc(net: Network, numbering) -> F.NetworkDoc:
    """The network (netlist) section: wiring only; timing lives in the programs. Its VAMPs and
    buffers are made as the writer reaches them (Rows)."""
    def vamps(lo: int, hi: int) -> list[F.VampDoc]:
        # an operand is written as its taps, and a Tap (array-like) as [kind, index, stage]
        return [F.VampDoc(v.index, numbering[v.index], _taps(v.a), _taps(v.b))
                for v in net.vamps[lo:hi]]
    return F.NetworkDoc(
        net.period, net.clock, Rows(len(net.vamps), vamps),
        Rows(len(net.buffers), lambda lo, hi: [F.BufferDoc(b.index, b.source, b.stages)
                                               for b in net.buffers[lo:hi]]),
        [F.PortDoc(p.index, p.size, [F.PortEntryDoc(e.key.quantity, e.key.joint, e.block)
                                     for e in p.entries]) for p in net.ports],
        [F.ConstDoc(c.index, c.name, numbers(c.value)) for c in net.consts],
        None if net.bus is None else bus_doc(net.bus),
        None if net.checking is None else F.CheckingDoc(list(net.checking.chain),
                                                         net.checking.warmup,
                                                         net.checking.compare))


def _taps(inputs) -> list:
    """A multiplexer's inputs as the program file writes them: each operand's taps."""
    return [inputs[0].taps] if len(inputs) == 1 else [op.taps for op in inputs]


def bus_doc(bus) -> F.BusDoc:
    """The network's Mostly-Local Bus section."""
    return F.BusDoc([F.TierDoc(t.span, t.offset) for t in bus.tiers], list(bus.position),
                    [F.BusWriteDoc((w.source.kind, w.source.index, w.source.stage), w.counter,
                                   w.tier) for w in bus.writes],
                    bus.stretch, bus.wait)


def programs_doc(net: Network, progs) -> Rows:
    """The programs section: each VAMP's slots with their control registers, made as the writer
    reaches them (Rows), as text. A one-slot VAMP's row is the text of its program and op, encoded
    once, with its node and VAMP index put in: the programs of a network are interned (a few hundred
    for a million VAMPs, vampc.program.emit.programs), and a Struct per row and slot, encoded,
    took 0.76 s of a 4096-joint log program's writing."""
    from msgspec import structs

    from vampc.program.file import encode
    made: dict[tuple[int, int], tuple] = {}
    def doc(v: Vamp, ps) -> F.ProgramDoc:
        return F.ProgramDoc(v.index, [F.SlotDoc(s.node, s.op.value, p.delay_a, p.delay_b,
                                                p.delay_r, p.rom, p.sel_a, p.sel_b)
                                      for s, p in zip(v.slots, ps)])
    def template(v: Vamp, ps) -> str | None:
        """The row's text with %d for its node and its VAMP index (None if that cannot be)."""
        s = v.slots[0]
        marked = encode(doc(Vamp(_VAMP_MARK, v.a, v.b, (structs.replace(s, node=_NODE_MARK),)),
                            ps))
        node, vamp = str(_NODE_MARK), str(_VAMP_MARK)
        if marked.count(node) != 1 or marked.count(vamp) != 1 or \
                marked.index(node) > marked.index(vamp):
            return None
        return marked.replace("%", "%%").replace(node, "%d").replace(vamp, "%d")
    def rows(lo: int, hi: int) -> bytes:
        lines = []
        add = lines.append
        for v, ps in zip(net.vamps[lo:hi], progs[lo:hi]):
            slots = v.slots
            s = slots[0] if len(slots) == 1 == len(ps) else None
            # (a template's %d writes a node and an index as msgspec does if they are ints)
            if s is not None and type(s.node) is int and type(v.index) is int:
                key = (id(ps), id(s.op))    # (by identity: hashing the listing's Programs is slow)
                hit = made.get(key)
                if hit is None and len(made) < TEMPLATES:
                    hit = made[key] = (ps, template(v, ps))
                if hit is not None and hit[0] is ps and hit[1] is not None:
                    add(hit[1] % (s.node, v.index))
                    continue
            add(encode(doc(v, ps)))
        add("")
        return "\n".join(lines).encode("ascii")
    if len(progs) != len(net.vamps):
        raise VampcInternalError(f"{len(progs)} programs for {len(net.vamps)} VAMPs")
    return Rows(len(net.vamps), rows)


TEMPLATES = 1 << 16      # the row texts programs_doc keeps at most (a program's listings: hundreds)
_NODE_MARK, _VAMP_MARK = -73400012345671, -73400076543217    # (a template has each once, or none)


def stream_doc(stream) -> Rows:
    """The program_stream section: per input buffer, the words the host writes in Program Mode,
    made as the writer reaches them (Rows)."""
    def rows(lo: int, hi: int) -> list[F.StreamDoc]:
        entries = stream[lo:hi]
        return [F.StreamDoc(F.RootDoc(e.root.kind, e.root.index), list(e.targets),
                            list(e.depth), words)
                for e, words in zip(entries, number_rows_each([e.words for e in entries]))]
    return Rows(len(stream), rows, [len(e.words) for e in stream])


def io_doc(net: Network, stream) -> F.IoDoc:
    """The io section: when the host writes each port, where and when each torque appears."""
    B = net.clock
    return F.IoDoc(net.period, B, load_ticks(stream),
                   [F.PortWriteDoc(p.index, e.key.quantity, e.key.joint, e.block * B)
                    for p in net.ports for e in p.entries],
                   [F.OutputDoc(o.joint, o.vamp, o.component, o.tick) for o in net.outputs])


def program_sections(chain, graph, sched, net, numbering, progs, stream, options: dict,
                     summary: dict, layout: F.LayoutDoc) -> dict:
    """Every section of the program file but its checksum, as vampc.program.format's Structs, the
    big row lists as vampc.program.file.Rows (for layout_chunks)."""
    return {"format": FORMAT, "version": VERSION, "robot": robot_doc(chain),
            "options": F.OptionsDoc(**options), "graph": graph_doc(graph),
            "schedule": schedule_doc(sched), "layout": layout,
            "network": network_doc(net, numbering), "programs": programs_doc(net, progs),
            "program_stream": stream_doc(stream), "io": io_doc(net, stream),
            "summary": summary}


def program_chunks(chain, graph, sched, net, numbering, progs, stream, options: dict,
                   summary: dict, layout: F.LayoutDoc) -> Iterator[bytes]:
    """The whole program-file document (without its checksum) as the text `write_program` writes,
    in ASCII byte pieces made as they are taken (vampc.program.file.layout_chunks): the sections'
    Structs encoded by msgspec as canonical JSON, laid out one row per line."""
    return layout_chunks(program_sections(chain, graph, sched, net, numbering, progs, stream,
                                          options, summary, layout))


def network_from_doc(doc: F.ProgramFile, path="<program>") -> Network:
    """The netlist, with each VAMP's slots as its `programs` listing gives them (latch and dump
    ticks are Cycle-Counter values here: absolute times are the emulator's to derive)."""
    def slot(v: int, k: int, r: F.SlotDoc, op: Op, column: int | None) -> ProgrammedSlot:
        return ProgrammedSlot(r.node, op, column, r.sel_a, r.sel_b, r.delay_a, r.delay_b,
                              r.delay_r)
    return _network(doc, path, slot)


def scheduled_network_from_doc(doc: F.ProgramFile, sched: Schedule, path) -> Network:
    """The netlist with each VAMP's slots at the schedule's ticks (absolute, set 0), as the
    allocator makes them: each slot latches at its node's start and dumps at its finish - 1. Its
    Cycle-Counter fields must be those ticks mod P (VampcError naming the field otherwise)."""
    P = doc.network.period
    starts, finishes = sched.start, sched.finish
    def slot(v: int, k: int, r: F.SlotDoc, op: Op, column: int | None) -> Slot:
        if not r.node < len(starts):
            raise VampcError(f"{path}: programs[{v}].slots[{k}].node: {r.node} is not a node of "
                             f"the graph (0..{len(starts) - 1})")
        start, dump = starts[r.node], finishes[r.node] - 1
        if r.delay_a != start % P or r.delay_b != start % P or r.delay_r != dump % P:
            _off_schedule(v, k, r, start, dump, P, path)
        return Slot(r.node, op, column, r.sel_a, r.sel_b, start, start, dump)
    return _network(doc, path, slot)


def _network(doc: F.ProgramFile, path, slot) -> Network:
    """The netlist of a document, each VAMP's slots made by slot(VAMP, k, row, op, column)."""
    nd = doc.network
    progs = doc.programs
    ops = _ops(graph=False)
    rom_size = len(ROM)
    operands: dict[tuple, Operand] = {}
    taps: dict[tuple, Tap] = {}
    def tap(row) -> Tap:
        t = taps.get(row)
        if t is None:
            t = taps[row] = Tap(*row)
        return t
    def operand(rows) -> Operand:
        key = tuple(rows)
        op = operands.get(key)
        if op is None:
            op = operands[key] = Operand(tuple(map(tap, key)))
        return op
    for i, prog in enumerate(progs):            # the listing is in VAMP order, each entry named
        if prog.vamp != i:
            raise VampcError(f"{path}: programs[{i}].vamp: {prog.vamp}, but entry {i} lists VAMP {i} "
                             "(the file was edited); recompile it")
    def slots(index: int):
        if not 0 <= index < len(progs):
            raise VampcError(f"{path}: network.vamps: VAMP {index} has no programs entry")
        out = []
        for r in progs[index].slots:
            where = f"{path}: programs[{index}].slots[{len(out)}]"
            if r.op not in ops:
                raise VampcError(f"{where}.op: {r.op!r} is not a compute op ({', '.join(ops)})")
            if r.rom >= rom_size:
                raise VampcError(f"{where}.rom: {r.rom} is not a ROM pointer (0..{rom_size - 1})")
            name, column = ROM[r.rom]
            if r.op != name.value:      # (the listing's op was read by nothing, so went unseen)
                raise VampcError(f"{where}.op: {r.op!r}, but its ROM pointer {r.rom} runs "
                                 f"{name.value}")
            out.append(slot(index, len(out), r, name, column))
        return tuple(out)
    for name, got, want in (("period", doc.io.period, nd.period), ("clock", doc.io.clock, nd.clock)):
        if got != want:             # (the host's side of the network's own figures)
            raise VampcError(f"{path}: io.{name}: {got}, but network.{name} is {want}")
    _check_bus_option(doc, path)
    for section, rows in (("vamps", nd.vamps), ("buffers", nd.buffers), ("ports", nd.ports),
                          ("consts", nd.consts)):
        for i, row in enumerate(rows):          # (taps name them by index: the position)
            if row.index != i:
                raise _misplaced(section, rows, i, path)
    _check_port_sizes(nd, path)
    vamps = tuple(Vamp(v.index, tuple(map(operand, v.a)), tuple(map(operand, v.b)),
                       slots(v.index)) for v in nd.vamps)
    _check_stages(nd, taps.values(), path)
    if nd.bus is not None:
        _check_direct_wires(vamps, path)
    return Network(nd.period, nd.clock, vamps,
                   tuple(Buffer(b.index, b.source, b.stages) for b in nd.buffers),
                   tuple(Port(p.index, p.size, tuple(PortEntry(InputKey(e.quantity, e.joint),
                                                               e.block) for e in p.entries))
                         for p in nd.ports),
                   tuple(Const(c.index, c.name, tuple(c.value)) for c in nd.consts),
                   tuple(OutputPoint(o.joint, o.vamp, o.component, o.tick)
                         for o in doc.io.outputs),
                   None if nd.bus is None else bus_from_doc(nd.bus, len(vamps), path),
                   None if nd.error_correction is None
                   else checking_from_doc(nd.error_correction, len(vamps), path))


def _check_bus_option(doc: F.ProgramFile, path) -> None:
    """options.bus names the wiring the network has: a Mostly-Local Bus (network.bus) with "mlb",
    none with "p2p" (the default, unwritten). An edited options.bus ran, and the report labelled
    the network by it: a bus program called point to point, its comparison row given the bus's
    pins and tiers, or a point-to-point program called a bus one (a new user's)."""
    option = doc.options.bus if isinstance(doc.options.bus, str) else "p2p"
    if (option == "mlb") == (doc.network.bus is not None):
        return
    if doc.network.bus is None:
        raise VampcError(f"{path}: options.bus: 'mlb', but the network has no bus (network.bus) "
                         "(the file was edited); recompile it")
    given = (f"options.bus is {option!r}" if isinstance(doc.options.bus, str)
             else "options.bus is not given")
    raise VampcError(f"{path}: network.bus: a Mostly-Local Bus, but {given} (point to point) "
                     "(the file was edited); recompile it")


def _check_direct_wires(vamps, path) -> None:
    """On the Mostly-Local Bus, results reach their readers over the bus: the only wire from a VAMP's
    Result (or a buffer behind it) to another VAMP is operand A's input 0, Program Mode's (which
    Data Mode never selects). A multiplexer input rewired from a bus tap to a Result ran, the same
    torques, and the report counted it as a Program-Mode wire (a new user's)."""
    for v in vamps:
        for name, inputs in (("a", v.a), ("b", v.b)):
            for k, operand in enumerate(inputs):
                if name == "a" and k == 0:
                    continue
                for tap in operand.taps:
                    if tap.kind is TapKind.VAMP or tap.kind is TapKind.BUFFER:
                        raise VampcError(
                            f"{path}: network.vamps[{v.index}].{name}[{k}]: {tap}, a wire from a "
                            "Result, but on the Mostly-Local Bus results reach their readers over "
                            "the bus (only operand A's input 0, Program Mode's wire, comes from "
                            "another VAMP) (the file was edited); recompile it")


def _misplaced(section: str, rows, i: int, path) -> VampcError:
    """Entry `i` of network.`section` holds another index: said with the entry that holds it too,
    if one does (a VAMP's index repeated ran the programs of the VAMP it names twice, which was
    said as a timing error of the VAMP it replaced)."""
    index = rows[i].index
    again = next((k for k, row in enumerate(rows) if row.index == index and k != i), None)
    twice = "" if again is None else f" (network.{section}[{again}] has index {index} too)"
    return VampcError(f"{path}: network.{section}[{i}].index: {index}, but it is entry {i}{twice}")


def check_port_writes(nd, writes, path) -> None:
    """io.port_writes is the host's write schedule of network.ports (each entry: its port, key and
    block's first tick, in the ports' order), which the engines and the RTL host work out from the
    ports themselves: an edited schedule was read by nothing and went unseen."""
    want = [(p.index, e.quantity, e.joint, e.block * nd.clock) for p in nd.ports for e in p.entries]
    got = [(w.port, w.quantity, w.joint, w.tick) for w in writes]
    if got == want:
        return
    k = next((i for i, (a, b) in enumerate(zip(got, want)) if a != b), min(len(got), len(want)))
    if k >= len(got) or k >= len(want):
        raise VampcError(f"{path}: io.port_writes: {len(got)} writes, but network.ports have "
                         f"{len(want)} entries")
    port, quantity, joint, tick = want[k]
    def named(q, j) -> str:          # (a floating base's omega0, not omega00: InputKey.label)
        return f"{q}{j if j else ''}"
    raise VampcError(f"{path}: io.port_writes[{k}]: port {got[k][0]} {named(got[k][1], got[k][2])} "
                     f"at tick {got[k][3]}, but network.ports give port {port} "
                     f"{named(quantity, joint)} at tick {tick}")


def _check_port_sizes(nd, path) -> None:
    """A port is as wide as what the host writes to it: 9 scalars for a matrix A_i (quantity A),
    3 for a vector, and 3 for a program port (no entries): an edited size was counted by the report
    as pins and wires nothing carries."""
    for i, p in enumerate(nd.ports):
        want = {9 if e.quantity is Quantity.A else 3 for e in p.entries} or {3}
        if want != {p.size}:
            need = (f"its entries are {' and '.join(f'{w}-scalar' for w in sorted(want))} "
                    "quantities" if p.entries else "a program port (no entries) carries 3")
            raise VampcError(f"{path}: network.ports[{i}].size: {p.size}, but {need}")


def _check_stages(nd, taps, path) -> None:
    """A buffer has as many stages as the deepest one a tap reads (`taps`: every distinct tap of a
    multiplexer input; and the bus writes): an edited count beyond it is hardware nothing uses (a
    report counted a billion stages, and the tick engine and the RTL tried to build them). So is a
    constant no tap reads (an edited file's extra one was counted as a constant buffer)."""
    deepest = [0] * len(nd.buffers)
    writes = (Tap(*w.source) for w in nd.bus.writes) if nd.bus is not None else ()
    for t in itertools.chain(taps, writes):
        if t.kind is TapKind.BUFFER and 0 <= t.index < len(deepest) and t.stage > deepest[t.index]:
            deepest[t.index] = t.stage
    for b, want in zip(nd.buffers, deepest):
        if b.stages > want:
            raise VampcError(f"{path}: network.buffers[{b.index}].stages: {b.stages}, but no tap "
                             f"reads past stage {want}")
    read = {t.index for t in taps if t.kind is TapKind.CONST}
    unread = next((c for c in nd.consts if c.index not in read), None)
    if unread is not None:          # (the report counted it, a constant buffer nothing reads)
        raise VampcError(f"{path}: network.consts[{unread.index}] ({shown(unread.name)}) is read by "
                         "no tap")


def checking_from_doc(cd: F.CheckingDoc, vamps: int, path) -> Checking:
    """The error-correction section as the network's Checking; VampcError where it does not fit."""
    if len(cd.chain) != vamps or sorted(cd.chain) != list(range(vamps)):
        raise VampcError(f"{path}: network.error_correction.chain: not each of the {vamps} VAMPs "
                         f"once (a permutation of 0..{vamps - 1})")
    return Checking(tuple(cd.chain), cd.warmup, cd.compare)


def bus_from_doc(bd: F.BusDoc, vamps: int, path) -> Bus:
    """The bus section as the network's Bus; VampcError where it does not fit the network."""
    if len(bd.position) != vamps or sorted(bd.position) != list(range(vamps)):
        raise VampcError(f"{path}: network.bus.position: not a place on the line for each of the "
                         f"{vamps} VAMPs (a permutation of 0..{vamps - 1})")
    for j, w in enumerate(bd.writes):
        if w.source[0] not in (TapKind.VAMP, TapKind.BUFFER):
            raise VampcError(f"{path}: network.bus.writes[{j}]: a {w.source[0]} cannot drive a "
                             "bus (only a VAMP's Result or a buffer stage)")
        if w.tier >= len(bd.tiers):
            raise VampcError(f"{path}: network.bus.writes[{j}]: tier {w.tier} does not exist "
                             f"({len(bd.tiers)} tiers)")
    return Bus(tuple(Tier(t.span, t.offset) for t in bd.tiers), tuple(bd.position),
               tuple(BusWrite(Tap(*w.source), w.counter, w.tier) for w in bd.writes),
               bd.stretch, bd.wait)


def stream_from_doc(doc: F.ProgramFile) -> tuple[StreamEntry, ...]:
    """The program stream entries, words included."""
    return tuple(StreamEntry(Tap(e.root.kind, e.root.index), tuple(e.targets), tuple(e.depth),
                             tuple(e.words)) for e in doc.program_stream)


def programs_from_doc(doc: F.ProgramFile) -> tuple[tuple[Program, ...], ...]:
    """Per-VAMP slot programs as the `programs` listing writes them."""
    return tuple(tuple(Program(r.delay_a, r.delay_b, r.delay_r, r.rom, r.sel_a, r.sel_b)
                       for r in p.slots) for p in doc.programs)


def typed(doc, path) -> F.ProgramFile:
    """A program document as its Structs: a ProgramFile as it is, a dict (json.loads of a file, a
    test's edit) converted and checked like a file (VampcError naming the place). Either way its
    layout names must be registered ones (what a type cannot say: the registry grows)."""
    if not isinstance(doc, F.ProgramFile):
        from vampc.program.file import validate_program
        doc = validate_program(doc, path)
    for where, name in (("options.layout", doc.options.layout), ("layout.name", doc.layout.name)):
        if name not in LAYOUTS:
            raise VampcError(f"{path}: {where}: {name!r} is not a layout ({', '.join(LAYOUTS)})")
    return doc


@gc_paused()
def compiled_from_doc(doc: F.ProgramFile | dict, path):
    """The compiler's IRs as a validated program document holds them (a vampc.compiler.Compiled),
    checked against each other, nothing scheduled again: the graph is verified; the schedule must
    run the graph under the file's latencies (durations, dependencies, latency and critical path);
    the layout is read off the network's slots, and the network, its slots at the schedule's ticks,
    must carry every operand by the machine's timing rules (Network.verify). So figures reported
    from a file are recomputed from what runs, never copied from its `summary` (VampcError naming
    the section that disagrees); only an exact solver's proof, which no check can redo, is read
    from it."""

    from vampc.compiler import Compiled
    doc = typed(doc, path)
    graph = graph_from_doc(doc.graph, path)
    options = recorded_options(doc, graph, path)
    chain = chain_from_doc(doc.robot, graph, path)
    numbering = tuple(v.number for v in doc.network.vamps)
    try:
        sched = schedule_from_doc(doc.schedule, graph, path)
        net = scheduled_network_from_doc(doc, sched, path)
        # (the emulator's loader's own index checks, before the network check indexes anything)
        from vampc.emulator.load import check_indices
        check_indices(net, numbering, graph, path)
        _check_selects(net, numbering, path)
        check_port_writes(doc.network, doc.io.port_writes, path)
        if sched.interval != net.period:
            raise VampcError(f"{path}: schedule.interval {sched.interval} is not the network's "
                             f"period {net.period}")
        budget = doc.summary.get("budget")
        proof = budget.get("proof", "") if isinstance(budget, dict) else ""
        layout = layout_from_network(doc.layout, net, graph, LAYOUTS[doc.layout.name].grouped,
                                     proof)
        layout.verify(graph)
        net.verify(graph, sched, path)    # (a bus without a writer named the file as <network>)
        if net.bus is not None:
            _check_bus_figures(net, graph, sched, doc.layout, options.tiers, path)
        from vampc.network.checking import check_checking
        check_checking(net, programs_from_doc(doc), sched.timing, options.error_correction, path,
                       options.check_cycles)
    except VampcInternalError as exc:
        raise VampcError(f"{path}: {exc} (the file was edited); recompile it") from None
    check_tiers(doc, options, path)           # (last: an edited network is said by its checks)
    return Compiled(chain, options, graph, sched, net,
                    numbering, programs_from_doc(doc), stream_from_doc(doc), layout)


def check_graph_of(graph: Graph, chain: Chain, options, path) -> None:
    """The file's graph is the one its robot section compiles to with its options (built again: a
    second or so for a 4096-joint log chain; vampc.commands.program_compiled runs it after the
    static checks, whose messages say more): a report compares configurations compiled from the
    robot section and places a tree's VAMPs by its graph's tables, so an edited robot section (a
    tip load, a base motion, parents) or an edited tree table changed the report's figures with
    exit 0 (`emulate --check` refuses such a file: its reference is the robot section's)."""
    from dataclasses import replace

    from vampc.compiler import build_graph
    if not graph.meta:      # a graph of the user's own (check_meta: linear), built by no builder
        return
    built = build_graph(chain, replace(options, verify=False))
    if built == graph:
        return
    def refuse(where: str, why: str):
        return VampcError(f"{path}: {where}: {why}, not what the robot section compiles to with the "
                          "file's options (the file was edited); recompile it")

    def node_differs(where: str, mine, theirs):
        # the first field that differs, named (a node's edited group had been said as its constant,
        # the two values printed alike: a faults audit's)
        field = next((f for f in mine.__struct_fields__ if getattr(mine, f) != getattr(theirs, f)), None)
        if field == "value" and mine.op is Op.CONST and theirs.op is Op.CONST and mine.name == theirs.name:
            return VampcError(f"{path}: {where}: constant {mine.label} is "
                              f"{numbers_shown(mine.value)}, where the robot section gives "
                              f"{numbers_shown(theirs.value)} (a mass, inertia or link vector is "
                              "baked into the graph's constants; the file was edited); recompile it")
        if field is not None:
            return VampcError(f"{path}: {where}: node {theirs.label}'s {field} is "
                              f"{shown(str(getattr(mine, field)))}, where the robot section compiles to "
                              f"{shown(str(getattr(theirs, field)))} (the file was edited); recompile it")
        return refuse(where, f"node {mine.label}")

    def output_differs(where: str, o, b):
        return refuse(where, f"τ{o.joint} from component {o.component} of node {o.node}, where it "
                      f"compiles to τ{b.joint} from component {b.component} of node {b.node}")
    # the nodes, then the torques: how many, then the first that differs
    for where, noun, how, mine, theirs, differs in (
            ("graph.nodes", "nodes", " with the file's options", graph.nodes, built.nodes, node_differs),
            ("graph.outputs", "torques", "", graph.outputs, built.outputs, output_differs)):
        if len(mine) != len(theirs):
            raise VampcError(f"{path}: {where}: {len(mine)} {noun}, where the robot section compiles "
                             f"to {len(theirs)}{how} (the file was edited); recompile it")
        i = next((i for i, (a, b) in enumerate(zip(mine, theirs)) if a != b), None)
        if i is not None:
            raise differs(f"{where}[{i}]", mine[i], theirs[i])
    mine, theirs = dict(graph.meta), dict(built.meta)
    key = next((k for k in sorted(set(mine) | set(theirs)) if mine.get(k) != theirs.get(k)), None)
    if key == "tree" and all(mine.get(k) == theirs.get(k) for k in set(mine) | set(theirs) if k != "tree") \
            and tree_counted_before(_loaded_json(mine["tree"]), _loaded_json(theirs["tree"])):
        return
    if key is None:                  # (n and the recursion are the options' and robot's already)
        raise refuse("graph", f"n {graph.n}, recursion {graph.recursion}")
    raise refuse(f"graph.meta.{key}", shown(str(mine.get(key))))


def tree_counted_before(stored, now) -> bool:
    """A tree's depth figures as stored before 2026-12-08, when its forward addition levels were a
    chain's worst range (vampc.dataflow.treeprefix.chain_sum_levels): the same figures but that one,
    not an edit (a log program of a quadruped compiled the day before was refused as edited)."""
    from vampc.dataflow.treeprefix import chain_sum_levels
    if not isinstance(stored, dict) or not isinstance(now, dict) or not isinstance(now.get("joints"), int):
        return False
    return stored == {**now, "forward_levels": chain_sum_levels(now["joints"])}


def _loaded_json(text):
    """A JSON text's value, or None where it is not JSON."""
    from vampc import jsontext
    try:
        return jsontext.loads(text)
    except (ValueError, TypeError):
        return None


def recorded_options(doc: F.ProgramFile, graph: Graph, path):
    """The CompileOptions a file records, checked against what its sections hold: the layout it
    names, the recursion of its graph, the latencies of its schedule (an edited options section
    was taken by `emulate` without a word, and a report compared configurations at its
    latencies, not the file's)."""
    from vampc.compiler import CompileOptions
    try:
        options = CompileOptions(**doc.options.recorded(), library=False)   # (its own rules below)
        options.check()
    except VampcError as exc:          # a usage error on the command line is the file's here
        raise VampcError(f"{path}: options: {exc}") from None
    _check_unwritten(doc.options.recorded(), options, path)
    _check_layout_names(doc, options, path)
    for where, got, want, section in (
            ("recursion", options.recursion, graph.recursion, "the graph is"),
            ("mult_latency", options.mult_latency, doc.schedule.mult_latency, "schedule.mult_latency is"),
            ("add_latency", options.add_latency, doc.schedule.add_latency, "schedule.add_latency is")):
        if got != want:
            raise VampcError(f"{path}: options.{where}: {got}, but {section} {want} "
                             "(the file was edited); recompile it")
    r = doc.robot
    check_meta(graph, options, path, tree=r.parents is not None or bool(r.floating),
               ground0=not (r.floating or any(r.base_omega) or any(r.base_omega_dot)))
    return options


def _check_unwritten(recorded: dict, options, path) -> None:
    """Refuse an option the compiler does not write for the file's other options (rounding or
    overflow beside a float word, tiers without the bus, check_cycles without error correction),
    where its value is not the default: the command line refuses it (--rounding on a float64
    program), and a float64 file's edited options.rounding was taken unseen by the report and
    used by a what-if --word run (a new user's find). A default's value changes nothing."""
    from vampc.compiler import CompileOptions
    defaults = CompileOptions.defaults()
    if options.recursion is Recursion.LINEAR:      # (the command line refuses them: exit 2; an
        # edited file's report had taken them, its Table O.1 and log figures changed: a new user's)
        for name in ("prefix", "uniform_leaves"):
            if getattr(options, name) != defaults[name]:
                value = getattr(options, name)
                value = "true" if value is True else repr(getattr(value, "value", value))  # (as JSON)
                raise VampcError(f"{path}: options.{name}: {value}, which "
                                 "applies to the log recursion only, and the file's is linear (the "
                                 "file was edited); recompile it")
    written = options.record()
    for key, value in recorded.items():
        if key not in written and value != defaults.get(key):
            raise VampcError(f"{path}: options.{key}: {value!r}, which the compiler records only "
                             f"where it applies, and it does not with these options (the file was "
                             "edited); recompile it")


def check_meta(graph: Graph, options, path, tree: bool, ground0: bool) -> None:
    """graph.meta as the compiler writes it for the file's options: a report reads a log graph's
    tables of recursion nodes to place and count VAMPs, and names its prefix network (an edited
    table was an internal error, exit 3, or changed the folded layouts' figures, exit 0; an edited
    prefix name was printed as the recursion's). A linear graph without meta is one the user built
    (vampc.compiler.compile_graph; a log graph cannot be compiled without its tables). A chain's
    tables are the ones its prefix network opens (vampc.dataflow.prefix.chain_table); a tree's are
    checked for their shape and groups here, and as a whole where a report reads them
    (check_graph_of builds the graph again). `tree`, `ground0`: the robot section's robot is built
    as a tree (a tree or a floating base), and grounded in O_0 (its base neither floats nor
    rotates), which decide the meta the compiler writes."""
    meta = dict(graph.meta)

    def refuse(key: str, why: str):
        return VampcError(f"{path}: graph.meta.{key}: {why} (the file was edited); recompile it")
    if graph.recursion is Recursion.LINEAR and not meta:
        return          # a graph of the user's own (vampc.compiler.compile_graph): no builder's
    if graph.recursion is Recursion.LINEAR:
        fixed = dict(LINEAR_META)
    else:
        fixed = {"recursion": "log", "prefix": options.prefix,
                 "leaves": LOG_LEAVES[bool(options.uniform_leaves)],
                 "convention": LOG_TREE_CONVENTION if tree else LOG_CONVENTION,
                 "ground": LOG_GROUNDS[ground0]}
        fixed.update({key: meta.get(key) for key in ("bwd_nodes", "fwd_nodes", "prefixes", "suffixes")
                      + (("tree",) if tree else ())})
        if tree:             # (a tree's graph is built pruned: vampc.dataflow.logtree)
            fixed["pruned"] = "yes"
    for key in sorted(set(meta) | set(fixed)):
        if key not in fixed:
            raise refuse(key, "not a key the compiler writes")
        if key not in meta:
            raise refuse(key, "missing, but the compiler writes it")
        if meta[key] != fixed[key] and fixed[key] is not None:
            by = ("the robot section's base, which " + ("neither floats nor rotates, compiles"
                                                        if ground0 else "floats or rotates, compiles")
                  if key == "ground" else "the file's options compile")
            raise refuse(key, f"{shown(meta[key])}, but {by} {shown(fixed[key])}")
    if graph.recursion is Recursion.LOG:
        _check_log_tables(graph, meta, options, refuse, tree, ground0)


def _check_log_tables(graph: Graph, meta: dict, options, refuse, tree: bool, ground0: bool) -> None:
    """A log graph's bwd_nodes and fwd_nodes (chain_table's, for a chain), prefixes and suffixes
    (per joint, node ids or null), and a tree's depth figures: JSON of the right shape."""
    from vampc import jsontext

    def decoded(key: str):
        try:
            return jsontext.loads(meta[key])
        except (jsontext.DecodeError, ValueError):
            raise refuse(key, f"{shown(meta[key])} is not JSON") from None
    if tree:
        decoded("tree")
    else:
        from vampc.dataflow.prefix import chain_table
        want = chain_table(options.prefix, graph.n, ground0)
    groups = {"bwd": set(), "fwd": set()}
    for nd in graph.nodes if tree else ():    # (a chain's: its prefix network's)
        if nd.section in groups:
            groups[nd.section].add(nd.group)
    for section in ("bwd", "fwd"):
        key, rows = f"{section}_nodes", decoded(f"{section}_nodes")
        if not isinstance(rows, list):
            raise refuse(key, "not a list of rows")
        for r, row in enumerate(rows):
            if not (isinstance(row, list) and len(row) == 5 and all(type(x) is int for x in row)
                    and row[0] == r + 1 and all(0 <= x <= graph.n for x in row[1:4]) and row[4] >= 0):
                raise refuse(key, f"row {r} {shown(jsontext.dumps(row))} is not [group {r + 1}, "
                             f"a, k, b, tier] with a, k, b joints of 0..{graph.n} and a tier from 0")
            if not tree and r < len(want[section]) and tuple(row) != want[section][r]:
                raise refuse(key, f"row {r} is {row}, but the {options.prefix} network over "
                             f"{graph.n} joints opens {list(want[section][r])} there")
        if not tree and len(rows) != len(want[section]):
            raise refuse(key, f"{len(rows)} rows, but the {options.prefix} network over {graph.n} "
                         f"joints opens {len(want[section])}")
        missing = sorted(groups[section] - {row[0] for row in rows})
        if missing:
            raise refuse(key, f"no row for group {missing[0]}, which the graph's {section} nodes use")
    for key, width in (("prefixes", 3), ("suffixes", 2)):
        rows = decoded(key)
        if not (isinstance(rows, list) and len(rows) == graph.n and all(
                isinstance(row, list) and len(row) == width and all(
                    x is None or (type(x) is int and 0 <= x < len(graph.nodes)) for x in row)
                for row in rows)):
            raise refuse(key, f"not {graph.n} rows of {width} node ids (or null) of the graph's "
                         f"{len(graph.nodes)} nodes")


def check_tiers(doc: F.ProgramFile, options, path) -> None:
    """A bus program's tiers are the ones its --tiers gives (the default's, or the spans given; a
    tuned set, 'auto', is the tuner's): an edited options.tiers added a 'bus, these tiers' row of
    other spans to the report, exit 0 (a hostile-input audit's)."""
    bus = doc.network.bus
    if bus is None or options.tiers == "auto":
        return
    from vampc.network.bus import default_spans, parse_tiers, tiers_of
    V = len(doc.network.vamps)
    spans = default_spans(V) if options.tiers is None else parse_tiers(options.tiers)
    given = "the default tiers" if options.tiers is None else f"--tiers {options.tiers}"
    _same_tiers(tiers_of(spans, V), bus.tiers, f"{given} mean", path)


def _same_tiers(want, got, given: str, path) -> None:
    """network.bus.tiers (`got`) are `want`, the tiers `given` says ('--tiers auto tunes'), span
    and offset, or VampcError naming the first that differs."""
    want = [(t.span, t.offset) for t in want]
    got = [(t.span, t.offset) for t in got]
    if want == got:
        return
    if len(want) != len(got):
        raise VampcError(f"{path}: options.tiers: {given} {len(want)} tiers, but "
                         f"network.bus.tiers has {len(got)} (the file was edited); recompile it")
    k = next(k for k, (a, b) in enumerate(zip(want, got)) if a != b)
    raise VampcError(f"{path}: network.bus.tiers[{k}]: [{got[k][0]}, {got[k][1]}], where "
                     f"{given} [{want[k][0]}, {want[k][1]}] (span, offset; the file was "
                     "edited); recompile it")


def _check_layout_names(doc: F.ProgramFile, options, path) -> None:
    """The layout section names what the options compile (a report's wiring figures follow the
    name: an edited one changed them, exit 0), and a systolic layout runs one slot a VAMP."""
    for where, got, want in (("layout.name", doc.layout.name, options.layout_name),
                             ("layout.share_passes", doc.layout.share_passes,
                              options.share_passes)):
        if got != want:
            raise VampcError(f"{path}: {where}: {got!r}, but the file's options compile "
                             f"{want!r} (the file was edited); recompile it")
    if is_layout(doc.layout.name, SYSTOLIC):
        several = next((p.vamp for p in doc.programs if len(p.slots) != 1), None)
        if several is not None:
            raise VampcError(f"{path}: layout.name: 'systolic', but VAMP {several} runs "
                             f"{len(doc.programs[several].slots)} slots (a systolic VAMP runs one; "
                             "the file was edited); recompile it")


def _check_selects(net: Network, numbers, path) -> None:
    """Each slot's selects name inputs of its VAMP's multiplexers (as the emulator's loader says of
    the programs the stream delivers; the network check indexed them unchecked: exit 3)."""
    for v in net.vamps:
        for k, s in enumerate(v.slots):
            for name, sel, inputs in (("A", s.sel_a, v.a), ("B", s.sel_b, v.b)):
                if sel >= len(inputs):
                    raise VampcError(f"{path}: VAMP {v.index} (number {numbers[v.index]}) slot {k}: "
                                     f"sel-{name.lower()} {sel} selects no input (operand {name} "
                                     f"has {len(inputs)})")


def _check_bus_figures(net, graph, sched, layout: F.LayoutDoc, tiers, path) -> None:
    """network.bus.stretch and .wait must be what the bus costs against the same layout wired point
    to point (scheduled again here: a report prints them); its positions the compiler's placement
    on the line, and the tiers of a program compiled `--tiers auto` the tuner's (tuned again here):
    an edited placement or tuned tier ran, where the buses still carried every write, and the report
    gave the edited wire lengths and bus counts as the program's (an audit's)."""
    from vampc.network.bus import _Problem, _tuned
    problem = _Problem(graph, sched.timing, layout.name, layout.share_passes, verify=False)
    base = problem.base_sched
    for name, got, want in (("stretch", net.bus.stretch, sched.interval - base.interval),
                            ("wait", net.bus.wait, sched.latency - base.latency)):
        if got != want:
            raise VampcError(f"{path}: network.bus.{name} is {got}, but the bus costs {want} ticks "
                             f"against the same layout wired point to point (the file was edited)")
    got, want = net.bus.position, problem.position
    if tuple(got) != tuple(want):
        v = next(v for v, (a, b) in enumerate(zip(got, want)) if a != b)
        raise VampcError(f"{path}: network.bus.position[{v}]: VAMP {v} at place {got[v]} on the "
                         f"line, where the compiler places it at {want[v]} (the file was edited); "
                         "recompile it")
    if tiers == "auto":
        _same_tiers(_tuned(problem, None)[2].tiers, net.bus.tiers, "--tiers auto tunes", path)


def schedule_of(stored: F.ScheduleDoc) -> Schedule:
    """The schedule section as a Schedule, as it stands (schedule_from_doc checks it too)."""
    from vampc.machine.ops import Timing
    return Schedule(Timing(stored.mult_latency, stored.add_latency), tuple(stored.start),
                    tuple(stored.finish), stored.latency, tuple(stored.critical_path),
                    stored.mults, stored.adds, stored.interval)


def schedule_from_doc(stored: F.ScheduleDoc, graph: Graph, path) -> Schedule:
    """The schedule section as a Schedule, verified against the graph: every op lasts its duration
    after its operands, the latency is the last torque's finish and the critical path and its
    Mult/Addn counts are the graph's under these times (VampcError naming the field otherwise)."""
    from vampc.machine.ops import Timing
    timing = Timing(stored.mult_latency, stored.add_latency)
    if len(stored.start) != len(graph.nodes) or len(stored.finish) != len(graph.nodes):
        raise VampcError(f"{path}: schedule: start and finish need one tick per graph node")
    sched = schedule_of(stored)
    duration = timing.durations
    for nd in graph.nodes:
        key = None
        if sched.finish[nd.id] - sched.start[nd.id] != duration[nd.op]:
            key = "finish"
        elif any(sched.finish[a] > sched.start[nd.id] for a in nd.args):
            key = "start"
        if key is not None:
            raise VampcError(f"{path}: schedule.{key} is not the schedule of the file's graph (the "
                             "file was edited); recompile it")
    if sched.latency != max(sched.finish[o.node] for o in graph.outputs):
        raise VampcError(f"{path}: schedule.latency is not the schedule of the file's graph (the "
                         "file was edited); recompile it")
    # the critical path: a chain of operands ending at a torque, with its Mults and Addns (the
    # graph's data path; a file from before 2026-12 holds the chain binding in its own schedule)
    outputs = {o.node for o in graph.outputs}
    crit = sched.critical_path
    chained = (bool(crit) and all(0 <= i < len(graph.nodes) for i in crit) and crit[-1] in outputs
               and all(a in graph.nodes[b].args for a, b in zip(crit, crit[1:])))
    counts = [timing.path_counts(graph.nodes[i].op) for i in crit if chained]
    if not chained or (sum(m for m, _ in counts), sum(a for _, a in counts)) != (sched.mults,
                                                                                 sched.adds):
        raise VampcError(f"{path}: schedule.critical_path is not a critical path of the file's "
                         "graph with its mults and adds (the file was edited); recompile it")
    return sched


def layout_from_network(lay: F.LayoutDoc, net: Network, graph: Graph, grouped: bool,
                        proof: str = "") -> Layout:
    """The layout a network runs: each node's VAMPs, read off the slots naming it (in column order)."""
    on: dict[int, list[tuple[int, int]]] = {}
    for v in net.vamps:
        for s in v.slots:
            on.setdefault(s.node, []).append((s.column or 0, v.index))
    empty = ()
    placement = tuple(tuple(v for _, v in sorted(on[i])) if i in on else empty
                      for i in range(len(graph.nodes)))
    return Layout(lay.name, placement, net.period, net.clock, lay.share_passes, grouped,
                  proof)


def _off_schedule(v: int, k: int, r: F.SlotDoc, start: int, dump: int, P: int, path) -> None:
    """The VampcError of a slot whose Cycle-Counter fields are not its node's scheduled ticks."""
    for name, got, want in (("delay-A", r.delay_a, start), ("delay-B", r.delay_b, start),
                            ("delay-R", r.delay_r, dump)):
        if got != want % P:
            raise VampcError(f"{path}: programs[{v}] slot {k}: {name} {got} is not "
                             f"the schedule's tick {want} mod {P}")
