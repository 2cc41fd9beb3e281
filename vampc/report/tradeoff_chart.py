"""The trade-off curve (`vampc report --tradeoff --curve FILE.svg`): latency and interval against
VAMPs, one point per row of vampc.report.tradeoff, on two panels sharing a logarithmic VAMP axis.

Budget points are dots joined in order of VAMPs; the folded and systolic layouts are squares, each
labelled with a leader line to its point. On each panel the points on that panel's two-dimensional
front (no other point has at most as many VAMPs and at most its latency, or interval, and fewer of
one) are filled and joined by a green staircase; the others are hollow. Axes are logarithmic with
integer ticks. Every point is an SVG group `latency-I` / `interval-I` (I: the row's index; `-pareto`
appended when on that panel's front) with a tooltip giving the row's figures, so a test or a script
can find each point; the output is deterministic (vampc.report.svg).
"""
from __future__ import annotations

from vampc.report import svg
from vampc.textio import count

WIDTH, HEIGHT = 760.0, 580.0
BUDGET, LAYOUT, FRONT = "#1f77b4", "#d62728", "#2ca02c"


def curve_svg(rows: list[dict], title: str) -> str:
    """The SVG text of the curve for `rows` (tradeoff() order)."""
    with svg.settings():
        fig = svg.figure(WIDTH, HEIGHT)
        top = fig.add_axes((0.09, 0.58, 0.86, 0.34))
        bottom = fig.add_axes((0.09, 0.19, 0.86, 0.34), sharex=top)
        titles: dict[str, str] = {}
        for ax, key, name in ((top, "latency_flops", "latency"), (bottom, "interval_flops", "interval")):
            _panel(ax, rows, key, name, titles)
        top.set_title(title, fontsize=10)
        top.tick_params(labelbottom=False)
        bottom.set_xlabel("VAMPs (log scale)")
        fig.legend(handles=_legend(top), loc="lower center", ncol=2, fontsize=7, frameon=False)
        return svg.to_svg(fig, titles)


def _panel(ax, rows, key: str, name: str, titles: dict) -> None:
    front_key = f"pareto_{name}"
    budget = [(r["vamps"], r[key]) for r in rows if r["layout"].startswith("budget")]
    if budget:
        (line,) = ax.plot(*zip(*budget), color=BUDGET, linewidth=0.8, zorder=1)
        line.set_gid(f"{name}-budget-line")
    front = sorted((r["vamps"], r[key]) for r in rows if r[front_key])
    if front:                 # the staircase: each front point holds until the next one
        (line,) = ax.step(*zip(*front), where="post", color=FRONT, linewidth=1.0, zorder=2)
        line.set_gid(f"{name}-front")
    layouts = []
    for i, r in enumerate(rows):
        is_layout = not r["layout"].startswith("budget")
        on = r[front_key]
        colour = LAYOUT if is_layout else BUDGET
        (point,) = ax.plot([r["vamps"]], [r[key]], marker="s" if is_layout else "o", markersize=6,
                           markeredgecolor=FRONT if on else colour, markeredgewidth=1.2,
                           markerfacecolor=colour if on else "white", linestyle="none", zorder=3)
        gid = f"{name}-{i}" + ("-pareto" if on else "")
        point.set_gid(gid)
        titles[gid] = (f"{r['layout']}: {count(r['vamps'], 'VAMP')}, latency {r['latency_flops']} flops "
                       f"(bound {r['latency_bound']}), interval {r['interval_flops']} flops (bound "
                       f"{r['interval_bound']}), {r['buffer_stages']} buffer stages"
                       + (f"; on the {name}-VAMP front" if on else "")
                       + ("; Pareto-optimal in all four" if r["pareto"] else ""))
        if is_layout:
            layouts.append(r)
    # the layouts' labels in a column at the right edge, in the order of their points from the top,
    # each with a leader line to its point (they often share a VAMP count or a latency)
    layouts.sort(key=lambda r: (-r[key], r["vamps"]))
    for j, r in enumerate(layouts):
        ax.annotate(r["layout"], (r["vamps"], r[key]), xycoords="data",
                    xytext=(0.99, 0.95 - 0.13 * j), textcoords="axes fraction", ha="right", va="top",
                    fontsize=7, color=LAYOUT,
                    arrowprops=dict(arrowstyle="-", color=LAYOUT, linewidth=0.5, shrinkA=2, shrinkB=4))
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter
    ax.set_xscale("log")
    ax.set_yscale("log")
    for axis in (ax.xaxis, ax.yaxis):        # 100, not 10² or 100.0; 1-2-5 ticks, all integers
        axis.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
        axis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:,.0f}" if v >= 1 else ""))
        axis.set_minor_formatter(NullFormatter())
    lowest = min((r[key] for r in rows), default=None)
    if lowest is not None and lowest >= 1:     # the floor the front flattens on, named on the axis
        ax.set_yticks([lowest], minor=True)    # (no 1-2-5 tick fell there: the Puma's 61, 21 for
        ax.yaxis.set_minor_formatter(          # one joint)
            FuncFormatter(lambda v, _, low=lowest: f"{v:,.0f}" if v == low else ""))
    ax.set_ylabel(f"{name} (flops, log scale)")
    ax.grid(True, which="major", linewidth=0.3, color="#bbbbbb")


def _legend(ax):
    from matplotlib.lines import Line2D
    return [Line2D([], [], marker="o", color=BUDGET, markerfacecolor=BUDGET, markeredgecolor=FRONT,
                   linestyle="-", linewidth=0.8, label="VAMP budget on the panel's front"),
            Line2D([], [], marker="o", color=BUDGET, markerfacecolor="white", linestyle="none",
                   label="VAMP budget, dominated (more VAMPs for no less time)"),
            Line2D([], [], marker="s", color=LAYOUT, markerfacecolor=LAYOUT, markeredgecolor=FRONT,
                   linestyle="none", label="folded / systolic layout on the panel's front"),
            Line2D([], [], marker="s", color=LAYOUT, markerfacecolor="white", linestyle="none",
                   label="folded / systolic layout, dominated"),
            Line2D([], [], color=FRONT, linewidth=1.0,
                   label="front: fewest VAMPs for each latency (top), interval (bottom)")]
