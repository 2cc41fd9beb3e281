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


def test_every_svg_group_id_is_unique_and_each_piece_has_its_tooltip(tmp_path):
    """An op drawn in pieces (a reservation bar wrapping past the interval; an MM on three VAMP rows
    of a budget's timing chart) had one group id per piece, the same (planar2's reservation table:
    14 ids twice; an audit's). Later pieces are -2, -3, each with the op's tooltip."""
    import collections
    import re as _re
    program = tmp_path / "b.vamp.json"
    from click.testing import CliRunner as _Runner

    from vampc.cli import main as _main
    assert _Runner().invoke(_main, ["compile", "examples/puma560.yaml", "--recursion", "log",
                                    "--vamps", "40", "-o", str(program)]).exit_code == 0
    for source, option in (("examples/planar2.yaml", "--reservation"), (str(program), "--timing"),
                           (str(program), "--reservation")):
        out = tmp_path / "p.svg"
        res = _Runner().invoke(_main, ["report", source, option, str(out)])
        assert res.exit_code == 0, res.output
        text = out.read_text()
        ids = _re.findall(r'<g id="([^"]+)">', text)
        assert [k for k, v in collections.Counter(ids).items() if v > 1] == []
        pieces = [i for i in ids if _re.fullmatch(r"(op|res)-\d+(-critical)?-\d+", i)]
        assert pieces, (source, option)
        for piece in pieces:
            base = piece.rsplit("-", 1)[0]
            first = _re.search(rf'<g id="{base}"><title>([^<]+)</title>', text)
            again = _re.search(rf'<g id="{piece}"><title>([^<]+)</title>', text)
            assert first and again and first.group(1) == again.group(1), piece


def test_characters_the_font_lacks_are_said_once(tmp_path):
    """A robot named in Japanese with an emoji printed matplotlib's own warning once a glyph and a
    picture, 18 lines for three pictures (a new user's find): one warning names them."""
    import re as _re

    from click.testing import CliRunner

    from vampc.cli import main
    from vampc.report import svg
    svg._SAID_GLYPHS.clear()
    robot = tmp_path / "jp.yaml"
    robot.write_text(_re.sub(r"(?m)^name: .*$", 'name: "ロボ腕 «ü» 🤖"',
                             (EXAMPLES / "planar2.yaml").read_text(), count=1))
    r = CliRunner().invoke(main, ["report", str(robot), "--timing", str(tmp_path / "t.svg"),
                                  "--network", str(tmp_path / "n.png"),
                                  "--reservation", str(tmp_path / "r.svg")])
    assert r.exit_code == 0, r.stderr
    said = [x for x in r.stderr.splitlines() if "font" in x or "Glyph" in x]
    assert said == ["vampc: warning: the pictures' font (DejaVu Sans) has no ロ ボ 腕 🤖: an SVG keeps "
                    "the text, which a browser shows in a font that has them; a PNG or PDF draws "
                    "boxes"], r.stderr
