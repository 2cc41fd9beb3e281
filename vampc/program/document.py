"""Conversion between the compiler's IRs and the program-file document (see vampc.program.file)."""
from __future__ import annotations

import functools
import json
from dataclasses import replace

import numpy as np

from vampc.dataflow.graph import Graph, InputKey, Node, Output
from vampc.gcpause import gc_paused
from vampc.kinds import Section, TapKind
from vampc.machine.ops import Op
from vampc.network.model import (
    Buffer,
    Const,
    Network,
    Operand,
    OutputPoint,
    Port,
    PortEntry,
    ProgrammedSlot,
    Slot,
    Tap,
    Vamp,
)
from vampc.program.emit import StreamEntry, load_ticks
from vampc.program.file import FORMAT, VERSION, Rows, layout, tolist
from vampc.program.words import ROM, Program
from vampc.robot.chain import Chain, Joint, JointType, Limits
from vampc.schedule.asap import Schedule
from vampc.schedule.layout import Layout
from vampc.schedule.registry import LAYOUTS


@functools.lru_cache(maxsize=65536)
def _str(text: str) -> str:
    """A string as JSON text (ASCII, as the encoder writes it); names repeat, so cached."""
    return json.dumps(text)


def _joint_doc(j: Joint) -> dict:
    out = {
        "name": j.name, "type": j.type.value, "phi": tolist(j.phi), "p_fixed": tolist(j.p_fixed),
        "offset": float(j.offset), "mass": float(j.mass), "com": tolist(j.com),
        "inertia": tolist(j.inertia), "axis": tolist(j.axis),
        "limits": {"q": list(j.limits.q) if j.limits.q else None, "qd": j.limits.qd,
                   "tau": j.limits.tau},
    }
    if j.pre is not None:        # a tree's joint frame (absent for a chain: its files are unchanged)
        out["pre"] = tolist(j.pre)
    if j.shift is not None:
        out["shift"] = tolist(j.shift)
    return out


def chain_to_doc(chain: Chain) -> dict:
    """The robot section (a tree adds `parents`; a floating base `floating` and the base inertia)."""
    out = {"name": chain.name, "n": chain.n, "source": chain.source,
           "joints": [_joint_doc(j) for j in chain.joints],
           "gravity": tolist(chain.gravity), "base_omega": tolist(chain.base_omega),
           "base_omega_dot": tolist(chain.base_omega_dot), "tip_force": tolist(chain.tip_force),
           "tip_torque": tolist(chain.tip_torque)}
    if not chain.is_chain:
        out["parents"] = list(chain.parent_of)
    if chain.floating:
        out.update(floating=True, base_mass=float(chain.base_mass), base_com=tolist(chain.base_com),
                   base_inertia=tolist(chain.base_inertia))
    return out


def chain_from_doc(doc: dict) -> Chain:
    """Inverse of chain_to_doc."""
    joints = tuple(Joint(
        name=j["name"], type=JointType(j["type"]), phi=np.array(j["phi"]),
        p_fixed=np.array(j["p_fixed"]), offset=j["offset"], mass=j["mass"], com=np.array(j["com"]),
        inertia=np.array(j["inertia"]),
        limits=Limits(tuple(j["limits"]["q"]) if j["limits"]["q"] else None, j["limits"]["qd"],
                      j["limits"]["tau"]),
        pre=np.array(j["pre"]) if "pre" in j else None,
        shift=np.array(j["shift"]) if "shift" in j else None) for j in doc["joints"])
    tree = {}
    if "parents" in doc:
        tree["parents"] = tuple(doc["parents"])
    if doc.get("floating"):
        tree.update(floating=True, base_mass=doc["base_mass"], base_com=np.array(doc["base_com"]),
                    base_inertia=np.array(doc["base_inertia"]))
    chain = Chain(doc["name"], joints, np.array(doc["gravity"]), np.array(doc["base_omega"]),
                  np.array(doc["base_omega_dot"]), np.array(doc["tip_force"]),
                  np.array(doc["tip_torque"]), doc["source"], **tree)
    if tree:      # the host walks the tree: parents must be a depth-first tree of n joints
        from vampc.errors import VampcError, VampcInternalError
        try:
            chain._verify_tree()
        except VampcInternalError as exc:
            raise VampcError(f"robot.parents: {exc}") from None
    return chain


def graph_to_doc(g: Graph) -> dict:
    """The graph section: one row per node (formatted straight to text, see Rows)."""
    def row(nd: Node) -> str:
        # keys in sorted order, as the canonical encoder writes them; a float as its repr, which
        # is json's (the values are finite: the graph was verified)
        key = f'"key":[{_str(nd.key.quantity)},{nd.key.joint}],' if nd.key else ""
        value = (",\"value\":[" + ",".join(map(float.__repr__, nd.value)) + "]"
                 if nd.value is not None else "")
        return (f'{{"args":{_ints(nd.args)},"group":{nd.group},"id":{nd.id},{key}'
                f'"name":{_str(nd.name)},"op":"{nd.op.value}","section":{_str(nd.section)}'
                f'{value}}}')
    return {"n": g.n, "recursion": g.recursion, "meta": dict(g.meta),
            "nodes": Rows(map(row, g.nodes)),
            "outputs": [[o.joint, o.node, o.component] for o in g.outputs]}


# name -> member, a dict lookup (an Enum call costs a microsecond, and a big file names millions)
_SECTION = {m.value: m for m in Section}
_TAP = {m.value: m for m in TapKind}


def graph_from_doc(d: dict) -> Graph:
    """Inverse of graph_to_doc."""
    nodes = tuple(Node(r["id"], Op(r["op"]), tuple(r["args"]), r["name"], _SECTION[r["section"]],
                       r["group"],
                       InputKey(*r["key"]) if "key" in r else None,
                       tuple(r["value"]) if "value" in r else None) for r in d["nodes"])
    return Graph(nodes, tuple(Output(*o) for o in d["outputs"]), d["n"], d["recursion"],
                 tuple(sorted(d["meta"].items())))


def schedule_to_doc(s: Schedule) -> dict:
    """The schedule section."""
    return {"mult_latency": s.timing.mult, "add_latency": s.timing.add, "latency": s.latency,
            "interval": s.interval, "mults": s.mults, "adds": s.adds,
            "critical_path": list(s.critical_path), "start": list(s.start), "finish": list(s.finish)}


def network_to_doc(net: Network, numbering) -> dict:
    """The network (netlist) section: wiring only; timing lives in the programs."""
    taps: dict[int, str] = {}   # id(operand) -> its taps as text: readers share operands, and so text
    def operand(op: Operand) -> str:
        text = taps.get(id(op))
        if text is None:
            text = taps[id(op)] = "[" + ",".join([f'["{t.kind}",{t.index},{t.stage}]'
                                                  for t in op.taps]) + "]"
        return text
    def mux(inputs) -> str:
        return "[" + ",".join([operand(op) for op in inputs]) + "]"
    return {
        "period": net.period, "clock": net.clock,
        "vamps": Rows(f'{{"a":{mux(v.a)},"b":{mux(v.b)},"index":{v.index},'
                      f'"number":{numbering[v.index]}}}' for v in net.vamps),
        "buffers": Rows(f'{{"index":{b.index},"source":{b.source},"stages":{b.stages}}}'
                        for b in net.buffers),
        "ports": [{"index": p.index, "size": p.size,
                   "entries": [[e.key.quantity, e.key.joint, e.block] for e in p.entries]}
                  for p in net.ports],
        "consts": [{"index": c.index, "name": c.name, "value": list(c.value)} for c in net.consts],
    }


def _slot_row(s, p) -> str:
    return (f'{{"delay_a":{p.delay_a},"delay_b":{p.delay_b},"delay_r":{p.delay_r},"node":{s.node},'
            f'"op":"{s.op.value}","rom":{p.rom},"sel_a":{p.sel_a},"sel_b":{p.sel_b}}}')


def program_text(chain, graph, sched, net, numbering, progs, stream, options: dict,
                 summary: dict, layout_doc: dict) -> str:
    """The whole program-file document (without its checksum) as the text `write_program` writes:
    canonical JSON laid out one row per line (vampc.program.file.layout)."""
    B = net.clock
    return layout({
        "format": FORMAT, "version": VERSION, "robot": chain_to_doc(chain), "options": options,
        "graph": graph_to_doc(graph), "schedule": schedule_to_doc(sched), "layout": layout_doc,
        "network": network_to_doc(net, numbering),
        "programs": Rows('{"slots":[' + ",".join([_slot_row(s, p) for s, p in zip(v.slots, ps)])
                         + f'],"vamp":{v.index}}}' for v, ps in zip(net.vamps, progs)),
        "program_stream": Rows(
            f'{{"depth":{_ints(e.depth)},"root":["{e.root.kind}",{e.root.index}],'
            f'"targets":{_ints(e.targets)},"words":['
            + ",".join([f"[{x!r},{y!r},{z!r}]" for x, y, z in e.words]) + "]}"
            for e in stream),
        "io": {"period": net.period, "clock": B, "load_ticks": load_ticks(stream),
               "port_writes": [{"port": p.index, "quantity": e.key.quantity, "joint": e.key.joint,
                                "tick": e.block * B} for p in net.ports for e in p.entries],
               "outputs": [{"joint": o.joint, "vamp": o.vamp, "component": o.component,
                            "tick": o.tick} for o in net.outputs]},
        "summary": summary,
    })


def _ints(values) -> str:
    return "[" + ",".join(map(str, values)) + "]"


def network_from_doc(doc: dict) -> Network:
    """The netlist, with each VAMP's slots as its `programs` listing gives them (latch and dump
    ticks are Cycle-Counter values here: absolute times are the emulator's to derive)."""
    nd = doc["network"]
    progs = doc["programs"]
    def operand(rows) -> Operand:
        return Operand(tuple(Tap(_TAP[k], i, s) for k, i, s in rows))
    def slots(index: int):
        return tuple(ProgrammedSlot(r["node"], ROM[r["rom"]][0], ROM[r["rom"]][1], r["sel_a"],
                                    r["sel_b"], r["delay_a"], r["delay_b"], r["delay_r"])
                     for r in progs[index]["slots"])
    vamps = tuple(Vamp(v["index"], tuple(map(operand, v["a"])), tuple(map(operand, v["b"])),
                       slots(v["index"])) for v in nd["vamps"])
    return Network(nd["period"], nd["clock"], vamps,
                   tuple(Buffer(b["index"], b["source"], b["stages"]) for b in nd["buffers"]),
                   tuple(Port(p["index"], p["size"], tuple(PortEntry(InputKey(q, j), blk)
                                                           for q, j, blk in p["entries"]))
                         for p in nd["ports"]),
                   tuple(Const(c["index"], c["name"], tuple(c["value"])) for c in nd["consts"]),
                   tuple(OutputPoint(o["joint"], o["vamp"], o["component"], o["tick"])
                         for o in doc["io"]["outputs"]))


def stream_from_doc(doc: dict) -> tuple[StreamEntry, ...]:
    """The program stream entries, words included."""
    return tuple(StreamEntry(Tap(*e["root"]), tuple(e["targets"]), tuple(e["depth"]),
                             tuple(tuple(w) for w in e["words"])) for e in doc["program_stream"])


def programs_from_doc(doc: dict) -> tuple[tuple[Program, ...], ...]:
    """Per-VAMP slot programs as the `programs` listing writes them."""
    return tuple(tuple(Program(r["delay_a"], r["delay_b"], r["delay_r"], r["rom"], r["sel_a"],
                               r["sel_b"]) for r in p["slots"]) for p in doc["programs"])


@gc_paused()
def compiled_from_doc(doc: dict, path):
    """The compiler's IRs as a validated program document holds them (a vampc.compiler.Compiled),
    checked against each other, nothing scheduled again: the graph is verified; the schedule must
    run the graph under the file's latencies (durations, dependencies, latency and critical path);
    the layout is read off the network's slots, and the network, its slots at the schedule's ticks,
    must carry every operand by the machine's timing rules (Network.verify). So figures reported
    from a file are recomputed from what runs, never copied from its `summary` (VampcError naming
    the section that disagrees); only an exact solver's proof, which no check can redo, is read
    from it."""

    from vampc.compiler import Compiled, CompileOptions
    from vampc.errors import VampcError, VampcInternalError
    graph = graph_from_doc(doc["graph"])
    net = network_from_doc(doc)
    opts = doc["options"]
    known = CompileOptions.recorded()
    try:
        options = CompileOptions(**{k: v for k, v in opts.items() if k in known})
        options.check()
    except VampcError as exc:          # a usage error on the command line is the file's here
        raise VampcError(f"{path}: options: {exc}") from None
    try:
        graph.verify()
        sched = schedule_from_doc(doc["schedule"], graph, path)
        if sched.interval != net.period:
            raise VampcError(f"{path}: schedule.interval {sched.interval} is not the network's "
                             f"period {net.period}")
        proof = (doc.get("summary", {}).get("budget") or {}).get("proof", "")
        kind = LAYOUTS.get(options.layout_name)      # the schema holds the name to the registry
        layout = layout_from_network(doc["layout"], net, graph, kind is None or kind.grouped,
                                     proof)
        layout.verify(graph)
        timed_network(net, sched, path).verify(graph, sched)
    except VampcInternalError as exc:
        raise VampcError(f"{path}: {exc} (the file was edited); recompile it") from None
    numbering = tuple(v["number"] for v in doc["network"]["vamps"])
    return Compiled(chain_from_doc(doc["robot"]), options, graph, sched, net,
                    numbering, programs_from_doc(doc), stream_from_doc(doc), layout)


def schedule_of(stored: dict) -> Schedule:
    """The schedule section as a Schedule, as it stands (schedule_from_doc checks it too)."""
    from vampc.machine.ops import Timing
    return Schedule(Timing(stored["mult_latency"], stored["add_latency"]), tuple(stored["start"]),
                    tuple(stored["finish"]), stored["latency"], tuple(stored["critical_path"]),
                    stored["mults"], stored["adds"], stored["interval"])


def schedule_from_doc(stored: dict, graph: Graph, path) -> Schedule:
    """The schedule section as a Schedule, verified against the graph: every op lasts its duration
    after its operands, the latency is the last torque's finish and the critical path and its
    Mult/Addn counts are the graph's under these times (VampcError naming the field otherwise)."""
    from vampc.errors import VampcError
    from vampc.machine.ops import Timing
    timing = Timing(stored["mult_latency"], stored["add_latency"])
    if len(stored["start"]) != len(graph.nodes) or len(stored["finish"]) != len(graph.nodes):
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
    # the critical path: a chain of operands ending at the last torque, with its Mults and Addns
    last = max(graph.outputs, key=lambda o: (sched.finish[o.node], o.joint))
    crit = sched.critical_path
    chained = (bool(crit) and all(0 <= i < len(graph.nodes) for i in crit) and crit[-1] == last.node
               and all(a in graph.nodes[b].args for a, b in zip(crit, crit[1:])))
    counts = [timing.path_counts(graph.nodes[i].op) for i in crit if chained]
    if not chained or (sum(m for m, _ in counts), sum(a for _, a in counts)) != (sched.mults,
                                                                                 sched.adds):
        raise VampcError(f"{path}: schedule.critical_path is not a critical path of the file's "
                         "graph with its mults and adds (the file was edited); recompile it")
    return sched


def layout_from_network(lay: dict, net: Network, graph: Graph, grouped: bool,
                        proof: str = "") -> Layout:
    """The layout a network runs: each node's VAMPs, read off the slots naming it (in column order)."""
    on: dict[int, list[tuple[int, int]]] = {}
    for v in net.vamps:
        for s in v.slots:
            on.setdefault(s.node, []).append((s.column or 0, v.index))
    empty = ()
    placement = tuple(tuple(v for _, v in sorted(on[i])) if i in on else empty
                      for i in range(len(graph.nodes)))
    return Layout(lay["name"], placement, net.period, net.clock, lay["share_passes"], grouped,
                  proof)


def timed_network(net: Network, sched: Schedule, path) -> Network:
    """The network with its programmed slots as scheduled ones, at absolute ticks (set 0): each slot
    latches at its node's start and dumps at its finish - 1. Its Cycle-Counter fields must be those
    ticks mod P (VampcError)."""
    from vampc.errors import VampcError
    P = net.period
    vamps = []
    for v in net.vamps:
        slots = []
        for k, s in enumerate(v.slots):
            start, dump = sched.start[s.node], sched.finish[s.node] - 1
            for name, got, want in (("delay-A", s.delay_a, start), ("delay-B", s.delay_b, start),
                                    ("delay-R", s.delay_r, dump)):
                if got != want % P:
                    raise VampcError(f"{path}: programs[{v.index}] slot {k}: {name} {got} is not "
                                     f"the schedule's tick {want} mod {P}")
            slots.append(Slot(s.node, s.op, s.column, s.sel_a, s.sel_b, start, start, dump))
        vamps.append(replace(v, slots=tuple(slots)))
    return replace(net, vamps=tuple(vamps))
