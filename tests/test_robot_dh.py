"""DH-table loader: examples against textbook DH kinematics, the Joint mapping, and exact error messages."""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
import yaml
from errors_util import assert_error
from frames_util import chain_frames
from hypothesis import given, settings
from hypothesis import strategies as st

from vampc.errors import VampcError
from vampc.robot import JointType, chain_from_dh, load_dh, load_robot
from vampc.robot import dh as dh_loader

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
DH_EXAMPLES = ["planar2.yaml", "puma560.yaml", "stanford.yaml", "snake64.yaml"]


# --- an independent textbook DH forward kinematics -----------------------------------------------------

def dh_transform(theta: float, d: float, a: float, alpha: float) -> np.ndarray:
    """Standard DH link transform Rz(θ) Tz(d) Tx(a) Rx(α), written out as in Spong/Craig tables."""
    ct, st_, ca, sa = math.cos(theta), math.sin(theta), math.cos(alpha), math.sin(alpha)
    return np.array([[ct, -st_ * ca, st_ * sa, a * ct],
                     [st_, ct * ca, -ct * sa, a * st_],
                     [0.0, sa, ca, d],
                     [0.0, 0.0, 0.0, 1.0]])


def textbook_frames(rows: list[dict], q: np.ndarray) -> list[np.ndarray]:
    """Base-frame poses of O_1..O_n straight from the table rows (q added to θ or d)."""
    out, pose = [], np.eye(4)
    for row, qi in zip(rows, q):
        revolute = row["type"] == "revolute"
        theta = row["theta"] + (qi if revolute else 0.0)
        d = row["d"] + (0.0 if revolute else qi)
        pose = pose @ dh_transform(theta, d, row["a"], row["alpha"])
        out.append(pose)
    return out


# --- the examples ----------------------------------------------------------------------------------------

@pytest.mark.parametrize("name", DH_EXAMPLES)
def test_examples_load_and_verify(name):
    chain = load_robot(EXAMPLES / name)
    chain.verify()
    assert chain.source == str(EXAMPLES / name)
    assert chain.n == len(yaml.safe_load((EXAMPLES / name).read_text())["joints"])


@pytest.mark.parametrize("name", ["puma560.yaml", "stanford.yaml", "planar2.yaml"])
def test_frames_match_textbook_dh(name):
    rows = yaml.safe_load((EXAMPLES / name).read_text())["joints"]
    chain = load_dh(EXAMPLES / name)
    rng = np.random.default_rng(1)
    for q in rng.uniform(-np.pi, np.pi, (20, chain.n)):
        for ours, theirs in zip(chain_frames(chain, q), textbook_frames(rows, q)):
            np.testing.assert_allclose(ours, theirs, atol=1e-12)


def test_puma_published_zero_pose():
    # Corke, Robotics, Vision and Control: p560.fkine(qz) has the identity rotation and t = (0.4521,
    # -0.15005, 0.4318): a2 + a3 forward, -d3 sideways, d4 up.
    tip = chain_frames(load_dh(EXAMPLES / "puma560.yaml"), np.zeros(6))[-1]
    np.testing.assert_allclose(tip[:3, :3], np.eye(3), atol=1e-12)
    np.testing.assert_allclose(tip[:3, 3], [0.4521, -0.15005, 0.4318], atol=1e-12)


def test_puma_published_inertial_values():
    chain = load_dh(EXAMPLES / "puma560.yaml")
    np.testing.assert_allclose([j.mass for j in chain.joints], [0, 17.4, 4.8, 0.82, 0.34, 0.09])
    np.testing.assert_allclose(chain.joints[1].com, [-0.3638, 0.006, 0.2275])
    np.testing.assert_allclose(np.diag(chain.joints[2].inertia), [0.066, 0.086, 0.0125])
    assert chain.joints[1].limits.q == pytest.approx((-math.pi / 4, 5 * math.pi / 4))


def test_stanford_has_one_prismatic_joint():
    chain = load_dh(EXAMPLES / "stanford.yaml")
    assert [j.type for j in chain.joints].count(JointType.PRISMATIC) == 1
    assert chain.joints[2].type is JointType.PRISMATIC
    assert chain.joints[2].limits.q == pytest.approx((12 * 0.0254, 50 * 0.0254))


def test_snake_is_regenerated_exactly(tmp_path):
    import subprocess
    import sys
    out = subprocess.run([sys.executable, str(EXAMPLES / "make_snake.py"), "64"], check=True,
                         capture_output=True, text=True).stdout
    assert out == (EXAMPLES / "snake64.yaml").read_text()
    chain = load_dh(EXAMPLES / "snake64.yaml")
    assert chain.n == 64 and all(j.type is JointType.REVOLUTE for j in chain.joints)
    assert all(abs(j.inertia[0, 1]) > 0 for j in chain.joints)  # general: products of inertia present


# --- the mapping onto Joint ------------------------------------------------------------------------------

def row(**over) -> dict:
    """A valid joint row; keyword arguments replace fields."""
    base = {"type": "revolute", "a": 0.3, "alpha": 0.4, "d": 0.1, "theta": 0.2, "mass": 1.0,
            "com": [0.1, 0.0, 0.0], "inertia": [0.01, 0.02, 0.03, 0.0, 0.0, 0.0]}
    base.update(over)
    return base


finite = st.floats(-3.0, 3.0, allow_nan=False)


@settings(max_examples=60, deadline=None)
@given(kind=st.sampled_from(["revolute", "prismatic"]), a=finite, alpha=finite, d=finite, theta=finite,
       q=finite)
def test_single_row_equals_dh_formula(kind, a, alpha, d, theta, q):
    chain = chain_from_dh({"name": "one", "joints": [row(type=kind, a=a, alpha=alpha, d=d, theta=theta)]},
                          "<test>")
    (ours,) = chain_frames(chain, [q])
    (theirs,) = textbook_frames([row(type=kind, a=a, alpha=alpha, d=d, theta=theta)], [q])
    np.testing.assert_allclose(ours, theirs, atol=1e-12)
    if kind == "revolute":  # p* = [a, d sin α, d cos α], the paper's formula, in O_i
        np.testing.assert_allclose(chain.joints[0].p_star(q), [a, d * math.sin(alpha), d * math.cos(alpha)],
                                   atol=1e-12)


def test_inertia_six_numbers_equal_matrix():
    six = [1.0, 2.0, 3.0, 0.1, 0.2, 0.3]  # ixx iyy izz ixy iyz ixz
    matrix = [[1.0, 0.1, 0.3], [0.1, 2.0, 0.2], [0.3, 0.2, 3.0]]
    a = chain_from_dh({"name": "x", "joints": [row(inertia=six)]}, "<a>")
    b = chain_from_dh({"name": "x", "joints": [row(inertia=matrix)]}, "<b>")
    np.testing.assert_array_equal(a.joints[0].inertia, np.array(matrix))
    np.testing.assert_array_equal(b.joints[0].inertia, np.array(matrix))


def test_defaults_and_endpoints():
    doc = {"name": "x", "joints": [row(), row(type="prismatic", name="slide")]}
    chain = chain_from_dh(doc, "<t>")
    assert [j.name for j in chain.joints] == ["j1", "slide"]
    np.testing.assert_array_equal(chain.gravity, [0, 0, -9.81])
    np.testing.assert_array_equal(chain.tip_force, [0, 0, 0])
    assert chain.joints[0].offset == 0.2 and chain.joints[1].offset == 0.1
    doc.update(gravity=[1, 2, 3], base={"omega": [0, 0, 1], "omega_dot": [0, 1, 0]},
               tip={"force": [1, 0, 0], "torque": [0, 0, 2]})
    chain = chain_from_dh(doc, "<t>")
    np.testing.assert_array_equal(chain.base_omega, [0, 0, 1])
    np.testing.assert_array_equal(chain.base_omega_dot, [0, 1, 0])
    np.testing.assert_array_equal(chain.tip_torque, [0, 0, 2])
    np.testing.assert_array_equal(chain.base_accel, [-1, -2, -3])


def test_json_and_yaml_agree(tmp_path):
    doc = yaml.safe_load((EXAMPLES / "stanford.yaml").read_text())
    (tmp_path / "s.json").write_text(json.dumps(doc))
    a, b = load_dh(EXAMPLES / "stanford.yaml"), load_robot(tmp_path / "s.json")
    for ja, jb in zip(a.joints, b.joints):
        np.testing.assert_array_equal(ja.phi, jb.phi)
        np.testing.assert_array_equal(ja.inertia, jb.inertia)


def test_yaml_anchors_are_allowed(tmp_path):
    text = yaml.safe_dump({"name": "x", "joints": [row(), row()]}).replace(
        "inertia:\n  - 0.01", "inertia: &I\n  - 0.01", 1)
    text = text.replace("inertia:\n  - 0.01\n  - 0.02\n  - 0.03\n  - 0.0\n  - 0.0\n  - 0.0", "inertia: *I")
    assert "*I" in text and "&I" in text
    (tmp_path / "r.yaml").write_text(text)
    chain = load_dh(tmp_path / "r.yaml")
    np.testing.assert_array_equal(chain.joints[0].inertia, chain.joints[1].inertia)


def test_exponent_without_dot_is_a_number(tmp_path):
    text = yaml.safe_dump({"name": "x", "joints": [row()]}).replace("0.01", "1e-2")
    assert "1e-2" in text
    (tmp_path / "r.yaml").write_text(text)
    assert load_dh(tmp_path / "r.yaml").joints[0].inertia[0, 0] == 0.01


# --- errors: one line, the file, the place ------------------------------------------------------------

def doc_with(**joint_over) -> dict:
    return {"name": "bad", "joints": [row(), row(**joint_over), row()]}


YAML_ERRORS = [
    ("name: [1, 2\n", r"line 2: not valid YAML: .+"),
    ("- just\n- a list\n", r'\["just","a list"\] is not of type "object"'),
    ("tau_a,tau_b\n1,2\n", r"this is not a DH table: it reads as a CSV table \(a trajectory, "
                            r"torques or limits\?\), where a DH table is a mapping .+"),
    ("42\n", r"this is not a DH table: it reads as one value, .+"),
    ("", r"the robot file is empty .+"),
    ("name: x\njoints: []\n", r"joints: \[\] has less than 1 item"),
    ("!!python/object/apply:os.system ['echo hi']\n",
     r"line 1: a value tagged !!python/object/apply:os\.system is not read: write it untagged"),
    ("name: x\nname: y\njoints: []\n", r"line 2: not valid YAML: duplicate key 'name'"),
    ("a: &a [1, *a]\nname: x\njoints: [*a]\n", r"a YAML alias refers to itself"),
    # a key YAML reads as no text is named (the whole mapping had been quoted, the key not named)
    ("name: x\n1: 2\njoints: []\n", r"the key 1 is read as a number, not a name \(quote it: "
                                      r"keys are text\)$"),
    ("name: x\n~: 2\njoints: []\n", r"the key null is read as null, not a name \(quote it: keys are text\)"),
    ("name: x\njoints:\n  - {yes: 3}\n",
     r"joints\[0\] \(joint 1\): the key true is read as a truth value, not a name \(quote it: "
     r"keys are text\)"),
    # "Billion laughs" in YAML: nine levels of nine aliases, 9^9 values once expanded.
    ("l0: &l0 [1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0]\n"
     + "".join(f"l{k}: &l{k} [{', '.join([f'*l{k - 1}'] * 9)}]\n" for k in range(1, 9))
     + "name: x\njoints: *l8\n",
     r"too large: \d{9} values once YAML aliases are expanded \(at most 16252922\)"),
]


@pytest.mark.parametrize("text, message", YAML_ERRORS)
def test_yaml_errors(tmp_path, text, message):
    path = tmp_path / "r.yaml"
    path.write_text(text)
    assert_error(lambda: load_robot(path), path, message)


DOC_ERRORS = [
    (doc_with(mass=-1.0), r"joints\[1\]\.mass \(joint 2\): -1\.0 is less than the minimum of 0"),
    (doc_with(mass="heavy"), r'joints\[1\]\.mass \(joint 2\): "heavy" is not of type "number"'),
    (doc_with(type="helical"), r'joints\[1\]\.type \(joint 2\): "helical" is not one of .+'),
    (doc_with(com=[0.0, float("nan"), 0.0]),
     r"joints\[1\]\.com\[1\] \(joint 2\): nan is not a finite number"),
    (doc_with(inertia=[1.0, 1.0, float("inf"), 0, 0, 0]),
     r"joints\[1\]\.inertia\[2\] \(joint 2\): inf is not a finite number"),
    (doc_with(inertia=[1.0, 1.0, 1.0, 2.0, 0.0, 0.0]),
     r"joints\[1\]\.inertia \(joint 2\): inertia is not positive semi-definite \(eigenvalues -1, 1, 3\)"),
    (doc_with(inertia=[[1, 0, 0], [0.5, 1, 0], [0, 0, 1]]),
     r"joints\[1\]\.inertia \(joint 2\): inertia is not symmetric"),
    (doc_with(inertia=[1, 2, 3]), r"joints\[1\]\.inertia \(joint 2\): \[1, 2, 3\] is neither a 3x3 matrix "
                                  r"nor six numbers \[ixx, iyy, izz, ixy, iyz, ixz\]"),
    (doc_with(masss=1.0),
     r"joints\[1\] \(joint 2\): Additional properties are not allowed \('masss' was unexpected\)"),
    ({"name": "bad", "joints": [row(), {k: v for k, v in row().items() if k != "d"}]},
     r'joints\[1\] \(joint 2\): "d" is a required property'),
    (doc_with(limits={"q": [1.0, -1.0]}),
     r"joints\[1\]\.limits\.q \(joint 2\): lower limit 1\.0 is above upper limit -1\.0"),
    (doc_with(name="j1"), r"joints\[1\]\.name \(joint 2\): duplicate joint name 'j1'"),
    ({"name": "bad", "gravity": [0, 0, float("-inf")], "joints": [row()]},
     r"gravity\[2\]: -inf is not a finite number"),
    ({"name": "bad", "gravity": [0, 0], "joints": [row()]}, r"gravity: \[0,0\] has less than 3 items"),
    ({"joints": [row()]}, r'"name" is a required property'),
    ({"name": "bad", "joints": [row()], "tip": {"force": [0, 0, 0], "wrench": 1}},
     r"tip: Additional properties are not allowed \('wrench' was unexpected\)"),
]


@pytest.mark.parametrize("doc, message", DOC_ERRORS)
def test_document_errors(tmp_path, doc, message):
    path = tmp_path / "r.yaml"
    path.write_text(yaml.safe_dump(doc))
    assert_error(lambda: load_dh(path), path, message)
    assert_error(lambda: chain_from_dh(doc, "mem.yaml"), "mem.yaml", message)


def test_json_errors(tmp_path):
    path = tmp_path / "r.json"
    path.write_text('{"name": "x", "joints": [}')
    assert_error(lambda: load_robot(path), path, r"not valid JSON: invalid character \(line 1, column 26\)")
    path.write_text('{"name": "x", "name": "y", "joints": []}')
    assert_error(lambda: load_robot(path), path, r"line 1: not valid JSON: duplicate key 'name'")
    path.write_text(json.dumps({"name": "x", "joints": [row(mass=float("nan"))]}))  # json writes NaN
    assert_error(lambda: load_robot(path), path, r"not valid JSON: NaN is not allowed \(line 1, column \d+\)")


def test_file_errors(tmp_path):
    assert_error(lambda: load_robot(tmp_path / "absent.yaml"), tmp_path / "absent.yaml", "no such file")
    odd = tmp_path / "robot.txt"
    odd.write_text("x")
    assert_error(lambda: load_robot(odd), odd, r"unknown robot file extension '\.txt' \(expected .+\)")
    assert_error(lambda: load_dh(odd), odd, r"unknown DH table extension '\.txt' \(expected .+\)")
    binary = tmp_path / "b.yaml"
    binary.write_bytes(b"name: \xff\xfe\n")
    assert_error(lambda: load_robot(binary), binary, r"not UTF-8 text \(byte 6\)")
    assert_error(lambda: load_robot(EXAMPLES / "planar2.yaml", tip="x"), EXAMPLES / "planar2.yaml",
                 r"base, tip, lock, mimic and accept_improper_inertia apply to URDF and MJCF "
                 r"files only \(a DH table is read whole\)")


PUMA_TABLE = yaml.safe_load((EXAMPLES / "puma560.yaml").read_text())


# --- size limits, and loading in O(n) -------------------------------------------------------------------

FULL_ROW = row(name="j1", inertia=[[0.01, 0, 0], [0, 0.02, 0], [0, 0, 0.03]],
               limits={"q": [-1.0, 1.0], "qd": 2.0, "tau": 3.0})
FULL_TABLE = {"name": "full", "gravity": [0, 0, -9.81], "base": {"omega": [0, 0, 0], "omega_dot": [0, 0, 0]},
              "tip": {"force": [0, 0, 0], "torque": [0, 0, 0]}, "joints": [FULL_ROW]}


def test_max_joints_is_what_the_smallest_network_can_number():
    # The linear network of an all-prismatic chain has 32 VAMPs a joint (30 a revolute one); VAMP numbers
    # go up to 2^24 - 1. The log network has more, so it meets the limit sooner (near 50 000 joints).
    from vampc.compiler import CompileOptions, compile_chain
    chain = chain_from_dh({"name": "p", "joints": [row(type="prismatic"), row(type="prismatic")]}, "<t>")
    per_joint = len(compile_chain(chain, CompileOptions(recursion="linear")).network.vamps) / chain.n
    assert per_joint == 32
    assert dh_loader.MAX_JOINTS * per_joint <= 2**24 - 1 < (dh_loader.MAX_JOINTS + 1) * per_joint


def test_every_table_within_the_joint_limit_is_within_the_value_limit(tmp_path, monkeypatch):
    # A row with every field holds ROW_VALUES values, the rest of a table at most TABLE_VALUES: so a table
    # of MAX_JOINTS such rows is exactly MAX_VALUES values.
    assert dh_loader.MAX_VALUES == dh_loader.ROW_VALUES * dh_loader.MAX_JOINTS + dh_loader.TABLE_VALUES
    budget = dh_loader.ROW_VALUES + dh_loader.TABLE_VALUES
    monkeypatch.setattr(dh_loader, "MAX_VALUES", budget)
    assert chain_from_dh(FULL_TABLE, "full.json").n == 1
    monkeypatch.setattr(dh_loader, "MAX_VALUES", budget - 1)
    assert_error(lambda: chain_from_dh(FULL_TABLE, "full.json"), "full.json",
                 rf"too large: {budget} values \(at most {budget - 1}\)")


def test_too_many_joints(tmp_path, monkeypatch):
    monkeypatch.setattr(dh_loader, "MAX_JOINTS", 2)
    path = tmp_path / "r.json"
    path.write_text(json.dumps(doc_with()))
    assert_error(lambda: load_robot(path), path,
                 r"too many joints: 3 \(at most 2: VAMP numbers have 24 bits and the smallest network, "
                 r"the linear one, has up to 32 VAMPs a joint\)")


@pytest.mark.parametrize("suffix", [".json", ".yaml"])
def test_too_large_without_aliases_does_not_mention_them(tmp_path, monkeypatch, suffix):
    monkeypatch.setattr(dh_loader, "MAX_VALUES", 50)
    path = tmp_path / f"r{suffix}"
    path.write_text(json.dumps(doc_with()) if suffix == ".json" else yaml.safe_dump(doc_with()))
    assert_error(lambda: load_robot(path), path, r"too large: 57 values \(at most 50\)")


def test_too_large_once_aliases_are_expanded(tmp_path, monkeypatch):
    # 24 values written (an alias counts once), 75 once the three aliases of the row are expanded.
    monkeypatch.setattr(dh_loader, "MAX_VALUES", 60)
    path = tmp_path / "r.yaml"
    path.write_text("name: x\nrows: &r {type: revolute, a: 0.3, alpha: 0.4, d: 0.1, theta: 0.2, mass: 1.0,\n"
                    "  com: [0.1, 0.0, 0.0], inertia: [0.01, 0.02, 0.03, 0.0, 0.0, 0.0]}\n"
                    "joints: [*r, *r, *r]\n")
    assert_error(lambda: load_robot(path), path, r"too large: 75 values once YAML aliases are expanded "
                                                 r"\(at most 60\)")


def snake(n: int) -> dict:
    """The n-joint snake of examples/make_snake.py as a document."""
    import importlib.util
    spec = importlib.util.spec_from_file_location("make_snake", EXAMPLES / "make_snake.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    rows = [{**module.joint(i, n), "type": "revolute"} for i in range(1, n + 1)]
    return {"name": f"snake{n}", "joints": rows}


def test_loading_is_linear():
    """Ten times the joints run the loader's lines fewer than 15 times as often (10 for O(n), 14 for
    O(n log n), 100 for O(n²)). The times are in benchmarks/load_robot.py."""
    from test_robot_urdf import executed_lines
    docs = [snake(n) for n in (200, 2000)]
    assert chain_from_dh(docs[1], "big.json").n == 2000
    lines = [executed_lines(dh_loader, lambda doc=doc: chain_from_dh(doc, "t.json")) for doc in docs]
    assert lines[1] < 15 * lines[0], lines


ONE_JOINT = ("name: y1\njoints:\n  - {{type: revolute, a: {a}, alpha: 0, d: 0.1, theta: 0, mass: 1.0, "
             "com: [0, 0, 0], inertia: [0.1, 0.1, 0.1, 0, 0, 0]}}\n")


@pytest.mark.parametrize("written, read", [("1:30", 90), ("010", 8), ("1_0", 10), ("0x10", 16),
                                           ("1_0.5", 10.5), ("1:30.0", 90.0)])
def test_a_number_yaml_11_reads_otherwise_is_refused(tmp_path, written, read):
    """PyYAML reads YAML 1.1: 'a: 1:30' was 90 m (base 60), 'd: 010' 8 (octal), 'mass: 1_0' 10, and
    the robot was built with those values without a word (a new user's run)."""
    path = tmp_path / "y1.yaml"
    path.write_text(ONE_JOINT.format(a=written))
    with pytest.raises(VampcError) as info:
        load_robot(path)
    assert f"y1.yaml: line 3: '{written}' is a number YAML 1.1 reads as {read!r} (base 60, octal, " \
           "hexadecimal or an underscore); write it in decimal digits" in str(info.value)


@pytest.mark.parametrize("written, said", [("0x10", "the number 16"), ("010", "the number 8"),
                                           ("5", "the number 5"), ("1.5", "the number 1.5"),
                                           ("yes", "the truth value True"), ("~", "null")])
@pytest.mark.parametrize("where", ["robot", "row"])
def test_a_name_yaml_reads_as_no_text_is_refused_as_written(tmp_path, written, said, where):
    """`name: 0x10` was refused as "name: 16 is not of type string", what YAML made of it and no
    line (an audit's): the line, the name as written and what it is read as. Quoted, it is a name."""
    text = (ONE_JOINT.replace("name: y1", f"name: {written}") if where == "robot" else
            ONE_JOINT.replace("- {{type", f"- {{{{name: {written}, type"))
    path = tmp_path / "y1.yaml"
    path.write_text(text.format(a="0.5"))
    with pytest.raises(VampcError) as info:
        load_robot(path)
    line = 1 if where == "robot" else 3
    assert str(info.value) == (f"{path}: line {line}: name {written!r} is read as {said}; a name is "
                               "text: quote it")
    path.write_text(text.replace(f"name: {written}", f"name: '{written}'").format(a="0.5"))
    robot = load_robot(path)
    assert (robot.name if where == "robot" else robot.joints[0].name) == written


def test_an_empty_name_is_said_empty_and_a_name_where_none_belongs_unexpected(tmp_path):
    """`name:` was said "read as null"; a name in `limits` (no such key) was told to be quoted, and
    then refused as unexpected (a review's): the check is of the robot's and the rows' names."""
    path = tmp_path / "y1.yaml"
    path.write_text(ONE_JOINT.replace("name: y1", "name:").format(a="0.5"))
    with pytest.raises(VampcError) as info:
        load_robot(path)
    assert str(info.value) == f"{path}: line 1: the name is empty: give it as text"
    path.write_text(ONE_JOINT.replace("theta: 0,", "theta: 0, limits: {{name: 5}},").format(a="0.5"))
    with pytest.raises(VampcError) as info:
        load_robot(path)
    assert "quote it" not in str(info.value) and "'name' was unexpected" in str(info.value)


@pytest.mark.parametrize("written, value", [("0.5", 0.5), ("5", 5.0), ("-0", 0.0), ("1e-1", 0.1),
                                            ("2.", 2.0), ("1.5E+0", 1.5), ("0", 0.0), ("+5", 5.0),
                                            ("01", 1.0)])
def test_plain_numbers_are_read_as_written(tmp_path, written, value):
    path = tmp_path / "y1.yaml"
    path.write_text(ONE_JOINT.format(a=written))
    assert load_robot(path).joints[0].p_fixed[0] == value            # (alpha 0: p* = (a, 0, d))


def test_annotations_are_free_whatever_yaml_11_makes_of_them(tmp_path):
    """The check is on what the robot is built from: `x-` keys are free for annotations (a part
    number 0123, a time 12:30 loaded before the check and must still: a review)."""
    path = tmp_path / "y1.yaml"
    path.write_text("x-part: 0123\nx-updated: 12:30\nx-colour: 0xFF00FF\n" + ONE_JOINT.format(a="0.5"))
    assert load_robot(path).joints[0].p_fixed[0] == 0.5


def test_yaml_merge_keys_are_refused_naming_the_line(tmp_path):
    """'<<: *anchor' said 'could not determine a constructor for the tag merge'. Reading them was
    tried and dropped: a merged mapping repeats every entry it merges, so a 600-byte file nesting
    merges took 11 s and 218 MB before its keys collapsed, past every size check (a review)."""
    path = tmp_path / "m.yaml"
    path.write_text("name: m\njoints:\n  - &j {name: one, type: revolute, a: 0.5, alpha: 0, d: 0, "
                    "theta: 0, mass: 1.0, com: [0, 0, 0], inertia: [0.1, 0.1, 0.1, 0, 0, 0]}\n"
                    "  - <<: *j\n    name: two\n")
    with pytest.raises(VampcError, match=r"m\.yaml: line 4: YAML merge keys \(<<\) are not read: write "
                                        r"the row's fields out \(an alias of a whole row or value is "
                                        r"read\)"):
        load_robot(path)


ROW = ("name: t\njoints:\n  - name: j1\n    type: revolute\n    a: {a}\n    alpha: 0\n    d: 0\n"
       "    theta: 0\n    mass: 1\n    com: {com}\n    inertia: [1, 1, 1, 0, 0, 0]\n")


@pytest.mark.parametrize("text, says", [
    (ROW.format(a="0.5", com="[0, 0, 0]") + "    ? [x]\n    : 2\n",
     "line 12: not valid YAML: a key is a list; keys are names"),
    (ROW.format(a="0.5", com="[0, 0, 0]") + "    {a: 1}: 2\n",
     "line 12: not valid YAML: a key is a mapping; keys are names"),
    (ROW.format(a="0.5", com="!!set {0.3, 0.1, 0.2}"), "line 10: a value tagged !!set is not read: write "
     "it untagged"),
    ("name: t\njoints: !!set {a}\n", "line 2: a value tagged !!set is not read: write it untagged"),
    (ROW.format(a="!!timestamp abc", com="[0, 0, 0]"), "line 5: a value tagged !!timestamp is not read"),
    (ROW.format(a="!!float abc", com="[0, 0, 0]"), "line 5: 'abc' is tagged !!float; numbers are read "
     "untagged, in decimal digits"),
    (ROW.format(a="!!float '0x10'", com="[0, 0, 0]"), "line 5: '0x10' is tagged !!float"),
    (ROW.format(a="!!float nan", com="[0, 0, 0]"), "line 5: 'nan' is tagged !!float"),
    (ROW.format(a="!!int '1.5'", com="[0, 0, 0]"), "line 5: '1.5' is tagged !!int"),
    (ROW.format(a="!!bool maybe", com="[0, 0, 0]"), "line 5: not valid YAML: 'maybe' cannot be read as "
     "!!bool"),
    (ROW.format(a="0.5", com="[0, 0, 0]") + 'x-note: !!int ""\n',
     "line 12: not valid YAML: '' cannot be read as !!int"),
    ("name: t\nx-base: &b {a: 1}\nx-use: {<<: *b}\n" + ROW.format(a="0.5", com="[0, 0, 0]")[8:],
     "line 3: YAML merge keys (<<) are not read"),
    # untagged values YAML 1.1 resolves to its own types are not called tagged (a review's find)
    (ROW.format(a="2001-12-14", com="[0, 0, 0]"), 'joints[0].a (joint 1): "2001-12-14" is not of type '
     '"number"'),
    (ROW.format(a="=", com="[0, 0, 0]"), 'joints[0].a (joint 1): "=" is not of type "number"'),
    (ROW.format(a="<<", com="[0, 0, 0]"), "line 5: '<<' is YAML's merge key, not a value"),
    (ROW.format(a="!!timestamp 2001-12-14", com="[0, 0, 0]"), "line 5: a value tagged !!timestamp is "
     "not read")])
def test_tagged_values_and_keys_that_are_not_names_are_one_line(tmp_path, text, says):
    """PyYAML's constructors raise Python's own errors (TypeError, ValueError, KeyError, ...) for a
    tagged value they cannot make, or a list as a key: each was an internal error, exit 3 (an
    audit's); `!!set` passed the schema as a list. Each is one line naming the line now, as
    `!!python/object` was; and a merge key under an annotation is said as anywhere else."""
    path = tmp_path / "t.yaml"
    path.write_text(text)
    with pytest.raises(VampcError) as err:
        load_robot(path)
    assert str(err.value).startswith(f"{path}: {says}"), str(err.value)
    assert "\n" not in str(err.value)


@pytest.mark.parametrize("a", ["!!float 0.5", "!!float 1", "0.5"])
def test_a_number_tagged_as_what_it_is_is_read(tmp_path, a):
    path = tmp_path / "t.yaml"
    path.write_text(ROW.format(a=a, com="[0, 0, 0]"))
    assert load_robot(path).joints[0].p_fixed[0] == float(a.split()[-1])


def _tree_rows(*order):
    row = {"a": "a", "b": "b", "c": "c"}
    spec = {"a": dict(parent=0, a=0.3, alpha=0.5, d=0.1), "b": dict(parent=0, a=0.2, alpha=1.0, d=0.0),
            "c": dict(parent="a", a=0.2, alpha=0.0, d=0.0)}
    return [{"name": row[k], "type": "revolute", "theta": 0.0, "mass": 1.0, "com": [0.1, 0, 0],
             "inertia": [0.01, 0.01, 0.01, 0, 0, 0], **spec[k]} for k in order]


def test_a_tip_load_on_a_tree_acts_on_the_last_joint_depth_first_or_is_refused():
    """The README said a tree's tip load acts on the last row's link; it acted on the last joint in
    depth-first order ('b' of rows a, b, c with c a child of a), and --check, whose reference reads
    the table the same way, passed (a new user's find against Pinocchio: 1.41 N·m on a 7-joint
    tree). A load whose last row is not that joint is refused, naming both."""
    tip = {"force": [0, 10, 0], "torque": [0, 0, 0]}
    with pytest.raises(VampcError) as err:
        chain_from_dh({"name": "t", "joints": _tree_rows("a", "b", "c"), "tip": tip}, "t.yaml")
    assert str(err.value) == ("t.yaml: tip: on a tree the tip load acts on link n, the last joint in "
                              "depth-first order: 'b' (row 2), not the last row's 'c' (row 3); list "
                              "the loaded link's branch last (README, DH table)")
    # the loaded branch last: the load acts on the last row's link, b
    chain = chain_from_dh({"name": "t", "joints": _tree_rows("a", "c", "b"), "tip": tip}, "t.yaml")
    assert [j.name for j in chain.joints] == ["a", "c", "b"]
    # no load (or an all-zero one) acts nowhere: any row order
    chain_from_dh({"name": "t", "joints": _tree_rows("a", "b", "c"),
                   "tip": {"force": [0, 0, 0]}}, "t.yaml")
    chain_from_dh({"name": "t", "joints": _tree_rows("a", "b", "c")}, "t.yaml")


def test_a_chain_listed_out_of_order_keeps_its_tip_load_at_its_end():
    """A chain whose rows name their parents out of order is no tree: its tip load acts on its last
    joint, 'b' here, and is not refused as a tree's (a review's find)."""
    rows = [{"name": "b", "parent": "a", "type": "revolute", "a": 0.2, "alpha": 0.0, "d": 0.0,
             "theta": 0.0, "mass": 1.0, "com": [0.1, 0, 0], "inertia": [0.01, 0.01, 0.01, 0, 0, 0]},
            {"name": "a", "parent": 0, "type": "revolute", "a": 0.3, "alpha": 0.5, "d": 0.1,
             "theta": 0.0, "mass": 1.0, "com": [0.1, 0, 0], "inertia": [0.01, 0.01, 0.01, 0, 0, 0]}]
    tip = {"force": [0, 10, 0], "torque": [0, 0, 0]}
    chain = chain_from_dh({"name": "t", "joints": rows, "tip": tip}, "t.yaml")
    assert [j.name for j in chain.joints] == ["a", "b"] and chain.is_chain
    assert list(chain.tip_force) == [0, 10, 0]


def test_an_angle_in_degrees_is_warned_about_once(tmp_path):
    """A DH angle beyond 2π is degrees read as radians, most likely: one warning naming the file,
    the first such place and how many more (`alpha: 90` was taken as 90 rad without a word)."""
    from vampc.errors import VampcWarning
    path = tmp_path / "degrees.yaml"
    path.write_text(yaml.safe_dump({"name": "x", "joints": [
        row(), row(alpha=90), row(type="prismatic", alpha=-90, theta=180)]}))
    with pytest.warns(VampcWarning) as said:
        chain = load_dh(path)
    assert [str(w.message) for w in said] == [
        f"{path}: joints[1].alpha (joint 2): alpha 90 is more than 2π: DH angles are radians "
        "(90° is 1.5708) (and 2 more)"]
    assert chain.n == 3                      # (taken as written: a warning, not a refusal)


def test_an_angle_within_2pi_is_not_warned_about(tmp_path):
    import warnings
    path = tmp_path / "radians.yaml"
    path.write_text(yaml.safe_dump({"name": "x", "joints": [
        row(alpha=6), row(theta=-6.2832), row(type="prismatic", alpha=-2 * math.pi, theta=6.2832)]}))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        load_dh(path)


def test_a_file_of_another_kind_says_what_it_looks_like(tmp_path):
    """A YAML table named .json was 'not valid JSON: invalid character (line 1, column 1)' alone, and
    a .npy array named .yaml 'not UTF-8 text (byte 0)' (an audit's find): each says what it looks
    like."""
    yaml_named_json = tmp_path / "planar2.json"
    yaml_named_json.write_text(Path("examples/planar2.yaml").read_text())
    with pytest.raises(VampcError) as err:
        load_robot(yaml_named_json)
    assert str(err.value) == (f"{yaml_named_json}: this is YAML, not JSON; a DH table in YAML is named "
                              ".yaml or .yml")
    npy_named_yaml = tmp_path / "robot.yaml"
    np.save(tmp_path / "t.npy", np.zeros((3, 6)))
    npy_named_yaml.write_bytes((tmp_path / "t.npy").read_bytes())
    with pytest.raises(VampcError) as err:
        load_robot(npy_named_yaml)
    assert str(err.value) == (f"{npy_named_yaml}: this is a NumPy array (.npy: a trajectory or "
                              "torques?), not a robot description")
    npy_named_urdf = tmp_path / "robot.urdf"           # (the same said by sniff for every robot suffix)
    npy_named_urdf.write_bytes((tmp_path / "t.npy").read_bytes())
    with pytest.raises(VampcError) as err:
        load_robot(npy_named_urdf)
    assert str(err.value) == (f"{npy_named_urdf}: this is a NumPy array (.npy: a trajectory or "
                              "torques?), not a robot description")
    commented = tmp_path / "c.json"          # JSON with a comment, which YAML does not read either:
    commented.write_text('// my robot\n{"name": "x", "joints": []}\n')   # the JSON reader's place
    with pytest.raises(VampcError) as err:
        load_robot(commented)
    assert str(err.value) == f"{commented}: not valid JSON: invalid character (line 1, column 1)"
    broken_json = tmp_path / "bad.json"                 # JSON, broken: no hint
    broken_json.write_text('{"name": "x", joints: []}')
    with pytest.raises(VampcError) as err:
        load_robot(broken_json)
    assert str(err.value) == f"{broken_json}: not valid JSON: object keys must be strings (line 1, column 15)"


def test_a_position_limit_in_degrees_is_warned_about_once(tmp_path):
    """`limits: {q: [-170, 170]}` on a revolute joint was taken as ±170 rad, random states drawn out
    to ±156 rad, unsaid (a new user's find): beyond two turns it is warned of, once, the first named
    and the other joints counted; a prismatic joint's metres and a few turns are not."""
    import warnings

    from vampc.errors import VampcWarning
    path = tmp_path / "degrees.yaml"
    path.write_text(yaml.safe_dump({"name": "x", "joints": [
        row(limits={"q": [-3 * math.pi, 3 * math.pi]}), row(limits={"q": [-170, 170]}),
        row(type="prismatic", limits={"q": [-50, 50]}), row(limits={"q": [0, 360]})]}))
    with pytest.warns(VampcWarning) as said:
        chain = load_dh(path)
    assert [str(w.message) for w in said] == [
        f"{path}: joints[1].limits (joint 2): q limit -170 is more than two turns: position limits "
        "are radians (-170° is -2.9671) (and 1 more joint)"]
    assert chain.joints[1].limits.q == (-170.0, 170.0)      # (taken as written)
    path.write_text(yaml.safe_dump({"name": "x", "joints": [
        row(limits={"q": [-4 * math.pi, 4 * math.pi]}), row(type="prismatic", limits={"q": [-50, 50]})]}))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        load_dh(path)
