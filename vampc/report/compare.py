"""Side-by-side comparisons for one robot: prefix-network shapes (log recursion) and layouts."""
from __future__ import annotations

from dataclasses import replace

from vampc.compiler import CompileOptions, build_graph, compile_chain
from vampc.errors import VampcError
from vampc.kinds import Prefix, TapKind
from vampc.memo import keep_last


def max_fan_out(network) -> int:
    """The most multiplexer inputs any one VAMP Result drives (directly or through its buffer)."""
    from vampc.network.bus import wired
    network = wired(network)     # a bus network: the wires it implements
    from vampc.report.processors import read_taps
    readers = [0] * len(network.vamps)
    sources = [b.source for b in network.buffers]
    vamp, buffer = TapKind.VAMP, TapKind.BUFFER
    from vampc.machine.ops import TABLE, View
    for v in network.vamps:      # (tap_source in line: a million VAMPs in a big network)
        a, b, slots = v.a, v.b, v.slots
        if len(a) == 1 and len(b) == 1 and len(slots) == 1:     # (most: a systolic VAMP)
            tb = b[0].taps
            if len(tb) > 1 and TABLE[slots[0].op].views[1] is View.BCOLUMN:
                tb = (tb[slots[0].column],)  # an MM member's B: the column it reads (read_taps)
            inputs = (a[0].taps, tb)
        else:
            inputs = read_taps(v)
        for taps in inputs:
            for tap in taps:
                if tap.kind is vamp:
                    readers[tap.index] += 1
                elif tap.kind is buffer:
                    readers[sources[tap.index]] += 1
    return max(readers, default=0)


def compare_prefixes(chain, options: CompileOptions, limit: int | None = None,
                     infeasible: list | None = None, own=None) -> list[dict]:
    """Latency, interval, VAMPs, buffer stages and fan-out of every prefix shape, other options as
    given (the interval: on a budget or folded each shape's work sets its own; a new user's find). A
    shape whose graph has more than `limit` ops (default: vampc.report.configs.ALLOCATE_LIMIT) is
    scheduled but not allocated: its row has latency, interval and VAMPs only, and on the
    Mostly-Local Bus those of the layout wired point to point (the bus's stretch and wait are
    found as it is allocated; the report's note says so). A shape these options cannot
    compile (the program's own --tiers too few for another shape's bus traffic) has no row; it is
    appended to `infeasible` as {"prefix", "why"} (its error made the whole report fail, naming
    no file: a new user's find). `own`: the program's compiled IRs (vampc.compiler.Compiled),
    whose shape's row is theirs, not compiled again. An --exact program's other shapes are placed
    by the list scheduler, their rows marked "exact": false (CP-SAT ran again for each shape: a
    report needed OR-Tools and ran for more than 13 minutes where the compile took 8; a new
    user's find)."""
    from vampc.report.configs import ALLOCATE_LIMIT
    from vampc.schedule.layout import layout_and_schedule
    from vampc.schedule.registry import LayoutRequest
    limit = ALLOCATE_LIMIT if limit is None else limit
    rows = []
    for shape in Prefix:
        if own is not None and shape == own.options.prefix:
            rows.append(_row(shape, own) | ({"exact": True} if options.exact else {}))
            continue
        opts = replace(options, recursion="log", prefix=shape, verify=False, numbering=None,
                       exact=False)
        marked = {"exact": False} if options.exact else {}
        graph = build_graph(chain, opts)
        if len(graph.compute_nodes()) > limit:
            lay, s = layout_and_schedule(graph, opts.timing, opts.layout,
                                         LayoutRequest(opts.share_passes, verify=False))
            rows.append({"prefix": shape, "latency_flops": s.latency, "mults": s.mults,
                         "adds": s.adds, "waits": s.waits, "interval_flops": s.interval,
                         "vamps": lay.vamp_count} | marked)
            continue
        try:
            c = compile_chain(chain, opts)
        except VampcError as exc:
            if infeasible is None or shape == options.prefix:
                raise
            infeasible.append({"prefix": shape, "why": str(exc)})
            continue
        rows.append(_row(shape, c) | marked)
    return rows


def _row(shape, c) -> dict:
    """A prefix shape's row from its compiled IRs."""
    return {"prefix": shape, "latency_flops": c.schedule.latency, "mults": c.schedule.mults,
            "adds": c.schedule.adds, "waits": c.schedule.waits,
            "interval_flops": c.schedule.interval, "vamps": len(c.network.vamps),
            "buffer_stages": c.network.buffer_stages, "max_fan_out": max_fan_out(c.network)}


def layout_rows(configs, recursion: str) -> list[dict]:
    """One row per layout of `recursion` among `configs` (vampc.report.configs): latency, interval,
    VAMPs, and — when the configuration was allocated — what the time-multiplexing costs."""
    from vampc.report.counts import hardware
    rows = []
    for k in configs:
        if k.recursion != recursion:
            continue
        s = k.schedule
        row = {"layout": k.label, "latency_flops": s.latency, "mults": s.mults, "adds": s.adds,
               "waits": s.waits, "interval_flops": s.interval, "vamps": k.vamps}
        if k.network is not None:
            hw = hardware(k)
            row.update({"buffer_stages": k.network.buffer_stages, "mux_inputs": hw["mux_inputs"],
                        "control_registers": hw["control_registers"],
                        "host_writes_per_set": hw["host_writes_per_set"],
                        "load_ticks": hw["load_ticks"]})
        rows.append(row)
    return rows


def compare_layouts(chain, options: CompileOptions) -> list[dict]:
    """layout_rows for a chain compiled with `options` (its recursion)."""
    from vampc.report.configs import configurations
    c = compile_chain(chain, replace(options, verify=False, numbering=None))
    return layout_rows(configurations(c, (c.graph.recursion,)), c.graph.recursion)


def revolute_path(chain, options, graph) -> dict | None:
    """{"mults", "adds"} on the critical path of the same arm with every prismatic joint revolute,
    and {"own_mults", "own_adds"} on this arm's `graph`'s, both scheduled ASAP at `options`' timing
    (recursion, prefix shape and leaves): the difference is what a latency's reasons give the
    prismatic joints' σ̄ terms (vampc.report.counts.latency_reasons; they had been given no size, a
    hardware user's find), measured between two graphs, whatever the layout waits. None without
    prismatic joints, on a tree or floating base, whose latency is not itemised, and for a graph of
    more than ALLOCATE_LIMIT ops, as the report leaves out its other comparisons that compile the
    robot again (two graphs more: 15 s of a 16 000-joint report, a review's find)."""
    from vampc.report.configs import ALLOCATE_LIMIT
    from vampc.robot.chain import JointType
    if not chain.is_fixed_chain or all(j.type is JointType.REVOLUTE for j in chain.joints) or \
            len(graph.compute_nodes()) > ALLOCATE_LIMIT:
        return None
    return _revolute_path(chain, graph, options.recursion, options.prefix, options.uniform_leaves,
                          options.mult_latency, options.add_latency)


@keep_last(4)          # (Table O.1 asks for each configuration: two graphs, one per recursion)
def _revolute_path(chain, graph, recursion, prefix, uniform_leaves, mult, add) -> dict:
    import warnings

    from vampc.robot.chain import JointType
    from vampc.schedule.asap import schedule_asap
    with warnings.catch_warnings():      # (the chain's own checks were said when it was read)
        warnings.simplefilter("ignore")
        turned = replace(chain, joints=tuple(replace(j, type=JointType.REVOLUTE)
                                             for j in chain.joints))
    options = CompileOptions(recursion=recursion, prefix=prefix, uniform_leaves=uniform_leaves,
                             mult_latency=mult, add_latency=add)
    s = schedule_asap(build_graph(turned, options), options.timing, verify=False)
    own = schedule_asap(graph, options.timing, verify=False)
    return {"mults": s.mults, "adds": s.adds, "own_mults": own.mults, "own_adds": own.adds}


def tree_latencies(chain, options) -> dict:
    """ASAP latency (flops) of the linear and the log graph of `chain` under `options`' timing and
    prefix shape: the report's "latency of linear and log" for a tree."""
    from vampc.dataflow.linear import build_linear
    from vampc.dataflow.logarithmic import build_log
    from vampc.schedule.asap import schedule_asap
    graphs = {"linear": build_linear(chain, verify=False),
              "log": build_log(chain, options.prefix, options.uniform_leaves, verify=False)}
    return {k: schedule_asap(g, options.timing, verify=False).latency for k, g in graphs.items()}
