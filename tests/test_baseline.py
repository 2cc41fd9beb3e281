"""Outputs unchanged: program files, reports and torques are byte-identical to those of commit
4d9317d, for every example, layout and recursion (tests/baseline.py made the digests from that
commit's code; see its docstring), except the changes made on purpose since, each listed with its
reason in tests/golden/baseline-changes.json (new digests made by `python tests/baseline.py .`
and kept only where they differ).

What this guards is change, not correctness: every report digest has been remade since 4d9317d
(the changes file says why), so the report's bytes are checked only against themselves; their
figures are checked against the paper and independent counts elsewhere (test_report*,
test_readme_figures). The torque digests are still 4d9317d's but arm6's (its products no longer
left to the BLAS: test_same_bits), and the torques themselves are checked against the reference
dynamics and Pinocchio (test_emulator*, test_example_robot_data)."""
from __future__ import annotations

import json

import pytest
from baseline import CASES, outputs
from conftest import GOLDEN

WANT = json.loads((GOLDEN / "baseline-4d9317d.json").read_text())
CHANGES = json.loads((GOLDEN / "baseline-changes.json").read_text())
for _case, _digests in CHANGES["changes"].items():
    assert set(_digests) <= set(CHANGES["_why"]), f"{_case}: a change without its reason"
    WANT[_case] = {**WANT[_case], **_digests}


# (the 64-joint snake's cases, 5 s of the suite's 4 minutes, under -m slow: the run compares every
# other example's outputs, and `python tests/baseline.py` all of them)
@pytest.mark.parametrize("case", [pytest.param(c, marks=pytest.mark.slow) if c[0].startswith("snake64")
                                  else c for c in CASES], ids=[c[0] for c in CASES])
def test_outputs_as_at_4d9317d(case, monkeypatch):
    monkeypatch.setenv("VAMPC_PROGRESS", "0")
    assert outputs(case) == WANT[case[0]]
