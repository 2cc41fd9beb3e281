"""Tests: find the JSON schemas shipped with vampc, and check documents against them with an
independent validator (jsonschema-rs, a test dependency: vampc itself checks what it reads with the
typed records the program-file and DH-table schemas are generated from).

They live in the repository's `schemas/` folder; `vampc/schemas` is a symlink to it, so an installed wheel
carries them as package data (pyproject: `vampc = ["schemas/*.json"]`). A checkout whose symlink was lost
(e.g. a zip on Windows) still works through the repository fallback.
"""
from __future__ import annotations

import copy
from dataclasses import dataclass
from functools import lru_cache
from importlib import resources
from pathlib import Path

from vampc import jsontext
from vampc.errors import VampcInternalError

_REPO_SCHEMAS = Path(__file__).resolve().parent.parent / "schemas"


def load_schema(name: str) -> dict:
    """The parsed schema `name` ("dh-table", "dh-table.schema.json" or any file name in schemas/).

    Returns a fresh copy each call, so callers may not corrupt the cached original.
    """
    filename = name if name.endswith(".json") else f"{name}.schema.json"
    return copy.deepcopy(_cached(filename))


@dataclass(frozen=True)
class SchemaError:
    """Where and why a document breaks its schema: the path into the document (keys and indices),
    a one-line message, and the schema node that refused it."""

    path: tuple
    message: str
    schema: dict


def schema_errors(name: str, instance) -> list[SchemaError]:
    """Every way `instance` breaks schema `name` (same names as load_schema), in document order;
    empty when it is valid. jsonschema-rs (compiled and fast), for the quick verdict and the
    messages alike: it checks the DH tables people write, and the tests check reports against
    their schema. Program files are decoded into typed records instead (vampc.program.format). A value JSON has no type for (a YAML date, say) is reported as such."""
    validator = _quick_validator(name if name.endswith(".json") else f"{name}.schema.json")
    try:
        if validator.is_valid(instance):
            return []
        errors = list(validator.iter_errors(instance))
    except (ValueError, TypeError, OverflowError):   # not representable as JSON
        path, value = _not_json(instance, ())
        return [SchemaError(path, f"{value!r} is not a JSON value (a number, string, boolean, "
                                  "null, list or mapping)", {})]
    schema = _cached(name if name.endswith(".json") else f"{name}.schema.json")
    out = [SchemaError(tuple(e.instance_path), " ".join(e.message.split()),
                       _node(schema, list(e.schema_path)[:-1])) for e in errors]
    return sorted(out, key=lambda e: [(0, p, "") if isinstance(p, int) else (1, 0, str(p))
                                      for p in e.path])


def _node(schema: dict, path: list):
    """The schema node at a schema path (following local $refs is not needed: the path names the
    keywords as written)."""
    node = schema
    for key in path:
        try:
            node = node[key]
        except (KeyError, IndexError, TypeError):
            return {}
    return node if isinstance(node, dict) else {}


def _not_json(value, path: tuple):
    """(path, value) of the first value in `value` JSON has no type for."""
    if isinstance(value, dict):
        for k, v in value.items():
            if not isinstance(k, str):
                return path, k
            found = _not_json(v, path + (k,))
            if found is not None:
                return found
        return None
    if isinstance(value, list):
        for i, v in enumerate(value):
            found = _not_json(v, path + (i,))
            if found is not None:
                return found
        return None
    if value is None or isinstance(value, (str, bool, int, float)):
        return None
    return path, value


def _quick_validator(filename: str):
    return _quick_validator_at(filename, _version())


@lru_cache(maxsize=None)
def _quick_validator_at(filename: str, version):
    import jsonschema_rs
    return jsonschema_rs.validator_for(_cached_at(filename, version))


def _cached(filename: str) -> dict:
    return _cached_at(filename, _version())


def _version() -> tuple:
    """What the schemas take from the registries: the op table's names and ROM, the layouts."""
    from vampc.machine.ops import ROM, TABLE
    from vampc.schedule.registry import LAYOUTS
    return (len(ROM), tuple(op.value for op in TABLE), tuple(LAYOUTS))


@lru_cache(maxsize=None)
def _cached_at(filename: str, version) -> dict:
    return _with_registries(jsontext.loads(_read(filename)))


def _with_registries(schema):
    """The schema with its op names, ROM range and layout names taken from the op table
    (vampc.machine.ops) and the layout registry (vampc.schedule.registry), so an op or a layout
    registered there is valid in a program file: every enum of op names becomes the table's names
    (compute ops, and INPUT and CONST where it had them), a `rom` maximum the last ROM pointer, every
    enum of layout names the registry's."""
    from vampc.machine.ops import ROM, Op
    from vampc.schedule.registry import LAYOUTS
    if isinstance(schema, list):
        return [_with_registries(x) for x in schema]
    if not isinstance(schema, dict):
        return schema
    out = {k: _with_registries(v) for k, v in schema.items()}
    names = out.get("enum")
    if isinstance(names, list) and "VA" in names and "MTV" in names:
        keep = {"INPUT", "CONST"} & set(names)
        out["enum"] = [op.value for op in Op if op.is_compute or op.value in keep]
    if isinstance(names, list) and "systolic" in names and "folded" in names:
        out["enum"] = list(LAYOUTS)
    rom = out.get("properties", {}).get("rom")
    if isinstance(rom, dict) and "maximum" in rom:
        rom["maximum"] = len(ROM) - 1
    return out


def _read(filename: str) -> str:
    try:
        return resources.files("vampc").joinpath("schemas", filename).read_text(encoding="utf-8")
    except OSError:
        pass
    try:
        return (_REPO_SCHEMAS / filename).read_text(encoding="utf-8")
    except OSError as exc:
        # A missing schema is a packaging bug, not the user's fault.
        raise VampcInternalError(f"schema {filename!r} not found in the package or {_REPO_SCHEMAS}") from exc
