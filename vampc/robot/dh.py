"""Standard (distal) DH tables in YAML or JSON → Chain (README, *DH table*; schema
`schemas/dh-table.schema.json`).

Row i gives A_i = Rz(θ_i) Tz(d_i) Tx(a_i) Rx(α_i), so the rotation is Rz(θ_i) Rx(α_i) and the origin of O_i
from O_{i-1}, in O_i, is p*_i = [a_i, d_i sin α_i, d_i cos α_i]. On the Chain model:

    revolute:  Φ_i = Rx(α_i),        p_fixed = [a_i, d_i sin α_i, d_i cos α_i],  offset = θ_i
    prismatic: Φ_i = Rz(θ_i) Rx(α_i), p_fixed = [a_i, 0, 0],                       offset = d_i

(prismatic: p*_i(q) = p_fixed + (q + d_i) Φ_iᵀ e_z, and Φ_iᵀ e_z = [0, sin α_i, cos α_i]).

Every problem is a one-line `VampcError` "FILE: WHERE: WHAT", WHERE being the JSON path in the file
(0-based) followed by the 1-based joint number, e.g. "joints[2].mass (joint 3)".

Size limits: at most MAX_JOINTS rows (VAMP numbers have 24 bits; the URDF loader applies it too) and
MAX_VALUES values, counted once YAML aliases are expanded (every table within the joint limit fits). Loading
is O(n): one walk counts the values and finds non-finite numbers, the inertias are checked as one numpy
stack, and the cyclic garbage collector is paused while the parsers build millions of objects (it took
more than half of the 39 s a 100 000-joint YAML table spent in PyYAML).
"""
from __future__ import annotations

import math
import re
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import yaml

from vampc import jsontext
from vampc.errors import VampcError, VampcWarning, located
from vampc.gcpause import gc_paused
from vampc.robot import JSON_SUFFIXES, YAML_SUFFIXES  # noqa: F401 - re-exported, used below
from vampc.robot.chain import Chain, Joint, JointType, Limits, matmul, rot_x, rot_z
from vampc.robot.dh_format import check as check_table
from vampc.robot.dh_format import where as _where
from vampc.robot.inertia import improper_inertias, inertia_problem  # noqa: F401 - re-exported
from vampc.textio import one_line


def load_dh(path, floating: bool = False) -> Chain:
    """Read a DH table (.yaml, .yml or .json) and return its Chain; VampcError on any problem.
    `floating` lets the base float (as the table's base.floating does)."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in YAML_SUFFIXES + JSON_SUFFIXES:
        raise located(path, "", f"unknown DH table extension {path.suffix!r} (expected .yaml, .yml or .json)")
    text = read_text(path)
    with gc_paused():  # a big table is millions of objects: the collector would walk them again and again
        doc = _parse_yaml(text, path) if suffix in YAML_SUFFIXES else _parse_json(text, path)
        chain = chain_from_dh(doc, str(path), floating)
    if all(j.mass == 0 and not np.any(j.inertia) for j in chain.joints):
        # (as a URDF's without any <inertial> is: said where the table gives every mass 0, an
        # audit's find)
        from vampc.errors import VampcWarning
        warnings.warn(VampcWarning(f"{path}: every joint's link has mass 0 and inertia 0: every body "
                                   "is massless, so every torque is zero but for the tip's load"),
                      stacklevel=2)
    return chain


def chain_from_dh(doc: dict, source: str, floating: bool = False) -> Chain:
    """Validate an already-parsed DH document and build its Chain; `source` names it in error messages.
    Rows with `parent` make a tree, numbered depth-first from the base (children in row order)."""
    if doc is None or doc == "":
        raise VampcError(f"{source}: the robot file is empty (a DH table is a mapping with "
                         "`joints`; README, DH table)")
    if not isinstance(doc, (dict, list)):
        # (a CSV named .yaml reads as one text: the schema error quoted it, cut short, and said
        # nothing else; a new user's torque file)
        what = ("a CSV table (a trajectory, torques or limits?)" if isinstance(doc, str) and ","
                in doc.split(" ", 1)[0] else "one value")
        raise VampcError(f"{source}: this is not a DH table: it reads as {what}, where a DH table "
                         "is a mapping with `name` and `joints` (README, DH table)")
    from vampc.sniff import vampc_output
    output = vampc_output(doc)
    if output:       # (one of vampc's own outputs: a schema error had named its first key)
        raise VampcError(f"{source}: this is {output}, not a robot description (a DH table, URDF "
                         "or MJCF model; README, File formats)")
    _check_values(doc, source)
    check_table(doc, source)
    rows = doc["joints"]
    _check_names(rows, source)
    parents = row_parents(rows, source)
    inertias = _inertias(rows, source)
    joints = [_joint(row, i, inertias[i], source) for i, row in enumerate(rows)]
    order = depth_first(parents)
    new = {old: k for k, old in enumerate(order, 1)}
    tree = {} if order == list(range(len(rows))) and parents == list(range(-1, len(rows) - 1)) else \
        {"parents": tuple(new.get(parents[old], 0) for old in order)}
    base, tip = doc.get("base", {}), doc.get("tip", {})
    branches = len(set(parents)) < len(parents)     # (a parent of two: a chain listed out of
    #                                                   order is no tree, and its tip is its end)
    if branches and order[-1] != len(rows) - 1 and any(
            float(x) != 0.0 for key in ("force", "torque") for x in tip.get(key, ())):
        last = order[-1]
        raise located(source, "tip", f"on a tree the tip load acts on link n, the last joint in "
                      f"depth-first order: {joints[last].name!r} (row {last + 1}), not the last "
                      f"row's {joints[-1].name!r} (row {len(rows)}); list the loaded link's branch "
                      "last (README, DH table)")
    _warn_degrees(rows, source)
    return Chain(name=doc["name"], joints=tuple(joints[old] for old in order),
                 gravity=_vec(doc.get("gravity", [0.0, 0.0, -9.81])),
                 base_omega=_vec(base.get("omega", [0, 0, 0])),
                 base_omega_dot=_vec(base.get("omega_dot", [0, 0, 0])),
                 tip_force=_vec(tip.get("force", [0, 0, 0])),
                 tip_torque=_vec(tip.get("torque", [0, 0, 0])), source=source,
                 **tree, **_floating_base(base, floating, source))


def _floating_base(base: dict, floating: bool, source: str) -> dict:
    """The Chain fields of a floating base: its link's mass, centre of mass and inertia (default none)."""
    if floating and base.get("floating"):     # (taken unsaid: a new user's find)
        warnings.warn(VampcWarning(f"{source}: base.floating is true already; --floating-base has no "
                                   "effect"), stacklevel=4)
    if floating and base.get("floating") is False:    # (overridden unsaid: a new user's find)
        warnings.warn(VampcWarning(f"{source}: base.floating is false; --floating-base floats the "
                                   "base all the same"), stacklevel=4)
    if not (floating or base.get("floating")):
        for key in ("mass", "com", "inertia"):
            if key in base:
                raise located(source, f"base.{key}", "the base link's inertia counts only for a floating "
                                                     "base (add floating: true or --floating-base)")
        return {}
    for key in ("omega", "omega_dot"):
        if key in base:
            raise located(source, f"base.{key}", "a floating base's motion is input per torque set "
                                                 "(trajectory columns), not a constant")
    inertia = np.array(_inertia_matrix(base.get("inertia", [0.0] * 6)), dtype=float)
    problem = inertia_problem(inertia)
    if problem:
        raise located(source, "base.inertia", problem)
    return {"floating": True, "base_mass": float(base.get("mass", 0.0)),
            "base_com": _vec(base.get("com", [0, 0, 0])), "base_inertia": inertia}


def row_parents(rows: list, source: str) -> list[int]:
    """Each row's parent row (0-based; -1 the base) from `parent` (a name, a 1-based row number or 0),
    default the previous row; refuse names and numbers that name nothing and cycles."""
    index = {row.get("name", f"j{i + 1}"): i for i, row in enumerate(rows)}
    parents = []
    for i, row in enumerate(rows):
        value = row.get("parent", i)           # the previous row's number, 0 (the base) for row 1
        if isinstance(value, str):
            if value not in index:
                raise located(source, _where(("joints", i, "parent")), f"{value!r} names no joint")
            parents.append(index[value])
        elif value > len(rows):
            raise located(source, _where(("joints", i, "parent")),
                          f"{value} is not a row number (1..{len(rows)}, or 0 for the base)")
        else:
            parents.append(value - 1)
    _check_cycles(rows, parents, source)
    return parents


def _check_cycles(rows: list, parents: list[int], source: str) -> None:
    """Every row must reach the base through its parents; name the first cycle met otherwise."""
    state = [0] * len(rows)         # 0 unseen, 1 on the current walk, 2 reaches the base
    for start in range(len(rows)):
        walk, i = [], start
        while i >= 0 and state[i] == 0:
            state[i] = 1
            walk.append(i)
            i = parents[i]
        if i >= 0 and state[i] == 1:
            loop = walk[walk.index(i):]
            names = ", ".join(repr(rows[k].get("name", f"j{k + 1}")) for k in loop[:10])
            raise located(source, _where(("joints", loop[0], "parent")),
                          f"parents form a cycle through joints {names}: none of them reaches the base")
        for k in walk:
            state[k] = 2


def depth_first(parents: list[int]) -> list[int]:
    """Rows in depth-first order from the base, children in row order (parents 0-based, -1 the base)."""
    children: dict[int, list[int]] = {}
    for i, p in enumerate(parents):
        children.setdefault(p, []).append(i)
    order, stack = [], list(reversed(children.get(-1, [])))
    while stack:
        i = stack.pop()
        order.append(i)
        stack.extend(reversed(children.get(i, [])))
    return order


def read_text(path: Path) -> str:
    """The file's text (a leading byte-order mark, as some editors write, dropped: JSON's parser
    had refused it at line 1, column 1, where YAML's took it: an audit's), or a VampcError saying
    why it cannot be read."""
    from vampc.textio import read_whole
    try:
        return read_whole(path, text=True).decode("utf-8").removeprefix("\ufeff")
    except FileNotFoundError:
        raise located(path, "", "no such file") from None
    except UnicodeDecodeError as exc:
        raise located(path, "", f"not UTF-8 text (byte {exc.start})") from None
    except OSError as exc:
        raise located(path, "", f"cannot read: {exc.strerror or exc}") from None


def joint_count_problem(n: int) -> str | None:
    """Why a chain of n joints is too long to compile, or None."""
    if n > MAX_JOINTS:
        return (f"too many joints: {n} (at most {MAX_JOINTS}: VAMP numbers have 24 bits and the smallest "
                f"network, the linear one, has up to 32 VAMPs a joint)")
    return None


# --- parsing -----------------------------------------------------------------------------------------

class _Loader(getattr(yaml, "CSafeLoader", yaml.SafeLoader)):
    """yaml.SafeLoader (no object construction; libyaml's parser when PyYAML has it: 1.7 s instead
    of 6.8 s on a 4096-joint table) that also refuses duplicate keys and reads `1e-3` as a number:
    YAML 1.1 (PyYAML) wants a dot in the mantissa, so a bare `1e-3` would otherwise be text."""

    def construct_object(self, node, deep=False):
        """A value, or a YAML error at its line: PyYAML's constructors raise Python's own errors
        for a tagged value they cannot make (`!!float abc`, `!!bool maybe`, `!!int ""`), which had
        been internal errors (an audit's)."""
        try:
            return super().construct_object(node, deep=deep)
        except yaml.YAMLError:
            raise
        except (TypeError, ValueError, KeyError, AttributeError, IndexError, OverflowError):
            raise yaml.constructor.ConstructorError(
                None, None, f"{node.value!r} cannot be read as {_tag_text(node.tag)}"
                if isinstance(node, yaml.ScalarNode) else f"this {_tag_text(node.tag)} cannot be read",
                node.start_mark) from None


def _tag_text(tag: str) -> str:
    """'!!float' for YAML's own tags, the tag itself for others."""
    return "!!" + tag[len("tag:yaml.org,2002:"):] if tag.startswith("tag:yaml.org,2002:") else tag


_FLOAT = re.compile(r"""^[-+]?(?:[0-9][0-9_]*)?(?:\.[0-9_]*)?[eE][-+]?[0-9]+$""")
_Loader.add_implicit_resolver("tag:yaml.org,2002:float", _FLOAT, list("-+0123456789."))
# YAML 1.1's dates and `=` are text here, as in YAML 1.2 and JSON (the schema then says a date where
# a number is due is no number; PyYAML's "no constructor for the tag value" had been said of `a: =`),
# so a tag on a value is always one the user wrote (a review's find)
_Loader.yaml_implicit_resolvers = {
    first: [(tag, rx) for tag, rx in resolvers
            if tag not in ("tag:yaml.org,2002:timestamp", "tag:yaml.org,2002:value")]
    for first, resolvers in _Loader.yaml_implicit_resolvers.items()}


def _construct_mapping(loader: _Loader, node: yaml.MappingNode, deep: bool = False) -> dict:
    seen = set()
    for key_node, _ in node.value:
        if not isinstance(key_node, yaml.ScalarNode):       # (`? [x]`: unhashable, an internal error)
            what = "list" if isinstance(key_node, yaml.SequenceNode) else "mapping"
            raise yaml.constructor.ConstructorError(None, None, f"a key is a {what}; keys are names",
                                                    key_node.start_mark)
        key = loader.construct_object(key_node, deep=deep)
        if key in seen:
            raise yaml.constructor.ConstructorError(None, None, f"duplicate key {key!r}", key_node.start_mark)
        seen.add(key)
    return loader.construct_mapping(node, deep=deep)


_Loader.add_constructor(yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG, _construct_mapping)

# A number as it is written everywhere else (YAML 1.2, JSON, Python without underscores): YAML 1.1,
# which PyYAML reads, takes 1:30 as 90 (base 60), 010 as 8 (octal), 1_0 as 10, 0x10 as 16, and a
# robot was built with those values without a word. Checked on the parsed nodes, before they are
# made into values, on what the robot is built from (not under `x-` keys, free for annotations, nor
# a name, which must be text: the schema says so).
_PLAIN = {"tag:yaml.org,2002:int": re.compile(r"^[-+]?(?:0|[1-9][0-9]*)$"),
          "tag:yaml.org,2002:float": re.compile(
              r"^[-+]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][-+]?[0-9]+)?$|^[-+]?\.(?:inf|Inf|INF)$|"
              r"^\.(?:nan|NaN|NAN)$")}
_MERGE = "tag:yaml.org,2002:merge"
_UNQUOTED = {"tag:yaml.org,2002:" + t: what for t, what in
             (("int", "the number"), ("float", "the number"), ("bool", "the truth value"),
              ("null", "null"))}
# the tags a DH table's values resolve to untagged (a name may be any text: not checked)
_PLAIN_TAGS = {"tag:yaml.org,2002:" + t for t in ("map", "seq", "str", "int", "float", "bool", "null")}


def _refuse_unquoted_names(loader: _Loader, root, path: Path) -> None:
    """VampcError naming the line of the robot's or a row's name that YAML reads as a number, a truth
    value or null (`name: 0x10`, `yes`, `~`): the schema's message gave what YAML made of it with no
    line ("name: 16 is not of type string": an audit's). Where no name belongs (`limits`, `base`,
    `tip`) the schema says the key is unexpected."""
    def entry(node, key: str):
        if isinstance(node, yaml.MappingNode):
            for k, v in node.value:
                if isinstance(k, yaml.ScalarNode) and k.value == key:
                    return v
        return None
    joints = entry(root, "joints")
    rows = joints.value if isinstance(joints, yaml.SequenceNode) else []
    for value in (entry(root, "name"), *(entry(row, "name") for row in rows)):
        if isinstance(value, yaml.ScalarNode) and value.tag in _UNQUOTED and not value.style:
            where = f"line {value.start_mark.line + 1}"
            if not value.value.strip():
                raise located(path, where, "the name is empty: give it as text")
            made = "" if value.tag.endswith("null") else f" {loader.construct_object(value)!r}"
            raise located(path, where, f"name {value.value!r} is read as "
                                       f"{_UNQUOTED[value.tag]}{made}; a name is text: quote it")


def _refuse_other_numbers(loader: _Loader, root, path: Path) -> None:
    """VampcError naming the line of the first number YAML 1.1 reads as another value (see above),
    of a value of the robot tagged by hand (`!!set`, `!!float nan`: _PLAIN_TAGS), or of a merge key
    anywhere, annotations included (`<<: *row`: not read; merged mappings repeat every entry they
    merge, so a small file nesting them grows without bound before its keys collapse)."""
    stack, seen = [(root, True)], set()
    while stack:
        node, robot = stack.pop()       # robot: what the robot is built from (not an annotation)
        if (id(node), robot) in seen:   # (an alias: its node is checked once)
            continue
        seen.add((id(node), robot))
        if robot and node.tag == _MERGE:          # (`a: <<`: a merge key's mark as a value)
            raise located(path, f"line {node.start_mark.line + 1}", "'<<' is YAML's merge key, "
                          "not a value")
        if robot and node.tag not in _PLAIN_TAGS:
            # a tag the user wrote (`com: !!set {...}` passed the schema as a list and was an
            # internal error; `!!omap`): dates and `=` resolve to text here (_Loader)
            raise located(path, f"line {node.start_mark.line + 1}", f"a value tagged "
                          f"{_tag_text(node.tag)} is not read: write it untagged")
        if isinstance(node, yaml.MappingNode):
            for key, value in node.value:
                if key.tag == _MERGE:   # (under an annotation too: PyYAML's own words were said)
                    raise located(path, f"line {key.start_mark.line + 1}", "YAML merge keys (<<) "
                                  "are not read: write the row's fields out (an alias of a whole "
                                  "row or value is read)")
                text = key.value if isinstance(key, yaml.ScalarNode) else None
                stack.append((value, robot and not (isinstance(text, str) and
                                                    (text.startswith("x-") or text == "name"))))
        elif isinstance(node, yaml.SequenceNode):
            stack.extend((v, robot) for v in node.value)
        elif robot and isinstance(node, yaml.ScalarNode) and node.tag in _PLAIN and \
                not _PLAIN[node.tag].match(node.value.strip()):
            if loader.resolve(yaml.ScalarNode, node.value, (True, False)) != node.tag:
                # tagged by hand (`!!float nan`, `!!float '0x10'`): not a YAML 1.1 reading
                raise located(path, f"line {node.start_mark.line + 1}",
                              f"{node.value!r} is tagged {_tag_text(node.tag)}; numbers are read "
                              "untagged, in decimal digits")
            digits = node.value.strip().lstrip("+-")
            if node.tag.endswith("int") and re.fullmatch(r"0[0-7]+", digits) and \
                    int(digits, 8) == int(digits):
                continue                # (01, 007: the same number either way)
            value = loader.construct_object(node)
            raise located(path, f"line {node.start_mark.line + 1}",
                          f"{node.value!r} is a number YAML 1.1 reads as {value!r} (base 60, octal, "
                          "hexadecimal or an underscore); write it in decimal digits")


def _parse_yaml(text: str, path: Path):
    try:
        loader = _Loader(text)
        try:
            root = loader.get_single_node()
            if root is None:
                return None
            _refuse_unquoted_names(loader, root, path)
            _refuse_other_numbers(loader, root, path)
            return loader.construct_document(root)
        finally:
            loader.dispose()
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        where = f"line {mark.line + 1}" if mark else ""
        raise located(path, where, f"not valid YAML: {exc.problem or exc.context}") from None
    except yaml.YAMLError as exc:
        raise located(path, "", f"not valid YAML: {one_line(str(exc))}") from None
    except RecursionError:
        raise located(path, "", "not valid YAML: nested too deeply") from None


def _parse_json(text: str, path: Path):
    try:
        try:
            doc = jsontext.loads(text)
        except jsontext.DecodeError as exc:
            if not str(exc).startswith("Number out of range"):
                raise located(path, "", f"not valid JSON: {jsontext.decode_problem(exc, text)}") from None
            # 1e400: read as inf, as YAML reads it, so the checks name the joint (msgspec's path
            # hides the keys: `$[...][0][...]`)
            import json
            doc = json.loads(text)
    except RecursionError:
        raise located(path, "", "not valid JSON: nested too deeply") from None
    duplicate = jsontext.duplicate_key(text)
    if duplicate is not None:
        key, line = duplicate
        raise located(path, f"line {line}", f"not valid JSON: duplicate key {key!r}") from None
    return doc


# --- validation --------------------------------------------------------------------------------------

# VAMP numbers have 24 bits (1..16 777 215) and the linear network, the smallest, has 30 VAMPs per revolute
# and 32 per prismatic joint: no longer chain can be numbered, whatever the recursion.
MAX_JOINTS = (2**24 - 1) // 32  # 524 287
# The most values a row can hold (its mapping; name, type, a, alpha, d, theta, mass; com 1 + 3; a 3x3
# inertia 1 + 3 x 4; limits 1 + q 3 + qd + tau) and the rest of a table (its mapping; name; gravity 4;
# base and tip 9 each; the joints list): every valid table of at most MAX_JOINTS rows fits in MAX_VALUES.
ROW_VALUES, TABLE_VALUES = 31, 25
MAX_VALUES = ROW_VALUES * MAX_JOINTS + TABLE_VALUES  # 16 252 922


def _check_values(doc, source: str) -> None:
    """Refuse a table of more than MAX_JOINTS rows or MAX_VALUES values, counted once YAML aliases are
    expanded: aliases let a small file expand into a huge (or infinite) tree, which the checks below and
    the error messages (which quote whole values) would walk or print in full. Then refuse NaN and
    ±inf, which pass a JSON schema's "number" (YAML .nan/.inf, JSON NaN)."""
    rows = doc.get("joints") if isinstance(doc, dict) else None
    problem = joint_count_problem(len(rows)) if isinstance(rows, list) else None
    if problem:
        raise located(source, "", problem)
    survey = _Survey()
    try:
        survey.expanded = _visit(doc, (), survey, {}, set())
    except RecursionError:
        raise located(source, "", "nested too deeply") from None
    if survey.expanded == math.inf:
        raise located(source, "", "a YAML alias refers to itself")
    if survey.written > MAX_VALUES:
        raise located(source, "", f"too large: {survey.written} values (at most {MAX_VALUES})")
    if survey.expanded > MAX_VALUES:
        raise located(source, "", f"too large: {survey.expanded} values once YAML aliases are expanded "
                                  f"(at most {MAX_VALUES})")
    if survey.bad is not None:
        keys, value = survey.bad
        raise located(source, _where(keys), f"{value} is not a finite number")


@dataclass
class _Survey:
    """What one walk over a document finds: its number of values once YAML aliases are expanded (inf when
    a container holds itself), as written (an alias counts once), and its first non-finite number
    (path, value) in document order."""

    expanded: float = 0
    written: int = 1
    bad: tuple | None = None


def _visit(node, keys: tuple, survey: _Survey, memo: dict, active: set) -> float:
    """The expanded size of `node`. Each container is walked once (memo: YAML aliases share containers,
    and a walk through every path of an alias "bomb" would take exponential time); scalars are checked
    in the loop, a finite float without any call, since a big table holds millions of them."""
    if not isinstance(node, (dict, list)):
        if not _finite(node):
            survey.bad = (keys, node)
        return 1
    key = id(node)
    if key in memo or key in active:  # active: a container inside itself
        return memo.get(key, math.inf)
    active.add(key)
    survey.written += len(node)
    size = 1 + len(node)  # itself and a value per child; a container child adds the rest of its size
    for k, child in node.items() if isinstance(node, dict) else enumerate(node):
        if isinstance(child, (dict, list)):
            size += _visit(child, keys + (k,), survey, memo, active) - 1
        elif type(child) is float and math.isfinite(child):
            continue
        elif survey.bad is None and not _finite(child):
            survey.bad = (keys + (k,), child)
    active.discard(key)
    memo[key] = size
    return size


def _finite(value) -> bool:
    """False for a NaN, an infinity or an int too large for a float; True for anything else."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return True
    try:
        return math.isfinite(value)
    except OverflowError:
        return False


def _warn_degrees(rows: list, source: str) -> None:
    """One warning for the constant DH angles (alpha, theta) beyond 2π + 1e-3 in size, the first
    named and the others counted: degrees, most likely, read as radians (`alpha: 90` was 90 rad,
    unsaid)."""
    found = [(i, key) for i, row in enumerate(rows) for key in ("alpha", "theta")
             if abs(float(row[key])) > 2 * math.pi + 1e-3]    # (2π rounded, 6.2832, is radians)
    _warn_degree_limits(rows, source)
    if not found:
        return
    i, key = found[0]
    value = float(rows[i][key])
    more = f" (and {len(found) - 1} more)" if len(found) > 1 else ""
    warnings.warn(VampcWarning(f"{source}: {_where(('joints', i, key))}: {key} {value:g} is "
                               f"{'more than 2π' if value > 0 else 'less than -2π'}: DH angles are "
                               f"radians ({value:g}° is {math.radians(value):.5g}){more}"),
                  stacklevel=3)


def _warn_degree_limits(rows: list, source: str) -> None:
    """One warning for a revolute joint's position limit beyond two turns (4π): degrees, most
    likely (`q: [-170, 170]` drove random states to ±156 rad, unsaid: a new user's find), up to
    1080 (three turns in degrees); a joint of a few turns, ±2π or ±3π, is not warned of."""
    found = [(i, float(x)) for i, row in enumerate(rows)
             if row.get("type", "revolute") == "revolute" and (row.get("limits") or {}).get("q")
             for x in row["limits"]["q"] if 4 * math.pi < abs(float(x)) <= 1080]
    #         (up to three turns in degrees: a bound of 1e308 is no angle, but "no limit")
    if not found:
        return
    i, value = found[0]
    more = sum(1 for k in {j for j, _ in found} if k != i)
    warnings.warn(VampcWarning(f"{source}: {_where(('joints', i, 'limits'))}: q limit {value:g} is "
                               f"more than two turns: position limits are radians ({value:g}° is "
                               f"{math.radians(value):.5g})"
                               + (f" (and {more} more joint{'s' if more > 1 else ''})" if more
                                  else "")), stacklevel=4)


def _check_names(rows: list, source: str) -> None:
    seen = set()
    for i, row in enumerate(rows):
        name = row.get("name", f"j{i + 1}")
        if name in seen:
            raise located(source, _where(("joints", i, "name")), f"duplicate joint name {name!r}")
        seen.add(name)


# --- building ----------------------------------------------------------------------------------------

def _joint(row: dict, i: int, inertia: np.ndarray, source: str) -> Joint:
    kind = JointType(row["type"])
    a, alpha, d, theta = (float(row[k]) for k in ("a", "alpha", "d", "theta"))
    if kind is JointType.REVOLUTE:
        phi, p_fixed, offset = rot_x(alpha), [a, d * math.sin(alpha), d * math.cos(alpha)], theta
    else:
        phi, p_fixed, offset = matmul(rot_z(theta), rot_x(alpha)), [a, 0.0, 0.0], d
    return Joint(name=row.get("name", f"j{i + 1}"), type=kind, phi=phi, p_fixed=_vec(p_fixed),
                 offset=offset, mass=float(row["mass"]), com=_vec(row["com"]),
                 inertia=inertia, limits=_limits(row.get("limits"), i, source))


def _inertias(rows: list, source: str) -> np.ndarray:
    """Every row's inertia as one (n, 3, 3) stack, refusing the first that is not symmetric positive
    semi-definite (checked all at once: one LAPACK call instead of one per row)."""
    stack = np.array([_inertia_matrix(row["inertia"]) for row in rows], dtype=float)
    for i in np.flatnonzero(improper_inertias(stack)):
        problem = inertia_problem(stack[i])
        if problem:
            raise located(source, _where(("joints", int(i), "inertia")), problem)
    return stack


def _inertia_matrix(value: list) -> list:
    """[ixx, iyy, izz, ixy, iyz, ixz] as a 3x3 matrix; a 3x3 matrix as it is."""
    if len(value) != 6:
        return value
    ixx, iyy, izz, ixy, iyz, ixz = value
    return [[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]]


def _limits(value: dict | None, i: int, source: str) -> Limits:
    if not value:
        return Limits()
    q = value.get("q")
    if q is not None and q[0] > q[1]:
        raise located(source, _where(("joints", i, "limits", "q")),
                      f"lower limit {q[0]} is above upper limit {q[1]}")
    return Limits(q=None if q is None else (float(q[0]), float(q[1])),
                  qd=_opt_float(value.get("qd")), tau=_opt_float(value.get("tau")))


def _opt_float(value) -> float | None:
    return None if value is None else float(value)


def _vec(value) -> np.ndarray:
    return np.array(value, dtype=float)
