"""The report's tables, built from the report dictionary (vampc.report.build) so that text, Markdown
and HTML show the same cells, and a program file's report the same as its robot's."""
from __future__ import annotations

from fractions import Fraction

from vampc.kinds import Recursion, exhaustive
from vampc.machine.ops import report_kinds
from vampc.report.clock import (
    control_need,
    control_sentence,
    hz_text,
    margin_text,
    sets_text,
    si_text,
    time_column,
    time_text,
)
from vampc.report.sites import SECTION_NAMES
from vampc.report.table import Table
from vampc.schedule.registry import SYSTOLIC, is_layout

DASH = "—"


def num(x) -> str:
    """An integer with thousands separators, a fraction with one decimal, None as a dash."""
    if x is None:
        return DASH
    if isinstance(x, float) and not x.is_integer():
        return f"{x:,.1f}"
    return f"{int(x):,}"


VULGAR = {(1, 2): "½", (1, 3): "⅓", (2, 3): "⅔", (1, 4): "¼", (3, 4): "¾", (1, 5): "⅕", (2, 5): "⅖",
          (3, 5): "⅗", (4, 5): "⅘", (1, 6): "⅙", (5, 6): "⅚", (1, 12): "¹⁄₁₂", (5, 12): "⁵⁄₁₂",
          (7, 12): "⁷⁄₁₂", (11, 12): "¹¹⁄₁₂"}


def exact(x) -> str:
    """A formula's value as the formula gives it: an integer with separators, or a whole part and a
    fraction ('89,323⅕'). `x` a Fraction or its text ('1201593554253712/3', the report's
    `*_exact`), or a number (the paper's coefficients have denominators 2, 3, 4 and 12, so a
    value at an integer n is a multiple of 1/12: guessed from a float, which past n of about 1487
    cannot hold it; a report of an older vampc has no exact text)."""
    if isinstance(x, (str, Fraction)):
        f = Fraction(x)
        if f.denominator == 1:
            return f"{f.numerator:,}"
    elif x is None or float(x).is_integer():
        return num(x)
    else:
        f = Fraction(x).limit_denominator(12)
    whole, part = divmod(abs(f.numerator), f.denominator)   # (-7/3 is −2⅓, not −3⅔: a review's)
    key = (part, f.denominator)
    return "-" * (f < 0) + f"{whole:,}" + VULGAR.get(key, f" {part}/{f.denominator}")


def signed(x) -> str:
    """'+3', '−96', '0'."""
    return f"{x:+,}".replace("-", "−") if x else "0"


def tables(rep: dict) -> list[Table]:
    """Every table of the report, in the order the report shows them."""
    out = [o1_formulas(rep), o1_at_n(rep), o1_measured(rep), layouts(rep)]
    if rep.get("prefix_comparison"):
        out.append(prefixes(rep))
    out += [vamps(rep, v) for v in rep["processors"]["vamps"]]
    out += [vamps_by_op(rep), ops_per_node(rep), packages(rep), buffering(rep), wiring(rep)]
    if rep.get("engineering"):
        out.append(engineering(rep))
    if rep.get("clock"):
        out.append(clock(rep))
    return out


def _bits(x: int) -> str:
    """'384 bits', '16.13 kbit', '3.1 Mbit'."""
    return si_text(x, "bit") if x >= 1000 else f"{x:,} bits"


def _rate(x: float, what: str) -> str:
    """'270 M scalars/s', '17.28 Gbit/s'."""
    return si_text(x, f"{what}/s")


def _ratio(x: float) -> str:
    return f"{x:,.0f}" if x >= 100 else f"{x:.3g}"


def control_logic_text(k: dict) -> str:
    """The engineering table's control-logic line (vampc.report.counts.control_logic)."""
    b = k["counter_bits"]
    against = [f"{k['delay_comparators']:,} of the slots' delays (3 a slot)"]
    if k["buffer_clock_comparators"]:
        against.append(f"{k['buffer_clock_comparators']:,} of the buffer clock's ticks")
    if k["bus_write_comparators"]:
        against.append(f"{k['bus_write_comparators']:,} of the bus-write registers")
    return (f"{k['cycle_counters']:,} Cycle-Counters of {b} bits with their incrementers; comparators "
            f"of {b} bits against them: {', '.join(against)}; {k['step_subtractors']:,} subtractors of "
            f"{b + 1} bits with their wrap-around adders (the ticks to a slot's dump, mod the period, "
            "addressing the ROM); "
            f"{k['number_comparators']:,} comparators of {k['number_comparator_bits']} bits (a VAMP's "
            f"number and its negation in Program Mode) and {k['slot_address_comparators']:,} of a slot "
            "address")


def engineering(rep: dict) -> Table:
    """Utilisation, host I/O, the critical path op by op, storage bits and the CPU reference."""
    e = rep["engineering"]
    u, io, bits = e["utilisation"], e["host_io"], e["bits"]
    rows = [("utilisation", f"mean {u['mean']:.1%} of the interval ({u['busy_ticks_per_set']:,} busy VAMP-ticks "
             f"of {u['vamp_ticks_per_set']:,} per set, interval {u['interval_flops']} flops); least busy "
             f"VAMP {u['min']:.1%}, busiest {u['max']:.1%}")]
    line = (f"{io['scalars_in_per_set']:,} scalars written per set in {io.get('port_writes_per_set', 0):,} "
            f"port writes ({_bits(io['bits_in_per_set'])}): {io.get('distinct_scalars_in_per_set', 0):,} "
            "distinct input scalars, a value several ports read written to each; and "
            f"{io['scalars_out_per_set']:,} read off the outputs ({_bits(io['bits_out_per_set'])}), "
            f"{io['word_bits']}-bit words")
    if "sets_per_second" in io:
        line += (f"; at {rep['clock']['text'] if rep.get('clock') else 'the clock'}: "
                 f"{_rate(io['scalars_in_per_second'], ' scalars')} in "
                 f"({_rate(io['bits_in_per_second'], 'bit')}), "
                 f"{_rate(io['scalars_out_per_second'], ' scalars')} out "
                 f"({_rate(io['bits_out_per_second'], 'bit')})")
    rows.append(("host traffic", line))
    path = e["critical_path"]
    shown = " → ".join(f"{p['label']} ({p['op']}, {p['flops']})" for p in path[:8])
    if len(path) > 8:
        shown += f" → … → {path[-1]['label']} ({path[-1]['op']}, {path[-1]['flops']})"
    data = sum(p["flops"] for p in path)
    waits = rep["latency"].get("waits") or 0
    rows.append(("critical path", f"the data path, {len(path)} ops, {data} flops"
                 + (f" (latency {data + waits} with {waits} waiting)" if waits else "") + f": {shown}"))
    checking = (f" (the checking's {_bits(bits['checking_control_bits'])} of them)"
                if "checking_control_bits" in bits else "")
    rows.append(("storage", f"data registers {_bits(bits['data_register_bits'])}, control registers "
                 f"{_bits(bits['control_register_bits'])}{checking}, microcode ROM {_bits(bits['rom_bits'])}, delay "
                 f"lines {_bits(bits['delay_line_bits'])}, constants {_bits(bits['constant_bits'])}, "
                 f"input ports {_bits(bits['input_port_bits'])}, program {_bits(bits['program_bits'])} "
                 f"({bits['bits']}-bit words)"))
    logic = e.get("control_logic")
    if logic:
        rows.append(("control logic", control_logic_text(logic)))
    notes = ["utilisation: a VAMP's ops' durations once per set over the interval; host I/O: what the "
             "host writes into the ports and reads off the outputs each set (constants are loaded once, "
             "in Program Mode); the whole critical path is in --format json (engineering.critical_path)"]
    cpu = e.get("cpu_reference")
    if cpu:
        for m in cpu["measured"]:
            text = f"{time_text(m['seconds_per_set'] * 1e6)} per set"
            if rep.get("clock"):
                c = rep["clock"]
                ratio = [m["seconds_per_set"] * 1e6 / c[k] for k in ("latency_us", "interval_us")]
                text += (f"; the network's latency {time_text(c['latency_us'])} (CPU / network "
                         f"{_ratio(ratio[0])}), its interval {time_text(c['interval_us'])} (CPU / "
                         f"network {_ratio(ratio[1])})")
            rows.append(("CPU reference", f"{m['what']}: {text}"))
        if cpu.get("not_measured"):
            rows.append(("CPU reference", cpu["not_measured"]))
        notes.append(f"CPU reference: measured on this machine ({cpu['machine']}), the median of 3 runs "
                     f"of {cpu['sets']} random sets one at a time; it varies from run to run")
    return Table("engineering", "Engineering figures", ("figure", "value"), tuple(rows), tuple(notes),
                 align="ll")


# --- Table O.1 -----------------------------------------------------------------------------------

def o1_formulas(rep: dict) -> Table:
    """Table O.1a as the paper prints it: formulas in n."""
    rows = tuple((f["method"], f["mults_formula"], f["adds_formula"], _measure(f))
                 for f in rep["table_o1"]["formulas"])
    return Table("o1-formulas", "Table O.1a, the paper's formulas (Mults, Addns in n; a general "
                 "rotary arm, 1 Mult = 1 Addn = 1 flop)", ("method", "Mults", "Addns", "counts"),
                 rows, align="llll")


def _measure(f: dict) -> str:
    what = {"serial": "one set, serially", "latency": "one set's latency",
            "interval": "interval between sets"}[f["measure"]]
    return what + (f" ({f['qualifier']})" if f.get("qualifier") else "")


def _weights(rep: dict) -> tuple[str, str]:
    """How a Mult's and an Addn's count is written beside its latency: ('', '') at the paper's 1
    flop each, ('×2', '') with --mult-latency 2."""
    t = rep["timing"]
    return tuple(f"×{t[k]}" if t[k] != 1 else "" for k in ("mult_latency", "add_latency"))


def _terms(rep: dict, mults, adds, *more) -> str:
    """'15 + 43', '15×2 + 43' at a Mult of 2 flops; `more` (waits) added as they are."""
    wm, wa = _weights(rep)
    return " + ".join([f"{num(mults)}{wm}", f"{num(adds)}{wa}", *(num(x) for x in more)])


def _terms_head(rep: dict, *more: str) -> str:
    """The heading of a column of `_terms`: '= M + A + wait', '= M×2 + A + wait'."""
    wm, wa = _weights(rep)
    return "= " + " + ".join([f"M{wm}", f"A{wa}", *more])


def o1_at_n(rep: dict) -> Table:
    """The formulas evaluated at this robot's n; for n = 6 the printed column O.1b beside them."""
    t = rep["table_o1"]
    n = t["n"]
    six = n == 6
    clk = rep.get("clock")
    if clk:
        unit, times = time_column([f["time_us"] for f in t["formulas"]])
    cols = ("method", "Mults", "Addns", "flops") + (("printed O.1b", "check") if six else ()) + \
        ((f"{unit or 'time'} at {clk['text']}",) if clk else ())
    rows, notes = [], []
    for i, f in enumerate(t["formulas"]):
        row = [f["method"], *(exact(f.get(f"{k}_exact", f[k])) for k in ("mults", "adds", "flops"))]
        if six:
            p = f["printed_n6"]
            row += [f"{num(p['mults'])} + {num(p['adds'])}",
                    "agrees" if p["matches"] else f"differs: note {len(notes) + 1}"]
            if not p["matches"]:
                notes.append(f"{len(notes) + 1}. {f['method']}: {p['note']}")
        if clk:
            row.append(times[i] + (f" ({sets_text(f['sets_per_second'])} sets/s)"
                                   if "sets_per_second" in f else ""))
        rows.append(tuple(row))
    title = (f"Table O.1 at n = {n}, from the paper's formulas (not measured)"
             + ("; the paper's printed column O.1b beside them" if six else ""))
    if any(_weights(rep)):
        tm = rep["timing"]
        notes.append(f"flops: the Mults and Addns at {num(tm['mult_latency'])} and "
                     f"{num(tm['add_latency'])} flops each, this report's latencies (the paper "
                     "counts 1 and 1)")
    if not six:
        notes.append("the paper prints values for n = 6 only (Table O.1b)")
    # (from the exact values: past n of about 4000 a value x⅓'s float is whole, and the note went
    # while the cells showed fractions: a review's find)
    fractional = [f["method"] for f in t["formulas"]
                  if any(Fraction(f.get(f"{k}_exact", f[k])).denominator != 1
                         for k in ("mults", "adds", "flops"))]
    if fractional:
        notes.append(f"{', '.join(fractional)}: the formula's fractional coefficients give a fraction "
                     f"at n = {n}; shown exactly as the formula gives it (a count of operations "
                     "would round it)")
    return Table("o1-at-n", title, cols, tuple(rows), tuple(notes),
                 align="lrrr" + ("rl" if six else "") + ("r" if clk else ""))


def o1_measured(rep: dict) -> Table:
    """vampc's measured rows: serial work of its graphs, latency and interval of each configuration."""
    t = rep["table_o1"]
    clk = rep.get("clock")
    if clk:
        unit, times = time_column([r.get("time_us") for r in t["measured"]])
    cols = ("vampc, measured", "Mults", "Addns", "waits", "flops", "interval", "VAMPs", "paper",
            "difference", "why") + ((f"{unit or 'time'} at {clk['text']}", "sets/s") if clk else ())
    rows = []
    wm, wa = _weights(rep)
    for i, r in enumerate(t["measured"]):
        ref = r["paper"]
        d = r["difference"]
        interval = (f"{r['interval_flops']} = {r['interval']['mults']} M{wm} + "
                    f"{r['interval']['adds']} A{wa}"
                    if "interval" in r else num(r.get("interval_flops")))
        label = r["configuration"] + (" (this report)" if r.get("own") else "")
        row = (label, num(r["mults"]), num(r["adds"]), num(r.get("waits")), num(r["flops"]), interval,
               num(r.get("vamps")),
               (f"{num(ref['mults'])} + {num(ref['adds'])} LWP" if r["measure"] == "serial"
                else f"{_terms(rep, ref['mults'], ref['adds'])} = {num(ref['flops'])}"),
               f"{signed(d['mults'])} M, {signed(d['adds'])} A", r["note"])
        if clk:
            row += (times[i], sets_text(r["sets_per_second"]) if "sets_per_second" in r else DASH)
        rows.append(row)
    notes = ["serial rows: the graph's ops one after another (op costs: README, Report tables), beside "
             "Luh-Walker-Paul (LWP); configuration rows: latency on the critical path as Mults + "
             "Addns (+ flops waiting for a busy VAMP), beside the paper's formula for the recursion; "
             "the systolic interval beside the paper's 1 Mult + 3 Addns"] + list(t["notes"])
    # (the interval and waits columns had no unit: a paper audit)
    return Table("o1-measured", f"Table O.1, vampc's figures for {rep['robot']} (measured from "
                 "its compiled graphs and schedules; waits, flops and interval in flops)", cols,
                 tuple(rows), tuple(notes),
                 align="lrrrrrrrll" + ("rr" if clk else ""))


# --- layouts and prefixes ------------------------------------------------------------------------

def layouts(rep: dict) -> Table:
    """The layout comparison (existing `layout_comparison` rows)."""
    clk = rep.get("clock")
    if clk:
        unit, times = time_column([r["latency_us"] for r in rep["layout_comparison"]])
    cols = ("layout", "latency", _terms_head(rep, "wait"), "interval", "VAMPs", "buffer stages",
            "mux inputs", "control regs", "host writes", "load ticks") + \
        ((f"latency {unit}".strip(), "sets/s") if clk else ())
    rows = []
    for i, r in enumerate(rep["layout_comparison"]):
        row = (r["layout"], num(r["latency_flops"]), _terms(rep, r["mults"], r["adds"], r["waits"]),
               num(r["interval_flops"]), num(r["vamps"]), num(r.get("buffer_stages")),
               num(r.get("mux_inputs")), num(r.get("control_registers")),
               num(r.get("host_writes_per_set")), num(r.get("load_ticks")))
        if clk:
            row += (times[i], sets_text(r["sets_per_second"]))
        rows.append(row)
    notes = [] if all("buffer_stages" in r for r in rep["layout_comparison"]) else [_unallocated(rep)]
    return Table("layouts", f"Layouts, {rep['recursion']} recursion (same robot; latency and "
                 "interval in flops; README, Layouts)", cols, tuple(rows), tuple(notes),
                 align="lrlrrrrrrr" + ("rr" if clk else ""))


def _unallocated(rep: dict) -> str:
    a = rep["allocation"]
    # (said "only when its graph has at most ... ops": a log report over the limit leaves even
    # the small linear rows unallocated, which that did not explain; an audit's find)
    return (f"{DASH}: not allocated — a configuration other than the report's own is allocated "
            f"only when its graph and the report's own each have at most {a['limit_ops']:,} ops "
            f"(the report's own: {a['ops']:,}; compile it with its --layout to see its buffers, "
            "multiplexers and load time)")


def prefixes(rep: dict) -> Table:
    """The prefix-shape comparison (log recursion)."""
    # (a folded layout's waits: '44' beside '12 + 30' did not add up, a review's find)
    waits = any(r.get("waits") for r in rep["prefix_comparison"])
    # the interval where the shapes' differ (a budget's or a folded layout's: each shape's work
    # sets it; the table had none, and Brent-Kung's 107 and 128 beside Sklansky's 136 and 168 on
    # one budget could not be seen: a new user's find)
    intervals = len({r["interval_flops"] for r in rep["prefix_comparison"]}) > 1
    rows = tuple((r["prefix"], num(r["latency_flops"]),
                  _terms(rep, r["mults"], r["adds"], *([r.get("waits", 0)] if waits else [])))
                 + ((num(r["interval_flops"]),) if intervals else ())
                 + (num(r["vamps"]), num(r.get("buffer_stages")), num(r.get("max_fan_out")))
                 for r in rep["prefix_comparison"])
    notes = [] if all("buffer_stages" in r for r in rep["prefix_comparison"]) else [_unallocated(rep)]
    if notes and rep.get("bus"):
        # (scheduled as wired point to point: their latency and interval leave out what the bus
        # adds, so a shape could look faster than on the bus; a review's find)
        notes.append("the shapes not allocated are scheduled wired point to point: their latency "
                     "and interval leave out the Mostly-Local Bus's stretch and wait")
    notes += [f"{r['prefix']}: not feasible with these options ({r['why']})"
              for r in rep.get("prefix_comparison_infeasible", ())]
    if any(r.get("exact") is False for r in rep["prefix_comparison"]):
        own = next((r["prefix"] for r in rep["prefix_comparison"] if r.get("exact")), None)
        notes.append((f"{own}: as --exact placed it; " if own else "") + "the other shapes placed by "
                     "the list scheduler, at the same budget (--exact's solver is not run again for "
                     "a comparison)")
    return Table("prefixes", f"Prefix shapes (log recursion, {rep['layout']} layout, same robot "
                 "and options)", ("prefix", "latency", _terms_head(rep, *(["wait"] if waits else [])))
                 + (("interval",) if intervals else ()) + ("VAMPs", "buffer stages", "fan-out"),
                 rows, tuple(notes), align="lrl" + ("r" if intervals else "") + "rrr")


# --- processors ----------------------------------------------------------------------------------

ROW_NAMES = {"bwd": "backward, propagated", "npv": "backward, non-propagated",
             "bwd_total": "backward, total", "fwd": "forward"}


def vamps(rep: dict, v: dict) -> Table:
    """One recursion's VAMP table (section VI): measured, the paper's figure in brackets."""
    n = rep["joints"]
    cols = ("pass", "per node", "per tier", "single device", "systolic", "check")
    rows = []
    for r in v["rows"]:
        cells = [_paired(r[c], r["paper"].get(c)) for c in ("per_node", "per_tier", "single_device",
                                                             "systolic")]
        rows.append((ROW_NAMES[r["section"]], *cells, r["note"]))
    shared = _paired(v["shared_passes"], v["paper_shared_passes"])
    rows.append(("both passes on one device", DASH, DASH, shared, DASH,
                 "Figure VI.1b (--share-passes); paper figure inferred: its tables give no count, "
                 "the larger pass's single device" if v["paper_shared_passes"] else
                 "Figure VI.1b (--share-passes)"))
    what = v["recursion"] + (f" ({v['prefix']}, {v['leaves']} leaves)" if v["leaves"] else "")
    leaves_as_mine = v["leaves"] is None or (v["leaves"] == "uniform") == bool(rep.get("uniform_leaves"))
    own = rep["recursion"] == v["recursion"] and leaves_as_mine
    title = (f"VAMPs, {what}, n = {n}: measured [the paper's section VI figure"
             + (", n = 6]" if n == 6 else ": per node only, its tables are for n = 6]")
             + (" — this report's recursion" if own else ""))
    notes = ["per node: the busiest recursion node; per tier: the busiest tier of combining nodes "
             "(non-propagated: those a tier's single device runs); single device: --layout folded; "
             "systolic: one VAMP per op (three per MM)"]
    return Table(f"vamps-{v['recursion']}-{v['leaves'] or 'linear'}", title, cols, tuple(rows),
                 tuple(notes), align="lrrrrl")




def vamps_by_op(rep: dict) -> Table:
    """VAMPs by op kind for each recursion (and leaf style) and layout."""
    rows = []
    for v in rep["processors"]["vamps"]:
        what = v["recursion"] + (f", {v['leaves']} leaves" if v["leaves"] else "")
        for layout, label in (("systolic", "systolic"), ("single_device", "single device"),
                              ("shared_passes", "both passes on one device")):
            got = v["by_op"][layout]
            rows.append((f"{what}, {label}", *(num(got.get(k)) if got.get(k) else "" for k in report_kinds()),
                         num(sum(got.values()))))
    # (a VAMP of a layout that shares VAMPs may run ops of several kinds: said, an audit's find)
    return Table("vamps-by-op", "VAMPs by op kind (an MM takes three), measured", ("configuration",
                 *report_kinds(), "total"), tuple(rows),
                 ("a VAMP that runs ops of several kinds (on one device, or both passes on one) is "
                  "counted under the kind of its first op",))


def _paired(got, paper) -> str:
    if got is None:
        return DASH
    return num(got) + (f" [{num(paper)}]" if paper is not None else "")


def ops_per_node(rep: dict) -> Table:
    """Ops of the busiest node by kind, beside the paper's requirements per node."""
    kinds = report_kinds()
    cols = ("node", *kinds, "total", "paper", "check")
    rows = []
    for r in rep["processors"]["ops_per_node"]:
        paper = " ".join(f"{k} {r['paper'][k]}" for k in kinds if r["paper"].get(k))
        rows.append((f"{r['recursion']} {SECTION_NAMES[r['section']]}",
                     *(num(r["ops"].get(k)) if r["ops"].get(k) else "" for k in kinds),
                     num(r["total"]), f"{paper} = {r['paper_total']}", r["note"]))
    return Table("ops-per-node", "Requirements per node (section VI): ops of the busiest node by "
                 "kind, measured; the paper's MV counts MV and MTV (Mᵀv)", cols, tuple(rows),
                 align="l" + "r" * (len(kinds) + 1) + "ll")


def _fit(count) -> str:
    """Packages of an allocated configuration, or 'none' when a VAMP needs more pins than one has."""
    return "none" if count is None else num(count)


def packages(rep: dict) -> Table:
    """Packages per configuration (section VII), at 40 pins and --pins N."""
    p = rep["packages"]
    cols = ["configuration", "VAMPs"]
    for size in p["pins"]:
        per = p["budget"]["vamps_per_package"][str(size)]
        # (at 8 pins both budgets give 1 VAMP a package: two columns headed '8 pins, 1 each', an audit)
        tell = ((" sep.", " shared") if per["separate"] == per["shared"] else ("", ""))
        cols += [f"{size} pins, {per['separate']} each{tell[0]}",
                 f"{size} pins, {per['shared']} each{tell[1]}", f"{size} pins, mux pins sep./shared"]
    cols.append("most pins a VAMP needs")
    rows = []
    for r in p["rows"]:
        packed = r.get("packaged_vamps", r["vamps"])
        row = [r["configuration"] + (" (this report)" if r["own"] else ""),
               num(r["vamps"]) + (f" + {num(packed - r['vamps'])} extraneous" if packed != r["vamps"]
                                  else "")]
        for e in r["by_pins"]:
            muxed = (f"{_fit(e['muxed_separate'])} / {_fit(e['muxed_shared'])}"
                     if "muxed_separate" in e else DASH)
            row += [num(e["paper_separate"]), num(e["paper_shared"]), muxed]
        row.append(num(r["by_pins"][0].get("max_pins_per_vamp")))
        rows.append(tuple(row))
    b = p["budget"]
    notes = [f"pin budget per VAMP (section VII): {b['separate']['pins_per_vamp']} wired separately "
             f"({', '.join(b['separate']['signals'])}); {b['shared']['pins_per_vamp']} when "
             f"{', '.join(b['shared']['package_signals'])} take {b['shared']['pins_per_package']} "
             f"pins per package ({', '.join(b['shared']['signals'])} per VAMP)",
             "mux pins: VAMPs packed in order, each wire into an operand multiplexer a pin of its "
             "own (a folded VAMP reads several wires; a systolic one the paper's budget, but a "
             "matrix that an MM's three VAMPs make is three wires, three pins, and one column "
             "of it, which an MM member reads as operand B, one); "
             f"{DASH}: not allocated" + ("; none: a VAMP needs more pins than the package has"
                                         if any(e.get("muxed_separate", 0) is None
                                                or e.get("muxed_shared", 0) is None
                                                for r in p["rows"] for e in r["by_pins"]) else "")]
    word = rep.get("word") or {}
    bits = word.get("bits") if str(word.get("format", "")).startswith("q") else None
    words = (f"three {bits}-bit words on each operand input and on the Result ({3 * bits} wires "
             "each)" if bits else "three words of a fixed-point word (--word qI.F) on each "
             "operand input and on the Result")
    serial = ("a pin per operand wire is section VII's serial off-module communication (a word's "
              "bits, and a vector's three scalars, one after another on one wire)")
    if rep.get("bus") or rep.get("error_correction"):    # (which `vampc rtl` does not render)
        notes.append(serial)
    else:
        notes.append(f"{serial}; the Verilog of `vampc rtl` moves them in parallel, {words}, so "
                     "its VAMPs are not these packages (README, RTL)")
    if any("packaged_vamps" in r for r in p["rows"]):
        notes.append("+ extraneous: error correction's extraneous VAMP (section VII), packaged with "
                     "the others: every count of the row is for both")
    if p.get("paper_check"):
        check = p["paper_check"]
        notes.append("section VII: \"11 such 40-pin packages would implement the full systolic "
                     f"pipeline for the linear case of n = 6\" — measured {check['measured']}: "
                     f"{check['note']}")
    return Table("packages", "Packages (section VII): by the paper's pin budget, and with each "
                 "operand wire a pin", tuple(cols), tuple(rows), tuple(notes))


# --- buffering and wiring ------------------------------------------------------------------------

def buffering(rep: dict) -> Table:
    """Input buffering and delay buffers of the report's configuration, and the delay buffering of
    every allocated configuration."""
    w = rep["wiring"]
    ib = w["input_buffering"]
    d = w["delay_buffers"]
    rows = [("input buffering (scalars)", num(ib["scalars"]), f"≈ 37n + 15 = {num(ib['paper'])}",
             "see the first note")]
    for flow, x in d["by_flow"].items():
        rows.append((f"delay buffers, {flow.replace('_', ' ')}",
                     f"{num(x['stages'])} stages, {num(x['scalars'])} scalars, {num(x['chains'])} "
                     + ("chain" if x["chains"] == 1 else "chains"),
                     _flow_paper(rep, flow), ""))
    rows.append(("delay buffers, all", f"{num(d['stages'])} stages, {num(d['scalars'])} scalars, "
                 f"{num(d['chains'])} " + ("chain" if d["chains"] == 1 else "chains") + f" (longest {d['max_stages']})", DASH, ""))
    for r in w["by_configuration"]:
        rows.append((f"  {r['configuration']}", f"{num(r['stages'])} stages, {num(r['scalars'])} "
                     f"scalars", DASH, f"backward to forward {num(r['backward_to_forward_scalars'])} "
                     "scalars"))
    notes = [_input_note(ib)] + [x for x in (_factor_note(rep), _log_between_nodes_note(rep)) if x]
    others = "; the other configurations below it" if len(w["by_configuration"]) > 1 else ""
    return Table("buffering", f"Buffering (section VI) of {w['configuration']}, measured{others}",
                 ("figure", "measured", "paper", "note"),
                 tuple(rows), tuple(notes), align="lrll")


def _input_note(ib: dict) -> str:
    ports = ", ".join(f"{k} {v}" for k, v in ib["ports"].items())
    consts = ", ".join(f"{k} {v}" for k, v in ib["constants"].items())
    return (f"input buffering: host ports per set {ports}; {ib['constant_buffers']} constant buffers "
            f"{consts}. The "
            "paper's 37 per joint count z q̇ 3, z q̈ 3, A 9, p*, ṗ*, r*, s*, z 3 each, m 1, J 6 "
            "(symmetric) and 15 for the endpoints; vampc stores no ṗ* or z (the input convention), "
            "m as a vector and J whole, and one buffer per distinct constant. Counted by quantity, as "
            "the paper counts it, so the same for every layout: the network's own port and constant "
            "registers (a folded port written several times a set) are the storage line's input "
            "ports and constants")


def _flow_paper(rep: dict, flow: str) -> str:
    if Recursion(rep["recursion"]) is Recursion.LINEAR and is_layout(rep["layout"], SYSTOLIC):
        return ("only between backward and forward" if flow == "backward_to_forward" else
                "none (\"only required between backward and forward\")")
    if Recursion(rep["recursion"]) is Recursion.LOG and flow != "backward_to_forward":
        # (section VI's "about 54 scalars per node in the logarithmic case" stood as "—": an audit)
        # (per node, beside a network's stages: the note sets them side by side; "≈ 27 latched"
        # was an inference of "nearly halved" put as the paper's figure, a review's find)
        return "≈ 54 scalars a node (note)"
    return DASH


def _log_between_nodes_note(rep: dict) -> str:
    """Section VI's buffering between the log recursion's nodes beside what vampc measures."""
    if Recursion(rep["recursion"]) is not Recursion.LOG:
        return ""
    b = rep["wiring"]["buses"]["between_nodes"]
    return ("log, between nodes: section VI's \"about 54 scalars per node\" (\"nearly halved\" if "
            "outputs are latched) is its 18 vectors into a node (its Communication: \"at most 18 vectors (54 "
            f"scalars) per node\"); measured, at most {b['bwd']['vectors']} vectors "
            f"({3 * b['bwd']['vectors']} scalars) into a backward node and {b['fwd']['vectors']} "
            f"({3 * b['fwd']['vectors']}) into a forward one (Wiring, below). Every VAMP latches its "
            "Result, which holds until the VAMP's next dump (README, Timing model), so a value takes "
            "delay stages only where it must outlast that; the stages above are per network, with "
            "the sets a systolic layout has in flight")


def _factor_note(rep: dict) -> str:
    rows = {r["configuration"]: r for r in rep["wiring"]["by_configuration"]}
    # (the report's own systolic row may carry its bus: "linear, systolic, Mostly-Local Bus", whose
    # comparison was dropped, looked up by the plain name: a check against the paper)
    bus = {name.removesuffix(", Mostly-Local Bus"): r for name, r in rows.items()}
    parts = []
    for rec, factor in (("linear", "n"), ("log", "⌈log₂ n⌉")):
        s, f = bus.get(f"{rec}, systolic"), rows.get(f"{rec}, folded")
        if s and f and f["scalars"]:
            # (a bus program's delay buffers hold less where its bus stretches the cycle: fewer
            # sets in flight, each value waiting in fewer stages of a slower buffer clock; the log
            # Puma's ×0.8 stood unexplained, and then was put down to the bus-write registers,
            # which hold a counter, a source and a tier, not values: two reviews)
            mlb = rep.get("bus")
            held = (f"; its bus stretches the cycle by {mlb['stretch']} to {mlb['interval_flops']} "
                    "flops, so fewer sets are in flight and its values wait in fewer stages"
                    if mlb and mlb["stretch"] > 0 and
                    s["configuration"].endswith(", Mostly-Local Bus") else "")
            parts.append(f"{rec}: systolic {num(s['scalars'])} against folded {num(f['scalars'])} "
                         f"scalars, ×{s['scalars'] / f['scalars']:.1f} (paper: about a factor of "
                         f"{factor}{held})")
    if not parts:
        return ""
    return "systolic pipelining needs more intermediate storage — " + "; ".join(parts)


def wiring(rep: dict) -> Table:
    """Vector buses, fan-out and the Program-Mode stream of the report's configuration."""
    w = rep["wiring"]
    b = w["buses"]
    pb, pi = b["paper_between_nodes"], b["paper_internal"]
    what = exhaustive({Recursion.LINEAR: "nodes", Recursion.LOG: "nodes of the tiers"},
                      Recursion)[Recursion(rep["recursion"])]
    rows = []
    log = Recursion(rep["recursion"]) is Recursion.LOG
    for sec in ("bwd", "fwd"):
        x = b["between_nodes"][sec]
        # (the paper's log figure is a bound, "at most 18": the forward node's 12 read as a
        # difference, with no word; a check against the paper)
        rows.append((f"vector buses into a {SECTION_NAMES[sec]} node from other {what}",
                     f"{x['vectors']} vectors on {x['wires']} wires",
                     f"{'at most ' if log else ''}{pb[sec]} vectors"))
    rows.append(("vector buses, backward to forward (in all)",
                 f"{b['backward_to_forward']['vectors']} vectors on "
                 f"{b['backward_to_forward']['wires']} wires", "F_i, N_i of each joint"))
    internal = b["internal_max"]
    inwires = b["internal_max_wires"]
    bound = pi["shared_passes"] if rep.get("share_passes") else pi["module"]
    rows.append(("buses into one node's VAMPs, most (backward / npv / forward)",
                 f"{inwires['bwd']} / {inwires['npv']} / {inwires['fwd']}",
                 f"≤ {bound} / {pi['npv']} / {bound}"))
    rows.append(("maximum fan-out (inputs one Result drives)", num(w["max_fan_out"]), DASH))
    p = w["program"]
    # (the paper's Program Mode writes every pair to every input port; its figure stood as "—": a
    # check against the paper)
    rows.append(("program stream", f"{num(p['words'])} words into {p['input_buffers']} input "
                 f"buffers, loaded in {num(p['load_ticks'])} ticks",
                 f"every word to each port: {num(p['words'])} a port, ≥ {num(p['words'])} ticks"))
    notes = ["program stream: section VII writes \"to each input port, one such number-program pair "
             "for each module\"; vampc writes each word into the one input buffer whose operand-A "
             "path reaches its VAMP (README, Program file), so the words go in side by side",
             "a bus is a vector bus three scalars wide (section VI): vectors counts the results a "
             "node receives (a matrix as three), wires the taps (a value read at two buffer stages "
             "twice); a folded layout's recursion variables return through its own multiplexers"]
    linear_bwd = b["between_nodes"]["bwd"]["vectors"]
    if not log and linear_bwd != pb["bwd"]:    # (3 against 4 with no word: a check against the paper)
        notes.append(f"a backward node receives {linear_bwd} vectors from the node before it "
                     f"(the linear recursion passes ω, ω̇ and p̈ of node i − 1); the paper says "
                     f"{pb['bwd']} and does not list them")
    operands = b.get("internal_max_connections", internal)      # (the point-to-point network's)
    limit = {"bwd": bound, "npv": pi["npv"], "fwd": bound}
    counts = f"{operands['bwd']} / {operands['npv']} / {operands['fwd']}"
    systolic = is_layout(rep.get("layout"), SYSTOLIC)
    said = False
    if systolic and any(inwires[s] > operands[s] for s in limit):
        # (the row gave 48 / 20 / 20 beside ≤ 50, 2 per operator, the paper's own arithmetic, while
        # the log node's matrices from MM groups take three wires each: a check against the paper;
        # "within its bound" is said only of counts within it, a review's find)
        within = all(operands[s] <= limit[s] for s in limit) and \
            any(inwires[s] > limit[s] for s in limit)
        notes.append("buses into one node: the distinct sources each operator reads (a bus fanning "
                     "out to an MM's three VAMPs once), so a matrix whose columns an MM's three "
                     "VAMPs make is three buses (three Results; buses are not multiplexed) and a "
                     "host port's or a constant's matrix one (vampc sends it serially on one, as the "
                     "paper's one Operand-A pin takes it); counting operands, two an operator as "
                     f"the paper does: {counts}"
                     + (", within its bound, which counts a matrix operand as one bus" if within
                        else ""))
        said = True
    elif inwires != operands:
        # (a folded or budget VAMP runs several ops: its multiplexer inputs are not the paper's two
        # an operator, and a source read on two of them is one bus)
        notes.append("buses into one node: the distinct sources its VAMPs read (a source read on "
                     "several multiplexer inputs once, a matrix whose columns an MM's three VAMPs "
                     f"make three); their multiplexer inputs count {counts}")
        said = True
    if "internal_max_connections" in b:        # (71 / 27 / 30 beside ≤ 50 / 20 / 50, unexplained)
        notes.append("on the Mostly-Local Bus a VAMP's multiplexer inputs are the bus tiers it reads "
                     "beside the wires still point to point, so one node's VAMPs count "
                     f"{internal['bwd']} / {internal['npv']} / {internal['fwd']} inputs; the "
                     "connections they carry are the point-to-point network's: the row"
                     + (" and the note above" if said else f", {counts} counting operands"))
    return Table("wiring", f"Wiring (section VI) of {w['configuration']}, measured",
                 ("figure", "measured", "paper"), tuple(rows), tuple(notes), align="lrl")


def clock(rep: dict) -> Table:
    """Times at the clock rate given."""
    c = rep["clock"]
    flops = rep["latency"]["flops"], rep["interval_flops"]
    rows = (("clock", f"{c['text']} ({time_text(c['tick_ns'] / 1e3)} per flop)"),
            ("latency", f"{time_text(c['latency_us'])} ({rep['latency']['flops']} flops)"),
            ("interval", f"{time_text(c['interval_us'])} ({rep['interval_flops']} flops): "
                         f"{sets_text(c['sets_per_second'])} torque sets per second"),
            ("program load", f"{time_text(c['load_us'])} ({rep['hardware']['load_ticks']} ticks)"),
            *((f"{hz_text(r['hz'])} control", ("met" if r["met"] else "not met")
               + f" ({margin_text(r['margin'], control_need(c, r['hz'], *flops))})"
               + ("; the paper's \"about 60Hz or faster\" (section I)" if r["hz"] == 60 else ""))
              for r in c["control_rates"]))
    return Table("clock", f"At {c['text']}, one flop per tick", ("figure", "value"), rows,
                 (control_sentence(c),), align="ll")
