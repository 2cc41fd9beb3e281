"""The README's deterministic figures are what vampc computes now.

Each test reads one table (or sentence) of README.md, recomputes its numbers with vampc (mostly
`vampc report ... --format json`) and compares; a failure names the README line. The README text is
the expectation: nothing here repeats a figure. Timing tables belong to the benchmark scripts the
README names and are not checked; nor are the CP-SAT figures (`--exact` runs take minutes).
"""
from __future__ import annotations

import functools
import json
import math
import re
import shlex

import numpy
import pytest
from click.testing import CliRunner
from conftest import EXAMPLES

from vampc.cli import main
from vampc.compiler import CompileOptions, build_graph, compile_chain
from vampc.dataflow.treeprefix import tree_depths
from vampc.errors import VampcError
from vampc.machine.ops import ROM
from vampc.options import FIELD_MAX
from vampc.program import emit, words
from vampc.robot import dh, load_robot
from vampc.robot.random import random_chain, random_tree, tree_parents
from vampc.schedule.asap import schedule_asap

LINES = (EXAMPLES.parent / "README.md").read_text(encoding="utf-8").splitlines()
NUMBER_WORDS = {w: k for k, w in enumerate(
    ("zero", "one", "two", "three", "four", "five", "six", "seven", "eight", "nine", "ten"))}


# --- reading the README ---------------------------------------------------------------------------

def section(heading: str) -> list[tuple[int, str]]:
    """(line number, text) of the lines under the first heading starting with `heading` (e.g.
    "## Layouts"), up to the next heading of the same or a higher level (code blocks skipped)."""
    level = len(heading) - len(heading.lstrip("#"))
    start = next((i for i, x in enumerate(LINES) if x.startswith(heading)), None)
    assert start is not None, f"README.md has no heading {heading!r}"
    out, fenced = [], False
    for i in range(start + 1, len(LINES)):
        text = LINES[i]
        if text.startswith("```"):
            fenced = not fenced
        elif not fenced and re.match(rf"#{{1,{level}}} ", text):
            break
        out.append((i + 1, text))
    return out


def table(heading: str, header: str) -> list[tuple[int, list[str]]]:
    """(line number, cells) of each body row of the Markdown table under `heading` whose header row
    starts with `header`."""
    lines = section(heading)
    k = next((k for k, (_, text) in enumerate(lines) if text.startswith(header)), None)
    assert k is not None, f"README.md, {heading}: no table whose header starts {header!r}"
    rows = []
    for no, text in lines[k + 2:]:
        if not text.startswith("|"):
            break
        rows.append((no, [c.strip() for c in re.split(r"(?<!\\)\|", text.strip().strip("|"))]))
    assert rows, f"README.md:{lines[k][0]}: the table has no rows"
    return rows


def prose(heading: str, pattern: str) -> tuple[int, re.Match]:
    """(line number, match) of `pattern` in the text under `heading`, its lines joined by spaces."""
    text, starts = "", []
    for no, line in section(heading):
        starts.append((len(text), no))
        text += line + " "
    m = re.search(pattern, text)
    assert m, f"README.md, {heading}: no text matching {pattern!r}"
    return max(no for offset, no in starts if offset <= m.start()), m


def row(rows: list[tuple[int, list[str]]], label: str) -> tuple[int, list[str]]:
    """The row whose first cell starts with `label`."""
    found = [(no, cells) for no, cells in rows if cells[0].startswith(label)]
    assert len(found) == 1, f"README.md: {len(found)} table rows start with {label!r}"
    return found[0]


def integer(text: str) -> int:
    """A README integer, its thousands separated by spaces ("16 252 922")."""
    return int(re.sub(r"\s", "", text))


def ints(match: re.Match) -> tuple[int, ...]:
    return tuple(integer(g) for g in match.groups())


def cell(no: int, text: str, pattern: str) -> re.Match:
    """`pattern` matched against a whole table cell."""
    m = re.fullmatch(pattern, text)
    assert m, f"README.md:{no}: {text!r} does not read as {pattern!r}"
    return m


# --- what vampc computes --------------------------------------------------------------------------

@functools.cache
def report(robot: str, *args: str) -> dict:
    """`vampc report examples/ROBOT ARGS --format json`, parsed (each report run once per session)."""
    res = CliRunner().invoke(main, ["report", str(EXAMPLES / robot), "--format", "json", *args])
    assert res.exit_code == 0, res.output
    return json.loads(res.stdout)


PUMA = "puma560.yaml"
LOG = ("--recursion", "log")
UNIFORM = ("--recursion", "log", "--uniform-leaves")


def tradeoff() -> dict[str, dict]:
    """The Puma 560 trade-off sweep's points by their label."""
    return {p["layout"]: p for p in report(PUMA, "--tradeoff")["points"]}


def processors(rep: dict, recursion: str, leaves: str | None) -> dict[str, dict]:
    """The report's section VI VAMP rows of one recursion (and leaves) by section."""
    entry = next(e for e in rep["processors"]["vamps"]
                 if e["recursion"] == recursion and e["leaves"] == leaves)
    return {r["section"]: r for r in entry["rows"]}


def packages(rep: dict, configuration: str) -> dict:
    """The 40-pin package counts of one configuration."""
    entry = next(r for r in rep["packages"]["rows"] if r["configuration"] == configuration)
    return next(p for p in entry["by_pins"] if p["pins"] == 40)


def measured(rep: dict, configuration: str) -> dict:
    return next(m for m in rep["table_o1"]["measured"] if m["configuration"] == configuration)


def formula(rep: dict, key: str) -> dict:
    return next(f for f in rep["table_o1"]["formulas"] if f["key"] == key)


def latency(rep: dict) -> tuple[int, int, int]:
    """(Mults, Addns, flops) of the report's own configuration."""
    return rep["latency"]["mults"], rep["latency"]["adds"], rep["latency"]["flops"]


# --- Size limits and program words ----------------------------------------------------------------

LIMITS = "### Size limits"


def test_joint_limit():
    """Joints per chain: the limit, its message, and the 32 VAMPs a joint it is derived from (the
    most a joint of a linear systolic chain takes: an all-prismatic chain's, against 30 revolute)."""
    no, (_, value, why, message) = row(table(LIMITS, "| limit |"), "joints per chain")
    limit = integer(value)
    bits, per_joint = ints(cell(no, why, r"VAMP numbers have (\d+) bits, and the smallest network "
                                         r"\(linear, systolic\) has up to (\d+) VAMPs a joint"))
    assert ints(cell(no, message, r"`FILE: too many joints: N \(at most (\d+): \.\.\.\)`")) == (limit,)
    assert (dh.MAX_JOINTS, (2**bits - 1) // per_joint) == (limit, limit), f"README.md:{no}"
    assert dh.joint_count_problem(limit) is None
    assert dh.joint_count_problem(limit + 1).startswith(
        f"too many joints: {limit + 1} (at most {limit}: "), f"README.md:{no}"

    def vamps(n, prismatic):
        chain = random_chain(n, 0, prismatic_fraction=float(prismatic))
        return len(compile_chain(chain, CompileOptions(verify=False)).network.vamps)
    most = max(vamps(3, p) - vamps(2, p) for p in (False, True))
    assert most == per_joint, f"README.md:{no}: up to {per_joint} VAMPs a joint; vampc: {most}"


def test_value_limit(tmp_path):
    """Values in a DH table: the limit, its arithmetic, and the message for YAML aliases past it."""
    rows = table(LIMITS, "| limit |")
    no, (_, value, why, message) = row(rows, "values in a DH table")
    limit = integer(value)
    per_row, joints, rest = ints(cell(no, why, r"(\d+) values per row .*× ([\d ]+) rows \+ (\d+) for the rest"))
    assert joints == integer(row(rows, "joints per chain")[1][1])
    assert (dh.MAX_VALUES, dh.ROW_VALUES, dh.TABLE_VALUES) == (limit, per_row, rest), f"README.md:{no}"
    assert per_row * joints + rest == limit, f"README.md:{no}: {per_row} × {joints} + {rest} ≠ {limit}"
    assert f"`FILE: too large: N values (at most {limit})`" in message, f"README.md:{no}"
    bomb = ["a0: &a0 [1, 1, 1, 1, 1, 1, 1, 1, 1, 1]"]
    bomb += [f"a{i}: &a{i} [{', '.join([f'*a{i - 1}'] * 10)}]" for i in range(1, 8)]   # 10⁸ values
    path = tmp_path / "bomb.yaml"
    path.write_text("\n".join([*bomb, "name: bomb", "joints: []", ""]))
    with pytest.raises(VampcError, match=rf"values once YAML aliases are expanded \(at most {limit}\)"):
        load_robot(path)


def test_vamp_number_limit(tmp_path):
    """VAMP numbers: the range a numbering file accepts, and that its bad line is named."""
    no, (_, value, why, message) = row(table(LIMITS, "| limit |"), "VAMP numbers")
    low, high = ints(cell(no, value, r"(\d+)\.\.([\d ]+)"))
    bits = ints(cell(no, why, r"(\d+)-bit numbers, exact in a binary32 scalar"))[0]
    assert (low, high) == (1, 2**bits - 1) and float(numpy.float32(high)) == high, f"README.md:{no}"
    assert "bad line is named" in message
    path = tmp_path / "numbers.txt"
    for good in (low, high):
        path.write_text(f"{good}\n")
        assert emit.read_numbering(path, 1) == (good,), f"README.md:{no}"
    for bad in (low - 1, high + 1):
        path.write_text(f"# numbers\n{bad}\n")
        with pytest.raises(VampcError, match=f"line 2: '{bad}' is not a VAMP number"):
            emit.read_numbering(path, 1)
    assert FIELD_MAX == high, f"README.md:{no}: --vamps and --interval take 1..{FIELD_MAX}"


def test_word_field_limit(tmp_path):
    """Program delays and selects: below 2^k, with the messages the table quotes: the encoder's
    when compiling, and a program file's reader's (its schema's, which an audit found is what an
    edited file meets; the table gave the encoder's only)."""
    no, (_, value, _, message) = row(table(LIMITS, "| limit |"), "program delays and selects")
    superscript = str.maketrans("⁰¹²³⁴⁵⁶⁷⁸⁹", "0123456789")
    m = cell(no, value, r"below (\d+)([⁰¹²³⁴⁵⁶⁷⁸⁹]+)")
    base, power = int(m[1]), int(m[2].translate(superscript))
    limit = base**power
    said = cell(no, message, r"compiling: `(VAMP N: slot K FIELD V does not fit in a word)`; reading a "
                r"program file: ``(FILE: programs\[i\]\.slots\[k\]\.FIELD: expected `int` <= (\d+))``")
    shape = said[1]
    assert int(said[3]) == limit - 1
    from vampc.program.file import checksum
    program = tmp_path / "b6.vamp.json"
    assert CliRunner().invoke(main, ["compile", str(EXAMPLES / "planar2.yaml"), "--vamps", "6",
                                     "-o", str(program)]).exit_code == 0
    doc = json.loads(program.read_text())
    doc["programs"][2]["slots"][1]["delay_a"] = limit
    doc["checksum"] = checksum(doc)
    program.write_text(json.dumps(doc))
    r = CliRunner().invoke(main, ["emulate", str(program), "--random", "2"])
    assert r.exit_code == 1 and r.output.strip() == "vampc: error: " + said[2].replace("FILE", str(program)) \
        .replace("[i]", "[2]").replace("[k]", "[1]").replace("FIELD", "delay_a"), r.output
    holes = {"N": r"\d+", "K": r"\d+", "FIELD": r"\w+", "V": r"\d+"}
    pattern = "".join(holes.get(w, re.escape(w)) for w in re.split(r"\b(N|K|FIELD|V)\b", shape))
    first = words.Program(0, 0, 0, 0)
    for name in ("delay_a", "sel_a", "sel_b"):
        fits = words.Program(**{**dict.fromkeys(words.FIELDS, 1), name: limit - 1})
        assert len(words.vamp_words(7, (first, fits))) == 7
        over = words.Program(**{**dict.fromkeys(words.FIELDS, 1), name: limit})
        with pytest.raises(VampcError) as err:
            words.vamp_words(7, (first, over))
        assert re.fullmatch(pattern, str(err.value)), f"README.md:{no}: {err.value}"


def test_program_words_table():
    """The compact and extended Program-Mode words are packed as the table says, and the ROM
    pointers are the ones the prose lists."""
    heading = "### Program file"
    rows = {cells[0]: (no, cells[1:]) for no, cells in table(heading, "| scalar |")}
    no1, (number, negated) = rows["1"]
    no2, (compact2, extended2) = rows["2"]
    no3, (compact3, extended3) = rows["3"]
    high = ints(cell(no1, number, r"VAMP number \(burned in; 1\.\.(\d+)\)"))[0]
    assert high == words.LIMIT - 1, f"README.md:{no1}: words hold numbers below {words.LIMIT}"
    cell(no1, negated, r"−\(VAMP number\)")
    field = ints(cell(no2, compact2, r"delay-A · (\d+) \+ delay-B"))[0]
    assert ints(cell(no3, compact3, r"delay-R · (\d+) \+ ROM pointer")) == (field,)
    m = cell(no2, extended2, r"slot · (\d+) \+ field \((.*)\)")
    per_slot = int(m[1])
    names = {int(k): v.lower().replace("-", "_")
             for k, v in (x.split(" ", 1) for x in m[2].split(", "))}
    cell(no3, extended3, r"the field's value")
    assert sorted(names.values()) == sorted(words.FIELDS), f"README.md:{no2}: {names}"
    slot0 = words.Program(5, 6, 7, 3, sel_a=2)
    slot1 = words.Program(9, 10, 11, 6, sel_a=1, sel_b=4)
    got = words.vamp_words(high, (slot0, slot1))
    assert got[0] == (high, 5 * field + 6, 7 * field + 3), f"README.md:{no2}"
    fields = {v: k for k, v in names.items()}
    want = {(-high, fields["sel_a"], 2)} | {(-high, per_slot + fields[f], slot1.field(f))
                                            for f in words.FIELDS}
    assert set(got[1:]) == want and len(got) == 1 + len(want), f"README.md:{no2}"

    no, m = prose(heading, r"which micro-sequence of Table VII\.1 runs: (.*?)\)")
    listed = []
    for item in m[1].split(", "):
        if r := re.fullmatch(r"(\d+)–(\d+) (\w+) column (\d+)–(\d+)", item):
            listed += [(r[3], c) for c in range(int(r[4]), int(r[5]) + 1)]
        else:
            listed.append((item.split(" ")[1], None))
    assert [(op.value, col) for op, col in ROM[:len(listed)]] == listed, f"README.md:{no}"


# --- Trees and floating bases ---------------------------------------------------------------------

TREES = "## Trees and floating bases"


def test_quadruped_report_lines():
    """The lines quoted from `vampc report examples/quadruped.urdf --recursion log` are its lines."""
    lines = section(TREES)
    k = next(k for k, (_, text) in enumerate(lines) if text.startswith("$ vampc report "))
    command = shlex.split(lines[k][1].removeprefix("$ "))
    assert command[:2] == ["vampc", "report"], f"README.md:{lines[k][0]}"
    res = CliRunner().invoke(main, ["report", str(EXAMPLES.parent / command[2]), *command[3:]])
    assert res.exit_code == 0, res.output
    out = {" ".join(x.split()) for x in res.stdout.splitlines()}
    quoted = []
    for no, text in lines[k + 1:]:
        if text.startswith("```"):
            break
        if text.strip() != "...":
            quoted.append(no)
            assert " ".join(text.split()) in out, f"README.md:{no}: {text.strip()!r} is not in the report"
    assert len(quoted) >= 3


def test_floating_base_quadruped():
    """"with --floating-base: N outputs, linear L flops on V VAMPs" for the quadruped."""
    no, m = prose(TREES, r"\(with `--floating-base`: (\d+) outputs, linear (\d+) flops on (\d+) VAMPs\)")
    rep = report("quadruped.urdf", "--floating-base")
    got = (rep["tree"]["outputs"], rep["latency"]["flops"], rep["vamps"]["total"])
    assert rep["recursion"] == "linear" and got == ints(m), f"README.md:{no}: vampc {got}"


def arm_lengths(n: int) -> list[int]:
    """Joints per arm of random_tree's n-joint star (an arm starts on the base, parent 0)."""
    out = []
    for p in tree_parents(n, "star"):
        if p == 0:
            out.append(0)
        out[-1] += 1
    return out


def test_linear_recursion_on_a_star():
    """The linear latencies of a 32-joint star, a 32-joint chain and six six-joint arms."""
    no, m = prose(TREES, r"a (\d+)-joint star \((\w+) (\w+)-joint arms and a (\w+)-joint one on a "
                         r"base; `vampc\.robot\.random\.random_tree\((\d+), shape=\"star\"\)`\) takes "
                         r"(\d+) flops against (\d+) for a (\d+)-joint chain, and (\w+) (\w+)-joint arms "
                         r"\((\d+) joints\) (\d+)\.")
    n, arms, arm, last, n2, star, chain, n3, arms2, arm2, n4, star2 = (
        int(x) if x.isdigit() else NUMBER_WORDS[x] for x in m.groups())
    assert n == n2 == n3 and arms2 * arm2 == n4

    def flops(count, shape):
        c = compile_chain(random_tree(count, shape=shape), CompileOptions(verify=False), until="schedule")
        return c.schedule.latency
    assert sorted(arm_lengths(n)) == sorted([arm] * arms + [last]), f"README.md:{no}"
    assert arm_lengths(n4) == [arm2] * arms2, f"README.md:{no}"
    got = (flops(n, "star"), flops(n, "chain"), flops(n4, "star"))
    assert got == (star, chain, star2), f"README.md:{no}: vampc {got}"


@functools.cache
def depth_row(shape: str, n: int, recursions: tuple[str, ...]) -> tuple[int, ...]:
    """What benchmarks/tree_depth.py prints for one tree: height, light edges, backward tiers,
    forward levels, ⌈log2(n+1)⌉, then the ASAP latencies of `recursions` (linear, log)."""
    tree = random_tree(n, 0, shape, prismatic_fraction=0.0)
    d = tree_depths(tree.parent_of, "sklansky", ground=tree.floating or tree.base_rotates,
                    floating=tree.floating)
    out = (d["height"], d["light_edges"], d["backward_tiers"], d["forward_levels"], d["log2"])
    return out + tuple(schedule_asap(build_graph(tree, CompileOptions(recursion=r, verify=False)),
                                     verify=False).latency for r in recursions)


SHAPES = {"chain": "chain", "binary": "binary", "star of chains": "star"}


# the 4096-joint rows (3.7 s) under -m slow: the same check as the 64- and 512-joint rows'
@pytest.mark.parametrize("n", [64, 512, pytest.param(4096, marks=pytest.mark.slow)])
def test_depth_against_n(n):
    """The "Depth against n" rows of size n (n = 4096: all but the log latency, whose graphs take
    minutes), and forward levels = ⌈log2 m⌉ as the prose says, m the largest subtree on the base."""
    rows = [(no, cells) for no, cells in table(TREES, "| shape | n |") if integer(cells[1]) == n]
    assert {cells[0] for _, cells in rows} == set(SHAPES)
    for no, cells in rows:
        want = tuple(integer(c) for c in cells[2:])
        got = depth_row(SHAPES[cells[0]], n, ("linear", "log") if n < 4096 else ("linear",))
        assert got == want[:len(got)], f"README.md:{no}: {cells[0]}, n = {n}: vampc {got}"
        parents = tree_parents(n, SHAPES[cells[0]])
        sizes = [1] * (n + 1)
        for j in range(n, 0, -1):
            sizes[parents[j - 1]] += sizes[j]
        largest = max(sizes[j] for j in range(1, n + 1) if parents[j - 1] == 0)
        assert got[3] == math.ceil(math.log2(largest))


# --- Layouts --------------------------------------------------------------------------------------

def test_layouts_table():
    """Every row of the Layouts table: the Puma 560's layout comparison (linear; log with uniform
    leaves), and the single device's backward + forward VAMPs."""
    reports = {"linear": (report(PUMA), "linear", None),
               "log (uniform leaves)": (report(PUMA, *UNIFORM), "log", "uniform")}
    seen = set()
    for no, cells in table("## Layouts", "| layout | latency"):
        recursion, layout = cells[0].split(", ", 1)
        rep, rec, leaves = reports[recursion]
        got_row = next(r for r in rep["layout_comparison"] if r["layout"] == layout)
        parts = cell(no, cells[4], r"(\d+)(?: = (\d+) \+ (\d+))?").groups()
        want = (integer(cells[1]), *ints(cell(no, cells[2], r"(\d+) \+ (\d+) \+ (\d+)")),
                integer(cells[3]), int(parts[0]), *(integer(c) for c in cells[5:]))
        got = tuple(got_row[k] for k in ("latency_flops", "mults", "adds", "waits", "interval_flops",
                                         "vamps", "buffer_stages", "mux_inputs", "control_registers",
                                         "load_ticks"))
        assert got == want, f"README.md:{no}: {cells[0]}: vampc {got}"
        if parts[1]:
            device = processors(rep, rec, leaves)
            split = (device["bwd_total"]["single_device"], device["fwd"]["single_device"])
            assert split == (int(parts[1]), int(parts[2])), f"README.md:{no}: vampc {split}"
        seen.add((recursion, layout))
    assert seen == {(r, lay) for r in reports for lay in ("systolic", "folded", "folded, shared passes")}


# --- VAMP budgets and the trade-off ---------------------------------------------------------------

BUDGETS = "## VAMP budgets and the trade-off"


def test_tradeoff_table():
    """Every row quoted from `vampc report examples/puma560.yaml --tradeoff` is a point of it."""
    points = tradeoff()
    rows = table(BUDGETS, "| layout | VAMPs |")
    assert len(rows) >= 10
    keys = ("vamps", "latency_flops", "latency_bound", "latency_gap_pct", "interval_flops",
            "interval_bound", "interval_gap_pct", "buffer_stages", "mux_inputs", "host_writes_per_set")
    for no, cells in rows:
        assert cells[0] in points, f"README.md:{no}: the sweep has no point {cells[0]!r}"
        p = points[cells[0]]
        got = tuple(f"{p[k]:.1f}%" if k.endswith("_pct") else str(p[k]) for k in keys)
        want = tuple(c.replace(" ", "") for c in cells[1:])
        assert got == want, f"README.md:{no}: {cells[0]}: vampc {got}"


def test_budget_7_prose():
    """"Budget 7 comes out at interval I with latency L (G% above the bound of B)"."""
    no, m = prose(BUDGETS, r"Budget (\d+) comes\s+out at interval (\d+) with latency (\d+) "
                           r"\(([\d.]+)% above the bound of (\d+)\)")
    p = tradeoff()[f"budget {m[1]}"]
    got = (p["interval_flops"], p["latency_flops"], f"{p['latency_gap_pct']:.1f}", p["latency_bound"])
    assert got == (int(m[2]), int(m[3]), m[4], int(m[5])), f"README.md:{no}: vampc {got}"


def test_fastest_budget_prose():
    """"N VAMPs already give an interval of I flops, below the paper's P": the sweep's smallest
    interval, reached on N VAMPs."""
    no, m = prose(BUDGETS, r"(\d+) VAMPs already give an interval of (\d+) flops, below the paper's\s+(\d+)")
    vamps, interval, paper = ints(m)
    points = tradeoff().values()
    fastest = min(p["interval_flops"] for p in points)
    fewest = min(p["vamps"] for p in points if p["interval_flops"] == fastest)
    got = (fewest, fastest, formula(report(PUMA), "lathrop_systolic")["flops"])
    assert got == (vamps, interval, paper), f"README.md:{no}: vampc {got}"


def test_interval_40_prose():
    """"--interval T on the Puma: K VAMPs at interval I, latency L, which --vamps K also gives, and
    --vamps K --interval T too"."""
    no, m = prose(BUDGETS, r"`--interval (\d+)` on the Puma:\s+(\d+) VAMPs at interval (\d+), latency (\d+), "
                           r"which `--vamps (\d+)` also gives, and `--vamps (\d+) --interval (\d+)` too;")
    t, k, interval, lat, k2, k3, t2 = ints(m)
    assert k == k2 == k3 and t == t2
    rep = report(PUMA, "--interval", str(t))
    got = (rep["budget"]["vamps_used"], rep["interval_flops"], rep["latency"]["flops"])
    assert got == (k, interval, lat), f"README.md:{no}: --interval {t}: vampc {got}"
    rep = report(PUMA, "--vamps", str(k))
    got = (rep["budget"]["vamps_used"], rep["interval_flops"], rep["latency"]["flops"])
    assert got == (k, interval, lat), f"README.md:{no}: --vamps {k}: vampc {got}"
    rep = report(PUMA, "--vamps", str(k), "--interval", str(t))
    got = (rep["budget"]["vamps_used"], rep["interval_flops"], rep["latency"]["flops"])
    assert got == (k, interval, lat), f"README.md:{no}: --vamps {k} --interval {t}: vampc {got}"


def test_budgets_on_the_folded_vamp_counts():
    """"On the folded layouts' VAMP counts (A and B) a budget runs at the same latency, L flops, with
    a set every I and J flops instead of P"."""
    no, m = prose(BUDGETS, r"On the folded layouts' VAMP counts \((\d+) and (\d+)\) a budget runs at the same\s+"
                           r"latency, (\d+) flops, with a set every (\d+) and (\d+) flops instead of (\d+)\.")
    a, b, lat, ia, ib, folded = ints(m)
    points = tradeoff()
    got = sorted((points[k]["vamps"], points[k]["latency_flops"], points[k]["interval_flops"])
                 for k in ("folded", "folded, shared passes"))
    assert got == [(a, lat, folded), (b, lat, folded)], f"README.md:{no}: folded layouts: vampc {got}"
    for k, interval in ((a, ia), (b, ib)):
        rep = report(PUMA, "--vamps", str(k))
        got = (rep["latency"]["flops"], rep["interval_flops"])
        assert got == (lat, interval), f"README.md:{no}: --vamps {k}: vampc {got}"


# --- Figures against the paper --------------------------------------------------------------------

FIGURES = "## Figures against the paper"


def figure(label: str) -> tuple[int, str, str, str]:
    """(line, paper, vampc, why) of the row of the figures table starting with `label`."""
    no, cells = row(table(FIGURES, "| figure, n = 6 |"), label)
    return no, cells[1], cells[2], cells[3]


def test_table_o1b_row():
    """Table O.1b: the paper's printed figures, what its formulas give, and the seven rows that agree."""
    no, paper, vampc, why = figure("Table O.1b")
    pattern = r"{}([\d ]+) M; ([\d ]+) M; (\d+) M \+ (\d+) A"
    rep = report(PUMA)
    uk, waters, lin = (formula(rep, k) for k in ("uicker_kahn", "waters", "luh_lin"))
    got = (uk["mults"], waters["mults"], lin["mults"], lin["adds"])
    assert got == ints(cell(no, vampc, pattern.format("the paper's own formulas give "))), \
        f"README.md:{no}: vampc {got}"
    printed = (uk["printed_n6"]["mults"], waters["printed_n6"]["mults"], lin["printed_n6"]["mults"],
               lin["printed_n6"]["adds"])
    assert printed == ints(cell(no, paper, pattern.format(""))), f"README.md:{no}: vampc {printed}"
    agree = sum(f["printed_n6"]["matches"] for f in rep["table_o1"]["formulas"])
    assert agree == NUMBER_WORDS[re.search(r"the other (\w+) rows agree", why)[1]], f"README.md:{no}"


def test_serial_newton_euler_row():
    no, paper, vampc, _ = figure("serial Newton-Euler")
    rep = report(PUMA)
    got = (rep["serial_work"]["mults"], rep["serial_work"]["adds"])
    assert got == ints(cell(no, vampc, r"(\d+) M \+ (\d+) A: .*")), f"README.md:{no}: vampc {got}"
    ref = (rep["serial_reference"]["mults"], rep["serial_reference"]["adds"])
    assert ref == ints(cell(no, paper, r"(\d+) M \+ (\d+) A")), f"README.md:{no}: vampc {ref}"


def test_linear_latency_row():
    """16 M + 45 A = 61 flops beside the paper's, and the difference, +1 Mult + 2 Addns."""
    no, paper, vampc, why = figure("linear latency")
    rep = report(PUMA)
    pattern = r"(\d+) M \+ (\d+) A = (\d+) flops"
    assert latency(rep) == ints(cell(no, vampc, pattern)), f"README.md:{no}: vampc {latency(rep)}"
    want = (rep["paper"]["mults"], rep["paper"]["adds"], rep["paper"]["flops"])
    assert want == ints(cell(no, paper, pattern)), f"README.md:{no}: vampc {want}"
    diff = measured(rep, "linear, systolic")["difference"]
    got = (diff["mults"], diff["adds"])
    assert got == ints(cell(no, why, r"output correction, \+(\d+) Mult \+ (\d+) Addns .*")), f"README.md:{no}"


def test_log_latency_row():
    """12 M + 30 A = 42 flops, 44 with uniform leaves (2 Addns more), beside the paper's."""
    no, paper, vampc, why = figure("logarithmic latency")
    m = cell(no, vampc, r"(\d+) M \+ (\d+) A = (\d+) flops; (\d+) M \+ (\d+) A = (\d+) with `--uniform-leaves`")
    got = latency(report(PUMA, *LOG)) + latency(report(PUMA, *UNIFORM))
    assert got == ints(m), f"README.md:{no}: vampc {got}"
    more = ints(re.search(r"uniform leaves cost (\d+) Addns more", why))
    assert (got[4] - got[1],) == more and got[0] == got[3], f"README.md:{no}"
    theirs = report(PUMA, *LOG)["paper"]
    want = (theirs["mults"], theirs["adds"], theirs["flops"])
    assert want == ints(cell(no, paper, r"(\d+) M \+ (\d+) A = (\d+) flops")), f"README.md:{no}"


def test_systolic_interval_row():
    no, paper, vampc, _ = figure("systolic interval")
    systolic = measured(report(PUMA), "linear, systolic")
    got = (systolic["interval"]["mults"], systolic["interval"]["adds"], systolic["interval_flops"])
    assert got[2:] == ints(cell(no, vampc, r"(\d+) flops")), f"README.md:{no}: vampc {got}"
    assert got == ints(cell(no, paper, r"(\d+) M \+ (\d+) A = (\d+) flops")), f"README.md:{no}: vampc {got}"


def test_vamps_per_node_linear_row():
    no, paper, vampc, _ = figure("VAMPs per node, linear")
    per = report(PUMA)["vamps"]["per_node"]
    got = (per["bwd"], per["npv"], per["fwd"])
    assert got == ints(cell(no, vampc, r"(\d+) \+ (\d+), (\d+)")), f"README.md:{no}: vampc {got}"
    assert got == ints(cell(no, paper, r"(\d+) \+ (\d+) backward, (\d+) forward")), f"README.md:{no}"


def test_vamps_linear_systolic_row():
    """132 + 48 = 180 for the Puma, and the Stanford arm's count (its prismatic joint named)."""
    no, paper, vampc, why = figure("VAMPs, linear systolic")
    v = report(PUMA)["vamps"]
    got = (v["backward"], v["forward"], v["total"])
    assert got == ints(cell(no, vampc, r"(\d+) \+ (\d+) = (\d+)")), f"README.md:{no}: vampc {got}"
    device = processors(report(PUMA), "linear", None)
    theirs = (device["bwd_total"]["paper"]["systolic"], device["fwd"]["paper"]["systolic"])
    assert theirs == ints(cell(no, paper, r"(\d+) backward \+ (\d+) forward")), f"README.md:{no}"
    joint, bwd, fwd = ints(re.search(r"the Stanford arm, prismatic joint (\d+): (\d+) \+ (\d+)", why))
    rep = report("stanford.yaml")
    got = (rep["prismatic_joints"], rep["vamps"]["backward"], rep["vamps"]["forward"])
    assert got == ([joint], bwd, fwd), f"README.md:{no}: Stanford arm: vampc {got}"


def test_vamps_log_systolic_rows():
    """Log systolic VAMPs with uniform leaves (beside the paper's) and with Table IV.1's leaves."""
    no, paper, vampc, why = figure("VAMPs, log systolic, uniform leaves")
    v = report(PUMA, *UNIFORM)["vamps"]
    assert (v["backward"], v["forward"]) == ints(cell(no, vampc, r"(\d+) \+ (\d+)")), \
        f"README.md:{no}: vampc {v['backward']} + {v['forward']}"
    device = processors(report(PUMA, *UNIFORM), "log", "uniform")
    theirs = (device["bwd_total"]["paper"]["systolic"], device["fwd"]["paper"]["systolic"])
    assert theirs == ints(cell(no, paper, r"(\d+) backward \+ (\d+) forward")), f"README.md:{no}"
    node = (device["fwd"]["per_node"], device["fwd"]["paper"]["per_node"])
    assert node == ints(re.search(r"(\d+) VAMPs instead of (\d+)", why)), f"README.md:{no}: vampc {node}"
    no, _, vampc, _ = figure("VAMPs, log systolic, Table IV.1 leaves")
    v = report(PUMA, *LOG)["vamps"]
    assert (v["backward"], v["forward"]) == ints(cell(no, vampc, r"(\d+) \+ (\d+)")), \
        f"README.md:{no}: vampc {v['backward']} + {v['forward']}"


def test_packages_linear_systolic_row():
    no, paper, vampc, why = figure("40-pin packages, linear systolic")
    rep = report(PUMA)
    per = rep["packages"]["budget"]["vamps_per_package"]["40"]
    count = packages(rep, "linear, systolic")
    got = (count["paper_shared"], per["shared"], count["paper_separate"], per["separate"])
    assert got == ints(cell(no, vampc, r"(\d+) \((\d+) each\) or (\d+) \((\d+) each\)")), \
        f"README.md:{no}: vampc {got}"
    check = rep["packages"]["paper_check"]
    assert (check["paper"], per["shared"]) == ints(cell(no, paper, r"(\d+) \((\d+) VAMPs each\)"))
    assert ints(re.search(r"(\d+) × (\d+) = (\d+) equals the backward", why)) == (
        check["paper"], per["shared"], rep["vamps"]["backward"]), f"README.md:{no}"


def test_packages_folded_row():
    no, _, vampc, why = figure("40-pin packages, folded")
    rep = report(PUMA)
    device = processors(rep, "linear", None)
    count = packages(rep, "linear, folded")
    got = (device["bwd_total"]["single_device"], device["fwd"]["single_device"], count["paper_separate"],
           count["paper_shared"], count["muxed_separate"], count["muxed_shared"])
    pattern = (r"(\d+) \+ (\d+) VAMPs: (\d+) or (\d+) packages by the pin budget, (\d+) or (\d+) with one "
               r"pin per multiplexer input")
    assert got == ints(cell(no, vampc, pattern)), f"README.md:{no}: vampc {got}"
    most = ints(re.search(r"up to (\d+) pins a VAMP", why))
    assert (count["max_pins_per_vamp"],) == most, f"README.md:{no}: vampc {count['max_pins_per_vamp']}"


def test_log_single_device_row():
    no, paper, vampc, _ = figure("VAMPs, log single device, uniform leaves")
    device = processors(report(PUMA, *UNIFORM), "log", "uniform")
    got = (device["bwd_total"]["single_device"], device["fwd"]["single_device"], device["bwd"]["per_tier"],
           device["npv"]["per_tier"], device["fwd"]["per_tier"])
    assert got == ints(cell(no, vampc, r"(\d+) \+ (\d+); per tier (\d+) \+ (\d+), (\d+)")), \
        f"README.md:{no}: vampc {got}"
    theirs = (device["bwd_total"]["paper"]["single_device"], device["fwd"]["paper"]["single_device"])
    assert theirs == ints(cell(no, paper, r"(\d+) \+ (\d+) \(tier of 3 nodes\)")), f"README.md:{no}"


def test_vector_buses_linear_row():
    no, paper, vampc, _ = figure("vector buses between nodes, linear")
    buses = report(PUMA)["wiring"]["buses"]
    got = (buses["between_nodes"]["bwd"]["vectors"], buses["between_nodes"]["fwd"]["vectors"])
    assert got == ints(cell(no, vampc, r"(\d+) \(.*\), (\d+) \(f, n\)")), f"README.md:{no}: vampc {got}"
    theirs = (buses["paper_between_nodes"]["bwd"], buses["paper_between_nodes"]["fwd"])
    assert theirs == ints(cell(no, paper, r"(\d+) backward, (\d+) forward")), f"README.md:{no}"


def test_vector_buses_log_row():
    """Buses into a log combining node: uniform leaves (the paper's node) and vampc's default
    separate leaves (Table IV.1's), which differ in wires."""
    no, paper, vampc, _ = figure("vector buses into a log combining node")
    buses = report(PUMA, *UNIFORM)["wiring"]["buses"]
    into = buses["between_nodes"]["bwd"]
    separate = report(PUMA, *LOG)["wiring"]["buses"]["between_nodes"]["bwd"]
    got = (into["vectors"], into["wires"], separate["wires"])
    assert separate["vectors"] == into["vectors"]
    assert got == ints(cell(no, vampc, r"(\d+) \([^)]*\) on (\d+) wires with `--uniform-leaves`, "
                                       r"(\d+) with Table IV\.1's leaves")), f"README.md:{no}: vampc {got}"
    assert (buses["paper_between_nodes"]["bwd"],) == ints(cell(no, paper, r"at most (\d+) vectors"))


def test_point_to_point_buses_row():
    no, paper, vampc, _ = figure("point-to-point buses into one node")
    linear, log = (report(PUMA)["wiring"]["buses"], report(PUMA, *LOG)["wiring"]["buses"])
    wires = (linear["internal_max_wires"]["bwd"], log["internal_max_wires"]["bwd"],
             linear["internal_max_wires"]["npv"])
    got = (linear["internal_max"]["bwd"], log["internal_max"]["bwd"], linear["internal_max"]["npv"])
    assert log["internal_max"]["npv"] == got[2] == log["internal_max_wires"]["npv"]
    assert wires + got == ints(cell(no, vampc, r"(\d+) \(linear backward\), (\d+) \(log backward\), "
                                               r"(\d+); counting operands, 2 an op as the paper does: "
                                               r"(\d+), (\d+), (\d+)")), f"README.md:{no}: vampc {wires + got}"
    theirs = (linear["paper_internal"]["module"], linear["paper_internal"]["npv"])
    assert theirs == ints(cell(no, paper, r"≤ (\d+) \(25 operators\), non-propagated ≤ (\d+)"))


def test_input_buffering_row():
    no, paper, vampc, _ = figure("input buffering")
    got = (report("arm6.urdf")["input_buffer_scalars"], report(PUMA)["input_buffer_scalars"])
    assert got == ints(cell(no, vampc, r"(\d+) \(arm6\), (\d+) \(Puma 560: .*\)")), f"README.md:{no}: vampc {got}"
    theirs = report(PUMA)["wiring"]["input_buffering"]["paper"]
    assert (theirs,) == ints(cell(no, paper, r"≈ 37n \+ 15 = (\d+) scalars")), f"README.md:{no}"


def test_delay_buffers_row():
    no, _, vampc, _ = figure("delay buffers, linear systolic")
    delay = report(PUMA)["wiring"]["delay_buffers"]
    got = (delay["stages"], delay["chains"], delay["scalars"])
    m = cell(no, vampc, r"(\d+) stages in (\d+) chains \((\d+) scalars\), all from backward results to "
                        r"forward nodes")
    assert got == ints(m), f"README.md:{no}: vampc {got}"
    assert delay["by_flow"]["backward_to_forward"] == {"chains": got[1], "scalars": got[2], "stages": got[0]}


def test_arm6_gives_the_same_numbers():
    """"examples/arm6.urdf (general URDF frames) gives the same numbers except where noted": every
    measured configuration of Table O.1 and the VAMP counts."""
    prose(FIGURES, r"`examples/arm6\.urdf` \(general URDF frames\) gives the same numbers\s+except where noted")
    for args in ((), UNIFORM):
        puma, arm6 = report(PUMA, *args), report("arm6.urdf", *args)
        assert arm6["table_o1"]["measured"] == puma["table_o1"]["measured"]
        assert arm6["vamps"] == puma["vamps"] and arm6["wiring"]["buses"] == puma["wiring"]["buses"]


def test_snake64_latency_prose():
    """"snake64 (64 joints) takes M + A = F flops against (2n+3) M + (6n+7) A = P"."""
    no, m = prose(FIGURES, r"snake64 \((\d+) joints\)\s+takes (\d+) M \+ (\d+) A = (\d+) flops against "
                           r"\(2n\+3\) M \+ \(6n\+7\) A = (\d+)")
    rep = report("snake64.yaml")
    got = (rep["joints"], *latency(rep), rep["paper"]["flops"])
    assert got == ints(m), f"README.md:{no}: vampc {got}"


def test_emulated_time_prose():
    """"the Puma's 1000 sets: L + F + 999 × I + 1 = T flops": what `vampc emulate` prints of the
    Puma's 1000 sets, and the sum."""
    no, m = prose("### `vampc emulate SOURCE`", r"the Puma's 1000 sets: (\d+) \+ (\d+) \+ 999 × (\d+) "
                                                r"\+ 1 = (\d+) flops")
    load, first, interval, total = ints(m)
    r = CliRunner().invoke(main, ["emulate", str(EXAMPLES / PUMA), "--random", "1000"])
    assert r.exit_code == 0, r.output
    said = re.search(r"program load (\d+) ticks; first set after (\d+) flops, then one every (\d+) "
                     r"flops; emulated time (\d+) flops", r.output)
    assert said and tuple(map(int, said.groups())) == (load, first, interval, total), \
        f"README.md:{no}: vampc {r.output}"
    assert load + first + 999 * interval + 1 == total, f"README.md:{no}: the sum is not {total}"
