"""The SVG helper (vampc.report.svg): deterministic output, ids through links, tooltips."""
from __future__ import annotations

import xml.etree.ElementTree as ET

from vampc.report import svg

SVG = "{http://www.w3.org/2000/svg}"


def _picture() -> str:
    from matplotlib.collections import PolyCollection
    from matplotlib.patches import Rectangle
    with svg.settings():
        fig = svg.figure(200, 100)
        ax = fig.add_axes((0, 0, 1, 1))
        r = Rectangle((0.1, 0.1), 0.2, 0.2)
        r.set_gid("box")
        ax.add_artist(r)
        ax.add_collection(PolyCollection([[(0, 0), (1, 0), (1, 1)], [(0, 0), (0, 1), (1, 1)]],
                                         urls=["#one", "#two"]))
        ax.text(0.5, 0.5, "ü & <")
        return svg.to_svg(fig, {"box": "a box", "two": "the second"})


def test_the_same_figure_gives_the_same_bytes():
    a, b = _picture(), _picture()
    assert a == b and "<dc:date>" not in a and "font-family" in a      # text kept as text


def test_links_become_groups_and_titles_are_added():
    root = ET.fromstring(_picture())
    groups = {g.get("id"): g for g in root.iter(f"{SVG}g") if g.get("id")}
    assert {"one", "two", "box"} <= set(groups)
    assert groups["two"].find(f"{SVG}title").text == "the second"
    assert groups["box"].find(f"{SVG}title").text == "a box"
    assert not list(root.iter(f"{SVG}a"))


def test_strip_prolog():
    assert svg.strip_prolog('<?xml version="1.0"?>\n<!DOCTYPE svg>\n<svg x="1"/>') == '<svg x="1"/>'
