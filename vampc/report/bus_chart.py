"""The bus chart (`vampc report --bus-chart FILE.svg`): the Mostly-Local Bus over one basic cycle. One
band per tier (shortest at the top), one row per bus of the tier, the Cycle-Counter values across;
a cell is filled where a write drives that bus then, coloured by tier, labelled `w→r,r` (the writer
VAMP and the VAMPs latching it, by VAMP index) where the label fits, and a tooltip names them with
their places on the line. A tier of more than
MAX_ROWS_PER_TIER buses is drawn as that many rows, each standing for several buses, shaded by how
many of them are driven in that tick (and the chart says so)."""
from __future__ import annotations

from vampc.network.bus import latched
from vampc.network.model import tap_source
from vampc.report import svg

MAX_ROWS_PER_TIER = 12
ROW_PT, GAP_PT, LEFT_PT, TOP_PT, BOTTOM_PT, RIGHT_PT, MAX_PLOT_PT = 9, 5, 110, 60, 40, 30, 1200.0
FONT = 5.5


def cells(net) -> list[dict]:
    """Every bus write of one cycle: tier, bus, counter, writer VAMP and readers (VAMP indices)."""
    bus = net.bus
    sources = [b.source for b in net.buffers]
    readers = latched(net)
    out = []
    for (k, b, c), writes in sorted(bus.drivers(sources, net.period).items()):
        w = writes[0]
        out.append({"tier": k, "bus": b, "counter": c, "writer": tap_source(w.source, sources),
                    "source": str(w.source), "readers": sorted(set(readers.get((k, b, c), [])))})
    return out


def bus_name(tier, b: int, vamps: int) -> str:
    """'bus 3 of 9', counted from 1 along the line (the network IR numbers an offset tier's short
    first bus -1, which a tooltip had shown: an audit's)."""
    first = tier.bus_at(0)
    return f"bus {b - first + 1} of {tier.buses(vamps)}" + \
        (" (the short one before the offset)" if tier.offset and b == first else "")


def writer_name(cell: dict, position) -> str:
    """'VAMP 111 at place 12', or 'buffer 3 stage 2, delaying VAMP 111 at place 12' (a VAMP's own
    Result was named twice: 'vamp 111 (VAMP 111 at place 12)')."""
    w = cell["writer"]
    at = f"VAMP {w} at place {position[w]}"
    return at if cell["source"] == f"vamp {w}" else f"{cell['source']}, delaying {at}"


def bus_chart_svg(net, title: str) -> str:
    """The chart as SVG text (a network with a bus)."""
    with svg.settings():
        return _draw(net, title)


def _draw(net, title: str) -> str:
    from matplotlib.collections import PolyCollection
    bus, P, V = net.bus, net.period, len(net.vamps)
    # rows: per tier, its buses (or groups of them)
    bands = []
    y = 0.0
    for k, tier in enumerate(bus.tiers):
        first, count = tier.bus_at(0), tier.buses(V)
        per = -(-count // MAX_ROWS_PER_TIER)
        rows = -(-count // per)
        bands.append((k, first, per, rows, y))
        y += rows + GAP_PT / ROW_PT
    total = y
    fig, ax, ptf, width, height = svg.cycle_axes(P, total, ROW_PT, LEFT_PT, TOP_PT, BOTTOM_PT, RIGHT_PT,
                                          MAX_PLOT_PT)
    import matplotlib
    cmap = matplotlib.colormaps["tab20"]
    polys, faces, alphas, urls, texts = [], [], [], [], []
    titles: dict[str, str] = {}
    shade: dict[tuple[int, int, int], int] = {}
    grouped = False
    for cell in cells(net):
        k, b, c = cell["tier"], cell["bus"], cell["counter"]
        _, first, per, _, top = bands[k]
        row = (b - first) // per
        if per > 1:
            grouped = True
            shade[(k, row, c)] = shade.get((k, row, c), 0) + 1
            continue
        yy = top + row
        gid = f"bus-{k}-{b}-{c}"
        polys.append([(c, yy + 0.1), (c + 1, yy + 0.1), (c + 1, yy + 0.9), (c, yy + 0.9)])
        faces.append(cmap(k % 20))
        alphas.append(1.0)
        urls.append(f"#{gid}")
        who = ",".join(str(r) for r in cell["readers"])
        places = ", ".join(f"VAMP {r} at place {bus.position[r]}" for r in cell["readers"])
        titles[gid] = (f"tier {k} (span {bus.tiers[k].span}), {bus_name(bus.tiers[k], b, V)}, "
                       f"Cycle-Counter {c}: {writer_name(cell, bus.position)} to {places}")
        text = f"{cell['writer']}→{who}"
        if len(text) * FONT * 0.6 <= ptf:
            texts.append((c + 0.5, yy + 0.5, text))
    for (k, row, c), n in shade.items():
        _, _, per, _, top = bands[k]
        yy = top + row
        polys.append([(c, yy + 0.1), (c + 1, yy + 0.1), (c + 1, yy + 0.9), (c, yy + 0.9)])
        colour = cmap(k % 20)
        # over the buses the row holds: a tier's last row may hold fewer than `per` (a fully busy
        # last row of one bus had been shaded as a quarter busy: an audit's, as the reservation
        # table's once was)
        held = min(per, bus.tiers[k].buses(V) - row * per)
        faces.append((*colour[:3], 0.25 + 0.75 * n / held))
        urls.append(None)
    if polys:
        coll = PolyCollection(polys, facecolors=faces, edgecolors="none", urls=urls)
        ax.add_collection(coll)
    for x, yy, text in texts:
        ax.text(x, yy, text, ha="center", va="center", fontsize=FONT, color="black")
    ax.set_yticks([top + rows / 2 for _, _, _, rows, top in bands])
    ax.set_yticklabels([f"tier {k} (span {bus.tiers[k].span})" + (f", {per} buses a row" if per > 1
                                                                   else "")
                        for k, _, per, _, _ in bands], fontsize=6)
    step = max(1, P // 40)
    ax.set_xticks([x + 0.5 for x in range(0, P, step)])
    ax.set_xticklabels([str(x) for x in range(0, P, step)], fontsize=6)
    ax.set_xlabel("Cycle-Counter (tick of the basic cycle)", fontsize=7)
    ax.tick_params(length=0)
    for spine in ax.spines.values():
        spine.set_visible(False)
    note = (f"{len(bus.tiers)} tiers over {V} VAMPs, a cycle of {P} ticks ({bus.stretch} "
            f"stretched), {len(bus.writes)} bus writes")
    if grouped:
        note += f"; tiers of more than {MAX_ROWS_PER_TIER} buses: a row stands for several, " \
                "shaded by how many are driven"
    fig.text(0.5, 1 - 18 / height, title, ha="center", va="top", fontsize=9)
    fig.text(0.5, 1 - 34 / height, note, ha="center", va="top", fontsize=7)
    return svg.to_svg(fig, titles)
