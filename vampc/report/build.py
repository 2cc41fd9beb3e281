"""The whole report of one compiled robot as one dictionary (what `vampc report --format json`
prints, checked against schemas/report.schema.json): the summary figures (vampc.report.counts),
the layout and prefix comparisons, Table O.1, processors, packages, buffering and wiring, and —
with a clock rate — times. Every figure is read off the compiled IRs of the report's configuration
and of the configurations it is compared with (vampc.report.configs); the paper's figures come from
vampc.report.paper and are labelled as the paper's."""
from __future__ import annotations

from vampc.gcpause import gc_paused
from vampc.kinds import Recursion
from vampc.report.clock import add_clock
from vampc.report.compare import compare_prefixes, layout_rows
from vampc.report.configs import ALLOCATE_LIMIT, configurations
from vampc.report.counts import summary, unused_vamps
from vampc.report.processors import packages, processors
from vampc.report.table_o1 import table_o1
from vampc.report.wiring import wiring

REPORT_VERSION = 2


REPORT_STAGES = ("configurations", "prefix shapes", "Table O.1", "processors", "packages", "wiring",
                 "engineering")


@gc_paused()
def build_report(c, clock_hz: float | None = None, pins: int | None = None,
                 figures: dict | None = None, cpu_reference: bool = False, stage=None) -> dict:
    """The report of `c` (a vampc.compiler.Compiled), with times at `clock_hz` when given and
    packages of `pins` pins beside the 40-pin ones. Above ALLOCATE_LIMIT ops the comparisons that
    would each compile the robot again (prefix shapes, the log graph with the other leaf style)
    are left out and `allocation.omitted` names them. `figures`: summary(c) if already made.
    `cpu_reference`: measure a CPU's time per set here (vampc.report.engineering.cpu_reference).
    `stage(name)` is told as each of REPORT_STAGES starts (a progress bar's)."""
    import math
    import numbers
    if clock_hz is not None and not (isinstance(clock_hz, numbers.Real)
                                     and not isinstance(clock_hz, bool)
                                     and math.isfinite(clock_hz) and clock_hz > 0):
        # (a math domain error: a new user's find)
        from vampc.errors import VampcUsageError
        raise VampcUsageError(f"build_report: clock_hz {clock_hz!r}: give a clock rate in Hz "
                              "above 0")
    if clock_hz is not None:      # (a numpy number went into the report, which json could not dump)
        clock_hz = int(clock_hz) if isinstance(clock_hz, numbers.Integral) else float(clock_hz)
    stage = stage or (lambda name: None)
    rep = dict(figures) if figures is not None else summary(c)
    rep["vamps"] = {**rep["vamps"], "unused": unused_vamps(c)}
    stage("configurations")
    configs = configurations(c)
    big = len(c.graph.compute_nodes()) > ALLOCATE_LIMIT
    rep["report_version"] = REPORT_VERSION
    rep["layout_comparison"] = layout_rows(configs, c.graph.recursion)
    if c.graph.recursion is Recursion.LOG and not big:
        stage("prefix shapes")
        infeasible: list = []
        rep["prefix_comparison"] = compare_prefixes(c.chain, c.options, infeasible=infeasible,
                                                    own=c)
        if infeasible:
            rep["prefix_comparison_infeasible"] = infeasible
    stage("Table O.1")
    rep["table_o1"] = table_o1(configs, c.chain)
    stage("processors")
    rep["processors"] = processors(configs, c.chain, other_leaves=not big)
    stage("packages")
    rep["packages"] = packages(configs, pins, c.chain)
    stage("wiring")
    rep["wiring"] = wiring(configs, c.chain)
    rep["allocation"] = {"limit_ops": ALLOCATE_LIMIT, "ops": len(c.graph.compute_nodes()),
                         "allocated": [k.name for k in configs if k.network is not None],
                         "scheduled_only": [k.name for k in configs if k.network is None],
                         "omitted": (["prefix_comparison"] * (c.graph.recursion is Recursion.LOG)
                                     + ["other leaf style"]) if big else []}
    from vampc.report.counts import path_conditions
    rep.update(path_conditions(c.chain))     # (the latency's reasons read them: latency_note)
    from vampc.report.compare import revolute_path
    turned = revolute_path(c.chain, c.options, c.graph)
    if turned is not None:                   # (present only then, so other reports keep their bytes)
        rep["revolute_path"] = turned
    if c.chain.mimic:            # coupled mimic joints (vampc.robot.mimic): the host's, not the network's
        names = [j.name for j in c.chain.joints]
        rep["mimic"] = [{"follower": names[m.follower - 1], "leader": names[m.leader - 1],
                         "multiplier": m.multiplier, "offset": m.offset} for m in c.chain.mimic]
    if "tree" in rep:
        from vampc.report.compare import tree_latencies
        rep["tree"]["latency_flops"] = tree_latencies(c.chain, c.options)
    from vampc.report.engineering import cpu_reference as measure_cpu
    from vampc.report.engineering import engineering
    stage("engineering")
    rep["engineering"] = engineering(c, clock_hz)
    if c.network is not None and c.network.bus is not None:
        from vampc.report.mlb import bus_figures
        rep["bus"] = bus_figures(c)
    if c.network is not None and c.network.checking is not None:
        from vampc.report.checking import checking_figures
        rep["error_correction"] = checking_figures(c)
    if cpu_reference:
        rep["engineering"]["cpu_reference"] = measure_cpu(c.chain)
    rep["clock"] = None
    if clock_hz is not None:
        add_clock(rep, clock_hz)
    return rep
