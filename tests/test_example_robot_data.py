"""Every URDF of example-robot-data against Pinocchio (issue "Every robot Pinocchio loads"): each one
`pin.buildModelFromUrdf` loads with a movable joint compiles, fixed and floating base, both
recursions, both mimic modes where it has mimic joints; the emulator's torques pass vampc's own
--check and are within 1e-9 of Pinocchio's. Skipped, with the reason, when example-robot-data (a
130 MB download, not a test dependency) or Pinocchio is absent. benchmarks/example_robot_data.py
lists the same, robot by robot, with times."""
from __future__ import annotations

import pytest
from pinocchio_util import IMPROPER_INERTIA, check_against_pinocchio, erd_urdfs

pytest.importorskip("pinocchio")

ROBOTS = erd_urdfs()
# ur3.urdf has no link (Pinocchio refuses its missing name, vampc its missing links); there is no
# movable joint in iris_simple and quadrotor_base. Pinocchio's mimic=True model refuses alex_psyonic_hands
# (its leaders are not in the file), and so does --mimic couple.
PIN_SKIPS = {"ur3.urdf", "iris_simple.urdf", "quadrotor_base.urdf"}
COUPLE_REFUSED = {"alex_psyonic_hands.urdf"}


@pytest.mark.parametrize("floating", [False, True], ids=["fixed", "floating"])
@pytest.mark.parametrize("name", sorted(ROBOTS) or [pytest.param(None, marks=pytest.mark.skip(
    reason="example-robot-data is not installed (pip install example-robot-data)"))])
def test_every_example_robot_matches_pinocchio(name, floating):
    out = check_against_pinocchio(ROBOTS[name], floating, count=2)
    if "skip" in out:
        assert name in PIN_SKIPS, out["skip"]
        pytest.skip(out["skip"])
    assert out["accepted"] == (name in IMPROPER_INERTIA)
    assert ("couple refused" in out) == (name in COUPLE_REFUSED)
    assert {r for _, r in out["errors"]} == {"linear", "log"}
    assert out["check"] <= 1e-9
    assert max(out["errors"].values()) <= 1e-9, out["errors"]
