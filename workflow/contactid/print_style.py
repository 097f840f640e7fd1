"""Figures drawn at the size they are printed at in paper/report.tex, with text no smaller than 8 pt on paper.

The report is one column on A4 with 2.2 cm margins (``\\documentclass[11pt,a4paper]{article}``,
``\\usepackage[margin=2.2cm]{geometry}``): its text width is 210 mm - 2 x 22 mm = 166 mm. A figure is drawn
either at the text width or at ``NARROW_FRACTION`` of it, and report.tex includes it at exactly that width
(``width=\\textwidth`` or ``width=0.65\\textwidth``), so one point of the figure is one point on paper.
"""

from __future__ import annotations

import functools

TEXT_WIDTH_IN = (210.0 - 2 * 22.0) / 25.4  # 6.535 in: A4 less the report's 2.2 cm margins
NARROW_FRACTION = 0.65
NARROW_WIDTH_IN = NARROW_FRACTION * TEXT_WIDTH_IN  # 4.248 in
MIN_FONT_PT = 8.0

STYLE = {
    "font.size": 8.0,
    "axes.titlesize": 9.0,
    "axes.labelsize": 8.0,
    "xtick.labelsize": 8.0,
    "ytick.labelsize": 8.0,
    "legend.fontsize": 8.0,
    "figure.titlesize": 9.0,
    "lines.linewidth": 1.0,
    "axes.linewidth": 0.6,
    "grid.linewidth": 0.4,
    "savefig.dpi": 200,
}


def pyplot():
    """matplotlib.pyplot on the non-interactive Agg backend."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def print_figure(func):
    """Draw the figure of ``func`` in the print style (``STYLE``: 8 pt text, 9 pt titles)."""

    @functools.wraps(func)
    def wrapper(*args, **kwargs):
        plt = pyplot()
        with plt.rc_context(STYLE):
            return func(*args, **kwargs)

    return wrapper


def save(fig, png: str, pdf: str | None = None) -> None:
    """Write ``fig`` at its own size (no cropping: the PDF is as wide as the figure) and close it."""
    fig.savefig(png)
    if pdf:
        fig.savefig(pdf)
    pyplot().close(fig)
