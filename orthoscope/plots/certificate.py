"""The one-page calibration certificate of a design (:mod:`distortion.certificate`): an A4 page
with the header (lens, date, conditions), the tables of focal length, principal points, radial
distortion along the four semi-diagonals and decentering, a radial-distortion plot per
semi-diagonal and the decentering profile.

Every number on the page is a cell of :mod:`orthoscope.report.certificate`, made from the JSON
dict of the certificate; each text object of a number carries the cell's JSON path as its
``gid``. Save the page with :func:`orthoscope.plots.save.save_figure` (``.pdf``, ``.png``,
``.svg``).
"""

from __future__ import annotations

import textwrap

import numpy as np

from .common import GRID, ZERO, blank_figure, figure_and_axes

#: how the page spells the plain-text labels of the report cells
PRETTY = (
    ("psi - 90 deg", "psi \u2212 90\u00b0"),
    ("tan(theta)", "tan \u03b8"),
    ("sqrt(P1^2 + P2^2)", "\u221a(P1\u00b2 + P2\u00b2)"),
    ("phi0", "\u03c6\u2080"),
    ("psi", "\u03c8"),
    ("r^2", "r\u00b2"),
    ("r^3", "r\u00b3"),
    ("r^5", "r\u2075"),
    ("r^7", "r\u2077"),
    ("mm^2", "mm\u00b2"),
    ("mm^4", "mm\u2074"),
    ("mm^6", "mm\u2076"),
    ("(um)", "(\u00b5m)"),
    ("um,", "\u00b5m,"),
    (" deg)", "\u00b0)"),
)


def pretty(text: str) -> str:
    """A label of :mod:`orthoscope.report.certificate` with Greek letters and superscripts."""
    for a, b in PRETTY:
        text = text.replace(a, b)
    return text


#: A4 portrait, inches
PAGE = (8.27, 11.69)
LEFT, RIGHT = 0.07, 0.95
LINE = 0.0148  # line spacing of the tables (figure fraction)
COLOURS = ("C0", "C1", "C2", "C3")


def _as_dict(cert) -> dict:
    if isinstance(cert, dict):
        return cert
    from ..report.certificate import certificate_to_dict

    return certificate_to_dict(cert)


def _dense(d: dict):
    dn = d["dense"]
    f = np.asarray(dn["fields_deg"], dtype=float)

    def arr(v):
        return np.array([np.nan if x is None else x for x in np.ravel(v)], dtype=float).reshape(
            np.shape(v)
        )

    return f, arr(dn["radial_um"]), arr(dn["mean_radial_um"]), arr(dn["decentering_profile_um"])


#: the most tabulated fields marked as points on the plots; beyond, the fields of the page's
#: table (:func:`orthoscope.report.certificate.page_field_indices`)
MARKED_MAX = 100


def _marked(d: dict) -> np.ndarray:
    """Indices of the tabulated fields the plots mark as points."""
    n = len(d["fields_deg"])
    if n <= MARKED_MAX:
        return np.arange(n)
    from ..report.certificate import page_field_indices

    return np.asarray(page_field_indices(d)[0])


#: room beyond the format's edge on the field axis (fraction of it), so that the tabulated
#: points at the edge are drawn whole, not cut by the axes' border
FIELD_MARGIN = 0.04


def _field_xlim(ax, f: np.ndarray) -> None:
    """The field axis from 0 to the format's edge, with ``FIELD_MARGIN`` beyond the edge."""
    edge = max(float(f[-1]), 1e-9)
    ax.set_xlim(0.0, edge * (1.0 + FIELD_MARGIN))


def _style(ax, xlabel: str | None, ylabel: str | None, fontsize: float = 7.0) -> None:
    ax.grid(True, **GRID)
    ax.axhline(0.0, **ZERO)
    ax.tick_params(labelsize=fontsize)
    if xlabel:
        ax.set_xlabel(xlabel, fontsize=fontsize)
    if ylabel:
        ax.set_ylabel(ylabel, fontsize=fontsize)


def plot_certificate_radial(cert, index: int, *, ax=None, title: str | None = None):
    """Radial distortion (µm) against the field angle along semi-diagonal ``index`` (0–3) of a
    certificate (or its dict), with the mean of the four in grey and the tabulated values as
    points (those of the page's table when there are more than ``MARKED_MAX``)."""
    d = _as_dict(cert)
    fig, ax = figure_and_axes(ax)
    f, rad, mean, _ = _dense(d)
    sd = d["semi_diagonals"][index]
    ax.plot(f, mean, color="0.6", lw=1.0, ls="--", label="mean of the four")
    ax.plot(f, rad[index], color=COLOURS[index % 4], lw=1.4, label=sd["label"])
    j = _marked(d)
    tf = np.asarray(d["fields_deg"], dtype=float)[j]
    tv = np.array([np.nan if v is None else v for v in sd["radial_um"]], dtype=float)[j]
    ax.plot(tf, tv, "o", ms=3, color=COLOURS[index % 4])
    _field_xlim(ax, f)
    _style(ax, "field angle \u03b8 (\u00b0)", "radial distortion (\u00b5m)")
    ax.set_title(
        title or f"semi-diagonal {sd['label']} (azimuth {sd['azimuth_deg']:.2f} deg)", fontsize=8
    )
    return fig


def plot_certificate_decentering(cert, *, ax=None, title: str | None = None):
    """The decentering profile J r² (µm) against the field angle."""
    d = _as_dict(cert)
    fig, ax = figure_and_axes(ax)
    f, _, _, prof = _dense(d)
    ax.plot(f, prof, color="C4", lw=1.4)
    j = _marked(d)
    tf = np.asarray(d["fields_deg"], dtype=float)[j]
    tv = np.array([np.nan if v is None else v for v in d["decentering"]["profile_um"]], dtype=float)
    ax.plot(tf, tv[j], "o", ms=3, color="C4")
    _field_xlim(ax, f)
    top = float(np.nanmax(np.abs(prof))) if np.isfinite(prof).any() else 0.0
    if top < 1e-3:  # a centred design: keep the axis readable around zero
        ax.set_ylim(-1.0, 1.0)
    _style(ax, "field angle \u03b8 (\u00b0)", "J r\u00b2 (\u00b5m)")
    ax.set_title(title or "decentering profile P(r) = J r\u00b2", fontsize=8)
    return fig


# ------------------------------------------------------------------ the page


class _Page:
    """Writes text on the page top-down; every number cell gets its JSON path as gid."""

    def __init__(self, fig) -> None:
        self.fig = fig
        self.y = 0.962

    def text(self, x, s, *, size=7.5, weight="normal", ha="left", gid=None, y=None, **kw):
        t = self.fig.text(
            x,
            self.y if y is None else y,
            s,
            fontsize=size,
            weight=weight,
            ha=ha,
            va="baseline",
            **kw,
        )
        if gid is not None:
            t.set_gid(gid)
        return t

    def down(self, n: float = 1.0) -> None:
        self.y -= n * LINE

    def rule(self, x0=LEFT, x1=RIGHT, lw=0.6, dy=0.35) -> None:
        from matplotlib.lines import Line2D

        yy = self.y + dy * LINE
        self.fig.add_artist(
            Line2D([x0, x1], [yy, yy], transform=self.fig.transFigure, color="0.3", lw=lw)
        )

    def heading(self, s: str) -> None:
        self.down(0.8)
        self.text(LEFT, s, size=9, weight="bold")
        self.rule(lw=0.8, dy=-0.45)
        self.down(1.45)


def _header(pg: _Page, d: dict) -> None:
    from ..report.certificate import condition_lines

    pg.text(LEFT, "CALIBRATION CERTIFICATE", size=15, weight="bold")
    pg.text(RIGHT, "design prediction \u2014 not a measurement", size=8, ha="right", style="italic")
    pg.down(1.6)
    pg.text(LEFT, d["lens"], size=10.5, weight="bold")
    pg.down(1.0)
    if d["source"]:
        for line in textwrap.wrap("Source: " + d["source"], 140)[:2]:
            pg.text(LEFT, line, size=6.5, color="0.3")
            pg.down(0.85)
    pg.down(0.2)
    pg.rule(lw=1.0)
    pg.down(0.9)
    for lab, txt in condition_lines(d):
        pg.text(LEFT, lab, size=7.5, weight="bold")
        pg.text(LEFT + 0.19, txt, size=7.5)
        pg.down(1.0)


def _summary(pg: _Page, d: dict) -> None:
    from ..report.certificate import coefficient_cells, summary_cells

    pg.heading("Focal length and principal points")
    top = pg.y
    xv1, xv2, xu = LEFT + 0.37, LEFT + 0.46, LEFT + 0.475
    pg.text(xv1, "x", size=7, ha="right", color="0.35", style="italic")
    pg.text(xv2, "y", size=7, ha="right", color="0.35", style="italic")
    pg.down(1.0)
    for lab, a, b, unit in summary_cells(d):
        pg.text(LEFT, pretty(lab), size=7.5)
        if b is None:
            pg.text(xv2, a.text, size=7.5, ha="right", gid=a.path, weight="bold")
        else:
            pg.text(xv1, a.text, size=7.5, ha="right", gid=a.path)
            pg.text(xv2, b.text, size=7.5, ha="right", gid=b.path)
        pg.text(xu, unit, size=7.5)
        pg.down(1.0)
    end = pg.y
    # the radial coefficients beside the table
    pg.y = top
    x0 = LEFT + 0.58
    pg.text(x0, "Radial coefficients of the mean curve", size=7.5, weight="bold")
    pg.down(1.0)
    pg.text(x0, pretty("dr = k0 r + k1 r^3 + k2 r^5 + k3 r^7  (mm)"), size=7)
    pg.down(1.0)
    for lab, c in coefficient_cells(d):
        pg.text(x0, pretty(lab), size=7.5)
        pg.text(RIGHT, c.text, size=7.5, ha="right", gid=c.path)
        pg.down(0.9)
    pg.y = min(end, pg.y)


#: where the columns of the field table start (figure fraction): the labels' width at 7.5 pt
TABLE_X0 = LEFT + 0.2
#: the font of the field table's numbers (pt): 7.5, smaller where the widest number would come
#: closer than ``TABLE_GAP_EM`` to its neighbour, never below ``TABLE_MIN_SIZE``
TABLE_SIZE, TABLE_MIN_SIZE, TABLE_GAP_EM = 7.5, 5.0, 0.9


def _columns(n: int) -> np.ndarray:
    """The right edges of ``n`` equal columns of the field table (figure fraction)."""
    w = (RIGHT - TABLE_X0) / n
    return TABLE_X0 + w * (np.arange(n) + 1)


def _table_size(d: dict) -> float:
    """The font size of the field table's numbers (the radial table and the decentering profile
    row share its columns): the widest printed number, in its weight, fits its column with a
    gap of ``TABLE_GAP_EM``."""
    from matplotlib.font_manager import FontProperties
    from matplotlib.textpath import TextToPath

    from ..report.certificate import decentering_cells, page_field_indices, radial_table_cells

    idx, _ = page_field_indices(d)
    head, rows = radial_table_cells(d)
    _, prof = decentering_cells(d)
    cells = [(head[j].text, "bold") for j in idx] + [(prof[j].text, "normal") for j in idx]
    for i, (_, cs) in enumerate(rows):
        weight = "bold" if i == len(rows) - 1 else "normal"
        cells += [(cs[j].text, weight) for j in idx]
    ttp = TextToPath()
    em = max(
        ttp.get_text_width_height_descent(t, FontProperties(size=1.0, weight=w), ismath=False)[0]
        for t, w in cells
    )
    column_pt = (RIGHT - TABLE_X0) * PAGE[0] * 72.0 / max(len(idx), 1)
    return float(np.clip(column_pt / (em + TABLE_GAP_EM), TABLE_MIN_SIZE, TABLE_SIZE))


def _radial_table(pg: _Page, d: dict) -> None:
    from ..report.certificate import page_field_indices, page_table_note, radial_table_cells

    pg.heading(pretty("Radial distortion along the semi-diagonals (um, + outward)"))
    head, rows = radial_table_cells(d)
    idx, _ = page_field_indices(d)  # at most ACROSS_MAX_FIELDS: one row of columns
    xs = _columns(len(idx))
    size = _table_size(d)
    pg.text(LEFT, "field angle \u03b8 (\u00b0)", size=7.5, weight="bold")
    for x, j in zip(xs, idx, strict=True):
        pg.text(x, head[j].text, size=size, ha="right", weight="bold", gid=head[j].path)
    pg.rule(lw=0.5, dy=-0.4)
    pg.down(1.2)
    for i, (lab, cells) in enumerate(rows):
        last = i == len(rows) - 1
        if last:
            pg.rule(lw=0.5, dy=0.75)
        colour = COLOURS[i - 1] if 1 <= i <= 4 else "black"
        weight = "bold" if last else "normal"
        pg.text(LEFT, pretty(lab), size=7.5, weight=weight, color=colour)
        for x, j in zip(xs, idx, strict=True):
            c = cells[j]
            pg.text(x, c.text, size=size, ha="right", gid=c.path, weight=weight)
        pg.down(1.0)
    note = page_table_note(d)
    if note:
        pg.text(LEFT, note, size=6.5, color="0.3", style="italic")
        pg.down(1.0)


def _decentering(pg: _Page, d: dict) -> None:
    from ..report.certificate import decentering_cells, page_field_indices

    pg.heading("Decentering distortion")
    params, prof = decentering_cells(d)
    half = (len(params) + 1) // 2
    y0 = pg.y
    for k, (lab, c, unit) in enumerate(params):
        col = 0 if k < half else 1
        x = LEFT + 0.47 * col
        y = y0 - (k % half) * LINE
        pg.text(x, pretty(lab), size=7.5, y=y)
        pg.text(x + 0.37, c.text, size=7.5, ha="right", gid=c.path, y=y)
        pg.text(x + 0.38, "\u00b0" if unit == "deg" else pretty(unit), size=7.5, y=y)
    pg.y = y0 - half * LINE
    idx, _ = page_field_indices(d)  # the columns of the radial table above
    xs = _columns(len(idx))
    size = _table_size(d)
    pg.text(LEFT, pretty("profile J r^2 (um)"), size=7.5, weight="bold")
    for x, j in zip(xs, idx, strict=True):
        pg.text(x, prof[j].text, size=size, ha="right", gid=prof[j].path)
    pg.down(1.0)


FOOT_SIZE, FOOT_LINE = 6.2, 0.8 * LINE


def _footer_lines(d: dict) -> list[str]:
    from ..report.certificate import definition_lines

    lines = []
    for s in definition_lines(d) + [f"Note: {n}" for n in d["notes"]]:
        lines += textwrap.wrap(pretty(s), 165)
    return lines


def _footer(fig, lines: list[str]) -> float:
    """Writes the definitions at the foot; returns the top of the block (figure fraction)."""
    y = 0.014 + FOOT_LINE * (len(lines) - 1)
    top = y + FOOT_LINE
    for ln in lines:
        fig.text(LEFT, y, ln, fontsize=FOOT_SIZE, color="0.25", va="baseline")
        y -= FOOT_LINE
    return top


def plot_certificate(cert):
    """The certificate on one A4 page (module docstring); returns the Figure.

    The page is a fixed layout (no ``ax=``): header, tables, then the plots — the four
    semi-diagonals in the quadrants they point to (−x+y top left, +x+y top right, −x−y bottom
    left, +x−y bottom right), the decentering profile and the four curves together — and the
    definitions at the foot.

    Radial distortion Δr in µm (+ outward = pincushion) and the decentering profile J r² in µm,
    against the field angle θ in degrees; coordinates in mm in the photogrammetric image frame
    (x right, y up); :mod:`distortion.certificate` defines them.

    Parameters
    ----------
    cert : CalibrationCertificate or dict
        From ``osc.calibration_certificate``, or its JSON dict
        (:func:`orthoscope.report.certificate.certificate_to_dict`).

    Returns
    -------
    matplotlib.figure.Figure
        A new A4 portrait figure (8.27 × 11.69 inches) marked ``orthoscope_page = True``, so that
        :func:`~orthoscope.plots.save.save_figure` keeps the whole page.
    """
    d = _as_dict(cert)
    fig = blank_figure(PAGE)
    fig.set_layout_engine("none")
    fig.orthoscope_page = True  # save_figure keeps the whole A4 page (no tight bounding box)
    pg = _Page(fig)
    _header(pg, d)
    _summary(pg, d)
    _radial_table(pg, d)
    _decentering(pg, d)
    foot = _footer(fig, _footer_lines(d))
    top = pg.y - 0.03
    bottom = foot + 0.045
    gap = 0.06  # room for the titles and axis labels
    h = (top - bottom - gap) / 2.0
    w = (RIGHT - LEFT - 0.05 - 2 * 0.075) / 3.0

    def box(row: int, col: int):
        x = LEFT + 0.05 + col * (w + 0.075)
        y = top - (row + 1) * h - row * gap + 0.02
        return fig.add_axes((x, y, w, h - 0.02))

    for i, sd in enumerate(d["semi_diagonals"]):
        a = np.radians(sd["azimuth_deg"])
        row = 0 if np.sin(a) >= 0 else 1
        col = 1 if np.cos(a) >= 0 else 0
        ax = box(row, col)
        plot_certificate_radial(
            d, i, ax=ax, title=f"semi-diagonal {sd['label']} ({sd['azimuth_deg']:.1f}\u00b0)"
        )
        ax.set_ylabel("dr (\u00b5m)", fontsize=7)
        if i == 0:
            ax.legend(fontsize=6, loc="best", frameon=False)
    _common_ylim(fig.axes, d)
    ax = box(0, 2)
    plot_certificate_decentering(d, ax=ax, title="decentering profile J r\u00b2")
    ax.set_ylabel("J r\u00b2 (\u00b5m)", fontsize=7)
    ax = box(1, 2)
    plot_certificate_all(d, ax=ax)
    _common_ylim([ax], d)
    return fig


def _common_ylim(axes, d: dict) -> None:
    """One radial scale for the semi-diagonal panels, so that they compare at a glance."""
    _, rad, _, _ = _dense(d)
    top = float(np.nanmax(np.abs(rad))) if np.isfinite(rad).any() else 0.0
    top = max(top, 1e-3) * 1.12
    for ax in axes:
        ax.set_ylim(-top, top)


def plot_certificate_all(cert, *, ax=None, title: str | None = None):
    """The four semi-diagonals' radial distortion (µm) and their mean against the field angle."""
    d = _as_dict(cert)
    fig, ax = figure_and_axes(ax)
    f, rad, mean, _ = _dense(d)
    for i, sd in enumerate(d["semi_diagonals"]):
        ax.plot(f, rad[i], color=COLOURS[i % 4], lw=1.0, label=sd["label"])
    ax.plot(f, mean, color="black", lw=1.0, ls="--", label="mean")
    _field_xlim(ax, f)
    _style(ax, "field angle \u03b8 (\u00b0)", "dr (\u00b5m)")
    ax.legend(fontsize=5.5, frameon=False, ncol=2, loc="best")
    ax.set_title(title or "all semi-diagonals and their mean", fontsize=8)
    return fig
