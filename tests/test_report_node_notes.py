"""The report's "ops per node" notes name what the robot has beyond the paper's Table I.1 (a fixed-base
chain of revolute joints in DH frames): a URDF arm, a tree or a floating base was told that
"prismatic joints add the σ̄ terms" though it had none (a new user's run, thirteenth round)."""
from __future__ import annotations

import json

import pytest
from click.testing import CliRunner
from conftest import EXAMPLES

from vampc.cli import main


def _notes(robot, *args) -> dict:
    res = CliRunner().invoke(main, ["report", str(EXAMPLES / robot), "--format", "json", *args])
    assert res.exit_code == 0, res.stderr
    rows = json.loads(res.stdout)["processors"]["ops_per_node"]
    return {(r["recursion"], r["section"]): r for r in rows}


@pytest.mark.parametrize("robot, args, says", [
    ("quadruped.urdf", (), ["joint frames shifted or turned", "branches (a tree)"]),
    ("ur5.urdf", ("--floating-base",), ["a floating base"]),
    ("stanford.yaml", (), ["prismatic joints (3: σ̄ terms)"])])
def test_a_difference_is_put_down_to_what_the_robot_has(robot, args, says):
    differing = [r for r in _notes(robot, *args).values() if not r["matches"]]
    assert differing
    for r in differing:
        if robot != "stanford.yaml":
            assert "prismatic" not in r["note"], r["note"]
    assert any(all(s in r["note"] for s in says) for r in differing), [r["note"] for r in differing]


def test_the_pumas_rows_match_but_the_log_forward_one():
    notes = _notes("puma560.yaml")
    assert [k for k, r in notes.items() if not r["matches"]] == [("log", "fwd")]
    assert "robot also has" not in notes[("log", "fwd")]["note"]


@pytest.mark.parametrize("kind", ["revolute", "prismatic"])
def test_a_one_joint_log_arms_backward_rows_say_its_leaf_is_the_node(kind, tmp_path):
    """A one-joint arm's log backward pass is its leaf: the VAMP table said "see README, Layouts"
    (which says nothing of it), and of a prismatic joint "add the σ̄ terms" beside 3 VAMPs against
    the paper's 26 (a hardware user's find)."""
    path = tmp_path / "one.yaml"
    path.write_text(f"name: one\njoints:\n  - {{name: j, type: {kind}, a: 0.1, alpha: 0.3, d: 0.1, "
                    "theta: 0.2, mass: 1.0, com: [0.01, 0.02, 0.03], "
                    "inertia: [0.01, 0.02, 0.03, 0.001, 0.001, 0.001]}\n")
    res = CliRunner().invoke(main, ["report", str(path), "--recursion", "log", "--format", "json"])
    assert res.exit_code == 0, res.stderr
    variant = next(v for v in json.loads(res.stdout)["processors"]["vamps"] if v["recursion"] == "log")
    rows = {r["section"]: r for r in variant["rows"]}
    for section in ("bwd", "bwd_total"):
        row = rows[section]
        assert row["per_node"] < row["paper"]["per_node"]
        assert row["note"].endswith(f"one joint: its leaf is the only backward node, "
                                    f"{row['per_node']} VAMPs (no combining node to compare with "
                                    "the paper's)"), row["note"]


def test_a_tree_without_turned_joint_frames_is_not_said_to_take_a_vd():
    """The quadruped's joints are shifted from their parents' frames, not turned: its graph has no
    VD, and its forward row said one took τ = u·n' (VD) (a hardware user's find)."""
    res = CliRunner().invoke(main, ["report", str(EXAMPLES / "quadruped.urdf"), "--format", "json"])
    rep = json.loads(res.stdout)
    assert res.exit_code == 0 and rep["ops"] and "VD" not in rep["ops"], rep["ops"]
    variant = next(v for v in rep["processors"]["vamps"] if v["recursion"] == "linear")
    fwd = next(r for r in variant["rows"] if r["section"] == "fwd")
    assert "Y1, Y2" in fwd["note"] and "VD" not in fwd["note"], fwd["note"]


def test_a_tree_with_a_turned_joint_frame_is_said_to_take_its_vd(tmp_path):
    """One hip turning about y where its siblings turn about x: its joint frame is turned from the
    trunk's, so its torque is u·n' (a VD, in the graph) and the forward row says so."""
    text = (EXAMPLES / "quadruped.urdf").read_text()
    at = text.index('<joint name="HR_HAA"')
    end = text.index("</joint>", at)
    path = tmp_path / "turned.urdf"
    path.write_text(text[:at] + text[at:end].replace('<axis xyz="1 0 0"/>', '<axis xyz="0 1 0"/>')
                    + text[end:])
    res = CliRunner().invoke(main, ["report", str(path), "--format", "json"])
    assert res.exit_code == 0, res.stderr
    rep = json.loads(res.stdout)
    assert rep["ops"].get("VD", 0) >= 1, rep["ops"]
    variant = next(v for v in rep["processors"]["vamps"] if v["recursion"] == "linear")
    fwd = next(r for r in variant["rows"] if r["section"] == "fwd")
    assert "takes τ = u·n' (VD)" in fwd["note"], fwd["note"]
