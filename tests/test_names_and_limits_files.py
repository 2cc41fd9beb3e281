"""What a new user's robot and limits files met (the twelfth round's run): names with `$` in the
pictures, joint names padded with spaces in a --limits file, negative URDF limits, NumPy files given
where only text is read, a limits file that is not UTF-8, and rate bounds said in units one can type.
Each test failed on the code before its fix."""
from __future__ import annotations

import numpy as np
import pytest
from click.testing import CliRunner
from conftest import EXAMPLES

from vampc.cli import main
from vampc.report.clock import parse_clock

JOINT = ("  - {{name: {name}, type: revolute, a: 0.5, alpha: 0, d: 0, theta: 0, mass: 1, "
         "com: [-0.25, 0, 0], inertia: [0.01, 0.01, 0.01, 0, 0, 0], limits: {{tau: 50}}}}\n")
STILL = "q1,q2,qd1,qd2,qdd1,qdd2\n" + "0,0,0,0,0,0\n" * 3


def robot(folder, name: str, joints: list[str]):
    path = folder / "robot.yaml"
    path.write_text(f"name: {name}\ngravity: [0, -9.81, 0]\njoints:\n"
                    + "".join(JOINT.format(name=j) for j in joints), encoding="utf-8")
    (folder / "still.csv").write_text(STILL)
    return path


def run(*args):
    r = CliRunner().invoke(main, [str(a) for a in args])
    return r.exit_code, r.stderr, r.stdout


def lookahead(folder, robot_file, *extra):
    return run("lookahead", robot_file, "--trajectory", folder / "still.csv", "--rate", "100Hz",
               "--window", "2", *extra)


def test_names_with_dollar_signs_are_drawn_as_text(tmp_path):
    """matplotlib read `$...$` in a title or label as TeX: 'cost$_$' was an internal error (exit 3)
    in lookahead --plot and a traceback in report --timing; a name that parsed was drawn as maths."""
    path = robot(tmp_path, '"cost$_$"', ["a", '"sh$\\\\frac{$x"'])
    code, err, _ = lookahead(tmp_path, path, "--plot", tmp_path / "la.svg")
    assert code == 0, err
    assert "cost$_$" in (tmp_path / "la.svg").read_text()
    code, err, _ = run("report", path, "--timing", tmp_path / "t.svg", "--network", tmp_path / "n.svg")
    assert code == 0, err
    assert "cost$_$" in (tmp_path / "t.svg").read_text()
    assert "cost$_$" in (tmp_path / "n.svg").read_text()


def test_a_joint_name_padded_with_spaces_takes_its_limit(tmp_path):
    """The limits reader dropped the spaces round every cell, so a joint named ' épaule 2 ' could
    never be given a limit ('no joint named 'épaule 2'')."""
    path = robot(tmp_path, "padded", ['"a,b"', '" épaule 2 "'])
    for cell in ('" épaule 2 "', "épaule 2"):
        limits = tmp_path / "lim.csv"
        limits.write_text(f'joint,tau,qd\n"a,b",1,\n{cell},0.5,\n', encoding="utf-8")
        code, err, out = lookahead(tmp_path, path, "--limits", limits)
        assert code == 0, err
        # joint 2's gravity torque over a limit of 0.5 instead of the file's 50
        worst = float(out.split("' épaule 2 ' ")[-1].split()[0])    # (quoted: spaces round it)
        assert worst > 1.0, out


def test_a_name_only_spaces_tell_apart_is_refused_saying_so(tmp_path):
    path = robot(tmp_path, "twins", ['" a"', '"a "'])
    limits = tmp_path / "lim.csv"
    limits.write_text("joint,tau,qd\na,1,\n")
    code, err, _ = lookahead(tmp_path, path, "--limits", limits)
    assert code == 1 and err.count("\n") == 1, err
    assert "line 2: no joint named 'a'" in err and "differ only in spaces" in err


@pytest.mark.parametrize("attribute", ["effort", "velocity"])
def test_a_negative_urdf_limit_is_refused_naming_the_joint(tmp_path, attribute):
    """A negative effort was read as "none given" without a word; lookahead then asked for the limit
    the file gives."""
    values = {"effort": "5", "velocity": "2", attribute: "-5"}
    path = tmp_path / "arm.urdf"
    path.write_text(
        '<robot name="bl"><link name="base"/><link name="l1"><inertial><origin xyz="0.1 0 0"/>'
        '<mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/>'
        '</inertial></link><joint name="j1" type="revolute"><parent link="base"/>'
        '<child link="l1"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" '
        f'effort="{values["effort"]}" velocity="{values["velocity"]}"/></joint></robot>')
    code, err, _ = run("emulate", path, "--random", 3)
    assert code == 1 and err.count("\n") == 1, err
    assert f"arm.urdf: joint 'j1': <limit> {attribute} -5 is not a positive number" in err


def test_numpy_files_where_text_is_read_are_not_told_to_be_renamed(tmp_path):
    """--accelerations reads CSV only: an .npy was told to be 'named .npy', which it was."""
    path = robot(tmp_path, "two", ["a", "b"])
    np.save(tmp_path / "acc.npy", np.ones((5, 2)))
    code, err, _ = run("lookahead", path, "--accelerations", tmp_path / "acc.npy", "--q0", "0,0",
                       "--rate", "100Hz", "--window", "2")
    assert code == 1 and err.count("\n") == 1, err
    assert "acc.npy: a NumPy .npy array; the acceleration table must be UTF-8 text" in err
    assert "name it" not in err


def test_a_limits_file_that_is_not_utf8_names_its_line_and_byte(tmp_path):
    path = robot(tmp_path, "two", ["a", "b"])
    (tmp_path / "lim.csv").write_bytes(b"joint,tau,qd\na,1\xff0,\n")
    code, err, _ = lookahead(tmp_path, path, "--limits", tmp_path / "lim.csv")
    assert code == 1 and err.count("\n") == 1, err
    assert "lim.csv: line 2: byte 0xff is not UTF-8 (the limits file must be UTF-8 text)" in err


def test_the_rate_bounds_are_said_in_units_one_can_type(tmp_path):
    """'at least 1 mHz and at most 1 THz': mHz is refused as a slip for MHz and THz is no unit."""
    path = robot(tmp_path, "two", ["a", "b"])
    code, err, _ = run("lookahead", path, "--trajectory", tmp_path / "still.csv", "--rate", "0Hz",
                       "--window", "2")
    assert code == 2 and "at least 0.001 Hz and at most 1000 GHz" in err, err
    assert parse_clock("0.001Hz") == 1e-3 and parse_clock("1000GHz") == 1e12
    for beyond in ("0.0009Hz", "1001GHz"):
        with pytest.raises(ValueError, match="at least 0.001 Hz and at most 1000 GHz"):
            parse_clock(beyond)


def test_a_padded_joints_row_without_tau_is_named_by_its_line(tmp_path):
    path = robot(tmp_path, "padded", ["a", '" b "'])
    path.write_text(path.read_text().replace(", limits: {tau: 50}", ""))   # (no effort limits)
    limits = tmp_path / "lim.csv"
    limits.write_text("joint,tau,qd\na,1,\nb,,2\n")
    code, err, _ = lookahead(tmp_path, path, "--limits", limits)
    assert code == 1 and "lim.csv: line 3: joint ' b ' has no effort limit" in err, err


@pytest.mark.parametrize("name, joints, where", [
    ('"two\\nlines"', ["a", "b"], "robot"), ("arm", ["a", '"el\\nbow"'], "joint 2"),
    ("arm", ['"tab\\there"', "b"], "joint 1"), ("arm", ["a", '"para\\u2029graph"'], "joint 2"),
    ("arm", ["a", '"el\\u202ebow"'], "joint 2"), ('"r\\u200fobot"', ["a", "b"], "robot")])
def test_a_name_with_a_control_character_is_one_line_naming_it(tmp_path, name, joints, where):
    """A newline in a joint's name split the text report's rows (and every one-line message naming
    the joint); it is refused where the robot file is read, by the joint's number. So is a
    bidirectional control: a U+202E right-to-left override reversed the text printed after it."""
    path = robot(tmp_path, name, joints)
    out = tmp_path / "r.vamp.json"
    code, err, _ = run("compile", path, "-o", out)
    what = "line separator" if "u2029" in joints[-1] else \
        "bidirectional control" if "u20" in joints[-1] + name else "control character"
    assert code == 1 and err.startswith(f"vampc: error: {path}: {where}: its name ") and \
        f"holds the {what} U+" in err and err.count("\n") == 1, err
    assert not out.exists()


def test_a_name_with_a_zero_width_joiner_or_non_joiner_is_taken(tmp_path):
    """Refusing every format character (Unicode Cf) refused the zero-width non-joiner and joiner
    that names in Persian and Indic scripts need (a review's find): only the bidirectional controls
    are refused; the name comes through to the program file as written."""
    import json
    path = robot(tmp_path, "arm", ["a", '"\u0645\u06cc\u200c\u062e\u0648\u0627\u0647\u0645"'])
    out = tmp_path / "r.vamp.json"
    code, err, _ = run("compile", path, "-o", out)
    assert code == 0, err
    names = [j["name"] for j in json.loads(out.read_text())["robot"]["joints"]]
    assert names[1] == "\u0645\u06cc\u200c\u062e\u0648\u0627\u0647\u0645", names


def test_a_urdf_joint_name_with_a_newline_is_refused(tmp_path):
    text = (EXAMPLES / "ur5.urdf").read_text()
    first = text.index('<joint name="') + len('<joint name="')
    path = tmp_path / "arm.urdf"
    path.write_text(text[:first] + "x&#10;" + text[first:])
    code, err, _ = run("report", path)
    assert code == 1 and f"{path}: joint " in err and "U+000A" in err and err.count("\n") == 1, err


@pytest.mark.parametrize("element, line", [("link", 22), ("joint", 44)])
def test_a_urdf_name_with_a_right_to_left_override_is_refused(tmp_path, element, line):
    """A U+202E in a URDF link's or joint's name was taken and printed as it is, reversing the text
    after it; it is refused by the element's line, the character escaped."""
    old = {"link": "shoulder_link", "joint": "elbow_joint"}[element]
    text = (EXAMPLES / "ur5.urdf").read_text()
    assert f'<{element} name="{old}"' in text and text.count("\n", 0, text.index(
        f'<{element} name="{old}"')) == line - 1
    path = tmp_path / "arm.urdf"
    path.write_text(text.replace(f'"{old}"', f'"{old[:2]}&#x202E;{old[2:]}"'))
    code, err, _ = run("report", path)
    assert code == 1 and err == (f"vampc: error: {path}: {element} on line {line}: its name "
                                 f"'{old[:2]}\\u202e{old[2:]}' holds the bidirectional control U+202E: "
                                 "names are printed in one-line messages, text reports and CSV "
                                 "headers\n"), err


def test_a_program_file_edited_to_a_name_with_a_newline_is_refused(tmp_path):
    from vampc.program.file import read_program, write_program
    path = robot(tmp_path, "arm", ["a", "b"])
    program = tmp_path / "r.vamp.json"
    assert run("compile", path, "-o", program)[0] == 0
    doc = read_program(program)
    doc["robot"]["joints"][1]["name"] = "el\nbow"
    write_program(doc, program)
    for command in (["report", program], ["emulate", program, "--random", "2"]):
        code, err, out = run(*command)
        assert code == 1 and err == (f"vampc: error: {program}: robot.joints[1].name: its name "
                                     "'el\\nbow' holds the control character U+000A: names are printed "
                                     "in one-line messages, text reports and CSV headers\n"), err


def test_a_trajectory_of_every_joint_for_a_coupled_robot_is_told_to_give_the_independent_ones(tmp_path):
    """'the program is for 1 joint' of a two-joint robot with a coupled follower, which report
    calls two joints (a new user's run): the message says both, and which columns to give."""
    urdf = tmp_path / "gr.urdf"
    urdf.write_text("""<robot name="g"><link name="b"/>
 <link name="l1"><inertial><mass value="1"/><origin xyz="0.1 0 0"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
 <link name="l2"><inertial><mass value="1"/><origin xyz="0.1 0 0"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
 <joint name="lead" type="revolute"><parent link="b"/><child link="l1"/><axis xyz="0 1 0"/></joint>
 <joint name="fol" type="revolute"><parent link="l1"/><child link="l2"/><origin xyz="0.2 0 0"/><axis xyz="0 1 0"/><mimic joint="lead" multiplier="-2" offset="0.1"/></joint></robot>
""")
    states = tmp_path / "two.csv"
    states.write_text("q1,q2,qd1,qd2,qdd1,qdd2\n0,0,0,0,0,0\n")
    code, err, _ = run("emulate", urdf, "--mimic", "couple", "--trajectory", states)
    assert code == 1 and "the program is for 2 joints, 1 independent (coupled followers follow their " \
        "leaders: give the independent joints' columns)" in err, err
