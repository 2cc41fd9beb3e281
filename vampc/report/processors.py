"""Processors (section VI) and packages (section VII), measured from the compiled configurations:
VAMPs by recursion and pass — propagated, non-propagated and forward — per node, per tier, as a
single device (the folded layout), with the passes sharing, and as a systolic pipeline; the ops of a
node by kind; and the 40-pin (or --pins N) packages each configuration needs."""
from __future__ import annotations

from collections import Counter
from dataclasses import replace

import numpy as np

from vampc.kinds import Recursion, Section, unhandled
from vampc.machine.ops import TABLE, VAMPS_PER_OP, Op, View
from vampc.memo import keep_last
from vampc.report import paper
from vampc.report.counts import physical_vamps, plus_minus, prismatic_joints
from vampc.report.sites import node_table, unit_firsts
from vampc.schedule.layout import folded_binding
from vampc.schedule.registry import FOLDED, SYSTOLIC
from vampc.textio import count

COLUMNS = ("per_node", "per_tier", "single_device", "systolic")


def processors(configs, chain, other_leaves: bool = True) -> dict:
    """VAMP tables and ops per node for every recursion the configurations cover, and for the log
    recursion also with the other leaf style (section VI counts Appendix D's uniform leaves) when
    `other_leaves`."""
    graphs = _graphs(configs, chain, other_leaves)
    own = list(dict.fromkeys(k.recursion for k in configs))
    bindings = {(id(k.graph), k.options.share_passes): (k.layout.units, k.layout.unit_vamps)
                for k in configs if k.options.layout_kind is FOLDED}
    return {"vamps": [_variant(graph, leaves, chain, _binder(graph, bindings))
                      for graph, leaves in graphs],
            "ops_per_node": [_ops_row(graph, s, chain) for graph, _ in graphs[:len(own)]
                             for s in ("bwd", "npv", "fwd")]}


def _graphs(configs, chain, other_leaves: bool) -> list:
    """(graph, leaves) per recursion in the configurations, then the log graph with the other leaf
    style: built here (binding and counts only, no schedule)."""
    out, seen = [], set()
    for k in configs:
        if k.recursion not in seen:
            seen.add(k.recursion)
            out.append((k.graph, _leaves(k.graph, k.options)))
    log = next((k for k in configs if k.recursion is Recursion.LOG), None)
    if log is not None and other_leaves:
        from vampc.compiler import build_graph
        other = replace(log.options, uniform_leaves=not log.options.uniform_leaves, verify=False)
        out.append((build_graph(chain, other), _leaves(None, other)))
    return out


def _leaves(graph, options) -> str | None:
    """The leaf style of a log graph (None for a linear one; `graph` None: a log graph)."""
    match Recursion.LOG if graph is None else graph.recursion:
        case Recursion.LINEAR:
            return None
        case Recursion.LOG:
            return "uniform" if options.uniform_leaves else "separate"
        case other:
            return unhandled(other)


def _binder(graph, bindings: dict):
    """share_passes -> the folded binding of `graph`: a folded configuration's layout when there
    is one (it is that binding), else made here."""
    return lambda share: bindings.get((id(graph), share)) or folded_binding(graph, share)


def _variant(graph, leaves, chain, binding) -> dict:
    """One recursion's VAMP table: rows bwd (propagated), npv, bwd total, fwd; paper beside.
    `binding(share_passes)` gives the folded binding (vampc.schedule.layout.folded_binding)."""
    n = chain.n
    per_node = _per_node(graph)
    single = _by_section(graph, binding(False))
    tier = _per_tier(graph, single)
    shared = sum(binding(True)[1])
    systolic = Counter()
    for (section, _, op), k in _node_ops(graph).items():
        systolic[section] += VAMPS_PER_OP[op] * k
    rows = []
    for sec in ("bwd", "npv", "bwd_total", "fwd"):
        parts = ("bwd", "npv") if sec == "bwd_total" else (sec,)
        row = {"section": sec,
               "per_node": sum(per_node[p] for p in parts),
               "per_tier": (sum(tier[p] for p in parts) if graph.recursion is Recursion.LOG else None),
               "single_device": sum(single[p] for p in parts),
               "systolic": sum(systolic[p] for p in parts)}
        row["paper"] = _paper_row(graph.recursion, sec, n)
        row["note"] = _vamp_note(graph.recursion, sec, leaves, row, chain)
        rows.append(row)
    return {"recursion": graph.recursion, "leaves": leaves, "prefix": dict(graph.meta).get("prefix"),
            "rows": rows, "shared_passes": shared, "paper_shared_passes":
            _paper_shared(graph.recursion, n, leaves), "by_op": _by_op(graph, binding)}


def _by_op(graph, binding) -> dict:
    """VAMPs by op kind: of the systolic pipeline (one per op, three per MM) and of the single
    device and the shared-pass device (a unit counts as the kind of its first op: its ops share it
    by role, and with shared passes a forward op may run on a VAMP of another kind — every VAMP
    runs every op of the ROM)."""
    systolic: Counter = Counter()
    for (_, _, op), k in _node_ops(graph).items():
        systolic[op.value] += VAMPS_PER_OP[op] * k
    out = {"systolic": dict(sorted(systolic.items()))}
    for name, share in (("single_device", False), ("shared_passes", True)):
        units, sizes = binding(share)
        got: Counter = Counter()
        for u, nd in enumerate(unit_firsts(graph, units)):
            if nd is not None:
                got[nd.op.value] += sizes[u]
        out[name] = dict(sorted(got.items()))
    return out


@keep_last(4)
def _node_ops(graph) -> Counter:
    """Compute nodes by (section, recursion node, op): one walk of a big graph for every count of
    this module."""
    out: Counter = Counter()
    for nd in graph.compute_nodes():
        out[(nd.section, nd.group, nd.op)] += 1
    return out


def _per_node(graph) -> Counter:
    """VAMPs of the busiest recursion node of each section."""
    groups: Counter = Counter()
    for (section, group, op), k in _node_ops(graph).items():
        groups[(section, group)] += VAMPS_PER_OP[op] * k
    out: Counter = Counter()
    for (sec, _), k in groups.items():
        out[sec] = max(out[sec], k)
    return out


def _per_tier(graph, single: Counter) -> Counter:
    """Log graph: VAMPs of the busiest tier of combining nodes per pass; for the non-propagated
    variables, those the single device (`single`, VAMPs by section) runs beside each tier
    (⌈n / tiers⌉ joints' worth)."""
    out: Counter = Counter()
    if graph.recursion is not Recursion.LOG:
        return out
    table = node_table(graph)
    tier_of = {(sec, r[0]): r[4] for sec, rows in table.items() for r in rows}
    sums: Counter = Counter()
    for (section, group, op), k in _node_ops(graph).items():
        t = tier_of.get((section, group), 0)
        if section is not Section.NPV and t > 0:
            sums[(section, t)] += VAMPS_PER_OP[op] * k
    for (sec, _), k in sums.items():
        out[sec] = max(out[sec], k)
    out["npv"] = single["npv"]
    return out


def _by_section(graph, binding) -> Counter:
    """VAMPs of a binding's units per section (a unit serving both passes counts as backward)."""
    units, sizes = binding
    out: Counter = Counter()
    for u, nd in enumerate(unit_firsts(graph, units)):
        if nd is not None:
            out[nd.section] += sizes[u]
    return out


def _paper_row(recursion: str, sec: str, n: int) -> dict:
    """The section VI figures for this row (its tables are for n = 6; per node holds for any n)."""
    if sec == "bwd_total":
        src = paper.VAMPS_N6_TOTALS[(recursion, "bwd")]
    else:
        src = paper.VAMPS_N6[(recursion, sec)]
    got = {"per_node": src["per_node"], "per_tier": src["tier"],
           "single_device": src["single_device"], "systolic": src["systolic"]}
    return got if n == 6 else {c: (got[c] if c == "per_node" else None) for c in COLUMNS}


def _paper_shared(recursion: str, n: int, leaves) -> int | None:
    """Single device with the passes sharing processors (Figure VI.1b), n = 6: the paper prints no
    count; its tables imply the larger pass's single device (inferred, and labelled so)."""
    if n != 6:
        return None
    t = paper.VAMPS_N6_TOTALS
    return max(t[(recursion, "bwd")]["single_device"], t[(recursion, "fwd")]["single_device"])


def _vamp_note(recursion: str, sec: str, leaves, row: dict, chain) -> str:
    """Whether the row matches the paper, and why not where it does not."""
    ref = row["paper"]
    diff = [c for c in COLUMNS if ref.get(c) is not None and row[c] != ref[c]]
    log_fwd = Recursion(recursion) is Recursion.LOG and sec == Section.FWD
    tree = not chain.is_fixed_chain
    tip = not tree and bool(np.any(chain.tip_force) or np.any(chain.tip_torque))
    odd = log_fwd and row["per_node"] != 12 and tip      # (13 = 12 and a tip torque's VA)
    if not diff and not odd:
        return "matches the paper" if any(ref.get(c) is not None for c in COLUMNS) else ""
    why = []
    if log_fwd:
        why.append(_log_forward_why(row["per_node"], chain, tree, tip))
    if Recursion(recursion) is Recursion.LOG and leaves == "separate" and "systolic" in diff:
        why.append("Table IV.1's leaves are cheaper than the uniform nodes section VI counts "
                   "(--uniform-leaves to compare)")
    if Recursion(recursion) is Recursion.LOG and leaves == "separate" and "single_device" in diff:
        why.append("the single device also runs the leaves, on device nodes of their own roles")
    if not why and tree:
        # (it said "see README, Layouts" of every per-node count of a tree that differs)
        why.append(_tree_why(recursion, sec, row, ref, chain))
    if not why and not log_fwd and Recursion(recursion) is Recursion.LOG and chain.n == 1:
        # (it said "see README, Layouts", or of a prismatic joint "add the σ̄ terms" beside 3 [26])
        why.append(f"one joint: its leaf is the only backward node, {row['per_node']} VAMPs (no "
                   "combining node to compare with the paper's)")
    prismatic = prismatic_joints(chain)
    if not why and prismatic:      # (the Stanford arm's 14 [12] said "see README, Layouts")
        from vampc.report.counts import numbers_text
        more = ref.get("per_node") is None or row["per_node"] >= ref["per_node"]
        why.append(f"prismatic joints {numbers_text(prismatic)} "
                   f"{'add' if more else 'take'} the σ̄ terms (Table I.1's translational case, "
                   f"{'beside' if more else 'in place of'} the rotary terms; section VI counts a "
                   "rotary arm)")
    head = (f"differs in {', '.join(c.replace('_', ' ') for c in diff)}: " if diff else
            "per node as the paper's, for another reason: ")
    return head + ("; ".join(why) or "see README, Layouts")


def _tree_why(recursion: str, sec: str, row: dict, ref: dict, chain) -> str:
    """Why a tree's per-node VAMPs differ from the paper's chain (README, Trees and floating
    bases): measured for the linear recursion, said in general otherwise."""
    linear = Recursion(recursion) is Recursion.LINEAR
    if chain.is_chain:               # a floating base on a serial chain
        return ("the base floats: its motion and wrench are the network's inputs and outputs, "
                "beyond the paper's fixed base (README, Trees and floating bases)")
    if linear and sec == Section.FWD:
        # (the sums were given as the reason on a quadruped, whose joints have one child each: its
        # busiest node is a hip on the trunk, a trees audit's find)
        kids = [0] * (chain.n + 1)
        for p in chain.parent_of:
            kids[p] += 1
        several = any(k > 1 for k in kids[1:])
        turned = any(j.pre is not None for j in chain.joints)    # (vampc.dataflow.linear's VD)
        return ("the robot has branches (a tree): " + (
            "a joint with several children sums their f' and n' (VA trees), " if several else "") +
            "a child whose frame is shifted from its parent's carries its moment over (Y1, Y2: "
            "VC + VA)" + (" and a joint whose axis is not its parent frame's z takes τ = u·n' (VD)"
                          if turned else "") +
            ", beyond the paper's Table I.1 (README, Trees and floating bases)")
    if linear and sec in (Section.BWD, "bwd_total") and ref.get("per_node") is not None and \
            row["per_node"] - ref["per_node"] == 5:
        return ("the robot has branches (a tree): a joint whose frame is shifted from its parent's "
                "(at a branch, o_i ≠ 0) first forms its origin's acceleration, H1..H5 = 3 VC + 2 VA, "
                "5 VAMPs more (README, Trees and floating bases)")
    return ("the robot has branches (a tree): its nodes are not the paper's chain's (README, "
            "Trees and floating bases)")


def _log_forward_why(per_node: int, chain, tree: bool, tip: bool) -> str:
    """Why the log recursion's busiest forward node is not the paper's 13 VAMPs: it said "12, not
    13" beside a tree's 6 and a tip-loaded leaf's 14 (a new user's find)."""
    if tree:
        return (f"a tree's or floating base's forward pass adds its subtrees' forces and moments in "
                f"addition levels, not through the paper's combining nodes: its busiest node has "
                f"{per_node} VAMPs (README, Trees and floating bases)")
    if chain.n == 1:   # (it said "12, not 13" beside 4, or 6 with a tip force)
        return (f"one joint: its leaf is the only forward node, {per_node} VAMPs (no combining "
                "node to compare with the paper's)")
    why = ("forward node 12 VAMPs, not 13: with f, n referred to O_{a-1} the paper's "
           "T20 = A_{k+1}ᵀ R_{a,k} is not needed (README, Figures against the paper)")
    if per_node > 12 and tip:
        why += (f"; the busiest is leaf n, {per_node}: it folds in the tip load, "
                f"{count(per_node - 12, 'VA')} more")
    return why


@keep_last()
def _ops_by_node(graph) -> dict[str, dict[int, Counter]]:
    """Per section, per recursion node (group): its ops by kind (one walk for every section)."""
    out: dict[str, dict[int, Counter]] = {}
    for (section, group, op), k in _node_ops(graph).items():
        out.setdefault(section, {}).setdefault(group, Counter())[op.value] += k
    return out


def _ops_row(graph, section: str, chain=None) -> dict:
    """Ops of the busiest node of a section by kind, beside the paper's requirements per node (its
    MV covers vampc's MV and MTV)."""
    groups = _ops_by_node(graph).get(section, {})
    busiest = max(groups.values(), key=lambda c: (sum(VAMPS_PER_OP[Op(o)] * k for o, k in c.items()),
                                                  sum(c.values())), default=Counter())
    ops = dict(sorted(busiest.items()))
    ref = paper.OPS_PER_NODE[(graph.recursion, section)]
    as_paper = Counter({("MV" if o == "MTV" else o): k for o, k in ops.items() if o != "MTV"})
    as_paper["MV"] += ops.get("MTV", 0)
    as_paper = {o: k for o, k in as_paper.items() if k}
    matches = as_paper == ref
    note = "matches the paper (its MV counts MV and MTV)" if matches else _ops_note(graph, section,
                                                                                    as_paper, ref, chain)
    return {"recursion": graph.recursion, "section": section, "ops": ops,
            "total": sum(ops.values()), "paper": ref, "paper_total": sum(ref.values()),
            "matches": matches, "note": note}


def _ops_note(graph, section: str, got: dict, ref: dict, chain=None) -> str:
    diff = ", ".join(f"{o} {got.get(o, 0)} (paper {ref.get(o, 0)})" for o in sorted(set(got) | set(ref))
                     if got.get(o, 0) != ref.get(o, 0))
    features = _beyond_the_paper(chain) if chain is not None else []
    if graph.recursion is Recursion.LOG and chain is not None and chain.n == 1 and not got.get("MM"):
        # (one joint: the pass is a leaf with no combining node; the backward row said "not
        # explained", the forward row put an 11-against-4 difference down to T20 alone)
        return (f"differs: {diff}: one joint: this pass is its leaf alone (Table IV.1's a = b form), "
                "with no combining node to set beside section VI's")
    if graph.recursion is Recursion.LOG and section == Section.FWD:
        # (the robot's features said only where they change the node beyond T20: a Stanford arm's
        # forward node is the Puma's, and was said to differ for its prismatic joint too)
        t20 = {o: k - (o == "MV") for o, k in ref.items() if k - (o == "MV")}
        also = (f"; the robot also has {', '.join(features)}, beyond the paper's counts (README, "
                "Trees and floating bases)" if features and got != t20 else "")
        return (f"differs: {diff}: no T20 = A_{{k+1}}ᵀ R_{{a,k}} with f, n referred to O_{{a-1}} "
                f"(README, Figures against the paper){also}")
    if not features:        # (the paper's own kind of robot: a difference nothing here explains)
        return (f"differs: {diff}; the robot is a fixed-base chain of revolute joints in DH frames, "
                "as the paper's, so this is not explained")
    # (the paper's Table I.1 has translational joints; its per-node counts are a rotary arm's)
    return (f"differs: {diff}: the robot has {', '.join(features)}, beyond the paper's per-node "
            "counts (a fixed-base chain of revolute joints in DH frames; README, Trees and floating "
            "bases)")


def _beyond_the_paper(chain) -> list[str]:
    """What a robot has that the paper's node requirements (Table I.1) do not cover: prismatic
    joints add the σ̄ terms; joint frames shifted or turned from their parent's (a URDF's) add
    the origin's acceleration (H1..H5) and τ = u·n; a tree's branches, a floating base."""
    from vampc.robot.chain import JointType
    out = []
    prismatic = [i + 1 for i, j in enumerate(chain.joints) if j.type is JointType.PRISMATIC]
    if prismatic:
        out.append(f"prismatic joints ({', '.join(map(str, prismatic[:6]))}"
                   f"{', ...' if len(prismatic) > 6 else ''}: σ̄ terms)")
    if any(j.shift is not None or j.pre is not None for j in chain.joints):
        out.append("joint frames shifted or turned from their parent's (not DH)")
    if chain.parents is not None and len(set(chain.parents)) < len(chain.parents):
        out.append("branches (a tree)")   # (a chain in tree form, as a floating base's, has none)
    if chain.floating:
        out.append("a floating base")
    return out


# --- packages ------------------------------------------------------------------------------------

def packages(configs, pins: int | None, chain=None) -> dict:
    """Packages per configuration by the paper's pin budget (section VII) at 40 pins and at `pins`;
    for an allocated configuration also with each operand wire as a pin of its own (vamp_pins)."""
    sizes = [40] + ([pins] if pins and pins != 40 else [])
    rows = []
    for k in configs:
        row = {"configuration": k.name, "vamps": k.vamps, "own": k.own, "by_pins": []}
        # (with error correction the extraneous VAMP is a VAMP to package too: the muxed counts
        # pack it, and the paper's budget counted without it, 36 packages beside 91 for 181)
        chips = k.vamps if k.network is None else physical_vamps(k.network)
        if chips != k.vamps:
            row["packaged_vamps"] = chips       # (the table said 180 beside counts for 181)
        for size in sizes:
            entry = {"pins": size, **{f"paper_{s}": v for s, v in
                                      paper.paper_packages(chips, size).items()}}
            if k.network is not None:
                entry.update(_packed(k.network, size))
            row["by_pins"].append(entry)
        rows.append(row)
    return {"pins": sizes, "budget": budget(sizes), "rows": rows, "paper_check": _paper_check(configs, chain)}


def budget(sizes) -> dict:
    """The pin budget per VAMP (section VII) and what a package of each size holds."""
    return {"separate": {"pins_per_vamp": len(paper.PINS_SEPARATE), "signals": list(paper.PINS_SEPARATE)},
            "shared": {"pins_per_vamp": len(paper.PINS_SHARED_PER_VAMP),
                       "signals": list(paper.PINS_SHARED_PER_VAMP),
                       "pins_per_package": len(paper.PINS_SHARED_PER_PACKAGE),
                       "package_signals": list(paper.PINS_SHARED_PER_PACKAGE)},
            "vamps_per_package": {str(p): paper.vamps_per_package(p) for p in sizes}}


def operand_wires(vamp) -> int:
    """The wires into a VAMP's operand multiplexers: one per tap it reads (read_taps), so three for
    a matrix whose columns three VAMPs (an MM group) make, latched at one tick (README, Timing
    model), but one where the VAMP reads one column of it (an MM member's operand B)."""
    n = len(vamp.a) + len(vamp.b)
    for operand in (vamp.a, vamp.b):     # (most inputs are one tap: a million VAMPs in a big report)
        for o in operand:
            if len(o.taps) != 1:
                return sum(len(taps) for taps in read_taps(vamp))
    return n


def read_taps(vamp):
    """The taps each multiplexer input of `vamp` carries that its slots read, operand A's inputs
    then B's: every tap, but of a matrix operand that every slot selecting it reads through
    View.BCOLUMN (an MM member computing column c: A times column c of B) only the columns read.
    The VAMP computing column c of A·B needs column c of B, one wire, not three: a review counted
    12 pins where the Puma's log VAMPs need 10 (84 packages of 40 pins for 83)."""
    slots = vamp.slots
    if len(slots) == 1:               # (a systolic VAMP: its one slot's selects, found at once)
        s = slots[0]
        views = TABLE[s.op].views
        for side, inputs, sel in ((0, vamp.a, s.sel_a), (1, vamp.b, s.sel_b)):
            column = views[side] is View.BCOLUMN
            for i, o in enumerate(inputs):
                yield (o.taps[s.column],) if column and i == sel and len(o.taps) > 1 else o.taps
        return
    users: dict = {}                  # (side, input) -> its slots, found once a VAMP (a review:
    for s in vamp.slots:              # per input it made a big log report's fan-out 6 times slower)
        users.setdefault((0, s.sel_a), []).append(s)
        users.setdefault((1, s.sel_b), []).append(s)
    for side, inputs in ((0, vamp.a), (1, vamp.b)):
        for i, o in enumerate(inputs):
            taps = o.taps
            if len(taps) > 1:
                by = users.get((side, i), ())
                if by and all(TABLE[s.op].views[side] is View.BCOLUMN for s in by):
                    taps = tuple(taps[c] for c in sorted({s.column for s in by}))
            yield taps


def vamp_pins(vamp) -> dict[str, int]:
    """Pins one VAMP needs: the paper's budget with one pin per wire into its operand multiplexers
    (operand_wires: a systolic VAMP reading a vector, a host port or a constant on each operand
    needs the paper's 8 separate, 3 shared; a matrix an MM group makes is three wires, three pins
    (the one column an MM member reads of its operand B, one: read_taps). Until 2026-12-05 such a
    matrix was counted as one, a log VAMP at 8 pins; until 2026-12-06 operand B's three, 12 for 10)."""
    wires = operand_wires(vamp)
    return {"separate": len(paper.PINS_SEPARATE) - 2 + wires,
            "shared": len(paper.PINS_SHARED_PER_VAMP) - 2 + wires}


def network_pins(network) -> list[int]:
    """Each physical VAMP's pins wired separately, in packing order: the paper's budget with one
    pin per wire into its operand multiplexers (vamp_pins); on the Mostly-Local Bus one pin per tier
    and per wire not on the bus (vampc.report.mlb); with error correction's checking, the extraneous VAMP too and
    each VAMP's checking pins (vampc.report.checking). The package count and the bus and checking
    sections read these same figures (a bus program's packages had been counted at 9 pins a VAMP
    beside a bus section of 30)."""
    if network.checking is not None:
        from vampc.report.checking import checked_pins
        return checked_pins(network)
    if network.bus is not None:
        from vampc.report.mlb import pins_on_bus
        return pins_on_bus(network)
    base = len(paper.PINS_SEPARATE) - 2
    return [base + operand_wires(v) for v in network.vamps]


def _packed(network, size: int) -> dict:
    """VAMPs packed in order (neighbours share a package), each with its pins (network_pins);
    sharing clock, power, ground and reset per package takes the difference of the two budgets
    off each VAMP."""
    separate = network_pins(network)
    saved = len(paper.PINS_SEPARATE) - len(paper.PINS_SHARED_PER_VAMP)
    out = {}
    for style in ("separate", "shared"):
        fixed = len(paper.PINS_SHARED_PER_PACKAGE) if style == "shared" else 0
        less = saved if style == "shared" else 0
        count, used, ok = 0, size, True
        for pins in separate:
            need = pins - less
            if need + fixed > size:
                ok = False
                break
            if used + need > size:
                count, used = count + 1, fixed
            used += need
        out[f"muxed_{style}"] = count if ok else None
    out["max_pins_per_vamp"] = max(separate, default=len(paper.PINS_SEPARATE))
    return out


def _paper_check(configs, chain=None) -> dict | None:
    """Section VII: '11 such 40-pin packages would implement the full systolic pipeline for the
    linear case of n = 6' — set beside the count for the linear systolic configuration."""
    k = next((k for k in configs if k.recursion is Recursion.LINEAR and k.options.layout_kind is SYSTOLIC), None)
    if k is None or k.graph.n != 6:
        return None
    got = paper.paper_packages(k.vamps)["shared"]
    from vampc.report.counts import vamp_counts
    counts = vamp_counts(k)
    bwd, fwd = counts["backward"], counts["forward"]
    rotary = 11 * 12                  # (section VI: 12 + 10 backward VAMPs a joint, 6 joints)
    if bwd == rotary:
        why = f"(its forward {fwd} need {got - 11} more)"
    else:   # (the Stanford arm's 16 was put down to the forward 48 alone, 4 of its 5 more: a check
        # against the paper)
        features = _beyond_the_paper(chain) if chain is not None else []
        why = (f"of a rotary arm, 22 a joint; here the backward recursion has {bwd} "
               f"({plus_minus(bwd - rotary)}" + (f": {', '.join(features)}" if features else "") +
               f") and the forward {fwd}: ⌈{k.vamps} / 12⌉ = {got}")
    return {"paper": paper.PAPER_PACKAGES_LINEAR_N6, "measured": got, "vamps": k.vamps,
            # (it said the paper's 132 "covers only" the backward VAMPs, an inference put as the
            # paper's word: an audit)
            "note": f"{got} packages of 12 for {k.vamps} VAMPs; the paper's 11 × 12 = 132 equals "
                    f"the backward recursion's VAMPs, so it seems to count those alone {why}"}
