"""Plots of the chief-ray angle (telecentricity), the distortion slope ∂D0/∂s' and the entrance
pupil (viewpoint) shift against the field (:mod:`distortion.telecentricity`). Every function
keeps the ``ax=`` convention of :mod:`orthoscope.plots.common`."""

from __future__ import annotations

import numpy as np

from distortion.curve import HEIGHT
from distortion.errors import DataError
from distortion.telecentricity import PupilAnalysis

from .common import figure_with_zero, fmt, label_axes, panel_figure, set_title


def _check(pa) -> None:
    if not isinstance(pa, PupilAnalysis):
        raise DataError(
            f"expected a PupilAnalysis (distortion.telecentricity.pupil_analysis), got "
            f"{type(pa).__name__}"
        )


def _xlabel(pa: PupilAnalysis) -> str:
    if pa.field_kind == HEIGHT:
        return "object height y (mm)"
    return "nominal field angle (deg)" if pa.finite else "field angle (deg)"


def _ok(pa: PupilAnalysis, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    m = np.isfinite(v)
    return pa.fields[m], v[m]


def _axes(pa, ax):
    """Check ``pa``; ``(figure, ax)`` with the zero line drawn (:func:`figure_with_zero`)."""
    _check(pa)
    return figure_with_zero(ax)


def _twin(ax, pa: PupilAnalysis, v: np.ndarray, style: str, color: str, ms: float, ylabel: str):
    """The finite values ``v`` on a right scale (``ax.twinx()``) labelled in their colour;
    returns the line."""
    tw = ax.twinx()
    (line,) = tw.plot(*_ok(pa, v), style, color=color, ms=ms)
    tw.set_ylabel(ylabel, color=color)
    return line


def _legend(ax, handles: list, labels: list[str]) -> None:
    ax.legend(handles, labels, fontsize=8, frameon=False)


def plot_chief_ray_angle(pa: PupilAnalysis, *, ax=None, title: str | None = None):
    """The image-side chief-ray angle (deg) of the real chief ray against the field, with the
    paraxial chief ray scaled linearly to the field (dashed; left scale), and their difference
    (right scale) — the pupil aberration that makes distortion change from plane to plane.
    0 everywhere = image-side telecentric.

    The angle α' of the final segment with the axis is signed like its direction cosine M
    (``atan2(M, N)``; :mod:`distortion.telecentricity`); the paraxial one is
    ``atan(x·dK0/ds')``. Field axis in degrees (field angles; nominal angles for a finite
    object) or mm (object heights).

    Parameters
    ----------
    pa : PupilAnalysis
        From ``osc.pupil_analysis`` (``DataError`` for anything else).
    ax : matplotlib.axes.Axes, optional
        Draw here (the difference scale goes on ``ax.twinx()``); default a new pyplot figure.
    title : str, optional
        Replaces the default title (which is wrapped to the axes width either way).

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, ax = _axes(pa, ax)
    (a,) = ax.plot(*_ok(pa, pa.cra_deg), "o-", color="tab:blue", ms=4)
    (b,) = ax.plot(pa.fields, pa.cra_paraxial_deg, "--", color="0.35", lw=1.0)
    label_axes(ax, _xlabel(pa), "chief-ray angle in image space (deg)", color="tab:blue")
    diff = pa.cra_deg - pa.cra_paraxial_deg
    c = _twin(ax, pa, diff, "s:", "tab:orange", 3, "real − paraxial (deg)")
    cra = f"real (max |CRA| {fmt(pa.max_abs_cra_deg, 4)}°)"
    _legend(ax, [a, b, c], [cra, "paraxial", "real − paraxial"])
    set_title(ax, title or f"{pa.name}: image-side chief-ray angle")
    return fig


def plot_distortion_slope(pa: PupilAnalysis, *, ax=None, title: str | None = None):
    """∂D0/∂s' (µm of distortion per mm of image-plane shift) against the field: how the
    characteristic distortion changes from one image plane to another (exact, Eq. 8).

    ``∂D0/∂s' = tan α' − x·dK0/ds'`` with K0 the constant of orthoscopy of Pestrecov (1958)
    Eq. (8) in the actual plane and D0 of Eq. (9): D0 is affine in s', so
    ``D0(s'_2) = D0(s'_1) + (s'_2 − s'_1)·∂D0/∂s'`` exactly (s' in mm from H'). Field axis
    in degrees (field angles; nominal angles for a finite object) or mm (object heights).

    Parameters
    ----------
    pa : PupilAnalysis
        From ``osc.pupil_analysis`` (``DataError`` for anything else); ``pa.slope`` is in mm/mm.
    ax : matplotlib.axes.Axes, optional
        Draw here; default a new pyplot figure.
    title : str, optional
        Replaces the default title (which is wrapped to the axes width either way).

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, ax = _axes(pa, ax)
    ax.plot(*_ok(pa, 1000.0 * pa.slope), "o-", color="tab:red", ms=4)
    label_axes(ax, _xlabel(pa), "∂D0/∂s' (µm per mm)")
    set_title(ax, title or f"{pa.name}: change of distortion with the image plane")
    return fig


def plot_entrance_pupil(pa: PupilAnalysis, *, ax=None, title: str | None = None):
    """The real entrance pupil's shift from the paraxial E0 along the axis (mm, left scale) and
    the lateral viewpoint offset — the distance of the object-space chief ray from E0 (mm, right
    scale) — against the field.

    The shift is z_EP − z_E0 (absolute z, light toward +z); the offset is the signed
    perpendicular distance ``(z_EP − z_E0)·sin θ`` (θ the real object-space chief-ray angle),
    zero at every field for a single-viewpoint camera (:mod:`distortion.telecentricity`). Field
    axis in degrees (field angles; nominal angles for a finite object) or mm (object heights).

    Parameters
    ----------
    pa : PupilAnalysis
        From ``osc.pupil_analysis`` (``DataError`` for anything else).
    ax : matplotlib.axes.Axes, optional
        Draw here (the offset scale goes on ``ax.twinx()``); default a new pyplot figure.
    title : str, optional
        Replaces the default title (which is wrapped to the axes width either way).

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, ax = _axes(pa, ax)
    (a,) = ax.plot(*_ok(pa, pa.entrance_pupil_shift), "o-", color="tab:green", ms=4)
    label_axes(ax, _xlabel(pa), "entrance pupil shift from E0 (mm)", color="tab:green")
    b = _twin(ax, pa, pa.viewpoint_offset, "s--", "tab:purple", 3.5, "viewpoint offset (mm)")
    _legend(ax, [a, b], ["entrance pupil shift (axial)", "viewpoint offset (lateral)"])
    set_title(ax, title or f"{pa.name}: entrance pupil (viewpoint) with field")
    return fig


def plot_pupils(pa: PupilAnalysis):
    """One figure of three panels: chief-ray angle, ∂D0/∂s' and the entrance-pupil shift.

    :func:`plot_chief_ray_angle`, :func:`plot_distortion_slope` and :func:`plot_entrance_pupil`
    side by side, with their default titles.

    Parameters
    ----------
    pa : PupilAnalysis
        From ``osc.pupil_analysis`` (``DataError`` for anything else).

    Returns
    -------
    matplotlib.figure.Figure
        A new figure of 15 × 4.6 inches (no ``ax=``: the figure is its own).
    """
    _check(pa)
    fig, axs = panel_figure(1, 3, figsize=(15.0, 4.6))
    plot_chief_ray_angle(pa, ax=axs[0])
    plot_distortion_slope(pa, ax=axs[1])
    plot_entrance_pupil(pa, ax=axs[2])
    return fig
