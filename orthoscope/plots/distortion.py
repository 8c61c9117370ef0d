"""Distortion charts in the style of Pestrecov 1958, Figs. 2, 3, 4 and 6.

Every function draws into ``ax`` (a new pyplot figure when ``ax`` is None) and returns the Figure
(:mod:`orthoscope.plots.common` states the convention); :func:`orthoscope.plots.save.save_figure`
writes it. Linear distortion in mm, relative distortion in per cent, image sizes in mm.

How the curves are drawn
------------------------
Markers sit at the field points of the result. The line through them depends on where the data
come from:

* a **traced** result (:class:`~distortion.characteristic.CharacteristicDistortion`, a curve taken
  from one with ``.curve(i)``, or a calibration of either) is traced again at
  :data:`~orthoscope.plots.common.DENSE_POINTS` fields over the same range (same lens, object,
  image planes, reference; about 2 ms), the field points included, and the line is that dense
  trace;
* a **table** (a :class:`~distortion.curve.DistortionCurve` read from a file, e.g. Pestrecov's
  Table I) is never extended with invented data: its points are joined by the monotone cubic
  spline of Fritsch & Carlson (``scipy.interpolate.PchipInterpolator``), which passes through every
  point and does not overshoot between them.
"""

from __future__ import annotations

import math

import numpy as np

from distortion.calibration import CalibrationResult, calibrate
from distortion.characteristic import CharacteristicDistortion
from distortion.curve import ANGLE, HEIGHT, DistortionCurve
from distortion.errors import DataError
from raytrace.errors import OrthoscopeError

from .common import (
    DENSE_POINTS,
    FIGSIZE,
    GRID,
    ZERO,
    dense_and_markers,
    figure_and_axes,
    figure_with_zero,
    fmt,
    label_axes,
    legend,
    monotone_spline,
    set_title,
    shared_zero,
)

LINEAR = "k"
RELATIVE = "tab:blue"


# ------------------------------------------------------------------ data helpers


def _as_curve(d, plane: int = 0) -> DistortionCurve:
    if isinstance(d, DistortionCurve):
        return d
    if isinstance(d, CharacteristicDistortion):
        if not 0 <= int(plane) < d.n_planes:
            raise DataError(f"plane={plane}: the result has {d.n_planes} image plane(s) (0-based)")
        return d.curve(int(plane))
    raise DataError(
        f"expected a DistortionCurve or a CharacteristicDistortion, got {type(d).__name__}"
    )


def _traced_source(curve: DistortionCurve):
    """``(CharacteristicDistortion, plane)`` a curve was taken from, when it can be traced again."""
    src = curve.extra.get("traced") if curve.extra else None
    if isinstance(src, CharacteristicDistortion) and src.lens is not None:
        return src, int(curve.extra.get("plane", 0))
    return None, 0


def dense_curve(
    curve: DistortionCurve, n: int = DENSE_POINTS, *, cache: dict | None = None
) -> DistortionCurve | None:
    """The curve traced again at ``n`` fields over its range (its own fields included), or None
    for a curve that does not come from a trace (a table) or whose re-trace fails (the plot then
    joins the points by a monotone spline). ``cache``: re-traces by source, for several planes of
    one result."""
    src, plane = _traced_source(curve)
    if src is None or curve.fields.size < 2:
        return None
    f = np.union1d(np.linspace(curve.fields.min(), curve.fields.max(), n), curve.fields)
    key = (id(src), f.size, float(f[0]), float(f[-1]))
    try:
        if cache is not None and key in cache:
            again = cache[key]
        else:
            again = src.retrace(f)
            if cache is not None:
                cache[key] = again
    except OrthoscopeError:
        return None
    return again.curve(plane)


def _dense_calibration(res: CalibrationResult) -> CalibrationResult | None:
    """The calibration with the same K_c applied to the densely traced curve (None for a table)."""
    d = dense_curve(res.curve)
    return None if d is None else calibrate(d, "given", value=res.Kc, k=res.k)


def _constant_text(symbol: str, sub: str, value: float, finite: bool) -> str:
    """``$F_{0}$ = 153.706 mm`` with no-break spaces (a wrapped title keeps it on one line)."""
    return f"${symbol}_{{{sub}}}$\u00a0=\u00a0{fmt(value, 7)}" + ("" if finite else "\u00a0mm")


def _plane_text(curve: DistortionCurve) -> str:
    """Image-plane label with sensible digits (traced curves), else the curve's own text."""
    src, i = _traced_source(curve)
    if src is None or curve.plane != src.plane_label(i):  # a table, or text set by the caller
        return curve.plane
    sp, dz = src.s_prime[i], src.defocus[i]
    head = f"$s'$\u00a0=\u00a0{fmt(sp, 6)}\u00a0mm"
    if abs(dz) <= 1e-9 * max(1.0, abs(sp)):
        return f"{head} (Gaussian plane)"
    dz_text = f"{dz:+.4g}".replace("-", "\u2212")
    return f"{head} (defocus {dz_text}\u00a0mm)"


def _field_axis_label(field_kind: str) -> str:
    return {
        ANGLE: r"field angle $\alpha$ (deg)",
        HEIGHT: "object height $y$ (mm)",
    }.get(field_kind, r"nominal field angle $\alpha$ (deg)")


def _heading(what: str, curve: DistortionCurve, extra: str = "") -> str:
    parts = [p for p in (curve.name, _plane_text(curve), extra) if p]
    return what + (" — " + ", ".join(parts) if parts else "")


def _interp(x, y, dense_x=None, dense_y=None):
    """Dense line: the given dense arrays, else a monotone spline through the points."""
    if dense_x is not None:
        return np.asarray(dense_x, float), np.asarray(dense_y, float)
    return monotone_spline(x, y)


# ------------------------------------------------------------------ Figs. 2 and 3


def _grid_from_zero(ax, x) -> None:
    """The light grid; the abscissa from 0 when no ``x`` is negative."""
    if np.nanmin(x) >= 0:
        ax.set_xlim(left=0.0)
    ax.grid(True, **GRID)


def _linear_and_relative(ax, x, lin, rel, dense, xlabel, lin_label, rel_label, title):
    """Linear distortion (mm, left axis, black solid) and relative (%, right axis, blue dashed),
    zero lines shared. ``dense`` is ``(x, lin, rel)`` dense arrays or None (spline the points)."""
    ax.axhline(0.0, **ZERO)
    dl = (dense[0], dense[1]) if dense is not None else monotone_spline(x, lin)
    dr = (dense[0], dense[2]) if dense is not None else monotone_spline(x, rel)
    h1 = dense_and_markers(ax, dl, (x, lin), color=LINEAR, marker="o")
    ax.set_xlabel(xlabel)
    ax.set_ylabel(lin_label)
    ax2 = ax.twinx()
    h2 = dense_and_markers(ax2, dr, (x, rel), color=RELATIVE, ls="--", marker="s", ms=3.5)
    ax2.set_ylabel(rel_label, color=RELATIVE)
    ax2.tick_params(axis="y", colors=RELATIVE)
    shared_zero(ax, ax2, np.concatenate([lin, dl[1]]), np.concatenate([rel, dr[1]]))
    _grid_from_zero(ax, x)
    legend(ax, [h1, h2], [lin_label, rel_label], loc="upper left")
    set_title(ax, title)
    return ax2


def plot_characteristic(
    distortion: DistortionCurve | CharacteristicDistortion,
    *,
    ax=None,
    title: str | None = None,
    plane: int = 0,
):
    """Pestrecov's Fig. 2: characteristic linear distortion D_0 (mm, left axis) and relative
    distortion D_r (%, right axis) against the ideal image size y_0' (mm).

    Parameters
    ----------
    distortion : DistortionCurve or CharacteristicDistortion
        A table or a traced result (its image plane ``plane``, 0-based). A traced curve is traced
        again densely for the line; a table's points are joined by a monotone spline (module
        docstring). Markers at the given field points.
    ax : matplotlib.axes.Axes, optional
        Draw here (the per-cent scale goes on ``ax.twinx()``); default a new pyplot figure.
    title : str, optional
        Replaces the default title (which is wrapped to the axes width either way).

    Returns
    -------
    matplotlib.figure.Figure
    """
    curve = _as_curve(distortion, plane)
    fig, ax = figure_and_axes(ax, figsize=FIGSIZE)
    d = dense_curve(curve)
    const = _constant_text(curve.symbol, "0", curve.constant, curve.finite)
    _linear_and_relative(
        ax,
        curve.y0p,
        curve.D0,
        100.0 * curve.Dr,
        None if d is None else (d.y0p, d.D0, 100.0 * d.Dr),
        "ideal image size $y_0'$ (mm)",
        "linear distortion $D_0$ (mm)",
        "relative distortion $D_r$ (%)",
        title or _heading("Characteristic linear and % distortion", curve, const),
    )
    return fig


def plot_calibrated(res: CalibrationResult, *, ax=None, title: str | None = None):
    """Pestrecov's Fig. 3: calibrated linear distortion D_c (mm, left axis) and relative
    distortion D_rc (%, right axis) against the calibrated image size y_c' (mm).

    A calibration of a traced curve is drawn through the dense trace with the same K_c; a
    calibration of a table through a monotone spline of its points (module docstring). Markers at
    the field points. The curves are Pestrecov's Eqs. (10)–(12) and (15) (1958, Section IV):
    ``y_c' = K_c·x``, ``D_c = y' − y_c'`` and ``D_rc = y'/y_c' − 1`` (x = tan α or the object
    height y in mm; y' the real chief ray's signed image height, mm).

    Parameters
    ----------
    res : CalibrationResult
        From :func:`distortion.calibration.calibrate` (``osc.calibrate``) of a traced result or
        of a table. The title states K_c (F_c in mm, or M_c) and the calibration method.
    ax : matplotlib.axes.Axes, optional
        Draw here (the per-cent scale goes on ``ax.twinx()``); default a new pyplot figure.
    title : str, optional
        Replaces the default title (which is wrapped to the axes width either way).

    Returns
    -------
    matplotlib.figure.Figure
    """
    c = res.curve
    fig, ax = figure_and_axes(ax, figsize=FIGSIZE)
    d = _dense_calibration(res)
    const = _constant_text(res.symbol, "c", res.Kc, c.finite) + f" ({res.method})"
    _linear_and_relative(
        ax,
        res.ycp,
        res.Dc,
        100.0 * res.Drc,
        None if d is None else (d.ycp, d.Dc, 100.0 * d.Drc),
        "calibrated image size $y_c'$ (mm)",
        "calibrated linear distortion $D_c$ (mm)",
        "calibrated relative distortion $D_{rc}$ (%)",
        title or _heading("Calibrated linear and % distortion", c, const),
    )
    return fig


# ------------------------------------------------------------------ Fig. 4


def rotated_characteristic(res: CalibrationResult) -> tuple[np.ndarray, np.ndarray]:
    """The characteristic curve rotated through −ρ_k (Section IV.A), plotted with exaggeration k.

    With X = y0' and Y = k·D0 (plot units), the paper's abscissa transformation for a rotated
    curve is ``X' = X/cos ρ_k − Y sin ρ_k``. The paper gives no ordinate formula; the ordinate is
    that of the rigid rotation, ``Y' = Y cos ρ_k − X sin ρ_k``, returned in mm of distortion
    (``Y'/k``). Returns ``(X', Y'/k)``.
    """
    c = res.curve
    rk = math.atan(res.k * res.scale_error)
    X, Y = c.y0p, res.k * c.D0
    Xp = X / math.cos(rk) - Y * math.sin(rk)
    Yp = Y * math.cos(rk) - X * math.sin(rk)
    return Xp, Yp / res.k


def plot_rotation(res: CalibrationResult, *, ax=None, title: str | None = None):
    """Pestrecov's Fig. 4: the characteristic curve rotated through −ρ_k
    (:func:`rotated_characteristic`) against the calibrated curve D_c(y_c'); both in mm.

    Lines: the dense trace (traced results) or a monotone spline through the points (tables);
    markers at the field points. The angle is that of Pestrecov's Eqs. (13)–(14):
    ``tan ρ = K_c/K_0 − 1`` and ``tan ρ_k = k·tan ρ`` with the plot exaggeration k of the
    calibration; the rotated abscissa is ``X' = X/cos ρ_k − Y sin ρ_k`` (Section IV.A). The legend
    states ρ_k in degrees and k.

    Parameters
    ----------
    res : CalibrationResult
        From :func:`distortion.calibration.calibrate` (``osc.calibrate``); its ``k`` (the
        ``k=`` of the calibration, default 200 as in the paper's Fig. 2) sets ρ_k.
    ax : matplotlib.axes.Axes, optional
        Draw here; default a new pyplot figure.
    title : str, optional
        Replaces the default title (which is wrapped to the axes width either way).

    Returns
    -------
    matplotlib.figure.Figure
    """
    c = res.curve
    fig, ax = figure_and_axes(ax, figsize=FIGSIZE)
    Xp, Dp = rotated_characteristic(res)
    d = _dense_calibration(res)
    ax.axhline(0.0, **ZERO)
    if d is not None:
        rot_dense = rotated_characteristic(d)
        cal_dense = (d.ycp, d.Dc)
    else:
        rot_dense = monotone_spline(Xp, Dp)
        cal_dense = monotone_spline(res.ycp, res.Dc)
    h1 = dense_and_markers(ax, rot_dense, (Xp, Dp), color="tab:red", ls="--", marker="o")
    h2 = dense_and_markers(ax, cal_dense, (res.ycp, res.Dc), color=LINEAR, marker="s", ms=3.5)
    rho = (
        rf"characteristic, rotated by $-\rho_k$ ($\rho_k$ = {res.rho_k_deg:.2f}°, "
        f"$k$ = {fmt(res.k, 4)})"
    )
    cal = "calibrated, " + _constant_text(res.symbol, "c", res.Kc, c.finite)
    ax.set_xlabel("image size $X'$ (rotated) / $y_c'$ (calibrated) (mm)")
    ax.set_ylabel("linear distortion (mm)")
    _grid_from_zero(ax, Xp)
    legend(ax, [h1, h2], [rho, cal], loc="lower left")
    set_title(ax, title or _heading("Shapes of characteristic and calibrated distortion curves", c))
    return fig


# ------------------------------------------------------------------ Fig. 6

_STYLES = [("-", "o"), ("--", "s"), ("-.", "^"), (":", "D"), ("-", "v"), ("--", "P")]


def plot_planes(
    curves: list[DistortionCurve] | CharacteristicDistortion,
    *,
    against: str = "field",
    ax=None,
    title: str | None = None,
):
    """Pestrecov's Fig. 6: characteristic linear distortion D_0 (mm) in several image planes on one
    chart.

    Parameters
    ----------
    curves : list of DistortionCurve, or a CharacteristicDistortion with several planes
        One curve per plane. Traced curves are traced again densely; tabulated ones are joined
        by a monotone spline (module docstring). Legend: the plane of each traced curve (s' in
        mm), else each curve's ``plane`` text.
    against : {"field", "image"}
        Abscissa: the field (angle α in degrees or object height in mm, common to all planes, as
        Fig. 6 and Table V) or the ideal image size y_0' (mm) of each plane.
    ax, title
        As :func:`plot_characteristic`.

    Returns
    -------
    matplotlib.figure.Figure
    """
    if isinstance(curves, CharacteristicDistortion):
        curves = [curves.curve(i) for i in range(curves.n_planes)]
    if not curves:
        raise DataError("no curves to plot")
    if against not in ("field", "image"):
        raise ValueError(f"against must be 'field' or 'image', got {against!r}")
    fig, ax = figure_with_zero(ax, figsize=FIGSIZE)
    handles, labels = [], []
    traces: dict = {}
    for i, c in enumerate(curves):
        d = dense_curve(c, cache=traces)
        x = c.fields if against == "field" else c.y0p
        dx = None if d is None else (d.fields if against == "field" else d.y0p)
        ls, mk = _STYLES[i % len(_STYLES)]
        h = dense_and_markers(
            ax,
            _interp(x, c.D0, dx, None if d is None else d.D0),
            (x, c.D0),
            color=f"C{i}",
            ls=ls,
            marker=mk,
            ms=3.5,
        )
        handles.append(h)
        labels.append(_plane_text(c) or f"plane {i + 1}")
    c0 = curves[0]
    label_axes(
        ax,
        _field_axis_label(c0.field_kind) if against == "field" else "ideal image size $y_0'$ (mm)",
        "linear distortion $D_0$ (mm)",
    )
    legend(ax, handles, labels)
    head = "Characteristic linear distortion in several image planes"
    set_title(ax, title or (f"{head} — {c0.name}" if c0.name else head))
    return fig


# ------------------------------------------------------------------ the one entry point


def plot_distortion(
    distortion: DistortionCurve | CharacteristicDistortion,
    calibration: CalibrationResult | None = None,
    *,
    ax=None,
    title: str | None = None,
):
    """The chart that fits the result: the calibrated curve (Fig. 3) when ``calibration`` is
    given, the curves of several image planes (Fig. 6) for a multi-plane result, else the
    characteristic linear and relative distortion (Fig. 2).

    Pestrecov (1958) Figs. 2, 3 and 6: :func:`plot_characteristic` (D_0 in mm and D_r in % of
    Eqs. 8–9), :func:`plot_calibrated` (D_c in mm and D_rc in % of Eqs. 10–15) or
    :func:`plot_planes` (D_0 in mm against the field, one curve per image plane).

    Parameters
    ----------
    distortion : CharacteristicDistortion or DistortionCurve
        A traced result (traced again densely for smooth lines; a multi-plane result gives
        Fig. 6) or a table (a monotone spline through its points). A
        :class:`~distortion.characteristic.ChromaticDistortion` is refused: pick one wavelength
        with ``result.at(nm)``.
    calibration : CalibrationResult, optional
        A calibration (``osc.calibrate``) of ``distortion`` or of one of its image planes; the
        chart is then that calibration's Fig. 3 (``distortion`` only checked against it:
        ``DataError`` for a calibration of another curve, ``TypeError`` for another type).
    ax : matplotlib.axes.Axes, optional
        Draw here (default a new pyplot figure), e.g.
        ``fig, (a, b) = plt.subplots(1, 2); osc.plot_distortion(d, ax=a)``.
    title : str, optional
        Replaces the default title (which is wrapped to the axes width either way).

    Returns
    -------
    matplotlib.figure.Figure
    """
    if calibration is not None:
        _check_same_curve(distortion, calibration)
        return plot_calibrated(calibration, ax=ax, title=title)
    if isinstance(distortion, CharacteristicDistortion) and distortion.n_planes > 1:
        return plot_planes(distortion, ax=ax, title=title)
    return plot_characteristic(distortion, ax=ax, title=title)


def _check_same_curve(distortion, calibration) -> None:
    """Refuse a calibration of another curve than ``distortion`` (the figure draws the
    calibration's own curve: ``distortion`` would be ignored)."""
    if not isinstance(calibration, CalibrationResult):
        raise TypeError(
            f"calibration must be a CalibrationResult (osc.calibrate(...)), not "
            f"{type(calibration).__name__}"
        )
    c = calibration.curve
    if isinstance(distortion, CharacteristicDistortion):
        curves = [distortion.curve(i) for i in range(distortion.n_planes)]
    elif isinstance(distortion, DistortionCurve):
        curves = [distortion]
    else:
        raise TypeError(
            f"distortion must be a CharacteristicDistortion or a DistortionCurve, not "
            f"{type(distortion).__name__} (a ChromaticDistortion: pick one wavelength, "
            "result.at(nm))"
        )

    def same(a) -> bool:
        return (
            a.field_kind == c.field_kind
            and a.constant == c.constant
            and np.array_equal(a.fields, c.fields)
            and np.array_equal(a.D0, c.D0, equal_nan=True)
        )

    if not any(same(a) for a in curves):
        raise DataError(
            f"the calibration is of another curve ({c.name or 'unnamed'}, {c.plane or 'its plane'}"
            f", {c.fields.size} fields) than the distortion given: pass the result it came from, "
            "or calibrate this one (osc.calibrate(distortion))"
        )


def png_bytes(fig, dpi: int = 100) -> bytes:
    """The figure as PNG bytes (for notebooks: ``IPython.display.Image(png_bytes(fig))``)."""
    import io

    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi, bbox_inches="tight")
    return buf.getvalue()
