"""What every plot function shares: the ``ax=`` convention, wrapped titles, number formatting and
curves drawn through tabulated points.

The convention (every public plot function of :mod:`orthoscope.plots` keeps it)::

    def plot_something(data, *, ax=None, title=None) -> Figure:
        fig, ax = figure_and_axes(ax, figsize=FIGSIZE)
        ...draw into ax only...
        return fig

* ``ax`` given: draw into it (a twin axis is made on it with ``ax.twinx()``); the figure's size and
  layout are the caller's. The return value is the figure that holds ``ax``.
* ``ax=None``: a new figure from :func:`matplotlib.pyplot.subplots` (constrained layout), so that
  ``plt.show()`` and Jupyter show it. No backend is chosen here: matplotlib's own choice stands.
  Inside :func:`offscreen_figures` (what the command line uses to write files) the new figure is a
  plain :class:`matplotlib.figure.Figure` that pyplot never sees.

:func:`orthoscope.plots.save.save_figure` writes any of these figures.
"""

from __future__ import annotations

import contextlib
import contextvars
import math
from collections.abc import Iterator, Sequence

import numpy as np

#: Default size (inches) of a new single-chart figure.
FIGSIZE = (7.0, 4.6)
#: Points per curve drawn densely (a traced curve is traced at this many fields; a tabulated one
#: is sampled at this many points of its monotone spline).
DENSE_POINTS = 241
#: Style of the light grid and the zero line.
GRID = {"color": "0.88", "lw": 0.6}
ZERO = {"color": "0.45", "lw": 0.8}

_OFFSCREEN: contextvars.ContextVar[bool] = contextvars.ContextVar("offscreen", default=False)


@contextlib.contextmanager
def offscreen_figures() -> Iterator[None]:
    """Inside this block the plot functions make plain ``Figure`` objects (no pyplot, no GUI
    window, nothing to close) — for writing files, as the command line does."""
    token = _OFFSCREEN.set(True)
    try:
        yield
    finally:
        _OFFSCREEN.reset(token)


def root_figure(ax):
    """The top-level Figure that holds ``ax`` (also for an Axes in a SubFigure)."""
    try:
        return ax.get_figure(root=True)  # matplotlib >= 3.10
    except TypeError:  # pragma: no cover - older matplotlib
        return ax.figure.figure


def figure_and_axes(ax=None, *, figsize: tuple[float, float] = FIGSIZE):
    """``(figure, ax)``: the given Axes and its figure, or a new figure with one Axes.

    Parameters
    ----------
    ax : matplotlib.axes.Axes, optional
        Where to draw. ``None``: a new figure of ``figsize`` inches, made by
        :func:`matplotlib.pyplot.subplots` with ``layout="constrained"`` (a plain ``Figure``
        inside :func:`offscreen_figures`).
    figsize : (float, float)
        Width and height in inches of a new figure.
    """
    if ax is not None:
        return root_figure(ax), ax
    if _OFFSCREEN.get():
        from matplotlib.figure import Figure

        fig = Figure(figsize=figsize, layout="constrained")
        return fig, fig.subplots()
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=figsize, layout="constrained")
    return fig, ax


def figure_with_zero(ax=None, *, figsize: tuple[float, float] = FIGSIZE):
    """:func:`figure_and_axes`, with the horizontal zero line (style :data:`ZERO`) drawn first."""
    fig, ax = figure_and_axes(ax, figsize=figsize)
    ax.axhline(0.0, **ZERO)
    return fig, ax


def label_axes(ax, xlabel: str, ylabel: str, **ylabel_kw) -> None:
    """The x and y axis labels (``ylabel_kw`` to :meth:`Axes.set_ylabel`, e.g. ``color``) and
    the light grid (style :data:`GRID`)."""
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel, **ylabel_kw)
    ax.grid(True, **GRID)


def blank_figure(figsize: tuple[float, float]):
    """A new figure of ``figsize`` inches with no Axes (made as :func:`figure_and_axes` makes
    one: pyplot's, or a plain ``Figure`` inside :func:`offscreen_figures`)."""
    fig, ax = figure_and_axes(None, figsize=figsize)
    ax.remove()
    return fig


def panel_figure(rows: int, cols: int, *, figsize: tuple[float, float]):
    """``(figure, axes)``: a new :func:`blank_figure` with a ``rows`` x ``cols`` grid of Axes
    (``axes`` as :meth:`matplotlib.figure.Figure.subplots` returns them)."""
    fig = blank_figure(figsize)
    return fig, fig.subplots(rows, cols)


# ------------------------------------------------------------------ titles and numbers


def _words(text: str) -> list[str]:
    """Split at spaces, keeping each ``$...$`` mathtext span in one piece."""
    out: list[str] = []
    cur: list[str] = []
    for w in text.split(" "):
        cur.append(w)
        if " ".join(cur).count("$") % 2 == 0:
            out.append(" ".join(cur))
            cur = []
    if cur:
        out.append(" ".join(cur))
    return [w for w in out if w]


def text_width_pt(text: str, fontsize: float) -> float:
    """Width in points of ``text`` (mathtext allowed) at ``fontsize``, independent of any
    canvas or backend."""
    from matplotlib.font_manager import FontProperties
    from matplotlib.textpath import text_to_path

    ismath = text.count("$") >= 2 and text.count("$") % 2 == 0
    w, _, _ = text_to_path.get_text_width_height_descent(
        text, FontProperties(size=fontsize), ismath=ismath
    )
    return float(w)


def wrap_text(text: str, width_pt: float, fontsize: float) -> str:
    """``text`` with line breaks so that no line is wider than ``width_pt`` points (a single word
    wider than that gets a line of its own). Existing line breaks are kept."""
    lines: list[str] = []
    for para in text.split("\n"):
        cur = ""
        for w in _words(para):
            trial = f"{cur} {w}" if cur else w
            if cur and text_width_pt(trial, fontsize) > width_pt:
                lines.append(cur)
                cur = w
            else:
                cur = trial
        lines.append(cur)
    return "\n".join(lines)


def set_title(ax, text: str, *, fontsize: float = 10.0, **kw) -> None:
    """Set the title of ``ax`` wrapped to the width of the axes (so it never runs past the figure
    edge; mathtext spans are never split). ``kw`` go to :meth:`Axes.set_title`."""
    fig = root_figure(ax)
    width_in = ax.get_position().width * fig.get_size_inches()[0]
    width_pt = max(72.0, 0.94 * 72.0 * width_in)
    ax.set_title(wrap_text(text, width_pt, fontsize), fontsize=fontsize, **kw)


def fmt(value: float, digits: int = 5) -> str:
    """``value`` with ``digits`` significant digits in plain notation (trailing zeros dropped):
    153.706 → "153.71" (digits=5), 0.0012345678 → "0.0012346", 12.0 → "12"."""
    v = float(value)
    if not math.isfinite(v):
        return str(v)
    if v == 0.0:
        return "0"
    mag = math.floor(math.log10(abs(v)))
    if mag >= digits + 2 or mag < -5:
        return f"{v:.{digits - 1}e}"
    dec = max(0, digits - 1 - mag)
    s = f"{v:.{dec}f}"
    if "." in s:
        s = s.rstrip("0").rstrip(".")
    return "0" if s in ("-0", "") else s


# ------------------------------------------------------------------ curves through table points


def strictly_increasing(x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The finite points of (x, y) sorted by x; raises ValueError on repeated x values."""
    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)
    ok = np.isfinite(x) & np.isfinite(y)
    x, y = x[ok], y[ok]
    order = np.argsort(x, kind="stable")
    x, y = x[order], y[order]
    if x.size > 1 and not np.all(np.diff(x) > 0.0):
        raise ValueError("repeated abscissa values")
    return x, y


def monotone_spline(
    x: Sequence[float] | np.ndarray, y: Sequence[float] | np.ndarray, n: int = DENSE_POINTS
) -> tuple[np.ndarray, np.ndarray]:
    """Dense samples of the Fritsch–Carlson monotone cubic (``scipy.interpolate.
    PchipInterpolator``) through tabulated points: it passes through every point and never
    overshoots between two of them (no invented wiggles). The tabulated abscissae are among the
    samples. Fewer than three points, or repeated abscissae: the points themselves (straight
    segments)."""
    try:
        xs, ys = strictly_increasing(np.asarray(x), np.asarray(y))
    except ValueError:
        return np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    if xs.size < 3:
        return xs, ys
    from scipy.interpolate import PchipInterpolator

    xd = np.union1d(np.linspace(xs[0], xs[-1], n), xs)
    yd = PchipInterpolator(xs, ys)(xd)
    return xd, yd


def dense_and_markers(
    ax,
    dense: tuple[np.ndarray, np.ndarray],
    points: tuple[np.ndarray, np.ndarray],
    *,
    color,
    ls: str = "-",
    marker: str = "o",
    lw: float = 1.4,
    ms: float = 4.0,
    mfc=None,
    zorder: float = 2.0,
):
    """Draw a dense curve and, on top of it, markers at the tabulated points. Returns the pair
    of Line2D ``(line, markers)`` — pass it to ``legend(handles=[...])`` as one entry (a tuple
    handle shows the line with its marker)."""
    (line,) = ax.plot(*dense, ls=ls, color=color, lw=lw, zorder=zorder)
    (marks,) = ax.plot(
        *points,
        ls="none",
        marker=marker,
        ms=ms,
        color=color,
        mfc=color if mfc is None else mfc,
        zorder=zorder + 0.1,
    )
    return line, marks


def legend(ax, handles: list, labels: list[str], **kw):
    """A legend whose entries may be ``(line, markers)`` tuples (drawn overlaid)."""
    from matplotlib.legend_handler import HandlerTuple

    kw.setdefault("frameon", False)
    kw.setdefault("fontsize", 9)
    return ax.legend(handles, labels, handler_map={tuple: HandlerTuple(ndivide=1)}, **kw)


def shared_zero(ax_left, ax_right, left: np.ndarray, right: np.ndarray, pad: float = 0.08):
    """Y limits on two twinned axes such that their zero lines coincide and the data of both fill
    the height (each scale normalised by its largest |value|; common normalised limits)."""
    norm, scales = [], []
    for v in (left, right):
        v = np.asarray(v, dtype=float)
        v = v[np.isfinite(v)]
        m = float(np.max(np.abs(v))) if v.size else 1.0
        m = m if m > 0 else 1.0
        scales.append(m)
        norm.append(v / m if v.size else np.zeros(1))
    lo = min(0.0, *(float(n.min()) for n in norm))
    hi = max(0.0, *(float(n.max()) for n in norm))
    span = hi - lo
    lo, hi = lo - pad * span, hi + pad * span
    for a, m in ((ax_left, scales[0]), (ax_right, scales[1])):
        a.set_ylim(lo * m, hi * m)
