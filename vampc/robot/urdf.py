"""URDF → Chain (README, *URDF*).

A URDF joint k has an origin T_k (pose of the child link frame in the parent link frame at q = 0) and a unit
axis a_k in the child frame. We put O_{k-1} at joint k's origin, fixed in link k-1, with z along a_k:
O_{k-1} = T_k R_{a_k}, R_{a_k} a fixed rotation with R_{a_k} e_z = a_k. If G_k is the pose of O_k in link
k's own frame (G_k = X T_{k+1} R_{a_{k+1}} with X the pose, through fixed joints, of joint k+1's parent
link; for the last link G_n is the pose of the tip link), then O_k in O_{k-1} is R_{a_k}ᵀ M_k(q) G_k with
M_k(q) = R_{a_k} Rz(q) R_{a_k}ᵀ (revolute) or a translation q a_k (prismatic). Hence exactly

    A_k = Rz(q) Φ_k,   Φ_k = R_{a_k}ᵀ Rot(G_k),   p*_k = Φ_kᵀ R_{a_k}ᵀ t(G_k)   (+ q Φ_kᵀ e_z if prismatic)

with offset 0. Links hanging on link k through fixed (or locked) joints form one rigid body with it: their
inertials are summed into link k by the parallel-axis theorem. Gravity is [0, 0, -9.81] in the root link's
frame (Pinocchio's reading), turned into the base link's frame through the joints above it (at their
--lock values, else 0) when --base names a link below the root (a floating base is not turned: it keeps
the world's orientation), and referred to O_0.

The file is parsed by lxml with entities off and refused if it declares any (entity bombs, external
entities) before yourdfpy sees it; the structure and numbers vampc relies on are checked on that lxml tree
too, so that yourdfpy (`URDF.load`, without scene graphs or meshes) never crashes on them, and whatever it
still raises is one line "yourdfpy cannot read it (...)". yourdfpy reads the file, not code of our own:
a well-kept library's reading (defaults, rpy order, which elements count) is less likely than ours to
disagree with urdfdom on a user's file. It is linear, and the slowest step of a big load (about 13 of the
21 s of a 100 000-joint chain: benchmarks/load_robot.py). Everything after it is O(n) in the number of
links and joints: the tree walks (vampc/robot/urdf_tree.py) are iterative and visit each joint a bounded
number of times, Φ_k, p*_k and the bodies' inertias are computed as numpy stacks, and the garbage
collector is paused while loading. A chain of more than MAX_JOINTS (vampc/robot/dh.py) movable joints is
refused. Every problem is a one-line VampcError "FILE: joint 'x': WHAT", "FILE: link 'x': WHAT" or
"FILE: line N: WHAT"; a --lock of a fixed joint is a VampcWarning.
"""
from __future__ import annotations

import codecs
import dataclasses
import io
import math
import re
import warnings
from contextvars import ContextVar
from pathlib import Path

import numpy as np
from lxml import etree

from vampc.errors import VampcUsageError, VampcWarning, located
from vampc.gcpause import gc_paused
from vampc.robot.chain import Chain, Joint, Limits, matmul, matvec
from vampc.robot.dh import joint_count_problem
from vampc.robot.inertia import (
    NEARLY_PSD,
    NEARLY_PSD_ABS,
    improper_inertias,
    inertia_problem,
)
from vampc.robot.urdf_tree import (
    MOVABLE,
    Tree,
    check_joint_types,
    choose_base,
    choose_tip,
    cut_away,
    follows_from_below,
    listed,
    quoted,
    turns,
)
from vampc.textio import did_you_mean, name_problem, one_line, plain_number

GRAVITY = np.array([0.0, 0.0, -9.81])

# Numeric attributes we read (element tag -> attribute -> how many numbers), and where they sit.
_NUMBERS = {"origin": {"xyz": 3, "rpy": 3}, "axis": {"xyz": 3}, "mass": {"value": 1},
            "inertia": dict.fromkeys(("ixx", "ixy", "ixz", "iyy", "iyz", "izz"), 1),
            "limit": dict.fromkeys(("lower", "upper", "velocity", "effort"), 1),
            "mimic": dict.fromkeys(("multiplier", "offset"), 1)}
_NUMBER_TAGS = {"link": {"origin", "mass", "inertia"},  # in <inertial>
                "joint": {"origin", "axis", "limit", "mimic"}}
# yourdfpy would default a missing ixx to 1.0 where urdfdom (and so Pinocchio) refuses: refuse too.
_REQUIRED = {"mass": ("value",), "inertia": tuple(_NUMBERS["inertia"])}
_IDENTITY = np.eye(4)
_IDENTITY.flags.writeable = False  # shared by every missing <origin> and every body's own link


def load_urdf(path, base: str | None = None, tip: str | None = None,
              lock: dict[str, float] | None = None, floating: bool = False,
              mimic: str = "ordinary", accept_improper_inertia: bool = False,
              mimic_given: bool = False) -> Chain:
    """Read a URDF and return its robot: the chain of movable joints from link `base` (default: the root)
    to link `tip` when `tip` is given or the movable joints form one branch, else the whole tree (every
    movable joint below `base`, numbered depth-first, children in Pinocchio's order: vampc.robot.urdf_tree).
    `lock` maps joint names to values at which they are frozen (treated as fixed); on a chain a locked
    joint off the chain freezes everything below it too. Locking a fixed joint has no effect and warns
    (VampcWarning). `floating`, or a root joint of type floating, lets the base link float. `mimic`:
    "ordinary" reads a `<mimic>` joint as an ordinary joint (Pinocchio's default), "couple" couples it
    to its leader (vampc.robot.mimic; a follower of a locked leader is locked with it); either, when
    `mimic_given` (the user named it), warns that it has no effect on a file without mimic joints.
    `accept_improper_inertia` takes an inertia that is not positive semi-definite as written, with a
    warning naming the link, however far it misses (Pinocchio does not check)."""
    path = Path(path)
    if mimic not in MIMIC_MODES:
        raise VampcUsageError(f"mimic {mimic!r}: give one of {', '.join(MIMIC_MODES)}")
    with gc_paused():  # a big robot is millions of objects: the collector would walk them again and again
        robot = _read_robot(path)
        return chain_of(robot, Tree.build(robot, path), path, base, tip, lock, floating, mimic,
                        accept_improper_inertia, mimic_given=mimic_given)


def _gravity_at_base(tree: Tree, base: str, floating: bool, above_locks: dict, leaders: dict,
                     below: set, path: Path, given=None) -> tuple[Tree, str | None, dict]:
    """The tree with its gravity ([0, 0, -9.81] in the root link's frame, as Pinocchio reads a URDF)
    turned into the frame of the link `--base` names, through the joints above it: a base on a
    tilted mount had read the root's vector as its own (wrong torques, said by nothing). Joints
    above it, which --base cuts away, are at their --lock values (`above_locks`), a --mimic couple
    follower at its leader's multiple plus offset (`leaders`), others at 0; and the warning that
    says so (None when only fixed joints are above), and the joints' positions. A follower above
    the base whose leader is a moving joint below it (`below`) is refused: the base would move with
    it. A floating base keeps the world's orientation (its motion is the host's input), and so its
    gravity. The warning says a joint is placed by --lock where the user locked it (`given`: all of
    `above_locks` when None), not where it follows a locked leader (an audit's: a coupled follower
    was said placed by --lock)."""
    if floating or tree.gravity_in == base:        # (MJCF's: turned by MuJoCo's own kinematics)
        return tree, None, {}
    above = list(tree.ancestors(base))[::-1]          # root first
    if not above:
        return tree, None, {}
    at = dict(above_locks)
    causes = {}
    for j in above:
        causes[j.name] = "lock" if j.name in above_locks and (given is None or j.name in given) \
            else "leader" if j.name in leaders else "default"
        if j.name not in at and j.name in leaders:
            leader, mult, off = leaders[j.name]
            if leader in below:
                raise follows_from_below(path, j.name, base, leader)
            at[j.name] = mult * at.get(leader, 0.0) + off
    rotation, said = np.eye(3), []
    for j in above:
        q = at.get(j.name, 0.0)
        if q and not np.linalg.norm(np.asarray(j.axis, dtype=float)) > 0:
            raise located(path, f"joint '{j.name}'", "its axis is zero: no position of it turns "
                                                    "gravity (--lock gave it one)")
        rotation = matmul(rotation, (matmul(_origin(j), _motion(j, q)) if q else _origin(j))[:3, :3])
        if j.type == "floating" and j.child != base:     # (the base's own: choose_base says so)
            said.append(f"{j.name} (floating) at its <origin>")
        elif j.type == "planar":
            said.append(f"{j.name} (planar) at its <origin>")
        elif j.type in MOVABLE:
            limits = _position_range(j)
            outside = limits is not None and not limits[0] <= q <= limits[1]
            said.append(f"{j.name} at {q:.6g}" + (f", outside its limits [{limits[0]:.6g}, "
                                                   f"{limits[1]:.6g}]" if outside else ""))
    gravity = matvec(rotation.T, tree.gravity)
    turned = dataclasses.replace(tree, gravity=tuple(float(g) for g in gravity), gravity_in=base)
    if not said:
        return turned, None, at
    from vampc.robot.urdf_tree import placed_by
    moved = {j.name: causes[j.name] for j in above if j.type in MOVABLE}
    how = placed_by(moved, "a coupled mimic's leader", "0 by default", "by default") if moved \
        else "at their <origin>"
    return turned, cut_away(path, base, said, how), at


MIMIC_MODES = ("ordinary", "couple")


def chain_of(robot, tree: Tree, path: Path, base: str | None = None, tip: str | None = None,
             lock: dict[str, float] | None = None, floating: bool = False, mimic: str = "ordinary",
             accept_improper_inertia: bool = False, mimic_said: str | None = "<mimic>",
             mimic_given: bool = False, turn_said: str = "the turn of its <origin> (rpy)",
             turned: str | None = None) -> Chain:
    """The Chain of a robot read as links and joints (yourdfpy's shape; vampc.robot.mjcf builds one
    too): base, tip, lock, floating, mimic and accept_improper_inertia as `load_urdf` takes them.
    `mimic_said`: what a file's mimic joints are called, for the warning that --mimic couple finds
    none (None: no warning, the caller's --mimic couple has done something already); `mimic_given`:
    the user named --mimic (an explicit --mimic ordinary warns so too); `turn_said`: what turns a
    floating joint's frame in the file (an MJCF's body was told of an <origin>, a new user's);
    `turned`: the caller's warning that --base turned gravity (an MJCF's, by MuJoCo's kinematics),
    said once the robot is made, before what --base left out beside the way up."""
    accepted = [False] if accept_improper_inertia else None    # [an inertia was taken so]
    token = _ACCEPT_IMPROPER.set(accepted)
    try:
        chain = _chain_of(robot, tree, path, base, tip, lock, floating, mimic, mimic_said,
                          mimic_given, turn_said, turned)
    finally:
        _ACCEPT_IMPROPER.reset(token)
    if accepted == [False]:
        # (as --mimic and --floating-base say where they do nothing: an options audit's find)
        warnings.warn(VampcWarning(f"{path}: no inertia needed it; --accept-improper-inertia "
                                   "has no effect"), stacklevel=3)
    return chain


def _no_mimic(tree: Tree, said: str) -> str:
    """Why --mimic has nothing to do: no joint has a <mimic> (`said`), or only fixed joints do."""
    fixed = [j.name for j in tree.joints.values() if j.mimic is not None and j.type not in MOVABLE]
    if not fixed:
        return f"no joint has a {said}"
    named = quoted(fixed, 3)
    return (f"no joint that moves has a {said} (the fixed joint{'s' if len(fixed) > 1 else ''} "
            f"{named} {'have' if len(fixed) > 1 else 'has'} one, and a fixed joint does not move)")


def _warn_floating_origin(tree: Tree, base: str, floating: bool, path: Path,
                          turn_said: str = "the turn of its <origin> (rpy)") -> None:
    """A floating base's joint whose <origin> turns the base: the turn is not used (the base is at
    the world's orientation, its tilt the host's input), said (it was dropped in silence, and the
    torques differed from Pinocchio's at that joint's neutral pose: a new user's find)."""
    j = tree.parent.get(base)
    if not floating or j is None or j.type != "floating" or not turns(j):
        return
    # (an MJCF's free joint by its body: one left unnamed in the file was called by vampc's name
    # for it, 'joint0', which the file does not have: a new user's find)
    who = f"joint '{j.name}' (floating)" if tree.by_name else f"the free joint of body '{j.child}'"
    warnings.warn(VampcWarning(
        f"{path}: {who}: {turn_said} is not used: the "
        "floating base is taken at the world's orientation, gravity in its own frame, and a tilted "
        "base's gravity goes in the base columns (README, Trees and floating bases)"), stacklevel=4)


def _chain_of(robot, tree: Tree, path: Path, base: str | None, tip: str | None,
              lock: dict[str, float] | None, floating: bool, mimic: str,
              mimic_said: str | None = "<mimic>", mimic_given: bool = False,
              turn_said: str = "the turn of its <origin> (rpy)", turned_by: str | None = None) -> Chain:
    lock = _check_lock(lock or {}, tree, path)
    given = dict.fromkeys(lock)     # (the user's, in their order: a set's followed the hash seed, and
    # with two locks the program file did; _lock_followers adds coupled followers' own)
    # the joints the file names, in its order (not an MJCF weld's made-up one; the tree is turned below)
    every_joint = [name for name, j in tree.joints.items() if getattr(j, "named", True)]
    leaders, problems = _mimic_leaders(tree) if mimic == "couple" else ({}, {})
    if mimic_said and (mimic == "couple" and not leaders and not problems
                       or mimic == "ordinary" and mimic_given
                       and not any(j.mimic is not None and j.type in MOVABLE for j in tree.joints.values())):
        # (a file whose <mimic> tags are all on fixed joints was told it has none: a look-ahead
        # audit's find on talos_left_arm; and under --mimic ordinary, a new user's; an explicit
        # --mimic ordinary on a file without mimic joints was taken in silence)
        warnings.warn(VampcWarning(f"{path}: {_no_mimic(tree, mimic_said)}; --mimic {mimic} has no "
                                   "effect"), stacklevel=3)
    lock = _lock_followers(leaders, lock, tree, path)
    named, asked = base, floating
    base, floating = choose_base(tree, base, path, floating)
    check_joint_types(tree, base, path)
    _warn_floating_origin(tree, base, floating, path, turn_said)
    root_joint = tree.parent.get(base)
    if asked and root_joint is not None and root_joint.type == "floating" and \
            named in (None, root_joint.parent):
        # (it floats by the file's own joint: the option was taken unsaid, a new user's find)
        warnings.warn(VampcWarning(f"{path}: the base '{base}' floats on the file's own floating "
                                   f"joint '{root_joint.name}'; --floating-base has no effect"),
                      stacklevel=3)
    below = {j.name for j in tree.below(base)}
    lock, above_locks = _locks_below(lock, tree, base, below, path, floating, leaders, given)
    tip = choose_tip(tree, base, tip, lock, path)
    tree, turned, at = _gravity_at_base(tree, base, floating, above_locks, leaders, below, path,
                                        given)
    # (a follower above the base that the coupling placed off 0, where gravity is turned, is an effect)
    if leaders and not any(at.get(f, 0.0) != 0 for f in leaders) and \
            not any(f in below for f in leaders) and mimic_said:
        # (the file has <mimic> pairs, but --base cut every follower away: it said nothing)
        warnings.warn(VampcWarning(f"{path}: no joint below the base link '{base}' has a "
                                   f"{mimic_said}; --mimic couple has no effect"), stacklevel=3)
    if tip is None:
        chain = _load_tree(robot.name, tree, base, lock, floating, path)
    else:
        route = tree.route(base, tip)
        joints = [j for j in route if j.type in MOVABLE and j.name not in lock]
        _check_chain(joints, base, tip, path)
        frames, body_of = _bodies(tree, base, joints, {j.name for j in route}, lock, path, tip, leaders)
        chain = build_tree(robot.name, tree, joints, list(range(len(joints))), frames, body_of, True, path,
                           leaf_link=tip) if floating else \
            _build(robot.name, tree, joints, frames, body_of, tip, path)
    if mimic == "ordinary":
        _check_mimics(chain.joints, tree, path)
    for j in chain.joints:           # a bad <mimic> matters on the robot's joints only
        if j.name in problems:
            raise located(path, *problems[j.name])
    chain = _coupled(chain, leaders, path) if leaders else chain
    for said in (turned, turned_by):     # (said once the robot is made: an error comes alone)
        if said:
            warnings.warn(VampcWarning(said), stacklevel=3)
    # the joints whose positions are used: the robot's, those locked, those on the way up
    used = {j.name for j in chain.joints} | set(lock) | set(above_locks) | \
        {j.name for j in tree.ancestors(base)}
    _warn_inverted_limits([j for name, j in tree.joints.items() if name in used], path)
    if named is not None:
        beside = _left_beside(tree, base, below, floating, given, path)
        if beside:
            warnings.warn(VampcWarning(beside), stacklevel=3)
    # the locks that took a joint out (below the base) or placed one (above it), in the order given;
    # not one said to have no effect, so that its program is the one without it
    taken = tuple(name for name in given if name in lock or name in above_locks)
    held = {j.name for j in chain.joints}
    left_out = tuple(name for name in every_joint if name not in held and name not in taken)
    return dataclasses.replace(chain, locked=taken, left_out=left_out) if taken or left_out else chain


def _left_beside(tree: Tree, base: str, below: set, floating: bool, given, path: Path) -> str | None:
    """The warning that --base left out the moving joints beside the way up to it (a fixed base:
    the way up's own are said where gravity is turned) or, for a floating base, every link and
    moving joint above and beside it: what is not below it, a body floating apart named by its
    floating joint alone (an MJCF's free body is its reader's to say). Planar and floating joints
    move too (a door hinged to the world beside a floating trunk, a box on a planar joint, went
    unnamed: a review's). A joint the user locked is said where its lock is. A quadruped's --base FL_hip had left three legs out, and with
    --floating-base the trunk too, saying nothing (a founder's reread)."""
    ancestors = {j.name for j in tree.ancestors(base)}
    own = tree.parent.get(base)          # (a floating base's own floating joint is its motion)
    up = ancestors if not floating else {own.name} if own is not None and own.type == "floating" \
        else set()
    seen, stack, joints, links = {base}, [base], [], []
    while stack:                     # the links held to the base but across a floating joint apart
        link = stack.pop()
        ways = [j for j in tree.children[link] if j.name not in below]
        if link in tree.parent:
            ways.append(tree.parent[link])
        for j in ways:
            other = j.parent if j.child == link else j.child
            if other in seen:
                continue
            moves = j.type in MOVABLE or j.type in ("planar", "floating")
            if moves and j.name not in up and j.name not in (given or ()) and \
                    (j.type != "floating" or j.name in ancestors or tree.by_name):
                joints.append(j.name)         # (an MJCF's free body apart: its reader says it)
            if j.type == "floating" and j.name not in ancestors:
                continue                      # (a body floating apart: what it carries is its own)
            seen.add(other)
            stack.append(other)
            links.append(other)
    order = {name: k for k, name in enumerate(tree.joints)}      # (said in the file's order)
    joints.sort(key=order.__getitem__)
    order = {name: k for k, name in enumerate(tree.links)}
    heavy = sorted((name for name in links if tree.has_own_mass(name)), key=order.__getitem__) \
        if floating else []
    if not joints and not heavy:
        return None
    count = f"{len(joints)} moving joint{'s' * (len(joints) != 1)}"
    if not floating:
        return (f"{path}: --base {base}: the branches beside the way up to it are left out "
                f"({count}: {quoted(joints)}); the fixed base takes their forces, so no torque "
                "below it depends on them")
    parts = ([f"{quoted(heavy)} with mass"] if heavy else []) + \
        ([f"{count}: {quoted(joints)}"] if joints else [])
    links = "links" if tree.by_name else "bodies"
    return (f"{path}: --base {base} --floating-base: only '{base}' and what hangs below it float; "
            f"the {links} above and beside it are left out ({'; '.join(parts)}), so they do not "
            "load the floating base")


# --- mimic joints (vampc.robot.mimic) ----------------------------------------------------------------

def _mimic_leaders(tree: Tree) -> tuple[dict, dict]:
    """Follower name -> (leader name, multiplier, offset), chains of mimics composed down to a joint
    nobody mimics; and follower name -> (where, why) for a leader the file lacks or that cannot move,
    or a cycle (refused when the follower is one of the robot's joints)."""
    direct = {j.name: j.mimic for j in tree.joints.values()
              if j.mimic is not None and j.type in MOVABLE}
    out, problems = {}, {}
    for name in direct:
        seen, at, mult, off = [name], name, 1.0, 0.0
        while at in direct:
            m = direct[at]
            leader = m.joint
            if leader not in tree.joints:
                problems[name] = (f"joint '{at}'", f"mimics joint '{leader}', which the file does not have")
                break
            if tree.joints[leader].type not in MOVABLE:
                problems[name] = (f"joint '{at}'", f"mimics joint '{leader}', which is "
                                                   f"{tree.joints[leader].type}: it cannot lead")
                break
            if leader in seen:
                loop = " -> ".join(seen[seen.index(leader):] + [leader])
                problems[name] = (f"joint '{at}'", f"mimic cycle {loop}: no joint leads it")
                break
            # q_at = m q_leader + o, and q_name = mult q_at + off
            mult, off = mult * _or(m.multiplier, 1.0), off + mult * _or(m.offset, 0.0)
            seen.append(leader)
            at = leader
        if name not in problems:
            out[name] = (at, mult, off)
    return out, problems


def _or(value, default: float) -> float:
    return default if value is None else float(value)


def _lock_followers(leaders: dict, lock: dict, tree: Tree, path: Path) -> dict:
    """A follower of a locked leader is locked with it (at multiplier · value + offset); locking a
    follower of a joint that moves is refused (the coupling would break)."""
    out = dict(lock)
    for follower, (leader, mult, off) in leaders.items():
        if follower in lock and leader not in lock:
            raise located(path, f"lock {follower}", f"joint '{follower}' follows joint '{leader}' "
                                                    f"(--mimic couple): lock '{leader}' instead")
        if leader in lock:
            derived = mult * lock[leader] + off
            if follower in lock and not math.isclose(lock[follower], derived, rel_tol=1e-12, abs_tol=1e-12):
                raise located(path, f"lock {follower}", f"joint '{follower}' follows joint '{leader}' "
                              f"(--mimic couple): locking '{leader}' at {lock[leader]!r} locks it at "
                              f"{derived!r}, not {lock[follower]!r}")
            limits = _position_range(tree.joints[follower])
            slack = 1e-12 * max(1.0, abs(derived))        # (0.1 * 3 is 0.30000000000000004)
            if limits is not None and not limits[0] - slack <= derived <= limits[1] + slack:
                # said, not refused: a file's couplings and limits can disagree (PR2's gripper: a
                # follower at -1 times its leader, both limited to [0, 0.548]), and the torques
                # are the model's either way
                warnings.warn(VampcWarning(f"{path}: locking '{leader}' at {lock[leader]!r} locks its "
                                           f"follower '{follower}' (--mimic couple) at {derived!r}, "
                                           f"outside that joint's limits [{limits[0]!r}, "
                                           f"{limits[1]!r}]"), stacklevel=4)
            out[follower] = derived
    return out


def _coupled(chain: Chain, leaders: dict, path: Path) -> Chain:
    """The chain with its Mimic couplings; a leader must be one of its joints."""
    from dataclasses import replace

    from vampc.robot.chain import Mimic
    index = {j.name: k for k, j in enumerate(chain.joints, 1)}
    out = []
    for j in chain.joints:
        if j.name in leaders:
            leader, mult, off = leaders[j.name]
            if leader not in index:
                # (it is in the file: "not one of the robot's joints" read as a typo, a new user's)
                raise located(path, f"joint '{j.name}'", f"mimics joint '{leader}', which is not among "
                                                         "the joints compiled (the base or the tip leaves "
                                                         f"it out): choose a --base above it, or --lock "
                                                         f"{leader}=VALUE (its followers are then held too)")
            out.append(Mimic(index[j.name], index[leader], mult, off))
    return replace(chain, mimic=tuple(out))


def _load_tree(name: str, tree: Tree, base: str, lock: dict, floating: bool, path: Path) -> Chain:
    """The whole tree below `base`: every movable, unlocked joint, depth-first (children in Pinocchio's
    order); the links each carries through fixed and locked joints form its body."""
    below = tree.below(base, by_name=tree.by_name)
    joints = [j for j in below if j.type in MOVABLE and j.name not in lock]
    _check_chain(joints, base, "", path)
    index = {j.name: k for k, j in enumerate(joints, 1)}
    frames, body_of = {base: _IDENTITY}, {base: 0}
    for j in below:
        if j.name in index:
            frames[j.child], body_of[j.child] = _IDENTITY, index[j.name]
        else:
            frames[j.child] = matmul(frames[j.parent], _origin(j), _motion(j, lock.get(j.name, 0.0)))
            body_of[j.child] = body_of[j.parent]
    parents = [body_of[j.parent] for j in joints]
    return build_tree(name, tree, joints, parents, frames, body_of, floating, path)


# --- parsing -----------------------------------------------------------------------------------------

def _parse_xml(path: Path):
    """Parse without resolving entities or touching the network, and refuse any entity at all."""
    try:
        from vampc.textio import read_whole
        data = read_whole(path, text=True)
    except FileNotFoundError:
        raise located(path, "", "no such file") from None
    except OSError as exc:
        raise located(path, "", f"cannot read: {exc.strerror or exc}") from None
    _refuse_declared_entities(data, path)
    parser = etree.XMLParser(resolve_entities=False, no_network=True, load_dtd=False, huge_tree=False,
                             remove_comments=True, remove_pis=True)
    declared = []        # what XML refuses and urdfdom reads past, mended: said once the file is read
    while True:
        try:
            root = etree.fromstring(data, parser)
            break
        except etree.XMLSyntaxError as exc:
            mended = None if len(declared) >= MENDS else \
                _lenient_declaration(data, exc.msg) or _undeclared_prefix(data, exc.msg, exc.lineno)
            if mended is None:
                hint = f" (a xacro file: {run_xacro(path)})" if "prefix xacro " in exc.msg else ""
                raise located(path, f"line {exc.lineno}", f"not well-formed XML: {exc.msg}{hint}") from None
            data, said = mended
            declared.append(said)
    _refuse_entities(root, path)
    # (_check_numbers looks at them; only where some attribute holds a tab or line break: a
    # 16 000-joint file would pay for every element's look otherwise)
    token = _RAW_LINES.set(_without_comments(data).splitlines(keepends=True)
                           if _BROKEN_VALUE.search(data) else None)
    try:
        _check_xml(root, path)
    finally:
        _RAW_LINES.reset(token)
    encoding = (root.getroottree().docinfo.encoding or "").upper()
    # (by the first bytes too: without a declaration lxml says UTF-8 of a UTF-16 file it read)
    if data.startswith((codecs.BOM_UTF32_LE, codecs.BOM_UTF32_BE, b"<\x00\x00\x00", b"\x00\x00\x00<")):
        encoding = "UTF-32"
    elif data.startswith((codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE, b"<\x00", b"\x00<")):
        encoding = "UTF-16"
    for said in declared:                                     # (after the checks: an error alone)
        warnings.warn(VampcWarning(f"{path}: {said}"), stacklevel=3)
    if encoding.startswith(("UTF-16", "UTF-32", "UCS")):      # (after the checks: an error alone)
        warnings.warn(VampcWarning(f"{path}: {encoding} text, which urdfdom (Pinocchio's URDF "
                                   "reader) cannot read; read here, but save it as UTF-8 to use it "
                                   "there"), stacklevel=3)
    return root


_DECLARATION = re.compile(rb"<\?xml\s[^>]*\?>")
_DECLARED_ENCODING = re.compile(rb"encoding\s*=\s*[\"']([^\"']*)[\"']")


def _lenient_declaration(data: bytes, msg: str) -> tuple[bytes, str] | None:
    """The file's bytes with its XML declaration blanked (spaces, so every line keeps its number),
    where that declaration alone made it not well-formed: a version other than 1.x (Bullet's
    `<?xml version="0.0" ?>`) or blank lines before it; urdfdom's TinyXML, and so Pinocchio, reads
    such files (a trial of public URDF collections: nine of Bullet's refused); and the warning that
    says so. None where something else is wrong, or the declaration names an encoding other than UTF-8 (a
    file read as UTF-8 without it would be read wrong)."""
    if "Unsupported version" not in msg and "XML declaration allowed only at the start" not in msg:
        return None
    found = _DECLARATION.search(data, 0, 4096)
    if found is None or data[:found.start()].strip(b" \t\r\n\xef\xbb\xbf"):
        return None
    encoding = _DECLARED_ENCODING.search(found.group(0))
    if encoding and encoding.group(1).lower().replace(b"_", b"-") not in (b"utf-8", b"utf8", b"ascii",
                                                                           b"us-ascii"):
        return None
    line = data.count(b"\n", 0, found.start()) + 1
    what = ("its XML declaration comes after blank space" if found.start()
            and "allowed only at the start" in msg else
            f"its XML declaration names {one_line(found.group(0).decode('utf-8', 'replace'))}")
    return (data[:found.start()] + b" " * len(found.group(0)) + data[found.end():],
            f"line {line}: {what}, which XML refuses; read as XML 1.0 without it, as urdfdom "
            "(Pinocchio's reader) reads it")


MENDS = 16        # (at most so many mends of one file: the declaration and a prefix each)
_UNBOUND = re.compile(r"Namespace prefix ([A-Za-z_][\w.-]*) (?:for (\S+) )?on (\S+) is not defined")


def _undeclared_prefix(data: bytes, msg: str, line: int) -> tuple[bytes, str] | None:
    """The file's bytes with a namespace prefix it uses but does not declare declared on its
    <robot> element (the same line: every line keeps its number), and the warning that says so:
    an old Gazebo extension's `<sensor:camera>` inside <gazebo> (Fetch's URDF), which urdfdom
    reads past, made the file not well-formed XML here (a trial of public URDF collections). An
    element of another namespace is not read (as one declared). None for another error, for
    xacro's prefix (a xacro file: run xacro) and for a file not in an ASCII-based encoding."""
    found = _UNBOUND.search(msg)
    if found is None or found[1] == "xacro" or b"\x00" in data[:4]:
        return None
    root = re.search(rb"<robot\b", _without_comments(data))
    if root is None:
        return None
    prefix = found[1]
    where = f"<{prefix}:{found[3]}>" if found[2] is None else f"{prefix}:{found[2]}=... on <{found[3]}>"
    declare = f' xmlns:{prefix}="urn:vampc:undeclared:{prefix}"'.encode()
    return (data[:root.end()] + declare + data[root.end():],
            f"line {line}: {where}: namespace prefix '{prefix}' is not declared, which XML "
            f"refuses; read as another namespace's, which is not read, as urdfdom reads past it")


_ENTITY_DECL = re.compile(rb"<!ENTITY\s+(?:%\s+)?([^\s>]+)")
# The file's lines as bytes while its elements are checked: a tab or line break in a number
# attribute, which XML reads as a space, is seen in them (_check_numbers)
_RAW_LINES: ContextVar[list | None] = ContextVar("raw_lines", default=None)
_AFTER_A_NUMBER = re.compile(r"\S *[\t\r\n]")
_AFTER_A_NUMBER_BYTES = re.compile(_AFTER_A_NUMBER.pattern.encode())      # (the file's, as read)
_BROKEN_VALUE = re.compile(rb"=\s*(\"[^\"<]*[\t\r\n][^\"<]*\"|'[^'<]*[\t\r\n][^'<]*')")


# XML's markup, stepped over in order so that a comment is found only where one begins: not a "<!--"
# in CDATA or a "-->" in an attribute's value (a review's: taking those for a comment's ends had
# blanked the joint's own tag, a tab after a number there unsaid)
_MARKUP = re.compile(rb"<!--.*?-->|<!\[CDATA\[.*?\]\]>|<\?.*?\?>|<(?:[^>\"']|\"[^\"]*\"|'[^']*')*>",
                     re.S)


def _without_comments(data: bytes) -> bytes:
    """`data` with each comment's bytes but its line ends made spaces, the same length (a tag
    commented out after an element's own on its line had been taken for it: an audit's)."""
    return _MARKUP.sub(lambda m: re.sub(rb"[^\r\n]", b" ", m[0]) if m[0].startswith(b"<!--")
                       else m[0], data)


def _broken_list(el, tag: str, attr: str, raw: str) -> int | None:
    """Whether a number list attribute holds a tab or line break after one of its numbers as the
    file has it (urdfdom, Pinocchio's URDF reader, splits at spaces alone and reads each piece
    whole: "0\t0.1" is not a float there; XML reads it as a space): in the parsed value (a
    character reference, &#9;, stays a tab) or in the element's start tag in the file's bytes. The
    line its start tag begins on where it does, else None."""
    if _AFTER_A_NUMBER.search(raw):
        return el.sourceline or 0
    lines = _RAW_LINES.get()
    if not lines or not el.sourceline:
        return None
    # the element's start tag: the last to begin by the end of its line (libxml2 gives a tag
    # broken over lines the line where it ends), looked for from a few lines before
    first = max(0, el.sourceline - 20)
    text = b"".join(lines[first:el.sourceline + 40])      # (comments blanked: _without_comments)
    end = len(b"".join(lines[first:el.sourceline]))
    tags = [m for m in re.finditer(rb"<" + tag.encode() + rb"\b[^>]*?\s" + re.escape(attr.encode())
                                   + rb"\s*=\s*(\"[^\"]*\"|'[^']*')", text) if m.start() < end]
    if not tags or _AFTER_A_NUMBER_BYTES.search(tags[-1][1][1:-1]) is None:
        return None
    return first + 1 + len(re.findall(rb"\r\n|\r|\n", text[:tags[-1].start()]))   # (its line)


def _refuse_declared_entities(data: bytes, path: Path) -> None:
    """Refuse entity declarations before any parser sees them (a declaration in a comment is refused too:
    harmless, and URDF files have no use for entities)."""
    names = [m.decode("utf-8", "replace") for m in _ENTITY_DECL.findall(data)]
    if names:
        _entity_error(names, path)


def _entity_error(names: list, path: Path):
    raise located(path, "", f"DOCTYPE declares entities ({', '.join(names)}); "
                            "URDF files must not use XML entities")


def _refuse_entities(root, path: Path) -> None:
    dtd = root.getroottree().docinfo.internalDTD
    names = [e.name for e in dtd.iterentities()] if dtd is not None else []
    if names:  # only reached by encodings the byte scan cannot read, e.g. UTF-16
        _entity_error(names, path)
    for node in root.iter(etree.Entity):
        raise located(path, f"line {node.sourceline}", f"undefined XML entity {node.text}")


# Drake's URDF elements that exert forces between links, which urdfdom (and so Pinocchio) and vampc
# do not read: said, since the torques then leave their forces out
FORCES_NOT_READ = {"force_element": "Drake's spring or damper", "cable": "Drake's cable",
                   "loop_joint": "Drake's closed loop", "linear_bushing_rpy": "Drake's bushing",
                   "ball_constraint": "Drake's closed loop"}


def _check_xml(root, path: Path) -> None:
    """Check the structure and numbers we rely on, so yourdfpy never crashes on them."""
    if etree.QName(root).localname != "robot":
        raise located(path, f"line {root.sourceline}", "the root element must be <robot name=\"...\"> "
                                                       "(a URDF) or <mujoco> (an MJCF model)")
    _drop_default_namespace(root)
    _refuse_xacro(root, path)
    if not root.get("name"):           # xacro output often has none; Pinocchio loads it
        warnings.warn(VampcWarning(f"{path}: <robot> has no name; calling it {path.stem!r}"),
                      stacklevel=2)
        root.set("name", path.stem)
    unread: list[str] = []      # what urdfdom's reading (and so vampc's) leaves out: said below
    for inner in root.iterdescendants("robot"):     # (its links and joints vanished, unsaid)
        unread.append(f"a <robot> inside <robot> (line {inner.sourceline}) is not read, nor "
                      "anything in it")
        break
    for el in root.iterchildren():        # what exerts forces in Drake, read by neither urdfdom nor vampc
        what = FORCES_NOT_READ.get(etree.QName(el).localname) if isinstance(el.tag, str) else None
        if what:     # (Drake's tendons passed without a word, where an MJCF's are refused: a URDF trial's)
            unread.append(f"<{el.prefix + ':' if el.prefix else ''}{etree.QName(el).localname}> "
                          f"(line {el.sourceline}, {what}) is not read: its forces are not in the "
                          "torques")
    for kind in ("link", "joint"):
        seen = set()
        for el in root.iterchildren(kind):
            name = _named(el, kind, path)
            problem = name_problem(name)      # (before any message quotes it: a link's was printed)
            if problem:
                raise located(path, f"{kind} on line {el.sourceline}", problem)
            if name in seen:
                raise located(path, f"{kind} '{name}'", f"defined twice (again on line {el.sourceline})")
            seen.add(name)
            _check_children(el, kind, f"{kind} '{name}'", path, unread)
    if unread:
        more = f" (and {len(unread) - 1} more such)" if len(unread) > 1 else ""
        warnings.warn(VampcWarning(f"{path}: {unread[0]}{more}"), stacklevel=2)
    for el in root.iterchildren("joint"):
        for mimic in el.iterchildren("mimic"):
            if not mimic.get("joint"):
                raise located(path, f"joint '{el.get('name')}'", "<mimic> names no joint (joint=\"...\")")
        for tag in ("parent", "child"):
            if el.find(tag) is None or el.find(tag).get("link") is None:
                raise located(path, f"joint '{el.get('name')}'", f"missing <{tag} link=\"...\"/>")


def _drop_default_namespace(root) -> None:
    """A <robot xmlns="..."> (Drake's and some exporters' URDFs) read as urdfdom reads it, by the
    elements' own names: every element was in that namespace, and the file was said to have "no
    <link>" (a new user's find). Elements of a prefixed namespace (an extension's) keep theirs."""
    default = root.nsmap.get(None)
    if not default:
        return
    prefix = f"{{{default}}}"
    for el in root.iter():
        if isinstance(el.tag, str) and el.tag.startswith(prefix):
            el.tag = el.tag[len(prefix):]
    etree.cleanup_namespaces(root)


def _refuse_xacro(root, path: Path) -> None:
    """A xacro element (<xacro:macro>, <xacro:include>, a macro's call) left in the file: URDF
    readers skip elements they do not know, so a xacro file read as a URDF lost every joint its
    macros make without a word (3 joints read as 1: a new user's; Pinocchio reads 1 too). Only
    where the root declares a xacro namespace, which xacro's own output keeps, unused."""
    # by the prefix too: PR2-era files bind xacro: to another address (Gazebo's interface schema)
    found = [el for uri in {u for p, u in root.nsmap.items() if u and (p == "xacro" or "xacro" in u.lower())}
             for el in root.iter(f"{{{uri}}}*")]
    found.sort(key=lambda el: el.sourceline or 0)
    for el in found:
        if etree.QName(el).localname in XACRO_WORDS:
            raise located(path, f"line {el.sourceline}",
                          f"<xacro:{etree.QName(el).localname}>: a xacro element, which no URDF "
                          f"reader expands; {run_xacro(path)}")
    if found:
        # only calls of macros the file does not define: xacro's own output, with a call it left
        # (Valkyrie's <xacro:v1_pelvis_sensors_usb/>, robotis-OP2's <xacro:grey/>); "run xacro
        # first" could not help, and urdfdom reads past them (a trial of public URDF collections)
        names = [f"<xacro:{etree.QName(el).localname}> (line {el.sourceline})" for el in found]
        warnings.warn(VampcWarning(
            f"{path}: {listed(names, 3)}: a call of a xacro macro the file does not define, left "
            "in xacro's output; read past, as urdfdom reads it: what the macro would make is not "
            "in the robot"), stacklevel=4)
        for el in found:
            if el.getparent() is not None:
                el.getparent().remove(el)


# xacro's own elements, which a file xacro has expanded does not hold: a xacro file (a call of a
# macro the file does not define is xacro's output's leftover: _refuse_xacro)
XACRO_WORDS = {"macro", "property", "include", "arg", "if", "unless", "insert_block", "element",
               "attribute", "call", "eval-comments", "loop"}


def run_xacro(path: Path) -> str:
    """The advice to expand a xacro file, into a file of another name (`xacro robot.urdf >
    robot.urdf` would have emptied it before xacro read it: a review's find)."""
    name = Path(path).name
    if name.lower().endswith(".xacro"):          # arm.urdf.xacro > arm.urdf, arm.xacro > arm.urdf
        out = name[:-len(".xacro")]
        out += "" if out.lower().endswith(".urdf") else ".urdf"
    else:                                        # robot.urdf > robot-expanded.urdf
        out = f"{Path(name).stem}-expanded.urdf"
    return f"run xacro first (xacro {name} > {out}) and give the URDF"


# The elements a joint, a link's <inertial> and a link read, each once (urdfdom, and so Pinocchio
# and yourdfpy, take the first of two and skip an element they do not know: a second <inertial> of
# 50 kg, a second <mimic>, <origin xzy="..."> and <axes> were left out without a word, a new user's
# find). A link holds many other elements (<contact>, Gazebo's <gravity>...): only a misspelt
# <inertial>, or its <mass> or <inertia> outside one, is said there; a <limit> holds vendors'
# attributes (ANYmal's command_effort): only one close to a read one is said.
_ONCE = {"joint": {"parent", "child", "origin", "axis", "calibration", "dynamics", "limit", "mimic",
                   "safety_controller"},
         "inertial": {"origin", "mass", "inertia"}}
_ATTRIBUTES = {**{tag: set(numbers) for tag, numbers in _NUMBERS.items()},
               "mimic": {"joint", *_NUMBERS["mimic"]}}


def _check_children(el, kind: str, where: str, path: Path, unread: list[str]) -> None:
    """Check the numbers of a link's <inertial> or of a joint, and note in `unread` what the reading
    leaves out (_ONCE). One pass over the children: path searches (findall("inertial/origin") and
    the like) took a quarter of a 100 000-joint load."""
    if kind == "link":
        inertials = []
        for sub in el:
            tag = sub.tag
            if tag == "inertial":
                inertials.append(sub)
            elif tag in ("joint", "link"):
                # (urdfdom skips it: a joint so placed was left out, its child link then a second
                # root, "choose one with --base", which loses part of the arm: a new user's find)
                name = f" name=\"{sub.get('name')}\"" if sub.get("name") else ""
                raise located(path, where, f"<{tag}{name}> (line {sub.sourceline}) is inside the "
                              f"link, where no URDF reader reads it: a <{tag}> goes directly in "
                              "<robot> (a misplaced </link>?)")
            elif tag == "origin":
                unread.append(f"{where}: <origin> (line {sub.sourceline}) is not read: a link's "
                              "origins are those of its <inertial>, <visual> and <collision>")
            elif isinstance(tag, str):
                near = _close(tag, ("inertial",), 0.8)
                if tag in ("mass", "inertia") or near:
                    unread.append(f"{where}: <{tag}> (line {sub.sourceline}) is not read"
                                  f"{' (did you mean <inertial>?)' if near else ''}: a link's mass "
                                  "and inertia are read inside its <inertial>")
        if len(inertials) > 1:
            unread.append(f"{where}: a second <inertial> (line {inertials[1].sourceline}) is not read "
                          "(the first is, as by urdfdom, Pinocchio's reader)")
        groups = [("inertial", inertial, f"{where} <inertial>") for inertial in inertials]
    else:
        groups = [("joint", el, where)]
    tags = _NUMBER_TAGS[kind]
    for group, parent, here in groups:
        once, met = _ONCE[group], set()
        for sub in parent:
            tag = sub.tag
            if tag in tags:
                _check_numbers(sub, tag, where, path)
            if tag == "axis" and "axis" not in met and sub.get("xyz") is None and \
                    parent.get("type") in MOVABLE:
                # read as urdfdom (and so Pinocchio) reads it, 0 0 0, which the joint checks then
                # refuse where the joint is used: it had been 1 0 0, URDF's default without an
                # <axis>, unsaid (a new user's <axis>0 1 0</axis>: torque 0 in Pinocchio)
                sub.set("xyz", "0 0 0")
            if tag in ("parent", "child") and len(sub):
                inner = next((x for x in sub if isinstance(x.tag, str)), None)
                if inner is not None:       # (<child link="b"><origin .../></child>: unsaid)
                    unread.append(f"{here}: <{inner.tag}> inside <{tag}> (line {inner.sourceline}) "
                                  "is not read" + (": a joint's <origin> goes directly in the "
                                                   "<joint>" if inner.tag == "origin" else ""))
            if tag in once:
                if tag in met:
                    unread.append(f"{here}: a second <{tag}> (line {sub.sourceline}) is not read (the "
                                  "first is, as by urdfdom, Pinocchio's reader)")
                    continue
                met.add(tag)
                known = _ATTRIBUTES.get(tag)
                if known is not None and not known.issuperset(sub.keys()):
                    for attribute in sub.keys():
                        if attribute not in known and "}" not in attribute and \
                                (tag != "limit" or _close(attribute, known, 0.8)):
                            unread.append(f"{here}: <{tag} {attribute}=...> (line {sub.sourceline}) is "
                                          f"not a URDF attribute{_close(attribute, known)}; it is not read")
            elif isinstance(tag, str) and "}" not in tag:    # (not a comment, nor an extension's)
                unread.append(f"{here}: <{tag}> (line {sub.sourceline}) is not a URDF element "
                              f"there{_close(f'<{tag}>', [f'<{t}>' for t in once])}; it is not read")


def _close(word: str, choices, cutoff: float = 0.6) -> str:
    """' (did you mean xyz?)', unquoted as an element or attribute is written (textio.did_you_mean),
    where `word` is close to one of `choices`, else ''."""
    return did_you_mean(word, sorted(choices), cutoff, quote=False)


def _named(el, kind: str, path: Path) -> str:
    name = el.get("name")
    if not name:
        raise located(path, f"line {el.sourceline}", f"<{kind}> has no name")
    if kind == "joint" and el.get("type") is None:
        raise located(path, f"joint '{name}'", "has no type")
    return name


def _check_numbers(el, tag: str, where: str, path: Path) -> None:
    """Required attributes present; each numeric one (in file order) the right count of finite numbers."""
    missing = [a for a in _REQUIRED.get(tag, ()) if el.get(a) is None]
    if missing:
        raise located(path, where, f"<{tag}> lacks {', '.join(missing)}")
    counts = _NUMBERS[tag]
    for attr, raw in el.items():
        count = counts.get(attr)
        if count is None:
            continue
        # numbers as typed (textio.plain_number: float() also took '1_0' as 10 and other scripts'
        # digits, '３' as 3, which Pinocchio reads as 0), split at spaces
        try:
            values = tuple(map(float, raw.split())) if plain_number(raw) else ()
        except ValueError:
            values = ()
        if len(values) != count or not all(map(math.isfinite, values)):
            if "${" in raw or "$(" in raw:    # (a xacro property or argument: "expected a finite
                # number" alone, where a <xacro:macro> is told to run xacro: a new user's find)
                raise located(path, where, f"<{tag} {attr}=\"{raw}\">: a xacro expression, which no "
                              f"URDF reader expands; {run_xacro(path)}")
            noun = "a finite number" if count == 1 else f"{count} finite numbers"
            raise located(path, where, f"<{tag} {attr}=\"{raw}\">: expected {noun}")
        line = _broken_list(el, tag, attr, raw) if count > 1 and (
            _RAW_LINES.get() is not None or "\t" in raw or "\n" in raw or "\r" in raw) else None
        if line is not None:
            # (read here unsaid, where Pinocchio refuses the file, or an <inertial>'s: a new user's)
            warnings.warn(VampcWarning(
                f"{path}: {where}: <{tag} {attr}=...> (line {line}): a tab or line break "
                "after a number, which urdfdom (Pinocchio's URDF reader) does not read: it refuses "
                "the file, or in an <inertial> leaves the link's mass out; read here as a space"),
                stacklevel=2)
        if count == 1 and raw[-1:].isspace():
            # urdfdom reads one number to the end of the text: a space after it is "not a float"
            # there, and Pinocchio drops that <inertial> (a mass of '2.0 ' gave torques of 2 kg
            # here, 0 there, unsaid: an audit's)
            # (said "refuses": urdfdom logs an error and Pinocchio loads the file, a bad mass
            # dropping the whole <inertial>, a bad inertia entry the rotational inertia alone, mass
            # and centre kept: the Unitree dex2_5 hands' line break after an ixz, a URDF trial's)
            then = {"mass": "Pinocchio drops the link's <inertial>",
                    "inertia": "Pinocchio zeroes the link's rotational inertia, keeping its mass "
                               "and centre of mass"}.get(tag, "Pinocchio does not take it as written")
            warnings.warn(VampcWarning(f"{path}: {where}: <{tag} {attr}=\"{raw}\">: a space or line "
                                       f"break after the number, which urdfdom (Pinocchio's URDF "
                                       f"reader) does not read as a number ({then}); read here as "
                                       f"{values[0]:g}"), stacklevel=2)


def _read_robot(path: Path):
    """yourdfpy's `Robot` of the checked file: links and joints in file order."""
    import yourdfpy  # costs about a second, so only when a URDF is really loaded

    # The root element only: the (already vetted) DOCTYPE stays behind. Our tree is freed before yourdfpy
    # parses its own (kept, it raised the peak memory of a 100 000-joint load from 1.2 to 2.0 GB).
    root = _parse_xml(path)
    # a link's <visual> and <collision> are not read (the dynamics needs neither): yourdfpy knows
    # boxes, cylinders, spheres and meshes only and refused a file with a <capsule> (Bullet's
    # humanoid), which urdfdom and Pinocchio read (a trial of public URDF collections)
    for link in root.iterchildren("link"):
        for child in [c for c in link if c.tag in ("visual", "collision")]:
            link.remove(child)
    data = etree.tostring(root)
    try:
        urdf = yourdfpy.URDF.load(io.BytesIO(data), build_scene_graph=False, load_meshes=False,
                                  build_collision_scene_graph=False, load_collision_meshes=False)
    except Exception as exc:  # noqa: BLE001 - on bad input yourdfpy raises anything (KeyError, AttributeError...)
        raise located(path, "", f"yourdfpy cannot read it ({type(exc).__name__}: {one_line(str(exc))})") from None
    return urdf.robot


# --- lock and chain ----------------------------------------------------------------------------------

def _check_lock(lock: dict, tree: Tree, path: Path) -> dict:
    """The --lock values as floats, every name a joint of the file. A fixed joint is dropped with a warning:
    it has no position to lock (kept, it would also freeze everything below it when off the chain)."""
    out = {}
    for name, value in lock.items():
        if name not in tree.joints:
            raise located(path, f"lock {name}", f"no joint named '{name}'"
                          + did_you_mean(name, tree.joints))
        try:
            number = float(value)
        except (TypeError, ValueError):
            number = math.nan
        if not math.isfinite(number):
            raise located(path, f"lock {name}", f"value {value!r} is not a finite number")
        joint = tree.joints[name]
        if joint.type == "planar":        # (its one position was taken and ignored, saying nothing)
            raise located(path, f"lock {name}", "a planar joint moves in three degrees of freedom; "
                          "--lock gives one position (above --base it is held at its <origin>)")
        if joint.type == "fixed":
            warnings.warn(VampcWarning(f"{path}: joint '{name}' is fixed; --lock {name}=... has no effect"),
                          stacklevel=2)
            continue
        lim = _position_range(joint)
        if lim is not None and not lim[0] <= number <= lim[1]:
            unit = (" (radians, as every --lock value of a revolute joint, whatever unit the "
                    "file writes its angles in)" if joint.type in ("revolute", "continuous") else
                    " (metres)")     # (an MJCF in degrees: --lock a1=30 went unexplained)
            raise located(path, f"lock {name}", f"{value} is outside the joint's limits "
                          f"[{lim[0]!r}, {lim[1]!r}]{unit}")
        out[name] = number
    return out


def _locks_below(lock: dict, tree: Tree, base: str, below: set, path: Path, floating: bool = False,
                 leaders: dict | None = None, given=None) -> tuple[dict, dict]:
    """(the locks of joints below the base (`below`: their names), those of joints above it): a
    joint above it, cut away by the base, is at its --lock value where gravity is turned into the
    base's frame (`_gravity_at_base`, which says so). A floating joint's lock is dropped with a
    warning, as a fixed joint's is: it was taken and ignored, saying nothing (a new user's find)."""
    above = {}
    up = {j.name for j in tree.ancestors(base)}
    # a lock counts above the base where it places a joint on the way up to it, or the leader of a
    # --mimic couple follower there; one anywhere else (a leg when --base is the torso) was taken
    # and ignored, saying nothing (a new user's find); so is any above a floating base, whose
    # motion is the host's
    placing = up | {leaders[f][0] for f in up | below if f in (leaders or {})}   # (a leader cut away
    # whose follower the robot keeps is locked so that the follower is: said to have no effect
    # though the error without it asks for it; review)
    for name in [n for n in lock if n not in below]:
        if tree.joints[name].type == "floating":
            warnings.warn(VampcWarning(f"{path}: joint '{name}' is the floating base's own joint (its "
                                       f"motion is the host's input); --lock {name}=... has no "
                                       "effect"), stacklevel=4)
        elif given is not None and name not in given and (floating or name not in placing):
            pass            # (a coupled follower's lock, derived from its leader's: not the user's)
        elif floating and name in up:
            warnings.warn(VampcWarning(f"{path}: joint '{name}' is above the floating base '{base}' "
                                       f"(whose motion is the host's input); --lock {name}=... has "
                                       "no effect"), stacklevel=4)
        elif name not in placing:
            warnings.warn(VampcWarning(f"{path}: joint '{name}' is neither below the base link "
                                       f"'{base}' nor on the way up to it (--base cuts its branch "
                                       f"away); --lock {name}=... has no effect"), stacklevel=4)
        else:
            above[name] = lock[name]
        del lock[name]
    return lock, above


def _check_chain(chain: list, base: str, tip: str, path: Path) -> None:
    """Refuse an empty chain and one longer than MAX_JOINTS."""
    if not chain and not tip:
        raise located(path, "", f"no movable joints below base link '{base}'")
    if not chain:
        raise located(path, "", f"no movable joints between base link '{base}' and tip link '{tip}'")
    problem = joint_count_problem(len(chain))
    if problem:
        raise located(path, "", problem)


def _check_mimics(joints, tree: Tree, path: Path) -> None:
    """--mimic ordinary: a mimic joint is taken as an ordinary joint, as Pinocchio's default reads it:
    its own q, q̇, q̈ from the host and its own torque in the output. One warning says so, naming the
    first few; a leader the file lacks is only a warning here (the tag is not used)."""
    names = {j.name for j in joints}
    mimics = [tree.joints[n] for n in tree.joints if n in names and tree.joints[n].mimic is not None]
    if not mimics:
        return
    lost = [j for j in mimics if j.mimic.joint not in tree.joints]
    if lost:
        warnings.warn(VampcWarning(f"{path}: joint '{lost[0].name}' mimics joint '{lost[0].mimic.joint}', "
                                   "which the file does not have" + (f" (and {len(lost) - 1} more)"
                                   if len(lost) > 1 else "") + "; --mimic couple would refuse it"),
                      stacklevel=3)
    # (those whose leader is lost are said above alone: they were said again here, "--mimic couple
    # couples them", beside "--mimic couple would refuse it", a new user's find)
    mimics = [j for j in mimics if j not in lost]
    if not mimics:
        return
    first = mimics[0]
    more = f" (and {len(mimics) - 1} more mimic joint{'s' if len(mimics) > 2 else ''})" \
        if len(mimics) > 1 else ""
    warnings.warn(VampcWarning(f"{path}: joint '{first.name}' mimics joint '{first.mimic.joint}'{more}: "
                               "taken as ordinary joints (own q, q̇, q̈ and torque), as Pinocchio reads "
                               "them by default; --mimic couple couples them"), stacklevel=3)


# --- rigid bodies ------------------------------------------------------------------------------------

def _bodies(tree: Tree, base: str, chain: list, route: set, lock: dict, path: Path,
            tip: str | None = None, leaders: dict | None = None):
    """Assign every link below `base` to a body 0..n (the chain link it is rigidly attached to) and give its
    pose in that body's reference frame (body 0: the base link; body k: the child link of chain joint k).

    Off-chain joints must be fixed, locked or below a locked off-chain joint (frozen at their lock value
    or 0); any other movable joint branches off the chain and is refused (`leaders`: --mimic couple's
    followers, which are locked by their leader's --lock, not their own)."""
    index = {j.name: k for k, j in enumerate(chain, 1)}
    frames, body_of, stray, at_zero, beyond = {base: _IDENTITY}, {base: 0}, [], [], set()
    stack = [(base, False, base == tip)]
    while stack:
        link, frozen, past_tip = stack.pop()
        for j in tree.children[link]:
            if j.name in index:
                frames[j.child], body_of[j.child] = _IDENTITY, index[j.name]
                stack.append((j.child, False, j.child == tip))
            elif j.type in MOVABLE and j.name not in lock and not frozen:
                stray.append(j.name)
                if past_tip:
                    beyond.add(j.name)
            else:
                if j.type in MOVABLE and j.name not in lock:
                    at_zero.append(j.name)   # below a locked branch: frozen in the file's pose, unasked
                # (the file's pose: q = 0 for a URDF joint, MuJoCo's reference position qpos0 for an
                # MJCF one, where --base holds the joints it cuts away; it had been qpos = 0)
                frames[j.child] = matmul(frames[link], _origin(j), _motion(j, lock.get(j.name, -_offset(j))))
                body_of[j.child] = body_of[link]
                # (a tip hung on a fixed joint: what moves below it was said to branch off, a new
                # user's --tip shoulder_flange)
                stack.append((j.child, frozen or (j.name in lock and j.name not in route),
                              past_tip or j.child == tip))
    if stray or at_zero:                 # named in file order
        order = {name: i for i, name in enumerate(tree.joints)}.__getitem__
    if stray:
        stray.sort(key=order)
        # (the others said as what they are, below the tip or branching off: a new user's talos
        # --tip arm_left_7_link listed its gripper joint among the joints branching off)
        alike = [j for j in stray[1:] if (j in beyond) == (stray[0] in beyond)]
        other = [j for j in stray[1:] if (j in beyond) != (stray[0] in beyond)]
        parts = ([f"also {quoted(alike)}"] if alike else []) + (
            [("and below the tip: " if stray[0] not in beyond else "and branching off the chain: ")
             + quoted(other)] if other else [])
        more = f" ({'; '.join(parts)})" if parts else ""
        # (a coupled follower is locked by its leader: "lock it with --lock FOLLOWER=VALUE" was
        # then refused, "lock 'LEADER' instead"; an audit's find)
        leader = (leaders or {}).get(stray[0], (None,))[0]
        lock_it = (f"lock it with --lock {stray[0]}=VALUE" if leader is None else
                   f"lock its leader with --lock {leader}=VALUE (it follows joint '{leader}', "
                   "--mimic couple)")
        if stray[0] in beyond:
            raise located(path, "", f"joint '{stray[0]}' moves below the tip link '{tip}'; choose a tip "
                                    f"further out or {lock_it}{more}")
        # (it said "or choose --tip" to a user who had: a tip is given whenever joints stray here,
        # for without one a robot of several branches is taken whole, as a tree)
        raise located(path, "", f"joint '{stray[0]}' branches off the chain from base link '{base}' to "
                                f"tip link '{tip}'; {lock_it}{more}, or "
                                "leave out --tip to take the whole robot (a tree)")
    if at_zero:              # their positions move the locked branch's mass: never assumed silently
        at_zero.sort(key=order)
        more = f" (and {quoted(at_zero[1:])})" if len(at_zero) > 1 else ""
        first = tree.joints[at_zero[0]]
        where = "0" if not _offset(first) else f"{-_offset(first):.6g} (its reference position, qpos0)"
        warnings.warn(VampcWarning(f"{path}: joint '{at_zero[0]}'{more}, below a locked joint, is frozen "
                                   f"at {where}; give --lock {at_zero[0]}=VALUE for another position"),
                      stacklevel=3)
    return frames, body_of


def _build(name: str, tree: Tree, chain: list, frames: dict, body_of: dict, tip: str, path: Path) -> Chain:
    """The Chain, every joint's Φ_k, p*_k and body computed for all joints at once (numpy stacks)."""
    r_a = _z_to(_unit(np.array([j.axis for j in chain])))  # R_{a_k}: e_z onto joint k's axis
    g = _reference_poses(chain, frames, r_a, tip)
    phi = matmul(_transposed(r_a), g[1:, :3, :3])
    p_fixed = matmul(_transposed(phi), _transposed(r_a), g[1:, :3, 3:])[..., 0]
    mass, com, inertia = _body_inertias(tree, _members(body_of), g, frames, path)
    _warn_no_limit(tree, chain, path)
    joints = tuple(Joint(name=j.name, type=MOVABLE[j.type], phi=phi[k], p_fixed=p_fixed[k], offset=_offset(j),
                         mass=float(mass[k]), com=com[k], inertia=inertia[k], limits=_limits(j, path))
                   for k, j in enumerate(chain))
    return Chain(name=name, joints=joints, gravity=matvec(g[0, :3, :3].T, tree.gravity), source=str(path))


def build_tree(name: str, tree: Tree, joints: list, parents: list, frames: dict, body_of: dict,
               floating: bool, path: Path, leaf_link: str | None = None) -> Chain:
    """A Chain with parents (vampc.robot.chain) from movable joints in depth-first order: body p's frame
    O_p is the joint frame of its heavy child (the most joints below it; the first on a tie), a leaf
    body's frame its own link's (or `leaf_link`'s, the tip of a chain); O_0 is the base link's frame
    for a floating base. Other children carry their joint frame in O_p (pre, shift)."""
    n = len(joints)
    r_a = _z_to(_unit(np.array([j.axis for j in joints])))
    x = _placed(frames, [(j.parent, _origin(j)) for j in joints])      # J_k in its parent body's frame
    x[:, :3, :3] = matmul(x[:, :3, :3], r_a)
    heavy = _heavy_children(parents)
    g = np.array([np.eye(4)] * (n + 1))
    for p in range(n + 1):
        if p in heavy and not (p == 0 and floating):
            g[p] = x[heavy[p] - 1]
        elif p and leaf_link is not None and p == n:
            g[p] = frames[leaf_link]
    phi = matmul(_transposed(r_a), g[1:, :3, :3])
    p_fixed = matmul(_transposed(phi), _transposed(r_a), g[1:, :3, 3:])[..., 0]
    mass, com, inertia = _body_inertias(tree, _members(body_of), g, frames, path)
    _warn_no_limit(tree, joints, path)
    built = []
    for k, j in enumerate(joints):
        frame = {} if heavy.get(parents[k]) == k + 1 and not (parents[k] == 0 and floating) else \
            _joint_frame(g[parents[k]], x[k])
        built.append(Joint(name=j.name, type=MOVABLE[j.type], phi=phi[k], p_fixed=p_fixed[k], offset=_offset(j),
                           mass=float(mass[k]), com=com[k], inertia=inertia[k], limits=_limits(j, path),
                           **frame))
    extra = _base_body(tree, body_of, g[0], frames, path) if floating else {}
    return Chain(name=name, joints=tuple(built), gravity=matvec(g[0, :3, :3].T, tree.gravity),
                 source=str(path),
                 parents=tuple(parents), **extra)


def _heavy_children(parents: list) -> dict:
    """Body -> its child joint with the most joints below it (the first on a tie), 1-based."""
    size = [1] * (len(parents) + 1)
    for k in range(len(parents), 0, -1):
        size[parents[k - 1]] += size[k]
    heavy: dict = {}
    for k, p in enumerate(parents, 1):
        if p not in heavy or size[k] > size[heavy[p]]:
            heavy[p] = k
    return heavy


def _joint_frame(g_parent: np.ndarray, x: np.ndarray) -> dict:
    """pre = J's orientation in O_p (None when it is the identity, as a DH frame's), shift = J's
    origin from O_p's origin in O_p (None when zero). An identity pre kept had cost the joint's
    torque a dot product with its axis (a VD and a constant) where a DH frame's takes n's third
    component: a URDF tree needed a VAMP and up to 3 flops more than the same tree as a DH table (a
    new user's find)."""
    rot = g_parent[:3, :3].T
    shift = matvec(rot, x[:3, 3] - g_parent[:3, 3])
    pre = matmul(rot, x[:3, :3])
    return {"pre": None if np.array_equal(pre, np.eye(3)) else pre,
            "shift": shift if np.any(shift) else None}


def _base_body(tree: Tree, body_of: dict, g0: np.ndarray, frames: dict, path: Path) -> dict:
    """A floating base link's mass, centre of mass and inertia in O_0 (links fixed to it included)."""
    links = [name for name, body in body_of.items() if body == 0 and tree.links[name].inertial is not None]
    if not links:
        return {"floating": True}
    for name in links:
        _check_mass(tree.links[name].inertial, name, path)
    parts = [tree.links[name].inertial for name in links]
    _check_inertias(np.array([p.inertia for p in parts]), links, path)
    pose = matmul(_rigid_inverse(g0[None])[0],
                  _placed(frames, [(name, _origin(p)) for name, p in zip(links, parts)]))
    rot = pose[:, :3, :3]
    mass, com, inertia = _sum_bodies(np.zeros(len(parts), dtype=int), 1, np.array([p.mass for p in parts]),
                                     pose[:, :3, 3],
                                     matmul(rot, np.array([p.inertia for p in parts]), _transposed(rot)))
    return {"floating": True, "base_mass": float(mass[0]), "base_com": com[0], "base_inertia": inertia[0]}


def _reference_poses(chain: list, frames: dict, r_a: np.ndarray, tip: str) -> np.ndarray:
    """G_0..G_n as an (n + 1, 4, 4) stack: G_{k-1} = X T_k R_{a_k}, X the pose of joint k's parent link in
    its body; G_n the pose of the tip link in body n."""
    g = np.concatenate([_placed(frames, [(j.parent, _origin(j)) for j in chain]), [frames[tip]]])
    g[:-1, :3, :3] = matmul(g[:-1, :3, :3], r_a)
    return g


def _members(body_of: dict) -> dict:
    """Body number -> its links, in the order `_bodies` reached them (one pass over all links: picking each
    body's links out of all of them would be O(n²))."""
    out = {}
    for name, body in body_of.items():
        out.setdefault(body, []).append(name)
    return out


def _body_inertias(tree: Tree, members: dict, g: np.ndarray, frames: dict, path: Path):
    """Mass (n,), centre of mass (n, 3) and inertia about it (n, 3, 3), in O_k, of every body k = 1..n."""
    n = len(g) - 1
    body, names, parts = _inertial_parts(tree, members, n, path)
    if not parts:                                      # every body massless
        return np.zeros(n), np.zeros((n, 3)), np.zeros((n, 3, 3))
    inertia = np.array([p.inertia for p in parts])
    _check_inertias(inertia, names, path)
    in_link = _placed(frames, [(name, _origin(p)) for name, p in zip(names, parts)])
    pose = matmul(_rigid_inverse(g[1:])[body], in_link)  # each inertial's frame in O_k
    rot = pose[:, :3, :3]
    return _sum_bodies(body, n, np.array([p.mass for p in parts]), pose[:, :3, 3],
                       matmul(rot, inertia, _transposed(rot)))


def _inertial_parts(tree: Tree, members: dict, n: int, path: Path):
    """Every link of bodies 1..n that has an <inertial>: its body (0-based, as an array), names, inertials."""
    body, names, parts = [], [], []
    for k in range(1, n + 1):       # a body without any <inertial> is massless (zero inertia)
        for name in members[k]:
            inertial = tree.links[name].inertial
            if inertial is not None:
                _check_mass(inertial, name, path)
                body.append(k - 1)
                names.append(name)
                parts.append(inertial)
    # massless bodies are Pinocchio's reading too; all of them is a bad sign, however the file says
    # it (mass 0 and inertia 0 given had gone unsaid: an audit's)
    if not parts or all(not p.mass and not np.any(p.inertia) for p in parts):
        how = ("no link moved by a joint has an <inertial>" if not parts else
               "every link moved by a joint has mass 0 and inertia 0")
        warnings.warn(VampcWarning(f"{path}: {how}: every body is massless, so every torque is zero "
                                   "but for the tip's load"), stacklevel=2)
    return np.array(body, dtype=int), names, parts


def _check_mass(inertial, link: str, path: Path) -> None:
    if inertial.mass is None or inertial.inertia is None:
        missing = "<mass>" if inertial.mass is None else "<inertia>"
        raise located(path, f"link '{link}'", f"<inertial> has no {missing}")
    if inertial.mass < 0:
        raise located(path, f"link '{link}'", f"negative mass {inertial.mass}")


# One that misses by at most this much of the robot's largest inertia entry is taken without a word:
# iCub's files write ixz="2.40741e-35" beside a zero diagonal, six links of it, each warned of on
# every command (a new user's find); a millionth of a millionth of any link's inertia moves no torque.
NEGLIGIBLE_PSD = 1e-12
# --accept-improper-inertia, for the load under way (a context variable: the checks sit deep in the
# body computations, and a load in one thread must not change another's): None without it, else
# [whether an inertia was taken as written].
_ACCEPT_IMPROPER: ContextVar[list | None] = ContextVar("accept_improper_inertia", default=None)


def _check_inertias(inertia: np.ndarray, names: list, path: Path) -> None:
    """Refuse the first inertia that is not symmetric positive semi-definite (checked as one stack);
    one that misses by a rounding error (NEARLY_PSD) is taken, with a warning naming the link.
    One that is not a finite number (a mass of 1e308 times a size squared) is refused first: the
    eigenvalues of an infinite matrix do not converge."""
    with np.errstate(invalid="ignore"):
        infinite = np.flatnonzero(~np.isfinite(inertia.reshape(len(inertia), -1)).all(axis=1))
    if infinite.size:
        raise located(path, f"link '{names[infinite[0]]}'", "its inertia is not a finite number "
                      "(numbers too large for a float once combined)")
    improper = np.flatnonzero(improper_inertias(inertia))
    negligible = NEGLIGIBLE_PSD * float(np.abs(inertia).max(initial=0.0))
    for i in improper:
        problem = inertia_problem(inertia[i])
        if not problem or inertia_problem(inertia[i], floor=negligible) is None:
            continue
        if inertia_problem(inertia[i], tolerance=NEARLY_PSD, floor=NEARLY_PSD_ABS) is None:
            warnings.warn(VampcWarning(f"{path}: link '{names[i]}': {problem}, by less than "
                                       f"{NEARLY_PSD:g} of its largest entry or {NEARLY_PSD_ABS:g} "
                                       "kg m²: taken as a rounding error"), stacklevel=2)
            continue
        accepted = _ACCEPT_IMPROPER.get()
        if accepted is not None:
            accepted[0] = True
            warnings.warn(VampcWarning(f"{path}: link '{names[i]}': {problem}: taken as written "
                                       "(--accept-improper-inertia); no rigid body has it"), stacklevel=2)
            continue
        raise located(path, f"link '{names[i]}'", f"{problem}; --accept-improper-inertia takes it as "
                                                  "written, as Pinocchio does")


def _sum_bodies(body: np.ndarray, n: int, mass: np.ndarray, com: np.ndarray, inertia: np.ndarray):
    """Sum rigidly joined parts (mass, com, inertia about com; `body` says whose) into n bodies, each
    about its joint centre of mass (parallel axes)."""
    total = np.bincount(body, weights=mass, minlength=n)
    first = np.zeros((n, 3))
    np.add.at(first, body, mass[:, None] * com)
    centre = np.divide(first, total[:, None], out=np.zeros((n, 3)), where=total[:, None] > 0)
    d = com - centre[body]
    square = d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1] + d[:, 2] * d[:, 2]   # (in turn, as chain.matmul)
    shift = square[:, None, None] * np.eye(3) - d[:, :, None] * d[:, None, :]
    out = np.zeros((n, 3, 3))
    np.add.at(out, body, inertia + mass[:, None, None] * shift)
    return total, centre, out


def _warn_no_limit(tree: Tree, joints, path: Path) -> None:
    """One warning naming the revolute and prismatic joints without <limit>, which the URDF
    specification requires of them: Pinocchio refuses such a file, vampc reads them as unlimited
    (it took one silently, saying it reads URDF as Pinocchio does: a new user's find). Not for an
    MJCF model, whose joints without a range are unlimited by its own rules (it was warned of in
    the URDF's words)."""
    if not tree.limits_required:
        return
    bare = [j for j in joints if j.type in ("revolute", "prismatic") and j.limit is None]
    if bare:
        have = f" and {quoted(j.name for j in bare[1:])} have" if len(bare) > 1 else " has"
        warnings.warn(VampcWarning(f"{path}: joint '{bare[0].name}' ({bare[0].type}){have} no "
                                   "<limit>, which the URDF specification requires of revolute and "
                                   "prismatic joints (Pinocchio refuses the file); read as unlimited"),
                      stacklevel=3)
    # a <limit> without its effort or velocity attribute (both required) was read as no such limit,
    # unsaid: the look-ahead then planned without it (a look-ahead audit's find)
    partial = [(j, [a for a in ("effort", "velocity") if getattr(j.limit, a, None) is None])
               for j in joints if j.limit is not None]
    partial = [(j, missing) for j, missing in partial if missing]
    if partial:
        j, missing = partial[0]
        more = f" (and {quoted(j.name for j, _ in partial[1:])})" if len(partial) > 1 else ""
        none = " and ".join({"effort": "no effort limit", "velocity": "no speed limit"}[a] for a in missing)
        warnings.warn(VampcWarning(f"{path}: joint '{j.name}'{more} has a <limit> without "
                                   f"{' or '.join(missing)}, which the URDF specification requires "
                                   f"(Pinocchio refuses the file); read as {none}"), stacklevel=3)


def _limits(j, path: Path) -> Limits:
    lim = j.limit
    if lim is None:
        return Limits()
    q = _position_range(j)
    # URDF files often write velocity="0" effort="0" as placeholders: read those as "not given".
    return Limits(q=q, qd=_positive(lim.velocity, "velocity", j, path),
                  tau=_positive(lim.effort, "effort", j, path))


def _position_range(j) -> tuple[float, float] | None:
    """A joint's position limits: None for a continuous joint, a <limit> giving neither lower nor
    upper, or one whose lower is above its upper (_inverted); one of them given, the other is URDF's default, 0 (as urdfdom and Pinocchio read it: a
    <limit upper="1"> had been read as no limits at all)."""
    lim = j.limit
    if j.type == "continuous" or lim is None or lim.lower is None and lim.upper is None:
        return None
    return None if _inverted(j) else (float(_or(lim.lower, 0.0)), float(_or(lim.upper, 0.0)))


def _inverted(j) -> bool:
    """Whether a joint's <limit> gives a lower bound above its upper (one not given is URDF's
    default, 0): Bullet's way of saying there is none (_warn_inverted_limits)."""
    lim = j.limit
    return j.type != "continuous" and lim is not None and \
        not (lim.lower is None and lim.upper is None) and \
        float(_or(lim.lower, 0.0)) > float(_or(lim.upper, 0.0))


def _warn_inverted_limits(joints, path: Path) -> None:
    """One warning naming the joints whose <limit> lower is above upper: read as no position
    limits, as Bullet reads them ("values ignored in case upper limit < lower limit": files made
    for pybullet write lower="1" upper="0" so); they were refused, though Pinocchio reads them and
    the dynamics does not need them (a trial of public URDF collections)."""
    inverted = [j for j in joints if _inverted(j)]
    if not inverted:
        return
    j, lim = inverted[0], inverted[0].limit
    lower = f"lower {float(lim.lower):g}" if lim.lower is not None else "lower not given (URDF's default, 0)"
    upper = f"upper {float(lim.upper):g}" if lim.upper is not None else "upper not given (URDF's default, 0)"
    more = f" (and {quoted(k.name for k in inverted[1:])})" if len(inverted) > 1 else ""
    warnings.warn(VampcWarning(f"{path}: joint '{j.name}'{more}: <limit> {lower} is above {upper}; "
                               "read as no position limits, as Bullet reads them (--lock then "
                               "takes any position)"), stacklevel=3)


def _positive(value, name: str, j, path: Path) -> float | None:
    """A <limit> bound: None for 0 (a placeholder, as many files write) or none given; a negative
    or non-finite one is an error (it was read as "not given", and the look-ahead then asked for a
    limit the file does give)."""
    if value is None:
        return None
    value = float(value)
    if not math.isfinite(value) or value < 0:
        raise located(path, f"joint '{j.name}'", f"<limit> {name} {value:g} is not a positive "
                      "number (0 means none given)")
    return value if value > 0 else None


# --- small rigid-body algebra (each also on stacks: leading axes are batch axes) ---------------------

def _origin(element) -> np.ndarray:
    """A yourdfpy joint's or inertial's <origin> as a 4x4 pose (identity when the file gives none)."""
    return _IDENTITY if element.origin is None else element.origin


def _offset(j) -> float:
    """What to add to a joint's q for its motion from the file's pose: 0 for a URDF joint, -ref for an
    MJCF joint whose reference position is ref (vampc.robot.mjcf)."""
    return float(getattr(j, "offset", 0.0))


def _motion(j, q: float) -> np.ndarray:
    """The joint's own motion at position q (identity for a fixed joint)."""
    q = q + _offset(j)
    out = np.eye(4)
    if j.type in ("revolute", "continuous"):
        out[:3, :3] = _axis_rotation(_unit(np.array(j.axis)), q)
    elif j.type == "prismatic":
        out[:3, 3] = q * _unit(np.array(j.axis))
    return out


def _unit(v: np.ndarray) -> np.ndarray:
    """Unit vectors along the rows of v. Where the squares of a row are out of float64's range, each
    row is scaled by its largest component first: the squares of an axis of 1e200 1e200 0 overflowed
    and the joint turned about another axis, without a word (a new user's find). Only then: scaling
    changes the last bit of other axes, and so every program made from them."""
    with np.errstate(over="ignore", under="ignore"):
        norm = np.linalg.norm(v, axis=-1, keepdims=True)
    if not np.all((norm > 1e-150) & (norm < 1e150)):
        v = v / np.max(np.abs(v), axis=-1, keepdims=True)
        norm = np.linalg.norm(v, axis=-1, keepdims=True)
    return v / norm


def _placed(frames: dict, pairs: list) -> np.ndarray:
    """frames[link] @ x for each (link, x), as one (m, 4, 4) stack."""
    if not pairs:
        return np.zeros((0, 4, 4))
    return matmul(np.array([frames[link] for link, _ in pairs]), np.array([x for _, x in pairs]))


def _transposed(m: np.ndarray) -> np.ndarray:
    return np.swapaxes(m, -1, -2)


def _skew(v: np.ndarray) -> np.ndarray:
    out = np.zeros(v.shape[:-1] + (3, 3))
    out[..., 0, 1], out[..., 0, 2], out[..., 1, 2] = -v[..., 2], v[..., 1], -v[..., 0]
    out[..., 1, 0], out[..., 2, 0], out[..., 2, 1] = v[..., 2], -v[..., 1], v[..., 0]
    return out


def _axis_rotation(axis: np.ndarray, angle) -> np.ndarray:
    """Rodrigues: rotation by `angle` about the unit vector `axis`."""
    k = _skew(axis)
    sin, versin = np.sin(angle), 1.0 - np.cos(angle)
    return (np.eye(3) + np.asarray(sin)[..., None, None] * k
            + np.asarray(versin)[..., None, None] * matmul(k, k))


def _z_to(a: np.ndarray) -> np.ndarray:
    """Rotations R with R e_z = a, for unit vectors a (m, 3): the shortest one, about e_z × a (a half turn
    about x when a = -e_z)."""
    s = np.hypot(a[:, 0], a[:, 1])
    turn = s >= 1e-12
    k = np.zeros_like(a)
    k[turn, 0], k[turn, 1] = -a[turn, 1] / s[turn], a[turn, 0] / s[turn]
    out = _axis_rotation(k, np.arctan2(s, a[:, 2]))
    out[~turn] = np.where(a[~turn, 2, None, None] > 0, np.eye(3), np.diag([1.0, -1.0, -1.0]))
    return out


def _rigid_inverse(t: np.ndarray) -> np.ndarray:
    """Inverses of rigid transforms (m, 4, 4): [Rᵀ, -Rᵀ p]."""
    out = np.zeros_like(t)
    out[:, :3, :3] = _transposed(t[:, :3, :3])
    out[:, :3, 3] = -matvec(out[:, :3, :3], t[:, :3, 3])
    out[:, 3, 3] = 1.0
    return out
