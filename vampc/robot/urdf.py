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
entities) before yourdfpy sees it. Every problem is a one-line VampcError "FILE: joint 'x': WHAT",
"FILE: link 'x': WHAT" or "FILE: line N: WHAT".
"""
from __future__ import annotations

import io
import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from lxml import etree

from vampc.errors import located
from vampc.robot.chain import E_Z, Chain, Joint, JointType, Limits
from vampc.robot.dh import inertia_problem

MOVABLE = {"revolute": JointType.REVOLUTE, "continuous": JointType.REVOLUTE,
           "prismatic": JointType.PRISMATIC}
GRAVITY = np.array([0.0, 0.0, -9.81])

# Numeric attributes we read (element tag -> attribute -> how many numbers), and where they sit.
_NUMBERS = {"origin": {"xyz": 3, "rpy": 3}, "axis": {"xyz": 3}, "mass": {"value": 1},
            "inertia": dict.fromkeys(("ixx", "ixy", "ixz", "iyy", "iyz", "izz"), 1),
            "limit": dict.fromkeys(("lower", "upper", "velocity", "effort"), 1),
            "mimic": dict.fromkeys(("multiplier", "offset"), 1)}
_NUMBER_PATHS = {"link": ("inertial/origin", "inertial/mass", "inertial/inertia"),
                 "joint": ("origin", "axis", "limit", "mimic")}
# yourdfpy would default a missing ixx to 1.0 where urdfdom (and so Pinocchio) refuses: refuse too.
_REQUIRED = {"mass": ("value",), "inertia": tuple(_NUMBERS["inertia"])}


def load_urdf(path, base: str | None = None, tip: str | None = None,
              lock: dict[str, float] | None = None) -> Chain:
    """Read a URDF and return the chain of movable joints from link `base` (default: the root) to link
    `tip` (default: the end of the only movable path). `lock` maps joint names to values at which they are
    frozen (treated as fixed); a locked joint off the chain freezes everything below it too."""
    path = Path(path)
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


# --- reading -----------------------------------------------------------------------------------------

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
    _check_xml(root, path)
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


def _check_xml(root, path: Path) -> None:
    """Check the structure and numbers we rely on, so yourdfpy never crashes on them."""
    if etree.QName(root).localname != "robot" or root.get("name") is None:
        raise located(path, f"line {root.sourceline}", "the root element must be <robot name=\"...\">")
    for kind in ("link", "joint"):
        seen = set()
        for el in root.findall(kind):
            name = _named(el, kind, path)
            if name in seen:
                raise located(path, f"{kind} '{name}'", f"defined twice (again on line {el.sourceline})")
            seen.add(name)
            for sub in _NUMBER_PATHS[kind]:
                for num in el.findall(sub):
                    _check_numbers(num, f"{kind} '{name}'", path)
    for el in root.findall("joint"):
        for tag in ("parent", "child"):
            if el.find(tag) is None or el.find(tag).get("link") is None:
                raise located(path, f"joint '{el.get('name')}'", f"missing <{tag} link=\"...\"/>")


def _named(el, kind: str, path: Path) -> str:
    name = el.get("name")
    if not name:
        raise located(path, f"line {el.sourceline}", f"<{kind}> has no name")
    if kind == "joint" and el.get("type") is None:
        raise located(path, f"joint '{name}'", "has no type")
    return name


def _check_numbers(el, where: str, path: Path) -> None:
    missing = [a for a in _REQUIRED.get(el.tag, ()) if el.get(a) is None]
    if missing:
        raise located(path, where, f"<{el.tag}> lacks {', '.join(missing)}")
    for attr, count in _NUMBERS[el.tag].items():
        raw = el.get(attr)
        if raw is None:
            continue
        try:
            values = [float(v) for v in raw.split()]
        except ValueError:
            values = []
        if len(values) != count or not all(math.isfinite(v) for v in values):
            noun = "a finite number" if count == 1 else f"{count} finite numbers"
            raise located(path, where, f"<{el.tag} {attr}=\"{raw}\">: expected {noun}")


def _read_robot(root, path: Path):
    import yourdfpy  # costs about a second, so only when a URDF is really loaded

    data = etree.tostring(root)  # the root element only: the (already vetted) DOCTYPE stays behind
    try:
        urdf = yourdfpy.URDF.load(io.BytesIO(data), build_scene_graph=False, load_meshes=False,
                                  build_collision_scene_graph=False, load_collision_meshes=False)
    except Exception as exc:  # noqa: BLE001 - on bad input yourdfpy raises anything (KeyError, AttributeError...)
        raise located(path, "", f"yourdfpy cannot read it ({type(exc).__name__}: {_one_line(exc)})") from None
    return urdf.robot


def _one_line(exc: Exception) -> str:
    return " ".join(str(exc).split())


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
            seen = []
            link = start
            while link in self.parent and link not in done:
                if link in seen:
                    loop = [self.parent[x].name for x in seen[seen.index(link):]]
                    raise located(path, f"joint '{loop[0]}'", "closes a loop through joints "
                                  + ", ".join(f"'{n}'" for n in loop) + "; closed loops are not supported")
                seen.append(link)
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

    def ancestors(self, link: str) -> list:
        """Joints from `link` up to its root, nearest first."""
        out = []
        while link in self.parent:
            out.append(self.parent[link])
            link = self.parent[link].parent
        return out

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
        if j.type in MOVABLE and not np.linalg.norm(j.axis) > 1e-9:
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
    above = {a.name for j in free for a in tree.ancestors(j.parent)}
    ends = [_descend(tree, j.child) for j in free if j.name not in above]
    if len(ends) > 1:
        raise located(path, "", f"several movable branches below base link '{base}'; "
                                f"choose --tip from {_names(ends)}")
    return ends[0]


def _descend(tree: _Tree, link: str) -> str:
    """Follow single (fixed) children down, so a tool link bolted on the last link becomes the tip."""
    while len(tree.children[link]) == 1:
        link = tree.children[link][0].child
    return link


def _check_chain(chain: list, base: str, tip: str, path: Path) -> None:
    if not chain:
        raise located(path, "", f"no movable joints between base link '{base}' and tip link '{tip}'")
    for j in chain:
        if j.mimic is not None:
            raise located(path, f"joint '{j.name}'", f"mimics joint '{j.mimic.joint}'; mimic joints are not "
                                                     f"supported (lock it with --lock {j.name}=VALUE)")


def _names(names) -> str:
    return ", ".join(f"'{n}'" for n in names)


# --- rigid bodies ------------------------------------------------------------------------------------

def _bodies(tree: _Tree, base: str, chain: list, route: set, lock: dict, path: Path):
    """Assign every link below `base` to a body 0..n (the chain link it is rigidly attached to) and give its
    pose in that body's reference frame (body 0: the base link; body k: the child link of chain joint k).

    Off-chain joints must be fixed, locked or below a locked off-chain joint (frozen at their lock value
    or 0); any other movable joint branches off the chain and is refused."""
    index = {j.name: k for k, j in enumerate(chain, 1)}
    frames, body_of, stray = {base: np.eye(4)}, {base: 0}, []
    stack = [(base, False)]
    while stack:
        link, frozen = stack.pop()
        for j in tree.children[link]:
            if j.name in index:
                frames[j.child], body_of[j.child] = np.eye(4), index[j.name]
                stack.append((j.child, False))
            elif j.type in MOVABLE and j.name not in lock and not frozen:
                stray.append(j.name)
            else:
                frames[j.child] = frames[link] @ _origin(j) @ _motion(j, lock.get(j.name, 0.0))
                body_of[j.child] = body_of[link]
                stack.append((j.child, frozen or (j.name in lock and j.name not in route)))
    if stray:
        stray.sort(key=list(tree.joints).index)
        more = f" (also {_names(stray[1:])})" if len(stray) > 1 else ""
        raise located(path, "", f"joint '{stray[0]}' branches off the chain; lock it with "
                                f"--lock {stray[0]}=VALUE or choose --tip{more}")
    return frames, body_of


def _build(name: str, tree: _Tree, chain: list, frames: dict, body_of: dict, tip: str, path: Path) -> Chain:
    axes = [_unit(j.axis) for j in chain]
    # g[k] = G_k, the pose of O_k in body k's reference frame.
    g = [frames[j.parent] @ _origin(j) @ _homogeneous(_z_to(a)) for j, a in zip(chain, axes)]
    g.append(frames[tip])
    joints = []
    for k, (j, a) in enumerate(zip(chain, axes), 1):
        r_a = _z_to(a)
        phi = r_a.T @ g[k][:3, :3]
        mass, com, inertia = _body_inertia(tree, k, g[k], frames, body_of, path)
        joints.append(Joint(name=j.name, type=MOVABLE[j.type], phi=phi, p_fixed=phi.T @ r_a.T @ g[k][:3, 3],
                            offset=0.0, mass=mass, com=com, inertia=inertia, limits=_limits(j, path)))
    return Chain(name=name, joints=tuple(joints), gravity=g[0][:3, :3].T @ GRAVITY, source=str(path))


def _body_inertia(tree: _Tree, k: int, g_k: np.ndarray, frames: dict, body_of: dict, path: Path):
    """Mass, centre of mass and inertia about it, in O_k, of every link in body k (parallel axes)."""
    parts = []
    to_o = np.linalg.inv(g_k)
    members = [name for name, b in body_of.items() if b == k]
    for name in members:
        inertial = tree.links[name].inertial
        if inertial is not None:
            mass, inertia = _checked_inertial(inertial, name, path)
            pose = to_o @ frames[name] @ (np.eye(4) if inertial.origin is None else inertial.origin)
            parts.append((mass, pose[:3, 3], pose[:3, :3] @ inertia @ pose[:3, :3].T))
    if not parts:
        raise located(path, f"link '{members[0]}'", f"no <inertial>: the body moved by joint "
                                                     f"'{tree.parent[members[0]].name}' would have no mass")
    return _combine(parts)


def _checked_inertial(inertial, link: str, path: Path):
    if inertial.mass is None or inertial.inertia is None:
        missing = "<mass>" if inertial.mass is None else "<inertia>"
        raise located(path, f"link '{link}'", f"<inertial> has no {missing}")
    if inertial.mass < 0:
        raise located(path, f"link '{link}'", f"negative mass {inertial.mass}")
    problem = inertia_problem(np.asarray(inertial.inertia, dtype=float))
    if problem:
        raise located(path, f"link '{link}'", problem)
    return float(inertial.mass), np.asarray(inertial.inertia, dtype=float)


def _combine(parts: list):
    """Sum rigidly joined (mass, com, inertia about com) triples into one, about the joint centre of mass."""
    total = sum(m for m, _, _ in parts)
    com = sum(m * c for m, c, _ in parts) / total if total > 0 else np.zeros(3)
    inertia = np.zeros((3, 3))
    for m, c, i in parts:
        d = c - com
        inertia += i + m * (d @ d * np.eye(3) - np.outer(d, d))
    return float(total), com, inertia


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


# --- small rigid-body algebra ------------------------------------------------------------------------

def _origin(j) -> np.ndarray:
    return np.eye(4) if j.origin is None else np.asarray(j.origin, dtype=float)


def _motion(j, q: float) -> np.ndarray:
    """The joint's own motion at position q (identity for a fixed joint)."""
    out = np.eye(4)
    if j.type in ("revolute", "continuous"):
        out[:3, :3] = _axis_rotation(_unit(j.axis), q)
    elif j.type == "prismatic":
        out[:3, 3] = q * _unit(j.axis)
    return out


def _unit(v) -> np.ndarray:
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v)


def _skew(v: np.ndarray) -> np.ndarray:
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def _axis_rotation(axis: np.ndarray, angle: float) -> np.ndarray:
    """Rodrigues: rotation by `angle` about the unit vector `axis`."""
    k = _skew(axis)
    return np.eye(3) + math.sin(angle) * k + (1.0 - math.cos(angle)) * (k @ k)


def _z_to(a: np.ndarray) -> np.ndarray:
    """A rotation R with R e_z = a (the shortest one; a half turn about x when a = -e_z)."""
    v = np.cross(E_Z, a)
    s, c = np.linalg.norm(v), float(a[2])
    if s < 1e-12:
        return np.eye(3) if c > 0 else np.diag([1.0, -1.0, -1.0])
    return _axis_rotation(v / s, math.atan2(s, c))


def _homogeneous(rotation: np.ndarray) -> np.ndarray:
    out = np.eye(4)
    out[:3, :3] = rotation
    return out
