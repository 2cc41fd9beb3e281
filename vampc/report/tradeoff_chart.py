"""The trade-off curve (`vampc report --tradeoff --curve FILE.svg`): latency and interval against
VAMPs, one point per row of vampc.report.tradeoff, on two panels sharing a logarithmic VAMP axis.

Budget points are dots joined in order of VAMPs, Pareto-optimal ones filled, the others hollow; the
folded and systolic layouts are squares, labelled. Every point is an SVG group `latency-I` /
`interval-I` (I: the row's index) with a tooltip giving the row's figures, so a test or a script can
find each point; the output is deterministic (vampc.report.svg).
"""
from __future__ import annotations

from vampc.report import svg

WIDTH, HEIGHT = 760.0, 520.0
BUDGET, LAYOUT, FRONT = "#1f77b4", "#d62728", "#2ca02c"


def curve_svg(rows: list[dict], title: str) -> str:
    """The SVG text of the curve for `rows` (tradeoff() order)."""
    with svg.settings():
        fig = svg.figure(WIDTH, HEIGHT)
        top = fig.add_axes((0.09, 0.55, 0.86, 0.36))
        bottom = fig.add_axes((0.09, 0.09, 0.86, 0.36), sharex=top)
        titles: dict[str, str] = {}
        for ax, key, name in ((top, "latency_flops", "latency"), (bottom, "interval_flops", "interval")):
            _panel(ax, rows, key, name, titles)
        top.set_title(title, fontsize=10)
        top.tick_params(labelbottom=False)
        bottom.set_xlabel("VAMPs (log scale)")
        top.legend(handles=_legend(top), loc="upper right", fontsize=7, frameon=False)
        return svg.to_svg(fig, titles)


def _panel(ax, rows, key: str, name: str, titles: dict) -> None:
    budget = [(r["vamps"], r[key]) for r in rows if r["layout"].startswith("budget")]
    if budget:
        (line,) = ax.plot(*zip(*budget), color=BUDGET, linewidth=0.8, zorder=1)
        line.set_gid(f"{name}-budget-line")
    shown = 0
    for i, r in enumerate(rows):
        is_layout = not r["layout"].startswith("budget")
        colour = LAYOUT if is_layout else BUDGET
        (point,) = ax.plot([r["vamps"]], [r[key]], marker="s" if is_layout else "o", markersize=6,
                           markeredgecolor=FRONT if r["pareto"] else colour, markeredgewidth=1.2,
                           markerfacecolor=colour if r["pareto"] else "white", linestyle="none",
                           zorder=3)
        gid = f"{name}-{i}" + ("-pareto" if r["pareto"] else "")
        point.set_gid(gid)
        titles[gid] = (f"{r['layout']}: {r['vamps']} VAMPs, latency {r['latency_flops']} flops "
                       f"(bound {r['latency_bound']}), interval {r['interval_flops']} flops (bound "
                       f"{r['interval_bound']}), {r['buffer_stages']} buffer stages"
                       + (", Pareto-optimal" if r["pareto"] else ""))
        if is_layout:          # labels stacked upwards: the layouts often share a latency
            ax.annotate(r["layout"], (r["vamps"], r[key]), textcoords="offset points",
                        xytext=(6, 5 + 10 * shown), fontsize=7, color=LAYOUT)
            shown += 1
    from matplotlib.ticker import ScalarFormatter
    ax.set_xscale("log")
    ax.set_yscale("log")
    for axis in (ax.xaxis, ax.yaxis):        # 100, not 10², on both axes
        axis.set_major_formatter(ScalarFormatter())
    ax.set_ylabel(f"{name} (flops, log scale)")
    ax.grid(True, which="major", linewidth=0.3, color="#bbbbbb")


def _legend(ax):
    from matplotlib.lines import Line2D
    return [Line2D([], [], marker="o", color=BUDGET, markerfacecolor=BUDGET, markeredgecolor=FRONT,
                   linestyle="-", linewidth=0.8, label="VAMP budget, Pareto-optimal"),
            Line2D([], [], marker="o", color=BUDGET, markerfacecolor="white", linestyle="none",
                   label="VAMP budget, dominated"),
            Line2D([], [], marker="s", color=LAYOUT, markerfacecolor=LAYOUT, markeredgecolor=FRONT,
                   linestyle="none", label="folded / systolic layout")]
