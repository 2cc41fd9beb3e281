"""Report figures (vampc.report.counts) and their text rendering (vampc.report.text).

Expected numbers come from the paper (Table O.1 formulas, section VI VAMP tables and 40-pin packaging)
and from the op costs of DESIGN §4, counted here by hand per joint.
"""
from __future__ import annotations

import math
from pathlib import Path

import pytest

from vampc.compiler import CompileOptions, compile_chain
from vampc.report.counts import (
    latency_note,
    packages,
    paper_latency,
    serial_reference,
    summary,
)
from vampc.report.text import render
from vampc.robot import load_robot
from vampc.robot.random import random_chain

EXAMPLES = Path(__file__).parent.parent / "examples"

# Per revolute joint of the linear graph (section VI tables): 3 MTV (ω, ω̇, T11), 4 MV (T16, T18, f, n),
# 12 VA, 10 VC, 1 SV. Serial work per op (DESIGN §4): MV/MTV 9M+6A, VA 3A, VC 6M+3A, SV 3M.
PER_JOINT_OPS = {"MTV": 3, "MV": 4, "VA": 12, "VC": 10, "SV": 1}
PER_JOINT_WORK = (7 * 9 + 10 * 6 + 3, 7 * 6 + 12 * 3 + 10 * 3)   # (126 M, 108 A)


@pytest.fixture(scope="module")
def rotary6():
    return summary(compile_chain(random_chain(6, 21, prismatic_fraction=0.0)))


def test_paper_formulas_for_n6():
    # Section I / Table O.1, n = 6: linear 15 M + 43 A, logarithmic 11 M + 28 A, serial 852 M + 738 A.
    assert paper_latency(6, "linear") == {"flops": 58, "mults": 15, "adds": 43}
    assert paper_latency(6, "log") == {"flops": 39, "mults": 11, "adds": 28}
    assert serial_reference(6) == {"mults": 852, "adds": 738}


@pytest.mark.parametrize("n", [1, 2, 3, 7, 8, 63, 64])
def test_log_formula_uses_ceil_log2_n_plus_1(n):
    tiers = math.ceil(math.log2(n + 1))
    want = (2 * tiers + 5, 6 * tiers + 10)
    got = paper_latency(n, "log")
    assert (got["mults"], got["adds"], got["flops"]) == want + (sum(want),)


@pytest.mark.parametrize("vamps,want", [(180, (36, 15)), (1, (1, 1)), (12, (3, 1)), (13, (3, 2))])
def test_packages_hold_5_or_12_vamps(vamps, want):
    assert packages(vamps) == {"separate": want[0], "shared": want[1]}


def test_rotary_arm_summary_n6(rotary6):
    rep = rotary6
    assert (rep["joints"], rep["recursion"], rep["layout"], rep["prismatic_joints"]) == (6, "linear",
                                                                                          "systolic", [])
    assert rep["latency"] == {"flops": 61, "mults": 16, "adds": 45, "waits": 0}
    assert rep["paper"] == {"flops": 58, "mults": 15, "adds": 43}
    assert rep["interval_flops"] == 4
    v = rep["vamps"]
    assert (v["total"], v["backward"], v["forward"]) == (180, 132, 48)
    assert v["per_node"] == {"bwd": 12, "npv": 10, "fwd": 8}
    assert v["by_op"] == {op: 6 * k for op, k in PER_JOINT_OPS.items()}
    assert rep["ops"] == v["by_op"]
    assert rep["serial_work"] == {"mults": 6 * PER_JOINT_WORK[0], "adds": 6 * PER_JOINT_WORK[1]}
    assert rep["packages_40pin"] == {"separate": 36, "shared": 15}
    assert rep["buffers"]["scalars"] == 3 * rep["buffers"]["stages"]


def test_input_buffer_scalars_count_constants_and_one_set_of_ports(rotary6):
    # Per revolute joint: ports A (9), z q̇ (3), z q̈ (3); constants p* (3), r* (3), s* (3), m (3), J (9).
    # Endpoints: ω0 = ω̇0 = f_{n+1} = n_{n+1} = 0 share one buffer (3), p̈0 = -g (3).
    assert rotary6["input_buffer_scalars"] == 6 * (15 + 21) + 6


def test_note_explains_the_output_correction(rotary6):
    notes = latency_note(rotary6)
    assert notes[0] == "+3 flops (+1 Mults, +2 Addns) against the paper's formula"
    assert len(notes) == 2 and explains_output_correction(notes[1])


def explains_output_correction(note: str) -> bool:
    """The note names the correction, its cost and its reason (DESIGN §5), whatever the wording."""
    return all(part in note for part in ("output correction", "1 Mult + 2 Addns", "τ_i = z_{i-1}·n_i",
                                         "A_i n_i", "O_{i-1}"))


def test_note_for_prismatic_joints_and_other_latencies():
    chain = random_chain(4, 3, prismatic_fraction=0.5)
    prismatic = [i for i, j in enumerate(chain.joints, 1) if j.sigma == 0]
    assert prismatic
    rep = summary(compile_chain(chain, CompileOptions(mult_latency=2, add_latency=3)))
    assert rep["prismatic_joints"] == prismatic
    assert rep["timing"] == {"mult_latency": 2, "add_latency": 3}
    notes = latency_note(rep)
    assert any(n.startswith("the paper assumes 1 Mult = 1 Addn = 1 flop; its formula is compared "
                            "at the given latencies") for n in notes)
    # the paper's 2n + 3 Mults and 6n + 7 Addns (n = 4), at 2 and 3 flops each
    expected = (2 * 4 + 3) * 2 + (6 * 4 + 7) * 3
    assert notes[0].startswith(f"{rep['latency']['flops'] - expected:+d} flops (".replace("-", "−"))
    assert notes[0].endswith("against the paper's formula at these latencies")
    assert any(s.startswith(f"prismatic joints {prismatic}: Table I.1's σ̄ terms add ops but no "
                            "latency") for s in notes)


def test_note_when_equal_to_the_paper(rotary6):
    rep = dict(rotary6, latency=dict(rotary6["paper"]))
    assert latency_note(rep) == ["equals the paper's formula"]


def test_render_shows_the_figures(rotary6):
    text = render(rotary6)
    lines = text.splitlines()
    assert text.endswith("\n")
    assert "latency          61 flops = 16 Mults + 45 Addns on the critical path" in lines
    assert "paper            58 flops = 15 Mults + 43 Addns" in lines
    assert "                 +3 flops (+1 Mults, +2 Addns) against the paper's formula" in lines
    assert "interval         4 flops between successive torque sets" in lines
    assert "VAMPs            180 = 132 backward + 48 forward" in lines
    assert "  per node       backward 12 propagated + 10 non-propagated, forward 8" in lines
    assert "  by op          MTV 18, MV 24, SV 6, VA 72, VC 60" in lines
    assert "40-pin packages  36 (5 VAMPs each, separate pins) or 15 (12 each, shared clock/power/reset)" \
        in lines
    assert "serial work      756 Mults + 648 Addns in the graph; Luh-Walker-Paul 852 + 738" in lines


def test_render_names_prismatic_joints():
    chain = random_chain(3, 8, prismatic_fraction=1.0)
    text = render(summary(compile_chain(chain)))
    assert text.splitlines()[0] == f"robot            {chain.name} (3 joints, prismatic [1, 2, 3])"


@pytest.mark.parametrize("recursion", ["linear", "log"])
def test_graph_figures_are_those_of_a_walk_over_its_nodes(recursion):
    """The serial work, the ops and the busiest recursion node's VAMPs, counted once by (section,
    group, op), are what a walk over every compute node gives."""
    from collections import Counter

    from vampc.machine.ops import SERIAL_WORK, VAMPS_PER_OP
    from vampc.report.counts import _per_node, serial_work
    c = compile_chain(random_chain(5, 2), CompileOptions(recursion=recursion))
    nodes = c.graph.compute_nodes()
    assert serial_work(c.graph) == {"mults": sum(SERIAL_WORK[nd.op][0] for nd in nodes),
                                    "adds": sum(SERIAL_WORK[nd.op][1] for nd in nodes)}
    assert summary(c)["ops"] == dict(sorted(Counter(nd.op.value for nd in nodes).items()))
    groups = Counter()
    for nd in nodes:
        groups[(nd.section, nd.group)] += VAMPS_PER_OP[nd.op]
    assert _per_node(c) == {s: max([k for (t, _), k in groups.items() if t == s], default=0)
                            for s in ("bwd", "npv", "fwd")}
    assert c.graph.compute_kinds() is not c.graph.compute_kinds()     # (a copy each time)
    assert c.graph.compute_ops() is not c.graph.compute_ops()


def test_vamp_counts_of_plain_and_unusual_vamps():
    """VAMP counts by pass and op, and control registers (per slot the paper's four and a select for
    each operand multiplexer of more than one input: until 2026-12-07 six a slot of any VAMP with
    several slots or inputs, 360 on planar2 folded where the RTL builds 282, a hardware user's
    find), counted one VAMP at a time here and compared with the bulk counts, also for a
    network with a VAMP of no slot (the allocator never makes one: counted as shared, no
    registers), one of two slots, and a folded one whose VAMPs have one, two or more inputs."""
    import dataclasses
    from collections import Counter

    import msgspec

    from vampc.kinds import Pass
    from vampc.report.counts import hardware_counts, vamp_counts
    c = compile_chain(random_chain(3, 0))

    def by_hand(c):
        sections, ops, control = Counter(), Counter(), 0
        for v in c.network.vamps:
            kinds = {Pass.of(c.graph.nodes[s.node].section) for s in v.slots}
            sections[kinds.pop() if len(kinds) == 1 else "shared"] += 1
            ops.update(s.op.value for s in v.slots)
            control += len(v.slots) * (4 + (len(v.a) > 1) + (len(v.b) > 1))
        return sections, dict(sorted(ops.items())), control

    vamps = list(c.network.vamps)
    empty = dataclasses.replace(c, network=dataclasses.replace(
        c.network, vamps=tuple(vamps[:-1] + [msgspec.structs.replace(vamps[-1], slots=())])))
    two = dataclasses.replace(c, network=dataclasses.replace(
        c.network, vamps=tuple([msgspec.structs.replace(vamps[0], slots=vamps[0].slots
                                                        + vamps[1].slots)] + vamps[1:])))
    folded = compile_chain(load_robot(EXAMPLES / "planar2.yaml"), CompileOptions(layout="folded"))
    assert {(len(v.a) > 1) + (len(v.b) > 1) for v in folded.network.vamps} == {0, 1, 2}
    assert by_hand(folded)[2] == hardware_counts(folded)["control_registers"] == 282
    for case in (c, empty, two, folded):
        sections, ops, control = by_hand(case)
        got = vamp_counts(case)
        assert [got["backward"], got["forward"], got["shared"]] == \
            [sections["backward"], sections["forward"], sections["shared"]]
        assert got["by_op"] == ops
        assert hardware_counts(case)["control_registers"] == control
    assert vamp_counts(empty)["shared"] == 1 and vamp_counts(c)["shared"] == 0


def test_long_lists_of_joint_numbers_are_cut_in_the_text(tmp_path):
    """A 4 096-joint chain's 585 prismatic joints were listed in full on five report lines of 3 500
    characters (the robot line, the paper note, a footnote, the VAMPs table's check column; a new
    user's find), where the joints line is cut: each list past twelve numbers gives the first
    eleven and how many in all (`--format json` lists every one)."""
    import json
    import re

    import yaml
    from click.testing import CliRunner

    from vampc.cli import main
    joints = [{"name": f"j{i + 1}", "type": "prismatic" if i % 3 == 0 else "revolute", "a": 0.1,
               "alpha": 0.3, "d": 0.05, "theta": 0.2, "mass": 1.0, "com": [0.01, 0, 0],
               "inertia": [0.01, 0.01, 0.01, 0, 0, 0]} for i in range(40)]
    robot = tmp_path / "p40.yaml"
    robot.write_text(yaml.safe_dump({"name": "p40", "joints": joints}))
    every = list(range(1, 41, 3))
    for recursion in ("linear", "log"):
        res = CliRunner().invoke(main, ["report", str(robot), "--recursion", recursion])
        assert res.exit_code == 0, res.output
        lists = re.findall(r"\[(\d+(?:, \d+)+)(, \.\.\. (\d+) in all)?\]", res.stdout)
        cut = [(nums, total) for nums, _, total in lists if total]
        assert cut and all(total == "14" and nums == ", ".join(map(str, every[:11]))
                           for nums, total in cut), cut
        assert all(len(nums.split(", ")) <= 12 for nums, _, _ in lists), lists
        assert f"(40 joints, prismatic [{', '.join(map(str, every[:11]))}, ... 14 in all])" in res.stdout
        rep = json.loads(CliRunner().invoke(main, ["report", str(robot), "--recursion", recursion,
                                                   "--format", "json"]).stdout)
        assert rep["prismatic_joints"] == every


ROW = ("{{name: j{k}, type: {t}, a: {a}, alpha: {alpha}, d: {d}, theta: {theta}, mass: 1.5, "
       "com: [0.01, 0.02, 0.03], inertia: [0.01, 0.02, 0.03, 0.001, 0.002, 0.001]}}")


@pytest.mark.parametrize("types", ["P", "PPP", "RPRP", "RRPRRR"])
@pytest.mark.parametrize("recursion", ["linear", "log"])
def test_prismatic_joints_on_the_path_are_sized_against_the_same_arm_revolute(types, recursion,
                                                                             tmp_path):
    """The latency's reasons give the prismatic joints' share, measured against the same arm with
    revolute joints (here a DH file of its own, compiled on its own), and together account for the
    whole difference from the paper's formula: a one-joint prismatic arm's −3 M − 10 A had been
    −1 M − 4 A of reasons and "prismatic joints (σ̄ terms)" of no size (a hardware user's find).
    (A schedule's route that waits keeps its own reason: test_report_table_o1.)"""
    from vampc.report.build import build_report

    def arm(kinds: str):
        path = tmp_path / f"{kinds}.yaml"
        rows = [ROW.format(k=k, t={"P": "prismatic", "R": "revolute"}[x], a=0.1 * k,
                           alpha=0.3 + 0.2 * k, d=0.05 * k, theta=0.2 * k)
                for k, x in enumerate(kinds, 1)]
        path.write_text("name: arm\njoints:\n" + "".join(f"  - {r}\n" for r in rows))
        return build_report(compile_chain(load_robot(str(path)), CompileOptions(recursion=recursion)))

    rep, same = arm(types), arm("R" * len(types))
    dm = rep["latency"]["mults"] - same["latency"]["mults"]
    da = rep["latency"]["adds"] - same["latency"]["adds"]
    size = ", ".join(f"{v:+d} {u}".replace("-", "−") for v, u in ((dm, "M"), (da, "A")) if v)
    notes = latency_note(rep)
    said = [n for n in notes if n.startswith("prismatic joints [")]
    assert len(said) == 1 and f"{size or 'no change'} on the path against the same arm" in said[0]
    assert not any("not explained" in n for n in notes), notes
    assert not any("not explained" in r.get("explanation", "") or "not explained" in r.get("note", "")
                   for r in rep["table_o1"]["measured"]), rep["table_o1"]["measured"]


def test_the_microcode_rom_holds_table_vii1s_micro_steps_at_twelve_bits_an_assignment():
    """The ROM a VAMP holds (section VII: "the microcode instructions needed for each item in the
    repertoire may be stored on-module in Read-Only-Memory"), counted by hand from Table VII.1's
    sequences: VA one assignment (ADDER), SV one (MULT-1), VC three (MULT-1 and MULT-2, then the
    SUBTRACTOR), and the dot sequence of MV, MTV, VD and each of MM's three columns (a ROM pointer
    each) five (MULT-1, MULT-2; ADDER, MULT-1; ADDER): 35. Each assignment is 12 bits: the unit
    written (one of 3: 2 bits), its function (mul, add, sub: 2 bits) and two operands (one of 9
    registers: 4 bits each). One copy a VAMP. Only the golden report's bytes had seen a wrong
    width here (a mutation audit's)."""
    from vampc.report.build import build_report
    c = compile_chain(load_robot(EXAMPLES / "planar2.yaml"), CompileOptions(word="q16.16"))
    rep = build_report(c)
    per_vamp = (1 + 1 + 3 + 5 * (3 + 3)) * (2 + 2 + 4 + 4)
    assert per_vamp == 420
    assert rep["word"]["rom_bits_per_vamp"] == per_vamp
    V = len(c.network.vamps)
    assert rep["word"]["rom_bits"] == rep["engineering"]["bits"]["rom_bits"] == per_vamp * V
    assert f"{per_vamp * V:,} of microcode ROM ({per_vamp} a VAMP)" in render(rep)


def test_the_time_multiplexed_line_counts_operand_inputs_host_writes_and_words_from_the_file(tmp_path):
    """The time-multiplexed line's figures, counted here from the program file alone: the widest
    operand multiplexer (operand B's, here wider than any operand A's), the host's port writes a
    torque set (each entry of a port), the program ports (a port with no entries, there only for
    Program Mode), the slots and the Program-Mode words. Only the golden report's and the
    baseline's bytes had seen these wrong (a mutation audit's: the widest taken from operand A
    alone, the host writes counted a port at a time)."""
    import json

    from click.testing import CliRunner

    from vampc.cli import main
    program = tmp_path / "p.vamp.json"
    r = CliRunner().invoke(main, ["compile", str(EXAMPLES / "planar2.yaml"), "--recursion", "log",
                                  "--layout", "folded", "--share-passes", "-o", str(program)])
    assert r.exit_code == 0, r.output
    hw = json.loads(CliRunner().invoke(main, ["report", str(program), "--format", "json"]).output)["hardware"]
    doc = json.loads(program.read_text())
    vamps, ports = doc["network"]["vamps"], doc["network"]["ports"]
    widest_b = max(len(v["b"]) for v in vamps)
    assert widest_b > max(len(v["a"]) for v in vamps)
    writes = sum(len(p["entries"]) for p in ports)
    assert writes > len(ports)              # (a port written more than once a set)
    words = sum(len(e["words"]) for e in doc["program_stream"])
    assert (hw["max_mux_inputs"], hw["host_writes_per_set"], hw["program_ports"], hw["slots"],
            hw["program_words"]) == (widest_b, writes, sum(1 for p in ports if not p["entries"]),
                                     sum(len(p["slots"]) for p in doc["programs"]), words)
    # per slot the paper's four (three delays, a ROM pointer) and a select for each operand
    # multiplexer of more than one input
    slots = {p["vamp"]: len(p["slots"]) for p in doc["programs"]}
    control = sum(slots[v["index"]] * (4 + (len(v["a"]) > 1) + (len(v["b"]) > 1)) for v in vamps)
    text = CliRunner().invoke(main, ["report", str(program)]).output
    assert f"{sum(slots.values())} slots on {len(vamps)} VAMPs (period " in text
    assert (f"; {control} control registers, {sum(len(v['a']) + len(v['b']) - 2 for v in vamps)} "
            "multiplexer inputs beyond the first "
            f"(at most {widest_b} inputs on one operand), {writes} host writes per set, {words} "
            "program words loaded in") in text
