"""MJCF (MuJoCo) → Chain: a MuJoCo model read by MuJoCo's own compiler, then built like a URDF.

The `mujoco` package (the `mjcf` extra: `pip install "vampc[mjcf]"`, imported only here) compiles the
file: includes, defaults, angle units, euler conventions, frames and inertias inferred from geoms are
MuJoCo's reading, not ours. From the compiled model vampc takes, per body, its pose in its parent
(body_pos, body_quat), its mass, centre of mass and principal inertia (body_ipos, body_iquat,
body_inertia), and its joints (type, pos, axis, range), and the gravity (opt.gravity, in the world
frame). These become links and joints of the shape yourdfpy gives for a URDF, and the URDF loader's
tree building (vampc.robot.urdf.chain_of) makes the Chain, so frames, merged fixed bodies and trees are
computed by one code.

MuJoCo moves a body with joints j_1..j_k (at pos c_i, axis a_i, in the body frame) by
T(c_1) M_1(q_1) T(-c_1) ⋯ T(c_k) M_k(q_k) T(-c_k) after its pose X in the parent. Link joint j_1's
origin is X T(c_1), j_i's (i > 1) T(c_i - c_{i-1}) in a massless link between them, and the body's own
link sits at T(c_k) from the body frame: its inertial and its children's poses are shifted by
T(-c_k). A free joint on a body the world carries makes it the floating base (its pose in the world is
then the base's motion, the host's input); gravity is MuJoCo's, in the world frame, with the base at
the world's orientation for a floating base, and turned into the base body's frame for a fixed
`--base` (`_in_base`). Bodies welded to their parent (no joint) merge into it.
Children are numbered in file order, as Pinocchio's MJCF reader numbers them.

A joint's q is MuJoCo's qpos: a joint with a reference position `ref` (the file's pose is at qpos =
ref) gets the offset -ref (vampc.robot.chain: A = Rz(q + offset) Φ). Refused, one line each naming the
joint or element: ball joints, free joints below the root, tendons that exert forces, equality
constraints other than joint equalities of degree 1, and what MuJoCo itself refuses (an unreadable
`<include>`, a bad attribute: its message, with the file).
Ignored with a warning: joint armature, damping, friction loss and springs, bodies' gravity
compensation (gravcomp) and fluid forces (not rigid-body inverse dynamics: MuJoCo's mj_inverse includes
them, Pinocchio's MJCF reader the armature). Gravity disabled by `<flag gravity="disable"/>` is zero.
"""
from __future__ import annotations

import threading
import warnings
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from vampc.errors import VampcError, VampcWarning, located
from vampc.gcpause import gc_paused
from vampc.robot.chain import matmul, matvec

FREE, BALL, SLIDE, HINGE = 0, 1, 2, 3
KINDS = {SLIDE: "prismatic", HINGE: "revolute"}


@dataclass
class _Inertial:
    mass: float
    inertia: np.ndarray
    origin: np.ndarray


@dataclass
class _Link:
    name: str
    inertial: _Inertial | None


@dataclass
class _Limit:
    lower: float | None
    upper: float | None
    velocity: float | None = None
    effort: float | None = None


@dataclass
class _Joint:
    name: str
    type: str
    parent: str
    child: str
    origin: np.ndarray
    axis: np.ndarray
    limit: _Limit | None = None
    mimic: object = None
    offset: float = 0.0           # -ref: the motion from the file's pose is qpos - ref
    named: bool = True            # the file names it (not a weld or origin joint made here, nor an
    #                               unnamed joint's "jointK"): a limits file can name it


@dataclass
class _Robot:
    name: str
    links: list
    joints: list
    bodies: tuple = ()        # each MuJoCo body's link name, by body id (named or made up)
    joint_names: tuple = ()   # each MuJoCo joint's name, by joint id (named or made up)
    loops: tuple = ()         # connect and weld equalities: (where, kind, body1 id, body2 id)


def is_mjcf(path) -> bool:
    """An XML file whose root element is <mujoco> (only its first start tag is parsed; entities are
    neither loaded nor resolved). False for anything else, unreadable or not XML: the URDF loader then
    says what is wrong."""
    from lxml import etree
    if not Path(path).is_file():             # (a FIFO would block it; the loaders say what it is)
        return False
    try:
        with open(path, "rb") as stream:     # (closed: iterparse left its file open when left early)
            for _, element in etree.iterparse(stream, events=("start",), resolve_entities=False,
                                              no_network=True, load_dtd=False):
                return etree.QName(element).localname == "mujoco"
    except (etree.XMLSyntaxError, OSError, ValueError):
        return False
    return False


# Elements whose files MuJoCo reads (their attributes), and the <compiler> folder each is found in
# (assetdir the fallback; an <include> from the including file's folder)
_FILE_ATTRIBUTES = {
    "include": (("file",), None), "mesh": (("file",), "meshdir"), "skin": (("file",), "meshdir"),
    "hfield": (("file",), "texturedir"), "flexcomp": (("file",), "meshdir"),
    "model": (("file",), None),
    "texture": (("file", "fileright", "fileleft", "fileup", "filedown", "filefront", "fileback"),
                "texturedir")}


def _model_files(path) -> Iterator[tuple[Path, object]]:
    """Each XML file of the MJCF model `path` with its parsed root: the model, then its
    <include>s, each found where MuJoCo finds it (the model's folder, else the including file's;
    an include of an include had been looked for in the model's folder only, a review's find, and
    then in the including file's first, where MuJoCo 4 reads the model folder's: another's).
    Entities are neither loaded nor resolved; a file that cannot be read or parsed is skipped
    (MuJoCo's own load says what is wrong with it)."""
    main = Path(path).parent
    todo, seen = [Path(path)], set()
    while todo:
        here = todo.pop(0)
        if here.resolve() in seen:            # (a file included twice, or itself: read once)
            continue
        seen.add(here.resolve())
        root = _xml_root(here)
        if root is None:
            continue
        yield here, root
        for element in root.iter("{*}include", "include"):
            if element.get("file"):
                todo.append(_found(element.get("file"), main, here.parent))


def _xml_root(here: Path):
    """The parsed root of an MJCF file, entities neither loaded nor resolved; None where it cannot
    be read or parsed (MuJoCo's own load says what is wrong with it)."""
    from lxml import etree
    parser = etree.XMLParser(resolve_entities=False, no_network=True, load_dtd=False, huge_tree=False)
    try:
        return etree.parse(str(here), parser).getroot()
    except (etree.XMLSyntaxError, OSError, ValueError):
        return None


def _in_reading_order(path) -> Iterator[tuple[Path, object]]:
    """Every element of the MJCF model `path` with its file, in the order MuJoCo reads them: each
    <include> replaced where it stands by its file's elements (found as _model_files finds it; a
    file within its own includes is not read again)."""
    from lxml import etree
    main = Path(path).parent

    def walk(here: Path, within: frozenset):
        root = _xml_root(here)
        if root is None:
            return
        for element in root.iter():
            if not isinstance(element.tag, str):
                continue
            yield here, element
            if etree.QName(element).localname == "include" and element.get("file"):
                found = _found(element.get("file"), main, here.parent)
                if found.resolve() not in within:
                    yield from walk(found, within | {found.resolve()})
    yield from walk(Path(path), frozenset({Path(path).resolve()}))


def _found(name: str, *folders: Path) -> Path:
    """`name` in the first of `folders` that has it (the first if none does)."""
    return next((f / name for f in folders if (f / name).exists()), folders[0] / name)


def files_read(path) -> list[Path]:
    """The other files MuJoCo reads for the MJCF model `path` ([] for anything else): its
    <include>s and the meshes, skins, textures, height fields and models they name, each in every
    folder MuJoCo may look in (from <compiler meshdir|texturedir|assetdir>, under the model's folder
    and the naming file's). An output was written over an included file, exit 0 (a file-safety
    audit): these are inputs like the model."""
    if not is_mjcf(path):
        return []
    from lxml import etree
    main = Path(path).parent
    files, dirs = [], {}
    for here, root in _model_files(path):
        for element in root.iter():
            if not isinstance(element.tag, str):
                continue
            tag = etree.QName(element).localname
            if tag == "compiler":
                dirs.update({k: v for k in ("meshdir", "texturedir", "assetdir")
                             if (v := element.get(k))})
            elif tag in _FILE_ATTRIBUTES:
                names, where = _FILE_ATTRIBUTES[tag]
                files += [(here.parent, where, element.get(a)) for a in names if element.get(a)]
    out = []
    for folder, where, name in files:
        sub = dirs.get(where, dirs.get("assetdir", "")) if where else ""
        out += [main / sub / name, folder / sub / name, folder / name, main / name]
    return list(dict.fromkeys(out))


def load_mjcf(path, base: str | None = None, tip: str | None = None,
              lock: dict[str, float] | None = None, floating: bool = False,
              accept_improper_inertia: bool = False, mimic: str = "ordinary",
              mimic_given: bool = False) -> object:
    """Read an MJCF file as a Chain (see the module docstring); base, tip, lock, floating and mimic
    as vampc.robot.urdf.load_urdf takes them (links are MuJoCo's bodies; joint equalities are its
    mimic joints)."""
    path = Path(path)
    model, heard = _compiled(path)
    # the warnings of reading the model and making the robot are said once it is made: an error,
    # a loop's refusal among them, comes alone (a Menagerie trial's: "joint armature ... ignored"
    # and a scene's cube "left out" came before the error that ended the run)
    with gc_paused(), warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        chain = _load(model, path, base, tip, lock, floating, accept_improper_inertia, mimic,
                      mimic_given)
    for w in caught:
        warnings.warn(w.message, w.category, stacklevel=2)
    for message in heard:
        warnings.warn(VampcWarning(f"{path}: MuJoCo warns: {message}"), stacklevel=2)
    return chain


def _load(model, path: Path, base, tip, lock, floating, accept_improper_inertia, mimic, mimic_given):
    """load_mjcf's robot of the compiled `model` (its warnings as they come)."""
    from vampc.robot.urdf import chain_of
    from vampc.robot.urdf_tree import Tree
    robot, gravity, held = _robot(model, path, base)
    lock = dict(lock or {})
    for name, value in held.items():
        if mimic == "ordinary":
            warnings.warn(VampcWarning(f"{path}: an equality holds joint '{name}' at {value:g}: taken "
                                       "as an ordinary joint; --mimic couple locks it there"), stacklevel=2)
        elif name in lock and lock[name] != value:
            raise located(path, f"lock {name}", f"an equality holds joint '{name}' at {value!r} "
                                                "(--mimic couple)")
        else:
            lock[name] = value
    turned, placed = None, False
    if base is not None and not floating:
        gravity, turned, placed = _in_base(model, robot, base, gravity, lock, path, mimic == "couple")
    tree = Tree.build(robot, path, gravity=gravity, by_name=False, gravity_in=base, limits_required=False)
    chain = chain_of(robot, tree, path, base, tip, lock, floating, mimic,
                     accept_improper_inertia=accept_improper_inertia,
                     # (an equality holding a joint is --mimic couple's doing too: it warned
                     # "no joint has a <mimic>" of a model whose equality it had just locked)
                     # (nor of one whose follower above the base it placed, turning gravity)
                     mimic_said=None if held or placed else "joint equality (<equality><joint>)",
                     mimic_given=mimic_given,
                     turn_said="the turn of its body (quat, euler, axisangle, xyaxes or zaxis)",
                     turned=turned)      # (said once the robot is made: an error comes alone)
    _loops(model, robot, chain, path, base)
    return chain


def _in_base(model, robot, base: str, gravity, lock: dict, path: Path, couple: bool = False):
    """MuJoCo's gravity (world frame) in the frame of the body `base` names, where --base fixes the
    robot: the chain's gravity is its base's (a base tilted by a weld in the world read the world's
    vector as its own: wrong torques that --check, on the same model, could not see). The body's
    orientation is its pose with the joints above it, which --base cuts away, at their --lock
    values (`lock`), a joint equality's follower (`couple`: --mimic couple) where its leader puts
    it, else at the model's reference positions (qpos0); and the warning that says so (None when
    no joint is above it), and whether a follower was placed off 0 so. A follower above whose leader
    is below is refused, as for a URDF."""
    import mujoco
    named = _named_body(model, robot, base)
    if named is None or named[0] == 0:    # (the world, or no link: chain_of says so of an unknown --base)
        return gravity, None, False
    b, last = named
    data = mujoco.MjData(model)
    moved, above = [], b           # (the body's own joints, to its parent, are cut away too)
    while above > 0:
        first, count = int(model.body_jntadr[above]), int(model.body_jntnum[above])
        if above == b and last is not None:
            count = last - first + 1          # (its joints after JOINT stay: they are below the base)
        moved = list(range(first, first + count)) + moved     # (root first)
        above = int(model.body_parentid[above])
    mimics = {jt.name: jt.mimic for jt in robot.joints if jt.mimic is not None} if couple else {}
    said, placed = [], False
    causes = {}
    for j in moved:
        name, at, free = robot.joint_names[j], int(model.jnt_qposadr[j]), int(model.jnt_type[j]) == FREE
        if free:
            if int(model.jnt_bodyid[j]) != b:      # (the base's own: choose_base says so)
                said.append(f"{name} (free) at qpos0")
            continue
        follows = mimics.get(name)
        causes[name] = "lock" if name in lock else "leader" if follows else "default"
        if name in lock:
            data.qpos[at] = lock[name]
        elif follows:
            leader = robot.joint_names.index(follows.joint)
            if leader not in moved and follows.joint not in lock:
                from vampc.robot.urdf_tree import follows_from_below
                raise follows_from_below(path, name, base, follows.joint)
            value = lock.get(follows.joint, float(data.qpos[int(model.jnt_qposadr[leader])]))
            data.qpos[at] = follows.offset + follows.multiplier * value
            placed = placed or data.qpos[at] != 0
        q = float(data.qpos[at])
        lo, hi = (float(x) for x in model.jnt_range[j])
        outside = bool(model.jnt_limited[j]) and not lo <= q <= hi
        said.append(f"{name} at {q:.6g}" + (f", outside its range [{lo:.6g}, {hi:.6g}]" if outside
                                            else ""))
    mujoco.mj_kinematics(model, data)                     # (qpos starts at qpos0)
    # body frame -> world; for BODY__JOINT, the body's joints after JOINT are at qpos0, where they
    # turn nothing: the body's frame is then the link's
    rotation = np.asarray(data.xmat[b], dtype=float).reshape(3, 3)
    turned = tuple(float(g) for g in matvec(rotation.T, gravity))
    if not said:
        return turned, None, placed
    from vampc.robot.urdf_tree import cut_away, placed_by
    how = placed_by(causes, "a coupled equality's leader", "at their reference positions, qpos0",
                    "at qpos0") if causes else "at qpos0"
    return turned, cut_away(path, base, said, how), placed


def _compiled(path: Path):
    try:
        import mujoco
    except ImportError:
        raise VampcError(f"{path}: an MJCF (MuJoCo) model needs the mujoco package: "
                         "pip install \"vampc[mjcf]\"") from None
    if not path.is_file():
        raise located(path, "", "no such file" if not path.exists() else "not a regular file")
    # MuJoCo's own warnings printed two lines of their own on stderr ahead of vampc's and wrote
    # MUJOCO_LOG.TXT into the folder (a new user's find): taken here, said once the robot is made
    heard: list[str] = []
    _finite_attributes(path)      # (before the handler is taken: its error had left it taken)
    with _HANDLER:                # (the handler is the process's: one model compiles at a time)
        previous = getattr(mujoco, "get_mju_user_warning", lambda: None)()
        hear = getattr(mujoco, "set_mju_user_warning", None)
        if hear is not None:
            hear(lambda message: heard.append(" ".join(str(message).split())))
        try:
            model = mujoco.MjModel.from_xml_path(str(path))
            _finite_model(model, path)
            return model, list(dict.fromkeys(heard))
        except ValueError as exc:            # MuJoCo's parser and compiler errors
            said = " ".join(str(exc).split())
            raise (_in_included_file(path, said)
                   or located(path, "", f"MuJoCo cannot read it ({said})")) from None
        finally:
            if hear is not None:
                hear(previous)


_HANDLER = threading.Lock()


def _in_included_file(path: Path, said: str):
    """MuJoCo's error `said` placed in the included file and line it is about, or None: MuJoCo gives
    "line 0" for an element of an included file (an error in a robot's file, compiled through its
    scene.xml, was said of scene.xml, line 0: a Menagerie trial's find). The element is found by what
    the message names: its tag and an unrecognized attribute it has, or the name it repeats; an
    unrecognized element by its tag. Where no one element of the included files fits, the message
    names the files it may be in."""
    import re

    from lxml import etree
    m = (re.search(r"Element '(?P<tag>[^']+)', line 0\b", said)            # the parser's
         or re.search(r"Element name '(?P<name>[^']*)', id \d+, line 0\b", said))  # the compiler's
    if m is None:
        return None
    model = Path(path).resolve()
    included = [(here, e) for here, e in _in_reading_order(path) if here.resolve() != model]
    if not included:
        return None
    tag, name = m.groupdict().get("tag"), m.groupdict().get("name")
    attribute = re.search(r"unrecognized attribute: '([^']+)'", said)
    repeated = re.search(r"repeated name '([^']*)'", said)
    if name is None and repeated:
        name = repeated.group(1)
    if tag and not (attribute or name is not None or "unrecognized element" in said):
        fits = []
    else:
        fits = [(here, e) for here, e in included
                if (tag is None or etree.QName(e).localname == tag)
                and (attribute is None or e.get(attribute.group(1)) is not None)
                and (name is None or e.get("name") == name)]
    if repeated and fits:
        fits = fits[-1:]        # (the later one is the repeat, in the order MuJoCo reads)
    if len(fits) == 1:
        here, element = fits[0]
        given = element.get("name")
        message = said[:m.start()] + m.group(0)[:-len(", line 0")]
        return located(here, f"line {element.sourceline}: <{etree.QName(element).localname}"
                       + (f" name='{given}'" if given else "") + ">",
                       f"MuJoCo cannot read {path} ({message})")
    names = ", ".join(dict.fromkeys(str(here) for here, _ in included))
    return located(path, "", f"MuJoCo cannot read it ({said}; MuJoCo gives line 0 for an element of "
                   f"a file it includes: {names})")

# attributes that hold names, not numbers ('inf' or 'nan' may name a body)
NAME_ATTRIBUTES = frozenset("name class childclass joint joint1 joint2 body body1 body2 site site1 site2 "
                            "geom geom1 geom2 mesh material texture hfield target tendon actuator "
                            "objname refname prefix file key model".split())


def _finite_attributes(path: Path) -> None:
    """Refuse a number of the file, or of a file it includes (found as MuJoCo finds it:
    _model_files), that is not finite (nan, inf, 1e400), naming its file, element and attribute:
    MuJoCo reads NaN as 0, saying only "XML contains a 'NaN'" (an inertial pos of nan gave the
    torques of 0), and an inf gravity or pose, or a nan range or ref, ended vampc in a traceback,
    exit 3 (a hostile-input audit's finds). A file that is not XML, or cannot be read, is left to
    MuJoCo, which says so."""
    import math

    from lxml import etree
    for here, root in _model_files(path):
        for element in root.iter():
            if not isinstance(element.tag, str):             # (comments, processing instructions)
                continue
            for attribute, value in element.attrib.items():
                if attribute in NAME_ATTRIBUTES:
                    continue
                for token in value.split():
                    try:
                        number = float(token)
                    except ValueError:
                        continue
                    if not math.isfinite(number):
                        name = element.get("name")
                        tag = etree.QName(element).localname
                        raise located(here, f"line {element.sourceline}: <{tag}"
                                      + (f" name='{name}'" if name else "") + f"> {attribute}",
                                      f"'{token}' is not a finite number")


def _finite_model(model, path: Path) -> None:
    """Refuse a compiled model whose poses, inertias, joints or gravity are not finite numbers,
    though the file's are (a geom of mass 1e308, whose inertia overflows; a body quat of 1e308 0 0
    1, which MuJoCo normalizes to 0 0 0 0), naming the body or joint."""
    arrays = (("body", ("body_pos", "body_quat", "body_ipos", "body_iquat", "body_mass", "body_inertia"),
               model.nbody),
              ("joint", ("jnt_pos", "jnt_axis", "jnt_range"), model.njnt))
    for kind, fields, n in arrays:
        if not n:        # (no joint: numpy's reshape error had been said as MuJoCo's, an audit's)
            continue
        for name in fields:
            bad = ~np.isfinite(np.asarray(getattr(model, name), dtype=float).reshape(n, -1)).all(1)
            if bad.any():
                k = int(np.flatnonzero(bad)[0])
                given = (model.body(k) if kind == "body" else model.joint(k)).name
                raise located(path, _element(kind, given, k - 1 if kind == "body" else k),
                              f"its {name.split('_', 1)[1]} is not finite once MuJoCo compiled it")
    for name in ("body_quat", "body_iquat"):      # (1e308 0 0 1: MuJoCo's normalizing gives 0 0 0 0)
        norms = np.linalg.norm(np.asarray(getattr(model, name), dtype=float).reshape(model.nbody, 4), axis=1)
        bad = np.flatnonzero(~(np.abs(norms - 1.0) <= 1e-6))
        if bad.size:
            k = int(bad[0])
            raise located(path, _element("body", model.body(k).name, k - 1),
                          f"its {name.split('_', 1)[1]} is not a rotation once MuJoCo compiled it "
                          f"(norm {norms[k]:.6g}: a quaternion too large or too small to normalize?)")
    axes = np.linalg.norm(np.asarray(model.jnt_axis, dtype=float).reshape(model.njnt, 3), axis=1)
    for j in range(model.njnt):
        if int(model.jnt_type[j]) in (2, 3) and not abs(axes[j] - 1.0) <= 1e-6:   # slide, hinge
            # (1e200 1e200 0: MuJoCo's normalizing gives 0 0 0, which was said as "axis is zero")
            raise located(path, _element("joint", model.joint(j).name, j),
                          f"its axis is not a direction once MuJoCo compiled it (length "
                          f"{axes[j]:.6g}: an axis too large or too small to normalize?)")
        at = int(model.jnt_qposadr[j])
        if not np.isfinite(model.qpos0[at]):
            raise located(path, _element("joint", model.joint(j).name, j),
                          "its ref is not finite once MuJoCo compiled it")
    if not np.isfinite(model.opt.gravity).all():
        raise located(path, "option gravity", "not finite once MuJoCo compiled it")


def _robot(model, path: Path, base: str | None = None):
    """Links and joints of the compiled model, and the gravity."""
    import mujoco
    links_taken, joints_taken = _Names(model.body(b).name for b in range(model.nbody)), \
        _Names(model.joint(j).name for j in range(model.njnt))
    body_name = [model.body(b).name or links_taken.new(f"body{b}") for b in range(model.nbody)]
    joint_name = [model.joint(j).name or joints_taken.new(f"joint{j}") for j in range(model.njnt)]
    _refuse(model, path, joint_name, mujoco)
    static = _static_beside_free(model, path, body_name, base)
    links = [_Link(body_name[0], None)]
    joints = []
    shift = {0: np.eye(4)}          # each body's own link frame from the body frame: T(-c_k)
    for b in range(1, model.nbody):
        parent = int(model.body_parentid[b])
        if b in static:
            continue
        # the body in its parent's link
        x = matmul(shift[parent], _pose(model.body_pos[b], model.body_quat[b]))
        first, count = int(model.body_jntadr[b]), int(model.body_jntnum[b])
        kinds = [int(model.jnt_type[j]) for j in range(first, first + count)]
        inertial = _inertial(model, b)
        if count == 0:
            joints.append(_Joint(joints_taken.new(f"{body_name[b]}_weld"), "fixed", body_name[parent], body_name[b], x,
                                 np.array([0.0, 0.0, 1.0]), named=False))
            shift[b] = np.eye(4)
        elif kinds == [FREE]:
            if parent != 0:
                raise located(path, _named(model, "joint", first, joint_name), "a free joint is the floating base; "
                                                                   "only a body the world carries may have one")
            joints.append(_Joint(joint_name[first], "floating", body_name[parent], body_name[b], x,
                                 np.array([0.0, 0.0, 1.0]), named=bool(model.joint(first).name)))
            shift[b] = np.eye(4)
        else:
            # --base BODY: BODY's link frame is its body frame, its origin the body's (the joints
            # above it, which --base cuts away, end in a link at the last one's anchor, fixed to it);
            # it had been the last joint's anchor, where a floating base's motion was then read
            anchored = body_name[b] == base
            at, previous, link = x, np.zeros(3), body_name[parent]
            for i, j in enumerate(range(first, first + count)):
                c = np.array(model.jnt_pos[j], dtype=float)
                inner = i < count - 1 or anchored
                child = links_taken.new(f"{body_name[b]}__{joint_name[j]}") if inner else body_name[b]
                if inner:
                    links.append(_Link(child, None))
                kind = KINDS[int(model.jnt_type[j])]
                if kind == "revolute" and not model.jnt_limited[j]:
                    kind = "continuous"
                joints.append(_Joint(joint_name[j], kind, link, child,
                                     matmul(at, _translation(c - previous)),
                                     np.array(model.jnt_axis[j], dtype=float),
                                     _limit(model, j), offset=-float(model.qpos0[model.jnt_qposadr[j]]),
                                     named=bool(model.joint(j).name)))
                at, previous, link = np.eye(4), c, child
            if anchored:
                joints.append(_Joint(joints_taken.new(f"{body_name[b]}_origin"), "fixed", link, body_name[b],
                                     _translation(-previous), np.array([0.0, 0.0, 1.0]), named=False))
                previous = np.zeros(3)
            shift[b] = _translation(-previous)
        if inertial is not None:
            inertial.origin = matmul(shift[b], inertial.origin)
        links.append(_Link(body_name[b], inertial))
    name = model.names[:model.names.index(b"\0")].decode() if model.names else ""
    if name in ("", "MuJoCo Model"):       # MuJoCo's name for a <mujoco> without model="..."
        warnings.warn(VampcWarning(f"{path}: <mujoco> has no model name; calling it {path.stem!r}"),
                      stacklevel=3)
        name = path.stem
    held, loops = _equalities(model, path, joints, joint_name)
    gravity = (0.0, 0.0, 0.0) if _gravity_off(model) else tuple(float(g) for g in model.opt.gravity)
    return _Robot(name, links, joints, tuple(body_name), tuple(joint_name), tuple(loops)), gravity, held


class _Names:
    """Names given in the file, and fresh ones for what it leaves unnamed (never one it uses)."""

    def __init__(self, given):
        self.taken = {n for n in given if n}

    def new(self, wanted: str) -> str:
        name, k = wanted, 1
        while name in self.taken:
            k += 1
            name = f"{wanted}~{k}"
        self.taken.add(name)
        return name


def _static_beside_free(model, path: Path, body_name: list, base: str | None) -> set:
    """Bodies to leave out: when the world carries one body on a free joint (the floating base) and
    other subtrees without any joint (a table, a floor: they move with nothing the network computes),
    those subtrees; with --base world, the subtrees on free joints beside bodies hinged to the world
    (a cube beside a fixed arm: it floats apart from the robot). Otherwise two free bodies, or a
    free body beside a jointed one, are refused: one robot."""
    children = [b for b in range(1, model.nbody) if int(model.body_parentid[b]) == 0]
    free = [b for b in children if int(model.body_jntnum[b]) and int(model.jnt_type[model.body_jntadr[b]]) == FREE]
    if not free or len(children) == 1:
        return set()
    root = np.array([int(model.body_rootid[b]) for b in range(model.nbody)])
    moving = [b for b in children if b not in free and np.any(model.body_jntnum[root == b])]
    world = body_name[0]
    if base == world and moving:
        names = ", ".join(repr(body_name[b]) for b in free)
        warnings.warn(VampcWarning(
            f"{path}: --base {world}: {names} on {'a free joint' if len(free) == 1 else 'free joints'} "
            f"float{'s' if len(free) == 1 else ''} apart from the bodies hinged to the world and "
            f"{'is' if len(free) == 1 else 'are'} left out"), stacklevel=4)
        return {b for b in range(1, model.nbody) if root[b] in free}
    if base is not None:
        # (another free body beside the base's: a scene's cube, left out as --base world leaves it
        # out, but unsaid: a Menagerie trial's find)
        owner = base if base in body_name else base.rsplit("__", 1)[0]     # (BODY__JOINT: BODY's)
        b = body_name.index(owner) if owner in body_name else None
        apart = [f for f in free if b is not None and root[b] != f]
        if apart:
            names = ", ".join(repr(body_name[f]) for f in apart)
            warnings.warn(VampcWarning(
                f"{path}: --base {base}: {names} on {'a free joint' if len(apart) == 1 else 'free joints'} "
                f"float{'s' if len(apart) == 1 else ''} apart from the robot below it and "
                f"{'is' if len(apart) == 1 else 'are'} left out"), stacklevel=4)
        return set()
    if len(free) > 1 or moving:
        others = [body_name[b] for b in free[1:] + moving]
        # the advice names only what --base can take whole: the world, for bodies hinged to it (a
        # body on a hinge to the world as --base cuts that hinge away: a new user's arm lost its
        # first joint so), and a free body with joints below its own
        below = [b for b in free if any(model.body_jntnum[d] for d in range(1, model.nbody)
                                        if root[d] == b and d != b)]
        ways = ([f"--base {world} for {', '.join(repr(body_name[b]) for b in moving)} on a fixed base, "
                 f"the free {'body' if len(free) == 1 else 'bodies'} left out"] if moving else []) \
            + [f"--base {body_name[b]} --floating-base" for b in below]
        how = ("choose one with " + " or ".join(ways) if ways
               else "none has joints below its own for --base to keep: give each its own file")
        raise located(path, _named(model, "body", free[0], body_name), f"has a free joint (a floating base) but the "
                      f"world also carries {', '.join(repr(n) for n in others)} with joints of its own: "
                      f"one robot per file ({how})")
    return {b for b in range(1, model.nbody) if root[b] in children and root[b] not in free}


def _refuse(model, path: Path, joint_name: list, mujoco) -> None:
    """What vampc does not model: ball joints, free joints but alone on a body, tendons that exert
    forces; and a warning for what rigid-body inverse dynamics leaves out."""
    for j in range(model.njnt):
        if int(model.jnt_type[j]) == BALL:
            raise located(path, _named(model, "joint", j, joint_name), "ball joints are not supported (one degree "
                                                            "of freedom per joint: use three hinges)")
        if int(model.jnt_type[j]) == FREE and int(model.body_jntnum[model.jnt_bodyid[j]]) > 1:
            raise located(path, _named(model, "joint", j, joint_name), "a free joint must be its body's only joint")
    _tendons(model, path)
    _flexes(model, path)
    # (MuJoCo 4 takes several values in damping="..." and stiffness="...": the terms past the first
    # are in the *poly arrays; a joint with damping="0 2" was left out, saying nothing)
    extras = [what for what, values in (
        ("armature", [model.dof_armature]),
        ("damping", [model.dof_damping, _field(model, "dof_dampingpoly")]),
        ("frictionloss", [model.dof_frictionloss]),
        ("stiffness", [model.jnt_stiffness, _field(model, "jnt_stiffnesspoly")])) if _any(values)]
    moved = [what for what, values in (         # (an actuator's are its joint's: gear² times them)
        ("armature", [_field(model, "actuator_armature")]),
        ("damping", [_field(model, "actuator_damping"), _field(model, "actuator_dampingpoly")]))
        if _any(values)]
    passive = [what for what, there in (
        ("body gravcomp (gravity compensation)", np.any(model.body_gravcomp) and not _gravity_off(model)),
        ("fluid forces (<option> density, viscosity)", model.opt.density > 0 or model.opt.viscosity > 0))
        if there]
    if extras or moved or passive:
        said = ([f"joint {', '.join(extras)}"] if extras else []) + \
            ([f"actuator {', '.join(moved)}"] if moved else []) + passive
        warnings.warn(VampcWarning(
            f"{path}: {'; '.join(said)} ignored: vampc's torques are the rigid bodies' inverse dynamics "
            "alone (MuJoCo's mj_inverse includes armature·q̈ and the passive forces, Pinocchio's MJCF "
            "reader armature·q̈)"), stacklevel=4)


def _field(model, name: str):
    """An array of the model's that older MuJoCo versions lack (None then)."""
    return getattr(model, name, None)


def _any(values) -> bool:
    return any(v is not None and np.any(v) for v in values)


def _flexes(model, path: Path) -> None:
    """A flex (<flex>, <flexcomp>: a deformable) is refused: its vertices are bodies on slide joints
    whose elastic forces couple them, which rigid-body inverse dynamics leaves out (a rope of three
    vertices was taken as six independent joints, 345 N where mj_inverse's rope pulled)."""
    import mujoco
    if int(getattr(model, "nflex", 0)):
        name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_FLEX, 0) or ""
        raise located(path, _element("flex", name), "deformable (flex) objects are not supported "
                                                    "(the network computes rigid bodies in an open tree)")


def _rows(model, name: str, k: int) -> list:
    """Row k of an array older MuJoCo versions lack (none then)."""
    values = _field(model, name)
    return [] if values is None else [values[k]]


def _gravity_off(model) -> bool:
    """Whether `<flag gravity="disable"/>` turns MuJoCo's gravity off (and so gravity compensation)."""
    import mujoco
    return bool(model.opt.disableflags & mujoco.mjtDisableBit.mjDSBL_GRAVITY)


def _tendons(model, path: Path) -> None:
    """A tendon that exerts no force (no stiffness, damping, friction, armature or limit: one only an
    actuator pulls, and actuators are not read) is left out, with a warning; any other is refused."""
    inert = []
    for t in range(model.ntendon):
        forces = [what for what, value in (
            ("stiffness", [model.tendon_stiffness[t]] + _rows(model, "tendon_stiffnesspoly", t)),
            ("damping", [model.tendon_damping[t]] + _rows(model, "tendon_dampingpoly", t)),
            ("frictionloss", [model.tendon_frictionloss[t]]), ("armature", [model.tendon_armature[t]]),
            ("a limit", [model.tendon_limited[t]])) if _any(value)]
        if forces:
            raise located(path, _element("tendon", model.tendon(t).name, t),
                          f"has {', '.join(forces)}: tendons that exert forces are not supported (the "
                          "network computes an open tree)")
        inert.append(model.tendon(t).name or f"#{t}")
    if inert:
        warnings.warn(VampcWarning(f"{path}: tendon {', '.join(repr(n) for n in inert)} left out: it exerts "
                                   "no force (no stiffness, damping, friction, armature or limit; "
                                   "actuators are not read)"), stacklevel=5)


class _Mimic:
    """A joint equality read as a URDF <mimic>: q_joint1 = offset + multiplier · q_joint2."""

    def __init__(self, joint: str, multiplier: float, offset: float):
        self.joint, self.multiplier, self.offset = joint, multiplier, offset


def _equalities(model, path: Path, joints: list, joint_name: list) -> dict:
    """Joint equalities (joint1 = c0 + c1 · joint2) become mimic couplings of joint1 (read as
    `--mimic` says: ordinary joints by default, coupled with --mimic couple); a joint held at c0
    (no joint2) is returned, joint name -> c0, to be locked there under --mimic couple. Inactive
    equalities are left out; other kinds, and polynomials beyond degree 1, are refused."""
    import mujoco
    by_name = {j.name: j for j in joints}
    held, inactive, loops = {}, [], []
    for e in range(model.neq):
        where = _element("equality", model.equality(e).name, e)
        if not model.eq_active0[e]:
            inactive.append(_element("equality", model.equality(e).name, e))   # (it said '#0')
            continue
        kind = int(model.eq_type[e])
        if kind in (int(mujoco.mjtEq.mjEQ_CONNECT), int(mujoco.mjtEq.mjEQ_WELD)):
            # (a loop: refused once the robot is made unless no joint of it moves, _loops)
            ends = [int(model.eq_obj1id[e]), max(0, int(model.eq_obj2id[e]))]
            if int(model.eq_objtype[e]) == int(mujoco.mjtObj.mjOBJ_SITE):
                ends = [int(model.site_bodyid[k]) for k in ends]
            loops.append((where, mujoco.mjtEq(kind).name[5:].lower(), *ends))
            continue
        if kind != int(mujoco.mjtEq.mjEQ_JOINT):
            raise located(path, where, f"{mujoco.mjtEq(kind).name[5:].lower()} equality constraints are not "
                                       "supported (the network computes an open tree; joint equalities "
                                       "are read as mimic joints)")
        c = [float(x) for x in model.eq_data[e, :5]]
        if any(c[2:]):
            raise located(path, where, "a joint equality beyond degree 1 (polycoef c2..c4 not 0) cannot "
                                       "be a mimic coupling")
        one, two = int(model.eq_obj1id[e]), int(model.eq_obj2id[e])
        follower = joint_name[one]
        y0 = float(model.qpos0[model.jnt_qposadr[one]])     # MuJoCo's polynomial is about the refs:
        if two < 0:                                          # y - y0 = c0 + c1 (x - x0)
            held[follower] = y0 + c[0]
            continue
        x0 = float(model.qpos0[model.jnt_qposadr[two]])
        by_name[follower].mimic = _Mimic(joint_name[two], c[1], y0 + c[0] - c[1] * x0)
    if inactive:
        warnings.warn(VampcWarning(f"{path}: inactive {', '.join(inactive)} left out"), stacklevel=4)
    return held, loops


def _loops(model, robot: _Robot, chain, path: Path, base: str | None) -> None:
    """Refuse a connect or weld equality (a closed loop: the network computes an open tree) whose
    loop has a joint that moves in the compiled robot: one on the way between its two bodies that
    is one of the chain's joints, or, on a floating base, the base's own motion (one of its bodies
    in the robot, at or below the base, and the other not). Where none moves (every one locked by
    --lock, held by an equality under --mimic couple, fixed, above a fixed base, or a free body's
    that the robot leaves out), its
    bodies are one rigid body to the network or no part of it, and the loop's forces internal to
    it: left out with a warning (a Menagerie trial's find: an xarm7 refused whatever its gripper's
    joints were locked at)."""
    moving = {j.name for j in chain.joints}
    floats = _base_body(model, robot, chain, base) if chain.floating else None
    left = []
    for where, kind, one, two in robot.loops:
        ups = _up(model, one), _up(model, two)
        way = [b for b in ups[0] + ups[1] if (b in ups[0]) != (b in ups[1])]   # (up to where they meet)
        moves = [robot.joint_names[j] for b in way
                 for j in range(int(model.body_jntadr[b]), int(model.body_jntadr[b]) + int(model.body_jntnum[b]))
                 if robot.joint_names[j] in moving]
        if floats is not None and (floats in ups[0]) != (floats in ups[1]):
            # (one body in the robot, the other not: the loop holds the base's own motion)
            moves.append(f"the floating base '{robot.bodies[floats]}'")
        if moves:
            raise located(path, where, f"{kind} equality constraints are not supported (the network "
                          f"computes an open tree; joint equalities are read as mimic joints): its loop "
                          f"moves on {_joints_said(moves[:5])}"
                          + (f" and {len(moves) - 5} more" if len(moves) > 5 else "")
                          + " (a loop no joint of which moves, all locked or above a fixed --base, "
                            "is left out)")
        left.append(f"{where} ({kind} of '{robot.bodies[one]}' and '{robot.bodies[two]}')")
    if left:
        warnings.warn(VampcWarning(
            f"{path}: {', '.join(left)} left out: no joint between {'its' if len(left) == 1 else 'their'} "
            "bodies moves in the compiled robot (locked, fixed, above the base or a free body's left "
            "out), so the loop's forces are internal to one rigid body or outside the robot"),
            stacklevel=3)


def _joints_said(moves: list) -> str:
    """'joint 'j2'', 'joints 'j2', 'j1'', or the floating base among them, for _loops' message."""
    named = [m for m in moves if not m.startswith("the floating base")]
    said = ([f"joint{'s' if len(named) > 1 else ''} {', '.join(repr(m) for m in named)}"] if named else []) \
        + [m for m in moves if m.startswith("the floating base")]
    return " and ".join(said)


def _named_body(model, robot: _Robot, base: str | None) -> tuple[int, int | None] | None:
    """The body `base` names (0 the world) and, for a link between two joints of one body
    (`BODY__JOINT`: the child of JOINT), JOINT's index; None for no body or link of the model."""
    if base in robot.bodies:
        return robot.bodies.index(base), None
    owner = next((jt.name for jt in robot.joints if jt.child == base and jt.name in robot.joint_names),
                 None)
    if owner is None:
        return None
    last = robot.joint_names.index(owner)
    return int(model.jnt_bodyid[last]), last


def _base_body(model, robot: _Robot, chain, base: str | None) -> int:
    """The body of a floating chain's base: the one `base` names (a link between two joints of a
    body, that body), else the body the world carries that holds the chain's first joint."""
    named = _named_body(model, robot, base) if base is not None else None
    if named is not None:
        return named[0]
    first = robot.joint_names.index(chain.joints[0].name)
    top = int(model.body_rootid[model.jnt_bodyid[first]])
    count = int(model.body_jntnum[top])
    if count and not (count == 1 and int(model.jnt_type[model.body_jntadr[top]]) == FREE):
        return 0    # (hinged to the world: the world body floats with what is welded to it, a review's)
    return top      # (on its free joint, or welded to the world with joints below: it floats)


def _up(model, b: int) -> list[int]:
    """Body `b` and the bodies above it, up to and with the world (0)."""
    out = [b]
    while b:
        b = int(model.body_parentid[b])
        out.append(b)
    return out


def _named(model, kind: str, k: int, names: list) -> str:
    """Where an error is: a joint or body by its name in the file, or, unnamed there, by its place
    among its kind and the name vampc gives it (joint2 was read as a name the file had)."""
    given = (model.joint(k) if kind == "joint" else model.body(k)).name
    place = k + 1 if kind == "joint" else k          # (body 0 is the world, no <body> of the file)
    return f"{kind} '{given}'" if given else f"<{kind}> number {place} (unnamed; vampc calls it '{names[k]}')"


def _element(kind: str, name: str, index: int = 0) -> str:
    """Where an error is: the element by name, or by its place among its kind when unnamed."""
    return f"{kind} '{name}'" if name else f"<{kind}> number {index + 1} (unnamed)"


def _inertial(model, b: int) -> _Inertial | None:
    mass = float(model.body_mass[b])
    diag = np.array(model.body_inertia[b], dtype=float)
    if mass == 0 and not np.any(diag):
        return None
    # principal moments in the principal frame, whose pose in the body is (ipos, iquat)
    return _Inertial(mass, np.diag(diag), _pose(model.body_ipos[b], model.body_iquat[b]))


def _limit(model, j: int) -> _Limit | None:
    if not model.jnt_limited[j]:
        return None
    lower, upper = (float(x) for x in model.jnt_range[j])
    return _Limit(lower, upper)


def _quat(q) -> np.ndarray:
    q = np.asarray(q, dtype=float)        # (np.linalg.norm of a vector is the BLAS's dot: chain.matmul)
    w, x, y, z = q / np.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def _pose(pos, quat) -> np.ndarray:
    out = np.eye(4)
    out[:3, :3], out[:3, 3] = _quat(quat), pos
    return out


def _translation(v) -> np.ndarray:
    out = np.eye(4)
    out[:3, 3] = v
    return out
