"""`vampc report --tradeoff --curve FILE.svg`: the trade-off curve as SVG."""
from __future__ import annotations

import json
import xml.etree.ElementTree as ET

from click.testing import CliRunner
from conftest import EXAMPLES

from vampc.cli import main

PLANAR = EXAMPLES / "planar2.yaml"
SVG = "{http://www.w3.org/2000/svg}"


def run(*args):
    return CliRunner().invoke(main, [str(a) for a in args])


def test_the_curve_has_a_point_per_row_and_marks_the_pareto_ones(tmp_path):
    rows = json.loads(run("report", PLANAR, "--tradeoff", "--format", "json").stdout)["points"]
    first, second = tmp_path / "a.svg", tmp_path / "b.svg"
    for path in (first, second):
        res = run("report", PLANAR, "--tradeoff", "--curve", path)
        assert res.exit_code == 0, res.stderr
    assert first.read_bytes() == second.read_bytes()          # deterministic
    ids = {g.get("id") for g in ET.parse(first).getroot().iter(f"{SVG}g")}
    for panel in ("latency", "interval"):
        for i, r in enumerate(rows):
            want = f"{panel}-{i}" + ("-pareto" if r["pareto"] else "")
            assert want in ids, (want, r)
        assert f"{panel}-{len(rows)}" not in ids and f"{panel}-{len(rows)}-pareto" not in ids
    titles = [t.text for t in ET.parse(first).getroot().iter(f"{SVG}title")]
    systolic = next(r for r in rows if r["layout"] == "systolic")
    assert any(t.startswith(f"systolic: {systolic['vamps']} VAMPs, latency "
                            f"{systolic['latency_flops']} flops") for t in titles)


def test_curve_needs_tradeoff_and_never_replaces_the_input(tmp_path):
    res = run("report", PLANAR, "--curve", tmp_path / "c.svg")
    assert res.exit_code == 2 and "--curve applies with --tradeoff" in res.stderr
    copy = tmp_path / "arm.yaml"
    copy.write_bytes(PLANAR.read_bytes())
    res = run("report", copy, "--tradeoff", "--curve", copy)
    assert res.exit_code == 1 and "never writes over its inputs" in res.stderr
    assert copy.read_bytes() == PLANAR.read_bytes()
