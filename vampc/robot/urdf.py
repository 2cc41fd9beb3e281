"""URDF → Chain (DESIGN §3).

A URDF joint k has an origin T_k (pose of the child link frame in the parent link frame at q = 0) and a unit
axis a_k in the child frame. We put O_{k-1} at joint k's origin, fixed in link k-1, with z along a_k:
O_{k-1} = T_k R_{a_k}, R_{a_k} a fixed rotation with R_{a_k} e_z = a_k. If G_k is the pose of O_k in link
k's own frame (G_k = X T_{k+1} R_{a_{k+1}} with X the pose, through fixed joints, of joint k+1's parent
link; for the last link G_n is the pose of the tip link), then O_k in O_{k-1} is R_{a_k}ᵀ M_k(q) G_k with
M_k(q) = R_{a_k} Rz(q) R_{a_k}ᵀ (revolute) or a translation q a_k (prismatic). Hence exactly

    A_k = Rz(q) Φ_k,   Φ_k = R_{a_k}ᵀ Rot(G_k),   p*_k = Φ_kᵀ R_{a_k}ᵀ t(G_k)   (+ q Φ_kᵀ e_z if prismatic)

with offset 0. Links hanging on link k through fixed (or locked) joints form one rigid body with it: their
inertials are summed into link k by the parallel-axis theorem. Gravity is [0, 0, -9.81] in the base link
frame, referred to O_0.

The file is parsed by lxml with entities off and refused if it declares any (entity bombs, external
entities). The elements vampc uses (<inertial>; a joint's type, <parent>, <child>, <origin>, <axis>, <limit>
and <mimic>) are read from the lxml tree with yourdfpy's semantics (a missing <origin> is the identity, a
missing <axis> is x, rpy are fixed-axis roll, pitch, yaw) and checked as they are read; the tests compare
them with yourdfpy's. yourdfpy itself is not called: it makes Python objects of every element, visuals and
collisions too, and spent 16 s of the 44 s a 100 000-joint chain took. Every step is O(n) in the number
of links and joints (the tree walks are iterative, each joint is visited a bounded number of times, and
Φ_k, p*_k and the bodies' inertias are computed as numpy stacks), and a chain of more than MAX_JOINTS
(vampc/robot/dh.py) movable joints is refused. Every problem is a one-line VampcError
"FILE: joint 'x': WHAT", "FILE: link 'x': WHAT" or "FILE: line N: WHAT".
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from lxml import etree

from vampc.errors import located
from vampc.gcpause import gc_paused
from vampc.robot.chain import Chain, Joint, JointType, Limits
from vampc.robot.dh import improper_inertias, inertia_problem, joint_count_problem

MOVABLE = {"revolute": JointType.REVOLUTE, "continuous": JointType.REVOLUTE,
           "prismatic": JointType.PRISMATIC}
GRAVITY = np.array([0.0, 0.0, -9.81])

# Numeric attributes we read (element tag -> attribute -> how many numbers), and where they sit.
_NUMBERS = {"origin": {"xyz": 3, "rpy": 3}, "axis": {"xyz": 3}, "mass": {"value": 1},
            "inertia": dict.fromkeys(("ixx", "ixy", "ixz", "iyy", "iyz", "izz"), 1),
            "limit": dict.fromkeys(("lower", "upper", "velocity", "effort"), 1),
            "mimic": dict.fromkeys(("multiplier", "offset"), 1)}
# yourdfpy would default a missing ixx to 1.0 where urdfdom (and so Pinocchio) refuses: refuse too.
_REQUIRED = {"mass": ("value",), "inertia": tuple(_NUMBERS["inertia"])}
_IDENTITY = np.eye(4)
_IDENTITY.flags.writeable = False  # shared by every missing <origin> and every body's own link


def load_urdf(path, base: str | None = None, tip: str | None = None,
              lock: dict[str, float] | None = None) -> Chain:
    """Read a URDF and return the chain of movable joints from link `base` (default: the root) to link
    `tip` (default: the end of the only movable path). `lock` maps joint names to values at which they are
    frozen (treated as fixed); a locked joint off the chain freezes everything below it too."""
    path = Path(path)
    with gc_paused():  # a big robot is millions of objects: the collector would walk them again and again
        return _load(path, base, tip, lock)


def _load(path: Path, base: str | None, tip: str | None, lock: dict[str, float] | None) -> Chain:
    robot = _read_robot(_parse_xml(path), path)
    tree = _Tree.build(robot, path)
    lock = _check_lock(lock or {}, tree, path)
    base = _choose_base(tree, base, path)
    _check_joint_types(tree, base, path)
    tip = _choose_tip(tree, base, tip, lock, path)
    route = tree.route(base, tip)
    chain = [j for j in route if j.type in MOVABLE and j.name not in lock]
    _check_chain(chain, base, tip, path)
    frames, body_of = _bodies(tree, base, chain, {j.name for j in route}, lock, path)
    return _build(robot.name, tree, chain, frames, body_of, tip, path)


# --- parsing -----------------------------------------------------------------------------------------

def _parse_xml(path: Path):
    """Parse without resolving entities or touching the network, and refuse any entity at all."""
    try:
        data = path.read_bytes()
    except FileNotFoundError:
        raise located(path, "", "no such file") from None
    except OSError as exc:
        raise located(path, "", f"cannot read: {exc.strerror or exc}") from None
    _refuse_declared_entities(data, path)
    parser = etree.XMLParser(resolve_entities=False, no_network=True, load_dtd=False, huge_tree=False,
                             remove_comments=True, remove_pis=True)
    try:
        root = etree.fromstring(data, parser)
    except etree.XMLSyntaxError as exc:
        raise located(path, f"line {exc.lineno}", f"not well-formed XML: {exc.msg}") from None
    _refuse_entities(root, path)
    return root


_ENTITY_DECL = re.compile(rb"<!ENTITY\s+(?:%\s+)?([^\s>]+)")


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


# --- reading: the elements vampc uses, with yourdfpy's semantics ------------------------------------

@dataclass(frozen=True)
class _Inertial:
    """A link's <inertial>: mass, inertia about the centre of mass and the pose of that frame in the link
    (identity without <origin>); mass or inertia None when its element is missing."""

    mass: float | None
    inertia: np.ndarray | None
    origin: np.ndarray


@dataclass(frozen=True)
class _Link:
    name: str
    inertial: _Inertial | None


@dataclass(frozen=True)
class _Limit:
    """<limit>: each attribute None when not given."""

    lower: float | None
    upper: float | None
    velocity: float | None
    effort: float | None


@dataclass(frozen=True)
class _UrdfJoint:
    """A <joint>: origin T_k (identity without <origin>), axis as written (x without <axis>), <limit>, and
    the joint its <mimic> names (None without <mimic>)."""

    name: str
    type: str
    parent: str
    child: str
    origin: np.ndarray
    axis: tuple
    limit: _Limit | None
    mimic: str | None


@dataclass(frozen=True)
class _Robot:
    name: str
    links: tuple
    joints: tuple


def _read_robot(root, path: Path) -> _Robot:
    """The robot's links and joints (in file order), checked as they are read so that every later step
    may rely on names, numbers, parents and children being there."""
    if etree.QName(root).localname != "robot" or root.get("name") is None:
        raise located(path, f"line {root.sourceline}", "the root element must be <robot name=\"...\">")
    return _Robot(root.get("name"), _read_all(root, "link", _read_link, path),
                  _read_all(root, "joint", _read_joint, path))


def _read_all(root, kind: str, read, path: Path) -> tuple:
    """Every <kind> child of the root (as yourdfpy: direct children only), each read by `read`."""
    out, seen = [], set()
    for el in root.iterchildren(kind):
        name = _named(el, kind, path)
        if name in seen:
            raise located(path, f"{kind} '{name}'", f"defined twice (again on line {el.sourceline})")
        seen.add(name)
        out.append(read(el, name, path))
    return tuple(out)


def _named(el, kind: str, path: Path) -> str:
    name = el.get("name")
    if not name:
        raise located(path, f"line {el.sourceline}", f"<{kind}> has no name")
    if kind == "joint" and el.get("type") is None:
        raise located(path, f"joint '{name}'", "has no type")
    return name


def _read_link(el, name: str, path: Path) -> _Link:
    inertial = _first_children(el).get("inertial")
    if inertial is None:
        return _Link(name, None)
    where = f"link '{name}'"
    sub = _first_children(inertial)
    origin, mass, inertia = [_numbers(sub.get(tag), where, path) for tag in ("origin", "mass", "inertia")]
    return _Link(name, _Inertial(mass=None if mass is None else mass["value"][0],
                                 inertia=None if inertia is None else _inertia_matrix(inertia),
                                 origin=_pose(origin)))


def _read_joint(el, name: str, path: Path) -> _UrdfJoint:
    where = f"joint '{name}'"
    sub = _first_children(el)
    tags = ("origin", "axis", "limit", "mimic")
    origin, axis, limit, _ = [_numbers(sub.get(tag), where, path) for tag in tags]
    parent, child = [_end(sub.get(tag), tag, where, path) for tag in ("parent", "child")]
    mimic = sub.get("mimic")
    return _UrdfJoint(name=name, type=el.get("type"), parent=parent, child=child, origin=_pose(origin),
                      axis=(axis or {}).get("xyz", (1.0, 0.0, 0.0)), limit=_limit(limit),
                      mimic=None if mimic is None else str(mimic.get("joint")))


def _end(el, tag: str, where: str, path: Path) -> str:
    """The link named by a joint's <parent> or <child>."""
    link = None if el is None else el.get("link")
    if link is None:
        raise located(path, where, f"missing <{tag} link=\"...\"/>")
    return link


def _limit(attrs: dict | None) -> _Limit | None:
    if attrs is None:
        return None
    return _Limit(*(attrs[k][0] if k in attrs else None for k in _NUMBERS["limit"]))


def _first_children(el) -> dict:
    """Tag -> first child with that tag (yourdfpy's `find`; one pass over the children is cheaper)."""
    out = {}
    for sub in el:
        out.setdefault(sub.tag, sub)
    return out


def _numbers(el, where: str, path: Path) -> dict | None:
    """The numeric attributes of `el` (attribute -> tuple of floats), checked: required ones present, each
    the right count of finite numbers. None when `el` is None."""
    if el is None:
        return None
    attrs = dict(el.items())
    missing = [a for a in _REQUIRED.get(el.tag, ()) if a not in attrs]
    if missing:
        raise located(path, where, f"<{el.tag}> lacks {', '.join(missing)}")
    out = {}
    for attr, count in _NUMBERS[el.tag].items():
        raw = attrs.get(attr)
        if raw is None:
            continue
        try:  # float() takes the one number with any spaces around it, as split() then float() would
            values = (float(raw),) if count == 1 else tuple(map(float, raw.split()))
        except ValueError:
            values = ()
        if len(values) != count or not all(map(math.isfinite, values)):
            noun = "a finite number" if count == 1 else f"{count} finite numbers"
            raise located(path, where, f"<{el.tag} {attr}=\"{raw}\">: expected {noun}")
        out[attr] = values
    return out


def _pose(origin: dict | None) -> np.ndarray:
    """An <origin> as yourdfpy reads it (trimesh's compose_matrix): T(xyz) Rz(yaw) Ry(pitch) Rx(roll),
    xyz and rpy zero when not given; the identity without <origin>."""
    if origin is None:
        return _IDENTITY
    x, y, z = origin.get("xyz", (0.0, 0.0, 0.0))
    roll, pitch, yaw = origin.get("rpy", (0.0, 0.0, 0.0))
    si, sj, sk = math.sin(roll), math.sin(pitch), math.sin(yaw)
    ci, cj, ck = math.cos(roll), math.cos(pitch), math.cos(yaw)
    cc, cs, sc, ss = ci * ck, ci * sk, si * ck, si * sk
    return np.array([[cj * ck, sj * sc - cs, sj * cc + ss, x],
                     [cj * sk, sj * ss + cc, sj * cs - sc, y],
                     [-sj, cj * si, cj * ci, z],
                     [0.0, 0.0, 0.0, 1.0]])


def _inertia_matrix(attrs: dict) -> np.ndarray:
    (ixx,), (ixy,), (ixz,), (iyy,), (iyz,), (izz,) = (attrs[k] for k in _NUMBERS["inertia"])
    return np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])


def _names(names, most: int = 10) -> str:
    """Quoted names for a message; past `most`, a count of the rest (a message stays one readable line)."""
    names = list(names)
    shown = ", ".join(f"'{n}'" for n in names[:most])
    return shown if len(names) <= most else f"{shown} and {len(names) - most} more"


# --- the kinematic tree ------------------------------------------------------------------------------

@dataclass(frozen=True)
class _Tree:
    """Links and joints by name, each link's parent joint and each link's child joints (file order)."""

    links: dict
    joints: dict
    parent: dict
    children: dict

    @staticmethod
    def build(robot, path: Path) -> _Tree:
        """Index the robot; refuse dangling links, links with two parents and closed loops."""
        links = {link.name: link for link in robot.links}
        parent, children = {}, {name: [] for name in links}
        for j in robot.joints:
            for role, link in (("parent", j.parent), ("child", j.child)):
                if link not in links:
                    raise located(path, f"joint '{j.name}'", f"{role} link '{link}' is not defined")
            if j.child in parent:
                both = _names([parent[j.child].name, j.name]).replace(", ", " and ")
                raise located(path, f"link '{j.child}'", f"has two parent joints ({both}); "
                                                         "closed loops are not supported")
            parent[j.child] = j
            children[j.parent].append(j)
        tree = _Tree(links, {j.name: j for j in robot.joints}, parent, children)
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
                    raise located(path, f"joint '{loop[0]}'", f"closes a loop through joints {_names(loop)}; "
                                                             "closed loops are not supported")
                seen[link] = len(seen)
                link = self.parent[link].parent
            done.update(seen)

    def below(self, link: str) -> list:
        """Every joint in the subtree under `link`, depth first."""
        out, stack = [], list(reversed(self.children[link]))
        while stack:
            j = stack.pop()
            out.append(j)
            stack.extend(reversed(self.children[j.child]))
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


def _check_lock(lock: dict, tree: _Tree, path: Path) -> dict:
    out = {}
    for name, value in lock.items():
        if name not in tree.joints:
            raise located(path, f"lock {name}", f"no joint named '{name}'")
        try:
            out[name] = float(value)
        except (TypeError, ValueError):
            out[name] = math.nan
        if not math.isfinite(out[name]):
            raise located(path, f"lock {name}", f"value {value!r} is not a finite number")
    return out


def _choose_base(tree: _Tree, base: str | None, path: Path) -> str:
    if base is not None:
        if base not in tree.links:
            raise located(path, "", f"unknown base link '{base}'")
        return base
    roots = [name for name in tree.links if name not in tree.parent]
    if len(roots) != 1:
        raise located(path, "", f"several root links ({_names(roots)}); choose one with --base")
    return roots[0]


def _check_joint_types(tree: _Tree, base: str, path: Path) -> None:
    for j in tree.below(base):
        if j.type in ("floating", "planar"):
            raise located(path, f"joint '{j.name}'", f"{j.type} joints are not supported")
        if j.type != "fixed" and j.type not in MOVABLE:
            raise located(path, f"joint '{j.name}'", f"unsupported joint type '{j.type}'")
        if j.type in MOVABLE and not math.hypot(*j.axis) > 1e-9:
            raise located(path, f"joint '{j.name}'", "axis is zero")


def _choose_tip(tree: _Tree, base: str, tip: str | None, lock: dict, path: Path) -> str:
    if tip is not None:
        if tip not in tree.links:
            raise located(path, "", f"unknown tip link '{tip}'")
        if tip != base and base not in {j.parent for j in tree.ancestors(tip)}:
            raise located(path, "", f"no path from base link '{base}' down to tip link '{tip}'")
        return tip
    free = [j for j in tree.below(base) if j.type in MOVABLE and j.name not in lock]
    if not free:
        raise located(path, "", f"no movable joints below base link '{base}'")
    ends = [_descend(tree, j.child) for j in _lowest(tree, free)]
    if len(ends) > 1:
        raise located(path, "", f"several movable branches below base link '{base}'; "
                                f"choose --tip from {_names(ends)}")
    return ends[0]


def _lowest(tree: _Tree, free: list) -> list:
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


def _descend(tree: _Tree, link: str) -> str:
    """Follow single (fixed) children down, so a tool link bolted on the last link becomes the tip."""
    while len(tree.children[link]) == 1:
        link = tree.children[link][0].child
    return link


def _check_chain(chain: list, base: str, tip: str, path: Path) -> None:
    if not chain:
        raise located(path, "", f"no movable joints between base link '{base}' and tip link '{tip}'")
    problem = joint_count_problem(len(chain))
    if problem:
        raise located(path, "", problem)
    for j in chain:
        if j.mimic is not None:
            raise located(path, f"joint '{j.name}'", f"mimics joint '{j.mimic}'; mimic joints are not "
                                                     f"supported (lock it with --lock {j.name}=VALUE)")


# --- rigid bodies ------------------------------------------------------------------------------------

def _bodies(tree: _Tree, base: str, chain: list, route: set, lock: dict, path: Path):
    """Assign every link below `base` to a body 0..n (the chain link it is rigidly attached to) and give its
    pose in that body's reference frame (body 0: the base link; body k: the child link of chain joint k).

    Off-chain joints must be fixed, locked or below a locked off-chain joint (frozen at their lock value
    or 0); any other movable joint branches off the chain and is refused."""
    index = {j.name: k for k, j in enumerate(chain, 1)}
    frames, body_of, stray = {base: _IDENTITY}, {base: 0}, []
    stack = [(base, False)]
    while stack:
        link, frozen = stack.pop()
        for j in tree.children[link]:
            if j.name in index:
                frames[j.child], body_of[j.child] = _IDENTITY, index[j.name]
                stack.append((j.child, False))
            elif j.type in MOVABLE and j.name not in lock and not frozen:
                stray.append(j.name)
            else:
                frames[j.child] = frames[link] @ j.origin @ _motion(j, lock.get(j.name, 0.0))
                body_of[j.child] = body_of[link]
                stack.append((j.child, frozen or (j.name in lock and j.name not in route)))
    if stray:
        order = {name: i for i, name in enumerate(tree.joints)}
        stray.sort(key=order.__getitem__)  # file order
        more = f" (also {_names(stray[1:])})" if len(stray) > 1 else ""
        raise located(path, "", f"joint '{stray[0]}' branches off the chain; lock it with "
                                f"--lock {stray[0]}=VALUE or choose --tip{more}")
    return frames, body_of


def _build(name: str, tree: _Tree, chain: list, frames: dict, body_of: dict, tip: str, path: Path) -> Chain:
    """The Chain, every joint's Φ_k, p*_k and body computed for all joints at once (numpy stacks)."""
    r_a = _z_to(_unit(np.array([j.axis for j in chain])))  # R_{a_k}: e_z onto joint k's axis
    g = _reference_poses(chain, frames, r_a, tip)
    phi = _transposed(r_a) @ g[1:, :3, :3]
    p_fixed = (_transposed(phi) @ _transposed(r_a) @ g[1:, :3, 3:])[..., 0]
    mass, com, inertia = _body_inertias(tree, _members(body_of), g, frames, path)
    joints = tuple(Joint(name=j.name, type=MOVABLE[j.type], phi=phi[k], p_fixed=p_fixed[k], offset=0.0,
                         mass=float(mass[k]), com=com[k], inertia=inertia[k], limits=_limits(j, path))
                   for k, j in enumerate(chain))
    return Chain(name=name, joints=joints, gravity=g[0, :3, :3].T @ GRAVITY, source=str(path))


def _reference_poses(chain: list, frames: dict, r_a: np.ndarray, tip: str) -> np.ndarray:
    """G_0..G_n as an (n + 1, 4, 4) stack: G_{k-1} = X T_k R_{a_k}, X the pose of joint k's parent link in
    its body; G_n the pose of the tip link in body n."""
    g = np.array([frames[j.parent] @ j.origin for j in chain] + [frames[tip]])
    g[:-1, :3, :3] = g[:-1, :3, :3] @ r_a
    return g


def _members(body_of: dict) -> dict:
    """Body number -> its links, in the order `_bodies` reached them (one pass over all links: picking each
    body's links out of all of them would be O(n²))."""
    out = {}
    for name, body in body_of.items():
        out.setdefault(body, []).append(name)
    return out


def _body_inertias(tree: _Tree, members: dict, g: np.ndarray, frames: dict, path: Path):
    """Mass (n,), centre of mass (n, 3) and inertia about it (n, 3, 3), in O_k, of every body k = 1..n."""
    n = len(g) - 1
    body, names, parts = _inertial_parts(tree, members, n, path)
    inertia = np.array([p.inertia for p in parts])
    _check_inertias(inertia, names, path)
    in_link = np.array([frames[name] @ p.origin for name, p in zip(names, parts)])
    pose = _rigid_inverse(g[1:])[body] @ in_link  # each inertial's frame in O_k
    rot = pose[:, :3, :3]
    return _sum_bodies(body, n, np.array([p.mass for p in parts]), pose[:, :3, 3],
                       rot @ inertia @ _transposed(rot))


def _inertial_parts(tree: _Tree, members: dict, n: int, path: Path):
    """Every link of bodies 1..n that has an <inertial>: its body (0-based, as an array), names, inertials."""
    body, names, parts = [], [], []
    for k in range(1, n + 1):
        count = len(parts)
        for name in members[k]:
            inertial = tree.links[name].inertial
            if inertial is not None:
                _check_mass(inertial, name, path)
                body.append(k - 1)
                names.append(name)
                parts.append(inertial)
        if len(parts) == count:
            first = members[k][0]
            raise located(path, f"link '{first}'", f"no <inertial>: the body moved by joint "
                                                   f"'{tree.parent[first].name}' would have no mass")
    return np.array(body, dtype=int), names, parts


def _check_mass(inertial: _Inertial, link: str, path: Path) -> None:
    if inertial.mass is None or inertial.inertia is None:
        missing = "<mass>" if inertial.mass is None else "<inertia>"
        raise located(path, f"link '{link}'", f"<inertial> has no {missing}")
    if inertial.mass < 0:
        raise located(path, f"link '{link}'", f"negative mass {inertial.mass}")


def _check_inertias(inertia: np.ndarray, names: list, path: Path) -> None:
    """Refuse the first inertia that is not symmetric positive semi-definite (checked as one stack)."""
    for i in np.flatnonzero(improper_inertias(inertia)):
        problem = inertia_problem(inertia[i])
        if problem:
            raise located(path, f"link '{names[i]}'", problem)


def _sum_bodies(body: np.ndarray, n: int, mass: np.ndarray, com: np.ndarray, inertia: np.ndarray):
    """Sum rigidly joined parts (mass, com, inertia about com; `body` says whose) into n bodies, each
    about its joint centre of mass (parallel axes)."""
    total = np.bincount(body, weights=mass, minlength=n)
    first = np.zeros((n, 3))
    np.add.at(first, body, mass[:, None] * com)
    centre = np.divide(first, total[:, None], out=np.zeros((n, 3)), where=total[:, None] > 0)
    d = com - centre[body]
    shift = np.einsum("ij,ij->i", d, d)[:, None, None] * np.eye(3) - d[:, :, None] * d[:, None, :]
    out = np.zeros((n, 3, 3))
    np.add.at(out, body, inertia + mass[:, None, None] * shift)
    return total, centre, out


def _limits(j, path: Path) -> Limits:
    lim = j.limit
    if lim is None:
        return Limits()
    q = None
    if j.type != "continuous" and lim.lower is not None and lim.upper is not None:
        if lim.lower > lim.upper:
            raise located(path, f"joint '{j.name}'", f"<limit> lower {lim.lower} is above upper {lim.upper}")
        q = (float(lim.lower), float(lim.upper))
    # URDF files often write velocity="0" effort="0" as placeholders: read those as "not given".
    return Limits(q=q, qd=_positive(lim.velocity), tau=_positive(lim.effort))


def _positive(value) -> float | None:
    return float(value) if value is not None and value > 0 else None


# --- small rigid-body algebra (each also on stacks: leading axes are batch axes) ---------------------

def _motion(j, q: float) -> np.ndarray:
    """The joint's own motion at position q (identity for a fixed joint)."""
    out = np.eye(4)
    if j.type in ("revolute", "continuous"):
        out[:3, :3] = _axis_rotation(_unit(np.array(j.axis)), q)
    elif j.type == "prismatic":
        out[:3, 3] = q * _unit(np.array(j.axis))
    return out


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


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
    return np.eye(3) + np.asarray(sin)[..., None, None] * k + np.asarray(versin)[..., None, None] * (k @ k)


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
    out[:, :3, 3] = -(out[:, :3, :3] @ t[:, :3, 3:])[..., 0]
    out[:, 3, 3] = 1.0
    return out
