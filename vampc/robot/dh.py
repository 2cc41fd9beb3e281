"""Standard (distal) DH tables in YAML or JSON → Chain (DESIGN §3, schema `schemas/dh-table.schema.json`).

Row i gives A_i = Rz(θ_i) Tz(d_i) Tx(a_i) Rx(α_i), so the rotation is Rz(θ_i) Rx(α_i) and the origin of O_i
from O_{i-1}, in O_i, is p*_i = [a_i, d_i sin α_i, d_i cos α_i]. On the Chain model:

    revolute:  Φ_i = Rx(α_i),        p_fixed = [a_i, d_i sin α_i, d_i cos α_i],  offset = θ_i
    prismatic: Φ_i = Rz(θ_i) Rx(α_i), p_fixed = [a_i, 0, 0],                       offset = d_i

(prismatic: p*_i(q) = p_fixed + (q + d_i) Φ_iᵀ e_z, and Φ_iᵀ e_z = [0, sin α_i, cos α_i]).

Every problem is a one-line `VampcError` "FILE: WHERE: WHAT", WHERE being the JSON path in the file
(0-based) followed by the 1-based joint number, e.g. "joints[2].mass (joint 3)".
"""
from __future__ import annotations

import json
import math
import re
from functools import lru_cache
from pathlib import Path

import numpy as np
import yaml

from vampc.errors import VampcError, located
from vampc.robot.chain import Chain, Joint, JointType, Limits, rot_x, rot_z

YAML_SUFFIXES = (".yaml", ".yml")
JSON_SUFFIXES = (".json",)


def load_dh(path) -> Chain:
    """Read a DH table (.yaml, .yml or .json) and return its Chain; VampcError on any problem."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in YAML_SUFFIXES + JSON_SUFFIXES:
        raise located(path, "", f"unknown DH table extension {path.suffix!r} (expected .yaml, .yml or .json)")
    text = read_text(path)
    doc = _parse_yaml(text, path) if suffix in YAML_SUFFIXES else _parse_json(text, path)
    return chain_from_dh(doc, str(path))


def chain_from_dh(doc: dict, source: str) -> Chain:
    """Validate an already-parsed DH document and build its Chain; `source` names it in error messages."""
    _check_size(doc, source)
    _check_finite(doc, source)
    _check_schema(doc, source)
    rows = doc["joints"]
    _check_names(rows, source)
    joints = tuple(_joint(row, i, source) for i, row in enumerate(rows))
    base, tip = doc.get("base", {}), doc.get("tip", {})
    return Chain(name=doc["name"], joints=joints,
                 gravity=_vec(doc.get("gravity", [0.0, 0.0, -9.81])),
                 base_omega=_vec(base.get("omega", [0, 0, 0])),
                 base_omega_dot=_vec(base.get("omega_dot", [0, 0, 0])),
                 tip_force=_vec(tip.get("force", [0, 0, 0])),
                 tip_torque=_vec(tip.get("torque", [0, 0, 0])), source=source)


def read_text(path: Path) -> str:
    """The file's text, or a VampcError saying why it cannot be read."""
    try:
        return path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise located(path, "", "no such file") from None
    except UnicodeDecodeError as exc:
        raise located(path, "", f"not UTF-8 text (byte {exc.start})") from None
    except OSError as exc:
        raise located(path, "", f"cannot read: {exc.strerror or exc}") from None


def inertia_problem(inertia: np.ndarray) -> str | None:
    """Why a 3x3 inertia is not symmetric positive semi-definite, or None if it is (up to rounding)."""
    scale = max(float(np.max(np.abs(inertia))), 1e-300)
    if np.max(np.abs(inertia - inertia.T)) > 1e-9 * scale:
        return "inertia is not symmetric"
    eig = np.linalg.eigvalsh(inertia)
    if eig[0] < -1e-9 * scale:
        shown = ", ".join(f"{e:.6g}" for e in eig)
        return f"inertia is not positive semi-definite (eigenvalues {shown})"
    return None


# --- parsing -----------------------------------------------------------------------------------------

class _Loader(getattr(yaml, "CSafeLoader", yaml.SafeLoader)):
    """yaml.SafeLoader (no object construction; libyaml's parser when PyYAML has it: 1.7 s instead
    of 6.8 s on a 4096-joint table) that also refuses duplicate keys and reads `1e-3` as a number:
    YAML 1.1 (PyYAML) wants a dot in the mantissa, so a bare `1e-3` would otherwise be text."""


_FLOAT = re.compile(r"""^[-+]?(?:[0-9][0-9_]*)?(?:\.[0-9_]*)?[eE][-+]?[0-9]+$""")
_Loader.add_implicit_resolver("tag:yaml.org,2002:float", _FLOAT, list("-+0123456789."))


def _construct_mapping(loader: _Loader, node: yaml.MappingNode, deep: bool = False) -> dict:
    seen = set()
    for key_node, _ in node.value:
        key = loader.construct_object(key_node, deep=deep)
        if key in seen:
            raise yaml.constructor.ConstructorError(None, None, f"duplicate key {key!r}", key_node.start_mark)
        seen.add(key)
    return loader.construct_mapping(node, deep=deep)


_Loader.add_constructor(yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG, _construct_mapping)


def _parse_yaml(text: str, path: Path):
    try:
        return yaml.load(text, Loader=_Loader)  # noqa: S506 - _Loader is a yaml.SafeLoader
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        where = f"line {mark.line + 1}" if mark else ""
        raise located(path, where, f"not valid YAML: {exc.problem or exc.context}") from None
    except yaml.YAMLError as exc:
        raise located(path, "", f"not valid YAML: {_one_line(str(exc))}") from None
    except RecursionError:
        raise located(path, "", "not valid YAML: nested too deeply") from None


def _parse_json(text: str, path: Path):
    try:
        return json.loads(text, object_pairs_hook=_unique_pairs)
    except json.JSONDecodeError as exc:
        raise located(path, f"line {exc.lineno}", f"not valid JSON: {exc.msg}") from None
    except ValueError as exc:
        raise located(path, "", f"not valid JSON: {exc}") from None
    except RecursionError:
        raise located(path, "", "not valid JSON: nested too deeply") from None


def _unique_pairs(pairs: list) -> dict:
    out = {}
    for key, value in pairs:
        if key in out:
            raise ValueError(f"duplicate key {key!r}")
        out[key] = value
    return out


# --- validation --------------------------------------------------------------------------------------

MAX_VALUES = 200_000  # a 1000-joint table has about 30 000


def _check_size(doc, source: str) -> None:
    """YAML aliases let a small file expand into a huge (or infinite) tree, which the checks below and the
    error messages (jsonschema quotes whole values) would walk or print in full: refuse those first."""
    try:
        size = _expanded_size(doc, {}, set())
    except RecursionError:
        raise located(source, "", "nested too deeply") from None
    if size == math.inf:
        raise located(source, "", "a YAML alias refers to itself")
    if size > MAX_VALUES:
        raise located(source, "", f"too large: {size} values once YAML aliases are expanded "
                                  f"(at most {MAX_VALUES})")


def _expanded_size(node, memo: dict, active: set) -> float:
    if not isinstance(node, (dict, list)):
        return 1
    key = id(node)
    if key in memo or key in active:  # active: a container inside itself
        return memo.get(key, math.inf)
    active.add(key)
    children = node.values() if isinstance(node, dict) else node
    memo[key] = 1 + sum(_expanded_size(child, memo, active) for child in children)
    active.discard(key)
    return memo[key]


def _check_finite(doc, source: str) -> None:
    """NaN and ±inf pass a JSON schema's "number", so look for them first (YAML .nan/.inf, JSON NaN)."""
    for keys, value in _walk(doc, ()):
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            continue
        try:
            finite = math.isfinite(value)
        except OverflowError:  # an int too large for a float
            finite = False
        if not finite:
            raise located(source, _where(keys), f"{value} is not a finite number")


def _walk(doc, keys: tuple):
    """(path, value) for every node, visiting each container once: YAML aliases share containers, and a
    walk through every path of an alias "bomb" would take exponential time."""
    seen, stack = set(), [(keys, doc)]
    while stack:
        keys, node = stack.pop()
        yield keys, node
        if isinstance(node, (dict, list)) and id(node) not in seen:
            seen.add(id(node))
            items = node.items() if isinstance(node, dict) else enumerate(node)
            stack.extend((keys + (key,), child) for key, child in reversed(list(items)))


@lru_cache(maxsize=1)
def _validator():
    import jsonschema

    from vampc.schemas_util import load_schema
    return jsonschema.Draft202012Validator(load_schema("dh-table"))


def _check_schema(doc, source: str) -> None:
    from vampc.schemas_util import accepted_quickly
    if accepted_quickly("dh-table", doc):
        return
    import jsonschema

    error = jsonschema.exceptions.best_match(_validator().iter_errors(doc))
    if error is None:
        return
    # best_match dives into the branches of a oneOf and reports one branch's complaint, which misleads
    # (e.g. "1 is not of type 'array'" for a 3-vector inertia); report the oneOf itself instead.
    while error.parent is not None:
        error = error.parent
    what = f"{error.instance!r} {error.schema['x-error']}" if "x-error" in error.schema else error.message
    raise located(source, _where(tuple(error.absolute_path)), _one_line(what))


def _check_names(rows: list, source: str) -> None:
    seen = set()
    for i, row in enumerate(rows):
        name = row.get("name", f"j{i + 1}")
        if name in seen:
            raise located(source, _where(("joints", i, "name")), f"duplicate joint name {name!r}")
        seen.add(name)


def _where(keys: tuple) -> str:
    """A JSON path ("joints[2].com[1]") plus the 1-based joint number when it points into a row."""
    text = "".join(f"[{k}]" if isinstance(k, int) else f".{k}" for k in keys).lstrip(".")
    if len(keys) >= 2 and keys[0] == "joints" and isinstance(keys[1], int):
        text += f" (joint {keys[1] + 1})"
    return text


def _one_line(text: str, limit: int = 300) -> str:
    """Collapse whitespace and cut very long messages (jsonschema quotes whole instances)."""
    text = " ".join(text.split())
    return text if len(text) <= limit else text[:limit - 3] + "..."


# --- building ----------------------------------------------------------------------------------------

def _joint(row: dict, i: int, source: str) -> Joint:
    kind = JointType(row["type"])
    a, alpha, d, theta = (float(row[k]) for k in ("a", "alpha", "d", "theta"))
    if kind is JointType.REVOLUTE:
        phi, p_fixed, offset = rot_x(alpha), [a, d * math.sin(alpha), d * math.cos(alpha)], theta
    else:
        phi, p_fixed, offset = rot_z(theta) @ rot_x(alpha), [a, 0.0, 0.0], d
    return Joint(name=row.get("name", f"j{i + 1}"), type=kind, phi=phi, p_fixed=_vec(p_fixed),
                 offset=offset, mass=float(row["mass"]), com=_vec(row["com"]),
                 inertia=_inertia(row["inertia"], i, source), limits=_limits(row.get("limits"), i, source))


def _inertia(value: list, i: int, source: str) -> np.ndarray:
    if len(value) == 6:
        ixx, iyy, izz, ixy, iyz, ixz = (float(v) for v in value)
        matrix = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
    else:
        matrix = np.array(value, dtype=float)
    problem = inertia_problem(matrix)
    if problem:
        raise located(source, _where(("joints", i, "inertia")), problem)
    return matrix


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
