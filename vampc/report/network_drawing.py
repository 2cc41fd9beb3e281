"""The network drawing (`vampc report --network FILE.svg`): recursion nodes as circles placed as in
Figures III.1, IV.2 and VI.3 (the rectilinear array: joints or prefix positions across, the
backward pass's tiers upwards, then the non-propagated variables, then the forward pass's tiers),
or — for a folded layout — its device nodes (Figure VI.1); vector buses between them as lines, the
delay buffers on a bus as a square labelled with its stages, host ports along the bottom edge and
the torque outputs along the top.

Ids in the SVG: `site-<section>-<index>` (circles), `buffer-<from>-<to>` (squares), `port-<index>`,
`tau-<joint>`, each with a <title>; the lines of each kind are one path, `wires-<kind>`. A kind with
more than DETAIL shapes (a 512-joint log network has thousands of nodes) is drawn as one path,
`sites-<section>`, `buffers`, `ports`, `outputs`, without ids or labels.
"""
from __future__ import annotations

from collections import Counter
from dataclasses import dataclass

from vampc.kinds import Recursion, Section, TapKind, unhandled
from vampc.report import svg
from vampc.report.sites import SECTION_NAMES, Site, node_table, vamp_sites
from vampc.schedule.registry import SYSTOLIC, is_layout

COLOURS = {"bwd": "#c6dbef", "npv": "#e5f5e0", "fwd": "#fdd0a2"}
CELL_PX, MARGIN_PX = 78, 80
MIN_COLS = 7
DETAIL = 600          # shapes of one kind drawn one by one (ids, titles, labels) up to this many


@dataclass(frozen=True)
class Drawing:
    """What the picture shows, before any drawing: sites with their grid place, label and VAMPs;
    buses between sites (direct taps and buffered ones with their stages); ports and outputs."""

    places: dict               # Site -> (x, y) grid cell
    labels: dict               # Site -> text
    vamps: Counter             # Site -> VAMPs
    buses: dict                # (from Site, to Site) -> vector buses read straight off a Result
    buffered: dict             # (from Site, to Site) -> (buses, deepest stage, chains)
    ports: list                # (port index, [Site], label)
    outputs: list              # (joint, Site)
    rows: int
    cols: int


def drawing(graph, layout, net) -> Drawing:
    """The drawing's content for a compiled graph, layout and network."""
    sites = vamp_sites(graph, layout)
    places, labels = _places(graph, layout, sorted(set(sites)))
    vamps = Counter(sites)
    buses: Counter = Counter()
    buffered: dict = {}
    chains_of: dict = {}
    readers_of_port: dict[int, list] = {}
    for v in net.vamps:
        here = sites[v.index]
        for operand in v.a + v.b:
            for tap in operand.taps:
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
    buffered = {k: (n, deep, len(chains_of[k])) for k, (n, deep) in buffered.items()}
    ports = [(p.index, readers_of_port.get(p.index, []), _port_label(p)) for p in net.ports]
    outputs = [(o.joint, sites[o.vamp]) for o in net.outputs]
    xs = [x for x, _ in places.values()]
    ys = [y for _, y in places.values()]
    return Drawing(places, labels, vamps, dict(buses), buffered, ports, outputs,
                   max(ys) + 1, max(xs) + 1)


def _port_label(p) -> str:
    """'A3', 'zqd2 +5' (a folded port carries a quantity for every joint), 'program'."""
    names = list(dict.fromkeys(f"{e.key.quantity}{e.key.joint}" for e in p.entries))
    if not names:
        return "program"
    return names[0] + (f" +{len(names) - 1}" if len(names) > 1 else "")


def _places(graph, layout, sites: list[Site]) -> tuple[dict, dict]:
    """Grid cell and label of every site (see the module docstring)."""
    if not is_layout(layout.name, SYSTOLIC):
        row = {"bwd": 0, "npv": 1, "fwd": 2}
        return ({s: (s.index, row[s.section]) for s in sites},
                {s: f"{SECTION_NAMES[s.section]}\ndevice {s.index}" for s in sites})
    match graph.recursion:
        case Recursion.LINEAR:
            row = {"bwd": 0, "npv": 1, "fwd": 2}
            n = graph.n
            name = {"bwd": lambda i: f"(0,{i})", "npv": lambda i: f"r̈ F N {i}",
                    "fwd": lambda i: f"({i},{n})"}
            return ({s: (s.index - 1, row[s.section]) for s in sites},
                    {s: name[s.section](s.index) for s in sites})
        case Recursion.LOG:
            return _log_places(graph, sites)
        case other:
            return unhandled(other)


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
                labels[s] = f"r̈ F N {s.index}"
            case Section.BWD | Section.FWD:
                _, a, _, b, tier = info[(s.section, s.index)]
                places[s] = ((b - first, tier) if s.section is Section.BWD
                             else (a - first, tiers + 2 + tier))
                labels[s] = f"({a},{b})"
            case other:
                unhandled(other)
    return places, labels


def network_svg(graph, layout, net, title: str) -> str:
    """The drawing as SVG text."""
    d = drawing(graph, layout, net)
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
    width = MARGIN_PX * 2 + cols * CELL_PX
    height = MARGIN_PX * 2 + span * CELL_PX
    fig = svg.figure(width, height)
    ax = fig.add_axes((MARGIN_PX / width, MARGIN_PX / height, cols * CELL_PX / width,
                       span * CELL_PX / height))
    ax.set_xlim(0, cols)
    ax.set_ylim(-0.3, d.rows + 1.3)
    ax.set_axis_off()
    titles: dict[str, str] = {}
    by_width: dict[float, list] = {}
    for (a, b), k in d.buses.items():
        if a != b:
            by_width.setdefault(min(0.4 + 0.4 * (k // 3), 3.0), []).append([_xy(d, a), _xy(d, b)])
    for w, segments in sorted(by_width.items()):
        _lines(ax, segments, f"wires-buses-{w:g}", "#555555", w, 1)
    _buffers(ax, d, titles)
    _sites(ax, d, titles)
    _ports(ax, d, titles)
    _outputs(ax, d, titles)
    ax.set_title(title.replace(": ", ":\n", 1), loc="left", fontsize=9)
    fig.text(MARGIN_PX / width, 8 / height,
             "circles: recursion or device nodes (V: VAMPs)\nlines: vector buses (wider: more)\n"
             "squares: delay buffers (deepest stage)\nbottom: host ports; top: torques τ_i",
             fontsize=6.5, va="bottom")
    return svg.to_svg(fig, titles)


def _lines(ax, segments, gid: str, colour: str, width: float, zorder: int) -> None:
    """Line segments as one SVG path (one element however many: a big drawing has thousands)."""
    from matplotlib.patches import PathPatch
    from matplotlib.path import Path
    if not segments:
        return
    verts = [p for seg in segments for p in seg]
    codes = [Path.MOVETO, Path.LINETO] * len(segments)
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
    shapes = [Shape("circle", *_xy(d, site), 0.32, f"site-{site.section}-{site.index}",
                    f"{SECTION_NAMES[site.section]} node {label.replace(chr(10), ' ')}: "
                    f"{d.vamps[site]} VAMPs") for site, label in d.labels.items()]
    for section in SECTION_NAMES:
        mine = [sh for sh, site in zip(shapes, d.labels) if site.section == section]
        style = {"facecolor": COLOURS[section], "edgecolor": "#333333", "linewidth": 0.6,
                 "zorder": 3}
        if _shapes(ax, mine, f"sites-{section}", style, titles):
            for sh, (site, label) in zip(shapes, d.labels.items()):
                if site.section == section:
                    ax.text(sh.x, sh.y, f"{label}\n{d.vamps[site]} V", fontsize=5.5, ha="center",
                            va="center", zorder=4)


def _buffers(ax, d: Drawing, titles: dict) -> None:
    """A square on each buffered bus (a node's own feedback beside it), labelled its deepest stage."""
    shapes, segments = [], []
    for (a, b), (buses, deepest, chains) in sorted(d.buffered.items()):
        (xa, ya), (xb, yb) = _xy(d, a), _xy(d, b)
        if a == b:                                        # feedback within a node or device
            x, y = xa + 0.42, ya + 0.38
        else:
            x, y = xa + 0.55 * (xb - xa), ya + 0.55 * (yb - ya)
        segments += [[(xa, ya), (x, y)], [(x, y), (xb, yb)]]
        shapes.append(Shape("square", x, y, 0.11, f"buffer-{a.section}{a.index}-{b.section}{b.index}",
                            f"delay buffers from {a.label} to {b.label}: {chains} chains, {buses} "
                            f"taps, up to stage {deepest}"))
    _lines(ax, segments, "wires-buffered", "#8c6d31", 0.6, 1)
    style = {"facecolor": "#fff7bc", "edgecolor": "#8c6d31", "linewidth": 0.6, "zorder": 2}
    if _shapes(ax, shapes, "buffers", style, titles):
        for sh, (_, deepest, _) in zip(shapes, (v for _, v in sorted(d.buffered.items()))):
            ax.text(sh.x, sh.y, str(deepest), fontsize=5, ha="center", va="center", zorder=3)


def _ports(ax, d: Drawing, titles: dict) -> None:
    """Host ports along the bottom edge, a thin line to each node that reads them."""
    stack: Counter = Counter()
    shapes, segments, labels = [], [], []
    for index, readers, label in d.ports:
        if not readers:
            continue
        x, _ = _xy(d, readers[0])
        k = stack[round(x, 3)]
        stack[round(x, 3)] += 1
        px, py = x - 0.3 + 0.2 * (k % 4), 0.1
        shapes.append(Shape("triangle", px, py, 0.09, f"port-{index}", f"host port {index}: {label}, "
                            "read by " + ", ".join(r.label for r in readers)))
        segments += [[(px, py), _xy(d, r)] for r in readers]
        if k < 4:
            labels.append((px, py - 0.16, label))
    _lines(ax, segments, "wires-ports", "#bbbbbb", 0.3, 0)
    style = {"facecolor": "#ffffff", "edgecolor": "#333333", "linewidth": 0.5, "zorder": 3}
    if _shapes(ax, shapes, "ports", style, titles):
        for x, y, text in labels:
            ax.text(x, y, text, fontsize=4, ha="center", va="top", rotation=90)


def _outputs(ax, d: Drawing, titles: dict) -> None:
    """Torque outputs along the top edge, spread when one node gives several."""
    top = d.rows + 1.0
    shown: Counter = Counter()
    per = Counter(site for _, site in d.outputs)
    shapes, segments = [], []
    for joint, site in sorted(d.outputs, key=lambda o: o[0]):
        x, y = _xy(d, site)
        k = shown[site]
        shown[site] += 1
        ox = x + (k - (per[site] - 1) / 2) * min(0.25, 0.9 / per[site])
        shapes.append(Shape("triangle-down", ox, top, 0.1, f"tau-{joint}", f"τ{joint} leaves "
                            f"{site.label}"))
        segments.append([(x, y), (ox, top)])
    _lines(ax, segments, "wires-outputs", "#d94801", 0.4, 0)
    style = {"facecolor": "#fcbba1", "edgecolor": "#333333", "linewidth": 0.5, "zorder": 3}
    if _shapes(ax, shapes, "outputs", style, titles):
        for sh in shapes:
            ax.text(sh.x, sh.y + 0.13, f"τ{sh.gid[4:]}", fontsize=5, ha="center", va="bottom")
