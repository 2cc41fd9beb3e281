"""Buffering and wiring (section VI), measured from a compiled network: input buffering, delay-buffer
stages by where their values go (within a pass, backward to forward), vector buses between nodes or
tiers and inside a node, fan-out, and the Program-Mode stream.

A "bus" is the paper's vector bus three scalars wide: one multiplexer input of a VAMP (a matrix
operand of an MM group counts once: the group's three VAMPs share it). A site is a recursion node or
device node (vampc.report.sites).
"""
from __future__ import annotations

import re
from collections import Counter

from vampc.kinds import Pass, Recursion, Section, TapKind, exhaustive
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


def _reads(graph, net):
    """(reader VAMP, tap, source node, reading node) for every operand tap of every slot."""
    for v in net.vamps:
        for s in v.slots:
            args = graph.nodes[s.node].args
            for operand, arg in ((v.a[s.sel_a], args[0]), (v.b[s.sel_b], args[1])):
                for tap in operand.taps:
                    yield v.index, tap, arg, s.node


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
    deepest stage is read."""
    early = early_forward(graph)
    deepest: dict[int, tuple[int, str]] = {}
    for _, tap, arg, node in _reads(graph, net):
        if tap.kind is not TapKind.BUFFER:
            continue
        kind = _flow(origin_pass(graph, early, arg), Pass.of(graph.nodes[node].section))
        if tap.stage > deepest.get(tap.index, (0, ""))[0]:
            deepest[tap.index] = (tap.stage, kind)
    classes = {k: {"chains": 0, "stages": 0, "scalars": 0} for k in FLOWS}
    for b in net.buffers:
        cls = classes[deepest.get(b.index, (0, "within_backward"))[1]]
        cls["chains"] += 1
        cls["stages"] += b.stages
        cls["scalars"] += 3 * b.stages
    return {"chains": len(net.buffers), "stages": net.buffer_stages,
            "scalars": 3 * net.buffer_stages, "by_flow": classes,
            "max_stages": max((b.stages for b in net.buffers), default=0)}


def _flow(src: str, dst: str) -> str:
    return f"within_{src}" if src == dst else "backward_to_forward"


def buses(graph, layout, net) -> dict:
    """Vector buses into each site from the other sites of its pass (vectors: distinct results
    received, a matrix as three; wires: distinct taps, a value read at two buffer stages counting
    twice, a matrix's three columns counting three), the most any
    one site receives per pass; the backward-to-forward traffic in all; and the buses into one
    site's VAMPs (the paper's point-to-point bound per module)."""
    sites = vamp_sites(graph, layout)
    values: dict = {}
    wires: dict = {}
    b2f_values, b2f_wires = set(), set()
    source = [b.source for b in net.buffers]
    passes = {site: Pass.of(site[0]) for site in set(sites)}
    vamp, buffer = TapKind.VAMP, TapKind.BUFFER
    for v, tap, arg, _ in _reads(graph, net):
        kind = tap.kind
        if kind is vamp:          # (tap_source in line) the host's ports and constants are no bus
            there = sites[tap.index]
        elif kind is buffer:
            there = sites[source[tap.index]]
        else:
            continue
        here = sites[v]
        if there == here:
            continue
        if passes[there] != passes[here]:
            b2f_values.add((arg, here))
            b2f_wires.add((kind, tap.index, tap.stage, here))
        elif there[0] == here[0]:
            values.setdefault(here, set()).add(arg)
            wires.setdefault(here, set()).add((kind, tap.index, tap.stage))
    def vectors(ids) -> int:          # a matrix value travels as three vectors (its columns)
        return sum(3 if graph.nodes[i].shape == "m" else 1 for i in ids)
    return {"between_nodes": {s: {"vectors": max((vectors(x) for site, x in values.items()
                                                  if site.section == s), default=0),
                                  "wires": _most(wires, s)} for s in ("bwd", "fwd")},
            "backward_to_forward": {"vectors": vectors(a for a, _ in b2f_values),
                                    "wires": len(b2f_wires)},
            "internal_max": _internal(sites, vamp_units(layout), net),
            "paper_between_nodes": exhaustive({
                Recursion.LINEAR: dict(paper.LINEAR_INTER_NODE_BUSES),
                Recursion.LOG: {"bwd": paper.LOG_INTER_NODE_BUSES, "fwd": paper.LOG_INTER_NODE_BUSES},
            }, Recursion)[graph.recursion],
            "paper_internal": dict(paper.INTERNAL_BUS_BOUNDS)}


def _most(per_site: dict, section: str) -> int:
    return max((len(x) for site, x in per_site.items() if site.section == section), default=0)


def _internal(sites, units, net) -> dict:
    """Per section, the most multiplexer inputs (buses) into the VAMPs of one site, an MM group's
    shared operands counted once."""
    per_site: Counter = Counter()
    counted = set()
    for v in net.vamps:
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
