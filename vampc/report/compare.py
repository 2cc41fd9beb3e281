"""Side-by-side comparison of prefix-network shapes for one robot (log recursion)."""
from __future__ import annotations

from collections import Counter
from dataclasses import replace

from vampc.compiler import PREFIXES, CompileOptions, compile_chain


def max_fan_out(network) -> int:
    """The most multiplexer inputs any one VAMP Result drives (directly or through its buffer)."""
    readers: Counter = Counter()
    for v in network.vamps:
        for operand in v.a + v.b:
            for tap in operand.taps:
                if tap.kind == "vamp":
                    readers[tap.index] += 1
                elif tap.kind == "buffer":
                    readers[network.buffers[tap.index].source] += 1
    return max(readers.values(), default=0)


def compare_prefixes(chain, options: CompileOptions) -> list[dict]:
    """Latency, VAMPs, buffer stages and fan-out of every prefix shape, other options as given."""
    rows = []
    for shape in PREFIXES:
        c = compile_chain(chain, replace(options, recursion="log", prefix=shape, verify=False))
        rows.append({"prefix": shape, "latency_flops": c.schedule.latency,
                     "mults": c.schedule.mults, "adds": c.schedule.adds,
                     "vamps": len(c.network.vamps), "buffer_stages": c.network.buffer_stages,
                     "max_fan_out": max_fan_out(c.network)})
    return rows


def render_comparison(rows: list[dict]) -> str:
    """A text table of compare_prefixes' rows."""
    head = f"{'prefix':<16}{'latency':>9}{'= M + A':>12}{'VAMPs':>8}{'buffers':>9}{'fan-out':>9}"
    lines = ["prefix shapes (log recursion, same robot and options):", head]
    for r in rows:
        lines.append(f"{r['prefix']:<16}{r['latency_flops']:>9}{r['mults']:>6} + {r['adds']:<4}"
                     f"{r['vamps']:>8}{r['buffer_stages']:>9}{r['max_fan_out']:>9}")
    return "\n".join(lines) + "\n"


LAYOUT_VARIANTS = (("systolic", "systolic", False), ("folded", "folded", False),
                   ("folded, shared passes", "folded", True))


def compare_layouts(chain, options: CompileOptions, current=None) -> list[dict]:
    """Latency, interval, VAMPs and what the time-multiplexing costs, for the systolic layout and the
    folded ones (other options as given), and the budget asked for; `current` is the configuration
    already compiled (its row is not compiled again: an exact budget takes a while)."""
    from vampc.report.counts import hardware
    rows = []
    variants = list(LAYOUT_VARIANTS)
    if options.vamps is not None or options.interval is not None:
        variants.append(("budget" + (f", {options.vamps} VAMPs" if options.vamps else "")
                         + (f", interval {options.interval}" if options.interval else ""),
                         "budget", False))
    for label, layout, share in variants:
        budget = {} if layout == "budget" else {"vamps": None, "interval": None, "exact": False}
        wanted = replace(options, layout="systolic" if layout == "budget" else layout,
                         share_passes=share, verify=False, **budget)
        same = current is not None and replace(current.options, verify=False) == wanted
        c = current if same else compile_chain(chain, wanted)
        s, hw = c.schedule, hardware(c)
        rows.append({"layout": label, "latency_flops": s.latency, "mults": s.mults, "adds": s.adds,
                     "waits": s.waits, "interval_flops": s.interval, "vamps": len(c.network.vamps),
                     "buffer_stages": c.network.buffer_stages, "mux_inputs": hw["mux_inputs"],
                     "control_registers": hw["control_registers"],
                     "host_writes_per_set": hw["host_writes_per_set"],
                     "load_ticks": hw["load_ticks"]})
    return rows


def render_layouts(rows: list[dict]) -> str:
    """A text table of compare_layouts' rows."""
    head = (f"{'layout':<24}{'latency':>8}{'= M + A + wait':>16}{'interval':>10}{'VAMPs':>7}"
            f"{'buffers':>9}{'mux in':>8}{'ctrl regs':>11}{'host wr':>9}{'load':>8}")
    lines = ["layouts (same robot and recursion; latency and interval in flops):", head]
    for r in rows:
        lines.append(f"{r['layout']:<24}{r['latency_flops']:>8}{r['mults']:>6} + {r['adds']:<3} + "
                     f"{r['waits']:<3}{r['interval_flops']:>9}{r['vamps']:>7}{r['buffer_stages']:>9}"
                     f"{r['mux_inputs']:>8}{r['control_registers']:>11}"
                     f"{r['host_writes_per_set']:>9}{r['load_ticks']:>8}")
    return "\n".join(lines) + "\n"


def tree_latencies(chain, options) -> dict:
    """ASAP latency (flops) of the linear and the log graph of `chain` under `options`' timing and
    prefix shape: the report's "latency of linear and log" for a tree."""
    from vampc.dataflow.linear import build_linear
    from vampc.dataflow.logarithmic import build_log
    from vampc.schedule.asap import schedule_asap
    graphs = {"linear": build_linear(chain, verify=False),
              "log": build_log(chain, options.prefix, options.uniform_leaves, verify=False)}
    return {k: schedule_asap(g, options.timing, verify=False).latency for k, g in graphs.items()}
