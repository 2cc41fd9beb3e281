"""Buffering and wiring (section VI), measured from a compiled network: input buffering, delay-buffer
stages by where their values go (within a pass, backward to forward), vector buses between nodes or
tiers and inside a node, fan-out, and the Program-Mode stream.

A "bus" is the paper's vector bus three scalars wide, carrying one source's value (a host port's or
a constant's matrix serially, as the paper's one Operand-A pin carries it): one tap of a VAMP's
operand multiplexer, so a matrix whose columns an MM group's three VAMPs make is three buses (an MM
group's shared operands count once: its three VAMPs share them). A site is a recursion node or
device node (vampc.report.sites).
"""
from __future__ import annotations

import math
import re
from collections import Counter
from typing import NamedTuple

from vampc.kinds import Pass, Recursion, Section, TapKind, exhaustive
from vampc.machine.ops import Op, result_shape
from vampc.memo import keep_last
from vampc.report import paper
from vampc.report.compare import max_fan_out
from vampc.report.sites import vamp_sites, vamp_units

FLOWS = ("within_backward", "backward_to_forward", "within_forward")


def wiring(configs, chain) -> dict:
    """Every wiring figure of the report's own configuration, and the delay buffering of each
    allocated configuration beside it."""
    from vampc.report.configs import own
    from vampc.report.counts import hardware
    k = own(configs)
    hw = hardware(k)
    mine = delay_buffers(k.graph, k.network)
    return {"configuration": k.name,
            "input_buffering": input_buffering(k.network, chain.n),
            "delay_buffers": mine,
            "buses": buses(k.graph, k.layout, k.network),
            "max_fan_out": max_fan_out(k.network),
            "program": {"words": hw["program_words"], "load_ticks": hw["load_ticks"],
                        "input_buffers": len(k.stream)},
            "by_configuration": [_buffering_row(c, mine if c is k else None) for c in configs
                                 if c.network is not None]}


def input_buffering(net, n: int) -> dict:
    """Scalars the host keeps: one torque set's port values and the constant buffers, by quantity,
    beside the paper's ≈ 37n + 15."""
    ports: Counter = Counter()
    seen = set()
    for p in net.ports:
        for e in p.entries:
            if (e.key.quantity, e.key.joint) not in seen:
                seen.add((e.key.quantity, e.key.joint))
                ports[e.key.quantity] += p.size
    consts: Counter = Counter()
    for c in net.consts:
        consts[re.sub(r"\d+$", "", c.name)] += len(c.value)
    total = sum(ports.values()) + sum(consts.values())
    return {"scalars": total, "ports": dict(sorted(ports.items())),
            "constants": dict(sorted(consts.items())), "constant_buffers": len(net.consts),
            "paper": paper.input_buffer_estimate(n),
            "paper_items": dict(paper.INPUT_BUFFER_ITEMS),
            "paper_endpoints": paper.INPUT_BUFFER_ENDPOINTS}


_WEIGHT = {op: 3 if result_shape(op) == "m" else 1 for op in Op if op.is_compute}   # vectors
_KIND_CODES = {TapKind.VAMP: 0, TapKind.BUFFER: 1, TapKind.PORT: 2, TapKind.CONST: 3}


class Reads(NamedTuple):
    """Every operand tap of every slot, VAMP by VAMP, slot by slot, A then B, as columns (numpy
    arrays, a row per tap): reader VAMP, tap kind (_KIND_CODES), tap index, tap stage, source node
    (the operand's), reading node (the slot's). A big network has millions of taps: the wiring
    figures count them with numpy."""

    reader: object
    kind: object
    index: object
    stage: object
    arg: object
    node: object


@keep_last()
def reads_table(graph, net) -> Reads:
    """The network's taps as a Reads table (the last one is kept: the report's figures ask twice)."""
    import numpy as np

    from vampc.network.bus import wired
    net = wired(net)             # a bus network: the wires it implements
    nodes = graph.nodes
    cols: list[list[int]] = [[], [], [], [], [], []]
    reader, kind, index, stage, source, reading = (c.append for c in cols)
    code = _KIND_CODES
    for v in net.vamps:
        vi = v.index
        for s in v.slots:
            args = nodes[s.node].args
            for operand, arg in ((v.a[s.sel_a], args[0]), (v.b[s.sel_b], args[1])):
                for tap in operand.taps:
                    reader(vi)
                    kind(code[tap.kind])
                    index(tap.index)
                    stage(tap.stage)
                    source(arg)
                    reading(s.node)
    return Reads(*(np.array(c, dtype=np.int64) for c in cols))


def _distinct(*columns):
    """The distinct rows of equal-length integer columns (each >= 0), as columns."""
    import numpy as np
    if not len(columns[0]):
        return tuple(np.zeros(0, dtype=np.int64) for _ in columns)
    radix = [int(c.max()) + 1 for c in columns]
    if math.prod(radix) >= 1 << 62:               # too wide for one int64 key: rows of a matrix
        rows = np.unique(np.stack(columns, axis=1), axis=0)
        return tuple(rows[:, k] for k in range(len(columns)))
    key = np.zeros(len(columns[0]), dtype=np.int64)
    for c, r in zip(columns, radix):
        key = key * r + c
    key = np.sort(key)        # (np.unique hashes: 2.5 s for two million keys here, the sort 0.14 s)
    key = key[np.r_[True, key[1:] != key[:-1]]]
    out = []
    for r in reversed(radix):
        key, rest = np.divmod(key, r)
        out.append(rest)
    return tuple(reversed(out))


def early_forward(graph) -> set[int]:
    """Forward-pass nodes whose value needs no other forward node's result: computable before the
    forward recursion reaches them (the paper's "already computed" T20, T21; the log leaves), so
    what they carry is backward-to-forward traffic."""
    early: set[int] = set()
    nodes = graph.nodes
    for nd in nodes:
        if nd.section is not Section.FWD:
            continue
        if all(nodes[a].section is not Section.FWD or (a in early and nodes[a].group == nd.group)
               for a in nd.args):
            early.add(nd.id)
    return early


def origin_pass(graph, early: set[int], node: int) -> Pass:
    """'backward' or 'forward': the pass whose recursion a value belongs to."""
    return Pass.BACKWARD if node in early else Pass.of(graph.nodes[node].section)


def delay_buffers(graph, net) -> dict:
    """Buffer chains, stages and scalars in all and by where the values go: within the backward
    pass (with its non-propagated variables), backward to forward (values computed from the
    backward pass and held for the forward one), within the forward pass. A chain counts where its
    deepest stage is read (the first such read, in the order of reads_table)."""
    kind = buffer_flows(graph, net)
    classes = {k: {"chains": 0, "stages": 0, "scalars": 0} for k in FLOWS}
    for b in net.buffers:
        cls = classes[kind.get(b.index, "within_backward")]
        cls["chains"] += 1
        cls["stages"] += b.stages
        cls["scalars"] += 3 * b.stages
    return {"chains": len(net.buffers), "stages": net.buffer_stages,
            "scalars": 3 * net.buffer_stages, "by_flow": classes,
            "max_stages": max((b.stages for b in net.buffers), default=0)}


def buffer_flows(graph, net) -> dict[int, str]:
    """Each buffer chain's flow (FLOWS), as delay_buffers counts it: by the pass of the value held
    (a forward node computing ahead from backward results alone holds backward-to-forward traffic,
    wherever its VAMP sits: the network picture, which draws buses between sites, says so too).
    A chain missing here is read at no stage past 0: within the backward pass."""
    import numpy as np
    early = early_forward(graph)
    t = reads_table(graph, net)
    buffered = np.flatnonzero(t.kind == _KIND_CODES[TapKind.BUFFER])
    buffered = buffered[t.stage[buffered] > 0]
    index, stage = t.index[buffered], t.stage[buffered]
    # per buffer: its first tap (in table order) of the deepest stage read
    order = np.lexsort((buffered, -stage, index))
    first = order[np.r_[True, index[order][1:] != index[order][:-1]]] if len(order) else order
    kind: dict[int, str] = {}
    for i, row in zip(index[first].tolist(), buffered[first].tolist()):
        src, node = int(t.arg[row]), int(t.node[row])
        kind[i] = _flow(origin_pass(graph, early, src), Pass.of(graph.nodes[node].section))
    return kind


def _flow(src: str, dst: str) -> str:
    return f"within_{src}" if src == dst else "backward_to_forward"


def buses(graph, layout, net) -> dict:
    """Vector buses into each site from the other sites of its pass (vectors: distinct results
    received, a matrix as three; wires: distinct taps, a value read at two buffer stages counting
    twice, a matrix's three columns counting three), the most any
    one site receives per pass; the backward-to-forward traffic in all; and the buses into one
    site's VAMPs (the paper's point-to-point bound per module)."""
    import numpy as np
    sites = vamp_sites(graph, layout)
    ids: dict = {}
    site_id = np.fromiter((ids.setdefault(x, len(ids)) for x in sites), dtype=np.int64,
                          count=len(sites))
    site_list = list(ids)
    sections = list(dict.fromkeys(x[0] for x in site_list))
    site_section = np.array([sections.index(x[0]) for x in site_list], dtype=np.int64)
    pass_code = {p: k for k, p in enumerate(Pass)}
    site_pass = np.array([pass_code.get(Pass.of(x[0]), -1) for x in site_list], dtype=np.int64)
    t = reads_table(graph, net)
    from vampc.network.bus import wired
    wired_net = wired(net)           # (a bus network: the point-to-point wires it implements)
    source = np.array([b.source for b in net.buffers], dtype=np.int64)
    vamp = t.kind == _KIND_CODES[TapKind.VAMP]
    buffer = t.kind == _KIND_CODES[TapKind.BUFFER]
    rows = np.flatnonzero(vamp | buffer)       # the host's ports and constants are no bus
    src = np.where(vamp[rows], t.index[rows], source[np.where(buffer[rows], t.index[rows], 0)]
                   if len(source) else 0)
    there, here = site_id[src], site_id[t.reader[rows]]
    across = there != here
    b2f = across & (site_pass[there] != site_pass[here])
    within = across & ~b2f & (site_section[there] == site_section[here])
    weight = np.fromiter((_WEIGHT[nd.op] if nd.op.is_compute else 3 if nd.shape == "m" else 1
                          for nd in graph.nodes), dtype=np.int64, count=len(graph.nodes))
    kind, index, stage, arg = t.kind[rows], t.index[rows], t.stage[rows], t.arg[rows]
    b2f_args, _ = _distinct(arg[b2f], here[b2f])
    b2f_wires = len(_distinct(kind[b2f], index[b2f], stage[b2f], here[b2f])[0])
    at, value = _distinct(here[within], arg[within])
    vectors = np.bincount(at, weights=weight[value], minlength=len(site_list)).astype(np.int64)
    wire_at = _distinct(here[within], kind[within], index[within], stage[within])[0]
    wires = np.bincount(wire_at, minlength=len(site_list))

    def most(per_site, section: str) -> int:
        if section not in sections:
            return 0
        return int(per_site[site_section == sections.index(section)].max(initial=0))
    out = {"between_nodes": {s: {"vectors": most(vectors, s), "wires": most(wires, s)}
                             for s in ("bwd", "fwd")},
           "backward_to_forward": {"vectors": int(weight[b2f_args].sum()), "wires": b2f_wires},
           "internal_max": _internal(sites, vamp_units(layout), net),
           "internal_max_wires": _internal(sites, vamp_units(layout), wired_net, per_tap=True),
           "paper_between_nodes": exhaustive({
               Recursion.LINEAR: dict(paper.LINEAR_INTER_NODE_BUSES),
               Recursion.LOG: {"bwd": paper.LOG_INTER_NODE_BUSES, "fwd": paper.LOG_INTER_NODE_BUSES},
           }, Recursion)[graph.recursion],
           "paper_internal": dict(paper.INTERNAL_BUS_BOUNDS)}
    if net.bus is not None:
        # on the bus a VAMP's multiplexer inputs are its tiers beside the wires still point to
        # point, more than the paper's bound, which counts connections: those too, on the
        # point-to-point network the bus implements (the report said 71 / 27 / 30 beside
        # ≤ 50 / 20 / 50 and nothing more: a new user's find)
        out["internal_max_connections"] = _internal(sites, vamp_units(layout), wired_net)
    return out


def _internal(sites, units, net, per_tap: bool = False) -> dict:
    """Per section, the most multiplexer inputs into the VAMPs of one site (the paper's count: an
    operand a bus; an MM group's counted once, its three VAMPs sharing them), or with `per_tap`
    the wires (buses) into them: each operator's distinct taps, so a matrix that an MM group's
    three VAMPs make is three, and an MM group's operand B, a column into each of its VAMPs, three."""
    per_site: Counter = Counter()
    if per_tap:
        members = Counter(units[v.index] for v in net.vamps)
        taps: dict = {}
        for v in net.vamps:
            a, b = v.a, v.b
            if members[units[v.index]] == 1 and len(a) == 1 and len(b) == 1:
                ta, tb = a[0].taps, b[0].taps     # (most VAMPs: one input an operand, one tap)
                if len(ta) == 1 and len(tb) == 1:
                    per_site[sites[v.index]] += 1 if ta[0] == tb[0] else 2
                else:
                    per_site[sites[v.index]] += len(set(ta) | set(tb))
                continue
            unit = taps.setdefault(units[v.index], (sites[v.index], set()))[1]
            unit.update(t for o in a + b for t in o.taps)
        for site, unit in taps.values():
            per_site[site] += len(unit)
    counted = set()
    for v in net.vamps if not per_tap else ():
        if units[v.index] in counted:
            continue
        counted.add(units[v.index])
        per_site[sites[v.index]] += len(v.a) + len(v.b)
    out: Counter = Counter()
    for site, k in per_site.items():
        out[site.section] = max(out[site.section], k)
    return {s: out[s] for s in ("bwd", "npv", "fwd")}


def _buffering_row(k, known: dict | None) -> dict:
    """One configuration's delay buffering (for the systolic-against-folded comparison); `known`:
    its delay_buffers if already counted."""
    d = known or delay_buffers(k.graph, k.network)
    return {"configuration": k.name, "chains": d["chains"], "stages": d["stages"],
            "scalars": d["scalars"],
            "backward_to_forward_scalars": d["by_flow"]["backward_to_forward"]["scalars"]}
