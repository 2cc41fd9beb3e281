"""The network drawing (`vampc report --network FILE.svg`): recursion nodes as circles placed as in
Figures III.1, IV.2 and VI.3 (the rectilinear array: joints or prefix positions across, the
backward pass's tiers upwards, then the non-propagated variables, then the forward pass's tiers),
or — for a folded layout — its device nodes (Figure VI.1); vector buses between them as lines, the
delay buffers on a bus as a square labelled with its stages, host ports along the bottom edge and
the torque outputs along the top.

Ids in the SVG: `site-<section>-<index>` (circles), `bus-<from>-<to>` (lines), `buffer-<from>-<to>`
(squares), `port-<index>`, `tau-<joint>`; each with a <title>.
"""
from __future__ import annotations

from collections import Counter
from dataclasses import dataclass

from vampc.report import svg
from vampc.report.sites import SECTION_NAMES, Site, node_table, vamp_sites

COLOURS = {"bwd": "#c6dbef", "npv": "#e5f5e0", "fwd": "#fdd0a2"}
CELL_PX, MARGIN_PX = 78, 80


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
                if tap.kind == "vamp":
                    buses[(sites[tap.index], here)] += 1
                elif tap.kind == "buffer":
                    key = (sites[net.buffers[tap.index].source], here)
                    got = buffered.get(key, (0, 0))
                    buffered[key] = (got[0] + 1, max(got[1], tap.stage))
                    chains_of.setdefault(key, set()).add(tap.index)
                elif tap.kind == "port":
                    readers_of_port.setdefault(tap.index, [])
                    if here not in readers_of_port[tap.index]:
                        readers_of_port[tap.index].append(here)
    buffered = {k: (n, deep, len(chains_of[k])) for k, (n, deep) in buffered.items()}
    ports = [(p.index, readers_of_port.get(p.index, []), _port_label(p)) for p in net.ports]
    outputs = [(o.joint, sites[o.vamp]) for o in net.outputs]
    xs = [x for x, _ in places.values()]
    ys = [y for _, y in places.values()]
    return Drawing(places, labels, vamps, dict(buses), buffered, ports, outputs,
                   max(ys) + 1, max(xs) + 1)


def _port_label(p) -> str:
    names = list(dict.fromkeys(f"{e.key.quantity}{e.key.joint}" for e in p.entries))
    if not names:
        return "program"
    return names[0] + (f" +{len(names) - 1}" if len(names) > 1 else "")


def _places(graph, layout, sites: list[Site]) -> tuple[dict, dict]:
    """Grid cell and label of every site (see the module docstring)."""
    if layout.name != "systolic":
        row = {"bwd": 0, "npv": 1, "fwd": 2}
        return ({s: (s.index, row[s.section]) for s in sites},
                {s: f"{SECTION_NAMES[s.section]}\ndevice {s.index}" for s in sites})
    if graph.recursion == "linear":
        row = {"bwd": 0, "npv": 1, "fwd": 2}
        n = graph.n
        name = {"bwd": lambda i: f"(0,{i})", "npv": lambda i: f"r̈ F N {i}",
                "fwd": lambda i: f"({i},{n})"}
        return ({s: (s.index - 1, row[s.section]) for s in sites},
                {s: name[s.section](s.index) for s in sites})
    table = node_table(graph)
    info = {(sec, r[0]): r for sec, rows in table.items() for r in rows}
    tiers = max((r[4] for r in table["bwd"]), default=0)
    first = min((r[1] for r in table["bwd"]), default=1)
    places, labels = {}, {}
    for s in sites:
        if s.section == "npv":
            places[s] = (s.index - first, tiers + 1)
            labels[s] = f"r̈ F N {s.index}"
            continue
        _, a, _, b, tier = info[(s.section, s.index)]
        if s.section == "bwd":
            places[s] = (b - first, tier)
        else:
            places[s] = (a - first, tiers + 2 + tier)
        labels[s] = f"({a},{b})"
    return places, labels


def network_svg(graph, layout, net, title: str) -> str:
    """The drawing as SVG text."""
    d = drawing(graph, layout, net)
    with svg.settings():
        return _draw(d, title)


def _xy(d: Drawing, site: Site) -> tuple[float, float]:
    x, y = d.places[site]
    return x + 0.5, y + 1.0


def _draw(d: Drawing, title: str) -> str:
    from matplotlib.collections import LineCollection
    span = d.rows + 1.6                   # y units: ports below row 0, outputs above the last
    width = MARGIN_PX * 2 + d.cols * CELL_PX
    height = MARGIN_PX * 2 + span * CELL_PX
    fig = svg.figure(width, height)
    ax = fig.add_axes((MARGIN_PX / width, MARGIN_PX / height, d.cols * CELL_PX / width,
                       span * CELL_PX / height))
    ax.set_xlim(0, d.cols)
    ax.set_ylim(-0.3, d.rows + 1.3)
    ax.set_axis_off()
    titles: dict[str, str] = {}
    lines, widths = [], []
    for (a, b), k in d.buses.items():
        if a != b:
            lines.append([_xy(d, a), _xy(d, b)])
            widths.append(min(0.4 + 0.25 * k, 3.0))
    segs = LineCollection(lines, linewidths=widths, colors="#555555", zorder=1)
    segs.set_gid("buses")
    ax.add_collection(segs)
    _buffers(ax, d, titles)
    _sites(ax, d, titles)
    _edges(ax, d, titles)
    ax.set_title(title, loc="left", fontsize=9)
    fig.text(MARGIN_PX / width, 8 / height,
             "circles: recursion or device nodes (V: VAMPs)\nlines: vector buses (wider: more)\n"
             "squares: delay buffers (deepest stage)\nbottom: host ports; top: torques τ_i",
             fontsize=6.5, va="bottom")
    return svg.to_svg(fig, titles)


def _sites(ax, d: Drawing, titles: dict) -> None:
    from matplotlib.patches import Circle
    small = len(d.places) > 400
    for site, label in d.labels.items():
        x, y = _xy(d, site)
        c = Circle((x, y), 0.32, facecolor=COLOURS[site.section], edgecolor="#333333", linewidth=0.6,
                   zorder=3)
        gid = f"site-{site.section}-{site.index}"
        c.set_gid(gid)
        ax.add_artist(c)
        titles[gid] = f"{SECTION_NAMES[site.section]} node {label.replace(chr(10), ' ')}: " \
                      f"{d.vamps[site]} VAMPs"
        if not small:
            ax.text(x, y, f"{label}\n{d.vamps[site]} V", fontsize=5.5, ha="center", va="center",
                    zorder=4)


def _buffers(ax, d: Drawing, titles: dict) -> None:
    from matplotlib.patches import Rectangle
    small = len(d.buffered) > 400
    for (a, b), (buses, deepest, chains) in sorted(d.buffered.items()):
        (xa, ya), (xb, yb) = _xy(d, a), _xy(d, b)
        if a == b:                                        # a folded device's feedback
            x, y = xa + 0.42, ya + 0.38
            ax.plot([xa, x, xb], [ya, y, yb], color="#8c6d31", linewidth=0.6, zorder=1)
        else:
            x, y = xa + 0.55 * (xb - xa), ya + 0.55 * (yb - ya)
            ax.plot([xa, x, xb], [ya, y, yb], color="#8c6d31", linewidth=0.6, zorder=1)
        r = Rectangle((x - 0.11, y - 0.11), 0.22, 0.22, facecolor="#fff7bc", edgecolor="#8c6d31",
                      linewidth=0.6, zorder=2)
        gid = f"buffer-{a.section}{a.index}-{b.section}{b.index}"
        r.set_gid(gid)
        ax.add_artist(r)
        titles[gid] = (f"delay buffers from {a.label} to {b.label}: {chains} chains, {buses} taps, "
                       f"up to stage {deepest}")
        if not small:
            ax.text(x, y, str(deepest), fontsize=5, ha="center", va="center", zorder=3)


def _edges(ax, d: Drawing, titles: dict) -> None:
    """Host ports along the bottom edge, torque outputs along the top."""
    from matplotlib.patches import RegularPolygon
    small = len(d.ports) > 400
    stack: Counter = Counter()
    for index, readers, label in d.ports:
        if not readers:
            continue
        x, _ = _xy(d, readers[0])
        k = stack[round(x, 3)]
        stack[round(x, 3)] += 1
        px, py = x - 0.3 + 0.2 * (k % 4), 0.1 - 0.0 * k
        tri = RegularPolygon((px, py), 3, radius=0.09, facecolor="#ffffff", edgecolor="#333333",
                             linewidth=0.5, zorder=3)
        gid = f"port-{index}"
        tri.set_gid(gid)
        ax.add_artist(tri)
        titles[gid] = f"host port {index}: {label}, read by " + ", ".join(r.label for r in readers)
        for r in readers:
            rx, ry = _xy(d, r)
            ax.plot([px, rx], [py, ry], color="#bbbbbb", linewidth=0.3, zorder=0)
        if not small and k < 4:
            ax.text(px, py - 0.16, label, fontsize=4, ha="center", va="top", rotation=90)
    top = d.rows + 1.0
    shown: Counter = Counter()
    for joint, site in sorted(d.outputs, key=lambda o: o[0]):
        x, y = _xy(d, site)
        k = shown[site]
        shown[site] += 1
        per = sum(1 for _, s in d.outputs if s == site)
        ox = x + (k - (per - 1) / 2) * min(0.25, 0.9 / per)
        tri = RegularPolygon((ox, top), 3, radius=0.1, orientation=0, facecolor="#fcbba1",
                             edgecolor="#333333", linewidth=0.5, zorder=3)
        gid = f"tau-{joint}"
        tri.set_gid(gid)
        ax.add_artist(tri)
        titles[gid] = f"τ{joint} leaves {site.label}"
        ax.plot([x, ox], [y, top], color="#d94801", linewidth=0.4, zorder=0)
        if len(d.outputs) <= 400:
            ax.text(ox, top + 0.13, f"τ{joint}", fontsize=5, ha="center", va="bottom")
