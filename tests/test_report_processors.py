"""Processors and packages (vampc.report.processors) for a general rotary 6-joint arm: the section VI
VAMP tables reproduced for every configuration vampc compiles, each row marked as matching the
paper or differing with its reason, and section VII's packages."""
from __future__ import annotations

import pytest

from vampc.compiler import CompileOptions, compile_chain
from vampc.report.configs import configurations
from vampc.report.processors import packages, processors, vamp_pins
from vampc.robot.random import random_chain

# Section VI, "VAMPs - Totals, n = 6" and its propagated / non-propagated tables:
# (per node, tier, single device, systolic pipeline)
LINEAR = {"bwd": (12, None, 12, 72), "npv": (10, None, 10, 60), "bwd_total": (22, None, 22, 132),
          "fwd": (8, None, 8, 48)}
LOG_UNIFORM = {"bwd": (26, 78, 78, 338), "npv": (10, 20, 20, 60), "bwd_total": (36, 98, 98, 398),
               "fwd": (12, 36, 36, 156)}       # forward: paper 13, 39, 39, 169 (one T20 per node)
COLS = ("per_node", "per_tier", "single_device", "systolic")


@pytest.fixture(scope="module")
def report():
    c = compile_chain(random_chain(6, 21, prismatic_fraction=0.0), CompileOptions(recursion="log"))
    configs = configurations(c)
    return processors(configs, c.chain), packages(configs, 64), configs


def _rows(proc, recursion, leaves):
    v = next(v for v in proc["vamps"] if (v["recursion"], v["leaves"]) == (recursion, leaves))
    return v, {r["section"]: r for r in v["rows"]}


def test_linear_vamps_match_section_vi(report):
    v, rows = _rows(report[0], "linear", None)
    for sec, want in LINEAR.items():
        assert tuple(rows[sec][c] for c in COLS) == want
        assert rows[sec]["note"] == "matches the paper"
    assert v["shared_passes"] == 22 == v["paper_shared_passes"]


def test_log_vamps_with_uniform_leaves_match_except_the_forward_t20(report):
    v, rows = _rows(report[0], "log", "uniform")
    for sec, want in LOG_UNIFORM.items():
        assert tuple(rows[sec][c] for c in COLS) == want
    for sec in ("bwd", "npv", "bwd_total"):
        assert rows[sec]["note"] == "matches the paper"
    assert rows["fwd"]["paper"] == {"per_node": 13, "per_tier": 39, "single_device": 39, "systolic": 169}
    assert rows["fwd"]["note"].startswith("differs in per node, per tier, single device, systolic: "
                                          "forward node 12 VAMPs, not 13")
    assert "T20" in rows["fwd"]["note"]


def test_log_vamps_with_separate_leaves_say_why_they_differ(report):
    _, rows = _rows(report[0], "log", "separate")
    assert rows["bwd"]["systolic"] < 338
    assert "Table IV.1's leaves are cheaper" in rows["bwd"]["note"]
    assert rows["npv"]["note"] == "matches the paper"


def test_ops_per_node_against_the_papers_requirements(report):
    ops = {(r["recursion"], r["section"]): r for r in report[0]["ops_per_node"]}
    assert ops[("linear", "bwd")]["ops"] == {"MTV": 3, "VA": 5, "VC": 4}      # paper: MV 3, VA 5, VC 4
    assert all(ops[k]["matches"] for k in ops if k != ("log", "fwd"))
    fwd = ops[("log", "fwd")]
    assert (fwd["total"], fwd["paper_total"], fwd["matches"]) == (10, 11, False)
    assert fwd["note"].startswith("differs: MV 4 (paper 5)")


def test_packages_by_pin_budget(report):
    pk = report[1]
    assert pk["pins"] == [40, 64]
    rows = {r["configuration"]: r for r in pk["rows"]}
    lin = rows["linear, systolic"]["by_pins"][0]
    assert (lin["paper_separate"], lin["paper_shared"]) == (36, 15)          # 180 VAMPs: 5 and 12 each
    assert (lin["muxed_separate"], lin["muxed_shared"], lin["max_pins_per_vamp"]) == (36, 15, 8)
    folded = rows["linear, folded"]["by_pins"][0]
    assert folded["max_pins_per_vamp"] > 8 and folded["muxed_separate"] > folded["paper_separate"]
    assert pk["paper_check"]["paper"] == 11 and pk["paper_check"]["measured"] == 15
    assert pk["budget"]["vamps_per_package"]["64"] == {"separate": 8, "shared": 20}


def test_pins_of_a_vamp_count_its_multiplexer_inputs(report):
    net = next(k for k in report[2] if k.name == "linear, folded").network
    for v in net.vamps:
        inputs = len(v.a) + len(v.b)
        assert vamp_pins(v) == {"separate": 6 + inputs, "shared": 1 + inputs}


def test_vamps_by_op_kind_add_up(report):
    proc, _, configs = report
    linear = next(v for v in proc["vamps"] if v["recursion"] == "linear")["by_op"]
    assert linear["systolic"] == {"MTV": 18, "MV": 24, "SV": 6, "VA": 72, "VC": 60}
    assert sum(linear["single_device"].values()) == 30 and sum(linear["shared_passes"].values()) == 22
    log = next(v for v in proc["vamps"] if v["leaves"] == "separate")["by_op"]
    systolic = next(k for k in configs if k.name == "log, systolic")
    assert sum(log["systolic"].values()) == systolic.vamps and log["systolic"]["MM"] % 3 == 0


def _forward_and_backward_notes(chain, recursion):
    rep = processors(configurations(compile_chain(chain, CompileOptions(recursion=recursion))), chain)
    out = {}
    for variant in rep["vamps"]:
        for row in variant["rows"]:
            out[(variant["recursion"], variant["leaves"], row["section"])] = (row["per_node"],
                                                                              row["note"])
    return out


@pytest.mark.parametrize("tip", [{"tip_force": [1.0, -2.0, 5.0]}, {"tip_torque": [0.1, 0.2, 0.3]}])
def test_a_tip_loaded_leaf_n_is_said_to_be_the_busiest_forward_node(tip):
    """With uniform leaves leaf n is a whole combining node and folds in the tip load besides (its
    VAs): the busiest forward node, 14 (a force: F and N both get a VA) or 13 (a torque alone). The
    row said "forward node 12 VAMPs, not 13" beside 14, and "matches the paper" beside the 13 (a new
    user's find)."""
    from dataclasses import replace

    import numpy as np
    arm = random_chain(7, 3, prismatic_fraction=0.0)
    notes = _forward_and_backward_notes(replace(arm, **{k: np.array(v) for k, v in tip.items()}),
                                        "log")
    per, note = notes[("log", "uniform", "fwd")]
    extra = 2 if "tip_force" in tip else 1
    assert per == 12 + extra, (per, note)
    assert note.endswith(f"the busiest is leaf n, {12 + extra}: it folds in the tip load, "
                         f"{extra} VA{'s' if extra > 1 else ''} more"), note
    assert note.startswith("differs in per node" if extra == 2 else "per node as the paper's, for "
                           "another reason"), note
    per, note = notes[("log", "separate", "fwd")]          # (a leaf of its own: smaller than 12)
    assert per == 12 and "leaf n" not in note
    plain = _forward_and_backward_notes(arm, "log")[("log", "uniform", "fwd")]
    assert plain[0] == 12 and "leaf n" not in plain[1]


def test_a_trees_per_node_rows_say_why_they_differ():
    """A tree's per-node rows said "see README, Layouts" (no reason) and its log forward row
    "forward node 12 VAMPs, not 13" beside 6 (a new user's find)."""
    from conftest import EXAMPLES

    from vampc.robot import load_robot
    tree = load_robot(str(EXAMPLES / "quadruped.urdf"))
    for recursion in ("linear", "log"):
        for key, (per, note) in _forward_and_backward_notes(tree, recursion).items():
            assert "see README, Layouts" not in note and "12 VAMPs, not 13" not in note, (key, note)
            if note.startswith("differs"):
                assert "(README, Trees and floating bases)" in note, (key, note)
    notes = _forward_and_backward_notes(tree, "linear")
    assert notes[("linear", None, "bwd")][0] == 12 + 5 and "H1..H5" in notes[("linear", None, "bwd")][1]
    # (each quadruped joint has one child: not the sums, which had been said: a trees audit)
    assert "sums their f' and n'" not in notes[("linear", None, "fwd")][1]
    assert "(Y1, Y2: VC + VA)" in notes[("linear", None, "fwd")][1]
    per, note = _forward_and_backward_notes(tree, "log")[("log", "separate", "fwd")]
    assert f"its busiest node has {per} VAMPs" in note and "addition levels" in note


def test_a_one_joint_arm_and_a_floating_chain_say_why_their_nodes_differ():
    """One joint has no combining node: its log forward row said "forward node 12 VAMPs, not 13"
    beside 4 (6 with a tip force); a floating serial chain's rows said "see README, Layouts" or
    "a tree's forward pass" (a review's finds)."""
    from dataclasses import replace

    import numpy as np
    one = replace(random_chain(1, 3, prismatic_fraction=0.0), tip_force=np.array([0.0, 0.0, -5.0]))
    for (rec, leaves, sec), (per, note) in _forward_and_backward_notes(one, "log").items():
        if rec == "log" and sec == "fwd":
            assert note == ("differs in per node: one joint: its leaf is the only forward node, "
                            f"{per} VAMPs (no combining node to compare with the paper's)"), note
    floating = replace(random_chain(4, 3, prismatic_fraction=0.0), floating=True)
    for recursion in ("linear", "log"):
        for key, (per, note) in _forward_and_backward_notes(floating, recursion).items():
            assert "see README, Layouts" not in note and "12 VAMPs, not 13" not in note, (key, note)
            assert "a tree's forward" not in note, (key, note)


@pytest.mark.parametrize("rotating", [False, True])
def test_a_one_joint_arms_ops_rows_say_each_pass_is_a_leaf(rotating):
    """One joint on a still base: the log backward pass is joint 1's leaf alone (8 ops against a
    combining node's 24), and its ops row said "the robot is a fixed-base chain of revolute joints
    in DH frames, as the paper's, so this is not explained"; its forward row put 4 ops against 11
    down to the missing T20 alone. On a rotating base the backward pass has a combining node (leaf 0
    joined to leaf 1) and matches; the forward pass is still a leaf."""
    from dataclasses import replace

    import numpy as np
    one = random_chain(1, 3, prismatic_fraction=0.0)
    if rotating:
        one = replace(one, base_omega=np.array([0.1, 0.2, 0.3]))
    rep = processors(configurations(compile_chain(one, CompileOptions(recursion="log"))), one)
    rows = {(r["recursion"], r["section"]): r for r in rep["ops_per_node"]}
    bwd, fwd = rows[("log", "bwd")], rows[("log", "fwd")]
    leaf = "one joint: this pass is its leaf alone (Table IV.1's a = b form)"
    assert fwd["total"] == 4 and leaf in fwd["note"] and "T20" not in fwd["note"], fwd
    if rotating:
        assert bwd["matches"] and bwd["total"] == 24, bwd
    else:
        assert bwd["total"] == 8 and "MM" not in bwd["ops"], bwd
        assert leaf in bwd["note"] and "not explained" not in bwd["note"], bwd
    for r in rep["ops_per_node"]:
        assert "not explained" not in r["note"], r


def test_a_prismatic_joints_rows_give_the_sigma_terms_and_its_log_forward_node_is_the_rotary_one():
    """The Stanford arm's linear rows (14 [12]) said "see README, Layouts"; its log forward node,
    the Puma's ops exactly (T20 alone), was said to differ for its prismatic joint too; the notes
    called the paper's Table I.1 revolute-only, which has translational joints (a check against the
    paper)."""
    from conftest import EXAMPLES

    from vampc.robot import load_robot
    stanford = load_robot(str(EXAMPLES / "stanford.yaml"))
    assert [i for i, j in enumerate(stanford.joints, 1) if j.sigma == 0] == [3]
    c = compile_chain(stanford, CompileOptions(recursion="log"))
    rep = processors(configurations(c), stanford)
    for variant in rep["vamps"]:
        for row in variant["rows"]:
            assert "see README, Layouts" not in row["note"], row
    linear = next(v for v in rep["vamps"] if v["recursion"] == "linear")
    bwd = next(r for r in linear["rows"] if r["section"] == "bwd")
    assert bwd["per_node"] == 14 and "prismatic joints [3] add the σ̄ terms" in bwd["note"], bwd
    log_fwd = next(r for r in rep["ops_per_node"] if (r["recursion"], r["section"]) == ("log", "fwd"))
    assert "no T20" in log_fwd["note"] and "prismatic" not in log_fwd["note"], log_fwd
    assert all("Table I.1 (a" not in r["note"] for r in rep["ops_per_node"]), rep["ops_per_node"]


def test_the_stanford_arms_packages_note_accounts_for_all_its_extra_packages():
    """Section VII's 11 packages of 12 for the linear n = 6 pipeline cover a rotary arm's 132
    backward VAMPs: the Stanford arm's 16 were put down to its forward 48 alone (4 more, so 15), its
    prismatic joint's 2 backward VAMPs unsaid (a check against the paper)."""
    import math

    from conftest import EXAMPLES

    from vampc.report.processors import packages
    from vampc.robot import load_robot
    stanford = load_robot(str(EXAMPLES / "stanford.yaml"))
    configs = configurations(compile_chain(stanford))
    check = packages(configs, None, stanford)["paper_check"]
    assert check["vamps"] == 134 + 48 and check["measured"] == math.ceil(182 / 12) == 16
    assert "the backward recursion has 134 (+2: prismatic joints (3: σ̄ terms)) and the forward 48: " \
        "⌈182 / 12⌉ = 16" in check["note"], check["note"]
    puma = load_robot(str(EXAMPLES / "puma560.yaml"))
    note = packages(configurations(compile_chain(puma)), None, puma)["paper_check"]["note"]
    assert note.endswith("equals the backward recursion's VAMPs, so it seems to count those alone (its "
                         "forward 48 need 4 more)"), note


def test_a_folded_all_revolute_arm_is_not_told_of_prismatic_joints():
    """The folded layout's single-device note said "prismatic joints add VAMPs for their σ̄ terms"
    of every robot, the Puma's all-revolute arm too (a new user's find); it names the robot's
    prismatic joints where it has some."""
    from click.testing import CliRunner
    from conftest import EXAMPLES

    from vampc.cli import main
    puma = CliRunner().invoke(main, ["report", str(EXAMPLES / "puma560.yaml"), "--layout", "folded"])
    note = next(x for x in puma.output.splitlines() if "single device (section VI" in x)
    assert note.endswith("paper 22 + 8 for a general rotary arm") and "σ̄" not in note, note
    stanford = CliRunner().invoke(main, ["report", str(EXAMPLES / "stanford.yaml"), "--layout", "folded"])
    assert "prismatic joints [3] add VAMPs for their σ̄ terms" in stanford.output


@pytest.mark.parametrize("recursion, want", [("linear", (2, 2)), ("log", (84, 64))])
def test_the_vamps_no_torque_needs_are_said_beside_the_vamp_count(tmp_path, recursion, want):
    """A log chain's network carries the prefix's W, Q, R, S of every X_{0,b} and W, R of every
    final suffix (the paper's nodes kept whole), which no torque reads: 101 of a 7-joint arm's 486
    VAMPs, said only in the error-correction section (a new user's find). Counted here from the
    program file alone: the ops no output depends on (walking back from the outputs), and the
    VAMPs all of whose slots are such ops."""
    import json

    from click.testing import CliRunner
    from conftest import EXAMPLES

    from vampc.cli import main
    prog = tmp_path / "p.vamp.json"
    assert CliRunner().invoke(main, ["compile", str(EXAMPLES / "puma560.yaml"), "--recursion", recursion,
                                     "-o", str(prog)]).exit_code == 0
    doc = json.loads(prog.read_text())
    nodes = doc["graph"]["nodes"]
    live = {node for _joint, node, _component in doc["graph"]["outputs"]}
    for nd in reversed(nodes):
        if nd["id"] in live:
            live.update(nd["args"])
    dead = {nd["id"] for nd in nodes if nd["op"] not in ("INPUT", "CONST") and nd["id"] not in live}
    idle = sum(all(s["node"] in dead for s in p["slots"]) for p in doc["programs"])
    assert (idle, len(dead)) == want
    names: dict = {}
    for i in dead:
        names[nodes[i]["name"]] = names.get(nodes[i]["name"], 0) + 1
    rep = json.loads(CliRunner().invoke(main, ["report", str(prog), "--format", "json"]).output)
    assert rep["vamps"]["unused"] == {"vamps": idle, "ops": len(dead), "names": names}
    text = CliRunner().invoke(main, ["report", str(prog)]).output
    line = next(x for x in text.splitlines() if x.startswith("  unused"))
    assert f"{idle} VAMPs run only those: {len(dead)} ops compute values no torque reads" in line
    # (each name the graph gives them, with its count: a fixed list had named only some)
    assert all(f"{name} {k}" in line for name, k in names.items()), line
    assert line.endswith(f"the torques need {rep['vamps']['total'] - idle}"), line


def test_a_trees_forward_node_is_explained_by_what_it_runs():
    """The quadruped's busiest linear forward node (11 VAMPs against the paper's 8) was put down to
    'a joint with several children sums their f' and n'', though each of its joints has one child,
    and its unused Y1, Y2 were said kept 'as the paper's nodes have them' (a trees audit): the
    sums are said only of a robot with such a joint, the shifts always, the axis (a VD) only of a
    joint frame turned from its parent's, and Y1, Y2 as a tree's own ops."""
    from click.testing import CliRunner
    from conftest import EXAMPLES

    from vampc.cli import main
    quad = CliRunner().invoke(main, ["report", str(EXAMPLES / "quadruped.urdf")]).output
    # (11 VAMPs until 2026-12-07, when a joint frame not turned from its parent's lost its VD)
    forward = next(x for x in quad.splitlines() if x.startswith("forward ") and "10 [8]" in x)
    # (and its VD, said until a hardware user found the graph had none: no joint frame is turned)
    assert "several children" not in forward and "(Y1, Y2: VC + VA)" in forward and "VD" not in forward
    assert "kept as the nodes are built (the paper's whole, and a tree's Y1, Y2 at each shifted " \
        "child)" in quad
    from vampc.robot import load_robot
    robot = load_robot(EXAMPLES / "quadruped.urdf")
    assert all(sum(1 for p in robot.parent_of if p == j) <= 1 for j in range(1, robot.n + 1))
    puma = CliRunner().invoke(main, ["report", str(EXAMPLES / "puma560.yaml")]).output
    assert "kept as the paper's nodes have them" in puma


def test_a_joint_with_two_children_is_said_to_sum_them(tmp_path):
    """A tree whose joint carries two branches: its forward node sums their f' and n', said."""
    from click.testing import CliRunner

    from vampc.cli import main
    inertial = ('<inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" '
                'ixz="0" iyz="0"/></inertial>')
    links = "".join(f'<link name="{n}">{inertial}</link>' for n in ("base", "hub", "a", "b"))
    joints = "".join(f'<joint name="j{n}" type="revolute"><parent link="{p}"/><child link="{n}"/>'
                     '<origin xyz="0 0 0.1"/><axis xyz="0 0 1"/>'
                     '<limit lower="-1" upper="1" effort="10" velocity="2"/></joint>'
                     for n, p in (("hub", "base"), ("a", "hub"), ("b", "hub")))
    path = tmp_path / "fork.urdf"
    path.write_text(f'<robot name="fork">{links}{joints}</robot>')
    text = CliRunner().invoke(main, ["report", str(path)]).output
    forward = next(x for x in text.splitlines() if x.startswith("forward ") and "differs" in x)
    assert "a joint with several children sums their f' and n' (VA trees)" in forward, forward
