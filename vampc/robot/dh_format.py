"""The DH table as typed records (msgspec Structs): what a table may hold, checked by the same library
that reads and writes program files (vampc.jsontext), and the source of `schemas/dh-table.schema.json`
(`python -m vampc.robot.dh_format > schemas/dh-table.schema.json`; a test keeps the two equal).

`check(doc, source)` takes a parsed table (YAML or JSON: dicts, lists and scalars) and raises the
one-line VampcError "FILE: WHERE: WHAT" of its first problem, WHERE being the JSON path in the file
(0-based) followed by the 1-based joint number ("joints[2].mass (joint 3): -1.0 is less than the
minimum of 0"). The building of the Chain (vampc.robot.dh) reads the dicts it has checked.
"""
from __future__ import annotations

import re
from typing import Annotated, Literal, Union

import msgspec
from msgspec import UNSET, Meta, Struct, UnsetType

from vampc import jsontext
from vampc.errors import located
from vampc.textio import one_line

Number = float            # msgspec takes an int where a float is asked, and refuses a bool, as JSON does
Vec3 = Annotated[list[Number], Meta(min_length=3, max_length=3)]
NonNegative = Annotated[Number, Meta(ge=0)]
Name = Annotated[str, Meta(min_length=1)]
INERTIA_ERROR = "is neither a 3x3 matrix nor six numbers [ixx, iyy, izz, ixy, iyz, ixz]"
PARENT_ERROR = "is neither a joint name nor a row number (0 for the base)"
# a 3x3 matrix (three rows of three) or six numbers; which of the two is checked after the types
Inertia = Annotated[list[Union[Number, Vec3]], Meta(
    min_length=3, max_length=6, extra_json_schema={"x-error": INERTIA_ERROR}, description=(
        "Inertia about the centre of mass (kg m^2): a symmetric positive semi-definite 3x3 matrix, "
        "or [ixx, iyy, izz, ixy, iyz, ixz]."))]


def _doc(text: str) -> Meta:
    return Meta(description=text)


class DhLimits(Struct, forbid_unknown_fields=True):
    """Joint limits (all optional)."""

    q: Annotated[list[Number], Meta(min_length=2, max_length=2,
                                    description="[lower, upper] position (rad or m).")] | UnsetType = UNSET
    qd: Annotated[NonNegative, _doc("Speed bound (rad/s or m/s).")] | UnsetType = UNSET
    tau: Annotated[NonNegative, _doc("Effort bound (N m or N).")] | UnsetType = UNSET


class DhJoint(Struct, forbid_unknown_fields=True):
    """One row: joint i and link i."""

    type: Literal["revolute", "prismatic"]
    a: Annotated[Number, _doc("Link length a_i (m), along x_i.")]
    alpha: Annotated[Number, _doc("Link twist alpha_i (rad), about x_i.")]
    d: Annotated[Number, _doc("Link offset d_i (m), along z_{i-1}; for a prismatic joint the "
                              "offset added to q.")]
    theta: Annotated[Number, _doc("Joint angle theta_i (rad), about z_{i-1}; for a revolute joint "
                                  "the offset added to q.")]
    mass: Annotated[NonNegative, _doc("Mass m_i of link i (kg).")]
    com: Annotated[Vec3, _doc("r*_i: centre of mass of link i from the origin of O_i, in O_i (m).")]
    inertia: Annotated[Inertia, _doc("Inertia J_i of link i about its centre of mass, in O_i "
                                     "(kg m^2): a symmetric positive semi-definite 3x3 matrix, or "
                                     "[ixx, iyy, izz, ixy, iyz, ixz].")]
    name: Annotated[Name, _doc("Joint name (default j1, j2, ...).")] | UnsetType = UNSET
    parent: Annotated[Union[Annotated[int, Meta(ge=0)], Name], Meta(
        extra_json_schema={"x-error": PARENT_ERROR}, description=(
            "The joint whose link carries this joint: its name, or its 1-based row number written "
            "as a whole number (2, not 2.0, which JSON Schema would pass and vampc refuses), 0 for "
            "the base (default: the previous row; the base for the first). The joint turns about z "
            "of its parent's frame O_parent, as a DH row does. Joints are numbered depth-first from "
            "the base, children in row order."))] | UnsetType = UNSET
    limits: DhLimits | UnsetType = UNSET


class DhBase(Struct, forbid_unknown_fields=True):
    """Base motion, in O_0 (default: at rest); or a floating base and its link."""

    omega: Annotated[Vec3, _doc("Base angular velocity omega_0.")] | UnsetType = UNSET
    omega_dot: Annotated[Vec3, _doc("Base angular acceleration.")] | UnsetType = UNSET
    floating: Annotated[bool, _doc(
        "The base floats (as --floating-base): its motion is input per torque set and the network "
        "also returns the base wrench; omega and omega_dot must then be left out.")] | UnsetType = UNSET
    mass: Annotated[NonNegative, _doc("Floating base: mass of the base link (kg; default 0).")] | \
        UnsetType = UNSET
    com: Annotated[Vec3, _doc("Floating base: centre of mass of the base link in O_0 (m).")] | \
        UnsetType = UNSET
    inertia: Annotated[Inertia, _doc("Floating base: inertia of the base link about its centre of "
                                     "mass, in O_0.")] | UnsetType = UNSET


class DhTip(Struct, forbid_unknown_fields=True):
    """The paper's tip load f_{n+1}, n_{n+1} at link n, in O_n (default zero)."""

    force: Vec3 | UnsetType = UNSET
    torque: Vec3 | UnsetType = UNSET


class DhTable(Struct, forbid_unknown_fields=True):
    """A serial robot or a tree in standard (distal) Denavit-Hartenberg form."""

    name: Annotated[Name, _doc("Robot name.")]
    joints: Annotated[list[DhJoint], Meta(min_length=1, description=(
        "One row per joint, base to tip (a tree: every joint after its parent or not, see parent). "
        "Row i carries link i."))]
    gravity: Annotated[Vec3, _doc("Gravity vector g in the base frame O_0 (default [0, 0, -9.81]); "
                                  "the base acceleration is -g.")] | UnsetType = UNSET
    base: DhBase | UnsetType = UNSET
    tip: DhTip | UnsetType = UNSET


def check(doc, source: str) -> None:
    """Refuse a table that is not a DhTable (types, ranges, required and unknown keys; keys starting
    with x- are free for annotations) or whose inertias are neither form: a one-line VampcError."""
    try:
        table = msgspec.convert(_annotations_dropped(doc), DhTable)
    except msgspec.ValidationError as exc:
        keys, what = _problem(doc, str(exc))
        raise located(source, where(keys), one_line(what)) from None
    for i, row in enumerate(table.joints):
        _check_inertia(doc, ("joints", i, "inertia"), row.inertia, source)
    if table.base is not UNSET and table.base.inertia is not UNSET:
        _check_inertia(doc, ("base", "inertia"), table.base.inertia, source)


def _check_inertia(doc, keys: tuple, value: list, source: str) -> None:
    """Six numbers or three rows of three: not a mixture, and not three numbers or six rows."""
    rows = sum(isinstance(x, list) for x in value)
    if not (rows == 0 and len(value) == 6 or rows == len(value) == 3):
        raise located(source, where(keys), one_line(f"{value_at(doc, keys)!r} {INERTIA_ERROR}"))


def _annotations_dropped(doc):
    """The table without its x- keys (at any depth: only mappings have keys)."""
    if isinstance(doc, dict):
        return {k: _annotations_dropped(v) for k, v in doc.items()
                if not (isinstance(k, str) and k.startswith("x-"))}
    if isinstance(doc, list):
        return [_annotations_dropped(v) for v in doc]
    return doc


_PATH = re.compile(r"\.([^.\[]+)|\[(\d+)\]")
_JSON_TYPES = {"float": "number", "int": "integer", "str": "string", "bool": "boolean",
               "array": "array", "object": "object", "null": "null"}


def _problem(doc, message: str) -> tuple[tuple, str]:
    """(keys, what) of a msgspec ValidationError's message: the place as the keys into the table,
    and the problem said as the schema's words say it ("-1.0 is less than the minimum of 0")."""
    text, _, at = message.partition(" - at `")
    if at.startswith("key` in `"):                  # "Expected `str` - at `key` in `$.base`"
        keys = _keys(at.removeprefix("key` in `"))
        return keys, _not_a_name(value_at(doc, keys))
    keys = _keys(at)
    m = re.fullmatch(r"Object (contains unknown|missing required) field `(.*)`", text)
    if m:
        if m.group(1) == "missing required":
            return keys, f'"{m.group(2)}" is a required property'
        return keys, f"Additional properties are not allowed ({m.group(2)!r} was unexpected)"
    # a union (a joint's parent, an inertia) is said in the schema's own words, at the union itself
    for k in range(len(keys)):
        if keys[k] in ("parent", "inertia") and (k == 1 or keys[0] == "joints" and k == 2):
            value = value_at(doc, keys[:k + 1])
            return keys[:k + 1], f"{value!r} " + (PARENT_ERROR if keys[k] == "parent" else INERTIA_ERROR)
    value = value_at(doc, keys)
    shown = _compact(value)
    if m := re.fullmatch(r"Invalid enum value .*", text):
        return keys, f'{shown} is not one of ["revolute", "prismatic"]'
    if m := re.fullmatch(r"Expected `(\w+)`, got `(\w+)`", text):
        return keys, f'{shown} is not of type "{_JSON_TYPES.get(m.group(1), m.group(1))}"'
    if m := re.fullmatch(r"Expected `\w+` >= (\S+)", text):
        return keys, f"{shown} is less than the minimum of {_plain(m.group(1))}"
    if m := re.fullmatch(r"Expected `(array|str)` of length ([<>])= (\d+)", text):
        n = int(m.group(3))
        unit = ("item" if m.group(1) == "array" else "character") + ("" if n == 1 else "s")
        return keys, f"{shown} has {'less' if m.group(2) == '>' else 'more'} than {n} {unit}"
    return keys, f"{shown}: {text[:1].lower()}{text[1:]}"


def _keys(at: str) -> tuple:
    """The keys of a msgspec path ("$.joints[2].mass`") into the table."""
    return tuple(int(i) if i else name for name, i in _PATH.findall(at.removeprefix("$").rstrip("`")))


def value_at(doc, keys: tuple):
    for key in keys:
        doc = doc[key]
    return doc


def _not_a_name(mapping) -> str:
    """What is wrong with a mapping one of whose keys is not text: that key, as YAML read it (the
    whole mapping had been quoted, cut at 300 characters in a big file, the key not named: a new
    user's find)."""
    key = next((k for k in mapping if not isinstance(k, str)), None) \
        if isinstance(mapping, dict) else None
    if key is None and not (isinstance(mapping, dict) and None in mapping):
        return f"a key of {_compact(mapping)} is not a string"
    shown = "null" if key is None else str(key).lower() if isinstance(key, bool) else repr(key)
    what = ("null" if key is None else "a truth value" if isinstance(key, bool) else
            "a number" if isinstance(key, (int, float)) else type(key).__name__)
    return f"the key {shown} is read as {what}, not a name (quote it: keys are text)"


def _compact(value) -> str:
    """A value as compact JSON (as the message quotes it), Python's repr if it is not JSON."""
    try:
        return jsontext.encode(jsontext.rendered(value), sort_keys=False)
    except (TypeError, ValueError):
        return repr(value)


def _plain(number: str) -> str:
    """msgspec's bound ("0.0") as the table would write it ("0")."""
    return number[:-2] if number.endswith(".0") else number


def where(keys: tuple) -> str:
    """A JSON path ("joints[2].com[1]") plus the 1-based joint number when it points into a row."""
    text = "".join(f"[{k}]" if isinstance(k, int) else f".{k}" for k in keys).lstrip(".")
    if len(keys) >= 2 and keys[0] == "joints" and isinstance(keys[1], int):
        text += f" (joint {keys[1] + 1})"
    return text


def schema() -> dict:
    """The JSON schema of a DH table, generated from DhTable (with the x- keys every mapping allows)."""
    out = msgspec.json.schema(DhTable)
    vec3 = {"type": "array", "items": {"type": "number"}, "minItems": 3, "maxItems": 3}
    for node in out["$defs"].values():
        node["patternProperties"] = {"^x-": {"description": "Free for annotations (vampc ignores it)."}}
        inertia = node["properties"].get("inertia")
        if inertia is not None:      # exactly: six numbers, or three rows of three (check_inertia)
            node["properties"]["inertia"] = {
                "description": inertia["description"], "x-error": INERTIA_ERROR, "oneOf": [
                    {"type": "array", "items": {"type": "number"}, "minItems": 6, "maxItems": 6},
                    {"type": "array", "items": vec3, "minItems": 3, "maxItems": 3}]}
    return {"$schema": "https://json-schema.org/draft/2020-12/schema",
            "$id": "https://vampc.invalid/schemas/dh-table.schema.json",
            "title": "vampc DH table", "description": (
                "A serial robot or a tree (rows naming their parent) in standard (distal) "
                "Denavit-Hartenberg form: A_i = Rz(theta_i) "
                "Tz(d_i) Tx(a_i) Rx(alpha_i). SI units (m, rad, kg, kg m^2). Vectors and matrices "
                "use numbers only (NaN and infinities are refused). Error messages locate a problem "
                "by its JSON path, 0-based as in the file (joints[0] is the first row), followed by "
                "the 1-based joint number of the paper, e.g. 'joints[2].mass (joint 3): -1 is less "
                "than the minimum of 0'."), **out}


if __name__ == "__main__":
    print(jsontext.dumps(schema(), indent=1, sort_keys=True))
