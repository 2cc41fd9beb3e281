"""The modulo reservation table (`vampc report --reservation`, issue "The report a hardware engineer
trusts", part 2): every op once, on its unit, at its start modulo the interval; no unit does two
things in one tick of the steady state (checked tick by tick here, not by the schedule's own
verifier); labels do not overlap; the HTML page carries it."""
from __future__ import annotations

import re
from collections import Counter

import pytest
from click.testing import CliRunner
from conftest import EXAMPLES
from overlap_util import catch_figure, overlapping_texts

from vampc.cli import main
from vampc.compiler import CompileOptions, compile_chain
from vampc.report import reservation
from vampc.robot import load_robot


@pytest.mark.parametrize("options", [dict(vamps=7, recursion="log"),
                                     dict(layout="folded", share_passes=True, recursion="log"), dict()],
                         ids=["log-budget7", "log-folded-shared", "systolic"])
def test_every_op_once_and_no_unit_does_two_things_at_once(options, monkeypatch):
    c = compile_chain(load_robot(EXAMPLES / "puma560.yaml"), CompileOptions(**options))
    P = c.schedule.interval
    rows = reservation.rows(c.graph, c.layout, c.schedule)
    seen = [i for _, ops in rows for i, *_ in ops]
    times = Counter(seen)                 # a budget's MM is on each of its three VAMPs' rows
    assert times == Counter({nd.id: 1 if c.layout.grouped else len(c.layout.placement[nd.id])
                             for nd in c.graph.compute_nodes()})
    for label, ops in rows:
        ticks = [(tick + t) % P for _, tick, d, _ in ops for t in range(d)]
        assert len(ticks) == len(set(ticks)), label             # one op per tick per unit
    for i, tick, _, k in (x for _, ops in rows for x in ops):
        assert k * P + tick == c.schedule.start[i]
    figures = catch_figure(monkeypatch)
    svg = reservation.reservation_svg(c.graph, c.layout, c.schedule, "t")
    if len(rows) <= reservation.MAX_ROWS:                    # else rows of several units, shaded
        assert all(f'id="res-{i}"' in svg for i in seen[:50])
    else:
        assert "units a row, shaded by how many are busy" in svg
    assert overlapping_texts(figures[0]) == []


def test_the_option_and_the_page(tmp_path):
    out, page = tmp_path / "r.svg", tmp_path / "p.html"
    r = CliRunner().invoke(main, ["report", str(EXAMPLES / "puma560.yaml"), "--vamps", "12",
                                  "--reservation", str(out), "--html", str(page)])
    assert r.exit_code == 0, r.output
    text = out.read_text()
    assert "modulo reservation table" in text and re.search(r"12 units × 27 ticks", text)
    assert page.read_text().count("<svg") == 3 and 'id="reservation"' in page.read_text()


def test_a_picture_named_otherwise_is_written_with_a_warning(tmp_path):
    """(.png and .pdf are drawn in those formats: tests/test_picture_formats.py)"""
    out = tmp_path / "r.jpg"
    r = CliRunner().invoke(main, ["report", str(EXAMPLES / "planar2.yaml"), "--reservation", str(out)])
    assert r.exit_code == 0 and "writes SVG, whatever the name says (name it .svg, or .png or " \
        ".pdf for that format)" in r.output
    assert out.read_text().lstrip().startswith("<?xml")


def test_a_grouped_tables_last_row_says_and_shades_the_units_it_holds(monkeypatch):
    """Every grouped row was labelled '(per)' and shaded out of `per` units, the last one too though
    it holds fewer: 1920 units in rows of 18 ended in a row of 12 labelled (18), fully busy ticks
    shaded two thirds."""
    c = compile_chain(load_robot(EXAMPLES / "puma560.yaml"), CompileOptions())
    units = len(reservation.rows(c.graph, c.layout, c.schedule))
    monkeypatch.setattr(reservation, "MAX_ROWS", 7)
    per = -(-units // 7)
    last = units - per * (-(-units // per) - 1)
    assert last < per                                        # (the case: a short last row)
    svg = reservation.reservation_svg(c.graph, c.layout, c.schedule, "t")
    labels = re.findall(r"… \((\d+)\)", svg)
    assert labels[:-1] == [str(per)] * (len(labels) - 1) and labels[-1] == str(last), labels
    # the shades have a key (a new user's find: they had none)
    for name in ("¼", "½", "¾", "all"):
        assert f"{name} of the row's units busy" in svg
