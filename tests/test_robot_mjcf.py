"""MJCF input (issue "Every robot Pinocchio loads", part 5): MuJoCo models written for the tests -- a
serial arm, a quadruped on a free joint, a humanoid-like tree -- compiled, emulated (both recursions)
and compared with Pinocchio's MJCF model (pin.buildModelFromMJCF) and with MuJoCo's own inverse
dynamics (mj_inverse); and what is refused, one line each."""
from __future__ import annotations

import re
import warnings

import numpy as np
import pytest
from errors_util import assert_error

from vampc.errors import VampcError, VampcWarning
from vampc.robot import load_robot

mujoco = pytest.importorskip("mujoco")
pin = pytest.importorskip("pinocchio")

INERTIAL = '<inertial pos="{c}" mass="{m}" diaginertia="{i}" quat="{q}"/>'


def body(name, pos, joints, inner="", m=1.0, c="0.05 0.01 0", i="0.01 0.02 0.025", q="1 0 0 0",
         quat="1 0 0 0"):
    """A <body> with its joints (name, type, axis, pos, range or None) and children."""
    js = "".join(f'<joint name="{n}" type="{t}" axis="{a}" pos="{p}"'
                 + (f' range="{r}" limited="true"' if r else "") + "/>" for n, t, a, p, r in joints)
    return (f'<body name="{name}" pos="{pos}" quat="{quat}">{js}'
            + INERTIAL.format(c=c, m=m, i=i, q=q) + inner + "</body>")


def model(name, bodies, gravity="0 0 -9.81", extra=""):
    return (f'<mujoco model="{name}"><option gravity="{gravity}"/><worldbody>{bodies}</worldbody>'
            f"{extra}</mujoco>")


# A 6-joint arm: rotated bodies, joints off the body origin, a slide, tilted principal axes, a
# body with two hinges (Pinocchio makes it a composite joint), a non-default gravity.
ARM = model("arm", body(
    "shoulder", "0 0 0.3", [("j1", "hinge", "0 0 1", "0.01 0 0", "-2 2")], quat="0.9 0.1 0.2 0.1", inner=body(
        "upper", "0.05 0 0.1", [("j2", "hinge", "0 1 0", "0 0 0", None)], q="0.8 0.2 0.1 0", inner=body(
            "fore", "0.3 0 0", [("j3", "hinge", "0 1 0", "0 0.02 0", None)], inner=body(
                "slider", "0.25 0 0", [("j4", "slide", "1 0 0", "0 0 0", "-0.1 0.1")], m=0.4, inner=body(
                    "wrist", "0.05 0 0", [("j5", "hinge", "1 0 0", "0 0 0.01", None),
                                          ("j6", "hinge", "0 0 1", "0 0 0", None)], m=0.3))))),
    gravity="0.5 -0.3 -9.7")


def leg(side, x, y):
    return body(f"{side}_hip", f"{x} {y} 0", [(f"{side}_haa", "hinge", "1 0 0", "0 0 0", "-1 1")], m=0.6,
                inner=body(f"{side}_thigh", "0 0.05 0", [(f"{side}_hfe", "hinge", "0 1 0", "0 0 0", None)],
                           m=0.9, c="0 0 -0.1", inner=body(
                               f"{side}_shank", "0 0 -0.2", [(f"{side}_kfe", "hinge", "0 1 0", "0 0 0", None)],
                               m=0.3, c="0 0 -0.1")))


QUADRUPED = model("quadruped", body(
    "trunk", "0 0 0.5", [], m=6.0, i="0.05 0.2 0.22", c="0.01 0 0.02",
    inner=leg("lf", 0.3, 0.1) + leg("rf", 0.3, -0.1) + leg("lh", -0.3, 0.1) + leg("rh", -0.3, -0.1)
).replace('<body name="trunk" pos="0 0 0.5" quat="1 0 0 0">',
          '<body name="trunk" pos="0 0 0.5" quat="1 0 0 0"><freejoint name="root"/>'))


def limb(name, pos, axes, m=1.0):
    """A limb of three bodies; the first has two hinges (a hip or a shoulder)."""
    return body(f"{name}1", pos, [(f"{name}_x", "hinge", "1 0 0", "0 0 0", None),
                                  (f"{name}_y", "hinge", "0 1 0", "0 0 0.02", None)], m=m, inner=body(
        f"{name}2", "0 0 -0.3", [(f"{name}_knee", "hinge", axes, "0 0 0", None)], m=0.7 * m,
        c="0 0 -0.15", inner=body(f"{name}3", "0 0 -0.3", [(f"{name}_ankle", "hinge", "0 1 0", "0 0 0", None)],
                                  m=0.2 * m)))


HUMANOID = model("humanoid", body(
    "pelvis", "0 0 1", [], m=8.0, i="0.1 0.1 0.08", inner=(
        limb("lleg", "0 0.1 -0.1", "0 1 0", 3.0) + limb("rleg", "0 -0.1 -0.1", "0 1 0", 3.0)
        + body("torso", "0 0 0.2", [("waist", "hinge", "0 0 1", "0 0 0", None)], m=10.0, i="0.3 0.3 0.1",
               inner=limb("larm", "0 0.2 0.3", "0 1 0", 1.0) + limb("rarm", "0 -0.2 0.3", "1 0 0", 1.0)
               + body("head", "0 0 0.4", [("neck", "hinge", "0 0 1", "0 0 0", None)], m=2.0))))
).replace('<body name="pelvis" pos="0 0 1" quat="1 0 0 0">',
          '<body name="pelvis" pos="0 0 1" quat="1 0 0 0"><freejoint name="root"/>')


def pin_reference(path, chain, traj, free_flyer: bool = False):
    """Pinocchio's rnea on its MJCF model, its velocities in vampc's joint order (its v order, one
    entry a joint, a composite's in file order), gravity set from the file as MuJoCo reads it;
    `free_flyer`: the model built with a free-flyer root (a file with no free joint, floated)."""
    if free_flyer:
        with warnings.catch_warnings():      # (this overload returns the model and its constraints,
            warnings.simplefilter("ignore")  # with a deprecation warning, in Pinocchio 3)
            pm = pin.buildModelFromMJCF(str(path), pin.JointModelFreeFlyer(), "root_joint")
        pm = pm[0] if isinstance(pm, tuple) else pm
    else:
        pm = pin.buildModelFromMJCF(str(path))
    pm.gravity.linear = mujoco.MjModel.from_xml_path(str(path)).opt.gravity
    head = 6 if chain.floating else 0
    assert pm.nv == chain.n + head
    data, out = pm.createData(), []
    for s in range(traj.count):
        q, v, a = pin.neutral(pm), np.zeros(pm.nv), np.zeros(pm.nv)
        q[head + (1 if head else 0):] = traj.q[s]
        v[head:], a[head:] = traj.qd[s], traj.qdd[s]
        if head:
            q[:7] = [0, 0, 0, 0, 0, 0, 1]
            b = traj.base[s]
            v[:6], a[:6] = np.r_[0, 0, 0, b[:3]], np.r_[b[6:], b[3:6]]
        tau = pin.rnea(pm, data, q, v, a)
        out.append(np.r_[tau[head:], tau[:6]] if head else tau)
    return np.array(out)


def mujoco_reference(path, traj):
    """MuJoCo's mj_inverse for a fixed base (its qpos is vampc's q)."""
    m = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(m)
    out = []
    for s in range(traj.count):
        d.qpos[:], d.qvel[:], d.qacc[:] = traj.q[s], traj.qd[s], traj.qdd[s]
        mujoco.mj_inverse(m, d)
        out.append(d.qfrc_inverse.copy())
    return np.array(out)


@pytest.mark.parametrize("name, text, n, floating", [("arm", ARM, 6, False),
                                                     ("quadruped", QUADRUPED, 12, True),
                                                     ("humanoid", HUMANOID, 18, True)])
def test_mjcf_models_match_pinocchio(tmp_path, name, text, n, floating):
    from vampc.compiler import CompileOptions, compile_chain, program_document
    from vampc.emulator import emulate, loaded_from_doc
    from vampc.emulator.host import check_torques, random_trajectory
    path = tmp_path / f"{name}.xml"
    path.write_text(text)
    chain = load_robot(path)
    assert chain.n == n and chain.floating == floating and chain.name == name
    traj = random_trajectory(chain, 5, 2)
    want = pin_reference(path, chain, traj)
    if not floating:
        assert np.max(np.abs(mujoco_reference(path, traj) - want)) <= 1e-9 * np.max(np.abs(want))
    for recursion in ("linear", "log"):
        ld = loaded_from_doc(program_document(compile_chain(chain, CompileOptions(recursion=recursion))))
        tau = emulate(ld, traj, "stream").tau
        assert check_torques(chain, traj, tau).ok
        assert np.max(np.abs(tau - want)) <= 1e-9 * np.max(np.abs(want))


def test_the_command_line_compiles_an_mjcf_model(tmp_path):
    from click.testing import CliRunner

    from vampc.cli import main
    path = tmp_path / "arm.xml"
    path.write_text(ARM)
    r = CliRunner().invoke(main, ["compile", str(path), "-o", str(tmp_path / "arm.vamp.json")])
    assert r.exit_code == 0, r.output
    assert "arm.vamp.json: 6 joints" in r.output
    r = CliRunner().invoke(main, ["emulate", str(tmp_path / "arm.vamp.json"), "--random", "50", "--check"])
    assert r.exit_code == 0 and ": OK" in r.output, r.output


MJCF_ERRORS = [
    # no joint at all: a body, none, or welded bodies (numpy's reshape error had been said as
    # MuJoCo's "cannot read it": a robots audit's)
    ('<mujoco model="n"><worldbody><body name="b"><inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/>'
     '</body></worldbody></mujoco>', "", r"no movable joints below base link 'world'"),
    ('<mujoco model="e"/>', "", r"no movable joints below base link 'world'"),
    (model("u", body("a", "0 0 0", [("j1", "hinge", "0 0 1", "0 0 0", None)], inner=body(
        "b", "0.1 0 0", [("j2", "hinge", "0 0 1", "0 0 0", None)])),
           extra='<equality><joint joint1="j1" joint2="j2"/><weld body1="b"/></equality>'), "",
     r"<equality> number 2 \(unnamed\): weld equality constraints are not supported \(the network "
     r"computes an open tree; joint equalities are read as mimic joints\): its loop moves on joints "
     r"'j2', 'j1' \(a loop no joint of which moves, all locked or above a fixed --base, is left out\)"),
    (model("p", body("a", "0 0 0", [("j1", "hinge", "0 0 1", "0 0 0", None)], inner=body(
        "b", "0.1 0 0", [("j2", "hinge", "0 0 1", "0 0 0", None)])),
           extra='<equality><joint name="sq" joint1="j1" joint2="j2" polycoef="0 1 0.5 0 0"/></equality>'),
     "", r"equality 'sq': a joint equality beyond degree 1 \(polycoef c2\.\.c4 not 0\) cannot be a mimic "
         r"coupling"),
    (model("b", body("a", "0 0 0", [("j1", "ball", "0 0 1", "0 0 0", None)])), "",
     r"joint 'j1': ball joints are not supported \(one degree of freedom per joint: use three hinges\)"),
    (model("t", body("a", "0 0 0", [("j1", "hinge", "0 0 1", "0 0 0", None)]),
           extra='<tendon><fixed name="tt" stiffness="10"><joint joint="j1" coef="1"/></fixed></tendon>'),
     "", r"tendon 'tt': has stiffness: tendons that exert forces are not supported \(the network "
         r"computes an open tree\)"),
    (model("e", body("a", "0 0 0", [("j1", "hinge", "0 0 1", "0 0 0", None)], inner=body(
        "b", "0.1 0 0", [("j2", "hinge", "0 0 1", "0 0 0", None)])),
           extra='<equality><connect name="eq" body1="b" anchor="0 0 0"/></equality>'), "",
     r"equality 'eq': connect equality constraints are not supported \(the network computes an open "
     r"tree; joint equalities are read as mimic joints\): its loop moves on joints 'j2', 'j1' \(a loop "
     r"no joint of which moves, all locked or above a fixed --base, is left out\)"),
    (model("i", body("a", "0 0 0", [("j1", "hinge", "0 0 1", "0 0 0", None)])).replace(
        "<worldbody>", '<include file="missing.xml"/><worldbody>'), "",
     r"MuJoCo cannot read it \(.*missing\.xml.*\)"),
]


@pytest.mark.parametrize("text, _, message", MJCF_ERRORS)
def test_mjcf_errors(tmp_path, text, _, message):
    path = tmp_path / "bad.xml"
    path.write_text(text)
    assert_error(lambda: load_robot(path), path, message)


def test_what_inverse_dynamics_leaves_out_is_a_warning(tmp_path):
    path = tmp_path / "d.xml"
    path.write_text(model("d", body("a", "0 0 0", [("j1", "hinge", "0 0 1", "0 0 0", None)]).replace(
        'name="j1"', 'name="j1" damping="0.5" armature="0.01"')))
    with pytest.warns(VampcWarning, match=r"joint armature, damping ignored: vampc's torques are the rigid "
                                          r"bodies' inverse dynamics alone \(MuJoCo's mj_inverse includes "
                                          r"armature·q̈ and the passive forces, Pinocchio's MJCF reader "
                                          r"armature·q̈\)"):
        assert load_robot(path).n == 1


@pytest.mark.parametrize("edit, said", [
    (('name="a"', 'name="a" gravcomp="0.5"'), r"body gravcomp \(gravity compensation\) ignored"),
    (('<option gravity="0 0 -9.81"/>', '<option gravity="0 0 -9.81" density="1.2" viscosity="0"/>'),
     r"fluid forces \(<option> density, viscosity\) ignored"),
    (('<option gravity="0 0 -9.81"/>', '<option gravity="0 0 -9.81" viscosity="0.01"/>'),
     r"fluid forces \(<option> density, viscosity\) ignored"),
    (('name="j1"', 'name="j1" damping="0 2"'), r"joint damping ignored"),
    (('name="j1"', 'name="j1" stiffness="0 0 3"'), r"joint stiffness ignored"),
    (("</worldbody>", '</worldbody><actuator><motor joint="j1" gear="2" armature="0.3"/></actuator>'),
     r"actuator armature ignored"),
    (("</worldbody>", '</worldbody><actuator><motor joint="j1" gear="2" damping="2"/></actuator>'),
     r"actuator damping ignored")])
def test_passive_forces_left_out_are_a_warning_that_mj_inverse_differs_by(tmp_path, edit, said):
    """A body's gravcomp and fluid forces are passive forces MuJoCo's mj_inverse subtracts: vampc's
    torques differed from it (by 0.36 of the torque on a two-link arm), saying nothing (a new user's
    find). So were MuJoCo 4's polynomial damping and stiffness (damping="0 2": all but the first
    term in dof_dampingpoly, jnt_stiffnesspoly) and an actuator's armature and damping, which act on
    its joint (up to 224 times the torque; a new user's find). Said; without them, the torques equal
    mj_inverse's."""
    from vampc.emulator.host import random_trajectory
    plain = model("d", body("a", "0 0 0.1", [("j1", "hinge", "0 1 0", "0 0 0", None)],
                            inner=body("b", "0.3 0 0", [("j2", "hinge", "0 1 0", "0 0 0", None)])))
    path = tmp_path / "d.xml"
    path.write_text(plain.replace(*edit, 1))
    assert path.read_text() != plain
    with pytest.warns(VampcWarning, match=said):
        chain = load_robot(path)
    (tmp_path / "plain.xml").write_text(plain)
    traj = random_trajectory(chain, 5, 2)
    from vampc.dynamics.reference import rnea
    want = mujoco_reference(tmp_path / "plain.xml", traj)
    assert np.max(np.abs(rnea(chain, traj.q, traj.qd, traj.qdd) - want)) <= 1e-12 * np.abs(want).max()
    assert np.max(np.abs(mujoco_reference(path, traj) - want)) > 1e-3      # (the file's: they matter)


def test_gravity_disabled_by_a_flag_is_none(tmp_path):
    """<option><flag gravity="disable"/></option>: MuJoCo applies no gravity; vampc read the
    gravity vector anyway (torques of 5.66 N·m at rest where mj_inverse gives 0; a new user's find)."""
    from vampc.dynamics.reference import rnea
    from vampc.emulator.host import random_trajectory
    path = tmp_path / "g.xml"
    path.write_text(model("g", body("a", "0 0 0.1", [("j1", "hinge", "0 1 0", "0 0 0", None)],
                                    inner=body("b", "0.3 0 0", [("j2", "hinge", "0 1 0", "0 0 0", None)])),
                          extra="").replace('<option gravity="0 0 -9.81"/>',
                                            '<option gravity="0 0 -9.81"><flag gravity="disable"/></option>'))
    chain = load_robot(path)
    assert np.all(chain.gravity == 0)
    traj = random_trajectory(chain, 5, 3)
    want = mujoco_reference(path, traj)
    assert np.max(np.abs(rnea(chain, traj.q, traj.qd, traj.qdd) - want)) <= 1e-12 * np.abs(want).max()
    zero = np.zeros((1, 2))
    assert np.all(rnea(chain, zero, zero, zero) == 0)          # at rest, no gravity: no torque
    # gravity compensation without gravity compensates nothing: not warned of, the same torques
    path.write_text(path.read_text().replace('<body name="a"', '<body name="a" gravcomp="1"', 1))
    assert 'gravcomp="1"' in path.read_text()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        chain = load_robot(path)
    want = mujoco_reference(path, traj)
    assert np.max(np.abs(rnea(chain, traj.q, traj.qd, traj.qdd) - want)) <= 1e-12 * np.abs(want).max()


# A gripper as the Menagerie's panda has one: two fingers an inert tendon pulls together and a joint
# equality couples (here with a multiplier and an offset), and a third finger an equality holds.
GRIPPER = model("gripper", body(
    "hand", "0 0 0.1", [("wrist", "hinge", "0 0 1", "0 0 0", None)], inner=(
        body("left", "0.1 0.02 0", [("f1", "slide", "0 1 0", "0 0 0", "0 0.04")], m=0.1)
        + body("right", "0.1 -0.02 0", [("f2", "slide", "0 -1 0", "0 0 0", "0 0.04")], m=0.15)
        + body("thumb", "0.05 0 0.02", [("f3", "hinge", "1 0 0", "0 0 0", None)], m=0.05))),
    extra='<tendon><fixed name="split"><joint joint="f1" coef="0.5"/><joint joint="f2" coef="0.5"/>'
          '</fixed></tendon><equality><joint name="twin" joint1="f2" joint2="f1" polycoef="0.01 0.8 0 0 0"/>'
          '<joint name="hold" joint1="f3" polycoef="0.2 0 0 0 0"/></equality>')


def test_joint_equalities_are_mimic_joints(tmp_path):
    """By default ordinary joints (Pinocchio's MJCF reader ignores equalities: its model has the same
    four joints); with --mimic couple f2 = 0.01 + 0.8 f1 and f3 is locked at 0.2, and the torques are
    Gᵀ τ of Pinocchio's model at the expanded states."""
    import warnings

    from pinocchio_util import coupled_matrix

    from vampc.robot.mimic import expand, reduce_torques
    path = tmp_path / "g.xml"
    path.write_text(GRIPPER)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        plain = load_robot(path)
    said = [str(w.message).split(": ", 1)[1] for w in caught if issubclass(w.category, VampcWarning)]
    assert said[0].startswith("tendon 'split' left out: it exerts no force")
    assert "an equality holds joint 'f3' at 0.2: taken as an ordinary joint; --mimic couple locks it there" in said
    assert [j.name for j in plain.joints] == ["wrist", "f1", "f2", "f3"] and plain.mimic == ()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        chain = load_robot(path, mimic="couple")
    assert [j.name for j in chain.joints] == ["wrist", "f1", "f2"]
    assert [(m.follower, m.leader, m.multiplier, m.offset) for m in chain.mimic] == [(3, 2, 0.8, 0.01)]
    from vampc.compiler import CompileOptions, compile_chain, program_document
    from vampc.emulator import emulate, loaded_from_doc
    from vampc.emulator.host import Trajectory
    rng = np.random.default_rng(5)
    q, qd, qdd = rng.uniform(-0.5, 0.5, (3, 6, 2))
    full = Trajectory(*expand(chain, q, qd, qdd))
    ld = loaded_from_doc(program_document(compile_chain(chain, CompileOptions())))
    got = reduce_torques(chain, emulate(ld, full, "stream").tau)
    pm = pin.buildModelFromMJCF(str(path))
    assert pm.nv == 4
    data, want = pm.createData(), []
    for s in range(6):
        pq = np.r_[full.q[s], 0.2]                 # f3 held at 0.2
        tau = pin.rnea(pm, data, pq, np.r_[full.qd[s], 0], np.r_[full.qdd[s], 0])
        want.append(tau[:3] @ coupled_matrix(chain))
    want = np.array(want)
    assert np.max(np.abs(got - want)) <= 1e-9 * np.max(np.abs(want))


def test_a_lock_that_an_equality_contradicts_is_refused_with_mimic_couple(tmp_path):
    """With --mimic couple an equality locks its joint where it holds it (README, MJCF); a --lock of
    that joint elsewhere is an error, not dropped for the equality's value (a mutation audit: taken
    in silence, the user's --lock f3=0.5 compiled f3 at 0.2). At the same value it is taken."""
    path = tmp_path / "g.xml"
    path.write_text(GRIPPER)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(VampcError, match=r"g\.xml: lock f3: an equality holds joint 'f3' at 0\.2 "
                                             r"\(--mimic couple\)$"):
            load_robot(path, mimic="couple", lock={"f3": 0.5})
        chain = load_robot(path, mimic="couple", lock={"f3": 0.2})
    assert [j.name for j in chain.joints] == ["wrist", "f1", "f2"]


def test_generated_names_never_take_a_name_the_file_uses(tmp_path):
    """An unnamed joint beside one named 'joint1' (MuJoCo's index would make it 'joint1' too), and a
    body named like the massless link between a body's two joints: distinct names, Pinocchio's
    torques (found by the review: a KeyError, exit 3)."""
    text = model("n", body("a", "0 0 0.1", [("joint1", "hinge", "0 0 1", "0 0 0", None),
                                            ("", "hinge", "0 1 0", "0 0 0", None)], inner=body(
        "a__joint1", "0.2 0 0", [("j3", "hinge", "1 0 0", "0 0 0", None)]))).replace(' name=""', "")
    path = tmp_path / "n.xml"
    path.write_text(text)
    chain = load_robot(path)
    assert len({j.name for j in chain.joints}) == chain.n == 3
    from vampc.dynamics.reference import rnea
    from vampc.emulator.host import random_trajectory
    traj = random_trajectory(chain, 3, 1)
    want = pin_reference(path, chain, traj)
    assert np.max(np.abs(rnea(chain, traj.q, traj.qd, traj.qdd) - want)) <= 1e-9 * np.max(np.abs(want))


def test_a_static_body_beside_the_floating_base_is_left_out(tmp_path):
    table = '<body name="table" pos="2 0 0"><inertial pos="0 0 0" mass="20" diaginertia="1 1 1"/></body>'
    path = tmp_path / "q.xml"
    path.write_text(QUADRUPED.replace("<worldbody>", "<worldbody>" + table))
    chain = load_robot(path)
    assert chain.floating and chain.n == 12
    plain = tmp_path / "plain.xml"
    plain.write_text(QUADRUPED)
    other = load_robot(plain)
    assert chain.base_mass == other.base_mass and np.array_equal(chain.gravity, other.gravity)


def test_two_free_bodies_are_refused(tmp_path):
    path = tmp_path / "two.xml"
    second = QUADRUPED.split("<worldbody>")[1].split("</worldbody>")[0].replace('name="', 'name="b_')
    path.write_text(QUADRUPED.replace("</worldbody>", second + "</worldbody>"))
    assert_error(lambda: load_robot(path), path,
                 r"body 'trunk': has a free joint \(a floating base\) but the world also carries 'b_trunk' "
                 r"with joints of its own: one robot per file \(choose one with --base trunk --floating-base "
                 r"or --base b_trunk --floating-base\)")
    chain = load_robot(path, base="b_trunk", floating=True)
    assert chain.n == 12 and chain.joints[0].name.startswith("b_")
    # two free bodies, neither with joints below its own: no --base helps (the advice had been
    # --base BODY --floating-base, which then failed either way: a new user's find)
    alone = tmp_path / "alone.xml"
    alone.write_text('<mujoco model="m"><worldbody><body name="a"><freejoint/><geom type="sphere" '
                     'size="0.1"/></body><body name="b"><freejoint/><geom type="sphere" size="0.1"/>'
                     "</body></worldbody></mujoco>")
    assert_error(lambda: load_robot(alone), alone, r"body 'a': .* one robot per file \(none has joints "
                                                   r"below its own for --base to keep: give each its own "
                                                   r"file\)")


def test_an_arm_hinged_to_the_world_beside_free_bodies_is_taken_whole_with_base_world(tmp_path):
    """A scene: an arm whose first hinge is on a body the world carries, beside a free cube (and a
    free quadruped). Refused as one robot per file, the advice had been --base shoulder, which cut
    the arm's first joint away (a new user's find), and --base world was refused too (a floating
    joint below the root). Now the advice is --base world, which keeps the whole arm on a fixed
    base and leaves the free bodies out, saying so: its torques are Pinocchio's on the arm alone."""
    cube = ('<body name="cube" pos="0.5 0 0.05"><freejoint name="cube_free"/>'
            '<geom type="box" size="0.02 0.02 0.02"/></body>')
    dog = QUADRUPED.split("<worldbody>")[1].split("</worldbody>")[0]
    alone, scene, kennel = tmp_path / "arm.xml", tmp_path / "scene.xml", tmp_path / "kennel.xml"
    alone.write_text(ARM)
    scene.write_text(ARM.replace("</worldbody>", cube + "</worldbody>"))
    kennel.write_text(ARM.replace("</worldbody>", cube + dog + "</worldbody>"))
    assert_error(lambda: load_robot(scene), scene,
                 r"body 'cube': has a free joint \(a floating base\) but the world also carries 'shoulder' "
                 r"with joints of its own: one robot per file \(choose one with --base world for "
                 r"'shoulder' on a fixed base, the free body left out\)")
    assert_error(lambda: load_robot(kennel), kennel,
                 r"body 'cube': .* the world also carries 'trunk', 'shoulder' with joints of its own: one "
                 r"robot per file \(choose one with --base world for 'shoulder' on a fixed base, the free "
                 r"bodies left out or --base trunk --floating-base\)")
    from vampc.dynamics.reference import rnea
    from vampc.emulator.host import random_trajectory
    for path, left in ((scene, r"'cube' on a free joint floats apart from the bodies hinged to the "
                                r"world and is left out"),
                       (kennel, r"'cube', 'trunk' on free joints float apart from the bodies hinged to "
                                r"the world and are left out")):
        with pytest.warns(VampcWarning, match=f"{path}: --base world: {left}"):
            chain = load_robot(path, base="world")
        assert not chain.floating and [j.name for j in chain.joints] == ["j1", "j2", "j3", "j4", "j5", "j6"]
        traj = random_trajectory(chain, 4, 2)
        want = pin_reference(alone, chain, traj)
        assert np.max(np.abs(rnea(chain, traj.q, traj.qd, traj.qdd) - want)) <= 1e-9 * np.max(np.abs(want))
    dogs = load_robot(kennel, base="trunk", floating=True)
    assert dogs.floating and dogs.n == 12


def test_a_model_without_a_name_is_named_after_its_file(tmp_path):
    path = tmp_path / "nameless.xml"
    path.write_text(ARM.replace('<mujoco model="arm">', "<mujoco>"))
    with pytest.warns(VampcWarning, match="<mujoco> has no model name; calling it 'nameless'"):
        assert load_robot(path).name == "nameless"


def test_a_reference_position_is_an_offset_and_q_is_qpos(tmp_path):
    """ref on a hinge (degrees, as MuJoCo reads them) and on a slide: vampc's q is MuJoCo's qpos
    (until then refused). Checked against mj_inverse at the same qpos, a joint locked at a qpos too,
    and an equality about the refs."""
    text = ARM.replace('name="j2" type="hinge"', 'name="j2" ref="20" type="hinge"').replace(
        'name="j4" type="slide"', 'name="j4" ref="0.05" type="slide"')
    path = tmp_path / "ref.xml"
    path.write_text(text)
    chain = load_robot(path)
    assert [round(j.offset, 12) for j in chain.joints] == [0, round(-np.radians(20), 12), 0, -0.05, 0, 0]
    from vampc.emulator.host import random_trajectory
    traj = random_trajectory(chain, 5, 4)
    want = mujoco_reference(path, traj)
    from vampc.compiler import CompileOptions, compile_chain, program_document
    from vampc.emulator import emulate, loaded_from_doc
    ld = loaded_from_doc(program_document(compile_chain(chain, CompileOptions())))
    got = emulate(ld, traj, "stream").tau
    assert np.max(np.abs(got - want)) <= 1e-9 * np.max(np.abs(want))
    locked = load_robot(path, lock={"j2": 0.4})          # at qpos 0.4, not at ref + 0.4
    assert [j.name for j in locked.joints] == ["j1", "j3", "j4", "j5", "j6"]
    m = mujoco.MjModel.from_xml_path(str(path))
    m.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONSTRAINT)     # j1 beyond its range
    d = mujoco.MjData(m)
    q = np.array([0.3, 0.4, -0.2, 0.01, 0.5, -0.6])
    d.qpos[:], d.qvel[:], d.qacc[:] = q, 0, 0
    mujoco.mj_inverse(m, d)
    from vampc.dynamics.reference import rnea
    keep = [0, 2, 3, 4, 5]
    ours = rnea(locked, q[None, keep], np.zeros((1, 5)), np.zeros((1, 5)))[0]
    assert np.max(np.abs(ours - d.qfrc_inverse[keep])) <= 1e-9 * np.max(np.abs(ours))


def test_an_equality_about_reference_positions_is_coupled_as_mujoco_means_it(tmp_path):
    """With refs on both fingers, MuJoCo's polynomial is about them (y - y0 = c0 + c1 (x - x0)): the
    expanded states satisfy MuJoCo's own equality constraint (its efc_pos is 0 there)."""
    import warnings

    from vampc.robot.mimic import expand
    text = GRIPPER.replace('name="f1" type="slide"', 'name="f1" ref="0.01" type="slide"').replace(
        'name="f2" type="slide"', 'name="f2" ref="0.02" type="slide"').replace(
        '<joint name="hold" joint1="f3" polycoef="0.2 0 0 0 0"/>', "")
    path = tmp_path / "gr.xml"
    path.write_text(text)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        chain = load_robot(path, mimic="couple")
    m = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(m)
    for q in ([0.3, 0.02, 0.5], [-0.1, 0.035, -0.4]):
        full = expand(chain, np.array([q]), np.zeros((1, 3)), np.zeros((1, 3)))[0][0]
        d.qpos[:] = full
        mujoco.mj_forward(m, d)
        rows = d.efc_type == int(mujoco.mjtConstraint.mjCNSTR_EQUALITY)
        assert rows.sum() == 1 and abs(d.efc_pos[rows][0]) < 1e-12


TILTED = """<mujoco model="tilted">
  <worldbody>
    {top}
      <body name="mount" pos="0.1 0.2 0.3" euler="{euler}">
        <geom type="box" size="0.1 0.1 0.1" mass="1"/>
        <body name="l1" pos="0 0 0.1">
          <joint name="j1" axis="0 0 1"/>
          <inertial pos="0.3 0.02 0" mass="1.3" diaginertia="0.01 0.02 0.03"/>
          <body name="l2" pos="0.4 0 0">
            <joint name="j2" axis="0 1 0"/>
            <inertial pos="0.2 0 0.01" mass="0.7" diaginertia="0.01 0.01 0.02"/>
          </body>
        </body>
      </body>
    {end}
  </worldbody>
</mujoco>"""


def assert_as_mj_inverse_with_the_rest_at_qpos0(path, chain, placed: dict | None = None):
    """The chain's torques (its joints MuJoCo's last ones) equal mj_inverse's with every other joint
    at qpos 0 (or at `placed`: qpos index -> value), still."""
    from vampc.dynamics.reference import rnea
    from vampc.emulator.host import random_trajectory
    k = chain.n
    traj = random_trajectory(chain, 6, 1)
    m = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(m)
    want = []
    for s in range(traj.count):
        d.qpos[:], d.qvel[:], d.qacc[:] = 0, 0, 0
        for i, value in (placed or {}).items():
            d.qpos[i] = value
        d.qpos[-k:], d.qvel[-k:], d.qacc[-k:] = traj.q[s], traj.qd[s], traj.qdd[s]
        mujoco.mj_inverse(m, d)
        want.append(d.qfrc_inverse[-k:].copy())
    got = rnea(chain, traj.q, traj.qd, traj.qdd)
    assert np.max(np.abs(got - np.array(want))) <= 1e-9 * np.max(np.abs(want))


@pytest.mark.parametrize("euler, top", [("90 0 0", False), ("30 40 50", False), ("30 40 50", True)])
def test_a_base_body_tilted_in_the_world_feels_gravity_in_its_frame(tmp_path, euler, top):
    """--base BODY on a body welded to the world at a tilt read MuJoCo's world gravity as its own
    frame's: torques wrong, and --check, on the same model, said OK (a new user's find). Against
    mj_inverse: the arm below the tilted mount; with a hinge above the mount (cut away by --base,
    at its reference position) the same, and a warning says so."""
    path = tmp_path / "tilted.xml"
    path.write_text(TILTED.format(euler=euler, top='<body name="top" euler="10 -20 5"><joint '
                                  'name="h" axis="1 0 0"/><geom type="sphere" size="0.05" mass="1"/>'
                                  if top else "", end="</body>" if top else ""))
    if top:
        with pytest.warns(VampcWarning, match=r"--base mount: the joints above it are cut away \(h "
                                              r"at 0: at their reference positions, qpos0\); "
                                              r"gravity is turned into mount's frame "
                                              r"through them there"):
            chain = load_robot(path, base="mount")
    else:
        chain = load_robot(path, base="mount")
    assert [j.name for j in chain.joints] == ["j1", "j2"]
    assert_as_mj_inverse_with_the_rest_at_qpos0(path, chain)


def test_a_base_bodys_own_joints_are_named_among_those_cut_away(tmp_path):
    """--base l1 cuts away l1's own joint j1 (to its parent) too; the warning named only the joints
    of the bodies above l1 (none here: nothing said; a new user's find). Against mj_inverse with j1 at
    its reference position."""
    path = tmp_path / "tilted.xml"
    path.write_text(TILTED.format(euler="30 40 50", top='<body name="top" euler="10 -20 5"><joint '
                                  'name="h" axis="1 0 0"/><geom type="sphere" size="0.05" mass="1"/>',
                                  end="</body>"))
    with pytest.warns(VampcWarning, match=r"--base l1: the joints above it are cut away \(h at 0, j1 "
                                          r"at 0:"):
        chain = load_robot(path, base="l1")
    assert [j.name for j in chain.joints] == ["j2"]
    assert_as_mj_inverse_with_the_rest_at_qpos0(path, chain)
    # a --lock of a joint above the base places it (it was dropped: "no effect"; a review's find)
    with pytest.warns(VampcWarning, match=r"the joints above it are cut away \(h at 0.4, j1 at -0.7:"):
        chain = load_robot(path, base="l1", lock={"h": 0.4, "j1": -0.7})
    assert_as_mj_inverse_with_the_rest_at_qpos0(path, chain, {0: 0.4, 1: -0.7})


def test_mimic_couple_says_it_has_no_effect_only_where_it_has_none(tmp_path):
    """--mimic couple warned "no joint has a <mimic>" (URDF's words) of a model whose equality
    holding a joint it had just locked (a new user's find); a model without joint equalities is
    told in MJCF's words."""
    import warnings
    held = tmp_path / "held.xml"
    held.write_text(ARM.replace("</mujoco>", '<equality><joint joint1="j4" polycoef="0.05 0 0 0 0"/>'
                                             "</equality></mujoco>"))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        chain = load_robot(held, mimic="couple")
    assert "j4" not in [j.name for j in chain.joints]
    plain = tmp_path / "plain.xml"
    plain.write_text(ARM)
    with pytest.warns(VampcWarning, match=r"no joint has a joint equality \(<equality><joint>\); "
                                          r"--mimic couple has no effect"):
        load_robot(plain, mimic="couple")


def test_inactive_equalities_are_named_as_the_errors_name_them(tmp_path):
    """An inactive equality is left out with a warning; an unnamed one was '#1' there (numbered
    from 0) where an error says '<equality> number 2 (unnamed)' (a new user's find)."""
    path = tmp_path / "inactive.xml"
    path.write_text(ARM.replace("</mujoco>", '<equality><joint name="e1" joint1="j4" active="false"/>'
                                             '<joint joint1="j2" joint2="j3" active="false"/>'
                                             "</equality></mujoco>"))
    with pytest.warns(VampcWarning, match=r"inactive equality 'e1', <equality> number 2 \(unnamed\) "
                                          r"left out"):
        chain = load_robot(path)
    assert [j.name for j in chain.joints] == ["j1", "j2", "j3", "j4", "j5", "j6"]


EQUALITY_ABOVE = TILTED.format(euler="30 40 50", top='<body name="top" euler="10 -20 5"><joint name="h0" '
                               'axis="1 0 0"/><geom type="sphere" size="0.05" mass="1"/><body name="mid" '
                               'pos="0 0 0.1"><joint name="h" axis="0 1 0"/><geom type="sphere" size="0.05" '
                               'mass="1"/>', end="</body></body>").replace(
    "</worldbody>", '</worldbody><equality><joint joint1="h" joint2="h0" polycoef="0.7 1.5 0 0 0"/></equality>')


@pytest.mark.parametrize("lock, said", [({}, "h0 at 0, h at 0.7"), ({"h0": 0.5}, "h0 at 0.5, h at 1.45")])
def test_an_equality_follower_above_the_base_is_where_its_leader_puts_it(tmp_path, lock, said):
    """--mimic couple: a joint equality's follower above --base was taken at qpos0, not where its
    leader puts it (6.1 N·m off mj_inverse with the equality kept; a review's find), and --mimic
    couple was said to have no effect."""
    path = tmp_path / "eq.xml"
    path.write_text(EQUALITY_ABOVE)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        chain = load_robot(path, base="mount", mimic="couple", lock=lock)
    texts = [str(w.message) for w in caught]
    assert any(f"({said}:" in t for t in texts) and not any("no effect" in t for t in texts), texts
    h0 = lock.get("h0", 0.0)
    assert_as_mj_inverse_with_the_rest_at_qpos0(path, chain, {0: h0, 1: 0.7 + 1.5 * h0})


TWO_HINGES = """<mujoco model="twohinge">
  <worldbody>
    <body name="A" pos="0 0 1" quat="0.9 0.3 0.2 0.1">
      <joint name="j0" axis="0 0 1"/>
      <geom type="sphere" size="0.05" mass="1"/>
      <body name="B" pos="0.3 0 0">
        <joint name="jb1" axis="1 0 0"/>
        <joint name="jb2" axis="0 1 0" pos="0.05 0 0"/>
        <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.03" mass="2"/>
        <body name="C" pos="0.3 0 0">
          <joint name="jc" axis="0 0 1"/>
          <geom type="capsule" fromto="0 0 0 0.2 0.1 0" size="0.03" mass="1"/>
        </body>
      </body>
    </body>
  </worldbody>
</mujoco>"""


@pytest.mark.parametrize("lock", [{}, {"j0": 0.4, "jb1": 0.7}])
def test_a_base_between_two_joints_of_one_body_feels_gravity_in_its_frame(tmp_path, lock):
    """--base B__jb1, the link between body B's two hinges, kept the world's gravity in its own frame
    and said nothing of the joints above it (4.64 N·m where mj_inverse gives 0.53 on a tilted mount;
    noticed in a review). Its frame is turned by the joints above, the first of B's two included."""
    path = tmp_path / "two.xml"
    path.write_text(TWO_HINGES)
    at = ", ".join(f"{name} at {lock.get(name, 0):g}" for name in ("j0", "jb1"))
    with pytest.warns(VampcWarning, match=rf"--base B__jb1: the joints above it are cut away \({at}:"):
        chain = load_robot(path, base="B__jb1", lock=lock)
    assert [j.name for j in chain.joints] == ["jb2", "jc"]
    assert_as_mj_inverse_with_the_rest_at_qpos0(path, chain, {0: lock.get("j0", 0), 1: lock.get("jb1", 0)})


def test_a_tendon_with_polynomial_stiffness_and_a_flex_are_refused(tmp_path):
    """A tendon whose stiffness or damping has only higher terms ("0 3") was left out as one that
    exerts no force, and a <flexcomp> rope's vertices were taken as independent slide joints, their
    elastic forces dropped (345 N where mj_inverse's rope pulled; a new user's find)."""
    arm = model("d", body("a", "0 0 0.1", [("j1", "hinge", "0 1 0", "0 0 0", None)],
                          inner=body("b", "0.3 0 0", [("j2", "hinge", "0 1 0", "0 0 0", None)])))
    path = tmp_path / "t.xml"
    for what in ("stiffness", "damping"):
        path.write_text(arm.replace("</worldbody>", f'</worldbody><tendon><fixed name="tf" {what}="0 3">'
                                    '<joint joint="j1" coef="1"/><joint joint="j2" coef="-1"/></fixed></tendon>'))
        assert_error(lambda: load_robot(path), path, rf"tendon 'tf': has {what}: tendons that exert forces "
                                                     r"are not supported \(the network computes an open tree\)")
    path.write_text(arm.replace("</worldbody>", '<flexcomp name="rope" type="grid" count="3 1 1" '
                                'spacing="0.1 0.1 0.1" pos="0 0 2" dim="1" radius="0.01" mass="0.3">'
                                '<edge equality="false" stiffness="50" damping="2"/><pin id="0"/></flexcomp>'
                                "</worldbody>"))
    assert_error(lambda: load_robot(path), path, r"flex 'rope': deformable \(flex\) objects are not "
                                                 r"supported \(the network computes rigid bodies in an open tree\)")


ON_A_HINGE = """<mujoco model="sj"><worldbody><body name="top" pos="0 0 1" quat="0.9 0.1 0.3 0.2">
 <joint name="h0" axis="0 1 0" pos="0.2 0.1 0.3"/><geom type="box" size="0.1 0.1 0.1" mass="2"/>
 <body name="l1" pos="0.3 0 0"><joint name="j1" axis="0 1 0" pos="0 0.05 0"/>
  <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.03"/></body></body></worldbody></mujoco>"""


def test_a_base_body_on_a_joint_has_its_frame_at_the_body_origin(tmp_path):
    """--floating-base --base top, a body on a hinge whose anchor is off the body's origin: the base's
    frame was at the anchor, where its motion was read and its wrench taken (0.23 of the wrench off
    the same body on a free joint; a new user's find). Its frame is the body's: against Pinocchio on
    the body given a free joint instead (vampc's floating base has the world's orientation: the body's
    quat is dropped there), and, on a fixed base, against mj_inverse with the hinge cut away."""
    path, free = tmp_path / "sj.xml", tmp_path / "free.xml"
    path.write_text(ON_A_HINGE)
    free.write_text(ON_A_HINGE.replace('<joint name="h0" axis="0 1 0" pos="0.2 0.1 0.3"/>', '<freejoint/>')
                    .replace(' quat="0.9 0.1 0.3 0.2"', ""))
    from vampc.compiler import CompileOptions, compile_chain, program_document
    from vampc.emulator import emulate, loaded_from_doc
    from vampc.emulator.host import check_torques, random_trajectory
    chain = load_robot(path, base="top", floating=True)
    assert [j.name for j in chain.joints] == ["j1"] and chain.floating
    traj = random_trajectory(chain, 6, 2)
    want = pin_reference(free, chain, traj)
    ld = loaded_from_doc(program_document(compile_chain(chain, CompileOptions())))
    tau = emulate(ld, traj, "stream").tau
    assert check_torques(chain, traj, tau).ok
    assert np.max(np.abs(tau - want)) <= 1e-12 * np.max(np.abs(want))
    with pytest.warns(VampcWarning, match=r"--base top: the joints above it are cut away \(h0 at 0:"):
        fixed = load_robot(path, base="top")
    assert_as_mj_inverse_with_the_rest_at_qpos0(path, fixed)


BRANCHES = """<mujoco model="br"><compiler angle="radian"/><option><flag contact="disable"/></option><worldbody><body name="torso" pos="0 0 1">
 <geom type="box" size="0.1 0.1 0.1" mass="2"/>
 <body name="l1" pos="0 0.2 0"><joint name="ls1" axis="1 0 0"/><geom type="capsule" fromto="0 0 0 0 0.2 0" size="0.03"/>
  <body name="l2" pos="0 0.2 0"><joint name="le" axis="0 1 0" ref="-0.3"/>
   <geom type="capsule" fromto="0 0 0 0.2 0.1 0" size="0.03"/></body></body>
 <body name="r1" pos="0 -0.2 0"><joint name="rs1" axis="1 0 0"/><geom type="capsule" fromto="0 0 0 0 -0.2 0" size="0.03"/>
  <body name="rhand" pos="0 -0.2 0"><joint name="re" axis="0 1 0"/>
   <geom type="capsule" fromto="0 0 0 0.2 0 0" size="0.03"/></body></body>
</body></worldbody></mujoco>"""


def test_a_joint_frozen_below_a_locked_branch_is_in_the_files_pose(tmp_path):
    """A joint below a locked branch was frozen at qpos = 0, off the file's pose when it has a
    reference position, while --base holds the joints it cuts away at qpos0 (a new user's find: the
    two conventions). Frozen at qpos0 now, said; against mj_inverse with it there."""
    path = tmp_path / "br.xml"
    path.write_text(BRANCHES)
    with pytest.warns(VampcWarning, match=r"joint 'le', below a locked joint, is frozen at -0\.3 \(its "
                                          r"reference position, qpos0\); give --lock le=VALUE"):
        chain = load_robot(path, tip="rhand", lock={"ls1": 0.2})
    assert [j.name for j in chain.joints] == ["rs1", "re"]
    assert_as_mj_inverse_with_the_rest_at_qpos0(path, chain, {0: 0.2, 1: -0.3})


def test_an_unnamed_joint_or_body_in_an_error_is_said_to_be_unnamed(tmp_path):
    """An error about an unnamed joint said "joint 'joint2'" (vampc's name for MuJoCo's joint 2, the
    third), which reads as a name in the file (a new user's find): its place and vampc's name."""
    path = tmp_path / "un.xml"
    path.write_text('<mujoco model="un"><worldbody><body name="a"><joint axis="0 1 0"/><geom size="0.1"/>'
                    '<body pos="0.2 0 0"><joint/><geom size="0.1"/><body pos="0.2 0 0"><joint type="ball"/>'
                    '<geom size="0.1"/></body></body></body></worldbody></mujoco>')
    assert_error(lambda: load_robot(path), path, r"<joint> number 3 \(unnamed; vampc calls it 'joint2'\): "
                                                 r"ball joints are not supported \(one degree of freedom per "
                                                 r"joint: use three hinges\)")
    path.write_text('<mujoco model="un"><worldbody><body name="a"><freejoint/><geom size="0.1"/>'
                    '<body pos="0.2 0 0"><joint/><geom size="0.1"/></body></body>'
                    '<body pos="0 1 0"><freejoint/><geom size="0.1"/></body></worldbody></mujoco>')
    assert_error(lambda: load_robot(path), path, r"body 'a': has a free joint \(a floating base\) but the "
                                                 r"world also carries 'body3' .*")
    path.write_text(path.read_text().replace('<body name="a">', "<body>"))
    assert_error(lambda: load_robot(path), path, r"<body> number 1 \(unnamed; vampc calls it 'body1'\): has "
                                                 r"a free joint \(a floating base\) but the world also carries "
                                                 r"'body3' .*")


def test_mujocos_own_warnings_are_one_line_each_and_leave_no_log(tmp_path, monkeypatch):
    """MuJoCo's compiler warning (a flex without constraints) printed two lines of its own ahead of
    vampc's error and wrote MUJOCO_LOG.TXT into the folder (a new user's find): the error comes
    alone, no file is left; on a model vampc takes, MuJoCo's warning is one vampc warning."""
    monkeypatch.chdir(tmp_path)
    arm = model("d", body("a", "0 0 0.1", [("j1", "hinge", "0 1 0", "0 0 0", None)]))
    path = tmp_path / "cloth.xml"
    path.write_text(arm.replace("</worldbody>", '<flexcomp name="cloth" type="grid" count="3 3 1" '
                                'spacing="0.1 0.1 0.1" pos="0 0 2" dim="2" radius="0.01" mass="0.3"/>'
                                "</worldbody>"))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert_error(lambda: load_robot(path), path, r"flex 'cloth': deformable \(flex\) objects are not "
                                                     r"supported \(the network computes rigid bodies in an "
                                                     r"open tree\)")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cloth.xml"]
    real = mujoco.MjModel.from_xml_path

    def warning_first(name):
        mujoco.get_mju_user_warning()("something odd\nElement name 'a', id 1")
        return real(name)
    monkeypatch.setattr(mujoco.MjModel, "from_xml_path", staticmethod(warning_first))
    (tmp_path / "arm.xml").write_text(arm)
    with pytest.warns(VampcWarning, match=r"arm\.xml: MuJoCo warns: something odd Element name 'a', id 1$"):
        assert load_robot(tmp_path / "arm.xml").n == 1


def test_the_link_after_a_bodys_last_joint_is_the_body(tmp_path):
    """--base B__jb2, after B's last joint, was only an 'unknown base link' (a new user's find): the
    message says that link is B itself."""
    path = tmp_path / "two.xml"
    path.write_text(TWO_HINGES)
    assert_error(lambda: load_robot(path, base="B__jb2"), path,
                 r"unknown base link 'B__jb2' \(the link after jb2, B's last joint, is B itself\)")


def test_the_link_after_a_last_joint_named_with_underscores_and_as_tip(tmp_path):
    """The hint took the joint's name from the text after the last '__' ('k__2' read as '2'), and
    --tip had none (review)."""
    path = tmp_path / "two.xml"
    path.write_text(TWO_HINGES.replace('name="jb2"', 'name="k__2"'))
    assert_error(lambda: load_robot(path, base="B__k__2"), path,
                 r"unknown base link 'B__k__2' \(the link after k__2, B's last joint, is B itself\)")
    assert_error(lambda: load_robot(path, tip="B__k__2"), path,
                 r"unknown tip link 'B__k__2' \(the link after k__2, B's last joint, is B itself\)")
    assert mujoco.get_mju_user_warning() is None       # (MuJoCo's handler put back)


def test_a_slide_without_a_range_is_unlimited_without_a_warning(tmp_path):
    """An MJCF joint without a range is unlimited by MuJoCo's rules: a slide so was warned of in
    the URDF specification's words ("no <limit>, which the URDF specification requires", a
    README audit's find). The model still reads it as unlimited."""
    path = tmp_path / "slide.xml"
    path.write_text(model("slide", body("a", "0 0 0.1", [("j1", "hinge", "0 0 1", "0 0 0", "-1 1")], inner=body(
        "b", "0 0 0.2", [("j2", "slide", "1 0 0", "0 0 0", None)]))))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        chain = load_robot(path)
    assert [j.name for j in chain.joints] == ["j1", "j2"]
    assert chain.joints[1].limits.q is None


def test_the_joints_a_program_leaves_out_are_the_ones_the_file_names(tmp_path):
    """The robot's left_out (the file's joints the chain does not hold, which a limits file may name)
    lists the MJCF's named joints only: not the fixed joints vampc makes for a welded body or a body's
    origin, nor an unnamed joint's made-up 'jointK'."""
    welded = tmp_path / "weld.xml"
    welded.write_text(
        '<mujoco model="w"><worldbody><body name="a" pos="0 0 0.1"><joint name="ja" axis="0 0 1"/>'
        '<geom type="sphere" size="0.05" mass="1"/><body name="w" pos="0.1 0 0"><geom type="sphere" '
        'size="0.05" mass="1"/><body name="b" pos="0.1 0 0"><joint axis="0 1 0"/><geom type="sphere" '
        'size="0.05" mass="1"/></body></body></body></worldbody></mujoco>')
    assert load_robot(welded).left_out == ()
    two = tmp_path / "two.xml"
    two.write_text(TWO_HINGES)
    assert load_robot(two).left_out == ()
    with pytest.warns(Warning, match="--base A: the joints above it are cut away"):
        cut = load_robot(two, base="A", tip="C")               # j0 above the base
    assert [j.name for j in cut.joints] == ["jb1", "jb2", "jc"] and cut.left_out == ("j0",)
    with pytest.warns(Warning, match="--base A: the joints above it are cut away"):
        locked = load_robot(two, base="A", tip="B", lock={"jc": 0.1})     # a lock's joint is its own
    assert locked.locked == ("jc",) and locked.left_out == ("j0",)


def test_a_joint_an_equality_holds_is_left_out_not_lost(tmp_path):
    """--mimic couple locks a joint an MJCF <equality> holds at a value; it was dropped from
    `locked` (the user's --lock only) and not put in `left_out`, so a limits file naming it was
    'no joint named' (a review's find)."""
    robot = tmp_path / "eq.xml"
    robot.write_text(
        '<mujoco model="eq"><worldbody><body name="a" pos="0 0 0.1"><joint name="j1" axis="0 0 1"/>'
        '<geom type="sphere" size="0.05" mass="1"/><body name="b" pos="0.1 0 0"><joint name="j2" '
        'axis="0 1 0"/><geom type="sphere" size="0.05" mass="1"/><body name="c" pos="0.1 0 0"><joint '
        'name="j3" axis="0 1 0"/><geom type="sphere" size="0.05" mass="1"/></body></body></body>'
        '</worldbody><equality><joint joint1="j2" polycoef="0.3 0 0 0 0"/></equality></mujoco>')
    held = load_robot(robot, mimic="couple")
    assert [j.name for j in held.joints] == ["j1", "j3"] and held.locked == () and held.left_out == ("j2",)
    mine = load_robot(robot, mimic="couple", lock={"j3": 0.1})        # the user's own lock stays one
    assert mine.locked == ("j3",) and mine.left_out == ("j2",)


def test_floating_an_mjcf_without_a_free_joint_floats_its_top_body(tmp_path):
    """--floating-base on an MJCF with no free joint floated the world body: the base at the world's
    origin (the trunk 0.4 m above it) and a table welded to the world counted in it, exit 0 unsaid
    (base_fz 203 N over; a new user's find). Pinocchio (a free-flyer root on the file) and MuJoCo float
    the robot's top body: so does vampc, checked against Pinocchio's rnea here."""
    from vampc.compiler import CompileOptions, compile_chain, program_document
    from vampc.emulator import emulate, loaded_from_doc
    from vampc.emulator.host import random_trajectory
    path = tmp_path / "trunk.xml"
    path.write_text(
        '<mujoco model="t"><compiler angle="radian"/><worldbody>'
        '<body name="trunk" pos="0 0 0.4"><inertial pos="0 0 0" mass="8" diaginertia="0.05 0.12 0.14"/>'
        '<body name="thigh" pos="0.25 0.1 0"><joint name="hip" type="hinge" axis="0 1 0" range="-2 2"/>'
        '<inertial pos="0 0 -0.1" mass="1" diaginertia="0.003 0.003 0.0003"/></body></body>'
        '<body name="table" pos="2 0 0"><inertial pos="0 0 0" mass="20" diaginertia="1 1 1"/></body>'
        '</worldbody></mujoco>')
    chain = load_robot(path, floating=True)
    assert chain.floating and [j.name for j in chain.joints] == ["hip"]
    assert chain.base_mass == pytest.approx(8.0)              # the trunk's, not the table's too
    traj = random_trajectory(chain, 5, 3)
    want = pin_reference(path, chain, traj, free_flyer=True)
    ld = loaded_from_doc(program_document(compile_chain(chain, CompileOptions())))
    got = emulate(ld, traj, "stream").tau
    assert np.max(np.abs(got - want)) <= 1e-9 * np.max(np.abs(want)), (got[0], want[0])


def test_floating_the_world_body_with_a_table_or_two_robots_on_it_is_refused(tmp_path):
    """An arm hinged straight to the world beside a welded table, or two bodies on joints of their
    own under the world: --floating-base floated the world body, the table's 50 kg in the base
    (base_fz 517 N at rest where MuJoCo's free-jointed arm gives 27 N), or both robots as one,
    exit 0 unsaid (a new user's find). Refused, saying why; the arm alone still floats (the world
    body, massless), and both files compile on a fixed base as before."""
    arm = ('<body name="arm" pos="0 0 0.5"><joint name="h1" axis="0 0 1"/><geom type="capsule" '
           'fromto="0 0 0 0.3 0 0" size="0.04"/><body name="fore" pos="0.3 0 0"><joint name="h2" '
           'axis="0 1 0"/><geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.03"/></body></body>')
    table = '<body name="table" pos="2 0 0"><geom type="box" size="0.5 0.5 0.05" mass="50"/></body>'
    other = ('<body name="b" pos="1 0 1"><joint name="jb" type="slide" axis="1 0 0"/>'
             '<geom type="box" size="0.1 0.1 0.1"/></body>')
    files = {}
    for name, bodies in (("table_arm", table + arm), ("two", arm + other), ("arm", arm)):
        files[name] = tmp_path / f"{name}.xml"
        files[name].write_text(f'<mujoco model="{name}"><worldbody>{bodies}</worldbody></mujoco>')
    assert_error(lambda: load_robot(files["table_arm"], floating=True), files["table_arm"],
                 r"--floating-base: 'arm' hangs on joint 'h1' from the world body, so the world body "
                 r"would float, and with it 'table', welded to it with no joint below: give the robot "
                 r"a free joint in the file to float it alone, or float 'arm' itself with --base "
                 r"arm \(README, MJCF\)")
    assert_error(lambda: load_robot(files["two"], floating=True), files["two"],
                 r"--floating-base: the world body carries 2 bodies with joints \('arm', 'b'\), each a "
                 r"robot of its own, .*--base BODY \(README, MJCF\)")
    alone = load_robot(files["arm"], floating=True)
    assert alone.floating and alone.base_mass == 0 and [j.name for j in alone.joints] == ["h1", "h2"]
    # a welded body of no mass (a camera's, a site's) floats with the world body as before: it
    # changes nothing (a review's find: refused)
    for extra in ('<body name="cambody" pos="1 0 1"><camera name="c"/></body>',
                  '<body name="target" pos="1 0 0"><site name="s"/></body>'):
        scene = tmp_path / "scene.xml"
        scene.write_text(f'<mujoco model="s"><worldbody>{extra}{arm}</worldbody></mujoco>')
        chain = load_robot(scene, floating=True)
        assert chain.floating and chain.base_mass == 0 and [j.name for j in chain.joints] == ["h1", "h2"]
    for name in ("table_arm", "two"):
        assert not load_robot(files[name]).floating


def test_a_number_that_is_not_finite_leaves_mujocos_warning_handler_as_it_was(tmp_path):
    """The check of the file's numbers ran after vampc had taken MuJoCo's warning handler (the
    process's) and outside the code that gives it back: a refused `nan` left vampc's in place, so
    the next test that asked for MuJoCo's handler failed, in one order of the suite only."""
    path = tmp_path / "nan.xml"
    path.write_text(TWO_HINGES.replace('pos="0.3 0 0"', 'pos="nan 0 0"', 1))
    assert mujoco.get_mju_user_warning() is None
    with pytest.raises(VampcError, match="pos: 'nan' is not a finite number"):
        load_robot(path)
    assert mujoco.get_mju_user_warning() is None


def test_a_free_joints_turned_body_is_said_in_mjcfs_words(tmp_path):
    """An MJCF free joint on a turned body was warned of "the turn of its <origin> (rpy)", a URDF's
    words (a new user's find): its body's orientation attributes are named."""
    path = tmp_path / "free.xml"
    path.write_text('<mujoco model="m"><worldbody><body name="base" pos="0 0 1" euler="0 0 20">'
                    '<freejoint name="root"/><geom type="sphere" size="0.1" mass="2"/>'
                    '<body name="a" pos="0.2 0 0"><joint name="j1" axis="0 0 1"/>'
                    '<geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.03" mass="1"/></body>'
                    '</body></worldbody></mujoco>')
    with pytest.warns(VampcWarning) as heard:
        load_robot(path)
    said = [str(w.message) for w in heard if "free joint" in str(w.message)]
    assert len(said) == 1 and "the free joint of body 'base': the turn of its body (quat, euler, " \
        "axisangle, xyaxes or zaxis) is not used" in said[0] and "<origin>" not in said[0], said
    # a free joint left unnamed: by its body, not by 'joint0', vampc's name for it (a new user's)
    path.write_text(path.read_text().replace('<freejoint name="root"/>', "<freejoint/>"))
    with pytest.warns(VampcWarning) as heard:
        load_robot(path)
    said = [str(w.message) for w in heard if "is not used" in str(w.message)]
    assert len(said) == 1 and "the free joint of body 'base': the turn" in said[0] and \
        "joint0" not in said[0], said


ROBOT_XML = """<mujoco model="r">
  <worldbody>
    <body name="upper" pos="0 0 0">
      <joint name="shoulder" type="hinge" axis="0 0 1"/>
      <inertial pos="0.05 0 0" mass="1" diaginertia="0.01 0.02 0.025"/>
      <body name="lower" pos="0.3 0 0">
        <joint name="elbow" type="hinge" axis="0 1 0"/>
        <inertial pos="0.05 0 0" mass="1" diaginertia="0.01 0.02 0.025"/>
      </body>
    </body>
  </worldbody>
</mujoco>
"""


@pytest.mark.parametrize("edit, line, element, said", [
    (('<body name="lower"', '<body name="lower" bogus="1"'), 6, "<body name='lower'>",
     r"XML Error: Schema violation: unrecognized attribute: 'bogus' Element 'body'"),
    (('name="elbow"', 'name="shoulder"'), 7, "<joint name='shoulder'>",
     r"XML Error: Error: repeated name 'shoulder' in joint Element 'joint'"),
    (('mass="1" diaginertia="0.01 0.02 0.025"/>\n      <body', 'mass="-1" diaginertia="0.01 0.02 0.025"/>\n      <body'),
     3, "<body name='upper'>", r"Error: .*Element name 'upper', id 1"),
    (('<inertial pos="0.05 0 0" mass="1"', '<inertialx pos="0.05 0 0" mass="1"'), 5, "<inertialx>",
     r"XML Error: Schema violation: unrecognized element Element 'inertialx'"),
])
def test_an_error_in_an_included_file_names_that_file_and_line(tmp_path, edit, line, element, said):
    """MuJoCo says "line 0" of an element of an included file: an error in a robot's file, compiled
    through the scene that includes it, was said of the scene, line 0 (a Menagerie trial's find).
    The file and line of the element are named; the same file compiled alone gives that line too."""
    robot = tmp_path / "robot.xml"
    robot.write_text(ROBOT_XML.replace(*edit, 1))
    scene = tmp_path / "scene.xml"
    scene.write_text('<mujoco model="scene">\n  <include file="robot.xml"/>\n  <option gravity="0 0 -9.81"/>\n'
                     '</mujoco>\n')
    assert_error(lambda: load_robot(scene), robot,
                 rf"line {line}: {re.escape(element)}: MuJoCo cannot read {re.escape(str(scene))} \({said}\)")
    with pytest.raises(VampcError, match=rf"line {line}\)$"):       # (MuJoCo's own, alone)
        load_robot(robot)


def test_an_error_in_an_included_file_no_one_element_fits_names_the_files(tmp_path):
    """Where the message fits no one element of the included files (two have the attribute), the
    message says MuJoCo's line 0 is in a file the model includes, and names them."""
    robot = tmp_path / "robot.xml"
    robot.write_text(ROBOT_XML.replace('<body name="', '<body bogus="1" name="'))
    scene = tmp_path / "scene.xml"
    scene.write_text('<mujoco model="scene">\n  <include file="robot.xml"/>\n</mujoco>\n')
    assert_error(lambda: load_robot(scene), scene,
                 r"MuJoCo cannot read it \(XML Error: Schema violation: unrecognized attribute: 'bogus' "
                 rf"Element 'body', line 0; MuJoCo gives line 0 for an element of a file it includes: "
                 rf"{re.escape(str(robot))}\)")


# the arm above with two fingers on its forearm, held together by a connect equality (a linkage)
FINGER = ('        <body name="{0}" pos="0.2 {1} 0">\n          <joint name="{2}" type="hinge" axis="0 0 1"/>\n'
          '          <inertial pos="0.02 0 0" mass="0.1" diaginertia="0.001 0.001 0.001"/>\n        </body>\n')
GRIPPER_XML = (ROBOT_XML.replace('model="r"', 'model="g"').replace('name="shoulder"', 'name="j1"')
               .replace('name="elbow"', 'name="j2"')
               .replace("      </body>\n    </body>", FINGER.format("left", "0.02", "f1")
                        + FINGER.format("right", "-0.02", "f2") + "      </body>\n    </body>")
               .replace("</mujoco>\n", '  <equality>\n    <connect name="linkage" body1="left" body2="right" '
                        'anchor="0.02 0 0"/>\n  </equality>\n</mujoco>\n'))


@pytest.mark.parametrize("edit, options, joints, said", [
    (("", ""), dict(lock={"f1": 0.2, "f2": -0.1}), ["j1", "j2"], "connect of 'left' and 'right'"),
    (('body1="left" body2="right"', 'body1="upper"'), dict(base="lower"), ["f1", "f2"],
     "connect of 'upper' and 'world'"),
], ids=["locked", "above-the-base"])
def test_a_loop_no_joint_of_which_moves_is_left_out_with_a_warning(tmp_path, edit, options, joints, said):
    """A connect or weld equality was refused whatever the joints of its loop were locked at (a
    Menagerie trial's find: an xarm7 with its Robotiq gripper's joints locked, or compiled to its
    wrist with --tip). With every joint between its two bodies locked or left out, the loop's
    bodies are one rigid body and its forces internal to it: it is left out, said, and the robot is
    the file's without the equality (the same torques)."""
    from vampc.dynamics.reference import rnea
    looped, plain = tmp_path / "looped.xml", tmp_path / "plain.xml"
    looped.write_text(GRIPPER_XML.replace(*edit))
    plain.write_text(GRIPPER_XML.replace(GRIPPER_XML[GRIPPER_XML.index("  <equality>"):
                                                     GRIPPER_XML.index("</mujoco>")], ""))
    assert_error(lambda: load_robot(looped), looped,
                 r"equality 'linkage': connect equality constraints are not supported \(the network "
                 r"computes an open tree; joint equalities are read as mimic joints\): its loop moves on "
                 rf"joints? '{'f1' if options.get('lock') else 'j1'}'.* \(a loop no joint of which moves, "
                 r"all locked or above a fixed --base, is left out\)")
    with pytest.warns(VampcWarning, match=rf"equality 'linkage' \({said}\) left out: no joint between "
                                          r"its bodies moves in the compiled robot"):
        chain = load_robot(looped, **options)
    want = load_robot(plain, **options)
    assert [j.name for j in chain.joints] == [j.name for j in want.joints] == joints
    rng = np.random.default_rng(0)
    q, qd, qdd = (rng.normal(size=(5, 2)) for _ in range(3))
    assert np.array_equal(rnea(chain, q, qd, qdd), rnea(want, q, qd, qdd))


def test_a_loop_through_a_joint_the_robot_keeps_is_refused_naming_it(tmp_path):
    """A loop from a finger to the link before the wrist joint moves with that joint, whatever the
    fingers are locked at: refused, naming the joint that moves."""
    path = tmp_path / "g.xml"
    path.write_text(GRIPPER_XML.replace('body2="right"', 'body2="upper"'))
    assert_error(lambda: load_robot(path, lock={"f1": 0.0, "f2": 0.0}), path,
                 r"equality 'linkage': connect equality constraints are not supported \(.*\): its loop "
                 r"moves on joint 'j2' \(.*\)")


def test_an_error_in_a_nested_include_is_found_where_mujoco_reads_it(tmp_path):
    """An include of an include is read from the model's folder where that has the file, else from
    the including file's (MuJoCo 4); and a name repeated in two included files is the one MuJoCo
    reads later, an include read where it stands (a review's finds: the folders the other way
    round named sub/b.xml where MuJoCo read ./b.xml, and a breadth-first order the first copy)."""
    body = ('<mujoco>\n  <body name="{b}" pos="0.3 0 0">\n    <joint name="{j}" type="hinge" axis="0 1 0"{x}/>\n'
            '    <inertial pos="0.05 0 0" mass="1" diaginertia="0.01 0.02 0.025"/>\n  </body>\n</mujoco>\n')
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "a.xml").write_text(
        '<mujoco>\n  <body name="upper">\n    <joint name="shoulder" type="hinge" axis="0 0 1"/>\n'
        '    <inertial pos="0.05 0 0" mass="1" diaginertia="0.01 0.02 0.025"/>\n'
        '    <include file="b.xml"/>\n  </body>\n</mujoco>\n')
    (tmp_path / "sub" / "b.xml").write_text(body.format(b="lower", j="elbow", x=' bogus="1"'))
    (tmp_path / "b.xml").write_text(body.format(b="lower", j="elbow", x=' bogus="2"'))
    model = tmp_path / "m.xml"
    model.write_text('<mujoco model="m">\n  <worldbody>\n    <include file="sub/a.xml"/>\n  </worldbody>\n'
                     '</mujoco>\n')
    assert_error(lambda: load_robot(model), tmp_path / "b.xml",
                 rf"line 3: <joint name='elbow'>: MuJoCo cannot read {re.escape(str(model))} \(.*'bogus'.*\)")
    (tmp_path / "b.xml").unlink()            # (then the including file's folder's)
    assert_error(lambda: load_robot(model), tmp_path / "sub" / "b.xml",
                 rf"line 3: <joint name='elbow'>: MuJoCo cannot read {re.escape(str(model))} \(.*'bogus'.*\)")
    # a name repeated: first in c.xml (included by a.xml), then in d.xml, included after a.xml
    (tmp_path / "a.xml").write_text('<mujoco>\n  <include file="c.xml"/>\n</mujoco>\n')
    (tmp_path / "c.xml").write_text(body.format(b="one", j="dup", x=""))
    (tmp_path / "d.xml").write_text('<mujoco>\n\n' + body.format(b="two", j="dup", x="")[10:])
    model.write_text('<mujoco model="m">\n  <worldbody>\n    <include file="a.xml"/>\n'
                     '    <include file="d.xml"/>\n  </worldbody>\n</mujoco>\n')
    assert_error(lambda: load_robot(model), tmp_path / "d.xml",
                 rf"line 4: <joint name='dup'>: MuJoCo cannot read {re.escape(str(model))} \(.*repeated "
                 r"name 'dup'.*\)")


@pytest.mark.parametrize("weld, options, said", [
    ('<weld name="w" body1="cube"/>', dict(base="world"), None),
    ('<weld name="w" body1="upper"/>', dict(base="lower", floating=True), None),
    ('<weld name="w" body1="upper"/>', {}, "the floating base 'upper'"),
    ('<weld name="w" body1="left" body2="upper"/>', dict(lock={"f1": 0.0}), "joint 'j2'"),
], ids=["free-cube-left-out", "above-a-floating-base", "the-floating-base", "through-a-joint"])
def test_a_loop_through_a_free_joint_moves_only_with_the_floating_base(tmp_path, weld, options, said):
    """A free joint on a loop's way moves only where it is the robot's floating base and the loop
    holds it (one body in the robot, the other not): a free cube welded to the world, left out with
    --base world, and a weld above a floating --base, were refused as moving on the free joint (a
    review's find)."""
    text = GRIPPER_XML.replace('<body name="upper" pos="0 0 0">\n      <joint name="j1" type="hinge" axis="0 0 1"/>',
                               '<body name="upper" pos="0 0 0">\n      <freejoint name="root"/>')
    if "cube" in weld:
        text = GRIPPER_XML.replace("  </worldbody>", '    <body name="cube" pos="1 0 0">\n      <freejoint/>\n'
                                   '      <inertial pos="0 0 0" mass="1" diaginertia="0.01 0.01 0.01"/>\n'
                                   '    </body>\n  </worldbody>')
    text = text.replace('<connect name="linkage" body1="left" body2="right" anchor="0.02 0 0"/>', weld)
    path = tmp_path / "w.xml"
    path.write_text(text)
    if said is None:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            load_robot(path, **options)
        assert any(re.search(r"equality 'w' \(weld of '\w+' and 'world'\) left out", str(w.message))
                   for w in caught), [str(w.message) for w in caught]
    else:
        assert_error(lambda: load_robot(path, **options), path,
                     rf"equality 'w': weld equality constraints are not supported \(.*\): its loop moves on "
                     rf"{said} \(.*\)")


def test_an_mjcf_error_comes_alone_and_a_free_body_beside_a_named_base_is_said(tmp_path):
    """The warnings of reading a model (armature ignored, no model name, ...) wait until the robot
    is made: a refused loop's error came after them (a review's find). And a free body beside the
    robot that --base names is left out as --base world leaves it out, said (a Menagerie trial's:
    said for --base world only)."""
    from click.testing import CliRunner

    from vampc.cli import main
    path = tmp_path / "g.xml"
    path.write_text(GRIPPER_XML.replace('name="j1"', 'name="j1" armature="0.1"'))
    out = tmp_path / "g.vamp.json"
    r = CliRunner().invoke(main, ["compile", str(path), "-o", str(out)])
    assert r.exit_code == 1 and not out.exists()
    assert r.stderr.count("\n") == 1 and r.stderr.startswith(f"vampc: error: {path}: equality 'linkage'"), r.stderr
    r = CliRunner().invoke(main, ["compile", str(path), "--lock", "f1=0", "--lock", "f2=0", "-o", str(out)])
    assert r.exit_code == 0 and "armature" in r.stderr and "equality 'linkage'" in r.stderr, r.stderr
    cube = tmp_path / "c.xml"
    cube.write_text(GRIPPER_XML.replace('<body name="upper" pos="0 0 0">\n      <joint name="j1" type="hinge" axis="0 0 1"/>',
                                        '<body name="upper" pos="0 0 0">\n      <freejoint name="root"/>')
                    .replace("  </worldbody>", '    <body name="cube" pos="1 0 0">\n      <freejoint/>\n'
                             '      <inertial pos="0 0 0" mass="1" diaginertia="0.01 0.01 0.01"/>\n'
                             '    </body>\n  </worldbody>'))
    with pytest.warns(VampcWarning, match=r"--base upper: 'cube' on a free joint floats apart from the "
                                          r"robot below it and is left out"):
        chain = load_robot(cube, base="upper", floating=True, lock={"f1": 0.0, "f2": 0.0})
    assert [j.name for j in chain.joints] == ["j2"]


def test_a_loop_on_a_floating_world_body_and_a_free_body_beside_a_link_base(tmp_path):
    """--floating-base on a model whose top body hinges to the world floats the world body: a weld
    to the world held inside it, its joints locked, was refused as moving on the floating base
    (the hinged body was taken for the base: a review's find). And a free body beside a base named
    as a link between two joints of a body (BODY__JOINT) is said to be left out, as beside BODY."""
    path = tmp_path / "a.xml"
    path.write_text(GRIPPER_XML.replace('<connect name="linkage" body1="left" body2="right" anchor="0.02 0 0"/>',
                                        '<weld name="w" body1="lower"/>'))
    with pytest.warns(VampcWarning, match=r"equality 'w' \(weld of 'lower' and 'world'\) left out"):
        chain = load_robot(path, floating=True, lock={"j1": 0.0, "j2": 0.0})
    assert chain.floating and [j.name for j in chain.joints] == ["f1", "f2"]
    assert_error(lambda: load_robot(path, floating=True, lock={"j1": 0.0}), path,
                 r"equality 'w': weld equality constraints are not supported \(.*\): its loop moves on "
                 r"joint 'j2' \(.*\)")
    two = tmp_path / "two.xml"
    two.write_text(GRIPPER_XML.replace('<joint name="j2" type="hinge" axis="0 1 0"/>',
                                       '<joint name="j2" type="hinge" axis="0 1 0"/>\n        '
                                       '<joint name="j2b" type="hinge" axis="1 0 0"/>')
                   .replace("  </worldbody>", '    <body name="cube" pos="1 0 0">\n      <freejoint/>\n'
                            '      <inertial pos="0 0 0" mass="1" diaginertia="0.01 0.01 0.01"/>\n'
                            '    </body>\n  </worldbody>')
                   .replace("  <equality>\n    <connect name=\"linkage\" body1=\"left\" body2=\"right\" "
                            "anchor=\"0.02 0 0\"/>\n  </equality>\n", ""))
    with pytest.warns(VampcWarning, match=r"--base lower__j2: 'cube' on a free joint floats apart"):
        load_robot(two, base="lower__j2")


LEGS_XML = """<mujoco model="legs">
  <worldbody>
    <body name="torso" pos="0 0 1">
      <freejoint name="root"/>
      <geom type="box" size="0.2 0.1 0.05" mass="5"/>
      <body name="a1" pos="0.2 0 0">
        <joint name="ja1" type="hinge" axis="0 1 0"/>
        <geom type="capsule" fromto="0 0 0 0 0 -0.3" size="0.03" mass="1"/>
        <body name="a2" pos="0 0 -0.3">
          <joint name="ja2" type="hinge" axis="0 1 0"/>
          <geom type="capsule" fromto="0 0 0 0 0 -0.3" size="0.03" mass="1"/>
        </body>
      </body>
      <body name="b1" pos="-0.2 0 0">
        <joint name="jb1" type="hinge" axis="0 1 0"/>
        <geom type="capsule" fromto="0 0 0 0 0 -0.3" size="0.03" mass="1"/>
      </body>
    </body>
    <body name="cube" pos="1 0 0">
      <freejoint/>
      <geom type="box" size="0.05 0.05 0.05" mass="1"/>
    </body>
  </worldbody>
</mujoco>
"""


def test_a_base_below_the_top_body_says_what_beside_it_is_left_out(tmp_path):
    """--base a1 left leg b out (floating, the torso too, with its free joint), saying nothing, as
    for a URDF (a founder's reread): said after the way up is, in the model's order, as bodies; the
    cube floating apart is said on its own, not here."""
    path = tmp_path / "legs.xml"
    path.write_text(LEGS_XML)
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        chain = load_robot(path, base="a1")
    said = [str(w.message) for w in seen]
    assert [j.name for j in chain.joints] == ["ja2"]
    cut = [k for k, t in enumerate(said) if "the joints above it are cut away" in t]
    beside = [k for k, t in enumerate(said) if "beside the way up" in t]
    assert len(cut) == 1 and beside == [cut[0] + 1], said
    assert said[beside[0]].endswith("--base a1: the branches beside the way up to it are left out (1 "
                                    "moving joint: 'jb1'); the fixed base takes their forces, so no "
                                    "torque below it depends on them"), said
    with pytest.warns(VampcWarning) as seen:
        chain = load_robot(path, base="a1", floating=True)
    said = [str(w.message) for w in seen if "above and beside" in str(w.message)]
    assert len(said) == 1 and said[0].endswith(
        "--base a1 --floating-base: only 'a1' and what hangs below it float; the bodies above and "
        "beside it are left out ('torso', 'b1' with mass; 3 moving joints: 'root', 'ja1', 'jb1'), so they "
        "do not load the floating base"), said
    assert chain.floating and [j.name for j in chain.joints] == ["ja2"]
