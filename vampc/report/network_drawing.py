"""The network drawing (`vampc report --network FILE.svg`): recursion nodes as circles placed as in
Figures III.1, IV.2 and VI.3 (the rectilinear array: joints or prefix positions across, the
backward pass's tiers upwards, then the non-propagated variables, then the forward pass's tiers),
or — for a folded layout — its device nodes (Figure VI.1); vector buses between them as lines, the
delay buffers on a bus as a square labelled with its stages, host ports along the bottom edge and
the torque outputs along the top.

Ids in the SVG: `site-<section>-<index>` (circles), `buffer-<from>-<to>` (squares), `port-<index>`,
`tau-<joint>`, each with a <title>; the lines of each kind are one path, `wires-<kind>`. A kind with
more than DETAIL shapes is drawn as one path, `sites-<section>`, `buffers`, `ports`, `outputs`,
without ids or labels.

A drawing more than MAX_COLS cells across (a 512-joint log network has 513 positions) aggregates:
each row's nodes are grouped by MAX_COLS-th of the positions, every group one circle labelled with
its positions and node count, buses and buffers summed between groups (those within a group named in
its tooltip), a port marker and an output marker per group. Its cells shrink so that the drawing
stays under about 2 000 px (MAX_PT) on its long side. Sites holding an op of the critical path are
outlined in red, aggregated or not.
"""
from __future__ import annotations

from collections import Counter
from dataclasses import dataclass
from typing import NamedTuple

from vampc.kinds import Recursion, Section, TapKind, unhandled
from vampc.memo import keep_last
from vampc.report import svg
from vampc.report.sites import SECTION_NAMES, Site, node_table, vamp_sites
from vampc.schedule.registry import SYSTOLIC, is_layout

COLOURS = {"bwd": "#c6dbef", "npv": "#e5f5e0", "fwd": "#fdd0a2", "both": "#dadaeb"}
NAMES = {**SECTION_NAMES, "both": "both passes"}
CELL_PX, MARGIN_PX = 78, 80
MIN_COLS = 7
DETAIL = 600          # shapes of one kind drawn one by one (ids, titles, labels) up to this many
PER_CELL = 8          # output markers of one node at most; more get one marker together
MAX_COLS = 16         # cells across; beyond, positions are grouped (see the module docstring)
MAX_PT = 1500         # the long side at most (cells shrink to fit), about 2 000 px


FLOW_WORDS = {"within_backward": "within backward", "backward_to_forward": "backward to forward",
              "within_forward": "within forward"}
FLOW_ORDER = {f: k for k, f in enumerate(FLOW_WORDS)}


@dataclass(frozen=True)
class Drawing:
    """What the picture shows, before any drawing: sites with their grid place, label and VAMPs;
    buses between sites (direct taps and buffered ones with their stages); ports and outputs."""

    places: dict               # Site -> (x, y) grid cell
    labels: dict               # Site -> text
    vamps: Counter             # Site -> VAMPs
    buses: dict                # (from Site, to Site) -> vector buses read straight off a Result
    buffered: dict             # (from Site, to Site) -> (buses, deepest stage, Counter of chains by flow)
    ports: list                # (port index, [Site], label)
    outputs: list              # (joint, Site)
    rows: int
    cols: int
    critical: frozenset = frozenset()   # sites holding an op of the critical path
    grouped: int = 1           # positions per cell (1: every node drawn)
    inside: dict | None = None  # aggregated: site -> (nodes, buses within, positions "a–b")
    budget: bool = False       # a budget's VAMPs, by pass (vampc.report.network_drawing._budget_sites)
    first: int = 0             # a focused drawing: the position its left edge shows, less one
    joints: int = 0            # outputs past this many are a floating base's wrench (0: none known)

    def name(self, site) -> str:
        """A site's name as its circle shows it (its label's first line: 'bwd dev 0' on a folded
        layout, where the tooltips had said 'bwd 0': a new user's find), else its own label."""
        text = self.labels.get(site)
        return text.split("\n")[0] if text else site.label

    def output_name(self, j: int) -> str:
        """Output j's label: τj, or the base wrench's component (the torque file's column)."""
        if self.joints and j > self.joints:
            from vampc.emulator.trajectory import WRENCH_COLUMNS
            return WRENCH_COLUMNS[j - self.joints - 1]
        return f"τ{j}"


def drawing(graph, layout, net, critical_path=(), focus: tuple[int, int] | None = None) -> Drawing:
    """The drawing's content for a compiled graph, layout and network; `critical_path`: the
    schedule's critical path (node ids), whose sites are outlined; `focus`: (A, B), only the nodes
    at positions A to B (1-based, inclusive), with the buses among them."""
    return _drawing(graph, layout, net, tuple(critical_path), focus)


@keep_last()          # the last drawing made: the DOT of a big network asks for the same one
def _drawing(graph, layout, net, critical_path, focus) -> Drawing:
    from vampc.network.bus import wired
    from vampc.report.processors import read_taps
    net = wired(net)             # a bus network: the wires it implements
    if layout.grouped:
        sites = vamp_sites(graph, layout)
        places, labels = _places(graph, layout, sorted(set(sites)))
    else:
        sites, places, labels = _budget_sites(graph, net)
    vamps = Counter(sites)
    buses: Counter = Counter()
    buffered: dict = {}
    chains_of: dict = {}
    readers_of_port: dict[int, list] = {}
    for v in net.vamps:
        here = sites[v.index]
        for taps in read_taps(v):        # (an MM member's operand B: the one column it reads)
            for tap in taps:
                match tap.kind:
                    case TapKind.VAMP:
                        buses[(sites[tap.index], here)] += 1
                    case TapKind.BUFFER:
                        key = (sites[net.buffers[tap.index].source], here)
                        got = buffered.get(key, (0, 0))
                        buffered[key] = (got[0] + 1, max(got[1], tap.stage))
                        chains_of.setdefault(key, set()).add(tap.index)
                    case TapKind.PORT:
                        readers_of_port.setdefault(tap.index, [])
                        if here not in readers_of_port[tap.index]:
                            readers_of_port[tap.index].append(here)
                    case TapKind.CONST:     # constant buffers are not drawn
                        pass
                    case other:
                        unhandled(other)
    from vampc.report.wiring import buffer_flows
    flows = buffer_flows(graph, net) if buffered else {}
    buffered = {k: (n, deep, Counter(flows.get(i, "within_backward") for i in chains_of[k]))
                for k, (n, deep) in buffered.items()}
    ports = [(p.index, readers_of_port.get(p.index, []), _port_label(p)) for p in net.ports]
    outputs = [(o.joint, sites[o.vamp]) for o in net.outputs]
    low = min(x for x, _ in places.values())
    if low:          # (a floating base's node 0 was placed at -1: outside the plot, clipped)
        places = {s: (x - low, y) for s, (x, y) in places.items()}
    xs = [x for x, _ in places.values()]
    ys = [y for _, y in places.values()]
    on_path = set(critical_path)
    critical = frozenset(sites[v.index] for v in net.vamps if any(sl.node in on_path for sl in v.slots))
    d = Drawing(places, labels, vamps, dict(buses), buffered, ports, outputs, max(ys) + 1, max(xs) + 1,
                critical, budget=not layout.grouped, joints=graph.n)
    if focus is not None:
        if isinstance(focus[0], str):                     # a node: the positions around it
            from vampc.errors import VampcUsageError
            site = next((s for s in d.places if (s.section, s.index) == focus), None)
            if site is None:     # (what it has, said: "bwd dev 0" on a systolic drawing was "no
                # node 0 in section bwd", whose nodes run from 1: a new user's find)
                have = sorted({s.index for s in d.places if s.section == focus[0]})
                names = {s.section: d.name(s).rsplit(" ", 1)[0] for s in d.places}
                there = (f"its nodes there: {names[focus[0]]} {have[0]} to {have[-1]}"
                         if len(have) > 1 else f"its one node there: {names[focus[0]]} {have[0]}"
                         if have else f"its sections: {', '.join(sorted(names))}")
                raise VampcUsageError(f"--focus: this drawing has no node {focus[1]} in section "
                                      f"{focus[0]} ({there})")
            x = d.places[site][0] + 1
            # 16 positions around it, within the drawing (a range made here, not typed: no warning
            # about positions the user never named)
            focus = (max(1, x - MAX_COLS // 2), min(d.cols, x + MAX_COLS // 2 - 1))
        d = focused(d, *focus)
    return aggregate(d) if d.cols > MAX_COLS else d


def focused(d: Drawing, first: int, last: int) -> Drawing:
    """Only the sites at positions first..last (1-based), moved to the left edge; VampcUsageError
    when there are none."""
    from vampc.errors import VampcUsageError
    if first > d.cols:
        raise VampcUsageError(f"--focus {first}:{last}: no node there (positions 1 to {d.cols})")
    if last > d.cols:
        import warnings

        from vampc.errors import VampcWarning
        warnings.warn(VampcWarning(f"--focus {first}:{last}: the network has positions 1 to {d.cols}; "
                                   f"drawing {first}:{d.cols}"))
    keep = {s for s, (x, _) in d.places.items() if first - 1 <= x <= last - 1}
    low = min(d.places[s][0] for s in keep)
    places = {s: (d.places[s][0] - low, d.places[s][1]) for s in keep}
    pick = lambda table: {k: v for k, v in table.items() if k[0] in keep and k[1] in keep}
    ports = [(i, [r for r in readers if r in keep], label) for i, readers, label in d.ports
             if any(r in keep for r in readers)]
    return Drawing(places, {s: d.labels[s] for s in keep}, Counter({s: d.vamps[s] for s in keep}),
                   pick(d.buses), pick(d.buffered), ports, [(j, s) for j, s in d.outputs if s in keep],
                   max(y for _, y in places.values()) + 1, max(x for x, _ in places.values()) + 1,
                   frozenset(d.critical & keep), first=low, joints=d.joints)


class Group(NamedTuple):
    """An aggregated cell: the nodes of one row over a range of positions (what Site is for one)."""

    section: str
    index: int                 # the group's column
    row: int

    @property
    def label(self) -> str:
        return f"{self.section} group {self.index} (row {self.row})"


def aggregate(d: Drawing) -> Drawing:
    """The drawing with each row's nodes grouped by ⌈cols / MAX_COLS⌉ positions (see the module
    docstring)."""
    per = -(-d.cols // MAX_COLS)
    group = {s: Group(s.section, x // per, y) for s, (x, y) in d.places.items()}
    places = {g: (g.index, g.row) for g in group.values()}
    members: dict = {}
    for s, g in group.items():
        members.setdefault(g, []).append(s)
    vamps: Counter = Counter()
    for s, g in group.items():
        vamps[g] += d.vamps[s]
    buses: Counter = Counter()
    within: Counter = Counter()
    for (a, b), k in d.buses.items():
        if group[a] == group[b]:
            within[group[a]] += k
        else:
            buses[(group[a], group[b])] += k
    buffered: dict = {}
    for (a, b), (n, deep, chains) in d.buffered.items():
        key = (group[a], group[b])
        got = buffered.get(key, (0, 0, Counter()))
        buffered[key] = (got[0] + n, max(got[1], deep), got[2] + chains)
    inside, labels = {}, {}
    for g, ss in members.items():
        xs = sorted(d.places[s][0] + d.first for s in ss)
        span = f"{xs[0] + 1}–{xs[-1] + 1}" if xs[0] != xs[-1] else f"{xs[0] + 1}"
        inside[g] = (len(ss), within[g], span)
        labels[g] = f"{g.section} ×{len(ss)}\npos {span}"
    ports: dict = {}
    for index, readers, label in d.ports:
        if readers:
            key = group[readers[0]]
            got = ports.get(key, (index, set(), 0))
            ports[key] = (got[0], got[1] | {group[r] for r in readers}, got[2] + 1)
    port_list = [(index, sorted(readers), f"{count} port{'s' * (count > 1)}")
                 for key, (index, readers, count) in sorted(ports.items())]
    outs: dict = {}
    for joint, site in d.outputs:
        outs.setdefault(group[site], []).append(joint)
    outputs = [(min(js), g) for g, js in sorted(outs.items())]
    return Drawing(places, labels, vamps, dict(buses), buffered, port_list, outputs, d.rows,
                   -(-d.cols // per), frozenset(group[s] for s in d.critical), per,
                   {**inside, "_outputs": {g: sorted(js) for g, js in outs.items()}}, joints=d.joints)


def _budget_sites(graph, net):
    """A budgeted layout's VAMPs as the program has them: each VAMP its own circle, in a row by the
    passes its ops belong to (backward, with the non-propagated values; both passes; forward), so a
    VAMP serving both is drawn as such. (sites per VAMP, places, labels)."""
    from vampc.kinds import Pass
    from vampc.report.sites import Site
    rows = {"bwd": 0, "both": 1, "fwd": 2}
    sites = []
    for v in net.vamps:
        passes = {Pass.of(graph.nodes[s.node].section) for s in v.slots}
        sites.append(Site("both" if len(passes) > 1 else
                          ("fwd" if passes == {Pass.FORWARD} else "bwd"), v.index))
    present = sorted({s.section for s in sites}, key=rows.get)
    row = {sec: k for k, sec in enumerate(present)}
    seen: Counter = Counter()
    places, labels = {}, {}
    for v, site in zip(net.vamps, sites):
        places[site] = (seen[site.section], row[site.section])
        seen[site.section] += 1
        labels[site] = f"VAMP {v.index}\n{len(v.slots)} ops"
    return sites, places, labels


def _port_label(p) -> str:
    """'A3', 'zqd2 +5' (a folded port carries a quantity for every joint), 'program'."""
    names = list(dict.fromkeys(e.key.label for e in p.entries))
    if not names:
        return "program"
    return names[0] + (f" +{len(names) - 1}" if len(names) > 1 else "")


def _places(graph, layout, sites: list[Site]) -> tuple[dict, dict]:
    """Grid cell and label of every site (see the module docstring)."""
    if not is_layout(layout.name, SYSTOLIC):
        row = {"bwd": 0, "npv": 1, "fwd": 2}
        return ({s: (s.index, row[s.section]) for s in sites},
                {s: f"{s.section} dev {s.index}" for s in sites})
    match graph.recursion:
        case Recursion.LINEAR:
            row = {"bwd": 0, "npv": 1, "fwd": 2}
            last = _subtree_ends(graph)
            name = {"bwd": lambda i: f"(0,{i})", "npv": lambda i: "r̈ F N",
                    "fwd": lambda i: f"({i},{last.get(i, i)})"}
            return ({s: (s.index - 1, row[s.section]) for s in sites},
                    {s: f"{s.section} {s.index}\n{name[s.section](s.index)}" for s in sites})
        case Recursion.LOG:
            return _log_places(graph, sites)
        case other:
            return unhandled(other)


def _subtree_ends(graph) -> dict[int, int]:
    """Per joint i of a linear graph: the last joint of its subtree (n for a chain; a leg's last
    joint in a tree, whose joints are numbered depth-first), read off the forward pass's edges (a
    forward node reads its children's)."""
    children: dict[int, set] = {}
    for nd in graph.compute_nodes():
        if nd.section == "fwd":
            for a in nd.args:
                src = graph.nodes[a]
                if src.op.is_compute and src.section == "fwd" and src.group not in (nd.group, 0):
                    children.setdefault(nd.group, set()).add(src.group)
    last: dict[int, int] = {}
    for i in range(graph.n, 0, -1):
        last[i] = max([i] + [last[c] for c in children.get(i, ()) if c > i])
    return last


def _log_places(graph, sites: list[Site]) -> tuple[dict, dict]:
    """Grid cells and labels of a log graph's systolic sites: recursion nodes by tier."""
    table = node_table(graph)
    info = {(sec, r[0]): r for sec, rows in table.items() for r in rows}
    tiers = max((r[4] for r in table["bwd"]), default=0)
    first = min((r[1] for r in table["bwd"]), default=1)
    places, labels = {}, {}
    for s in sites:
        match s.section:
            case Section.NPV:
                places[s] = (s.index - first, tiers + 1)
                labels[s] = f"npv {s.index}\nr̈ F N"
            case Section.BWD | Section.FWD:
                _, a, _, b, tier = info[(s.section, s.index)]
                places[s] = ((b - first, tier) if s.section is Section.BWD
                             else (a - first, tiers + 2 + tier))
                labels[s] = f"{s.section} {s.index}\n({a},{b})"
            case other:
                unhandled(other)
    return places, labels


def network_svg(graph, layout, net, title: str, critical_path=(), focus=None) -> str:
    """The drawing as SVG text (`focus`: (A, B), positions A to B only)."""
    d = drawing(graph, layout, net, critical_path, focus)
    if focus is not None and isinstance(focus[0], int):     # B beyond the last position: up to it
        title += f" — positions {focus[0]} to {min(focus[1], focus[0] - 1 + d.cols * d.grouped)} only"
    elif focus is not None:
        title += f" — around node {focus[0]} {focus[1]}"
    with svg.settings():
        return _draw(d, title)


def _xy(d: Drawing, site: Site) -> tuple[float, float]:
    """The centre of a site's cell (the row above the ports)."""
    x, y = d.places[site]
    return x + 0.5, y + 1.0


def _draw(d: Drawing, title: str) -> str:
    """The figure: buses, buffers, nodes, ports, outputs, title and key."""
    span = d.rows + 1.6                   # y units: ports below row 0, outputs above the last
    cols = max(d.cols, MIN_COLS)          # room for the title and the key
    cell = min(CELL_PX, (MAX_PT - 2 * MARGIN_PX) / max(cols, span))
    width = MARGIN_PX * 2 + cols * cell
    height = MARGIN_PX * 2 + span * cell
    fig = svg.figure(width, height)
    ax = fig.add_axes((MARGIN_PX / width, MARGIN_PX / height, cols * cell / width,
                       span * cell / height))
    ax.set_xlim(0, cols)
    ax.set_ylim(-0.3, d.rows + 1.3)
    ax.set_axis_off()
    titles: dict[str, str] = {}
    by_width: dict[float, list] = {}
    for (a, b), k in d.buses.items():
        if a != b:
            by_width.setdefault(min(0.4 + 0.4 * (k // 3), 3.0), []).append(_bus_line(d, a, b))
    for w, segments in sorted(by_width.items()):
        _lines(ax, segments, f"wires-buses-{w:g}", "#555555", w, 1)
    _buffers(ax, d, titles)
    _sites(ax, d, titles)
    _ports(ax, d, titles, cell)
    _outputs(ax, d, titles)
    if d.grouped > 1:
        title += (f" — {sum(i[0] for k, i in d.inside.items() if k != '_outputs'):,} nodes in "
                  f"groups of {d.grouped} positions (--focus A:B with at most {MAX_COLS} positions "
                  "draws them node by node)")
    ax.set_title(title.replace(": ", ":\n", 1), loc="left", fontsize=9, pad=26)
    fig.text(MARGIN_PX / width, 8 / height,
             ("circles: groups of nodes (×: nodes, pos: positions, V: VAMPs)" if d.grouped > 1 else
              "circles: VAMPs of a budget, in rows by pass (blue: backward, with the non-propagated "
              "values; purple: both passes; orange: forward)" if any(s.section == "both" for s in d.labels)
              or d.budget else "circles: recursion or device nodes (V: VAMPs)")
             + "; red outline: on the critical path\nlines: vector buses (wider: more)\n"
             "squares: delay buffers (deepest stage)\nbottom: host ports; top: torques τ_i"
             + (" and the floating base's wrench (base_fx..base_nz)" if d.joints and any(
                 js[-1] > d.joints for _, js, _ in _output_markers(d)) else ""),
             fontsize=6.5, va="bottom")
    return svg.to_svg(fig, titles)


def _output_markers(d: Drawing) -> list[tuple[int, list, object]]:
    """The output markers, as (first output, its outputs in order, site), by first output: one an
    output, but one for all of a node's past PER_CELL (a folded device gives every torque: 16
    markers and labels in one cell overlapped) and one an aggregated group."""
    if d.grouped > 1:
        entries = [(joint, d.inside["_outputs"][site], site) for joint, site in d.outputs]
    else:
        by_site: dict = {}
        for joint, site in sorted(d.outputs, key=lambda o: o[0]):
            by_site.setdefault(site, []).append(joint)
        entries = []
        for site, js in by_site.items():
            entries += [(js[0], js, site)] if len(js) > PER_CELL else [(j, [j], site) for j in js]
    return sorted(entries, key=lambda e: e[0])


ARC_RISE = 0.8      # a same-row bus past its neighbours: its curve's control point, rows above


def _bus_line(d: Drawing, a, b) -> list:
    """A bus as a segment [start, end], or, between two nodes of one row with others between them
    (a tree's bus from a node to a child further along: torso's bwd 1 to bwd 6), a curve [start,
    control, end] rising ARC_RISE / 2 rows over them at its top: drawn straight, it ran behind
    the nodes between, and the tree looked a chain (a new user's find)."""
    (x0, y0), (x1, y1) = _xy(d, a), _xy(d, b)
    if y0 != y1 or abs(x1 - x0) <= 1.0:
        return [(x0, y0), (x1, y1)]
    return [(x0, y0), ((x0 + x1) / 2, y0 + ARC_RISE), (x1, y1)]


def _lines(ax, segments, gid: str, colour: str, width: float, zorder: int) -> None:
    """Line segments as one SVG path (one element however many: a big drawing has thousands); a
    segment of three points is a quadratic curve through its middle one's pull."""
    from matplotlib.patches import PathPatch
    from matplotlib.path import Path
    if not segments:
        return
    verts = [p for seg in segments for p in seg]
    codes = [c for seg in segments for c in ([Path.MOVETO, Path.LINETO] if len(seg) == 2 else
                                             [Path.MOVETO, Path.CURVE3, Path.CURVE3])]
    patch = PathPatch(Path(verts, codes), facecolor="none", edgecolor=colour, linewidth=width,
                      zorder=zorder)
    patch.set_gid(gid)
    ax.add_artist(patch)


@dataclass(frozen=True)
class Shape:
    """One marker: `kind` circle, square, triangle (pointing up) or triangle-down; its centre and
    size (radius or half side), and its SVG id and title."""

    kind: str
    x: float
    y: float
    size: float
    gid: str
    title: str


def _unit_path(kind: str):
    """A marker's outline around the origin, radius or half side 1."""
    from matplotlib.path import Path
    if kind == "circle":
        return Path.unit_circle()
    if kind == "square":
        return Path([(-1, -1), (1, -1), (1, 1), (-1, 1), (-1, -1)],
                    [Path.MOVETO, Path.LINETO, Path.LINETO, Path.LINETO, Path.CLOSEPOLY])
    up = Path.unit_regular_polygon(3)
    return up if kind == "triangle" else Path(up.vertices * [1, -1], up.codes)


def _shapes(ax, shapes: list[Shape], gid: str, style: dict, titles: dict) -> bool:
    """Markers, each its own SVG group with an id and a title when there are at most DETAIL of
    them; else one compound path (a 512-joint drawing has thousands). Returns whether they were
    drawn one by one (and so whether labels fit)."""
    import numpy as np
    from matplotlib.patches import PathPatch
    from matplotlib.path import Path
    if not shapes:
        return True
    unit = _unit_path(shapes[0].kind)
    if len(shapes) <= DETAIL:
        for sh in shapes:
            patch = PathPatch(Path(unit.vertices * sh.size + (sh.x, sh.y), unit.codes), **style)
            patch.set_gid(sh.gid)
            ax.add_artist(patch)
            titles[sh.gid] = sh.title
        return True
    centres = np.array([(sh.x, sh.y) for sh in shapes])
    sizes = np.array([sh.size for sh in shapes])[:, None, None]
    verts = (unit.vertices[None, :, :] * sizes + centres[:, None, :]).reshape(-1, 2)
    patch = PathPatch(Path(verts, np.tile(unit.codes, len(shapes))), **style)
    patch.set_gid(gid)
    ax.add_artist(patch)
    return False


def _sites(ax, d: Drawing, titles: dict) -> None:
    """The nodes as circles coloured by section, labelled (a, b) and VAMPs when few enough."""
    def title(site, label) -> str:
        if d.grouped == 1:
            return (f"{NAMES[site.section]} node {label.replace(chr(10), ' ')}: "
                    f"{d.vamps[site]} VAMPs")
        nodes, within, span = d.inside[site]
        return (f"{NAMES[site.section]} nodes at positions {span} (row {site.row}): {nodes} "
                f"nodes, {d.vamps[site]} VAMPs, {within} vector buses among them")
    gid = (lambda site: f"site-{site.section}-{site.index}") if d.grouped == 1 else \
        (lambda site: f"group-{site.section}-{site.row}-{site.index}")
    shapes = [Shape("circle", *_xy(d, site), 0.32, gid(site), title(site, label)
                    + ("; on the critical path" if site in d.critical else ""))
              for site, label in d.labels.items()]
    for section in NAMES:
        for on in (False, True):
            mine = [sh for sh, site in zip(shapes, d.labels)
                    if site.section == section and (site in d.critical) == on]
            style = {"facecolor": COLOURS[section], "edgecolor": "#d62728" if on else "#333333",
                     "linewidth": 1.4 if on else 0.6, "zorder": 3}
            if _shapes(ax, mine, f"sites-{section}" + ("-critical" if on else ""), style, titles):
                for sh, (site, label) in zip(shapes, d.labels.items()):
                    if site.section == section and (site in d.critical) == on:
                        ax.text(sh.x, sh.y, f"{label}\n{d.vamps[site]} V", fontsize=5.5,
                                ha="center", va="center", zorder=4)


def _free_spot(x: float, y: float, dx: float, dy: float, taken: list, circles: list,
               right: float = float("inf")) -> tuple:
    """Where a buffer square (half side 0.11 cells) goes near (x, y): there, or moved across the bus
    (direction dx, dy) until it meets neither another square nor a node's circle."""
    import math
    norm = math.hypot(dx, dy) or 1.0
    px, py = -dy / norm, dx / norm                        # across the bus
    ux, uy = dx / norm, dy / norm                         # along it
    tries = sorted(((k, m) for k in range(-6, 7) for m in (-2, -1, 0, 1, 2)),
                   key=lambda km: (abs(km[0]) + abs(km[1]), km[1] != 0, -km[0]))
    for k, m in tries:
        cx = x + 0.24 * k * px + 0.2 * m * ux
        cy = y + 0.24 * k * py + 0.2 * m * uy
        if 0.12 <= cx <= right - 0.12 and all(abs(cx - a) >= 0.23 or abs(cy - b) >= 0.23 for a, b in taken) \
                and all(math.hypot(cx - a, cy - b) >= 0.32 + 0.16 for a, b in circles):
            return cx, cy
    return x, y


def _buffers(ax, d: Drawing, titles: dict) -> None:
    """A square on each buffered bus (a node's own feedback beside it), labelled its deepest stage;
    squares are moved across their bus so that none covers another or a node."""
    shapes, segments = [], []
    taken: list = []
    circles = [_xy(d, s) for s in d.places] if len(d.buffered) <= DETAIL else []
    seen: dict[str, int] = {}
    for (a, b), (buses, deepest, chains) in sorted(d.buffered.items()):
        (xa, ya), (xb, yb) = _xy(d, a), _xy(d, b)
        if a == b:                                        # feedback within a node or device
            x, y, dx, dy = xa + 0.42, ya + 0.38, 0.0, 1.0
        else:
            x, y, dx, dy = xa + 0.55 * (xb - xa), ya + 0.55 * (yb - ya), xb - xa, yb - ya
        if circles:
            x, y = _free_spot(x, y, dx, dy, taken, circles, max(d.cols, MIN_COLS))
            taken.append((x, y))
        segments += [[(xa, ya), (x, y)], [(x, y), (xb, yb)]]
        count = sum(chains.values())
        # (by the flow of the values they hold, as the buffering table counts them: a forward
        # node's VAMP holding values computed ahead from backward results is backward to forward
        # there; the table and this picture had seemed to disagree: a new user's find)
        flows = ", ".join(f"{k} {FLOW_WORDS[f]}" for f, k in sorted(chains.items(), key=lambda fk: FLOW_ORDER[fk[0]]))
        name = f"buffer-{a.section}{a.index}-{b.section}{b.index}"
        seen[name] = seen.get(name, 0) + 1      # (a grouped drawing's sites share section and
        if seen[name] > 1:                      # index across rows: one id each, not one for all)
            name += f"-{seen[name]}"
        shapes.append(Shape("square", x, y, 0.11, name,
                            f"delay buffers from {d.name(a)} to {d.name(b)}: {count} chain{'s' * (count != 1)}, "
                            f"{buses} tap{'s' * (buses != 1)}, up to stage {deepest}; the buffering "
                            f"table counts these chains as {flows} (a chain read at several sites is "
                            "drawn at each, and counted once there)"))
    _lines(ax, segments, "wires-buffered", "#8c6d31", 0.6, 1)
    style = {"facecolor": "#fff7bc", "edgecolor": "#8c6d31", "linewidth": 0.6, "zorder": 2}
    if _shapes(ax, shapes, "buffers", style, titles):
        for sh, (_, deepest, _) in zip(shapes, (v for _, v in sorted(d.buffered.items()))):
            ax.text(sh.x, sh.y, str(deepest), fontsize=5, ha="center", va="center", zorder=3)


PORT_LABEL_PT = 4.5        # the least room a port's label (4-point text, turned upright) is given


def _ports(ax, d: Drawing, titles: dict, cell: float) -> None:
    """Host ports along the bottom edge, a thin line to each node that reads them: up to four under
    a column 0.2 apart, more spread over its cell (each port where it can be seen: the fifth had
    been drawn on the first, a new user's find), labelled where a label has room (`cell` points a
    unit), each named in its tooltip."""
    column = Counter(round(_xy(d, readers[0])[0], 3) for _, readers, _ in d.ports if readers)
    stack: Counter = Counter()
    shapes, segments, labels = [], [], []
    for index, readers, label in d.ports:
        if not readers:
            continue
        x, _ = _xy(d, readers[0])
        k, per = stack[round(x, 3)], column[round(x, 3)]
        stack[round(x, 3)] += 1
        # more than four: spread over ±0.4 of the column's centre, each triangle (√3 × its size
        # wide) within 90% of its step and of the 0.2 left to the next column's (a review found
        # neighbours overlapping where they were spread over ±0.45 at full size)
        step = 0.2 if per <= 4 else 0.8 / (per - 1)
        px, py = (x - 0.3 + 0.2 * k if per <= 4 else x - 0.4 + step * k), 0.1
        size = 0.09 if per <= 4 else min(0.09, 0.9 * min(step, 0.2) / 3 ** 0.5)
        shapes.append(Shape("triangle", px, py, size, f"port-{index}", f"host port {index}: {label}, "
                            "read by " + ", ".join(d.name(r) for r in readers)))
        segments += [[(px, py), _xy(d, r)] for r in readers]
        if per <= 4 or step * cell >= PORT_LABEL_PT:
            labels.append((px, py - 0.16, label))
    _lines(ax, segments, "wires-ports", "#bbbbbb", 0.3, 0)
    style = {"facecolor": "#ffffff", "edgecolor": "#333333", "linewidth": 0.5, "zorder": 3}
    if _shapes(ax, shapes, "ports", style, titles):
        for x, y, text in labels:
            ax.text(x, y, text, fontsize=4, ha="center", va="top", rotation=90)


def _outputs(ax, d: Drawing, titles: dict) -> None:
    """Torque outputs along the top edge, one column's spread over its cell (several nodes of one
    column can give torques: the log recursion's forward tiers, a folded device); a node giving more
    than PER_CELL, and an aggregated group, get one marker for all of theirs."""
    top = d.rows + 1.0
    name = d.output_name
    entries = _output_markers(d)
    column = Counter(round(_xy(d, site)[0], 3) for _, _, site in entries)
    shown: Counter = Counter()
    shapes, segments, texts = [], [], []
    for joint, js, site in entries:
        x, y = _xy(d, site)
        key = round(x, 3)
        k, per = shown[key], column[key]
        shown[key] += 1
        ox = x + (k - (per - 1) / 2) * min(0.25, 0.9 / per)
        if len(js) == 1:
            shapes.append(Shape("triangle-down", ox, top, 0.1, f"tau-{joint}", f"{name(joint)} leaves "
                                f"{d.name(site)}"))
            texts.append(name(joint))
        else:
            # a range only where the outputs run without a gap ('τ1–64' had labelled 3 torques,
            # τ1, τ33 and τ64): else how many, each named in the tooltip
            running = js == list(range(js[0], js[-1] + 1))
            listed = ", ".join(name(j) for j in js[:40]) + (", …" if len(js) > 40 else "")
            shapes.append(Shape("triangle-down", ox, top, 0.1, f"tau-{joint}",
                                (f"{name(js[0])}–{name(js[-1])}" if running else listed)
                                + f" ({len(js)} outputs) leave {d.name(site)}"))
            texts.append(f"{name(js[0])}–{name(js[-1])}" if running else f"{len(js)} outputs")
        segments.append([(x, y), (ox, top)])
    _lines(ax, segments, "wires-outputs", "#d94801", 0.4, 0)
    style = {"facecolor": "#fcbba1", "edgecolor": "#333333", "linewidth": 0.5, "zorder": 3}
    if _shapes(ax, shapes, "outputs", style, titles):
        # labels upright when they fit their spacing, else turned up (still one per marker)
        for sh, text in zip(shapes, texts):
            ax.text(sh.x, sh.y + 0.13, text, fontsize=5, ha="center", va="bottom",
                    rotation=90 if any(column[c] > 1 for c in column) else 0)
