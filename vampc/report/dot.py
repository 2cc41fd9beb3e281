"""Graphviz text (`vampc report --dot FILE.dot`): two digraphs in one file — `network` (every VAMP,
grouped in a cluster per recursion or device node, its delay buffers, host ports, constant buffers
and torque outputs; one edge per multiplexer input) and `dataflow` (every graph node, grouped per
recursion node; one edge per operand). `dot -Tsvg FILE.dot` draws both.

A network of more than DETAIL_VAMPS VAMPs (a 64-joint log network has 7 000, which Graphviz does
not lay out in minutes) gets the drawing's aggregation instead (vampc.report.network_drawing): one
DOT node per recursion node, or per group of positions for a wide network, with its VAMPs; one edge
per pair with the vector buses (solid) or buffered buses (dashed) between them; the critical path's
nodes in red; the dataflow digraph is then left out (the file says so)."""
from __future__ import annotations

from vampc.kinds import TapKind
from vampc.report.sites import SECTION_NAMES, vamp_sites


def quote(text: str) -> str:
    """A DOT string literal."""
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n") + '"'


DETAIL_VAMPS = 2000


def report_dot(graph, layout, net, name: str, critical_path=()) -> str:
    """Both digraphs (the network, then the dataflow graph) as DOT text; for a big network the
    aggregated network alone (see the module docstring)."""
    if len(net.vamps) > DETAIL_VAMPS:
        return aggregated_dot(graph, layout, net, name, critical_path)
    return network_dot(graph, layout, net, name) + "\n" + dataflow_dot(graph, name)


def aggregated_dot(graph, layout, net, name: str, critical_path=()) -> str:
    """The network as the drawing aggregates it, a DOT digraph named `network`."""
    from vampc.report.network_drawing import COLOURS, drawing
    d = drawing(graph, layout, net, critical_path)
    ids = {site: f"s{k}" for k, site in enumerate(d.labels)}
    what = (f"{len(net.vamps):,} VAMPs, one node per recursion node" if d.grouped == 1 else
            f"{len(net.vamps):,} VAMPs in groups of {d.grouped} positions")
    lines = [f"// {len(net.vamps):,} VAMPs: more than {DETAIL_VAMPS:,}, so the network is aggregated "
             f"and the dataflow graph ({len(graph.compute_nodes()):,} ops) left out",
             "digraph network {", f"  label={quote(f'{name}: VAMP network ({layout.name}), {what}')};",
             "  rankdir=BT; newrank=true; node [fontsize=9, style=filled]; edge [fontsize=7];"]
    for site, label in d.labels.items():
        red = ", color=red, penwidth=2" if site in d.critical else ""
        lines.append(f"  {ids[site]} [label={quote(label + chr(10) + f'{d.vamps[site]} V')}, "
                     f"fillcolor={quote(COLOURS[site.section])}{red}];")
    for (a, b), k in sorted(d.buses.items(), key=lambda e: (ids[e[0][0]], ids[e[0][1]])):
        if a != b:
            lines.append(f"  {ids[a]} -> {ids[b]} [label={quote(str(k))}];")
    for (a, b), (k, deepest, chains) in sorted(d.buffered.items(), key=lambda e: (ids[e[0][0]], ids[e[0][1]])):
        lines.append(f"  {ids[a]} -> {ids[b]} [style=dashed, label={quote(f'{k} buffered, st. ≤{deepest}')}];")
    for index, readers, label in d.ports:
        if readers:
            lines.append(f"  p{index} [shape=invtriangle, style=solid, label={quote(label)}];")
            lines += [f"  p{index} -> {ids[r]};" for r in readers]
    for joint, site in d.outputs:
        name = d.output_name(joint)
        lines.append(f"  tau{joint} [shape=house, style=solid, label={quote(name + '…' if d.grouped > 1 else name)}]; "
                     f"{ids[site]} -> tau{joint};")
    return "\n".join(lines) + "\n}\n"


def network_dot(graph, layout, net, name: str) -> str:
    """The network as a DOT digraph named `network`."""
    if layout.grouped:
        sites = vamp_sites(graph, layout)
    else:                 # a budget: one cluster per pass its VAMPs serve (as the drawing has them)
        from vampc.report.network_drawing import _budget_sites
        from vampc.report.sites import Site
        sites = [Site(s.section, 0) for s in _budget_sites(graph, net)[0]]
    names = {**SECTION_NAMES, "both": "both passes"}
    lines = ["digraph network {", f"  label={quote(f'{name}: VAMP network ({layout.name})')};",
             "  rankdir=BT; newrank=true; node [fontsize=9]; edge [fontsize=7];"]
    by_site: dict = {}
    for v in net.vamps:
        by_site.setdefault(sites[v.index], []).append(v)
    for site in sorted(by_site):
        lines.append(f"  subgraph {quote('cluster_' + site.section + str(site.index))} {{")
        lines.append(f"    label={quote(f'{site.section} {site.index} ({names[site.section]})' if layout.grouped else f'VAMPs serving {names[site.section]}')};")
        for v in by_site[site]:
            ops = ", ".join(dict.fromkeys(f"{graph.nodes[s.node].name} {s.op.value}" for s in v.slots))
            lines.append(f"    v{v.index} [label={quote(f'VAMP {v.index}' + chr(10) + ops)}];")
        lines.append("  }")
    lines += [f"  b{b.index} [shape=square, label={quote(f'{b.stages} st.')}]; v{b.source} -> b{b.index};"
              for b in net.buffers]
    for p in net.ports:
        what = ", ".join(dict.fromkeys(e.key.label for e in p.entries)) or "program"
        lines.append(f"  p{p.index} [shape=invtriangle, label={quote(f'port {p.index}: {what}')}];")
    lines += [f"  k{c.index} [shape=box, style=dashed, label={quote(c.name)}];" for c in net.consts]
    lines += _network_edges(net)
    for o in net.outputs:
        lines.append(f"  tau{o.joint} [shape=house, label={quote(_output(graph, o.joint))}]; "
                     f"v{o.vamp} -> tau{o.joint};")
    return "\n".join(lines) + "\n}\n"


def _network_edges(net) -> list[str]:
    """One edge per wire into a multiplexer input (a matrix operand: one per column it reads, so
    one into an MM member's operand B, as the report's pins count: read_taps), labelled operand
    and input."""
    from vampc.network.bus import wired
    from vampc.report.processors import read_taps
    net = wired(net)             # a bus network: the wires it implements
    names = {"vamp": "v", "buffer": "b", "port": "p", "const": "k"}
    out = []
    for v in net.vamps:
        inputs = [f"A{k}" for k in range(len(v.a))] + [f"B{k}" for k in range(len(v.b))]
        for name, taps in zip(inputs, read_taps(v)):
            for tap in taps:
                label = name + (f" s{tap.stage}" if tap.kind is TapKind.BUFFER else "")
                out.append(f"  {names[tap.kind]}{tap.index} -> v{v.index} [label={quote(label)}];")
    return out


def dataflow_dot(graph, name: str) -> str:
    """The dataflow graph as a DOT digraph named `dataflow`."""
    lines = ["digraph dataflow {", f"  label={quote(f'{name}: {graph.recursion} dataflow graph')};",
             "  rankdir=BT; newrank=true; node [fontsize=9];"]
    groups: dict = {}
    for nd in graph.nodes:
        if nd.op.is_compute:
            groups.setdefault((nd.section, nd.group), []).append(nd)
        else:
            shape = "plaintext" if nd.key else "box, style=dashed"
            lines.append(f"  n{nd.id} [shape={shape}, label={quote(nd.name)}];")
    for (section, group), nodes in groups.items():
        lines.append(f"  subgraph {quote(f'cluster_{section}{group}')} {{")
        lines.append(f"    label={quote(f'{section} {group} ({SECTION_NAMES[section]})')};")
        lines += [f"    n{nd.id} [label={quote(nd.name + chr(10) + nd.op.value)}];" for nd in nodes]
        lines.append("  }")
    for nd in graph.nodes:
        lines += [f"  n{a} -> n{nd.id};" for a in nd.args]
    for o in graph.outputs:
        lines.append(f"  tau{o.joint} [shape=house, label={quote(_output(graph, o.joint))}]; "
                     f"n{o.node} -> tau{o.joint};")
    return "\n".join(lines) + "\n}\n"


def _output(graph, j: int) -> str:
    """Output j's label: τj, or past the joints a floating base's wrench component, named as the
    torque file's column and the network drawing name it (the DOT had τ13..τ18 on a 12-joint
    quadruped: an audit's)."""
    if j > graph.n:
        from vampc.emulator.trajectory import WRENCH_COLUMNS
        return WRENCH_COLUMNS[j - graph.n - 1]
    return f"τ{j}"
