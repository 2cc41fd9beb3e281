"""Pictures named .png or .pdf are drawn in that format (they were SVG under any name, with a
warning): the same drawing as the SVG, the same bytes for the same run, the HTML page still SVG."""
from __future__ import annotations

import re

import numpy as np
from click.testing import CliRunner
from conftest import EXAMPLES

from vampc.cli import main

PNG, PDF = b"\x89PNG\r\n\x1a\n", b"%PDF-"


def _run(*args):
    r = CliRunner().invoke(main, [str(a) for a in args])
    assert r.exit_code == 0, r.output
    assert "whatever the name says" not in r.output, r.output
    return r


def _points(svg_text: str) -> tuple[float, float]:
    """An SVG picture's width and height in points."""
    w, h = (float(re.search(rf'{k}="([\d.]+)pt"', svg_text).group(1)) for k in ("width", "height"))
    return w, h


def test_report_pictures_by_name(tmp_path):
    robot = EXAMPLES / "puma560.yaml"
    _run("report", robot, "--timing", tmp_path / "t.png", "--network", tmp_path / "n.pdf",
         "--reservation", tmp_path / "r.svg", "--html", tmp_path / "p.html")
    png, pdf = (tmp_path / "t.png").read_bytes(), (tmp_path / "n.pdf").read_bytes()
    assert png.startswith(PNG) and pdf.startswith(PDF)
    assert (tmp_path / "r.svg").read_text().lstrip().startswith("<?xml")
    page = (tmp_path / "p.html").read_text()
    assert page.count("<svg") == 3 and PNG.decode("latin-1") not in page
    # the same drawing as the SVG: its size in points at 144 pixels an inch (2 a point)
    _run("report", robot, "--timing", tmp_path / "t.svg", "--network", tmp_path / "n2.pdf",
         "--reservation", tmp_path / "r2.png")
    from matplotlib.image import imread
    height, width = imread(tmp_path / "t.png").shape[:2]
    w, h = _points((tmp_path / "t.svg").read_text())
    assert (width, height) == (round(2 * w), round(2 * h))
    # the same bytes again (no date, no software version in them)
    assert (tmp_path / "n2.pdf").read_bytes() == pdf
    assert b"CreationDate" not in pdf and b"Matplotlib" not in pdf
    assert b"Software" not in png[:4096] and (tmp_path / "r2.png").read_bytes().startswith(PNG)


def test_tradeoff_curve_and_lookahead_plot(tmp_path):
    _run("report", EXAMPLES / "planar2.yaml", "--tradeoff", "--curve", tmp_path / "c.pdf",
         "--html", tmp_path / "c.html")
    assert (tmp_path / "c.pdf").read_bytes().startswith(PDF)
    assert (tmp_path / "c.html").read_text().count("<svg") == 1
    program = tmp_path / "p.vamp.json"
    _run("compile", EXAMPLES / "puma560.yaml", "-o", program)
    _run("lookahead", program, "--trajectory", EXAMPLES / "puma560-path.csv", "--rate", "1kHz",
         "--window", "64", "--limits", EXAMPLES / "puma560-limits.csv", "--retime", "uniform",
         "--plot", tmp_path / "l.png")
    from matplotlib.image import imread
    img = imread(tmp_path / "l.png")
    assert (tmp_path / "l.png").read_bytes().startswith(PNG) and img.shape[0] > img.shape[1] > 500
    assert np.ptp(img[..., :3]) > 0.5           # (drawn on: not one colour)


def test_a_png_too_big_for_the_renderer_is_drawn_smaller():
    """The Agg renderer stops at 2^16 pixels a side; a picture wider than that at 144 pixels an
    inch (a lookahead --plot of some hundreds of joints is that tall) is drawn at fewer (the SVG has
    no such limit)."""
    from matplotlib.figure import Figure

    from vampc.report import svg
    fig = Figure(figsize=(600, 2), dpi=svg.DPI)           # 600 inches: 86 400 pixels at 144
    fig.add_axes((0, 0, 1, 1)).plot([0, 1], [0, 1])
    with svg.drawn_as("png"):
        data = svg.to_svg(fig)
    import io

    from matplotlib.image import imread
    height, width = imread(io.BytesIO(data)).shape[:2]
    assert svg.RASTER_MOST - 2 <= width <= svg.RASTER_MOST and abs(height - 2 * width / 600) <= 1
