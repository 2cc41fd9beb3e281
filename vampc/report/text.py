"""Text and Markdown renderings of a report (the default `vampc report` output and `--format
markdown`): the summary lines, then the tables of vampc.report.sections."""
from __future__ import annotations

from vampc.report.counts import (
    latency_note,
    latency_terms,
    numbers_text,
    paper_flops,
    vamp_notes,
)
from vampc.schedule.registry import SYSTOLIC, is_layout
from vampc.textio import count


def flops(k: int) -> str:
    """'1 flop', '61 flops'."""
    return count(k, "flop")


def render(rep: dict) -> str:
    """The text report: the summary lines, then every table (vampc.report.sections) aligned."""
    text = "".join(f"{label:<16} {value}".rstrip() + "\n" for label, value in summary_pairs(rep))
    if "table_o1" not in rep:
        return text
    from vampc.report.sections import tables
    from vampc.report.table import render_text
    return text + "".join("\n" + render_text(t) for t in tables(rep))


def render_markdown(rep: dict) -> str:
    """The Markdown report (for a design review): the summary as a table, then every table."""
    from vampc.report.sections import tables
    from vampc.report.table import render_markdown as table_md
    lines = [f"## vampc report: {rep['robot']}", "", "| figure | value |", "|---|---|"]
    for label, value in summary_pairs(rep):
        lines.append(f"| {label or ' '} | {value.replace('|', chr(92) + '|')} |")
    return "\n".join(lines) + "\n" + "".join("\n" + table_md(t) for t in tables(rep))


def summary_pairs(rep: dict) -> list[tuple[str, str]]:
    """The summary as (label, value) lines; a continuation line has an empty label."""
    lat, paper, v = rep["latency"], rep["paper"], rep["vamps"]
    pairs = [
        ("robot", f"{rep['robot']} ({count(rep['joints'], 'joint')}"
         + (f", prismatic {numbers_text(rep['prismatic_joints'])})" if rep["prismatic_joints"]
            else ")")),
        ("joints", _joints(rep)),
        ("recursion", rep["recursion"] + (f" ({rep['prefix']})" if rep.get("prefix") else "")),
        ("layout", rep["layout"] + (" (forward pass on the backward VAMPs)"
                                    if rep.get("share_passes") else "")),
        ("latency", f"{flops(lat['flops'])} = {latency_terms(rep, lat)} on the critical path"),
        ("paper", f"{flops(paper_flops(rep))} = {latency_terms(rep, paper)}"),
    ]
    pairs += [("", note) for note in latency_note(rep)]
    if lat.get("waits"):
        what = ("a free bus or a busy VAMP" if rep.get("bus") and rep.get("layout") != "systolic"
                else "a free bus" if rep.get("bus") else "a busy VAMP")
        pairs.append(("", f"{flops(lat['waits'])} of it waiting for {what} (the layout's "
                          "schedule); the data path alone takes the Mults + Addns"))
    hw = rep.get("hardware")
    b = rep.get("budget")
    if b:
        pairs.append(("budget", f"{count(b['vamps_used'], 'VAMP')} used"
                      + (f" of {b['vamps_asked']} allowed" if b["vamps_asked"] else "")
                      + f"; interval {rep['interval_flops']} against the bound {b['interval_bound']} "
                      f"(⌈W/K⌉ = ⌈{b['work']}/{b['vamps_asked'] or b['vamps_used']}⌉ = "
                      f"{b['work_over_vamps']}"
                      # (a bound above ⌈W/K⌉ is the longest op's: "= 1 ... against the bound 3"
                      # left the 3 unexplained, a new user's find)
                      + (f"; the longest op, {b['interval_bound']} flops"
                         if b["interval_bound"] > b["work_over_vamps"] else
                         ", and no op shorter than its duration") + "): gap "
                      f"{b['interval_gap_pct']}%; latency {lat['flops']} against the bound "
                      f"{b['latency_bound']} (critical path {b['critical_path']}, level bound "
                      f"{b['level_bound']}): gap {b['latency_gap_pct']}%"
                      + (f"; exact solver: {b['proof']}" if b.get("exact") else "")))
    pairs.append(("interval", f"{rep['interval_flops']} flops between successive torque sets"))
    if hw and not is_layout(rep.get("layout"), SYSTOLIC):
        pairs.append(("time-multiplexed",
                      f"{hw['slots']} slots on {count(v['total'], 'VAMP')} (period {hw['period']}, "
                      f"buffer clock {flops(hw['buffer_clock'])}); {hw['control_registers']} control "
                      f"registers, {hw['mux_inputs']} multiplexer inputs beyond the first (at most "
                      f"{hw['max_mux_inputs']} inputs on one operand), {hw['host_writes_per_set']} host "
                      f"writes per set, {hw['program_words']} program words loaded in "
                      f"{hw['load_ticks']} ticks"))
    w = rep.get("word")
    if w:
        modes = f" ({w['rounding']}, {w['overflow']})" if "rounding" in w else ""
        pairs.append(("word", f"{w['format']}{modes}: {w['bits']} bits; {w['data_register_bits']:,} "
                      f"bits of data registers, {w['control_register_bits']:,} of control registers"
                      + (f" (the checking's {w['checking_control_bits']:,} of them)"
                         if "checking_control_bits" in w else "") + ", "
                      f"{w['rom_bits']:,} of microcode ROM ({w['rom_bits_per_vamp']:,} a VAMP), "
                      f"{w['delay_line_bits']:,} of delay lines, {w['constant_bits']:,} of constants, "
                      f"{w['input_port_bits']:,} of input ports; "
                      f"the host writes {w['host_write_bits_per_set']:,} and reads "
                      f"{w['host_read_bits_per_set']:,} bits a torque set, and loads "
                      f"{w['program_bits']:,} bits in Program Mode"))
    if rep.get("clock"):
        from vampc.report.clock import control_sentence, sets_text, time_text
        c = rep["clock"]
        pairs.append(("clock", f"{c['text']}: latency {time_text(c['latency_us'])}, a torque set every "
                      f"{time_text(c['interval_us'])} ({sets_text(c['sets_per_second'])} per second)"))
        pairs.append(("", control_sentence(c)))
    pairs += [
        ("VAMPs", f"{v['total']} = {v['backward']} backward + {v['forward']} forward"
         + (f" + {v['shared']} shared by both passes" if v.get("shared") else "")
         # (the packages and the error-correction line counted 61 beside this 60: a new user's find)
         + (f", and 1 extraneous VAMP for the error correction ({v['total'] + 1} in all)"
            if rep.get("error_correction") else "")),
        ("  per node", f"backward {v['per_node']['bwd']} propagated + {v['per_node']['npv']} "
         f"non-propagated, forward {v['per_node']['fwd']}"
         # (more than the network's VAMPs on a budget: they are the busiest node's ops, an audit's)
         + (" (the busiest node's ops, one a VAMP as the paper counts them; this layout's VAMPs run "
            "several)" if sum(v["by_op"].values()) > v["total"] else "")),
        # (ops, one a slot: summed to 180 beside "VAMPs 30" of a folded layout: a new user's find)
        ("  by op", ", ".join(f"{k} {n}" for k, n in v["by_op"].items())
         + (f" (ops, {sum(v['by_op'].values())} in all, run on these {v['total']} VAMPs)"
            if sum(v["by_op"].values()) != v["total"] else "")),
        *([("  unused", _unused_text(v["unused"], v["total"]))]
          if v.get("unused", {}).get("ops") else []),        # (a report's: build_report)
        *[("", note) for note in vamp_notes(rep)],
        ("buffers", f"{count(rep['buffers']['stages'], 'stage')} in {count(rep['buffers']['chains'], 'chain')} "
         f"({rep['buffers']['scalars']} scalars)"),
        ("host I/O", f"{rep['ports']} ports, {rep['constants']} constant buffers, "
         f"{rep['input_buffer_scalars']} input-buffer scalars"),
        ("40-pin packages", _packages_line(rep)),
        ("serial work", f"{rep['serial_work']['mults']} Mults + {rep['serial_work']['adds']} Addns "
         f"in the graph; Luh-Walker-Paul {rep['serial_reference']['mults']} + "
         f"{rep['serial_reference']['adds']}"),
    ]
    pairs += _tree_pairs(rep.get("tree"))
    pairs += _mimic_pairs(rep.get("mimic"))
    if rep.get("bus") is not None:
        from vampc.report.mlb import bus_pairs
        pairs += bus_pairs(rep["bus"])
    if rep.get("error_correction") is not None:
        from vampc.report.checking import checking_pairs
        pairs += checking_pairs(rep["error_correction"])
    if rep.get("rtl") is not None:
        from vampc.report.rtl import rtl_pairs
        pairs += rtl_pairs(rep["rtl"])
    return pairs


def _mimic_pairs(mimic: list | None) -> list[tuple[str, str]]:
    """Coupled mimic joints: who follows whom (the network computes every joint; the host derives
    the followers' inputs and folds their torques into their leaders')."""
    if not mimic:
        return []
    shown = [f"{m['follower']} = {m['multiplier']:g} · {m['leader']}"
             + (f" {'+' if m['offset'] >= 0 else '-'} {abs(m['offset']):g}" if m["offset"] else "")
             for m in mimic[:SHOWN_JOINTS]]
    more = f", ... {len(mimic)} in all" if len(mimic) > SHOWN_JOINTS else ""
    return [("mimic", ", ".join(shown) + more + " (coupled on the host: states and torques give the "
             "independent joints; the network computes every joint)")]


SHOWN_JOINTS = 12


def _joints(rep: dict) -> str:
    """Joints in order (torque columns follow it): '1 shoulder (R), 2 elbow (R)'; long chains cut."""
    names, types = rep.get("joint_names"), rep.get("joint_types")
    if names is None:
        return f"{rep['joints']} (names not recorded in this file)"
    items = [f"{k} {name} ({kind[0].upper()})" for k, (name, kind) in
             enumerate(zip(names, types), 1)]
    if len(items) > SHOWN_JOINTS:
        items = items[:SHOWN_JOINTS - 1] + [f"... {len(names)} in all (--format json lists "
                                            "every one)"]
    return ", ".join(items) + "   (R revolute, P prismatic)"


def _tree_pairs(tree: dict | None) -> list[tuple[str, str]]:
    """A tree's shape and depths (counts.tree_summary, and the latencies `vampc report` adds)."""
    if not tree:
        return []
    # ("1 leaves", "1 heavy paths" on a leg taken alone: a trees audit)
    leaves = f"{tree['leaves']} {'leaf' if tree['leaves'] == 1 else 'leaves'}"
    pairs = [("tree", f"{count(tree['joints'], 'joint')}, {leaves}, height {tree['height']} "
              f"(the level-by-level depth), {count(tree['heavy_paths'], 'heavy path')}, at most "
              f"{count(tree['light_edges'], 'light edge')} on a path"
              + ("; floating base: 6 wrench outputs after the joints" if tree["floating"] else ""))]
    pairs.append(("  log depth", f"backward {count(tree['backward_tiers'], 'combining tier')}, forward "
                  f"{count(tree['forward_levels'], 'addition level')}; ⌈log2(n+1)⌉ = "
                  f"{tree['log2_n_plus_1']}, height {tree['height']}"))
    lat = tree.get("latency_flops")
    if lat:
        pairs.append(("  latency", f"linear {lat['linear']} flops, log {lat['log']} flops "
                      "(systolic, this timing)"))
    return pairs


def _unused_text(unused: dict, total: int) -> str:
    """The VAMPs (and ops) that compute values no torque reads (vampc.report.counts.unused_vamps),
    named from the graph (a fixed list had named only the log prefix's, where forward T19 and f and
    a tree's Y1, Y2 are among them too: a review's find)."""
    names = list(unused.get("names", {}).items())
    what = ", ".join(f"{name} {k}" for name, k in names[:10]) + (", …" if len(names) > 10 else "")
    # (Y1, Y2 are a tree's ops, not the paper's: they were said kept "as the paper's nodes have
    # them", a trees audit's find)
    tree = [name for name, _ in names if name in ("Y1", "Y2")]
    ops = f"{count(unused['ops'], 'op')} compute values no torque reads, kept as " + (
        "the nodes are built (the paper's whole, and a tree's Y1, Y2 at each shifted child)"
        if tree else "the paper's nodes have them") + f" ({what})"
    if not unused["vamps"]:
        return f"{ops}, on VAMPs that run others too: none to spare"
    return (f"{count(unused['vamps'], 'VAMP')} run only those: {ops}; the torques need "
            f"{total - unused['vamps']}")


def _packages_line(rep: dict) -> str:
    """40-pin packages with each operand wire a pin (what the network needs), beside the paper's
    pin budget when the two differ (a folded or budget VAMP reads several wires, a VAMP reading a
    matrix that an MM's three VAMPs make three)."""
    paper = (f"{rep['packages_40pin']['separate']} (5 VAMPs each, separate pins) or "
             f"{rep['packages_40pin']['shared']} (12 each, shared clock/power/reset)")
    own = next((r for r in rep.get("packages", {}).get("rows", []) if r.get("own")), None)
    at40 = next((b for b in own["by_pins"] if b["pins"] == 40), None) if own else None
    if not at40 or "muxed_separate" not in at40 or (
            (at40["muxed_separate"], at40["muxed_shared"]) == (at40["paper_separate"], at40["paper_shared"])):
        return paper
    most = at40["max_pins_per_vamp"]
    if at40["muxed_separate"] is None and at40["muxed_shared"] is None:
        return (f"none: with each operand wire a pin, a VAMP here needs up to {most} pins, "
                f"more than a 40-pin package has (--pins N counts other packages); by the paper's "
                f"budget of 8 or 3 pins a VAMP: {paper}")

    def count(n) -> str:
        return "none (a VAMP needs too many pins)" if n is None else str(n)
    return (f"{count(at40['muxed_separate'])} with separate pins or {count(at40['muxed_shared'])} "
            f"with shared clock/power/reset, each operand wire a pin (a VAMP here needs up to "
            f"{most}); by the paper's budget of 8 or 3 pins a VAMP: {paper}")
