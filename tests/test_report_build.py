"""The whole report (vampc.report.build): valid against schemas/report.schema.json for every example
robot and configuration; for a general rotary 6-joint arm every number of Table O.1b and of the
section VI VAMP tables is reproduced and marked as matching the paper or differing, with the reason;
and a program file reports exactly what its robot does."""
from __future__ import annotations

import json

import jsonschema_rs
import pytest
from conftest import EXAMPLES, example_paths
from schema_check import load_schema, schema_errors

from vampc.compiler import CompileOptions, compile_chain, program_document
from vampc.program.document import compiled_from_doc
from vampc.report import pictures
from vampc.report.build import build_report
from vampc.robot import load_robot
from vampc.robot.random import random_chain

LAYOUTS = [dict(), dict(layout="folded"), dict(layout="folded", share_passes=True)]
CONFIGS = ([dict(recursion="linear", **x) for x in LAYOUTS] + [dict(recursion="log", **x) for x in LAYOUTS]
           + [dict(recursion="log", uniform_leaves=True, **LAYOUTS[1])])


def valid(rep: dict) -> dict:
    """The report as JSON text read back (what --format json prints), checked against the schema."""
    doc = json.loads(json.dumps(rep))
    errors = schema_errors("report", doc)
    assert not errors, [f"{list(e.path)}: {e.message}" for e in errors[:5]]
    return doc


def test_the_schema_is_a_valid_schema():
    assert jsonschema_rs.meta.is_valid(load_schema("report"))


@pytest.mark.parametrize("opts", CONFIGS, ids=lambda o: "-".join(str(v) for v in o.values()))
@pytest.mark.parametrize("path", [p for p in example_paths() if p.name != "snake64.yaml"],
                         ids=lambda p: p.name)
def test_every_example_and_configuration_validates(path, opts):
    valid(build_report(compile_chain(load_robot(path), CompileOptions(**opts)), 2e7, 64))


@pytest.mark.parametrize("opts", [dict(), dict(recursion="log", layout="folded")],
                         ids=["linear", "log-folded"])
def test_the_64_joint_example_validates(opts):
    c = compile_chain(load_robot(EXAMPLES / "snake64.yaml"), CompileOptions(**opts))
    rep = valid(build_report(c))
    assert rep["allocation"]["scheduled_only"] == [] and rep["allocation"]["omitted"] == []


def test_a_big_robot_leaves_out_what_would_compile_it_again(monkeypatch):
    import vampc.report.build as build
    import vampc.report.configs as configs
    monkeypatch.setattr(build, "ALLOCATE_LIMIT", 10)
    monkeypatch.setattr(configs, "ALLOCATE_LIMIT", 10)
    rep = valid(build_report(compile_chain(random_chain(3, 2), CompileOptions(recursion="log"))))
    assert "prefix_comparison" not in rep and rep["allocation"]["omitted"] == ["prefix_comparison",
                                                                             "other leaf style"]
    assert len(rep["allocation"]["scheduled_only"]) == 5 and len(rep["processors"]["vamps"]) == 2
    assert "buffer_stages" not in rep["layout_comparison"][1]
    from vampc.report.sections import layouts
    note, = layouts(rep).notes      # the linear rows are small, yet not allocated: said why
    assert rep["allocation"]["ops"] > 10 and f"the report's own: {rep['allocation']['ops']:,}" in note
    assert "its graph and the report's own each have at most 10 ops" in note


@pytest.fixture(scope="module")
def rotary6():
    """A general 6-joint rotary arm (random frames, masses and inertias, all joints revolute)."""
    c = compile_chain(random_chain(6, 21, prismatic_fraction=0.0),
                      CompileOptions(recursion="log", uniform_leaves=True))
    return valid(build_report(c)), c


def test_rotary6_reproduces_table_o1b(rotary6):
    rows = {r["key"]: r for r in rotary6[0]["table_o1"]["formulas"]}
    printed = {"uicker_kahn": (66271, 51548), "waters": (7051, 5652), "hollerbach_4x4": (4388, 3586),
               "hollerbach_3x3": (2195, 1719), "luh_walker_paul": (852, 738),
               "horn_raibert": (468, 264), "luh_lin": (323, 280), "lathrop_linear": (15, 43),
               "lathrop_log": (11, 28), "lathrop_systolic": (1, 3)}
    for key, (m, a) in printed.items():
        p = rows[key]["printed_n6"]
        assert (p["mults"], p["adds"]) == (m, a)
        assert p["matches"] == ((rows[key]["mults"], rows[key]["adds"]) == (m, a))
        assert p["note"] == "formula and printed value agree" if p["matches"] else p["note"]
    assert sorted(k for k, r in rows.items() if not r["printed_n6"]["matches"]) == \
        ["luh_lin", "uicker_kahn", "waters"]


def test_rotary6_measured_rows_beside_the_paper(rotary6):
    rows = {r["configuration"]: r for r in rotary6[0]["table_o1"]["measured"]}
    assert {k for k in rows} >= {"linear graph, serial work", "log graph, serial work",
                                 "linear, systolic", "log, folded, shared passes"}
    # latency: the paper's formula + the output correction (+ 2 A for uniform leaves)
    assert (rows["linear, systolic"]["mults"], rows["linear, systolic"]["adds"]) == (15 + 1, 43 + 2)
    assert (rows["log, systolic"]["mults"], rows["log, systolic"]["adds"]) == (11 + 1, 28 + 4)
    for r in rows.values():
        assert r["note"]                    # every row says why it differs (or what it is)


def test_rotary6_section_vi_tables_marked(rotary6):
    for variant in rotary6[0]["processors"]["vamps"]:
        for row in variant["rows"]:
            assert row["note"] == "matches the paper" or row["note"].startswith("differs in "), row
    uniform = next(v for v in rotary6[0]["processors"]["vamps"] if v["leaves"] == "uniform")
    assert {r["section"]: r["note"] == "matches the paper" for r in uniform["rows"]} == \
        {"bwd": True, "npv": True, "bwd_total": True, "fwd": False}


def test_a_program_reports_what_its_robot_does(rotary6):
    rep, c = rotary6
    from_file = compiled_from_doc(program_document(c), "x.vamp.json")
    assert valid(build_report(from_file)) == rep
    wanted = {"--timing", "--network", "--dot"}
    assert pictures.make(from_file, rep, wanted) == pictures.make(c, rep, wanted)


@pytest.mark.parametrize("recursion", ["linear", "log"])
def test_the_report_says_which_part_it_is_working_on(recursion):
    """A report of an 8000-joint chain took 13 s after the compile's progress bar ended, saying
    nothing (a new user's find): build_report names each part as it starts (the progress bar's
    stages), in order, the same report either way."""
    from vampc.report.build import REPORT_STAGES
    c = compile_chain(random_chain(5, 2), CompileOptions(recursion=recursion))
    said = []
    rep = build_report(c, stage=said.append)
    assert said == [s for s in REPORT_STAGES if recursion == "log" or s != "prefix shapes"]
    assert json.dumps(rep, sort_keys=True) == json.dumps(build_report(c), sort_keys=True)
