"""Figures of a tolerancing run (:mod:`distortion.tolerance`): the percentile envelope of the
distortion curve over a Monte Carlo batch (raw and calibrated), histograms of the per-lens
outputs (P1, P2, Fc, g, ...) and the ranked sensitivity bars. Every function keeps the ``ax=``
convention of :mod:`orthoscope.plots.common`."""

from __future__ import annotations

import numpy as np

from .common import GRID, ZERO, figure_and_axes, panel_figure, set_title

#: the envelope bands drawn (outer, inner percentile pairs), when the run computed them
BANDS = ((2.5, 97.5), (16.0, 84.0))


def _level(levels, p: float):
    """Index of percentile ``p`` in ``levels`` or None."""
    hit = np.nonzero(np.isclose(np.asarray(levels, dtype=float), p))[0]
    return int(hit[0]) if hit.size else None


def plot_envelope(mc, *, calibrated: bool = False, limits=(), ax=None, title=None):
    """Percentile envelope of the distortion curve D (µm) along +y against the field angle (deg):
    the 2.5–97.5 % and 16–84 % bands, the median and the nominal lens; ``calibrated`` draws
    ``D_cal`` (what a calibration of each lens leaves: camera constant and principal point
    removed). ``limits`` [(µm, deg), ...] are drawn as ± marks. Returns the Figure.

    ``D = y' − K0·tan α`` (Pestrecov 1958, Eq. 9, with K0 of Eq. 8 in the refocused plane) and
    ``D_cal = y' − y0 − c·tan α`` (µm, + = pincushion; :class:`ToleranceOutputs`). A band or the
    median is drawn only when the run computed those percentiles.

    Parameters
    ----------
    mc : MonteCarloResult
        From ``osc.tolerance_monte_carlo`` (exact or streamed summary).
    calibrated : bool
        Draw ``D_cal`` instead of the raw D.
    limits : sequence of (float, float)
        (limit in µm, field angle in degrees) pairs, each drawn as an error bar ±limit about 0
        at that field.
    ax : matplotlib.axes.Axes, optional
        Draw here; default a new pyplot figure.
    title : str, optional
        Replaces the default title (which is wrapped to the axes width either way).

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, ax = figure_and_axes(ax)
    f = np.asarray(mc.fields_deg, dtype=float)
    env = np.asarray(mc.envelope_cal_um if calibrated else mc.envelope_um, dtype=float)
    levels = mc.percentiles
    for (lo, hi), alpha in zip(BANDS, (0.18, 0.32), strict=True):
        a, b = _level(levels, lo), _level(levels, hi)
        if a is not None and b is not None:
            ax.fill_between(f, env[a], env[b], color="C0", alpha=alpha, lw=0,
                            label=f"{lo:g}–{hi:g} %")  # fmt: skip
    m = _level(levels, 50.0)
    if m is not None:
        ax.plot(f, env[m], color="C0", lw=1.4, label="median")
    nom = np.asarray((mc.nominal.D_cal_um if calibrated else mc.nominal.D_um), dtype=float).reshape(
        -1
    )
    ax.plot(f, nom, color="k", lw=1.0, ls="--", label="nominal lens")
    for lim, deg in limits:
        ax.errorbar([deg], [0.0], yerr=[[lim], [lim]], fmt="none", ecolor="C3", capsize=4,
                    lw=1.0)  # fmt: skip
    ax.axhline(0.0, **ZERO)
    ax.grid(True, **GRID)
    ax.set_xlabel("field angle α (deg)")
    ax.set_ylabel("calibrated distortion D_c (µm)" if calibrated else "distortion D (µm)")
    ax.legend(fontsize=8, frameon=False)
    what = "calibrated (Fc and principal point removed)" if calibrated else "raw"
    set_title(ax, title or f"{mc.n} lenses: distortion along +y, {what}")
    return fig


def plot_histogram(values=None, *, label: str, nominal: float | None = None, hist=None, ax=None,
                   title=None):  # fmt: skip
    """Histogram of one per-lens output, with the nominal value marked: ``values`` (finite
    entries are counted) or ``hist`` = (counts, edges) already binned (a streamed Monte Carlo
    summary, :meth:`MonteCarloResult.histogram`). Returns the Figure."""
    fig, ax = figure_and_axes(ax)
    if hist is not None:
        counts, edges = (np.asarray(a) for a in hist)
        if counts.size:
            ax.stairs(counts, edges, fill=True, color="C0", alpha=0.75)
    else:
        v = np.asarray(values, dtype=float)
        v = v[np.isfinite(v)]
        if v.size:
            ax.hist(v, bins=min(60, max(10, int(np.sqrt(v.size)))), color="C0", alpha=0.75)
    if nominal is not None and np.isfinite(nominal):
        ax.axvline(nominal, color="k", ls="--", lw=1.0, label="nominal")
        ax.legend(fontsize=8, frameon=False)
    ax.grid(True, **GRID)
    ax.set_xlabel(label)
    ax.set_ylabel("lenses")
    set_title(ax, title or label)
    return fig


def plot_sensitivity(rows, *, label: str, top: int = 15, ax=None, title=None):
    """Ranked horizontal bars of a sensitivity table (``rows`` as
    :meth:`SensitivityResult.table` returns them: name, delta_min, delta_max): the change at the
    item's min and at its max, the largest ``top`` items. Returns the Figure.

    Parameters
    ----------
    rows : iterable of dict
        Each with ``"name"``, ``"delta_min"`` and ``"delta_max"`` (the output's change, signed,
        in the output's unit), largest first; the first ``top`` are drawn, the largest on top.
    label : str
        The x-axis label: the output and its unit (e.g. ``"ΔD_c at 30° (µm)"``); also the
        default title's.
    top : int
        How many rows to draw.
    ax : matplotlib.axes.Axes, optional
        Draw here; default a new pyplot figure.
    title : str, optional
        Replaces the default title (which is wrapped to the axes width either way).

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, ax = figure_and_axes(ax)
    rows = list(rows)[:top][::-1]
    y = np.arange(len(rows))
    dmin = np.array([r["delta_min"] for r in rows], dtype=float)
    dmax = np.array([r["delta_max"] for r in rows], dtype=float)
    ax.barh(y - 0.2, dmin, height=0.4, color="C0", label="item at min")
    ax.barh(y + 0.2, dmax, height=0.4, color="C1", label="item at max")
    ax.set_yticks(y, [r["name"] for r in rows], fontsize=8)
    ax.axvline(0.0, **ZERO)
    ax.grid(True, axis="x", **GRID)
    ax.set_xlabel(label)
    ax.legend(fontsize=8, frameon=False)
    set_title(ax, title or f"sensitivity: {label}")
    return fig


#: the histogram panels of a run: (output, label, factor from the output's unit)
HISTOGRAMS = (
    ("P1", "P1 (1e-6 / mm)", 1e6),
    ("P2", "P2 (1e-6 / mm)", 1e6),
    ("P1_raw", "P1 raw (1e-6 / mm)", 1e6),
    ("P2_raw", "P2 raw (1e-6 / mm)", 1e6),
    ("c", "calibrated camera constant Fc (mm)", 1.0),
    ("k0", "F0 of the refocused plane (mm)", 1.0),
    ("g", "variation factor g_ss' (Fraser & Shortis)", 1.0),
)


def _hist_panels(mc):
    """((counts, edges), label, nominal) of the histograms of a run — P1, P2 (calibrated and
    raw), Fc, F0, g — for the outputs the run has values of (from the run's own histograms, so
    a streamed run draws them too)."""
    out = []
    for key, lab, fac in HISTOGRAMS:
        if key == "g" and key not in mc.stats:
            continue
        counts, edges = mc.histogram(key)
        if counts.size == 0 or counts.sum() == 0:
            continue
        nom = float(np.asarray(getattr(mc.nominal, key)).reshape(-1)[0]) * fac
        out.append(((counts, np.asarray(edges) * fac), lab, nom))
    return out


def plot_tolerance(mc=None, sens=None, *, limits=()):
    """One figure of a tolerancing run: the raw and calibrated envelopes and the histograms
    (when ``mc``, a MonteCarloResult, is given) and the sensitivity bars (``sens``). Returns the
    Figure.

    Panels: :func:`plot_envelope` raw and calibrated (µm against degrees), histograms of P1, P2
    (calibrated and raw, 1e-6/mm), Fc and F0 (mm) and Fraser & Shortis's g_ss' (Eq. 6; when the
    run computed it), and the sensitivity of D_c (µm) at the largest field of ``sens``; three
    panels a row, 5.2 × 3.9 inches each.

    Parameters
    ----------
    mc : MonteCarloResult, optional
        From ``osc.tolerance_monte_carlo``.
    sens : SensitivityResult, optional
        From ``osc.tolerance_sensitivity``.
    limits : sequence of (float, float)
        (limit in µm, field angle in degrees) pairs drawn on both envelopes
        (:func:`plot_envelope`).

    Returns
    -------
    matplotlib.figure.Figure
        A new figure (no ``ax=``: the figure is its own).
    """
    panels = []
    if mc is not None:
        panels += ["env", "env_cal"] + [("hist", h) for h in _hist_panels(mc)]
    if sens is not None:
        panels.append("sens")
    if not panels:
        raise TypeError(
            "plot_tolerance needs mc= (a Monte Carlo result), sens= (a sensitivity), or both"
        )
    cols = 3 if len(panels) > 2 else max(1, len(panels))
    rows = -(-len(panels) // cols)
    fig, axs = panel_figure(rows, cols, figsize=(5.2 * cols, 3.9 * rows))
    axs = np.atleast_1d(axs).ravel()
    for ax, p in zip(axs, panels, strict=False):
        if p == "env":
            plot_envelope(mc, limits=limits, ax=ax)
        elif p == "env_cal":
            plot_envelope(mc, calibrated=True, limits=limits, ax=ax)
        elif p == "sens":
            fmax = float(np.max(sens.fields_deg))
            plot_sensitivity(sens.table("D_cal_um", fmax), label=f"ΔD_c at {fmax:g}° (µm)",
                             ax=ax)  # fmt: skip
        else:
            h, lab, nom = p[1]
            plot_histogram(hist=h, label=lab, nominal=nom, ax=ax)
    for ax in axs[len(panels) :]:
        ax.remove()
    return fig


__all__ = [
    "plot_envelope",
    "plot_histogram",
    "plot_sensitivity",
    "plot_tolerance",
]
