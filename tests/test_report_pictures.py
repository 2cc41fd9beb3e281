"""The pictures of one report (vampc.report.pictures): what each output option gets."""
from __future__ import annotations

from conftest import EXAMPLES

from vampc.compiler import compile_chain
from vampc.report import pictures
from vampc.report.build import build_report
from vampc.robot import load_robot


def test_only_what_is_asked_for_and_each_drawing_once(monkeypatch):
    c = compile_chain(load_robot(EXAMPLES / "planar2.yaml"))
    rep = build_report(c)
    drawn = []
    for name in ("timing", "network", "dot"):
        real = getattr(pictures, name)
        monkeypatch.setattr(pictures, name, lambda c, rep, *more, real=real, name=name:
                            drawn.append(name) or real(c, rep, *more))
    assert set(pictures.make(c, rep, {"--dot"})) == {"--dot"} and drawn == ["dot"]
    drawn.clear()
    out = pictures.make(c, rep, {"--html", "--timing"})
    assert set(out) == {"--html", "--timing"}
    assert sorted(drawn) == ["network", "timing"]
    drawn.clear()       # a PNG's drawing is not the page's SVG: drawn for each
    out = pictures.make(c, rep, {"--html": "p.html", "--timing": "t.png"})
    assert out["--timing"].startswith(b"\x89PNG") and "<svg" in out["--html"]
    assert sorted(drawn) == ["network", "timing", "timing"]


def test_title_names_robot_layout_latency_and_interval():
    c = compile_chain(load_robot(EXAMPLES / "planar2.yaml"))
    assert pictures.title(build_report(c)) == ("planar2, 2 joints, linear recursion, systolic layout: "
                                              "latency 29 flops, a torque set every 4")
