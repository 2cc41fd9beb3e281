"""The configurations a report compares: both recursions, each in every layout vampc makes, for the
report's robot and options (README, *Layouts*).

The report's own configuration is the compiled one it was given (from a robot or a program file).
The others are built here from the same chain: the graph once per recursion, then each layout's
binding and schedule. They are allocated too (buffers, multiplexers, load time) when both their
graph and the report's own have at most ALLOCATE_LIMIT ops; otherwise they keep the figures the
graph, layout and schedule give (latency, interval, VAMPs), which is what lets `vampc report` of a
512-joint log program stay within seconds.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

from vampc.compiler import CompileOptions, build_graph
from vampc.dataflow.graph import Graph
from vampc.network.allocate import allocate
from vampc.network.model import Network
from vampc.program import emit
from vampc.schedule.asap import Schedule
from vampc.schedule.layout import Layout, layout_and_schedule
from vampc.schedule.registry import BUDGET, LAYOUTS, LayoutRequest
from vampc.textio import count

# Ops in a graph above which the other configurations are scheduled but not allocated.
ALLOCATE_LIMIT = 20_000


def compared_layouts() -> tuple[tuple[str, str, bool], ...]:
    """(label, layout, share_passes) of every layout the report lays each recursion out in, in the
    order every table lists them: the registry's compared layouts (vampc.schedule.registry),
    systolic, folded and folded with shared passes."""
    out = []
    for kind in LAYOUTS.values():
        if kind.compared:
            out.append((kind.name, kind.name, False))
            if kind.shares_passes:
                out.append((f"{kind.name}, shared passes", kind.name, True))
    return tuple(out)


@dataclass(frozen=True)
class Config:
    """One configuration: its options, graph, layout and schedule, and its network when allocated.
    `own` marks the report's own configuration."""

    label: str
    options: CompileOptions
    graph: Graph
    layout: Layout
    schedule: Schedule
    network: Network | None
    stream: tuple = ()            # the Program-Mode stream (vampc.program.emit), when allocated
    own: bool = False

    @property
    def recursion(self) -> str:
        """'linear' or 'log'."""
        return self.graph.recursion

    @property
    def vamps(self) -> int:
        """VAMPs of the layout (one per unit member: three per MM unit; a budget's placement)."""
        return self.layout.vamp_count

    @property
    def name(self) -> str:
        """'linear, systolic', 'log, folded, shared passes', ..."""
        return f"{self.recursion}, {self.label}"


def layout_label(layout: str, share_passes: bool) -> str:
    """The label the report gives a layout."""
    return next((lab for lab, lay, share in compared_layouts() if (lay, share) == (layout,
                                                                             share_passes)), layout)


def configurations(c, recursions=None) -> list[Config]:
    """Every recursion of `recursions` (default: the registry's, vampc.dataflow.registry) in every
    layout, `c` (a vampc.compiler.Compiled) among them; the other options (prefix, leaves,
    latencies) as `c` was compiled."""
    from vampc.dataflow.registry import RECURSIONS
    recursions = tuple(RECURSIONS) if recursions is None else recursions
    out = []
    small = len(c.graph.compute_nodes()) <= ALLOCATE_LIMIT
    kind = c.options.layout_kind
    extra = not kind.compared        # a budget, or a registered layout the report does not compare
    for rec in recursions:
        opts = replace(c.options, recursion=rec, verify=False, numbering=None, vamps=None,
                       interval=None, exact=False)
        graph = c.graph if rec == c.graph.recursion else build_graph(c.chain, opts)
        full = small and len(graph.compute_nodes()) <= ALLOCATE_LIMIT
        for label, layout, share in compared_layouts():
            own = not extra and (rec, layout, share) == (c.graph.recursion, c.options.layout,
                                                          c.options.share_passes)
            if own:
                bus = ", Mostly-Local Bus" if c.options.bus == "mlb" else ""
                out.append(Config(label + bus, c.options, c.graph, c.layout, c.schedule,
                                  c.network, c.stream, True))
                continue
            out.append(_config(label, replace(opts, layout=layout, share_passes=share), graph, full))
        if extra and rec == c.graph.recursion:      # the budget asked for, after the layouts
            label = budget_label(c.options) if kind is BUDGET else kind.name
            out.append(Config(label, c.options, c.graph, c.layout, c.schedule,
                              c.network, c.stream, True))
    return out


def budget_label(options: CompileOptions) -> str:
    """'budget, 12 VAMPs', 'budget, interval 40', ..."""
    return ("budget" + (f", {count(options.vamps, 'VAMP')}" if options.vamps else "")
            + (f", interval {options.interval}" if options.interval else "")
            + (", exact" if options.exact else ""))


def _config(label: str, opts: CompileOptions, graph: Graph, full: bool) -> Config:
    """One configuration of `graph`: laid out and scheduled; allocated and emitted when `full`."""
    lay, sched = layout_and_schedule(graph, opts.timing, opts.layout,
                                      LayoutRequest(opts.share_passes, verify=False))
    if not full:
        return Config(label, opts, graph, lay, sched, None)
    net = allocate(graph, sched, lay, False)
    progs = emit.programs(net)
    return Config(label, opts, graph, lay, sched, net,
                  emit.program_stream(net, progs, emit.default_numbering(net)))


def own(configs: list[Config]) -> Config:
    """The report's own configuration."""
    return next(k for k in configs if k.own)
