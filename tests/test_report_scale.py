"""Pictures at scale (issue "The report a hardware engineer trusts", part 3): every picture of a
512-joint log robot stays under about 2 000 px (1 500 pt) on its long side and 1 MB, keeps the
critical path, and no two labels overlap; the DOT is aggregated small enough for Graphviz; and the
Puma 560's pictures of every layout have no overlapping labels either. One 512-joint compile and
report (about 6 s of CPU): the only way to see the pictures at that size."""
from __future__ import annotations

import re

import pytest
from conftest import EXAMPLES
from overlap_util import catch_figure, overlapping_texts

from vampc.compiler import CompileOptions, compile_chain
from vampc.report import pictures
from vampc.robot import load_robot
from vampc.robot.random import random_chain

MAX_PT, MAX_BYTES = 1500, 1_000_000


def size(svg: str) -> tuple[float, float]:
    return tuple(float(x) for x in re.search(r'width="([0-9.]+)pt" height="([0-9.]+)pt"', svg).groups())


@pytest.mark.slow      # the run draws every picture of the Puma 560 (test_no_labels_overlap_...)
def test_every_picture_of_a_512_joint_log_robot_is_bounded_and_readable(monkeypatch):
    """The pictures only (the page around them is the report's tables: README, Report speed has the
    whole 512-joint page at 859 kB)."""
    from vampc.report.counts import summary
    c = compile_chain(random_chain(512, 5), CompileOptions(recursion="log"))
    rep = summary(c)
    figures = catch_figure(monkeypatch)
    out = pictures.make(c, rep, {"--timing", "--network", "--reservation", "--dot"})
    for name in ("--timing", "--network", "--reservation"):
        w, h = size(out[name])
        assert max(w, h) <= MAX_PT and len(out[name].encode()) < MAX_BYTES, (name, w, h)
    assert len(out["--dot"].encode()) < MAX_BYTES
    assert len(figures) == 3
    for fig in figures:
        assert overlapping_texts(fig) == []
    # the critical path: red bars joined in the chart, red-outlined nodes in the drawing
    assert "critical-path" in out["--timing"] and "; on the critical path</title>" in out["--network"]
    assert sum(f'op-{i}-critical' in out["--timing"] for i in c.schedule.critical_path) == \
        len(c.schedule.critical_path)
    # the DOT: one node per group, fewer than a thousand edges, the critical nodes red
    assert out["--dot"].startswith("// ") and out["--dot"].count("->") < 3000 and "color=red" in out["--dot"]
    # the drill-down: a range of positions, or the positions around a node, node by node
    focus = pictures.make(c, rep, {"--network"}, focus=(100, 110))["--network"]
    assert "positions 100 to 110 only" in focus and "site-bwd-" in focus and max(size(focus)) <= MAX_PT
    around = pictures.make(c, rep, {"--network"}, focus=("bwd", 300))["--network"]
    assert "around node bwd 300" in around and 'id="site-bwd-300"' in around
    assert 'id="site-bwd-250"' not in around


@pytest.mark.parametrize("options", [dict(), dict(layout="folded", share_passes=True, recursion="log"),
                                     dict(vamps=12)],
                         ids=["linear", "log-folded-shared", "budget12"])
def test_no_labels_overlap_in_the_pumas_pictures(options, monkeypatch):
    c = compile_chain(load_robot(EXAMPLES / "puma560.yaml"), CompileOptions(**options))
    from vampc.report.counts import summary
    figures = catch_figure(monkeypatch)
    pictures.make(c, summary(c), {"--timing", "--network"})
    for fig in figures:
        assert overlapping_texts(fig) == []


def test_focus_past_the_last_position_and_a_device_name(tmp_path):
    from click.testing import CliRunner

    from vampc.cli import main
    out = tmp_path / "f.svg"
    r = CliRunner().invoke(main, ["report", str(EXAMPLES / "puma560.yaml"), "--network", str(out),
                                  "--focus", "5:1000"])
    assert r.exit_code == 0 and "positions 5 to 6 only" in out.read_text()
    r = CliRunner().invoke(main, ["report", str(EXAMPLES / "puma560.yaml"), "--layout", "folded",
                                  "--network", str(out), "--focus", "bwd dev 0"])
    assert r.exit_code == 0 and "warning" not in r.output, r.output   # (it warned of "--focus 1:8",
    r = CliRunner().invoke(main, ["report", str(EXAMPLES / "puma560.yaml"),  # a range never typed)
                                  "--network", str(out), "--focus", "bwd 3"])
    assert r.exit_code == 0 and "warning" not in r.output, r.output
    r = CliRunner().invoke(main, ["report", str(EXAMPLES / "puma560.yaml"), "--network", str(out),
                                  "--focus", "bwd dev 0"])        # (systolic: node 0 is not drawn)
    # (with what it has: it said only "no node 0 in section bwd", a new user's find)
    assert r.exit_code == 2 and "this drawing has no node 0 in section bwd (its nodes there: bwd 1 " \
        "to 6)" in r.output, r.output
    r = CliRunner().invoke(main, ["report", str(EXAMPLES / "puma560.yaml"), "--layout", "folded",
                                  "--share-passes", "--network", str(out), "--focus", "fwd 0"])
    assert r.exit_code == 2 and "no node 0 in section fwd (its sections: bwd, npv)" in r.output, \
        r.output
    r = CliRunner().invoke(main, ["report", str(EXAMPLES / "puma560.yaml"), "--network", str(out),
                                  "--focus", "9:12"])
    assert r.exit_code == 2 and "--focus 9:12: no node there (positions 1 to 6)" in r.output


def test_a_groups_outputs_are_a_range_only_where_they_run_without_a_gap():
    """Grouped drawings labelled each group's torques by their lowest and highest ('τ1–64' for τ1,
    τ2 and τ64; neighbouring 'ranges' overlapped): a range only where they run without a gap, else
    how many, each named in the tooltip."""
    from vampc.report.network_drawing import network_svg
    from vampc.robot.random import random_chain as _chain
    c = compile_chain(_chain(40, 3), CompileOptions(recursion="log", layout="folded"))
    svg = network_svg(c.graph, c.layout, c.network, "t")
    titles = re.findall(r'<g id="tau-\d+"><title>([^<]+) \((\d+) outputs\) leave', svg)
    single = re.findall(r'<g id="tau-\d+"><title>τ\d+ leaves', svg)
    assert titles and sum(int(k) for _, k in titles) + len(single) == 40
    for said, k in titles:
        if "–" in said:
            lo, hi = (int(x.lstrip("τ")) for x in said.split("–"))
            assert hi - lo + 1 == int(k), said                       # a range: every one in it
        else:
            assert len(said.split(", ")) == int(k), said             # else each named
    assert any("–" not in said and int(k) > 1 for said, k in titles)  # (the case that was wrong)


def test_a_folded_devices_many_outputs_are_one_marker():
    """A folded layout's forward device gives every torque: one marker each, squeezed into its
    cell, overlapped from 16 joints (a smear at 32). More than PER_CELL get one marker together."""
    from vampc.report.network_drawing import PER_CELL, network_svg
    c = compile_chain(random_chain(20, 5), CompileOptions(layout="folded"))
    svg = network_svg(c.graph, c.layout, c.network, "t")
    outputs = re.findall(r'<g id="tau-(\d+)"><title>([^<]+)</title>', svg)
    assert len(outputs) <= PER_CELL and any("(20 outputs) leave" in t or "outputs) leave" in t
                                            for _, t in outputs), outputs


def test_a_long_robot_name_wraps_in_the_pictures_titles(tmp_path):
    """A long robot name ran the network and timing titles off the picture's right edge."""
    from click.testing import CliRunner

    from vampc.cli import main
    name = ("a robot with a very long name given by a careful engineer who likes to describe "
            "everything about the arm in its name field so that nobody forgets, not even about its "
            "wrist, its elbow, its shoulder and the base it stands on in the cell")
    robot = tmp_path / "long.yaml"
    robot.write_text((EXAMPLES / "planar2.yaml").read_text().replace("name: planar2", f'name: "{name}"'))
    res = CliRunner().invoke(main, ["report", str(robot), "--network", str(tmp_path / "n.svg"),
                                    "--timing", str(tmp_path / "t.svg")])
    assert res.exit_code == 0, res.stderr
    for picture in ("n.svg", "t.svg"):
        text = (tmp_path / picture).read_text()
        first = re.search(r">(a robot with[^<]*)<", text).group(1)     # the title's first line
        assert "a torque set every" not in first, (picture, first)         # (not the whole title)


@pytest.mark.parametrize("focus", ["fwd ٢", "bwd ３", "١:3", "1:1_0"])
def test_focus_in_other_scripts_digits_is_refused(tmp_path, focus):
    """'fwd ٢' was read as fwd 2 (\\d and int() take any script's digits), as the file readers and
    the other options do not."""
    from click.testing import CliRunner

    from vampc.cli import main
    r = CliRunner().invoke(main, ["report", str(EXAMPLES / "planar2.yaml"), "--network",
                                  str(tmp_path / "f.svg"), "--focus", focus])
    assert r.exit_code == 2 and "give A:B, two positions" in r.output, r.output
