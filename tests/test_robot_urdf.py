"""URDF loader: frames and inertias against yourdfpy's forward kinematics, torques against Pinocchio (when
present), trees and locking, and exact error messages for bad files."""
from __future__ import annotations

import re
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest
from errors_util import assert_error
from frames_util import chain_frames as chain_poses
from pinocchio_util import pin_arrays

import vampc.robot
from vampc.errors import VampcError, VampcWarning
from vampc.robot import JointType, load_robot, load_urdf
from vampc.robot import dh as dh_loader

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
ARM6 = EXAMPLES / "arm6.urdf"
# Which URDF links make up each moving body of arm6 (fixed joints merge camera, link3b and tool).
ARM6_BODIES = {1: ["link1"], 2: ["link2", "camera"], 3: ["link3", "link3b"], 4: ["link4"], 5: ["link5"],
               6: ["link6", "tool"]}


# --- writing URDF text -----------------------------------------------------------------------------------

def vec(v) -> str:
    return " ".join(f"{x:.17g}" for x in v)


def link(name: str, mass=1.0, xyz=(0.1, 0, 0), rpy=(0, 0, 0), inertia=(0.01, 0, 0, 0.02, 0, 0.03)) -> str:
    """A <link> with an inertial; mass=None for a link without one. inertia = ixx ixy ixz iyy iyz izz."""
    if mass is None:
        return f'<link name="{name}"/>'
    names = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
    attrs = " ".join(f'{k}="{v:.17g}"' for k, v in zip(names, inertia))
    return (f'<link name="{name}"><inertial><origin xyz="{vec(xyz)}" rpy="{vec(rpy)}"/>'
            f'<mass value="{mass:.17g}"/><inertia {attrs}/></inertial></link>')


def joint(name: str, kind: str, parent: str, child: str, xyz=(0, 0, 0.1), rpy=(0, 0, 0), axis=(0, 0, 1),
          extra: str = "") -> str:
    limited = kind in ("revolute", "prismatic")
    limit = '<limit lower="-1" upper="1" velocity="1" effort="1"/>' if limited else ""
    return (f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
            f'<origin xyz="{vec(xyz)}" rpy="{vec(rpy)}"/><axis xyz="{vec(axis)}"/>{limit}{extra}</joint>')


def robot(*parts: str, name: str = "r") -> str:
    return f'<?xml version="1.0"?>\n<robot name="{name}">\n' + "\n".join(parts) + "\n</robot>\n"


def write(tmp_path: Path, text: str, name: str = "r.urdf") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def random_inertia(rng) -> list[float]:
    m = rng.normal(size=(3, 3)) * 0.05
    i = m @ m.T + 1e-3 * np.eye(3)
    return [i[0, 0], i[0, 1], i[0, 2], i[1, 1], i[1, 2], i[2, 2]]


def random_urdf(seed: int, n: int = 5) -> tuple[str, dict, str]:
    """A serial URDF with random origins (xyz, rpy), random unit axes, all three movable types, fixed
    joints in the middle, fixed side branches and a fixed tool. Returns (text, bodies, tip)."""
    rng = np.random.default_rng(seed)
    kinds = ["revolute", "continuous", "prismatic"]
    parts, bodies, parent = [link("base", 2.0)], {}, "base"

    def rlink(name):
        return link(name, float(rng.uniform(0.2, 3.0)), rng.uniform(-0.2, 0.2, 3), rng.uniform(-3, 3, 3),
                    random_inertia(rng))

    def rjoint(name, kind, par, child):
        axis = rng.normal(size=3)
        return joint(name, kind, par, child, rng.uniform(-0.3, 0.3, 3), rng.uniform(-3, 3, 3),
                     axis / np.linalg.norm(axis))

    for k in range(1, n + 1):
        if rng.random() < 0.5:  # a fixed joint before this movable one: its link merges into body k-1
            parts += [rjoint(f"fix{k}", "fixed", parent, f"mid{k}"), rlink(f"mid{k}")]
            bodies.setdefault(k - 1, []).append(f"mid{k}")
            parent = f"mid{k}"
        parts += [rjoint(f"j{k}", kinds[(k + seed) % 3], parent, f"l{k}"), rlink(f"l{k}")]
        bodies.setdefault(k, []).append(f"l{k}")
        if rng.random() < 0.4:  # a fixed side branch
            parts += [rjoint(f"side{k}", "fixed", f"l{k}", f"s{k}"), rlink(f"s{k}")]
            bodies[k].append(f"s{k}")
        parent = f"l{k}"
    parts += [rjoint("tool_fix", "fixed", parent, "tool"), rlink("tool")]
    bodies[n].append("tool")
    bodies.pop(0, None)
    return robot(*parts), bodies, "tool"


TREE = robot(
    link("torso", 5.0), link("chest", 3.0), link("head", 1.0),
    link("l_upper", 1.5, (0.1, 0.02, 0), (0.3, 0, 0)), link("l_lower", 1.0), link("left_hand", 0.3),
    link("r_upper", 1.4, (0.1, -0.02, 0), (0, 0.2, 0)), link("r_lower", 0.9), link("right_hand", 0.35),
    joint("waist", "revolute", "torso", "chest", (0, 0, 0.3), (0.1, 0, 0), (0, 0, 1)),
    joint("neck", "fixed", "chest", "head", (0, 0, 0.3)),
    joint("left_1", "revolute", "chest", "l_upper", (0, 0.2, 0.2), (0.3, 0.1, 0), (0, 1, 0)),
    joint("left_2", "prismatic", "l_upper", "l_lower", (0.25, 0, 0), (0, 0.2, 0.1), (1, 0, 0)),
    joint("left_grip", "fixed", "l_lower", "left_hand", (0.2, 0, 0), (0, 0, 0.5)),
    joint("right_1", "revolute", "chest", "r_upper", (0, -0.2, 0.2), (-0.3, 0.1, 0), (0, 0.6, 0.8)),
    joint("right_2", "continuous", "r_upper", "r_lower", (0.25, 0, 0), (0.2, 0, 0), (1, 0, 0)),
    joint("right_grip", "fixed", "r_lower", "right_hand", (0.2, 0, 0)), name="tree")
TREE_LEFT_BODIES = {1: ["chest", "head", "r_upper", "r_lower", "right_hand"], 2: ["l_upper"],
                    3: ["l_lower", "left_hand"]}


# --- independent references --------------------------------------------------------------------------------

def yourdfpy_model(path: Path):
    import yourdfpy
    return yourdfpy.URDF.load(str(path), build_scene_graph=True, load_meshes=False)


def check_frames(path: Path, chain, base: str, tip: str, bodies: dict, frozen: dict | None = None) -> None:
    """At random q, every O_i and every body's mass, CoM and inertia agree with yourdfpy's kinematics.

    O_0 is not stored in the Chain, so it is recovered from the tip pose at one q and then must be constant,
    sit on joint 1's axis with z along it, and refer gravity correctly."""
    urdf = yourdfpy_model(path)
    joints = {j.name: j for j in urdf.robot.joints}
    links = {link.name: link for link in urdf.robot.links}
    rng = np.random.default_rng(7)
    w0, in_link = None, {}
    for q in rng.uniform(-1.0, 1.0, (4, chain.n)):
        urdf.update_cfg({**(frozen or {}), **{j.name: qi for j, qi in zip(chain.joints, q)}})
        world = lambda name: urdf.get_transform(name, base)  # noqa: E731
        ours = chain_poses(chain, q)
        guess = world(tip) @ np.linalg.inv(ours[-1])
        w0 = guess if w0 is None else w0
        np.testing.assert_allclose(guess, w0, atol=1e-10)
        poses = [w0] + [w0 @ p for p in ours]
        for i, j in enumerate(chain.joints):  # O_i: at joint i+1's origin, z along its axis, fixed in link i
            uj = joints[j.name]
            at = world(uj.parent) @ as_pose(uj.origin)
            np.testing.assert_allclose(poses[i][:3, 3], at[:3, 3], atol=1e-10)
            np.testing.assert_allclose(poses[i][:3, 2], at[:3, :3] @ uj.axis / np.linalg.norm(uj.axis),
                                       atol=1e-10)
            relative = np.linalg.inv(world(uj.parent)) @ poses[i]
            np.testing.assert_allclose(relative, in_link.setdefault(i, relative), atol=1e-10)
        np.testing.assert_allclose(poses[-1], world(tip), atol=1e-10)
        for k, names in bodies.items():
            check_body(chain.joints[k - 1], poses[k], [(links[n].inertial, world(n)) for n in names])
    # gravity is the root link's -z (Pinocchio's reading), in O_0: the base link's pose in the root
    # with the joints above it (cut away) at 0
    urdf.update_cfg({j.name: 0.0 for j in urdf.robot.joints if j.type != "fixed" and j.mimic is None})
    above = urdf.get_transform(base, urdf.base_link)[:3, :3]
    np.testing.assert_allclose(chain.gravity, w0[:3, :3].T @ above.T @ [0, 0, -9.81], atol=1e-12)


def check_body(j, pose: np.ndarray, parts: list) -> None:
    """Mass, centre of mass and inertia about the base origin (base frame) of a body against the sum of its
    URDF links' inertials."""
    mass = sum(inertial.mass for inertial, _ in parts)
    first = sum(inertial.mass * (w @ as_pose(inertial.origin))[:3, 3] for inertial, w in parts)
    poses = [(inertial, w @ as_pose(inertial.origin)) for inertial, w in parts]
    second = sum(about_origin(inertial.mass, at[:3, 3], rotate(inertial.inertia, at[:3, :3]))
                 for inertial, at in poses)
    rot = pose[:3, :3]
    com = pose[:3, :3] @ j.com + pose[:3, 3]
    assert j.mass == pytest.approx(mass, abs=1e-12)
    np.testing.assert_allclose(j.mass * com, first, atol=1e-10)
    np.testing.assert_allclose(about_origin(j.mass, com, rotate(j.inertia, rot)), second, atol=1e-10)


def rotate(inertia: np.ndarray, rot: np.ndarray) -> np.ndarray:
    return rot @ inertia @ rot.T


def about_origin(m: float, c: np.ndarray, i_com: np.ndarray) -> np.ndarray:
    """Inertia about the origin of a body with mass m, centre of mass c and inertia i_com about c."""
    return i_com + m * (c @ c * np.eye(3) - np.outer(c, c))


def pinocchio_rnea(path: Path, chain, q, qd, qdd, lock: dict | None = None) -> np.ndarray:
    """Pinocchio's RNEA on the URDF (fixed base = root link, gravity -9.81 z), locked joints removed with
    buildReducedModel, joints matched by name (continuous joints use Pinocchio's cos/sin coordinates)."""
    pin = pytest.importorskip("pinocchio")
    model = pin.buildModelFromUrdf(str(path))
    q_ref = pin.neutral(model)
    for name, value in (lock or {}).items():
        set_q(model, q_ref, name, value)
    if lock:
        model = pin.buildReducedModel(model, [model.getJointId(n) for n in lock], q_ref)
    data = model.createData()
    qp, v, a = pin.neutral(model), np.zeros(model.nv), np.zeros(model.nv)
    for j, qi, vi, ai in zip(chain.joints, q, qd, qdd):
        set_q(model, qp, j.name, qi)
        v[model.joints[model.getJointId(j.name)].idx_v] = vi
        a[model.joints[model.getJointId(j.name)].idx_v] = ai
    tau = pin.rnea(model, data, qp, v, a)
    return np.array([tau[model.joints[model.getJointId(j.name)].idx_v] for j in chain.joints])


def set_q(model, q_vec, name: str, value: float) -> None:
    jm = model.joints[model.getJointId(name)]
    if jm.nq == 2:
        q_vec[jm.idx_q:jm.idx_q + 2] = np.cos(value), np.sin(value)
    else:
        q_vec[jm.idx_q] = value


def check_torques(path: Path, chain, lock: dict | None = None) -> None:
    from vampc.dynamics import reference  # (vampc's own: a plain import, never a skip)
    rng = np.random.default_rng(3)
    for q, qd, qdd in rng.uniform(-1.5, 1.5, (5, 3, chain.n)):
        ours = reference.rnea(chain, q, qd, qdd)
        np.testing.assert_allclose(ours, pinocchio_rnea(path, chain, q, qd, qdd, lock), atol=1e-9)


# --- defaults: what yourdfpy reads when the file leaves something out -----------------------------------

# No <origin>, an <origin> with xyz or rpy only, no <axis>, a partial <limit>, an
# <inertial> without <origin>.
DEFAULTS = robot(
    '<link name="base"><inertial><mass value="2"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/>'
    "</inertial></link>", link("l1"), link("l2"), link("l3"), link("l4", None),
    '<joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><limit upper="2" effort="3"/>'
    "</joint>",
    # (no <axis>: URDF's default 1 0 0; an <axis/> without xyz is no axis to urdfdom, refused)
    '<joint name="j2" type="prismatic"><parent link="l1"/><child link="l2"/><origin xyz="1 2 3"/>'
    '</joint>',
    '<joint name="j3" type="continuous"><parent link="l2"/><child link="l3"/><origin rpy="0.3 -0.2 1.1"/>'
    '<axis xyz="0 1 0"/></joint>',
    '<joint name="j4" type="fixed"><parent link="l3"/><child link="l4"/></joint>')


def as_pose(origin) -> np.ndarray:
    return np.eye(4) if origin is None else origin


def test_defaults_match_yourdfpy_kinematics(tmp_path):
    path = write(tmp_path, DEFAULTS)
    with pytest.warns(VampcWarning, match=r"joint 'j2' \(prismatic\) has no <limit>, which the URDF "
                      r"specification requires"), \
            pytest.warns(VampcWarning, match=r"joint 'j1' has a <limit> without velocity"):
        chain = load_urdf(path)
    assert [j.name for j in chain.joints] == ["j1", "j2", "j3"]
    # no lower: URDF's default, 0, as urdfdom and Pinocchio read it (it had been read as no interval)
    assert chain.joints[0].limits.q == (0.0, 2.0) and chain.joints[0].limits.tau == 3.0
    check_frames(path, chain, "base", "l4", {1: ["l1"], 2: ["l2"], 3: ["l3"]})


# --- arm6 and random chains --------------------------------------------------------------------------------

def test_arm6_structure():
    chain = load_robot(ARM6)
    chain.verify()
    names = ["waist", "shoulder", "elbow", "wrist_roll", "wrist_bend", "flange"]
    assert [j.name for j in chain.joints] == names
    assert all(j.type is JointType.REVOLUTE for j in chain.joints)
    assert chain.joints[2].limits.q is None and chain.joints[2].limits.qd == 2.5  # continuous
    assert chain.joints[3].limits.q == (-3.0, 3.0) and chain.joints[3].limits.tau == 30.0
    # Every inertial but the base's ends up in some body: mass totals are kept by the merging.
    from lxml import etree
    masses = {el.getparent().getparent().get("name"): float(el.get("value"))
              for el in etree.parse(str(ARM6)).iter("mass")}
    assert sum(j.mass for j in chain.joints) == pytest.approx(sum(masses.values()) - masses["base_link"])
    assert chain.joints[2].mass == pytest.approx(masses["link3"] + masses["link3b"])


def test_arm6_frames_and_inertias_match_yourdfpy():
    check_frames(ARM6, load_urdf(ARM6), "base_link", "tool", ARM6_BODIES)


def test_arm6_torques_match_pinocchio():
    check_torques(ARM6, load_urdf(ARM6))


@pytest.mark.parametrize("seed", range(4))
def test_random_urdf_matches_yourdfpy_and_pinocchio(tmp_path, seed):
    text, bodies, tip = random_urdf(seed)
    path = write(tmp_path, text)
    chain = load_urdf(path)
    chain.verify()
    assert {j.type for j in chain.joints} == {JointType.REVOLUTE, JointType.PRISMATIC}
    check_frames(path, chain, "base", tip, bodies)
    check_torques(path, chain)


def test_the_joints_cut_away_say_how_each_was_placed():
    """Each joint above --base is said placed as it was (--lock, or 0 by default), where every
    possible cause was listed for each (a new user's find)."""
    with pytest.warns(VampcWarning) as seen:
        load_urdf(ARM6, base="link2", tip="link5", lock={"flange": 0.3})
    said = [str(w.message) for w in seen if "cut away" in str(w.message)]
    assert len(said) == 1 and "(waist at 0, shoulder at 0: 0 by default);" in said[0], said
    with pytest.warns(VampcWarning) as seen:
        load_urdf(ARM6, base="link2", tip="link5", lock={"flange": 0.3, "waist": 0.5})
    said = [str(w.message) for w in seen if "cut away" in str(w.message)]
    assert len(said) == 1 and "(waist at 0.5, shoulder at 0: waist by --lock; shoulder by " \
        "default);" in said[0], said
    with pytest.warns(VampcWarning) as seen:
        load_urdf(ARM6, base="link2", tip="link5", lock={"flange": 0.3, "waist": 0.5,
                                                           "shoulder": -0.2})
    said = [str(w.message) for w in seen if "cut away" in str(w.message)]
    assert len(said) == 1 and "(waist at 0.5, shoulder at -0.2: by --lock);" in said[0], said


def test_base_below_the_root():
    # The flange hangs below the chosen tip, so it must be locked; the tool then rides on link 5.
    with pytest.warns(VampcWarning, match=r"--base link2: the joints above it are cut away \(waist at 0, "
                                          r"shoulder at 0:"):
        chain = load_urdf(ARM6, base="link2", tip="link5", lock={"flange": 0.3})
    assert [j.name for j in chain.joints] == ["elbow", "wrist_roll", "wrist_bend"]
    bodies = {1: ["link3", "link3b"], 2: ["link4"], 3: ["link5", "link6", "tool"]}
    check_frames(ARM6, chain, "link2", "link5", bodies, frozen={"flange": 0.3})


def _file_joints_and_heavy_links(path):
    """(moving joint names by their link, the links with a mass), read from the file with ElementTree."""
    import xml.etree.ElementTree as ET
    root = ET.parse(path).getroot()
    moving = {j.find("child").get("link"): j.get("name") for j in root.iter("joint")
              if j.get("type") in ("revolute", "continuous", "prismatic")}
    heavy = [link.get("name") for link in root.iter("link")
             if link.find("inertial/mass") is not None and float(link.find("inertial/mass").get("value")) > 0]
    return moving, heavy


@pytest.mark.parametrize("floating", [False, True], ids=["fixed", "floating"])
def test_a_base_below_the_root_says_what_beside_it_is_left_out(floating):
    """--base FL_hip on the quadruped left the other three legs out (and, floating, the trunk too:
    a different robot floats), saying nothing: a founder's reread. The warning names, in the
    file's order, the moving joints off the way up (a fixed base takes their forces) or, for a
    floating base, every link with a mass and every moving joint not below FL_hip."""
    path = EXAMPLES / "quadruped.urdf"
    moving, heavy = _file_joints_and_heavy_links(path)
    leg = {"FL_hip", "FL_upper", "FL_lower", "FL_foot"}       # FL_hip and what hangs below it
    joints = [j for link, j in moving.items() if link not in leg - {"FL_hip"}] if floating else \
        [j for link, j in moving.items() if not link.startswith("FL_")]
    assert len(joints) == (10 if floating else 9)
    with pytest.warns(VampcWarning) as seen:
        chain = load_urdf(path, base="FL_hip", floating=floating)
    said = [str(w.message) for w in seen if "beside" in str(w.message)]
    assert len(said) == 1, said
    names = ", ".join(f"'{j}'" for j in joints)
    if floating:
        links = [name for name in heavy if name not in leg]
        shown = ", ".join(f"'{n}'" for n in links[:10]) + f" and {len(links) - 10} more"
        assert f"--base FL_hip --floating-base: only 'FL_hip' and what hangs below it float; the links " \
            f"above and beside it are left out ({shown} with mass; 10 moving joints: {names}), so " \
            "they do not load the floating base" in said[0], said
    else:
        assert f"--base FL_hip: the branches beside the way up to it are left out (9 moving joints: " \
            f"{names});" in said[0], said
    assert [j.name for j in chain.joints] == [moving[k] for k in ("FL_upper", "FL_lower")]


def test_nothing_beside_the_base_is_said_only_what_a_floating_base_leaves_above():
    """A chain's base below its root leaves nothing beside it (the way up is said where gravity is
    turned); floating, the links above it are left out, said with the one moving joint; the root
    named as --base leaves nothing out."""
    path = EXAMPLES / "ur5.urdf"
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        load_urdf(path, base="shoulder_link")
        load_urdf(path, base="world")
        load_urdf(EXAMPLES / "quadruped.urdf", base="trunk", floating=True)
    assert not [w for w in seen if "beside" in str(w.message)], [str(w.message) for w in seen]
    with pytest.warns(VampcWarning, match=r"--base shoulder_link --floating-base: only 'shoulder_link' "
                                          r"and what hangs below it float; the links above and beside "
                                          r"it are left out \('base_link' with mass; 1 moving joint: "
                                          r"'shoulder_pan_joint'\)"):
        load_urdf(path, base="shoulder_link", floating=True)


# --- trees and locking -------------------------------------------------------------------------------------

def test_tree_tip_and_locked_branch(tmp_path):
    path = write(tmp_path, TREE)
    lock = {"right_1": 0.4}
    with pytest.warns(VampcWarning, match=r"joint 'right_2', below a locked joint, is frozen at 0; give "
                                          r"--lock right_2=VALUE"):    # never assumed silently
        chain = load_urdf(path, tip="left_hand", lock=lock)
    assert [j.name for j in chain.joints] == ["waist", "left_1", "left_2"]
    check_frames(path, chain, "torso", "left_hand", TREE_LEFT_BODIES, frozen={"right_1": 0.4, "right_2": 0.0})
    check_torques(path, chain, lock={"right_1": 0.4, "right_2": 0.0})  # below a lock: frozen at 0


def test_tree_locked_values_and_locked_chain_joint(tmp_path):
    path = write(tmp_path, TREE)
    lock = {"right_1": -0.3, "right_2": 0.7, "left_1": 0.2}
    chain = load_urdf(path, tip="left_hand", lock=lock)
    assert [j.name for j in chain.joints] == ["waist", "left_2"]
    bodies = {1: TREE_LEFT_BODIES[1] + ["l_upper"], 2: TREE_LEFT_BODIES[3]}
    check_frames(path, chain, "torso", "left_hand", bodies, frozen=lock)
    check_torques(path, chain, lock=lock)


def test_tree_default_tip_after_locking_one_arm(tmp_path):
    path = write(tmp_path, TREE)
    chain = load_urdf(path, lock={"left_1": 0.0, "left_2": 0.1})
    assert [j.name for j in chain.joints] == ["waist", "right_1", "right_2"]


# --- errors: one line, the file, the place ------------------------------------------------------------

ARM = [link("base"), link("l1"), link("l2"), joint("j1", "revolute", "base", "l1"),
       joint("j2", "revolute", "l1", "l2")]

URDF_ERRORS = [
    ("<robot name='x'><link name='a'></robot>", {}, r"line 1: not well-formed XML: .+"),
    ('<?xml version="1.0"?><!DOCTYPE lolz [<!ENTITY lol "lol"><!ENTITY lol2 "&lol;&lol;&lol;&lol;&lol;">'
     '<!ENTITY lol3 "&lol2;&lol2;&lol2;&lol2;">]><robot name="&lol3;"/>', {},
     r"DOCTYPE declares entities \(lol, lol2, lol3\); URDF files must not use XML entities"),
    ('<?xml version="1.0"?><!DOCTYPE r [<!ENTITY x SYSTEM "file:///etc/passwd">]><robot name="&x;"/>', {},
     r"DOCTYPE declares entities \(x\); URDF files must not use XML entities"),
    ("<sdf version='1.6'/>", {}, r"line 1: the root element must be <robot name=\"...\"> \(a URDF\) or "
     r"<mujoco> \(an MJCF model\)"),
    (robot(link("a", None)), {}, r"no movable joints below base link 'a'"),
    (robot(*ARM[:4], joint("j2", "floating", "l1", "l2")), {},
     r"joint 'j2': a floating joint is taken only as the one joint of the root link \(the base then "
     r"floats; README, Trees and floating bases\), and this one is not"),
    (robot(*ARM[:4], joint("j2", "planar", "l1", "l2")), {}, r"joint 'j2': planar joints are not supported"),
    (robot(*ARM[:4], joint("j2", "ball", "l1", "l2")), {}, r"joint 'j2': unsupported joint type 'ball'"),
    (robot(link("base"), link("l1", -2.0), link("l2"), *ARM[3:]), {}, r"link 'l1': negative mass -2\.0"),
    (robot(link("base"), link("l1", 1.0, inertia=(1, 2, 0, 1, 0, 1)), link("l2"), *ARM[3:]), {},
     r"link 'l1': inertia is not positive semi-definite \(eigenvalues -1, 1, 3\); "
     r"--accept-improper-inertia takes it as written, as Pinocchio does"),
    (robot(*ARM, joint("j3", "fixed", "base", "l2")), {},
     r"link 'l2': has two parent joints \('j2' and 'j3'\); closed loops are not supported"),
    (robot(link("a"), link("b"), joint("j1", "revolute", "a", "b"), joint("j2", "revolute", "b", "a")), {},
     r"joint '(j1|j2)': closes a loop through joints '(j1|j2)', '(j1|j2)'; closed loops are not supported"),
    (robot(*[link(f"l{k}") for k in range(12)],
           *[joint(f"j{k}", "revolute", f"l{k}", f"l{(k + 1) % 12}") for k in range(12)]), {},
     r"joint 'j11': closes a loop through joints 'j11', 'j10', 'j9', 'j8', 'j7', 'j6', 'j5', 'j4', 'j3', 'j2' "
     r"and 2 more; closed loops are not supported"),
    (robot(*ARM[:4], joint("j2", "revolute", "l1", "l9")), {}, r"joint 'j2': child link 'l9' is not defined"),
    (robot(*ARM[:4], joint("j2", "revolute", "l1", "l2", rpy=(float("nan"), 0, 0))), {},
     r"joint 'j2': <origin rpy=\"nan 0 0\">: expected 3 finite numbers"),
    (robot(*ARM[:4], joint("j2", "revolute", "l1", "l2", axis=(0, 0, 0))), {}, r"joint 'j2': axis is zero \(its <axis> gives xyz=\"0 0 0\" or no xyz, which urdfdom, Pinocchio's reader, reads so; README, URDF\)"),
    # (said to be zero: a new user's find)
    (robot(*ARM[:4], joint("j2", "revolute", "l1", "l2", axis=(0, 1e-170, 1e-170))), {},
     r"joint 'j2': its axis is 1\.41e-170 long: too short to be told from zero \(at least 1e-9; only "
     r"its direction counts: give a unit vector\)"),
    (robot(link("base"), link("l1", xyz=(float("inf"), 0, 0)), link("l2"), *ARM[3:]), {},
     r"link 'l1': <origin xyz=\"inf 0 0\">: expected 3 finite numbers"),
    (robot(*ARM).replace('<inertia ixx="0.01" ', "<inertia "), {}, r"link 'base': <inertia> lacks ixx"),
    (robot(*ARM).replace('<origin xyz="0 0 0.10000000000000001"', '<origin xyz="0 0"', 1), {},
     r"joint 'j1': <origin xyz=\"0 0\">: expected 3 finite numbers"),
    (robot(*ARM).replace("<parent link=\"base\"/>", ""), {}, r"joint 'j1': missing <parent link=\"...\"/>"),
    (robot(*ARM).replace('<joint name="j1" type="revolute">', '<joint type="revolute">'), {},
     r"line 6: <joint> has no name"),
    (robot(*ARM, link("extra_root")), {},
     r"several root links \('base', 'extra_root'\); choose one with --base"),
    (robot(*[link(f"r{i}") for i in range(12)]), {},
     r"several root links \('r0', 'r1', 'r2', 'r3', 'r4', 'r5', 'r6', 'r7', 'r8', 'r9' and 2 more\); "
     r"choose one with --base"),
    # (it said "several root links ()": a new user's find, on example-robot-data's ur3.urdf)
    ('<?xml version="1.0"?>\n<robot name="empty">\n  <!-- a comment alone -->\n</robot>\n', {},
     r"no <link>: the robot has nothing to compile$"),
    (robot(*ARM), {"base": "nope"}, r"unknown base link 'nope'"),
    (robot(*ARM), {"tip": "nope"}, r"unknown tip link 'nope'"),
    (robot(*ARM), {"base": "l2", "tip": "l1"}, r"no path from base link 'l2' down to tip link 'l1'"),
    # (all locked: "no movable joints" had been said, of three locked through their leader too)
    (robot(*ARM), {"lock": {"j1": 0.0, "j2": 0.0}}, r"no free joint below base link 'base': its 2 "
     r"movable joints \('j1', 'j2'\) are all locked$"),
    (robot(*ARM), {"base": "l1", "lock": {"j2": 0.0}}, r"no free joint below base link 'l1': its one "
     r"movable joint \('j2'\) is locked$"),
    (robot(*ARM), {"tip": "l2", "lock": {"j1": 0.0, "j2": 0.0}},
     r"no movable joints between base link 'base' and tip link 'l2'"),
    (robot(*ARM), {"lock": {"j9": 0.0}}, r"lock j9: no joint named 'j9'"),
    # a zero axis above --base, given a position by --lock (a mutation audit: unchecked, said as
    # gravity "numbers too large for a float")
    (robot(*ARM, link("l3"), joint("j0", "revolute", "l2", "l3", axis=(1, 0, 0)))
     .replace('<axis xyz="0 0 1"/>', '<axis xyz="0 0 0"/>', 1), {"base": "l1", "lock": {"j1": 0.5}},
     r"joint 'j1': its axis is zero: no position of it turns gravity \(--lock gave it one\)$"),
    # a name given twice (a mutation audit: unchecked, a joint's was a KeyError, exit 3)
    (robot(*ARM, link("l1")), {}, r"link 'l1': defined twice \(again on line 8\)$"),
    (robot(*ARM).replace('<joint name="j2"', '<joint name="j1"'), {},
     r"joint 'j1': defined twice \(again on line 7\)$"),
    (robot(*ARM), {"lock": {"j1": float("nan")}}, r"lock j1: value nan is not a finite number"),
    (TREE, {"tip": "left_hand"},
     r"joint 'right_1' branches off the chain from base link '\w+' to tip link 'left_hand'; lock it "
     r"with --lock right_1=VALUE, or leave out --tip to take the whole robot \(a tree\)$"),
    (TREE, {"tip": "chest"}, r"joint 'left_1' moves below the tip link 'chest'; choose a tip further out "
                             r"or lock it with --lock left_1=VALUE \(also 'right_1'\)"),   # not a branch
    # the others as what they are: below the tip, or branching off (a new user's talos --tip
    # arm_left_7_link listed the gripper's joint, below the tip, as branching off)
    (TREE, {"tip": "l_upper"}, r"joint 'left_2' moves below the tip link 'l_upper'; choose a tip further "
                               r"out or lock it with --lock left_2=VALUE \(and branching off the chain: "
                               r"'right_1'\)$"),
    (TREE, {"tip": "r_upper"},
     r"joint 'left_1' branches off the chain from base link '\w+' to tip link 'r_upper'; lock it "
     r"with --lock left_1=VALUE \(and below the tip: 'right_2'\), or leave out --tip to take the "
     r"whole robot \(a tree\)$"),
    # a tip hung on a fixed joint (a flange): what moves below it was said to branch off (a new
    # user's --tip shoulder_flange)
    # (an unexpanded xacro property was "expected a finite number" alone: a new user's)
    (robot(*ARM).replace('<mass value="1"/>', '<mass value="${forearm_mass}"/>', 1), {},
     r"link 'base': <mass value=\"\$\{forearm_mass\}\">: a xacro expression, which no URDF "
     r"reader expands; run xacro first \(xacro r.urdf > r-expanded.urdf\) and give the URDF$"),
    (robot(link("base"), link("l1"), link("flange"), link("l2"), joint("j1", "revolute", "base", "l1"),
           joint("fx", "fixed", "l1", "flange"), joint("j2", "revolute", "flange", "l2")),
     {"tip": "flange"}, r"joint 'j2' moves below the tip link 'flange'; choose a tip further out or "
                        r"lock it with --lock j2=VALUE$"),
]


@pytest.mark.parametrize("text, options, message", URDF_ERRORS)
def test_urdf_errors(tmp_path, text, options, message):
    path = write(tmp_path, text)
    assert_error(lambda: load_robot(path, **options), path, message)


def test_a_lock_at_a_joints_limit_is_within_it(tmp_path):
    """--lock refuses a value outside the joint's limits (README, --lock); one at a limit itself is
    within them (a mutation audit: a strict comparison refused --lock j1=1 for upper="1")."""
    path = write(tmp_path, robot(*ARM))
    for at in (-1.0, 1.0):
        chain = load_urdf(path, lock={"j1": at})
        assert [j.name for j in chain.joints] == ["j2"]
    with pytest.raises(VampcError, match=r"lock j1: 1\.0000001 is outside the joint's limits \[-1\.0, 1\.0\]"):
        load_urdf(path, lock={"j1": 1.0000001})


def test_missing_file(tmp_path):
    assert_error(lambda: load_robot(tmp_path / "gone.urdf"), tmp_path / "gone.urdf", "no such file")


def test_external_entity_is_never_read(tmp_path):
    secret = write(tmp_path, "<link name='leaked'/>", "secret.xml")
    text = (f'<?xml version="1.0"?><!DOCTYPE robot [<!ENTITY x SYSTEM "file://{secret}">]>'
            '<robot name="r">&x;</robot>')
    path = write(tmp_path, text)
    with pytest.raises(VampcError, match="DOCTYPE declares entities") as info:
        load_robot(path)
    assert "leaked" not in str(info.value)


def test_entities_refused_in_utf16_too(tmp_path):
    # The byte scan cannot read UTF-16; the declaration is then caught after the (entity-free) parse.
    text = '<?xml version="1.0" encoding="UTF-16"?><!DOCTYPE r [<!ENTITY a "b">]><robot name="&a;"/>'
    path = tmp_path / "r.urdf"
    path.write_bytes(text.encode("utf-16"))
    assert_error(lambda: load_robot(path), path, r"DOCTYPE declares entities \(a\); URDF files must not use XML entities")


def test_xml_extension_and_lazy_yourdfpy(tmp_path):
    # Importing vampc.robot does not import yourdfpy (it costs about a second); loading a URDF does.
    import subprocess
    copy = write(tmp_path, ARM6.read_text(), "arm6.xml")
    assert load_robot(copy).n == 6
    code = "import sys, vampc.robot; print('yourdfpy' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                         cwd=Path(__file__).resolve().parent.parent).stdout
    assert out.strip() == "False"


def test_lock_of_a_fixed_joint_warns_and_does_nothing():
    message = f"{ARM6}: joint 'camera_mount' is fixed; --lock camera_mount=... has no effect"
    with pytest.warns(VampcWarning, match=f"^{re.escape(message)}$") as record:
        chain = load_robot(ARM6, lock={"camera_mount": 0.3})
    assert len(record) == 1
    plain = load_robot(ARM6)
    assert [j.name for j in chain.joints] == [j.name for j in plain.joints]
    for ours, theirs in zip(chain.joints, plain.joints):
        np.testing.assert_array_equal(ours.phi, theirs.phi)
        np.testing.assert_array_equal(ours.p_fixed, theirs.p_fixed)
        np.testing.assert_array_equal(ours.inertia, theirs.inertia)


# --- size: the joint limit, and loading in O(n) -------------------------------------------------------------

def test_too_many_joints(tmp_path, monkeypatch):
    # The real limit (524 287 joints, tests/test_robot_dh.py) needs a 250 MB file: lower it.
    monkeypatch.setattr(dh_loader, "MAX_JOINTS", 1)
    path = write(tmp_path, robot(*ARM))
    assert_error(lambda: load_robot(path), path,
                 r"too many joints: 2 \(at most 1: VAMP numbers have 24 bits and the smallest network, "
                 r"the linear one, has up to 32 VAMPs a joint\)")
    assert load_robot(path, lock={"j2": 0.0}).n == 1  # the limit is on the chain, not on the file


def chain_urdf(n: int) -> str:
    """A chain of n revolute joints with a fixed joint and link after every fourth, listed tip first (so
    that every walk up the tree starts from the far end)."""
    parts, parent = [link("l0")], "l0"
    for k in range(1, n + 1):
        parts += [joint(f"j{k}", "revolute", parent, f"l{k}", axis=(0, k % 2, 1)), link(f"l{k}")]
        parent = f"l{k}"
        if k % 4 == 0:
            parts += [joint(f"f{k}", "fixed", parent, f"f{k}"), link(f"f{k}")]
            parent = f"f{k}"
    return robot(*reversed(parts))


def executed_lines(module, call) -> int:
    """How many lines of `module` (of every module in its folder, for a package) run during call(): a count,
    not a time, so it does not depend on the machine or its load (steps inside C, such as `list.index`,
    and lines of other packages, such as yourdfpy's, are not counted)."""
    count = 0
    files = {module.__file__}
    if hasattr(module, "__path__"):
        files = {str(f) for folder in module.__path__ for f in Path(folder).glob("*.py")}

    def in_module(frame, event, arg):
        nonlocal count
        count += event == "line"
        return in_module

    def tracer(frame, event, arg):
        return in_module if frame.f_code.co_filename in files else None

    previous = sys.gettrace()
    sys.settrace(tracer)
    try:
        call()
    finally:
        sys.settrace(previous)
    return count


def test_loading_is_linear(tmp_path):
    """Ten times the joints run our lines (every module of vampc/robot/; yourdfpy's are not counted) fewer
    than 15 times as often: 10 times for O(n), 14 for O(n log n), 100 for O(n²) (collecting every joint's
    ancestors and scanning all links for each body made it 66). The times are in benchmarks/load_robot.py."""
    small, big = (write(tmp_path, chain_urdf(n), f"chain{n}.urdf") for n in (200, 2000))
    assert load_urdf(big).n == 2000
    lines = [executed_lines(vampc.robot, lambda p=p: load_urdf(p)) for p in (small, big)]
    assert lines[1] < 15 * lines[0], lines


def test_a_tree_without_tip_is_taken_whole(tmp_path):
    """Issue 12 replaced the error "several movable branches below base link 'torso'; choose --tip from
    'left_hand', 'right_hand'" (a case of URDF_ERRORS until then): the tree is compiled whole, numbered
    depth-first with children in Pinocchio's order, and its torques are Pinocchio's."""
    path = write(tmp_path, TREE)
    chain = load_robot(path)
    assert [j.name for j in chain.joints] == ["waist", "left_1", "left_2", "right_1", "right_2"]
    assert chain.parent_of == (0, 1, 2, 1, 4)
    pin = pytest.importorskip("pinocchio")
    model = pin.buildModelFromUrdf(str(path))
    assert list(model.names[1:]) == [j.name for j in chain.joints]
    from vampc.dynamics.reference import rnea
    from vampc.robot.random import random_state
    names = [j.name for j in chain.joints]
    for q, qd, qdd in zip(*random_state(chain, 3, 1)):
        pq, pv = pin_arrays(model, names, q, qd, [])
        _, pa = pin_arrays(model, names, q, qdd, [])
        want = pin.rnea(model, model.createData(), pq, pv, pa)
        assert np.max(np.abs(rnea(chain, q, qd, qdd) - want)) <= 1e-9 * np.max(np.abs(want))


# --- robots Pinocchio loads (issue "Every robot Pinocchio loads") --------------------------------------

def test_a_massless_link_is_taken_with_zero_inertia_as_pinocchio_does(tmp_path):
    """Until then refused ("no <inertial>: the body moved by joint 'j1' would have no mass")."""
    path = write(tmp_path, robot(link("base"), link("l1", None), link("l2"), *ARM[3:]))
    chain = load_urdf(path)
    assert chain.joints[0].mass == 0.0 and not np.any(chain.joints[0].inertia)
    check_torques(path, chain)


def test_a_robot_with_no_mass_at_all_is_taken_with_a_warning(tmp_path):
    path = write(tmp_path, robot(link("base"), link("l1", None), link("l2", None), *ARM[3:]))
    with pytest.warns(VampcWarning, match="every body is massless"):
        chain = load_urdf(path)
    assert all(j.mass == 0.0 for j in chain.joints)


def test_a_robot_given_mass_0_and_inertia_0_everywhere_is_taken_with_the_same_warning(tmp_path):
    """Zeros written out had gone unsaid, where leaving out the <inertial> warned (an audit's); a
    DH table of zeros is said the same way."""
    zero = dict(mass=0.0, inertia=(0, 0, 0, 0, 0, 0))
    path = write(tmp_path, robot(link("base"), link("l1", **zero), link("l2", **zero), *ARM[3:]))
    with pytest.warns(VampcWarning, match="every link moved by a joint has mass 0 and inertia 0: every "
                                          "body is massless"):
        load_urdf(path)
    one = write(tmp_path, robot(link("base"), link("l1", **zero), link("l2"), *ARM[3:]), "one.urdf")
    with warnings.catch_warnings():
        warnings.simplefilter("error")               # (one massive body: nothing said)
        load_urdf(one)
    import yaml

    from vampc.robot import load_robot
    table = yaml.safe_load((EXAMPLES / "planar2.yaml").read_text())
    for row in table["joints"]:
        row["mass"], row["inertia"] = 0, [0] * 6
    (tmp_path / "z.yaml").write_text(yaml.safe_dump(table))
    with pytest.warns(VampcWarning, match="every joint's link has mass 0 and inertia 0: every body is "
                                          "massless"):
        load_robot(tmp_path / "z.yaml")


def test_an_inertia_off_by_a_rounding_error_is_taken_with_a_warning(tmp_path):
    """Eigenvalues (-1e-7, 0.01, 0.02): negative by 5e-6 of the largest entry, under NEARLY_PSD."""
    skew = (0.01, 0, 0, 0.02, 0, -1e-7)
    path = write(tmp_path, robot(link("base"), link("l1", 1.0, inertia=skew), link("l2"), *ARM[3:]))
    with pytest.warns(VampcWarning, match=r"link 'l1': inertia is not positive semi-definite .+ "
                                          "taken as a rounding error"):
        chain = load_urdf(path)
    check_torques(path, chain)


def test_an_inertia_off_by_a_negligible_part_of_the_robots_is_taken_without_a_word(tmp_path):
    """iCub's files write ixz="1.35525e-20" beside a zero diagonal (eigenvalues -1.4e-20, 0,
    1.4e-20), six links of it, each warned of on every command (a new user's find). Off by at most
    1e-12 of the robot's largest inertia entry (here 0.01) it is taken silently; the same link in a
    robot whose inertias are all that small is still warned of."""
    import warnings as w
    noise = (0, 0, 1.35525e-20, 0, 0, 0)
    path = write(tmp_path, robot(link("base"), link("l1", 1.0, inertia=noise), link("l2"), *ARM[3:]))
    with w.catch_warnings():
        w.simplefilter("error")
        chain = load_urdf(path)
    check_torques(path, chain)
    tiny = write(tmp_path, robot(link("base", 1.0, inertia=(1e-20, 0, 0, 1e-20, 0, 1e-20)),
                                 link("l1", 1.0, inertia=noise),
                                 link("l2", 1.0, inertia=(1e-20, 0, 0, 1e-20, 0, 1e-20)), *ARM[3:]),
                 name="tiny.urdf")
    with pytest.warns(VampcWarning, match=r"link 'l1': inertia is not positive semi-definite"):
        load_urdf(tiny)


def test_an_improper_inertia_is_taken_as_written_when_asked(tmp_path):
    """romeo_laas_small's hip link has eigenvalues (-0.0027, 0.040, 0.054), far beyond a rounding
    error: refused by default (URDF_ERRORS), taken with a warning by --accept-improper-inertia, and
    the torques are then Pinocchio's, which does not check."""
    path = write(tmp_path, robot(link("base"), link("l1", 1.0, inertia=(1, 2, 0, 1, 0, 1)), link("l2"),
                                 *ARM[3:]))
    with pytest.warns(VampcWarning, match=r"link 'l1': inertia is not positive semi-definite "
                                          r"\(eigenvalues -1, 1, 3\): taken as written"):
        chain = load_urdf(path, accept_improper_inertia=True)
    check_torques(path, chain)
    with pytest.raises(VampcError):
        load_urdf(path)                      # the next load is strict again


def test_accepting_improper_inertias_where_none_is_says_it_has_no_effect(tmp_path):
    """As --mimic and --floating-base say where they do nothing (it was silent: an options
    audit's find); where an inertia is taken so, the warning is that one's, not this."""
    path = write(tmp_path, robot(*ARM))
    with pytest.warns(VampcWarning, match="no inertia needed it; --accept-improper-inertia has no "
                                          "effect"):
        load_urdf(path, accept_improper_inertia=True)
    improper = write(tmp_path, robot(link("base"), link("l1", 1.0, inertia=(1, 2, 0, 1, 0, 1)),
                                     link("l2"), *ARM[3:]))
    import warnings
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        load_urdf(improper, accept_improper_inertia=True)
    assert not any("no effect" in str(w.message) for w in said)
    assert any("taken as written" in str(w.message) for w in said)


def test_a_robot_without_a_name_is_named_after_its_file(tmp_path):
    text = robot(*ARM).replace('<robot name="r">', "<robot>")
    assert "<robot>" in text
    path = write(tmp_path, text)
    with pytest.warns(VampcWarning, match="<robot> has no name; calling it"):
        chain = load_urdf(path)
    assert chain.name == path.stem


def test_a_mimic_joint_is_an_ordinary_joint_as_pinocchio_reads_it_by_default(tmp_path):
    """Until then refused ("mimic joints are not supported"): its own q, q̇, q̈ and torque, as
    pin.buildModelFromUrdf gives it without mimic=True."""
    path = write(tmp_path, robot(*ARM[:4], joint("j2", "revolute", "l1", "l2",
                                                extra='<mimic joint="j1" multiplier="2"/>')))
    with pytest.warns(VampcWarning, match="joint 'j2' mimics joint 'j1': taken as ordinary joints"):
        chain = load_urdf(path)
    assert [j.name for j in chain.joints] == ["j1", "j2"]
    check_torques(path, chain)


@pytest.mark.parametrize("given, expected", [('lower="-1"', (-1.0, 0.0)), ('upper="1"', (0.0, 1.0)),
                                             ('lower="-1" upper="1"', (-1.0, 1.0)), ("", None)])
def test_a_limit_with_one_bound_takes_urdfs_default_for_the_other(tmp_path, given, expected):
    """<limit upper="1" effort velocity>: q = 2.5 was emulated and --random drew q in ±π (a new user's
    run); the URDF default of a missing bound is 0, as Pinocchio reads it. A <limit> with neither
    bound still gives no position interval (a common placeholder)."""
    text = robot(link("b"), link("l1"),
                 f'<joint name="j1" type="revolute"><parent link="b"/><child link="l1"/>'
                 f'<axis xyz="0 0 1"/><limit {given} effort="1" velocity="1"/></joint>')
    path = write(tmp_path, text)
    chain = load_urdf(path)
    assert chain.joints[0].limits.q == expected
    try:
        import pinocchio as pin
    except ImportError:
        return
    model = pin.buildModelFromUrdf(str(path))
    if expected is not None:
        assert (model.lowerPositionLimit[0], model.upperPositionLimit[0]) == expected


@pytest.mark.parametrize("value", ["1_0", "\uff11", "\u0663", "0x10", "1.5f"])
def test_a_number_not_written_in_decimal_is_refused(tmp_path, value):
    """float() took '1_0' as 10 and other scripts' digits ('１' as 1, '٣' as 3): a mass Pinocchio
    reads as 0 was built as 10 (a new user's run)."""
    text = robot(link("b"), link("l1").replace('value="1"', f'value="{value}"', 1),
                 '<joint name="j1" type="revolute"><parent link="b"/><child link="l1"/>'
                 '<axis xyz="0 0 1"/></joint>')
    path = write(tmp_path, text)
    assert f'value="{value}"' in path.read_text(encoding="utf-8")
    with pytest.raises(VampcError, match=rf'<mass value="{value}">: expected a finite number'):
        load_urdf(path)


FLOATING_ROOT = robot(link("world", None), link("trunk", 2.0), link("l1"),
                      '<joint name="float" type="floating"><parent link="world"/><child link="trunk"/>'
                      "</joint>",
                      '<joint name="j1" type="revolute"><parent link="trunk"/><child link="l1"/>'
                      '<axis xyz="0 0 1"/></joint>')


def test_naming_the_root_of_a_floating_robot_as_base_is_as_leaving_it_out(tmp_path):
    """--base world (the root, the default) refused the root's floating joint ('floating joints are
    not supported'), where leaving --base out floats; --base trunk dropped the floating joint
    without a word (a new user's run)."""
    path = write(tmp_path, FLOATING_ROOT)
    with pytest.warns(VampcWarning, match=r"joint 'j1' \(revolute\) has no <limit>"):
        plain = load_urdf(path)
    with pytest.warns(VampcWarning, match=r"joint 'j1' \(revolute\) has no <limit>"):
        named = load_urdf(path, base="world")
    assert plain.floating and named.floating and [j.name for j in named.joints] == ["j1"]
    assert named.base_mass == plain.base_mass == 2.0
    with pytest.warns(VampcWarning, match=r"base link 'trunk' hangs on floating joint 'float': it is "
                                          r"taken as a fixed base \(--floating-base lets it float\)"), \
            pytest.warns(VampcWarning, match=r"joint 'j1' \(revolute\) has no <limit>"):
        fixed = load_urdf(path, base="trunk")
    assert not fixed.floating
    # the floating joint's <origin> turned: gravity is turned by it, as at Pinocchio's neutral
    # pose, said (only "taken as a fixed base" was: a new user's find); unturned above, not said
    turned = write(tmp_path, FLOATING_ROOT.replace('<child link="trunk"/>',
                                                   '<child link="trunk"/><origin rpy="0.3 0 0"/>'), "t.urdf")
    with pytest.warns(VampcWarning, match=r"taken as a fixed base \(--floating-base lets it float\); "
                                          r"gravity is turned by the joint's <origin> rpy, as at "
                                          r"Pinocchio's neutral pose$"), \
            pytest.warns(VampcWarning, match=r"joint 'j1' \(revolute\) has no <limit>"):
        tilted = load_urdf(turned, base="trunk")
    assert np.allclose(tilted.gravity, [0, -9.81 * np.sin(0.3), -9.81 * np.cos(0.3)])


def test_locking_a_leader_where_its_follower_leaves_its_limits_is_said(tmp_path):
    """--mimic couple --lock lead=0.9 locked the follower at -2 * 0.9 + 0.1 = -1.7, outside its
    [-1, 1], unsaid (a new user's run). Said in a warning, not refused: the PR2 gripper's couplings
    and limits disagree, and its leader locked open must still load (a review)."""
    limit = '<limit lower="-1" upper="1" effort="1" velocity="1"/>'
    text = robot(link("b"), link("l1"), link("l2"), link("l3"),
                 f'<joint name="lead" type="revolute"><parent link="b"/><child link="l1"/>'
                 f'<axis xyz="0 1 0"/>{limit}</joint>',
                 f'<joint name="fol" type="revolute"><parent link="l1"/><child link="l2"/>'
                 f'<axis xyz="0 1 0"/>{limit}<mimic joint="lead" multiplier="-2" offset="0.1"/></joint>',
                 f'<joint name="j3" type="revolute"><parent link="l2"/><child link="l3"/>'
                 f'<axis xyz="0 1 0"/>{limit}</joint>')
    path = write(tmp_path, text)
    with pytest.warns(VampcWarning, match=r"locking 'lead' at 0\.9 locks its follower 'fol' "
                                          r"\(--mimic couple\) at -1\.7\d*, outside that joint's "
                                          r"limits \[-1\.0, 1\.0\]"):
        load_urdf(path, mimic="couple", lock={"lead": 0.9})   # (said, not refused: PR2's gripper)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        chain = load_urdf(path, mimic="couple", lock={"lead": 0.2})
    assert [j.name for j in chain.joints] == ["j3"]


def test_a_one_bound_limit_beyond_the_default_names_the_default(tmp_path):
    """<limit upper="-0.5"> with no lower: 'lower 0 is above upper -0.5' named a lower bound the
    file does not have (a review)."""
    text = robot(link("b"), link("l1"),
                 '<joint name="j1" type="revolute"><parent link="b"/><child link="l1"/>'
                 '<axis xyz="0 0 1"/><limit upper="-0.5" effort="1" velocity="1"/></joint>')
    with pytest.warns(VampcWarning, match=r"joint 'j1': <limit> lower not given \(URDF's default, 0\) "
                                          r"is above upper -0\.5; read as no position limits"):
        load_urdf(write(tmp_path, text))


def test_limits_lower_above_upper_are_none_as_bullet_reads_them_and_a_capsule_is_not_read(tmp_path):
    """Files made for pybullet write <limit lower="1" upper="0"> for a joint without position
    limits ("values ignored in case upper limit < lower limit", pybullet's guide), and Bullet's
    humanoid a <capsule> collision shape: both were refused (a trial of public URDF collections),
    though Pinocchio reads them and the dynamics needs neither. The limits are read as none, said
    once for the joints so written; the shape is not read; the torques are those of the file
    without them, by Pinocchio's rnea."""
    body = ('<inertial><mass value="1"/><origin xyz="0.1 0 0"/><inertia ixx="0.01" iyy="0.02" '
            'izz="0.03" ixy="0" ixz="0" iyz="0"/></inertial>')
    capsule = ('<collision><geometry><capsule radius="0.05" length="0.3"/></geometry></collision>'
               '<visual><geometry><box/></geometry></visual>')    # (a box without size: yourdfpy's KeyError)
    joints = ''.join(f'<joint name="j{k}" type="revolute"><parent link="l{k - 1}"/><child link="l{k}"/>'
                     f'<origin xyz="0.3 0 0"/><axis xyz="0 {k % 2} {1 - k % 2}"/>'
                     f'<limit lower="1" upper="0" effort="5" velocity="2"/></joint>' for k in (1, 2))
    links = link("l0") + "".join(f'<link name="l{k}">{body}{capsule}</link>' for k in (1, 2))
    path = write(tmp_path, robot(links, joints))
    with pytest.warns(VampcWarning) as seen:
        chain = load_urdf(path, lock={})
    said = [str(w.message) for w in seen if "is above" in str(w.message)]
    assert said == [f"{path}: joint 'j1' (and 'j2'): <limit> lower 1 is above upper 0; read as no "
                    "position limits, as Bullet reads them (--lock then takes any position)"], said
    assert all(j.limits.q is None and j.limits.tau == 5 for j in chain.joints)
    plain = write(tmp_path, robot(link("l0") + "".join(f'<link name="l{k}">{body}</link>' for k in (1, 2)),
                                  joints.replace(' lower="1" upper="0"', "")), "plain.urdf")
    check_torques(plain, chain)


TILTED_MOUNT = """<robot name="tilted">
  <link name="world"/>
  <joint name="mount" type="fixed"><parent link="world"/><child link="pedestal"/>
    <origin xyz="0.1 0 0.2" rpy="0.5 -0.3 0.2"/></joint>
  <link name="pedestal"/>
  <joint name="j1" type="revolute"><parent link="pedestal"/><child link="a"/><axis xyz="0 1 0"/>
    <origin xyz="0 0 0.1"/><limit lower="-3" upper="3" effort="10" velocity="3"/></joint>
  <link name="a"><inertial><origin xyz="0.2 0 0"/><mass value="1.5"/>
    <inertia ixx="0.01" iyy="0.02" izz="0.03" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="j2" type="revolute"><parent link="a"/><child link="b"/><axis xyz="1 0 0"/>
    <origin xyz="0.4 0 0" rpy="0.3 0 0"/><limit lower="-3" upper="3" effort="10" velocity="3"/></joint>
  <link name="b"><inertial><origin xyz="0.1 0.05 0"/><mass value="0.7"/>
    <inertia ixx="0.01" iyy="0.02" izz="0.03" ixy="0" ixz="0" iyz="0"/></inertial></link>
</robot>"""


@pytest.mark.parametrize("base", [None, "pedestal"])
def test_a_base_on_a_tilted_mount_feels_the_roots_gravity(tmp_path, base):
    """--base LINK on a link fixed to the root at a tilt read [0, 0, -9.81] in LINK's own frame:
    torques 0.99 N·m off Pinocchio's rnea on the same file (a new user's find). Gravity is the root's,
    turned into LINK's frame: against Pinocchio, with and without --base."""
    pin = pytest.importorskip("pinocchio")
    from vampc.dynamics.reference import rnea
    from vampc.emulator.host import random_trajectory
    path = write(tmp_path, TILTED_MOUNT)
    chain = load_urdf(path, base=base)
    assert [j.name for j in chain.joints] == ["j1", "j2"]
    traj = random_trajectory(chain, 8, 5)
    pm = pin.buildModelFromUrdf(str(path))
    data = pm.createData()
    want = np.array([pin.rnea(pm, data, traj.q[s], traj.qd[s], traj.qdd[s]) for s in range(traj.count)])
    got = rnea(chain, traj.q, traj.qd, traj.qdd)
    assert np.max(np.abs(got - want)) <= 1e-12 * np.max(np.abs(want))


# Two joints above a tilted mount: w0, and w, which mimics it (multiplier 1.5, offset 0.7).
ABOVE_THE_MOUNT = TILTED_MOUNT.replace(
    """  <joint name="mount" type="fixed"><parent link="world"/><child link="pedestal"/>""",
    """  <joint name="w0" type="revolute"><parent link="world"/><child link="x"/><axis xyz="0 1 1"/>
    <origin xyz="0 0 0.1" rpy="0.1 0 0"/><limit lower="-3" upper="3" effort="10" velocity="3"/></joint>
  <link name="x"><inertial><origin xyz="0.1 0 0"/><mass value="1"/>
    <inertia ixx="0.01" iyy="0.02" izz="0.03" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="w" type="revolute"><parent link="x"/><child link="pre"/><axis xyz="1 0 0"/>
    <origin xyz="0 0 0.1" rpy="0 0.4 0"/><limit lower="-3" upper="3" effort="10" velocity="3"/>
    <mimic joint="w0" multiplier="1.5" offset="0.7"/></joint>
  <link name="pre"/>
  <joint name="mount" type="fixed"><parent link="pre"/><child link="pedestal"/>""")


@pytest.mark.parametrize("mimic, lock, said", [
    ("ordinary", {}, "w0 at 0, w at 0"), ("ordinary", {"w0": 0.5}, "w0 at 0.5, w at 0"),
    ("ordinary", {"w0": 0.5, "w": -0.3}, "w0 at 0.5, w at -0.3"),
    ("couple", {}, "w0 at 0, w at 0.7"), ("couple", {"w0": 0.5}, "w0 at 0.5, w at 1.45")])
def test_joints_above_the_base_turn_gravity_where_they_are_locked(tmp_path, mimic, lock, said):
    """--base below movable joints: gravity is turned through them at their --lock values (a lock of
    one was dropped, "no effect"), a coupled follower at its leader's multiple plus offset (it was
    taken at 0: 3.5 N·m off Pinocchio's mimic model; a review's find), others at 0, and the warning
    says where each is. Against Pinocchio on the whole file, those joints there and still."""
    pin = pytest.importorskip("pinocchio")
    from vampc.dynamics.reference import rnea
    from vampc.emulator.host import random_trajectory
    path = write(tmp_path, ABOVE_THE_MOUNT)
    with pytest.warns(VampcWarning, match=rf"--base pedestal: the joints above it are cut away \({said}:"):
        chain = load_urdf(path, base="pedestal", lock=lock, mimic=mimic)
    assert [j.name for j in chain.joints] == ["j1", "j2"]
    traj = random_trajectory(chain, 8, 5)
    pm = pin.buildModelFromUrdf(str(path), mimic=True) if mimic == "couple" else \
        pin.buildModelFromUrdf(str(path))
    data = pm.createData()
    at = {"w0": lock.get("w0", 0.0)} | ({} if mimic == "couple" else {"w": lock.get("w", 0.0)})
    want = []
    for s in range(traj.count):
        q, v, a = pin.neutral(pm), np.zeros(pm.nv), np.zeros(pm.nv)
        for name, value in at.items():
            q[pm.idx_qs[pm.getJointId(name)]] = value
        for k, name in enumerate(("j1", "j2")):
            i = pm.getJointId(name)
            q[pm.idx_qs[i]], v[pm.idx_vs[i]], a[pm.idx_vs[i]] = traj.q[s, k], traj.qd[s, k], traj.qdd[s, k]
        tau = pin.rnea(pm, data, q, v, a)
        want.append([tau[pm.idx_vs[pm.getJointId(name)]] for name in ("j1", "j2")])
    want = np.array(want)
    got = rnea(chain, traj.q, traj.qd, traj.qdd)
    assert np.max(np.abs(got - want)) <= 1e-12 * np.max(np.abs(want))


# A planar joint, its frame tilted, carries the mount.
PLANAR_ABOVE = TILTED_MOUNT.replace(
    """  <joint name="mount" type="fixed"><parent link="world"/><child link="pedestal"/>""",
    """  <joint name="p" type="planar"><parent link="world"/><child link="cart"/><axis xyz="0 0 1"/>
    <origin rpy="1.2 0 0"/></joint>
  <link name="cart"><inertial><mass value="1"/>
    <inertia ixx="0.01" iyy="0.02" izz="0.03" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="mount" type="fixed"><parent link="cart"/><child link="pedestal"/>""")


def test_a_planar_joint_above_the_base_is_said_and_cannot_be_locked(tmp_path):
    """A planar joint above --base was cut away saying nothing, and --lock p=0.5 was taken and
    ignored (its one position cannot place three degrees of freedom; noticed in a review). It is
    named at its <origin>, where Pinocchio's neutral configuration has it (against Pinocchio), and
    its lock is refused."""
    pin = pytest.importorskip("pinocchio")
    from vampc.dynamics.reference import rnea
    from vampc.emulator.host import random_trajectory
    path = write(tmp_path, PLANAR_ABOVE)
    with pytest.warns(VampcWarning, match=r"--base pedestal: the joints above it are cut away \(p \(planar\) "
                                          r"at its <origin>:"):
        chain = load_urdf(path, base="pedestal")
    traj = random_trajectory(chain, 6, 5)
    pm = pin.buildModelFromUrdf(str(path))
    data = pm.createData()
    want = []
    for s in range(traj.count):
        q, v, a = pin.neutral(pm), np.zeros(pm.nv), np.zeros(pm.nv)
        q[-2:], v[-2:], a[-2:] = traj.q[s], traj.qd[s], traj.qdd[s]
        want.append(pin.rnea(pm, data, q, v, a)[-2:])
    got = rnea(chain, traj.q, traj.qd, traj.qdd)
    assert np.max(np.abs(got - np.array(want))) <= 1e-12 * np.max(np.abs(want))
    assert_error(lambda: load_urdf(path, base="pedestal", lock={"p": 0.5}), path,
                 r"lock p: a planar joint moves in three degrees of freedom; --lock gives one position "
                 r"\(above --base it is held at its <origin>\)")


def test_a_lock_that_places_nothing_is_said_to_have_no_effect(tmp_path):
    """--lock of a joint on another branch than the one up to --base (a leg, when the base is the
    torso), or above a floating base, was taken and ignored, saying nothing (a new user's find)."""
    side = ABOVE_THE_MOUNT.replace("</robot>", """  <joint name="s" type="revolute"><parent link="world"/><child link="side"/>
    <axis xyz="1 0 0"/><limit lower="-3" upper="3" effort="10" velocity="3"/></joint>
  <link name="side"><inertial><mass value="1"/>
    <inertia ixx="0.01" iyy="0.02" izz="0.03" ixy="0" ixz="0" iyz="0"/></inertial></link>
</robot>""")
    path = write(tmp_path, side)
    with pytest.warns(VampcWarning) as said:
        chain = load_urdf(path, base="pedestal", lock={"s": 0.3, "w0": 0.5})
    texts = [str(w.message) for w in said]
    assert f"{path}: joint 's' is neither below the base link 'pedestal' nor on the way up to it (--base " \
           "cuts its branch away); --lock s=... has no effect" in texts
    assert any("the joints above it are cut away (w0 at 0.5, w at 0:" in t for t in texts)   # (w0's placed)
    assert [j.name for j in chain.joints] == ["j1", "j2"]
    with pytest.warns(VampcWarning) as said:
        load_urdf(path, base="pedestal", lock={"w0": 0.5}, floating=True, mimic="couple")
    texts = [str(w.message) for w in said]
    assert f"{path}: joint 'w0' is above the floating base 'pedestal' (whose motion is the host's " \
           "input); --lock w0=... has no effect" in texts
    # w, coupled to w0, is locked by --mimic couple, not by the user: nothing said of it (review)
    assert not any("--lock w=" in t for t in texts), texts


def test_an_error_after_the_base_comes_without_the_gravity_warning(tmp_path):
    """The gravity warning is said once the robot is made: an error about the tip is one line."""
    path = write(tmp_path, ABOVE_THE_MOUNT)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert_error(lambda: load_urdf(path, base="pedestal", tip="pedestal"), path,
                     "no movable joints between base link 'pedestal' and tip link 'pedestal'")


def test_a_joint_above_the_base_at_0_outside_its_limits_is_said_so(tmp_path):
    """A joint above the base taken at 0 where 0 is outside its limits (a quadruped's calf, say):
    the warning says so, since --lock gives it a position within them (a new user's find)."""
    path = write(tmp_path, ABOVE_THE_MOUNT.replace('<limit lower="-3" upper="3" effort="10" velocity="3"/></joint>\n'
                                                   '  <link name="x">',
                                                   '<limit lower="0.2" upper="1" effort="10" velocity="3"/></joint>\n'
                                                   '  <link name="x">', 1))
    assert 'lower="0.2"' in path.read_text()
    with pytest.warns(VampcWarning, match=r"\(w0 at 0, outside its limits \[0\.2, 1\], w at 0:"):
        load_urdf(path, base="pedestal")
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        load_urdf(path, base="pedestal", lock={"w0": 0.5})
    assert ["outside" not in str(w.message) for w in said] == [True] * len(said) and said


def test_a_follower_above_the_base_of_a_leader_below_it(tmp_path):
    """--mimic couple, a follower above --base whose leader is one of the robot's joints below it:
    the base would move with the leader; it was taken with the leader at 0, saying nothing (a
    review's find). Refused; with the leader locked, the follower is placed where the lock puts it,
    and --mimic couple is not said to have no effect."""
    inertial = ('<inertial><origin xyz="0.1 0 0"/><mass value="1"/><inertia ixx="0.01" iyy="0.01" '
                'izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>')
    links = "".join(f'<link name="{n}">{inertial}</link>' for n in ("root", "base", "l1", "l2"))
    joints = "".join(f'<joint name="{j}" type="continuous"><parent link="{p}"/><child link="{c}"/>'
                     f'<origin xyz="0.2 0 0" rpy="0.3 0 0"/><axis xyz="1 0 0"/>{extra}</joint>'
                     for j, p, c, extra in (("w", "root", "base", '<mimic joint="j1" multiplier="2"/>'),
                                            ("j1", "base", "l1", ""), ("j2", "l1", "l2", "")))
    path = write(tmp_path, f'<robot name="b">{links}{joints}</robot>')
    assert_error(lambda: load_urdf(path, base="base", mimic="couple"), path,
                 r"joint 'w': above the base link 'base', follows joint 'j1' below it \(--mimic couple\): "
                 r"the base would move with it; lock 'j1', or choose another --base")
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        chain = load_urdf(path, base="base", mimic="couple", lock={"j1": 0.5})
    texts = [str(w.message) for w in said]
    assert [j.name for j in chain.joints] == ["j2"]
    assert not any("no effect" in t for t in texts) and any("(w at 1:" in t for t in texts), texts


def test_a_lock_of_a_cut_away_leader_whose_follower_is_kept_is_not_said_to_do_nothing(tmp_path):
    """A --mimic couple leader on a branch --base cuts away, whose follower is below the base: its
    lock places the follower, and without it the load asks for it; the warning called it useless
    (review)."""
    inertial = ('<inertial><origin xyz="0.1 0 0"/><mass value="1"/><inertia ixx="0.01" iyy="0.01" '
                'izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>')
    links = "".join(f'<link name="{n}">{inertial}</link>' for n in ("world", "torso", "leg", "arm", "hand"))
    joints = "".join(f'<joint name="{j}" type="continuous"><parent link="{p}"/><child link="{c}"/>'
                     f'<origin xyz="0.2 0 0"/><axis xyz="1 0 0"/>{extra}</joint>'
                     for j, p, c, extra in (("j0", "world", "torso", ""), ("L", "world", "leg", ""),
                                            ("A", "torso", "arm", '<mimic joint="L" multiplier="2"/>'),
                                            ("B", "arm", "hand", "")))
    path = write(tmp_path, f'<robot name="m">{links}{joints}</robot>')
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        chain = load_urdf(path, base="torso", lock={"L": 0.3}, mimic="couple")
    assert [j.name for j in chain.joints] == ["B"]
    assert not any("--lock L=" in str(w.message) for w in said), [str(w.message) for w in said]


def test_a_moving_joint_without_a_limit_is_read_with_a_warning(tmp_path):
    """The URDF specification requires <limit> of revolute and prismatic joints, and Pinocchio
    refuses a file without; vampc, which says it reads URDF as Pinocchio does, took one silently
    (a new user's find). It warns once, naming the first and counting the others; a continuous
    joint needs none."""
    def joint(name, kind, parent, child, limit=True):
        lim = '<limit lower="-1" upper="1" effort="5" velocity="2"/>' if limit else ""
        return (f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
                f'<origin xyz="0 0 0.1"/><axis xyz="0 0 1"/>{lim}</joint>')
    inertial = ('<inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" '
                'ixz="0" iyz="0"/></inertial>')
    links = "".join(f'<link name="l{k}">{inertial}</link>' for k in range(4))
    for limits, said in (((True, True, True), None), ((True, False, False), "'j2' (prismatic) and 'j3' have")):
        kinds = ("continuous", "prismatic", "revolute")
        body = "".join(joint(f"j{k + 1}", kinds[k], f"l{k}", f"l{k + 1}", limits[k] or kinds[k] == "continuous")
                       for k in range(3))
        path = tmp_path / "arm.urdf"
        path.write_text(f'<robot name="arm">{links}{body}</robot>')
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            chain = load_robot(path)
        told = [str(w.message) for w in caught if issubclass(w.category, VampcWarning)]
        assert chain.n == 3
        if said is None:
            assert not any("<limit>" in t for t in told), told
        else:
            assert told == [f"{path}: joint {said} no <limit>, which the URDF specification "
                            "requires of revolute and prismatic joints (Pinocchio refuses the file); "
                            "read as unlimited"], told


def test_a_limit_without_effort_or_velocity_is_read_with_a_warning(tmp_path):
    """A <limit> must give effort and velocity (Pinocchio refuses a file whose <limit> lacks
    either); one without velocity was read as no speed limit in silence, and the look-ahead planned
    without it (a look-ahead audit's find). One warning names the first and what it lacks."""
    inertial = ('<inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" '
                'ixz="0" iyz="0"/></inertial>')
    links = "".join(f'<link name="l{k}">{inertial}</link>' for k in range(3))
    def joint(name, parent, child, limit):
        return (f'<joint name="{name}" type="revolute"><parent link="{parent}"/><child link="{child}"/>'
                f'<origin xyz="0 0 0.1"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" {limit}/></joint>')
    for limits, said in ((('effort="5" velocity="2"', 'effort="5" velocity="2"'), None),
                         (('effort="5"', 'effort="5" velocity="2"'), "joint 'j1' has a <limit> without "
                          "velocity, which the URDF specification requires (Pinocchio refuses the "
                          "file); read as no speed limit"),
                         (('', 'velocity="2"'), "joint 'j1' (and 'j2') has a <limit> without "
                          "effort or velocity, which the URDF specification requires (Pinocchio "
                          "refuses the file); read as no effort limit and no speed limit")):
        path = tmp_path / "arm.urdf"
        path.write_text(f'<robot name="arm">{links}{joint("j1", "l0", "l1", limits[0])}'
                        f'{joint("j2", "l1", "l2", limits[1])}</robot>')
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            chain = load_robot(path)
        told = [str(w.message) for w in caught if issubclass(w.category, VampcWarning)]
        assert told == ([] if said is None else [f"{path}: {said}"]), told
        assert chain.joints[0].limits.qd == (2.0 if 'velocity="2"' in limits[0] else None)


def test_a_number_with_a_space_after_it_is_read_with_a_warning(tmp_path):
    """urdfdom does not read '2.0 ' ("not a float"), and Pinocchio drops that <inertial>: vampc read
    it as 2 without a word (an audit's). The warning had said urdfdom refuses the file: Pinocchio
    loads it, a bad inertia entry zeroing the rotational inertia alone (the Unitree dex2_5 hands'
    line break after an ixz, a URDF trial's): each said as Pinocchio reads it, checked with it when
    it is installed. A space before the number is urdfdom's reading too: no warning."""
    text = robot(link("base"), link("l1", mass=2.0), link("l2"), *ARM[3:])
    path = write(tmp_path, text.replace('<mass value="2"', '<mass value="2 "', 1))
    assert '<mass value="2 "' in path.read_text()
    with pytest.warns(VampcWarning, match=r"link 'l1': <mass value=\"2 \">: a space or line break after the "
                                          r"number, which urdfdom \(Pinocchio's URDF reader\) does not read as "
                                          r"a number \(Pinocchio drops the link's <inertial>\); read here as 2"):
        chain = load_urdf(path)
    assert chain.joints[0].mass == 2.0
    l1 = link("l1", mass=2.0)
    entry = write(tmp_path, text.replace(l1, l1.replace('ixz="0"', 'ixz="0\r\n"')), "i.urdf")
    with pytest.warns(VampcWarning, match=r"link 'l1': <inertia ixz=\"0 \">: a space or line break after "
                                          r"the number, .* \(Pinocchio zeroes the link's rotational inertia, "
                                          r"keeping its mass and centre of mass\); read here as 0"):
        load_urdf(entry)
    try:
        import pinocchio as pin
    except ImportError:
        pin = None
    if pin is not None:                # (what the warnings say of Pinocchio, seen in Pinocchio)
        dropped = pin.buildModelFromUrdf(str(path)).inertias[1]
        assert dropped.mass == 0 and not dropped.inertia.any()
        zeroed = pin.buildModelFromUrdf(str(entry)).inertias[1]
        assert zeroed.mass == 2 and not zeroed.inertia.any() and zeroed.lever.any()
    before = write(tmp_path, text.replace('<mass value="2"', '<mass value=" 2"', 1), "b.urdf")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        load_urdf(before)


def test_a_xacro_file_is_refused_not_read_as_fewer_joints(tmp_path):
    """A xacro file given as a URDF: every element in xacro's namespace was skipped, so the joints
    its macros make were lost without a word (3 joints read as 1: a new user's). Refused, naming
    the first xacro element's line; xacro's own output, whose root keeps the namespace unused,
    loads; a .xacro name is told to run xacro."""
    ns = 'xmlns:xacro="http://www.ros.org/wiki/xacro"'
    seg = ('<xacro:macro name="seg" params="n parent">'
           + link("l${n}") + joint("j${n}", "revolute", "${parent}", "l${n}") + "</xacro:macro>")
    body = [link("base"), link("l1"), joint("j1", "revolute", "base", "l1")]
    text = robot(seg, *body, '<xacro:seg n="2" parent="l1"/>').replace("<robot ", f"<robot {ns} ")
    path = write(tmp_path, text)
    # (into another name: `xacro r.urdf > r.urdf` would empty the file before xacro read it)
    assert_error(lambda: load_robot(path), path, r"line 3: <xacro:macro>: a xacro element, which "
                 r"no URDF reader expands; run xacro first \(xacro r\.urdf > r-expanded\.urdf\) "
                 r"and give the URDF")
    # PR2-era files bind xacro: to Gazebo's interface schema; a file that never binds it
    pr2 = write(tmp_path, text.replace("http://www.ros.org/wiki/xacro", "http://playerstage."
                                       "sourceforge.net/gazebo/xmlschema/#interface"), "pr2.urdf")
    assert_error(lambda: load_robot(pr2), pr2, r"line 3: <xacro:macro>: a xacro element.*")
    unbound = write(tmp_path, text.replace(f" {ns}", ""), "u.urdf")
    assert_error(lambda: load_robot(unbound), unbound, r"line 3: not well-formed XML: Namespace "
                 r"prefix xacro .* \(a xacro file: run xacro first \(xacro u\.urdf > "
                 r"u-expanded\.urdf\) and give the URDF\)")
    included = write(tmp_path, robot(*body, '<xacro:include filename="$(find arm)/a.xacro"/>')
                     .replace("<robot ", f"<robot {ns} "), "i.urdf")
    assert_error(lambda: load_robot(included), included, r"line 6: <xacro:include>: a xacro element.*")
    expanded = write(tmp_path, robot(*body).replace("<robot ", f"<robot {ns} "), "e.urdf")
    assert load_robot(expanded).n == 1
    named = write(tmp_path, text, "arm.urdf.xacro")
    assert_error(lambda: load_robot(named), named, r"unknown robot file extension '\.xacro': a xacro "
                 r"file, which expands to a URDF: run xacro first \(xacro arm\.urdf\.xacro > "
                 r"arm\.urdf\) and give the URDF \(expected .*\)")
    bare = write(tmp_path, text, "arm.xacro")
    assert_error(lambda: load_robot(bare), bare, r"unknown robot file extension '\.xacro': a xacro "
                 r"file, which expands to a URDF: run xacro first \(xacro arm\.xacro > arm\.urdf\) "
                 r"and give the URDF \(expected .*\)")


def test_an_axis_too_long_to_square_turns_about_its_direction(tmp_path):
    """The squares of an axis of 1e200 1e200 0 overflowed in normalizing it, and the joint turned
    about -z instead, without a word, `--check` passing (a new user's find): it turns about its
    direction, as 1 1 0, whose torques are Pinocchio's."""
    unit = write(tmp_path, robot(*ARM[:4], joint("j2", "revolute", "l1", "l2", axis=(1, 1, 0))), "u.urdf")
    huge = write(tmp_path, robot(*ARM[:4], joint("j2", "revolute", "l1", "l2", axis=(1e200, 1e200, 0))),
                 "h.urdf")
    want, got = load_urdf(unit), load_urdf(huge)
    for a, b in zip(want.joints, got.joints):
        np.testing.assert_allclose(b.phi, a.phi, rtol=0, atol=1e-15)
        np.testing.assert_allclose(b.p_fixed, a.p_fixed, rtol=0, atol=1e-15)
    check_torques(unit, got)


@pytest.mark.parametrize("edit, said", [
    (('<origin xyz="0 0 0.10000000000000001"', '<origin xyz="1 0 0"/><origin xyz="0 0 0.10000000000000001"'),
     r"joint 'j1': a second <origin> \(line \d+\) is not read \(the first is, as by urdfdom, Pinocchio's "
     r"reader\)"),
    (('<axis xyz="0 0 1"/>', '<axis xyz="0 0 1"/><axis xyz="1 0 0"/>'), r"joint 'j1': a second <axis>"),
    (('<axis xyz="0 0 1"/>', '<axis xyz="0 0 1"/><mimic joint="j2"/><mimic joint="j2" multiplier="5"/>'),
     r"joint 'j1': a second <mimic>"),
    (("</inertial></link>", '</inertial><inertial><mass value="50"/><inertia ixx="1" ixy="0" ixz="0" '
      'iyy="1" iyz="0" izz="1"/></inertial></link>'),
     r"link 'base': a second <inertial> \(line \d+\) is not read"),
    (('<mass value="1"/>', '<mass value="1"/><mass value="9"/>'), r"link 'base' <inertial>: a second <mass>"),
    (('<origin xyz="0 0 0.10000000000000001"', '<origin xzy="0 0 0.10000000000000001"'),
     r"joint 'j1': <origin xzy=...> \(line \d+\) is not a URDF attribute \(did you mean xyz\?\); it is "
     r"not read"),
    (('<axis xyz="0 0 1"/>', '<axes xyz="0 0 1"/>'),
     r"joint 'j1': <axes> \(line \d+\) is not a URDF element there \(did you mean <axis>\?\); it is not "
     r"read"),
    (('effort="1"', 'efort="1"'), r"joint 'j1': <limit efort=...> .* \(did you mean effort\?\)"),
    ((link("l2"), link("l2").replace("inertial>", "inertal>")), r"link 'l2': <inertal> \(line \d+\) is not read \(did you mean "
     r"<inertial>\?\): a link's mass and inertia are read inside its <inertial>"),
    (('<link name="l2">', '<link name="l2"><mass value="3"/>'), r"link 'l2': <mass> \(line \d+\) is not "
     r"read: a link's mass and inertia are read inside its <inertial>"),
    # (a new user's: each left out without a word)
    (('<link name="l2">', '<link name="l2"><origin xyz="1 0 0"/>'), r"link 'l2': <origin> \(line \d+\) "
     r"is not read: a link's origins are those of its <inertial>, <visual> and <collision>"),
    (('<child link="l1"/>', '<child link="l1"><origin xyz="1 0 0"/></child>'), r"joint 'j1': <origin> "
     r"inside <child> \(line \d+\) is not read: a joint's <origin> goes directly in the <joint>"),
    (("</robot>", '<robot name="x"><link name="ghost"/></robot></robot>'), r"a <robot> inside <robot> "
     r"\(line \d+\) is not read, nor anything in it")])
def test_what_urdfdom_leaves_out_is_said(tmp_path, edit, said):
    """A second <origin>, <axis>, <mimic>, <inertial> or <mass>, an attribute or element misspelt: urdfdom
    (and so Pinocchio and yourdfpy) reads the first and skips what it does not know, and so had vampc,
    without a word (a second <inertial> of 50 kg; <origin xzy=...> read as the origin 0; a new
    user's finds). One warning, naming the joint or link and the line."""
    text = robot(*ARM)
    assert edit[0] in text
    path = write(tmp_path, text.replace(edit[0], edit[1], 1))
    with pytest.warns(VampcWarning) as said_:
        load_urdf(path)
    texts = [str(w.message) for w in said_ if "not read" in str(w.message)]
    assert len(texts) == 1 and re.search(said, texts[0]), [str(w.message) for w in said_]


def test_what_a_vendor_adds_is_read_without_a_word(tmp_path):
    """Elements of another namespace, a link's other elements (<contact>, Gazebo's <gravity>) and a
    <limit>'s vendor attributes (ANYmal's command_effort) are not URDF's to read: no warning."""
    text = robot(*ARM).replace('effort="1"', 'effort="1" command_effort="2" gear_velocity="3"', 1).replace(
        "</link>", "<contact><lateral_friction value='1'/></contact><gravity>true</gravity></link>", 1)
    text = text.replace('<robot name="r">', '<robot name="r" xmlns:ext="http://example.org/ext">').replace(
        '<axis xyz="0 0 1"/>', '<axis xyz="0 0 1"/><ext:gain value="2"/>', 1)
    for added in ("command_effort", "<contact>", "<gravity>", "xmlns:ext", "<ext:gain"):
        assert added in text, added      # (each edit took: the robot had what it replaces)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        load_urdf(write(tmp_path, text))


def test_the_turn_of_a_floating_roots_origin_is_said_to_be_unused(tmp_path):
    """A floating root joint's <origin rpy> turned the base at Pinocchio's neutral pose; vampc takes the
    floating base at the world's orientation and dropped it without a word (a new user's find)."""
    turned = FLOATING_ROOT.replace("<child link=\"trunk\"/>", '<child link="trunk"/><origin xyz="0.5 0 1" '
                                   'rpy="0.3 0.4 0.5"/>')
    with pytest.warns(VampcWarning) as said:
        load_urdf(write(tmp_path, turned))
    assert any(re.search(r"joint 'float' \(floating\): the turn of its <origin> \(rpy\) is not used: the "
                         r"floating base is taken at the world's orientation", str(w.message)) for w in said)
    moved = FLOATING_ROOT.replace("<child link=\"trunk\"/>", '<child link="trunk"/><origin xyz="0.5 0 1"/>')
    with pytest.warns(VampcWarning) as said:
        load_urdf(write(tmp_path, moved, "m.urdf"))
    assert not any("origin" in str(w.message) for w in said)


def test_mimic_ordinary_on_mimics_of_fixed_joints_says_they_do_not_move(tmp_path):
    """--mimic ordinary on a file whose one <mimic> is a fixed joint's said "no joint has a <mimic>"
    (a new user's find); --mimic couple said it right."""
    text = robot(*ARM, link("l3", None), joint("f", "fixed", "l2", "l3", extra='<mimic joint="j1"/>'))
    path = write(tmp_path, text)
    for mode in ("ordinary", "couple"):
        with pytest.warns(VampcWarning, match=r"no joint that moves has a <mimic> \(the fixed joint 'f' has "
                                              rf"one, and a fixed joint does not move\); --mimic {mode} has "
                                              r"no effect"):
            load_urdf(path, mimic=mode, mimic_given=True)


@pytest.mark.parametrize("base, said", [(None, True), ("world", True), ("trunk", False)])
def test_floating_base_on_a_robot_that_floats_already_is_said_to_do_nothing(tmp_path, base, said):
    """--floating-base on a URDF whose root joint floats was taken unsaid (a new user's find, on a
    DH table's base.floating): it has no effect but where --base names the link the floating joint
    carries, which is otherwise a fixed base."""
    path = write(tmp_path, FLOATING_ROOT)
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        chain = load_urdf(path, base=base, floating=True)
    assert chain.floating
    texts = [str(w.message) for w in seen]
    assert any("the base 'trunk' floats on the file's own floating joint 'float'; --floating-base has "
               "no effect" in t for t in texts) == said, texts


def test_floating_base_on_a_dh_table_that_floats_already_is_said_to_do_nothing(tmp_path):
    text = (EXAMPLES / "planar2.yaml").read_text().replace("name:", "base: {floating: true}\nname:", 1)
    path = write(tmp_path, text, "fl.yaml")
    with pytest.warns(VampcWarning, match=r"base\.floating is true already; --floating-base has no "
                                          r"effect"):
        assert load_robot(path, floating=True).floating
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert load_robot(path).floating


def test_floating_base_on_a_dh_table_that_says_fixed_is_said_to_override_it(tmp_path):
    """`base: {floating: false}` and --floating-base: the base floated, nothing said, and the base
    link's mass, refused without the option, was taken silently with it (a new user's find)."""
    text = (EXAMPLES / "planar2.yaml").read_text().replace(
        "name:", "base: {floating: false, mass: 3.0}\nname:", 1)
    path = write(tmp_path, text, "fixed.yaml")
    with pytest.warns(VampcWarning, match=r"fixed\.yaml: base\.floating is false; --floating-base "
                                          r"floats the base all the same"):
        assert load_robot(path, floating=True).floating
    with pytest.raises(VampcError, match="counts only for a floating base"):
        load_robot(path)


def test_a_urdf_with_a_default_namespace_is_read_as_urdfdom_reads_it(tmp_path):
    """<robot xmlns="..."> (Drake-style) put every element in that namespace, and the file was said
    to have "no <link>" (a new user's find): read by the elements' own names, as urdfdom does, its
    torques are Pinocchio's on the same file."""
    text = robot(*ARM).replace('<robot name="r">', '<robot name="r" xmlns="http://www.ros.org/urdf">')
    path = write(tmp_path, text)
    chain = load_urdf(path)
    plain = load_urdf(write(tmp_path, robot(*ARM), "plain.urdf"))
    assert [j.name for j in chain.joints] == [j.name for j in plain.joints] == ["j1", "j2"]
    check_torques(path, chain)


def test_an_axis_element_without_xyz_is_refused_on_a_moving_joint(tmp_path):
    """<axis>0 1 0</axis> (the axis as text) and <axis/> were read as 1 0 0, URDF's default when
    there is no <axis>; urdfdom leaves the axis 0 0 0 then, and Pinocchio's torque is 0 (a new
    user's find, exit 0 unsaid). Read as urdfdom reads it, it is refused as an axis of 0 0 0 is,
    where the joint is used (a review's find: refused anywhere in the file, and before a joint
    type the file gets wrong); on a fixed joint it is not read."""
    said = re.escape("joint 'j2': axis is zero (its <axis> gives xyz=\"0 0 0\" or no xyz, which "
                     "urdfdom, Pinocchio's reader, reads so; README, URDF)")
    for element in ("<axis>0 1 0</axis>", "<axis/>", '<axis xyz="0 0 0"/>'):
        body = robot(*ARM[:4], joint("j2", "revolute", "l1", "l2").replace('<axis xyz="0 0 1"/>', element))
        path = write(tmp_path, body, "a.urdf")
        assert_error(lambda: load_urdf(path), path, said)
        # above the base, cut away at 0: not looked at, as with xyz="0 0 0"
        above = write(tmp_path, robot(*ARM[:3], ARM[3].replace('<axis xyz="0 0 1"/>', element), ARM[4]),
                      "above.urdf")
        with pytest.warns(VampcWarning, match="the joints above it are cut away"):
            assert [j.name for j in load_urdf(above, base="l1").joints] == ["j2"]
    hinge = write(tmp_path, robot(*ARM[:4], joint("j2", "hinge", "l1", "l2").replace(
        '<axis xyz="0 0 1"/>', "<axis/>")), "h.urdf")
    assert_error(lambda: load_urdf(hinge), hinge, re.escape("joint 'j2': unsupported joint type 'hinge'"))
    fixed = write(tmp_path, robot(*ARM[:4], joint("j2", "fixed", "l1", "l2").replace(
        '<axis xyz="0 0 1"/>', "<axis/>")), "f.urdf")
    assert [j.name for j in load_urdf(fixed).joints] == ["j1"]
    # no <axis> at all is URDF's default, 1 0 0, as urdfdom reads it
    bare = write(tmp_path, robot(*ARM[:4], joint("j2", "revolute", "l1", "l2").replace(
        '<axis xyz="0 0 1"/>', "")), "b.urdf")
    x = write(tmp_path, robot(*ARM[:4], joint("j2", "revolute", "l1", "l2", axis=(1, 0, 0))), "x.urdf")
    assert np.array_equal(load_urdf(bare).joints[1].phi, load_urdf(x).joints[1].phi)


@pytest.mark.parametrize("inner", ['<joint name="j9" type="fixed"/>', '<link name="l9"/>'])
def test_a_joint_or_link_inside_a_link_is_refused_by_name(tmp_path, inner):
    """A misplaced </link> put a joint inside a link: urdfdom skips it, so its child link became a
    second root, "several root links ...; choose one with --base", which would lose part of the
    arm (a new user's find); a fixed joint so placed, with nothing after it, was left out unsaid.
    One line naming the link, the element and its line."""
    path = write(tmp_path, robot(*ARM).replace('<link name="l1">', f'<link name="l1">{inner}', 1))
    tag = inner[1:inner.index(" ")]
    name = inner.split('"')[1]
    assert_error(lambda: load_urdf(path), path,
                 rf"link 'l1': <{tag} name=\"{name}\"> \(line \d+\) is inside the link, where no URDF "
                 rf"reader reads it: a <{tag}> goes directly in <robot> \(a misplaced </link>\?\)")


@pytest.mark.parametrize("case", ["tab", "line break", "&#9;", "utf-16", "utf-16 unmarked",
                                  "leading tab", "in a comment", "in a comment after the tag",
                                  "a --> in an attribute after it", "a <!-- in CDATA before it"])
def test_what_pinocchios_reader_refuses_is_warned_of(tmp_path, case):
    """A tab or line break after a number in an <origin>'s list, or a UTF-16 file: XML (and so
    vampc) reads them, urdfdom (Pinocchio's URDF reader) refuses the file, unsaid here (a new
    user's finds). Pinocchio, where installed, is the judge: where it refuses, vampc warns; where
    it loads the file (a leading tab, which its reader skips; a tab in a comment), vampc says
    nothing (a review found both warned of, by a search over the file's bytes; an audit, a
    commented-out tag after the real one on its line, taken for it)."""
    text = robot(*ARM)
    old = '<origin xyz="0 0 0.10000000000000001" rpy="0 0 0"/><axis'
    assert old in text
    line = text[:text.index(old)].count("\n") + 1
    said = (rf"joint 'j1': <origin xyz=\.\.\.> \(line {line}\): a tab or line break after a number, "
            r"which urdfdom \(Pinocchio's URDF reader\) does not read: it refuses the file, or in an "
            r"<inertial> leaves the link's mass out; read here as a space")
    refused = True
    path = tmp_path / "r.urdf"
    if case.startswith("utf-16"):
        encoding = "utf-16" if case == "utf-16" else "utf-16-le"     # (with and without a BOM)
        path.write_bytes(text.encode(encoding))
        said = r"UTF-16 text, which urdfdom \(Pinocchio's URDF reader\) cannot read"
    elif case == "in a comment":
        path = write(tmp_path, text.replace("<robot name=\"r\">", "<robot name=\"r\">\n<!-- <origin "
                                            "xyz=\"0\t0 0\"/> -->"))
        refused = False
    elif case == "in a comment after the tag":
        mine = old + ' xyz="0 0 1"/>'
        assert mine in text
        path = write(tmp_path, text.replace(mine, mine + '<!-- <axis xyz="1\t0 0"/> -->', 1))
        refused = False
    elif case.startswith("a "):       # (neither is a comment: a review's, both had hidden the tab)
        broken = text.replace(old, old.replace('"0 0 0.1', '"0\t0 0.1'), 1)
        path = write(tmp_path, broken.replace("</robot>", '<gazebo reference="x-->y"/></robot>')
                     if "-->" in case else broken.replace(
                         '<robot name="r">', '<robot name="r"><gazebo><![CDATA[ <!-- ]]></gazebo>'
                         ).replace("</robot>", "<!-- a comment --></robot>"))
    else:
        gap = {"tab": "0\t0", "line break": "0\n0", "&#9;": "0&#9;0", "leading tab": "\t0 0"}[case]
        path = write(tmp_path, text.replace(old, old.replace('"0 0 0.1', f'"{gap} 0.1'), 1))
        refused = case != "leading tab"
    with warnings.catch_warnings(record=True) as heard:
        warnings.simplefilter("always")
        chain = load_urdf(path)
    found = [str(w.message) for w in heard if re.search(said, str(w.message))]
    assert len(found) == refused, [str(w.message) for w in heard]
    assert not [w for w in heard if "urdfdom" in str(w.message) and not re.search(said, str(w.message))]
    assert len(chain.joints) == 2
    pin = pytest.importorskip("pinocchio")
    if refused:
        with pytest.raises(Exception):
            pin.buildModelFromUrdf(str(path))
    else:
        assert pin.buildModelFromUrdf(str(path)).nq == 2


@pytest.mark.parametrize("rpy, xyz, warned", [((0, 0, 0.5), (0, 0, 1), True), ((0, 0, 0), (0, 0, 0), False)])
def test_floating_a_massless_root_fixed_away_from_its_body_is_said(tmp_path, rpy, xyz, warned):
    """--floating-base on a URDF whose root is a massless `base_footprint` fixed to the torso 1 m
    above and turned: the root floats (as Pinocchio's free flyer at the root), so the base's columns
    and wrench are in its frame, and a new user's torques differed by 10% from --base torso, unsaid.
    Said, with the --base that floats the torso; not where the weld leaves the frames as one. The
    chains differ as said: --base torso floats the torso at its own frame."""
    text = robot(link("base_footprint", None), link("torso"), *ARM[1:3],
                 joint("bf", "fixed", "base_footprint", "torso", xyz=xyz, rpy=rpy),
                 joint("j1", "revolute", "torso", "l1"), joint("j2", "revolute", "l1", "l2"))
    path = write(tmp_path, text)
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        floated = load_urdf(path, floating=True)
    said = [str(w.message) for w in seen if "free flyer" in str(w.message)]
    assert said == ([f"{path}: --floating-base floats the root link 'base_footprint', which has no mass: "
                     "'torso' is fixed to it by joint 'bf' away from its frame, so the base's columns "
                     "are read, and its wrench given, in the frame of 'base_footprint' (as Pinocchio's "
                     "free flyer at the root); --base torso --floating-base floats 'torso' itself"]
                    if warned else [])
    torso = load_urdf(path, base="torso", floating=True)     # j1 from the floating base's frame:
    assert np.allclose(floated.joints[0].shift, np.add(xyz, [0, 0, 0.1]))     # through the weld
    assert np.allclose(torso.joints[0].shift, [0, 0, 0.1])                 # from the torso's own
    # through two massless links, the first weld leaving the frame as it is: said all the same (a
    # review's world -> base_link -> torso went unsaid, only the root's own joints looked at)
    deeper = robot(link("world", None), link("base_footprint", None), link("torso"), *ARM[1:3],
                   joint("w", "fixed", "world", "base_footprint", xyz=(0, 0, 0)),
                   joint("bf", "fixed", "base_footprint", "torso", xyz=xyz, rpy=rpy),
                   joint("j1", "revolute", "torso", "l1"), joint("j2", "revolute", "l1", "l2"))
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        load_urdf(write(tmp_path, deeper, "deeper.urdf"), floating=True)
    said = [str(w.message) for w in seen if "free flyer" in str(w.message)]
    assert len(said) == warned and all("floats the root link 'world', which has no mass: 'torso' is "
                                       "fixed to it by joints 'w', 'bf' away from its frame" in m
                                       for m in said), said
    # and where the walk ends (a review of that walk found two it had dropped): at a massless link
    # the joints move from, and past a plate of mass welded beside the body
    for name, parts, body in (
            ("massless.urdf", [link("world", None), link("bf", None), *ARM[1:3],
                               joint("w", "fixed", "world", "bf", xyz=xyz, rpy=rpy),
                               joint("j1", "revolute", "bf", "l1"), joint("j2", "revolute", "l1", "l2")],
             "bf"),
            ("plate.urdf", [link("world", None), link("torso"), link("plate"), *ARM[1:3],
                            joint("w", "fixed", "world", "torso", xyz=xyz, rpy=rpy),
                            joint("p", "fixed", "world", "plate", xyz=(1, 0, 0)),
                            joint("j1", "revolute", "torso", "l1"), joint("j2", "revolute", "l1", "l2")],
             "torso")):
        with warnings.catch_warnings(record=True) as seen:
            warnings.simplefilter("always")
            load_urdf(write(tmp_path, robot(*parts), name), floating=True)
        said = [str(w.message) for w in seen if "free flyer" in str(w.message)]
        assert len(said) == warned and all(f"'{body}' is fixed to it by joint 'w' away" in m
                                           for m in said), (name, said)


YTREE_URDF = """<?xml version="1.0"?>
<robot name="ytree">
  <link name="base"/>
  <link name="l1"><inertial><origin xyz="0.25 0 0"/><mass value="2.0"/><inertia ixx="0.001" iyy="0.04" izz="0.04" ixy="0" iyz="0" ixz="0"/></inertial></link>
  <link name="l2"><inertial><origin xyz="0.2 0 0"/><mass value="1.5"/><inertia ixx="0.001" iyy="0.02" izz="0.02" ixy="0" iyz="0" ixz="0"/></inertial></link>
  <link name="l3"><inertial><origin xyz="0.15 0 0"/><mass value="1.0"/><inertia ixx="0.001" iyy="0.01" izz="0.01" ixy="0" iyz="0" ixz="0"/></inertial></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><origin xyz="0 0 0"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" velocity="3" effort="50"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/><origin xyz="0.5 0 0"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" velocity="3" effort="50"/></joint>
  <joint name="j3" type="revolute"><parent link="l1"/><child link="l3"/><origin xyz="0.5 0 0"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" velocity="3" effort="50"/></joint>
</robot>
"""
YTREE_DH = """name: ytree
gravity: [0.0, 0.0, -9.81]
joints:
  - {name: j1, type: revolute, a: 0.5, alpha: 0.0, d: 0.0, theta: 0.0, mass: 2.0, com: [-0.25, 0, 0], inertia: [0.001, 0.04, 0.04, 0, 0, 0],
     limits: {q: [-3, 3], qd: 3, tau: 50}}
  - {name: j2, parent: j1, type: revolute, a: 0.4, alpha: 0.0, d: 0.0, theta: 0.0, mass: 1.5, com: [-0.2, 0, 0], inertia: [0.001, 0.02, 0.02, 0, 0, 0],
     limits: {q: [-3, 3], qd: 3, tau: 50}}
  - {name: j3, parent: j1, type: revolute, a: 0.3, alpha: 0.0, d: 0.0, theta: 0.0, mass: 1.0, com: [-0.15, 0, 0], inertia: [0.001, 0.01, 0.01, 0, 0, 0],
     limits: {q: [-3, 3], qd: 3, tau: 50}}
"""


@pytest.mark.parametrize("recursion", ["linear", "log"])
def test_a_urdf_tree_costs_what_the_same_tree_as_a_dh_table_does(tmp_path, recursion):
    """A three-joint tree as a URDF (joint frames not turned from their parents') and as a DH table:
    the same torques and the same latency and VAMPs. The URDF kept each identity turn and took a dot
    product with the axis for each torque (a VD and a constant): a VAMP more, and 3 flops more in
    the log recursion (a new user's find)."""
    import json

    from click.testing import CliRunner

    from vampc.cli import main
    (tmp_path / "ytree.urdf").write_text(YTREE_URDF)
    (tmp_path / "ytree.yaml").write_text(YTREE_DH)
    figures, torques = [], []
    for name in ("ytree.urdf", "ytree.yaml"):
        res = CliRunner().invoke(main, ["report", str(tmp_path / name), "--recursion", recursion,
                                        "--format", "json"])
        assert res.exit_code == 0, res.output
        rep = json.loads(res.stdout)
        figures.append((rep["latency"]["flops"], rep["vamps"]["total"]))
        res = CliRunner().invoke(main, ["emulate", str(tmp_path / name), "--recursion", recursion,
                                        "--random", "20", "--check", "-o", "-"])
        assert res.exit_code == 0, res.output
        torques.append(np.array([[float(c) for c in line.split(",")]
                                 for line in res.stdout.splitlines()[1:]]))
    assert figures[0] == figures[1]
    assert np.allclose(torques[0], torques[1], rtol=1e-12, atol=1e-12)


def test_a_chain_on_a_floating_base_is_not_said_to_branch():
    """The report's node-requirements note listed "branches (a tree)" for a chain on a floating
    base (held as a tree of one branch): a new user's find. A tree still says it."""
    from click.testing import CliRunner
    from conftest import EXAMPLES

    from vampc.cli import main
    for robot, options, branches in (("ur5.urdf", ["--floating-base"], False), ("quadruped.urdf", [], True)):
        res = CliRunner().invoke(main, ["report", str(EXAMPLES / robot), *options])
        assert res.exit_code == 0, res.output
        assert ("branches (a tree)" in res.stdout) is branches, robot


@pytest.mark.parametrize("head, said", [
    ('<?xml version="0.0" ?>\n', 'line 1: its XML declaration names <?xml version="0.0" ?>, which XML refuses'),
    ('\n\n<?xml version="1.0" encoding="utf-8"?>\n', "line 3: its XML declaration comes after blank "
                                                     "space, which XML refuses")])
def test_an_xml_declaration_that_alone_breaks_the_xml_is_read_past_as_urdfdom_does(tmp_path, head, said):
    """Bullet's `<?xml version="0.0" ?>` (seven files) and a blank line before the declaration
    (two) were refused as not well-formed XML, though urdfdom (TinyXML) and so Pinocchio read them
    (a trial of public URDF collections): read as the file without the declaration, said; an error
    further on names its own line; a declared encoding other than UTF-8 is still refused."""
    body = robot(link("b"), link("l1"), '<joint name="j1" type="revolute"><parent link="b"/>'
                 '<child link="l1"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" '
                 'velocity="1"/></joint>')
    body = body[body.index("\n") + 1:]                      # (robot() writes a declaration of 1.0)
    clean = write(tmp_path, body, "clean.urdf")
    path = write(tmp_path, head + body)
    with pytest.warns(VampcWarning) as seen:
        chain = load_urdf(path)
    assert [str(w.message) for w in seen] == [f"{path}: {said}; read as XML 1.0 without it, as "
                                              "urdfdom (Pinocchio's reader) reads it"]
    assert [j.name for j in chain.joints] == ["j1"]
    check_torques(clean, chain)                  # (Pinocchio's rnea on the file without it)
    broken = write(tmp_path, head + body.replace("</robot>", ""), "broken.urdf")
    last = broken.read_text().count("\n") + 1            # (the end of the data, where it is cut)
    assert_error(lambda: load_urdf(broken), broken, rf"line {last}: not well-formed XML: .*")
    latin = write(tmp_path, re.sub(r'\s*encoding="[^"]*"', "", head).replace("?>", ' encoding="latin-1"?>')
                  + body, "latin.urdf")
    assert_error(lambda: load_urdf(latin), latin, r"line \d: not well-formed XML: .*")


def test_an_undeclared_namespace_prefix_is_read_past_as_urdfdom_does(tmp_path):
    """An old Gazebo extension's `<sensor:camera>` (Fetch's URDF), its prefix never declared, made
    the file not well-formed XML here, though Pinocchio reads it (a trial of public URDF
    collections): the prefix is declared, each said once with its line, the element not read; the
    torques are Pinocchio's on the same file; xacro's prefix is still a xacro file's error."""
    text = robot(link("b"), link("l1"), '<joint name="j1" type="revolute"><parent link="b"/>'
                 '<child link="l1"/><axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="1" '
                 'velocity="1"/></joint>', '<gazebo reference="l1" gz:x="1">\n<sensor:camera name="c">'
                 '<controller:cam plugin="p"/></sensor:camera>\n<sensor:ray/></gazebo>')
    path = write(tmp_path, text)
    line = text[:text.index("<gazebo")].count("\n") + 1
    with pytest.warns(VampcWarning) as seen:
        chain = load_urdf(path)
    tail = "is not declared, which XML refuses; read as another namespace's, which is not read, as " \
        "urdfdom reads past it"
    assert [str(w.message) for w in seen] == [
        f"{path}: line {line}: gz:x=... on <gazebo>: namespace prefix 'gz' {tail}",
        f"{path}: line {line + 1}: <sensor:camera>: namespace prefix 'sensor' {tail}",
        f"{path}: line {line + 1}: <controller:cam>: namespace prefix 'controller' {tail}"]
    assert [j.name for j in chain.joints] == ["j1"]
    check_torques(path, chain)                   # (Pinocchio reads the file as it is)
    xacro = write(tmp_path, text.replace("<gazebo ", "<xacro:arm/><gazebo "), "x.urdf")
    assert_error(lambda: load_urdf(xacro), xacro, rf"line {line}: not well-formed XML: Namespace prefix "
                                                  r"xacro on arm is not defined.* \(a xacro file: .*\)")


def test_a_macro_call_left_in_xacros_output_is_read_past_with_a_warning(tmp_path):
    """Valkyrie's <xacro:v1_pelvis_sensors_usb/> and robotis-OP2's <xacro:grey/> in a <visual>:
    calls of macros the file does not define, left in xacro's output, were refused with "run
    xacro first", which could not help (a trial of public URDF collections); urdfdom reads past
    them. Read past, said once with their lines; the torques are Pinocchio's on the same file; a
    file that defines a macro is still a xacro file."""
    ns = 'xmlns:xacro="http://www.ros.org/wiki/xacro"'
    text = robot(link("b"), link("l1").replace("</link>", '<visual><geometry><box size="1 1 1"/>'
                                                          '</geometry><xacro:grey/></visual></link>'),
                 '<joint name="j1" type="revolute"><parent link="b"/><child link="l1"/>'
                 '<axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>',
                 '<xacro:sensors_usb parent="b"/>').replace("<robot ", f"<robot {ns} ")
    path = write(tmp_path, text)
    with pytest.warns(VampcWarning) as seen:
        chain = load_urdf(path)
    assert [str(w.message) for w in seen] == [
        f"{path}: <xacro:grey> (line 4), <xacro:sensors_usb> (line 6): a call of a xacro macro the "
        "file does not define, left in xacro's output; read past, as urdfdom reads it: what the "
        "macro would make is not in the robot"]
    check_torques(path, chain)                   # (Pinocchio reads the file as it is)
    defined = write(tmp_path, text.replace('<xacro:sensors_usb parent="b"/>',
                                           '<xacro:macro name="grey"/>'), "d.urdf")
    assert_error(lambda: load_urdf(defined), defined, r"line 6: <xacro:macro>: a xacro element, which "
                                                      r"no URDF reader expands; run xacro first .*")


def test_drakes_force_elements_are_said_not_read(tmp_path):
    """Drake's <force_element> (a spring) and <cable> passed without a word, where an MJCF's
    tendons that exert forces are refused (a trial of public URDF collections, Drake's
    robotiq_tendons): said not read, the first named with its line; the torques are those of the
    file as urdfdom reads it, Pinocchio's."""
    text = robot(link("b"), link("l1"), '<joint name="j1" type="revolute"><parent link="b"/>'
                 '<child link="l1"/><axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="1" '
                 'velocity="1"/></joint>', '<force_element name="s"><torsional_spring joint="j1" '
                 'stiffness="3"/></force_element>', '<cable name="c"/>')
    path = write(tmp_path, text)
    with pytest.warns(VampcWarning) as seen:
        chain = load_urdf(path)
    assert [str(w.message) for w in seen] == [
        f"{path}: <force_element> (line 6, Drake's spring or damper) is not read: its forces are not "
        "in the torques (and 1 more such)"]
    check_torques(path, chain)


def test_what_beside_the_base_moves_across_a_floating_joint_or_on_a_planar_one_is_said(tmp_path):
    """A door hinged to the world beside the quadruped's floating trunk, and a box on a planar
    joint there, were left out unnamed: the walk stopped at every floating joint and named
    revolute and prismatic joints only (a review's). Named now, in the file's order; the trunk's
    own floating joint is said as its motion when the trunk floats."""
    text = (EXAMPLES / "quadruped.urdf").read_text()
    extra = ('<link name="world"/><joint name="root" type="floating"><parent link="world"/>'
             '<child link="trunk"/></joint>' + link("door") + '<joint name="door_hinge" type="revolute">'
             '<parent link="world"/><child link="door"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" '
             'effort="1" velocity="1"/></joint>' + link("box", mass=3.0) + '<joint name="slide" '
             'type="planar"><parent link="world"/><child link="box"/><axis xyz="0 0 1"/></joint>')
    path = write(tmp_path, text.replace("</robot>", extra + "</robot>"))
    legs = [j for link_, j in _file_joints_and_heavy_links(EXAMPLES / "quadruped.urdf")[0].items()
            if not link_.startswith("FL_")]
    for base, floating, named in (("FL_hip", False, legs + ["door_hinge", "slide"]),
                                  ("trunk", False, ["door_hinge", "slide"]),
                                  ("trunk", True, ["door_hinge", "slide"])):
        with warnings.catch_warnings(record=True) as seen:
            warnings.simplefilter("always")
            load_urdf(path, base=base, floating=floating)
        said = [str(w.message) for w in seen if "beside the way up" in str(w.message)
                or "above and beside" in str(w.message)]       # (not the folder's name)
        shown = ", ".join(f"'{j}'" for j in named[:10]) + (f" and {len(named) - 10} more" if len(named) > 10 else "")
        assert len(said) == 1 and f"{len(named)} moving joints: {shown})" in said[0], (base, said)
        assert ("'door'" in said[0] and "'box'" in said[0]) == floating, said   # (their mass, floating)


def test_inverted_limits_of_a_locked_joint_or_one_above_the_base_are_said(tmp_path):
    """The warning that <limit> lower above upper is read as no limits looked at the robot's joints
    only: a --lock of such a joint, once refused (no value fits), was taken at any value in silence,
    and one on the way up to --base went unsaid (a review's)."""
    chain = [link("b"), link("l1"), link("l2"), link("l3")]
    joints = [f'<joint name="j{k}" type="revolute"><parent link="{p}"/><child link="l{k}"/>'
              f'<axis xyz="0 0 1"/><limit lower="{1 if k < 3 else -1}" upper="{0 if k < 3 else 1}" '
              f'effort="1" velocity="1"/></joint>' for k, p in ((1, "b"), (2, "l1"), (3, "l2"))]
    path = write(tmp_path, robot(*chain, *joints))
    for kwargs, said in (({"lock": {"j2": 5.0}}, "joint 'j1' (and 'j2')"),
                         ({"base": "l1"}, "joint 'j1' (and 'j2')"),
                         ({"base": "l2", "tip": "l3"}, "joint 'j1' (and 'j2')")):
        with pytest.warns(VampcWarning) as seen:
            load_urdf(path, **kwargs)
        told = [str(w.message) for w in seen if "is above" in str(w.message)]
        assert told == [f"{path}: {said}: <limit> lower 1 is above upper 0; read as no position "
                        "limits, as Bullet reads them (--lock then takes any position)"], (kwargs, told)
