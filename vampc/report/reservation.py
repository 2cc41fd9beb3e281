"""The modulo reservation table (`vampc report --reservation FILE.svg`): the steady state the timing
chart's first set does not show. One row per unit (a VAMP; an MM's three VAMPs are one row in a
folded layout, as in the timing chart), the ticks of one interval across; every op of the schedule
sits on its unit at its start modulo the interval, so in the steady state each row shows everything
its unit does, whichever torque set it is for. A bar is labelled with its op and node (`T4·3`, as in
the timing chart) and `−k` when it belongs to the set that entered k intervals earlier (k = start //
interval); a bar that runs past the end of the interval continues at its start. Each bar is a group
`res-<node id>` with a tooltip. More than MAX_ROWS units are not drawn one by one: the table then
shows, per row of MAX_ROWS, the busy fraction of each tick (how many of the units it stands for are
busy), and says so.
"""
from __future__ import annotations

from vampc.machine.ops import colours
from vampc.report import svg
from vampc.report.sites import unit_nodes, unit_sizes

MAX_ROWS = 110          # rows drawn one by one at most: 110 × 12 pt keeps the table within 1 500 pt
ROW_PT, LEFT_PT, TOP_PT, BOTTOM_PT, RIGHT_PT, MAX_PLOT_PT = 12, 150, 70, 40, 30, 1200.0
FONT = 6.0
SHADE = (0.2, 0.35, 0.6)   # a grouped row's colour, its opacity the share of its units busy


def reservation_svg(graph, layout, sched, title: str) -> str:
    """The table as SVG text."""
    with svg.settings():
        return _draw(graph, layout, sched, title)


def rows(graph, layout, sched) -> list[tuple[str, list[tuple[int, int, int, int]]]]:
    """Per unit: (label, [(node, tick in the interval, duration, set offset k)])."""
    P = sched.interval
    duration = sched.timing.durations
    out = []
    sizes = unit_sizes(layout)
    first = 0
    for unit, ids in enumerate(unit_nodes(graph, layout)):
        size = sizes[unit]
        label = f"VAMP {first}" if size == 1 else f"VAMPs {first}-{first + size - 1}"
        first += size
        out.append((label, [(i, sched.start[i] % P, duration[graph.nodes[i].op], sched.start[i] // P)
                            for i in ids]))
    return out


def _draw(graph, layout, sched, title: str) -> str:
    from matplotlib.collections import PolyCollection
    from matplotlib.patches import Rectangle
    P = sched.interval
    table = rows(graph, layout, sched)
    grouped = len(table) > MAX_ROWS
    per = -(-len(table) // MAX_ROWS)
    shown = -(-len(table) // per)
    fig, ax, ptf, width, height = svg.cycle_axes(P, shown, ROW_PT, LEFT_PT, TOP_PT, BOTTOM_PT, RIGHT_PT,
                                          MAX_PLOT_PT)
    titles: dict[str, str] = {}
    polys, faces, urls = [], [], []
    texts = []
    if not grouped:
        for y, (_, ops) in enumerate(table):
            for i, tick, d, k in ops:
                nd = graph.nodes[i]
                gid = f"res-{i}"
                for start, end in _pieces(tick, d, P):
                    polys.append([(start, y + 0.1), (end, y + 0.1), (end, y + 0.9), (start, y + 0.9)])
                    faces.append(colours()[nd.op.value])
                    urls.append(f"#{gid}")
                titles[gid] = (f"{nd.section}{nd.group}.{nd.name} ({nd.op.value}), node {i}: ticks "
                               f"{tick}-{(tick + d - 1) % P} of the interval, for the set that entered "
                               f"{k} interval{'s' * (k != 1)} earlier")
                text = f"{nd.name}·{nd.group}" + (f" −{k}" if k else "")
                if len(text) * FONT * 0.62 <= min(d, P - tick) * ptf:
                    texts.append((tick + min(d, P - tick) / 2, y + 0.5, text))
        labels = [label for label, _ in table]
    else:
        import numpy as np
        busy = np.zeros((shown, P), dtype=np.int64)
        unit = np.array([u // per for u, (_, ops) in enumerate(table) for _ in ops], dtype=np.int64)
        tick = np.array([t for _, ops in table for _, t, _, _ in ops], dtype=np.int64)
        dur = np.array([d for _, ops in table for _, _, d, _ in ops], dtype=np.int64)
        for t in range(int(dur.max(initial=0))):       # durations are a few ticks
            on = dur > t
            np.add.at(busy, (unit[on], (tick[on] + t) % P), 1)
        # the units of each row: `per`, but the last row holds what is left (it was labelled and
        # shaded as a full row: a fully busy last row of 12 units looked a third idle)
        held = [min(per, len(table) - y * per) for y in range(shown)]
        for y in range(shown):
            for t in range(P):
                if busy[y][t]:
                    polys.append([(t, y + 0.1), (t + 1, y + 0.1), (t + 1, y + 0.9), (t, y + 0.9)])
                    faces.append((*SHADE, min(1.0, busy[y][t] / held[y])))
                    urls.append(None)
        labels = [f"{table[y * per][0]} … ({held[y]})" for y in range(shown)]
    coll = PolyCollection(polys, facecolors=faces, edgecolors="#404040", linewidths=0.3,
                          urls=urls if not grouped else None)
    coll.set_gid("reservations")
    ax.add_collection(coll)
    for x, y, text in texts:
        ax.text(x, y, text, fontsize=FONT, ha="center", va="center")
    ax.set_yticks([y + 0.5 for y in range(shown)], labels, fontsize=FONT)
    ax.tick_params(axis="y", length=0)
    step = next(s for s in (1, 2, 4, 5, 10, 20, 50, 100, 200, 500, 1000, 10**9) if s * ptf >= 24)
    ax.set_xticks(range(0, P + 1, step))
    ax.tick_params(axis="x", labelsize=FONT, top=True, labeltop=True)
    ax.set_xlabel(f"tick within the interval (0 to {P - 1}); T4·3 −k: op T4 of node 3 of its pass "
                  "(bwd, npv or fwd 3 in every picture), for the set that entered k intervals earlier",
                  fontsize=7)
    for x in range(P + 1):
        ax.axvline(x, color="#eeeeee", linewidth=0.4, zorder=0)
    head = (f"{title} — modulo reservation table: every op of the steady state on its unit, "
            f"{len(table)} units × {P} ticks")
    if grouped:
        head += f"; {per} units a row, shaded by how many are busy"
    ax.set_title(head if width > 900 else head.replace(" — ", "\n", 1), loc="left", fontsize=8, pad=14)
    handles = [Rectangle((0, 0), 1, 1, facecolor=c, edgecolor="#404040", linewidth=0.4, label=op)
               for op, c in colours().items()]
    if grouped:         # shaded by the share of the row's units busy, not by op: its key (it had none)
        handles = [Rectangle((0, 0), 1, 1, facecolor=(*SHADE, share), edgecolor="#404040",
                             linewidth=0.4, label=f"{name} of the row's units busy")
                   for share, name in ((0.25, "¼"), (0.5, "½"), (0.75, "¾"), (1.0, "all"))]
    if handles:
        fig.legend(handles=handles, loc="upper left", ncols=10, fontsize=6.5, frameon=False,
                   bbox_to_anchor=(LEFT_PT / width, 1 - 2 / height))
    return svg.to_svg(fig, titles)


def _pieces(tick: int, d: int, P: int) -> list[tuple[int, int]]:
    """[tick, tick + d) folded into [0, P): one or more pieces (an op longer than the interval
    cannot be: the schedule verifies it)."""
    end = tick + d
    return [(tick, min(end, P))] + ([(0, end - P)] if end > P else [])
