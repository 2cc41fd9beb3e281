"""Cost figures of a compiled robot, and the paper's closed forms to compare them with (Table O.1).

Everything here is read off the Chain, Graph, Schedule and Network; nothing is re-derived.
"""
from __future__ import annotations

import itertools
import math
import operator
from collections import Counter

from vampc.kinds import Pass, Recursion
from vampc.machine.ops import SERIAL_WORK, VAMPS_PER_OP
from vampc.program.words import (  # noqa: F401  (counter_bits, values_bits: the report's)
    counter_bits,
    field_widths,
    values_bits,
)
from vampc.schedule.registry import BUDGET, FOLDED, is_layout
from vampc.textio import count

_SLOTS, _A, _B, _NODE, _OP, _SECTION = (operator.attrgetter(name) for name in (
    "slots", "a", "b", "node", "op", "section"))
_FIRST = operator.itemgetter(0)

# A 40-pin package holds 5 VAMPs with all pins separate, 12 with shared clock/power/reset (section VII).
VAMPS_PER_PACKAGE = {"separate": 5, "shared": 12}


def paper_latency(n: int, recursion: str, timing=None) -> dict:
    """The paper's latency formula for a general rotary arm of n joints: Mults, Addns, and flops at
    `timing`'s Mult and Addn latencies (a vampc.machine.ops.Timing; the paper's 1 and 1 if None)."""
    from vampc.dataflow.registry import RECURSIONS
    from vampc.machine.ops import Timing
    mults, adds = RECURSIONS[Recursion(recursion)].paper_latency(n)
    return {"flops": (timing or Timing()).flops(mults, adds), "mults": mults, "adds": adds}


def serial_reference(n: int) -> dict:
    """Luh-Walker-Paul serial Newton-Euler: (150n − 48) Mults + (131n − 48) Addns."""
    return {"mults": 150 * n - 48, "adds": 131 * n - 48}


def vamp_counts(c) -> dict:
    """VAMPs in total, on the backward (incl. non-propagated) and forward recursions, and by op."""
    nodes, vamps = c.graph.nodes, c.network.vamps
    by_section, by_op = Counter(), Counter()
    slots = list(map(_SLOTS, vamps))
    one = list(map((1).__eq__, map(len, slots)))
    alone = list(map(_FIRST, itertools.compress(slots, one)))   # most VAMPs: counted in bulk
    for section, k in Counter(map(_SECTION, map(nodes.__getitem__, map(_NODE, alone)))).items():
        by_section[Pass.of(section)] += k
    for op, k in Counter(map(_OP, alone)).items():
        by_op[op.value] += k
    for v in itertools.compress(vamps, map(operator.not_, one)):
        kinds = {Pass.of(nodes[s.node].section) for s in v.slots}
        by_section[kinds.pop() if len(kinds) == 1 else "shared"] += 1
        by_op.update([s.op.value for s in v.slots])
    per_node = _per_node(c)
    return {"total": len(vamps), "backward": by_section["backward"],
            "forward": by_section["forward"], "shared": by_section["shared"],
            "by_op": dict(sorted(by_op.items())), "per_node": per_node}


def unused_vamps(c) -> dict:
    """{vamps: VAMPs all of whose ops compute values no torque reads, ops: those ops, names: how
    many of each name}: the graph keeps the paper's nodes whole (the log prefix's W, Q, R, S of
    every X_{0,b}, W and R of every final suffix; forward T19 and f where τ reads n alone; a tree's
    Y1, Y2), so a network built from it carries them. A
    sizing figure: a new user counted 101 of a 7-joint log arm's 486 VAMPs, said nowhere but in
    the error-correction section. The report's (vamps.unused), not the program file's summary,
    whose figures stay as they were."""
    live = c.graph.live_nodes()
    dead = [nd for nd in c.graph.nodes if nd.op.is_compute and nd.id not in live]
    if not dead:
        return {"vamps": 0, "ops": 0, "names": {}}
    gone = {nd.id for nd in dead}
    names = Counter(nd.name for nd in dead)
    return {"vamps": sum(all(s.node in gone for s in v.slots) for v in c.network.vamps),
            "ops": len(dead), "names": dict(sorted(names.items(), key=lambda kv: (-kv[1], kv[0])))}


def _per_node(c) -> dict:
    """VAMPs of the busiest recursion node of each section ('bwd', 'npv', 'fwd')."""
    groups: dict[tuple[str, int], int] = Counter()
    for (section, group, op), k in c.graph.compute_kinds().items():
        groups[(section, group)] += k * VAMPS_PER_OP[op]
    out = {}
    for section in ("bwd", "npv", "fwd"):
        sizes = [k for (s, _), k in groups.items() if s == section]
        out[section] = max(sizes) if sizes else 0
    return out


def serial_work(graph) -> dict:
    """Total scalar operations of the graph executed one after another."""
    ops = graph.compute_ops()
    return {"mults": sum(SERIAL_WORK[op][0] * k for op, k in ops.items()),
            "adds": sum(SERIAL_WORK[op][1] * k for op, k in ops.items())}


def physical_vamps(net) -> int:
    """The VAMPs a network is built of: its own and, with error correction's checking, the
    extraneous ones at the head of the checking chain (`order` holds every VAMP it checks and
    them). Package counts pack these."""
    return len(net.checking.order) if net.checking is not None else len(net.vamps)


def packages(vamps: int) -> dict:
    """40-pin packages needed, per packaging style."""
    return {style: math.ceil(vamps / per) for style, per in VAMPS_PER_PACKAGE.items()}


def input_buffer_scalars(c) -> int:
    """Scalars the host keeps in input buffers: constants plus one torque set's port values."""
    return sum(len(k.value) for k in c.network.consts) + distinct_port_scalars(c.network)


def distinct_port_scalars(net) -> int:
    """Scalars of one torque set's distinct host inputs (a quantity of a joint counted once, however
    many ports carry it)."""
    return sum({(e.key.quantity, e.key.joint): p.size for p in net.ports for e in p.entries}.values())


def summary(c) -> dict:
    """The headline figures stored in the program file and shown by `vampc report`."""
    s = c.schedule
    return {
        "joints": c.chain.n, "robot": c.chain.name, "prismatic_joints": prismatic_joints(c.chain),
        "joint_names": [j.name for j in c.chain.joints],
        "joint_types": [j.type.value for j in c.chain.joints],
        "recursion": c.graph.recursion, "layout": c.options.layout_name,
        "share_passes": c.options.share_passes,
        "latency": {"flops": s.latency, "mults": s.mults, "adds": s.adds, "waits": s.waits},
        "paper": paper_latency(c.chain.n, c.graph.recursion),
        "interval_flops": s.interval,
        "hardware": hardware(c),
        "budget": budget_figures(c),
        "vamps": vamp_counts(c),
        "buffers": {"chains": len(c.network.buffers), "stages": c.network.buffer_stages,
                    "scalars": 3 * c.network.buffer_stages},
        "ports": len(c.network.ports), "constants": len(c.network.consts),
        "input_buffer_scalars": input_buffer_scalars(c),
        "packages_40pin": packages(physical_vamps(c.network)),
        "serial_work": serial_work(c.graph),
        "serial_reference": serial_reference(c.chain.n),
        "ops": dict(sorted((op.value, k) for op, k in c.graph.compute_ops().items())),
        "timing": {"mult_latency": s.timing.mult, "add_latency": s.timing.add},
        "uniform_leaves": c.options.uniform_leaves if c.graph.recursion is Recursion.LOG else None,
        "prefix": c.options.prefix if c.graph.recursion is Recursion.LOG else None,
        **({"tree": tree_summary(c.chain, c.options.prefix)} if not c.chain.is_fixed_chain
           else {}),
        **({"word": word_bits(c)} if c.options.word != "float64" else {}),
    }


# A VAMP's data registers, in words: operands A and B (9 each), its three modules' MULT-1, MULT-2
# and ADDER (9), its Result (3).
DATA_WORDS_PER_VAMP = 9 + 9 + 9 + 3
# A micro-step assignment as the ROM holds it: the unit written (3: 2 bits), the function (mul, add,
# sub: 2 bits), and each of its two operands (one of 9 registers: A0-A2, B0-B2, U0-U2: 4 bits each).
ROM_BITS_PER_ASSIGNMENT = 2 + 2 + 4 + 4


def slot_table_bits(v, period: int) -> int:
    """A VAMP's slot table in bits, as vampc.rtl.design builds it: per slot a valid bit and its
    fields (vampc.program.words.field_widths: the delays as wide as the Cycle-Counter, the ROM
    pointer, the multiplexer selects, none for a multiplexer of one input)."""
    return len(v.slots) * (1 + sum(field_widths(period, len(v.a), len(v.b))))


def network_control_bits(c) -> tuple[int, int]:
    """The network's control registers beside its VAMPs' and buffers' (word_bits): (the overflow
    flag of a fixed-point word, vampc.rtl.design: 1 or 0; the Mostly-Local Bus's bus-write
    registers, vampc.report.mlb). Counted since 2026-12-06, the bus registers before the flag."""
    net = c.network
    flag = 1 if c.options.word.startswith("q") else 0
    if net.bus is None:
        return flag, 0
    from vampc.report.mlb import write_register_bits
    return flag, len(net.bus.writes) * write_register_bits(net)


def word_bits(c) -> dict:
    """What the program's word format costs in bits (README, Word formats): the word width, every
    VAMP's data registers, control registers and microcode ROM (with error correction the
    extraneous VAMP's too), the delay lines, the constant buffers, the host's input ports, the
    host's writes and reads per torque set and the Program-Mode stream. (The ports had been left
    out, and the extraneous VAMP's registers and ROM: an audit's.) Control
    registers are each VAMP's Cycle-Counter and slot table (counter_bits, slot_table_bits), the
    buffers' own Cycle-Counter, on the Mostly-Local Bus the bus-write registers, and in a
    fixed-point word the network's overflow flag; the ROM holds the op table's micro-steps (12 bits per assignment,
    ROM_BITS_PER_ASSIGNMENT), one copy per VAMP. (The Cycle-Counters and the slots' valid bits had
    been left out, and the delay fields counted at ceil(log2 P) bits, one fewer than the RTL's where
    P is a power of two: 426 of planar2 folded's 33 192 flip-flops, an audit's.)"""
    from vampc.machine import ops
    word, net = c.options.arith(), c.network
    W = word.bits
    counter = counter_bits(net.period)
    # with error correction, the extraneous VAMP is built as the others: data registers, a ROM, a
    # Cycle-Counter (its slot table is the second table the checking counts: vampc.report.checking)
    physical = physical_vamps(net)
    control = sum(counter + slot_table_bits(v, net.period) for v in net.vamps) \
        + (counter if net.buffers else 0) + counter * (physical - len(net.vamps))
    control += sum(network_control_bits(c))
    checking = 0
    if net.checking is not None:     # the second slot tables, modes and stage counters
        from vampc.report.checking import checking_control_bits
        checking = checking_control_bits(net)
        control += checking
    rom = ROM_BITS_PER_ASSIGNMENT * sum(len(step) for r in range(len(ops.ROM))
                                        for step in ops.entry(r)[0].steps)
    inputs = sum(p.size for p in net.ports for _ in p.entries)
    out = {"format": c.options.word, "bits": W,
           "data_register_bits": DATA_WORDS_PER_VAMP * W * physical,
           "control_register_bits": control, "rom_bits_per_vamp": rom,
           **({"checking_control_bits": checking} if net.checking is not None else {}),
           "rom_bits": rom * physical,
           "delay_line_bits": 3 * W * net.buffer_stages,
           "constant_bits": W * sum(len(k.value) for k in net.consts),
           # each host port is a register of its size (vampc.rtl.design), written at its entries
           "input_port_bits": W * sum(p.size for p in net.ports),
           "host_write_bits_per_set": W * inputs, "host_read_bits_per_set": W * c.chain.n_outputs,
           "program_bits": 3 * W * sum(len(e.words) for e in c.stream)}
    if c.options.word.startswith("q"):
        out.update(rounding=c.options.rounding, overflow=c.options.overflow)
    return out


def control_logic(c) -> dict:
    """The logic that reads the control registers (section VII: "the delays are easily implemented
    by counters and comparators"), as vampc.rtl.design builds it: a Cycle-Counter on each VAMP (and
    the extraneous VAMP of error correction) and one for the delay buffers, each with its
    incrementer; per slot three comparators of the Cycle-Counter's width (delay-A, delay-B, delay-R
    against the Cycle-Counter: latch A, latch B, dump), a comparator of the slot address (Program
    Mode's extended words) and a subtractor one bit wider with its wrap-around adder (delay-R −
    Cycle-Counter mod P, the ticks to the dump that address the microcode ROM); per VAMP two
    comparators of a word (its VAMP-number and its negation in the first word of Operand-A: a
    compact and an extended program word); for the buffers' clock one comparator a block end of the
    period (none where it shifts every tick); on the Mostly-Local Bus one comparator a bus-write
    register (its Cycle-Counter value) and a slot-address comparator for each register past the
    VAMP's slots (register j is loaded at address j·8 + 6 or 7). Counted since 2026-12-08 (a
    hardware engineer's question: the registers were counted, not what reads them). The RTL renders
    neither the bus nor the checking: their logic is counted by the same rule (the bus) or not at
    all (the checking's second tables, whose registers its section counts, and its comparators of
    results, there too)."""
    from vampc.machine.timing import shift_compares
    net = c.network
    slots = sum(len(v.slots) for v in net.vamps)
    physical = physical_vamps(net)
    ends = len(shift_compares(net.period, net.clock)) if net.buffers else 0
    writes = len(net.bus.writes) if net.bus is not None else 0
    # a slot address a slot, and on the bus one a bus-write register (register j at address j·8 +
    # 6 or 7): as many as the VAMP's slots or its registers, whichever is more
    addresses = [len(v.slots) for v in net.vamps]
    if net.bus is not None:
        from vampc.report.mlb import registers_by_vamp
        registers = registers_by_vamp(net)
        addresses = [max(a, registers.get(v.index, 0)) for a, v in zip(addresses, net.vamps)]
    counters = physical + (1 if net.buffers else 0)
    return {"cycle_counters": counters, "counter_bits": counter_bits(net.period),
            "delay_comparators": 3 * slots, "buffer_clock_comparators": ends,
            "bus_write_comparators": writes, "slot_address_comparators": sum(addresses),
            "step_subtractors": slots, "number_comparators": 2 * physical,
            "number_comparator_bits": c.options.arith().bits}


def tree_summary(chain, prefix: str) -> dict:
    """A tree's shape and depths (vampc.dataflow.treeprefix.tree_depths): joints, leaves, height (the
    depth of the level-by-level, linear recursion), the log recursion's backward ⊗ tiers (heavy paths
    plus light edges) and forward addition levels, beside ⌈log2(n+1)⌉; the base wrench's outputs."""
    from vampc.dataflow.treeprefix import tree_depths
    # a ground leaf at position 0 only where the log builders put one: a floating or rotating base
    # (the builders' ground0 is a fixed base standing still); with it always, a fixed-base tree's
    # tiers were one more than its graph's wherever its heavy path from the base has 2, 4, 8 ...
    # joints (a trees audit: talos_reduced 4 against 3)
    depths = tree_depths(chain.parent_of, prefix, ground=chain.floating or chain.base_rotates,
                         floating=chain.floating)
    return {**depths, "log2_n_plus_1": (chain.n).bit_length(), "floating": chain.floating,
            "outputs": chain.n_outputs, "parents": list(chain.parent_of)}


_HARDWARE: dict = {}


def hardware(c) -> dict:
    """hardware_counts, kept for the last few networks (a report asks for its own several times)."""
    key = (id(c.network), id(c.stream))
    hit = _HARDWARE.get(key)
    if hit is None or hit[0] is not c.network or hit[1] is not c.stream:
        if len(_HARDWARE) >= 8:
            _HARDWARE.pop(next(iter(_HARDWARE)))
        hit = _HARDWARE[key] = (c.network, c.stream, hardware_counts(c))
    return dict(hit[2])


def control_registers(slots: int, ins_a: int, ins_b: int, period: int) -> int:
    """A VAMP's control registers: per slot the fields of vampc.program.words.field_widths that
    have bits (delay-A, delay-B, delay-R, the ROM pointer, and a select for each operand multiplexer
    of more than one input), the registers vampc.rtl builds."""
    from vampc.program.words import field_widths
    return slots * sum(1 for w in field_widths(period, ins_a, ins_b) if w)


def six_per_slot(net) -> int:
    """The control registers as counted until 2026-12-07: the paper's four for a VAMP of one slot
    and one input per operand, else six a slot (what a stored summary of then holds)."""
    return sum(4 if len(v.slots) == len(v.a) == len(v.b) == 1 else 6 * len(v.slots) for v in net.vamps)


def hardware_counts(c) -> dict:
    """What a layout needs beyond one op per VAMP, counted from the network and the program:
    slots (ops run per period), control registers (per slot the paper's four, and a select for each
    operand multiplexer of more than one input, as the RTL builds them and word_bits counts their
    bits; until 2026-12-07 two selects a slot whenever a VAMP had several slots or inputs, a
    hardware user's find: 360 on planar2 folded where the RTL builds 282; on the Mostly-Local Bus
    also each bus-write register, which word_bits counts in the control bits too), multiplexer inputs
    beyond the first of each operand, program ports, host writes per torque set, the period and
    buffer clock, program words and Program-Mode load time."""
    net = c.network
    slots = list(map(len, map(_SLOTS, net.vamps)))
    ins_a = list(map(len, map(_A, net.vamps)))
    ins_b = list(map(len, map(_B, net.vamps)))
    if min(slots) == max(slots) == max(ins_a) == max(ins_b) == 1:   # all plain (systolic): at once
        control = 4 * len(slots)
    else:
        control = sum(control_registers(s, a, b, net.period) for s, a, b in zip(slots, ins_a, ins_b))
    if net.bus is not None:     # (a new user's find: the bits were counted, the registers were not)
        control += len(net.bus.writes)
    from vampc.program.emit import load_ticks
    return {
        "slots": sum(slots),
        "control_registers": control,
        "mux_inputs": sum(ins_a) + sum(ins_b) - 2 * len(net.vamps),
        "max_mux_inputs": max(max(ins_a), max(ins_b)),
        "program_ports": sum(1 for p in net.ports if not p.entries),
        "host_writes_per_set": sum(len(p.entries) for p in net.ports),
        "period": net.period, "buffer_clock": net.clock,
        "program_words": sum(len(e.words) for e in c.stream),
        "load_ticks": load_ticks(c.stream),
    }


def budget_figures(c) -> dict | None:
    """For a budgeted layout: the VAMPs asked for and used, the work, the interval and latency
    against their certified lower bounds (vampc.schedule.budget.bounds), the gaps in percent."""
    if c.options.layout_kind is not BUDGET:
        return None
    from vampc.schedule.budget import bounds
    k = c.options.vamps if c.options.vamps is not None else len(c.network.vamps)
    b = bounds(c.graph, c.schedule.timing, k)
    interval_bound = b.interval_bound
    s = c.schedule
    return {"vamps_asked": c.options.vamps, "interval_asked": c.options.interval,
            "vamps_used": len(c.network.vamps), "work": b.work,
            "interval_bound": interval_bound, "work_over_vamps": b.interval,
            "interval_gap_pct": gap_pct(s.interval, interval_bound),
            "latency_bound": b.latency, "critical_path": b.critical_path, "level_bound": b.level,
            "latency_gap_pct": gap_pct(s.latency, b.latency),
            "exact": c.options.exact, "proof": c.layout.proof if c.layout else ""}


def gap_pct(value: int, bound: int) -> float:
    """How far `value` is above `bound`, in percent (one decimal; 0 for a zero bound)."""
    return round(100.0 * (value - bound) / bound, 1) if bound else 0.0


def prismatic_joints(chain) -> list[int]:
    """1-based indices of prismatic joints."""
    return [i for i, j in enumerate(chain.joints, 1) if j.sigma == 0]


SHOWN_NUMBERS = 12


def numbers_text(numbers) -> str:
    """Joint numbers as a message gives them, '[3, 5]'; past SHOWN_NUMBERS the first few and how
    many in all (585 prismatic joints of a 4 096-joint chain had made lines of 3 500 characters: a
    new user's find; --format json lists every one)."""
    numbers = list(numbers)
    if len(numbers) <= SHOWN_NUMBERS:
        return str(numbers)
    return "[" + ", ".join(map(str, numbers[:SHOWN_NUMBERS - 1])) + f", ... {len(numbers)} in all]"


def paper_flops(rep: dict) -> int:
    """The paper's formula in flops at the report's Mult and Addn latencies (the paper's own figure
    when both are 1 flop)."""
    from vampc.machine.ops import Timing
    t, paper = rep["timing"], rep["paper"]
    return Timing(t["mult_latency"], t["add_latency"]).flops(paper["mults"], paper["adds"])


def latency_terms(rep: dict, lat: dict) -> str:
    """'16 Mults + 45 Addns', '28 Mults × 3 + 33 Addns', '12 Mults + 30 Addns + 2 waiting'."""
    t = rep["timing"]
    ml, al = t["mult_latency"], t["add_latency"]
    text = (f"{lat['mults']} Mults" + (f" × {ml}" if ml != 1 else "")
            + f" + {lat['adds']} Addns" + (f" × {al}" if al != 1 else ""))
    return text + (f" + {lat['waits']} waiting" if lat.get("waits") else "")


def plus_minus(v: int) -> str:
    """An integer with its sign, a minus sign as the tables write it, not a hyphen ('+3', '−2',
    '+0'; vampc.report.sections.signed writes 0 bare and groups thousands)."""
    return f"{v:+d}".replace("-", "−")


def latency_note(rep: dict) -> list[str]:
    """Sentences explaining where the achieved latency differs from the paper's formula, and why."""
    got, paper = rep["latency"], rep["paper"]
    if rep.get("tree"):
        return [TREE_SENTENCE]
    dm, da = got["mults"] - paper["mults"], got["adds"] - paper["adds"]
    expected = paper_flops(rep)
    if (dm, da) == (0, 0) and got["flops"] == expected:
        return ["equals the paper's formula"]
    scaled = "" if expected == paper["flops"] else " at these latencies"
    notes = [f"{plus_minus(got['flops'] - expected)} flops ({plus_minus(dm)} Mults, "
             f"{plus_minus(da)} Addns"
             + (f", {got['waits']} waiting" if got.get("waits") else "")
             + f") against the paper's formula{scaled}"]
    # the longest data path, where a budget's bounds give it (a route that waited may be shorter)
    path = (rep.get("budget") or {}).get("critical_path")
    if path is not None and got.get("waits"):
        rep = {**rep, "latency": {**got, "data_path": path}}
    return notes + [long for _, long in latency_reasons(rep)]


CORRECTION = "output correction, +1 M + 2 A"
TIER = "one tier less each way (n a power of 2)"
TIER_TIP_TO_BASE = "one tier less tip to base (n a power of 2)"
TIP = "tip force, +1 A"
LEAF = "leaf p̈ unpadded, −2 A"
LEAF_S = "leaf S unpadded, −1 A"
UNIFORM = "uniform leaves, +2 A"
TREE_SENTENCE = ("the paper's formula is for a serial chain of n joints on a fixed base; a tree's or a "
                 "floating base's latency follows its depth, not n (README, Trees and floating bases)")
# what each itemised reason accounts for, (Mults, Addns) on the path: what is left of a difference
# from the paper's formula is said to be unexplained (`latency_reasons`)
ACCOUNTED = {CORRECTION: (1, 2), TIER: (-2, -6), TIER_TIP_TO_BASE: (-1, -3), TIP: (0, 1),
             LEAF: (0, -2), LEAF_S: (0, -1), UNIFORM: (0, 2)}


def tip_force(chain) -> bool:
    """Whether a force acts at the tip: the log recursion folds it into leaf n, one VA on the path
    (a torque alone at the tip is added off it: measured, README, Figures against the paper)."""
    import numpy as np
    return bool(np.any(chain.tip_force))


def path_conditions(chain) -> dict:
    """The report's keys for what moves the log recursion's latency off the paper's formula beyond
    its own reasons (latency_reasons): present only when true, so other reports keep their bytes."""
    if not chain.is_fixed_chain:     # (a tree's latency follows its depth: not itemised)
        return {}
    return {**({"base_rotates": True} if chain.base_rotates else {}),
            **({"tip_force": True} if tip_force(chain) else {})}


def _unaccounted(got: dict, paper: dict, reasons) -> tuple[int, int] | None:
    """The (Mults, Addns) of a latency's difference from the paper's formula that `reasons` do not
    account for, where each is a known count (ACCOUNTED); None where one is not."""
    if not all(short in ACCOUNTED for short, _ in reasons):
        return None
    return (got["mults"] - paper["mults"] - sum(ACCOUNTED[short][0] for short, _ in reasons),
            got["adds"] - paper["adds"] - sum(ACCOUNTED[short][1] for short, _ in reasons))


def _sized(mults: int, adds: int) -> str:
    """'−1 M, −3 A' (the nonzero parts)."""
    return ", ".join(f"{plus_minus(v)} {unit}" for v, unit in ((mults, "M"), (adds, "A")) if v)


def latency_reasons(rep: dict) -> list[tuple[str, str]]:
    """Why a latency differs from the paper's formula, each reason as (short, sentence); `rep` holds
    the summary keys latency, paper, joints, recursion, uniform_leaves, timing, prismatic_joints,
    and optionally tree (a tree or floating base: "tree" or "floating"), prefix (its shape),
    base_rotates and tip_force (path_conditions) and revolute_path (with prismatic joints: the
    same arm's path with them revolute, vampc.report.compare.revolute_path)."""
    got, paper = rep["latency"], rep["paper"]
    turned = rep.get("revolute_path")
    if rep["prismatic_joints"] and turned and not rep.get("tree"):
        # what the prismatic joints change, measured between this arm's graph and the same arm's
        # with them revolute (vampc.report.compare.revolute_path), then the reasons of the rest,
        # this schedule's own (its waits, a route that waits): the prismatic joints' reason had no
        # size, a one-joint arm's −2 M − 6 A left unsaid (a hardware user's find)
        dm, da = turned["own_mults"] - turned["mults"], turned["own_adds"] - turned["adds"]
        from vampc.machine.ops import Timing
        timing = Timing(rep["timing"]["mult_latency"], rep["timing"]["add_latency"])
        rest = {**got, "mults": got["mults"] - dm, "adds": got["adds"] - da}
        if got.get("data_path") is not None:     # (the longest data path, shifted the same)
            rest["data_path"] = got["data_path"] - timing.flops(dm, da)
        reasons = latency_reasons({**rep, "prismatic_joints": [], "revolute_path": None,
                                   "latency": rest})
        size = _sized(dm, da) or "no change"
        return reasons + [(f"prismatic joints, {size}",
                           f"prismatic joints {numbers_text(rep['prismatic_joints'])}: Table I.1's "
                           f"σ̄ terms in place of the rotary ones: {size} on the path against the "
                           "same arm with revolute joints (its graph's critical path, measured; "
                           "the paper's formula is for a general rotary arm)")]
    reasons = [(CORRECTION,
                "includes the output correction of 1 Mult + 2 Addns: τ_i = z_{i-1}·n_i is the third "
                "coordinate of A_i n_i, not of n_i (the paper's convention is exact only when Φ_i = "
                "I), so f and n are carried referred to O_{i-1} with one more MV on the path to the "
                "torques (README, Exactness convention)")]
    n = rep["joints"]
    log = Recursion(rep["recursion"]) is Recursion.LOG
    # a tip force's Addn is on Sklansky's path (measured, n = 1..33); with another prefix it often
    # is not (Kogge-Stone n = 3, 5, 6, 12: no cost), so it is counted with Sklansky's only
    sklansky = rep.get("prefix", "sklansky") in (None, "sklansky")     # (the paper's prefix)
    tip = bool(rep.get("tip_force")) and sklansky
    unit_timing = rep["timing"]["mult_latency"] == 1 and rep["timing"]["add_latency"] == 1
    # (Mults and Addns on the path, not flops: a folded layout's waits had hidden the saving there,
    # its row giving only the output correction beside the same -1 M, -4 A: a new user's find)
    tier_saved = log and n & (n - 1) == 0 and \
        got["mults"] + got["adds"] < paper["mults"] + paper["adds"] + 3 + tip
    if rep.get("tree"):     # (neither a tier a power of two saves nor a residual: its depth counts)
        reasons.append(("a tree: its depth, not n" if rep["tree"] == "tree" else
                        "a floating base", TREE_SENTENCE))
    elif tier_saved and rep.get("base_rotates"):
        # (the base rotating, a tier was still said saved each way: 1 M + 3 A of the difference
        # went unexplained, and unsaid: a new user's find)
        reasons.append((TIER_TIP_TO_BASE,
                        "log recursion: the base rotates, so the base-to-tip pass is grounded in "
                        "O_{-1} and spans n + 1 leaves, as the paper's formula counts; the "
                        "tip-to-base pass spans n leaves, which saves a whole tier there (4 flops) "
                        "when n is a power of 2"))
    elif tier_saved:
        reasons.append((TIER,
                        "log recursion: grounded in O_0 when the base does not rotate (section VI), "
                        "the prefix network spans n leaves instead of n + 1, which saves a whole tier "
                        "each way (8 flops) when n is a power of 2"))
    if log and tip and not rep.get("tree"):
        # (it was "+1 A not explained", naming a README section that says nothing of loads)
        reasons.append((TIP, "the force at the tip is folded into leaf n (F_n + f_{n+1}): one VA on "
                             "the path (a torque at the tip is added off it); the paper's arm has a "
                             "free tip"))
    if log and n == 1 and not rep.get("tree") and not rep.get("base_rotates") and \
            not rep.get("uniform_leaves") and not rep["prismatic_joints"]:
        # (one joint: no combining node follows the leaf, so its p̈ is on the path; it was "-2 A
        # not explained" until a check against Appendix C)
        reasons.append((LEAF, "one joint: the leaf's p̈ is on the path, at MV + 2 VC + VA, where "
                              "Appendix C pads it to MV + 2 VC + 3 VA (a VA for a prismatic joint's "
                              "σ̄ term, none for a revolute one, and one for its delay conditions)"))
    if log and n <= 2 and rep.get("base_rotates") and not rep.get("tree") and sklansky and \
            not rep.get("uniform_leaves") and not rep["prismatic_joints"] and unit_timing:
        # (the first combining node joins leaf 0's constants to joint 1's leaf, so the route into
        # its p̈ starts at that leaf's S; measured on the critical path, n = 1 and 2: ω, S, then the
        # node's T11, T12, ... p̈. It was "−1 A not explained" until a check against Appendix C)
        reasons.append((LEAF_S, "the base rotates and n ≤ 2: the first combining node joins leaf 0's "
                                "constants (ω0, ω̇0, gravity) to joint 1's leaf, so the path into its "
                                "p̈ starts at that leaf's S, ready at MV + VC, where Appendix C pads "
                                "S_{a,a} to MV + VC + VA"))
    if log and rep.get("uniform_leaves"):
        reasons.append((UNIFORM, "Appendix D's uniform leaves cost 2 Addns more than Table IV.1's leaves"))
    if not unit_timing:
        # (it said only that a slower Mult can move the path onto another route: a new user found
        # the same 38 ops on the path at 3 and 2 flops as at 1 and 1, its +15 M −12 A against the
        # formula being the shared steps counted as Mults)
        shared = ("; here the Mult is the slower, so those count as Mults where the paper's MV is "
                  "1 Mult + 2 Addns, which moves Addns to Mults in the difference"
                  if rep["timing"]["mult_latency"] > rep["timing"]["add_latency"] else "")
        reasons.append(("Mult/Addn latencies ≠ 1 flop",
                        "the paper assumes 1 Mult = 1 Addn = 1 flop; its formula is compared at the "
                        "given latencies with its own Mult and Addn counts. A micro-step running the "
                        "multiplier beside the adder (the middle step of MV, MTV and MM) lasts as long "
                        f"as the slower unit and counts as that unit{shared}; a slower unit can also "
                        "move the critical path onto another route"))
    if rep["prismatic_joints"]:
        # (measured against the same arms all revolute, 48 random chains of 1-9 joints: never a
        # longer path, the same or shorter, by 1 M + 4 A linear, 1 A to 2 M + 4 A log (README,
        # Exactness convention); "add the σ̄ terms" had been read as a cost)
        reasons.append(("prismatic joints (σ̄ terms)",
                        f"prismatic joints {numbers_text(rep['prismatic_joints'])}: Table I.1's σ̄ "
                        "terms add ops but no latency, and the path is the same as with revolute "
                        "joints or shorter "
                        "(the paper's formula is for a general rotary arm)"))
    if log and rep.get("prefix", "sklansky") != "sklansky":
        # sized where every other reason is a known count: the rest of the difference is the
        # prefix's, with what Sklansky's leaves would have saved (a Kogge-Stone row's parts had come
        # to -1 A against -2 A, and a 3-joint one's -1 M -3 A had no size: a report audit's)
        rest = _unaccounted(got, paper, reasons)
        size = "" if rest is None else _sized(*rest) or "no change"
        reasons.append((f"a {rep['prefix']} prefix" + (f", {size}" if size else ""),
                        f"the paper's formula counts Sklansky's prefix network; a {rep['prefix']} "
                        # (not "other depths": at n = 6 both have 3 tiers; a review's find)
                        "prefix joins other pairs of partial results, on other sides of Table V.1's "
                        "combining node, which is not symmetric (X_{a,k}'s vectors are turned by "
                        "W_{k+1,b}, an MV before the VA that adds X_{k+1,b}'s)"
                        + (f" ({size} on the path here, the rest of the difference)" if size else "")
                        + " (compile with --prefix sklansky to compare)"))
    # what the reasons above account for, where each is a known count: anything left is said to be
    # unexplained (the log recursion at n = 1 showed 2 Addns fewer than the reasons gave, its row
    # saying only the reasons: a new user's find)
    rest = _unaccounted(got, paper, reasons)
    if rest is not None and rest != (0, 0):
        left_m, left_a = rest
        left = _sized(left_m, left_a)
        ml, al = rep["timing"]["mult_latency"], rep["timing"]["add_latency"]
        waits = got.get("waits") or 0
        longest = got.get("data_path")          # the graph's longest data path (flops), if known
        from vampc.machine.ops import Timing
        if waits and longest is not None and longest > Timing(ml, al).flops(got["mults"],
                                                                            got["adds"]) \
                and left_m <= 0 and left_a <= 0:
            # (a budget schedule's critical path can be a shorter route that waited: the exact
            # solver's Puma, 14 M + 42 A + 5 waiting = 61 on a route other than the 61-flop data
            # path, was "-2 M, -3 A not explained"; where the route is the longest data path, a
            # remainder stays unexplained: a one-joint log arm on 2 VAMPs, -2 A)
            reasons.append((f"{left} on a route that waits",
                            f"{left}: the schedule's critical path is another route than the "
                            f"longest data path, with fewer ops and {count(waits, 'flop')} of "
                            "waiting; the longest data path ends within the same latency"))
        else:
            reasons.append((f"{left} not explained",
                            f"{left} on the path beyond what the reasons above account for: "
                            "not explained yet (README, Figures against the paper)"))
    return reasons


def vamp_notes(rep: dict) -> list[str]:
    """Where the per-node VAMP counts differ from section VI, and why."""
    per = rep["vamps"]["per_node"]
    paper = {"linear": (12, 10, 8), "log": (26, 10, 13)}[rep["recursion"]]
    notes = _layout_notes(rep)
    if Recursion(rep["recursion"]) is Recursion.LOG and per["fwd"] == 12:
        notes.append("forward node 12 VAMPs, paper 13: with f, n referred to O_{a-1} the forward "
                     "combine needs W_{a,k} and R_{a,k} as the backward pass makes them, so the "
                     "paper's T20 = A_{k+1}ᵀ R_{a,k} (one MV) is not needed")
    if per["bwd"] != paper[0] and not rep["prismatic_joints"]:
        why = (": in a tree, a joint whose frame is shifted from its parent's (at a branch, o_i ≠ 0) "
               "first forms its origin's acceleration, H1..H5 = 3 VC + 2 VA, 5 VAMPs more (README, "
               "Trees and floating bases)" if rep.get("tree") and per["bwd"] - paper[0] == 5 else "")
        notes.append(f"backward node {per['bwd']} VAMPs, paper {paper[0]}{why}")
    if Recursion(rep["recursion"]) is Recursion.LOG and not rep.get("uniform_leaves") and \
            not is_layout(rep.get("layout"), FOLDED):    # (_layout_notes says it for a folded one)
        notes.append("leaves are Table IV.1's separate a = b forms (fewer VAMPs than Appendix D's "
                     "uniform nodes, which section VI counts: use --uniform-leaves to compare)")
    return notes


def _layout_notes(rep: dict) -> list[str]:
    """The single-device counts of section VI beside a folded layout's."""
    if not is_layout(rep.get("layout"), FOLDED):
        return []
    if Recursion(rep["recursion"]) is Recursion.LINEAR:
        paper = "22 with the passes sharing processors" if rep.get("share_passes") else "22 + 8"
        # (the σ̄ clause was said of all-revolute arms too: a new user's find)
        prismatic = rep.get("prismatic_joints")
        return [f"single device (section VI, Figure VI.1): paper {paper} for a general rotary arm"
                + (f"; prismatic joints {numbers_text(prismatic)} add VAMPs for their σ̄ terms"
                   if prismatic else "")]
    notes = ["single device (section VI, n = 6): paper 98 + 39, a tier of 3 nodes (26 + 10 "
             "backward, 13 forward each); vampc binds each tier position's ops by name"]
    if not rep.get("uniform_leaves"):
        notes.append("leaves are Table IV.1's separate forms, whose ops get VAMPs of their own "
                     "(use --uniform-leaves to compare with section VI)")
    return notes
