"""Plots in the style of Fraser & Shortis (1992) Figs. 1–7.

* :func:`plot_profiles` — δr (µm) against radial distance (mm), one curve per profile; profiles
  in their plane of focus solid ("12×"), object planes off focus dashed ("8×(12×)": object plane
  at 8× with the lens focused at 12×), as in Fig. 2.
* :func:`plot_g` — g_ss' against radial distance, per object plane; radii where
  |δr_s' − δr_s| is below the threshold dashed with open markers (weak determination,
  Figs. 5–6), the least-squares g as a thin horizontal line.

Markers sit at the radii of the profiles (measured, or the common grid of a traced study); the
lines join them with the monotone cubic spline of Fritsch & Carlson
(``scipy.interpolate.PchipInterpolator``), the interpolant the analysis itself uses: it passes
through every point and never overshoots between two of them — nothing is invented between the
radii. Both functions take ``ax=`` and return the Figure (:mod:`orthoscope.plots.common`).
"""

from __future__ import annotations

from pathlib import Path

import matplotlib
import numpy as np

from distortion.variation.analysis import VariationAnalysis

from .common import (
    FIGSIZE,
    GRID,
    ZERO,
    dense_and_markers,
    figure_and_axes,
    legend,
    monotone_spline,
    set_title,
)


def _colours() -> list:
    return matplotlib.rcParams["axes.prop_cycle"].by_key()["color"]


def _source(a: VariationAnalysis) -> str:
    """The data's name for a title: a file's name, or the text as given (e.g. a lens name)."""
    s = a.source or ""
    return (Path(s).name if s.lower().endswith(".csv") else s) or "profiles"


def _finish(ax, ylabel: str, title: str, handles: list, labels: list[str], key: str) -> None:
    """Axis labels (radial distance r across), the wrapped title, the grid and — when there are
    curves — the legend titled ``key``."""
    ax.set_xlabel("radial distance r (mm)")
    ax.set_ylabel(ylabel)
    set_title(ax, title)
    ax.grid(True, **GRID)
    if handles:
        legend(ax, handles, labels, title=key, fontsize=8, title_fontsize=8)


def _analysis(a) -> VariationAnalysis:
    """The analysis of a :class:`VariationAnalysis` or of a ``trace_variation`` result."""
    a = getattr(a, "analysis", a)
    if not isinstance(a, VariationAnalysis):
        raise TypeError(
            f"expected a VariationAnalysis or a trace_variation result, not {type(a).__name__}"
        )
    return a


def _start(a, ax):
    """``(analysis, figure, ax, colours)``: the analysis of ``a`` (:func:`_analysis`), the figure
    and its Axes (:func:`figure_and_axes`) and the colour cycle."""
    a = _analysis(a)
    fig, ax = figure_and_axes(ax, figsize=FIGSIZE)
    return a, fig, ax, _colours()


def plot_profiles(a: VariationAnalysis, *, ax=None, title: str | None = None):
    """Radial distortion profiles i×(j×) of an analysis (Fraser & Shortis Figs. 1–4 style):
    δr (µm) against the radial distance r (mm); Gaussian profiles (object plane = plane of
    focus) solid with filled markers, off-focus object planes dashed with open markers.

    Parameters
    ----------
    a : VariationAnalysis or TracedVariation
        From :func:`distortion.variation.analyze_variation` or :func:`trace_variation`.
    ax : matplotlib.axes.Axes, optional
        Draw here; default a new pyplot figure.
    title : str, optional
        Replaces the default title (wrapped to the axes width either way).

    Returns
    -------
    matplotlib.figure.Figure
    """
    a, fig, ax, colours = _start(a, ax)
    handles, labels = [], []
    for i, p in enumerate(a.profiles):
        gauss = p.focus == p.obj
        c = colours[i % len(colours)]
        h = dense_and_markers(
            ax,
            monotone_spline(p.r_mm, p.dr_um),
            (p.r_mm, p.dr_um),
            color=c,
            ls="-" if gauss else "--",
            marker="o" if gauss else "s",
            ms=3.5 if gauss else 3.0,
            mfc=None if gauss else "white",
            lw=1.3,
        )
        handles.append(h)
        labels.append(p.label)
    ax.axhline(0.0, **ZERO)
    _finish(
        ax,
        r"radial distortion $\delta r$ (µm)",
        title or f"Radial distortion profiles — {_source(a)}",
        handles,
        labels,
        "object plane (plane of focus)",
    )
    return fig


def _strong_segments(r: np.ndarray, strong: np.ndarray, rd: np.ndarray) -> np.ndarray:
    """Mask of dense radii ``rd`` lying between two neighbouring strong radii of ``r``."""
    k = np.clip(np.searchsorted(r, rd, side="right") - 1, 0, r.size - 2)
    return strong[k] & strong[k + 1]


def plot_g(a: VariationAnalysis, *, ax=None, title: str | None = None):
    """g_ss' (Fraser & Shortis Eq. 6) against the radial distance r (mm) per object plane
    (Figs. 5–7 style). Radii of weak determination (|δr_s' − δr_s| below the analysis threshold)
    are open markers on a dashed line; the estimated g of each plane is a thin horizontal line.
    ``ax``, ``title``: as :func:`plot_profiles`. Returns the Figure.

    g_ss' is dimensionless: the pointwise values of Eq. (6) from the profiles δr (µm) of the
    analysis; the legend gives each plane's least-squares g ± its standard error, or
    "undetermined". The y range is set from the 2nd–98th percentiles of the strong values.

    Parameters
    ----------
    a : VariationAnalysis or TracedVariation
        From :func:`distortion.variation.analyze_variation` or :func:`trace_variation`; its
        ``threshold_um`` (µm) separates weak from strong radii.
    ax : matplotlib.axes.Axes, optional
        Draw here; default a new pyplot figure.
    title : str, optional
        Replaces the default title (wrapped to the axes width either way).

    Returns
    -------
    matplotlib.figure.Figure
    """
    a, fig, ax, colours = _start(a, ax)
    k = 0
    finite = []
    handles, labels = [], []
    for fs in a.focus_summaries:
        for pl in fs.planes:
            e = pl.estimate
            c = colours[k % len(colours)]
            k += 1
            ok = np.isfinite(e.g_pointwise)
            r, g, weak = e.r_mm[ok], e.g_pointwise[ok], e.weak[ok]
            if r.size == 0:
                continue
            rd, gd = monotone_spline(r, g)
            # the whole curve dashed (thin); the stretches between two strong radii solid on top
            ax.plot(rd, gd, "--", color=c, lw=0.9)
            if r.size > 1 and rd.size == np.unique(rd).size:
                solid = np.where(_strong_segments(r, ~weak, rd), gd, np.nan)
            else:
                solid = np.where(~weak, g, np.nan)
                rd = r
            h = dense_and_markers(
                ax,
                (rd, solid),
                (r[~weak], g[~weak]),
                color=c,
                marker="o",
                ms=3.5,
                lw=1.4,
            )
            ax.plot(r[weak], g[weak], ls="none", marker="o", ms=3.5, color=c, mfc="white")
            g_txt = f"$g$ = {e.g:.3f} ± {e.se:.3f}" if e.determined else "undetermined"
            handles.append(h)
            labels.append(f"{pl.obj.label}({pl.focus.label}): {g_txt}")
            if e.determined:
                ax.axhline(e.g, color=c, lw=0.6, alpha=0.7)
            finite.extend(g[~weak])
    if finite:
        lo, hi = np.percentile(finite, [2, 98])
        pad = max(0.1, 0.25 * (hi - lo))
        ax.set_ylim(lo - pad, hi + pad)
    _finish(
        ax,
        "distortion factor $g_{ss'}$ (dimensionless)",
        title or f"Distortion factor $g_{{ss'}}$ (Eq. 6) — {_source(a)}",
        handles,
        labels,
        rf"dashed, open: $|\delta r_{{s'}} - \delta r_s|$ < {a.threshold_um:g} µm (weak)",
    )
    if not handles:
        ax.text(
            0.5,
            0.5,
            "no $g_{ss'}$ determinable from these profiles",
            ha="center",
            transform=ax.transAxes,
        )
    return fig
