"""The kinematic tree of a URDF robot, and the choice of base, tip and route through it
(README, *URDF*).

`Tree` indexes yourdfpy's links and joints by name, with each link's parent joint and child joints, and
refuses what is not a tree (undefined links, a link with two parents, closed loops). The functions below
pick the base link (the root, or --base), check the joint types under it, and pick the tip link (--tip, or
the end of the only movable branch). Every step is O(n) in the number of links and joints: the walks are
iterative and visit each joint a bounded number of times, so a 100 000-joint chain is walked in
milliseconds. Every problem is a one-line VampcError naming the file and the joint or link.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

from vampc.errors import located
from vampc.robot.chain import JointType, matmul
from vampc.textio import did_you_mean

MOVABLE = {"revolute": JointType.REVOLUTE, "continuous": JointType.REVOLUTE,
           "prismatic": JointType.PRISMATIC}


def quoted(items, most: int = 10) -> str:
    """Quoted names for a message; past `most`, a count of the rest (a message stays one readable line)."""
    return listed((f"'{n}'" for n in items), most)


def listed(items, most: int = 10) -> str:
    """Texts for a message, comma separated; past `most`, a count of the rest."""
    items = list(items)
    shown = ", ".join(items[:most])
    return shown if len(items) <= most else f"{shown} and {len(items) - most} more"


def cut_away(path, base: str, said: list, placed_by: str) -> str:
    """The warning that --base cut away the joints above it, `said` (each with where it is, placed
    as `placed_by` says), through which gravity is turned into the base's frame."""
    return (f"{path}: --base {base}: the joints above it are cut away ({listed(said)}: {placed_by}); "
            f"gravity is turned into {base}'s frame through them there")


def placed_by(causes: dict, leader: str, default: str, default_each: str) -> str:
    """How the cut-away joints were placed, said of each (`causes`: name -> 'lock', 'leader' or
    'default'): 'by --lock' where all were alike, else 'j2 by --lock; j1 by default'. Every cause
    that could be had been listed for each ('by --lock, by a coupled mimic's leader, or 0 by
    default' of a joint at 0 by default: a new user's find)."""
    groups: dict[str, list] = {"lock": [], "leader": [], "default": []}
    for name, cause in causes.items():
        groups[cause].append(name)
    used = [k for k in groups if groups[k]]
    if len(used) == 1:
        return {"lock": "by --lock", "leader": f"by {leader}", "default": default}[used[0]]
    each = {"lock": "by --lock", "leader": f"by {leader}", "default": default_each}
    return "; ".join(f"{listed(groups[k])} {each[k]}" for k in used)


def follows_from_below(path, name: str, base: str, leader: str):
    """The error for a --mimic couple follower above the base whose leader moves below it."""
    return located(path, f"joint '{name}'", f"above the base link '{base}', follows joint '{leader}' "
                                           f"below it (--mimic couple): the base would move with it; "
                                           f"lock '{leader}', or choose another --base")


@dataclass(frozen=True)
class Tree:
    """Links and joints by name, each link's parent joint and each link's child joints (file order)."""

    links: dict
    joints: dict
    parent: dict
    children: dict
    gravity: tuple = (0.0, 0.0, -9.81)   # in the frame of the link gravity_in names (None: the root's)
    by_name: bool = True                 # Pinocchio numbers a URDF's children by name, an MJCF's in order
    gravity_in: str | None = None
    limits_required: bool = True         # URDF requires a revolute or prismatic joint's <limit>;
    #                                      an MJCF joint without a range is simply unlimited

    @staticmethod
    def build(robot, path: Path, gravity=(0.0, 0.0, -9.81), by_name: bool = True,
              gravity_in: str | None = None, limits_required: bool = True) -> Tree:
        """Index the robot (yourdfpy's `Robot`, or vampc.robot.mjcf's of the same shape); refuse dangling
        links, links with two parents and closed loops."""
        links = {link.name: link for link in robot.links}
        parent, children = {}, {name: [] for name in links}
        for j in robot.joints:
            for role, link in (("parent", j.parent), ("child", j.child)):
                if link not in links:
                    raise located(path, f"joint '{j.name}'", f"{role} link '{link}' is not defined")
            if j.child in parent:
                both = quoted([parent[j.child].name, j.name]).replace(", ", " and ")
                raise located(path, f"link '{j.child}'", f"has two parent joints ({both}); "
                                                         "closed loops are not supported")
            parent[j.child] = j
            children[j.parent].append(j)
        tree = Tree(links, {j.name: j for j in robot.joints}, parent, children, tuple(gravity), by_name,
                    gravity_in, limits_required)
        tree.check_loops(path)
        return tree

    def check_loops(self, path: Path) -> None:
        """With one parent per link, a loop is a cycle of parent joints never reaching a root."""
        done = set()
        for start in self.links:
            seen = {}  # link -> its step on this walk: a dict, since a list's `in` would make this O(n²)
            link = start
            while link in self.parent and link not in done:
                if link in seen:
                    loop = [self.parent[x].name for x in list(seen)[seen[link]:]]
                    raise located(path, f"joint '{loop[0]}'", f"closes a loop through joints {quoted(loop)}; "
                                                             "closed loops are not supported")
                seen[link] = len(seen)
                link = self.parent[link].parent
            done.update(seen)

    def has_own_mass(self, link: str) -> bool:
        """Whether `link` itself has an inertial of nonzero mass."""
        inertial = getattr(self.links[link], "inertial", None)
        return inertial is not None and bool(inertial.mass)

    def has_mass(self, link: str) -> bool:
        """Whether `link` or a link under it has an inertial of nonzero mass."""
        return any(self.has_own_mass(name) for name in [link] + [j.child for j in self.below(link)])

    def below(self, link: str, by_name: bool = False) -> list:
        """Every joint in the subtree under `link`, depth first, children in file order or, `by_name`,
        in the order of their names (as urdfdom keeps them, so Pinocchio numbers a URDF's joints)."""
        def kids(name):
            c = self.children[name]
            return sorted(c, key=lambda j: j.name.encode()) if by_name else c
        out, stack = [], list(reversed(kids(link)))
        while stack:
            j = stack.pop()
            out.append(j)
            stack.extend(reversed(kids(j.child)))
        return out

    def ancestors(self, link: str):
        """Joints from `link` up to its root, nearest first (a generator: callers may stop early)."""
        while link in self.parent:
            yield self.parent[link]
            link = self.parent[link].parent

    def route(self, base: str, tip: str) -> list:
        """The joints from `base` down to `tip` (tip is known to lie below base)."""
        out = []
        for j in self.ancestors(tip):
            if j.child == base:
                break
            out.append(j)
        return out[::-1]


def turns(joint) -> bool:
    """Whether a joint's <origin> turns the frame of the link it carries (by more than 1e-12 in any
    entry: the two warnings that say so had taken a turn at 1e-12 and at numpy's 1e-8 each)."""
    import numpy as np
    return joint.origin is not None and not np.allclose(joint.origin[:3, :3], np.eye(3), rtol=0,
                                                        atol=1e-12)


def choose_base(tree: Tree, base: str | None, path: Path, floating: bool = False) -> tuple[str, bool]:
    """The base link: `base` if given (it must exist; the root link whose one joint floats is taken as
    when it is not given, and a link hanging on a floating joint is a fixed base, said), else the only
    root link, or the link a root joint of type floating carries (the base then floats); and whether
    the base floats."""
    if base is not None:
        if base not in tree.links:
            raise located(path, "", f"unknown base link '{base}'"
                          + (_after_last_joint(tree, base) or did_you_mean(base, tree.links)))
        carried = _floating_child(tree, base) if base not in tree.parent else None
        if carried:
            return carried, True                         # the root named: as without --base
        above = tree.parent.get(base)
        if above is not None and above.type == "floating" and not floating:
            import warnings

            from vampc.errors import VampcWarning
            turned = turns(above)
            warnings.warn(VampcWarning(f"{path}: base link '{base}' hangs on floating joint "
                                       f"'{above.name}': it is taken as a fixed base (--floating-base "
                                       "lets it float)" + ("; gravity is turned by the joint's "
                                       "<origin> rpy, as at Pinocchio's neutral pose" if turned
                                       else "")), stacklevel=3)
        return base, floating
    roots = [name for name in tree.links if name not in tree.parent]
    if not roots:   # (a <robot> with no <link> was "several root links ()": a new user's find)
        raise located(path, "", "no <link>: the robot has nothing to compile")
    if len(roots) != 1:
        raise located(path, "", f"several root links ({quoted(roots)}); choose one with --base")
    carried = _floating_child(tree, roots[0])
    if carried:
        return carried, True
    if floating and tree.by_name:
        _warn_massless_root(tree, roots[0], path)
    if floating and not tree.by_name:
        # an MJCF with no free joint, --floating-base: its root is the world body, and floating
        # that put the base at the world's origin and counted the bodies welded to the world (a
        # scene's table) in it; Pinocchio and MuJoCo float the robot's top body (a new user's
        # find). The one body under the world with moving joints below it, welded to the world.
        top = tree.children[roots[0]]
        moving = [j for j in top if j.type in MOVABLE
                  or any(k.type in MOVABLE for k in tree.below(j.child))]
        if len(moving) == 1 and all(j.type == "fixed" for j in top):
            return moving[0].child, True
        # (the world body floated with what is welded to it, unsaid, where a robot hangs on a
        # joint from it beside a table, or where two robots do: a new user's find)
        if len(moving) > 1:
            raise located(path, "", f"--floating-base: the world body carries {len(moving)} bodies "
                          f"with joints ({quoted(j.child for j in moving)}), each a robot of its "
                          "own, and floating the world body would join them: give the one to float "
                          "a free joint in the file, or compile it alone with --base BODY (README, "
                          "MJCF)")
        # (a welded body of no mass, a camera's or a site's, changes nothing: a review's find)
        still = [j.child for j in top if j not in moving and tree.has_mass(j.child)]
        if moving and still:
            hung = moving[0]
            raise located(path, "", f"--floating-base: '{hung.child}' hangs on joint '{hung.name}' "
                          f"from the world body, so the world body would float, and with it "
                          f"{quoted(still)}, welded to it with no joint below: give the robot a free "
                          f"joint in the file to float it alone, or float '{hung.child}' itself with "
                          f"--base {hung.child} (README, MJCF)")
    return roots[0], floating


def _warn_massless_root(tree: Tree, root: str, path: Path) -> None:
    """--floating-base on a URDF whose root link has no mass and holds the body on fixed joints,
    through massless links, away from its frame (a `world` or `base_footprint` over the torso): the
    root floats, as Pinocchio's free flyer at the root does, so the base's columns are read, and its
    wrench given, in the root's frame, not the body's. Said, with --base to float the body (a new
    user's torques differed by 10% between the two, unsaid; a review's world -> base_link -> torso
    went unsaid where only the root's own joints were looked at)."""
    import numpy as np
    link, pose, through = root, np.eye(4), []
    while not tree.has_own_mass(link):
        welded = tree.children[link]
        if not welded:
            return
        if any(j.type != "fixed" for j in welded):
            break                 # (a massless link the joints move from: it is the body that floats)
        heavy = [j for j in welded if tree.has_mass(j.child)]
        moving = [j for j in heavy if any(k.type in MOVABLE for k in tree.below(j.child))]
        # the one body with joints below it (a plate welded beside the torso does not hide it),
        # or the one body of mass; none or several: no one body to name
        chosen = moving if len(moving) == 1 else heavy if len(heavy) == 1 else []
        if not chosen:
            return
        j = chosen[0]
        pose = matmul(pose, np.eye(4) if j.origin is None else j.origin)
        link, through = j.child, through + [j.name]
    if link == root or np.allclose(pose, np.eye(4)):
        return
    import warnings

    from vampc.errors import VampcWarning
    joints = ", ".join(f"'{name}'" for name in through)
    warnings.warn(VampcWarning(
        f"{path}: --floating-base floats the root link '{root}', which has no mass: '{link}' is "
        f"fixed to it by joint{'s' if len(through) > 1 else ''} {joints} away from its frame, so the "
        f"base's columns are read, and its wrench given, in the frame of '{root}' (as Pinocchio's "
        f"free flyer at the root); --base {link} --floating-base floats '{link}' itself"),
        stacklevel=3)


def _after_last_joint(tree: Tree, link: str) -> str:
    """For an unknown link named BODY__JOINT where JOINT is an MJCF body's last joint: the hint that
    that link is BODY itself ('arm__j2' for the body arm on j1, j2 was only 'unknown'; a new user's
    find); else nothing."""
    last = next((j for j in tree.joints.values() if "__" in link and link == f"{j.child}__{j.name}"),
                None)
    return f" (the link after {last.name}, {last.child}'s last joint, is {last.child} itself)" \
        if last else ""


def _floating_child(tree: Tree, link: str) -> str | None:
    """The link a root's one joint, of type floating, carries (the base that then floats), or None."""
    free = [j for j in tree.children[link] if j.type == "floating"]
    return free[0].child if free and len(tree.children[link]) == 1 else None


def check_joint_types(tree: Tree, base: str, path: Path) -> None:
    """Refuse floating joints below the base (a floating joint is only the root's), planar and unknown
    joint types, and movable joints with a zero axis."""
    for j in tree.below(base):
        if j.type == "floating":    # a floating root joint was taken by choose_base
            # (why this one is not, said: a root with a floating and a fixed joint had been told
            # floating joints are not supported, an audit's)
            # (the way round it, where there is one, was unsaid: a new user's find)
            way = (f"; --base {j.child} --floating-base floats '{j.child}', what is above it left "
                   "out" if any(k.type in MOVABLE for k in tree.below(j.child)) else "")
            raise located(path, f"joint '{j.name}'", "a floating joint is taken only as the one joint "
                          "of the root link (the base then floats; README, Trees and floating "
                          f"bases), and this one is not{way}")
        if j.type == "planar":
            raise located(path, f"joint '{j.name}'", f"{j.type} joints are not supported")
        if j.type != "fixed" and j.type not in MOVABLE:
            raise located(path, f"joint '{j.name}'", f"unsupported joint type '{j.type}'")
        length = math.hypot(*j.axis) if j.type in MOVABLE else 1.0
        if not length > 1e-9:       # (an axis of 1e-170 was said to be zero: a new user's find)
            raise located(path, f"joint '{j.name}'", (
                "axis is zero" + (" (its <axis> gives xyz=\"0 0 0\" or no xyz, which urdfdom, "
                                  "Pinocchio's reader, reads so; README, URDF)" if tree.by_name
                                  else "")) if not length else
                          f"its axis is {length:.3g} long: too short to be told from zero (at "
                          "least 1e-9; only its direction counts: give a unit vector)")


def choose_tip(tree: Tree, base: str, tip: str | None, lock: dict, path: Path) -> str:
    """The tip link: `tip` if given (it must lie below `base`), else the end of the only branch of free
    (movable, unlocked) joints below `base`, followed down through single fixed children; None when
    there are several branches (the robot is taken whole, as a tree)."""
    if tip is not None:
        if tip not in tree.links:
            raise located(path, "", f"unknown tip link '{tip}'"
                          + (_after_last_joint(tree, tip) or did_you_mean(tip, tree.links)))
        if tip != base and base not in {j.parent for j in tree.ancestors(tip)}:
            raise located(path, "", f"no path from base link '{base}' down to tip link '{tip}'")
        return tip
    movable = [j for j in tree.below(base) if j.type in MOVABLE]
    free = [j for j in movable if j.name not in lock]
    # (said "no movable joints" of three locked through their leader; not said how they are locked:
    # by --lock, by an MJCF equality, or as a follower of a locked leader under --mimic couple)
    if not free and movable:
        raise located(path, "", f"no free joint below base link '{base}': "
                      + ("its one movable joint" if len(movable) == 1 else
                         f"its {len(movable)} movable joints")
                      + f" ({quoted((j.name for j in movable), 5)}) "
                      + ("is" if len(movable) == 1 else "are all") + " locked")
    if not free:
        raise located(path, "", f"no movable joints below base link '{base}'")
    ends = [_descend(tree, j.child) for j in _lowest(tree, free)]
    return ends[0] if len(ends) == 1 else None    # several branches: the whole tree


def _lowest(tree: Tree, free: list) -> list:
    """The joints of `free` with none of the others below them. Each walk up from a joint marks the joints
    above it and stops at one already marked, so every joint is marked once: O(n), where collecting all
    the ancestors of every joint would be O(n²) on a long chain."""
    above = set()
    for j in free:
        for a in tree.ancestors(j.parent):
            if a.name in above:
                break
            above.add(a.name)
    return [j for j in free if j.name not in above]


def _descend(tree: Tree, link: str) -> str:
    """Follow single (fixed) children down, so a tool link bolted on the last link becomes the tip."""
    while len(tree.children[link]) == 1:
        link = tree.children[link][0].child
    return link
