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
