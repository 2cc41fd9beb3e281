"""What limited automatic error correction costs, in the report (README, Error correction): read off
the compiled network and its Checking (vampc.network.checking; the mechanism is
vampc.emulator.checking).

- VAMPs: one extraneous VAMP before the chain.
- Registers: every VAMP with a successor holds a second slot table matching its successor's (the
  control registers hardware_counts counts for one table, bits as vampc.report.counts.word_bits
  counts them), the mode (normal, warm, check, fill, inhibited: 3 bits) and a stage counter of
  ⌈log2(warmup + compare + 1)⌉ bits; its own Result register holds its copy of the successor's
  result, and a comparator of three words sets it beside the Result' line.
- Pins per VAMP: Operand-A' and Operand-B' (one per wire into its successor's operand
  multiplexers, as its own are counted: a matrix an MM group makes is three), Result' (one), and six one-bit pins: Test-in, Test-out,
  Test-back-in, Test-back-out, Inhibit-in, Inhibit-out.
- Wires: to each VAMP's successor, one per successor operand wire the primed inputs share, the Result'
  line, and the three control lines (Test, Test-back, Inhibit); the chain runs in logical order, so
  these are neighbours' wires (one VAMP pitch each) plus, for each shared input, the wire already
  reaching the successor extended by one pitch; a chain in another order (a file edited: the
  emulator runs it) has each link as long as its two VAMPs are apart on the line.
- Time: no latency, interval or Program-Mode tick is added (the checker runs its successor's slots
  at their ticks, on the same wires; the program stream is the same). A sweep checks every VAMP
  once in V·(warmup + compare) + (V - 1)·warmup periods: a permanent fault is found at most that
  many torque sets after it starts (a sweep and a stage, if it starts just after its check).
- Maintenance Mode: VAMPs whose results reach no torque (an op no output depends on) can be
  excised but not named: counted.
"""
from __future__ import annotations

from vampc.report.processors import operand_wires, vamp_pins

CONTROL_PINS = ("Test-in", "Test-out", "Test-back-in", "Test-back-out", "Inhibit-in", "Inhibit-out")
MODE_BITS = 3
LOOP_BACKS = 2      # the chain's two ends: a VAMP's Test line fed back to itself



def successors(net) -> dict[int, int]:
    """Each physical VAMP's successor in the check chain (the extraneous VAMP V's is the chain's
    first; the chain's last has none)."""
    order = net.checking.order
    return {order[i]: order[i + 1] for i in range(len(net.vamps))}


def checked_pins(net) -> list[int]:
    """Each physical VAMP's pins with checking, wired separately, in chain order (the extraneous
    VAMP E first): its own (the paper's budget with a pin per operand wire; E: power, clocks,
    reset, Result), its successor's operand wires and Result', and the Test and Inhibit pins. The
    package count packs these (vampc.report.processors.network_pins)."""
    V, succ = len(net.vamps), successors(net)
    out = []
    for p in net.checking.order:
        own = vamp_pins(net.vamps[p])["separate"] if p < V else 6
        s = succ.get(p)
        extra = len(CONTROL_PINS) + (operand_wires(net.vamps[s]) + 1 if s is not None else 0)
        out.append(own + extra)
    return out

def checking_multiplexers(net) -> dict:
    """The multiplexer inputs the checking adds, each multiplexer's inputs beyond its first as the
    network's are counted (vampc.report.counts): a checker selects its successor's operands among
    the primed inputs as the successor's own selects do (a copy of each of its successor's operand
    multiplexers), chooses between its own operands and the primed ones (one more input on each
    operand, but on the extraneous VAMP, which has none of its own), and each Result line has a
    second driver, its predecessor's Result' (one more input a line). Until 2026-12-07 the report
    counted none of them (planar2 systolic: 0 mux inputs with checking; a hardware user's find)."""
    V, succ = len(net.vamps), successors(net)
    copies = sum(len(net.vamps[s].a) - 1 + len(net.vamps[s].b) - 1 for s in succ.values())
    own_or_primed = 2 * sum(1 for p in succ if p < V)
    out = {"successor_copies": copies, "own_or_primed": own_or_primed, "result_lines": V}
    return {**out, "mux_inputs": sum(out.values())}


def checking_register_bits(net) -> dict[str, int]:
    """The checking's control registers in bits: each checker's second slot table (its successor's,
    counted as the first: vampc.report.counts.slot_table_bits), and every physical VAMP's mode and
    stage counter."""
    from vampc.report.counts import slot_table_bits, values_bits
    ck, physical = net.checking, len(net.vamps) + 1
    return {"second_control_bits": sum(slot_table_bits(net.vamps[s], net.period)
                                       for s in successors(net).values()),
            "mode_bits": MODE_BITS * physical,
            "stage_counter_bits": values_bits(ck.warmup + ck.compare + 1) * physical}


def checking_control_bits(net) -> int:
    """checking_register_bits summed: the storage line's control registers include them (a
    hardware user's find: they were only on the error-correction line)."""
    return sum(checking_register_bits(net).values())


def checking_figures(c) -> dict | None:
    """The error-correction section of a report of `c` (a vampc.compiler.Compiled); None without."""
    net = c.network
    ck = net.checking if net is not None else None
    if ck is None:
        return None
    from vampc.emulator.checking import sweep_periods
    V, succ = len(net.vamps), successors(net)
    from vampc.report.counts import control_registers
    plain = {v.index: control_registers(len(v.slots), len(v.a), len(v.b), net.period)
             for v in net.vamps}
    word = c.options.arith().bits
    pins_before = [vamp_pins(v)["separate"] for v in net.vamps]
    pins_after = checked_pins(net)
    shared = sum(operand_wires(net.vamps[s]) for s in succ.values())
    # Each link's wires run from a VAMP to its successor: one pitch between neighbours on the line
    # of VAMPs (the logical order the compiler writes, the extraneous VAMP just before VAMP 0). A
    # chain in another order (a program edited) was priced as if neighbours: its length is measured.
    place = {**{v: v for v in range(V)}, V: -1}
    length = sum((operand_wires(net.vamps[s]) + 4) * abs(place[p] - place[s]) for p, s in succ.items())
    sweep = sweep_periods(V, ck.warmup, ck.compare)
    from vampc.report.compare import max_fan_out
    fan = max_fan_out(net)
    muxes = checking_multiplexers(net)
    from vampc.network.checking import unnameable
    unnamed = unnameable(net)
    return {
        "chain": ("logical order" if ck.chain == tuple(range(V)) else "as the program lists it")
                 + ", one extraneous VAMP first",
        "extra_vamps": 1,
        "vamps": V + 1,
        "warmup_periods": ck.warmup, "compare_periods": ck.compare,
        "registers": {"second_control_registers": sum(plain[s] for s in succ.values()),
                      **checking_register_bits(net),
                      "comparators": V, "comparator_bits": 3 * word * V},
        "pins_per_vamp": {"with": {"max": max(pins_after), "mean": sum(pins_after) / len(pins_after)},
                          "without": {"max": max(pins_before),
                                      "mean": sum(pins_before) / len(pins_before)},
                          "control": len(CONTROL_PINS)},
        # control: Test, Test-back and Inhibit of each link, and the two loop-backs at the chain's
        # ends (the last VAMP's Test-out to its own Test-back-in, the extraneous VAMP's
        # Test-back-out to its own Test-in, within a VAMP: no length), which were left out (a
        # review's find, from section VII's description)
        "multiplexers": muxes,
        # each multiplexer input reading a Result (or its buffer) has its twin on the checker's
        # primed input, and each Result line is read by its checker's Result' as well
        "fan_out": {"with": 2 * fan + 1, "without": fan},
        "wires": {"successor_inputs": shared, "result_prime": V, "control": 3 * V + LOOP_BACKS,
                  "total": shared + 4 * V + LOOP_BACKS, "length_pitches": length},
        "added": {"latency_flops": 0, "interval_flops": 0, "load_ticks": 0},
        "sweep_periods": sweep,
        "worst_detection_periods": sweep + ck.warmup + ck.compare,
        "unnameable_vamps": unnamed,
    }


def checking_pairs(ck: dict | None) -> list[tuple[str, str]]:
    """The section as (label, text) rows for the text and markdown reports."""
    if not ck:
        return []
    r, pins, wires = ck["registers"], ck["pins_per_vamp"], ck["wires"]
    sweep = f"{ck['sweep_periods']} periods (torque sets)"
    out = [
        ("error correction", f"section VII checking: {ck['vamps'] - 1} VAMPs in a chain after "
                             f"{ck['extra_vamps']} extraneous VAMP ({ck['vamps']} in all); warm-up "
                             f"{ck['warmup_periods']} period(s), compare {ck['compare_periods']}"),
        ("  added time", "none: latency, interval and Program Mode as without checking"),
        ("  second control registers", f"{r['second_control_registers']} ({r['second_control_bits']} "
                                       f"bits), mode {r['mode_bits']} bits, stage counters "
                                       f"{r['stage_counter_bits']} bits, {r['comparators']} "
                                       f"comparators of {r['comparator_bits'] // max(1, r['comparators'])} bits"),
        ("  pins per VAMP", f"up to {pins['with']['max']} (mean {pins['with']['mean']:.1f}) with "
                            f"checking, {pins['without']['max']} (mean {pins['without']['mean']:.1f}) "
                            f"without: Operand-A', Operand-B' per successor operand wire, Result', and "
                            f"{pins['control']} Test and Inhibit pins"),
        ("  multiplexers", f"{ck['multiplexers']['mux_inputs']} inputs beyond each one's first: "
                           f"{ck['multiplexers']['successor_copies']} on the copies of each "
                           f"successor's operand multiplexers (the primed inputs), "
                           f"{ck['multiplexers']['own_or_primed']} choosing own or primed operands, "
                           f"{ck['multiplexers']['result_lines']} a second driver on each Result "
                           "line (its predecessor's Result')"),
        ("  fan-out", f"up to {ck['fan_out']['with']} inputs on one Result line ("
                      f"{ck['fan_out']['without']} without checking): each multiplexer input "
                      "reading it has its twin on the reader's checker, and the line is read by "
                      "its own checker's Result'"),
        ("  successor wires", f"{wires['total']}: {wires['successor_inputs']} shared operand wires, "
                              f"{wires['result_prime']} Result', {wires['control']} control lines"),
        # (it said "a permanent fault found within", of faults the compared values may mask for a
        # sweep or more, and of a dead VAMP that stalls the sweep: a review's find)
        ("  sweep", f"every VAMP checked once in {sweep}; a permanent fault that shows in the "
                    f"compared values found within {ck['worst_detection_periods']} periods of its "
                    "start (one they mask waits for a later sweep; a dead VAMP can stall it)"),
    ]
    if ck["unnameable_vamps"]:
        out.append(("  Maintenance Mode", f"{len(ck['unnameable_vamps'])} VAMP(s) whose results "
                                          f"reach no torque can be excised but not named: "
                                          f"{', '.join(map(str, ck['unnameable_vamps'][:8]))}"
                                          + (" ..." if len(ck["unnameable_vamps"]) > 8 else "")))
    return out
