"""`vampc report --tradeoff --curve FILE.svg`: the trade-off curve as SVG."""
from __future__ import annotations

import json
import re
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
            want = f"{panel}-{i}" + ("-pareto" if r[f"pareto_{panel}"] else "")
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


def test_each_panel_marks_its_own_front_and_ticks_are_integers(tmp_path):
    """In four dimensions almost every point is optimal (planar2: 25 of 26); each panel's
    two-dimensional front is what it marks (fewer points), with a staircase, and its tick labels are
    whole numbers."""
    import re
    out = tmp_path / "c.svg"
    res = run("report", PLANAR, "--tradeoff", "--curve", out, "--format", "json")
    assert res.exit_code == 0, res.stderr
    rows = json.loads(res.stdout)["points"]
    root = ET.parse(out).getroot()
    ids = {g.get("id") for g in root.iter(f"{SVG}g")}
    for panel in ("latency", "interval"):
        marked = sum(1 for i in range(len(rows)) if f"{panel}-{i}-pareto" in ids)
        assert marked == sum(r[f"pareto_{panel}"] for r in rows)
        assert f"{panel}-front" in ids
    assert sum(r["pareto_latency"] for r in rows) < sum(r["pareto"] for r in rows)
    ticks = [t.text.strip() for t in root.iter(f"{SVG}text") if t.text and re.fullmatch(r"[0-9.,]+", t.text.strip())]
    assert ticks and all(re.fullmatch(r"[0-9]{1,3}(,[0-9]{3})*", t) for t in ticks), ticks


def test_html_with_tradeoff_is_a_page_of_the_table_and_the_curve(tmp_path):
    page, curve = tmp_path / "t.html", tmp_path / "c.svg"
    res = run("report", PLANAR, "--tradeoff", "--html", page, "--curve", curve, "--format", "json")
    assert res.exit_code == 0, res.stderr
    rows = json.loads(res.stdout)["points"]
    text = page.read_text()
    assert text.startswith("<!DOCTYPE html>") and text.count("<svg") == 1
    assert text.count("<tr>") == len(rows) + 1                     # the header and a row per point
    svg = curve.read_text()[curve.read_text().index("<svg"):]
    assert re.sub(r'(\sid="|href="#|url\(#)', r"\1curve-", svg) in text     # (ids prefixed)
    res = run("report", PLANAR, "--tradeoff", "--timing", tmp_path / "x.svg")
    assert res.exit_code == 2 and "--timing does not apply to --tradeoff (--html and --curve do)" in res.stderr


def test_the_floor_is_on_the_axis_and_the_legend_shows_what_is_drawn(monkeypatch):
    """The flat part of the front had no value on the axis (the Puma's 61: no 1-2-5 tick there), and
    the legend drew the layouts as filled squares while dominated ones are hollow."""
    from overlap_util import catch_figure, overlapping_texts

    from vampc.report.tradeoff_chart import curve_svg
    rows = [{"layout": "budget 2", "vamps": 2, "latency_flops": 90, "interval_flops": 60,
             "latency_bound": 80, "interval_bound": 50, "buffer_stages": 1, "pareto": True,
             "pareto_latency": True, "pareto_interval": True},
            {"layout": "budget 9", "vamps": 9, "latency_flops": 61, "interval_flops": 17,
             "latency_bound": 61, "interval_bound": 15, "buffer_stages": 3, "pareto": True,
             "pareto_latency": True, "pareto_interval": True},
            {"layout": "systolic", "vamps": 180, "latency_flops": 61, "interval_flops": 4,
             "latency_bound": 61, "interval_bound": 4, "buffer_stages": 9, "pareto": True,
             "pareto_latency": False, "pareto_interval": True}]
    figures = catch_figure(monkeypatch)
    svg = curve_svg(rows, "puma: linear recursion, 6 joints")
    labels = [t.get_text() for t in figures[0].axes[0].get_yticklabels(minor=True) if t.get_text()]
    assert labels == ["61"], labels
    legend = [t.get_text() for t in figures[0].legends[0].get_texts()]
    assert "folded / systolic layout, dominated" in legend
    assert overlapping_texts(figures[0]) == []
    assert "61" in svg


def test_a_budget_slower_than_one_with_fewer_vamps_is_explained():
    """A one-joint chain's budget 3 has latency 40, budget 2's 28: each budget runs at its smallest
    interval (the documented rule), and the table gave no hint of it."""
    from vampc.report.tradeoff import render_text
    rows = [{"layout": f"budget {v}", "vamps": v, "latency_flops": lat, "latency_bound": 21,
             "latency_gap_pct": 0.0, "interval_flops": 10, "interval_bound": 10,
             "interval_gap_pct": 0.0, "buffer_stages": 1, "control_registers": 1, "mux_inputs": 1,
             "host_writes_per_set": 1, "pareto": True, "pareto_latency": True,
             "pareto_interval": True} for v, lat in ((1, 50), (2, 28), (3, 40), (4, 21))]
    text = render_text(rows)
    assert text.splitlines()[-1].startswith("budget 3: latency 40 flops, longer than budget 2's 28 "
                                            "with fewer VAMPs: each budget is scheduled at the "
                                            "smallest interval the search reaches near its bound (as "
                                            "`--vamps` does: README, VAMP budgets); `vampc compile "
                                            "--vamps 3 --interval I`")
    # the Markdown table and the HTML page say it too (they had left it out: a new user's find)
    from vampc.report.html import tradeoff_page
    from vampc.report.tradeoff import render_markdown
    said = text.splitlines()[-1]
    assert render_markdown(rows).splitlines()[-1] == said
    import html as h
    assert h.escape(said.replace("`", "")) in tradeoff_page(rows, "one joint", "<svg/>")
    rows[2]["latency_flops"] = 25
    assert "longer than" not in render_text(rows) + render_markdown(rows) + \
        tradeoff_page(rows, "one joint", "<svg/>")
