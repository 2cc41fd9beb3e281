"""Plain-text rendering of a report summary (the default `vampc report` output)."""
from __future__ import annotations

from vampc.report.counts import latency_note, vamp_notes


def render(rep: dict) -> str:
    """A human-readable table of the summary produced by vampc.report.counts.summary."""
    lat, paper, v = rep["latency"], rep["paper"], rep["vamps"]
    lines = [
        f"robot            {rep['robot']} ({rep['joints']} joints"
        + (f", prismatic {rep['prismatic_joints']})" if rep["prismatic_joints"] else ")"),
        f"joints           {_joints(rep)}",
        f"recursion        {rep['recursion']}" + (f" ({rep['prefix']})" if rep.get("prefix") else ""),
        f"layout           {rep['layout']}" + (" (forward pass on the backward VAMPs)"
                                                   if rep.get("share_passes") else ""),
        f"latency          {lat['flops']} flops = {lat['mults']} Mults + {lat['adds']} Addns "
        "on the critical path",
        f"paper            {paper['flops']} flops = {paper['mults']} Mults + {paper['adds']} Addns",
    ]
    lines += [f"                 {note}" for note in latency_note(rep)]
    if lat.get("waits"):
        lines.append(f"                 {lat['waits']} flops of it wait for a busy VAMP (the layout's "
                     "list schedule); the data path alone takes the Mults + Addns")
    hw = rep.get("hardware")
    b = rep.get("budget")
    if b:
        lines.append(f"budget           {b['vamps_used']} VAMPs used"
                     + (f" of {b['vamps_asked']} allowed" if b["vamps_asked"] else "")
                     + f"; interval {rep['interval_flops']} against the bound {b['interval_bound']} "
                     f"(⌈W/K⌉ = ⌈{b['work']}/{b['vamps_asked'] or b['vamps_used']}⌉ = "
                     f"{b['work_over_vamps']}, and no op shorter than its duration): gap "
                     f"{b['interval_gap_pct']}%; latency {lat['flops']} against the bound "
                     f"{b['latency_bound']} (critical path {b['critical_path']}, level bound "
                     f"{b['level_bound']}): gap {b['latency_gap_pct']}%"
                     + (f"; exact solver: {b['proof']}" if b.get("exact") else ""))
    lines += [
        f"interval         {rep['interval_flops']} flops between successive torque sets",
        *([f"time-multiplexed {hw['slots']} slots on {v['total']} VAMPs (period {hw['period']}, "
           f"buffer clock {hw['buffer_clock']} flops); {hw['control_registers']} control "
           f"registers, {hw['mux_inputs']} multiplexer inputs beyond the first (at most "
           f"{hw['max_mux_inputs']} on one operand), {hw['host_writes_per_set']} host writes per "
           f"set, {hw['program_words']} program words loaded in {hw['load_ticks']} ticks"]
          if hw and rep.get("layout") != "systolic" else []),
        f"VAMPs            {v['total']} = {v['backward']} backward + {v['forward']} forward"
        + (f" + {v['shared']} shared by both passes" if v.get("shared") else ""),
        f"  per node       backward {v['per_node']['bwd']} propagated + {v['per_node']['npv']} "
        f"non-propagated, forward {v['per_node']['fwd']}",
        "  by op          " + ", ".join(f"{k} {n}" for k, n in v["by_op"].items()),
        *[f"                 {note}" for note in vamp_notes(rep)],
        f"buffers          {rep['buffers']['stages']} stages in {rep['buffers']['chains']} chains "
        f"({rep['buffers']['scalars']} scalars)",
        f"host I/O         {rep['ports']} ports, {rep['constants']} constant buffers, "
        f"{rep['input_buffer_scalars']} input-buffer scalars",
        f"40-pin packages  {rep['packages_40pin']['separate']} (5 VAMPs each, separate pins) or "
        f"{rep['packages_40pin']['shared']} (12 each, shared clock/power/reset)",
        f"serial work      {rep['serial_work']['mults']} Mults + {rep['serial_work']['adds']} Addns "
        f"in the graph; Luh-Walker-Paul {rep['serial_reference']['mults']} + "
        f"{rep['serial_reference']['adds']}",
    ]
    lines += _tree_lines(rep.get("tree"))
    text = "\n".join(lines) + "\n"
    if rep.get("layout_comparison"):
        from vampc.report.compare import render_layouts
        text += "\n" + render_layouts(rep["layout_comparison"])
    if rep.get("prefix_comparison"):
        from vampc.report.compare import render_comparison
        text += "\n" + render_comparison(rep["prefix_comparison"])
    return text


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


def _tree_lines(tree: dict | None) -> list[str]:
    """A tree's shape and depths (counts.tree_summary, and the latencies `vampc report` adds)."""
    if not tree:
        return []
    lines = [f"tree             {tree['joints']} joints, {tree['leaves']} leaves, height {tree['height']} "
             f"(the level-by-level depth), {tree['heavy_paths']} heavy paths, at most "
             f"{tree['light_edges']} light edges on a path"
             + ("; floating base: 6 wrench outputs after the joints" if tree["floating"] else "")]
    lines.append(f"  log depth      backward {tree['backward_tiers']} combining tiers, forward "
                 f"{tree['forward_levels']} addition levels; ⌈log2(n+1)⌉ = {tree['log2_n_plus_1']}, "
                 f"height {tree['height']}")
    lat = tree.get("latency_flops")
    if lat:
        lines.append(f"  latency        linear {lat['linear']} flops, log {lat['log']} flops "
                     "(systolic, this timing)")
    return lines
