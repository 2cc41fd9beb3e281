"""A report table (title, columns, rows of text cells, notes) and its three renderings: aligned
plain text, Markdown and HTML. The report's sections (vampc.report.sections) build tables from the
report dictionary, so every format shows the same cells."""
from __future__ import annotations

import html
import re
import unicodedata
from dataclasses import dataclass


@dataclass(frozen=True)
class Table:
    """One table. `align` has one letter per column, 'l' or 'r' (default: first left, rest right).
    `key` names it (HTML anchor, tests)."""

    key: str
    title: str
    columns: tuple[str, ...]
    rows: tuple[tuple[str, ...], ...]
    notes: tuple[str, ...] = ()
    align: str = ""

    def alignment(self) -> str:
        """The align string, filled in."""
        return self.align or "l" + "r" * (len(self.columns) - 1)


def width(text: str) -> int:
    """Columns `text` takes in a terminal: combining marks take none (σ̄ is one column)."""
    return sum(0 if unicodedata.combining(ch) else 1 for ch in text)


def _pad(text: str, size: int, how: str) -> str:
    gap = " " * (size - width(text))
    return gap + text if how == "r" else text + gap


def render_text(t: Table) -> str:
    """Title, aligned columns two spaces apart, then notes as `  * ...` lines."""
    cells = [t.columns] + list(t.rows)
    sizes = [max(width(r[i]) for r in cells) for i in range(len(t.columns))]
    how = t.alignment()
    lines = [t.title]
    for r in cells:
        lines.append("  ".join(_pad(c, s, a) for c, s, a in zip(r, sizes, how)).rstrip())
    lines += [f"  * {n}" for n in t.notes]
    return "\n".join(lines) + "\n"


def _md(text: str) -> str:
    return text.replace("|", "\\|")


def render_markdown(t: Table) -> str:
    """A `###` heading, a pipe table and the notes as a list."""
    sep = ["---:" if a == "r" else "---" for a in t.alignment()]
    lines = [f"### {t.title}", "", "| " + " | ".join(map(_md, t.columns)) + " |",
             "|" + "|".join(sep) + "|"]
    lines += ["| " + " | ".join(map(_md, r)) + " |" for r in t.rows]
    if t.notes:
        lines += [""] + [f"- {_md(n)}" for n in t.notes]
    return "\n".join(lines) + "\n"


_SUBSCRIPT = re.compile(r"_\{([^{}<>]*)\}")


def html_text(text) -> str:
    """Text escaped for HTML, with the report's subscripts in braces set as subscripts:
    'z_{i-1}' -> 'z<sub>i−1</sub>' (a bare '_' stays: joint names have them)."""
    return _SUBSCRIPT.sub(lambda m: f"<sub>{m.group(1).replace('-', '−')}</sub>", html.escape(str(text)))


def render_html(t: Table) -> str:
    """A <section> with an <h3>, a <table> and the notes as a list."""
    esc = html_text
    how = t.alignment()
    head = "".join(f'<th class="{a}">{esc(c)}</th>' for c, a in zip(t.columns, how))
    body = "".join("<tr>" + "".join(f'<td class="{a}">{esc(c)}</td>' for c, a in zip(r, how))
                   + "</tr>\n" for r in t.rows)
    notes = ("<ul>" + "".join(f"<li>{esc(n)}</li>" for n in t.notes) + "</ul>") if t.notes else ""
    return (f'<section id="{esc(t.key)}"><h3>{esc(t.title)}</h3>\n<table><thead><tr>{head}</tr>'
            f"</thead>\n<tbody>\n{body}</tbody></table>{notes}</section>\n")
