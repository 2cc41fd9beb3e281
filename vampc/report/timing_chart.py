"""The timing chart (`vampc report --timing FILE.svg`), in the style of the paper's Table III.2:
flops across, one row per variable and op kind (systolic layout: the op of that name and kind in every node, one lane
more wherever two run at once) or per VAMP (folded layouts: a unit, three VAMPs for an MM), every
scheduled op a bar labelled with its op and node, the critical path outlined in red and joined, and
a strip above showing successive torque sets: one every interval, each lasting the latency, so a
pipelined layout's overlapping sets are visible.

Each op's bar is an SVG group with id `op-<node id>` (`op-<node id>-critical` on the critical path)
and a <title> naming it. A chart of more than MAX_BARS ops (a 512-joint log network has 95 000), of
more than LABELLED_BARS ops under 2 pt wide each (a 300-joint chain's), or of more than MAX_LANES lanes (a 64-joint log network has 1 952) would be neither readable nor quick to
draw: it shows, per variable, when any node computes it (merged bars, ids `busy-<row>-<k>`), keeps
the critical path's ops as their own red-edged bars on their variable's row, joined (ids
`op-<node id>-critical`), and says so in its title; one of more than LABELLED_BARS ops keeps its
labels in the tooltips. The plot is at most MAX_PLOT_PT wide (flops narrower than a label then
carry theirs in the tooltip), so every chart stays under about 2 000 px on its long side.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from vampc.machine.ops import colours
from vampc.report import svg
from vampc.report.sites import SECTIONS, unit_nodes, unit_sizes
from vampc.schedule.registry import SYSTOLIC, is_layout

MAX_BARS = 10_000
MAX_LANES = 300           # rows of bars: above this, the chart merges per variable
MAX_PLOT_PT = 1300        # the plot's width at most (the labels column and margins come on top)
MAX_CRITICAL_BARS = 600   # a merged chart's critical ops drawn one by one up to this many
LABELLED_BARS = 4_000     # above this many bars, labels only in the tooltips (text is slow to lay out)
MAX_SETS = 8
ROW_PX, LEFT_PX, TOP_PX, BOTTOM_PX, RIGHT_PX = 13, 150, 84, 40, 30
FONT = 6.0


@dataclass(frozen=True)
class Row:
    """One row: its label and its lanes, each a list of node ids (merged: (start, finish, count))."""

    label: str
    lanes: tuple[tuple, ...]
    op: str = ""                 # the op of a merged row (its bars' colour)


@dataclass(frozen=True)
class Chart:
    """What the chart shows, before any drawing: rows, whether bars are merged, the x span."""

    rows: tuple[Row, ...]
    merged: bool
    span: int
    sets: tuple[int, ...]        # start tick of each torque set shown


def chart(graph, layout, sched) -> Chart:
    """The rows of the chart for a graph, its layout and schedule (see the module docstring)."""
    ops = graph.compute_nodes()
    P = sched.interval
    count = min(MAX_SETS, math.ceil(sched.latency / P) + 1) if P < sched.latency else 2
    sets = tuple(k * P for k in range(count))
    span = max(max((sched.finish[nd.id] for nd in ops), default=0), sets[-1] + sched.latency)
    # merged: too many ops, too many rows, or thousands of ops each under 2 pt wide
    merged = len(ops) > MAX_BARS or (len(ops) > LABELLED_BARS and _scale(span) < 2.0)
    if not merged:
        rows = (_variable_rows(graph, sched) if is_layout(layout.name, SYSTOLIC)
                else _unit_rows(graph, layout, sched))
        merged = sum(len(r.lanes) for r in rows) > MAX_LANES
    if merged:          # spans closer than 3 pt of the plot are one bar
        rows = _merged_rows(graph, sched, gap=3 * span / MAX_PLOT_PT if span > MAX_PLOT_PT / 6 else 0)
    return Chart(tuple(rows), merged, span, sets)


def _roles(graph) -> list[tuple[str, str, str]]:
    """(section, name, op kind) of every op, sections in pass order, names in order of first
    appearance: a row per kind, as its label and colour say one (the log recursion computes a
    variable by an MTV in a combining node and a VA in a leaf, and both were drawn in one row
    labelled MTV, coloured so when merged: a new user's find)."""
    seen: dict[tuple[str, str, str], None] = {}
    for sec in SECTIONS:
        for nd in graph.compute_nodes():
            if nd.section == sec:
                seen.setdefault((sec, nd.name, nd.op.value))
    return list(seen)


def _by_role(graph) -> dict[tuple[str, str, str], list[int]]:
    by_role: dict[tuple[str, str, str], list[int]] = {}
    for nd in graph.compute_nodes():
        by_role.setdefault((nd.section, nd.name, nd.op.value), []).append(nd.id)
    return by_role


def _lanes(ids, sched) -> tuple[tuple[int, ...], ...]:
    """Ops packed into as few lanes as let no two of a lane overlap (earliest start first)."""
    lanes: list[list[int]] = []
    ends: list[int] = []
    for i in sorted(ids, key=lambda i: (sched.start[i], i)):
        k = next((k for k, end in enumerate(ends) if end <= sched.start[i]), None)
        if k is None:
            lanes.append([])
            ends.append(0)
            k = len(lanes) - 1
        lanes[k].append(i)
        ends[k] = sched.finish[i]
    return tuple(tuple(x) for x in lanes)


def _variable_rows(graph, sched) -> list[Row]:
    by_role = _by_role(graph)
    return [Row(f"{sec} {name} ({op})", _lanes(by_role[(sec, name, op)], sched))
            for sec, name, op in _roles(graph)]


def _unit_rows(graph, layout, sched) -> list[Row]:
    rows, first, sizes = [], 0, unit_sizes(layout)
    for unit, ids in enumerate(unit_nodes(graph, layout)):
        size = sizes[unit]
        roles = list(dict.fromkeys(f"{graph.nodes[i].section} {graph.nodes[i].name}" for i in ids))
        where = f"VAMP {first}" if size == 1 else f"VAMPs {first}-{first + size - 1}"
        rows.append(Row(f"{where}: {', '.join(roles[:2])}" + (" …" if len(roles) > 2 else ""),
                        _lanes(ids, sched)))
        first += size
    return rows


def _merged_rows(graph, sched, gap: float = 0) -> list[Row]:
    """Per variable, the spans in which some node computes it, with how many ops each covers; spans
    less than `gap` flops apart are one (a long schedule's plot cannot show the gap)."""
    by_role = _by_role(graph)
    rows = []
    for sec, name, op in _roles(graph):
        spans: list[list[int]] = []
        for i in sorted(by_role[(sec, name, op)], key=lambda i: sched.start[i]):
            s, f = sched.start[i], sched.finish[i]
            if spans and s <= spans[-1][1] + gap:
                spans[-1][1] = max(spans[-1][1], f)
                spans[-1][2] += 1
            else:
                spans.append([s, f, 1])
        rows.append(Row(f"{sec} {name} ({op})", (tuple(tuple(x) for x in spans),), op))
    return rows


def label(nd) -> str:
    """A bar's label: op name and node, 'T4·3'."""
    return f"{nd.name}·{nd.group}"


def timing_svg(graph, layout, sched, title: str) -> str:
    """The chart as SVG text."""
    data = chart(graph, layout, sched)
    with svg.settings():
        return _draw(graph, layout, sched, data, title)


def _scale(span: int) -> float:
    """Points per flop: wide enough for 'T4·3' in a one-flop bar, narrower for long schedules, and
    never wider in all than MAX_PLOT_PT."""
    return min(max(6.0, min(24.0, 18.0 if span <= 600 else 9000.0 / span)), MAX_PLOT_PT / max(span, 1))


def _draw(graph, layout, sched, data: Chart, title: str) -> str:
    """The figure: torque-set strip, bars, critical path, axes, title and key."""
    from matplotlib.lines import Line2D
    from matplotlib.patches import Rectangle
    pxf = _scale(data.span)
    fig, ax, width, height = _figure(data, pxf)
    titles: dict[str, str] = {}
    _draw_sets(ax, data, sched, titles)
    ticks, names, bars = _bars(graph, layout, sched, data)
    if data.merged:
        bars += _critical_bars(graph, layout, sched, data)
    _draw_bars(ax, bars, pxf, titles)
    _critical_line(ax, Line2D, graph, sched, data, set(sched.critical_path))
    _axes(ax, data, sched, ticks, names, pxf)
    if data.merged:
        one_by_one = len(sched.critical_path) <= MAX_CRITICAL_BARS
        title += (f" — {len(graph.compute_nodes()):,} ops: merged per variable and op kind, the critical path's "
                  f"{len(sched.critical_path):,} ops " + ("shown one by one" if one_by_one else
                                                          "merged the same way, in red")
                  # (said "at most 10,000 ops and 300 rows" of a 9,000-op chart merged as its
                  # bars were under 2 pt wide: an audit's find)
                  + f" (charts of at most {MAX_BARS:,} ops and {MAX_LANES} rows show every op, "
                  f"unless more than {LABELLED_BARS:,} of them would each be under 2 pt wide)")
    elif len(bars) > LABELLED_BARS:
        title += f" — {len(bars):,} ops: labels in the tooltips"
    ax.set_title(title.replace(": ", ":\n", 1) if width < 900 else title,
                 loc="left", fontsize=9, pad=16)
    fig.legend(handles=_legend(Rectangle, Line2D), loc="upper left", ncols=10, fontsize=7,
               frameon=False, bbox_to_anchor=(LEFT_PX / width, 1 - 2 / height))
    return svg.to_svg(fig, titles)


def _figure(data: Chart, pxf: float):
    """Figure and axes sized to the rows and the span: (fig, ax, width, height)."""
    rows = sum(len(r.lanes) for r in data.rows) + len(data.sets) + 1
    width = LEFT_PX + data.span * pxf + RIGHT_PX
    height = TOP_PX + rows * ROW_PX + BOTTOM_PX
    fig = svg.figure(width, height)
    ax = fig.add_axes((LEFT_PX / width, BOTTOM_PX / height, data.span * pxf / width,
                       (height - TOP_PX - BOTTOM_PX) / height))
    ax.set_xlim(0, data.span)
    ax.set_ylim(rows, 0)
    return fig, ax, width, height


def _bars(graph, layout, sched, data: Chart):
    """(row tick positions, row names, bars), lanes below the torque-set strip."""
    critical = set(sched.critical_path)
    y = len(data.sets) + 1
    ticks, names, bars = [], [], []
    for row in data.rows:
        for k, lane in enumerate(row.lanes):
            ticks.append(y + 0.5)
            names.append(row.label if k == 0 else "")
            for item in lane:
                bars.append(_merged_bar(item, y, f"busy-{len(ticks) - 1}", row) if data.merged
                            else _bar(graph, layout, sched, item, y, item in critical))
            y += 1
    return ticks, names, bars


def _draw_sets(ax, data: Chart, sched, titles: dict) -> None:
    """The strip of successive torque sets: each from its entry to its last torque."""
    from matplotlib.patches import Rectangle
    for k, start in enumerate(data.sets):
        r = Rectangle((start, k + 0.15), sched.latency, 0.7, facecolor="#e0e0e0", edgecolor="#808080",
                      linewidth=0.5, clip_on=False)
        r.set_gid(f"set-{k}")
        ax.add_artist(r)
        ax.text(start + 0.3, k + 0.5, f"torque set {k}: flops {start}-{start + sched.latency}",
                fontsize=FONT, va="center", ha="left")
        titles[f"set-{k}"] = (f"torque set {k} enters at flop {start} and its last torque leaves "
                              f"at flop {start + sched.latency}")


@dataclass(frozen=True)
class Bar:
    """One bar: ticks [start, end) on row y, colours, id, tooltip and label candidates (the first
    that fits is drawn)."""

    start: int
    end: int
    y: int
    face: str
    edge: str
    width: float
    gid: str
    title: str
    labels: tuple[str, ...]


def _bar(graph, layout, sched, i: int, y: int, crit: bool) -> Bar:
    """The bar of op i."""
    nd = graph.nodes[i]
    s, f = sched.start[i], sched.finish[i]
    return Bar(s, f, y, colours()[nd.op.value], "#d62728" if crit else "#404040",
               1.6 if crit else 0.4, f"op-{i}" + ("-critical" if crit else ""),
               f"{nd.section}{nd.group}.{nd.name} ({nd.op.value}), node {i}: flops {s}-{f}, "
               + _where(layout, i) + (", on the critical path" if crit else ""),
               (label(nd), str(nd.group)))


def _where(layout, i: int) -> str:
    """'unit 4', or in a budgeted layout 'VAMPs 0,3,5'."""
    if not layout.grouped:
        vs = layout.placement[i]
        return f"VAMP{'s' if len(vs) > 1 else ''} {','.join(map(str, vs))}"
    return f"unit {layout.units[i]}"


def _merged_bar(item, y: int, gid_base: str, row) -> Bar:
    """The bar of a span in which some node computes a variable."""
    s, f, count = item
    return Bar(s, f, y, colours().get(row.op, "#dddddd"), "#404040", 0.4, f"{gid_base}-{s}",
               f"{row.label}: {count} ops in flops {s}-{f}", (f"×{count}",))


def _draw_bars(ax, bars: list[Bar], pxf: float, titles: dict) -> None:
    """All bars as one collection (one SVG path each, fast for thousands), each carrying its id as
    a link target that vampc.report.svg turns into a group with that id and a tooltip; then the
    labels that fit."""
    from matplotlib.collections import PolyCollection
    if not bars:
        return
    coll = PolyCollection([[(b.start, b.y + 0.1), (b.end, b.y + 0.1), (b.end, b.y + 0.9),
                            (b.start, b.y + 0.9)] for b in bars],
                          facecolors=[b.face for b in bars], edgecolors=[b.edge for b in bars],
                          linewidths=[b.width for b in bars], urls=[f"#{b.gid}" for b in bars],
                          clip_on=False)
    coll.set_gid("bars")
    ax.add_collection(coll)
    for b in bars:
        titles[b.gid] = b.title
        if len(bars) > LABELLED_BARS:
            continue
        room = (b.end - b.start) * pxf
        text = next((t for t in b.labels if len(t) * FONT * 0.62 <= room), None)
        if text is not None:
            ax.text((b.start + b.end) / 2, b.y + 0.5, text, fontsize=FONT, ha="center", va="center")


def _merged_row_of(graph, data: Chart) -> dict:
    """In a merged chart, the row (y) of each critical op: its variable's."""
    y0 = len(data.sets) + 1
    at = {role: y0 + k for k, role in enumerate(_roles(graph))}     # the merged rows' order
    return lambda i: at[(graph.nodes[i].section, graph.nodes[i].name, graph.nodes[i].op.value)]


def _critical_bars(graph, layout, sched, data: Chart) -> list:
    """A merged chart's critical-path ops, each its own bar on its variable's row."""
    from dataclasses import replace
    row_of = _merged_row_of(graph, data)      # unlabelled: the merged bar under each has its label
    path = sched.critical_path
    if len(path) <= MAX_CRITICAL_BARS:
        return [replace(_bar(graph, layout, sched, i, row_of(i), True), labels=()) for i in path]
    # a long path (a 4 096-joint chain's has 8 000 ops): its ops merged per row, as the others
    gap = 3 * data.span / MAX_PLOT_PT
    spans: dict[int, list[list[int]]] = {}
    for i in sorted(path, key=lambda i: sched.start[i]):
        row = spans.setdefault(row_of(i), [])
        s, f = sched.start[i], sched.finish[i]
        if row and s <= row[-1][1] + gap:
            row[-1][1], row[-1][2] = max(row[-1][1], f), row[-1][2] + 1
        else:
            row.append([s, f, 1])
    return [Bar(s, f, y, "none", "#d62728", 1.6, f"critical-{y}-{s}",
                f"{k} ops of the critical path in flops {s}-{f}", ())
            for y, row in spans.items() for s, f, k in row]


def _critical_line(ax, Line2D, graph, sched, data: Chart, critical: set) -> None:
    """Join the critical path's bars, each op's end to the next one's start, along the bars' lower
    edges (through their middles it struck their labels out: a new user's find)."""
    edge = 0.9                           # (a bar spans y + 0.1 to y + 0.9: _draw_bars)
    where = {}
    if data.merged:
        row_of = _merged_row_of(graph, data)
        where = {i: row_of(i) + edge for i in sched.critical_path}
    y = len(data.sets) + 1
    for row in data.rows if not data.merged else ():
        for lane in row.lanes:
            for i in lane:
                where[i] = y + edge
            y += 1
    xs, ys = [], []
    for i in sched.critical_path:
        xs += [sched.start[i], sched.finish[i]]
        ys += [where[i], where[i]]
    line = Line2D(xs, ys, color="#d62728", linewidth=0.9, alpha=0.8)
    line.set_gid("critical-path")
    ax.add_artist(line)


def _axes(ax, data: Chart, sched, ticks, names, pxf: float) -> None:
    """Row names, flop ticks (top and bottom), period lines."""
    ax.set_yticks(ticks, names, fontsize=FONT)
    ax.tick_params(axis="y", length=0)
    step = next(s for s in (1, 2, 4, 5, 10, 20, 50, 100, 200, 500, 1000, 2000, 5000, 10000, 10**9)
                if s * pxf >= 28)
    ax.set_xticks(range(0, data.span + 1, step))
    ax.tick_params(axis="x", labelsize=FONT, top=True, labeltop=True)
    ax.set_xlabel("flops (ticks) from the first input of torque set 0; a bar T4·3 is op T4 of node 3 of "
                  "its row's pass (named bwd 3, npv 3 or fwd 3 in every picture)", fontsize=7)
    P = sched.interval
    if P * pxf >= 8:
        for x in range(0, data.span + 1, P):
            ax.axvline(x, color="#e8e8e8", linewidth=0.5, zorder=0)
    ax.axhline(len(data.sets) + 0.5, color="#808080", linewidth=0.5)


def _legend(Rectangle, Line2D) -> list:
    """The key: op colours, the critical path, the torque-set bars."""
    handles = [Rectangle((0, 0), 1, 1, facecolor=c, edgecolor="#404040", linewidth=0.4, label=op)
               for op, c in colours().items()]
    handles.append(Line2D([0], [0], color="#d62728", linewidth=1.6, label="critical path"))
    handles.append(Rectangle((0, 0), 1, 1, facecolor="#e0e0e0", edgecolor="#808080", linewidth=0.5,
                             label="torque set (entry to last torque)"))
    return handles
