"""The HTML page (vampc.report.html): self-contained — tables and both pictures inline, nothing to
fetch — and it opens in a browser (headless Chromium, when installed)."""
from __future__ import annotations

import re
import shutil
import subprocess

import pytest
from conftest import EXAMPLES

from vampc.compiler import CompileOptions, compile_chain
from vampc.report import pictures
from vampc.report.build import build_report
from vampc.report.sections import tables
from vampc.robot import load_robot

CHROMIUM = next((p for p in (shutil.which("chromium"), shutil.which("chromium-browser"),
                             shutil.which("google-chrome")) if p), None)


@pytest.fixture(scope="module")
def made():
    c = compile_chain(load_robot(EXAMPLES / "puma560.yaml"), CompileOptions(layout="folded"))
    rep = build_report(c, 20e6)
    return rep, pictures.make(c, rep, {"--html", "--timing", "--network"})


def test_the_page_holds_every_table_and_the_three_pictures(made):
    rep, out = made
    page = out["--html"]
    assert page.startswith("<!DOCTYPE html>") and page.count("<svg") == 3     # chart, drawing, table
    for t in tables(rep):
        assert f'<section id="{t.key}">' in page
    timing = out["--timing"][out["--timing"].index("<svg"):]
    # the same drawing, inline, its ids given the section's prefix (test_every_id_is_unique...)
    assert re.sub(r'(\sid="|href="#|url\(#)', r"\1timing-", timing) in page


def test_every_id_is_unique_and_every_reference_lands_in_its_own_picture(made):
    """Three pictures inline had 264 ids twice (matplotlib's figure_1, axes_1, ...; each picture's
    own root id), invalid HTML whose links could land in another picture (a new user's find)."""
    from collections import Counter
    from html.parser import HTMLParser

    class Ids(HTMLParser):
        def __init__(self):
            super().__init__()
            self.ids, self.refs, self.section = Counter(), [], None

        def handle_starttag(self, tag, attrs):
            attrs = dict(attrs)
            if tag == "section":
                self.section = attrs.get("id")
            if "id" in attrs:
                self.ids[attrs["id"]] += 1
            for key in ("href", "xlink:href"):
                if (attrs.get(key) or "").startswith("#"):
                    self.refs.append((self.section, attrs[key][1:]))
    page = made[1]["--html"]
    parser = Ids()
    parser.feed(page)
    assert [k for k, n in parser.ids.items() if n > 1] == []
    refs = parser.refs + [(None, r) for r in re.findall(r"url\(#([^)]+)\)", page)]
    assert refs and all(r in parser.ids for _, r in refs)
    assert all(r.startswith(f"{section}-") for section, r in parser.refs if section in
               ("timing", "network", "reservation"))


def test_nothing_is_fetched(made):
    page = made[1]["--html"]
    for attr in re.findall(r'(?:src|href)="([^"#][^"]*)"', page):
        pytest.fail(f"the page refers to {attr}")
    assert "<script" not in page and "@import" not in page and "url(http" not in page


@pytest.mark.skipif(CHROMIUM is None, reason="no headless Chromium installed")
@pytest.mark.parametrize("what", ["--html", "--timing", "--network"])
def test_it_opens_in_a_browser(made, what, tmp_path):
    from PIL import Image
    suffix = ".html" if what == "--html" else ".svg"
    page = tmp_path / f"page{suffix}"
    page.write_text(made[1][what], encoding="utf-8")
    shot = tmp_path / "shot.png"
    subprocess.run([CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
                    f"--screenshot={shot}", "--window-size=1000,800", page.as_uri()],
                   capture_output=True, timeout=120)
    assert shot.exists(), "Chromium wrote no screenshot"
    img = Image.open(shot).convert("L")
    colours = img.getcolors(maxcolors=1 << 16) or []
    assert len(colours) > 20                                     # not a blank page
    dark = sum(n for n, level in colours if level < 128)
    assert dark > 0.002 * img.width * img.height                 # text and lines drawn


def test_subscripts_are_set_as_subscripts_not_left_raw(made):
    """'z_{i-1}' in a note reads z<sub>i−1</sub> on the page; a joint name's underscore stays."""
    from vampc.report.table import html_text
    assert html_text("τ_i = z_{i-1}·n_i & wrist_roll") == "τ_i = z<sub>i−1</sub>·n_i &amp; wrist_roll"
    page = made[1]["--html"]
    assert "_{" not in page and "z<sub>i−1</sub>" in page
