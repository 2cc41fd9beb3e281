"""Text boxes of a matplotlib figure that intersect (for the pictures' tests): the figure is caught as
vampc.report.svg.to_svg receives it, drawn, and every visible text's window extent compared."""
from __future__ import annotations

import numpy as np


def overlapping_texts(fig, slack: float = 0.5) -> list[tuple[str, str]]:
    """Pairs of visible, non-empty texts whose boxes (shrunk by `slack` points each side) meet."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    renderer = FigureCanvasAgg(fig).get_renderer()
    fig.draw(renderer)                    # places the annotations and the legend
    from matplotlib.text import Text
    found = fig.findobj(Text)
    texts = list({id(t): t for t in found
                  if t.get_visible() and t.get_text().strip() and t.get_figure() is fig}.values())
    if len(texts) < 2:
        return []
    boxes = np.array([t.get_window_extent(renderer).extents for t in texts]) + [slack, slack, -slack, -slack]
    x0, y0, x1, y1 = boxes.T
    meet = ((x0[:, None] < x1[None, :]) & (x0[None, :] < x1[:, None])
            & (y0[:, None] < y1[None, :]) & (y0[None, :] < y1[:, None]))
    np.fill_diagonal(meet, False)
    i, j = np.nonzero(np.triu(meet))
    return [(texts[a].get_text(), texts[b].get_text()) for a, b in zip(i, j)]


def catch_figure(monkeypatch):
    """Make vampc.report.svg.to_svg record the figures it renders; returns the list."""
    from vampc.report import svg
    caught = []
    real = svg.to_svg

    def to_svg(fig, titles=None):
        out = real(fig, titles) if titles is not None else real(fig)
        caught.append(fig)
        return out
    monkeypatch.setattr(svg, "to_svg", to_svg)
    return caught
