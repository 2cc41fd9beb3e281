"""Report tables (vampc.report.table): aligned text, Markdown and HTML renderings of one table."""
from __future__ import annotations

from vampc.report.table import Table, render_html, render_markdown, render_text, width

T = Table("t", "A title", ("name", "n", "note"), (("σ̄ row", "1,234", "a|b"), ("long name", "5", "<x>")),
          ("first note",), align="lrl")


def test_width_ignores_combining_marks():
    assert width("σ̄") == 1 and width("q̇q̈") == 2 and width("abc") == 3


def test_text_columns_line_up_even_with_combining_marks():
    lines = render_text(T).splitlines()
    assert lines[0] == "A title"
    assert lines[1:4] == ["name           n  note", "σ̄ row      1,234  a|b", "long name      5  <x>"]
    assert lines[4] == "  * first note"


def test_markdown_escapes_pipes_and_aligns_numbers_right():
    md = render_markdown(T).splitlines()
    assert md[0] == "### A title" and md[3] == "|---|---:|---|"
    assert md[4] == r"| σ̄ row | 1,234 | a\|b |"
    assert md[-1] == "- first note"


def test_html_escapes_and_keeps_alignment_classes():
    h = render_html(T)
    assert '<section id="t"><h3>A title</h3>' in h
    assert "<td class=\"l\">&lt;x&gt;</td>" in h and '<td class="r">1,234</td>' in h
    assert "<li>first note</li>" in h
