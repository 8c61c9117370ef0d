"""Plots in the style of Fraser & Shortis (1992) Figs. 1–7.

* :func:`plot_profiles` — δr (µm) against radial distance (mm), one curve per profile; profiles
  in their plane of focus solid ("12×"), object planes off focus dashed ("8×(12×)": object plane
  at 8× with the lens focused at 12×), as in Fig. 2.
* :func:`plot_g` — g_ss' against radial distance, per object plane; radii where
  |δr_s' − δr_s| is below the threshold dashed (weak determination, Figs. 5–6), the least-squares
  g as a thin horizontal line.

Both return the matplotlib Figure (no pyplot, no backend needed); ``path`` saves a PNG.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib
import numpy as np
from matplotlib.figure import Figure

from distortion.variation.analysis import VariationAnalysis


def plot_profiles(
    a: VariationAnalysis, *, title: str | None = None
):
    """Radial distortion profiles i×(j×) of an analysis (Figs. 1–4 style)."""
    fig = Figure(figsize=(7, 5))
    ax = fig.subplots()
    colors = matplotlib.rcParams["axes.prop_cycle"].by_key()["color"]
    for i, p in enumerate(a.profiles):
        gauss = p.focus == p.obj
        ax.plot(
            p.r_mm,
            p.dr_um,
            "-" if gauss else "--",
            marker="o" if gauss else ".",
            ms=3,
            color=colors[i % len(colors)],
            label=p.label,
        )
    ax.axhline(0.0, color="0.6", lw=0.6)
    ax.set_xlabel("radial distance r (mm)")
    ax.set_ylabel("radial distortion δr (µm)")
    ax.set_title(title or f"Radial distortion profiles — {Path(a.source).name or 'profiles'}")
    ax.grid(True, lw=0.3)
    ax.legend(title="i×(j×): object i×, focus j×", fontsize=8, title_fontsize=8)
    fig.tight_layout()
    return fig


def plot_g(a: VariationAnalysis, *, title: str | None = None):
    """g_ss' against radial distance (Figs. 5–7 style); weak radii dashed."""
    fig = Figure(figsize=(7, 5))
    ax = fig.subplots()
    colors = matplotlib.rcParams["axes.prop_cycle"].by_key()["color"]
    k = 0
    finite = []
    for fs in a.focus_summaries:
        for pl in fs.planes:
            e = pl.estimate
            c = colors[k % len(colors)]
            k += 1
            lab = f"{pl.obj.label}({pl.focus.label})"
            ax.plot(e.r_mm, e.g_pointwise, "--", color=c, lw=0.9)
            strong = np.where(e.weak, np.nan, e.g_pointwise)
            g_txt = f"g = {e.g:.3f} ± {e.se:.3f}" if e.determined else "undetermined"
            ax.plot(e.r_mm, strong, "-", marker="o", ms=3, color=c, label=f"{lab}: {g_txt}")
            if e.determined:
                ax.axhline(e.g, color=c, lw=0.6, alpha=0.7)
            finite.extend(strong[np.isfinite(strong)])
    if finite:
        lo, hi = np.percentile(finite, [2, 98])
        pad = max(0.1, 0.25 * (hi - lo))
        ax.set_ylim(lo - pad, hi + pad)
    ax.set_xlabel("radial distance r (mm)")
    ax.set_ylabel("g_ss' (dimensionless)")
    ax.set_title(title or f"Distortion factor g_ss' (Eq. 6) — {Path(a.source).name or 'profiles'}")
    ax.grid(True, lw=0.3)
    if k:
        ax.legend(
            fontsize=8, title=f"dashed: |δr_s' − δr_s| < {a.threshold_um:g} µm", title_fontsize=8
        )
    else:
        ax.text(
            0.5,
            0.5,
            "no g_ss' determinable from these profiles",
            ha="center",
            transform=ax.transAxes,
        )
    fig.tight_layout()
    return fig
