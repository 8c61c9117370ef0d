"""Distortion charts in the style of Pestrecov 1958, Figs. 2, 3, 4 and 6 (matplotlib Figure API).

Every function draws one figure and returns it (so tests and notebooks can inspect the lines);
:func:`orthoscope.plots.save.save_figure` writes it.
Linear distortion in mm, relative distortion in per cent, image sizes in mm.
"""

from __future__ import annotations

import math

import numpy as np
from matplotlib.figure import Figure

from distortion.calibration import CalibrationResult
from distortion.curve import DistortionCurve
from distortion.errors import DataError

def _title(name: str, plane: str, what: str) -> str:
    head = " ".join(s for s in (name, plane) if s)
    return f"{what}\n{head}" if head else what


def _two_axes(x, lin, rel, xlabel, lin_label, rel_label, title):
    fig = Figure(figsize=(7.0, 4.6))
    ax = fig.subplots()
    ax.axhline(0.0, color="0.4", lw=0.8)
    (l1,) = ax.plot(x, lin, "-o", color="k", ms=4, label=lin_label)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(lin_label)
    ax2 = ax.twinx()
    (l2,) = ax2.plot(x, rel, "--s", color="tab:blue", ms=4, label=rel_label)
    ax2.set_ylabel(rel_label, color="tab:blue")
    ax2.tick_params(axis="y", colors="tab:blue")
    # share the zero line between the two scales
    for a, v in ((ax, lin), (ax2, rel)):
        m = float(np.nanmax(np.abs(v))) if np.size(v) else 1.0
        m = m if m > 0 else 1.0
        a.set_ylim(-1.15 * m, 1.15 * m)
    ax.set_xlim(left=0.0 if np.nanmin(x) >= 0 else None)
    ax.grid(True, color="0.85", lw=0.6)
    ax.legend(handles=[l1, l2], loc="upper left", frameon=False)
    ax.set_title(title, fontsize=10)
    fig.tight_layout()
    return fig, ax, ax2


def plot_characteristic(curve: DistortionCurve):
    """Fig. 2: characteristic linear (mm, left axis) and per-cent distortion (right axis) against
    the ideal image size y0' (mm)."""
    k = f"{curve.symbol}0 = {curve.constant:.4f}{'' if curve.finite else ' mm'}"
    fig, *_ = _two_axes(
        curve.y0p,
        curve.D0,
        100.0 * curve.Dr,
        "ideal image size y0' (mm)",
        "linear distortion D0 (mm)",
        "relative distortion Dr (%)",
        _title(curve.name, curve.plane, f"Characteristic linear and % distortion ({k})"),
    )
    return fig


def plot_calibrated(res: CalibrationResult):
    """Fig. 3: calibrated linear (mm) and per-cent distortion against calibrated image size y_c'."""
    c = res.curve
    k = f"{res.symbol}c = {res.Kc:.4f}{'' if c.finite else ' mm'}, {res.method}"
    fig, *_ = _two_axes(
        res.ycp,
        res.Dc,
        100.0 * res.Drc,
        "calibrated image size yc' (mm)",
        "calibrated linear distortion Dc (mm)",
        "calibrated relative distortion Drc (%)",
        _title(c.name, c.plane, f"Calibrated linear and % distortion ({k})"),
    )
    return fig


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


def plot_rotation(res: CalibrationResult):
    """Fig. 4: the characteristic curve rotated by −ρ_k vs the calibrated curve (D_c vs y_c')."""
    c = res.curve
    Xp, Dp = rotated_characteristic(res)
    fig = Figure(figsize=(7.0, 4.6))
    ax = fig.subplots()
    ax.axhline(0.0, color="0.4", lw=0.8)
    ax.plot(
        Xp,
        Dp,
        "--o",
        color="tab:red",
        ms=4,
        label=f"characteristic, rotated by −ρk (ρk = {res.rho_k_deg:.2f}°, k = {res.k:g})",
    )
    ax.plot(
        res.ycp, res.Dc, "-s", color="k", ms=4, label=f"calibrated, {res.symbol}c = {res.Kc:.3f}"
    )
    ax.set_xlabel("image size: X' (rotated) / yc' (calibrated) (mm)")
    ax.set_ylabel("linear distortion (mm)")
    ax.set_xlim(left=0.0 if np.nanmin(Xp) >= 0 else None)
    ax.grid(True, color="0.85", lw=0.6)
    ax.legend(loc="lower left", frameon=False, fontsize=9)
    ax.set_title(
        _title(c.name, c.plane, "Shapes of characteristic and calibrated distortion curves"),
        fontsize=10,
    )
    fig.tight_layout()
    return fig


def plot_planes(
    curves: list[DistortionCurve], *, against: str = "field", title: str | None = None
):
    """Fig. 6: linear distortion curves in several image planes on one chart.

    against: ``"field"`` (field angle / object height, common to all planes — as Fig. 6 and
    Table V) or ``"image"`` (the ideal image size y0' of each plane). Labels come from each
    curve's ``plane``.
    """
    if not curves:
        raise DataError("no curves to plot")
    if against not in ("field", "image"):
        raise ValueError(f"against must be 'field' or 'image', got {against!r}")
    fig = Figure(figsize=(7.0, 4.6))
    ax = fig.subplots()
    ax.axhline(0.0, color="0.4", lw=0.8)
    styles = ["-o", "--s", "-.^", ":D", "-v", "--x"]
    for i, c in enumerate(curves):
        x = c.fields if against == "field" else c.y0p
        ax.plot(
            x, c.D0, styles[i % len(styles)], color=f"C{i}", ms=4, label=c.plane or f"plane {i + 1}"
        )
    c0 = curves[0]
    ax.set_xlabel(
        c0.field_label.replace("α", "field angle α")
        if against == "field"
        else "ideal image size y0' (mm)"
    )
    ax.set_ylabel("linear distortion D0 (mm)")
    ax.grid(True, color="0.85", lw=0.6)
    ax.legend(frameon=False, fontsize=9)
    ax.set_title(
        title or _title(c0.name, "", "Characteristic linear distortion in several image planes"),
        fontsize=10,
    )
    fig.tight_layout()
    return fig


def png_bytes(fig, dpi: int = 100) -> bytes:
    """The figure as PNG bytes (for notebooks: ``IPython.display.Image(png_bytes(fig))``)."""
    import io

    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi, bbox_inches="tight")
    return buf.getvalue()


def plot_distortion(distortion, calibration: CalibrationResult | None = None):
    """The chart that fits the result: a calibrated curve (Fig. 3) when ``calibration`` is given,
    the curves of several image planes (Fig. 6) for a multi-plane result, else the characteristic
    linear and relative distortion (Fig. 2). ``distortion`` is a
    :class:`~distortion.characteristic.CharacteristicDistortion` or a
    :class:`~distortion.curve.DistortionCurve`. Returns the Figure."""
    if calibration is not None:
        return plot_calibrated(calibration)
    if isinstance(distortion, DistortionCurve):
        return plot_characteristic(distortion)
    if distortion.n_planes > 1:
        return plot_planes([distortion.curve(i) for i in range(distortion.n_planes)])
    return plot_characteristic(distortion.curve(0))
