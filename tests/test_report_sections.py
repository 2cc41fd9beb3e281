"""The report's tables (vampc.report.sections), built from the report dictionary."""
from __future__ import annotations

import pytest
from conftest import EXAMPLES

from vampc.compiler import CompileOptions, compile_chain
from vampc.report.build import build_report
from vampc.report.sections import num, signed, tables
from vampc.robot import load_robot


@pytest.fixture(scope="module")
def rep():
    c = compile_chain(load_robot(EXAMPLES / "puma560.yaml"), CompileOptions(layout="folded"))
    return build_report(c, clock_hz=20e6, pins=64)


def test_numbers():
    assert [num(x) for x in (None, 0, 66271, 1437 + 1 / 3, 3.0)] == ["—", "0", "66,271", "1,437.3", "3"]
    assert [signed(x) for x in (0, 3, -96, 1026)] == ["0", "+3", "−96", "+1,026"]


def test_every_table_is_there_with_rows_as_wide_as_its_columns(rep):
    got = tables(rep)
    assert [t.key for t in got] == ["o1-formulas", "o1-at-n", "o1-measured", "layouts",
                                    "vamps-linear-linear", "vamps-log-separate", "vamps-log-uniform",
                                    "vamps-by-op", "ops-per-node", "packages", "buffering", "wiring",
                                    "engineering", "clock"]
    for t in got:
        assert t.rows and all(len(r) == len(t.columns) == len(t.alignment()) for r in t.rows), t.key


def test_o1_at_n_marks_every_row(rep):
    t = next(t for t in tables(rep) if t.key == "o1-at-n")
    checks = [r[5] for r in t.rows]
    assert checks.count("agrees") == 7
    assert [c for c in checks if c != "agrees"] == [f"differs: note {k}" for k in (1, 2, 3)]
    assert len(t.notes) == 3 and t.columns[-1] == "time at 20 MHz"   # 5.935 ms down to 200 ns


def test_the_own_configuration_is_marked(rep):
    t = next(t for t in tables(rep) if t.key == "o1-measured")
    assert [r[0] for r in t.rows if "(this report)" in r[0]] == ["linear, folded (this report)"]


def test_packages_show_the_pins_asked_for(rep):
    t = next(t for t in tables(rep) if t.key == "packages")
    assert "64 pins, 8 each" in t.columns and "64 pins, 20 each" in t.columns
    assert any("11 such 40-pin packages" in n for n in t.notes)


def test_the_log_buffering_between_nodes_has_the_papers_figure_beside_it():
    """Section VI: 'Buffering between nodes ... requires about 54 scalars per node in the
    logarithmic case (if outputs are latched, this can nearly be halved)' stood as '—' in the log
    report's Buffering table, whose title says every figure of the paper is beside its measure (an
    audit). The measured counterpart, the vectors into a node, comes from the wiring figures."""
    import json

    from click.testing import CliRunner
    from conftest import EXAMPLES

    from vampc.cli import main

    def run(*extra):
        r = CliRunner().invoke(main, ["report", str(EXAMPLES / "puma560.yaml"), *extra])
        assert r.exit_code == 0, r.output
        return r.output
    text = run("--recursion", "log")
    table = text.split("\nBuffering (section VI)")[1].split("\nWiring")[0]
    assert table.count("≈ 54 scalars a node (note)") == 2
    between = json.loads(run("--recursion", "log", "--format", "json"))["wiring"]["buses"]["between_nodes"]
    assert (f"measured, at most {between['bwd']['vectors']} vectors ({3 * between['bwd']['vectors']} "
            "scalars) into a backward node") in table
    linear = run().split("\nBuffering (section VI)")[1].split("\nWiring")[0]
    assert "54 scalars" not in linear


def test_two_pin_budgets_with_the_same_vamps_a_package_have_different_headings():
    """At --pins 8 both of the paper's budgets put 1 VAMP in a package, and the packages table had
    two columns headed '8 pins, 1 each' (an audit): they now say which is which."""
    from click.testing import CliRunner
    from conftest import EXAMPLES

    from vampc.cli import main

    r = CliRunner().invoke(main, ["report", str(EXAMPLES / "puma560.yaml"), "--pins", "8"])
    assert r.exit_code == 0, r.output
    head = r.output.split("\nPackages (section VII)")[1].splitlines()[1]
    assert "8 pins, 1 each sep." in head and "8 pins, 1 each shared" in head
    assert "40 pins, 5 each " in head and "sep. " not in head.split("8 pins")[0]


def test_the_prefix_table_of_a_layout_that_waits_adds_up():
    """The folded log Puma's prefix table had '44' beside '12 + 30' (its 2 flops waiting for busy
    VAMPs left out: a review's find): the rows carry their waits and the column adds them, and
    each row's latency is the sum of its terms."""
    import json

    from click.testing import CliRunner
    from conftest import EXAMPLES

    from vampc.cli import main

    def run(*extra):
        r = CliRunner().invoke(main, ["report", str(EXAMPLES / "puma560.yaml"), "--recursion", "log",
                                      *extra])
        assert r.exit_code == 0, r.output
        return r.output
    rows = json.loads(run("--layout", "folded", "--format", "json"))["prefix_comparison"]
    assert all(r["latency_flops"] == r["mults"] + r["adds"] + r["waits"] for r in rows)
    assert any(r["waits"] for r in rows)
    table = run("--layout", "folded").split("\nPrefix shapes")[1].split("\n\n")[0].splitlines()
    assert "= M + A + wait" in table[1]
    for r in rows:
        line = next(x for x in table if x.startswith(r["prefix"] + " "))
        assert f"{r['mults']} + {r['adds']} + {r['waits']}" in line
    systolic = run().split("\nPrefix shapes")[1].split("\n\n")[0]
    assert "= M + A " in systolic and "wait" not in systolic


def test_a_trees_counts_of_one_are_singular(tmp_path):
    """'1 leaves', '1 heavy paths' on a leg taken alone (a trees audit)."""
    from click.testing import CliRunner

    from vampc.cli import main
    inertial = ('<inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" '
                'ixz="0" iyz="0"/></inertial>')
    path = tmp_path / "one.urdf"
    path.write_text(f'<robot name="one"><link name="base">{inertial}</link><link name="a">{inertial}'
                    '</link><joint name="j" type="revolute"><parent link="base"/><child link="a"/>'
                    '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/>'
                    '</joint></robot>')
    r = CliRunner().invoke(main, ["report", str(path), "--floating-base"])
    assert r.exit_code == 0, r.output
    line = next(x for x in r.output.splitlines() if x.startswith("tree "))
    assert "1 joint, 1 leaf, height 1" in line and "1 heavy path, at most 0 light edges" in line, line
