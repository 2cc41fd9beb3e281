"""The Mostly-Local Bus in the report (README, Mostly-Local Bus): per tier its buses, the writes it
carries, its utilisation and message distances; the cycle stretch and the wait; the bus-write
registers; pins and wires per VAMP against the point-to-point wiring the bus replaces; and, for
robots small enough to compile again, the same robot with the default tiers, tuned tiers and
point-to-point wiring side by side. Every figure is read off the compiled network."""
from __future__ import annotations

from collections import Counter
from dataclasses import replace

from vampc.kinds import TapKind
from vampc.network.bus import latched, wired
from vampc.network.model import tap_source
from vampc.report import paper
from vampc.report.processors import read_taps

COMPARE_LIMIT = 4000      # VAMPs up to which the report compiles the other wirings to compare
TIER_BITS = 6             # a tier select (at most 64 tiers)


def _reads(net):
    """Per (tier, bus, counter): the places of the VAMPs latching it then."""
    return {key: [net.bus.position[v] for v in vamps] for key, vamps in latched(net).items()}


def write_register_bits(net) -> int:
    """Bits of one bus-write register: a Cycle-Counter value (as wide as the VAMPs' Cycle-Counters
    and delay fields: vampc.report.counts.counter_bits; it was 24 bits here beside the word line's
    P.bit_length()), its source and its tier. The word line's control registers count them (they
    were left out: 72 registers of planar2's bus, 2 304 bits, a new user's find)."""
    from vampc.report.counts import counter_bits
    return counter_bits(net.period) + _stage_bits(net) + TIER_BITS


def _stage_bits(net) -> int:
    """Bits of a bus-write register's source field: Result or one of the buffer's stages."""
    deepest = max((b.stages for b in net.buffers), default=0)
    return max(1, deepest.bit_length())


def bus_figures(c) -> dict | None:
    """The bus section of a report of `c` (a vampc.compiler.Compiled); None without a bus."""
    net = c.network
    bus = net.bus
    if bus is None:
        return None
    P, V = net.period, len(net.vamps)
    sources = [b.source for b in net.buffers]
    drivers = bus.drivers(sources, P)
    reads = _reads(net)
    per_tier = []
    for k, tier in enumerate(bus.tiers):
        dist = []
        for (kk, b, cnt), writes in drivers.items():
            if kk != k:
                continue
            p = bus.writer_position(writes[0].source, sources)
            dist.append(max(abs(p - r) for r in reads.get((kk, b, cnt), [p])))
        buses = tier.buses(V)
        per_tier.append({"tier": k, "span": tier.span, "offset": tier.offset, "buses": buses,
                         "writes": len(dist), "utilisation": len(dist) / (buses * P),
                         "longest": max(dist, default=0),
                         "mean": sum(dist) / len(dist) if dist else 0.0})
    writers = registers_by_vamp(net)
    # a VAMP drives a tier's bus through a driver of its own; where it drives that tier with more
    # than one source (its Result, stages of the buffer behind it), through a multiplexer of them
    # that the firing register's source field selects (counted since 2026-12-08: the registers
    # were, the drivers and their multiplexers were not)
    driven: dict[tuple[int, int], set] = {}
    for w in bus.writes:
        driven.setdefault((tap_source(w.source, sources), w.tier), set()).add(w.source)
    register_bits = write_register_bits(net)
    p2p = wired(net)
    p2p_pins = [_p2p_pins(v) for v in p2p.vamps]
    bus_pins = pins_on_bus(net)
    p2p_wires, p2p_length = _wires(p2p, bus.position)
    direct_wires, direct_length = _wires(net, bus.position)
    p2p_in = [_from_vamps(v) for v in p2p.vamps]
    bus_in = [len(bus.tiers) + _from_vamps(v) for v in net.vamps]
    total_buses = sum(t["buses"] for t in per_tier)
    out = {
        "tiers": per_tier,
        "vamps_on_line": V,
        "interval_flops": P, "interval_without_bus": P - bus.stretch, "stretch": bus.stretch,
        "latency_flops": c.schedule.latency, "wait": bus.wait,
        "writes": len(bus.writes),
        "utilisation": sum(t["writes"] for t in per_tier) / (total_buses * P),
        "registers": {"bus_write": len(bus.writes), "max_per_vamp": max(writers.values(), default=0),
                      "bits_each": register_bits, "bits": register_bits * len(bus.writes),
                      "tier_select_bits": TIER_BITS},
        "drivers": {"count": len(driven),
                    "mux_inputs": sum(len(d) - 1 for d in driven.values()),
                    "max_sources": max(map(len, driven.values()), default=0),
                    "max_per_vamp": max(Counter(u for u, _ in driven).values(), default=0)},
        "pins_per_vamp": {"bus": {"max": max(bus_pins), "mean": sum(bus_pins) / V},
                          "point_to_point": {"max": max(p2p_pins), "mean": sum(p2p_pins) / V}},
        "wires_per_vamp": {"bus": {"max": max(bus_in), "mean": sum(bus_in) / V},
                           "point_to_point": {"max": max(p2p_in), "mean": sum(p2p_in) / V}},
        "wires": {"buses": total_buses,
                  "bus_length": sum(_tier_length(t, V) for t in bus.tiers),
                  "direct": direct_wires, "direct_length": direct_length,
                  "point_to_point": p2p_wires, "point_to_point_length": p2p_length},
    }
    if V <= COMPARE_LIMIT:
        out["comparison"] = _comparison(c)
    else:
        out["comparison_omitted"] = (f"{V} VAMPs: the other wirings are compared up to "
                                     f"{COMPARE_LIMIT} (each is a compile; benchmarks/bus.py "
                                     "compares bigger ones)")
    return out


def registers_by_vamp(net) -> Counter:
    """The bus-write registers each VAMP holds (a write of a stage of its buffer is its own)."""
    sources = [b.source for b in net.buffers]
    return Counter(tap_source(w.source, sources) for w in net.bus.writes)


def _tier_length(tier, vamps: int) -> int:
    """A tier's buses' lengths in VAMP pitches, each from the first to the last place it serves (a
    bus at an end of the line serves fewer), as a point-to-point wire is measured."""
    total = 0
    for b in range(tier.bus_at(0), tier.bus_at(vamps - 1) + 1):
        lo = max(0, tier.offset + b * tier.span)
        hi = min(vamps - 1, tier.offset + (b + 1) * tier.span - 1)
        total += hi - lo
    return total


def _from_vamps(vamp) -> int:
    """A VAMP's multiplexer inputs wired from other VAMPs' Results or buffers (the taps it reads:
    vampc.report.processors.read_taps)."""
    return sum(1 for taps in read_taps(vamp) for t in taps
               if t.kind in (TapKind.VAMP, TapKind.BUFFER))


def _p2p_pins(vamp) -> int:
    """A VAMP's pins with each operand wire a pin (a matrix's three columns, three; the one column
    an MM member reads of its operand B, one)."""
    from vampc.report.processors import vamp_pins
    return vamp_pins(vamp)["separate"]


def _bus_pins(vamp, tiers: int) -> int:
    """A VAMP's pins on the bus: the paper's budget without its two operand pins, one pin per tier
    (reading and driving the bus in front of it), and one per wire not on the bus (host ports,
    constant buffers, the Program-Mode wire; a matrix's three columns three wires, as
    vampc.report.processors.operand_wires counts them)."""
    direct = sum(1 for taps in read_taps(vamp) for t in taps if t.kind is not TapKind.BUS)
    return len(paper.PINS_SEPARATE) - 2 + tiers + direct


def pins_on_bus(net) -> list[int]:
    """Every VAMP's pins on the bus (_bus_pins), in logical order (the package count's too:
    vampc.report.processors.network_pins)."""
    tiers = len(net.bus.tiers)
    return [_bus_pins(v, tiers) for v in net.vamps]


def _wires(net, position) -> tuple[int, int]:
    """VAMP-to-VAMP wires (each multiplexer input from a Result or buffer) and their total length
    along the line, in VAMP pitches."""
    sources = [b.source for b in net.buffers]
    count = length = 0
    for v in net.vamps:
        for taps in read_taps(v):
            for tap in taps:
                if tap.kind in (TapKind.VAMP, TapKind.BUFFER):
                    count += 1
                    length += abs(position[tap_source(tap, sources)] - position[v.index])
    return count, length


def _comparison(c) -> list[dict]:
    """The robot compiled with point-to-point wiring, the default tiers and tuned tiers."""
    from vampc.compiler import compile_graph
    rows = []
    wirings = [("point-to-point", "p2p", None), ("bus, default tiers", "mlb", None),
               ("bus, tuned tiers", "mlb", "auto")]
    if c.options.tiers not in (None, "auto"):
        wirings.append(("bus, these tiers", "mlb", c.options.tiers))
    for label, bus, tiers in wirings:
        if (bus, tiers) == (c.options.bus, c.options.tiers):
            k = c
        else:
            opts = replace(c.options, bus=bus, tiers=tiers, verify=False, numbering=None)
            k = compile_graph(c.chain, c.graph, opts, until="allocate")
        net = k.network
        row = {"wiring": label, "interval_flops": k.schedule.interval,
               "latency_flops": k.schedule.latency, "vamps": len(net.vamps)}
        if net.bus is None:
            row.update({"tiers": None, "stretch": 0, "wait": 0, "utilisation": None,
                        "max_pins_per_vamp": max(_p2p_pins(v) for v in net.vamps)})
        else:
            slots = sum(t.buses(len(net.vamps)) for t in net.bus.tiers) * net.period
            row.update({"tiers": [t.span for t in net.bus.tiers], "stretch": net.bus.stretch,
                        "wait": net.bus.wait, "utilisation": len(net.bus.writes) / slots,
                        "max_pins_per_vamp": max(pins_on_bus(net))})
        rows.append(row)
    return rows


def _drivers_text(d: dict | None) -> str:
    """The bus lines' drivers: a VAMP's onto a tier's bus, and the multiplexers of their sources."""
    if d is None:
        return "—"
    return (f"{d['count']:,} drivers of a VAMP onto a tier's bus (up to {d['max_per_vamp']} on one "
            f"VAMP); {d['mux_inputs']:,} multiplexer inputs beyond the first where one drives a tier "
            f"with several sources (its Result, stages of the buffer behind it; up to "
            f"{d['max_sources']} on one driver)")


def bus_pairs(b: dict | None) -> list[tuple[str, str]]:
    """The text report's Mostly-Local Bus lines, as (label, value) pairs; none without a bus."""
    if b is None:
        return []
    spans = ",".join(str(t["span"]) for t in b["tiers"])
    regs, pins, wires = b["registers"], b["pins_per_vamp"], b["wires"]
    pairs = [
        ("bus", f"Mostly-Local Bus: {len(b['tiers'])} tiers (spans {spans}) over "
                f"{b['vamps_on_line']} VAMPs in a line; {b['writes']} bus writes a cycle, "
                f"{b['utilisation']:.1%} of the bus slots"),
        ("  cycle", _cycle_text(b)),
        ("  registers", f"{regs['bus_write']} bus-write registers of {regs['bits_each']} bits (up "
                        f"to {regs['max_per_vamp']} on one VAMP); an operand select picks a tier"),
        ("  drivers", _drivers_text(b.get("drivers"))),
        ("  pins per VAMP", f"up to {pins['bus']['max']} (mean {pins['bus']['mean']:.1f}) on the "
                            f"bus; point-to-point up to {pins['point_to_point']['max']} (mean "
                            f"{pins['point_to_point']['mean']:.1f})"),
        ("  wires per VAMP", f"up to {b['wires_per_vamp']['bus']['max']} (mean "
                             f"{b['wires_per_vamp']['bus']['mean']:.1f}): a tap on each tier and "
                             f"its direct wires; point-to-point up to "
                             f"{b['wires_per_vamp']['point_to_point']['max']} (mean "
                             f"{b['wires_per_vamp']['point_to_point']['mean']:.1f})"),
        ("  wires", f"{wires['buses']} buses {wires['bus_length']:,} VAMP pitches long in all, and "
                    f"{wires['direct']} direct VAMP-to-VAMP wires (Program Mode's) "
                    f"{wires['direct_length']:,} long; point-to-point {wires['point_to_point']} "
                    f"wires {wires['point_to_point_length']:,} long"),
        ("  by tier", "tier span offset buses writes utilisation longest mean-distance"),
    ]
    for t in b["tiers"]:
        pairs.append(("", f"{t['tier']:>4} {t['span']:>4} {t['offset']:>6} {t['buses']:>5} "
                          f"{t['writes']:>6} {t['utilisation']:>11.1%} {t['longest']:>7} "
                          f"{t['mean']:>13.1f}"))
    if "comparison_omitted" in b:
        pairs.append(("  compared", f"not here: {b['comparison_omitted']}"))
    for r in b.get("comparison", ()):
        tiers = "" if r["tiers"] is None else f", tiers {','.join(map(str, r['tiers']))}"
        pairs.append(("  compared" if r is b["comparison"][0] else "",
                      f"{r['wiring']}: interval {r['interval_flops']}, latency "
                      f"{r['latency_flops']}, up to {r['max_pins_per_vamp']} pins a VAMP{tiers}"))
    return pairs


def _cycle_text(b: dict) -> str:
    """'8 flops = 4 + 4 stretched ...', or how a shorter folded schedule came about."""
    if b["stretch"] >= 0 and b["wait"] >= 0:
        return (f"{b['interval_flops']} flops = {b['interval_without_bus']} + {b['stretch']} "
                f"stretched for conflicting transfers; latency {b['latency_flops']} flops, "
                f"{b['wait']} more than without the bus")
    return (f"{b['interval_flops']} flops against {b['interval_without_bus']} point to point, "
            f"latency {b['latency_flops']} flops ({b['wait']:+d}): waiting for buses reordered "
            "the folded list schedule, which came out shorter")
