"""The report's pictures and pages for one compiled robot: what `vampc report --timing --network
--dot --html` write (matplotlib is imported only here, and only when a picture is asked for)."""
from __future__ import annotations

from vampc.gcpause import gc_paused
from vampc.textio import count


def title(rep: dict) -> str:
    """'puma560, 6 joints, linear recursion, systolic layout: latency 61 flops, interval 4'."""
    layout = rep["layout"] + (", shared passes" if rep.get("share_passes") else "")
    return (f"{rep['robot']}, {count(rep['joints'], 'joint')}, {rep['recursion']} recursion, {layout} layout: "
            f"latency {rep['latency']['flops']} flops, a torque set every {rep['interval_flops']}")


def timing(c, rep: dict) -> str:
    """The timing chart as SVG."""
    from vampc.report.timing_chart import timing_svg
    return timing_svg(c.graph, c.layout, c.schedule, title(rep))


def network(c, rep: dict, focus=None) -> str:
    """The network drawing as SVG (`focus`: positions (A, B) only)."""
    from vampc.report.network_drawing import network_svg
    return network_svg(c.graph, c.layout, c.network, title(rep), c.schedule.critical_path, focus)


def reservation(c, rep: dict) -> str:
    """The modulo reservation table as SVG."""
    from vampc.report.reservation import reservation_svg
    return reservation_svg(c.graph, c.layout, c.schedule, title(rep))


def dot(c, rep: dict) -> str:
    """The network and the dataflow graph as Graphviz text."""
    from vampc.report.dot import report_dot
    return report_dot(c.graph, c.layout, c.network, rep["robot"], c.schedule.critical_path)


@gc_paused()
def make(c, rep: dict, wanted, focus=None) -> dict[str, str | bytes]:
    """The content of every output option in `wanted` (--timing, --network, --reservation, --dot,
    --html, --bus-chart: a set, or a dict of each to its path, whose name says the picture's format:
    `svg.format_of`); each picture is drawn once even when the page needs it too (twice where it
    goes to a PNG or PDF: the page holds SVG). `focus`: --focus A:B for the drawing."""
    from vampc.report import svg
    formats = {o: svg.format_of(p) for o, p in wanted.items()} if isinstance(wanted, dict) else {}
    wanted = set(wanted)
    drawers = {"--timing": lambda: timing(c, rep), "--network": lambda: network(c, rep, focus),
               "--reservation": lambda: reservation(c, rep)}
    if "--bus-chart" in wanted:
        from vampc.report.bus_chart import bus_chart_svg
        drawers["--bus-chart"] = lambda: bus_chart_svg(c.network, title(rep))
    out: dict[str, str | bytes] = {}
    page: dict[str, str] = {}
    for option, draw in drawers.items():
        fmt = formats.get(option, "svg")
        if option in wanted:
            with svg.drawn_as(fmt):
                out[option] = draw()
        if "--html" in wanted and option != "--bus-chart":
            page[option] = out[option] if option in wanted and fmt == "svg" else draw()
    if "--dot" in wanted:
        out["--dot"] = dot(c, rep)
    if "--html" in wanted:
        from vampc.report.html import page as html_page
        out["--html"] = html_page(rep, page["--timing"], page["--network"], page["--reservation"])
    return out
