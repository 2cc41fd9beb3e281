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
import os
from dataclasses import replace

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
    does), or the Dask cluster whose scheduler is at `scheduler`."""
    graph = build_graph(chain, replace(options, verify=False))
    timing = options.timing
    largest = vamp_ops(graph)
    ks = budgets(smallest_network(graph), largest)
    thorough = largest <= THOROUGH_UP_TO
    workers = min(available_cores() if workers is None else workers, len(ks))
    rows, seen = [], set()
    computed = _cluster_rows(graph, timing, ks, thorough, scheduler, progress) if scheduler is not None else \
        _budget_rows(graph, timing, ks, thorough, workers, progress)
    for row in computed:
        figures = tuple(row[c] for c in FIGURES)
        if figures not in seen:            # a larger budget the schedule did not use
            seen.add(figures)
            rows.append(row)
    for label, name, share in compared_layouts():     # the registry's (vampc.schedule.registry)
        layout, sched = layout_and_schedule(graph, timing, name,
                                            LayoutRequest(share, verify=False))
        rows.append(_row(label, graph, sched, layout, bounds(graph, timing, layout.vamp_count)))
    _mark_pareto(rows)
    return sorted(rows, key=lambda r: (r["vamps"], r["interval_flops"], r["latency_flops"]))


def _budget_row(graph, timing, k: int, thorough: bool) -> dict:
    layout, sched, b = budget_schedule(graph, timing, k, verify=False, thorough=thorough)
    return _row(f"budget {k}", graph, sched, layout, b)


def _budget_rows(graph, timing, ks: list, thorough: bool, workers: int, progress):
    """The budgets' rows in budget order, computed here or by `workers` forked processes (each
    inherits the graph when it starts; a task sends a budget and returns a row). Workers ignore
    Ctrl-C: an interrupt, a signal or a failed budget in this process stops them at once."""
    import multiprocessing
    if workers > 1 and not hasattr(os, "fork"):
        import warnings

        from vampc.errors import VampcWarning
        warnings.warn(VampcWarning(f"--workers {workers}: this platform cannot fork; the budgets run "
                                   "in this process"), stacklevel=3)
    if workers <= 1 or not hasattr(os, "fork") or multiprocessing.current_process().daemon:
        for done, k in enumerate(ks):
            yield _budget_row(graph, timing, k, thorough)
            if progress is not None:
                progress(done + 1, len(ks))
        return
    from concurrent.futures import ProcessPoolExecutor, as_completed
    pool = ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("fork"),
                               initializer=_worker_start, initargs=(graph, timing, thorough))
    try:
        futures = {pool.submit(_worker_row, k): i for i, k in enumerate(ks)}
        out = [None] * len(ks)
        for done, future in enumerate(as_completed(futures), 1):
            out[futures[future]] = future.result()
            if progress is not None:
                progress(done, len(ks))
    except BaseException:
        for proc in list(getattr(pool, "_processes", {}).values()):     # do not wait for the queue
            proc.kill()
        pool.shutdown(wait=False, cancel_futures=True)
        raise
    pool.shutdown()
    yield from out


_WORKER = None        # a forked worker's (graph, timing, thorough)
SCHEDULER_TIMEOUT = "10s"       # how long to try to reach a Dask scheduler


def _worker_start(graph, timing, thorough: bool) -> None:
    """A worker's start: keep the graph; leave Ctrl-C to the process that started it."""
    import signal
    global _WORKER
    _WORKER = (graph, timing, thorough)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    for name in ("SIGTERM", "SIGHUP"):     # not vampc's handlers: a worker holds nothing to clean up
        if hasattr(signal, name):
            signal.signal(getattr(signal, name), signal.SIG_DFL)


def _worker_row(k: int) -> dict:
    graph, timing, thorough = _WORKER
    return _budget_row(graph, timing, k, thorough)


def _cluster_rows(graph, timing, ks: list, thorough: bool, address: str, progress) -> list:
    """The budgets' rows in budget order, computed on a Dask cluster; anything the cluster does
    wrong (no workers, a worker without vampc, a lost worker, an address it cannot use) is one
    line."""
    from vampc.errors import VampcError
    try:
        from distributed import Client, as_completed
    except ImportError:
        raise VampcError("--scheduler needs dask.distributed: pip install \"vampc[dask]\"") from None
    try:
        client = Client(address, timeout=SCHEDULER_TIMEOUT)
    except Exception as exc:  # noqa: BLE001 - OSError, TimeoutError, TypeError for tls:// ...
        raise VampcError(f"--scheduler {address}: cannot reach a Dask scheduler there "
                         f"({type(exc).__name__}: {_one_line(exc)})") from None
    with client:
        try:
            shared = client.scatter(graph, broadcast=True)
            futures = [client.submit(_budget_row, shared, timing, k, thorough, pure=False) for k in ks]
            index = {f.key: i for i, f in enumerate(futures)}
            out = [None] * len(ks)
            for done, future in enumerate(as_completed(futures), 1):
                out[index[future.key]] = future.result()
                if progress is not None:
                    progress(done, len(ks))
        except Exception as exc:  # noqa: BLE001 - whatever the cluster raises
            raise VampcError(f"--scheduler {address}: the cluster failed ({type(exc).__name__}: "
                             f"{_one_line(exc)})") from None
    return out


def _one_line(exc: Exception) -> str:
    return " ".join(str(exc).split())[:300]


def _row(label, graph, sched, layout, b) -> dict:
    net = allocate(graph, sched, layout, verify=False)
    plain = [len(v.slots) == 1 and len(v.a) == 1 and len(v.b) == 1 for v in net.vamps]
    ib = b.interval_bound
    return {"layout": label, "vamps": len(net.vamps), "latency_flops": sched.latency,
            "interval_flops": sched.interval, "buffer_stages": net.buffer_stages,
            "control_registers": sum(4 if p else 6 * len(v.slots) for v, p in zip(net.vamps, plain)),
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


def render_text(rows: list[dict]) -> str:
    """An aligned table; the fronts marked: L on the latency-VAMP front, I on the interval-VAMP
    front, * Pareto-optimal in all four figures."""
    head = (f"{'':4}{'layout':<24}{'VAMPs':>7}{'latency':>9}{'bound':>7}{'gap':>7}{'interval':>10}"
            f"{'bound':>7}{'gap':>7}{'buffers':>9}{'ctrl regs':>11}{'mux in':>8}{'host wr':>9}")
    fronts = [sum(r[k] for r in rows) for k in FRONTS]
    lines = [f"trade-off (flops): L on the latency-VAMP front ({fronts[1]} of {len(rows)} points), I on "
             f"the interval-VAMP front ({fronts[2]}), * Pareto-optimal in VAMPs, latency, interval and "
             f"buffer stages ({fronts[0]})", head]
    for r in rows:
        mark = ("L" if r["pareto_latency"] else " ") + ("I" if r["pareto_interval"] else " ") + \
            ("*" if r["pareto"] else " ")
        lines.append(f"{mark:4}{r['layout']:<24}{r['vamps']:>7}"
                     f"{r['latency_flops']:>9}{r['latency_bound']:>7}{r['latency_gap_pct']:>6}%"
                     f"{r['interval_flops']:>10}{r['interval_bound']:>7}{r['interval_gap_pct']:>6}%"
                     f"{r['buffer_stages']:>9}{r['control_registers']:>11}{r['mux_inputs']:>8}"
                     f"{r['host_writes_per_set']:>9}")
    return "\n".join(lines) + "\n"
