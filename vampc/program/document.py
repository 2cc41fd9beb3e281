"""Conversion between the compiler's IRs and the program-file document (see vampc.program.file)."""
from __future__ import annotations

from json.encoder import encode_basestring_ascii as _str

import numpy as np

from vampc.dataflow.graph import Graph, InputKey, Node, Output
from vampc.machine.ops import Op
from vampc.network.model import (
    Buffer,
    Const,
    Network,
    Operand,
    OutputPoint,
    Port,
    PortEntry,
    Slot,
    Tap,
    Vamp,
)
from vampc.program.emit import StreamEntry, load_ticks
from vampc.program.file import FORMAT, VERSION, Rows, compact_encoder, layout, tolist
from vampc.program.words import ROM, Program
from vampc.robot.chain import Chain, Joint, JointType, Limits
from vampc.schedule.asap import Schedule


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
    enc = compact_encoder()
    def row(nd: Node) -> str:
        if nd.op.is_compute:    # nearly every node of a big graph: no key, no value
            return (f'{{"args":{_ints(nd.args)},"group":{nd.group},"id":{nd.id},'
                    f'"name":{_str(nd.name)},"op":"{nd.op.value}","section":{_str(nd.section)}}}')
        r = {"id": nd.id, "op": nd.op.value, "args": list(nd.args), "name": nd.name,
             "section": nd.section, "group": nd.group}
        if nd.key:
            r["key"] = [nd.key.quantity, nd.key.joint]
        if nd.value is not None:
            r["value"] = list(nd.value)
        return enc(r)
    return {"n": g.n, "recursion": g.recursion, "meta": dict(g.meta),
            "nodes": Rows(map(row, g.nodes)),
            "outputs": [[o.joint, o.node, o.component] for o in g.outputs]}


def graph_from_doc(d: dict) -> Graph:
    """Inverse of graph_to_doc."""
    nodes = tuple(Node(r["id"], Op(r["op"]), tuple(r["args"]), r["name"], r["section"], r["group"],
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
        return Operand(tuple(Tap(k, i, s) for k, i, s in rows))
    def slots(index: int):
        return tuple(Slot(r["node"], ROM[r["rom"]][0], ROM[r["rom"]][1], r["sel_a"], r["sel_b"],
                          r["delay_a"], r["delay_b"], r["delay_r"]) for r in progs[index]["slots"])
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


def compiled_from_doc(doc: dict, path):
    """The compiler's IRs as a validated program document holds them (a vampc.compiler.Compiled),
    checked against each other: the graph is verified and the schedule must be the one the graph
    gives under the file's latencies. So figures reported from a file are recomputed from what runs,
    never copied from its `summary` (VampcError naming the section that disagrees)."""
    from dataclasses import fields

    from vampc.compiler import Compiled, CompileOptions
    from vampc.errors import VampcError, VampcInternalError
    from vampc.machine.ops import Timing
    from vampc.schedule.layout import layout_and_schedule
    graph = graph_from_doc(doc["graph"])
    stored = doc["schedule"]
    lay = doc["layout"]
    try:
        graph.verify()
        opts = doc["options"]
        layout, sched = layout_and_schedule(graph, Timing(stored["mult_latency"],
                                                          stored["add_latency"]),
                                            lay["name"], lay["share_passes"], True,
                                            opts.get("vamps"), opts.get("interval"),
                                            opts.get("exact", False))
    except VampcInternalError as exc:
        raise VampcError(f"{path}: graph: {exc}") from None
    for key, value in schedule_to_doc(sched).items():
        if stored.get(key) != value:
            raise VampcError(f"{path}: schedule.{key} is not the schedule of the file's graph (the "
                             "file was edited); recompile it")
    known = {f.name for f in fields(CompileOptions)}
    options = CompileOptions(**{k: v for k, v in doc["options"].items() if k in known})
    numbering = tuple(v["number"] for v in doc["network"]["vamps"])
    return Compiled(chain_from_doc(doc["robot"]), options, graph, sched, network_from_doc(doc),
                    numbering, programs_from_doc(doc), stream_from_doc(doc), layout)
