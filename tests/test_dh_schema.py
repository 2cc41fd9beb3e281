"""The DH table's schema is generated from the typed records vampc checks tables with
(vampc.robot.dh_format), and an independent validator (jsonschema-rs) agrees with that check on the
shipped examples and on tables broken one way each."""
from __future__ import annotations

from pathlib import Path

import jsonschema_rs
import pytest
import yaml
from schema_check import load_schema, schema_errors

from vampc.errors import VampcError
from vampc.robot import dh_format

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
TABLES = sorted(p for p in EXAMPLES.iterdir() if p.suffix in (".yaml", ".yml"))


def test_the_schema_file_is_generated_from_the_records():
    assert load_schema("dh-table") == dh_format.schema()
    assert jsonschema_rs.meta.is_valid(load_schema("dh-table"))


@pytest.mark.parametrize("path", TABLES, ids=lambda p: p.name)
def test_every_example_table_is_valid_both_ways(path):
    doc = yaml.safe_load(path.read_text())
    assert not schema_errors("dh-table", doc)
    dh_format.check(doc, str(path))


def _row(**change):
    row = {"type": "revolute", "a": 0.1, "alpha": 0.0, "d": 0.0, "theta": 0.0, "mass": 1.0,
           "com": [0, 0, 0], "inertia": [1, 1, 1, 0, 0, 0]}
    return {k: v for k, v in {**row, **change}.items() if v is not None}


BROKEN = [
    {"name": "r", "joints": [_row(mass=-1)]},
    {"name": "r", "joints": [_row(type="helical")]},
    {"name": "r", "joints": [_row(inertia=[1, 2, 3])]},
    {"name": "r", "joints": [_row(inertia=[[1, 0, 0], [0, 1, 0], 0, 0, 0, 0])]},
    {"name": "r", "joints": [_row(parent=1.5)]},
    {"name": "r", "joints": [_row(parent="")]},
    {"name": "r", "joints": [_row(d=None)]},
    {"name": "r", "joints": [_row(masss=1)]},
    {"name": "r", "joints": [_row(limits={"q": [0]})]},
    {"name": "r", "joints": [_row(com=[0, 0, True])]},
    {"name": "r", "joints": []},
    {"name": "", "joints": [_row()]},
    {"joints": [_row()]},
    {"name": "r", "joints": [_row()], "tip": {"wrench": [0, 0, 0]}},
    {"name": "r", "joints": [_row()], "base": {"inertia": [[1, 0, 0], [0, 1, 0]]}},
    {"name": "r", "joints": [_row()], "gravity": [0, 0]},
]


@pytest.mark.parametrize("doc", BROKEN)
def test_a_broken_table_is_refused_both_ways(doc):
    assert schema_errors("dh-table", doc)
    with pytest.raises(VampcError):
        dh_format.check(doc, "r.yaml")


def test_annotations_are_free_both_ways():
    doc = {"name": "r", "x-note": 1, "joints": [_row(**{"x-cad": "a"})], "tip": {"x-by": "me"}}
    assert not schema_errors("dh-table", doc)
    dh_format.check(doc, "r.yaml")


@pytest.mark.parametrize("suffix", [".json", ".yaml"])
def test_a_table_with_a_byte_order_mark_reads_as_without(tmp_path, suffix):
    """A UTF-8 byte-order mark before a JSON table had been refused ("not valid JSON: invalid
    character (line 1, column 1)") while YAML's took it: an audit's."""
    from vampc.robot import load_robot
    text = Path("examples/planar2.yaml").read_text(encoding="utf-8")
    if suffix == ".json":
        import json
        text = json.dumps(yaml.safe_load(text))
    plain, marked = tmp_path / f"p{suffix}", tmp_path / f"m{suffix}"
    plain.write_text(text, encoding="utf-8")
    marked.write_bytes(b"\xef\xbb\xbf" + text.encode("utf-8"))
    a, b = load_robot(plain), load_robot(marked)
    assert [j.name for j in a.joints] == [j.name for j in b.joints] and a.n == b.n == 2
    assert all(x.mass == y.mass and (x.com == y.com).all() for x, y in zip(a.joints, b.joints))
