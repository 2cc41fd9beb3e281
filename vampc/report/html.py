"""The HTML report (`vampc report --html FILE.html`): one self-contained page — the summary, every
table and the three pictures (timing chart, network, reservation table) inline (SVG elements, styles in the page), nothing fetched from anywhere."""
from __future__ import annotations

import html

from vampc.report.sections import tables
from vampc.report.svg import inline
from vampc.report.table import html_text, render_html
from vampc.report.text import summary_pairs
from vampc.textio import count

STYLE = """
body { font-family: sans-serif; font-size: 13px; margin: 1.5em; color: #222; }
h1 { font-size: 20px; } h2 { font-size: 16px; margin-top: 2em; } h3 { font-size: 14px; }
table { border-collapse: collapse; margin: 0.5em 0; }
th, td { border: 1px solid #ccc; padding: 2px 6px; vertical-align: top; }
th { background: #f0f0f0; } td.r, th.r { text-align: right; } td.l, th.l { text-align: left; }
.picture { overflow: auto; max-height: 90vh; border: 1px solid #ddd; margin: 0.5em 0; }
ul { margin: 0.2em 0 1em 1.2em; padding: 0; color: #444; }
"""


def page(rep: dict, timing_svg: str, network_svg: str, reservation_svg: str = "") -> str:
    """The whole page as text."""
    esc = html.escape
    summary = "".join(f"<tr><th class=\"l\">{esc(label)}</th><td class=\"l\">{html_text(value)}</td></tr>\n"
                      for label, value in summary_pairs(rep))
    body = [f"<h1>vampc report: {esc(rep['robot'])} ({count(rep['joints'], 'joint')}, {esc(rep['recursion'])} "
            f"recursion, {esc(rep['layout'])} layout)</h1>",
            f'<section id="summary"><h2>Summary</h2><table>{summary}</table></section>',
            '<section id="timing"><h2>Timing chart</h2><div class="picture">'
            f"{inline(timing_svg, 'timing')}</div></section>",
            '<section id="network"><h2>Network</h2><div class="picture">'
            f"{inline(network_svg, 'network')}</div></section>",
            *(['<section id="reservation"><h2>Steady state: the modulo reservation table</h2>'
               f'<div class="picture">{inline(reservation_svg, "reservation")}</div></section>']
              if reservation_svg else []),
            "<h2>Tables</h2>", *[render_html(t) for t in tables(rep)]]
    return ("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
            f"<title>vampc report: {esc(rep['robot'])}</title><style>{STYLE}</style></head>\n<body>\n"
            + "\n".join(body) + "\n</body></html>\n")


def tradeoff_page(rows: list[dict], title: str, curve_svg: str) -> str:
    """`vampc report --tradeoff --html FILE.html`: the sweep's table and its curve on one page."""
    from vampc.report.table import Table
    from vampc.report.tradeoff import notes
    esc = html.escape
    marks = lambda r: ("L" if r["pareto_latency"] else "") + ("I" if r["pareto_interval"] else "") + \
        ("*" if r["pareto"] else "")
    table = Table("tradeoff", f"Trade-off: {title} (flops)",
                  ("front", "layout", "VAMPs", "latency", "bound", "gap", "interval", "bound", "gap",
                   "buffer stages", "control registers", "mux inputs", "host writes"),
                  tuple((marks(r), r["layout"], f"{r['vamps']:,}", f"{r['latency_flops']:,}",
                         f"{r['latency_bound']:,}", f"{r['latency_gap_pct']}%", f"{r['interval_flops']:,}",
                         f"{r['interval_bound']:,}", f"{r['interval_gap_pct']}%", f"{r['buffer_stages']:,}",
                         f"{r['control_registers']:,}", f"{r['mux_inputs']:,}",
                         f"{r['host_writes_per_set']:,}") for r in rows),
                  ("front: L on the latency-VAMP front, I on the interval-VAMP front, * Pareto-optimal "
                   "in VAMPs, latency, interval and buffer stages (README, VAMP budgets and the trade-off)",
                   *(note.replace("`", "") for note in notes(rows))),     # (Markdown's quotes)
                  align="llrrrrrrrrrrr")
    body = [f"<h1>vampc trade-off: {esc(title)}</h1>",
            '<section id="curve"><h2>Curve</h2><div class="picture">'
            f"{inline(curve_svg, 'curve')}</div></section>", render_html(table)]
    return ("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
            f"<title>vampc trade-off: {esc(title)}</title><style>{STYLE}</style></head>\n<body>\n"
            + "\n".join(body) + "\n</body></html>\n")
