"""matplotlib, set up once for the report's pictures: imported only when a picture is asked for,
the SVG backend without pyplot (no global figure state), and deterministic output — a fixed hash
salt for the ids matplotlib derives, text kept as text (and never read as TeX), no date, a fixed
creator — so the same IRs give the same bytes and tests can compare pictures."""
from __future__ import annotations

import contextvars
import io
import re
from contextlib import contextmanager

DPI = 72            # SVG user units are points: one inch is 72 of them
SETTINGS = {"svg.hashsalt": "vampc", "svg.fonttype": "none", "svg.id": "vampc",
            "font.family": "DejaVu Sans", "font.size": 8.0, "axes.unicode_minus": True,
            "text.parse_math": False}     # (names are text: a robot named 'cost$_$' is not TeX)
METADATA = {"Date": None, "Creator": "vampc", "Format": None, "Type": None}
# A picture whose name ends so is drawn in that format instead (README "Report pictures"): the same
# drawing, without the SVG's tooltips; deterministic too (no date, no software version)
FORMATS = {".png": "png", ".pdf": "pdf"}
RASTER_DPI = 144             # a PNG's pixels per inch: twice the SVG's points
RASTER_MOST = 32000          # pixels along either side at most (the Agg renderer stops at 2^16)
OTHER_METADATA = {"png": {"Software": None},
                  "pdf": {"Creator": "vampc", "Producer": None, "CreationDate": None}}
_FORMAT = contextvars.ContextVar("vampc_picture_format", default="svg")


def format_of(path) -> str:
    """The format a picture named `path` is drawn in: "png", "pdf" or "svg" (any other name)."""
    name = str(path).lower()
    return next((fmt for end, fmt in FORMATS.items() if name.endswith(end)), "svg")


@contextmanager
def drawn_as(fmt: str):
    """Pictures drawn inside come out in `fmt` ("svg", "png", "pdf"): `to_svg` gives bytes for the
    last two."""
    token = _FORMAT.set(fmt)
    try:
        yield
    finally:
        _FORMAT.reset(token)


def rendered(fig, fmt: str) -> bytes:
    """The figure as PNG or PDF bytes, the same for the same drawing (no date, no version). A PNG
    is drawn at RASTER_DPI, less where a side would pass RASTER_MOST pixels (a big network's
    drawing: the SVG has no such limit)."""
    buf = io.BytesIO()
    width, height = fig.get_size_inches()
    dpi = min(RASTER_DPI, RASTER_MOST / max(width, height, 1e-9)) if fmt == "png" else DPI
    fig.savefig(buf, format=fmt, dpi=dpi, metadata=OTHER_METADATA[fmt])
    return buf.getvalue()


def figure(width_px: float, height_px: float):
    """A pyplot-free matplotlib Figure of the given size in SVG units (points)."""
    from matplotlib.figure import Figure
    return Figure(figsize=(width_px / DPI, height_px / DPI), dpi=DPI)


def cycle_axes(ticks: int, rows: float, row_pt: float, left: float, top: float, bottom: float,
               right: float, max_plot: float):
    """(figure, axes, points per tick, width, height) of a chart of one cycle: `ticks` across (at most
    `max_plot` points and at most 24 a tick, at least 600 points in all: room for the title and
    key), `rows` of `row_pt` points down, the first at the top; margins in points."""
    ptf = max(min(24.0, max_plot / ticks), 600.0 / ticks)
    width, height = left + ticks * ptf + right, top + rows * row_pt + bottom
    fig = figure(width, height)
    ax = fig.add_axes((left / width, bottom / height, ticks * ptf / width,
                       (height - top - bottom) / height))
    ax.set_xlim(0, ticks)
    ax.set_ylim(rows, 0)
    return fig, ax, ptf, width, height


_GLYPH = re.compile(r"Glyph (\d+) .*missing from font")
_SAID_GLYPHS: set[str] = set()       # (said once a run, whatever the pictures)


@contextmanager
def settings():
    """matplotlib's rc settings for a deterministic SVG, for the duration of one drawing; the
    characters its font lacks said in one warning (matplotlib's own, one a glyph and a picture, had
    printed 18 lines for a robot named in Japanese: a new user's find). Only those are taken aside:
    every other warning is shown as it would be (the shower is wrapped, not the filters changed)."""
    import warnings

    import matplotlib
    missing: list[str] = []
    shower = warnings.showwarning

    def show(message, category, filename, lineno, file=None, line=None):
        m = _GLYPH.search(str(message))
        if m is None:
            return shower(message, category, filename, lineno, file, line)
        missing.append(chr(int(m.group(1))))
    warnings.showwarning = show
    try:
        with matplotlib.rc_context(SETTINGS):
            yield
    finally:
        warnings.showwarning = shower
        new = [c for c in dict.fromkeys(missing) if c not in _SAID_GLYPHS]
        if new:
            from vampc.errors import VampcWarning
            _SAID_GLYPHS.update(new)
            warnings.warn(VampcWarning(
                f"the pictures' font (DejaVu Sans) has no {' '.join(new)}: an SVG keeps the text, "
                "which a browser shows in a font that has them; a PNG or PDF draws boxes"),
                stacklevel=3)


def to_svg(fig, titles: dict[str, str] | None = None) -> str | bytes:
    """The figure as SVG text (inside `drawn_as("png")` or "pdf": those bytes, `rendered`), with a <title> (a tooltip in browsers) added inside each group whose
    id is a key of `titles`. Paths of a collection that carry a link to `#ID` (matplotlib wraps each
    in an <a>) become groups with that id: the way to give thousands of bars drawn as one collection
    an id each."""
    for ax in fig.axes:       # a title longer than the figure (a long robot name) wraps at its
        for t in (ax.title, ax._left_title, ax._right_title):    # spaces, not off the edge
            # (not one with a '$': matplotlib measures the lines it wraps as maths, whatever
            # text.parse_math says, and '$_$' in a robot's name failed to parse)
            t.set_wrap("$" not in t.get_text())
    if _FORMAT.get() != "svg":
        return rendered(fig, _FORMAT.get())
    buf = io.StringIO()
    fig.savefig(buf, format="svg", metadata=METADATA)
    text = _links_to_groups(_round_paths(buf.getvalue()))
    if titles:
        text = _add_titles(text, titles)
    return text


def _links_to_groups(text: str) -> str:
    """Each linked shape a group named by its link; a name drawn again (an op in several pieces:
    an MM on its three VAMPs' rows, a bar wrapping past the interval) is suffixed -2, -3, ... so
    every id is unique (the pieces had shared one, which SVG does not allow: an audit's)."""
    if '<a xlink:href="#' not in text:
        return text
    seen: dict[str, int] = {}

    def group(m: re.Match) -> str:
        name = m.group(1)
        seen[name] = seen.get(name, 0) + 1
        return f'<g id="{name}">' if seen[name] == 1 else f'<g id="{name}-{seen[name]}">'
    text = re.sub(r'<a xlink:href="#([^"]+)"(?: target="_blank")?>', group, text)
    return text.replace("</a>", "</g>")


def _add_titles(text: str, titles: dict[str, str]) -> str:
    from xml.sax.saxutils import escape

    def title(m: re.Match) -> str:
        what = titles.get(m.group(1))
        if what is None and (piece := re.fullmatch(r"(.+)-\d+", m.group(1))):
            what = titles.get(piece.group(1))        # (a later piece of a shape: its title too)
        return m.group(0) if what is None else f'{m.group(0)}<title>{escape(what)}</title>'
    return re.sub(r'<g id="([^"]+)">', title, text)


def strip_prolog(svg: str) -> str:
    """The <svg> element alone (no XML declaration or DOCTYPE), to inline in HTML."""
    return svg[svg.index("<svg"):]


_ID = re.compile(r'(\sid=")([^"]+)"')
_REF = re.compile(r'(href="#|url\(#)([^")]+)')


def inline(svg: str, prefix: str) -> str:
    """The <svg> element alone (strip_prolog) with every id, and every reference to one (an
    xlink:href, a url(#...)), given `prefix`: a page of several pictures had hundreds of ids twice
    (matplotlib's figure_1, axes_1, ...; each picture's own `vampc`), invalid HTML whose links
    could land in another picture (a new user's find)."""
    body = strip_prolog(svg)
    body = _ID.sub(lambda m: f'{m.group(1)}{prefix}-{m.group(2)}"', body)
    return _REF.sub(lambda m: f"{m.group(1)}{prefix}-{m.group(2)}", body)


_PATH = re.compile(r' d="([^"]*)"')
_NUMBER = re.compile(r"-?\d+\.\d+")


def _short(m) -> str:
    text = f"{float(m.group()):.1f}"
    return text[:-2] if text.endswith(".0") else text


def _round_paths(text: str) -> str:
    """Path coordinates to a tenth of a point (matplotlib writes six decimals): a drawing of
    thousands of shapes is a third smaller and looks the same."""
    return _PATH.sub(lambda m: ' d="' + _NUMBER.sub(_short, m.group(1)) + '"', text)
