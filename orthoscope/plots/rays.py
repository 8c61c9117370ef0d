"""Transverse ray-aberration plots (ray fans) and spot diagrams.

Both follow the ``ax=`` convention of :mod:`orthoscope.plots.common`: draw into ``ax`` when given,
else make a new figure; return the Figure. Aberrations and spot coordinates are in µm relative to
the real chief ray (:mod:`raytrace.trace.fans`).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from raytrace.trace import RayFan, SpotDiagram

from .common import GRID, ZERO, figure_and_axes, figure_with_zero, fmt, set_title


def _field_label(field: float, kind: str) -> str:
    return f"{fmt(field)}°" if kind == "angle" else f"y = {fmt(field)} mm"


def _listed(items, cls: type, refusal: str) -> list:
    """``items`` as a list (one ``cls`` or a sequence of them); ``TypeError(refusal)`` when
    empty."""
    items = [items] if isinstance(items, cls) else list(items)
    if not items:
        raise TypeError(refusal)
    return items


def plot_ray_fan(fans: RayFan | Sequence[RayFan], *, ax=None, title: str | None = None):
    """Transverse ray aberration ε (µm) against the normalised pupil coordinate, one curve per
    fan (tangential: ε_y against p_y, solid; sagittal: ε_x against p_x, dashed).

    ε is the ray's intercept minus the real chief ray's in the fan's image plane (x', y' in the
    lens frame, mm, drawn in µm); pupil coordinates run from −1 to 1. Rays that failed are left
    out. One colour per field (degrees, or object height in mm); the title states the first
    fan's wavelength (nm).

    Parameters
    ----------
    fans : RayFan or sequence of RayFan
        From ``osc.ray_fan`` (e.g. a tangential and a sagittal fan per field).
    ax : matplotlib.axes.Axes, optional
        Draw here; default a new pyplot figure.
    title : str, optional
        Replaces the default title (which is wrapped to the axes width either way).

    Returns
    -------
    matplotlib.figure.Figure
    """
    fans = _listed(
        fans, RayFan, "plot_ray_fan needs at least one RayFan (osc.ray_fan(lens, field))"
    )
    fig, ax = figure_with_zero(ax)
    ax.axvline(0.0, **ZERO)
    fields = sorted({(f.field, f.field_kind) for f in fans})
    colour = {key: f"C{i}" for i, key in enumerate(fields)}
    for f in fans:
        ok = f.status == 0
        style = "-" if f.axis == "y" else "--"
        name = "$\\varepsilon_y(p_y)$" if f.axis == "y" else "$\\varepsilon_x(p_x)$"
        ax.plot(
            f.pupil[ok],
            1000.0 * f.aberration[ok],
            style,
            color=colour[(f.field, f.field_kind)],
            label=f"{_field_label(f.field, f.field_kind)}, {name}",
        )
    ax.set_xlabel("normalised pupil coordinate")
    ax.set_ylabel("transverse ray aberration $\\varepsilon$ (µm)")
    ax.set_xlim(-1.05, 1.05)
    ax.grid(True, **GRID)
    ax.legend(frameon=False, fontsize=8)
    set_title(ax, title or f"Ray fans at {fmt(fans[0].wavelength)} nm")
    return fig


def plot_spot(spots: SpotDiagram | Sequence[SpotDiagram], *, ax=None, title: str | None = None):
    """Spot diagrams side by side (µm, relative to each field's real chief ray), with the RMS
    radius circle about the centroid.

    Each spot is its rays' intercepts minus the chief ray's (x', y' in the lens frame, mm, drawn
    in µm), equal axes; the spots are spaced 2.6 times the largest spot radius apart along x
    (no x ticks) and labelled with their field (degrees, or object height in mm) and RMS radius
    (µm). Rays that failed are left out. The title states the first spot's wavelength (nm).

    Parameters
    ----------
    spots : SpotDiagram or sequence of SpotDiagram
        From ``osc.spot_diagram``, one per field.
    ax : matplotlib.axes.Axes, optional
        Draw here; default a new pyplot figure of 2.6 inches width per spot (+1) by 3.2 inches.
    title : str, optional
        Replaces the default title (which is wrapped to the axes width either way).

    Returns
    -------
    matplotlib.figure.Figure
    """
    spots = _listed(
        spots,
        SpotDiagram,
        "plot_spot needs at least one SpotDiagram (osc.spot_diagram(lens, field))",
    )
    fig, ax = figure_and_axes(ax, figsize=(2.6 * max(1, len(spots)) + 1.0, 3.2))
    span = max(
        (
            float(np.nanmax(np.hypot(s.x - s.centroid_x, s.y - s.centroid_y)))
            for s in spots
            if np.isfinite(s.x).any()
        ),
        default=1e-3,
    )
    step = 2.6 * span * 1000.0
    th = np.linspace(0, 2 * np.pi, 181)
    for i, s in enumerate(spots):
        ok = s.status == 0
        x0 = i * step
        ax.plot(x0 + 1000 * s.x[ok], 1000 * s.y[ok], ".", ms=2.5, color=f"C{i}")
        r = 1000 * s.rms_radius
        ax.plot(x0 + 1000 * s.centroid_x + r * np.cos(th), 1000 * s.centroid_y + r * np.sin(th),
                "-", lw=0.7, color="0.3")  # fmt: skip
        ax.annotate(
            f"{_field_label(s.field, s.field_kind)}\nRMS {fmt(r, 3)} µm",
            (x0, float(np.min(1000 * s.y[ok])) - 0.05 * step),
            ha="center",
            va="top",
            fontsize=8,
        )
    ys = np.concatenate([1000 * s.y[s.status == 0] for s in spots])
    top, bottom = float(np.max(ys)), float(np.min(ys))
    pad = 0.1 * (top - bottom) + 1e-6
    ax.set_aspect("equal")
    ax.set_xlim(-0.6 * step, (len(spots) - 0.4) * step)
    ax.set_ylim(bottom - pad - 0.35 * step, top + pad)
    ax.set_xticks([])
    ax.set_ylabel("y relative to the chief ray (µm)")
    ax.grid(True, **GRID)
    set_title(ax, title or f"Spot diagrams at {fmt(spots[0].wavelength)} nm")
    return fig
