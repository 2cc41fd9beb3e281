"""The program schema and the writer agree, both ways, key by key: every object the writer emits
(from the compiler's IRs) has exactly the properties the schema names for it where the schema names
them, and every property the schema requires — for documents of every layout, both recursions, a
budget, non-unit latencies, a tree and a floating base. Fast (a walk, no validator), so it runs on
every change to the writer, the IRs or the schema."""
from __future__ import annotations

import json

import pytest
from conftest import EXAMPLES

from vampc.compiler import CompileOptions, compile_chain, program_text
from vampc.robot import load_robot
from schema_check import load_schema, schema_errors

SCHEMA = load_schema("program")
CASES = [("planar2.yaml", {}, False), ("planar2.yaml", {"recursion": "log"}, False),
         ("planar2.yaml", {"layout": "folded", "share_passes": True}, False),
         ("planar2.yaml", {"vamps": 3}, False), ("planar2.yaml", {"mult_latency": 2}, True),
         ("quadruped.urdf", {}, False)]


def _resolve(node: dict) -> dict:
    while "$ref" in node:
        node = SCHEMA["$defs"][node["$ref"].rsplit("/", 1)[1]]
    return node


def _walk(doc, node: dict, where: str, seen: set) -> None:
    node = _resolve(node)
    for branch in node.get("oneOf", []) + node.get("anyOf", []):
        if not schema_errors_at(doc, branch):
            _walk(doc, branch, where, seen)
    if isinstance(doc, dict) and "properties" in node:
        props = set(node["properties"])
        extra = set(doc) - props
        if extra:
            seen.add(f"PROBLEM {where}: the writer emits {sorted(extra)}, which the schema does not name")
        missing = set(node.get("required", ())) - set(doc)
        if missing:
            seen.add(f"PROBLEM {where}: the schema requires {sorted(missing)}, which the writer omits")
        for key, value in doc.items():
            seen.add(f"{where}.{key}")
            if key in props:
                _walk(value, node["properties"][key], f"{where}.{key}", seen)
    if isinstance(doc, list) and isinstance(node.get("items"), dict):
        for value in doc[:50]:            # the rows of a list share one shape
            _walk(value, node["items"], f"{where}[]", seen)


def schema_errors_at(doc, node: dict) -> bool:
    """Whether `doc` breaks the schema `node` (a branch of a oneOf), by the one validator."""
    import jsonschema_rs
    return not jsonschema_rs.validator_for({**node, "$defs": SCHEMA["$defs"]}).is_valid(doc)


@pytest.mark.parametrize("robot,opts,floating", CASES,
                         ids=[f"{r}-{'-'.join(map(str, o.values())) or 'systolic'}"
                              for r, o, _ in CASES])
def test_the_writer_emits_what_the_schema_names(robot, opts, floating):
    chain = load_robot(EXAMPLES / robot, floating=floating)
    doc = json.loads(program_text(compile_chain(chain, CompileOptions(**opts))))
    doc["checksum"] = "sha256:" + "0" * 64
    assert not schema_errors("program", doc)
    seen: set = set()
    _walk(doc, SCHEMA, "document", seen)
    problems = sorted(p for p in seen if p.startswith("PROBLEM"))
    assert not problems, problems
    assert "document.network.vamps" in seen and "document.graph.nodes" in seen


def test_every_section_the_schema_requires_is_written():
    doc = json.loads(program_text(compile_chain(load_robot(EXAMPLES / "planar2.yaml"))))
    assert set(SCHEMA["$defs"]["ProgramFile"]["required"]) - {"checksum"} <= set(doc)


def test_the_shipped_schema_is_the_one_the_types_generate():
    """schemas/program.schema.json is generated from vampc.program.format's Structs (regenerate
    with `python -m vampc.program.format > schemas/program.schema.json`)."""
    from vampc.program.format import schema
    raw = json.loads((EXAMPLES.parent / "schemas" / "program.schema.json").read_text())
    assert raw == json.loads(json.dumps(schema())), "regenerate schemas/program.schema.json"


def test_the_schema_names_the_kinds_the_types_define():
    from vampc.kinds import Prefix, Quantity, Recursion, Section, TapKind
    defs = SCHEMA["$defs"]
    for kind in (Prefix, Quantity, Recursion, Section, TapKind):
        assert sorted(defs[kind.__name__]["enum"]) == sorted(kind.names())
    node = defs["NodeDoc"]["properties"]
    assert node["section"] == {"$ref": "#/$defs/Section"}
    # op and layout names come from registries a test may add to: strings here, checked on reading
    assert node["op"] == {"type": "string"}
    assert defs["LayoutDoc"]["properties"]["name"] == {"type": "string"}
