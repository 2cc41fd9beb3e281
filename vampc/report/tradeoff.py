"""The latency / interval / VAMP trade-off (`vampc report --tradeoff`): VAMP budgets from the smallest
network that runs the graph up to one VAMP per VAMP-op, beside the folded and systolic layouts, with
the Pareto-optimal points marked.

Every point is compiled for real (budgeted schedule, allocation) and its figures read off the
network: VAMPs used, latency, interval, delay-buffer stages, control registers, multiplexer inputs and
host writes per set, with the interval and latency bounds of vampc.schedule.budget and the gaps. A
point is Pareto-optimal (`pareto`) when no other point is at least as good in VAMPs, latency, interval
and buffer stages and better in one; in four dimensions most points are, so the two fronts a picture
can show are kept too: `pareto_latency` (no other point has at most as many VAMPs and at most its
latency, and fewer of one) and `pareto_interval` (the same with the interval). Every budget is swept when there are at most MAX_STEPS of them, else
MAX_STEPS budgets spaced geometrically over the range (fewer where rounding makes two equal); a budget whose schedule leaves VAMPs idle and repeats a smaller budget's point is shown
once. Graphs up to THOROUGH_UP_TO VAMP-ops get the latency search `vampc compile --vamps` does; larger
ones a cheaper one (vampc.schedule.budget._quick_for: no shortening below 10% above the latency
bound; the sweep would take too long otherwise).

The budgets are independent: `workers` processes (default: one per available core) each build the
graph once and compute the budgets handed to them; the rows are put back in budget order before the
repeats are dropped, so the result is the same as one process gives (a test compares both). With
`scheduler` (a Dask scheduler's address, `--scheduler tcp://HOST:8786`), the graph is broadcast to
the cluster's workers once and each budget is one task (dask.distributed, the `dask` extra).
"""
from __future__ import annotations

import csv
import io

from vampc.background import available_cores
from vampc.compiler import CompileOptions, build_graph
from vampc.gcpause import gc_paused
from vampc.network.allocate import allocate
from vampc.report.configs import compared_layouts
from vampc.report.counts import gap_pct
from vampc.schedule.budget import bounds, budget_schedule, smallest_network, vamp_ops
from vampc.schedule.layout import layout_and_schedule
from vampc.schedule.registry import LayoutRequest

MAX_STEPS = 48
THOROUGH_UP_TO = 2000    # VAMP-ops: larger graphs get the cheaper search (_quick_for)
COLUMNS = ("layout", "vamps", "latency_flops", "interval_flops", "buffer_stages",
           "control_registers", "mux_inputs", "host_writes_per_set", "interval_bound",
           "interval_gap_pct", "latency_bound", "latency_gap_pct", "pareto", "pareto_latency",
           "pareto_interval")


def budgets(smallest: int, largest: int, steps: int = MAX_STEPS) -> list[int]:
    """VAMP budgets from `smallest` to `largest`: all of them, or `steps` geometrically spaced."""
    if largest - smallest + 1 <= steps:
        return list(range(smallest, largest + 1))
    ratio = (largest / smallest) ** (1 / (steps - 1))
    out = sorted({min(largest, max(smallest, round(smallest * ratio ** i))) for i in range(steps)})
    return out


@gc_paused()
def tradeoff(chain, options: CompileOptions, progress=None, workers: int | None = 1,
             scheduler: str | None = None) -> list[dict]:
    """One row per point (see the module docstring), in order of VAMPs; `workers` processes compute
    the budgets (1, the default: this process; None: one per available core, as `vampc report`
    does), or the Dask cluster whose scheduler is at `scheduler`. Every stage of every point is
    checked as a compile's is (options.verify: --verify, the default; --no-verify leaves them out)."""
    verify = options.verify
    graph = build_graph(chain, options)
    timing = options.timing
    largest = vamp_ops(graph)
    ks = budgets(smallest_network(graph), largest)
    thorough = largest <= THOROUGH_UP_TO
    workers = min(available_cores() if workers is None else workers, len(ks))
    rows, seen = [], set()
    computed = _budget_rows(graph, timing, ks, thorough, workers, scheduler, progress, verify)
    for row in computed:
        figures = tuple(row[c] for c in FIGURES)
        if figures not in seen:            # a larger budget the schedule did not use
            seen.add(figures)
            rows.append(row)
    for label, name, share in compared_layouts():     # the registry's (vampc.schedule.registry)
        layout, sched = layout_and_schedule(graph, timing, name,
                                            LayoutRequest(share, verify=verify))
        rows.append(_row(label, graph, sched, layout, bounds(graph, timing, layout.vamp_count),
                         verify))
    _mark_pareto(rows)
    return sorted(rows, key=lambda r: (r["vamps"], r["interval_flops"], r["latency_flops"]))


def _budget_row(graph, timing, k: int, thorough: bool, verify: bool = False) -> dict:
    layout, sched, b = budget_schedule(graph, timing, k, verify=verify, thorough=thorough)
    return _row(f"budget {k}", graph, sched, layout, b, verify)


def _budget_task(context, k: int) -> dict:
    graph, timing, thorough, verify = context
    return _budget_row(graph, timing, k, thorough, verify)


def _budget_rows(graph, timing, ks: list, thorough: bool, workers: int, scheduler, progress,
                 verify: bool = False):
    """The budgets' rows in budget order, computed here, by `workers` forked processes or on the
    Dask cluster at `scheduler` (vampc.parallel)."""
    from vampc import parallel
    out = [None] * len(ks)
    client = parallel.connect(scheduler, SCHEDULER_TIMEOUT) if scheduler is not None else None
    try:
        parallel.run_tasks(_budget_task, (graph, timing, thorough, verify), ks, out.__setitem__, workers,
                           scheduler, client, progress, warn_stack=5)
    finally:
        if client is not None:
            client.close()
    return out


SCHEDULER_TIMEOUT = "10s"       # how long to try to reach a Dask scheduler


def _row(label, graph, sched, layout, b, verify: bool = False) -> dict:
    net = allocate(graph, sched, layout, verify=verify)
    from vampc.report.counts import control_registers
    ib = b.interval_bound
    return {"layout": label, "vamps": len(net.vamps), "latency_flops": sched.latency,
            "interval_flops": sched.interval, "buffer_stages": net.buffer_stages,
            "control_registers": sum(control_registers(len(v.slots), len(v.a), len(v.b), net.period)
                                     for v in net.vamps),
            "mux_inputs": sum(len(v.a) - 1 + len(v.b) - 1 for v in net.vamps),
            "host_writes_per_set": sum(len(p.entries) for p in net.ports),
            "interval_bound": ib, "interval_gap_pct": gap_pct(sched.interval, ib),
            "latency_bound": b.latency, "latency_gap_pct": gap_pct(sched.latency, b.latency)}


KEYS = ("vamps", "latency_flops", "interval_flops", "buffer_stages")
FIGURES = KEYS + ("control_registers", "mux_inputs", "host_writes_per_set")


FRONTS = {"pareto": KEYS, "pareto_latency": ("vamps", "latency_flops"),
          "pareto_interval": ("vamps", "interval_flops")}


def _mark_pareto(rows: list[dict]) -> None:
    for name, keys in FRONTS.items():
        for r in rows:
            r[name] = not any(all(o[k] <= r[k] for k in keys) and any(o[k] < r[k] for k in keys)
                              for o in rows)


def render_csv(rows: list[dict]) -> str:
    """One CSV row per point, COLUMNS in order."""
    out = io.StringIO()
    writer = csv.DictWriter(out, fieldnames=COLUMNS, lineterminator="\n")
    writer.writeheader()
    writer.writerows(rows)
    return out.getvalue()


def _caption(rows: list[dict]) -> str:
    """What the marks say, with the size of each front."""
    fronts = [sum(r[k] for r in rows) for k in FRONTS]
    return (f"(flops): L on the latency-VAMP front ({fronts[1]} of {len(rows)} points), I on the "
            f"interval-VAMP front ({fronts[2]}), * Pareto-optimal in VAMPs, latency, interval and "
            f"buffer stages ({fronts[0]})")


def _marks(r: dict, star: str = "*", blank: str = " ") -> str:
    """A point's marks: L, I and * where it is on each front, `blank` where not."""
    return "".join(mark if r[key] else blank for key, mark in
                   (("pareto_latency", "L"), ("pareto_interval", "I"), ("pareto", star)))


def render_markdown(rows: list[dict]) -> str:
    """The table of render_text as Markdown, for a design review: the same columns and marks."""
    lines = [f"**Trade-off** {_caption(rows)}", "",
             "| front | layout | VAMPs | latency | bound | gap | interval | bound | gap | buffers | "
             "ctrl regs | mux in | host wr |",
             "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        marks = _marks(r, "\\*", "")          # Markdown's * escaped
        lines.append(f"| {marks} | {r['layout']} | {r['vamps']} | {r['latency_flops']} | "
                     f"{r['latency_bound']} | {r['latency_gap_pct']}% | {r['interval_flops']} | "
                     f"{r['interval_bound']} | {r['interval_gap_pct']}% | {r['buffer_stages']} | "
                     f"{r['control_registers']} | {r['mux_inputs']} | {r['host_writes_per_set']} |")
    said = notes(rows)
    return "\n".join(lines + ["", *said] if said else lines) + "\n"


def render_text(rows: list[dict]) -> str:
    """An aligned table; the fronts marked: L on the latency-VAMP front, I on the interval-VAMP
    front, * Pareto-optimal in all four figures."""
    head = (f"{'':4}{'layout':<24}{'VAMPs':>7}{'latency':>9}{'bound':>7}{'gap':>7}{'interval':>10}"
            f"{'bound':>7}{'gap':>7}{'buffers':>9}{'ctrl regs':>11}{'mux in':>8}{'host wr':>9}")
    lines = [f"trade-off {_caption(rows)}", head]
    for r in rows:
        lines.append(f"{_marks(r):4}{r['layout']:<24}{r['vamps']:>7}"
                     f"{r['latency_flops']:>9}{r['latency_bound']:>7}{r['latency_gap_pct']:>6}%"
                     f"{r['interval_flops']:>10}{r['interval_bound']:>7}{r['interval_gap_pct']:>6}%"
                     f"{r['buffer_stages']:>9}{r['control_registers']:>11}{r['mux_inputs']:>8}"
                     f"{r['host_writes_per_set']:>9}")
    return "\n".join(lines + notes(rows)) + "\n"


def notes(rows: list[dict]) -> list[str]:
    """What the table says below it, in every format (text, Markdown, HTML): where a budget's
    latency is longer than one with fewer VAMPs (the Markdown and HTML tables had left it out: a
    new user's find)."""
    slower = _slower_than_fewer(rows)
    if not slower:
        return []
    more, fewer = slower
    return [f"{more['layout']}: latency {more['latency_flops']} flops, longer than "
            f"{fewer['layout']}'s {fewer['latency_flops']} with fewer VAMPs: each budget is "
            f"scheduled at the smallest interval the search reaches near its bound (as `--vamps` "
            f"does: README, VAMP budgets); `vampc compile --vamps {more['vamps']} "
            "--interval I` with a longer interval may shorten its latency"]


def _slower_than_fewer(rows: list[dict]):
    """The first budget whose latency is longer than a budget's with fewer VAMPs, and that one (a
    table read as 'more VAMPs, never slower' misleads there), or None."""
    budgets = sorted((r for r in rows if r["layout"].startswith("budget")), key=lambda r: r["vamps"])
    for k, r in enumerate(budgets):
        fewer = [b for b in budgets[:k] if b["latency_flops"] < r["latency_flops"]]
        if fewer:
            return r, min(fewer, key=lambda b: b["latency_flops"])
    return None
