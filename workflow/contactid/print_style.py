r"""Figures drawn at the size they are printed at in paper/report.tex, with text no smaller than 8 pt on paper.

The report is one column on A4 with 2.2 cm margins (``\documentclass[11pt,a4paper]{article}``,
``\usepackage[margin=2.2cm]{geometry}``): its text width is 210 mm - 2 x 22 mm = 166 mm. A figure is drawn
either at the text width or at ``NARROW_FRACTION`` of it, and report.tex includes it at exactly that width
(``width=\textwidth`` or ``width=0.65\textwidth``), so one point of the figure is one point on paper.
"""

from __future__ import annotations

import functools
import math
from types import ModuleType
from typing import TYPE_CHECKING, Any, Callable

if TYPE_CHECKING:
    from matplotlib.axis import Axis
    from matplotlib.figure import Figure

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


def pyplot() -> ModuleType:
    """Return matplotlib.pyplot on the non-interactive Agg backend.

    Returns
    -------
    plt : ModuleType
        The module ``matplotlib.pyplot``, its backend set to Agg (no display needed).
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def print_figure(func: Callable[..., Any]) -> Callable[..., Any]:
    """Wrap a figure-drawing function so that it draws in the print style.

    The wrapper runs ``func`` within ``STYLE`` (8 pt text, 9 pt titles) as matplotlib's rc settings.

    Parameters
    ----------
    func
        A function that draws a figure.

    Returns
    -------
    wrapper : Callable[..., Any]
        ``func`` with the same signature and result, drawing in the print style.
    """

    @functools.wraps(func)
    def wrapper(*args, **kwargs):
        plt = pyplot()
        with plt.rc_context(STYLE):
            return func(*args, **kwargs)

    return wrapper


def save(fig: Figure, png: str, pdf: str | None = None) -> None:
    """Write a figure at its own size and close it.

    No cropping: the PDF is as wide as the figure.

    Parameters
    ----------
    fig
        The figure to write.
    png
        Path of the PNG file.
    pdf
        Path of a PDF file to write as well; None: no PDF.
    """
    fig.savefig(png)
    if pdf:
        fig.savefig(pdf)
    pyplot().close(fig)


# Sub- and superscripts as Unicode characters drawn at the text's full size: mathtext draws ``$^{-2}$`` and
# ``$_0$`` at 70 % of it (8 pt -> 5.6 pt). DejaVu Sans, matplotlib's default font, has every glyph below.
_SUPERSCRIPT = str.maketrans("0123456789-+/in", "⁰¹²³⁴⁵⁶⁷⁸⁹⁻⁺ᐟⁱⁿ")
_SUBSCRIPT = str.maketrans("0123456789inpt", "₀₁₂₃₄₅₆₇₈₉ᵢₙₚₜ")


def sup(text: str) -> str:
    """Return ``text`` as Unicode superscript characters.

    For example sup("-2") = "⁻²", sup("1/2") = "¹ᐟ²".

    Parameters
    ----------
    text
        Digits, signs, "/", "i" and "n" (other characters are kept as they are).

    Returns
    -------
    superscript : str
        The text in superscript characters.
    """
    return str(text).translate(_SUPERSCRIPT)


def sub(text: str) -> str:
    """Return ``text`` as Unicode subscript characters.

    For example sub("0") = "₀", sub("p") = "ₚ".

    Parameters
    ----------
    text
        Digits and the letters "i", "n", "p", "t" (other characters are kept as they are).

    Returns
    -------
    subscript : str
        The text in subscript characters.
    """
    return str(text).translate(_SUBSCRIPT)


def _tick_text(value: float) -> str:
    """Return a log axis' tick label.

    A plain number from 1e-4 to 1e5 (0.001, 20), else a power of ten as 10⁻⁶.
    """
    if value <= 0:
        return ""
    if 1e-4 <= value < 1e5:
        return f"{value:g}"
    exponent = int(round(math.log10(value)))
    mantissa = value / 10.0**exponent
    head = "" if abs(mantissa - 1) < 1e-9 else f"{mantissa:g}×"
    return f"{head}10{sup(str(exponent))}".replace("-", "−")


def plain_log_ticks(axis: Axis) -> None:
    """Label a log axis at full size.

    Plain numbers or 10⁻⁶, no mathtext exponents; minor ticks unlabelled.

    Parameters
    ----------
    axis
        The axis to label: ax.xaxis or ax.yaxis.
    """
    from matplotlib.ticker import FuncFormatter, NullFormatter

    axis.set_major_formatter(FuncFormatter(lambda v, _: _tick_text(v)))
    axis.set_minor_formatter(NullFormatter())


def rendered_sizes_pt(fig: Figure) -> list[tuple[float, str]]:
    """Return the smallest rendered size of every visible, non-empty text of a drawn figure.

    A text's size is its font size, or for mathtext the smallest glyph's (sub- and superscripts at 70 %). With the
    figure drawn at its printed width these are sizes on paper.

    Parameters
    ----------
    fig
        A drawn figure.

    Returns
    -------
    sizes : list[tuple[float, str]]
        (smallest rendered size in typographic points, 1/72 in, as ``MIN_FONT_PT`` [unit of MIN_FONT_PT], the
        text) of each text.
    """
    import matplotlib.text
    from matplotlib.mathtext import MathTextParser

    parser = MathTextParser("path")
    out = []
    for t in fig.findobj(matplotlib.text.Text):
        s = t.get_text()
        if not (t.get_visible() and s.strip()):
            continue
        s, ismath = t._preprocess_math(s)
        size = t.get_fontsize()
        if ismath:
            glyphs = parser.parse(s, dpi=72, prop=t.get_fontproperties()).glyphs
            size = min((g[1] for g in glyphs), default=size)
        out.append((float(size), t.get_text()))
    return out
